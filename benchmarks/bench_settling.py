"""Settling time with and without the skid start (issue 11, acceptance): the reference bearing
(20,000 rpm, 1000 N, arc end), seed 0, `simulate(settle="auto")` (tolerance 0.1 % per
revolution) from

1. the skid start (`start="skid"`, the default: skid equilibrium plus projective steps of the
   cage speed while settling), window `window_revs` revolutions;
2. the quasi-static start (`start="quasi-static"`: kinematic speeds), same settings, cap
   `cap_ms` (full: 300 ms).

Recorded per start: the start's cage speed, every revolution's mean cage speed with its end
time, the projective steps, the settling time, whether it settled, the window's cage speed
with its 95 % CI, the start-up step (first revolution's mean against the start, % of the cage
speed), the wall time. Quick mode: 2-revolution window and a 60 ms cap (not a measurement).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

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
    return {
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
        "machine": _common.machine_info(),
    }
    result["table"] = _common.format_table(
        "Settling at the reference point (arc end, seed 0)",
        [
            "start",
            "start rpm",
            "start-up step %",
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
