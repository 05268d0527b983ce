"""`jaxbearing sensitivity`: which uncertain inputs matter (docs/model.md 18).

The static method (cage slip from the static skid equilibrium, central difference at h = u)
is checked against an independent central difference at h = u/4 for two keys; the CRN method's
estimator (per-seed paired differences, Student-t interval) against closed forms, with the
settled runs replaced by statistics known exactly, and on real settled runs (11 slices, one seed)
against central differences computed from those runs. Reduced size: 5 slices (static)."""

from __future__ import annotations

import dataclasses
import json
import math
from types import SimpleNamespace as NS

import numpy as np
import pytest

from jaxbearing._errors import UserInputError
from jaxbearing.cli import main
from jaxbearing.design import (
    MODEL_CONSTANTS,
    SENSITIVITY_STATISTICS,
    sensitivity,
    sensitivity_inputs,
    static_cage_slip,
)
from jaxbearing.design import _sensitivity as module
from jaxbearing.io import loads_config, reference_config

#: a reduced reference bearing whose inputs are two model constants (the others set to u = 0),
#: with more oil than the reference (0.08): the static cage slip has a knee, the onset of
#: skidding, at an oil fraction of about 0.047 at the reference point (docs/validation.md), and a
#: finite difference across a knee depends on its step; here every step stays on the skidding side
SMALL = """\
[bearing]
num_slices = 5
[lubricant]
oil_fraction = 0.08
[simulation]
progress = false
[uncertainty]
"lubricant.traction_a" = 0.0
"lubricant.traction_b_s_m" = 0.0
"lubricant.traction_c_s_m" = 0.0
"lubricant.traction_d" = { plus_minus = 0.005, estimated = "a rule" }
"lubricant.oil_fraction" = 0.01
"""


@pytest.fixture
def small(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    return path


def test_quick_cli_ranks_writes_and_agrees_with_a_finer_step(small, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["sensitivity", str(small), "--quick", "--statistics", "cage_slip", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "lubricant.traction_d" in text and "lubricant.oil_fraction" in text and "method static" in text
    doc = json.loads((out / "sensitivity.json").read_text())
    assert (out / "sensitivity.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert doc["provenance"]["command"][-1] == str(out)
    block = doc["statistics"]["cage_slip"]
    assert set(block["ranking"]) == {"lubricant.traction_d", "lubricant.oil_fraction"}
    assert [i["source"] for i in doc["inputs"]] == ["uncertain", "estimated"]
    # independent: a central difference of the static cage slip at h = u/4, computed here
    cfg = loads_config(SMALL)
    for key, u in (("lubricant.traction_d", 0.005), ("lubricant.oil_fraction", 0.01)):
        h = u / 4
        x = cfg[key]
        fine = (static_cage_slip(cfg.replace({key: x + h})) - static_cage_slip(cfg.replace({key: x - h}))) / (
            2 * h
        )
        e = block["effects"][key]
        assert e["method"] == "static" and e["step"] == pytest.approx(u)
        assert np.sign(e["effect"]) == np.sign(fine * u), (key, e, fine)
        assert abs(e["effect"] - fine * u) < 0.3 * abs(fine * u), (key, e["effect"], fine * u)
        assert e["ci95_low"] <= e["effect"] <= e["ci95_high"]
    # less traction at high sliding speed, or more drag (oil), lets the cage slip more
    assert (
        block["effects"]["lubricant.traction_d"]["effect"]
        < 0
        < block["effects"]["lubricant.oil_fraction"]["effect"]
    )


@dataclasses.dataclass
class _Run:
    seed: int
    window: dict
    edges: np.ndarray
    measured: bool = True


@dataclasses.dataclass
class _Result:
    bearing: object
    operating: object
    runs: list


def _fake_settled(statistic):
    """Settled runs replaced by a closed form: seed k's statistics block from `statistic(x, k)`,
    x the traction constant D of the run's bearing."""

    def points(bearings, ops, settings):
        return [
            _Result(
                b,
                op,
                [
                    _Run(k, {"x": float(b.lubricant.traction_d), "k": k}, np.zeros(3))
                    for k in range(settings.seeds)
                ],
            )
            for b, op in zip(bearings, ops)
        ]

    def statistics(windows, edges, bearing, op):
        (w,) = windows
        v = statistic(w["x"], w["k"])
        return NS(
            cage_slip=NS(value=v),
            flange_pv_Pa_m_s=NS(mean=NS(value=2 * v), max=NS(value=math.nan)),
            contact_height_m=NS(max=NS(value=v)),
        )

    return points, statistics


def test_crn_differences_recover_closed_forms(monkeypatch):
    # S_k(x) = x^2 + c_k: the central difference is exact for a quadratic, 2 x, and the seed's
    # offset c_k cancels in each pair; the effect is 2 x u with an interval of zero width
    points, stats = _fake_settled(lambda x, k: x**2 + 0.3 * k)
    monkeypatch.setattr(module, "simulate_steady_points", points)
    monkeypatch.setattr(module, "settled_statistics", stats)
    cfg = reference_config().replace({"bearing.num_slices": 5})
    settings = module.SteadySettings(seeds=3, window_revs=2)
    r = sensitivity(cfg, ["cage_slip", "mean_pv", "peak_pv"], settings)
    i = [x.key for x in r.inputs].index("lubricant.traction_d")
    e = r.effects["cage_slip"][i]
    u = MODEL_CONSTANTS["lubricant.traction_d"][0]
    assert e.method == "crn" and e.n == 3 and e.step == pytest.approx(u)
    assert e.effect == pytest.approx(2 * 0.04 * u, rel=1e-9)
    assert e.ci95_high - e.ci95_low == pytest.approx(0.0, abs=1e-12)
    assert r.effects["mean_pv"][i].effect == pytest.approx(2 * e.effect)
    assert math.isnan(r.effects["peak_pv"][i].effect)  # a statistic no seed measured: no effect
    assert r.ranking("cage_slip")[0] == i
    # the other inputs do not move D: zero effect
    assert all(r.effects["cage_slip"][j].effect == 0.0 for j in range(len(r.inputs)) if j != i)


def test_crn_interval_is_student_t_over_seeds(monkeypatch):
    # S_k(x) = x + eps_k(x) with a seed- and x-dependent part: D_k = 1 + (eps_k(x+h) - eps_k(x-h)) / 2h
    rng = {k: np.random.default_rng(k) for k in range(4)}
    noise = {}

    def statistic(x, k):
        return x + noise.setdefault((round(x, 12), k), 1e-3 * rng[k].standard_normal())

    points, stats = _fake_settled(statistic)
    monkeypatch.setattr(module, "simulate_steady_points", points)
    monkeypatch.setattr(module, "settled_statistics", stats)
    cfg = reference_config().replace({"bearing.num_slices": 5})
    r = sensitivity(cfg, ["cage_slip"], module.SteadySettings(seeds=4, window_revs=2))
    i = [x.key for x in r.inputs].index("lubricant.traction_d")
    e = r.effects["cage_slip"][i]
    u = 0.01
    d = np.array(
        [(noise[(round(0.04 + u, 12), k)] - noise[(round(0.04 - u, 12), k)]) / (2 * u) for k in range(4)]
    )
    d = 1.0 + d
    half = 3.182446305284263 * d.std(ddof=1) / 2.0  # t_{0.975, 3} SE
    assert e.effect == pytest.approx(d.mean() * u)
    assert (e.ci95_low, e.ci95_high) == pytest.approx(((d.mean() - half) * u, (d.mean() + half) * u))


def test_settled_options_reach_the_study(small, monkeypatch, capsys):
    seen = {}

    def fake(cfg, statistics, settings, *, quick=False, model_constants=True):
        seen.update(statistics=statistics, seeds=settings.seeds, window=settings.window_revs, quick=quick)
        raise UserInputError("stop here")

    monkeypatch.setattr("jaxbearing.design.sensitivity", fake)
    assert main(["sensitivity", str(small), "--seeds", "2", "--window-revs", "4"]) == 2
    assert seen == {
        "statistics": tuple(SENSITIVITY_STATISTICS),
        "seeds": 2,
        "window": 4,
        "quick": False,
    }


@pytest.mark.parametrize(
    ("argv", "names"),
    [
        (["--statistics", "cage_slip,wear"], "statistics = 'wear'"),
        (["--quick", "--statistics", "cage_slip,mean_pv"], "statistics = mean_pv"),
        (["--seeds", "0"], "--seeds = 0"),
        (["--window-revs", "1"], "--window-revs = 1"),
        (["--out", "FILE"], "--out"),
    ],
)
def test_bad_options_are_one_line(small, argv, names, capsys):
    argv = [str(small) if a == "FILE" else a for a in argv]
    assert main(["sensitivity", str(small), *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and names in err, err


def test_bad_configurations_are_one_line(tmp_path, capsys):
    unknown = tmp_path / "unknown.toml"
    unknown.write_text('[uncertainty]\n"roller.diametr_mm" = 0.1\n')
    assert main(["sensitivity", str(unknown), "--quick"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "roller.diametr_mm" in err and "roller.diameter_mm" in err, err
    nothing = tmp_path / "nothing.toml"
    nothing.write_text("[uncertainty]\n" + "".join(f'"{k}" = 0.0\n' for k in MODEL_CONSTANTS))
    assert main(["sensitivity", str(nothing), "--quick"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "nothing to rank" in err, err
    with pytest.raises(UserInputError, match="nothing to rank"):
        sensitivity_inputs(reference_config(), model_constants=False)
    edge = tmp_path / "edge.toml"  # oil fraction 0.01 +/- 0.025: the step halves into the range
    edge.write_text('[lubricant]\noil_fraction = 0.01\n[uncertainty]\n"lubricant.oil_fraction" = 0.025\n')
    cfg = loads_config(edge.read_text())
    item = next(i for i in sensitivity_inputs(cfg) if i.key == "lubricant.oil_fraction")
    h, up, down = module.perturbed(cfg, item, item.plus_minus)
    assert 0 < h <= 0.01 and down["lubricant.oil_fraction"] >= 0 and up["lubricant.oil_fraction"] > 0.01


#: the reference bearing at 11 slices (the shapes of tests/test_settle.py, whose compiled programs
#: the settled runs load) on the rolling side of the onset of skidding (oil fraction 0.03 +/- 0.01
#: against the onset near 0.047 at the reference point, docs/validation.md), so that the secant
#: does not straddle the knee; two inputs with a clear effect on the cage slip, the traction
#: constant D (0.035-0.045) and the oil fraction, the model's other constants at u = 0
SETTLED = """\
[bearing]
num_slices = 11
[lubricant]
oil_fraction = 0.03
[simulation]
progress = false
[uncertainty]
"lubricant.traction_a" = 0.0
"lubricant.traction_b_s_m" = 0.0
"lubricant.traction_c_s_m" = 0.0
"lubricant.traction_d" = 0.005
"lubricant.oil_fraction" = 0.01
"""
#: Student-t 97.5 % quantile at 1 degree of freedom: the batch-means interval of a 2-revolution
#: window (`run.settled_statistics`, Student-t over b - 1 = 1 batch)
_T975_1 = 12.706204736174698


def test_crn_effects_agree_with_central_differences_of_settled_runs(monkeypatch):
    """The settled ("crn") method against a central difference computed here from the very runs
    it made: the engine's calls are recorded (not replaced), each point's cage slip is read from
    its settled summary (`run.summarise_steady`, not the per-seed reading and paired difference
    of the sensitivity code), and (S(x + h) - S(x - h)) / 2h u must agree with the reported
    effect: the same sign, within 30 %, with |S(x + h) - S(x - h)| above 3 standard errors of
    the two windows' batch means (not vacuous). Also checked: the engine ran x + h and x - h of
    exactly the key in question with every other input unchanged, h = u, with common seeds.

    Reduced size: 11 slices, one seed, the skid start, 0.5 ms of settling (the skid start lands
    on the plateau, tests/test_skid.py), a 2-revolution window. Each point's skid start (static
    equilibrium and pre-start) is solved afresh for its inputs, about 9 s of the 2-core machine
    per point cold, so one seed: the engine's own determinism makes a second set of calls at the
    same seeds return the same numbers, and the recorded runs stand for them."""
    from jaxbearing.run import SteadySettings, summarise_steady

    seen = []
    real = module.simulate_steady_points

    def record(bearings, ops, settings):
        results = real(bearings, ops, settings)
        seen.append((list(bearings), list(ops), settings, results))
        return results

    monkeypatch.setattr(module, "simulate_steady_points", record)
    cfg = loads_config(SETTLED)
    settings = SteadySettings(seeds=1, window_revs=2, settle=0.5)
    r = sensitivity(cfg, ["cage_slip"], settings)
    ((bearings, ops, used, results),) = seen
    steps = {"lubricant.oil_fraction": 0.01, "lubricant.traction_d": 0.005}
    assert used == settings and [i.key for i in r.inputs] == list(steps)
    for i, item in enumerate(r.inputs):
        u = steps[item.key]
        for k, sign in ((2 * i, 1.0), (2 * i + 1, -1.0)):
            want = cfg.replace({item.key: cfg[item.key] + sign * u})
            assert _leaves(bearings[k]) == _leaves(want.bearing()), (item.key, sign)
            assert _leaves(ops[k]) == _leaves(want.operating_point())
            assert [run.seed for run in results[k].runs] == [0] and results[k].settled
        plus, minus = (summarise_steady(results[k])["cage_slip"] for k in (2 * i, 2 * i + 1))
        diff = plus["value"] - minus["value"]
        se = math.hypot(*((s["ci95_high"] - s["ci95_low"]) / (2 * _T975_1) for s in (plus, minus)))
        assert abs(diff) > 3 * se, (item.key, plus, minus)
        fd = diff / (2 * u) * u
        e = r.effects["cage_slip"][i]
        assert e.method == "crn" and e.step == pytest.approx(u) and e.n == 1
        assert np.sign(e.effect) == np.sign(fd) and abs(e.effect - fd) < 0.3 * abs(fd), (item.key, e, fd)
    # more oil drags the cage back; more traction at high sliding speed drives it towards rolling
    assert r.effects["cage_slip"][1].effect < 0 < r.effects["cage_slip"][0].effect


def _leaves(tree) -> list:
    """The numbers of a bearing or operating point (a pytree), for equality."""
    import jax

    return [np.asarray(x).tolist() for x in jax.tree_util.tree_leaves(tree)]
