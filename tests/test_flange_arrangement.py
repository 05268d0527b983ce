"""Flange arrangement by bearing type (docs/model.md 5.3, `bearing.type`): the configuration key
and its checks, absent flanges carrying nothing in the contact model, and short runs of the
full-size bearing comparing NU and NJ with the reference NUP from the same start (1 ms, and 3 ms
for the NUP under an axial load, from the quasi-static start with 4000 saves: the program
tests/test_cmd_simulate.py compiles, conftest.PROGRAM_GROUPS). The static axial-load balance of NU against NUP is
tests/test_misalignment.py's `test_nu_inner_ring_floats_under_axial_load`."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing import ConfigError
from jaxbearing.flange import all_flange_contacts, without_absent_flanges
from jaxbearing.geometry import BEARING_TYPES, FLANGES, arrangement_of
from jaxbearing.io import validate_bearing

#: the flanges of each type written out (order inner -X, inner +X, outer -X, outer +X), from the
#: catalogue definitions, not read from the code's table
EXPECTED = {
    "NUP": (1.0, 1.0, 1.0, 1.0),
    "NU": (0.0, 0.0, 1.0, 1.0),
    "N": (1.0, 1.0, 0.0, 0.0),
    "NJ": (1.0, 0.0, 1.0, 1.0),
}


def _typed(arrangement, **operating) -> jb.Config:
    return jb.Config({"bearing": {"type": arrangement}, "operating": operating})


def _with_presence(bearing, presence):
    return eqx.tree_at(lambda b: b.flange_presence, bearing, jnp.asarray(presence, dtype=float))


# -- the configuration key -------------------------------------------------------------------------
@pytest.mark.parametrize("name", list(EXPECTED))
def test_each_type_maps_to_its_flanges(name):
    presence = np.asarray(_typed(name).bearing().flange_presence)
    assert presence.tolist() == list(EXPECTED[name])
    assert arrangement_of(presence) == name


def test_reference_is_nup_and_a_custom_set_in_any_order():
    assert jb.reference_config()["bearing.type"] == "NUP"
    assert np.asarray(jb.reference_bearing().flange_presence).tolist() == [1.0] * 4
    cfg = _typed(["outer+X", "inner-X", "outer-X"])  # an NJ written as a set
    assert cfg["bearing.type"] == ("outer+X", "inner-X", "outer-X")
    assert np.asarray(cfg.bearing().flange_presence).tolist() == [1.0, 0.0, 1.0, 1.0]
    assert arrangement_of(cfg.bearing().flange_presence) == "NJ"
    assert arrangement_of([0.0, 1.0, 1.0, 1.0]) == ("inner+X", "outer-X", "outer+X")
    assert FLANGES == ("inner-X", "inner+X", "outer-X", "outer+X")
    assert set(BEARING_TYPES) == set(EXPECTED)


@pytest.mark.parametrize("arrangement", ["NU", "NJ", ["outer+X", "outer-X", "inner+X"]])
def test_toml_round_trip(arrangement):
    cfg = _typed(arrangement)
    for comments in (True, False):
        text = cfg.to_toml(comments=comments)
        assert jb.loads_config(text) == cfg
    line = next(li for li in cfg.to_toml().splitlines() if li.startswith("type = "))
    if isinstance(arrangement, str):
        assert line == f'type = "{arrangement}"'
    else:
        assert line == 'type = ["outer+X", "outer-X", "inner+X"]'
    assert "bearing.type" in cfg.changed()


@pytest.mark.parametrize(
    ("toml", "fragment"),
    [
        ('"NX"', '"NX" is not one of "NUP", "NU", "N", "NJ" or a list of distinct names from "inner-X"'),
        ('"nu"', '"nu" is not one of "NUP", "NU", "N", "NJ"'),
        (
            '["outer-X", "outer+Y"]',
            '"outer+Y" is not one of the names "inner-X", "inner+X", "outer-X", "outer+X"',
        ),
        ('["outer-X", "outer-X", "outer+X"]', 'names "outer-X" twice'),
        (
            '["outer-X", "inner-X"]',
            'no flange on the +X side, so nothing locates the rollers axially: add "inner+X" or',
        ),
        ("[]", "no flange on the -X side"),
        ("3", "expected a string or a list of strings (one of"),
        ("[1, 2]", "expected a string or a list of strings"),
    ],
)
def test_invalid_arrangement_is_one_line(toml, fragment):
    with pytest.raises(ConfigError) as exc:
        jb.loads_config(f"[bearing]\ntype = {toml}\n")
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("bearing.type: ") and exc.value.field == "bearing.type"
    assert fragment in msg


@pytest.mark.parametrize(
    ("name", "load", "valid"),
    [("NU", 100.0, "0"), ("NU", -100.0, "0"), ("N", 100.0, "0"), ("NJ", -100.0, ">= 0")],
)
def test_axial_load_without_a_flange_path_goes_to_the_locating_bearing(name, load, valid):
    """No flange path for the load: with the ring free axially it is an error (the ring would be
    pushed off the rollers); with the ring held axially (the default) the load is accepted and
    carried by the shaft's locating bearing (docs/model.md 5.3)."""
    with pytest.raises(ConfigError) as exc:
        _typed(name, axial_load_N=load, inner_ring_axial_freedom=True)
    msg = str(exc.value)
    assert "\n" not in msg and exc.value.field == "operating.axial_load_N"
    assert f'no flange path in bearing.type = "{name}"' in msg and f"must be {valid} N" in msg
    assert "locating bearing carries it and holds the inner ring" in msg
    # the same rule on a pytree built in Python (what `simulate` checks first)
    cfg_free = _typed(name, inner_ring_axial_freedom=True)
    op = eqx.tree_at(lambda o: o.axial_load, cfg_free.operating_point(), jnp.asarray(load))
    with pytest.raises(ConfigError, match="operating.axial_load_N: .* no flange path"):
        validate_bearing(cfg_free.bearing(), op)
    with pytest.raises(ConfigError, match="no flange path"):
        jb.simulate(cfg_free.bearing(), op, duration=1e-4, num_saves=10)
    # held axially: valid, in the configuration and on the pytree
    held = _typed(name, axial_load_N=load)
    assert held["operating.axial_load_N"] == load and held.operating_point().axial_freedom == 0.0
    validate_bearing(held.bearing(), held.operating_point())


def test_axial_load_carried_by_nup_and_nj_along_x():
    for name, loads in (("NUP", (100.0, -100.0)), ("NJ", (100.0,))):
        for load in loads:
            assert (
                _typed(name, axial_load_N=load, inner_ring_axial_freedom=True)["operating.axial_load_N"]
                == load
            )
            # a load the flanges carry needs the ring free axially (held, it would do nothing)
            with pytest.raises(ConfigError, match="needs operating.inner_ring_axial_freedom = true"):
                _typed(name, axial_load_N=load)
    # NU with the axial freedom and no load: the inner ring floats (valid)
    assert _typed("NU", inner_ring_axial_freedom=True).operating_point().axial_freedom == 1.0


def test_validate_bearing_checks_the_presence_pytree():
    b = jb.reference_bearing()
    validate_bearing(_with_presence(b, EXPECTED["NU"]))
    with pytest.raises(ConfigError) as exc:
        validate_bearing(_with_presence(b, [1.0, 0.5, 1.0, 1.0]))
    msg = str(exc.value)
    assert "\n" not in msg
    assert (
        msg
        == "bearing.type: presence of flange inner+X = 0.5 is out of range: must be 1.0 (there) or 0.0 (absent)"
    )
    with pytest.raises(
        ConfigError, match=r'^bearing.type: \["inner-X", "outer-X"\] has no flange on the \+X'
    ):
        validate_bearing(_with_presence(b, [1.0, 0.0, 1.0, 0.0]))
    # a stacked batch: NUP and NU, element by element
    batch = jax.tree_util.tree_map(lambda *x: jnp.stack(x), b, _with_presence(b, EXPECTED["NU"]))
    validate_bearing(batch)
    bad = jax.tree_util.tree_map(lambda *x: jnp.stack(x), b, _with_presence(b, [0.0] * 4))
    with pytest.raises(ConfigError, match=r"^bearing.type: \(batch element \(1,\)\) \[\] has no flange"):
        validate_bearing(bad)


# -- the contact model ---------------------------------------------------------------------------
def _pressed_contacts(bearing):
    """Every roller pressing on all four flanges: the flange spacing 20 um shorter than the
    rollers (a negative axial clearance, only possible here), rollers on the pitch circle."""
    b = eqx.tree_at(lambda b: b.flange.axial_clearance, bearing, jnp.asarray(-20e-6))
    z = 6
    az = np.linspace(0, 2 * np.pi, z, endpoint=False)
    p = b.pitch_diameter / 2 * jnp.asarray(np.stack([np.zeros(z), np.sin(az), np.cos(az)], 1))
    e = np.tile([1.0, 0.0, 0.0], (z, 1))
    v = np.zeros((z, 3))
    w = np.tile([0.0, 0.0, 1000.0], (z, 1))
    zero = np.zeros(3)
    ring_w = np.array([2000.0, 0.0, 0.0])
    return jax.jit(all_flange_contacts)(b, p, e, v, w, zero, zero, ring_w, zero, zero, zero)


@pytest.fixture(scope="module")
def contacts():
    b = jb.reference_bearing()
    return {name: _pressed_contacts(_with_presence(b, flags)) for name, flags in EXPECTED.items()}


def test_absent_flanges_carry_nothing(contacts):
    """Each type: the flanges it lacks exert no force, moment, pressure or PV on any roller or
    ring, and the flanges it has give the NUP numbers bit for bit."""
    nup = contacts["NUP"]
    assert np.all(np.asarray(nup.normal_force) > 1.0)  # every flange of the NUP is loaded
    loads = ("normal_force", "peak_pressure", "pv", "ellipse_semi_axes", "force_on_roller")
    loads += ("moment_on_roller", "force_on_ring", "moment_on_ring")
    for name, flags in EXPECTED.items():
        c = contacts[name]
        for field in loads:
            got, ref = np.asarray(getattr(c, field)), np.asarray(getattr(nup, field))
            for f, there in enumerate(flags):
                if there:
                    assert np.array_equal(got[:, f], ref[:, f]), (name, field, f)
                else:
                    assert np.all(got[:, f] == 0.0), (name, field, f)
        # the geometry of an absent flange is still computed (as for an open gap)
        assert np.array_equal(np.asarray(c.contact_height), np.asarray(nup.contact_height))


def test_presence_of_ones_is_exact(contacts):
    """Multiplying by presence 1.0 changes no bit: masking the NUP contacts again is the identity."""
    nup = contacts["NUP"]
    again = without_absent_flanges(nup, jnp.ones(4))
    for a, b in zip(jax.tree_util.tree_leaves(again), jax.tree_util.tree_leaves(nup)):
        assert np.array_equal(np.asarray(a), np.asarray(b))


def test_presence_is_data_batched_and_differentiable():
    """One vmapped batch of NUP and NU equals the separate calls, and the NU's total outer-flange
    force has a gradient with respect to the layback angle (the inner flanges none)."""
    b = jb.reference_bearing()
    batch = jax.tree_util.tree_map(lambda *x: jnp.stack(x), b, _with_presence(b, EXPECTED["NU"]))
    out = jax.vmap(_pressed_contacts)(batch)
    for i, name in enumerate(("NUP", "NU")):
        one = _pressed_contacts(_with_presence(b, EXPECTED[name]))
        np.testing.assert_array_equal(np.asarray(out.normal_force[i]), np.asarray(one.normal_force))

    def per_flange(theta):
        nu = eqx.tree_at(lambda b: b.flange.layback_angle, _with_presence(b, EXPECTED["NU"]), theta)
        return jnp.sum(_pressed_contacts(nu).normal_force, axis=0)

    jac = np.asarray(jax.jacfwd(per_flange)(b.flange.layback_angle))
    assert np.all(jac[:2] == 0.0) and np.all(np.isfinite(jac)) and np.all(jac[2:] != 0.0)


# -- short runs of the full-size bearing from the quasi-static start -----------------------------
SAVES = 4000  # as `jaxbearing simulate` saves: the program of tests/test_cmd_simulate.py's runs


_RUNS: dict = {}


def _run(arrangement, duration=1e-3, **operating):
    """A run of the full-size bearing from the quasi-static start, kept for the module (the
    tests below share the NU, NUP and NJ runs)."""
    key = (str(arrangement), duration, tuple(sorted(operating.items())))
    if key not in _RUNS:
        cfg = _typed(arrangement, **operating)
        res = jb.simulate(cfg.bearing(), cfg.operating_point(), duration=duration, num_saves=SAVES)
        assert res.status == "ok"
        _RUNS[key] = res
    return _RUNS[key]


def test_nu_and_nup_at_zero_axial_load_differ_only_by_the_inner_flanges():
    """No axial load, ring held axially, 1 ms from the same start. The NU's inner flanges carry
    nothing at any sample and make no contact event; until the NUP's inner flanges first touch a
    roller (near the end of this run: the runs are then chaotic and part), every history of the
    two is the same bit for bit, so they differ only by the flanges the NU lacks; and over the
    whole run the outer flanges' loads agree (measured: time-mean outer -X flange load 0.76 N
    NUP, 0.82 N NU; largest 111 and 121 N)."""
    nup, nu = _run("NUP"), _run("NU")
    q_nup, q_nu = np.asarray(nup.histories["flange_force"]), np.asarray(nu.histories["flange_force"])
    assert np.all(q_nu[:, :, :2] == 0.0)
    events = jb.summarise(nu)
    assert events["flange_contact_events"] >= 1
    assert set(np.asarray(jb.contact_events(nu.histories)["flange"]).tolist()) <= {2, 3}
    touched = np.flatnonzero(q_nup[:, :, :2].max(axis=(1, 2)) > 0.0)
    # a contact starts between saves a few samples before it shows: 40 samples (10 us) margin
    same = (touched[0] if touched.size else SAVES) - 40
    assert same > SAVES // 2
    for name, h in nup.histories.items():
        assert np.array_equal(np.asarray(h)[:same], np.asarray(nu.histories[name])[:same], equal_nan=True), (
            name
        )
    mean_nup, mean_nu = q_nup[:, :, 2:].sum(axis=1).mean(axis=0), q_nu[:, :, 2:].sum(axis=1).mean(axis=0)
    np.testing.assert_allclose(mean_nu, mean_nup, rtol=0.25, atol=0.05)
    np.testing.assert_allclose(
        q_nu[:, :, 2:].max(axis=(0, 1)), q_nup[:, :, 2:].max(axis=(0, 1)), rtol=0.25, atol=0.5
    )


def test_nj_carries_an_axial_load_along_x_as_nup_does():
    """F_a = 200 N along +X with the axial freedom on, 1 ms: the load path is inner -X ->
    rollers -> outer +X, which the NJ has, and the NUP's inner +X flange stays open throughout,
    so the NJ (without it) runs bit for bit as the NUP; the loaded flanges carry the load
    (measured: 240 and 202 N time-mean over the last fifth against F_a = 200 N)."""
    kw = dict(axial_load_N=200.0, inner_ring_axial_freedom=True)
    nup, nj = _run("NUP", **kw), _run("NJ", **kw)
    q_nup, q_nj = np.asarray(nup.histories["flange_force"]), np.asarray(nj.histories["flange_force"])
    assert np.all(q_nj[:, :, 1] == 0.0) and np.all(q_nup[:, :, 1] == 0.0)
    for name, h in nup.histories.items():
        assert np.array_equal(np.asarray(h), np.asarray(nj.histories[name]), equal_nan=True), name
    late = q_nj[-SAVES // 5 :].sum(axis=1).mean(axis=0)
    assert late[0] > 100.0 and late[3] > 100.0 and late[2] == 0.0


def test_nu_under_an_axial_load_carries_none_at_its_flanges_and_nup_carries_it():
    """F_a = 200 N along +X on the inner ring. NU (no flange path): the ring is held axially by
    the shaft's locating bearing, which carries F_a (docs/model.md 5.3; its reaction, F_a plus
    the raceways' axial traction, is tests/test_misalignment.py's
    `test_nu_inner_ring_floats_under_axial_load`). 1 ms of the NU under the load is the NU
    without it bit for bit: the load never passes through the bearing; its inner flanges exert
    nothing and the outer flanges' axial force stays the rollers' own (time mean below 1 % of
    F_a; measured 0.8 N). NUP (free axially): the ring crosses the axial clearance and the load
    goes inner -X -> rollers -> outer +X. Axial component of flange f on its ring: s_f Q_f
    cos(theta_f) (the normal n = s cos(theta_f) X - g sin(theta_f) e_rad; friction, at most
    mu sin(theta_f) Q = 0.2 % of Q, left out). Over a 3 ms run from rest the flanges' axial
    impulse is F_a T plus the raceways' axial traction less the ring's final momentum (it
    bounces in the clearance), so the run's mean is F_a within 15 % (measured: 201.5 N at
    inner -X, 198.6 N at outer +X; inner +X and outer -X open throughout). 4-8 s each run."""
    f_a = 200.0
    nu, nu_free_of_load = _run("NU", axial_load_N=f_a), _run("NU")
    for name, h in nu.histories.items():
        assert np.array_equal(np.asarray(h), np.asarray(nu_free_of_load.histories[name]), equal_nan=True), (
            name
        )
    q_nu = np.asarray(nu.histories["flange_force"])
    assert np.all(q_nu[:, :, :2] == 0.0)
    cos_f = float(np.cos(jb.reference_bearing().flange.layback_angle))
    outer_nu = q_nu[:, :, 2:].sum(axis=1).mean(axis=0) * cos_f
    assert abs(outer_nu[1] - outer_nu[0]) < 0.01 * f_a
    nup = _run("NUP", duration=3e-3, axial_load_N=f_a, inner_ring_axial_freedom=True)
    mean = np.asarray(nup.histories["flange_force"]).sum(axis=1).mean(axis=0) * cos_f
    assert mean[1] == 0.0 and mean[2] == 0.0
    np.testing.assert_allclose(mean[[0, 3]], f_a, rtol=0.15)


def test_design_zone_is_the_same_for_every_flange():
    """The aligned roller seated on either raceway against either side: contact radius and
    height, interference and principal radii identical to the last bit, so the design zone
    (computed at the inner +X flange) holds for whichever flanges a type has."""
    from jaxbearing.flange import flange_geometry

    b = jb.reference_bearing()
    x, ring = jnp.array([1.0, 0.0, 0.0]), jnp.zeros(3)
    d = b.roller.diameter
    seats = [(b.inner_raceway_radius, 1.0, b.inner_raceway_radius + d / 2)] * 2
    seats += [(b.outer_raceway_radius, -1.0, b.outer_raceway_radius - d / 2)] * 2
    fields = ("contact_radius", "contact_height", "interference", "radius_meridian", "radius_parallel")
    rows = []
    for (radius, ring_sign, centre), side in zip(seats, (-1.0, 1.0, -1.0, 1.0)):
        geo = flange_geometry(b, radius, side, ring_sign, jnp.array([0.0, 0.0, 1.0]) * centre, x, ring)
        rows.append([float(getattr(geo, f)) for f in fields])
    assert all(row == rows[0] for row in rows), rows
    assert rows[0][1] == float(jb.design_zone(b).contact_height)
