"""Misalignment study at reduced size, on settled running (slow: 468 s on the shared 2-core
machine under a load average of 6-10, `pytest -m slow -k skew`).

benchmarks/studies/bench_misalignment.py's `study` with its QUICK settings: misalignment 0, 1, 2 mrad at
the reference point, each settled (`settle="auto"` from the skid start, docs/model.md 16), then a
window of 2 cage revolutions, one seed. Asserted: every run settled (no cap hit), and the mean
roller skew and the mean total flange load increase with misalignment (means). Whether each step
is also resolved by the 95 % intervals (batch means over 2 revolutions, 1 dof: wide) is recorded
in the benchmark's output, not asserted here; the full study (3 seeds, 4 revolutions) is
benchmarks/results/bench_misalignment.json.
"""

import sys
from pathlib import Path

import pytest

sys.path[:0] = [str(Path(__file__).resolve().parents[1] / "benchmarks" / d) for d in ("studies", ".")]


@pytest.mark.slow
def test_misalignment_raises_mean_skew_and_flange_load():
    import bench_misalignment as bm

    out = bm.study(**bm.QUICK, log=lambda *a: None)
    assert out["ok"], [r["status"] for r in out["rows"]]
    assert out["all_settled"], [r["per_seed_settling"] for r in out["rows"]]
    skew = out["trend"]["roller_skew_mean_abs"]
    load = out["trend"]["total_flange_load"]
    assert skew["increasing"], skew["means"]
    assert load["increasing"], load["means"]


@pytest.mark.slow
def test_free_ring_under_axial_load_integrates_and_loads_the_opposite_flanges():
    """2 ms with both freedoms on, 1 mrad misalignment and 200 N along +X (10-60 s with compilation): the
    solve succeeds, the ring moves towards +X, and the load path is inner -X flange -> rollers ->
    outer +X flange (the other two flanges stay open)."""
    import numpy as np

    import jaxbearing as jb

    cfg = jb.loads_config(
        "[operating]\naxial_load_N = 200.0\ninner_ring_axial_freedom = true\n"
        "inner_ring_tilt_freedom = true\nmisalignment_mrad = 1.0\n"
    )
    res = jb.simulate(jb.reference_bearing(), cfg.operating_point(), duration=2e-3, num_saves=200)
    assert res.status == "ok"
    f = np.asarray(res.histories["flange_force"])[-40:].sum(axis=1).mean(axis=0)  # (4,) mean totals
    assert f[0] > 10.0 and f[3] > 10.0  # inner -X, outer +X
    assert f[1] == 0.0 and f[2] == 0.0  # inner +X, outer -X
