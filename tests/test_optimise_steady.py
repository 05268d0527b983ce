"""`optimise run` on steady running (issue 13, items 1 and 3) at a reduced size: 11 slices,
2 seeds, a fixed 0.5 ms settle, two-revolution windows, 0.1 ms gradient windows.

Checked: the settings' one-line errors; a run killed after its first iteration resumes from
the checkpoint and ends with exactly the result of an uninterrupted run; the verification uses
seeds the search never saw and reports value and CI of mean PV, p95 PV and corner share."""

import json
import math

import numpy as np
import pytest

import optimise._steady as steady
from jaxbearing import UserInputError
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
        steady.SteadySettings(**kw)


@pytest.mark.parametrize(
    "args,text",
    [
        (["--estimator", "lss"], "estimator = 'lss': must be one of frozen, window"),
        (["--objective", "peak"], "objective = 'peak': must be 'steady' or 'startup'"),
        (["--seeds", "0"], "seeds = 0"),
        (["--settle", "soon"], "settle = 'soon'"),
        (["--gradient-window-ms", "-1"], "gradient_window_ms = -1.0: must be > 0"),
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


def test_killed_run_resumes_with_the_same_result(tmp_path, config, monkeypatch, capsys):
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    assert main(["run", "--config", config, *ARGS, "--no-verify", "--out", str(whole)]) == 0
    r1, j1, x1 = _history(whole)
    assert r1["objective_kind"] == "steady" and r1["status"] == "ok" and r1["resumed_from_iteration"] == -1
    assert j1.shape == (2, 1) and np.all(np.isfinite(j1)) and np.all(j1 > 0)
    assert np.all(np.isfinite(np.asarray(r1["history"]["gradient_per_unit_box"])))
    lo, hi = r1["objective_GPa_m_s"]["ci95_low"], r1["objective_GPa_m_s"]["ci95_high"]
    assert lo <= r1["objective_GPa_m_s"]["value"] <= hi

    # kill the second run in its second evaluation (after iteration 0 was checkpointed)
    calls = {"n": 0}
    evaluate = steady.evaluate

    def dying(*a, **k):
        calls["n"] += 1
        if calls["n"] == 2:
            raise KeyboardInterrupt
        return evaluate(*a, **k)

    monkeypatch.setattr(steady, "evaluate", dying)
    # the command line reports the interruption (exit code 130) and writes no result
    assert main(["run", "--config", config, *ARGS, "--no-verify", "--out", str(killed)]) == 130
    assert (killed / "checkpoint.pkl").exists() and not (killed / "result.json").exists()
    monkeypatch.setattr(steady, "evaluate", evaluate)
    assert main(["run", "--config", config, *ARGS, "--no-verify", "--out", str(killed)]) == 0
    assert "resumed after iteration 0" in capsys.readouterr().out
    r2, j2, x2 = _history(killed)
    assert r2["resumed_from_iteration"] == 0
    np.testing.assert_array_equal(j2, j1)
    np.testing.assert_array_equal(x2, x1)
    assert r2["design"] == r1["design"]
    # other settings: the checkpoint is refused in one line
    assert main(["run", "--config", config, *ARGS[:-2], "--no-verify", "--out", str(killed)]) == 2
    assert "checkpoint of a search with other settings" in capsys.readouterr().err


def test_verification_uses_unseen_seeds(config):
    import jaxbearing as jb
    from optimise import make_problem

    cfg = jb.load_config(config)
    problem = make_problem(cfg.bearing(), cfg.operating_point())
    settings = steady.SteadySettings(
        seeds=2,
        window_revs=2,
        settle=0.5,
        workers=1,
        verify_seeds=2,
        verify_first_seed=7,
        verify_window_revs=2,
    )
    x = np.array([0.08, 1.6 * math.pi / 180, 0.15e-3])
    v = steady.verification(problem, settings, x, x)
    assert v["seeds"] == [7, 8]
    for name in ("reference", "optimum"):
        row = v[name]
        assert row["seeds"] == [7, 8]
        for key in ("mean_pv_GPa_m_s", "p95_pv_GPa_m_s", "corner_contact_share"):
            est = row[key]
            assert est["ci95_low"] <= est["value"] <= est["ci95_high"]
    # the same design and seeds: the same numbers, so the CIs overlap
    assert v["mean_pv_lower_disjoint"] is False
    assert v["optimum_corner_contacts"] is False
