"""Design search on steady running: the default objective of `optimise run` (docs/model.md 17).

Minimise the steady objective J(x) of the design x = (R_end, theta_f, Delta_bf) over the
envelope (`_evaluate`: settled mean, peak or tail flange PV or the flange friction power, with its 95 % interval and its
estimated gradient) inside the four static design-zone margins of `DesignProblem.constraints`
and the dynamic corner-contact margin, from several starts, by the projected
augmented-Lagrangian step of `_lagrangian` (one step per start and iteration).

The dynamic corner margin m_dyn = rho_lim - (a bound of the per-revolution largest contact
radius) - `corner_margin` (`SteadySettings.corner_constraint`) is an extreme of a dynamic run
with no derivative of its own. It is modelled as its measured value plus the change of the
static limited-circle margin rho_lim - rho_c (the aligned contact radius): m_dyn(u') ~ m_dyn(u)
+ m_lc(u') - m_lc(u), i.e. the skew excursion is held at its measured value over one step; its
gradient is the static margin's (`constraints`).

Continuation. Every start carries the settled states of its last design, per operating point;
the next iterate (a step of a few per cent of the box) starts from them instead of from the skid
start, and settles by the verdict. `steady_search(initial_states=...)` gives a start's first
evaluation such states too (e.g. the `final_states` of a settled ensemble of the start design).
The envelope's active set (`_envelope.next_active`) leaves out operating points of negligible
weight. The state is checkpointed after every iteration (`_state`); a killed run started again
with the same settings continues from its last finished iteration and reaches the same result.
The best feasible design and the start design are then verified on seeds the search never used
(`_verify`).
"""

from __future__ import annotations

import dataclasses
import pathlib
import time
from collections.abc import Callable

import jax
import jax.numpy as jnp
import numpy as np

from jaxbearing import UserInputError
from jaxbearing.flange import MARGIN_NAMES

from ._envelope import Envelope
from ._evaluate import Evaluation, evaluate_starts, in_shared_pool
from ._lagrangian import Hyper, IterationReport, augmented_lagrangian_step
from ._problem import MARGIN_SCALE, DesignProblem, any_feasible
from ._search import start_points
from ._settings import Choice, SteadySettings
from ._state import CHECKPOINT, History, SearchState, fingerprint, resumed_state, save_checkpoint
from ._verify import Verification, verification

#: names of the five constraints of the steady search (static zone margins, then dynamic)
CONSTRAINT_NAMES = (*MARGIN_NAMES, "dynamic_corner")
#: the scale of each limit's margin (`SteadySettings.limits`): Lambda in units of 0.1, the
#: flash temperature in units of 10 K, the friction power in W, so that the scaled constraints are O(1) like the others
LIMIT_SCALES = {"film_parameter": 0.1, "flash_temperature": 10.0, "friction_power": 1.0}
#: a limit no operating point measured (+inf margin) enters as this scaled value: far from
#: binding, and finite in the augmented Lagrangian's arithmetic
UNMEASURED_LIMIT = 1e3


def constraint_names(settings: SteadySettings) -> tuple[str, ...]:
    """The names of the search's constraints: `CONSTRAINT_NAMES`, then the limits set."""
    return (*CONSTRAINT_NAMES, *(name for name, _ in settings.limits))


def scaled_limits(settings: SteadySettings, margins, jacobian=None) -> tuple[np.ndarray, np.ndarray | None]:
    """The limits' margins (`Evaluation.limit_margins`) as scaled, tightened constraints, and
    their Jacobian (`Evaluation.limit_jacobian`, or None) in the same scale."""
    scales = np.array([LIMIT_SCALES[name] for name, _ in settings.limits])
    scaled = np.asarray(margins, dtype=float) / scales if len(scales) else np.zeros(0)
    jac = None if jacobian is None or not len(scales) else np.asarray(jacobian, dtype=float) / scales[:, None]
    return np.minimum(scaled, UNMEASURED_LIMIT), jac


def constraints(problem: DesignProblem, u, dynamic_margin: float, u_measured, limits=(), limit_jacobian=None):
    """Scaled, tightened constraints (5 + L,) and their Jacobian (5 + L, n): the static ones
    exactly, the dynamic corner margin by its measured value plus the static limited-circle
    margin's change from `u_measured` (module docstring); then the L limits (`scaled_limits`:
    film parameter, flash temperature, friction power) at their measured values, with the rows
    of `limit_jacobian` where given (the friction power's frozen-load gradient,
    `_evaluate.limit_jacobian`) and zero rows otherwise (the film parameter and the flash
    temperature have no derivative of their own: such a limit binds through the choice of the
    returned design and through its multiplier's pull on the step that crossed it)."""

    def c(v):
        static = problem.margins(v)
        lc = static[MARGIN_NAMES.index("limited_circle")]
        lc0 = problem.margins(u_measured)[MARGIN_NAMES.index("limited_circle")]
        dyn = dynamic_margin + lc - lc0
        return jnp.concatenate([static, dyn[None]]) / MARGIN_SCALE - problem.tighten

    u = jnp.asarray(u)
    held = np.asarray(limits, dtype=float) - problem.tighten
    value = np.concatenate([np.asarray(c(u)), held])
    rows = (
        np.zeros((held.size, u.size)) if limit_jacobian is None else np.asarray(limit_jacobian, dtype=float)
    )
    jac = np.concatenate([np.asarray(jax.jacfwd(c)(u)), rows])
    return value, jac


@dataclasses.dataclass
class SteadySearchResult:
    """Outcome of `steady_search` (designs in SI units; objective in GPa m/s)."""

    status: str  # "ok", "no_feasible_design_in_bounds", "no_feasible_iterate"
    feasible: bool
    design: np.ndarray | None
    objective: float
    objective_ci: tuple | None
    start_design: np.ndarray
    history: History  # per iteration and start (arrays with leading axes iteration, start)
    num_iterations: int
    num_evaluations: int  # settled ensembles (one per start, iteration and operating point)
    wall_time_s: float
    resumed_from: int  # iteration the run resumed after (-1: fresh)
    best_start: int = -1
    best_iteration: int = -1
    verification: Verification | None = None


def check_profile_settings(problem: DesignProblem, settings: SteadySettings) -> None:
    """A profile search (eight variables) estimates its gradient with the frozen-load
    estimator: the short-window sensitivities are written for R_end, theta_f, Delta_bf."""
    if problem.num_variables != 3 and settings.estimator != "frozen":
        raise UserInputError(
            f"estimator = {settings.estimator.value!r}: a profile search needs the frozen-load estimator ('frozen')"
        )


def _checked_starts(problem: DesignProblem, num_starts, num_iterations, starts, initial_states):
    """The scaled starts and their continuation states, or a one-line error."""
    for name, v in (("starts", num_starts), ("iterations", num_iterations)):
        if int(v) < 1:
            raise UserInputError(f"{name} = {v}: must be >= 1")
    u = np.asarray(starts, dtype=float) if starts is not None else start_points(problem, num_starts)
    chains = [None] * u.shape[0] if initial_states is None else list(initial_states)
    if len(chains) != u.shape[0] or any(
        c is not None and len(c) != problem.num_operating_points for c in chains
    ):
        raise UserInputError(
            f"initial_states: {len(chains)} given, expected one per start ({u.shape[0]}), each None or "
            f"one list of states per operating point ({problem.num_operating_points})"
        )
    return u, chains


def _iteration(problem: DesignProblem, settings: SteadySettings, hyper: Hyper, state: SearchState, it: int):
    """One iteration of every start: every start's evaluation in one engine call (and one
    gradient call) at the operating points of the envelope's active set, then one
    augmented-Lagrangian step per start. Updates `state` and returns the iteration's rows."""
    num_starts = state.u.shape[0]
    optimiser = hyper.optimiser()
    free = (problem.bounds.upper - problem.bounds.lower) > 0
    env = state.envelope
    evaluations = evaluate_starts(
        problem,
        settings,
        list(state.u),
        state.chains,
        active=env.active,
        previous=[env.previous(s, state.chains[s]) for s in range(num_starts)],
    )
    rows = {f.name: [] for f in dataclasses.fields(History)}
    u_next, opt_next, lam_next = [], [], []
    for s, ev in enumerate(evaluations):
        us = state.u[s]
        state.chains[s] = ev.states
        state.evaluations += int(np.sum(env.active[s]))
        rows["points_simulated"].append(env.active[s].copy())
        env.record(problem, settings, s, ev)
        held, held_jac = scaled_limits(settings, ev.limit_margins, ev.limit_jacobian)
        c, jc = constraints(problem, us, ev.dynamic_margin, us, held, held_jac)
        g_obj = ev.gradient if np.all(np.isfinite(ev.gradient)) else np.zeros(problem.num_variables)
        u_new, opt, act = augmented_lagrangian_step(
            optimiser, hyper.rho, free, g_obj, c, jc, state.lam[s], state.opt[s], jnp.asarray(us)
        )
        u_next.append(np.asarray(u_new))
        opt_next.append(opt)
        lam_next.append(np.asarray(act))
        margins = np.concatenate([ev.static_margins, [ev.dynamic_margin], ev.limit_margins])
        x = np.asarray(problem.bounds.from_scaled(us))
        for name, value in _row(ev, x, margins).items():
            rows[name].append(value)
    if it < hyper.num_iterations:
        state.u, state.opt, state.lam = np.stack(u_next), opt_next, np.stack(lam_next)
    state.history.append(rows)
    return rows


def _row(ev: Evaluation, x, margins) -> dict:
    return dict(
        x=x,
        objective=ev.objective,
        ci=ev.objective_ci,
        gradient=ev.gradient,
        gradient_stderr=ev.gradient_stderr,
        margins=margins,
        wall_s=ev.wall_time_s,
        simulated_ms=ev.simulated_ms,
        corner_risk=ev.corner_risk,
    )


def _report(rows: dict, history: History) -> IterationReport:
    """The iteration's rows and the best feasible objective so far (`tied_with_best`: the lowest
    upper bound of the objective; inf: none yet)."""
    h = History(**history.as_arrays())
    _, best = tied_with_best(h)
    return IterationReport(
        x=np.stack(rows["x"]),
        objective=np.asarray(rows["objective"]),
        margins=np.stack(rows["margins"]),
        best=float("inf") if best is None else float(h.objective[best]),
        ci=rows["ci"],
        gradient=np.stack(rows["gradient"]),
    )


@in_shared_pool
def steady_search(
    problem: DesignProblem,
    settings: SteadySettings = SteadySettings(),
    *,
    num_starts: int = 2,
    num_iterations: int = 4,
    learning_rate: float = 0.08,
    rho: float = 10.0,
    starts: np.ndarray | None = None,
    directory: str | pathlib.Path | None = None,
    callback: Callable[[int, IterationReport], None] | None = None,
    verify: bool = True,
    initial_states: list | None = None,
) -> SteadySearchResult:
    """Minimise the steady objective inside the static and dynamic margins (module docstring)
    from `num_starts` starts (the bearing's own design, then Halton points), `num_iterations`
    projected Adam steps each. With `directory`, the state is checkpointed there after every
    iteration and a matching checkpoint is resumed. `callback(iteration, report)` reports
    progress after every iteration. `initial_states`: None, or per start None or the states its
    first evaluation continues from, per operating point one state per seed (e.g.
    `[[metrics.final_states]]`: a settled ensemble of the start design with `settings.seeds`
    seeds); a resumed checkpoint's own states win."""
    t_start = time.perf_counter()
    check_profile_settings(problem, settings)
    u, chains = _checked_starts(problem, num_starts, num_iterations, starts, initial_states)
    x_start = np.asarray(problem.bounds.from_scaled(u[0]))
    hyper = Hyper(float(learning_rate), int(num_iterations), float(rho))
    if not any_feasible(problem)[0]:
        wall = time.perf_counter() - t_start
        return SteadySearchResult(
            "no_feasible_design_in_bounds",
            False,
            None,
            float("nan"),
            None,
            x_start,
            History(),
            0,
            0,
            wall,
            -1,
        )
    fresh = SearchState(
        iteration=-1,
        u=u,
        opt=[hyper.optimiser().init(jnp.asarray(ui)) for ui in u],
        lam=np.zeros((u.shape[0], len(constraint_names(settings)))),
        chains=chains,
        history=History(),
        evaluations=0,
        envelope=Envelope.fresh(u.shape[0], problem.num_operating_points, problem.num_variables),
    )
    path = None if directory is None else pathlib.Path(directory) / CHECKPOINT
    key = fingerprint(problem, settings, hyper, u)
    state = resumed_state(path, key, fresh, num_iterations)
    resumed = state.iteration
    for it in range(state.iteration + 1, num_iterations + 1):
        rows = _iteration(problem, settings, hyper, state, it)
        state.iteration = it
        if path is not None:
            save_checkpoint(path, key, state)
        if callback is not None:
            callback(it, _report(rows, state.history))
    result = _result(state, x_start, num_iterations, resumed, settings.choose)
    if verify and result.feasible:
        result.verification = verification(problem, settings, result.design, x_start)
    result.wall_time_s = time.perf_counter() - t_start
    return result


def _feasible(h: History) -> np.ndarray:
    objective, margins = np.asarray(h.objective, float), np.asarray(h.margins, float)
    return np.all(margins > 0, axis=-1) & np.isfinite(objective)


def interval_bounds(ci, objective) -> np.ndarray:
    """The 95 % bounds (..., 2) of evaluations' objectives, an evaluation without an interval (one
    seed: NaN bounds) counting with its point estimate as both."""
    ci = np.asarray(ci, float)
    return np.where(np.isfinite(ci), ci, np.asarray(objective, float)[..., None])


def returned_so_far(feasible, ci, objective) -> np.ndarray:
    """After each of a search's settled evaluations, in order, the index of the one it returns
    had it stopped there: the feasible evaluation of the lowest upper 95 % bound (the first of
    ties; one without an interval counts with its point estimate, `interval_bounds`), -1 before
    the first feasible one."""
    high = np.where(feasible, interval_bounds(ci, objective)[:, 1], np.inf)
    out = np.full(len(high), -1)
    best = -1
    for i in range(len(high)):
        if np.isfinite(high[i]) and (best < 0 or high[i] < high[best]):
            best = i
        out[i] = best
    return out


def measured_constraints(problem: DesignProblem, settings: SteadySettings, u, ev) -> tuple[np.ndarray, bool]:
    """The scaled constraints of the settled evaluation `ev` of the scaled design u at its own
    measurements (`constraints`, the limits at their measured values, `scaled_limits`) and
    whether it is feasible: every one positive and its objective finite."""
    c, _ = constraints(problem, u, ev.dynamic_margin, u, scaled_limits(settings, ev.limit_margins)[0])
    return c, bool(np.all(c > 0) and np.isfinite(ev.objective))


def tied_with_best(h: History) -> tuple[np.ndarray, tuple | None]:
    """The feasible evaluations statistically tied with the best (iteration, start mask), and
    the best's index: the best is the feasible evaluation of the lowest upper 95 % bound of the
    objective (not the lowest point estimate: one with a wide interval may lie anywhere in it);
    tied are those whose lower bound lies below that upper bound (the intervals overlap). An
    evaluation without an interval (one seed) counts with its point estimate as both bounds."""
    feasible = _feasible(h) if len(h) else np.zeros((0, 0), bool)
    if not feasible.any():
        return feasible, None
    ci = interval_bounds(h.ci, h.objective)
    high = np.where(feasible, ci[..., 1], np.inf)
    best = np.unravel_index(int(np.argmin(high)), high.shape)
    return feasible & (ci[..., 0] <= high[best]), best


def choose(h: History, how: Choice | str) -> tuple | None:
    """The (iteration, start) the search returns (`SteadySettings.choose`): `Choice.BEST`, the
    feasible evaluation of the lowest upper bound of the objective; `Choice.SAFEST`, of those tied with it
    (`tied_with_best`), the lowest upper bound of the corner-contact risk per revolution, then
    the largest dynamic corner margin. None without a feasible evaluation."""
    tied, best = tied_with_best(h)
    if best is None or Choice(how) is Choice.BEST:
        return best
    risk = np.asarray(h.corner_risk, float)
    risk = np.where(np.isfinite(risk), risk, 1.0)  # an unknown risk is not the safest
    dynamic = np.asarray(h.margins, float)[..., len(CONSTRAINT_NAMES) - 1]
    candidates = np.argwhere(tied)
    order = sorted(candidates.tolist(), key=lambda i: (risk[tuple(i)], -dynamic[tuple(i)]))
    return tuple(order[0])


def _result(state: SearchState, x_start, num_iterations: int, resumed: int, how: str) -> SteadySearchResult:
    history = History(**state.history.as_arrays())
    common = dict(
        start_design=x_start,
        history=history,
        num_iterations=num_iterations,
        num_evaluations=int(state.evaluations),
        resumed_from=resumed,
        wall_time_s=0.0,
    )
    chosen = choose(history, how)
    if chosen is None:
        return SteadySearchResult("no_feasible_iterate", False, None, float("nan"), None, **common)
    it, s = (int(v) for v in chosen)
    return SteadySearchResult(
        "ok",
        True,
        np.asarray(history.x[it, s]),
        float(history.objective[it, s]),
        tuple(float(v) for v in history.ci[it, s]),
        best_start=s,
        best_iteration=it,
        **common,
    )


@dataclasses.dataclass(frozen=True)
class NearOptimal:
    """A feasible design the search evaluated that is statistically tied with the best
    (`tied_with_best`), with its corner-contact risk and margins."""

    design: np.ndarray  # (R_end, theta_f, Delta_bf) or the profile's eight [SI]
    objective: float  # [GPa m/s]
    ci95: tuple
    iteration: int
    start: int
    binding_margin: str  # the smallest of its margins in m (`CONSTRAINT_NAMES`)
    binding_margin_m: float
    corner_risk: float  # the upper 95 % bound of the corner-contact risk per revolution (worst point)
    corner_margin_m: float  # the dynamic corner margin (`SteadySettings.corner_constraint`)


def near_optimal_set(result: SteadySearchResult) -> list[NearOptimal]:
    """The feasible designs the search evaluated that are statistically tied with the best
    (their objective's interval reaches below the best's upper 95 % bound, `tied_with_best`):
    the optimum is a ridge along a binding margin, not a point, and a designer chooses among
    these by other criteria; each with its corner-contact risk and margins. Best objective
    first; empty without a feasible design."""
    h = result.history
    if result.design is None or not len(h):
        return []
    tied, _ = tied_with_best(h)
    x, objective = np.asarray(h.x), np.asarray(h.objective, float)  # (I, S, n), (I, S)
    ci = np.asarray(h.ci, float)  # (I, S, 2)
    margins = np.asarray(h.margins, float)[..., : len(CONSTRAINT_NAMES)]  # (I, S, 5) [m]
    risk = np.asarray(h.corner_risk, float)
    out = []
    for it, s in zip(*np.nonzero(tied)):
        k = int(np.argmin(margins[it, s]))
        out.append(
            NearOptimal(
                design=x[it, s],
                objective=float(objective[it, s]),
                ci95=(float(ci[it, s, 0]), float(ci[it, s, 1])),
                iteration=int(it),
                start=int(s),
                binding_margin=CONSTRAINT_NAMES[k],
                binding_margin_m=float(margins[it, s, k]),
                corner_risk=float(risk[it, s]),
                corner_margin_m=float(margins[it, s, -1]),
            )
        )
    return sorted(out, key=lambda d: d.objective)
