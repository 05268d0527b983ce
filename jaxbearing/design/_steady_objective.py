"""The steady-running design objective, its statistics and the ratio estimator that both of its
gradient estimators (`_window_gradient`, `_frozen_load`) combine their samples with
(docs/model.md 17).

Objective. The smooth mean flange PV over contact time of settled running,

    J(d) = PV_ref sum_k A_k / sum_k C_k,   A_k = int sum_c w(Q_c) PV_c / PV_ref dt,
                                           C_k = int sum_c w(Q_c) dt,

summed over every roller-end/flange contact c, over the window of each sample k (seeds and
revolutions), with the smooth contact indicator w(Q) = Q / (Q + Q_0), Q_0 = `CONTACT_LOAD`
(`STEADY_FUNCTIONALS`: the accumulators of docs/model.md 13 with p = 1). It is the time average that
flange wear integrates, weighted by contact time: a ratio estimator, so windows with more contact
count more.

Ratio estimator. From per-sample integrals A_k, C_k and their derivatives in the design,

    dJ/dd = PV_ref (sum_k dA_k sum_k C_k - sum_k A_k sum_k dC_k) / (sum_k C_k)^2,

with standard errors from the jackknife over the K samples (Efron & Stein 1981).

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

The friction statistic. The time-mean total flange friction power of settled running,

    P(d) = P_ref sum_k A_k / sum_k C_k,   A_k = int sum_c mu_c Q_c |u_c| / P_ref dt,
                                          C_k = int 1 dt,

over every contact c (docs/model.md 5.5; P_ref = `FRICTION_REFERENCE` = 1 W): the same ratio
estimator with a plain time average (C = the window's length, every sample counts).
"""

from __future__ import annotations

import dataclasses
import enum

import numpy as np

from .._errors import UserInputError
from ..dynamics import Functionals, Params
from ..flange import variables_from_array, with_design
from ..geometry import Bearing, OperatingPoint
from ..io import require
from ..run import TAIL_LEVEL

#: Q_0 of the smooth contact indicator w(Q) = Q / (Q + Q_0) of the steady objective [N]: the
#: force at which a flange sample counts half (the statistics' hard threshold is 1 N)
CONTACT_LOAD = 1.0
#: the accumulators of the steady objective: p = 1 (the time integral of PV over contact)
STEADY_FUNCTIONALS = Functionals(pv_exponent=1.0, contact_load=CONTACT_LOAD)
#: p of the peak statistic: the p-mean of PV over contact time, PV_ref (sum A_p / sum C)^(1/p),
#: which weights the tail (p = 8: a sample at twice the mean counts 256 times as much)
PEAK_EXPONENT = 8.0
#: P_ref of the friction statistic's integrand [W] (module docstring, the friction statistic)
FRICTION_REFERENCE = 1.0


class Statistic(enum.StrEnum):
    """The statistic a steady objective measures (module docstring): of flange PV, `MEAN` over
    contact time (p = 1), `PEAK` (the p-mean, p = `PEAK_EXPONENT`) or `TAIL` (the tail mean of
    PV over contact time, the mean of its worst 1 - `TAIL_LEVEL` = 5 %, from the saved
    samples); or `FRICTION`, the time-mean total flange friction power. Its value is the name
    the command line and the TOML files use."""

    MEAN = "mean"
    PEAK = "peak"
    TAIL = "tail"
    FRICTION = "friction"

    @property
    def reference(self) -> float:
        """The SI reference the statistic's integrand is divided by: PV_ref [Pa m/s] or
        `FRICTION_REFERENCE` [W]."""
        return FRICTION_REFERENCE if self is Statistic.FRICTION else STEADY_FUNCTIONALS.pv_reference

    @property
    def shown(self) -> tuple[float, str]:
        """(factor, unit) the statistic is printed and stored in: its SI value divided by the
        factor is in the unit (GPa m/s for PV, W for friction power)."""
        return (1.0, "W") if self is Statistic.FRICTION else (1e9, "GPa m/s")

    @property
    def key(self) -> str:
        """The key a results file stores the statistic's value under, unit in the name:
        "objective_GPa_m_s" or "objective_W"."""
        return "objective_" + self.shown[1].replace(" ", "_").replace("/", "_")


#: the accumulators each statistic's runs integrate
STATISTICS = {
    Statistic.MEAN: STEADY_FUNCTIONALS,
    Statistic.PEAK: Functionals(pv_exponent=PEAK_EXPONENT, contact_load=CONTACT_LOAD),
    Statistic.TAIL: STEADY_FUNCTIONALS,
    Statistic.FRICTION: STEADY_FUNCTIONALS,
}
#: default window of the short-window sensitivities [s] (docs/validation.md)
GRADIENT_WINDOW = 1.0e-3


def _design_params(bearing: Bearing, op: OperatingPoint, x) -> Params:
    b = (
        with_design(bearing, x[0], x[1], x[2])
        if np.shape(x)[-1] == 3
        else variables_from_array(x).apply(bearing)
    )
    return Params(bearing=b, operating=op, functionals=STEADY_FUNCTIONALS)


@dataclasses.dataclass
class SteadyGradient:
    """The ensemble short-window estimate of J and its gradient in the n design variables
    (module docstring): (R_end, theta_f, Delta_bf), or the eight of a `flange.ProfileVariables`.
    SI units: J [Pa m/s], gradient [Pa m/s per m, per rad, per m, per 1/m]."""

    value: float
    gradient: np.ndarray  # (n,)
    gradient_stderr: np.ndarray  # (n,) jackknife
    value_stderr: float
    window_s: float
    num_samples: int  # samples that succeeded
    integrals: np.ndarray  # (K, 2): A_k, C_k
    integral_jacobians: np.ndarray  # (K, 3, 2): dA_k/dx_i, dC_k/dx_i
    ok: np.ndarray  # (K,) bool

    @classmethod
    def missing(cls, num_variables: int = 3) -> SteadyGradient:
        """No estimate (value-only evaluations): NaN value and gradient, no samples."""
        nan = np.full(num_variables, np.nan)
        return cls(
            np.nan,
            nan,
            nan,
            np.nan,
            0.0,
            0,
            np.zeros((0, 2)),
            np.zeros((0, num_variables, 2)),
            np.zeros(0, bool),
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


def ratio_gradient(a, c, da, dc, reference: float):
    """(J, dJ/dx) of J = reference sum a / sum c from per-sample a (K,), c (K,), da, dc (K, n)."""
    sa, sc = np.sum(a), np.sum(c)
    return reference * sa / sc, reference * (np.sum(da, 0) * sc - sa * np.sum(dc, 0)) / sc**2


def _jackknife_stderr(a, c, da, dc, reference):
    """Jackknife standard errors of (J, dJ/dx) of `ratio_gradient` over the K samples."""
    k = len(a)
    if k < 2:
        return float("nan"), np.full(da.shape[1], np.nan)
    keep = ~np.eye(k, dtype=bool)
    loo = [ratio_gradient(a[m], c[m], da[m], dc[m], reference) for m in keep]
    vals = np.array([v for v, _ in loo])
    grads = np.stack([g for _, g in loo])
    f = (k - 1) / k
    return float(np.sqrt(f * np.sum((vals - vals.mean()) ** 2))), np.sqrt(
        f * np.sum((grads - grads.mean(0)) ** 2, axis=0)
    )


def _combine(
    outs,
    window,
    exponent: float = 1.0,
    tail_threshold: float | None = None,
    num_variables: int = 3,
    reference: float = STEADY_FUNCTIONALS.pv_reference,
) -> SteadyGradient:
    """The ratio estimator and its jackknife from per-sample ((A, C), Jacobian (n, 2)); a
    failed sample carries NaN and is left out. With `exponent` p (A the integral of
    (PV/PV_ref)^p): J = PV_ref R^(1/p) with R = sum A / sum C, dJ = J dR / (p R), and the
    standard errors by the same factor (delta method). With `tail_threshold` q [Pa m/s] (A the
    integral of (PV/PV_ref - q/PV_ref)^+): the tail mean's Rockafellar-Uryasev form
    J = q + PV_ref R / (1 - alpha), dJ = PV_ref dR / (1 - alpha) at fixed q, alpha = `TAIL_LEVEL`
    (module docstring, the tail statistic). `reference`: the integrand's reference (PV_ref, or
    P_ref of the friction statistic)."""
    if not outs:  # no states given
        return dataclasses.replace(SteadyGradient.missing(num_variables), window_s=float(window))
    vals = np.stack([v for v, _ in outs])  # (K, 2): A, C
    jacs = np.stack([j for _, j in outs])  # (K, n variables, 2 outputs)
    ok = np.all(np.isfinite(vals), axis=1) & np.all(np.isfinite(jacs), axis=(1, 2))
    a, c = vals[ok, 0], vals[ok, 1]
    da, dc = jacs[ok, :, 0], jacs[ok, :, 1]
    if not ok.any() or np.sum(c) <= 0:
        nan = np.full(jacs.shape[1], np.nan)
        return SteadyGradient(
            float("nan"), nan, nan, float("nan"), float(window), int(ok.sum()), vals, jacs, ok
        )
    value, grad = ratio_gradient(a, c, da, dc, reference)
    value_se, grad_se = _jackknife_stderr(a, c, da, dc, reference)
    if tail_threshold is not None:  # value = reference R above
        scale = 1.0 / (1.0 - TAIL_LEVEL)
        value, grad = tail_threshold + scale * value, scale * grad
        value_se, grad_se = scale * value_se, scale * grad_se
    elif exponent != 1.0:  # value = reference R above
        j = reference * (value / reference) ** (1.0 / exponent)
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


def statistic_of(value: Statistic | str) -> Statistic:
    """`value` as a `Statistic` (the command line's and the TOML files' name maps here), or a
    one-line error naming the valid ones."""
    try:
        return Statistic(value)
    except ValueError:
        raise UserInputError(
            f"statistic = {value!r}: must be one of {', '.join(repr(s.value) for s in Statistic)}"
        ) from None


def _functionals(statistic: Statistic | str) -> Functionals:
    """The accumulators of the steady objective's `statistic` (`STATISTICS`), or a one-line error."""
    return STATISTICS[statistic_of(statistic)]


def _failed_integrals(num_variables: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """The ((A, C), Jacobian (n, 2)) of a failed trajectory: NaN, left out by `_combine`."""
    return np.full(2, np.nan), np.full((num_variables, 2), np.nan)
