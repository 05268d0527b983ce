"""Measured cage speeds from a CSV file with units in its header (the source study's Figure 16
workflow: measured cage speed at stated shaft speeds and radial loads, against the model).

The file: lines starting with `#` are comments; the first other line is the header, one name and
unit in brackets per column; every further line one operating point::

    # test rig A, 2026-05-12, oil-air lubrication
    shaft speed [rpm], radial load [N], cage speed [rpm]
    10000, 1000, 4210
    20000, 1000, 8410

Columns (names case-insensitive; the order is free; other columns are ignored and listed):

| column | units | meaning |
|---|---|---|
| shaft speed | rpm, rad/s | inner-ring speed n_i (`operating.speed_rpm`) |
| radial load | N, kN | radial load F_r (`operating.radial_load_N`) |
| cage speed | rpm, rad/s | measured cage speed n_c |

Every value is checked: one line naming the file, the line, the column, the value and the valid
range (`UserInputError`), never a traceback or a silent NaN.
"""

from __future__ import annotations

import csv
import dataclasses
import math
import os
import re

from .._errors import UserInputError

#: column -> (accepted units -> factor to the unit used inside, the unit used inside)
COLUMNS = {
    "shaft speed": ({"rpm": 1.0, "rad/s": 30.0 / math.pi}, "rpm"),
    "radial load": ({"n": 1.0, "kn": 1e3}, "N"),
    "cage speed": ({"rpm": 1.0, "rad/s": 30.0 / math.pi}, "rpm"),
}
#: valid range of each column, in the unit used inside (the configuration's own ranges apply on
#: top when a point is run: `operating.speed_rpm`, `operating.radial_load_N`)
RANGES = {"shaft speed": (0.0, 1e5), "radial load": (0.0, 1e8), "cage speed": (0.0, 1e5)}
#: at most this many operating points in one file (each is a settled run)
MAX_POINTS = 1000

_HEADER_CELL = re.compile(r"^\s*(?P<name>[^\[\]]*?)\s*\[\s*(?P<unit>[^\[\]]+?)\s*\]\s*$")


@dataclasses.dataclass(frozen=True)
class CageSpeedMeasurement:
    """One measured operating point: shaft speed n_i [rpm], radial load F_r [N], measured cage
    speed n_c [rpm], and the line of the file it came from."""

    shaft_speed_rpm: float
    radial_load_N: float
    cage_speed_rpm: float
    line: int


def _lines(path: str) -> list[tuple[int, str]]:
    try:
        with open(path, encoding="utf-8-sig") as f:
            text = f.read()
    except UnicodeDecodeError:
        raise UserInputError(f"{path}: not a text (UTF-8) CSV file") from None
    except OSError as exc:
        raise UserInputError(f"{path}: cannot read the measurements: {exc.strerror or exc}") from None
    return [
        (i, s)
        for i, s in enumerate(text.splitlines(), start=1)
        if s.strip() and not s.lstrip().startswith("#")
    ]


def read_cage_speed_measurements(path: str | os.PathLike) -> tuple[list[CageSpeedMeasurement], list[str]]:
    """The measurements of `path` (module docstring) and the names of ignored columns;
    `UserInputError` (one line naming the file, line and column) for anything else."""
    path = os.fspath(path)
    lines = _lines(path)
    if not lines:
        raise UserInputError(
            f"{path}: no header and no data (expected e.g. 'shaft speed [rpm], radial load [N], cage speed [rpm]')"
        )
    rows = list(csv.reader([s for _, s in lines], skipinitialspace=True))
    header_line, header = lines[0][0], rows[0]
    where: dict[str, tuple[int, float]] = {}
    ignored = []
    for j, cell in enumerate(header):
        m = _HEADER_CELL.match(cell)
        name = " ".join((m.group("name") if m else cell).lower().split())
        if name not in COLUMNS:
            ignored.append(cell.strip())
            continue
        units, _ = COLUMNS[name]
        if not m:
            raise UserInputError(
                f"{path} line {header_line}: column {cell.strip()!r} has no unit; write it as "
                f"'{name} [{next(iter(units))}]' (units: {', '.join(units)})"
            )
        unit = m.group("unit").strip()
        if unit.lower() not in units:
            raise UserInputError(
                f"{path} line {header_line}: column {name!r} in {unit!r}: the unit must be one of "
                f"{', '.join(units)}"
            )
        if name in where:
            raise UserInputError(f"{path} line {header_line}: column {name!r} appears twice")
        where[name] = (j, units[unit.lower()])
    missing = [c for c in COLUMNS if c not in where]
    if missing:
        raise UserInputError(
            f"{path} line {header_line}: missing column(s) {', '.join(repr(c) for c in missing)} "
            f"(header: {', '.join(repr(c.strip()) for c in header)})"
        )
    if len(rows) - 1 > MAX_POINTS:
        raise UserInputError(f"{path}: {len(rows) - 1} operating points: at most {MAX_POINTS} in one file")
    if len(rows) == 1:
        raise UserInputError(f"{path}: a header but no operating point")
    points = []
    for (line, _), row in zip(lines[1:], rows[1:]):
        if len(row) != len(header):
            raise UserInputError(
                f"{path} line {line}: {len(row)} values, the header has {len(header)} columns"
            )
        values = {}
        for name, (j, factor) in where.items():
            text = row[j].strip()
            try:
                v = float(text) * factor
            except ValueError:
                v = math.nan
            lo, hi = RANGES[name]
            if not (math.isfinite(v) and lo <= v <= hi) or (name != "radial load" and v <= 0):
                unit = COLUMNS[name][1]
                bound = f"({lo:g}, {hi:g}]" if name != "radial load" else f"[{lo:g}, {hi:g}]"
                raise UserInputError(
                    f"{path} line {line}: {name} = {text!r}: must be a number in {bound} {unit} "
                    "(after conversion from the header's unit)"
                )
            values[name] = v
        points.append(
            CageSpeedMeasurement(
                shaft_speed_rpm=values["shaft speed"],
                radial_load_N=values["radial load"],
                cage_speed_rpm=values["cage speed"],
                line=line,
            )
        )
    return points, ignored
