"""General roller-end and rib faces: their parameters, their meridians and their range check
(docs/model.md 5.4).

The roller end is a surface of revolution about the roller axis whose meridian is a circular arc
of radius R_end with its centre offset from the axis by e (e = 0: the sphere of docs/model.md 4;
e > 0: a torus whose centre circle has radius e, the arc centre lying on the same side of the
axis as the contact), meeting the corner radius R_cor tangentially at the limited circle. The
rib (flange) face is a surface of revolution about the ring axis whose meridian is a circular arc
of signed curvature kappa_rib = 1/R_rib, tangent to today's cone (layback angle theta_f, foot at
the raceway edge) at the height h_t above the raceway (kappa_rib = 0: today's cone;
kappa_rib > 0: concave, the arc's centre on the roller side, conforming with the end as the
spherical ribs of tapered roller bearings do, whose rib radius is 1.05-1.18 times the end radius).
The formulas hold for a convex rib (kappa_rib < 0) as well, but `check_faces` rejects it: a
convex rib touches a circle of the end (the corner circle, or the ridge circle of a toroidal end)
at two points once |kappa_rib| rho > sin(alpha) (rho the circle's radius, alpha the normal's angle
from the roller axis), for the reference corner circle already at |R_rib| ~ 120 mm, and a
single-point contact model does not hold there.

Both curvatures are parameters, not radii, so the cone (kappa_rib = 0) and the flat end
(kappa_end = 0) are ordinary values with finite derivatives.

End meridian, measured in the roller's meridian half-plane (axial a from the roller centre,
radius rho from the roller axis), with R_ce = D/2 - R_cor, x_cor = L_b1/2 - R_cor,
kappa' = kappa_end / (1 - kappa_end R_cor) = 1/(R_end - R_cor) (internal tangency of the arc
and the corner circle: their centres are R_end - R_cor apart):

    arc centre      (a_c, e),   a_c = x_cor - sqrt((R_end - R_cor)^2 - (R_ce - e)^2)
    limited circle  rho_lim = e + (R_ce - e) / (1 - kappa_end R_cor)
    protrusion      e_p = sag(R_ce - e, kappa') = a_c + R_end - L_b1/2   (apex at rho = e)

which are docs/model.md 4's formulas with R_ce replaced by R_ce - e and rho shifted by e
(at e = 0 they are those formulas exactly).

Rib meridian, in the ring's plane through the roller's azimuth with coordinates u_n along the
normal into the flange n0 = s cos(theta_f) a - g sin(theta_f) e_rad and u_t up the flange
t0 = g cos(theta_f) e_rad + s sin(theta_f) a, both measured from the tangent point
P_t = P0 + (h_t / cos(theta_f)) t0 (P0 the raceway edge, paper Eq. 8): the arc's centre is
P_t - n0 / kappa_rib, and the signed distance of a point into the rib is, cancellation-free
and exact for every kappa_rib including 0 (`rib_distance`),

    d = (2 u_n + kappa_rib (u_n^2 + u_t^2)) / (1 + S),
    S = sqrt((1 + kappa_rib u_n)^2 + kappa_rib^2 u_t^2),

(d = (S - 1)/kappa_rib = |X - centre| - R_rib for a concave rib; d = u_n for the cone), with the
unit normal grad d = ((1 + kappa_rib u_n) n0 + kappa_rib u_t t0) / S.
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from ..geometry import Bearing, Roller, sag
from ..io import is_concrete, require

Scalar = Float[Array, ""]


def _f(x) -> Array:
    return jnp.asarray(x, dtype=jnp.float64)


class Faces(eqx.Module):
    """The parameters of the general roller-end and rib faces (SI units; docs/model.md 5.4).

    They override the bearing's own R_end, R_cor, theta_f, H_rf and Delta_bf in the face
    functions (`face_contact`, `face_design_zone`); D and L_b1 come from the bearing's roller.
    The central length L_b2 does not enter the end/rib contact. Build one from a bearing with
    `faces_of`; check one with `check_faces`.
    """

    end_curvature: Scalar = eqx.field(converter=_f)  # kappa_end = 1/R_end [1/m] (0: flat end)
    end_offset: Scalar = eqx.field(converter=_f)  # e [m], arc centre from the roller axis
    corner_radius: Scalar = eqx.field(converter=_f)  # R_cor [m]
    layback_angle: Scalar = eqx.field(converter=_f)  # theta_f [rad], rib tangent at its foot
    rib_curvature: Scalar = eqx.field(converter=_f)  # kappa_rib = 1/R_rib [1/m] (0: cone)
    rib_tangent_height: Scalar = eqx.field(converter=_f)  # h_t [m], where the arc touches the cone
    flange_height: Scalar = eqx.field(converter=_f)  # H_rf [m]
    axial_clearance: Scalar = eqx.field(converter=_f)  # Delta_bf [m]

    @property
    def end_radius(self) -> Array:
        """R_end = 1/kappa_end (inf for a flat end)."""
        return 1.0 / self.end_curvature

    @property
    def rib_radius(self) -> Array:
        """R_rib = 1/kappa_rib (inf for the cone; positive concave, negative convex)."""
        return 1.0 / self.rib_curvature


def faces_of(
    bearing: Bearing,
    end_offset: ArrayLike | None = None,
    rib_curvature: ArrayLike | None = None,
    rib_tangent_height: ArrayLike | None = None,
) -> Faces:
    """The faces of `bearing` (its R_end, R_cor, theta_f, H_rf, Delta_bf) with the end offset e
    [m], the rib curvature 1/R_rib [1/m] and the rib's tangent height h_t [m] given; each one
    not given is the bearing's own (`Roller.end_offset`, `Flange.rib_curvature`,
    `Flange.rib_tangent_height`), 0 where the bearing has none (today's sphere or flat end
    against today's cone)."""
    own = (bearing.roller.end_offset, bearing.flange.rib_curvature, bearing.flange.rib_tangent_height)
    given = (end_offset, rib_curvature, rib_tangent_height)
    e, k_rib, h_t = (g if g is not None else (o if o is not None else 0.0) for g, o in zip(given, own))
    return Faces(
        end_curvature=1.0 / bearing.roller.end_radius,
        end_offset=e,
        corner_radius=bearing.roller.corner_radius,
        layback_angle=bearing.flange.layback_angle,
        rib_curvature=k_rib,
        rib_tangent_height=h_t,
        flange_height=bearing.flange.height,
        axial_clearance=bearing.flange.axial_clearance,
    )


# -- end meridian ------------------------------------------------------------------------------
def corner_centre_radius(roller: Roller, faces: Faces) -> Array:
    """R_ce = D/2 - R_cor: radius of the corner circle's centre circle."""
    return roller.diameter / 2 - faces.corner_radius


def corner_centre_offset(roller: Roller, faces: Faces) -> Array:
    """x_cor = L_b1/2 - R_cor: axial position of the corner centre circle."""
    return roller.length / 2 - faces.corner_radius


def face_limited_circle(roller: Roller, faces: Faces) -> Array:
    """rho_lim = e + (R_ce - e) / (1 - kappa_end R_cor): where the end arc meets the corner."""
    k, e = faces.end_curvature, faces.end_offset
    return e + (corner_centre_radius(roller, faces) - e) / (1.0 - k * faces.corner_radius)


def face_protrusion(roller: Roller, faces: Faces) -> Array:
    """e_p = sag(R_ce - e, 1/(R_end - R_cor)): axial protrusion of the arc's apex (at rho = e)
    beyond the flat end plane a = L_b1/2 (0 for a flat end)."""
    k = faces.end_curvature
    k_offset = k / (1.0 - k * faces.corner_radius)
    return sag(corner_centre_radius(roller, faces) - faces.end_offset, k_offset)


# -- rib meridian ------------------------------------------------------------------------------
def rib_distance(u_n: ArrayLike, u_t: ArrayLike, rib_curvature: ArrayLike) -> tuple[Array, Array, Array]:
    """(d, g_n, g_t): signed distance into the rib of the point (u_n, u_t) of the rib's meridian
    plane (module docstring) and its unit gradient (g_n, g_t) along (n0, t0).

    d = (2 u_n + k (u_n^2 + u_t^2)) / (1 + S), S = sqrt((1 + k u_n)^2 + k^2 u_t^2): the exact
    distance to the circle of curvature k tangent to the u_t axis at the origin (to the line
    u_n = 0 for k = 0), positive on the rib's side; valid while S > 0 (the point is not the
    circle's centre)."""
    k = jnp.asarray(rib_curvature)
    s = jnp.sqrt((1.0 + k * u_n) ** 2 + (k * u_t) ** 2)
    d = (2.0 * u_n + k * (u_n**2 + u_t**2)) / (1.0 + s)
    return d, (1.0 + k * u_n) / s, k * u_t / s


# -- range check -------------------------------------------------------------------------------
def _value(x) -> float:
    return float(np.max(np.asarray(x, dtype=float)))


def check_faces(faces: Faces, bearing: Bearing) -> None:
    """Raise a one-line `UserInputError` (parameter, value, valid range) for faces that do not
    make a contact geometry with `bearing`'s roller; traced values pass (check outside `jit`).

    R_end > D/2 (kappa_end in [0, 2/D)); 0 < R_cor < D/2; 0 <= e < R_ce and e < R_end; theta_f
    in [0, 45) deg; 0 <= kappa_rib < kappa_end (a cone or a concave rib with R_rib > R_end: the
    curvature sum along the meridian, kappa_end - kappa_rib, must be positive; for a flat end
    kappa_rib < 1/R_cor; convex ribs are excluded, module docstring); 0 <= h_t <= H_rf;
    H_rf > 0; Delta_bf >= 0."""
    leaves = (faces, bearing.roller.diameter)
    if not is_concrete(*leaves):
        return
    d = _value(bearing.roller.diameter)
    require(
        "faces.end_curvature",
        faces.end_curvature,
        lambda v: (v >= 0) & (v < 2 / d),
        f"in [0, 2/D = {2 / d:g}) 1/m (R_end > D/2; 0 for flat ends)",
    )
    require(
        "faces.corner_radius",
        faces.corner_radius,
        lambda v: (v > 0) & (v < d / 2),
        f"in (0, D/2 = {d / 2:g}) m",
    )
    r_ce = d / 2 - _value(faces.corner_radius)
    require(
        "faces.end_offset",
        faces.end_offset,
        lambda v: (v >= 0) & (v < r_ce),
        f"in [0, R_ce = D/2 - R_cor = {r_ce:g}) m",
    )
    r_end = 1.0 / _value(faces.end_curvature) if _value(faces.end_curvature) > 0 else np.inf
    require("faces.end_offset", faces.end_offset, lambda v: v < r_end, f"< R_end = {r_end:g} m")
    require(
        "faces.layback_angle",
        faces.layback_angle,
        lambda v: (v >= 0) & (v < np.pi / 4),
        "in [0, 45) deg (radians inside the code)",
    )
    require("faces.flange_height", faces.flange_height, lambda v: v > 0, "> 0 m")
    k_end = _value(faces.end_curvature)
    upper = k_end if k_end > 0 else 1.0 / _value(faces.corner_radius)
    require(
        "faces.rib_curvature",
        faces.rib_curvature,
        lambda v: (v >= 0) & (v < upper),
        f"in [0, {upper:g}) 1/m (1/R_rib: 0 the cone, positive a concave rib with R_rib > R_end)",
    )
    h_rf = _value(faces.flange_height)
    require(
        "faces.rib_tangent_height",
        faces.rib_tangent_height,
        lambda v: (v >= 0) & (v <= h_rf),
        f"in [0, H_rf = {h_rf:g}] m",
    )
    require("faces.axial_clearance", faces.axial_clearance, lambda v: v >= 0, ">= 0 m")
