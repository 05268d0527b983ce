"""Misalignment study at reduced size (slow: about 6 minutes on the shared 2-core machine).

benchmarks/bench_misalignment.py's `study` with its QUICK settings: misalignment 0, 1, 2 mrad at
the reference point, 1 ms of fixed settling (NOT settled: the cage needs 100-150 ms), a window
of 2 cage revolutions, one seed. Asserted: the mean roller skew and the mean total flange load
increase with misalignment (means). Whether each step is also resolved by the 95 % intervals
(batch means over 2 revolutions, 1 dof: wide) is recorded in the benchmark's output, not
asserted here.
"""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))


@pytest.mark.slow
def test_misalignment_raises_mean_skew_and_flange_load():
    import bench_misalignment as bm

    out = bm.study(**bm.QUICK, log=lambda *a: None)
    assert out["ok"], [r["status"] for r in out["rows"]]
    skew = out["trend"]["roller_skew_mean_abs"]
    load = out["trend"]["total_flange_load"]
    assert skew["increasing"], skew["means"]
    assert load["increasing"], load["means"]
