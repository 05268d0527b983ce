"""Compile once (issue 12, item 5): compile time of a first and a second process with the
persistent compilation cache (`jaxbearing.enable_compilation_cache`, on at import).

Each program is compiled in two fresh Python processes, one after the other, sharing a new,
empty cache directory (`JAXBEARING_CACHE_DIR`): the first compiles and writes the cache, the
second should load it. Reported: each process's compile time (the `jax.jit(...).lower().compile()`
of the program, or `SimulationResult.compile_time_s`), the ratio second / first (target <= 0.30),
and the number of cache files written. Programs: `simulate` (reference bearing, 0.05 ms,
4000 samples) and, in full mode, `jaxbearing.design_jacobian` (forward mode: the smooth peak PV and contact
heights and their derivatives in the 3 design variables over `GRADIENT_HORIZON`, as
`bench_gradients`; its compile time is the first call's wall time less the second's) and one
sweep batch (`jaxbearing.sweep.batch_runner`, 2 cases).

Each program's results (a sha256 of its outputs) are compared between the first process, the
second and a third with the caches off (`JAXBEARING_CACHE_DIR=off`: plain `jax.jit`).

What a second process skips: the compilation (JAX's persistent compilation cache) and, for the
programs built by `jaxbearing.run.compiled_program`, the tracing too (a `jax.export` artefact
stored beside that cache).

    python benchmarks/bench_compile_cache.py [--quick]
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common  # noqa: E402

NAME = "bench_compile_cache"
ROOT = Path(__file__).resolve().parents[1]


def _digest(tree) -> str:
    """sha256 of every array of a result: equal digests mean bitwise-equal results."""
    import hashlib

    import jax
    import numpy as np

    h = hashlib.sha256()
    for leaf in jax.tree_util.tree_leaves(tree):
        h.update(np.ascontiguousarray(np.asarray(leaf)).tobytes())
    return h.hexdigest()


def _program_simulate() -> tuple[float, str]:
    import jaxbearing as jb

    res = jb.simulate(jb.reference_bearing(), jb.reference_operating_point(), duration=0.05e-3)
    assert res.ok, res.status
    return res.compile_time_s, _digest(res.histories)


def _program_gradient() -> float:
    import jax

    import jaxbearing as jb
    from jaxbearing.design import GRADIENT_ATOL, GRADIENT_HORIZON, GRADIENT_RTOL, design_jacobian
    from jaxbearing.flange import DesignVariables

    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    design = DesignVariables.of(bearing)
    kwargs = dict(duration=GRADIENT_HORIZON, rtol=GRADIENT_RTOL, atol=GRADIENT_ATOL, max_steps=100_000)
    times = []
    for _ in range(2):  # the first call compiles and runs, the second only runs
        start = time.perf_counter()
        out = jax.block_until_ready(design_jacobian(bearing, op, design, **kwargs))
        times.append(time.perf_counter() - start)
    return times[0] - times[1], _digest(out)


def _program_sweep() -> float:
    import jax
    import numpy as np

    import jaxbearing as jb
    from jaxbearing.sweep import batch_runner

    b, op = jb.reference_bearing(), jb.reference_operating_point()
    cases = [(b, op, 0.05e-3, 1e-3, 1e-6)] * 2
    inputs = jax.tree_util.tree_map(lambda *xs: np.stack([np.asarray(x, float) for x in xs]), *cases)
    runner = batch_runner(50, 100_000, tuple(jax.local_devices()))
    start = time.perf_counter()
    compiled = runner.compile(*inputs)
    seconds = time.perf_counter() - start
    return seconds, _digest(compiled(*inputs))


PROGRAMS = {
    "simulate": _program_simulate,
    "forward_gradient": _program_gradient,
    "sweep_batch": _program_sweep,
}


def _child(program: str) -> None:
    seconds, digest = PROGRAMS[program]()
    print(json.dumps({"compile_s": seconds, "digest": digest}))


def _run_process(program: str, cache_dir: str) -> dict:
    """{"compile_s", "digest"} of `program` in a fresh process with `cache_dir` ("off": no cache)."""
    env = dict(os.environ, JAXBEARING_CACHE_DIR=cache_dir, PYTHONPATH=str(ROOT))
    out = subprocess.run(
        [sys.executable, __file__, "--child", program], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(quick: bool = False) -> dict:
    started = time.perf_counter()
    programs = ["simulate"] if quick else list(PROGRAMS)
    rows = {}
    for program in programs:
        with tempfile.TemporaryDirectory(prefix="jaxbearing-cache-") as cache:
            _common.log(f"{NAME}: {program}: first process (empty cache)")
            first = _run_process(program, cache)
            files = sum(1 for _ in Path(cache).rglob("*") if _.is_file())
            _common.log(f"{NAME}: {program}: second process")
            second = _run_process(program, cache)
        _common.log(f"{NAME}: {program}: a process with the caches off (plain jax.jit)")
        plain = _run_process(program, "off")
        rows[program] = {
            "first_process_compile_s": first["compile_s"],
            "second_process_compile_s": second["compile_s"],
            "ratio": second["compile_s"] / first["compile_s"],
            "cache_files": files,
            "results_bitwise_equal_first_second_plain_jit": first["digest"]
            == second["digest"]
            == plain["digest"],
        }
    worst = max(r["ratio"] for r in rows.values())
    result = {
        "benchmark": NAME,
        "quick": quick,
        "programs": rows,
        "targets": {
            "second_process_compile": _common.target(
                "a second process compiles in <= 30 % of the first (persistent cache)",
                worst,
                0.30,
                higher_is_better=False,
            )
        },
        "benchmark_wall_s": time.perf_counter() - started,
    }
    result["table"] = _common.format_table(
        "Compile once: first vs second process, shared persistent cache",
        ["program", "first s", "second s", "second/first", "cache files", "bitwise = plain jit"],
        [
            [
                k,
                r["first_process_compile_s"],
                r["second_process_compile_s"],
                r["ratio"],
                r["cache_files"],
                r["results_bitwise_equal_first_second_plain_jit"],
            ]
            for k, r in rows.items()
        ],
    )
    print(result["table"])
    _common.write_json(NAME, result)
    return result


if __name__ == "__main__":
    if "--child" in sys.argv:
        _child(sys.argv[sys.argv.index("--child") + 1])
    else:
        main(quick="--quick" in sys.argv)
