"""Geometry of the roller end body: corner torus and, for arc ends, a spherical cap.

The end is the convex body of revolution made of a corner torus (tube radius R_cor, centre circle
of radius R_ce = D/2 - R_cor at x_cor = L_b1/2 - R_cor) and, for an arc end, a spherical cap of
radius R_end centred on the roller axis at L_beb = x_cor - sqrt((R_end - R_cor)^2 - R_ce^2)
(paper Eq. 19), tangent to the torus along the limited circle of radius
rho_lim = R_ce R_end / (R_end - R_cor). A flat end is the limit R_end -> inf.

Everything is written in the end curvature kappa = 1/R_end, so that the flat end (kappa = 0) is
an ordinary value with no cancellation of large numbers and finite derivatives.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

if TYPE_CHECKING:  # annotations only: the end body needs no parameter class at run time
    from ._params import Roller


def end_curvature(roller: Roller) -> Array:
    """kappa = 1/R_end (0 for a flat end)."""
    return 1.0 / roller.end_radius


def _offset_curvature(roller: Roller) -> Array:
    """kappa' = 1/(R_end - R_cor): curvature of the sphere through the corner-tube centres."""
    k = end_curvature(roller)
    return k / (1.0 - k * roller.corner_radius)


def limited_circle_radius(roller: Roller) -> Array:
    """rho_lim = R_ce R_end / (R_end - R_cor): where the arc end meets the corner torus; for a
    toroidal end of offset e (`Roller.end_offset` not None) e + (R_ce - e) R_end / (R_end - R_cor)
    (docs/model.md 5.4: R_ce replaced by R_ce - e, rho shifted by e)."""
    k = end_curvature(roller)
    if roller.end_offset is None:
        return roller.corner_centre_radius / (1.0 - k * roller.corner_radius)
    e = roller.end_offset
    return e + (roller.corner_centre_radius - e) / (1.0 - k * roller.corner_radius)


def arc_protrusion(roller: Roller) -> Array:
    """e = R_end - R_cor - sqrt((R_end - R_cor)^2 - R_ce^2): axial protrusion of the arc apex
    beyond the flat end plane x = L_b1/2 (0 for a flat end).

    Written as kappa' R_ce^2 / (1 + sqrt(1 - kappa'^2 R_ce^2)) to avoid cancellation.
    For a toroidal end (`Roller.end_offset` e not None) the apex is the circle rho = e and the
    protrusion sag(R_ce - e, kappa') (docs/model.md 5.4).
    """
    kp = _offset_curvature(roller)
    if roller.end_offset is not None:
        return sag(roller.corner_centre_radius - roller.end_offset, kp)
    rce = roller.corner_centre_radius
    return kp * rce**2 / (1.0 + jnp.sqrt(1.0 - (kp * rce) ** 2))


def sag(radius: ArrayLike, curvature: ArrayLike) -> Array:
    """Sagitta of a circle of curvature k at distance r from its axis: k r^2/(1 + sqrt(1-k^2 r^2))."""
    return curvature * radius**2 / (1.0 + jnp.sqrt(1.0 - (curvature * radius) ** 2))


def arc_half_length(roller: Roller, rho: ArrayLike) -> Array:
    """Axial position x(rho) of the spherical end at distance rho from the roller axis
    (rho <= rho_lim): L_b1/2 + e - sag(rho, 1/R_end). For a flat end: L_b1/2. For a toroidal
    end of offset e_o (`Roller.end_offset`) the arc is centred at rho = e_o: L_b1/2 + e -
    sag(rho - e_o, 1/R_end), which inside the centre circle (rho < e_o) is the arc continued to
    the axis (a central dimple of depth sag(e_o, 1/R_end))."""
    if roller.end_offset is not None:
        rho = rho - roller.end_offset
    return roller.length / 2 + arc_protrusion(roller) - sag(rho, end_curvature(roller))


# -- support function of the end body --------------------------------------------------------
#
# The end body is axisymmetric, so everything below works in the meridian half-plane that
# contains the roller axis x (pointing out of the end, towards the flange) and the plane normal
# n = cos(alpha) x + sin(alpha) r, with r the unit radial direction of the end plane and
# 0 <= alpha <= pi/2. A point of the profile is (axial position a, radius rho) from the roller
# centre; the support function is h(n) = max over the body of (point . n) = a cos(alpha)
# + rho sin(alpha) at the extreme point.

#: Width (m) of the band, measured in the sphere-extrapolated contact radius R_end sin(alpha)
#: just OUTSIDE the limited circle (rho_lim < R_end sin(alpha) < rho_lim + band, i.e. an angle
#: band of band / (R_end cos(alpha)), 6e-5 rad for the reference roller), over which the contact
#: curvature is blended from the sphere to the corner torus (quintic smoothstep). The support
#: function itself is exact; only the Hertz curvature is blended, so that the contact stiffness
#: is C1 where the contact crosses the limited circle. The band lies on the corner side so that
#: every contact on the arc uses the exact sphere curvature (and the design-zone margins stay
#: monotone up to the limited circle); the contact point moves only R_cor * 6e-5 = 0.025 um
#: onto the torus across it.
LIMITED_CIRCLE_BAND = 5e-6

#: Floor on sin(alpha) in the parallel-circle curvature sin(alpha)/rho of the corner torus, so
#: an exactly square-on flat end (alpha = 0, a line contact in the limit) keeps a finite, very
#: long contact ellipse instead of an infinite principal radius. Relative effect at the reference
#: layback angle: 6e-10.
SIN_ALPHA_FLOOR = 1e-6


def end_support(roller: Roller, cos_alpha: ArrayLike, sin_alpha: ArrayLike) -> tuple[Array, Array, Array]:
    """Support function and extreme point of the roller end in the direction
    n = (cos(alpha), sin(alpha)) of the meridian half-plane.

    Sphere branch (arc end, R_end sin(alpha) < rho_lim; paper Eqs. 19-23): the extreme point of
    the sphere of radius R_end centred at L_beb on the axis,
        rho = R_end sin(alpha),   a = L_b1/2 + e - sag(rho, 1/R_end),
    which equals L_beb + R_end cos(alpha) without the cancellation of two ~R_end numbers.
    Torus branch (otherwise; paper Eqs. 2-7 for the corner): the extreme point of the corner
    tube, rho = R_ce + R_cor sin(alpha), a = x_cor + R_cor cos(alpha).
    In both, h = a cos(alpha) + rho sin(alpha) (= L_beb cos(alpha) + R_end on the sphere,
    x_cor cos(alpha) + R_ce sin(alpha) + R_cor on the torus). The two branches meet at the
    limited circle with the same extreme point and the same h, so h is C1 in the direction
    (its gradient is the extreme point) and the extreme point is continuous.

    Written in kappa = 1/R_end with a double `where`: a flat end (kappa = 0) never takes the
    sphere branch, and no branch ever divides by zero, so values and gradients are finite.

    Returns (h, a, rho): the support value, the axial position and the radius of the extreme
    point, all measured from the roller centre.
    """
    k = end_curvature(roller)
    rho_lim = limited_circle_radius(roller)
    on_sphere = sin_alpha < k * rho_lim
    k_safe = jnp.where(on_sphere, k, 1.0)
    rho_sphere = jnp.where(on_sphere, sin_alpha / k_safe, 0.0)
    a_sphere = arc_half_length(roller, rho_sphere)
    rho_torus = roller.corner_centre_radius + roller.corner_radius * sin_alpha
    a_torus = roller.corner_centre_offset + roller.corner_radius * cos_alpha
    a = jnp.where(on_sphere, a_sphere, a_torus)
    rho = jnp.where(on_sphere, rho_sphere, rho_torus)
    return a * cos_alpha + rho * sin_alpha, a, rho


def _smoothstep5(t: Array) -> Array:
    """Quintic smoothstep 6t^5 - 15t^4 + 10t^3 on [0, 1] (C2), clamped outside."""
    t = jnp.clip(t, 0.0, 1.0)
    return t**3 * (10.0 + t * (-15.0 + 6.0 * t))


def arc_weight(roller: Roller, sin_alpha: ArrayLike, band: float = LIMITED_CIRCLE_BAND) -> Array:
    """Smooth weight in [0, 1] of the arc (sphere) curvature at the contact: 1 on the arc (up to
    the limited circle), 0 on the corner beyond R_end sin(alpha) = rho_lim + band, quintic
    smoothstep of 1 + (rho_lim - R_end sin(alpha)) / band in between. Always 0 for a flat end
    (written with a double `where`, no division by kappa = 0)."""
    k = end_curvature(roller)
    pos = k > 0
    rho_arc = sin_alpha / jnp.where(pos, k, 1.0)  # R_end sin(alpha)
    xi = jnp.where(pos, limited_circle_radius(roller) - rho_arc, -2.0 * band)
    return _smoothstep5(1.0 + xi / band)


def end_principal_curvatures(
    roller: Roller, sin_alpha: ArrayLike, band: float = LIMITED_CIRCLE_BAND
) -> tuple[Array, Array, Array]:
    """Principal curvatures of the end surface at the extreme point in direction alpha.

    Sphere: 1/R_end in every direction. Corner torus: 1/R_cor across the corner (meridian) and,
    along the parallel circle of radius rho_c = R_ce + R_cor sin(alpha), the normal curvature
    sin(alpha)/rho_c (Meusnier's theorem: the circle's curvature 1/rho_c times the cosine of the
    angle between its principal normal, -r, and the surface normal n). At the limited circle the
    torus' parallel curvature equals 1/R_end exactly, so only the meridian curvature jumps; both
    are blended with `arc_weight` so the Hertz stiffness is C1 across the limited circle.

    Returns (k_meridian, k_parallel, w) with w the arc weight (1 = arc, 0 = corner).
    """
    k = end_curvature(roller)
    w = arc_weight(roller, sin_alpha, band)
    sin_floor = jnp.sqrt(sin_alpha**2 + SIN_ALPHA_FLOOR**2)
    rho_torus = roller.corner_centre_radius + roller.corner_radius * sin_alpha
    k_meridian = w * k + (1.0 - w) / roller.corner_radius
    k_parallel = w * k + (1.0 - w) * sin_floor / rho_torus
    return k_meridian, k_parallel, w
