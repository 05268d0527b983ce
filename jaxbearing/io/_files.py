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

Output directories are checked before any work (`check_output_dir`: created if needed, a file
written and removed there, and whatever it created removed again, so a rejected command leaves
no empty directory), and results are never lost after it (`write_or_fallback`: when writing
into the output directory fails, they go to a fresh fallback directory,
`$XDG_CACHE_HOME/jaxbearing/results/<time>-<pid>` or one under the system's temporary
directory, whose path the caller prints; the command line exits with its own status 4).
"""

from __future__ import annotations

import json
import math
import os
import pathlib
import socket
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from .._errors import UserInputError

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


def finite_or_none(x) -> float | None:
    """`x` as a float, or None where it is missing or not finite (JSON has no NaN)."""
    if x is None:
        return None
    v = float(x)
    return v if math.isfinite(v) else None


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


# -- output directories --------------------------------------------------------------------------
def check_output_dir(path: str | os.PathLike, option: str = "--out") -> None:
    """Raise `UserInputError` (one line naming `option`, the path and why) unless `path` is a
    directory this process can create files in, or can be created as one. Checked by writing
    and removing a file; directories created for the check are removed again."""
    p = pathlib.Path(path)
    shown = f"{option} {os.fspath(path)}"
    if p.exists() and not p.is_dir():
        raise UserInputError(f"{shown}: exists and is not a directory; name a directory")
    missing = []
    anc = p
    while not anc.exists() and not anc.is_symlink():
        missing.append(anc)
        if anc.parent == anc:
            break
        anc = anc.parent
    if anc.exists() and not anc.is_dir():
        raise UserInputError(f"{shown}: cannot create the directory: {anc} is not a directory")
    try:
        # processes of one distributed run check the same new directory at once; one may remove
        # the directory it created for its check while another probes it: create and probe again
        for attempt in range(3):
            try:
                p.mkdir(parents=True, exist_ok=True)
                probe = p / f".jaxbearing-write-test.{_host()}.{os.getpid()}"
                with open(probe, "wb") as f:
                    f.write(b"ok")
                probe.unlink()
                break
            except FileNotFoundError:
                if attempt == 2:
                    raise
    except OSError as exc:
        raise UserInputError(
            f"{shown}: cannot write there: {exc.strerror or exc}; choose a writable directory"
        ) from None
    finally:
        for d in missing:  # deepest first
            try:
                d.rmdir()
            except OSError:
                break


def fallback_dir() -> pathlib.Path:
    """A fresh directory for results that could not be written where asked:
    `$XDG_CACHE_HOME/jaxbearing/results/<time>-<pid>` (default `~/.cache`), else a new one under
    the system's temporary directory."""
    import tempfile

    stamp = f"{time.strftime('%Y%m%dT%H%M%S')}-{os.getpid()}"
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    candidate = pathlib.Path(base) / "jaxbearing" / "results" / stamp
    try:
        candidate.mkdir(parents=True, exist_ok=False)
        return candidate
    except OSError:
        return pathlib.Path(tempfile.mkdtemp(prefix=f"jaxbearing-results-{stamp}-"))


def write_or_fallback(
    path: str | os.PathLike, write: Callable[[pathlib.Path], Any]
) -> tuple[pathlib.Path, str | None]:
    """`write(directory)` into `path`; if that fails with an OSError, into `fallback_dir()`.
    Returns (the directory written, None) or (the fallback directory, why `path` failed). A
    failure of the fallback too raises `UserInputError` naming both."""
    path = pathlib.Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
        write(path)
        return path, None
    except OSError as exc:
        reason = f"{exc.strerror or exc}" + (f": {exc.filename}" if getattr(exc, "filename", None) else "")
    other = fallback_dir()
    try:
        write(other)
    except OSError as exc:
        raise UserInputError(
            f"results could not be written to {path} ({reason}) nor to {other} ({exc.strerror or exc})"
        ) from None
    return other, reason


# -- self-describing results ---------------------------------------------------------------------
#: unit of a result quantity by the suffix of its name (longest first); names without one are
#: dimensionless ratios, counts, flags or text
_UNIT_SUFFIXES = (
    ("_GPa_m_s", "GPa m/s"),
    ("_Pa_m_s", "Pa m/s"),
    ("_m_s", "m/s"),
    ("_rad_s", "rad/s"),
    ("_Pa", "Pa"),
    ("_GPa", "GPa"),
    ("_N", "N"),
    ("_mm", "mm"),
    ("_um", "um"),
    ("_m", "m"),
    ("_ms", "ms"),
    ("_s", "s"),
    ("_rpm", "rpm"),
    ("_deg", "deg"),
    ("_mrad", "mrad"),
    ("_kg", "kg"),
    ("_W", "W"),
    ("_K", "K"),
)


def unit_of(name: str) -> str:
    """The unit a result name carries in its suffix (`flange_force_N` -> "N"); "1" for
    dimensionless quantities (shares, slips, counts, codes, text)."""
    for suffix, unit in _UNIT_SUFFIXES:
        if name.endswith(suffix):
            return unit
    return "1"


def units_of(doc: dict) -> dict[str, str]:
    """{key: unit} for every top-level key of a result document (`unit_of`)."""
    return {k: unit_of(k) for k in doc if isinstance(k, str)}


#: the command line being run (`set_command_line`, by the command-line dispatcher)
_COMMAND_LINE: list[str] | None = None


def set_command_line(argv: list[str] | None) -> None:
    """Record the command line being run, as `provenance` reports it (None: `sys.argv`)."""
    global _COMMAND_LINE
    _COMMAND_LINE = None if argv is None else [str(a) for a in argv]


def provenance(config=None, *, seeds=None, argv: list[str] | None = None) -> dict:
    """What produced a result: the package version, the command line, the full configuration in
    engineering units (`Config.to_dict`, and its TOML text, which `loads_config` reads back to an
    equal configuration; non-finite values such as a flat end's inf are exact there), the seeds."""
    package = sys.modules.get(__name__.split(".")[0])
    doc: dict[str, Any] = {
        "jaxbearing_version": getattr(package, "__version__", "unknown"),
        "command": list(argv if argv is not None else (_COMMAND_LINE or sys.argv)),
    }
    if config is not None:
        doc["config"] = config.to_dict()
        doc["config_toml"] = config.to_toml(comments=False)
    doc["seeds"] = seeds
    return doc
