"""Statistics of settled running with 95 % confidence intervals (docs/model.md 16).

A dynamic run is a correlated time series: consecutive contact events and cage-speed samples are
not independent, so the naive standard error of all samples is far too small. Two estimators:

* **Non-overlapping batch means** over cage revolutions (one seed). The measurement window is
  split into b >= 2 batches, one per cage revolution; each batch gives one value X_i of the
  statistic (the mean cage speed over that revolution, the largest flange force of the events
  whose peak falls in it, ...). The point estimate is the grand mean X = (1/b) sum X_i and the
  interval is

      X +/- t_{b-1, 0.975} S / sqrt(b),      S^2 = sum (X_i - X)^2 / (b - 1)

  (Law & Kelton, Simulation Modeling and Analysis, 3rd ed., section 9.5.3; Schmeiser 1982,
  "Batch size effects in the analysis of simulation output", Oper. Res. 30, 556). Assumptions:
  the run is stationary over the window (settled, `_settle`), and batches one revolution long are
  long enough that the batch values are nearly independent and nearly normal. Both hold when the
  correlation time of the statistic is short against one revolution; the cage-speed
  autocorrelation after settling (ms) is short against a revolution (6.6 ms at 9118 rpm), and
  the coverage of the interval on AR(1) series with that ratio is tested in
  tests/test_statistics.py. Dependent batches make the interval too narrow, never too wide.
* **Ensemble of seeds** (N >= 2 independent runs with different seeded initial scatter,
  `Perturbation.seed`). Each run's batch-means estimate is one replicate Y_k; the interval is the
  Student-t interval of the Y_k with N - 1 degrees of freedom. Replicates are independent by
  construction, so only stationarity and approximate normality of Y_k are assumed.

The quantity estimated for an event statistic is its expectation *per cage revolution*: "max"
is the expected largest value within one revolution, "p95" the expected 95th percentile of one
revolution's events. Unlike the maximum of a whole window (which grows with the window length),
these are properties of the running bearing with a finite variance, so an interval exists.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy import stats as _sp_stats

from .._errors import UserInputError
from ..geometry import kinematic_cage_speed, limited_circle_radius, rad_s_to_rpm
from ..io import finite_or_none
from ._corner_risk import (
    CORNER_RISK_CONFIDENCE,
    CornerRisk,
    RevolutionMaxima,
    corner_risk_of_revolutions,
    revolution_maxima,
)
from ._summary import (
    _EVENT_QUANTITIES,
    CONTACT_THRESHOLD,
    FILM_KEYS,
    FRICTION_POWER_KEYS,
    contact_events,
    film_statistics,
    friction_power_statistics,
)

CONFIDENCE = 0.95

#: reductions of one revolution's contact events, in summary.json order
EVENT_REDUCTIONS = {
    "max": np.max,
    "mean": np.mean,
    "median": np.median,
    "p95": lambda v: np.percentile(v, 95.0),
}


@dataclasses.dataclass(frozen=True)
class Estimate:
    """A point estimate with its 95 % confidence interval over `n` batches or seeds."""

    value: float
    ci95_low: float
    ci95_high: float
    n: int

    @property
    def half_width(self) -> float:
        return 0.5 * (self.ci95_high - self.ci95_low)

    def as_dict(self) -> dict:
        num = finite_or_none
        return {
            "value": num(self.value),
            "ci95_low": num(self.ci95_low),
            "ci95_high": num(self.ci95_high),
            "n": int(self.n),
        }


@dataclasses.dataclass(frozen=True)
class CornerCount:
    """How often the contact reached the corner over every measured revolution of every seed,
    with the upper 95 % bounds of its probability per revolution and per seed
    (`corner_contact_bound`)."""

    revolutions: int
    revolutions_with_corner_contact: int
    per_revolution_upper95: float
    seeds: int
    seeds_with_corner_contact: int
    per_seed_upper95: float

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclasses.dataclass(frozen=True)
class PredictionBound:
    """The one-sided upper prediction bound of one further revolution's largest contact radius
    [m] at `confidence` over `revolutions` measured ones (`max_contact_radius_bound`); NaN with
    fewer than two."""

    value: float
    revolutions: int
    confidence: float

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def student_t_interval(samples, confidence: float = CONFIDENCE) -> Estimate:
    """Mean of independent, roughly normal `samples` (NaNs dropped) with its Student-t interval
    mean +/- t_{n-1,(1+c)/2} s/sqrt(n). One sample: the value with an unbounded interval (NaN
    bounds); none: all NaN."""
    x = np.asarray(samples, dtype=float).ravel()
    x = x[np.isfinite(x)]
    n = x.size
    if n == 0:
        return Estimate(np.nan, np.nan, np.nan, 0)
    mean = float(np.mean(x))
    if n == 1:
        return Estimate(mean, np.nan, np.nan, 1)
    half = float(_sp_stats.t.ppf(0.5 + confidence / 2, n - 1) * np.std(x, ddof=1) / np.sqrt(n))
    return Estimate(mean, mean - half, mean + half, n)


def batch_means(series, num_batches: int, confidence: float = CONFIDENCE) -> Estimate:
    """Non-overlapping batch-means estimate of the mean of a stationary `series`: `num_batches`
    equal consecutive batches (a remainder at the end is dropped), Student-t interval over the
    batch means with num_batches - 1 degrees of freedom (Law & Kelton 9.5.3)."""
    x = np.asarray(series, dtype=float).ravel()
    size = x.size // num_batches
    if num_batches < 2 or size < 1:
        raise ValueError(f"num_batches = {num_batches}: need 2 <= num_batches <= len(series) = {x.size}")
    return student_t_interval(x[: size * num_batches].reshape(num_batches, size).mean(axis=1), confidence)


def _window(hist: dict, t0: float, t1: float) -> dict:
    t = np.asarray(hist["t"])
    keep = (t >= t0) & (t < t1)
    return {k: np.asarray(v)[keep] for k, v in hist.items()}


#: per-revolution statistics other than the contact-event reductions (`revolution_statistics`)
_REVOLUTION_SCALARS = (
    "cage_speed_rpm",
    "cage_slip",
    "roller_skew_rad.mean_abs",
    "roller_skew_rad.max_abs",
    "corner_contact_share.time",
    "corner_contact_share.events",
    "contact_radius_m.p99",
    "contact_radius_m.max_in_contact",
    "flange_contact_events_per_rev",
    "flange_pv_contact_time_Pa_m_s.mean",
    "flange_pv_contact_time_Pa_m_s.p95",
    "flange_pv_contact_time_Pa_m_s.tail95",
)

#: the level of the tail statistic "tail95": the mean of the values at or above the 95th
#: percentile (the superquantile, or conditional value at risk, at 0.95)
TAIL_LEVEL = 0.95


def tail_mean(values, level: float = TAIL_LEVEL) -> float:
    """The mean of the values at or above their `level` quantile (linear interpolation, as
    `np.percentile`): the superquantile, or conditional value at risk (Rockafellar & Uryasev
    2000, "Optimization of conditional value-at-risk", J. Risk 2:21). Unlike the quantile it
    responds to every value in the tail, and it bounds the quantile from above."""
    v = np.asarray(values, dtype=float).ravel()
    return float(np.mean(v[v >= np.percentile(v, 100.0 * level)]))


def revolution_statistic_keys() -> tuple[str, ...]:
    """The keys of `revolution_statistics`, in its order ("group.reduction" or "name")."""
    events = tuple(f"{key}.{red}" for key in _EVENT_QUANTITIES for red in EVENT_REDUCTIONS)
    return events + _REVOLUTION_SCALARS + tuple(FILM_KEYS) + FRICTION_POWER_KEYS


def revolution_statistics(
    hist: dict, edges, rho_lim: float, kinematic_speed: float, threshold: float = CONTACT_THRESHOLD
) -> dict[str, np.ndarray]:
    """Every reported statistic, one value per revolution [edges[i], edges[i+1]) (NaN where a
    revolution has no contact for a contact statistic). Keys are "group.reduction"."""
    edges = np.asarray(edges, dtype=float)
    nrev = edges.size - 1
    events = contact_events(hist, threshold)
    rev_of_event = np.searchsorted(edges, events["time"], side="right") - 1
    out: dict[str, np.ndarray] = {}
    for key in _EVENT_QUANTITIES:
        for red, fn in EVENT_REDUCTIONS.items():
            vals = np.full(nrev, np.nan)
            for i in range(nrev):
                v = events[key][rev_of_event == i]
                if v.size:
                    vals[i] = fn(v)
            out[f"{key}.{red}"] = vals
    for name in (*_REVOLUTION_SCALARS, *FILM_KEYS, *FRICTION_POWER_KEYS):
        out[name] = np.full(nrev, np.nan)
    kin_rpm = float(rad_s_to_rpm(kinematic_speed))
    for i in range(nrev):
        w = _window(hist, edges[i], edges[i + 1])
        if w["t"].size == 0:
            continue
        rpm = float(rad_s_to_rpm(np.mean(w["cage_speed"])))
        out["cage_speed_rpm"][i] = rpm
        out["cage_slip"][i] = (kin_rpm - rpm) / kin_rpm
        skew = np.abs(w["roller_skew"])
        out["roller_skew_rad.mean_abs"][i] = np.mean(skew)
        out["roller_skew_rad.max_abs"][i] = np.max(skew)
        touching = w["flange_force"] > threshold
        beyond = w["contact_radius"] > rho_lim
        if touching.any():
            out["corner_contact_share.time"][i] = np.mean(beyond[touching])
            # PV over contact time (every touching flange sample, equally spaced in time)
            pv = np.asarray(w["flange_pv"])[touching]
            out["flange_pv_contact_time_Pa_m_s.mean"][i] = np.mean(pv)
            out["flange_pv_contact_time_Pa_m_s.p95"][i] = np.percentile(pv, 95.0)
            out["flange_pv_contact_time_Pa_m_s.tail95"][i] = tail_mean(pv)
            rho = np.asarray(w["contact_radius"])[touching]
            out["contact_radius_m.p99"][i] = np.percentile(rho, 99.0)
            # the largest contact radius of any touching sample: the corner is reached iff > rho_lim
            out["contact_radius_m.max_in_contact"][i] = np.max(rho)
        for key, value in (*film_statistics(w, threshold).items(), *friction_power_statistics(w).items()):
            out[key][i] = value
        sel = rev_of_event == i
        out["flange_contact_events_per_rev"][i] = np.sum(sel)
        if sel.any():
            out["corner_contact_share.events"][i] = np.mean(events["contact_radius_m"][sel] > rho_lim)
    return out


def confidence_intervals(per_revolution: list[dict[str, np.ndarray]]) -> tuple[dict[str, Estimate], str]:
    """95 % intervals of every statistic: batch means over the revolutions of one seed, or the
    Student-t interval over seeds of each seed's batch-means value (module docstring)."""
    keys = per_revolution[0].keys()
    if len(per_revolution) == 1:
        method = "batch means over cage revolutions (Student-t, b-1 dof)"
        return {k: student_t_interval(per_revolution[0][k]) for k in keys}, method
    method = "ensemble of seeds (Student-t over per-seed batch means, N-1 dof)"
    out = {}
    for k in keys:
        per_seed = [np.nanmean(r[k]) if np.isfinite(r[k]).any() else np.nan for r in per_revolution]
        out[k] = student_t_interval(per_seed)
    return out, method


def upper_probability_bound(count: int, trials: int, confidence: float = CONFIDENCE) -> float:
    """One-sided Clopper-Pearson upper confidence bound on the probability of an event seen
    `count` times in `trials` independent trials: p <= beta^-1(confidence; count + 1,
    trials - count) (Clopper & Pearson 1934, Biometrika 26: 404); with no event,
    1 - (1 - confidence)^(1/trials), about 3 / trials at 95 %. NaN without trials."""
    if trials <= 0:
        return float("nan")
    if count >= trials:
        return 1.0
    return float(_sp_stats.beta.ppf(confidence, count + 1, trials - count))


def corner_contact_bound(per_revolution: list[dict[str, np.ndarray]], rho_lim: float) -> CornerCount:
    """How often the contact reached the corner (a revolution whose largest contact radius in
    contact lies beyond the limited circle `rho_lim`), over every measured revolution of every
    seed, with the upper 95 % bounds on its probability (`upper_probability_bound`): per
    revolution (revolutions taken as independent) and per seed (a seed with any corner contact
    in its window; independent by construction, and weaker). Zero corner contact seen in a
    verification bounds the tail only as far as these bounds say."""
    revs = seeds = revs_hit = seeds_hit = 0
    for r in per_revolution:
        measured = np.isfinite(np.asarray(r["cage_speed_rpm"], float))
        hit = measured & (np.nan_to_num(np.asarray(r["contact_radius_m.max_in_contact"], float)) > rho_lim)
        revs, revs_hit = revs + int(measured.sum()), revs_hit + int(hit.sum())
        if measured.any():
            seeds, seeds_hit = seeds + 1, seeds_hit + int(hit.any())
    return CornerCount(
        revolutions=revs,
        revolutions_with_corner_contact=revs_hit,
        per_revolution_upper95=upper_probability_bound(revs_hit, revs),
        seeds=seeds,
        seeds_with_corner_contact=seeds_hit,
        per_seed_upper95=upper_probability_bound(seeds_hit, seeds),
    )


def max_contact_radius_bound(
    per_revolution: list[dict[str, np.ndarray]], confidence: float = CONFIDENCE
) -> PredictionBound:
    """The one-sided upper prediction bound of the largest contact radius in contact of one
    further cage revolution: over the N measured revolutions of every seed (taken as
    independent: the rollers' axial memory is 3-4 ms against a 7 ms revolution, docs/model.md
    17) with mean m and standard deviation s,

        U = m + t_{confidence, N-1} s sqrt(1 + 1/N)

    (the normal prediction interval; Hahn & Meeker 1991, Statistical Intervals, section 4.7):
    a new revolution stays below U with probability `confidence`, where the expectation of the
    per-revolution maximum (the `contact_radius_m.max_in_contact` estimate) says nothing about
    single revolutions. NaN with fewer than two revolutions."""
    values = np.concatenate(
        [np.asarray(r["contact_radius_m.max_in_contact"], float).ravel() for r in per_revolution]
        or [np.zeros(0)]
    )
    values = values[np.isfinite(values)]
    n = int(values.size)
    bound = float("nan")
    if n >= 2:
        t = float(_sp_stats.t.ppf(confidence, n - 1))
        bound = float(np.mean(values) + t * np.std(values, ddof=1) * np.sqrt(1.0 + 1.0 / n))
    return PredictionBound(value=bound, revolutions=n, confidence=float(confidence))


def window_statistics(
    window: dict, edges, bearing, op, threshold: float = CONTACT_THRESHOLD
) -> dict[str, np.ndarray]:
    """`revolution_statistics` of one seed's measurement window `window` with revolution
    boundaries `edges` [s], for `bearing` at `op`."""
    rho_lim = float(limited_circle_radius(bearing.roller))
    kin = float(kinematic_cage_speed(bearing, op))
    return revolution_statistics(window, edges, rho_lim, kin, threshold)


def _measured_revolutions(result) -> list:
    """Every measured member's `window_statistics` of a settled run (`SteadyResult`)."""
    return [
        r.per_revolution
        if r.per_revolution is not None
        else window_statistics(r.window, r.edges, result.bearing, result.operating)
        for r in result.runs
        if r.measured
    ]


def steady_revolution_maxima(result) -> RevolutionMaxima:
    """The per-revolution largest contact radius and peak flange PV of every measured member of
    a settled run (`revolution_maxima`; no member: empty lists)."""
    return revolution_maxima(_measured_revolutions(result))


def steady_corner_risk(result, confidence: float = CORNER_RISK_CONFIDENCE) -> CornerRisk:
    """`corner_risk` of a settled run (`SteadyResult`): every measured member's revolutions, the
    bearing's limited circle, the peak PV given corner contact."""
    risk = corner_risk_of_revolutions(
        _measured_revolutions(result), float(limited_circle_radius(result.bearing.roller)), confidence
    )
    if risk is None:
        raise UserInputError(
            "result: no member has a measured revolution: nothing to estimate the corner risk from"
        )
    return risk
