"""Bearing parameters as `equinox.Module` pytrees.

Float fields are JAX arrays: differentiable and vmappable (a sweep or a design search stacks
them). Counts (number of rollers, number of raceway slices) are static metadata, so changing
them recompiles but never enters a gradient. Everything is in SI units (m, kg, s, N, rad, Pa);
configuration files (`jaxbearing._config`) carry engineering units in their key names.

Masses and inertias are derived from geometry and density (`jaxbearing._inertia`), never typed
in. The one exception is the inner ring, whose effective mass includes the shaft.

Symbols follow the source study (Machines 2025, 13(11), 993) and `docs/model.md`.
"""

from __future__ import annotations

import math

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, Float

Scalar = Float[Array, ""]


def _f(x) -> Array:
    """Converter: every float field becomes a 64-bit JAX array."""
    return jnp.asarray(x, dtype=jnp.float64)


def _field():
    return eqx.field(converter=_f)


def _optional(x) -> Array | None:
    """Converter of the general-face parameters: None stays None (today's faces, a structural
    switch: the contact code traced for them is today's), anything else a 64-bit JAX array."""
    return None if x is None else _f(x)


def _optional_field():
    return eqx.field(converter=_optional, default=None)


class Roller(eqx.Module):
    """Cylindrical roller with a crowned generatrix and corner-rounded or arc (spherical) ends.

    The end body is the convex hull of a corner torus (tube radius `corner_radius` R_cor, centre
    circle of radius R_ce = D/2 - R_cor at x_cor = L_b1/2 - R_cor from the roller centre) and,
    for an arc end, a spherical cap of radius `end_radius` R_end. A flat end is R_end = inf.

    `end_offset` e (None by default: e = 0, today's sphere, traced as today) makes the arc end a
    torus: the arc's centre lies a distance e off the roller axis (docs/model.md 5.4); the mass
    properties and the limited circle follow it (`jaxbearing.geometry.limited_circle_radius`).
    """

    diameter: Scalar = _field()  # D
    length: Scalar = _field()  # L_b1, overall length of the flat-end roller
    central_length: Scalar = _field()  # L_b2, straight part of the generatrix
    crown_drop: Scalar = _field()  # c_crown at the ends of the effective length
    corner_radius: Scalar = _field()  # R_cor
    end_radius: Scalar = _field()  # R_end (inf: flat end with corners only)
    end_offset: Scalar | None = _optional_field()  # e [m]; None: today's sphere (e = 0)

    @property
    def corner_centre_radius(self) -> Array:
        """R_ce = D/2 - R_cor: radius of the corner torus' centre circle."""
        return self.diameter / 2 - self.corner_radius

    @property
    def corner_centre_offset(self) -> Array:
        """x_cor = L_b1/2 - R_cor: axial distance of the corner centre circle from the centre."""
        return self.length / 2 - self.corner_radius

    @property
    def effective_length(self) -> Array:
        """L_we = L_b1 - 2 R_cor: length carried by the raceway slices."""
        return self.length - 2 * self.corner_radius

    def with_flat_ends(self) -> Roller:
        """The same roller with flat ends and corner radii (R_end = inf)."""
        return eqx.tree_at(lambda r: r.end_radius, self, jnp.asarray(jnp.inf))


class Flange(eqx.Module):
    """Ring flange (the same on both sides of both rings).

    The flange face is a cone of revolution about the ring axis starting at the raceway edge
    x = +/-(L_b1 + Delta_bf)/2 and opening away from the roller by the layback angle theta_f.

    `rib_curvature` 1/R_rib and `rib_tangent_height` h_t (None by default: today's cone, traced
    as today) make the face a surface of revolution whose meridian is an arc of curvature
    1/R_rib (positive concave) tangent to that cone at the height h_t (docs/model.md 5.4).
    """

    height: Scalar = _field()  # H_rf, above the raceway surface
    relief_height: Scalar = _field()  # h_rel, base undercut
    contact_height_limit: Scalar = _field()  # h_up, upper limit of the contact height
    layback_angle: Scalar = _field()  # theta_f [rad]
    axial_clearance: Scalar = _field()  # Delta_bf = flange spacing - L_b1
    # sigma = sqrt(s_end^2 + s_flange^2), composite rms roughness of roller end and flange [m]
    roughness: Scalar = eqx.field(converter=_f, default=0.2e-6)
    rib_curvature: Scalar | None = _optional_field()  # kappa_rib = 1/R_rib [1/m]; None: cone
    rib_tangent_height: Scalar | None = _optional_field()  # h_t [m]; None: 0


class Cage(eqx.Module):
    """Outer-ring-land guided machined cage (annulus with one pocket per roller)."""

    inner_diameter: Scalar = _field()
    outer_diameter: Scalar = _field()
    width: Scalar = _field()
    pocket_clearance: Scalar = _field()  # C_p, circumferential, total
    guiding_clearance: Scalar = _field()  # C_g, diametral, on the outer-ring lands
    land_width: Scalar = _field()  # b_l, per land (two lands)


#: thermal conductivity [W/(m K)] and specific heat [J/(kg K)] of through-hardened bearing steel,
#: SAE-AISI 52100 (100Cr6): MakeItFrom.com, "SAE-AISI 52100 (G52986) Chromium Steel" (47 W/m-K,
#: 470 J/kg-K); the defaults of `Material` (docs/model.md 5.5)
BEARING_STEEL_CONDUCTIVITY = 47.0
BEARING_STEEL_SPECIFIC_HEAT = 470.0


class Material(eqx.Module):
    """Isotropic linear-elastic material with the thermal constants of the flash temperature.

    `thermal_conductivity` k and `specific_heat` c default to bearing steel (AISI 52100,
    `BEARING_STEEL_CONDUCTIVITY`); the thermal diffusivity is derived, kappa = k / (rho c).
    """

    elastic_modulus: Scalar = _field()  # E [Pa]
    poisson_ratio: Scalar = _field()  # nu
    density: Scalar = _field()  # rho [kg/m^3]
    thermal_conductivity: Scalar = eqx.field(converter=_f, default=BEARING_STEEL_CONDUCTIVITY)  # k [W/(m K)]
    specific_heat: Scalar = eqx.field(converter=_f, default=BEARING_STEEL_SPECIFIC_HEAT)  # c [J/(kg K)]

    @property
    def thermal_diffusivity(self) -> Array:
        """kappa = k / (rho c) [m^2/s]."""
        return self.thermal_conductivity / (self.density * self.specific_heat)


class Lubricant(eqx.Module):
    """Lubricant, oil-air mixture in the cavity, and the traction curve of rolling contacts.

    Traction curve (docs/model.md 8): kappa(du) = (A + B du) exp(-C du) + D, with kappa(0) = A + D.
    Viscosity at the flange inlet: eta_0 exp(-beta_T (T_in - T_0)) (`contact.viscosity_at_temperature`).
    """

    viscosity: Scalar = _field()  # eta_0 [Pa s] at reference_temperature
    pressure_viscosity: Scalar = _field()  # alpha_p [1/Pa]
    temperature_viscosity: Scalar = _field()  # beta_T [1/K]
    density: Scalar = _field()  # rho_oil [kg/m^3]
    oil_fraction: Scalar = _field()  # f_oil, oil volume fraction in the cavity
    traction_a: Scalar = _field()  # A [-]
    traction_b: Scalar = _field()  # B [s/m]
    traction_c: Scalar = _field()  # C [s/m]
    traction_d: Scalar = _field()  # D [-]
    reference_temperature: Scalar = eqx.field(converter=_f, default=80.0)  # T_0 of eta_0 [C]
    inlet_temperature: Scalar = eqx.field(converter=_f, default=80.0)  # T_in at the flange [C]


class Bearing(eqx.Module):
    """A whole cylindrical roller bearing: geometry, materials, lubricant, friction, and which
    flanges it has (`flange_presence`, the bearing type).

    `num_rollers` (Z) and `num_slices` (N_s) are static: they fix array shapes.
    """

    pitch_diameter: Scalar = _field()  # d_m
    radial_clearance: Scalar = _field()  # P_d, diametral
    inner_ring_mass: Scalar = _field()  # m_i, inner ring + shaft effective mass
    flange_traction: Scalar = _field()  # mu_f
    pocket_friction: Scalar = _field()  # mu_p
    roller: Roller
    flange: Flange
    cage: Cage
    ring_material: Material
    roller_material: Material
    cage_material: Material
    lubricant: Lubricant
    num_rollers: int = eqx.field(static=True)  # Z
    num_slices: int = eqx.field(static=True, default=31)  # N_s (odd)
    #: roller-end/flange friction law (static: it selects the compiled law): "dry" = constant
    #: `flange_traction`; "mixed" = film-dependent mixed-lubrication traction (docs/model.md 5.1)
    flange_lubrication: str = eqx.field(static=True, default="dry")
    #: presence of each flange, 1.0 there or 0.0 absent, in the order inner -X, inner +X,
    #: outer -X, outer +X (`geometry.FLANGES`); data, not static: the bearing type
    #: (`geometry.BEARING_TYPES`, docs/model.md 5.3). All four there: an NUP bearing.
    flange_presence: Float[Array, "*batch 4"] = eqx.field(converter=_f, default=(1.0, 1.0, 1.0, 1.0))

    # -- derived geometry ----------------------------------------------------------------
    @property
    def inner_raceway_radius(self) -> Array:
        """Radius of the inner raceway: (d_m - D)/2 - P_d/4 (clearance split between rings)."""
        return (self.pitch_diameter - self.roller.diameter) / 2 - self.radial_clearance / 4

    @property
    def outer_raceway_radius(self) -> Array:
        """Radius of the outer raceway: (d_m + D)/2 + P_d/4."""
        return (self.pitch_diameter + self.roller.diameter) / 2 + self.radial_clearance / 4

    @property
    def raceway_width(self) -> Array:
        """W_r = L_b1 + Delta_bf: flange-to-flange spacing at the raceway (paper Eq. 8)."""
        return self.roller.length + self.flange.axial_clearance

    # -- derived masses (jaxbearing._inertia) -------------------------------------------
    @property
    def roller_mass(self) -> Array:
        from ._inertia import roller_mass_properties

        return roller_mass_properties(self.roller, self.roller_material.density)[0]

    @property
    def roller_inertia(self) -> Array:
        """(I_axial, I_transverse) of one roller about its centre [kg m^2]."""
        from ._inertia import roller_mass_properties

        _, i_ax, i_tr = roller_mass_properties(self.roller, self.roller_material.density)
        return jnp.stack([i_ax, i_tr])

    @property
    def cage_mass(self) -> Array:
        from ._inertia import cage_mass_properties

        return cage_mass_properties(self)[0]

    @property
    def cage_inertia(self) -> Array:
        """(I_polar, I_transverse) of the cage about its centre [kg m^2]."""
        from ._inertia import cage_mass_properties

        _, i_p, i_t = cage_mass_properties(self)
        return jnp.stack([i_p, i_t])

    @property
    def inner_ring_inertia(self) -> Array:
        """(I_axial, I_transverse) of the inner ring about its centre [kg m^2]
        (`_inertia.inner_ring_inertia`)."""
        from ._inertia import inner_ring_inertia

        return jnp.stack(inner_ring_inertia(self))

    @property
    def has_general_faces(self) -> bool:
        """Whether the roller end or the rib carries a general-face parameter (a torus end, a
        curved rib; docs/model.md 5.4): static, from the pytree's structure, so the reference
        bearing (all None) traces today's contact code unchanged."""
        r, f = self.roller, self.flange
        return any(x is not None for x in (r.end_offset, f.rib_curvature, f.rib_tangent_height))

    def with_flat_ends(self) -> Bearing:
        """The same bearing with flat-end (corner) rollers."""
        return eqx.tree_at(lambda b: b.roller, self, self.roller.with_flat_ends())


class OperatingPoint(eqx.Module):
    """Inner ring driven at `inner_speed`, radial `radial_load` on the inner ring along +Z
    (the direction of gravity), outer ring fixed.

    Misalignment and inner-ring freedom (docs/model.md, "Misalignment"): the inner ring's axis
    is tilted by `misalignment` psi_m about +Y (the radial axis perpendicular to the load), so
    that it points along (cos psi_m, 0, -sin psi_m). `axial_load` F_a acts on the inner ring
    along +X. `axial_freedom` and `tilt_freedom` are switches (1.0 on, 0.0 off; floats so that
    they are traced data, not recompilation keys): with them off the ring's axial position and
    its tilt stay at 0 and at psi_m. All four default to 0 (the aligned, radially loaded ring).
    """

    inner_speed: Scalar = _field()  # omega_i [rad/s]
    radial_load: Scalar = _field()  # F_r [N]
    gravity: Scalar = _field()  # g [m/s^2], 0 switches gravity off
    misalignment: Scalar = eqx.field(converter=_f, default=0.0)  # psi_m about +Y [rad]
    axial_load: Scalar = eqx.field(converter=_f, default=0.0)  # F_a along +X [N]
    axial_freedom: Scalar = eqx.field(converter=_f, default=0.0)  # 1: x_i free, 0: x_i = 0
    tilt_freedom: Scalar = eqx.field(converter=_f, default=0.0)  # 1: tilt free, 0: tilt = psi_m


def rpm_to_rad_s(rpm):
    return rpm * (2 * math.pi / 60)


def rad_s_to_rpm(w):
    return w * (60 / (2 * math.pi))


def kinematic_cage_speed(bearing: Bearing, op: OperatingPoint) -> Array:
    """Cage speed under pure rolling with a fixed outer ring: omega_c = omega_i (1 - D/d_m)/2.

    (Harris & Kotzalas, Essential Concepts of Bearing Technology, Eq. 8.13 with zero contact
    angle.)
    """
    return op.inner_speed * (1 - bearing.roller.diameter / bearing.pitch_diameter) / 2
