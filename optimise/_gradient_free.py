"""Gradient-free searches on the settled objective: random search and CMA-ES, to measure what
the gradient search's estimates buy at equal cost (docs/how-to/design-search.md).

Both see what `steady_search` sees: the same `DesignProblem` (box, static zone, envelope), the
same `SteadySettings` (seeds, window, corner constraint) and the same evaluation
(`evaluate_starts` without gradients: every design of a generation is a member group of one call
of the steady-running engine, one batched program per generation on an accelerator; each design
from the skid start). A design outside the static zone is not simulated (its margins are exact
and cheap) and costs nothing; a simulated one costs its settled members (seeds x operating
points) and is feasible when every static and dynamic constraint holds, tightened as the
gradient search's (`_steady.constraints`). The returned design is chosen as `steady_search`
chooses: the feasible design of the lowest upper 95 % bound of the objective.

CMA-ES is Hansen's `cma` package (N. Hansen, "The CMA Evolution Strategy: A Tutorial",
arXiv:1604.00772, 2016) on the scaled box [0, 1]^n with its bound handling, fixed variables
held. Its fitness is the objective's point estimate where feasible, and
`INFEASIBLE + violation` elsewhere (violation: the sum of the negative parts of the scaled
constraints), so any feasible design ranks before any infeasible one. Random search draws
uniformly in the box (numpy's PCG64 from `seed`), a generation at a time.

With `directory`, every finished generation is kept in DIR/gradient_free_checkpoint.npz (data
only) and a rerun with the same arguments resumes: random search redraws the same generations,
CMA-ES replays its ask/tell sequence with the stored fitness, so a resumed run equals one never
interrupted.
"""

from __future__ import annotations

import dataclasses
import pathlib
import time

import jax.numpy as jnp
import numpy as np

from jaxbearing import UserInputError

from ._evaluate import evaluate_starts, in_shared_pool
from ._problem import DesignProblem, margins_batch
from ._settings import SteadySettings
from ._state import load_checkpoint, save_checkpoint
from ._steady import constraints, measured_constraints, returned_so_far

#: the fitness offset of an infeasible design [GPa m/s]: far above every objective
INFEASIBLE = 1e3
METHODS = ("random", "cmaes")
_CHECKPOINT = "gradient_free_checkpoint.npz"


@dataclasses.dataclass
class GradientFreeResult:
    """Every design a gradient-free search drew, in order (designs in SI units: R_end [m],
    theta_f [rad], Delta_bf [m]; objectives in GPa m/s)."""

    method: str  # "random" or "cmaes"
    x: np.ndarray  # (N, 3) the designs drawn
    objective: np.ndarray  # (N,) the settled objective, NaN where not simulated
    ci: np.ndarray  # (N, 2) its 95 % interval
    feasible: np.ndarray  # (N,) every static and dynamic constraint holds
    simulated: np.ndarray  # (N,) inside the static zone, hence simulated
    corner_risk: np.ndarray  # (N,) upper 95 % bound of the corner risk per revolution
    members: np.ndarray  # (N,) settled members simulated up to and including this design
    simulated_ms: float  # simulated time of every member [ms]
    wall_time_s: float

    @property
    def best(self) -> int:
        """Index of the returned design: the feasible one of the lowest upper bound (-1: none; one
        without an interval counts with its point estimate, as in `steady_search`)."""
        chosen = returned_so_far(self.feasible, self.ci, self.objective)
        return int(chosen[-1]) if len(chosen) else -1

    def best_so_far(self) -> tuple[np.ndarray, np.ndarray]:
        """(members, objective of the design returned had the search stopped there) after each
        simulated design; NaN before the first feasible one."""
        chosen = returned_so_far(self.feasible, self.ci, self.objective)
        out = np.where(chosen >= 0, self.objective[np.maximum(chosen, 0)], np.nan)
        keep = self.simulated
        return self.members[keep], out[keep]


def _members_per_design(problem: DesignProblem, settings: SteadySettings) -> int:
    return problem.num_operating_points * settings.seeds


def _generation(problem: DesignProblem, settings: SteadySettings, us: np.ndarray) -> dict:
    """Simulate the statically feasible designs of `us` (scaled, (P, n)) in one engine call."""
    static = np.asarray(margins_batch(problem, jnp.asarray(us)))
    inside = np.all(static > 0, axis=1)
    n = len(us)
    row = dict(
        objective=np.full(n, np.nan),
        ci=np.full((n, 2), np.nan),
        violation=np.zeros(n),
        feasible=np.zeros(n, bool),
        simulated=inside,
        corner_risk=np.full(n, np.nan),
        simulated_ms=np.zeros(n),
    )
    state = np.random.get_state()  # the engine must not move the strategy's random stream
    evs = evaluate_starts(problem, settings, list(us[inside]), None, gradient=False) if inside.any() else []
    np.random.set_state(state)
    for i, ev in zip(np.flatnonzero(inside), evs):
        c, row["feasible"][i] = measured_constraints(problem, settings, us[i], ev)
        row["objective"][i], row["ci"][i] = ev.objective, ev.objective_ci
        row["violation"][i] = float(np.sum(np.minimum(c, 0.0) ** 2) ** 0.5)
        row["corner_risk"][i], row["simulated_ms"][i] = ev.corner_risk, ev.simulated_ms
    for i in np.flatnonzero(~inside):  # the static constraints alone (the dynamic one far off)
        c, _ = constraints(problem, us[i], 1.0, us[i])
        row["violation"][i] = float(np.sum(np.minimum(c, 0.0) ** 2) ** 0.5)
    return row


def _fitness(row: dict) -> np.ndarray:
    return np.where(row["feasible"], row["objective"], INFEASIBLE + row["violation"])


def _checked(problem, settings, method, budget_members, population):
    if method not in METHODS:
        raise UserInputError(f"method: {method!r}; valid: {', '.join(METHODS)}")
    if not (isinstance(population, int) and population >= 2):
        raise UserInputError(f"population: {population}; valid: an integer >= 2")
    per = _members_per_design(problem, settings)
    if not budget_members >= per:
        raise UserInputError(f"budget_members: {budget_members}; valid: >= {per} (one design's members)")


def _fixed(problem: DesignProblem) -> np.ndarray:
    return np.asarray(problem.bounds.upper - problem.bounds.lower) <= 0


class _Random:
    """Uniform draws in the box, one generation at a time (fixed variables at 0)."""

    def __init__(self, problem, seed, population, x0):
        self.rng, self.p, self.fixed = np.random.default_rng(seed), population, _fixed(problem)

    def ask(self) -> np.ndarray:
        u = self.rng.uniform(size=(self.p, len(self.fixed)))
        u[:, self.fixed] = 0.0
        return u

    def tell(self, us, fitness) -> None:
        pass


class _CMAES:
    """`cma.CMAEvolutionStrategy` on [0, 1]^n from the bearing's own design, step sigma0."""

    def __init__(self, problem, seed, population, x0, sigma0=0.3):
        import cma

        fixed = {int(i): 0.0 for i in np.flatnonzero(_fixed(problem))}
        # cma's seed 0 means "from the clock": seed + 1 keeps every run repeatable
        opts = dict(
            bounds=[0.0, 1.0], popsize=population, seed=seed + 1, verbose=-9, fixed_variables=fixed or None
        )
        self.es = cma.CMAEvolutionStrategy(list(np.clip(x0, 0.0, 1.0)), sigma0, opts)

    def ask(self) -> np.ndarray:
        return np.asarray(self.es.ask(), float)

    def tell(self, us, fitness) -> None:
        self.es.tell(list(us), list(map(float, fitness)))


@in_shared_pool
def gradient_free_search(
    problem: DesignProblem,
    settings: SteadySettings,
    method: str,
    budget_members: int,
    *,
    seed: int = 0,
    population: int = 6,
    directory: str | pathlib.Path | None = None,
    callback=None,
) -> GradientFreeResult:
    """Random search (`method="random"`) or CMA-ES (`"cmaes"`) on the settled objective until
    `budget_members` settled members are spent (the generation that crosses it finishes), a
    generation of `population` designs per engine call (module docstring). `callback(result)`
    after each generation; with `directory` a rerun resumes."""
    from ._search import start_points

    _checked(problem, settings, method, budget_members, population)
    t0 = time.perf_counter()
    x0 = start_points(problem, 1)[0]
    strategy = (_Random if method == "random" else _CMAES)(problem, seed, population, x0)
    key = f"{method}-{seed}-{population}"
    path = None if directory is None else pathlib.Path(directory) / _CHECKPOINT
    done = _stored(path, key)
    rows, us_all, spent = [], [], 0
    per = _members_per_design(problem, settings)
    while spent < budget_members:
        us = strategy.ask()
        row = done[len(rows)] if len(rows) < len(done) else _generation(problem, settings, us)
        strategy.tell(us, _fitness(row))
        rows.append(row)
        us_all.append(us)
        spent += per * int(np.sum(row["simulated"]))
        if path is not None and len(rows) > len(done):
            save_checkpoint(path, key, {str(i): r for i, r in enumerate(rows)})
        if callback is not None:
            callback(_result(problem, method, us_all, rows, per, t0))
    return _result(problem, method, us_all, rows, per, t0)


def _stored(path, key) -> list[dict]:
    if path is None or not path.exists():
        return []
    data = load_checkpoint(path)
    if not isinstance(data, dict) or data.get("fingerprint") != key:
        raise UserInputError(f"{path}: a checkpoint of another search; remove it to start afresh")
    state = data["state"]
    return [{k: np.asarray(v) for k, v in state[str(i)].items()} for i in range(len(state))]


def _result(problem, method, us_all, rows, per, t0) -> GradientFreeResult:
    us = np.concatenate(us_all)
    cat = {k: np.concatenate([r[k] for r in rows]) for k in rows[0]}
    x = np.stack([np.asarray(problem.bounds.from_scaled(jnp.asarray(u))) for u in us])
    return GradientFreeResult(
        method=method,
        x=x,
        objective=cat["objective"],
        ci=cat["ci"],
        feasible=cat["feasible"].astype(bool),
        simulated=cat["simulated"].astype(bool),
        corner_risk=cat["corner_risk"],
        members=np.cumsum(per * cat["simulated"].astype(int)),
        simulated_ms=float(np.sum(cat["simulated_ms"])),
        wall_time_s=time.perf_counter() - t0,
    )
