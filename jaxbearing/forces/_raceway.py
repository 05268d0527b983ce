"""Roller against raceway: sliced line contact with crown, damping and traction (docs/model.md 8).

The effective length L_we = L_b1 - 2 R_cor of the roller generatrix is cut into N_s slices of
width L_we/N_s centred at

    xi_j = -L_we/2 + (j + 1/2) L_we/N_s,        j = 0 .. N_s - 1.

Each slice is a thin disc of radius r(xi_j) = D/2 - c(xi_j) normal to the roller axis, where the
crown drop c(xi) is zero on the straight central length |xi| <= L_b2/2 and a circular arc
outside it, tangent to the straight part and reaching c_crown at |xi| = L_we/2
(ISO/TS 16281 sec. 5 "slicing"; Harris & Kotzalas, Advanced Concepts, ch. 1 "roller crowning").

Geometry (exact in the roller pose, no small-angle assumption for tilt or skew). With the
slice centre q_j = p + xi_j e on the roller axis (roller centre p, unit axis e), the ring centre
c_r and the unit ring axis a (X for the outer ring; the inner ring's axis tilted by the
misalignment, `geometry.ring_axis`), the radial offset of q_j from the ring axis is
rho_j = (q_j - c_r) - ((q_j - c_r).a) a, its length d_j = |rho_j| and direction n_j = rho_j/d_j.
The raceway is the cylinder |rho| = R_race about the (possibly tilted) ring axis, so a tilted
ring is handled by the same formula: no small-angle assumption for the ring either.

Tilted ring, closed form (the unit test's oracle): an aligned roller (e = X) at azimuth theta,
centre p = r e_rad(theta), against an inner ring through the origin tilted by psi about +Y,
a = (cos psi, 0, -sin psi). Then q_j.a = xi_j cos psi - r cos theta sin psi and

    d_j^2 = |q_j|^2 - (q_j.a)^2 = r^2 + 2 r xi_j cos theta sin psi cos psi + O(psi^2),

so d_j = r + xi_j cos theta sin psi + O(psi^2) and the inner interference falls linearly along
the roller with slope d(delta_j)/d(xi_j) = -sin psi cos theta: the tilt projected onto the
roller's azimuth (full at theta = 0 and pi, zero at +-pi/2); the support factor
sqrt(1 - (e.n_j)^2), e.n_j = cos theta sin psi + O(psi^2), only shifts every slice by the same
O(r_roller psi^2).
The disc's extent towards the raceway along n_j is its support function
r(xi_j) sqrt(1 - (e.n_j)^2), so the interference is

    delta_j = r(xi_j) sqrt(1 - (e.n_j)^2) + g (R_race - d_j),

g = +1 for the inner ring (roller outside its raceway cylinder: delta = R_i + r - d) and g = -1
for the outer ring (roller inside: delta = d + r - R_o). Skew (axis turned towards the
tangential direction) enters exactly through the slice centres q_j, tilt (axis turned in the
radial plane) through the support factor. The one approximation is that the disc's extreme
point is sought along n_j (the raceway taken as its tangent plane across the disc): exact for
pure tilt or pure skew, and for combined tilt and skew of 10 mrad each the interference
differs from a brute-force search over the disc's rim by 2e-12 m (4e-9 m at an extreme
100/50 mrad), far below the penetration width of 1e-9 m at any physical attitude (the tests
check the rim search at up to 10 mrad).

Load per slice (docs/model.md 8): q_j = (k_c/N_s) softplus_w(delta_j)^(10/9), with k_c the
ISO/TS 16281 stiffness of one whole roller-raceway line contact (`contact.line_contact_stiffness`),
so that a uniformly loaded roller follows the whole-contact law exactly.

Normal damping (Hunt & Crossley 1975, "Coefficient of restitution interpreted as damping in
vibroimpact", J. Appl. Mech. 42:440-445):

    N_j = q_j * s(1 + 3/2 alpha d(delta_j)/dt),

with d(delta_j)/dt = -(v_rel . n_j) the approach rate of the material points at the contact.
The damping is proportional to the elastic load, so it vanishes with the contact and never
makes the force jump when a slice opens or closes; s() is a softplus of width 0.02 that keeps
the factor positive (no adhesive pull when the bodies separate faster than 1/(1.5 alpha) =
2.2 m/s) and differs from the identity by < 1e-21 near 1. Hunt and Crossley's experimental
alpha is 0.08 - 0.32 s/m for steel, bronze and ivory (coefficient of restitution
e = 1 - alpha v); the default 0.3 s/m sits at the top of the range because the oil film of a
lubricated contact damps more than a dry one. At the reference operating point it gives the
most loaded roller's radial contact vibration a damping ratio of about 0.1.

Traction (docs/model.md 8): the sliding velocity of slice j is the tangential part of
v_rel = (v_b + w_b x (x_j - p)) - (v_r + w_r x (x_j - c_r)) at the contact point x_j, and the
traction on the roller is -N_j kappa(|u|) u/|u| (`contact.traction_force`, direction smoothed
by SLIDING_EPS), with the lubricant traction curve kappa of `Lubricant`.

The contact point x_j is the middle of the overlap: the disc's extreme point moved back by
delta_j/2 along the normal, which points from the raceway into the roller (g n_j). Forces and
moments on the ring are exactly opposite to those on the roller (moments taken about the ring
centre).
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from .._errors import UserInputError
from ..contact import (
    HUNT_CROSSLEY_ALPHA,
    PENETRATION_WIDTH,
    SLIDING_EPS,
    effective_modulus,
    hunt_crossley_factor,
    line_contact_stiffness,
    line_slice_loads,
    safe_norm,
    traction_force,
)
from ..geometry import Bearing, Roller, sag

#: load weight added to each slice in the load-weighted mean sliding speed [N] (avoids 0/0).
_MEAN_WEIGHT_EPS = 1e-12

_AXIS = np.array([1.0, 0.0, 0.0])


def _safe_unit(v: Array, fallback: Array) -> tuple[Array, Array]:
    """(|v|, v/|v|) with the double-where pattern; `fallback` where |v| = 0."""
    n = safe_norm(v, axis=-1, keepdims=True)
    ok = n > 0
    u = jnp.where(ok, v / jnp.where(ok, n, 1.0), fallback)
    return n[..., 0], u


def slice_positions(bearing: Bearing, num_slices: int | None = None) -> Float[Array, " N_s"]:
    """xi_j = -L_we/2 + (j + 1/2) L_we/N_s: slice centres along the roller axis [m]
    (N_s = bearing.num_slices unless `num_slices` is given, as for the cage pocket)."""
    n = bearing.num_slices if num_slices is None else num_slices
    l_we = bearing.roller.effective_length
    return l_we * ((jnp.arange(n) + 0.5) / n - 0.5)


def crown_curvature(roller: Roller) -> Array:
    """Curvature 1/R_cr of the circular crown: the arc tangent to the straight central part at
    |xi| = L_b2/2 whose sagitta over the crowned length s = (L_we - L_b2)/2 is c_crown,
    1/R_cr = 2 c / (s^2 + c^2) (chord-sagitta relation). 0 when there is no crown."""
    s = jnp.maximum(roller.effective_length - roller.central_length, 0.0) / 2
    c = roller.crown_drop
    den = s**2 + c**2
    ok = den > 0
    return jnp.where(ok, 2 * c / jnp.where(ok, den, 1.0), 0.0)


def crown_drop(roller: Roller, xi: ArrayLike) -> Array:
    """c(xi): drop of the generatrix below D/2 at axial position xi from the roller centre.

    c(xi) = 0 for |xi| <= L_b2/2, else sag(|xi| - L_b2/2, 1/R_cr) (exact circle, cancellation-free
    `_roller_end.sag`); c(+/- L_we/2) = c_crown.
    """
    k = crown_curvature(roller)
    s_max = jnp.maximum(roller.effective_length - roller.central_length, 0.0) / 2
    excess = jnp.clip(jnp.abs(xi) - roller.central_length / 2, 0.0, s_max)
    return sag(excess, k)


def raceway_stiffness(bearing: Bearing) -> Array:
    """k_c of one roller-raceway line contact, Q = k_c delta^(10/9) [N/m^(10/9)] (ISO/TS 16281,
    docs/model.md 8), for the effective length L_we and E' of the ring and roller materials."""
    rm, bm = bearing.ring_material, bearing.roller_material
    e_prime = effective_modulus(rm.elastic_modulus, rm.poisson_ratio, bm.elastic_modulus, bm.poisson_ratio)
    return line_contact_stiffness(bearing.roller.effective_length, e_prime)


def slice_loads_from_interference(
    bearing: Bearing, interference: Float[Array, "... N_s"], width: float = PENETRATION_WIDTH
) -> Float[Array, "... N_s"]:
    """q_j = (k_c/N_s) softplus_w(delta_j)^(10/9): elastic slice loads [N] (docs/model.md 8).

    The one slice law shared by the dynamic contact and the quasi-static solution.
    """
    k_c = raceway_stiffness(bearing)
    return line_slice_loads(interference, k_c, bearing.num_slices, width)


def uniform_approach_interference(bearing: Bearing, approach: ArrayLike) -> Float[Array, "... N_s"]:
    """Slice interferences delta_j = a - c(xi_j) of an aligned roller whose straight generatrix
    penetrates the raceway by the approach a (what `raceway_slice_geometry` gives for e = X)."""
    xi = slice_positions(bearing)
    return jnp.asarray(approach)[..., None] - crown_drop(bearing.roller, xi)


def _check_ring_sign(ring_sign) -> None:
    """ring_sign must be +1 (inner) or -1 (outer); checked when it is a concrete value."""
    try:
        g = np.asarray(ring_sign, dtype=float)
    except (TypeError, jax.errors.ConcretizationTypeError, jax.errors.TracerArrayConversionError):
        return
    if not np.all(np.abs(g) == 1.0):
        raise UserInputError(
            f"ring_sign = {g.tolist()} is out of range: must be +1 (inner ring) or -1 (outer ring)"
        )


def raceway_slice_geometry(
    bearing: Bearing,
    ring_sign: ArrayLike,
    raceway_radius: ArrayLike,
    roller_centre: Float[Array, 3],
    roller_axis: Float[Array, 3],
    ring_centre: Float[Array, 3],
    *,
    ring_axis: Float[Array, 3] | None = None,
) -> tuple[Float[Array, " N_s"], Float[Array, "N_s 3"], Float[Array, "N_s 3"]]:
    """(interference, contact_points, normals) of the N_s slices (module docstring):

        delta_j = r(xi_j) sqrt(1 - (e.n_j)^2) + g (R_race - |rho_j|),   r(xi) = D/2 - c(xi),
        rho_j = (q_j - c_r) - ((q_j - c_r).a) a.

    `ring_sign` g = +1 inner ring, -1 outer ring; `raceway_radius` R_race; the ring axis is the
    unit vector `ring_axis` a (default X) through `ring_centre`. `roller_axis` must be a unit
    vector.
    """
    _check_ring_sign(ring_sign)
    g = jnp.asarray(ring_sign, dtype=float)
    e = roller_axis
    a = _AXIS if ring_axis is None else ring_axis
    xi = slice_positions(bearing)
    q = roller_centre + xi[:, None] * e  # slice centres on the roller axis
    rel = q - ring_centre
    rho = rel - (rel @ a)[:, None] * a  # radial offset from the ring axis
    fallback_n = jnp.broadcast_to(jnp.array([0.0, 0.0, 1.0]), rho.shape)
    dist, n_r = _safe_unit(rho, fallback_n)

    # support of the slice disc (normal e, radius r) in the direction n_r: r |n_r - (e.n_r) e|
    cos_tilt = n_r @ e
    perp = n_r - cos_tilt[:, None] * e
    support_factor, u_ext = _safe_unit(perp, n_r)
    radius = bearing.roller.diameter / 2 - crown_drop(bearing.roller, xi)
    interference = radius * support_factor + g * (raceway_radius - dist)

    normals = g * n_r
    extreme = q - g * radius[:, None] * u_ext  # disc point deepest into the raceway
    contact_points = extreme + 0.5 * interference[:, None] * normals
    return interference, contact_points, normals


class RacewayContact(eqx.Module):
    """One roller against one raceway: per-slice and resultant quantities (SI units)."""

    interference: Float[Array, " N_s"]  # delta_j [m]
    slice_loads: Float[Array, " N_s"]  # N_j, normal force incl. damping [N]
    elastic_slice_loads: Float[Array, " N_s"]  # q_j, elastic part [N]
    normal_load: Float[Array, ""]  # sum_j N_j [N]
    contact_points: Float[Array, "N_s 3"]
    normals: Float[Array, "N_s 3"]  # from the raceway into the roller
    sliding_velocity: Float[Array, "N_s 3"]  # u_j, roller minus ring, tangential [m/s]
    slice_traction: Float[Array, "N_s 3"]  # traction force on the roller per slice [N]
    mean_sliding_speed: Float[Array, ""]  # load-weighted mean |u_j| [m/s]
    force_on_roller: Float[Array, 3]
    moment_on_roller: Float[Array, 3]  # about the roller centre
    force_on_ring: Float[Array, 3]
    moment_on_ring: Float[Array, 3]  # about the ring centre


def raceway_contact(
    bearing: Bearing,
    ring_sign: ArrayLike,
    raceway_radius: ArrayLike,
    roller_centre: Float[Array, 3],
    roller_axis: Float[Array, 3],
    roller_velocity: Float[Array, 3],
    roller_angular_velocity: Float[Array, 3],
    ring_centre: Float[Array, 3],
    ring_velocity: Float[Array, 3],
    ring_angular_velocity: Float[Array, 3],
    *,
    ring_axis: Float[Array, 3] | None = None,
    damping: ArrayLike = HUNT_CROSSLEY_ALPHA,
    penetration_width: float = PENETRATION_WIDTH,
    speed_eps: float = SLIDING_EPS,
) -> RacewayContact:
    """Sliced roller-raceway contact with Hunt-Crossley damping and traction (module docstring).

    Arguments are inertial-frame 3-vectors: roller centre p, unit axis e, velocity v_b, angular
    velocity w_b; ring centre c_r, velocity v_r, angular velocity w_r, unit ring axis
    `ring_axis` a (default X).
    `damping` is the Hunt-Crossley alpha [s/m]: N_j = q_j s(1 + 1.5 alpha d(delta_j)/dt).
    Vectorised over slices; vmap it over rollers.
    """
    _check_ring_sign(ring_sign)
    delta, x, n = raceway_slice_geometry(
        bearing, ring_sign, raceway_radius, roller_centre, roller_axis, ring_centre, ring_axis=ring_axis
    )
    q_el = slice_loads_from_interference(bearing, delta, penetration_width)

    v_roller = roller_velocity + jnp.cross(roller_angular_velocity, x - roller_centre)
    v_ring = ring_velocity + jnp.cross(ring_angular_velocity, x - ring_centre)
    v_rel = v_roller - v_ring
    v_n = jnp.sum(v_rel * n, axis=-1)
    approach_rate = -v_n  # d(delta)/dt: positive while the bodies close in
    factor = hunt_crossley_factor(approach_rate, damping)
    normal = q_el * factor

    u = v_rel - v_n[:, None] * n
    lub = bearing.lubricant
    traction = traction_force(u, normal, lub, speed_eps)

    f_slices = normal[:, None] * n + traction
    force = jnp.sum(f_slices, axis=0)
    moment = jnp.sum(jnp.cross(x - roller_centre, f_slices), axis=0)
    ring_moment = -jnp.sum(jnp.cross(x - ring_centre, f_slices), axis=0)

    speed = safe_norm(u, axis=-1)
    weight = normal + _MEAN_WEIGHT_EPS
    mean_speed = jnp.sum(weight * speed) / jnp.sum(weight)
    return RacewayContact(
        interference=delta,
        slice_loads=normal,
        elastic_slice_loads=q_el,
        normal_load=jnp.sum(normal),
        contact_points=x,
        normals=n,
        sliding_velocity=u,
        slice_traction=traction,
        mean_sliding_speed=mean_speed,
        force_on_roller=force,
        moment_on_roller=moment,
        force_on_ring=-force,
        moment_on_ring=ring_moment,
    )
