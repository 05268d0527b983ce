"""Both cores for sweeps (issue 12, item 4): `jaxbearing.sweep.run_sweep` with its batches in two
worker processes (`workers=2`, what `jaxbearing sweep` does on a 2-core CPU) against all batches
in this process (`workers=1`), end to end.

Sweep: the reference bearing at 1000 N, arc and corner ends (the base configuration's "both")
x speeds 15,000 .. 22,000 rpm in 8 steps (16 cases), batch size 2 (8 batches), `duration` simulated per case (full: 2 ms, quick: 0.2 ms), 50 saved
samples. Each mode runs the whole sweep into a new directory: wall time from `run_sweep` to the
assembled dataset, worker start, import and program load included (the first, untimed sweep
fills the persistent cache and the stored programs, as a user's earlier run would). The two
modes are interleaved (full: 2 rounds, best of each kept) and their datasets must be bitwise
equal. Throughput = cases / wall; target: workers=2 >= 1.5x workers=1. Also timed: the
quasi-static start of one case alone and per case inside a vmap of 8 (`quasi_static_start_cost`),
against a case's share of the sweep's wall time: what moving it out of the vmap could save.

    python benchmarks/studies/bench_sweep_workers.py [--quick]
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "bench_sweep_workers"

SPEC = """
[sweep]
batch_size = 2
num_saves = 50

[base.simulation]
duration_ms = {duration_ms}
max_steps = 1000000

[axes]
"operating.speed_rpm" = {{ start = 15000, stop = 22000, num = 8 }}
"""


def _sweep(spec_path: Path, workers: int):
    from jaxbearing.sweep import load_sweep_spec, run_sweep

    with tempfile.TemporaryDirectory(prefix="jaxbearing-sweep-") as out:
        start = time.perf_counter()
        ds = run_sweep(load_sweep_spec(spec_path), out, progress=False, workers=workers)
        return time.perf_counter() - start, ds.load()


def quasi_static_start_cost(batch: int = 8, repeats: int = 3) -> dict:
    """Wall time of the quasi-static start (`jaxbearing.run.initial_state`, Newton's method) of
    one case, and per case inside a vmap of `batch` (as in a sweep batch), compiled, best of
    `repeats`: what running it outside the vmap could save."""
    import jax
    import jax.numpy as jnp

    import jaxbearing as jb
    from jaxbearing.run import initial_state

    b, op = jb.reference_bearing(), jb.reference_operating_point()
    one = jax.jit(lambda b, o: initial_state(b, o, jb.Perturbation(seed=0)))
    many = jax.jit(jax.vmap(lambda b, o: initial_state(b, o, jb.Perturbation(seed=0))))
    stacked = jax.tree_util.tree_map(lambda x: jnp.stack([x] * batch), (b, op))
    alone = min(_common.time_repeats(lambda: jax.block_until_ready(one(b, op)), repeats))
    batched = min(_common.time_repeats(lambda: jax.block_until_ready(many(*stacked)), repeats))
    return {"one_case_s": alone, "per_case_in_vmap_s": batched / batch, "batch": batch}


def main(quick: bool = False) -> dict:
    import numpy as np

    started = time.perf_counter()
    duration_ms = 0.2 if quick else 2.0
    rounds = 1 if quick else 2
    with tempfile.TemporaryDirectory(prefix="jaxbearing-spec-") as d:
        spec_path = Path(d) / "speeds.toml"
        spec_path.write_text(SPEC.format(duration_ms=duration_ms))
        _common.log(f"{NAME}: untimed sweep (fills the caches)")
        _sweep(spec_path, 1)
        walls: dict[int, list[float]] = {1: [], 2: []}
        datasets = {}
        for r in range(rounds):
            for workers in (1, 2):
                _common.log(f"{NAME}: round {r + 1}, workers={workers}")
                wall, ds = _sweep(spec_path, workers)
                walls[workers].append(wall)
                datasets[workers] = ds
    start_cost = quasi_static_start_cost()
    one, two = datasets[1], datasets[2]
    identical = all(
        np.array_equal(one[v].values, two[v].values, equal_nan=one[v].dtype.kind == "f")
        for v in one.data_vars
    )
    cases = int(one["result_code"].size)
    best = {w: min(t) for w, t in walls.items()}
    ratio = best[1] / best[2]
    result = {
        "benchmark": NAME,
        "quick": quick,
        "case": {
            "cases": cases,
            "batch_size": 2,
            "simulated_time_s": duration_ms * 1e-3,
            "sweep": "reference bearing, 1000 N, arc and corner x speed 15,000-22,000 rpm (8 values)",
        },
        "wall_s": {str(w): t for w, t in walls.items()},
        "throughput_cases_per_s": {str(w): cases / best[w] for w in walls},
        "ratio_two_workers": ratio,
        "datasets_bitwise_equal": bool(identical),
        "failed_cases": int(np.sum(one["result_code"].values != 0)),
        "quasi_static_start": start_cost,
        "quasi_static_start_share_of_a_case": start_cost["per_case_in_vmap_s"] / (best[1] / cases),
        "load_average_at_end": list(os.getloadavg()),
        "targets": {
            "two_core_sweep": _common.target(
                "sweep on 2 cores (workers=2) >= 1.5x the throughput of one process", ratio, 1.5, True
            )
        },
        "benchmark_wall_s": time.perf_counter() - started,
    }
    result["table"] = _common.format_table(
        f"Sweep of {cases} cases x {duration_ms:g} ms, batches of 2 (best of {rounds}, end to end)",
        ["mode", "wall s", "cases/s", "ratio"],
        [
            ["workers=1 (one process)", best[1], cases / best[1], 1.0],
            ["workers=2 (two worker processes)", best[2], cases / best[2], ratio],
        ],
    )
    print(result["table"])
    print(f"datasets bitwise equal: {identical}")
    print(
        f"quasi-static start: {start_cost['one_case_s'] * 1e3:.1f} ms alone, "
        f"{start_cost['per_case_in_vmap_s'] * 1e3:.1f} ms per case in a vmap of {start_cost['batch']} "
        f"({100 * result['quasi_static_start_share_of_a_case']:.1f} % of a case's sweep wall time)"
    )
    _common.write_json(NAME, result)
    return result


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
