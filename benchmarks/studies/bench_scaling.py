"""Part 5 of issue 8: wall time and peak memory versus simulated duration and roller count.

Each point runs in a fresh Python process (``python bench_scaling.py --point JSON``), so that
its peak resident memory (`resource.getrusage(RUSAGE_SELF).ru_maxrss`, the high-water mark of
the process, which counts XLA's buffers; `tracemalloc` sees only Python objects and JAX's
`memory_stats()` is unavailable on CPU) belongs to that point alone and no compilation is
shared between points. A point calls the public `jaxbearing.simulate` (default 4000 saved
samples, rtol 1e-3, atol 1e-6), which reports compile and run time separately, and records:

* peak resident memory after importing jaxbearing and building the bearing ("import"), over
  the whole process ("peak": the compiler dominates it), and during the timed run alone
  ("run peak", the VmHWM mark reset after compiling; "run extra": run peak minus the resident
  memory after compiling, i.e. what the histories and solver state add);
* compile time, wall time (compile excluded), step attempts, rejected steps, evaluations
  (6 attempts + 1) and wall time per step attempt.

Duration sweep: the reference bearing (26 rollers) over 1, 2, 4, 8 ms (quick: 0.25, 0.5 ms).
Roller-count sweep: 12, 18, 26 and the largest count that fits the pitch circle with the
reference cage (Z (D + C_p) < pi d_m: 34; 36 does not fit), otherwise the reference geometry,
each validated with `validate_bearing`, over 2 ms (quick: 12 and 26 rollers, 0.25 ms).
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/: _common

import _common  # noqa: E402

NAME = "bench_scaling"
POINT_TIMEOUT_S = 300


def max_roller_count(bearing) -> int:
    """Largest Z with Z (D + C_p) < pi d_m (the roller-complement rule of `validate_bearing`)."""
    circ = math.pi * float(bearing.pitch_diameter)
    pitch = float(bearing.roller.diameter) + float(bearing.cage.pocket_clearance)
    z = int(circ // pitch)
    return z - 1 if z * pitch >= circ else z


def bearing_with_rollers(num_rollers: int):
    """The reference bearing with `num_rollers` rollers (same geometry otherwise), validated."""
    import dataclasses

    import jaxbearing as jb

    bearing = dataclasses.replace(jb.reference_bearing(), num_rollers=int(num_rollers))
    jb.validate_bearing(bearing, jb.reference_operating_point())
    return bearing


def _rss_bytes() -> int:
    """Peak resident set of this process so far (ru_maxrss; kilobytes on Linux)."""
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _proc_status_bytes(field: str) -> int | None:
    """VmRSS (current) or VmHWM (peak since the last reset) from /proc/self/status."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(field + ":"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def _reset_peak_rss() -> bool:
    """Reset this process's VmHWM (Linux >= 4.0: write 5 to /proc/self/clear_refs)."""
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def run_point(num_rollers: int, duration: float) -> dict:
    """One point, in this process (call it in a fresh one: see `measure_point`).

    `simulate` is first called over a very short time (1 us), which compiles (the compilation
    is cached per structure; the duration is a traced argument); then the peak-RSS mark is
    reset and the timed run over `duration` reuses the compiled program, so that its memory
    (histories, solver state) is measured apart from the compiler's."""
    import jaxbearing as jb

    bearing = bearing_with_rollers(num_rollers)
    op = jb.reference_operating_point()
    baseline = _rss_bytes()
    warm = jb.simulate(bearing, op, duration=1e-6)
    after_compile = _proc_status_bytes("VmRSS")
    reset = _reset_peak_rss()
    res = jb.simulate(bearing, op, duration=duration)
    run_peak = _proc_status_bytes("VmHWM") if reset else None
    end = _rss_bytes()
    return {
        "num_rollers": num_rollers,
        "duration_s": duration,
        "status": res.status,
        "ok": res.ok and warm.ok,
        "compile_s": warm.compile_time_s,
        "recompiled_for_run": res.compile_time_s > 0.5 * warm.compile_time_s,
        "wall_s": res.wall_time_s,
        "step_attempts": res.num_steps,
        "rejected_steps": res.num_rejected_steps,
        "evaluations": _common.fsal_rk_evaluations(res.num_steps),
        "wall_per_step_s": res.wall_time_s / max(res.num_steps, 1),
        "rss_baseline_bytes": baseline,
        "peak_rss_bytes": end,
        "rss_after_compile_bytes": after_compile,
        "run_peak_rss_bytes": run_peak,
        "run_peak_above_post_compile_bytes": None
        if run_peak is None or after_compile is None
        else run_peak - after_compile,
    }


def measure_point(num_rollers: int, duration: float, timeout: float = POINT_TIMEOUT_S) -> dict:
    """Run `run_point` in a fresh Python process; its last stdout line is the JSON result."""
    spec = json.dumps({"num_rollers": num_rollers, "duration": duration})
    start = time.perf_counter()
    try:
        proc = subprocess.run(
            [sys.executable, str(Path(__file__).resolve()), "--point", spec],
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return {
            "num_rollers": num_rollers,
            "duration_s": duration,
            "ok": False,
            "status": f"failed: the point ran past {timeout:g} s",
        }
    if proc.returncode != 0:
        tail = (proc.stderr or proc.stdout).strip().splitlines()[-1:] or ["(no output)"]
        return {
            "num_rollers": num_rollers,
            "duration_s": duration,
            "ok": False,
            "status": f"failed: exit {proc.returncode}: {tail[0]}",
        }
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out["process_wall_s"] = time.perf_counter() - start
    return out


def main(quick: bool = False) -> dict:
    import jaxbearing as jb

    started = time.perf_counter()
    z_max = max_roller_count(jb.reference_bearing())
    if quick:
        durations, counts, count_duration = [0.25e-3, 0.5e-3], [12, 26], 0.25e-3
    else:
        durations, counts, count_duration = [1e-3, 2e-3, 4e-3, 8e-3], [12, 18, 26, z_max], 2e-3
    for z in counts:  # fail early, in this process, on an invalid bearing
        bearing_with_rollers(z)
    cache: dict = {}

    def point(z, d):
        if (z, d) not in cache:
            _common.log(f"{NAME}: {z} rollers, {d * 1e3:g} ms (fresh process)")
            cache[(z, d)] = measure_point(z, d)
        return cache[(z, d)]

    by_duration = [point(26, d) for d in durations]
    by_rollers = [point(z, count_duration) for z in counts]
    failed = [p for p in cache.values() if not p.get("ok")]
    result = {
        "benchmark": NAME,
        "quick": quick,
        "case": {
            "bearing": "reference_bearing(), num_rollers varied (geometry otherwise unchanged)",
            "operating_point": "reference_operating_point() (20,000 rpm, 1000 N, gravity on)",
            "solver": "jaxbearing.simulate defaults: Tsit5, rtol 1e-3, atol 1e-6, 4000 saved samples",
            "memory": "fresh process per point; peak_rss = ru_maxrss of the whole process (compiler "
            "included); run_peak_rss = VmHWM during the timed run (reset after compiling)",
            "largest_roller_count_that_fits": z_max,
        },
        "versus_duration": by_duration,
        "versus_roller_count": by_rollers,
        "failed_points": len(failed),
        "benchmark_wall_s": time.perf_counter() - started,
    }
    result["table"] = _table(result)
    print(result["table"])
    _common.write_json(NAME, result)
    if failed:
        raise RuntimeError(
            f"{len(failed)} scaling point(s) failed: " + "; ".join(p["status"] for p in failed)
        )
    return result


def _rows(points):
    mib = 1024.0**2
    rows = []
    for p in points:
        if not p.get("ok"):
            rows.append([p["num_rollers"], p["duration_s"] * 1e3, p["status"]] + [None] * 8)
            continue
        run_peak = p.get("run_peak_rss_bytes")
        rows.append(
            [
                p["num_rollers"],
                p["duration_s"] * 1e3,
                "ok",
                p["wall_s"],
                p["compile_s"],
                p["step_attempts"],
                p["wall_per_step_s"] * 1e6,
                p["rss_baseline_bytes"] / mib,
                p["peak_rss_bytes"] / mib,
                None if run_peak is None else run_peak / mib,
                None if run_peak is None else p["run_peak_above_post_compile_bytes"] / mib,
            ]
        )
    return rows


def _table(r: dict) -> str:
    header = [
        "rollers",
        "sim ms",
        "status",
        "wall s",
        "compile s",
        "attempts",
        "us/step",
        "import MiB",
        "peak MiB",
        "run peak MiB",
        "run extra MiB",
    ]
    return "\n".join(
        [
            _common.format_table(
                "Part 5 - scaling with simulated duration (reference bearing, 26 rollers; "
                "fresh process per point)",
                header,
                _rows(r["versus_duration"]),
            ),
            _common.format_table(
                "Part 5 - scaling with roller count (reference geometry)",
                header,
                _rows(r["versus_roller_count"]),
            ),
        ]
    )


def self_check() -> None:
    """Cheap checks: the roller counts of the sweep are valid bearings, one more is not."""
    import dataclasses

    import jaxbearing as jb

    ref = jb.reference_bearing()
    z_max = max_roller_count(ref)
    for z in (12, 18, 26, z_max):
        assert bearing_with_rollers(z).num_rollers == z
    try:
        jb.validate_bearing(dataclasses.replace(ref, num_rollers=z_max + 1), jb.reference_operating_point())
    except jb.ConfigError:
        pass
    else:  # pragma: no cover
        raise AssertionError(f"{z_max + 1} rollers should not fit")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--point":
        spec = json.loads(sys.argv[2])
        print(json.dumps(_common._jsonable(run_point(int(spec["num_rollers"]), float(spec["duration"])))))
    else:
        main(quick="--quick" in sys.argv)
