"""Error control of the solve: which components of the state steer the step size.

diffrax's `PIDController` accepts a step when norm(err / (atol + rtol |Y|)) <= 1, the error
estimate `err` and `Y` being pytrees of the scaled deviation state (`dynamics.Scaling`). The
norm decides which degrees of freedom the step size is spent on.

The max norm over every component (`optimistix.max_norm`, jaxbearing's old default) lets the
fastest mode of the model set the step: the radial vibration of a loaded roller between its
raceways (about 62 kHz at the reference point, eigenvalue -5.6e4 +- 3.9e5 i; micrometre
amplitude; issue 12). Its error estimate reaches the tolerance at steps of about 2-4 us, while
the flange statistics do not depend on resolving its phase.

`RacewayNormalNorm` is the max norm with the raceway-normal coordinates of every roller (radial
position and velocity) and the inner ring's radial position, tilt and their rates (the tilt
moves the raceway normally, against the same slice stiffness) weighted by 1/`loosen`:
their tolerances are `loosen` times looser, every other component (axial motion, skew and tilt
of the axis, spin, orbit, cage) keeps the tolerance it had. With `loosen = 1` it is exactly the
max norm. An explicit method still keeps the radial mode stable (its step cannot exceed the
stability limit, about 7.5 us for Tsit5); what is no longer paid for is resolving its phase to
rtol.
"""

from __future__ import annotations

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, Float

from ..dynamics import State

#: default loosening of the raceway-normal tolerances, chosen with
#: benchmarks/bench_work_precision.py (README, Performance): 10, 100, 1000 and 1e4 all take
#: 1.28-1.31x fewer field evaluations than the plain max norm at rtol 1e-3 (beyond 10 the step
#: is held by the explicit stability limit of the radial mode, not by its error), with the
#: flange statistics within the reference's confidence interval; 100 still controls the radial
#: coordinates to 10 % of their deviation.
RACEWAY_NORMAL_LOOSEN = 100.0

#: PID step-size controller coefficients (diffrax `PIDController`: proportional 0.3, integral
#: 0.4, the values diffrax's documentation suggests for non-stiff problems).
PID_PCOEFF, PID_ICOEFF = 0.3, 0.4
#: smallest step [s]: below it the solve stops with `dt_min_reached` (non-finite dynamics).
DT_MIN = 1e-13
#: first step tried [s] (diffrax's automatic first step stalls at the quasi-static start).
DT0 = 1e-7


def step_controller(rtol, atol, norm) -> diffrax.PIDController:
    """The step-size controller of every solve: PID with `PID_PCOEFF`, `PID_ICOEFF`, `DT_MIN`
    and the error `norm` (e.g. `raceway_normal_norm(y0)`)."""
    return diffrax.PIDController(
        rtol=rtol, atol=atol, pcoeff=PID_PCOEFF, icoeff=PID_ICOEFF, norm=norm, dtmin=DT_MIN
    )


def raceway_normal_weights(state: State, loosen) -> State:
    """Weights of the error norm: 1/`loosen` on roller radial position and velocity and on the
    inner ring's centre, tilt and their rates, 1 elsewhere (same pytree as `state`)."""
    w = jnp.asarray(1.0) / jnp.asarray(loosen, dtype=float)
    ones = jax.tree_util.tree_map(jnp.ones_like, state)
    loose = lambda x: w * jnp.ones_like(x)  # noqa: E731
    return eqx.tree_at(
        lambda s: (
            s.rollers.radial,
            s.rollers.radial_velocity,
            s.inner_ring.centre,
            s.inner_ring.velocity,
            s.inner_ring.tilt,
            s.inner_ring.tilt_rate,
        ),
        ones,
        replace_fn=loose,
    )


class RacewayNormalNorm(eqx.Module):
    """max_i w_i |x_i| over the leaves of a `State` (weights from `raceway_normal_weights`)."""

    weights: State

    def __call__(self, x: State) -> Float[Array, ""]:
        leaves = jax.tree_util.tree_leaves(
            jax.tree_util.tree_map(lambda w, v: jnp.max(jnp.abs(w * v)), self.weights, x)
        )
        return jnp.max(jnp.stack(leaves))


def raceway_normal_norm(state: State, loosen=RACEWAY_NORMAL_LOOSEN) -> RacewayNormalNorm:
    """The error norm of `solve` for a state shaped like `state` (module docstring)."""
    return RacewayNormalNorm(weights=raceway_normal_weights(state, loosen))
