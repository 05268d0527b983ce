"""Would a quasi-static radial equilibrium per roller stop paying for the 62 kHz ringing?
(issue 12, item 2; docs/model.md 13 names it as one admissible treatment.)

The variant, built here and not in the library: every roller's radial position r_b is slaved
to its radial force balance instead of being integrated with its radial velocity,

    0 = F_rad(r_b*) = F.e_rad(r_b*) + m r_b* theta'^2        (paper Eq. 33, r'' = 0, r' = 0).

Each field evaluation takes one Newton step per roller from the radial position the state
carries (r_g) with the derivative from one forward-mode pass of the contact loads seeded on
every roller's r_b at once (a roller's contacts depend on its own r_b only):

    (L, F_rad), (dL, dF) = jvp(r -> (contact loads, F_rad), r_g, 1)
    dr = -F_rad / dF,    r_b* = r_g + dr,    loads at r_b*:  L + dL dr    (linearised),

and the carried position relaxes to the equilibrium, r_g' = (r_b* - r_g) / TAU, so the guess
stays within TAU |dr*/dt| (about 0.1 um) of it and one Newton step is enough. The radial
velocity is held at zero (its rate is zero), so the raceway contact damping sees no radial
approach velocity of the roller. The relaxation's eigenvalue, -1/TAU, is far inside Tsit5's
stability region at the steps the other modes allow.

What it measures (seeds 0-3 of `bench_work_precision_settled`'s settled states, its window of 2
cage revolutions, default tolerances rtol 1e-3, atol 1e-6, the default error norm with the
radial coordinates loosened as in `solve`):
* field evaluations per simulated ms, against the default solve of the same window;
* wall time per simulated ms (the field is dearer: one primal and one tangent of the contacts);
* the four settled flange statistics against the stored tight reference of
  `bench_work_precision_settled` (paired over seeds, the same agreement test).

    python benchmarks/studies/diagnose_radial_elimination.py [--quick]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "diagnose_radial_elimination"
#: relaxation time of the carried radial position towards the equilibrium [s]
TAU = 20e-6
RTOL, ATOL = 1e-3, 1e-6
#: raceway-normal loosening of the error norm (`solve`'s default)
LOOSEN = 100.0
QUICK_WINDOW = 0.5e-3  # [s]
#: smallest radial stiffness a Newton step divides by [N/m per kg: dF/dr / m]
MIN_STIFFNESS = 1e6
#: largest Newton correction of one evaluation [m] (a guess out of contact has almost no
#: stiffness; the relaxation then closes the gap over a few TAU)
MAX_CORRECTION = 5e-6


def _leading(dr, leaf):
    """dr (Z,) broadcast against a per-roller leaf (Z, ...)."""
    return dr.reshape(dr.shape + (1,) * (leaf.ndim - 1))


def quasi_static(y, params):
    """(state with r_b = r_b* and r_b' = 0, contact loads there, r_b* - r_g) of the physical
    state `y` (module docstring)."""
    import equinox as eqx
    import jax
    import jax.numpy as jnp

    from jaxbearing.dynamics._field import _roller_rates, contact_loads

    rollers = eqx.tree_at(lambda r: r.radial_velocity, y.rollers, jnp.zeros_like(y.rollers.radial))
    y = eqx.tree_at(lambda s: s.rollers, y, rollers)

    def at(radial):
        s = eqx.tree_at(lambda s: s.rollers.radial, y, radial)
        loads = contact_loads(s, params)
        accel = _roller_rates(s.rollers, loads, params).radial_velocity  # F_rad / m
        return loads, accel

    r_g = y.rollers.radial
    (loads, accel), (d_loads, d_accel) = jax.jvp(at, (r_g,), (jnp.ones_like(r_g),))
    stiffness = jnp.minimum(d_accel, -MIN_STIFFNESS)  # restoring: d(F_rad/m)/dr < 0
    dr = jnp.clip(-accel / stiffness, -MAX_CORRECTION, MAX_CORRECTION)
    loads = jax.tree_util.tree_map(lambda l, dl: l + dl * _leading(dr, dl), loads, d_loads)
    y = eqx.tree_at(lambda s: s.rollers.radial, y, r_g + dr)
    return y, loads, dr


def quasi_static_rates(y, params):
    """d(state)/dt with the radial coordinates slaved (module docstring)."""
    import equinox as eqx
    import jax.numpy as jnp

    from jaxbearing.dynamics import State
    from jaxbearing.dynamics._field import _cage_rates, _functional_rates, _inner_ring_rates, _roller_rates

    y_star, loads, dr = quasi_static(y, params)
    rollers = _roller_rates(y_star.rollers, loads, params)
    rollers = eqx.tree_at(lambda r: (r.radial, r.radial_velocity), rollers, (dr / TAU, jnp.zeros_like(dr)))
    return State(
        rollers=rollers,
        cage=_cage_rates(y.cage, loads, params),
        inner_ring=_inner_ring_rates(y.inner_ring, loads, params),
        accumulators=_functional_rates(loads.flange, params.functionals),
    )


def _field(t, y_scaled, args):
    y = args.scaling.unscale(t, y_scaled)
    return args.scaling.scale_rate(quasi_static_rates(y, args.params))


def _samples(t, y_scaled, args):
    """The saved quantities of `bench_work_precision_settled.SAVED` at the slaved state."""
    y = args.scaling.unscale(t, y_scaled)
    _, loads, _ = quasi_static(y, args.params)
    fl = loads.flange
    return {
        "t": t,
        "flange_force": fl.normal_force,
        "flange_pv": fl.pv,
        "flange_sliding_speed": fl.sliding_speed,
        "cage_speed": y.cage.speed,
    }


def newton_residual(params, start):
    """How well one Newton step balances the rollers (module docstring): with the carried
    position at `start`'s (the worst case, a ringing settled state rather than the relaxed
    guess), the largest |F_rad(r_b*)| over the rollers, from the exact (not linearised) loads
    at r_b*, against the largest |F_rad| at `start` and the largest correction |dr| [m]."""
    import equinox as eqx
    import jax.numpy as jnp

    from jaxbearing.dynamics._field import _roller_rates, contact_loads

    start = eqx.tree_at(lambda s: s.rollers.radial_velocity, start, jnp.zeros_like(start.rollers.radial))

    def radial_force(y):
        loads = contact_loads(y, params)
        return params.bearing.roller_mass * _roller_rates(y.rollers, loads, params).radial_velocity

    y_star, _, dr = quasi_static(start, params)
    return jnp.max(jnp.abs(radial_force(y_star))), jnp.max(jnp.abs(radial_force(start))), jnp.max(jnp.abs(dr))


def window_solve(
    params, start, duration, rtol, atol, loosen, controller=None, rotation_loosen=1.0, *, num_saves: int
):
    """Tsit5 of the quasi-static-radial field from the physical state `start` (radial velocity
    set to zero), with the arguments and returns of `bench_work_precision_settled.window_solve`
    (the max norm's raceway-normal loosening `loosen`, the step `controller`, the rotations'
    loosening `rotation_loosen`), so that `run_tsit5` runs both. jit-able."""
    import diffrax
    import equinox as eqx
    import jax
    import jax.numpy as jnp
    from bench_work_precision_settled import library_controller

    from jaxbearing.run import prepare_from, result_code
    from jaxbearing.run._step_control import DT0, raceway_normal_norm, step_controller

    start = eqx.tree_at(lambda s: s.rollers.radial_velocity, start, jnp.zeros_like(start.rollers.radial))
    _, args, y0, _ = prepare_from(params, start, rtol, atol)
    pcoeff, icoeff, safety, factormax = library_controller() if controller is None else controller
    sol = diffrax.diffeqsolve(
        diffrax.ODETerm(_field),
        diffrax.Tsit5(),
        t0=0.0,
        t1=duration,
        dt0=DT0,
        y0=y0,
        args=args,
        # sampled as the settled benchmark and the library sample: states in the loop, the
        # flange quantities after it
        saveat=diffrax.SaveAt(ts=jnp.linspace(0.0, duration, num_saves)),
        stepsize_controller=step_controller(
            rtol,
            atol,
            raceway_normal_norm(y0, loosen, "max", rotation_loosen),
            pcoeff=pcoeff,
            icoeff=icoeff,
            safety=safety,
            factormax=factormax,
        ),
        max_steps=2_000_000,
        throw=False,
    )
    hist = jax.vmap(_samples, in_axes=(0, 0, None))(sol.ts, sol.ys, args)
    return hist, result_code(sol.result), sol.stats["num_steps"], sol.stats["num_rejected_steps"]


def main(quick: bool = False) -> dict:
    import jax
    import jax.numpy as jnp
    import numpy as np
    from bench_work_precision import SAMPLE_DT, STATS, window_statistics
    from bench_work_precision_settled import (
        SEEDS,
        compile_window_solve,
        library_controller,
        paired_over_seeds,
        run_tsit5,
        settled_start,
        stored_reference,
    )

    import jaxbearing as jb
    from jaxbearing.dynamics import Functionals, Params

    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    params = Params(bearing=bearing, operating=op, functionals=Functionals())
    omega_kin = float(jb.kinematic_cage_speed(bearing, op))
    seeds = SEEDS[:1] if quick else SEEDS
    settled = {s: settled_start(bearing, op, s) for s in seeds}
    starts = {s: jax.tree_util.tree_map(jnp.asarray, v["state"]) for s, v in settled.items()}
    rpm = float(np.mean([v["info"]["last_revolution_cage_speed_rpm"] for v in settled.values()]))
    window = QUICK_WINDOW if quick else 2 * 60.0 / rpm
    num_saves = int(round(window / SAMPLE_DT)) + 1
    window = (num_saves - 1) * SAMPLE_DT
    ms = window * 1e3

    def qs(p, s, d, r, a, loosen, c, rotation):
        return window_solve(p, s, d, r, a, loosen, tuple(c), rotation, num_saves=num_saves)

    f = jnp.asarray
    compiled = {
        "quasi-static radial": _common.compile_jit(
            qs,
            params,
            starts[seeds[0]],
            f(window),
            f(RTOL),
            f(ATOL),
            f(LOOSEN),
            f(library_controller()),
            f(1.0),
        ),
        "default": compile_window_solve(params, starts[seeds[0]], num_saves),
    }

    residual = jax.jit(newton_residual)
    newton = {}
    for s in seeds:
        after, before, correction = (float(v) for v in residual(params, starts[s]))
        newton[str(s)] = {"max_residual_N": after, "max_imbalance_N": before, "max_correction_m": correction}
        _common.log(f"{NAME}: seed {s}: one Newton step, |F_rad| {before:.3g} N -> {after:.3g} N")

    rows = {label: {} for label in compiled}
    for s in seeds:
        for label, (program, _) in compiled.items():
            r = run_tsit5(program, params, starts[s], window, RTOL, ATOL, LOOSEN)
            r["statistics"] = window_statistics(r.pop("hist"), 0.0, omega_kin)
            r["evaluations_per_ms"] = r["evaluations"] / ms
            r["wall_s_per_ms"] = r["wall_s"] / ms
            rows[label][s] = r
            _common.log(
                f"{NAME}: seed {s} {label}: ok {r['ok']}, {r['evaluations_per_ms']:.0f} evals/ms, "
                f"{r['wall_s_per_ms']:.2f} s/ms, mean PV {r['statistics']['mean_pv'] / 1e6:.0f} MPa m/s"
            )

    case = {
        "seeds": list(seeds),
        "window_s": window,
        "num_saves": num_saves,
        "inner_speed_rpm": float(jb.rad_s_to_rpm(op.inner_speed)),
        "radial_load_N": float(op.radial_load),
        "reference": {"rtol": 1e-7, "atol": 1e-10, "method": "Tsit5, max norm (loosen 1)"},
    }
    reference = None if quick else stored_reference(case)
    summary = {}
    for label, per_seed in rows.items():
        summary[label] = {
            "evaluations_per_ms": float(np.mean([r["evaluations_per_ms"] for r in per_seed.values()])),
            "wall_s_per_ms": float(np.mean([r["wall_s_per_ms"] for r in per_seed.values()])),
            "all_ok": all(r["ok"] for r in per_seed.values()),
        }
        if reference is not None:
            summary[label]["against_reference"] = {
                st: paired_over_seeds(
                    [per_seed[s]["statistics"][st] for s in seeds],
                    [reference[str(s)]["statistics"][st] for s in seeds],
                )
                for st in STATS
            }
    q, d = summary["quasi-static radial"], summary["default"]
    result = {
        "benchmark": NAME,
        "quick": quick,
        "case": case,
        "tau_s": TAU,
        "newton_step_at_start": newton,
        "compile_s": {label: c[1] for label, c in compiled.items()},
        "rows": {k: {str(s): v for s, v in per.items()} for k, per in rows.items()},
        "summary": summary,
        "fewer_evaluations_than_default": d["evaluations_per_ms"] / q["evaluations_per_ms"],
        "wall_ratio_default_over_quasi_static": d["wall_s_per_ms"] / q["wall_s_per_ms"],
        "reference_found": reference is not None,
    }
    table_rows = []
    for label, s in summary.items():
        agree = s.get("against_reference")
        table_rows.append(
            [
                label,
                s["evaluations_per_ms"],
                s["wall_s_per_ms"],
                "n/a" if agree is None else all(a["agrees"] for a in agree.values()),
            ]
        )
    result["table"] = _common.format_table(
        f"Quasi-static radial elimination ({len(seeds)} seeds, {ms:.2f} ms, rtol 1e-3)",
        ["variant", "evals/ms", "wall s/ms", "agrees with reference"],
        table_rows,
    )
    print(result["table"])
    if not quick:
        _common.write_json(NAME, result)
    return result


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="seed 0, 0.5 ms, nothing written")
    args = parser.parse_args()
    started = time.perf_counter()
    main(quick=args.quick)
    _common.log(f"{NAME}: {time.perf_counter() - started:.0f} s")
