"""Hunt-Crossley damping law against the closed-form restitution of a single impact.

1-DOF impact of a mass m on a contact Q = K delta^n s(1 + c d(delta)/dt), c = (3/2) alpha
(Hunt & Crossley, J. Appl. Mech. 42:440-445, 1975), integrated with scipy's solve_ivp (DOP853,
rtol 1e-12) from first touch to separation. With v = d(delta)/dt, m v dv/(1 + c v) = -K delta^n
d(delta) integrates over the closed loop in delta to the exact relation

    f(v_in) = f(-v_out),   f(v) = v/c - ln(1 + c v)/c^2,

independent of m, K and n, solved here with brentq; its expansion (derived in the module
docstring of jaxbearing.contact._damping) is e = v_out/v_in = 1 - (2/3) x + (4/9) x^2 + O(x^3),
x = c v_in, i.e. Hunt & Crossley's e = 1 - alpha v_in to first order.
"""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from jaxbearing.contact import (
    DAMPING_FACTOR_WIDTH,
    HUNT_CROSSLEY_ALPHA,
    hertz_force,
    hunt_crossley_factor,
    hunt_crossley_force,
)

WIDTH = 1e-14  # penetration softplus width for the impact runs [m], << the ~10 um approach


def _exact_restitution(v_in, c):
    f = lambda v: v / c - math.log1p(c * v) / c**2
    v_out = brentq(lambda w: f(-w) - f(v_in), 0.0, min(v_in, (1 - 1e-12) / c), xtol=1e-15, rtol=1e-14)
    return v_out / v_in


def _simulate_restitution(mass, stiffness, exponent, alpha, v_in):
    force = jax.jit(lambda d, v: hunt_crossley_force(stiffness, d, v, alpha, exponent, WIDTH))
    # approach scale (undamped): delta_max = ((n+1) m v^2 / (2 K))^(1/(n+1))
    d_max = ((exponent + 1) * mass * v_in**2 / (2 * stiffness)) ** (1 / (exponent + 1))

    def rhs(_, y):
        return [y[1], -float(force(y[0], y[1])) / mass]

    def separated(_, y):
        return y[0]

    separated.terminal = True
    separated.direction = -1
    t_scale = d_max / v_in
    sol = solve_ivp(
        rhs,
        (0.0, 50 * t_scale),
        [0.0, v_in],
        method="DOP853",
        rtol=1e-12,
        atol=[1e-9 * d_max, 1e-12 * v_in],
        events=separated,
        first_step=1e-3 * t_scale,
    )
    assert sol.status == 1, "no separation"
    return -sol.y_events[0][0][1] / v_in


@pytest.mark.parametrize(
    "mass, stiffness, exponent, x",
    [
        (0.02, 5e9, 1.5, 0.01),  # point contact, light damping
        (0.02, 5e9, 1.5, 0.45),  # default alpha at v_in = 0.67 m/s
        (0.5, 2e9, 10 / 9, 0.9),  # line-contact exponent, heavy damping
    ],
)
def test_restitution_of_one_impact(mass, stiffness, exponent, x):
    alpha = HUNT_CROSSLEY_ALPHA
    c = 1.5 * alpha
    v_in = x / c
    e_sim = _simulate_restitution(mass, stiffness, exponent, alpha, v_in)
    e_exact = _exact_restitution(v_in, c)
    assert e_sim == pytest.approx(e_exact, rel=1e-9)  # measured: 1e-11
    # the expansion: e = 1 - (2/3) x + (4/9) x^2 + O(x^3)
    assert abs(e_exact - (1 - 2 * x / 3 + 4 * x * x / 9)) < x**3


def test_small_alpha_limit_is_hunt_crossley_restitution():
    # e = 1 - alpha v_in to first order (Hunt & Crossley's definition of alpha)
    for alpha in [0.08, 0.32]:
        v_in = 0.01
        e = _exact_restitution(v_in, 1.5 * alpha)
        assert abs(e - (1 - alpha * v_in)) < (1.5 * alpha * v_in) ** 2


def test_factor_is_the_raceway_and_pocket_law():
    # N = q s(1 + 1.5 alpha rate), s(x) = 0.02 softplus(x / 0.02), as written in _raceway/_pocket
    rates = jnp.array([-10.0, -2.3, -1.0, 0.0, 0.1, 1.0, 5.0])
    want = DAMPING_FACTOR_WIDTH * np.logaddexp(0.0, (1 + 1.5 * 0.3 * np.asarray(rates)) / 0.02)
    np.testing.assert_allclose(hunt_crossley_factor(rates), want, rtol=1e-14)
    # identity near 1, no pull when separating fast
    np.testing.assert_allclose(hunt_crossley_factor(jnp.array([0.0, 0.5])), [1.0, 1.225], rtol=1e-15)
    assert 0.0 <= float(hunt_crossley_factor(-10.0)) < 1e-40


def test_force_is_elastic_times_factor_and_vanishes_with_the_contact():
    k = 3e9
    for d, v in [(2e-6, 0.3), (2e-6, -0.3), (0.0, 1.0), (-1e-6, 5.0)]:
        want = float(hertz_force(d, k)) * float(hunt_crossley_factor(v))
        assert float(hunt_crossley_force(k, d, v)) == pytest.approx(want, rel=1e-14, abs=0.0)
    assert float(hunt_crossley_force(k, -1e-6, 5.0)) == 0.0


@pytest.mark.parametrize("d, v", [(0.0, 0.0), (-1e-9, 0.0), (1e-9, -1 / 0.45), (-1e-6, -3.0), (2e-6, 0.2)])
def test_smooth_at_zero(d, v):
    # finite gradient and Hessian at first touch, at zero rate, at the factor's zero crossing
    # and far outside; the gradient matches central differences where the force is loaded
    f = lambda x: hunt_crossley_force(3e9, x[0], x[1])
    x = jnp.array([d, v])
    g = jax.grad(f)(x)
    h = jax.hessian(f)(x)
    assert bool(jnp.all(jnp.isfinite(g))) and bool(jnp.all(jnp.isfinite(h)))
    if d > 1e-6:
        step = np.array([1e-12, 1e-6])
        fd = [(float(f(x + s * e)) - float(f(x - s * e))) / (2 * s) for s, e in zip(step, np.eye(2))]
        np.testing.assert_allclose(g, fd, rtol=1e-6)
