"""Corner-contact risk: the probability per cage revolution that a roller-flange contact reaches
the limited circle, with confidence bounds (docs/model.md 16, "Corner-contact risk").

The data are the per-revolution maxima M of the contact radius in contact, over every roller and
both flanges of one cage revolution (`revolution_statistics`' `contact_radius_m.max_in_contact`;
a revolution without flange contact counts as M = 0), one row per member (seed) of a settled
ensemble. Corner contact in a revolution is M > rho_lim (the contact lies on the corner torus,
paper Eqs. 2-7; `geometry.limited_circle_radius`). The quantity estimated is

    p = P(M > rho_lim)   per cage revolution,

with lower and upper bounds, each one-sided at `confidence` at least (the counts' together a
two-sided interval at 2 confidence - 1). Three methods, chosen by the data (`corner_risk`):

* **count** (some revolution reached the corner): x of n revolutions, the Clopper-Pearson bounds
  (Clopper & Pearson 1934, Biometrika 26:404) on the effective sample of Korn & Graubard (1998,
  "Confidence intervals for proportions with small expected number of positive counts estimated
  from survey data", Survey Methodology 24:193): the members are independent clusters of
  revolutions, the design effect deff = var_cluster(p^) / (p^(1 - p^)/n) (the ratio estimator's
  between-member variance, at least 1), the effective size n* = n / deff shrunk by
  (t_{n-1}/t_{N-1})^2 for the N - 1 degrees of freedom of that variance, x* = p^ n*.
* **tail** (none reached it, at least `MIN_TAIL_REVOLUTIONS` revolutions): peaks over a threshold.
  Above a high threshold u the excess of a maximum follows a generalised Pareto distribution
  (Pickands 1975, Ann. Stat. 3:119; Balkema & de Haan 1974, Ann. Prob. 2:792; Coles 2001, An
  Introduction to Statistical Modeling of Extreme Values, ch. 4):

      P(M > x) = zeta_u (1 + xi (x - u) / sigma)^(-1/xi),   x > u,

  zeta_u = P(M > u) (binomial), the exponential limit exp(-(x - u)/sigma) at xi = 0, and exactly 0
  beyond the finite endpoint u - sigma/xi when xi < 0. Threshold: the k largest maxima exceed u,
  k = max(`MIN_TAIL_EXCEEDANCES`, ceil(`TAIL_FRACTION` n)) (u near the 85 % quantile, at least 30
  exceedances), and at most `MAX_TAIL_FRACTION` n (else: too few revolutions). The interval is
  the profile likelihood of p itself (Coles 2001, sec. 2.6.6 and 4.3.4): for each p the joint
  log-likelihood of (zeta_u, sigma, xi) is maximised with p = zeta_u S(rho_lim - u; sigma, xi)
  held fixed (sigma written through zeta_u, xi and p), and the bounds are where the deviance
  2 (l^ - l_p(p)) reaches deff chi2_1(c), the quantile of chi-square(1) at `confidence`: Coles's
  two-sided interval at c, so each bound is one-sided at (1 + c)/2, stricter than the counts'.
  The likelihood knows nothing of the model error of the extrapolation, the slow approach of a
  tail to its GPD limit (normal maxima; Coles 2001, sec. 4.3.4), and the stricter cut keeps the
  upper bound at its nominal coverage where that error is present (the coverage on maxima with
  known tails: benchmarks/studies/study_corner_risk.py --synthetic, tests/test_corner_risk.py).
  A profile bound is honest also when the fitted endpoint lies below
  rho_lim (p^ = 0): its upper bound is the largest p the data do not exclude. xi is kept in
  [-0.5, 1] (the range where maximum likelihood is regular, Smith 1985, Biometrika 72:67; below
  -1 the likelihood is unbounded; a lighter fitted tail would set p = 0 on little evidence, and
  xi >= 1 is not physical for a bounded contact radius). A fit with xi at -0.5 says the tail is
  lighter than any GPD allowed, or unlike one: a density that rises towards an edge, as the
  contact radius does where the contact runs to the arc's edge and jumps onto the corner (the
  settled dynamics near the corner, docs/model.md 16). The extrapolation is then not trusted and
  the upper bound is the counting bound (`TailFit.at_shape_bound`). Dependence between revolutions scales
  the deviance threshold by deff >= 1 (the magnitude adjustment of the independence likelihood;
  Chandler & Bate 2007, Biometrika 94:167), deff the larger of the threshold-exceedance
  indicator's design effect over members (as above) and (1 + r1)/(1 - r1), r1 its lag-1
  autocorrelation within members.
* **not enough data** (none reached it, too few revolutions for a tail fit): p^ = 0 and the
  Clopper-Pearson upper bound with no event, 1 - (1 - c)^(1/n) (about 3/n at 95 %: the "rule of
  three"), revolutions taken as independent.

`counting_upper` (the Clopper-Pearson upper bound of the counts alone) is reported with every
method. `revolutions_needed` says how many revolutions with none at the corner bound p at a
level by counting alone. Pure host-side numpy/scipy.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import optimize as _opt
from scipy import stats as _sp_stats
from scipy.special import expit as _expit

from .._errors import UserInputError
from ..io import require

#: default one-sided confidence of the bounds
CORNER_RISK_CONFIDENCE = 0.95
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

METHODS = ("count", "tail", "not enough data")


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


@dataclasses.dataclass(frozen=True)
class ConditionalPeak:
    """The expected peak flange PV of a revolution that reached the corner [Pa m/s], with its
    two-sided Student-t interval at `confidence` over those revolutions (NaN bounds from one)."""

    value: float
    low: float
    high: float
    revolutions: int


@dataclasses.dataclass(frozen=True)
class CornerRisk:
    """The corner-contact risk per cage revolution (module docstring).

    `probability` p^; `lower`, `upper`: bounds, each one-sided at `confidence` (the counts) or
    at (1 + confidence)/2 (the tail's profile likelihood); `method`: one of
    `METHODS`; `revolutions` n, `members` N, `exceedances` x (revolutions beyond `rho_lim_m`);
    `counting_upper`: the Clopper-Pearson upper bound of the counts alone; `design_effect`: the
    between-revolution dependence factor applied (1: none); `tail`: the `TailFit` (method
    "tail"); `peak_pv_given_contact`: a `ConditionalPeak` when a revolution reached the corner
    and peak PVs were given; `largest_m`: the largest maximum seen."""

    probability: float
    lower: float
    upper: float
    confidence: float
    method: str
    revolutions: int
    members: int
    exceedances: int
    rho_lim_m: float
    largest_m: float
    counting_upper: float
    design_effect: float = 1.0
    tail: TailFit | None = None
    peak_pv_given_contact: ConditionalPeak | None = None

    def bounded_below(self, level: float) -> bool:
        """Whether the upper bound shows p <= `level` (per revolution) at `confidence`."""
        return bool(self.upper <= level)

    def as_dict(self) -> dict:
        """Plain JSON-able values (None for non-finite numbers)."""

        def num(v):
            return float(v) if math.isfinite(v) else None

        out = {
            f.name: getattr(self, f.name)
            for f in dataclasses.fields(self)
            if f.name not in ("tail", "peak_pv_given_contact")
        }
        out = {k: (num(v) if isinstance(v, float) else v) for k, v in out.items()}
        out["tail"] = self.tail.as_dict() if self.tail is not None else None
        peak = self.peak_pv_given_contact
        out["peak_pv_given_contact"] = (
            {k: (num(v) if isinstance(v, float) else v) for k, v in dataclasses.asdict(peak).items()}
            if peak is not None
            else None
        )
        return out


# -- input -----------------------------------------------------------------------------------
def _members(name: str, values) -> list[np.ndarray]:
    """`values` as one float array per member: a 2-D array (members x revolutions), a sequence of
    1-D sequences (members of different lengths), or one 1-D sequence (one member)."""
    if np.ndim(values) == 0 and not isinstance(values, (list, tuple)):
        raise UserInputError(f"{name}: a single value: must be an array of members x revolutions")
    try:
        ragged = (
            not isinstance(values, np.ndarray)
            and np.ndim(values[0] if len(values) else 0) == 1
            and len({np.size(v) for v in values}) > 1
        )
        if ragged:
            rows = [np.asarray(v, dtype=float).ravel() for v in values]
        else:
            arr = np.asarray(values, dtype=float)
            if arr.ndim == 1:
                arr = arr[None, :]
            if arr.ndim != 2:
                raise UserInputError(
                    f"{name}: {arr.ndim}-D: must be members x revolutions (2-D) or one member (1-D)"
                )
            rows = list(arr)
    except (TypeError, ValueError) as e:
        if isinstance(e, UserInputError):
            raise
        raise UserInputError(f"{name}: not numbers: must be an array of members x revolutions") from None
    if sum(r.size for r in rows) == 0:
        raise UserInputError(f"{name}: empty: must hold at least one revolution")
    return rows


def _check(maxima, rho_lim, confidence, peak_pv=None):
    rows = _members("maxima", maxima)
    require("maxima", np.concatenate(rows), lambda v: np.isfinite(v) & (v >= 0), "finite and >= 0 m")
    require("rho_lim", rho_lim, lambda v: np.isfinite(v) & (v > 0), "finite and > 0 m")
    require("confidence", confidence, lambda v: (v > 0.5) & (v < 1), "in (0.5, 1) (one-sided)")
    pv = None
    if peak_pv is not None:
        pv = _members("peak_pv", peak_pv)
        if [p.size for p in pv] != [r.size for r in rows]:
            raise UserInputError(
                f"peak_pv: {[p.size for p in pv]} revolutions per member: must match maxima's "
                f"{[r.size for r in rows]}"
            )
        require("peak_pv", np.concatenate(pv), lambda v: np.isfinite(v) & (v >= 0), "finite and >= 0 Pa m/s")
    return [r for r in rows], pv


# -- counting --------------------------------------------------------------------------------
def revolutions_needed(level: float, confidence: float = CORNER_RISK_CONFIDENCE) -> int:
    """Revolutions without corner contact that bound the per-revolution probability at `level`
    by counting alone (independent revolutions): the smallest n with 1 - (1 - c)^(1/n) <= level,
    n = ceil(ln(1 - c) / ln(1 - level)) (2995 for 1e-3 at 95 %)."""
    require("level", level, lambda v: (v > 0) & (v < 1), "in (0, 1) (probability per revolution)")
    require("confidence", confidence, lambda v: (v > 0) & (v < 1), "in (0, 1)")
    n = math.log1p(-confidence) / math.log1p(-level)
    n_int = math.ceil(n - 1e-9)
    return int(n_int if -math.expm1(math.log1p(-confidence) / n_int) <= level else n_int + 1)


def clopper_pearson(count: float, trials: float, confidence: float = CORNER_RISK_CONFIDENCE) -> tuple:
    """One-sided Clopper-Pearson bounds (lower, upper), each at `confidence`, of a binomial
    probability seen `count` times in `trials` (real counts allowed, for effective samples):
    lower = B^-1(1 - c; x, n - x + 1) (0 for x = 0), upper = B^-1(c; x + 1, n - x) (1 for x = n),
    B^-1 the beta quantile (Clopper & Pearson 1934)."""
    x, n = float(count), float(trials)
    lower = 0.0 if x <= 0 else float(_sp_stats.beta.ppf(1 - confidence, x, n - x + 1))
    upper = 1.0 if x >= n else float(_sp_stats.beta.ppf(confidence, x + 1, n - x))
    return lower, upper


def cluster_design_effect(counts, sizes) -> float:
    """The design effect of a proportion whose trials come in independent clusters (members):
    counts x_k of sizes n_k, p^ = sum x / sum n, var = N/(N-1) sum (x_k - p^ n_k)^2 / n^2 (the
    ratio estimator's between-cluster variance; Cochran 1977, Sampling Techniques, sec. 6.11),
    deff = var / (p^(1 - p^)/n), at least 1; 1 when it cannot be estimated (one cluster, p^ in
    {0, 1})."""
    x, m = np.asarray(counts, float), np.asarray(sizes, float)
    keep = m > 0
    x, m = x[keep], m[keep]
    n, clusters = float(m.sum()), int(m.size)
    p = float(x.sum() / n) if n else 0.0
    if clusters < 2 or p <= 0 or p >= 1:
        return 1.0
    var = clusters / (clusters - 1) * float(np.sum((x - p * m) ** 2)) / n**2
    return max(1.0, var / (p * (1 - p) / n))


def _counting(rows, rho_lim, confidence):
    """(p^, lower, upper, counting_upper, deff) by counting (module docstring, method "count")."""
    counts = np.array([np.sum(r > rho_lim) for r in rows], float)
    sizes = np.array([r.size for r in rows], float)
    n, x = float(sizes.sum()), float(counts.sum())
    p = x / n
    clusters = int(np.sum(sizes > 0))
    deff = cluster_design_effect(counts, sizes)
    n_eff = n
    if x > 0 and clusters >= 2 and p < 1:
        df_factor = (_sp_stats.t.ppf(confidence, n - 1) / _sp_stats.t.ppf(confidence, clusters - 1)) ** 2
        n_eff = min(n, n / deff * df_factor)
    lower, upper = clopper_pearson(p * n_eff, n_eff, confidence)
    return p, lower, upper, deff


# -- tail fit ----------------------------------------------------------------------------------
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


def _tail(rows, rho_lim, confidence, n):
    """(p^, lower, upper, TailFit) by the peaks-over-threshold fit (module docstring); None when
    ties leave too few values above the threshold."""
    values = np.concatenate(rows)
    k = max(MIN_TAIL_EXCEEDANCES, math.ceil(TAIL_FRACTION * n))
    srt = np.sort(values)
    u = 0.5 * (srt[n - k - 1] + srt[n - k])
    if srt[n - k] <= u:  # ties at the threshold: every value above u exceeds it
        u = float(srt[n - k - 1])
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
    # dependence: the design effect of the threshold-exceedance indicator over members and the
    # lag-1 autocorrelation within members (module docstring)
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


# -- the estimate ------------------------------------------------------------------------------
def _conditional_peak(rows, pv, rho_lim, confidence):
    vals = np.concatenate([p[r > rho_lim] for r, p in zip(rows, pv)])
    if vals.size == 0:
        return None
    mean = float(np.mean(vals))
    if vals.size == 1:
        return ConditionalPeak(mean, math.nan, math.nan, 1)
    half = float(
        _sp_stats.t.ppf(0.5 + confidence / 2, vals.size - 1) * np.std(vals, ddof=1) / math.sqrt(vals.size)
    )
    return ConditionalPeak(mean, mean - half, mean + half, int(vals.size))


def corner_risk(
    maxima, rho_lim: float, confidence: float = CORNER_RISK_CONFIDENCE, *, peak_pv=None, method: str = "auto"
) -> CornerRisk:
    """The probability per cage revolution that a roller-flange contact reaches the limited
    circle, with one-sided bounds at `confidence` (module docstring).

    `maxima` [m]: per-revolution maxima of the contact radius in contact over every roller and
    flange, members x revolutions (a 2-D array, or one sequence per member; 0 for a revolution
    without flange contact); `rho_lim` [m]: the limited-circle radius; `peak_pv` [Pa m/s]: the
    revolutions' peak flange PV, same layout (optional; gives the expected peak PV of a revolution
    that reached the corner). `method`: "auto" (by the data, module docstring) or "tail" (the
    tail fit also where revolutions reached the corner, to compare the model with the counts;
    needs `MIN_TAIL_REVOLUTIONS` and a threshold below `rho_lim`)."""
    rows, pv = _check(maxima, rho_lim, confidence, peak_pv)
    if method not in ("auto", "tail"):
        raise UserInputError(f"method = {method!r}: must be 'auto' or 'tail'")
    rho_lim, confidence = float(rho_lim), float(confidence)
    n = int(sum(r.size for r in rows))
    members = int(sum(r.size > 0 for r in rows))
    x = int(sum(np.sum(r > rho_lim) for r in rows))
    largest = float(max(np.max(r) for r in rows if r.size))
    p, lower, upper, deff = _counting(rows, rho_lim, confidence)
    counting_upper = upper
    common = dict(
        confidence=confidence,
        revolutions=n,
        members=members,
        exceedances=x,
        rho_lim_m=rho_lim,
        largest_m=largest,
        counting_upper=counting_upper,
    )
    peak = _conditional_peak(rows, pv, rho_lim, confidence) if pv is not None and x > 0 else None
    if x > 0 and method == "auto":
        return CornerRisk(
            p, lower, upper, method="count", design_effect=deff, peak_pv_given_contact=peak, **common
        )
    few = n < MIN_TAIL_REVOLUTIONS or np.unique(np.concatenate(rows)).size < MIN_TAIL_EXCEEDANCES + 1
    tail = None if few else _tail(rows, rho_lim, confidence, n)
    if tail is None and method == "tail":
        raise UserInputError(
            f"maxima: {n} revolutions: the tail fit needs at least {MIN_TAIL_REVOLUTIONS} with "
            f"{MIN_TAIL_EXCEEDANCES} distinct values above a threshold below rho_lim"
        )
    if tail is None:
        return CornerRisk(0.0, 0.0, counting_upper, method="not enough data", **common)
    p, lower, upper, fit = tail
    if fit.at_shape_bound:  # a tail the GPD family does not fit: the counting bound, model-free
        upper = max(upper, counting_upper)
    return CornerRisk(
        p,
        lower,
        upper,
        method="tail",
        design_effect=fit.design_effect,
        tail=fit,
        peak_pv_given_contact=peak,
        **common,
    )


# -- the data of a settled run -----------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class RevolutionMaxima:
    """Per member (seed) and measured cage revolution: `contact_radius_m`, the largest contact
    radius in contact over every roller and flange (0 for a revolution without flange contact),
    and `peak_pv_Pa_m_s`, the largest flange PV of the contact events peaking in it (0 without);
    one 1-D array per member, the input of `corner_risk`."""

    contact_radius_m: list
    peak_pv_Pa_m_s: list


def revolution_maxima(per_revolution) -> RevolutionMaxima:
    """The per-revolution maxima of every member from its `window_statistics` (one dict per
    member: `contact_radius_m.max_in_contact`, `flange_pv_Pa_m_s.max`); revolutions without a
    measured cage speed are left out, those without flange contact count as 0."""
    radius, pv = [], []
    for r in per_revolution:
        measured = np.isfinite(np.asarray(r["cage_speed_rpm"], float))
        radius.append(np.nan_to_num(np.asarray(r["contact_radius_m.max_in_contact"], float)[measured]))
        pv.append(np.nan_to_num(np.asarray(r["flange_pv_Pa_m_s.max"], float)[measured]))
    return RevolutionMaxima(radius, pv)


def corner_risk_of_revolutions(
    per_revolution, rho_lim: float, confidence: float = CORNER_RISK_CONFIDENCE
) -> CornerRisk | None:
    """`corner_risk` of the members' `window_statistics` (`revolution_maxima`), with the peak PV
    given corner contact; None without a measured revolution."""
    m = revolution_maxima(per_revolution)
    if sum(r.size for r in m.contact_radius_m) == 0:
        return None
    return corner_risk(m.contact_radius_m, rho_lim, confidence, peak_pv=m.peak_pv_Pa_m_s)
