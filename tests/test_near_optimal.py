"""The steady search's near-optimal set (issue 35, item 7): the evaluated feasible designs whose
objective lies within the best design's 95 % interval, each with its binding margin, in
result.json's terms and on the search-path figure. Fabricated histories: no solve."""

import dataclasses

import numpy as np

from optimise import near_optimal_set
from optimise._state import History
from optimise._steady import CONSTRAINT_NAMES, SteadySearchResult, choose, tied_with_best


def _result():
    # 3 iterations x 2 starts; objectives [GPa m/s], intervals, margins [m] (5 per iterate)
    x = np.array(
        [
            [[0.080, 0.0279, 1.5e-4], [0.100, 0.0250, 1.5e-4]],
            [[0.090, 0.0300, 1.5e-4], [0.105, 0.0277, 1.5e-4]],
            [[0.094, 0.0321, 1.5e-4], [0.106, 0.0278, 1.5e-4]],
        ]
    )
    objective = np.array([[2.2, 1.6], [1.3, 1.16], [1.12, 1.11]])
    ci = np.stack([objective - 0.05, objective + 0.05], axis=-1)
    margins = np.full((3, 2, 5), 1e-4)
    margins[2, 0, 0] = 2e-6  # the best's neighbour on the ridge: relief binds
    margins[2, 1, 4] = 3e-6  # the best: the dynamic corner margin binds
    margins[1, 0, 1] = -1e-5  # infeasible (height limit), objective inside the interval anyway
    objective[1, 0] = 1.12
    return SteadySearchResult(
        status="ok",
        feasible=True,
        design=x[2, 1],
        objective=1.11,
        objective_ci=(1.06, 1.16),
        start_design=x[0, 0],
        history=History(
            x=x,
            objective=objective,
            ci=ci,
            margins=margins,
            gradient=np.zeros((3, 2, 3)),
            gradient_stderr=np.zeros((3, 2, 3)),
            wall_s=np.zeros((3, 2)),
            simulated_ms=np.zeros((3, 2)),
            points_simulated=np.ones((3, 2, 1), bool),
            corner_risk=np.array([[0.5, 0.2], [0.4, 3e-4], [1e-4, 2e-3]]),
        ),
        num_iterations=2,
        num_evaluations=6,
        wall_time_s=0.0,
        resumed_from=-1,
        best_start=1,
        best_iteration=2,
    )


def test_near_optimal_set_is_the_feasible_designs_within_the_best_interval():
    near = near_optimal_set(_result())
    # 1.11 (best), 1.12 (iteration 2, start 0), 1.16 (iteration 1, start 1, at the interval's top);
    # 1.12 at iteration 1 start 0 is infeasible, 1.3 and above outside the interval
    assert [(d.iteration, d.start) for d in near] == [(2, 1), (2, 0), (1, 1)]
    assert [d.objective for d in near] == [1.11, 1.12, 1.16]
    assert near[0].binding_margin == "dynamic_corner" and near[0].binding_margin_m == 3e-6
    assert near[1].binding_margin == CONSTRAINT_NAMES[0] and near[1].binding_margin_m == 2e-6
    assert near[0].design.tolist() == [0.106, 0.0278, 1.5e-4] and np.allclose(near[0].ci95, [1.06, 1.16])


def test_the_safest_of_the_tied_designs_is_returned_unless_asked_otherwise():
    """The best is the feasible evaluation of the lowest upper bound (1.11 + 0.05 = 1.16 at
    iteration 2, start 1); tied with it are the feasible ones whose lower bound reaches below
    1.16 (1.11, 1.12 and 1.16: 1.16 - 0.05 <= 1.16); "safest" returns the tied one of the lowest
    corner-risk bound (1e-4 at iteration 2, start 0), "best" the best itself; a wide interval
    with a low point estimate does not win on its point estimate."""
    h = _result().history
    tied, best = tied_with_best(h)
    assert best == (2, 1) and sorted(map(tuple, np.argwhere(tied))) == [(1, 1), (2, 0), (2, 1)]
    assert choose(h, "best") == (2, 1) and choose(h, "safest") == (2, 0)
    wide = dataclasses.replace(h, ci=np.array(h.ci, float))
    wide.objective[2, 0], wide.ci[2, 0] = 1.0, (0.2, 1.8)  # lowest point, widest interval
    assert choose(wide, "best") == (2, 1)
    fresh = _result().history
    one_seed = dataclasses.replace(fresh, ci=np.full_like(np.array(fresh.ci, float), np.nan))  # no intervals
    assert choose(one_seed, "safest") == choose(one_seed, "best") == (2, 1)  # the lowest point estimate
    near = near_optimal_set(_result())
    assert [d.corner_risk for d in near] == [2e-3, 1e-4, 3e-4]
    assert near[0].corner_margin_m == 3e-6


def test_no_near_optimal_set_without_a_feasible_design():
    r = _result()
    r.design, r.objective_ci = None, None
    assert near_optimal_set(r) == []


def test_result_json_and_figure_carry_the_near_optimal_set(tmp_path, monkeypatch):
    import matplotlib.axes

    import jaxbearing as jb
    from optimise import make_problem, plot_search
    from optimise._cli_steady import _steady_result_json
    from optimise._settings import SteadySettings

    res = _result()
    problem = make_problem(jb.reference_bearing(), jb.reference_operating_point())
    doc = _steady_result_json(problem, {}, SteadySettings(), res)
    assert [d["end_radius_mm"] for d in doc["near_optimal"]] == [106.0, 94.0, 105.0]
    assert doc["near_optimal"][0]["binding_margin"] == "dynamic_corner"
    # the clearance: not seen by the estimator, said with the measured bound, not silently kept
    effect = doc["axial_clearance_effect"]
    assert effect["estimator_sees_it"] is False and effect["moved"] is False
    assert "docs/model.md 17" in effect["measured"]  # the measured bounds: on that page, with their study
    assert abs(doc["near_optimal"][1]["binding_margin_mm"] - 2e-3) < 1e-12
    labels = []
    real = matplotlib.axes.Axes.plot
    monkeypatch.setattr(
        matplotlib.axes.Axes,
        "plot",
        lambda self, *a, **k: labels.append(k.get("label")) or real(self, *a, **k),
    )
    plot_search(problem, res, tmp_path / "paths.png")
    assert "near-optimal: within the best's 95 % interval (3)" in labels
