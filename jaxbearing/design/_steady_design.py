"""The steady-running design objective: what a design does in settled running.

For a design (R_end, theta_f, Delta_bf; `flange.DesignVariables`) at one operating point,
`steady_design_metrics` runs the bearing from the skid start until settled, measures a window of
cage revolutions for an ensemble of seeds (`simulate_steady`) and returns, each with its 95 %
confidence interval (Student-t over the seeds' batch means, `jaxbearing.run.student_t_interval`):

- `mean_pv`: the mean flange PV over contact time (every touching flange sample, equally spaced in
  time: the time average wear integrates), per cage revolution;
- `p95_pv`: its 95th percentile over contact time (the tail measure);
- `corner_contact_share`: the share of contact time whose contact point lies beyond the limited
  circle (on the corner torus);
- `corner_margin` [m]: the dynamic corner-contact margin rho_lim - max(contact radius) - `margin`,
  with max the largest contact radius of any touching sample in one cage revolution (expected
  per revolution, Student-t over the seeds): positive when the contact stays inside the limited
  circle by `margin` all the time (the dynamic counterpart of the static `limited_circle`
  margin: skewing rollers ride out towards the corner, the paper's Figure 13b). A percentile is
  not enough: at R_end 106.9 mm / theta_f 1.616 deg the p99 stayed 0.083 mm inside while 0.15 %
  of the contact time reached the corner (docs/model.md 17);
- `corner_margin_bound` [m]: the same margin on the upper 95 % prediction bound of one
  revolution's largest contact radius (`jaxbearing.run.max_contact_radius_bound`): it holds for
  a further revolution with 95 % probability, where `corner_margin` holds on average;

beside the four static design-zone margins of `flange.zone_margins` (relief, height,
limited circle, clearance; positive when satisfied) and the full settled summary.

- `objective`: the smooth mean PV over contact time of `_steady_objective` (the accumulators
  int w PV dt / int w dt with the smooth contact indicator w = Q / (Q + 1 N), integrated inside
  the solve over the window), per seed, with its Student-t interval over the seeds: the quantity
  the optimiser minimises and whose gradient `steady_gradient` estimates (`mean_pv` is the same
  average over the saved samples with the hard 1 N threshold); with `Statistic.PEAK` the
  p-mean PV_ref (int w (PV/PV_ref)^p dt / int w dt)^(1/p), p = `PEAK_EXPONENT`, which weights
  the peaks; with `Statistic.TAIL` the tail mean of PV over contact time per revolution, the
  mean of its worst 5 % of the saved touching samples (`run.tail_mean`); with
  `Statistic.FRICTION` the time-mean total flange friction power [W] (`STATISTICS`);
- `objectives_per_seed`: per seed, the objective of every statistic the run's accumulators give
  (the mean, the tail and the friction power integrate the same ones, so one ensemble gives
  all three);

It is a measurement, not a differentiable function: the gradient of a long impacting trajectory
is not a design signal (`_design`, docs/model.md 14); `steady_gradient` estimates the gradient
of the ensemble average from the states this returns (`final_states`).

Continuation. `initial_states` (one per seed, e.g. a neighbouring design's `final_states`)
starts every seed from a settled state instead of the skid start, so a design close to the
previous one settles in the settling verdict's minimum four revolutions (`jaxbearing.run.
simulate_steady`) instead of from the start.
"""

from __future__ import annotations

import dataclasses

import jax
import numpy as np

from ..flange import (
    DEFAULT_FLANGE_LOAD,
    MARGIN_NAMES,
    DesignVariables,
    ProfileVariables,
    check_design,
    plain_faces,
    zone_margins,
)
from ..geometry import Bearing, OperatingPoint
from ..io import per_point, require
from ..run import (
    Estimate,
    Perturbation,
    SettledStatistics,
    SteadySettings,
    settled_statistics,
    simulate_steady_points,
    steady_revolution_maxima,
    student_t_interval,
    summarise_steady,
)
from ._steady_objective import STATISTICS, Statistic, _functionals

#: default dynamic corner margin [m]: the largest contact radius this far inside the limited circle
CORNER_MARGIN = 0.05e-3


@dataclasses.dataclass
class SteadyDesignMetrics:
    """The steady-running objective of one design (module docstring). Estimates are
    `run.Estimate`s (value and 95 % interval); `statistics`: every statistic of the settled
    run (`run.SettledStatistics`; None when no seed was measured); `summary`: the run's
    summary.json block; `static_margins` [m] by `MARGIN_NAMES`."""

    design: dict
    objective: Estimate
    objective_per_seed: list
    mean_pv: Estimate
    p95_pv: Estimate
    corner_contact_share: Estimate
    corner_margin: Estimate
    static_margins: dict
    settled: bool
    seeds: list
    summary: dict
    statistics: SettledStatistics | None = dataclasses.field(default=None, repr=False)
    #: simulated time of the ensemble [ms]: every seed's settling and window
    simulated_ms: float = 0.0
    #: the state at the end of every seed's run (numpy leaves), to continue from
    final_states: list = dataclasses.field(default_factory=list, repr=False)
    #: settled states of every seed (window start and end): samples for `steady_gradient`
    sample_states: list = dataclasses.field(default_factory=list, repr=False)
    #: rho_lim - `margin` - the upper 95 % prediction bound of one revolution's largest contact
    #: radius (`run.max_contact_radius_bound`) [m]: the corner margin that holds for a further
    #: revolution with 95 % probability, not only on average
    corner_margin_bound: float = float("nan")
    #: per seed, the objective of every statistic of `STATISTICS` that the run's accumulators
    #: give (those with the run's functionals: the mean and the tail come from one ensemble,
    #: the peak from its own); `objective_per_seed` is the chosen statistic's
    objectives_per_seed: dict = dataclasses.field(default_factory=dict)
    #: per seed, the largest contact radius in contact of every measured cage revolution [m]
    #: (0: no flange contact; `run.revolution_maxima`): the data of the corner-contact risk
    contact_radius_maxima: list = dataclasses.field(default_factory=list, repr=False)
    #: rho_lim [m] (`geometry.limited_circle_radius`)
    limited_circle_radius_m: float = float("nan")

    def as_dict(self) -> dict:
        """Everything but the states, the per-revolution maxima and the statistics (the summary
        holds them), as plain (JSON-able) values; estimates as {"value", "ci95_low",
        "ci95_high", "n"}."""
        skip = ("final_states", "sample_states", "contact_radius_maxima", "statistics")
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name not in skip}
        return {k: v.as_dict() if isinstance(v, Estimate) else v for k, v in out.items()}


def steady_design_metrics(
    bearing: Bearing,
    op: OperatingPoint,
    design: DesignVariables,
    settings: SteadySettings | None = None,
    *,
    initial_states=None,
    **options,
) -> SteadyDesignMetrics:
    """Settled flange statistics of `design` over `settings.seeds` seeds (module docstring);
    `options`: those of `steady_design_metrics_points` (`corner_margin`, `flange_load`,
    `first_seed`, `statistic`) and keywords that change `settings`. `initial_states`:
    continuation (module docstring)."""
    one = None if initial_states is None else [initial_states]
    (metrics,) = steady_design_metrics_points(bearing, [op], design, settings, initial_states=one, **options)
    return metrics


def steady_design_metrics_points(
    bearing: Bearing | list[Bearing],
    ops,
    design: DesignVariables | ProfileVariables | list,
    settings: SteadySettings | None = None,
    *,
    corner_margin: float = CORNER_MARGIN,
    flange_load: float = DEFAULT_FLANGE_LOAD,
    first_seed: int = 0,
    initial_states=None,
    statistic: Statistic | str = Statistic.MEAN,
    perturbation: Perturbation = Perturbation(),
    **changes,
) -> list[SteadyDesignMetrics]:
    """`steady_design_metrics` at every operating point of `ops`, every point's seeds members of
    one call of the steady-running engine (`run.simulate_steady_points`: a design's whole
    envelope in one process pool, or one vmapped program on an accelerator). `design`: one
    design, or one per point (several designs in one call: every start of an iteration of a
    design search). `settings`: how the seeds settle and measure (`run.SteadySettings`, changed
    by `changes`; its functionals are those of `statistic` unless `changes` sets them).
    `first_seed` selects the seeds (first_seed .. first_seed + seeds - 1): a verification uses
    seeds a search never saw. `initial_states`: None, or per point None or one state per seed."""
    ops = list(ops)
    designs = per_point("design", design, (DesignVariables, ProfileVariables), len(ops))
    bases = per_point("bearing", bearing, Bearing, len(ops))
    for b, d in zip(bases, designs):
        check_design(b, d)
    require("corner_margin", corner_margin, lambda v: np.isfinite(v) & (v >= 0), ">= 0 m")
    require("first_seed", first_seed, lambda v: (v >= 0) & (v == np.round(v)), "an integer >= 0")
    changes.setdefault("functionals", _functionals(statistic))
    settings = (settings if settings is not None else SteadySettings()).replace(**changes)
    bearings = [d.apply(b) for b, d in zip(bases, designs)]
    pert = dataclasses.replace(perturbation, seed=int(first_seed))
    # a profile of today's faces (e = 0, a cone rib) settles on today's contact code: the same
    # numbers to round-off at about half the cost per step (`flange.plain_faces`)
    results = simulate_steady_points(
        [plain_faces(b) for b in bearings], ops, settings, initial_states=initial_states, perturbation=pert
    )
    fn = settings.functionals
    return [
        _metrics(
            result, d, np.asarray(zone_margins(b, d, flange_load=flange_load)), corner_margin, fn, statistic
        )
        for result, b, d in zip(results, bearings, designs)
    ]


def _own_statistic(result, run, read) -> float:
    """`read` of one seed's own settled statistics (`run.settled_statistics` of its window
    alone), e.g. the tail mean of PV over contact time or the friction power of that seed; NaN
    without a measured window."""
    if not run.measured:
        return float("nan")
    windows, edges, given = (
        ([run.window], [run.edges], None) if run.per_revolution is None else ([], [], [run.per_revolution])
    )
    own = settled_statistics(windows, edges, result.bearing, result.operating, per_revolution=given)
    return float(read(own))


#: per statistic read from a seed's own settled statistics (`_own_statistic`): the tail mean of
#: PV over contact time (the mean over the window's revolutions of `run.tail_mean` of the
#: touching samples) and the time-mean total flange friction power
_OWN_STATISTICS = {
    Statistic.TAIL: lambda own: own.flange_pv_contact_time_Pa_m_s.tail95.value,
    Statistic.FRICTION: lambda own: own.flange_friction_power_W.total.value,
}


def _metrics(
    result,
    design: DesignVariables | ProfileVariables,
    margins,
    corner_margin: float,
    functionals,
    statistic: Statistic | str = Statistic.MEAN,
) -> SteadyDesignMetrics:
    """The design metrics of one operating point's settled run (module docstring)."""
    stats = result.statistics()
    s = summarise_steady(result, statistics=stats)
    nothing = Estimate(np.nan, np.nan, np.nan, 0)
    rho_lim = np.nan if stats is None else stats.limited_circle_radius_m
    top = rho_lim - corner_margin

    def shifted(est: Estimate) -> Estimate:  # rho_lim - margin - est (the interval flips)
        return Estimate(top - est.value, top - est.ci95_high, top - est.ci95_low, est.n)

    objectives = {
        name: [float(v) for v in _objective_per_seed(result, name, functionals)]
        for name, fn in STATISTICS.items()
        if _same_functionals(fn, functionals)
    }
    per_seed = objectives.get(statistic)
    if per_seed is None:  # functionals of the caller's own
        per_seed = _objective_per_seed(result, statistic, functionals)
    return SteadyDesignMetrics(
        design=_design_record(design),
        objective=student_t_interval(per_seed),
        objective_per_seed=[float(v) for v in per_seed],
        mean_pv=nothing if stats is None else stats.flange_pv_contact_time_Pa_m_s.mean,
        p95_pv=nothing if stats is None else stats.flange_pv_contact_time_Pa_m_s.p95,
        corner_contact_share=nothing if stats is None else stats.corner_contact_share.time,
        corner_margin=nothing if stats is None else shifted(stats.contact_radius_m.max_in_contact),
        static_margins={name: float(m) for name, m in zip(MARGIN_NAMES, margins)},
        settled=bool(result.settled),
        seeds=[r.seed for r in result.runs],
        summary=s,
        statistics=stats,
        simulated_ms=_simulated_ms(result),
        final_states=[r.final_state for r in result.runs],
        sample_states=[
            x for r in result.runs if r.status == "ok" for x in (r.window_start_state, r.final_state)
        ],
        corner_margin_bound=np.nan if stats is None else top - stats.max_contact_radius_bound.value,
        objectives_per_seed=objectives,
        contact_radius_maxima=steady_revolution_maxima(result).contact_radius_m,
        limited_circle_radius_m=float(rho_lim),
    )


#: SI units of the profile fields beyond the three-variable design (`flange.PROFILE_NAMES`)
_PROFILE_UNITS = {
    "end_offset": "m",
    "corner_radius": "m",
    "rib_curvature": "1_per_m",
    "rib_tangent_height": "m",
    "flange_height": "m",
}


def _design_record(design) -> dict:
    """The design as {name_unit: value} in SI units; a profile adds its five face fields."""
    out = {
        "end_radius_m": float(design.end_radius),
        "layback_angle_rad": float(design.layback_angle),
        "axial_clearance_m": float(design.axial_clearance),
    }
    if isinstance(design, ProfileVariables):
        out |= {f"{name}_{unit}": float(getattr(design, name)) for name, unit in _PROFILE_UNITS.items()}
    return out


def _simulated_ms(result) -> float:
    """Simulated time of a settled ensemble [ms]: every seed's settling, and the mean measured
    window once per seed."""
    windows = [r.edges[-1] - r.edges[0] for r in result.runs if r.measured]
    window_ms = float(np.mean(windows)) * 1e3 if windows else 0.0
    return sum(r.settle_time * 1e3 for r in result.runs) + len(result.runs) * window_ms


def _same_functionals(a, b) -> bool:
    """True when `a` and `b` integrate the same accumulators (equal leaves, floats or arrays)."""
    la, ta = jax.tree_util.tree_flatten(a)
    lb, tb = jax.tree_util.tree_flatten(b)
    return ta == tb and all(np.array_equal(np.asarray(x), np.asarray(y)) for x, y in zip(la, lb))


def _objective_per_seed(result, statistic: Statistic | str, functionals) -> list:
    """Each seed's objective of `statistic` from the window of `result`'s runs (module
    docstring): the tail and the friction power from the seed's own statistics
    (`_OWN_STATISTICS`), the mean and the peak from the accumulated integrals of `functionals`,
    PV_ref (sum A / sum C)^(1/p); NaN where a seed has no measured window or contact."""
    if statistic in _OWN_STATISTICS:
        return [_own_statistic(result, r, _OWN_STATISTICS[statistic]) for r in result.runs]
    pv_ref, p = float(functionals.pv_reference), float(functionals.pv_exponent)
    return [
        pv_ref * (sum(a for a, _ in r.window_integrals) / sum(c for _, c in r.window_integrals)) ** (1.0 / p)
        if r.status == "ok" and r.window_integrals and sum(c for _, c in r.window_integrals) > 0
        else np.nan
        for r in result.runs
    ]
