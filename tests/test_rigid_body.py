"""Torque-free symmetric rigid body (docs/validation.md): precession rate, energy, angular momentum."""

import diffrax
import jax.numpy as jnp
import numpy as np

from jaxbearing.dynamics import angular_momentum, axisymmetric_body_rates, kinetic_energy

I_A, I_T = 1.94e-8, 2.46e-8  # the reference roller's inertias [kg m^2]


def _solve(e0, w0, t1, moment=lambda e, w: jnp.zeros(3)):
    def f(t, y, args):
        e, w = y
        return axisymmetric_body_rates(e, w, moment(e, w), I_A, I_T)

    ts = jnp.linspace(0, t1, 201)
    sol = diffrax.diffeqsolve(
        diffrax.ODETerm(f),
        diffrax.Tsit5(),
        0.0,
        t1,
        t1 / 2000,
        (e0, w0),
        saveat=diffrax.SaveAt(ts=ts),
        stepsize_controller=diffrax.PIDController(rtol=1e-11, atol=1e-13),
        max_steps=200_000,
    )
    return ts, sol.ys


def test_torque_free_precession_energy_momentum():
    # spinning roller (1e4 rad/s) with a 0.05 rad nutation: not a small-angle case for the axis path
    e0 = jnp.array([1.0, 0.0, 0.0])
    w0 = jnp.array([-1.0e4, 300.0, -200.0])
    ts, (e, w) = _solve(e0, w0, 2e-3)
    h0 = angular_momentum(e0, w0, I_A, I_T)
    h = angular_momentum(e, w, I_A, I_T)
    np.testing.assert_allclose(
        h, np.broadcast_to(h0, h.shape), rtol=0, atol=1e-9 * float(jnp.linalg.norm(h0))
    )
    t0 = kinetic_energy(e0, w0, I_A, I_T)
    np.testing.assert_allclose(kinetic_energy(e, w, I_A, I_T), t0, rtol=1e-9)
    spin = jnp.sum(w * e, axis=-1)
    np.testing.assert_allclose(spin, spin[0], rtol=1e-9)
    # the axis stays on a cone about H and turns about it at Omega_p = |H| / I_t
    h_unit = h0 / jnp.linalg.norm(h0)
    cos_cone = e @ h_unit
    np.testing.assert_allclose(cos_cone, cos_cone[0], atol=1e-10)
    perp = e - cos_cone[:, None] * h_unit
    ref = perp[0] / jnp.linalg.norm(perp[0])
    other = jnp.cross(h_unit, ref)
    angle = np.unwrap(np.arctan2(perp @ other, perp @ ref))
    rate = np.polyfit(np.asarray(ts), angle, 1)[0]
    np.testing.assert_allclose(rate, float(jnp.linalg.norm(h0)) / I_T, rtol=1e-8)


def test_gyroscopic_moment_matches_closed_form():
    # steady precession of a fast top: a moment M perpendicular to H turns H at |M|/|H|
    e0 = jnp.array([1.0, 0.0, 0.0])
    w0 = jnp.array([1.0e4, 0.0, 0.0])
    m = jnp.array([0.0, 1e-6, 0.0])
    rates = axisymmetric_body_rates(e0, w0, m, I_A, I_T)
    # dH/dt = M exactly
    dh = I_T * rates[1] + (I_A - I_T) * (jnp.dot(rates[1], e0) * e0 + jnp.dot(w0, e0) * rates[0])
    np.testing.assert_allclose(dh, m, atol=1e-18)
