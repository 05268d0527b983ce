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
- the cage torque, with the rollers in equilibrium, mostly decreases with the cage speed (a
  faster cage drives its rollers faster than the raceways roll them, the traction brakes them
  and they push back on the pockets): the Illinois regula falsi on omega_c in [0.2, 1.02] x
  kinematic. Near the skid onset it need not be monotone: where the traction peak can carry the
  rollers at nearly pure rolling it has three roots (skid, unstable, near rolling; at 20,000 rpm
  and 1000 N, docs/validation.md "The skid regime"), and the regula falsi returns the skid root,
  where the dynamics started from pure rolling settle too (`balanced_cage_torque` scans it);
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

from ..forces import cage_drag_torque, cage_land_forces, roller_drag
from ._field import Params, contact_loads, physical_rates
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


class SkidBalance(eqx.Module):
    """The terms of the skid balance at one state, each from the vector field's own force laws.

    Orbit torques [N m] about the bearing axis on roller j, r_j F.e_tan (r_j its orbit radius,
    e_tan its tangential unit): from the inner and outer raceway traction (all slices), the four
    flange contacts, the pocket, the oil-air drag (`forces.roller_drag`) and gravity. Their sum
    is r_j m_b (r_j theta_j'' + 2 r_j' theta_j'), zero in the orbit balance.
    Spin moments [N m] about roller j's axis e_j, M.e_j: the same contacts and the drag's spin
    torque; their sum is I_a (d omega_j/dt).e_j, zero in the spin balance.
    Cage torques [N m] about the bearing axis: all pockets, the guiding-land film
    (`forces.cage_land_forces`) and churning (`forces.cage_drag_torque`); their sum is
    I_p omega_c', zero in the cage balance.
    `loaded`: the rollers with an inner-raceway load (the loaded zone); `inner_sliding`,
    `outer_sliding` [m/s]: each roller's load-weighted mean sliding speed on the raceway
    (the argument du of the traction curve kappa(du), docs/model.md 8); `inner_load`,
    `outer_load` [N]: the raceway normal loads Q."""

    loaded: Array
    inner_load: Float[Array, " Z"]
    outer_load: Float[Array, " Z"]
    inner_sliding: Float[Array, " Z"]
    outer_sliding: Float[Array, " Z"]
    orbit_inner: Float[Array, " Z"]
    orbit_outer: Float[Array, " Z"]
    orbit_flange: Float[Array, " Z"]
    orbit_pocket: Float[Array, " Z"]
    orbit_drag: Float[Array, " Z"]
    orbit_gravity: Float[Array, " Z"]
    spin_inner: Float[Array, " Z"]
    spin_outer: Float[Array, " Z"]
    spin_flange: Float[Array, " Z"]
    spin_pocket: Float[Array, " Z"]
    spin_drag: Float[Array, " Z"]
    cage_pocket: Float[Array, ""]
    cage_land: Float[Array, ""]
    cage_drag: Float[Array, ""]


def skid_balance(state: State, params: Params) -> SkidBalance:
    """The terms of the roller orbit, roller spin and cage torque balances at `state`
    (`SkidBalance`), e.g. at `skid_equilibrium(...).state`: the same contacts as
    `physical_rates` (`contact_loads`, `roller_drag`, `cage_land_forces`, `cage_drag_torque`),
    resolved by body, direction and contact instead of summed."""
    b = params.bearing
    r = state.rollers
    loads = contact_loads(state, params)
    e = r.axis / jnp.linalg.norm(r.axis, axis=-1, keepdims=True)
    spin = jnp.sum(r.angular_velocity * e, axis=-1)
    drag_f, drag_m = jax.vmap(roller_drag, in_axes=(None, 0, 0))(b, r.velocity, spin)
    lever = r.radial[:, None] * tangential_unit(r.azimuth)

    def orbit(force):
        return jnp.sum(force * lever, axis=-1)

    def about_axis(moment):
        return jnp.sum(moment * e, axis=-1)

    weight = b.roller_mass * params.operating.gravity * jnp.array([0.0, 0.0, 1.0])
    fl = loads.flange
    cage = state.cage
    cage_c = jnp.concatenate([jnp.zeros(1), cage.centre])
    cage_v = jnp.concatenate([jnp.zeros(1), cage.velocity])
    _, land_m = cage_land_forces(b, cage_c, cage_v, cage.speed)
    return SkidBalance(
        loaded=loads.inner.normal_load > 0,
        inner_load=loads.inner.normal_load,
        outer_load=loads.outer.normal_load,
        inner_sliding=loads.inner.mean_sliding_speed,
        outer_sliding=loads.outer.mean_sliding_speed,
        orbit_inner=orbit(loads.inner.force_on_roller),
        orbit_outer=orbit(loads.outer.force_on_roller),
        orbit_flange=orbit(jnp.sum(fl.force_on_roller, axis=1)),
        orbit_pocket=orbit(loads.pocket.force_on_roller),
        orbit_drag=orbit(drag_f),
        orbit_gravity=orbit(jnp.broadcast_to(weight, drag_f.shape)),
        spin_inner=about_axis(loads.inner.moment_on_roller),
        spin_outer=about_axis(loads.outer.moment_on_roller),
        spin_flange=about_axis(jnp.sum(fl.moment_on_roller, axis=1)),
        spin_pocket=about_axis(loads.pocket.moment_on_roller),
        spin_drag=drag_m,
        cage_pocket=jnp.sum(loads.pocket.moment_on_cage[:, 0]),
        cage_land=land_m,
        cage_drag=cage_drag_torque(b, cage.speed),
    )


def balanced_cage_torque(state: State, params: Params, cage_speed) -> tuple[Array, SkidBalance]:
    """M(omega_c): the cage torque [N m] about the bearing axis with every roller in its spin and
    orbit balance at cage speed `cage_speed` (the function whose root `skid_equilibrium` seeks),
    at the positions and cage centre of `state` (e.g. the equilibrium's), and its `SkidBalance`.

    The regula falsi of `skid_equilibrium` takes M as decreasing in omega_c. Where the traction
    curve's peak lets the loaded rollers carry the drag at nearly pure rolling, M also has roots
    near the kinematic speed (docs/validation.md, "The skid regime"): scanning M over omega_c
    shows every balance, stable where M falls through zero."""
    params, state = jax.lax.stop_gradient((params, state))
    z = state.rollers.azimuth.shape[0]
    offset0 = state.rollers.azimuth - 2 * jnp.pi * jnp.arange(z) / z
    spin, offset, _, _ = _roller_balance(params, state, cage_speed, state.cage.centre, offset0)
    balanced = _with_unknowns(state, cage_speed, spin, offset, state.cage.centre)
    terms = skid_balance(balanced, params)
    return terms.cage_pocket + terms.cage_land + terms.cage_drag, terms


class SkidZones(eqx.Module):
    """A `SkidBalance` summed by zone: torques [N m] about the bearing axis on the roller set
    (the loaded zone: rollers with an inner-raceway load) and on the cage, and the loaded
    rollers' mean raceway sliding speeds [m/s]. The roller-set terms add up to minus the
    pocket term (the roller orbit balance), the cage terms to zero (the cage balance)."""

    inner_traction_loaded: Float[Array, ""]
    outer_traction_loaded: Float[Array, ""]
    outer_traction_unloaded: Float[Array, ""]
    roller_drag: Float[Array, ""]
    flange: Float[Array, ""]
    gravity: Float[Array, ""]
    pocket_on_rollers: Float[Array, ""]
    cage_pocket: Float[Array, ""]
    cage_land: Float[Array, ""]
    cage_drag: Float[Array, ""]
    inner_load: Float[Array, ""]  # sum_j Q_i,j [N]
    inner_sliding_loaded: Float[Array, ""]
    outer_sliding_loaded: Float[Array, ""]


def skid_zones(t: SkidBalance) -> SkidZones:
    """`SkidZones` of the balance `t` (sums over the loaded and unloaded rollers)."""
    ld = t.loaded
    return SkidZones(
        inner_traction_loaded=jnp.sum(jnp.where(ld, t.orbit_inner, 0.0)),
        outer_traction_loaded=jnp.sum(jnp.where(ld, t.orbit_outer, 0.0)),
        outer_traction_unloaded=jnp.sum(jnp.where(ld, 0.0, t.orbit_outer)),
        roller_drag=jnp.sum(t.orbit_drag),
        flange=jnp.sum(t.orbit_flange),
        gravity=jnp.sum(t.orbit_gravity),
        pocket_on_rollers=jnp.sum(t.orbit_pocket),
        cage_pocket=t.cage_pocket,
        cage_land=t.cage_land,
        cage_drag=t.cage_drag,
        inner_load=jnp.sum(t.inner_load),
        inner_sliding_loaded=jnp.sum(jnp.where(ld, t.inner_sliding, 0.0)) / jnp.sum(ld),
        outer_sliding_loaded=jnp.sum(jnp.where(ld, t.outer_sliding, 0.0)) / jnp.sum(ld),
    )
