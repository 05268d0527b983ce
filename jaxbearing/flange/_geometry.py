"""Flange face and roller-end pose: the pose-only part of the roller-end/flange contact.

`flange_geometry` places the flange face (its tangent plane at the roller's azimuth, MODEL.md
4.1), finds the extreme point of the roller end body in the direction of the flange normal
(`jaxbearing.geometry.end_support`), and returns the interference, the contact point, its height
above the raceway, its position on the end face and the principal radii of the active end
surface. It is shared by the dynamic contact (`roller_flange_contact`) and the static design
zone (`design_zone`).
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
    """
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
    )


def flange_effective_modulus(bearing: Bearing) -> Array:
    """E' of the roller (roller material) against a ring flange (ring material)."""
    r, g = bearing.roller_material, bearing.ring_material
    return effective_modulus(r.elastic_modulus, r.poisson_ratio, g.elastic_modulus, g.poisson_ratio)
