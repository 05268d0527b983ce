"""The design-zone margins of an aligned roller's flange contact (docs/model.md 6), shared by
today's faces (`design_zone`) and the general ones (`face_design_zone`)."""

from __future__ import annotations


def zone_margin_fields(
    flange, contact_height, half_width, rho_lim, contact_radius, clearance, min_clearance
) -> dict:
    """The four design-zone margins [m], positive when satisfied, and their conjunction
    `feasible`: the contact ellipse above the relief (h_c - a - relief height), the contact
    height below its limit, the contact radius inside the limited circle (rho_lim - rho) and the
    actual axial clearance above `min_clearance`; the fields of `DesignZone` and `FaceZone`."""
    relief = contact_height - half_width - flange.relief_height
    height = flange.contact_height_limit - contact_height
    limited = rho_lim - contact_radius
    clear = clearance - min_clearance
    return dict(
        relief_margin=relief,
        height_margin=height,
        limited_circle_margin=limited,
        clearance_margin=clear,
        feasible=(relief > 0) & (height > 0) & (limited > 0) & (clear > 0),
    )
