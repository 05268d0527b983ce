"""TOML configuration: reference equality, exact round trips, defaults, suggestions, the CLI."""

from __future__ import annotations

import dataclasses
import math
import pickle
import tomllib

import equinox as eqx
import jax
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import jaxbearing as jb
from jaxbearing import ConfigError
from jaxbearing.cli import main as cli_main
from jaxbearing.io import KEYS


def _module_fields(module) -> dict[str, object]:
    """{dotted field: value} of an equinox pytree, static fields included, recursively."""
    out = {}
    for f in dataclasses.fields(module):
        value = getattr(module, f.name)
        if isinstance(value, eqx.Module):
            out.update({f"{f.name}.{k}": v for k, v in _module_fields(value).items()})
        else:
            out[f.name] = value
    return out


# -- reference ---------------------------------------------------------------------------------
#: docs/model.md section 1 (the physics contract), in SI: the reference bearing is written down once,
#: in the configuration schema; this table is the independent copy it is checked against.
MODEL_MD_REFERENCE = {
    "pitch_diameter": 85e-3,
    "radial_clearance": 20e-6,
    "inner_ring_mass": 0.5,
    "flange_traction": 0.08,
    "pocket_friction": 0.10,
    "roller.diameter": 7.5e-3,
    "roller.length": 8.0e-3,
    "roller.central_length": 4.5e-3,
    "roller.crown_drop": 4e-6,
    "roller.corner_radius": 0.4e-3,
    "roller.end_radius": 80e-3,
    "flange.height": 2.0e-3,
    "flange.relief_height": 0.3e-3,
    "flange.contact_height_limit": 1.8e-3,
    "flange.layback_angle": np.radians(1.6),
    "flange.axial_clearance": 0.15e-3,
    "cage.inner_diameter": 80e-3,
    "cage.outer_diameter": 90e-3,
    "cage.width": 14e-3,
    "cage.pocket_clearance": 0.20e-3,
    "cage.guiding_clearance": 0.40e-3,
    "cage.land_width": 3e-3,
    "ring_material.elastic_modulus": 203e9,
    "ring_material.poisson_ratio": 0.28,
    "ring_material.density": 7830.0,
    "roller_material.elastic_modulus": 203e9,
    "cage_material.elastic_modulus": 205e9,
    "cage_material.poisson_ratio": 0.29,
    "cage_material.density": 7850.0,
    "lubricant.viscosity": 0.055,
    "lubricant.pressure_viscosity": 1.85e-8,
    "lubricant.temperature_viscosity": 0.0315,
    "lubricant.density": 960.0,
    "lubricant.oil_fraction": 0.05,
}


def test_reference_bearing_is_model_md_section_2():
    b = jb.reference_bearing()
    assert b.num_rollers == 26 and b.num_slices % 2 == 1
    for path, want in MODEL_MD_REFERENCE.items():
        value = b
        for part in path.split("."):
            value = getattr(value, part)
        assert np.asarray(value).dtype == np.float64, path
        np.testing.assert_allclose(float(value), want, rtol=1e-12, err_msg=path)


def test_reference_operating_point_and_simulation():
    cfg = jb.reference_config()
    got = _module_fields(cfg.operating_point())
    want = _module_fields(jb.reference_operating_point())
    assert got.keys() == want.keys()
    for name in want:
        assert np.asarray(got[name]).tobytes() == np.asarray(want[name]).tobytes(), name
    sim = cfg.simulation
    assert (sim.end, sim.duration_ms, sim.rtol, sim.atol, sim.max_steps, sim.progress) == (
        "both",
        20.0,
        1e-3,
        1e-6,
        2_000_000,
        True,
    )
    assert sim.ends == ("arc", "corner") and sim.duration == pytest.approx(0.02)
    with pytest.raises(dataclasses.FrozenInstanceError):
        sim.rtol = 1.0  # type: ignore[misc]


def test_schema_maps_every_pytree_field_once():
    b_fields = set(_module_fields(jb.reference_bearing()))
    op_fields = {f"op.{k}" for k in _module_fields(jb.reference_operating_point())}
    attrs = [k.attr for k in KEYS if k.attr is not None]
    assert len(attrs) == len(set(attrs))
    assert set(attrs) == b_fields | op_fields


def test_load_none_is_reference():
    assert jb.load_config(None) == jb.reference_config() == jb.Config() == jb.Config({})
    assert repr(jb.reference_config()) == "Config(reference)"


# -- SI conversion against hand-computed values ------------------------------------------------
def test_engineering_units_convert_to_si():
    cfg = jb.loads_config("""
[bearing]
pitch_diameter_mm = 100
radial_clearance_um = 35
num_rollers = 20
[roller]
diameter_mm = 10.0
length_mm = 12.0
crown_drop_um = 5.0
end_radius_mm = 120.0
[flange]
layback_angle_deg = 2.0
[cage]
inner_diameter_mm = 94
outer_diameter_mm = 106
width_mm = 20
[materials.cage]
elastic_modulus_GPa = 3.6
poisson_ratio = 0.4
density_kg_m3 = 1320
[operating]
speed_rpm = 6000
radial_load_N = 2500
gravity = false
""")
    b, op = cfg.bearing(), cfg.operating_point()
    close = dict(rtol=1e-15, atol=0)
    np.testing.assert_allclose(b.pitch_diameter, 0.1, **close)
    np.testing.assert_allclose(b.radial_clearance, 35e-6, **close)
    np.testing.assert_allclose(b.roller.diameter, 0.01, **close)
    np.testing.assert_allclose(b.roller.crown_drop, 5e-6, **close)
    np.testing.assert_allclose(b.roller.end_radius, 0.12, **close)
    np.testing.assert_allclose(b.flange.layback_angle, 2.0 * math.pi / 180, **close)
    np.testing.assert_allclose(b.cage.width, 0.02, **close)
    np.testing.assert_allclose(b.cage_material.elastic_modulus, 3.6e9, **close)
    np.testing.assert_allclose(b.cage_material.density, 1320.0, **close)
    np.testing.assert_allclose(op.inner_speed, 200 * math.pi, **close)
    np.testing.assert_allclose(op.radial_load, 2500.0, **close)
    assert float(op.gravity) == 0.0 and b.num_rollers == 20
    assert float(jb.reference_config().operating_point().gravity) == 9.81


def test_flat_end_is_inf():
    cfg = jb.loads_config('[roller]\nend_radius_mm = inf\n[simulation]\nend = "corner"\n')
    assert math.isinf(cfg["roller.end_radius_mm"])
    assert math.isinf(float(cfg.bearing().roller.end_radius))
    assert "end_radius_mm = inf" in cfg.to_toml()
    # loads with the default end = "both" too, so that `simulate --end corner` can override it
    assert jb.loads_config("[roller]\nend_radius_mm = inf\n").simulation.end == "both"


# -- round trips -------------------------------------------------------------------------------
def test_reference_dump_load_dump_is_byte_identical():
    text = jb.reference_config().to_toml()
    assert jb.loads_config(text).to_toml() == text
    plain = jb.reference_config().to_toml(comments=False)
    assert jb.loads_config(plain).to_toml(comments=False) == plain
    assert tomllib.loads(text) == tomllib.loads(plain) == jb.reference_config().to_dict()


def test_full_file_round_trips_as_parsed():
    # integers for float keys, exponents, inf: parsed again, the dump is the same dict
    text = jb.reference_config().to_toml(comments=False)
    text = text.replace("pitch_diameter_mm = 85.0", "pitch_diameter_mm = 85")
    text = text.replace("end_radius_mm = 80.0", "end_radius_mm = 8.0e1")
    text = text.replace("viscosity_Pa_s = 0.055", "viscosity_Pa_s = 5.5e-2")
    parsed = tomllib.loads(text)
    assert tomllib.loads(jb.loads_config(text).to_toml()) == parsed


def test_partial_file_missing_keys_take_reference(tmp_path):
    path = tmp_path / "partial.toml"
    path.write_text("[roller]\nend_radius_mm = 95.5\n\n[operating]\nspeed_rpm = 15000\n")
    cfg = jb.load_config(path)
    ref = jb.reference_config().to_dict()
    ref["roller"]["end_radius_mm"] = 95.5
    ref["operating"]["speed_rpm"] = 15000.0
    assert cfg.to_dict() == ref
    assert cfg.changed() == {"roller.end_radius_mm": 95.5, "operating.speed_rpm": 15000.0}
    assert tomllib.loads(cfg.to_toml()) == ref
    # an empty file and an empty section are the reference
    assert jb.loads_config("") == jb.loads_config("[cage]\n") == jb.reference_config()


FLOAT_KEYS = [k for k in KEYS if k.kind is float]


@settings(max_examples=120, deadline=None)
@given(changes=st.dictionaries(st.sampled_from(FLOAT_KEYS), st.floats(0.98, 1.02), min_size=1, max_size=8))
def test_random_valid_configs_round_trip(changes):
    ref = jb.reference_config()
    dotted = {k.path: ref[k.path] * f for k, f in changes.items()}
    try:
        cfg = ref.replace(**dotted)
    except ConfigError:
        assume(False)  # a perturbation crossed a coupled limit (e.g. h_up above H_rf)
    text = cfg.to_toml()
    again = jb.loads_config(text)
    assert again == cfg
    assert again.to_toml() == text
    assert tomllib.loads(text) == cfg.to_dict()
    same = jax.tree_util.tree_map(
        lambda x, y: np.asarray(x).tobytes() == np.asarray(y).tobytes(), again.bearing(), cfg.bearing()
    )
    assert all(jax.tree_util.tree_leaves(same))


# -- replace, immutability ---------------------------------------------------------------------
def test_replace_dotted_keys_revalidates():
    ref = jb.reference_config()
    cfg = ref.replace(**{"roller.end_radius_mm": 90, "flange.layback_angle_deg": 1.8})
    assert cfg["roller.end_radius_mm"] == 90.0 and type(cfg["roller.end_radius_mm"]) is float
    assert ref["roller.end_radius_mm"] == 80.0  # the original is untouched
    np.testing.assert_allclose(cfg.bearing().roller.end_radius, 0.09, rtol=1e-15)
    assert cfg.replace({"roller.end_radius_mm": 80.0, "flange.layback_angle_deg": 1.6}) == ref
    with pytest.raises(ConfigError, match=r"roller\.corner_radius_mm"):
        ref.replace(**{"roller.corner_radius_mm": 5.0})
    with pytest.raises(ConfigError, match="did you mean roller.end_radius_mm"):
        ref.replace(**{"roller.end_radus_mm": 90})
    with pytest.raises(dataclasses.FrozenInstanceError):
        ref.foo = 1  # type: ignore[attr-defined]
    assert hash(ref) == hash(jb.Config())
    assert pickle.loads(pickle.dumps(cfg)) == cfg


# -- unknown keys, types -----------------------------------------------------------------------
@pytest.mark.parametrize(
    "text, field, suggestion",
    [
        ("[roller]\ndiamter_mm = 7.5\n", "roller.diamter_mm", "did you mean roller.diameter_mm?"),
        ("[roler]\ndiameter_mm = 7.5\n", "roler", "did you mean [roller]?"),
        ("[flange]\nlayback_angle = 1.6\n", "flange.layback_angle", "did you mean flange.layback_angle_deg?"),
        ("[operating]\nspeed_rmp = 1000\n", "operating.speed_rmp", "did you mean operating.speed_rpm?"),
        (
            "[materials.rollers]\npoisson_ratio = 0.3\n",
            "materials.rollers",
            "did you mean [materials.roller]?",
        ),
        (
            "[roller]\npitch_diameter_mm = 85\n",
            "roller.pitch_diameter_mm",
            "did you mean bearing.pitch_diameter_mm (in [bearing])?",
        ),
        (
            "[cage]\ndensity_kg_m3 = 1320\n",
            "cage.density_kg_m3",
            "did you mean materials.cage.density_kg_m3 (in [materials.cage])?",
        ),
        ("speed_rpm = 1000\n", "speed_rpm", "did you mean operating.speed_rpm (in [operating])?"),
    ],
)
def test_did_you_mean(text, field, suggestion):
    with pytest.raises(ConfigError) as info:
        jb.loads_config(text)
    assert info.value.field == field
    assert str(info.value).endswith(suggestion)


def test_unknown_key_without_close_match_lists_valid_keys():
    with pytest.raises(ConfigError, match=r"valid in \[flange\]: flange\.height_mm"):
        jb.loads_config("[flange]\nzzzzz = 1\n")


@pytest.mark.parametrize(
    "text, field, fragment",
    [
        ('[bearing]\npitch_diameter_mm = "85"\n', "bearing.pitch_diameter_mm", 'got string "85"'),
        ("[roller]\ndiameter_mm = true\n", "roller.diameter_mm", "got boolean true"),
        ("[bearing]\nnum_rollers = 26.0\n", "bearing.num_rollers", "got float 26.0"),
        ("[bearing]\nnum_slices = true\n", "bearing.num_slices", "got boolean true"),
        ("[operating]\ngravity = 1\n", "operating.gravity", "got integer 1"),
        ("[roller]\nlength_mm = [8.0]\n", "roller.length_mm", "got array"),
        ("[roller]\nlength_mm = 2025-01-01\n", "roller.length_mm", "expected a number"),
        ("[simulation]\nend = 1\n", "simulation.end", "expected a string"),
        ("roller = 7.5\n", "roller", "expected a table [roller]"),
        ("[bearing]\npitch_diameter_mm = 1" + "0" * 400 + "\n", "bearing.pitch_diameter_mm", "too large"),
    ],
)
def test_wrong_types(text, field, fragment):
    with pytest.raises(ConfigError) as info:
        jb.loads_config(text)
    assert info.value.field == field
    assert fragment in str(info.value)


def test_syntax_errors_and_missing_files(tmp_path):
    with pytest.raises(ConfigError) as info:
        jb.loads_config("[roller]\ndiameter_mm = 7.5\nlength_mm =\n")
    assert info.value.field == "line 3, column 12" and "TOML syntax error" in str(info.value)
    with pytest.raises(ConfigError) as info:
        jb.loads_config("[roller\n")
    assert info.value.field.startswith("line 1")
    with pytest.raises(ConfigError) as info:
        jb.load_config(tmp_path / "absent.toml")
    assert info.value.field == "file" and "cannot read" in str(info.value)
    (tmp_path / "latin1.toml").write_bytes(b"# \xe9\n")
    with pytest.raises(ConfigError, match="UTF-8"):
        jb.load_config(tmp_path / "latin1.toml")


# -- command line ------------------------------------------------------------------------------
def test_config_show_prints_every_key_with_a_comment(capsys):
    assert cli_main(["config", "show"]) == 0
    out = capsys.readouterr().out
    assert tomllib.loads(out) == jb.reference_config().to_dict()
    lines = out.splitlines()
    for key in KEYS:
        i = next(
            i
            for i, line in enumerate(lines)
            if line.startswith(f"{key.name} = ") and _section_of(lines, i) == key.section
        )
        comment = lines[i - 1]
        assert comment.startswith("# ") and len(comment) > 10, key.path
        if key.kind in (int, float):
            assert "in " in comment or ">" in comment, key.path  # the valid range
        if key.symbol:
            assert key.symbol in comment, key.path


def _section_of(lines, i):
    for line in reversed(lines[:i]):
        if line.startswith("["):
            return line.strip("[]")
    return ""


def test_config_show_merges_file(tmp_path, capsys):
    path = tmp_path / "mine.toml"
    path.write_text("[flange]\nlayback_angle_deg = 1.8\n")
    assert cli_main(["config", "show", "--config", str(path)]) == 0
    shown = tomllib.loads(capsys.readouterr().out)
    assert shown["flange"]["layback_angle_deg"] == 1.8
    assert shown["roller"] == jb.reference_config().to_dict()["roller"]


def test_config_show_bad_file_is_one_line(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text("[flange]\nlayback_angle_deg = 20.0\n")
    assert cli_main(["config", "show", "--config", str(path)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1
    assert err.startswith(f"{path}: flange.layback_angle_deg: 20.0 deg")


def test_config_check_ok_and_missing(tmp_path, capsys):
    good = tmp_path / "good.toml"
    good.write_text(jb.reference_config().to_toml())
    assert cli_main(["config", "check", str(good)]) == 0
    assert capsys.readouterr().out == f"{good}: ok\n"
    missing = tmp_path / "missing.toml"
    assert cli_main(["config", "check", str(missing)]) == 2
    out, err = capsys.readouterr()
    assert err == f"{missing}: file: cannot read: No such file or directory\n"
