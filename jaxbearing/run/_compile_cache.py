"""Compile once: JAX's persistent compilation cache for every program that contains a solve.

Compiling `simulate` takes 10-40 s and the forward-mode gradient about 40 s; a second process
that compiles the same program reads it from the cache instead.

Two parts:

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
  off), else `$XDG_CACHE_HOME/jaxbearing/xla` (default `~/.cache/jaxbearing/xla`). Called when
  `jaxbearing` is imported; a cache directory the user configured in JAX already is kept.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

import jax

#: environment variable naming the cache directory (or switching the cache off)
CACHE_ENV = "JAXBEARING_CACHE_DIR"
_OFF = {"", "0", "off", "false", "no", "none"}


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
    # every solve program is worth caching; tiny helper programs are not
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 1.0)
    return path
