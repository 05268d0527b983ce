"""The held-load search: minimise the held-load objective of settled contacts, settle, repeat
(docs/model.md 17, the held-load objective).

Each round settles the current design on the search's seeds (`evaluate`, the members every
search counts), holds the flange contacts of a `window_ms` plain solve from each seed's settled
state (`design.held_contacts`) and minimises, by SLSQP with the held objective's exact
derivatives, the largest held mean PV over the operating points against its value at the
current design, over the whole scaled box: the static zone margins >= the problem's tightened
bound with 2 um to spare, and every point's held corner distance (the limited circle minus the
largest held contact radius) >= what the measured dynamic corner margin needs (the held
distance at the current design minus its measured dynamic margin, plus the same spare: the gap
between the tolerance bound of the maxima and the held maximum taken as fixed). The held
objective has no seed noise and no dynamics, so one round can move far; what it leaves out (how
the design changes the loads and the poses) the next round's settled run measures. The
returned design is the feasible settled one of the lowest upper 95 % bound, as the
gradient-free searches choose.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from jaxbearing.design import held_contacts, held_readouts, trajectory_states
from jaxbearing.io import require

from ._evaluate import evaluate, operating_points
from ._problem import MARGIN_SCALE, DesignProblem
from ._settings import SteadySettings
from ._steady import measured_constraints, returned_so_far

#: the margin [m] the held minimum keeps beyond the problem's tightened constraints
SPARE = 2e-6
#: saved states per ms of each held window
SAVES_PER_MS = 100


def held_evaluator(bearing, held, lower, upper, margins):
    """at(u) -> (readouts, their Jacobian in u), cached by u: for every set of held contacts of
    `held` (one `design.HeldContacts` per operating point) the held mean PV [GPa m/s], peak PV
    [GPa m/s] and corner distance [m] (`design.held_readouts`), then the four static zone
    margins [m] `margins(u)`, of the design lower + u (upper - lower) (SI arrays, 3 or 8
    variables) applied to `bearing`."""

    def readouts(u):
        x = jnp.asarray(lower) + u * jnp.asarray(upper - lower)
        per = []
        for c in held:
            r = held_readouts(bearing, x, c)
            per += [r.mean_pv / 1e9, r.peak_pv / 1e9, r.corner_distance]
        return jnp.concatenate([jnp.stack(per), margins(u)])

    value, jacobian = jax.jit(readouts), jax.jit(jax.jacfwd(readouts))
    cache = {}

    def at(u):
        key = tuple(np.round(np.asarray(u, float), 14))
        if key not in cache:
            v = jnp.asarray(np.asarray(u, float))
            cache[key] = (np.asarray(value(v)), np.asarray(jacobian(v)))
        return cache[key]

    return at


def held_minimum(at, reference, u_start, points, floor, maxiter: int, zone_floor: float = 0.0):
    """SLSQP from `u_start` in the unit box: the design u (and scipy's result) minimising the
    largest held mean PV over the operating points `points` (indices), each over its
    `reference` value (the epigraph form: minimise t subject to t >= J_k(u) / J_k^ref), with the
    static zone margins >= `zone_floor` [m] and, unless `floor` is None, every point's held
    corner distance >= floor[point] [m]. `at`: a `held_evaluator`'s (or any function with the
    same layout: 3 readouts per point, then 4 margins)."""
    from scipy.optimize import minimize

    n = len(u_start)
    k = (len(at(u_start)[0]) - 4) // 3
    cons = [
        {
            "type": "ineq",
            "fun": lambda v, i=i: v[-1] - at(v[:n])[0][3 * i] / reference[i],
            "jac": lambda v, i=i: np.r_[-at(v[:n])[1][3 * i] / reference[i], 1.0],
        }
        for i in points
    ]
    cons.append(
        {
            "type": "ineq",
            "fun": lambda v: (at(v[:n])[0][3 * k :] - zone_floor) * 1e3,
            "jac": lambda v: np.c_[at(v[:n])[1][3 * k :] * 1e3, np.zeros(4)],
        }
    )
    if floor is not None:
        cons.append(
            {
                "type": "ineq",
                "fun": lambda v: (at(v[:n])[0][2 : 3 * k : 3] - floor) * 1e3,
                "jac": lambda v: np.c_[at(v[:n])[1][2 : 3 * k : 3] * 1e3, np.zeros(k)],
            }
        )
    r_start, _ = at(u_start)
    t_start = max(r_start[3 * i] / reference[i] for i in points)
    res = minimize(
        lambda v: (v[-1], np.r_[np.zeros(n), 1.0]),
        np.r_[u_start, t_start],
        jac=True,
        method="SLSQP",
        bounds=[(0.0, 1.0)] * n + [(0.0, None)],
        constraints=cons,
        options={"maxiter": maxiter, "ftol": 1e-6},
    )
    return np.clip(res.x[:n], 0.0, 1.0), res


@dataclasses.dataclass
class HeldLoadResult:
    """Outcome of `held_load_search`: per settled round the design (SI), its settled objective
    (GPa m/s; NaN where not measured), its 95 % interval and whether it met every constraint;
    `best` the index of the returned round (-1: none feasible)."""

    designs: np.ndarray  # (R, n) SI
    objective: np.ndarray  # (R,)
    ci: np.ndarray  # (R, 2)
    feasible: np.ndarray  # (R,) bool

    @property
    def best(self) -> int:
        chosen = returned_so_far(self.feasible, self.ci, self.objective)
        return int(chosen[-1]) if len(chosen) else -1

    def best_so_far(self) -> np.ndarray:
        """After each round, the objective of the design returned had the search stopped there
        (NaN before the first feasible round)."""
        chosen = returned_so_far(self.feasible, self.ci, self.objective)
        return np.where(chosen >= 0, self.objective[np.maximum(chosen, 0)], np.nan)

    @property
    def design(self) -> np.ndarray | None:
        """The returned design (SI), None where no round was feasible."""
        return None if self.best < 0 else self.designs[self.best]


def _held(problem: DesignProblem, ev, design, window_ms: float) -> list:
    """The held contacts of one settled evaluation: per operating point, a plain solve of
    `window_ms` from each seed's settled state."""
    n = max(1, int(round(window_ms * SAVES_PER_MS)))
    held = []
    for k, op in enumerate(operating_points(problem)):
        b = problem.bearing_at(k)
        windows = [trajectory_states(design.apply(b), op, s, window_ms * 1e-3, n)[0] for s in ev.states[k]]
        states = jax.tree_util.tree_map(lambda *a: np.concatenate(a), *windows)
        held.append(held_contacts(b, op, design, states))
    return held


def held_load_search(
    problem: DesignProblem,
    settings: SteadySettings,
    *,
    rounds: int = 2,
    window_ms: float = 1.0,
    maxiter: int = 40,
    start=None,
    log=None,
) -> HeldLoadResult:
    """The held-load search (module docstring) from `start` (scaled; default the bearing's own
    design, `start_points`): `rounds` holds, `rounds + 1` settled evaluations (fewer where a
    settled design has no flange contact to hold at some operating point). `log`: called with
    one line per settled round."""
    from ._search import start_points

    require("rounds", rounds, lambda v: (v >= 0) & (v == np.round(v)), "an integer >= 0")
    require("window_ms", window_ms, lambda v: v > 0, "> 0 ms")
    require("maxiter", maxiter, lambda v: (v >= 1) & (v == np.round(v)), "an integer >= 1")
    u = np.asarray(start_points(problem, 1)[0] if start is None else start, float)
    lower, upper = np.asarray(problem.bounds.lower, float), np.asarray(problem.bounds.upper, float)
    points = list(range(problem.num_operating_points))
    spare = problem.tighten * MARGIN_SCALE + SPARE
    designs, objective, ci, feasible = [], [], [], []
    for k in range(int(rounds) + 1):
        ev = evaluate(problem, settings, u, gradient=False)
        designs.append(np.asarray(problem.bounds.from_scaled(u), float))
        objective.append(float(ev.objective))
        ci.append(tuple(ev.objective_ci))
        feasible.append(measured_constraints(problem, settings, u, ev)[1])
        if log is not None:
            log(
                f"held-load round {k}: objective {ev.objective:.3f}, feasible {feasible[-1]}, "
                f"zone margins {np.round(np.asarray(ev.static_margins) * 1e6, 1)} um, "
                f"dynamic corner margin {ev.dynamic_margin * 1e6:.1f} um"
            )
        if k == rounds:
            break
        design = problem.bounds.variables(jnp.asarray(designs[-1]))
        held = _held(problem, ev, design, window_ms)
        if any(c.load.shape[0] == 0 for c in held):  # no flange contact to hold at some point
            if log is not None:
                log(f"held-load round {k}: an operating point has no flange contact to hold; stopped")
            break
        at = held_evaluator(problem.bearing, held, lower, upper, problem.margins)
        readouts = at(u)[0]
        dynamic = ev.dynamic_margin if np.isfinite(ev.dynamic_margin) else settings.corner_margin
        floor = readouts[2 : 3 * len(points) : 3] - dynamic + spare
        u, _ = held_minimum(
            at, readouts[0 : 3 * len(points) : 3], u, points, floor, maxiter, zone_floor=spare
        )
    return HeldLoadResult(
        designs=np.asarray(designs),
        objective=np.asarray(objective),
        ci=np.asarray(ci, dtype=float).reshape(-1, 2),
        feasible=np.asarray(feasible),
    )
