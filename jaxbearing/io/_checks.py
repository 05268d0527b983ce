"""Range checks on concrete values: one-line `UserInputError`s naming parameter, value and range.

The configuration schema (`_validation`) checks engineering-unit keys; this module checks the
SI values of Python entry points (design variables, flange loads, solver arguments) the same
way: a check runs only on concrete values (under `jax.jit`/`grad`/`vmap` the caller's concrete
check has already run, outside the trace), and the first violating element is named.
"""

from __future__ import annotations

from collections.abc import Callable

import jax
import numpy as np

from .._errors import UserInputError


def is_concrete(*values) -> bool:
    """True when no value is a JAX tracer (so numpy can read it)."""
    return not any(isinstance(v, jax.core.Tracer) for v in values)


def require(name: str, value, ok: Callable[[np.ndarray], np.ndarray], valid: str) -> None:
    """Raise `UserInputError("{name} = {value}: must be {valid}")` when a concrete `value` (any
    shape) has an element for which `ok` is False or that is NaN; traced values pass."""
    if not is_concrete(value):
        return
    v = np.asarray(value, dtype=float)
    with np.errstate(invalid="ignore"):
        bad = ~np.asarray(ok(v), dtype=bool) | np.isnan(v)
    if np.any(bad):
        shown = float(v) if v.ndim == 0 else float(v[bad].ravel()[0])
        raise UserInputError(f"{name} = {shown}: must be {valid}")
