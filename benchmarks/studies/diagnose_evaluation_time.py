"""Where the time of one design-search evaluation goes (issue 35, item 5):
``python benchmarks/studies/diagnose_evaluation_time.py``.

The default problem (reference bearing, 31 slices, 20,000 rpm, 1000 N), start 0, settings of
`optimise run` (4 seeds, settle auto, 2-revolution window, frozen-load gradient) with one worker,
so that everything runs in this process: a first evaluation from the skid start, then the one a
search iteration pays, continuing from the first's states. During the second, the Python stack
is sampled every second (`faulthandler`), and the samples are counted by the two innermost
jaxbearing/optimise frames: integration (`settle_and_measure_steps`), static skid equilibria
(`_static_skid_start`), the gradient's trajectories (`_frozen_job`), ... Finding (2026-11-26,
2-core CPU): of 66 s, 46 s integrating, 17 s the continuing seeds' static skid equilibria (one
per seed, for the settling verdict's time constant), 3 s the gradient; since the seeds of a case
share one equilibrium, 6 of 73 s (another process loading the machine). Results:
results/diagnose_evaluation_time.json.
"""

from __future__ import annotations

import collections
import faulthandler
import re
import sys
import tempfile
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]
import _common  # noqa: E402

NAME = "diagnose_evaluation_time"


def stack_counts(text: str, depth: int = 2) -> dict[str, int]:
    """Samples per innermost `depth` jaxbearing/optimise frames of a `faulthandler` dump."""
    counts: collections.Counter = collections.Counter()
    for block in text.split("Timeout (")[1:]:
        frames = re.findall(r'File "([^"]+)", line \d+ in (\w+)', block)
        ours = [f"{p.split('/')[-1]}:{fn}" for p, fn in frames if "jaxbearing" in p or "optimise" in p]
        counts[" < ".join(ours[:depth]) or "(outside)"] += 1
    return dict(counts.most_common())


def main() -> dict:
    import jaxbearing as jb
    from optimise import make_problem
    from optimise._steady import SteadySettings, evaluate_starts, start_points

    problem = make_problem(jb.reference_bearing(), jb.reference_operating_point())
    settings = SteadySettings(seeds=4, window_revs=2, workers=1)
    us = list(start_points(problem, 1))
    t0 = time.perf_counter()
    (first,) = evaluate_starts(problem, settings, us, [None])
    first_s = time.perf_counter() - t0
    _common.log(f"{NAME}: first evaluation {first_s:.1f} s")
    with tempfile.TemporaryFile("w+") as dump:
        faulthandler.dump_traceback_later(1.0, repeat=True, file=dump)
        t0 = time.perf_counter()
        (second,) = evaluate_starts(problem, settings, us, [first.states])
        second_s = time.perf_counter() - t0
        faulthandler.cancel_dump_traceback_later()
        dump.seek(0)
        counts = stack_counts(dump.read())
    _common.log(f"{NAME}: continuing evaluation {second_s:.1f} s: {counts}")
    data = {
        "first_s": first_s,
        "continuing_s": second_s,
        "simulated_ms": second.simulated_ms,
        "samples_per_1s": counts,
    }
    _common.write_json(NAME, data)
    return data


if __name__ == "__main__":
    main()
