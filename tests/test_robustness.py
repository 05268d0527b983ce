"""A design against a reference over the corners of the model's uncertain constants
(`jaxbearing.design.robustness`).

Fast: the steady-running engine replaced by a closed form of each member's bearing (5 slices, no
solve), which checks the corners, the members the engine is given (the constants in their
bearings, both designs, the caller's seeds), the verdict and the JSON; the constants' effect on
the runs by the cage slip of the static skid equilibrium (the state every settled run starts
from) of the corners' configurations. Slow (`make test-slow`): the real settled runs at reduced
size (11 slices, 2 seeds, a fixed 0.5 ms settling, a 2-revolution window, 30,000 rpm, the
traction asymptote D alone: its two corners and the nominal point), in which a lower D lets the
cage slip more."""

import dataclasses
import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing.design import (
    Robustness,
    robustness,
    robustness_corners,
    sensitivity_inputs,
    static_cage_slip,
    write_robustness_json,
)
from jaxbearing.design import _robustness as module
from jaxbearing.design._robustness import _lower
from jaxbearing.flange import DesignVariables
from jaxbearing.io import reference_config
from jaxbearing.run import Estimate, SteadySettings

KEY = "lubricant.traction_d"
FIRST_SEED = 5000
DESIGN = DesignVariables(101.6e-3, math.radians(1.527), 0.140e-3)
GPA = 1e9
SPEEDS = (20000, 30000)


@pytest.fixture(scope="module")
def cfg():
    return reference_config().replace({"bearing.num_slices": 5, "operating.speed_rpm": 30000.0})


def _fake_engine(seen: dict):
    """The engine and the metrics replaced by a closed form of the member: the design's mean PV
    1 GPa m/s (2 at the lower traction asymptote), the reference's 2, both +/- 0.1; peak PV 3
    and 5; cage slip 0.1 + 10 (0.04 - D). Records the members the engine was given."""

    def points(bearings, ops, settings, perturbation):
        seen.update(bearings=list(bearings), ops=list(ops), seeds=settings.seeds, first=perturbation.seed)
        return [SimpleNamespace(bearing=b) for b in bearings]

    def est(v, h):
        return Estimate(v, v - h, v + h, 2)

    def metrics(result, design, margins, corner_margin, functionals):
        d = float(result.bearing.lubricant.traction_d)
        mine = float(design.end_radius) == float(DESIGN.end_radius)
        mean = (2.0 if d < 0.04 - 1e-9 else 1.0) if mine else 2.0
        statistics = SimpleNamespace(
            flange_pv_Pa_m_s=SimpleNamespace(max=est((3.0 if mine else 5.0) * GPA, 0.1 * GPA)),
            cage_slip=est(0.1 + 10 * (0.04 - d), 0.01),
        )
        return SimpleNamespace(
            mean_pv=est(mean * GPA, 0.1 * GPA),
            statistics=statistics,
            settled=True,
            design={"end_radius_m": float(design.end_radius)},
        )

    return points, metrics


@pytest.fixture(scope="module")
def fake(cfg):
    """(the result on the fake engine at 20,000 and 30,000 rpm, what the engine was given)."""
    seen: dict = {}
    points, metrics = _fake_engine(seen)
    ops = [dataclasses.replace(cfg.operating_point(), inner_speed=jb.rpm_to_rad_s(s)) for s in SPEEDS]
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(module, "simulate_steady_points", points)
        mp.setattr(module, "_metrics", metrics)
        res = robustness(
            cfg, DESIGN, ops=ops, settings=SteadySettings(seeds=2, window_revs=2), first_seed=FIRST_SEED
        )
    return res, seen


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


def test_members_carry_the_corners_designs_and_seeds(fake):
    """Every (corner, design, point) is a member of the one engine call, its bearing carrying
    the corner's constants and the design, on the caller's seeds."""
    res, seen = fake
    assert [c.name for c in res.corners] == [
        "nominal",
        "traction_d-, oil_fraction-",
        "traction_d-, oil_fraction+",
        "traction_d+, oil_fraction-",
        "traction_d+, oil_fraction+",
    ]
    assert seen["seeds"] == 2 and seen["first"] == FIRST_SEED and res.seeds == (FIRST_SEED, FIRST_SEED + 1)
    bearings = seen["bearings"]
    assert len(bearings) == 5 * 2 * 2  # corners x designs x points
    ref = jb.reference_bearing()
    for i, b in enumerate(bearings):
        corner, design, point = res.corners[i // 4], (i // 2) % 2, i % 2
        for key, attr in (("lubricant.traction_d", "traction_d"), ("lubricant.oil_fraction", "oil_fraction")):
            assert float(getattr(b.lubricant, attr)) == pytest.approx(corner.values[key])
        want = DESIGN.end_radius if design == 0 else ref.roller.end_radius
        assert float(b.roller.end_radius) == pytest.approx(float(want))
        assert float(seen["ops"][i].inner_speed) == pytest.approx(float(jb.rpm_to_rad_s(SPEEDS[point])))
    assert [p[0] for p in res.points] == pytest.approx(list(SPEEDS))
    assert res.reference["end_radius_m"] == pytest.approx(float(ref.roller.end_radius))


def test_verdict_lists_where_the_design_is_not_lower(fake):
    res, _ = fake
    assert res.rows == tuple(res.row(c, p) for c in range(5) for p in range(2))
    want = [(c.name, p, "mean_pv") for c in res.corners if c.signs[0] < 0 for p in range(2)]
    assert list(res.not_lower) == want and not res.lower_everywhere
    r = res.row(0, 1)
    assert r.mean_pv_lower and r.peak_pv_lower and r.settled
    assert (r.design_mean_pv.value, r.reference_mean_pv.value) == (1.0 * GPA, 2.0 * GPA)


def test_lower_traction_asymptote_slips_more(cfg):
    """The constant acts on the runs: the static skid equilibrium (where every settled run
    starts) of the corners' configurations slips more at the lower traction asymptote D (in the
    skid regime the roller set's drive is capped near D; docs/validation.md, the skid regime)."""
    _, _, cases = robustness_corners(cfg, (KEY,))
    slips = [static_cage_slip(c) for _, c in cases]  # nominal, D-, D+
    assert slips[1] > slips[0] > slips[2] > 0, slips


def test_json_is_plain_data(fake, tmp_path):
    res, _ = fake
    path = write_robustness_json(res, tmp_path / "r.json", command="pytest")
    data = json.loads(path.read_text())
    assert data["command"] == "pytest" and data["lower_everywhere"] is False
    assert [c["name"] for c in data["corners"]] == [c.name for c in res.corners]
    assert data["not_lower"][0] == {"corner": res.corners[1].name, "point": 0, "statistic": "mean_pv"}
    assert data["rows"][3]["design_cage_slip"]["value"] == pytest.approx(res.row(1, 1).design_cage_slip.value)
    assert [c["key"] for c in data["constants"]] == list(module.ROBUSTNESS_CONSTANTS)


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


@pytest.mark.slow
def test_settled_runs_at_reduced_size():
    """The real settled runs: the structure, and a lower traction asymptote lets the cage slip
    more in the settled runs of both designs."""
    cfg = reference_config().replace({"bearing.num_slices": 11, "operating.speed_rpm": 30000.0})
    settings = SteadySettings(seeds=2, window_revs=2, settle=0.5)
    res = robustness(cfg, DESIGN, settings=settings, first_seed=FIRST_SEED, constants=(KEY,))
    assert isinstance(res, Robustness) and [c.name for c in res.corners] == [
        "nominal",
        "traction_d-",
        "traction_d+",
    ]
    assert res.seeds == (FIRST_SEED, FIRST_SEED + 1) and res.num_slices == 11 and len(res.rows) == 3
    for r in res.rows:
        assert r.settled
        for e in (r.design_mean_pv, r.reference_mean_pv, r.design_peak_pv, r.reference_peak_pv):
            assert e.n == 2 and e.ci95_low <= e.value <= e.ci95_high
        assert r.mean_pv_lower == (r.design_mean_pv.ci95_high < r.reference_mean_pv.ci95_low)
    nominal, low, high = (res.row(c, 0) for c in range(3))
    for who in ("design", "reference"):
        s = [getattr(r, f"{who}_cage_slip").value for r in (low, nominal, high)]
        assert s[0] > s[1] > s[2] > 0, (who, s)
