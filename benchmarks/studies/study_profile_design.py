"""The profile design's faces drawn against today's: the meridians to scale and as deviations.

    python benchmarks/studies/study_profile_design.py \
        --design 83.829,0.0540063,0.360549,0.230176,0,1.64406,2,0.149999 \
        --plot docs/figures/profile_design/faces.png

The meridians of the reference bearing's faces, of the three-variable optimum (`--three`, R_end
[mm], theta_f [deg], Delta_bf [mm], the reference's other faces) and of a profile design,
`--design` (eight values in the order and units of `optimise.ProfileBounds`: R_end mm, e mm,
R_cor mm, 1/R_rib 1/m, h_t mm, theta_f deg, H_rf mm, Delta_bf mm), to scale and as deviations
from the flat end plane and from the cone (`optimise._faces_plot.plot_faces`). Draws only:
nothing is simulated.
"""

from __future__ import annotations

import argparse
import pathlib
import sys

import numpy as np

#: the three-variable optimum the profile design is compared with (design-search how-to)
THREE_VARIABLE_OPTIMUM = "101.6,1.527,0.140"


def _design_array(row: dict, table) -> np.ndarray:
    """A design by engineering key as its SI array in the order of `table`."""
    return np.array([row[var.key] * var.si for var in table])


def faces(args) -> int:
    import jaxbearing as jb
    from jaxbearing.flange import ProfileVariables
    from optimise._bounds import DESIGN_TABLE, PROFILE_TABLE
    from optimise._faces_plot import plot_faces

    bearing = jb.reference_bearing()
    three = dict(zip((v.key for v in DESIGN_TABLE), (float(v) for v in args.three.split(","))))
    profile = dict(zip((v.key for v in PROFILE_TABLE), (float(v) for v in args.design.split(","))))
    designs = {
        "reference": np.asarray(ProfileVariables.of(bearing).as_array()),
        "three-variable optimum": _three_as_profile(bearing, _design_array(three, DESIGN_TABLE)),
        "profile design": _design_array(profile, PROFILE_TABLE),
    }
    pathlib.Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
    print(f"wrote {plot_faces(bearing, designs, args.plot)}")
    return 0


def _three_as_profile(bearing, x) -> np.ndarray:
    from jaxbearing.flange import DesignVariables, ProfileVariables

    return np.asarray(ProfileVariables.from_design(DesignVariables.from_array(x), bearing).as_array())


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--design", required=True, help="the profile design: eight values (module docstring)")
    p.add_argument("--three", default=THREE_VARIABLE_OPTIMUM)
    p.add_argument("--plot", required=True)
    return faces(p.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
