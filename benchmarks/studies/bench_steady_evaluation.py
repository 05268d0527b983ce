"""One evaluation of the steady design search, timed: ``python benchmarks/studies/bench_steady_evaluation.py``.

From the settled states of start 0 of the default `optimise run` (its checkpoint,
out/bench_optimise_steady/run/checkpoint.npz, written by `benchmarks/studies/bench_optimise_steady.py`):
`steady_design_metrics` (4 seeds, the run's, settle auto, 2-revolution window; continuation) then
`frozen_load_gradient` (8 x 1 ms), on 2 workers, twice in a row (the second call is the one a
search iteration pays once compiled), first with a process pool per call, then inside one
`jaxbearing.run.shared_workers` block. Reported: wall seconds of each part and simulated ms per
second (`--quick`: one call each, from the quick run's checkpoint, run_quick/, when the full
run's is missing, as on a fresh clone under `run_all.py --quick`). Results:
benchmarks/results/bench_steady_evaluation.json.
"""

from __future__ import annotations

import pathlib
import sys
import time

sys.path[:0] = [
    str(pathlib.Path(__file__).resolve().parent),
    str(pathlib.Path(__file__).resolve().parents[1]),
]
import _common  # noqa: E402

NAME = "bench_steady_evaluation"
_RUNS = pathlib.Path(__file__).resolve().parents[2] / "out" / "bench_optimise_steady"
CHECKPOINT = _RUNS / "run" / "checkpoint.npz"
#: `--quick` without the full run's checkpoint: that of `bench_optimise_steady.py --quick`
QUICK_CHECKPOINT = _RUNS / "run_quick" / "checkpoint.npz"
WORKERS = 2


def _timed(problem, u, chain, repeats: int = 2) -> list[dict]:
    import jax.numpy as jnp

    from jaxbearing.design import frozen_load_gradient, steady_design_metrics
    from optimise._steady import _operating_point

    design = problem.design(jnp.asarray(u))
    op = _operating_point(problem, 0)
    rows = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        m = steady_design_metrics(
            problem.bearing,
            op,
            design,
            seeds=len(chain),  # 4 in the default run, 2 in the quick one
            window_revs=2,
            settle="auto",
            flange_load=problem.flange_load,
            initial_states=chain,
            workers=WORKERS,
        )
        t1 = time.perf_counter()
        frozen_load_gradient(
            design.apply(problem.bearing), op, design, m.sample_states, window=1e-3, workers=WORKERS
        )
        t2 = time.perf_counter()
        sim = sum(r["settle_time_ms"] for r in m.summary["per_seed"]) + len(m.seeds) * m.summary["window_ms"]
        rows.append(dict(ensemble_s=t1 - t0, gradient_s=t2 - t1, simulated_ms=sim, ms_per_s=sim / (t1 - t0)))
        _common.log(f"{NAME}: ensemble {t1 - t0:.1f} s ({sim:.1f} simulated ms), gradient {t2 - t1:.1f} s")
    return rows


def main(quick: bool = False) -> dict:
    import jaxbearing as jb
    from jaxbearing.run import shared_workers
    from optimise import make_problem

    checkpoint = QUICK_CHECKPOINT if quick and not CHECKPOINT.exists() else CHECKPOINT
    if not checkpoint.exists():
        raise SystemExit(
            f"{checkpoint}: missing; run benchmarks/studies/bench_optimise_steady.py"
            f"{' --quick' if quick else ''} first"
        )
    from jaxbearing.io import load_tree

    state = load_tree(checkpoint, what="checkpoint")["state"]
    problem = make_problem(jb.reference_bearing(), jb.reference_operating_point())
    u, chain = state["u"][0], state["chains"][0][0]
    repeats = 1 if quick else 2
    per_call = _timed(problem, u, chain, repeats)
    with shared_workers(WORKERS):
        shared = _timed(problem, u, chain, repeats)
    out = {
        "benchmark": NAME,
        "checkpoint": str(checkpoint.relative_to(_RUNS.parents[1])),
        "machine": _common.machine_info(),
        "pool_per_call": per_call,
        "shared_pool": shared,
    }
    _common.write_json(NAME, out)
    return out


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
