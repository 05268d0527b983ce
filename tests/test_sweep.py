"""Parameter sweeps (issue 6): spec validation, failed cases, kill -9 and resume.

The sweep of tests/sweeps/small.toml (arc/corner x two speeds, 0.2 ms, 2 batches of 2) is run
once in this process (the reference); the kill/restart test runs the same command in
subprocesses and must reproduce it bit for bit. (Each subprocess traces the batch program and
loads it from JAX's persistent compilation cache, a few seconds.)
"""

from __future__ import annotations

import json
import os
import pathlib
import signal
import subprocess
import sys

import numpy as np
import pytest
from _figures import assert_png_drawn

from jaxbearing import UserInputError
from jaxbearing.cli import main as cli_main
from jaxbearing.sweep import (
    SweepSpecError,
    computed_batches,
    load_sweep_spec,
    loads_sweep_spec,
    run_sweep,
    variable_names,
)

SWEEPS = pathlib.Path(__file__).parent / "sweeps"
SMALL = SWEEPS / "small.toml"
REPO = pathlib.Path(__file__).parents[1]


def subprocess_env(**extra) -> dict:
    """Environment of a sweep subprocess: CPU only, one device unless `extra` sets XLA_FLAGS.

    The subprocess keeps this process's XLA flags (in `make test` those of conftest.py), with
    `extra`'s XLA_FLAGS added: JAX's persistent compilation cache keys its entries on the XLA
    flags, so a subprocess with other flags compiles again every program this process, or
    another test, has already compiled and stored (tens of seconds each)."""
    env = dict(os.environ)
    inherited = [f for f in env.get("XLA_FLAGS", "").split() if not f.startswith("--xla_force_host_platform")]
    env.update(
        JAX_PLATFORMS="cpu",
        JAX_ENABLE_X64="1",
        PYTHONPATH=str(REPO) + os.pathsep + env.get("PYTHONPATH", ""),
    )
    env.update(extra)
    # extra's first (XLA stops reading at the first token that is not a flag, should the
    # inherited flags hold one); the cache key sorts the flags, so the order is free
    env["XLA_FLAGS"] = " ".join(extra.get("XLA_FLAGS", "").split() + inherited)
    return env


def sweep_command(spec: pathlib.Path, out: pathlib.Path, *args: str) -> list[str]:
    return [
        sys.executable,
        "-m",
        "jaxbearing.cli",
        "sweep",
        str(spec),
        "--out",
        str(out),
        "--no-progress",
        *args,
    ]


def assert_same_results(a, b) -> None:
    """Bitwise-equal datasets (NaN equal to NaN), coordinates and variables alike."""
    assert set(a.data_vars) == set(b.data_vars)
    for name in list(a.data_vars) + list(a.coords):
        x, y = a[name].values, b[name].values
        if x.dtype.kind == "f":
            assert np.array_equal(x, y, equal_nan=True), name
        else:
            assert np.array_equal(x, y), name
    # the same everywhere but the command line that produced each (issue 38: provenance)
    a, b = a.copy(), b.copy()
    for ds in (a, b):
        ds.attrs.pop("command", None)
    assert a.identical(b)


@pytest.fixture
def reference(small_sweep):
    """The small sweep run uninterrupted, single device, in this process: (its DIR, its dataset),
    which no test changes (they copy the DIR); run once for this file and
    tests/test_sweep_distributed.py (`small_sweep`, tests/conftest.py)."""
    return small_sweep


# -- spec validation (no computing) --------------------------------------------------------------
BAD_SPECS = [
    ('"operating.sped_rpm" = [1e4]', "operating.sped_rpm", "did you mean operating.speed_rpm"),
    ('"roller.end_radius_m" = [0.08]', "roller.end_radius_m", "use roller.end_radius_mm"),
    ('"operating.speed_rad_s" = [2000.0]', "operating.speed_rad_s", "use operating.speed_rpm"),
    ('"roller.end_radius_mm" = ["80 mm"]', "roller.end_radius_mm", "units are part of the key"),
    ('"operating.speed_rpm" = []', "operating.speed_rpm", "empty axis"),
    ('"operating.speed_rpm" = {start = 1e4, stop = 2e4, num = 0}', "operating.speed_rpm", "empty axis"),
    ('"roller.end_radius_mm" = [80.0, 2.0]', "roller.end_radius_mm", "out of range"),
    ('"flange.layback_angle_deg" = {start = 1, stop = 12, num = 3}', "flange.layback_angle_deg", "(0, 10]"),
    (
        '"roller.central_length_mm" = [4.5, 7.5]',
        "roller.central_length_mm",
        "length_mm - 2 corner_radius_mm = 7.2",
    ),
    ('"operating.speed_rpm" = [-100.0]', "operating.speed_rpm", "out of range"),
    ('"bearing.num_rollers" = [20, 26]', "bearing.num_rollers", "changes array shapes"),
    ('"simulation.max_steps" = [10, 20]', "simulation.max_steps", "static"),
    ('"bearing.flange_lubrication" = ["dry", "mixed"]', "bearing.flange_lubrication", "static"),
    ('"bearing.type" = ["NU", "NUP"]', "bearing.type", "one sweep per type"),
    ('end = ["arc", "flat"]', "end", "not a roller end type"),
    ('"operating.speed_rpm" = [1e4, 1e4]', "operating.speed_rpm", "appears twice"),
]


@pytest.mark.parametrize("axes, axis, text", BAD_SPECS, ids=[b[1] + ":" + b[2] for b in BAD_SPECS])
def test_bad_spec_names_the_axis(axes, axis, text):
    with pytest.raises(SweepSpecError) as info:
        loads_sweep_spec(f"[axes]\n{axes}\n")
    assert info.value.axis == axis
    msg = str(info.value)
    assert msg.startswith(axis + ":") and text in msg and "\n" not in msg


def test_bad_spec_fields():
    with pytest.raises(SweepSpecError, match=r"^sweep.batchsize: .*did you mean sweep.batch_size"):
        loads_sweep_spec('[sweep]\nbatchsize = 3\n[axes]\n"operating.speed_rpm" = [1e4]\n')
    with pytest.raises(SweepSpecError, match=r"^axes: no axes"):
        loads_sweep_spec("[sweep]\nbatch_size = 3\n")
    with pytest.raises(SweepSpecError, match=r"^operating.radial_load_N: zipped axes must have"):
        loads_sweep_spec(
            '[sweep]\nmode = "zip"\n[axes]\n"operating.speed_rpm" = [1e4, 2e4]\n'
            '"operating.radial_load_N" = [1e3]\n'
        )
    with pytest.raises(SweepSpecError, match=r'^roller.end_radius_mm: case 1: end = "arc" needs'):
        loads_sweep_spec('[base.simulation]\nend = "arc"\n[axes]\n"roller.end_radius_mm" = [80.0, inf]\n')
    with pytest.raises(SweepSpecError, match=r"^base.roller.diameter_mm: "):
        loads_sweep_spec('[base.roller]\ndiameter_mm = -1.0\n[axes]\nend = ["arc"]\n')


def test_bad_spec_fails_before_computing(tmp_path, capsys, monkeypatch):
    """The CLI prints one line naming the axis, exits 2 and creates nothing."""
    spec = tmp_path / "bad.toml"
    spec.write_text('[axes]\n"operating.speed_rpm" = [1e4, 2e4]\n"roller.end_radius_mm" = [1.0]\n')
    out = tmp_path / "out"
    import jaxbearing.sweep as sweep

    started = []  # nothing is computed: neither the sweep nor jax.distributed starts (a count)
    monkeypatch.setattr(sweep, "run_sweep", lambda *a, **k: started.append("run_sweep"))
    monkeypatch.setattr(sweep, "initialize_distributed", lambda *a: started.append("distributed"))
    assert cli_main(["sweep", str(spec), "--out", str(out)]) == 2
    assert started == []
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("jaxbearing sweep: error: roller.end_radius_mm: ")
    assert "out of range" in err[-1]
    assert not out.exists()


def test_grid_and_zip_layout():
    """Zipped axes share one dimension; cases run in C order over the dimensions."""
    spec = load_sweep_spec(SWEEPS / "grid_zip.toml")
    assert spec.dims == ("end", "zip0", "end_radius_mm") and spec.shape == (2, 3, 2)
    assert spec.num_cases == 12 and spec.num_batches == 3
    speeds = np.linspace(10000, 30000, 3)
    loads = (500.0, 1000.0, 2000.0)
    for case in range(12):
        e, z, r = np.unravel_index(case, spec.shape)
        v = spec.case_values(case)
        assert v == {
            "end": ("arc", "corner")[e],
            "operating.speed_rpm": speeds[z],
            "operating.radial_load_N": loads[z],
            "roller.end_radius_mm": (60.0, 80.0)[r],
        }
    cfg, end = spec.case_config(11)
    assert end == "corner" and cfg["operating.radial_load_N"] == 2000.0
    assert cfg["simulation.duration_ms"] == 0.2
    # the reference's simulation.end = "both" adds the end axis when none is given
    assert loads_sweep_spec('[axes]\n"operating.speed_rpm" = [1e4]\n').dims == ("speed_rpm", "end")
    # the hash follows the content (and the batch size, which fixes the batch files)
    assert spec.hash == load_sweep_spec(SWEEPS / "grid_zip.toml").hash
    assert spec.hash != spec.with_batch_size(3).hash


# -- running -------------------------------------------------------------------------------------
def test_reference_dataset(reference):
    """Labelled results: axes as coordinates, summary statistics, zone margins, status."""
    out, ds = reference
    assert (out / "results.nc").exists() and dict(ds.sizes)["end"] == 2
    assert list(ds["end"].values) == ["arc", "corner"]
    assert list(ds["speed_rpm"].values) == [15000.0, 20000.0]
    assert ds["speed_rpm"].attrs["config_key"] == "operating.speed_rpm"
    for name in variable_names():
        assert ds[name].dims == ("end", "speed_rpm")
    assert "flange_pv_Pa_m_s_max" in ds and "zone_relief_margin_m" in ds
    assert (ds["status"].values == "ok").all() and (ds["result_code"].values == 0).all()
    # independent checks: kinematic cage speed omega_i (1 - D/d_m) / 2, and the design zone
    kin = ds["speed_rpm"].values * (1 - 7.5 / 85.0) / 2
    np.testing.assert_allclose(ds["kinematic_cage_speed_rpm"].values, np.stack([kin, kin]), rtol=1e-12)
    assert (np.abs(ds["cage_slip"].values) < 0.05).all()
    # arc end: h_c = D/2 - R_end sin(theta_f) (docs/model.md 5), corner: D/2 - R_ce - R_cor sin
    s = np.sin(np.radians(1.6))
    np.testing.assert_allclose(
        ds["zone_contact_height_m"].sel(end="arc").values, (3.75 - 80 * s) * 1e-3, rtol=1e-9
    )
    np.testing.assert_allclose(
        ds["zone_contact_height_m"].sel(end="corner").values, (3.75 - 3.35 - 0.4 * s) * 1e-3, rtol=1e-9
    )
    assert (ds["zone_feasible"].sel(end="arc").values == 1).all()
    # self-describing (issue 38): units of every variable and coordinate, what produced it
    import jaxbearing

    assert all("units" in ds[v].attrs for v in [*ds.data_vars, "speed_rpm", "end"])
    assert ds["flange_pv_Pa_m_s_max"].attrs["units"] == "Pa m/s" and ds["cage_slip"].attrs["units"] == "1"
    # friction power per flange and in total, flash temperature at the rib (docs/model.md 5.5)
    assert ds["flange_friction_power_W_total"].attrs["units"] == "W"
    assert ds["flange_flash_temperature_K_max"].attrs["units"] == "K"
    parts = sum(
        ds[f"flange_friction_power_W_{f}"]
        for f in ("inner_neg_x", "inner_pos_x", "outer_neg_x", "outer_pos_x")
    )
    np.testing.assert_allclose(parts.values, ds["flange_friction_power_W_total"].values, rtol=1e-12)
    assert ds.attrs["jaxbearing_version"] == jaxbearing.__version__
    assert json.loads(ds.attrs["seeds"]) == [0] and isinstance(json.loads(ds.attrs["command"]), list)
    assert json.loads(ds.attrs["config"])["roller"]["end_radius_mm"] == 80.0
    assert jaxbearing.loads_config(ds.attrs["config_toml"]) == load_sweep_spec(SMALL).base
    # one log entry per batch, each computed once
    assert sorted(computed_batches(out)) == [0, 1]
    # a later run of the same sweep computes nothing
    again = run_sweep(load_sweep_spec(SMALL), out, progress=False)
    assert sorted(computed_batches(out)) == [0, 1]
    assert_same_results(ds, again)


def test_two_worker_processes_give_the_same_results(tmp_path, reference):
    """Both cores (issue 12, item 4): the batches solved in two spawned workers, each batch file
    written as it finishes, assemble to the single-process dataset bit for bit."""
    _, ds = reference
    two = run_sweep(load_sweep_spec(SMALL), tmp_path, progress=False, workers=2)
    assert_same_results(ds, two)
    assert sorted(computed_batches(tmp_path)) == [0, 1]


@pytest.mark.parametrize("workers", [0, -1, 1.5])
def test_bad_worker_count_is_one_line(tmp_path, workers):
    with pytest.raises(UserInputError, match="workers"):
        run_sweep(load_sweep_spec(SMALL), tmp_path, progress=False, workers=workers)


def test_cli_bad_worker_count_is_the_only_line(tmp_path, capsys):
    """`jaxbearing sweep --workers 0`: one error line naming the option, nothing printed or
    created before it, exit status 2."""
    out = tmp_path / "out"
    assert cli_main(["sweep", str(SMALL), "--out", str(out), "--workers", "0"]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("jaxbearing sweep: error: workers = 0"), err
    assert not captured.out and not out.exists()


def test_failed_case_is_recorded(tmp_path, reference):
    """A case hitting max_steps is recorded with its status and NaNs; the sweep goes on."""
    ds = run_sweep(load_sweep_spec(SWEEPS / "failing.toml"), tmp_path, progress=False)
    status = list(ds["status"].values)
    assert status[0] == "ok"
    assert status[1].startswith("failed: the step limit max_steps was reached")
    assert ds["result_code"].values[1] != 0
    failed = ds.isel(duration_ms=1)
    assert np.isnan(failed["cage_speed_rpm"].values) and np.isnan(failed["smooth_peak_pv_Pa_m_s"])
    assert failed["num_steps"].values == 2000
    assert np.isfinite(ds.isel(duration_ms=0)["cage_speed_rpm"].values)
    # the successful case equals the same case of the reference sweep (arc, 20000 rpm)
    ref = reference[1].sel(end="arc", speed_rpm=20000.0)
    assert ds.isel(duration_ms=0)["cage_speed_rpm"].values == ref["cage_speed_rpm"].values


#: `jaxbearing sweep` in a process that kills itself with SIGKILL right after its first batch
#: file is written and logged: the kill lands at one known point of the work, not in a race
#: with it (a kill sent from outside when the file appears may arrive after the next batch)
_KILLED_AFTER_FIRST_BATCH = """
import os, signal, sys
import jaxbearing.sweep._driver as driver
log = driver.append_log
def append_then_die(out_dir, record):
    log(out_dir, record)
    if record.get("event") == "batch":
        os.kill(os.getpid(), signal.SIGKILL)
driver.append_log = append_then_die
from jaxbearing.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_kill_and_resume(tmp_path, reference):
    """SIGKILL after the first batch file is written (one worker: the batches run in order);
    the same command with --resume then computes only the missing batch and the dataset equals
    the uninterrupted run bit for bit."""
    out = tmp_path / "sweep"
    env = subprocess_env()
    cmd = sweep_command(SMALL, out, "--workers", "1")
    first = out / "batches" / "batch_00000.npz"
    killed = subprocess.run(
        [sys.executable, "-c", _KILLED_AFTER_FIRST_BATCH, *cmd[3:]],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert killed.returncode == -signal.SIGKILL, killed.stderr[-3000:]
    assert not (out / "results.nc").exists()
    assert computed_batches(out) == [0] and first.exists()
    stat = first.stat()
    content = first.read_bytes()

    rerun = subprocess.run(cmd + ["--resume"], env=env, capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stderr[-3000:]
    assert computed_batches(out) == [0, 1]  # only the missing batch computed
    assert first.stat().st_mtime_ns == stat.st_mtime_ns and first.read_bytes() == content
    from jaxbearing.sweep import open_results

    assert_same_results(open_results(out), reference[1])
    assert json.loads((out / "spec.json").read_text())["hash"] == reference[1].attrs["spec_hash"]


def test_no_resume_recomputes_every_batch(tmp_path, reference):
    """`--no-resume` over a finished sweep computes every batch again (same numbers); the
    default (resume) computes none."""
    import shutil

    out = tmp_path / "again"
    shutil.copytree(reference[0], out)
    before = computed_batches(out)
    args = ["sweep", str(SMALL), "--out", str(out), "--no-progress", "--workers", "1"]
    assert cli_main(args) == 0
    assert computed_batches(out) == before
    assert cli_main([*args, "--no-resume"]) == 0
    assert computed_batches(out) == before + [0, 1]
    from jaxbearing.sweep import open_results

    assert_same_results(open_results(out), reference[1])


def test_dry_run_lists_the_axes_and_computes_nothing(tmp_path, capsys):
    out = tmp_path / "dry"
    assert cli_main(["sweep", str(SMALL), "--out", str(out), "--dry-run", "--batch-size", "1"]) == 0
    captured = capsys.readouterr()
    assert "4 cases" in captured.err and "4 batches of 1" in captured.err
    assert 'START-UP TRANSIENTS (settle = "off"): 0.2 ms' in captured.err  # what every case computes
    assert "operating.speed_rpm [speed_rpm]: 15000.0, 20000.0" in captured.out
    assert not out.exists()


def test_wait_timeout_names_the_missing_batch(tmp_path, capsys, monkeypatch):
    """Process 0 of 2 (jax.distributed stood in for: this process computes batch 0, the other
    never runs) waits --wait-timeout-s for batch 1, then says which file is missing, exit 2."""
    import jaxbearing.sweep as sweep

    monkeypatch.setattr(sweep, "initialize_distributed", lambda *a: (0, 2))
    out = tmp_path / "half"
    code = cli_main(["sweep", str(SMALL), "--out", str(out), "--no-progress", "--wait-timeout-s", "0.2"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert "1 batch file(s)" in err[-1] and "still missing after 0.2 s" in err[-1]
    assert "batch_00001.npz" in err[-1]
    assert computed_batches(out) == [0]


def test_resume_refuses_another_sweep(reference):
    """A DIR holding another sweep is an error (before computing), naming --out."""
    out, _ = reference
    other = load_sweep_spec(SMALL).with_batch_size(4)
    with pytest.raises(SweepSpecError, match=r"^--out: .* holds another sweep"):
        run_sweep(other, out, progress=False)


def test_plot_draws_every_figure_from_assembled_batches(tmp_path, capsys):
    """Dataset assembly and `jaxbearing plot` on fabricated batch files (no solving): every
    figure is drawn when the axes are there, and the design zone of each case is filled in."""
    from jaxbearing.sweep import write_batch

    spec = load_sweep_spec(SWEEPS / "figures.toml")
    rng = np.random.default_rng(0)
    cases = np.arange(spec.num_cases)
    data = {name: rng.uniform(1.0, 2.0, spec.num_cases) for name in variable_names()}
    angle = rng.uniform(0, 2 * np.pi, (spec.num_cases, spec.max_positions))
    data.update(
        case_index=cases,
        status=np.asarray(["ok"] * spec.num_cases),
        result_code=np.zeros(spec.num_cases, np.int32),
        contact_position=2e-3 * np.stack([np.cos(angle), np.sin(angle)], axis=-1),
        contact_position_count=np.full(spec.num_cases, spec.max_positions, np.int32),
    )
    (tmp_path / "spec.json").write_text(json.dumps({"hash": spec.hash, "spec": spec.canonical()}))
    write_batch(tmp_path, spec, 0, data)
    assert cli_main(["plot", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert out.count("drew Figure") == 8 and "could not" not in out
    figures = sorted((tmp_path / "figures").glob("figure*.png"))
    assert len(figures) == 8
    for path in figures:
        assert_png_drawn(path, min_pixels=100_000)
    # --out: the same figures, written there instead
    elsewhere = tmp_path / "elsewhere"
    assert cli_main(["plot", str(tmp_path), "--out", str(elsewhere)]) == 0
    assert sorted(p.name for p in elsewhere.glob("figure*.png")) == [p.name for p in figures]
    from jaxbearing.sweep import open_results

    ds = open_results(tmp_path)
    assert ds["flange_pv_Pa_m_s_max"].dims == spec.dims
    np.testing.assert_array_equal(ds["flange_pv_Pa_m_s_max"].values.ravel(), data["flange_pv_Pa_m_s_max"])
    # design zone per case: arc contact height D/2 - R_end sin(theta_f) (docs/model.md 5)
    arc = ds.sel(end="arc", speed_rpm=10000.0, central_length_mm=4.5)
    r, t = np.meshgrid(
        arc["end_radius_mm"].values, np.radians(arc["layback_angle_deg"].values), indexing="ij"
    )
    np.testing.assert_allclose(arc["zone_contact_height_m"].values, (3.75 - r * np.sin(t)) * 1e-3, rtol=1e-9)


def test_plot_names_missing_axes(tmp_path, capsys):
    assert cli_main(["plot", str(tmp_path / "nope")]) == 2
    assert "is not a directory" in capsys.readouterr().err
    assert cli_main(["plot", str(tmp_path)]) == 2
    assert "not a sweep directory" in capsys.readouterr().err
