"""Differentiable design metrics (jaxbearing.design.design_metrics): AD through the diffrax solve against
central finite differences (the acceptance check of issue 5), the contact-height sensitivities
against the closed form of docs/model.md 5, the static margins against `design_zone`, vmapping over
designs, and the one-line input errors.

Cost: one forward compile, one forward-mode Jacobian compile and 13 short solves (0.3 ms of
simulated time at rtol 1e-6). Checkpointed reverse mode gives the same gradient (to 1e-8 in the
measurements) but its compilation alone takes minutes on a 2-core CPU; its agreement with forward
mode and with finite differences is measured by benchmarks/bench_gradients.py instead."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing import UserInputError
from jaxbearing.design import (
    GRADIENT_ATOL,
    GRADIENT_HORIZON,
    GRADIENT_RTOL,
    design_jacobian,
    design_metrics,
    seated_perturbation,
)
from jaxbearing.flange import DesignVariables, zone_margins

REF = jb.reference_bearing()
OP = jb.reference_operating_point()
X0 = np.asarray(DesignVariables.of(REF).as_array())
TIGHT = dict(rtol=GRADIENT_RTOL, atol=GRADIENT_ATOL, max_steps=100_000)
#: relative FD steps: the check step and a 10x smaller one for the FD convergence check
FD_REL = (1e-4, 1e-5)


@jax.jit
def _values(x):
    d = DesignVariables.from_array(x)
    m = design_metrics(REF, OP, d, duration=GRADIENT_HORIZON, **TIGHT)
    return jnp.stack([m.peak_pv, m.max_contact_height, m.min_contact_height])


@pytest.fixture(scope="module")
def central_differences():
    """{rel: (3 outputs, 3 variables) central differences} and the value at the reference."""
    out = {}
    for rel in FD_REL:
        cols = []
        for i in range(3):
            h = rel * X0[i]
            xp, xm = X0.copy(), X0.copy()
            xp[i] += h
            xm[i] -= h
            cols.append(
                (np.asarray(_values(jnp.asarray(xp))) - np.asarray(_values(jnp.asarray(xm)))) / (2 * h)
            )
        out[rel] = np.stack(cols, axis=1)
    return np.asarray(_values(jnp.asarray(X0))), out


@pytest.fixture(scope="module")
def forward_jacobian():
    f = jax.jit(
        lambda x: design_jacobian(
            REF, OP, DesignVariables.from_array(x), duration=GRADIENT_HORIZON, mode="forward", **TIGHT
        )
    )
    v, j = f(jnp.asarray(X0))
    return np.asarray(v), np.asarray(j)


def test_horizon_contains_flange_contacts(central_differences):
    value, _ = central_differences
    pv, h_max, h_min = value
    assert np.all(np.isfinite(value))
    assert pv > 1e6  # a real roller-flange contact occurred within the horizon
    # the contact sits on the arc, between the relief and the upper limit (docs/model.md 5)
    z = jb.design_zone(REF)
    assert 0.3e-3 < h_min <= h_max < 1.8e-3
    assert h_min == pytest.approx(float(z.contact_height), abs=20e-6)


def test_finite_differences_converge(central_differences):
    """The FD reference itself is converged: the two step sizes agree to 0.1%."""
    _, fd = central_differences
    a, b = fd[FD_REL[0]], fd[FD_REL[1]]
    scale = np.abs(a).max(axis=1, keepdims=True)
    assert np.all(np.abs(a - b) < 1e-3 * scale), (a, b)


def test_forward_mode_matches_central_differences(central_differences, forward_jacobian):
    """Issue 5 acceptance: d(peak PV)/d(design) and d(contact height)/d(design) by AD agree
    with central finite differences to 1% on the reference bearing (same tight tolerances)."""
    value, fd = central_differences
    v, jac = forward_jacobian
    np.testing.assert_allclose(v, value, rtol=1e-9)
    ref = fd[FD_REL[0]]
    scale = np.abs(ref).max(axis=1, keepdims=True)  # per output, so tiny entries compare fairly
    assert np.all(np.abs(jac - ref) < 0.01 * scale), (jac, ref)
    # the large entries individually to 1%
    big = np.abs(ref) > 0.05 * scale
    np.testing.assert_allclose(jac[big], ref[big], rtol=0.01)


def test_contact_height_sensitivity_matches_closed_form(forward_jacobian):
    """An aligned arc-end roller touches at h_c = D/2 - R_end sin(theta_f) (docs/model.md 5):
    dh/dR_end = -sin(theta_f), dh/dtheta_f = -R_end cos(theta_f), independent of Delta_bf."""
    _, jac = forward_jacobian
    r, t = X0[0], X0[1]
    for row in (1, 2):
        assert jac[row, 0] == pytest.approx(-math.sin(t), rel=0.01)
        assert jac[row, 1] == pytest.approx(-r * math.cos(t), rel=0.01)
        assert abs(jac[row, 2]) * 1e-4 < 1e-3 * abs(jac[row, 0]) * X0[0]


def test_static_margins_match_design_zone_and_vmap():
    designs = DesignVariables(
        end_radius=jnp.array([0.08, 0.1, 0.12]),
        layback_angle=jnp.radians(jnp.array([1.6, 1.2, 1.0])),
        axial_clearance=jnp.array([0.15e-3, 0.2e-3, 0.3e-3]),
    )
    m = jax.vmap(lambda d: zone_margins(REF, d, min_clearance=0.01e-3))(designs)
    for k in range(3):
        d = jax.tree_util.tree_map(lambda a: a[k], designs)
        z = jb.design_zone(d.apply(REF), min_clearance=0.01e-3)
        np.testing.assert_allclose(
            m[k], [z.relief_margin, z.height_margin, z.limited_circle_margin, z.clearance_margin]
        )
        # the closed form of the height margin: h_up - (D/2 - R sin theta)
        r, t = float(d.end_radius), float(d.layback_angle)
        assert float(m[k, 1]) == pytest.approx(1.8e-3 - (3.75e-3 - r * math.sin(t)), abs=1e-9)
    # gradients of the margins are finite and vmappable
    jac = jax.vmap(jax.jacfwd(lambda x: zone_margins(REF, DesignVariables.from_array(x))))(designs.as_array())
    assert jac.shape == (3, 4, 3) and bool(jnp.all(jnp.isfinite(jac)))


def test_seated_perturbation_starts_outermost_roller_at_contact():
    p = seated_perturbation(REF)
    z = jb.design_zone(REF)
    k1, _ = jax.random.split(jax.random.PRNGKey(p.seed))
    u = np.asarray(jax.random.uniform(k1, (REF.num_rollers,), minval=-1.0, maxval=1.0))
    assert float(p.axial) * np.abs(u).max() == pytest.approx(float(z.seated_gap) / 2, rel=1e-12)


@pytest.mark.parametrize(
    "field,value,text",
    [
        ("end_radius", 1e-3, "design.end_radius = 0.001"),
        ("layback_angle", -0.1, "design.layback_angle = -0.1"),
        ("axial_clearance", 0.0, "design.axial_clearance = 0.0"),
    ],
)
def test_bad_design_is_one_line_error(field, value, text):
    d = DesignVariables.of(REF)
    d = DesignVariables(
        **{**{k: getattr(d, k) for k in ("end_radius", "layback_angle", "axial_clearance")}, field: value}
    )
    with pytest.raises(UserInputError, match=text.replace(".", r"\.")) as e:
        design_metrics(REF, OP, d, duration=1e-4)
    assert "\n" not in str(e.value)
    with pytest.raises(UserInputError):
        design_jacobian(REF, OP, d, duration=1e-4)


def test_bad_mode():
    with pytest.raises(UserInputError, match="mode = 'sideways'"):
        design_jacobian(REF, OP, DesignVariables.of(REF), duration=1e-4, mode="sideways")
