"""A complete configuration of a catalogue cylindrical roller bearing estimated from its boundary
dimensions (`jaxbearing config new`).

A catalogue gives the bore d, the outside diameter D_o, the width B, the type (NU, N, NJ, NUP)
and sometimes the roller set (number Z, diameter D, length L). Every other key is estimated by
a stated rule, and every estimated key is entered in the configuration's `[uncertainty]` table
with the rule and an uncertainty (+/- in the key's unit), so that `config show` marks it and a
sensitivity study can read how well it is known:

- published rules: the pitch diameter d_m ~ (d + D_o)/2 (the rolling elements' centres midway
  through the ring section; Harris & Kotzalas, Essential Concepts of Bearing Technology, 5th ed.,
  ch. 2; the usual default of bearing programs, e.g. the MESYS manual); the roller diameter
  D ~ 0.25 (D_o - d) (approximate: catalogue cylindrical roller bearings of the 02 and 03
  series lie near it, Harris & Kotzalas ch. 2; against the raceway diameters of SKF's catalogue,
  (E - F)/2 = 11, 14, 19 mm for the 210, 212, 312 ECP sizes, it is 8-11 % low, within its
  stated +/- 15 %); the roller length from the ring width,
  L ~ 0.6 B (the width less two ribs of about 0.2 B; L ~ D for the 02 and 03 series, longer
  for the 22 series); the roller count from the pitch circle and the cage bars,
  Z = floor(pi d_m / (D (1 + g))), with the reference bearing's bar width g = 0.37 D;
- the inner geometry is scaled from the reference bearing (docs/model.md section 1) where no
  published rule exists: the roller-end and flange lengths (corner radius, end radius, flange
  height, relief height, contact-height limit, axial clearance, crown drop) in proportion to
  the roller diameter, which keeps the roller-end/flange contact geometrically similar (same
  layback angle, same contact height relative to the flange); the straight central length in
  proportion to the roller length; the cage diameters and clearances in proportion to the
  roller diameter about the pitch circle; the radial clearance in proportion to d_m;
- materials: through-hardened bearing steel (AISI 52100 / 100Cr6) for rings and rollers; the
  reference's steel cage, lubricant, traction curve and friction coefficients (representative
  values, marked as such);
- operating point: placeholders the user must set (speed n d_m = 0.5e6 mm rpm, a light radial
  load scaled from the reference's 1000 N by D L), marked in the file.

Inputs out of range raise `ConfigError` whose field is the parameter name (`bore_mm`, ...),
one line naming the value and the valid range.
"""

from __future__ import annotations

import csv
import dataclasses
import importlib.resources
import math
from collections.abc import Mapping
from typing import Any, NamedTuple

from .._errors import ConfigError
from ..geometry import BEARING_STEEL_CONDUCTIVITY, BEARING_STEEL_SPECIFIC_HEAT
from ._config import Config
from ._keys import format_derived, format_value
from ._schema import KEY_BY_PATH, REFERENCE_VALUES
from ._uncertainty import SECTION, Uncertainty

#: the dimension series of the ISO 15 table shipped with the package
DIMENSION_SERIES = ("10", "02", "22", "03")
#: the bearing types `config new` writes (`bearing.type`)
BEARING_TYPES = ("NU", "N", "NJ", "NUP")

_DATA = "iso15_dimension_series.csv"
_REF = REFERENCE_VALUES
_HK = "Harris & Kotzalas, Essential Concepts of Bearing Technology, 5th ed., ch. 2"
_SCALED = "scaled from the reference bearing"

#: the reference bearing's roller fill of the pitch circle, Z D / (pi d_m)
REFERENCE_FILL = (
    _REF["bearing.num_rollers"] * _REF["roller.diameter_mm"] / (math.pi * _REF["bearing.pitch_diameter_mm"])
)
#: roller diameter over the ring section, D / (D_o - d) (approximate, Harris & Kotzalas ch. 2)
ROLLER_DIAMETER_RATIO = 0.25
#: roller length over the ring width, L / B
ROLLER_LENGTH_RATIO = 0.6
#: the placeholder speed's n d_m [mm rpm] (a moderate speed for an oil-lubricated bearing)
PLACEHOLDER_N_DM = 0.5e6


class BoundaryDimensions(NamedTuple):
    """The boundary dimensions of a radial bearing [mm] and, if read from the ISO 15 table,
    its dimension series ("" otherwise): bore d, outside diameter D_o, width B."""

    bore_mm: float
    outside_diameter_mm: float
    width_mm: float
    series: str = ""


@dataclasses.dataclass(frozen=True)
class EstimatedConfig:
    """A configuration estimated from boundary dimensions (`estimate_config`).

    `config`: the configuration, its `[uncertainty]` table holding every estimated key's rule
    and uncertainty; `dimensions`: the boundary dimensions it was made from; `bearing_type`;
    `placeholders`: {operating key: what to set} for the operating point the user must set.
    """

    config: Config
    dimensions: BoundaryDimensions
    bearing_type: str
    placeholders: Mapping[str, str]

    def to_toml(self) -> str:
        """The commented TOML file: a header naming the bearing, every key with its comment,
        "ESTIMATED (+/- ...): rule" above every estimated key, "PLACEHOLDER: ..." above every
        operating key to set, and the `[uncertainty]` table."""
        dim = self.dimensions
        series = f" (ISO 15 dimension series {dim.series})" if dim.series else ""
        header = (
            f"# jaxbearing configuration of an {self.bearing_type} cylindrical roller bearing, "
            f"d x D x B = {format_value(dim.bore_mm)} x {format_value(dim.outside_diameter_mm)} x "
            f"{format_value(dim.width_mm)} mm{series},\n"
            "# written by `jaxbearing config new`. Engineering units: the unit is part of every "
            "key's name.\n"
            "# Keys marked ESTIMATED were estimated from the boundary dimensions by the rule "
            "stated (+/- their\n"
            "# uncertainty; the [uncertainty] table at the end holds the same, for programs). "
            "Replace any value\n"
            "# you know and delete its [uncertainty] entry. Keys marked PLACEHOLDER are an "
            "operating point\n"
            "# you must set. Check the file with `jaxbearing config check FILE`.\n"
        )
        return self.config.to_toml(header=header, notes=self.placeholders)


# -- the ISO 15 table ----------------------------------------------------------------------------
def _table() -> dict[str, dict[float, tuple[float, float]]]:
    """{series: {bore: (outside diameter, width)}} [mm] of the packaged ISO 15 table."""
    text = importlib.resources.files(__package__).joinpath(_DATA).read_text(encoding="utf-8")
    rows = csv.DictReader(line for line in text.splitlines() if not line.startswith("#"))
    out: dict[str, dict[float, tuple[float, float]]] = {s: {} for s in DIMENSION_SERIES}
    for row in rows:
        out[row["series"]][float(row["bore_mm"])] = (
            float(row["outside_diameter_mm"]),
            float(row["width_mm"]),
        )
    return out


def dimension_series(series: str, bore_mm: float) -> BoundaryDimensions:
    """The ISO 15 boundary dimensions of dimension series `series` ("10", "02", "22" or "03")
    with bore `bore_mm`, from the table shipped with the package (bores 20 to 200 mm; every
    row checked against the Schaeffler and SKF catalogue tables its header names). Raises
    ConfigError (field "series" or "bore_mm") naming the valid series or bores."""
    table = _table()
    if series not in table:
        raise ConfigError(
            "series", f"{series!r} is not a dimension series of the table; valid: {', '.join(table)}"
        )
    rows = table[series]
    if bore_mm not in rows:
        bores = ", ".join(format_value(b) for b in rows)
        raise ConfigError(
            "bore_mm",
            f"{format_value(bore_mm)} mm is not a bore of dimension series {series}; valid: {bores} mm",
        )
    outside, width = rows[bore_mm]
    return BoundaryDimensions(float(bore_mm), outside, width, series)


# -- input checks ----------------------------------------------------------------------------------
def _require(
    name: str, value: float, lo: float, hi: float, lo_label: str, hi_label: str, unit: str = " mm"
) -> None:
    """ConfigError(name) unless lo < value < hi (open at both ends), naming the range."""
    if not (isinstance(value, (int, float)) and math.isfinite(value) and lo < value < hi):
        raise ConfigError(
            name, f"{format_value(value)}{unit} is out of range: must be in ({lo_label}, {hi_label}){unit}"
        )


def _check_dimensions(dim: BoundaryDimensions) -> None:
    d, do, b = dim.bore_mm, dim.outside_diameter_mm, dim.width_mm
    _require("bore_mm", d, 0.0, 10000.0, "0", "10000")
    _require("outside_diameter_mm", do, d, 20000.0 - d, f"bore = {format_value(d)}", "20000 - bore")
    _require(
        "width_mm",
        b,
        0.0,
        10.0 * (do - d),
        "0",
        f"10 (outside diameter - bore) = {format_derived(10 * (do - d))}",
    )


# -- the rules ---------------------------------------------------------------------------------------
def _est(value: float, plus_minus: float, rule: str) -> tuple[float, Uncertainty]:
    return value, Uncertainty(plus_minus, rule)


def _ratio(key: str, base: str) -> float:
    """The reference bearing's `key` over its `base` (units as in the keys' names)."""
    return _REF[key] / _REF[base]


def _roller_set(
    dim: BoundaryDimensions, num_rollers: int | None, diameter: float | None, length: float | None
) -> dict[str, tuple[Any, Uncertainty | None]]:
    """Pitch diameter, roller diameter, length and count: given ones checked, the others estimated."""
    d, do, b = dim.bore_mm, dim.outside_diameter_mm, dim.width_mm
    dm = 0.5 * (d + do)
    out: dict[str, tuple[Any, Uncertainty | None]] = {
        "bearing.pitch_diameter_mm": _est(
            dm, 0.02 * dm, f"d_m ~ (d + D_o)/2 = (bore + outside diameter)/2 ({_HK}); +/- 2 %"
        )
    }
    section = 0.5 * (do - d)
    if diameter is None:
        diameter = ROLLER_DIAMETER_RATIO * (do - d)
        out["roller.diameter_mm"] = _est(
            diameter,
            0.15 * diameter,
            f"D ~ {ROLLER_DIAMETER_RATIO} (D_o - d), approximate ({_HK}); +/- 15 %",
        )
    else:
        _require(
            "roller_diameter_mm",
            diameter,
            0.0,
            section,
            "0",
            f"(outside diameter - bore)/2 = {format_derived(section)}, the ring section",
        )
        out["roller.diameter_mm"] = (float(diameter), None)
    corner = _ratio("roller.corner_radius_mm", "roller.diameter_mm") * diameter
    if length is None:
        length = min(ROLLER_LENGTH_RATIO * b, 10.0 * diameter)
        out["roller.length_mm"] = _est(
            length,
            0.1 * length,
            f"L ~ {ROLLER_LENGTH_RATIO} B, the ring width less two ribs of about 0.2 B "
            "(L ~ D for the 02 and 03 series); +/- 10 %",
        )
    else:
        hi = min(b, 10.0 * diameter)
        hi_label = f"width = {format_value(b)}" if hi == b else f"10 roller diameters = {format_derived(hi)}"
        _require(
            "roller_length_mm",
            length,
            2.0 * corner,
            hi,
            f"2 corner radii = {format_derived(2 * corner)}",
            hi_label,
        )
        out["roller.length_mm"] = (float(length), None)
    pocket = _ratio("cage.pocket_clearance_mm", "roller.diameter_mm") * diameter
    z_max = math.ceil(math.pi * dm / (diameter + pocket)) - 1
    if num_rollers is None:
        z = max(3, math.floor(REFERENCE_FILL * math.pi * dm / diameter))
        gap = 1.0 / REFERENCE_FILL - 1.0
        out["bearing.num_rollers"] = _est(
            min(z, z_max),
            1,
            f"Z = floor(pi d_m / (D (1 + g))), cage bars g = {gap:.2f} D wide at the pitch circle, "
            f"{_SCALED} (Z D = {REFERENCE_FILL:.2f} pi d_m); +/- 1 roller",
        )
    else:
        if isinstance(num_rollers, bool) or not isinstance(num_rollers, int) or not 3 <= num_rollers <= z_max:
            raise ConfigError(
                "num_rollers",
                f"{format_value(num_rollers)} is out of range: must be an integer in [3, {max(z_max, 3)}] "
                f"(Z (D + C_p) < pi d_m: {format_derived(diameter)} mm rollers with "
                f"{format_derived(pocket)} mm pocket clearance on a {format_derived(dm)} mm pitch circle)",
            )
        out["bearing.num_rollers"] = (num_rollers, None)
    return out


def _scaled(key: str, base: str, base_value: float, rel: float, what: str = "") -> tuple[float, Uncertainty]:
    """`key` = the reference's key/base ratio times `base_value`, +/- `rel` of the value."""
    value = _ratio(key, base) * base_value
    unit = KEY_BY_PATH[key].unit
    base_name = base.rpartition(".")[2].removesuffix("_mm")
    ratio = _ratio(key, base)
    per = f"{ratio:.4g} {unit}/mm" if unit != "mm" else f"{ratio:.4g}"
    return _est(
        value,
        rel * value,
        f"{_SCALED}: {per} x {base_name.replace('_', ' ')}{what}; +/- {round(rel * 100)} %",
    )


def _representative(key: str, plus_minus: float, what: str = "") -> tuple[Any, Uncertainty]:
    return _est(_REF[key], plus_minus, f"the reference bearing's representative value{what}")


#: density of through-hardened bearing steel [kg/m^3] (the inner ring's mass, the materials)
_STEEL_DENSITY = 7830.0


def _estimates(
    dim: BoundaryDimensions, num_rollers: int | None, diameter: float | None, length: float | None
) -> dict[str, tuple[Any, Uncertainty | None]]:
    """{key: (value, its Uncertainty, or None for a value the user gave)} of every key that
    differs from its reference value or is estimated: the roller set, then the ring, the roller
    and flange, the cage, and the materials and lubricant."""
    out = _roller_set(dim, num_rollers, diameter, length)
    dm = out["bearing.pitch_diameter_mm"][0]
    dr = out["roller.diameter_mm"][0]
    lr = out["roller.length_mm"][0]
    out.update(_ring_estimates(dm, dr, dim.width_mm))
    out.update(_roller_flange_estimates(dr, lr))
    out.update(_cage_estimates(dm, dr, lr, dim.width_mm))
    out.update(_material_lubricant_estimates())
    return out


def _ring_estimates(dm: float, dr: float, b: float) -> dict:
    """The clearance, the inner ring's mass and the tractions of a bearing of pitch diameter
    `dm`, roller diameter `dr` and width `b` [mm] (`_estimates`)."""
    out = {}
    clearance = _REF["bearing.radial_clearance_um"] * dm / _REF["bearing.pitch_diameter_mm"]
    out["bearing.radial_clearance_um"] = _est(
        clearance,
        0.5 * clearance,
        f"{_SCALED} in proportion to d_m (an operating clearance: the unmounted ISO 5753-1 "
        "groups are larger; set your mounted clearance); +/- 50 %",
    )
    inner_raceway = dm - dr
    mass = _STEEL_DENSITY * math.pi / 4 * inner_raceway**2 * b * 1e-9
    out["bearing.inner_ring_mass_kg"] = _est(
        mass,
        0.5 * mass,
        "the inner ring and the solid shaft under it over the width, rho pi d_i^2 B / 4 with "
        "d_i = d_m - D and rho = 7830 kg/m^3 (set the shaft's real share); +/- 50 %",
    )
    out["bearing.flange_traction"] = _representative("bearing.flange_traction", 0.02)
    out["bearing.pocket_friction"] = _representative("bearing.pocket_friction", 0.03)
    return out


def _roller_flange_estimates(dr: float, lr: float) -> dict:
    """The roller's profile and the flange of rollers of diameter `dr` and length `lr` [mm],
    scaled from the reference bearing (`_estimates`)."""
    out = {}
    roller = "roller.diameter_mm"
    corner = _ratio("roller.corner_radius_mm", roller) * dr
    out["roller.corner_radius_mm"] = _scaled("roller.corner_radius_mm", roller, dr, 0.3)
    central = min(_ratio("roller.central_length_mm", "roller.length_mm") * lr, lr - 2 * corner)
    out["roller.central_length_mm"] = _est(
        central,
        0.25 * central,
        f"{_SCALED}: {_ratio('roller.central_length_mm', 'roller.length_mm'):.4g} x length "
        "(at most length - 2 corner radii); +/- 25 %",
    )
    out["roller.crown_drop_um"] = _scaled("roller.crown_drop_um", roller, dr, 0.5)
    out["roller.end_radius_mm"] = _scaled("roller.end_radius_mm", roller, dr, 0.25)
    out["flange.height_mm"] = _scaled("flange.height_mm", roller, dr, 0.2)
    out["flange.relief_height_mm"] = _scaled("flange.relief_height_mm", roller, dr, 0.5)
    out["flange.contact_height_limit_mm"] = _scaled("flange.contact_height_limit_mm", roller, dr, 0.15)
    out["flange.layback_angle_deg"] = _representative("flange.layback_angle_deg", 0.5)
    out["flange.axial_clearance_mm"] = _scaled("flange.axial_clearance_mm", roller, dr, 0.5)
    out["flange.roughness_um"] = _representative("flange.roughness_um", 0.1, " (ground end and flange)")
    return out


def _cage_estimates(dm: float, dr: float, lr: float, b: float) -> dict:
    """The cage of a bearing of pitch diameter `dm`, roller diameter `dr`, roller length `lr`
    and width `b` [mm] (`_estimates`)."""
    out = {}
    roller = "roller.diameter_mm"
    # cage: diameters about the pitch circle, clearances in proportion to D, width between the
    # roller length and the ring width
    half_gap = (_REF["bearing.pitch_diameter_mm"] - _REF["cage.inner_diameter_mm"]) / _REF[roller]
    out["cage.inner_diameter_mm"] = _est(
        dm - half_gap * dr,
        0.1 * dr,
        f"{_SCALED}: d_m - {half_gap:.4g} D; +/- 0.1 D",
    )
    half_gap = (_REF["cage.outer_diameter_mm"] - _REF["bearing.pitch_diameter_mm"]) / _REF[roller]
    out["cage.outer_diameter_mm"] = _est(
        dm + half_gap * dr,
        0.1 * dr,
        f"{_SCALED}: d_m + {half_gap:.4g} D; +/- 0.1 D",
    )
    pocket = _ratio("cage.pocket_clearance_mm", roller) * dr
    out["cage.pocket_clearance_mm"] = _scaled("cage.pocket_clearance_mm", roller, dr, 0.5)
    out["cage.guiding_clearance_mm"] = _scaled("cage.guiding_clearance_mm", roller, dr, 0.5)
    width = min(max(0.5 * (lr + b), lr + 2 * pocket), 3 * lr)
    out["cage.width_mm"] = _est(
        width, 0.15 * width, "(L + B)/2, between the roller length and the ring width; +/- 15 %"
    )
    land = _ratio("cage.land_width_mm", "cage.width_mm") * width
    out["cage.land_width_mm"] = _est(
        land,
        0.3 * land,
        f"{_SCALED}: {_ratio('cage.land_width_mm', 'cage.width_mm'):.4g} x cage width; +/- 30 %",
    )
    return out


def _material_lubricant_estimates() -> dict:
    """The materials' and the lubricant's handbook or representative values (`_estimates`)."""
    out = {}
    steel = "through-hardened bearing steel (AISI 52100 / 100Cr6), handbook value"
    for part in ("ring", "roller"):
        s = f"materials.{part}"
        out[f"{s}.elastic_modulus_GPa"] = _est(208.0, 5.0, f"{steel} (201-210 GPa in handbooks)")
        out[f"{s}.poisson_ratio"] = _est(0.3, 0.01, steel)
        out[f"{s}.density_kg_m3"] = _est(_STEEL_DENSITY, 30.0, steel)
        # the flash temperature's constants (docs/model.md 5.5): MakeItFrom.com's 52100 values
        out[f"{s}.thermal_conductivity_W_mK"] = _est(BEARING_STEEL_CONDUCTIVITY, 4.7, f"{steel}; +/- 10 %")
        out[f"{s}.specific_heat_J_kgK"] = _est(BEARING_STEEL_SPECIFIC_HEAT, 23.5, f"{steel}; +/- 5 %")
    cage = " (steel; a catalogue cage may be brass, E ~ 100 GPa, rho ~ 8500 kg/m^3, or polyamide)"
    out["materials.cage.elastic_modulus_GPa"] = _representative(
        "materials.cage.elastic_modulus_GPa", 100.0, cage
    )
    out["materials.cage.poisson_ratio"] = _representative("materials.cage.poisson_ratio", 0.05, cage)
    out["materials.cage.density_kg_m3"] = _representative("materials.cage.density_kg_m3", 700.0, cage)
    for key, rel in (
        ("lubricant.viscosity_Pa_s", 0.3),
        ("lubricant.pressure_viscosity_1_Pa", 0.2),
        ("lubricant.temperature_viscosity_1_C", 0.2),
        ("lubricant.density_kg_m3", 0.05),
        ("lubricant.traction_a", 0.25),
        ("lubricant.traction_b_s_m", 0.25),
        ("lubricant.traction_c_s_m", 0.25),
        ("lubricant.traction_d", 0.25),
    ):
        out[key] = _representative(key, rel * abs(_REF[key]), f"; +/- {round(rel * 100)} %")
    out["lubricant.inlet_temperature_C"] = _representative(
        "lubricant.inlet_temperature_C", 10.0, " (set your oil inlet temperature)"
    )
    out["lubricant.oil_fraction"] = _representative("lubricant.oil_fraction", 0.03)
    return out


def _placeholders(dm: float, dr: float, lr: float) -> dict[str, tuple[float, str]]:
    """{operating key: (placeholder value, the note saying what to set)}."""
    speed = round(PLACEHOLDER_N_DM / dm, -1)
    scale = dr * lr / (_REF["roller.diameter_mm"] * _REF["roller.length_mm"])
    load = round(_REF["operating.radial_load_N"] * scale, -1)
    return {
        "operating.speed_rpm": (
            speed,
            f"PLACEHOLDER: set your speed (this one is n d_m = {PLACEHOLDER_N_DM:g} mm rpm)",
        ),
        "operating.radial_load_N": (
            load,
            "PLACEHOLDER: set your radial load (this one is a light load, the reference's 1000 N "
            "scaled by D L)",
        ),
    }


def estimate_config(
    bore_mm: float,
    outside_diameter_mm: float,
    width_mm: float,
    *,
    bearing_type: str = "NU",
    num_rollers: int | None = None,
    roller_diameter_mm: float | None = None,
    roller_length_mm: float | None = None,
    series: str = "",
) -> EstimatedConfig:
    """A complete configuration of a cylindrical roller bearing from its boundary dimensions
    (bore d, outside diameter D_o, width B [mm]), its type and what is known of the roller set
    (each of `num_rollers`, `roller_diameter_mm`, `roller_length_mm` is estimated when None).

    Every estimated key is in the result's `config.uncertainty` with its rule and uncertainty
    (the rules: this module's docstring); the operating point is a placeholder to set
    (`placeholders`). `series` only labels the file (`dimension_series` gives the dimensions of
    an ISO 15 series). Raises ConfigError naming the parameter, its value and the valid range:
    bore >= outside diameter, width <= 0, a roller diameter larger than the ring section, a
    roller longer than the width, or more rollers than fit around the pitch circle.
    """
    dim = BoundaryDimensions(bore_mm, outside_diameter_mm, width_mm, series)
    _check_dimensions(dim)
    if bearing_type not in BEARING_TYPES:
        raise ConfigError(
            "bearing_type", f"{bearing_type!r} is not a bearing type; valid: {', '.join(BEARING_TYPES)}"
        )
    estimates = _estimates(dim, num_rollers, roller_diameter_mm, roller_length_mm)
    dm = estimates["bearing.pitch_diameter_mm"][0]
    dr = estimates["roller.diameter_mm"][0]
    lr = estimates["roller.length_mm"][0]
    placeholders = _placeholders(dm, dr, lr)
    data: dict[str, Any] = {"bearing": {"type": bearing_type}}
    values = {k: v for k, (v, _) in estimates.items()} | {k: v for k, (v, _) in placeholders.items()}
    for path, value in values.items():
        node = data
        *sections, name = path.split(".")
        for s in sections:
            node = node.setdefault(s, {})
        node[name] = _rounded(path, value)
    data[SECTION] = {
        k: {"plus_minus": _rounded(k, u.plus_minus), "estimated": u.estimated}
        for k, (_, u) in estimates.items()
        if u is not None
    }
    config = Config(data)
    return EstimatedConfig(config, dim, bearing_type, {k: note for k, (_, note) in placeholders.items()})


def _rounded(path: str, value: Any) -> Any:
    """An estimate to 4 significant digits (integers as they are): the file shows what the rule
    gives, not 17 digits of arithmetic."""
    if isinstance(value, int) or KEY_BY_PATH[path].kind is int:
        return int(value)
    return float(f"{value:.4g}")
