"""The pose-only flange geometry of a bearing with general faces, in the form the dynamic contact
uses (`FlangeGeometry`), and the structural switch between today's faces and the general ones
(docs/model.md 5.4).

`contact_geometry` is what `roller_flange_contact` calls. A bearing whose face parameters are all
None (`Bearing.has_general_faces` False: the reference bearing, every bearing built before the
general faces existed) gets `flange_geometry`, traced exactly as before, so its numbers are the
same bit for bit. A bearing with any of them set (`Roller.end_offset`, `Flange.rib_curvature`,
`Flange.rib_tangent_height`; a missing one counts as 0) gets `face_flange_geometry`: the deepest
point of the end in the rib (`face_contact`) with its interference, normal and contact point,
and the Hertz radii from the relative curvature of the two faces.

Hertz radii and their directions. The relative curvature is the 2 x 2 form A = ((A11, A12),
(A12, A22)) in the end's frame (meridian t_E, parallel p_E) (`FaceContact.relative_curvature`);
its eigenvalues are the curvature sums of the exact Hertz law (Johnson, Contact Mechanics, 1985,
sec. 2.1). The film needs them with their directions (Euler's theorem along the entrainment,
`entrainment_radii`), so `radius_meridian` is 1/lambda of the eigenvector nearest to t_E,

    tan(2 phi) = 2 A12 / (A11 - A22),  |phi| <= pi/4,  d = cos(phi) t_E + sin(phi) p_E,
    lambda_d = A11 cos^2 + 2 A12 cos sin + A22 sin^2,  lambda_perp = A11 sin^2 - 2 A12 cos sin + A22 cos^2,

`meridian_direction` d and `radius_parallel` 1/lambda_perp. Where A12 = 0 (a cone, or an aligned
roller) phi = 0 exactly: the radii are 1/A11 along the end's meridian and 1/A22 along its
parallel, today's labels. The stiffness and the film are symmetric in the two (radius,
direction) pairs, so the labels' swap where A11 - A22 changes sign with A12 != 0 changes
neither; only which semi-axis of `ellipse_semi_axes` is reported first.
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np
from jaxtyping import ArrayLike

from ..contact import safe_norm
from ..geometry import Bearing
from ._face_contact import face_contact
from ._faces import faces_of
from ._geometry import FlangeGeometry, Vec3, flange_geometry, unit

#: start angles of `face_contact`'s Newton solves in the dynamics (the static functions use
#: `START_ANGLES` = 16; module docstring)
DYNAMIC_START_ANGLES = 4

_AXIS = np.array([1.0, 0.0, 0.0])
_YZ = np.array([0.0, 1.0, 1.0])


def principal_radii(tensor, t_e: Vec3, p_e: Vec3):
    """(1/lambda_d, 1/lambda_perp, d) of the relative curvature `tensor` (A11, A12, A22) in the
    frame (t_E, p_E): the eigen-pair nearest to t_E and the other one (module docstring).
    Finite with finite derivatives where A is a multiple of the identity (a sphere on a cone)."""
    a11, a12, a22 = tensor[0], tensor[1], tensor[2]
    sign = jnp.where(a11 >= a22, 1.0, -1.0)
    x, y = jnp.abs(a11 - a22), 2.0 * a12 * sign  # (cos 2 phi, sin 2 phi) times r, x >= 0
    r = safe_norm(jnp.stack([x, y]))
    ok = r > 0
    r_safe = jnp.where(ok, r, 1.0)
    cos2 = jnp.where(ok, x / r_safe, 1.0)
    sin2 = jnp.where(ok, y / r_safe, 0.0)
    c = jnp.sqrt((1.0 + cos2) / 2.0)  # >= 1/sqrt(2)
    s = sin2 / (2.0 * c)
    lam_d = a11 * c * c + 2.0 * a12 * c * s + a22 * s * s
    lam_p = a11 * s * s - 2.0 * a12 * c * s + a22 * c * c
    return 1.0 / lam_d, 1.0 / lam_p, c * t_e + s * p_e


def face_flange_geometry(
    bearing: Bearing,
    raceway_radius: ArrayLike,
    side: ArrayLike,
    ring_sign: ArrayLike,
    roller_centre: Vec3,
    roller_axis: Vec3,
    ring_centre: Vec3,
    ring_axis: Vec3 | None = None,
) -> FlangeGeometry:
    """`flange_geometry`'s quantities for the bearing's general faces (`faces_of`): normal,
    interference, contact point and height, contact radius and arc weight from `face_contact`;
    Hertz radii and the direction of the first from the relative curvature (`principal_radii`);
    the end-face position, circumferential offset and radial height of C as in
    `flange_geometry`. Arguments as `flange_geometry`."""
    p, c_r = jnp.asarray(roller_centre), jnp.asarray(ring_centre)
    fc = face_contact(
        bearing,
        faces_of(bearing),
        raceway_radius,
        side,
        ring_sign,
        p,
        roller_axis,
        c_r,
        ring_axis,
        starts=DYNAMIC_START_ANGLES,
    )
    a = _AXIS if ring_axis is None else jnp.asarray(ring_axis)
    rel = p - c_r
    e_rad = unit(rel - jnp.dot(rel, a) * a)
    x_end = side * unit(jnp.asarray(roller_axis))
    c = fc.contact_point
    offset = c - p
    z_loc = unit(e_rad - jnp.dot(e_rad, x_end) * x_end)
    y_loc = jnp.cross(z_loc, x_end)
    r_m, r_p, direction = principal_radii(fc.relative_curvature, fc.meridian_direction, fc.parallel_direction)
    rel_c = (c - c_r) * _YZ
    rho_c = safe_norm(rel_c)
    return FlangeGeometry(
        normal=fc.normal,
        interference=fc.interference,
        contact_point=c,
        contact_height=fc.contact_height,
        end_face_position=jnp.stack([jnp.dot(offset, y_loc), jnp.dot(offset, z_loc)]),
        contact_radius=fc.contact_radius,
        on_arc=fc.on_arc,
        radius_meridian=r_m,
        radius_parallel=r_p,
        meridian_direction=direction,
        circumferential_offset=jnp.dot(rel_c, jnp.cross(_AXIS, e_rad)),
        face_error=fc.face_error,
        cone_height=ring_sign * (rho_c - raceway_radius),
    )


def contact_geometry(
    bearing: Bearing,
    raceway_radius: ArrayLike,
    side: ArrayLike,
    ring_sign: ArrayLike,
    roller_centre: Vec3,
    roller_axis: Vec3,
    ring_centre: Vec3,
    ring_axis: Vec3 | None = None,
) -> FlangeGeometry:
    """The flange geometry of `bearing`: `face_flange_geometry` where it has general faces
    (`Bearing.has_general_faces`, decided from the pytree's structure at trace time), otherwise
    today's `flange_geometry`, traced unchanged (module docstring)."""
    geometry = face_flange_geometry if bearing.has_general_faces else flange_geometry
    return geometry(
        bearing, raceway_radius, side, ring_sign, roller_centre, roller_axis, ring_centre, ring_axis
    )
