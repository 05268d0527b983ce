"""The inner ring's attitude: its axis and the angular velocity of its tilt.

The ring is tilted by two angles: psi_y about the inertial +Y axis, then psi_z about the ring's
own Z axis (a rotation R = R_Y(psi_y) R_Z(psi_z), Tait-Bryan angles Y-Z). Its axis is the image
of the bearing axis X:

    a = R X = (cos psi_y cos psi_z,  sin psi_z,  -sin psi_y cos psi_z),

a unit vector for every angle (exact, no small-angle assumption). psi_y > 0 turns the +X end of
the axis towards -Z (a positive rotation about +Y). The angular velocity of the tilt follows
from R' R^T: omega_tilt = psi_y' Y + psi_z' R_Y(psi_y) Z, i.e.

    omega_tilt = (psi_z' sin psi_y,  psi_y',  psi_z' cos psi_y).

At psi_y = psi_z = 0, a = (1, 0, 0) exactly, so the aligned ring reproduces the untilted
contact geometry to the last bit.
"""

from __future__ import annotations

import jax.numpy as jnp
from jaxtyping import Array, Float


def ring_axis(tilt: Float[Array, "... 2"]) -> Float[Array, "... 3"]:
    """a = (cos psi_y cos psi_z, sin psi_z, -sin psi_y cos psi_z) for tilt = (psi_y, psi_z)."""
    ty, tz = tilt[..., 0], tilt[..., 1]
    return jnp.stack([jnp.cos(ty) * jnp.cos(tz), jnp.sin(tz), -jnp.sin(ty) * jnp.cos(tz)], axis=-1)


def ring_tilt_angular_velocity(tilt: Float[Array, "... 2"], tilt_rate: Float[Array, "... 2"]) -> Array:
    """omega_tilt = (psi_z' sin psi_y, psi_y', psi_z' cos psi_y) (module docstring)."""
    ty = tilt[..., 0]
    dy, dz = tilt_rate[..., 0], tilt_rate[..., 1]
    return jnp.stack([dz * jnp.sin(ty), dy, dz * jnp.cos(ty)], axis=-1)
