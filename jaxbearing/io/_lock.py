"""A lock on an output directory, so that two runs never write into one directory at once.

`acquire_lock(DIR, name)` takes an exclusive `flock` on DIR/NAME and writes into it who holds
it (pid, host, start time, command). The kernel drops the lock when its process ends, however
it ends (SIGKILL included), so a lock file left behind by a killed run is stale by definition:
the next run takes it over and says so. A lock held by a running process makes the second run
wait (`wait_s`) or fail at once with `DirectoryInUse`, one line naming the holder. On network
file systems without working locks the lock is skipped with a warning.
"""

from __future__ import annotations

import errno
import json
import math
import os
import pathlib
import socket
import sys
import time

from .._errors import UserInputError

try:
    import fcntl
except ImportError:  # pragma: no cover (not POSIX)
    fcntl = None


class DirectoryInUse(UserInputError):
    """Another running process holds the lock on an output directory."""


class DirectoryLock:
    """A held lock (`acquire_lock`); `release()` or use it as a context manager."""

    def __init__(self, path: pathlib.Path, fd: int | None, took_over: dict | None):
        self.path, self._fd, self.took_over = path, fd, took_over

    def release(self) -> None:
        if self._fd is None:
            return
        try:
            os.ftruncate(self._fd, 0)
            fcntl.flock(self._fd, fcntl.LOCK_UN)
        finally:
            os.close(self._fd)
            self._fd = None

    def __enter__(self) -> DirectoryLock:
        return self

    def __exit__(self, *exc) -> None:
        self.release()


def _holder(path: pathlib.Path) -> dict:
    try:
        info = json.loads(path.read_text() or "{}")
    except (OSError, ValueError):
        return {}
    return info if isinstance(info, dict) else {}


def _describe(info: dict) -> str:
    if not info:
        return "another process"
    return (
        f"pid {info.get('pid')} on {info.get('host')}, started {info.get('started')}"
        f"{': ' + info['command'] if info.get('command') else ''}"
    )


def acquire_lock(
    directory: str | os.PathLike, name: str, *, wait_s: float = 0.0, poll_s: float = 1.0, what: str = "run"
) -> DirectoryLock:
    """Lock DIR/NAME for this process. A lock file whose holder has ended is taken over
    (`DirectoryLock.took_over` = the old holder's record); one held by a running process is
    waited for up to `wait_s` seconds (`math.inf`: as long as it takes), then raises
    `DirectoryInUse` naming the holder and the way out."""
    path = pathlib.Path(directory) / name
    path.parent.mkdir(parents=True, exist_ok=True)
    if fcntl is None:  # pragma: no cover
        print(
            f"warning: cannot lock {path} on this system; make sure no other {what} writes there",
            file=sys.stderr,
        )
        return DirectoryLock(path, None, None)
    deadline = time.monotonic() + wait_s
    told = False
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            os.close(fd)
            if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                print(
                    f"warning: cannot lock {path} ({exc.strerror}); make sure no other {what} writes there",
                    file=sys.stderr,
                )
                return DirectoryLock(path, None, None)
            holder = _holder(path)
            if time.monotonic() >= deadline:
                wait = "" if wait_s > 0 else "; wait for it to finish (--wait-for-lock)"
                raise DirectoryInUse(
                    f"{directory} is in use by another {what} ({_describe(holder)}){wait} or "
                    "use another output directory"
                ) from None
            if not told:
                limit = "" if math.isinf(wait_s) else f" (up to {wait_s:g} s)"
                print(
                    f"{directory} is in use by another {what} ({_describe(holder)}); waiting{limit}",
                    file=sys.stderr,
                    flush=True,
                )
                told = True
            time.sleep(max(0.01, min(poll_s, deadline - time.monotonic())))
            continue
        old = _holder(path)
        record = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "command": " ".join(sys.argv),
        }
        os.ftruncate(fd, 0)
        os.pwrite(fd, json.dumps(record).encode(), 0)
        os.fsync(fd)
        return DirectoryLock(path, fd, old or None)
