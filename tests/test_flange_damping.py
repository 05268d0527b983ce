"""The roller-end/flange contact's normal damping (Hunt-Crossley, `jaxbearing.contact`): the
restitution of one end-on impact against a flange, integrated, against the exact closed form;
and the paper's sliding definition reported beside the material sliding speed."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import jaxbearing as jb
from jaxbearing.contact import HUNT_CROSSLEY_ALPHA, hunt_crossley_factor, restitution_coefficient
from jaxbearing.flange import flange_geometry, roller_flange_contact

X = np.array([1.0, 0.0, 0.0])


def test_factor_is_the_hunt_crossley_factor_and_stays_positive():
    v = np.array([-0.5, 0.0, 0.3, 2.0])
    np.testing.assert_allclose(hunt_crossley_factor(v, 0.3), 1 + 0.45 * v, rtol=1e-9)
    assert float(hunt_crossley_factor(-100.0, 0.3)) >= 0.0  # no adhesive pull
    assert np.isfinite(jax.grad(lambda r: hunt_crossley_factor(r))(-100.0))


@pytest.mark.parametrize("v_in", [0.01, 0.2, 1.0])
def test_restitution_closed_form_limits(v_in):
    e = restitution_coefficient(v_in, 0.3)
    lam = 0.45
    f = lambda v: v / lam - np.log1p(lam * v) / lam**2
    np.testing.assert_allclose(f(-e * v_in), f(v_in), rtol=1e-10)
    # small alpha v: e = 1 - alpha v + O((alpha v)^2) (Hunt & Crossley 1975)
    assert abs(e - (1 - 0.3 * v_in)) < 0.5 * (0.45 * v_in) ** 2 + 1e-12


def _impact(v_in: float) -> float:
    """Roller (axis along X, on the inner raceway) thrown at the inner +X flange along the
    flange normal: rebound speed / impact speed, integrated at tight tolerance."""
    b = jb.reference_bearing()
    radius = b.inner_raceway_radius
    centre = jnp.array([0.0, 0.0, 1.0]) * (radius + b.roller.diameter / 2)
    ring = jnp.zeros(3)
    geo = flange_geometry(b, radius, 1.0, 1.0, centre, jnp.asarray(X), ring)
    n = np.asarray(geo.normal)
    start = centre - (float(geo.interference) + 2e-6) * n  # 2 um gap along the normal
    mass = float(b.roller_mass)

    @jax.jit
    def normal_force(s, s_dot):
        c = roller_flange_contact(
            b,
            radius,
            1.0,
            1.0,
            start + s * n,
            jnp.asarray(X),
            s_dot * n,
            jnp.zeros(3),
            ring,
            jnp.zeros(3),
            jnp.zeros(3),
        )
        return jnp.dot(c.force_on_roller, n), c.approach_rate

    def rhs(t, y):
        f, _ = normal_force(y[0], y[1])
        return [y[1], float(f) / mass]

    def separated(t, y):
        return y[0] - 0.0  # back at the starting gap

    separated.terminal, separated.direction = True, -1
    sol = solve_ivp(
        rhs,
        (0.0, 1e-3),
        [1e-12, v_in],
        rtol=1e-10,
        atol=1e-15,
        events=separated,
        method="DOP853",
        max_step=2e-8,
    )
    assert sol.status == 1, "the roller did not come back"
    # the approach rate seen by the contact is the closing speed along n
    np.testing.assert_allclose(float(normal_force(0.0, v_in)[1]), v_in, rtol=1e-12)
    return -sol.y_events[0][0][1] / v_in


@pytest.mark.parametrize("v_in", [0.05, 0.5])
def test_end_on_flange_impact_restitution(v_in):
    e = _impact(v_in)
    np.testing.assert_allclose(e, restitution_coefficient(v_in, HUNT_CROSSLEY_ALPHA), rtol=2e-3)
    assert e < 1.0


def test_roller_surface_speed_is_the_papers_definition():
    """An aligned roller spinning at w about its axis: the paper's sliding speed (Figure 7c) is
    its own surface speed w rho_c at the contact radius, rho_c = R_end sin(theta_f) on the arc
    and R_ce + R_cor sin(theta_f) on the corner (docs/model.md 5), so corner > arc by their ratio;
    the material sliding speed, which includes the flange's motion, is reported beside it."""
    b = jb.reference_bearing()
    radius = b.inner_raceway_radius
    centre = jnp.array([0.0, 0.0, 1.0]) * (radius + b.roller.diameter / 2)
    w = 2000.0
    out = {}
    for name, bb in (("arc", b), ("corner", b.with_flat_ends())):
        c = roller_flange_contact(
            bb,
            radius,
            1.0,
            1.0,
            centre,
            jnp.asarray(X),
            jnp.zeros(3),
            -w * jnp.asarray(X),
            jnp.zeros(3),
            jnp.zeros(3),
            jnp.zeros(3),
        )
        out[name] = float(c.roller_surface_speed)
    theta, r = float(b.flange.layback_angle), b.roller
    rho_arc = float(r.end_radius) * np.sin(theta)
    rho_corner = float(r.diameter) / 2 - float(r.corner_radius) + float(r.corner_radius) * np.sin(theta)
    np.testing.assert_allclose(out["arc"], w * rho_arc, rtol=1e-9)
    np.testing.assert_allclose(out["corner"], w * rho_corner, rtol=1e-9)
    assert out["corner"] > 1.4 * out["arc"]
