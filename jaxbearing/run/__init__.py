"""Runs of the model: the solve, the simulation result, statistics, design metrics, plots.

- `solve` (pure, jit/vmap/grad-able diffrax integration of the scaled state), `simulate`
  (compiled, with wall times and a `SimulationResult`), `simulation_result`,
  `flange_functionals` (smooth peak PV and contact heights for gradients), `Perturbation`
  (seeded initial roller scatter), `initial_state`, `smooth_functionals`;
- statistics: `contact_events`, `summarise`; of settled running with 95 % confidence
  intervals: `steady_statistics`, `revolution_statistics`, `confidence_intervals`,
  `batch_means`, `student_t_interval`, `Estimate`;
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
from ._simulate import (
    Perturbation,
    SimulationResult,
    Solution,
    SolveArgs,
    flange_functionals,
    initial_state,
    scaled_field,
    simulate,
    simulation_result,
    smooth_functionals,
    solve,
)
from ._statistics import (
    Estimate,
    batch_means,
    confidence_intervals,
    revolution_statistics,
    steady_statistics,
    student_t_interval,
)
from ._summary import contact_events, summarise

__all__ = [
    "GRADIENT_ATOL",
    "GRADIENT_HORIZON",
    "GRADIENT_MODE_NOTE",
    "GRADIENT_RTOL",
    "DesignMetrics",
    "Estimate",
    "Perturbation",
    "SimulationResult",
    "Solution",
    "SolveArgs",
    "batch_means",
    "confidence_intervals",
    "contact_events",
    "design_jacobian",
    "design_metrics",
    "flange_functionals",
    "forward_jacobian",
    "initial_state",
    "plot_run",
    "revolution_statistics",
    "scaled_field",
    "seated_perturbation",
    "simulate",
    "simulation_result",
    "smooth_functionals",
    "solve",
    "steady_statistics",
    "student_t_interval",
    "summarise",
]
