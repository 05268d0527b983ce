"""The gradient of the steady-running design objective (docs/model.md 17).

Objective. The smooth mean flange PV over contact time of settled running,

    J(d) = PV_ref sum_k A_k / sum_k C_k,   A_k = int sum_c w(Q_c) PV_c / PV_ref dt,
                                           C_k = int sum_c w(Q_c) dt,

summed over every roller-end/flange contact c, over the window of each sample k (seeds and
revolutions), with the smooth contact indicator w(Q) = Q / (Q + Q_0), Q_0 = `CONTACT_LOAD`
(`STEADY_FUNCTIONALS`: the accumulators of docs/model.md 13 with p = 1). It is the time average that
flange wear integrates, weighted by contact time: a ratio estimator, so windows with more contact
count more.

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

The tail statistic. The tail mean of PV over contact time, the mean of its worst
1 - alpha = 5 % (the superquantile or conditional value at risk, `run.tail_mean`; the settled
objective is its expectation per cage revolution), has the Rockafellar-Uryasev form
(Rockafellar & Uryasev 2000, J. Risk 2:21)

    T(d) = min_q  q + E[(PV - q)^+] / (1 - alpha),

whose minimiser is the alpha-quantile q*. The derivative at fixed q = q* is the derivative of T
(envelope theorem: the q-derivative vanishes at q*), so the frozen-load estimator applies with
the integrand (PV / PV_ref - q / PV_ref)^+ and the statistics' hard contact indicator
1(Q0 > 1 N) for w: J = q + PV_ref R / (1 - alpha), dJ = PV_ref dR / (1 - alpha), with q the
95th percentile of the touching samples of the estimator's own trajectories (`tail_integrals`),
so that 5 % of them lie above it. An error dq in q changes J by O(dq^2) only. Unlike the
quantile itself, whose derivative E[dPV | PV = q] needs a kernel around q and the few samples
inside it, every sample of the worst 5 % carries the signal.
"""

from __future__ import annotations

import dataclasses

import diffrax
import jax
import jax.numpy as jnp
import numpy as np

from .._errors import UserInputError
from ..contact import LOAD_FLOOR
from ..dynamics import Functionals, Params, State, contact_loads
from ..flange import DesignVariables, with_design
from ..geometry import Bearing, OperatingPoint
from ..io import require
from ..run import (
    CONTACT_THRESHOLD,
    STRATEGIES,
    TAIL_LEVEL,
    checks_without_host_callbacks,
    choose_strategy,
    compiled_program,
    parallel_map,
    prepare_from,
    result_code,
    scaled_diffeqsolve,
    solve_from,
    stack_trees,
)
from ._design import forward_jacobian

#: Q_0 of the smooth contact indicator w(Q) = Q / (Q + Q_0) of the steady objective [N]: the
#: force at which a flange sample counts half (the statistics' hard threshold is 1 N)
CONTACT_LOAD = 1.0
#: the accumulators of the steady objective: p = 1 (the time integral of PV over contact)
STEADY_FUNCTIONALS = Functionals(pv_exponent=1.0, contact_load=CONTACT_LOAD)
#: p of the peak statistic: the p-mean of PV over contact time, PV_ref (sum A_p / sum C)^(1/p),
#: which weights the tail (p = 8: a sample at twice the mean counts 256 times as much)
PEAK_EXPONENT = 8.0
#: the steady objective's statistics and the accumulators their runs integrate: "mean" (p = 1),
#: "peak" (p = `PEAK_EXPONENT`) and "tail" (the tail mean of PV over contact time, the mean of its
#: worst 1 - `TAIL_LEVEL` = 5 %, taken from the saved samples: module docstring, the tail statistic)
STATISTICS = {
    "mean": STEADY_FUNCTIONALS,
    "peak": Functionals(pv_exponent=PEAK_EXPONENT, contact_load=CONTACT_LOAD),
    "tail": STEADY_FUNCTIONALS,
}
#: default window of the short-window sensitivities [s] (docs/validation.md)
GRADIENT_WINDOW = 1.0e-3


def _design_params(bearing: Bearing, op: OperatingPoint, x) -> Params:
    b = with_design(bearing, x[0], x[1], x[2])
    return Params(bearing=b, operating=op, functionals=STEADY_FUNCTIONALS)


def window_integrals(bearing, op, start: State, x, duration, *, rtol, atol, max_steps, adjoint=None):
    """(A, C, ok) over [0, duration] from `start` with design x = (R_end, theta_f, Delta_bf):
    A = int sum_c w PV_c / PV_ref dt, C = int sum_c w dt (module docstring); ok = 1.0 where the
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


@dataclasses.dataclass
class SteadyGradient:
    """The ensemble short-window estimate of J and dJ/d(R_end, theta_f, Delta_bf) (module
    docstring). SI units: J [Pa m/s], gradient [Pa m/s per m, per rad, per m]."""

    value: float
    gradient: np.ndarray  # (3,)
    gradient_stderr: np.ndarray  # (3,) jackknife
    value_stderr: float
    window_s: float
    num_samples: int  # samples that succeeded
    integrals: np.ndarray  # (K, 2): A_k, C_k
    integral_jacobians: np.ndarray  # (K, 3, 2): dA_k/dx_i, dC_k/dx_i
    ok: np.ndarray  # (K,) bool

    @classmethod
    def missing(cls) -> SteadyGradient:
        """No estimate (value-only evaluations): NaN value and gradient, no samples."""
        nan3 = np.full(3, np.nan)
        return cls(
            np.nan, nan3, nan3, np.nan, 0.0, 0, np.zeros((0, 2)), np.zeros((0, 3, 2)), np.zeros(0, bool)
        )


def _check_window(window) -> None:
    require("window", window, lambda v: np.isfinite(v) & (v > 0), "> 0 s and finite")


def paired_central_difference(plus, minus, h: float) -> tuple[float, float, int]:
    """The common-random-number central difference of a settled statistic over paired seeds:
    the mean over seeds k of (J_k(x + h) - J_k(x - h)) / 2h, its standard error
    std_k / sqrt(n) and n, the seeds with both values finite (NaN mean without any, NaN error
    with fewer than two). Each pair shares its seed and starting state, so the seed's scatter
    cancels in the difference."""
    d = (np.asarray(plus, float) - np.asarray(minus, float)) / (2 * h)
    d = d[np.isfinite(d)]
    n = int(d.size)
    mean = float(np.mean(d)) if n else float("nan")
    se = float(np.std(d, ddof=1) / np.sqrt(n)) if n > 1 else float("nan")
    return mean, se, n


def ratio_gradient(a, c, da, dc, pv_reference: float):
    """(J, dJ/dx) of J = PV_ref sum a / sum c from per-sample a (K,), c (K,), da, dc (K, n)."""
    sa, sc = np.sum(a), np.sum(c)
    return pv_reference * sa / sc, pv_reference * (np.sum(da, 0) * sc - sa * np.sum(dc, 0)) / sc**2


def _jackknife_stderr(a, c, da, dc, pv_reference):
    """Jackknife standard errors of (J, dJ/dx) of `ratio_gradient` over the K samples."""
    k = len(a)
    if k < 2:
        return float("nan"), np.full(da.shape[1], np.nan)
    keep = ~np.eye(k, dtype=bool)
    loo = [ratio_gradient(a[m], c[m], da[m], dc[m], pv_reference) for m in keep]
    vals = np.array([v for v, _ in loo])
    grads = np.stack([g for _, g in loo])
    f = (k - 1) / k
    return float(np.sqrt(f * np.sum((vals - vals.mean()) ** 2))), np.sqrt(
        f * np.sum((grads - grads.mean(0)) ** 2, axis=0)
    )


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


def _combine(outs, window, exponent: float = 1.0, tail_threshold: float | None = None) -> SteadyGradient:
    """The ratio estimator and its jackknife from per-sample ((A, C), Jacobian (3, 2)); a
    failed sample carries NaN and is left out. With `exponent` p (A the integral of
    (PV/PV_ref)^p): J = PV_ref R^(1/p) with R = sum A / sum C, dJ = J dR / (p R), and the
    standard errors by the same factor (delta method). With `tail_threshold` q [Pa m/s] (A the
    integral of (PV/PV_ref - q/PV_ref)^+): the tail mean's Rockafellar-Uryasev form
    J = q + PV_ref R / (1 - alpha), dJ = PV_ref dR / (1 - alpha) at fixed q, alpha = `TAIL_LEVEL`
    (module docstring, the tail statistic)."""
    if not outs:  # no states given
        return dataclasses.replace(SteadyGradient.missing(), window_s=float(window))
    vals = np.stack([v for v, _ in outs])  # (K, 2): A, C
    jacs = np.stack([j for _, j in outs])  # (K, 3 variables, 2 outputs)
    ok = np.all(np.isfinite(vals), axis=1) & np.all(np.isfinite(jacs), axis=(1, 2))
    a, c = vals[ok, 0], vals[ok, 1]
    da, dc = jacs[ok, :, 0], jacs[ok, :, 1]
    pv_ref = STEADY_FUNCTIONALS.pv_reference
    if not ok.any() or np.sum(c) <= 0:
        nan3 = np.full(3, np.nan)
        return SteadyGradient(
            float("nan"), nan3, nan3, float("nan"), float(window), int(ok.sum()), vals, jacs, ok
        )
    value, grad = ratio_gradient(a, c, da, dc, pv_ref)
    value_se, grad_se = _jackknife_stderr(a, c, da, dc, pv_ref)
    if tail_threshold is not None:  # value = PV_ref R above
        scale = 1.0 / (1.0 - TAIL_LEVEL)
        value, grad = tail_threshold + scale * value, scale * grad
        value_se, grad_se = scale * value_se, scale * grad_se
    elif exponent != 1.0:  # value = PV_ref R above
        j = pv_ref * (value / pv_ref) ** (1.0 / exponent)
        factor = j / (exponent * value)
        value, grad, value_se, grad_se = j, grad * factor, value_se * factor, grad_se * factor
    return SteadyGradient(
        value=float(value),
        gradient=grad,
        gradient_stderr=grad_se,
        value_stderr=value_se,
        window_s=float(window),
        num_samples=int(ok.sum()),
        integrals=vals,
        integral_jacobians=jacs,
        ok=ok,
    )


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


# -- the frozen-load estimator ---------------------------------------------------------------
def trajectory_states(
    bearing, op, start: State, duration: float, num_saves: int, *, rtol=1e-3, atol=1e-6, max_steps=400_000
):
    """The physical states at `num_saves` equally spaced times in (0, duration] of a plain
    solve from `start` (a State with a leading time axis on every leaf)."""
    params = Params(bearing=bearing, operating=op, functionals=STEADY_FUNCTIONALS)
    scaling, args, y0, controller = prepare_from(
        params, jax.tree_util.tree_map(jnp.asarray, start), rtol, atol
    )
    ts = jnp.linspace(0.0, duration, num_saves + 1)[1:]
    saveat = diffrax.SaveAt(ts=ts, fn=lambda t, y, a: a.scaling.unscale(t, y))
    with checks_without_host_callbacks():
        sol = scaled_diffeqsolve(y0, args, duration, saveat, controller, max_steps, None, False)
    return sol.ys, result_code(sol.result)


def _failed_integrals() -> tuple[np.ndarray, np.ndarray]:
    """The ((A, C), Jacobian (3, 2)) of a failed trajectory: NaN, left out by `_combine`."""
    return np.full(2, np.nan), np.full((3, 2), np.nan)


def _reference_loads(bearing, op, x, states):
    """The flange contact loads Q0 (T, Z, 4) the dynamics gave at the saved `states` (a leading
    time axis) of design x: the loads the frozen-load estimator holds."""
    return jax.vmap(lambda s: contact_loads(s, _design_params(bearing, op, x)).flange.normal_force)(states)


def frozen_pv(bearing, op, x, state: State, reference_load):
    """(w(Q0_c), PV_c(x) (Q0_c / Q_c(x))^(1/3) / PV_ref), each (Z, 4), over the flange contacts of
    one state: the flange PV with design x at the loads Q0 = `reference_load` (Z, 4) the
    dynamics gave (module docstring, frozen-load estimator), and the smooth contact indicator.
    Hertz: p_max = c(radii) Q^(1/3), so PV (Q0/Q)^(1/3) is the PV at load Q0 with the contact
    point, curvatures and sliding velocity of design x."""
    fl = contact_loads(state, _design_params(bearing, op, x)).flange
    q0 = reference_load
    on = (q0 > LOAD_FLOOR) & (fl.normal_force > LOAD_FLOOR)
    safe_q = jnp.where(on, fl.normal_force, 1.0)
    ratio = jnp.where(on, (jnp.where(on, q0, 1.0) / safe_q) ** (1.0 / 3.0), 0.0)
    w = q0 / (q0 + STEADY_FUNCTIONALS.contact_load)
    return w, fl.pv * ratio / STEADY_FUNCTIONALS.pv_reference


def frozen_load_integrands(bearing, op, x, state: State, reference_load, exponent=1.0):
    """(sum_c w(Q0_c) (PV_c(x) (Q0_c / Q_c(x))^(1/3) / PV_ref)^p, sum_c w(Q0_c)) over the flange
    contacts of one state, p = `exponent` (`frozen_pv`)."""
    w, frozen = frozen_pv(bearing, op, x, state, reference_load)
    return jnp.stack([jnp.sum(w * frozen**exponent), jnp.sum(w)])


def frozen_tail_samples(bearing, op, x, states):
    """The tail statistic's samples along one trajectory (`states`: a leading time axis): per
    saved state and flange contact, the statistics' hard contact indicator 1(Q0 > 1 N), the
    frozen PV / PV_ref at x (`frozen_pv`) and its Jacobian in x (leading axis 3)."""
    q0 = _reference_loads(bearing, op, x, states)
    pv, dpv = forward_jacobian(
        lambda v: jax.vmap(lambda s, q: frozen_pv(bearing, op, v, s, q)[1])(states, q0), x
    )
    return (q0 > CONTACT_THRESHOLD).astype(float), pv, dpv


def tail_integrals(samples) -> tuple[list, float]:
    """The tail statistic's per-trajectory integrals from `frozen_tail_samples` of every
    trajectory of one design ((w, pv, dpv) each, or None for a failed one): q, the 95th
    percentile of the frozen PV / PV_ref over every touching sample, and per trajectory
    ((A, C), Jacobian (3, 2)) with A = sum w (pv - q)^+, C = sum w, dA = sum w 1(pv > q) dpv
    (the Rockafellar-Uryasev form at fixed q, module docstring). Returns (outs, q)."""
    touching = [np.asarray(pv)[np.asarray(w) > 0.5] for w, pv, _ in filter(None, samples)]
    pooled = np.concatenate(touching) if touching else np.zeros(0)
    if pooled.size == 0:
        return [_failed_integrals() for _ in samples], float("nan")
    q = float(np.percentile(pooled, 100.0 * TAIL_LEVEL))
    outs = []
    for sample in samples:
        if sample is None:
            outs.append(_failed_integrals())
            continue
        w, pv, dpv = (np.asarray(a) for a in sample)
        above = w * (pv > q)
        a = float(np.sum(w * np.maximum(pv - q, 0.0)))
        da = np.sum(above[None] * dpv, axis=tuple(range(1, dpv.ndim)))
        outs.append((np.array([a, float(np.sum(w))]), np.stack([da, np.zeros(3)], axis=1)))
    return outs, q


@dataclasses.dataclass(frozen=True)
class _FrozenSample:
    """Picklable frozen-load integrals and Jacobians along one trajectory (`parallel_map`)."""

    bearing: Bearing
    op: OperatingPoint
    x: np.ndarray
    duration: float
    num_saves: int
    rtol: float
    exponent: float = 1.0
    tail: bool = False  # the tail statistic's samples (`frozen_tail_samples`) instead of sums

    def __call__(self, state):
        x = jnp.asarray(self.x)
        state = jax.tree_util.tree_map(jnp.asarray, state)
        num_saves = self.num_saves
        args = (self.bearing, self.op, state, jnp.asarray(self.duration), jnp.asarray(self.rtol))
        trajectory = lambda b, o, s, d, r: trajectory_states(b, o, s, d, num_saves, rtol=r)
        states, code = compiled_program("trajectory_states", trajectory, args, num_saves)(*args)
        if int(code) != 0:  # a failed trajectory: no samples (tail), NaN integrals (sums)
            return None if self.tail else _failed_integrals()
        if self.tail:
            args = (self.bearing, self.op, x, states)
            return tuple(
                map(np.asarray, compiled_program("frozen_tail_samples", frozen_tail_samples, args)(*args))
            )
        args = (self.bearing, self.op, x, states, np.float64(self.exponent))
        val, jac = compiled_program("frozen_load_jacobian", _frozen_jacobian, args)(*args)
        return np.asarray(val), np.asarray(jac)


def _frozen_jacobian(bearing, op, x, states, exponent=1.0):
    """Sum over the saved states of the frozen-load integrands (`frozen_load_integrands`) and
    their Jacobian in x."""
    q0 = _reference_loads(bearing, op, x, states)

    def total(v):
        per = jax.vmap(lambda s, q: frozen_load_integrands(bearing, op, v, s, q, exponent))(states, q0)
        return jnp.sum(per, axis=0)

    return forward_jacobian(total, x)


def frozen_load_gradient(
    bearing: Bearing,
    op: OperatingPoint,
    design: DesignVariables,
    states,
    *,
    window: float = 1.0e-3,
    saves_per_ms: int = 200,
    rtol: float = 1e-3,
    workers: int = 1,
    strategy: str = "auto",
    statistic: str = "mean",
) -> SteadyGradient:
    """The frozen-load estimate (module docstring) of the steady objective and its gradient at
    `design`: from each of `states`, a plain solve over `window` seconds saves the state every
    1 / `saves_per_ms` ms; at every saved state the flange PV is differentiated in the design at
    the loads the dynamics gave (`frozen_load_integrands`), summed, and combined through the
    ratio estimator; jackknife over the trajectories. `statistic`: "mean" (PV over contact
    time), "peak" (its p-mean) or "tail" (the mean of its worst 5 %, at the 95th percentile of the
    trajectories' own touching samples: `tail_integrals`; `STATISTICS`); `strategy`: as
    `frozen_load_gradients`."""
    forwarded = {k: v for k, v in locals().items() if k not in ("bearing", "op", "design", "states")}
    (gradient,) = frozen_load_gradients([(bearing, op, design, states)], **forwarded)
    return gradient


def frozen_load_gradients(
    cases,
    *,
    window: float = 1.0e-3,
    saves_per_ms: int = 200,
    rtol: float = 1e-3,
    workers: int = 1,
    strategy: str = "auto",
    statistic: str = "mean",
) -> list[SteadyGradient]:
    """`frozen_load_gradient` of every case (bearing, op, design, states), e.g. every start and
    operating point of one iteration of the design search; one `SteadyGradient` per case, in
    order. Each case's trajectories run with `design` applied to `bearing` (its other parameters
    kept) from `states`, states of settled running of that design. Every trajectory of every
    case is one member of one call (`strategy`, as the steady-running engine's
    `choose_strategy`): "vmap" (the default on an accelerator) integrates and differentiates
    them all in one vmapped program; on a CPU they run `workers` processes at a time
    ("processes"), or one after another ("sequential")."""
    _check_window(window)
    require("saves_per_ms", saves_per_ms, lambda v: (v >= 1) & (v == np.round(v)), "an integer >= 1")
    if strategy not in STRATEGIES:
        raise UserInputError(f"strategy = {strategy!r}: must be one of {', '.join(map(repr, STRATEGIES))}")
    exponent = float(_functionals(statistic).pv_exponent)
    tail = statistic == "tail"
    cases = list(cases)
    n = max(1, int(round(window * 1e3 * saves_per_ms)))
    jobs, owner = [], []
    for k, (bearing, op, design, states) in enumerate(cases):
        x = np.asarray(design.as_array(), dtype=float)
        # the trajectories run with the design, as the settled states did: a bearing of another
        # design would start every window off its contacts (micrometres against a changed end arc)
        job = _FrozenSample(design.apply(bearing), op, x, float(window), n, float(rtol), exponent, tail)
        jobs += [(job, s) for s in states]
        owner += [k] * len(states)
    chosen = choose_strategy(strategy, min(int(workers), max(1, len(jobs))))
    if not jobs:
        outs = []
    elif chosen == "vmap":
        outs = _frozen_samples_batched(jobs)
    else:
        outs = parallel_map(_frozen_job, jobs, workers=workers if chosen == "processes" else 1)
    per_case = [[o for o, j in zip(outs, owner) if j == k] for k in range(len(cases))]
    if not tail:
        return [_combine(o, window, exponent) for o in per_case]
    found = []
    for o in per_case:
        integrals, q = tail_integrals(o)
        found.append(_combine(integrals, window, tail_threshold=q * STEADY_FUNCTIONALS.pv_reference))
    return found


def _functionals(statistic: str) -> Functionals:
    """The accumulators of the steady objective's `statistic` (`STATISTICS`), or a one-line error."""
    if statistic not in STATISTICS:
        raise UserInputError(f"statistic = {statistic!r}: must be one of {', '.join(map(repr, STATISTICS))}")
    return STATISTICS[statistic]


def _frozen_job(item):
    """One (`_FrozenSample`, state) of `frozen_load_gradients` (picklable for `parallel_map`)."""
    job, state = item
    return job(state)


def _frozen_samples_batched(jobs) -> list:
    """Every (`_FrozenSample`, state) of `jobs` as one member of one vmapped program: its
    trajectory and the frozen-load integrals and Jacobian along it."""
    num_saves, tail = jobs[0][0].num_saves, jobs[0][0].tail

    def one(b, o, x, s, d, r, p):
        states, code = trajectory_states(b, o, s, d, num_saves, rtol=r)
        if tail:
            return frozen_tail_samples(b, o, x, states), code
        return _frozen_jacobian(b, o, x, states, p), code

    args = stack_trees(
        [
            (
                job.bearing,
                job.op,
                jnp.asarray(job.x),
                state,
                np.float64(job.duration),
                np.float64(job.rtol),
                np.float64(job.exponent),
            )
            for job, state in jobs
        ]
    )
    name = "frozen_tail_members" if tail else "frozen_load_members"
    outs, codes = jax.device_get(compiled_program(name, jax.vmap(one), args, num_saves)(*args))
    if tail:
        return [tuple(a[i] for a in outs) if int(codes[i]) == 0 else None for i in range(len(jobs))]
    vals, jacs = outs
    return [(vals[i], jacs[i]) if int(codes[i]) == 0 else _failed_integrals() for i in range(len(jobs))]
