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
  known tails: docs/model.md 16, tests/test_corner_risk.py).
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
* **normal** (none reached it, too few revolutions for a tail fit, at least
  `MIN_NORMAL_REVOLUTIONS` with contact): the maxima of the revolutions in contact taken as
  normal, p = Phi(-(rho_lim - mu)/sigma), bounds from the approximate noncentral t of the
  standardised distance on the effective sample (`_normal_tail`). A model of the tail, like the
  GPD: it covers the counted rate where the maxima spread below the corner (docs/model.md 16)
  and underestimates it where they pile up at rho_lim, which only designs that already reach
  the corner in a few revolutions show (those are counted).
* **not enough data** (none reached it, fewer revolutions in contact or no spread): p^ = 0 and the
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
from scipy import stats as _sp_stats

from .._errors import UserInputError
from ..io import finite_or_none, require
from ._normal_tail import NormalTail, normal_tail, normal_tail_bounds
from ._proportions import CORNER_RISK_CONFIDENCE, clopper_pearson, cluster_design_effect
from ._tail_fit import MIN_TAIL_EXCEEDANCES, MIN_TAIL_REVOLUTIONS, TailFit, tail_fit_bounds

METHODS = ("count", "tail", "normal", "not enough data")


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
    "tail"); `normal`: the `NormalTail` (method "normal"); `peak_pv_given_contact`: a `ConditionalPeak` when a revolution reached the corner
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
    normal: NormalTail | None = None

    def bounded_below(self, level: float) -> bool:
        """Whether the upper bound shows p <= `level` (per revolution) at `confidence`."""
        return bool(self.upper <= level)

    def as_dict(self) -> dict:
        """Plain JSON-able values (None for non-finite numbers)."""

        num = finite_or_none
        out = {
            f.name: getattr(self, f.name)
            for f in dataclasses.fields(self)
            if f.name not in ("tail", "peak_pv_given_contact", "normal")
        }
        out = {k: (num(v) if isinstance(v, float) else v) for k, v in out.items()}
        out["tail"] = self.tail.as_dict() if self.tail is not None else None
        out["normal"] = self.normal.as_dict() if self.normal is not None else None
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
def _counting(rows, rho_lim, confidence):
    """(p^, lower, upper, deff) by counting (module docstring, method "count")."""
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
    tail = None if few else tail_fit_bounds(rows, rho_lim, confidence, n)
    if tail is None and method == "tail":
        raise UserInputError(
            f"maxima: {n} revolutions: the tail fit needs at least {MIN_TAIL_REVOLUTIONS} with "
            f"{MIN_TAIL_EXCEEDANCES} distinct values above a threshold below rho_lim"
        )
    if tail is None:
        return _normal_or_nothing(rows, rho_lim, confidence, common)
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


def _normal_or_nothing(rows, rho_lim: float, confidence: float, common: dict) -> CornerRisk:
    """Method "normal" where the model can be fitted, else "not enough data" (module docstring)."""
    fit = normal_tail(rows, rho_lim)
    if fit is None:
        return CornerRisk(0.0, 0.0, common["counting_upper"], method="not enough data", **common)
    p, lower, upper = normal_tail_bounds(fit, confidence)
    return CornerRisk(p, lower, upper, method="normal", design_effect=fit.design_effect, normal=fit, **common)


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
