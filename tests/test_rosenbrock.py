"""The Rosenbrock-W solver (`jaxbearing.run._rosenbrock`, issue 12): order of convergence
against closed-form solutions, stability far beyond the explicit limit, the W-property (order
kept with any Jacobian approximation), derivatives through the solver, the per-roller block
Jacobian against `jax.jacfwd`, and agreement with Tsit5 on the reference bearing (slow)."""

from __future__ import annotations

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
import pytest
import scipy.linalg

import jaxbearing as jb
from jaxbearing import UserInputError
from jaxbearing.run._rosenbrock import (
    ROS34PW2_B,
    ROS34PW2_B_EMBEDDED,
    DenseBlock,
    RollerBlockJacobian,
    RosenbrockW,
    dense_jacobian,
)

#: the roller's radial mode between its raceways at the reference point (issue 12)
RADIAL_EIGENVALUE = complex(-5.6e4, 3.88e5)
#: Tsit5's stability limit for it (benchmarks/bench_work_precision.tsit5_stability_limit)
TSIT5_LIMIT = 7.46e-6


def _stiff_linear_system():
    """y' = A y: a damped oscillator with the radial mode's eigenvalues (x1 position, x2
    velocity), forced by a slow damped oscillator (-200 +- 1000 i), which it does not feed back."""
    lam = RADIAL_EIGENVALUE
    a = np.zeros((4, 4))
    a[0, 1] = 1.0
    a[1, 0], a[1, 1] = -(abs(lam) ** 2), 2 * lam.real
    a[2, 2], a[2, 3], a[3, 2], a[3, 3] = -200.0, 1000.0, -1000.0, -200.0
    a[1, 2] = 1e3  # the slow part drives the stiff one
    return jnp.asarray(a), jnp.array([1e-3, 0.0, 1.0, 0.5])


def _fixed_step_finals(f, y0, t1, ns, jacobian):
    """y(t1) of fixed-step ROS34PW2 with t1/n steps for every n (one compilation)."""

    @jax.jit
    def final(dt):
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(f),
            RosenbrockW(jacobian=jacobian),
            0.0,
            t1,
            dt,
            y0,
            stepsize_controller=diffrax.ConstantStepSize(),
            max_steps=max(ns) + 1,
        )
        return sol.ys[-1]

    return [np.asarray(final(t1 / n)) for n in ns]


def test_embedded_weights_are_consistent():
    # both solutions of ROS34PW2 are consistent: sum b = sum b^ = 1
    assert abs(ROS34PW2_B.sum() - 1.0) < 1e-14
    assert abs(ROS34PW2_B_EMBEDDED.sum() - 1.0) < 1e-14


@pytest.mark.parametrize("which", ["exact", "stiff block only"])
def test_third_order_on_a_stiff_linear_system_at_steps_beyond_the_explicit_limit(which):
    """Observed order ~3 against expm, with every step (10-80 us) longer than Tsit5's stability
    limit for the radial mode (7.5 us); T the exact Jacobian or only the stiff 2 x 2 block."""
    a, y0 = _stiff_linear_system()
    if which == "exact":
        jac = dense_jacobian
    else:
        block = jnp.zeros((4, 4)).at[:2, :2].set(a[:2, :2])

        def jac(f, t, y):
            return DenseBlock(matrix=block)

    t1 = 1.6e-3
    ns = [20, 40, 80, 160]  # h = 80, 40, 20, 10 us
    assert t1 / ns[-1] > TSIT5_LIMIT
    exact = scipy.linalg.expm(np.asarray(a) * t1) @ np.asarray(y0)
    finals = _fixed_step_finals(lambda t, y, args: a @ y, y0, t1, ns, jac)
    errs = np.array([np.max(np.abs(y - exact) / (1e-3 + np.abs(exact))) for y in finals])
    orders = np.log2(errs[:-1] / errs[1:])
    assert np.all(np.isfinite(errs)) and errs[-1] < 1e-4, errs
    assert 2.7 < orders[-1] < 3.3, (errs, orders)


@pytest.mark.parametrize("kind", ["exact", "random", "zero"])
def test_w_method_keeps_third_order_with_any_jacobian_approximation(kind):
    """A W-method keeps its order for any T (Hairer & Wanner IV.7): a nonlinear, non-autonomous
    problem with T exact, a fixed random matrix or zero (then the method is explicit)."""

    def f(t, y, args):
        return jnp.array([y[1], -y[0] - 0.1 * y[1] + 0.5 * jnp.sin(y[2]), -y[2] * y[0] ** 2 + jnp.cos(t)])

    y0, t1 = jnp.array([1.0, 0.0, 0.3]), 2.0
    ref = diffrax.diffeqsolve(
        diffrax.ODETerm(f),
        diffrax.Tsit5(),
        0.0,
        t1,
        1e-3,
        y0,
        stepsize_controller=diffrax.PIDController(rtol=1e-13, atol=1e-13),
        max_steps=100_000,
    ).ys[-1]
    m = jnp.asarray(np.random.default_rng(0).normal(size=(3, 3)))
    jac = {
        "exact": lambda ff, t, y: DenseBlock(matrix=jax.jacfwd(lambda z: ff(t, z))(y)),
        "random": lambda ff, t, y: DenseBlock(matrix=m),
        "zero": lambda ff, t, y: DenseBlock(matrix=jnp.zeros((3, 3))),
    }[kind]
    finals = _fixed_step_finals(f, y0, t1, (40, 80, 160), jac)
    errs = [float(np.max(np.abs(y - np.asarray(ref)))) for y in finals]
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all((orders > 2.8) & (orders < 3.2)), (errs, orders)


def test_stability_functions():
    """R(z) = 1 + z b^T (I - z B)^-1 1 (B = alpha + Gamma): the method is L-stable (R(-inf) = 0,
    |R| <= 1 on the imaginary axis); the embedded solution is not (R^(inf) = 0.478), so its
    error estimate of an excited stiff mode is about half the mode's amplitude at any step:
    a stiff mode excited above the tolerance is resolved, not stepped over."""
    from jaxbearing.run._rosenbrock import ROS34PW2_ALPHA, ROS34PW2_GAMMA, ROS34PW2_GAMMAS

    big = ROS34PW2_ALPHA + ROS34PW2_GAMMAS + ROS34PW2_GAMMA * np.eye(4)

    def r(z, b):
        return abs(1 + z * b @ np.linalg.solve(np.eye(4) - z * big, np.ones(4)))

    assert r(-1e12, ROS34PW2_B) < 1e-9
    assert all(r(1j * y, ROS34PW2_B) <= 1.0 + 1e-12 for y in np.logspace(-2, 4, 61))
    assert abs(r(-1e12, ROS34PW2_B_EMBEDDED) - 0.4783) < 1e-3


def test_adaptive_steps_exceed_the_explicit_limit_on_the_stiff_system():
    """With diffrax's PID controller and the embedded error estimate, on the stiff system with
    its stiff mode not excited (it starts at rest and is driven only by the slow part, an
    amplitude of ~1e-8, below atol), the mean accepted step is many times Tsit5's stability limit
    (85 us against 7.5 us) and the solution meets the tolerance; refreshing T every 4 accepted steps changes neither."""
    a, _ = _stiff_linear_system()
    y0 = jnp.array([0.0, 0.0, 1.0, 0.5])
    t1 = 1e-2
    exact = scipy.linalg.expm(np.asarray(a) * t1) @ np.asarray(y0)
    for refresh in (1, 4):
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(lambda t, y, args: a @ y),
            RosenbrockW(jacobian=dense_jacobian, refresh_every=refresh),
            0.0,
            t1,
            1e-7,
            y0,
            stepsize_controller=diffrax.PIDController(rtol=1e-3, atol=1e-6, pcoeff=0.3, icoeff=0.4),
            max_steps=10_000,
        )
        accepted = int(sol.stats["num_accepted_steps"])
        assert t1 / accepted > 5 * TSIT5_LIMIT, accepted
        # global error of the order of rtol x the initial amplitude (1)
        assert np.max(np.abs(np.asarray(sol.ys[-1]) - exact)) < 2e-3


def test_forward_and_reverse_derivatives_through_the_solver():
    """d y(t1) / d k of y' = -k y (closed form -t1 exp(-k t1) y0) through the adaptive solve, in
    forward mode (diffrax.ForwardMode) and reverse mode, both to the solver's accuracy."""
    t1, y0 = 1.0, 2.0

    def final(k, adjoint):
        sol = diffrax.diffeqsolve(
            diffrax.ODETerm(lambda t, y, args: -args * y),
            RosenbrockW(jacobian=dense_jacobian),
            0.0,
            t1,
            0.01,
            jnp.array([y0]),
            args=k,
            stepsize_controller=diffrax.PIDController(rtol=1e-8, atol=1e-10),
            adjoint=adjoint,
            max_steps=10_000,
        )
        return sol.ys[-1, 0]

    k = 3.0
    exact = -t1 * np.exp(-k * t1) * y0
    fwd = jax.jacfwd(lambda k: final(k, diffrax.ForwardMode()))(k)
    rev = jax.grad(lambda k: final(k, diffrax.RecursiveCheckpointAdjoint()))(k)
    assert abs(float(fwd) - exact) < 1e-5 * abs(exact)
    assert abs(float(rev) - exact) < 1e-5 * abs(exact)


def test_bad_solver_name_is_a_one_line_user_input_error():
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    for call in (
        lambda: jb.solve(b, op, 1e-4, solver="rk4"),
        lambda: jb.simulate(b, op, duration=1e-4, solver="rk4"),
        lambda: jb.simulate_steady(b, op, solver="rk4"),
    ):
        with pytest.raises(UserInputError, match=r"^solver = 'rk4': must be one of 'tsit5', 'ros34pw2'$"):
            call()


def test_roller_blocks_equal_the_diagonal_blocks_of_the_dense_jacobian():
    """One JVP per block coordinate, seeded on every roller at once, gives each roller's own
    12 x 12 block exactly: the field couples no roller's rates to another roller's coordinates
    (`jax.jacfwd` of the full 744-dimensional scaled field at a perturbed start; 11 slices per
    raceway, the suite's reduced size: the coupling is structural, the slices only sum)."""
    import dataclasses

    from jax.flatten_util import ravel_pytree

    from jaxbearing.dynamics import Functionals, Params, Scaling, state_scales
    from jaxbearing.run import SolveArgs, scaled_field
    from jaxbearing.run._initial import kinematic_start

    b, op = dataclasses.replace(jb.reference_bearing(), num_slices=11), jb.reference_operating_point()
    y0 = kinematic_start(b, op, jb.Perturbation(seed=3))  # `initial_state`, compiled
    scaling = Scaling(
        nominal=y0,
        scale=state_scales(b.num_rollers, b.pitch_diameter / 2),
        orbit_speed=jb.kinematic_cage_speed(b, op),
    )
    args = SolveArgs(params=Params(bearing=b, operating=op, functionals=Functionals()), scaling=scaling)
    # a state off the quasi-static start: every scaled coordinate moved by O(1)
    y = jax.tree_util.tree_map(
        lambda s: s + 0.5 * jnp.cos(jnp.arange(s.size).reshape(s.shape)), scaling.scale_state(0.0, y0)
    )
    t = jnp.asarray(1e-4)
    flat, unravel = ravel_pytree(y)

    @jax.jit
    def both(flat):
        dense = jax.jacfwd(lambda v: ravel_pytree(scaled_field(t, unravel(v), args))[0])(flat)
        blocks = RollerBlockJacobian()(lambda t_, y_: scaled_field(t_, y_, args), t, unravel(flat)).blocks
        return dense, blocks

    dense, blocks = map(np.asarray, both(flat))
    # flat index of (roller z, block coordinate c): the roller leaves come first, field by field
    z_n = b.num_rollers
    widths = [1, 1, 1, 3, 1, 1, 1, 3]
    index = np.zeros((z_n, 12), int)
    start, col = 0, 0
    for w in widths:
        for k in range(w):
            index[:, col + k] = start + np.arange(z_n) * w + k
        start, col = start + z_n * w, col + w
    scale = np.max(np.abs(dense[np.ix_(index.ravel(), index.ravel())]))
    for z in range(z_n):
        own = dense[np.ix_(index[z], index[z])]
        assert np.allclose(blocks[z], own, rtol=1e-9, atol=1e-12 * scale)
        others = np.setdiff1d(index.ravel(), index[z])
        assert np.all(dense[np.ix_(index[z], others)] == 0.0)  # no roller-roller coupling


def test_ros34pw2_on_the_bearing_agrees_with_tsit5_at_reduced_size():
    """ROS34PW2 on the whole bearing in the default suite: 0.1 ms of the 11-slice bearing from
    the quasi-static start, ROS34PW2 and Tsit5 both at rtol 1e-5, atol 1e-10, through the
    settled runs' integrator (`solve_from` with their saves per revolution and step limit, and
    their error norm, the per-body RMS): the Tsit5 program is the one the suite's settled runs
    at 11 slices compile (tests/test_settle.py), so only ROS34PW2 compiles here. Both succeed and
    the roller loads agree to 1e-3 of the largest (measured 2026-11-28: 2.1e-5), the cage speed
    to 1e-6. (About 40 s of ROS34PW2 compilation cold; the comparison through `solve`, the
    start-up transients' error norm, at full size and the gradient through the solve are the
    slow tests below.)"""
    import dataclasses

    from jaxbearing.dynamics import Functionals, Params
    from jaxbearing.run import SAVES_PER_REV
    from jaxbearing.run._initial import kinematic_start
    from jaxbearing.run._solve_from import _compiled

    b = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    op = jb.reference_operating_point()
    start = kinematic_start(b, op, jb.Perturbation())  # `initial_state`, compiled
    params = Params(bearing=b, operating=op, functionals=Functionals())
    out = {}
    for solver in ("tsit5", "ros34pw2"):
        run = _compiled(params, start, SAVES_PER_REV, 2_000_000, solver)
        histories, _, code, _ = run(params, start, *map(jnp.asarray, (1e-4, 1e-5, 1e-10)))
        assert int(code) == 0, solver
        out[solver] = jax.tree_util.tree_map(np.asarray, histories)
    t5, ros = out["tsit5"], out["ros34pw2"]
    np.testing.assert_allclose(ros["cage_speed"], t5["cage_speed"], rtol=1e-6)
    load = np.max(t5["roller_inner_load"])
    assert load > 100.0  # the loaded zone carries the 1000 N
    assert np.max(np.abs(ros["roller_inner_load"] - t5["roller_inner_load"])) < 1e-3 * load


@pytest.mark.slow
def test_agrees_with_tsit5_on_a_short_reference_bearing_run():
    """0.3 ms of the reference bearing from the quasi-static start: cage speed and roller loads
    of ROS34PW2 and Tsit5 (both rtol 1e-5, atol 1e-10: 1 pm, 1 nm/s, 1 urad/s) agree to far below
    their own scale. (At atol 10 nm under the max norm with the raceway-normal coordinates 100x
    looser, the default of 2026-11-24, the roller loads of the two differed by 1.7 % of the
    largest: the tolerance, not the solvers.)"""
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    out = {}
    for solver in ("tsit5", "ros34pw2"):
        sol = jb.solve(b, op, 3e-4, num_saves=31, rtol=1e-5, atol=1e-10, solver=solver)
        assert int(sol.result) == 0
        out[solver] = jax.tree_util.tree_map(np.asarray, sol.histories)
    t5, ros = out["tsit5"], out["ros34pw2"]
    assert np.allclose(ros["cage_speed"], t5["cage_speed"], rtol=1e-5)
    load = np.max(t5["roller_inner_load"])
    assert np.max(np.abs(ros["roller_inner_load"] - t5["roller_inner_load"])) < 1e-2 * load


@pytest.mark.slow
def test_forward_mode_gradient_through_the_bearing_solve_is_finite():
    """d(largest inner-raceway roller load at 50 us)/d(radial load) through ROS34PW2 in forward
    mode (diffrax.ForwardMode, the quasi-static start included): finite, nonzero and equal to a
    central difference of the same solve to 1 %."""
    import equinox as eqx

    b, op = jb.reference_bearing(), jb.reference_operating_point()

    def peak_load(radial_load):
        o = eqx.tree_at(lambda x: x.radial_load, op, radial_load)
        sol = jb.solve(b, o, 5e-5, num_saves=2, rtol=1e-6, solver="ros34pw2", adjoint=diffrax.ForwardMode())
        return jnp.max(sol.histories["roller_inner_load"][-1])

    f0 = op.radial_load
    grad = float(jax.jit(jax.jacfwd(peak_load))(f0))
    f = jax.jit(peak_load)
    step = 1e-3 * float(f0)
    fd = (float(f(f0 + step)) - float(f(f0 - step))) / (2 * step)
    print(f"d(max inner load)/d(radial load): forward mode {grad:.6g}, central difference {fd:.6g}")
    assert np.isfinite(grad) and fd != 0.0 and abs(grad - fd) <= 1e-2 * abs(fd), (grad, fd)
