"""Contact-mechanics primitives: Hertz point contact, sliced line contact, smoothing, traction.

Pure functions of geometry and loads, broadcasting over leading axes, in SI units, and
jit/vmap/grad-friendly: every law is smoothed so that values, gradients and Hessians are finite
at, below and above zero penetration and at zero sliding (MODEL.md section 4).

- Point contact (Hamrock & Brewe 1983): `effective_modulus`, `point_contact_stiffness`,
  `point_contact_ellipse`, `point_contact_peak_pressure`, `point_contact_deflection`,
  `hamrock_brewe_parameters`.
- Line contact (ISO/TS 16281, MODEL.md 4.2): `line_contact_stiffness`, `line_slice_loads`,
  `line_power` (the slice law's power with a hand-written tangent).
- Smoothing: `smooth_penetration`, `smooth_power`, `hertz_force`, `safe_norm`,
  `smooth_direction`.
- Traction and friction: `traction_coefficient`, `traction_force`, `friction_force`.
"""

from ._hertz import (
    HAMROCK_BREWE_ERROR,
    LOAD_FLOOR,
    MAX_CURVATURE_RATIO,
    effective_modulus,
    hamrock_brewe_parameters,
    point_contact_deflection,
    point_contact_ellipse,
    point_contact_peak_pressure,
    point_contact_stiffness,
)
from ._line import (
    ISO_LINE_CONSTANT,
    LINE_EXPONENT,
    STEEL_E_PRIME,
    STEEL_ELASTIC_MODULUS,
    STEEL_POISSON_RATIO,
    line_contact_stiffness,
    line_power,
    line_slice_loads,
)
from ._smooth import (
    PENETRATION_WIDTH,
    SLIDING_EPS,
    hertz_force,
    log_smooth_penetration,
    safe_norm,
    smooth_direction,
    smooth_penetration,
    smooth_power,
)
from ._traction import friction_force, traction_coefficient, traction_force

__all__ = [
    "HAMROCK_BREWE_ERROR",
    "ISO_LINE_CONSTANT",
    "LINE_EXPONENT",
    "LOAD_FLOOR",
    "MAX_CURVATURE_RATIO",
    "PENETRATION_WIDTH",
    "SLIDING_EPS",
    "STEEL_ELASTIC_MODULUS",
    "STEEL_E_PRIME",
    "STEEL_POISSON_RATIO",
    "effective_modulus",
    "friction_force",
    "hamrock_brewe_parameters",
    "hertz_force",
    "line_contact_stiffness",
    "line_power",
    "line_slice_loads",
    "log_smooth_penetration",
    "point_contact_deflection",
    "point_contact_ellipse",
    "point_contact_peak_pressure",
    "point_contact_stiffness",
    "safe_norm",
    "smooth_direction",
    "smooth_penetration",
    "smooth_power",
    "traction_coefficient",
    "traction_force",
]
