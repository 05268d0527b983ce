"""Range checks on concrete values: one-line `UserInputError`s naming parameter, value and range.

The configuration schema (`_schema`, checked by `_validation`) checks engineering-unit keys; this module checks the
SI values of Python entry points (design variables, flange loads, solver arguments) the same
way: a check runs only on concrete values (under `jax.jit`/`grad`/`vmap` the caller's concrete
check has already run, outside the trace), and the first violating element is named.

Every public entry point that runs the model (`simulate`, `solve`, `flange_functionals`,
`design_metrics`, `design_jacobian`, `quasi_static`, the sweep and the `optimise` problem) goes
through `check_solve_inputs` / `check_solver_arguments` / `check_model_inputs` before anything
is traced. The valid ranges of the solver arguments are one table, `SOLVER_ARGUMENTS`
(name -> `Rule`); a new option is one new entry there.

What cannot be checked: inside `jax.jit`, `jax.grad` or `jax.vmap` the values are tracers and
have no value to check. Those checks are skipped (never an error): call the entry point once
with concrete values, or check them first with `validate_bearing` / `check_solver_arguments`.
Static arguments (`max_steps`, `num_saves`, `progress`) are Python values and are always
checked.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Callable, Mapping

import jax
import numpy as np

from .._errors import UserInputError


def is_concrete(*values) -> bool:
    """True when no value is a JAX tracer (so numpy can read it)."""
    return not any(isinstance(v, jax.core.Tracer) for v in jax.tree_util.tree_leaves(values))


def per_point(name: str, value, single: type, num_points: int) -> list:
    """`value` given once (an instance of `single`) or once per operating point, as a list of
    `num_points`; one line naming `name` when the count is neither."""
    values = [value] * num_points if isinstance(value, single) else list(value)
    if len(values) != num_points:
        raise UserInputError(
            f"{name}: {len(values)} given, expected one, or one per operating point ({num_points})"
        )
    return values


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


# -- rules: the valid range of one argument ------------------------------------------------------
def _short(x: float) -> str:
    return f"{x:g}".replace("e+0", "e").replace("e-0", "e-").replace("e+", "e")


def _shown(value) -> str:
    """A value as shown in messages: repr of strings, 'got <type>' of other objects."""
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, numbers.Number):
        return repr(value.item() if hasattr(value, "item") else value)
    if isinstance(value, str):
        return repr(value)
    return f"a {type(value).__name__}"


@dataclasses.dataclass(frozen=True)
class Rule:
    """The valid values of one argument.

    `kind`: "real" (one finite number, in the range lo..hi; "(" open or "[" closed ends), "count" (an integer, never a bool or a float, in lo..hi) or "bool".
    `unit` is shown after the range; `note` after that (what a special value means).
    """

    kind: str
    lo: float | None = None
    hi: float | None = None
    lo_closed: bool = False
    hi_closed: bool = False
    unit: str = ""
    note: str = ""

    def text(self) -> str:
        """The valid range in words: 'in (0, 1)', '> 0 s and finite', 'an integer >= 1'."""
        if self.kind == "bool":
            return "True or False"
        unit = f" {self.unit}" if self.unit else ""
        lo, hi = self.lo, self.hi
        if lo is not None and hi is not None:
            rng = (
                f"in {'[' if self.lo_closed else '('}{_short(lo)}, {_short(hi)}"
                f"{']' if self.hi_closed else ')'}{unit}"
            )
        elif lo is not None:
            rng = f"{'>=' if self.lo_closed else '>'} {_short(lo)}{unit}"
        elif hi is not None:
            rng = f"{'<=' if self.hi_closed else '<'} {_short(hi)}{unit}"
        else:
            rng = ""
        if self.kind == "count":
            text = f"an integer {rng}".rstrip()
        else:
            text = f"{rng} and finite" if rng else f"finite{unit}"
        return f"{text} ({self.note})" if self.note else text

    def _in_range(self, v: np.ndarray) -> np.ndarray:
        ok = np.ones(np.shape(v), dtype=bool)
        if self.lo is not None:
            ok &= (v >= self.lo) if self.lo_closed else (v > self.lo)
        if self.hi is not None:
            ok &= (v <= self.hi) if self.hi_closed else (v < self.hi)
        return ok

    def check(self, name: str, value) -> None:
        """Raise `UserInputError("{name} = {value}: must be {text}")` unless `value` is valid;
        traced (under jit/grad/vmap) values pass."""

        def fail(shown: str):
            raise UserInputError(f"{name} = {shown}: must be {self.text()}")

        if self.kind == "bool":
            if not isinstance(value, (bool, np.bool_)):
                fail(_shown(value))
            return
        if self.kind == "count":
            if not is_concrete(value):  # a traced integer (e.g. the scatter seed under jit)
                if getattr(value, "dtype", np.dtype(float)).kind not in "iu":
                    fail(f"a traced {getattr(value, 'dtype', 'value')}")
                return
            integral = isinstance(value, numbers.Integral) or (
                np.ndim(value) == 0 and getattr(value, "dtype", np.dtype(float)).kind in "iu"
            )
            if isinstance(value, (bool, np.bool_)) or not integral:
                fail(_shown(value))
            if not self._in_range(np.asarray(int(value), dtype=float)):
                fail(str(int(value)))
            return
        if not is_concrete(value):
            return
        if isinstance(value, (bool, np.bool_, str)) or value is None:
            fail(_shown(value))
        try:
            kind = np.asarray(value).dtype.kind
            v = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            fail(_shown(value))
        if kind not in "iuf":
            fail(_shown(value))
        if v.ndim:
            fail(f"an array of shape {v.shape} (one value is needed)")
        with np.errstate(invalid="ignore"):
            bad = ~(np.isfinite(v) & self._in_range(v))
        if np.any(bad):
            first = float(v if v.ndim == 0 else v[bad].ravel()[0])
            fail(repr(float(f"{first:.12g}")) if math.isfinite(first) else repr(first))


def real(lo=None, hi=None, *, lo_closed=False, hi_closed=False, unit="", note="") -> Rule:
    """A rule for a finite real number in the range lo..hi (open ends unless closed)."""
    return Rule("real", lo, hi, lo_closed, hi_closed, unit, note)


def count(lo=None, hi=None, *, note="") -> Rule:
    """A rule for an integer in [lo, hi]."""
    return Rule("count", lo, hi, True, True, "", note)


#: The solver arguments of every entry point that runs the dynamics (`solve`, `simulate`,
#: `flange_functionals`, `design_metrics`, the sweep, the `optimise` problem). A new option is
#: one entry here; `check_solver_arguments(name=value)` then checks it everywhere.
SOLVER_ARGUMENTS: dict[str, Rule] = {
    "duration": real(0, unit="s", note="simulated time"),
    "rtol": real(0, 1, note="relative tolerance"),
    "atol": real(0, 1, note="absolute tolerance on the scaled state"),
    "max_steps": count(1, 1_000_000_000),
    "num_saves": count(0, note="0 = only the smooth functionals at the end"),
    "progress": Rule("bool"),
    "window_revs": real(0, unit="cage revolutions"),
    "seeds": count(1, note="number of seeded repeats"),
    "raceway_loosen": real(0, note="factor on the raceway-normal coordinates' tolerances"),
    "rotation_loosen": real(0, note="factor on the rollers' orbit and spin and the cage's tolerances"),
}

#: `simulate` keeps histories: at least one sample
SIMULATE_NUM_SAVES = count(1, note="samples of the histories")

#: fields of `jaxbearing.Perturbation` (initial roller scatter)
PERTURBATION_FIELDS: dict[str, Rule] = {
    "seed": count(),
    "axial": real(0, lo_closed=True, unit="m"),
    "skew": real(0, lo_closed=True, unit="rad"),
}

#: fields of `jaxbearing.Functionals` (smooth peak functionals)
FUNCTIONALS_FIELDS: dict[str, Rule] = {
    "pv_reference": real(0, unit="Pa m/s"),
    "pv_exponent": real(0),
    "height_reference": real(unit="m"),
    "height_sharpness": real(0, unit="1/m"),
    "contact_load": real(0, unit="N"),
}


def check_arguments(values: Mapping[str, object], rules: Mapping[str, Rule]) -> None:
    """Check each named value against its rule (None = left at its default, not checked)."""
    for name, value in values.items():
        if name not in rules:
            raise TypeError(f"no validation rule for argument {name!r}; add it to the table")
        if value is not None:
            rules[name].check(name, value)


def check_solver_arguments(**values) -> None:
    """Check solver arguments by name against `SOLVER_ARGUMENTS` (None values are skipped):
    ``check_solver_arguments(duration=0.02, rtol=1e-3)``. Raises a one-line UserInputError,
    e.g. ``rtol = nan: must be in (0, 1) and finite (relative tolerance)``."""
    check_arguments(values, SOLVER_ARGUMENTS)


def check_fields(name: str, obj, rules: Mapping[str, Rule]) -> None:
    """Check the fields of `obj` (a Perturbation, Functionals...) named in `rules`, as
    ``name.field``."""
    for field, rule in rules.items():
        rule.check(f"{name}.{field}", getattr(obj, field))


def check_model_inputs(bearing, op=None) -> None:
    """`validate_bearing(bearing, op)` on every concrete leaf: checks that involve a traced leaf
    (under jit/grad/vmap) are skipped. Raises ConfigError naming the configuration key."""
    from ._validation import validate_bearing

    validate_bearing(bearing, op, traced="skip")


def check_solve_inputs(
    bearing,
    op,
    *,
    perturbation=None,
    functionals=None,
    rules: Mapping[str, Rule] | None = None,
    **solver_arguments,
) -> None:
    """Everything a solve takes, before anything is traced: the solver arguments
    (`SOLVER_ARGUMENTS`, or `rules` where given), the perturbation and functionals fields, then
    the bearing and operating point (`check_model_inputs`)."""
    check_arguments(solver_arguments, {**SOLVER_ARGUMENTS, **(rules or {})})
    if perturbation is not None:
        check_fields("perturbation", perturbation, PERTURBATION_FIELDS)
    if functionals is not None:
        check_fields("functionals", functionals, FUNCTIONALS_FIELDS)
    check_model_inputs(bearing, op)
