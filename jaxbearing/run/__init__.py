"""Runs of the model: the solve, the simulation result, statistics, design metrics, plots.

- `solve` (pure, jit/vmap/grad-able diffrax integration of the scaled state), `simulate`
  (compiled, with wall times and a `SimulationResult`), `simulation_result`,
  `flange_functionals` (smooth peak PV and contact heights for gradients), `Perturbation`
  (seeded initial roller scatter), `initial_state`, `smooth_functionals`, `result_code` and
  `RESULT_NAMES` (the outcome code of a solve), `SolveProgress` (the text progress meter);
- statistics: `contact_events`, `summarise`;
- design metrics through the dynamics: `design_metrics`, `design_jacobian`, `DesignMetrics`,
  `seated_perturbation`, `forward_jacobian`;
- `plot_run`: the figures of one run.

May import: `jaxbearing._errors`, `contact`, `geometry`, `io`, `flange`, `forces`, `dynamics`.
"""

from ._design import (
    GRADIENT_ATOL,
    GRADIENT_HORIZON,
    GRADIENT_MODE_NOTE,
    GRADIENT_RTOL,
    DesignMetrics,
    design_jacobian,
    design_metrics,
    forward_jacobian,
    seated_perturbation,
)
from ._plots import plot_run
from ._progress import SolveProgress
from ._simulate import (
    RESULT_NAMES,
    Perturbation,
    SimulationResult,
    Solution,
    SolveArgs,
    flange_functionals,
    initial_state,
    result_code,
    scaled_field,
    simulate,
    simulation_result,
    smooth_functionals,
    solve,
)
from ._summary import contact_events, summarise

__all__ = [
    "RESULT_NAMES",
    "GRADIENT_ATOL",
    "GRADIENT_HORIZON",
    "GRADIENT_MODE_NOTE",
    "GRADIENT_RTOL",
    "DesignMetrics",
    "Perturbation",
    "SimulationResult",
    "Solution",
    "SolveProgress",
    "SolveArgs",
    "contact_events",
    "design_jacobian",
    "design_metrics",
    "flange_functionals",
    "forward_jacobian",
    "initial_state",
    "plot_run",
    "result_code",
    "scaled_field",
    "seated_perturbation",
    "simulate",
    "simulation_result",
    "smooth_functionals",
    "solve",
    "summarise",
]
