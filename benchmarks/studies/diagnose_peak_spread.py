"""How much does the smooth peak flange PV of one start-up transient move when only the step
sequence changes? (issue 12: the price of the error control's loosenings.)

The smooth peak PV (an 8-norm over contact time, docs/model.md 13) of the 4 ms start-up
transient of tests/test_dynamics.py (reference bearing, default perturbation, 800 samples) is
computed with each error control of `SETTINGS` at `RUNS` tolerances spaced 1 % apart above its
rtol (atol = 1e-3 rtol): the same accuracy asked for, a different sequence of steps. The spread
of those runs is the numerical noise of that error control on this quantity; their median
against the tight setting's (the last of `SETTINGS`) is its bias. A run whose smooth peak PV is
more than `VIOLENT` times the tight median holds an impact the tight runs never show (a roller
corner on the flange: the largest sampled PV with on_arc = 0).

    python benchmarks/studies/diagnose_peak_spread.py    (about 3 min; results/diagnose_peak_spread.json)

The first setting is `solve`'s since 2026-11-25 (third session), chosen by this study; the third
was every solve's before and stays that of settled windows (`prepare_from`; docs/performance.md).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "diagnose_peak_spread"
DURATION, NUM_SAVES = 4e-3, 800  # as tests/test_dynamics.py
RUNS = 8
SPACING = 0.01  # relative spacing of the runs' rtols
VIOLENT = 3.0  # x the tight setting's median smooth peak PV
#: (label, error norm kind, raceway-normal loosening, rotations' loosening, rtol); the last is
#: the tight setting the others are compared with
SETTINGS = (
    ("max norm, raceway-normal x100 (start-up transients: solve)", "max", 100.0, 1.0, 1e-3),
    ("per-roller RMS, raceway-normal x10", "body_rms", 10.0, 1.0, 1e-3),
    ("per-roller RMS, raceway-normal x10, rotations x10 (settled windows)", "body_rms", 10.0, 10.0, 1e-3),
    ("per-roller RMS, raceway-normal x10, rotations x10, rtol 5e-4", "body_rms", 10.0, 10.0, 5e-4),
    ("per-roller RMS, raceway-normal x10, rotations x10, rtol 2e-4", "body_rms", 10.0, 10.0, 2e-4),
    ("max norm, raceway-normal x100, rotations x10", "max", 100.0, 10.0, 1e-3),
    ("tight: max norm, raceway-normal x100, rtol 2e-4", "max", 100.0, 1.0, 2e-4),
)


def compile_run(norm: str):
    """The transient's (smooth peak PV, largest sampled PV, on_arc there, steps) as a compiled
    function of (bearing, op, rtol, raceway_loosen, rotation_loosen) for the norm kind `norm`."""
    import jax
    import jax.numpy as jnp

    import jaxbearing as jb
    from jaxbearing.dynamics import Functionals
    from jaxbearing.run import solve
    from jaxbearing.run._result import smooth_functionals

    def run(bearing, op, rtol, raceway, rotation):
        sol = solve(
            bearing,
            op,
            DURATION,
            num_saves=NUM_SAVES,
            rtol=rtol,
            atol=1e-3 * rtol,
            perturbation=jb.Perturbation(),
            error_norm=norm,
            raceway_loosen=raceway,
            rotation_loosen=rotation,
        )
        peak = smooth_functionals(sol.accumulators, Functionals())[0]
        pv = sol.histories["flange_pv"]
        at = jnp.unravel_index(jnp.argmax(pv), pv.shape)
        return peak, pv[at], sol.histories["on_arc"][at], sol.num_steps, sol.result

    return jax.jit(run)


def main(quick: bool = False) -> dict:
    import numpy as np

    import jaxbearing as jb

    started = time.perf_counter()
    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    runs = 2 if quick else RUNS
    settings = (SETTINGS[2], SETTINGS[-1]) if quick else SETTINGS
    programs = {}
    out = []
    for label, norm, raceway, rotation, rtol in settings:
        if norm not in programs:
            programs[norm] = compile_run(norm)
        rows = []
        for k in range(runs):
            r = rtol * (1 + SPACING * k)
            peak, largest, on_arc, steps, code = programs[norm](bearing, op, r, raceway, rotation)
            if int(code) != 0:
                raise RuntimeError(f"{label}: the solve failed at rtol {r:g}")
            rows.append(
                {
                    "rtol": r,
                    "steps": int(steps),
                    "smooth_peak_pv": float(peak),
                    "largest_sampled_pv": float(largest),
                    "on_arc_at_largest": float(on_arc),
                }
            )
            _common.log(
                f"{label}, rtol {r:.4g}: {rows[-1]['smooth_peak_pv'] / 1e9:.3f} GPa m/s, {int(steps)} steps"
            )
        out.append(
            {
                "label": label,
                "norm": norm,
                "raceway_loosen": raceway,
                "rotation_loosen": rotation,
                "rtol": rtol,
                "runs": rows,
            }
        )
    tight = np.median([r["smooth_peak_pv"] for r in out[-1]["runs"]])
    for s in out:
        peaks = np.array([r["smooth_peak_pv"] for r in s["runs"]])
        violent = peaks > VIOLENT * tight
        calm = peaks[~violent]
        s["mean_steps"] = float(np.mean([r["steps"] for r in s["runs"]]))
        s["violent_runs"] = int(violent.sum())
        s["violent_on_arc"] = [r["on_arc_at_largest"] for r, v in zip(s["runs"], violent) if v]
        s["calm_median_vs_tight"] = float(np.median(calm) / tight) if calm.size else None
        s["calm_min_vs_tight"] = float(calm.min() / tight) if calm.size else None
        s["calm_max_vs_tight"] = float(calm.max() / tight) if calm.size else None
    table = _common.format_table(
        f"Smooth peak PV of the {DURATION * 1e3:g} ms start-up transient, {runs} runs per setting at rtols "
        f"{SPACING:.0%} apart (atol = 1e-3 rtol); tight median {tight / 1e9:.3f} GPa m/s",
        ["error control", "rtol", "mean steps", f"runs > {VIOLENT:g}x tight", "their on_arc", "calm median / tight", "calm min / tight", "calm max / tight"],
        [
            [s["label"], s["rtol"], s["mean_steps"], f"{s['violent_runs']} of {runs}", s["violent_on_arc"] or "-",
             s["calm_median_vs_tight"], s["calm_min_vs_tight"], s["calm_max_vs_tight"]]
            for s in out
        ],
    )  # fmt: skip
    print(table)
    result = {
        "benchmark": NAME,
        "quick": quick,
        "case": {
            "bearing": "reference_bearing(), reference_operating_point(), Perturbation()",
            "duration_s": DURATION,
            "num_saves": NUM_SAVES,
            "runs_per_setting": runs,
            "rtol_spacing": SPACING,
            "violent_factor": VIOLENT,
        },
        "tight_median_smooth_peak_pv": float(tight),
        "settings": out,
        "table": table,
        "wall_s": time.perf_counter() - started,
    }
    if not quick:
        _common.write_json(NAME, result)
    return result


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
