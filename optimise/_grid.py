"""The steady objective over a grid of (R_end, theta_f) at fixed Delta_bf: the gradient-free
comparison for `steady_search`, resumable (docs/how-to/design-search.md)."""

from __future__ import annotations

import pathlib
import time
from collections.abc import Callable

import jax.numpy as jnp
import numpy as np

from jaxbearing import UserInputError

from ._evaluate import evaluate, in_shared_pool
from ._problem import DesignProblem
from ._settings import SteadySettings
from ._state import load_checkpoint, refuse_legacy, save_checkpoint


@in_shared_pool
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
        refuse_legacy(path.with_name("grid_checkpoint.pkl"))
    done = (
        load_checkpoint(path) if path is not None and path.exists() else {"fingerprint": "grid", "state": {}}
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
                save_checkpoint(path, "grid", done)
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
