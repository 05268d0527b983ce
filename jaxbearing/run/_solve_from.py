"""Continue the dynamics from any physical state: the integration request of a settled run
(docs/model.md 16).

`solve_from` integrates from a state over [0, duration] with the integrator of `solve` (Tsit5 or
ROS34PW2, the PID controller on the scaled state) and the settled windows' error norm
(`raceway_normal_norm`); the scaling's nominal orbit restarts at every request from the
request's own start state and cage speed, so the scaled azimuths never accumulate the cage slip
over a long run. `_compiled` and `_integrator` give it compiled once per process
(`compiled_program`), as one member's run needs it.
"""

from __future__ import annotations

import time

import diffrax
import jax
import jax.numpy as jnp

from ..dynamics import Params, Scaling, State, state_scales
from ._compile_cache import checks_without_host_callbacks, compiled_program
from ._result import result_code
from ._rosenbrock import DEFAULT_SOLVER
from ._simulate import SolveArgs, _histories, _saved_state, scaled_diffeqsolve
from ._step_control import raceway_normal_norm, step_controller


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
