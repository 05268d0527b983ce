"""Configuration schema and validation, before any JAX tracing.

Every configuration key is described once, here, by a `Key`: its dotted path (the unit is part
of the name), type, reference value in engineering units, symbol, meaning, valid range and the
field of the `jaxbearing._params` pytree it maps onto. The TOML reader and writer
(`jaxbearing._config`), the comments of `jaxbearing config show` and `validate_bearing` (for
pytrees built directly in Python) all read this one table, so the documented range is the
checked range.

Ranges are those a bearing engineer would accept for a cylindrical roller bearing; they are
checked in dependency order (a roller's corner radius only after its diameter), and the first
violation raises `jaxbearing.ConfigError(field, message)` whose one-line text names the key, the
value with its unit and the valid range, e.g.

    roller.corner_radius_mm: 4.0 mm is out of range: must be in (0, diameter_mm/2 = 3.75) mm

Schema (ranges; "(" open, "[" closed; symbols as in docs/MODEL.md and the source paper):

| key | symbol | valid range |
|---|---|---|
| bearing.pitch_diameter_mm | d_m | (0, 10000] |
| bearing.radial_clearance_um | P_d (diametral) | [0, pitch_diameter_mm*10] (1 % of d_m) |
| bearing.num_rollers | Z | integer >= 3 with Z (D + C_p) < pi d_m |
| bearing.num_slices | N_s | odd integer in [3, 200] |
| bearing.inner_ring_mass_kg | m_i | (0, 1e5] |
| bearing.flange_traction, pocket_friction | mu_f, mu_p | [0, 1] |
| roller.diameter_mm | D | (0, pitch_diameter_mm/2) |
| roller.corner_radius_mm | R_cor | (0, diameter_mm/2) |
| roller.length_mm | L_b1 | (2 corner_radius_mm, 10 diameter_mm] |
| roller.central_length_mm | L_b2 | [0, length_mm - 2 corner_radius_mm] |
| roller.crown_drop_um | c_crown | [0, diameter_mm/10] |
| roller.end_radius_mm | R_end | (diameter_mm/2, inf], inf = flat end |
| flange.height_mm | H_rf | (0, diameter_mm) |
| flange.relief_height_mm | h_rel | [0, height_mm) |
| flange.contact_height_limit_mm | h_up | (relief_height_mm, height_mm] |
| flange.layback_angle_deg | theta_f | (0, 10] |
| flange.axial_clearance_mm | Delta_bf | [0, length_mm) |
| cage.inner_diameter_mm | | (inner raceway diameter, pitch_diameter_mm) |
| cage.outer_diameter_mm | | (pitch_diameter_mm, outer raceway diameter - guiding_clearance_mm] |
| cage.width_mm | | (length_mm + pocket_clearance_mm, 3 length_mm] |
| cage.pocket_clearance_mm, guiding_clearance_mm | C_p, C_g | (0, diameter_mm/2) |
| cage.land_width_mm | b_l | (0, width_mm/2] |
| materials.*.elastic_modulus_GPa | E | (0, 1500] |
| materials.*.poisson_ratio | nu | (-1, 0.5) |
| materials.*.density_kg_m3 | rho | (0, 25000] |
| lubricant.viscosity_Pa_s | eta_0 | (0, 100] |
| lubricant.pressure_viscosity_1_Pa | alpha_p | [0, 1e-6] |
| lubricant.temperature_viscosity_1_C | beta_T | [0, 1] |
| lubricant.density_kg_m3 | rho_oil | (0, 2000] |
| lubricant.oil_fraction | f_oil | [0, 1] |
| lubricant.traction_a, traction_d | A, D | [-1, 1] |
| lubricant.traction_b_s_m | B | [-1e4, 1e4], and the curve stays within [-1, 1] |
| lubricant.traction_c_s_m | C | (0, 1e4] |
| operating.speed_rpm | n_i | [0, 100000] |
| operating.radial_load_N | F_r | [0, 1e8] |
| operating.gravity | g | true / false (9.81 m/s^2 along +Z) |
| simulation.end | | "arc", "corner" or "both" |
| simulation.duration_ms | | (0, 10000] |
| simulation.rtol, atol | | (0, 1) |
| simulation.max_steps | | integer in [1, 1e9] |
| simulation.progress | | true / false |

The inner and outer raceway diameters are d_m -/+ (D + P_d/2) (`Bearing.inner_raceway_radius`).
Non-finite values are rejected everywhere except `roller.end_radius_mm = inf`.
"""

from __future__ import annotations

import dataclasses
import json
import math
import numbers
import re
from collections.abc import Callable, Iterable, Mapping
from typing import Any

import numpy as np

from .._errors import ConfigError
from ..geometry import rad_s_to_rpm, rpm_to_rad_s

#: gravitational acceleration used when `operating.gravity = true` [m/s^2] (as the reference).
GRAVITY = 9.81

# --------------------------------------------------------------------------------------------
# units: engineering value <-> SI. The micrometre conversion goes through millimetres so the
# reference configuration reproduces `reference_bearing()` bit for bit (0.020 * 1e-3).
_UNITS: dict[str, tuple[Callable[[float], float], Callable[[float], float]]] = {
    "mm": (lambda x: x * 1e-3, lambda x: x * 1e3),
    "um": (lambda x: (x / 1000) * 1e-3, lambda x: x * 1e6),
    "GPa": (lambda x: x * 1e9, lambda x: x / 1e9),
    "deg": (math.radians, math.degrees),
    "rpm": (rpm_to_rad_s, rad_s_to_rpm),
}


def _identity(x):
    return x


def format_value(value: Any, digits: int = 12) -> str:
    """A value as shown in messages: floats to 12 significant digits (so that 0.30000000000000004
    reads 0.3; derived quantities use fewer), strings quoted, booleans in TOML spelling."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        v = float(value)
        if not math.isfinite(v):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
        return repr(float(f"{v:.{digits}g}"))
    if isinstance(value, str):
        return json.dumps(value)
    return repr(value)


def _derived(x: float) -> str:
    """A quantity computed from other keys, for messages (6 significant digits)."""
    return format_value(x, digits=6)


def type_name(value: Any) -> str:
    """TOML-flavoured name of a value's type, for error messages."""
    if isinstance(value, (bool, np.bool_)):
        return "boolean"
    if isinstance(value, numbers.Integral):
        return "integer"
    if isinstance(value, numbers.Real):
        return "float"
    if isinstance(value, str):
        return "string"
    if isinstance(value, Mapping):
        return "table"
    if isinstance(value, (list, tuple)):
        return "array"
    return type(value).__name__


# --------------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class Bound:
    """One end of a valid range: a constant, or an expression of other keys (`deps`)."""

    label: str
    value: Callable[[Mapping[str, Any]], float]
    closed: bool
    deps: tuple[str, ...] = ()


def _short(x: float) -> str:
    """1e+08 -> 1e8, 1e-06 -> 1e-6, 100000 -> 100000."""
    return re.sub(r"e\+?(-?)0*(\d)", r"e\1\2", f"{x:g}")


def _const(x: float, closed: bool) -> Bound:
    return Bound(_short(x), lambda v: x, closed)


def _rel(label: str, deps: tuple[str, ...], fn: Callable[..., float], closed: bool) -> Bound:
    return Bound(label, lambda v: fn(*(v[d] for d in deps)), closed, deps)


@dataclasses.dataclass(frozen=True)
class Extra:
    """A check that is not a range on one key (rollers fitting around the pitch circle...).

    `check(values)` returns None when satisfied, else the message (without the field name).
    """

    deps: tuple[str, ...]
    check: Callable[[Mapping[str, Any]], str | None]
    doc: str


@dataclasses.dataclass(frozen=True)
class Key:
    """One configuration key.

    `attr` is the pytree field it maps onto: "pitch_diameter", "roller.diameter" (fields of
    `Bearing`) or "op.inner_speed" (fields of `OperatingPoint`); None for simulation settings.
    """

    path: str
    kind: type
    default: Any
    unit: str
    symbol: str
    meaning: str
    lo: Bound | None = None
    hi: Bound | None = None
    attr: str | None = None
    allow_inf: bool = False
    choices: tuple[str, ...] = ()
    extras: tuple[Extra, ...] = ()
    note: str = ""

    @property
    def section(self) -> str:
        return self.path.rpartition(".")[0]

    @property
    def name(self) -> str:
        return self.path.rpartition(".")[2]

    @property
    def deps(self) -> tuple[str, ...]:
        out: list[str] = []
        for b in (self.lo, self.hi):
            if b is not None:
                out += b.deps
        for e in self.extras:
            out += e.deps
        return tuple(dict.fromkeys(d for d in out if d != self.path))

    def to_si(self, value):
        return _UNITS.get(self.unit, (_identity, _identity))[0](value)

    def from_si(self, value):
        return _UNITS.get(self.unit, (_identity, _identity))[1](value)

    def range_text(self, values: Mapping[str, Any] | None = None) -> str:
        """'in (0, diameter_mm/2 = 3.75)' (values given) or 'in (0, diameter_mm/2)'."""
        if self.choices:
            return "one of " + ", ".join(format_value(c) for c in self.choices)
        if self.kind is bool:
            return "true or false"

        def show(b: Bound) -> str:
            if values is None or not b.deps:
                return b.label
            return f"{b.label} = {_derived(b.value(values))}"

        lo, hi = self.lo, self.hi
        if lo is not None and hi is None and not self.allow_inf:
            return (">= " if lo.closed else "> ") + show(lo)
        lo_s = ("[" if lo.closed else "(") + show(lo) if lo is not None else "(-inf"
        hi_s = (
            (show(hi) + ("]" if hi.closed else ")"))
            if hi is not None
            else "inf" + ("]" if self.allow_inf else ")")
        )
        return f"in {lo_s}, {hi_s}"

    def doc(self) -> str:
        """One comment line: meaning, symbol, unit and valid range (and any further rule)."""
        sym = f" {self.symbol}" if self.symbol else ""
        unit = f" [{self.unit}]" if self.unit else ""
        kind = "integer " if self.kind is int else ""
        text = f"{self.meaning}{sym}{unit}, {kind}{self.range_text()}"
        for extra in (self.note, *(e.doc for e in self.extras)):
            if extra:
                text += f"; {extra}"
        return text


def _k(path, kind, default, unit, symbol, meaning, lo=None, hi=None, **kw) -> Key:
    return Key(path, kind, default, unit, symbol, meaning, lo, hi, **kw)


# -- extra checks ------------------------------------------------------------------------------
def _rollers_fit(v) -> str | None:
    """Roller complement: Z rollers of diameter D and Z cage bars share the pitch circle,
    Z D < pi d_m (rollers do not overlap) and Z (D + C_p) < pi d_m (bars of positive width at
    the pitch circle; the roller complement of Harris & Kotzalas, Essential Concepts of
    Bearing Technology)."""
    z, d, cp = v["bearing.num_rollers"], v["roller.diameter_mm"], v["cage.pocket_clearance_mm"]
    circ = math.pi * v["bearing.pitch_diameter_mm"]
    if z * d >= circ:
        return (
            f"{z} rollers do not fit around the pitch circle (neighbouring rollers overlap): "
            f"Z D = {_derived(z * d)} mm must be < pi d_m = {_derived(circ)} mm"
        )
    if z * (d + cp) >= circ:
        return (
            f"{z} rollers leave no room for the cage bars: Z (D + C_p) = "
            f"{_derived(z * (d + cp))} mm must be < pi d_m = {_derived(circ)} mm"
        )
    return None


def _odd_slices(v) -> str | None:
    """MODEL.md 4.2: an odd slice count puts a slice at the roller centre (symmetric slicing)."""
    n = v["bearing.num_slices"]
    return None if n % 2 == 1 else f"{n} is even: the slice count must be odd (a slice at the roller centre)"


def _traction_extreme(a: float, b: float, c: float, d: float) -> tuple[float, float]:
    """(max |kappa|, where) of kappa(du) = (A + B du) exp(-C du) + D over du >= 0 (C > 0).

    The extremes are at du = 0 (A + D), du -> inf (D) and at the stationary point
    du* = 1/C - A/B, where kappa = (B/C) exp(C A/B - 1) + D.
    """
    cands = [(abs(a + d), 0.0), (abs(d), math.inf)]
    if b != 0.0:
        try:
            du = 1.0 / c - a / b
            if du > 0.0:
                cands.append((abs((b / c) * math.exp(c * a / b - 1.0) + d), du))
        except (OverflowError, ZeroDivisionError):
            cands.append((math.inf, math.inf))
    cands = [(math.inf if math.isnan(k) else k, at) for k, at in cands]
    return max(cands, key=lambda t: t[0])


def _traction_bounded(v) -> str | None:
    a, b = v["lubricant.traction_a"], v["lubricant.traction_b_s_m"]
    c, d = v["lubricant.traction_c_s_m"], v["lubricant.traction_d"]
    peak, at = _traction_extreme(a, b, c, d)
    if peak <= 1.0:
        return None
    return (
        f"the traction curve kappa = (A + B du) exp(-C du) + D reaches |kappa| = "
        f"{_derived(peak)} at du = {_derived(at)} m/s; it must stay within [-1, 1] "
        f"(A = {format_value(a)}, B = {format_value(b)} s/m, C = {format_value(c)} s/m, "
        f"D = {format_value(d)})"
    )


# -- the schema --------------------------------------------------------------------------------
_DM, _PD = "bearing.pitch_diameter_mm", "bearing.radial_clearance_um"
_D, _L, _RC = "roller.diameter_mm", "roller.length_mm", "roller.corner_radius_mm"
_H, _HREL = "flange.height_mm", "flange.relief_height_mm"
_CP, _CG = "cage.pocket_clearance_mm", "cage.guiding_clearance_mm"


def _material(part: str, attr: str, e: float, nu: float, rho: float, what: str) -> list[Key]:
    s = f"materials.{part}"
    return [
        _k(
            f"{s}.elastic_modulus_GPa",
            float,
            e,
            "GPa",
            "E",
            f"elastic modulus of the {what}",
            _const(0, False),
            _const(1500, True),
            attr=f"{attr}.elastic_modulus",
        ),
        _k(
            f"{s}.poisson_ratio",
            float,
            nu,
            "",
            "nu",
            f"Poisson ratio of the {what}",
            _const(-1, False),
            _const(0.5, False),
            attr=f"{attr}.poisson_ratio",
        ),
        _k(
            f"{s}.density_kg_m3",
            float,
            rho,
            "kg/m^3",
            "rho",
            f"density of the {what}",
            _const(0, False),
            _const(25000, True),
            attr=f"{attr}.density",
        ),
    ]


KEYS: tuple[Key, ...] = (
    # [bearing]
    _k(
        _DM,
        float,
        85.0,
        "mm",
        "d_m",
        "pitch diameter",
        _const(0, False),
        _const(10000, True),
        attr="pitch_diameter",
    ),
    _k(
        _PD,
        float,
        20.0,
        "um",
        "P_d",
        "radial clearance (diametral, split between the rings)",
        _const(0, True),
        _rel("pitch_diameter_mm*10", (_DM,), lambda dm: dm * 10, True),
        attr="radial_clearance",
        note="at most 1 % of the pitch diameter",
    ),
    _k(
        "bearing.num_rollers",
        int,
        26,
        "",
        "Z",
        "number of rollers",
        _const(3, True),
        attr="num_rollers",
        extras=(
            Extra(
                (_DM, _D, _CP),
                _rollers_fit,
                "rollers and cage bars fit around the pitch circle: Z (D + C_p) < pi d_m",
            ),
        ),
    ),
    _k(
        "bearing.num_slices",
        int,
        31,
        "",
        "N_s",
        "raceway slices per roller (odd)",
        _const(3, True),
        _const(200, True),
        attr="num_slices",
        note="odd, so that a slice sits at the roller centre",
        extras=(Extra(("bearing.num_slices",), _odd_slices, "the slice count is odd"),),
    ),
    _k(
        "bearing.inner_ring_mass_kg",
        float,
        0.5,
        "kg",
        "m_i",
        "effective mass of inner ring and shaft",
        _const(0, False),
        _const(1e5, True),
        attr="inner_ring_mass",
    ),
    _k(
        "bearing.flange_traction",
        float,
        0.08,
        "",
        "mu_f",
        "roller-flange traction coefficient",
        _const(0, True),
        _const(1, True),
        attr="flange_traction",
    ),
    _k(
        "bearing.pocket_friction",
        float,
        0.10,
        "",
        "mu_p",
        "roller-pocket friction coefficient",
        _const(0, True),
        _const(1, True),
        attr="pocket_friction",
    ),
    # [roller]
    _k(
        _D,
        float,
        7.5,
        "mm",
        "D",
        "roller diameter",
        _const(0, False),
        _rel("pitch_diameter_mm/2", (_DM,), lambda dm: dm / 2, False),
        attr="roller.diameter",
    ),
    _k(
        _L,
        float,
        8.0,
        "mm",
        "L_b1",
        "overall roller length (flat-end roller)",
        _rel("2 corner_radius_mm", (_RC,), lambda rc: 2 * rc, False),
        _rel("10 diameter_mm", (_D,), lambda d: 10 * d, True),
        attr="roller.length",
    ),
    _k(
        "roller.central_length_mm",
        float,
        4.5,
        "mm",
        "L_b2",
        "straight central length of the generatrix (crowned outside it)",
        _const(0, True),
        _rel("length_mm - 2 corner_radius_mm", (_L, _RC), lambda lb, rc: lb - 2 * rc, True),
        attr="roller.central_length",
    ),
    _k(
        "roller.crown_drop_um",
        float,
        4.0,
        "um",
        "c_crown",
        "crown drop at the ends of the effective length",
        _const(0, True),
        _rel("diameter_mm/10", (_D,), lambda d: d * 100, True),
        attr="roller.crown_drop",
    ),
    _k(
        _RC,
        float,
        0.4,
        "mm",
        "R_cor",
        "corner radius",
        _const(0, False),
        _rel("diameter_mm/2", (_D,), lambda d: d / 2, False),
        attr="roller.corner_radius",
    ),
    # the sphere meets the corner torus tangentially only if R_end - R_cor > R_ce, i.e.
    # R_end > D/2 (paper Eq. 19: L_beb = x_cor - sqrt((R_end - R_cor)^2 - R_ce^2)); then the
    # limited circle rho_lim = R_ce R_end/(R_end - R_cor) < D/2 and the end is convex.
    _k(
        "roller.end_radius_mm",
        float,
        80.0,
        "mm",
        "R_end",
        "end (arc) radius",
        _rel("diameter_mm/2", (_D,), lambda d: d / 2, False),
        None,
        attr="roller.end_radius",
        allow_inf=True,
        note="inf = flat end with corner radii only",
    ),
    # [flange]
    _k(
        _H,
        float,
        2.0,
        "mm",
        "H_rf",
        "flange height above the raceway",
        _const(0, False),
        _rel("diameter_mm", (_D,), lambda d: d, False),
        attr="flange.height",
    ),
    _k(
        _HREL,
        float,
        0.3,
        "mm",
        "h_rel",
        "flange base relief (undercut) height",
        _const(0, True),
        _rel("height_mm", (_H,), lambda h: h, False),
        attr="flange.relief_height",
    ),
    _k(
        "flange.contact_height_limit_mm",
        float,
        1.8,
        "mm",
        "h_up",
        "upper limit of the contact height on the flange",
        _rel("relief_height_mm", (_HREL,), lambda h: h, False),
        _rel("height_mm", (_H,), lambda h: h, True),
        attr="flange.contact_height_limit",
    ),
    _k(
        "flange.layback_angle_deg",
        float,
        1.6,
        "deg",
        "theta_f",
        "flange layback (opening) angle",
        _const(0, False),
        _const(10, True),
        attr="flange.layback_angle",
    ),
    _k(
        "flange.axial_clearance_mm",
        float,
        0.15,
        "mm",
        "Delta_bf",
        "axial clearance (flange spacing minus length_mm)",
        _const(0, True),
        _rel("length_mm", (_L,), lambda lb: lb, False),
        attr="flange.axial_clearance",
    ),
    # [cage]
    _k(
        "cage.inner_diameter_mm",
        float,
        80.0,
        "mm",
        "",
        "cage bore",
        _rel("inner raceway diameter", (_DM, _D, _PD), lambda dm, d, pd: dm - d - pd / 2000, False),
        _rel("pitch_diameter_mm", (_DM,), lambda dm: dm, False),
        attr="cage.inner_diameter",
        note="inner raceway diameter = pitch_diameter_mm - diameter_mm - radial_clearance_um/2000",
    ),
    _k(
        "cage.outer_diameter_mm",
        float,
        90.0,
        "mm",
        "",
        "cage outside diameter (guided on the outer-ring lands)",
        _rel("pitch_diameter_mm", (_DM,), lambda dm: dm, False),
        _rel(
            "outer raceway diameter - guiding_clearance_mm",
            (_DM, _D, _PD, _CG),
            lambda dm, d, pd, cg: dm + d + pd / 2000 - cg,
            True,
        ),
        attr="cage.outer_diameter",
        note="outer raceway diameter = pitch_diameter_mm + diameter_mm + radial_clearance_um/2000",
    ),
    _k(
        "cage.width_mm",
        float,
        14.0,
        "mm",
        "",
        "cage width",
        _rel("length_mm + pocket_clearance_mm", (_L, _CP), lambda lb, cp: lb + cp, False),
        _rel("3 length_mm", (_L,), lambda lb: 3 * lb, True),
        attr="cage.width",
    ),
    _k(
        _CP,
        float,
        0.20,
        "mm",
        "C_p",
        "pocket clearance (circumferential, total)",
        _const(0, False),
        _rel("diameter_mm/2", (_D,), lambda d: d / 2, False),
        attr="cage.pocket_clearance",
    ),
    _k(
        _CG,
        float,
        0.40,
        "mm",
        "C_g",
        "guiding clearance on the outer-ring lands (diametral)",
        _const(0, False),
        _rel("diameter_mm/2", (_D,), lambda d: d / 2, False),
        attr="cage.guiding_clearance",
    ),
    _k(
        "cage.land_width_mm",
        float,
        3.0,
        "mm",
        "b_l",
        "guiding land width (each of two)",
        _const(0, False),
        _rel("width_mm/2", ("cage.width_mm",), lambda w: w / 2, True),
        attr="cage.land_width",
    ),
    # [materials.*]
    *_material("ring", "ring_material", 203.0, 0.28, 7830.0, "rings (AISI M50)"),
    *_material("roller", "roller_material", 203.0, 0.28, 7830.0, "rollers (AISI M50)"),
    *_material("cage", "cage_material", 205.0, 0.29, 7850.0, "cage (AISI 4340)"),
    # [lubricant]
    _k(
        "lubricant.viscosity_Pa_s",
        float,
        0.055,
        "Pa s",
        "eta_0",
        "dynamic viscosity at the operating temperature",
        _const(0, False),
        _const(100, True),
        attr="lubricant.viscosity",
    ),
    _k(
        "lubricant.pressure_viscosity_1_Pa",
        float,
        1.85e-8,
        "1/Pa",
        "alpha_p",
        "pressure-viscosity coefficient",
        _const(0, True),
        _const(1e-6, True),
        attr="lubricant.pressure_viscosity",
    ),
    _k(
        "lubricant.temperature_viscosity_1_C",
        float,
        0.0315,
        "1/C",
        "beta_T",
        "temperature-viscosity coefficient",
        _const(0, True),
        _const(1, True),
        attr="lubricant.temperature_viscosity",
    ),
    _k(
        "lubricant.density_kg_m3",
        float,
        960.0,
        "kg/m^3",
        "rho_oil",
        "lubricant density",
        _const(0, False),
        _const(2000, True),
        attr="lubricant.density",
    ),
    _k(
        "lubricant.oil_fraction",
        float,
        0.05,
        "",
        "f_oil",
        "oil volume fraction in the cavity",
        _const(0, True),
        _const(1, True),
        attr="lubricant.oil_fraction",
    ),
    _k(
        "lubricant.traction_a",
        float,
        -0.04,
        "",
        "A",
        "traction curve constant",
        _const(-1, True),
        _const(1, True),
        attr="lubricant.traction_a",
        note="rolling-contact traction kappa(du) = (A + B du) exp(-C du) + D, du = sliding speed",
    ),
    _k(
        "lubricant.traction_b_s_m",
        float,
        0.2528,
        "s/m",
        "B",
        "traction curve slope",
        _const(-1e4, True),
        _const(1e4, True),
        attr="lubricant.traction_b",
        extras=(
            Extra(
                ("lubricant.traction_a", "lubricant.traction_c_s_m", "lubricant.traction_d"),
                _traction_bounded,
                "|kappa(du)| <= 1 for all du >= 0",
            ),
        ),
    ),
    _k(
        "lubricant.traction_c_s_m",
        float,
        2.926,
        "s/m",
        "C",
        "traction curve decay",
        _const(0, False),
        _const(1e4, True),
        attr="lubricant.traction_c",
    ),
    _k(
        "lubricant.traction_d",
        float,
        0.04,
        "",
        "D",
        "traction at high sliding speed",
        _const(-1, True),
        _const(1, True),
        attr="lubricant.traction_d",
    ),
    # [operating]
    _k(
        "operating.speed_rpm",
        float,
        20000.0,
        "rpm",
        "n_i",
        "inner ring speed (outer ring fixed)",
        _const(0, True),
        _const(100000, True),
        attr="op.inner_speed",
    ),
    _k(
        "operating.radial_load_N",
        float,
        1000.0,
        "N",
        "F_r",
        "radial load on the inner ring (+Z)",
        _const(0, True),
        _const(1e8, True),
        attr="op.radial_load",
    ),
    _k(
        "operating.gravity",
        bool,
        True,
        "",
        "g",
        "gravity on every body (9.81 m/s^2 along +Z)",
        attr="op.gravity",
    ),
    # [simulation]
    _k(
        "simulation.end",
        str,
        "both",
        "",
        "",
        "roller ends to simulate",
        choices=("arc", "corner", "both"),
        note="the arc run needs a finite end_radius_mm",
    ),
    _k(
        "simulation.duration_ms",
        float,
        20.0,
        "ms",
        "",
        "simulated time",
        _const(0, False),
        _const(10000, True),
    ),
    _k(
        "simulation.rtol",
        float,
        1e-3,
        "",
        "",
        "relative tolerance of the step-size controller",
        _const(0, False),
        _const(1, False),
    ),
    _k(
        "simulation.atol",
        float,
        1e-6,
        "",
        "",
        "absolute tolerance (on the scaled state)",
        _const(0, False),
        _const(1, False),
    ),
    _k(
        "simulation.max_steps",
        int,
        2_000_000,
        "",
        "",
        "maximum number of integrator steps",
        _const(1, True),
        _const(1_000_000_000, True),
    ),
    _k("simulation.progress", bool, True, "", "", "show a progress meter"),
)

KEY_BY_PATH: dict[str, Key] = {k.path: k for k in KEYS}

#: the reference configuration in engineering units; converts exactly to reference_bearing() and
#: reference_operating_point().
REFERENCE_VALUES: dict[str, Any] = {k.path: k.default for k in KEYS}


def _check_order() -> tuple[str, ...]:
    """Keys in schema order, each moved after the keys its range and extra checks depend on."""
    order: list[str] = []
    seen: set[str] = set()

    def visit(path: str) -> None:
        if path in seen:
            return
        seen.add(path)
        for dep in KEY_BY_PATH[path].deps:
            visit(dep)
        order.append(path)

    for k in KEYS:
        visit(k.path)
    return tuple(order)


CHECK_ORDER = _check_order()


# -- types -------------------------------------------------------------------------------------
def coerce(key: Key, value: Any) -> Any:
    """The value as the key's Python type (int -> float for float keys), or ConfigError.

    Booleans are never numbers and floats are never counts, even when integral (26.0).
    """
    if hasattr(value, "__array__") and not isinstance(value, (numbers.Number, str)):
        arr = np.asarray(value)
        if arr.ndim == 0 and arr.dtype.kind in "biuf":
            value = arr.item()
    unit = f" ({key.unit})" if key.unit else ""
    got = (
        f"got {type_name(value)} {format_value(value)}"
        if isinstance(value, (numbers.Number, str, np.bool_))
        else f"got {type_name(value)}"
    )
    is_bool = isinstance(value, (bool, np.bool_))
    if key.kind is float:
        if is_bool or not isinstance(value, numbers.Real):
            raise ConfigError(key.path, f"expected a number{unit}, {got}")
        try:
            return float(value)
        except OverflowError:
            raise ConfigError(
                key.path,
                f"{type_name(value)} too large for a float{unit}; must be "
                f"{key.range_text()}{(' ' + key.unit) if key.unit else ''}",
            ) from None
    if key.kind is int:
        if is_bool or not isinstance(value, numbers.Real):
            raise ConfigError(key.path, f"expected an integer, {got}")
        if not isinstance(value, numbers.Integral):
            raise ConfigError(
                key.path, f"expected an integer (a count, written without a decimal point), {got}"
            )
        return int(value)
    if key.kind is bool:
        if not is_bool:
            raise ConfigError(key.path, f"expected true or false, {got}")
        return bool(value)
    if not isinstance(value, str):
        raise ConfigError(key.path, f"expected a string ({key.range_text()}), {got}")
    return value


# -- ranges ------------------------------------------------------------------------------------
def check_key(key: Key, values: Mapping[str, Any]) -> None:
    """Range and extra checks of one key; `values` holds it and the keys it depends on."""
    v = values[key.path]
    unit = f" {key.unit}" if key.unit else ""
    if key.choices:
        if v not in key.choices:
            raise ConfigError(key.path, f"{format_value(v)} is not {key.range_text()}")
    elif key.kind in (float, int):
        if key.kind is float and not math.isfinite(v) and not (key.allow_inf and v == math.inf):
            raise ConfigError(
                key.path, f"{format_value(v)}{unit} is not finite: must be {key.range_text(values)}{unit}"
            )
        ok = True
        if key.lo is not None:
            lo = key.lo.value(values)
            ok &= v >= lo if key.lo.closed else v > lo
        if key.hi is not None:
            hi = key.hi.value(values)
            ok &= v <= hi if key.hi.closed else v < hi
        if not ok:
            raise ConfigError(
                key.path, f"{format_value(v)}{unit} is out of range: must be {key.range_text(values)}{unit}"
            )
    for extra in key.extras:
        msg = extra.check(values)
        if msg is not None:
            raise ConfigError(key.path, msg)


def check_values(values: Mapping[str, Any], paths: Iterable[str] | None = None) -> None:
    """Check the keys `paths` (all by default) of a complete, typed value mapping, in
    dependency order; raise ConfigError on the first violation."""
    wanted = set(CHECK_ORDER if paths is None else paths)
    for path in CHECK_ORDER:
        if path in wanted:
            check_key(KEY_BY_PATH[path], values)


# -- pytrees built in Python -------------------------------------------------------------------
def _leaf(bearing, op, attr: str):
    obj = op if attr.startswith("op.") else bearing
    for part in attr.removeprefix("op.").split("."):
        obj = getattr(obj, part)
    return obj


def _traced(x) -> bool:
    import jax

    return any(isinstance(v, jax.core.Tracer) for v in jax.tree_util.tree_leaves(x))


def validate_bearing(bearing, op=None, *, traced: str = "error") -> None:
    """Validate a `Bearing` (and optionally an `OperatingPoint`) built directly in Python.

    Values are converted to configuration units so that a failure reads like a configuration
    error, naming the configuration key (e.g. ``roller.end_radius_mm: 3.0 mm is out of range:
    must be in (diameter_mm/2 = 3.75, inf] mm``). Stacked (batched) pytrees are checked element
    by element. Gravity, a bool in configuration files, must here be finite and in [0, 100]
    m/s^2.

    Leaves must be concrete: under `jax.jit`/`grad`/`vmap` they are tracers, which raise
    TypeError (`traced="error"`, the default) or, with `traced="skip"` (what the model's entry
    points use), leave out every check that reads a traced leaf and check the rest.

    Raises ConfigError on the first violation; returns None.
    """
    if traced not in ("error", "skip"):
        raise ValueError(f"traced = {traced!r}: must be 'error' or 'skip'")
    keys = [k for k in KEYS if k.attr is not None and (op is not None or not k.attr.startswith("op."))]
    leaves = {k.path: _leaf(bearing, op, k.attr) for k in keys}
    skipped = {p for p, v in leaves.items() if _traced(v)}
    if skipped and traced == "error":
        raise TypeError("validate_bearing needs concrete values: call it outside jax.jit/grad/vmap")
    # a key is checked when neither it nor a key its range reads is traced
    keys = [k for k in keys if k.path not in skipped]
    checked = [k.path for k in keys if not set(k.deps) & skipped]
    arrays = {k.path: np.asarray(leaves[k.path]) for k in keys if k.kind is not int}
    shape = np.broadcast_shapes(*(a.shape for a in arrays.values())) if arrays else ()
    if op is not None and not _traced(op.gravity):
        _check_gravity(np.broadcast_to(np.asarray(op.gravity, dtype=float), shape), shape)
    for idx in np.ndindex(shape):
        values = dict(REFERENCE_VALUES)
        for k in keys:
            if k.kind is int:
                values[k.path] = coerce(k, leaves[k.path])
            elif k.kind is bool:  # gravity
                values[k.path] = bool(np.broadcast_to(arrays[k.path], shape)[idx] > 0)
            else:
                values[k.path] = k.from_si(float(np.broadcast_to(arrays[k.path], shape)[idx]))
        try:
            check_values(values, checked)
        except ConfigError as exc:
            if not shape:
                raise
            msg = str(exc).removeprefix(f"{exc.field}: ")
            raise ConfigError(exc.field, f"(batch element {idx}) {msg}") from None


def _check_gravity(g: np.ndarray, shape: tuple) -> None:
    bad = ~(np.isfinite(g) & (g >= 0) & (g <= 100))
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f"(batch element {idx}) " if shape else ""
        raise ConfigError(
            "operating.gravity",
            f"{where}{format_value(float(g[idx]))} m/s^2 is "
            "out of range: must be in [0, 100] m/s^2 (9.81 = on, 0 = off)",
        )
