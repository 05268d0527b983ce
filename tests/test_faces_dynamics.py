"""General end and rib faces in the dynamics (docs/model.md 5.4): the structural switch that
keeps today's faces on today's code, the general path at today's faces against today's run
(round-off), the kinematic film oracle of a torus end on a concave rib, the profile design
variables (round trip, range errors, a gradient through a short run), and the configuration
keys and `jaxbearing simulate --config` with them."""

from __future__ import annotations

import json
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from test_contact_hertz import exact_hertz
from test_flange_lubrication import _bearing, _contact, _e_prime, _hand_film, _state

import jaxbearing as jb
from jaxbearing._errors import UserInputError
from jaxbearing.cli import main
from jaxbearing.flange import (
    PROFILE_NAMES,
    DesignVariables,
    ProfileVariables,
    check_profile,
    design_zone,
    face_design_zone,
    faces_of,
    flange_geometry,
    plain_faces,
    with_faces,
)
from jaxbearing.io import Config, loads_config
from jaxbearing.run import Perturbation, simulate

X = np.array([1.0, 0.0, 0.0])
#: rollers scattered axially by up to 80 um, beyond the 75 um half clearance: flanges load at once
SCATTER = Perturbation(seed=1, axial=0.08e-3, skew=1e-3)
SHORT = 0.3e-3  # s
SAVES = 4000  # the program of tests/test_dynamics.py's runs (the reference bearing)


# -- the switch -------------------------------------------------------------------------------
def test_todays_faces_carry_no_face_fields():
    """The reference bearing, and a configuration whose face keys are today's faces (e = 0,
    R_rib = inf, any h_t), carry no general-face field (None: a structural switch, so the
    contact traced is today's `flange_geometry`, bit for bit); any other value gives a bearing
    with general faces, which `flange_geometry` refuses and `design_zone` hands to
    `face_design_zone`."""
    reference = jb.reference_bearing()
    today = Config({"flange": {"rib_tangent_height_mm": 1.0}}).bearing()
    for b in (reference, today):
        assert not b.has_general_faces
        assert b.roller.end_offset is None and b.flange.rib_curvature is None
    torus = Config({"roller": {"end_offset_mm": 0.5}}).bearing()
    assert torus.has_general_faces and float(torus.roller.end_offset) == 0.5e-3
    assert float(torus.flange.rib_curvature) == 0.0
    with pytest.raises(ValueError, match="general faces"):
        flange_geometry(torus, 0.04, 1.0, 1.0, jnp.zeros(3), X, jnp.zeros(3))
    zone = design_zone(torus)
    np.testing.assert_allclose(
        zone.contact_height, face_design_zone(torus, faces_of(torus)).contact_height, rtol=0
    )
    assert zone.limited_circle_radius == pytest.approx(float(jb.geometry.limited_circle_radius(torus.roller)))


def test_plain_faces_drops_todays_general_faces_only_where_concrete():
    """`plain_faces`: a bearing given today's faces as general ones (e = 0, kappa_rib = 0, any
    h_t: what a profile design at the reference applies) loses the three fields and so runs
    today's contact code (the oracle below: the same numbers to round-off); every other field is
    kept. A torus end, a curved rib, or traced values (a bearing differentiated in e) keep their
    general faces."""
    reference = jb.reference_bearing()
    assert plain_faces(reference) is reference
    general = ProfileVariables.of(reference).apply(reference)
    general = with_faces(general, 0.0, 0.0, 1.2e-3)
    assert general.has_general_faces
    plain = plain_faces(general)
    assert not plain.has_general_faces
    for a, b in zip(jax.tree_util.tree_leaves(plain), jax.tree_util.tree_leaves(reference)):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))
    for kept in (with_faces(reference, 1e-6, 0.0), with_faces(reference, 0.0, 0.5)):
        assert plain_faces(kept) is kept
    seen = []

    def traced(e):
        seen.append(plain_faces(with_faces(reference, e, 0.0)).has_general_faces)
        return e

    jax.jit(traced)(0.0)
    assert seen == [True]


def test_general_path_at_todays_faces_reproduces_a_short_run():
    """Oracle: the reference bearing forced through the general contact (`with_faces`: e = 0,
    kappa_rib = 0 as arrays) runs 0.3 ms with loaded flanges and gives today's histories to
    round-off. Tolerance: one contact evaluation agrees to a few 1e-17 m in the interference
    (face_contact adds R_end = 80 mm to a distance near -R_end) and 1e-12 relative in the
    forces (tests/test_faces.py); the adaptive integration carries that through 0.3 ms,
    measured at most 3e-9 of each history's largest value (film and pressure; 5e-10 in the
    flange force), asserted at 1e-6. The step sequence is the same."""
    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    old = simulate(bearing, op, duration=SHORT, num_saves=SAVES, perturbation=SCATTER)
    new = simulate(with_faces(bearing), op, duration=SHORT, num_saves=SAVES, perturbation=SCATTER)
    assert old.status == new.status == "ok"
    assert float(np.nanmax(old.histories["flange_force"])) > 1.0
    for name, value in old.histories.items():
        a, b = np.asarray(value, dtype=float), np.asarray(new.histories[name], dtype=float)
        scale = float(np.nanmax(np.abs(a))) if a.size else 0.0
        np.testing.assert_allclose(b, a, rtol=0, atol=1e-6 * scale + 1e-300, err_msg=name)


# -- the kinematic film oracle, extended to a torus end on a concave rib ------------------------
def _closed_form(b, side, ring_sign, p):
    """Contact of the aligned roller centred at p in the meridian plane of its azimuth (axial x,
    radius r about the ring axis): the end ball of radius R about Q = (x_p + s a_c, r_p - g e)
    against the rib circle of radius R_rib about K = P_t - R_rib n0 (tests/test_faces.py's
    torus-on-torus closed form, for either side and ring): n = (Q - K)/|Q - K|, C = Q + R n,
    delta = R + |Q - K| - R_rib; h_c = g (C_r - R_r), sin(alpha) = |n_r|, rho_c = e + R sin(alpha).
    Returns (delta, h_c, sin(alpha), rho_c)."""
    d, length = float(b.roller.diameter), float(b.roller.length)
    r, r_cor, e = float(b.roller.end_radius), float(b.roller.corner_radius), float(b.roller.end_offset)
    r_rib, h_t = 1 / float(b.flange.rib_curvature), float(b.flange.rib_tangent_height)
    th = float(b.flange.layback_angle)
    r_ring = float(b.inner_raceway_radius if ring_sign > 0 else b.outer_raceway_radius)
    x_p, r_p = float(p[0]), float(np.hypot(p[1], p[2]))
    r_prime, r_ce = r - r_cor, d / 2 - r_cor
    e_p = r_prime - math.sqrt(r_prime**2 - (r_ce - e) ** 2)
    q = np.array([x_p + side * (length / 2 + e_p - r), r_p - ring_sign * e])
    n0 = np.array([side * math.cos(th), -ring_sign * math.sin(th)])
    t0 = np.array([side * math.sin(th), ring_sign * math.cos(th)])
    width = length + float(b.flange.axial_clearance)
    k = np.array([side * width / 2, r_ring]) + h_t / math.cos(th) * t0 - r_rib * n0
    dist = float(np.linalg.norm(q - k))
    n = (q - k) / dist
    c = q + r * n
    return r + dist - r_rib, ring_sign * (c[1] - r_ring), abs(n[1]), e + r * abs(n[1])


@pytest.mark.parametrize(("side", "ring_sign"), [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0)])
def test_torus_on_concave_rib_film_is_the_kinematic_closed_form(side, ring_sign):
    """Aligned roller in pure rolling, a torus end (e = 0.5 mm) on a concave rib (R_rib = 120 mm
    tangent at h_t = 1.0 mm, near the contact), loaded 2 um, through `roller_flange_contact`: the interference and
    the contact height are the closed form (`_closed_form`); the entrainment speed is the hand
    kinematics at that height, u_e = |w_r - w_c| (R_r + g h_c (D - 2 g R_r) / (2 D)); the film
    radii are R_x = rho_c / sin(alpha) along the circumferential entrainment (the end's parallel,
    Meusnier; the rib's straight generator adds nothing) and R_y = 1 / (1/R_end - 1/R_rib) up the
    flange (the concave rib subtracts its curvature), the ellipticity k = a_y / a_x from the
    independent scipy Hertz oracle; h_min, h_c and Lambda by hand."""
    b = with_faces(_bearing("mixed"), 0.5e-3, 1 / 0.120, 1.0e-3)
    st, (e_rad, w_ring, w_c) = _state(b, ring_sign)
    d0 = float(_contact(b, side, ring_sign, st).interference)
    shift = side * (2e-6 - d0) / math.cos(float(b.flange.layback_angle))
    st, _ = _state(b, ring_sign, axial=shift)
    res = _contact(b, side, ring_sign, st)
    delta, h, sin_a, rho = _closed_form(b, side, ring_sign, np.asarray(st[1]))
    np.testing.assert_allclose(float(res.interference), delta, rtol=1e-9)
    assert 1.5e-6 < delta < 2.5e-6 and float(res.on_arc) == 1.0
    np.testing.assert_allclose(float(res.contact_height), h, rtol=0, atol=1e-15)
    np.testing.assert_allclose(float(res.contact_radius), rho, rtol=1e-11)
    q = float(res.normal_force)
    assert q > 10.0
    d = float(b.roller.diameter)
    r_r = float(b.inner_raceway_radius if ring_sign > 0 else b.outer_raceway_radius)
    u_e = abs(w_ring - w_c) * (r_r + ring_sign * h * (d - 2 * ring_sign * r_r) / (2 * d))
    np.testing.assert_allclose(float(res.entrainment_speed), u_e, rtol=1e-9)
    rx = rho / sin_a
    ry = 1 / (1 / float(b.roller.end_radius) - float(b.flange.rib_curvature))
    assert ry > rx  # the conforming rib stretches the contact up the flange
    e_prime = _e_prime(b)
    k = exact_hertz(q, ry, rx, e_prime)["k"]  # a_y / a_x > 1
    eta = 0.055  # at T_in = T_0 = 80 C
    h_min, h_c = _hand_film(q, rx, k, u_e, eta, 1.85e-8, e_prime)
    np.testing.assert_allclose(float(res.min_film), h_min, rtol=1e-8)
    np.testing.assert_allclose(float(res.central_film), h_c, rtol=1e-8)
    np.testing.assert_allclose(float(res.film_parameter), h_min / 0.2e-6, rtol=1e-8)


# -- the dynamics' Newton starts and the toroidal end's mass ------------------------------------
def test_dynamic_start_count_finds_the_same_contact():
    """The dynamics' `DYNAMIC_START_ANGLES` = 4 Newton starts give the contact of 16 starts
    (`START_ANGLES`, the static functions') over 400 sampled faces and poses (e in [0, 0.9 R_ce],
    kappa_rib in [0, 0.95 kappa_end], h_t in [0, H_rf], tilt and skew up to 40 mrad, 20 um
    axial offsets, all four flanges; the corner carries most of them): the interference to
    1e-16 m and the contact point to 1e-15 m (benchmarks/studies/study_face_newton.py
    --tilt-mrad 40: 4 starts within 2.8e-17 m and 1.8e-16 m of 16 starts with 8 + 8 steps over
    20,000 samples)."""
    from jaxbearing.flange import Faces, face_contact
    from jaxbearing.flange._face_contact import START_ANGLES
    from jaxbearing.flange._face_geometry import DYNAMIC_START_ANGLES

    b = jb.reference_bearing()
    rng = np.random.default_rng(7)
    n = 400
    r_ce = float(b.roller.diameter) / 2 - float(b.roller.corner_radius)
    base = faces_of(b)
    e, k, h = rng.uniform(0, 0.9, n) * r_ce, rng.uniform(0, 0.95, n) * 12.5, rng.uniform(0, 2e-3, n)
    tilt, skew, axial = rng.uniform(-0.04, 0.04, n), rng.uniform(-0.04, 0.04, n), rng.uniform(-2e-5, 2e-5, n)
    ring, side = rng.choice([1.0, -1.0], n), rng.choice([1.0, -1.0], n)
    e_rad = np.array([0.0, math.sin(0.3), math.cos(0.3)])
    e_tan = np.cross(X, e_rad)
    p = float(b.pitch_diameter) / 2 * e_rad + axial[:, None] * X
    axis = (
        X * (np.cos(tilt) * np.cos(skew))[:, None]
        + e_rad * np.sin(tilt)[:, None]
        + e_tan * (np.sin(skew) * np.cos(tilt))[:, None]
    )
    radius = np.where(ring > 0, float(b.inner_raceway_radius), float(b.outer_raceway_radius))

    def contacts(starts):
        def one(e_, k_, h_, r_, s_, g_, p_, a_):
            faces = Faces(
                base.end_curvature, e_, base.corner_radius, base.layback_angle, k_, h_,
                base.flange_height, base.axial_clearance,
            )  # fmt: skip
            return face_contact(b, faces, r_, s_, g_, p_, a_, jnp.zeros(3), starts=starts)

        return jax.jit(jax.vmap(one))(e, k, h, radius, side, ring, p, axis)

    few, many = contacts(DYNAMIC_START_ANGLES), contacts(START_ANGLES)
    assert DYNAMIC_START_ANGLES == 4 and float(np.mean(np.asarray(many.on_arc) < 0.5)) > 0.5
    np.testing.assert_allclose(few.interference, many.interference, rtol=0, atol=1e-16)
    np.testing.assert_allclose(few.contact_point, many.contact_point, rtol=0, atol=1e-15)


def test_toroidal_end_mass_is_the_volume_of_its_meridian():
    """The roller's mass with a toroidal end (e = 1 mm) against the volume of revolution of its
    meridian written here (cylinder, corner quarter-circles, and the end arc centred at
    (a_c, e): x(rho) = a_c + sqrt(R_end^2 - (rho - e)^2), a_c = x_cor - sqrt((R_end - R_cor)^2
    - (R_ce - e)^2)), integrated by scipy: to 1e-9 relative; and it is lighter than the sphere
    end's (less protrusion)."""
    from scipy.integrate import quad

    b = jb.reference_bearing()
    torus = with_faces(b, 1e-3)
    d, length = float(b.roller.diameter), float(b.roller.length)
    r, r_cor, e = float(b.roller.end_radius), float(b.roller.corner_radius), 1e-3
    r_ce, x_cor = d / 2 - r_cor, length / 2 - r_cor
    a_c = x_cor - math.sqrt((r - r_cor) ** 2 - (r_ce - e) ** 2)
    rho_lim = e + (r_ce - e) * r / (r - r_cor)

    def half_length(rho):
        if rho <= rho_lim:
            return a_c + math.sqrt(r**2 - (rho - e) ** 2)
        return x_cor + math.sqrt(r_cor**2 - (rho - r_ce) ** 2)

    volume = quad(lambda rho: 2 * math.pi * rho * 2 * half_length(rho), 0, d / 2, points=[e, rho_lim], epsabs=0, epsrel=1e-12, limit=200)[0]  # fmt: skip
    density = float(b.roller_material.density)
    np.testing.assert_allclose(float(torus.roller_mass), density * volume, rtol=1e-9)
    assert float(torus.roller_mass) < float(b.roller_mass)
    assert float(jb.geometry.limited_circle_radius(torus.roller)) == pytest.approx(rho_lim, rel=1e-14)


# -- the profile design variables ---------------------------------------------------------------
def test_profile_variables_round_trip_and_apply():
    """Eight variables in `PROFILE_NAMES` order; `from_array(as_array)` is the identity; `apply`
    sets every one on the bearing (general faces even at e = 0, kappa_rib = 0); `of` reads them
    back; a three-variable design converts (`from_design`) with the bearing's other five, and
    `DesignVariables` keeps its shape (3,)."""
    b = jb.reference_bearing()
    assert len(PROFILE_NAMES) == 8 and DesignVariables.of(b).as_array().shape == (3,)
    p = ProfileVariables(0.09, 0.4e-3, 0.35e-3, 8.0, 1.2e-3, 0.03, 1.9e-3, 0.12e-3)
    np.testing.assert_array_equal(ProfileVariables.from_array(p.as_array()).as_array(), p.as_array())
    applied = p.apply(b)
    assert applied.has_general_faces
    np.testing.assert_array_equal(ProfileVariables.of(applied).as_array(), p.as_array())
    design = DesignVariables(0.1016, math.radians(1.527), 0.14e-3)
    q = ProfileVariables.from_design(design, b)
    np.testing.assert_array_equal(
        q.as_array(), [0.1016, 0.0, 0.4e-3, 0.0, 0.0, math.radians(1.527), 2e-3, 0.14e-3]
    )
    assert ProfileVariables.of(b).apply(b).has_general_faces and not design.apply(b).has_general_faces
    check_profile(b, p)


@pytest.mark.parametrize(
    ("name", "value", "valid"),
    [
        ("end_radius", 3e-3, "in (D/2 = 0.00375, inf) m"),
        ("end_offset", 3.4e-3, "in [0, D/2 - R_cor = 0.00335) m"),
        ("corner_radius", 0.0, "in (0, D/2 = 0.00375) m"),
        ("rib_curvature", 12.5, "in [0, 1/R_end = 12.5) 1/m"),
        ("rib_curvature", -1.0, "in [0, 1/R_end = 12.5) 1/m"),
        ("rib_tangent_height", 2.5e-3, "in [0, H_rf = 0.002] m"),
        ("layback_angle", 1.0, "in [0, 45) deg"),
        ("flange_height", 0.0, "in (0, D = 0.0075) m"),
        ("axial_clearance", 0.0, "> 0 m"),
    ],
)
def test_bad_profile_is_one_line(name, value, valid):
    """`check_profile`: one line naming the variable, its value and the valid range."""
    b = jb.reference_bearing()
    values = dict(zip(PROFILE_NAMES, np.asarray(ProfileVariables.of(b).as_array())))
    values[name] = value
    with pytest.raises(UserInputError) as info:
        check_profile(b, ProfileVariables(**values))
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"profile.{name} = ") and valid in message, message


@pytest.mark.slow
def test_profile_gradient_flows_through_a_short_run():
    """jax.grad of the smooth peak PV of a 0.1 ms run at 11 slices (rollers scattered 100 um
    axially: the flanges load at once, the toroidal end protruding 20 um less than the sphere)
    with respect to the profile at a torus end on a concave rib: finite in all eight variables,
    and nonzero in the end offset, the rib curvature and the end radius (H_rf enters only the
    reported top-edge indicator: its derivative is 0). Slow: compiling the reverse-mode program
    takes 2-4 minutes on the 2-core machine (a forward-mode JVP in one direction as long)."""
    import dataclasses

    b = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    op = jb.reference_operating_point()
    p = ProfileVariables.from_array(
        ProfileVariables.of(b).as_array().at[1].set(0.5e-3).at[3].set(8.0).at[4].set(1.0e-3)
    )

    def peak_pv(profile):
        scatter = Perturbation(seed=1, axial=0.1e-3, skew=1e-3)
        return jb.flange_functionals(profile.apply(b), op, 0.1e-3, perturbation=scatter)[0]

    g = np.asarray(jax.jit(jax.grad(peak_pv))(p).as_array())
    assert np.isfinite(g).all(), g
    for name in ("end_radius", "end_offset", "rib_curvature"):
        assert g[PROFILE_NAMES.index(name)] != 0.0, name


# -- configuration and command line -------------------------------------------------------------
@pytest.mark.parametrize(
    ("text", "field", "fragment"),
    [
        ("[roller]\nend_offset_mm = 3.5\n", "roller.end_offset_mm", "must be in [0, diameter_mm/2"),
        ("[flange]\nrib_radius_mm = 60.0\n", "flange.rib_radius_mm", "must be > end_radius_mm = 80"),
        ("[flange]\nrib_radius_mm = -100.0\n", "flange.rib_radius_mm", "must be in (0, inf] mm"),
        ("[flange]\nrib_tangent_height_mm = 2.5\n", "flange.rib_tangent_height_mm", "[0, height_mm = 2"),
    ],
)
def test_face_keys_out_of_range_are_one_line(text, field, fragment):
    """The face keys' ranges: one line naming the key, the value with its unit and the range."""
    with pytest.raises(jb.ConfigError) as info:
        loads_config(text)
    assert info.value.field == field and "\n" not in str(info.value) and fragment in str(info.value)


def test_face_keys_round_trip_and_reach_the_bearing():
    """`[roller] end_offset_mm`, `[flange] rib_radius_mm` (inf: the cone) and
    `rib_tangent_height_mm` in engineering units become e [m], 1/R_rib [1/m] and h_t [m]; the
    written TOML reads back to the same configuration; `validate_bearing` accepts the bearing."""
    cfg = loads_config(
        "[roller]\nend_offset_mm = 0.5\n[flange]\nrib_radius_mm = 120.0\nrib_tangent_height_mm = 1.5\n"
    )
    b = cfg.bearing()
    assert b.has_general_faces
    np.testing.assert_allclose(
        [b.roller.end_offset, b.flange.rib_curvature, b.flange.rib_tangent_height],
        [0.5e-3, 1 / 0.120, 1.5e-3],
        rtol=1e-15,
    )
    assert loads_config(cfg.to_toml()) == cfg
    assert math.isinf(Config()["flange.rib_radius_mm"])
    jb.validate_bearing(b)
    jb.validate_bearing(b.with_flat_ends())  # a curved rib against a flat end's corner


def test_simulate_command_runs_with_general_faces(tmp_path, capsys):
    """`jaxbearing simulate --config x.toml` with a torus end on a concave rib (its aligned
    contact inside the design zone: no warning): the run is ok and its summary carries the face
    keys' values (the program is the one of the short-run oracle above: no compilation of its
    own in this module)."""
    cfg = tmp_path / "faces.toml"
    cfg.write_text(
        "[roller]\nend_offset_mm = 0.5\n[flange]\nrib_radius_mm = 120.0\nrib_tangent_height_mm = 1.0\n"
        '[simulation]\nduration_ms = 0.3\nend = "arc"\n'
    )
    out = tmp_path / "out"
    assert main(["simulate", "--config", str(cfg), "--transient", "--no-progress", "--out", str(out)]) == 0
    assert "outside the design zone" not in capsys.readouterr().err
    doc = json.loads((out / "summary.json").read_text())
    assert doc["status"] == "ok", doc["status"]
    assert doc["config"]["roller"]["end_offset_mm"] == 0.5
    assert doc["config"]["flange"]["rib_radius_mm"] == 120.0
