"""Lubrication of the roller-end/flange contact: entrainment, EHL film, film parameter and the
friction coefficient (docs/model.md 5.1; the laws are `jaxbearing.contact`'s `_film`).

Kinematics. Hamrock & Dowson's film depends on the mean entrainment velocity of the two surfaces
RELATIVE TO THE CONTACT (1977; Hamrock, Schmid & Jacobson, Fundamentals of Fluid Film
Lubrication, 2004, ch. 18): with v_1(C) = v + w x (C - p) the roller material velocity at the
contact point C, v_2(C) = v_r + w_r x (C - c_r) the ring's, and v_C the velocity of the contact
point itself,

    u_e = P_t [ (v_1(C) - v_C) + (v_2(C) - v_C) ] / 2 = P_t [ (v_1(C) + v_2(C)) / 2 - v_C ],

P_t = I - n n^T the projection on the tangent plane of the contact. The sliding velocity
u = P_t (v_1(C) - v_2(C)) is independent of v_C; u_e is not.

The contact point's velocity. C is the extreme point of the end body along the flange normal n
(`flange_geometry`), and n is fixed in the frame F that turns with the roller's azimuth about
the ring axis X at the azimuth rate

    Omega = X . ((p - c_r) x (v - v_r)) / |(p - c_r)_YZ|^2

and moves with the ring centre. If the roller's pose relative to F were frozen, C would be
fixed relative to the roller centre in F, so it moves with the roller centre and turns with F:

    v_C = v + Omega X x (C - p).

This drops the motion of C over the end surface caused by the RATES of skew and tilt (the
contact point slides along the end by (end radius) x (rate of turn of n in the roller frame):
at a skew oscillation of amplitude 1 mrad and 1 kHz on an 80 mm end radius, 0.5 m/s against
entrainment speeds of 10-30 m/s at the reference speed). For an aligned roller under pure
rolling it is exact: then v = Omega_c X x (p - c_r), Omega = Omega_c (the cage speed), and

    u_e = |Omega_r - Omega_c| (R_r + g h_c (D - 2 g R_r) / (2 D))

(roller and ring surface speeds at contact height h_c in the cage frame, tests). Omega uses a
safe denominator, so v_C is finite (the roller's own velocity) when p is on the ring axis.

Film. Effective radii along and across u_e from the end surface's principal radii (R_meridian,
R_parallel, the ones the exact Hertz code uses) by Euler's theorem (`entrainment_radii`), with
cos^2 = (u_e . t_m)^2 / (|u_e|^2 + u_eps^2) against the meridian tangent t_m (a smooth choice
that tends to rolling along the parallel circle, R_x = R_parallel, at zero speed); the
ellipticity k is the exact Hertz one inside `minimum_film_thickness`. Viscosity at the inlet
temperature eta = eta_0 exp(-beta_T (T_in - T_0)); alpha_p from the lubricant. The films h_min
and h_c are reported in both friction modes; Lambda = h_min / sigma with the composite rms
roughness sigma of end and flange (`Flange.roughness`).

Friction coefficient. `Bearing.flange_lubrication == "dry"`: the constant mu_f
(`Bearing.flange_traction`, the source paper, docs/model.md 5). "mixed": the load-sharing blend
mu = f_a(Lambda) mu_f + (1 - f_a(Lambda)) kappa(s), s = sqrt(|u|^2 + u_eps^2), of the boundary
coefficient mu_f and the lubricant's full-film traction curve kappa (`mixed_traction_coefficient`),
C-infinity in Lambda and s: mu -> mu_f as Lambda -> 0 and -> kappa(s) for Lambda >> 1 (f_a = 1/82
at Lambda = 3).
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from ..contact import (
    SLIDING_EPS,
    central_film_thickness,
    entrainment_radii,
    entrainment_velocity,
    film_parameter,
    minimum_film_thickness,
    mixed_traction_coefficient,
    safe_norm,
    traction_coefficient,
    viscosity_at_temperature,
)
from ..geometry import Bearing
from ._geometry import FlangeGeometry

Scalar = Float[Array, ""]
Vec3 = Float[Array, "3"]

_AXIS = np.array([1.0, 0.0, 0.0])
_YZ = np.array([0.0, 1.0, 1.0])

#: friction laws of `Bearing.flange_lubrication`
FLANGE_LUBRICATION_MODES = ("dry", "mixed")


class FlangeFilm(eqx.Module):
    """Lubricant film of one roller-end/flange contact (leading batch axes when vmapped)."""

    entrainment_velocity: Float[Array, "*batch 3"]  # u_e, tangential [m/s]
    entrainment_speed: Float[Array, "*batch"]  # |u_e| [m/s]
    radius_x: Float[Array, "*batch"]  # effective radius along u_e [m]
    radius_y: Float[Array, "*batch"]  # across u_e [m]
    viscosity: Float[Array, "*batch"]  # eta at the inlet temperature [Pa s]
    min_film: Float[Array, "*batch"]  # h_min [m] (Hamrock & Dowson 1977)
    central_film: Float[Array, "*batch"]  # h_c [m]
    film_parameter: Float[Array, "*batch"]  # Lambda = h_min / sigma


def contact_point_velocity(
    roller_centre: Vec3, roller_velocity: Vec3, ring_centre: Vec3, ring_velocity: Vec3, contact_point: Vec3
) -> Vec3:
    """Velocity of the contact point, v_C = v + Omega X x (C - p), with the roller's azimuth
    rate Omega = X . ((p - c_r) x (v - v_r)) / |(p - c_r)_YZ|^2 (module docstring: the pose
    relative to the frame turning with the azimuth held fixed; exact for an aligned roller)."""
    p = jnp.asarray(roller_centre)
    v = jnp.asarray(roller_velocity)
    r = (p - jnp.asarray(ring_centre)) * _YZ
    dv = (v - jnp.asarray(ring_velocity)) * _YZ
    r2 = jnp.sum(r * r)
    omega = jnp.cross(r, dv)[0] / jnp.where(r2 > 0, r2, 1.0)
    return v + jnp.cross(omega * _AXIS, jnp.asarray(contact_point) - p)


def flange_film(
    bearing: Bearing,
    geometry: FlangeGeometry,
    load: ArrayLike,
    roller_surface_velocity: Vec3,
    ring_surface_velocity: Vec3,
    contact_velocity: Vec3,
    e_prime: ArrayLike,
) -> FlangeFilm:
    """Entrainment velocity, effective radii, Hamrock-Dowson films and Lambda of one contact.

    u_e = P_t ((v_1(C) + v_2(C))/2 - v_C) (`entrainment_velocity` of the surface velocities
    relative to the contact point); (R_x, R_y) = `entrainment_radii`(R_meridian, R_parallel,
    cos^2 = (u_e . t_m)^2 / (|u_e|^2 + u_eps^2)); h_min, h_c = `minimum_film_thickness`,
    `central_film_thickness`(Q, R_x, R_y, |u_e|, E', eta(T_in), alpha_p); Lambda =
    `film_parameter`(h_min, sigma, 0). Finite with finite gradients at zero load and speed (the
    laws' load floor and speed regularisation; `safe_norm`).

    Args:
        bearing: supplies the lubricant (eta_0, alpha_p, beta_T, T_0, T_in) and sigma.
        geometry: `flange_geometry` of the contact (normal, principal radii, meridian tangent).
        load: normal load Q [N].
        roller_surface_velocity: v_1(C) [m/s], roller material at the contact point.
        ring_surface_velocity: v_2(C) [m/s], ring material at the contact point.
        contact_velocity: v_C [m/s] (`contact_point_velocity`).
        e_prime: E' [Pa] (`flange_effective_modulus`).
    """
    lub = bearing.lubricant
    n = geometry.normal
    v_c = jnp.asarray(contact_velocity)
    u_e = entrainment_velocity(roller_surface_velocity - v_c, ring_surface_velocity - v_c)
    u_e = u_e - jnp.dot(u_e, n) * n
    speed = safe_norm(u_e)
    cos_m = jnp.dot(u_e, geometry.meridian_direction) / jnp.sqrt(jnp.dot(u_e, u_e) + SLIDING_EPS**2)
    r_x, r_y = entrainment_radii(geometry.radius_meridian, geometry.radius_parallel, cos_m)
    eta = viscosity_at_temperature(
        lub.inlet_temperature, lub.viscosity, lub.temperature_viscosity, lub.reference_temperature
    )
    args = (load, r_x, r_y, speed, e_prime, eta, lub.pressure_viscosity)
    h_min = minimum_film_thickness(*args)
    h_c = central_film_thickness(*args)
    return FlangeFilm(
        entrainment_velocity=u_e,
        entrainment_speed=speed,
        radius_x=r_x,
        radius_y=r_y,
        viscosity=eta,
        min_film=h_min,
        central_film=h_c,
        film_parameter=film_parameter(h_min, bearing.flange.roughness, 0.0),
    )


def flange_friction_coefficient(
    bearing: Bearing, film_parameter: ArrayLike, sliding_velocity: Float[ArrayLike, "*batch 3"]
) -> Float[Array, "*batch"]:
    """Friction coefficient of the roller-end/flange contact (module docstring).

    "dry": mu_f. "mixed": f_a(Lambda) mu_f + (1 - f_a(Lambda)) kappa(sqrt(|u|^2 + u_eps^2))
    (`mixed_traction_coefficient`, `traction_coefficient`); the friction force is then
    -mu Q u / sqrt(|u|^2 + u_eps^2) in both modes, i.e. `mixed_traction_force` in "mixed".
    """
    mode = bearing.flange_lubrication
    mu_f = jnp.asarray(bearing.flange_traction)
    lam = jnp.asarray(film_parameter)
    if mode == "dry":
        return jnp.broadcast_to(mu_f, lam.shape)
    if mode != "mixed":
        raise ValueError(f"flange_lubrication = {mode!r}: must be one of {FLANGE_LUBRICATION_MODES}")
    u = jnp.asarray(sliding_velocity)
    s = jnp.sqrt(jnp.sum(u * u, axis=-1) + SLIDING_EPS**2)
    return mixed_traction_coefficient(lam, mu_f, traction_coefficient(s, bearing.lubricant))
