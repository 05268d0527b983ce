"""Cage on the outer-ring guiding lands (jaxbearing.forces, docs/model.md 9).

Oracles: Petroff's concentric torque; Ocvirk's closed-form short-bearing load and attitude
angle (Hamrock, Schmid & Jacobson, Fundamentals of Fluid Film Lubrication, short-width
journal bearing); a direct numerical integration (scipy.integrate.fixed_quad) of the
short-bearing pressure over the pi film for squeeze and whirl; the ISO/TS 16281 line-contact
law written out by hand for the rub contact.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy import integrate

from jaxbearing import reference_bearing
from jaxbearing.forces import (
    FILM_ECCENTRICITY_KNEE,
    FILM_ECCENTRICITY_MAX,
    cage_land_forces,
    capped_eccentricity,
)

B = reference_bearing()
ETA = float(B.lubricant.oil_fraction * B.lubricant.viscosity)  # mixture viscosity on the lands
R = float(B.cage.outer_diameter) / 2
C = float(B.cage.guiding_clearance) / 2
L = float(B.cage.land_width)
X = np.array([1.0, 0.0, 0.0])

_forces = jax.jit(lambda c, v, w: cage_land_forces(B, c, v, w))


def _direction(angle):
    n = np.array([0.0, np.sin(angle), np.cos(angle)])
    return n, np.cross(X, n)


def test_concentric_cage_petroff_torque():
    omega = 1100.0
    f, m = _forces(np.zeros(3), np.zeros(3), omega)
    np.testing.assert_array_equal(np.asarray(f), 0.0)
    petroff = -2 * np.pi * ETA * R**3 * (2 * L) * omega / C
    np.testing.assert_allclose(float(m), petroff, rtol=1e-12)
    assert float(m) < 0  # opposes the rotation
    _, m_back = _forces(np.zeros(3), np.zeros(3), -omega)
    np.testing.assert_allclose(float(m_back), -petroff, rtol=1e-12)


@pytest.mark.parametrize("angle", [0.0, 1.2, -2.5])
def test_ocvirk_closed_form_at_half_clearance(angle):
    """eps = 0.5, steady rotation: per land W_r = eta omega R L^3 eps^2 / (c^2 (1 - eps^2)^2)
    against the eccentricity, W_t = pi eta omega R L^3 eps / (4 c^2 (1 - eps^2)^(3/2)) along
    the rotation; attitude angle tan(phi) = pi sqrt(1 - eps^2) / (4 eps)."""
    eps, omega = 0.5, 1100.0
    n, t = _direction(angle)
    f, _ = _forces(eps * C * n, np.zeros(3), omega)
    f = np.asarray(f)
    w_r = 2 * ETA * omega * R * L**3 * eps**2 / (C**2 * (1 - eps**2) ** 2)
    w_t = 2 * np.pi * ETA * omega * R * L**3 * eps / (4 * C**2 * (1 - eps**2) ** 1.5)
    np.testing.assert_allclose(f, -w_r * n + w_t * t, rtol=1e-12, atol=1e-12 * w_r)
    attitude = np.arctan2(np.dot(f, t), -np.dot(f, n))
    np.testing.assert_allclose(attitude, np.arctan(np.pi * np.sqrt(1 - eps**2) / (4 * eps)))
    assert float(f[0]) == 0.0


def _pi_film_quadrature(eps, omega, eps_dot, eps_phi_dot):
    """Force on the cage (n, t components) by integrating the short-bearing pressure.

    h = c (1 - eps cos theta), theta from the eccentricity direction n towards t; the
    short-bearing Reynolds equation gives int p dz = -eta L^3 G / h^3 with
    G = c (eps (omega/2 - phi') sin theta - eps' cos theta); pi film: theta in (pi, 2 pi);
    force on the journal = -R int (int p dz) (cos theta, sin theta) d theta, times two lands.
    """

    def g(theta):
        return C * ((eps * omega / 2 - eps_phi_dot) * np.sin(theta) - eps_dot * np.cos(theta))

    def p_int(theta):
        h = C * (1 - eps * np.cos(theta))
        return -ETA * L**3 * g(theta) / h**3

    # smooth integrand on a closed interval (eps < 1): 200-point Gauss-Legendre is exact to
    # rounding
    f_n = -R * integrate.fixed_quad(lambda th: p_int(th) * np.cos(th), np.pi, 2 * np.pi, n=200)[0]
    f_t = -R * integrate.fixed_quad(lambda th: p_int(th) * np.sin(th), np.pi, 2 * np.pi, n=200)[0]
    return 2 * f_n, 2 * f_t


@pytest.mark.parametrize(
    "eps, omega, v_n, v_t",
    [
        (0.5, 0.0, 0.02, 0.0),
        (0.3, 0.0, 0.0, 0.03),
        (0.6, 900.0, -0.01, 0.015),
        (0.0, 900.0, 0.02, 0.0),
    ],
)
def test_squeeze_and_whirl_against_quadrature(eps, omega, v_n, v_t):
    angle = 0.4
    n, t = _direction(angle)
    vel = v_n * n + v_t * t
    f, _ = _forces(eps * C * n, vel, omega)
    f_n, f_t = _pi_film_quadrature(eps, omega, v_n / C, v_t / C)
    scale = max(abs(f_n), abs(f_t))
    np.testing.assert_allclose(np.dot(f, n), f_n, rtol=1e-9, atol=1e-12 * scale)
    np.testing.assert_allclose(np.dot(f, t), f_t, rtol=1e-9, atol=1e-12 * scale)


def test_concentric_squeeze_is_isotropic_damping():
    """At e = 0 the pi-film squeeze force is -(pi eta R L^3 / (2 c^3)) v per land, any v."""
    v = np.array([0.0, 0.013, -0.021])
    f, _ = _forces(np.zeros(3), v, 700.0)
    damping = 2 * np.pi * ETA * R * L**3 / (2 * C**3)  # two lands
    np.testing.assert_allclose(np.asarray(f), -damping * v, rtol=1e-12)


def _rub_stiffness():
    """ISO/TS 16281 by hand over 2 b_l, scaled by E'(cage, ring) / E'(steel), SI units."""
    k_mm = 2 ** (10 / 9) * 35948.0 * (2 * L * 1e3) ** (8 / 9)
    e1, n1 = float(B.cage_material.elastic_modulus), float(B.cage_material.poisson_ratio)
    e2, n2 = float(B.ring_material.elastic_modulus), float(B.ring_material.poisson_ratio)
    e_pair = 2 / ((1 - n1**2) / e1 + (1 - n2**2) / e2)
    return k_mm * e_pair / (2.075e11 / 0.91) * 1e3 ** (10 / 9)


def test_rub_contact_beyond_clearance():
    n, _ = _direction(2.0)
    k = _rub_stiffness()
    # no rotation and no velocity: the film carries nothing, the rub law is exposed
    for eps in (1.001, 1.01, 1.1):
        delta = (eps - 1) * C
        f, m = _forces(eps * C * n, np.zeros(3), 0.0)
        np.testing.assert_allclose(np.asarray(f), -k * delta ** (10 / 9) * n, rtol=1e-9)
        assert float(m) == 0.0
    # with rotation the force grows without bound past the clearance
    mags = [
        float(np.linalg.norm(_forces(eps * C * n, np.zeros(3), 1000.0)[0]))
        for eps in (0.9, 0.99, 1.0, 1.01, 1.1, 1.5)
    ]
    assert all(b > a for a, b in zip(mags, mags[1:]))
    assert mags[-1] > 100 * mags[0]
    # rub friction: the torque drops below Petroff while the cage rubs the land
    _, m_free = _forces(0.97 * C * n, np.zeros(3), 1000.0)
    _, m_rub = _forces(1.01 * C * n, np.zeros(3), 1000.0)
    assert float(m_rub) < float(m_free) < 0


def test_capped_eccentricity():
    eps = np.linspace(0.0, 3.0, 301)
    capped = np.asarray(capped_eccentricity(eps))
    below = eps <= FILM_ECCENTRICITY_KNEE
    np.testing.assert_array_equal(capped[below], eps[below])
    assert np.all(np.diff(capped) > 0) and capped.max() < FILM_ECCENTRICITY_MAX
    # C1 at the knee
    d = jax.grad(capped_eccentricity)
    np.testing.assert_allclose(float(d(FILM_ECCENTRICITY_KNEE + 1e-9)), 1.0, rtol=1e-6)


def test_finite_values_and_gradients_everywhere():
    def total(centre, vel, omega):
        f, m = cage_land_forces(B, centre, vel, omega)
        return jnp.sum(f) + m

    grad = jax.jit(jax.grad(total, argnums=(0, 1, 2)))
    n, _ = _direction(0.9)
    vel = np.array([0.0, 0.02, -0.01])
    for eps in (0.0, 1e-12, 0.5, 0.8, 0.95, 0.999, 1.0, 1.2, 5.0):
        centre = eps * C * n
        f, m = _forces(centre, vel, 1000.0)
        assert np.all(np.isfinite(np.asarray(f))) and np.isfinite(float(m))
        for g in grad(jnp.asarray(centre), jnp.asarray(vel), jnp.asarray(1000.0)):
            assert np.all(np.isfinite(np.asarray(g)))
    # zero eccentricity, zero velocity, zero speed
    for g in grad(jnp.zeros(3), jnp.zeros(3), jnp.asarray(0.0)):
        assert np.all(np.isfinite(np.asarray(g)))
