"""Quasi-static load distribution (docs/model.md 12) against closed forms and finite differences.

Oracles: Stribeck's maximum roller load F_r / sum cos(psi)^(n+1) (n = 10/9) and its many-roller
limit 4.08 F_r / Z written with the Gamma function; force balances of every roller and of the
ring; pure-rolling kinematics; the dynamic contact `_raceway.raceway_contact` evaluated at the
solution; central finite differences of the solution.
"""

from __future__ import annotations

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.special import gamma

import jaxbearing as jb
from jaxbearing import UserInputError
from jaxbearing.dynamics import quasi_static
from jaxbearing.forces import raceway_contact

N_LINE = 10 / 9
X = jnp.array([1.0, 0.0, 0.0])
ZERO = jnp.zeros(3)

# one compilation for every test: the bearing and operating point are pytree arguments
_qs = jax.jit(quasi_static)


def _case(clearance=20e-6, crown=4e-6, rpm=20_000.0, load=1000.0, g=9.81):
    b = jb.reference_bearing()
    b = eqx.tree_at(
        lambda b: (b.radial_clearance, b.roller.crown_drop), b, (jnp.asarray(clearance), jnp.asarray(crown))
    )
    op = jb.OperatingPoint(inner_speed=jb.rpm_to_rad_s(rpm), radial_load=load, gravity=g)
    return b, op


def _stribeck_qmax(load, z):
    psi = 2 * np.pi * np.arange(z) / z
    c = np.cos(psi)
    c = c[c > 0]
    return load / np.sum(c ** (N_LINE + 1))


def test_stribeck_maximum_roller_load():
    """Zero speed, zero clearance, no gravity, no crown: Q_max = F_r / sum cos^(n+1).

    Tolerance 1e-8 relative. Sources of error: the softplus smoothing adds w exp(-|delta|/w) to
    each slice's interference (w = 1e-9 m); the slice closest to zero interference belongs to the
    rollers at 83 deg, delta = 0.12 delta_max ~ 1e-7 m, so exp(-100): nil; the bisection resolves
    each roller's radius to the float spacing of r (7e-18 m), i.e. ~1e-9 N on 157 N. Observed
    error ~ 4e-12.
    """
    b, op = _case(clearance=0.0, crown=0.0, rpm=0.0, g=0.0)
    qs = _qs(b, op)
    q_max = _stribeck_qmax(1000.0, b.num_rollers)
    assert float(jnp.max(qs.inner_load)) == pytest.approx(q_max, rel=1e-8)
    assert float(qs.inner_load[0]) == float(jnp.max(qs.inner_load))  # roller 0 sits at the load
    # every loaded roller follows Q_max cos^n psi (delta proportional to cos psi)
    c = np.cos(np.asarray(qs.azimuth))
    expected = np.where(c > 0, q_max * np.clip(c, 0, None) ** N_LINE, 0.0)
    np.testing.assert_allclose(np.asarray(qs.inner_load), expected, rtol=1e-8, atol=1e-9)
    # ring force balance to 1e-9, and symmetric: no displacement along Y
    balance = float(jnp.sum(qs.inner_load * jnp.cos(qs.azimuth)))
    assert abs(balance - 1000.0) <= 1e-9 * 1000.0
    assert abs(float(jnp.sum(qs.inner_load * jnp.sin(qs.azimuth)))) <= 1e-9 * 1000.0
    assert abs(float(qs.inner_ring_displacement[0])) < 1e-15
    # zero speed, no gravity: both contacts of a roller carry the same load
    np.testing.assert_allclose(np.asarray(qs.outer_load), np.asarray(qs.inner_load), rtol=0, atol=1e-7)


def test_stribeck_many_roller_limit_is_4_08():
    """Z Q_max / F_r -> 2 pi / int_{-pi/2}^{pi/2} cos^(n+1) = 2 sqrt(pi) Gamma((n+3)/2)/Gamma((n+2)/2)
    = 4.08 for line contact (Harris & Kotzalas, Essential Concepts, ch. 7). Checked for Z = 200
    analytically, without running the solver."""
    m = N_LINE + 1
    integral = math.sqrt(math.pi) * gamma((m + 1) / 2) / gamma(m / 2 + 1)
    limit = 2 * math.pi / integral
    assert limit == pytest.approx(4.08, abs=0.005)
    z = 200
    assert z * _stribeck_qmax(1.0, z) == pytest.approx(limit, rel=1e-3)


def test_reference_point_balances():
    """Speed, clearance, crown and gravity on: every roller and the ring are in equilibrium."""
    b, op = _case()
    qs = _qs(b, op)
    m_b = float(b.roller_mass)
    omega_c = float(op.inner_speed) * (1 - float(b.roller.diameter) / float(b.pitch_diameter)) / 2
    f_c = m_b * float(b.pitch_diameter) / 2 * omega_c**2
    assert float(qs.centrifugal_force) == pytest.approx(f_c, rel=1e-14)
    psi = np.asarray(qs.azimuth)
    np.testing.assert_allclose(psi, 2 * np.pi * np.arange(b.num_rollers) / b.num_rollers, rtol=1e-15)
    # roller: Q_o = Q_i + F_c + m_b g cos psi (resolution ~1e-9 N, see test above)
    np.testing.assert_allclose(
        np.asarray(qs.outer_load - qs.inner_load), f_c + m_b * 9.81 * np.cos(psi), rtol=0, atol=1e-7
    )
    # ring: sum Q_i cos psi = F_r + m_i g, sum Q_i sin psi = 0
    ring_load = 1000.0 + float(b.inner_ring_mass) * 9.81
    assert float(jnp.sum(qs.inner_load * jnp.cos(qs.azimuth))) == pytest.approx(ring_load, rel=1e-9)
    assert abs(float(jnp.sum(qs.inner_load * jnp.sin(qs.azimuth)))) < 1e-9 * ring_load
    assert float(jnp.max(jnp.abs(qs.ring_residual))) < 1e-9 * ring_load
    assert abs(float(qs.inner_ring_displacement[0])) < 1e-15
    # the load zone: only rollers near psi = 0 touch the inner ring, every roller the outer one
    assert 3 <= int(jnp.sum(qs.inner_load > 1e-3)) < b.num_rollers // 2
    assert float(jnp.min(qs.outer_load)) > 0.9 * f_c


def test_clearance_loads_fewer_rollers_harder():
    b0, op0 = _case(clearance=0.0, crown=0.0, rpm=0.0, g=0.0)
    b1, op1 = _case(clearance=40e-6, crown=0.0, rpm=0.0, g=0.0)
    q0, q1 = _qs(b0, op0), _qs(b1, op1)
    n0, n1 = int(jnp.sum(q0.inner_load > 1e-6)), int(jnp.sum(q1.inner_load > 1e-6))
    assert n1 < n0
    assert float(jnp.max(q1.inner_load)) > 1.2 * float(jnp.max(q0.inner_load))
    # with clearance the ring must first cross the radial gap P_d/2
    assert float(q1.inner_ring_displacement[1]) > 20e-6
    for q in (q0, q1):
        assert abs(float(jnp.sum(q.inner_load * jnp.cos(q.azimuth))) - 1000.0) < 1e-9 * 1000.0
        assert abs(float(q.inner_ring_displacement[0])) < 1e-15


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(rpm=0.0),  # zero speed with gravity: rollers on top rest on the inner ring
        dict(rpm=0.0, g=0.0, clearance=100e-6),  # floating rollers in a large clearance
        dict(rpm=30_000.0, load=10.0),  # light load, centrifugal force dominates
        dict(rpm=30_000.0, load=0.0),  # ring carried by its own weight only
        dict(rpm=0.0, load=0.0, g=0.0),  # nothing loaded at all
        dict(load=20_000.0),  # heavy load
        dict(clearance=-10e-6, rpm=0.0, g=0.0),  # preload: every roller loaded
        dict(crown=30e-6),  # strongly crowned
    ],
)
def test_converges_robustly(kwargs):
    b, op = _case(**kwargs)
    qs = _qs(b, op)
    assert all(np.all(np.isfinite(np.asarray(x))) for x in jax.tree_util.tree_leaves(qs))
    ring_load = float(op.radial_load) + float(b.inner_ring_mass) * float(op.gravity)
    assert float(jnp.max(jnp.abs(qs.ring_residual))) <= 1e-9 * max(ring_load, 1.0)
    m_b = float(b.roller_mass)
    roller = qs.outer_load - qs.inner_load - qs.centrifugal_force - m_b * op.gravity * jnp.cos(qs.azimuth)
    assert float(jnp.max(jnp.abs(roller))) < 1e-7
    assert np.all(np.asarray(qs.inner_load) >= 0) and np.all(np.asarray(qs.outer_load) >= 0)
    # every roller between the raceways (within their elastic approach)
    r = np.asarray(qs.roller_radius)
    assert np.all(r > float(b.inner_raceway_radius)) and np.all(r < float(b.outer_raceway_radius))


def test_pure_rolling_kinematics():
    b, op = _case()
    qs = _qs(b, op)
    d_m, d = float(b.pitch_diameter), float(b.roller.diameter)
    omega_i = float(op.inner_speed)
    omega_c = omega_i * (1 - d / d_m) / 2
    assert float(qs.cage_speed) == pytest.approx(omega_c, rel=1e-14)
    assert float(qs.roller_orbital_speed) == float(qs.cage_speed)
    # nominal geometry, roller 0 on +Z: e_r = Z, e_t = X x Z = -Y
    e_r, e_t = np.array([0.0, 0.0, 1.0]), np.array([0.0, -1.0, 0.0])
    centre_v = omega_c * d_m / 2 * e_t
    spin = float(qs.roller_spin) * np.array([1.0, 0.0, 0.0])
    # outer contact point (fixed ring): zero velocity
    v_outer = centre_v + np.cross(spin, d / 2 * e_r)
    np.testing.assert_allclose(v_outer, 0.0, atol=1e-12 * omega_i * d_m)
    # inner contact point moves with the inner raceway surface
    v_inner = centre_v + np.cross(spin, -d / 2 * e_r)
    v_ring = np.cross(omega_i * np.array([1.0, 0.0, 0.0]), (d_m - d) / 2 * e_r)
    np.testing.assert_allclose(v_inner, v_ring, atol=1e-12 * omega_i * d_m)
    # Harris: roller speed relative to the cage = -(d_m / 2D)(1 - D^2/d_m^2) omega_i
    rel = float(qs.roller_spin) - omega_c
    assert rel == pytest.approx(-(d_m / (2 * d)) * (1 - d**2 / d_m**2) * omega_i, rel=1e-13)


def test_solution_is_an_equilibrium_of_the_dynamic_contact():
    """The same slice law: at rest (no damping, no traction) `raceway_contact` at the solution
    gives the same outer loads everywhere and the same inner load on roller 0 (psi = 0, where
    the linear ring kinematics is exact); elsewhere the inner loads differ by the documented
    |d|^2 sin^2 psi / (2 r) term (< 0.5 %)."""
    b, op = _case()
    qs = _qs(b, op)
    p = qs.roller_centres
    e = jnp.broadcast_to(X, p.shape)
    zeros = jnp.zeros_like(p)
    contact = jax.jit(jax.vmap(raceway_contact, in_axes=(None, None, None, 0, 0, 0, 0, None, None, None)))
    inner = contact(b, 1.0, b.inner_raceway_radius, p, e, zeros, zeros, qs.inner_ring_centre, ZERO, ZERO)
    outer = contact(b, -1.0, b.outer_raceway_radius, p, e, zeros, zeros, ZERO, ZERO, ZERO)
    np.testing.assert_allclose(np.asarray(outer.normal_load), np.asarray(qs.outer_load), rtol=1e-9)
    np.testing.assert_allclose(
        np.asarray(outer.slice_loads), np.asarray(qs.outer_slice_loads), rtol=1e-9, atol=1e-12
    )
    assert float(inner.normal_load[0]) == pytest.approx(float(qs.inner_load[0]), rel=1e-9)
    loaded = np.asarray(qs.inner_load) > 1.0
    np.testing.assert_allclose(
        np.asarray(inner.normal_load)[loaded], np.asarray(qs.inner_load)[loaded], rtol=5e-3
    )
    # net radial force on each roller = -m_b r_j omega_c^2 (centripetal) up to the linearised ring
    # kinematics (< 0.1 N) and F_c taken at the pitch radius, m_b (r_j - d_m/2) omega_c^2 ~ 0.03 N
    f = (
        inner.force_on_roller
        + outer.force_on_roller
        + b.roller_mass * op.gravity * jnp.array([0.0, 0.0, 1.0])
    )
    radial = jnp.sum(f * qs.radial_units, axis=-1)
    need = -b.roller_mass * qs.roller_radius * qs.cage_speed**2
    np.testing.assert_allclose(np.asarray(radial), np.asarray(need), rtol=0, atol=0.2)


def test_gradients_match_finite_differences():
    b_ref, _ = _case()

    def solution(x):
        clearance, load, crown, speed = x
        b = eqx.tree_at(lambda b: (b.radial_clearance, b.roller.crown_drop), b_ref, (clearance, crown))
        qs = quasi_static(b, jb.OperatingPoint(inner_speed=speed, radial_load=load, gravity=9.81))
        # well-conditioned outputs (their finite differences are not swamped by solver resolution)
        return jnp.stack([qs.inner_load[0], qs.inner_ring_displacement[1] * 1e6, qs.roller_radius[5] * 1e6])

    x0 = jnp.array([20e-6, 1000.0, 4e-6, jb.rpm_to_rad_s(20_000.0)])
    jac = np.asarray(jax.jit(jax.jacfwd(solution))(x0))
    f = jax.jit(solution)
    h = np.array([1e-9, 1e-2, 1e-9, 1e-1])
    fd = np.stack([(f(x0.at[i].add(h[i])) - f(x0.at[i].add(-h[i]))) / (2 * h[i]) for i in range(4)], axis=1)
    for row_ad, row_fd in zip(jac, fd):
        np.testing.assert_allclose(row_ad, row_fd, rtol=1e-5, atol=1e-6 * np.max(np.abs(row_fd)))
    assert np.all(np.abs(jac[:, 0]) > 0) and np.all(np.abs(jac[:2, 1]) > 0)


def test_bad_operating_point_is_a_user_error():
    b, _ = _case()
    with pytest.raises(UserInputError, match="radial_load"):
        quasi_static(b, jb.OperatingPoint(inner_speed=0.0, radial_load=-1.0, gravity=9.81))
    with pytest.raises(UserInputError, match="gravity"):
        quasi_static(b, jb.OperatingPoint(inner_speed=0.0, radial_load=1.0, gravity=-9.81))


def test_misaligned_ring_balances_with_the_dynamic_tilted_contact():
    """Issue 34 item 3: with an imposed misalignment psi_m = 1 mrad the quasi-static inner slice
    interferences carry the tilt's slope -sin(psi_m) cos(psi_j) along the roller (docs/model.md 3a,
    12), so the dynamic model's own tilted raceway contact (`raceway_contact` with the ring axis
    `ring_axis((psi_m, 0))`) at the solution gives the quasi-static inner loads (as aligned, to the
    documented linear ring kinematics) and the ring's radial balance holds. The aligned
    solution placed against the tilted ring, the start used before, overloads the ring by more than
    30 % (its loaded rollers pick up the tilt's edge load)."""
    from jaxbearing.geometry._ring import ring_axis

    b, op = _case()
    mis = eqx.tree_at(lambda o: o.misalignment, op, 1e-3)
    axis = ring_axis(jnp.array([1e-3, 0.0]))

    def inner_loads(qs):
        p = qs.roller_centres
        e = jnp.broadcast_to(X, p.shape)
        zeros = jnp.zeros_like(p)

        def one(p, e, v, w):
            return raceway_contact(
                b, 1.0, b.inner_raceway_radius, p, e, v, w, qs.inner_ring_centre, ZERO, ZERO, ring_axis=axis
            )

        return jax.jit(jax.vmap(one))(p, e, zeros, zeros)

    qs = _qs(b, mis)
    inner = inner_loads(qs)
    loaded = np.asarray(qs.inner_load) > 1.0
    heavy = np.asarray(qs.inner_load) > 100.0
    # measured: 0.1 % on the three heaviest rollers, 0.53 % on the light flank rollers (19 N)
    np.testing.assert_allclose(
        np.asarray(inner.normal_load)[heavy], np.asarray(qs.inner_load)[heavy], rtol=2e-3
    )
    np.testing.assert_allclose(
        np.asarray(inner.normal_load)[loaded], np.asarray(qs.inner_load)[loaded], rtol=1e-2
    )
    ring_load = op.radial_load + b.inner_ring_mass * op.gravity
    assert float(jnp.sum(qs.inner_load * qs.radial_units[:, 2])) == pytest.approx(float(ring_load), rel=1e-9)
    carried = float(jnp.sum(inner.normal_load * qs.radial_units[:, 2]))
    assert carried == pytest.approx(float(ring_load), rel=5e-3)
    # the aligned solution against the tilted ring
    before = float(jnp.sum(inner_loads(_qs(b, op)).normal_load * qs.radial_units[:, 2]))
    assert before > 1.3 * float(ring_load)
