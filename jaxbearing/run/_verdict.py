"""The settling verdict: whether the cage speed of a settled run has stopped drifting
(docs/model.md 16).

Near its plateau the revolution-mean cage speed relaxes along the slow mode of the cage,
omega - omega_inf = -tau d omega/dt, so the drift still to come is |b| tau, with b the slope of a
least-squares line through the last revolution means and tau the running slow mode's time
constant. The run counts as settled when the one-sided 95 % upper bound of that drift is within
the settling tolerance of the cage speed.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import stats as _sp_stats

from ..geometry import Bearing, OperatingPoint
from ._initial import Perturbation, skid_start

#: the settling verdict (`settling_verdict`): a line through the revolution-mean cage speeds of at
#: least `VERDICT_MIN_REVS` and at most `VERDICT_MAX_REVS` revolutions since the last projective step
VERDICT_MIN_REVS = 4
VERDICT_MAX_REVS = 8
#: one-sided confidence of the verdict's upper bound on the remaining drift
VERDICT_CONFIDENCE = 0.95
#: the verdict's running slow mode, in multiples of the static tau_s (`running_time_constant`)
RUNNING_SLOW_MODE_FACTOR = 1.5


@dataclasses.dataclass(frozen=True)
class Verdict:
    """`settling_verdict`'s answer. `residual_drift_rpm`: how far the cage speed still has to go
    on its slow mode, |slope| tau_run (nan before `VERDICT_MIN_REVS` revolutions); `bound_rpm`:
    its one-sided 95 % upper bound (slope + t SE); `slope_rpm_s`, `slope_se_rpm_s`: the line's
    slope and standard error; `revolutions`: how many revolutions the line ran through."""

    settled: bool
    residual_drift_rpm: float
    bound_rpm: float
    slope_rpm_s: float
    slope_se_rpm_s: float
    revolutions: int
    time_constant_s: float


def settling_verdict(centres, speeds, tolerance: float, time_constant: float) -> Verdict:
    """Whether the revolution-mean cage speeds `speeds` [rpm] at revolution centres `centres`
    [s] (those since the last projective step, oldest first) have settled (docs/model.md 16):
    the least-squares line through the last `VERDICT_MAX_REVS` of them (at least
    `VERDICT_MIN_REVS`) has slope b +/- SE; near its plateau the cage speed relaxes along its slow
    mode, omega - omega_inf = -tau b, so the remaining drift is |b| tau with tau =
    `time_constant` [s] (a conservative estimate of the running slow mode). Settled when the
    one-sided 95 % upper bound (|b| + t_{n-2, 0.95} SE) tau is at most `tolerance` times the
    last speed. Pure, host-side (numpy)."""
    t = np.asarray(centres, float)[-VERDICT_MAX_REVS:]
    w = np.asarray(speeds, float)[-VERDICT_MAX_REVS:]
    n = t.size
    nan = float("nan")
    if n < VERDICT_MIN_REVS:
        return Verdict(False, nan, nan, nan, nan, n, float(time_constant))
    tc = t - t.mean()
    sxx = float(np.sum(tc * tc))
    slope = float(np.sum(tc * (w - w.mean())) / sxx)
    resid = w - w.mean() - slope * tc
    se = float(np.sqrt(np.sum(resid * resid) / (n - 2) / sxx))
    q = float(_sp_stats.t.ppf(VERDICT_CONFIDENCE, n - 2))
    drift = abs(slope) * time_constant
    bound = (abs(slope) + q * se) * time_constant
    return Verdict(bool(bound <= tolerance * abs(w[-1])), drift, bound, slope, se, n, float(time_constant))


def running_time_constant(skid, bearing: Bearing, op: OperatingPoint, perturbation: Perturbation) -> float:
    """The running slow mode's time constant [s] the verdict uses (`settling_verdict`,
    docs/model.md 16): `RUNNING_SLOW_MODE_FACTOR` times the static slow mode's tau_s
    (`dynamics.cage_time_constant` at the static skid equilibrium of this seed; `skid`, a
    `SkidStart`, carries it, else it is solved here, as for the quasi-static start), or the
    longest positive secant of the pre-start's measured drifts if that is longer (every secant,
    also those the pre-start's own steps rejected: a static balance far from the running state,
    e.g. a misaligned one before its quasi-static start knew the tilt, gave tau_s = 0.19 ms)."""
    if skid is None:
        skid = skid_start(bearing, op, perturbation)
    tau_s = float(skid.static_time_constant)
    if not math.isfinite(tau_s):
        tau_s = float(skid.time_constant)
    tau = RUNNING_SLOW_MODE_FACTOR * tau_s
    w, g = np.asarray(skid.drift_speeds, float), np.asarray(skid.drifts, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        secants = -np.diff(w) / np.diff(g)
    secants = secants[np.isfinite(secants) & (secants > 0)]
    return float(max(tau, *secants)) if secants.size else float(tau)
