"""3-vectors held by components, for contacts evaluated slice by slice.

Every per-slice quantity of the sliced contacts (raceways, cage pocket) is a tuple of its three
Cartesian components, each an array over the slices (over rollers and slices once the contact
is vmapped over rollers), instead of one array with a trailing axis of 3. XLA's CPU loops then
run over the slices, not over three components, and a sum over the slices is one reduction
(issue 12: the sliced contacts are most of a field evaluation; `benchmarks/diagnose_field_cost.py`).
"""

from __future__ import annotations

import jax.numpy as jnp
from jaxtyping import Array

Vec = tuple[Array, Array, Array]


def components(v) -> Vec:
    """(v_x, v_y, v_z) of an array whose last axis holds the components."""
    v = jnp.asarray(v)
    return v[..., 0], v[..., 1], v[..., 2]


def dot(a: Vec, b: Vec) -> Array:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: Vec, b: Vec) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def stack(v: Vec) -> Array:
    """The components back into one array with a trailing axis of 3 (broadcast first)."""
    return jnp.stack(jnp.broadcast_arrays(*v), axis=-1)


def expand(v: Vec) -> Vec:
    """Per-body components with a trailing axis for the slices."""
    return tuple(c[..., None] for c in v)


def safe_unit(v: Vec, fallback: Vec) -> tuple[Array, Vec]:
    """(|v|, v/|v|) with the double-where pattern; `fallback` where |v| = 0."""
    sq = dot(v, v)
    ok = sq > 0
    n = jnp.where(ok, jnp.sqrt(jnp.where(ok, sq, 1.0)), 0.0)
    inv = 1.0 / jnp.where(ok, n, 1.0)
    return n, tuple(jnp.where(ok, c * inv, f) for c, f in zip(v, fallback, strict=True))


def relative_velocity(
    velocity: Vec,
    angular_velocity: Vec,
    other_velocity: Vec,
    other_angular_velocity: Vec,
    lever: Vec,
    arm: Vec,
) -> Vec:
    """Velocity of a body's material point at x minus that of the other body's point at x:

        v_rel = (v + w x arm) - (v_o + w_o x (lever + arm)),   arm = x - p,  lever = p - c_o,

    written as (v - v_o - w_o x lever) + (w - w_o) x arm, so that only one cross product is
    taken per slice (p the body's centre, c_o the other's; `arm` per slice, the rest per body)."""
    drift = cross(other_angular_velocity, lever)
    centre = tuple(a - b - c for a, b, c in zip(velocity, other_velocity, drift, strict=True))
    w_rel = tuple(a - b for a, b in zip(angular_velocity, other_angular_velocity, strict=True))
    n = arm[0].ndim - centre[0].ndim  # slice axes of `arm` beyond the body's
    grow = lambda c: c.reshape(c.shape + (1,) * n)  # noqa: E731
    spin = cross(tuple(map(grow, w_rel)), arm)
    return tuple(grow(c) + s for c, s in zip(centre, spin, strict=True))


def resultants(forces: Vec, arm: Vec, lever: Vec, num_slice_axes: int):
    """(force, moment about the body's centre p, moment about the other body's centre c_o) of
    per-slice forces f_j on the body at lever arms arm_j = x_j - p, summed over the trailing
    `num_slice_axes` axes in one reduction; arrays with a trailing axis of 3.
    sum (x_j - c_o) x f_j = M_p + (p - c_o) x F with lever = p - c_o."""
    axes = tuple(range(-num_slice_axes - 1, -1))
    totals = jnp.sum(jnp.stack(forces + cross(arm, forces), axis=-1), axis=axes)
    force, moment = totals[..., :3], totals[..., 3:]
    return force, moment, moment + stack(cross(lever, components(force)))
