"""The corner-contact risk from a few revolutions: a normal model of the per-revolution largest
contact radius and its one-sided tolerance bound (docs/model.md 16, "Corner-contact risk").

Of the revolutions with flange contact, the largest contact radius M of a revolution is taken
as normal with mean mu and standard deviation sigma (estimated by m and s over the n such
revolutions), so that

    p = P(M > L) = Phi(-(L - mu) / sigma)

at a limit L (the limited-circle radius rho_lim). Revolutions without flange contact cannot
reach the corner, so p is an upper value of the unconditional risk. The bounds of p follow from
those of z_p = (L - mu) / sigma: with k = (L - m) / s, the one-sided bound at confidence gamma

    p_U = Phi(-z_L),   z_L the z whose tolerance factor (below) is k,

exactly through the noncentral t, or where scipy's noncentral t gives no finite value its normal
approximation z_L = k - z_gamma sqrt(1 / n + k^2 / (2 (n - 1))) (Bissell 1990, "How reliable is
your capability index?", Appl. Stat. 39:331, for the equivalent bound of C_pk; Hahn & Meeker
1991, Statistical Intervals, sec. 4.4 and 4.6); the lower bound the same at 1 - gamma. So
the design keeps p <= `level` at confidence gamma exactly when

    m + k_tol s <= L,    k_tol = t'_{gamma}(n - 1, z_{1-level} sqrt(n)) / sqrt(n),

the exact one-sided normal tolerance factor (the gamma quantile of the noncentral t with
noncentrality z_{1-level} sqrt(n); Hahn & Meeker 1991, sec. 4.6): the margin form the design
search constrains (`tolerance_bound`). Revolutions of one member are not independent: n is the
effective sample n / deff, deff = 1 + (n0 - 1) rho with rho the intra-member correlation of M
(one-way analysis of variance, clipped to [0, 1]; Kish 1965, Survey Sampling, sec. 5.4) and n0
the revolutions per member.

The model is an assumption about the tail: it is checked where corner contact is frequent enough
to count (docs/model.md 16) and, unlike the counts, it bounds a small p from few revolutions.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import optimize, stats

#: fewest revolutions with contact the normal model is fitted to
MIN_NORMAL_REVOLUTIONS = 3


@dataclasses.dataclass(frozen=True)
class NormalTail:
    """The normal model of the per-revolution maxima (module docstring): `mean_m`, `std_m` over
    `revolutions` revolutions with contact, `effective` revolutions n / deff, `design_effect`
    deff, and the standardised distance `k` = (L - mean) / std to the limit."""

    mean_m: float
    std_m: float
    revolutions: int
    effective: float
    design_effect: float
    k: float

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def _in_contact(rows) -> list[np.ndarray]:
    return [np.asarray(r, float)[np.asarray(r, float) > 0] for r in rows]


def design_effect(rows) -> float:
    """deff = 1 + (n0 - 1) rho of the members' revolutions (module docstring); 1 with one member
    or one revolution per member."""
    rows = [r for r in rows if r.size]
    sizes = np.array([r.size for r in rows], float)
    n, g = float(sizes.sum()), len(rows)
    if g < 2 or n <= g:
        return 1.0
    grand = np.concatenate(rows).mean()
    msb = sum(r.size * (r.mean() - grand) ** 2 for r in rows) / (g - 1)
    msw = sum(((r - r.mean()) ** 2).sum() for r in rows) / (n - g)
    n0 = (n - (sizes**2).sum() / n) / (g - 1)
    rho = (msb - msw) / (msb + (n0 - 1) * msw) if msb + (n0 - 1) * msw > 0 else 0.0
    return float(1.0 + (n0 - 1.0) * min(max(rho, 0.0), 1.0))


def normal_tail(rows, limit: float) -> NormalTail | None:
    """The normal model of the per-member maxima `rows` (one array per member; 0: a revolution
    without contact, left out) against `limit`; None with fewer than `MIN_NORMAL_REVOLUTIONS`
    revolutions in contact or no spread."""
    rows = _in_contact(rows)
    values = np.concatenate(rows) if rows else np.zeros(0)
    n = int(values.size)
    if n < MIN_NORMAL_REVOLUTIONS:
        return None
    m, s = float(values.mean()), float(values.std(ddof=1))
    if not s > 1e-12 * abs(m):  # all alike (to round-off): no spread to fit
        return None
    deff = design_effect(rows)
    effective = max(n / deff, 2.0)
    return NormalTail(m, s, n, effective, deff, (float(limit) - m) / s)


def _z_bound(k: float, n: float, confidence: float) -> float:
    """The bound of z_p = (L - mu)/sigma at `confidence` from the sample's k on n revolutions:
    the z whose tolerance factor is k (exact: the noncentral t, `_factor`), or where scipy's
    noncentral t gives no finite value, its normal approximation (module docstring)."""
    z_gamma = float(stats.norm.ppf(confidence))
    approx = k - z_gamma * math.sqrt(1.0 / n + k * k / (2.0 * (n - 1.0)))
    lo, hi = approx - 4.0, approx + 4.0

    def f(z):
        return _factor(n, z, confidence) - k

    try:
        a, b = f(lo), f(hi)
        if math.isfinite(a) and math.isfinite(b) and a < 0 < b:
            return float(optimize.brentq(f, lo, hi, xtol=1e-12))
    except (ValueError, ArithmeticError):
        pass
    return approx


def _factor(n: float, z: float, confidence: float) -> float:
    """The exact one-sided tolerance factor of the quantile Phi(z) (module docstring)."""
    return float(stats.nct.ppf(confidence, n - 1.0, z * math.sqrt(n)) / math.sqrt(n))


def normal_tail_bounds(fit: NormalTail, confidence: float) -> tuple[float, float, float]:
    """p^, and the lower and upper bounds of p, each one-sided at `confidence` (module
    docstring): the upper bound is the level whose tolerance bound (`tolerance_bound`) is the
    limit."""
    p = float(stats.norm.sf(fit.k))
    upper = float(stats.norm.sf(_z_bound(fit.k, fit.effective, confidence)))
    lower = float(stats.norm.sf(_z_bound(fit.k, fit.effective, 1.0 - confidence)))
    return p, lower, upper


def tolerance_factor(effective: float, level: float, confidence: float) -> float:
    """k_tol: m + k_tol s bounds the (1 - `level`) quantile of a normal from `effective`
    revolutions at `confidence` (module docstring); the exact noncentral-t factor, or its normal
    approximation where scipy's noncentral t does not return a finite value."""
    n = float(effective)
    zp = float(stats.norm.isf(level))
    k = _factor(n, zp, confidence)
    if math.isfinite(k):
        return k
    z = float(stats.norm.ppf(confidence))
    a = 1.0 - z * z / (2.0 * (n - 1.0))
    b = zp * zp - z * z / n
    return (zp + math.sqrt(max(zp * zp - a * b, 0.0))) / a


def tolerance_bound(rows, level: float, confidence: float) -> float:
    """m + k_tol s of the per-member maxima `rows` (`tolerance_factor`, module docstring): the
    contact radius the design keeps below with probability 1 - `level` per revolution, at
    `confidence`. NaN where the model cannot be fitted (`normal_tail`)."""
    fit = normal_tail(rows, 0.0)
    if fit is None:
        return float("nan")
    return fit.mean_m + tolerance_factor(fit.effective, level, confidence) * fit.std_m
