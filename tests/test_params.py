"""Derived masses and inertias against closed forms."""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

import jaxbearing as jb
from jaxbearing.geometry import arc_protrusion, limited_circle_radius, roller_mass_properties


def _roller(**kw):
    base = dict(
        diameter=7.5e-3,
        length=8e-3,
        central_length=4.5e-3,
        crown_drop=4e-6,
        corner_radius=0.4e-3,
        end_radius=jnp.inf,
    )
    base.update(kw)
    return jb.Roller(**base)


def test_sharp_cylinder_matches_closed_form():
    # a flat-end roller with a vanishing corner radius is a plain cylinder
    r = _roller(corner_radius=1e-12)
    m, i_ax, i_tr = roller_mass_properties(r, 7830.0)
    rad, length = 3.75e-3, 8e-3
    m_ref = 7830.0 * math.pi * rad**2 * length
    np.testing.assert_allclose(m, m_ref, rtol=1e-9)
    np.testing.assert_allclose(i_ax, m_ref * rad**2 / 2, rtol=1e-9)
    np.testing.assert_allclose(i_tr, m_ref * (rad**2 / 4 + length**2 / 12), rtol=1e-9)


def test_corner_rounding_removes_pappus_volume():
    # each rounded corner removes (R_cor^2 - pi R_cor^2/4) * 2 pi * (radius of that area's centroid)
    rc, rad, length = 0.4e-3, 3.75e-3, 8e-3
    m, _, _ = roller_mass_properties(_roller(corner_radius=rc), 1.0)
    area = rc**2 * (1 - math.pi / 4)
    # centroid of the region between a square's corner and the quarter circle, from the corner
    c = rc * (1 - (2 / 3) / (4 - math.pi))
    removed = 2 * area * 2 * math.pi * (rad - c)
    np.testing.assert_allclose(m, math.pi * rad**2 * length - removed, rtol=1e-9)


def test_arc_end_limits():
    flat = _roller()
    arc = _roller(end_radius=80e-3)
    assert float(arc_protrusion(flat)) == 0.0
    np.testing.assert_allclose(limited_circle_radius(flat), 3.35e-3, rtol=1e-15)
    # closed form of the paper's Eq. 19/24
    r_ce, r_cor, r_end = 3.35e-3, 0.4e-3, 80e-3
    e_ref = r_end - r_cor - math.sqrt((r_end - r_cor) ** 2 - r_ce**2)
    np.testing.assert_allclose(arc_protrusion(arc), e_ref, rtol=1e-9)
    np.testing.assert_allclose(limited_circle_radius(arc), r_ce * r_end / (r_end - r_cor), rtol=1e-14)
    # arc-end roller is heavier than flat by about the two caps' volume
    m_flat = roller_mass_properties(flat, 1.0)[0]
    m_arc = roller_mass_properties(arc, 1.0)[0]
    rho = limited_circle_radius(arc)
    h = e_ref  # cap height above the flat plane over the limited circle ~ e - sag(rho_lim)
    assert m_arc > m_flat
    assert float(m_arc - m_flat) < 2 * math.pi * float(rho) ** 2 * h


def test_masses_differentiable():
    b = jb.reference_bearing()
    g = jax.grad(
        lambda rr: roller_mass_properties(eqx.tree_at(lambda r: r.end_radius, b.roller, rr), 7830.0)[0]
    )(jnp.asarray(80e-3))
    assert jnp.isfinite(g) and g < 0  # larger end radius, flatter caps, less mass


def test_reference_bearing_summary():
    b = jb.reference_bearing()
    op = jb.reference_operating_point()
    assert b.num_rollers == 26 and b.num_slices == 31
    np.testing.assert_allclose(
        jb.rad_s_to_rpm(jb.kinematic_cage_speed(b, op)), 20000 * (1 - 7.5 / 85) / 2, rtol=1e-12
    )
    assert 0.05 < float(b.cage_mass) < 0.15
    assert b.roller_inertia.shape == (2,)


def test_cli_demo_prints_summary(capsys):
    from jaxbearing.cli import main

    assert main(["demo", "--summary-only"]) == 0
    out = capsys.readouterr().out
    assert "roller mass" in out and "kinematic cage speed" in out and "9117.6" in out
