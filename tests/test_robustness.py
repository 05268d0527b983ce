"""A design against a reference over the corners of the model's uncertain constants
(`jaxbearing.design.robustness`), at reduced size: 11 slices, 2 seeds, a 2-revolution window, one
operating point (30,000 rpm, the skid regime), one constant (the traction asymptote D: its two
corners and the nominal point)."""

import dataclasses
import json
import math

import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing.design import (
    Robustness,
    robustness,
    robustness_corners,
    sensitivity_inputs,
    write_robustness_json,
)
from jaxbearing.design._robustness import _lower
from jaxbearing.flange import DesignVariables
from jaxbearing.io import reference_config
from jaxbearing.run import Estimate, SteadySettings

KEY = "lubricant.traction_d"
FIRST_SEED = 5000


@pytest.fixture(scope="module")
def cfg():
    return reference_config().replace({"bearing.num_slices": 11, "operating.speed_rpm": 30000.0})


@pytest.fixture(scope="module")
def result(cfg) -> Robustness:
    design = DesignVariables(101.6e-3, math.radians(1.527), 0.140e-3)
    settings = SteadySettings(seeds=2, window_revs=2, settle=0.5)
    return robustness(cfg, design, settings=settings, first_seed=FIRST_SEED, constants=(KEY,))


def test_corners_take_the_stated_range(cfg):
    """The corners are the nominal point and x -/+ u with u from `sensitivity_inputs` (the one
    place the range is stated), and the bearings built from them carry those values."""
    (item,) = [i for i in sensitivity_inputs(cfg) if i.key == KEY]
    chosen, steps, cases = robustness_corners(cfg, (KEY,))
    assert [i.key for i in chosen] == [KEY] and steps == (item.plus_minus,)
    assert [c.name for c, _ in cases] == ["nominal", "traction_d-", "traction_d+"]
    want = [item.value, item.value - item.plus_minus, item.value + item.plus_minus]
    for (corner, c), w in zip(cases, want):
        assert corner.values[KEY] == pytest.approx(w)
        assert float(c.bearing().lubricant.traction_d) == pytest.approx(w)


def test_structure_and_verdict(result):
    assert [c.name for c in result.corners] == ["nominal", "traction_d-", "traction_d+"]
    assert result.seeds == (FIRST_SEED, FIRST_SEED + 1) and result.num_slices == 11
    assert len(result.rows) == 3 and result.points[0][0] == pytest.approx(30000.0)
    assert result.reference["end_radius_m"] == pytest.approx(float(jb.reference_bearing().roller.end_radius))
    for r in result.rows:
        assert r.settled
        for e in (r.design_mean_pv, r.reference_mean_pv, r.design_peak_pv, r.reference_peak_pv):
            assert e.n == 2 and e.ci95_low <= e.value <= e.ci95_high
        assert r.mean_pv_lower == (r.design_mean_pv.ci95_high < r.reference_mean_pv.ci95_low)
        assert r.peak_pv_lower == (r.design_peak_pv.ci95_high < r.reference_peak_pv.ci95_low)
    flags = [(result.corners[r.corner].name, s) for r in result.rows for s in ("mean_pv", "peak_pv")]
    missing = [(c, s) for (c, _, s) in result.not_lower]
    assert set(missing) <= set(flags)
    assert result.lower_everywhere == (not result.not_lower)


def test_lower_traction_asymptote_slips_more(result):
    """The constant really changed in the bearings run: in the skid regime the roller set's
    drive is capped near the traction asymptote D, so a lower D lets the cage slip more
    (docs/validation.md, the skid regime), for both designs."""
    nominal, low, high = (result.row(c, 0) for c in range(3))
    for who in ("design", "reference"):
        s = [getattr(r, f"{who}_cage_slip").value for r in (low, nominal, high)]
        assert s[0] > s[1] > s[2] > 0, (who, s)


def test_json_is_plain_data(result, tmp_path):
    path = write_robustness_json(result, tmp_path / "r.json", command="pytest")
    data = json.loads(path.read_text())
    assert data["command"] == "pytest" and data["lower_everywhere"] == result.lower_everywhere
    assert [c["name"] for c in data["corners"]] == [c.name for c in result.corners]
    assert data["rows"][1]["reference_cage_slip"]["value"] == pytest.approx(
        result.row(1, 0).reference_cage_slip.value
    )


def test_disjoint_means_wholly_below():
    a, b = Estimate(1.0, 0.9, 1.1, 4), Estimate(2.0, 1.8, 2.2, 4)
    assert _lower(a, b) and not _lower(b, a)
    assert not _lower(dataclasses.replace(a, ci95_high=1.9), b)
    assert not _lower(Estimate(1.0, np.nan, np.nan, 1), b)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"constants": ("lubricant.viscosity_Pa_s",)}, "constants"),
        ({"constants": (KEY, KEY)}, "constants"),
        ({"constants": ()}, "constants"),
        ({"first_seed": -1}, "first_seed"),
        ({"ops": []}, "ops"),
    ],
)
def test_bad_input_is_one_line(cfg, kwargs, name):
    design = DesignVariables.of(cfg.bearing())
    with pytest.raises(jb.UserInputError) as err:
        robustness(cfg, design, **({"first_seed": FIRST_SEED} | kwargs))
    assert str(err.value).startswith(name) and "\n" not in str(err.value)
