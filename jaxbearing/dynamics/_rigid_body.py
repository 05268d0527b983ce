"""Rigid-body rates of an axisymmetric body (the roller) in inertial components.

The attitude is carried by the unit symmetry axis e and the angular velocity omega; the spin
angle about e is not integrated. With H = I_t omega + (I_a - I_t)(omega . e) e and e' = omega x e,
dH/dt = M gives (Euler's equations with their gyroscopic terms, no small angles):

    omega'.e     = M.e / I_a
    omega'_perp  = (M_perp - (I_a - I_t)(omega . e)(omega x e)) / I_t

Torque-free check (Goldstein, Classical Mechanics, sec. 5.6): H is constant, the axis precesses
about H at Omega_p = |H| / I_t, and the spin omega . e is constant.
"""

from __future__ import annotations

import jax.numpy as jnp
from jaxtyping import Array, Float


def axisymmetric_body_rates(
    axis: Float[Array, "... 3"],
    angular_velocity: Float[Array, "... 3"],
    moment: Float[Array, "... 3"],
    axial_inertia,
    transverse_inertia,
) -> tuple[Array, Array]:
    """(de/dt, d omega/dt) for moment M about the centre of mass."""
    e = axis / jnp.linalg.norm(axis, axis=-1, keepdims=True)
    w = angular_velocity
    spin = jnp.sum(w * e, axis=-1, keepdims=True)
    m_axial = jnp.sum(moment * e, axis=-1, keepdims=True)
    m_perp = moment - m_axial * e
    gyro = (axial_inertia - transverse_inertia) * spin * jnp.cross(w, e)
    omega_dot = m_axial * e / axial_inertia + (m_perp - gyro) / transverse_inertia
    return jnp.cross(w, axis), omega_dot


def angular_momentum(axis, angular_velocity, axial_inertia, transverse_inertia) -> Array:
    """H = I_t omega + (I_a - I_t)(omega . e) e."""
    e = axis / jnp.linalg.norm(axis, axis=-1, keepdims=True)
    spin = jnp.sum(angular_velocity * e, axis=-1, keepdims=True)
    return transverse_inertia * angular_velocity + (axial_inertia - transverse_inertia) * spin * e


def kinetic_energy(axis, angular_velocity, axial_inertia, transverse_inertia) -> Array:
    """T = (I_a (omega.e)^2 + I_t |omega_perp|^2) / 2."""
    e = axis / jnp.linalg.norm(axis, axis=-1, keepdims=True)
    spin = jnp.sum(angular_velocity * e, axis=-1)
    perp2 = jnp.sum(angular_velocity**2, axis=-1) - spin**2
    return 0.5 * (axial_inertia * spin**2 + transverse_inertia * perp2)
