"""The one dispatcher of the steady-running engine: every member (`Member`: a case and a seed)
of a settled run, settled and measured by one of the drivers of `_engine` (docs/model.md 16).

`settle_members` resolves what the members' starts need first, in one step for every strategy
(`_starts.resolve_starts`: the static skid equilibria, each solved once, read from or stored in
the start cache), then runs the member programs (`member_steps`) by the settings' strategy
through the one member dispatcher (`_starts.map_members`, which the gradient estimators use
too): one after another in this process ("sequential"), one process per core ("processes",
`parallel_map`, one pool for both steps), or all members as one vmapped program per round
("vmap", `drive_batched`); "auto" picks by the machine (`choose_strategy`). Every strategy takes
the same decisions for a member.
"""

from __future__ import annotations

import dataclasses
import time
from contextlib import nullcontext

import jax

from ._engine import BatchTimes, choose_strategy, drive, drive_batched
from ._ensemble import shared_workers
from ._member import Member, SeedRun, member_steps
from ._member_progress import active_progress
from ._settings import SteadySettings
from ._solve_from import _integrator, solve_from
from ._starts import map_members, resolve_starts


def _reporting(program):
    """`program` (a member's requests), telling the active `MemberProgress` when it has finished
    (in this process: the one-member and the vmapped drivers)."""
    result = yield from program
    progress = active_progress()
    if progress is not None:
        progress.finished()
    return result


def _run_one(member: Member, settings: SteadySettings, reduce=None, static=None) -> tuple[SeedRun, float]:
    """One member in this process (`drive`, its own compiled `solve_from`): (run, compile time);
    `static`: as `member_steps`."""
    compiled: list = []
    rtol, atol = settings.tolerances(member)
    integrate = _integrator(
        settings.params(member),
        settings.saves_per_rev,
        settings.max_steps,
        rtol,
        atol,
        compiled,
        settings.solver,
    )
    run = drive(_reporting(member_steps(member, settings, reduce, static, stored_start=True)), integrate)
    return run, sum(compiled)


@dataclasses.dataclass(frozen=True)
class _MemberJob:
    """Picklable `_run_one` (for `parallel_map`)."""

    settings: SteadySettings
    reduce: object = None

    def __call__(self, item):
        member, static = item
        return _run_one(member, self.settings, self.reduce, static)


@dataclasses.dataclass
class EngineRun:
    """What `settle_members` returns: one `SeedRun` per member (in order), the strategy that
    ran them, the wall time without compilation and the compilation time [s]; `batch_times`
    for the vmapped strategy (`_engine.BatchTimes`)."""

    runs: list
    strategy: str
    wall_time_s: float
    compile_time_s: float
    batch_times: BatchTimes | None = None


def settle_members(
    members, settings: SteadySettings = SteadySettings(), *, devices=None, reduce=None
) -> EngineRun:
    """The steady-running engine: settle and measure every member (`Member`: a case and one
    seed) with `settings`, by `settings.strategy` (module docstring): "processes" starts its
    workers with `spawn` (a script calling this needs the `if __name__ == "__main__":` guard);
    "vmap" runs over `devices` (the local devices by default). `reduce(run, member)`
    (picklable for "processes") turns each finished `SeedRun` into what is kept."""
    members = list(members)
    chosen = choose_strategy(settings.strategy, min(settings.workers, len(members)), devices)
    wall0 = time.perf_counter()
    progress = active_progress()
    if progress is not None:
        progress.started(len(members))
    pool = shared_workers(min(settings.workers, len(members))) if chosen == "processes" else nullcontext()
    with pool:
        h0 = time.perf_counter()
        statics = resolve_starts(members, settings, chosen)
        if chosen == "vmap":
            return _settle_vmapped(
                members, settings, devices, reduce, wall0, statics, time.perf_counter() - h0
            )
        outs = map_members(
            [(m, statics.get(i)) for i, m in enumerate(members)],
            chosen,
            settings.workers,
            _MemberJob(settings, reduce),
            on_done=None if progress is None else progress.finished,
        )
    if chosen == "processes" and len(members) > 1:
        compile_time = max(c for _, c in outs)
        # the pool's wall time less its longest compilation (the workers compile side by side)
    else:
        compile_time = sum(c for _, c in outs)
    return EngineRun([r for r, _ in outs], chosen, time.perf_counter() - wall0 - compile_time, compile_time)


def _settle_vmapped(
    members, settings: SteadySettings, devices, reduce, wall0: float, statics: dict, host_s: float
) -> EngineRun:
    """`settle_members` by the "vmap" strategy: one batch per parameter structure, each the
    members' programs driven together (`drive_batched`); `statics`: the resolved starts, solved
    in `host_s` seconds."""
    times = BatchTimes()
    times.host_s += host_s
    groups: dict = {}
    for i, m in enumerate(members):
        groups.setdefault(jax.tree_util.tree_structure(settings.params(m)), []).append(i)
    runs: list = [None] * len(members)
    quiet = dataclasses.replace(settings, progress=False)
    for idx in groups.values():
        outs = drive_batched(
            [_reporting(member_steps(members[i], quiet, reduce, statics.get(i))) for i in idx],
            [settings.params(members[i]) for i in idx],
            [settings.tolerances(members[i]) for i in idx],
            solve_from=solve_from,
            num_saves=settings.saves_per_rev,
            max_steps=settings.max_steps,
            solver=settings.solver,
            devices=devices,
            times=times,
        )
        for i, out in zip(idx, outs):
            runs[i] = out
    wall = time.perf_counter() - wall0 - times.compile_s
    return EngineRun(runs, "vmap", wall, times.compile_s, times)
