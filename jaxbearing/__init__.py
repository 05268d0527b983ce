"""jaxbearing: a differentiable dynamic model of cylindrical roller bearings in JAX.

64-bit floats are switched on at import: contact interferences are micrometres on millimetre
geometry, and gradients through long integrations need the precision.
"""

import jax

jax.config.update("jax_enable_x64", True)

from ._params import (  # noqa: E402
    Bearing,
    Cage,
    Flange,
    Lubricant,
    Material,
    OperatingPoint,
    Roller,
    kinematic_cage_speed,
    rad_s_to_rpm,
    reference_bearing,
    reference_operating_point,
    rpm_to_rad_s,
)

from ._config import Config, SimulationSettings, load_config, loads_config, reference_config  # noqa: E402
from ._errors import ConfigError, UserInputError  # noqa: E402
from ._validation import validate_bearing  # noqa: E402

__version__ = "0.1.0"

__all__ = [
    "Bearing",
    "Cage",
    "Flange",
    "Lubricant",
    "Material",
    "OperatingPoint",
    "Roller",
    "kinematic_cage_speed",
    "rad_s_to_rpm",
    "reference_bearing",
    "reference_operating_point",
    "rpm_to_rad_s",
    "Config",
    "ConfigError",
    "SimulationSettings",
    "UserInputError",
    "load_config",
    "loads_config",
    "reference_config",
    "validate_bearing",
]

# roller-end/flange design zone (MODEL.md 4.1; the paper's Figure 14)
from ._zone import DesignZone, design_zone, design_zone_grid  # noqa: E402

__all__ += ["DesignZone", "design_zone", "design_zone_grid"]

# roller-raceway sliced contact (MODEL.md 4.2) and the quasi-static initial solution (MODEL.md 5)
from ._quasistatic import QuasiStatic, quasi_static  # noqa: E402
from ._raceway import RacewayContact, raceway_contact  # noqa: E402

__all__ += ["QuasiStatic", "RacewayContact", "quasi_static", "raceway_contact"]

from ._dynamics import Functionals  # noqa: E402
from ._simulate import (  # noqa: E402
    Perturbation,
    SimulationResult,
    Solution,
    flange_functionals,
    simulate,
    solve,
)
from ._summary import contact_events, summarise  # noqa: E402

__all__ += [
    "Functionals",
    "Perturbation",
    "SimulationResult",
    "Solution",
    "contact_events",
    "flange_functionals",
    "simulate",
    "solve",
    "summarise",
]

# parameter sweeps: vmapped, sharded, resumable batches with labelled results (issue 6)
from ._sweep import (  # noqa: E402
    SweepSpec,
    SweepSpecError,
    load_sweep_spec,
    loads_sweep_spec,
    open_results,
    run_sweep,
)

__all__ += ["SweepSpec", "SweepSpecError", "load_sweep_spec", "loads_sweep_spec", "open_results", "run_sweep"]

# differentiable design metrics of the roller end and flange (issue 5)
from ._design import (  # noqa: E402
    DesignMetrics,
    DesignVariables,
    design_jacobian,
    design_metrics,
    seated_perturbation,
    zone_margins,
)

__all__ += [
    "DesignMetrics",
    "DesignVariables",
    "design_jacobian",
    "design_metrics",
    "seated_perturbation",
    "zone_margins",
]
