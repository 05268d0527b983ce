"""Oil-air drag on rollers and churning on the cage (jaxbearing.forces, docs/model.md 9).

Oracles written out by hand: the quadratic drag law 1/2 rho C_d A v^2 with White's cylinder
fit C_d = 1 + 10 Re^(-2/3); the creeping-flow limits of the spin torques (Couette torque
4 pi eta R^2 l of a cylinder in unbounded fluid, Stokes' 32/3 eta R^3 of a disk spinning about
its axis), which are the slopes at rest; symmetry, sign and scaling.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxbearing import reference_bearing
from jaxbearing.forces import cage_drag_torque, roller_drag

B = reference_bearing()
RHO = 0.05 * 960.0  # f_oil rho_oil, from docs/model.md section 1
ETA = 0.05 * 0.055  # f_oil eta_0
D = float(B.roller.diameter)
LB1 = float(B.roller.length)

_roller = jax.jit(lambda v, s: roller_drag(B, v, s))
_roller_cd1 = jax.jit(lambda v, s: roller_drag(B, v, s, drag_coefficient=1.0))
_cage = jax.jit(lambda w: cage_drag_torque(B, w))


def test_zero_at_rest():
    f, m = _roller(np.zeros(3), 0.0)
    np.testing.assert_array_equal(np.asarray(f), 0.0)
    assert float(m) == 0.0
    assert float(_cage(0.0)) == 0.0


@pytest.mark.parametrize("speed", [0.5, 12.0, 40.0])
def test_orbital_drag_white_fit(speed):
    direction = np.array([0.0, -0.6, 0.8])
    v = speed * direction
    f, _ = _roller(v, 0.0)
    re = RHO * speed * D / ETA
    cd = 1 + 10 * re ** (-2 / 3)
    expected = -0.5 * RHO * cd * D * LB1 * speed**2 * direction
    np.testing.assert_allclose(np.asarray(f), expected, rtol=1e-12, atol=1e-15)


def test_constant_cd_is_quadratic_and_opposes_motion():
    v = np.array([0.1, 25.0, -7.0])
    f1, _ = _roller_cd1(v, 0.0)
    f2, _ = _roller_cd1(2 * v, 0.0)
    np.testing.assert_allclose(np.asarray(f2), 4 * np.asarray(f1), rtol=1e-12)
    np.testing.assert_allclose(np.asarray(f1), -0.5 * RHO * D * LB1 * np.linalg.norm(v) * v, rtol=1e-12)
    f, _ = _roller(v, 0.0)
    assert float(np.dot(f, v)) < 0
    np.testing.assert_allclose(np.asarray(f), -np.asarray(_roller(-v, 0.0)[0]), rtol=1e-14)


def test_spin_torque_opposes_spin_and_creeping_limit():
    for spin in (1e-3, 50.0, 11000.0):
        _, m = _roller(np.zeros(3), spin)
        _, m_back = _roller(np.zeros(3), -spin)
        assert float(m) < 0
        np.testing.assert_allclose(float(m_back), -float(m), rtol=1e-14)
    # slope at rest: Couette cylinder (4 pi eta R^2 L_b1) + Stokes disk (32/3 eta R^3)
    slope = jax.grad(lambda s: roller_drag(B, jnp.zeros(3), s)[1])(0.0)
    r = D / 2
    np.testing.assert_allclose(
        float(slope), -(4 * np.pi * ETA * r**2 * LB1 + 32 / 3 * ETA * r**3), rtol=1e-12
    )
    # faster than linear at speed (turbulent and boundary-layer terms)
    m1 = float(_roller(np.zeros(3), 5000.0)[1])
    m2 = float(_roller(np.zeros(3), 10000.0)[1])
    assert 2.0 < m2 / m1 < 4.0


def test_cage_churning_torque():
    c = B.cage
    r_o, r_i = float(c.outer_diameter) / 2, float(c.inner_diameter) / 2
    w, b_l = float(c.width), float(c.land_width)
    for omega in (1.0, 300.0, 1500.0):
        assert float(_cage(omega)) < 0
        np.testing.assert_allclose(float(_cage(-omega)), -float(_cage(omega)), rtol=1e-14)
    t1, t2 = float(_cage(700.0)), float(_cage(1400.0))
    assert 2.0 < t2 / t1 < 4.0
    # creeping-flow slope at rest: Stokes annulus faces + Couette bore and outer cylinder
    slope = jax.grad(lambda s: cage_drag_torque(B, s))(0.0)
    expected = -(
        32 / 3 * ETA * (r_o**3 - r_i**3)
        + 4 * np.pi * ETA * r_i**2 * w
        + 4 * np.pi * ETA * r_o**2 * (w - 2 * b_l)
    )
    np.testing.assert_allclose(float(slope), expected, rtol=1e-12)


def test_gradients_finite_at_rest():
    def total(v, s, w):
        f, m = roller_drag(B, v, s)
        return jnp.sum(f) + m + cage_drag_torque(B, w)

    for args in ((jnp.zeros(3), 0.0, 0.0), (jnp.array([0.0, 1e-12, 0.0]), 1e-12, -1e-12)):
        g = jax.grad(total, argnums=(0, 1, 2))(*args)
        assert all(np.all(np.isfinite(np.asarray(x))) for x in g)
    jac = jax.jacfwd(lambda v: roller_drag(B, v, 0.0)[0])(jnp.zeros(3))
    np.testing.assert_array_equal(np.asarray(jac), 0.0)  # |v| v has zero slope at rest


def test_no_oil_means_no_drag_and_finite_gradients():
    """f_oil = 0 (allowed by the configuration, [0, 1]) is a dry cavity: zero drag force and
    torques, not 0/0 (the kinematic viscosity eta_mix/rho_mix = eta_0/rho_oil is taken from the
    oil), with finite derivatives with respect to f_oil."""
    import equinox as eqx
    import jax
    import jax.numpy as jnp

    import jaxbearing as jb
    from jaxbearing.forces import cage_drag_torque, roller_drag

    def total(f_oil):
        b = eqx.tree_at(lambda b: b.lubricant.oil_fraction, jb.reference_bearing(), f_oil)
        force, torque = roller_drag(b, jnp.array([0.0, 40.0, 3.0]), -1.0e4)
        return jnp.sum(jnp.abs(force)) + jnp.abs(torque) + jnp.abs(cage_drag_torque(b, 900.0))

    assert float(total(0.0)) == 0.0
    assert bool(jnp.isfinite(jax.grad(total)(0.0)))
