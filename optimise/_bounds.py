"""The search box: lower and upper bounds of every design variable, from one table per design kind.

Two kinds of design are searched. `Bounds`: the three variables of the paper's design zone,
x = (R_end [m], theta_f [rad], Delta_bf [m]) (`jaxbearing.flange.DesignVariables`).
`ProfileBounds`: the eight variables of the roller end and rib faces, x = (R_end, e, R_cor,
1/R_rib, h_t, theta_f, H_rf, Delta_bf) (`jaxbearing.flange.ProfileVariables`, docs/model.md 5.4).
Both are the same box: each variable's row of the table (`Variable`: its engineering unit, the
factor from SI, its valid range) drives the range checks, the engineering-unit keys of the TOML
file (`[bounds] end_offset_mm = [0, 1]`) and the map to the unit box, x = lo + u (hi - lo),
u in [0, 1]^n. A variable whose bounds coincide (lo = hi) is held fixed.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from typing import ClassVar

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from jaxbearing import Bearing, UserInputError
from jaxbearing.flange import PROFILE_NAMES, variables_from_array
from jaxbearing.io import is_concrete, require

MM = 1e-3
DEG = math.pi / 180


@dataclasses.dataclass(frozen=True)
class Variable:
    """One design variable of a search box: its field name, its key in engineering units (the
    TOML file's and the messages'), the factor engineering unit -> SI, and its valid range in
    that unit (a predicate and its text)."""

    name: str
    key: str
    si: float
    ok: Callable[[float], bool]
    valid: str

    @property
    def scale(self) -> float:
        """The factor SI -> engineering unit."""
        return 1 / self.si


_POSITIVE_MM = (lambda v: v > 0, "> 0 mm")
_NON_NEGATIVE_MM = (lambda v: v >= 0, ">= 0 mm")

#: the three variables of `Bounds` (R_end > D/2 is checked against the roller in `check`)
DESIGN_TABLE = (
    Variable("end_radius", "end_radius_mm", MM, lambda v: v > 0, "> 0 mm (and > D/2 of the roller)"),
    Variable("layback_angle", "layback_angle_deg", DEG, lambda v: (v >= 0) & (v < 45), "in [0, 45) deg"),
    Variable("axial_clearance", "axial_clearance_mm", MM, *_POSITIVE_MM),
)

#: the eight variables of `ProfileBounds`, in the order of `jaxbearing.flange.PROFILE_NAMES`;
#: the rib as its curvature 1/R_rib [1/m] (0: the cone), so that the box contains today's rib
PROFILE_TABLE = (
    DESIGN_TABLE[0],
    Variable("end_offset", "end_offset_mm", MM, *_NON_NEGATIVE_MM),
    Variable("corner_radius", "corner_radius_mm", MM, *_POSITIVE_MM),
    Variable("rib_curvature", "rib_curvature_per_m", 1.0, lambda v: v >= 0, ">= 0 1/m (0: the cone)"),
    Variable("rib_tangent_height", "rib_tangent_height_mm", MM, *_NON_NEGATIVE_MM),
    DESIGN_TABLE[1],
    Variable("flange_height", "flange_height_mm", MM, *_POSITIVE_MM),
    DESIGN_TABLE[2],
)
assert tuple(v.name for v in PROFILE_TABLE) == PROFILE_NAMES


@dataclasses.dataclass(frozen=True)
class _Box:
    """Box bounds (lower, upper) in SI units of every variable of `TABLE` (module docstring)."""

    TABLE: ClassVar[tuple[Variable, ...]] = ()

    def __post_init__(self):
        """Each bound finite and in its range (`jaxbearing.io.require`), lower <= upper."""
        for var in self.TABLE:
            pair = getattr(self, var.name)
            if len(pair) != 2:
                raise UserInputError(f"bounds.{var.key} = {pair!r}: expected (lower, upper)")
            lo, hi = (float(f"{float(v) * var.scale:.12g}") for v in pair)  # 60 deg, not 59.99999999999999
            for which, v in (("lower", lo), ("upper", hi)):
                require(
                    f"bounds.{var.key} {which} bound",
                    v,
                    lambda x, ok=var.ok: np.isfinite(x) & ok(x),
                    var.valid,
                )
            if lo > hi:
                raise UserInputError(f"bounds.{var.key} = [{lo:g}, {hi:g}]: lower bound above upper bound")

    @property
    def names(self) -> tuple[str, ...]:
        """The variables' field names, in the order of the design arrays."""
        return tuple(v.name for v in self.TABLE)

    @property
    def clearance_index(self) -> int:
        """The position of Delta_bf in the design arrays."""
        return self.names.index("axial_clearance")

    @property
    def lower(self) -> np.ndarray:
        return np.array([getattr(self, v.name)[0] for v in self.TABLE])

    @property
    def upper(self) -> np.ndarray:
        return np.array([getattr(self, v.name)[1] for v in self.TABLE])

    def to_scaled(self, x) -> Array:
        """u = (x - lo) / (hi - lo) (0 for fixed variables)."""
        width = self.upper - self.lower
        return jnp.where(width > 0, (jnp.asarray(x) - self.lower) / jnp.where(width > 0, width, 1.0), 0.0)

    def from_scaled(self, u) -> Array:
        """x = lo + u (hi - lo)."""
        return self.lower + jnp.asarray(u) * (self.upper - self.lower)

    def variables(self, x):
        """The design of the SI array x: `DesignVariables` (3) or `ProfileVariables` (8)."""
        return variables_from_array(x)

    def engineering(self) -> dict:
        """Bounds in engineering units, by key (`end_radius_mm`: [lower, upper], ...)."""
        return {v.key: [b * v.scale for b in getattr(self, v.name)] for v in self.TABLE}

    def engineering_values(self, x) -> dict:
        """The SI design array x in engineering units, by key."""
        return {v.key: float(xi) * v.scale for v, xi in zip(self.TABLE, np.asarray(x, dtype=float))}

    @classmethod
    def from_engineering(cls, values) -> np.ndarray:
        """The SI design array of `values` in engineering units, in the order of `TABLE` (the
        inverse of `engineering_values`)."""
        values = np.asarray(values, dtype=float)
        if values.shape != (len(cls.TABLE),):
            raise UserInputError(
                f"design = {values.tolist()}: must be {len(cls.TABLE)} values "
                f"({', '.join(v.key for v in cls.TABLE)})"
            )
        return np.array([value * v.si for value, v in zip(values, cls.TABLE)])

    def _require_bound(self, name: str, which: str, ok, valid: str) -> None:
        var = next(v for v in self.TABLE if v.name == name)
        value = getattr(self, name)[0 if which == "lower" else 1]
        require(f"bounds.{var.key} {which} bound", float(f"{value * var.scale:.12g}"), ok, valid)


@dataclasses.dataclass(frozen=True)
class Bounds(_Box):
    """Box bounds of the design, SI units (R_end [m], theta_f [rad], Delta_bf [m]).

    Defaults: a sensible range around the reference design (R_end 60-120 mm, theta_f 1.0-2.0
    deg, Delta_bf 0.10-0.30 mm). lo == hi fixes a variable."""

    TABLE: ClassVar[tuple[Variable, ...]] = DESIGN_TABLE

    end_radius: tuple[float, float] = (60 * MM, 120 * MM)
    layback_angle: tuple[float, float] = (1.0 * DEG, 2.0 * DEG)
    axial_clearance: tuple[float, float] = (0.10 * MM, 0.30 * MM)

    def check(self, bearing: Bearing) -> None:
        """The end-radius bounds against the roller of `bearing`: R_end > D/2 (the end must be
        convex and meet the corner torus; the same range as `roller.end_radius_mm`)."""
        if not is_concrete(bearing.roller.diameter):
            return
        half_d = _mm(np.max(np.asarray(bearing.roller.diameter)) / 2)
        for which in ("lower", "upper"):
            self._require_bound(
                "end_radius",
                which,
                lambda x: x > half_d,
                f"> D/2 = {half_d:g} mm (half the roller diameter of the bearing)",
            )


@dataclasses.dataclass(frozen=True)
class ProfileBounds(_Box):
    """Box bounds of the profile design, SI units (R_end [m], e [m], R_cor [m], 1/R_rib [1/m],
    h_t [m], theta_f [rad], H_rf [m], Delta_bf [m]; `jaxbearing.flange.ProfileVariables`).

    Defaults: around the reference bearing (D = 7.5 mm, R_cor 0.4 mm, H_rf 2 mm): R_end 60-120
    mm, e 0-1 mm, R_cor 0.3-0.6 mm, 1/R_rib 0-5 1/m (R_rib >= 200 mm, less curved than any end
    in the box), h_t 0-1.5 mm, theta_f 1.0-2.0 deg, H_rf 1.9-2.4 mm (above the reference's h_up 1.8 mm), Delta_bf 0.10-0.30 mm.
    lo == hi fixes a variable."""

    TABLE: ClassVar[tuple[Variable, ...]] = PROFILE_TABLE

    end_radius: tuple[float, float] = (60 * MM, 120 * MM)
    end_offset: tuple[float, float] = (0.0, 1.0 * MM)
    corner_radius: tuple[float, float] = (0.3 * MM, 0.6 * MM)
    rib_curvature: tuple[float, float] = (0.0, 5.0)
    rib_tangent_height: tuple[float, float] = (0.0, 1.5 * MM)
    layback_angle: tuple[float, float] = (1.0 * DEG, 2.0 * DEG)
    flange_height: tuple[float, float] = (1.9 * MM, 2.4 * MM)
    axial_clearance: tuple[float, float] = (0.10 * MM, 0.30 * MM)

    def check(self, bearing: Bearing) -> None:
        """Every profile in the box makes faces of `bearing`'s roller (`check_profile`'s
        ranges at the box's worst corner): R_end > D/2, R_cor < D/2, h_up < H_rf < D (h_up the
        bearing's upper limit of the contact height), e < D/2 - R_cor, 1/R_rib < 1/R_end,
        h_t <= H_rf."""
        if not is_concrete(bearing.roller.diameter):
            return
        d = _mm(np.max(np.asarray(bearing.roller.diameter)))
        self._require_bound("end_radius", "lower", lambda x: x > d / 2, f"> D/2 = {d / 2:g} mm")
        self._require_bound("corner_radius", "upper", lambda x: x < d / 2, f"< D/2 = {d / 2:g} mm")
        self._require_bound("flange_height", "upper", lambda x: x < d, f"< D = {d:g} mm")
        h_up = _mm(np.max(np.asarray(bearing.flange.contact_height_limit)))
        self._require_bound(
            "flange_height", "lower", lambda x: x > h_up, f"> the contact height limit h_up = {h_up:g} mm"
        )
        r_ce = d / 2 - _mm(self.corner_radius[1])
        self._require_bound(
            "end_offset", "upper", lambda x: x < r_ce, f"< D/2 - R_cor (upper bound) = {r_ce:g} mm"
        )
        kappa = 1 / self.end_radius[1]
        self._require_bound(
            "rib_curvature", "upper", lambda x: x < kappa, f"< 1/R_end (upper bound) = {kappa:g} 1/m"
        )
        h_rf = _mm(self.flange_height[0])
        self._require_bound(
            "rib_tangent_height", "upper", lambda x: x <= h_rf, f"<= H_rf (lower bound) = {h_rf:g} mm"
        )


def _mm(value) -> float:
    return float(f"{float(value) / MM:.12g}")


def box_from_engineering(kind: type[_Box], values: Mapping[str, object], base: _Box | None = None) -> _Box:
    """Bounds of `kind` from {key: [lower, upper]} in engineering units (the TOML `[bounds]`
    keys: `end_radius_mm`, ...); a key missing or None keeps `base` (default `kind()`)."""
    base = base or kind()
    known = {v.key: v for v in kind.TABLE}
    for key in values:
        if key not in known:
            raise UserInputError(f"bounds.{key}: unknown (valid: {', '.join(known)})")
    fields = {}
    for key, var in known.items():
        v = values.get(key)
        if v is None:
            fields[var.name] = getattr(base, var.name)
            continue
        v = list(v) if isinstance(v, list | tuple) else [v]
        if len(v) != 2:
            raise UserInputError(f"bounds.{key}: expected [lower, upper], got {v}")
        fields[var.name] = (float(v[0]) * var.si, float(v[1]) * var.si)
    return kind(**fields)
