"""The held-load search's pieces (`optimise.held_load_search`, docs/model.md 17): its SLSQP step
on a function of known constrained minimum, the choice of the returned round, and one-line
errors. The held objective itself is checked against the frozen-load functional in
tests/test_steady_gradient.py; the search at full size in
benchmarks/studies/study_gradient_free.py (`--methods held`)."""

from __future__ import annotations

import numpy as np
import pytest

from jaxbearing import UserInputError
from optimise import HeldLoadResult, held_load_search
from optimise._held_load import held_minimum


def _at(u):
    """The layout of a held evaluator for one operating point: (mean PV, peak PV, corner
    distance, four zone margins) and their Jacobian. Mean PV 1 + (u0 - 0.8)^2 + (u1 - 0.3)^2,
    corner distance 0.5 - u0, zone margins (u1 - 0.1, 1, 1, 1)."""
    u0, u1 = u
    value = np.array([1 + (u0 - 0.8) ** 2 + (u1 - 0.3) ** 2, 2.0, 0.5 - u0, u1 - 0.1, 1.0, 1.0, 1.0])
    jac = np.zeros((7, 2))
    jac[0] = [2 * (u0 - 0.8), 2 * (u1 - 0.3)]
    jac[2] = [-1.0, 0.0]
    jac[3] = [0.0, 1.0]
    return value, jac


def test_held_minimum_finds_the_constrained_minimum():
    """Unconstrained the minimum is (0.8, 0.3); the corner floor 0 holds u0 at 0.5."""
    u, res = held_minimum(_at, [1.0], np.array([0.2, 0.9]), [0], np.array([0.0]), 50)
    assert res.success
    np.testing.assert_allclose(u, [0.5, 0.3], atol=1e-5)
    free, _ = held_minimum(_at, [1.0], np.array([0.2, 0.9]), [0], None, 50)
    np.testing.assert_allclose(free, [0.8, 0.3], atol=1e-5)
    # a zone floor above the margin u1 - 0.1 at the unconstrained u1 moves u1 up to it
    up, _ = held_minimum(_at, [1.0], np.array([0.2, 0.9]), [0], None, 50, zone_floor=0.4)
    np.testing.assert_allclose(up, [0.8, 0.5], atol=1e-5)


def test_the_returned_round_is_the_feasible_one_of_the_lowest_upper_bound():
    res = HeldLoadResult(
        designs=np.arange(8.0).reshape(4, 2),
        objective=np.array([3.0, np.nan, 2.0, 1.5]),
        ci=np.array([[2.9, 3.1], [np.nan, np.nan], [1.8, 2.2], [1.0, 2.5]]),
        feasible=np.array([True, False, True, False]),
    )
    assert res.best == 2
    np.testing.assert_array_equal(res.design, [4.0, 5.0])
    none = HeldLoadResult(res.designs, res.objective, res.ci, np.zeros(4, bool))
    assert none.best == -1 and none.design is None


@pytest.mark.parametrize(
    ("options", "words"),
    [
        ({"rounds": -1}, "rounds = -1"),
        ({"rounds": 1.5}, "rounds = 1.5"),
        ({"window_ms": 0.0}, "window_ms = 0"),
        ({"maxiter": 0}, "maxiter = 0"),
    ],
)
def test_bad_settings_are_one_line(options, words):
    with pytest.raises(UserInputError, match=words) as err:
        held_load_search(None, None, **options)
    assert "\n" not in str(err.value)
