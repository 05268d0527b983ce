"""Progress of long settled runs: how many members have settled, printed at least every
`interval` seconds while the engine runs.

A design search, a settled sweep or a verification runs many members (a case and a seed each)
for minutes; each member may itself take longer than a user waits for a sign of life.
`MemberProgress` is a context manager: while it is active, every call of the member dispatcher
(`settle_members`) reports to it (members started and finished; no argument passes through the
layers in between), and a daemon thread prints one line every `interval` seconds: the members
settled of those started, the elapsed wall time and an estimate of what remains (elapsed time
per settled member times the members still to settle; none before the first has settled).
"""

from __future__ import annotations

import contextvars
import threading
import time
from collections.abc import Callable

import numpy as np

from ..io import require
from ._progress import Ticker

_ACTIVE: contextvars.ContextVar[MemberProgress | None] = contextvars.ContextVar(
    "member_progress", default=None
)


class MemberProgress(Ticker):
    """Print the members' progress every `interval` seconds while the `with` block runs, through
    `say` (default: print). `label` starts every line."""

    def __init__(self, interval: float = 30.0, label: str = "", say: Callable[[str], None] | None = None):
        require("interval", interval, lambda v: np.isfinite(v) & (v > 0), "> 0 s")
        self.interval = float(interval)
        self.label = label
        self.say = say if say is not None else (lambda line: print(line, flush=True))
        self.total = 0
        self.done = 0
        self._lock = threading.Lock()
        self._token = None
        self.start = time.perf_counter()

    def started(self, members: int) -> None:
        """`members` more members are on their way."""
        with self._lock:
            self.total += int(members)

    def finished(self, members: int = 1) -> None:
        """`members` more members have settled and been measured (or failed)."""
        with self._lock:
            self.done += int(members)

    def line(self) -> str:
        """The progress line now."""
        with self._lock:
            done, total = self.done, self.total
        elapsed = time.perf_counter() - self.start
        left = (
            f"about {elapsed / done * (total - done):.0f} s left" if done else "no estimate before the first"
        )
        return f"{self.label}members settled {done} of {total}, {elapsed:.0f} s elapsed, {left}"

    def tick(self) -> None:
        self.say(self.line())

    def __enter__(self) -> MemberProgress:
        super().__enter__()
        self._token = _ACTIVE.set(self)
        return self

    def __exit__(self, *exc) -> None:
        super().__exit__(*exc)
        _ACTIVE.reset(self._token)


def active_progress() -> MemberProgress | None:
    """The `MemberProgress` of the enclosing `with` block, if any."""
    return _ACTIVE.get()
