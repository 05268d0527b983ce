"""Input and output of parameters: the TOML configuration schema, validation, range checks.

Owns: every configuration key (path with unit, range, meaning; `KEYS`), reading and writing
TOML in engineering units (`Config`, `load_config`), validation of pytrees built in Python
(`validate_bearing`), the range checks of SI entry-point arguments (`require`, the table of
solver arguments `SOLVER_ARGUMENTS` and `check_solver_arguments`, `check_solve_inputs` that
every model entry point calls before tracing), the checks a configuration needs to be run
(`check_runnable`), and result files that are whole or absent, in strict JSON (`atomic_write`,
`write_json`, `dumps_strict`), pytrees in data-only files (`save_tree`, `load_tree`: `.npz`
with `allow_pickle=False` and JSON, never a pickle), the lock on an output directory (`acquire_lock`), and output directories checked before
work and results kept in a fallback directory when writing fails (`check_output_dir`,
`write_or_fallback`), measured cage speeds from a CSV file with units in its header
(`read_cage_speed_measurements`), the `[uncertainty]` table of values known only roughly
(`Uncertainty`, `Config.uncertainty`), and a configuration of a catalogue bearing estimated
from its boundary dimensions (`estimate_config`, the ISO 15 table `dimension_series`).

May import: `jaxbearing._errors`, `jaxbearing.geometry`.
"""

from ._checks import (
    FUNCTIONALS_FIELDS,
    PERTURBATION_FIELDS,
    SIMULATE_NUM_SAVES,
    SOLVER_ARGUMENTS,
    Rule,
    check_arguments,
    check_fields,
    check_model_inputs,
    check_solve_inputs,
    check_solver_arguments,
    count,
    is_concrete,
    per_point,
    real,
    require,
)
from ._config import (
    Config,
    SimulationSettings,
    check_runnable,
    load_config,
    loads_config,
    reference_bearing,
    reference_config,
    reference_operating_point,
)
from ._estimate import (
    BEARING_TYPES,
    DIMENSION_SERIES,
    BoundaryDimensions,
    EstimatedConfig,
    dimension_series,
    estimate_config,
)
from ._extras import optional_import, pyplot
from ._files import (
    NULL_REASONS,
    atomic_write,
    check_output_dir,
    dumps_strict,
    fallback_dir,
    finite_or_none,
    provenance,
    remove_stale_temporaries,
    set_command_line,
    to_strict_json,
    unit_of,
    units_of,
    with_null_reasons,
    write_json,
    write_or_fallback,
)
from ._keys import format_value, type_name
from ._lock import DirectoryInUse, DirectoryLock, acquire_lock
from ._measurements import CageSpeedMeasurement, read_cage_speed_measurements
from ._schema import KEY_BY_PATH, KEYS
from ._tree import TreeFileError, check_like, load_tree, save_tree, tree_bytes, tree_from_bytes
from ._uncertainty import Uncertainty
from ._validation import IMPLAUSIBLY_SMALL, plausibility_warnings, validate_bearing

__all__ = [
    "BEARING_TYPES",
    "BoundaryDimensions",
    "DIMENSION_SERIES",
    "EstimatedConfig",
    "Uncertainty",
    "dimension_series",
    "estimate_config",
    "CageSpeedMeasurement",
    "FUNCTIONALS_FIELDS",
    "IMPLAUSIBLY_SMALL",
    "KEYS",
    "KEY_BY_PATH",
    "NULL_REASONS",
    "PERTURBATION_FIELDS",
    "SIMULATE_NUM_SAVES",
    "SOLVER_ARGUMENTS",
    "Config",
    "DirectoryInUse",
    "DirectoryLock",
    "Rule",
    "SimulationSettings",
    "TreeFileError",
    "acquire_lock",
    "atomic_write",
    "read_cage_speed_measurements",
    "check_arguments",
    "check_fields",
    "check_like",
    "check_model_inputs",
    "check_output_dir",
    "check_runnable",
    "check_solve_inputs",
    "check_solver_arguments",
    "count",
    "dumps_strict",
    "fallback_dir",
    "finite_or_none",
    "format_value",
    "is_concrete",
    "load_config",
    "load_tree",
    "loads_config",
    "optional_import",
    "plausibility_warnings",
    "provenance",
    "pyplot",
    "real",
    "reference_bearing",
    "reference_config",
    "reference_operating_point",
    "remove_stale_temporaries",
    "per_point",
    "require",
    "save_tree",
    "set_command_line",
    "to_strict_json",
    "tree_bytes",
    "tree_from_bytes",
    "type_name",
    "unit_of",
    "units_of",
    "validate_bearing",
    "with_null_reasons",
    "write_json",
    "write_or_fallback",
]
