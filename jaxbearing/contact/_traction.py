"""Traction and friction forces of lubricated and dry contacts (docs/model.md 8, 4.1, 4.3).

The traction coefficient of the roller-raceway contacts follows the lubricant's traction curve

    kappa(du) = (A + B du) exp(-C du) + D,

with A, B, C, D from `jaxbearing.Lubricant` (`traction_a` ... `traction_d`). For the defaults
(A = -0.04, B = 0.2528 s/m, C = 2.926 s/m, D = 0.04) kappa(0) = A + D = 0, the peak lies at
du_max = (B - A C) / (B C) = 0.5 m/s with kappa_max = B/C exp(-C du_max) + D = 0.06, and
kappa -> D = 0.04 at high sliding (docs/model.md 8; the curve is a property of the lubricant and
its defaults are representative, not measured).

The force opposes the sliding velocity u with the regularised direction of
`smooth_direction`: F = -Q kappa(s) u / s, s = sqrt(|u|^2 + u_eps^2), smooth and zero at u = 0.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

if TYPE_CHECKING:  # annotations only: contact laws sit below the parameter layer
    from ..geometry import Lubricant
from ._smooth import SLIDING_EPS


def traction_coefficient(
    sliding_speed: Float[ArrayLike, "*batch"], lubricant: Lubricant
) -> Float[Array, "*batch"]:
    """Traction coefficient kappa(du) = (A + B du) exp(-C du) + D (docs/model.md 8).

    Args:
        sliding_speed: du >= 0 [m/s], the magnitude of the sliding velocity.
        lubricant: supplies A = `traction_a`, B = `traction_b` [s/m], C = `traction_c` [s/m],
            D = `traction_d`.
    """
    du = jnp.asarray(sliding_speed)
    a, b = lubricant.traction_a, lubricant.traction_b
    c, d = lubricant.traction_c, lubricant.traction_d
    return (a + b * du) * jnp.exp(-c * du) + d


def _regularised_speed(u, speed_eps):
    u = jnp.asarray(u)
    eps2 = jnp.asarray(speed_eps)[..., None] ** 2
    return u, jnp.sqrt(jnp.sum(u * u, axis=-1, keepdims=True) + eps2)


def traction_force(
    sliding_velocity: Float[ArrayLike, "*batch dim"],
    normal_load: Float[ArrayLike, "*#batch"],
    lubricant: Lubricant,
    speed_eps: Float[ArrayLike, "*#batch"] = SLIDING_EPS,
) -> Float[Array, "*batch dim"]:
    """Lubricated traction force F = -Q kappa(s) u / s, s = sqrt(|u|^2 + u_eps^2) [N].

    Opposes the sliding velocity u (last axis: its components); its magnitude is
    Q kappa(s) |u| / s, i.e. Q kappa(|u|) up to O(u_eps^2/|u|^2) for |u| >> u_eps, and it
    vanishes smoothly at u = 0 (C-infinity for u_eps > 0).

    Args:
        sliding_velocity: u [m/s], velocity of the body the force acts on relative to the
            other body at the contact point, tangential components.
        normal_load: Q >= 0 [N], broadcast over the leading axes.
        lubricant: traction curve (`traction_coefficient`).
        speed_eps: u_eps [m/s], default `SLIDING_EPS`.
    """
    u, s = _regularised_speed(sliding_velocity, speed_eps)
    kappa = traction_coefficient(s, lubricant)
    return -jnp.asarray(normal_load)[..., None] * kappa * u / s


def friction_force(
    sliding_velocity: Float[ArrayLike, "*batch dim"],
    normal_load: Float[ArrayLike, "*#batch"],
    coefficient: Float[ArrayLike, "*#batch"],
    speed_eps: Float[ArrayLike, "*#batch"] = SLIDING_EPS,
) -> Float[Array, "*batch dim"]:
    """Regularised Coulomb friction F = -mu Q u / sqrt(|u|^2 + u_eps^2) [N].

    For contacts with a constant coefficient: roller end on flange (mu_f = 0.08 in the paper's
    roller-flange model) and roller on cage pocket (mu_p), docs/model.md 5 and 4.3.

    Args:
        sliding_velocity: u [m/s] (last axis: components).
        normal_load: Q >= 0 [N].
        coefficient: mu.
        speed_eps: u_eps [m/s].
    """
    u, s = _regularised_speed(sliding_velocity, speed_eps)
    mu_q = jnp.asarray(coefficient) * jnp.asarray(normal_load)
    return -mu_q[..., None] * u / s
