"""Design zone of the roller end and flange (the paper's Section 3.4 and Figure 14).

For an aligned roller in pure rolling (no skew, no tilt) the flange contact geometry depends on
the design only: the arc end (radius R_end) touches a flange laid back by theta_f at the radius
rho_c = R_end sin(theta_f) from the roller axis, i.e. at the contact height h_c = D/2 - rho_c
above the raceway, as long as rho_c stays inside the limited circle rho_lim; beyond it the corner
touches at rho_c = R_ce + R_cor sin(theta_f) (docs/model.md 5). A design is feasible when

- the contact stays below the upper contact-height limit: h_up - h_c > 0;
- the edge of the contact ellipse stays above the flange base relief (undercut) at the given
  flange load: h_c - a_t - h_rel > 0, with a_t the ellipse half-width along the flange height;
- the contact is on the arc end, not on the corner: rho_lim - rho_c > 0;
- the actual axial clearance Lambda_bf = Delta_bf - 2 e cos(theta_f) stays positive (or above a
  required minimum): the arc apex of each end protrudes e = R_end - R_cor
  - sqrt((R_end - R_cor)^2 - R_ce^2) beyond the flat end plane (paper Eq. 24), e cos(theta_f)
  measured along the flange normal, once on each side (docs/model.md 5). This is the paper's
  conservative criterion: the true gap along the normals of an aligned, centred roller seated on
  the raceway (`seated_gap`) is larger, because the laid-back flange opens away from the roller
  above the raceway edge.

Every quantity is computed through the same support-function contact code the dynamics uses
(`jaxbearing.flange`), at the aligned pose, so it is differentiable in every design parameter and
vmappable over designs (`design_zone_grid`).
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Bool, Float

from ..contact import point_contact_ellipse
from ..geometry import Bearing, end_support, limited_circle_radius
from ._checks import DEFAULT_FLANGE_LOAD, check_design
from ._design import DesignVariables, with_design
from ._face_zone import face_design_zone
from ._faces import faces_of
from ._geometry import flange_effective_modulus, flange_geometry
from ._margins import zone_margin_fields


class DesignZone(eqx.Module):
    """Contact geometry of an aligned roller against its flange, and the design margins
    (positive = feasible). Lengths in m; leading batch axes when computed over a grid."""

    contact_radius: Float[Array, "*batch"]  # rho_c of the actual contact (arc end if it reaches)
    corner_contact_radius: Float[Array, "*batch"]  # same roller with flat ends: R_ce + R_cor sin
    contact_height: Float[Array, "*batch"]  # h_c = D/2 - rho_c
    limited_circle_radius: Float[Array, "*batch"]  # rho_lim
    arc_protrusion: Float[Array, "*batch"]  # e, axial protrusion of the arc apex
    actual_axial_clearance: Float[Array, "*batch"]  # Lambda_bf = Delta_bf - 2 e cos(theta_f)
    seated_gap: Float[Array, "*batch"]  # total gap along the normals, aligned centred roller
    ellipse_half_width: Float[Array, "*batch"]  # a_t, along the flange height, at flange_load
    on_arc: Float[Array, "*batch"]  # 1 arc, 0 corner (smooth weight of the contact)
    relief_margin: Float[Array, "*batch"]  # h_c - a_t - h_rel
    height_margin: Float[Array, "*batch"]  # h_up - h_c
    limited_circle_margin: Float[Array, "*batch"]  # rho_lim - rho_c
    clearance_margin: Float[Array, "*batch"]  # Lambda_bf - min_clearance
    feasible: Bool[Array, "*batch"]  # every margin > 0


def design_zone(
    bearing: Bearing,
    flange_load: ArrayLike = DEFAULT_FLANGE_LOAD,
    min_clearance: ArrayLike = 0.0,
) -> DesignZone:
    """Design zone quantities of `bearing` for an aligned roller in pure rolling.

    The roller sits on the inner raceway, axis along X, centred axially; the contact with the
    flange at +X is evaluated by `jaxbearing.flange` (support function of the end body), the
    corner contact by the same code with flat ends, the arc protrusion e by the support function
    along the roller axis, e = h(x) - L_b1/2. The contact-ellipse half-width along the flange
    height comes from the exact Hertz solution (`jaxbearing.contact`) with
    the principal radii at the contact point and the normal load `flange_load` (N).
    `min_clearance` (m) is the required actual axial clearance.

    A bearing with general faces (`Bearing.has_general_faces`) gets `face_design_zone` of its
    own faces (`faces_of`): the same fields and more (`FaceZone`).
    """
    check_design(bearing, flange_load=flange_load, min_clearance=min_clearance)
    if bearing.has_general_faces:
        return face_design_zone(bearing, faces_of(bearing), flange_load, min_clearance)
    roller = bearing.roller
    theta = bearing.flange.layback_angle
    radius = bearing.inner_raceway_radius
    x = jnp.array([1.0, 0.0, 0.0])
    centre = jnp.array([0.0, 0.0, 1.0]) * (radius + roller.diameter / 2)
    ring = jnp.zeros(3)

    geo = flange_geometry(bearing, radius, 1.0, 1.0, centre, x, ring)
    corner = flange_geometry(bearing.with_flat_ends(), radius, 1.0, 1.0, centre, x, ring)
    h_axis, _, _ = end_support(roller, jnp.asarray(1.0), jnp.asarray(0.0))
    protrusion = h_axis - roller.length / 2
    clearance = bearing.flange.axial_clearance - 2 * protrusion * jnp.cos(theta)
    half_width, _ = point_contact_ellipse(
        jnp.asarray(flange_load, dtype=float),
        geo.radius_meridian,
        geo.radius_parallel,
        flange_effective_modulus(bearing),
    )
    rho_lim = limited_circle_radius(roller)
    return DesignZone(
        contact_radius=geo.contact_radius,
        corner_contact_radius=corner.contact_radius,
        contact_height=geo.contact_height,
        limited_circle_radius=rho_lim,
        arc_protrusion=protrusion,
        actual_axial_clearance=clearance,
        seated_gap=-2 * geo.interference,
        ellipse_half_width=half_width,
        on_arc=geo.on_arc,
        **zone_margin_fields(
            bearing.flange,
            geo.contact_height,
            half_width,
            rho_lim,
            geo.contact_radius,
            clearance,
            min_clearance,
        ),
    )


@eqx.filter_jit
def _grid(bearing, r_end, theta, clearance, flange_load, min_clearance):
    def one(r, t, c):
        return design_zone(with_design(bearing, r, t, c), flange_load, min_clearance)

    return jax.vmap(one)(r_end, theta, clearance)


def design_zone_grid(
    bearing: Bearing,
    end_radius: ArrayLike,
    layback_angle: ArrayLike,
    axial_clearance: ArrayLike,
    flange_load: ArrayLike = DEFAULT_FLANGE_LOAD,
    min_clearance: ArrayLike = 0.0,
) -> DesignZone:
    """`design_zone` over broadcast arrays of designs (R_end in m, theta_f in rad, Delta_bf in m),
    in one jit-compiled vmap. Returns a DesignZone whose fields have the broadcast shape."""
    r, t, c = jnp.broadcast_arrays(
        jnp.asarray(end_radius, float),
        jnp.asarray(layback_angle, float),
        jnp.asarray(axial_clearance, float),
    )
    check_design(with_design(bearing, r, t, c), flange_load=flange_load, min_clearance=min_clearance)
    shape = r.shape
    out = _grid(bearing, r.ravel(), t.ravel(), c.ravel(), flange_load, min_clearance)
    return jax.tree_util.tree_map(lambda x: x.reshape(shape + x.shape[1:]), out)


MARGIN_NAMES = ("relief", "height", "limited_circle", "clearance")


def zone_margins(
    bearing: Bearing,
    design: DesignVariables,
    *,
    flange_load: ArrayLike = DEFAULT_FLANGE_LOAD,
    min_clearance: ArrayLike = 0.0,
) -> Float[Array, 4]:
    """The four design-zone margins [m] of `design` (`jaxbearing.design_zone`): relief
    h_c - a_t - h_rel, height h_up - h_c, limited circle rho_lim - rho_c, clearance
    Lambda_bf - Lambda_min. Cheap (no dynamics); differentiable and vmappable."""
    z = design_zone(design.apply(bearing), flange_load, min_clearance)
    return jnp.stack([z.relief_margin, z.height_margin, z.limited_circle_margin, z.clearance_margin])
