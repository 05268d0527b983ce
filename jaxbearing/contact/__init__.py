"""Contact-mechanics primitives: Hertz and line contact, smoothing, damping, traction.

Pure functions of geometry and loads, broadcasting over leading axes, in SI units, and
jit/vmap/grad-friendly: every law is smoothed so that values, gradients and Hessians are finite
at, below and above zero penetration and at zero sliding (MODEL.md section 4).

- Point contact, exact Hertz solution (Johnson 1985, sec. 4.2): `effective_modulus`,
  `point_contact_stiffness`, `point_contact_ellipse`, `point_contact_peak_pressure`,
  `point_contact_deflection`, `point_contact_ellipticity`, `point_contact_parameters`,
  `complete_elliptic_integrals`; the Hamrock & Brewe (1983) fit for comparison:
  `hamrock_brewe_parameters`.
- Line contact (ISO/TS 16281, MODEL.md 4.2): `line_contact_stiffness`, `line_slice_loads`.
- Smoothing: `smooth_penetration`, `smooth_power`, `hertz_force`, `safe_norm`,
  `smooth_direction`.
- Traction and friction: `traction_coefficient`, `traction_force`, `friction_force`.
- Normal damping (Hunt & Crossley 1975): `hunt_crossley_force`, `hunt_crossley_factor`,
  `HUNT_CROSSLEY_ALPHA`.
"""

from ._damping import (
    DAMPING_FACTOR_WIDTH,
    HUNT_CROSSLEY_ALPHA,
    hunt_crossley_factor,
    hunt_crossley_force,
)
from ._hertz import (
    HAMROCK_BREWE_ERROR,
    LOAD_FLOOR,
    MAX_CURVATURE_RATIO,
    complete_elliptic_integrals,
    effective_modulus,
    hamrock_brewe_parameters,
    point_contact_deflection,
    point_contact_ellipse,
    point_contact_ellipticity,
    point_contact_parameters,
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
    "DAMPING_FACTOR_WIDTH",
    "HAMROCK_BREWE_ERROR",
    "HUNT_CROSSLEY_ALPHA",
    "ISO_LINE_CONSTANT",
    "LINE_EXPONENT",
    "LOAD_FLOOR",
    "MAX_CURVATURE_RATIO",
    "PENETRATION_WIDTH",
    "SLIDING_EPS",
    "STEEL_ELASTIC_MODULUS",
    "STEEL_E_PRIME",
    "STEEL_POISSON_RATIO",
    "complete_elliptic_integrals",
    "effective_modulus",
    "friction_force",
    "hamrock_brewe_parameters",
    "hertz_force",
    "hunt_crossley_factor",
    "hunt_crossley_force",
    "line_contact_stiffness",
    "line_slice_loads",
    "log_smooth_penetration",
    "point_contact_deflection",
    "point_contact_ellipse",
    "point_contact_ellipticity",
    "point_contact_parameters",
    "point_contact_peak_pressure",
    "point_contact_stiffness",
    "safe_norm",
    "smooth_direction",
    "smooth_penetration",
    "smooth_power",
    "traction_coefficient",
    "traction_force",
]
