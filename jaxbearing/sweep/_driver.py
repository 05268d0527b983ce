"""Running a sweep: progress, batches assigned to this process, resume, waiting for the others."""

from __future__ import annotations

import os
import pathlib
import sys
import time
from collections.abc import Sequence

import numpy as np

from .._errors import UserInputError
from ._batch import solve_batch
from ._dataset import assemble
from ._spec import SweepSpec
from ._storage import append_log, batch_path, prepare_dir, read_batch, write_batch


# -- progress ------------------------------------------------------------------------------------
class _Progress:
    """Plain-text progress over cases on stderr (one line per finished batch)."""

    def __init__(self, total: int, done: int, enabled: bool, prefix: str):
        self.total, self.done, self.enabled, self.prefix = total, done, enabled, prefix
        self.start = time.perf_counter()
        self.start_done = done
        self.show()

    def show(self) -> None:
        if not self.enabled:
            return
        width = 30
        frac = self.done / self.total if self.total else 1.0
        bar = "#" * int(width * frac) + "." * (width - int(width * frac))
        el = time.perf_counter() - self.start
        rate = (self.done - self.start_done) / el if el > 0 and self.done > self.start_done else 0
        eta = f", ETA {(self.total - self.done) / rate:.0f} s" if rate else ""
        print(f"{self.prefix}[{bar}] {self.done}/{self.total} cases ({frac:.0%}), "
              f"{el:.1f} s{eta}", file=sys.stderr, flush=True)

    def update(self, n: int) -> None:
        self.done += n
        self.show()


# -- driver --------------------------------------------------------------------------------------
def assigned_batches(spec: SweepSpec, process_id: int, num_processes: int) -> list[int]:
    """The batches of process `process_id`: batch k belongs to process k % num_processes."""
    return [b for b in range(spec.num_batches) if b % num_processes == process_id]


def run_sweep(
    spec: SweepSpec,
    out_dir: str | os.PathLike,
    *,
    resume: bool = True,
    process_id: int = 0,
    num_processes: int = 1,
    progress: bool = True,
    assemble_results: bool = True,
    wait_timeout_s: float = 24 * 3600.0,
    devices: Sequence | None = None,
):
    """Run (or finish) the sweep `spec` into `out_dir`; returns the assembled dataset (process 0)
    or None (other processes, or `assemble_results=False`).

    This process computes its batches (k % num_processes == process_id) that have no valid batch
    file (all of them with `resume=False`), writing each as it finishes. Process 0 then waits up
    to `wait_timeout_s` for every other batch file and assembles DIR/results.nc.
    """
    out_dir = pathlib.Path(out_dir)
    prepare_dir(out_dir, spec, resume, process_id)
    mine = assigned_batches(spec, process_id, num_processes)
    todo = [b for b in mine if not resume or read_batch(out_dir, spec, b) is None]
    n_mine = sum(len(spec.batch_cases(b)) for b in mine)
    n_todo = sum(len(spec.batch_cases(b)) for b in todo)
    prefix = f"sweep[{process_id}/{num_processes}] " if num_processes > 1 else "sweep "
    bar = _Progress(n_mine, n_mine - n_todo, progress, prefix)
    for b in todo:
        cases = spec.batch_cases(b)
        start = time.perf_counter()
        data = solve_batch(spec, cases, devices)
        write_batch(out_dir, spec, b, data)
        append_log(out_dir, {"event": "batch", "batch": b, "process": process_id,
                       "cases": [int(cases[0]), int(cases[-1])],
                       "failed": int(np.sum(data["result_code"] != 0)),
                       "wall_s": round(time.perf_counter() - start, 3)})
        bar.update(len(cases))
    if process_id != 0 or not assemble_results:
        return None
    missing = _wait_for_batches(out_dir, spec, wait_timeout_s, progress)
    if missing:
        raise UserInputError(
            f"{len(missing)} batch file(s) of {out_dir} still missing after {wait_timeout_s:g} s "
            f"(first: {batch_path(out_dir, missing[0]).name}); run the same command again to "
            "finish them")
    return assemble(out_dir, spec)


def missing_batches(out_dir: str | os.PathLike, spec: SweepSpec) -> list[int]:
    return [b for b in range(spec.num_batches) if read_batch(pathlib.Path(out_dir), spec, b) is None]


def _wait_for_batches(out_dir, spec, timeout_s, progress) -> list[int]:
    deadline = time.monotonic() + timeout_s
    told = False
    while True:
        missing = missing_batches(out_dir, spec)
        if not missing or time.monotonic() >= deadline:
            return missing
        if progress and not told:
            print(f"sweep: waiting for {len(missing)} batch(es) from the other processes",
                  file=sys.stderr, flush=True)
            told = True
        time.sleep(0.5)
