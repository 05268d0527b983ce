"""What the envelope's active set saves in a 3-speed design search (issue 35, item 4):
``python benchmarks/studies/bench_envelope_active_set.py``.

The same steady search (`optimise._steady.steady_search`: 10,000, 20,000 and 30,000 rpm, smooth
max with T = 0.1 GPa m/s, one start at the default start design) twice in this process: with
every operating point simulated every iteration (`skip_weight = 0`, the baseline) and with the
active set (`skip_weight = 1e-3`, `recheck_every = 3`, the defaults). Reported: wall time and
simulated ms of each (ratio against the baseline of this run), the points simulated per
iteration, and the found design and objective of both (the quantities a user reads: the
active set is worth having only if they agree). No verification (the same in both).

Defaults (reduced size, about 20 minutes on 2 cores): 11 slices, 4 seeds, 4 iterations, window 2.
Options: `--slices N`, `--seeds K`, `--iterations I`, `--results-dir DIR`.
Results: results/bench_envelope_active_set.json.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]
import _common  # noqa: E402

NAME = "bench_envelope_active_set"
SPEEDS = [10000.0, 20000.0, 30000.0]


def main(slices: int = 11, seeds: int = 4, iterations: int = 4, results_dir=None) -> dict:
    import numpy as np

    import jaxbearing as jb
    from optimise import make_problem
    from optimise._steady import SteadySettings, steady_search

    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=slices)
    problem = make_problem(bearing, jb.reference_operating_point(), speeds_rpm=SPEEDS)
    runs = {}
    for label, skip in (("every_point", 0.0), ("active_set", 1e-3)):
        settings = SteadySettings(seeds=seeds, window_revs=2, skip_weight=skip)
        _common.log(f"{NAME}: {label}")
        t0 = time.perf_counter()
        res = steady_search(problem, settings, num_starts=1, num_iterations=iterations, verify=False)
        wall = time.perf_counter() - t0
        h = res.history
        runs[label] = {
            "wall_s": wall,
            "simulated_ms": float(np.sum(h["simulated_ms"])),
            "settled_ensembles": res.num_evaluations,
            "points_simulated": np.asarray(h["points_simulated"])[:, 0].tolist(),
            "objective_GPa_m_s": np.asarray(h["objective"])[:, 0].tolist(),
            "ci95_GPa_m_s": np.asarray(h["ci"])[:, 0].tolist(),
            "end_radius_mm": (np.asarray(h["x"])[:, 0, 0] * 1e3).tolist(),
            "layback_angle_deg": np.degrees(np.asarray(h["x"])[:, 0, 1]).tolist(),
            "best_design": None if res.design is None else np.asarray(res.design).tolist(),
            "best_objective_GPa_m_s": res.objective,
            "best_ci95": None if res.objective_ci is None else list(res.objective_ci),
        }
        _common.log(
            f"{NAME}: {label}: {wall:.0f} s, {runs[label]['simulated_ms']:.0f} simulated ms, "
            f"objective {runs[label]['objective_GPa_m_s']}"
        )
    base, new = runs["every_point"], runs["active_set"]
    data = {
        "speeds_rpm": SPEEDS,
        "num_slices": slices,
        "seeds": seeds,
        "iterations": iterations,
        "runs": runs,
        "wall_ratio": new["wall_s"] / base["wall_s"],
        "simulated_ratio": new["simulated_ms"] / base["simulated_ms"],
    }
    _common.log(f"{NAME}: wall ratio {data['wall_ratio']:.3f}, simulated ratio {data['simulated_ratio']:.3f}")
    _common.write_json(NAME, data, results_dir)
    return data


if __name__ == "__main__":
    argv = sys.argv
    main(
        slices=int(_common.option_value(argv, "--slices") or 11),
        seeds=int(_common.option_value(argv, "--seeds") or 4),
        iterations=int(_common.option_value(argv, "--iterations") or 4),
        results_dir=_common.option_value(argv, "--results-dir"),
    )
