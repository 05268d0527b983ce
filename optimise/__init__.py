"""optimise: gradient-based design of roller ends and flanges on top of jaxbearing.

Minimise the smooth peak flange PV of arc-end rollers over the end radius R_end, the flange
layback angle theta_f and the axial clearance Delta_bf, inside the design zone (relief, height
limit, limited circle, actual axial clearance), robustly over an envelope of speeds and loads.
The search is a multi-start projected augmented Lagrangian driven by optax (`_search`); the
objective's gradients come from forward-mode differentiation through the diffrax solve
(`jaxbearing.design.design_metrics`). The search on settled running, `steady_search`, takes one
`SteadySettings`; its choices are typed: `Statistic` (the PV statistic minimised), `Estimator`
(the gradient estimate), `CornerConstraint` (the dynamic corner constraint) and `Choice` (which
of the tied designs is returned); the command line and the TOML files name them by their values.
`held_load_search` minimises the held-load objective of settled contacts by SLSQP, settles the
result and repeats (`HeldLoadResult`).
Command line: `optimise run --help`.
"""

import jaxbearing  # noqa: F401  (enables 64-bit floats)
from jaxbearing.design import Statistic
from jaxbearing.flange import MARGIN_NAMES

from ._gradient_free import GradientFreeResult, gradient_free_search
from ._grid import steady_grid
from ._held_load import HeldLoadResult, held_load_search
from ._plot import plot_search
from ._problem import (
    Bounds,
    DesignProblem,
    ProfileBounds,
    any_feasible,
    bounds_from_engineering,
    feasibility_map,
    make_problem,
    operating_envelope,
)
from ._search import SearchResult, grid_search, search, start_points
from ._settings import Choice, CornerConstraint, Estimator, SteadySettings
from ._steady import NearOptimal, SteadySearchResult, near_optimal_set, steady_search
from ._toml import load_optimise_toml
from ._verify import TailVerification, Verification, VerifiedPoint, verification

__all__ = [
    "MARGIN_NAMES",
    "HeldLoadResult",
    "held_load_search",
    "Bounds",
    "ProfileBounds",
    "Choice",
    "CornerConstraint",
    "Estimator",
    "Statistic",
    "DesignProblem",
    "GradientFreeResult",
    "NearOptimal",
    "SearchResult",
    "SteadySearchResult",
    "SteadySettings",
    "TailVerification",
    "Verification",
    "VerifiedPoint",
    "any_feasible",
    "bounds_from_engineering",
    "feasibility_map",
    "gradient_free_search",
    "grid_search",
    "load_optimise_toml",
    "make_problem",
    "near_optimal_set",
    "operating_envelope",
    "plot_search",
    "search",
    "start_points",
    "steady_grid",
    "steady_search",
    "verification",
]
