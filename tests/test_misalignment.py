"""Inner-ring misalignment and the inner ring's axial and tilt freedom (docs/model.md,
"Misalignment"): the tilted geometry against closed forms, the aligned limit against the
aligned formulas, the static carrying of an axial load by the inner flanges, finiteness, and
the configuration keys. Unit level: seconds."""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing import ConfigError
from jaxbearing.dynamics import Params, contact_loads, inner_ring_pose, physical_rates, radial_unit
from jaxbearing.flange import roller_flange_contact
from jaxbearing.forces import crown_drop, raceway_contact, raceway_slice_geometry, slice_positions
from jaxbearing.geometry import end_support, ring_axis, ring_tilt_angular_velocity
from jaxbearing.io import validate_bearing
from jaxbearing.run._initial import kinematic_start

X = jnp.array([1.0, 0.0, 0.0])
#: the field and the contact loads (`dynamics` jits both) with one argument signature in every
#: static check below, so that they share one compiled program each: `_op` and the states' edits
#: are float64 arrays, not weakly typed scalars, and every leaf is put on the device (a leaf fresh
#: from `jnp.asarray` and one from a compiled program otherwise key a second compilation, 6 s each)
_DEVICE = jax.devices()[0]


def _rates(t, y, params):
    return physical_rates(t, *jax.device_put((y, params), _DEVICE))


def _loads(y, params):
    return contact_loads(*jax.device_put((y, params), _DEVICE))


def _rot_y(psi):
    """R_Y(psi): a positive rotation about +Y (takes X to (cos, 0, -sin))."""
    c, s = math.cos(psi), math.sin(psi)
    return jnp.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _op(**kw):
    return eqx.tree_at(
        lambda o: tuple(getattr(o, k) for k in kw),
        jb.reference_operating_point(),
        tuple(jnp.asarray(float(v), dtype=float) for v in kw.values()),
    )


# -- the ring's attitude -------------------------------------------------------------------------
def test_ring_axis_exact_and_unit():
    assert np.array_equal(np.asarray(ring_axis(jnp.zeros(2))), [1.0, 0.0, 0.0])
    t = jnp.array([0.3, -0.2])
    a = ring_axis(t)
    assert float(jnp.linalg.norm(a)) == pytest.approx(1.0, abs=1e-15)
    # R_Y(psi_y) R_Z(psi_z) X
    rz = jnp.array([[math.cos(-0.2), -math.sin(-0.2), 0], [math.sin(-0.2), math.cos(-0.2), 0], [0, 0, 1.0]])
    np.testing.assert_allclose(np.asarray(a), np.asarray(_rot_y(0.3) @ rz @ X), atol=1e-15)
    # omega_tilt is the angular velocity of that rotation: a' = omega_tilt x a
    rate = jnp.array([0.7, -1.3])
    a_dot = jax.jvp(ring_axis, (t,), (rate,))[1]
    np.testing.assert_allclose(
        np.asarray(a_dot), np.asarray(jnp.cross(ring_tilt_angular_velocity(t, rate), a)), atol=1e-14
    )


# -- tilted raceway geometry ---------------------------------------------------------------------
@pytest.mark.parametrize("theta", [0.0, math.pi / 3, math.pi / 2, 2 * math.pi / 3, math.pi, 4.0])
def test_tilted_ring_interference_gradient_closed_form(theta):
    """Aligned roller at azimuth theta against an inner ring tilted by psi about +Y: the slice
    interference changes along the roller by -sin(psi) cos(theta) xi (forces/_raceway.py
    docstring), on top of the aligned slices (crown and all)."""
    b = jb.reference_bearing()
    psi = 1e-3
    r = float(b.inner_raceway_radius + b.roller.diameter / 2) - 2e-6  # 2 um approach
    p = r * radial_unit(jnp.asarray(theta))
    xi = np.asarray(slice_positions(b))
    aligned, _, _ = raceway_slice_geometry(b, 1.0, b.inner_raceway_radius, p, X, jnp.zeros(3))
    tilted, _, _ = raceway_slice_geometry(
        b, 1.0, b.inner_raceway_radius, p, X, jnp.zeros(3), ring_axis=ring_axis(jnp.array([psi, 0.0]))
    )
    diff = np.asarray(tilted - aligned)
    slope, offset = np.polyfit(xi, diff, 1)
    assert slope == pytest.approx(-math.sin(psi) * math.cos(theta), abs=1e-3 * psi)
    # linear along the roller to far below the penetration width (1e-9 m)
    assert np.max(np.abs(diff - (slope * xi + offset))) < 1e-10
    # and the aligned case is the uniform approach less the crown drop
    np.testing.assert_allclose(
        np.asarray(aligned), 2e-6 - np.asarray(crown_drop(b.roller, xi)), rtol=0, atol=1e-15
    )


def test_tilted_contacts_are_rotated_aligned_contacts():
    """Rotating roller and inner ring together about the ring centre by R_Y(psi) (exact, large
    psi): interferences unchanged, forces and moments rotated, for the raceway and the flange."""
    b = jb.reference_bearing()
    psi = 0.05
    rot = _rot_y(psi)
    c = jnp.array([0.1e-3, 2e-6, -3e-6])
    r = float(b.inner_raceway_radius + b.roller.diameter / 2) - 3e-6  # 3 um approach
    p = c + jnp.array([-0.09e-3, 0.0, 0.0]) + r * radial_unit(jnp.asarray(0.4))  # into the -X flange
    e = jnp.array([math.cos(2e-3), math.sin(2e-3), 0.0])
    v, w = jnp.array([0.01, -3.0, 5.0]), jnp.array([-2000.0, 10.0, 3.0])
    v_r, w_r = jnp.array([0.001, 0.002, -0.001]), jnp.array([2000.0, 1.0, -2.0])

    def pose(r):
        return (c + r @ (p - c), r @ e, r @ v, r @ w, c, r @ v_r, r @ w_r, r @ X)

    p0, e0, v0, w0, c0, vr0, wr0, a0 = pose(jnp.eye(3))
    p1, e1, v1, w1, c1, vr1, wr1, a1 = pose(rot)
    ref = raceway_contact(b, 1.0, b.inner_raceway_radius, p0, e0, v0, w0, c0, vr0, wr0)
    tilt = raceway_contact(b, 1.0, b.inner_raceway_radius, p1, e1, v1, w1, c1, vr1, wr1, ring_axis=a1)
    assert float(jnp.max(ref.interference)) > 0
    np.testing.assert_allclose(np.asarray(tilt.interference), np.asarray(ref.interference), atol=1e-15)
    for name in ("force_on_roller", "moment_on_roller", "force_on_ring", "moment_on_ring"):
        np.testing.assert_allclose(
            np.asarray(getattr(tilt, name)), np.asarray(rot @ getattr(ref, name)), rtol=1e-9, atol=1e-9
        )
    for side in (-1.0, 1.0):
        f0 = roller_flange_contact(b, b.inner_raceway_radius, side, 1.0, p0, e0, v0, w0, c0, vr0, wr0)
        f1 = roller_flange_contact(
            b, b.inner_raceway_radius, side, 1.0, p1, e1, v1, w1, c1, vr1, wr1, ring_axis=a1
        )
        assert float(f1.interference) == pytest.approx(float(f0.interference), abs=1e-15)
        np.testing.assert_allclose(
            np.asarray(f1.force_on_roller), np.asarray(rot @ f0.force_on_roller), rtol=1e-9, atol=1e-9
        )
        if side < 0:
            assert float(f0.normal_force) > 1.0  # a loaded flange contact was compared


# -- aligned limit ---------------------------------------------------------------------------------
def _aligned_raceway_interference(b, p, e, c):
    """The aligned formula of the main branch: rho = rel - (rel.X) X (ring axis X)."""
    xi = slice_positions(b)
    q = p + xi[:, None] * e
    rel = q - c
    rho = rel - rel[:, :1] * np.array([1.0, 0.0, 0.0])
    d = jnp.linalg.norm(rho, axis=-1)
    n = rho / d[:, None]
    cos_t = n @ e
    support = jnp.linalg.norm(n - cos_t[:, None] * e, axis=-1)
    return (b.roller.diameter / 2 - crown_drop(b.roller, xi)) * support + (b.inner_raceway_radius - d)


def _aligned_flange_interference(b, side, p, e, c):
    """The aligned flange plane of the main branch: e_rad from the Y, Z components of p - c_r."""
    rad = (p - c) * jnp.array([0.0, 1.0, 1.0])
    e_rad = rad / jnp.linalg.norm(rad)
    th = b.flange.layback_angle
    p0 = c + side * (b.raceway_width / 2) * X + b.inner_raceway_radius * e_rad
    n = side * jnp.cos(th) * X - jnp.sin(th) * e_rad
    x_end = side * e
    cos_a = jnp.dot(n, x_end)
    sin_a = jnp.linalg.norm(n - cos_a * x_end)
    h = end_support(b.roller, cos_a, sin_a)[0]
    return h - jnp.dot(p0 - p, n)


def test_zero_misalignment_reproduces_aligned_contacts():
    """At zero misalignment, axial position and tilt, the inner contacts of a perturbed state are
    those of the aligned formulas (to rounding), and switching the new freedoms on changes no
    rate but those of the new coordinates."""
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    y = kinematic_start(b, op, jb.Perturbation(seed=5))
    y = eqx.tree_at(lambda s: s.rollers.axial, y, y.rollers.axial + 0.06e-3)  # into the +X flanges
    y = eqx.tree_at(lambda s: s.inner_ring.centre, y, y.inner_ring.centre + jnp.array([2e-6, -1e-6]))
    loads = _loads(y, Params(bearing=b, operating=op))
    ring = inner_ring_pose(y.inner_ring, op)
    assert np.array_equal(np.asarray(ring.axis), [1.0, 0.0, 0.0])
    assert np.array_equal(np.asarray(ring.angular_velocity), np.asarray(op.inner_speed * X))
    e = y.rollers.axis / jnp.linalg.norm(y.rollers.axis, axis=-1, keepdims=True)
    p, c = y.rollers.centre, ring.centre
    ref = jax.vmap(_aligned_raceway_interference, in_axes=(None, 0, 0, None))(b, p, e, c)
    np.testing.assert_allclose(np.asarray(loads.inner.interference), np.asarray(ref), rtol=0, atol=1e-17)
    for k, side in ((0, -1.0), (1, 1.0)):
        ref = jax.vmap(_aligned_flange_interference, in_axes=(None, None, 0, 0, None))(b, side, p, e, c)
        np.testing.assert_allclose(
            np.asarray(loads.flange.interference[:, k]), np.asarray(ref), rtol=0, atol=1e-17
        )
    assert float(jnp.max(loads.flange.normal_force[:, 1])) > 1.0  # a flange contact was tested
    off = _rates(0.0, y, Params(bearing=b, operating=op))
    on = _rates(0.0, y, Params(bearing=b, operating=_op(axial_freedom=1, tilt_freedom=1)))
    for name in ("rollers", "cage", "accumulators"):
        for a, bb in zip(
            jax.tree_util.tree_leaves(getattr(off, name)), jax.tree_util.tree_leaves(getattr(on, name))
        ):
            assert np.array_equal(np.asarray(a), np.asarray(bb))
    assert np.array_equal(np.asarray(off.inner_ring.velocity), np.asarray(on.inner_ring.velocity))
    assert float(off.inner_ring.axial_velocity) == 0.0 and float(on.inner_ring.axial_velocity) != 0.0
    assert np.all(np.asarray(off.inner_ring.tilt_rate) == 0.0)
    assert np.all(np.asarray(on.inner_ring.tilt_rate) != 0.0)


# -- axial load ----------------------------------------------------------------------------------
def test_axial_load_is_carried_by_the_inner_flanges():
    """Static check: with the axial freedom on and F_a = 300 N along +X, the ring moves to where
    its axial force balances; there the -X inner flanges carry F_a (the raceways nothing
    axially, the +X flanges nothing) and the ring's axial acceleration vanishes."""
    b = jb.reference_bearing()
    f_a = 300.0
    op = _op(axial_load=f_a, axial_freedom=1)
    params = Params(bearing=b, operating=op)
    y = kinematic_start(b, op, jb.Perturbation(axial=0.0, skew=0.0))  # no scatter

    def axial(x):
        s = eqx.tree_at(lambda s: s.inner_ring.axial, y, jnp.asarray(x, dtype=float))
        return _rates(0.0, s, params).inner_ring.axial_velocity * b.inner_ring_mass, _loads(s, params)

    lo, hi = 0.0, 0.3e-3
    assert float(axial(lo)[0]) > 0 and float(axial(hi)[0]) < 0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if float(axial(mid)[0]) > 0 else (lo, mid)
    net, loads = axial(0.5 * (lo + hi))
    assert abs(float(net)) < 1e-6 * f_a
    fl_ring = np.asarray(loads.flange.force_on_ring)  # (Z, 4, 3)
    assert np.sum(fl_ring[:, 0, 0]) == pytest.approx(-f_a, rel=1e-3)  # inner -X flange
    assert np.max(np.asarray(loads.flange.normal_force[:, 1])) == 0.0  # inner +X flange open
    assert abs(float(np.sum(np.asarray(loads.inner.force_on_ring)[:, 0]))) < 1e-3 * f_a
    # every roller is pushed towards +X by the same flange
    assert np.all(np.asarray(loads.flange.force_on_roller)[:, 0, 0] > 0)


def test_nu_inner_ring_floats_under_axial_load():
    """The same axial load on an NU bearing (`bearing.type = "NU"`: no inner flanges). Free
    axially (which the configuration rejects for this reason, docs/model.md 5.3): at every
    axial position of the ring, from centred to 0.3 mm, its inner flanges exert exactly nothing
    and the ring's axial force is F_a plus the raceways' axial traction alone, positive
    throughout: no position balances it, the ring would be pushed off the rollers. The NUP at
    0.3 mm pushes it back. Held axially (the accepted NU configuration: the shaft's locating
    bearing carries F_a): the ring's axial rates are exactly zero and the reaction the locating
    bearing supplies, R = -(F_a + F_raceways.X + F_inner flanges.X), is -F_a to within the
    raceways' axial traction (below 1 %), none of it through the flanges."""
    b = jb.reference_bearing()
    nu = eqx.tree_at(lambda b: b.flange_presence, b, jnp.array([0.0, 0.0, 1.0, 1.0]))
    f_a = 300.0
    op = _op(axial_load=f_a, axial_freedom=1)
    y = kinematic_start(b, op, jb.Perturbation(axial=0.0, skew=0.0))  # no scatter

    def axial(bearing, x, op=op):
        s = eqx.tree_at(lambda s: s.inner_ring.axial, y, jnp.asarray(x, dtype=float))
        params = Params(bearing=bearing, operating=op)
        return _rates(0.0, s, params).inner_ring, _loads(s, params)

    for x in (0.0, 0.1e-3, 0.2e-3, 0.3e-3):
        rates, loads = axial(nu, x)
        net = float(rates.axial_velocity * b.inner_ring_mass)
        fl = loads.flange
        assert np.all(np.asarray(fl.normal_force)[:, :2] == 0.0)
        assert np.all(np.asarray(fl.force_on_ring)[:, :2] == 0.0)
        raceway = float(np.sum(np.asarray(loads.inner.force_on_ring)[:, 0]))
        assert net == pytest.approx(f_a + raceway, rel=1e-12)
        assert net > 0.99 * f_a
        # held by the locating bearing (axial freedom off): the same contacts, no axial motion
        held_op = _op(axial_load=f_a)
        validate_bearing(nu, held_op)
        held, held_loads = axial(nu, x, held_op)
        assert float(held.axial) == 0.0 and float(held.axial_velocity) == 0.0
        flanges = float(np.sum(np.asarray(held_loads.flange.force_on_ring)[:, :2, 0]))
        raceway = float(np.sum(np.asarray(held_loads.inner.force_on_ring)[:, 0]))
        reaction = -(f_a + raceway + flanges)
        assert flanges == 0.0 and reaction == pytest.approx(-f_a, rel=0.01)
    rates, loads_nup = axial(b, 0.3e-3)
    assert (
        float(rates.axial_velocity) < 0 and np.sum(np.asarray(loads_nup.flange.force_on_ring)[:, 0, 0]) < -f_a
    )


def test_axial_and_tilt_rates_follow_the_equations():
    """x_i'' = F.X / m_i and the gyroscopic tilt coupling I_t psi'' = M_perp + I_a omega_i (-psi_z', psi_y')."""
    b = jb.reference_bearing()
    op = _op(axial_freedom=1, tilt_freedom=1, misalignment=0.5e-3)
    params = Params(bearing=b, operating=op)
    y = kinematic_start(b, op, jb.Perturbation(seed=1))
    rate = jnp.array([0.2, -0.1])
    y = eqx.tree_at(lambda s: s.inner_ring.tilt_rate, y, rate)
    y = eqx.tree_at(lambda s: s.inner_ring.axial_velocity, y, jnp.asarray(0.003, dtype=float))
    r = _rates(0.0, y, params).inner_ring
    loads = _loads(y, params)
    fm = np.asarray(loads.flange.force_on_ring)[:, :2].sum(axis=(0, 1))
    mm = np.asarray(loads.flange.moment_on_ring)[:, :2].sum(axis=(0, 1))
    force = fm + np.asarray(loads.inner.force_on_ring).sum(axis=0)
    moment = mm + np.asarray(loads.inner.moment_on_ring).sum(axis=0)
    a = np.asarray(inner_ring_pose(y.inner_ring, op).axis)
    m_perp = moment - moment @ a * a
    i_a, i_t = (float(x) for x in b.inner_ring_inertia)
    w = float(op.inner_speed)
    expect = (m_perp[1:] + i_a * w * np.array([0.1, 0.2])) / i_t
    np.testing.assert_allclose(np.asarray(r.tilt_rate), expect, rtol=1e-10)
    np.testing.assert_allclose(np.asarray(r.tilt), np.asarray(rate))
    assert float(r.axial) == pytest.approx(0.003)
    assert float(r.axial_velocity) == pytest.approx(force[0] / float(b.inner_ring_mass), rel=1e-10)


def test_vector_field_finite_with_free_tilted_ring_at_unphysical_states():
    b = jb.reference_bearing()
    op = _op(axial_freedom=1, tilt_freedom=1, misalignment=10e-3, axial_load=-5000.0)
    params = Params(bearing=b, operating=op)
    y = kinematic_start(b, op, jb.Perturbation())
    bad = eqx.tree_at(lambda s: s.inner_ring.axial, y, jnp.asarray(0.4e-3, dtype=float))
    bad = eqx.tree_at(lambda s: s.inner_ring.tilt, bad, jnp.array([0.1, -0.05]))
    bad = eqx.tree_at(lambda s: s.inner_ring.tilt_rate, bad, jnp.array([300.0, -200.0]))
    for state in (y, bad):
        assert all(
            bool(jnp.all(jnp.isfinite(x))) for x in jax.tree_util.tree_leaves(_rates(0.0, state, params))
        )
    jac = jax.jacfwd(
        lambda t: (
            physical_rates(0.0, eqx.tree_at(lambda s: s.inner_ring.tilt, bad, t), params).inner_ring.tilt_rate
        )
    )(bad.inner_ring.tilt)
    assert bool(jnp.all(jnp.isfinite(jac)))


# -- configuration -------------------------------------------------------------------------------
def test_config_keys_map_onto_the_operating_point():
    cfg = jb.loads_config(
        "[operating]\nmisalignment_mrad = 1.5\naxial_load_N = -200.0\n"
        "inner_ring_axial_freedom = true\ninner_ring_tilt_freedom = false\n"
    )
    op = cfg.operating_point()
    assert float(op.misalignment) == pytest.approx(1.5e-3)
    assert float(op.axial_load) == -200.0
    assert float(op.axial_freedom) == 1.0 and float(op.tilt_freedom) == 0.0
    ref = jb.reference_operating_point()
    assert all(
        float(getattr(ref, k)) == 0.0 for k in ("misalignment", "axial_load", "axial_freedom", "tilt_freedom")
    )
    validate_bearing(jb.reference_bearing(), op)


@pytest.mark.parametrize(
    "text, message",
    [
        (
            "misalignment_mrad = 12.0",
            "operating.misalignment_mrad: 12.0 mrad is out of range: must be in [-10, 10] mrad",
        ),
        ("misalignment_mrad = nan", "operating.misalignment_mrad: nan mrad is not finite"),
        (
            "axial_load_N = 100.0",
            "operating.axial_load_N: 100.0 N needs operating.inner_ring_axial_freedom = true",
        ),
        (
            "axial_load_N = 2e8\ninner_ring_axial_freedom = true",
            "operating.axial_load_N: 200000000.0 N is out of range: must be in [-1e8, 1e8] N",
        ),
        ("inner_ring_tilt_freedom = 1", "operating.inner_ring_tilt_freedom: expected true or false"),
    ],
)
def test_config_key_errors(text, message):
    with pytest.raises(ConfigError) as info:
        jb.loads_config(f"[operating]\n{text}\n")
    assert str(info.value).startswith(message), str(info.value)
    assert "\n" not in str(info.value)


def test_python_built_operating_point_is_validated():
    b = jb.reference_bearing()
    with pytest.raises(ConfigError, match=r"^operating.misalignment_mrad: 20.0 mrad is out of range"):
        validate_bearing(b, _op(misalignment=0.02))
    with pytest.raises(ConfigError, match=r"^operating.axial_load_N: 10.0 N needs"):
        validate_bearing(b, _op(axial_load=10.0))


@pytest.mark.parametrize("value", [0.5, -1.0, math.nan])
def test_switch_values_other_than_zero_and_one_are_rejected(value):
    with pytest.raises(
        ConfigError, match=r"^operating.inner_ring_tilt_freedom: .* is out of range: must be 1.0 \(true\)"
    ):
        validate_bearing(jb.reference_bearing(), _op(tilt_freedom=value))
