"""Support function, extreme point and principal curvatures of the roller end body
(jaxbearing.geometry) against independent oracles: a numerical maximisation over the
end profile (scipy), the closed forms of docs/model.md 5, and the principal radii of curvature as
eigenvalues of the Hessian of the support function (a convex-geometry identity)."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import jaxbearing as jb
from jaxbearing.geometry import (
    LIMITED_CIRCLE_BAND,
    arc_protrusion,
    arc_weight,
    end_principal_curvatures,
    end_support,
    limited_circle_radius,
)

D, L, R_COR = 7.5e-3, 8e-3, 0.4e-3
R_CE, X_COR = D / 2 - R_COR, L / 2 - R_COR


def _roller(end_radius):
    return jb.Roller(
        diameter=D,
        length=L,
        central_length=4.5e-3,
        crown_drop=4e-6,
        corner_radius=R_COR,
        end_radius=end_radius,
    )


def _profile_support(end_radius, alpha):
    """max over the meridian profile of a cos(alpha) + rho sin(alpha), by bounded scalar
    optimisation on each piece: the corner arc (tube centre (x_cor, R_ce), radius R_cor, polar
    angle phi in [0, pi/2]) and, for an arc end, the sphere cap (centre (L_beb, 0), radius
    R_end, polar angle up to the limited circle)."""
    c, s = math.cos(alpha), math.sin(alpha)
    cands = []

    def torus(phi):
        return (X_COR + R_COR * math.cos(phi), R_CE + R_COR * math.sin(phi))

    phi0 = 0.0
    if math.isfinite(end_radius):
        l_beb = X_COR - math.sqrt((end_radius - R_COR) ** 2 - R_CE**2)
        phi_lim = math.asin(R_CE / (end_radius - R_COR))

        def sphere(phi):
            return (l_beb + end_radius * math.cos(phi), end_radius * math.sin(phi))

        res = minimize_scalar(
            lambda f: -(np.dot(sphere(f), (c, s))),
            bounds=(0, phi_lim),
            method="bounded",
            options={"xatol": 1e-14},
        )
        cands.append((-res.fun, sphere(res.x)))
        phi0 = phi_lim
    res = minimize_scalar(
        lambda f: -(np.dot(torus(f), (c, s))),
        bounds=(phi0, math.pi / 2),
        method="bounded",
        options={"xatol": 1e-14},
    )
    cands.append((-res.fun, torus(res.x)))
    return max(cands, key=lambda t: t[0])


@pytest.mark.parametrize("end_radius", [60e-3, 80e-3, 120e-3, math.inf])
@pytest.mark.parametrize("alpha_deg", [0.3, 1.0, 1.6, 2.4, 5.0, 20.0])
def test_support_matches_profile_maximisation(end_radius, alpha_deg):
    alpha = math.radians(alpha_deg)
    h, a, rho = end_support(_roller(end_radius), jnp.cos(alpha), jnp.sin(alpha))
    h_ref, (a_ref, rho_ref) = _profile_support(end_radius, alpha)
    np.testing.assert_allclose(h, h_ref, rtol=1e-12)
    # the optimiser locates the point to ~sqrt(eps) in angle; the value to ~eps
    np.testing.assert_allclose([a, rho], [a_ref, rho_ref], atol=1e-9)


@pytest.mark.parametrize("end_radius", [60e-3, 80e-3, 120e-3])
def test_branch_closed_forms(end_radius):
    r = _roller(end_radius)
    rho_lim = R_CE * end_radius / (end_radius - R_COR)
    np.testing.assert_allclose(limited_circle_radius(r), rho_lim, rtol=1e-14)
    l_beb = X_COR - math.sqrt((end_radius - R_COR) ** 2 - R_CE**2)
    for alpha in (0.0, 0.01, 0.02):  # on the sphere: rho = R_end sin(alpha)
        h, a, rho = end_support(r, jnp.cos(alpha), jnp.sin(alpha))
        assert end_radius * math.sin(alpha) < rho_lim
        np.testing.assert_allclose(rho, end_radius * math.sin(alpha), rtol=1e-14, atol=1e-18)
        np.testing.assert_allclose(a, l_beb + end_radius * math.cos(alpha), rtol=1e-12)
        np.testing.assert_allclose(h, l_beb * math.cos(alpha) + end_radius, rtol=1e-12)
    alpha = 0.2  # on the torus
    h, a, rho = end_support(r, jnp.cos(alpha), jnp.sin(alpha))
    np.testing.assert_allclose(rho, R_CE + R_COR * math.sin(alpha), rtol=1e-14)
    np.testing.assert_allclose(h, X_COR * math.cos(alpha) + R_CE * math.sin(alpha) + R_COR, rtol=1e-14)
    # along the axis the support is the arc apex: L_b1/2 + e
    h0, _, _ = end_support(r, jnp.asarray(1.0), jnp.asarray(0.0))
    e = end_radius - R_COR - math.sqrt((end_radius - R_COR) ** 2 - R_CE**2)
    np.testing.assert_allclose(h0 - L / 2, e, rtol=1e-9)
    np.testing.assert_allclose(arc_protrusion(r), e, rtol=1e-9)


def test_support_is_c1_across_the_limited_circle():
    """h(alpha) and dh/dalpha continuous at the switch; the extreme point continuous."""
    r = _roller(80e-3)
    alpha_lim = math.asin(R_CE / (80e-3 - R_COR))

    def h(alpha):
        return end_support(r, jnp.cos(alpha), jnp.sin(alpha))[0]

    dh = jax.grad(h)
    for eps in (1e-7, 1e-9):
        lo, hi = alpha_lim - eps, alpha_lim + eps
        assert float(end_support(r, jnp.cos(lo), jnp.sin(lo))[2]) < float(limited_circle_radius(r))
        assert float(end_support(r, jnp.cos(hi), jnp.sin(hi))[2]) > float(limited_circle_radius(r))
        # value: the chord matches the tangent to O((2 eps)^2 R_end) (no jump in h)
        assert abs(float(h(hi) - h(lo) - dh(lo) * 2 * eps)) <= (2 * eps) ** 2 * 80e-3 + 1e-17
        # dh/dalpha = -a sin + rho cos (the extreme point), jumps only by O(eps R_end)
        np.testing.assert_allclose(dh(lo), dh(hi), atol=2 * eps * 80e-3)
        _, a_lo, rho_lo = end_support(r, jnp.cos(lo), jnp.sin(lo))
        _, a_hi, rho_hi = end_support(r, jnp.cos(hi), jnp.sin(hi))
        np.testing.assert_allclose([a_lo, rho_lo], [a_hi, rho_hi], atol=2 * eps * 80e-3)


def test_flat_end_is_ordinary_and_differentiable():
    r = _roller(math.inf)
    for alpha in (0.0, 1e-6, 0.03):
        h, a, rho = end_support(r, jnp.cos(alpha), jnp.sin(alpha))
        np.testing.assert_allclose(rho, R_CE + R_COR * math.sin(alpha), rtol=1e-14)
        assert float(arc_weight(r, jnp.sin(alpha))) == 0.0

    def f(end_radius, alpha):
        rr = _roller(end_radius)
        h, a, rho = end_support(rr, jnp.cos(alpha), jnp.sin(alpha))
        km, kp, w = end_principal_curvatures(rr, jnp.sin(alpha))
        return h + a + rho + km * 1e-6 + kp * 1e-3 + w

    for end_radius in (math.inf, 80e-3):
        for alpha in (0.0, 0.028):
            g = jax.grad(f, argnums=(0, 1))(jnp.asarray(end_radius), jnp.asarray(alpha))
            assert all(np.isfinite(np.asarray(x)) for x in g)


def _support_3d(roller, v):
    """Positively homogeneous extension H(v) = |v| h(v/|v|) of the support function; its
    Hessian at a unit n has the principal radii of curvature at the extreme point as
    eigenvalues on the plane perpendicular to n (Schneider, Convex Bodies, sec. 2.5)."""
    nv = jnp.linalg.norm(v)
    c = v[0] / nv
    s = jnp.linalg.norm(v[1:]) / nv
    return nv * end_support(roller, c, s)[0]


@pytest.mark.parametrize(
    "end_radius,alpha", [(80e-3, 0.02), (80e-3, 0.05), (math.inf, 0.028), (120e-3, 0.035), (60e-3, 0.3)]
)
def test_principal_radii_are_support_hessian_eigenvalues(end_radius, alpha):
    r = _roller(end_radius)
    n = jnp.array([math.cos(alpha), 0.0, math.sin(alpha)])
    hess = jax.hessian(lambda v: _support_3d(r, v))(n)
    meridian = jnp.array([-math.sin(alpha), 0.0, math.cos(alpha)])
    parallel = jnp.array([0.0, 1.0, 0.0])
    r_m = float(meridian @ hess @ meridian)
    r_p = float(parallel @ hess @ parallel)
    assert abs(float(meridian @ hess @ parallel)) < 1e-9
    km, kp, w = end_principal_curvatures(r, jnp.sin(alpha))
    np.testing.assert_allclose([1 / km, 1 / kp], [r_m, r_p], rtol=1e-9)
    on_sphere = end_radius * math.sin(alpha) < float(limited_circle_radius(r))
    if on_sphere:
        np.testing.assert_allclose([r_m, r_p], [end_radius, end_radius], rtol=1e-9)
        assert float(w) == 1.0
    else:
        rho = R_CE + R_COR * math.sin(alpha)
        np.testing.assert_allclose([r_m, r_p], [R_COR, rho / math.sin(alpha)], rtol=1e-9)
        assert float(w) == 0.0


def test_parallel_curvature_is_continuous_at_the_limited_circle():
    """Meusnier: sin(alpha_lim)/rho_lim = 1/R_end, so the torus' parallel curvature meets the
    sphere's; only the meridian curvature needs the blend."""
    r = _roller(80e-3)
    s_lim = R_CE / (80e-3 - R_COR)
    _, kp_blend, _ = end_principal_curvatures(r, jnp.asarray(s_lim))
    _, kp_torus, w = end_principal_curvatures(r, jnp.asarray(s_lim * (1 + 1e-12)), band=1e-30)
    assert float(w) == 0.0  # just onto the torus, no band
    np.testing.assert_allclose([kp_blend, kp_torus], 1 / 80e-3, rtol=1e-9)


def test_arc_weight_band():
    r = _roller(80e-3)
    rho_lim = float(limited_circle_radius(r))
    xi = np.linspace(-3, 2, 501) * LIMITED_CIRCLE_BAND  # rho_lim - R_end sin(alpha)
    s = (rho_lim - xi) / 80e-3
    w = np.asarray(jax.vmap(lambda x: arc_weight(r, x))(jnp.asarray(s)))
    assert np.all((w >= 0) & (w <= 1))
    tol = 1e-6 * LIMITED_CIRCLE_BAND  # rounding of s
    # 1 on the whole arc, 0 from one band width beyond the limited circle
    assert np.all(w[xi >= tol] == 1) and np.all(w[xi <= -LIMITED_CIRCLE_BAND - tol] == 0)
    assert np.all(np.diff(w) >= -1e-15)  # xi increasing: towards the axis
    dw = np.asarray(jax.vmap(jax.grad(lambda x: arc_weight(r, x)))(jnp.asarray(s)))
    assert np.all(np.isfinite(dw))
    # smoothstep: zero slope at both ends of the band
    for edge in (0.0, -LIMITED_CIRCLE_BAND):
        assert abs(dw[np.argmin(np.abs(xi - edge))]) < 1e-6 * np.max(np.abs(dw))
