"""One member of the steady-running engine: a case (bearing with its design, operating point) and
one seeded initial scatter, run as a program of integration requests (docs/model.md 16).

A member's run is a Python generator: it yields a `Request` (continue the dynamics from a state
for a duration), is sent the `Answer` of `solve_from` (histories, final state, result code,
steps), and takes every host-side decision between requests itself, so that every driver of
`_engine` (one member in its own process, one process per core, members vmapped) gives the same
member the same decisions. Its phases (`Phase`):

* **start**: the skid equilibrium and its pre-start (`_initial.pre_start_steps`; read from the
  start cache where the member runs alone), the kinematic start, or a given state
  (continuation);
* **settle**: chunks of one cage revolution (2 pi / the previous revolution's mean cage speed)
  until the settling verdict (`settling_verdict`) passes, at most `settle_cap_ms` (then not
  settled, the residual drift reported); or a fixed time (`SettleFixed`); or none
  (`SettleOff`). While settling from a skid start whose pre-start failed, **projective steps**
  correct the slow variable (Gear & Kevrekidis 2003, "Projective methods for stiff differential
  equations", SIAM J. Sci. Comput. 24:1091): after every two revolutions the measured drift of
  the revolution-mean cage speed, d omega/dt, moves the cage speed (and the rollers' orbit and
  spin in proportion) by tau d omega/dt, the Newton step of the linear slow mode onto its
  plateau, while the step exceeds a quarter of the tolerance, at most `PROJECTIVE_STEPS` times;
* **measure**: `window_revs` further revolutions, whose histories and accumulated integrals
  are the member's `SeedRun`.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Callable
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from ..geometry import Bearing, OperatingPoint, rad_s_to_rpm
from ._initial import (
    Perturbation,
    SkidStart,
    _static_skid_start,
    along_slow_mode,
    kinematic_start,
    pre_start_steps,
    traced_scatter,
)
from ._result import result_message
from ._settings import SettleAuto, SettleFixed, SettleOff, Settling, SteadySettings
from ._start_cache import load_start, start_key, store_start
from ._verdict import running_time_constant, settling_verdict

#: at most this many projective steps of the cage speed while settling from the skid start
PROJECTIVE_STEPS = 4
#: a projective step moves the cage speed by at most this fraction
PROJECTIVE_CAP = 0.05
#: projective steps go on while a step exceeds this fraction of the settling tolerance (a slower
#: drift is left to the settling verdict, which catches a drift below the tolerance per
#: revolution that would still carry the window off its plateau)
PROJECTIVE_THRESHOLD = 0.25


class Phase(enum.Enum):
    """Where a member's run is: settling towards its plateau, or measuring its window."""

    SETTLE = "settle"
    MEASURE = "measure"


class Request(NamedTuple):
    """What a member asks its driver: continue from `state` for `duration` seconds."""

    state: object
    duration: float


class Answer(NamedTuple):
    """What the driver sends back (`solve_from`'s return): the saved histories, the final state,
    the solve's result code (`RESULT_NAMES`) and its number of steps."""

    histories: dict
    final: object
    code: object
    steps: object


@dataclasses.dataclass(frozen=True)
class Member:
    """One member of the steady-running engine (`settle_members`): a bearing (with its design),
    an operating point and one seeded initial scatter. `initial_state` (continuation): a `State`
    to start from instead of the run's start (e.g. `SeedRun.final_state` of a neighbouring
    design), settled without projective steps; `rtol`, `atol`: this member's tolerances (None:
    the settings')."""

    bearing: Bearing
    operating: OperatingPoint
    perturbation: Perturbation = Perturbation()
    initial_state: object = None
    rtol: float | None = None
    atol: float | None = None


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
    #: the settling verdict at the end of settling (`settling_verdict`; with a fixed settling
    #: time or none, the one before the window is not evaluated: nan fields)
    verdict: object = None
    #: the window's `window_statistics`, when a reducer computed them as the seed finished (the
    #: window's histories are then dropped: `window` is empty); `extras`: what else it kept
    per_revolution: dict | None = None
    extras: dict = dataclasses.field(default_factory=dict)

    @property
    def measured(self) -> bool:
        """Whether the run has a window to take statistics from."""
        return self.status == "ok" and (bool(self.window) or self.per_revolution is not None)


@dataclasses.dataclass
class _Course:
    """What one member's settling and window have run so far (`settle_and_measure_steps`)."""

    state: object
    window_start: object
    t: float = 0.0
    steps: int = 0
    since_jump: int = 0  # revolutions run since the last projective step
    speeds: list = dataclasses.field(default_factory=list)  # revolution means [rpm]
    ends: list = dataclasses.field(default_factory=list)  # revolution ends [s]
    centres: list = dataclasses.field(default_factory=list)  # revolution centres [s]
    jumps: list = dataclasses.field(default_factory=list)  # projective steps [rpm]
    windows: list = dataclasses.field(default_factory=list)  # the window's revolutions
    edges: list = dataclasses.field(default_factory=list)  # the window's revolution starts [s]
    integrals: list = dataclasses.field(default_factory=list)  # the window's accumulators

    def advance(self, answer: Answer, rev: float) -> tuple[dict, str | None]:
        """Take the answer of one revolution's request: (its histories at absolute times, None),
        or (its histories, why the run failed) when the solve failed."""
        hist = {k: np.asarray(v) for k, v in answer.histories.items()}
        self.steps += int(answer.steps)
        code = int(answer.code)
        if code != 0 or not np.all(np.isfinite(hist["cage_speed"])):
            why = result_message(code) if code != 0 else "the cage speed became non-finite"
            return (
                hist,
                f"failed: {why}, in the cage revolution from {self.t * 1e3:.2f} to {(self.t + rev) * 1e3:.2f} ms",
            )
        hist["t"] = hist["t"] + self.t
        self.t += rev
        self.state = answer.final
        self.speeds.append(float(rad_s_to_rpm(np.mean(hist["cage_speed"]))))
        self.ends.append(self.t)
        self.centres.append(self.t - 0.5 * rev)
        return hist, None

    def measure(self, hist: dict, rev: float) -> None:
        """Add one window revolution: its histories, start and integrals (the accumulators restart
        at every request)."""
        self.windows.append(hist)
        self.edges.append(self.t - rev)
        acc = self.state.accumulators
        self.integrals.append((float(jnp.sum(acc.pv_power)), float(jnp.sum(acc.contact_time))))

    def projective_step(self, time_constant: float, tolerance: float, fixed: float | None) -> float | None:
        """The projective step of the cage speed [rpm] due now, or None: tau d omega/dt from the
        last two revolution means (capped at `PROJECTIVE_CAP` of the speed), taken while it
        exceeds `PROJECTIVE_THRESHOLD` of the tolerance and a fixed settling time has time left."""
        if self.since_jump < 2 or len(self.jumps) >= PROJECTIVE_STEPS:
            return None
        s, e = self.speeds, self.ends
        drift = (s[-1] - s[-2]) / (0.5 * (e[-1] - (e[-3] if len(e) > 2 else 0.0)))  # rpm/s
        bound = PROJECTIVE_CAP * abs(s[-1])
        jump = float(np.clip(time_constant * drift, -bound, bound))
        big = abs(jump) > PROJECTIVE_THRESHOLD * tolerance * abs(s[-1])
        return jump if big and (fixed is None or self.t < fixed - 1e-12) else None

    def jump(self, jump: float) -> None:
        """Move the cage speed by `jump` rpm along the slow mode."""
        self.jumps.append(jump)
        self.state = along_slow_mode(self.state, jump * math.pi / 30)
        self.since_jump = 0

    def verdict(self, tolerance: float, slow_mode: float):
        """The settling verdict on the revolutions since the last projective step."""
        recent = slice(len(self.speeds) - self.since_jump, None)
        return settling_verdict(self.centres[recent], self.speeds[recent], tolerance, slow_mode)


def settle_and_measure_steps(
    start,
    *,
    seed: int,
    settle: Settling,
    window_revs: int,
    tolerance: float,
    cap: float,
    report: Callable[[str], None] | None = None,
    time_constant: float | None = None,
    slow_mode: float = float("nan"),
):
    """Settle then measure one member from the state `start` (module docstring), as a program of
    integration requests: yields `Request`s, is sent `Answer`s, returns its `SeedRun`.
    `time_constant` [s] (a skid start whose pre-start failed) turns on the projective steps of
    the cage speed; `slow_mode` [s]: the running slow mode's time constant the verdict uses;
    `cap` [s]: the longest settling; `report`: called with a line of progress per revolution."""
    course = _Course(state=start, window_start=start)
    verdict = settling_verdict([], [], tolerance, slow_mode)
    fixed = settle.ms * 1e-3 if isinstance(settle, SettleFixed) else None
    phase = Phase.MEASURE if isinstance(settle, SettleOff) or fixed == 0.0 else Phase.SETTLE
    settled, settle_time, status = isinstance(settle, SettleOff), 0.0, "ok"
    while True:
        rev = 2 * math.pi / abs(float(course.state.cage.speed))
        if phase is Phase.SETTLE and fixed is not None:
            rev = min(rev, fixed - course.t)
        if phase is Phase.MEASURE and not course.windows:
            course.window_start = course.state
        answer = Answer(*(yield Request(course.state, rev)))
        hist, failure = course.advance(answer, rev)
        if failure is not None:
            status = failure
            break
        if report is not None:
            window = " (window)" if phase is Phase.MEASURE else ""
            report(
                f"  t = {course.t * 1e3:7.2f} ms: cage {course.speeds[-1]:9.2f} rpm over the last revolution{window}"
            )
        if phase is Phase.MEASURE:
            course.measure(hist, rev)
            if len(course.windows) == window_revs:
                course.edges.append(course.t)
                break
            continue
        course.since_jump += 1
        jump = None if time_constant is None else course.projective_step(time_constant, tolerance, fixed)
        if jump is not None:
            course.jump(jump)
            if report is not None:
                report(f"  projective step: cage speed {jump:+.2f} rpm")
            continue
        if fixed is not None:
            done = course.t >= fixed - 1e-12
        else:
            verdict = course.verdict(tolerance, slow_mode)
            done = verdict.settled
        if done or course.t >= cap:
            settled, settle_time, phase = done, course.t, Phase.MEASURE
    ws = course.windows
    return SeedRun(
        seed=seed,
        window={k: np.concatenate([w[k] for w in ws]) for k in ws[0]} if ws else {},
        edges=np.asarray(course.edges),
        settle_time=settle_time,
        settled=settled,
        revolution_speeds_rpm=course.speeds,
        revolution_ends=course.ends,
        status=status,
        num_steps=course.steps,
        projective_steps_rpm=course.jumps,
        window_integrals=course.integrals,
        window_start_state=jax.tree_util.tree_map(np.asarray, course.window_start),
        final_state=jax.tree_util.tree_map(np.asarray, course.state),
        start_cage_speed_rpm=float(rad_s_to_rpm(start.cage.speed)),
        verdict=verdict,
    )


def _print(line: str) -> None:
    print(line, flush=True)


def member_steps(member: Member, settings: SteadySettings, reduce=None, static=None, *, stored_start=False):
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
    settle = settings.settle
    if given is not None:  # continuation from a given state
        y0, tau = jax.tree_util.tree_map(jnp.asarray, given), None
        settle = continuation_settle(settings, y0)
    elif settings.start == "skid":
        key = pre_start_key(member, settings) if stored_start else None
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
    if isinstance(settle, SettleAuto):
        slow_mode = running_time_constant(skid if skid is not None else static, bearing, op, pert)
    if settings.progress:
        print(f"seed {pert.seed}: settling ({settle}), then {settings.window_revs} revolutions", flush=True)
    run = yield from settle_and_measure_steps(
        y0,
        seed=pert.seed,
        settle=settle,
        window_revs=settings.window_revs,
        tolerance=settings.tolerance,
        cap=settings.settle_cap_ms * 1e-3,
        report=_print if settings.progress else None,
        time_constant=tau,
        slow_mode=slow_mode,
    )
    return run if reduce is None else reduce(run, member)


def pre_start_key(member: Member, settings: SteadySettings) -> str:
    """The start cache's key of `member`'s pre-start (`_start_cache`): its case and scatter, and
    everything that defines the one-member integration it runs (`_integrator`): the
    functionals, the tolerances, the saves per revolution, the step cap and the solver."""
    inputs = (member.bearing, member.operating, traced_scatter(member.perturbation), settings.functionals)
    setting = (
        *settings.tolerances(member),
        int(settings.saves_per_rev),
        int(settings.max_steps),
        str(settings.solver),
    )
    return start_key("pre-start", inputs, setting)


def continuation_settle(settings: SteadySettings, state) -> Settling:
    """How a member continuing from `state` settles: `settings.settle`, or with
    `settings.continuation_settle_revs` = n a fixed n revolutions of its own cage, 2 pi n /
    |omega_c|, where omega_c is `state`'s cage speed. A design search's next iterate starts from
    the settled states of a design a few per cent of the box away; the settling verdict would
    need at least `VERDICT_MIN_REVS` revolutions for what is mostly a small shift
    (docs/model.md 17)."""
    n = settings.continuation_settle_revs
    if n is None:
        return settings.settle
    return SettleFixed(2e3 * math.pi * float(n) / abs(float(state.cage.speed)))
