"""Design search on steady running: the default objective of `optimise run`.

Objective. For a design x = (R_end, theta_f, Delta_bf), at every operating point k of the
envelope, the smooth mean flange PV over contact time of settled running (`jaxbearing.design.
steady_design_metrics`: skid start or continuation, settling, a window of `window_revs` cage
revolutions, `seeds` seeded scatters; Student-t CI over the seeds), combined over the envelope
as in `DesignProblem.combine` (smooth max or weighted mean), in GPa m/s.

Gradient (`estimator`). "frozen" (default): the frozen-load estimate of
`jaxbearing.design.frozen_load_gradient`: from the settled states the objective's runs passed
through (every seed's state at the start of its window and at its end: 2 x seeds samples of the
invariant measure), plain trajectories of `gradient_window` seconds; at every saved state the
flange PV is differentiated in the design at the loads the dynamics gave, through the ratio
estimator. "window": the short-window forward-mode sensitivities of
`jaxbearing.design.steady_gradient` over `gradient_window` seconds. Both are measured against
common-random-number central differences in docs/validation.md and docs/how-to/design-search.md.

Constraints. The four static design-zone margins of `DesignProblem.constraints` and the
dynamic corner-contact margin m_dyn = rho_lim - max(contact radius) - `corner_margin`, max
being the largest contact radius of a cage revolution (the worst operating point), which has no
derivative of its own (an extreme of a dynamic run). It
is modelled as the measured value plus the change of the static limited-circle margin
rho_lim - rho_c (the aligned contact radius): m_dyn(u') ~ m_dyn(u) + m_lc(u') - m_lc(u), i.e.
the skew excursion max - rho_c is held at its measured value over one step; its gradient is the
static margin's. All five enter the same augmented Lagrangian as `_search` (projected Adam step
in the unit box, multiplier update).

Continuation. Every start carries the settled states of its last design, per operating point;
the next iterate (a step of a few per cent of the box) starts from them instead of from the skid
start, and settles by the verdict (at least four revolutions; a fixed shorter settle is biased,
docs/model.md 17). `steady_search(initial_states=...)` gives a start's first evaluation such
states too (e.g. the `final_states` of a settled ensemble of the start design that the caller
already ran, as notebook 05 does): it then continues from them instead of running its own skid
start.

The envelope's active set (`next_active`, smooth max only): an operating point whose weight in
the objective stays below `skip_weight` even at its interval's bounds is not simulated in the
next iteration (its last values are reused), unless its corner margin could bind within a step
or it was last simulated `recheck_every` iterations ago.

Resume. After every iteration the whole search state (iterates, optimiser and multiplier
states, continuation states, history, best design) is written atomically to
DIR/checkpoint.npz (data only: `jaxbearing.io.save_tree`, checked for type and shape against a
fresh state when read back; a `checkpoint.pkl` of an older version is refused, never
unpickled); a killed run started again with the same settings continues from its last
finished iteration and reaches the same result (the runs are deterministic per seed and state).

Verification. The best feasible design and the start design are re-simulated from the skid
start with `verify_seeds` seeds numbered from `verify_first_seed` (never used by the search:
it uses 0 .. seeds - 1), window `verify_window_revs`; `result.json` holds both under
`verification` with mean and p95 PV over contact time and the corner-contact share as
value/ci95_low/ci95_high, and whether the CIs of the mean PV are disjoint.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import pathlib
import time
from collections.abc import Callable

import jax
import jax.numpy as jnp
import numpy as np
import optax
from scipy import stats

from jaxbearing import UserInputError
from jaxbearing.design import (
    CORNER_MARGIN,
    STATISTICS,
    SteadyGradient,
    frozen_load_gradients,
    paired_central_difference,
    steady_design_metrics_points,
    steady_gradient,
)
from jaxbearing.flange import MARGIN_NAMES, DesignVariables
from jaxbearing.io import TreeFileError, check_like, load_tree, require, save_tree
from jaxbearing.run import available_cpus, revolutions_needed, shared_workers

from ._problem import MARGIN_SCALE, PV_SCALE, DesignProblem, any_feasible
from ._search import _Hyper, start_points

#: names of the five constraints of the steady search (static zone margins, then dynamic)
CONSTRAINT_NAMES = (*MARGIN_NAMES, "dynamic_corner")
CHECKPOINT = "checkpoint.npz"
#: the name of the pickled checkpoints of older versions: refused, never loaded
LEGACY_CHECKPOINT = "checkpoint.pkl"
#: version of the measured objective and margins, part of a checkpoint's fingerprint: a
#: checkpoint of an older definition (2: the dynamic corner margin on the largest contact
#: radius instead of the p99; 3: the envelope's active set, the corner constraint's prediction
#: bound; 4: the clearance difference only where significant) is refused, not resumed
MEASUREMENT_VERSION = 4
#: gradient estimators (module docstring)
ESTIMATORS = ("frozen", "window")
#: a point left out of the envelope's active set still runs while its corner margin is below
#: this [m] (`next_active`): one step of the default search moved the limited-circle margin by
#: up to 0.25 mm and the dynamic corner margin by up to 0.28 mm (results/optimise_steady_default_run.json),
#: so a margin above it does not bind within a step. Without it, margins alike at every speed
#: kept every point running (benchmarks/results/bench_envelope_active_set.json)
CORNER_WATCH = 0.3e-3
#: the dynamic corner constraint's statistic (`SteadySettings.corner_constraint`)
CORNER_CONSTRAINTS = ("prediction", "mean")


#: `clearance_step="auto"` gives the search a signal for Delta_bf where an operating point is
#: misaligned by more than this [rad]: the clearance study (`CLEARANCE_EFFECT`) found dJ/dDelta_bf
#: clearly significant at 2 mrad (+2.5 % of J per 10 um at 100 mm / 1.4 deg) and bounded near 0
#: at 1 mrad at both designs (within -0.4 .. +0.4 % of J per 10 um)
CLEARANCE_MISALIGNMENT = 1.0e-3
#: ... with this half-step [m] (the study's h)
CLEARANCE_STEP = 0.01e-3


def clearance_step_for(problem: DesignProblem, settings: SteadySettings) -> float:
    """The half-step h [m] of the search's Delta_bf difference: `settings.clearance_step`, or
    with "auto", `CLEARANCE_STEP` where any operating point of `problem` is misaligned by more
    than `CLEARANCE_MISALIGNMENT` and 0 (off: three times the members for a slope the study
    bounds near 0) elsewhere."""
    if not isinstance(settings.clearance_step, str):
        return float(settings.clearance_step)
    tilt = np.max(np.abs(np.asarray(problem.operating.misalignment, dtype=float)))
    return CLEARANCE_STEP if tilt > CLEARANCE_MISALIGNMENT * (1 + 1e-9) else 0.0


@dataclasses.dataclass(frozen=True)
class SteadySettings:
    """How the steady objective is measured (module docstring). Times in seconds."""

    seeds: int = 4
    window_revs: int = 2
    settle: object = "auto"
    gradient_window: float = 1.0e-3
    estimator: str = "frozen"
    corner_margin: float = CORNER_MARGIN
    rtol: float = 1e-3
    workers: int = 0  # 0: one per CPU
    verify_seeds: int = 4
    verify_first_seed: int = 1000
    verify_window_revs: int = 4
    #: the statistic of flange PV minimised: "mean" (over contact time), "peak" (its p-mean) or
    #: "tail" (the mean of its worst 5 %, `jaxbearing.design.STATISTICS`)
    statistic: str = "mean"
    #: half-step of the common-random-number central difference in Delta_bf [m] (0: off), or
    #: "auto": `CLEARANCE_STEP` where the envelope is misaligned by more than
    #: `CLEARANCE_MISALIGNMENT`, else off (`clearance_step_for`); the frozen-load estimator
    #: cannot see the clearance (`evaluate_starts`)
    clearance_step: float | str = "auto"
    #: the dynamic corner constraint: "prediction" (the margin on the upper 95 % prediction bound
    #: of one revolution's largest contact radius: it holds for a further revolution with 95 %
    #: probability) or "mean" (on its expectation per revolution: holds on average)
    corner_constraint: str = "prediction"
    #: the corner-contact risk per cage revolution the verification must bound at every
    #: operating point (its upper 95 % bound, `run.corner_risk`), else the design is reported
    #: unverified in the tail (`tail_verification`)
    corner_risk_level: float = 1e-3
    #: the envelope's active set (`next_active`): an operating point whose weight in the smooth
    #: max stays below this is not simulated (0: every point, every iteration) ...
    skip_weight: float = 1e-3
    #: ... for at most this many iterations in a row
    recheck_every: int = 3

    def __post_init__(self):
        """One-line errors naming the setting, before anything runs."""
        for name in ("seeds", "verify_seeds"):
            require(name, getattr(self, name), lambda v: (v >= 1) & (v == np.round(v)), "an integer >= 1")
        if self.corner_constraint not in CORNER_CONSTRAINTS:
            raise UserInputError(
                f"corner_constraint = {self.corner_constraint!r}: must be one of {', '.join(CORNER_CONSTRAINTS)}"
            )
        require("skip_weight", self.skip_weight, lambda v: (v >= 0) & (v < 1), "in [0, 1)")
        require(
            "corner_risk_level",
            self.corner_risk_level,
            lambda v: (v > 0) & (v < 1),
            "in (0, 1) per revolution",
        )
        require(
            "recheck_every", self.recheck_every, lambda v: (v >= 1) & (v == np.round(v)), "an integer >= 1"
        )
        for name in ("window_revs", "verify_window_revs"):  # batch means need two batches
            require(name, getattr(self, name), lambda v: (v >= 2) & (v == np.round(v)), "an integer >= 2")
        require(
            "verify_first_seed",
            self.verify_first_seed,
            lambda v: (v >= 0) & (v == np.round(v)),
            "an integer >= 0",
        )
        if self.verify_first_seed < self.seeds:
            raise UserInputError(
                f"verify_first_seed = {self.verify_first_seed}: must be >= seeds = {self.seeds} "
                "(verification uses seeds the search never saw)"
            )
        if self.statistic not in STATISTICS:
            raise UserInputError(
                f"statistic = {self.statistic!r}: must be one of {', '.join(map(repr, STATISTICS))}"
            )
        if self.statistic != "mean" and self.estimator != "frozen":
            raise UserInputError(
                f"statistic = {self.statistic!r} needs estimator = 'frozen' (not {self.estimator!r})"
            )
        if self.estimator not in ESTIMATORS:
            raise UserInputError(f"estimator = {self.estimator!r}: must be one of {', '.join(ESTIMATORS)}")
        require("gradient_window", self.gradient_window, lambda v: np.isfinite(v) & (v > 0), "> 0 s")
        require("corner_margin", self.corner_margin, lambda v: np.isfinite(v) & (v >= 0), ">= 0 m")
        require("rtol", self.rtol, lambda v: np.isfinite(v) & (v > 0) & (v < 1), "in (0, 1)")
        require("workers", self.workers, lambda v: (v >= 0) & (v == np.round(v)), "an integer >= 0")
        if self.clearance_step != "auto":
            if isinstance(self.clearance_step, str):
                raise UserInputError(
                    f"clearance_step = {self.clearance_step!r}: must be 'auto' or a number in [0, 1e-3) m"
                )
            require(
                "clearance_step",
                self.clearance_step,
                lambda v: np.isfinite(v) & (v >= 0) & (v < 1e-3),
                "'auto' or in [0, 1e-3) m",
            )

    @property
    def num_workers(self) -> int:
        """`workers`, or 0: one per CPU; on an accelerator one (the members are vmapped there,
        and worker processes would each claim the device)."""
        if int(self.workers):
            return int(self.workers)
        return available_cpus() if jax.default_backend() == "cpu" else 1


def _in_shared_pool(function):
    """Run `function(problem, settings, ...)` with one pool of `settings.num_workers` processes
    for all its ensembles and gradients (`jaxbearing.run.shared_workers`): the workers import
    JAX and load their programs once per search instead of twice per evaluation."""

    @functools.wraps(function)
    def wrapper(problem, settings=None, *args, **kwargs):
        settings = SteadySettings() if settings is None else settings
        with shared_workers(settings.num_workers):
            return function(problem, settings, *args, **kwargs)

    return wrapper


def _operating_point(problem: DesignProblem, k: int):
    return jax.tree_util.tree_map(lambda a: a[k], problem.operating)


@dataclasses.dataclass
class Evaluation:
    """The steady objective, its gradient and the constraints of one design (scaled u)."""

    objective: float  # combined over the envelope [GPa m/s]
    objective_ci: tuple  # (low, high): its 95 % interval (`_combined_interval`) [GPa m/s]
    gradient: np.ndarray  # dJ/du (3,)
    gradient_stderr: np.ndarray  # (3,)
    per_point: list  # per operating point: value, ci, gradient, corner margin [m], share
    static_margins: np.ndarray  # (4,) [m]
    dynamic_margin: float  # [m], worst operating point
    states: list  # per operating point: the settled states to continue from
    wall_time_s: float
    simulated_ms: float  # simulated time of every seed's settling, window and gradient samples


def evaluate(
    problem: DesignProblem, settings: SteadySettings, u, states=None, *, gradient: bool = True
) -> Evaluation:
    """Settled objective and constraints of the scaled design u (one settled ensemble per
    operating point, continuing from `states` when given) and, with `gradient`, the estimated
    gradient (NaN without): `evaluate_starts` of one start."""
    (ev,) = evaluate_starts(problem, settings, [u], [states], gradient=gradient)
    return ev


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
    gradients of one call of `frozen_load_gradients` (on an accelerator, one vmapped program
    each). The wall time of each evaluation is the whole call's.

    The clearance (`settings.clearance_step` h > 0, Delta_bf free): the frozen-load estimator
    cannot see Delta_bf (it moves the flange in its own plane at a fixed load), so dJ/dDelta_bf
    is the common-random-number central difference of the settled objective, per seed
    (J_k(Delta_bf + h) - J_k(Delta_bf - h)) / 2h with the same seeds from the same states,
    averaged over the seeds with the paired standard error; the two shifted designs of every
    start and operating point are further members of the same engine call.

    The envelope (`active`: per start, one flag per operating point, or None: all): a point
    not active is not simulated; its value, interval, gradient and corner margin are those of
    `previous` (the start's last `Evaluation`), the margin moved by the static limited-circle
    margin's change since it was measured, and it continues later from its old states
    (`next_active`)."""
    t0 = time.perf_counter()
    width = np.asarray(problem.bounds.upper - problem.bounds.lower)
    ops = [_operating_point(problem, k) for k in range(problem.num_operating_points)]
    n = len(ops)
    h = clearance_step_for(problem, settings)
    shifts = (0.0, h, -h) if gradient and h > 0 and width[2] > 0 else (0.0,)
    designs = [problem.design(jnp.asarray(u)) for u in us]
    chains = [None] * len(designs) if chains is None else list(chains)
    active = [[True] * n for _ in designs] if active is None else [[bool(a) for a in row] for row in active]
    for s, row in enumerate(active):
        if not all(row) and (previous is None or previous[s] is None):
            raise ValueError(f"start {s}: an operating point left out needs the start's previous evaluation")
    # every active (start, shift, operating point) is one member group of the engine call
    jobs = [
        (s, j, k) for s in range(len(designs)) for j in range(len(shifts)) for k in range(n) if active[s][k]
    ]
    listed = _settled_metrics(
        problem,
        settings,
        [ops[k] for _, _, k in jobs],
        [_shift_clearance(designs[s], shifts[j]) for s, j, _ in jobs],
        seeds=settings.seeds,
        window_revs=settings.window_revs,
        initial_states=None
        if all(c is None for c in chains)
        else [None if chains[s] is None else chains[s][k] for s, _, k in jobs],
    )
    metrics = dict(zip(jobs, listed))
    keys = [(s, k) for (s, j, k) in jobs if j == 0]
    cases = [
        (designs[s].apply(problem.bearing), ops[k], designs[s], metrics[(s, 0, k)].sample_states)
        for s, k in keys
    ]
    if not gradient:
        found = [SteadyGradient.missing() for _ in cases]
    elif settings.estimator == "frozen":
        found = frozen_load_gradients(
            cases,
            window=settings.gradient_window,
            rtol=settings.rtol,
            workers=settings.num_workers,
            statistic=settings.statistic,
        )
    else:
        found = [
            steady_gradient(
                *case, window=settings.gradient_window, rtol=settings.rtol, workers=settings.num_workers
            )
            for case in cases
        ]
    gradients = dict(zip(keys, found))
    if len(shifts) == 3:
        for s, k in keys:
            gradients[(s, k)] = _with_clearance_difference(
                gradients[(s, k)], metrics[(s, 1, k)], metrics[(s, 2, k)], h
            )
    wall = time.perf_counter() - t0
    evaluations = []
    for s, u in enumerate(us):
        measured = {k: (metrics[(s, 0, k)], gradients[(s, k)]) for k in range(n) if active[s][k]}
        ev = _evaluation(
            problem, settings, u, measured, None if previous is None else previous[s], width, wall, gradient
        )
        ev.simulated_ms += sum(
            _simulated_ms(metrics[(s, j, k)]) for j in range(1, len(shifts)) for k in measured
        )
        evaluations.append(ev)
    return evaluations


def _simulated_ms(m) -> float:
    """Simulated ms of one operating point's settled ensemble: every seed's settling and window."""
    return sum(r["settle_time_ms"] for r in m.summary["per_seed"]) + len(m.seeds) * m.summary.get(
        "window_ms", 0.0
    )


def _settled_metrics(problem: DesignProblem, settings: SteadySettings, ops, designs, **kwargs):
    """`steady_design_metrics_points` of (design, operating point) pairs, one engine call, with
    the problem's and the settings' measurement options (`kwargs`: seeds, window, ...)."""
    return steady_design_metrics_points(
        problem.bearing,
        ops,
        designs,
        settle=settings.settle,
        corner_margin=settings.corner_margin,
        flange_load=problem.flange_load,
        workers=settings.num_workers,
        rtol=settings.rtol,
        statistic=settings.statistic,
        **kwargs,
    )


def _shift_clearance(design: DesignVariables, dh: float) -> DesignVariables:
    if dh == 0.0:
        return design
    x = np.asarray(design.as_array(), dtype=float)
    return DesignVariables.from_array(jnp.asarray([x[0], x[1], x[2] + dh]))


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


def _with_clearance_difference(g: SteadyGradient, plus, minus, h: float) -> SteadyGradient:
    """`g` with its Delta_bf component the paired common-random-number central difference of
    the objective per seed where significant (`clearance_signal`) and its standard error."""
    grad, se = np.array(g.gradient, dtype=float), np.array(g.gradient_stderr, dtype=float)
    grad[2], se[2] = clearance_signal(plus.objective_per_seed, minus.objective_per_seed, h)
    return dataclasses.replace(g, gradient=grad, gradient_stderr=se)


def _evaluation(problem, settings, u, measured, previous, width, wall, gradient: bool) -> Evaluation:
    """One start's `Evaluation` from the metrics and gradient estimates of its simulated
    operating points (`measured`: {point: (metrics, gradient)}) and, for the others, `previous`
    (`evaluate_starts`)."""
    per, new_states, simulated = [], [], 0.0
    lc = MARGIN_NAMES.index("limited_circle")
    here = np.asarray(problem.margins(jnp.asarray(u)))
    for k in range(problem.num_operating_points):
        if k not in measured:  # left out: the previous values, the margin moved statically
            old = dict(previous.per_point[k])
            then = np.asarray(problem.margins(jnp.asarray(old["measured_at"])))
            old["corner_margin"] = old["measured_corner_margin"] + float(here[lc] - then[lc])
            old["simulated"] = False
            per.append(old)
            new_states.append(previous.states[k])
            continue
        m, g = measured[k]
        j = m.objective
        margin = (
            _num(m.corner_margin_bound)
            if settings.corner_constraint == "prediction"
            else _num(m.corner_margin["value"])
        )
        per.append(
            dict(
                value=_num(j["value"]) / PV_SCALE,
                ci=(_num(j["ci95_low"]) / PV_SCALE, _num(j["ci95_high"]) / PV_SCALE),
                gradient=g.gradient * width / PV_SCALE,
                gradient_stderr=g.gradient_stderr * width / PV_SCALE,
                estimator_value=g.value / PV_SCALE,
                corner_margin=margin,
                measured_corner_margin=margin,
                measured_at=np.asarray(u, dtype=float),
                corner_contact_share=_num(m.corner_contact_share["value"]),
                mean_pv=m.mean_pv,
                settled=m.settled,
                simulated=True,
            )
        )
        new_states.append(m.final_states)
        simulated += _simulated_ms(m)
        simulated += (len(m.sample_states) * settings.gradient_window * 1e3) if gradient else 0.0
    values = jnp.asarray([p["value"] for p in per])
    val, vjp = jax.vjp(problem.combine, values)
    (weights,) = vjp(jnp.ones(()))
    weights = np.asarray(weights)
    grad = sum(w * p["gradient"] for w, p in zip(weights, per))
    grad_se = np.sqrt(sum((w * p["gradient_stderr"]) ** 2 for w, p in zip(weights, per)))
    return Evaluation(
        objective=float(val),
        objective_ci=_combined_interval(float(val), weights, per),
        gradient=np.where(width > 0, grad, 0.0),
        gradient_stderr=grad_se,
        per_point=per,
        static_margins=here,
        dynamic_margin=float(min(p["corner_margin"] for p in per)),
        states=new_states,
        wall_time_s=wall,
        simulated_ms=simulated,
    )


def next_active(problem: DesignProblem, settings: SteadySettings, ev: Evaluation, since) -> list[bool]:
    """Which operating points the next evaluation of a start simulates (the envelope's active
    set), from its last evaluation `ev` and `since[k]`, the iterations since point k was last
    simulated. With the smooth max (weights exp(J_k / T), docs/model.md 17) a point whose upper
    95 % bound J_k^hi is so far below the worst point's lower bound J_w^lo that its weight
    w_k exp((J_k^hi - J_w^lo) / T) stays below `settings.skip_weight` adds less than that share to
    the objective and its gradient: it is left out, unless its dynamic corner margin is within
    `CORNER_WATCH` of zero and within `corner_margin` of the smallest (the constraint may bind
    there within a step), or it was last simulated `settings.recheck_every` iterations ago.
    Every point is simulated with the weighted mean, or with `skip_weight` 0."""
    n = problem.num_operating_points
    if problem.aggregate != "max" or settings.skip_weight <= 0 or n == 1:
        return [True] * n
    w = np.asarray(problem.weights, float) / float(np.sum(problem.weights))
    hi = np.array([p["ci"][1] for p in ev.per_point], float)
    lo = np.array([p["ci"][0] for p in ev.per_point], float)
    values = np.array([p["value"] for p in ev.per_point], float)
    margins = np.array([p["corner_margin"] for p in ev.per_point], float)
    if not (np.all(np.isfinite(hi)) and np.all(np.isfinite(lo)) and np.all(np.isfinite(margins))):
        return [True] * n
    worst = int(np.argmax(values))
    bound = w * np.exp(np.minimum((hi - lo[worst]) / problem.temperature, 0.0))
    near_corner = (margins <= margins.min() + settings.corner_margin) & (margins < CORNER_WATCH)
    due = np.asarray(since) + 1 >= settings.recheck_every
    keep = (bound >= settings.skip_weight) | near_corner | due
    keep[worst] = True
    return [bool(v) for v in keep]


def _combined_interval(value: float, weights, per: list) -> tuple[float, float]:
    """The 95 % interval of the combined objective J = combine(J_1 .. J_K) by the delta method:
    J -+ sqrt(sum_k (w_k h_k)^2), w_k = dJ/dJ_k and h_k the lower or upper half-width of point
    k's interval (the points' ensembles independent). With one dominant point of the smooth max
    it is that point's interval moved to J (the smooth max lies T ln K below the largest J_k
    when the others weigh nothing)."""
    lo = np.sqrt(sum((w * (p["value"] - p["ci"][0])) ** 2 for w, p in zip(weights, per)))
    hi = np.sqrt(sum((w * (p["ci"][1] - p["value"])) ** 2 for w, p in zip(weights, per)))
    return (float(value - lo), float(value + hi))


def _num(v) -> float:
    return float("nan") if v is None else float(v)


def _constraints(problem: DesignProblem, u, dynamic_margin: float, u_measured):
    """Scaled, tightened constraints (5,) and their Jacobian (5, 3): the static ones exactly,
    the dynamic corner margin by its measured value plus the static limited-circle margin's
    change from `u_measured` (module docstring)."""

    def c(v):
        static = problem.margins(v)
        lc = static[MARGIN_NAMES.index("limited_circle")]
        lc0 = problem.margins(u_measured)[MARGIN_NAMES.index("limited_circle")]
        dyn = dynamic_margin + lc - lc0
        return jnp.concatenate([static, dyn[None]]) / MARGIN_SCALE - problem.tighten

    u = jnp.asarray(u)
    return np.asarray(c(u)), np.asarray(jax.jacfwd(c)(u))


@dataclasses.dataclass
class SteadySearchResult:
    """Outcome of `steady_search` (designs in SI units; objective in GPa m/s)."""

    status: str  # "ok", "no_feasible_design_in_bounds", "no_feasible_iterate"
    feasible: bool
    design: np.ndarray | None
    objective: float
    objective_ci: tuple | None
    start_design: np.ndarray
    history: dict  # per iteration and start: x, objective, ci, gradient, margins (5)
    num_iterations: int
    num_evaluations: int  # settled ensembles (one per start, iteration and operating point)
    wall_time_s: float
    resumed_from: int  # iteration the run resumed after (-1: fresh)
    best_start: int = -1
    best_iteration: int = -1
    verification: dict | None = None


def _fingerprint(problem: DesignProblem, settings: SteadySettings, hyper: _Hyper, starts) -> str:
    """A hash of everything that decides the search's result (for resuming): the bearing and
    operating points, bounds, constraints, envelope, measurement settings, step sizes, starts."""
    leaves = [
        np.asarray(v).tobytes() for v in jax.tree_util.tree_leaves((problem.bearing, problem.operating))
    ]
    text = repr(
        (
            MEASUREMENT_VERSION,
            problem.bounds,
            problem.aggregate,
            problem.temperature,
            problem.tighten,
            problem.flange_load,
            problem.min_clearance,
            np.asarray(problem.weights).tolist(),
            dataclasses.replace(settings, workers=0),  # the processes do not change the result
            hyper,
            np.asarray(starts).tolist(),
        )
    )
    h = hashlib.sha256(text.encode())
    for leaf in leaves:
        h.update(leaf)
    return h.hexdigest()


@_in_shared_pool
def steady_search(
    problem: DesignProblem,
    settings: SteadySettings = SteadySettings(),
    *,
    num_starts: int = 2,
    num_iterations: int = 6,
    learning_rate: float = 0.08,
    rho: float = 10.0,
    starts: np.ndarray | None = None,
    directory: str | pathlib.Path | None = None,
    callback: Callable[[int, dict], None] | None = None,
    verify: bool = True,
    initial_states: list | None = None,
) -> SteadySearchResult:
    """Minimise the steady objective inside the static and dynamic margins (module docstring)
    from `num_starts` starts (the bearing's own design, then Halton points), `num_iterations`
    projected Adam steps each. With `directory`, the state is checkpointed there after every
    iteration and a matching checkpoint is resumed. `callback(iteration, info)` reports
    progress after every iteration. `initial_states`: None, or per start None or the states its
    first evaluation continues from, per operating point one state per seed (e.g.
    `[[metrics.final_states]]`: a settled ensemble of the start design with `settings.seeds`
    seeds; module docstring, Continuation); a resumed checkpoint's own states win."""
    t_start = time.perf_counter()
    for name, v in (("starts", num_starts), ("iterations", num_iterations)):
        if int(v) < 1:
            raise UserInputError(f"{name} = {v}: must be >= 1")
    u = np.asarray(starts, dtype=float) if starts is not None else start_points(problem, num_starts)
    num_starts = u.shape[0]
    chains = [None] * num_starts if initial_states is None else list(initial_states)
    if len(chains) != num_starts or any(
        c is not None and len(c) != problem.num_operating_points for c in chains
    ):
        raise UserInputError(
            f"initial_states: {len(chains)} given, expected one per start ({num_starts}), each None or "
            f"one list of states per operating point ({problem.num_operating_points})"
        )
    x_start = np.asarray(problem.bounds.from_scaled(u[0]))
    hyper = _Hyper(float(learning_rate), int(num_iterations), float(rho))
    empty = dict(
        x=[],
        objective=[],
        ci=[],
        gradient=[],
        gradient_stderr=[],
        margins=[],
        wall_s=[],
        simulated_ms=[],
        points_simulated=[],
    )
    if not any_feasible(problem)[0]:
        return SteadySearchResult(
            "no_feasible_design_in_bounds",
            False,
            None,
            float("nan"),
            None,
            x_start,
            empty,
            0,
            0,
            time.perf_counter() - t_start,
            -1,
        )
    optimiser = hyper.optimiser()
    free = (problem.bounds.upper - problem.bounds.lower) > 0
    state = dict(
        iteration=-1,
        u=u,
        opt=[optimiser.init(jnp.asarray(ui)) for ui in u],
        lam=np.zeros((num_starts, len(CONSTRAINT_NAMES))),
        chains=chains,
        history={k: [] for k in empty},
        best=(np.inf, -1, -1, None, None),
        evaluations=0,
        envelope=_fresh_envelope(num_starts, problem.num_operating_points),
    )
    path = None if directory is None else pathlib.Path(directory) / CHECKPOINT
    key = _fingerprint(problem, settings, hyper, u)
    resumed = -1
    if path is not None:
        _refuse_legacy(path.with_name(LEGACY_CHECKPOINT))
    if path is not None and path.exists():
        saved = _load_checkpoint(path)
        if not isinstance(saved, dict) or saved.get("fingerprint") != key:
            raise UserInputError(
                f"{path}: a checkpoint of a search with other settings; remove it or choose "
                "another --out to start afresh"
            )
        state = _checked_state(path, saved.get("state"), state, num_iterations)
        resumed = state["iteration"]
    for it in range(state["iteration"] + 1, num_iterations + 1):
        rows = {k: [] for k in empty}
        u_next, opt_next, lam_next = [], [], []
        # every start's evaluation in one engine call (and one gradient call), at the
        # operating points of the envelope's active set
        env = state["envelope"]
        evaluations = evaluate_starts(
            problem,
            settings,
            list(state["u"]),
            state["chains"],
            active=env["active"],
            previous=[_previous(env, s, state["chains"][s]) for s in range(num_starts)],
        )
        for s, ev in enumerate(evaluations):
            us = state["u"][s]
            state["chains"][s] = ev.states
            state["evaluations"] += int(np.sum(env["active"][s]))
            rows["points_simulated"].append(env["active"][s].copy())
            _record_envelope(problem, settings, env, s, ev)
            c, jc = _constraints(problem, us, ev.dynamic_margin, us)
            g_obj = ev.gradient if np.all(np.isfinite(ev.gradient)) else np.zeros(3)
            act = np.maximum(0.0, state["lam"][s] - rho * c)
            g = np.where(free, g_obj - act @ jc, 0.0)
            updates, opt = optimiser.update(jnp.asarray(g), state["opt"][s], jnp.asarray(us))
            u_next.append(np.clip(np.asarray(optax.apply_updates(jnp.asarray(us), updates)), 0.0, 1.0))
            opt_next.append(opt)
            lam_next.append(act)
            margins = np.concatenate([ev.static_margins, [ev.dynamic_margin]])
            x = np.asarray(problem.bounds.from_scaled(us))
            feasible = bool(np.all(margins > 0) and np.isfinite(ev.objective))
            if feasible and ev.objective < state["best"][0]:
                state["best"] = (ev.objective, it, s, x, ev.objective_ci)
            for name, value in (
                ("x", x),
                ("objective", ev.objective),
                ("ci", ev.objective_ci),
                ("gradient", ev.gradient),
                ("gradient_stderr", ev.gradient_stderr),
                ("margins", margins),
                ("wall_s", ev.wall_time_s),
                ("simulated_ms", ev.simulated_ms),
            ):
                rows[name].append(value)
        for name, value in rows.items():
            state["history"][name].append(value)
        if it < num_iterations:
            state["u"], state["opt"], state["lam"] = np.stack(u_next), opt_next, np.stack(lam_next)
        state["iteration"] = it
        if path is not None:
            _save_checkpoint(path, key, state)
        if callback is not None:
            callback(
                it,
                dict(
                    x=np.stack(rows["x"]),
                    objective=np.asarray(rows["objective"]),
                    ci=rows["ci"],
                    gradient=np.stack(rows["gradient"]),
                    margins=np.stack(rows["margins"]),
                    best=state["best"][0],
                ),
            )
    history = {k: np.asarray(v) for k, v in state["history"].items()}
    best = state["best"]
    common = dict(
        start_design=x_start,
        history=history,
        num_iterations=num_iterations,
        num_evaluations=state["evaluations"],
        resumed_from=resumed,
    )
    if best[1] < 0:
        return SteadySearchResult(
            "no_feasible_iterate",
            False,
            None,
            float("nan"),
            None,
            wall_time_s=time.perf_counter() - t_start,
            **common,
        )
    result = SteadySearchResult(
        "ok",
        True,
        best[3],
        float(best[0]),
        tuple(best[4]),
        wall_time_s=0.0,
        best_start=int(best[2]),
        best_iteration=int(best[1]),
        **common,
    )
    if verify:
        result.verification = verification(problem, settings, best[3], x_start)
    result.wall_time_s = time.perf_counter() - t_start
    return result


#: what the search knows about the axial clearance's effect on its objective (result.json
#: `axial_clearance_effect`; docs/model.md 17): the frozen-load estimator cannot see Delta_bf;
#: common-random-number central differences of settled ensembles found it significant only
#: with the inner ring misaligned by 2 mrad
CLEARANCE_EFFECT = {
    "estimator_sees_it": False,
    "why": "the frozen-load estimator moves the flange in its own plane at a fixed load: its dJ/dDelta_bf "
    "is 0 by construction; Delta_bf moves only where a margin (the axial clearance Lambda_bf) pushes it",
    "measured": "R_end 100 mm, theta_f 1.4 deg, Delta_bf 0.15 mm, 20,000 rpm, 1000 N: dJ/dDelta_bf = "
    "+1.83e12 +- 0.95e12 Pa m/s per m, 95 % CI [-0.13e12, +3.79e12] (24 seeds, common-random-number "
    "central differences): not significant; up to about 2.3 % of J per 10 um is not excluded. "
    "Not significant at 80 mm / 1.6 deg and 70 mm / 1.8 deg either (8 seeds)",
    "study": "the clearance study (benchmarks/studies/README.md) on one H200 (11 slices, 16 seeds, h = 0.01 mm, "
    "results/study_clearance_effect.json, docs/figures/clearance_effect): 7 operating points (10,000, 20,000, "
    "30,000 rpm; 1 and 2 mrad; 500 and 4000 N) x 2 designs (100 mm / 1.4 deg and 94.3 mm / 1.84 deg, "
    "Delta_bf 0.15 mm). Never significantly negative: where the clearance matters, a larger one raises PV",
    "significant": "100 mm / 1.4 deg at 2 mrad misalignment: +4.41e12 Pa m/s per m, 95 % CI [3.15e12, 5.67e12] "
    "(+2.5 % of J per 10 um, 7.5 standard errors; 8 seeds on the CPU gave +4.37e12). Marginal (2.2-2.3 "
    "standard errors; with 14 comparisons, not significant after a Bonferroni correction): 100 mm / 1.4 deg "
    "at 30,000 rpm, +6.5e12 [0.4e12, 12.6e12] (+2.1 %, one member not settled); 94.3 mm / 1.84 deg at "
    "500 N, +14.2e12 [0.6e12, 27.8e12] (+8.9 %)",
    "not_significant": "the other 11: 10,000 and 20,000 rpm, 1 mrad and 4000 N at both designs, 30,000 rpm and "
    "2 mrad at 94.3 mm / 1.84 deg, 500 N at 100 mm / 1.4 deg; 95 % intervals within -6e12 .. +5e12 Pa m/s "
    "per m, within -4.2 .. +3.6 % of J per 10 um except 94.3 mm / 1.84 deg at 10,000 rpm (-7.8 .. +6.2 %, "
    "where J is smallest)",
    "unmeasured": "31 slices (the study ran at 11), combined factors (misaligned and fast), other designs",
}


def near_optimal_set(result: SteadySearchResult) -> list[dict]:
    """The feasible designs the search evaluated whose objective lies within the best design's
    95 % interval (the optimum is a ridge along a binding margin, not a point; a designer chooses among these by other criteria), best first. Each: the design
    (R_end, theta_f, Delta_bf in SI), its objective and interval, where it was evaluated
    (iteration, start), and its binding margin: the smallest of its static and dynamic margins
    (`CONSTRAINT_NAMES`) with its value [m]. Empty without a feasible design."""
    if result.design is None or result.objective_ci is None or not len(result.history.get("x", ())):
        return []
    h = result.history
    x, objective = np.asarray(h["x"]), np.asarray(h["objective"], float)  # (I, S, 3), (I, S)
    ci, margins = np.asarray(h["ci"], float), np.asarray(h["margins"], float)  # (I, S, 2), (I, S, 5)
    high = float(result.objective_ci[1])
    feasible = np.all(margins > 0, axis=-1) & np.isfinite(objective)
    near = feasible & (objective <= high)
    out = []
    for it, s in zip(*np.nonzero(near)):
        k = int(np.argmin(margins[it, s]))
        out.append(
            {
                "design": x[it, s].tolist(),
                "objective": float(objective[it, s]),
                "ci95": [float(ci[it, s, 0]), float(ci[it, s, 1])],
                "iteration": int(it),
                "start": int(s),
                "binding_margin": CONSTRAINT_NAMES[k],
                "binding_margin_m": float(margins[it, s, k]),
            }
        )
    return sorted(out, key=lambda d: d["objective"])


def _save_checkpoint(path: pathlib.Path, key: str, state: dict) -> None:
    """The search state, data only (`jaxbearing.io.save_tree`: `.npz` and JSON), atomically."""
    save_tree(path, {"fingerprint": key, "state": jax.tree_util.tree_map(np.asarray, state)})


def _load_checkpoint(path: pathlib.Path) -> dict:
    """A checkpoint written by `_save_checkpoint`; one line naming the file for anything else
    (a pickle is refused, never unpickled)."""
    try:
        return load_tree(path, what="checkpoint")
    except TreeFileError as exc:
        raise UserInputError(f"{exc}; remove it to start afresh") from None


def _refuse_legacy(path: pathlib.Path) -> None:
    if path.exists():
        raise UserInputError(
            f"{path}: a pickled checkpoint of an older version (not loaded: a pickle can run "
            "code); remove it to start afresh"
        )


def _checked_state(path: pathlib.Path, state, template: dict, num_iterations: int) -> dict:
    """`state` read from a checkpoint, checked for type and shape against a fresh `template`."""

    def bad(why: str):
        return UserInputError(f"{path}: not a checkpoint of this search ({why}); remove it to start afresh")

    if not isinstance(state, dict) or set(state) != set(template):
        raise bad("its fields differ")
    it = state["iteration"]
    it = int(it) if np.ndim(it) == 0 and np.asarray(it).dtype.kind in "iu" else None
    if it is None or not -1 <= it <= num_iterations:
        raise bad(f"iteration {state['iteration']!r}")
    state["iteration"] = it
    check_like(state["u"], template["u"], path, "checkpoint")
    check_like(state["lam"], template["lam"], path, "checkpoint")
    check_like(state["opt"], jax.tree_util.tree_map(np.asarray, template["opt"]), path, "checkpoint")
    chains, history = state["chains"], state["history"]
    if not isinstance(chains, list) or len(chains) != len(template["chains"]):
        raise bad("continuation states")
    if not isinstance(history, dict) or set(history) != set(template["history"]):
        raise bad("history")
    if any(not isinstance(v, list) or len(v) != it + 1 for v in history.values()):
        raise bad("history length")
    if not isinstance(state["best"], tuple) or len(state["best"]) != 5:
        raise bad("best design")
    env = state["envelope"]
    if not isinstance(env, dict) or set(env) != set(template["envelope"]):
        raise bad("envelope")
    for k, v in template["envelope"].items():
        check_like(env[k], v, path, "checkpoint")
    return state


def _fresh_envelope(num_starts: int, num_points: int) -> dict:
    """The envelope's active set of every start (`next_active`) and, per start and operating
    point, what was last measured there (`Evaluation.per_point`): arrays, for the checkpoint."""
    shape = (num_starts, num_points)
    nan = np.full(shape, np.nan)
    return dict(
        active=np.ones(shape, bool),
        since=np.zeros(shape, np.int64),
        value=nan.copy(),
        ci=np.full(shape + (2,), np.nan),
        gradient=np.zeros(shape + (3,)),
        gradient_stderr=np.zeros(shape + (3,)),
        corner_margin=nan.copy(),
        measured_at=np.zeros(shape + (3,)),
        share=nan.copy(),
        settled=np.zeros(shape, bool),
    )


def _record_envelope(problem: DesignProblem, settings: SteadySettings, env: dict, s: int, ev: Evaluation):
    """Store start `s`'s simulated points of `ev` in `env` and choose its next active set."""
    for k, p in enumerate(ev.per_point):
        if not p["simulated"]:
            env["since"][s, k] += 1
            continue
        env["since"][s, k] = 0
        env["value"][s, k], env["ci"][s, k] = p["value"], p["ci"]
        env["gradient"][s, k], env["gradient_stderr"][s, k] = p["gradient"], p["gradient_stderr"]
        env["corner_margin"][s, k], env["measured_at"][s, k] = p["measured_corner_margin"], p["measured_at"]
        env["share"][s, k], env["settled"][s, k] = p["corner_contact_share"], p["settled"]
    env["active"][s] = next_active(problem, settings, ev, env["since"][s])


def _previous(env: dict, s: int, states):
    """Start `s`'s last measurements at every operating point (`evaluate_starts`' `previous`),
    None before its first evaluation."""
    if states is None:
        return None
    per = [
        dict(
            value=float(env["value"][s, k]),
            ci=tuple(float(v) for v in env["ci"][s, k]),
            gradient=np.array(env["gradient"][s, k]),
            gradient_stderr=np.array(env["gradient_stderr"][s, k]),
            estimator_value=float("nan"),
            corner_margin=float(env["corner_margin"][s, k]),
            measured_corner_margin=float(env["corner_margin"][s, k]),
            measured_at=np.array(env["measured_at"][s, k]),
            corner_contact_share=float(env["share"][s, k]),
            mean_pv={},
            settled=bool(env["settled"][s, k]),
            simulated=False,
        )
        for k in range(env["value"].shape[1])
    ]
    return _Previous(per, list(states))


@dataclasses.dataclass(frozen=True)
class _Previous:
    """What `evaluate_starts` reuses of a start's operating points left out."""

    per_point: list
    states: list


def _estimates(m) -> dict:
    """One design's verification row: the issue's `mean_pv`, `p95_pv` [Pa m/s, SI] and
    `corner_contact_share`, each as value / ci95_low / ci95_high / n, and the same in the
    engineering units the documentation and the CLI print (GPa m/s, mm)."""
    return {
        "mean_pv": _scaled(m.mean_pv, 1.0) | {"unit": "Pa m/s"},
        "p95_pv": _scaled(m.p95_pv, 1.0) | {"unit": "Pa m/s"},
        "mean_pv_GPa_m_s": _scaled(m.mean_pv),
        "p95_pv_GPa_m_s": _scaled(m.p95_pv),
        "objective_GPa_m_s": _scaled(m.objective),
        # the expected largest PV of a cage revolution (what the "peak" statistic aims at)
        "peak_pv_GPa_m_s": _scaled(m.summary.get("flange_pv_Pa_m_s", {}).get("max", {})),
        # the mean of the worst 5 % of PV over contact time (the "tail" statistic)
        "tail_pv_GPa_m_s": _scaled(m.summary.get("flange_pv_contact_time_Pa_m_s", {}).get("tail95", {})),
        "corner_contact_share": dict(m.corner_contact_share),
        "corner_margin_mm": _scaled(m.corner_margin, 1e-3),
        # the margin on the upper 95 % prediction bound of one revolution's largest contact radius
        "corner_margin_bound_mm": float(m.corner_margin_bound) * 1e3,
        # how far zero corner contact in these seeds bounds the tail (upper 95 % bounds)
        "corner_contact_bound": m.summary.get("corner_contact_bound"),
        # the probability per revolution of reaching the corner, with its bounds (`run.corner_risk`)
        "corner_risk": m.summary.get("corner_risk"),
        "settled": m.settled,
        "seeds": m.seeds,
    }


def _scaled(est: dict, unit: float = PV_SCALE) -> dict:
    return {
        k: (None if est.get(k) is None else float(est[k]) / unit) if k != "n" else est.get("n", 0)
        for k in ("value", "ci95_low", "ci95_high", "n")
    }


@_in_shared_pool
def verification(problem: DesignProblem, settings: SteadySettings, design, reference) -> dict:
    """The found design and the reference design re-simulated from the skid start with seeds
    the search never used (module docstring), at every operating point: both designs' points'
    seeds members of one call of the steady-running engine."""
    out = {
        "seeds": list(range(settings.verify_first_seed, settings.verify_first_seed + settings.verify_seeds))
    }
    ops = [_operating_point(problem, k) for k in range(problem.num_operating_points)]
    designs = [DesignVariables.from_array(jnp.asarray(x)) for x in (reference, design)]
    metrics = _settled_metrics(
        problem,
        settings,
        ops * 2,
        [d for d in designs for _ in ops],
        seeds=settings.verify_seeds,
        window_revs=settings.verify_window_revs,
        first_seed=settings.verify_first_seed,
    )
    for i, name in enumerate(("reference", "optimum")):
        rows = [_estimates(m) for m in metrics[i * len(ops) : (i + 1) * len(ops)]]
        out[name] = rows[0] if len(rows) == 1 else {"per_operating_point": rows}
    refs = out["reference"].get("per_operating_point", [out["reference"]])
    opts = out["optimum"].get("per_operating_point", [out["optimum"]])

    def lower(key: str) -> list[bool]:  # per point: the optimum's interval below the reference's
        return [
            bool(
                None not in (r[key]["ci95_low"], o[key]["ci95_high"])
                and o[key]["ci95_high"] < r[key]["ci95_low"]
            )
            for r, o in zip(refs, opts)
        ]

    # at every operating point (the whole envelope)
    out["mean_pv_lower_disjoint"] = all(lower("mean_pv_GPa_m_s"))
    out["objective_lower_disjoint"] = all(lower("objective_GPa_m_s"))
    if len(ops) > 1:
        out["mean_pv_lower_disjoint_per_operating_point"] = lower("mean_pv_GPa_m_s")
        out["objective_lower_disjoint_per_operating_point"] = lower("objective_GPa_m_s")
    out["optimum_corner_contacts"] = any((o["corner_contact_share"].get("value") or 0.0) > 0 for o in opts)
    for name in ("reference", "optimum"):  # the weakest bound over the operating points
        rows = out[name].get("per_operating_point", [out[name]])
        bounds = [r["corner_contact_bound"] for r in rows if r.get("corner_contact_bound")]
        if bounds:
            out[f"{name}_corner_contact_per_revolution_upper95"] = max(
                b["per_revolution_upper95"] for b in bounds
            )
    out["tail"] = tail_verification(opts, settings.corner_risk_level)
    return out


def tail_verification(rows: list[dict], level: float) -> dict:
    """Whether the verification bounds the found design's corner-contact risk at `level` per
    cage revolution at every operating point: the largest upper bound of `run.corner_risk` over
    the points (one-sided 95 % or more), `verified` when it is at most `level`; else the design
    is unverified in the tail, and `revolutions_needed` says how many revolutions per point
    without corner contact would bound it by counting alone."""
    risks = [r.get("corner_risk") for r in rows]
    uppers = [r["upper"] if r and r.get("upper") is not None else 1.0 for r in risks]
    upper = max(uppers) if uppers else 1.0
    return {
        "level_per_revolution": float(level),
        "upper_per_revolution": float(upper),
        "methods": [r.get("method") if r else None for r in risks],
        "revolutions_per_point": [r.get("revolutions") if r else 0 for r in risks],
        "verified": bool(upper <= level),
        "revolutions_needed": revolutions_needed(level),
    }


@_in_shared_pool
def steady_grid(
    problem: DesignProblem,
    settings: SteadySettings,
    n_end_radius: int,
    n_layback: int,
    axial_clearance: float,
    *,
    directory: str | pathlib.Path | None = None,
    callback: Callable[[int, dict], None] | None = None,
) -> dict:
    """The steady objective (value only) over an n_end_radius x n_layback grid of (R_end,
    theta_f) inside the bounds at fixed Delta_bf, for comparison with `steady_search`: the
    statically feasible points in a serpentine order, each continuing from the previous point's
    settled states (the first from the skid start). The best point is the lowest objective
    among those with every static and dynamic margin positive. With `directory`, every finished
    point is kept in DIR/grid_checkpoint.npz (data only) and a rerun resumes."""
    t0 = time.perf_counter()
    lo, hi = problem.bounds.lower, problem.bounds.upper
    r = np.linspace(lo[0], hi[0], n_end_radius)
    t = np.linspace(lo[1], hi[1], n_layback)
    order = [
        (i, j if i % 2 == 0 else n_layback - 1 - j) for i in range(n_end_radius) for j in range(n_layback)
    ]
    path = None if directory is None else pathlib.Path(directory) / "grid_checkpoint.npz"
    if path is not None:
        _refuse_legacy(path.with_name("grid_checkpoint.pkl"))
    done = (
        _load_checkpoint(path) if path is not None and path.exists() else {"fingerprint": "grid", "state": {}}
    )
    done = done.get("state") if isinstance(done, dict) and done.get("fingerprint") == "grid" else None
    if not isinstance(done, dict):
        raise UserInputError(f"{path}: not a grid checkpoint; remove it to start afresh")
    objective = np.full((n_end_radius, n_layback), np.nan)
    ci = np.full((n_end_radius, n_layback, 2), np.nan)
    dynamic = np.full((n_end_radius, n_layback), np.nan)
    static = np.full((n_end_radius, n_layback, 4), np.nan)
    chain, evaluations, simulated = None, 0, 0.0
    for i, j in order:
        x = np.array([r[i], t[j], axial_clearance])
        u = np.asarray(problem.bounds.to_scaled(x))
        static[i, j] = np.asarray(problem.margins(jnp.asarray(u)))
        if not np.all(static[i, j] > 0):
            continue
        if (i, j) not in done:
            ev = evaluate(problem, settings, u, chain, gradient=False)
            done[(i, j)] = dict(
                objective=ev.objective,
                ci=ev.objective_ci,
                dynamic=ev.dynamic_margin,
                states=ev.states,
                simulated_ms=ev.simulated_ms,
            )
            if path is not None:
                _save_checkpoint(path, "grid", done)
        e = done[(i, j)]
        chain = e["states"]
        evaluations += problem.num_operating_points
        simulated += e["simulated_ms"]
        objective[i, j], ci[i, j], dynamic[i, j] = e["objective"], e["ci"], e["dynamic"]
        if callback is not None:
            callback(
                evaluations, dict(x=x, objective=e["objective"], ci=e["ci"], dynamic_margin=e["dynamic"])
            )
    ok = np.isfinite(objective) & (dynamic > 0)
    best = np.unravel_index(np.argmin(np.where(ok, objective, np.inf)), objective.shape) if ok.any() else None
    return dict(
        end_radius=r,
        layback_angle=t,
        axial_clearance=axial_clearance,
        objective=objective,
        ci=ci,
        dynamic_margin=dynamic,
        static_margins=static,
        best_design=None if best is None else np.array([r[best[0]], t[best[1]], axial_clearance]),
        best_objective=float("nan") if best is None else float(objective[best]),
        best_ci=None if best is None else tuple(ci[best]),
        num_evaluations=evaluations,
        simulated_ms=simulated,
        wall_time_s=time.perf_counter() - t0,
    )
