"""The skid start (issue 11): the static skid equilibrium against its closed-form limit (no drag,
no land film, no gravity: pure rolling), its own equations, the dynamics started from it, and the
pre-start that lands it on the settled plateau.

The dynamic checks run the reference bearing with 11 slices per raceway (the `test_settle`
configuration) over two or three cage revolutions, all through the settled run's compiled
`solve_from`."""

import dataclasses

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing.dynamics import Params, contact_loads, physical_rates, skid_balance, skid_zones
from jaxbearing.geometry import kinematic_cage_speed
from jaxbearing.run import Perturbation, skid_start
from jaxbearing.run._initial import kinematic_start


@pytest.fixture(scope="module")
def reference():
    b = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    return b, jb.reference_operating_point()


@pytest.fixture(scope="module")
def reference_skid(reference):
    b, op = reference
    return skid_start(b, op, Perturbation())


def test_no_drag_no_land_film_gives_pure_rolling(reference):
    """With oil fraction 0 (no drag, no land film or Petroff torque) and no gravity, nothing
    brakes the rollers or the cage: the skid equilibrium is the kinematic one, cage speed
    omega_i (1 - D/d_m)/2 and roller spin -omega_c d_m/D (Harris & Kotzalas, Essential
    Concepts, ch. 8), to the elastic rolling radii (1e-3)."""
    b, op = reference
    b = eqx.tree_at(lambda b: b.lubricant.oil_fraction, b, 0.0)
    op = eqx.tree_at(lambda o: o.gravity, op, 0.0)
    # no scatter, as a zero-amplitude perturbation: the skid-start program every other skid start
    # in the suite uses (None is a program of its own, 18 s cold)
    skid = skid_start(b, op, Perturbation(axial=0.0, skew=0.0))
    w_kin = float(kinematic_cage_speed(b, op))
    assert float(skid.equilibrium.cage_speed) == pytest.approx(w_kin, rel=1e-3)
    spin = np.asarray(skid.state.rollers.angular_velocity[:, 0])
    np.testing.assert_allclose(spin, -w_kin * b.pitch_diameter / b.roller.diameter, rtol=1e-3)


def test_skid_equilibrium_balances_the_slow_equations(reference, reference_skid):
    """At the solution the spin, orbit and cage accelerations vanish (to the bisection and
    Newton precision, against the accelerations of the kinematic start), the cage runs below
    the kinematic speed (drag and land torques), and every roller rests on a pocket wall."""
    b, op = reference
    eq = reference_skid.equilibrium
    params = Params(bearing=b, operating=op)
    kin = kinematic_start(b, op, Perturbation())  # `initial_state`, compiled
    rates0 = jax.jit(physical_rates)(0.0, kin, params)
    spin_scale = float(jnp.max(jnp.abs(rates0.rollers.angular_velocity[:, 0])))
    assert float(jnp.max(jnp.abs(eq.spin_residual))) < 1e-6 * spin_scale
    assert float(jnp.max(jnp.abs(eq.orbit_residual))) < 1e-6 * float(
        jnp.max(jnp.abs(rates0.rollers.azimuth_rate))
    )
    assert abs(float(eq.cage_torque_residual)) < 1e-6 * abs(float(rates0.cage.speed))
    assert float(jnp.max(jnp.abs(eq.cage_force_residual))) < 1e-2  # m/s^2 (gravity: 9.81)
    w_kin = float(kinematic_cage_speed(b, op))
    assert 0.6 * w_kin < float(eq.cage_speed) < 0.999 * w_kin
    pocket = jax.jit(contact_loads)(reference_skid.state, params).pocket
    assert np.all(np.asarray(jnp.sum(jnp.abs(pocket.force_on_roller), axis=-1)) > 1e-3)
    assert 0.005 < float(reference_skid.time_constant) < 0.5  # s: the slow mode of the cage


def test_skid_balance_resolves_the_equations_and_caps_the_drive(reference, reference_skid):
    """`skid_balance` splits the vector field's own sums: per roller, the orbit torques add up to
    m_b r^2 theta'' and the spin moments to I_a (d omega/dt).e; the cage torques to I_p omega_c'
    (all three near zero at the equilibrium). Past the traction peak (20,000 rpm: several m/s of
    sliding on the inner raceway) the traction coefficient is its asymptote D to 1e-6
    (kappa(du) - D = (A + B du) exp(-C du)), so the inner-raceway drive of each loaded roller is
    the closed form D Q_i r_j: to 1 % per roller (the displaced inner ring's contact normals lean
    by about 1e-4 rad, so the normal force adds +/-0.4 % of the traction on the two flanks of the
    load zone) and to 1e-3 summed over the zone, where the two flanks cancel."""
    b, op = reference
    eq = reference_skid.equilibrium
    t = skid_balance(eq.state, Params(bearing=b, operating=op))
    r = np.asarray(eq.state.rollers.radial)
    orbit = sum(
        np.asarray(getattr(t, k))
        for k in ("orbit_inner", "orbit_outer", "orbit_flange", "orbit_pocket", "orbit_drag", "orbit_gravity")
    )
    spin = sum(
        np.asarray(getattr(t, k))
        for k in ("spin_inner", "spin_outer", "spin_flange", "spin_pocket", "spin_drag")
    )
    scale = float(np.max(np.abs(t.orbit_pocket)))
    np.testing.assert_allclose(
        orbit, float(b.roller_mass) * r**2 * np.asarray(eq.orbit_residual), atol=1e-9 * scale
    )
    np.testing.assert_allclose(
        spin, float(b.roller_inertia[0]) * np.asarray(eq.spin_residual), atol=1e-9 * scale
    )
    cage = float(t.cage_pocket + t.cage_land + t.cage_drag)
    assert cage == pytest.approx(float(b.cage_inertia[0] * eq.cage_torque_residual), abs=1e-9 * scale)
    assert np.max(np.abs(orbit)) < 1e-6 * scale and abs(cage) < 1e-6 * abs(float(t.cage_pocket))
    loaded = np.asarray(t.loaded)
    assert 3 <= loaded.sum() < b.num_rollers and float(np.min(t.inner_sliding[loaded])) > 2.0  # m/s
    d = float(b.lubricant.traction_d)
    closed = d * np.asarray(t.inner_load)[loaded] * r[loaded]
    np.testing.assert_allclose(np.asarray(t.orbit_inner)[loaded], closed, rtol=1e-2)
    z = skid_zones(t)  # by zone: the roller set's terms add up to minus the pocket term
    rollers = z.inner_traction_loaded + z.outer_traction_loaded + z.outer_traction_unloaded
    rollers = rollers + z.roller_drag + z.flange + z.gravity
    assert float(rollers) == pytest.approx(-float(z.pocket_on_rollers), abs=1e-6 * scale)
    assert float(z.inner_traction_loaded) == pytest.approx(float(np.sum(closed)), rel=1e-3)


def test_no_start_up_step_from_the_skid_start(reference, reference_skid):
    """The dynamics from the skid start: the first revolution's mean cage speed is within 0.2 %
    of the start (the quasi-static start falls 0.3 % in its first revolution and 7 % in all),
    and the second revolution's within 0.2 % of the first."""
    state = reference_skid.state
    w0 = float(state.cage.speed)
    means = _revolution_means(_integrator(reference), state, 2)
    assert abs(means[0] - w0) < 2e-3 * w0
    assert abs(means[1] - means[0]) < 2e-3 * w0


def _integrator(reference):
    """The settled run's own integrator (`solve_from` compiled with `simulate_steady`'s saves,
    step limit and tolerances), as `skid_start`'s pre-start takes it: the program of every
    11-slice settled run in the suite (tests/test_settle.py, notebook 03), compiled once."""
    from jaxbearing.run import SAVES_PER_REV
    from jaxbearing.run._solve_from import _integrator

    params = Params(bearing=reference[0], operating=reference[1])
    return _integrator(params, SAVES_PER_REV, 2_000_000, 1e-3, 1e-6, [])


def _revolution_means(integrate, state, n):
    """Mean cage speed of each of `n` cage revolutions from `state`."""
    means = []
    for _ in range(n):
        hist, state, code, _ = integrate(state, 2 * np.pi / float(state.cage.speed))
        assert int(code) == 0
        means.append(float(np.mean(hist["cage_speed"])))
    return means


#: the band a revolution-mean cage speed must keep around the plateau from revolution 1 on: the
#: half-width of the ensemble 95 % CI of the settled cage speed at the reference point (4 seeds,
#: docs/performance-history.md: 8417 [8415, 8420] rpm, +/- 0.03 %), the yardstick docs/model.md 16 gives for the cage
#: speed (one seed's batch-means interval, +/- 0.2 rpm, is narrower than the 0.3 rpm that halving
#: rtol moves the plateau)
PLATEAU_BAND = 3e-4


def test_skid_start_lands_on_the_plateau(reference):
    """With the pre-start (the run's own integrator given), the start is on the plateau: over
    three cage revolutions every revolution's mean cage speed, the first included, lies within
    `PLATEAU_BAND` of the mean of the last two (the static skid start drifts 1.3 % to its plateau
    with a 60 ms time constant, about 12 rpm = 0.15 % per revolution here), and the first
    revolution's mean is within 0.2 % of the handed-over cage speed (no start-up step)."""
    b, op = reference
    integrate = _integrator(reference)
    skid = skid_start(b, op, Perturbation(), integrate=integrate)
    assert skid.pre_start_status == "ok"
    w0 = float(skid.state.cage.speed)
    assert float(skid.equilibrium.cage_speed) > skid.plateau_speed  # the flanges brake it
    means = np.asarray(_revolution_means(integrate, skid.state, 3))
    plateau = means[1:].mean()
    assert np.all(np.abs(means - plateau) < PLATEAU_BAND * plateau), (means, plateau)
    assert abs(means[0] - w0) < 2e-3 * w0


def test_cage_drift_is_the_least_squares_line():
    """`cage_drift` returns a line's own mean, slope and end value, ignores the samples before
    `since`, and with a rattle on top agrees with numpy's least-squares polyfit."""
    from jaxbearing.run._initial import cage_drift

    t = np.linspace(0.0, 0.01, 1001)
    line = 800.0 - 150.0 * t
    w = np.where(t < 0.002, 0.0, line)  # the skew-in part is left out
    mean, drift, end = cage_drift(t, w, 0.002)
    kept = t >= 0.002
    assert drift == pytest.approx(-150.0, rel=1e-9)
    assert mean == pytest.approx(line[kept].mean(), rel=1e-12)
    assert end == pytest.approx(line[-1], rel=1e-12)
    rattle = line + 0.3 * np.sin(2 * np.pi * 37 * t / 0.008)
    _, drift, end = cage_drift(t, rattle, 0.002)
    slope, intercept = np.polyfit(t[kept], rattle[kept], 1)
    assert drift == pytest.approx(slope, rel=1e-9)
    assert end == pytest.approx(intercept + slope * t[-1], rel=1e-9)
