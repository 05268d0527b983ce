"""State of the whole bearing and the frames it is expressed in.

Frames (docs/model.md 2): inertial X along the bearing axis, Z along the radial load and gravity.
A roller at azimuth theta sits at

    p = x X + r e_rad(theta),  e_rad(theta) = (0, -sin theta, cos theta),
    e_tan(theta) = d e_rad / d theta = X x e_rad = (0, -cos theta, -sin theta),

so theta = 0 is the load direction (+Z) and a positive rotation about +X increases theta.

Roller attitude: the unit axis `e` (inertial components) and the inertial angular velocity
`omega`. The axis follows e' = omega x e; the spin angle about the axis is never integrated
(the roller is axisymmetric), so there is no attitude singularity and no small-angle
assumption for skew or tilt.

The integrator sees a *scaled deviation* of this state (`ScaledState`): every component is
measured from a nominal value (azimuths from the kinematic orbit theta_0 + omega_c t) in units of
a physically meaningful scale (1 um, 1 urad of arc at the pitch radius, 1 mm/s ...), so that
diffrax's rtol and atol mean the same thing for every component (docs/model.md 13).
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Float


def radial_unit(theta: Array) -> Array:
    """e_rad(theta) = (0, -sin theta, cos theta), stacked on the last axis."""
    z = jnp.zeros_like(theta)
    return jnp.stack([z, -jnp.sin(theta), jnp.cos(theta)], axis=-1)


def tangential_unit(theta: Array) -> Array:
    """e_tan(theta) = X x e_rad(theta) = (0, -cos theta, -sin theta)."""
    z = jnp.zeros_like(theta)
    return jnp.stack([z, -jnp.cos(theta), -jnp.sin(theta)], axis=-1)


class RollerState(eqx.Module):
    """All rollers (leading dimension Z)."""

    axial: Float[Array, " Z"]  # x_b [m]
    radial: Float[Array, " Z"]  # r_b, distance of the centre from the bearing axis [m]
    azimuth: Float[Array, " Z"]  # theta_b [rad]
    axis: Float[Array, "Z 3"]  # unit roller axis e
    axial_velocity: Float[Array, " Z"]
    radial_velocity: Float[Array, " Z"]
    azimuth_rate: Float[Array, " Z"]  # d theta_b / dt [rad/s]
    angular_velocity: Float[Array, "Z 3"]  # omega (inertial components) [rad/s]

    @property
    def centre(self) -> Array:
        x = self.axial[..., None] * jnp.array([1.0, 0.0, 0.0])
        return x + self.radial[..., None] * radial_unit(self.azimuth)

    @property
    def velocity(self) -> Array:
        return (
            self.axial_velocity[..., None] * jnp.array([1.0, 0.0, 0.0])
            + self.radial_velocity[..., None] * radial_unit(self.azimuth)
            + (self.radial * self.azimuth_rate)[..., None] * tangential_unit(self.azimuth)
        )


class CageState(eqx.Module):
    centre: Float[Array, 2]  # (y_c, z_c) [m]
    angle: Float[Array, ""]  # theta_c [rad]
    velocity: Float[Array, 2]
    speed: Float[Array, ""]  # omega_c [rad/s]


class RingState(eqx.Module):
    """Inner ring: radial position (y_i, z_i) and velocity, axial position x_i and velocity, and
    its tilt (psi_y, psi_z) with rates; its spin is prescribed.

    `tilt` is measured from the imposed misalignment psi_m (`OperatingPoint.misalignment`): the
    ring's attitude angles are (psi_m + tilt[0], tilt[1]) (`geometry.ring_axis`: psi_y about +Y,
    then psi_z about the ring's Z axis). The axial and tilt coordinates move only when the
    operating point's `axial_freedom` / `tilt_freedom` switch is on; otherwise they stay at 0.
    """

    centre: Float[Array, 2]  # (y_i, z_i) [m]
    velocity: Float[Array, 2]
    axial: Float[Array, ""]  # x_i [m]
    axial_velocity: Float[Array, ""]
    tilt: Float[Array, 2]  # (psi_y - psi_m, psi_z) [rad]
    tilt_rate: Float[Array, 2]  # (psi_y', psi_z') [rad/s]

    @staticmethod
    def aligned(centre, velocity) -> RingState:
        """A ring at radial position `centre` with `velocity`, axially at 0 and untilted (beyond
        the imposed misalignment), at rest in its axial and tilt coordinates."""
        return RingState(
            centre=centre,
            velocity=velocity,
            axial=jnp.zeros(()),
            axial_velocity=jnp.zeros(()),
            tilt=jnp.zeros(2),
            tilt_rate=jnp.zeros(2),
        )


class Accumulators(eqx.Module):
    """Smooth functionals integrated inside the solve (docs/model.md 13), per roller and flange.

    pv_power:        int w(Q) (PV / PV_ref)^p dt              -> smooth peak PV (p-norm over time)
    height_max_power: int w(Q) exp(+beta (h_c - h_ref)) dt   -> smooth max contact height
    height_min_power: int w(Q) exp(-beta (h_c - h_ref)) dt   -> smooth min contact height
    contact_time:    int w(Q) dt                              (w: smooth contact indicator)
    """

    pv_power: Float[Array, "Z 4"]
    height_max_power: Float[Array, "Z 4"]
    height_min_power: Float[Array, "Z 4"]
    contact_time: Float[Array, "Z 4"]


class State(eqx.Module):
    rollers: RollerState
    cage: CageState
    inner_ring: RingState
    accumulators: Accumulators


#: one unit of scaled state (`state_scales`): (length [m], linear velocity [m/s], angular
#: velocity [rad/s], axis component [-]). The default absolute tolerance atol = 1e-6 is 1e-6 of
#: these: 10 nm, 10 um/s, 0.01 rad/s, 1e-8. Chosen with
#: benchmarks/bench_work_precision_settled.py (docs/performance.md).
SCALED_UNITS = (1e-2, 10.0, 1e4, 1e-2)


def state_scales(num_rollers: int, pitch_radius: float) -> State:
    """Scale of every state component (one unit of scaled state, `Scaling`).

    The integrator's tolerances apply to the scaled deviation state (docs/model.md 13), so the
    scales decide what the absolute tolerance means. They are chosen so that the paper's
    atol = 1e-6 (docs/model.md 13) is 1e-6 of `SCALED_UNITS`: 10 nm in length (and of arc at the
    pitch radius for orbital angles and the inner ring's tilt), 10 um/s in linear velocity (and
    at the pitch radius for orbital and cage rates), 0.01 rad/s in angular velocity, 1e-8 in
    the axis components. That is two orders of magnitude below the micrometre deflections of
    the contacts and far below the sliding speeds (m/s) that a flange statistic reads; smaller
    scales (1 um per unit, an absolute tolerance of 1 pm) made components whose deviation passes
    through zero hold the step for nothing (docs/performance.md: 1.54x more field evaluations
    at agreeing settled statistics). rtol is relative to the deviation and does not depend on
    the scales. Accumulators are scaled large: they must not steer the step size.
    """
    ones = jnp.ones((num_rollers,))
    length, velocity, rate, axis = SCALED_UNITS
    return State(
        rollers=RollerState(
            axial=length * ones,
            radial=length * ones,
            azimuth=(length / pitch_radius) * ones,
            axis=axis * jnp.ones((num_rollers, 3)),
            axial_velocity=velocity * ones,
            radial_velocity=velocity * ones,
            azimuth_rate=(velocity / pitch_radius) * ones,
            angular_velocity=rate * jnp.ones((num_rollers, 3)),
        ),
        cage=CageState(
            centre=length * jnp.ones(2),
            angle=jnp.asarray(length / pitch_radius),
            velocity=velocity * jnp.ones(2),
            speed=jnp.asarray(velocity / pitch_radius),
        ),
        inner_ring=RingState(
            centre=length * jnp.ones(2),
            velocity=velocity * jnp.ones(2),
            axial=jnp.asarray(length),
            axial_velocity=jnp.asarray(velocity),
            tilt=(length / pitch_radius) * jnp.ones(2),
            tilt_rate=(velocity / pitch_radius) * jnp.ones(2),
        ),
        accumulators=Accumulators(
            pv_power=1e12 * jnp.ones((num_rollers, 4)),
            height_max_power=1e12 * jnp.ones((num_rollers, 4)),
            height_min_power=1e12 * jnp.ones((num_rollers, 4)),
            contact_time=1e12 * jnp.ones((num_rollers, 4)),
        ),
    )


class Scaling(eqx.Module):
    """y = nominal(t) + scale * Y, with the azimuths advancing at the kinematic cage speed."""

    nominal: State
    scale: State
    orbit_speed: Float[Array, ""]  # omega_c of the nominal orbit [rad/s]

    def _drift(self, t) -> State:
        zero = jax.tree_util.tree_map(jnp.zeros_like, self.nominal)
        zero = eqx.tree_at(
            lambda s: s.rollers.azimuth,
            zero,
            self.orbit_speed * t * jnp.ones_like(self.nominal.rollers.azimuth),
        )
        return eqx.tree_at(lambda s: s.cage.angle, zero, self.orbit_speed * t)

    def _drift_rate(self) -> State:
        zero = jax.tree_util.tree_map(jnp.zeros_like, self.nominal)
        zero = eqx.tree_at(
            lambda s: s.rollers.azimuth, zero, self.orbit_speed * jnp.ones_like(self.nominal.rollers.azimuth)
        )
        return eqx.tree_at(lambda s: s.cage.angle, zero, self.orbit_speed)

    def unscale(self, t, scaled: State) -> State:
        drift = self._drift(t)
        return jax.tree_util.tree_map(
            lambda n, d, s, y: n + d + s * y, self.nominal, drift, self.scale, scaled
        )

    def scale_state(self, t, y: State) -> State:
        drift = self._drift(t)
        return jax.tree_util.tree_map(lambda n, d, s, v: (v - n - d) / s, self.nominal, drift, self.scale, y)

    def scale_rate(self, dy: State) -> State:
        rate = self._drift_rate()
        return jax.tree_util.tree_map(lambda d, r, s: (d - r) / s, dy, rate, self.scale)
