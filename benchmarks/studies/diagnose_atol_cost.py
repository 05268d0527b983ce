"""What the default absolute tolerance (atol 1e-6 of the scaled state: 10 nm, 10 um/s,
0.01 rad/s since the state's scales were chosen for it; docs/model.md 13) costs and gains beside
the earlier one (atol 1e-10 today: 1 pm, 1 nm/s, 1 urad/s), and one per-call cost found while
measuring the gradient ratio (issue 12).

1. Roller inner-raceway loads against a tight reference (Tsit5, rtol 1e-7, atol 1e-14 =
   1e-16 m): (a) the first 0.3 ms from the quasi-static start (31 samples), where every
   deviation from the nominal orbit is near zero and atol alone sets the tolerance; (b) 0.1 ms
   from seed 0's settled state of `bench_work_precision_settled` (51 samples; `settled_start`,
   cached). Largest and mean absolute difference over loaded samples, the time-mean of the
   total load, and the flange forces.
2. Steps of 4 ms from the quasi-static start, arc and corner ends, at both atols.
4. The steps of `bench_gradients`' case (0.3 ms, rtol 1e-6, `seated_perturbation`) in a plain
   and a forward-mode solve, at atol 1e-9 (`GRADIENT_ATOL`) and 1e-13.
3. A plain solve of 1 us and of 0.3 ms (rtol 1e-6, atol 1e-9, `seated_perturbation`) compiled
   with the bearing as an argument and with the bearing closed over (its arrays constants of the
   program): wall time per call, minimum of 5; and the same for the quasi-static start alone
   (`initial_state`), where the difference lay (0.202 against 0.037 s per call) until
   `quasi_static` put an optimization barrier on the bearing (2026-11-25: XLA specialised its
   Newton loops on the closed-over constants).

    python benchmarks/studies/diagnose_atol_cost.py      (about 4 min; results/diagnose_atol_cost.json)
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "diagnose_atol_cost"
ATOLS = {"default (10 nm)": 1e-6, "earlier (1 pm)": 1e-10}
REF_RTOL, REF_ATOL = 1e-7, 1e-14


def _min_time(fn, *args, repeats: int = 5) -> float:
    import jax

    jax.block_until_ready(fn(*args))
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        jax.block_until_ready(fn(*args))
        times.append(time.perf_counter() - t)
    return min(times)


def _load_errors(run, loads_ref, flange_ref) -> dict:
    """{atol label: differences of `run(rtol 1e-3, atol)`'s loads from the reference}."""
    import numpy as np

    out = {}
    for label, atol in ATOLS.items():
        loads, flange, steps = run(1e-3, atol)
        d = np.abs(loads - loads_ref)
        out[label] = {
            "steps": steps,
            "max_abs_N": float(d.max()),
            "max_relative_to_largest_load": float(d.max() / loads_ref.max()),
            "mean_abs_over_loaded_N": float(d[loads_ref > 1.0].mean()),
            "time_mean_total_load_difference_N": float(abs(loads.sum(1).mean() - loads_ref.sum(1).mean())),
            "flange_force_max_abs_N": float(np.abs(flange - flange_ref).max()),
        }
    return out


def main() -> dict:
    import diffrax
    import jax
    import jax.numpy as jnp
    import numpy as np
    from bench_work_precision_settled import settled_start

    import jaxbearing as jb
    from jaxbearing.design import GRADIENT_ATOL, GRADIENT_HORIZON, GRADIENT_RTOL, seated_perturbation
    from jaxbearing.dynamics import Functionals, Params
    from jaxbearing.flange import DesignVariables
    from jaxbearing.run import solve
    from jaxbearing.run._settle import solve_from

    b, op = jb.reference_bearing(), jb.reference_operating_point()
    result = {"benchmark": NAME, "case": "reference bearing, 20,000 rpm, 1000 N", "atols": ATOLS}

    def from_start(rtol, atol):
        sol = solve(b, op, 3e-4, num_saves=31, rtol=rtol, atol=atol)
        h = jax.tree_util.tree_map(np.asarray, sol.histories)
        return h["roller_inner_load"], h["flange_force"], int(sol.num_steps)

    _common.log(f"{NAME}: raceway loads from the quasi-static start")
    ref = from_start(REF_RTOL, REF_ATOL)
    result["loads_from_quasi_static_start_0.3ms"] = _load_errors(from_start, ref[0], ref[1])

    params = Params(bearing=b, operating=op, functionals=Functionals())
    start = jax.tree_util.tree_map(jnp.asarray, settled_start(b, op, 0)["state"])
    settled = jax.jit(
        lambda r, a: solve_from(params, start, 1e-4, num_saves=51, rtol=r, atol=a, max_steps=2_000_000)
    )

    def from_settled(rtol, atol):
        h, _, _, n = settled(jnp.asarray(rtol), jnp.asarray(atol))
        return np.asarray(h["roller_inner_load"]), np.asarray(h["flange_force"]), int(n)

    _common.log(f"{NAME}: raceway loads from a settled state")
    ref = from_settled(REF_RTOL, REF_ATOL)
    result["loads_from_settled_state_0.1ms"] = _load_errors(from_settled, ref[0], ref[1])

    _common.log(f"{NAME}: steps over 4 ms, arc and corner ends")
    result["steps_4ms_from_quasi_static_start"] = {
        ends: {
            label: int(jb.simulate(bb, op, duration=4e-3, atol=atol, progress=False).num_steps)
            for label, atol in ATOLS.items()
        }
        for ends, bb in (("arc", b), ("corner", b.with_flat_ends()))
    }

    _common.log(f"{NAME}: bearing as an argument against closed over")
    pert = seated_perturbation(b)
    kw = dict(num_saves=0, rtol=GRADIENT_RTOL, atol=GRADIENT_ATOL, max_steps=100_000, perturbation=pert)
    per_call = {}
    for duration in (1e-6, 3e-4):
        argument = jax.jit(lambda bb, d=duration: solve(bb, op, d, **kw).num_steps)
        closed = jax.jit(lambda x, d=duration: solve(b, op, d, **kw).num_steps)
        per_call[f"{duration * 1e3:g} ms"] = {
            "bearing_argument_s": _min_time(argument, b),
            "bearing_closed_over_s": _min_time(closed, jnp.zeros(())),
            "steps": int(argument(b)),
        }
    # where the closed-over solve's extra time goes: the quasi-static start alone
    from jaxbearing.run._simulate import initial_state

    argument = jax.jit(lambda bb: initial_state(bb, op, pert))
    closed = jax.jit(lambda x: initial_state(b, op, pert))
    per_call["quasi-static start alone"] = {
        "bearing_argument_s": _min_time(argument, b),
        "bearing_closed_over_s": _min_time(closed, jnp.zeros(())),
    }
    result["plain_solve_per_call"] = per_call

    _common.log(f"{NAME}: steps of the plain and the forward-mode solve (bench_gradients' case)")
    x0 = DesignVariables.of(b).as_array()

    def steps(x, base, atol, adjoint=None):
        bb = DesignVariables.from_array(x).apply(base)
        sol = solve(
            bb,
            op,
            GRADIENT_HORIZON,
            **{**kw, "atol": atol, "perturbation": seated_perturbation(bb)},
            adjoint=adjoint,
        )
        return sol.num_steps

    grad_steps = {}
    for atol in (GRADIENT_ATOL, 1e-13):
        plain = jax.jit(steps)(x0, b, atol)
        tangent = jax.jit(
            lambda x, base, a=atol: jax.jvp(
                lambda y: steps(y, base, a, diffrax.ForwardMode()), (x,), (jnp.eye(3)[0],)
            )[0]
        )(x0, b)
        grad_steps[f"atol {atol:g}"] = {"plain": int(plain), "forward_mode": int(tangent)}
    result["gradient_case_steps"] = grad_steps
    print(json.dumps(result, indent=1))
    _common.write_json(NAME, result)
    return result


if __name__ == "__main__":
    main()
