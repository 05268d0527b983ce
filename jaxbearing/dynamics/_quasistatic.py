"""Quasi-static radial load distribution: the initial state of the dynamic run (docs/model.md 12).

The source study starts from "the quasi-static model in ref. [30] (pp. 64-75)", Harris' Rolling
Bearing Analysis; here: the radial load distribution of Harris & Kotzalas (Essential Concepts of
Bearing Technology, ch. 7) with the centrifugal force of high-speed operation (Advanced Concepts
of Bearing Technology), clearance, and the slice law of `_raceway`, so that the dynamic run
starts in equilibrium.

Roller j sits at azimuth psi_j = 2 pi j / Z (right-handed about +X, measured from the load
direction +Z, as in `_state.radial_unit`): radial unit e_j = (0, -sin psi_j, cos psi_j), centre
p_j = r_j e_j. The inner ring is displaced by d = (d_y, d_z) in the radial plane; the outer ring is
fixed. Rings are rigid and their displacement small against the pitch radius (Harris' kinematics
of the load distribution): the inner raceway's approach towards roller j is d.e_j. For an aligned
roller the slice interferences are then those of `_raceway.raceway_slice_geometry` to first
order in |d|/r_j. The neglected term, |d|^2 sin^2(psi_j)/(2 r_j), is 5e-10 m at most over the
loaded rollers of the reference operating point (d = 14 um): the dynamic run starts with inner
loads up to 0.3 % below these on the flank rollers (crowned rollers are sensitive to it), a
small start-up transient. The linear kinematics is kept because it is the load-distribution
theory the Stribeck oracle (docs/model.md 12) is stated in:

    inner approach  a_i,j = R_i + D/2 + d.e_j - r_j
    outer approach  a_o,j = r_j + D/2 - R_o
    slice loads     q_j,k = (k_c/N_s) softplus_w(a - c(xi_k))^(10/9)     (`_raceway`)
    Q_i,j = sum_k q(a_i,j),   Q_o,j = sum_k q(a_o,j).

Equilibrium (forces along e_j on roller j; all vectors on the inner ring):

    roller j:    Q_o,j = Q_i,j + F_c + m_b g (e_j . Z),      F_c = m_b (d_m/2) omega_c^2
    inner ring:  sum_j Q_i,j e_j = (F_r + m_i g) Z,

with the orbital speed omega_c = omega_i (1 - D/d_m)/2 of pure rolling on a fixed outer ring
(Harris & Kotzalas, Essential Concepts, Eq. 8.13 with zero contact angle). F_c is taken at the
pitch radius, as Harris does; the dynamic model's centripetal term m_b r_j omega_c^2 differs by
m_b (r_j - d_m/2) omega_c^2, about 0.03 N at the reference operating point. The contact force on
roller j from a displaced ring points from the ring centre, not exactly along e_j; the
tangential remainder (order Q |d|/r_j, millinewtons) is carried by the cage and left out here.

Solution: each roller's radial position solves its own monotone 1-D equation (Q_o - Q_i increases
with r_j) by bisection on a bracket that always contains the root; the ring displacement d solves
the 2-vector ring equation by Newton's method started from an overestimate (one roller carrying
the whole load), where the load is convex in d and Newton converges monotonically. Both loops run
on stop-gradient copies of the parameters; the returned solution is then moved by one Newton
step of the full-parameter equations, so its first derivatives with respect to every float
parameter are exactly the implicit-function derivatives (-J^-1 dF/dtheta) and the loops are never
differentiated. A roller with neither contact loaded (zero speed, no gravity, in the clearance)
has an indeterminate position; it is placed in the middle of its free range and contributes no
load and no derivative.

Speeds: cage and roller orbit omega_c; roller spin (absolute angular velocity about +X, the
roller axis) omega_b = -omega_c d_m / D from pure rolling on the fixed outer raceway, i.e.
-(d_m/2D)(1 - D^2/d_m^2) omega_i relative to the cage (Harris & Kotzalas, Essential Concepts,
ch. 8, zero contact angle).
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Float

from ..contact import PENETRATION_WIDTH
from ..forces import (
    raceway_stiffness,
    slice_loads_from_interference,
    slice_positions,
    uniform_approach_interference,
)
from ..geometry import Bearing, OperatingPoint, kinematic_cage_speed
from ..io import check_model_inputs

#: bisection steps of each roller's 1-D equilibrium (bracket of ~1e-4 m down to below 1e-20 m).
_BISECTION_STEPS = 64
#: maximum Newton iterations on the ring displacement.
_MAX_NEWTON = 60
#: ring force residual that stops Newton, relative to the ring load F_r + m_i g.
_NEWTON_RTOL = 1e-13


class QuasiStatic(eqx.Module):
    """Quasi-static solution (SI units; Z rollers, N_s slices)."""

    azimuth: Float[Array, " Z"]  # psi_j [rad], from +Z, right-handed about +X
    inner_ring_displacement: Float[Array, 2]  # (d_y, d_z) [m]
    roller_radius: Float[Array, " Z"]  # r_j, roller centre distance from the bearing axis [m]
    inner_approach: Float[Array, " Z"]  # a_i,j [m] (uncrowned generatrix)
    outer_approach: Float[Array, " Z"]  # a_o,j [m]
    inner_load: Float[Array, " Z"]  # Q_i,j [N]
    outer_load: Float[Array, " Z"]  # Q_o,j [N]
    inner_slice_loads: Float[Array, "Z N_s"]
    outer_slice_loads: Float[Array, "Z N_s"]
    cage_speed: Float[Array, ""]  # omega_c = roller orbital speed [rad/s]
    roller_spin: Float[Array, ""]  # absolute spin about +X (roller axis) [rad/s]
    centrifugal_force: Float[Array, ""]  # F_c [N]
    ring_residual: Float[Array, 2]  # sum_j Q_i,j e_j - (F_r + m_i g) Z, (Y, Z) [N]

    @property
    def roller_orbital_speed(self) -> Array:
        """Orbital speed of every roller centre: omega_c [rad/s]."""
        return self.cage_speed

    @property
    def radial_units(self) -> Float[Array, "Z 3"]:
        """e_j = (0, -sin psi_j, cos psi_j)."""
        return _radial_unit(self.azimuth)

    @property
    def roller_centres(self) -> Float[Array, "Z 3"]:
        """p_j = r_j e_j [m]."""
        return self.roller_radius[:, None] * self.radial_units

    @property
    def inner_ring_centre(self) -> Float[Array, 3]:
        """(0, d_y, d_z) [m]."""
        return jnp.concatenate([jnp.zeros(1), self.inner_ring_displacement])


def _radial_unit(psi):
    z = jnp.zeros_like(psi)
    return jnp.stack([z, -jnp.sin(psi), jnp.cos(psi)], axis=-1)


class _Problem(eqx.Module):
    """The float inputs of the equilibrium equations (so they can be stop-gradient'ed whole)."""

    bearing: Bearing
    ring_load: Array  # F_r + m_i g [N]
    roller_external: Array  # (Z,) F_c + m_b g cos psi_j, outward [N]
    radial_units_yz: Array  # (Z, 2)
    #: (Z,) slope of the inner slice interferences along the roller from the imposed
    #: misalignment psi_m, -sin(psi_m) cos(psi_j), and the approach it adds at the roller centre,
    #: (d_m/2)(1 - sqrt(1 - sin^2(psi_m) cos^2(psi_j))) (the roller centre's distance from the
    #: tilted axis; docs/model.md 12; both 0 for an aligned ring)
    inner_tilt_slope: Array
    inner_tilt_approach: Array


def _loads(prob: _Problem, a_i, a_o):
    b = prob.bearing
    tilt = prob.inner_tilt_slope[:, None] * slice_positions(b) + prob.inner_tilt_approach[:, None]
    qi = slice_loads_from_interference(b, uniform_approach_interference(b, a_i) + tilt, PENETRATION_WIDTH)
    qo = slice_loads_from_interference(b, uniform_approach_interference(b, a_o), PENETRATION_WIDTH)
    return qi, qo


def _approaches(prob: _Problem, d, r):
    b = prob.bearing
    half_d = b.roller.diameter / 2
    a_i = b.inner_raceway_radius + half_d + prob.radial_units_yz @ d - r
    a_o = r + half_d - b.outer_raceway_radius
    return a_i, a_o


@jax.jit
def _roller_residual(prob: _Problem, d, r):
    """f_j(r_j) = Q_o,j - Q_i,j - F_ext,j (increasing in r_j)."""
    a_i, a_o = _approaches(prob, d, r)
    qi, qo = _loads(prob, a_i, a_o)
    return jnp.sum(qo, -1) - jnp.sum(qi, -1) - prob.roller_external


def _deflection_bound(prob: _Problem, load):
    """Approach at which the straight central slices alone carry `load` (an overestimate of the
    approach of one contact under `load`, crown included): (N_s load / (k_c n_c))^(9/10)."""
    b = prob.bearing
    k_c = raceway_stiffness(b)
    n = b.num_slices
    n_central = jnp.maximum(jnp.floor(b.roller.central_length / b.roller.effective_length * n), 1.0)
    return (n * jnp.abs(load) / (k_c * n_central)) ** 0.9


@jax.jit
def _solve_rollers(prob: _Problem, d):
    """Roller radial positions r_j(d) by bisection (no gradient; see `_roller_positions`)."""
    b = prob.bearing
    half_d = b.roller.diameter / 2
    r_inner_touch = b.inner_raceway_radius + half_d + prob.radial_units_yz @ d
    r_outer_touch = b.outer_raceway_radius - half_d
    margin = (
        _deflection_bound(prob, prob.roller_external)
        + b.roller.crown_drop
        + jnp.abs(prob.inner_tilt_slope) * b.roller.effective_length / 2
        + 1e3 * PENETRATION_WIDTH
    )
    lo0 = jnp.minimum(r_inner_touch, r_outer_touch) - margin
    hi0 = jnp.maximum(r_inner_touch, r_outer_touch) + margin

    def bisect(strict):
        # strict: f > 0 moves hi (finds the upper end of a zero set), else f >= 0 (lower end)
        def body(_, bracket):
            lo, hi = bracket
            mid = 0.5 * (lo + hi)
            f = _roller_residual(prob, d, mid)
            up = (f > 0) if strict else (f >= 0)
            return jnp.where(up, lo, mid), jnp.where(up, mid, hi)

        lo, hi = jax.lax.fori_loop(0, _BISECTION_STEPS, body, (lo0, hi0))
        return 0.5 * (lo + hi)

    return 0.5 * (bisect(True) + bisect(False))


def _roller_positions(prob: _Problem, d):
    """r_j(d) with implicit-function derivatives: r = r* - f(r*)/f'(r*) at the bisection root r*
    (value unchanged, derivatives -f_theta/f_r); a flat root (f' = 0, unloaded) gets none."""
    r_star = _solve_rollers(jax.lax.stop_gradient(prob), jax.lax.stop_gradient(d))
    # f_j depends on r_j only: the diagonal derivative is one forward-mode product
    _, f_r = jax.jvp(lambda r: _roller_residual(prob, d, r), (r_star,), (jnp.ones_like(r_star),))
    f_r = jax.lax.stop_gradient(f_r)
    f = _roller_residual(prob, d, r_star)
    ok = f_r > 0
    return r_star - jnp.where(ok, f / jnp.where(ok, f_r, 1.0), 0.0)


def _ring_residual(prob: _Problem, d):
    """F(d) = sum_j Q_i,j e_j - (F_r + m_i g) Z in (Y, Z) components [N]."""
    r = _roller_positions(prob, d)
    a_i, a_o = _approaches(prob, d, r)
    qi, _ = _loads(prob, a_i, a_o)
    q_inner = jnp.sum(qi, -1)
    return q_inner @ prob.radial_units_yz - jnp.array([0.0, 1.0]) * prob.ring_load


def _solve_ring(prob: _Problem):
    """Newton on F(d) = 0 from an overestimate of d_z (no gradient; see `quasi_static`)."""
    prob = jax.lax.stop_gradient(prob)
    b = prob.bearing
    half_gap = (b.outer_raceway_radius - b.inner_raceway_radius - b.roller.diameter) / 2
    f0 = prob.roller_external[0]
    d0 = jnp.stack(
        [
            jnp.zeros(()),
            jnp.maximum(2 * half_gap, 0.0)
            + _deflection_bound(prob, prob.ring_load)
            + _deflection_bound(prob, jnp.maximum(prob.ring_load + f0, 0.0))
            + 2 * b.roller.crown_drop,
        ]
    )
    scale = jnp.maximum(jnp.abs(prob.ring_load), 1e-300)
    # Jacobian and residual from one forward-mode pass
    jac_fn = jax.jacfwd(lambda d: (_ring_residual(prob, d),) * 2, has_aux=True)

    def step(carry):
        i, d, _ = carry
        jac, f = jac_fn(d)
        # tiny Tikhonov term: a ring with no loaded roller (J = 0) stays where it is
        reg = 1e-14 * (jnp.max(jnp.abs(jac)) + 1e-300) * jnp.eye(2)
        dd = jnp.linalg.solve(jac + reg, -f)
        return i + 1, d + dd, jnp.max(jnp.abs(f)) / scale

    def cond(carry):
        i, _, res = carry
        return (i < _MAX_NEWTON) & (res > _NEWTON_RTOL)

    _, d, _ = jax.lax.while_loop(cond, step, (0, d0, jnp.asarray(jnp.inf)))
    return d


def quasi_static(bearing: Bearing, op: OperatingPoint) -> QuasiStatic:
    """Quasi-static radial load distribution with centrifugal force, gravity, clearance and
    crowned slices (module docstring). jit-able; differentiable w.r.t. every float parameter.

    Raises `ConfigError` (a `UserInputError`, naming the configuration key) for any value out of
    its configuration range (`jaxbearing.io.check_model_inputs`: a negative radial load or
    gravity, a non-finite speed, rollers that do not fit...); traced values are not checked.
    """
    check_model_inputs(bearing, op)
    # A bearing closed over by a caller's jit is a set of constants, and XLA then specialises
    # the Newton loops on them: a quasi-static start took 0.21 s instead of 0.036 s
    # (benchmarks/results/diagnose_atol_cost.json). The barrier makes them opaque values, as arguments are.
    bearing, op = jax.lax.optimization_barrier((bearing, op))
    z = bearing.num_rollers
    psi = 2 * jnp.pi * jnp.arange(z) / z
    e = _radial_unit(psi)
    omega_c = kinematic_cage_speed(bearing, op)
    m_b = bearing.roller_mass
    f_c = m_b * (bearing.pitch_diameter / 2) * omega_c**2
    prob = _Problem(
        bearing=bearing,
        ring_load=op.radial_load + bearing.inner_ring_mass * op.gravity,
        roller_external=f_c + m_b * op.gravity * e[:, 2],
        radial_units_yz=e[:, 1:],
        inner_tilt_slope=-jnp.sin(op.misalignment) * jnp.cos(psi),
        inner_tilt_approach=(bearing.pitch_diameter / 2)
        * (1 - jnp.sqrt(1 - (jnp.sin(op.misalignment) * jnp.cos(psi)) ** 2)),
    )

    d_star = _solve_ring(prob)
    # one Newton step of the full-parameter equation: same value, implicit-function derivatives
    jac = jax.lax.stop_gradient(jax.jacfwd(lambda d: _ring_residual(prob, d))(d_star))
    reg = 1e-14 * (jnp.max(jnp.abs(jac)) + 1e-300) * jnp.eye(2)
    d = d_star - jnp.linalg.solve(jac + reg, _ring_residual(prob, d_star))

    r = _roller_positions(prob, d)
    a_i, a_o = _approaches(prob, d, r)
    qi, qo = _loads(prob, a_i, a_o)
    residual = jnp.sum(qi, -1) @ prob.radial_units_yz - jnp.array([0.0, 1.0]) * prob.ring_load
    return QuasiStatic(
        azimuth=psi,
        inner_ring_displacement=d,
        roller_radius=r,
        inner_approach=a_i,
        outer_approach=a_o,
        inner_load=jnp.sum(qi, -1),
        outer_load=jnp.sum(qo, -1),
        inner_slice_loads=qi,
        outer_slice_loads=qo,
        cage_speed=omega_c,
        roller_spin=-omega_c * bearing.pitch_diameter / bearing.roller.diameter,
        centrifugal_force=f_c,
        ring_residual=residual,
    )
