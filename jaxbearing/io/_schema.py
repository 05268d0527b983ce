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

Schema (ranges; "(" open, "[" closed; symbols as in docs/model.md and the source paper):

| key | symbol | valid range |
|---|---|---|
| bearing.pitch_diameter_mm | d_m | (0, 10000] |
| bearing.radial_clearance_um | P_d (diametral) | [0, pitch_diameter_mm*10] (1 % of d_m) |
| bearing.num_rollers | Z | integer >= 3 with Z (D + C_p) < pi d_m |
| bearing.num_slices | N_s | odd integer in [3, 200] |
| bearing.inner_ring_mass_kg | m_i | (0, 1e5] |
| bearing.flange_traction, pocket_friction | mu_f, mu_p | [0, 1] |
| bearing.flange_lubrication | | "dry" (constant mu_f) or "mixed" (film-dependent) |
| bearing.type | | "NUP", "NU", "N", "NJ" or a list of flanges from "inner-X", "inner+X", "outer-X", "outer+X" with one on each side |
| roller.diameter_mm | D | (0, pitch_diameter_mm/2) |
| roller.corner_radius_mm | R_cor | (0, diameter_mm/2) |
| roller.length_mm | L_b1 | (2 corner_radius_mm, 10 diameter_mm] |
| roller.central_length_mm | L_b2 | [0, length_mm - 2 corner_radius_mm] |
| roller.crown_drop_um | c_crown | [0, diameter_mm/10] |
| roller.end_radius_mm | R_end | (diameter_mm/2, inf], inf = flat end |
| roller.end_offset_mm | e (end arc centre off the roller axis) | [0, diameter_mm/2 - corner_radius_mm), 0 = sphere |
| flange.height_mm | H_rf | (0, diameter_mm) |
| flange.relief_height_mm | h_rel | [0, height_mm) |
| flange.contact_height_limit_mm | h_up | (relief_height_mm, height_mm] |
| flange.layback_angle_deg | theta_f | (0, 10] |
| flange.axial_clearance_mm | Delta_bf | [0, length_mm) |
| flange.roughness_um | sigma (composite rms, end and flange) | [0, 10] |
| flange.rib_radius_mm | R_rib (rib meridian arc, concave) | (end_radius_mm, inf], inf = cone; (corner_radius_mm, inf] for a flat end |
| flange.rib_tangent_height_mm | h_t (where the rib arc touches the cone) | [0, height_mm] |
| cage.inner_diameter_mm | | (inner raceway diameter, pitch_diameter_mm) |
| cage.outer_diameter_mm | | (pitch_diameter_mm, outer raceway diameter - guiding_clearance_mm] |
| cage.width_mm | | (length_mm + pocket_clearance_mm, 3 length_mm] |
| cage.pocket_clearance_mm, guiding_clearance_mm | C_p, C_g | (0, diameter_mm/2) |
| cage.land_width_mm | b_l | (0, width_mm/2] |
| materials.*.elastic_modulus_GPa | E | (0, 1500] |
| materials.*.poisson_ratio | nu | (-1, 0.5) |
| materials.*.density_kg_m3 | rho | (0, 25000] |
| materials.*.thermal_conductivity_W_mK | k | (0, 500] |
| materials.*.specific_heat_J_kgK | c | (0, 5000] |
| lubricant.viscosity_Pa_s | eta_0 | (0, 100] |
| lubricant.pressure_viscosity_1_Pa | alpha_p | [0, 1e-6] |
| lubricant.temperature_viscosity_1_C | beta_T | [0, 1] |
| lubricant.reference_temperature_C, inlet_temperature_C | T_0, T_in | [-60, 300] |
| lubricant.density_kg_m3 | rho_oil | (0, 2000] |
| lubricant.oil_fraction | f_oil | [0, 1] |
| lubricant.traction_a, traction_d | A, D | [-1, 1] |
| lubricant.traction_b_s_m | B | [-1e4, 1e4], and the curve stays within [-1, 1] |
| lubricant.traction_c_s_m | C | (0, 1e4] |
| operating.speed_rpm | n_i | [0, 100000] |
| operating.radial_load_N | F_r | [0, 1e8] |
| operating.gravity | g | true / false (9.81 m/s^2 along +Z) |
| operating.misalignment_mrad | psi_m | [-10, 10] (inner-ring tilt about +Y) |
| operating.axial_load_N | F_a | [-1e8, 1e8] (along +X); flanges carry it (axial freedom on) or, without a flange path, the locating bearing (freedom off) |
| operating.inner_ring_axial_freedom, inner_ring_tilt_freedom | | true / false |
| simulation.end | | "arc", "corner" or "both" |
| simulation.duration_ms | | (0, 10000] |
| simulation.rtol, atol | | (0, 1) |
| simulation.max_steps | | integer in [1, 1e9] |
| simulation.progress | | true / false |
| simulation.solver | | "tsit5" (default) or "ros34pw2" |

The inner and outer raceway diameters are d_m -/+ (D + P_d/2) (`Bearing.inner_raceway_radius`).
Non-finite values are rejected everywhere except `roller.end_radius_mm = inf` and
`flange.rib_radius_mm = inf`. The three face keys (`roller.end_offset_mm`,
`flange.rib_radius_mm`, `flange.rib_tangent_height_mm`; docs/model.md 5.4) give a bearing with
general faces only where they differ from today's faces (e > 0 or a finite R_rib); otherwise the
bearing carries none (`Bearing.has_general_faces` False) and runs today's contact code.
"""

from __future__ import annotations

import math
from typing import Any

from ..geometry import (
    BEARING_TYPES,
    FLANGES,
    arrangement_of,
    carries_axial_load,
    flange_presence,
    locates_rollers,
)
from ._keys import Convert, Extra, Key, constant_bound, format_derived, format_value, make_key, relative_bound


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
            f"Z D = {format_derived(z * d)} mm must be < pi d_m = {format_derived(circ)} mm"
        )
    if z * (d + cp) >= circ:
        return (
            f"{z} rollers leave no room for the cage bars: Z (D + C_p) = "
            f"{format_derived(z * (d + cp))} mm must be < pi d_m = {format_derived(circ)} mm"
        )
    return None


def _odd_slices(v) -> str | None:
    """docs/model.md 8: an odd slice count puts a slice at the roller centre (symmetric slicing)."""
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
        f"{format_derived(peak)} at du = {format_derived(at)} m/s; it must stay within [-1, 1] "
        f"(A = {format_value(a)}, B = {format_value(b)} s/m, C = {format_value(c)} s/m, "
        f"D = {format_value(d)})"
    )


def _axial_load_held(v) -> str | None:
    """An axial load that the flanges carry (`_axial_load_carried`) needs the inner ring's axial
    freedom: a ring held axially carries it to ground itself, so the load would silently do
    nothing. (A load without a flange path goes to the shaft's locating bearing instead, which
    holds the ring: `_axial_load_carried`.)"""
    f = v["operating.axial_load_N"]
    if f == 0.0 or v["operating.inner_ring_axial_freedom"]:
        return None
    if not carries_axial_load(flange_presence(v["bearing.type"]), f):
        return None
    return (
        f"{format_value(f)} N needs operating.inner_ring_axial_freedom = true (the ring is held "
        "axially, so the load would do nothing): must be 0 N while the axial freedom is off"
    )


def _rollers_located(v) -> str | None:
    """A flange on each side (-X and +X, either ring): otherwise nothing locates the rollers
    axially and they leave the raceway (docs/model.md 5.3)."""
    t = v["bearing.type"]
    presence = flange_presence(t)
    if locates_rollers(presence):
        return None
    side = "-X" if not (presence[0] or presence[2]) else "+X"
    return (
        f"{format_value(t)} has no flange on the {side} side, so nothing locates the rollers "
        f'axially: add "inner{side}" or "outer{side}"'
    )


def _axial_load_carried(v) -> str | None:
    """Where an axial load on the inner ring goes. With a flange path to the outer ring (along +X
    the inner -X and the outer +X flange, along -X the inner +X and the outer -X flange,
    `geometry.carries_axial_load`) the flanges carry it, the ring free axially. Without one (a
    floating bearing: NU, N; NJ along -X) the shaft's locating bearing carries it, as in a
    machine, and holds the inner ring axially: the axial freedom must then be off. A ring free
    axially would be pushed off the rollers, nothing in the bearing balancing the load
    (docs/model.md 5.3)."""
    f, t = v["operating.axial_load_N"], v["bearing.type"]
    presence = flange_presence(t)
    if f == 0.0 or carries_axial_load(presence, f) or not v["operating.inner_ring_axial_freedom"]:
        return None
    need = '"inner-X" and "outer+X"' if f > 0 else '"inner+X" and "outer-X"'
    valid = {(True, False): ">= 0", (False, True): "<= 0"}.get(
        (carries_axial_load(presence, 1.0), carries_axial_load(presence, -1.0)), "0"
    )
    return (
        f"{format_value(f)} N has no flange path in bearing.type = {format_value(t)} (along "
        f"{'+X' if f > 0 else '-X'} it needs the flanges {need}), so the shaft's locating bearing "
        f"carries it and holds the inner ring: with operating.inner_ring_axial_freedom = true it "
        f"must be {valid} N (set the freedom false to apply it)"
    )


def _rib_beyond_end_radius(v) -> str | None:
    """A concave rib conforms with the end only while R_rib > R_end (the meridian curvature sum
    1/R_end - 1/R_rib stays positive; docs/model.md 5.4); against a flat end (R_end = inf, its
    corner carrying the contact) while R_rib > R_cor."""
    r_rib, r, r_cor = v["flange.rib_radius_mm"], v[_REND], v[_RC]
    bound, name = (r, "end_radius_mm") if math.isfinite(r) else (r_cor, "corner_radius_mm (flat end)")
    if math.isinf(r_rib) or r_rib > bound:
        return None
    return (
        f"{format_value(r_rib)} mm must be > {name} = {format_derived(bound)} mm "
        "(a concave rib less curved than the end; inf = the cone)"
    )


def _rib_curvature(radius_mm: float) -> float:
    """flange.rib_radius_mm -> Flange.rib_curvature 1/R_rib [1/m] (+inf: 0, the cone; -inf, which
    is no radius, NaN, so that the pytree's range check rejects it as the file's does)."""
    if math.isinf(radius_mm):
        return 0.0 if radius_mm > 0 else math.nan
    return math.inf if radius_mm == 0 else 1e3 / radius_mm


def _rib_radius_mm(curvature) -> float:
    """Flange.rib_curvature [1/m] -> flange.rib_radius_mm (0: inf, the cone)."""
    return math.inf if curvature == 0 else 1e3 / float(curvature)


# -- the schema --------------------------------------------------------------------------------
_REND = "roller.end_radius_mm"
_DM, _PD = "bearing.pitch_diameter_mm", "bearing.radial_clearance_um"
_D, _L, _RC = "roller.diameter_mm", "roller.length_mm", "roller.corner_radius_mm"
_H, _HREL = "flange.height_mm", "flange.relief_height_mm"
_CP, _CG = "cage.pocket_clearance_mm", "cage.guiding_clearance_mm"


def _material(
    part: str, attr: str, e: float, nu: float, rho: float, what: str, k: float, c: float
) -> list[Key]:
    """The keys of one material: elastic constants, density, and the thermal conductivity and
    specific heat of the flash temperature (docs/model.md 5.5)."""
    s = f"materials.{part}"
    return [
        make_key(
            f"{s}.elastic_modulus_GPa",
            float,
            e,
            "GPa",
            "E",
            f"elastic modulus of the {what}",
            constant_bound(0, False),
            constant_bound(1500, True),
            attr=f"{attr}.elastic_modulus",
        ),
        make_key(
            f"{s}.poisson_ratio",
            float,
            nu,
            "",
            "nu",
            f"Poisson ratio of the {what}",
            constant_bound(-1, False),
            constant_bound(0.5, False),
            attr=f"{attr}.poisson_ratio",
        ),
        make_key(
            f"{s}.density_kg_m3",
            float,
            rho,
            "kg/m^3",
            "rho",
            f"density of the {what}",
            constant_bound(0, False),
            constant_bound(25000, True),
            attr=f"{attr}.density",
        ),
        make_key(
            f"{s}.thermal_conductivity_W_mK",
            float,
            k,
            "W/(m K)",
            "k",
            f"thermal conductivity of the {what}",
            constant_bound(0, False),
            constant_bound(500, True),
            attr=f"{attr}.thermal_conductivity",
        ),
        make_key(
            f"{s}.specific_heat_J_kgK",
            float,
            c,
            "J/(kg K)",
            "c",
            f"specific heat of the {what}",
            constant_bound(0, False),
            constant_bound(5000, True),
            attr=f"{attr}.specific_heat",
        ),
    ]


KEYS: tuple[Key, ...] = (
    # [bearing]
    make_key(
        _DM,
        float,
        85.0,
        "mm",
        "d_m",
        "pitch diameter",
        constant_bound(0, False),
        constant_bound(10000, True),
        attr="pitch_diameter",
    ),
    make_key(
        _PD,
        float,
        20.0,
        "um",
        "P_d",
        "radial clearance (diametral, split between the rings)",
        constant_bound(0, True),
        relative_bound("pitch_diameter_mm*10", (_DM,), lambda dm: dm * 10, True),
        attr="radial_clearance",
        note="at most 1 % of the pitch diameter",
    ),
    make_key(
        "bearing.num_rollers",
        int,
        26,
        "",
        "Z",
        "number of rollers",
        constant_bound(3, True),
        attr="num_rollers",
        extras=(
            Extra(
                (_DM, _D, _CP),
                _rollers_fit,
                "rollers and cage bars fit around the pitch circle: Z (D + C_p) < pi d_m",
            ),
        ),
    ),
    make_key(
        "bearing.num_slices",
        int,
        31,
        "",
        "N_s",
        "raceway slices per roller (odd)",
        constant_bound(3, True),
        constant_bound(200, True),
        attr="num_slices",
        note="odd, so that a slice sits at the roller centre",
        extras=(Extra(("bearing.num_slices",), _odd_slices, "the slice count is odd"),),
    ),
    make_key(
        "bearing.inner_ring_mass_kg",
        float,
        0.5,
        "kg",
        "m_i",
        "effective mass of inner ring and shaft",
        constant_bound(0, False),
        constant_bound(1e5, True),
        attr="inner_ring_mass",
    ),
    make_key(
        "bearing.flange_traction",
        float,
        0.08,
        "",
        "mu_f",
        "roller-flange traction coefficient",
        constant_bound(0, True),
        constant_bound(1, True),
        attr="flange_traction",
    ),
    make_key(
        "bearing.flange_lubrication",
        str,
        "dry",
        "",
        "",
        "roller-flange friction law",
        choices=("dry", "mixed"),
        attr="flange_lubrication",
        note=(
            "dry = constant flange_traction (the source paper); mixed = film-dependent "
            "mixed-lubrication traction from the Hamrock-Dowson film (docs/model.md 5.1)"
        ),
    ),
    make_key(
        "bearing.type",
        str,
        "NUP",
        "",
        "",
        "bearing type: which flanges the rings have",
        choices=tuple(BEARING_TYPES),
        members=FLANGES,
        convert=Convert(flange_presence, arrangement_of),
        attr="flange_presence",
        note=(
            "flanges of NUP: both rings; NU: the outer ring (the inner ring floats); N: the inner "
            "ring; NJ: the outer ring and inner -X (docs/model.md 5.3)"
        ),
        extras=(Extra(("bearing.type",), _rollers_located, "a flange on each side (-X and +X)"),),
    ),
    make_key(
        "bearing.pocket_friction",
        float,
        0.10,
        "",
        "mu_p",
        "roller-pocket friction coefficient",
        constant_bound(0, True),
        constant_bound(1, True),
        attr="pocket_friction",
    ),
    # [roller]
    make_key(
        _D,
        float,
        7.5,
        "mm",
        "D",
        "roller diameter",
        constant_bound(0, False),
        relative_bound("pitch_diameter_mm/2", (_DM,), lambda dm: dm / 2, False),
        attr="roller.diameter",
    ),
    make_key(
        _L,
        float,
        8.0,
        "mm",
        "L_b1",
        "overall roller length (flat-end roller)",
        relative_bound("2 corner_radius_mm", (_RC,), lambda rc: 2 * rc, False),
        relative_bound("10 diameter_mm", (_D,), lambda d: 10 * d, True),
        attr="roller.length",
    ),
    make_key(
        "roller.central_length_mm",
        float,
        4.5,
        "mm",
        "L_b2",
        "straight central length of the generatrix (crowned outside it)",
        constant_bound(0, True),
        relative_bound("length_mm - 2 corner_radius_mm", (_L, _RC), lambda lb, rc: lb - 2 * rc, True),
        attr="roller.central_length",
    ),
    make_key(
        "roller.crown_drop_um",
        float,
        4.0,
        "um",
        "c_crown",
        "crown drop at the ends of the effective length",
        constant_bound(0, True),
        relative_bound("diameter_mm/10", (_D,), lambda d: d * 100, True),
        attr="roller.crown_drop",
    ),
    make_key(
        _RC,
        float,
        0.4,
        "mm",
        "R_cor",
        "corner radius",
        constant_bound(0, False),
        relative_bound("diameter_mm/2", (_D,), lambda d: d / 2, False),
        attr="roller.corner_radius",
    ),
    # the sphere meets the corner torus tangentially only if R_end - R_cor > R_ce, i.e.
    # R_end > D/2 (paper Eq. 19: L_beb = x_cor - sqrt((R_end - R_cor)^2 - R_ce^2)); then the
    # limited circle rho_lim = R_ce R_end/(R_end - R_cor) < D/2 and the end is convex.
    make_key(
        "roller.end_radius_mm",
        float,
        80.0,
        "mm",
        "R_end",
        "end (arc) radius",
        relative_bound("diameter_mm/2", (_D,), lambda d: d / 2, False),
        None,
        attr="roller.end_radius",
        allow_inf=True,
        note="inf = flat end with corner radii only",
    ),
    make_key(
        "roller.end_offset_mm",
        float,
        0.0,
        "mm",
        "e",
        "offset of the end arc's centre from the roller axis (toroidal end)",
        constant_bound(0, True),
        relative_bound("diameter_mm/2 - corner_radius_mm", (_D, _RC), lambda d, rc: d / 2 - rc, False),
        attr="roller.end_offset",
        note="0 = today's spherical end (below end_radius_mm too, since end_radius_mm > diameter_mm/2)",
    ),
    # [flange]
    make_key(
        _H,
        float,
        2.0,
        "mm",
        "H_rf",
        "flange height above the raceway",
        constant_bound(0, False),
        relative_bound("diameter_mm", (_D,), lambda d: d, False),
        attr="flange.height",
    ),
    make_key(
        _HREL,
        float,
        0.3,
        "mm",
        "h_rel",
        "flange base relief (undercut) height",
        constant_bound(0, True),
        relative_bound("height_mm", (_H,), lambda h: h, False),
        attr="flange.relief_height",
    ),
    make_key(
        "flange.contact_height_limit_mm",
        float,
        1.8,
        "mm",
        "h_up",
        "upper limit of the contact height on the flange",
        relative_bound("relief_height_mm", (_HREL,), lambda h: h, False),
        relative_bound("height_mm", (_H,), lambda h: h, True),
        attr="flange.contact_height_limit",
    ),
    make_key(
        "flange.layback_angle_deg",
        float,
        1.6,
        "deg",
        "theta_f",
        "flange layback (opening) angle",
        constant_bound(0, False),
        constant_bound(10, True),
        attr="flange.layback_angle",
    ),
    make_key(
        "flange.axial_clearance_mm",
        float,
        0.15,
        "mm",
        "Delta_bf",
        "axial clearance (flange spacing minus length_mm)",
        constant_bound(0, True),
        relative_bound("length_mm", (_L,), lambda lb: lb, False),
        attr="flange.axial_clearance",
    ),
    make_key(
        "flange.roughness_um",
        float,
        0.2,
        "um",
        "sigma",
        "composite rms roughness of roller end and flange face",
        constant_bound(0, True),
        constant_bound(10, True),
        attr="flange.roughness",
        note="sigma = sqrt(s_end^2 + s_flange^2); 0.2 um: ground end and flange",
    ),
    # a concave rib conforms with the end only while R_rib > R_end (the meridian curvature sum
    # 1/R_end - 1/R_rib stays positive; docs/model.md 5.4); a convex rib is not modelled
    make_key(
        "flange.rib_radius_mm",
        float,
        math.inf,
        "mm",
        "R_rib",
        "radius of the rib face's meridian arc (concave)",
        constant_bound(0, False),
        None,
        attr="flange.rib_curvature",
        allow_inf=True,
        convert=Convert(_rib_curvature, _rib_radius_mm),
        note="inf = today's cone",
        extras=(
            Extra(("flange.rib_radius_mm", _REND), _rib_beyond_end_radius, "finite only above end_radius_mm"),
        ),
    ),
    make_key(
        "flange.rib_tangent_height_mm",
        float,
        0.0,
        "mm",
        "h_t",
        "height above the raceway where the rib arc touches the cone",
        constant_bound(0, True),
        relative_bound("height_mm", (_H,), lambda h: h, True),
        attr="flange.rib_tangent_height",
    ),
    # [cage]
    make_key(
        "cage.inner_diameter_mm",
        float,
        80.0,
        "mm",
        "",
        "cage bore",
        relative_bound("inner raceway diameter", (_DM, _D, _PD), lambda dm, d, pd: dm - d - pd / 2000, False),
        relative_bound("pitch_diameter_mm", (_DM,), lambda dm: dm, False),
        attr="cage.inner_diameter",
        note="inner raceway diameter = pitch_diameter_mm - diameter_mm - radial_clearance_um/2000",
    ),
    make_key(
        "cage.outer_diameter_mm",
        float,
        90.0,
        "mm",
        "",
        "cage outside diameter (guided on the outer-ring lands)",
        relative_bound("pitch_diameter_mm", (_DM,), lambda dm: dm, False),
        relative_bound(
            "outer raceway diameter - guiding_clearance_mm",
            (_DM, _D, _PD, _CG),
            lambda dm, d, pd, cg: dm + d + pd / 2000 - cg,
            True,
        ),
        attr="cage.outer_diameter",
        note="outer raceway diameter = pitch_diameter_mm + diameter_mm + radial_clearance_um/2000",
    ),
    make_key(
        "cage.width_mm",
        float,
        14.0,
        "mm",
        "",
        "cage width",
        relative_bound("length_mm + pocket_clearance_mm", (_L, _CP), lambda lb, cp: lb + cp, False),
        relative_bound("3 length_mm", (_L,), lambda lb: 3 * lb, True),
        attr="cage.width",
    ),
    make_key(
        _CP,
        float,
        0.20,
        "mm",
        "C_p",
        "pocket clearance (circumferential, total)",
        constant_bound(0, False),
        relative_bound("diameter_mm/2", (_D,), lambda d: d / 2, False),
        attr="cage.pocket_clearance",
    ),
    make_key(
        _CG,
        float,
        0.40,
        "mm",
        "C_g",
        "guiding clearance on the outer-ring lands (diametral)",
        constant_bound(0, False),
        relative_bound("diameter_mm/2", (_D,), lambda d: d / 2, False),
        attr="cage.guiding_clearance",
    ),
    make_key(
        "cage.land_width_mm",
        float,
        3.0,
        "mm",
        "b_l",
        "guiding land width (each of two)",
        constant_bound(0, False),
        relative_bound("width_mm/2", ("cage.width_mm",), lambda w: w / 2, True),
        attr="cage.land_width",
    ),
    # [materials.*]
    # thermal constants: MakeItFrom.com, SAE-AISI M50 (35 W/m-K, 470 J/kg-K) and 4340 (44, 470)
    *_material("ring", "ring_material", 203.0, 0.28, 7830.0, "rings (AISI M50)", 35.0, 470.0),
    *_material("roller", "roller_material", 203.0, 0.28, 7830.0, "rollers (AISI M50)", 35.0, 470.0),
    *_material("cage", "cage_material", 205.0, 0.29, 7850.0, "cage (AISI 4340)", 44.0, 470.0),
    # [lubricant]
    make_key(
        "lubricant.viscosity_Pa_s",
        float,
        0.055,
        "Pa s",
        "eta_0",
        "dynamic viscosity at reference_temperature_C",
        constant_bound(0, False),
        constant_bound(100, True),
        attr="lubricant.viscosity",
    ),
    make_key(
        "lubricant.pressure_viscosity_1_Pa",
        float,
        1.85e-8,
        "1/Pa",
        "alpha_p",
        "pressure-viscosity coefficient",
        constant_bound(0, True),
        constant_bound(1e-6, True),
        attr="lubricant.pressure_viscosity",
    ),
    make_key(
        "lubricant.temperature_viscosity_1_C",
        float,
        0.0315,
        "1/C",
        "beta_T",
        "temperature-viscosity coefficient",
        constant_bound(0, True),
        constant_bound(1, True),
        attr="lubricant.temperature_viscosity",
    ),
    make_key(
        "lubricant.reference_temperature_C",
        float,
        80.0,
        "C",
        "T_0",
        "temperature at which viscosity_Pa_s is given",
        constant_bound(-60, True),
        constant_bound(300, True),
        attr="lubricant.reference_temperature",
    ),
    make_key(
        "lubricant.inlet_temperature_C",
        float,
        80.0,
        "C",
        "T_in",
        "oil temperature at the roller-flange contact inlet",
        constant_bound(-60, True),
        constant_bound(300, True),
        attr="lubricant.inlet_temperature",
        note="eta = viscosity_Pa_s exp(-temperature_viscosity_1_C (T_in - T_0)) in the flange film",
    ),
    make_key(
        "lubricant.density_kg_m3",
        float,
        960.0,
        "kg/m^3",
        "rho_oil",
        "lubricant density",
        constant_bound(0, False),
        constant_bound(2000, True),
        attr="lubricant.density",
    ),
    make_key(
        "lubricant.oil_fraction",
        float,
        0.05,
        "",
        "f_oil",
        "oil volume fraction in the cavity",
        constant_bound(0, True),
        constant_bound(1, True),
        attr="lubricant.oil_fraction",
    ),
    make_key(
        "lubricant.traction_a",
        float,
        -0.04,
        "",
        "A",
        "traction curve constant",
        constant_bound(-1, True),
        constant_bound(1, True),
        attr="lubricant.traction_a",
        note="rolling-contact traction kappa(du) = (A + B du) exp(-C du) + D, du = sliding speed",
    ),
    make_key(
        "lubricant.traction_b_s_m",
        float,
        0.2528,
        "s/m",
        "B",
        "traction curve slope",
        constant_bound(-1e4, True),
        constant_bound(1e4, True),
        attr="lubricant.traction_b",
        extras=(
            Extra(
                ("lubricant.traction_a", "lubricant.traction_c_s_m", "lubricant.traction_d"),
                _traction_bounded,
                "|kappa(du)| <= 1 for all du >= 0",
            ),
        ),
    ),
    make_key(
        "lubricant.traction_c_s_m",
        float,
        2.926,
        "s/m",
        "C",
        "traction curve decay",
        constant_bound(0, False),
        constant_bound(1e4, True),
        attr="lubricant.traction_c",
    ),
    make_key(
        "lubricant.traction_d",
        float,
        0.04,
        "",
        "D",
        "traction at high sliding speed",
        constant_bound(-1, True),
        constant_bound(1, True),
        attr="lubricant.traction_d",
    ),
    # [operating]
    make_key(
        "operating.speed_rpm",
        float,
        20000.0,
        "rpm",
        "n_i",
        "inner ring speed (outer ring fixed)",
        constant_bound(0, True),
        constant_bound(100000, True),
        attr="op.inner_speed",
    ),
    make_key(
        "operating.radial_load_N",
        float,
        1000.0,
        "N",
        "F_r",
        "radial load on the inner ring (+Z)",
        constant_bound(0, True),
        constant_bound(1e8, True),
        attr="op.radial_load",
    ),
    make_key(
        "operating.gravity",
        bool,
        True,
        "",
        "g",
        "gravity on every body (9.81 m/s^2 along +Z)",
        attr="op.gravity",
    ),
    make_key(
        "operating.misalignment_mrad",
        float,
        0.0,
        "mrad",
        "psi_m",
        "imposed inner-ring misalignment: tilt of the ring axis about +Y (the radial axis "
        "perpendicular to the radial load; > 0 turns the +X end towards -Z)",
        constant_bound(-10, True),
        constant_bound(10, True),
        attr="op.misalignment",
    ),
    make_key(
        "operating.inner_ring_axial_freedom",
        bool,
        False,
        "",
        "",
        "inner ring free to move axially (located by the inner flanges through the rollers)",
        attr="op.axial_freedom",
    ),
    make_key(
        "operating.inner_ring_tilt_freedom",
        bool,
        False,
        "",
        "",
        "inner ring free to tilt about Y and Z (misalignment_mrad is then its initial tilt)",
        attr="op.tilt_freedom",
    ),
    make_key(
        "operating.axial_load_N",
        float,
        0.0,
        "N",
        "F_a",
        "axial load on the inner ring (+X)",
        constant_bound(-1e8, True),
        constant_bound(1e8, True),
        attr="op.axial_load",
        extras=(
            Extra(
                ("operating.inner_ring_axial_freedom", "bearing.type"),
                _axial_load_held,
                "carried by the flanges (bearing.type: +X needs inner-X and outer+X, -X inner+X "
                "and outer-X) with inner_ring_axial_freedom = true",
            ),
            Extra(
                ("bearing.type", "operating.inner_ring_axial_freedom"),
                _axial_load_carried,
                "or, without that flange path (NU, N), by the shaft's locating bearing with "
                "inner_ring_axial_freedom = false",
            ),
        ),
    ),
    # [simulation]
    make_key(
        "simulation.end",
        str,
        "both",
        "",
        "",
        "roller ends to simulate",
        choices=("arc", "corner", "both"),
        note="the arc run needs a finite end_radius_mm",
    ),
    make_key(
        "simulation.duration_ms",
        float,
        20.0,
        "ms",
        "",
        "simulated time",
        constant_bound(0, False),
        constant_bound(10000, True),
    ),
    make_key(
        "simulation.rtol",
        float,
        1e-3,
        "",
        "",
        "relative tolerance of the step-size controller",
        constant_bound(0, False),
        constant_bound(1, False),
    ),
    make_key(
        "simulation.atol",
        float,
        1e-6,
        "",
        "",
        "absolute tolerance on the scaled state (1e-6: 10 nm, 10 um/s, 0.01 rad/s)",
        constant_bound(0, False),
        constant_bound(1, False),
    ),
    make_key(
        "simulation.max_steps",
        int,
        2_000_000,
        "",
        "",
        "maximum number of integrator steps",
        constant_bound(1, True),
        constant_bound(1_000_000_000, True),
    ),
    make_key("simulation.progress", bool, True, "", "", "show a progress meter"),
    make_key(
        "simulation.solver",
        str,
        "tsit5",
        "",
        "",
        "time integrator",
        choices=("tsit5", "ros34pw2"),
        note="ros34pw2: linearly implicit Rosenbrock-W; costs more at equal error (docs/performance.md)",
    ),
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
