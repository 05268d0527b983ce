"""A found design against the reference on seeds no search or verification used.

    python benchmarks/studies/study_unseen_seeds.py --design 84.8,1.680,0.150 \
        --speeds-rpm 20000,30000 --seeds 8 --first-seed 5000 --window-revs 4 --name NAME

A design is three values (R_end [mm], theta_f [deg], Delta_bf [mm]) or a profile's eight (R_end
[mm], e [mm], R_cor [mm], 1/R_rib [1/m], h_t [mm], theta_f [deg], H_rf [mm], Delta_bf [mm]; the
keys of `optimise.ProfileBounds`); `--reference` (default: the reference bearing's own design)
is the design it is compared with, e.g. the three-variable optimum against a profile.
Both designs at every speed, every seed one member of one call of the steady-running engine
(skid start, settling by the verdict, a window of `--window-revs` cage revolutions), the
reference bearing at 1000 N. Per design and speed: mean and peak flange PV with 95 % intervals,
the corner-contact share of contact time, how many revolutions reached the limited circle, and
the corner-contact risk per revolution with its bounds (`jaxbearing.run.corner_risk`). Writes
the results file `--name` names (under benchmarks/results) with the command, the commit and the
machine.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import pathlib
import subprocess
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve()
sys.path.insert(0, str(HERE.parents[1]))

import _common  # noqa: E402


def _gpa(est) -> dict:
    """An estimate in GPa m/s, {"value", "ci95_low", "ci95_high"} (None for NaN)."""
    d = est.as_dict()
    return {k: None if d[k] is None else d[k] / 1e9 for k in ("value", "ci95_low", "ci95_high")}


def _row(m) -> dict:
    st = m.statistics
    maxima = np.concatenate([np.asarray(r, float) for r in m.contact_radius_maxima] or [np.zeros(0)])
    return {
        "mean_pv_GPa_m_s": _gpa(m.mean_pv),
        "peak_pv_GPa_m_s": _gpa(st.flange_pv_Pa_m_s.max) if st is not None else None,
        "corner_contact_share": m.corner_contact_share.as_dict(),
        "revolutions": int(maxima.size),
        "revolutions_at_the_corner": int(np.sum(maxima > m.limited_circle_radius_m)),
        "largest_contact_radius_mm": float(maxima.max() * 1e3) if maxima.size else None,
        "limited_circle_radius_mm": float(m.limited_circle_radius_m * 1e3),
        "corner_risk": None if st is None or st.corner_risk is None else st.corner_risk.as_dict(),
        "friction_power_W": None if st is None else st.flange_friction_power_W.total.as_dict(),
        "flash_temperature_K": None if st is None else st.flange_flash_temperature_K.max.as_dict(),
        "film_parameter_p05": None if st is None else st.film_parameter.p05.as_dict(),
        # what the mean PV is made of: per contact event (the mean per revolution of the events'
        # largest values) the normal load, the peak pressure and the sliding speed, the events per
        # revolution and the mean contact height
        "event_load_N": None if st is None else st.flange_force_N.mean.as_dict(),
        "event_pressure_GPa": None if st is None else _gpa(st.flange_pressure_Pa.mean),
        "event_sliding_speed_m_s": None if st is None else st.flange_sliding_velocity_m_s.mean.as_dict(),
        "events_per_revolution": None if st is None else st.flange_contact_events_per_rev.as_dict(),
        "contact_height_mm": None
        if st is None
        else {
            k: (None if v is None else v * 1e3)
            for k, v in st.contact_height_m.mean.as_dict().items()
            if k != "n"
        },
        "settled": m.settled,
        "seeds": m.seeds,
    }


def _design(values):
    """A design from its engineering values: three (`DesignVariables`) or a profile's eight."""
    import jax.numpy as jnp

    from jaxbearing.flange import variables_from_array
    from optimise._bounds import DESIGN_TABLE, PROFILE_TABLE

    table = {3: DESIGN_TABLE, 8: PROFILE_TABLE}.get(len(values))
    if table is None:
        raise SystemExit(f"--design: {len(values)} values, expected 3 or 8")
    return variables_from_array(jnp.asarray([v * var.si for v, var in zip(values, table)]))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument(
        "--design", required=True, help="R_end [mm], theta_f [deg], Delta_bf [mm], or a profile's eight"
    )
    p.add_argument("--reference", default="", help="the design compared with (default: the bearing's own)")
    p.add_argument("--speeds-rpm", default="20000,30000")
    p.add_argument("--seeds", type=int, default=8)
    p.add_argument("--first-seed", type=int, default=5000)
    p.add_argument("--window-revs", type=int, default=4)
    p.add_argument("--slices", type=int, default=31)
    p.add_argument("--name", default="unseen_seeds")
    args = p.parse_args(argv)

    import jaxbearing as jb
    from jaxbearing.design import steady_design_metrics_points
    from jaxbearing.flange import DesignVariables
    from jaxbearing.geometry import rpm_to_rad_s
    from jaxbearing.run import SteadySettings

    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=args.slices)
    values = [float(v) for v in args.design.split(",")]
    found = _design(values)
    reference = _design([float(v) for v in args.reference.split(",")]) if args.reference else None
    reference = DesignVariables.of(bearing) if reference is None else reference
    speeds = [float(v) for v in args.speeds_rpm.split(",")]
    op0 = jb.reference_operating_point()
    ops = [dataclasses.replace(op0, inner_speed=np.asarray(rpm_to_rad_s(v))) for v in speeds]
    settings = SteadySettings(seeds=args.seeds, window_revs=args.window_revs)
    t0 = time.perf_counter()
    metrics = steady_design_metrics_points(
        bearing, ops * 2, [reference] * len(ops) + [found] * len(ops), settings, first_seed=args.first_seed
    )
    wall = time.perf_counter() - t0
    out = {
        "design_mm_deg_mm": values,
        "reference_design": [float(v) for v in args.reference.split(",")] if args.reference else None,
        "speeds_rpm": speeds,
        "slices": args.slices,
        "seeds": list(range(args.first_seed, args.first_seed + args.seeds)),
        "window_revs": args.window_revs,
        "reference": [_row(m) for m in metrics[: len(ops)]],
        "found": [_row(m) for m in metrics[len(ops) :]],
        "wall_s": wall,
        "command": "python benchmarks/studies/study_unseen_seeds.py "
        + " ".join(sys.argv[1:] if argv is None else argv),
        "commit": subprocess.run(
            ["git", "-C", str(HERE.parents[2]), "rev-parse", "HEAD"], capture_output=True, text=True
        ).stdout.strip(),
        "machine": _common.machine_info(),
    }
    path = HERE.parents[1] / "results" / f"{args.name}.json"
    path.write_text(json.dumps(out, indent=1, default=float))
    for name in ("reference", "found"):
        for v, row in zip(speeds, out[name]):
            e, q = row["mean_pv_GPa_m_s"], row["peak_pv_GPa_m_s"]
            print(
                f"{name:9s} {v:7.0f} rpm: mean PV {e['value']:.3f} [{e['ci95_low']:.3f}, {e['ci95_high']:.3f}], "
                f"peak {q['value']:.2f} [{q['ci95_low']:.2f}, {q['ci95_high']:.2f}] GPa m/s, "
                f"{row['revolutions_at_the_corner']} of {row['revolutions']} revolutions at the corner, "
                f"risk <= {row['corner_risk']['upper']:.2g}/rev ({row['corner_risk']['method']})"
            )
    print(f"wrote {path} ({wall:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
