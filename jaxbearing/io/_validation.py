"""Checking configuration values against the schema (`_schema.KEYS`): type coercion, ranges in
dependency order, and `validate_bearing` for pytrees built directly in Python. The first
violation raises `jaxbearing.ConfigError(field, message)` with a one-line text naming the key,
the value with its unit and the valid range."""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from .._errors import ConfigError
from ._keys import Key, format_value, type_name
from ._schema import CHECK_ORDER, KEY_BY_PATH, KEYS, REFERENCE_VALUES


# -- types -------------------------------------------------------------------------------------
def coerce(key: Key, value: Any) -> Any:
    """The value as the key's Python type (int -> float for float keys), or ConfigError.

    Booleans are never numbers and floats are never counts, even when integral (26.0).
    """
    if hasattr(value, "__array__") and not isinstance(value, (numbers.Number, str)):
        arr = np.asarray(value)
        if arr.ndim == 0 and arr.dtype.kind in "biuf":
            value = arr.item()
    unit = f" ({key.unit})" if key.unit else ""
    got = (
        f"got {type_name(value)} {format_value(value)}"
        if isinstance(value, (numbers.Number, str, np.bool_))
        else f"got {type_name(value)}"
    )
    is_bool = isinstance(value, (bool, np.bool_))
    if key.kind is float:
        if is_bool or not isinstance(value, numbers.Real):
            raise ConfigError(key.path, f"expected a number{unit}, {got}")
        try:
            return float(value)
        except OverflowError:
            raise ConfigError(
                key.path,
                f"{type_name(value)} too large for a float{unit}; must be "
                f"{key.range_text()}{(' ' + key.unit) if key.unit else ''}",
            ) from None
    if key.kind is int:
        if is_bool or not isinstance(value, numbers.Real):
            raise ConfigError(key.path, f"expected an integer, {got}")
        if not isinstance(value, numbers.Integral):
            raise ConfigError(
                key.path, f"expected an integer (a count, written without a decimal point), {got}"
            )
        return int(value)
    if key.kind is bool:
        if not is_bool:
            raise ConfigError(key.path, f"expected true or false, {got}")
        return bool(value)
    if key.members and isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value):
        return tuple(value)  # a set of members (the flanges of `bearing.type`), hashable
    if not isinstance(value, str):
        what = "a string or a list of strings" if key.members else "a string"
        raise ConfigError(key.path, f"expected {what} ({key.range_text()}), {got}")
    return value


# -- ranges ------------------------------------------------------------------------------------
def check_key(key: Key, values: Mapping[str, Any]) -> None:
    """Range and extra checks of one key; `values` holds it and the keys it depends on."""
    v = values[key.path]
    unit = f" {key.unit}" if key.unit else ""
    if key.members and isinstance(v, tuple):
        _check_members(key, v)
    elif key.choices:
        if v not in key.choices:
            raise ConfigError(key.path, f"{format_value(v)} is not {key.range_text()}")
    elif key.kind in (float, int):
        if key.kind is float and not math.isfinite(v) and not (key.allow_inf and v == math.inf):
            raise ConfigError(
                key.path, f"{format_value(v)}{unit} is not finite: must be {key.range_text(values)}{unit}"
            )
        ok = True
        if key.lo is not None:
            lo = key.lo.value(values)
            ok &= v >= lo if key.lo.closed else v > lo
        if key.hi is not None:
            hi = key.hi.value(values)
            ok &= v <= hi if key.hi.closed else v < hi
        if not ok:
            culprit = _culprit(key, values)
            if culprit is not None:
                dep = KEY_BY_PATH[culprit]
                dep_unit = f" {dep.unit}" if dep.unit else ""
                raise ConfigError(
                    culprit,
                    f"{format_value(values[culprit])}{dep_unit} puts {key.path} = {format_value(v)}{unit} "
                    f"(its reference value) out of range: {key.name} must be {key.range_text(values)}{unit}; "
                    f"check {dep.name}'s value and unit",
                )
            raise ConfigError(
                key.path, f"{format_value(v)}{unit} is out of range: must be {key.range_text(values)}{unit}"
            )
    for extra in key.extras:
        msg = extra.check(values)
        if msg is not None:
            raise ConfigError(key.path, msg)


def _check_members(key: Key, v: tuple) -> None:
    """A list value of a key with `members`: every name a member, none twice."""
    unknown = [m for m in v if m not in key.members]
    if unknown:
        raise ConfigError(
            key.path,
            f"{format_value(v)}: {format_value(unknown[0])} is not one of the names "
            + ", ".join(format_value(m) for m in key.members),
        )
    twice = [m for m in v if v.count(m) > 1]
    if twice:
        raise ConfigError(
            key.path, f"{format_value(v)} names {format_value(twice[0])} twice: must be {key.range_text()}"
        )


def _culprit(key: Key, values: Mapping[str, Any]) -> str | None:
    """The key to blame when `key` fails a range that depends on other keys: when `key` still
    has its reference value and a key its range reads does not, that key is the wrong one (e.g.
    `bearing.pitch_diameter_mm = 0.085`, metres typed as mm, makes the reference radial
    clearance too large); None otherwise."""
    if values[key.path] != REFERENCE_VALUES.get(key.path):
        return None
    changed = [d for d in key.deps if d != key.path and values.get(d) != REFERENCE_VALUES.get(d)]
    return changed[0] if changed else None


def check_values(values: Mapping[str, Any], paths: Iterable[str] | None = None) -> None:
    """Check the keys `paths` (all by default) of a complete, typed value mapping, in
    dependency order; raise ConfigError on the first violation."""
    wanted = set(CHECK_ORDER if paths is None else paths)
    for path in CHECK_ORDER:
        if path in wanted:
            check_key(KEY_BY_PATH[path], values)


# -- pytrees built in Python -------------------------------------------------------------------
def _leaf(bearing, op, attr: str):
    obj = op if attr.startswith("op.") else bearing
    for part in attr.removeprefix("op.").split("."):
        obj = getattr(obj, part)
    return obj


def _traced(x) -> bool:
    import jax

    return any(isinstance(v, jax.core.Tracer) for v in jax.tree_util.tree_leaves(x))


def validate_bearing(bearing, op=None, *, traced: str = "error") -> None:
    """Validate a `Bearing` (and optionally an `OperatingPoint`) built directly in Python.

    Values are converted to configuration units so that a failure reads like a configuration
    error, naming the configuration key (e.g. ``roller.end_radius_mm: 3.0 mm is out of range:
    must be in (diameter_mm/2 = 3.75, inf] mm``). Stacked (batched) pytrees are checked element
    by element. Gravity, a bool in configuration files, must here be finite and in [0, 100]
    m/s^2; the switches (`axial_freedom`, `tilt_freedom`, booleans in configuration files) must
    be 1.0 (true) or 0.0 (false), and so must each flange's presence (`flange_presence`, the
    flanges of `bearing.type`).

    Leaves must be concrete: under `jax.jit`/`grad`/`vmap` they are tracers, which raise
    TypeError (`traced="error"`, the default) or, with `traced="skip"` (what the model's entry
    points use), leave out every check that reads a traced leaf and check the rest.

    Raises ConfigError on the first violation; returns None.
    """
    if traced not in ("error", "skip"):
        raise ValueError(f"traced = {traced!r}: must be 'error' or 'skip'")
    keys = [k for k in KEYS if k.attr is not None and (op is not None or not k.attr.startswith("op."))]
    leaves = {k.path: _leaf(bearing, op, k.attr) for k in keys}
    # a general-face field left None is today's face: the key's reference value
    leaves = {p: KEY_BY_PATH[p].to_si(KEY_BY_PATH[p].default) if v is None else v for p, v in leaves.items()}
    skipped = {p for p, v in leaves.items() if _traced(v)}
    if skipped and traced == "error":
        raise TypeError("validate_bearing needs concrete values: call it outside jax.jit/grad/vmap")
    # a key is checked when neither it nor a key its range reads is traced
    keys = [k for k in keys if k.path not in skipped]
    checked = [k.path for k in keys if not set(k.deps) & skipped]
    # counts and choices (static pytree fields) are one Python value for the whole batch
    arrays = {k.path: np.asarray(leaves[k.path]) for k in keys if k.kind not in (int, str)}
    # converted string keys (the flange presence of `bearing.type`) have one trailing axis of
    # their own; a converted float key (`flange.rib_radius_mm`) is a scalar like the others
    vectors = {
        k.path: np.asarray(leaves[k.path], dtype=float)
        for k in keys
        if k.convert is not None and k.kind is str
    }
    shape = np.broadcast_shapes(
        *(a.shape for a in arrays.values()), *(a.shape[:-1] for a in vectors.values())
    )
    vectors = {p: np.broadcast_to(a, shape + a.shape[-1:]) for p, a in vectors.items()}
    if op is not None and not _traced(op.gravity):
        _check_gravity(np.broadcast_to(np.asarray(op.gravity, dtype=float), shape), shape)
    for k in keys:  # switches (inner-ring freedoms): 1.0 (true) or 0.0 (false)
        if k.kind is bool and k.path != "operating.gravity":
            _check_switch(k.path, np.broadcast_to(arrays[k.path].astype(float), shape), shape)
    for path, a in vectors.items():  # flange presence: 1.0 (there) or 0.0 (absent)
        _check_presence(path, a, shape)
    for idx in np.ndindex(shape):
        values = dict(REFERENCE_VALUES)
        for k in keys:
            if k.path in vectors:
                values[k.path] = k.from_si(vectors[k.path][idx])
            elif k.kind in (int, str):
                values[k.path] = coerce(k, leaves[k.path])
            elif k.kind is bool:  # gravity
                values[k.path] = bool(np.broadcast_to(arrays[k.path], shape)[idx] > 0)
            else:
                values[k.path] = k.from_si(float(np.broadcast_to(arrays[k.path], shape)[idx]))
        try:
            check_values(values, checked)
        except ConfigError as exc:
            if not shape:
                raise
            msg = str(exc).removeprefix(f"{exc.field}: ")
            raise ConfigError(exc.field, f"(batch element {idx}) {msg}") from None


def _check_gravity(g: np.ndarray, shape: tuple) -> None:
    bad = ~(np.isfinite(g) & (g >= 0) & (g <= 100))
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f"(batch element {idx}) " if shape else ""
        raise ConfigError(
            "operating.gravity",
            f"{where}{format_value(float(g[idx]))} m/s^2 is "
            "out of range: must be in [0, 100] m/s^2 (9.81 = on, 0 = off)",
        )


def _check_switch(path: str, v: np.ndarray, shape: tuple) -> None:
    bad = ~((v == 0.0) | (v == 1.0))
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f"(batch element {idx}) " if shape else ""
        raise ConfigError(
            path, f"{where}{format_value(float(v[idx]))} is out of range: must be 1.0 (true) or 0.0 (false)"
        )


def _check_presence(path: str, v: np.ndarray, shape: tuple) -> None:
    """Each flange's presence (`Bearing.flange_presence`, last axis in the order `FLANGES`,
    after the batch `shape`) is 1.0 (there) or 0.0 (absent)."""
    from ..geometry import FLANGES

    bad = ~((v == 0.0) | (v == 1.0))
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f"(batch element {idx[:-1]}) " if shape else ""
        raise ConfigError(
            path,
            f"{where}presence of flange {FLANGES[idx[-1]]} = {format_value(float(v[idx]))} is out of "
            "range: must be 1.0 (there) or 0.0 (absent)",
        )


# -- plausibility --------------------------------------------------------------------------------
#: (key, limit, what the value probably is): a value in (0, limit) is valid but almost certainly
#: a unit slip; `plausibility_warnings` names it (0 itself is a deliberate choice and passes)
IMPLAUSIBLY_SMALL: tuple[tuple[str, float, str], ...] = (
    ("bearing.pitch_diameter_mm", 1.0, "below 1 mm: a pitch diameter in metres?"),
    ("bearing.radial_clearance_um", 0.1, "below 0.1 um: a clearance in mm?"),
    ("roller.diameter_mm", 0.5, "below 0.5 mm: a diameter in metres?"),
    ("roller.length_mm", 0.5, "below 0.5 mm: a length in metres?"),
    ("roller.crown_drop_um", 0.1, "below 0.1 um: a crown drop in mm?"),
    ("flange.height_mm", 0.1, "below 0.1 mm: a height in metres?"),
    ("flange.layback_angle_deg", 0.1, "below 0.1 deg: an angle in radians?"),
    ("flange.axial_clearance_mm", 1e-4, "below 0.1 um: a clearance in metres?"),
    ("cage.pocket_clearance_mm", 1e-3, "below 1 um: a clearance in metres?"),
    ("cage.guiding_clearance_mm", 1e-3, "below 1 um: a clearance in metres?"),
    ("operating.speed_rpm", 1.0, "below 1 rpm: a speed in revolutions per second?"),
)


def plausibility_warnings(values) -> list[str]:
    """One line per value of a valid configuration (a `Config` or a {dotted key: value}
    mapping) that is almost certainly a unit slip (`IMPLAUSIBLY_SMALL`), naming the key, the
    value with its unit and why."""
    out = []
    for path, limit, why in IMPLAUSIBLY_SMALL:
        v = values[path]
        if isinstance(v, (int, float)) and 0 < v < limit:
            unit = KEY_BY_PATH[path].unit
            out.append(f"{path} = {format_value(v)} {unit} is valid but implausible: {why}")
    return out
