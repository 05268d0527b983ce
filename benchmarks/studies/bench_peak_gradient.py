"""The frozen-load estimate of the peak statistic against common-random-number differences, at
reduced size (issue 35, item 3): ``python benchmarks/studies/bench_peak_gradient.py``.

At each of three designs (R_end / theta_f = 80 mm / 1.6 deg, the reference bearing's own,
100 mm / 1.4 deg and 70 mm / 1.8 deg; Delta_bf 0.15 mm),
for the statistic "mean" and "peak" (the p-mean of PV over contact time, p = 8,
`jaxbearing.design.STATISTICS`): 3 seeds settle (a fixed 5 us from the skid start, which lands
on the plateau; 2-revolution windows; 11 slices), then the designs with theta_f +- 0.15 deg and
with R_end +- 5 % continue from the same states with the same seeds (3.5 us, 2 revolutions):
the paired central difference of the per-seed objective, with its standard error, against the
frozen-load estimate from the same settled states (`frozen_load_gradient(...,
statistic=...)`). The acceptance of issue 35 item 3: where the difference is significant
(|FD| > 3 SE), the same sign and within 30 %. The same procedure as the default suite's mean
check (tests/test_steady_gradient.py). About 2.5 minutes per design and statistic on the 2-core
CPU. `--statistics peak` (or mean, or both: "mean,peak"), `--designs 1,2` (indices into
DESIGNS). Results: results/bench_peak_gradient.json (all three designs; else with the indices).
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


def check(bearing, op, x, statistic: str, workers: int) -> list[dict]:
    """Per variable (theta_f, R_end): the CRN difference and the frozen-load estimate."""
    import numpy as np

    from jaxbearing.design import frozen_load_gradient, paired_central_difference, steady_design_metrics
    from jaxbearing.flange import DesignVariables

    kw = dict(seeds=SEEDS, window_revs=2, workers=workers, statistic=statistic)
    base = steady_design_metrics(bearing, op, DesignVariables.from_array(x), settle=0.005, **kw)
    g = frozen_load_gradient(
        bearing, op, DesignVariables.from_array(x), base.sample_states, workers=workers, statistic=statistic
    )
    rows = []
    for i, h in ((1, math.radians(0.15)), (0, 0.05 * x[0])):
        per = []
        for sign in (1.0, -1.0):
            xs = x.copy()
            xs[i] += sign * h
            m = steady_design_metrics(
                bearing,
                op,
                DesignVariables.from_array(xs),
                settle=0.0035,
                initial_states=base.final_states,
                **kw,
            )
            per.append(np.asarray(m.objective_per_seed))
        fd, se, _ = paired_central_difference(per[0], per[1], h)
        est = float(g.gradient[i])
        significant = abs(fd) > 3 * se
        rows.append(
            {
                "variable": ("end_radius", "layback_angle")[i],
                "objective_Pa_m_s": base.objective["value"],
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
    return rows


def main(statistics=("mean", "peak"), designs=(0, 1, 2)) -> dict:
    import numpy as np

    import jaxbearing as jb
    from jaxbearing.flange import DesignVariables

    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    op = jb.reference_operating_point()
    out = []
    for design in [DESIGNS[i] for i in designs]:
        x = np.array(DesignVariables.of(bearing).as_array(), dtype=float)
        if design is not None:
            x[0], x[1] = design[0] * 1e-3, math.radians(design[1])
        for statistic in statistics:
            t0 = time.perf_counter()
            rows = check(bearing, op, x, statistic, workers=2)
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
            _common.log(f"{NAME}: {time.perf_counter() - t0:.0f} s")
    data = {"seeds": SEEDS, "num_slices": 11, "rows": out}
    _common.write_json(NAME + ("" if tuple(designs) == (0, 1, 2) else "_" + "".join(map(str, designs))), data)
    return data


if __name__ == "__main__":
    chosen = _common.option_value(sys.argv, "--statistics")
    which = _common.option_value(sys.argv, "--designs")
    main(
        tuple(chosen.split(",")) if chosen else ("mean", "peak"),
        tuple(int(i) for i in which.split(",")) if which else (0, 1, 2),
    )
