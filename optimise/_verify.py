"""Verification of a found design: the design and the reference re-simulated from the skid
start with seeds the search never used, at every operating point (docs/model.md 17).

The search uses seeds 0 .. seeds - 1; the verification `verify_seeds` seeds numbered from
`verify_first_seed` with windows of `verify_window_revs` revolutions. Each design's
`VerifiedPoint` holds mean, p95, peak and tail PV over contact time and the corner-contact
share with their 95 % intervals, the corner margin, and the corner-contact risk per cage
revolution with its bounds (`jaxbearing.run.corner_risk`); `TailVerification` says whether that
risk is bounded at the user's level at every operating point. `Verification.as_json` is the
block result.json stores.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import jax.numpy as jnp
import numpy as np

from jaxbearing.design import Statistic
from jaxbearing.flange import variables_from_array
from jaxbearing.run import CornerCount, CornerRisk, Estimate, revolutions_needed

from ._evaluate import in_shared_pool, operating_points, settled_metrics
from ._problem import PV_SCALE, DesignProblem
from ._settings import SteadySettings

#: an estimate nothing was measured for (a run without statistics)
_NOTHING = Estimate(np.nan, np.nan, np.nan, 0)


@dataclasses.dataclass(frozen=True)
class VerifiedPoint:
    """One design at one operating point on the verification's seeds, in SI units: flange PV
    over contact time (`mean_pv`, `p95_pv`; `peak_pv` the expected largest PV of a cage
    revolution, what the peak statistic aims at; `tail_pv` the mean of the worst 5 %) [Pa m/s],
    the search's `objective` in the statistic's SI unit, the corner-contact share, what the
    faces are designed for besides PV (docs/model.md 5.5: total flange `friction_power` [W],
    the largest `flash_temperature` rise of a contact event [K], the film parameter's 5th
    percentile over contact time), the dynamic corner margin [m] and its bound on the upper 95 %
    prediction bound of one revolution's largest contact radius, how far zero corner contact in
    these seeds bounds the tail (`corner_contact_bound`) and the corner-contact risk per
    revolution (`corner_risk`)."""

    statistic: Statistic
    mean_pv: Estimate
    p95_pv: Estimate
    peak_pv: Estimate
    tail_pv: Estimate
    objective: Estimate
    corner_contact_share: Estimate
    friction_power: Estimate
    flash_temperature: Estimate
    film_parameter_p05: Estimate
    corner_margin: Estimate
    corner_margin_bound: float
    corner_contact_bound: CornerCount | None
    corner_risk: CornerRisk | None
    settled: bool
    seeds: list

    @classmethod
    def of(cls, m, statistic: Statistic) -> VerifiedPoint:
        """From a design's settled metrics (`jaxbearing.design.SteadyDesignMetrics`)."""
        st = m.statistics
        return cls(
            statistic=statistic,
            mean_pv=m.mean_pv,
            p95_pv=m.p95_pv,
            peak_pv=_NOTHING if st is None else st.flange_pv_Pa_m_s.max,
            tail_pv=_NOTHING if st is None else st.flange_pv_contact_time_Pa_m_s.tail95,
            objective=m.objective,
            corner_contact_share=m.corner_contact_share,
            friction_power=_NOTHING if st is None else st.flange_friction_power_W.total,
            flash_temperature=_NOTHING if st is None else st.flange_flash_temperature_K.max,
            film_parameter_p05=_NOTHING if st is None else st.film_parameter.p05,
            corner_margin=m.corner_margin,
            corner_margin_bound=float(m.corner_margin_bound),
            corner_contact_bound=None if st is None else st.corner_contact_bound,
            corner_risk=None if st is None else st.corner_risk,
            settled=m.settled,
            seeds=list(m.seeds),
        )

    def as_json(self) -> dict:
        """The row result.json stores: `mean_pv`, `p95_pv` in Pa m/s and again in GPa m/s
        (`..._GPa_m_s`), each estimate as {"value", "ci95_low", "ci95_high", "n"} (None for
        NaN); the objective under `Statistic.key`; margins in mm."""
        return {
            "mean_pv": _scaled(self.mean_pv, 1.0) | {"unit": "Pa m/s"},
            "p95_pv": _scaled(self.p95_pv, 1.0) | {"unit": "Pa m/s"},
            "mean_pv_GPa_m_s": _scaled(self.mean_pv),
            "p95_pv_GPa_m_s": _scaled(self.p95_pv),
            self.statistic.key: _scaled(self.objective, self.statistic.shown[0]),
            "peak_pv_GPa_m_s": _scaled(self.peak_pv),
            "tail_pv_GPa_m_s": _scaled(self.tail_pv),
            "corner_contact_share": self.corner_contact_share.as_dict(),
            "friction_power_W": _scaled(self.friction_power, 1.0),
            "flash_temperature_K": _scaled(self.flash_temperature, 1.0),
            "film_parameter_p05": _scaled(self.film_parameter_p05, 1.0),
            "corner_margin_mm": _scaled(self.corner_margin, 1e-3),
            "corner_margin_bound_mm": self.corner_margin_bound * 1e3,
            "corner_contact_bound": None
            if self.corner_contact_bound is None
            else self.corner_contact_bound.as_dict(),
            "corner_risk": None if self.corner_risk is None else self.corner_risk.as_dict(),
            "settled": self.settled,
            "seeds": self.seeds,
        }


def _scaled(est: Estimate, unit: float = PV_SCALE) -> dict:
    """`est` divided by `unit`, as {"value", "ci95_low", "ci95_high", "n"} (None for NaN)."""
    d = est.as_dict()
    return {k: v if k == "n" or v is None else v / unit for k, v in d.items()}


@dataclasses.dataclass(frozen=True)
class TailVerification:
    """Whether the verification bounds the found design's corner-contact risk at
    `level_per_revolution` at every operating point: `upper_per_revolution` the largest upper
    bound of `run.corner_risk` over the points (1 where a point has none), `verified` when it
    is at most the level; else the design is unverified in the tail, and `revolutions_needed`
    says how many revolutions per point without corner contact would bound it by counting
    alone."""

    level_per_revolution: float
    upper_per_revolution: float
    methods: list
    revolutions_per_point: list
    verified: bool
    revolutions_needed: int

    def as_json(self) -> dict:
        return dataclasses.asdict(self)


def tail_verification(risks: Sequence[CornerRisk | None], level: float) -> TailVerification:
    """`TailVerification` of the found design's corner-contact risk at each operating point
    (None: not estimated, counted as unbounded)."""
    uppers = [1.0 if r is None or not np.isfinite(r.upper) else float(r.upper) for r in risks]
    upper = max(uppers) if uppers else 1.0
    return TailVerification(
        level_per_revolution=float(level),
        upper_per_revolution=float(upper),
        methods=[None if r is None else r.method for r in risks],
        revolutions_per_point=[0 if r is None else int(r.revolutions) for r in risks],
        verified=bool(upper <= level),
        revolutions_needed=revolutions_needed(level),
    )


def _lower_disjoint(reference: Estimate, optimum: Estimate) -> bool:
    """Whether the optimum's 95 % interval lies wholly below the reference's."""
    return bool(
        np.isfinite(reference.ci95_low)
        and np.isfinite(optimum.ci95_high)
        and optimum.ci95_high < reference.ci95_low
    )


def _not_worse(reference: Estimate, optimum: Estimate, *, higher_is_better: bool) -> bool:
    """Whether the optimum's 95 % interval is not wholly on the worse side of the reference's
    (unknown intervals count as not worse: nothing shows them worse)."""
    bounds = (reference.ci95_low, reference.ci95_high, optimum.ci95_low, optimum.ci95_high)
    if not np.all(np.isfinite(bounds)):
        return True
    if higher_is_better:
        return bool(optimum.ci95_high >= reference.ci95_low)
    return bool(optimum.ci95_low <= reference.ci95_high)


@dataclasses.dataclass(frozen=True)
class Verification:
    """The found design (`optimum`) and the reference design on the verification's `seeds`,
    one `VerifiedPoint` per operating point each, and what they show: lower mean PV and lower
    objective with disjoint intervals (per point and at every point), friction power and film
    parameter not worse, corner contact, and the tail (`TailVerification`)."""

    seeds: list
    reference: tuple[VerifiedPoint, ...]
    optimum: tuple[VerifiedPoint, ...]
    tail: TailVerification

    @property
    def mean_pv_lower_disjoint_per_point(self) -> list[bool]:
        return [_lower_disjoint(r.mean_pv, o.mean_pv) for r, o in zip(self.reference, self.optimum)]

    @property
    def objective_lower_disjoint_per_point(self) -> list[bool]:
        return [_lower_disjoint(r.objective, o.objective) for r, o in zip(self.reference, self.optimum)]

    @property
    def mean_pv_lower_disjoint(self) -> bool:
        """Lower mean PV with disjoint 95 % intervals at every operating point."""
        return all(self.mean_pv_lower_disjoint_per_point)

    @property
    def objective_lower_disjoint(self) -> bool:
        return all(self.objective_lower_disjoint_per_point)

    @property
    def friction_power_not_worse(self) -> bool:
        pairs = zip(self.reference, self.optimum)
        return all(_not_worse(r.friction_power, o.friction_power, higher_is_better=False) for r, o in pairs)

    @property
    def film_parameter_not_worse(self) -> bool:
        pairs = zip(self.reference, self.optimum)
        return all(
            _not_worse(r.film_parameter_p05, o.film_parameter_p05, higher_is_better=True) for r, o in pairs
        )

    @property
    def optimum_corner_contacts(self) -> bool:
        return any(np.nan_to_num(o.corner_contact_share.value) > 0 for o in self.optimum)

    @staticmethod
    def corner_contact_upper95(rows: Sequence[VerifiedPoint]) -> float | None:
        """The weakest upper 95 % bound per revolution of zero corner contact over the points
        (None: no point counted)."""
        bounds = [r.corner_contact_bound.per_revolution_upper95 for r in rows if r.corner_contact_bound]
        return max(bounds) if bounds else None

    def as_json(self) -> dict:
        """The verification block of result.json (one row per design, or `per_operating_point`
        rows where there are several points)."""

        def rows(points):
            out = [p.as_json() for p in points]
            return out[0] if len(out) == 1 else {"per_operating_point": out}

        out = {"seeds": self.seeds, "reference": rows(self.reference), "optimum": rows(self.optimum)}
        out["mean_pv_lower_disjoint"] = self.mean_pv_lower_disjoint
        out["objective_lower_disjoint"] = self.objective_lower_disjoint
        if len(self.optimum) > 1:
            out["mean_pv_lower_disjoint_per_operating_point"] = self.mean_pv_lower_disjoint_per_point
            out["objective_lower_disjoint_per_operating_point"] = self.objective_lower_disjoint_per_point
        out["friction_power_not_worse"] = self.friction_power_not_worse
        out["film_parameter_not_worse"] = self.film_parameter_not_worse
        out["optimum_corner_contacts"] = self.optimum_corner_contacts
        for name, points in (("reference", self.reference), ("optimum", self.optimum)):
            bound = self.corner_contact_upper95(points)
            if bound is not None:
                out[f"{name}_corner_contact_per_revolution_upper95"] = bound
        out["tail"] = self.tail.as_json()
        return out


@in_shared_pool
def verification(problem: DesignProblem, settings: SteadySettings, design, reference) -> Verification:
    """The found design and the reference design re-simulated from the skid start with seeds
    the search never used (module docstring), at every operating point: both designs' points'
    seeds members of one call of the steady-running engine."""
    ops = operating_points(problem)
    designs = [variables_from_array(jnp.asarray(x)) for x in (reference, design)]
    metrics = settled_metrics(
        problem,
        settings,
        list(range(len(ops))) * 2,
        [d for d in designs for _ in ops],
        verification=True,
        first_seed=settings.verify_first_seed,
    )
    points = [VerifiedPoint.of(m, settings.statistic) for m in metrics]
    optimum = tuple(points[len(ops) :])
    return Verification(
        seeds=list(range(settings.verify_first_seed, settings.verify_first_seed + settings.verify_seeds)),
        reference=tuple(points[: len(ops)]),
        optimum=optimum,
        tail=tail_verification([p.corner_risk for p in optimum], settings.corner_risk_level),
    )
