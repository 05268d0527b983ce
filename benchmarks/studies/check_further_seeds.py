"""Does a found design keep clear of the corner on seeds beyond its verification? (issue 35,
item 6) ``python benchmarks/studies/check_further_seeds.py``.

Re-simulates one design from the skid start on further unseen seeds (settled, 4-revolution
windows) at one operating point and reports its corner contact (share of contact time,
revolutions and seeds that reached the corner with their Clopper-Pearson bounds), its dynamic
corner margin on the expectation and on the 95 % prediction bound of one revolution
(`jaxbearing.run.max_contact_radius_bound`), and its mean, peak and tail PV.

Default: the 3-speed default search's design (results/optimise_3speed_default_run.json: R_end
103.008 mm, theta_f 1.5506 deg, Delta_bf 0.14 mm) at its worst speed, 30,000 rpm, seeds
2000-2007 (the search used 0-3, its verification 1000-1007); about 2 minutes on 2 cores.
Options: `--design R_MM,THETA_DEG,CLEARANCE_MM`, `--speed-rpm V`, `--seeds K`, `--first-seed S`,
`--results-dir DIR`. Results: results/check_further_seeds.json.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]
import _common  # noqa: E402

NAME = "check_further_seeds"
DESIGN = (103.008394027782, 1.5506259780347063, 0.13999927706228385)  # mm, deg, mm


def _scaled(est: dict, unit: float) -> dict:
    return {k: (v / unit if isinstance(v, float) else v) for k, v in est.items()}


def main(
    design=DESIGN, speed_rpm: float = 30000.0, seeds: int = 8, first_seed: int = 2000, results_dir=None
) -> dict:
    import numpy as np

    import jaxbearing as jb
    from jaxbearing.flange import DesignVariables
    from jaxbearing.run import available_cpus

    t0 = time.perf_counter()
    op = dataclasses.replace(jb.reference_operating_point(), inner_speed=jb.rpm_to_rad_s(speed_rpm))
    r, t, c = design
    d = DesignVariables.from_array(np.array([r * 1e-3, math.radians(t), c * 1e-3]))
    _common.log(f"{NAME}: {design} at {speed_rpm:.0f} rpm, seeds {first_seed}-{first_seed + seeds - 1}")
    m = jb.steady_design_metrics(
        jb.reference_bearing(),
        op,
        d,
        seeds=seeds,
        window_revs=4,
        first_seed=first_seed,
        workers=available_cpus(),
    )
    data = {
        "design_mm_deg_mm": list(design),
        "speed_rpm": speed_rpm,
        "seeds": m.seeds,
        "settled": m.settled,
        "corner_contact_share": m.corner_contact_share,
        "corner_contact_bound": m.summary["corner_contact_bound"],
        "corner_margin_mm": _scaled(m.corner_margin, 1e-3),
        "corner_margin_bound_mm": m.corner_margin_bound * 1e3,
        "peak_pv_GPa_m_s": _scaled(m.summary["flange_pv_Pa_m_s"]["max"], 1e9),
        "mean_pv_GPa_m_s": _scaled(m.mean_pv, 1e9),
        "tail_pv_GPa_m_s": _scaled(m.summary["flange_pv_contact_time_Pa_m_s"]["tail95"], 1e9),
        "wall_s": time.perf_counter() - t0,
    }
    b = data["corner_contact_bound"]
    _common.log(
        f"{NAME}: corner contact in {b['revolutions_with_corner_contact']} of {b['revolutions']} revolutions "
        f"(per revolution <= {b['per_revolution_upper95']:.3f}, upper 95 %); corner margin "
        f"{data['corner_margin_mm']['value']:.3f} mm, on the prediction bound {data['corner_margin_bound_mm']:.3f} mm; "
        f"peak PV {data['peak_pv_GPa_m_s']['value']:.2f} GPa m/s"
    )
    _common.write_json(NAME, data, results_dir)
    return data


if __name__ == "__main__":
    argv = sys.argv
    given = _common.option_value(argv, "--design")
    main(
        design=tuple(float(v) for v in given.split(",")) if given else DESIGN,
        speed_rpm=float(_common.option_value(argv, "--speed-rpm") or 30000.0),
        seeds=int(_common.option_value(argv, "--seeds") or 8),
        first_seed=int(_common.option_value(argv, "--first-seed") or 2000),
        results_dir=_common.option_value(argv, "--results-dir"),
    )
