"""Result files that are whole or absent, and strict JSON.

`atomic_write` writes to a temporary file next to the target, fsyncs it and renames it over the
target (`os.replace`), so a file at its final name is always complete: a process killed while
writing (SIGKILL, power loss before the rename) leaves at most a temporary file
`.NAME.HOST.PID.tmp`, which `remove_stale_temporaries` deletes later.

`to_strict_json` turns a result document into strict JSON (RFC 8259: no NaN or Infinity
tokens, which strict parsers reject): every non-finite float becomes `null`, and the document
records why under `"null_reasons"` (dotted path -> reason), e.g.
``{"smooth_peak_pv_Pa_m_s": null, ..., "null_reasons": {"smooth_peak_pv_Pa_m_s": "nan: the run
failed (see status)"}}``.
"""

from __future__ import annotations

import json
import math
import os
import pathlib
import socket
from collections.abc import Callable
from typing import Any

import numpy as np

#: key under which `to_strict_json` records why values are null
NULL_REASONS = "null_reasons"


def _host() -> str:
    return socket.gethostname().replace(".", "_").replace("/", "_") or "host"


def temporary_name(path: pathlib.Path) -> pathlib.Path:
    """`.NAME.HOST.PID.tmp` next to `path` (the writer is named, so its files can be cleaned)."""
    return path.with_name(f".{path.name}.{_host()}.{os.getpid()}.tmp")


def atomic_write(path: str | os.PathLike, write: Callable) -> None:
    """Write through `write(binary file)` to a temporary file next to `path`, fsync, rename."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = temporary_name(path)
    try:
        with open(tmp, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def remove_stale_temporaries(directory: str | os.PathLike, *, all_hosts: bool = False) -> list[pathlib.Path]:
    """Delete temporary files of `atomic_write` in `directory` whose writer is gone: written on
    this host by a process that no longer runs (or on any host, with `all_hosts`, when the
    caller knows no other process writes there). Returns the files removed."""
    removed = []
    host = _host()
    for tmp in pathlib.Path(directory).glob(".*.tmp*"):
        stem = tmp.name[: -len(".tmp")] if tmp.name.endswith(".tmp") else None
        parts = stem.rsplit(".", 2) if stem else []
        if len(parts) == 3 and parts[2].isdigit():
            mine = parts[1] == host
            stale = (mine and not _pid_alive(int(parts[2]))) or (all_hosts and not mine)
        else:  # the older name `.NAME.tmpPID`
            pid = tmp.name.rpartition(".tmp")[2]
            stale = all_hosts or (pid.isdigit() and not _pid_alive(int(pid)))
        if stale and tmp.is_file():
            tmp.unlink(missing_ok=True)
            removed.append(tmp)
    return removed


# -- strict JSON ---------------------------------------------------------------------------------
def _nonfinite_text(v: float) -> str:
    return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")


def to_strict_json(doc: Any, reason: str | None = None) -> tuple[Any, dict[str, str]]:
    """(a copy of `doc` with every non-finite float replaced by None, {dotted path: reason}).

    numpy scalars and arrays become Python numbers and lists; the reason of each replaced value
    is "nan", "inf" or "-inf", followed by ": `reason`" when one is given."""
    reasons: dict[str, str] = {}

    def walk(x, path: str):
        if isinstance(x, dict):
            return {k: walk(v, f"{path}.{k}" if path else str(k)) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [walk(v, f"{path}[{i}]") for i, v in enumerate(x)]
        if isinstance(x, np.ndarray):
            return walk(x.tolist(), path)
        if isinstance(x, (bool, np.bool_)):
            return bool(x)
        if isinstance(x, (int, np.integer)):
            return int(x)
        if isinstance(x, (float, np.floating)):
            v = float(x)
            if math.isfinite(v):
                return v
            reasons[path] = _nonfinite_text(v) + (f": {reason}" if reason else "")
            return None
        return x

    return walk(doc, ""), reasons


def with_null_reasons(doc: dict, reason: str | None = None) -> dict:
    """`doc` made strict (`to_strict_json`) with the reasons for its nulls added under
    `"null_reasons"` (only when there are any)."""
    clean, reasons = to_strict_json(doc, reason)
    if reasons:
        clean[NULL_REASONS] = {**clean.get(NULL_REASONS, {}), **reasons}
    return clean


def dumps_strict(doc: Any, *, reason: str | None = None, indent: int | None = 2) -> str:
    """Strict JSON text of `doc`: non-finite floats as null, with their reasons under
    `"null_reasons"` when `doc` is a dict (`with_null_reasons`); never a NaN token."""
    clean = with_null_reasons(doc, reason) if isinstance(doc, dict) else to_strict_json(doc)[0]
    return json.dumps(clean, indent=indent, allow_nan=False)


def write_json(path: str | os.PathLike, doc: Any, *, reason: str | None = None) -> None:
    """Write `doc` as strict JSON (`dumps_strict`), atomically (`atomic_write`)."""
    text = dumps_strict(doc, reason=reason) + "\n"
    atomic_write(path, lambda f: f.write(text.encode()))
