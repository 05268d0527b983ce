"""Settled runs (`simulate --settle`): option errors, a short fixed-settle run with confidence
intervals on every statistic, and a run that hits the settling cap (never silent, exit 1).
Reduced size (11 raceway slices, 2-revolution windows) to keep the tests short."""

import json

import pytest

from jaxbearing.cli import main

EVENT_STATS = (
    "flange_force_N",
    "flange_pressure_Pa",
    "flange_sliding_velocity_m_s",
    "flange_pv_Pa_m_s",
    "contact_height_m",
    "contact_radius_m",
)


@pytest.mark.parametrize(
    "option, value, name",
    [
        ("--window-revs", "-1", "--window-revs"),
        ("--window-revs", "2.5", "--window-revs"),
        ("--seeds", "0", "--seeds"),
        ("--settle-tolerance", "0", "--settle-tolerance"),
        ("--settle-tolerance", "-1e-3", "--settle-tolerance"),
        ("--settle-cap-ms", "0", "--settle-cap-ms"),
        ("--settle", "soon", "--settle"),
        ("--settle", "-5", "--settle"),
    ],
)
def test_bad_steady_options_one_line(option, value, name, capsys):
    given = f"{option}={value}"  # '=' so that argparse reads a negative number as the value
    args = ["simulate", "--settle", "auto", given] if option != "--settle" else ["simulate", given]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and name in err[0] and "must be" in err[0]


@pytest.fixture(scope="module")
def small_config(tmp_path_factory):
    d = tmp_path_factory.mktemp("settle")
    cfg = d / "c.toml"
    cfg.write_text("[bearing]\nnum_slices = 11\n[simulation]\nprogress = false\n")
    return d, str(cfg)


def test_fixed_settle_reports_intervals(small_config, capsys):
    d, cfg = small_config
    out = d / "fixed"
    code = main(
        [
            "simulate",
            "--config",
            cfg,
            "--end",
            "arc",
            "--settle",
            "2",
            "--window-revs",
            "2",
            "--out",
            str(out),
        ]
    )
    text = capsys.readouterr().out
    assert code == 0, text
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "ok" and s["settled"] is True and s["settle_mode"] == "fixed"
    assert s["settle_time_ms"] == pytest.approx(2.0)
    assert s["seeds"] == [0] and s["window_revs"] == 2
    assert s["window_ms"] == pytest.approx(2 * 6.6, rel=0.05)  # two cage revolutions near 9000 rpm
    for key in EVENT_STATS:
        for stat in ("max", "mean", "median", "p95"):
            est = s[key][stat]
            assert set(est) == {"value", "ci95_low", "ci95_high", "n"}
            assert est["ci95_low"] <= est["value"] <= est["ci95_high"]
    for key in ("cage_speed_rpm", "cage_slip"):
        assert s[key]["ci95_low"] <= s[key]["value"] <= s[key]["ci95_high"]
    assert 0 <= s["corner_contact_share"]["events"]["value"] <= 1
    assert s["contact_radius_m"]["p99"]["value"] < s["limited_circle_radius_m"]
    assert "batch means" in s["ci_method"]
    assert "corner-contact share" in text


def test_auto_settle_hitting_the_cap_is_not_silent(small_config, capsys):
    _, cfg = small_config
    code = main(
        [
            "simulate",
            "--config",
            cfg,
            "--end",
            "arc",
            "--settle",
            "auto",
            "--settle-cap-ms",
            "1",
            "--window-revs",
            "2",
        ]
    )
    text = capsys.readouterr().out
    assert code == 1
    assert "settled false" in text and "NOT SETTLED" in text
