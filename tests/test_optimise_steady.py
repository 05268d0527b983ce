"""`optimise run` on steady running (issue 13, items 1 and 3) at a reduced size: 11 slices,
2 seeds, a fixed 0.5 ms settle, two-revolution windows, 0.1 ms gradient windows.

Checked: the settings' one-line errors; a run killed after its first iteration resumes from
the checkpoint and ends with exactly the result of an uninterrupted run; the verification uses
seeds the search never saw and reports value and CI of mean PV, p95 PV and corner share. The
mechanics run on stand-ins for the settled ensemble (seconds instead of minutes); one
iteration's evaluation of two starts runs on real settled running (one engine call, one
gradient call), and the real ensemble is measured in tests/test_steady_design.py and by the
search in notebook 05."""

import dataclasses
import json
import math

import jax.numpy as jnp
import numpy as np
import pytest

import optimise._envelope as envelope
import optimise._evaluate as evaluation
import optimise._grid as grid_module
import optimise._settings as search_settings
import optimise._steady as steady
import optimise._verify as verify
from jaxbearing import UserInputError
from jaxbearing.run import CornerCount, CornerRisk, Estimate
from optimise._cli import main

SMALL = "[bearing]\nnum_slices = 11\n"
ARGS = [
    "--starts",
    "1",
    "--iterations",
    "1",
    "--seeds",
    "2",
    "--window-revs",
    "2",
    "--settle",
    "0.5",
    "--gradient-window-ms",
    "0.1",
    "--workers",
    "1",
    "--clearance-mm",
    "0.15,0.15",
]


@pytest.mark.parametrize(
    "kw,text",
    [
        (dict(seeds=0), "seeds = 0"),
        (dict(window_revs=1), "window_revs = 1.0: must be an integer >= 2"),
        (dict(gradient_window=-1.0), "gradient_window = -1"),
        (dict(estimator="lss"), "estimator = 'lss'"),
        (dict(verify_first_seed=2, seeds=4), "verify_first_seed = 2: must be >= seeds = 4"),
        (dict(corner_margin=float("nan")), "corner_margin = nan"),
    ],
)
def test_bad_steady_settings_are_one_line(kw, text):
    with pytest.raises(UserInputError, match=text.replace("(", r"\(")):
        search_settings.SteadySettings(**kw)


@pytest.mark.parametrize(
    "args,text",
    [
        (["--estimator", "lss"], "estimator = 'lss': must be one of 'frozen', 'window'"),
        (["--objective", "peak"], "objective = 'peak': must be 'steady' or 'startup'"),
        (["--seeds", "0"], "seeds = 0"),
        (["--settle", "soon"], "settle = 'soon'"),
        (["--gradient-window-ms", "-1"], "gradient_window_ms = -1.0: must be > 0"),
        (["--statistic", "max"], "statistic = 'max': must be one of 'mean', 'peak', 'tail'"),
        (["--statistic", "peak", "--estimator", "window"], "statistic = 'peak' needs estimator = 'frozen'"),
        (["--statistic", "tail", "--estimator", "window"], "statistic = 'tail' needs estimator = 'frozen'"),
        (["--clearance-step-mm", "-0.01"], "clearance_step_mm = -0.01: must be >= 0"),
        (["--clearance-step-mm", "soon"], "clearance_step_mm = 'soon': expected a float"),
        (["--skip-weight", "1.5"], "skip_weight = 1.5: must be in [0, 1)"),
        (
            ["--corner-constraint", "p99"],
            "corner_constraint = 'p99': must be one of 'risk', 'prediction', 'mean'",
        ),
        (["--choose", "cheapest"], "choose = 'cheapest': must be one of 'safest', 'best'"),
        (["--recheck-every", "0"], "recheck_every = 0: must be > 0"),
        (["--corner-risk-level", "2"], "corner_risk_level = 2.0: must be in (0, 1) per revolution"),
    ],
)
def test_cli_steady_option_errors(tmp_path, capsys, args, text):
    assert main(["run", "--out", str(tmp_path), *args]) == 2
    err = capsys.readouterr().err
    assert text in err and err.count("\n") == 1


@pytest.fixture(scope="module")
def config(tmp_path_factory):
    path = tmp_path_factory.mktemp("cfg") / "small.toml"
    path.write_text(SMALL)
    return str(path)


def _history(out):
    r = json.loads((out / "result.json").read_text())
    return r, np.asarray(r["history"]["objective_GPa_m_s"]), np.asarray(r["history"]["end_radius_mm"])


def _stand_in(problem, settings, u, states=None, *, gradient=True):
    """A cheap deterministic stand-in for the settled ensemble of `steady.evaluate` (the real one
    runs in tests/test_steady_design.py and notebook 05): J = 1 + |u - u*|^2 plus a term that
    depends on the continuation chain (the states count the evaluations along a start), so a
    resume that lost the continuation states would give other numbers."""
    u = np.asarray(u, dtype=float)
    target = np.array([0.7, 0.6, 0.5])
    steps = 0 if states is None else int(states[0][0])
    value = 1.0 + float(np.sum((u - target) ** 2)) + 0.01 * steps
    point = evaluation.PointRecord(  # every operating point alike: the envelope simulates them all
        value=value,
        ci=(value - 0.02, value + 0.02),
        gradient=2.0 * (u - target),
        gradient_stderr=np.full(3, 0.01),
        corner_margin=1e-4,
        measured_corner_margin=1e-4,
        measured_at=u,
        corner_contact_share=0.0,
        settled=True,
        simulated=True,
    )
    return evaluation.Evaluation(
        objective=value,
        objective_ci=(value - 0.02, value + 0.02),
        gradient=2.0 * (u - target) if gradient else np.full(3, np.nan),
        gradient_stderr=np.full(3, 0.01),
        per_point=[point] * problem.num_operating_points,
        static_margins=np.asarray(problem.margins(jnp.asarray(u))),
        dynamic_margin=1e-4,
        states=[[steps + 1]],
        wall_time_s=0.0,
        simulated_ms=10.0,
    )


def _stand_in_starts(problem, settings, us, chains, *, gradient=True, active=None, previous=None):
    """`_stand_in` for every start of an iteration (`steady.evaluate_starts`)."""
    return [_stand_in(problem, settings, u, c, gradient=gradient) for u, c in zip(us, chains)]


def test_friction_statistic_is_stored_and_printed_in_watts(tmp_path, config, monkeypatch, capsys):
    """`optimise run --statistic friction`: the objective is the friction power in W, printed
    with its unit and stored under keys that name it (`Statistic.key`: objective_W, ci95_W),
    never under the PV keys; on a stand-in for the settled ensemble."""
    monkeypatch.setattr(steady, "evaluate_starts", _stand_in_starts)
    out = tmp_path / "friction"
    assert (
        main(["run", "--config", config, "--statistic", "friction", *ARGS, "--no-verify", "--out", str(out)])
        == 0
    )
    text = capsys.readouterr().out
    assert "best feasible" in text and " W  " in text and "steady friction power" in text
    r = json.loads((out / "result.json").read_text())
    assert r["settings"]["statistic"] == "friction"
    assert "objective_W" in r and "objective_GPa_m_s" not in r
    assert (
        "objective_W" in r["history"] and "ci95_W" in r["history"] and "objective_GPa_m_s" not in r["history"]
    )
    assert np.isfinite(r["objective_W"]["value"])


def test_killed_run_resumes_with_the_same_result(tmp_path, config, monkeypatch, capsys):
    """The checkpoint mechanics of the steady search through the command line, on a stand-in
    for the settled ensemble: a run killed in its second evaluation exits 130 with a checkpoint
    and no result, resumes after iteration 0 with the continuation states, and ends with exactly
    the history and design of an uninterrupted run; other settings are refused."""
    monkeypatch.setattr(steady, "evaluate_starts", _stand_in_starts)
    args = [
        "--estimator",
        "frozen",
        "--statistic",
        "peak",
        "--corner-margin-mm",
        "0.04",
        "--clearance-step-mm",
        "0.01",
        "--skip-weight",
        "0",
        "--recheck-every",
        "2",
        "--corner-constraint",
        "mean",
        "--choose",
        "best",
        *ARGS,
    ]
    args[args.index("--iterations") + 1] = "2"
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    assert main(["run", "--config", config, *args, "--no-verify", "--quiet", "--out", str(whole)]) == 0
    assert "iter   0" not in capsys.readouterr().out  # --quiet: no per-iteration lines
    r1, j1, x1 = _history(whole)
    assert r1["objective_kind"] == "steady" and r1["status"] == "ok" and r1["resumed_from_iteration"] == -1
    # self-describing (issue 38): version, command line, configuration, settings, seeds, units
    assert r1["jaxbearing_version"] and r1["command"][:2] == ["optimise", "run"]
    assert r1["config"]["bearing"]["num_slices"] == 11 and "config_toml" in r1
    assert r1["seeds"]["search"] == [0, 1] and r1["seeds"]["verification"] == [1000, 1001, 1002, 1003]
    assert r1["optimiser_settings"]["seeds"] == 2 and "units" in r1
    assert r1["settings"]["statistic"] == "peak"
    assert (r1["settings"]["skip_weight"], r1["settings"]["recheck_every"]) == (0.0, 2)
    assert r1["settings"]["corner_constraint"] == "mean" and r1["settings"]["choose"] == "best"
    assert r1["settings"]["estimator"] == "frozen" and r1["settings"]["corner_margin"] == pytest.approx(
        0.04e-3
    )
    assert (r1["settings"]["seeds"], r1["settings"]["window_revs"], r1["settings"]["settle"]) == (2, 2, 0.5)
    assert r1["settings"]["gradient_window"] == pytest.approx(0.1e-3) and r1["settings"]["workers"] == 1
    assert r1["settings"]["clearance_step"] == pytest.approx(0.01e-3)
    assert r1["axial_clearance_effect"]["estimator_sees_it"] is True  # the CRN differences are on
    assert j1.shape == (3, 1) and np.all(np.isfinite(j1)) and np.all(j1 > 0)
    assert np.all(np.isfinite(np.asarray(r1["history"]["gradient_per_unit_box"])))
    lo, hi = r1["objective_GPa_m_s"]["ci95_low"], r1["objective_GPa_m_s"]["ci95_high"]
    assert lo <= r1["objective_GPa_m_s"]["value"] <= hi
    assert j1[1, 0] < j1[0, 0]  # the step went downhill

    # kill the second run in its second evaluation (after iteration 0 was checkpointed)
    calls = {"n": 0}
    evaluate = _stand_in_starts

    def dying(*a, **k):
        calls["n"] += 1
        if calls["n"] == 2:
            raise KeyboardInterrupt
        return evaluate(*a, **k)

    monkeypatch.setattr(steady, "evaluate_starts", dying)
    # the command line reports the interruption (exit code 130) and writes no result
    assert main(["run", "--config", config, *args, "--no-verify", "--out", str(killed)]) == 130
    assert (killed / "checkpoint.npz").exists() and not (killed / "result.json").exists()
    monkeypatch.setattr(steady, "evaluate_starts", evaluate)
    assert main(["run", "--config", config, *args, "--no-verify", "--out", str(killed)]) == 0
    text = capsys.readouterr().out
    assert "resumed after iteration 0" in text and "iter   1" in text  # without --quiet
    r2, j2, x2 = _history(killed)
    assert r2["resumed_from_iteration"] == 0
    np.testing.assert_array_equal(j2, j1)
    np.testing.assert_array_equal(x2, x1)
    assert r2["design"] == r1["design"]
    # other settings: the checkpoint is refused in one line
    assert main(["run", "--config", config, *args[:-2], "--no-verify", "--out", str(killed)]) == 2
    assert "checkpoint of a search with other settings" in capsys.readouterr().err
    # another choice among the tied designs picks from the finished history: nothing simulated
    monkeypatch.setattr(steady, "evaluate_starts", lambda *a, **k: pytest.fail("simulated again"))
    other = [*args]
    other[other.index("--choose") + 1] = "safest"
    assert main(["run", "--config", config, *other, "--no-verify", "--quiet", "--out", str(killed)]) == 0
    r3, j3, _ = _history(killed)
    assert r3["settings"]["choose"] == "safest" and r3["resumed_from_iteration"] == 2
    np.testing.assert_array_equal(j3, j1)


def _metrics_stand_in(calls):
    """A stand-in for `steady_design_metrics_points` that records (R_end, seeds, first_seed,
    window) of each point and "call" after each call; mean PV proportional to R_end, corner
    contacts below R_end 75 mm."""
    import types

    def one(design, seeds, first_seed, window_revs):
        calls.append((float(design.end_radius), seeds, first_seed, window_revs))
        pv = 1e9 * float(design.end_radius) / 0.08  # lower for a smaller end radius here

        def est(v, hw):
            return Estimate(v, v - hw, v + hw, seeds)

        share = 0.01 if design.end_radius < 0.075 else 0.0
        nothing = Estimate(math.nan, math.nan, math.nan, 0)
        revs = 4 * seeds
        counted = (
            CornerCount(revs, 0, 0.17, seeds, 0, 0.5)
            if share == 0
            else CornerCount(revs, revs, 1.0, seeds, seeds, 1.0)
        )
        return types.SimpleNamespace(
            mean_pv=est(pv, 0.05e9),
            p95_pv=est(2 * pv, 0.1e9),
            objective=est(pv, 0.05e9),
            corner_contact_share=est(share, 0.0),
            corner_margin=est(1e-4, 1e-5),
            corner_margin_bound=0.5e-4,
            simulated_ms=0.0,
            statistics=types.SimpleNamespace(
                flange_pv_Pa_m_s=types.SimpleNamespace(max=nothing),
                flange_pv_contact_time_Pa_m_s=types.SimpleNamespace(tail95=nothing),
                flange_friction_power_W=types.SimpleNamespace(total=nothing),
                flange_flash_temperature_K=types.SimpleNamespace(max=nothing),
                film_parameter=types.SimpleNamespace(p05=nothing),
                corner_contact_bound=counted,
                corner_risk=None,
            ),
            settled=True,
            seeds=list(range(first_seed, first_seed + seeds)),
        )

    def points(bearing, ops, designs, settings, *, first_seed=0, **kw):
        out = [one(d, settings.seeds, first_seed, settings.window_revs) for d in designs]
        calls.append("call")
        return out

    return points


def test_verify_seeds_option_reaches_the_verification(tmp_path, config, monkeypatch, capsys):
    """`optimise run --verify-seeds 3`: the verification re-measures the reference and the found
    design with 3 seeds from 1000 on (stand-ins for the search's ensemble and for
    `steady_design_metrics_points`; the real ones are in tests/test_steady_design.py)."""
    monkeypatch.setattr(steady, "evaluate_starts", _stand_in_starts)
    calls = []
    monkeypatch.setattr(evaluation, "steady_design_metrics_points", _metrics_stand_in(calls))
    out = tmp_path / "verified"
    assert main(["run", "--config", config, *ARGS, "--verify-seeds", "3", "--quiet", "--out", str(out)]) == 0
    r = json.loads((out / "result.json").read_text())
    assert r["verification"]["seeds"] == [1000, 1001, 1002]
    assert [c[1:] for c in calls[:2]] == [(3, 1000, 4), (3, 1000, 4)]  # reference, then the optimum
    assert calls[2:] == ["call"]  # both designs in one engine call
    # at two speeds: one line per design and operating point
    out = tmp_path / "two_speeds"
    args = [*ARGS, "--speeds-rpm", "10000,30000", "--verify-seeds", "3", "--out", str(out)]
    assert main(["run", "--config", config, *args]) == 0
    text = capsys.readouterr().out
    for where in ("at 10000 rpm", "at 30000 rpm"):
        assert (
            text.count(f"verification reference {where}") == text.count(f"verification optimum {where}") == 1
        )
    assert "disjoint 95 % CIs at every operating point: False" in text


def test_verification_uses_unseen_seeds(config, monkeypatch):
    """`verification` re-measures both designs with the seeds from verify_first_seed on (a
    stand-in for `steady_design_metrics_points` records them, both designs in one call; the real one is tested in
    tests/test_steady_design.py) and reports value and CI of mean PV, p95 PV and corner share,
    whether the mean-PV intervals are disjoint, and corner contacts of the found design."""

    import jaxbearing as jb
    from optimise import make_problem

    calls = []
    metrics = _metrics_stand_in(calls)

    monkeypatch.setattr(evaluation, "steady_design_metrics_points", metrics)
    cfg = jb.load_config(config)
    problem = make_problem(cfg.bearing(), cfg.operating_point())
    settings = search_settings.SteadySettings(
        seeds=2, window_revs=2, workers=1, verify_seeds=3, verify_first_seed=7, verify_window_revs=4
    )
    x = np.array([0.08, 1.6 * math.pi / 180, 0.15e-3])
    v = verify.verification(problem, settings, x, x)
    assert v.seeds == [7, 8, 9]
    assert calls == [(0.08, 3, 7, 4), (0.08, 3, 7, 4), "call"]
    for (point,) in (v.reference, v.optimum):
        assert point.seeds == [7, 8, 9]
        for est in (point.mean_pv, point.p95_pv, point.corner_contact_share):
            assert est.ci95_low <= est.value <= est.ci95_high
    # result.json's rows: the keys in SI, the engineering-unit keys in GPa m/s, the same
    # estimates
    js = json.loads(json.dumps(v.as_json(), allow_nan=False))
    assert js["seeds"] == [7, 8, 9]
    for name in ("reference", "optimum"):
        row = js[name]
        for key in ("mean_pv", "p95_pv"):
            assert row[key]["unit"] == "Pa m/s"
            for k in ("value", "ci95_low", "ci95_high"):
                assert row[key][k] == pytest.approx(row[f"{key}_GPa_m_s"][k] * 1e9, rel=1e-12)
        assert row["peak_pv_GPa_m_s"]["value"] is None  # nothing measured: None, not NaN
    # the same design and seeds: the same numbers, so the CIs overlap
    assert v.mean_pv_lower_disjoint is False and js["mean_pv_lower_disjoint"] is False
    assert v.optimum_corner_contacts is False
    # a design 12.5 % lower, beyond the intervals, with corner contact
    v = verify.verification(problem, settings, np.array([0.07, *x[1:]]), x)
    assert v.optimum[0].mean_pv.value == pytest.approx(0.875e9)
    assert v.mean_pv_lower_disjoint is True and v.optimum_corner_contacts is True
    js = v.as_json()
    assert js["optimum"]["mean_pv_GPa_m_s"]["value"] == pytest.approx(0.875)
    assert js["reference_corner_contact_per_revolution_upper95"] == 0.17
    assert js["optimum_corner_contact_per_revolution_upper95"] == 1.0


def test_grid_picks_the_best_point_inside_every_margin_and_resumes(tmp_path, config, monkeypatch):
    """`steady_grid` on the stand-in ensemble: only statically feasible points are evaluated,
    each continuing from the previous one (serpentine order), the best point is the lowest
    objective whose dynamic margin is positive too, and a rerun takes every point from
    DIR/grid_checkpoint.npz without evaluating again."""
    import jaxbearing as jb
    from optimise import make_problem

    problem = make_problem(jb.load_config(config).bearing(), jb.load_config(config).operating_point())
    seen = []

    def evaluate(problem, settings, u, states=None, *, gradient=True):
        assert gradient is False
        seen.append((np.asarray(u).copy(), states))
        ev = _stand_in(problem, settings, u, states, gradient=False)
        ev.dynamic_margin = 1e-4 if u[0] < 0.6 else -1e-4  # large end radii reach the corner
        return ev

    monkeypatch.setattr(grid_module, "evaluate", evaluate)
    settings = search_settings.SteadySettings(seeds=2, workers=1)
    grid = grid_module.steady_grid(problem, settings, 4, 3, 0.15e-3, directory=tmp_path)
    feasible = np.all(grid["static_margins"] > 0, axis=-1)
    assert len(seen) == grid["num_evaluations"] == feasible.sum() > 0
    assert seen[0][1] is None and all(s is not None for _, s in seen[1:])  # continuation
    ok = feasible & (grid["dynamic_margin"] > 0)
    assert grid["best_objective"] == pytest.approx(np.min(grid["objective"][ok]))
    assert np.all(np.isnan(grid["objective"][~feasible]))
    seen.clear()
    again = grid_module.steady_grid(problem, settings, 4, 3, 0.15e-3, directory=tmp_path)
    assert seen == [] and again["best_objective"] == grid["best_objective"]


def _engine_stand_in(seen, samples=False):
    """A stand-in for the steady-running engine (`steady_design_metrics_points`): per seed
    J = 1e9 (1 + 2000 Delta_bf / m + R_end / m) + 1e8 seed, so every design gets its own value
    and a paired difference in Delta_bf cancels the seed term; `seen` records each call's
    clearances and initial states. The real engine's members, each exactly its own single run,
    are tests/test_engine.py's (`test_several_operating_points_in_one_engine_call_equal_their_
    single_runs`); the search on real output is notebook 05's (tests/test_notebooks.py). With
    `samples`, each design has one stand-in sample state for the gradient estimator."""
    import types

    def engine(bearing, ops, designs, settings, *, initial_states, **kw):
        seeds = settings.seeds
        seen.append(([float(d.axial_clearance) for d in designs], initial_states))
        out = []
        for d in designs:
            x = 1 + 2000 * float(d.axial_clearance) + float(d.end_radius)
            per_seed = [1e9 * x + 1e8 * k for k in range(seeds)]
            est = Estimate(float(np.mean(per_seed)), 0.0, 1e10, seeds)
            out.append(
                types.SimpleNamespace(
                    objective=est,
                    objective_per_seed=per_seed,
                    corner_margin=est,
                    corner_margin_bound=1e-4,
                    corner_contact_share=est,
                    mean_pv=est,
                    statistics=None,
                    settled=True,
                    seeds=list(range(seeds)),
                    simulated_ms=3.0 * seeds,
                    final_states=[("state", float(d.axial_clearance))] * seeds,
                    sample_states=[("sample", float(d.end_radius))] if samples else [],
                    contact_radius_maxima=[],  # no revolutions: the risk margin falls back
                    limited_circle_radius_m=3.36e-3,
                )
            )
        return out

    return engine


def _frozen_stand_in(calls=None):
    """A stand-in for `frozen_load_statistics`: dJ/dx = (3e9, -4e9, 0) per case and statistic
    (the estimator cannot see Delta_bf); `calls` records each call's cases."""
    from jaxbearing.design import SteadyGradient

    def frozen(cases, statistics=("mean",), **kw):
        if calls is not None:
            calls.append(cases)
        g = SteadyGradient(1e9, np.array([3e9, -4e9, 0.0]), np.full(3, 1e7), 1e6, 1e-4, 4, None, None, None)
        return [dict.fromkeys(statistics, g) for _ in cases]

    return frozen


def test_an_iteration_evaluates_every_start_in_one_engine_call(monkeypatch):
    """`evaluate_starts` with two starts (stand-ins for the engine and the estimator,
    `_engine_stand_in`): every start's seeds are members of one call of the steady-running
    engine and every start's gradient trajectories of one `frozen_load_statistics` call, each
    from its own start's settled states, and each start gets its own design's objective (its
    interval around it), gradient, static margins and continuation states."""
    import jaxbearing as jb
    from optimise import make_problem

    seen, cases = [], []
    monkeypatch.setattr(evaluation, "steady_design_metrics_points", _engine_stand_in(seen, samples=True))
    monkeypatch.setattr(evaluation, "frozen_load_statistics", _frozen_stand_in(cases))
    problem = make_problem(jb.reference_bearing(), jb.reference_operating_point())
    settings = search_settings.SteadySettings(
        seeds=2, window_revs=2, settle=0.005, gradient_window=0.1e-3, workers=1
    )
    us = [np.array([0.5, 0.5, 0.25]), np.array([0.8, 0.3, 0.25])]
    evaluations = evaluation.evaluate_starts(problem, settings, us, [None, None])
    assert len(seen) == 1 and len(seen[0][0]) == 2 and len(cases) == 1 and len(cases[0]) == 2
    width = np.asarray(problem.bounds.upper - problem.bounds.lower)
    for u, ev, case in zip(us, evaluations, cases[0]):
        d = problem.design(jnp.asarray(u))
        assert case[2] == d and case[3] == [("sample", float(d.end_radius))]  # its own states
        expected = 1 + 2000 * float(d.axial_clearance) + float(d.end_radius) + 0.05  # GPa m/s
        assert ev.objective == pytest.approx(expected, rel=1e-12)
        lo, hi = ev.objective_ci
        assert lo <= ev.objective <= hi
        np.testing.assert_allclose(ev.gradient[:2], np.array([3e9, -4e9])[:2] * width[:2] / 1e9, rtol=1e-9)
        np.testing.assert_array_equal(ev.static_margins, np.asarray(problem.margins(jnp.asarray(u))))
        assert len(ev.states) == 1 and len(ev.states[0]) == 2  # one operating point, two seeds
    assert evaluations[0].objective != evaluations[1].objective


def test_clearance_gradient_is_a_paired_crn_difference_in_the_same_engine_call(monkeypatch):
    """`clearance_step` h: every start's design also runs at Delta_bf +- h, with the same seeds
    from the same continuation states, as members of the same engine call, and the Delta_bf
    component of the gradient is the mean over seeds of (J+ - J-) / 2h with its paired standard
    error; the frozen-load estimate keeps the other two (stand-ins for the engine and the
    estimator, `_engine_stand_in` and `_frozen_stand_in`: the seed term cancels)."""
    import jaxbearing as jb
    from optimise import make_problem

    seen = []
    monkeypatch.setattr(evaluation, "steady_design_metrics_points", _engine_stand_in(seen))
    monkeypatch.setattr(evaluation, "frozen_load_statistics", _frozen_stand_in())
    problem = make_problem(jb.reference_bearing(), jb.reference_operating_point())
    h = 0.01e-3
    settings = search_settings.SteadySettings(seeds=3, workers=1, clearance_step=h)
    u = np.array([0.5, 0.5, 0.25])
    chain = [["a", "b", "c"]]
    (ev,) = evaluation.evaluate_starts(problem, settings, [u], [chain])
    ((clearances, initial),) = seen
    base = float(problem.design(jnp.asarray(u)).axial_clearance)
    np.testing.assert_allclose(clearances, [base, base + h, base - h], rtol=1e-12)
    assert initial == [chain[0]] * 3  # the same states for the base and both shifted designs
    width = np.asarray(problem.bounds.upper - problem.bounds.lower)
    np.testing.assert_allclose(ev.gradient, np.array([3e9, -4e9, 2e12]) * width / 1e9, rtol=1e-6)
    assert ev.gradient_stderr[2] == pytest.approx(0.0, abs=1e-6 * ev.gradient[2])
    assert ev.simulated_ms == pytest.approx(3 * 3 * (1.0 + 2.0))
    # off without a gradient (and by default): one design per start
    seen.clear()
    evaluation.evaluate_starts(problem, settings, [u], [chain], gradient=False)
    assert len(seen[0][0]) == 1
    # with a friction limit the friction power's frozen-load gradient, from the same call,
    # is kept beside the objective's; the clearance difference is the objective's only
    seen.clear()
    limited = dataclasses.replace(settings, max_friction_power=30.0)
    (ev,) = evaluation.evaluate_starts(problem, limited, [u], [chain])
    np.testing.assert_allclose(ev.gradient, np.array([3e9, -4e9, 2e12]) * width / 1e9, rtol=1e-6)
    np.testing.assert_allclose(ev.per_point[0].friction_gradient, np.array([3e9, -4e9, 0.0]) * width)
    with pytest.raises(UserInputError, match=r"^clearance_step = -1"):
        search_settings.SteadySettings(clearance_step=-1.0)
    with pytest.raises(UserInputError, match=r"^clearance_step = 'soon': must be 'auto'"):
        search_settings.SteadySettings(clearance_step="soon")


def test_clearance_signal_is_the_paired_difference_where_significant():
    """The search's Delta_bf component: the paired difference where |d| exceeds the two-sided
    5 % Student-t bound of its standard error, else 0 (Adam would take a full step on noise);
    the standard error is kept either way."""
    h = 1e-5
    minus = np.array([1.0, 2.0, 3.0, 4.0])
    clear = minus + 2 * h * np.array([1.0, 1.1, 0.9, 1.05])  # d about 1, SE 0.04
    d, se = evaluation.clearance_signal(clear, minus, h)
    assert d == pytest.approx(1.0125) and se == pytest.approx(np.std([1, 1.1, 0.9, 1.05], ddof=1) / 2)
    noisy = minus + 2 * h * np.array([1.0, -1.2, 0.8, -0.4])  # d 0.05, SE 0.5
    d, se = evaluation.clearance_signal(noisy, minus, h)
    assert d == 0.0 and se > 0.4
    # at the bound: t_{0.975, 3} = 3.182; d = 3.0 SE is not significant, 3.3 SE is
    for z, expected in ((3.0, 0.0), (3.3, None)):
        per = np.array([1.0, -1.0, 1.0, -1.0])  # std 1.1547, SE 0.5774
        steps = per + z * np.std(per, ddof=1) / 2
        d, _ = evaluation.clearance_signal(minus + 2 * h * steps, minus, h)
        assert d == (pytest.approx(np.mean(steps)) if expected is None else expected), z
    assert evaluation.clearance_signal(minus[:1] + h, minus[:1], h) == (
        0.0,
        pytest.approx(np.nan, nan_ok=True),
    )


def test_auto_clearance_step_is_on_where_the_envelope_is_misaligned_beyond_1_mrad():
    """The default `clearance_step="auto"`: the Delta_bf difference runs (h = 0.01 mm, the
    clearance study's step) where any operating point is tilted by more than 1 mrad, where the
    study found dJ/dDelta_bf significant, and not for an aligned or 1 mrad envelope, where it
    bounded the slope near 0; a number overrides it."""
    import dataclasses

    import jaxbearing as jb
    from optimise import make_problem

    auto = search_settings.SteadySettings()
    assert auto.clearance_step == "auto"
    op = jb.reference_operating_point()
    for tilt, step in ((0.0, 0.0), (1e-3, 0.0), (-2e-3, search_settings.CLEARANCE_STEP), (1.5e-3, 0.01e-3)):
        problem = make_problem(jb.reference_bearing(), dataclasses.replace(op, misalignment=tilt))
        assert search_settings.clearance_step_for(problem, auto) == pytest.approx(step, abs=1e-15), tilt
    aligned = make_problem(jb.reference_bearing(), op, speeds_rpm=[10000.0, 30000.0])
    assert search_settings.clearance_step_for(aligned, auto) == 0.0
    assert (
        search_settings.clearance_step_for(aligned, search_settings.SteadySettings(clearance_step=2e-5))
        == 2e-5
    )


def _envelope_engine(seen):
    """A stand-in for the engine at several speeds: J [Pa m/s] = 1e9 (omega / 1000 rad/s)^2 per
    seed with an interval of +- 5 %, corner margin 1 mm / (omega / 1000 rad/s); each state
    counts the evaluations along its chain."""
    import types

    def engine(bearing, ops, designs, settings, *, initial_states, **kw):
        seeds = settings.seeds
        seen.append([float(op.inner_speed) for op in ops])
        out = []
        for k, op in enumerate(ops):
            w = float(op.inner_speed) / 1000.0
            j = 1e9 * w * w
            est = Estimate(j, 0.95 * j, 1.05 * j, seeds)
            margin = Estimate(1e-3 / w, 0.0, 1.0, seeds)
            steps = 0 if initial_states is None or initial_states[k] is None else initial_states[k][0][1]
            out.append(
                types.SimpleNamespace(
                    objective=est,
                    objective_per_seed=[j] * seeds,
                    corner_margin=margin,
                    corner_margin_bound=0.5e-3 / w,
                    corner_contact_share=Estimate(0.0, 0.0, 0.0, seeds),
                    mean_pv=est,
                    statistics=None,
                    settled=True,
                    seeds=list(range(seeds)),
                    simulated_ms=3.0 * seeds,
                    final_states=[(w, steps + 1)] * seeds,
                    sample_states=[],
                    contact_radius_maxima=[],  # no revolutions: the risk margin falls back
                    limited_circle_radius_m=3.36e-3,
                )
            )
        return out

    return engine


def _three_speed_stand_ins(monkeypatch, engine):
    """The reference problem at 10,000, 20,000 and 30,000 rpm with `engine` for the settled
    ensembles and a constant frozen-load gradient; 2 seeds, one worker."""
    import jaxbearing as jb
    from optimise import make_problem

    monkeypatch.setattr(evaluation, "steady_design_metrics_points", engine)
    monkeypatch.setattr(evaluation, "frozen_load_statistics", _frozen_stand_in())
    problem = make_problem(
        jb.reference_bearing(), jb.reference_operating_point(), speeds_rpm=[10e3, 20e3, 30e3]
    )
    return problem, search_settings.SteadySettings(seeds=2, workers=1)


def test_envelope_leaves_out_points_of_negligible_weight(monkeypatch):
    """The envelope's active set (`next_active`): with the smooth max (T = 0.1 GPa m/s) the
    points whose upper bound is far below the worst point's lower bound are not simulated; their
    values, gradients and states are the last ones, their corner margin moved by the static
    limited-circle change; a point near the smallest corner margin, a point due for its recheck,
    and every point of the weighted mean are simulated (stand-ins for the engine and estimator)."""
    import jaxbearing as jb
    from jaxbearing.flange import MARGIN_NAMES
    from optimise import make_problem

    seen = []
    problem, settings = _three_speed_stand_ins(monkeypatch, _envelope_engine(seen))
    u0, u1 = np.array([0.5, 0.5, 0.25]), np.array([0.55, 0.45, 0.25])
    (ev0,) = evaluation.evaluate_starts(problem, settings, [u0], [None])
    assert len(seen[-1]) == 3
    # the corner constraint: by default on the prediction bound, "mean" on the expectation
    assert ev0.dynamic_margin == pytest.approx(0.5e-3 / (float(problem.operating.inner_speed[2]) / 1000.0))
    (ev_mean,) = evaluation.evaluate_starts(
        problem, search_settings.SteadySettings(seeds=2, workers=1, corner_constraint="mean"), [u0], [None]
    )
    assert ev_mean.dynamic_margin == pytest.approx(2 * ev0.dynamic_margin)
    assert envelope.next_active(problem, settings, ev0, [0, 0, 0]) == [False, False, True]
    assert envelope.next_active(problem, settings, ev0, [2, 0, 0]) == [True, False, True]  # recheck due
    wide = search_settings.SteadySettings(
        seeds=2, workers=1, corner_margin=0.3e-3
    )  # 20k within 0.3 mm of 30k's
    assert envelope.next_active(problem, wide, ev0, [0, 0, 0]) == [False, True, True]
    # 10,000 rpm's 0.48 mm is within 0.4 mm of the smallest but above CORNER_WATCH: cannot bind yet
    wider = search_settings.SteadySettings(seeds=2, workers=1, corner_margin=0.4e-3)
    assert envelope.next_active(problem, wider, ev0, [0, 0, 0]) == [False, True, True]
    assert (
        envelope.next_active(problem, search_settings.SteadySettings(skip_weight=0.0), ev0, [0, 0, 0])
        == [True] * 3
    )
    mean = make_problem(
        jb.reference_bearing(),
        jb.reference_operating_point(),
        speeds_rpm=[10e3, 20e3, 30e3],
        aggregate="mean",
    )
    assert envelope.next_active(mean, settings, ev0, [0, 0, 0]) == [True] * 3

    (ev1,) = evaluation.evaluate_starts(
        problem, settings, [u1], [ev0.states], active=[[False, False, True]], previous=[ev0]
    )
    assert len(seen[-1]) == 1  # only 30,000 rpm simulated
    for k in (0, 1):
        old, new = ev0.per_point[k], ev1.per_point[k]
        assert new.value == old.value and new.simulated is False and ev1.states[k] is ev0.states[k]
        lc = MARGIN_NAMES.index("limited_circle")
        moved = float(problem.margins(jnp.asarray(u1))[lc] - problem.margins(jnp.asarray(u0))[lc])
        assert new.corner_margin == pytest.approx(old.corner_margin + moved, rel=1e-12)
    assert ev1.states[2][0][1] == 2  # the simulated point continued its chain
    assert ev1.objective == pytest.approx(ev0.objective, rel=1e-12)  # the worst point's value, unchanged here
    # the combined objective's interval: the dominant point's half-widths (+-5 %) around J, which
    # lies T ln 3 below the largest point (the others weigh nothing)
    worst = ev0.per_point[2].value
    assert ev0.objective == pytest.approx(worst - 0.1 * math.log(3), rel=1e-9)
    np.testing.assert_allclose(
        ev0.objective_ci, (ev0.objective - 0.05 * worst, ev0.objective + 0.05 * worst), rtol=1e-9
    )
    with pytest.raises(ValueError, match="previous evaluation"):
        evaluation.evaluate_starts(problem, settings, [u1], [ev0.states], active=[[False, False, True]])
    for bad, name in ((1.0, "skip_weight"), (-0.1, "skip_weight")):
        with pytest.raises(UserInputError, match=f"^{name} = "):
            search_settings.SteadySettings(skip_weight=bad)
    with pytest.raises(UserInputError, match="^recheck_every = 0"):
        search_settings.SteadySettings(recheck_every=0)


def test_envelope_search_rechecks_and_resumes_identically(tmp_path, monkeypatch):
    """`steady_search` at three speeds on the stand-in engine: iteration 0 simulates every point,
    then only the worst until the recheck (every 3 iterations); the settled ensembles counted are
    those simulated; a search killed after iteration 1 resumes from its checkpoint (the active set
    and the last measurements included) to exactly the uninterrupted history."""

    seen = []
    engine = _envelope_engine(seen)
    problem, settings = _three_speed_stand_ins(monkeypatch, engine)
    kw = dict(num_starts=1, num_iterations=4, verify=False)
    whole = steady.steady_search(problem, settings, directory=tmp_path / "whole", **kw)
    assert [len(s) for s in seen] == [3, 1, 1, 3, 1]
    simulated = whole.history.points_simulated[:, 0]
    np.testing.assert_array_equal(simulated.sum(axis=1), [3, 1, 1, 3, 1])
    assert whole.num_evaluations == 9

    calls = {"n": 0}

    def dying(*a, **k):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return engine(*a, **k)

    monkeypatch.setattr(evaluation, "steady_design_metrics_points", dying)
    with pytest.raises(KeyboardInterrupt):
        steady.steady_search(problem, settings, directory=tmp_path / "killed", **kw)
    monkeypatch.setattr(evaluation, "steady_design_metrics_points", engine)
    seen.clear()
    resumed = steady.steady_search(problem, settings, directory=tmp_path / "killed", **kw)
    assert resumed.resumed_from == 1 and [len(s) for s in seen] == [1, 3, 1]
    for key in ("x", "objective", "gradient", "margins", "points_simulated"):
        np.testing.assert_array_equal(getattr(resumed.history, key), getattr(whole.history, key))


def test_verification_reports_every_operating_point(monkeypatch, capsys):
    """At several operating points the verification reports each one, and says whether the
    found design's intervals lie below the reference's at every point (here lower at 30,000
    rpm only: the stand-in's mean PV rises with R_end and the speed, its interval +-0.05 GPa m/s
    at 30,000 rpm, +-1 GPa m/s elsewhere), and whether it touched the corner at any."""
    import jaxbearing as jb
    from optimise import make_problem

    inner = _metrics_stand_in([])

    def engine(bearing, ops, designs, *args, **kw):
        out = inner(bearing, ops, designs, *args, **kw)
        for m, op in zip(out, ops):
            fast = float(op.inner_speed) > 3000.0
            hw = 0.05e9 if fast else 1e9
            for name in ("mean_pv", "objective"):
                est = getattr(m, name)
                setattr(m, name, Estimate(est.value, est.value - hw, est.value + hw, est.n))
        return out

    monkeypatch.setattr(evaluation, "steady_design_metrics_points", engine)
    problem = make_problem(jb.reference_bearing(), jb.reference_operating_point(), speeds_rpm=[10e3, 30e3])
    settings = search_settings.SteadySettings(seeds=2, workers=1)
    reference = np.array([0.08, 1.6 * math.pi / 180, 0.15e-3])
    found = np.array([0.07, 1.6 * math.pi / 180, 0.15e-3])
    v = verify.verification(problem, settings, found, reference)
    assert len(v.optimum) == 2 and len(v.as_json()["optimum"]["per_operating_point"]) == 2
    assert v.mean_pv_lower_disjoint_per_point == [False, True]
    assert v.as_json()["objective_lower_disjoint_per_operating_point"] == [False, True]
    assert v.mean_pv_lower_disjoint is False and v.objective_lower_disjoint is False
    assert v.optimum_corner_contacts is True  # R_end 70 mm touches the corner in the stand-in


def test_initial_states_continue_a_start_s_first_evaluation(config, monkeypatch):
    """`steady_search(initial_states=...)`: a start given states (notebook 05: the settled
    ensemble of its design that the notebook ran before) evaluates its first iterate from them,
    a start given None from the skid start; a list that does not match the starts and operating
    points is refused in one line before anything runs (a stand-in for the settled ensemble)."""
    import jaxbearing as jb
    from optimise import make_problem

    seen = []

    def evaluate_starts(problem, settings, us, chains, *, gradient=True, **kw):
        seen.append(list(chains))
        return _stand_in_starts(problem, settings, us, chains, gradient=gradient)

    monkeypatch.setattr(steady, "evaluate_starts", evaluate_starts)
    cfg = jb.load_config(config)
    problem = make_problem(cfg.bearing(), cfg.operating_point())
    settings = search_settings.SteadySettings(seeds=2, window_revs=2, settle=0.5, workers=1)
    kw = dict(num_starts=2, num_iterations=1, verify=False)
    given = steady.steady_search(problem, settings, initial_states=[[[4]], None], **kw)
    # the stand-in's states count the evaluations along a chain (and add 0.01 each to J): the
    # first start's chain went on from the 4 given, the second's from the skid start
    assert seen == [[[[4]], None], [[[5]], [[1]]]]
    u0 = np.asarray(given.history.x)[0]
    j0 = np.asarray(given.history.objective)[0]
    target = 1.0 + np.sum((np.asarray(problem.bounds.to_scaled(u0)) - [0.7, 0.6, 0.5]) ** 2, axis=-1)
    np.testing.assert_allclose(j0 - target, [0.04, 0.0], atol=1e-9)
    for bad in ([[[4]]], [[[4], [4]], None]):
        with pytest.raises(UserInputError, match=r"^initial_states: \d given, expected one per start \(2\)"):
            steady.steady_search(problem, settings, initial_states=bad, **kw)
    assert len(seen) == 2


@pytest.mark.slow
def test_clearance_signal_at_2_mrad_is_the_paired_difference_and_positive(monkeypatch):
    """Slow (about 5 minutes on 2 cores): the search's Delta_bf signal on real settled running
    where the clearance matters (inner ring tilted 2 mrad, R_end 100 mm, theta_f 1.4 deg,
    Delta_bf 0.15 mm; 11 slices, 4 seeds, settling verdict, 2-revolution windows). With the
    default `clearance_step="auto"` the evaluation continuing from a settled ensemble runs the
    design at Delta_bf +- 0.01 mm from the same states with the same seeds in its engine call;
    the gradient's Delta_bf component is the paired central difference of those members'
    per-seed objectives where significant at 5 % (`clearance_signal`; scaled to the box), and
    the difference is positive: a larger clearance lets the
    tilted ring's rollers skew further (the clearance study measured +2.5 % of J per 10 um
    here, 7.5 standard errors at 16 seeds; at 4 seeds the expected difference lies about 3.7
    standard errors above 0)."""
    import dataclasses

    import jaxbearing as jb
    from jaxbearing.design import paired_central_difference
    from optimise import make_problem

    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    op = dataclasses.replace(jb.reference_operating_point(), misalignment=2e-3)
    problem = make_problem(bearing, op)
    settings = search_settings.SteadySettings(seeds=4, window_revs=2)
    h = search_settings.clearance_step_for(problem, settings)
    assert h == search_settings.CLEARANCE_STEP
    lower, upper = np.asarray(problem.bounds.lower), np.asarray(problem.bounds.upper)
    u = (np.array([0.100, np.radians(1.4), 0.15e-3]) - lower) / (upper - lower)
    (settled,) = evaluation.evaluate_starts(problem, settings, [u], [None], gradient=False)
    seen = []
    engine = evaluation.steady_design_metrics_points

    def spied(bearing_, ops, designs, *args, **kw):
        out = engine(bearing_, ops, designs, *args, **kw)
        seen.append(([float(d.axial_clearance) for d in designs], out))
        return out

    monkeypatch.setattr(evaluation, "steady_design_metrics_points", spied)
    (ev,) = evaluation.evaluate_starts(problem, settings, [u], [settled.states])
    ((clearances, members),) = seen
    np.testing.assert_allclose(clearances, [0.15e-3, 0.15e-3 + h, 0.15e-3 - h], rtol=1e-9)
    fd, se, n = paired_central_difference(members[1].objective_per_seed, members[2].objective_per_seed, h)
    assert n == 4
    signal, _ = evaluation.clearance_signal(members[1].objective_per_seed, members[2].objective_per_seed, h)
    assert signal in (0.0, fd)  # the difference where significant at 5 %, else 0
    scale = (upper[2] - lower[2]) / evaluation.PV_SCALE
    assert ev.gradient[2] == pytest.approx(signal * scale, rel=1e-9, abs=1e-300)
    assert ev.gradient_stderr[2] == pytest.approx(se * scale, rel=1e-9)
    assert fd > 0, (fd, se)


def test_tail_verification_needs_the_risk_bounded_at_every_operating_point(tmp_path, capsys):
    """The verification's tail statement: verified only when the corner-contact risk's upper bound
    is at most the level at every operating point; a point without a risk estimate counts as
    unbounded; the revolutions needed are those of counting alone (2995 for 1e-3 at 95 %)."""
    from optimise._cli_steady import tail_text

    def risk(upper, n, method="count"):
        return CornerRisk(upper / 2, 0.0, upper, 0.95, method, n, 4, 0, 3e-3, 2e-3, upper)

    ok = verify.tail_verification([risk(4e-4, 4000), risk(9e-4, 3200)], 1e-3)
    assert ok.verified and ok.upper_per_revolution == 9e-4 and ok.revolutions_needed == 2995
    assert "verified in the tail at 0.001" in tail_text(ok) and "NOT" not in tail_text(ok)
    short = verify.tail_verification([risk(4e-4, 4000), risk(0.17, 16)], 1e-3)
    assert not short.verified and short.upper_per_revolution == 0.17
    assert "NOT verified in the tail" in tail_text(short) and "2995 revolutions per point" in tail_text(short)
    assert "from counted corner contacts" in tail_text(short)
    modelled = verify.tail_verification([risk(2e-4, 16, "normal")], 1e-3)
    assert modelled.verified and "a normal model of the per-revolution largest contact radius" in tail_text(
        modelled
    )
    assert not verify.tail_verification([None], 1e-3).verified
    assert verify.tail_verification([None], 1e-3).as_json()["upper_per_revolution"] == 1.0
    # the level is a setting of the search: out of (0, 1) it is one line before anything runs
    assert main(["run", "--out", str(tmp_path), "--corner-risk-level", "0"]) == 2
    assert capsys.readouterr().err.count("corner_risk_level = 0.0: must be in (0, 1) per revolution") == 1


def test_risk_corner_margin_is_the_tolerance_bound_inside_the_limited_circle():
    """`corner_constraint = "risk"` (the default): the margin is rho_lim - corner_margin - (m +
    k_tol s) of the per-revolution maxima, k_tol the one-sided normal tolerance factor at the
    risk level and 95 % (`run.tolerance_factor`, checked against Natrella's table in
    tests/test_corner_risk.py); it shrinks as the level falls; "prediction" keeps the prediction
    bound, and so does "risk" where fewer than three revolutions touched a flange."""
    import types

    from jaxbearing.run import tolerance_factor

    rows = [np.array([2.9e-3, 3.0e-3, 2.95e-3, 3.05e-3]), np.array([2.92e-3, 3.02e-3, 2.97e-3, 2.99e-3])]
    m = types.SimpleNamespace(
        contact_radius_maxima=rows,
        limited_circle_radius_m=3.36e-3,
        corner_margin_bound=1e-4,
        corner_margin={},
    )
    values = np.concatenate(rows)
    settings = search_settings.SteadySettings(corner_margin=0.05e-3, corner_risk_level=1e-3)
    margin = evaluation.corner_margin_of(settings, m)
    # the two members' means differ little against their spread: no design effect (deff = 1)
    k = tolerance_factor(values.size, 1e-3, 0.95)
    assert margin == pytest.approx(3.36e-3 - 0.05e-3 - (values.mean() + k * values.std(ddof=1)), rel=1e-9)
    stricter = dataclasses.replace(settings, corner_risk_level=1e-5)
    assert evaluation.corner_margin_of(stricter, m) < margin
    assert (
        evaluation.corner_margin_of(dataclasses.replace(settings, corner_constraint="prediction"), m) == 1e-4
    )
    m.contact_radius_maxima = [np.array([3.0e-3, 0.0]), np.array([3.1e-3])]  # two in contact
    assert evaluation.corner_margin_of(settings, m) == 1e-4


def test_uncertain_constants_run_every_point_at_every_corner(tmp_path, config, monkeypatch, capsys):
    """`optimise run --uncertain-constants lubricant.traction_d,lubricant.oil_fraction`: every
    operating point also runs at every corner of the two constants' ranges (and the nominal
    point), as further points of the envelope; the engine gets each point with its corner's
    bearing, the verification and result.json name the corner of each point. Stand-ins for the
    search's ensemble and `steady_design_metrics_points` (the engine is the same as without)."""
    import jaxbearing as jb
    from jaxbearing.design import robustness_corners

    monkeypatch.setattr(steady, "evaluate_starts", _stand_in_starts)
    seen = []
    inner = _metrics_stand_in([])

    def engine(bearings, ops, designs, settings, **kw):
        seen.extend(
            (float(b.lubricant.traction_d), float(b.lubricant.oil_fraction), float(op.inner_speed))
            for b, op in zip(bearings, ops)
        )
        return inner(bearings, ops, designs, settings, **kw)

    monkeypatch.setattr(evaluation, "steady_design_metrics_points", engine)
    out = tmp_path / "robust"
    keys = "lubricant.traction_d,lubricant.oil_fraction"
    args = [*ARGS, "--speeds-rpm", "10000,30000", "--uncertain-constants", keys, "--out", str(out)]
    assert main(["run", "--config", config, *args]) == 0
    r = json.loads((out / "result.json").read_text())
    _, _, corners = robustness_corners(jb.load_config(config), keys.split(","))
    names = [c.name for c, _ in corners]
    assert [p["constants"] for p in r["operating_points"]] == [n for n in names for _ in range(2)]
    assert len(r["verification"]["optimum"]["per_operating_point"]) == 10
    expected = [
        (c.values["lubricant.traction_d"], c.values["lubricant.oil_fraction"])
        for c, _ in corners
        for _ in range(2)
    ]
    assert len(seen) == 20  # the reference and the found design at the 10 points, one engine call
    for i, (d, f, _) in enumerate(seen):
        assert (d, f) == pytest.approx(expected[i % 10])
    assert "at 30000 rpm, 1000 N, traction_d+, oil_fraction-" in capsys.readouterr().out
    # a key without a stated range: one line naming the setting
    bad = [*ARGS, "--uncertain-constants", "roller.length_mm", "--out", str(tmp_path / "bad")]
    assert main(["run", "--config", config, *bad]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: uncertain_constants: constants = 'roller.length_mm'") or (
        "uncertain_constants" in err and err.count("\n") == 1
    )


def test_problem_with_constant_corners_runs_each_point_with_its_bearing():
    """`make_problem(..., constant_corners=...)`: K envelope points x C corners, corner-major,
    each with its corner's bearing (`DesignProblem.bearing_at`) and the envelope's weights
    repeated; without corners every point runs the problem's bearing; the start-up objective
    refuses corners in one line."""
    import dataclasses as dc

    import jaxbearing as jb
    from optimise import make_problem

    b, op = jb.reference_bearing(), jb.reference_operating_point()
    low = dc.replace(b, lubricant=dc.replace(b.lubricant, traction_d=jnp.asarray(0.03)))
    plain = make_problem(b, op, speeds_rpm=[10e3, 30e3], weights=[1.0, 2.0])
    assert plain.bearing_at(1) is b and plain.point_constants is None
    p = make_problem(
        b, op, speeds_rpm=[10e3, 30e3], weights=[1.0, 2.0], constant_corners=[("nominal", b), ("low D", low)]
    )
    assert p.num_operating_points == 4 and p.point_constants == ("nominal", "nominal", "low D", "low D")
    assert np.asarray(p.weights).tolist() == [1.0, 2.0, 1.0, 2.0]
    assert [float(p.bearing_at(k).lubricant.traction_d) for k in range(4)] == pytest.approx(
        [0.04, 0.04, 0.03, 0.03]
    )
    assert p.point_label(3) == "30000 rpm, 1000 N, low D"
    with pytest.raises(UserInputError, match="start-up objective"):
        p.peak_pv(jnp.full(3, 0.5))
