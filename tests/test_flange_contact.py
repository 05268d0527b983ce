"""Roller end against flange (jaxbearing.flange) against docs/model.md 5's analytic oracle,
hand-written sphere and torus geometry, the sphere-on-plane Hertz closed form, and central
finite differences."""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing.contact import effective_modulus
from jaxbearing.flange import (
    FLANGE_ORDER,
    FlangeContact,
    all_flange_contacts,
    roller_flange_contact,
    with_design,
)
from jaxbearing.geometry import LIMITED_CIRCLE_BAND

X = np.array([1.0, 0.0, 0.0])
OMEGA_I = jb.rpm_to_rad_s(20_000.0)


def _bearing(clearance=0.0):
    b = jb.reference_bearing()
    return eqx.tree_at(lambda b: b.radial_clearance, b, jnp.asarray(clearance))


def _rolling_state(bearing, azimuth, ring_sign, axial=0.0, axis=None):
    """Roller exactly on the raceways (P_d = 0) at `azimuth`, pure rolling, inner ring at
    OMEGA_I about X, outer ring fixed. Returns (raceway_radius, p, e, v, w, c_r, v_r, w_r,
    e_rad, omega_ring, omega_cage)."""
    dm, d = bearing.pitch_diameter, bearing.roller.diameter
    e_rad = jnp.array([0.0, jnp.sin(azimuth), jnp.cos(azimuth)])
    w_c = OMEGA_I * (1 - d / dm) / 2  # kinematic cage speed
    r_o = bearing.outer_raceway_radius
    p = (dm / 2) * e_rad + axial * X
    v = jnp.cross(w_c * X, p)
    # spin relative to the cage from rolling on the fixed outer ring: w_rel R_b = -w_c R_o
    w = (w_c - 2 * w_c * r_o / d) * X
    if ring_sign > 0:
        radius, w_ring = bearing.inner_raceway_radius, OMEGA_I
    else:
        radius, w_ring = r_o, 0.0
    e = X if axis is None else axis
    return (radius, p, jnp.asarray(e), v, w, jnp.zeros(3), jnp.zeros(3), w_ring * X, e_rad, w_ring, w_c)


@jax.jit
def _contact_jit(bearing, side, ring_sign, state):
    radius, p, e, v, w, c, vr, wr = state
    return roller_flange_contact(bearing, radius, side, ring_sign, p, e, v, w, c, vr, wr)


def _contact(bearing, side, ring_sign, state):
    """roller_flange_contact for a `_rolling_state` (jit-compiled once per bearing layout)."""
    f64 = lambda x: jnp.asarray(x, jnp.float64)  # noqa: E731
    bearing = jax.tree_util.tree_map(f64, bearing)
    return _contact_jit(bearing, f64(side), f64(ring_sign), tuple(f64(x) for x in state[:8]))


# -- docs/model.md 5 analytic oracle ----------------------------------------------------------


@jax.jit
def _oracle_case(end_radius, theta, side, ring_sign, azimuth):
    b = with_design(_bearing(), end_radius=end_radius, layback_angle=theta)
    st = _rolling_state(b, azimuth, 1.0)
    st_o = _rolling_state(b, azimuth, -1.0)
    inner = _contact(b, side, 1.0, st)
    outer = _contact(b, side, -1.0, st_o)
    pick = lambda a, o: jnp.where(ring_sign > 0, a, o)  # noqa: E731
    r = jax.tree_util.tree_map(pick, inner, outer)
    n = side * jnp.cos(theta) * X - ring_sign * jnp.sin(theta) * st[8]
    return r, n, st[8]


def test_aligned_oracle_arc_and_corner():
    """rho = R_end sin(theta_f) on the arc (R_ce + R_cor sin(theta_f) on the corner),
    h_c = D/2 - rho, |u| = |omega_ring - omega_cage| (d_m/D) h_c, to 1e-9 relative, across
    R_end 60..120 mm, theta_f 1..2 deg, inner and outer flanges, both sides, two azimuths."""
    b = _bearing()
    d, dm = float(b.roller.diameter), float(b.pitch_diameter)
    r_ce, r_cor = float(b.roller.corner_centre_radius), float(b.roller.corner_radius)
    w_c = OMEGA_I * (1 - d / dm) / 2
    cases = [
        (r_end, math.radians(t), s, g, phi)
        for r_end in (60e-3, 75e-3, 90e-3, 105e-3, 120e-3, math.inf)
        for t in (1.0, 1.25, 1.5, 1.75, 2.0)
        for s in (-1.0, 1.0)
        for g in (1.0, -1.0)
        for phi in (0.0, 2.1)
    ]
    arr = [jnp.asarray(c) for c in zip(*cases)]
    res, n, e_rad = jax.vmap(_oracle_case)(*arr)
    n_arc = n_corner = 0
    for i, (r_end, t, s, g, phi) in enumerate(cases):
        rho_lim = r_ce * r_end / (r_end - r_cor) if math.isfinite(r_end) else r_ce
        if math.isfinite(r_end) and r_end * math.sin(t) < rho_lim:
            rho, n_arc = r_end * math.sin(t), n_arc + 1
            assert float(res.on_arc[i]) == 1.0
        else:
            rho, n_corner = r_ce + r_cor * math.sin(t), n_corner + 1
            assert float(res.on_arc[i]) == 0.0
        h_c = d / 2 - rho
        w_ring = OMEGA_I if g > 0 else 0.0
        speed = abs(w_ring - w_c) * (dm / d) * h_c
        np.testing.assert_allclose(res.contact_radius[i], rho, rtol=1e-9)
        np.testing.assert_allclose(res.contact_height[i], h_c, rtol=1e-9)
        np.testing.assert_allclose(res.sliding_speed[i], speed, rtol=1e-9)
        # the contact sits on the raceway side of the end: z = -g rho, y = 0
        np.testing.assert_allclose(res.end_face_position[i], [0.0, -g * rho], atol=1e-12 * d)
        # sliding is circumferential: perpendicular to n and to e_rad
        u = np.asarray(res.sliding_velocity[i])
        assert abs(u @ np.asarray(n[i])) < 1e-12 * speed
        assert abs(u @ np.asarray(e_rad[i])) < 1e-12 * speed
    assert n_arc > 20 and n_corner > 20  # both branches exercised (120 mm x 2 deg: corner)


def test_large_end_radius_converges_to_corner():
    """R_end -> inf: the arc-end result tends to the flat-end (corner) result.

    At the reference layback the contact leaves the arc once R_end sin(theta_f) > rho_lim
    (R_end > 121 mm), and from there the result is the corner's exactly (the cap is not
    touched), e.g. for 1e3, 1e4, 1e6 m and the paper's 1e10 mm. With the flange almost square
    to the axis (theta_f = 1e-4 rad) the contact stays on the arc up to R_end = 33.7 m and the
    geometric difference shrinks monotonically to zero as R_end grows through it."""
    keys = (
        "interference",
        "normal_force",
        "peak_pressure",
        "sliding_speed",
        "pv",
        "contact_radius",
        "contact_height",
        "on_arc",
    )

    def case(theta, target):
        b = with_design(_bearing(), layback_angle=theta)
        flat = b.with_flat_ends()
        st = _rolling_state(b, 0.3, 1.0)
        d0 = float(_contact(flat, 1.0, 1.0, st).interference)
        st = _rolling_state(b, 0.3, 1.0, axial=(target - d0) / math.cos(theta))
        return b, st, _contact(flat, 1.0, 1.0, st)

    b, st, ref = case(math.radians(1.6), 4e-6)
    assert float(ref.normal_force) > 1.0
    for r_end in (0.2, 1e3, 1e4, 1e6, 1e7):
        r = _contact(with_design(b, end_radius=r_end), 1.0, 1.0, st)
        for k in keys + ("contact_point", "force_on_roller", "ellipse_semi_axes"):
            np.testing.assert_allclose(getattr(r, k), getattr(ref, k), rtol=1e-13, atol=1e-16)

    b, st, ref = case(1e-4, 1e-6)
    errs = []
    for r_end in (0.5, 2.0, 8.0, 20.0, 30.0, 33.0, 1e3, 1e4, 1e6):
        r = _contact(with_design(b, end_radius=r_end), 1.0, 1.0, st)
        errs.append(
            max(
                abs(float(r.interference - ref.interference)),
                abs(float(r.contact_radius - ref.contact_radius)),
                float(jnp.max(jnp.abs(r.contact_point - ref.contact_point))),
            )
        )
        if r_end >= 1e3:
            for k in keys:
                np.testing.assert_allclose(getattr(r, k), getattr(ref, k), rtol=1e-13)
    assert all(e2 < e1 for e1, e2 in zip(errs[:6], errs[1:6])), errs
    assert errs[0] > 1e-3 and errs[5] < 1e-4 and max(errs[6:]) < 1e-15


# -- skewed roller: hand geometry of the sphere and the torus -------------------------------


@pytest.mark.parametrize("ring_sign", [1.0, -1.0])
@pytest.mark.parametrize("side", [-1.0, 1.0])
@pytest.mark.parametrize("skew", [-0.01, 0.004, 0.02])
def test_skewed_roller_contact_point(skew, side, ring_sign):
    b = _bearing()
    azimuth = 0.7
    e_rad = np.array([0.0, math.sin(azimuth), math.cos(azimuth)])
    tang = np.cross(e_rad, X)  # rotation about e_rad takes X towards e_rad x X
    e = math.cos(skew) * X + math.sin(skew) * tang
    st = _rolling_state(b, azimuth, ring_sign, axis=e)
    radius, p = float(st[0]), np.asarray(st[1])
    theta = float(b.flange.layback_angle)
    n = side * math.cos(theta) * X - ring_sign * math.sin(theta) * e_rad
    p0 = side * float(b.raceway_width) / 2 * X + radius * e_rad
    ro = b.roller
    x_cor, r_ce, r_cor = (
        float(ro.corner_centre_offset),
        float(ro.corner_centre_radius),
        float(ro.corner_radius),
    )

    # arc end: sphere centre on the axis at s L_beb, contact point O + R_end n
    r_end = float(ro.end_radius)
    l_beb = x_cor - math.sqrt((r_end - r_cor) ** 2 - r_ce**2)
    centre = p + side * l_beb * e
    c_sphere = centre + r_end * n
    res = _contact(b, side, ring_sign, st)
    np.testing.assert_allclose(res.contact_point, c_sphere, rtol=0, atol=1e-13)
    np.testing.assert_allclose(res.interference, r_end - (p0 - centre) @ n, rtol=0, atol=1e-13)
    # the skew moves the contact tangentially by s L_beb sin(skew) (L_beb < 0: far behind)
    t_shift = (c_sphere - p) @ tang
    np.testing.assert_allclose(t_shift, float(res.contact_point @ tang - p @ tang), atol=1e-13)
    assert abs(t_shift) > 0.5 * abs(l_beb * skew)
    assert np.sign(t_shift) == np.sign(side * l_beb * skew)

    # corner: extreme point of the corner centre circle, then out by R_cor along n
    flat = b.with_flat_ends()
    res = _contact(flat, side, ring_sign, st)
    x_end = side * e
    n_perp = n - (n @ x_end) * x_end
    q = p + x_cor * x_end + r_ce * n_perp / np.linalg.norm(n_perp)
    c_torus = q + r_cor * n
    np.testing.assert_allclose(res.contact_point, c_torus, rtol=0, atol=1e-13)
    np.testing.assert_allclose(res.interference, (q - p0) @ n + r_cor, rtol=0, atol=1e-13)
    # it moved around the corner circle: same circle (distance R_ce from the axis point),
    # angle from the raceway side -g e_rad (projected) given by the tangential component
    rel = q - (p + x_cor * x_end)
    np.testing.assert_allclose(np.linalg.norm(rel), r_ce, rtol=1e-12)
    angle = math.atan2(rel @ tang, rel @ (-ring_sign * e_rad))
    assert abs(angle) > 0.1 * abs(skew) and abs(angle) < 2 * abs(skew) / math.tan(theta)
    np.testing.assert_allclose(
        res.contact_radius, np.linalg.norm(c_torus - p - ((c_torus - p) @ x_end) * x_end), rtol=1e-12
    )
    np.testing.assert_allclose(
        np.linalg.norm(np.asarray(res.end_face_position)), float(res.contact_radius), rtol=1e-12
    )


# -- Hertz: sphere on plane ----------------------------------------------------------------


def test_sphere_on_plane_force_and_pressure():
    """Arc-end contact = sphere (R_end) on a plane: Q = (4/3) E* sqrt(R) delta^1.5, E* = E'/2,
    p_max = (6 Q E*^2 / (pi^3 R^2))^(1/3), contact radius a = sqrt(R delta) (Johnson, Contact
    Mechanics, sec. 4.2). The point-contact law is the exact Hertz solution, so the closed form
    holds to rounding (the rolling roller does not approach the flange: no damping term)."""
    b = _bearing()
    st0 = _rolling_state(b, 0.0, 1.0)
    d0 = float(_contact(b, 1.0, 1.0, st0).interference)
    theta = float(b.flange.layback_angle)
    r_end = float(b.roller.end_radius)
    e_star = float(effective_modulus(203e9, 0.28, 203e9, 0.28)) / 2
    for target in (1e-6, 5e-6, 2e-5):
        st = _rolling_state(b, 0.0, 1.0, axial=(target - d0) / math.cos(theta))
        res = _contact(b, 1.0, 1.0, st)
        delta = float(res.interference)
        np.testing.assert_allclose(delta, target, rtol=1e-9)
        np.testing.assert_allclose(float(res.approach_rate), 0.0, atol=1e-9)
        q = float(res.normal_force)
        np.testing.assert_allclose(q, 4 / 3 * e_star * math.sqrt(r_end) * delta**1.5, rtol=1e-9)
        p_exact = (6 * q * e_star**2 / (math.pi**3 * r_end**2)) ** (1 / 3)
        np.testing.assert_allclose(float(res.peak_pressure), p_exact, rtol=1e-9)
        np.testing.assert_allclose(np.asarray(res.ellipse_semi_axes), math.sqrt(r_end * delta), rtol=1e-6)
        a_x, a_y = (float(x) for x in res.ellipse_semi_axes)
        np.testing.assert_allclose(a_x, a_y, rtol=1e-6)  # a circle
        a_exact = (3 * q * r_end / (4 * e_star)) ** (1 / 3)
        np.testing.assert_allclose(a_x, a_exact, rtol=1e-9)
        np.testing.assert_allclose(res.pv, float(res.peak_pressure) * float(res.sliding_speed), rtol=1e-12)


def test_corner_ellipse_is_long_along_the_parallel():
    b = _bearing().with_flat_ends()
    st0 = _rolling_state(b, 0.0, 1.0)
    d0 = float(_contact(b, 1.0, 1.0, st0).interference)
    theta = float(b.flange.layback_angle)
    st = _rolling_state(b, 0.0, 1.0, axial=(2e-6 - d0) / math.cos(theta))
    res = _contact(b, 1.0, 1.0, st)
    a_t, a_par = (float(x) for x in res.ellipse_semi_axes)
    assert a_par > 5 * a_t > 0
    assert float(res.peak_pressure) > 1e9  # GPa-level corner pressure


# -- forces, moments, friction -------------------------------------------------------------


def test_forces_moments_and_friction():
    b = _bearing(clearance=20e-6)
    e = np.array([1.0, 0.003, -0.002])
    e = e / np.linalg.norm(e)
    st = list(_rolling_state(b, 1.1, -1.0, axial=-85e-6, axis=e))
    st[3] = st[3] + jnp.array([0.1, -0.3, 0.2])  # extra roller velocity
    st[5] = jnp.array([1e-5, 2e-6, -3e-6])  # displaced ring centre
    res = _contact(b, -1.0, -1.0, st)
    q = float(res.normal_force)
    assert q > 1.0
    theta = float(b.flange.layback_angle)
    e_rad = np.asarray(st[1] - st[5]) * [0, 1, 1]
    e_rad /= np.linalg.norm(e_rad)
    n = -math.cos(theta) * X + math.sin(theta) * e_rad
    f = np.asarray(res.force_on_roller)
    np.testing.assert_allclose(f @ n, -q, rtol=1e-12)
    f_t = f + q * n
    u = np.asarray(res.sliding_velocity)
    speed = np.linalg.norm(u)
    np.testing.assert_allclose(float(res.sliding_speed), speed, rtol=1e-12)
    np.testing.assert_allclose(f_t, -0.08 * q * u / math.sqrt(speed**2 + 1e-6), rtol=1e-12, atol=1e-12 * q)
    np.testing.assert_allclose(res.force_on_ring, -f, rtol=1e-15)
    c = np.asarray(res.contact_point)
    np.testing.assert_allclose(
        res.moment_on_roller, np.cross(c - np.asarray(st[1]), f), rtol=1e-12, atol=1e-15
    )
    np.testing.assert_allclose(
        res.moment_on_ring, np.cross(c - np.asarray(st[5]), -f), rtol=1e-12, atol=1e-15
    )
    # the sliding velocity from rigid-body kinematics, tangential part
    v_b = np.asarray(st[3]) + np.cross(np.asarray(st[4]), c - np.asarray(st[1]))
    v_r = np.asarray(st[6]) + np.cross(np.asarray(st[7]), c - np.asarray(st[5]))
    u_ref = (v_b - v_r) - ((v_b - v_r) @ n) * n
    np.testing.assert_allclose(u, u_ref, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(res.pv, float(res.peak_pressure) * speed, rtol=1e-12)


def test_all_flange_contacts_matches_single_calls():
    b = _bearing(clearance=20e-6)
    z = 5
    rng = np.random.default_rng(0)
    az = np.linspace(0, 2 * np.pi, z, endpoint=False)
    e_rad = np.stack([np.zeros(z), np.sin(az), np.cos(az)], 1)
    p = float(b.pitch_diameter) / 2 * e_rad + rng.normal(0, 30e-6, (z, 3))
    e = np.array([1.0, 0, 0]) + rng.normal(0, 3e-3, (z, 3))
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    v = rng.normal(0, 1, (z, 3))
    w = rng.normal(0, 100, (z, 3))
    ring = dict(
        c_i=rng.normal(0, 1e-5, 3),
        v_i=rng.normal(0, 0.01, 3),
        w_i=OMEGA_I * X,
        c_o=np.zeros(3),
        v_o=np.zeros(3),
        w_o=np.zeros(3),
    )
    out = jax.jit(all_flange_contacts)(b, p, e, v, w, *ring.values())
    assert isinstance(out, FlangeContact)
    assert out.normal_force.shape == (z, 4) and out.contact_point.shape == (z, 4, 3)
    assert out.end_face_position.shape == (z, 4, 2)
    for j, (g, s) in enumerate(FLANGE_ORDER):
        inner = g > 0
        rad = b.inner_raceway_radius if inner else b.outer_raceway_radius
        c, vr, wr = (
            (ring["c_i"], ring["v_i"], ring["w_i"]) if inner else (ring["c_o"], ring["v_o"], ring["w_o"])
        )
        for i in (0, 3):
            one = roller_flange_contact(b, rad, s, g, p[i], e[i], v[i], w[i], c, vr, wr)
            for leaf_all, leaf_one in zip(jax.tree_util.tree_leaves(out), jax.tree_util.tree_leaves(one)):
                np.testing.assert_allclose(leaf_all[i, j], leaf_one, rtol=1e-12, atol=1e-18)
    assert FLANGE_ORDER == ((1.0, -1.0), (1.0, 1.0), (-1.0, -1.0), (-1.0, 1.0))


# -- continuity across the limited circle ----------------------------------------------------


def test_force_and_gradient_continuous_across_limited_circle():
    """Sweep the layback angle so the contact crosses the limited circle (on_arc 0 -> 1) with
    the roller pressed into the flange: Q(theta) and dQ/dtheta obey the mean-value bounds
    |Q(t+h) - Q(t)| <= h max|Q'| and |Q'(t+h) - Q'(t)| <= h max|Q''| between neighbours
    (a jump would break them by orders of magnitude at this spacing)."""
    b = _bearing()
    r_end = float(b.roller.end_radius)
    r_ce, r_cor = float(b.roller.corner_centre_radius), float(b.roller.corner_radius)
    a_lim = math.asin(r_ce / (r_end - r_cor))
    st0 = _rolling_state(b, 0.0, 1.0)
    b_lim = with_design(b, layback_angle=a_lim)
    d0 = float(_contact(b_lim, 1.0, 1.0, st0).interference)
    st = _rolling_state(b, 0.0, 1.0, axial=(3e-6 - d0) / math.cos(a_lim))

    def q(theta):
        return _contact(with_design(b, layback_angle=theta), 1.0, 1.0, st).normal_force

    dq = jax.grad(q)
    d2q = jax.grad(dq)
    band = LIMITED_CIRCLE_BAND / (r_end * math.cos(a_lim))  # the band in angle
    thetas = jnp.asarray(a_lim + np.linspace(-1.5 * band, 2.5 * band, 1201))
    h = float(thetas[1] - thetas[0])
    f = jax.jit(
        jax.vmap(
            lambda t: (q(t), dq(t), d2q(t), _contact(with_design(b, layback_angle=t), 1.0, 1.0, st).on_arc)
        )
    )
    qs, dqs, d2qs, w = (np.asarray(x) for x in f(thetas))
    assert w[0] == 1.0 and w[-1] == 0.0 and np.any((w > 0.05) & (w < 0.95))
    assert np.all(np.isfinite(qs)) and np.all(np.isfinite(dqs)) and np.all(np.isfinite(d2qs))
    assert qs.min() > 1.0 and qs.max() > 2 * qs.min()  # the stiffness really changes
    assert np.max(np.abs(np.diff(qs))) <= 1.05 * h * np.max(np.abs(dqs))
    assert np.max(np.abs(np.diff(dqs))) <= 1.05 * h * np.max(np.abs(d2qs))
    # the bound has teeth: the change across the band is many neighbour bounds
    assert (qs.max() - qs.min()) > 20 * h * np.max(np.abs(dqs))


# -- gradients against finite differences ---------------------------------------------------


def _design_pose():
    """Skewed roller on the inner raceway pressed ~10 um into the +X flange, pure rolling."""
    b = _bearing(clearance=20e-6)
    skew = 2e-3
    e_rad = np.array([0.0, math.sin(0.4), math.cos(0.4)])
    e = math.cos(skew) * X + math.sin(skew) * np.cross(e_rad, X)
    st = _rolling_state(b, 0.4, 1.0, axis=e)
    d0 = float(_contact(b, 1.0, 1.0, st).interference)
    theta = float(b.flange.layback_angle)
    return b, _rolling_state(b, 0.4, 1.0, axis=e, axial=(10e-6 - d0) / math.cos(theta))


@pytest.mark.parametrize("end", ["arc", "corner"])
def test_design_gradients_match_finite_differences(end):
    b, st = _design_pose()
    if end == "corner":
        b = b.with_flat_ends()
    x0 = np.array(
        [
            float(b.roller.end_radius) if end == "arc" else 80e-3,
            float(b.flange.layback_angle),
            float(b.flange.axial_clearance),
        ]
    )

    def outputs(x):
        bb = with_design(
            b, end_radius=x[0] if end == "arc" else None, layback_angle=x[1], axial_clearance=x[2]
        )
        r = _contact(bb, 1.0, 1.0, st)
        return jnp.stack([r.contact_height, r.pv])

    out = jax.jit(outputs)
    jac = np.asarray(jax.jit(jax.jacfwd(outputs))(jnp.asarray(x0)))
    jac_rev = np.asarray(jax.jit(jax.jacrev(outputs))(jnp.asarray(x0)))
    np.testing.assert_allclose(jac, jac_rev, rtol=1e-10, atol=1e-300)
    assert np.all(np.isfinite(jac))
    val = np.asarray(out(jnp.asarray(x0)))
    assert val[1] > 1e8  # loaded and sliding: PV of order GPa m/s
    for k in range(3):
        if end == "corner" and k == 0:
            assert np.all(jac[:, 0] == 0)  # a flat end does not depend on R_end
            continue
        step = 1e-6 * x0[k]
        xp, xm = x0.copy(), x0.copy()
        xp[k] += step
        xm[k] -= step
        fd = (np.asarray(out(jnp.asarray(xp))) - np.asarray(out(jnp.asarray(xm)))) / (2 * step)
        if k == 2:  # the height above the raceway does not depend on the axial clearance
            assert jac[0, k] == 0 and abs(fd[0]) < 1e-12
            np.testing.assert_allclose(jac[1, k], fd[1], rtol=1e-6)
        else:
            np.testing.assert_allclose(jac[:, k], fd, rtol=1e-6)


def test_finite_everywhere():
    """Values and gradients finite at zero interference, far separation, zero sliding, and a
    flat end square-on to the flange (alpha = 0)."""
    b = _bearing()
    st0 = _rolling_state(b, 0.0, 1.0)

    def total(bb, p, e, v, w):
        r = roller_flange_contact(
            bb, bb.inner_raceway_radius, 1.0, 1.0, p, e, v, w, jnp.zeros(3), jnp.zeros(3), jnp.zeros(3)
        )
        return sum(jnp.sum(x) for x in jax.tree_util.tree_leaves(r))

    grad = jax.jit(jax.grad(total, argnums=(0, 1, 2, 3, 4)))
    value = jax.jit(total)
    d0 = float(_contact(b, 1.0, 1.0, st0).interference)
    theta = float(b.flange.layback_angle)
    zero = jnp.zeros(3)
    for bb, axial, v, w in [
        (b, -d0 / math.cos(theta), zero, zero),  # zero interference, zero sliding
        (b, -1e-3, st0[3], st0[4]),  # far from the flange
        (b, (2e-6 - d0) / math.cos(theta), zero, zero),  # loaded, no sliding
        (with_design(b.with_flat_ends(), layback_angle=0.0), 0.1e-3, zero, zero),
        (with_design(b.with_flat_ends(), layback_angle=0.0), -0.1e-3, st0[3], st0[4]),
    ]:
        p = st0[1] + axial * X
        bb = jax.tree_util.tree_map(lambda x: jnp.asarray(x, jnp.float64), bb)
        val = value(bb, p, st0[2], v, w)
        assert np.isfinite(float(val))
        for leaf in jax.tree_util.tree_leaves(grad(bb, p, st0[2], v, w)):
            assert np.all(np.isfinite(np.asarray(leaf)))
