"""How long must a design search's next iterate settle? (issue 35, item 4)
``python benchmarks/studies/study_continuation_settle.py``.

The search continues every start from the settled states of its last design. With the settling
verdict (`settle="auto"`) a continuing member needs at least `VERDICT_MIN_REVS` = 4 revolutions
before its window of 2: two thirds of an evaluation's simulated time. This study measures what
a fixed, shorter settling of n revolutions (`continuation_settle_revs`, n = 0 and 1) changes in
the objective J (the mean flange PV over contact time of the window) at each speed of the
envelope:

1. K seeds settle from the skid start at design A (verdict) and measure their window;
2. from each seed's final state, design B = A + one search step continues with the same seed
   three times: settling by the verdict, and a fixed 1 and 0 revolutions;
3. per speed: J_B(n) - J_B(verdict) over the seeds (mean, standard error, Student-t 95 %
   interval; the two runs share their start state and seed but not their window's time, so
   the pairs are only partly correlated), against the step's own effect J_B(verdict) - J_A.

A (80 mm / 1.6 deg / 0.15 mm) is the default search's start; B (84.8 mm / 1.68 deg) its first
step (0.08 of the box in R_end and theta_f). Defaults: 10,000, 20,000 and 30,000 rpm, 8 seeds,
11 slices. Options: `--seeds K`, `--slices N`, `--speeds 10000,20000,30000`,
`--variants 1,0` (the fixed revolutions tried), `--results-dir DIR`. Results: results/study_continuation_settle.json.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]
import _common  # noqa: E402

NAME = "study_continuation_settle"
DESIGN_A = (80.0, 1.6, 0.15)  # R_end [mm], theta_f [deg], Delta_bf [mm]
DESIGN_B = (84.8, 1.68, 0.15)
VARIANTS = (None, 1, 0)  # None: the settling verdict; n: a fixed n revolutions (`--variants 1,0`)


def _difference(a, b) -> dict:
    """mean, standard error and Student-t 95 % interval of a - b over paired seeds
    (`design.paired_central_difference` with 2h = 1)."""
    from scipy import stats

    from jaxbearing.design import paired_central_difference

    mean, se, n = paired_central_difference(a, b, 0.5)
    half = float(stats.t.ppf(0.975, n - 1)) * se
    return {"mean": mean, "stderr": se, "ci95": [mean - half, mean + half], "seeds": n}


def main(
    seeds: int = 8,
    slices: int = 11,
    speeds=(10000.0, 20000.0, 30000.0),
    variants=VARIANTS[1:],
    results_dir=None,
) -> dict:
    import numpy as np

    import jaxbearing as jb
    from jaxbearing.design import steady_design_metrics_points
    from jaxbearing.flange import DesignVariables
    from jaxbearing.run import available_cpus

    started = time.perf_counter()
    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=slices)
    ops = [
        dataclasses.replace(jb.reference_operating_point(), inner_speed=jb.rpm_to_rad_s(v)) for v in speeds
    ]

    def design(r, t, c):
        return DesignVariables.from_array(np.array([r * 1e-3, math.radians(t), c * 1e-3]))

    kw = dict(seeds=seeds, window_revs=2, settle="auto", workers=available_cpus())
    _common.log(f"{NAME}: design A at {len(ops)} speeds x {seeds} seeds from the skid start")
    t0 = time.perf_counter()
    base = steady_design_metrics_points(bearing, ops, design(*DESIGN_A), **kw)
    times = {"A_from_skid": time.perf_counter() - t0}
    continuing = {}
    for n in (None, *variants):
        label = "verdict" if n is None else f"{n}_revs"
        _common.log(f"{NAME}: design B continuing, settling: {label}")
        t0 = time.perf_counter()
        continuing[label] = steady_design_metrics_points(
            bearing,
            ops,
            design(*DESIGN_B),
            initial_states=[m.final_states for m in base],
            continuation_settle_revs=n,
            **kw,
        )
        times[label] = time.perf_counter() - t0
    rows = []
    for k, v in enumerate(speeds):
        a = base[k].objective_per_seed
        ref = continuing["verdict"][k]
        row = {
            "speed_rpm": v,
            "J_A_Pa_m_s": base[k].objective,
            "J_B_verdict_Pa_m_s": ref.objective,
            "step_effect": _difference(ref.objective_per_seed, a),
            "settle_ms_verdict": ref.summary["settle_time_ms"],
            "settled_verdict": bool(ref.settled),
        }
        for label, runs in continuing.items():
            if label != "verdict":
                row[f"J_B_{label}_Pa_m_s"] = runs[k].objective
                row[f"{label}_minus_verdict"] = _difference(
                    runs[k].objective_per_seed, ref.objective_per_seed
                )
                row[f"settle_ms_{label}"] = runs[k].summary["settle_time_ms"]
        rows.append(row)
        _common.log(
            f"{NAME}: {v:.0f} rpm: J_A {base[k].objective['value']:.4g}, J_B verdict {ref.objective['value']:.4g} "
            f"(settle {row['settle_ms_verdict']:.1f} ms), step {row['step_effect']['mean']:.3g} "
            f"+- {row['step_effect']['stderr']:.2g}; "
            + "; ".join(
                f"{n} revs - verdict {row[f'{n}_revs_minus_verdict']['mean']:.3g} "
                f"+- {row[f'{n}_revs_minus_verdict']['stderr']:.2g}"
                for n in variants
            )
        )
    data = {
        "seeds": seeds,
        "num_slices": slices,
        "design_A": DESIGN_A,
        "design_B": DESIGN_B,
        "rows": rows,
        "wall_s_per_call": times,
        "wall_s": time.perf_counter() - started,
    }
    _common.write_json(NAME, data, results_dir)
    return data


if __name__ == "__main__":
    argv = sys.argv
    v = _common.option_value(argv, "--speeds")
    main(
        seeds=int(_common.option_value(argv, "--seeds") or 8),
        slices=int(_common.option_value(argv, "--slices") or 11),
        speeds=tuple(float(x) for x in v.split(",")) if v else (10000.0, 20000.0, 30000.0),
        variants=tuple(int(x) for x in (_common.option_value(argv, "--variants") or "1,0").split(",")),
        results_dir=_common.option_value(argv, "--results-dir"),
    )
