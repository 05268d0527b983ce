"""The held-load objective: the settled flange PV of any design at the poses, velocities and
flange loads of one design's settled running (docs/model.md 17, the held-load objective).

The frozen-load estimator differentiates the settled mean PV at the design that ran, holding
the loads the dynamics gave. Held at those saved states for every design x, the same functional
is a deterministic, smooth function of the whole design, without seed noise and without
dynamics (a few thousand contact evaluations):

    J(x) = sum_c w(Q0_c) p_max(x; Q0_c) |u_c(x)| / sum_c w(Q0_c),    w(Q) = Q / (Q + Q_w)

over the touching contacts c of the saved states, p_max(x; Q0) the Hertz peak pressure of design
x's contact at the held load Q0 and |u(x)| the material sliding speed at design x's contact
point (`flange.flange_pv_at_load`). Unlike the estimator's ratio form, the contact is kept where
design x's faces would not overlap the end at the held pose (a roller re-seats against the faces
it has): at x0 both are the same number, near x0 the same function. Beside it the peak
statistic's p-mean, (sum w PV^p / sum w)^(1/p), and the distance of the largest held contact
radius from the limited circle, rho_lim(x) - max_c rho_c(x), the maximum a log-sum-exp of width
`smooth_max_width` so that it has a derivative. What it leaves out is how a design changes the
loads and the poses: the held-load design is a candidate for settled running, not a result.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Float

from ..dynamics import inner_ring_pose
from ..flange import FLANGE_ORDER, flange_pv_at_load, variables_from_array
from ..geometry import limited_circle_radius
from ._frozen_load import _exponent, _reference_loads
from ._steady_objective import STEADY_FUNCTIONALS

#: held contacts whose weight w(Q0) is below this are left out (`HeldContacts.weight_share`)
MIN_WEIGHT = 1e-4
#: the log-sum-exp width of the largest held contact radius [m]
SMOOTH_MAX_WIDTH = 1e-6


class HeldContacts(eqx.Module):
    """The touching roller-end/flange contacts of saved states, flattened (N contacts): the
    flange (raceway radius, side, ring sign), the ring's and the roller's pose and velocities,
    the load Q0 the dynamics gave and its weight w(Q0); `weight_share` the share of the total
    weight the kept contacts carry."""

    raceway_radius: Float[Array, " N"]
    side: Float[Array, " N"]
    ring_sign: Float[Array, " N"]
    ring_centre: Float[Array, "N 3"]
    ring_velocity: Float[Array, "N 3"]
    ring_angular_velocity: Float[Array, "N 3"]
    ring_axis: Float[Array, "N 3"]
    roller_centre: Float[Array, "N 3"]
    roller_axis: Float[Array, "N 3"]
    roller_velocity: Float[Array, "N 3"]
    roller_angular_velocity: Float[Array, "N 3"]
    load: Float[Array, " N"]
    weight: Float[Array, " N"]
    weight_share: float = eqx.field(static=True)


class HeldReadouts(eqx.Module):
    """The held-load readouts of one design (module docstring), SI: mean PV J [Pa m/s], the
    peak statistic's p-mean [Pa m/s], rho_lim - the smooth largest contact radius [m]."""

    mean_pv: Float[Array, ""]
    peak_pv: Float[Array, ""]
    corner_distance: Float[Array, ""]


def held_contacts(bearing, op, design, states, *, min_weight: float = MIN_WEIGHT) -> HeldContacts:
    """The touching contacts of the saved `states` (a leading time axis, e.g. from
    `trajectory_states`) of `design` (a `DesignVariables` or `ProfileVariables`) applied to
    `bearing`: those whose weight w(Q0) exceeds `min_weight`."""
    q0 = np.asarray(_reference_loads(bearing, op, jnp.asarray(design.as_array()), states))  # (T, Z, 4)
    w = q0 / (q0 + STEADY_FUNCTIONALS.contact_load)
    t, z, f = np.nonzero(w > min_weight)
    r = states.rollers
    axis = np.asarray(r.axis) / np.linalg.norm(np.asarray(r.axis), axis=-1, keepdims=True)
    ring = jax.vmap(lambda s: inner_ring_pose(s, op))(states.inner_ring)
    inner = (f < 2)[:, None]
    zero = np.zeros((len(t), 3))
    flange = np.asarray(FLANGE_ORDER, dtype=float)[f]  # (ring sign, side)
    radii = np.array([float(bearing.inner_raceway_radius)] * 2 + [float(bearing.outer_raceway_radius)] * 2)
    return HeldContacts(
        raceway_radius=jnp.asarray(radii[f]),
        side=jnp.asarray(flange[:, 1]),
        ring_sign=jnp.asarray(flange[:, 0]),
        ring_centre=jnp.asarray(np.where(inner, np.asarray(ring.centre)[t], zero)),
        ring_velocity=jnp.asarray(np.where(inner, np.asarray(ring.velocity)[t], zero)),
        ring_angular_velocity=jnp.asarray(np.where(inner, np.asarray(ring.angular_velocity)[t], zero)),
        ring_axis=jnp.asarray(np.where(inner, np.asarray(ring.axis)[t], np.array([1.0, 0.0, 0.0]))),
        roller_centre=jnp.asarray(np.asarray(r.centre)[t, z]),
        roller_axis=jnp.asarray(axis[t, z]),
        roller_velocity=jnp.asarray(np.asarray(r.velocity)[t, z]),
        roller_angular_velocity=jnp.asarray(np.asarray(r.angular_velocity)[t, z]),
        load=jnp.asarray(q0[t, z, f]),
        weight=jnp.asarray(w[t, z, f]),
        weight_share=float(w[t, z, f].sum() / w.sum()) if w.sum() > 0 else 1.0,
    )


def held_readouts(
    bearing, x, contacts: HeldContacts, *, smooth_max_width: float = SMOOTH_MAX_WIDTH
) -> HeldReadouts:
    """The held-load readouts (module docstring) of design x (the SI array of a
    `DesignVariables` or a `ProfileVariables`, applied to `bearing`) at `contacts`.
    Differentiable in x (jax.jacfwd); traced, so one compiled program serves every design."""
    b = variables_from_array(jnp.asarray(x)).apply(bearing)
    c = contacts
    pv, rho = jax.vmap(
        lambda *a: flange_pv_at_load(b, *a[:-2], a[-2], ring_axis=a[-1])
    )(
        c.raceway_radius, c.side, c.ring_sign, c.roller_centre, c.roller_axis, c.roller_velocity,
        c.roller_angular_velocity, c.ring_centre, c.ring_velocity, c.ring_angular_velocity,
        c.load, c.ring_axis,
    )  # fmt: skip
    total = jnp.sum(c.weight)
    p = float(_exponent("peak"))
    ref = STEADY_FUNCTIONALS.pv_reference
    top = smooth_max_width * jax.scipy.special.logsumexp(rho / smooth_max_width)
    return HeldReadouts(
        mean_pv=jnp.sum(c.weight * pv) / total,
        peak_pv=ref * (jnp.sum(c.weight * (pv / ref) ** p) / total) ** (1.0 / p),
        corner_distance=limited_circle_radius(b.roller) - top,
    )
