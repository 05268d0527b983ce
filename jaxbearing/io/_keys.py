"""The configuration key model: a `Key` (dotted path with unit, type, reference value, symbol,
meaning, range as `Bound`s, extra checks, the pytree field it maps onto), the unit conversions
between engineering units and SI, and the value formatting every error message uses. The keys
themselves are the table in `_schema.py`."""

from __future__ import annotations

import dataclasses
import json
import math
import numbers
import re
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ..geometry import rad_s_to_rpm, rpm_to_rad_s

#: gravitational acceleration used when `operating.gravity = true` [m/s^2] (as the reference).
GRAVITY = 9.81

# --------------------------------------------------------------------------------------------
# units: engineering value <-> SI. The micrometre conversion goes through millimetres so the
# reference configuration reproduces `reference_bearing()` bit for bit (0.020 * 1e-3).
_UNITS: dict[str, tuple[Callable[[float], float], Callable[[float], float]]] = {
    "mm": (lambda x: x * 1e-3, lambda x: x * 1e3),
    "um": (lambda x: (x / 1000) * 1e-3, lambda x: x * 1e6),
    "GPa": (lambda x: x * 1e9, lambda x: x / 1e9),
    "deg": (math.radians, math.degrees),
    "mrad": (lambda x: x * 1e-3, lambda x: x * 1e3),
    "rpm": (rpm_to_rad_s, rad_s_to_rpm),
}


def _identity(x):
    return x


def format_value(value: Any, digits: int = 12) -> str:
    """A value as shown in messages: floats to 12 significant digits (so that 0.30000000000000004
    reads 0.3; derived quantities use fewer), strings quoted, booleans in TOML spelling."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        v = float(value)
        if not math.isfinite(v):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
        return repr(float(f"{v:.{digits}g}"))
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple)):  # TOML array spelling
        return "[" + ", ".join(format_value(v, digits) for v in value) + "]"
    return repr(value)


def format_derived(x: float) -> str:
    """A quantity computed from other keys, for messages (6 significant digits)."""
    return format_value(x, digits=6)


def type_name(value: Any) -> str:
    """TOML-flavoured name of a value's type, for error messages."""
    if isinstance(value, (bool, np.bool_)):
        return "boolean"
    if isinstance(value, numbers.Integral):
        return "integer"
    if isinstance(value, numbers.Real):
        return "float"
    if isinstance(value, str):
        return "string"
    if isinstance(value, Mapping):
        return "table"
    if isinstance(value, (list, tuple)):
        return "array"
    return type(value).__name__


# --------------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class Bound:
    """One end of a valid range: a constant, or an expression of other keys (`deps`)."""

    label: str
    value: Callable[[Mapping[str, Any]], float]
    closed: bool
    deps: tuple[str, ...] = ()


def _short(x: float) -> str:
    """1e+08 -> 1e8, 1e-06 -> 1e-6, 100000 -> 100000."""
    return re.sub(r"e\+?(-?)0*(\d)", r"e\1\2", f"{x:g}")


def constant_bound(x: float, closed: bool) -> Bound:
    return Bound(_short(x), lambda v: x, closed)


def relative_bound(label: str, deps: tuple[str, ...], fn: Callable[..., float], closed: bool) -> Bound:
    return Bound(label, lambda v: fn(*(v[d] for d in deps)), closed, deps)


@dataclasses.dataclass(frozen=True)
class Extra:
    """A check that is not a range on one key (rollers fitting around the pitch circle...).

    `check(values)` returns None when satisfied, else the message (without the field name).
    """

    deps: tuple[str, ...]
    check: Callable[[Mapping[str, Any]], str | None]
    doc: str


@dataclasses.dataclass(frozen=True)
class Convert:
    """The conversion of a key whose value has no unit to convert: its value as written in the
    file to the pytree leaf (`to_si`) and back (`from_si`), e.g. a bearing type to the presence
    of its flanges."""

    to_si: Callable[[Any], Any]
    from_si: Callable[[Any], Any]


@dataclasses.dataclass(frozen=True)
class Key:
    """One configuration key.

    `attr` is the pytree field it maps onto: "pitch_diameter", "roller.diameter" (fields of
    `Bearing`) or "op.inner_speed" (fields of `OperatingPoint`); None for simulation settings.
    A string key with `choices` takes one of them; with `members` as well it also takes a list
    of distinct members (a TOML array, kept as a tuple): the flange arrangement
    `bearing.type`, a bearing type or a set of flanges. `convert` replaces the unit conversion.
    """

    path: str
    kind: type
    default: Any
    unit: str
    symbol: str
    meaning: str
    lo: Bound | None = None
    hi: Bound | None = None
    attr: str | None = None
    allow_inf: bool = False
    choices: tuple[str, ...] = ()
    members: tuple[str, ...] = ()
    convert: Convert | None = None
    extras: tuple[Extra, ...] = ()
    note: str = ""

    @property
    def section(self) -> str:
        return self.path.rpartition(".")[0]

    @property
    def name(self) -> str:
        return self.path.rpartition(".")[2]

    @property
    def deps(self) -> tuple[str, ...]:
        out: list[str] = []
        for b in (self.lo, self.hi):
            if b is not None:
                out += b.deps
        for e in self.extras:
            out += e.deps
        return tuple(dict.fromkeys(d for d in out if d != self.path))

    def to_si(self, value):
        if self.convert is not None:
            return self.convert.to_si(value)
        return _UNITS.get(self.unit, (_identity, _identity))[0](value)

    def from_si(self, value):
        if self.convert is not None:
            return self.convert.from_si(value)
        return _UNITS.get(self.unit, (_identity, _identity))[1](value)

    def range_text(self, values: Mapping[str, Any] | None = None) -> str:
        """'in (0, diameter_mm/2 = 3.75)' (values given) or 'in (0, diameter_mm/2)'."""
        if self.choices:
            text = "one of " + ", ".join(format_value(c) for c in self.choices)
            if self.members:
                text += " or a list of distinct names from " + ", ".join(
                    format_value(m) for m in self.members
                )
            return text
        if self.kind is bool:
            return "true or false"

        def show(b: Bound) -> str:
            if values is None or not b.deps:
                return b.label
            return f"{b.label} = {format_derived(b.value(values))}"

        lo, hi = self.lo, self.hi
        if lo is not None and hi is None and not self.allow_inf:
            return (">= " if lo.closed else "> ") + show(lo)
        lo_s = ("[" if lo.closed else "(") + show(lo) if lo is not None else "(-inf"
        hi_s = (
            (show(hi) + ("]" if hi.closed else ")"))
            if hi is not None
            else "inf" + ("]" if self.allow_inf else ")")
        )
        return f"in {lo_s}, {hi_s}"

    def doc(self) -> str:
        """One comment line: meaning, symbol, unit and valid range (and any further rule)."""
        sym = f" {self.symbol}" if self.symbol else ""
        unit = f" [{self.unit}]" if self.unit else ""
        kind = "integer " if self.kind is int else ""
        text = f"{self.meaning}{sym}{unit}, {kind}{self.range_text()}"
        for extra in (self.note, *(e.doc for e in self.extras)):
            if extra:
                text += f"; {extra}"
        return text


def make_key(path, kind, default, unit, symbol, meaning, lo=None, hi=None, **kw) -> Key:
    return Key(path, kind, default, unit, symbol, meaning, lo, hi, **kw)
