"""A time limit on one example of a property test (`signal.alarm`): a hang fails the example
with a `TimeoutError` instead of stalling the suite. Shared by the property and fuzz tests."""

from __future__ import annotations

import contextlib
import signal

#: seconds one example may run (parsing and checking inputs, no solve)
EXAMPLE_LIMIT_S = 30


@contextlib.contextmanager
def time_limit(seconds: int = EXAMPLE_LIMIT_S):
    def expired(signum, frame):
        raise TimeoutError(f"example ran over {seconds} s (a hang?)")

    old = signal.signal(signal.SIGALRM, expired)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
