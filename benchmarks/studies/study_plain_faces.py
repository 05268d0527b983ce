"""What does a profile design at today's faces cost on the general contact path, against today's
contact code? (`jaxbearing.flange.plain_faces`, docs/model.md 5.4.)

    python benchmarks/studies/study_plain_faces.py [--slices 11] [--speed-rpm 30000] [--rounds 2] [--settle-ms 10]

The reference bearing's own profile (e = 0, a cone rib: the start design and the verification's
reference of every profile search) run from the skid start, settled for a fixed `--settle-ms`
(so both paths simulate the same time) and measured over 2 revolutions, one seed at a time, on the
general contact path (the profile applied with `with_faces` alone) and on today's code
(`plain_faces`, what `steady_design_metrics_points` runs), alternated `--rounds` times in
one process so both see the same load, seeds 0 .. rounds - 1 on each: settled wall time per
member (the programs compiled in a first, untimed pass of each) and per simulated ms, mean
flange PV with its 95 % interval over the seeds per path, and the largest contact radius.
Both paths give the same forces to round-off (tests/test_faces_dynamics.py); the trajectories
part at round-off, so the settled statistics should agree within their intervals, and the wall
times then compare at equal error. Writes results/NAME.json (`--name`, default study_plain_faces).
"""

from __future__ import annotations

import argparse
import dataclasses
import pathlib
import sys
import time

HERE = pathlib.Path(__file__).resolve()
sys.path.insert(0, str(HERE.parents[1]))

import _common  # noqa: E402


def _settled(path: str, bearing, op, seed: int, settle_ms: float) -> dict:
    import jaxbearing.design._steady_design as sd
    from jaxbearing.design import steady_design_metrics_points
    from jaxbearing.flange import ProfileVariables, plain_faces
    from jaxbearing.run import SettleFixed, SteadySettings

    sd.plain_faces = plain_faces if path == "today's code" else (lambda b: b)
    settings = SteadySettings(seeds=1, window_revs=2, workers=1, settle=SettleFixed(settle_ms))
    t0 = time.perf_counter()
    (m,) = steady_design_metrics_points(
        bearing, [op], ProfileVariables.of(bearing), settings, first_seed=seed
    )
    wall = time.perf_counter() - t0
    st = m.statistics
    return {
        "path": path,
        "seed": seed,
        "wall_s": wall,
        "simulated_ms": m.simulated_ms,
        "mean_pv_GPa_m_s": m.mean_pv.value / 1e9,
        "largest_contact_radius_mm": None if st is None else st.contact_radius_m.max_in_contact.value * 1e3,
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--slices", type=int, default=11)
    p.add_argument("--speed-rpm", type=float, default=30000.0)
    p.add_argument("--rounds", type=int, default=2)
    p.add_argument(
        "--settle-ms", type=float, default=10.0, help="a fixed settling time, the same on both paths"
    )
    p.add_argument("--name", default="study_plain_faces")
    args = p.parse_args(argv)

    import jaxbearing as jb
    from jaxbearing.geometry import OperatingPoint
    from jaxbearing.run import student_t_interval

    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=args.slices)
    ref = jb.reference_operating_point()
    op = OperatingPoint(
        inner_speed=jb.rpm_to_rad_s(args.speed_rpm), radial_load=ref.radial_load, gravity=ref.gravity
    )
    paths = ("general contact", "today's code")
    for path in paths:  # compile both programs before timing
        _settled(path, bearing, op, seed=100, settle_ms=args.settle_ms)
    runs = []
    for k in range(args.rounds):
        for path in paths if k % 2 == 0 else paths[::-1]:
            runs.append(_settled(path, bearing, op, seed=k, settle_ms=args.settle_ms))
            _common.log(f"{runs[-1]}")
    walls = {path: sum(r["wall_s"] for r in runs if r["path"] == path) for path in paths}
    per_ms = {path: walls[path] / sum(r["simulated_ms"] for r in runs if r["path"] == path) for path in paths}
    pv = {
        path: student_t_interval([r["mean_pv_GPa_m_s"] for r in runs if r["path"] == path]).as_dict()
        for path in paths
    }
    out = {
        "benchmark": "a profile design at today's faces settled on the general contact path and on today's code",
        "slices": args.slices,
        "speed_rpm": args.speed_rpm,
        "settle_ms": args.settle_ms,
        "runs": runs,
        "wall_ratio_today_over_general": walls["today's code"] / walls["general contact"],
        "wall_s_per_simulated_ms": per_ms,
        "wall_per_simulated_ms_ratio_today_over_general": per_ms["today's code"] / per_ms["general contact"],
        # the seeds' mean PV per path with its 95 % interval (Student t over the seeds)
        "mean_pv_GPa_m_s": pv,
        "command": " ".join(["python", "benchmarks/studies/study_plain_faces.py", *sys.argv[1:]]),
        "machine": _common.machine_info(),
    }
    _common.write_json(args.name, out)
    print(f"wall, today's code / general contact: {out['wall_ratio_today_over_general']:.3f}")
    print(f"wall per simulated ms: {per_ms}; mean PV: {pv}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
