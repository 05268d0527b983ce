"""Contact of a general roller end with a general rib face: pure, differentiable geometry
(docs/model.md 5.4; the faces and their meridians: `_faces`).

As for today's faces (docs/model.md 5, `flange_geometry`) the rib is replaced by its tangent
surface at the roller's azimuth: the rib meridian (an arc of curvature kappa_rib in the ring's
plane through the roller's azimuth) swept straight along the circumferential direction. For
kappa_rib = 0 that is today's tangent plane; its error is the same `face_error` (docs/model.md
5.2), and its circumferential curvature, sin(theta)/rho about the ring axis, is neglected as
today.

Contact as a union of balls. Near the contact the end body is the union of the balls of radius
R_end centred on the arc's centre circle (radius e about the roller axis, at a_c) and, at the
corner, of the balls of radius R_cor centred on the corner's centre circle (radius R_ce, at
x_cor). The interference of a ball B(Q, R) with the rib is exactly R + d(Q), d the signed
distance into the rib (`rib_distance`), its deepest point Q + R n, n = grad d(Q), because d
grows at unit rate along its own gradient. So each branch is

    delta = R + max over the centre circle of d(Q(phi)),    C = Q* + R n(Q*),

a one-dimensional maximisation in the circle's angle phi: Newton's method on F'(phi) = 0,
`SCOUT_STEPS` steps from each of `START_ANGLES` angles (enough to tell which maximum each start
climbs), then `NEWTON_STEPS` from the deepest of their ends (accuracy `NEWTON_ACCURACY`,
derivatives by implicit differentiation, `jax.lax.custom_root`).
Angles are measured from the direction in which the circle's radius points along the normal at
the circle's centre, so for the cone (d linear) the first start is the root. For e = 0 the arc's
circle is a point (the sphere's centre) and the maximisation is trivial. The end body lies inside
the union of the arc's balls, which makes the arc's result the body's deepest point while it is
on the cap. The arc branch holds while its contact lies inside the
limited circle, sin(alpha) < kappa_end (rho_lim - e), alpha the angle between the normal and the
roller axis (docs/model.md 4's switch with rho shifted by e); at the switch the two branches have
the same contact point and normal, so delta is continuous and C1 in the pose, as today.

Curvatures. The end: kappa_end along its meridian on the arc, and along its parallel circle the
normal curvature sin(alpha)/rho_c = kappa_end sin(alpha)/(kappa_end e + sin(alpha)) (Meusnier;
rho_c = e + R_end sin(alpha)); on the corner 1/R_cor and sin(alpha)/(R_ce + R_cor sin(alpha));
blended across the limited circle exactly as today (`LIMITED_CIRCLE_BAND`, `SIN_ALPHA_FLOOR`).
The rib: -kappa_rib along its meridian (convex positive), 0 along its generator. The principal
directions of the two surfaces differ when the roller is skewed, so the relative curvature is the
sum of the two second fundamental forms in the common tangent plane, written in the end's
principal frame (meridian t_E, parallel p_E); its eigenvalues are the curvature sums of the Hertz
law (Johnson, Contact Mechanics, 1985, sec. 2.1 and 4.2).
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from ..contact import point_contact_stiffness, safe_norm
from ..geometry import LIMITED_CIRCLE_BAND, SIN_ALPHA_FLOOR, Bearing
from ._faces import (
    Faces,
    corner_centre_offset,
    corner_centre_radius,
    face_limited_circle,
    face_protrusion,
    rib_distance,
)
from ._geometry import unit

Scalar = Float[Array, ""]
Vec3 = Float[Array, "3"]

#: Newton steps from each start angle (`_circle_max`): they only have to bring each start into
#: the basin of the maximum it climbs, so the deepest end picks the global one.
SCOUT_STEPS = 3

#: Newton steps from the deepest start's end (`_circle_max`); convergence is quadratic. Three
#: scout steps and five here give the contact of 16 starts with 8 + 8 steps to round-off over the
#: sampled faces and poses below, with tilt and skew up to 40 mrad, from 4 starts as from 16
#: (docs/model.md 5.4; two scout steps pick the wrong maximum there), at 17 rib evaluations
#: from 4 starts against 40 for 8 + 8.
NEWTON_STEPS = 5

#: Stated accuracy [m] of the ball centre on its circle after the Newton steps: the next step
#: times the circle's radius, radius min(|F'/F''|, pi) (reported as `FaceContact.solve_error`). Met over
#: e in [0, 0.9 R_ce], kappa_rib in [0, 0.95 kappa_end], h_t in [0, H_rf], tilt and skew up to
#: 10 mrad, axial offsets of 20 um and all four flanges (tests/test_faces.py, hypothesis-sampled;
#: 10,000 random samples gave at most 5.7e-17 m, docs/model.md 5.4). The contact point is then
#: exact to round-off, the interference (stationary in the angle) by far more.
NEWTON_ACCURACY = 1e-14

_X = np.array([1.0, 0.0, 0.0])

#: start angles of the maximisation over a centre circle (Newton's method runs from each)
START_ANGLES = 16


class FaceContact(eqx.Module):
    """Geometry of one general end/rib contact (lengths m, curvatures 1/m; leading batch axes
    when vmapped). Curvatures are convex positive."""

    normal: Vec3  # n, from the roller into the rib
    interference: Scalar  # delta (negative: gap)
    contact_point: Vec3  # C, deepest point of the end body
    rib_point: Vec3  # C - delta n, on the rib face
    contact_height: Scalar  # g ((C - c_r) . e_rad - R_r)
    contact_radius: Scalar  # rho_c, distance of C from the roller axis
    corner_contact_radius: Scalar  # rho_c of the corner alone (the same roller with flat ends)
    on_arc: Scalar  # 1 arc, 0 corner (smooth weight of the curvature blend)
    end_curvatures: Float[Array, 2]  # end: (along its meridian t_E, along its parallel p_E)
    rib_curvatures: Float[Array, 2]  # rib: (along its meridian, along its generator) = (-kappa_rib, 0)
    meridian_direction: Vec3  # t_E
    parallel_direction: Vec3  # p_E
    relative_curvature: Float[Array, 3]  # (A11, A12, A22) of the summed forms in (t_E, p_E)
    curvature_sums: Float[Array, 2]  # its eigenvalues (larger, smaller): the Hertz 1/R_x, 1/R_y
    top_edge: Scalar  # 1 where C lies above the flange height H_rf
    face_error: Scalar  # tangent-surface error at C, sin(theta_C) (rho_C - (C - c_r) . e_rad)
    solve_error: Float[Array, 2]  # radius |F'/F''| [m]: the next Newton step, (arc, corner)


class _Frame(eqx.Module):
    """The rib's frame at the roller's azimuth and the end's outward axis."""

    axis: Vec3  # a, ring axis
    e_rad: Vec3
    n0: Vec3
    t0: Vec3
    tangent_point: Vec3  # P_t
    x_end: Vec3  # x = s e
    fallback: Vec3  # radial direction of the end plane towards the raceway (for alpha = 0)


def _frame(bearing, faces, raceway_radius, side, ring_sign, p, roller_axis, c_r, ring_axis):
    a = _X if ring_axis is None else jnp.asarray(ring_axis)
    rel = p - c_r
    e_rad = unit(rel - jnp.dot(rel, a) * a)
    theta = faces.layback_angle
    width = bearing.roller.length + faces.axial_clearance
    p0 = c_r + side * (width / 2) * a + raceway_radius * e_rad
    n0 = side * jnp.cos(theta) * a - ring_sign * jnp.sin(theta) * e_rad
    t0 = ring_sign * jnp.cos(theta) * e_rad + side * jnp.sin(theta) * a
    x_end = side * unit(jnp.asarray(roller_axis))
    fallback = unit(-ring_sign * (e_rad - jnp.dot(e_rad, x_end) * x_end))
    p_t = p0 + (faces.rib_tangent_height / jnp.cos(theta)) * t0
    return _Frame(a, e_rad, n0, t0, p_t, x_end, fallback)


def _rib(frame: _Frame, faces: Faces, point: Vec3) -> tuple[Array, Vec3, Array, Vec3]:
    """(d, n, k/S, m): signed distance of `point` into the rib, the rib's unit normal at its foot,
    the curvature factor of d's Hessian, which is (k/S) m m^T with m = the rib's meridian tangent
    perpendicular to n (the distance to a circle of radius |X - centre| = S/|k|)."""
    u = point - frame.tangent_point
    u_n, u_t = jnp.dot(u, frame.n0), jnp.dot(u, frame.t0)
    k = faces.rib_curvature
    d, g_n, g_t = rib_distance(u_n, u_t, k)
    s = jnp.sqrt((1.0 + k * u_n) ** 2 + (k * u_t) ** 2)
    return d, g_n * frame.n0 + g_t * frame.t0, k / s, g_n * frame.t0 - g_t * frame.n0


def _newton(derivatives, steps=None):
    """Safeguarded Newton ascent on F, `derivatives`(phi) = (F', F''): `steps` (default
    `NEWTON_STEPS`) steps F'/|F''| clipped to 0.5 rad (an ascent step on either side of a
    maximum)."""
    steps = NEWTON_STEPS if steps is None else steps

    def solve(_, phi0):
        def step(_, phi):
            g1, g2 = derivatives(phi)
            h = jnp.abs(g2)
            return phi + jnp.clip(g1 / jnp.where(h > 0, h, 1.0), -0.5, 0.5)

        return jax.lax.fori_loop(0, steps, step, phi0)

    return solve


def _tangent_solve(g, y):
    slope = g(1.0)
    return y / jnp.where(slope != 0, slope, 1.0)


def _circle_max(frame: _Frame, faces: Faces, centre: Vec3, radius, starts: int) -> tuple[Vec3, Array]:
    """(Q*, its error): the point of the circle (centre, axis x_end, radius) deepest in the rib,
    and radius min(|F'/F''|, pi) at it, how far one more Newton step would move it [m].

    F(phi) = d(Q(phi)), Q = centre + radius (cos(phi) r0 + sin(phi) s0); F' = grad d . Q',
    F'' = (k/S) (m . Q')^2 - grad d . (Q - centre) (`_rib`). Newton's method runs
    `SCOUT_STEPS` steps from each of `starts` angles, and `NEWTON_STEPS` (with implicit
    derivatives) from the deepest of their ends, so the maximum found is the circle's global
    one even where the depth has two maxima of nearly equal height (a two-point contact, of
    which the model keeps the deeper point)."""
    _, n_c, _, _ = _rib(frame, faces, centre)
    perp = n_c - jnp.dot(n_c, frame.x_end) * frame.x_end
    r0 = jnp.where(safe_norm(perp) > 1e-12, unit(perp), frame.fallback)
    s0 = jnp.cross(frame.x_end, r0)

    def point(phi):
        return centre + radius * (jnp.cos(phi) * r0 + jnp.sin(phi) * s0)

    def derivatives(phi):
        d, n, curv, m = _rib(frame, faces, point(phi))
        dq = radius * (jnp.cos(phi) * s0 - jnp.sin(phi) * r0)
        return jnp.dot(n, dq), curv * jnp.dot(m, dq) ** 2 - jnp.dot(n, point(phi) - centre)

    newton = _newton(derivatives)
    angles = 2 * np.pi * np.arange(starts) / starts
    scout = _newton(derivatives, SCOUT_STEPS)
    roots = jax.vmap(lambda t: scout(None, t))(jnp.asarray(angles))
    depths = jax.vmap(lambda phi: _rib(frame, faces, point(phi))[0])(roots)
    start = jax.lax.stop_gradient(roots[jnp.argmax(depths)])
    phi = jax.lax.custom_root(lambda t: derivatives(t)[0], start, newton, _tangent_solve)
    g1, g2 = derivatives(jax.lax.stop_gradient(phi))
    # the next Newton step in metres along the circle; an angle moves at most pi on a circle
    # (where the circle shrinks to a point, e -> 0, F is flat in phi and the ratio is 0/0)
    angle = jnp.minimum(jnp.abs(g1) / jnp.where(g2 != 0, jnp.abs(g2), 1.0), jnp.pi)
    return point(phi), jax.lax.stop_gradient(radius * angle)


def _branch(frame, faces, centre, radius, ball, starts):
    """(delta, C, n, last Newton step) of the balls of radius `ball` centred on a circle."""
    q, step = _circle_max(frame, faces, centre, radius, starts)
    d, n, _, _ = _rib(frame, faces, q)
    return ball + d, q + ball * n, n, step


def _smoothstep5(t):
    t = jnp.clip(t, 0.0, 1.0)
    return t**3 * (10.0 + t * (-15.0 + 6.0 * t))


def _end_curvatures(roller, faces, sin_a):
    """(k_meridian, k_parallel, w) of the end at normal angle alpha, blended across the limited
    circle as `jaxbearing.geometry.end_principal_curvatures` (rho shifted by e)."""
    k, e, r_cor = faces.end_curvature, faces.end_offset, faces.corner_radius
    pos = k > 0
    k_safe = jnp.where(pos, k, 1.0)
    band = LIMITED_CIRCLE_BAND
    xi = jnp.where(pos, face_limited_circle(roller, faces) - e - sin_a / k_safe, -2.0 * band)
    w = _smoothstep5(1.0 + xi / band)
    sin_floor = jnp.sqrt(sin_a**2 + SIN_ALPHA_FLOOR**2)
    rho_torus = corner_centre_radius(roller, faces) + r_cor * sin_a
    # k sin/(k e + sin) (Meusnier), exactly k at e = 0 and 0 at the crest of a torus (alpha = 0)
    den = k * e + sin_a
    k_par_arc = k - k**2 * e / jnp.where(den > 0, den, 1.0)
    k_m = w * k + (1.0 - w) / r_cor
    k_p = w * k_par_arc + (1.0 - w) * sin_floor / rho_torus
    return k_m, k_p, w


def _relative_curvature(k_m, k_p, n, x_end, fallback, n0, t0, rib_curvature):
    """(t_E, p_E, (A11, A12, A22), (lambda_max, lambda_min)) of the summed curvature forms."""
    cross = jnp.cross(x_end, n)
    p_e = jnp.where(safe_norm(cross) > 1e-12, unit(cross), unit(jnp.cross(x_end, fallback)))
    t_e = jnp.cross(n, p_e)
    m_rib = -jnp.dot(n, t0) * n0 + jnp.dot(n, n0) * t0  # rib meridian tangent, perpendicular to n
    c, s = jnp.dot(m_rib, t_e), jnp.dot(m_rib, p_e)
    a11 = k_m - rib_curvature * c * c
    a22 = k_p - rib_curvature * s * s
    a12 = -rib_curvature * c * s
    mean = (a11 + a22) / 2
    half = safe_norm(jnp.stack([(a11 - a22) / 2, a12]))
    return t_e, p_e, jnp.stack([a11, a12, a22]), jnp.stack([mean + half, mean - half])


def face_contact(
    bearing: Bearing,
    faces: Faces,
    raceway_radius: ArrayLike,
    side: ArrayLike,
    ring_sign: ArrayLike,
    roller_centre: Vec3,
    roller_axis: Vec3,
    ring_centre: Vec3,
    ring_axis: Vec3 | None = None,
    *,
    starts: int = START_ANGLES,
) -> FaceContact:
    """Contact geometry of one general roller end with one general rib face (docs/model.md 5.4).

    Arguments as `flange_geometry` (which it generalises: with e = 0 and kappa_rib = 0 it gives
    the same interference, contact point and curvatures): `raceway_radius` R_r, `side` s = +-1,
    `ring_sign` g = +1 inner / -1 outer ring, roller centre p and axis e (any 3-D pose), ring
    centre c_r and axis a (default X). The face parameters come from `faces` (`Faces`), the
    roller's D and L_b1 from `bearing`. Differentiable in every argument (implicit
    differentiation through the Newton solves); check the faces first with `check_faces`.
    """
    roller = bearing.roller
    p, c_r = jnp.asarray(roller_centre), jnp.asarray(ring_centre)
    fr = _frame(bearing, faces, raceway_radius, side, ring_sign, p, roller_axis, c_r, ring_axis)
    k, e = faces.end_curvature, faces.end_offset
    k_safe = jnp.where(k > 0, k, 1.0)
    r_end = 1.0 / k_safe
    arc_centre = p + (roller.length / 2 + face_protrusion(roller, faces) - r_end) * fr.x_end
    arc = _branch(fr, faces, arc_centre, e, r_end, starts)
    corner_centre = p + corner_centre_offset(roller, faces) * fr.x_end
    r_ce = corner_centre_radius(roller, faces)
    corner = _branch(fr, faces, corner_centre, r_ce, faces.corner_radius, starts)
    sin_arc = safe_norm(arc[2] - jnp.dot(arc[2], fr.x_end) * fr.x_end)
    sin_corner = safe_norm(corner[2] - jnp.dot(corner[2], fr.x_end) * fr.x_end)
    on_arc = sin_arc < k * (face_limited_circle(roller, faces) - e)
    delta, c, n = (jnp.where(on_arc, a, b) for a, b in zip(arc[:3], corner[:3]))
    sin_a = safe_norm(n - jnp.dot(n, fr.x_end) * fr.x_end)
    rho = jnp.where(on_arc, e + sin_a / k_safe, r_ce + faces.corner_radius * sin_a)
    k_m, k_p, w = _end_curvatures(roller, faces, sin_a)
    t_e, p_e, tensor, sums = _relative_curvature(
        k_m, k_p, n, fr.x_end, fr.fallback, fr.n0, fr.t0, faces.rib_curvature
    )
    rel = c - c_r
    rho_ring = safe_norm(rel - jnp.dot(rel, fr.axis) * fr.axis)
    along = jnp.dot(rel, fr.e_rad)
    sin_layback = -ring_sign * jnp.dot(n, fr.e_rad)
    return FaceContact(
        normal=n,
        interference=delta,
        contact_point=c,
        rib_point=c - delta * n,
        contact_height=ring_sign * (along - raceway_radius),
        contact_radius=rho,
        corner_contact_radius=r_ce + faces.corner_radius * sin_corner,
        on_arc=w,
        end_curvatures=jnp.stack([k_m, k_p]),
        rib_curvatures=jnp.stack([-faces.rib_curvature, jnp.zeros_like(k_m)]),
        meridian_direction=t_e,
        parallel_direction=p_e,
        relative_curvature=tensor,
        curvature_sums=sums,
        top_edge=jnp.where(ring_sign * (rho_ring - raceway_radius) > faces.flange_height, 1.0, 0.0),
        face_error=sin_layback * (rho_ring - along),
        solve_error=jnp.stack([arc[3], corner[3]]),
    )


def face_contact_stiffness(contact: FaceContact, e_prime: ArrayLike) -> Array:
    """Hertz stiffness K_s [N/m^1.5] of `contact` (Q = K_s delta^1.5): the model's exact point
    contact law (`jaxbearing.contact.point_contact_stiffness`, docs/model.md 7.1) with the
    principal relative radii 1/lambda of `contact.curvature_sums` and the effective modulus E'."""
    sums = contact.curvature_sums
    return point_contact_stiffness(1.0 / sums[..., 0], 1.0 / sums[..., 1], e_prime)
