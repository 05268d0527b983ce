"""Settled running: settle every seed of a case until its cage speed stops drifting, then measure
a window of whole cage revolutions, with 95 % confidence intervals (docs/model.md 16).

`simulate_steady` runs the seeds of a case (and `simulate_steady_points` those of several cases,
e.g. a design's whole speed envelope or every design of a search iteration) as members of one
call of the steady-running engine (`settle_members`), with one `SteadySettings`: the start (the
skid equilibrium, by default), settling (`SettleAuto`: the settling verdict; `SettleFixed`;
`SettleOff`), the window and the seeds. `summarise_steady` writes its summary.json block; its
statistics and intervals come from `_statistics`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._errors import UserInputError
from ..geometry import Bearing, OperatingPoint, kinematic_cage_speed, rad_s_to_rpm
from ..io import finite_or_none
from ._dispatch import settle_members
from ._initial import Perturbation
from ._member import Member
from ._settings import SteadySettings
from ._settled_statistics import SettledStatistics, settled_statistics
from ._simulate import simulate as _simulate_fixed
from ._summary import CONTACT_THRESHOLD, FAILED_LABEL, SETTLED_LABEL, UNSETTLED_LABEL
from ._summary import summarise as _summarise_fixed


@dataclasses.dataclass
class SteadyResult:
    """A settled run of one case over its seeds (`SeedRun`s): the settings it ran with, how its
    members settled (`settle_mode`: "auto", "fixed", "off", or "continuation, N revolutions"),
    how they started ("skid", "quasi-static" or "continuation"), and the wall and compilation
    times of the engine call that ran it [s]."""

    runs: list
    settings: SteadySettings
    settle_mode: str
    start: str
    wall_time_s: float
    compile_time_s: float
    bearing: Bearing
    operating: OperatingPoint

    @property
    def ok(self) -> bool:
        return all(r.status == "ok" for r in self.runs)

    @property
    def settled(self) -> bool:
        return all(r.settled for r in self.runs)

    @property
    def status(self) -> str:
        return "ok" if self.ok else next(r.status for r in self.runs if r.status != "ok")

    @property
    def histories(self) -> dict:
        """The first seed's window (for plots and the histories file)."""
        return self.runs[0].window

    def statistics(self, threshold: float = CONTACT_THRESHOLD) -> SettledStatistics | None:
        """The statistics of the measured members' windows (`SettledStatistics`; a sample is
        contact above `threshold` [N]); None when no member was measured."""
        ok = [r for r in self.runs if r.measured]
        if not ok:
            return None
        fresh = [r for r in ok if r.per_revolution is None]
        return settled_statistics(
            [r.window for r in fresh],
            [r.edges for r in fresh],
            self.bearing,
            self.operating,
            threshold,
            per_revolution=[r.per_revolution for r in ok if r.per_revolution is not None],
        )


def simulate_steady(
    bearing: Bearing,
    op: OperatingPoint,
    settings: SteadySettings | None = None,
    *,
    initial_states=None,
    perturbation: Perturbation = Perturbation(),
    **changes,
) -> SteadyResult:
    """Settle, then measure `settings.window_revs` cage revolutions, for each of `settings.seeds`
    seeded initial scatters (`perturbation` with seeds perturbation.seed, +1, ...), each a
    member of the steady-running engine (`settle_members`). `settings`: a `SteadySettings`
    (default: its defaults); keywords naming its fields change it (`simulate_steady(b, op,
    seeds=4)`). `initial_states` (continuation): one `State` per seed (e.g. `SeedRun.final_state`
    of a neighbouring design's settled run) to start from instead of the start; settling then
    runs without projective steps and the start is reported as "continuation". "processes"
    (settings.workers > 1 on a CPU) starts its workers with `spawn`: a script calling this needs
    the `if __name__ == "__main__":` guard."""
    one = None if initial_states is None else [initial_states]
    (result,) = simulate_steady_points(
        bearing, [op], settings, initial_states=one, perturbation=perturbation, **changes
    )
    return result


def simulate_steady_points(
    bearing: Bearing | list[Bearing],
    ops,
    settings: SteadySettings | None = None,
    *,
    initial_states=None,
    perturbation: Perturbation = Perturbation(),
    **changes,
) -> list[SteadyResult]:
    """`simulate_steady` at every operating point of `ops`, every point's seeds members of one
    call of the steady-running engine (one process pool or one vmapped program for all of them);
    one `SteadyResult` per point, in order. `bearing`: one bearing, or one per point (several
    designs, each at its operating points). `initial_states`: None, or per point None or one
    state per seed. The wall and compilation times of each result are those of the whole call."""
    from ..io import per_point, validate_bearing

    settings = (settings if settings is not None else SteadySettings()).replace(**changes)
    ops = list(ops)
    bearings = per_point("bearing", bearing, Bearing, len(ops))
    for b, op in zip(bearings, ops):
        validate_bearing(b, op)
    given = _given_states(initial_states, len(ops), settings.seeds)
    n = settings.seeds
    perturbations = [dataclasses.replace(perturbation, seed=perturbation.seed + k) for k in range(n)]
    members = [
        Member(b, op, p, s)
        for b, op, states in zip(bearings, ops, given)
        for p, s in zip(perturbations, states)
    ]
    engine = settle_members(members, settings)
    return [
        SteadyResult(
            runs=engine.runs[k * n : (k + 1) * n],
            settings=settings,
            settle_mode=_settle_mode(
                settings, continuing=initial_states is not None and given[k][0] is not None
            ),
            start=settings.start if given[k][0] is None else "continuation",
            wall_time_s=engine.wall_time_s,
            compile_time_s=engine.compile_time_s,
            bearing=b,
            operating=op,
        )
        for k, (b, op) in enumerate(zip(bearings, ops))
    ]


def _given_states(initial_states, num_points: int, seeds: int) -> list[list]:
    """Per point, one start state or None per seed, checked against the points and seeds."""
    if initial_states is None:
        return [[None] * seeds for _ in range(num_points)]
    given = list(initial_states)
    if len(given) != num_points:
        raise UserInputError(
            f"initial_states: {len(given)} given, expected one list per operating point ({num_points})"
        )
    out = []
    for states in given:
        states = [None] * seeds if states is None else list(states)
        if len(states) != seeds:
            raise UserInputError(f"initial_states: {len(states)} given, expected one per seed ({seeds})")
        out.append(states)
    return out


def _settle_mode(settings: SteadySettings, continuing: bool) -> str:
    """How a case's members settled, for its summary: "auto", "fixed", "off", or, continuing
    with `continuation_settle_revs` = n, "continuation, n revolutions"."""
    if continuing and settings.continuation_settle_revs is not None:
        return f"continuation, {settings.continuation_settle_revs} revolutions"
    return settings.settle.mode


def summarise_steady(
    result: SteadyResult, threshold: float = CONTACT_THRESHOLD, statistics: SettledStatistics | None = None
) -> dict:
    """The summary.json block of a settled run: how it settled, and every statistic of the
    window as {"value", "ci95_low", "ci95_high", "n"} (`SettledStatistics.as_dict`;
    `statistics`: the run's, when already computed)."""
    runs = result.runs
    ok = [r for r in runs if r.measured]
    block = {
        "running": FAILED_LABEL if not result.ok else SETTLED_LABEL if result.settled else UNSETTLED_LABEL,
        "status": "ok" if result.ok else next(r.status for r in runs if r.status != "ok"),
        "settled": bool(result.settled),
        "settle_mode": result.settle_mode,
        "settle_time_ms": max(r.settle_time for r in runs) * 1e3,
        "settle_tolerance": result.settings.tolerance,
        "settle_cap_ms": result.settings.settle_cap_ms,
        "window_revs": result.settings.window_revs,
        "window_ms": float(np.mean([r.edges[-1] - r.edges[0] for r in ok])) * 1e3 if ok else 0.0,
        "seeds": [r.seed for r in runs],
        "start": result.start,
        "kinematic_cage_speed_rpm": float(
            rad_s_to_rpm(kinematic_cage_speed(result.bearing, result.operating))
        ),
        "per_seed": [
            {
                "seed": r.seed,
                "settled": r.settled,
                "settle_time_ms": r.settle_time * 1e3,
                "status": r.status,
                "num_steps": r.num_steps,
                "revolution_end_ms": [t * 1e3 for t in r.revolution_ends],
                "revolution_cage_speed_rpm": r.revolution_speeds_rpm,
                "start_cage_speed_rpm": r.start_cage_speed_rpm,
                "projective_steps_rpm": r.projective_steps_rpm,
                **_verdict_block(r.verdict),
            }
            for r in runs
        ],
        **_residual_drift(runs),
        "num_steps": sum(r.num_steps for r in runs),
        "wall_time_s": result.wall_time_s,
        "compile_time_s": result.compile_time_s,
    }
    stats = statistics if statistics is not None else result.statistics(threshold)
    if stats is not None:
        block.update(stats.as_dict())
    return block


#: how the summary's residual drift is estimated (docs/model.md 16)
RESIDUAL_DRIFT_METHOD = (
    "remaining drift of the cage speed on its slow mode, |b| tau_run: b the slope of the least-squares "
    "line through the revolution-mean cage speeds of the last 4-8 revolutions before the window (since "
    "the last projective step), tau_run the running slow mode's time constant (1.5 x the static skid "
    "equilibrium's tau_s, or the pre-start's longest secant if longer); bound: (|b| + t_{n-2,0.95} SE(b)) tau_run; "
    "settled when bound <= tolerance x cage speed"
)


def _verdict_block(verdict) -> dict:
    """A seed's settling verdict in the summary (nan fields as None: JSON has no nan)."""
    if verdict is None:
        return {}

    num = finite_or_none
    return {
        "residual_drift_rpm": num(verdict.residual_drift_rpm),
        "residual_drift_bound_rpm": num(verdict.bound_rpm),
        "settling_drift_rpm_s": num(verdict.slope_rpm_s),
        "settling_drift_se_rpm_s": num(verdict.slope_se_rpm_s),
        "verdict_revolutions": int(verdict.revolutions),
        "slow_mode_time_constant_ms": num(verdict.time_constant_s * 1e3),
    }


def _residual_drift(runs) -> dict:
    """The summary's residual drift: the largest over the seeds (None where no verdict was
    evaluated: fixed or no settling)."""
    drifts = [r.verdict.residual_drift_rpm for r in runs if r.verdict is not None]
    bounds = [r.verdict.bound_rpm for r in runs if r.verdict is not None]
    finite = [d for d in drifts if math.isfinite(d)]
    if not finite:
        return {"residual_drift_rpm": None, "residual_drift_bound_rpm": None}
    return {
        "residual_drift_rpm": max(finite),
        "residual_drift_bound_rpm": max(b for b in bounds if math.isfinite(b)),
        "residual_drift_method": RESIDUAL_DRIFT_METHOD,
    }


def simulate(
    bearing: Bearing, op: OperatingPoint, *, settle=None, settings: SteadySettings | None = None, **kwargs
):
    """`jaxbearing.simulate`: without `settle` or `settings`, one fixed-duration run from the
    quasi-static start (`_simulate.simulate`, a `SimulationResult`); with either, a settled run
    (`simulate_steady`, a `SteadyResult`; `settle` and the other keywords that name a field of
    `SteadySettings` change `settings`)."""
    if settle is None and settings is None:
        return _simulate_fixed(bearing, op, **kwargs)
    kwargs.pop("duration", None)
    kwargs.pop("num_saves", None)
    if kwargs.get("perturbation", 1) is None:
        kwargs["perturbation"] = Perturbation()
    if settle is not None:
        kwargs["settle"] = settle
    return simulate_steady(bearing, op, settings, **kwargs)


def summarise(result, threshold: float = CONTACT_THRESHOLD) -> dict:
    """`jaxbearing.summarise`: the summary.json block of a fixed run (`_summary.summarise`) or of
    a settled run (`summarise_steady`)."""
    if isinstance(result, SteadyResult):
        return summarise_steady(result, threshold)
    return _summarise_fixed(result, threshold)
