"""Sweep spec TOML -> validated `SweepSpec`: base configuration, axes, zip groups, every case checked."""

from __future__ import annotations

import difflib
import math
import numbers
import os
import pathlib
import tomllib
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .._errors import ConfigError
from ..io import KEY_BY_PATH, KEYS, Config, format_value, load_config, type_name
from ._spec import (
    _RANGE_FIELDS,
    _STATIC_KEYS,
    _SWEEP_FIELDS,
    MAX_CASES,
    SETTLED_DEFAULTS,
    Axis,
    SweepSpec,
    SweepSpecError,
    _positive_int,
)


def _wrong_unit(path: str) -> str | None:
    """'roller.end_radius_m' -> a message pointing at roller.end_radius_mm (engineering units)."""
    section, _, name = path.rpartition(".")
    for key in KEYS:
        if key.section != section or not key.unit or key.name == name:
            continue
        stem = key.name[: len(key.name) - len(key.path.rpartition("_")[2]) - 1]
        if "_" in key.name and name.startswith(stem + "_"):
            return (
                f"wrong unit suffix: configuration keys are in engineering units with the "
                f"unit in the name; use {key.path} [{key.unit}]"
            )
    return None


def _axis_values(key: str, raw) -> tuple:
    """The values of one axis: a list, or a range table {start, stop, num} (inclusive)."""
    if isinstance(raw, Mapping):
        unknown = [k for k in raw if k not in _RANGE_FIELDS]
        if unknown:
            raise SweepSpecError(
                key,
                f"unknown range field {unknown[0]!r}; a range is "
                "{ start = ..., stop = ..., num = ... } (stop included)",
            )
        missing = [k for k in _RANGE_FIELDS if k not in raw]
        if missing:
            raise SweepSpecError(
                key,
                f"range is missing {missing[0]!r}; a range is "
                "{ start = ..., stop = ..., num = ... } (stop included)",
            )
        num = raw["num"]
        if isinstance(num, bool) or not isinstance(num, numbers.Integral):
            raise SweepSpecError(key, f"range num must be an integer, got {type_name(num)}")
        if num < 1:
            raise SweepSpecError(key, f"empty axis: range num = {num} (must be >= 1)")
        if num > MAX_CASES:
            raise SweepSpecError(key, f"range num = {num}: at most {MAX_CASES} values (split the sweep)")
        for f in ("start", "stop"):
            v = raw[f]
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
                raise SweepSpecError(
                    key, f"range {f} must be a finite number, got {type_name(v)} {format_value(v)}"
                )
        return tuple(float(v) for v in np.linspace(raw["start"], raw["stop"], num))
    if isinstance(raw, (list, tuple)):
        if not raw:
            raise SweepSpecError(key, "empty axis: give at least one value")
        return tuple(raw)
    raise SweepSpecError(
        key,
        f"expected a list of values or a range table "
        f"{{start, stop, num}}, got {type_name(raw)} {format_value(raw)}",
    )


def _check_axis_key(key: str) -> None:
    if key == "end":
        return
    if key in _STATIC_KEYS:
        raise SweepSpecError(key, f"cannot be swept: {_STATIC_KEYS[key]}")
    if key not in KEY_BY_PATH:
        wrong = _wrong_unit(key)
        if wrong:
            raise SweepSpecError(key, wrong)
        try:
            Config().replace(**{key: 0})
        except ConfigError as exc:
            msg = str(exc).partition(": ")[2]
            if key == exc.field and "did you mean" not in msg and "end" in key:
                msg += '; the roller end type is the special axis "end"'
            raise SweepSpecError(key, msg) from None
        raise SweepSpecError(key, "unknown key")  # pragma: no cover


def _coordinate_names(keys: Sequence[str]) -> dict[str, str]:
    """Dataset names of the axes: the key's last part when unique, else the full path with
    '.' -> '_' ('speed_rpm', 'materials_ring_density_kg_m3')."""
    short = [k.rpartition(".")[2] for k in keys]
    return {k: (s if short.count(s) == 1 else k.replace(".", "_")) for k, s in zip(keys, short)}


def build_spec(data: Mapping[str, Any], base_dir: str | os.PathLike | None = None) -> SweepSpec:
    """A validated `SweepSpec` from the parsed TOML of a spec (see `jaxbearing.sweep._spec`).

    Every case is validated through `Config.replace`; errors name the axis."""
    unknown = [k for k in data if k not in ("sweep", "base", "axes")]
    if unknown:
        raise SweepSpecError(unknown[0], "unknown table; a sweep spec has [sweep], [base] and [axes]")
    sweep = _sweep_table(data.get("sweep", {}))
    base = _base_config(sweep, data.get("base", {}), base_dir)
    values = _axis_values_by_key(data.get("axes", {}))
    if "end" not in values and base.simulation.end == "both":
        values["end"] = ("arc", "corner")
    axes, dims, shape = _dimensions(sweep, values)
    total = math.prod(shape)
    if total > MAX_CASES:
        raise SweepSpecError(
            "axes", f"{total} cases ({' x '.join(map(str, shape))}): at most {MAX_CASES} per sweep; split it"
        )
    spec = SweepSpec(
        base=base,
        axes=axes,
        dims=dims,
        shape=shape,
        batch_size=_positive_int("sweep.batch_size", sweep.get("batch_size", 8), MAX_CASES),
        num_saves=_positive_int("sweep.num_saves", sweep.get("num_saves", 400)),
        max_positions=_positive_int("sweep.max_positions", sweep.get("max_positions", 500)),
        **_settled_fields(sweep),
    )
    validate_cases(spec)
    return spec


def _settled_fields(sweep: Mapping[str, Any]) -> dict[str, Any]:
    """The settled-running fields of [sweep] (`SETTLED_DEFAULTS`), checked as `jaxbearing
    simulate` checks its options: a bad value is one line naming the key."""
    from ..run import steady_settings

    got = {k: sweep.get(k, v) for k, v in SETTLED_DEFAULTS.items()}
    for key, value in got.items():
        kinds = {"settle": (str, numbers.Real), "start": (str,)}.get(key, (numbers.Real,))
        if isinstance(value, bool) or not isinstance(value, kinds):
            raise SweepSpecError(f"sweep.{key}", f"{format_value(value)} is not a valid value")
    settle = got["settle"]
    if isinstance(settle, str) and settle not in ("auto", "off"):
        raise SweepSpecError(
            "sweep.settle", f'{format_value(settle)} must be "auto", "off" or a settling time >= 0 ms'
        )
    names = {
        k: f"sweep.{k}"
        for k in ("settle", "seeds", "window_revs", "settle_tolerance", "settle_cap_ms", "start")
    }
    steady_settings(
        names,
        settle=settle,
        window_revs=got["window_revs"],
        seeds=got["seeds"],
        tolerance=got["settle_tolerance"],
        settle_cap_ms=got["settle_cap_ms"],
        start=got["start"],
    )
    return {
        "settle": settle if isinstance(settle, str) else float(settle),
        "seeds": int(got["seeds"]),
        "window_revs": int(got["window_revs"]),
        "settle_tolerance": float(got["settle_tolerance"]),
        "settle_cap_ms": float(got["settle_cap_ms"]),
        "start": got["start"],
    }


def _sweep_table(sweep) -> Mapping[str, Any]:
    """The [sweep] table, its field names checked ("did you mean")."""
    if not isinstance(sweep, Mapping):
        raise SweepSpecError("sweep", f"expected a table, got {type_name(sweep)}")
    for k in sweep:
        if k not in _SWEEP_FIELDS:
            near = difflib.get_close_matches(k, _SWEEP_FIELDS, n=1)
            hint = f"did you mean sweep.{near[0]}?" if near else "valid: " + ", ".join(_SWEEP_FIELDS)
            raise SweepSpecError(f"sweep.{k}", f"unknown field; {hint}")
    return sweep


def _base_config(sweep: Mapping[str, Any], inline, base_dir) -> Config:
    """The base configuration: `sweep.base` (a file relative to the spec, or "reference"), with
    the inline [base.*] tables merged over it."""
    base_ref = sweep.get("base", "reference")
    if not isinstance(base_ref, str):
        raise SweepSpecError(
            "sweep.base", f'expected a config file path or "reference", got {type_name(base_ref)}'
        )
    if base_ref == "reference":
        base = Config()
    else:
        path = pathlib.Path(base_ref)
        if not path.is_absolute() and base_dir is not None:
            path = pathlib.Path(base_dir) / path
        try:
            base = load_config(path)
        except ConfigError as exc:
            raise SweepSpecError("sweep.base", f"{path}: {exc}") from None
    if not inline:
        return base
    if not isinstance(inline, Mapping):
        raise SweepSpecError("base", f"expected a table, got {type_name(inline)}")
    merged = base.to_dict()
    for section, table in inline.items():
        if isinstance(table, Mapping) and isinstance(merged.get(section), dict):
            for name, value in table.items():
                if isinstance(value, Mapping) and isinstance(merged[section].get(name), dict):
                    merged[section][name].update(value)
                else:
                    merged[section][name] = value
        else:
            merged[section] = table
    try:
        return Config(merged)
    except ConfigError as exc:
        raise SweepSpecError(f"base.{exc.field}", str(exc).partition(": ")[2]) from None


def _flat_axes(axes_raw) -> dict[str, Any]:
    """{dotted key: raw values}: TOML dotted keys without quotes arrive nested
    ({"operating": {"speed_rpm": [...]}})."""
    if not isinstance(axes_raw, Mapping):
        raise SweepSpecError("axes", f"expected a table of axes, got {type_name(axes_raw)}")
    flat: dict[str, Any] = {}

    def walk(node, prefix):
        for k, v in node.items():
            path = prefix + k
            if isinstance(v, Mapping) and not (set(v) & set(_RANGE_FIELDS)) and path != "end":
                walk(v, path + ".")
            else:
                flat[path] = v

    walk(axes_raw, "")
    if not flat:
        raise SweepSpecError(
            "axes", 'no axes: give at least one, e.g. "operating.speed_rpm" = [10000, 20000]'
        )
    return flat


def _axis_values_by_key(axes_raw) -> dict[str, tuple]:
    """{axis key: values}, each axis key and value checked (engineering units, no duplicates)."""
    values: dict[str, tuple] = {}
    for key, raw in _flat_axes(axes_raw).items():
        _check_axis_key(key)
        vals = _axis_values(key, raw)
        if key == "end":
            bad = [v for v in vals if v not in ("arc", "corner")]
            if bad:
                raise SweepSpecError(
                    "end", f'{format_value(bad[0])} is not a roller end type; values are "arc" and "corner"'
                )
        else:
            cfg_key = KEY_BY_PATH[key]
            for v in vals:
                if isinstance(v, str):
                    raise SweepSpecError(
                        key,
                        f"expected numbers [{cfg_key.unit}], got string "
                        f"{format_value(v)}; units are part of the key name",
                    )
            vals = tuple(
                cfg_key.kind(v) if cfg_key.kind is float and not isinstance(v, bool) else v for v in vals
            )
        if len(set(vals)) != len(vals):
            dup = next(v for v in vals if vals.count(v) > 1)
            raise SweepSpecError(key, f"value {format_value(dup)} appears twice")
        values[key] = vals
    return values


def _zip_groups(sweep: Mapping[str, Any], values: Mapping[str, tuple], mode: str) -> dict[str, int]:
    """{axis key: zip group} from `sweep.mode` / `sweep.zip`; zipped axes have equal lengths."""
    groups_raw = sweep.get("zip", [])
    if mode == "zip":
        if groups_raw:
            raise SweepSpecError(
                "sweep.zip", 'give either mode = "zip" (all axes zipped) or zip groups, not both'
            )
        groups = [list(values)]
    else:
        if not isinstance(groups_raw, list) or not all(isinstance(g, list) for g in groups_raw):
            raise SweepSpecError("sweep.zip", "expected a list of lists of axis keys")
        groups = [list(g) for g in groups_raw]
    grouped: dict[str, int] = {}
    for gi, group in enumerate(groups):
        for key in group:
            if key not in values:
                raise SweepSpecError("sweep.zip", f"{key!r} is not an axis (axes: {', '.join(values)})")
            if key in grouped:
                raise SweepSpecError("sweep.zip", f"{key!r} is in two zip groups")
            grouped[key] = gi
        lengths = {key: len(values[key]) for key in group}
        if len(set(lengths.values())) > 1:
            first = group[0]
            other = next(k for k in group if lengths[k] != lengths[first])
            raise SweepSpecError(
                other,
                f"zipped axes must have equal lengths: {other} has "
                f"{lengths[other]} values, {first} has {lengths[first]}",
            )
    return grouped


def _dimensions(sweep: Mapping[str, Any], values: Mapping[str, tuple]):
    """(axes, dims, shape): every axis its own dimension, unless zipped."""
    mode = sweep.get("mode", "grid")
    if mode not in ("grid", "zip"):
        raise SweepSpecError("sweep.mode", f'{format_value(mode)} is not "grid" or "zip"')
    grouped = _zip_groups(sweep, values, mode)
    names = _coordinate_names(list(values))
    dims: list[str] = []
    shape: list[int] = []
    axes: list[Axis] = []
    group_dims: dict[int, str] = {}
    for key, vals in values.items():
        if key in grouped:
            gi = grouped[key]
            if gi not in group_dims:
                group_dims[gi] = "case" if mode == "zip" else f"zip{gi}"
                dims.append(group_dims[gi])
                shape.append(len(vals))
            dim = group_dims[gi]
        else:
            dim = names[key]
            dims.append(dim)
            shape.append(len(vals))
        axes.append(Axis(key, names[key], vals, dim))
    return tuple(axes), tuple(dims), tuple(shape)


def validate_cases(spec: SweepSpec) -> None:
    """Build and validate every case (no JAX); the first bad case raises SweepSpecError naming
    the axis that made it invalid (the first axis whose value alone fails, else every axis)."""
    for case in range(spec.num_cases):
        values = spec.case_values(case)
        end = values.pop("end", spec.base.simulation.end)
        try:
            cfg = spec.base.replace(**values) if values else spec.base
        except ConfigError as exc:
            axis = exc.field if exc.field in values else None
            if axis is None:  # a dependent check: find the axis whose value alone breaks it
                for k, v in values.items():
                    try:
                        spec.base.replace(**{k: v})
                    except ConfigError:
                        axis = k
                        break
            shown = ", ".join(f"{k} = {format_value(v)}" for k, v in values.items())
            raise SweepSpecError(
                axis or " + ".join(values), f"case {case} ({shown}) is invalid: {exc}"
            ) from None
        if end == "arc" and not math.isfinite(cfg["roller.end_radius_mm"]):
            axis = "roller.end_radius_mm" if "roller.end_radius_mm" in values else "end"
            raise SweepSpecError(
                axis,
                f'case {case}: end = "arc" needs a finite '
                'roller.end_radius_mm (inf is the flat end); use end = "corner"',
            )


def loads_sweep_spec(text: str, base_dir: str | os.PathLike | None = None) -> SweepSpec:
    """Parse and validate the TOML text of a sweep spec."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SweepSpecError("spec", f"TOML syntax error: {exc}") from None
    return build_spec(data, base_dir)


def load_sweep_spec(path: str | os.PathLike) -> SweepSpec:
    """Read and validate a sweep spec file; a base config path in it is relative to the file."""
    path = pathlib.Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SweepSpecError("spec", f"cannot read {path}: {exc}") from None
    return loads_sweep_spec(text, base_dir=path.parent)
