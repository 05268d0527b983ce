"""Issue 38, items 2-5: outputs checked before work and results never lost after it;
plausibility warnings, `zone`'s exit status and the optimiser's start check; self-describing
summary.json; help that matches the code.

Every check but two fails before any solve (seconds). The two that solve share one reduced-size
simulate compilation (11 slices, arc end, 1 ms; compiled once per process): a write failure
injected after the solve keeps the results in the fallback directory (exit 4), and feeding
summary.json's recorded configuration back reproduces its statistics."""

from __future__ import annotations

import json
import math
import os
import pathlib
import re

import pytest

from jaxbearing.cli import EXIT_CODES, EXIT_INFEASIBLE, EXIT_RESULTS_ELSEWHERE
from jaxbearing.cli import main as jb_main
from optimise._cli import main as opt_main

ROOT = pathlib.Path(__file__).resolve().parents[1]
SPEC = ROOT / "tests" / "sweeps" / "small.toml"


def _err_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


@pytest.fixture
def blocked(tmp_path):
    """A --out path under a regular file (cannot be created by anyone, root included)."""
    f = tmp_path / "a_file"
    f.write_text("x")
    return f / "out"


# -- item 2: unwritable --out, before any solving ------------------------------------------------
@pytest.mark.parametrize(
    "command",
    [
        ["simulate"],
        ["sweep", str(SPEC)],
        ["zone", "--map"],
        ["demo"],
        ["plot", str(SPEC.parent)],
    ],
    ids=["simulate", "sweep", "zone", "demo", "plot"],
)
def test_jaxbearing_out_under_a_file_is_one_line_exit_2(command, blocked, capsys):
    assert jb_main([*command, "--out", str(blocked)]) == 2
    line = _err_line(capsys)
    assert "--out" in line and str(blocked) in line and "not a directory" in line


def test_optimise_out_under_a_file_is_one_line_exit_2(blocked, capsys):
    assert opt_main(["run", "--out", str(blocked)]) == 2
    line = _err_line(capsys)
    assert "--out" in line and str(blocked) in line


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root writes anywhere")
@pytest.mark.parametrize("command", [["simulate"], ["sweep", str(SPEC)], ["zone", "--map"]])
def test_out_without_write_permission_is_one_line_exit_2(command, tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o555)
    try:
        assert jb_main([*command, "--out", str(locked / "sub")]) == 2
        assert "cannot write there" in _err_line(capsys) or "cannot" in capsys.readouterr().err
    finally:
        locked.chmod(0o755)


@pytest.mark.parametrize(
    "main,command",
    [
        (jb_main, ["simulate"]),
        (jb_main, ["sweep", str(SPEC)]),
        (jb_main, ["zone", "--map"]),
        (opt_main, ["run"]),
    ],
    ids=["simulate", "sweep", "zone", "optimise"],
)
def test_out_refusing_writes_is_one_line_exit_2_even_as_root(main, command, tmp_path, monkeypatch, capsys):
    """A directory that refuses the write test (EACCES, as a read-only directory does for a user
    who is not root; injected here, since root writes anywhere): one line, exit 2, before any
    solve, and the directory the check created is removed again."""
    import builtins

    from jaxbearing.io import _files

    def refusing(path, *a, **k):
        if ".jaxbearing-write-test" in str(path):
            raise PermissionError(13, "Permission denied", str(path))
        return builtins.open(path, *a, **k)

    monkeypatch.setattr(_files, "open", refusing, raising=False)
    out = tmp_path / "ro" / "out"
    assert main([*command, "--out", str(out)]) == 2
    line = _err_line(capsys)
    assert "--out" in line and "cannot write there: Permission denied" in line
    assert not (tmp_path / "ro").exists()


def test_zone_map_out_naming_a_file_is_one_line(tmp_path, capsys):
    f = tmp_path / "zone.png"
    f.write_text("x")
    assert jb_main(["zone", "--map", "--out", str(f)]) == 2
    assert "exists and is not a directory" in _err_line(capsys)


def test_zone_maps_kept_in_the_fallback_directory(tmp_path, monkeypatch, capsys):
    """The maps are computed, then writing into --out fails (injected): they go to the
    fallback directory named in one line, exit status 4."""
    import jaxbearing.cli._zone as zone

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    maps = zone.zone_maps
    monkeypatch.setattr(zone, "zone_maps", lambda bearing, load: maps(bearing, load, 9))
    out = tmp_path / "maps"
    real = zone.draw_maps

    def failing(bearing, load, d, maps):
        if pathlib.Path(d) == out:
            raise OSError(28, "No space left on device (injected)")
        return real(bearing, load, d, maps)

    monkeypatch.setattr(zone, "draw_maps", failing)
    assert jb_main(["zone", "--map", "--out", str(out)]) == EXIT_RESULTS_ELSEWHERE
    line = _err_line(capsys)
    kept = pathlib.Path(line.rsplit("they are kept in ", 1)[1])
    assert (kept / "zone_height_map.png").exists() and (kept / "zone_clearance_map.png").exists()


def test_optimise_results_kept_in_the_fallback_directory(tmp_path, monkeypatch, capsys):
    from optimise._cli_output import _write_results

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    f = tmp_path / "f"
    f.write_text("x")
    used, code = _write_results(
        f / "out", {"status": "ok"}, lambda d: (d / "search_paths.png").write_bytes(b"p")
    )
    assert code == EXIT_RESULTS_ELSEWHERE and json.loads((used / "result.json").read_text()) == {
        "status": "ok"
    }
    assert str(used) in _err_line(capsys)


def test_config_check_warns_about_unit_slips(tmp_path, capsys):
    cfg = _toml(tmp_path, "[flange]\nlayback_angle_deg = 0.0279\n")
    assert jb_main(["config", "check", cfg]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "flange.layback_angle_deg = 0.0279 deg" in err[0] and "radians" in err[0]


def test_check_output_dir_leaves_nothing_behind(tmp_path):
    from jaxbearing.io import check_output_dir

    target = tmp_path / "a" / "b" / "c"
    check_output_dir(target)
    assert not (tmp_path / "a").exists()
    existing = tmp_path / "there"
    existing.mkdir()
    check_output_dir(existing)
    assert list(existing.iterdir()) == []


@pytest.mark.parametrize(
    "main,args",
    [
        (jb_main, ["simulate", "--settle", "soon"]),
        (jb_main, ["simulate", "--speed-rpm", "-5"]),
        (opt_main, ["run", "--estimator", "lss"]),
        (opt_main, ["run", "--seeds", "0"]),
    ],
)
def test_a_rejected_command_leaves_no_directory(main, args, tmp_path, capsys):
    out = tmp_path / "new" / "dir"
    assert main([*args, "--out", str(out)]) == 2
    assert not (tmp_path / "new").exists()


def test_write_or_fallback_keeps_the_results(tmp_path, monkeypatch):
    from jaxbearing.io import write_or_fallback

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    blocked = tmp_path / "f"
    blocked.write_text("x")
    used, reason = write_or_fallback(blocked / "out", lambda d: (d / "r.txt").write_text("kept"))
    assert reason and (used / "r.txt").read_text() == "kept"
    assert used.is_relative_to(tmp_path / "cache" / "jaxbearing" / "results")


def test_exit_codes_are_documented():
    assert {0, 1, 2, 3, 4, 130} <= set(EXIT_CODES)
    assert EXIT_INFEASIBLE == 3 and EXIT_RESULTS_ELSEWHERE == 4
    doc = (ROOT / "docs" / "reference" / "files-and-exit-codes.md").read_text()
    for code in EXIT_CODES:
        assert f"| {code} |" in doc


# -- item 3: plausibility, zone's exit status, the optimiser's start ------------------------------
def test_unit_slips_are_warned_in_one_line_each():
    from jaxbearing.io import plausibility_warnings, reference_config

    cfg = reference_config().replace(
        **{"flange.layback_angle_deg": 0.0279, "bearing.radial_clearance_um": 0.02}
    )
    lines = plausibility_warnings(cfg)
    assert len(lines) == 2 and all("\n" not in x for x in lines)
    assert "flange.layback_angle_deg = 0.0279 deg" in lines[1] and "radians" in lines[1]
    assert "bearing.radial_clearance_um = 0.02 um" in lines[0]
    assert plausibility_warnings(reference_config()) == []
    assert plausibility_warnings(reference_config().replace(**{"bearing.radial_clearance_um": 0.0})) == []


def test_range_error_blames_the_key_that_is_wrong():
    from jaxbearing import ConfigError
    from jaxbearing.io import reference_config

    with pytest.raises(ConfigError) as e:
        reference_config().replace(**{"bearing.pitch_diameter_mm": 0.085})
    assert e.value.field == "bearing.pitch_diameter_mm" and "radial_clearance_um" in str(e.value)
    with pytest.raises(ConfigError) as e:  # the key itself changed: it is blamed
        reference_config().replace(**{"bearing.radial_clearance_um": 2000.0})
    assert e.value.field == "bearing.radial_clearance_um"


def _toml(tmp_path, text: str) -> str:
    p = tmp_path / "c.toml"
    p.write_text(text)
    return str(p)


def test_zone_exits_3_outside_the_design_zone(tmp_path, capsys):
    cfg = _toml(tmp_path, "[flange]\naxial_clearance_mm = 0.001\nlayback_angle_deg = 0.0279\n")
    assert jb_main(["zone", "--config", cfg]) == EXIT_INFEASIBLE
    captured = capsys.readouterr()
    assert "NOT FEASIBLE" in captured.out
    err = captured.err.strip().splitlines()
    assert any("flange.layback_angle_deg = 0.0279 deg" in x and "radians" in x for x in err)
    assert any("clearance margin" in x and "Lambda_bf" in x for x in err)


def test_optimise_refuses_a_start_with_negative_actual_clearance(tmp_path, capsys):
    cfg = _toml(tmp_path, "[flange]\naxial_clearance_mm = 0.001\n")
    out = tmp_path / "out"
    assert opt_main(["run", "--config", cfg, "--out", str(out)]) == 2
    line = _err_line(capsys)
    assert "flange.axial_clearance_mm" in line and "Lambda_bf" in line and "negative" in line
    assert not out.exists()


# -- item 5: help that matches the code ----------------------------------------------------------
def _actions(parser, command):
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return [a for a in sub.choices[command]._actions if a.dest != "help"]


def _shown_default(action) -> str:
    text = " ".join((action.help or "").split())
    text = text.replace("%(default)s", str(action.default))
    if "%(default)g" in text:
        text = text.replace("%(default)g", f"{action.default:g}")
    m = re.search(r"\(default: (.*)\)$", text)
    assert m, f"{action.option_strings}: no '(default: ...)' in {text!r}"
    return m.group(1)


def test_optimise_run_help_shows_the_actual_defaults_and_values():
    import jaxbearing as jb
    from optimise._cli import (
        AGGREGATES,
        OBJECTIVES,
        build_parser,
        objective_of,
        problem_from_settings,
        steady_settings_from,
    )
    from optimise._settings import ESTIMATORS, SteadySettings

    actions = {a.option_strings[0]: a for a in _actions(build_parser(), "run")}
    shown = {k: _shown_default(a) for k, a in actions.items()}  # every option says its default
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    steady_problem, steady_opts = problem_from_settings(b, op, {})
    _, startup_opts = problem_from_settings(b, op, {"objective": "startup"})
    _, profile_opts = problem_from_settings(b, op, {"profile": True})
    st = steady_settings_from({})
    assert st == SteadySettings()
    bounds = steady_problem.bounds.engineering()

    def num(key):
        return float(shown[key].split(",")[0].split()[0])

    assert shown["--objective"] == "steady" == objective_of({})
    assert shown["--starts"] == (
        f"{steady_opts['num_starts']} steady, {profile_opts['num_starts']} with --profile, "
        f"{startup_opts['num_starts']} startup"
    )
    assert shown["--iterations"] == (
        f"{steady_opts['num_iterations']} steady, {profile_opts['num_iterations']} with --profile, "
        f"{startup_opts['num_iterations']} startup"
    )
    assert num("--learning-rate") == steady_opts["learning_rate"]
    assert num("--seeds") == st.seeds and num("--window-revs") == st.window_revs
    assert shown["--settle"] == st.settle and shown["--estimator"] == st.estimator
    assert num("--gradient-window-ms") == pytest.approx(st.gradient_window * 1e3)
    assert num("--corner-margin-mm") == pytest.approx(st.corner_margin * 1e3)
    assert num("--verify-seeds") == st.verify_seeds and num("--workers") == st.workers
    assert num("--rtol") == steady_problem.rtol == st.rtol and num("--atol") == steady_problem.atol
    assert num("--duration-ms") == pytest.approx(steady_problem.duration * 1e3)
    assert num("--flange-load-N") == steady_problem.flange_load
    assert num("--min-clearance-mm") == steady_problem.min_clearance * 1e3
    assert shown["--aggregate"] == steady_problem.aggregate
    for opt, key in (
        ("--end-radius-mm", "end_radius_mm"),
        ("--layback-deg", "layback_angle_deg"),
        ("--clearance-mm", "axial_clearance_mm"),
    ):
        lo, hi = (float(v) for v in shown[opt].split(","))
        assert (lo, hi) == pytest.approx(tuple(bounds[key]))
    assert shown["--out"] == actions["--out"].default
    # the values each option accepts are the values the code accepts
    assert actions["--estimator"].metavar == "{" + ",".join(ESTIMATORS) + "}"
    for e in ESTIMATORS:
        SteadySettings(estimator=e)
    assert actions["--objective"].metavar == "{" + ",".join(OBJECTIVES) + "}"
    assert all(objective_of({"objective": o}) == o for o in OBJECTIVES)
    assert tuple(actions["--aggregate"].choices) == AGGREGATES
    for a in AGGREGATES:
        assert problem_from_settings(b, op, {"aggregate": a})[0].aggregate == a


def test_optimise_top_level_help_describes_the_steady_default(capsys):
    with pytest.raises(SystemExit):
        opt_main(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "settled running (default" in text


def test_simulate_help_shows_the_actual_defaults_and_values():
    from jaxbearing.cli import build_parser
    from jaxbearing.cli._simulate import _OVERRIDES
    from jaxbearing.io import KEY_BY_PATH, format_value, reference_config

    actions = {a.option_strings[0]: a for a in _actions(build_parser(), "simulate")}
    shown = {k: _shown_default(a) for k, a in actions.items()}
    ref = reference_config()
    for opt, key in _OVERRIDES.values():
        value = format_value(ref[key]).strip('"')
        assert shown[opt].startswith(f"{key} of the configuration, {value}"), (opt, shown[opt])
    assert tuple(actions["--end"].choices) == KEY_BY_PATH["simulation.end"].choices
    assert actions["--solver"].metavar == "{" + ",".join(KEY_BY_PATH["simulation.solver"].choices) + "}"
    for opt in ("--window-revs", "--seeds", "--settle-tolerance", "--settle-cap-ms", "--start"):
        a = actions[opt]
        assert shown[opt].split(":")[0] == (
            f"{a.default:g}" if isinstance(a.default, (int, float)) else a.default
        )


# -- items 2 and 4 with a solve: fallback directory, self-describing summary.json ------------------
#: the reference bearing at full size with the default max_steps and 4000 saves: the program of
#: `jaxbearing simulate` that test_cmd_simulate, test_dynamics, test_misalignment_trend and two
#: notebooks run (conftest.PROGRAM_GROUPS); 1 ms from the quasi-static start runs in seconds, so
#: 11 slices would only compile another
NO_PROGRESS = "[simulation]\nprogress = false\n"
STATS_SKIPPED = {"wall_time_s", "compile_time_s"}


@pytest.fixture(scope="module")
def first_run(tmp_path_factory):
    """One simulate (arc end and 1 ms given as options)."""
    d = tmp_path_factory.mktemp("first")
    cfg = d / "small.toml"
    cfg.write_text(NO_PROGRESS)
    out = d / "out"
    code = jb_main(
        [
            "simulate",
            "--config",
            str(cfg),
            "--end",
            "arc",
            "--transient",
            "--duration-ms",
            "1",
            "--out",
            str(out),
        ]
    )
    return code, json.loads((out / "summary.json").read_text())


def _statistics(doc: dict) -> dict:
    units = doc["units"]
    return {k: doc[k] for k in units if k not in STATS_SKIPPED}


def test_summary_json_describes_itself(first_run):
    import jaxbearing

    code, doc = first_run
    assert code == 0
    assert doc["jaxbearing_version"] == jaxbearing.__version__
    assert doc["command"][:2] == ["jaxbearing", "simulate"] and doc["command"][-2] == "--out"
    assert doc["command"][doc["command"].index("--end") + 1] == "arc"
    assert doc["seeds"] == [0] and doc["ends"] == ["arc"]
    assert doc["config"]["simulation"]["end"] == "arc" and doc["config"]["simulation"]["duration_ms"] == 1.0
    assert doc["config"]["bearing"]["num_slices"] == jaxbearing.reference_bearing().num_slices
    assert doc["units"]["cage_speed_rpm"] == "rpm" and doc["units"]["flange_pv_Pa_m_s"] == "Pa m/s"
    assert doc["units"]["cage_slip"] == "1"


def test_recorded_configuration_reproduces_the_statistics(first_run, tmp_path):
    """summary.json's configuration fed back (only --transient, the running it records) gives
    the same statistics."""
    _, doc = first_run
    cfg = tmp_path / "recorded.toml"
    cfg.write_text(doc["config_toml"])
    out = tmp_path / "again"
    assert jb_main(["simulate", "--config", str(cfg), "--transient", "--out", str(out)]) == 0
    again = json.loads((out / "summary.json").read_text())
    assert again["config"] == doc["config"]
    assert _statistics(again) == _statistics(doc)
    assert math.isfinite(again["cage_speed_rpm"])


def test_write_failure_after_the_solve_keeps_the_results(first_run, tmp_path, monkeypatch, capsys):
    """The solve succeeds, then writing into --out fails (injected): the results go to the
    fallback directory named in one line on stderr, exit status 4."""
    import jaxbearing.cli._simulate as sim

    _, doc = first_run
    cfg = tmp_path / "recorded.toml"
    cfg.write_text(doc["config_toml"])
    out = tmp_path / "out"
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    real = sim.write_outputs

    def failing(d, *a, **k):
        if pathlib.Path(d) == out:
            raise PermissionError(13, "Permission denied (injected)", str(d / "summary.json"))
        return real(d, *a, **k)

    monkeypatch.setattr(sim, "write_outputs", failing)
    capsys.readouterr()
    assert (
        jb_main(["simulate", "--config", str(cfg), "--transient", "--out", str(out)])
        == EXIT_RESULTS_ELSEWHERE
    )
    line = _err_line(capsys)
    kept = pathlib.Path(line.rsplit("they are kept in ", 1)[1])
    assert "injected" in line and kept.is_relative_to(tmp_path / "cache")
    again = json.loads((kept / "summary.json").read_text())
    assert _statistics(again) == _statistics(doc)
    assert (kept / "histories_arc.npz").exists()


def test_sweep_batches_kept_in_the_fallback_directory(tmp_path, monkeypatch, capsys):
    """A batch is solved, then writing it into --out fails (injected): it and every later batch
    go to the fallback directory named in one line, exit status 4; copied back, they assemble."""
    import shutil

    from jaxbearing.sweep import _driver
    from jaxbearing.sweep._storage import read_batch

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    out = tmp_path / "sweep"
    real = _driver.write_batch

    def failing(d, spec, b, data):
        if pathlib.Path(d) == out:
            raise OSError(28, "No space left on device (injected)")
        return real(d, spec, b, data)

    monkeypatch.setattr(_driver, "write_batch", failing)
    args = ["sweep", str(SPEC), "--out", str(out), "--workers", "1", "--no-progress"]
    assert jb_main(args) == EXIT_RESULTS_ELSEWHERE
    err = capsys.readouterr().err.strip().splitlines()
    assert "injected" in err[-1] and "kept in" in err[-1]
    kept = pathlib.Path(err[-1].split("kept in ", 1)[1].split("/batches", 1)[0])
    from jaxbearing.sweep import load_sweep_spec

    spec = load_sweep_spec(SPEC)
    assert all(read_batch(kept, spec, b) is not None for b in range(spec.num_batches))
    monkeypatch.setattr(_driver, "write_batch", real)
    (out / "batches").mkdir(exist_ok=True)
    for f in (kept / "batches").glob("batch_*.npz"):
        shutil.copy(f, out / "batches" / f.name)
    assert jb_main(args) == 0  # nothing left to solve: assembled from the copied batches


def _parsers(parser, path=()):
    for a in parser._actions:
        if a.__class__.__name__ == "_SubParsersAction":
            for name, sp in a.choices.items():
                yield (*path, name), sp
                yield from _parsers(sp, (*path, name))


def test_every_command_and_option_has_a_description_and_a_default():
    from jaxbearing.cli import build_parser as jb_parser
    from optimise._cli import build_parser as opt_parser

    missing = []
    for top in (jb_parser(), opt_parser()):
        for path, sp in _parsers(top):
            if not sp.description:
                missing.append(f"{top.prog} {' '.join(path)}: no description")
            for a in sp._actions:
                if a.dest == "help" or not a.option_strings or a.__class__.__name__ == "_SubParsersAction":
                    continue
                if "(default" not in " ".join((a.help or "").split()):
                    missing.append(f"{top.prog} {' '.join(path)} {a.option_strings[0]}: no default shown")
    assert missing == []


def test_warnings_of_a_command_are_one_line(capsys):
    """A warning raised while a command runs (here a two-line one from a stand-in command) is one
    line on stderr naming the command, as an error is; outside the command the display is Python's."""
    import argparse
    import warnings

    from jaxbearing.cli import dispatch

    parser = argparse.ArgumentParser(prog="jaxbearing")
    sub = parser.add_subparsers(dest="command")
    p = sub.add_parser("demo")
    p.set_defaults(func=lambda args: warnings.warn("first line\nsecond line", UserWarning, stacklevel=1) or 0)
    before = warnings.showwarning
    assert dispatch(parser, ["demo"]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["jaxbearing demo: warning: first line"]
    assert warnings.showwarning is before
