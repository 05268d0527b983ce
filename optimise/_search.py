"""Multi-start projected augmented-Lagrangian search driven by optax.

Method. In the unit box u in [0, 1]^3 (`DesignProblem.bounds`), minimise the robust smooth peak
PV J(u) subject to the design-zone constraints c_i(u) >= 0 (i = relief, height, limited circle,
clearance) with the Powell-Hestenes-Rockafellar augmented Lagrangian for inequalities
(Nocedal & Wright, Numerical Optimization, 2nd ed., Eq. 17.65):

    L_rho(u, lambda) = J(u) + sum_i psi(c_i(u), lambda_i),
    psi(c, lambda)   = (max(0, lambda - rho c)^2 - lambda^2) / (2 rho),

one optax step (Adam, with a cosine-decayed step size) on grad_u L per iteration, followed by
the projection onto the box (a clip: the bounds are simple), and the multiplier update
lambda_i <- max(0, lambda_i - rho c_i(u)) (Eq. 17.66 with lambda >= 0).

Why this method:
- the box bounds are exact by projection (no penalty on them, no iterate ever leaves the box);
- the design zone is a narrow diagonal band in (R_end, theta_f) (the contact height
  D/2 - R_end sin(theta_f) must sit between the relief and the upper limit), and a reasonable
  start is often outside it. A log-barrier needs a strictly feasible start and a phase-1 search;
  the augmented Lagrangian accepts infeasible starts and pulls them into the zone;
- unlike a pure quadratic penalty, the multipliers make the constraints exact at a finite
  rho, so the limit point does not sit outside the zone by O(1/rho); the small remaining
  violation is absorbed by tightening the constraints (`DesignProblem.tighten`);
- the constraints are cheap and static, the objective is one dynamic solve per operating point
  with forward-mode gradients (`jaxbearing.design.design_metrics`: faster than checkpointed reverse mode for
  three variables), so every iteration costs one vmapped batch of starts x operating points.

The result is the best *feasible* iterate (every untightened margin > 0) over all starts and
iterations; if the design zone has no point inside the bounds (checked on a dense grid of the
cheap margins before any dynamic solve) or no iterate became feasible, the result says so
(`status`), and the command line exits non-zero.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from jaxbearing import UserInputError
from jaxbearing.design import forward_jacobian
from jaxbearing.flange import DesignVariables, ProfileVariables

from ._lagrangian import Hyper, IterationReport, augmented_lagrangian_step
from ._problem import DesignProblem, any_feasible, halton_points, margins_batch


@dataclasses.dataclass
class SearchResult:
    """Outcome of `search` (numpy arrays; designs in SI units)."""

    status: str  # "ok", "no_feasible_design_in_bounds", "no_feasible_iterate"
    feasible: bool
    design: np.ndarray | None  # (3,) best feasible design x (R_end, theta_f, Delta_bf)
    objective: float  # robust smooth peak PV [GPa m/s] of `design` (nan if none)
    peak_pv: np.ndarray | None  # (K,) per operating point [GPa m/s]
    margins: np.ndarray | None  # (4,) design-zone margins of `design` [m]
    start_design: np.ndarray  # (3,) x of start 0 (the bearing's own design, clipped)
    start_objective: float  # objective of start 0 [GPa m/s]
    start_margins: np.ndarray  # (4,)
    history: dict  # per iteration: u, x (I, S, 3), objective (I, S), margins (I, S, 4),
    #                multipliers (I, S, 4), peak_pv (I, S, K)
    num_model_evaluations: int  # dynamic solves (each with its forward-mode gradient)
    num_iterations: int
    wall_time_s: float
    compile_time_s: float
    best_start: int = -1
    best_iteration: int = -1

    @property
    def improvement(self) -> float:
        """Relative reduction of the objective from start 0 to the result (nan if undefined)."""
        if not (self.feasible and np.isfinite(self.start_objective) and self.start_objective > 0):
            return float("nan")
        return 1.0 - self.objective / self.start_objective


def start_points(problem: DesignProblem, num_starts: int, first: np.ndarray | None = None) -> np.ndarray:
    """Scaled starts (S, n): the bearing's own design (clipped to the bounds, or `first`),
    then a deterministic scrambled-free Halton sequence over the box (bases the first primes)."""

    if first is None:
        own = DesignVariables if problem.num_variables == 3 else ProfileVariables
        first = np.asarray(own.of(problem.bearing).as_array())
    u0 = np.clip(np.asarray(problem.bounds.to_scaled(first)), 0.0, 1.0)
    u = np.concatenate([u0[None], halton_points(num_starts - 1, problem.num_variables)])
    fixed = (problem.bounds.upper - problem.bounds.lower) <= 0
    u[:, fixed] = 0.0
    return u


def _one_iteration(problem: DesignProblem, hyper: Hyper, u, opt_state, lam):
    """One iteration from one start: objective value and forward-mode gradient (one solve per
    operating point carrying three tangents), constraints and their Jacobian (cheap),
    augmented-Lagrangian gradient, optax update, projection onto the box, multiplier update."""
    free = jnp.asarray((problem.bounds.upper - problem.bounds.lower) > 0)
    rho = hyper.rho

    def f(v):
        pv = problem.peak_pv(v)
        return problem.combine(pv), pv

    (val, pv), (g_obj, _) = forward_jacobian(f, u)
    c = problem.constraints(u)
    jc = jax.jacfwd(problem.constraints)(u)  # (4, 3)
    ok = jnp.isfinite(val) & jnp.all(jnp.isfinite(g_obj))
    g_obj = jnp.where(ok, g_obj, 0.0)  # failed solve: follow the constraints only
    u_new, opt_state, act = augmented_lagrangian_step(
        hyper.optimiser(), rho, free, g_obj, c, jc, lam, opt_state, u
    )
    return u_new, opt_state, act, val, pv, problem.margins(u)


@eqx.filter_jit
def _iterate(problem: DesignProblem, hyper: Hyper, u, opt_state, lam):
    """`_one_iteration` vmapped over starts; compiled once per problem structure and hyper."""
    return jax.vmap(_one_iteration, in_axes=(None, None, 0, 0, 0))(problem, hyper, u, opt_state, lam)


@eqx.filter_jit
def _objective_batch(problem: DesignProblem, u):
    """Objective (value only) of a batch of scaled designs (vmapped)."""
    return jax.vmap(problem.objective)(u)


def _without_design(status: str, **fields) -> SearchResult:
    """A `SearchResult` that found no feasible design (`status` says why), with `fields`."""
    return SearchResult(
        status=status,
        feasible=False,
        design=None,
        objective=float("nan"),
        peak_pv=None,
        margins=None,
        **fields,
    )


def search(
    problem: DesignProblem,
    *,
    num_starts: int = 4,
    num_iterations: int = 20,
    learning_rate: float = 0.08,
    rho: float = 10.0,
    starts: np.ndarray | None = None,
    callback: Callable[[int, dict], None] | None = None,
) -> SearchResult:
    """Minimise `problem.objective` inside the design zone from `num_starts` starts in parallel
    (one vmapped batch per iteration); see the module docstring for the method.

    `starts`: optional scaled starts (S, 3) overriding the default start points.
    `callback(iteration, info)` is called after every iteration with numpy arrays
    (u, x, objective, margins, feasible, best) for progress reporting."""
    t_start = time.perf_counter()
    if num_starts < 1:
        raise UserInputError(f"starts = {num_starts}: must be >= 1")
    if num_iterations < 1:
        raise UserInputError(f"iterations = {num_iterations}: must be >= 1")
    u = np.asarray(starts, dtype=float) if starts is not None else start_points(problem, num_starts)
    num_starts = u.shape[0]
    x_start = np.asarray(problem.bounds.from_scaled(u[0]))
    start_margins = np.asarray(margins_batch(problem, jnp.asarray(u[:1])))[0]

    found, _ = any_feasible(problem)
    if not found:
        return _without_design(
            "no_feasible_design_in_bounds",
            start_design=x_start,
            start_objective=float("nan"),
            start_margins=start_margins,
            history={},
            num_model_evaluations=0,
            num_iterations=0,
            wall_time_s=time.perf_counter() - t_start,
            compile_time_s=0.0,
        )

    hyper = Hyper(float(learning_rate), int(num_iterations), float(rho))
    history, best, times = _iterations(problem, hyper, jnp.asarray(u), callback)
    # the first call compiles (unless cached): its excess over the later iterations
    compile_time = max(0.0, times[0] - float(np.median(times[1:]))) if len(times) > 1 else 0.0
    common = dict(
        start_design=x_start,
        start_objective=float(history["objective"][0, 0]),
        start_margins=start_margins,
        history=history,
        num_model_evaluations=(num_iterations + 1) * num_starts * problem.num_operating_points,
        num_iterations=num_iterations,
        wall_time_s=time.perf_counter() - t_start,
        compile_time_s=compile_time,
    )
    if best[1] < 0:
        return _without_design("no_feasible_iterate", **common)
    _, i, s = best
    return SearchResult(
        status="ok",
        feasible=True,
        design=history["x"][i, s],
        objective=best[0],
        peak_pv=history["peak_pv"][i, s],
        margins=history["margins"][i, s],
        best_start=s,
        best_iteration=i,
        **common,
    )


def _iterations(problem: DesignProblem, hyper: Hyper, uj, callback):
    """Run the search from the scaled starts `uj` (S, 3): (history of stacked per-iteration
    arrays, best feasible (objective, iteration, start), wall time of each iteration).
    Iteration i evaluates the objective at u_i (before its update); one extra pass evaluates
    the final iterate."""
    opt_state = jax.vmap(hyper.optimiser().init)(uj)
    lam = jnp.zeros((uj.shape[0], 4))
    times = []
    hist = {k_: [] for k_ in ("u", "x", "objective", "margins", "multipliers", "peak_pv")}
    best = (np.inf, -1, -1)
    for it in range(hyper.num_iterations + 1):
        t_it = time.perf_counter()
        u_new, opt_state_new, lam_new, val, pv, marg = _iterate(problem, hyper, uj, opt_state, lam)
        val, pv, marg = np.asarray(val), np.asarray(pv), np.asarray(marg)
        times.append(time.perf_counter() - t_it)
        x = np.asarray(problem.bounds.from_scaled(uj))
        feas = np.all(marg > 0, axis=1) & np.isfinite(val)
        for s in np.where(feas)[0]:
            if val[s] < best[0]:
                best = (float(val[s]), it, int(s))
        for key, value in (
            ("u", np.asarray(uj)),
            ("x", x),
            ("objective", val),
            ("margins", marg),
            ("multipliers", np.asarray(lam)),
            ("peak_pv", pv),
        ):
            hist[key].append(value)
        if callback is not None:
            callback(it, IterationReport(x=x, objective=val, margins=marg, best=best[0], feasible=feas))
        if it < hyper.num_iterations:
            uj, opt_state, lam = u_new, opt_state_new, lam_new
    return {k_: np.stack(v) for k_, v in hist.items()}, best, times


def grid_search(
    problem: DesignProblem, n_end_radius: int, n_layback: int, axial_clearance: float, *, batch: int = 32
) -> dict:
    """Brute force over an n_end_radius x n_layback grid of (R_end, theta_f) inside the bounds at
    fixed Delta_bf, with the same model as `search` (value only, vmapped batches of `batch`
    designs). Infeasible points are not solved. Returns the grid, objective (nan where
    infeasible), the best feasible point, the number of model evaluations and the wall time."""
    t0 = time.perf_counter()
    lo, hi = problem.bounds.lower, problem.bounds.upper
    r = np.linspace(lo[0], hi[0], n_end_radius)
    t = np.linspace(lo[1], hi[1], n_layback)
    rr, tt = np.meshgrid(r, t, indexing="ij")
    x = np.stack([rr.ravel(), tt.ravel(), np.full(rr.size, axial_clearance)], axis=-1)
    u = np.asarray(problem.bounds.to_scaled(x))
    marg = np.asarray(margins_batch(problem, jnp.asarray(u)))
    feas = np.all(marg > 0, axis=1)
    obj = np.full(len(u), np.nan)
    idx = np.where(feas)[0]
    for j in range(0, len(idx), batch):
        chunk = idx[j : j + batch]
        pad = np.concatenate([chunk, np.repeat(chunk[-1:], batch - len(chunk))])
        obj[chunk] = np.asarray(_objective_batch(problem, jnp.asarray(u[pad])))[: len(chunk)]
    ok = np.isfinite(obj)
    best = int(np.nanargmin(np.where(ok, obj, np.nan))) if ok.any() else -1
    return dict(
        end_radius=r,
        layback_angle=t,
        axial_clearance=axial_clearance,
        objective=obj.reshape(rr.shape),
        feasible=feas.reshape(rr.shape),
        best_design=x[best] if best >= 0 else None,
        best_objective=float(obj[best]) if best >= 0 else float("nan"),
        num_model_evaluations=int(len(idx)),
        wall_time_s=time.perf_counter() - t0,
    )
