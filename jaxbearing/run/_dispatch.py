"""The one dispatcher of the steady-running engine: every member (`Member`: a case and a seed)
of a settled run, settled and measured by one of the drivers of `_engine` (docs/model.md 16).

`settle_members` resolves what the members' starts need first (the static skid equilibria: one
vmapped program for a vmapped batch; one per case for members that continue from given states,
whose verdict needs only the case's time constant), then runs the member programs
(`member_steps`) by the settings' strategy: one after another in this process ("sequential"),
one process per core ("processes", `parallel_map`), or all members as one vmapped program per
round ("vmap", `drive_batched`); "auto" picks by the machine (`choose_strategy`). Every strategy
takes the same decisions for a member.
"""

from __future__ import annotations

import dataclasses
import time

import jax
import numpy as np

from ._engine import BatchTimes, choose_strategy, drive, drive_batched
from ._ensemble import parallel_map
from ._initial import _static_skid_start, static_skid_starts
from ._member import Member, SeedRun, member_steps
from ._member_progress import active_progress
from ._settings import SettleAuto, SteadySettings
from ._solve_from import _integrator, solve_from


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


def _continuing_cases(members, settings: SteadySettings) -> dict:
    """{member index: index of its case's first member} for the members that continue from a
    given state and settle with the verdict: they share the static skid equilibrium of that
    first member's seed (a case: one bearing and operating point). The verdict needs only its
    time constant, which the seeds' scatters move by 3e-6 (reference bearing, 31 slices, seeds
    0-2); solved per seed, the equilibria took a quarter of a continuing design-search
    evaluation on the 2-core CPU."""
    if not isinstance(settings.settle, SettleAuto) or settings.continuation_settle_revs is not None:
        return {}
    first, out = {}, {}
    for i, m in enumerate(members):
        if m.initial_state is not None:
            leaves, tree = jax.tree_util.tree_flatten((m.bearing, m.operating))
            key = (str(tree), tuple(np.asarray(x).tobytes() for x in leaves))
            out[i] = first.setdefault(key, i)
    return out


def _shared_time_constants(members, settings: SteadySettings) -> dict:
    """{member index: static skid equilibrium} of `_continuing_cases`, one solve per case."""
    cases = _continuing_cases(members, settings)
    solved = {
        j: _static_skid_start(members[j].bearing, members[j].operating, members[j].perturbation)
        for j in set(cases.values())
    }
    return {i: solved[j] for i, j in cases.items()}


def _batched_statics(members, idx: list, settings: SteadySettings) -> dict:
    """{member index: static skid equilibrium} of the members `idx` of one vmapped group that need
    one, solved as one vmapped program: for the skid start, and for the verdict's time constant
    of continuing members (solved one by one on the host they took most of a search iteration on
    a GPU)."""
    cases = _continuing_cases([members[i] for i in idx], settings)
    auto = isinstance(settings.settle, SettleAuto)
    needs = [
        i
        for k, i in enumerate(idx)
        if (members[i].initial_state is None and (settings.start == "skid" or auto)) or cases.get(k) == k
    ]
    cases_needed = [(members[i].bearing, members[i].operating, members[i].perturbation) for i in needs]
    statics = dict(zip(needs, static_skid_starts(cases_needed) if needs else []))
    statics.update({idx[k]: statics[idx[j]] for k, j in cases.items()})
    return statics


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
    if chosen == "vmap":
        return _settle_vmapped(members, settings, devices, reduce, wall0)
    statics = _shared_time_constants(members, settings)
    if chosen == "processes" and len(members) > 1:
        items = [(m, statics.get(i)) for i, m in enumerate(members)]
        done = None if progress is None else progress.finished
        outs = parallel_map(
            _MemberJob(settings, reduce), items, workers=min(settings.workers, len(members)), on_done=done
        )
        compile_time = max(c for _, c in outs)
        # the pool's wall time less its longest compilation (the workers compile side by side)
        return EngineRun(
            [r for r, _ in outs], chosen, time.perf_counter() - wall0 - compile_time, compile_time
        )
    outs = [_run_one(m, settings, reduce, statics.get(i)) for i, m in enumerate(members)]
    compile_time = sum(c for _, c in outs)
    return EngineRun([r for r, _ in outs], chosen, time.perf_counter() - wall0 - compile_time, compile_time)


def _settle_vmapped(members, settings: SteadySettings, devices, reduce, wall0: float) -> EngineRun:
    """`settle_members` by the "vmap" strategy: one batch per parameter structure, each the
    members' programs driven together (`drive_batched`)."""
    times = BatchTimes()
    groups: dict = {}
    for i, m in enumerate(members):
        groups.setdefault(jax.tree_util.tree_structure(settings.params(m)), []).append(i)
    runs: list = [None] * len(members)
    quiet = dataclasses.replace(settings, progress=False)
    for idx in groups.values():
        h0 = time.perf_counter()
        statics = _batched_statics(members, idx, settings)
        times.host_s += time.perf_counter() - h0
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
