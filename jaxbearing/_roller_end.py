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

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

from ._params import Roller


def end_curvature(roller: Roller) -> Array:
    """kappa = 1/R_end (0 for a flat end)."""
    return 1.0 / roller.end_radius


def _offset_curvature(roller: Roller) -> Array:
    """kappa' = 1/(R_end - R_cor): curvature of the sphere through the corner-tube centres."""
    k = end_curvature(roller)
    return k / (1.0 - k * roller.corner_radius)


def limited_circle_radius(roller: Roller) -> Array:
    """rho_lim = R_ce R_end / (R_end - R_cor): where the arc end meets the corner torus."""
    k = end_curvature(roller)
    return roller.corner_centre_radius / (1.0 - k * roller.corner_radius)


def arc_protrusion(roller: Roller) -> Array:
    """e = R_end - R_cor - sqrt((R_end - R_cor)^2 - R_ce^2): axial protrusion of the arc apex
    beyond the flat end plane x = L_b1/2 (0 for a flat end).

    Written as kappa' R_ce^2 / (1 + sqrt(1 - kappa'^2 R_ce^2)) to avoid cancellation.
    """
    kp = _offset_curvature(roller)
    rce = roller.corner_centre_radius
    return kp * rce**2 / (1.0 + jnp.sqrt(1.0 - (kp * rce) ** 2))


def sag(radius: ArrayLike, curvature: ArrayLike) -> Array:
    """Sagitta of a circle of curvature k at distance r from its axis: k r^2/(1 + sqrt(1-k^2 r^2))."""
    return curvature * radius**2 / (1.0 + jnp.sqrt(1.0 - (curvature * radius) ** 2))


def arc_half_length(roller: Roller, rho: ArrayLike) -> Array:
    """Axial position x(rho) of the spherical end at distance rho from the roller axis
    (rho <= rho_lim): L_b1/2 + e - sag(rho, 1/R_end). For a flat end: L_b1/2."""
    return roller.length / 2 + arc_protrusion(roller) - sag(rho, end_curvature(roller))
