"""Roller-raceway sliced contact (docs/model.md 8) against independent oracles.

Oracles: the whole-contact line law Q = k_c a^(10/9) (ISO/TS 16281 via `contact`), an explicit
circular crown, a brute-force search over each slice disc's rim for the interference of a tilted
and skewed roller, the small-tilt linearisation of the restoring moment, Hunt-Crossley's damping
law and the traction curve written out by hand.
"""

from __future__ import annotations

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import jaxbearing as jb
from jaxbearing import UserInputError
from jaxbearing.contact import HUNT_CROSSLEY_ALPHA, effective_modulus, line_contact_stiffness
from jaxbearing.forces import (
    crown_drop,
    raceway_contact,
    raceway_slice_geometry,
    raceway_stiffness,
    slice_positions,
)

X = np.array([1.0, 0.0, 0.0])
Y = np.array([0.0, 1.0, 0.0])
Z = np.array([0.0, 0.0, 1.0])
ZERO = jnp.zeros(3)


def _bearing(crown=None):
    b = jb.reference_bearing()
    if crown is not None:
        b = eqx.tree_at(lambda b: b.roller.crown_drop, b, jnp.asarray(crown))
    return b


def _whole_contact_stiffness(b):
    m, r = b.ring_material, b.roller_material
    e_prime = effective_modulus(m.elastic_modulus, m.poisson_ratio, r.elastic_modulus, r.poisson_ratio)
    return float(line_contact_stiffness(b.roller.effective_length, e_prime))


# one compiled contact for every test (the bearing is a pytree argument, so crowns etc. are data)
_contact = jax.jit(raceway_contact)


def _inner_position(b, approach):
    """Roller centre on +Z whose straight generatrix penetrates the inner raceway by `approach`."""
    return jnp.asarray((float(b.inner_raceway_radius) + float(b.roller.diameter) / 2 - approach) * Z)


def test_slice_positions_and_circular_crown():
    b = _bearing()
    r = b.roller
    xi = np.asarray(slice_positions(b))
    l_we, l_b2, c = float(r.effective_length), float(r.central_length), float(r.crown_drop)
    n = b.num_slices
    np.testing.assert_allclose(xi, -l_we / 2 + (np.arange(n) + 0.5) * l_we / n, rtol=0, atol=1e-15)
    # independent oracle: circle of radius R tangent at L_b2/2 with drop c at L_we/2
    s = (l_we - l_b2) / 2
    big_r = (s**2 + c**2) / (2 * c)
    x = np.linspace(-l_we / 2, l_we / 2, 201)
    excess = np.clip(np.abs(x) - l_b2 / 2, 0, None)
    expected = big_r - np.sqrt(big_r**2 - excess**2)
    # (the oracle R - sqrt(R^2 - x^2) cancels: ~1e-16 R = 2e-17 m of rounding)
    np.testing.assert_allclose(np.asarray(crown_drop(r, x)), expected, rtol=1e-9, atol=1e-15)
    assert float(crown_drop(r, l_we / 2)) == pytest.approx(c, rel=1e-12)
    assert float(crown_drop(r, 0.0)) == 0.0
    # tangent to the straight part: zero slope where the crown starts
    slope = jax.grad(lambda x: crown_drop(r, x))(l_b2 / 2 + 1e-12)
    assert abs(float(slope)) < 1e-9
    # no crown: exactly zero everywhere, finite gradient
    r0 = _bearing(crown=0.0).roller
    assert np.all(np.asarray(crown_drop(r0, x)) == 0.0)
    assert np.isfinite(
        float(jax.grad(lambda c: crown_drop(eqx.tree_at(lambda q: q.crown_drop, r0, c), 3e-3))(0.0))
    )


@pytest.mark.parametrize("ring_sign", [1.0, -1.0])
def test_uniform_approach_reproduces_whole_contact_law(ring_sign):
    b = _bearing(crown=0.0)
    a = 2.0e-6
    if ring_sign > 0:
        radius, p = b.inner_raceway_radius, _inner_position(b, a)
    else:
        radius = b.outer_raceway_radius
        p = jnp.asarray((float(b.outer_raceway_radius) - float(b.roller.diameter) / 2 + a) * Z)
    c = _contact(b, ring_sign, radius, p, jnp.asarray(X), ZERO, ZERO, ZERO, ZERO, ZERO)
    expected = _whole_contact_stiffness(b) * a ** (10 / 9)
    assert float(c.normal_load) == pytest.approx(expected, rel=1e-9)
    np.testing.assert_allclose(np.asarray(c.interference), a, rtol=1e-9)
    # pure normal force along the raceway normal (into the roller), no traction at rest
    np.testing.assert_allclose(np.asarray(c.force_on_roller), ring_sign * expected * Z, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(
        np.asarray(c.normals), np.broadcast_to(ring_sign * Z, (b.num_slices, 3)), atol=1e-15
    )
    assert np.all(np.asarray(c.slice_traction) == 0.0)
    # symmetric slices: no moment about the roller centre
    np.testing.assert_allclose(np.asarray(c.moment_on_roller), 0.0, atol=1e-9 * expected * 1e-3)


def _rim_interference(b, ring_sign, radius, p, e, c):
    """Brute force: extreme radial distance of each slice disc's rim from the ring axis."""
    xi = np.asarray(slice_positions(b))
    rad = float(b.roller.diameter) / 2 - np.asarray(crown_drop(b.roller, xi))
    a = np.cross(e, Y if abs(e[1]) < 0.9 else Z)
    a /= np.linalg.norm(a)
    bb = np.cross(e, a)
    out = []
    for x_j, r_j in zip(xi, rad):
        q = p + x_j * e - c

        def dist(phi, q=q, r_j=r_j):
            pt = q + r_j * (math.cos(phi) * a + math.sin(phi) * bb)
            return math.hypot(pt[1], pt[2])

        sign = 1.0 if ring_sign > 0 else -1.0  # inner: minimise distance; outer: maximise
        phis = np.linspace(0, 2 * np.pi, 721)
        vals = np.array([sign * dist(f) for f in phis])
        k = int(np.argmin(vals))
        res = minimize_scalar(
            lambda f: sign * dist(f),
            bounds=(phis[k] - 0.02, phis[k] + 0.02),
            method="bounded",
            options={"xatol": 1e-12},
        )
        d_ext = sign * res.fun
        out.append(radius - d_ext if ring_sign > 0 else d_ext - radius)
    return np.array(out)


@pytest.mark.parametrize("ring_sign", [1.0, -1.0])
def test_tilted_skewed_interference_matches_rim_search(ring_sign):
    b = _bearing()
    rng = np.random.default_rng(4)
    radius = float(b.inner_raceway_radius if ring_sign > 0 else b.outer_raceway_radius)
    for _ in range(3):
        psi = rng.uniform(0, 2 * np.pi)
        e_r = np.array([0.0, -np.sin(psi), np.cos(psi)])
        e_t = np.cross(X, e_r)
        tilt, skew = rng.uniform(-1e-2, 1e-2, size=2)
        e = np.cos(tilt) * np.cos(skew) * X + np.sin(tilt) * e_r + np.cos(tilt) * np.sin(skew) * e_t
        e /= np.linalg.norm(e)
        c = np.array([0.0, *rng.uniform(-2e-5, 2e-5, size=2)])
        r_b = float(b.pitch_diameter) / 2 + rng.uniform(-5e-6, 5e-6)
        p = r_b * e_r + rng.uniform(-1e-4, 1e-4) * X
        delta, _, _ = raceway_slice_geometry(
            b, ring_sign, radius, jnp.asarray(p), jnp.asarray(e), jnp.asarray(c)
        )
        oracle = _rim_interference(b, ring_sign, radius, p, e, c)
        # documented approximation: raceway curvature across the footprint, ~1e-11 m at 10 mrad
        np.testing.assert_allclose(np.asarray(delta), oracle, rtol=0, atol=1e-10)


def test_tilt_produces_restoring_moment():
    """Roller between both raceways (uniform approach a on each), tilted by beta about
    t = X x e_r: M.t = -beta * 2 sum_j (10/9)(k_c/N_s) a^(1/9) xi_j^2 to first order."""
    b = _bearing(crown=0.0)
    a = 1.5e-6
    d, r_i, r_o = float(b.roller.diameter), float(b.inner_raceway_radius), float(b.outer_raceway_radius)
    # place the outer ring so the outer approach also equals a (outer ring centre shifted)
    p = jnp.asarray((r_i + d / 2 - a) * Z)
    outer_c = jnp.asarray((float(p[2]) + d / 2 - a - r_o) * Z)
    t = np.cross(X, Z)  # = -Y
    k_c = _whole_contact_stiffness(b)
    xi = np.asarray(slice_positions(b))
    stiffness = 2 * (10 / 9) * (k_c / b.num_slices) * a ** (1 / 9) * np.sum(xi**2)
    for beta in (1e-5, -1e-5):
        e = jnp.asarray(np.cos(beta) * X + np.sin(beta) * Z)
        ci = _contact(b, 1.0, r_i, p, e, ZERO, ZERO, ZERO, ZERO, ZERO)
        co = _contact(b, -1.0, r_o, p, e, ZERO, ZERO, outer_c, ZERO, ZERO)
        m_t = float(jnp.dot(ci.moment_on_roller + co.moment_on_roller, t))
        assert np.sign(m_t) == -np.sign(beta)
        assert m_t == pytest.approx(-beta * stiffness, rel=2e-2)


def test_crown_reduces_end_slice_loads():
    a = 6.0e-6
    bc, b0 = _bearing(), _bearing(crown=0.0)
    p = _inner_position(bc, a)
    crowned = _contact(bc, 1.0, bc.inner_raceway_radius, p, jnp.asarray(X), ZERO, ZERO, ZERO, ZERO, ZERO)
    straight = _contact(b0, 1.0, b0.inner_raceway_radius, p, jnp.asarray(X), ZERO, ZERO, ZERO, ZERO, ZERO)
    q = np.asarray(crowned.slice_loads)
    mid = b0.num_slices // 2
    assert q[0] < q[mid] and q[-1] < q[mid]
    assert float(crowned.normal_load) < float(straight.normal_load)
    np.testing.assert_allclose(q, q[::-1], rtol=1e-12)  # symmetric
    # oracle: q_j = (k_c/N_s) (a - c(xi_j))^(10/9) with the explicit circular crown
    r = bc.roller
    l_we, l_b2, c = float(r.effective_length), float(r.central_length), float(r.crown_drop)
    s = (l_we - l_b2) / 2
    big_r = (s**2 + c**2) / (2 * c)
    xi = np.asarray(slice_positions(bc))
    ex = np.clip(np.abs(xi) - l_b2 / 2, 0, None)
    drop = big_r - np.sqrt(big_r**2 - ex**2)
    expected = _whole_contact_stiffness(bc) / bc.num_slices * (a - drop) ** (10 / 9)
    np.testing.assert_allclose(q, expected, rtol=1e-8)


def _outputs(b, p, e, v, w):
    c = raceway_contact(b, 1.0, b.inner_raceway_radius, p, e, v, w, ZERO, ZERO, jnp.asarray(2000.0 * X))
    return jnp.concatenate(
        [c.force_on_roller, c.moment_on_roller, c.normal_load[None], c.mean_sliding_speed[None]]
    )


_jac_fwd = jax.jit(jax.jacfwd(_outputs, argnums=(1, 2, 3, 4)))
_jac_rev = jax.jit(jax.jacrev(_outputs, argnums=(0, 1, 2, 3, 4)))
_hess_p = jax.jit(jax.hessian(lambda b, p, e, v, w: _outputs(b, p, e, v, w)[6], argnums=1))


@pytest.mark.parametrize("offset", [-1e-6, -1e-9, 0.0, 1e-9, 1e-6])
def test_gradients_finite_at_and_around_zero_penetration(offset):
    b = _bearing(crown=0.0)  # every slice at the same interference = offset
    p = _inner_position(b, offset)
    e = jnp.asarray(X)
    # at rest (zero sliding) and rolling with sliding; derivatives w.r.t. pose, velocities and
    # every float parameter of the bearing
    for v, w in ((ZERO, ZERO), (jnp.array([0.0, 0.3, 0.0]), jnp.array([-1e4, 0.0, 0.0]))):
        args = (b, p, e, v, w)
        assert np.all(np.isfinite(np.asarray(_outputs(*args))))
        for jac in (_jac_fwd(*args), _jac_rev(*args)):
            assert all(np.all(np.isfinite(np.asarray(x))) for x in jax.tree_util.tree_leaves(jac))
        assert np.all(np.isfinite(np.asarray(_hess_p(*args))))


def test_degenerate_pose_is_finite():
    """Roller centre on the ring axis with the axis along the radial direction: nonsense, but
    diffrax may evaluate it during step rejection; values and gradients stay finite."""
    b = _bearing()

    def f(p, e):
        c = raceway_contact(b, -1.0, b.outer_raceway_radius, p, e, ZERO, ZERO, ZERO, ZERO, ZERO)
        return jnp.sum(c.force_on_roller) + jnp.sum(c.moment_on_roller)

    value_and_grad = jax.jit(jax.value_and_grad(f, argnums=(0, 1)))
    for p, e in ((ZERO, jnp.asarray(X)), (jnp.asarray(1e-3 * Z), jnp.asarray(Z))):
        value, grads = value_and_grad(p, e)
        assert np.isfinite(float(value))
        for g in grads:
            assert np.all(np.isfinite(np.asarray(g)))


def test_forces_and_moments_on_roller_and_ring_are_opposite():
    b = _bearing()
    rng = np.random.default_rng(7)
    e = X + rng.uniform(-3e-3, 3e-3, 3)
    e = jnp.asarray(e / np.linalg.norm(e))
    p = _inner_position(b, 3e-6) + jnp.asarray([1e-4, 2e-6, 0.0])
    v, w = jnp.asarray(rng.normal(size=3) * 0.5), jnp.asarray(rng.normal(size=3) * 1e3)
    c_r = jnp.asarray([0.0, 1e-6, -2e-6])
    v_r, w_r = jnp.asarray([0.0, 0.01, 0.02]), jnp.asarray(2000.0 * X)
    c = _contact(b, 1.0, b.inner_raceway_radius, p, e, v, w, c_r, v_r, w_r)
    f = np.asarray(c.force_on_roller)
    assert np.linalg.norm(f) > 10.0 and np.linalg.norm(np.asarray(c.slice_traction)) > 1.0
    np.testing.assert_array_equal(np.asarray(c.force_on_ring), -f)
    # total moment about the origin vanishes: M_b + p x F_b + M_r + c_r x F_r = 0
    total = (
        np.asarray(c.moment_on_roller)
        + np.cross(np.asarray(p), f)
        + np.asarray(c.moment_on_ring)
        + np.cross(np.asarray(c_r), np.asarray(c.force_on_ring))
    )
    scale = np.linalg.norm(f) * float(b.pitch_diameter)
    assert np.linalg.norm(total) < 1e-12 * scale
    # and the per-slice forces add up to the resultant
    per_slice = np.asarray(c.slice_loads)[:, None] * np.asarray(c.normals) + np.asarray(c.slice_traction)
    np.testing.assert_allclose(per_slice.sum(0), f, rtol=1e-12, atol=1e-9)


def test_hunt_crossley_damping_vanishes_with_contact():
    b = _bearing(crown=0.0)
    alpha = HUNT_CROSSLEY_ALPHA
    p = _inner_position(b, 2e-6)
    rest = _contact(b, 1.0, b.inner_raceway_radius, p, jnp.asarray(X), ZERO, ZERO, ZERO, ZERO, ZERO)
    for vn in (0.1, -0.1, 1.0):
        # roller moving towards the inner raceway (-Z) closes the contact: d(delta)/dt = vn
        c = _contact(
            b, 1.0, b.inner_raceway_radius, p, jnp.asarray(X), jnp.asarray(-vn * Z), ZERO, ZERO, ZERO, ZERO
        )
        assert float(c.normal_load) == pytest.approx(
            float(rest.normal_load) * (1 + 1.5 * alpha * vn), rel=1e-12
        )
    # separating faster than 1/(1.5 alpha): no adhesive pull, the force fades to zero
    c = _contact(
        b, 1.0, b.inner_raceway_radius, p, jnp.asarray(X), jnp.asarray(10.0 * Z), ZERO, ZERO, ZERO, ZERO
    )
    assert 0.0 <= float(c.normal_load) < 1e-12 * float(rest.normal_load)
    # out of contact: no force whatever the approach speed
    p_far = _inner_position(b, -1e-6)
    c = _contact(
        b, 1.0, b.inner_raceway_radius, p_far, jnp.asarray(X), jnp.asarray(-5.0 * Z), ZERO, ZERO, ZERO, ZERO
    )
    assert float(c.normal_load) == 0.0 and np.all(np.asarray(c.force_on_roller) == 0.0)
    # ring moving into the roller is the same as the roller moving into the ring
    c1 = _contact(
        b, 1.0, b.inner_raceway_radius, p, jnp.asarray(X), ZERO, ZERO, ZERO, jnp.asarray(0.1 * Z), ZERO
    )
    c2 = _contact(
        b, 1.0, b.inner_raceway_radius, p, jnp.asarray(X), jnp.asarray(-0.1 * Z), ZERO, ZERO, ZERO, ZERO
    )
    assert float(c1.normal_load) == pytest.approx(float(c2.normal_load), rel=1e-12)


def test_traction_follows_lubricant_curve_against_sliding():
    b = _bearing(crown=0.0)
    lub = b.lubricant
    p = _inner_position(b, 2e-6)
    u = 0.5  # axial sliding of the roller over the ring [m/s]
    c = _contact(
        b, 1.0, b.inner_raceway_radius, p, jnp.asarray(X), jnp.asarray(u * X), ZERO, ZERO, ZERO, ZERO
    )
    s = math.sqrt(u**2 + 1e-3**2)  # SLIDING_EPS regularisation
    kappa = (float(lub.traction_a) + float(lub.traction_b) * s) * math.exp(
        -float(lub.traction_c) * s
    ) + float(lub.traction_d)
    assert kappa == pytest.approx(0.06, abs=1e-5)  # the curve's documented peak at 0.5 m/s
    n = float(c.normal_load)
    f = np.asarray(c.force_on_roller)
    assert f[0] == pytest.approx(-n * kappa * u / s, rel=1e-10)
    assert f[2] == pytest.approx(n, rel=1e-12)
    assert float(c.mean_sliding_speed) == pytest.approx(u, rel=1e-12)
    # roller spinning against a fixed ring: the traction moment opposes the spin
    for spin in (500.0, -500.0):
        c = _contact(
            b, 1.0, b.inner_raceway_radius, p, jnp.asarray(X), ZERO, jnp.asarray(spin * X), ZERO, ZERO, ZERO
        )
        assert np.sign(float(c.moment_on_roller[0])) == -np.sign(spin)
        # sliding speed at the contact: spin * (D/2 - a/2) (contact point in the middle of the overlap)
        lever = float(b.roller.diameter) / 2 - 1e-6
        assert float(c.mean_sliding_speed) == pytest.approx(abs(spin) * lever, rel=1e-9)


def test_vmap_over_rollers_matches_single_calls():
    b = _bearing()
    rng = np.random.default_rng(3)
    n = 5
    psi = rng.uniform(0, 2 * np.pi, n)
    e_r = np.stack([np.zeros(n), -np.sin(psi), np.cos(psi)], -1)
    p = jnp.asarray((float(b.inner_raceway_radius) + float(b.roller.diameter) / 2 - 1e-6) * e_r)
    e = jnp.broadcast_to(jnp.asarray(X), (n, 3))
    v = jnp.asarray(rng.normal(size=(n, 3)))
    w = jnp.asarray(rng.normal(size=(n, 3)) * 100)
    batched = jax.jit(jax.vmap(raceway_contact, in_axes=(None, None, None, 0, 0, 0, 0, None, None, None)))(
        b, 1.0, b.inner_raceway_radius, p, e, v, w, ZERO, ZERO, jnp.asarray(1000.0 * X)
    )
    for j in range(n):
        single = _contact(
            b, 1.0, b.inner_raceway_radius, p[j], e[j], v[j], w[j], ZERO, ZERO, jnp.asarray(1000.0 * X)
        )
        np.testing.assert_allclose(
            np.asarray(batched.force_on_roller[j]), np.asarray(single.force_on_roller), rtol=1e-12
        )
        np.testing.assert_allclose(
            np.asarray(batched.slice_loads[j]), np.asarray(single.slice_loads), rtol=1e-12
        )


def test_stiffness_is_the_whole_contact_coefficient():
    b = _bearing()
    assert float(raceway_stiffness(b)) == pytest.approx(_whole_contact_stiffness(b), rel=1e-14)


def test_bad_ring_sign_is_a_user_error():
    b = _bearing()
    with pytest.raises(UserInputError, match="ring_sign"):
        raceway_contact(b, 0.0, b.inner_raceway_radius, ZERO, jnp.asarray(X), ZERO, ZERO, ZERO, ZERO, ZERO)


def test_sliding_velocity_and_ring_moment_are_the_slice_formulas():
    """The sliding velocity and the ring's moment of `raceway_contact` are the formulas of the
    module docstring written per slice (a regression check for any rewrite of them for speed):
    u_j = tangential part of (v_b + w_b x (x_j - p)) - (v_r + w_r x (x_j - c_r)) and
    M_ring = -sum_j (x_j - c_r) x f_j."""
    b = _bearing()
    rng = np.random.default_rng(11)
    e = X + rng.uniform(-3e-3, 3e-3, 3)
    e = jnp.asarray(e / np.linalg.norm(e))
    p = _inner_position(b, 3e-6) + jnp.asarray([1e-4, 2e-6, -1e-6])
    v, w = jnp.asarray(rng.normal(size=3) * 0.5), jnp.asarray(rng.normal(size=3) * 1e3)
    c_r = jnp.asarray([2e-5, 1e-6, -2e-6])
    v_r, w_r = jnp.asarray([0.001, 0.01, 0.02]), jnp.asarray([2000.0, 3.0, -2.0])
    a = jnp.asarray([math.cos(2e-3), 0.0, -math.sin(2e-3)])
    c = _contact(b, 1.0, b.inner_raceway_radius, p, e, v, w, c_r, v_r, w_r, ring_axis=a)
    x, n = np.asarray(c.contact_points), np.asarray(c.normals)
    v_rel = (np.asarray(v) + np.cross(np.asarray(w), x - np.asarray(p))) - (
        np.asarray(v_r) + np.cross(np.asarray(w_r), x - np.asarray(c_r))
    )
    u = v_rel - np.sum(v_rel * n, axis=-1, keepdims=True) * n
    np.testing.assert_allclose(np.asarray(c.sliding_velocity), u, rtol=1e-9, atol=1e-9 * np.abs(u).max())
    f = np.asarray(c.slice_loads)[:, None] * n + np.asarray(c.slice_traction)
    ring_moment = -np.sum(np.cross(x - np.asarray(c_r), f), axis=0)
    scale = np.linalg.norm(np.asarray(c.force_on_roller)) * float(b.roller.diameter)
    assert scale > 1e-2
    np.testing.assert_allclose(np.asarray(c.moment_on_ring), ring_moment, rtol=0, atol=1e-12 * scale)


def test_the_field_takes_both_raceways_as_single_calls_do():
    """`dynamics.contact_loads`' raceways equal `raceway_contact` for each ring alone (inner:
    tilted, displaced, moving ring; outer: fixed, axis X by default): a regression check for
    any regrouping of the raceway evaluations for speed."""
    from jaxbearing.dynamics import Params, contact_loads, inner_ring_pose

    b = jb.reference_bearing()
    op = eqx.tree_at(lambda o: o.misalignment, jb.reference_operating_point(), jnp.asarray(2e-3))
    from jaxbearing.run._initial import kinematic_start

    y = kinematic_start(b, op, jb.Perturbation(seed=4))  # `initial_state`, compiled
    y = eqx.tree_at(lambda s: s.inner_ring.centre, y, y.inner_ring.centre + jnp.array([2e-6, -1e-6]))
    y = eqx.tree_at(lambda s: s.inner_ring.velocity, y, jnp.array([0.01, -0.02]))
    loads = contact_loads(y, Params(bearing=b, operating=op))
    ring = inner_ring_pose(y.inner_ring, op)
    r = y.rollers
    e = r.axis / jnp.linalg.norm(r.axis, axis=-1, keepdims=True)
    per_roller = jax.jit(jax.vmap(raceway_contact, in_axes=(None, None, None, 0, 0, 0, 0, None, None, None)))

    def inner_one(p, e, v, w):
        return raceway_contact(
            b,
            1.0,
            b.inner_raceway_radius,
            p,
            e,
            v,
            w,
            ring.centre,
            ring.velocity,
            ring.angular_velocity,
            ring_axis=ring.axis,
        )

    inner = jax.jit(jax.vmap(inner_one))(r.centre, e, r.velocity, r.angular_velocity)
    outer = per_roller(
        b, -1.0, b.outer_raceway_radius, r.centre, e, r.velocity, r.angular_velocity, ZERO, ZERO, ZERO
    )
    assert float(jnp.max(inner.normal_load)) > 10.0 and float(jnp.max(outer.normal_load)) > 10.0
    for got, want in ((loads.inner, inner), (loads.outer, outer)):
        for name in (
            "interference",
            "slice_loads",
            "sliding_velocity",
            "force_on_roller",
            "moment_on_roller",
            "moment_on_ring",
        ):
            g, w = np.asarray(getattr(got, name)), np.asarray(getattr(want, name))
            np.testing.assert_allclose(g, w, rtol=1e-10, atol=1e-10 * np.abs(w).max(), err_msg=name)
