"""Input and output of parameters: the TOML configuration schema, validation, range checks.

Owns: every configuration key (path with unit, range, meaning; `KEYS`), reading and writing
TOML in engineering units (`Config`, `load_config`), validation of pytrees built in Python
(`validate_bearing`) and the range checks of SI entry-point arguments (`require`).

May import: `jaxbearing._errors`, `jaxbearing.geometry`.
"""

from ._checks import is_concrete, require
from ._config import (
    Config,
    SimulationSettings,
    load_config,
    loads_config,
    reference_bearing,
    reference_config,
    reference_operating_point,
)
from ._extras import optional_import, pyplot
from ._validation import KEY_BY_PATH, KEYS, format_value, type_name, validate_bearing

__all__ = [
    "KEYS",
    "KEY_BY_PATH",
    "Config",
    "SimulationSettings",
    "format_value",
    "is_concrete",
    "load_config",
    "loads_config",
    "optional_import",
    "pyplot",
    "reference_bearing",
    "reference_config",
    "reference_operating_point",
    "require",
    "type_name",
    "validate_bearing",
]
