"""Both cores: independent cases (seeds of an ensemble, sweep points, a batch of designs) run one
process per core.

Why processes and not `vmap`: an adaptive solve is a while loop whose step count depends on the
case, so a vmapped batch runs every case as long as its slowest and pays for the masked lanes;
on a 2-core CPU a batch of 32 ran at 0.74x the per-case throughput of one case at a time
(benchmarks/results/throughput.json), and one case at a time used only about 1.1 of the 2 cores.
Separate processes keep every core on a case of its own.

`parallel_map(function, items)` maps a picklable top-level function over picklable items in a
pool of `workers` processes (default: the CPUs this process may use), started with `spawn`
(JAX is not fork-safe). Results come back in the order of `items`. The workers share the
persistent compilation cache (`_compile_cache`), so a program compiled by this process or by one
worker is loaded, not recompiled, by the others. `threads_per_worker=1` limits each worker to
one XLA thread; the default keeps this process's XLA flags, because the flags are part of the
cache key (with other flags every worker compiles its program again: measured 2 min 13 s per
worker against 16 s for a cache load, benchmarks/bench_ensemble.py). `workers=1` runs in this
process (no pool). A worker that dies (killed, out of memory, or a script without
``if __name__ == "__main__":`` whose workers re-run it on import, as `spawn` does) ends the map
with a one-line `UserInputError` instead of a pool that restarts workers for ever
(`concurrent.futures.ProcessPoolExecutor` reports a broken pool; `multiprocessing.Pool` hangs).
The other way round, the workers end when the process that started them is killed
(`_exit_with_parent`): a killed sweep or search leaves no workers behind.

Each worker is pinned to one CPU of this process's set, in turn (`_pin_to_one_cpu`, Linux). An
unpinned worker's XLA threads move between the cores and contend with the other worker's:
two unpinned workers ran a case in 1.45x the time of one case alone, two pinned ones in 1.04x
(benchmarks/bench_ensemble.py, docs/performance.md). A pool with more workers than CPUs shares
each CPU between the workers pinned to it.

`as_completed_map(function, items, workers=N)` yields each result as it finishes (the sweep
writes every batch file at once).

`shared_workers(workers)` keeps one pool open for every `parallel_map` inside a `with` block (a
search's ensembles and gradients), so the workers import JAX and load their programs once.

`simulate_ensemble(bearing, op, seeds, ...)` runs `simulate` once per seed of the initial roller
scatter (`Perturbation(seed=s)`) through `parallel_map`.
"""

from __future__ import annotations

import contextlib
import dataclasses
import multiprocessing
import os
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from .._errors import UserInputError
from ..io import require

#: XLA flags of a worker with one thread. (The often-quoted `intra_op_parallelism_threads=1` after
#: it is not an XLA flag: XLA stops reading XLA_FLAGS at the first such token, so every flag
#: written after it was ignored.)
_ONE_THREAD_FLAGS = "--xla_cpu_multi_thread_eigen=false"


def _with_flags(flags: str, more: str) -> str:
    """XLA_FLAGS `flags` with the flags of `more` it lacks appended. JAX's persistent compilation
    cache keys its entries on the flags as written, so a flag given twice would make the workers'
    programs other entries than those of a parent that already has it."""
    have = flags.split()
    return " ".join(have + [f for f in more.split() if f not in have])


def available_cpus() -> int:
    """CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


@contextlib.contextmanager
def _environment(**values: str):
    old = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def parallel_map(
    function: Callable[[Any], Any],
    items: Iterable[Any],
    *,
    workers: int | None = None,
    threads_per_worker: int | None = None,
    on_done: Callable[[], None] | None = None,
) -> list:
    """[function(item) for item in items], one process per worker (module docstring);
    `on_done()` is called in this process as each item finishes (e.g. a progress count)."""
    items = list(items)
    if workers is None:
        workers = available_cpus()
    workers = max(1, min(int(workers), len(items)))
    if workers == 1:
        return [_reported(function(item), on_done) for item in items]
    flags = os.environ.get("XLA_FLAGS", "")
    if threads_per_worker == 1:
        flags = _with_flags(flags, _ONE_THREAD_FLAGS)
    shared = _SHARED.get(flags)
    try:
        if shared is not None and shared[0] >= workers:
            return _mapped(shared[1], function, items, on_done)
        with _environment(XLA_FLAGS=flags), _pool(workers) as pool:
            return _mapped(pool, function, items, on_done)
    except BrokenProcessPool:
        _SHARED.pop(flags, None)
        raise _worker_died(workers) from None


def as_completed_map(function: Callable[[Any], Any], items: Sequence[Any], *, workers: int) -> Iterator:
    """(index, function(items[index])) as each case finishes, in `workers` processes (started
    with `spawn`, this process's XLA flags; in this process, in order, when `workers` is 1): for
    a caller that stores each result as soon as it exists (the sweep's batch files). Leaving the
    loop early cancels the cases not yet started."""
    workers = max(1, min(int(workers), len(items)))
    if workers == 1:
        for i, item in enumerate(items):
            yield i, function(item)
        return
    pool = _pool(workers)
    try:
        futures = {pool.submit(function, item): i for i, item in enumerate(items)}
        for future in as_completed(futures):
            try:
                result = future.result()
            except BrokenProcessPool:
                raise _worker_died(workers) from None
            yield futures[future], result
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _reported(result, on_done):
    if on_done is not None:
        on_done()
    return result


def _mapped(pool, function, items: list, on_done) -> list:
    """`pool.map(function, items)` as a list, calling `on_done()` as each item finishes."""
    if on_done is None:
        return list(pool.map(function, items))
    futures = [pool.submit(function, item) for item in items]
    for future in futures:
        future.add_done_callback(lambda _: on_done())
    return [future.result() for future in futures]


def _worker_died(workers: int) -> UserInputError:
    return UserInputError(
        f"workers = {workers}: a worker process died before finishing its case. In a script, "
        'call this under `if __name__ == "__main__":` (each worker imports the main module '
        "first), check the memory, or pass workers=1"
    )


def _pool(workers: int) -> ProcessPoolExecutor:
    context = multiprocessing.get_context("spawn")
    return ProcessPoolExecutor(
        workers,
        mp_context=context,
        initializer=_start_worker,
        initargs=(context.Value("i", 0), sorted(_cpu_set())),
    )


def _cpu_set() -> set[int]:
    try:
        return os.sched_getaffinity(0)
    except AttributeError:  # pragma: no cover - not Linux
        return set()


def _start_worker(started, cpus: list[int]) -> None:
    """Worker initializer: `_exit_with_parent`, then `_pin_to_one_cpu`."""
    _exit_with_parent()
    with started.get_lock():
        index = started.value
        started.value += 1
    _pin_to_one_cpu(index, cpus)


def _pin_to_one_cpu(index: int, cpus: list[int]) -> None:
    """Run this process (and the threads it starts later, XLA's among them) on CPU
    `cpus[index % len(cpus)]` only: the `index`-th worker of a pool takes the next CPU of the
    parent's set (module docstring). No-op where the OS has no affinity call or `cpus` is
    empty."""
    if cpus and hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {cpus[index % len(cpus)]})


def _exit_with_parent() -> None:
    """Worker initializer: end this worker when the process that started the pool dies.

    A pool's workers hold both ends of its call queue, so a parent that is killed (SIGKILL, the
    out-of-memory killer, a cluster's time limit) never closes it: the workers would wait on it
    for ever, each holding a JAX runtime (about 0.5 GB). A daemon thread waits on the parent's
    sentinel (`multiprocessing.parent_process()`, ready when the parent ends) and exits the
    worker; a worker of a living parent is untouched."""
    import threading
    from multiprocessing.connection import wait

    parent = multiprocessing.parent_process()
    if parent is None:  # pragma: no cover - a pool worker always has one
        return

    def watch():
        wait([parent.sentinel])
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


#: pools kept open by `shared_workers`, by XLA flags: (workers, executor)
_SHARED: dict[str, tuple[int, ProcessPoolExecutor]] = {}


@contextlib.contextmanager
def shared_workers(workers: int | None = None):
    """Keep one pool of `workers` processes for every `parallel_map` inside the block (with the
    default XLA flags and at most `workers` workers), instead of starting a pool per call.

    A fresh worker imports JAX and loads its programs from the persistent compilation cache
    before its first case (seconds per program); a loop of short parallel calls (the steady
    design search: an ensemble and a gradient per iteration) pays that once in the block. The
    workers are pure (every case carries its inputs), so results do not depend on which worker
    ran a case. Nested blocks reuse the outer pool."""
    if workers is not None:
        require("workers", workers, lambda v: (v >= 1) & (v % 1 == 0), "an integer >= 1")
    workers = available_cpus() if workers is None else int(workers)
    flags = os.environ.get("XLA_FLAGS", "")
    if workers <= 1 or flags in _SHARED:
        yield
        return
    with _environment(XLA_FLAGS=flags):
        pool = _pool(workers)
    _SHARED[flags] = (workers, pool)
    try:
        yield
    finally:
        _SHARED.pop(flags, None)
        pool.shutdown(wait=True, cancel_futures=True)


@dataclasses.dataclass(frozen=True)
class _SimulateSeed:
    """Picklable `simulate` of one seed (the keyword arguments travel with it)."""

    bearing: Any
    op: Any
    kwargs: dict

    def __call__(self, seed: int):
        from ._initial import Perturbation
        from ._simulate import simulate

        base = self.kwargs.get("perturbation") or Perturbation()
        kwargs = dict(self.kwargs, perturbation=dataclasses.replace(base, seed=int(seed)))
        return simulate(self.bearing, self.op, **kwargs)


def simulate_ensemble(
    bearing,
    op,
    seeds: Sequence[int],
    *,
    workers: int | None = None,
    **simulate_kwargs,
) -> list:
    """`simulate(bearing, op, perturbation=Perturbation(seed=s), **simulate_kwargs)` for every seed,
    one process per core; a list of `SimulationResult` in the order of `seeds`."""
    return parallel_map(_SimulateSeed(bearing, op, dict(simulate_kwargs)), list(seeds), workers=workers)
