"""The roller-end and rib meridians of profile designs, drawn to scale (docs/model.md 5.4).

Coordinates in the ring's plane through the roller's azimuth: x axial [mm] from the roller's
centre, h the height above the raceway [mm] (h = D/2 - rho, rho the distance from the roller
axis, so the end's half towards the raceway is drawn). The end meridian: the arc of radius R_end
whose centre lies at (a_c, e) in the roller's half-plane, a = a_c + sqrt(R_end^2 - (rho - e)^2)
up to the limited circle rho_lim, then the corner circle of radius R_cor about (x_cor, R_ce)
(R_ce = D/2 - R_cor, x_cor = L/2 - R_cor; `jaxbearing.flange.face_limited_circle`). The
rib meridian: the arc of curvature 1/R_rib tangent to the cone of layback theta_f at the height
h_t, its normal offset from the tangent line u_n = -kappa u_t^2 / (1 + sqrt(1 - kappa^2 u_t^2))
(towards the roller for a concave rib), with its foot a half clearance Delta_bf / 2 beyond the
end's apex (the roller centred between its flanges). The second panel shows the same curves as
their deviation from the flat end plane and from the design's cone, in micrometres.
"""

from __future__ import annotations

import pathlib

import numpy as np

from jaxbearing import Bearing
from jaxbearing.flange import face_limited_circle, face_protrusion, faces_of, variables_from_array

MM = 1e-3


def face_meridians(bearing: Bearing, x, num: int = 200) -> dict:
    """The end and rib meridians of the design array x (3 or 8 SI values) on `bearing`, in mm:
    {"end": (x, h), "rib": (x, h), "end_plane": x of the flat end plane, "rib_deviation": (u_n
    [um], h), "end_deviation": (a - a_plane [um], h)} (module docstring)."""
    b = variables_from_array(np.asarray(x, dtype=float)).apply(bearing)
    roller, faces = b.roller, faces_of(b)
    d = float(roller.diameter)
    r_end, e, r_cor = 1.0 / float(faces.end_curvature), float(faces.end_offset), float(faces.corner_radius)
    r_ce, x_cor = d / 2 - r_cor, float(roller.length) / 2 - r_cor  # the corner circle's centre
    rho_lim = float(face_limited_circle(roller, faces))
    a_c = x_cor - np.sqrt((r_end - r_cor) ** 2 - (r_ce - e) ** 2)
    rho_arc = np.linspace(0.0, rho_lim, num)
    a_arc = a_c + np.sqrt(r_end**2 - (rho_arc - e) ** 2)
    rho_cor = np.linspace(rho_lim, d / 2, num)
    a_cor = x_cor + np.sqrt(np.maximum(r_cor**2 - (rho_cor - r_ce) ** 2, 0.0))
    rho = np.concatenate([rho_arc, rho_cor])
    a = np.concatenate([a_arc, a_cor])
    plane = float(roller.length) / 2
    apex = plane + float(face_protrusion(roller, faces))
    theta, kappa = float(b.flange.layback_angle), float(faces.rib_curvature)
    h_t, h_rf = float(faces.rib_tangent_height), float(b.flange.height)
    foot = apex + float(b.flange.axial_clearance) / 2
    h = np.linspace(0.0, h_rf, num)
    u_t = (h - h_t) / np.cos(theta)
    u_n = -kappa * u_t**2 / (1.0 + np.sqrt(np.maximum(1.0 - (kappa * u_t) ** 2, 0.0)))
    rib_x = foot + h * np.tan(theta) + u_n / np.cos(theta)
    return {
        "end": (a / MM, (d / 2 - rho) / MM),
        "rib": (rib_x / MM, h / MM),
        "end_plane": plane / MM,
        "end_deviation": ((a - plane) / 1e-6, (d / 2 - rho) / MM),
        "rib_deviation": (u_n / 1e-6, h / MM),
    }


def plot_faces(bearing: Bearing, designs: dict, path) -> pathlib.Path:
    """Draw the meridians of every design of `designs` ({label: SI design array}) on
    `bearing`: to scale (left) and as deviations from the flat end and the cone (right)."""
    from jaxbearing.io import pyplot

    plt = pyplot()
    fig, (scale, dev) = plt.subplots(1, 2, figsize=(11, 5.5), gridspec_kw={"width_ratios": [1, 2.2]})
    right = []
    for i, (label, x) in enumerate(designs.items()):
        m = face_meridians(bearing, x)
        colour = f"C{i}"
        scale.plot(*m["end"], color=colour)
        scale.plot(*m["rib"], color=colour, linestyle="--")
        right.append(float(np.max(m["rib"][0])))
        dev.plot(*m["end_deviation"], color=colour, label=f"{label}: end, beyond the flat end plane")
        dev.plot(*m["rib_deviation"], color=colour, linestyle="--", label=f"{label}: rib, off its cone")
    plane = float(bearing.roller.length) / 2 / MM
    scale.set_xlim(plane - 1.0, max(right) + 0.3)
    scale.set_aspect("equal")
    scale.locator_params(axis="x", nbins=3)
    scale.set_xlabel("axial position from the roller centre [mm]")
    scale.set_ylabel("height above the raceway [mm]")
    scale.set_title("to scale (solid: end, dashed: rib)")
    dev.set_xlabel("axial deviation [um]")
    dev.set_ylabel("height above the raceway [mm]")
    dev.set_title("deviations (end from its flat plane, rib from its cone)")
    dev.legend(fontsize=7)
    fig.tight_layout()
    out = pathlib.Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
