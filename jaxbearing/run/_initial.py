"""The initial state of a run: the quasi-static load distribution (`dynamics.quasi_static`) with
pure-rolling speeds, plus a seeded `Perturbation` of the rollers' axial positions and skew (a
perfectly symmetric bearing never skews in a deterministic model; real rollers start with
manufacturing scatter); or, `skid_start`, the same positions with the speeds of steady running.

The skid start has two parts (docs/model.md 16):

1. the static skid equilibrium (`dynamics.skid_equilibrium`: cage and roller speeds from the
   skid balance, rollers against the pocket side they are pushed to, cage centre at its land
   equilibrium), solved in one compiled call per bearing structure and never inside a vmap over
   cases;
2. the pre-start, given the run's integrator: what a static balance cannot know (once running,
   the rollers skew to about 1 mrad and rub the flanges; their friction lowers the plateau by
   1.3 % at the reference point) is measured on the dynamics themselves and the start moved onto
   the plateau, by a secant (coarse Newton) step on the slow variable, the cage speed (the
   equation-free fixed point of Kevrekidis et al. 2003, "Equation-free, coarse-grained multiscale
   computation", Comm. Math. Sci. 1:715; Gear & Kevrekidis 2003, SIAM J. Sci. Comput. 24:1091):

   - bursts of `PRE_START_SKIP` + `PRE_START_MEASURE` cage revolutions, the first from the
     static state (the rollers skew and reach the flanges within its first quarter revolution);
     in each, the drift g = d omega_c/dt is the slope of a least-squares line through the cage
     speed after the skip, at the mean speed w (`cage_drift`);
   - after each burst a step of the cage speed onto the plateau w* = w + tau g, the rollers'
     orbit and spin along with it (`along_slow_mode`), taken from the line's value at the end
     of the burst, not from the instantaneous cage speed (which rattles by about 3 rpm about
     its mean: a step from it would carry that offset along); tau is the static slow mode's
     tau_s (`dynamics.cage_time_constant`) for the first step and the secant of the last two
     bursts, tau = -(w_k - w_{k-1}) / (g_k - g_{k-1}), afterwards (near the plateau the drift is
     close to linear in the cage speed, the slow mode: a secant step is a coarse Newton step);
   - stop after the second or third burst, when a step is below `PRE_START_TOLERANCE`.

   The running bearing's slow mode is slower than the static balance's (at the reference point
   the secants give tau = 66 and 62 ms against tau_s = 46 ms), which is why one projective step
   with tau_s lands short (-80 rpm of the 116 needed) and the settling loop used to need two or
   three. Cost: 2.45 cage revolutions of simulated time (17.2 ms at the reference point), through
   the run's own compiled `solve_from` (no compilation of its own). Measured there
   (benchmarks/results/bench_settling.json): revolution 1 of the run within 0.006 % of the window's cage
   speed. Deterministic per seed; not differentiated (a start, not a model output). If a burst
   fails, the static state is handed over (`pre_start_status` says why) and the settling loop's
   projective steps take over.
"""

from __future__ import annotations

import dataclasses

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

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
from ._compile_cache import compiled_program
from ._engine import drive
from ._start_cache import load_start, start_key, store_start


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
    """Quasi-static solution (docs/model.md 12) as the initial state of the dynamic run."""
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
    """The skid start of a run: the state handed over at t = 0, the static equilibrium it grew
    from, and the cage's slow mode (module docstring).

    `time_constant` [s]: of the cage speed's approach to steady running; with a pre-start the one
    the dynamics showed (the secant of the last two measured drifts), else the static
    `dynamics.cage_time_constant`. `pre_start_time` [s]: simulated time spent before t = 0 (0 for
    the static start). `drift_speeds`, `drifts` [rad/s, rad/s^2]: the pre-start's measured
    revolution-mean cage speeds and their drifts d omega_c/dt (empty for the static start).
    `plateau_speed` [rad/s]: the cage speed at which the drift vanishes (the static one without
    pre-start). `pre_start_status`: "ok", "static" (no integrator given) or why the pre-start
    fell back to the static state."""

    state: State
    equilibrium: SkidEquilibrium
    time_constant: jax.Array
    pre_start_time: float = 0.0
    drift_speeds: tuple = ()
    drifts: tuple = ()
    plateau_speed: float = float("nan")
    pre_start_status: str = eqx.field(static=True, default="static")
    #: the static slow mode's tau_s [s] (`dynamics.cage_time_constant`), also after a pre-start
    static_time_constant: float = float("nan")


def _kinematic(bearing, op, scatter):
    return initial_state(bearing, op, perturbation_of(scatter))


def kinematic_start(bearing: Bearing, op: OperatingPoint, perturbation: Perturbation | None) -> State:
    """`initial_state` (the quasi-static, kinematic start) as one program, built once per
    machine (`compiled_program`): called eagerly, its quasi-static Newton solve compiles every
    operation on its own in every process (about 10 s)."""
    dyn = (bearing, op, traced_scatter(perturbation))
    return compiled_program("kinematic_start", _kinematic, dyn)(*dyn)


def _skid(bearing, op, scatter):
    start = initial_state(bearing, op, perturbation_of(scatter))
    params = Params(bearing=bearing, operating=op)
    eq = skid_equilibrium(start, params, kinematic_cage_speed(bearing, op))
    return SkidStart(state=eq.state, equilibrium=eq, time_constant=cage_time_constant(eq, params))


def _static_skid_start(bearing: Bearing, op: OperatingPoint, perturbation: Perturbation | None) -> SkidStart:
    """The static skid equilibrium of one case, solved once per machine: read from the start
    cache (`_start_cache`) when this very solve was stored, else solved and stored."""
    dyn = (bearing, op, traced_scatter(perturbation))
    key = start_key("static", dyn)
    static = load_start("static", key, SkidStart)
    if static is None:
        static = compiled_program("skid_start", _skid, dyn)(*dyn)
        static = dataclasses.replace(
            static,
            plateau_speed=float(static.equilibrium.cage_speed),
            static_time_constant=float(static.time_constant),
        )
        store_start("static", key, static)
    return static


def static_skid_starts(members, devices=None) -> list[SkidStart]:
    """`_static_skid_start` of every (bearing, operating point, perturbation) in `members`
    (all of one parameter structure) as one vmapped program: the accelerator path of the
    steady-running engine, where thousands of members would otherwise each solve their skid
    equilibrium on the host one after another (3.6 s each at 11 slices on the 2-core CPU)."""
    import numpy as np

    dyn = [(b, op, traced_scatter(p)) for b, op, p in members]
    stacked = jax.tree_util.tree_map(lambda *xs: np.stack([np.asarray(x) for x in xs]), *dyn)
    out = jax.device_get(compiled_program("skid_start_members", jax.vmap(_skid), stacked)(*stacked))
    starts = []
    for i in range(len(members)):
        one = jax.tree_util.tree_map(lambda a: a[i], out)
        starts.append(
            dataclasses.replace(
                one,
                plateau_speed=float(one.equilibrium.cage_speed),
                static_time_constant=float(one.time_constant),
            )
        )
    return starts


#: the pre-start's bursts, in revolutions at the static skid speed: each skips `PRE_START_SKIP`
#: (the first: the rollers skew and reach the flanges; the later ones: the rollers' spins and
#: pocket contacts readjust to the stepped cage speed), then measures the cage speed's drift over
#: `PRE_START_MEASURE` (the first two drifts only aim the last burst: half a revolution each)
PRE_START_SKIP = (0.25, 0.1, 0.1)
PRE_START_MEASURE = (0.5, 0.5, 1.0)
#: the pre-start stops when a step is below this fraction of the cage speed (after two bursts)
PRE_START_TOLERANCE = 2e-4
#: a step of the pre-start moves the cage speed by at most this fraction
PRE_START_CAP = 0.05
#: the secant's time constant is accepted within these multiples of the static one
TIME_CONSTANT_RANGE = (0.5, 4.0)


def along_slow_mode(state: State, jump) -> State:
    """The state with the cage speed moved by `jump` [rad/s] along the slow mode: every roller's
    orbit rate moves with it, the rollers' angular velocities scale in proportion."""
    ratio = (state.cage.speed + jump) / state.cage.speed
    rollers = dataclasses.replace(
        state.rollers,
        azimuth_rate=state.rollers.azimuth_rate + jump,
        angular_velocity=state.rollers.angular_velocity * ratio,
    )
    cage = dataclasses.replace(state.cage, speed=state.cage.speed + jump)
    return dataclasses.replace(state, rollers=rollers, cage=cage)


def cage_drift(t, cage_speed, since):
    """Least-squares line through the cage speed samples at t >= `since`: (mean speed, drift
    d omega_c/dt, the line's value at the last sample). The line's end value, not the last
    sample, is the level a projective step starts from: the instantaneous cage speed rattles by
    several rpm about its mean (pocket contacts)."""
    t, w = np.asarray(t, float), np.asarray(cage_speed, float)
    keep = t >= since
    t, w = t[keep], w[keep]
    tc = t - t.mean()
    drift = float(np.sum(tc * w) / np.sum(tc * tc))
    mean = float(w.mean())
    return mean, drift, mean + drift * float(tc[-1])


def pre_start_steps(static: SkidStart):
    """The pre-start as a program of integration requests (`_engine`): bursts of the dynamics
    from the static skid state with secant steps on the cage speed's drift between them (module
    docstring). Yields `(state, duration)`, is sent `(histories, final state, result code,
    steps)` and returns the `SkidStart`; falls back to `static` if a burst fails."""
    w0, tau_s = float(static.state.cage.speed), float(static.time_constant)
    rev = 2 * np.pi / abs(w0)
    cap = PRE_START_CAP * abs(w0)
    lo, hi = TIME_CONSTANT_RANGE
    state, tau, elapsed, speeds, drifts = static.state, tau_s, 0.0, [], []
    for k, (skip, measure) in enumerate(zip(PRE_START_SKIP, PRE_START_MEASURE)):
        hist, end, code, _ = yield state, (skip + measure) * rev
        elapsed += (skip + measure) * rev
        speed = np.asarray(hist["cage_speed"])
        if int(code) != 0 or not np.all(np.isfinite(speed)):
            why = f"failed: the solver did not succeed in pre-start burst {k + 1}; static start"
            return dataclasses.replace(static, pre_start_time=elapsed, pre_start_status=why)
        w, drift, level = cage_drift(np.asarray(hist["t"]), speed, skip * rev)
        if speeds and w != speeds[-1]:
            # secant of the last two bursts: d(drift)/d(omega_c) = -1/tau; a flat one or one of
            # the wrong sign, or a tau outside TIME_CONSTANT_RANGE x tau_s, keeps the last tau
            secant = -(w - speeds[-1]) / (drift - drifts[-1]) if drift != drifts[-1] else float("nan")
            tau = secant if lo * tau_s <= secant <= hi * tau_s else tau
        speeds.append(w)
        drifts.append(drift)
        # step from the line's end value (the level) onto the plateau w + tau drift
        jump = float(np.clip(w + tau * drift - level, -cap, cap))
        state = along_slow_mode(end, jump)
        if k >= 1 and abs(jump) <= PRE_START_TOLERANCE * abs(w0):
            break
    return SkidStart(
        state=state,
        equilibrium=static.equilibrium,
        time_constant=jnp.asarray(tau),
        pre_start_time=elapsed,
        drift_speeds=tuple(speeds),
        drifts=tuple(drifts),
        plateau_speed=level + jump,
        pre_start_status="ok",
        static_time_constant=tau_s,
    )


def skid_start(
    bearing: Bearing, op: OperatingPoint, perturbation: Perturbation | None, *, integrate=None
) -> SkidStart:
    """The start of a settled run (module docstring): the static skid equilibrium at
    `initial_state`'s positions, then, given `integrate`, the pre-start that lands it on the
    settled plateau.

    `integrate(state, duration) -> (histories, final state, result code, steps)`: the run's own
    compiled continuation (`solve_from` with its parameters and tolerances bound; histories with
    "t" and "cage_speed"), so that the pre-start costs no compilation of its own. The static
    equilibrium is compiled once per bearing structure (seeds, speeds and loads reuse it) and
    runs outside any vmap (a vmapped bisection costs several times more per case)."""
    static = _static_skid_start(bearing, op, perturbation)
    if integrate is None:
        return static
    return drive(pre_start_steps(static), integrate)
