"""Integration of the whole-bearing dynamics with diffrax (MODEL.md 6).

* Initial state from the quasi-static solution (`_quasistatic`), plus an optional seeded
  perturbation of the rollers' axial positions and skew (a perfectly symmetric bearing never
  skews in a deterministic model; real rollers start with manufacturing scatter).
* Explicit adaptive Runge-Kutta (Tsit5) with a PID step-size controller, the paper's tolerances
  (rtol 1e-3, atol 1e-6) applied to a *scaled deviation* of the state (`_state.Scaling`) under the
  max norm, so that every component's tolerance means something physical; `max_steps` explicit.
* Outputs through `SaveAt(ts=..., fn=...)`: only the flange-contact quantities, cage speed and
  roller loads are kept, so memory does not grow with the state.
* Smooth peak functionals (p-norm of PV, log-sum-exp of the contact height) are integrated in the
  state and are differentiable with respect to every float parameter.
* A failed solve (step limit, step size collapse on non-finite states) returns a result whose
  `status` names the failure and the simulated time reached; it never raises from inside JAX.
"""

from __future__ import annotations

import dataclasses
import time

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx

from ._dynamics import FLANGE_NAMES, Functionals, Params, contact_loads, physical_rates
from ._params import Bearing, OperatingPoint, kinematic_cage_speed, rad_s_to_rpm
from ._quasistatic import quasi_static
from ._state import (
    Accumulators,
    CageState,
    RingState,
    RollerState,
    Scaling,
    State,
    state_scales,
)


@dataclasses.dataclass(frozen=True)
class Perturbation:
    """Seeded initial scatter of the rollers (uniform in +/- the amplitudes)."""

    seed: int = 0
    axial: float = 0.02e-3  # [m]
    skew: float = 1e-4  # [rad]


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
    from ._state import tangential_unit

    axis = jnp.cos(skew)[:, None] * jnp.array([1.0, 0.0, 0.0]) + jnp.sin(skew)[:, None] * tangential_unit(azimuth)
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
    ring = RingState(centre=qs.inner_ring_displacement, velocity=jnp.zeros(2))
    zeros = jnp.zeros((z, 4))
    acc = Accumulators(pv_power=zeros, height_max_power=zeros, height_min_power=zeros, contact_time=zeros)
    return State(rollers=rollers, cage=cage, inner_ring=ring, accumulators=acc)


class _Args(eqx.Module):
    params: Params
    scaling: Scaling


def _field(t, y_scaled, args: _Args):
    y = args.scaling.unscale(t, y_scaled)
    return args.scaling.scale_rate(physical_rates(t, y, args.params))


def _save(t, y_scaled, args: _Args):
    y = args.scaling.unscale(t, y_scaled)
    loads = contact_loads(y, args.params)
    fl = loads.flange
    e = y.rollers.axis / jnp.linalg.norm(y.rollers.axis, axis=-1, keepdims=True)
    from ._state import tangential_unit

    return dict(
        t=t,
        flange_force=fl.normal_force,
        flange_pressure=fl.peak_pressure,
        flange_sliding_speed=fl.sliding_speed,
        flange_pv=fl.pv,
        contact_height=fl.contact_height,
        contact_radius=fl.contact_radius,
        end_face_position=fl.end_face_position,
        on_arc=fl.on_arc,
        cage_speed=y.cage.speed,
        cage_centre=y.cage.centre,
        inner_ring_centre=y.inner_ring.centre,
        roller_inner_load=loads.inner.normal_load,
        roller_outer_load=loads.outer.normal_load,
        roller_axial=y.rollers.axial,
        roller_skew=jnp.sum(e * tangential_unit(y.rollers.azimuth), axis=-1),
        accumulators=y.accumulators,
    )


def smooth_functionals(acc: Accumulators, functionals: Functionals):
    """(smooth peak PV, smooth max and min contact height) from the integrated accumulators.

    peak PV  = PV_ref (sum int w PV^p dt / sum int w dt)^(1/p)        (p-norm over contact time)
    max h_c  = h_ref + log(sum int w e^{beta dh} dt / sum int w dt) / beta   (log-sum-exp)
    min h_c  = h_ref - log(sum int w e^{-beta dh} dt / sum int w dt) / beta
    Sums run over every roller and flange. Both tend to the true extremes as p, beta grow.
    """
    ct = jnp.sum(acc.contact_time) + 1e-300
    pv = functionals.pv_reference * (jnp.sum(acc.pv_power) / ct) ** (1.0 / functionals.pv_exponent)
    h_max = functionals.height_reference + jnp.log(jnp.sum(acc.height_max_power) / ct + 1e-300) / functionals.height_sharpness
    h_min = functionals.height_reference - jnp.log(jnp.sum(acc.height_min_power) / ct + 1e-300) / functionals.height_sharpness
    return pv, h_max, h_min


@dataclasses.dataclass
class SimulationResult:
    """Histories (numpy, leading axis time), smooth peak functionals and solver status."""

    status: str
    ok: bool
    reached_time: float
    num_steps: int
    num_rejected_steps: int
    wall_time_s: float
    compile_time_s: float
    histories: dict
    smooth_peak_pv: float
    smooth_max_contact_height: float
    smooth_min_contact_height: float
    bearing: Bearing
    operating: OperatingPoint


def _integrate(y0_scaled, args, t1, ts, rtol, atol, max_steps, progress):
    term = diffrax.ODETerm(_field)
    controller = diffrax.PIDController(
        rtol=rtol, atol=atol, pcoeff=0.3, icoeff=0.4, norm=optx.max_norm, dtmin=1e-13
    )
    return diffrax.diffeqsolve(
        term,
        diffrax.Tsit5(),
        t0=0.0,
        t1=t1,
        dt0=1e-7,
        y0=y0_scaled,
        args=args,
        saveat=diffrax.SaveAt(ts=ts, fn=_save, t1=True),
        stepsize_controller=controller,
        max_steps=max_steps,
        throw=False,
        progress_meter=diffrax.TextProgressMeter(minimum_increase=0.05)
        if progress
        else diffrax.NoProgressMeter(),
    )


_integrate_jit = eqx.filter_jit(_integrate)


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
) -> SimulationResult:
    """Integrate the bearing for `duration` seconds from the quasi-static state."""
    y0 = initial_state(bearing, op, perturbation)
    omega_c = kinematic_cage_speed(bearing, op)
    scaling = Scaling(
        nominal=y0, scale=state_scales(bearing.num_rollers, float(bearing.pitch_diameter) / 2), orbit_speed=omega_c
    )
    # nominal azimuths/cage angle advance with the orbit; their nominal value is the t=0 value
    args = _Args(params=Params(bearing=bearing, operating=op, functionals=functionals), scaling=scaling)
    y0_scaled = scaling.scale_state(0.0, y0)
    ts = jnp.linspace(0.0, duration, num_saves)

    start = time.perf_counter()
    lowered = _integrate_jit.lower(y0_scaled, args, duration, ts, rtol, atol, max_steps, progress)
    compiled = lowered.compile()
    compile_time = time.perf_counter() - start
    start = time.perf_counter()
    sol = compiled(y0_scaled, args, duration, ts, rtol, atol, max_steps, progress)
    jax.block_until_ready(sol.ys)
    wall = time.perf_counter() - start
    return _result(sol, scaling, args, bearing, op, functionals, duration, wall, compile_time)


def _result_message(result) -> str:
    for name in ("max_steps_reached", "dt_min_reached"):
        if hasattr(diffrax.RESULTS, name) and result == getattr(diffrax.RESULTS, name):
            return {"max_steps_reached": "the step limit max_steps was reached",
                    "dt_min_reached": "the step size collapsed below dtmin (non-finite or unresolvable dynamics)"}[name]
    return "the solver did not succeed"


def _result(sol, scaling, args, bearing, op, functionals, duration, wall, compile_time) -> SimulationResult:
    ys = jax.tree_util.tree_map(np.asarray, sol.ys)
    # the last saved entry is t1 (SaveAt(t1=True)); histories are the ts entries
    hist = {k: jax.tree_util.tree_map(lambda a: a[:-1], v) for k, v in ys.items()}
    ok = bool(sol.result == diffrax.RESULTS.successful)
    t_saved = hist["t"]
    finite = np.isfinite(t_saved) & np.all(np.isfinite(hist["cage_speed"].reshape(len(t_saved), -1)), axis=1)
    reached = float(t_saved[finite][-1]) if finite.any() else 0.0
    if ok:
        status = "ok"
    else:
        status = (
            f"failed: {_result_message(sol.result)} (simulated time reached {reached * 1e3:.4f} ms"
            f" of {duration * 1e3:.4f} ms)"
        )
    hist.pop("accumulators")
    hist = {k: v[finite] for k, v in hist.items()}  # cut at the last finite sample
    stats = sol.stats
    final_acc = jax.tree_util.tree_map(lambda x: x[-1], sol.ys["accumulators"])
    pv_peak, h_max, h_min = (float(v) for v in smooth_functionals(final_acc, functionals))
    if not ok:
        pv_peak, h_max, h_min = np.nan, np.nan, np.nan
    return SimulationResult(
        status=status,
        ok=ok,
        reached_time=reached,
        num_steps=int(stats["num_steps"]),
        num_rejected_steps=int(stats["num_rejected_steps"]),
        wall_time_s=wall,
        compile_time_s=compile_time,
        histories=hist,
        smooth_peak_pv=pv_peak,
        smooth_max_contact_height=h_max,
        smooth_min_contact_height=h_min,
        bearing=bearing,
        operating=op,
    )
