"""The projected augmented-Lagrangian step both design searches take (start-up objective in
`_search`, steady running in `_steady`): minimise J(u) subject to c_i(u) >= 0 in the unit box.

With multipliers lambda >= 0 and penalty rho, the gradient of the augmented Lagrangian
(Nocedal & Wright 2006, Numerical Optimization, 2nd ed., sec. 17.4, inequality constraints) is

    g = dJ/du - sum_i max(0, lambda_i - rho c_i) dc_i/du,

the step is optax's Adam update of g (a cosine-decayed step size), the iterate is projected
onto the box [0, 1]^3, and the multipliers become lambda_i <- max(0, lambda_i - rho c_i).
Components of u whose bounds coincide (a fixed variable) do not move.
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax.numpy as jnp
import numpy as np
import optax


@dataclasses.dataclass(frozen=True)
class Hyper:
    """Static hyperparameters of a search (hashable: part of the compile-cache key)."""

    learning_rate: float
    num_iterations: int
    rho: float

    def optimiser(self) -> optax.GradientTransformation:
        """Adam with a cosine-decayed step size (to 10% at the last iteration)."""
        schedule = optax.cosine_decay_schedule(self.learning_rate, self.num_iterations, alpha=0.1)
        return optax.adam(schedule)


def augmented_lagrangian_step(optimiser, rho: float, free, g_obj, c, jc, lam, opt_state, u):
    """One step (module docstring) from the scaled design `u`: the objective's gradient
    `g_obj` (n,), the scaled constraints `c` (m,) and their Jacobian `jc` (m, n), the
    multipliers `lam` (m,), the optimiser's state; `free` (n,) marks the variables that move.
    Returns the projected next iterate, the optimiser's next state and the next multipliers.
    Pure jax.numpy: traced and vmapped in `_search`, called eagerly in `_steady`."""
    act = jnp.maximum(0.0, lam - rho * c)
    g = jnp.where(free, g_obj - act @ jc, 0.0)
    updates, opt_state = optimiser.update(g, opt_state, u)
    return jnp.clip(optax.apply_updates(u, updates), 0.0, 1.0), opt_state, act


class IterationReport(NamedTuple):
    """What a search reports to its callback after every iteration, per start."""

    x: np.ndarray  # (S, 3) designs [SI]
    objective: np.ndarray  # (S,) [GPa m/s]
    margins: np.ndarray  # (S, m) [m]
    best: float  # the best feasible objective so far (inf: none yet)
    ci: list | None = None  # per start (low, high) [GPa m/s] (steady running)
    gradient: np.ndarray | None = None  # (S, 3) per unit box (steady running)
    feasible: np.ndarray | None = None  # (S,) (start-up objective)
