"""Every file under examples/ is valid: configurations load, sweep specs validate (every case),
the optimiser settings parse. Nothing is integrated here."""

from __future__ import annotations

import pathlib

import pytest

import jaxbearing as jb
from optimise import load_optimise_toml

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def _files(pattern):
    return sorted(EXAMPLES.glob(pattern), key=lambda p: p.name)


def test_examples_exist():
    names = {p.name for p in EXAMPLES.iterdir()}
    assert {"reference.toml", "flat_end.toml", "optimise.toml"} <= names
    assert _files("*sweep*.toml")


@pytest.mark.parametrize(
    "path",
    [p for p in _files("*.toml") if "sweep" not in p.name and not p.name.startswith("optimise")],
    ids=lambda p: p.name,
)
def test_configuration_loads(path):
    """The file loads, builds its bearing, and every value it sets is the configuration's."""
    import tomllib

    cfg = jb.load_config(path)
    assert cfg.bearing().num_rollers >= 1
    given, loaded = tomllib.loads(path.read_text()), cfg.to_dict()
    for section, table in given.items():
        for key, value in table.items():
            assert loaded[section][key] == value, (section, key)


def test_reference_example_is_the_reference():
    assert jb.load_config(EXAMPLES / "reference.toml").to_dict() == jb.reference_config().to_dict()


@pytest.mark.parametrize("path", _files("*sweep*.toml"), ids=lambda p: p.name)
def test_sweep_spec_validates(path):
    spec = jb.load_sweep_spec(path)
    assert spec.num_cases >= 2


def test_optimise_settings_parse():
    settings = load_optimise_toml(str(EXAMPLES / "optimise.toml"))
    assert settings["end_radius_mm"] == [60.0, 120.0]


def test_optimise_profile_example_parses_as_a_profile_search():
    settings = load_optimise_toml(str(EXAMPLES / "optimise_profile.toml"))
    assert settings["profile"] is True and settings["end_offset_mm"] == [0.0, 1.0]


def test_optimise_example_builds_the_steady_settings():
    from optimise._cli import objective_of, steady_settings_from

    settings = load_optimise_toml(str(EXAMPLES / "optimise.toml"))
    assert objective_of(settings) == "steady"
    s = steady_settings_from(settings)
    assert (s.seeds, s.window_revs, s.settle, s.estimator) == (4, 2, "auto", "frozen")
    assert s.gradient_window == 1e-3 and s.corner_margin == 0.05e-3
    assert (s.skip_weight, s.recheck_every) == (1e-3, 3) and settings["speeds_rpm"] == [10e3, 20e3, 30e3]
    assert s.clearance_step == "auto" and settings["iterations"] == 4
