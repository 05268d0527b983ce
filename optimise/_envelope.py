"""The envelope's active set of the design search on steady running: which operating points the
next evaluation of a start simulates, and what it keeps of the others (docs/model.md 17)."""

from __future__ import annotations

import dataclasses

import jax
import numpy as np

from ._evaluate import Evaluation, PointRecord, Previous
from ._problem import DesignProblem
from ._settings import CORNER_WATCH, SteadySettings


def next_active(problem: DesignProblem, settings: SteadySettings, ev: Evaluation, since) -> list[bool]:
    """Which operating points the next evaluation of a start simulates (the envelope's active
    set), from its last evaluation `ev` and `since[k]`, the iterations since point k was last
    simulated. With the smooth max (weights exp(J_k / T), docs/model.md 17) a point whose upper
    95 % bound J_k^hi is so far below the worst point's lower bound J_w^lo that its weight
    w_k exp((J_k^hi - J_w^lo) / T) stays below `settings.skip_weight` adds less than that share to
    the objective and its gradient: it is left out, unless its dynamic corner margin is within
    `CORNER_WATCH` of zero and within `corner_margin` of the smallest (the constraint may bind
    there within a step), or it was last simulated `settings.recheck_every` iterations ago.
    Every point is simulated with the weighted mean, or with `skip_weight` 0."""
    n = problem.num_operating_points
    if problem.aggregate != "max" or settings.skip_weight <= 0 or n == 1:
        return [True] * n
    w = np.asarray(problem.weights, float) / float(np.sum(problem.weights))
    hi = np.array([p.ci[1] for p in ev.per_point], float)
    lo = np.array([p.ci[0] for p in ev.per_point], float)
    values = np.array([p.value for p in ev.per_point], float)
    margins = np.array([p.corner_margin for p in ev.per_point], float)
    if not (np.all(np.isfinite(hi)) and np.all(np.isfinite(lo)) and np.all(np.isfinite(margins))):
        return [True] * n
    worst = int(np.argmax(values))
    bound = w * np.exp(np.minimum((hi - lo[worst]) / problem.temperature, 0.0))
    near_corner = (margins <= margins.min() + settings.corner_margin) & (margins < CORNER_WATCH)
    due = np.asarray(since) + 1 >= settings.recheck_every
    keep = (bound >= settings.skip_weight) | near_corner | due
    keep[worst] = True
    return [bool(v) for v in keep]


@jax.tree_util.register_dataclass
@dataclasses.dataclass
class Envelope:
    """Per start and operating point (arrays of shape (starts, points, ...), for the
    checkpoint): the active set (`next_active`), the iterations since each point was simulated,
    and what was last measured there (the fields of `PointRecord`)."""

    active: np.ndarray
    since: np.ndarray
    value: np.ndarray
    ci: np.ndarray
    gradient: np.ndarray
    gradient_stderr: np.ndarray
    corner_margin: np.ndarray
    measured_at: np.ndarray
    share: np.ndarray
    settled: np.ndarray
    risk: np.ndarray
    film: np.ndarray  # the lower bound of Lambda's 5th percentile (`PointRecord`)
    flash: np.ndarray  # the upper bound of the largest flash temperature rise [K]
    friction: np.ndarray  # the upper bound of the total flange friction power [W]

    @classmethod
    def fresh(cls, num_starts: int, num_points: int, num_variables: int = 3) -> Envelope:
        """Every point active, nothing measured."""
        shape = (num_starts, num_points)
        nan = np.full(shape, np.nan)
        return cls(
            active=np.ones(shape, bool),
            since=np.zeros(shape, np.int64),
            value=nan.copy(),
            ci=np.full(shape + (2,), np.nan),
            gradient=np.zeros(shape + (num_variables,)),
            gradient_stderr=np.zeros(shape + (num_variables,)),
            corner_margin=nan.copy(),
            measured_at=np.zeros(shape + (num_variables,)),
            share=nan.copy(),
            settled=np.zeros(shape, bool),
            risk=nan.copy(),
            film=nan.copy(),
            flash=nan.copy(),
            friction=nan.copy(),
        )

    def record(self, problem: DesignProblem, settings: SteadySettings, s: int, ev: Evaluation) -> None:
        """Store start `s`'s simulated points of `ev` and choose its next active set."""
        for k, p in enumerate(ev.per_point):
            if not p.simulated:
                self.since[s, k] += 1
                continue
            self.since[s, k] = 0
            self.value[s, k], self.ci[s, k] = p.value, p.ci
            self.gradient[s, k], self.gradient_stderr[s, k] = p.gradient, p.gradient_stderr
            self.corner_margin[s, k], self.measured_at[s, k] = p.measured_corner_margin, p.measured_at
            self.share[s, k], self.settled[s, k] = p.corner_contact_share, p.settled
            self.risk[s, k] = p.corner_risk
            self.film[s, k], self.flash[s, k] = p.film_parameter_low, p.flash_temperature_high
            self.friction[s, k] = p.friction_power_high
        self.active[s] = next_active(problem, settings, ev, self.since[s])

    def previous(self, s: int, states) -> Previous | None:
        """Start `s`'s last measurements at every operating point (`evaluate_starts`'
        `previous`), None before its first evaluation."""
        if states is None:
            return None
        per = [
            PointRecord(
                value=float(self.value[s, k]),
                ci=tuple(float(v) for v in self.ci[s, k]),
                gradient=np.array(self.gradient[s, k]),
                gradient_stderr=np.array(self.gradient_stderr[s, k]),
                corner_margin=float(self.corner_margin[s, k]),
                measured_corner_margin=float(self.corner_margin[s, k]),
                measured_at=np.array(self.measured_at[s, k]),
                corner_contact_share=float(self.share[s, k]),
                settled=bool(self.settled[s, k]),
                simulated=False,
                corner_risk=float(self.risk[s, k]),
                film_parameter_low=float(self.film[s, k]),
                flash_temperature_high=float(self.flash[s, k]),
                friction_power_high=float(self.friction[s, k]),
            )
            for k in range(self.value.shape[1])
        ]
        return Previous(per, list(states))
