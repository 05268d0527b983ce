"""Design: metrics of a roller-end/flange design and their gradients through the dynamics.

- short runs, differentiable (docs/model.md 13 and 14): `design_metrics` (smooth peak flange PV and
  contact heights of a run, the static design-zone margins), `design_jacobian` (their Jacobian
  with respect to the design, forward mode by default, `GRADIENT_MODE_NOTE`), `DesignMetrics`,
  `seated_perturbation` (the initial scatter that starts every roller at zero interference with
  its flange), `forward_jacobian`, and the gradient check's `GRADIENT_HORIZON`,
  `GRADIENT_RTOL`, `GRADIENT_ATOL`;
- settled running (docs/model.md 17): `steady_design_metrics` (and `steady_design_metrics_points`,
  a whole envelope in one engine call; the steady-running design
  objective: mean and p95 PV over contact time, corner share and margin, static margins, with
  95 % intervals over seeds; continuation from given states), `SteadyDesignMetrics`,
  `CORNER_MARGIN`;
- its gradient: `steady_gradient` (an ensemble of short-window forward-mode sensitivities from
  settled states, `GRADIENT_WINDOW`), `frozen_load_gradient` (`frozen_load_gradients`: many cases, one call; `frozen_load_statistics`: several statistics from the same trajectories), `ratio_gradient`, `paired_central_difference` (common-random-number differences),
  `SteadyGradient`, `tangent_growth` (finite-time growth of the tangents) and the smooth
  accumulators they differentiate, `STEADY_FUNCTIONALS` (`STATISTICS`, by `Statistic`: the mean, the
  peak statistic's p-mean with p = `PEAK_EXPONENT`, the tail mean, and the time-mean flange
  friction power, `FRICTION_REFERENCE`).
- the held-load objective (docs/model.md 17): `held_readouts` (mean and peak PV and the corner
  distance of any design at the poses and loads of one design's settled running, `HeldReadouts`:
  deterministic, differentiable, without dynamics), `held_contacts` (those contacts,
  `HeldContacts`, from saved states of `trajectory_states`).

- which uncertain inputs matter (docs/model.md 18): `sensitivity` (the effect, derivative x
  stated uncertainty, of every `[uncertainty]` key and `MODEL_CONSTANTS` entry on settled
  statistics, `SENSITIVITY_STATISTICS`, by the methods `SENSITIVITY_METHODS`: CRN central
  differences of settled runs, or the static skid equilibrium for the cage slip), `Sensitivity`,
  `SensitivityInput`, `Effect`, `sensitivity_inputs`, `static_cage_slip`,
  `parse_sensitivity_statistics`.
- designs robust to the model's constants: `robustness` (a design against a reference at every
  corner of the uncertain constants' ranges, `ROBUSTNESS_CONSTANTS`, and every operating point,
  settled on the caller's seeds: mean and peak PV with 95 % intervals and whether the design's
  lies below), `Robustness`, `RobustnessRow`, `RobustnessCorner`, `robustness_corners`,
  `write_robustness_json`.

The `optimise` package searches designs with these.

May import: every layer below (`run` and down); `run` only through its public names.
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
from ._frozen_load import (
    frozen_load_gradient,
    frozen_load_gradients,
    frozen_load_statistics,
    trajectory_states,
)
from ._held_load import HeldContacts, HeldReadouts, held_contacts, held_readouts
from ._robustness import (
    ROBUSTNESS_CONSTANTS,
    Robustness,
    RobustnessCorner,
    RobustnessRow,
    robustness,
    robustness_corners,
    write_robustness_json,
)
from ._sensitivity import METHODS as SENSITIVITY_METHODS
from ._sensitivity import (
    MODEL_CONSTANTS,
    Effect,
    Sensitivity,
    SensitivityInput,
    sensitivity,
    sensitivity_inputs,
    static_cage_slip,
)
from ._sensitivity import STATISTICS as SENSITIVITY_STATISTICS
from ._sensitivity import parse_statistics as parse_sensitivity_statistics
from ._steady_design import (
    CORNER_MARGIN,
    SteadyDesignMetrics,
    steady_design_metrics,
    steady_design_metrics_points,
)
from ._steady_objective import (
    FRICTION_REFERENCE,
    GRADIENT_WINDOW,
    PEAK_EXPONENT,
    STATISTICS,
    STEADY_FUNCTIONALS,
    Statistic,
    SteadyGradient,
    paired_central_difference,
    ratio_gradient,
)
from ._window_gradient import steady_gradient, tangent_growth

__all__ = [
    "CORNER_MARGIN",
    "GRADIENT_ATOL",
    "GRADIENT_HORIZON",
    "GRADIENT_MODE_NOTE",
    "GRADIENT_RTOL",
    "GRADIENT_WINDOW",
    "MODEL_CONSTANTS",
    "FRICTION_REFERENCE",
    "PEAK_EXPONENT",
    "ROBUSTNESS_CONSTANTS",
    "SENSITIVITY_METHODS",
    "SENSITIVITY_STATISTICS",
    "STATISTICS",
    "Statistic",
    "STEADY_FUNCTIONALS",
    "DesignMetrics",
    "Robustness",
    "RobustnessCorner",
    "RobustnessRow",
    "Effect",
    "Sensitivity",
    "SensitivityInput",
    "SteadyDesignMetrics",
    "SteadyGradient",
    "design_jacobian",
    "design_metrics",
    "forward_jacobian",
    "frozen_load_gradient",
    "HeldContacts",
    "HeldReadouts",
    "held_contacts",
    "held_readouts",
    "trajectory_states",
    "frozen_load_gradients",
    "frozen_load_statistics",
    "paired_central_difference",
    "parse_sensitivity_statistics",
    "ratio_gradient",
    "robustness",
    "robustness_corners",
    "seated_perturbation",
    "sensitivity",
    "sensitivity_inputs",
    "static_cage_slip",
    "steady_design_metrics",
    "steady_design_metrics_points",
    "steady_gradient",
    "tangent_growth",
    "write_robustness_json",
]
