"""Runs of the model: the solve, the simulation result, statistics, design metrics, plots.

- `solve` (pure, jit/vmap/grad-able diffrax integration of the scaled state), `simulate`
  (compiled, with wall times and a `SimulationResult`), `simulation_result`,
  `flange_functionals` (smooth peak PV and contact heights for gradients), `Perturbation`
  (seeded initial roller scatter), `initial_state`, `smooth_functionals`;
- statistics: `contact_events`, `summarise`;
- design metrics through the dynamics: `design_metrics`, `design_jacobian`, `DesignMetrics`,
  `seated_perturbation`, `forward_jacobian`;
- `plot_run`: the figures of one run;
- speed: `raceway_normal_norm` (the error norm of `solve`), `enable_compilation_cache` (JAX's
  persistent cache in a user directory, `$JAXBEARING_CACHE_DIR`; on at import),
  `parallel_map` / `simulate_ensemble` (independent cases, one process per core).

May import: `jaxbearing._errors`, `contact`, `geometry`, `io`, `flange`, `forces`, `dynamics`.
"""

from ._compile_cache import CACHE_ENV, enable_compilation_cache
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
from ._ensemble import parallel_map, simulate_ensemble
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
from ._step_control import RACEWAY_NORMAL_LOOSEN, RacewayNormalNorm, raceway_normal_norm
from ._summary import contact_events, summarise

__all__ = [
    "CACHE_ENV",
    "RACEWAY_NORMAL_LOOSEN",
    "RacewayNormalNorm",
    "enable_compilation_cache",
    "parallel_map",
    "raceway_normal_norm",
    "simulate_ensemble",
    "GRADIENT_ATOL",
    "GRADIENT_HORIZON",
    "GRADIENT_MODE_NOTE",
    "GRADIENT_RTOL",
    "DesignMetrics",
    "Perturbation",
    "SimulationResult",
    "Solution",
    "SolveArgs",
    "contact_events",
    "design_jacobian",
    "design_metrics",
    "flange_functionals",
    "forward_jacobian",
    "initial_state",
    "plot_run",
    "scaled_field",
    "seated_perturbation",
    "simulate",
    "simulation_result",
    "smooth_functionals",
    "solve",
    "summarise",
]
