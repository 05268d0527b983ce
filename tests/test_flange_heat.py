"""Friction power and flash temperature of the roller-end/flange contacts (docs/model.md 5.5):
the friction power against its closed form and against the work of the contact's own friction
force, Tian & Kennedy's moving-source maximum against its two exact limits and a quadrature of
Jaeger's exact moving-source solution, Blok's partition, the steel constants in the
configuration, and the settled statistics with their intervals from hand-made histories."""

import dataclasses
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy import integrate
from scipy.optimize import minimize_scalar

import jaxbearing as jb
from jaxbearing.flange import (
    FLANGE_ORDER,
    FlangeContact,
    all_flange_contacts,
    blok_flash_temperature,
    contact_point_velocity,
    flange_flash_temperature,
    flange_friction_power,
    flange_geometry,
    flange_heat_source_speeds,
    flash_temperature_factor,
    friction_power,
)
from jaxbearing.geometry import BEARING_TYPES, Material
from jaxbearing.run import FRICTION_POWER_KEYS, FrictionPower, settled_statistics, summarise

X = np.array([1.0, 0.0, 0.0])
OMEGA_I = jb.rpm_to_rad_s(20_000.0)


# -- friction power ------------------------------------------------------------------------------
def _hand_contacts(q, mu, speed) -> FlangeContact:
    """A FlangeContact of shape (Z, 4) with the given Q, mu and |u| and zeros elsewhere."""
    shapes = {"3": (3,), "2": (2,)}
    fields = {}
    for f in dataclasses.fields(FlangeContact):
        trailing = shapes.get(str(f.type).split()[-1].rstrip("]\"'"), ())
        fields[f.name] = jnp.zeros(q.shape + trailing)
    fields.update(normal_force=jnp.asarray(q), friction_coefficient=jnp.asarray(mu))
    return FlangeContact(**{**fields, "sliding_speed": jnp.asarray(speed)})


def test_friction_power_closed_form():
    """P = mu Q |u| per contact; per flange the sum over the rollers, an unloaded flange 0."""
    q = np.array([[100.0, 0.0, 20.0, 0.0], [50.0, 0.0, 0.0, 0.0], [10.0, 0.0, 5.0, 0.0]])
    mu = np.full_like(q, 0.02)
    speed = np.array([[2.0, 9.0, 1.0, 9.0], [4.0, 9.0, 1.0, 9.0], [1.0, 9.0, 3.0, 9.0]])
    c = _hand_contacts(q, mu, speed)
    np.testing.assert_allclose(friction_power(c), mu * q * speed, rtol=1e-15)
    # flange 0: 0.02 (200 + 200 + 10) = 8.2 W; flange 2: 0.02 (20 + 15) = 0.7 W
    np.testing.assert_allclose(flange_friction_power(c), [8.2, 0.0, 0.7, 0.0], rtol=1e-14)


def _pressed_rolling(bearing, z=6, seed=0):
    """Every roller pressing on all four flanges (flange spacing 20 um shorter than the rollers),
    rolling at the kinematic cage speed with a random skew of about 2 mrad: (bearing, contacts,
    roller axes)."""
    b = eqx.tree_at(lambda b: b.flange.axial_clearance, bearing, jnp.asarray(-20e-6))
    rng = np.random.default_rng(seed)
    az = np.linspace(0, 2 * np.pi, z, endpoint=False)
    e_rad = np.stack([np.zeros(z), np.sin(az), np.cos(az)], 1)
    dm, d = float(b.pitch_diameter), float(b.roller.diameter)
    w_c = OMEGA_I * (1 - d / dm) / 2
    p = dm / 2 * e_rad
    e = X + np.cross(e_rad, X) * rng.normal(0, 2e-3, (z, 1))
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    v = np.cross(w_c * X, p)
    w = np.outer(np.full(z, w_c - 2 * w_c * float(b.outer_raceway_radius) / d), X)
    zero = np.zeros(3)
    contacts = jax.jit(all_flange_contacts)(b, p, e, v, w, zero, zero, OMEGA_I * X, zero, zero, zero)
    return b, contacts, e


@pytest.fixture(scope="module")
def pressed():
    return _pressed_rolling(jb.reference_bearing())


def test_friction_power_is_the_work_of_the_friction_force(pressed):
    """The total friction power of the whole bearing equals the power sum |F_t . u| of the
    contacts' friction forces (F = -Q n + F_t on the roller, u tangential, so F . u = F_t . u),
    to the regularisation |u| / sqrt(|u|^2 + u_eps^2) of the friction direction (u_eps = 1 mm/s)."""
    _, c, _ = pressed
    q, u = np.asarray(c.normal_force), np.asarray(c.sliding_velocity)
    assert np.all(q > 1.0) and np.all(np.asarray(c.sliding_speed) > 0.1)
    work = np.abs(np.sum(np.asarray(c.force_on_roller) * u, axis=-1))
    speed = np.linalg.norm(u, axis=-1)
    power = np.asarray(friction_power(c))
    np.testing.assert_allclose(work, power * speed / np.sqrt(speed**2 + 1e-6), rtol=1e-9)
    np.testing.assert_allclose(np.sum(work), np.sum(power), rtol=1e-6)
    np.testing.assert_allclose(np.sum(flange_friction_power(c)), np.sum(power), rtol=1e-14)


# -- flash temperature ---------------------------------------------------------------------------
def _exact_max(peclet):
    """The largest surface temperature, in units of q a / k, of a uniform disc source (radius 1,
    kappa = 1) moving at V = 2 Pe over a half-space: the quasi-steady moving point-source solution
    T = q / (2 pi k R) exp(-V (R + xi) / (2 kappa)) (Carslaw & Jaeger 10.7; Jaeger 1942) integrated
    over the disc, maximised along the centre line behind the centre."""
    v = 2.0 * peclet

    def temperature(x):
        def ray(phi):  # source points at distance R along direction phi from the field point
            c = math.cos(phi)
            disc = (x * c) ** 2 - (x * x - 1.0)
            r1, r2 = max(0.0, -x * c - math.sqrt(disc)), -x * c + math.sqrt(disc)
            k = v * (1.0 - c) / 2.0
            return r2 - r1 if k < 1e-14 else (math.exp(-k * r1) - math.exp(-k * r2)) / k

        return integrate.quad(ray, 0.0, 2 * math.pi, limit=200, points=[math.pi])[0] / (2 * math.pi)

    return -minimize_scalar(lambda x: -temperature(x), bounds=(-1.0, 0.0), method="bounded").fun


def test_tian_kennedy_limits_and_the_exact_moving_source():
    """f(Pe) -> 1 (the stationary disc's centre, q a / k) as Pe -> 0, -> 2 / sqrt(pi Pe) (the
    one-dimensional surface temperature after the time 2 a / V under the source) as Pe -> inf,
    and within 3 % of the exact moving-source maximum in between."""
    np.testing.assert_allclose(float(flash_temperature_factor(0.0)), 1.0, rtol=2e-4)
    np.testing.assert_allclose(float(flash_temperature_factor(1e8)), 2 / math.sqrt(math.pi * 1e8), rtol=1e-8)
    np.testing.assert_allclose(_exact_max(1e-3), 1.0, rtol=1e-3)  # the quadrature's own limit
    for pe in (0.3, 1.0, 3.0, 10.0, 30.0):
        np.testing.assert_allclose(float(flash_temperature_factor(pe)), _exact_max(pe), rtol=0.03)


def test_blok_partition_equal_surface_temperatures():
    """The heat shares beta and 1 - beta that Blok's postulate gives make both bodies' largest
    temperatures equal: beta q a f_1 / k_1 = (1 - beta) q a f_2 / k_2 = Delta T; two equal bodies
    at rest share the heat evenly, Delta T = (q a / k) f(0) / 2."""
    power, a = 30.0, 0.2e-3
    q = power / (math.pi * a * a)
    k, kappa = (35.0, 47.0), (9.5e-6, 12.8e-6)
    for speeds in ((0.0, 0.0), (5.0, 25.0), (40.0, 0.5)):
        dt = float(blok_flash_temperature(power, a, speeds, k, kappa))
        f = [float(flash_temperature_factor(v * a / (2 * d))) for v, d in zip(speeds, kappa)]
        beta = dt * k[0] / (q * a * f[0])
        np.testing.assert_allclose(beta + dt * k[1] / (q * a * f[1]), 1.0, rtol=1e-12)
    even = float(blok_flash_temperature(power, a, (0.0, 0.0), (40.0, 40.0), (1e-5, 1e-5)))
    np.testing.assert_allclose(even, q * a / 40.0 * float(flash_temperature_factor(0.0)) / 2, rtol=1e-12)
    assert float(blok_flash_temperature(0.0, a, (1.0, 1.0), k, kappa)) == 0.0
    assert float(blok_flash_temperature(power, 0.0, (1.0, 1.0), k, kappa)) == 0.0


def test_heat_source_speeds_are_the_surfaces_relative_to_the_contact(pressed):
    """V_1 = |P_t (v_1(C) - v_C)|, V_2 = |P_t (v_2(C) - v_C)| by hand for roller 0 on each flange."""
    b, c, axes = pressed
    v1, v2 = (np.asarray(s) for s in flange_heat_source_speeds(c))
    dm, d = float(b.pitch_diameter), float(b.roller.diameter)
    w_c = OMEGA_I * (1 - d / dm) / 2
    for f, (ring_sign, side) in enumerate(FLANGE_ORDER):
        cp = np.asarray(c.contact_point[0, f])
        p = np.array([0.0, 0.0, dm / 2])
        v = np.cross(w_c * X, p)
        w = (w_c - 2 * w_c * float(b.outer_raceway_radius) / d) * X
        w_ring = OMEGA_I * X if ring_sign > 0 else np.zeros(3)
        radius = b.inner_raceway_radius if ring_sign > 0 else b.outer_raceway_radius
        n = np.asarray(flange_geometry(b, radius, side, ring_sign, p, axes[0], np.zeros(3)).normal)
        v_c = np.asarray(contact_point_velocity(p, v, np.zeros(3), np.zeros(3), cp))
        for got, body in ((v1[0, f], v + np.cross(w, cp - p)), (v2[0, f], np.cross(w_ring, cp))):
            rel = body - v_c
            np.testing.assert_allclose(got, np.linalg.norm(rel - np.dot(rel, n) * n), rtol=1e-9)


def test_flash_temperature_of_the_contacts(pressed):
    """Positive at every loaded contact, zero at the flanges a bearing type lacks, the same as
    Blok's formula with the contact's own numbers, with finite gradients in the thermal constants."""
    b, c, axes = pressed
    dt = np.asarray(flange_flash_temperature(b, c))
    assert np.all(dt > 0) and np.all(np.isfinite(dt))
    semi = np.asarray(c.ellipse_semi_axes)
    v1, v2 = flange_heat_source_speeds(c)
    mats = (b.roller_material, b.ring_material)
    hand = blok_flash_temperature(
        friction_power(c),
        np.sqrt(semi[..., 0] * semi[..., 1]),
        (v1, v2),
        tuple(m.thermal_conductivity for m in mats),
        tuple(m.thermal_diffusivity for m in mats),
    )
    np.testing.assert_allclose(dt, hand, rtol=1e-14)
    nu = eqx.tree_at(lambda x: x.flange_presence, b, jnp.asarray(BEARING_TYPES["NU"]))
    _, c_nu, _ = _pressed_rolling(nu)
    dt_nu = np.asarray(flange_flash_temperature(nu, c_nu))
    absent = np.asarray(BEARING_TYPES["NU"]) == 0.0
    assert np.all(dt_nu[:, absent] == 0.0) and np.all(dt_nu[:, ~absent] > 0)

    def peak(k):
        m = eqx.tree_at(lambda x: x.ring_material.thermal_conductivity, nu, k)
        return jnp.max(flange_flash_temperature(m, c_nu))

    g = float(jax.grad(peak)(jnp.asarray(35.0)))
    assert np.isfinite(g) and g < 0  # a better conducting rib runs cooler


# -- the constants in the configuration ------------------------------------------------------------
def test_steel_constants_in_the_configuration():
    """Reference M50 rings and rollers (35 W/(m K), 470 J/(kg K)); the Material default is
    AISI 52100 (47, 470); kappa = k / (rho c); an out-of-range value is one line naming the key."""
    b = jb.reference_bearing()
    assert float(b.ring_material.thermal_conductivity) == 35.0
    assert float(b.roller_material.specific_heat) == 470.0
    np.testing.assert_allclose(float(b.ring_material.thermal_diffusivity), 35.0 / (7830.0 * 470.0))
    m = Material(elastic_modulus=208e9, poisson_ratio=0.3, density=7810.0)
    assert (float(m.thermal_conductivity), float(m.specific_heat)) == (47.0, 470.0)
    cfg = jb.loads_config("[materials.roller]\nthermal_conductivity_W_mK = 40.0\nspecific_heat_J_kgK = 460\n")
    assert float(cfg.bearing().roller_material.thermal_conductivity) == 40.0
    for text, words in (
        (
            "thermal_conductivity_W_mK = 0",
            "materials.ring.thermal_conductivity_W_mK: 0.0 W/(m K) is out of range",
        ),
        ("specific_heat_J_kgK = 6000", "materials.ring.specific_heat_J_kgK: 6000.0 J/(kg K) is out of range"),
    ):
        with pytest.raises(jb.ConfigError) as err:
            jb.loads_config(f"[materials.ring]\n{text}\n")
        assert str(err.value).startswith(words) and "\n" not in str(err.value)


# -- the statistics ------------------------------------------------------------------------------
def _heat_history(n=200, z=2):
    """Two cage revolutions [0, 10 ms), [10, 20 ms). Friction power: roller 0 on flange 0 at 4 W
    and roller 1 on flange 2 at 1 W all the time, plus 6 W on flange 1 (roller 0) during the 40
    samples 20-59 of revolution 0; one contact event per revolution on flange 0 whose flash
    temperature peaks at 80 K (revolution 0) and 120 K (revolution 1)."""
    t = np.linspace(0.0, 0.02, n, endpoint=False)
    shape = (n, z, 4)
    force = np.zeros(shape)
    force[20:60, 0, 0] = 50.0
    force[120:160, 0, 0] = 50.0
    power = np.zeros(shape)
    power[:, 0, 0], power[:, 1, 2] = 4.0, 1.0
    power[20:60, 0, 1] = 6.0
    flash = np.zeros(shape)
    flash[20:60, 0, 0] = np.linspace(10.0, 80.0, 40)
    flash[120:160, 0, 0] = np.linspace(120.0, 20.0, 40)
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
        flange_friction_power=power,
        flange_flash_temperature=flash,
        cage_speed=np.full(n, 100.0),
        roller_skew=np.zeros((n, z)),
    )


def test_settled_statistics_of_friction_power_and_flash_temperature():
    """Per revolution: the time-mean friction power per flange and in total (flange 1: 6 W x 40
    of 100 samples in revolution 0, none in revolution 1), the events' flash temperature; the
    estimate is the mean over the two revolutions with a Student-t interval."""
    hist = _heat_history()
    stats = settled_statistics(
        [hist], [[0.0, 0.01, 0.02]], jb.reference_bearing(), jb.reference_operating_point()
    )
    power = stats.flange_friction_power_W
    assert isinstance(power, FrictionPower)
    assert [f"flange_friction_power_W.{f.name}" for f in dataclasses.fields(FrictionPower)] == list(
        FRICTION_POWER_KEYS
    )
    np.testing.assert_allclose(power.inner_neg_x.value, 4.0)
    np.testing.assert_allclose(power.inner_pos_x.value, (2.4 + 0.0) / 2)
    np.testing.assert_allclose(power.outer_neg_x.value, 1.0)
    assert power.outer_pos_x.value == 0.0
    np.testing.assert_allclose(power.total.value, 5.0 + 1.2)
    half = 12.706204736174707 * 2.4 / 2  # t_{1, 0.975} s / sqrt(2), s = 2.4 / sqrt(2)
    np.testing.assert_allclose(power.total.half_width, half, rtol=1e-9)
    assert power.total.n == 2
    flash = stats.flange_flash_temperature_K
    np.testing.assert_allclose(flash.max.value, (80.0 + 120.0) / 2)
    block = stats.as_dict()
    assert set(block["flange_friction_power_W"]) == {
        "inner_neg_x",
        "inner_pos_x",
        "outer_neg_x",
        "outer_pos_x",
        "total",
    }
    assert set(block["flange_flash_temperature_K"]["p95"]) == {"value", "ci95_low", "ci95_high", "n"}
    assert {"median", "p05"} <= set(block["film_parameter"])  # Lambda beside them


def test_transient_summary_has_friction_power_and_flash_temperature():
    """A start-up transient's summary: the time-mean friction power over the run and the flash
    temperature over events; histories without them (older runs) give None, never a KeyError."""
    import types

    hist = _heat_history()
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
    np.testing.assert_allclose(s["flange_friction_power_W"]["total"], 5.0 + 6.0 * 40 / 200)
    np.testing.assert_allclose(s["flange_flash_temperature_K"]["max"], 120.0)
    old = {k: v for k, v in hist.items() if k not in ("flange_friction_power", "flange_flash_temperature")}
    s_old = summarise(types.SimpleNamespace(**{**vars(result), "histories": old}))
    assert s_old["flange_friction_power_W"]["total"] is None
    assert s_old["flange_flash_temperature_K"]["max"] is None
