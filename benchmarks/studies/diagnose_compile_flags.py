"""Whether XLA's CPU compile options shorten the compilation of a solve (issue 37: about half of
`make test`'s time is compiling): ``python benchmarks/studies/diagnose_compile_flags.py``.

One program, `jaxbearing.solve` of the 11-slice reference bearing for 0.1 ms (Tsit5, rtol 1e-5,
atol 1e-10, 11 saves: the Tsit5 half of tests/test_rosenbrock.py's ROS34PW2 check), compiled in
a fresh process per flag set with an empty cache, on one CPU with single-threaded XLA as in
`make test`; then run twice, the second timed. Each flag set is measured after a run with the
default flags (interleaved: this machine's speed drifts by tens of per cent within minutes). Result: results/diagnose_compile_flags.json (compile and run seconds, and
the largest roller load, which must not change).

``--on-top``: the further flag sets `ON_TOP` added to the older emitters (what `make test` uses),
each after a run with the older emitters alone; results/diagnose_compile_flags_on_top.json.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]
import _common  # noqa: E402

NAME = "diagnose_compile_flags"
ONE_THREAD = "--xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1"
#: the flag sets tried, besides the default
#: (XLA reads XLA_FLAGS up to the first token that is not a flag and ignores the rest, so each set
#: goes before the one-thread flags; XLA refuses the unknown ones it reads, such as
#: `--xla_cpu_optimize_for_size`, which its library names but does not register)
FLAG_SETS = (
    "--xla_cpu_use_fusion_emitters=false",
    "--xla_backend_optimization_level=0",
    "--xla_llvm_disable_expensive_passes=true",
    "--xla_cpu_use_thunk_runtime=false",
)
#: further flag sets tried on top of the older emitters (`--on-top`)
ON_TOP = (
    "--xla_backend_optimization_level=1",
    "--xla_cpu_parallel_codegen_split_count=1",
    "--xla_llvm_force_inline_before_split=false",
    "--xla_cpu_copy_insertion_use_region_analysis=false",
    "--xla_cpu_prefer_vector_width=128",
    "--xla_cpu_max_isa=SSE4_2",
    "--xla_cpu_enable_concurrency_optimized_scheduler=false",
)
EMITTERS = FLAG_SETS[0]
REPEATS = 1

_CHILD = """
import dataclasses, json, time
import jax
jax.config.update("jax_enable_x64", True)
import numpy as np
import jaxbearing as jb
b = dataclasses.replace(jb.reference_bearing(), num_slices=11)
op = jb.reference_operating_point()
f = jax.jit(lambda b, op: jb.solve(b, op, 1e-4, num_saves=11, rtol=1e-5, atol=1e-10, solver="tsit5").histories)
low = f.lower(b, op)
t0 = time.perf_counter(); c = low.compile(); t1 = time.perf_counter()
jax.block_until_ready(c(b, op)); t2 = time.perf_counter(); h = jax.block_until_ready(c(b, op)); t3 = time.perf_counter()
print(json.dumps({"compile_s": t1 - t0, "run_s": t3 - t2, "max_inner_load_N": float(np.max(h["roller_inner_load"]))}))
"""


def measure(flags: str) -> dict:
    """Compile and run seconds of the program in a fresh process with XLA_FLAGS `flags` (the
    added flags first: XLA stops reading at `intra_op_parallelism_threads=1`)."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, XLA_FLAGS=f"{flags} {ONE_THREAD}".strip(), JAXBEARING_CACHE_DIR=cache)
        cpu = ["taskset", "-c", "0"] if sys.platform == "linux" else []
        out = subprocess.run([*cpu, sys.executable, "-c", _CHILD], env=env, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"XLA_FLAGS={env['XLA_FLAGS']!r}: {out.stderr.strip().splitlines()[-1]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(on_top: bool = False) -> dict:
    base, sets = (EMITTERS, ON_TOP) if on_top else ("", FLAG_SETS)
    plain = "(older emitters alone)" if on_top else "(default)"
    rows = []
    for repeat in range(REPEATS):
        for flags in sets:
            for tried in ("", flags):  # the base interleaved with each flag set
                r = measure(f"{base} {tried}".strip()) | {"flags": tried or plain, "repeat": repeat}
                _common.log(f"{NAME}: {r['flags']}: compile {r['compile_s']:.1f} s, run {r['run_s']:.3f} s")
                rows.append(r)
    default = [r["compile_s"] for r in rows if r["flags"] == plain]
    summary = {
        flags: {
            "compile_s": [r["compile_s"] for r in rows if r["flags"] == flags],
            "run_s": [r["run_s"] for r in rows if r["flags"] == flags],
        }
        for flags in sets
    }
    data = {
        "program": "solve, 11-slice reference bearing, 0.1 ms, Tsit5, rtol 1e-5, atol 1e-10, 11 saves",
        "base_flags": base or "(none)",
        "default_compile_s": default,
        "by_flags": summary,
        "rows": rows,
    }
    _common.write_json(NAME + ("_on_top" if on_top else ""), data)
    return data


if __name__ == "__main__":
    main(on_top="--on-top" in sys.argv[1:])
