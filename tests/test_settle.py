"""Settled runs (`simulate --settle`): option errors, a short fixed-settle run with confidence
intervals on every statistic, and a run that hits the settling cap (never silent, exit 1).
Reduced size (11 raceway slices, 2-revolution windows) to keep the tests short."""

import json
import math

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
        ("--start", "warm", "--start"),
        ("--workers", "0", "--workers"),
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


def test_auto_settle_succeeds_and_reports_intervals(small_config, capsys):
    """A successful `--settle auto` run (11 slices, one seed, tolerance 2e-3): from
    the skid start the revolution-mean cage speed of two consecutive revolutions agrees to the
    tolerance, the run is declared settled there (no cap), and the window of two revolutions that
    follows reports every statistic with its confidence interval. (The fixed settling time is run
    on real output by tests/test_steady_design.py.)"""
    d, cfg = small_config
    out = d / "auto"
    code = main(
        [
            "simulate",
            "--config",
            cfg,
            "--end",
            "arc",
            "--settle",
            "auto",
            "--window-revs",
            "2",
            "--start",
            "skid",
            "--settle-tolerance",
            "2e-3",
            "--out",
            str(out),
        ]
    )
    text = capsys.readouterr().out
    assert code == 0, text
    s = json.loads((out / "summary.json").read_text())
    assert s["status"] == "ok" and s["settled"] is True and s["settle_mode"] == "auto"
    (seed,) = s["per_seed"]
    assert seed["settled"] is True and s["seeds"] == [0] and s["window_revs"] == 2
    # the criterion, from the revolutions themselves: the settling revolutions are those before
    # the window; the last two agree to the tolerance, no earlier pair does
    speeds, ends = seed["revolution_cage_speed_rpm"], seed["revolution_end_ms"]
    n = len(speeds) - 2
    assert n >= 2 and s["settle_time_ms"] == pytest.approx(ends[n - 1])
    assert s["settle_time_ms"] < s["settle_cap_ms"]
    tol = s["settle_tolerance"]
    assert tol == 2e-3
    assert abs(speeds[n - 1] - speeds[n - 2]) <= tol * abs(speeds[n - 1])
    assert all(abs(speeds[k] - speeds[k - 1]) > tol * abs(speeds[k]) for k in range(1, n - 1))
    # two cage revolutions at the window's cage speed (the skid start: about 8500 rpm)
    assert s["window_ms"] == pytest.approx(2 * 60e3 / s["cage_speed_rpm"]["value"], rel=0.01)
    assert s["window_ms"] == pytest.approx(ends[-1] - ends[n - 1], rel=1e-9)
    assert s["start"] == "skid" and seed["start_cage_speed_rpm"] < s["kinematic_cage_speed_rpm"]
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
    """A cap of 1 ms from the quasi-static start (kinematic speeds, no projective steps): the
    first revolution passes the cap, the run measures unsettled, says so and exits 1."""
    d, cfg = small_config
    out = d / "capped"
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
            "--start",
            "quasi-static",
            "--out",
            str(out),
        ]
    )
    text = capsys.readouterr().out
    assert code == 1
    assert "settled false" in text and "NOT SETTLED" in text
    s = json.loads((out / "summary.json").read_text())
    assert s["settled"] is False and s["settle_cap_ms"] == 1.0 and s["start"] == "quasi-static"
    (seed,) = s["per_seed"]
    assert len(seed["revolution_cage_speed_rpm"]) == 3  # one revolution past the cap, then the window
    assert seed["projective_steps_rpm"] == []
    # the quasi-static start runs the cage at the kinematic speed (pure rolling)
    assert seed["start_cage_speed_rpm"] == pytest.approx(s["kinematic_cage_speed_rpm"], rel=1e-9)


@pytest.mark.slow
def test_halving_the_tolerances_moves_settled_pv_and_slip_less_than_their_intervals():
    """Issue 11 acceptance at a reduced size (11 slices per raceway, a 4-revolution window,
    seeds 0-2 in two processes, skid start, settle auto), MODEL.md 7: halving the tolerances (rtol
    and atol; the default atol is 10 nm, 10 um/s, 0.01 rad/s since the state's scales were chosen
    for it, docs/model.md 13) moves the settled mean PV and the cage slip by less than the 95 % CI
    half-width of their difference, sqrt(h_1^2 + h_2^2) for two independent estimates with
    half-widths h_1, h_2: the change is not significant. (Measured with rtol alone halved, before
    the scales changed: mean PV moved 2.0 % against half-widths 1.5 % and 4.4 %.)

    The interval is the ensemble one (Student-t over the seeds), as in `--seeds 4`: one seed's
    batch-means interval of the cage slip is far too narrow (0.04 rpm: consecutive revolutions of
    the slow cage are alike, the batches are not independent, docs/model.md 16), narrower than
    where a projective step lands; measured with one seed, halving rtol moved the slip by 0.3 rpm
    against a half-width of 0.04 rpm, while the seed-to-seed spread is about 2 rpm."""
    import dataclasses

    import jaxbearing as jb

    b = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    op = jb.reference_operating_point()
    runs = [
        jb.summarise(jb.simulate(b, op, settle="auto", window_revs=4, seeds=3, workers=2, rtol=r, atol=a))
        for r, a in ((1e-3, 1e-6), (5e-4, 5e-7))
    ]
    assert all(s["status"] == "ok" and s["settled"] for s in runs)
    for get in (lambda s: s["flange_pv_Pa_m_s"]["mean"], lambda s: s["cage_slip"]):
        ref, fine = get(runs[0]), get(runs[1])
        h1, h2 = (0.5 * (e["ci95_high"] - e["ci95_low"]) for e in (ref, fine))
        assert abs(fine["value"] - ref["value"]) < math.hypot(h1, h2), (ref, fine)


def test_demo_paper_table_shows_settled_estimates_with_intervals():
    from jaxbearing.cli._demo import paper_table

    est = {"value": 1.5e9, "ci95_low": 1.2e9, "ci95_high": 1.8e9, "n": 4}
    summaries = {e: {"flange_pressure_Pa": {"max": est}} for e in ("arc", "corner")}
    table = paper_table(summaries)
    assert "1.5 [1.2, 1.8]" in table and "about 4.8" in table
    assert "0.35" in paper_table({"arc": {"flange_pressure_Pa": {"max": 0.35e9}}})


@pytest.mark.parametrize("kwargs, name", [({"start": "warm"}, "start"), ({"workers": 0}, "workers")])
def test_bad_start_or_workers_in_python_one_line(kwargs, name):
    import jaxbearing as jb
    from jaxbearing import UserInputError

    with pytest.raises(UserInputError, match=f"^{name} = "):
        jb.simulate(jb.reference_bearing(), jb.reference_operating_point(), settle="auto", **kwargs)


def test_settled_options_reach_the_run(monkeypatch):
    """`--seeds`, `--workers`, `--settle-tolerance`, `--settle-cap-ms`, `--window-revs`, `--start`
    and `--settle` arrive in the settled run `simulate` is asked for (a stand-in records the
    request and stops the command; the real settled runs are the tests above)."""
    import jaxbearing.run as run

    seen = []

    def stand_in(bearing, op, **kw):
        seen.append(kw)
        raise KeyboardInterrupt

    monkeypatch.setattr(run, "simulate", stand_in)
    args = ["--settle", "auto", "--seeds", "3", "--workers", "2", "--settle-tolerance", "2e-3"]
    args += ["--settle-cap-ms", "50", "--window-revs", "4", "--start", "quasi-static"]
    assert main(["simulate", "--end", "arc", *args, "--no-progress"]) == 130
    (kw,) = seen
    assert (kw["settle"], kw["seeds"], kw["workers"]) == ("auto", 3, 2)
    assert (kw["tolerance"], kw["settle_cap_ms"], kw["window_revs"], kw["start"]) == (
        2e-3,
        50.0,
        4,
        "quasi-static",
    )
