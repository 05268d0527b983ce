"""Contact-mechanics primitives: Hertz and line contact, smoothing, damping, EHL film, traction.

Pure functions of geometry and loads, broadcasting over leading axes, in SI units, and
jit/vmap/grad-friendly: every law is smoothed so that values, gradients and Hessians are finite
at, below and above zero penetration and at zero sliding (docs/model.md section 7.3).

- Point contact, exact Hertz solution (Johnson 1985, sec. 4.2): `effective_modulus`,
  `point_contact_stiffness`, `point_contact_ellipse`, `point_contact_peak_pressure`,
  `point_contact_deflection`, `point_contact_ellipticity`, `point_contact_parameters`,
  `complete_elliptic_integrals`; the Hamrock & Brewe (1983) fit for comparison:
  `hamrock_brewe_parameters`.
- Line contact (ISO/TS 16281, docs/model.md 8): `line_contact_stiffness`, `line_slice_loads`,
  `line_power` (the slice law's power with a hand-written tangent).
- Smoothing: `smooth_penetration`, `smooth_power`, `hertz_force`, `safe_norm`,
  `smooth_direction`.
- Traction and friction: `traction_coefficient`, `traction_force`, `friction_force`.
- Normal damping (Hunt & Crossley 1975): `hunt_crossley_force`, `hunt_crossley_factor`,
  `restitution_coefficient`, `HUNT_CROSSLEY_ALPHA`.
- Lubricated point contact: Hamrock & Dowson (1977) film thickness `minimum_film_thickness`,
  `central_film_thickness`, `ehl_parameters`; `viscosity_at_temperature`,
  `entrainment_velocity`, `entrainment_radii`; film parameter `film_parameter`; load-sharing
  mixed traction `asperity_load_fraction`, `mixed_traction_coefficient`, `mixed_traction_force`.
"""

from ._damping import (
    DAMPING_FACTOR_WIDTH,
    HUNT_CROSSLEY_ALPHA,
    hunt_crossley_factor,
    hunt_crossley_force,
    restitution_coefficient,
)
from ._film import (
    ASPERITY_EXPONENT,
    ASPERITY_MIDPOINT,
    FILM_LOAD_FLOOR,
    ROUGHNESS_FLOOR,
    asperity_load_fraction,
    central_film_thickness,
    ehl_parameters,
    entrainment_radii,
    entrainment_velocity,
    film_parameter,
    minimum_film_thickness,
    mixed_traction_coefficient,
    mixed_traction_force,
    viscosity_at_temperature,
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
    "ASPERITY_EXPONENT",
    "ASPERITY_MIDPOINT",
    "DAMPING_FACTOR_WIDTH",
    "FILM_LOAD_FLOOR",
    "HAMROCK_BREWE_ERROR",
    "HUNT_CROSSLEY_ALPHA",
    "ISO_LINE_CONSTANT",
    "LINE_EXPONENT",
    "LOAD_FLOOR",
    "MAX_CURVATURE_RATIO",
    "PENETRATION_WIDTH",
    "ROUGHNESS_FLOOR",
    "SLIDING_EPS",
    "STEEL_ELASTIC_MODULUS",
    "STEEL_E_PRIME",
    "STEEL_POISSON_RATIO",
    "asperity_load_fraction",
    "central_film_thickness",
    "complete_elliptic_integrals",
    "effective_modulus",
    "ehl_parameters",
    "entrainment_radii",
    "entrainment_velocity",
    "film_parameter",
    "friction_force",
    "hamrock_brewe_parameters",
    "hertz_force",
    "hunt_crossley_factor",
    "hunt_crossley_force",
    "line_contact_stiffness",
    "line_power",
    "line_slice_loads",
    "log_smooth_penetration",
    "minimum_film_thickness",
    "mixed_traction_coefficient",
    "mixed_traction_force",
    "point_contact_deflection",
    "point_contact_ellipse",
    "point_contact_ellipticity",
    "point_contact_parameters",
    "point_contact_peak_pressure",
    "point_contact_stiffness",
    "restitution_coefficient",
    "safe_norm",
    "smooth_direction",
    "smooth_penetration",
    "smooth_power",
    "traction_coefficient",
    "traction_force",
    "viscosity_at_temperature",
]
