"""Roller against its cage pocket (jaxbearing.forces, docs/model.md 9).

Oracles: the ISO/TS 16281 line-contact law written out by hand (N, mm), rigid-body statics
(action = reaction, moment arms), the direction of Coulomb friction, and the Hunt-Crossley
damping factor. Frames follow `_state`: e_rad(phi) = (0, -sin phi, cos phi), t_c = X x e_rad.
"""

import functools

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxbearing import reference_bearing
from jaxbearing.contact import HUNT_CROSSLEY_ALPHA
from jaxbearing.forces import PocketContact, pocket_contact

X = np.array([1.0, 0.0, 0.0])
ZERO = np.zeros(3)
PHI = 0.7  # pocket azimuth
BEARING = reference_bearing()


def _frame(phi=PHI, cage_centre=ZERO):
    e_rad = np.array([0.0, -np.sin(phi), np.cos(phi)])
    t_c = np.cross(X, e_rad)
    pocket = np.asarray(cage_centre) + float(BEARING.pitch_diameter) / 2 * e_rad
    return e_rad, t_c, pocket


@functools.partial(jax.jit, static_argnames="num_slices")
def _contact(p, e, v, w, pc, t, vc, wc, cc, num_slices=5):
    return pocket_contact(BEARING, p, e, v, w, pc, t, vc, wc, cc, num_slices=num_slices)


def _iso_stiffness_si():
    """k_c of one line contact, ISO/TS 16281 by hand: 2^(10/9) 35948 L_we^(8/9) N/mm^(10/9),
    scaled by E'(roller, cage)/E'(steel 207.5 GPa, 0.3), converted to N/m^(10/9)."""
    b = BEARING
    l_we_mm = (float(b.roller.length) - 2 * float(b.roller.corner_radius)) * 1e3
    k_mm = 2 ** (10 / 9) * 35948.0 * l_we_mm ** (8 / 9)
    e1, n1 = float(b.roller_material.elastic_modulus), float(b.roller_material.poisson_ratio)
    e2, n2 = float(b.cage_material.elastic_modulus), float(b.cage_material.poisson_ratio)
    e_pair = 2 / ((1 - n1**2) / e1 + (1 - n2**2) / e2)
    e_steel = 2.075e11 / (1 - 0.3**2)
    return k_mm * (e_pair / e_steel) * 1e3 ** (10 / 9)


def test_centred_roller_feels_nothing():
    _, t, pc = _frame()
    r = _contact(pc, X, ZERO, np.array([5000.0, 0, 0]), pc, t, ZERO, ZERO, ZERO)
    assert isinstance(r, PocketContact)
    for f in (r.force_on_roller, r.moment_on_roller, r.force_on_cage, r.moment_on_cage):
        np.testing.assert_array_equal(np.asarray(f), 0.0)
    assert float(r.normal_force) == 0.0


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("delta", [0.5e-6, 3e-6])
def test_line_contact_law_against_each_wall(side, delta):
    """Roller displaced by C_p/2 + delta towards a wall: Q = k_c delta^(10/9), pushing back."""
    _, t, pc = _frame()
    c_p = float(BEARING.cage.pocket_clearance)
    p = pc + side * (c_p / 2 + delta) * t
    r = _contact(p, X, ZERO, ZERO, pc, t, ZERO, ZERO, ZERO)
    q = _iso_stiffness_si() * delta ** (10 / 9)
    np.testing.assert_allclose(float(r.normal_force), -side * q, rtol=1e-9)
    np.testing.assert_allclose(np.asarray(r.force_on_roller), -side * q * t, rtol=1e-9, atol=1e-9)
    # the force acts on the roller's axis line: no moment about its centre
    np.testing.assert_allclose(np.asarray(r.moment_on_roller), 0.0, atol=1e-9 * q)


def test_skewed_roller_slices_and_restoring_moment():
    """Skew beta about e_rad: slice k at xi_k is offset xi_k sin(beta) and its circle reaches
    (D/2) cos(beta) along t_c, so delta_k = |xi_k| sin(beta) + (D/2) cos(beta) - (D + C_p)/2."""
    e_rad, t, pc = _frame()
    beta = 0.04
    e = np.cos(beta) * X + np.sin(beta) * t
    n = 5
    r = _contact(pc, e, ZERO, ZERO, pc, t, ZERO, ZERO, ZERO, num_slices=n)
    b = BEARING
    d, c_p = float(b.roller.diameter), float(b.cage.pocket_clearance)
    l_we = float(b.roller.length) - 2 * float(b.roller.corner_radius)
    xi = l_we * ((np.arange(n) + 0.5) / n - 0.5)
    delta = np.abs(xi) * np.sin(beta) + d / 2 * np.cos(beta) - (d + c_p) / 2
    q = _iso_stiffness_si() / n * np.clip(delta, 0, None) ** (10 / 9)
    # slices with xi > 0 press the +wall, xi < 0 the -wall, equally: no net force. e is the
    # roller turned by -beta about e_rad; each loaded slice's force -/+q t_c acts at
    # xi e +/- (D/2) u_hat, u_hat = cos(beta) t_c - sin(beta) X, so the couple about e_rad is
    # q (|xi| cos(beta) - (D/2) sin(beta)) per slice, positive: it turns the roller back.
    np.testing.assert_allclose(np.asarray(r.force_on_roller), 0.0, atol=1e-6 * q.sum())
    couple = np.sum(q * (np.abs(xi) * np.cos(beta) - d / 2 * np.sin(beta)))
    np.testing.assert_allclose(float(np.dot(r.moment_on_roller, e_rad)), couple, rtol=1e-6)


def test_action_reaction_and_cage_moment_arm():
    """Force on the cage = -force on the roller; moments balance about any point; the moment
    on the cage about X is the pocket radius times the tangential force."""
    e_rad, t, pc0 = _frame()
    cage_centre = np.array([0.0, 3e-5, -2e-5])
    _, _, pc = _frame(cage_centre=cage_centre)
    c_p = float(BEARING.cage.pocket_clearance)
    p = pc + (c_p / 2 + 2e-6) * t
    # static: pure normal force
    r = _contact(p, X, ZERO, ZERO, pc, t, ZERO, ZERO, cage_centre)
    np.testing.assert_allclose(np.asarray(r.force_on_cage), -np.asarray(r.force_on_roller))
    f_t = float(np.dot(r.force_on_cage, t))
    np.testing.assert_allclose(float(r.moment_on_cage[0]), float(BEARING.pitch_diameter) / 2 * f_t, rtol=1e-9)
    # moving bodies, friction on: total moment about the cage centre is zero
    v = np.array([0.01, 0.3, -0.2])
    w = np.array([8000.0, 20.0, -15.0])
    vc = np.array([0.0, 0.05, 0.02])
    wc = np.array([900.0, 0.0, 0.0])
    r = _contact(p, X, v, w, pc, t, vc, wc, cage_centre)
    f = np.asarray(r.force_on_roller)
    np.testing.assert_allclose(np.asarray(r.force_on_cage), -f)
    total = np.asarray(r.moment_on_roller) + np.cross(p - cage_centre, f) + np.asarray(r.moment_on_cage)
    np.testing.assert_allclose(total, 0.0, atol=1e-12 * np.abs(f).max())


def test_friction_opposes_sliding():
    e_rad, t, pc = _frame()
    c_p, d = float(BEARING.cage.pocket_clearance), float(BEARING.roller.diameter)
    mu = float(BEARING.pocket_friction)
    p = pc + (c_p / 2 + 2e-6) * t
    q = _iso_stiffness_si() * (2e-6) ** (10 / 9)
    # roller sliding radially outwards along the wall at 1 m/s (no approach: no damping)
    r = _contact(p, X, e_rad, ZERO, pc, t, ZERO, ZERO, ZERO)
    f = np.asarray(r.force_on_roller)
    np.testing.assert_allclose(np.dot(f, e_rad), -mu * q, rtol=1e-5)
    np.testing.assert_allclose(np.dot(f, t), -q, rtol=1e-9)
    # roller spinning about +X: its surface at the +wall moves along -e_rad, friction along
    # +e_rad on the roller and a moment about the axis against the spin, mu Q times the arm
    # D/2 - delta/2 (the force acts at the middle of the overlap)
    spin = 10000.0
    r = _contact(p, X, ZERO, spin * X, pc, t, ZERO, ZERO, ZERO)
    np.testing.assert_allclose(np.dot(r.force_on_roller, e_rad), mu * q, rtol=1e-5)
    arm = d / 2 - 1e-6
    np.testing.assert_allclose(float(r.moment_on_roller[0]), -mu * q * arm, rtol=1e-6)
    # the cage moving with the roller: no relative sliding, no friction
    r = _contact(p, X, e_rad, ZERO, pc, t, e_rad, ZERO, ZERO)
    np.testing.assert_allclose(np.dot(r.force_on_roller, e_rad), 0.0, atol=1e-12)


def test_hunt_crossley_damping():
    """Approaching the wall at v_n: N = Q (1 + 1.5 alpha v_n); receding: less, never negative."""
    _, t, pc = _frame()
    c_p = float(BEARING.cage.pocket_clearance)
    p = pc + (c_p / 2 + 2e-6) * t
    q = _iso_stiffness_si() * (2e-6) ** (10 / 9)
    for v_n in (0.1, -0.1):
        r = _contact(p, X, v_n * t, ZERO, pc, t, ZERO, ZERO, ZERO)
        np.testing.assert_allclose(
            float(r.normal_force), -q * (1 + 1.5 * HUNT_CROSSLEY_ALPHA * v_n), rtol=1e-9
        )
    r = _contact(p, X, -100.0 * t, ZERO, pc, t, ZERO, ZERO, ZERO)
    assert -q * 1e-3 < float(r.normal_force) <= 0.0


def test_gradients_finite_at_zero_interference_and_zero_sliding():
    _, t, pc = _frame()
    c_p = float(BEARING.cage.pocket_clearance)

    def total(y, vel, spin):
        r = pocket_contact(
            BEARING, pc + y * t, X, vel, spin * X, pc, t, jnp.zeros(3), jnp.zeros(3), jnp.zeros(3)
        )
        return jnp.sum(r.force_on_roller) + jnp.sum(r.moment_on_roller) + r.normal_force

    grad = jax.jit(jax.grad(total, argnums=(0, 1, 2)))
    for y in (0.0, c_p / 2, c_p / 2 + 1e-6, -c_p / 2):
        g = grad(jnp.asarray(y), jnp.zeros(3), jnp.asarray(0.0))
        assert all(np.all(np.isfinite(np.asarray(x))) for x in g)

    # at exactly zero interference the load law has a finite slope: pushing the roller further
    # into the +wall makes the (signed) normal force more negative
    def normal(y):
        z = jnp.zeros(3)
        return pocket_contact(BEARING, pc + y * t, X, z, z, pc, t, z, z, z).normal_force

    g_y = jax.jit(jax.grad(normal))(jnp.asarray(c_p / 2))
    assert np.isfinite(float(g_y)) and float(g_y) < 0.0
