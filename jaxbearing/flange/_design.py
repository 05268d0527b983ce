"""The roller-end/flange design variables: R_end, theta_f, Delta_bf (the paper's Section 3.4).

`DesignVariables` holds the three quantities the source study tunes (Machines 2025, 13(11), 993,
Figure 14): the end radius R_end [m], the flange layback angle theta_f [rad] and the axial
clearance Delta_bf [m]; `with_design` puts them into a `Bearing`. Fields are JAX arrays, so a
design is differentiable data and stacks for `jax.vmap`.
"""

from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

from ..geometry import Bearing

Scalar = Float[Array, "*batch"]


def _f(x) -> Array:
    return jnp.asarray(x, dtype=jnp.float64)


def with_design(
    bearing: Bearing,
    end_radius: ArrayLike | None = None,
    layback_angle: ArrayLike | None = None,
    axial_clearance: ArrayLike | None = None,
) -> Bearing:
    """`bearing` with the roller-end/flange design variables replaced (None keeps the value):
    R_end (m), theta_f (rad), Delta_bf (m)."""
    out = bearing
    if end_radius is not None:
        out = eqx.tree_at(lambda b: b.roller.end_radius, out, jnp.asarray(end_radius, float))
    if layback_angle is not None:
        out = eqx.tree_at(lambda b: b.flange.layback_angle, out, jnp.asarray(layback_angle, float))
    if axial_clearance is not None:
        out = eqx.tree_at(lambda b: b.flange.axial_clearance, out, jnp.asarray(axial_clearance, float))
    return out


class DesignVariables(eqx.Module):
    """The roller-end/flange design: R_end [m], theta_f [rad], Delta_bf [m].

    Fields may carry leading batch axes (stacked designs for `jax.vmap`)."""

    end_radius: Scalar = eqx.field(converter=_f)  # R_end
    layback_angle: Scalar = eqx.field(converter=_f)  # theta_f
    axial_clearance: Scalar = eqx.field(converter=_f)  # Delta_bf

    @classmethod
    def of(cls, bearing: Bearing) -> DesignVariables:
        """The design of `bearing`."""
        return cls(
            end_radius=bearing.roller.end_radius,
            layback_angle=bearing.flange.layback_angle,
            axial_clearance=bearing.flange.axial_clearance,
        )

    def apply(self, bearing: Bearing) -> Bearing:
        """`bearing` with this design (`with_design`)."""
        return with_design(bearing, self.end_radius, self.layback_angle, self.axial_clearance)

    def as_array(self) -> Float[Array, "*batch 3"]:
        """(R_end, theta_f, Delta_bf) stacked on a trailing axis."""
        return jnp.stack([self.end_radius, self.layback_angle, self.axial_clearance], axis=-1)

    @classmethod
    def from_array(cls, x: Float[Array, "*batch 3"]) -> DesignVariables:
        x = jnp.asarray(x, dtype=float)
        return cls(end_radius=x[..., 0], layback_angle=x[..., 1], axial_clearance=x[..., 2])
