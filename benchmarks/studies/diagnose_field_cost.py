"""Where a field evaluation's work goes, and what a tangent costs (issue 12, items 3 and the
gradient/solve ratio): XLA's own operation counts of the compiled programs
(`Compiled.cost_analysis()`: floating-point operations, transcendental functions, bytes), which
do not depend on the machine's load, unlike wall times.

Programs, on the reference bearing at 20,000 rpm and 1000 N, at the seeded quasi-static start
(26 rollers, 31 slices per raceway):

* the field `physical_rates` (what the solve evaluates 7 times per Tsit5 step attempt);
* its parts: the inner and the outer raceway contacts of all rollers, the four flange contacts
  of all rollers (only the roller forces and moments, as the field uses them);
* the outer raceway, the traction law and the slice law (all slices of one raceway) with one
  tangent: where a tangent's operations go;
* the forward-mode field of `design_jacobian` / `bench_gradients`: `jax.jvp` of the field with
  three tangents (vmapped) in the design variables (R_end, theta_f, Delta_bf) AND in the state,
  as inside a solve under `diffrax.ForwardMode()` (the tangents ride on the state), and with
  tangents in the design only (a lower bound that no solve reaches).

The ratio (value + 3 tangents) / value of the field's operations bounds what forward mode can
cost relative to one solve, since the Runge-Kutta stages carry the tangents linearly.

    python benchmarks/studies/diagnose_field_cost.py
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "diagnose_field_cost"
KEYS = ("flops", "transcendentals", "bytes accessed")


def cost(fn, *args) -> dict:
    """XLA's cost analysis of `jax.jit(fn)` compiled for `args`."""
    import jax

    analysis = jax.jit(fn).lower(*args).compile().cost_analysis()
    if isinstance(analysis, list):  # older JAX returns one dict per device
        analysis = analysis[0]
    return {k: float(analysis.get(k, 0.0)) for k in KEYS}


def programs() -> dict:
    """{name: (function, args)} of the programs in the module docstring."""
    import jax
    import jax.numpy as jnp

    import jaxbearing as jb
    from jaxbearing.contact import traction_force
    from jaxbearing.dynamics import Params, physical_rates
    from jaxbearing.dynamics._field import inner_ring_pose
    from jaxbearing.flange import DesignVariables, all_flange_contacts
    from jaxbearing.forces import raceway_contact
    from jaxbearing.forces._raceway import slice_loads_from_interference

    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    y = jb.run.initial_state(bearing, op, jb.Perturbation(seed=0))
    x0 = DesignVariables.of(bearing).as_array()
    r = y.rollers
    e = r.axis / jnp.linalg.norm(r.axis, axis=-1, keepdims=True)
    ring = inner_ring_pose(y.inner_ring, op)
    zero = jnp.zeros(3)
    bodies = (r.centre, e, r.velocity, r.angular_velocity)
    raceway = jax.vmap(raceway_contact, in_axes=(None, None, None, 0, 0, 0, 0, None, None, None))

    def field(x, state):
        b = DesignVariables.from_array(x).apply(bearing)
        return physical_rates(0.0, state, Params(bearing=b, operating=op))

    def inner(p, e, v, w):
        c = raceway(
            bearing,
            1.0,
            bearing.inner_raceway_radius,
            p,
            e,
            v,
            w,
            ring.centre,
            ring.velocity,
            ring.angular_velocity,
        )
        return c.force_on_roller, c.moment_on_roller

    def outer(p, e, v, w):
        c = raceway(bearing, -1.0, bearing.outer_raceway_radius, p, e, v, w, zero, zero, zero)
        return c.force_on_roller, c.moment_on_roller

    def flange(p, e, v, w):
        c = all_flange_contacts(
            bearing, p, e, v, w, ring.centre, ring.velocity, ring.angular_velocity, zero, zero, zero,
            inner_ring_axis=ring.axis,
        )  # fmt: skip
        return c.force_on_roller, c.moment_on_roller

    basis = jnp.eye(3)
    slices = (bearing.num_rollers, bearing.num_slices)
    sliding = jnp.full(slices + (3,), 0.3)
    loads = jnp.full(slices, 10.0)
    interference = jnp.full(slices, 5e-6)

    def with_tangent(fn, *args):
        """fn and its JVP along ones on every argument (one tangent)."""
        ones = jax.tree_util.tree_map(jnp.ones_like, args)
        return lambda *a: jax.jvp(fn, a, ones)

    def traction(u, q):
        return traction_force(u, q, bearing.lubricant)

    def slice_law(d):
        return slice_loads_from_interference(bearing, d)

    def tangents_state_and_design(x, state):
        ones = jax.tree_util.tree_map(lambda a: jnp.ones((3,) + a.shape), state)
        return jax.vmap(lambda d, t: jax.jvp(field, (x, state), (d, t)), out_axes=(None, 0))(basis, ones)

    def tangents_design_only(x, state):
        return jax.vmap(lambda d: jax.jvp(lambda v: field(v, state), (x,), (d,)), out_axes=(None, 0))(basis)

    return {
        "field": (field, (x0, y)),
        "inner raceway": (inner, bodies),
        "outer raceway": (outer, bodies),
        "flange contacts": (flange, bodies),
        "field + 3 tangents (state and design, as in a solve)": (tangents_state_and_design, (x0, y)),
        "field + 3 tangents (design only)": (tangents_design_only, (x0, y)),
        "outer raceway + 1 tangent": (with_tangent(outer, *bodies), bodies),
        "traction law, all slices of one raceway": (traction, (sliding, loads)),
        "traction law + 1 tangent": (with_tangent(traction, sliding, loads), (sliding, loads)),
        "slice law, all slices of one raceway": (slice_law, (interference,)),
        "slice law + 1 tangent": (with_tangent(slice_law, interference), (interference,)),
    }


def main() -> dict:
    rows = {}
    for name, (fn, args) in programs().items():
        _common.log(f"{NAME}: {name}")
        rows[name] = cost(fn, *args)
    field = rows["field"]
    for row in rows.values():
        row["flops_vs_field"] = row["flops"] / field["flops"]
        row["transcendentals_vs_field"] = row["transcendentals"] / field["transcendentals"]
    solve_like = rows["field + 3 tangents (state and design, as in a solve)"]
    result = {
        "benchmark": NAME,
        "programs": rows,
        "flops_per_tangent_vs_field": (solve_like["flops"] - field["flops"]) / (3 * field["flops"]),
        "transcendentals_per_tangent_vs_field": (solve_like["transcendentals"] - field["transcendentals"])
        / (3 * field["transcendentals"]),
    }
    result["table"] = _common.format_table(
        "XLA cost analysis of the field (reference bearing, quasi-static start)",
        ["program", "flops", "transcendentals", "bytes", "flops / field", "transc. / field"],
        [
            [
                n,
                r["flops"],
                r["transcendentals"],
                r["bytes accessed"],
                r["flops_vs_field"],
                r["transcendentals_vs_field"],
            ]
            for n, r in rows.items()
        ],
    )
    print(result["table"])
    print(
        f"per tangent: {result['flops_per_tangent_vs_field']:.2f} x the field's flops, "
        f"{result['transcendentals_per_tangent_vs_field']:.3f} x its transcendentals"
    )
    result["machine"] = _common.machine_info()
    _common.write_json(NAME, result)
    return result


if __name__ == "__main__":
    main()
