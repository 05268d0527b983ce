"""The generalised Pareto tail of the per-revolution maxima of the contact radius, and the
profile-likelihood bounds of the probability beyond the limited circle it gives (the method
"tail" of `corner_risk`; docs/model.md 16, "Corner-contact risk"; Coles 2001, An Introduction to
Statistical Modeling of Extreme Values, ch. 4). Pure host-side numpy/scipy."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import optimize as _opt
from scipy import stats as _sp_stats
from scipy.special import expit as _expit

from ._proportions import cluster_design_effect

#: share of the revolutions above the tail threshold u (u near the 85 % quantile) ...
TAIL_FRACTION = 0.15
#: ... with at least this many exceedances of u ...
MIN_TAIL_EXCEEDANCES = 30
#: ... and at most this share of the revolutions above u (else too few for a tail fit)
MAX_TAIL_FRACTION = 0.30
#: fewest revolutions for the tail fit: MIN_TAIL_EXCEEDANCES / MAX_TAIL_FRACTION
MIN_TAIL_REVOLUTIONS = math.ceil(MIN_TAIL_EXCEEDANCES / MAX_TAIL_FRACTION)
#: the range of the GPD shape xi in the fit
SHAPE_RANGE = (-0.5, 1.0)
#: a fitted shape within this of the lower end of SHAPE_RANGE is "at the bound"
SHAPE_BOUND_TOLERANCE = 0.01
#: the smallest probability the profile search resolves; a bound below it is reported as 0
PROFILE_FLOOR = 1e-15
#: the relative precision of a profile bound (on log p)
BOUND_RTOL = 0.01


@dataclasses.dataclass(frozen=True)
class TailFit:
    """The generalised Pareto tail above the threshold u (module docstring): `threshold_m` u,
    `scale_m` sigma, `shape` xi, `exceedances` k, `exceedance_rate` zeta_u = k/n, `endpoint_m`
    u - sigma/xi for xi < 0 (inf otherwise), `design_effect` the deviance scaling,
    `profile_upper` the profile-likelihood upper bound of p."""

    threshold_m: float
    scale_m: float
    shape: float
    exceedances: int
    exceedance_rate: float
    endpoint_m: float
    design_effect: float
    #: the fitted shape at the lower end of `SHAPE_RANGE`: the tail is lighter than, or unlike,
    #: any GPD the fit allows; the upper bound is then the counting bound (module docstring)
    at_shape_bound: bool = False
    #: the profile likelihood's upper bound itself (the reported bound may be the counting one)
    profile_upper: float = math.nan

    def as_dict(self) -> dict:
        return {
            k: (v if isinstance(v, bool) or math.isfinite(v) else None)
            for k, v in dataclasses.asdict(self).items()
        }


def _gpd_nll(excess, log_scale, shape):
    """Negative log-likelihood of generalised Pareto excesses (Coles 2001, eq. 4.10); inf outside
    the support."""
    sigma = math.exp(log_scale)
    k = excess.size
    if abs(shape) < 1e-9:
        return k * log_scale + float(np.sum(excess)) / sigma
    z = 1.0 + shape * excess / sigma
    if np.any(z <= 0):
        return math.inf
    return k * log_scale + (1.0 + 1.0 / shape) * float(np.sum(np.log(z)))


def _survival(z, sigma, shape):
    """S(z) = (1 + xi z/sigma)^(-1/xi) (exp(-z/sigma) at xi = 0), 0 beyond the endpoint."""
    if abs(shape) < 1e-9:
        return math.exp(-z / sigma)
    base = 1.0 + shape * z / sigma
    return 0.0 if base <= 0 else base ** (-1.0 / shape)


def _fit_gpd(excess):
    """Maximum-likelihood (sigma, xi) of excesses, xi in `SHAPE_RANGE` (Nelder-Mead on (ln sigma,
    xi) from several starts): ((sigma, xi), negative log-likelihood)."""
    lo, hi = SHAPE_RANGE
    top = float(np.max(excess))
    mean = float(np.mean(excess))

    def nll(q):
        if not lo <= q[1] <= hi:
            return math.inf
        return _gpd_nll(excess, q[0], q[1])

    best = None
    for xi0 in (-0.5, -0.2, 0.1):
        # a start inside the support: sigma > -xi max(y)
        s0 = max(mean * (1 - xi0), -xi0 * top * 1.05, 1e-300)
        with np.errstate(invalid="ignore"):  # inf - inf of simplex points outside the support
            r = _opt.minimize(
                nll, [math.log(s0), xi0], method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-10}
            )
        if best is None or r.fun < best.fun:
            best = r
    return (math.exp(best.x[0]), float(best.x[1])), float(best.fun)


def _binomial_ll(k, n, zeta):
    if zeta <= 0 or zeta >= 1:
        return -math.inf
    return k * math.log(zeta) + (n - k) * math.log1p(-zeta)


def _scale_for(z, shape, s):
    """sigma with S(z; sigma, xi) = s, 0 < s < 1."""
    if abs(shape) < 1e-9:
        return z / -math.log(s)
    return shape * z / math.expm1(-shape * math.log(s))


class _Profile:
    """The profile log-likelihood of p = zeta_u S(z) (module docstring), warm-started."""

    def __init__(self, excess, k, n, z, shape):
        self.excess, self.k, self.n, self.z, self.shape = excess, k, n, z, shape
        self.start = (0.0, shape)

    def __call__(self, p: float) -> float:
        lo, hi = SHAPE_RANGE
        k, n, z, excess = self.k, self.n, self.z, self.excess

        def negll(q):
            # zeta in (p, 1): zeta = p + (1 - p) expit(q0)
            zeta = p + (1 - p) * float(_expit(q[0]))
            if not lo <= q[1] <= hi or zeta >= 1:
                return math.inf
            s = p / zeta
            if not 0 < s < 1:
                return math.inf
            sigma = _scale_for(z, q[1], s)
            if not sigma > 0:
                return math.inf
            return _gpd_nll(excess, math.log(sigma), q[1]) - _binomial_ll(k, n, zeta)

        zeta0 = k / n
        q0 = math.log(max(zeta0 - p, 1e-300) / max(1 - zeta0, 1e-300)) if zeta0 > p else 5.0
        best = None
        for start in ([q0, self.start[1]], [q0, self.shape]):
            with np.errstate(invalid="ignore"):  # inf - inf of simplex points outside the support
                r = _opt.minimize(negll, start, method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-5})
            if np.isfinite(r.fun) and (best is None or r.fun < best.fun):
                best = r
            if best is not None:
                break
        if best is None:
            return -math.inf
        self.start = (best.x[0], float(best.x[1]))
        return -float(best.fun)


def _threshold(values, n: int) -> float:
    """The threshold u of the peaks-over-threshold fit: midway between the k-th and (k+1)-th
    largest of the `n` `values`, k = max(`MIN_TAIL_EXCEEDANCES`, `TAIL_FRACTION` n); with ties
    there, the (k+1)-th largest itself (every value above u then exceeds it)."""
    k = max(MIN_TAIL_EXCEEDANCES, math.ceil(TAIL_FRACTION * n))
    srt = np.sort(values)
    u = 0.5 * (srt[n - k - 1] + srt[n - k])
    if srt[n - k] <= u:  # ties at the threshold: every value above u exceeds it
        u = float(srt[n - k - 1])
    return u


def _exceedance_design_effect(rows, u: float, zeta: float) -> float:
    """The dependence of the exceedances of `u` (module docstring): the design effect of the
    threshold-exceedance indicator over members (`rows`), or, where larger, that of its lag-1
    autocorrelation r1 within members, (1 + r1) / (1 - r1); `zeta` the exceedance rate."""
    counts = [np.sum(r > u) for r in rows]
    deff = cluster_design_effect(counts, [r.size for r in rows])
    ind = [(r > u).astype(float) for r in rows if r.size >= 2]
    if ind:
        c = np.concatenate([i - zeta for i in ind])
        num = sum(float(np.sum((i[1:] - zeta) * (i[:-1] - zeta))) for i in ind)
        den = float(np.sum(c * c))
        r1 = num / den if den > 0 else 0.0
        if 0 < r1 < 1:
            deff = max(deff, (1 + r1) / (1 - r1))
    return deff


def tail_fit_bounds(rows, rho_lim, confidence, n):
    """(p^, lower, upper, TailFit) by the peaks-over-threshold fit (module docstring); None when
    ties leave too few values above the threshold."""
    values = np.concatenate(rows)
    u = _threshold(values, n)
    excess = values[values > u] - u
    k = int(excess.size)
    if k < MIN_TAIL_EXCEEDANCES // 2:  # ties at the top: too few distinct exceedances to fit
        return None
    zeta = k / n
    (sigma, shape), nll = _fit_gpd(excess)
    z = rho_lim - u
    if z <= 0:  # the threshold lies beyond the limit (method "tail" with many revolutions there)
        return None
    p_hat = zeta * _survival(z, sigma, shape)
    ll_hat = _binomial_ll(k, n, zeta) - nll
    deff = _exceedance_design_effect(rows, u, zeta)
    cut = deff * float(_sp_stats.chi2.ppf(confidence, 1))
    profile = _Profile(excess, k, n, z, shape)

    def excess_deviance(log_p):
        return 2.0 * (ll_hat - profile(math.exp(log_p))) - cut

    log_floor, log_top = math.log(PROFILE_FLOOR), math.log(1 - 1e-9)
    log_hat = math.log(max(p_hat, PROFILE_FLOOR))

    def crossing(step, end):
        """The first p from p^ along log p (steps of `step`, up to `end`) where the deviance
        reaches the cut; `end` itself when it never does."""
        a = log_hat
        if excess_deviance(a) > 0:
            return a  # the floor itself is excluded
        if excess_deviance(end) <= 0:
            return end
        while True:
            b = min(a + step, end) if step > 0 else max(a + step, end)
            if excess_deviance(b) > 0:
                try:
                    return _opt.brentq(excess_deviance, min(a, b), max(a, b), xtol=BOUND_RTOL)
                except ValueError:  # the warm-started profile moved between evaluations
                    return b
            if b == end:
                return end
            a = b

    upper = math.exp(crossing(math.log(10.0), log_top))
    if p_hat <= PROFILE_FLOOR and upper <= PROFILE_FLOOR:
        upper = 0.0  # even the floor is excluded: the fitted endpoint lies below rho_lim
    lower = 0.0
    if p_hat > PROFILE_FLOOR:
        profile.start = (0.0, shape)
        found = crossing(-math.log(10.0), log_floor)
        lower = 0.0 if found <= log_floor else math.exp(found)
    endpoint = u - sigma / shape if shape < 0 else math.inf
    at_bound = shape <= SHAPE_RANGE[0] + SHAPE_BOUND_TOLERANCE
    fit = TailFit(
        float(u),
        float(sigma),
        float(shape),
        k,
        float(zeta),
        float(endpoint),
        float(deff),
        bool(at_bound),
        float(upper),
    )
    return float(p_hat), float(lower), float(upper), fit
