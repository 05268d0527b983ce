"""A roller's pose for the flange contact, built from the quantities a bearing engineer reads:
its azimuth, axial offset, tilt and skew (docs/model.md 5)."""

from __future__ import annotations

import math

import numpy as np

from ..geometry import Bearing

_X = np.array([1.0, 0.0, 0.0])


def roller_pose(
    bearing: Bearing,
    ring_sign: float,
    axial: float = 0.0,
    tilt: float = 0.0,
    skew: float = 0.0,
    azimuth: float = 0.3,
) -> tuple[float, np.ndarray, np.ndarray]:
    """(R_r, p, e) of a roller on the pitch circle at `azimuth` [rad], offset `axial` [m] along
    the bearing axis X, its axis e turned by `tilt` [rad] towards the radial direction e_rad (in
    the meridian plane) and by `skew` [rad] towards the tangential e_tan = X x e_rad:

        e = X cos(tilt) cos(skew) + e_rad sin(tilt) + e_tan sin(skew) cos(tilt),

    with R_r the raceway radius of the ring (`ring_sign` +1: inner, -1: outer); the inputs of
    `flange_geometry` and `face_contact` for a concrete pose (host values, not traced)."""
    e_rad = np.array([0.0, math.sin(azimuth), math.cos(azimuth)])
    e_tan = np.cross(_X, e_rad)
    p = float(bearing.pitch_diameter) / 2 * e_rad + axial * _X
    axis = (
        _X * math.cos(tilt) * math.cos(skew)
        + e_rad * math.sin(tilt)
        + e_tan * math.sin(skew) * math.cos(tilt)
    )
    radius = bearing.inner_raceway_radius if ring_sign > 0 else bearing.outer_raceway_radius
    return float(radius), p, axis
