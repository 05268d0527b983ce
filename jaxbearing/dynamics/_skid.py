"""Quasi-static skid start: the bearing's steady running speeds before the dynamic run.

The quasi-static load distribution (`_quasistatic`, docs/model.md 12) starts every body at the
kinematic (pure rolling) speeds. Drag, the cage lands and the pockets then slow the cage over
about 100 ms of simulated time at the reference point. This module solves, at the quasi-static
roller positions, the skid equilibrium of Harris' high-speed analysis (Harris & Kotzalas,
"Advanced Concepts of Bearing Technology", 5th ed., ch. 6 "Roller skidding"; Harris 1966,
"An analytical method to predict skidding in high speed roller bearings", ASLE Trans. 9:229-241)
with the dynamic model's own force laws, i.e. the state at which the slow accelerations of the
vector field (`physical_rates`) vanish:

    roller j, spin about its axis e_j:   (d omega_j / dt) . e_j = 0       unknown: spin s_j
    roller j, orbit (tangential):         d^2 theta_j / dt^2     = 0       unknown: offset phi_j
    cage, rotation:                       d omega_c / dt          = 0       unknown: omega_c
    cage, radial (land equilibrium):      d v_c / dt              = 0       unknown: centre c

with every roller orbiting at the cage speed (theta_j' = omega_c), its angular velocity
s_j e_j, its azimuth 2 pi j / Z + phi_j (phi_j: its position inside the pocket, the side the
raceway traction and drag press it to), and everything else (radial positions, inner-ring
displacement, the seeded axial positions and skews) as in the start state passed in. The
raceway traction, drag, pocket normal and friction forces, flange contacts, cage land film and
churning torque are exactly those of the vector field: no law is written twice, and the
dynamics started from the solution begin at their own equilibrium of the slow variables.

Solution (no Jacobian of a flat residual is ever needed; this is why a plain Newton or
Levenberg-Marquardt iteration over all unknowns fails: a roller inside its pocket clearance has
no tangential stiffness):
- each roller's equations depend only on its own unknowns given the cage: for a fixed cage,
  the spin equation is decreasing in s_j and the tangential equation decreasing in phi_j (the
  pocket wall pushes a roller back harder the further it goes in), so both are solved for all
  rollers at once by bisection on brackets that contain the root (the spin between 0 and 1.5
  times the faster of the outer- and inner-raceway rolling spins, the offset across the pocket clearance plus a margin),
  alternately (block Gauss-Seidel; the coupling is the pocket friction moment);
- the cage torque, with the rollers in equilibrium, decreases with the cage speed (a faster cage
  drives its rollers faster than the raceways roll them, the traction brakes them and they push
  back on the pockets): the Illinois regula falsi on omega_c in [0.2, 1.02] x kinematic;
- the cage centre: Newton's method on the 2-vector force balance with the rollers riding along
  with their pockets (smooth: the Ocvirk land film), the step capped inside the guiding
  clearance; cage speed and centre alternate twice.

The solve runs outside any `vmap` over cases (a vmapped bisection costs several times more per
case on a CPU) and is not differentiated (`stop_gradient`): it is a start, not a model output.
Oracle: with no drag, no land film and no gravity, it returns the kinematic speeds
(tests/test_skid.py); the dynamics started from it show no start-up step (0.08 % in the first
revolution at the reference point).

What it cannot know: once running, the rollers skew (about 1 mrad, even with no initial scatter)
and rub the flanges, and that friction is not in a balance at the start positions (the seeded
skews of 0.1 mrad keep the ends off the flanges). At the reference point the static cage speed,
8534 rpm, lies 1.4 % above the plateau the dynamics reach (about 8418 rpm). Adding the flanges'
measured time-mean friction as constant loads would not close the gap either: a constant
correction moves the balance through the static slope of the cage torque, and the running
bearing's slow mode is slower (secants of measured drifts: 62-66 ms) than the static balance's
(`cage_time_constant`, 46 ms), so such a correction stops about a quarter short. `run.skid_start`'s pre-start therefore measures the drift on the dynamics
themselves, twice, and takes a secant step onto the plateau (run/_initial.py).
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Float

from ._field import Params, physical_rates
from ._state import CageState, RollerState, State, tangential_unit

#: bisection steps for each roller's spin and pocket offset (bracket / 2^48 is far below rounding
#: of the residuals)
_BISECTION_STEPS = 48
#: alternations of the spin and offset bisections per cage speed (block Gauss-Seidel)
_GAUSS_SEIDEL_ROUNDS = 3
#: Illinois iterations on the cage speed and their relative tolerance
_SPEED_ITERATIONS = 30
_SPEED_RTOL = 1e-10
#: cage speed bracket, relative to the kinematic speed
SPEED_BRACKET = (0.2, 1.02)
#: Newton steps on the cage centre, alternations of cage speed and centre
_CENTRE_NEWTON = 12
_ALTERNATIONS = 4
#: Newton steps on the cage centre stay within this multiple of the guiding clearance C_g / 2
#: (the cage may ride on its lands: the rub contact beyond the clearance is stiff)
_CENTRE_CAP = 1.02


class SkidEquilibrium(eqx.Module):
    """The skid start: a `State` and how well it balances (accelerations at the solution)."""

    state: State
    cage_speed: Float[Array, ""]  # omega_c [rad/s]
    spin_residual: Float[Array, " Z"]  # (d omega / dt) . e [rad/s^2]
    orbit_residual: Float[Array, " Z"]  # d^2 theta / dt^2 [rad/s^2]
    cage_torque_residual: Float[Array, ""]  # d omega_c / dt [rad/s^2]
    cage_force_residual: Float[Array, 2]  # d v_c / dt [m/s^2]


def _with_unknowns(base: State, omega_c, spin, offset, centre) -> State:
    z = base.rollers.azimuth.shape[0]
    r = base.rollers
    axis = r.axis / jnp.linalg.norm(r.axis, axis=-1, keepdims=True)
    rollers = RollerState(
        axial=r.axial,
        radial=r.radial,
        azimuth=2 * jnp.pi * jnp.arange(z) / z + offset,
        axis=r.axis,
        axial_velocity=jnp.zeros_like(r.axial),
        radial_velocity=jnp.zeros_like(r.radial),
        azimuth_rate=omega_c * jnp.ones_like(r.azimuth),
        angular_velocity=spin[:, None] * axis,
    )
    cage = CageState(centre=centre, angle=jnp.zeros(()), velocity=jnp.zeros(2), speed=omega_c)
    return State(rollers=rollers, cage=cage, inner_ring=base.inner_ring, accumulators=base.accumulators)


def _residuals(params: Params, base: State, omega_c, spin, offset, centre):
    state = _with_unknowns(base, omega_c, spin, offset, centre)
    rates = physical_rates(0.0, state, params)
    axis = base.rollers.axis / jnp.linalg.norm(base.rollers.axis, axis=-1, keepdims=True)
    spin_res = jnp.sum(rates.rollers.angular_velocity * axis, axis=-1)
    return spin_res, rates.rollers.azimuth_rate, rates.cage.speed, rates.cage.velocity


def _balance_brackets(params: Params, omega_c, z: int):
    """The brackets of every roller's spin and pocket offset at cage speed omega_c, each a (lo,
    hi) pair of (Z,) arrays: the spin between 1.5 times the faster of the outer- and
    inner-raceway rolling spins and 0, the offset across the pocket clearance plus a margin of
    0.1 roller diameters (module docstring)."""
    b = params.bearing
    rolling_spin = -omega_c * b.pitch_diameter / b.roller.diameter  # pure rolling on the outer race
    # pure rolling on the inner race (ring at omega_i, roller centre on the pitch circle)
    inner_spin = (
        -(params.operating.inner_speed - omega_c) * (b.pitch_diameter - b.roller.diameter) / b.roller.diameter
    )
    half_range = (b.cage.pocket_clearance / 2 + 0.1 * b.roller.diameter) / (b.pitch_diameter / 2)
    # spin < 0: lo is the faster; the balance lies between the two rolling spins
    s_range = (1.5 * jnp.minimum(rolling_spin, inner_spin) * jnp.ones(z), jnp.zeros(z))
    o_range = (-half_range * jnp.ones(z), half_range * jnp.ones(z))
    return s_range, o_range


def _roller_balance(params: Params, base: State, omega_c, centre, offset0):
    """Each roller's spin and pocket offset at cage speed omega_c: rounds of block Gauss-Seidel,
    each a bisection of every roller's spin equation (decreasing in s_j) at fixed offsets, then
    of its tangential equation (decreasing in phi_j) at fixed spins, all rollers at once and with
    one evaluation of the vector field per step (one call site: one compilation of the field).
    Returns (spin, offset, cage torque residual, cage force residual) at the last evaluation."""
    n = _BISECTION_STEPS
    s_range, o_range = _balance_brackets(params, omega_c, base.rollers.azimuth.shape[0])

    def step(k, carry):
        s_lo, s_hi, o_lo, o_hi, _, _ = carry
        i = k % (2 * n)
        spin_phase = i < n
        s_lo, s_hi = (jnp.where(i == 0, r, v) for r, v in zip(s_range, (s_lo, s_hi)))
        o_lo, o_hi = (jnp.where(i == n, r, v) for r, v in zip(o_range, (o_lo, o_hi)))
        spin, offset = 0.5 * (s_lo + s_hi), 0.5 * (o_lo + o_hi)
        spin_res, orbit_res, torque, force = _residuals(params, base, omega_c, spin, offset, centre)
        res = jnp.where(spin_phase, spin_res, orbit_res)
        up = res > 0  # decreasing residual: the root lies above the midpoint
        s_lo, s_hi = jnp.where(spin_phase & up, spin, s_lo), jnp.where(spin_phase & ~up, spin, s_hi)
        o_lo, o_hi = jnp.where(~spin_phase & up, offset, o_lo), jnp.where(~spin_phase & ~up, offset, o_hi)
        return s_lo, s_hi, o_lo, o_hi, torque, force

    init = (*s_range, offset0, offset0, jnp.zeros(()), jnp.zeros(2))
    s_lo, s_hi, o_lo, o_hi, torque, force = jax.lax.fori_loop(0, 2 * n * _GAUSS_SEIDEL_ROUNDS, step, init)
    return 0.5 * (s_lo + s_hi), 0.5 * (o_lo + o_hi), torque, force


def _cage_speed(params: Params, base: State, centre, offset0, omega_kin):
    """Illinois regula falsi on the cage torque balance (decreasing in omega_c); the first two
    iterations evaluate the bracket's ends. Returns (omega_c, spin, offset)."""
    z = base.rollers.azimuth.shape[0]
    lo, hi = SPEED_BRACKET[0] * omega_kin, SPEED_BRACKET[1] * omega_kin

    def cond(c):
        i, a, b, fa, fb = c[:5]
        open_ = (jnp.abs(b - a) > _SPEED_RTOL * jnp.abs(omega_kin)) & (fa * fb < 0)
        return (i < 2) | ((i < _SPEED_ITERATIONS) & open_)

    def body(c):
        i, a, b, fa, fb, side, _, _, _ = c
        regula = (a * fb - b * fa) / (fb - fa)
        inside = jnp.isfinite(regula) & (regula > jnp.minimum(a, b)) & (regula < jnp.maximum(a, b))
        m = jnp.where(i == 0, a, jnp.where(i == 1, b, jnp.where(inside, regula, 0.5 * (a + b))))
        spin, offset, fm, _ = _roller_balance(params, base, m, centre, offset0)
        left = fm * fa > 0  # root between m and b: m replaces a
        # Illinois: halve the retained end's value when the same end is kept twice
        fb_kept = jnp.where(left & (side == 1), 0.5 * fb, fb)
        fa_kept = jnp.where(~left & (side == -1), 0.5 * fa, fa)
        a2, fa2 = jnp.where(left, m, a), jnp.where(left, fm, fa_kept)
        b2, fb2 = jnp.where(left, b, m), jnp.where(left, fb_kept, fm)
        ends = i < 2  # the first two evaluations are the bracket's ends
        a2, fa2 = jnp.where(ends, a, a2), jnp.where(i == 0, fm, jnp.where(ends, fa, fa2))
        b2, fb2 = jnp.where(ends, b, b2), jnp.where(i == 1, fm, jnp.where(ends, fb, fb2))
        side = jnp.where(i < 2, 0, jnp.where(left, 1, -1))
        return i + 1, a2, b2, fa2, fb2, side, m, spin, offset

    nan = jnp.asarray(jnp.nan)
    init = (0, lo, hi, nan, nan, 0, omega_kin, jnp.zeros(z), offset0)
    *_, m, spin, offset = jax.lax.while_loop(cond, body, init)
    return m, spin, offset


def _cage_centre(params: Params, base: State, omega_c, spin, offset, centre0):
    """Newton on the cage force balance, rollers riding along with their pockets."""
    b = params.bearing
    z = base.rollers.azimuth.shape[0]
    t_yz = tangential_unit(2 * jnp.pi * jnp.arange(z) / z)[:, 1:]
    radius = base.rollers.radial
    cap = _CENTRE_CAP * b.cage.guiding_clearance / 2

    def force(c):
        follow = offset + (t_yz @ (c - centre0)) / radius
        return _residuals(params, base, omega_c, spin, follow, c)[3]

    def step(_, carry):
        c, _ = carry
        jac, f = jax.jacfwd(lambda x: (force(x),) * 2, has_aux=True)(c)
        reg = 1e-12 * (jnp.max(jnp.abs(jac)) + 1e-300) * jnp.eye(2)
        dc = jnp.linalg.solve(jac + reg, -f)
        dc = jnp.where(jnp.all(jnp.isfinite(dc)), dc, 0.0)
        new = c + dc
        norm = jnp.linalg.norm(new)
        new = jnp.where(norm > cap, new * cap / jnp.maximum(norm, 1e-300), new)
        return new, offset + (t_yz @ (new - centre0)) / radius

    return jax.lax.fori_loop(0, _CENTRE_NEWTON, step, (centre0, offset))


def skid_equilibrium(start: State, params: Params, kinematic_speed) -> SkidEquilibrium:
    """The skid equilibrium (module docstring) at the positions of `start` (the quasi-static
    start with its seeded scatter). jit-able; not differentiated (`stop_gradient`)."""
    params, start = jax.lax.stop_gradient((params, start))
    b = params.bearing
    z = start.rollers.azimuth.shape[0]
    omega_kin = jnp.asarray(kinematic_speed)
    # gravity pulls the cage onto the bottom of its lands (+Z): start Newton there, off the
    # centre where the film force is only Lipschitz
    centre0 = jnp.array([0.0, 0.3 * b.cage.guiding_clearance / 2])

    def alternate(k, carry):
        centre, w, spin, offset = carry
        moved, offset_moved = _cage_centre(params, start, w, spin, offset, centre)
        first = k == 0
        centre = jnp.where(first, centre, moved)
        offset = jnp.where(first, offset, offset_moved)
        w, spin, offset = _cage_speed(params, start, centre, offset, omega_kin)
        return centre, w, spin, offset

    init = (centre0, omega_kin, jnp.zeros(z), jnp.zeros(z))
    centre, w, spin, offset = jax.lax.fori_loop(0, _ALTERNATIONS + 1, alternate, init)
    spin_res, orbit_res, torque_res, force_res = _residuals(params, start, w, spin, offset, centre)
    return SkidEquilibrium(
        state=_with_unknowns(start, w, spin, offset, centre),
        cage_speed=w,
        spin_residual=spin_res,
        orbit_residual=orbit_res,
        cage_torque_residual=torque_res,
        cage_force_residual=force_res,
    )


def cage_time_constant(equilibrium: SkidEquilibrium, params: Params, relative_step: float = 2e-3):
    """Time constant [s] of the cage speed's approach to its skid equilibrium: the slow mode
    I_eff d omega_c/dt = M(omega_c), linearised, tau = I_eff / (-dM/d omega_c).

    M(omega_c) is the cage torque with every roller in its spin and orbit balance (central
    difference of the skid equations at +/- `relative_step`); I_eff = dL/d omega_c, with L the
    axial angular momentum of the cage and the rollers riding in it:
    L = I_c omega_c + sum_j (m_b r_j^2 omega_c + I_a s_j(omega_c)) (the rollers' spins follow the
    cage speed through their own balance, also differentiated numerically)."""
    params = jax.lax.stop_gradient(params)
    b = params.bearing
    s = equilibrium.state
    w = equilibrium.cage_speed
    dw = relative_step * w
    offset = (
        s.rollers.azimuth - 2 * jnp.pi * jnp.arange(s.rollers.azimuth.shape[0]) / s.rollers.azimuth.shape[0]
    )
    lo = _roller_balance(params, s, w - dw, s.cage.centre, offset)
    hi = _roller_balance(params, s, w + dw, s.cage.centre, offset)
    i_c, i_a = b.cage_inertia[0], b.roller_inertia[0]
    torque_slope = i_c * (hi[2] - lo[2]) / (2 * dw)
    spin_slope = (hi[0] - lo[0]) / (2 * dw)
    inertia = i_c + jnp.sum(b.roller_mass * s.rollers.radial**2 + i_a * jnp.abs(spin_slope))
    return inertia / -torque_slope
