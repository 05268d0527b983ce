"""jaxbearing: a differentiable dynamic model of cylindrical roller bearings in JAX.

64-bit floats are switched on at import: contact interferences are micrometres on millimetre
geometry, and gradients through long integrations need the precision.

Layers (imports point down only; `docs/architecture.md`):

    cli       the `jaxbearing` command line, one module per command
    sweep     sweep specs, batched and sharded execution, storage, dataset, plots
    design    design metrics and their gradients through the dynamics, steady-running objective
    run       solve / simulate, statistics, settled running, ensembles, plots
    dynamics  state layout, rigid bodies, the vector field, the quasi-static start
    flange    the roller-end/flange model: contact, static design zone, design variables
    forces    the other body pairs: raceway, pocket, cage lands, drag
    io        configuration schema (TOML, engineering units), validation, range checks
    geometry  parameter pytrees, mass properties, the roller end body
    contact   contact laws: Hertz point and line contact, smoothing, traction
    _errors   the exceptions every layer raises

The names below are the public API; each subpackage's `__init__` lists what it offers.
"""

import jax

jax.config.update("jax_enable_x64", True)

from ._errors import ConfigError, UserInputError  # noqa: E402
from .design import (  # noqa: E402
    DesignMetrics,
    design_jacobian,
    design_metrics,
    seated_perturbation,
    steady_design_metrics,
)
from .dynamics import Functionals, QuasiStatic, quasi_static  # noqa: E402
from .flange import (  # noqa: E402
    DesignVariables,
    DesignZone,
    design_zone,
    design_zone_grid,
    zone_margins,
)
from .forces import RacewayContact, raceway_contact  # noqa: E402
from .geometry import (  # noqa: E402
    Bearing,
    Cage,
    Flange,
    Lubricant,
    Material,
    OperatingPoint,
    Roller,
    kinematic_cage_speed,
    rad_s_to_rpm,
    rpm_to_rad_s,
)
from .io import (  # noqa: E402
    Config,
    SimulationSettings,
    load_config,
    loads_config,
    reference_bearing,
    reference_config,
    reference_operating_point,
    validate_bearing,
)
from .run import (  # noqa: E402
    Perturbation,
    SimulationResult,
    Solution,
    SteadyResult,
    contact_events,
    enable_compilation_cache,
    flange_functionals,
    simulate,
    simulate_steady,
    solve,
    summarise,
    summarise_steady,
)
from .sweep import (  # noqa: E402
    SweepSpec,
    SweepSpecError,
    load_sweep_spec,
    loads_sweep_spec,
    open_results,
    run_sweep,
)

__version__ = "0.4.0"

__all__ = [
    # parameters (docs/model.md 1)
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
    # configuration and errors
    "Config",
    "ConfigError",
    "SimulationSettings",
    "UserInputError",
    "load_config",
    "loads_config",
    "reference_config",
    "validate_bearing",
    # roller-end/flange design zone (docs/model.md 5; the paper's Figure 14)
    "DesignZone",
    "design_zone",
    "design_zone_grid",
    # roller-raceway contact (docs/model.md 8) and the quasi-static start (docs/model.md 12)
    "QuasiStatic",
    "RacewayContact",
    "quasi_static",
    "raceway_contact",
    # dynamics and runs
    "Functionals",
    "Perturbation",
    "SimulationResult",
    "Solution",
    "contact_events",
    "flange_functionals",
    "SteadyResult",
    "simulate",
    "simulate_steady",
    "steady_design_metrics",
    "solve",
    "summarise",
    "summarise_steady",
    # parameter sweeps
    "SweepSpec",
    "SweepSpecError",
    "load_sweep_spec",
    "loads_sweep_spec",
    "open_results",
    "run_sweep",
    # design
    "DesignMetrics",
    "DesignVariables",
    "design_jacobian",
    "design_metrics",
    "seated_perturbation",
    "zone_margins",
    # speed
    "enable_compilation_cache",
]

#: the persistent compilation cache (`run._compile_cache`): `$JAXBEARING_CACHE_DIR`, or
#: ~/.cache/jaxbearing/xla; JAXBEARING_CACHE_DIR=off switches it off
COMPILATION_CACHE_DIR = enable_compilation_cache()
