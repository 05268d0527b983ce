"""The `[uncertainty]` table of a configuration file: which keys' values are not known exactly,
by how much, and for an estimated value the rule that gave it.

    [uncertainty]
    "roller.diameter_mm" = { plus_minus = 2.0, estimated = "D ~ 0.25 (D_o - d_b) ..." }
    "lubricant.oil_fraction" = { plus_minus = 0.03 }

Each entry names a numeric configuration key (dotted, quoted) and gives `plus_minus`, the
half-width of the value's uncertainty in the key's own unit (the key value +/- plus_minus), and
optionally `estimated`, the rule the value was estimated by (`jaxbearing config new` writes one
for every key it estimates). An entry without `estimated` marks a value the user knows only
roughly. The table is data only: it changes no model input, `config show` marks these keys,
and a sensitivity study reads each key's stated uncertainty from it.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from collections.abc import Callable, Mapping
from typing import Any

import tomli_w

from .._errors import ConfigError
from ._keys import format_value, type_name
from ._schema import KEY_BY_PATH

#: the name of the table in a configuration file
SECTION = "uncertainty"


@dataclasses.dataclass(frozen=True)
class Uncertainty:
    """The stated uncertainty of one configuration key's value.

    `plus_minus`: half-width in the key's unit (the value is known to +/- plus_minus);
    `estimated`: the rule the value was estimated by, "" for a value the user marked uncertain.
    """

    plus_minus: float
    estimated: str = ""

    def comment(self, unit: str) -> str:
        """The mark `config show` puts above the key: estimated or uncertain, and by how much."""
        unit = f" {unit}" if unit else ""
        head = "ESTIMATED" if self.estimated else "UNCERTAIN"
        tail = f": {self.estimated}" if self.estimated else ""
        return f"{head} (+/- {format_value(self.plus_minus)}{unit}){tail}"

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"plus_minus": self.plus_minus}
        if self.estimated:
            out["estimated"] = self.estimated
        return out


def parse_uncertainty(table: Any, unknown_path: Callable[[str], ConfigError]) -> dict[str, Uncertainty]:
    """The validated `[uncertainty]` table, {dotted key: Uncertainty}; `unknown_path(path)` makes
    the error for a path that names no key (with its "did you mean" suggestion). Raises
    ConfigError naming the entry, the value and what it must be."""
    if not isinstance(table, Mapping):
        raise ConfigError(SECTION, f"expected a table [{SECTION}], got {type_name(table)}")
    out: dict[str, Uncertainty] = {}
    for path, entry in table.items():
        field = f'{SECTION}."{path}"'
        key = KEY_BY_PATH.get(path)
        if key is None:
            exc = unknown_path(str(path))
            raise ConfigError(field, str(exc).partition(": ")[2]) from None
        if key.kind not in (int, float):
            raise ConfigError(
                field, f"{path} is a {key.kind.__name__} key: only numeric keys have an uncertainty"
            )
        if isinstance(entry, numbers.Real) and not isinstance(entry, bool):
            entry = {"plus_minus": entry}
        if not isinstance(entry, Mapping):
            raise ConfigError(
                field, f'expected {{ plus_minus = number, estimated = "rule" }}, got {type_name(entry)}'
            )
        extra = set(entry) - {"plus_minus", "estimated"}
        if extra:
            raise ConfigError(f"{field}.{sorted(extra)[0]}", "unknown field; valid: plus_minus, estimated")
        if "plus_minus" not in entry:
            raise ConfigError(
                f"{field}.plus_minus", "missing: the half-width of the uncertainty in the key's unit"
            )
        pm = entry["plus_minus"]
        unit = f" {key.unit}" if key.unit else ""
        if isinstance(pm, bool) or not isinstance(pm, numbers.Real) or not math.isfinite(pm) or pm < 0:
            shown = format_value(pm) if isinstance(pm, numbers.Real) else type_name(pm)
            raise ConfigError(
                f"{field}.plus_minus", f"{shown}{unit} is out of range: must be a finite number >= 0{unit}"
            )
        if key.kind is int and float(pm) != int(pm):
            raise ConfigError(
                f"{field}.plus_minus", f"{format_value(pm)} must be a whole number ({path} is an integer)"
            )
        rule = entry.get("estimated", "")
        if not isinstance(rule, str):
            raise ConfigError(f"{field}.estimated", f"expected a string (the rule), got {type_name(rule)}")
        out[path] = Uncertainty(int(pm) if key.kind is int else float(pm), rule)
    return {p: out[p] for p in KEY_BY_PATH if p in out}  # schema order


def uncertainty_toml(table: Mapping[str, Uncertainty]) -> list[str]:
    """The `[uncertainty]` table as TOML lines, one inline table per key (empty: no lines)."""
    if not table:
        return []
    lines = [f"[{SECTION}]"]
    for path, u in table.items():
        fields = ", ".join(tomli_w.dumps({k: v}).rstrip("\n") for k, v in u.to_dict().items())
        lines.append(f'"{path}" = {{ {fields} }}')
    return lines
