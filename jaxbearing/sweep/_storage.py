"""Sweep output directory: atomic batch files, the spec, the log, what is already computed, and
damaged batch files (moved aside to DIR/batches/damaged/ and computed again)."""

from __future__ import annotations

import json
import os
import pathlib
import time

import numpy as np

from ..io import atomic_write
from ._spec import SweepSpec, SweepSpecError


# -- files ---------------------------------------------------------------------------------------
def batch_path(out_dir: pathlib.Path, batch: int) -> pathlib.Path:
    return pathlib.Path(out_dir) / "batches" / f"batch_{batch:05d}.npz"


def damaged_dir(out_dir: pathlib.Path) -> pathlib.Path:
    """DIR/batches/damaged: where batch files that fail to load are moved."""
    return pathlib.Path(out_dir) / "batches" / "damaged"


def write_batch(out_dir: pathlib.Path, spec: SweepSpec, batch: int, data: dict) -> pathlib.Path:
    path = batch_path(out_dir, batch)
    atomic_write(path, lambda f: np.savez(f, spec_hash=np.asarray(spec.hash), batch=np.int64(batch), **data))
    return path


def load_batch_file(path: pathlib.Path) -> dict:
    """Every array of a batch file; raises `DamagedBatch` (with the reason) when it does not
    load (truncated by a full disk or power loss: zipfile.BadZipFile, EOFError, zlib.error...)
    and FileNotFoundError when there is none."""
    try:
        with np.load(path, allow_pickle=False) as z:
            return {k: z[k] for k in z.files}
    except FileNotFoundError:
        raise
    except Exception as exc:  # noqa: BLE001 (any failure to load means a damaged file)
        raise DamagedBatch(f"{type(exc).__name__}: {exc}") from exc


class DamagedBatch(Exception):
    """A batch file exists but does not load."""


def read_batch(out_dir: pathlib.Path, spec: SweepSpec, batch: int) -> dict | None:
    """The contents of a finished batch file, or None if it is missing, damaged (does not
    load), of another spec or of other cases. Never raises."""
    path = batch_path(out_dir, batch)
    try:
        data = load_batch_file(path)
    except (OSError, DamagedBatch):
        return None
    if str(data.get("spec_hash")) != spec.hash:
        return None
    if not np.array_equal(data.get("case_index"), spec.batch_cases(batch)):
        return None
    return data


def set_aside_damaged(out_dir: pathlib.Path, batches) -> list[tuple[int, str, pathlib.Path]]:
    """Move every batch file of `batches` that does not load to DIR/batches/damaged/ (named
    with the time, so nothing is overwritten); returns (batch, reason, new path) of each."""
    moved = []
    for b in batches:
        path = batch_path(out_dir, b)
        try:
            load_batch_file(path)
        except FileNotFoundError:
            continue
        except (OSError, DamagedBatch) as exc:
            target = damaged_dir(out_dir) / f"{path.name}.{time.strftime('%Y%m%dT%H%M%S')}.{os.getpid()}"
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(path, target)
            moved.append((b, str(exc), target))
    return moved


def append_log(out_dir: pathlib.Path, record: dict) -> None:
    line = json.dumps(record) + "\n"
    fd = os.open(pathlib.Path(out_dir) / "sweep.log", os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
    try:
        os.write(fd, line.encode())
    finally:
        os.close(fd)


def computed_batches(out_dir: str | os.PathLike) -> list[int]:
    """Batch indices computed so far, from DIR/sweep.log, one entry per computation."""
    path = pathlib.Path(out_dir) / "sweep.log"
    if not path.exists():
        return []
    out = []
    for line in path.read_bytes().decode("utf-8", errors="replace").splitlines():
        try:
            rec = json.loads(line)
        except ValueError:
            continue  # a line cut by a kill
        if isinstance(rec, dict) and rec.get("event") == "batch" and isinstance(rec.get("batch"), int):
            out.append(int(rec["batch"]))
    return out


def prepare_dir(out_dir: pathlib.Path, spec: SweepSpec, resume: bool, process_id: int) -> None:
    """Create DIR and DIR/spec.json; a DIR holding another sweep is an error when resuming."""
    out_dir.mkdir(parents=True, exist_ok=True)
    spec_file = out_dir / "spec.json"
    if spec_file.exists() and resume:
        try:
            old = json.loads(spec_file.read_bytes())
        except (OSError, ValueError):  # unreadable, not UTF-8, not JSON
            old = {"hash": "(not a spec file)"}
        if not isinstance(old, dict):
            old = {"hash": "(not a spec file)"}
        if old.get("hash") != spec.hash:
            raise SweepSpecError(
                "--out",
                f"{out_dir} holds another sweep (spec hash {old.get('hash')}, this one "
                f"{spec.hash}; the spec or --batch-size changed); use another --out or --no-resume",
            )
    if process_id == 0:
        doc = {"hash": spec.hash, "spec": spec.canonical()}
        atomic_write(spec_file, lambda f: f.write(json.dumps(doc, indent=1, allow_nan=True).encode()))
        if not resume:
            (out_dir / "results.nc").unlink(missing_ok=True)


def load_spec_from_dir(out_dir: str | os.PathLike) -> SweepSpec:
    """The spec of the sweep in DIR (from DIR/spec.json)."""
    path = pathlib.Path(out_dir) / "spec.json"
    try:
        doc = json.loads(path.read_bytes())
    except OSError:
        raise SweepSpecError("DIR", f"{out_dir} is not a sweep directory (no spec.json)") from None
    except ValueError:
        raise SweepSpecError("DIR", f"{path}: not a sweep spec file (not JSON); not loaded") from None
    try:
        return SweepSpec.from_canonical(doc["spec"])
    except SweepSpecError:
        raise
    except Exception as exc:  # noqa: BLE001 - any malformed content: one line naming the file
        raise SweepSpecError(
            "DIR", f"{path}: not a sweep spec file ({type(exc).__name__}); not loaded"
        ) from None
