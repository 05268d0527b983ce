"""The profile design variables: the shapes of the roller end and the rib face with the axial
clearance, eight scalars (docs/model.md 5.4).

`ProfileVariables` holds R_end [m], the end offset e [m], the corner radius R_cor [m], the rib
curvature kappa_rib = 1/R_rib [1/m] (0: the cone, so today's rib is an ordinary value with finite
derivatives), the rib's tangent height h_t [m], the layback angle theta_f [rad], the flange
height H_rf [m] and the axial clearance Delta_bf [m]. `apply` puts them into a `Bearing`, which
then has general faces (`Bearing.has_general_faces`) and runs the general contact
(`face_contact`), even at e = 0, kappa_rib = 0.

Why a class beside `DesignVariables` rather than optional fields on it: the three-variable
search (R_end, theta_f, Delta_bf), its arrays of shape (..., 3) and the bearings it builds must
stay exactly as they are (today's faces, today's contact code, the same numbers bit for bit),
while a profile is always the general contact. Two classes keep that a matter of which class a
caller holds, not of which fields happen to be None. `ProfileVariables.from_design` carries a
three-variable design (and the bearing's other face parameters) into the profile space.

Gradients. Every field enters the dynamics differentiably except H_rf, which enters only the
reported top-edge indicator (and the static design zone's flange-height margin): its derivative
of a dynamic metric is 0. h_t moves nothing on a cone (the tangent point slides along it).
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from ..geometry import Bearing
from ..io import is_concrete, require
from ._design import DesignVariables, with_design

Scalar = Float[Array, "*batch"]

#: the fields of `ProfileVariables` in the order of `as_array`
PROFILE_NAMES = (
    "end_radius",
    "end_offset",
    "corner_radius",
    "rib_curvature",
    "rib_tangent_height",
    "layback_angle",
    "flange_height",
    "axial_clearance",
)


def _f(x) -> Array:
    return jnp.asarray(x, dtype=jnp.float64)


def _face_fields(bearing: Bearing) -> tuple:
    """The bearing's three general-face fields (e, kappa_rib, h_t; None where not set): the
    nodes `with_faces` sets and `plain_faces` drops."""
    return (bearing.roller.end_offset, bearing.flange.rib_curvature, bearing.flange.rib_tangent_height)


def with_faces(
    bearing: Bearing,
    end_offset: ArrayLike | None = None,
    rib_curvature: ArrayLike | None = None,
    rib_tangent_height: ArrayLike | None = None,
) -> Bearing:
    """`bearing` with the general-face parameters e [m], 1/R_rib [1/m] and h_t [m] set (None
    keeps the bearing's own; a bearing without them gets 0). The result has general faces
    (`Bearing.has_general_faces`): the general contact runs, even for e = 0, kappa_rib = 0."""
    own = _face_fields(bearing)
    given = (end_offset, rib_curvature, rib_tangent_height)
    values = tuple(_f(g if g is not None else (o if o is not None else 0.0)) for g, o in zip(given, own))
    return eqx.tree_at(_face_fields, bearing, values, is_leaf=lambda x: x is None)


def plain_faces(bearing: Bearing) -> Bearing:
    """`bearing` without its general-face fields where they are concretely today's faces
    (e = 0 and kappa_rib = 0 in every member; h_t then places nothing), else `bearing` itself.
    Section 5's contact code then runs, with the same numbers to round-off as the general
    contact at these values (docs/model.md 5.4) at about half its cost per step, as for a
    configuration whose face keys are today's. Not for a bearing that is differentiated with
    respect to e, kappa_rib or h_t: it has no such fields."""
    r, f = bearing.roller, bearing.flange
    if not bearing.has_general_faces or not is_concrete(r.end_offset, f.rib_curvature):
        return bearing
    flat = all(v is None or not np.any(np.asarray(v, dtype=float)) for v in (r.end_offset, f.rib_curvature))
    if not flat:
        return bearing
    return eqx.tree_at(_face_fields, bearing, (None, None, None), is_leaf=lambda x: x is None)


class ProfileVariables(eqx.Module):
    """The profile design (module docstring): eight scalars in SI units (curvature 1/m).

    Fields may carry leading batch axes (stacked designs for `jax.vmap`)."""

    end_radius: Scalar = eqx.field(converter=_f)  # R_end [m]
    end_offset: Scalar = eqx.field(converter=_f)  # e [m]
    corner_radius: Scalar = eqx.field(converter=_f)  # R_cor [m]
    rib_curvature: Scalar = eqx.field(converter=_f)  # 1/R_rib [1/m], 0: cone
    rib_tangent_height: Scalar = eqx.field(converter=_f)  # h_t [m]
    layback_angle: Scalar = eqx.field(converter=_f)  # theta_f [rad]
    flange_height: Scalar = eqx.field(converter=_f)  # H_rf [m]
    axial_clearance: Scalar = eqx.field(converter=_f)  # Delta_bf [m]

    @classmethod
    def of(cls, bearing: Bearing) -> ProfileVariables:
        """The profile of `bearing` (0 for a face parameter it does not carry)."""
        return cls.from_design(DesignVariables.of(bearing), bearing)

    @classmethod
    def from_design(cls, design: DesignVariables, bearing: Bearing) -> ProfileVariables:
        """The three-variable `design` (R_end, theta_f, Delta_bf) as a profile, the other five
        from `bearing` (0 for a face parameter it does not carry)."""
        r, f = bearing.roller, bearing.flange
        return cls(
            end_radius=design.end_radius,
            end_offset=0.0 if r.end_offset is None else r.end_offset,
            corner_radius=r.corner_radius,
            rib_curvature=0.0 if f.rib_curvature is None else f.rib_curvature,
            rib_tangent_height=0.0 if f.rib_tangent_height is None else f.rib_tangent_height,
            layback_angle=design.layback_angle,
            flange_height=f.height,
            axial_clearance=design.axial_clearance,
        )

    def apply(self, bearing: Bearing) -> Bearing:
        """`bearing` with this profile: general faces (`with_faces`), R_cor and H_rf replaced,
        and R_end, theta_f, Delta_bf (`with_design`)."""
        out = with_design(bearing, self.end_radius, self.layback_angle, self.axial_clearance)
        out = eqx.tree_at(
            lambda b: (b.roller.corner_radius, b.flange.height),
            out,
            (self.corner_radius, self.flange_height),
        )
        return with_faces(out, self.end_offset, self.rib_curvature, self.rib_tangent_height)

    def as_array(self) -> Float[Array, "*batch 8"]:
        """The fields stacked on a trailing axis in the order `PROFILE_NAMES`."""
        return jnp.stack([getattr(self, n) for n in PROFILE_NAMES], axis=-1)

    @classmethod
    def from_array(cls, x: Float[Array, "*batch 8"]) -> ProfileVariables:
        x = jnp.asarray(x, dtype=float)
        return cls(**{n: x[..., i] for i, n in enumerate(PROFILE_NAMES)})


def _max(x) -> float:
    return float(np.max(np.asarray(x, dtype=float)))


def check_profile(bearing: Bearing, profile: ProfileVariables) -> None:
    """Raise a one-line `UserInputError` (parameter, value, valid range) for a profile that
    does not make faces of `bearing`'s roller; traced values are skipped (check outside `jit`).

    R_end > D/2 (finite); 0 < R_cor < D/2; 0 <= e < R_ce = D/2 - R_cor and e < R_end;
    0 <= 1/R_rib < 1/R_end (a cone or a concave rib less curved than the end); theta_f in
    [0, 45) deg; H_rf in (0, D); 0 <= h_t <= H_rf; Delta_bf > 0. Batched fields: each bound
    against the largest dependency (a conservative check of every member)."""
    p = profile
    if not is_concrete(bearing.roller.diameter, p):
        return
    d = _max(bearing.roller.diameter)
    require(
        "profile.end_radius",
        p.end_radius,
        lambda v: (v > d / 2) & np.isfinite(v),
        f"in (D/2 = {d / 2:g}, inf) m",
    )
    require(
        "profile.corner_radius",
        p.corner_radius,
        lambda v: (v > 0) & (v < d / 2),
        f"in (0, D/2 = {d / 2:g}) m",
    )
    r_ce = d / 2 - _max(p.corner_radius)
    require(
        "profile.end_offset",
        p.end_offset,
        lambda v: (v >= 0) & (v < r_ce),
        f"in [0, D/2 - R_cor = {r_ce:g}) m",
    )
    r_end = float(np.min(np.asarray(p.end_radius, dtype=float)))
    require("profile.end_offset", p.end_offset, lambda v: v < r_end, f"< R_end = {r_end:g} m")
    require(
        "profile.rib_curvature",
        p.rib_curvature,
        lambda v: (v >= 0) & (v < 1 / r_end),
        f"in [0, 1/R_end = {1 / r_end:g}) 1/m (0: the cone; a concave rib with R_rib > R_end)",
    )
    require(
        "profile.layback_angle",
        p.layback_angle,
        lambda v: (v >= 0) & (v < np.pi / 4),
        "in [0, 45) deg (radians inside the code)",
    )
    require("profile.flange_height", p.flange_height, lambda v: (v > 0) & (v < d), f"in (0, D = {d:g}) m")
    h_rf = float(np.min(np.asarray(p.flange_height, dtype=float)))
    require(
        "profile.rib_tangent_height",
        p.rib_tangent_height,
        lambda v: (v >= 0) & (v <= h_rf),
        f"in [0, H_rf = {h_rf:g}] m",
    )
    require("profile.axial_clearance", p.axial_clearance, lambda v: v > 0, "> 0 m")


def variables_from_array(x) -> DesignVariables | ProfileVariables:
    """The design of an array of SI values by its trailing length: 3, a `DesignVariables`
    (R_end, theta_f, Delta_bf); 8, a `ProfileVariables` (in the order `PROFILE_NAMES`). The
    length is static, so a traced function of x builds one kind of bearing."""
    n = int(np.shape(x)[-1])
    if n == 3:
        return DesignVariables.from_array(x)
    if n == len(PROFILE_NAMES):
        return ProfileVariables.from_array(x)
    raise ValueError(f"design array of trailing length {n}: expected 3 or {len(PROFILE_NAMES)}")
