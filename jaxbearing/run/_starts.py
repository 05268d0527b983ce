"""The starts of the steady-running engine's members, resolved in one step before any member
runs (docs/model.md 16).

A member that starts from the skid start needs its static skid equilibrium (the plateau the
pre-start starts from, and the slow mode's time constant the settling verdict uses); a member
from the quasi-static start needs only the time constant, when it settles with the verdict
("auto"); members continuing from given states share one equilibrium per case (a bearing and
operating point), since the verdict needs only its time constant, which the seeds' scatters move
by 3e-6 (reference bearing, 31 slices, seeds 0-2). `resolve_starts` finds which members need an
equilibrium, solves each needed one once, by the engine's strategy through the one member
dispatcher (`map_members`: one vmapped program per parameter structure, one process per core, or
one after another), each read from or stored in the start cache (`_start_cache`), and hands every
member its own. The member programs (`member_steps`) then never solve one themselves.
"""

from __future__ import annotations

import dataclasses

import jax
import numpy as np

from ._ensemble import parallel_map
from ._initial import SkidStart, _static_skid_start, static_skid_starts
from ._member import Member
from ._settings import SettleAuto, SteadySettings


def map_members(items, strategy: str, workers: int, one, batched=None, on_done=None) -> list:
    """The one member dispatcher: [one(item) for item in items] in order, by `strategy` (as
    `choose_strategy` chose it): "vmap" hands them all to `batched(items)` (one vmapped program),
    "processes" maps `one` (picklable) over `workers` processes (`parallel_map`, `on_done()` as
    each finishes), "sequential" runs them one after another in this process."""
    items = list(items)
    if not items:
        return []
    if strategy == "vmap":
        return batched(items)
    if strategy == "processes" and len(items) > 1:
        return parallel_map(one, items, workers=min(int(workers), len(items)), on_done=on_done)
    return [one(item) for item in items]


def continuing_cases(members, settings: SteadySettings) -> dict:
    """{member index: index of the first member of its case} for the members that continue from
    a given state and settle with the verdict (module docstring); {} otherwise."""
    if not isinstance(settings.settle, SettleAuto) or settings.continuation_settle_revs is not None:
        return {}
    first, out = {}, {}
    for i, m in enumerate(members):
        if m.initial_state is not None:
            leaves, tree = jax.tree_util.tree_flatten((m.bearing, m.operating))
            key = (str(tree), tuple(np.asarray(x).tobytes() for x in leaves))
            out[i] = first.setdefault(key, i)
    return out


def _needs_own(member: Member, settings: SteadySettings) -> bool:
    """Whether a member that starts afresh needs its own static skid equilibrium: the skid start,
    or the verdict's time constant."""
    return member.initial_state is None and (
        settings.start == "skid" or isinstance(settings.settle, SettleAuto)
    )


@dataclasses.dataclass(frozen=True)
class _StaticJob:
    """Picklable `_static_skid_start` of one (bearing, operating point, perturbation)."""

    def __call__(self, case) -> SkidStart:
        return _static_skid_start(*case)


def _batched(cases) -> list[SkidStart]:
    """`static_skid_starts` of `cases`, one vmapped program per parameter structure, in order."""
    groups: dict = {}
    for k, (b, op, _) in enumerate(cases):
        groups.setdefault(jax.tree_util.tree_structure((b, op)), []).append(k)
    out: list = [None] * len(cases)
    for idx in groups.values():
        for k, s in zip(idx, static_skid_starts([cases[k] for k in idx])):
            out[k] = s
    return out


def resolve_starts(members, settings: SteadySettings, strategy: str) -> dict[int, SkidStart]:
    """{member index: its static skid equilibrium} for every member that needs one (module
    docstring), each equilibrium solved once by `strategy` (`map_members`)."""
    members = list(members)
    cases = continuing_cases(members, settings)
    owners = sorted({i for i, m in enumerate(members) if _needs_own(m, settings)} | set(cases.values()))
    work = [(members[i].bearing, members[i].operating, members[i].perturbation) for i in owners]
    solved = dict(zip(owners, map_members(work, strategy, settings.workers, _StaticJob(), _batched)))
    solved.update({i: solved[j] for i, j in cases.items()})
    return solved
