"""Body-pair contacts and loads, one module per pair (docs/model.md 8-4.5).

- roller against raceway (`raceway_contact`, sliced line contact with crown, Hunt-Crossley
  damping and lubricant traction; `RacewayContact`);
- roller against cage pocket (`pocket_contact`, `PocketContact`);
- cage against its guiding lands (`cage_land_forces`: Ocvirk film, rub contact, Petroff torque);
- oil-air drag on rollers and cage (`roller_drag`, `cage_drag_torque`).

The roller-end/flange pair is the project's subject and has its own package,
`jaxbearing.flange`.

May import: `jaxbearing._errors`, `contact`, `geometry`.
"""

from ._cage_lands import (
    FILM_ECCENTRICITY_KNEE,
    FILM_ECCENTRICITY_MAX,
    cage_land_forces,
    capped_eccentricity,
    land_contact_stiffness,
)
from ._drag import (
    cage_drag_torque,
    cylinder_drag_coefficient,
    mixture_density,
    mixture_viscosity,
    roller_drag,
)
from ._pocket import (
    NUM_POCKET_SLICES,
    PocketContact,
    pocket_contact,
    pocket_slice_positions,
    pocket_stiffness,
)
from ._raceway import (
    RacewayContact,
    crown_curvature,
    crown_drop,
    raceway_contact,
    raceway_slice_geometry,
    raceway_stiffness,
    slice_loads_from_interference,
    slice_positions,
    uniform_approach_interference,
)

__all__ = [
    "FILM_ECCENTRICITY_KNEE",
    "FILM_ECCENTRICITY_MAX",
    "NUM_POCKET_SLICES",
    "PocketContact",
    "RacewayContact",
    "cage_drag_torque",
    "cage_land_forces",
    "capped_eccentricity",
    "crown_curvature",
    "crown_drop",
    "cylinder_drag_coefficient",
    "land_contact_stiffness",
    "mixture_density",
    "mixture_viscosity",
    "pocket_contact",
    "pocket_slice_positions",
    "pocket_stiffness",
    "raceway_contact",
    "raceway_slice_geometry",
    "raceway_stiffness",
    "roller_drag",
    "slice_loads_from_interference",
    "slice_positions",
    "uniform_approach_interference",
]
