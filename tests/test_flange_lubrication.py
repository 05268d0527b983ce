"""Lubricated roller-end/flange contact (issue 14, items 3 and 4): the Hamrock-Dowson film
through the flange wiring against the closed form with hand kinematics, the contact point's
velocity, the dry/mixed friction limits, finite gradients (loaded, unloaded, at rest), the
tangent-plane error against an independent cone distance, top-edge detection, and the new
statistics in both summaries."""

import dataclasses
import math
import types

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import minimize, minimize_scalar
from test_contact_hertz import exact_hertz

import jaxbearing as jb
from jaxbearing.contact import mixed_traction_force, traction_coefficient
from jaxbearing.flange import (
    contact_point_velocity,
    flange_friction_coefficient,
    flange_geometry,
    roller_flange_contact,
)
from jaxbearing.run import FILM_KEYS, steady_statistics, summarise

X = np.array([1.0, 0.0, 0.0])
OMEGA_I = jb.rpm_to_rad_s(20_000.0)
AZIMUTH = 0.7


def _bearing(mode="dry", **lub):
    b = jb.reference_bearing()
    b = eqx.tree_at(lambda b: b.radial_clearance, b, jnp.asarray(0.0))
    for name, value in lub.items():
        b = eqx.tree_at(lambda b, n=name: getattr(b.lubricant, n), b, jnp.asarray(value, jnp.float64))
    return dataclasses.replace(b, flange_lubrication=mode)


def _state(b, ring_sign, axial=0.0, axis=None, azimuth=AZIMUTH):
    """Roller on the raceways at `azimuth` under pure rolling (outer ring fixed, inner ring at
    OMEGA_I): (R_r, p, e, v, w, c_r, v_r, w_r), plus (e_rad, omega_ring, omega_cage)."""
    dm, d = float(b.pitch_diameter), float(b.roller.diameter)
    e_rad = np.array([0.0, math.sin(azimuth), math.cos(azimuth)])
    w_c = OMEGA_I * (1 - d / dm) / 2
    r_o = float(b.outer_raceway_radius)
    p = (dm / 2) * e_rad + axial * X
    v = np.cross(w_c * X, p)
    w = (w_c - 2 * w_c * r_o / d) * X
    radius, w_ring = (float(b.inner_raceway_radius), OMEGA_I) if ring_sign > 0 else (r_o, 0.0)
    e = X if axis is None else np.asarray(axis)
    arrays = tuple(
        jnp.asarray(x, jnp.float64) for x in (radius, p, e, v, w, np.zeros(3), np.zeros(3), w_ring * X)
    )
    return arrays, (e_rad, w_ring, w_c)


@jax.jit
def _contact(b, side, ring_sign, st):
    radius, p, e, v, w, c, vr, wr = st
    return roller_flange_contact(b, radius, side, ring_sign, p, e, v, w, c, vr, wr)


def _loaded(b, side, ring_sign, interference=2e-6, axis=None):
    """A rolling state whose contact with flange (side, ring) has the given interference."""
    st, kin = _state(b, ring_sign, axis=axis)
    d0 = float(_contact(b, side, ring_sign, st).interference)
    theta = float(b.flange.layback_angle)
    st, kin = _state(b, ring_sign, axial=side * (interference - d0) / math.cos(theta), axis=axis)
    return st, kin, _contact(b, side, ring_sign, st)


def _e_prime(b):
    e, nu = float(b.ring_material.elastic_modulus), float(b.ring_material.poisson_ratio)
    assert float(b.roller_material.elastic_modulus) == e and float(b.roller_material.poisson_ratio) == nu
    return e / (1 - nu**2)  # Hamrock's E' = 2 / (2 (1 - nu^2)/E) for equal materials


def _hand_film(q, rx, k, u, eta, alpha, e_prime):
    """Hamrock & Dowson (1977) h_min and the central film, evaluated by hand."""
    big_u, g, w = eta * u / (e_prime * rx), alpha * e_prime, q / (e_prime * rx * rx)
    h_min = rx * 3.63 * big_u**0.68 * g**0.49 * w**-0.073 * (1 - math.exp(-0.68 * k))
    h_c = rx * 2.69 * big_u**0.67 * g**0.53 * w**-0.067 * (1 - 0.61 * math.exp(-0.73 * k))
    return h_min, h_c


# -- film through the wiring ---------------------------------------------------------------


@pytest.mark.parametrize("end", ["arc", "corner"])
@pytest.mark.parametrize("ring_sign", [1.0, -1.0])
@pytest.mark.parametrize("side", [-1.0, 1.0])
def test_flange_film_is_hamrock_dowson_closed_form(side, ring_sign, end):
    """Aligned roller, pure rolling: the entrainment speed from hand kinematics (roller and ring
    surface speeds at contact height h_c in the cage frame), u_e = |w_r - w_c| (R_r +
    g h_c (D - 2 g R_r) / (2 D)); the viscosity at T_in = 60 C from Reynolds' law; the radii of
    the end surface (arc: R_end both ways, k = 1; corner: R_x = rho_c / sin(theta_f) along the
    circumferential entrainment, R_y = R_cor, k from the independent scipy Hertz oracle); then
    h_min, h_c and Lambda = h_min / sigma by hand."""
    b = _bearing("mixed", inlet_temperature=60.0)
    if end == "corner":
        b = b.with_flat_ends()
    _, (e_rad, w_ring, w_c), res = _loaded(b, side, ring_sign)
    q = float(res.normal_force)
    assert q > 10.0
    d, theta = float(b.roller.diameter), float(b.flange.layback_angle)
    r_r = float(b.inner_raceway_radius if ring_sign > 0 else b.outer_raceway_radius)
    h = float(res.contact_height)
    u_e = abs(w_ring - w_c) * (r_r + ring_sign * h * (d - 2 * ring_sign * r_r) / (2 * d))
    np.testing.assert_allclose(float(res.entrainment_speed), u_e, rtol=1e-9)
    eta = 0.055 * math.exp(-0.0315 * (60.0 - 80.0))
    e_prime = _e_prime(b)
    if end == "arc":
        assert float(res.on_arc) == 1.0
        rx, k = float(b.roller.end_radius), 1.0
    else:
        assert float(res.on_arc) == 0.0
        rho = float(b.roller.corner_centre_radius) + float(b.roller.corner_radius) * math.sin(theta)
        rx, ry = rho / math.sin(theta), float(b.roller.corner_radius)
        k = 1.0 / exact_hertz(q, rx, ry, e_prime)["k"]  # a_y / a_x < 1: rolling along the long axis
    h_min, h_c = _hand_film(q, rx, k, u_e, eta, 1.85e-8, e_prime)
    np.testing.assert_allclose(float(res.min_film), h_min, rtol=1e-8)
    np.testing.assert_allclose(float(res.central_film), h_c, rtol=1e-8)
    np.testing.assert_allclose(float(res.film_parameter), h_min / 0.2e-6, rtol=1e-8)
    # a number to read: the arc end at 20,000 rpm carries a thick film
    if end == "arc":
        assert 3e-6 < h_min < 10e-6 and float(res.film_parameter) > 10


def test_film_follows_the_inlet_temperature():
    """eta ~ exp(-beta_T T_in) and h ~ eta^0.68: heating the inlet by 22 C halves eta and
    scales h_min by 2^-0.68 (the film law's speed exponent, through the wiring)."""
    hot = 80.0 + math.log(2.0) / 0.0315
    h80 = float(_loaded(_bearing(), 1.0, 1.0)[2].min_film)
    hh = float(_loaded(_bearing(inlet_temperature=hot), 1.0, 1.0)[2].min_film)
    np.testing.assert_allclose(hh / h80, 2.0**-0.68, rtol=1e-9)


def test_contact_point_moves_with_the_azimuth_frame():
    """v_C = v + Omega X x (C - p) is the exact velocity of the contact point when the roller's
    pose relative to the frame turning with its azimuth is frozen (skewed and tilted roller,
    ring centre off the origin, radial and axial drift): central difference of C(t)."""
    b = _bearing()
    c_r = np.array([0.0, 2e-5, -3e-5])
    omega, v_rad, v_ax = 900.0, 0.05, -0.02
    e_rad0 = np.array([0.0, math.sin(AZIMUTH), math.cos(AZIMUTH)])
    tang = np.cross(e_rad0, X)
    e0 = X + 0.01 * tang + 0.004 * e_rad0
    e0 /= np.linalg.norm(e0)
    p0 = c_r + (float(b.pitch_diameter) / 2) * e_rad0 + 1e-5 * X

    def rot(t):
        a = omega * t
        return np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])

    def pose(t):
        p = c_r + rot(t) @ (p0 - c_r + t * (v_rad * e_rad0 + v_ax * X))
        return p, rot(t) @ e0

    for side, ring_sign in [(1.0, 1.0), (-1.0, -1.0)]:
        radius = float(b.inner_raceway_radius if ring_sign > 0 else b.outer_raceway_radius)

        def point(t, side=side, ring_sign=ring_sign, radius=radius):
            p, e = pose(t)
            return np.asarray(_geometry(b, radius, side, ring_sign, p, e, c_r).contact_point)

        dt = 1e-7
        fd = (point(dt) - point(-dt)) / (2 * dt)
        v = np.cross(omega * X, p0 - c_r) + v_rad * e_rad0 + v_ax * X
        got = contact_point_velocity(p0, v, c_r, np.zeros(3), point(0.0))
        np.testing.assert_allclose(got, fd, rtol=0, atol=1e-7 * np.linalg.norm(fd))


# -- friction: dry and mixed -----------------------------------------------------------------


def test_mixed_friction_limits():
    """mu(Lambda -> 0) = mu_f (boundary), mu(Lambda >> 1) = kappa(|u|) (full film), the load
    share of Lambda = 1 and 3 in between; "dry" is mu_f whatever the film."""
    lam = jnp.array([0.0, 1e-3, 1.0, 3.0, 10.0, 1e3])
    u = jnp.array([0.0, 20.0, 0.0])
    b = _bearing("mixed")
    mu_f = float(b.flange_traction)
    kappa = float(traction_coefficient(math.sqrt(400.0 + 1e-6), b.lubricant))
    assert abs(kappa - mu_f) > 0.03  # the two limits differ (0.04 against 0.08)
    mu = np.asarray(flange_friction_coefficient(b, lam, jnp.broadcast_to(u, (6, 3))))
    assert mu[0] == mu_f
    np.testing.assert_allclose(mu[1], mu_f, rtol=1e-15)
    np.testing.assert_allclose(mu[2], 0.9 * mu_f + 0.1 * kappa, rtol=1e-12)
    np.testing.assert_allclose(mu[3], (mu_f + 81 * kappa) / 82, rtol=1e-12)
    np.testing.assert_allclose(mu[5], kappa, rtol=1e-15)
    assert np.all(np.diff(mu) <= 0)  # monotone from boundary to full film here
    dry = np.asarray(flange_friction_coefficient(_bearing("dry"), lam, jnp.broadcast_to(u, (6, 3))))
    assert np.all(dry == mu_f)


def test_contact_friction_dry_and_mixed():
    """Through the contact: "dry" keeps the old law -mu_f Q u/s; "mixed" gives exactly
    `mixed_traction_force` with the contact's own Lambda, tends to kappa with a thick film
    (reference oil, Lambda ~ 25) and to mu_f with a vanishing one (300 C inlet, rough)."""
    theta = float(jb.reference_bearing().flange.layback_angle)
    e_rad = np.array([0.0, math.sin(AZIMUTH), math.cos(AZIMUTH)])
    n = math.cos(theta) * X - math.sin(theta) * e_rad  # side +1, inner ring
    for mode in ("dry", "mixed"):
        b = _bearing(mode)
        _, _, res = _loaded(b, 1.0, 1.0, axis=_skewed_axis(0.003))
        q, u = res.normal_force, res.sliding_velocity
        assert float(q) > 10 and float(res.sliding_speed) > 1
        if mode == "dry":
            expect = -b.flange_traction * q * u / jnp.sqrt(jnp.sum(u * u) + 1e-6)
            assert float(res.friction_coefficient) == float(b.flange_traction)
        else:
            expect = mixed_traction_force(u, q, res.film_parameter, b.flange_traction, b.lubricant)
        # force on the roller = -Q n + friction
        np.testing.assert_allclose(res.force_on_roller + q * n, expect, rtol=0, atol=1e-12 * float(q))
    thick = _loaded(_bearing("mixed"), 1.0, 1.0)[2]
    kappa = float(traction_coefficient(float(thick.sliding_speed), jb.reference_bearing().lubricant))
    assert float(thick.film_parameter) > 10
    np.testing.assert_allclose(float(thick.friction_coefficient), kappa, rtol=1e-6)
    b = _bearing("mixed", inlet_temperature=300.0)
    b = eqx.tree_at(lambda b: b.flange.roughness, b, jnp.asarray(2e-6))
    thin = _loaded(b, 1.0, 1.0)[2]
    assert float(thin.film_parameter) < 0.1
    np.testing.assert_allclose(float(thin.friction_coefficient), float(b.flange_traction), rtol=1e-6)


# -- gradients --------------------------------------------------------------------------------


@pytest.mark.parametrize("mode", ["dry", "mixed"])
def test_gradients_finite_loaded_unloaded_and_at_rest(mode):
    """jax.grad of every output of the contact (films and Lambda included) with respect to the
    bearing (roughness, temperatures, viscosity, mu_f ...), pose and velocities: finite when
    loaded and sliding, separated from the flange (zero load), touching at rest (zero sliding and
    zero entrainment), and for a flat end square-on to the flange (alpha = 0)."""
    b = _bearing(mode)

    def total(bb, p, e, v, w, wr):
        r = roller_flange_contact(
            bb, bb.inner_raceway_radius, 1.0, 1.0, p, e, v, w, jnp.zeros(3), jnp.zeros(3), wr
        )
        return sum(jnp.sum(x) for x in jax.tree_util.tree_leaves(r))

    grad = jax.jit(jax.grad(total, argnums=(0, 1, 2, 3, 4, 5)))
    (radius, p, e, v, w, _, _, wr), _ = _state(b, 1.0)
    theta = float(b.flange.layback_angle)
    d0 = float(_contact(b, 1.0, 1.0, _state(b, 1.0)[0]).interference)
    zero = jnp.zeros(3)
    flat = eqx.tree_at(lambda b: b.flange.layback_angle, b.with_flat_ends(), jnp.asarray(0.0))
    cases = [
        (b, (2e-6 - d0) / math.cos(theta), v, w, wr),  # loaded, sliding
        (b, -1e-3, v, w, wr),  # far from the flange: Q = 0
        (b, -d0 / math.cos(theta), zero, zero, zero),  # zero interference, everything at rest
        (b, (2e-6 - d0) / math.cos(theta), zero, zero, zero),  # loaded at rest: u = u_e = 0
        (flat, 0.1e-3, zero, zero, zero),  # flat end square-on (alpha = 0)
        (flat, -0.1e-3, v, w, wr),
    ]
    for bb, axial, vv, ww, wwr in cases:
        pp = p + axial * X
        val = jax.jit(total)(bb, pp, e, vv, ww, wwr)
        assert np.isfinite(float(val))
        for leaf in jax.tree_util.tree_leaves(grad(bb, pp, e, vv, ww, wwr)):
            assert np.all(np.isfinite(np.asarray(leaf)))
    # the film gradients are not trivially zero where loaded: d h_min / d T_in < 0
    st, _, _ = _loaded(b, 1.0, 1.0)

    def h_of_t(t):
        bb = eqx.tree_at(lambda b: b.lubricant.inlet_temperature, b, t)
        return _contact(bb, 1.0, 1.0, st).min_film

    assert float(jax.grad(h_of_t)(jnp.asarray(80.0))) < 0


# -- item 4: the flange face -----------------------------------------------------------------


_geometry = jax.jit(flange_geometry)


def _cone_distance(b, side, ring_sign, radius, points):
    """Signed distance into the flange cone, computed independently in cylindrical coordinates
    about the ring axis (exact for a cone of revolution: distance to the generator line in the
    meridian half-plane of the point)."""
    theta = float(b.flange.layback_angle)
    w_half = float(b.raceway_width) / 2
    pts = np.atleast_2d(points)
    rho = np.hypot(pts[:, 1], pts[:, 2])
    return side * math.cos(theta) * (pts[:, 0] - side * w_half) - ring_sign * math.sin(theta) * (rho - radius)


def _skewed_axis(skew):
    e_rad = np.array([0.0, math.sin(AZIMUTH), math.cos(AZIMUTH)])
    return math.cos(skew) * X + math.sin(skew) * np.cross(e_rad, X)


@pytest.mark.parametrize("ring_sign", [1.0, -1.0])
@pytest.mark.parametrize("side", [-1.0, 1.0])
def test_tangent_plane_error_against_the_exact_cone(side, ring_sign):
    """The tangent-plane gap at the contact point differs from the exact cone distance by
    exactly g e(C), e = sin(theta_f) rho (1 - cos psi) = `face_error`, bounded by
    sin(theta_f) s_c^2 / rho and ~ sin(theta_f) s_c^2 / (2 rho) (docs/model.md 5.2). For the arc
    end the exact cone interference (maximised numerically over the end sphere) differs from the
    model's by g e(O) at the sphere centre O = C - R_end n, within 7 % of `face_error`; on the
    corner (a union of balls of radius R_cor on the centre circle) by at most e at the plane's
    (inner ring) or the cone's (outer ring) ball centre (within 15 % of `face_error`; the actual
    difference within 7 %). Reference values: 0.30-0.34 um at s_c = 1 mm (13 mrad
    skew, arc), 2.5-2.7 um at 2.8 mm (60 mrad, the contact has moved onto the corner)."""
    b = _bearing()
    theta = float(b.flange.layback_angle)
    radius = float(b.inner_raceway_radius if ring_sign > 0 else b.outer_raceway_radius)
    r_end = float(b.roller.end_radius)
    for skew in (0.003, 0.013, 0.06):
        st, _ = _state(b, ring_sign, axis=_skewed_axis(skew))
        _, p, e, *_ = st
        for bb in (b, b.with_flat_ends()):
            g = _geometry(bb, radius, side, ring_sign, p, e, jnp.zeros(3))
            c = np.asarray(g.contact_point)
            e_rad = np.array([0.0, math.sin(AZIMUTH), math.cos(AZIMUTH)])
            n = side * math.cos(theta) * X - ring_sign * math.sin(theta) * e_rad
            p0 = side * float(b.raceway_width) / 2 * X + radius * e_rad
            d_plane = (c - p0) @ n
            d_cone = _cone_distance(b, side, ring_sign, radius, c)[0]
            err = float(g.face_error)
            np.testing.assert_allclose(d_plane - d_cone, ring_sign * err, rtol=1e-9, atol=1e-16)
            rho = math.hypot(c[1], c[2])
            s_c = float(g.circumferential_offset)
            np.testing.assert_allclose(s_c, c @ np.cross(X, e_rad), rtol=1e-12, atol=1e-18)
            assert err <= math.sin(theta) * s_c**2 / rho
            np.testing.assert_allclose(err, math.sin(theta) * s_c**2 / (2 * rho), rtol=(s_c / rho) ** 2)
            if bb is b and skew == 0.013:  # about 1 mm: the measured 0.36 um
                assert 0.9e-3 < abs(s_c) < 1.1e-3 and 0.3e-6 < err < 0.4e-6
            if bb is b and skew == 0.06:  # on the corner by now, 2.8 mm: 2.5-2.7 um
                assert 2.7e-3 < abs(s_c) < 2.9e-3 and 2.4e-6 < err < 2.8e-6

        # exact cone interference of the arc end: max of the cone distance over the end sphere
        g = _geometry(b, radius, side, ring_sign, p, e, jnp.zeros(3))
        if float(g.on_arc) < 1.0:
            continue  # the contact has left the cap (corner: checked below)
        c = np.asarray(g.contact_point)
        centre = c - r_end * np.asarray(g.normal)

        def neg(angles, centre=centre, n=np.asarray(g.normal)):
            a, bb_ = angles
            t1 = np.cross(n, X)
            t1 /= np.linalg.norm(t1)
            t2 = np.cross(n, t1)
            m = n * math.cos(math.hypot(a, bb_)) + (a * t1 + bb_ * t2) * np.sinc(math.hypot(a, bb_) / math.pi)
            return -_cone_distance(b, side, ring_sign, radius, centre + r_end * m)[0]

        opt = minimize(
            neg, [0.0, 0.0], method="Nelder-Mead", options=dict(xatol=1e-13, fatol=1e-19, maxiter=4000)
        )
        delta_cone = -opt.fun
        x_end = side * np.asarray(e)
        a_, b_ = opt.x
        assert math.hypot(a_, b_) < 2e-3  # the normal turns by ~ sin(theta_f) |psi|
        assert r_end * math.sin(math.acos(float(np.asarray(g.normal) @ x_end)) + math.hypot(a_, b_)) < float(
            jb.geometry.limited_circle_radius(b.roller)
        )  # and the cone's contact stays on the cap
        delta_plane = float(g.interference)
        o_err = math.sin(theta) * (math.hypot(centre[1], centre[2]) - centre @ e_rad)
        np.testing.assert_allclose(delta_plane - delta_cone, ring_sign * o_err, rtol=1e-6, atol=1e-14)
        if float(g.face_error) > 1e-9:
            assert 0.93 < o_err / float(g.face_error) < 1.07

    # corner: the tube is a union of balls of radius R_cor on the centre circle
    flat = b.with_flat_ends()
    st, _ = _state(b, ring_sign, axis=_skewed_axis(0.02))
    _, p, e, *_ = st
    g = _geometry(flat, radius, side, ring_sign, p, e, jnp.zeros(3))
    x_end = side * np.asarray(e)
    u1 = np.cross(x_end, X + np.array([0.0, 1.0, 0.3]))
    u1 /= np.linalg.norm(u1)
    u2 = np.cross(x_end, u1)
    ring_centre = np.asarray(p) + float(flat.roller.corner_centre_offset) * x_end
    r_ce = float(flat.roller.corner_centre_radius)

    def neg_circle(phi):
        q = ring_centre + r_ce * (math.cos(phi) * u1 + math.sin(phi) * u2)
        return -_cone_distance(b, side, ring_sign, radius, q)[0]

    q_c = np.asarray(g.contact_point) - float(flat.roller.corner_radius) * np.asarray(g.normal)
    rel = q_c - ring_centre
    phi0 = math.atan2(rel @ u2, rel @ u1)
    opt = minimize_scalar(
        neg_circle, bounds=(phi0 - 0.2, phi0 + 0.2), method="bounded", options=dict(xatol=1e-13)
    )
    delta_cone = -opt.fun + float(flat.roller.corner_radius)
    diff = ring_sign * (float(g.interference) - delta_cone)
    e_rad = np.array([0.0, math.sin(AZIMUTH), math.cos(AZIMUTH)])

    def e_at(q):
        return math.sin(theta) * (math.hypot(q[1], q[2]) - q @ e_rad)

    q_star = ring_centre + r_ce * (math.cos(opt.x) * u1 + math.sin(opt.x) * u2)
    # g = +1: bounded by e at the plane's ball centre; g = -1: at the cone's
    bound = e_at(q_c) if ring_sign > 0 else e_at(q_star)
    assert -1e-13 <= diff <= bound + 1e-13
    assert diff <= 1.07 * float(g.face_error) and bound <= 1.15 * float(g.face_error)


def test_top_edge_contact_is_detected():
    """`top_edge` = 1 exactly when the contact point's radial height above the raceway (exact,
    about the ring axis) exceeds the flange height: never on the reference design, always with
    a flange lower than the contact height."""
    b = _bearing()
    for ring_sign in (1.0, -1.0):
        res = _loaded(b, 1.0, ring_sign)[2]
        assert float(res.top_edge) == 0.0
        h = float(res.contact_height)
        low = eqx.tree_at(lambda b: b.flange.height, b, jnp.asarray(h - 0.05e-3))
        assert float(_loaded(low, 1.0, ring_sign)[2].top_edge) == 1.0
        high = eqx.tree_at(lambda b: b.flange.height, b, jnp.asarray(h + 0.05e-3))
        assert float(_loaded(high, 1.0, ring_sign)[2].top_edge) == 0.0


# -- statistics ------------------------------------------------------------------------------


def _film_history(n=200, z=2):
    """Two cage revolutions [0, 10 ms), [10, 20 ms); roller 0 presses on flange 0 during samples
    20-59 (revolution 0) and 120-159 (revolution 1). Lambda runs 0.5 -> 2.45 in the first and is
    4 in the second; the first 10 contact samples of revolution 1 are above the flange top."""
    t = np.linspace(0.0, 0.02, n, endpoint=False)
    shape = (n, z, 4)
    force = np.zeros(shape)
    force[20:60, 0, 0] = 50.0
    force[120:160, 0, 0] = 50.0
    lam = np.full(shape, 100.0)  # outside contact: must not count
    lam[20:60, 0, 0] = np.linspace(0.5, 2.45, 40)
    lam[120:160, 0, 0] = 4.0
    top = np.zeros(shape)
    top[120:130, 0, 0] = 1.0
    zeros = np.zeros(shape)
    return dict(
        t=t,
        flange_force=force,
        flange_pressure=force * 1e7,
        flange_sliding_speed=zeros + 2.0,
        flange_roller_surface_speed=zeros + 3.0,
        flange_pv=force * 2e7,
        contact_height=zeros + 1e-3,
        contact_radius=zeros + 3e-3,
        on_arc=zeros + 1.0,
        flange_min_film=lam * 0.2e-6,
        flange_central_film=lam * 0.3e-6,
        flange_film_parameter=lam,
        flange_top_edge=top,
        flange_face_error=zeros + 1e-8,
        cage_speed=np.full(n, 100.0),
        roller_skew=np.zeros((n, z)),
    )


def test_fixed_and_settled_summaries_contain_the_film_statistics():
    hist = _film_history()
    contact_lam = np.concatenate([np.linspace(0.5, 2.45, 40), np.full(40, 4.0)])
    result = types.SimpleNamespace(
        histories=hist,
        bearing=jb.reference_bearing(),
        operating=jb.reference_operating_point(),
        status="ok",
        smooth_peak_pv=0.0,
        smooth_max_contact_height=1e-3,
        num_steps=1,
        num_rejected_steps=0,
        wall_time_s=0.0,
        compile_time_s=0.0,
        reached_time=0.02,
    )
    s = summarise(result)
    np.testing.assert_allclose(s["film_parameter"]["mean"], np.mean(contact_lam))
    np.testing.assert_allclose(s["film_parameter"]["median"], np.median(contact_lam))
    np.testing.assert_allclose(s["film_parameter"]["p05"], np.percentile(contact_lam, 5))
    np.testing.assert_allclose(s["flange_min_film_m"]["min"], 0.5 * 0.2e-6)
    np.testing.assert_allclose(s["flange_central_film_m"]["median"], np.median(contact_lam) * 0.3e-6)
    # Lambda < 1 for linspace(0.5, 2.45, 40) samples 0..10 (0.5 + 0.05 i < 1: i < 10) -> 10 of 80
    np.testing.assert_allclose(s["lambda_below_one_share"], 10 / 80)
    np.testing.assert_allclose(s["top_edge_contact_share"], 10 / 80)
    np.testing.assert_allclose(s["flange_face_error_max_m"], 1e-8)

    block = steady_statistics(
        [hist], [[0.0, 0.01, 0.02]], jb.reference_bearing(), jb.reference_operating_point()
    )
    for key in FILM_KEYS:
        group, _, red = key.partition(".")
        est = block[group][red] if red else block[group]
        assert set(est) == {"value", "ci95_low", "ci95_high", "n"}
        assert est["n"] == 2
    share = block["lambda_below_one_share"]
    np.testing.assert_allclose(share["value"], (10 / 40 + 0.0) / 2)
    assert share["ci95_low"] <= share["value"] <= share["ci95_high"]
    np.testing.assert_allclose(block["top_edge_contact_share"]["value"], (0.0 + 10 / 40) / 2)
    np.testing.assert_allclose(
        block["film_parameter"]["p05"]["value"], (np.percentile(contact_lam[:40], 5) + 4.0) / 2
    )
    # older histories without film quantities: None in the summary, never a KeyError
    old = {
        k: v
        for k, v in hist.items()
        if not k.startswith("flange_") or k in ("flange_force", "flange_pressure")
    }
    old.update({k: hist[k] for k in ("flange_sliding_speed", "flange_roller_surface_speed", "flange_pv")})
    s_old = summarise(types.SimpleNamespace(**{**vars(result), "histories": old}))
    assert s_old["lambda_below_one_share"] is None and s_old["film_parameter"]["median"] is None
