"""Static design zone of the general roller-end and rib faces (docs/model.md 5.4), with the
meanings of `design_zone` (docs/model.md 6) for today's faces.

The aligned roller seated on the inner raceway (centre at R_i + D/2 along Z, axis X, axially
centred) against the +X inner rib, evaluated by `face_contact`, so every quantity is
differentiable in every face parameter. Margins (positive = feasible):

    relief          h_c - a_t - h_rel        a_t: Hertz half-width along the end meridian
    height          h_up - h_c
    limited circle  rho_lim - rho_c          rho_lim = e + (R_ce - e)/(1 - R_cor/R_end)
    clearance       Lambda_bf - Lambda_min,  Lambda_bf = Delta_bf - 2 e_p cos(theta_f)

with e_p the protrusion of the arc's apex (at rho = e) beyond the flat end plane, the paper's
conservative Eq. 24 criterion as for today's faces. h_rel and h_up are the bearing's flange
relief and upper contact-height limit. The flange-height margin H_rf - h_c (the contact on the
rib face, not on the arc continued above it) is reported beside them; h_up < H_rf makes it
redundant for the usual limits, so it is not part of `feasible`, as in `design_zone`.

For the aligned roller the rib's meridian and the end's meridian lie in the same plane, so the
relative curvature is diagonal in the end's frame (A12 = 0): the Hertz radii along the flange
height and along the parallel are 1/A11 and 1/A22.
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Bool, Float

from ..contact import point_contact_ellipse
from ..geometry import Bearing
from ..io import require
from ._checks import DEFAULT_FLANGE_LOAD
from ._face_contact import face_contact
from ._faces import Faces, check_faces, face_limited_circle, face_protrusion
from ._geometry import flange_effective_modulus
from ._margins import zone_margin_fields


class FaceZone(eqx.Module):
    """Contact geometry of an aligned roller against its rib for general faces, and the design
    margins (positive = feasible). Lengths in m; leading batch axes when vmapped."""

    contact_radius: Float[Array, "*batch"]  # rho_c
    corner_contact_radius: Float[Array, "*batch"]  # the same roller with flat ends (corner only)
    contact_height: Float[Array, "*batch"]  # h_c = D/2 - rho_c
    limited_circle_radius: Float[Array, "*batch"]  # rho_lim
    arc_protrusion: Float[Array, "*batch"]  # e_p
    actual_axial_clearance: Float[Array, "*batch"]  # Lambda_bf = Delta_bf - 2 e_p cos(theta_f)
    seated_gap: Float[Array, "*batch"]  # -2 delta, total gap along the normals
    ellipse_half_width: Float[Array, "*batch"]  # a_t along the end meridian at flange_load
    curvature_sums: Float[Array, "*batch 2"]  # (A11, A22): along the meridian, along the parallel
    on_arc: Float[Array, "*batch"]  # 1 arc, 0 corner
    relief_margin: Float[Array, "*batch"]
    height_margin: Float[Array, "*batch"]
    limited_circle_margin: Float[Array, "*batch"]
    clearance_margin: Float[Array, "*batch"]
    flange_height_margin: Float[Array, "*batch"]  # H_rf - h_c (reported, not in `feasible`)
    feasible: Bool[Array, "*batch"]  # relief, height, limited circle and clearance margins > 0


def face_design_zone(
    bearing: Bearing,
    faces: Faces,
    flange_load: ArrayLike = DEFAULT_FLANGE_LOAD,
    min_clearance: ArrayLike = 0.0,
) -> FaceZone:
    """Design zone quantities of the faces `faces` on `bearing` for an aligned roller (module
    docstring); `flange_load` (N) sets the contact-ellipse half-width, `min_clearance` (m) the
    required actual axial clearance. Checks its inputs (`check_faces`) when they are concrete."""
    check_faces(faces, bearing)
    require("flange_load", flange_load, lambda v: v > 0, "> 0 N")
    require("min_clearance", min_clearance, np.isfinite, "finite (m)")
    roller = bearing.roller
    radius = bearing.inner_raceway_radius
    x = jnp.array([1.0, 0.0, 0.0])
    centre = jnp.array([0.0, 0.0, 1.0]) * (radius + roller.diameter / 2)
    ring = jnp.zeros(3)
    c = face_contact(bearing, faces, radius, 1.0, 1.0, centre, x, ring)
    protrusion = face_protrusion(roller, faces)
    clearance = faces.axial_clearance - 2 * protrusion * jnp.cos(faces.layback_angle)
    a11, a22 = c.relative_curvature[0], c.relative_curvature[2]
    half_width, _ = point_contact_ellipse(
        jnp.asarray(flange_load, dtype=float), 1.0 / a11, 1.0 / a22, flange_effective_modulus(bearing)
    )
    rho_lim = face_limited_circle(roller, faces)
    return FaceZone(
        contact_radius=c.contact_radius,
        corner_contact_radius=c.corner_contact_radius,
        contact_height=c.contact_height,
        limited_circle_radius=rho_lim,
        arc_protrusion=protrusion,
        actual_axial_clearance=clearance,
        seated_gap=-2 * c.interference,
        ellipse_half_width=half_width,
        curvature_sums=jnp.stack([a11, a22]),
        on_arc=c.on_arc,
        flange_height_margin=faces.flange_height - c.contact_height,
        **zone_margin_fields(
            bearing.flange, c.contact_height, half_width, rho_lim, c.contact_radius, clearance, min_clearance
        ),
    )
