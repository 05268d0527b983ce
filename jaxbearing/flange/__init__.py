"""The roller-end/flange model (docs/model.md 5; the source paper's subject), in one place.

- flange face and end pose: `flange_geometry` (tangent plane of the flange cone at the roller's
  azimuth, extreme point of the end body, interference, contact height, principal radii);
- the contact: `roller_flange_contact` (one roller, one flange), `all_flange_contacts` (every
  roller against the four flanges, shape (Z, 4); absent flanges of the bearing type carry
  nothing, `without_absent_flanges`), `FlangeContact`;
- its lubrication: `contact_point_velocity`, `flange_film` (entrainment, Hamrock-Dowson film,
  Lambda), `FlangeFilm`, `flange_friction_coefficient` (dry or mixed, `FLANGE_LUBRICATION_MODES`);
- its heat (docs/model.md 5.5): `friction_power`, `flange_friction_power` (per flange),
  `flange_flash_temperature` (Tian & Kennedy's moving source, Blok's partition),
  `blok_flash_temperature`, `flash_temperature_factor`, `flange_heat_source_speeds`;
- the static design zone of an aligned roller: `design_zone`, `design_zone_grid`, `DesignZone`,
  `zone_margins`, `MARGIN_NAMES`;
- general end and rib faces (a toroidal end of offset e, a rib meridian arc of curvature
  1/R_rib; docs/model.md 5.4): `Faces`, `faces_of`, `check_faces`, `face_contact`,
  `FaceContact`, `face_contact_stiffness`, `face_design_zone`, `FaceZone`,
  `face_limited_circle`, `face_protrusion`, `rib_distance`; in the dynamics through
  `contact_geometry` (today's `flange_geometry` for a bearing without general faces,
  `face_flange_geometry` for one with them, `Bearing.has_general_faces`), set on a bearing with
  `with_faces` (and dropped where they are today's, `plain_faces`); `roller_pose` (a concrete pose from azimuth, axial offset, tilt and skew);
- the design variables R_end, theta_f, Delta_bf: `DesignVariables`, `with_design`, and the one
  range check every design entry point uses, `check_design`; the eight profile variables
  (R_end, e, R_cor, 1/R_rib, h_t, theta_f, H_rf, Delta_bf): `ProfileVariables`,
  `PROFILE_NAMES`, `check_profile`; `variables_from_array` (either kind from its SI array).

The shape of the roller end itself (support function, limited circle) is in
`jaxbearing.geometry`, because the roller's mass properties need it.

May import: `jaxbearing._errors`, `contact`, `geometry`, `io`.
"""

from ._checks import DEFAULT_FLANGE_LOAD, check_design
from ._contact import (
    FLANGE_ORDER,
    FlangeContact,
    all_flange_contacts,
    flange_pv_at_load,
    roller_flange_contact,
    without_absent_flanges,
)
from ._design import DesignVariables, with_design
from ._face_contact import FaceContact, face_contact, face_contact_stiffness
from ._face_geometry import contact_geometry, face_flange_geometry
from ._face_zone import FaceZone, face_design_zone
from ._faces import Faces, check_faces, face_limited_circle, face_protrusion, faces_of, rib_distance
from ._geometry import FlangeGeometry, flange_effective_modulus, flange_geometry
from ._heat import (
    blok_flash_temperature,
    flange_flash_temperature,
    flange_friction_power,
    flange_heat_source_speeds,
    flash_temperature_factor,
    friction_power,
)
from ._lubrication import (
    FLANGE_LUBRICATION_MODES,
    FlangeFilm,
    contact_point_velocity,
    flange_film,
    flange_friction_coefficient,
)
from ._pose import roller_pose
from ._profile import (
    PROFILE_NAMES,
    ProfileVariables,
    check_profile,
    plain_faces,
    variables_from_array,
    with_faces,
)
from ._zone import MARGIN_NAMES, DesignZone, design_zone, design_zone_grid, zone_margins

__all__ = [
    "flange_pv_at_load",
    "roller_pose",
    "plain_faces",
    "friction_power",
    "flash_temperature_factor",
    "flange_heat_source_speeds",
    "flange_friction_power",
    "flange_flash_temperature",
    "blok_flash_temperature",
    "DEFAULT_FLANGE_LOAD",
    "FLANGE_LUBRICATION_MODES",
    "FLANGE_ORDER",
    "MARGIN_NAMES",
    "PROFILE_NAMES",
    "variables_from_array",
    "DesignVariables",
    "DesignZone",
    "FaceContact",
    "FaceZone",
    "Faces",
    "FlangeContact",
    "FlangeFilm",
    "FlangeGeometry",
    "ProfileVariables",
    "all_flange_contacts",
    "check_design",
    "check_faces",
    "check_profile",
    "contact_geometry",
    "contact_point_velocity",
    "design_zone",
    "design_zone_grid",
    "face_contact",
    "face_contact_stiffness",
    "face_design_zone",
    "face_flange_geometry",
    "face_limited_circle",
    "face_protrusion",
    "faces_of",
    "flange_effective_modulus",
    "flange_film",
    "flange_friction_coefficient",
    "flange_geometry",
    "rib_distance",
    "roller_flange_contact",
    "with_design",
    "with_faces",
    "without_absent_flanges",
    "zone_margins",
]
