"""Differentiable design metrics of the roller end and flange (docs/model.md 13 and 17).

The design variables are the three quantities the source study tunes (Machines 2025, 13(11),
993, Section 3.4 and Figure 14): the end radius R_end, the flange layback angle theta_f and the
axial clearance Delta_bf. `design_metrics` returns, for one design,

- from the dynamic run (`jaxbearing.flange_functionals`, smooth functionals integrated inside
  the solve): the smooth peak flange PV (a p-norm over contact time of p_max |u|) and the smooth
  extreme contact heights (log-sum-exp over contact time);
- from the static design zone of an aligned roller (`jaxbearing.design_zone`): the contact
  height h_c = D/2 - R_end sin(theta_f), and the four margins of the design zone (relief, upper
  height limit, limited circle, actual axial clearance Lambda_bf = Delta_bf - 2 e cos(theta_f),
  the paper's Eq. 24), positive when satisfied.

Everything is a pure function of JAX arrays: `jax.grad` / `jax.jacfwd` differentiate it with
respect to the design and to any float parameter of the bearing and operating point, and
`jax.vmap` maps it over stacked `DesignVariables`.

Gradient mode. With three design variables and a scalar (or few-output) objective, forward mode
(`diffrax.ForwardMode()`, three Jacobian-vector products vmapped: one solve carries the primal
and three tangents) is the default of `design_jacobian` and of the `optimise` package;
diffrax's checkpointed reverse mode (`RecursiveCheckpointAdjoint`, the default adjoint of
`jax.grad`) re-runs the forward pass from checkpoints and integrates the adjoint backwards.
Measured on the reference bearing (`benchmarks/bench_gradients.py`, 2-core CPU, 0.3 ms, rtol
1e-6 / atol 1e-9, compile excluded, value and gradient of the smooth peak PV): forward mode
4.4x the time of one forward solve, checkpointed reverse mode 5.4x, central differences 7.1x;
forward mode is faster by 1.24x and compiles in half the time (44 s against 92 s), so it is the
default. (An earlier measurement on the same machine under heavy load from other jobs had the
order reversed, reverse 1.5x faster; the interleaved minimum above is the one to trust, and
benchmarks/results/gradients.json holds the latest figures.)

Horizon and initial scatter (why `GRADIENT_HORIZON` is 0.3 ms with `seated_perturbation`).
From the default absolute scatter (`jaxbearing.Perturbation`: +/- 0.02 mm axial, +/- 1e-4 rad
skew) no roller touches a flange before about 1.0 ms at 20,000 rpm; then skew has driven the
rollers across their axial play and they *impact* the flanges. Through those impacts the
smooth peak PV is a steep function of the design (the impact timing moves with Delta_bf by
d(Delta_bf) / (2 v_axial)), and central differences do not converge: at 1.2 ms, rtol 1e-6,
the FD estimate of d(PV)/d(Delta_bf) was 5.3e12, 2.5e13 and -9.3e13 Pa m/s / m for relative
steps 1e-3, 1e-4 and 1e-5 (d/dR_end: -1.1e11, -1.4e11, -3.1e11). With the scatter scaled to each
design's axial play so that the outermost roller starts at zero interference with its flange
(`seated_perturbation`), the first contact is gentle and the flange functionals are smooth in
the design: at 0.3 ms central differences with relative steps 1e-3, 1e-4 and 1e-5 agree to
better than 1e-5 and forward-mode AD agrees with them to about 1e-6 (tests/test_design.py
asserts 1%, and the FD convergence itself to 0.1%). At 0.5 ms the smooth peak PV is unchanged
(the first contact still dominates the p-norm); by 1.0 ms further rollers reach their flanges
with impacts, the PV rises to about 4 GPa m/s, and FD no longer converges (d(PV)/d(theta_f)
changed sign between relative steps 1e-4 and 1e-5). AD remains the exact derivative of the
discrete solution there, but it is a sensitivity of impact timing, not a smooth design trend:
past the first impacts, gradients of peak quantities through a long run are not a reliable
design signal. Hence the short horizon for the gradient check, and the documented choice of
horizon in the `optimise` package.
"""

from __future__ import annotations

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from .._errors import UserInputError
from ..flange import DEFAULT_FLANGE_LOAD, DesignVariables, check_design, design_zone
from ..geometry import Bearing, OperatingPoint
from ..io import SOLVER_ARGUMENTS, check_model_inputs, check_solver_arguments
from ..run import Perturbation, compiled_program, flange_functionals

#: horizon [s] at which AD and central finite differences of the flange functionals agree to 1%
#: on the reference bearing from `seated_perturbation` (see the module docstring)
GRADIENT_HORIZON = 0.3e-3
#: tolerances of the gradient check (applied to the scaled state, as in `jaxbearing.solve`; atol
#: 1e-9 is 10 pm, 10 nm/s, 1e-5 rad/s, `dynamics.SCALED_UNITS`)
GRADIENT_RTOL = 1e-6
GRADIENT_ATOL = 1e-9

#: measured cost of value + gradient in the three design variables (benchmarks/bench_gradients.py,
#: reference bearing, 0.3 ms, rtol 1e-6 / atol 1e-9, 2-core CPU, compile excluded, minimum of 5
#: interleaved repeats)
GRADIENT_MODE_NOTE = (
    "forward mode (3 vmapped JVPs through diffrax.ForwardMode) is the default: 4.4x one forward "
    "solve, against 5.4x for checkpointed reverse mode (RecursiveCheckpointAdjoint) and 7.1x for "
    "central differences (7 solves); forward mode is 1.24x faster than reverse mode and compiles "
    "in half the time (44 s against 92 s); both agree with central differences to 1.2e-8"
)

Scalar = Float[Array, "*batch"]


class DesignMetrics(eqx.Module):
    """Dynamic and static measures of one design (SI units; positive margins are satisfied).

    peak_pv: smooth peak flange PV [Pa m/s] of the dynamic run (p-norm over contact time).
    max_contact_height, min_contact_height: smooth extremes of the dynamic contact height [m].
    static_contact_height: h_c = D/2 - rho_c of an aligned roller [m].
    actual_axial_clearance: Lambda_bf = Delta_bf - 2 e cos(theta_f) [m] (paper Eq. 24).
    relief_margin, height_margin, limited_circle_margin, clearance_margin: design zone margins
    [m] (`jaxbearing.DesignZone`).
    """

    peak_pv: Scalar
    max_contact_height: Scalar
    min_contact_height: Scalar
    static_contact_height: Scalar
    actual_axial_clearance: Scalar
    relief_margin: Scalar
    height_margin: Scalar
    limited_circle_margin: Scalar
    clearance_margin: Scalar

    @property
    def margins(self) -> Float[Array, "*batch 4"]:
        """(relief, height, limited circle, clearance) margins [m] on a trailing axis."""
        return jnp.stack(
            [self.relief_margin, self.height_margin, self.limited_circle_margin, self.clearance_margin],
            axis=-1,
        )

    @property
    def feasible(self):
        """Every design-zone margin positive."""
        return jnp.all(self.margins > 0, axis=-1)


def seated_perturbation(bearing: Bearing, *, seed: int = 0, skew: float = 1e-4) -> Perturbation:
    """Initial roller scatter scaled to the axial play of `bearing`'s design.

    The axial offsets of `jaxbearing.Perturbation` are a_j = A u_j, u_j uniform in [-1, 1]
    (seeded). Here A = g_s / (2 max_j |u_j|), with g_s the seated gap of an aligned, centred
    roller (`jaxbearing.DesignZone.seated_gap`, the total gap along both flange normals), so
    the outermost roller starts exactly at zero interference with its flange and every other
    roller inside its play. Designs are then compared from equivalent initial conditions: an
    absolute scatter would start a tight-clearance design with rollers inside the flange and a
    loose one with every roller far from it, and the first contacts would be impacts whose
    timing, not the design, dominates the flange functionals. A is differentiable in the design.
    """
    import numpy as np

    with jax.ensure_compile_time_eval():  # the seeded draws are constants, also under jit
        k1, _ = jax.random.split(jax.random.PRNGKey(seed))
        u_max = float(
            np.max(
                np.abs(np.asarray(jax.random.uniform(k1, (bearing.num_rollers,), minval=-1.0, maxval=1.0)))
            )
        )
    half_gap = design_zone(bearing).seated_gap / 2
    return Perturbation(seed=seed, axial=half_gap / u_max, skew=skew)


def _check_design_inputs(bearing, op, design, duration, solve_kwargs, flange_load=None, min_clearance=None):
    """Before tracing: the solver arguments among `solve_kwargs` and the duration, the base
    bearing and operating point (`check_model_inputs`) and the design (`check_design`); `solve`
    checks the rest."""
    check_solver_arguments(
        duration=duration, **{k: v for k, v in solve_kwargs.items() if k in SOLVER_ARGUMENTS}
    )
    check_model_inputs(bearing, op)
    check_design(bearing, design, flange_load=flange_load, min_clearance=min_clearance)


def design_metrics(
    bearing: Bearing,
    op: OperatingPoint,
    design: DesignVariables,
    *,
    duration: ArrayLike,
    flange_load: ArrayLike = DEFAULT_FLANGE_LOAD,
    min_clearance: ArrayLike = 0.0,
    **solve_kwargs,
) -> DesignMetrics:
    """Dynamic flange functionals and static design-zone margins of `bearing` with `design`.

    Dynamic part: `jaxbearing.flange_functionals(design.apply(bearing), op, duration,
    **solve_kwargs)` (smooth peak PV [Pa m/s], smooth max / min contact height [m], integrated
    inside the diffrax solve; NaN where the solve failed). Static part: `jaxbearing.design_zone`
    of the same bearing at `flange_load` [N] (contact-ellipse half-width) and `min_clearance`
    [m] (required Lambda_bf).

    Differentiable with `jax.grad` (default adjoint: checkpointed reverse mode) or `jax.jacfwd`
    (pass `adjoint=diffrax.ForwardMode()`), with respect to `design` and every float leaf of
    `bearing` and `op`; vmappable over stacked `DesignVariables`.
    """
    _check_design_inputs(bearing, op, design, duration, solve_kwargs, flange_load, min_clearance)
    b = design.apply(bearing)
    if "perturbation" not in solve_kwargs:
        solve_kwargs = dict(solve_kwargs, perturbation=seated_perturbation(b))
    pv, h_max, h_min = flange_functionals(b, op, duration, **solve_kwargs)
    z = design_zone(b, flange_load, min_clearance)
    return DesignMetrics(
        peak_pv=pv,
        max_contact_height=h_max,
        min_contact_height=h_min,
        static_contact_height=z.contact_height,
        actual_axial_clearance=z.actual_axial_clearance,
        relief_margin=z.relief_margin,
        height_margin=z.height_margin,
        limited_circle_margin=z.limited_circle_margin,
        clearance_margin=z.clearance_margin,
    )


def forward_jacobian(f, x: Float[Array, " n"]):
    """(f(x), J) by forward mode: n Jacobian-vector products along the unit vectors, vmapped, so
    one evaluation of `f` (e.g. one diffrax solve) carries the primal and n tangents. `f` may
    return a pytree; each leaf of J has the tangent index on its leading axis (J[i] = df/dx_i)."""
    basis = jnp.eye(x.shape[-1], dtype=x.dtype)
    return jax.vmap(lambda e: jax.jvp(f, (x,), (e,)), out_axes=(None, 0))(basis)


def design_jacobian(
    bearing: Bearing,
    op: OperatingPoint,
    design: DesignVariables,
    *,
    duration: ArrayLike,
    mode: str = "forward",
    **solve_kwargs,
) -> tuple[Float[Array, 3], Float[Array, "3 3"]]:
    """(peak PV, max h_c, min h_c) of the dynamic run and their Jacobian with respect to
    (R_end, theta_f, Delta_bf) (rows: outputs, columns: variables; SI units).

    `mode="forward"` (default; the faster one here, see `GRADIENT_MODE_NOTE`): three
    Jacobian-vector products through `diffrax.ForwardMode()`, vmapped, so one solve carries the
    primal and three tangents. `mode="reverse"`: one vector-Jacobian product per output through
    diffrax's checkpointed `RecursiveCheckpointAdjoint`. The initial scatter defaults to
    `seated_perturbation` as in `design_metrics`."""
    if mode not in ("forward", "reverse"):
        raise UserInputError(f"mode = {mode!r}: must be 'forward' or 'reverse'")
    _check_design_inputs(bearing, op, design, duration, solve_kwargs)
    if mode == "forward":
        solve_kwargs = dict(solve_kwargs, adjoint=diffrax.ForwardMode())
    numbers, others = eqx.partition(solve_kwargs, eqx.is_inexact_array_like)
    args = (bearing, op, design.as_array(), duration, numbers)
    static = (mode, tuple(sorted(others.items())))
    if not _concrete_and_hashable(args, static):  # traced by the caller (jit, vmap, grad)
        return _design_jacobian(*args, others, mode)
    run = lambda *a: _design_jacobian(*a, others, mode)
    return compiled_program("design_jacobian", run, args, static)(*args)


def _concrete_and_hashable(args, static) -> bool:
    """Whether a call can use a stored program: no tracer among `args`, a hashable `static`."""
    if any(isinstance(leaf, jax.core.Tracer) for leaf in jax.tree_util.tree_leaves(args)):
        return False
    try:
        hash(static)
    except TypeError:
        return False
    return True


def _design_jacobian(bearing, op, x, duration, numbers, others, mode):
    solve_kwargs = eqx.combine(numbers, others)

    def f(x):
        b = DesignVariables.from_array(x).apply(bearing)
        kw = solve_kwargs
        if "perturbation" not in kw:
            kw = dict(kw, perturbation=seated_perturbation(b))
        return jnp.stack(flange_functionals(b, op, duration, **kw))

    if mode == "forward":
        value, cols = forward_jacobian(f, x)
        return value, cols.T
    value, vjp = jax.vjp(f, x)
    (rows,) = jax.vmap(vjp)(jnp.eye(3))
    return value, rows
