"""The text progress meter of one solve: percentage of the simulated time, elapsed wall time and
an estimate of the time left; a solve that stops early says where it stopped.

    [arc end] simulating 20 ms ...
       0% of the simulated time
       5% of the simulated time, 1.2 s elapsed, about 23 s left
      ...
     100% of the simulated time, 24.3 s elapsed
or, when the solve fails (step limit, step-size collapse):
      stopped at 37.2% of the simulated time after 9.1 s: the solve failed (see its status)

A `diffrax.AbstractProgressMeter`: the traced state carries the progress of the last accepted
step (cheap, every step) and the progress last printed; the host is called only when the
progress has grown by `minimum_increase` (and once at the end). The estimate of the time left
is elapsed * (1 - p) / p: the rate of the run so far, so it is rough while the step size still
settles. Meant for one unbatched solve (`simulate`); batched solves (sweeps) run without it.

Its price: the meter's host callbacks are part of the compiled program, and JAX neither persists
such a program (the persistent compilation cache) nor exports it (`jax.export`), so a solve with
the meter is traced and compiled afresh in every process. `HostProgress` is the meter that
costs nothing in the program: a thread of the calling process prints the elapsed wall time
every `interval` seconds while an ordinary (cached) solve runs, and the same closing line as
`SolveProgress` from its result (100 %, or where a failed solve stopped). It cannot know the
percentage while the solve runs. The command line uses it (`jaxbearing simulate` of 0.2 ms on
warm caches: 7.9-9.1 s with it, 24.5-30.9 s with `SolveProgress`; docs/performance-history.md).
"""

from __future__ import annotations

import itertools
import threading
import time

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax.experimental import io_callback
from jaxtyping import Array

from ..io import require

_METERS: dict[int, dict] = {}
_IDS = itertools.count(1)
_LOCK = threading.Lock()
_INDENT = "   "


def _open() -> np.ndarray:
    with _LOCK:
        idx = next(_IDS)
        _METERS[idx] = {"start": time.perf_counter(), "shown": 0.0}
    print(f"{_INDENT}  0% of the simulated time", flush=True)
    return np.asarray(idx, dtype=np.int32)


def _show(progress, idx) -> np.ndarray:
    p = float(np.min(progress))
    with _LOCK:
        meter = _METERS.get(int(np.max(idx)))
    if meter is not None:  # None: a re-run of the steps (e.g. a backward pass)
        meter["shown"] = p
        elapsed = time.perf_counter() - meter["start"]
        left = f", about {elapsed * (1 - p) / p:.0f} s left" if 0 < p < 1 else ""
        print(f"{_INDENT}{100 * p:3.0f}% of the simulated time, {elapsed:.1f} s elapsed{left}", flush=True)
    return np.asarray(idx, dtype=np.int32)


def closing_line(fraction: float, elapsed: float) -> str:
    """The meter's last line: 100 %, or where a failed solve stopped (`fraction` < 1)."""
    if fraction < 1.0:
        return (
            f"{_INDENT}stopped at {100 * fraction:.1f}% of the simulated time after {elapsed:.1f} s: "
            "the solve failed (see its status)"
        )
    return f"{_INDENT}100% of the simulated time, {elapsed:.1f} s elapsed"


def _close(idx, latest) -> None:
    p = float(np.min(latest))
    with _LOCK:
        meter = _METERS.pop(int(np.max(idx)), None)
    if meter is None:
        return
    if p < 1.0 or meter["shown"] < 1.0:
        print(closing_line(p, time.perf_counter() - meter["start"]), flush=True)


class Ticker:
    """A daemon thread that calls `tick()` every `interval` seconds while the `with` block runs
    (`start`: when the block began, `time.perf_counter()`)."""

    interval: float = 10.0

    def tick(self) -> None:  # pragma: no cover - every subclass has its own
        raise NotImplementedError

    def _loop(self) -> None:
        while not self._stop.wait(self.interval):
            self.tick()

    def __enter__(self):
        self.start = time.perf_counter()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name=type(self).__name__, daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        self._thread.join()


class HostProgress(Ticker):
    """The progress of a solve that runs without `SolveProgress` (module docstring): while the
    `with` block runs, a daemon thread prints the elapsed wall time every `interval` seconds;
    `close(fraction)` prints the closing line, `fraction` being the simulated time reached over
    the duration (1 for a solve that succeeded)."""

    def __init__(self, interval: float = 10.0):
        require("interval", interval, lambda v: np.isfinite(v) & (v > 0), "> 0 s")
        self.interval = float(interval)
        self.start = time.perf_counter()

    def tick(self) -> None:
        print(f"{_INDENT}{time.perf_counter() - self.start:.0f} s elapsed", flush=True)

    def close(self, fraction: float) -> None:
        print(closing_line(float(fraction), time.perf_counter() - self.start), flush=True)


class _MeterState(eqx.Module):
    shown: Array  # progress last printed, in [0, 1]
    latest: Array  # progress of the last accepted step
    idx: Array  # host-side meter id; threading it orders the callbacks


class SolveProgress(diffrax.AbstractProgressMeter):
    """Text progress of one solve with elapsed time and an estimate of the time left; says where
    a failed solve stopped (module docstring)."""

    minimum_increase: float = 0.05

    def init(self) -> _MeterState:
        idx = io_callback(_open, jax.ShapeDtypeStruct((), jnp.int32))
        zero = jnp.asarray(0.0)
        return _MeterState(shown=zero, latest=zero, idx=idx)

    def step(self, state: _MeterState, progress) -> _MeterState:
        progress = jnp.asarray(progress, dtype=float)
        show = (progress - state.shown >= self.minimum_increase) | (progress >= 1.0)
        idx = jax.lax.cond(
            show,
            lambda i: jax.pure_callback(
                _show, jax.ShapeDtypeStruct((), jnp.int32), progress, i, vmap_method="expand_dims"
            ),
            lambda i: i,
            state.idx,
        )
        return _MeterState(shown=jnp.where(show, progress, state.shown), latest=progress, idx=idx)

    def close(self, state: _MeterState) -> None:
        io_callback(_close, None, state.idx, state.latest)
