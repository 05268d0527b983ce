"""Settling time with and without the skid start (issue 11, acceptance): the reference bearing
(20,000 rpm, 1000 N, arc end), seed 0, `simulate(settle="auto")` (tolerance 0.1 % per
revolution) from

1. the skid start (`start="skid"`, the default: the static skid equilibrium, the pre-start that
   moves it onto the plateau (two short bursts and a secant step on the cage speed's drift,
   run/_initial.py), projective steps of the cage speed while settling as a safeguard), window
   `window_revs` revolutions;
2. the quasi-static start (`start="quasi-static"`: kinematic speeds), same settings, cap
   `cap_ms` (full: 300 ms).

Recorded per start: the start's cage speed, every revolution's mean cage speed with its end
time, the projective steps, the settling time, whether it settled, the window's cage speed
with its 95 % CI, the start-up step (first revolution's mean against the start, % of the cage
speed), the largest distance of a revolution's mean from the window's value from revolution 1
on (% of the cage speed), the wall time. For the skid start also the pre-start (`skid_start`
with the run's integrator, run again here on its own: deterministic, the same as inside the
run): its simulated time, the static skid speed, the two measured drifts, the secant's time
constant and plateau; `before_window_ms` = pre-start + settling, the simulated time spent before
the window. Quick mode: 2-revolution window and a 60 ms cap (not a measurement).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "bench_settling"


def _one(start: str, window_revs: int, cap_ms: float) -> dict:
    import jaxbearing as jb

    b, op = jb.reference_bearing(), jb.reference_operating_point()
    t0 = time.perf_counter()
    res = jb.simulate(
        b, op, settle="auto", window_revs=window_revs, start=start, settle_cap_ms=cap_ms, progress=True
    )
    wall = time.perf_counter() - t0
    s = jb.summarise(res)
    seed = s["per_seed"][0]
    speeds = seed["revolution_cage_speed_rpm"]
    start_rpm = seed["start_cage_speed_rpm"]
    if start_rpm != start_rpm:  # quasi-static: the kinematic speed
        start_rpm = s["kinematic_cage_speed_rpm"]
    window = s["cage_speed_rpm"]["value"]
    pre = _pre_start(b, op) if start == "skid" else {"pre_start_ms": 0.0}
    return {
        **pre,
        "before_window_ms": pre["pre_start_ms"] + s["settle_time_ms"],
        "largest_revolution_offset_percent": 100 * max(abs(v - window) for v in speeds) / window,
        "start": start,
        "start_cage_speed_rpm": start_rpm,
        "start_up_step_percent": 100 * abs(speeds[0] - start_rpm) / start_rpm,
        "revolution_end_ms": seed["revolution_end_ms"],
        "revolution_cage_speed_rpm": speeds,
        "projective_steps_rpm": seed["projective_steps_rpm"],
        "settled": s["settled"],
        "settle_time_ms": s["settle_time_ms"],
        "window_ms": s["window_ms"],
        "cage_speed_rpm": s.get("cage_speed_rpm"),
        "cage_slip": s.get("cage_slip"),
        "wall_time_s": wall,
        "solve_wall_time_s": s["wall_time_s"],
        "compile_time_s": s["compile_time_s"],
    }


def _pre_start(b, op) -> dict:
    """The skid start's pre-start on its own, with the integrator `simulate_steady` gives it
    (`solve_from` at the default tolerances and saves)."""
    import jax

    from jaxbearing.dynamics import Params, cage_time_constant
    from jaxbearing.geometry import rad_s_to_rpm as rpm
    from jaxbearing.run import Perturbation, skid_start, solve_from
    from jaxbearing.run._settle import SAVES_PER_REV

    params = Params(bearing=b, operating=op)
    run = jax.jit(solve_from, static_argnames=("num_saves", "max_steps"))

    def integrate(state, duration):
        return run(
            params, state, duration, num_saves=SAVES_PER_REV, rtol=1e-3, atol=1e-6, max_steps=2_000_000
        )

    skid = skid_start(b, op, Perturbation(), integrate=integrate)
    return {
        "pre_start_status": skid.pre_start_status,
        "pre_start_ms": 1e3 * skid.pre_start_time,
        "static_skid_cage_speed_rpm": float(rpm(skid.equilibrium.cage_speed)),
        "pre_start_drift_speeds_rpm": [float(rpm(w)) for w in skid.drift_speeds],
        "pre_start_drifts_rpm_per_s": [float(rpm(g)) for g in skid.drifts],
        "pre_start_plateau_rpm": float(rpm(skid.plateau_speed)),
        "time_constant_ms": 1e3 * float(skid.time_constant),
        "static_time_constant_ms": 1e3 * float(cage_time_constant(skid.equilibrium, params)),
    }


def main(quick: bool = False) -> dict:
    window, cap = (2, 60.0) if quick else (8, 300.0)
    runs = {}
    for start in ("skid", "quasi-static"):
        _common.log(f"{NAME}: settling from the {start} start (window {window} revolutions, cap {cap} ms)")
        runs[start] = _one(start, window, cap)
    skid, qs = runs["skid"], runs["quasi-static"]
    rows = [
        [
            r["start"],
            f"{r['start_cage_speed_rpm']:.1f}",
            f"{r['start_up_step_percent']:.3f}",
            f"{r['largest_revolution_offset_percent']:.3f}",
            f"{r['pre_start_ms']:.1f}",
            f"{r['settle_time_ms']:.1f}",
            str(r["settled"]).lower(),
            f"{r['cage_speed_rpm']['value']:.1f} [{r['cage_speed_rpm']['ci95_low']:.1f}, "
            f"{r['cage_speed_rpm']['ci95_high']:.1f}]",
            f"{r['wall_time_s']:.0f}",
        ]
        for r in (skid, qs)
    ]
    result = {
        "quick": quick,
        "runs": runs,
        "settle_time_ratio_quasi_static_over_skid": qs["settle_time_ms"] / max(skid["settle_time_ms"], 1e-9),
        "before_window_ratio_quasi_static_over_skid": qs["before_window_ms"]
        / max(skid["before_window_ms"], 1e-9),
        "machine": _common.machine_info(),
    }
    result["table"] = _common.format_table(
        "Settling at the reference point (arc end, seed 0)",
        [
            "start",
            "start rpm",
            "start-up step %",
            "largest rev. offset %",
            "pre-start ms",
            "settle ms",
            "settled",
            "window cage rpm [95 % CI]",
            "wall s",
        ],
        rows,
    )
    print(result["table"])
    _common.write_json(NAME, result)
    return result


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
