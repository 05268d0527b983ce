"""Roller end against ring flange: contact geometry, kinematics, Hertz force, PV (docs/model.md 5).

One function, `roller_flange_contact`, handles one roller against one flange for every kind of
roller end: flat ends with corner radii (R_end = inf), arc (spherical) ends, and the switch from
arc to corner at the limited circle. It is the support-function form of the paper's Eqs. 2-12
(corner) and 19-26 (arc end): the contact point is the extreme point of the convex end body in
the direction of the flange normal, the interference is the support value minus the distance of
the flange plane from the roller centre.

Frames (all vectors are 3-vectors in the inertial frame; X = bearing axis, Z = radial load):

- ring r with centre c_r, raceway radius R_r, ring_sign g = +1 (inner ring, flange rises
  radially outward) or -1 (outer ring, flange rises inward); flange side s in {-1, +1};
- e_rad: unit radial direction from the ring axis to the roller centre (Y, Z components of
  p - c_r, normalised);
- the flange cone is replaced by its tangent plane at the roller's azimuth (its circumferential
  radius of curvature, R_r / sin(theta_f), is over a metre), through
  P0 = c_r + s (W_r/2) X + R_r e_rad, W_r = L_b1 + Delta_bf (paper Eq. 8), with
  "up the flange" direction t = g e_rad cos(theta_f) + s X sin(theta_f) and unit normal into
  the flange n = s X cos(theta_f) - g e_rad sin(theta_f);
- the roller end facing the flange is the one at +s along the roller axis e; its outward axis is
  x = s e, cos(alpha) = n . x, and r = (n - cos(alpha) x)/sin(alpha) is the radial direction of
  the end plane towards the contact.

Roller-local end-face coordinates (`end_face_position`): x = s e, z = e_rad made perpendicular to
e (so z points away from the ring axis, towards the outer ring), y = z cross x. An aligned
roller touches an inner-ring flange at z = -rho (the raceway side) and an outer-ring flange at
z = +rho.

Contact height (`contact_height`) is the height of the contact point above the raceway surface,
measured radially in the flange's tangent plane: g ((C - c_r) . e_rad - R_r). For an aligned
roller it is exactly D/2 - rho (docs/model.md 5 oracle); the slant distance along the flange face,
(C - P0) . t, differs from it by the factor cos(theta_f) (4e-4 at 1.6 deg).

Smoothness. The support function is C1 in the pose, so the interference and the normal force
are C1; the Hertz curvature is blended across the limited circle
(`jaxbearing._roller_end.LIMITED_CIRCLE_BAND`), so the stiffness is C1 as well. The contact
point itself is the exact extreme point: continuous, but its rate of change jumps from R_end to
R_cor per radian of the normal where it crosses the limited circle, so the moment arm (and the
moments) are C0 with a kink there.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from ..contact import (
    HUNT_CROSSLEY_ALPHA,
    PENETRATION_WIDTH,
    SLIDING_EPS,
    hertz_force,
    hunt_crossley_factor,
    point_contact_ellipse,
    point_contact_peak_pressure,
    point_contact_stiffness,
    safe_norm,
    smooth_direction,
)
from ..geometry import Bearing
from ._face_geometry import contact_geometry
from ._geometry import flange_effective_modulus
from ._lubrication import contact_point_velocity, flange_film, flange_friction_coefficient

Scalar = Float[Array, ""]
Vec3 = Float[Array, "3"]


class FlangeContact(eqx.Module):
    """Result of one roller-end/flange contact (leading batch axes when vmapped).

    Forces in N, moments in N m (about the roller centre / the ring centre), lengths in m,
    velocities in m/s, pressures in Pa, PV in Pa m/s. `ellipse_semi_axes` are the Hertz
    semi-axes along the end surface's meridian direction (which is the flange height direction
    t for an aligned roller; across the corner on a corner contact) and along its parallel
    circle (circumferential on the roller end).
    """

    interference: Float[Array, "*batch"]  # delta = h(n) - (P0 - p) . n  (negative: gap)
    normal_force: Float[Array, "*batch"]  # Q = K delta^1.5 (softplus-smoothed)
    peak_pressure: Float[Array, "*batch"]  # p_max = 3 Q / (2 pi a b)
    sliding_velocity: Float[Array, "*batch 3"]  # u, tangential part (paper Eqs. 12/26)
    sliding_speed: Float[Array, "*batch"]  # |u|, material sliding speed (the default)
    roller_surface_speed: Float[Array, "*batch"]  # |w x (C - p)| tangential: the paper's Fig. 7c
    approach_rate: Float[Array, "*batch"]  # d(delta)/dt, positive while closing in
    pv: Float[Array, "*batch"]  # p_max |u|
    contact_point: Float[Array, "*batch 3"]  # C, extreme point of the end body
    contact_height: Float[Array, "*batch"]  # h_c above the raceway surface
    end_face_position: Float[Array, "*batch 2"]  # (y, z) of C in the roller-local end frame
    contact_radius: Float[Array, "*batch"]  # rho_c, distance of C from the roller axis
    on_arc: Float[Array, "*batch"]  # 1 on the arc end, 0 on the corner (smooth)
    force_on_roller: Float[Array, "*batch 3"]  # F = -Q n + F_t
    moment_on_roller: Float[Array, "*batch 3"]  # (C - p) x F
    force_on_ring: Float[Array, "*batch 3"]  # -F
    moment_on_ring: Float[Array, "*batch 3"]  # (C - c_r) x (-F)
    ellipse_semi_axes: Float[Array, "*batch 2"]  # (along t / the end meridian, along the parallel)
    entrainment_speed: Float[Array, "*batch"]  # |u_e|, mean surface speed relative to C
    # u_e, tangential: the surfaces move at u_e +/- u/2 relative to C (`flange_heat_source_speeds`)
    entrainment_velocity: Float[Array, "*batch 3"]
    min_film: Float[Array, "*batch"]  # h_min, Hamrock-Dowson minimum film [m]
    central_film: Float[Array, "*batch"]  # h_c, Hamrock-Dowson central film [m]
    film_parameter: Float[Array, "*batch"]  # Lambda = h_min / sigma
    friction_coefficient: Float[Array, "*batch"]  # mu of the friction force (dry or mixed)
    top_edge: Float[Array, "*batch"]  # 1 where C lies above the flange height H_rf, else 0
    face_error: Float[Array, "*batch"]  # tangent-plane error at C, sin(theta_f) rho (1 - cos psi)


def _flange_sliding(
    n, c, p, c_r, roller_velocity, roller_angular_velocity, ring_velocity, ring_angular_velocity
):
    """(v_roller(C), v_ring(C), u, d(delta)/dt, |u|, roller surface speed) at the flange contact
    point C with normal n (from the roller into the flange), roller centre p, ring centre c_r.

    Sliding velocity (paper Eqs. 12 and 26): u = (v + w x (C - p)) - (v_r + w_r x (C - c_r)),
    minus its component along n: the material sliding velocity, from which PV is formed; the
    component along n is the approach rate d(delta)/dt. The paper's Figure 7c ranks corner
    contacts as sliding faster than arc contacts, which is what the roller's own surface speed at
    the contact, |w x (C - p)| (tangential part; the flange's motion ignored), gives: reported as
    `roller_surface_speed`, never used in PV."""
    v_roller = roller_velocity + jnp.cross(roller_angular_velocity, c - p)
    v_ring = ring_velocity + jnp.cross(ring_angular_velocity, c - c_r)
    u = v_roller - v_ring
    approach_rate = jnp.dot(u, n)  # n points from the roller into the flange
    u = u - approach_rate * n
    speed = safe_norm(u)
    spin_surface = jnp.cross(roller_angular_velocity, c - p)
    surface_speed = safe_norm(spin_surface - jnp.dot(spin_surface, n) * n)
    return v_roller, v_ring, u, approach_rate, speed, surface_speed


def _flange_normal_load(g, approach_rate, e_prime, damping):
    """(Q, p_max, ellipse semi-axes (2,)) of the flange contact of geometry `g` (`flange_geometry`).

    Hertz point contact of the end surface against the plane (exact elliptic solution, via
    `jaxbearing.contact`): principal radii R_end, R_end on the arc; R_cor across the corner and
    rho_c / sin(alpha) along it on the corner torus, blended C1 across the limited circle
    (`end_principal_curvatures`); for general faces the principal relative radii of the end
    and the rib (`face_flange_geometry`, docs/model.md 5.4). Q = K delta^1.5 (softplus of width PENETRATION_WIDTH),
    p_max = 3Q/(2 pi a b).

    Normal damping (Hunt & Crossley 1975, as on the raceways and pockets): the elastic load is
    multiplied by s(1 + 1.5 alpha d(delta)/dt), d(delta)/dt = (v_roller(C) - v_ring(C)) . n,
    alpha = `damping` [s/m] (`jaxbearing.contact.hunt_crossley_factor`)."""
    stiffness = point_contact_stiffness(g.radius_meridian, g.radius_parallel, e_prime)
    q = hertz_force(g.interference, stiffness, PENETRATION_WIDTH) * hunt_crossley_factor(
        approach_rate, damping
    )
    # both are 0, with zero derivatives, for Q below jaxbearing.contact's load floor
    p_max = point_contact_peak_pressure(q, g.radius_meridian, g.radius_parallel, e_prime)
    semi = jnp.stack(point_contact_ellipse(q, g.radius_meridian, g.radius_parallel, e_prime))
    return q, p_max, semi


def _flange_friction(bearing, g, q, u, v_roller, v_ring, centres, e_prime):
    """(film, mu, F_t) of the flange contact of geometry `g` at load `q` and sliding velocity u;
    `centres` = (p, v, c_r, v_r): the roller's and the ring's centres and velocities.

    Lubrication (`_lubrication`): entrainment velocity u_e = P_t((v_1(C) + v_2(C))/2 - v_C)
    with the contact point's velocity v_C = v + Omega X x (C - p) (Omega: the roller's azimuth
    rate), Hamrock-Dowson h_min and h_c with the end's principal radii along and across u_e,
    Lambda = h_min / sigma. mu = mu_f (`bearing.flange_lubrication == "dry"`, the default) or
    the mixed law f_a(Lambda) mu_f + (1 - f_a) kappa(|u|) ("mixed"). Friction
    F_t = -mu Q u / sqrt(|u|^2 + u_eps^2)."""
    p, roller_velocity, c_r, ring_velocity = centres
    v_c = contact_point_velocity(p, roller_velocity, c_r, ring_velocity, g.contact_point)
    film = flange_film(bearing, g, q, v_roller, v_ring, v_c, e_prime)
    mu = flange_friction_coefficient(bearing, film.film_parameter, u)
    f_t = -mu * q * smooth_direction(u, SLIDING_EPS)
    return film, mu, f_t


def roller_flange_contact(
    bearing: Bearing,
    raceway_radius: ArrayLike,
    side: ArrayLike,
    ring_sign: ArrayLike,
    roller_centre: Vec3,
    roller_axis: Vec3,
    roller_velocity: Vec3,
    roller_angular_velocity: Vec3,
    ring_centre: Vec3,
    ring_velocity: Vec3,
    ring_angular_velocity: Vec3,
    *,
    ring_axis: Vec3 | None = None,
    damping: ArrayLike = HUNT_CROSSLEY_ALPHA,
) -> FlangeContact:
    """Contact of one roller end with one ring flange (docs/model.md 5; the caller vmaps).

    Interference delta = h(n) - (P0 - p) . n with h the support function of the end body
    (`jaxbearing._roller_end.end_support`); contact point C = its extreme point. A bearing with
    general faces (`Bearing.has_general_faces`: a toroidal end, a curved rib) takes them from
    `face_contact` instead (`contact_geometry`, docs/model.md 5.4), into the same laws.
    Sliding velocity u and the roller's surface speed: `_flange_sliding`; normal load Q (Hertz
    point contact, Hunt-Crossley damping), peak pressure p_max and contact ellipse:
    `_flange_normal_load`; film, friction coefficient mu and friction force F_t:
    `_flange_friction`; PV = p_max |u|.

    Top edge: `top_edge` = 1 where the exact radial height of C above the raceway,
    g(|C - c_r|_YZ - R_r), exceeds the flange height H_rf: the contact is then computed on the
    plane continued beyond a flange that is not there (reported, not corrected).
    Forces: on the roller F = -Q n + F_t, moment (C - p) x F; on the ring -F, moment (C - c_r) x (-F).

    Arguments: `raceway_radius` R_r of the ring; `side` s = -1 or +1 (flange at -X or +X);
    `ring_sign` g = +1 inner ring, -1 outer ring; roller centre p, unit axis e (about +X),
    velocity v and angular velocity w; ring centre c_r, velocity v_r, angular velocity w_r;
    `ring_axis` a, the ring's unit axis (default X; a tilted inner ring: `geometry.ring_axis`),
    along which the flange faces sit (`flange_geometry`).
    """
    g = contact_geometry(
        bearing, raceway_radius, side, ring_sign, roller_centre, roller_axis, ring_centre, ring_axis
    )
    n = g.normal
    c = g.contact_point
    p = jnp.asarray(roller_centre)
    c_r = jnp.asarray(ring_centre)
    e_prime = flange_effective_modulus(bearing)

    v_roller, v_ring, u, approach_rate, speed, surface_speed = _flange_sliding(
        n, c, p, c_r, roller_velocity, roller_angular_velocity, ring_velocity, ring_angular_velocity
    )
    q, p_max, semi = _flange_normal_load(g, approach_rate, e_prime, damping)
    film, mu, f_t = _flange_friction(
        bearing, g, q, u, v_roller, v_ring, (p, roller_velocity, c_r, ring_velocity), e_prime
    )
    force = -q * n + f_t
    return FlangeContact(
        interference=g.interference,
        normal_force=q,
        peak_pressure=p_max,
        sliding_velocity=u,
        sliding_speed=speed,
        roller_surface_speed=surface_speed,
        approach_rate=approach_rate,
        pv=p_max * speed,
        contact_point=c,
        contact_height=g.contact_height,
        end_face_position=g.end_face_position,
        contact_radius=g.contact_radius,
        on_arc=g.on_arc,
        force_on_roller=force,
        moment_on_roller=jnp.cross(c - p, force),
        force_on_ring=-force,
        moment_on_ring=jnp.cross(c - c_r, -force),
        ellipse_semi_axes=semi,
        entrainment_speed=film.entrainment_speed,
        entrainment_velocity=film.entrainment_velocity,
        min_film=film.min_film,
        central_film=film.central_film,
        film_parameter=film.film_parameter,
        friction_coefficient=mu,
        top_edge=jnp.where(g.cone_height > bearing.flange.height, 1.0, 0.0),
        face_error=g.face_error,
    )


#: flange order of `all_flange_contacts`: (ring_sign, side)
FLANGE_ORDER = ((1.0, -1.0), (1.0, 1.0), (-1.0, -1.0), (-1.0, 1.0))


def flange_pv_at_load(
    bearing: Bearing,
    raceway_radius: ArrayLike,
    side: ArrayLike,
    ring_sign: ArrayLike,
    roller_centre: Vec3,
    roller_axis: Vec3,
    roller_velocity: Vec3,
    roller_angular_velocity: Vec3,
    ring_centre: Vec3,
    ring_velocity: Vec3,
    ring_angular_velocity: Vec3,
    load: ArrayLike,
    *,
    ring_axis: Vec3 | None = None,
) -> tuple[Scalar, Scalar]:
    """(PV [Pa m/s], contact radius rho_c [m]) of one roller end against one flange at the pose
    and velocities given (the arguments of `roller_flange_contact`), with the normal load Q held
    at `load` instead of the one the interference gives: p_max(Q) |u|, the contact point, the
    curvature sums and the material sliding speed |u| those of `bearing`'s faces at this pose
    (docs/model.md 17, the held-load objective). On a cone rib the contact point and the
    curvatures do not depend on how far the end is pressed into the rib, so this is the PV the
    roller would have pressed against these faces with load Q, whether or not they overlap at
    this pose; on a concave rib the same to the order of the interference."""
    g = contact_geometry(
        bearing, raceway_radius, side, ring_sign, roller_centre, roller_axis, ring_centre, ring_axis
    )
    speed = _flange_sliding(
        g.normal,
        g.contact_point,
        jnp.asarray(roller_centre),
        jnp.asarray(ring_centre),
        roller_velocity,
        roller_angular_velocity,
        ring_velocity,
        ring_angular_velocity,
    )[4]
    p_max = point_contact_peak_pressure(
        load, g.radius_meridian, g.radius_parallel, flange_effective_modulus(bearing)
    )
    return p_max * speed, g.contact_radius


def all_flange_contacts(
    bearing: Bearing,
    roller_centre: Float[Array, "Z 3"],
    roller_axis: Float[Array, "Z 3"],
    roller_velocity: Float[Array, "Z 3"],
    roller_angular_velocity: Float[Array, "Z 3"],
    inner_ring_centre: Vec3,
    inner_ring_velocity: Vec3,
    inner_ring_angular_velocity: Vec3,
    outer_ring_centre: Vec3,
    outer_ring_velocity: Vec3,
    outer_ring_angular_velocity: Vec3,
    inner_ring_axis: Vec3 | None = None,
    outer_ring_axis: Vec3 | None = None,
) -> FlangeContact:
    """Every roller against every flange: a FlangeContact with leading shape (Z, 4).

    Flange order along axis 1 (`FLANGE_ORDER`): inner -X, inner +X, outer -X, outer +X
    (-X/+X: the side along each ring's own axis, X unless `inner_ring_axis` /
    `outer_ring_axis` is given).
    Lifted with `jax.vmap` over flanges and rollers (no Python loop over rollers).

    Absent flanges (`Bearing.flange_presence` k_f = 0, the bearing type; docs/model.md 5.3)
    carry nothing: `without_absent_flanges`.
    """
    ring_sign = jnp.array([f[0] for f in FLANGE_ORDER])
    side = jnp.array([f[1] for f in FLANGE_ORDER])
    radius = jnp.stack([bearing.inner_raceway_radius] * 2 + [bearing.outer_raceway_radius] * 2)
    x_axis = jnp.array([1.0, 0.0, 0.0])
    inner_a = x_axis if inner_ring_axis is None else inner_ring_axis
    outer_a = x_axis if outer_ring_axis is None else outer_ring_axis
    inner = (inner_ring_centre, inner_ring_velocity, inner_ring_angular_velocity, inner_a)
    outer = (outer_ring_centre, outer_ring_velocity, outer_ring_angular_velocity, outer_a)
    inner, outer = ([jnp.asarray(x) for x in ring] for ring in (inner, outer))
    c_r, v_r, w_r, a_r = (jnp.stack([i, i, o, o]) for i, o in zip(inner, outer))

    def one(rad, sd, sg, c, vr, wr, ar, p, e, v, w):
        return roller_flange_contact(bearing, rad, sd, sg, p, e, v, w, c, vr, wr, ring_axis=ar)

    per_roller = jax.vmap(one, in_axes=(0,) * 7 + (None,) * 4)
    contacts = jax.vmap(per_roller, in_axes=(None,) * 7 + (0, 0, 0, 0))(
        radius,
        side,
        ring_sign,
        c_r,
        v_r,
        w_r,
        a_r,
        roller_centre,
        roller_axis,
        roller_velocity,
        roller_angular_velocity,
    )
    return without_absent_flanges(contacts, bearing.flange_presence)


def without_absent_flanges(contacts: FlangeContact, presence: Float[Array, "*batch 4"]) -> FlangeContact:
    """`contacts` (leading shape (Z, 4)) with the loads of absent flanges set to zero.

    Every load-carrying quantity of flange f is multiplied by its presence k_f (1 there, 0
    absent): normal force Q, peak pressure, PV, contact ellipse, and the forces and moments on
    roller and ring (normal and friction), so an absent flange exerts nothing on a roller or a
    ring and enters no contact event, statistic over contact time (all select Q above a
    threshold) or smooth functional (all weighted by Q / (Q + Q_0)). Multiplying by 1.0 is
    exact: a flange that is there gives its numbers bit for bit. The geometric quantities
    (interference, contact point and height, film) stay as computed, as for an open gap.
    """
    k = jnp.asarray(presence)

    def scaled(x):
        return x * k.reshape((4,) + (1,) * (x.ndim - 2))

    return eqx.tree_at(_loads, contacts, tuple(scaled(x) for x in _loads(contacts)))


def _loads(c: FlangeContact) -> tuple:
    """The load-carrying fields of a FlangeContact (`without_absent_flanges`)."""
    return (
        c.normal_force,
        c.peak_pressure,
        c.pv,
        c.ellipse_semi_axes,
        c.force_on_roller,
        c.moment_on_roller,
        c.force_on_ring,
        c.moment_on_ring,
    )
