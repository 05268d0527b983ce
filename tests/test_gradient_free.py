"""The gradient-free searches (`optimise.gradient_free_search`): random search and CMA-ES on the
same objective and constraints as the gradient search, counting settled members, resumable.
A cheap analytic stand-in replaces the settled ensemble (the real one runs in
tests/test_steady_design.py); the study at full size is benchmarks/studies/study_gradient_free.py."""

from __future__ import annotations

import dataclasses

import jax.numpy as jnp
import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing import UserInputError
from optimise import SteadySettings, gradient_free_search, make_problem
from optimise import _evaluate as evaluation
from optimise import _gradient_free as gf

TARGET = np.array([0.35, 0.55, 0.5])


def _stand_in_starts(problem, settings, us, chains, *, gradient=True, active=None, previous=None):
    """J = 1 + |u - u*|^2 with a 0.02 half-width, the dynamic corner margin negative for the
    largest end radii (u_0 > 0.8): a constraint only a simulation shows."""
    assert gradient is False and chains is None
    out = []
    for u in us:
        u = np.asarray(u, float)
        value = 1.0 + float(np.sum((u - TARGET) ** 2))
        out.append(
            evaluation.Evaluation(
                objective=value,
                objective_ci=(value - 0.02, value + 0.02),
                gradient=np.full(3, np.nan),
                gradient_stderr=np.full(3, np.nan),
                per_point=[],
                static_margins=np.asarray(problem.margins(jnp.asarray(u))),
                dynamic_margin=1e-4 if u[0] < 0.8 else -1e-4,
                states=[None] * problem.num_operating_points,
                wall_time_s=0.0,
                simulated_ms=10.0,
                corner_risk=1e-6,
            )
        )
    return out


@pytest.fixture
def problem(monkeypatch):
    monkeypatch.setattr(gf, "evaluate_starts", _stand_in_starts)
    return make_problem(jb.reference_bearing(), jb.reference_operating_point())


@pytest.mark.parametrize("method", ["random", "cmaes"])
def test_search_counts_members_and_returns_the_best_feasible_design(problem, method):
    """Only designs inside the static zone are simulated and cost seeds x points members each;
    the returned design is the feasible one of the lowest upper bound, and the best-so-far curve
    never rises."""
    settings = SteadySettings(seeds=2, workers=1)
    res = gradient_free_search(problem, settings, method, 120, seed=1, population=6)
    per = problem.num_operating_points * 2
    assert res.members[-1] == per * res.simulated.sum() >= 120
    assert res.simulated.sum() < len(res.x) or method == "cmaes"
    assert not np.any(res.feasible & ~res.simulated)
    best = res.best
    assert res.feasible[best]
    assert res.ci[best, 1] == np.min(res.ci[res.feasible, 1])
    members, curve = res.best_so_far()
    finite = curve[np.isfinite(curve)]
    assert np.all(np.diff(finite) <= 0) and members[-1] == res.members[-1]
    u = np.asarray(problem.bounds.to_scaled(res.x[best]))
    assert u[0] < 0.8  # the dynamic constraint holds
    one_seed = dataclasses.replace(res, ci=np.full_like(res.ci, np.nan))  # no intervals: point estimates
    assert one_seed.best == int(np.argmin(np.where(res.feasible, res.objective, np.inf)))


def test_cmaes_beats_random_search_on_a_smooth_objective(problem):
    """On a smooth bowl CMA-ES gets closer to the minimum than random search with the same members."""
    settings = SteadySettings(seeds=1, workers=1)
    cma = gradient_free_search(problem, settings, "cmaes", 300, seed=0, population=6)
    rnd = gradient_free_search(problem, settings, "random", 300, seed=0, population=6)
    assert cma.objective[cma.best] < rnd.objective[rnd.best]
    assert cma.objective[cma.best] < 1.0 + 0.02


def test_killed_search_resumes_with_the_same_result(problem, tmp_path, monkeypatch):
    """Every finished generation is kept (data only); a rerun after a crash simulates only the
    rest and returns what an uninterrupted run returns."""
    settings = SteadySettings(seeds=1, workers=1)
    whole = gradient_free_search(problem, settings, "cmaes", 60, seed=2, population=4)
    calls = []

    def dying(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return _stand_in_starts(*args, **kwargs)

    monkeypatch.setattr(gf, "evaluate_starts", dying)
    with pytest.raises(KeyboardInterrupt):
        gradient_free_search(problem, settings, "cmaes", 60, seed=2, population=4, directory=tmp_path)
    calls.clear()
    monkeypatch.setattr(
        gf, "evaluate_starts", lambda *a, **k: (calls.append(1), _stand_in_starts(*a, **k))[1]
    )
    again = gradient_free_search(problem, settings, "cmaes", 60, seed=2, population=4, directory=tmp_path)
    np.testing.assert_array_equal(again.x, whole.x)
    np.testing.assert_array_equal(again.objective, whole.objective)
    assert len(calls) == whole.simulated.reshape(-1, 4).any(axis=1).sum() - 2  # two were kept
    with pytest.raises(UserInputError, match="another search"):
        gradient_free_search(problem, settings, "random", 60, seed=2, population=4, directory=tmp_path)


@pytest.mark.parametrize(
    "kw, text",
    [
        (dict(method="grid"), "^method: 'grid'; valid: random, cmaes$"),
        (dict(population=1), "^population: 1; valid: an integer >= 2$"),
        (dict(budget_members=0), r"^budget_members: 0; valid: >= 1 \(one design's members\)$"),
    ],
)
def test_bad_arguments_are_one_line(problem, kw, text):
    args = dict(method="random", budget_members=10) | kw
    with pytest.raises(UserInputError, match=text):
        gradient_free_search(
            problem,
            SteadySettings(seeds=1, workers=1),
            args.pop("method"),
            args.pop("budget_members"),
            **args,
        )
