"""Lubricated point contact: Hamrock-Dowson film, viscosity, film parameter, mixed traction.

Oracle for the film thickness: the published formulas, evaluated by hand in the tests with the
published coefficients (Hamrock & Dowson, J. Lubr. Technol. 99:264-276, 1977, whose abstract
states H_min = 3.63 U^0.68 G^0.49 W^-0.073 (1 - e^-0.68k); the central film
H_c = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 e^-0.73k) from Hamrock & Dowson, Ball Bearing
Lubrication, 1981). A worked numerical example from Hamrock's textbooks could not be retrieved
with the sources available to this project, so no textbook film value is asserted. The
ellipticity k = a_y/a_x comes from the independent scipy oracle of test_contact_hertz.
"""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from test_contact_hertz import exact_hertz

from jaxbearing.contact import (
    ASPERITY_MIDPOINT,
    asperity_load_fraction,
    central_film_thickness,
    effective_modulus,
    ehl_parameters,
    entrainment_radii,
    entrainment_velocity,
    film_parameter,
    minimum_film_thickness,
    mixed_traction_coefficient,
    mixed_traction_force,
    traction_coefficient,
    viscosity_at_temperature,
)
from jaxbearing.geometry import Lubricant

# representative steel contact in oil (the source paper's oil: 0.055 Pa s at 80 C,
# alpha_p = 1.85e-8 1/Pa, beta_T = 0.0315 1/C)
E_PRIME = float(effective_modulus(2.08e11, 0.3, 2.08e11, 0.3))
ETA, ALPHA_P, BETA_T, T0 = 0.055, 1.85e-8, 0.0315, 80.0
LUB = Lubricant(
    viscosity=ETA,
    pressure_viscosity=ALPHA_P,
    temperature_viscosity=BETA_T,
    density=870.0,
    oil_fraction=0.05,
    traction_a=-0.04,
    traction_b=0.2528,
    traction_c=2.926,
    traction_d=0.04,
)


def _hand_film(load, rx, ry, u, kind):
    """Hamrock-Dowson by hand: U, G, W from the definitions, k from the exact Hertz oracle."""
    big, small = max(rx, ry), min(rx, ry)
    k_long_short = exact_hertz(load, big, small, E_PRIME)["k"]
    k = k_long_short if ry >= rx else 1 / k_long_short  # a_y / a_x
    U = ETA * u / (E_PRIME * rx)
    G = ALPHA_P * E_PRIME
    W = load / (E_PRIME * rx * rx)
    if kind == "min":
        return rx * 3.63 * U**0.68 * G**0.49 * W**-0.073 * (1 - math.exp(-0.68 * k))
    return rx * 2.69 * U**0.67 * G**0.53 * W**-0.067 * (1 - 0.61 * math.exp(-0.73 * k))


_hmin = jax.jit(minimum_film_thickness)
_hc = jax.jit(central_film_thickness)


@pytest.mark.parametrize(
    "load, rx, ry, u",
    [
        (50.0, 40e-3, 40e-3, 5.0),  # ball on plate (k = 1), arc end on flange size
        (1000.0, 5e-3, 50e-3, 10.0),  # ball-bearing-like groove contact, k = 4.5
        (200.0, 2e-3, 16e-3, 2.0),  # k = 3.3
        (20.0, 0.4e-3, 1.5e-3, 20.0),  # small, fast
    ],
)
def test_film_thickness_is_hamrock_dowson(load, rx, ry, u):
    for fn, kind in [(_hmin, "min"), (_hc, "central")]:
        got = float(fn(load, rx, ry, u, E_PRIME, ETA, ALPHA_P, 0.0))
        np.testing.assert_allclose(got, _hand_film(load, rx, ry, u, kind), rtol=1e-10)
    # the regularised speed and load change nothing measurable at these loads and speeds
    np.testing.assert_allclose(
        _hmin(load, rx, ry, u, E_PRIME, ETA, ALPHA_P), _hand_film(load, rx, ry, u, "min"), rtol=1e-7
    )


def test_ehl_parameters_and_ellipticity_orientation():
    u, g, w, k = ehl_parameters(1000.0, 5e-3, 50e-3, 10.0, E_PRIME, ETA, ALPHA_P, 0.0)
    np.testing.assert_allclose(
        [u, g, w], [ETA * 10 / (E_PRIME * 5e-3), ALPHA_P * E_PRIME, 1000 / (E_PRIME * 25e-6)], rtol=1e-14
    )
    np.testing.assert_allclose(k, exact_hertz(1000.0, 50e-3, 5e-3, E_PRIME)["k"], rtol=1e-9)
    # rolling along the long axis: k < 1
    *_, k_long = ehl_parameters(1000.0, 50e-3, 5e-3, 10.0, E_PRIME, ETA, ALPHA_P, 0.0)
    np.testing.assert_allclose(k_long, 1 / k, rtol=1e-12)


_log_hmin = jax.jit(
    jax.grad(
        lambda x: jnp.log(
            minimum_film_thickness(
                jnp.exp(x[0]), 5e-3, 50e-3, jnp.exp(x[1]), E_PRIME, jnp.exp(x[2]), jnp.exp(x[3]), 0.0
            )
        )
    )
)
_log_hc = jax.jit(
    jax.grad(
        lambda x: jnp.log(
            central_film_thickness(
                jnp.exp(x[0]), 5e-3, 50e-3, jnp.exp(x[1]), E_PRIME, jnp.exp(x[2]), jnp.exp(x[3]), 0.0
            )
        )
    )
)


def test_exponents_of_the_film_formulas():
    # d ln h / d ln (Q, u, eta, alpha_p) = exponents of W, U, U, G (Q = 1000 N >> load floor)
    x = jnp.log(jnp.array([1000.0, 10.0, ETA, ALPHA_P]))
    np.testing.assert_allclose(_log_hmin(x), [-0.073, 0.68, 0.68, 0.49], rtol=1e-9)
    np.testing.assert_allclose(_log_hc(x), [-0.067, 0.67, 0.67, 0.53], rtol=1e-9)


def test_viscosity_at_temperature():
    np.testing.assert_allclose(viscosity_at_temperature(T0, ETA, BETA_T, T0), ETA, rtol=1e-15)
    # halves every ln(2)/beta_T = 22.0 C
    np.testing.assert_allclose(
        viscosity_at_temperature(T0 + math.log(2) / BETA_T, ETA, BETA_T, T0), ETA / 2, rtol=1e-14
    )
    np.testing.assert_allclose(
        viscosity_at_temperature(40.0, ETA, BETA_T, T0), ETA * math.exp(0.0315 * 40), rtol=1e-14
    )


def test_entrainment_velocity_and_radii():
    np.testing.assert_allclose(
        entrainment_velocity(jnp.array([3.0, 1.0]), jnp.array([1.0, -1.0])), [2.0, 0.0]
    )
    r1, r2 = 0.4e-3, 120e-3
    np.testing.assert_allclose(entrainment_radii(r1, r2, 1.0), (r1, r2), rtol=1e-15)
    np.testing.assert_allclose(entrainment_radii(r1, r2, 0.0), (r2, r1), rtol=1e-15)
    # at 45 degrees both directions see the mean curvature
    rx, ry = entrainment_radii(r1, r2, math.sqrt(0.5))
    np.testing.assert_allclose([rx, ry], [2 / (1 / r1 + 1 / r2)] * 2, rtol=1e-14)


def test_film_parameter():
    h, s1, s2 = 0.3e-6, 0.0625e-6, 0.175e-6
    # the 1e-12 m roughness floor changes this by 1.4e-11
    np.testing.assert_allclose(film_parameter(h, s1, s2), h / math.hypot(s1, s2), rtol=1e-10)
    assert math.isfinite(float(film_parameter(h, 0.0, 0.0)))


def test_asperity_load_fraction():
    f = jax.jit(asperity_load_fraction)
    np.testing.assert_allclose(
        f(jnp.array([0.0, 1.0, 3.0, ASPERITY_MIDPOINT])), [1.0, 0.9, 1 / 82, 0.5], rtol=1e-14
    )
    lam = jnp.linspace(0.0, 10.0, 101)
    assert bool(jnp.all(jnp.diff(f(lam)) < 0))
    assert float(jax.grad(asperity_load_fraction)(0.0)) == 0.0


def test_mixed_traction_coefficient_limits_and_blend():
    mu_b, mu_f = 0.08, 0.04
    np.testing.assert_allclose(mixed_traction_coefficient(0.0, mu_b, mu_f), mu_b, rtol=1e-15)
    np.testing.assert_allclose(mixed_traction_coefficient(50.0, mu_b, mu_f), mu_f, rtol=1e-9)
    np.testing.assert_allclose(
        mixed_traction_coefficient(1.0, mu_b, mu_f), 0.9 * mu_b + 0.1 * mu_f, rtol=1e-14
    )


def test_mixed_traction_force():
    u = jnp.array([3.0, -4.0])  # |u| = 5 m/s
    q, lam, mu_b = 40.0, 2.0, 0.08
    s = math.sqrt(25.0 + 1e-6)
    kappa = float(traction_coefficient(s, LUB))
    f_a = 1 / (1 + lam**6 / 9)  # Lambda_m^6 = 9
    mu = f_a * mu_b + (1 - f_a) * kappa
    np.testing.assert_allclose(
        mixed_traction_force(u, q, lam, mu_b, LUB), -q * mu * np.asarray(u) / s, rtol=1e-13
    )
    # boundary limit is Coulomb friction with the flange coefficient
    np.testing.assert_allclose(
        mixed_traction_force(u, q, 0.0, mu_b, LUB), -q * mu_b * np.asarray(u) / s, rtol=1e-14
    )


def _lubricated(x):
    """Film and traction chain of one contact at (Q, u_entrain, u_slide)."""
    q, ue, us = x[0], x[1], x[2]
    h = minimum_film_thickness(q, 40e-3, 40e-3, ue, E_PRIME, ETA, ALPHA_P)
    lam = film_parameter(h, 0.1e-6, 0.1e-6)
    f = mixed_traction_force(jnp.array([us, 0.0]), q, lam, 0.08, LUB)
    return jnp.stack([h, lam, f[0]])


_lub = jax.jit(_lubricated)
_lub_d1 = jax.jit(jax.jacfwd(_lubricated))
_lub_d2 = jax.jit(jax.hessian(_lubricated))


@pytest.mark.parametrize(
    "x",
    [
        (0.0, 0.0, 0.0),
        (0.0, 5.0, 5.0),
        (50.0, 0.0, 0.0),
        (50.0, 0.0, 1e-4),
        (-1.0, -3.0, 2.0),
        (50.0, 5.0, 5.0),
    ],
)
def test_finite_and_smooth_at_zero_speed_and_load(x):
    x = jnp.asarray(x, dtype=float)
    out = _lub(x)
    assert bool(jnp.all(jnp.isfinite(out)))
    assert bool(jnp.all(jnp.isfinite(_lub_d1(x))))
    assert bool(jnp.all(jnp.isfinite(_lub_d2(x))))
    assert float(out[0]) > 0.0
    if float(x[1]) == 0.0 and float(x[0]) > 0:
        # at rest: a nanometre-scale film, boundary lubrication, Coulomb friction at mu_b
        assert float(out[0]) < 1e-8 and float(out[1]) < 0.1


def test_film_at_rest_scale_and_zero_load():
    # at zero entrainment speed the film is the one of u_eps = 1 mm/s; at zero load the one of
    # Q_f (1 + ln(1 + e^-1)) (the smooth floor), so finite; the traction vanishes with the load
    h0 = float(_hmin(50.0, 40e-3, 40e-3, 0.0, E_PRIME, ETA, ALPHA_P))
    np.testing.assert_allclose(h0, _hand_film(50.0, 40e-3, 40e-3, 1e-3, "min"), rtol=1e-12)
    hq = float(_hmin(0.0, 40e-3, 40e-3, 5.0, E_PRIME, ETA, ALPHA_P))
    q_floor = 1e-3 * (1 + math.log1p(math.exp(-1)))
    np.testing.assert_allclose(hq, _hand_film(q_floor, 40e-3, 40e-3, 5.0, "min"), rtol=1e-7)
    assert float(jnp.abs(mixed_traction_force(jnp.array([5.0, 0.0]), 0.0, 1.0, 0.08, LUB)).max()) == 0
