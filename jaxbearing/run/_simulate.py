"""Integration of the whole-bearing dynamics with diffrax (docs/model.md 13).

* Initial state from the quasi-static solution (`_quasistatic`), plus an optional seeded
  perturbation of the rollers' axial positions and skew (a perfectly symmetric bearing never
  skews in a deterministic model; real rollers start with manufacturing scatter).
* Explicit adaptive Runge-Kutta (Tsit5) with a PID step-size controller, the paper's tolerances
  (rtol 1e-3, atol 1e-6) applied to a *scaled deviation* of the state (`_state.Scaling`), so
  that every component's tolerance means something physical (atol: 10 nm, 10 um/s, 0.01 rad/s;
  `dynamics.SCALED_UNITS`, docs/model.md 13), except that the raceway-normal coordinates
  (roller radial position and velocity, inner-ring centre) have tolerances `raceway_loosen` =
  100 times looser (their 62 kHz ringing need not be resolved to rtol) under the max norm
  (`_step_control.TRANSIENT_ERROR_NORM`). Settled windows (`_solve_from.prepare_from`) loosen them
  10 times and the rotations 10 times under the largest RMS of a body's coordinates, which is
  faster there and wrong in the start-up transient (spurious roller-corner impacts);
  `max_steps` explicit. `solver="ros34pw2"` selects the linearly implicit
  Rosenbrock-W method with per-roller Jacobian blocks instead (`_rosenbrock`; slower, docs/performance.md).
* Outputs: the solve keeps only the scaled state at the sample times (`SaveAt(ts=...,
  fn=_saved_state)`, without the accumulators), and the flange-contact quantities, cage speed
  and roller loads are evaluated from those states after the loop (`_histories`), so memory
  grows with the samples, not with the state, and the contacts are compiled once for the
  samples instead of inside diffrax's saving (about 12 % less time to compile;
  docs/performance.md).
* Smooth peak functionals (p-norm of PV, log-sum-exp of the contact height) are integrated in the
  state and are differentiable with respect to every float parameter.
* A failed solve (step limit, step size collapse on non-finite states) returns a result whose
  `status` names the failure and the simulated time reached; it never raises from inside JAX.
"""

from __future__ import annotations

import dataclasses
import functools
import time

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp

from .._errors import UserInputError
from ..dynamics import (
    Functionals,
    Params,
    Scaling,
    contact_loads,
    physical_rates,
    state_scales,
    tangential_unit,
)
from ..flange import flange_flash_temperature, friction_power
from ..geometry import Bearing, OperatingPoint, kinematic_cage_speed
from ..io import SIMULATE_NUM_SAVES, check_solve_inputs
from ._compile_cache import checks_without_host_callbacks, compiled_program
from ._flat import flatten_problem
from ._initial import Perturbation, initial_state, perturbation_of, traced_scatter
from ._progress import SolveProgress
from ._result import SimulationResult, Solution, result_code, simulation_result, smooth_functionals
from ._rosenbrock import DEFAULT_SOLVER, check_solver, diffrax_solver
from ._step_control import (
    DT0,
    ERROR_NORMS,
    TRANSIENT_ERROR_NORM,
    TRANSIENT_RACEWAY_LOOSEN,
    TRANSIENT_ROTATION_LOOSEN,
    raceway_normal_norm,
    step_controller,
)


class SolveArgs(eqx.Module):
    """Arguments of `scaled_field`: the model parameters and the state scaling."""

    params: Params
    scaling: Scaling


def scaled_field(t, y_scaled, args: SolveArgs):
    """The vector field diffrax integrates: dY/dt of the scaled deviation state
    Y = (y - nominal(t)) / scale (`jaxbearing.dynamics.Scaling`)."""
    y = args.scaling.unscale(t, y_scaled)
    return args.scaling.scale_rate(physical_rates(t, y, args.params))


#: samples whose outputs `_histories` evaluates at once (a vmapped chunk; a sweep's vmap over
#: cases multiplies it, so it stays small)
HISTORY_CHUNK = 8


def _saved_state(t, y_scaled, args: SolveArgs):
    """What the solve keeps at a sample time: the scaled state without its accumulators."""
    return dataclasses.replace(y_scaled, accumulators=None)


def _histories(ts, saved, args: SolveArgs) -> dict:
    """The sampled outputs (`_save`) at the times `ts` from the states the solve kept
    (`_saved_state`), evaluated after the loop, `HISTORY_CHUNK` samples at a time
    (`jax.lax.map` over the samples padded to whole chunks; the padding is dropped).

    Evaluating `_save` inside diffrax's saving instead (`SaveAt(fn=_save)`) gives the same
    samples to rounding (4e-12 relative): the states are the same interpolants, and the
    trajectory does not depend on what is saved. Here XLA compiles the contacts of the outputs
    once, which takes about 12 % less time to compile a solve with samples (docs/performance.md)."""
    n = ts.shape[0]
    # padded rather than lax.map's own remainder, which would be a second compiled copy of the
    # contacts (a vmap over the leftover samples)
    chunk = min(HISTORY_CHUNK, n)
    m = -(-n // chunk) * chunk

    def pad(a):
        return jnp.concatenate([a, jnp.broadcast_to(a[-1:], (m - n, *a.shape[1:]))]) if m > n else a

    no_integrals = jax.tree_util.tree_map(jnp.zeros_like, args.scaling.nominal.accumulators)

    def one(sample):
        t, y = sample
        return _save(t, dataclasses.replace(y, accumulators=no_integrals), args)

    out = jax.lax.map(one, (pad(ts), jax.tree_util.tree_map(pad, saved)), batch_size=chunk)
    return jax.tree_util.tree_map(lambda a: a[:n], out)


def _save(t, y_scaled, args: SolveArgs):
    """The sampled outputs at time t of the scaled state `y_scaled` (flange contacts with their
    friction power and flash temperature, docs/model.md 5.5; cage, inner ring, roller loads,
    axial positions and skew)."""
    y = args.scaling.unscale(t, y_scaled)
    loads = contact_loads(y, args.params)
    fl = loads.flange
    e = y.rollers.axis / jnp.linalg.norm(y.rollers.axis, axis=-1, keepdims=True)

    return dict(
        t=t,
        flange_force=fl.normal_force,
        flange_pressure=fl.peak_pressure,
        flange_sliding_speed=fl.sliding_speed,
        flange_roller_surface_speed=fl.roller_surface_speed,
        flange_pv=fl.pv,
        contact_height=fl.contact_height,
        contact_radius=fl.contact_radius,
        end_face_position=fl.end_face_position,
        on_arc=fl.on_arc,
        flange_min_film=fl.min_film,
        flange_central_film=fl.central_film,
        flange_film_parameter=fl.film_parameter,
        flange_top_edge=fl.top_edge,
        flange_face_error=fl.face_error,
        flange_friction_coefficient=fl.friction_coefficient,
        flange_friction_power=friction_power(fl),
        flange_flash_temperature=flange_flash_temperature(args.params.bearing, fl),
        cage_speed=y.cage.speed,
        cage_centre=y.cage.centre,
        inner_ring_centre=y.inner_ring.centre,
        inner_ring_contact_force=jnp.sum(loads.inner.force_on_ring[:, 1:], axis=0)
        + jnp.sum(fl.force_on_ring[:, :2, 1:], axis=(0, 1)),
        roller_inner_load=loads.inner.normal_load,
        roller_outer_load=loads.outer.normal_load,
        roller_axial=y.rollers.axial,
        roller_skew=jnp.sum(e * tangential_unit(y.rollers.azimuth), axis=-1),
    )


#: the keyword arguments of `solve` and `simulate` that `_check_solve` checks
_CHECKED_OPTIONS = (
    "num_saves",
    "rtol",
    "atol",
    "max_steps",
    "progress",
    "perturbation",
    "functionals",
    "adjoint",
    "solver",
    "error_norm",
    "raceway_loosen",
    "rotation_loosen",
)


def _checked_options(arguments: dict) -> dict:
    """The options among a caller's `arguments` (its `locals()` on entry) that `_check_solve`
    checks: one list for `solve` and `simulate`, not a copy of their keywords in each."""
    return {k: arguments[k] for k in _CHECKED_OPTIONS if k in arguments}


def _check_solve(
    bearing, op, duration, *, adjoint=None, solver=DEFAULT_SOLVER, error_norm=None, **kwargs
) -> None:
    """`check_solve_inputs` of the solver arguments, perturbation, functionals and pytrees;
    `adjoint` must be a diffrax adjoint or None; `solver` one of `_rosenbrock.SOLVERS`;
    `error_norm` None, one of `ERROR_NORMS` or a callable."""
    check_solver(solver)
    if not (error_norm is None or error_norm in ERROR_NORMS or callable(error_norm)):
        raise UserInputError(
            f"error_norm = {error_norm!r}: must be one of {ERROR_NORMS}, a function of the scaled "
            f"state pytree returning a scalar, or None (the default, {TRANSIENT_ERROR_NORM!r})"
        )
    if adjoint is not None and not isinstance(adjoint, diffrax.AbstractAdjoint):
        raise UserInputError(
            f"adjoint = {adjoint!r}: must be a diffrax adjoint (e.g. diffrax.ForwardMode()) or None"
        )
    check_solve_inputs(bearing, op, duration=duration, **kwargs)


def _save_functionals(t, y_scaled, args: SolveArgs):
    return args.scaling.unscale(t, y_scaled).accumulators


def scaled_diffeqsolve(
    y0_scaled,
    args,
    duration,
    saveat,
    controller,
    max_steps,
    adjoint,
    progress,
    solver=DEFAULT_SOLVER,
    *,
    flat: bool | None = None,
):
    """diffrax's solver named `solver` (`_rosenbrock.diffrax_solver`: "tsit5" or "ros34pw2")
    over [0, duration] from the scaled state; failures land in `result`. `flat` (None: for
    the explicit solver): the state ravelled into one vector (`_flat.flatten_problem`)."""
    field = scaled_field
    if flat is None:
        flat = solver != "ros34pw2"
    if flat:
        field, y0_scaled, saveat, controller = flatten_problem(field, y0_scaled, saveat, controller)
    return diffrax.diffeqsolve(
        diffrax.ODETerm(field),
        diffrax_solver(solver),
        t0=0.0,
        t1=duration,
        dt0=DT0,
        y0=y0_scaled,
        args=args,
        saveat=saveat,
        stepsize_controller=controller,
        max_steps=max_steps,
        throw=False,
        adjoint=adjoint if adjoint is not None else diffrax.RecursiveCheckpointAdjoint(),
        progress_meter=SolveProgress() if progress else diffrax.NoProgressMeter(),
    )


def solve(
    bearing: Bearing,
    op: OperatingPoint,
    duration,
    *,
    num_saves: int = 4000,
    rtol=1e-3,
    atol=1e-6,
    max_steps: int = 2_000_000,
    progress: bool = False,
    perturbation: Perturbation | None = Perturbation(),
    functionals: Functionals = Functionals(),
    adjoint: diffrax.AbstractAdjoint | None = None,
    raceway_loosen=TRANSIENT_RACEWAY_LOOSEN,
    error_norm=None,
    solver: str = DEFAULT_SOLVER,
    rotation_loosen=TRANSIENT_ROTATION_LOOSEN,
) -> Solution:
    """Pure, jit-able and vmappable solve of the whole bearing over [0, duration].

    `num_saves` (static) samples of the flange-contact quantities, cage and rings are kept
    (`num_saves = 0`: only the smooth functionals at t1, the cheapest form for gradients).
    `adjoint` selects how gradients flow through the solve (default: diffrax's checkpointed
    reverse mode; `diffrax.ForwardMode()` for `jax.jacfwd`).
    Error control (`_step_control`): `error_norm` "max" (None: the default,
    `TRANSIENT_ERROR_NORM`), "rms" or "body_rms" (the largest of the rollers', cage's and inner
    ring's RMS) over the scaled state, with the raceway-normal coordinates' tolerances
    `raceway_loosen` times looser (default 100) and the rotations' (each roller's orbital rate
    and angular velocity, the cage's coordinates) `rotation_loosen` times looser (default 1;
    floats, may be traced; 1 and 1 = the plain norm); a function pytree -> scalar (e.g.
    `optimistix.rms_norm`) replaces it. This is the error control of start-up transients; the
    settled windows' (`prepare_from`) is `error_norm="body_rms", raceway_loosen=10,
    rotation_loosen=10`, which in a start-up transient gives spurious roller-corner impacts
    (`TRANSIENT_ERROR_NORM`).
    `solver` (static): "tsit5" (default, explicit) or "ros34pw2" (linearly implicit
    Rosenbrock-W with every roller's Jacobian block implicit, `_rosenbrock`; slower at the
    tolerances measured so far: docs/performance.md).

    Every argument is checked before anything is traced (`jaxbearing.io.check_solve_inputs`;
    one-line `UserInputError`/`ConfigError`); under jit/vmap/grad traced values cannot be
    checked and pass (`simulate` and the sweep check them concretely first).
    """
    _check_solve(bearing, op, duration, **_checked_options(locals()))
    args, y0_scaled = _transient_start(bearing, op, perturbation, functionals)
    saveat = _transient_saveat(duration, num_saves)
    controller = _transient_controller(y0_scaled, rtol, atol, error_norm, raceway_loosen, rotation_loosen)
    with checks_without_host_callbacks():  # cacheable program (`_compile_cache`)
        sol = scaled_diffeqsolve(
            y0_scaled, args, duration, saveat, controller, max_steps, adjoint, progress, solver
        )
    return _solution(sol, num_saves, args)


def _transient_start(bearing: Bearing, op: OperatingPoint, perturbation, functionals):
    """(SolveArgs, scaled initial state) of a start-up run: the quasi-static initial state with
    `perturbation` (`initial_state`), scaled about itself (`Scaling`: the state's scales and the
    kinematic cage speed's orbit)."""
    y0 = initial_state(bearing, op, perturbation)
    scaling = Scaling(
        nominal=y0,
        scale=state_scales(bearing.num_rollers, bearing.pitch_diameter / 2),
        orbit_speed=kinematic_cage_speed(bearing, op),
    )
    args = SolveArgs(params=Params(bearing=bearing, operating=op, functionals=functionals), scaling=scaling)
    return args, scaling.scale_state(0.0, y0)


def _transient_saveat(duration, num_saves: int):
    """What `solve` keeps: `num_saves` equally spaced samples over [0, duration] and the smooth
    functionals at t1, or only the functionals (`num_saves` = 0)."""
    if num_saves:
        samples = diffrax.SubSaveAt(ts=jnp.linspace(0.0, duration, num_saves), fn=_saved_state)
        return diffrax.SaveAt(subs=[samples, diffrax.SubSaveAt(t1=True, fn=_save_functionals)])
    return diffrax.SaveAt(t1=True, fn=_save_functionals)


def _transient_controller(y0_scaled, rtol, atol, error_norm, raceway_loosen, rotation_loosen):
    """The step controller of `solve`: its `error_norm` by name (None: `TRANSIENT_ERROR_NORM`)
    with the raceway-normal and rotation loosening (`raceway_normal_norm`), or a given norm."""
    if error_norm is None or isinstance(error_norm, str):
        norm = raceway_normal_norm(
            y0_scaled, raceway_loosen, error_norm or TRANSIENT_ERROR_NORM, rotation_loosen
        )
    else:
        norm = error_norm
    return step_controller(rtol, atol, norm)


def _solution(sol, num_saves: int, args: SolveArgs) -> Solution:
    """The `Solution` of `solve` from diffrax's: the histories of the saved samples (none
    without them), the accumulators at t1, the result code and the step counts."""
    if num_saves:
        saved, integrals = sol.ys
        hist = _histories(sol.ts[0], saved, args)
        acc = jax.tree_util.tree_map(lambda a: a[-1], integrals)
    else:
        hist, acc = {}, jax.tree_util.tree_map(lambda a: a[-1], sol.ys)
    return Solution(
        histories=hist,
        accumulators=acc,
        result=result_code(sol.result),
        num_steps=jnp.asarray(sol.stats["num_steps"]),
        num_rejected_steps=jnp.asarray(sol.stats["num_rejected_steps"]),
    )


def flange_functionals(bearing: Bearing, op: OperatingPoint, duration, **kwargs):
    """(smooth peak PV [Pa m/s], smooth max contact height [m], smooth min contact height [m])
    of a run, differentiable with respect to every float parameter of `bearing` and `op`.

    Keyword arguments go to `solve` (`num_saves` is fixed to 0). Non-finite values are
    returned where the solve failed."""
    sol = solve(bearing, op, duration, num_saves=0, **kwargs)
    functionals = kwargs.get("functionals", Functionals())
    values = smooth_functionals(sol.accumulators, functionals)
    ok = sol.result == 0
    return tuple(jnp.where(ok, v, jnp.nan) for v in values)


def _compiled_solve(bearing, op, duration, rtol, atol, static: tuple):
    """Ahead-of-time compiled `solve` (`compiled_program`: once per process, traced once per
    machine), keyed on the pytree structure, shapes and static arguments, so arc and corner ends,
    other speeds, loads, tolerances and seeds of the initial scatter reuse one compilation (the
    scatter's seed and amplitudes are traced)."""
    num_saves, max_steps, progress, perturbation, functionals, solver = static
    scatter = traced_scatter(perturbation)
    dyn = (bearing, op, duration, rtol, atol, scatter)
    static = (num_saves, max_steps, progress, perturbation is None, functionals, solver)

    def run(b, o, d, r, a, sc):
        pert = perturbation_of(sc)
        return solve(
            b,
            o,
            d,
            num_saves=num_saves,
            rtol=r,
            atol=a,
            max_steps=max_steps,
            progress=progress,
            perturbation=pert,
            functionals=functionals,
            solver=solver,
        )

    return functools.partial(compiled_program("simulate", run, dyn, static), *dyn)


def simulate(
    bearing: Bearing,
    op: OperatingPoint,
    *,
    duration: float = 0.02,
    rtol: float = 1e-3,
    atol: float = 1e-6,
    max_steps: int = 2_000_000,
    num_saves: int = 4000,
    progress: bool = False,
    perturbation: Perturbation | None = Perturbation(),
    functionals: Functionals = Functionals(),
    solver: str = DEFAULT_SOLVER,
) -> SimulationResult:
    """Integrate the bearing for `duration` seconds from the quasi-static state with `solver`
    ("tsit5" or "ros34pw2", `solve`).

    Compiles once per bearing structure (cached) and reports compile and run time separately.
    """
    _check_solve(bearing, op, duration, **_checked_options(locals()), rules={"num_saves": SIMULATE_NUM_SAVES})
    dyn = (bearing, op, jnp.asarray(duration, float), jnp.asarray(rtol, float), jnp.asarray(atol, float))
    static = (int(num_saves), int(max_steps), bool(progress), perturbation, functionals, solver)
    start = time.perf_counter()
    compiled = _compiled_solve(*dyn, static)
    compile_time = time.perf_counter() - start
    start = time.perf_counter()
    sol = compiled()
    jax.block_until_ready(sol)
    wall = time.perf_counter() - start
    return simulation_result(sol, bearing, op, functionals, duration, wall, compile_time)
