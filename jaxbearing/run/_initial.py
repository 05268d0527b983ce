"""The initial state of a run: the quasi-static load distribution (`dynamics.quasi_static`) with
pure-rolling speeds, plus a seeded `Perturbation` of the rollers' axial positions and skew (a
perfectly symmetric bearing never skews in a deterministic model; real rollers start with
manufacturing scatter)."""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp

from ..dynamics import (
    Accumulators,
    CageState,
    RingState,
    RollerState,
    State,
    quasi_static,
    tangential_unit,
)
from ..geometry import Bearing, OperatingPoint, kinematic_cage_speed


@dataclasses.dataclass(frozen=True)
class Perturbation:
    """Seeded initial scatter of the rollers (uniform in +/- the amplitudes)."""

    seed: int = 0
    axial: float = 0.02e-3  # [m]
    skew: float = 1e-4  # [rad]


def initial_state(bearing: Bearing, op: OperatingPoint, perturbation: Perturbation | None) -> State:
    """Quasi-static solution (MODEL.md 5) as the initial state of the dynamic run."""
    qs = quasi_static(bearing, op)
    z = bearing.num_rollers
    omega_c = kinematic_cage_speed(bearing, op)
    azimuth = 2 * jnp.pi * jnp.arange(z) / z
    axial = jnp.zeros(z)
    skew = jnp.zeros(z)
    if perturbation is not None:
        k1, k2 = jax.random.split(jax.random.PRNGKey(perturbation.seed))
        axial = perturbation.axial * jax.random.uniform(k1, (z,), minval=-1.0, maxval=1.0)
        skew = perturbation.skew * jax.random.uniform(k2, (z,), minval=-1.0, maxval=1.0)
    # skew: rotation of the axis about the roller's radial direction, towards e_tan

    axis = jnp.cos(skew)[:, None] * jnp.array([1.0, 0.0, 0.0]) + jnp.sin(skew)[:, None] * tangential_unit(
        azimuth
    )
    # pure rolling on the outer raceway: absolute roller spin -omega_c d_m / D about its axis
    spin = -omega_c * bearing.pitch_diameter / bearing.roller.diameter
    rollers = RollerState(
        axial=axial,
        radial=qs.roller_radius,
        azimuth=azimuth,
        axis=axis,
        axial_velocity=jnp.zeros(z),
        radial_velocity=jnp.zeros(z),
        azimuth_rate=omega_c * jnp.ones(z),
        angular_velocity=spin * axis,
    )
    cage = CageState(centre=jnp.zeros(2), angle=jnp.asarray(0.0), velocity=jnp.zeros(2), speed=omega_c)
    # radial quasi-static position; axially at 0 and at the imposed misalignment, at rest
    ring = RingState.aligned(qs.inner_ring_displacement, jnp.zeros(2))
    zeros = jnp.zeros((z, 4))
    acc = Accumulators(pv_power=zeros, height_max_power=zeros, height_min_power=zeros, contact_time=zeros)
    return State(rollers=rollers, cage=cage, inner_ring=ring, accumulators=acc)
