"""General roller-end and rib faces (jaxbearing.flange: `Faces`, `face_contact`,
`face_design_zone`; docs/model.md 5.4) against today's contact to round-off (e = 0, R_rib = inf),
closed-form torus-on-cone and torus-on-torus contacts of an aligned roller, central finite
differences in every face parameter, a brute-force maximisation over the end surface with the
Newton solve's stated accuracy over sampled faces and poses, and the one-line range errors."""

from __future__ import annotations

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import jaxbearing as jb
from jaxbearing._errors import UserInputError
from jaxbearing.contact import point_contact_stiffness
from jaxbearing.flange import (
    Faces,
    check_faces,
    design_zone,
    face_contact,
    face_contact_stiffness,
    face_design_zone,
    faces_of,
    flange_effective_modulus,
    flange_geometry,
    rib_distance,
    roller_pose,
)
from jaxbearing.flange._face_contact import NEWTON_ACCURACY

X = np.array([1.0, 0.0, 0.0])
BEARING = jb.reference_bearing()
FIELDS = (
    "end_curvature",
    "end_offset",
    "corner_radius",
    "layback_angle",
    "rib_curvature",
    "rib_tangent_height",
    "flange_height",
    "axial_clearance",
)


def _f64(tree):
    """Every leaf as a strong float64 array (one compiled program for every bearing)."""
    return jax.tree_util.tree_map(lambda x: jnp.asarray(x, jnp.float64), tree)


def _pose(bearing, ring_sign, side, axial=0.0, tilt=0.0, skew=0.0, azimuth=0.3):
    """(R_r, p, e) of `flange.roller_pose` (the side is the contact's, not the pose's)."""
    return roller_pose(bearing, ring_sign, axial, tilt, skew, azimuth)


_face_contact = jax.jit(face_contact)
_zone = jax.jit(face_design_zone)


@jax.jit
def _contacts(bearing, faces, radius, side, ring_sign, p, axis, ring_axis):
    """face_contact and today's flange_geometry over a batch of poses (one compiled program)."""

    def one(r, s, g, pp, e):
        new = face_contact(bearing, faces, r, s, g, pp, e, jnp.zeros(3), ring_axis)
        old = flange_geometry(bearing, r, s, g, pp, e, jnp.zeros(3), ring_axis)
        return new, old

    return jax.vmap(one)(radius, side, ring_sign, p, axis)


POSES = [
    (0.0, 0.0, 0.0),
    (1e-5, 0.0, 0.0),
    (0.0, 3e-3, 0.0),
    (0.0, -3e-3, 0.0),
    (0.0, 0.0, 5e-3),
    (2e-5, -4e-3, 8e-3),
    (0.0, 0.03, 0.0),
    (0.0, 0.0, 0.05),
]


def _batch(bearing):
    rows = [(*_pose(bearing, g, s, *pose), s, g) for g in (1.0, -1.0) for s in (1.0, -1.0) for pose in POSES]
    radius, p, axis, side, sign = (np.array(c) for c in zip(*rows))
    return radius, side, sign, p, axis


# -- (a) e = 0 and R_rib = inf: today's contact to round-off --------------------------------------
@pytest.mark.parametrize(
    ("flat", "ring_tilt"),
    [(False, 0.0), (True, 0.0), (False, 2e-3)],
    ids=["arc-end", "flat-end", "tilted-ring"],
)
def test_today_faces_reproduce_flange_geometry(flat, ring_tilt):
    """At e = 0, kappa_rib = 0 (h_t any) `face_contact` gives `flange_geometry`'s interference,
    contact point, contact height, contact radius, arc weight and Hertz curvature sums (the
    plane adds none) to round-off, at 8 poses (aligned, axial offset, tilt, skew, combined, and
    two large enough to put the contact on the corner) on all four flanges, also with the
    ring's axis tilted by 2 mrad about Y (`ring_axis`, a misaligned ring); and the same
    Hertz stiffness through the model's exact law. Round-off: the arc branch adds R_end = 80 mm
    to a distance near -R_end, so lengths agree to a few 1e-17 m (1e-16 asserted; measured at
    most 1.7e-17 m in the interference, 9e-18 m in the contact point)."""
    bearing = _f64(BEARING.with_flat_ends() if flat else BEARING)
    faces = faces_of(bearing, rib_tangent_height=0.7e-3)
    ring_axis = np.array([math.cos(ring_tilt), 0.0, -math.sin(ring_tilt)])
    new, old = _contacts(bearing, faces, *_batch(bearing), ring_axis)
    np.testing.assert_allclose(new.interference, old.interference, rtol=0, atol=1e-16)
    np.testing.assert_allclose(new.contact_point, old.contact_point, rtol=0, atol=1e-16)
    np.testing.assert_allclose(new.contact_height, old.contact_height, rtol=0, atol=1e-16)
    np.testing.assert_allclose(new.contact_radius, old.contact_radius, rtol=1e-14)
    np.testing.assert_array_equal(new.on_arc, old.on_arc)
    today = np.sort(np.stack([1 / old.radius_meridian, 1 / old.radius_parallel], -1), -1)[:, ::-1]
    # rtol: near-square-on poses (alpha ~ 2 mrad at the 30 mrad tilt) magnify the round-off of
    # sin(alpha), computed from the normal, in the corner's parallel curvature sin(alpha)/rho
    np.testing.assert_allclose(new.curvature_sums, today, rtol=1e-12)
    e_prime = flange_effective_modulus(bearing)
    np.testing.assert_allclose(
        face_contact_stiffness(new, e_prime),
        point_contact_stiffness(old.radius_meridian, old.radius_parallel, e_prime),
        rtol=1e-12,
    )
    assert (np.asarray(new.on_arc) < 0.5).any() and (flat or (np.asarray(new.on_arc) > 0.5).any())


def test_today_faces_reproduce_design_zone():
    """`face_design_zone` at e = 0, kappa_rib = 0 equals `design_zone` field by field (lengths
    to 1e-16 m)."""
    old = design_zone(BEARING)
    new = face_design_zone(BEARING, faces_of(BEARING))
    for name in (
        "contact_radius",
        "corner_contact_radius",
        "contact_height",
        "limited_circle_radius",
        "arc_protrusion",
        "actual_axial_clearance",
        "seated_gap",
        "ellipse_half_width",
        "on_arc",
        "relief_margin",
        "height_margin",
        "limited_circle_margin",
        "clearance_margin",
        "feasible",
    ):
        # atol: lengths to round-off at the 80 mm scale of R_end (the seated gap differs by 2e-17 m)
        np.testing.assert_allclose(
            getattr(new, name), getattr(old, name), rtol=1e-13, atol=1e-16, err_msg=name
        )


# -- (b) closed forms for an aligned roller --------------------------------------------------------
def _aligned(bearing, faces, axial):
    """face_contact of the roller seated on the inner raceway at azimuth 0 (e_rad = Z), axis X,
    offset `axial`, against the +X inner rib; and (x_p, z_p, R_i)."""
    r_i = float(bearing.inner_raceway_radius)
    z_p = r_i + float(bearing.roller.diameter) / 2
    p = np.array([axial, 0.0, z_p])
    return _face_contact(bearing, faces, r_i, 1.0, 1.0, p, X, np.zeros(3)), axial, z_p, r_i


def _end_arc_centre(bearing, faces, x_p, z_p):
    """Q = (x_p + a_c, z_p - e): the end arc's centre on the contact side (towards the raceway),
    with a_c = L/2 + e_p - R, e_p = R' - sqrt(R'^2 - (R_ce - e)^2), R' = R - R_cor: the arc is
    internally tangent to the corner circle (centre (x_cor, R_ce), radius R_cor), so the two
    centres are R' apart, (x_cor - a_c)^2 + (R_ce - e)^2 = R'^2, and the apex a_c + R lies
    e_p beyond the flat end plane L/2 (x_cor = L/2 - R_cor)."""
    d, length = float(bearing.roller.diameter), float(bearing.roller.length)
    r, r_cor, e = 1 / float(faces.end_curvature), float(faces.corner_radius), float(faces.end_offset)
    r_prime, r_ce = r - r_cor, d / 2 - r_cor
    e_p = r_prime - math.sqrt(r_prime**2 - (r_ce - e) ** 2)
    return np.array([x_p + length / 2 + e_p - r, z_p - e]), e_p


def _check(c, delta, point_xz, z_p, r_i, sums):
    np.testing.assert_allclose(c.interference, delta, rtol=1e-9, atol=1e-17)
    np.testing.assert_allclose(np.asarray(c.contact_point)[[0, 2]], point_xz, rtol=0, atol=1e-15)
    assert abs(float(c.contact_point[1])) < 1e-15
    np.testing.assert_allclose(c.contact_height, point_xz[1] - r_i, rtol=0, atol=1e-15)
    np.testing.assert_allclose(c.contact_radius, z_p - point_xz[1], rtol=1e-11)
    np.testing.assert_allclose(c.curvature_sums, np.sort(sums)[::-1], rtol=1e-11)
    assert float(c.on_arc) == 1.0 and float(c.solve_error.max()) < NEWTON_ACCURACY


@pytest.mark.parametrize("offset", [0.0, 0.6e-3, 1.0e-3])
def test_torus_on_cone_closed_form(offset):
    """Torus end (offset e) on today's cone, aligned roller 10 um off centre.

    In the meridian plane (x along the axis, z radial, e_rad = Z) the rib is the line through
    the raceway edge P0 = (W/2, R_i), W = L + Delta_bf, with unit normal into the rib
    n0 = (cos theta, -sin theta). The end near the contact is the ball of radius R about the arc
    centre Q = (x_p + a_c, z_p - e) (`_end_arc_centre`); its depth in the half-space
    (X - P0) . n0 > 0 is delta = R + (Q - P0) . n0 at C = Q + R n0:

        delta = R (1 - cos theta) + cos theta (x_p + e_p - Delta/2) - sin theta (D/2 - e)
        rho_c = z_p - C_z = e + R sin theta,   h_c = C_z - R_i = D/2 - e - R sin theta.

    Curvature sums (the plane adds none): 1/R along the end's meridian, and along its parallel
    circle (radius rho_c about the roller axis, principal normal towards the axis, +Z, at the
    angle 90 deg - theta to the normal n0) sin(theta)/rho_c by Meusnier's theorem."""
    faces = faces_of(BEARING, end_offset=offset)
    c, x_p, z_p, r_i = _aligned(BEARING, faces, 10e-6)
    th, r = float(faces.layback_angle), 1 / float(faces.end_curvature)
    d, clearance = float(BEARING.roller.diameter), float(faces.axial_clearance)
    q, e_p = _end_arc_centre(BEARING, faces, x_p, z_p)
    delta = (
        r * (1 - math.cos(th)) + math.cos(th) * (x_p + e_p - clearance / 2) - math.sin(th) * (d / 2 - offset)
    )
    point = q + r * np.array([math.cos(th), -math.sin(th)])
    rho = offset + r * math.sin(th)
    np.testing.assert_allclose(z_p - point[1], rho, rtol=1e-12)
    _check(c, delta, point, z_p, r_i, [1 / r, math.sin(th) / rho])


@pytest.mark.parametrize(
    ("offset", "rib_radius", "tangent_height"),
    [(0.4e-3, 0.100, 1.2e-3), (0.0, 0.090, 1.5e-3), (1.0e-3, 0.300, 0.0)],
)
def test_torus_on_torus_closed_form(offset, rib_radius, tangent_height):
    """Torus end (offset e) on a concave toroidal rib (meridian radius R_rib tangent to the cone
    at the height h_t), aligned roller 10 um off centre.

    The rib's meridian circle touches the cone line at P_t = P0 + (h_t / cos theta) t0,
    t0 = (sin theta, cos theta) up the flange, and is concave: its centre K = P_t - R_rib n0 lies
    on the roller side and the rib is the outside of the circle, so the depth into the rib of a
    point X is |X - K| - R_rib. The ball of radius R about Q (inside the circle, R_rib > R)
    reaches deepest along n = (Q - K)/|Q - K|:

        delta = R + |Q - K| - R_rib,   C = Q + R n,   sin(alpha) = -n_z,
        rho_c = z_p - C_z = e + R sin(alpha),   h_c = C_z - R_i.

    Curvature sums: along the meridians 1/R - 1/R_rib (the concave rib subtracts its curvature),
    along the end's parallel sin(alpha)/rho_c (Meusnier, as on the cone) plus 0 for the rib's
    straight generator (the rib's tangent surface at the roller's azimuth, docs/model.md 5.4)."""
    faces = faces_of(
        BEARING, end_offset=offset, rib_curvature=1 / rib_radius, rib_tangent_height=tangent_height
    )
    c, x_p, z_p, r_i = _aligned(BEARING, faces, 10e-6)
    th, r = float(faces.layback_angle), 1 / float(faces.end_curvature)
    width = float(BEARING.roller.length) + float(faces.axial_clearance)
    n0, t0 = np.array([math.cos(th), -math.sin(th)]), np.array([math.sin(th), math.cos(th)])
    p_t = np.array([width / 2, r_i]) + tangent_height / math.cos(th) * t0
    k = p_t - rib_radius * n0
    q, _ = _end_arc_centre(BEARING, faces, x_p, z_p)
    dist = float(np.linalg.norm(q - k))
    n = (q - k) / dist
    point = q + r * n
    rho = offset + r * (-n[1])
    np.testing.assert_allclose(z_p - point[1], rho, rtol=1e-12)
    _check(c, r + dist - rib_radius, point, z_p, r_i, [1 / r - 1 / rib_radius, -n[1] / rho])


# -- (c) gradients in every face parameter against central differences -----------------------------
#: central-difference steps per face parameter (1e-5 to 1e-4 of their typical size, `SCALES`)
STEPS = {
    "end_curvature": 1e-4,
    "end_offset": 1e-7,
    "corner_radius": 1e-7,
    "layback_angle": 1e-7,
    "rib_curvature": 1e-4,
    "rib_tangent_height": 1e-7,
    "flange_height": 1e-7,
    "axial_clearance": 1e-7,
}

#: typical size of each face parameter: derivatives are compared as the change of an output per
#: this much change of the parameter (atol 1e-6 of the outputs' units, above the differences'
#: round-off: 1e-17 m in delta, from adding R_end = 80 mm, over a step of 2e-7 m, times 1 mm,
#: is 7e-8 um)
SCALES = {
    "end_curvature": 10.0,
    "end_offset": 1e-3,
    "corner_radius": 1e-3,
    "layback_angle": 0.03,
    "rib_curvature": 10.0,
    "rib_tangent_height": 1e-3,
    "flange_height": 1e-3,
    "axial_clearance": 1e-3,
}


def _outputs(faces, pose):
    """Scaled outputs of a skewed, tilted, axially offset roller: delta [um], C [mm], h_c [mm],
    rho_c [mm], the curvature sums [1/m], the Hertz stiffness [GN/m^1.5]."""
    radius, p, axis = pose
    c = face_contact(BEARING, faces, radius, 1.0, 1.0, p, axis, jnp.zeros(3))
    k = face_contact_stiffness(c, flange_effective_modulus(BEARING))
    scalars = jnp.stack([c.interference * 1e6, c.contact_height * 1e3, c.contact_radius * 1e3, k / 1e9])
    return jnp.concatenate([scalars, c.contact_point * 1e3, c.curvature_sums])


_jacobian = jax.jit(jax.jacfwd(_outputs))
_values = jax.jit(_outputs)


@pytest.mark.parametrize(
    ("offset", "rib_curvature", "tangent_height", "tilt", "skew"),
    [(0.3e-3, 5.0, 1.0e-3, 4e-3, 6e-3), (0.3e-3, 0.0, 0.0, 4e-3, 6e-3), (0.3e-3, 10.0, 1.2e-3, 4e-4, 6e-4)],
    ids=["torus-on-torus", "torus-on-cone", "near-conforming"],
)
def test_gradients_match_central_differences(offset, rib_curvature, tangent_height, tilt, skew):
    """jax.jacfwd through `face_contact` (implicit derivatives of the Newton solves) agrees with
    central differences in all eight face parameters, on the arc, at a tilted, skewed pose 2 um
    off centre: to 1e-4 relative, or 1e-6 of the output's unit per typical change of the
    parameter (`SCALES`). The flange height enters no output (derivative 0 both ways); the
    tangent height of the cone none either (the tangent point slides along the cone). The
    near-conforming rib (R_rib = 1.25 R_end) gets a tenth of the tilt and skew: its contact moves
    by about R_end R_rib / (R_rib - R_end) = 0.4 m per radian of the normal and would leave the
    arc at 4 mrad."""
    pose = _pose(BEARING, 1.0, 1.0, 2e-6, tilt, skew)
    faces = faces_of(
        BEARING, end_offset=offset, rib_curvature=rib_curvature, rib_tangent_height=tangent_height
    )
    radius, p, axis = pose
    assert float(_face_contact(BEARING, faces, radius, 1.0, 1.0, p, axis, np.zeros(3)).on_arc) == 1.0
    jac = _jacobian(faces, pose)
    for name in FIELDS:
        h = STEPS[name]
        value = getattr(faces, name)
        plus = _values(eqx.tree_at(lambda f, n=name: getattr(f, n), faces, value + h), pose)
        minus = _values(eqx.tree_at(lambda f, n=name: getattr(f, n), faces, value - h), pose)
        fd = (plus - minus) / (2 * h) * SCALES[name]
        ad = np.asarray(getattr(jac, name)) * SCALES[name]
        np.testing.assert_allclose(ad, fd, rtol=1e-4, atol=1e-6, err_msg=name)


def test_zone_margin_gradients_match_central_differences():
    """The four design-zone margins (`face_design_zone`) of a torus on a concave rib:
    jax.jacfwd in every face parameter agrees with central differences (1e-4 relative)."""
    faces = faces_of(BEARING, end_offset=0.3e-3, rib_curvature=6.0, rib_tangent_height=1.0e-3)

    def margins(f):
        z = face_design_zone(BEARING, f)
        return (
            jnp.stack([z.relief_margin, z.height_margin, z.limited_circle_margin, z.clearance_margin]) * 1e3
        )

    jac = jax.jit(jax.jacfwd(margins))(faces)
    values = jax.jit(margins)
    assert bool(_zone(BEARING, faces).feasible)
    for name in FIELDS:
        h = STEPS[name]
        value = getattr(faces, name)
        plus = values(eqx.tree_at(lambda f, n=name: getattr(f, n), faces, value + h))
        minus = values(eqx.tree_at(lambda f, n=name: getattr(f, n), faces, value - h))
        fd = (plus - minus) / (2 * h) * SCALES[name]
        ad = np.asarray(getattr(jac, name)) * SCALES[name]
        np.testing.assert_allclose(ad, fd, rtol=1e-4, atol=1e-6, err_msg=name)


# -- (d) the Newton solve's accuracy and the global maximum, over sampled faces and poses -----------
def _end_surface(bearing, faces, p, axis_out):
    """Points of the end surface (arc cap and corner torus) on a grid: 300 radii on the arc,
    150 angles on the corner, 1440 azimuths; written from the meridians directly:
    arc a(rho) = L/2 + e_p - sag(rho - e, 1/R_end) for rho in [0, rho_lim], corner
    (x_cor + R_cor cos(beta), R_ce + R_cor sin(beta)) for beta in [0, pi/2]."""
    d, length = float(bearing.roller.diameter), float(bearing.roller.length)
    k, e, r_cor = float(faces.end_curvature), float(faces.end_offset), float(faces.corner_radius)
    r, r_ce = 1 / k, d / 2 - r_cor
    r_prime = r - r_cor
    e_p = (r_ce - e) ** 2 / (r_prime + math.sqrt(r_prime**2 - (r_ce - e) ** 2))
    rho_lim = e + (r_ce - e) * r / r_prime
    rho = np.linspace(0.0, rho_lim, 300)
    arc_a = length / 2 + e_p - (rho - e) ** 2 / (r + np.sqrt(r**2 - (rho - e) ** 2))
    beta = np.linspace(0.0, np.pi / 2, 150)
    a = np.concatenate([arc_a, length / 2 - r_cor + r_cor * np.cos(beta)])
    rho = np.concatenate([rho, r_ce + r_cor * np.sin(beta)])
    u1 = np.cross(axis_out, [0.0, 1.0, 0.0] if abs(axis_out[1]) < 0.9 else [0.0, 0.0, 1.0])
    u1 /= np.linalg.norm(u1)
    u2 = np.cross(axis_out, u1)
    psi = np.linspace(0.0, 2 * np.pi, 1440, endpoint=False)
    radial = np.cos(psi)[:, None] * u1 + np.sin(psi)[:, None] * u2  # (1440, 3)
    return p + a[:, None, None] * axis_out + rho[:, None, None] * radial[None]


def _deepest_on_grid(bearing, faces, radius, side, ring_sign, p, axis):
    """Largest signed depth into the rib over the end-surface grid (ring axis X, centre 0):
    the rib's meridian plane at the roller's azimuth, n0 and t0 as in docs/model.md 5.4."""
    th = float(faces.layback_angle)
    e_rad = np.array([0.0, p[1], p[2]]) / math.hypot(p[1], p[2])
    n0 = side * math.cos(th) * X - ring_sign * math.sin(th) * e_rad
    t0 = ring_sign * math.cos(th) * e_rad + side * math.sin(th) * X
    width = float(bearing.roller.length) + float(faces.axial_clearance)
    p_t = side * width / 2 * X + radius * e_rad + float(faces.rib_tangent_height) / math.cos(th) * t0
    u = _end_surface(bearing, faces, p, side * axis) - p_t
    d, _, _ = rib_distance(u @ n0, u @ t0, float(faces.rib_curvature))
    return float(np.max(d))


def test_rib_distance_is_the_distance_to_the_meridian_circle():
    """`rib_distance` (cancellation-free) against the plain geometry: |X - K| - R_rib for the
    concave circle with centre K = (-R_rib, 0), and u_n for the cone."""
    rng = np.random.default_rng(1)
    u_n, u_t = rng.uniform(-0.1, 0.01, 50), rng.uniform(-0.01, 0.01, 50)
    for k in (2.0, 11.0, 500.0):
        np.testing.assert_allclose(
            rib_distance(u_n, u_t, k)[0], np.hypot(u_n + 1 / k, u_t) - 1 / k, rtol=1e-11, atol=1e-17
        )
    np.testing.assert_array_equal(rib_distance(u_n, u_t, 0.0)[0], u_n)


@settings(max_examples=40, deadline=None)
@given(
    st.floats(0.0, 0.9),
    st.floats(0.0, 0.95),
    st.floats(0.0, 1.0),
    st.floats(-0.01, 0.01),
    st.floats(-0.01, 0.01),
    st.floats(-20e-6, 20e-6),
    st.sampled_from([1.0, -1.0]),
    st.sampled_from([1.0, -1.0]),
)
# the corner nearly square-on to a concave rib (the normal 4 mrad off the roller axis, by the
# skew alone): the depth along the corner circle has two maxima, and Newton's method from the
# circle's radial direction alone stops between them (checked: it fails this example)
@example(0.834, 0.677, 0.221, -1.49e-4, 4.36e-3, 0.0, 1.0, -1.0)
# an end offset e of 1e-126 of R_ce: the arc's centre circle shrinks to a point, the depth is
# flat in the angle and F'/F'' is 0/0 (the reported step is bounded by pi times the radius)
@example(1.2913027781919056e-126, 0.5, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0)
def test_newton_converges_to_the_deepest_point(
    offset, conformity, height, tilt, skew, axial, ring_sign, side
):
    """Over e in [0, 0.9 R_ce], kappa_rib in [0, 0.95 kappa_end], h_t in [0, H_rf], tilt and
    skew up to 10 mrad, 20 um axial offsets and all four flanges: the Newton solves' next step
    is below the stated `NEWTON_ACCURACY` (1e-14 m along the circle), every output is finite, and the
    interference is the deepest point of the end surface in the rib: no grid point of the
    surface (`_end_surface`) lies deeper (to 1e-15 m), and the grid's deepest is within 5e-8 m
    of it (the grid's spacing, 15 um around and 4 um across the corner, times the relative
    curvature)."""
    r_ce = float(BEARING.roller.diameter) / 2 - float(BEARING.roller.corner_radius)
    faces = faces_of(
        BEARING,
        end_offset=offset * r_ce,
        rib_curvature=conformity / float(BEARING.roller.end_radius),
        rib_tangent_height=height * float(BEARING.flange.height),
    )
    radius, p, axis = _pose(BEARING, ring_sign, side, axial, tilt, skew)
    c = _face_contact(BEARING, faces, radius, side, ring_sign, p, axis, np.zeros(3))
    assert float(np.max(c.solve_error)) < NEWTON_ACCURACY
    assert all(np.isfinite(np.asarray(x)).all() for x in jax.tree_util.tree_leaves(c))
    deepest = _deepest_on_grid(BEARING, faces, radius, side, ring_sign, p, axis)
    assert deepest <= float(c.interference) + 1e-15
    assert float(c.interference) - deepest < 5e-8


# -- (e) bad faces: one line naming the parameter, its value and the valid range ------------------
@pytest.mark.parametrize(
    ("name", "value", "valid"),
    [
        ("end_offset", -1e-4, "in [0, R_ce = D/2 - R_cor = 0.00335) m"),
        ("end_offset", 3.4e-3, "in [0, R_ce = D/2 - R_cor = 0.00335) m"),
        ("end_curvature", 1 / 3e-3, "in [0, 2/D = 266.667) 1/m (R_end > D/2; 0 for flat ends)"),
        ("end_curvature", -1.0, "in [0, 2/D"),
        ("rib_curvature", -2.0, "in [0, 12.5) 1/m"),
        ("rib_curvature", 12.5, "in [0, 12.5) 1/m"),
        ("rib_curvature", float("nan"), "in [0, 12.5) 1/m"),
        ("corner_radius", 0.0, "in (0, D/2 = 0.00375) m"),
        ("layback_angle", 1.0, "in [0, 45) deg"),
        ("rib_tangent_height", 2.5e-3, "in [0, H_rf = 0.002] m"),
        ("flange_height", 0.0, "> 0 m"),
        ("axial_clearance", -1e-5, ">= 0 m"),
    ],
)
def test_bad_faces_are_rejected_with_one_line(name, value, valid):
    """`check_faces` (and `face_design_zone`, which calls it) rejects faces that make no contact
    geometry: e < 0 or e >= R_ce (the arc's centre circle beyond the corner's), R_end <= D/2
    (which includes R_end <= e), a convex rib or one conforming at least as closely as the end
    (R_rib <= 0 or R_rib <= R_end), NaN, and the other ranges; one line, no traceback."""
    faces = eqx.tree_at(lambda f: getattr(f, name), faces_of(BEARING), jnp.asarray(value))
    for call in (lambda: check_faces(faces, BEARING), lambda: face_design_zone(BEARING, faces)):
        with pytest.raises(UserInputError) as info:
            call()
        message = str(info.value)
        assert "\n" not in message
        assert message.startswith(f"faces.{name} = ") and valid in message, message


def test_valid_faces_pass_the_check():
    """The reference faces, a torus on a concave rib and a flat end pass `check_faces`."""
    check_faces(faces_of(BEARING), BEARING)
    check_faces(faces_of(BEARING, end_offset=1e-3, rib_curvature=10.0, rib_tangent_height=1e-3), BEARING)
    check_faces(faces_of(BEARING.with_flat_ends(), rib_curvature=100.0), BEARING)
    assert isinstance(faces_of(BEARING), Faces)
