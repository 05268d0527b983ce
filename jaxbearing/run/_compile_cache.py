"""Compile once: JAX's persistent compilation cache for every program that contains a solve.

Compiling `simulate` takes 10-40 s and the forward-mode gradient about 40 s; a second process
that compiles the same program reads it from the cache instead.

Three parts:

* `checks_without_host_callbacks`: JAX refuses to persist an executable that contains a host
  callback, and equinox implements its run-time checks (`equinox.internal.error_if`, under
  `EQX_ON_ERROR=raise`, the default) as host callbacks. The checks that diffrax traces into a
  solve with `throw=False` only validate the solve's own arguments (dt0 has the sign of
  t1 - t0; the save times increase and lie in [t0, t1]), which `solve` builds valid by
  construction from a positive duration. While `solve` traces diffrax they are traced with
  equinox's `on_error="nan"`: a violated check makes the state NaN, the step size collapses and
  the solve ends with a failure `result`, which `SimulationResult.status` reports, as every
  other failure of the integration is (diffrax's `throw=False`). Nothing else changes:
  equinox's global setting and checks traced outside `solve` are untouched.
* `enable_compilation_cache`: points JAX's persistent cache at a user cache directory,
  `$JAXBEARING_CACHE_DIR` if set (`off`, `0`, `false`, `no` or an empty value switch the cache
  off), else `$XDG_CACHE_HOME/jaxbearing/xla` (default `~/.cache/jaxbearing/xla`), and stores
  every compiled program in it, also the single operations eager code compiles (unless
  `$JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS` says otherwise). Called when `jaxbearing` is
  imported; a cache directory the user configured in JAX already is kept.
* `compiled_program`: the persistent cache skips compilation, not tracing, and tracing a solve's
  forward-mode Jacobian or a vmapped batch takes 5-10 s (the JVP and batching of diffrax's while
  loop). The library's programs (`simulate`, `solve_from`, the skid start, `design_jacobian`,
  the steady gradients and the one-device sweep batch) are therefore built once per machine
  and stored as `jax.export` artefacts (serialized StableHLO, "Exporting and serializing staged
  out computations" in JAX's documentation) in `programs/` inside the cache directory, keyed on
  the argument structure, shapes, dtypes and static arguments and on a digest of jaxbearing's
  source and the traced packages' versions. Each file is data only (`jaxbearing.io.tree_bytes`:
  the serialized program and the output structure in an `.npz` read with `allow_pickle=False`);
  a file that is not one (a pickle planted in the directory) is removed with a warning and the
  program built again, never executed. A second process deserializes the program instead of
  tracing it, and compiles it with a hit in the persistent cache
  (`benchmarks/bench_compile_cache.py`).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import warnings
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from ..io import atomic_write, tree_bytes, tree_from_bytes

#: environment variable naming the cache directory (or switching the cache off)
CACHE_ENV = "JAXBEARING_CACHE_DIR"
#: most bytes the stored programs keep (`programs/`): beyond it the least recently used are
#: removed when a new one is stored. A program is 0.3-1 MB, and every change of jaxbearing's
#: source makes new keys, so without a bound the folder grows with every version.
PROGRAM_CACHE_MAX_BYTES = 256 * 2**20
_OFF = {"", "0", "off", "false", "no", "none"}
#: JAX's own environment variable for the shortest compilation it stores (jaxbearing: 0 s)
MIN_COMPILE_TIME_ENV = "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS"


@contextlib.contextmanager
def checks_without_host_callbacks():
    """Trace equinox run-time checks (`equinox.internal.error_if`) with `on_error="nan"`."""
    import equinox.internal as eqxi

    original = eqxi.error_if

    def error_if(x, pred, msg, *, on_error="nan"):
        del on_error
        return original(x, pred, msg, on_error="nan")

    eqxi.error_if = error_if
    try:
        yield
    finally:
        eqxi.error_if = original


def default_cache_dir() -> Path:
    """$XDG_CACHE_HOME/jaxbearing/xla, or ~/.cache/jaxbearing/xla."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "jaxbearing" / "xla"


def cache_dir_from_environment() -> Path | None:
    """The cache directory `$JAXBEARING_CACHE_DIR` asks for; None when it switches the cache off."""
    value = os.environ.get(CACHE_ENV)
    if value is None:
        return default_cache_dir()
    if value.strip().lower() in _OFF:
        return None
    return Path(value).expanduser()


def enable_compilation_cache(directory: str | os.PathLike | None = None) -> Path | None:
    """Switch on JAX's persistent compilation cache (module docstring); returns the directory in
    use, or None when the cache is off. An explicit `directory` overrides the environment."""
    if jax.config.jax_compilation_cache_dir and directory is None:
        return Path(jax.config.jax_compilation_cache_dir)  # the user's own choice wins
    path = Path(directory).expanduser() if directory is not None else cache_dir_from_environment()
    if path is None:
        return None
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None  # an unwritable cache location must not stop the model from running
    jax.config.update("jax_compilation_cache_dir", str(path))
    # every program, down to the single operations that eager code compiles one by one (30-50 ms
    # each, thousands in a session): a second process compiles none of them again, about half the
    # time of eager-heavy test files (docs/performance.md). A user's own
    # JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS wins.
    if MIN_COMPILE_TIME_ENV not in os.environ:
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    return path


# --------------------------------------------------------------------------------------------
# Traced once per machine: programs exported to disk (jax.export)
# --------------------------------------------------------------------------------------------

#: bump when the layout of a stored program changes (2: a data-only `.npz`, `jaxbearing.io`'s
#: `tree_bytes`, instead of a pickle)
PROGRAM_FORMAT = 2
#: packages whose code is traced into a program (their versions are part of its key)
_TRACED_PACKAGES = ("jax", "jaxlib", "diffrax", "equinox", "lineax", "optimistix")
_PROGRAMS: dict = {}


class Program:
    """A compiled program called with the pytree structure it was built for: flattens the
    arguments, runs the executable, rebuilds the output tree."""

    def __init__(self, compiled, specs: tuple, out_tree, exported: bool):
        self._compiled = compiled
        self._dtypes = tuple(s.dtype for s in specs)
        self._out_tree = out_tree
        #: True when the program came through `jax.export` (stored on disk, or loaded from it)
        self.exported = exported

    def __call__(self, *args):
        leaves = jax.tree_util.tree_leaves(args)
        if len(leaves) != len(self._dtypes):
            raise TypeError(f"expected {len(self._dtypes)} array leaves, got {len(leaves)}")
        leaves = [jnp.asarray(x, dtype=d) for x, d in zip(leaves, self._dtypes)]
        return jax.tree_util.tree_unflatten(self._out_tree, self._compiled(*leaves))


def program_cache_dir() -> Path | None:
    """`programs/` inside JAX's persistent compilation cache directory; None when that cache is
    off (then nothing is stored)."""
    directory = jax.config.jax_compilation_cache_dir
    return Path(directory) / "programs" if directory else None


@functools.cache
def _code_digest() -> str:
    """sha256 of jaxbearing's own source and the versions of every package it traces: a program
    stored by other code is never loaded."""
    from importlib import metadata

    h = hashlib.sha256(f"format {PROGRAM_FORMAT}".encode())
    for package in _TRACED_PACKAGES:
        try:
            h.update(f"{package} {metadata.version(package)}".encode())
        except metadata.PackageNotFoundError:
            h.update(f"{package} -".encode())
    root = Path(__file__).resolve().parents[1]
    for path in sorted(root.rglob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def _program_key(name: str, in_tree, specs: tuple, static) -> str:
    text = "\n".join(
        [
            _code_digest(),
            name,
            jax.default_backend(),
            f"x64={jax.config.jax_enable_x64}",
            str(in_tree),
            repr([(s.shape, str(s.dtype)) for s in specs]),
            repr(static),
        ]
    )
    return hashlib.sha256(text.encode()).hexdigest()[:40]


def _load(path: Path):
    """(Exported, output tree) stored at `path`, or None (absent, unreadable or damaged: a
    damaged file, or one that is not a data-only program file, e.g. a pickle, which is never
    unpickled, is removed with a one-line warning and the program built again)."""
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        return None
    except OSError:
        return None
    try:
        entry = tree_from_bytes(data)
        exported = jax.export.deserialize(bytearray(np.asarray(entry["exported"], dtype=np.uint8).tobytes()))
        out_tree = jax.tree_util.tree_structure(entry["skeleton"])
    except Exception as exc:  # noqa: BLE001 - any damage means: build it again
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        warnings.warn(
            f"{path}: not a stored program ({reason}); removed, the program is built again", stacklevel=2
        )
        with contextlib.suppress(OSError):
            path.unlink()
        return None
    with contextlib.suppress(OSError):
        os.utime(path)  # used now: the last to be evicted (`_evict`)
    return exported, out_tree


def _store(path: Path, serialized: bytes, out_tree) -> None:
    """Write the serialized program atomically (`io.atomic_write`): whole or absent. A
    full or read-only disk only costs the next process the tracing; an output structure that is
    not plain data (`tree_bytes`) is not stored."""
    skeleton = jax.tree_util.tree_unflatten(out_tree, [0] * out_tree.num_leaves)
    try:
        data = tree_bytes({"exported": np.frombuffer(serialized, dtype=np.uint8), "skeleton": skeleton})
    except TypeError:
        return
    try:
        atomic_write(path, lambda f: f.write(data))
    except OSError:
        return
    _evict(path.parent, keep=path, max_bytes=PROGRAM_CACHE_MAX_BYTES)


def _evict(directory: Path, *, keep: Path, max_bytes: int, pattern: str = "*.jaxexport") -> None:
    """Remove the least recently used files matching `pattern` (oldest modification time: a
    load touches the files it reads) until those in `directory` take at most `max_bytes`;
    `keep` stays. Files another process removes meanwhile are skipped."""
    files = []
    for path in directory.glob(pattern):
        with contextlib.suppress(OSError):
            st = path.stat()
            files.append((st.st_mtime, st.st_size, path))
    total = sum(size for _, size, _ in files)
    for _, size, path in sorted(files, key=lambda f: f[0]):
        if total <= max_bytes:
            break
        if path == keep:
            continue
        with contextlib.suppress(OSError):
            path.unlink()
        total -= size


def _export(jitted, specs: tuple, box: dict):
    """(Exported, its serialized bytes, output tree) of the jitted flat function, or None where
    it cannot be exported (e.g. a progress meter's host callback): then the program is compiled
    the usual way, from the same trace (JAX caches it on the jitted function)."""
    try:
        exported = jax.export.export(jitted)(*specs)
        serialized = bytes(exported.serialize())  # effects and custom calls without a stable ABI fail here
    except Exception:  # noqa: BLE001 - the usual compilation re-raises a genuine error
        return None
    return exported, serialized, box["tree"]


def _build(name: str, fn, in_tree, specs: tuple, static) -> Program:
    box: dict = {}

    def flat(*leaves):
        out = fn(*jax.tree_util.tree_unflatten(in_tree, leaves))
        out_leaves, box["tree"] = jax.tree_util.tree_flatten(out)
        return out_leaves

    jitted = jax.jit(flat)
    directory = program_cache_dir()
    if directory is not None:
        path = directory / f"{name}-{_program_key(name, in_tree, specs, static)}.jaxexport"
        entry = _load(path)
        if entry is None:
            exported = _export(jitted, specs, box)
            if exported is not None:
                _store(path, *exported[1:])
                entry = exported[0], exported[2]
        if entry is not None:
            exported, out_tree = entry
            return Program(jax.jit(exported.call).lower(*specs).compile(), specs, out_tree, True)
    compiled = jitted.lower(*specs).compile()
    return Program(compiled, specs, box["tree"], False)


def compiled_program(name: str, fn, args: tuple, static=()) -> Program:
    """`fn(*args)` compiled once per process and traced once per machine.

    In a process, the program is kept per (name, argument structure, shapes and dtypes,
    `static`). On disk (`program_cache_dir`, when the persistent compilation cache is on), it is
    stored as a `jax.export` artefact keyed on the same and on jaxbearing's source and the traced
    packages' versions (`_code_digest`): a second process loads it instead of tracing `fn`, and
    its compilation is then a hit of the persistent compilation cache. `static` is everything
    `fn` closes over that changes the program (hashable, with a deterministic `repr`). `fn` must
    be pure in its arguments. Programs that `jax.export` cannot store (host callbacks) are
    compiled as usual.

    The key covers jaxbearing's source, not what was traced: code that monkeypatches
    jaxbearing's traced functions must run with the cache off (`JAXBEARING_CACHE_DIR=off`) or
    in a cache directory of its own. The folder keeps at most `PROGRAM_CACHE_MAX_BYTES`, least
    recently used programs first out; `rm -r` of `program_cache_dir()` forgets every program.
    """
    leaves, in_tree = jax.tree_util.tree_flatten(args)
    specs = tuple(jax.ShapeDtypeStruct(jnp.shape(x), jnp.result_type(x)) for x in leaves)
    key = (name, in_tree, specs, static)
    program = _PROGRAMS.get(key)
    if program is None:
        program = _PROGRAMS[key] = _build(name, fn, in_tree, specs, static)
    return program
