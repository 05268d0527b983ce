"""Flange face and roller-end pose: the pose-only part of the roller-end/flange contact.

`flange_geometry` places the flange face (its tangent plane at the roller's azimuth, docs/model.md
5), finds the extreme point of the roller end body in the direction of the flange normal
(`jaxbearing.geometry.end_support`), and returns the interference, the contact point, its height
above the raceway, its position on the end face and the principal radii of the active end
surface. It is shared by the dynamic contact (`roller_flange_contact`) and the static design
zone (`design_zone`).

Error of the tangent plane (docs/model.md 5.2). Write a point Q in cylindrical coordinates
about the ring axis: axial x, radius rho, azimuth psi measured from the roller's azimuth e_rad.
The tangent plane at the roller's azimuth gives the signed distance into the flange

    d_plane(Q) = s cos(theta_f) (x - s W_r/2) - g sin(theta_f) (rho cos(psi) - R_r),

while the flange cone itself, a surface of revolution whose generator in the meridian half-plane
through Q is a straight line with unit normal (s cos(theta_f), -g sin(theta_f)) in (x, rho),
gives EXACTLY (distance to a line in that half-plane, valid while the foot of the perpendicular
lies on the face)

    d_cone(Q)  = s cos(theta_f) (x - s W_r/2) - g sin(theta_f) (rho - R_r).

Hence d_plane - d_cone = g e(Q) with

    e(Q) = sin(theta_f) rho (1 - cos(psi)) = sin(theta_f) s_c^2 / (rho (1 + cos(psi)))
         <= sin(theta_f) s_c^2 / rho     (|psi| <= pi/2),   ~ sin(theta_f) s_c^2 / (2 rho),

s_c = rho sin(psi) the circumferential offset of Q from the roller's azimuth plane. At the
contact point this is `face_error` = sin(theta_f) (rho_C - (C - c_r) . e_rad), computed from the
exact position. For the interference delta = max over the end body of d: the end surface is
(locally) a union of balls, the sphere of radius R_end centred at O on the arc, the balls of
radius R_cor centred on the corner circle on the corner, and along the normal ray from a ball
centre Q either distance grows at exactly unit rate (the ray stays in Q's meridian half-plane,
where the cone is a straight line), so delta = max_Q d(Q) + R. Hence on the arc (while the
cone's contact stays on the cap) delta_plane - delta_cone = g e(O) EXACTLY, O = C - R_end n,
and e(O)/e(C) = rho_C (1 + cos psi_C) / (rho_O (1 + cos psi_O)) ~ 1 -/+ R_end sin(theta_f)/rho
(within 6 % on the reference bearing, the offsets s_c of O and C being equal since n has no
circumferential component). On the corner, 0 <= g (delta_plane - delta_cone) <= e(Q) with Q the
plane's ball centre (g = +1) or the cone's (g = -1), both within R_cor of C. Reference bearing:
rho ~ 40 mm, theta_f = 1.6 deg gives e ~ 0.35 um at s_c = 1 mm and 2.7 um at 2.8 mm (a skew
of 60 mrad, the largest offset of the corner circle); tests/test_flange_lubrication.py checks
the identity at C and the interference against an independently maximised cone distance.
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from ..contact import effective_modulus, safe_norm
from ..geometry import Bearing, end_principal_curvatures, end_support

Scalar = Float[Array, ""]
Vec3 = Float[Array, "3"]

_AXIS = np.array([1.0, 0.0, 0.0])


class FlangeGeometry(eqx.Module):
    """Pose-only part of the contact (no velocities, no load)."""

    normal: Vec3  # n, into the flange
    interference: Scalar
    contact_point: Vec3
    contact_height: Scalar
    end_face_position: Float[Array, 2]
    contact_radius: Scalar
    on_arc: Scalar
    radius_meridian: Scalar  # principal radius of the end across the corner / along t
    radius_parallel: Scalar  # principal radius along the parallel circle
    meridian_direction: Vec3  # unit tangent of the end's meridian at C (0 if alpha = 0)
    circumferential_offset: Scalar  # s_c = (C - c_r) . e_tan, offset of C from the azimuth plane
    face_error: Scalar  # e = sin(theta_f) (rho_C - (C - c_r) . e_rad) >= 0 (module docstring)
    cone_height: Scalar  # g (rho_C - R_r): exact radial height of C above the raceway


def unit(x: Array) -> Array:
    """x / |x| with a safe norm (zero vector -> zero vector, finite gradient)."""
    n = safe_norm(x, axis=-1, keepdims=True)
    return x / jnp.where(n > 0, n, 1.0)


def flange_geometry(
    bearing: Bearing,
    raceway_radius: ArrayLike,
    side: ArrayLike,
    ring_sign: ArrayLike,
    roller_centre: Vec3,
    roller_axis: Vec3,
    ring_centre: Vec3,
    ring_axis: Vec3 | None = None,
) -> FlangeGeometry:
    """Flange tangent plane, interference, contact point and principal radii (pose only);
    shared by `roller_flange_contact` and `jaxbearing.design_zone`.

    The ring's axis is the unit vector `ring_axis` a (default X: the outer ring, an aligned
    inner ring). The flange faces are cones of revolution about a at +-W_r/2 along a from the
    ring centre c_r, so for a tilted or axially displaced ring every ring direction follows a:
    e_rad = unit((p - c_r) - ((p - c_r).a) a) (the roller's radial direction from the ring
    axis), P0 = c_r + s (W_r/2) a + R_r e_rad, n = s cos(theta_f) a - g sin(theta_f) e_rad
    (module docstring of `_contact` with X -> a). With a = X these are exactly the aligned
    formulas.

    Today's faces only (a sphere or flat end against the cone): a bearing with general faces
    (`Bearing.has_general_faces`) is refused with a ValueError; its geometry is
    `face_flange_geometry`.
    """
    if bearing.has_general_faces:
        raise ValueError("flange_geometry: the bearing has general faces; use face_flange_geometry")
    roller = bearing.roller
    theta = bearing.flange.layback_angle
    p = jnp.asarray(roller_centre)
    c_r = jnp.asarray(ring_centre)
    a = _AXIS if ring_axis is None else jnp.asarray(ring_axis)
    # radial direction of the roller's azimuth from the ring axis
    rel = p - c_r
    e_rad = unit(rel - jnp.dot(rel, a) * a)
    # flange tangent plane
    p0 = c_r + side * (bearing.raceway_width / 2) * a + raceway_radius * e_rad
    n = side * jnp.cos(theta) * a - ring_sign * jnp.sin(theta) * e_rad
    # end frame: outward axis x = s e, radial direction r of the contact
    x_end = side * unit(jnp.asarray(roller_axis))
    cos_a = jnp.dot(n, x_end)
    n_perp = n - cos_a * x_end
    sin_a = safe_norm(n_perp)
    r_hat = unit(n_perp)
    h, a, rho = end_support(roller, cos_a, sin_a)
    delta = h - jnp.dot(p0 - p, n)
    offset = a * x_end + rho * r_hat  # C - p
    c = p + offset
    # roller-local end-face frame (x = s e, z = e_rad perpendicular to e, y = z cross x)
    z_loc = unit(e_rad - jnp.dot(e_rad, x_end) * x_end)
    y_loc = jnp.cross(z_loc, x_end)
    yz = jnp.stack([jnp.dot(offset, y_loc), jnp.dot(offset, z_loc)])
    k_m, k_p, w = end_principal_curvatures(roller, sin_a)
    # meridian tangent at C: the end surface's normal there is n, its parallel circle runs
    # along x_end x r_hat (perpendicular to n), the meridian along n x (x_end x r_hat)
    meridian = jnp.cross(n, jnp.cross(x_end, r_hat))
    # exact cylindrical position of C about the ring axis (tangent-plane error, top edge)
    rel = (c - c_r) * jnp.array([0.0, 1.0, 1.0])
    rho_c = safe_norm(rel)
    along = jnp.dot(rel, e_rad)
    e_tan = jnp.cross(_AXIS, e_rad)
    return FlangeGeometry(
        normal=n,
        interference=delta,
        contact_point=c,
        contact_height=ring_sign * (jnp.dot(c - c_r, e_rad) - raceway_radius),
        end_face_position=yz,
        contact_radius=rho,
        on_arc=w,
        radius_meridian=1.0 / k_m,
        radius_parallel=1.0 / k_p,
        meridian_direction=meridian,
        circumferential_offset=jnp.dot(rel, e_tan),
        face_error=jnp.sin(theta) * (rho_c - along),
        cone_height=ring_sign * (rho_c - raceway_radius),
    )


def flange_effective_modulus(bearing: Bearing) -> Array:
    """E' of the roller (roller material) against a ring flange (ring material)."""
    r, g = bearing.roller_material, bearing.ring_material
    return effective_modulus(r.elastic_modulus, r.poisson_ratio, g.elastic_modulus, g.poisson_ratio)
