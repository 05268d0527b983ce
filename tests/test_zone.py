"""Design zone (jaxbearing.design_zone) against the closed forms of docs/model.md 5, its
gradients against the analytic derivatives and finite differences, the Figure 14 maps on the
grid arrays, and the `jaxbearing zone` command (output, PNGs, errors)."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from _figures import assert_png_drawn

import jaxbearing as jb
from jaxbearing import UserInputError
from jaxbearing.cli import main, zone_maps
from jaxbearing.flange import design_zone, design_zone_grid, with_design

REF = jb.reference_bearing()
D, R_COR = 7.5e-3, 0.4e-3
R_CE = D / 2 - R_COR


def _closed_form(r_end, theta, clearance, load, e_prime):
    rho_lim = R_CE * r_end / (r_end - R_COR)
    rho = r_end * math.sin(theta)
    e = r_end - R_COR - math.sqrt((r_end - R_COR) ** 2 - R_CE**2)
    h_c = D / 2 - rho
    # Hertz sphere on plane (Johnson 4.2): a = (3 Q R / (4 E*)), E* = E'/2
    a = (3 * load * r_end / (2 * e_prime)) ** (1 / 3)
    return dict(
        rho=rho,
        rho_lim=rho_lim,
        e=e,
        h_c=h_c,
        a=a,
        lam=clearance - 2 * e * math.cos(theta),
        gap=(clearance - 2 * e) * math.cos(theta) + D * math.sin(theta) - 2 * r_end * (1 - math.cos(theta)),
        corner=R_CE + R_COR * math.sin(theta),
    )


@pytest.mark.parametrize(
    "r_end_mm,theta_deg,clear_mm", [(80, 1.6, 0.15), (60, 1.0, 0.2), (120, 1.5, 0.1), (100, 1.8, 0.3)]
)
def test_zone_matches_closed_forms(r_end_mm, theta_deg, clear_mm):
    r_end, theta, clear = r_end_mm * 1e-3, math.radians(theta_deg), clear_mm * 1e-3
    b = with_design(REF, r_end, theta, clear)
    z = design_zone(b, flange_load=50.0)
    e_prime = 203e9 / (1 - 0.28**2)
    ref = _closed_form(r_end, theta, clear, 50.0, e_prime)
    assert ref["rho"] < ref["rho_lim"] and float(z.on_arc) == 1.0
    np.testing.assert_allclose(z.contact_radius, ref["rho"], rtol=1e-12)
    np.testing.assert_allclose(z.corner_contact_radius, ref["corner"], rtol=1e-12)
    np.testing.assert_allclose(z.contact_height, ref["h_c"], rtol=1e-12)
    np.testing.assert_allclose(z.limited_circle_radius, ref["rho_lim"], rtol=1e-12)
    np.testing.assert_allclose(z.arc_protrusion, ref["e"], rtol=1e-9)
    np.testing.assert_allclose(z.actual_axial_clearance, ref["lam"], rtol=1e-9, atol=1e-16)
    np.testing.assert_allclose(z.seated_gap, ref["gap"], rtol=1e-9)
    # exact Hertz: the sphere-on-plane contact circle (3 Q R / (4 E*))^(1/3)
    np.testing.assert_allclose(z.ellipse_half_width, ref["a"], rtol=1e-9)
    fl = REF.flange
    np.testing.assert_allclose(
        z.relief_margin,
        float(z.contact_height) - float(z.ellipse_half_width) - float(fl.relief_height),
        rtol=1e-12,
    )
    np.testing.assert_allclose(z.height_margin, float(fl.contact_height_limit) - ref["h_c"], rtol=1e-9)
    np.testing.assert_allclose(z.limited_circle_margin, ref["rho_lim"] - ref["rho"], rtol=1e-9)
    np.testing.assert_allclose(z.clearance_margin, ref["lam"], rtol=1e-9, atol=1e-16)
    margins = [z.relief_margin, z.height_margin, z.limited_circle_margin, z.clearance_margin]
    assert bool(z.feasible) == all(float(m) > 0 for m in margins)


def test_reference_design_is_feasible_and_flat_end_is_not():
    z = design_zone(REF)
    assert bool(z.feasible)
    flat = design_zone(REF.with_flat_ends())
    # a flat end touches on the corner, outside the (degenerate) limited circle rho_lim = R_ce
    assert float(flat.on_arc) == 0.0 and not bool(flat.feasible)
    np.testing.assert_allclose(flat.contact_radius, flat.corner_contact_radius, rtol=1e-15)
    assert float(flat.limited_circle_margin) < 0
    np.testing.assert_allclose(flat.arc_protrusion, 0.0, atol=1e-18)
    np.testing.assert_allclose(flat.actual_axial_clearance, REF.flange.axial_clearance)
    # a required minimum clearance shifts the margin
    z2 = design_zone(REF, min_clearance=1e-5)
    np.testing.assert_allclose(z2.clearance_margin, float(z.clearance_margin) - 1e-5)


def test_contact_on_the_corner_beyond_the_limited_circle():
    theta = math.radians(2.0)
    z = design_zone(with_design(REF, end_radius=120e-3, layback_angle=theta))
    assert float(z.on_arc) == 0.0
    np.testing.assert_allclose(z.contact_radius, R_CE + R_COR * math.sin(theta), rtol=1e-12)
    assert float(z.limited_circle_margin) < 0 and not bool(z.feasible)


def test_zone_gradients():
    """dh_c/dR_end = -sin(theta_f), dh_c/dtheta_f = -R_end cos(theta_f),
    dLambda/dDelta = 1, dLambda/dR_end = -2 cos(theta_f) de/dR_end (central differences)."""
    x0 = jnp.array([80e-3, math.radians(1.6), 0.15e-3])

    def f(x):
        z = design_zone(with_design(REF, x[0], x[1], x[2]), flange_load=100.0)
        return jnp.stack([z.contact_height, z.actual_axial_clearance, z.relief_margin, z.seated_gap])

    jac = np.asarray(jax.jit(jax.jacfwd(f))(x0))
    r_end, theta = float(x0[0]), float(x0[1])
    np.testing.assert_allclose(
        jac[0], [-math.sin(theta), -r_end * math.cos(theta), 0.0], rtol=1e-12, atol=1e-300
    )
    np.testing.assert_allclose(jac[1, 2], 1.0, rtol=1e-12)

    def e_of(r):
        return r - R_COR - math.sqrt((r - R_COR) ** 2 - R_CE**2)

    h = 1e-6
    de = (e_of(r_end + h) - e_of(r_end - h)) / (2 * h)
    np.testing.assert_allclose(jac[1, 0], -2 * math.cos(theta) * de, rtol=1e-6)
    fj = jax.jit(f)
    for k in range(3):
        step = 1e-6 * float(x0[k])
        fd = (np.asarray(fj(x0.at[k].add(step))) - np.asarray(fj(x0.at[k].add(-step)))) / (2 * step)
        np.testing.assert_allclose(jac[:, k], fd, rtol=1e-6, atol=1e-9)


def test_grid_is_vmapped_design_zone():
    r = np.array([60e-3, 80e-3, 130e-3])
    t = np.radians([1.2, 1.6, 2.5])
    g = design_zone_grid(REF, r[:, None], t[None, :], REF.flange.axial_clearance)
    assert g.contact_height.shape == (3, 3) and g.feasible.dtype == bool
    for i in range(3):
        for j in range(3):
            z = design_zone(with_design(REF, r[i], t[j]))
            for a, b in zip(jax.tree_util.tree_leaves(g), jax.tree_util.tree_leaves(z)):
                np.testing.assert_allclose(a[i, j], b, rtol=1e-12)


def test_figure_14_maps_have_a_bounded_feasible_zone():
    (r_mm, t_deg, hz), (_, c_mm, cz) = zone_maps(REF, 100.0, points=61)
    feas = (
        (np.asarray(hz.relief_margin) > 0)
        & (np.asarray(hz.height_margin) > 0)
        & (np.asarray(hz.limited_circle_margin) > 0)
    )
    assert feas.any() and not feas.all()
    bounded = 0
    for j in range(len(r_mm)):  # along theta_f at fixed R_end: one interval, both ends closed
        col = feas[:, j]
        if not col.any():
            continue
        idx = np.flatnonzero(col)
        assert np.all(np.diff(idx) == 1)  # contiguous
        if idx[0] > 0 and idx[-1] < len(t_deg) - 1:
            bounded += 1
            # below: contact too high (upper limit); above: too low (relief / limited circle)
            assert float(hz.height_margin[idx[0] - 1, j]) <= 0
            assert (
                float(hz.relief_margin[idx[-1] + 1, j]) <= 0
                or float(hz.limited_circle_margin[idx[-1] + 1, j]) <= 0
            )
    assert bounded > len(r_mm) // 2
    # the reference design lies inside
    j = np.argmin(np.abs(r_mm - 80.0))
    i = np.argmin(np.abs(t_deg - 1.6))
    assert feas[i, j]
    # smaller R_end or theta_f raises the contact height (paper, Sec. 3.4)
    h = np.asarray(hz.contact_height)
    assert np.all(np.diff(h[:, 10:40], axis=0) < 0) and np.all(np.diff(h[5:15], axis=1) < 0)
    # clearance map: Lambda_bf = 0 splits it; smaller R_end needs more Delta_bf
    ok = np.asarray(cz.clearance_margin) > 0
    assert ok.any() and not ok.all()
    first_ok = [np.flatnonzero(ok[:, j])[0] for j in range(len(r_mm)) if ok[:, j].any()]
    assert len(first_ok) == len(r_mm)
    assert np.all(np.diff(first_ok) <= 0) and first_ok[0] > first_ok[-1]


def test_cli_zone_prints_margins_and_writes_maps(tmp_path, capsys):
    rc = main(["zone", "--map", "--out", str(tmp_path / "maps"), "--flange-load-N", "80"])
    assert rc == 0
    out = capsys.readouterr().out
    for word in (
        "contact height h_c",
        "relief",
        "height",
        "limited circle",
        "clearance",
        "80.0 N",
        "FEASIBLE",
    ):
        assert word in out
    assert out.count(" OK") == 4
    for name in ("zone_height_map.png", "zone_clearance_map.png"):
        assert_png_drawn(tmp_path / "maps" / name)  # a real plot, not an empty canvas


def test_cli_zone_reports_violations():
    lines = __import__("jaxbearing.cli", fromlist=["zone_lines"]).zone_lines
    b = with_design(REF, end_radius=40e-3, layback_angle=math.radians(1.0))
    text = "\n".join(lines(b, design_zone(b), 100.0))
    assert "VIOLATED" in text and "NOT FEASIBLE" in text


def test_bad_input_is_a_clear_error(capsys):
    assert main(["zone", "--flange-load-N", "-5"]) == 2
    err = capsys.readouterr().err
    assert "--flange-load-N" in err and "-5" in err and "> 0" in err
    assert len(err.strip().splitlines()) == 1
    with pytest.raises(UserInputError, match=r"roller.end_radius = 0.003.*D/2"):
        design_zone(with_design(REF, end_radius=3e-3))
    with pytest.raises(UserInputError, match=r"flange.layback_angle"):
        design_zone(with_design(REF, layback_angle=-0.01))
    with pytest.raises(UserInputError, match=r"flange_load = 0"):
        design_zone(REF, flange_load=0.0)
    with pytest.raises(UserInputError, match=r"roller.end_radius"):
        design_zone_grid(REF, np.array([80e-3, 2e-3]), 0.03, 0.15e-3)


def test_cli_zone_reads_a_config(tmp_path, capsys):
    cfg = tmp_path / "design.toml"
    cfg.write_text("[roller]\nend_radius_mm = 100.0\n\n[flange]\nlayback_angle_deg = 1.4\n")
    assert main(["zone", "--config", str(cfg)]) == 0
    out = capsys.readouterr().out
    assert "100.0000 mm" in out and "1.4000 deg" in out
    rho_mm = 100.0 * math.sin(math.radians(1.4))
    assert f"{rho_mm:10.4f} mm  (on the arc)" in out
    bad = tmp_path / "bad.toml"
    bad.write_text("[roller]\nend_radius_mm = 1.0\n")
    assert main(["zone", "--config", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "end_radius_mm" in err and len(err.strip().splitlines()) == 1
