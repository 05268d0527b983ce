"""Is a design better than a reference whatever the model's unmeasured constants are?

A design found with the model's representative constants (the traction curve's asymptote D, the
oil fraction of the oil-air mixture; docs/model.md 5 and 8) may owe its gain to them. This
compares a design with a reference over the corners of the constants' stated ranges: for the k
chosen constants x_i with half-widths u_i (`sensitivity_inputs`, the one place the ranges are
stated: `MODEL_CONSTANTS` or the configuration's `[uncertainty]` table), the 2^k corners
x_i +/- u_i and the nominal point (u_i halved, as `perturbed` does, while x_i +/- u_i leaves the
key's valid range). At every corner and operating point both designs run settled
(`run.simulate_steady_points`, every member of one call of the steady-running engine) on the
caller's seeds, which a search must never have used, and give

- the mean flange PV over contact time (`SteadyDesignMetrics.mean_pv`) and
- the peak PV, the expected largest PV of a cage revolution (`flange_pv_Pa_m_s.max` of the
  settled summary, the statistic the design search's verification reports),

each with its Student-t 95 % interval over the seeds. The design is lower at a (corner, point)
when its interval lies wholly below the reference's (disjoint intervals: a one-sided test at
better than 2.5 %). The verdict is that it is lower in both statistics at every corner and
point; `not_lower` lists where it is not.

The drag coefficient is not a constant of the model apart from the oil fraction: the drag
forces and torques are proportional to the oil-air mixture's density (White's C_d(Re) for the
rollers, forces/_drag.py), so the oil fraction's range carries the drag coefficient's
uncertainty (`MODEL_CONSTANTS`). The default constants are therefore the traction asymptote and
the oil fraction (`ROBUSTNESS_CONSTANTS`). Each constant moves alone, as in the sensitivity study:
moving D with A kept moves the whole curve, kappa(0) = A + D included, by the same amount.

The cage slip of every run is kept: it shows that the constants acted (at high speed a lower
traction asymptote lowers the drive of the roller set, and the cage slips more; docs/validation.md,
the skid regime).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .._errors import UserInputError
from ..flange import DEFAULT_FLANGE_LOAD, DesignVariables, check_design, with_design, zone_margins
from ..geometry import OperatingPoint, rad_s_to_rpm
from ..io import Config, require, write_json
from ..run import Estimate, Perturbation, SteadySettings, simulate_steady_points
from ._sensitivity import SensitivityInput, perturbed, sensitivity_inputs
from ._steady_design import CORNER_MARGIN, _metrics
from ._steady_objective import _functionals

#: the constants varied by default: the traction curve's asymptote and the oil fraction (which
#: carries the drag coefficient's uncertainty, module docstring)
ROBUSTNESS_CONSTANTS = ("lubricant.traction_d", "lubricant.oil_fraction")
#: the statistics compared (attribute names of `RobustnessRow`'s estimates)
COMPARED = ("mean_pv", "peak_pv")


@dataclasses.dataclass(frozen=True)
class RobustnessCorner:
    """One combination of the constants: `signs` (-1, +1 per constant; all 0 at the nominal
    point), `values` {key: value}, and a short `name` ("nominal", or "traction_d-, oil_fraction+")."""

    name: str
    signs: tuple[int, ...]
    values: dict


@dataclasses.dataclass(frozen=True)
class RobustnessRow:
    """Both designs at one corner and operating point: mean and peak PV [Pa m/s] and the cage
    slip [1] with 95 % intervals over the seeds, and whether the design is lower (disjoint
    intervals) in mean and in peak PV; `settled`: every seed of both designs settled."""

    corner: int
    point: int
    design_mean_pv: Estimate
    reference_mean_pv: Estimate
    design_peak_pv: Estimate
    reference_peak_pv: Estimate
    design_cage_slip: Estimate
    reference_cage_slip: Estimate
    mean_pv_lower: bool
    peak_pv_lower: bool
    settled: bool

    def to_dict(self) -> dict:
        out = {"corner": self.corner, "point": self.point}
        for f in dataclasses.fields(self)[2:]:
            v = getattr(self, f.name)
            out[f.name] = v.as_dict() if isinstance(v, Estimate) else v
        return out


@dataclasses.dataclass(frozen=True)
class Robustness:
    """A design against a reference over the corners of the constants' ranges (module
    docstring): the constants (with their ranges), corners (nominal first), operating points
    (speed [rpm], radial load [N]), both designs, the seeds, the settled-run settings and one row
    per (corner, point), corners outer."""

    constants: tuple[SensitivityInput, ...]
    steps: tuple[float, ...]
    corners: tuple[RobustnessCorner, ...]
    points: tuple[tuple[float, float], ...]
    design: dict
    reference: dict
    seeds: tuple[int, ...]
    window_revs: int
    num_slices: int
    rows: tuple[RobustnessRow, ...]

    @property
    def not_lower(self) -> tuple[tuple[str, int, str], ...]:
        """(corner name, operating point index, statistic) wherever the design's interval does not
        lie below the reference's."""
        return tuple(
            (self.corners[r.corner].name, r.point, s)
            for r in self.rows
            for s in COMPARED
            if not getattr(r, f"{s}_lower")
        )

    @property
    def lower_everywhere(self) -> bool:
        """The verdict: lower mean and peak PV, disjoint intervals, at every corner and point."""
        return not self.not_lower

    def row(self, corner: int, point: int) -> RobustnessRow:
        return self.rows[corner * len(self.points) + point]

    def to_dict(self) -> dict:
        """Plain data (JSON): everything, with the verdict and where the design is not lower."""
        return {
            "constants": [
                dataclasses.asdict(c) | {"step": h} for c, h in zip(self.constants, self.steps, strict=True)
            ],
            "corners": [dataclasses.asdict(c) | {"signs": list(c.signs)} for c in self.corners],
            "points": [{"speed_rpm": s, "radial_load_N": f} for s, f in self.points],
            "design": self.design,
            "reference": self.reference,
            "seeds": list(self.seeds),
            "window_revs": self.window_revs,
            "num_slices": self.num_slices,
            "unit": {"mean_pv": "Pa m/s", "peak_pv": "Pa m/s", "cage_slip": "1"},
            "rows": [r.to_dict() for r in self.rows],
            "lower_everywhere": self.lower_everywhere,
            "not_lower": [{"corner": c, "point": p, "statistic": s} for c, p, s in self.not_lower],
        }


def write_robustness_json(result: Robustness, path, **extra) -> Path:
    """Write `result.to_dict()` (and `extra` plain data, e.g. the command) as strict JSON."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_json(path, result.to_dict() | extra)
    return path


def robustness_corners(cfg: Config, constants: Sequence[str] = ROBUSTNESS_CONSTANTS):
    """(the chosen `SensitivityInput`s, their steps h, the corners with their configurations):
    the nominal point, then the 2^k corners x_i +/- h_i (module docstring). Unknown or repeated
    constants: one line naming `constants`."""
    inputs = {i.key: i for i in sensitivity_inputs(cfg, model_constants=True)}
    keys = [constants] if isinstance(constants, str) else list(constants)
    for k in keys:
        if k not in inputs:
            raise UserInputError(
                f"constants = {k!r}: must be one of {', '.join(inputs)} (the uncertain inputs with a stated range)"
            )
    if not keys or len(set(keys)) != len(keys):
        raise UserInputError(f"constants = {keys!r}: give one or more different keys of {', '.join(inputs)}")
    chosen = tuple(inputs[k] for k in keys)
    steps = tuple(perturbed(cfg, i, i.plus_minus)[0] for i in chosen)
    out = [(RobustnessCorner("nominal", (0,) * len(keys), {i.key: i.value for i in chosen}), cfg)]
    for signs in itertools.product((-1, 1), repeat=len(keys)):
        values = {i.key: i.value + s * h for i, s, h in zip(chosen, signs, steps)}
        name = ", ".join(f"{i.key.split('.')[-1]}{'+' if s > 0 else '-'}" for i, s in zip(chosen, signs))
        out.append((RobustnessCorner(name, signs, values), cfg.replace(values)))
    return chosen, steps, out


#: an estimate of nothing (no measured seed)
_NOTHING = Estimate(math.nan, math.nan, math.nan, 0)


def _lower(a: Estimate, b: Estimate) -> bool:
    """`a`'s interval wholly below `b`'s (NaN: not shown lower)."""
    return bool(math.isfinite(a.ci95_high) and math.isfinite(b.ci95_low) and a.ci95_high < b.ci95_low)


def robustness(
    cfg: Config,
    design: DesignVariables,
    reference: DesignVariables | None = None,
    ops: Sequence[OperatingPoint] | None = None,
    settings: SteadySettings | None = None,
    *,
    first_seed: int,
    constants: Sequence[str] = ROBUSTNESS_CONSTANTS,
    flange_load: float = DEFAULT_FLANGE_LOAD,
) -> Robustness:
    """`design` against `reference` (default: the configuration's own design) over the corners
    of `constants`' ranges at every operating point of `ops` (default: the configuration's),
    settled with `settings` (seeds, window, ...; default `SteadySettings()`) on the seeds
    first_seed .. first_seed + settings.seeds - 1 (module docstring). Every (corner, design,
    point)'s seeds are members of one engine call."""
    require("first_seed", first_seed, lambda v: (v >= 0) & (v == np.round(v)), "an integer >= 0")
    settings = (settings if settings is not None else SteadySettings()).replace(
        functionals=_functionals("mean")
    )
    ops = [cfg.operating_point()] if ops is None else list(ops)
    if not ops:
        raise UserInputError("ops: no operating point given; give one or more")
    chosen, steps, cases = robustness_corners(cfg, constants)
    base = cfg.bearing()
    reference = DesignVariables.of(base) if reference is None else reference
    designs = (design, reference)
    for d in designs:
        check_design(base, d)
    members = [(b, d, op) for _, c in cases for b in [c.bearing()] for d in designs for op in ops]
    bearings = [with_design(b, d.end_radius, d.layback_angle, d.axial_clearance) for b, d, _ in members]
    results = simulate_steady_points(
        bearings, [op for *_, op in members], settings, perturbation=Perturbation(seed=int(first_seed))
    )
    metrics = [
        _metrics(
            r, d, np.asarray(zone_margins(b, d, flange_load=flange_load)), CORNER_MARGIN, settings.functionals
        )
        for r, b, (_, d, _) in zip(results, bearings, members, strict=True)
    ]
    n = len(ops)
    rows = []
    for c in range(len(cases)):
        for p in range(n):
            mine, ref = metrics[2 * n * c + p], metrics[2 * n * c + n + p]
            rows.append(_row(c, p, mine, ref))
    return Robustness(
        constants=chosen,
        steps=steps,
        corners=tuple(corner for corner, _ in cases),
        points=tuple((float(rad_s_to_rpm(op.inner_speed)), float(op.radial_load)) for op in ops),
        design=metrics[0].design,
        reference=metrics[n].design,
        seeds=tuple(range(int(first_seed), int(first_seed) + settings.seeds)),
        window_revs=settings.window_revs,
        num_slices=int(base.num_slices),
        rows=tuple(rows),
    )


def _row(corner: int, point: int, mine, ref) -> RobustnessRow:
    """One (corner, point) row from the two designs' `SteadyDesignMetrics`."""

    def peak(m) -> Estimate:
        return _NOTHING if m.statistics is None else m.statistics.flange_pv_Pa_m_s.max

    def slip(m) -> Estimate:
        return _NOTHING if m.statistics is None else m.statistics.cage_slip

    dm, rm = mine.mean_pv, ref.mean_pv
    dp, rp = peak(mine), peak(ref)
    return RobustnessRow(
        corner=corner,
        point=point,
        design_mean_pv=dm,
        reference_mean_pv=rm,
        design_peak_pv=dp,
        reference_peak_pv=rp,
        design_cage_slip=slip(mine),
        reference_cage_slip=slip(ref),
        mean_pv_lower=_lower(dm, rm),
        peak_pv_lower=_lower(dp, rp),
        settled=bool(mine.settled and ref.settled),
    )
