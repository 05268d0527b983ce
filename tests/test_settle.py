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
    """A successful `--settle auto` run (11 slices, one seed, tolerance 2e-3): from the skid
    start the run is declared settled (before the cap) at the first revolution where the verdict
    (`settling_verdict`: the remaining drift's upper bound, from the revolution means themselves)
    is within the tolerance, and the window of two revolutions that follows reports every
    statistic with its confidence interval. (The fixed settling time is run on real output by
    tests/test_steady_design.py.)"""
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
    # the verdict, from the revolutions themselves: the settling revolutions are those before
    # the window (no projective step after a completed pre-start); the verdict holds at the last
    # of them and at no earlier one, with the run's own slow-mode time constant
    from jaxbearing.run._verdict import settling_verdict

    speeds, ends = seed["revolution_cage_speed_rpm"], seed["revolution_end_ms"]
    n = len(speeds) - 2
    assert n >= 4 and s["settle_time_ms"] == pytest.approx(ends[n - 1])
    assert s["settle_time_ms"] < s["settle_cap_ms"] and seed["projective_steps_rpm"] == []
    tol = s["settle_tolerance"]
    assert tol == 2e-3
    starts = [0.0, *ends[:-1]]
    centres = [0.5 * (a + b) * 1e-3 for a, b in zip(starts, ends)]
    tau = seed["slow_mode_time_constant_ms"] * 1e-3
    verdicts = [settling_verdict(centres[:k], speeds[:k], tol, tau) for k in range(1, n + 1)]
    assert verdicts[-1].settled and not any(v.settled for v in verdicts[:-1])
    assert seed["residual_drift_bound_rpm"] == pytest.approx(verdicts[-1].bound_rpm, rel=1e-9)
    assert seed["residual_drift_bound_rpm"] <= tol * speeds[n - 1]
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
    assert "settled false" in text and "NOT SETTLED" in text and "remaining drift" in text
    s = json.loads((out / "summary.json").read_text())
    assert s["settled"] is False and s["settle_cap_ms"] == 1.0 and s["start"] == "quasi-static"
    (seed,) = s["per_seed"]
    assert len(seed["revolution_cage_speed_rpm"]) == 3  # one revolution past the cap, then the window
    assert seed["projective_steps_rpm"] == []
    # the quasi-static start runs the cage at the kinematic speed (pure rolling)
    assert seed["start_cage_speed_rpm"] == pytest.approx(s["kinematic_cage_speed_rpm"], rel=1e-9)


def test_failed_settled_run_is_one_honest_line(small_config, capsys):
    """A settled run whose solve fails (here at its step limit): the command prints one line with
    the solver's reason and where it failed (not "NOT SETTLED ... at the cap"), writes
    summary.json, draws what it can (nothing) and exits 1 without a traceback; the Python API
    returns the same record and `summarise` does not raise. The reduced bearing and the
    quasi-static start of the run above: its start and its static skid equilibrium (the verdict's
    time constant) are built and stored already, and only the member program with its own step
    limit (static) is compiled. (Here, not in tests/test_cmd_simulate.py, whose process compiles
    the full-size `simulate` while this one builds the reduced runs: with 3 slices there, the
    start and the equilibrium were two more programs, 15 s.)"""
    import jaxbearing as jb
    from jaxbearing.run import simulate, summarise

    d, _ = small_config
    cfg = d / "failing.toml"
    cfg.write_text("[bearing]\nnum_slices = 11\n[simulation]\nprogress = false\nmax_steps = 30\n")
    out = d / "failed"
    code = main(
        ["simulate", "--config", str(cfg), "--end", "arc", "--start", "quasi-static", "--out", str(out)]
    )
    printed = capsys.readouterr()
    assert code == 1 and "Traceback" not in printed.out + printed.err
    failed = [line for line in printed.out.splitlines() if "FAILED" in line]
    assert failed == [
        "[arc] FAILED: the step limit max_steps was reached, in the cage revolution from 0.00 to "
        f"{failed[0].split(' to ')[1].split(' ms')[0]} ms; no statistics (summary.json has the run's record)"
    ]
    assert "NOT SETTLED" not in printed.out and "flange force, max" not in printed.out
    doc = json.loads((out / "summary.json").read_text())
    assert doc["running"] == "failed (see status)" and "max_steps" in doc["status"]
    assert not list(out.glob("*.png"))

    b = jb.load_config(cfg).bearing()
    res = simulate(b, jb.reference_operating_point(), settle="auto", start="quasi-static", max_steps=30)
    s = summarise(res)
    assert not res.ok and s["status"] == doc["status"] and s["running"] == "failed (see status)"


@pytest.mark.slow
def test_halving_the_tolerances_moves_settled_pv_and_slip_less_than_their_intervals():
    """Issue 11 acceptance at a reduced size (11 slices per raceway, a 4-revolution window,
    seeds 0-2 in two processes, skid start, settle auto), docs/validation.md: halving the tolerances (rtol
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


def test_continuation_settles_whole_revolutions_of_its_own_cage():
    """`continuation_settle`: without `continuation_settle_revs` the run's `settle`; with n, 2 pi n /
    |omega_c| of the given state's cage speed, in ms (the unit of `settle`)."""
    from types import SimpleNamespace

    from jaxbearing.run import SettleAuto, SettleFixed, SteadySettings
    from jaxbearing.run._member import continuation_settle

    state = SimpleNamespace(cage=SimpleNamespace(speed=-800.0))  # rad/s; the sign is the direction
    assert continuation_settle(SteadySettings(settle="auto"), state) == SettleAuto()
    two = continuation_settle(SteadySettings(settle="auto", continuation_settle_revs=2), state)
    assert isinstance(two, SettleFixed) and two.ms == pytest.approx(2 * 2 * math.pi / 800.0 * 1e3, rel=1e-15)
    assert continuation_settle(SteadySettings(settle=5.0, continuation_settle_revs=0), state) == SettleFixed(
        0.0
    )


@pytest.mark.parametrize("value", [-1, 1.5])
def test_bad_continuation_settle_revs_one_line(value):
    import jaxbearing as jb
    from jaxbearing import UserInputError
    from jaxbearing.run import simulate_steady_points

    with pytest.raises(UserInputError, match="^continuation_settle_revs = .*integer >= 0"):
        simulate_steady_points(
            jb.reference_bearing(), [jb.reference_operating_point()], continuation_settle_revs=value
        )


#: a revolution of the reference cage near its plateau (8420 rpm) [s]
REV = 60.0 / 8420.0


def _revolutions(speed, n, t0=0.0):
    """Centres of `n` revolutions from t0 and the mean of `speed(t)` over each (closed form for
    the exponential below: the mean of a line or exponential over a revolution, by quadrature)."""
    import numpy as np

    edges = t0 + REV * np.arange(n + 1)
    fine = [np.linspace(a, b, 201) for a, b in zip(edges[:-1], edges[1:])]
    return 0.5 * (edges[:-1] + edges[1:]), np.array([np.trapezoid(speed(t), t) / REV for t in fine])


def test_verdict_line_is_the_least_squares_fit():
    """The verdict's slope and standard error are those of scipy's `linregress` on the last
    `VERDICT_MAX_REVS` revolutions, the residual drift is |slope| tau, its bound adds the one-sided
    95 % Student-t quantile with n - 2 degrees of freedom; fewer than `VERDICT_MIN_REVS`
    revolutions give no verdict."""
    import numpy as np
    from scipy import stats

    from jaxbearing.run._verdict import VERDICT_MAX_REVS, VERDICT_MIN_REVS, settling_verdict

    rng = np.random.default_rng(1)
    t = REV * (np.arange(12) + 0.5)
    w = 8420.0 - 300.0 * t + rng.normal(0.0, 0.3, t.size)
    v = settling_verdict(t, w, 1e-3, 0.1)
    fit = stats.linregress(t[-VERDICT_MAX_REVS:], w[-VERDICT_MAX_REVS:])
    assert v.revolutions == VERDICT_MAX_REVS
    assert v.slope_rpm_s == pytest.approx(fit.slope, rel=1e-9)
    assert v.slope_se_rpm_s == pytest.approx(fit.stderr, rel=1e-9)
    assert v.residual_drift_rpm == pytest.approx(abs(fit.slope) * 0.1, rel=1e-9)
    q = stats.t.ppf(0.95, VERDICT_MAX_REVS - 2)
    assert v.bound_rpm == pytest.approx((abs(fit.slope) + q * fit.stderr) * 0.1, rel=1e-9)
    short = settling_verdict(t[: VERDICT_MIN_REVS - 1], w[: VERDICT_MIN_REVS - 1], 1e-3, 0.1)
    assert not short.settled and math.isnan(short.residual_drift_rpm)


def test_verdict_slow_exponential_drift_does_not_pass():
    """Issue 34 item 2: a cage speed on an exponential approach omega_inf + A exp(-t/tau)
    (tau = 100 ms, the kinematic start's approach, docs/model.md 16) that changes by less than the
    tolerance per revolution while still 0.5 % above its plateau passes the old criterion
    (consecutive revolutions within the tolerance) and must not pass the verdict; once the
    remaining offset A exp(-t/tau) is below half the tolerance it must."""
    import numpy as np

    from jaxbearing.run._verdict import settling_verdict

    tau, plateau, tol = 0.1, 8420.0, 1e-3
    for offset, settled in ((0.005 * plateau, False), (0.4 * tol * plateau, True)):
        # the approach reaches `offset` at the end of the eighth revolution
        t_end = 8 * REV

        def speed(t, offset=offset):
            return plateau + offset * np.exp(-(t - t_end) / tau)

        centres, means = _revolutions(speed, 8)
        steps = np.abs(np.diff(means))
        if not settled:
            assert np.all(steps <= tol * means[1:])  # the old criterion passes
        v = settling_verdict(centres, means, tol, tau)
        assert v.settled is settled, (offset, v)
        # the remaining drift is the offset from the plateau (the line's slope over 8 revolutions
        # of an exponential is steeper than at their end: conservative, by 34 % here)
        assert offset <= v.residual_drift_rpm <= 1.4 * offset


def test_verdict_noisy_plateau_passes_in_four_to_six_revolutions():
    """A flat plateau with the revolution means' measured scatter (about 0.2 rpm at the reference
    point, docs/model.md 16; here 0.3 rpm, i.i.d.) passes after `VERDICT_MIN_REVS` revolutions in
    most runs, within six in 95 % at least, with the conservative tau_run of 100 ms (the bound
    carries a Student-t quantile with 2 to 4 degrees of freedom)."""
    import numpy as np

    from jaxbearing.run._verdict import VERDICT_MIN_REVS, settling_verdict

    rng = np.random.default_rng(0)
    t = REV * (np.arange(12) + 0.5)
    first = []
    for _ in range(400):
        w = 8420.0 + rng.normal(0.0, 0.3, t.size)
        passed = [settling_verdict(t[:n], w[:n], 1e-3, 0.1).settled for n in range(1, t.size + 1)]
        first.append(passed.index(True) + 1 if any(passed) else np.inf)
    first = np.asarray(first)
    assert first.min() == VERDICT_MIN_REVS and np.median(first) == VERDICT_MIN_REVS
    assert np.mean(first <= 6) >= 0.95


@pytest.mark.slow
def test_kinematic_start_settles_only_on_the_skid_plateau():
    """Issue 34 acceptance at reduced size (11 slices per raceway, seed 0, 2-revolution windows,
    tolerance 5e-3 so that the kinematic start settles within the cap): from the kinematic start
    (`start="quasi-static"`) the run is declared settled only once its window cage speed agrees
    with the skid start's plateau (same seed) within the tolerance the verdict promises, widened by
    the two windows' 95 % half-widths; the old criterion (two consecutive revolution means within
    the tolerance) would have passed at a revolution whose cage speed was more than the tolerance
    above that plateau (measured: at 20 ms, 440 rpm above it). Both runs report their residual
    drift, below the tolerance."""
    import dataclasses

    import jaxbearing as jb

    b = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    op = jb.reference_operating_point()
    tol = 5e-3
    skid, kin = (
        jb.summarise(jb.simulate(b, op, settle="auto", window_revs=2, tolerance=tol, start=start))
        for start in ("skid", "quasi-static")
    )
    for s in (skid, kin):
        assert s["status"] == "ok" and s["settled"], s["per_seed"][0]
        assert s["residual_drift_bound_rpm"] <= tol * s["cage_speed_rpm"]["value"]
    plateau, speed = skid["cage_speed_rpm"], kin["cage_speed_rpm"]
    half = math.hypot(*(0.5 * (e["ci95_high"] - e["ci95_low"]) for e in (plateau, speed)))
    assert abs(speed["value"] - plateau["value"]) <= tol * plateau["value"] + half, (plateau, speed)
    revs = kin["per_seed"][0]["revolution_cage_speed_rpm"]
    old = next(i for i in range(1, len(revs)) if abs(revs[i] - revs[i - 1]) <= tol * abs(revs[i]))
    assert revs[old] - plateau["value"] > tol * plateau["value"]
    assert kin["settle_time_ms"] > kin["per_seed"][0]["revolution_end_ms"][old]


def test_running_time_constant_is_conservative():
    """tau_run = 1.5 tau_s, or the pre-start's longest positive secant -(w_k - w_{k-1}) /
    (g_k - g_{k-1}) of its measured drifts if longer (every secant, also one far outside the
    static tau_s); a secant of the wrong sign is ignored."""
    from types import SimpleNamespace

    from jaxbearing.run._verdict import RUNNING_SLOW_MODE_FACTOR, running_time_constant

    def skid(tau_s, speeds=(), drifts=()):
        return SimpleNamespace(
            static_time_constant=tau_s, time_constant=tau_s, drift_speeds=speeds, drifts=drifts
        )

    assert running_time_constant(skid(0.046), None, None, None) == pytest.approx(
        RUNNING_SLOW_MODE_FACTOR * 0.046
    )
    # secants 79.4 / 1198 = 66.3 ms and 32.8 / 530 = 61.9 ms (the reference point, docs/model.md 16)
    ref = skid(0.046, (8527.4, 8448.0, 8415.2), (-1696.0, -498.0, 32.0))
    assert running_time_constant(ref, None, None, None) == pytest.approx(RUNNING_SLOW_MODE_FACTOR * 0.046)
    assert running_time_constant(skid(0.0002, (9000.0, 8900.0), (-2000.0, -400.0)), None, None, None) == (
        pytest.approx(100.0 / 1600.0)
    )
    assert running_time_constant(skid(0.0002, (9000.0, 8900.0), (-400.0, -2000.0)), None, None, None) == (
        pytest.approx(RUNNING_SLOW_MODE_FACTOR * 0.0002)
    )


@pytest.mark.slow
def test_misaligned_run_settles_as_fast_as_the_aligned_one():
    """Issue 34 acceptance at reduced size (11 slices per raceway, seed 0, skid start, settle auto,
    2-revolution windows): with 1 mrad of imposed misalignment the run settles within twice the
    aligned run's settling time (measured: 35.6 ms against 28.5 ms; before the quasi-static start
    knew the tilt, 124.7 ms by the old criterion, still falling by 6 rpm per revolution)."""
    import dataclasses

    import equinox as eqx

    import jaxbearing as jb

    b = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    op = jb.reference_operating_point()
    aligned, tilted = (
        jb.summarise(
            jb.simulate(b, eqx.tree_at(lambda o: o.misalignment, op, m), settle="auto", window_revs=2)
        )
        for m in (0.0, 1e-3)
    )
    for s in (aligned, tilted):
        assert s["status"] == "ok" and s["settled"], s["per_seed"][0]
    assert tilted["settle_time_ms"] <= 2 * aligned["settle_time_ms"]


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
    s = kw["settings"]
    assert (s.settle, s.seeds, s.workers) == (run.SettleAuto(), 3, 2)
    assert (s.tolerance, s.settle_cap_ms, s.window_revs, s.start) == (2e-3, 50.0, 4, "quasi-static")
