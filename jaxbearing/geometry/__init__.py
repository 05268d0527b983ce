"""Bearing geometry: parameter pytrees, derived mass properties, the roller end body.

Owns: `Bearing` and its parts (`Roller`, `Flange`, `Cage`, `Material` with the bearing-steel
thermal defaults `BEARING_STEEL_CONDUCTIVITY`, `BEARING_STEEL_SPECIFIC_HEAT`, `Lubricant`), the
flange arrangement of the bearing types (`FLANGES`, `BEARING_TYPES`, `flange_presence`), the
`OperatingPoint`, the reference bearing (docs/model.md 1), unit conversions, the mass properties
derived from geometry, the inner ring's tilted axis (`ring_axis`), and the shape of the roller end (corner torus and spherical cap, docs/model.md
4: support function, limited circle, arc protrusion, principal curvatures).

The end body lives here rather than in `jaxbearing.flange` because the roller's mass properties
need it (the arc cap changes the volume), and mass properties sit below every contact.

May import: `jaxbearing._errors`. Nothing above it.
"""

from ._arrangement import (
    BEARING_TYPES,
    FLANGES,
    arrangement_of,
    carries_axial_load,
    flange_presence,
    locates_rollers,
)
from ._inertia import cage_mass_properties, inner_ring_inertia, roller_mass_properties
from ._params import (
    BEARING_STEEL_CONDUCTIVITY,
    BEARING_STEEL_SPECIFIC_HEAT,
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
from ._ring import ring_axis, ring_tilt_angular_velocity
from ._roller_end import (
    LIMITED_CIRCLE_BAND,
    SIN_ALPHA_FLOOR,
    arc_half_length,
    arc_protrusion,
    arc_weight,
    end_curvature,
    end_principal_curvatures,
    end_support,
    limited_circle_radius,
    sag,
)

__all__ = [
    "BEARING_STEEL_CONDUCTIVITY",
    "BEARING_STEEL_SPECIFIC_HEAT",
    "BEARING_TYPES",
    "FLANGES",
    "LIMITED_CIRCLE_BAND",
    "SIN_ALPHA_FLOOR",
    "Bearing",
    "Cage",
    "Flange",
    "Lubricant",
    "Material",
    "OperatingPoint",
    "Roller",
    "arc_half_length",
    "arc_protrusion",
    "arc_weight",
    "arrangement_of",
    "carries_axial_load",
    "cage_mass_properties",
    "end_curvature",
    "end_principal_curvatures",
    "end_support",
    "flange_presence",
    "inner_ring_inertia",
    "kinematic_cage_speed",
    "limited_circle_radius",
    "locates_rollers",
    "rad_s_to_rpm",
    "ring_axis",
    "ring_tilt_angular_velocity",
    "roller_mass_properties",
    "rpm_to_rad_s",
    "sag",
]
