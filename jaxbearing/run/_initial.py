"""The initial state of a run: the quasi-static load distribution (`dynamics.quasi_static`) with
pure-rolling speeds, plus a seeded `Perturbation` of the rollers' axial positions and skew (a
perfectly symmetric bearing never skews in a deterministic model; real rollers start with
manufacturing scatter); or, `skid_start`, the same positions with the speeds of steady running
(`dynamics.skid_equilibrium`: cage and roller speeds from the skid balance, rollers against the
pocket side they are pushed to, cage centre at its land equilibrium), solved in one compiled
call per bearing structure and never inside a vmap over cases."""

from __future__ import annotations

import dataclasses

import equinox as eqx
import jax
import jax.numpy as jnp

from ..dynamics import (
    Accumulators,
    CageState,
    Params,
    RingState,
    RollerState,
    SkidEquilibrium,
    State,
    cage_time_constant,
    quasi_static,
    skid_equilibrium,
    tangential_unit,
)
from ..geometry import Bearing, OperatingPoint, kinematic_cage_speed


@dataclasses.dataclass(frozen=True)
class Perturbation:
    """Seeded initial scatter of the rollers (uniform in +/- the amplitudes)."""

    seed: int = 0
    axial: float = 0.02e-3  # [m]
    skew: float = 1e-4  # [rad]


def traced_scatter(perturbation: Perturbation | None):
    """The perturbation as arrays (seed, axial, skew), so that seeds and amplitudes are traced
    arguments of a compiled program and never force a recompilation; None stays None."""
    if perturbation is None:
        return None
    return (
        jnp.asarray(perturbation.seed, jnp.int32),
        jnp.asarray(perturbation.axial, float),
        jnp.asarray(perturbation.skew, float),
    )


def perturbation_of(scatter) -> Perturbation | None:
    """Inverse of `traced_scatter` (inside the compiled program)."""
    return None if scatter is None else Perturbation(seed=scatter[0], axial=scatter[1], skew=scatter[2])


#: the starts a run may use
STARTS = ("skid", "quasi-static")


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


class SkidStart(eqx.Module):
    """The skid start of a run: its state, the equilibrium's residuals, and the time constant
    [s] of the cage speed's slow approach to steady running (`dynamics.cage_time_constant`)."""

    state: State
    equilibrium: SkidEquilibrium
    time_constant: jax.Array


def _skid(bearing, op, scatter):
    start = initial_state(bearing, op, perturbation_of(scatter))
    params = Params(bearing=bearing, operating=op)
    eq = skid_equilibrium(start, params, kinematic_cage_speed(bearing, op))
    return SkidStart(state=eq.state, equilibrium=eq, time_constant=cage_time_constant(eq, params))


_COMPILED: dict = {}


def skid_start(bearing: Bearing, op: OperatingPoint, perturbation: Perturbation | None) -> SkidStart:
    """`initial_state`'s positions with the speeds of steady running (module docstring).

    Compiled once per bearing structure (seeds, speeds and loads reuse it); runs outside any
    vmap (a vmapped bisection costs several times more per case)."""
    scatter = traced_scatter(perturbation)
    dyn = (bearing, op, scatter)
    leaves, treedef = jax.tree_util.tree_flatten(dyn)
    key = (treedef, tuple((jnp.shape(x), jnp.result_type(x)) for x in leaves))
    if key not in _COMPILED:
        _COMPILED[key] = jax.jit(_skid).lower(*dyn).compile()
    return _COMPILED[key](*dyn)
