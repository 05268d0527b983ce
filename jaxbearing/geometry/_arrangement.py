"""Flange arrangement of a cylindrical roller bearing by type: which of the four flanges are
there (docs/model.md 5.3).

A cylindrical roller bearing has up to two flanges (ribs) on each ring. The catalogue types
(DIN 5412-1; the cylindrical roller bearing pages of the SKF and Schaeffler catalogues) differ
only in which are there:

| type | inner ring | outer ring | axial location of the inner ring |
|---|---|---|---|
| NUP | both sides | both sides | both directions (the model's reference bearing) |
| NU  | none       | both sides | none: the inner ring floats axially |
| N   | both sides | none       | none: the outer ring floats axially |
| NJ  | -X side    | both sides | one direction: an axial load along +X |

The NJ's one inner rib is on the -X side so that it carries the configuration's positive axial
load (`operating.axial_load_N` > 0 pushes the inner ring along +X: its -X rib pushes the
rollers' -X ends, the outer ring's +X rib holds them); a load along -X finds no rib.

The presence of each flange is a float, 1.0 (there) or 0.0 (absent), in the order of
`FLANGES` (that of every per-flange array, `jaxbearing.flange.FLANGE_ORDER`), and is data of the
`Bearing` pytree (`Bearing.flange_presence`), not a static setting: bearings of different types
run in one compiled program and one vmapped batch.
"""

from __future__ import annotations

from collections.abc import Sequence

#: the four flanges, named by ring and side along the ring's axis, in the order of every
#: per-flange array (inner -X, inner +X, outer -X, outer +X)
FLANGES: tuple[str, ...] = ("inner-X", "inner+X", "outer-X", "outer+X")

#: flange presence (1.0 there, 0.0 absent) of each bearing type, in the order of `FLANGES`
BEARING_TYPES: dict[str, tuple[float, ...]] = {
    "NUP": (1.0, 1.0, 1.0, 1.0),
    "NU": (0.0, 0.0, 1.0, 1.0),
    "N": (1.0, 1.0, 0.0, 0.0),
    "NJ": (1.0, 0.0, 1.0, 1.0),
}


def flange_presence(arrangement: str | Sequence[str]) -> tuple[float, ...]:
    """The presence of the four flanges (order `FLANGES`) of a bearing type ("NU") or of a set
    of flange names (["outer-X", "outer+X"]). Raises KeyError for an unknown name."""
    if isinstance(arrangement, str):
        return BEARING_TYPES[arrangement]
    unknown = [n for n in arrangement if n not in FLANGES]
    if unknown:
        raise KeyError(unknown[0])
    return tuple(1.0 if n in arrangement else 0.0 for n in FLANGES)


def arrangement_of(presence: Sequence[float]) -> str | tuple[str, ...]:
    """The bearing type whose flanges are `presence` (1.0 / 0.0 per flange, order `FLANGES`),
    or, where no type has them, the tuple of the flanges that are there."""
    present = tuple(1.0 if float(p) == 1.0 else 0.0 for p in presence)
    for name, flags in BEARING_TYPES.items():
        if flags == present:
            return name
    return tuple(n for n, p in zip(FLANGES, present) if p == 1.0)


def locates_rollers(presence: Sequence[float]) -> bool:
    """True when a flange is there on each side (-X and +X, either ring): the rollers are
    then located axially. With no flange on one side nothing stops them leaving the raceway."""
    p = [float(x) == 1.0 for x in presence]
    return (p[0] or p[2]) and (p[1] or p[3])


def carries_axial_load(presence: Sequence[float], sign: float) -> bool:
    """True when the flanges carry an axial load on the inner ring of sign `sign` (> 0: along
    +X) to the outer ring: along +X the inner -X flange pushes the rollers, the outer +X flange
    holds them; along -X the inner +X and the outer -X flanges. `sign` 0 needs nothing."""
    p = [float(x) == 1.0 for x in presence]
    if sign > 0:
        return p[0] and p[3]
    if sign < 0:
        return p[1] and p[2]
    return True
