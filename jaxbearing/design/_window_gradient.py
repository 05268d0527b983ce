"""The short-window estimator of the gradient of the steady-running design objective
(docs/model.md 17; the objective and the ratio estimator: `_steady_objective`).

Why not the derivative of one long trajectory. Roller-flange impacts make the tangent dynamics
grow: a design perturbation moves impact times, and the tangent of the state grows like
exp(lambda t) with a finite-time Lyapunov exponent lambda of the order of 1e3-1e4 1/s here
(`tangent_growth`; docs/validation.md). The derivative of a long
window average is then dominated by a few impacts and its variance grows like exp(2 lambda T)
(Lea, Allen & Haine 2000, "Sensitivity analysis of the climate of a chaotic system", Tellus
52A: 523, the same failure for the Lorenz system); the design trend is in the ensemble average.

Estimator (ensemble of short windows). From K states of settled running of design d (the seeds'
states after settling and after the window: samples of the invariant measure), integrate a short
window of length T (shorter than the time in which the tangents blow up) with forward-mode
tangents in the three design variables (`diffrax.ForwardMode`, one solve carries the primal and
three tangents), and differentiate the ratio estimator:

    dJ/dd = PV_ref (sum_k dA_k sum_k C_k - sum_k A_k sum_k dC_k) / (sum_k C_k)^2.

Its standard error is the jackknife over the K samples (Efron & Stein 1981). The estimator
neglects the slow part of the response (how the distribution of settled states moves with the
design, e.g. the cage speed or the skew amplitude): its bias against the derivative of the
settled mean is measured against common-random-number central differences of settled runs,
with the window length T and ensemble size K it was measured at (docs/validation.md,
docs/how-to/design-search.md).
"""

from __future__ import annotations

import dataclasses

import diffrax
import jax
import jax.numpy as jnp
import numpy as np

from ..dynamics import State
from ..flange import DesignVariables
from ..geometry import Bearing, OperatingPoint
from ..run import (
    checks_without_host_callbacks,
    compiled_program,
    parallel_map,
    prepare_from,
    result_code,
    scaled_diffeqsolve,
    solve_from,
)
from ._design import forward_jacobian
from ._steady_objective import GRADIENT_WINDOW, SteadyGradient, _check_window, _combine, _design_params


def window_integrals(bearing, op, start: State, x, duration, *, rtol, atol, max_steps, adjoint=None):
    """(A, C, ok) over [0, duration] from `start` with design x = (R_end, theta_f, Delta_bf):
    A = int sum_c w PV_c / PV_ref dt, C = int sum_c w dt (`_steady_objective`); ok = 1.0 where the
    solve succeeded (a float, so forward mode carries it). Pure and jit-able."""
    params = _design_params(bearing, op, x)
    _, final, code, _ = solve_from(
        params, start, duration, num_saves=0, rtol=rtol, atol=atol, max_steps=max_steps, adjoint=adjoint
    )
    acc = final.accumulators
    return jnp.stack([jnp.sum(acc.pv_power), jnp.sum(acc.contact_time), (code == 0).astype(float)])


def _compiled_jacobian(bearing, op, start, x, max_steps: int):
    """(A, C, ok) and their forward-mode Jacobian in x, compiled once per structure
    (`compiled_program`)."""

    def run(b, o, s, x_, d, r, a):
        def f(v):
            return window_integrals(
                b, o, s, v, d, rtol=r, atol=a, max_steps=max_steps, adjoint=diffrax.ForwardMode()
            )

        return forward_jacobian(f, x_)

    f0 = jnp.asarray(1.0)
    return compiled_program("window_jacobian", run, (bearing, op, start, x, f0, f0, f0), max_steps)


@dataclasses.dataclass(frozen=True)
class _WindowSample:
    """Picklable short-window Jacobian of one start state (for `parallel_map`)."""

    bearing: Bearing
    op: OperatingPoint
    x: np.ndarray
    duration: float
    rtol: float
    atol: float
    max_steps: int

    def __call__(self, state) -> tuple[np.ndarray, np.ndarray]:
        start = jax.tree_util.tree_map(jnp.asarray, state)
        x = jnp.asarray(self.x)
        run = _compiled_jacobian(self.bearing, self.op, start, x, self.max_steps)
        val, jac = run(
            self.bearing, self.op, start, x, *map(jnp.asarray, (self.duration, self.rtol, self.atol))
        )
        return np.asarray(val), np.asarray(jac)  # (3,), (3 variables, 3 outputs)


def steady_gradient(
    bearing: Bearing,
    op: OperatingPoint,
    design: DesignVariables,
    states,
    *,
    window: float = GRADIENT_WINDOW,
    rtol: float = 1e-3,
    atol: float = 1e-6,
    max_steps: int = 200_000,
    workers: int = 1,
) -> SteadyGradient:
    """The ensemble short-window estimate (module docstring) of the steady objective and its
    gradient at `design`, from `states` (settled states of this design, e.g.
    `SeedRun.final_state`), each integrated over `window` seconds with three forward-mode
    tangents; `workers` processes share the samples."""
    _check_window(window)
    x = np.asarray(design.as_array(), dtype=float)
    job = _WindowSample(bearing, op, x, float(window), float(rtol), float(atol), int(max_steps))
    outs = parallel_map(job, list(states), workers=workers)
    return _combine([(v[:2] if v[2] > 0.5 else np.full(2, np.nan), j[:, :2]) for v, j in outs], window)


def tangent_growth(
    bearing: Bearing,
    op: OperatingPoint,
    design: DesignVariables,
    start: State,
    duration: float,
    *,
    num_saves: int = 50,
    rtol: float = 1e-3,
    atol: float = 1e-6,
    max_steps: int = 400_000,
):
    """(t (num_saves,), tangent norms (3, num_saves)): the RMS over the scaled state (lengths in
    units of 10 mm, velocities of 10 m/s, angular velocities of 1e4 rad/s;
    `dynamics.SCALED_UNITS`; accumulators excluded) of the forward-mode tangent of the
    trajectory from `start` with respect to each design variable, scaled by that variable
    (d/d ln x). The slope of log(norm) against t is the
    finite-time Lyapunov exponent of the tangent dynamics along the design direction."""
    x = jnp.asarray(design.as_array(), dtype=float)
    ts = jnp.linspace(0.0, duration, num_saves)
    start = jax.tree_util.tree_map(jnp.asarray, start)

    def trajectory(v):
        params = _design_params(bearing, op, v)
        _, args, y0, controller = prepare_from(params, start, rtol, atol)
        saveat = diffrax.SaveAt(ts=ts, fn=lambda t, y, a: dataclasses.replace(y, accumulators=None))
        with checks_without_host_callbacks():
            sol = scaled_diffeqsolve(
                y0, args, duration, saveat, controller, max_steps, diffrax.ForwardMode(), False
            )
        flat = jnp.concatenate(
            [jnp.reshape(leaf, (num_saves, -1)) for leaf in jax.tree_util.tree_leaves(sol.ys)], 1
        )
        return flat, result_code(sol.result)

    @jax.jit
    def run(v):
        def f(w):
            flat, code = trajectory(w)
            return flat, (code == 0).astype(float)

        (flat, ok), (dflat, _) = forward_jacobian(f, v)
        return jnp.sqrt(jnp.mean((dflat * v[:, None, None]) ** 2, axis=-1)), ok

    norms, ok = run(x)
    if float(ok) < 0.5:
        raise RuntimeError("tangent_growth: the solve did not succeed")
    return np.asarray(ts), np.asarray(norms)
