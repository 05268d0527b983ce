"""The steady-running engine's drivers: many members' runs as programs of integration requests,
driven one at a time, one process per core, or together as one vmapped program (docs/model.md 16).

A settled run (`_member.member_steps`) is written once, as a Python generator: it yields an
integration request `(state, duration)` (continue the dynamics from `state` for `duration`
seconds), is sent the answer `(histories, final state, result code, steps)` of `solve_from`, and
makes every host-side decision between requests itself (the skid start's pre-start bursts,
revolution chunks whose length follows its own cage speed, projective steps, the settling
verdict, the window). A *member* is one such run: one bearing, operating point and design, one
seed. The drivers below answer the requests; none of them knows what a member does, so every
driver gives the same member the same decisions.

* `drive`: one member, its requests answered by its own compiled `solve_from` (the CPU path;
  `simulate_steady` with one worker).
* `drive_batched`: many members together. Every round, each running member's pending request is
  one slot of one call of `vmap(solve_from)` over (parameters, state, duration, rtol, atol),
  compiled once for the batch size (`compiled_program`) and, with several local devices,
  split over them (`jax.shard_map` over a 1-D mesh, axis "members"). Each slot integrates with
  its own adaptive steps (diffrax's loop under `vmap` masks the slots that have finished), so a
  member's answer does not depend on its batch-mates beyond round-off (tested). A member that
  has finished waits masked: its slot integrates `IDLE_DURATION` from its last state and the
  answer is dropped. The round costs as long as its longest request: members settle and measure
  in revolutions of similar length, so the loss is small when the members' speeds are alike
  (sort a sweep's members by speed to keep it small).
* Which one (`choose_strategy`): on an accelerator, members are vmapped ("vmap"); on CPUs,
  one member after another per process, one process per core ("processes"), since a vmapped
  batch is slower per member on a CPU than one member at a time (0.74x, docs/performance.md).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence

import jax
import numpy as np

from ._compile_cache import compiled_program

#: a finished member's slot integrates this long [s] while the others run (one step)
IDLE_DURATION = 1e-7
#: engine strategies (`choose_strategy`)
STRATEGIES = ("auto", "sequential", "processes", "vmap")


def drive(program, integrate: Callable):
    """Run the request program `program` (a generator, module docstring) to its end, answering
    each request with `integrate(state, duration)`; returns the program's return value."""
    try:
        request = next(program)
        while True:
            request = program.send(integrate(*request))
    except StopIteration as stop:
        return stop.value


def choose_strategy(strategy: str, workers: int, devices: Sequence | None = None) -> str:
    """The driver for `strategy` ("auto": "vmap" on an accelerator or with several devices
    given, else "processes" with `workers` > 1, else "sequential")."""
    if strategy != "auto":
        return strategy
    devices = jax.local_devices() if devices is None else devices
    if devices and (devices[0].platform != "cpu" or len(devices) > 1):
        return "vmap"
    return "processes" if workers > 1 else "sequential"


def stack_trees(trees):
    """The pytrees `trees` (one structure) as one pytree of numpy arrays with a leading axis."""
    return jax.tree_util.tree_map(lambda *xs: np.stack([np.asarray(x) for x in xs]), *trees)


def _slot(tree, i: int):
    return jax.tree_util.tree_map(lambda a: a[i], tree)


@dataclasses.dataclass
class BatchTimes:
    """Where a batched drive spent its time [s]: compiling, the batched calls, and host work
    (the members' decisions, statistics, transfers); `rounds`: batched calls made."""

    compile_s: float = 0.0
    solve_s: float = 0.0
    host_s: float = 0.0
    rounds: int = 0


def batched_program(
    solve_from: Callable, params, state, num_saves: int, max_steps: int, solver: str, devices: Sequence
):
    """`vmap(solve_from)` over stacked (params, state, duration, rtol, atol) with leading axis a
    multiple of len(devices), compiled: on one device the plain vmap (`compiled_program`: traced
    once per machine), on several `jax.shard_map` over the mesh axis "members". `solve_from`:
    the integrator one member at a time uses (`_solve_from.solve_from`)."""

    def one(p, s, d, r, a):
        return solve_from(p, s, d, num_saves=num_saves, rtol=r, atol=a, max_steps=max_steps, solver=solver)

    n = jax.tree_util.tree_leaves(state)[0].shape[0]
    f = np.ones(n)
    args = (params, state, f, f, f)
    if len(devices) == 1 and jax.process_count() == 1 and devices[0] == jax.devices()[0]:
        return compiled_program("solve_from_members", jax.vmap(one), args, (num_saves, max_steps, solver))
    from jax.sharding import Mesh, PartitionSpec

    mesh = Mesh(np.asarray(devices), ("members",))
    spec = PartitionSpec("members")
    sharded = jax.shard_map(jax.vmap(one), mesh=mesh, in_specs=(spec,) * 5, out_specs=spec, check_vma=False)
    return jax.jit(sharded).lower(*args).compile()


def drive_batched(
    programs: Sequence,
    params: Sequence,
    tolerances: Sequence[tuple[float, float]],
    *,
    solve_from: Callable,
    num_saves: int,
    max_steps: int,
    solver: str,
    devices: Sequence | None = None,
    times: BatchTimes | None = None,
) -> list:
    """Run the request programs `programs` together (module docstring): member i integrates
    with `params[i]` (a `dynamics.Params`; all of one structure) and `tolerances[i]` = (rtol,
    atol), answered by `solve_from` vmapped. Returns the programs' return values, in order."""
    times = times if times is not None else BatchTimes()
    devices = tuple(jax.local_devices() if devices is None else devices)
    n = len(programs)
    size = -(-n // len(devices)) * len(devices)
    pad = list(range(n)) + [n - 1] * (size - n)  # padded slots repeat the last member, idle
    h0 = time.perf_counter()
    results: list = [None] * n
    pending: dict[int, tuple] = {}
    for i, program in enumerate(programs):
        try:
            pending[i] = next(program)
        except StopIteration as stop:
            results[i] = stop.value
    last = {i: req for i, req in pending.items()}
    stacked_params = stack_trees([params[i] for i in pad])
    rtol = np.asarray([tolerances[i][0] for i in pad], float)
    atol = np.asarray([tolerances[i][1] for i in pad], float)
    times.host_s += time.perf_counter() - h0
    run = None
    while pending:
        h0 = time.perf_counter()
        states, durations = [], []
        for slot, i in enumerate(pad):
            if slot < n and slot in pending:
                state, duration = pending[slot]
            else:  # finished or padding: idle from the last state
                state, duration = last.get(i, next(iter(last.values())))[0], IDLE_DURATION
            states.append(jax.tree_util.tree_map(np.asarray, state))
            durations.append(float(duration))
        stacked = stack_trees(states)
        times.host_s += time.perf_counter() - h0
        if run is None:
            c0 = time.perf_counter()
            run = batched_program(solve_from, stacked_params, stacked, num_saves, max_steps, solver, devices)
            times.compile_s += time.perf_counter() - c0
        s0 = time.perf_counter()
        out = jax.device_get(run(stacked_params, stacked, np.asarray(durations), rtol, atol))
        times.solve_s += time.perf_counter() - s0
        times.rounds += 1
        h0 = time.perf_counter()
        for i in list(pending):
            answer = _slot(out, i)
            last[i] = (answer[1], IDLE_DURATION)
            try:
                pending[i] = programs[i].send(answer)
            except StopIteration as stop:
                results[i] = stop.value
                del pending[i]
        times.host_s += time.perf_counter() - h0
    return results
