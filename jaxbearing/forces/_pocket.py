"""Roller against its cage pocket: sliced line contact with two planar walls (docs/model.md 9).

Pocket geometry. Pocket j of a cage with centre c_c and angle theta_c has its centre
c_p = c_c + (d_m/2) e_rad(theta_c + 2 pi j / Z) and the cage's tangential unit t_c at that azimuth
(the caller passes both; this module never assumes a sign convention for e_tan). Its two walls
are planes normal to t_c at +/-(D + C_p)/2 from c_p, with C_p the total circumferential pocket
clearance (`Cage.pocket_clearance`). The walls are taken as unbounded planes: the roller never
leaves its pocket radially or axially in the model.

Slices. The roller's effective length L_we = L_b1 - 2 R_cor is cut into N_p slices (default 5)
centred at xi_k = -L_we/2 + (k + 1/2) L_we / N_p on the axis e, q_k = p + xi_k e. For wall
s in {+1, -1} (outward normal n_s = s t_c, from the roller into the wall) the slice's extreme
point is its circle's support point in the direction n_s,

    x_k = q_k + s (D/2) u / |u|,    u = t_c - (t_c . e) e,

and the interference is the support distance minus the wall distance:

    delta_k,s = s y_k + (D/2) |u| - (D + C_p)/2,     y_k = (q_k - c_p) . t_c.

For an aligned roller (e . t_c = 0) this is y_k + D/2 - (D + C_p)/2 on the +wall and its mirror
on the -wall; a skewed roller (e . t_c = sin(skew)) is exact to all orders, |u| =
sqrt(1 - (e . t_c)^2). Forces act at the middle of the overlap, x_k - (delta_k/2) n_s.

Load per slice: q_k = (k_c / N_p) softplus_w(delta_k)^(10/9) (`contact.line_slice_loads`),
where k_c = `contact.line_contact_stiffness`(L_we, E'(roller, cage)) is the ISO/TS 16281
stiffness of one whole roller-on-plane line contact scaled to the roller/cage materials, so a
uniformly loaded roller follows Q = k_c delta^(10/9) (docs/model.md 8). (A flat wall is less
conformal than a raceway; ISO/TS 16281's formula, like Palmgren's, ignores the curvature sum of
line contacts, so the same law applies.)

Damping (Hunt & Crossley 1975, J. Appl. Mech. 42:440-445), as in `_raceway`:
N_k = q_k s(1 + 3/2 alpha d(delta_k)/dt), d(delta_k)/dt = (v_roller - v_cage) . n_s at the
contact point. It is proportional to the elastic load, so it vanishes with the contact and is
continuous when a slice opens or closes; s() is a softplus of width 0.02 that keeps the factor
positive (no adhesive pull on fast separation). alpha defaults to `contact.HUNT_CROSSLEY_ALPHA`.

Friction (Coulomb, mu_p = `Bearing.pocket_friction`): -mu_p N_k u/sqrt(|u|^2 + u_eps^2) on the
roller, u the tangential part (to the wall) of the sliding velocity of the roller material
point minus the cage material point at the contact,
v_rel = (v + w x (x - p)) - (v_c + Omega_c x (x - c_c)) (the paper's roller-pocket model is in
its refs. [1, 22]; Harris & Kotzalas, "Advanced Concepts of Bearing Technology", on cage
pocket forces).

Forces and moments on the cage are exactly opposite to those on the roller, moments taken about
the cage centre.
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from ..contact import (
    HUNT_CROSSLEY_ALPHA,
    PENETRATION_WIDTH,
    SLIDING_EPS,
    effective_modulus,
    hunt_crossley_factor,
    line_contact_stiffness,
    line_slice_loads,
    safe_norm,
    smooth_direction,
)
from ..geometry import Bearing
from ._raceway import slice_positions

#: Default number of slices of the roller-pocket line contact.
NUM_POCKET_SLICES = 5


class PocketContact(eqx.Module):
    """Roller-pocket contact of one roller (both walls, all slices summed)."""

    normal_force: Float[Array, ""]  # signed total [N]: > 0 pushes the roller along +t_c
    force_on_roller: Float[Array, 3]  # [N]
    moment_on_roller: Float[Array, 3]  # about the roller centre p [N m]
    force_on_cage: Float[Array, 3]  # = -force_on_roller [N]
    moment_on_cage: Float[Array, 3]  # about the cage centre c_c [N m]


def pocket_stiffness(bearing: Bearing) -> Float[Array, ""]:
    """k_c of one whole roller-wall line contact [N/m^(10/9)]: ISO/TS 16281 over L_we with
    E'(roller, cage) (`contact.line_contact_stiffness`)."""
    e_prime = effective_modulus(
        bearing.roller_material.elastic_modulus,
        bearing.roller_material.poisson_ratio,
        bearing.cage_material.elastic_modulus,
        bearing.cage_material.poisson_ratio,
    )
    return line_contact_stiffness(bearing.roller.effective_length, e_prime)


def pocket_slice_positions(bearing: Bearing, num_slices: int) -> Float[Array, " N_p"]:
    """xi_k = -L_we/2 + (k + 1/2) L_we / N_p: slice centres along the roller axis [m]
    (the raceway slicing, `_raceway.slice_positions`, with N_p slices)."""
    return slice_positions(bearing, num_slices)


def pocket_contact(
    bearing: Bearing,
    roller_centre: Float[Array, 3],
    roller_axis: Float[Array, 3],
    roller_velocity: Float[Array, 3],
    roller_angular_velocity: Float[Array, 3],
    pocket_centre: Float[Array, 3],
    pocket_tangent: Float[Array, 3],
    cage_velocity: Float[Array, 3],
    cage_angular_velocity: Float[Array, 3],
    cage_centre: Float[Array, 3],
    *,
    num_slices: int = NUM_POCKET_SLICES,
    damping: ArrayLike = HUNT_CROSSLEY_ALPHA,
    penetration_width: float = PENETRATION_WIDTH,
    speed_eps: float = SLIDING_EPS,
) -> PocketContact:
    """Contact of one roller with the two walls of its pocket (module docstring).

    Inertial-frame 3-vectors: roller centre p, unit axis e, velocity v, angular velocity w;
    pocket centre c_p and unit tangential direction t_c (wall normals +/- t_c); cage velocity
    v_c, angular velocity Omega_c (3,) and centre c_c. `num_slices` is static. Vmap over rollers.
    """
    p = jnp.asarray(roller_centre)
    e = jnp.asarray(roller_axis)
    t = jnp.asarray(pocket_tangent)
    c_p = jnp.asarray(pocket_centre)
    c_c = jnp.asarray(cage_centre)
    d = bearing.roller.diameter
    wall = (d + bearing.cage.pocket_clearance) / 2

    xi = pocket_slice_positions(bearing, num_slices)  # (N,)
    q = p + xi[:, None] * e  # (N, 3) slice centres
    y = (q - c_p) @ t  # (N,) tangential offsets

    u = t - jnp.dot(t, e) * e
    u_len = safe_norm(u)
    ok = u_len > 0
    u_hat = jnp.where(ok, u / jnp.where(ok, u_len, 1.0), t)
    support = d / 2 * u_len

    side = jnp.array([1.0, -1.0])  # +wall, -wall
    delta = side[:, None] * y[None, :] + support - wall  # (2, N)
    normal = side[:, None] * t  # (2, 3), outward: roller -> wall
    extreme = q[None, :, :] + side[:, None, None] * (d / 2) * u_hat  # (2, N, 3)
    x = extreme - 0.5 * delta[..., None] * normal[:, None, :]  # middle of the overlap

    q_el = line_slice_loads(delta, pocket_stiffness(bearing), num_slices, penetration_width)

    v_roller = roller_velocity + jnp.cross(roller_angular_velocity, x - p)
    v_cage = cage_velocity + jnp.cross(cage_angular_velocity, x - c_c)
    v_rel = v_roller - v_cage  # (2, N, 3)
    approach_rate = jnp.sum(v_rel * normal[:, None, :], axis=-1)  # d(delta)/dt
    factor = hunt_crossley_factor(approach_rate, damping)
    n_load = q_el * factor  # (2, N)

    slide = v_rel - approach_rate[..., None] * normal[:, None, :]
    friction = -bearing.pocket_friction * n_load[..., None] * smooth_direction(slide, speed_eps)
    f_slices = -n_load[..., None] * normal[:, None, :] + friction  # on the roller, (2, N, 3)

    force = jnp.sum(f_slices, axis=(0, 1))
    moment = jnp.sum(jnp.cross(x - p, f_slices), axis=(0, 1))
    cage_moment = -jnp.sum(jnp.cross(x - c_c, f_slices), axis=(0, 1))
    signed = jnp.sum(n_load[1]) - jnp.sum(n_load[0])
    return PocketContact(
        normal_force=signed,
        force_on_roller=force,
        moment_on_roller=moment,
        force_on_cage=-force,
        moment_on_cage=cage_moment,
    )
