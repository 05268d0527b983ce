"""Validation of configurations and of pytrees built in Python.

- every hand-written bad file in tests/bad_configs/ fails `jaxbearing config check` with exit
  status 2 and one stderr line naming the field given in its `# expect:` comment;
- hypothesis throws bad values (NaN, inf, negatives, huge, wrong types, unknown keys) at the
  loader: each must raise ConfigError, never another exception and never pass;
- range boundaries against independent closed forms (rollers around the pitch circle, traction
  curve maximum by dense sampling, end sphere meeting the corner torus).
"""

from __future__ import annotations

import dataclasses
import datetime
import math
import pathlib
import shutil
import subprocess
import sys

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
import tomli_w
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import jaxbearing as jb
from jaxbearing import ConfigError
from jaxbearing.cli import main as cli_main
from jaxbearing.io import KEYS

BAD_DIR = pathlib.Path(__file__).parent / "bad_configs"
BAD_FILES = sorted(BAD_DIR.glob("*.toml"))


def _expected_field(path: pathlib.Path) -> str:
    first = path.read_text().splitlines()[0]
    assert first.startswith("# expect: "), path
    return first.removeprefix("# expect: ").strip()


def _nested(path: str, value) -> dict:
    *sections, name = path.split(".")
    out: dict = {name: value}
    for s in reversed(sections):
        out = {s: out}
    return out


FLOAT_KEYS = [k for k in KEYS if k.kind is float]
INT_KEYS = [k for k in KEYS if k.kind is int]
BOOL_KEYS = [k for k in KEYS if k.kind is bool]
#: float keys where a negative value is physically meaningful (written out by hand, not read
#: from the schema): Poisson ratio of auxetic materials, the traction curve coefficients and
#: temperatures in C.
NEGATIVE_OK = {
    "materials.ring.poisson_ratio",
    "materials.roller.poisson_ratio",
    "materials.cage.poisson_ratio",
    "lubricant.traction_a",
    "lubricant.traction_b_s_m",
    "lubricant.traction_d",
    "lubricant.reference_temperature_C",
    "lubricant.inlet_temperature_C",
    "operating.misalignment_mrad",  # a tilt either way about +Y
    "operating.axial_load_N",  # either direction along X
}


# -- the bad files, through the real command ---------------------------------------------------
def test_there_are_enough_bad_files():
    assert len(BAD_FILES) >= 30
    assert len({_expected_field(p) for p in BAD_FILES}) >= 30  # many different fields


@pytest.mark.parametrize("path", BAD_FILES, ids=[p.stem for p in BAD_FILES])
def test_bad_config_check_fails_with_one_line(path, capsys):
    rc = cli_main(["config", "check", str(path)])
    out, err = capsys.readouterr()
    assert rc == 2
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    field = _expected_field(path)
    assert lines[0].startswith(f"{path}: {field}"), lines[0]
    assert "Traceback" not in err


def test_bad_config_messages_name_value_and_range(capsys):
    path = BAD_DIR / "corner_radius_too_large.toml"
    assert cli_main(["config", "check", str(path)]) == 2
    assert capsys.readouterr().err == (
        f"{path}: roller.corner_radius_mm: 4.0 mm is out of range: must be in (0, diameter_mm/2 = 3.75) mm\n"
    )


def test_console_script_checks_every_bad_file(tmp_path):
    """The installed `jaxbearing` script, once over all files (one line per file, exit 2)."""
    exe = pathlib.Path(sys.executable).with_name("jaxbearing")
    exe = str(exe) if exe.exists() else shutil.which("jaxbearing")
    if exe is None:
        pytest.skip("jaxbearing console script not installed")
    good = tmp_path / "good.toml"
    good.write_text("[roller]\nend_radius_mm = 90\n")
    proc = subprocess.run(
        [exe, "config", "check", str(good), *map(str, BAD_FILES)], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 2
    assert proc.stdout == f"{good}: ok\n"
    lines = proc.stderr.splitlines()
    assert len(lines) == len(BAD_FILES)
    for path, line in zip(BAD_FILES, lines):
        assert line.startswith(f"{path}: {_expected_field(path)}"), line


# -- hypothesis: bad values --------------------------------------------------------------------
def _load(data: dict):
    """Through TOML text where TOML can say it, else as a Python mapping."""
    try:
        text = tomli_w.dumps(data)
    except (TypeError, ValueError):
        return jb.Config(data)
    return jb.loads_config(text)


WRONG_TYPE = st.one_of(
    st.text(max_size=8),
    st.lists(st.floats(allow_nan=False), max_size=3),
    st.dictionaries(st.text(min_size=1, max_size=5), st.integers(), max_size=2),
    st.just(datetime.date(2025, 1, 1)),
    st.none(),
)


@settings(max_examples=300, deadline=None)
@given(key=st.sampled_from(FLOAT_KEYS), data=st.data())
def test_bad_float_values_raise_config_error(key, data):
    kinds = ["nan", "-inf", "bool", "wrong_type", "huge"]
    if not key.allow_inf:
        kinds.append("inf")
    if key.path not in NEGATIVE_OK:
        kinds.append("negative")
    kind = data.draw(st.sampled_from(kinds))
    if kind == "huge" and key.allow_inf:  # R_end = 1e30 mm is a valid, practically flat end
        value = -data.draw(st.floats(1e12, 1e300))
    else:
        value = {
            "nan": lambda: math.nan,
            "inf": lambda: math.inf,
            "-inf": lambda: -math.inf,
            "bool": lambda: data.draw(st.booleans()),
            "wrong_type": lambda: data.draw(WRONG_TYPE),
            "huge": lambda: data.draw(st.sampled_from([1.0, -1.0])) * data.draw(st.floats(1e12, 1e300)),
            "negative": lambda: -data.draw(st.floats(1e-300, 1e300)),
        }[kind]()
    with pytest.raises(ConfigError) as info:
        _load(_nested(key.path, value))
    assert "\n" not in str(info.value)


@settings(max_examples=150, deadline=None)
@given(
    key=st.sampled_from(INT_KEYS),
    value=st.one_of(
        st.integers(max_value=0),
        st.integers(min_value=10**10, max_value=10**40),
        st.floats(allow_nan=True),
        st.booleans(),
        WRONG_TYPE,
    ),
)
def test_bad_counts_raise_config_error(key, value):
    with pytest.raises(ConfigError) as info:
        jb.Config(_nested(key.path, value))
    assert info.value.field == key.path


@settings(max_examples=60, deadline=None)
@given(key=st.sampled_from(BOOL_KEYS), value=st.one_of(st.integers(), st.floats(), st.text(max_size=5)))
def test_bad_switches_raise_config_error(key, value):
    with pytest.raises(ConfigError) as info:
        _load(_nested(key.path, value))
    assert info.value.field == key.path


SECTIONS = sorted({k.section for k in KEYS})
ALL_NAMES = {k.path for k in KEYS} | {k.name for k in KEYS} | set(SECTIONS) | {"materials"}


@settings(max_examples=200, deadline=None)
@given(
    section=st.sampled_from([""] + SECTIONS),
    name=st.text(min_size=1, max_size=12),
    value=st.one_of(st.floats(), st.integers(), st.text(max_size=4), st.booleans()),
)
def test_unknown_keys_raise_config_error(section, name, value):
    assume(name not in ALL_NAMES)
    path = f"{section}.{name}" if section else name
    data = _nested(section, {name: value}) if section else {name: value}
    with pytest.raises(ConfigError) as info:
        _load(data)
    assert info.value.field == path
    assert "unknown" in str(info.value)


@settings(max_examples=100, deadline=None)
@given(
    section=st.sampled_from(SECTIONS + ["materials"]),
    value=st.one_of(st.floats(), st.integers(), st.text(max_size=4), st.lists(st.integers())),
)
def test_sections_that_are_not_tables_raise(section, value):
    with pytest.raises(ConfigError):
        jb.Config(_nested(section, value))


# -- boundaries against closed forms -----------------------------------------------------------
def test_example_message_is_exact():
    with pytest.raises(ConfigError) as info:
        jb.reference_config().replace(**{"roller.corner_radius_mm": 4.0})
    assert info.value.field == "roller.corner_radius_mm"
    assert str(info.value) == (
        "roller.corner_radius_mm: 4.0 mm is out of range: must be in (0, diameter_mm/2 = 3.75) mm"
    )


def test_rollers_around_the_pitch_circle():
    ref = jb.reference_config()
    d_m, d, c_p = 85.0, 7.5, 0.2
    z_bars = math.floor(math.pi * d_m / (d + c_p))  # 34: the most that leave room for cage bars
    z_overlap = math.ceil(math.pi * d_m / d)  # 36: the fewest whose rollers overlap
    assert ref.replace(**{"bearing.num_rollers": z_bars})["bearing.num_rollers"] == z_bars
    for z in range(z_bars + 1, z_overlap):
        with pytest.raises(ConfigError, match="cage bars"):
            ref.replace(**{"bearing.num_rollers": z})
    with pytest.raises(ConfigError, match="overlap"):
        ref.replace(**{"bearing.num_rollers": z_overlap})


def test_end_radius_must_exceed_half_diameter():
    ref = jb.reference_config()
    # R_end - R_cor > R_ce  <=>  R_end > D/2; at D/2 the cap is a hemisphere, below it no tangency
    assert ref.replace(**{"roller.end_radius_mm": 3.75 + 1e-9})["roller.end_radius_mm"] > 3.75
    for bad in (3.75, 3.0, 0.0, -80.0):
        with pytest.raises(ConfigError, match=r"roller\.end_radius_mm"):
            ref.replace(**{"roller.end_radius_mm": bad})
    flat = ref.replace(**{"roller.end_radius_mm": math.inf, "simulation.end": "corner"})
    assert math.isinf(float(flat.bearing().roller.end_radius))


def _traction_peak(a, b, c, d):
    """max |kappa| over du >= 0 by dense sampling (independent of the validator's closed form)."""
    du_star = 1.0 / c - (a / b if b else 0.0)
    grid = np.concatenate(
        [
            np.linspace(0.0, 60.0 / c, 200_001),
            du_star * (1 + np.linspace(-1e-3, 1e-3, 101)) if du_star > 0 else [],
        ]
    )
    kappa = (a + b * grid) * np.exp(-c * grid) + d
    return float(np.max(np.abs(np.concatenate([kappa, [d]]))))


@settings(max_examples=60, deadline=None)
@given(
    a=st.floats(-1, 1),
    c=st.floats(0.05, 50),
    d=st.floats(-1, 1),
    b=st.one_of(st.just(0.0), st.floats(1e-3, 20), st.floats(-20, -1e-3)),
)
def test_traction_curve_bound_matches_sampling(a, b, c, d):
    peak = _traction_peak(a, b, c, d)
    assume(abs(peak - 1.0) > 1e-3)  # away from the boundary, where sampling is exact enough
    change = {
        "lubricant.traction_a": a,
        "lubricant.traction_b_s_m": b,
        "lubricant.traction_c_s_m": c,
        "lubricant.traction_d": d,
    }
    if peak < 1.0:
        jb.reference_config().replace(**change)
    else:
        with pytest.raises(ConfigError) as info:
            jb.reference_config().replace(**change)
        assert info.value.field == "lubricant.traction_b_s_m"


def test_dependencies_are_checked_first():
    # an invalid diameter is reported before the corner radius that is judged against it
    with pytest.raises(ConfigError) as info:
        jb.Config({"roller": {"corner_radius_mm": 4.0, "diameter_mm": math.nan}})
    assert info.value.field == "roller.diameter_mm"
    # and a bad pocket clearance before the roller count that depends on it
    with pytest.raises(ConfigError) as info:
        jb.Config({"bearing": {"num_rollers": 40}, "cage": {"pocket_clearance_mm": -1.0}})
    assert info.value.field == "cage.pocket_clearance_mm"


def test_contact_height_limit_may_equal_flange_height():
    cfg = jb.reference_config().replace(**{"flange.contact_height_limit_mm": 2.0})
    assert cfg["flange.contact_height_limit_mm"] == 2.0


def test_messages_are_one_line_for_all_bad_files():
    for path in BAD_FILES:
        with pytest.raises(ConfigError) as info:
            jb.load_config(path)
        assert "\n" not in str(info.value)
        assert str(info.value).startswith(_expected_field(path))


# -- pytrees built in Python -------------------------------------------------------------------
def test_validate_reference_pytrees():
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    assert jb.validate_bearing(b) is None
    assert jb.validate_bearing(b, op) is None
    assert jb.validate_bearing(b.with_flat_ends(), op) is None


@pytest.mark.parametrize(
    "where, value, field, shown",
    [
        (lambda b: b.roller.corner_radius, 4e-3, "roller.corner_radius_mm", "4.0 mm"),
        (lambda b: b.roller.end_radius, 3e-3, "roller.end_radius_mm", "3.0 mm"),
        (lambda b: b.flange.layback_angle, math.radians(12.0), "flange.layback_angle_deg", "12.0 deg"),
        (lambda b: b.radial_clearance, -5e-6, "bearing.radial_clearance_um", "-5.0 um"),
        (lambda b: b.roller_material.poisson_ratio, 0.5, "materials.roller.poisson_ratio", "0.5 is"),
        (lambda b: b.cage_material.elastic_modulus, -1e9, "materials.cage.elastic_modulus_GPa", "-1.0 GPa"),
        (lambda b: b.lubricant.oil_fraction, jnp.nan, "lubricant.oil_fraction", "nan is not finite"),
    ],
)
def test_validate_bearing_names_config_key(where, value, field, shown):
    bad = eqx.tree_at(where, jb.reference_bearing(), jnp.asarray(value))
    with pytest.raises(ConfigError) as info:
        jb.validate_bearing(bad)
    assert info.value.field == field
    assert shown in str(info.value)


def test_validate_operating_point():
    b = jb.reference_bearing()
    op = jb.reference_operating_point()
    with pytest.raises(ConfigError, match=r"operating\.speed_rpm: 150000\.0 rpm"):
        jb.validate_bearing(
            b, eqx.tree_at(lambda o: o.inner_speed, op, jnp.asarray(jb.rpm_to_rad_s(150_000.0)))
        )
    with pytest.raises(ConfigError, match=r"operating\.gravity"):
        jb.validate_bearing(b, eqx.tree_at(lambda o: o.gravity, op, jnp.asarray(-9.81)))
    jb.validate_bearing(b, eqx.tree_at(lambda o: o.gravity, op, jnp.asarray(0.0)))


def test_validate_counts_and_batches():
    b = jb.reference_bearing()
    with pytest.raises(ConfigError, match=r"bearing\.num_rollers"):
        jb.validate_bearing(dataclasses.replace(b, num_rollers=40))
    with pytest.raises(ConfigError, match=r"bearing\.num_slices"):
        jb.validate_bearing(dataclasses.replace(b, num_slices=2))
    with pytest.raises(ConfigError, match=r"bearing\.num_rollers: expected an integer"):
        jb.validate_bearing(dataclasses.replace(b, num_rollers=26.0))
    # a stacked design sweep: element 2 is bad
    radii = jnp.asarray([70e-3, 90e-3, 3e-3, 110e-3])
    with pytest.raises(ConfigError, match=r"batch element \(2,\)"):
        jb.validate_bearing(eqx.tree_at(lambda t: t.roller.end_radius, b, radii))
    jb.validate_bearing(eqx.tree_at(lambda t: t.roller.end_radius, b, radii[:2]))


def test_validate_bearing_refuses_tracers():
    b = jb.reference_bearing()

    @jax.jit
    def f(r):
        jb.validate_bearing(eqx.tree_at(lambda t: t.roller.end_radius, b, r))
        return r

    with pytest.raises(TypeError, match="concrete"):
        f(jnp.asarray(80e-3))
