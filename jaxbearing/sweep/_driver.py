"""Running a sweep: progress, batches assigned to this process, resume, waiting for the others."""

from __future__ import annotations

import dataclasses
import os
import pathlib
import sys
import time
from collections.abc import Sequence

import numpy as np

from .._errors import UserInputError
from ..io import acquire_lock, check_arguments, count, fallback_dir, remove_stale_temporaries
from ._batch import solve_batch
from ._dataset import assemble
from ._spec import SweepSpec
from ._storage import (
    append_log,
    batch_path,
    prepare_dir,
    read_batch,
    set_aside_damaged,
    write_batch,
)


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
        print(
            f"{self.prefix}[{bar}] {self.done}/{self.total} cases ({frac:.0%}), {el:.1f} s{eta}",
            file=sys.stderr,
            flush=True,
        )

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
    lock_wait_s: float = 0.0,
    workers: int = 1,
):
    """Run (or finish) the sweep `spec` into `out_dir`; returns the assembled dataset (process 0)
    or None (other processes, or `assemble_results=False`).

    This process computes its batches (k % num_processes == process_id) that have no valid batch
    file (all of them with `resume=False`), writing each as it finishes. Process 0 then waits up
    to `wait_timeout_s` for every other batch file and assembles DIR/results.nc.

    Reliability: the process locks DIR (DIR/sweep.<process_id>.lock; another running sweep
    there raises `DirectoryInUse` at once, or after waiting `lock_wait_s` seconds), deletes
    temporary files left by killed writers, and moves batch files that do not load to
    DIR/batches/damaged/ and computes them again (`recover`).

    `workers` > 1 solves this process's batches in that many local worker processes
    (`jaxbearing.run.as_completed_map`; one per core on a CPU, where one solve uses about one
    core): each batch is the same one-device program whichever worker runs it, so the results
    are bitwise those of `workers=1`, and each batch file is written by this process as soon as
    its batch finishes. `jaxbearing sweep` uses one per CPU on a CPU platform (`--workers`).
    """
    out_dir = pathlib.Path(out_dir)
    check_run_arguments(process_id, num_processes, wait_timeout_s, lock_wait_s)
    check_arguments({"workers": workers}, {"workers": count(1)})
    with acquire_lock(out_dir, f"sweep.{process_id}.lock", wait_s=lock_wait_s, what="sweep") as lock:
        if lock.took_over:
            _say(
                progress,
                f"sweep: {out_dir} was left locked by a run that ended "
                f"(pid {lock.took_over.get('pid')} on {lock.took_over.get('host')}); resuming",
            )
        return _run_locked(
            spec,
            out_dir,
            resume,
            process_id,
            num_processes,
            progress,
            assemble_results,
            wait_timeout_s,
            devices,
            workers,
        )


def check_run_arguments(process_id, num_processes, wait_timeout_s, lock_wait_s) -> None:
    """The process layout and the waiting times, before anything is locked or computed."""
    check_arguments({"num_processes": num_processes}, {"num_processes": count(1)})
    check_arguments(
        {"process_id": process_id}, {"process_id": count(0, num_processes - 1, note="0..num_processes-1")}
    )
    for name, value in (("wait_timeout_s", wait_timeout_s), ("lock_wait_s", lock_wait_s)):
        if not (isinstance(value, (int, float)) and not isinstance(value, bool) and value >= 0):
            raise UserInputError(f"{name} = {value!r}: must be >= 0 s (inf: no limit)")


def _say(enabled: bool, text: str) -> None:
    if enabled:
        print(text, file=sys.stderr, flush=True)


def recover(out_dir: pathlib.Path, mine: list[int], process_id: int, num_processes: int) -> list[int]:
    """Clean up after a killed or damaged run: delete temporary files whose writer is gone, and
    move this process's batch files that do not load to DIR/batches/damaged/ (logged and
    reported on stderr); they are then computed again. Returns the batches moved aside."""
    for directory in (out_dir, out_dir / "batches"):
        if directory.is_dir():
            remove_stale_temporaries(directory, all_hosts=num_processes == 1)
    moved = set_aside_damaged(out_dir, mine)
    for b, reason, target in moved:
        print(
            f"sweep: {batch_path(out_dir, b).name} is damaged ({reason}); moved to "
            f"{target.relative_to(out_dir)}; computing it again",
            file=sys.stderr,
            flush=True,
        )
        append_log(
            out_dir,
            {
                "event": "damaged",
                "batch": b,
                "process": process_id,
                "reason": reason,
                "moved_to": str(target.relative_to(out_dir)),
            },
        )
    return [b for b, _, _ in moved]


@dataclasses.dataclass(frozen=True)
class _SolveBatch:
    """Picklable `solve_batch` of one batch number: (summary rows, wall time [s])."""

    spec: SweepSpec
    devices: Sequence | None = None

    def __call__(self, batch: int) -> tuple[dict, float]:
        start = time.perf_counter()
        data = solve_batch(self.spec, self.spec.batch_cases(batch), self.devices)
        return data, time.perf_counter() - start


def _run_locked(
    spec,
    out_dir,
    resume,
    process_id,
    num_processes,
    progress,
    assemble_results,
    wait_timeout_s,
    devices,
    workers,
):
    prepare_dir(out_dir, spec, resume, process_id)
    mine = assigned_batches(spec, process_id, num_processes)
    recover(out_dir, mine, process_id, num_processes)
    todo = [b for b in mine if not resume or read_batch(out_dir, spec, b) is None]
    n_mine = sum(len(spec.batch_cases(b)) for b in mine)
    n_todo = sum(len(spec.batch_cases(b)) for b in todo)
    prefix = f"sweep[{process_id}/{num_processes}] " if num_processes > 1 else "sweep "
    bar = _Progress(n_mine, n_mine - n_todo, progress, prefix)
    from ..run import as_completed_map

    if devices is not None and workers > 1:
        raise UserInputError(f"workers = {workers}: must be 1 when devices are given")
    target, reason = out_dir, None
    for i, (data, wall) in as_completed_map(_SolveBatch(spec, devices), todo, workers=workers):
        b = todo[i]
        cases = spec.batch_cases(b)
        try:
            write_batch(target, spec, b, data)
        except OSError as exc:  # finished work is never lost: the rest goes to a fallback directory
            if reason is not None:
                raise
            reason = f"{exc.strerror or exc}" + (
                f": {exc.filename}" if getattr(exc, "filename", None) else ""
            )
            target = fallback_dir()
            prepare_dir(target, spec, False, 0)
            write_batch(target, spec, b, data)
        append_log(
            target,
            {
                "event": "batch",
                "batch": b,
                "process": process_id,
                "cases": [int(cases[0]), int(cases[-1])],
                "failed": int(np.sum(data["result_code"] != 0)),
                "wall_s": round(wall, 3),
            },
        )
        bar.update(len(cases))
    if reason is not None:
        raise ResultsElsewhere(out_dir, target, reason)
    if process_id != 0 or not assemble_results:
        return None
    missing = _wait_for_batches(out_dir, spec, wait_timeout_s, progress)
    if missing:
        raise UserInputError(
            f"{len(missing)} batch file(s) of {out_dir} still missing after {wait_timeout_s:g} s "
            f"(first: {batch_path(out_dir, missing[0]).name}); run the same command again to "
            "finish them"
        )
    return assemble(out_dir, spec)


class ResultsElsewhere(Exception):
    """Batches could not be written into the sweep directory; those finished since are in
    `fallback`/batches (copy them into DIR/batches/ and run the same command to assemble)."""

    def __init__(self, out_dir, fallback, reason: str):
        self.out_dir, self.fallback, self.reason = out_dir, fallback, reason
        super().__init__(
            f"batches could not be written to {out_dir} ({reason}); the batches finished since are "
            f"kept in {fallback}/batches: copy them into {out_dir}/batches/ and run the same "
            "command again to assemble the results"
        )


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
            print(
                f"sweep: waiting for {len(missing)} batch(es) from the other processes",
                file=sys.stderr,
                flush=True,
            )
            told = True
        time.sleep(0.5)
