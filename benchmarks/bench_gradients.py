"""Gradient cost (issue 8, item 4; issue 5): value and gradient of the smooth peak flange PV with
respect to the three design variables (R_end, theta_f, Delta_bf) on the reference bearing at
20,000 rpm and 1000 N, by

- forward mode: `jax.jvp` through `diffrax.ForwardMode()`, three tangents vmapped (one solve
  carrying the primal and three tangents),
- checkpointed reverse mode: `jax.value_and_grad` through diffrax's `RecursiveCheckpointAdjoint`,
- central finite differences: six extra forward solves,

each timed relative to one forward solve (compile excluded; compile times reported separately),
and their agreement (relative to the largest entry). Same horizon and tolerances as the
acceptance test (`jaxbearing.design.GRADIENT_HORIZON`, `GRADIENT_RTOL`, `GRADIENT_ATOL`).

Writes benchmarks/results/gradients.json and prints a table. Timings: the four methods are run
round-robin (2 repeats with quick=True, 5 otherwise) and the minimum of each is reported (the
least-disturbed call on a shared machine), with the median alongside.

Run: .venv/bin/python benchmarks/bench_gradients.py [--quick] [--atol A]
(`--atol`: instead of `GRADIENT_ATOL`, results to gradients_atol_<A>.json; e.g. 1e-13, the
physical tolerance `GRADIENT_ATOL` meant before the state's scales changed)
"""

from __future__ import annotations

import functools
import json
import pathlib
import sys
import time

import numpy as np

RESULTS = pathlib.Path(__file__).resolve().parent / "results"
sys.path.insert(0, str(RESULTS.parent))

from _common import machine_info, option_value  # noqa: E402


def _compile_and_first(f, *args):
    """(output, time of the first call = compile + one run)."""
    import jax

    t0 = time.perf_counter()
    out = jax.block_until_ready(f(*args))
    return out, time.perf_counter() - t0


def _interleaved(fns: dict, x, repeats: int) -> dict:
    """Run times (s) of already-compiled `fns` on x, interleaved round-robin `repeats` times so
    that a changing machine load disturbs every method alike: {name: (min, median)}."""
    import jax

    times = {k: [] for k in fns}
    for _ in range(repeats):
        for k, f in fns.items():
            t0 = time.perf_counter()
            jax.block_until_ready(f(x))
            times[k].append(time.perf_counter() - t0)
    return {k: (float(np.min(v)), float(np.median(v))) for k, v in times.items()}


def main(quick: bool = True, atol: float | None = None) -> dict:
    import diffrax
    import jax
    import jax.numpy as jnp

    import jaxbearing as jb
    from jaxbearing.design import GRADIENT_ATOL, GRADIENT_HORIZON, GRADIENT_RTOL, seated_perturbation
    from jaxbearing.flange import DesignVariables
    from jaxbearing.run import flange_functionals

    repeats = 2 if quick else 5
    bearing = jb.reference_bearing()
    op = jb.reference_operating_point()
    x0 = DesignVariables.of(bearing).as_array()
    name = "gradients" if atol is None else f"gradients_atol_{atol:g}"
    atol = GRADIENT_ATOL if atol is None else atol
    kw = dict(rtol=GRADIENT_RTOL, atol=atol, max_steps=100_000)

    # the bearing is an argument of every compiled program, not a closed-over constant: closing
    # over its arrays cost about 0.17 s per call of the plain solve (docs/performance.md)
    def pv(x, base, adjoint=None):
        b = DesignVariables.from_array(x).apply(base)
        return flange_functionals(
            b, op, GRADIENT_HORIZON, perturbation=seated_perturbation(b), adjoint=adjoint, **kw
        )[0]

    forward_jit = jax.jit(pv)

    @jax.jit
    def fwd_mode_jit(x, base):
        val, tang = jax.vmap(
            lambda e: jax.jvp(lambda y: pv(y, base, diffrax.ForwardMode()), (x,), (e,)), out_axes=(None, 0)
        )(jnp.eye(3))
        return val, tang

    rev_mode_jit = jax.jit(jax.value_and_grad(pv))
    forward, fwd_mode, rev_mode = (
        functools.partial(f, base=bearing) for f in (forward_jit, fwd_mode_jit, rev_mode_jit)
    )

    value, first_fwd = _compile_and_first(forward, x0)
    (v_f, g_f), first_jf = _compile_and_first(fwd_mode, x0)
    (v_r, g_r), first_rv = _compile_and_first(rev_mode, x0)

    rel = 1e-4

    def central_fd(x):
        g = []
        for i in range(3):
            h = rel * float(x[i])
            e = jnp.zeros(3).at[i].set(h)
            g.append((float(forward(x + e)) - float(forward(x - e))) / (2 * h))
        return float(forward(x)), np.asarray(g)

    _, g_fd = central_fd(x0)
    t = _interleaved(
        {"forward": forward, "fwd_mode": fwd_mode, "rev_mode": rev_mode, "fd": central_fd}, x0, repeats
    )
    # minimum over repeats: the least-disturbed call on a shared machine (timeit convention)
    t_fwd, t_jf, t_rv, t_fd = (t[k][0] for k in ("forward", "fwd_mode", "rev_mode", "fd"))
    c_fwd, c_jf, c_rv = (max(0.0, a - b) for a, b in ((first_fwd, t_fwd), (first_jf, t_jf), (first_rv, t_rv)))
    g_fd = np.asarray(g_fd)
    g_f, g_r = np.asarray(g_f), np.asarray(g_r)
    scale = np.abs(g_fd).max()

    def agree(g):
        return float(np.abs(g - g_fd).max() / scale)

    faster = "forward" if t_jf <= t_rv else "reverse"
    ratio = max(t_jf, t_rv) / min(t_jf, t_rv)
    out = {
        "bearing": "reference (jaxbearing.reference_bearing), 20,000 rpm, 1000 N, gravity on",
        "horizon_ms": GRADIENT_HORIZON * 1e3,
        "rtol": GRADIENT_RTOL,
        "atol": atol,
        "initial_scatter": "seated_perturbation (outermost roller at zero flange interference)",
        "peak_pv_GPa_m_s": float(value) / 1e9,
        "variables": ["end_radius [m]", "layback_angle [rad]", "axial_clearance [m]"],
        "gradient_forward_mode": g_f.tolist(),
        "gradient_reverse_mode": g_r.tolist(),
        "gradient_central_fd": g_fd.tolist(),
        "fd_relative_step": rel,
        "forward_solve_s": t_fwd,
        "timing": "minimum over interleaved repeats (median in times_min_median_s)",
        "times_min_median_s": t,
        "repeats": repeats,
        "methods": {
            "forward_mode": {
                "time_s": t_jf,
                "relative_to_forward_solve": t_jf / t_fwd,
                "compile_s": c_jf,
                "max_rel_diff_to_fd": agree(g_f),
            },
            "reverse_mode_checkpointed": {
                "time_s": t_rv,
                "relative_to_forward_solve": t_rv / t_fwd,
                "compile_s": c_rv,
                "max_rel_diff_to_fd": agree(g_r),
            },
            "central_fd": {
                "time_s": t_fd,
                "relative_to_forward_solve": t_fd / t_fwd,
                "compile_s": c_fwd,
                "max_rel_diff_to_fd": 0.0,
            },
        },
        "forward_solve_compile_s": c_fwd,
        "faster_ad_mode": faster,
        "faster_by": ratio,
        "quick": quick,
        "machine": machine_info(),
    }
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / f"{name}.json").write_text(json.dumps(out, indent=2))
    print(
        f"value + gradient of smooth peak PV in (R_end, theta_f, Delta_bf); horizon "
        f"{GRADIENT_HORIZON * 1e3:g} ms, rtol {GRADIENT_RTOL:g}, atol {atol:g}"
    )
    print(
        f"one forward solve: {t_fwd:.3f} s (compile {c_fwd:.1f} s); peak PV {float(value) / 1e9:.4g} GPa m/s"
    )
    print(f"{'method':<28}{'time [s]':>10}{'x forward':>11}{'compile [s]':>13}{'max rel diff to FD':>20}")
    for name, m in out["methods"].items():
        print(
            f"{name:<28}{m['time_s']:>10.3f}{m['relative_to_forward_solve']:>11.2f}"
            f"{m['compile_s']:>13.1f}{m['max_rel_diff_to_fd']:>20.2e}"
        )
    print(f"faster AD mode: {faster}, by {ratio:.2f}x")
    return out


if __name__ == "__main__":
    given = None
    text = option_value(sys.argv, "--atol")
    if text is not None:
        try:
            given = float(text)
        except ValueError:
            given = float("nan")
        if not 0.0 < given < 1.0:
            raise SystemExit(f"--atol = {text!r}: must be a number in (0, 1)")
    main(quick="--quick" in sys.argv[1:], atol=given)
