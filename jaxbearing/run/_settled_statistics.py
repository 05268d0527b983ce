"""The statistics of settled running as a typed object (docs/model.md 16).

`SettledStatistics` holds every statistic of a settled run's measurement window as fields, each
an `Estimate` (value and 95 % interval, `_statistics`); groups of one quantity's reductions per
cage revolution (the largest event of a revolution, its mean, ...) are small frozen classes of
their own. Callers read fields (`stats.flange_pv_Pa_m_s.max.value`); the summary.json block is
written from the object (`as_dict`), the one place where the statistics get their text keys.
"""

from __future__ import annotations

import dataclasses
import typing
from typing import Any

from ..geometry import kinematic_cage_speed, limited_circle_radius, rad_s_to_rpm
from ._corner_risk import CornerRisk, corner_risk_of_revolutions
from ._statistics import (
    CornerCount,
    Estimate,
    PredictionBound,
    confidence_intervals,
    corner_contact_bound,
    max_contact_radius_bound,
    revolution_statistics,
)
from ._summary import CONTACT_THRESHOLD

#: the estimate of a statistic that was not measured
_NOT_MEASURED = Estimate(float("nan"), float("nan"), float("nan"), 0)


def _estimates(cls, flat: dict[str, Estimate], prefix: str):
    """`cls` with each field the estimate of "prefix.field" in `flat` (not measured where absent)."""
    return cls(**{f.name: flat.get(f"{prefix}.{f.name}", _NOT_MEASURED) for f in dataclasses.fields(cls)})


def _nested(group) -> dict:
    """A group's estimates as {reduction: {"value", "ci95_low", "ci95_high", "n"}}."""
    return {f.name: getattr(group, f.name).as_dict() for f in dataclasses.fields(group)}


@dataclasses.dataclass(frozen=True)
class Reductions:
    """A group of one quantity's statistics per cage revolution, each field an `Estimate`: nested
    under the quantity's name in the summary block, "quantity.reduction" in `estimates`."""


@dataclasses.dataclass(frozen=True)
class PerEvent(Reductions):
    """One flange-contact quantity over the contact events of a cage revolution: the largest,
    the mean, the median and the 95th percentile of the events' values, each the expectation
    per revolution with its interval."""

    max: Estimate
    mean: Estimate
    median: Estimate
    p95: Estimate


@dataclasses.dataclass(frozen=True)
class ContactRadius(PerEvent):
    """The contact point's distance from the roller axis [m] (`PerEvent`), and over contact
    time: its 99th percentile and the largest of any touching sample (`max_in_contact`: the
    corner is reached in a revolution exactly when it exceeds the limited circle)."""

    p99: Estimate
    max_in_contact: Estimate


@dataclasses.dataclass(frozen=True)
class ContactTimePV(Reductions):
    """Flange PV over contact time [Pa m/s] (every touching sample, equally spaced in time), per
    revolution: the mean, the 95th percentile and the tail mean above it (`tail_mean`)."""

    mean: Estimate
    p95: Estimate
    tail95: Estimate


@dataclasses.dataclass(frozen=True)
class RollerSkew(Reductions):
    """The roller skew angle's magnitude [rad] per revolution: mean and largest."""

    mean_abs: Estimate
    max_abs: Estimate


@dataclasses.dataclass(frozen=True)
class CornerShare(Reductions):
    """The share of contact beyond the limited circle: of contact time and of contact events."""

    time: Estimate
    events: Estimate


@dataclasses.dataclass(frozen=True)
class MinimumFilm(Reductions):
    """The minimum film thickness at the flange over contact time [m]."""

    min: Estimate
    p05: Estimate
    median: Estimate


@dataclasses.dataclass(frozen=True)
class CentralFilm(Reductions):
    """The central film thickness at the flange over contact time [m]."""

    min: Estimate
    median: Estimate


@dataclasses.dataclass(frozen=True)
class FilmParameter(Reductions):
    """The film parameter Lambda (film over composite roughness) over contact time."""

    mean: Estimate
    median: Estimate
    p05: Estimate
    min: Estimate


@dataclasses.dataclass(frozen=True)
class FrictionPower(Reductions):
    """The time-mean friction power mu Q |u| [W] over each cage revolution, of each flange
    (summed over the rollers; inner -X, inner +X, outer -X, outer +X) and in total
    (docs/model.md 5.5). The field names are `_summary.FRICTION_POWER_NAMES`."""

    inner_neg_x: Estimate
    inner_pos_x: Estimate
    outer_neg_x: Estimate
    outer_pos_x: Estimate
    total: Estimate


@dataclasses.dataclass(frozen=True)
class SettledStatistics:
    """Every statistic of a settled run's window (module docstring). Units in the field names;
    `cage_slip` = (kinematic - measured)/kinematic cage speed; `flange_flash_temperature_K`: the
    largest flash temperature rise at the rib of each contact event, `flange_friction_power_W`:
    the time-mean friction power (docs/model.md 5.5); `ci_method`: how the intervals
    were formed (batch means of one seed, or the ensemble of seeds); `corner_risk`: the
    corner-contact risk per revolution (None without a measured revolution)."""

    cage_speed_rpm: Estimate
    cage_slip: Estimate
    flange_force_N: PerEvent
    flange_pressure_Pa: PerEvent
    flange_sliding_velocity_m_s: PerEvent
    flange_roller_surface_speed_m_s: PerEvent
    flange_pv_Pa_m_s: PerEvent
    flange_flash_temperature_K: PerEvent
    flange_friction_power_W: FrictionPower
    contact_height_m: PerEvent
    contact_radius_m: ContactRadius
    roller_skew_rad: RollerSkew
    corner_contact_share: CornerShare
    flange_contact_events_per_rev: Estimate
    flange_pv_contact_time_Pa_m_s: ContactTimePV
    flange_min_film_m: MinimumFilm
    flange_central_film_m: CentralFilm
    film_parameter: FilmParameter
    lambda_below_one_share: Estimate
    top_edge_contact_share: Estimate
    flange_face_error_max_m: Estimate
    ci_method: str
    corner_contact_bound: CornerCount
    max_contact_radius_bound: PredictionBound
    corner_risk: CornerRisk | None
    limited_circle_radius_m: float
    kinematic_cage_speed_rpm: float

    @classmethod
    def of(cls, flat: dict[str, Estimate], **rest: Any) -> SettledStatistics:
        """From the flat estimates of `confidence_intervals` ("group.reduction" or "name"; an
        absent one is not measured: NaN, n = 0) and the remaining fields by keyword."""
        groups = {name: _estimates(group, flat, name) for name, group in _GROUPS.items()}
        return cls(**groups, **{name: flat.get(name, _NOT_MEASURED) for name in _SINGLES}, **rest)

    def estimates(self) -> dict[str, Estimate]:
        """Every estimate by its summary name, "group.reduction" or "name" (the keys of
        `revolution_statistic_keys`): for tables whose columns are named."""
        out: dict[str, Estimate] = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, Reductions):
                out.update({f"{f.name}.{g.name}": getattr(v, g.name) for g in dataclasses.fields(v)})
            elif isinstance(v, Estimate):
                out[f.name] = v
        return out

    def as_dict(self) -> dict:
        """The summary.json block: each estimate as {"value", "ci95_low", "ci95_high", "n"}
        (None for NaN), groups nested by reduction."""
        out: dict = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, Reductions):
                out[f.name] = _nested(v)
            elif isinstance(v, Estimate):
                out[f.name] = v.as_dict()
            elif hasattr(v, "as_dict"):
                out[f.name] = v.as_dict()
            else:
                out[f.name] = v
        return out


#: the fields of `SettledStatistics` that are groups of reductions, and those that are single
#: estimates (read from its annotations: the class is the one list of its statistics)
_HINTS = typing.get_type_hints(SettledStatistics)
_GROUPS = {n: t for n, t in _HINTS.items() if isinstance(t, type) and issubclass(t, Reductions)}
_SINGLES = tuple(n for n, t in _HINTS.items() if t is Estimate)


def settled_statistics(
    windows: list[dict], edges: list, bearing, op, threshold: float = CONTACT_THRESHOLD, per_revolution=None
) -> SettledStatistics:
    """The statistics of a settled run: `windows` are the measurement-window histories of each
    seed, `edges` their revolution boundaries [s]; or, instead, `per_revolution`: each seed's
    `window_statistics`, computed as the seed finished. At least one seed's window."""
    rho_lim = float(limited_circle_radius(bearing.roller))
    kin = float(kinematic_cage_speed(bearing, op))
    per_rev = list(per_revolution) if per_revolution is not None else []
    per_rev += [revolution_statistics(h, e, rho_lim, kin, threshold) for h, e in zip(windows, edges)]
    est, method = confidence_intervals(per_rev)
    return SettledStatistics.of(
        est,
        ci_method=method,
        corner_contact_bound=corner_contact_bound(per_rev, rho_lim),
        max_contact_radius_bound=max_contact_radius_bound(per_rev),
        corner_risk=corner_risk_of_revolutions(per_rev, rho_lim),
        limited_circle_radius_m=rho_lim,
        kinematic_cage_speed_rpm=float(rad_s_to_rpm(kin)),
    )


def steady_statistics(
    windows: list[dict], edges: list, bearing, op, threshold: float = CONTACT_THRESHOLD, per_revolution=None
) -> dict:
    """The summary.json statistics block of a settled run (`settled_statistics(...).as_dict()`)."""
    return settled_statistics(windows, edges, bearing, op, threshold, per_revolution).as_dict()
