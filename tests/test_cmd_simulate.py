"""`jaxbearing simulate` end to end: outputs, both end types, bad input, forced failure."""

import json

import numpy as np
import pytest
from _figures import assert_png_drawn

from jaxbearing.cli import main

SUMMARY_STATS = (
    "flange_force_N",
    "flange_pressure_Pa",
    "flange_sliding_velocity_m_s",
    "flange_pv_Pa_m_s",
    "contact_height_m",
    "contact_radius_m",
)


def _config(tmp_path, text):
    p = tmp_path / "c.toml"
    p.write_text(text)
    return str(p)


@pytest.fixture(scope="module")
def both_run(tmp_path_factory):
    """The reference bearing, both ends, 2 ms: the configuration file says otherwise (15000 rpm,
    500 N, 0.5 ms, progress on, arc only) and the command-line options win."""
    import contextlib
    import io

    out = tmp_path_factory.mktemp("sim")
    cfg = out / "c.toml"
    cfg.write_text(
        "[operating]\nspeed_rpm = 15000.0\nradial_load_N = 500.0\n"
        '[simulation]\nduration_ms = 0.5\nprogress = true\nend = "arc"\n'
    )
    args = ["--speed-rpm", "20000", "--load-N", "1000", "--transient", "--duration-ms", "2", "--no-progress"]
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        code = main(["simulate", "--config", str(cfg), "--end", "both", *args, "--out", str(out)])
    return code, out, text.getvalue()


def test_both_ends_write_summary_histories_plots(both_run, capsys):
    code, out, _ = both_run
    assert code == 0
    doc = json.loads((out / "summary.json").read_text())
    assert {"arc", "corner"} <= set(doc) and doc["ends"] == ["arc", "corner"]
    _, _, printed = both_run
    assert printed.count("START-UP TRANSIENT: 2 ms from the quasi-static start, not settled running") == 1
    for end in ("arc", "corner"):
        block = doc[end]
        assert block["status"] == "ok" and block["running"] == "start-up transient"
        for key in (
            "cage_speed_rpm",
            "kinematic_cage_speed_rpm",
            "cage_slip",
            "flange_contact_events",
            "on_arc_fraction",
            "num_steps",
            "wall_time_s",
            "status",
        ):
            assert key in block
        for key in SUMMARY_STATS:
            assert set(block[key]) == {"max", "mean", "median", "min"}
        # lubricated flange contact (issue 14): film statistics over contact time
        assert set(block["film_parameter"]) == {"mean", "median", "p05", "min"}
        assert set(block["flange_min_film_m"]) == {"min", "p05", "median"}
        assert block["flange_min_film_m"]["min"] > 0 and block["film_parameter"]["p05"] > 0
        for key in ("lambda_below_one_share", "top_edge_contact_share"):
            assert 0.0 <= block[key] <= 1.0
        # friction power per flange and in total, flash temperature at the rib (docs/model.md 5.5)
        power = block["flange_friction_power_W"]
        assert set(power) == {"inner_neg_x", "inner_pos_x", "outer_neg_x", "outer_pos_x", "total"}
        np.testing.assert_allclose(sum(v for k, v in power.items() if k != "total"), power["total"])
        assert power["total"] > 0 and block["flange_flash_temperature_K"]["max"] > 0
        h = np.load(out / f"histories_{end}.npz")
        assert h["flange_force"].shape[1:] == (26, 4)
        for key in ("flange_min_film", "flange_central_film", "flange_film_parameter", "flange_top_edge"):
            assert h[key].shape == h["flange_force"].shape
        mu_q_u = h["flange_friction_coefficient"] * h["flange_force"] * h["flange_sliding_speed"]
        np.testing.assert_allclose(h["flange_friction_power"], mu_q_u, rtol=1e-12, atol=1e-300)
        touching = h["flange_force"] > 1.0
        assert np.all(h["flange_flash_temperature"][touching] > 0)
        assert np.all(h["flange_flash_temperature"] >= 0)
    assert printed.count("flash temperature") == 1 and printed.count("friction power (mean)") == 2
    for png in ("flange_boxplots.png", "contact_positions.png", "cage_speed.png"):
        assert_png_drawn(out / png)
    # arc ends press less on the flange than corners (the paper's headline result)
    assert doc["arc"]["flange_pressure_Pa"]["max"] < doc["corner"]["flange_pressure_Pa"]["max"]


def test_invalid_config_one_line_exit_2(tmp_path, capsys):
    cfg = _config(tmp_path, "[roller]\ncorner_radius_mm = 5.0\n")
    assert main(["simulate", "--config", cfg]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "roller.corner_radius_mm" in err[0]


def test_invalid_override_one_line_exit_2(tmp_path, capsys):
    assert main(["simulate", "--speed-rpm", "-5"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "operating.speed_rpm" in err[0]


def test_unknown_solver_one_line_exit_2(capsys):
    """`--solver` overrides simulation.solver; a name outside the choices is one line naming the
    option and the valid values, before anything is compiled."""
    assert main(["simulate", "--solver", "rk4"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--solver" in err[0] and "tsit5" in err[0] and "ros34pw2" in err[0]


def test_solver_reaches_the_run(monkeypatch):
    """The configured solver, or `--solver`, is the one `simulate` receives."""
    import jaxbearing as jb
    import jaxbearing.run as run
    from jaxbearing.cli._simulate import run_cases

    seen = {}

    def fake(bearing, op, **kw):
        seen.update(kw)
        raise SystemExit(0)

    monkeypatch.setattr(run, "simulate", fake)
    cfg = jb.loads_config('[simulation]\nsolver = "ros34pw2"\nend = "arc"\n')
    with pytest.raises(SystemExit):
        run_cases(cfg, progress=False)
    assert seen["solver"] == "ros34pw2"
    # `--solver` over the configuration's (the reference's tsit5); ROS34PW2 on the bearing runs
    # in tests/test_rosenbrock.py
    seen.clear()
    with pytest.raises(SystemExit):
        main(["simulate", "--solver", "ros34pw2", "--end", "arc", "--no-progress"])
    assert seen["settings"].solver == "ros34pw2"  # a settled run: the solver is a setting


def test_progress_of_a_fixed_run_keeps_the_program_cacheable(monkeypatch, capsys):
    """With progress on, a fixed-duration run is solved without the in-solve meter (a host
    callback: JAX would compile that program afresh in every process); the host-side meter
    prints the closing line from the result."""
    import types

    import jaxbearing as jb
    import jaxbearing.run as run
    from jaxbearing.cli._simulate import run_cases

    seen = []

    def fake(bearing, op, **kw):
        seen.append(kw)
        ok = len(seen) == 1  # the arc run succeeds, the corner run stops at a quarter
        return types.SimpleNamespace(ok=ok, reached_time=kw["duration"] * (1.0 if ok else 0.25))

    monkeypatch.setattr(run, "simulate", fake)
    monkeypatch.setattr(run, "summarise", lambda res: {})
    cfg = jb.loads_config('[simulation]\nduration_ms = 2.0\nend = "both"\n')
    run_cases(cfg, progress=True)
    assert [kw["progress"] for kw in seen] == [False, False]
    out = capsys.readouterr().out
    assert "[arc end] simulating a 2 ms start-up transient" in out and "100% of the simulated time" in out
    assert "stopped at 25.0% of the simulated time" in out


def test_host_progress_prints_elapsed_time_and_the_closing_line(capsys):
    import time

    import jaxbearing as jb
    from jaxbearing.run import HostProgress

    # wait for the first tick however loaded the machine is (no wall-clock threshold: the
    # deadline only keeps a broken meter from hanging the suite)
    printed = ""
    with HostProgress(interval=0.05) as meter:
        deadline = time.monotonic() + 120
        while "s elapsed" not in printed and time.monotonic() < deadline:
            time.sleep(0.01)
            printed += capsys.readouterr().out
    meter.close(1.0)
    with HostProgress(interval=10.0) as meter:
        pass
    meter.close(0.372)
    ticks = printed.splitlines()
    assert ticks and all(line.strip().endswith("s elapsed") and "%" not in line for line in ticks)
    lines = capsys.readouterr().out.splitlines()
    assert "100% of the simulated time" in lines[-2]
    assert "stopped at 37.2% of the simulated time" in lines[-1] and "the solve failed" in lines[-1]
    with pytest.raises(jb.UserInputError, match=r"^interval = -1.0: must be > 0 s$"):
        HostProgress(interval=-1)


def test_forced_solver_failure_nonzero_exit(tmp_path, capsys):
    """A failed solve: exit 1, the progress meter says where it stopped (no jump to 100 %), the
    table marks the failed run's values, summary.json is strict JSON (issue 16)."""
    cfg = _config(tmp_path, '[simulation]\nduration_ms = 0.6\nmax_steps = 30\nprogress = true\nend = "arc"\n')
    out = tmp_path / "out"
    assert main(["simulate", "--config", cfg, "--transient", "--out", str(out)]) == 1
    printed = capsys.readouterr().out
    assert "stopped at" in printed and "100%" not in printed
    assert "! [arc] the run failed" in printed

    def strict(token):
        raise ValueError(f"non-standard JSON token {token}")

    doc = json.loads((out / "summary.json").read_text(), parse_constant=strict)
    assert doc["status"].startswith("failed")
    assert "max_steps" in doc["status"]
    assert doc["smooth_peak_pv_Pa_m_s"] is None
    assert doc["null_reasons"]["smooth_peak_pv_Pa_m_s"] == "nan: the run failed (see status)"
    assert "not reliable" in doc["warning"]


def test_forced_failure_reports_status():
    """The Python API's report of a failed solve (moved here from tests/test_dynamics.py: it is
    the program of the failure run above, default num_saves and max_steps 30, and a step limit
    is static, so in another file it was a second compilation)."""
    import jaxbearing as jb
    from jaxbearing.run import simulate, summarise

    res = simulate(jb.reference_bearing(), jb.reference_operating_point(), duration=0.004, max_steps=30)
    s = summarise(res)
    assert not res.ok
    assert s["status"].startswith("failed: the step limit max_steps was reached")
    assert "simulated time reached" in s["status"]
    assert np.isnan(res.smooth_peak_pv)


def test_command_line_overrides_win_over_the_file(both_run):
    """`--speed-rpm`, `--load-N`, `--duration-ms`, `--end` and `--no-progress` over the file's
    values: the kinematic cage speed is n_i (1 - D/d_m) / 2 at 20000 rpm, the quasi-static start
    carries 1000 N (the contacts' force on the inner ring balances the radial load and the
    ring's weight, a few newtons), the histories end at 2 ms and no progress is printed."""
    code, out, text = both_run
    assert code == 0
    doc = json.loads((out / "summary.json").read_text())
    for end in ("arc", "corner"):
        assert doc[end]["kinematic_cage_speed_rpm"] == pytest.approx(20000 * (1 - 7.5 / 85.0) / 2, rel=1e-9)
        h = np.load(out / f"histories_{end}.npz")
        assert h["t"][-1] == pytest.approx(2e-3, rel=1e-9)
        assert np.linalg.norm(h["inner_ring_contact_force"][0]) == pytest.approx(1000.0, rel=0.01)
    assert "simulating" not in text and "elapsed" not in text and "% of the simulated time" not in text


def test_demo_transient_writes_both_ends(both_run, tmp_path, capsys):
    """`jaxbearing demo --transient --duration-ms 0.2 --out DIR`: one fixed-duration run per end
    type of the reference bearing from the quasi-static start, 0.2 ms each (the program of the
    `simulate` run above, so nothing new is compiled), the paper table, and the outputs in DIR."""
    out = tmp_path / "demo"
    assert main(["demo", "--transient", "--duration-ms", "0.2", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "a 0.2 ms start-up transient" in text and "peak pressure, max" in text
    assert f"written to {out}/" in text
    doc = json.loads((out / "summary.json").read_text())
    assert doc["ends"] == ["arc", "corner"] and doc["command"][:3] == ["jaxbearing", "demo", "--transient"]
    assert doc["config"]["operating"]["speed_rpm"] == 20000.0 and "jaxbearing_version" in doc
    for end in ("arc", "corner"):
        assert doc[end]["status"] == "ok"
        t = np.load(out / f"histories_{end}.npz")["t"]
        assert t[0] == 0.0 and t[-1] == pytest.approx(0.2e-3, rel=1e-9)
    for png in ("flange_boxplots.png", "contact_positions.png", "cage_speed.png"):
        assert_png_drawn(out / png)


def test_demo_settled_passes_its_window_to_the_run(tmp_path, capsys, monkeypatch):
    """`jaxbearing demo --window-revs 3 --out DIR` (the default, settled mode) asks `run_cases`
    for a settled run of both ends with a 3-revolution window from the skid start, settle auto
    (a stand-in records the request and stops the command: the real settled demo runs the full
    bearing for minutes; settled runs on real output are tests/test_settle.py); a window that is
    not a whole number >= 2 revolutions is refused before anything runs."""
    import jaxbearing.cli._simulate as simulate_cli

    seen = []

    def stand_in(cfg, progress=True, steady=None):
        seen.append((cfg.simulation.end, steady))
        raise KeyboardInterrupt

    monkeypatch.setattr(simulate_cli, "run_cases", stand_in)
    out = tmp_path / "demo"
    assert main(["demo", "--window-revs", "3", "--out", str(out)]) == 130
    from jaxbearing.run import SteadySettings

    assert seen == [("both", SteadySettings(window_revs=3))]  # settle auto, one seed, the skid start
    assert not out.exists()
    capsys.readouterr()
    assert main(["demo", "--window-revs", "2.5", "--out", str(out)]) == 2
    assert "--window-revs" in capsys.readouterr().err and len(seen) == 1


def test_simulate_settles_by_default_and_a_transient_is_explicit(monkeypatch, capsys):
    """`jaxbearing simulate` without options is a settled run (`--settle auto`); a start-up
    transient takes `--transient` or `--settle off`; `--duration-ms` without it, or `--transient`
    with a settling mode, is one line naming the option (exit 2), never silently ignored."""
    import jaxbearing.run as run

    seen = []

    def fake(bearing, op, **kw):
        seen.append(kw)
        raise SystemExit(0)

    monkeypatch.setattr(run, "simulate", fake)
    for args, settle in (
        ([], run.SettleAuto()),
        (["--settle", "5"], run.SettleFixed(5.0)),
        (["--transient"], None),
        (["--settle", "off"], None),
    ):
        seen.clear()
        with pytest.raises(SystemExit):
            main(["simulate", "--end", "arc", "--no-progress", *args])
        settings = seen[0].get("settings")
        assert (None if settings is None else settings.settle) == settle, (args, seen[0])
    capsys.readouterr()
    for args, words in (
        (
            ["--duration-ms", "2"],
            "--duration-ms = 2: sets the length of a start-up transient; add --transient",
        ),
        (["--transient", "--settle", "auto"], "--transient: cannot be combined with --settle auto"),
    ):
        assert main(["simulate", "--no-progress", *args]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and words in err[0], err
