"""Sweep throughput: cases per second for vmapped batches of 1, 8, 32 (and 128) cases.

Every batch integrates the reference bearing (arc ends, speeds spread over 15,000-25,000 rpm so
the cases are not identical) over the same simulated time, through the sweep machinery
(`jaxbearing.sweep.batch_runner`: `jax.vmap(solve)` under `jax.shard_map` over all local
devices). Compilation is timed separately and excluded from the throughput; each batch size is
run `repeats` times and the best run counts.

    python benchmarks/bench_throughput.py [--full]

writes benchmarks/results/throughput.json and prints a table. `main(quick)` is the entry point
for benchmarks/run_all.py (quick=True: batch sizes 1, 8, 32 at 0.2 ms, well under 3 minutes on
two CPU cores; quick=False adds 128 and simulates 1 ms).
"""

from __future__ import annotations

import json
import pathlib
import platform
import sys
import time

RESULTS = pathlib.Path(__file__).parent / "results" / "throughput.json"


def _inputs(batch: int, duration: float):
    import jax
    import numpy as np

    from jaxbearing import reference_bearing, reference_operating_point, rpm_to_rad_s
    from jaxbearing.geometry import OperatingPoint

    b = reference_bearing()
    op = reference_operating_point()
    speeds = np.linspace(15000.0, 25000.0, batch) if batch > 1 else np.array([20000.0])
    cases = [
        (
            b,
            OperatingPoint(inner_speed=rpm_to_rad_s(s), radial_load=op.radial_load, gravity=op.gravity),
            duration,
            1e-3,
            1e-6,
        )
        for s in speeds
    ]
    return jax.tree_util.tree_map(lambda *xs: np.stack([np.asarray(x, float) for x in xs]), *cases)


def measure(
    batch: int,
    duration: float,
    num_saves: int = 50,
    max_steps: int = 100_000,
    repeats: int = 1,
    devices: tuple | None = None,
) -> dict:
    """Compile time, best wall time and cases/s of one vmapped, sharded batch of `batch` over
    `devices` (default: every local device of the default backend)."""
    import jax
    import numpy as np

    from jaxbearing.sweep import batch_runner, padded_size

    devices = tuple(jax.local_devices() if devices is None else devices)
    size = padded_size(batch, len(devices))
    inputs = _inputs(size, duration)
    runner = batch_runner(num_saves, max_steps, devices)
    start = time.perf_counter()
    compiled = runner.compile(*inputs)
    compile_s = time.perf_counter() - start
    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        sol = jax.block_until_ready(compiled(*inputs))
        walls.append(time.perf_counter() - start)
    ok = int(np.sum(np.asarray(sol.result) == 0))
    wall = min(walls)
    return {
        "batch_size": batch,
        "padded_to": size,
        "devices": len(devices),
        "platform": devices[0].platform,
        "simulated_time_ms": duration * 1e3,
        "compile_s": round(compile_s, 3),
        "wall_s": round(wall, 4),
        "cases_per_s": round(batch / wall, 4),
        "simulated_ms_per_s": round(batch * duration * 1e3 / wall, 4),
        "max_steps_taken": int(np.max(np.asarray(sol.num_steps))),
        "cases_ok": ok,
    }


def main(quick: bool = True) -> dict:
    import jax

    jax.config.update("jax_enable_x64", True)
    sizes = (1, 8, 32) if quick else (1, 8, 32, 128)
    duration = 0.2e-3 if quick else 1e-3
    rows = []
    for n in sizes:
        row = measure(n, duration, repeats=1 if quick else 2)
        rows.append(row)
        print(
            f"  batch {n:>4}: {row['cases_per_s']:.3f} cases/s (compile {row['compile_s']:.1f} s)",
            file=sys.stderr,
            flush=True,
        )
    result = {
        "benchmark": "sweep throughput (vmapped batches of the reference bearing)",
        "quick": quick,
        "device": f"{jax.devices()[0].platform} x{jax.local_device_count()}",
        "machine": platform.processor() or platform.machine(),
        "rows": rows,
    }
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps(result, indent=2))
    print(format_table(result))
    return result


def format_table(result: dict) -> str:
    head = (
        f"{'batch':>6}{'devices':>9}{'sim ms':>8}{'compile s':>11}{'wall s':>9}"
        f"{'cases/s':>10}{'steps':>8}{'ok':>5}"
    )
    lines = [f"sweep throughput on {result['device']}", head, "-" * len(head)]
    for r in result["rows"]:
        lines.append(
            f"{r['batch_size']:>6}{r['devices']:>9}{r['simulated_time_ms']:>8.2f}"
            f"{r['compile_s']:>11.1f}{r['wall_s']:>9.2f}{r['cases_per_s']:>10.3f}"
            f"{r['max_steps_taken']:>8}{r['cases_ok']:>5}"
        )
    return "\n".join(lines)


if __name__ == "__main__":
    main(quick="--full" not in sys.argv[1:])
