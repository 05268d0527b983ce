"""Hardening (issue 16): every entry point validates before tracing, every failure is loud and
parseable, a damaged or locked sweep directory never crashes a resume.

Each failure listed in the issue has a test here that failed before the fix. None of them
solves: `initial_state` (the first step of every solve) is replaced by a sentinel, so an input
that slipped through validation fails at once instead of compiling or hanging (rtol = nan used to
run for over 10 minutes). The one test that runs the real thing in a subprocess has a timeout.
"""

from __future__ import annotations

import json
import math
import os
import pathlib
import subprocess
import sys
import threading
import time

import equinox as eqx
import numpy as np
import pytest

import jaxbearing as jb
import jaxbearing.run._simulate as simulate_module
from jaxbearing.cli import main as cli_main
from jaxbearing.io import load_config, loads_config

REPO = pathlib.Path(__file__).parents[1]
SWEEPS = pathlib.Path(__file__).parent / "sweeps"
SHORT = 0.05e-3  # s: every solve argument below is otherwise valid


class ReachedTheSolver(AssertionError):
    """Validation let a bad input through to the solve."""


@pytest.fixture
def no_solve(monkeypatch):
    """Any solve fails at once (before compiling) instead of running."""

    def sentinel(*args, **kwargs):
        raise ReachedTheSolver("the input reached the solver: it was not validated")

    monkeypatch.setattr(simulate_module, "initial_state", sentinel)


@pytest.fixture(scope="module")
def reference():
    return jb.reference_bearing(), jb.reference_operating_point()


def strict_loads(text: str):
    """json.loads that rejects NaN / Infinity tokens (as strict parsers do)."""

    def bad(token):
        raise ValueError(f"non-standard JSON token {token}")

    return json.loads(text, parse_constant=bad)


def dead_pid() -> int:
    """The pid of a process that has ended."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


# -- 1. the solver arguments of simulate (the list) -------------------------------------
@pytest.mark.parametrize(
    "name,value",
    [
        ("rtol", math.nan),  # ran for over 10 minutes on 0.1 ms
        ("duration", 0.0),  # returned status 'ok' with NaN statistics
        ("duration", math.nan),  # returned status 'ok' with NaN statistics
        ("duration", -1e-4),  # an equinox/JAX runtime traceback
        ("max_steps", 0),  # diffrax "Must have at least one checkpoint"
        ("atol", -1.0),  # accepted
        ("rtol", 1.0),
        ("atol", math.inf),
        ("max_steps", 2.5),
        ("num_saves", 0),
        ("progress", "yes"),
    ],
)
def test_simulate_rejects_bad_solver_arguments(no_solve, reference, name, value):
    kwargs = {"duration": SHORT, name: value}
    with pytest.raises(jb.UserInputError, match=rf"^{name} = \S+: must be "):
        jb.simulate(*reference, **kwargs)


@pytest.mark.parametrize("entry", ["solve", "flange_functionals"])
@pytest.mark.parametrize(
    "name,value", [("duration", 0.0), ("rtol", math.nan), ("atol", -1.0), ("max_steps", 0)]
)
def test_solve_and_gradient_path_reject_bad_solver_arguments(no_solve, reference, entry, name, value):
    kwargs = {"duration": SHORT, name: value}
    duration = kwargs.pop("duration")
    with pytest.raises(jb.UserInputError, match=rf"^{name} = "):
        getattr(jb, entry)(*reference, duration, **kwargs)


def test_flange_functionals_rejects_a_bad_pytree(no_solve, reference):
    """A negative end radius returned (0, nan, nan) silently."""
    bearing, op = reference
    bad = eqx.tree_at(lambda b: b.roller.end_radius, bearing, -0.08)
    with pytest.raises(jb.ConfigError, match=r"^roller\.end_radius_mm: -80\.0 mm is out of range"):
        jb.flange_functionals(bad, op, SHORT)
    with pytest.raises(jb.ConfigError, match=r"^roller\.end_radius_mm"):
        jb.solve(bad, op, SHORT)


def test_design_metrics_checks_before_solving(no_solve, reference):
    bearing, op = reference
    design = jb.DesignVariables(end_radius=0.08, layback_angle=0.028, axial_clearance=0.15e-3)
    with pytest.raises(jb.UserInputError, match=r"^duration = 0\.0: must be > 0 s"):
        jb.design_metrics(bearing, op, design, duration=0.0)
    with pytest.raises(jb.UserInputError, match=r"^flange_load = -1\.0: must be > 0 N"):
        jb.design_metrics(bearing, op, design, duration=SHORT, flange_load=-1.0)
    bad_op = jb.OperatingPoint(inner_speed=np.nan, radial_load=1000.0, gravity=9.81)
    with pytest.raises(jb.ConfigError, match=r"^operating\.speed_rpm: nan rpm is not finite"):
        jb.design_metrics(bearing, bad_op, design, duration=SHORT)
    with pytest.raises(jb.UserInputError, match=r"^rtol = nan"):
        jb.design_metrics(bearing, op, design, duration=SHORT, rtol=math.nan)


def test_perturbation_functionals_and_adjoint_are_checked(no_solve, reference):
    with pytest.raises(jb.UserInputError, match=r"^perturbation\.axial = -1\.0: must be >= 0 m"):
        jb.simulate(*reference, duration=SHORT, perturbation=jb.Perturbation(axial=-1.0))
    with pytest.raises(jb.UserInputError, match=r"^functionals\.pv_exponent = nan"):
        jb.solve(*reference, SHORT, functionals=jb.Functionals(pv_exponent=math.nan))
    with pytest.raises(jb.UserInputError, match=r"^adjoint = 'forward': must be a diffrax adjoint"):
        jb.solve(*reference, SHORT, adjoint="forward")


def test_traced_values_are_skipped_static_ones_checked(reference):
    """Under jit the floats are tracers (no value to check); static arguments are checked."""
    import jax

    bearing, op = reference
    # traced: the partial check leaves out every key that reads a traced leaf
    jax.eval_shape(
        lambda d: jb.validate_bearing(
            eqx.tree_at(lambda b: b.roller.diameter, bearing, d), op, traced="skip"
        ),
        7.5e-3,
    )
    with pytest.raises(jb.UserInputError, match=r"^max_steps = 0"):
        jax.eval_shape(lambda d: jb.solve(bearing, op, d, max_steps=0), SHORT)


def test_solver_argument_table_is_extensible():
    """The steady-running options are in the one table already."""
    from jaxbearing.io import check_solver_arguments

    check_solver_arguments(window_revs=5.0, seeds=4)
    with pytest.raises(jb.UserInputError, match=r"^window_revs = 0\.0: must be > 0 cage revolutions"):
        check_solver_arguments(window_revs=0.0)
    with pytest.raises(jb.UserInputError, match=r"^seeds = 0: must be an integer >= 1"):
        check_solver_arguments(seeds=0)
    with pytest.raises(TypeError, match="no validation rule"):
        check_solver_arguments(settle_turns=3)


def test_quasi_static_uses_the_schema(reference):
    bearing, _ = reference
    with pytest.raises(jb.ConfigError, match=r"^operating\.speed_rpm: -100\.0 rpm is out of range"):
        jb.quasi_static(
            bearing, jb.OperatingPoint(inner_speed=jb.rpm_to_rad_s(-100.0), radial_load=1000.0, gravity=9.81)
        )


def test_nan_rtol_in_a_subprocess_fails_fast():
    """The real thing, no sentinel: rtol = nan is refused at once (it used to hang)."""
    code = (
        "import math, jaxbearing as jb\n"
        "jb.simulate(jb.reference_bearing(), jb.reference_operating_point(), "
        "duration=1e-4, rtol=math.nan)\n"
    )
    env = dict(os.environ, JAX_PLATFORMS="cpu", PYTHONPATH=str(REPO))
    proc = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120, cwd=REPO
    )
    assert proc.returncode == 1
    assert proc.stderr.strip().splitlines()[-1] == (
        "jaxbearing._errors.UserInputError: rtol = nan: must be in (0, 1) and finite (relative tolerance)"
    )


# -- 2. the optimise bounds use the bearing's roller ---------------------------------------------
def test_optimise_bounds_use_the_actual_roller():
    import optimise as opt

    cfg = jb.reference_config()
    op = cfg.operating_point()
    bounds = opt.bounds_from_engineering(end_radius_mm=[4.0, 120.0])  # > 3.75 of the reference
    opt.make_problem(cfg.bearing(), op, bounds=bounds)
    big = cfg.replace(**{"roller.diameter_mm": 9.0}).bearing()  # D/2 = 4.5 mm
    with pytest.raises(
        jb.UserInputError, match=r"^bounds\.end_radius_mm lower bound = 4\.0: must be > D/2 = 4\.5 mm"
    ):
        opt.make_problem(big, op, bounds=bounds)
    small = cfg.replace(**{"roller.diameter_mm": 6.0}).bearing()  # D/2 = 3 mm
    opt.make_problem(small, op, bounds=opt.bounds_from_engineering(end_radius_mm=[3.5, 120.0]))
    with pytest.raises(jb.UserInputError, match=r"^rtol = 2\.0: must be in \(0, 1\)"):
        opt.make_problem(small, op, rtol=2.0)


# -- 3. failures are loud and machine-readable ---------------------------------------------------
def test_strict_json_nulls_with_reasons(tmp_path):
    from jaxbearing.io import dumps_strict, write_json

    doc = {
        "status": "failed: x",
        "a": math.nan,
        "b": {"c": [1.0, np.inf]},
        "d": np.float64(2.0),
        "e": np.int32(3),
        "f": None,
    }
    text = dumps_strict(doc, reason="the run failed")
    out = strict_loads(text)
    assert out["a"] is None and out["b"]["c"] == [1.0, None] and out["d"] == 2.0 and out["e"] == 3
    assert out["null_reasons"] == {"a": "nan: the run failed", "b.c[1]": "inf: the run failed"}
    write_json(tmp_path / "r.json", doc)
    assert strict_loads((tmp_path / "r.json").read_text())["a"] is None
    assert not list(tmp_path.glob(".*tmp"))


def _summary(status: str, height: float) -> dict:
    stats = {"max": height, "mean": height, "median": height, "min": height}
    from jaxbearing.cli._simulate import _TABLE_ROWS

    block = {key: dict(stats) for key, *_ in _TABLE_ROWS}
    block.update(
        status=status,
        on_arc_fraction=None,
        flange_contact_events=3,
        cage_speed_rpm=1.0,
        kinematic_cage_speed_rpm=1.0,
        cage_slip=math.nan,
        num_steps=10,
        wall_time_s=1.0,
        compile_time_s=1.0,
    )
    return block


def test_table_headers_separate_and_failed_values_marked():
    from jaxbearing.cli import format_table

    text = format_table({"arc": _summary("ok", 1e-3), "corner": _summary("failed: step limit", -17.4e-3)})
    banner, head = text.splitlines()[:2]
    assert banner.startswith("START-UP TRANSIENT:")  # a transient's table says so first
    assert "meancorner" not in head and "maxarc" not in head
    for label in ("arc max", "arc mean", "arc median", "corner max", "corner mean", "corner median"):
        assert f" {label}" in head
    row = next(line for line in text.splitlines() if line.startswith("contact height"))
    assert row.split()[3:6] == ["1", "1", "1"] and row.split()[-1] == "-17.4!"
    assert "! [corner] the run failed" in text and "! [arc]" not in text


def test_failed_summary_is_strict_json_with_a_warning():
    from jaxbearing.cli._simulate import _strict_summary

    block = _strict_summary(_summary("failed: the step limit max_steps was reached", math.nan))
    out = strict_loads(json.dumps(block, allow_nan=False))
    assert out["contact_height_m"]["max"] is None
    assert out["null_reasons"]["contact_height_m.max"] == "nan: the run failed (see status)"
    assert "not reliable" in out["warning"]
    ok = _strict_summary(_summary("ok", 1.0))
    assert "warning" not in ok and ok["null_reasons"] == {"cage_slip": "nan: no value"}


def test_result_codes_through_public_api():
    import diffrax

    from jaxbearing.run import RESULT_NAMES, result_code

    assert int(result_code(diffrax.RESULTS.successful)) == 0
    assert RESULT_NAMES[int(result_code(diffrax.RESULTS.max_steps_reached))] == "max_steps_reached"
    assert "._value" not in pathlib.Path(simulate_module.__file__).read_text()


def test_progress_meter_says_where_a_failed_solve_stopped(capsys):
    """A small ODE (dy/dt = -y) with the meter: success reaches 100 % with a time estimate on
    the way; a step limit stops it early, and the meter says so instead of jumping to 100 %."""
    import diffrax
    import jax.numpy as jnp

    from jaxbearing.run import SolveProgress

    def run(max_steps):
        return diffrax.diffeqsolve(
            diffrax.ODETerm(lambda t, y, args: -y),
            diffrax.Tsit5(),
            0.0,
            10.0,
            0.01,
            jnp.ones(()),
            stepsize_controller=diffrax.PIDController(rtol=1e-10, atol=1e-10),
            max_steps=max_steps,
            throw=False,
            progress_meter=SolveProgress(),
        )

    ok = run(10_000)
    out = capsys.readouterr().out
    assert ok.result == diffrax.RESULTS.successful
    assert "100% of the simulated time" in out and "s left" in out and "stopped" not in out
    failed = run(20)
    out = capsys.readouterr().out
    assert failed.result == diffrax.RESULTS.max_steps_reached
    stopped = [line for line in out.splitlines() if "stopped at" in line]
    assert len(stopped) == 1 and "100%" not in out
    percent = float(stopped[0].split("stopped at ")[1].split("%")[0])
    assert 0 < percent < 100


# -- 4. sweeps survive damaged files and a second sweep ------------------------------------------
def _fake_batch(spec, batch: int) -> dict:
    from jaxbearing.sweep import variable_names

    cases = spec.batch_cases(batch)
    n = len(cases)
    data = {name: np.full(n, 1.0 + batch) for name in variable_names()}
    data.update(
        case_index=cases,
        status=np.asarray(["ok"] * n),
        result_code=np.zeros(n, np.int32),
        contact_position=np.zeros((n, spec.max_positions, 2)),
        contact_position_count=np.zeros(n, np.int32),
    )
    return data


@pytest.fixture
def fake_solves(monkeypatch):
    """`solve_batch` replaced by fabricated rows; returns the list of case lists it was given."""
    import jaxbearing.sweep._driver as driver

    calls = []

    def fake(spec, cases, devices=None):
        calls.append([int(c) for c in cases])
        return _fake_batch(spec, int(cases[0]) // spec.batch_size)

    monkeypatch.setattr(driver, "solve_batch", fake)
    return calls


def test_damaged_batch_is_moved_aside_and_recomputed(tmp_path, fake_solves, capsys):
    from jaxbearing.sweep import batch_path, load_sweep_spec, read_batch, run_sweep

    spec = load_sweep_spec(SWEEPS / "small.toml")
    run_sweep(spec, tmp_path, progress=False, assemble_results=False)
    assert fake_solves == [[0, 1], [2, 3]]
    raw = batch_path(tmp_path, 1).read_bytes()
    batch_path(tmp_path, 1).write_bytes(raw[: len(raw) // 2])  # truncated: zipfile.BadZipFile
    batch_path(tmp_path, 0).write_bytes(b"")  # empty: EOFError
    capsys.readouterr()
    run_sweep(spec, tmp_path, progress=False, assemble_results=False)
    err = capsys.readouterr().err
    assert fake_solves[2:] == [[0, 1], [2, 3]]
    assert "batch_00001.npz is damaged (BadZipFile" in err and "batch_00000.npz is damaged (EOFError" in err
    damaged = sorted(p.name for p in (tmp_path / "batches" / "damaged").iterdir())
    assert len(damaged) == 2 and damaged[1].startswith("batch_00001.npz.")
    assert all(read_batch(tmp_path, spec, b) is not None for b in (0, 1))
    log = [json.loads(line) for line in (tmp_path / "sweep.log").read_text().splitlines()]
    assert [r["batch"] for r in log if r["event"] == "damaged"] == [0, 1]


def test_read_batch_never_raises_on_damage(tmp_path):
    from jaxbearing.sweep import batch_path, load_sweep_spec, missing_batches, read_batch

    spec = load_sweep_spec(SWEEPS / "small.toml")
    path = batch_path(tmp_path, 0)
    path.parent.mkdir(parents=True)
    path.write_bytes(b"PK\x03\x04 not really a zip")
    assert read_batch(tmp_path, spec, 0) is None
    assert missing_batches(tmp_path, spec) == [0, 1]


def test_stale_temporary_files_are_removed(tmp_path, fake_solves):
    import socket

    from jaxbearing.sweep import load_sweep_spec, run_sweep

    spec = load_sweep_spec(SWEEPS / "small.toml")
    batches = tmp_path / "batches"
    batches.mkdir(parents=True)
    host = socket.gethostname().replace(".", "_")
    dead = dead_pid()
    stale = [
        batches / f".batch_00000.npz.tmp{dead}",  # the name older versions wrote
        batches / f".batch_00001.npz.{host}.{dead}.tmp",
        tmp_path / f".spec.json.{host}.{dead}.tmp",
    ]
    live = batches / f".batch_00001.npz.{host}.{os.getppid()}.tmp"  # a writer that still runs
    for p in (*stale, live):
        p.write_bytes(b"partial")
    run_sweep(spec, tmp_path, progress=False, assemble_results=False)
    assert not any(p.exists() for p in stale) and live.exists()


def test_second_sweep_into_a_locked_directory_exits_2(tmp_path, fake_solves, capsys):
    from jaxbearing.io import DirectoryInUse, acquire_lock
    from jaxbearing.sweep import load_sweep_spec, run_sweep

    spec_path = SWEEPS / "small.toml"
    spec = load_sweep_spec(spec_path)
    with acquire_lock(tmp_path, "sweep.0.lock", what="sweep"):
        with pytest.raises(
            DirectoryInUse, match=rf"^{tmp_path} is in use by another sweep \(pid {os.getpid()}"
        ):
            run_sweep(spec, tmp_path, progress=False, assemble_results=False)
        capsys.readouterr()
        assert cli_main(["sweep", str(spec_path), "--out", str(tmp_path), "--no-progress"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert err[-1].startswith(f"jaxbearing sweep: error: {tmp_path} is in use by another sweep")
        assert "--wait-for-lock" in err[-1]
    assert fake_solves == []
    run_sweep(spec, tmp_path, progress=False, assemble_results=False)  # released: runs
    assert fake_solves == [[0, 1], [2, 3]]


def test_wait_for_lock_option_waits_for_the_other_sweep(tmp_path, fake_solves, capsys, monkeypatch):
    """`jaxbearing sweep --wait-for-lock 600` on a locked directory says it waits, and runs once
    the holder lets go. The holder lets go in the waiting loop's first pause (a stand-in for
    the lock module's clock), so the command has waited by construction: no race with a timer."""
    import types

    import jaxbearing.io._lock as lock_module
    from jaxbearing.io import acquire_lock

    held = acquire_lock(tmp_path, "sweep.0.lock", what="sweep")
    pauses = []

    def pause(seconds):
        pauses.append(seconds)
        held.release()

    monkeypatch.setattr(
        lock_module,
        "time",
        types.SimpleNamespace(monotonic=time.monotonic, strftime=time.strftime, sleep=pause),
    )
    spec_path = SWEEPS / "small.toml"
    args = ["sweep", str(spec_path), "--out", str(tmp_path), "--no-progress", "--workers", "1"]
    assert cli_main([*args, "--wait-for-lock", "600"]) == 0
    err = capsys.readouterr().err
    assert f"{tmp_path} is in use by another sweep" in err and "waiting (up to 600 s)" in err
    assert len(pauses) == 1 and fake_solves == [[0, 1], [2, 3]]


def test_sweep_waits_for_the_lock_when_asked(tmp_path, fake_solves):
    from jaxbearing.io import acquire_lock
    from jaxbearing.sweep import load_sweep_spec, run_sweep

    spec = load_sweep_spec(SWEEPS / "small.toml")
    lock = acquire_lock(tmp_path, "sweep.0.lock", what="sweep")
    threading.Timer(0.5, lock.release).start()
    run_sweep(spec, tmp_path, progress=False, assemble_results=False, lock_wait_s=30.0)
    assert fake_solves == [[0, 1], [2, 3]]


def test_lock_left_by_a_killed_sweep_is_taken_over(tmp_path, fake_solves, capsys):
    from jaxbearing.sweep import load_sweep_spec, run_sweep

    spec = load_sweep_spec(SWEEPS / "small.toml")
    record = {"pid": dead_pid(), "host": "elsewhere", "started": "2025-01-01T00:00:00"}
    (tmp_path / "sweep.0.lock").write_text(json.dumps(record))  # no process holds it
    run_sweep(spec, tmp_path, progress=True, assemble_results=False)
    assert f"left locked by a run that ended (pid {record['pid']} on elsewhere)" in capsys.readouterr().err
    assert fake_solves == [[0, 1], [2, 3]]
    assert (tmp_path / "sweep.0.lock").read_text() == ""  # released


def test_run_sweep_checks_its_process_layout(tmp_path, fake_solves):
    from jaxbearing.sweep import load_sweep_spec, run_sweep

    spec = load_sweep_spec(SWEEPS / "small.toml")
    with pytest.raises(jb.UserInputError, match=r"^process_id = 2: must be an integer in \[0, 1\]"):
        run_sweep(spec, tmp_path, process_id=2, num_processes=2)
    with pytest.raises(jb.UserInputError, match=r"^num_processes = 0"):
        run_sweep(spec, tmp_path, num_processes=0)
    assert fake_solves == [] and not tmp_path.joinpath("spec.json").exists()


# -- 5. the command line -------------------------------------------------------------------------
FLAT_ARC = '[roller]\nend_radius_mm = inf\n[simulation]\nend = "arc"\n'


@pytest.mark.parametrize("text", [FLAT_ARC, "[roller]\nend_radius_mm = inf\n"])
def test_config_check_runs_the_checks_of_simulate(tmp_path, capsys, no_solve, text):
    cfg = tmp_path / "flat.toml"
    cfg.write_text(text)
    assert cli_main(["config", "check", str(cfg)]) == 2
    check_err = capsys.readouterr().err.strip()
    assert check_err.startswith(f"{cfg}: roller.end_radius_mm: inf (flat end) cannot be simulated")
    assert cli_main(["simulate", "--config", str(cfg)]) == 2
    sim_err = capsys.readouterr().err.strip().splitlines()
    assert sim_err == [f"jaxbearing simulate: error: {check_err}"]
    # the override that makes it runnable
    corner = tmp_path / "corner.toml"
    corner.write_text(
        text.replace('end = "arc"', 'end = "corner"')
        if "arc" in text
        else text + '[simulation]\nend = "corner"\n'
    )
    assert cli_main(["config", "check", str(corner)]) == 0


def test_simulate_errors_name_the_file_and_the_option(tmp_path, capsys, no_solve):
    cfg = tmp_path / "bad.toml"
    cfg.write_text("[roller]\ncorner_radius_mm = 5.0\n")
    assert cli_main(["simulate", "--config", str(cfg)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"jaxbearing simulate: error: {cfg}: roller.corner_radius_mm:")
    assert cli_main(["simulate", "--duration-ms", "-1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "jaxbearing simulate: error: --duration-ms: simulation.duration_ms: -1.0 ms is out "
        "of range: must be in (0, 10000] ms"
    ]


def test_simulate_out_naming_a_file_is_one_line(tmp_path, capsys, no_solve):
    target = tmp_path / "results.txt"
    target.write_text("keep me")
    assert cli_main(["simulate", "--out", str(target), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"jaxbearing simulate: error: --out {target}: exists and is not a directory; name a directory"
    ]
    assert target.read_text() == "keep me"


def test_byte_order_mark_is_accepted(tmp_path, capsys):
    cfg = tmp_path / "bom.toml"
    cfg.write_bytes("\ufeff[roller]\nend_radius_mm = 90.0\n".encode())
    assert load_config(cfg)["roller.end_radius_mm"] == 90.0
    assert loads_config("\ufeff[operating]\nspeed_rpm = 1000.0\n")["operating.speed_rpm"] == 1000.0
    assert cli_main(["config", "check", str(cfg)]) == 0
    utf16 = tmp_path / "utf16.toml"
    utf16.write_bytes("[roller]\nend_radius_mm = 90.0\n".encode("utf-16"))
    assert cli_main(["config", "check", str(utf16)]) == 2
    assert "UTF-16 byte-order mark: save it as UTF-8" in capsys.readouterr().err


def test_exit_codes_and_help_texts(capsys):
    from optimise._cli import build_parser

    with pytest.raises(SystemExit):
        cli_main(["--help"])
    out = capsys.readouterr().out
    assert "exit status:" in out and "130" in out and "bad input" in out
    with pytest.raises(SystemExit):
        build_parser().parse_args(["run", "--help"])
    out = capsys.readouterr().out
    assert "Search the roller-end/flange design" in out and "exit status:" in out
