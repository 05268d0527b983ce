"""`jaxbearing validate`: measured cage speeds read with their units, the model run settled at
every point, the comparison written as a table, a JSON record and a figure; finished points kept
when a run is interrupted. The fixture examples/validation/made_up_cage_speeds.csv holds made-up
numbers (said in the file), not measurements."""

from __future__ import annotations

import csv
import json
import math
import pathlib

import pytest

from jaxbearing.cli import main
from jaxbearing.io import read_cage_speed_measurements

REPO = pathlib.Path(__file__).resolve().parents[1]
FIXTURE = REPO / "examples" / "validation" / "made_up_cage_speeds.csv"
SMALL = "[bearing]\nnum_slices = 11\n[simulation]\nprogress = false\n"


def test_fixture_says_it_is_made_up_and_reads_with_its_units():
    text = FIXTURE.read_text()
    assert "MADE-UP NUMBERS" in text and "not measurements" in text
    points, ignored = read_cage_speed_measurements(FIXTURE)
    assert ignored == []
    assert [(p.shaft_speed_rpm, p.radial_load_N, p.cage_speed_rpm) for p in points][:2] == [
        (10000.0, 1000.0, 4230.0),
        (20000.0, 1000.0, 8400.0),
    ]
    assert points[0].line == 6  # comments counted: errors name the file's own line


def test_units_are_converted_and_other_columns_ignored(tmp_path):
    f = tmp_path / "m.csv"
    f.write_text(
        "Cage Speed [rad/s],temperature [C], Radial load [kN],shaft speed [RPM]\n100.0, 40, 1.5, 12000\n"
    )
    points, ignored = read_cage_speed_measurements(f)
    assert ignored == ["temperature [C]"]
    (p,) = points
    assert p.cage_speed_rpm == pytest.approx(100.0 * 30.0 / math.pi, rel=1e-15)
    assert (p.radial_load_N, p.shaft_speed_rpm) == (1500.0, 12000.0)


@pytest.mark.parametrize(
    "text, words",
    [
        ("shaft speed [rpm], radial load [N]\n1, 2\n", "missing column(s) 'cage speed'"),
        ("shaft speed [rpm], radial load [lbf], cage speed [rpm]\n1, 2, 3\n", "'radial load' in 'lbf'"),
        ("shaft speed, radial load [N], cage speed [rpm]\n1, 2, 3\n", "has no unit"),
        (
            "shaft speed [rpm], radial load [N], cage speed [rpm]\n1000, 2, fast\n",
            "line 2: cage speed = 'fast'",
        ),
        ("shaft speed [rpm], radial load [N], cage speed [rpm]\n-5, 2, 3\n", "line 2: shaft speed = '-5'"),
        ("shaft speed [rpm], radial load [N], cage speed [rpm]\n1000, nan, 3\n", "radial load = 'nan'"),
        ("shaft speed [rpm], radial load [N], cage speed [rpm]\n1000, 2\n", "2 values, the header has 3"),
        ("shaft speed [rpm], radial load [N], cage speed [rpm]\n", "a header but no operating point"),
        ("# only a comment\n", "no header and no data"),
    ],
)
def test_bad_measurement_files_are_one_line_before_any_run(tmp_path, capsys, text, words):
    f = tmp_path / "m.csv"
    f.write_text(text)
    out = tmp_path / "out"
    assert main(["validate", str(f), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0] and str(f) in err[0], err
    assert not out.exists()  # refused before anything was created


@pytest.mark.parametrize(
    "args, words",
    [
        (["--seeds", "0"], "--seeds = 0.0: must be an integer >= 1"),
        (["--window-revs", "1"], "--window-revs"),
        (["--settle", "off"], "--settle = 'off'"),
        (["--settle", "soon"], "--settle"),
        (["--end", "round"], "--end = 'round'"),
        (["--workers", "0"], "--workers"),
    ],
)
def test_bad_options_are_one_line(capsys, args, words):
    assert main(["validate", str(FIXTURE), *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0], err


@pytest.fixture(scope="module")
def two_points(tmp_path_factory):
    """The fixture's first two points (10,000 and 20,000 rpm at 1000 N), a reduced bearing."""
    d = tmp_path_factory.mktemp("validate")
    lines = FIXTURE.read_text().splitlines()
    header = next(i for i, s in enumerate(lines) if not s.startswith("#"))
    (d / "two.csv").write_text("\n".join(lines[: header + 3]) + "\n")
    (d / "c.toml").write_text(SMALL)
    return d


#: a 0.5 ms settle: the skid start lands on the plateau (tests/test_skid.py)
ARGS = ["--settle", "0.5", "--window-revs", "2", "--seeds", "2", "--workers", "1", "--no-progress"]


def test_validate_writes_the_comparison(two_points, capsys):
    d = two_points
    out = d / "out"
    code = main(
        [
            "validate",
            str(d / "two.csv"),
            "--config",
            str(d / "c.toml"),
            "--end",
            "arc",
            *ARGS,
            "--out",
            str(out),
        ]
    )
    text = capsys.readouterr().out
    assert code == 0, text
    rows = list(csv.DictReader((out / "validation.csv").open()))
    doc = json.loads((out / "validation.json").read_text())
    assert [float(r["shaft_speed_rpm"]) for r in rows] == [10000.0, 20000.0]
    for r, p in zip(rows, doc["points"]):
        model, measured = float(r["model_cage_speed_rpm"]), float(r["measured_cage_speed_rpm"])
        lo, hi = float(r["model_ci95_low_rpm"]), float(r["model_ci95_high_rpm"])
        assert lo < model < hi  # two seeds: a Student-t interval
        assert float(r["relative_error"]) == pytest.approx((model - measured) / measured, rel=1e-12)
        assert float(r["relative_error_ci95_low"]) == pytest.approx((lo - measured) / measured, rel=1e-12)
        assert (r["measurement_inside_ci"] == "True") == (lo <= measured <= hi)
        # physics, not yesterday's numbers: the cage runs below its kinematic speed (it slips)
        assert 0.0 < model < p["kinematic_cage_speed_rpm"] and p["settled"] is True
        assert p["seeds"] == [0, 1] and p["status"] == "ok"
    # the cage speed grows with the shaft speed (roughly in proportion: slip of a few per cent)
    m10, m20 = (float(r["model_cage_speed_rpm"]) for r in rows)
    assert 1.7 < m20 / m10 < 2.3
    assert doc["config"]["bearing"]["num_slices"] == 11 and doc["command"][:2] == ["jaxbearing", "validate"]
    assert doc["units"]["model_cage_speed_rpm"] == "rpm" and doc["seeds"] == [0, 1]
    assert (out / "validation.png").stat().st_size > 10_000
    assert "error %" in text and "[" in text


def test_an_interrupted_validation_keeps_its_finished_points(two_points, capsys, monkeypatch):
    """The second point is interrupted (Ctrl-C): exit 130, and validation.csv holds the first
    point, finished before it. The points in the other order (20,000 rpm first: its
    revolutions take half the time of 10,000 rpm's, and `test_validate_writes_the_comparison`
    stored the skid start of its seed 0)."""
    from jaxbearing.run import _measured

    real = _measured.simulate_steady
    calls = []

    def interrupted_second(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(_measured, "simulate_steady", interrupted_second)
    d = two_points
    out = d / "killed"
    lines = (d / "two.csv").read_text().splitlines()
    (d / "swapped.csv").write_text("\n".join([*lines[:-2], lines[-1], lines[-2]]) + "\n")
    one_seed = [*ARGS[:5], "1", *ARGS[6:]]  # one seed: the first point's run is all this needs
    code = main(
        ["validate", str(d / "swapped.csv"), "--config", str(d / "c.toml"), *one_seed, "--out", str(out)]
    )
    assert code == 130
    rows = list(csv.DictReader((out / "validation.csv").open()))
    assert [float(r["shaft_speed_rpm"]) for r in rows] == [20000.0]
    assert not (out / "validation.json").exists()  # the record is written once every point is done
