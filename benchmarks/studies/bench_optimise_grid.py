"""Optimiser against brute force (issue 5 acceptance): on the reference bearing at 20,000 rpm and
1000 N, minimise the smooth peak flange PV over (R_end, theta_f) inside the design zone with
the `optimise` search (multi-start projected augmented Lagrangian, forward-mode gradients), and
evaluate a brute-force grid over the same bounds (R_end 60-120 mm x theta_f 1.0-2.0 deg, at
least 15 x 15) with the same model. Delta_bf is held at the reference 0.15 mm in both, so that the grid and
the search cover the same design space.

Records both results, both costs (model evaluations; wall time, compile excluded where it can
be separated) in benchmarks/results/optimise_vs_grid.json and prints a table.

A model evaluation of the search is one dynamic solve carrying three forward-mode tangents
(value and gradient); one of the grid is a plain solve (value only). Infeasible grid points
are not solved (their margins are static and cheap), so the grid's count is its feasible points.

`main(quick)`: quick=True runs a 6 x 6 grid and 2 starts x 8 iterations (a smoke test of the
harness); quick=False the full comparison: 15 x 15 grid, 4 starts x 15 iterations. Both use the
`optimise` defaults (0.3 ms per evaluation from the seated start with 1 mrad skew scatter,
rtol 1e-3, atol 1e-6).

Run: .venv/bin/python benchmarks/studies/bench_optimise_grid.py [--quick]
"""

from __future__ import annotations

import json
import math
import pathlib
import sys
import time

import numpy as np

RESULTS = pathlib.Path(__file__).resolve().parents[1] / "results"
sys.path.insert(0, str(RESULTS.parent))

from _common import machine_info  # noqa: E402

CLEARANCE_MM = 0.15  # the reference design's Delta_bf


def main(quick: bool = True) -> dict:
    import jaxbearing as jb
    import optimise as opt
    from optimise._problem import DEFAULT_DURATION

    if quick:
        n_grid, starts, iterations, duration = 6, 2, 8, DEFAULT_DURATION
    else:
        n_grid, starts, iterations, duration = 15, 4, 15, DEFAULT_DURATION
    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    bounds = opt.bounds_from_engineering([60, 120], [1.0, 2.0], [CLEARANCE_MM, CLEARANCE_MM])
    problem = opt.make_problem(bearing, op, bounds=bounds, duration=duration)

    t0 = time.perf_counter()
    res = opt.search(problem, num_starts=starts, num_iterations=iterations)
    t_search = time.perf_counter() - t0
    grid = opt.grid_search(problem, n_grid, n_grid, CLEARANCE_MM * 1e-3)

    def design(x):
        return (
            None
            if x is None
            else {
                "end_radius_mm": float(x[0]) * 1e3,
                "layback_angle_deg": math.degrees(float(x[1])),
                "axial_clearance_mm": float(x[2]) * 1e3,
            }
        )

    out = {
        "bearing": "reference (jaxbearing.reference_bearing), 20,000 rpm, 1000 N, gravity on",
        "duration_ms": duration * 1e3,
        "bounds": bounds.engineering(),
        "objective": "smooth peak flange PV [GPa m/s] (p-norm over contact time)",
        "search": {
            "method": "multi-start projected augmented Lagrangian (optax Adam), forward-mode gradients",
            "starts": starts,
            "iterations": iterations,
            "status": res.status,
            "feasible": bool(res.feasible),
            "design": design(res.design),
            "objective_GPa_m_s": float(res.objective),
            "margins_mm": None if res.margins is None else (np.asarray(res.margins) * 1e3).tolist(),
            "start_objective_GPa_m_s": float(res.start_objective),
            "model_evaluations": res.num_model_evaluations,
            "model_evaluation_kind": "solve + 3 forward-mode tangents",
            "wall_time_s": t_search,
            "compile_time_s_estimate": res.compile_time_s,
        },
        "grid": {
            "shape": [n_grid, n_grid],
            "feasible_points": int(np.sum(grid["feasible"])),
            "design": design(grid["best_design"]),
            "objective_GPa_m_s": grid["best_objective"],
            "model_evaluations": grid["num_model_evaluations"],
            "model_evaluation_kind": "solve (value only)",
            "wall_time_s": grid["wall_time_s"],
        },
        "search_no_worse_than_grid": bool(res.feasible and res.objective <= grid["best_objective"] + 1e-3),
        "no_worse_tolerance_GPa_m_s": 1e-3,
        "quick": quick,
        "machine": machine_info(),
    }
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "optimise_vs_grid.json").write_text(json.dumps(out, indent=2))
    s, g = out["search"], out["grid"]
    print(
        f"optimiser vs {n_grid} x {n_grid} grid, Delta_bf {CLEARANCE_MM} mm, {duration * 1e3:g} ms per evaluation"
    )
    print(
        f"{'':<10}{'PV [GPa m/s]':>14}{'R_end [mm]':>12}{'theta_f [deg]':>15}{'evaluations':>13}{'wall [s]':>10}"
    )
    for name, r in (("search", s), ("grid", g)):
        d = r["design"] or {"end_radius_mm": float("nan"), "layback_angle_deg": float("nan")}
        print(
            f"{name:<10}{r['objective_GPa_m_s']:>14.4f}{d['end_radius_mm']:>12.2f}"
            f"{d['layback_angle_deg']:>15.3f}{r['model_evaluations']:>13d}{r['wall_time_s']:>10.1f}"
        )
    print(f"search no worse than grid: {out['search_no_worse_than_grid']}")
    return out


if __name__ == "__main__":
    main(quick="--quick" in sys.argv[1:])
