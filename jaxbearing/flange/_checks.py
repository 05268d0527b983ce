"""One range check for a roller-end/flange design, shared by every entry point that takes one.

`check_design` is the single place where R_end, theta_f and Delta_bf (and the flange load and
required clearance of the design zone) are checked before anything is traced: `design_zone`,
`design_zone_grid`, `design_metrics`, `design_jacobian` and the `optimise` package call it.
"""

from __future__ import annotations

import numpy as np

from ..geometry import Bearing
from ..io import is_concrete, require
from ._profile import ProfileVariables, check_profile

#: default flange load (N) for the contact-ellipse half-width: a representative peak roller-end
#: load at the reference operating point (20,000 rpm, 1000 N).
DEFAULT_FLANGE_LOAD = 100.0


def check_design(
    bearing: Bearing,
    design=None,
    *,
    flange_load=None,
    min_clearance=None,
) -> None:
    """Raise a one-line `UserInputError` (parameter, value, valid range) for an out-of-range
    design; values under a JAX trace are skipped (check outside `jit`).

    A `ProfileVariables` design is checked by `check_profile`. With `design` (a
    `DesignVariables`) its fields are checked as ``design.end_radius`` etc.;
    without it the bearing's own ``roller.end_radius``, ``flange.layback_angle`` and
    ``flange.axial_clearance``. R_end must exceed D/2 (inf = flat ends), theta_f lie in
    [0, 45) deg, Delta_bf be positive (>= 0 for a bearing's own value); `flange_load` > 0 N and
    `min_clearance` finite when given."""
    if isinstance(design, ProfileVariables):
        check_profile(bearing, design)
    elif design is None:
        names = ("roller.end_radius", "flange.layback_angle", "flange.axial_clearance")
        values = (bearing.roller.end_radius, bearing.flange.layback_angle, bearing.flange.axial_clearance)
        clearance_ok, clearance_valid = (lambda v: v >= 0), ">= 0 m"
    else:
        names = ("design.end_radius", "design.layback_angle", "design.axial_clearance")
        values = (design.end_radius, design.layback_angle, design.axial_clearance)
        clearance_ok, clearance_valid = (lambda v: v > 0), "> 0 m"
    if not isinstance(design, ProfileVariables):  # a profile's own check ran above
        _check_three(bearing, names, values, clearance_ok, clearance_valid)
    if flange_load is not None:
        require("flange_load", flange_load, lambda v: v > 0, "> 0 N")
    if min_clearance is not None:
        require("min_clearance", min_clearance, np.isfinite, "finite (m)")


def _check_three(bearing: Bearing, names, values, clearance_ok, clearance_valid) -> None:
    """R_end > D/2, theta_f in [0, 45) deg, Delta_bf in its range (`check_design`)."""
    if is_concrete(bearing.roller.diameter):
        half_d = float(np.max(np.asarray(bearing.roller.diameter))) / 2
        require(names[0], values[0], lambda v: v > half_d, f"> D/2 = {half_d} m (inf for flat ends)")
    require(
        names[1], values[1], lambda v: (v >= 0) & (v < np.pi / 4), "in [0, 45) deg (radians inside the code)"
    )
    require(names[2], values[2], clearance_ok, clearance_valid)
