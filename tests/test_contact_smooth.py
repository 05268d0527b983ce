"""Smoothing primitives and traction: closed forms, asymptotes, and finite derivatives everywhere.

Oracles: the softplus closed forms (derivative sigmoid, second derivative sigmoid(1-sigmoid)/eps),
the Hertz power law K delta^n and its derivatives for delta >> eps, the Euclidean norm, and the
traction curve's closed-form peak du* = (B - A C)/(B C) (docs/model.md 8).
"""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import jaxbearing as jb
from jaxbearing.contact import (
    PENETRATION_WIDTH,
    SLIDING_EPS,
    friction_force,
    hertz_force,
    safe_norm,
    smooth_direction,
    smooth_penetration,
    traction_coefficient,
    traction_force,
)

DELTAS = [-1e-6, -1e-9, 0.0, 1e-9, 1e-6]
W = PENETRATION_WIDTH


def _sigmoid(x):
    return 0.5 * (1 + math.tanh(x / 2))


def _finite(tree):
    return all(bool(jnp.all(jnp.isfinite(x))) for x in jax.tree_util.tree_leaves(tree))


_sp = jax.jit(smooth_penetration)
_sp_d1 = jax.jit(jax.grad(smooth_penetration))
_sp_d2 = jax.jit(jax.grad(jax.grad(smooth_penetration)))


@pytest.mark.parametrize("delta", DELTAS + [-1e-3, 1e-3, -1.0])
def test_smooth_penetration_closed_form(delta):
    x = delta / W
    want = W * (math.log1p(math.exp(-abs(x))) + max(x, 0.0))
    np.testing.assert_allclose(_sp(delta, W), want, rtol=1e-13, atol=1e-300)
    np.testing.assert_allclose(_sp_d1(delta, W), _sigmoid(x), rtol=1e-12, atol=1e-300)
    s = _sigmoid(x)
    np.testing.assert_allclose(_sp_d2(delta, W), s * (1 - s) / W, rtol=1e-10, atol=1e-300)


def test_smooth_penetration_asymptotes():
    np.testing.assert_allclose(_sp(0.0, W), W * math.log(2), rtol=1e-15)
    np.testing.assert_allclose(_sp(2e-6, W), 2e-6, rtol=1e-14)  # delta >> eps
    assert float(_sp(-2e-6, W)) == 0.0  # delta << -eps
    assert float(_sp(-30e-9, W)) < 1e-21


@settings(max_examples=60, deadline=None)
@given(st.floats(-1e-6, 1e-6), st.floats(-1e-6, 1e-6))
def test_smooth_penetration_bounds_and_monotone(d1, d2):
    lo, hi = sorted([d1, d2])
    assert float(_sp(lo, W)) <= float(_sp(hi, W))
    s = float(_sp(d1, W))
    assert max(d1, 0.0) <= s * (1 + 1e-12) and s <= max(d1, 0.0) + W * math.log(2) * (1 + 1e-12)


_hf = jax.jit(hertz_force, static_argnums=3)
_hf_d1 = jax.jit(jax.grad(hertz_force, argnums=(0, 1)), static_argnums=3)
_hf_d2 = jax.jit(jax.hessian(hertz_force, argnums=(0, 1)), static_argnums=3)


@pytest.mark.parametrize("exponent", [1.5, 10 / 9, 1.0])
@pytest.mark.parametrize("delta", DELTAS)
def test_hertz_force_finite_derivatives(delta, exponent):
    k = 3e10
    assert _finite(_hf(delta, k, W, exponent))
    assert _finite(_hf_d1(delta, k, W, exponent))
    assert _finite(_hf_d2(delta, k, W, exponent))
    if delta >= 1e-6:  # loaded: K delta^n and its derivatives (delta >> eps)
        np.testing.assert_allclose(_hf(delta, k, W, exponent), k * delta**exponent, rtol=1e-9)
        np.testing.assert_allclose(
            _hf_d1(delta, k, W, exponent)[0], k * exponent * delta ** (exponent - 1), rtol=1e-9
        )
        np.testing.assert_allclose(
            _hf_d2(delta, k, W, exponent)[0][0],
            k * exponent * (exponent - 1) * delta ** (exponent - 2),
            rtol=1e-6,
            atol=1e-6 * k * delta ** (exponent - 2),
        )
    if delta == 0.0:  # d/d delta [K s^n] = n K s^(n-1) sigmoid(0), s = eps ln 2
        s = W * math.log(2)
        np.testing.assert_allclose(
            _hf_d1(delta, k, W, exponent)[0], exponent * k * s ** (exponent - 1) * 0.5, rtol=1e-12
        )
    if delta <= -1e-6:  # far outside the contact: exactly zero, zero derivatives
        assert float(_hf(delta, k, W, exponent)) == 0.0
        assert float(_hf_d2(delta, k, W, exponent)[0][0]) == 0.0


@settings(max_examples=60, deadline=None)
@given(st.floats(-5e-8, 5e-6), st.floats(-5e-8, 5e-6), st.floats(1e8, 1e12))
def test_hertz_force_monotone_in_penetration(d1, d2, k):
    lo, hi = sorted([d1, d2])
    assert float(_hf(lo, k, W, 1.5)) <= float(_hf(hi, k, W, 1.5))
    assert float(_hf_d1(d1, k, W, 1.5)[0]) >= 0.0


# ------------------------------------------------------------------------------- norms
_norm_d1 = jax.jit(jax.grad(lambda x: safe_norm(x)))
_norm_d2 = jax.jit(jax.hessian(lambda x: safe_norm(x)))


def test_safe_norm_values_and_zero():
    x = jnp.array([[3.0, 4.0, 12.0], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(safe_norm(x), [13.0, 0.0], rtol=1e-15)
    assert safe_norm(x, keepdims=True).shape == (2, 1)
    np.testing.assert_allclose(safe_norm(x, axis=0), np.linalg.norm(np.asarray(x), axis=0))
    zero = jnp.zeros(3)
    np.testing.assert_array_equal(_norm_d1(zero), np.zeros(3))
    np.testing.assert_array_equal(_norm_d2(zero), np.zeros((3, 3)))
    v = jnp.array([1e-3, -2e-3, 0.5e-3])
    n = float(np.linalg.norm(np.asarray(v)))
    np.testing.assert_allclose(_norm_d1(v), np.asarray(v) / n, rtol=1e-12)
    hess = (np.eye(3) - np.outer(v, v) / n**2) / n
    np.testing.assert_allclose(_norm_d2(v), hess, rtol=1e-10, atol=1e-12)
    # eps masks small vectors (value and derivatives zero)
    assert float(safe_norm(jnp.array([1e-12, 0.0]), eps=1e-9)) == 0.0


_dir = jax.jit(smooth_direction)
_dir_jac = jax.jit(jax.jacfwd(smooth_direction))
_dir_hess = jax.jit(jax.hessian(smooth_direction))


def test_smooth_direction():
    u = jnp.array([3.0, -4.0])
    np.testing.assert_allclose(_dir(u, SLIDING_EPS), np.array([0.6, -0.8]), rtol=1e-7)
    zero = jnp.zeros(2)
    np.testing.assert_array_equal(_dir(zero, SLIDING_EPS), np.zeros(2))
    # linear near zero: d dir / du = I / u_eps
    np.testing.assert_allclose(_dir_jac(zero, SLIDING_EPS), np.eye(2) / SLIDING_EPS, rtol=1e-14)
    assert _finite(_dir_hess(zero, SLIDING_EPS))
    # batched, and a per-contact u_eps broadcasts
    ub = jnp.array([[1.0, 0.0], [0.0, 2e-3]])
    got = smooth_direction(ub, jnp.array([1e-3, 1e-3]))
    np.testing.assert_allclose(got[1], [0.0, 2e-3 / math.sqrt(4e-6 + 1e-6)], rtol=1e-14)


# ------------------------------------------------------------------------------ traction
LUB = jb.reference_bearing().lubricant
_kappa = jax.jit(traction_coefficient)
_kappa_d = jax.jit(jax.grad(traction_coefficient))


def test_traction_curve_defaults():
    # docs/model.md 8: kappa(0) = 0, peak 0.06 at 0.5 m/s, asymptote D = 0.04
    a, b, c, d = -0.04, 0.2528, 2.926, 0.04
    assert abs(float(_kappa(0.0, LUB))) < 1e-15
    peak = (b - a * c) / (b * c)  # d kappa / du = 0: B - C (A + B u) = 0
    np.testing.assert_allclose(peak, 0.5, rtol=1e-3)
    np.testing.assert_allclose(_kappa(peak, LUB), 0.06, rtol=1e-3)
    assert abs(float(_kappa_d(peak, LUB))) < 1e-12
    np.testing.assert_allclose(_kappa(50.0, LUB), d, rtol=1e-9)
    for u in [0.1, 0.3, 0.5, 1.0, 5.0]:
        np.testing.assert_allclose(_kappa(u, LUB), (a + b * u) * math.exp(-c * u) + d, rtol=1e-14)


_tf = jax.jit(traction_force)
_tf_jac = jax.jit(jax.jacfwd(traction_force, argnums=(0, 1)))
_tf_hess = jax.jit(jax.hessian(lambda u, q: jnp.sum(traction_force(u, q, LUB)), argnums=(0, 1)))
_ff_hess = jax.jit(jax.hessian(lambda u, q: jnp.sum(friction_force(u, q, 0.08)), argnums=(0, 1)))


def test_traction_force_at_zero_sliding():
    zero = jnp.zeros(3)
    np.testing.assert_array_equal(_tf(zero, 500.0, LUB), np.zeros(3))
    assert _finite(_tf_jac(zero, 500.0, LUB))
    assert _finite(_tf_hess(zero, 500.0))
    assert _finite(_ff_hess(zero, 500.0))
    # zero load: zero force, finite derivatives
    np.testing.assert_array_equal(_tf(jnp.array([1.0, 0.0, 0.0]), 0.0, LUB), np.zeros(3))


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(-30.0, 30.0), min_size=3, max_size=3), st.floats(0.0, 5e3))
def test_traction_opposes_sliding(u, q):
    u = jnp.array(u)
    f = _tf(u, q, LUB)
    speed = float(jnp.linalg.norm(u))
    assert float(jnp.dot(f, u)) <= 0.0
    # |F| = Q kappa(s) |u| / s <= Q kappa_max
    assert float(jnp.linalg.norm(f)) <= q * 0.06 * (1 + 1e-3) + 1e-12
    if speed > 1.0:  # |u| >> u_eps: magnitude Q kappa(|u|), direction -u/|u|
        want = -q * float(_kappa(speed, LUB)) * np.asarray(u) / speed
        np.testing.assert_allclose(f, want, rtol=1e-5, atol=1e-9 * (q + 1))


def test_friction_force():
    u = jnp.array([[10.0, 0.0], [0.0, 0.0], [0.0, -1e-4]])
    q = jnp.array([100.0, 100.0, 100.0])
    f = friction_force(u, q, 0.08)
    np.testing.assert_allclose(f[0], [-8.0, 0.0], rtol=1e-8)
    np.testing.assert_array_equal(f[1], [0.0, 0.0])
    # below u_eps the force fades linearly: -mu Q u / sqrt(u^2 + eps^2)
    np.testing.assert_allclose(f[2, 1], 8.0 * 1e-4 / math.sqrt(1e-8 + SLIDING_EPS**2), rtol=1e-12)
