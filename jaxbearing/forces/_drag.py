"""Oil-air drag on the rollers and churning torque on the cage (the paper's F_bd and M_cd).

The bearing cavity holds an oil-air mist. It is treated as one Newtonian fluid with

    rho_mix = f_oil rho_oil,          eta_mix = f_oil eta_0,

the volume-weighted mixture of oil and (massless, inviscid next to oil) air, with f_oil the oil
volume fraction (`Lubricant.oil_fraction`). Linear mixing of the viscosity is the simplest
choice that vanishes with the oil and returns eta_0 for a flooded cavity; Harris & Kotzalas
("Advanced Concepts of Bearing Technology", 5th ed., fluid drag on rolling elements)
use the same effective-density idea with an empirically tuned oil fraction.

Laws (every one smooth at rest: speeds enter through |v|^2 or |omega|, never a bare norm or
`sign`, so values and first derivatives are finite and continuous at zero speed):

* Orbital drag of a roller (cylinder of diameter D, length L_b1 in cross flow)::

      F_bd = -1/2 rho_mix C_d (D L_b1) |v| v,
      C_d = 1 + 10 Re^(-2/3),     Re = rho_mix |v| D / eta_mix

  C_d is White's curve fit for a circular cylinder in cross flow (F. M. White, "Viscous Fluid
  Flow", 3rd ed., valid for 1 <= Re <= 2e5; C_d -> 1 on the Re 1e3-1e5 plateau). A constant
  C_d may be passed instead, which makes the drag exactly quadratic in speed.

* Spin (skin-friction) torque on a roller about its axis, and the cylindrical surfaces of the
  cage: wall shear stress of a cylinder of radius R spinning at omega in a quiescent fluid::

      tau_w = 2 eta_mix omega  +  1/2 rho_mix C_f U^2,   U = omega R,
      C_f = 0.074 Re_x^(-1/5),  Re_x = rho_mix |U| (2 pi R) / eta_mix

  The first term is the exact laminar (Couette/Stokes) stress of a cylinder rotating in an
  unbounded fluid (Batchelor, "An Introduction to Fluid Dynamics"); the second is Prandtl's
  1/7-power turbulent flat-plate skin friction with the run length taken as the circumference
  (Schlichting, "Boundary-Layer Theory", turbulent flat plate). Their sum is a smooth blend:
  each dominates in its own regime. Torque = tau_w (2 pi R l) R, opposing the spin.

* End faces (disks and annuli rotating about their axis), both faces together::

      M = 32/3 eta_mix R^3 omega                                   (Stokes, Jeffery 1915)
        + 0.616 pi rho_mix nu^(1/2) |omega|^(1/2) omega (R_o^4 - R_i^4)   (von Karman laminar
                                                                       boundary layer)

  with nu = eta_mix / rho_mix (Schlichting, "Boundary-Layer Theory", the free rotating disk:
  torque coefficient C_M = 3.87 Re^(-1/2)). Again the sum blends the creeping and boundary-layer
  regimes; the cage faces run at Re = omega R^2 / nu ~ 4e4, below disk transition (~3e5).

The cage churning torque `cage_drag_torque` adds both annular side faces (inner diameter to
outer diameter), the bore (full width) and the outer cylinder outside the two guiding lands
(width W - 2 b_l; the lands themselves are the hydrodynamic film of `_cage_lands`). Pocket
openings are neglected. These are order-of-magnitude churning laws, documented rather than
tuned; the paper does not give its own (it refers to its refs. [1, 22]).
"""

from __future__ import annotations

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from ..geometry import Bearing

Scalar = Float[Array, ""]
Vector = Float[Array, "3"]

#: Coefficients of White's cylinder drag fit C_d = 1 + 10 Re^(-2/3) (Viscous Fluid Flow).
_WHITE_CD_PLATEAU = 1.0
_WHITE_CD_COEFF = 10.0
#: Prandtl 1/7-power turbulent skin friction C_f = 0.074 Re_x^(-1/5).
_PRANDTL_CF = 0.074
#: von Karman free-disk boundary-layer torque constant (-G'(0) = 0.616).
_KARMAN_DISK = 0.616


def mixture_density(bearing: Bearing) -> Scalar:
    """rho_mix = f_oil rho_oil: density of the oil-air mist in the cavity [kg/m^3]."""
    lub = bearing.lubricant
    return lub.oil_fraction * lub.density


def mixture_viscosity(bearing: Bearing) -> Scalar:
    """eta_mix = f_oil eta_0: dynamic viscosity of the oil-air mist [Pa s]."""
    lub = bearing.lubricant
    return lub.oil_fraction * lub.viscosity


def mixture_kinematic_viscosity(bearing: Bearing) -> Scalar:
    """nu_mix = eta_mix / rho_mix = eta_0 / rho_oil [m^2/s]: the oil fraction cancels, so it is
    taken from the oil directly (finite at f_oil = 0, where the mist has no drag at all)."""
    lub = bearing.lubricant
    return lub.viscosity / lub.density


def _safe_power(x2: ArrayLike, p: float) -> Array:
    """(x2)^p for x2 >= 0 with a zero value *and zero gradient* at x2 = 0 (double `where`).

    Used for |v|^(2p) with fractional p: the plain power has an infinite derivative at zero
    that, multiplied by the zero derivative of |v|^2, would give NaN.
    """
    pos = x2 > 0
    return jnp.where(pos, jnp.where(pos, x2, 1.0) ** p, 0.0)


def _cylinder_wall_shear(omega, radius, rho, eta, nu) -> Array:
    """tau_w = 2 eta omega + 1/2 rho C_f U |U| of a cylinder spinning at omega (signed, along U).

    Laminar Couette stress plus Prandtl's turbulent flat-plate law over one circumference
    (see the module docstring); C_f U^2 = 0.074 (eta / (rho 2 pi R))^(1/5) |U|^(4/5) U.
    """
    u = omega * radius
    turbulent = 0.5 * rho * _PRANDTL_CF * (nu / (2 * jnp.pi * radius)) ** 0.2 * _safe_power(u * u, 0.4) * u
    return 2 * eta * omega + turbulent


def _cylinder_torque(omega, radius, length, rho, eta, nu) -> Array:
    """Skin-friction torque tau_w (2 pi R l) R on a spinning cylindrical surface (opposes omega)."""
    return -_cylinder_wall_shear(omega, radius, rho, eta, nu) * 2 * jnp.pi * radius**2 * length


def _disk_torque(omega, outer_radius, inner_radius, rho, eta, nu) -> Array:
    """Torque on an annulus (R_i..R_o) spinning about its axis, both faces (opposes omega).

    M = -(32/3 eta (R_o^3 - R_i^3) omega + 0.616 pi rho nu^(1/2) |omega|^(1/2) omega
    (R_o^4 - R_i^4)): Stokes' creeping-flow disk torque (Jeffery 1915; applied to the annulus by
    difference, an approximation for the creeping term only) plus von Karman's laminar boundary
    layer, which is additive over radius and so exact for the annulus.
    """
    creeping = 32.0 / 3.0 * eta * (outer_radius**3 - inner_radius**3) * omega
    boundary_layer = (
        _KARMAN_DISK
        * jnp.pi
        * rho
        * jnp.sqrt(nu)
        * _safe_power(omega * omega, 0.25)
        * omega
        * (outer_radius**4 - inner_radius**4)
    )
    return -(creeping + boundary_layer)


def cylinder_drag_coefficient(reynolds: ArrayLike) -> Array:
    """C_d = 1 + 10 Re^(-2/3): White's fit for a circular cylinder in cross flow.

    F. M. White, "Viscous Fluid Flow", 3rd ed., valid for 1 <= Re <= 2e5. Infinite at
    Re = 0; the drag force below multiplies it by Re^2 so the force itself is finite.
    """
    return _WHITE_CD_PLATEAU + _WHITE_CD_COEFF * reynolds ** (-2.0 / 3.0)


def roller_drag(
    bearing: Bearing,
    roller_orbital_velocity: Float[Array, 3],
    roller_spin_rate: Float[Array, ""],
    drag_coefficient: float | None = None,
) -> tuple[Vector, Scalar]:
    """Oil-air drag on one roller: (force (3,), spin torque about the roller axis).

    Orbital drag (paper's F_bd), the roller as a cylinder D x L_b1 in cross flow::

        F = -1/2 rho_mix C_d (D L_b1) |v| v

    with `roller_orbital_velocity` v the velocity of the roller centre relative to the mist
    (the caller passes the inertial velocity for a quiescent mist). With the default
    `drag_coefficient=None`, C_d follows White's fit (`cylinder_drag_coefficient`), which makes
    F = -1/2 rho_mix D L_b1 (|v| + 10 (eta_mix / (rho_mix D))^(2/3) |v|^(1/3)) v; a float
    gives a constant C_d (1.0 is the usual choice for Re 1e3-1e5), and F is exactly quadratic.

    Spin torque (scalar, about the roller axis, opposing `roller_spin_rate`): skin friction on
    the cylindrical surface (`_cylinder_torque`, length L_b1) plus both end faces as a disk of
    radius D/2 (`_disk_torque`). See the module docstring for the laws and their sources.
    """
    rho = mixture_density(bearing)
    eta = mixture_viscosity(bearing)
    nu = mixture_kinematic_viscosity(bearing)
    d = bearing.roller.diameter
    length = bearing.roller.length
    v = jnp.asarray(roller_orbital_velocity)
    speed2 = jnp.sum(v * v)
    area = d * length
    if drag_coefficient is None:
        # C_d |v| = |v| + 10 (eta/(rho D))^(2/3) |v|^(1/3)
        cd_speed = _safe_power(speed2, 0.5) + _WHITE_CD_COEFF * (nu / d) ** (2.0 / 3.0) * _safe_power(
            speed2, 1.0 / 6.0
        )
    else:
        cd_speed = drag_coefficient * _safe_power(speed2, 0.5)
    force = -0.5 * rho * area * cd_speed * v

    omega = jnp.asarray(roller_spin_rate)
    radius = d / 2
    torque = _cylinder_torque(omega, radius, length, rho, eta, nu) + _disk_torque(
        omega, radius, jnp.zeros_like(radius), rho, eta, nu
    )
    return force, torque


def cage_drag_torque(bearing: Bearing, cage_speed: Float[Array, ""]) -> Scalar:
    """Churning torque on the cage about the bearing axis (paper's M_cd), opposing `cage_speed`.

    Sum of: both annular side faces (`_disk_torque`, R_i = D_ci/2 to R_o = D_co/2), the bore
    (`_cylinder_torque`, radius D_ci/2, full width W) and the outer cylinder outside the two
    guiding lands (radius D_co/2, width W - 2 b_l). Mist properties rho_mix, eta_mix as above.
    """
    rho = mixture_density(bearing)
    eta = mixture_viscosity(bearing)
    nu = mixture_kinematic_viscosity(bearing)
    cage = bearing.cage
    omega = jnp.asarray(cage_speed)
    r_o = cage.outer_diameter / 2
    r_i = cage.inner_diameter / 2
    faces = _disk_torque(omega, r_o, r_i, rho, eta, nu)
    bore = _cylinder_torque(omega, r_i, cage.width, rho, eta, nu)
    outside = _cylinder_torque(omega, r_o, cage.width - 2 * cage.land_width, rho, eta, nu)
    return faces + bore + outside
