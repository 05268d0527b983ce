"""The steady-running engine (`jaxbearing.run.settle_members`) and the settled sweep on it.

Reduced size (11 raceway slices, 2-revolution windows, tolerance 2e-3): a settled sweep of the
arc and corner ends with two seeds (one member after another, as on a CPU), the same members
vmapped (the accelerator path, here on the CPU), and the
independence of a member from its batch-mates.

The sweep and the vmapped members settle for a fixed 0.5 ms from the skid start (which lands on
the plateau, tests/test_skid.py) and are declared settled: what is tested here is the engine's
two paths and the sweep around them, not the settling verdict, whose success on real output is
tests/test_settle.py's (`test_auto_settle_succeeds_and_reports_intervals`). The verdict takes at
least four revolutions before the two measured: with it the sweep took 93 s, with the fixed
settle 63 s (warm, 2026-11-26)."""

import dataclasses
import json
import math

import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing.run import Member, SettleFixed, SteadySettings, settle_members, summarise_steady
from jaxbearing.run._initial import kinematic_start

SPEC = """
[sweep]
settle = 0.5
seeds = 2
window_revs = 2
settle_tolerance = 2e-3
batch_size = 1
max_positions = 50
[base.bearing]
num_slices = 11
[axes]
end = ["arc", "corner"]
"operating.speed_rpm" = [20000.0]
"""
OPTIONS = SteadySettings(window_revs=2, tolerance=2e-3)
#: the sweep's settling: a fixed 0.5 ms from the skid start, declared settled (module docstring)
FIXED_SETTLE = OPTIONS.replace(settle=SettleFixed(0.5))


@pytest.fixture(scope="module")
def settled_sweep(tmp_path_factory):
    from jaxbearing.sweep import loads_sweep_spec, run_sweep

    out = tmp_path_factory.mktemp("settled_sweep")
    spec = loads_sweep_spec(SPEC)
    ds = run_sweep(spec, out, progress=False, workers=1)  # in this process: no second cold compile
    return spec, ds, out


def _small():
    return dataclasses.replace(jb.reference_bearing(), num_slices=11), jb.reference_operating_point()


def test_settled_sweep_holds_every_statistic_with_its_interval(settled_sweep):
    """The sweep settles: every case is settled running, every statistic comes with a
    95 % interval that contains it, the dataset says what it describes, and the arc end never
    reaches its corner while the flat end's contact is all at the corner."""
    spec, ds, _ = settled_sweep
    assert (
        spec.settled and ds.attrs["running"] == "settled running" and json.loads(ds.attrs["seeds"]) == [0, 1]
    )
    arc, corner = (ds.sel(end=e).isel(speed_rpm=0) for e in ("arc", "corner"))
    for case in (arc, corner):
        assert str(case["status"].values) == "ok" and float(case["settled"]) == 1.0
        assert float(case["seeds"]) == 2 and float(case["window_ms"]) > 0
        assert 0 < float(case["settle_time_ms"]) <= spec.settle_cap_ms
        for name in ("cage_speed_rpm", "flange_pv_Pa_m_s_max", "flange_force_N_mean", "cage_slip"):
            low, value, high = (float(case[name + s]) for s in ("_ci95_low", "", "_ci95_high"))
            assert low <= value <= high and high > low, (name, low, value, high)
        assert int(case["contact_position_count"]) > 0
    assert float(arc["corner_contact_share_time"]) == 0.0
    assert float(corner["corner_contact_share_time"]) == 1.0
    assert ds["flange_pv_Pa_m_s_max_ci95_low"].attrs["units"] == "Pa m/s"
    # the arc end presses less on its flange than the flat end (the paper's headline), settled
    assert float(arc["flange_pressure_Pa_max"]) < float(corner["flange_pressure_Pa_max"])


def test_settled_sweep_figures_draw_error_bars(settled_sweep, tmp_path, monkeypatch):
    """`jaxbearing plot` of a settled sweep draws the intervals as error bars, with settled
    running in the title; a start-up transient's figures say so instead."""
    import matplotlib.axes

    from jaxbearing.sweep import plot_sweep
    from jaxbearing.sweep._plots import running_label

    _, ds, _ = settled_sweep
    bars = []
    real = matplotlib.axes.Axes.errorbar
    monkeypatch.setattr(
        matplotlib.axes.Axes, "errorbar", lambda self, *a, **k: bars.append(k) or real(self, *a, **k)
    )
    drawn, _ = plot_sweep(ds, tmp_path)
    assert [label.split(" (")[0] for label, _ in drawn] == ["Figure 9", "Figure 10", "Figure 11"]
    assert len(bars) == 3 * 2 * 2  # three figures, two ends, max and mean
    assert running_label(ds).startswith("settled running")
    transient = ds.copy()
    transient.attrs["running"] = "start-up transient"
    assert running_label(transient).startswith("START-UP TRANSIENT")


def test_vmapped_members_agree_with_the_sweep_within_their_intervals(settled_sweep):
    """The accelerator path (every member of a round in one vmapped program; here on the CPU)
    settles the same two seeds of the arc case as the sweep's one-at-a-time path did, and its
    statistics agree with the sweep's within their 95 % intervals (the runs are chaotic: the
    two paths differ by round-off, which grows, so agreement is statistical)."""
    _, ds, _ = settled_sweep
    bearing, op = _small()
    members = [Member(bearing, op, jb.Perturbation(seed=k)) for k in range(2)]
    engine = settle_members(members, FIXED_SETTLE.replace(strategy="vmap"))
    assert engine.strategy == "vmap" and engine.batch_times.rounds > 0
    assert all(r.settled and r.status == "ok" for r in engine.runs)
    result = jb.SteadyResult(
        runs=engine.runs,
        settings=FIXED_SETTLE,
        settle_mode="fixed",
        start="skid",
        wall_time_s=engine.wall_time_s,
        compile_time_s=engine.compile_time_s,
        bearing=bearing,
        operating=op,
    )
    block = summarise_steady(result)
    arc = ds.sel(end="arc").isel(speed_rpm=0)
    for group, red, name in (
        ("cage_speed_rpm", None, "cage_speed_rpm"),
        ("flange_pv_Pa_m_s", "max", "flange_pv_Pa_m_s_max"),
        ("flange_force_N", "mean", "flange_force_N_mean"),
    ):
        est = block[group][red] if red else block[group]
        half_vmap = 0.5 * (est["ci95_high"] - est["ci95_low"])
        half_sweep = 0.5 * float(arc[name + "_ci95_high"] - arc[name + "_ci95_low"])
        assert abs(est["value"] - float(arc[name])) <= half_vmap + half_sweep, (name, est, float(arc[name]))


def test_a_member_does_not_depend_on_its_batch_mates():
    """Seed 0 at 20,000 rpm in a batch with seed 1, and in a batch (of the same size, so the same
    program) with a member at another speed and in the other slot: its revolutions and window
    agree to round-off. (A short run: 2 revolutions measured from the kinematic start.)"""
    bearing, op = _small()
    other = dataclasses.replace(op, inner_speed=op.inner_speed * 0.75)
    options = OPTIONS.replace(settle="off", start="quasi-static", strategy="vmap")
    a = Member(bearing, op, jb.Perturbation(seed=0))
    first = settle_members([a, Member(bearing, op, jb.Perturbation(seed=1))], options).runs[0]
    second = settle_members([Member(bearing, other, jb.Perturbation(seed=2)), a], options).runs[1]
    assert first.status == second.status == "ok"
    np.testing.assert_allclose(first.revolution_speeds_rpm, second.revolution_speeds_rpm, rtol=1e-9)
    np.testing.assert_allclose(
        first.window["flange_force"], second.window["flange_force"], rtol=1e-6, atol=1e-6
    )
    assert first.num_steps == second.num_steps and math.isfinite(first.revolution_speeds_rpm[-1])


@pytest.mark.parametrize(
    "line, words",
    [
        ("seeds = 0", "sweep.seeds = 0.0: must be an integer >= 1"),
        ("window_revs = -1", "sweep.window_revs = -1.0: must be an integer >= 2"),
        ('settle = "soon"', 'sweep.settle: "soon" must be "auto", "off" or a settling time >= 0 ms'),
        ("settle = -4", "sweep.settle = -4.0: must be"),
        ("settle = true", "sweep.settle: true is not a valid value"),
        ('start = "warm"', "sweep.start = 'warm': must be one of 'skid', 'quasi-static'"),
        ("settle_tolerance = 2", "sweep.settle_tolerance = 2.0: must be in (0, 1)"),
        ("settle_cap_ms = 0", "sweep.settle_cap_ms = 0.0: must be > 0 ms"),
        ('seeds = "2"', "sweep.seeds"),
    ],
)
def test_bad_settled_sweep_options_are_one_line(line, words, tmp_path, capsys):
    from jaxbearing.cli import main

    spec = tmp_path / "bad.toml"
    spec.write_text(f'[sweep]\n{line}\n[axes]\n"operating.speed_rpm" = [10000]\n')
    assert main(["sweep", str(spec), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0], err
    assert not (tmp_path / "out").exists()


def test_engine_options_are_checked_in_one_line():
    bearing, op = _small()
    with pytest.raises(jb.UserInputError, match=r"^strategy = 'gpu': must be one of 'auto'"):
        settle_members([Member(bearing, op)], OPTIONS.replace(strategy="gpu"))


def test_a_settled_sweep_missing_a_batch_resumes_exactly(settled_sweep, tmp_path):
    """A settled sweep killed after its first batch (here: the second batch file removed from a
    finished sweep) computes only the missing batch when started again, and assembles exactly
    the dataset of the uninterrupted run (each member's program is deterministic)."""
    import shutil

    from jaxbearing.sweep import run_sweep
    from jaxbearing.sweep._storage import batch_path

    spec, ds, out = settled_sweep
    again = tmp_path / "again"
    shutil.copytree(out, again)
    batch_path(again, 1).unlink()
    (again / "results.nc").unlink()
    resumed = run_sweep(spec, again, progress=False, workers=1)
    log = (again / "sweep.log").read_text().splitlines()
    assert sum('"batch": 1' in line for line in log) == 2 and sum('"batch": 0' in line for line in log) == 1
    for name in ("cage_speed_rpm", "flange_pv_Pa_m_s_max_ci95_high", "settle_time_ms", "contact_position"):
        np.testing.assert_array_equal(resumed[name].values, ds[name].values)


def test_several_operating_points_in_one_engine_call_equal_their_single_runs():
    """`simulate_steady_points` (a design's envelope, e.g. the design search's speeds, as members
    of one engine call; here with one bearing per point, as a search iteration's starts) gives
    each point exactly its own `simulate_steady` (one member at a time: the same decisions, the
    same numbers). A short run: 2 revolutions measured from the
    kinematic start."""
    from jaxbearing.flange import DesignVariables, with_design
    from jaxbearing.run import simulate_steady, simulate_steady_points

    bearing, op = _small()
    other = dataclasses.replace(op, inner_speed=op.inner_speed * 0.75)
    d = DesignVariables.of(bearing)  # the second point with another design (one bearing per point)
    redesigned = with_design(bearing, d.end_radius * 1.1, d.layback_angle, d.axial_clearance)
    kw = dict(settle="off", window_revs=2, start="quasi-static")
    both = simulate_steady_points([bearing, redesigned], [op, other], **kw)
    alone = simulate_steady(redesigned, other, **kw)
    assert [r.operating is o for r, o in zip(both, (op, other))] == [True, True]
    assert [r.bearing is b for r, b in zip(both, (bearing, redesigned))] == [True, True]
    assert both[1].runs[0].revolution_speeds_rpm == alone.runs[0].revolution_speeds_rpm
    assert both[0].runs[0].revolution_speeds_rpm[-1] > both[1].runs[0].revolution_speeds_rpm[-1]
    with pytest.raises(
        jb.UserInputError, match=r"^initial_states: 1 given, expected one list per operating point"
    ):
        simulate_steady_points(bearing, [op, other], initial_states=[None], **kw)
    with pytest.raises(
        jb.UserInputError, match=r"^bearing: 3 given, expected one, or one per operating point \(2\)"
    ):
        simulate_steady_points([bearing] * 3, [op, other], **kw)


def test_continuing_seeds_share_their_case_time_constant(monkeypatch):
    """Members continuing from given states with the settling verdict (the design search's
    default) solve one static skid equilibrium per case, not one per seed: the verdict uses
    only its time constant, so both seeds' verdicts carry the same one. It is solved in the
    engine's one start step (`resolve_starts`), never inside a member's program. (A short run: from
    the quasi-static states, settling capped at 1 ms, a 2-revolution window.)"""
    import jaxbearing.run._starts as starts

    bearing, op = _small()
    seeds = [jb.Perturbation(seed=k) for k in range(2)]
    # the quasi-static states through `initial_state`'s compiled program (the quasi-static starts of
    # the batch-mates test built it; eagerly, each call compiles every operation again, 5-7 s)
    continuing = [Member(bearing, op, p, kinematic_start(bearing, op, p)) for p in seeds]
    fresh = Member(bearing, op, jb.Perturbation(seed=5))
    assert starts.continuing_cases([fresh, *continuing], OPTIONS) == {1: 1, 2: 1}
    assert starts.continuing_cases(continuing, OPTIONS.replace(settle="off")) == {}
    solved = []
    import jaxbearing.run._member as member_module

    def solved_in_a_member(*a):  # the starts are resolved before any member runs
        raise AssertionError("a member program solved its own static skid equilibrium")

    monkeypatch.setattr(member_module, "_static_skid_start", solved_in_a_member)
    real = starts._static_skid_start
    monkeypatch.setattr(starts, "_static_skid_start", lambda *a: solved.append(a[2].seed) or real(*a))
    capped = OPTIONS.replace(settle_cap_ms=1.0, strategy="sequential")
    runs = settle_members(continuing, capped).runs
    assert solved == [0]
    assert all(r.status == "ok" for r in runs)
    taus = [r.verdict.time_constant_s for r in runs]
    assert math.isfinite(taus[0]) and taus[0] > 0 and taus[0] == taus[1]
