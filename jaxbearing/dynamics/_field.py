"""The vector field of the whole bearing: `vector_field(t, state, params) -> d(state)/dt`.

Bodies (docs/model.md 2): every roller (3-D translation, axis direction, angular velocity), the cage
(radial translation, rotation) and the inner ring (radial translation; spin prescribed at
omega_i, motor driven; optionally axial translation and tilt, docs/model.md "Misalignment").
The outer ring is fixed.

Forces on each roller (vectorised over rollers with `jax.vmap`, no Python loop):
  inner and outer raceway slices (`_raceway`), four roller-end/flange contacts (`flange`),
  the cage pocket (`_pocket`), oil-air drag (`_drag`) and gravity.
On the cage: all pockets, the outer-ring guiding lands (`_cage_lands`), churning, gravity.
On the inner ring: all inner raceway and flange reactions, the radial load F_r (+Z), the axial
load F_a (+X), gravity.

Equations of motion
-------------------
Roller centre in cylindrical coordinates (paper Eq. 33, exact, no small angles):

    m x''     = F.X
    m r''     = F.e_rad + m r theta'^2
    m r theta'' = F.e_tan - 2 m r' theta'

Roller attitude: axis e' = omega x e and Euler's equations with their gyroscopic terms (which
the paper's Eq. 33 omits), in `_rigid_body.axisymmetric_body_rates`.
Cage: m_c c'' = F_c (radial), I_p omega_c' = M_c.X. Inner ring: m_i c_i'' = F_i (radial);
with its switches on, m_i x_i'' = F_i.X + F_a and the tilt (psi_y, psi_z) below.

Inner-ring pose: axis a = `geometry.ring_axis(psi_m + tilt_y, tilt_z)` (psi_m the imposed
misalignment about +Y), centre (x_i, y_i, z_i), angular velocity omega_i a + omega_tilt
(`geometry.ring_tilt_angular_velocity`). Every inner raceway slice and inner flange uses this
axis and centre (`raceway_contact(..., ring_axis=a)`, `all_flange_contacts(...,
inner_ring_axis=a)`). Tilt equations: the ring's angular momentum H = I_a omega_i a + I_t
omega_perp with a' = (0, psi_z', -psi_y') and omega_perp = (0, psi_y', psi_z') to first order in
the tilt (the misalignment is a few mrad), so dH/dt = M gives

    I_t psi_y'' = M_perp.Y - I_a omega_i psi_z',     I_t psi_z'' = M_perp.Z + I_a omega_i psi_y',

with M_perp = M - (M.a) a the contact moment about the ring centre less its part along the spin
axis (taken by the drive, which prescribes omega_i), and (I_a, I_t) = `Bearing.inner_ring_inertia`.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from ..flange import FLANGE_ORDER, all_flange_contacts
from ..forces import (
    PocketContact,
    RacewayContact,
    cage_drag_torque,
    cage_land_forces,
    pocket_contact,
    raceway_contact,
    roller_drag,
)
from ..geometry import Bearing, OperatingPoint, ring_axis, ring_tilt_angular_velocity
from ._rigid_body import axisymmetric_body_rates
from ._state import (
    Accumulators,
    CageState,
    RingState,
    RollerState,
    State,
    radial_unit,
    tangential_unit,
)

X = np.array([1.0, 0.0, 0.0])  # numpy: importing must not start the JAX backend

#: names of the four flanges along the last axis of every per-flange array (`FLANGE_ORDER`)
FLANGE_NAMES = ("inner_left", "inner_right", "outer_left", "outer_right")
#: clip [m] of the contact-height deviation inside the log-sum-exp integrands (finite at the
#: unphysical states diffrax visits during step rejection; far beyond any real contact height)
HEIGHT_DEVIATION_CLIP = 5e-3


class Functionals(eqx.Module):
    """Parameters of the smooth peak functionals integrated inside the solve (docs/model.md 13)."""

    pv_reference: float = 1e9  # PV_ref [Pa m/s]
    pv_exponent: float = 8.0  # p of the p-norm over time
    height_reference: float = 2.0e-3  # h_ref [m]
    height_sharpness: float = 1.0 / 20e-6  # beta [1/m]
    contact_load: float = 0.1  # Q_0 of the contact indicator w(Q) = Q / (Q + Q_0) [N]


class Params(eqx.Module):
    """Everything the vector field needs besides the state (all differentiable floats)."""

    bearing: Bearing
    operating: OperatingPoint
    functionals: Functionals = Functionals()


class Loads(eqx.Module):
    """Every contact of one evaluation (for outputs as well as for the vector field)."""

    inner: RacewayContact
    outer: RacewayContact
    flange: object  # flange.FlangeContact with leading shape (Z, 4)
    pocket: PocketContact


class RingPose(eqx.Module):
    """The inner ring's pose and motion in inertial components (module docstring)."""

    centre: Array  # (x_i, y_i, z_i) [m]
    velocity: Array  # [m/s]
    angular_velocity: Array  # omega_i a + omega_tilt [rad/s]
    axis: Array  # unit axis a
    tilt: Array  # attitude angles (psi_m + tilt_y, tilt_z) [rad]


def inner_ring_pose(ring: RingState, op: OperatingPoint) -> RingPose:
    """Centre, velocity, angular velocity and unit axis of the inner ring (module docstring);
    aligned and axially centred, exactly (0, y, z), (0, v_y, v_z), omega_i X and X."""
    tilt = jnp.stack([op.misalignment + ring.tilt[0], ring.tilt[1]])
    a = ring_axis(tilt)
    return RingPose(
        centre=jnp.concatenate([ring.axial[None], ring.centre]),
        velocity=jnp.concatenate([ring.axial_velocity[None], ring.velocity]),
        angular_velocity=op.inner_speed * a + ring_tilt_angular_velocity(tilt, ring.tilt_rate),
        axis=a,
        tilt=tilt,
    )


@jax.jit
def contact_loads(state: State, params: Params) -> Loads:
    """All contacts at a physical (unscaled) state."""
    b, op = params.bearing, params.operating
    r = state.rollers
    e = r.axis / jnp.linalg.norm(r.axis, axis=-1, keepdims=True)
    p, v, w = r.centre, r.velocity, r.angular_velocity

    ring = inner_ring_pose(state.inner_ring, op)
    inner_c, inner_v, inner_w, inner_a = ring.centre, ring.velocity, ring.angular_velocity, ring.axis
    zero = jnp.zeros(3)

    def inner_raceway(p, e, v, w):
        return raceway_contact(
            b, 1.0, b.inner_raceway_radius, p, e, v, w, inner_c, inner_v, inner_w, ring_axis=inner_a
        )

    raceway = jax.vmap(raceway_contact, in_axes=(None, None, None, 0, 0, 0, 0, None, None, None))
    inner = jax.vmap(inner_raceway)(p, e, v, w)
    outer = raceway(b, -1.0, b.outer_raceway_radius, p, e, v, w, zero, zero, zero)
    flange = all_flange_contacts(
        b, p, e, v, w, inner_c, inner_v, inner_w, zero, zero, zero, inner_ring_axis=inner_a
    )

    cage = state.cage
    cage_c = jnp.concatenate([jnp.zeros(1), cage.centre])
    cage_v = jnp.concatenate([jnp.zeros(1), cage.velocity])
    pocket_angle = cage.angle + 2 * jnp.pi * jnp.arange(b.num_rollers) / b.num_rollers
    pocket_c = cage_c + (b.pitch_diameter / 2) * radial_unit(pocket_angle)
    pocket_t = tangential_unit(pocket_angle)
    pocket = jax.vmap(pocket_contact, in_axes=(None, 0, 0, 0, 0, 0, 0, None, None, None))(
        b, p, e, v, w, pocket_c, pocket_t, cage_v, cage.speed * X, cage_c
    )
    return Loads(inner=inner, outer=outer, flange=flange, pocket=pocket)


@jax.jit
def physical_rates(t, state: State, params: Params) -> State:
    """d(state)/dt in physical units: every contact of the state (`contact_loads`), then the
    rates of the rollers, the cage, the inner ring and the smooth flange functionals."""
    del t
    loads = contact_loads(state, params)
    return State(
        rollers=_roller_rates(state.rollers, loads, params),
        cage=_cage_rates(state.cage, loads, params),
        inner_ring=_inner_ring_rates(state.inner_ring, loads, params),
        accumulators=_functional_rates(loads.flange, params.functionals),
    )


def _gravity(op: OperatingPoint) -> Array:
    return op.gravity * jnp.array([0.0, 0.0, 1.0])


def _roller_rates(r: RollerState, loads: Loads, params: Params) -> RollerState:
    """Newton's law in the orbiting (axial, radial, azimuth) coordinates with centrifugal and
    Coriolis terms, and Euler's equations of the axisymmetric roller (gyroscopic terms kept)."""
    b, fl = params.bearing, loads.flange
    m_b = b.roller_mass
    i_a, i_t = b.roller_inertia[0], b.roller_inertia[1]
    e = r.axis / jnp.linalg.norm(r.axis, axis=-1, keepdims=True)
    w = r.angular_velocity
    spin = jnp.sum(w * e, axis=-1)
    drag_f, drag_m = jax.vmap(roller_drag, in_axes=(None, 0, 0))(b, r.velocity, spin)
    force = (
        loads.inner.force_on_roller
        + loads.outer.force_on_roller
        + jnp.sum(fl.force_on_roller, axis=1)
        + loads.pocket.force_on_roller
        + drag_f
        + m_b * _gravity(params.operating)
    )
    moment = (
        loads.inner.moment_on_roller
        + loads.outer.moment_on_roller
        + jnp.sum(fl.moment_on_roller, axis=1)
        + loads.pocket.moment_on_roller
        + drag_m[:, None] * e
    )
    e_rad, e_tan = radial_unit(r.azimuth), tangential_unit(r.azimuth)
    f_r = jnp.sum(force * e_rad, axis=-1)
    f_t = jnp.sum(force * e_tan, axis=-1)
    axis_rate, omega_dot = axisymmetric_body_rates(r.axis, w, moment, i_a, i_t)
    return RollerState(
        axial=r.axial_velocity,
        radial=r.radial_velocity,
        azimuth=r.azimuth_rate,
        axis=axis_rate,
        axial_velocity=force[:, 0] / m_b,
        radial_velocity=f_r / m_b + r.radial * r.azimuth_rate**2,
        azimuth_rate=(f_t / m_b - 2 * r.radial_velocity * r.azimuth_rate) / r.radial,
        angular_velocity=omega_dot,
    )


def _cage_rates(cage: CageState, loads: Loads, params: Params) -> CageState:
    """Cage: radial motion under pocket, land and weight forces; rotation under pocket, land
    and drag torques."""
    b = params.bearing
    cage_c = jnp.concatenate([jnp.zeros(1), cage.centre])
    cage_v = jnp.concatenate([jnp.zeros(1), cage.velocity])
    land_f, land_m = cage_land_forces(b, cage_c, cage_v, cage.speed)
    force = jnp.sum(loads.pocket.force_on_cage, axis=0) + land_f + b.cage_mass * _gravity(params.operating)
    torque = jnp.sum(loads.pocket.moment_on_cage[:, 0]) + land_m + cage_drag_torque(b, cage.speed)
    return CageState(
        centre=cage.velocity,
        angle=cage.speed,
        velocity=force[1:] / b.cage_mass,
        speed=torque / b.cage_inertia[0],
    )


def _inner_ring_rates(ring: RingState, loads: Loads, params: Params) -> RingState:
    """Inner ring: radial motion under raceway and inner-flange forces, the applied radial load
    and its weight (spin prescribed); with the operating point's switches on, axial motion
    under the same forces and the axial load, and tilt under their moments about the ring
    centre with the gyroscopic coupling of the spin (module docstring)."""
    b, op, fl = params.bearing, params.operating, loads.flange
    inner_flanges = jnp.asarray([ring_sign > 0 for ring_sign, _ in FLANGE_ORDER])
    force = (
        jnp.sum(loads.inner.force_on_ring, axis=0)
        + jnp.sum(jnp.where(inner_flanges[None, :, None], fl.force_on_ring, 0.0), axis=(0, 1))
        + op.radial_load * jnp.array([0.0, 0.0, 1.0])
        + op.axial_load * X
        + b.inner_ring_mass * _gravity(op)
    )
    moment = jnp.sum(loads.inner.moment_on_ring, axis=0) + jnp.sum(
        jnp.where(inner_flanges[None, :, None], fl.moment_on_ring, 0.0), axis=(0, 1)
    )
    a = inner_ring_pose(ring, op).axis
    m_perp = moment - jnp.dot(moment, a) * a
    i_a, i_t = b.inner_ring_inertia[0], b.inner_ring_inertia[1]
    gyro = i_a * op.inner_speed * jnp.stack([-ring.tilt_rate[1], ring.tilt_rate[0]])
    f_ax, f_tilt = op.axial_freedom, op.tilt_freedom
    return RingState(
        centre=ring.velocity,
        velocity=force[1:] / b.inner_ring_mass,
        axial=f_ax * ring.axial_velocity,
        axial_velocity=f_ax * force[0] / b.inner_ring_mass,
        tilt=f_tilt * ring.tilt_rate,
        tilt_rate=f_tilt * (m_perp[1:] + gyro) / i_t,
    )


def _functional_rates(fl, fn: Functionals) -> Accumulators:
    """Integrands of the smooth peak functionals (p-norm of PV, log-sum-exp of contact height),
    each weighted by the contact indicator Q / (Q + Q_ref)."""
    q = fl.normal_force
    w_c = q / (q + fn.contact_load)
    # clipped so that states diffrax may visit during step rejection stay finite
    dh = jnp.clip(fl.contact_height - fn.height_reference, -HEIGHT_DEVIATION_CLIP, HEIGHT_DEVIATION_CLIP)
    return Accumulators(
        pv_power=w_c * (fl.pv / fn.pv_reference) ** fn.pv_exponent,
        height_max_power=w_c * jnp.exp(fn.height_sharpness * dh),
        height_min_power=w_c * jnp.exp(-fn.height_sharpness * dh),
        contact_time=w_c,
    )
