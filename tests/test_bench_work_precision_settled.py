"""The over-seeds paired comparison of benchmarks/bench_work_precision_settled.py on synthetic
numbers, against hand-computed Student-t intervals (the benchmark itself is not run here)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from bench_work_precision_settled import paired_over_seeds  # noqa: E402

T_975_3DOF = 3.182446  # Student t quantile 0.975, 3 degrees of freedom


def test_paired_difference_and_reference_intervals():
    ref = [1.0, 2.0, 3.0, 4.0]  # mean 2.5, s = sqrt(5/3)
    out = paired_over_seeds([1.1, 2.3, 2.9, 4.1], ref)  # differences 0.1, 0.3, -0.1, 0.1
    d, r = out["difference"], out["reference"]
    assert d["value"] == pytest.approx(0.1) and d["n"] == 4
    assert d["half_width"] == pytest.approx(T_975_3DOF * (0.12 / 4.5) ** 0.5 / 2.0, rel=1e-6)
    assert d["ci95_low"] == pytest.approx(0.1 - d["half_width"])
    assert r["value"] == pytest.approx(2.5)
    assert r["half_width"] == pytest.approx(T_975_3DOF * (5.0 / 3.0) ** 0.5 / 2.0, rel=1e-6)
    assert out["agrees"] is True


def test_agreement_needs_the_difference_below_the_reference_half_width():
    ref = [1.0, 1.001, 0.999, 1.0]  # half-width ~1.3e-3
    out = paired_over_seeds([1.5, 0.701, 1.399, 0.8], ref)  # differences 0.5, -0.3, 0.4, -0.2
    assert out["difference"]["ci95_low"] < 0.0 < out["difference"]["ci95_high"]
    assert out["agrees"] is False
    assert paired_over_seeds([1.0], [1.0])["agrees"] is None  # one seed: no interval


def test_rows_and_seeds_options_are_checked_in_one_line():
    from bench_work_precision_settled import (
        SEEDS,
        VARIANTS,
        output_name,
        rows_argument,
        seeds_argument,
        tag_argument,
    )

    assert rows_argument(["x"], len(VARIANTS)) is None
    assert rows_argument(["x", "--rows", "0,12"], len(VARIANTS)) == (0, 12)
    for bad in ("0,99", "a", ""):
        with pytest.raises(SystemExit, match=r"--rows = .*in \[0, \d+\]"):
            rows_argument(["x", "--rows", bad], len(VARIANTS))
    assert seeds_argument(["x"]) == SEEDS
    assert seeds_argument(["x", "--seeds", "4,5,6,7"]) == (4, 5, 6, 7)
    for bad in ("4", "4,4", "-1,2", "a,b"):
        with pytest.raises(SystemExit, match="--seeds = "):
            seeds_argument(["x", "--seeds", bad])
    assert output_name(None, SEEDS) == "bench_work_precision_settled"
    assert output_name((0, 12), (4, 5, 6, 7)) == "bench_work_precision_settled_rows_seeds4-5-6-7"
    assert output_name((0,), (4, 5), "rotation") == "bench_work_precision_settled_rows_rotation_seeds4-5"
    assert tag_argument(["x"]) is None and tag_argument(["x", "--tag", "a-b_1"]) == "a-b_1"
    for bad in ("", "a/b", "x y"):
        with pytest.raises(SystemExit, match="--tag = "):
            tag_argument(["x", "--tag", bad])


def test_design_option_is_checked_and_builds_that_design():
    """`--design R_end,theta_f,Delta_bf` (mm, deg, mm): parsed, range-checked by the
    configuration schema in one line naming the option, its value, the key and its range, named
    in the results file, and applied to the reference bearing."""
    import math

    from bench_work_precision_settled import SEEDS, design_argument, design_bearing, output_name

    import jaxbearing as jb

    assert design_argument(["x"]) is None
    assert design_argument(["x", "--design", "94.31,1.839,0.15"]) == (94.31, 1.839, 0.15)
    for bad in ("94.31,1.839", "a,b,c", ""):
        with pytest.raises(SystemExit, match=r"--design = .*three numbers R_end,theta_f,Delta_bf"):
            design_argument(["x", "--design", bad])
    for bad, key in (
        ("94.31,45,0.15", "flange.layback_angle_deg"),
        ("94.31,1.839,-0.1", "flange.axial_clearance_mm"),
    ):
        with pytest.raises(SystemExit, match=rf"--design = .*{key}: .* is out of range: must be in"):
            design_argument(["x", "--design", bad])
    assert (
        output_name((26,), SEEDS, "corner", (94.31, 1.839, 0.15))
        == "bench_work_precision_settled_rows_corner_design94.31-1.839-0.15"
    )
    b = design_bearing((94.31, 1.839, 0.15))
    assert math.isclose(float(b.roller.end_radius), 94.31e-3)
    assert math.isclose(float(b.flange.layback_angle), math.radians(1.839))
    assert math.isclose(float(b.flange.axial_clearance), 0.15e-3)
    reference_radius = float(jb.reference_bearing().roller.end_radius)
    assert float(design_bearing(None).roller.end_radius) == reference_radius
