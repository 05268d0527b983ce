"""The frozen-load estimate of the peak statistic against common-random-number differences, at
reduced size (issue 35, item 3): ``python benchmarks/studies/bench_peak_gradient.py``.

At each of three designs (R_end / theta_f = 80 mm / 1.6 deg, the reference bearing's own,
100 mm / 1.4 deg and 70 mm / 1.8 deg; Delta_bf 0.15 mm),
for the statistic "mean", "peak" (the p-mean of PV over contact time, p = 8) and "tail" (the mean
of its worst 5 %, the estimator's threshold the 95th percentile of its own samples;
`jaxbearing.design.STATISTICS`): 3 seeds settle (a fixed 5 ms from the skid start, which lands
on the plateau; 2-revolution windows; 11 slices), then the designs with theta_f +- 0.15 deg and
with R_end +- 5 % continue from the same states with the same seeds (3.5 us, 2 revolutions):
the paired central difference of the per-seed objective, with its standard error, against the
frozen-load estimate from the same settled states (`frozen_load_gradient(...,
statistic=...)`). The acceptance of issue 35 item 3: where the difference is significant
(|FD| > 3 SE), the same sign and within 30 %. The same procedure as the default suite's mean
check (tests/test_steady_gradient.py). About 2.5 minutes per design and statistic on the 2-core
CPU. `--statistics peak` (or mean, tail, or several: "mean,peak"), `--designs 1,2` (indices into
DESIGNS), `--seeds K`, `--slices N` (the full size: `--seeds 8 --slices 31`, minutes on one GPU).
Every design's members are one call of the steady-running engine per step (settle, frozen-load
gradients, shifted designs). Results: results/bench_peak_gradient.json (all three designs, mean and peak; else
with the indices, the statistics if others, and other sizes with `_<N>slices_<K>seeds`).
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]
import _common  # noqa: E402

NAME = "bench_peak_gradient"
#: R_end [mm], theta_f [deg] (Delta_bf 0.15 mm): the reference bearing's own design (80 mm /
#: 1.6 deg), and the other two designs of the full-size mean study (bench_steady_gradient.py)
DESIGNS = (None, (100.0, 1.4), (70.0, 1.8))
SEEDS = 3


def check(bearing, op, designs, statistic: str, seeds: int, workers: int) -> list[list[dict]]:
    """Per design, per variable (theta_f, R_end): the CRN difference and the frozen-load
    estimate. Every design's seeds settle in one call of the steady-running engine, their
    frozen-load gradients are one call, and every shifted design continues in one call (one
    vmapped program each on an accelerator, one process per core on a CPU)."""
    import numpy as np

    from jaxbearing.design import (
        frozen_load_gradients,
        paired_central_difference,
        steady_design_metrics_points,
    )
    from jaxbearing.flange import DesignVariables

    kw = dict(seeds=seeds, window_revs=2, workers=workers, statistic=statistic)
    dvs = [DesignVariables.from_array(x) for x in designs]
    base = steady_design_metrics_points(bearing, [op] * len(dvs), dvs, settle=0.005, **kw)
    grads = frozen_load_gradients(
        [(bearing, op, d, m.sample_states) for d, m in zip(dvs, base)], workers=workers, statistic=statistic
    )
    steps = ((1, lambda x: math.radians(0.15)), (0, lambda x: 0.05 * x[0]))
    shifted, starts = [], []
    for x, m in zip(designs, base):
        for i, step in steps:
            for sign in (1.0, -1.0):
                xs = np.array(x, dtype=float)
                xs[i] += sign * step(x)
                shifted.append(DesignVariables.from_array(xs))
                starts.append(m.final_states)
    per = steady_design_metrics_points(
        bearing, [op] * len(shifted), shifted, settle=0.0035, initial_states=starts, **kw
    )
    out = []
    for j, (x, m, g) in enumerate(zip(designs, base, grads)):
        rows = []
        for k, (i, step) in enumerate(steps):
            plus, minus = per[4 * j + 2 * k], per[4 * j + 2 * k + 1]
            fd, se, _ = paired_central_difference(
                np.asarray(plus.objective_per_seed), np.asarray(minus.objective_per_seed), step(x)
            )
            est = float(g.gradient[i])
            significant = abs(fd) > 3 * se
            rows.append(
                {
                    "variable": ("end_radius", "layback_angle")[i],
                    "objective_Pa_m_s": m.objective["value"],
                    "crn_difference": fd,
                    "crn_stderr": se,
                    "frozen_load": est,
                    "frozen_load_stderr": float(g.gradient_stderr[i]),
                    "significant": significant,
                    "relative_difference": (est - fd) / abs(fd),
                    "agrees": bool(
                        significant and np.sign(est) == np.sign(fd) and abs(est - fd) <= 0.3 * abs(fd)
                    ),
                }
            )
        out.append(rows)
    return out


def main(statistics=("mean", "peak"), designs=(0, 1, 2), seeds: int = SEEDS, slices: int = 11) -> dict:
    import numpy as np

    import jaxbearing as jb
    from jaxbearing.flange import DesignVariables
    from jaxbearing.run import available_cpus

    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=slices)
    op = jb.reference_operating_point()
    xs = []
    for design in [DESIGNS[i] for i in designs]:
        x = np.array(DesignVariables.of(bearing).as_array(), dtype=float)
        if design is not None:
            x[0], x[1] = design[0] * 1e-3, math.radians(design[1])
        xs.append(x)
    out = []
    for statistic in statistics:
        t0 = time.perf_counter()
        for x, rows in zip(xs, check(bearing, op, xs, statistic, seeds, workers=available_cpus())):
            for r in rows:
                r |= {
                    "statistic": statistic,
                    "end_radius_mm": x[0] * 1e3,
                    "layback_angle_deg": math.degrees(x[1]),
                }
                _common.log(
                    f"{NAME}: {statistic} {r['variable']} at {r['end_radius_mm']:.1f} mm / "
                    f"{r['layback_angle_deg']:.2f} deg: CRN {r['crn_difference']:.3e} +- {r['crn_stderr']:.1e}, "
                    f"frozen {r['frozen_load']:.3e} ({100 * r['relative_difference']:+.0f} %), agrees {r['agrees']}"
                )
            out += rows
        _common.log(f"{NAME}: {statistic}: {time.perf_counter() - t0:.0f} s")
    data = {"seeds": seeds, "num_slices": slices, "rows": out}
    name = NAME + ("" if tuple(designs) == (0, 1, 2) else "_" + "".join(map(str, designs)))
    if tuple(statistics) != ("mean", "peak"):
        name += "_" + "_".join(statistics)
    if (seeds, slices) != (SEEDS, 11):
        name += f"_{slices}slices_{seeds}seeds"
    _common.write_json(name, data)
    return data


if __name__ == "__main__":
    chosen = _common.option_value(sys.argv, "--statistics")
    which = _common.option_value(sys.argv, "--designs")
    seeds_given = _common.option_value(sys.argv, "--seeds")
    slices_given = _common.option_value(sys.argv, "--slices")
    main(
        tuple(chosen.split(",")) if chosen else ("mean", "peak"),
        tuple(int(i) for i in which.split(",")) if which else (0, 1, 2),
        int(seeds_given) if seeds_given else SEEDS,
        int(slices_given) if slices_given else 11,
    )
