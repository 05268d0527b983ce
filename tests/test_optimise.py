"""The `optimise` package: bounds and settings, the design-zone feasibility check, the
multi-start projected augmented-Lagrangian search against a brute-force grid, infeasible starts
and bounds that exclude the design zone, and the `optimise run` command line.

The search and the grid share one small problem (reference bearing at 11 slices, 20,000 rpm and 1000 N,
Delta_bf fixed at 0.2 mm, R_end x theta_f over the default bounds, 0.3 ms per evaluation), so
every model evaluation reuses one compilation. The grid here is 5 x 5; the full >= 15 x 15
comparison is benchmarks/results/optimise_vs_grid.json."""

import json
import math

import jax.numpy as jnp
import numpy as np
import pytest
from _figures import assert_png_drawn

import jaxbearing as jb
import optimise as opt
from optimise._cli import main
from optimise._cli_output import EXIT_INFEASIBLE

#: the reference bearing at 11 raceway slices (the reduced size of every dynamic test; the command
#: line reads it from SMALL_CONFIG, so that its search is the same compiled program)
REF = __import__("dataclasses").replace(jb.reference_bearing(), num_slices=11)
SMALL_CONFIG = "[bearing]\nnum_slices = 11\n"
OP = jb.reference_operating_point()
DURATION_MS = 0.3
CLEARANCE_MM = 0.2
#: 3 iterations leave both starts infeasible (2026-11-25: margins -5.3e-4 and -5.8e-7 m)
ITERATIONS = 8
#: the command line's run: its plumbing end to end on the search's compiled program. The same
#: number of iterations: the cosine step schedule is static in the compiled iteration, so 3
#: iterations compiled a second program (cold: 38 s of compilation against 2.2 s per iteration;
#: the CLI test took 40 s with 3 iterations and its own program)
CLI_ITERATIONS = ITERATIONS
STARTS = 2
BOUNDS = opt.bounds_from_engineering([60, 120], [1.0, 2.0], [CLEARANCE_MM, CLEARANCE_MM])
#: designs per vmapped grid batch: the default, 32, whose compiled program the command line's
#: search-path plot uses too (a batch of 4 solved fewer padded designs, 24 s against 42 s, but
#: the plot then compiled its own batch-32 program: 34 s against 18 s for the CLI test)
GRID_BATCH = 32


def _problem(**kw):
    return opt.make_problem(REF, OP, bounds=kw.pop("bounds", BOUNDS), duration=DURATION_MS * 1e-3, **kw)


# -- cheap checks (no dynamics) ---------------------------------------------------------------
def test_bounds_scaling_roundtrip_and_fixed_variable():
    b = opt.Bounds()
    x = np.array([0.09, math.radians(1.5), 0.2e-3])
    u = np.asarray(b.to_scaled(x))
    np.testing.assert_allclose(u, [0.5, 0.5, 0.5])
    np.testing.assert_allclose(np.asarray(b.from_scaled(u)), x)
    assert float(BOUNDS.to_scaled(x)[2]) == 0.0
    assert float(BOUNDS.from_scaled(jnp.array([0.0, 0.0, 0.7]))[2]) == pytest.approx(0.2e-3)


@pytest.mark.parametrize(
    "kw,text",
    [
        (dict(end_radius_mm=[-2, 120]), "bounds.end_radius_mm lower bound = -2"),  # > D/2: make_problem
        (dict(layback_angle_deg=[2.0, 1.0]), "lower bound above upper bound"),
        (dict(axial_clearance_mm=[0.1]), "expected \\[lower, upper\\]"),
        (dict(layback_angle_deg=[1.0, 50.0]), "bounds.layback_angle_deg upper bound = 50"),
    ],
)
def test_bad_bounds_are_one_line_errors(kw, text):
    with pytest.raises(jb.UserInputError, match=text) as e:
        opt.bounds_from_engineering(**kw)
    assert "\n" not in str(e.value)


def test_operating_envelope_is_speed_load_product():
    ops = opt.operating_envelope(OP, [5000, 15000, 30000], [500, 1000])
    assert ops.inner_speed.shape == (6,)
    np.testing.assert_allclose(np.asarray(ops.inner_speed[::2]) * 60 / (2 * math.pi), [5000, 15000, 30000])
    np.testing.assert_allclose(np.asarray(ops.radial_load[:2]), [500, 1000])
    with pytest.raises(jb.UserInputError, match="speeds_rpm"):
        opt.operating_envelope(OP, [-5.0])
    with pytest.raises(jb.UserInputError, match="weights: 1 given"):
        opt.make_problem(REF, OP, speeds_rpm=[5000, 10000], weights=[1.0])


def test_smooth_max_and_mean_aggregation():
    p = opt.make_problem(REF, OP, speeds_rpm=[5000, 10000, 20000], weights=[1, 1, 2], temperature=0.01)
    pv = jnp.array([1.0, 3.0, 2.0])
    # log-sum-exp: max + T log(sum w exp((pv - max)/T)) -> within T log(w_max) of the max
    assert float(p.combine(pv)) == pytest.approx(3.0 + 0.01 * math.log(0.25), rel=1e-9)
    q = opt.make_problem(REF, OP, speeds_rpm=[5000, 10000, 20000], weights=[1, 1, 2], aggregate="mean")
    assert float(q.combine(pv)) == pytest.approx((1 + 3 + 4) / 4)


def test_optimise_toml(tmp_path):
    f = tmp_path / "opt.toml"
    f.write_text("[bounds]\nend_radius_mm = [70, 110]\n[envelope]\nspeeds_rpm = [5000, 15000]\n")
    s = opt.load_optimise_toml(str(f))
    assert s == {"end_radius_mm": [70, 110], "speeds_rpm": [5000, 15000]}
    f.write_text("[bounds]\nend_radius = [70, 110]\n")
    with pytest.raises(jb.UserInputError, match="unknown key bounds.end_radius"):
        opt.load_optimise_toml(str(f))


def test_bounds_that_exclude_the_zone_report_no_feasible_design():
    """R_end <= 70 mm and theta_f <= 1.1 deg put the contact above the height limit everywhere
    (h_c = D/2 - R sin theta > 1.8 mm): the search reports it without any dynamic solve."""
    bounds = opt.bounds_from_engineering([60, 70], [1.0, 1.1], [0.1, 0.3])
    p = _problem(bounds=bounds)
    found, _ = opt.any_feasible(p)
    assert not found
    res = opt.search(p, num_starts=2, num_iterations=3)
    assert res.status == "no_feasible_design_in_bounds"
    assert not res.feasible and res.design is None and res.num_model_evaluations == 0


# -- the search against the grid (one shared compilation) -------------------------------------
@pytest.fixture(scope="module")
def searched():
    p = _problem()
    # start 0 infeasible (contact above the height limit), start 1 infeasible (beyond the
    # limited circle, on the corner)
    starts = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]])
    m = np.asarray([p.margins(jnp.asarray(s)) for s in starts])
    assert np.all(m.min(axis=1) < 0)
    return p, opt.search(p, num_starts=STARTS, num_iterations=ITERATIONS, starts=starts)


def test_infeasible_starts_end_feasible(searched):
    p, res = searched
    assert res.status == "ok" and res.feasible
    assert np.all(res.margins > 0)
    np.testing.assert_allclose(np.asarray(p.margins(p.bounds.to_scaled(res.design))), res.margins)
    # inside the bounds, Delta_bf held fixed
    lo, hi = p.bounds.lower, p.bounds.upper
    assert np.all(res.history["x"] >= lo - 1e-15) and np.all(res.history["x"] <= hi + 1e-15)
    assert res.design[2] == pytest.approx(CLEARANCE_MM * 1e-3)
    # both starts end inside the design zone
    assert np.all(res.history["margins"][-1].min(axis=-1) > 0)
    assert res.num_model_evaluations == (ITERATIONS + 1) * STARTS


def test_search_no_worse_than_grid(searched):
    """Issue 5 acceptance (small form): the final design is feasible and its smooth peak PV is
    no worse than the best feasible point of a 5 x 5 brute-force grid over the same bounds,
    evaluated with the same model, by more than 1e-6 of the objective's range over the grid.

    At this short horizon (0.3 ms) the objective has a floor: designs whose flange is not yet
    loaded give PV of 1e-10 to 1e-7 GPa m/s against 0.4-3 GPa m/s for the loaded ones (measured
    2026-11-25: search 2.3e-7, grid best 2.1e-10, range 3.0), so which of two points on the floor
    is lower is the rounding of an unloaded contact, not a ranking; what is claimed, and checked,
    is that the search reaches the floor the grid's best point is on. (It used to allow 1e-3
    GPa m/s, 4 000 times the values compared.) The full >= 15 x 15 comparison is
    benchmarks/results/optimise_vs_grid.json."""
    p, res = searched
    grid = opt.grid_search(p, 5, 5, CLEARANCE_MM * 1e-3, batch=GRID_BATCH)
    assert grid["best_design"] is not None and grid["num_model_evaluations"] > 0
    values = np.asarray(grid["objective"])[np.isfinite(grid["objective"])]
    span = float(values.max() - values.min())
    assert span > 0.1  # the grid holds loaded designs: a range to compare against
    assert res.objective <= grid["best_objective"] + 1e-6 * span, (
        res.objective,
        grid["best_objective"],
        span,
    )
    # the objective the search reports is the model's value at that design (in a batch of the
    # grid's size: the grid's compiled program, not a second one for a batch of 1)
    from optimise._search import _objective_batch

    u = jnp.repeat(p.bounds.to_scaled(res.design)[None], GRID_BATCH, axis=0)
    direct = float(_objective_batch(p, u)[0])
    assert res.objective == pytest.approx(direct, rel=1e-6)


# -- command line -------------------------------------------------------------------------------
def _cli_args(out):
    config = out.parent / "small.toml"
    config.write_text(SMALL_CONFIG)
    return [
        "run",
        "--config",
        str(config),
        "--objective",
        "startup",
        "--starts",
        str(STARTS),
        "--iterations",
        str(CLI_ITERATIONS),
        "--duration-ms",
        str(DURATION_MS),
        "--clearance-mm",
        f"{CLEARANCE_MM},{CLEARANCE_MM}",
        "--out",
        str(out),
    ]


def test_cli_end_to_end(tmp_path, capsys, searched):
    out = tmp_path / "run"
    assert main(_cli_args(out)) == 0
    text = capsys.readouterr().out
    assert "iter   0" in text and "final design" in text and "improvement" in text
    result = json.loads((out / "result.json").read_text())
    assert result["status"] == "ok" and result["feasible"]
    assert all(v > 0 for v in result["margins"].values())
    assert result["design"]["axial_clearance_mm"] == pytest.approx(CLEARANCE_MM)
    assert len(result["history"]["objective_GPa_m_s"]) == CLI_ITERATIONS + 1
    assert_png_drawn(out / "search_paths.png")


def test_cli_no_feasible_design_exits_nonzero(tmp_path, capsys):
    out = tmp_path / "none"
    code = main(
        [
            "run",
            "--objective",
            "startup",
            "--end-radius-mm",
            "60,70",
            "--layback-deg",
            "1.0,1.1",
            "--out",
            str(out),
        ]
    )
    assert code == EXIT_INFEASIBLE
    err = capsys.readouterr().err
    assert "no feasible design exists within the bounds" in err
    assert json.loads((out / "result.json").read_text())["status"] == "no_feasible_design_in_bounds"
    assert (out / "search_paths.png").exists()


@pytest.mark.parametrize(
    "args,text",
    [
        (["--speeds-rpm", "fast"], "--speeds-rpm = 'fast'"),
        (["--end-radius-mm", "60"], "--end-radius-mm = '60': expected LOWER,UPPER"),
        (["--starts", "0"], "starts = 0: must be > 0"),
        (["--layback-deg", "1,60"], "bounds.layback_angle_deg upper bound = 60"),
        (["--config", "/nonexistent/x.toml"], "file: cannot read"),
    ],
)
def test_cli_bad_input_one_line_exit_2(tmp_path, capsys, args, text):
    assert main(["run", "--out", str(tmp_path), *args]) == 2
    err = capsys.readouterr().err
    assert text in err and err.count("\n") == 1


def test_cli_settings_from_a_file_and_options_reach_the_problem(tmp_path, capsys, monkeypatch):
    """`optimise run --objective startup` with its settings from `--bounds FILE` and the
    options: the bounds (from the file, one of them overridden by `--layback-deg`), envelope
    (`--speeds-rpm` x `--loads-N`, speed-major, `--weights`, `--aggregate`), constraints
    (`--min-clearance-mm`, `--flange-load-N`) and solver and search settings (`--rtol`, `--atol`,
    `--learning-rate`, `--duration-ms`) are those of the problem the search receives and of
    result.json. The bounds exclude the design zone, so nothing is integrated (exit 3)."""
    import optimise._search as search_module

    settings = tmp_path / "opt.toml"
    settings.write_text(
        "[bounds]\nend_radius_mm = [60, 70]\nlayback_angle_deg = [1.0, 2.0]\n"
        "[constraints]\nmin_clearance_mm = 0.5\n[envelope]\nspeeds_rpm = [1000.0]\n"
    )
    seen = []
    real_search = search_module.search

    def recording(problem, **kw):
        seen.append((problem, kw))
        return real_search(problem, **kw)

    monkeypatch.setattr(search_module, "search", recording)
    out = tmp_path / "run"
    args = [
        "run",
        "--objective",
        "startup",
        "--bounds",
        str(settings),
        "--layback-deg",
        "1.0,1.1",
        "--min-clearance-mm",
        "0.05",
        "--flange-load-N",
        "120",
        "--speeds-rpm",
        "15000,20000",
        "--loads-N",
        "500,1000",
        "--weights",
        "1,2,3,4",
        "--aggregate",
        "mean",
        "--rtol",
        "1e-4",
        "--atol",
        "1e-7",
        "--learning-rate",
        "0.05",
        "--duration-ms",
        "0.2",
        "--out",
        str(out),
    ]
    assert main(args) == EXIT_INFEASIBLE
    assert "no feasible design exists within the bounds" in capsys.readouterr().err
    ((problem, kw),) = seen
    assert (problem.rtol, problem.atol) == (1e-4, 1e-7)
    assert kw["learning_rate"] == 0.05
    r = json.loads((out / "result.json").read_text())
    assert r["status"] == "no_feasible_design_in_bounds"
    assert r["bounds"]["end_radius_mm"] == pytest.approx([60, 70])  # from the file
    assert r["bounds"]["layback_angle_deg"] == pytest.approx([1.0, 1.1])  # the option wins
    assert r["min_clearance_mm"] == pytest.approx(0.05) and r["flange_load_N"] == 120.0
    points = [(p["speed_rpm"], p["load_N"]) for p in r["operating_points"]]
    np.testing.assert_allclose(points, [(15000, 500), (15000, 1000), (20000, 500), (20000, 1000)], rtol=1e-9)
    assert r["weights"] == [1.0, 2.0, 3.0, 4.0]
    assert r["aggregate"] == "mean" and r["duration_ms"] == pytest.approx(0.2)
    assert r["search"]["learning_rate"] == 0.05
