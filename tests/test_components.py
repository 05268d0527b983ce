"""The by-component vector helpers of the sliced contacts (`jaxbearing.forces._components`)
against their definitions written with 3-vector arrays."""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from jaxbearing.forces._components import components, relative_velocity, resultants, safe_unit, stack

RNG = np.random.default_rng(12)


def _vec(*shape):
    return jnp.asarray(RNG.normal(size=shape + (3,)))


def test_relative_velocity_is_the_difference_of_the_material_point_velocities():
    """v_rel = (v + w x (x - p)) - (v_o + w_o x (x - c_o)) at every slice point x, for bodies
    with a leading batch axis and slices over two trailing axes (the pocket's walls x slices)."""
    p, c_o = _vec(4), _vec(4)
    v, w, v_o, w_o = _vec(4), _vec(4), _vec(4), _vec(4)
    x = p[:, None, None, :] + _vec(4, 2, 5)
    direct = (v[:, None, None] + jnp.cross(w[:, None, None], x - p[:, None, None])) - (
        v_o[:, None, None] + jnp.cross(w_o[:, None, None], x - c_o[:, None, None])
    )
    arm = components(x - p[:, None, None])
    lever = components(p - c_o)
    got = relative_velocity(components(v), components(w), components(v_o), components(w_o), lever, arm)
    np.testing.assert_allclose(stack(got), direct, rtol=1e-12, atol=1e-12)


def test_resultants_sum_forces_and_moments_about_both_centres():
    p, c_o = _vec(3), _vec(3)
    x = p[:, None, :] + _vec(3, 7)
    f = _vec(3, 7)
    force, moment, moment_other = resultants(
        components(f), components(x - p[:, None]), components(p - c_o), 1
    )
    np.testing.assert_allclose(force, f.sum(axis=1), rtol=1e-12)
    np.testing.assert_allclose(moment, jnp.cross(x - p[:, None], f).sum(axis=1), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(
        moment_other, jnp.cross(x - c_o[:, None], f).sum(axis=1), rtol=1e-12, atol=1e-12
    )


def test_safe_unit_falls_back_at_zero_with_finite_gradient():
    import jax

    v = _vec(5).at[2].set(0.0)
    fallback = components(jnp.broadcast_to(jnp.array([0.0, 0.0, 1.0]), v.shape))
    n, u = safe_unit(components(v), fallback)
    np.testing.assert_allclose(n, jnp.linalg.norm(v, axis=-1), rtol=1e-14)
    np.testing.assert_allclose(stack(u)[2], [0.0, 0.0, 1.0])
    ok = np.arange(5) != 2
    np.testing.assert_allclose(
        stack(u)[ok], v[ok] / jnp.linalg.norm(v[ok], axis=-1, keepdims=True), rtol=1e-14
    )
    grad = jax.grad(lambda a: jnp.sum(safe_unit(components(a), fallback)[0]))(v)
    assert np.all(np.isfinite(grad)) and np.all(grad[2] == 0.0)
