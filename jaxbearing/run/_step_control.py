"""Error control of the solve: which components of the state steer the step size.

diffrax's `PIDController` accepts a step when norm(err / (atol + rtol |Y|)) <= 1, the error
estimate `err` and `Y` being pytrees of the scaled deviation state (`dynamics.Scaling`). The
norm decides which degrees of freedom the step size is spent on.

The max norm over every component (`optimistix.max_norm`, jaxbearing's old default) lets the
fastest mode of the model set the step: the radial vibration of a loaded roller between its
raceways (about 62 kHz at the reference point, eigenvalue -5.6e4 +- 3.9e5 i; micrometre
amplitude). Its error estimate reaches the tolerance at steps of about 2-4 us, while
the flange statistics do not depend on resolving its phase.

`RacewayNormalNorm` weights the raceway-normal coordinates of every roller (radial position
and velocity) and the inner ring's radial position, tilt and their rates (the tilt moves the
raceway normally, against the same slice stiffness) by 1/`loosen`: their tolerances are `loosen`
times looser; the rotations (spin, orbit, cage) are weighted by 1/`rotation_loosen` (below);
the flange contact's coordinates (axial motion, skew and tilt of the axis) keep their
tolerance. An explicit method still keeps the radial mode stable (its step
cannot exceed the stability limit, about 7.5 us for Tsit5); what is no longer paid for is
resolving its phase to rtol.

Two error controls, one per kind of run:
- settled windows (`_solve_from.prepare_from`: settled `simulate`, the steady design search, the
  settled benchmark) take `DEFAULT_ERROR_NORM` = "body_rms" with `RACEWAY_NORMAL_LOOSEN` = 10
  and `ROTATION_LOOSEN` = 10 (below);
- start-up transients (`solve`: fixed-duration runs, sweeps, trajectory gradients) take
  `TRANSIENT_ERROR_NORM` = "max" with the raceway-normal tolerances 100x looser and the
  rotations not loosened, because the settled windows' control gives spurious roller-corner
  impacts on the flange in a transient (`benchmarks/results/diagnose_peak_spread.json`).

The weighted components are combined per body (`DEFAULT_ERROR_NORM` = "body_rms"): the RMS
over each roller's 12 coordinates, over the cage's and over the inner ring's, and the largest
of these (Hairer, Norsett & Wanner, Solving ODEs I, II.4, eq. 4.11, per body). No roller's
error hides among the other rollers' (one coordinate may exceed its tolerance by at most
sqrt(12) = 3.5 when it alone errs), while the several coordinates of one roller that all held
the step under the max norm (docs/performance.md) share one tolerance. Chosen by the settled
work-precision benchmark and by the peak-PV check of `benchmarks/results/diagnose_error_norms.json`
(docs/performance.md; docs/model.md 13):
- "max", the max norm over every coordinate (with the raceway-normal tolerances 100x looser,
  the error control of start-up transients): every statistic agrees with a tight reference;
- "rms", the RMS over all 328 coordinates of the bodies (SciPy's and diffrax's default
  norm): 1.7x fewer evaluations than "max" in settled running, but the p95 flange PV failed
  against the reference on seeds not used to choose it, and the smooth peak PV of a start-up
  transient came out up to 28 % low at some tolerances: one roller's impact error hides
  among 26 rollers' coordinates;
- "body_rms", the settled windows' norm: 1.33x fewer evaluations than "max", agreeing on every statistic
  on both sets of seeds, with the peak PV spread of "max".

Under the per-roller RMS the rotations held the step: each roller's orbital rate (its
collisions with the cage pockets), its angular velocity (spin traction) and the cage's
coordinates (benchmarks/results/diagnose_step_control_body_rms.json). Their tolerances are
`rotation_loosen` = 10 times looser in settled windows (`ROTATION_LOOSEN`): 1.25x fewer evaluations in
settled running, every flange statistic and the cage slip agreeing with the tight reference
on the seeds used to choose it and on others. The smooth peak PV of a start-up transient
shows no bias against the max norm, but scatters about three times as much between
trajectories (standard deviation 3.4 % against 1.1 %; docs/performance.md), and with the
step sequence alone changed it holds spurious corner impacts (`TRANSIENT_ERROR_NORM`), so
`solve` does not loosen them. The flange contact's own coordinates (a
roller's axial position and velocity, its axis: skew and tilt) keep their tolerances.
`solve(error_norm="body_rms", raceway_loosen=10, rotation_loosen=10)` runs a transient under
the settled windows' control.
"""

from __future__ import annotations

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx
from jaxtyping import Array, Float

from ..dynamics import State

#: default loosening of the raceway-normal tolerances. Under the max norm (the earlier default),
#: 10, 100, 1000 and 1e4 all took 1.28-1.31x fewer field evaluations than the plain max norm at
#: rtol 1e-3 (benchmarks/bench_work_precision.py; beyond 10 the step is held by the explicit
#: stability limit of the radial mode), and 100 was the default. Under the RMS norms, 10 and
#: 100 cost about the same (benchmarks/bench_work_precision_settled.py), but with the all-body
#: RMS at 100 the p95 flange PV came out 5 % low against the tight reference (beyond its
#: half-width): the radial coordinates then hardly count and the step nears the radial mode's
#: stability limit. 10 keeps them in the error control.
RACEWAY_NORMAL_LOOSEN = 10.0
#: default loosening of the rotations' tolerances: each roller's orbital rate and angular
#: velocity and the cage's coordinates. Under the per-roller RMS with the raceway-normal
#: coordinates 10x looser, these held the step (benchmarks/results/diagnose_step_control_body_rms.json:
#: with everything else 100x looser, the roller's orbital rate alone kept 93 % of the
#: evaluations). 10x looser: 1.25x fewer evaluations in settled running, every statistic
#: agreeing with the tight reference on seeds 0-3 and on seeds 4-7 not used to choose it; 100x
#: gains 1.5 % more (benchmarks/bench_work_precision_settled.py, rows 25-27). Settled windows
#: only (`prepare_from`): in the start-up transient it gives spurious corner impacts
#: (`TRANSIENT_ERROR_NORM`).
ROTATION_LOOSEN = 10.0

#: PID step-size controller coefficients (diffrax `PIDController`: proportional 0.3, integral
#: 0.4, the values diffrax's documentation suggests for non-stiff problems).
PID_PCOEFF, PID_ICOEFF = 0.3, 0.4
#: the controller's safety factor on the proposed step and its largest growth per step
#: (diffrax's defaults, stated here so that a benchmark can vary them)
PID_SAFETY, PID_FACTORMAX = 0.9, 10.0
#: smallest step [s]: below it the solve stops with `dt_min_reached` (non-finite dynamics).
DT_MIN = 1e-13
#: first step tried [s] (diffrax's automatic first step stalls at the quasi-static start).
DT0 = 1e-7


def step_controller(
    rtol,
    atol,
    norm,
    *,
    pcoeff=PID_PCOEFF,
    icoeff=PID_ICOEFF,
    safety=PID_SAFETY,
    factormax=PID_FACTORMAX,
) -> diffrax.PIDController:
    """The step-size controller of every solve: PID with `PID_PCOEFF`, `PID_ICOEFF`,
    `PID_SAFETY`, `PID_FACTORMAX`, `DT_MIN` and the error `norm` (e.g.
    `raceway_normal_norm(y0)`). The keywords are for studies of the controller
    (benchmarks/bench_work_precision_settled.py); they may be traced."""
    return diffrax.PIDController(
        rtol=rtol,
        atol=atol,
        pcoeff=pcoeff,
        icoeff=icoeff,
        safety=safety,
        factormax=factormax,
        norm=norm,
        dtmin=DT_MIN,
    )


def raceway_normal_weights(state: State, loosen, rotation_loosen=1.0) -> State:
    """Weights of the error norm: 1/`loosen` on roller radial position and velocity and on the
    inner ring's centre, tilt and their rates; 1/`rotation_loosen` on the rollers' orbital rate
    and angular velocity and on the cage's coordinates; 1 elsewhere (same pytree as
    `state`)."""
    w = jnp.asarray(1.0) / jnp.asarray(loosen, dtype=float)
    w_rotation = jnp.asarray(1.0) / jnp.asarray(rotation_loosen, dtype=float)
    ones = jax.tree_util.tree_map(jnp.ones_like, state)
    loose = lambda x: w * jnp.ones_like(x)  # noqa: E731
    weights = eqx.tree_at(
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
    return eqx.tree_at(
        lambda s: (s.rollers.azimuth_rate, s.rollers.angular_velocity, s.cage),
        weights,
        replace_fn=lambda x: jax.tree_util.tree_map(lambda v: w_rotation * v, x),
    )


#: the error norms `RacewayNormalNorm` can take over the weighted components, and the default
ERROR_NORMS = ("max", "rms", "body_rms")
DEFAULT_ERROR_NORM = "body_rms"

#: The error control of start-up transients (`solve`: fixed-duration runs, sweeps, trajectory
#: gradients): the max norm with the raceway-normal tolerances 100x looser, the rotations not
#: loosened. The settled windows' error control
#: (`DEFAULT_ERROR_NORM`, `RACEWAY_NORMAL_LOOSEN`, `ROTATION_LOOSEN`; `prepare_from`) takes
#: 1.4x fewer steps on the 4 ms start-up transient, but there, with only the step sequence
#: changed (8 runs at rtols 1 % apart), 5 of 8 runs hold a roller-corner impact on the flange
#: (smooth peak PV 8x the tight runs') that no run at rtol 2e-4 shows, and the other 3 come out
#: 31 % low; the per-roller RMS alone gives 2 of 8, the max norm with the rotations 10x looser
#: 2 of 8, this setting 0 of 8 within 2 % (to 3 %) of the tight median
#: (benchmarks/results/diagnose_peak_spread.json). Settled windows show no corner contact under their
#: error control (docs/performance.md).
TRANSIENT_ERROR_NORM = "max"
TRANSIENT_RACEWAY_LOOSEN = 100.0
TRANSIENT_ROTATION_LOOSEN = 1.0


class RacewayNormalNorm(eqx.Module):
    """The weighted error norm over the components x_i of a `State` (weights w_i from
    `raceway_normal_weights`; module docstring): `kind` "max", max_i w_i |x_i|
    (`optimistix.max_norm`); "rms", sqrt(sum_i (w_i x_i)^2 / N) (`optimistix.rms_norm`, zero
    derivative at zero) over the N = 12 Z + 16 coordinates of the rollers, cage and inner ring;
    "body_rms", max over bodies B of sqrt(sum_{i in B} (w_i x_i)^2 / N_B), the bodies being each
    roller (N_B = 12), the cage (6) and the inner ring (10). The accumulators of the smooth
    functionals are scaled so that they never steer the step (docs/model.md 13) and are left
    out of both RMS kinds: counted in N they would loosen every tolerance, and the error
    control would depend on how many functionals are integrated."""

    weights: State
    kind: str = eqx.field(static=True, default=DEFAULT_ERROR_NORM)

    def __check_init__(self):
        if self.kind not in ERROR_NORMS:
            raise ValueError(f"error norm kind {self.kind!r} is not one of {ERROR_NORMS}")

    def __call__(self, x: State) -> Float[Array, ""]:
        weighted = jax.tree_util.tree_map(lambda w, v: w * v, self.weights, x)
        if self.kind == "max":
            return optx.max_norm(weighted)
        if self.kind == "rms":
            return optx.rms_norm((weighted.rollers, weighted.cage, weighted.inner_ring))
        largest = jnp.max(_mean_squares_per_body(weighted))
        positive = largest > 0.0  # double where: a zero, not a NaN, derivative at zero error
        return jnp.where(positive, jnp.sqrt(jnp.where(positive, largest, 1.0)), 0.0)


def _mean_squares_per_body(x: State) -> Float[Array, " Z+2"]:
    """Mean square of each roller's 12 coordinates, of the cage's and of the inner ring's."""
    z = x.rollers.axial.shape[0]
    rollers = [jnp.reshape(v, (z, -1)) for v in jax.tree_util.tree_leaves(x.rollers)]
    per_roller = sum(jnp.sum(v**2, axis=1) for v in rollers) / sum(v.shape[1] for v in rollers)
    bodies = [optx.rms_norm(x.cage) ** 2, optx.rms_norm(x.inner_ring) ** 2]
    return jnp.concatenate([per_roller, jnp.stack(bodies)])


def raceway_normal_norm(
    state: State,
    loosen=RACEWAY_NORMAL_LOOSEN,
    kind: str = DEFAULT_ERROR_NORM,
    rotation_loosen=ROTATION_LOOSEN,
) -> RacewayNormalNorm:
    """The error norm of `solve` for a state shaped like `state` (module docstring)."""
    return RacewayNormalNorm(weights=raceway_normal_weights(state, loosen, rotation_loosen), kind=kind)
