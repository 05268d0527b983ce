"""One evaluation of the design search on steady running: the settled objective, its gradient
and the constraints of every start's design at every operating point of the envelope
(docs/model.md 17).

Objective. At every operating point k the statistic of settled running the settings name
(`jaxbearing.design.Statistic`: mean, peak or tail flange PV, or the total flange friction
power; `jaxbearing.design.steady_design_metrics_points`: skid start or continuation, settling,
a window of `window_revs` cage revolutions, `seeds` seeded scatters; Student-t CI over the
seeds), combined over the envelope as in `DesignProblem.combine` (smooth max or weighted mean),
in GPa m/s (W for the friction power), with the delta-method interval of `combined_interval`.

Gradient. "frozen": the frozen-load estimate (`jaxbearing.design.frozen_load_statistics`) from
the settled states the objective's runs passed through; "window": short-window forward-mode
sensitivities (`jaxbearing.design.steady_gradient`). Neither sees the axial clearance: where
`clearance_step_for` gives h > 0, dJ/dDelta_bf is the paired common-random-number central
difference of the settled objective (`clearance_signal`).
"""

from __future__ import annotations

import dataclasses
import functools
import time

import jax
import jax.numpy as jnp
import numpy as np
from scipy import stats

from jaxbearing import UserInputError
from jaxbearing.design import (
    Statistic,
    SteadyGradient,
    frozen_load_statistics,
    paired_central_difference,
    steady_design_metrics_points,
    steady_gradient,
)
from jaxbearing.flange import MARGIN_NAMES, variables_from_array
from jaxbearing.run import CORNER_RISK_CONFIDENCE, shared_workers, tolerance_bound

from ._problem import DesignProblem
from ._settings import CornerConstraint, Estimator, SteadySettings, clearance_step_for


@dataclasses.dataclass(frozen=True)
class PointGradients:
    """The gradient estimates at one start and operating point (`_gradients`): the objective's
    and, where a friction limit is set and the estimator is the frozen-load one, the total
    flange friction power's from the same trajectories (None otherwise)."""

    objective: SteadyGradient
    friction: SteadyGradient | None = None


@dataclasses.dataclass
class PointRecord:
    """What one evaluation measured at one operating point (objective values in the statistic's
    unit, `Statistic.shown`: GPa m/s, or W for the friction power; gradients per unit of the
    scaled box, margins in m)."""

    value: float
    ci: tuple  # (low, high): the point's 95 % interval
    gradient: np.ndarray  # (n,)
    gradient_stderr: np.ndarray  # (n,)
    #: the dynamic corner margin the search constrains (`SteadySettings.corner_constraint`), moved
    #: by the static limited-circle margin's change where the point was not simulated
    corner_margin: float
    measured_corner_margin: float  # ... as measured, at `measured_at`
    measured_at: np.ndarray  # the scaled design (n,) where it was measured
    corner_contact_share: float
    settled: bool
    simulated: bool  # False: the values of an earlier evaluation (`next_active`)
    estimator_value: float = float("nan")  # the gradient estimator's own objective
    #: the upper 95 % bound of the corner-contact risk per cage revolution (`run.corner_risk`)
    corner_risk: float = float("nan")
    #: the lower 95 % bound of the 5th percentile of the film parameter Lambda over contact time
    film_parameter_low: float = float("nan")
    #: the upper 95 % bound of a revolution's largest flash temperature rise at the rib [K]
    flash_temperature_high: float = float("nan")
    #: the upper 95 % bound of the time-mean total flange friction power [W]
    friction_power_high: float = float("nan")
    #: the frozen-load gradient of the time-mean total flange friction power per unit of the
    #: scaled box [W] (`_gradients`: with a friction limit and the frozen-load estimator; None
    #: otherwise)
    friction_gradient: np.ndarray | None = None


@dataclasses.dataclass
class Evaluation:
    """The steady objective, its gradient and the constraints of one design (scaled u)."""

    objective: float  # combined over the envelope, in the statistic's unit (`PointRecord`)
    objective_ci: tuple  # (low, high): its 95 % interval (`combined_interval`)
    gradient: np.ndarray  # dJ/du (n,)
    gradient_stderr: np.ndarray  # (n,)
    per_point: list[PointRecord]
    static_margins: np.ndarray  # (4,) [m]
    dynamic_margin: float  # [m], worst operating point
    states: list  # per operating point: the settled states to continue from
    wall_time_s: float
    simulated_ms: float  # simulated time of every seed's settling, window and gradient samples
    #: the largest upper bound of the corner-contact risk per revolution over the points
    corner_risk: float = float("nan")
    #: per limit of `SteadySettings.limits`, its margin at the worst operating point in the
    #: limit's own unit (Lambda - limit; limit - K), +inf where no point measured it
    limit_margins: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    #: per limit, the gradient of its margin per unit of the scaled box (L, n): the friction
    #: power's from the frozen-load estimate at the worst point (`limit_jacobian`), the others 0
    limit_jacobian: np.ndarray | None = None


@dataclasses.dataclass(frozen=True)
class Previous:
    """What `evaluate_starts` reuses of a start's operating points left out."""

    per_point: list[PointRecord]
    states: list


def in_shared_pool(function):
    """Run `function(problem, settings, ...)` with one pool of `settings.num_workers` processes
    for all its ensembles and gradients (`jaxbearing.run.shared_workers`): the workers import
    JAX and load their programs once per search instead of twice per evaluation."""

    @functools.wraps(function)
    def wrapper(problem, settings=None, *args, **kwargs):
        settings = SteadySettings() if settings is None else settings
        with shared_workers(settings.num_workers):
            return function(problem, settings, *args, **kwargs)

    return wrapper


def operating_points(problem: DesignProblem) -> list:
    """The envelope's operating points, one `OperatingPoint` each."""
    return [
        jax.tree_util.tree_map(lambda a: a[k], problem.operating) for k in range(problem.num_operating_points)
    ]


def settled_metrics(
    problem: DesignProblem, settings: SteadySettings, points, designs, *, verification: bool = False, **kwargs
):
    """`steady_design_metrics_points` of (design, operating point index) pairs, one engine
    call, each point with its bearing (`DesignProblem.bearing_at`), with the problem's
    constraints and the search's (or, with `verification`, the verification's) settled-run
    settings (`SteadySettings.measurement`); `kwargs`: `first_seed`, `initial_states`."""
    ops = operating_points(problem)
    return steady_design_metrics_points(
        [problem.bearing_at(k) for k in points],
        [ops[k] for k in points],
        designs,
        settings.measurement(verification=verification),
        corner_margin=settings.corner_margin,
        flange_load=problem.flange_load,
        statistic=settings.statistic,
        **kwargs,
    )


def evaluate(
    problem: DesignProblem, settings: SteadySettings, u, states=None, *, gradient: bool = True
) -> Evaluation:
    """Settled objective and constraints of the scaled design u (one settled ensemble per
    operating point, continuing from `states` when given) and, with `gradient`, the estimated
    gradient (NaN without): `evaluate_starts` of one start."""
    (ev,) = evaluate_starts(problem, settings, [u], [states], gradient=gradient)
    return ev


def _checked_active(active, n: int, num_designs: int, previous) -> list[list[bool]]:
    active = (
        [[True] * n for _ in range(num_designs)] if active is None else [[bool(a) for a in r] for r in active]
    )
    for s, row in enumerate(active):
        if not all(row) and (previous is None or previous[s] is None):
            raise ValueError(f"start {s}: an operating point left out needs the start's previous evaluation")
    return active


def _gradients(settings: SteadySettings, cases, gradient: bool, num_variables: int) -> list[PointGradients]:
    """The gradient estimates of `cases` (bearing, op, design, states) by `settings.estimator`,
    one `PointGradients` per case. The friction power's is estimated where a friction limit is
    set (`SteadySettings.max_friction_power`), from the same trajectories as the objective's
    (`frozen_load_statistics`)."""
    if not gradient:
        return [PointGradients(SteadyGradient.missing(num_variables)) for _ in cases]
    if settings.estimator is Estimator.FROZEN:
        friction = settings.max_friction_power is not None
        found = frozen_load_statistics(
            cases,
            statistics=(settings.statistic, Statistic.FRICTION) if friction else (settings.statistic,),
            window=settings.gradient_window,
            rtol=settings.rtol,
            workers=settings.num_workers,
        )
        return [PointGradients(f[settings.statistic], f.get(Statistic.FRICTION)) for f in found]
    if num_variables != 3:
        raise UserInputError(
            f"estimator = {settings.estimator.value!r}: a profile search needs the frozen-load estimator ('frozen')"
        )
    return [
        PointGradients(
            steady_gradient(
                *case, window=settings.gradient_window, rtol=settings.rtol, workers=settings.num_workers
            )
        )
        for case in cases
    ]


def evaluate_starts(
    problem: DesignProblem,
    settings: SteadySettings,
    us,
    chains,
    *,
    gradient: bool = True,
    active=None,
    previous=None,
) -> list[Evaluation]:
    """`evaluate` of every scaled design of `us` (the starts of one iteration; `chains`: the
    continuation states of each, or None): every start's operating points' seeds are members
    of one call of the steady-running engine, and every trajectory of the frozen-load
    gradients of one call of `frozen_load_statistics` (on an accelerator, one vmapped program
    each). The wall time of each evaluation is the whole call's.

    The clearance (h = `clearance_step_for(...)` > 0, Delta_bf free): dJ/dDelta_bf is the paired
    common-random-number central difference of the settled objective per seed, (J_k(Delta_bf +
    h) - J_k(Delta_bf - h)) / 2h with the same seeds from the same states (`clearance_signal`);
    the two shifted designs of every start and operating point are further members of the same
    engine call.

    The envelope (`active`: per start, one flag per operating point, or None: all): a point
    not active is not simulated; its record is `previous`'s (the start's last measurements),
    the corner margin moved by the static limited-circle margin's change since it was measured,
    and it continues later from its old states (`next_active`)."""
    t0 = time.perf_counter()
    width = np.asarray(problem.bounds.upper - problem.bounds.lower)
    ops = operating_points(problem)
    n = len(ops)
    h = clearance_step_for(problem, settings)
    ci = problem.bounds.clearance_index
    shifts = (0.0, h, -h) if gradient and h > 0 and width[ci] > 0 else (0.0,)
    designs = [problem.design(jnp.asarray(u)) for u in us]
    chains = [None] * len(designs) if chains is None else list(chains)
    active = _checked_active(active, n, len(designs), previous)
    # every active (start, shift, operating point) is one member group of the engine call
    jobs = [
        (s, j, k) for s in range(len(designs)) for j in range(len(shifts)) for k in range(n) if active[s][k]
    ]
    listed = settled_metrics(
        problem,
        settings,
        [k for _, _, k in jobs],
        [_shift_clearance(designs[s], shifts[j], ci) for s, j, _ in jobs],
        initial_states=None
        if all(c is None for c in chains)
        else [None if chains[s] is None else chains[s][k] for s, _, k in jobs],
    )
    metrics = dict(zip(jobs, listed))
    keys = [(s, k) for (s, j, k) in jobs if j == 0]
    cases = [
        (designs[s].apply(problem.bearing_at(k)), ops[k], designs[s], metrics[(s, 0, k)].sample_states)
        for s, k in keys
    ]
    gradients = dict(zip(keys, _gradients(settings, cases, gradient, problem.num_variables)))
    if len(shifts) == 3:
        for s, k in keys:
            g = gradients[(s, k)]
            with_clearance = _with_clearance_difference(
                g.objective, metrics[(s, 1, k)], metrics[(s, 2, k)], h, ci
            )
            gradients[(s, k)] = dataclasses.replace(g, objective=with_clearance)
    wall = time.perf_counter() - t0
    evaluations = []
    for s, u in enumerate(us):
        measured = {k: (metrics[(s, 0, k)], gradients[(s, k)]) for k in range(n) if active[s][k]}
        ev = _evaluation(
            problem, settings, u, measured, None if previous is None else previous[s], wall, gradient
        )
        ev.simulated_ms += sum(
            simulated_ms(metrics[(s, j, k)]) for j in range(1, len(shifts)) for k in measured
        )
        evaluations.append(ev)
    return evaluations


def simulated_ms(m) -> float:
    """Simulated ms of one operating point's settled ensemble: every seed's settling and window."""
    return m.simulated_ms


def _shift_clearance(design, dh: float, index: int):
    """`design` with Delta_bf (at `index` of its array) moved by dh."""
    if dh == 0.0:
        return design
    x = np.array(design.as_array(), dtype=float)
    x[index] += dh
    return variables_from_array(jnp.asarray(x))


def clearance_signal(plus, minus, h: float) -> tuple[float, float]:
    """The search's dJ/dDelta_bf and its standard error from the per-seed objectives at
    Delta_bf +- h (`paired_central_difference`): the difference where it is significant at
    5 % (|d| > t_{0.975, n-1} SE, two-sided), else 0. Adam scales every component's step to
    about the learning rate whatever its size, so an insignificant difference would move
    Delta_bf a full step in the direction of its noise; gated, Delta_bf moves where the
    difference shows a direction. (Ungated, the first evaluation of the default search at
    2 mrad, from the skid start at 90 mm / 1.33 deg, gave -1.3e12 Pa m/s per m, and Delta_bf
    took a full step up, 0.016 mm; the next evaluation's difference was positive.)"""
    d, se, n = paired_central_difference(plus, minus, h)
    if n < 2 or not np.isfinite(se) or abs(d) <= stats.t.ppf(0.975, n - 1) * se:
        return 0.0, se
    return d, se


def _with_clearance_difference(g: SteadyGradient, plus, minus, h: float, index: int) -> SteadyGradient:
    """`g` with its Delta_bf component the paired common-random-number central difference of
    the objective per seed where significant (`clearance_signal`) and its standard error."""
    grad, se = np.array(g.gradient, dtype=float), np.array(g.gradient_stderr, dtype=float)
    grad[index], se[index] = clearance_signal(plus.objective_per_seed, minus.objective_per_seed, h)
    return dataclasses.replace(g, gradient=grad, gradient_stderr=se)


def corner_margin_of(settings: SteadySettings, m) -> float:
    """The dynamic corner margin [m] of one operating point's metrics `m` that the search
    constrains (`SteadySettings.corner_constraint`): rho_lim - `corner_margin` minus the normal
    tolerance bound of the per-revolution largest contact radius at `corner_risk_level`
    ("risk"; the prediction bound where fewer than three revolutions touched a flange), the
    prediction bound ("prediction") or its mean ("mean")."""
    if settings.corner_constraint is CornerConstraint.MEAN:
        return float(m.corner_margin.value)
    if settings.corner_constraint is CornerConstraint.RISK:
        bound = tolerance_bound(m.contact_radius_maxima, settings.corner_risk_level, CORNER_RISK_CONFIDENCE)
        if np.isfinite(bound):
            return float(m.limited_circle_radius_m - settings.corner_margin - bound)
    return float(m.corner_margin_bound)


def _risk_upper(m) -> float:
    """The upper 95 % bound of the corner-contact risk per revolution (NaN: not estimated)."""
    risk = None if m.statistics is None else m.statistics.corner_risk
    return float("nan") if risk is None else float(risk.upper)


def _limit_readouts(m) -> tuple[float, float, float]:
    """(lower 95 % bound of Lambda's 5th percentile over contact time, upper 95 % bound of a
    revolution's largest flash temperature rise [K], upper 95 % bound of the time-mean total
    flange friction power [W]) of one point's metrics `m` (NaN: not measured, e.g. no flange
    contact)."""
    st = m.statistics
    if st is None:
        return float("nan"), float("nan"), float("nan")
    return (
        float(st.film_parameter.p05.ci95_low),
        float(st.flange_flash_temperature_K.max.ci95_high),
        float(st.flange_friction_power_W.total.ci95_high),
    )


def limit_margins(settings: SteadySettings, per: list[PointRecord]) -> np.ndarray:
    """The margin of every limit of `settings.limits` at the worst operating point of `per`, in
    the limit's unit: min_k Lambda_k^lo - Lambda_min, T_max - max_k T_k^hi and
    P_max - max_k P_k^hi; a point that did not measure it (no flange contact, no film or heat
    to limit) is left out, +inf if none did."""
    out = []
    for name, limit in settings.limits:
        if name == "film_parameter":
            values = [p.film_parameter_low - limit for p in per]
        elif name == "flash_temperature":
            values = [limit - p.flash_temperature_high for p in per]
        else:
            values = [limit - p.friction_power_high for p in per]
        known = [v for v in values if np.isfinite(v)]
        out.append(min(known) if known else np.inf)
    return np.asarray(out, dtype=float)


def limit_jacobian(settings: SteadySettings, per: list[PointRecord]) -> np.ndarray:
    """The gradient (L, n) per unit of the scaled box of every limit's margin of `limit_margins`:
    for the friction power, -dP/du of the frozen-load estimate at the operating point of the
    smallest margin (the upper bound moves with the mean); 0 for the film parameter and the
    flash temperature (no estimator of their own) and where no estimate is known."""
    n = len(per[0].gradient) if per else 0
    rows = []
    for name, limit in settings.limits:
        row = np.zeros(n)
        if name == "friction_power":
            known = [p for p in per if np.isfinite(p.friction_power_high) and p.friction_gradient is not None]
            if known:
                worst = min(known, key=lambda p: limit - p.friction_power_high)
                if np.all(np.isfinite(worst.friction_gradient)):
                    row = -np.asarray(worst.friction_gradient, dtype=float)
        rows.append(row)
    return np.asarray(rows, dtype=float).reshape(len(rows), n)


def _measured_record(settings: SteadySettings, u, m, gradients: PointGradients, width) -> PointRecord:
    """The record of one simulated operating point from its metrics `m` and gradient estimates
    (`_gradients`)."""
    g, friction_g = gradients.objective, gradients.friction
    j = m.objective
    scale = settings.statistic.shown[0]  # GPa m/s, or W for the friction power
    margin = corner_margin_of(settings, m)
    film, flash, friction = _limit_readouts(m)
    return PointRecord(
        value=float(j.value) / scale,
        ci=(float(j.ci95_low) / scale, float(j.ci95_high) / scale),
        gradient=g.gradient * width / scale,
        gradient_stderr=g.gradient_stderr * width / scale,
        estimator_value=g.value / scale,
        corner_margin=margin,
        measured_corner_margin=margin,
        measured_at=np.asarray(u, dtype=float),
        corner_contact_share=float(m.corner_contact_share.value),
        settled=m.settled,
        simulated=True,
        corner_risk=_risk_upper(m),
        film_parameter_low=film,
        flash_temperature_high=flash,
        friction_power_high=friction,
        friction_gradient=None if friction_g is None else friction_g.gradient * width,
    )


def _reused_record(problem: DesignProblem, old: PointRecord, here) -> PointRecord:
    """A point left out: its previous record, the corner margin moved by the static
    limited-circle margin's change since it was measured."""
    lc = MARGIN_NAMES.index("limited_circle")
    then = np.asarray(problem.margins(jnp.asarray(old.measured_at)))
    moved = old.measured_corner_margin + float(here[lc] - then[lc])
    return dataclasses.replace(old, corner_margin=moved, simulated=False)


def _evaluation(problem, settings, u, measured, previous, wall, gradient: bool) -> Evaluation:
    """One start's `Evaluation` from the metrics and gradient estimates of its simulated
    operating points (`measured`: {point: (metrics, `PointGradients`)}) and, for the others,
    `previous` (`evaluate_starts`)."""
    width = np.asarray(problem.bounds.upper - problem.bounds.lower)
    per, new_states, simulated = [], [], 0.0
    here = np.asarray(problem.margins(jnp.asarray(u)))
    for k in range(problem.num_operating_points):
        if k not in measured:
            per.append(_reused_record(problem, previous.per_point[k], here))
            new_states.append(previous.states[k])
            continue
        m, g = measured[k]
        per.append(_measured_record(settings, u, m, g, width))
        new_states.append(m.final_states)
        simulated += simulated_ms(m)
        simulated += (len(m.sample_states) * settings.gradient_window * 1e3) if gradient else 0.0
    values = jnp.asarray([p.value for p in per])
    val, vjp = jax.vjp(problem.combine, values)
    (weights,) = vjp(jnp.ones(()))
    weights = np.asarray(weights)
    grad = sum(w * p.gradient for w, p in zip(weights, per))
    grad_se = np.sqrt(sum((w * p.gradient_stderr) ** 2 for w, p in zip(weights, per)))
    return Evaluation(
        objective=float(val),
        objective_ci=combined_interval(float(val), weights, per),
        gradient=np.where(width > 0, grad, 0.0),
        gradient_stderr=grad_se,
        per_point=per,
        static_margins=here,
        dynamic_margin=float(min(p.corner_margin for p in per)),
        states=new_states,
        wall_time_s=wall,
        simulated_ms=simulated,
        corner_risk=worst_risk([p.corner_risk for p in per]),
        limit_margins=limit_margins(settings, per),
        limit_jacobian=limit_jacobian(settings, per),
    )


def combined_interval(value: float, weights, per: list[PointRecord]) -> tuple[float, float]:
    """The 95 % interval of the combined objective J = combine(J_1 .. J_K) by the delta method:
    J -+ sqrt(sum_k (w_k h_k)^2), w_k = dJ/dJ_k and h_k the lower or upper half-width of point
    k's interval (the points' ensembles independent). With one dominant point of the smooth max
    it is that point's interval moved to J (the smooth max lies T ln K below the largest J_k
    when the others weigh nothing)."""
    lo = np.sqrt(sum((w * (p.value - p.ci[0])) ** 2 for w, p in zip(weights, per)))
    hi = np.sqrt(sum((w * (p.ci[1] - p.value)) ** 2 for w, p in zip(weights, per)))
    return (float(value - lo), float(value + hi))


def worst_risk(uppers) -> float:
    """The largest of the corner-risk bounds `uppers`, the unknown (NaN) left out; NaN if none
    is known."""
    known = [float(v) for v in uppers if np.isfinite(v)]
    return max(known) if known else float("nan")
