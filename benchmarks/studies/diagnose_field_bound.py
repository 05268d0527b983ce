"""How much faster could the field get by the means issue 12 item 3 names? Upper bounds, measured.

Item 3 asks for a field >= 1.5x faster through "the slice law and traction with fewer
transcendentals ... and a `jax.custom_jvp` for the slice-load and traction laws". This script
bounds what any such rewrite can gain, by timing the field with those laws replaced by
transcendental-free stand-ins. The stand-ins are physically wrong (the numbers they give mean
nothing); they keep the data flow, shapes and fusions of the real field, so their time is a
lower bound on the time of any exact rewrite of the laws.

Variants, each traced and compiled in this process with module attributes patched at trace time
(restored after), timed in alternating rounds so that the shared machine's load falls on all
alike; the minimum over rounds is reported:

* ``as built``: `physical_rates` as it is;
* ``laws without transcendentals``: the raceway and pocket slice law `line_power`
  (exp, log1p, log, exp per slice) -> max(delta, 0)^2 scaled, the Hunt-Crossley positivity
  guard (a softplus: exp and log1p per slice, all contacts) -> its linear argument, and the
  traction curve kappa(s) (one exp per slice) -> A + B s;
* ``slice power only``, ``damping guard only``, ``traction curve only``: one stand-in at a time;
* ``raceways free``: `raceway_contact` -> zero forces of the right shapes, i.e. the field with
  no raceway work at all (how much of the field's time the raceways are).

For each, ``field_us`` is one evaluation inside a compiled `lax.fori_loop` (no dispatch) and
``tangents_us`` the field with three forward-mode tangents in the state and the design
(R_end, theta_f, Delta_bf), as inside a `diffrax.ForwardMode` solve (`bench_field_speed.py`).

It also times the two contact laws item 3 names over one raceway's slices, alone and with one
tangent (what a tangent of each law costs against its value), and single elementwise f64 operations over 1612 elements (the slices of both raceways,
26 rollers x 31 slices x 2) inside a compiled loop: the unit costs of XLA CPU's exp, log, log1p,
pow, sqrt, tanh, division and a multiply-add on this machine.

    python benchmarks/studies/diagnose_field_bound.py [--rounds N] [--no-tangents]

Results: results/diagnose_field_bound.json.

Measured 2026-11-25 (fifth session; the 2-core machine shared and noisy, the same program's
minimum over rounds moving by +-15 % between runs):

* committed run (`--rounds 9`): as built 268 us; laws without transcendentals 213 us (1.26x);
  slice power only 1.24x, damping guard only 1.29x, traction curve only 1.11x (the parts do
  not add up within the noise); raceways free 88 us (3.03x). Field + 3 tangents 2007 us, 1.22x
  faster without the laws' transcendentals. Earlier runs the same session gave 1.59x, 1.53x and
  1.23x for all laws, 3.8-4.2x without the raceways.
* unit costs (ns an element): multiply-add 0.2, divide 0.43, sqrt 0.74, exp 2.0, tanh 1.7,
  log 4.2-5.4, log1p 6.5-9.4, power 10/9 13.7-21.1. XLA's float64 exp is vectorised; log,
  log1p and pow cost 2-10x more.
* the laws' tangents: slice power (hand-written `custom_jvp`) 0.61-1.04x its value, traction law
  (JAX's own tangent) 0.76-0.99x.

So the contact laws' transcendentals are a fifth to a third of the field; an exact law keeps at
least an exp and a log a slice, and removing even those (wrong physics) does not reliably give
the 1.5x. The rest of the field is the raceway geometry and force assembly (the raceways are
two thirds to three quarters of it).
"""

from __future__ import annotations

import contextlib
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402
from bench_field_speed import EVALS, reference_field  # noqa: E402  (the same field and loop)

NAME = "diagnose_field_bound"
UNIT_ELEMENTS = 1612  # 2 raceways x 26 rollers x 31 slices
UNIT_ITERS = 2000


@contextlib.contextmanager
def _patched(replacements):
    """Set module attributes [(module, name, value)] for the duration (restored after). JAX's
    tracing caches are cleared on the way in and out: `physical_rates` and `contact_loads` are
    `jax.jit` functions, whose cached traces would otherwise ignore the patch."""
    import jax

    saved = [(m, n, getattr(m, n)) for m, n, _ in replacements]
    jax.clear_caches()
    try:
        for m, n, v in replacements:
            setattr(m, n, v)
        yield
    finally:
        for m, n, v in saved:
            setattr(m, n, v)
        jax.clear_caches()


def _law_stand_ins(which=("power", "guard", "kappa")):
    import jax.numpy as jnp

    import jaxbearing.contact._line as line
    import jaxbearing.contact._traction as traction
    import jaxbearing.flange._contact as flange_contact
    import jaxbearing.forces._cage_lands as lands
    import jaxbearing.forces._pocket as pocket
    import jaxbearing.forces._raceway as raceway

    def power(delta, width):
        return 1e6 * jnp.maximum(delta, 0.0) ** 2 + 0.0 * width

    def guard(rate, alpha=0.0, width=0.0):
        return 1.0 + 1.5 * alpha * rate

    def kappa(s, lub):
        return lub.traction_a + lub.traction_b * s

    out = []
    if "power" in which:
        out.append((line, "line_power", power))
    if "kappa" in which:
        out.append((traction, "traction_coefficient", kappa))
    if "guard" in which:
        out += [(m, "hunt_crossley_factor", guard) for m in (raceway, pocket, lands, flange_contact)]
    return out


def _raceways_free():
    import jax.numpy as jnp

    import jaxbearing.dynamics._field as field_module
    from jaxbearing.forces import RacewayContact

    def free(bearing, ring_sign, raceway_radius, p, e, v, w, c, vr, wr, **_):
        z = 0.0 * p[0]
        s = jnp.zeros(bearing.num_slices) + z
        s3 = jnp.zeros((bearing.num_slices, 3)) + z
        v3 = jnp.zeros(3) + z
        return RacewayContact(
            interference=s, slice_loads=s, elastic_slice_loads=s, normal_load=z, contact_points=s3,
            normals=s3, sliding_velocity=s3, slice_traction=s3, mean_sliding_speed=z,
            force_on_roller=v3, moment_on_roller=v3, force_on_ring=v3, moment_on_ring=v3,
        )  # fmt: skip

    return [(field_module, "raceway_contact", free)]


VARIANTS = {
    "as built": lambda: [],
    "laws without transcendentals": _law_stand_ins,
    "slice power only": lambda: _law_stand_ins(("power",)),
    "damping guard only": lambda: _law_stand_ins(("guard",)),
    "traction curve only": lambda: _law_stand_ins(("kappa",)),
    "raceways free": _raceways_free,
}


def _programs(with_tangents: bool) -> dict:
    """{(variant, kind): compiled no-argument program of EVALS evaluations}."""
    import jax

    _, _, x0, y0, field, tangents, loop = reference_field()

    def looped(fn):
        return loop(fn).lower().compile()

    kinds = {"field_us": field, **({"tangents_us": tangents} if with_tangents else {})}
    programs, counts = {}, {}
    for variant, replacements in VARIANTS.items():
        with _patched(replacements()):
            cost = jax.jit(field).lower(x0, y0).compile().cost_analysis()
            cost = cost[0] if isinstance(cost, list) else cost
            counts[variant] = {k: float(cost.get(k, 0.0)) for k in ("flops", "transcendentals")}
            for kind, fn in kinds.items():
                _common.log(f"{NAME}: compiling {variant} / {kind}")
                programs[(variant, kind)] = looped(fn)
    if len({tuple(c.values()) for c in counts.values()}) != len(counts):
        raise RuntimeError(f"a variant compiled to the same program as another (patch not traced): {counts}")
    return programs, counts


def _unit_costs() -> dict:
    """ns per f64 element of single elementwise operations (module docstring), min of 5."""
    import jax
    import jax.numpy as jnp

    ops = {
        "multiply-add": lambda x: x * x + 1.0,
        "divide": lambda x: 1.0 / x,
        "sqrt": jnp.sqrt,
        "exp": jnp.exp,
        "tanh": jnp.tanh,
        "log": jnp.log,
        "log1p": jnp.log1p,
        "power 10/9": lambda x: x ** (10.0 / 9.0),
    }
    x0 = jnp.linspace(0.1, 2.0, UNIT_ELEMENTS)
    out = {}
    for name, op in ops.items():
        loop = jax.jit(lambda x, op=op: jax.lax.fori_loop(0, UNIT_ITERS, lambda i, y: 1e-3 * op(y) + y, x))
        best = min(_common.time_repeats(lambda: loop(x0), 5))
        out[name] = 1e9 * best / (UNIT_ITERS * UNIT_ELEMENTS)
    return out


def _law_tangent_costs() -> dict:
    """us per call of the slice power and the traction law over all slices of one raceway
    (26 x 31), alone and with one forward-mode tangent in every argument (min of 5): what a
    tangent of each law costs against its value (issue 12 item 3: "a tangent costs about one
    primal")."""
    import jax
    import jax.numpy as jnp

    import jaxbearing as jb
    from jaxbearing.contact import line_power, traction_force

    lub = jb.reference_bearing().lubricant
    shape = (26, 31)
    delta = jnp.linspace(-3e-6, 5e-6, shape[0] * shape[1]).reshape(shape)
    width = jnp.full(shape, 1e-9)
    sliding = jnp.stack([jnp.linspace(-0.5, 0.7, delta.size).reshape(shape)] * 3, axis=-1)
    load = jnp.full(shape, 10.0)
    laws = {
        "slice power": (line_power, (delta, width)),
        "traction law": (lambda u, q: traction_force(u, q, lub), (sliding, load)),
    }
    out = {}
    for name, (law, args) in laws.items():
        ones = tuple(jnp.ones_like(a) for a in args)
        programs = {
            "value_us": lambda a, law=law: law(*a),
            "value_and_tangent_us": lambda a, law=law, ones=ones: jax.jvp(law, a, ones),
        }
        row = {}
        for kind, fn in programs.items():

            def body(i, acc, a, fn=fn):
                # the arguments depend on the carry, so XLA cannot hoist the law out of the loop
                moved = jax.tree_util.tree_map(lambda x: x + 1e-30 * acc, a)
                return acc + 1e-30 * sum(jnp.sum(x) for x in jax.tree_util.tree_leaves(fn(moved)))

            loop = jax.jit(
                lambda a, body=body: jax.lax.fori_loop(0, UNIT_ITERS, lambda i, c: body(i, c, a), 0.0)
            )
            row[kind] = 1e6 * min(_common.time_repeats(lambda: loop(args), 5)) / UNIT_ITERS
        row["tangent_vs_value"] = (row["value_and_tangent_us"] - row["value_us"]) / row["value_us"]
        out[name] = row
    return out


def main(argv: list[str]) -> dict:
    rounds = int(_common.option_value(argv, "--rounds") or 5)
    programs, counts = _programs(with_tangents="--no-tangents" not in argv)
    times = {key: [] for key in programs}
    for r in range(rounds):
        _common.log(f"{NAME}: round {r + 1}/{rounds}")
        for key, program in programs.items():
            program().block_until_ready()
            start = time.perf_counter()
            program().block_until_ready()
            times[key].append(1e6 * (time.perf_counter() - start) / EVALS)
    rows = {}
    for (variant, kind), ts in times.items():
        rows.setdefault(variant, {"xla_field_counts": counts[variant]})[kind] = min(ts)
        rows[variant][kind + "_all_rounds"] = ts
    built = rows["as built"]
    for row in rows.values():
        for kind in ("field_us", "tangents_us"):
            if kind in row:
                row[kind.replace("_us", "_speedup_vs_as_built")] = built[kind] / row[kind]
    units = _unit_costs()
    laws = _law_tangent_costs()
    result = {
        "benchmark": NAME,
        "evals_per_timing": EVALS,
        "rounds": rounds,
        "variants": rows,
        "unit_costs_ns": units,
        "law_tangent_costs": laws,
    }
    result["table"] = (
        _common.format_table(
            "field time with the contact laws' transcendentals removed (min over alternating rounds)",
            [
                "variant",
                "flops",
                "transc.",
                "field [us]",
                "field speed-up",
                "field + 3 tangents [us]",
                "speed-up",
            ],
            [
                [
                    v,
                    r["xla_field_counts"]["flops"],
                    r["xla_field_counts"]["transcendentals"],
                    r["field_us"],
                    r["field_speedup_vs_as_built"],
                    r.get("tangents_us"),
                    r.get("tangents_speedup_vs_as_built"),
                ]  # fmt: skip
                for v, r in rows.items()
            ],
        )
        + "\n"
        + _common.format_table(
            f"XLA CPU f64 unit costs over {UNIT_ELEMENTS} elements",
            ["operation", "ns / element"],
            list(units.items()),
        )
        + "\n"
        + _common.format_table(
            "contact laws over one raceway's slices (26 x 31): value, value + 1 tangent",
            ["law", "value [us]", "value + tangent [us]", "tangent / value"],
            [[n, r["value_us"], r["value_and_tangent_us"], r["tangent_vs_value"]] for n, r in laws.items()],
        )
    )
    print(result["table"])
    result["machine"] = _common.machine_info()
    _common.write_json(NAME, result)
    return result


if __name__ == "__main__":
    main(sys.argv[1:])
