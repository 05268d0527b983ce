"""Settled running: integrate in cage revolutions until the cage speed stops drifting, then
measure over a window of whole revolutions (issue 11; docs/model.md 16).

* `solve_from` continues the integration from any physical state (one call per revolution); it
  returns the saved histories and the final state. Its integrator settings are those of `solve`
  (Tsit5, PID controller on the scaled state under `solve`'s error norm); the scaling's nominal orbit
  restarts at every chunk from the chunk's own start state and cage speed, so the scaled
  azimuths never accumulate the cage slip over a long run.
* Settling (`settle="auto"`): chunks of one cage revolution (2 pi / the previous revolution's
  mean cage speed) until the settling verdict (`settling_verdict`) finds the cage speed's
  remaining drift below `tolerance` (relative): the slope of a least-squares line through the
  last 4-8 revolution means times the running slow mode's time constant, with its one-sided 95 %
  bound (a drift slower than the tolerance per revolution does not pass; docs/model.md 16), at
  most `settle_cap_ms` (then not settled, the residual drift reported). `settle=MS` runs a
  fixed MS ms first (declared settled by the user); `settle="off"` measures from the start
  (`settled` is then False: nothing was verified).
* The start (`start="skid"`, the default): the skid equilibrium (`_initial.skid_start`: cage
  and roller speeds of steady running, rollers against their pocket walls, cage on its land
  equilibrium). A static balance cannot know the flange friction of rollers that skew and hit
  the flanges once running (at the reference point it settles in during the first two
  revolutions and lowers the cage speed by about 1 %, which the cage then follows with the
  ~46 ms time constant of its slow mode). The settling phase therefore corrects the slow
  variable by projective steps (Gear & Kevrekidis 2003, "Projective methods for stiff
  differential equations", SIAM J. Sci. Comput. 24:1091; the coarse step of equation-free
  computing): after every two revolutions the drift of the revolution-mean cage speed,
  d omega/dt, measured by the dynamics themselves, moves the cage speed (and the rollers' orbit
  and spin in proportion) by tau d omega/dt, tau = `dynamics.cage_time_constant` (the Newton
  step of the linear slow mode onto its plateau), while the step exceeds a quarter of `tolerance`;
  at most `PROJECTIVE_STEPS` times. Settling is then detected as above, on revolutions after the
  last step only. Since the skid start's pre-start (`_initial`) measures that drift itself and lands
  on the plateau, the projective steps are taken only when its pre-start failed.
  `start="quasi-static"`: kinematic speeds, no projective steps.
* The window is `window_revs` further revolutions; its statistics and intervals come from
  `_statistics`. With `seeds = N` the whole run is repeated for N seeded initial scatters
  (`Perturbation.seed` = 0 .. N-1), with `workers` > 1 one process per core (`parallel_map`: 1.52x the throughput of
  one case at a time on 2 cores, benchmarks/results/bench_ensemble.json; a vmapped batch is slower
  per case than one at a time, docs/performance.md).
"""

from __future__ import annotations

import dataclasses
import math
import time

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
from scipy import stats as _sp_stats

from .._errors import UserInputError
from ..dynamics import Functionals, Params, Scaling, State, state_scales
from ..geometry import Bearing, OperatingPoint, kinematic_cage_speed, rad_s_to_rpm
from ..io import require
from ._compile_cache import checks_without_host_callbacks, compiled_program
from ._engine import STRATEGIES, BatchTimes, choose_strategy, drive, drive_batched
from ._ensemble import parallel_map
from ._initial import (
    STARTS,
    Perturbation,
    SkidStart,
    _static_skid_start,
    along_slow_mode,
    kinematic_start,
    pre_start_steps,
    skid_start,
    static_skid_starts,
    traced_scatter,
)
from ._result import result_code, result_message
from ._rosenbrock import DEFAULT_SOLVER, check_solver
from ._simulate import SolveArgs, _histories, _saved_state, scaled_diffeqsolve
from ._simulate import simulate as _simulate_fixed
from ._start_cache import load_start, start_key, store_start
from ._statistics import steady_statistics
from ._step_control import raceway_normal_norm, step_controller
from ._summary import CONTACT_THRESHOLD, FAILED_LABEL, SETTLED_LABEL, UNSETTLED_LABEL
from ._summary import summarise as _summarise_fixed

#: defaults of the settled run
SETTLE_TOLERANCE = 1e-3  # relative change of the revolution-mean cage speed
SETTLE_CAP_MS = 300.0
WINDOW_REVS = 8
SAVES_PER_REV = 1320  # 5 us at the reference cage speed, as `simulate`'s default 4000 per 20 ms
#: at most this many projective steps of the cage speed while settling from the skid start
PROJECTIVE_STEPS = 4
#: a projective step moves the cage speed by at most this fraction
PROJECTIVE_CAP = 0.05
#: projective steps go on while a step exceeds this fraction of the settling tolerance (chosen
#: when the criterion compared consecutive revolutions, which let a slow drift below the tolerance
#: per revolution into the window: at the reference point 1 rpm per revolution after the first
#: step, 0.09 % of the plateau in tau = 46 ms; the verdict now catches such a drift itself)
PROJECTIVE_THRESHOLD = 0.25

#: the settling verdict (`settling_verdict`): a line through the revolution-mean cage speeds of at
#: least `VERDICT_MIN_REVS` and at most `VERDICT_MAX_REVS` revolutions since the last projective step
VERDICT_MIN_REVS = 4
VERDICT_MAX_REVS = 8
#: one-sided confidence of the verdict's upper bound on the remaining drift
VERDICT_CONFIDENCE = 0.95
#: the verdict's running slow mode, in multiples of the static tau_s (`running_time_constant`)
RUNNING_SLOW_MODE_FACTOR = 1.5


@dataclasses.dataclass(frozen=True)
class Verdict:
    """`settling_verdict`'s answer. `residual_drift_rpm`: how far the cage speed still has to go
    on its slow mode, |slope| tau_run (nan before `VERDICT_MIN_REVS` revolutions); `bound_rpm`:
    its one-sided 95 % upper bound (slope + t SE); `slope_rpm_s`, `slope_se_rpm_s`: the line's
    slope and standard error; `revolutions`: how many revolutions the line ran through."""

    settled: bool
    residual_drift_rpm: float
    bound_rpm: float
    slope_rpm_s: float
    slope_se_rpm_s: float
    revolutions: int
    time_constant_s: float


def settling_verdict(centres, speeds, tolerance: float, time_constant: float) -> Verdict:
    """Whether the revolution-mean cage speeds `speeds` [rpm] at revolution centres `centres`
    [s] (those since the last projective step, oldest first) have settled (docs/model.md 16):
    the least-squares line through the last `VERDICT_MAX_REVS` of them (at least
    `VERDICT_MIN_REVS`) has slope b +/- SE; near its plateau the cage speed relaxes along its slow
    mode, omega - omega_inf = -tau b, so the remaining drift is |b| tau with tau =
    `time_constant` [s] (a conservative estimate of the running slow mode). Settled when the
    one-sided 95 % upper bound (|b| + t_{n-2, 0.95} SE) tau is at most `tolerance` times the
    last speed. Pure, host-side (numpy)."""
    t = np.asarray(centres, float)[-VERDICT_MAX_REVS:]
    w = np.asarray(speeds, float)[-VERDICT_MAX_REVS:]
    n = t.size
    nan = float("nan")
    if n < VERDICT_MIN_REVS:
        return Verdict(False, nan, nan, nan, nan, n, float(time_constant))
    tc = t - t.mean()
    sxx = float(np.sum(tc * tc))
    slope = float(np.sum(tc * (w - w.mean())) / sxx)
    resid = w - w.mean() - slope * tc
    se = float(np.sqrt(np.sum(resid * resid) / (n - 2) / sxx))
    q = float(_sp_stats.t.ppf(VERDICT_CONFIDENCE, n - 2))
    drift = abs(slope) * time_constant
    bound = (abs(slope) + q * se) * time_constant
    return Verdict(bool(bound <= tolerance * abs(w[-1])), drift, bound, slope, se, n, float(time_constant))


def running_time_constant(skid, bearing: Bearing, op: OperatingPoint, perturbation: Perturbation) -> float:
    """The running slow mode's time constant [s] the verdict uses (`settling_verdict`,
    docs/model.md 16): `RUNNING_SLOW_MODE_FACTOR` times the static slow mode's tau_s
    (`dynamics.cage_time_constant` at the static skid equilibrium of this seed; `skid`, a
    `SkidStart`, carries it, else it is solved here, as for the quasi-static start), or the
    longest positive secant of the pre-start's measured drifts if that is longer (every secant,
    also those the pre-start's own steps rejected: a static balance far from the running state,
    e.g. a misaligned one before its quasi-static start knew the tilt, gave tau_s = 0.19 ms)."""
    if skid is None:
        skid = skid_start(bearing, op, perturbation)
    tau_s = float(skid.static_time_constant)
    if not math.isfinite(tau_s):
        tau_s = float(skid.time_constant)
    tau = RUNNING_SLOW_MODE_FACTOR * tau_s
    w, g = np.asarray(skid.drift_speeds, float), np.asarray(skid.drifts, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        secants = -np.diff(w) / np.diff(g)
    secants = secants[np.isfinite(secants) & (secants > 0)]
    return float(max(tau, *secants)) if secants.size else float(tau)


def prepare_from(params: Params, start: State, rtol, atol):
    """What a solve from the physical state `start` needs: (scaling, solve arguments, scaled
    start with the accumulators at zero, step controller), with the settled windows' error
    norm (`raceway_normal_norm`'s defaults: the per-roller RMS with the raceway-normal
    coordinates and the rotations 10x looser; validated on settled statistics, not on start-up
    transients, whose `solve` has `TRANSIENT_ERROR_NORM`); the scaling's nominal orbit runs at
    the start's own cage speed."""
    b = params.bearing
    zero_acc = jax.tree_util.tree_map(jnp.zeros_like, start.accumulators)
    start = State(rollers=start.rollers, cage=start.cage, inner_ring=start.inner_ring, accumulators=zero_acc)
    scaling = Scaling(
        nominal=start, scale=state_scales(b.num_rollers, b.pitch_diameter / 2), orbit_speed=start.cage.speed
    )
    y0_scaled = scaling.scale_state(0.0, start)
    controller = step_controller(rtol, atol, raceway_normal_norm(y0_scaled))
    return scaling, SolveArgs(params=params, scaling=scaling), y0_scaled, controller


def solve_from(
    params: Params,
    start: State,
    duration,
    *,
    num_saves: int,
    rtol,
    atol,
    max_steps: int,
    adjoint=None,
    solver=DEFAULT_SOLVER,
):
    """Integrate from the physical state `start` over [0, duration] with `solver` ("tsit5" or
    "ros34pw2"): (histories, final state, diffrax result code, steps). The histories are
    those of `solve` (`_histories`); the final state carries the accumulators, which restart
    from zero. jit-able; `adjoint` as in `solve` (`diffrax.ForwardMode()` for forward-mode
    derivatives; `num_saves = 0` keeps only the final state)."""
    scaling, args, y0_scaled, controller = prepare_from(params, start, rtol, atol)
    last = diffrax.SubSaveAt(t1=True)
    if num_saves:
        saves = diffrax.SubSaveAt(ts=jnp.linspace(0.0, duration, num_saves + 1)[:-1], fn=_saved_state)
        saveat = diffrax.SaveAt(subs=[saves, last])
    else:
        saveat = diffrax.SaveAt(subs=[last])
    with checks_without_host_callbacks():  # the integrator of `solve`, the error norm of `prepare_from`
        sol = scaled_diffeqsolve(
            y0_scaled, args, duration, saveat, controller, max_steps, adjoint, False, solver
        )
    if num_saves:
        hist, final = _histories(sol.ts[0], sol.ys[0], args), sol.ys[1]
    else:
        hist, final = {}, sol.ys[0]
    final = scaling.unscale(duration, jax.tree_util.tree_map(lambda a: a[-1], final))
    return hist, final, result_code(sol.result), jnp.asarray(sol.stats["num_steps"])


def _compiled(params, start, num_saves, max_steps, solver=DEFAULT_SOLVER):
    """`solve_from` compiled (`compiled_program`) for (params, start, duration, rtol, atol)."""

    def run(p, s, d, r, a):
        return solve_from(p, s, d, num_saves=num_saves, rtol=r, atol=a, max_steps=max_steps, solver=solver)

    f = jnp.asarray(1.0)
    return compiled_program("solve_from", run, (params, start, f, f, f), (num_saves, max_steps, solver))


def _integrator(params, num_saves, max_steps, rtol, atol, compile_times: list, solver=DEFAULT_SOLVER):
    """`solve_from` compiled (`_compiled`) with the run's parameters and tolerances bound, as
    `skid_start`'s pre-start needs it; compilation times are appended to `compile_times`."""

    def integrate(state, duration):
        c0 = time.perf_counter()
        run = _compiled(params, state, num_saves, max_steps, solver)
        compile_times.append(time.perf_counter() - c0)
        return run(params, state, jnp.asarray(duration), jnp.asarray(rtol), jnp.asarray(atol))

    return integrate


@dataclasses.dataclass
class SeedRun:
    """One seed's settled run: the window's histories (absolute times) and its revolutions."""

    seed: int
    window: dict
    edges: np.ndarray  # revolution boundaries of the window [s]
    settle_time: float  # [s]
    settled: bool
    revolution_speeds_rpm: list  # revolution-mean cage speed of every revolution run
    revolution_ends: list  # end time of every revolution run [s]
    status: str
    num_steps: int
    projective_steps_rpm: list = dataclasses.field(default_factory=list)  # cage speed moves
    #: per window revolution, (sum of int w (PV/PV_ref)^p dt, sum of int w dt) over every roller
    #: and flange contact: the accumulators of `Params.functionals` (with p = 1 the smooth mean
    #: PV over contact time is PV_ref times their ratio; `_steady_design`)
    window_integrals: list = dataclasses.field(default_factory=list)
    #: the states at the start of the window and at the end of the run (numpy leaves): states
    #: of settled running (samples for `steady_gradient`, starts for a neighbouring design)
    window_start_state: object = None
    final_state: object = None
    start_cage_speed_rpm: float = float("nan")
    #: the settling verdict at the end of settling (`settling_verdict`; with `settle` fixed or
    #: "off", the one before the window is not evaluated: nan fields)
    verdict: object = None
    #: the window's `window_statistics`, when a reducer computed them as the seed finished (the
    #: window's histories are then dropped: `window` is empty); `extras`: what else it kept
    per_revolution: dict | None = None
    extras: dict = dataclasses.field(default_factory=dict)

    @property
    def measured(self) -> bool:
        """Whether the run has a window to take statistics from."""
        return self.status == "ok" and (bool(self.window) or self.per_revolution is not None)


def check_steady_options(
    settle, window_revs, seeds, tolerance, cap_ms, names=None, *, start="skid", workers=1, prefix=""
) -> None:
    """One-line `UserInputError` naming the option for a bad value of the settled-run options
    (named `prefix` + the keyword's name, e.g. "sweep.seeds", unless `names` says otherwise)."""
    defaults = {
        "settle": "settle",
        "window_revs": "window_revs",
        "seeds": "seeds",
        "tolerance": "settle_tolerance",
        "cap_ms": "settle_cap_ms",
        "start": "start",
        "workers": "workers",
    }
    n = {**{k: prefix + v for k, v in defaults.items()}, **(names or {})}
    if start not in STARTS:
        from .._errors import UserInputError

        raise UserInputError(f"{n['start']} = {start!r}: must be one of {', '.join(map(repr, STARTS))}")
    require(n["workers"], workers, lambda v: (v >= 1) & (v == np.round(v)), "an integer >= 1")
    if not (isinstance(settle, str) and settle in ("auto", "off")):
        require(
            n["settle"],
            _as_float(n["settle"], settle),
            lambda v: np.isfinite(v) & (v >= 0),
            '"auto", "off" or a settling time >= 0 ms',
        )
    require(
        n["window_revs"],
        window_revs,
        lambda v: (v >= 2) & (v == np.round(v)),
        "an integer >= 2 (cage revolutions; batch means need two batches)",
    )
    require(n["seeds"], seeds, lambda v: (v >= 1) & (v == np.round(v)), "an integer >= 1")
    require(n["tolerance"], tolerance, lambda v: (v > 0) & (v < 1), "in (0, 1) (relative change)")
    require(n["cap_ms"], cap_ms, lambda v: np.isfinite(v) & (v > 0), "> 0 ms")


def _as_float(name, value):
    try:
        return float(value)
    except (TypeError, ValueError):
        from .._errors import UserInputError

        raise UserInputError(
            f'{name} = {value!r}: must be "auto", "off" or a settling time >= 0 ms'
        ) from None


def settle_and_measure_steps(
    start,
    *,
    settle,
    window_revs,
    tolerance,
    cap,
    progress,
    time_constant=None,
    slow_mode=float("nan"),
):
    """Settle then measure one seed (module docstring), as a program of integration requests
    (`_engine`: yields `(state, duration)`, is sent `solve_from`'s answer); `time_constant` [s]
    (skid start) turns on the projective steps of the cage speed; `slow_mode` [s]: the running
    slow mode's time constant the verdict uses (`settling_verdict`)."""
    state, t, steps = start, 0.0, 0
    speeds, ends, windows, edges, jumps, integrals = [], [], [], [], [], []
    centres = []  # revolution centres [s]
    window_start = start
    since_jump = 0  # revolutions run since the last projective step
    verdict = settling_verdict([], [], tolerance, slow_mode)
    settled, settle_time, status = settle == "off", 0.0, "ok"
    fixed = None if isinstance(settle, str) else float(settle) * 1e-3
    measuring = settle == "off" or fixed == 0.0
    while True:
        rev = 2 * math.pi / abs(float(state.cage.speed))
        if not measuring and fixed is not None:
            rev = min(rev, fixed - t)
        if measuring and not windows:
            window_start = state
        hist, final, code, n = yield state, rev
        hist = {k: np.asarray(v) for k, v in hist.items()}
        steps += int(n)
        if int(code) != 0 or not np.all(np.isfinite(hist["cage_speed"])):
            why = result_message(int(code)) if int(code) != 0 else "the cage speed became non-finite"
            status = f"failed: {why}, in the cage revolution from {t * 1e3:.2f} to {(t + rev) * 1e3:.2f} ms"
            break
        hist["t"] = hist["t"] + t
        t += rev
        state = final
        speeds.append(float(rad_s_to_rpm(np.mean(hist["cage_speed"]))))
        ends.append(t)
        centres.append(t - 0.5 * rev)
        if progress:
            print(
                f"  t = {t * 1e3:7.2f} ms: cage {speeds[-1]:9.2f} rpm over the last revolution"
                f"{' (window)' if measuring else ''}",
                flush=True,
            )
        if measuring:
            windows.append(hist)
            edges.append(t - rev)
            acc = final.accumulators  # integrals over this revolution (they restart per chunk)
            integrals.append((float(jnp.sum(acc.pv_power)), float(jnp.sum(acc.contact_time))))
            if len(windows) == window_revs:
                edges.append(t)
                break
            continue
        since_jump += 1
        if time_constant is not None and since_jump >= 2 and len(jumps) < PROJECTIVE_STEPS:
            # d omega/dt between the centres of the last two revolutions, in rpm/s
            drift = (speeds[-1] - speeds[-2]) / (0.5 * (ends[-1] - (ends[-3] if len(ends) > 2 else 0.0)))
            bound = PROJECTIVE_CAP * abs(speeds[-1])
            jump = float(np.clip(time_constant * drift, -bound, bound))
            big = abs(jump) > PROJECTIVE_THRESHOLD * tolerance * abs(speeds[-1])
            if big and (fixed is None or t < fixed - 1e-12):
                jumps.append(jump)
                state = along_slow_mode(state, jump * math.pi / 30)
                since_jump = 0
                if progress:
                    print(f"  projective step: cage speed {jump:+.2f} rpm", flush=True)
                continue
        if fixed is not None:
            done = t >= fixed - 1e-12
        else:
            recent = slice(len(speeds) - since_jump, None)
            verdict = settling_verdict(centres[recent], speeds[recent], tolerance, slow_mode)
            done = verdict.settled
        if done:
            settled, settle_time, measuring = True, t, True
        elif t >= cap:
            settled, settle_time, measuring = False, t, True
    window = {k: np.concatenate([w[k] for w in windows]) for k in windows[0]} if windows else {}
    host = [jax.tree_util.tree_map(np.asarray, x) for x in (window_start, state)]
    return (
        window,
        np.asarray(edges),
        settle_time,
        settled,
        speeds,
        ends,
        status,
        steps,
        jumps,
        integrals,
        *host,
        verdict,
    )


@dataclasses.dataclass
class SteadyResult:
    """A settled run over `seeds` seeds (`SeedRun`s) and how it was obtained."""

    runs: list
    settle: object
    window_revs: int
    tolerance: float
    cap: float
    start: str
    wall_time_s: float
    compile_time_s: float
    bearing: Bearing
    operating: OperatingPoint

    @property
    def ok(self) -> bool:
        return all(r.status == "ok" for r in self.runs)

    @property
    def settled(self) -> bool:
        return all(r.settled for r in self.runs)

    @property
    def status(self) -> str:
        return "ok" if self.ok else next(r.status for r in self.runs if r.status != "ok")

    @property
    def histories(self) -> dict:
        """The first seed's window (for plots and the histories file)."""
        return self.runs[0].window


@dataclasses.dataclass(frozen=True)
class Member:
    """One member of the steady-running engine (`settle_members`): a bearing (with its design),
    an operating point and one seeded initial scatter. `initial_state` (continuation): a `State`
    to start from instead of the run's start (e.g. `SeedRun.final_state` of a neighbouring
    design), settled without projective steps; `rtol`, `atol`: this member's tolerances (None:
    the run's)."""

    bearing: Bearing
    operating: OperatingPoint
    perturbation: Perturbation = Perturbation()
    initial_state: object = None
    rtol: float | None = None
    atol: float | None = None


@dataclasses.dataclass(frozen=True)
class SteadyOptions:
    """How every member of a settled run settles and measures (`simulate_steady`'s options)."""

    settle: object = "auto"
    window_revs: int = WINDOW_REVS
    tolerance: float = SETTLE_TOLERANCE
    settle_cap_ms: float = SETTLE_CAP_MS
    start: str = "skid"
    rtol: float = 1e-3
    atol: float = 1e-6
    max_steps: int = 2_000_000
    saves_per_rev: int = SAVES_PER_REV
    functionals: Functionals = Functionals()
    progress: bool = False
    solver: str = DEFAULT_SOLVER
    #: members continuing from a given state settle this many of their own cage revolutions
    #: (fixed, declared settled) instead of by `settle` (None: by `settle`); for a small design
    #: step from a settled state (`continuation_settle`)
    continuation_settle_revs: int | None = None

    def tolerances(self, member: Member) -> tuple[float, float]:
        return (
            float(self.rtol if member.rtol is None else member.rtol),
            float(self.atol if member.atol is None else member.atol),
        )

    def params(self, member: Member) -> Params:
        return Params(bearing=member.bearing, operating=member.operating, functionals=self.functionals)


def member_steps(member: Member, options: SteadyOptions, reduce=None, static=None, *, stored_start=False):
    """The settled run of one member as a program of integration requests (`_engine`): its
    start (the skid equilibrium and its pre-start, the kinematic start, or the given state),
    settling and the window (module docstring); returns its `SeedRun`, passed through
    `reduce(run, member)` if given (e.g. a sweep's statistics, so that the window's histories
    need not be kept). `static`: the member's static skid equilibrium if already solved
    (`static_skid_starts`, the vmapped path), else it is solved here when needed.
    `stored_start`: read the pre-start from the start cache, or store it there
    (`_start_cache`; only where `integrate` is the one-member program, `_run_one`)."""
    bearing, op, pert, given = member.bearing, member.operating, member.perturbation, member.initial_state
    skid = None
    settle = options.settle
    if given is not None:  # continuation from a given state
        y0, tau = jax.tree_util.tree_map(jnp.asarray, given), None
        settle = continuation_settle(options, y0)
    elif options.start == "skid":
        key = pre_start_key(member, options) if stored_start else None
        skid = None if key is None else load_start("pre-start", key, SkidStart)
        if skid is None:
            skid = yield from pre_start_steps(
                static if static is not None else _static_skid_start(bearing, op, pert)
            )
            if key is not None and skid.pre_start_status == "ok":
                store_start("pre-start", key, skid)
        # on the plateau after a completed pre-start: no projective steps (their drift, from
        # two revolution means, is noisier than the pre-start's secant; docs/model.md 16)
        y0 = skid.state
        tau = None if skid.pre_start_status == "ok" else float(skid.time_constant)
    else:
        y0, tau = kinematic_start(bearing, op, pert), None
    slow_mode = float("nan")
    if settle == "auto":
        slow_mode = running_time_constant(skid if skid is not None else static, bearing, op, pert)
    if options.progress:
        print(
            f"seed {pert.seed}: settling ({settle}), then {options.window_revs} revolutions",
            flush=True,
        )
    *out, verdict = yield from settle_and_measure_steps(
        y0,
        settle=settle,
        window_revs=int(options.window_revs),
        tolerance=options.tolerance,
        cap=options.settle_cap_ms * 1e-3,
        progress=options.progress,
        time_constant=tau,
        slow_mode=slow_mode,
    )
    run = SeedRun(pert.seed, *out, start_cage_speed_rpm=float(rad_s_to_rpm(y0.cage.speed)), verdict=verdict)
    return run if reduce is None else reduce(run, member)


def pre_start_key(member: Member, options: SteadyOptions) -> str:
    """The start cache's key of `member`'s pre-start (`_start_cache`): its case and scatter, and
    everything that defines the one-member integration it runs (`_integrator`): the
    functionals, the tolerances, the saves per revolution, the step cap and the solver."""
    inputs = (member.bearing, member.operating, traced_scatter(member.perturbation), options.functionals)
    setting = (
        *options.tolerances(member),
        int(options.saves_per_rev),
        int(options.max_steps),
        str(options.solver),
    )
    return start_key("pre-start", inputs, setting)


def continuation_settle(options: SteadyOptions, state) -> object:
    """How a member continuing from `state` settles: `options.settle`, or with
    `options.continuation_settle_revs` = n a fixed n revolutions of its own cage, 2 pi n /
    |omega_c| (in ms, as `settle`), where omega_c is `state`'s cage speed. A design search's next
    iterate starts from the settled states of a design a few per cent of the box away; the
    settling verdict would need at least `VERDICT_MIN_REVS` revolutions for what is mostly a
    small shift (docs/model.md 17)."""
    n = options.continuation_settle_revs
    if n is None:
        return options.settle
    return 2e3 * math.pi * float(n) / abs(float(state.cage.speed))


def _run_one(member: Member, options: SteadyOptions, reduce=None, static=None) -> tuple[SeedRun, float]:
    """One member in this process (`drive`, its own compiled `solve_from`): (run, compile time);
    `static`: as `member_steps`."""
    compiled: list = []
    rtol, atol = options.tolerances(member)
    integrate = _integrator(
        options.params(member),
        int(options.saves_per_rev),
        int(options.max_steps),
        rtol,
        atol,
        compiled,
        options.solver,
    )
    run = drive(member_steps(member, options, reduce, static, stored_start=True), integrate)
    return run, sum(compiled)


def _continuing_cases(members, options: SteadyOptions) -> dict:
    """{member index: index of its case's first member} for the members that continue from a
    given state and settle with the verdict: they share the static skid equilibrium of that
    first member's seed (a case: one bearing and operating point). The verdict needs only its
    time constant, which the seeds' scatters move by 3e-6 (reference bearing, 31 slices, seeds
    0-2); solved per seed, the equilibria took 17 of the 66 s of a design-search evaluation (4
    seeds, continuing) on the 2-core CPU, 2026-11-26."""
    if options.settle != "auto" or options.continuation_settle_revs is not None:
        return {}
    first, out = {}, {}
    for i, m in enumerate(members):
        if m.initial_state is not None:
            leaves, tree = jax.tree_util.tree_flatten((m.bearing, m.operating))
            key = (str(tree), tuple(np.asarray(x).tobytes() for x in leaves))
            out[i] = first.setdefault(key, i)
    return out


def _shared_time_constants(members, options: SteadyOptions) -> dict:
    """{member index: static skid equilibrium} of `_continuing_cases`, one solve per case."""
    cases = _continuing_cases(members, options)
    solved = {
        j: _static_skid_start(members[j].bearing, members[j].operating, members[j].perturbation)
        for j in set(cases.values())
    }
    return {i: solved[j] for i, j in cases.items()}


@dataclasses.dataclass(frozen=True)
class _MemberJob:
    """Picklable `_run_one` (for `parallel_map`)."""

    options: SteadyOptions
    reduce: object = None

    def __call__(self, item):
        member, static = item
        return _run_one(member, self.options, self.reduce, static)


@dataclasses.dataclass
class EngineRun:
    """What `settle_members` returns: one `SeedRun` per member (in order), the strategy that
    ran them, the wall time without compilation and the compilation time [s]; `batch_times`
    for the vmapped strategy (`_engine.BatchTimes`)."""

    runs: list
    strategy: str
    wall_time_s: float
    compile_time_s: float
    batch_times: BatchTimes | None = None


def settle_members(
    members,
    options: SteadyOptions = SteadyOptions(),
    *,
    strategy: str = "auto",
    workers: int = 1,
    devices=None,
    reduce=None,
) -> EngineRun:
    """The steady-running engine: settle and measure every member (`Member`: a case and one
    seed) with `options`, by `strategy` (`_engine`): "sequential" (one after another in this
    process), "processes" (one process per core, `workers` of them; started with `spawn`: a
    script calling this needs the `if __name__ == "__main__":` guard), "vmap" (all members as
    one vmapped program per round, over `devices`: the local devices by default) or "auto"
    (`choose_strategy`: vmap on an accelerator, else processes with `workers` > 1, else
    sequential). Every strategy takes the same decisions for a member; `reduce(run, member)`
    (picklable for "processes") turns each finished `SeedRun` into what is kept."""
    members = list(members)
    if strategy not in STRATEGIES:
        raise UserInputError(f"strategy = {strategy!r}: must be one of {', '.join(map(repr, STRATEGIES))}")
    require("workers", workers, lambda v: (v >= 1) & (v == np.round(v)), "an integer >= 1")
    chosen = choose_strategy(strategy, min(int(workers), len(members)), devices)
    wall0 = time.perf_counter()
    if chosen == "vmap":
        times = BatchTimes()
        groups: dict = {}
        for i, m in enumerate(members):  # one batch per parameter structure
            key = jax.tree_util.tree_structure(options.params(m))
            groups.setdefault(key, []).append(i)
        runs: list = [None] * len(members)
        quiet = dataclasses.replace(options, progress=False)
        for idx in groups.values():
            # the static skid equilibria of the group in one vmapped program, not one by one:
            # for the skid start, and for the verdict's time constant (continuing members too;
            # solved one by one on the host they took 72 of an 84 s search iteration on a GPU)
            cases = _continuing_cases([members[i] for i in idx], options)
            needs = [
                i
                for k, i in enumerate(idx)
                if (
                    members[i].initial_state is None and (options.start == "skid" or options.settle == "auto")
                )
                or cases.get(k) == k
            ]
            h0 = time.perf_counter()
            statics = dict(
                zip(
                    needs,
                    static_skid_starts(
                        [(members[i].bearing, members[i].operating, members[i].perturbation) for i in needs]
                    )
                    if needs
                    else [],
                )
            )
            statics.update({idx[k]: statics[idx[j]] for k, j in cases.items()})
            times.host_s += time.perf_counter() - h0
            outs = drive_batched(
                [member_steps(members[i], quiet, reduce, statics.get(i)) for i in idx],
                [options.params(members[i]) for i in idx],
                [options.tolerances(members[i]) for i in idx],
                solve_from=solve_from,
                num_saves=int(options.saves_per_rev),
                max_steps=int(options.max_steps),
                solver=options.solver,
                devices=devices,
                times=times,
            )
            for i, out in zip(idx, outs):
                runs[i] = out
        wall = time.perf_counter() - wall0 - times.compile_s
        return EngineRun(runs, chosen, wall, times.compile_s, times)
    statics = _shared_time_constants(members, options)
    if chosen == "processes" and len(members) > 1:
        items = [(m, statics.get(i)) for i, m in enumerate(members)]
        outs = parallel_map(_MemberJob(options, reduce), items, workers=min(int(workers), len(members)))
        compile_time = max(c for _, c in outs)
        # the pool's wall time less its longest compilation (the workers compile side by side)
        return EngineRun(
            [r for r, _ in outs], chosen, time.perf_counter() - wall0 - compile_time, compile_time
        )
    outs = [_run_one(m, options, reduce, statics.get(i)) for i, m in enumerate(members)]
    compile_time = sum(c for _, c in outs)
    return EngineRun([r for r, _ in outs], chosen, time.perf_counter() - wall0 - compile_time, compile_time)


def simulate_steady(
    bearing: Bearing,
    op: OperatingPoint,
    *,
    settle="auto",
    window_revs: int = WINDOW_REVS,
    seeds: int = 1,
    tolerance: float = SETTLE_TOLERANCE,
    settle_cap_ms: float = SETTLE_CAP_MS,
    start: str = "skid",
    rtol: float = 1e-3,
    atol: float = 1e-6,
    max_steps: int = 2_000_000,
    saves_per_rev: int = SAVES_PER_REV,
    perturbation: Perturbation = Perturbation(),
    functionals: Functionals = Functionals(),
    progress: bool = False,
    workers: int = 1,
    initial_states=None,
    solver: str = DEFAULT_SOLVER,
    strategy: str = "auto",
    continuation_settle_revs: int | None = None,
) -> SteadyResult:
    """Settle (module docstring), then measure `window_revs` cage revolutions, for each of
    `seeds` seeded initial scatters, each from `start`: "skid" (default; the skid equilibrium and
    projective steps of the cage speed while settling) or "quasi-static" (kinematic speeds).
    The seeds are members of the steady-running engine (`settle_members`).

    `workers` > 1 runs the seeds in that many processes (`parallel_map`, started with `spawn`: a
    script calling this needs the `if __name__ == "__main__":` guard); `jaxbearing simulate`
    uses one per CPU. Default 1: one after another, in this process. On an accelerator the
    seeds run as one vmapped program (`strategy`, `settle_members`). `solver`: "tsit5"
    (default) or "ros34pw2" (`solve`).

    `initial_states` (continuation): one `State` per seed (e.g. `SeedRun.final_state` of a
    neighbouring design's settled run) to start from instead of `start`; settling then runs
    without projective steps (the state is already near its plateau) and `start` is reported
    as "continuation"."""
    forwarded = {k: v for k, v in locals().items() if k not in ("bearing", "op", "initial_states")}
    one = None if initial_states is None else [initial_states]
    (result,) = simulate_steady_points(bearing, [op], initial_states=one, **forwarded)
    return result


def simulate_steady_points(
    bearing: Bearing | list[Bearing],
    ops,
    *,
    settle="auto",
    window_revs: int = WINDOW_REVS,
    seeds: int = 1,
    tolerance: float = SETTLE_TOLERANCE,
    settle_cap_ms: float = SETTLE_CAP_MS,
    start: str = "skid",
    rtol: float = 1e-3,
    atol: float = 1e-6,
    max_steps: int = 2_000_000,
    saves_per_rev: int = SAVES_PER_REV,
    perturbation: Perturbation = Perturbation(),
    functionals: Functionals = Functionals(),
    progress: bool = False,
    workers: int = 1,
    initial_states=None,
    solver: str = DEFAULT_SOLVER,
    strategy: str = "auto",
    continuation_settle_revs: int | None = None,
) -> list[SteadyResult]:
    """`simulate_steady` at every operating point of `ops` (a sequence), every point's seeds
    members of one call of the steady-running engine (`settle_members`: one process pool or one
    vmapped program for all of them, e.g. a design's whole speed envelope); one `SteadyResult`
    per point, in order. `bearing`: one bearing, or one per point (e.g. several designs, each at
    its operating points: one call for a whole iteration of a design search). `initial_states`:
    None, or per point None or one state per seed; `continuation_settle_revs` = n: members given
    a state settle n revolutions of their own cage instead of by `settle` (`continuation_settle`).
    The wall and compilation times of each result are those of the whole call."""
    from ..io import validate_bearing

    ops = list(ops)
    bearings = [bearing] * len(ops) if isinstance(bearing, Bearing) else list(bearing)
    if len(bearings) != len(ops):
        raise UserInputError(
            f"bearing: {len(bearings)} given, expected one, or one per operating point ({len(ops)})"
        )
    check_solver(solver)
    for b, op in zip(bearings, ops):
        validate_bearing(b, op)
    check_steady_options(settle, window_revs, seeds, tolerance, settle_cap_ms, start=start, workers=workers)
    if continuation_settle_revs is not None:
        require(
            "continuation_settle_revs",
            continuation_settle_revs,
            lambda v: (v >= 0) & (v == np.round(v)),
            "an integer >= 0 (revolutions), or None",
        )
        continuation_settle_revs = int(continuation_settle_revs)
    settle = settle if isinstance(settle, str) and settle in ("auto", "off") else float(settle)
    options = SteadyOptions(
        settle=settle,
        window_revs=int(window_revs),
        tolerance=tolerance,
        settle_cap_ms=settle_cap_ms,
        start=start,
        rtol=rtol,
        atol=atol,
        max_steps=int(max_steps),
        saves_per_rev=int(saves_per_rev),
        functionals=functionals,
        progress=progress,
        solver=solver,
        continuation_settle_revs=continuation_settle_revs,
    )
    n = int(seeds)
    perturbations = [dataclasses.replace(perturbation, seed=perturbation.seed + k) for k in range(n)]
    given = list(initial_states) if initial_states is not None else [None] * len(ops)
    if len(given) != len(ops):
        raise UserInputError(
            f"initial_states: {len(given)} given, expected one list per operating point ({len(ops)})"
        )
    members = []
    for b, op, states in zip(bearings, ops, given):
        if states is not None:
            states = list(states)
            if len(states) != n:
                raise UserInputError(f"initial_states: {len(states)} given, expected one per seed ({n})")
        members += [Member(b, op, p, s) for p, s in zip(perturbations, states or [None] * n)]
    engine = settle_members(members, options, strategy=strategy, workers=workers)
    return [
        SteadyResult(
            runs=engine.runs[k * n : (k + 1) * n],
            settle=settle
            if given[k] is None or continuation_settle_revs is None
            else f"continuation, {continuation_settle_revs} revolutions",
            window_revs=int(window_revs),
            tolerance=tolerance,
            cap=settle_cap_ms * 1e-3,
            start=start if given[k] is None else "continuation",
            wall_time_s=engine.wall_time_s,
            compile_time_s=engine.compile_time_s,
            bearing=b,
            operating=op,
        )
        for k, (b, op) in enumerate(zip(bearings, ops))
    ]


def summarise_steady(result: SteadyResult, threshold: float = CONTACT_THRESHOLD) -> dict:
    """The summary.json block of a settled run: how it settled, and every statistic of the
    window as {"value", "ci95_low", "ci95_high", "n"} (`_statistics`)."""
    runs = result.runs
    ok = [r for r in runs if r.measured]
    block = {
        "running": FAILED_LABEL if not result.ok else SETTLED_LABEL if result.settled else UNSETTLED_LABEL,
        "status": "ok" if result.ok else next(r.status for r in runs if r.status != "ok"),
        "settled": bool(result.settled),
        "settle_mode": result.settle if isinstance(result.settle, str) else "fixed",
        "settle_time_ms": max(r.settle_time for r in runs) * 1e3,
        "settle_tolerance": float(result.tolerance),
        "settle_cap_ms": result.cap * 1e3,
        "window_revs": result.window_revs,
        "window_ms": float(np.mean([r.edges[-1] - r.edges[0] for r in ok])) * 1e3 if ok else 0.0,
        "seeds": [r.seed for r in runs],
        "start": result.start,
        "kinematic_cage_speed_rpm": float(
            rad_s_to_rpm(kinematic_cage_speed(result.bearing, result.operating))
        ),
        "per_seed": [
            {
                "seed": r.seed,
                "settled": r.settled,
                "settle_time_ms": r.settle_time * 1e3,
                "status": r.status,
                "num_steps": r.num_steps,
                "revolution_end_ms": [t * 1e3 for t in r.revolution_ends],
                "revolution_cage_speed_rpm": r.revolution_speeds_rpm,
                "start_cage_speed_rpm": r.start_cage_speed_rpm,
                "projective_steps_rpm": r.projective_steps_rpm,
                **_verdict_block(r.verdict),
            }
            for r in runs
        ],
        **_residual_drift(runs),
        "num_steps": sum(r.num_steps for r in runs),
        "wall_time_s": result.wall_time_s,
        "compile_time_s": result.compile_time_s,
    }
    if ok:
        given = [r for r in ok if r.per_revolution is not None]  # the reducer's threshold
        block.update(
            steady_statistics(
                [r.window for r in ok if r.per_revolution is None],
                [r.edges for r in ok if r.per_revolution is None],
                result.bearing,
                result.operating,
                threshold,
                per_revolution=[r.per_revolution for r in given],
            )
        )
    return block


#: how the summary's residual drift is estimated (docs/model.md 16)
RESIDUAL_DRIFT_METHOD = (
    "remaining drift of the cage speed on its slow mode, |b| tau_run: b the slope of the least-squares "
    "line through the revolution-mean cage speeds of the last 4-8 revolutions before the window (since "
    "the last projective step), tau_run the running slow mode's time constant (1.5 x the static skid "
    "equilibrium's tau_s, or the pre-start's longest secant if longer); bound: (|b| + t_{n-2,0.95} SE(b)) tau_run; "
    "settled when bound <= tolerance x cage speed"
)


def _verdict_block(verdict) -> dict:
    """A seed's settling verdict in the summary (nan fields as None: JSON has no nan)."""
    if verdict is None:
        return {}

    def num(x):
        return float(x) if math.isfinite(x) else None

    return {
        "residual_drift_rpm": num(verdict.residual_drift_rpm),
        "residual_drift_bound_rpm": num(verdict.bound_rpm),
        "settling_drift_rpm_s": num(verdict.slope_rpm_s),
        "settling_drift_se_rpm_s": num(verdict.slope_se_rpm_s),
        "verdict_revolutions": int(verdict.revolutions),
        "slow_mode_time_constant_ms": num(verdict.time_constant_s * 1e3),
    }


def _residual_drift(runs) -> dict:
    """The summary's residual drift: the largest over the seeds (None where no verdict was
    evaluated: fixed or no settling)."""
    drifts = [r.verdict.residual_drift_rpm for r in runs if r.verdict is not None]
    bounds = [r.verdict.bound_rpm for r in runs if r.verdict is not None]
    finite = [d for d in drifts if math.isfinite(d)]
    if not finite:
        return {"residual_drift_rpm": None, "residual_drift_bound_rpm": None}
    return {
        "residual_drift_rpm": max(finite),
        "residual_drift_bound_rpm": max(b for b in bounds if math.isfinite(b)),
        "residual_drift_method": RESIDUAL_DRIFT_METHOD,
    }


def simulate(bearing: Bearing, op: OperatingPoint, *, settle=None, **kwargs):
    """`jaxbearing.simulate`: without `settle`, one fixed-duration run from the quasi-static
    start (`_simulate.simulate`, a `SimulationResult`); with `settle` ("auto", "off" or a
    settling time in ms), a settled run (`simulate_steady`, a `SteadyResult`; `window_revs`,
    `seeds`, `tolerance`, `settle_cap_ms` and the solver options go there)."""
    if settle is None:
        return _simulate_fixed(bearing, op, **kwargs)
    kwargs.pop("duration", None)
    kwargs.pop("num_saves", None)
    if kwargs.get("perturbation", 1) is None:
        kwargs["perturbation"] = Perturbation()
    return simulate_steady(bearing, op, settle=settle, **kwargs)


def summarise(result, threshold: float = CONTACT_THRESHOLD) -> dict:
    """`jaxbearing.summarise`: the summary.json block of a fixed run (`_summary.summarise`) or of
    a settled run (`summarise_steady`)."""
    if isinstance(result, SteadyResult):
        return summarise_steady(result, threshold)
    return _summarise_fixed(result, threshold)
