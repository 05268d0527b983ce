"""TOML configuration files in engineering units.

A configuration file has one table per part of the bearing, with the unit in every key's name
(`_mm`, `_um`, `_deg`, `_rpm`, `_GPa`, `_N`, ...); `jaxbearing config show` prints every key with
its meaning, symbol and valid range. The schema and the ranges are `jaxbearing.io.KEYS` (`_schema.py`).

    [bearing]            pitch_diameter_mm, radial_clearance_um, num_rollers, num_slices, ...
    [roller]             diameter_mm, length_mm, ..., end_radius_mm (inf = flat end)
    [flange]             height_mm, relief_height_mm, contact_height_limit_mm, ...
    [cage]               inner_diameter_mm, outer_diameter_mm, width_mm, ...
    [materials.ring]     elastic_modulus_GPa, poisson_ratio, density_kg_m3, thermal_conductivity_W_mK,
                         specific_heat_J_kgK
    [materials.roller]   (same)
    [materials.cage]     (same)
    [lubricant]          viscosity_Pa_s, ..., traction_a, traction_b_s_m, traction_c_s_m, traction_d
    [operating]          speed_rpm, radial_load_N, gravity, misalignment_mrad, axial_load_N,
                         inner_ring_axial_freedom, inner_ring_tilt_freedom
    [simulation]         end, duration_ms, rtol, atol, max_steps, progress, solver
    [uncertainty]        optional: "dotted.key" = { plus_minus = ..., estimated = "rule" }
                         for values known only roughly (`_uncertainty.py`)

Missing keys take the reference value (docs/model.md section 1); unknown keys and sections are
errors with a "did you mean ...?" suggestion; wrong types and out-of-range values are errors
naming the key, the value with its unit and the valid range (`jaxbearing.ConfigError`).

A `Config` keeps the values exactly as given, in engineering units: that is the source of truth,
so a file round-trips exactly through `Config.to_toml()`. Conversion to SI happens only in
`Config.bearing()` and `Config.operating_point()`; the reference configuration converts to
`reference_bearing()` and `reference_operating_point()` bit for bit.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import os
import re
import tomllib
import types
from collections.abc import Mapping
from typing import Any

import tomli_w

from .._errors import ConfigError
from ..geometry import Bearing, Cage, Flange, Lubricant, Material, OperatingPoint, Roller
from ._keys import GRAVITY, Key, format_value, type_name
from ._schema import KEY_BY_PATH, KEYS, REFERENCE_VALUES
from ._uncertainty import SECTION as _UNCERTAINTY
from ._uncertainty import Uncertainty, parse_uncertainty, uncertainty_toml
from ._validation import check_values, coerce

_HEADER = """\
# jaxbearing configuration. Engineering units: the unit is part of every key's name.
# Keys left out take the reference value: a representative aero-engine mainshaft cylindrical
# roller bearing (docs/model.md section 1), not the source paper's Table 1.
"""


def _tree() -> dict[str, Any]:
    """Nested {section: {subsection: {name: Key}}} of the schema, in schema order."""
    tree: dict[str, Any] = {}
    for key in KEYS:
        node = tree
        for part in key.section.split("."):
            node = node.setdefault(part, {})
        node[key.name] = key
    return tree


_TREE = _tree()
_SECTIONS = tuple(dict.fromkeys(k.section for k in KEYS))


@dataclasses.dataclass(frozen=True)
class SimulationSettings:
    """The [simulation] table: which roller ends to run and how to integrate.

    `end`: "arc", "corner" or "both"; `duration_ms`: simulated time; `rtol`, `atol`: PID
    step-size controller tolerances (on the scaled state); `max_steps`: integrator step limit;
    `progress`: show a progress meter; `solver`: "tsit5" or "ros34pw2" (`run.simulate`).
    """

    end: str
    duration_ms: float
    rtol: float
    atol: float
    max_steps: int
    progress: bool
    solver: str = "tsit5"

    @property
    def duration(self) -> float:
        """Simulated time [s]."""
        return self.duration_ms * 1e-3

    @property
    def ends(self) -> tuple[str, ...]:
        """The roller-end variants to simulate: ("arc",), ("corner",) or ("arc", "corner")."""
        return ("arc", "corner") if self.end == "both" else (self.end,)


# -- unknown keys --------------------------------------------------------------------------------
def _unknown(path: str, name: str, node: Mapping[str, Any], prefix: str, section: bool) -> ConfigError:
    """Error for an unknown key or section `path`, with a "did you mean ...?" suggestion."""
    is_table = {n: isinstance(c, dict) for n, c in node.items()}

    def show(n: str) -> str:
        full = prefix + n
        return f"[{full}]" if is_table[n] else full

    what = "unknown section" if section else "unknown key"
    homes: dict[str, list[str]] = {}  # key name -> dotted paths with that name
    for key in KEYS:
        homes.setdefault(key.name, []).append(key.path)

    def elsewhere(n: str) -> ConfigError:
        paths = homes[n]
        # "density_kg_m3" in [cage] -> materials.cage.density_kg_m3
        near = [p for p in paths if set(prefix.split(".")[:-1]) & set(p.split(".")[:-1])]
        shown = " or ".join(f"{p} (in [{KEY_BY_PATH[p].section}])" for p in (near or paths))
        return ConfigError(path, f"{what}; did you mean {shown}?")

    if name in homes:  # the right key in the wrong section ("pitch_diameter_mm" in [roller])
        return elsewhere(name)
    match = difflib.get_close_matches(name, list(node), n=1, cutoff=0.6)
    if match:
        return ConfigError(path, f"{what}; did you mean {show(match[0])}?")
    match = difflib.get_close_matches(name, list(homes), n=1, cutoff=0.75)
    if match:
        return elsewhere(match[0])
    where = f" in [{prefix[:-1]}]" if prefix else ""
    return ConfigError(path, f"{what}; valid{where}: " + ", ".join(show(n) for n in node))


def _unknown_path(path: str) -> ConfigError:
    """Error for a dotted path that names no key: unknown at its first unknown part."""
    node: Mapping[str, Any] = _TREE
    prefix = ""
    parts = path.split(".")
    for i, part in enumerate(parts):
        child = node.get(part)
        if isinstance(child, dict) and i < len(parts) - 1:
            node, prefix = child, prefix + part + "."
            continue
        if isinstance(child, dict):
            return ConfigError(path, "is a section, not a key")
        if child is not None:
            return ConfigError(path, f"{prefix}{part} is a key, not a section")
        return _unknown(path, parts[i], node, prefix, section=i < len(parts) - 1)
    raise AssertionError(path)  # pragma: no cover


def _flatten(data: Any, node: Mapping[str, Any], prefix: str, out: dict[str, Any]) -> None:
    for name, value in data.items():
        path = prefix + str(name)
        if not isinstance(name, str) or name not in node:
            raise _unknown(path, str(name), node, prefix, section=isinstance(value, Mapping))
        child = node[name]
        if isinstance(child, dict):
            if not isinstance(value, Mapping):
                raise ConfigError(path, f"expected a table [{path}], got {type_name(value)}")
            _flatten(value, child, path + ".", out)
        else:
            out[path] = coerce(child, value)


def _values_from(data: Mapping[str, Any] | None) -> dict[str, Any]:
    """Typed, merged (reference for missing keys) and validated flat values of nested `data`."""
    given: dict[str, Any] = {}
    if data is not None:
        if not isinstance(data, Mapping):
            raise ConfigError("config", f"expected a table of sections, got {type_name(data)}")
        _flatten(data, _TREE, "", given)
    values = {k.path: given.get(k.path, k.default) for k in KEYS}
    check_values(values)
    return values


# -- the container -------------------------------------------------------------------------------
class Config:
    """A validated configuration: engineering-unit values (the source of truth) and accessors.

    Build one with `load_config`, `loads_config`, `reference_config`, or `Config(nested_dict)`
    (the parsed TOML layout, e.g. ``{"roller": {"end_radius_mm": 90.0}}``; missing keys take the
    reference value). Immutable: `replace` returns a new, re-validated configuration.

    `cfg["roller.end_radius_mm"]` reads one value; `to_dict()`/`to_toml()` write all of them;
    `bearing()`, `operating_point()` and `simulation` give the model's inputs (SI pytrees).
    `uncertainty` is the optional `[uncertainty]` table: the keys whose values are estimated or
    known only roughly, each with its stated uncertainty (`Uncertainty`); it is data only and
    changes no model input.
    """

    __slots__ = ("_values", "_uncertainty")

    def __init__(self, data: Mapping[str, Any] | None = None):
        uncertainty: dict[str, Uncertainty] = {}
        if isinstance(data, Mapping) and _UNCERTAINTY in data:
            data = dict(data)
            uncertainty = parse_uncertainty(data.pop(_UNCERTAINTY), _unknown_path)
        object.__setattr__(self, "_values", types.MappingProxyType(_values_from(data)))
        object.__setattr__(self, "_uncertainty", types.MappingProxyType(uncertainty))

    def __setattr__(self, name, value):
        raise dataclasses.FrozenInstanceError(f"Config is immutable; use replace() (set {name!r})")

    def __reduce__(self):
        return (Config, (self.to_dict(),))

    # -- access ---------------------------------------------------------------------------------
    def __getitem__(self, path: str) -> Any:
        try:
            return self._values[path]
        except KeyError:
            raise KeyError(f"{path!r} is not a configuration key") from None

    def keys(self) -> tuple[str, ...]:
        """Dotted keys in schema order."""
        return tuple(self._values)

    @property
    def uncertainty(self) -> Mapping[str, Uncertainty]:
        """{dotted key: Uncertainty} of the `[uncertainty]` table, in schema order (empty when
        the file has none): each key's stated uncertainty and, if estimated, its rule."""
        return self._uncertainty

    def to_dict(self) -> dict[str, Any]:
        """Nested {section: {key: value}} (the TOML layout), every key, engineering units; the
        `[uncertainty]` table as {dotted key: {plus_minus, estimated}} when it is not empty."""
        out: dict[str, Any] = {}
        for path, value in self._values.items():
            node = out
            *sections, name = path.split(".")
            for s in sections:
                node = node.setdefault(s, {})
            node[name] = value
        if self._uncertainty:
            out[_UNCERTAINTY] = {p: u.to_dict() for p, u in self._uncertainty.items()}
        return out

    def changed(self) -> dict[str, Any]:
        """The keys whose values differ from the reference configuration."""
        return {p: v for p, v in self._values.items() if v != REFERENCE_VALUES[p]}

    def replace(self, changes: Mapping[str, Any] | None = None, /, **dotted: Any) -> Config:
        """A new configuration with dotted keys changed, re-validated, the `[uncertainty]` table
        kept: ``cfg.replace(**{"roller.end_radius_mm": 90})``."""
        updates = {**(changes or {}), **dotted}
        data = self.to_dict()
        for path, value in updates.items():
            if path not in KEY_BY_PATH:
                raise _unknown_path(path)
            node = data
            *sections, name = path.split(".")
            for s in sections:
                node = node[s]
            node[name] = value
        return Config(data)

    # -- model inputs ---------------------------------------------------------------------------
    def bearing(self) -> Bearing:
        """The `Bearing` pytree in SI units; with general faces only where the face keys differ
        from today's faces (`jaxbearing.io._schema` docstring)."""
        parts: dict[str, dict[str, Any]] = {}
        top: dict[str, Any] = {}
        for key in KEYS:
            if key.attr is None or key.attr.startswith("op."):
                continue
            value = self._values[key.path]
            value = value if key.kind is int else key.to_si(value)
            group, _, field = key.attr.rpartition(".")
            (parts.setdefault(group, {}) if group else top)[field] = value
        classes = {
            "roller": Roller,
            "flange": Flange,
            "cage": Cage,
            "lubricant": Lubricant,
            "ring_material": Material,
            "roller_material": Material,
            "cage_material": Material,
        }
        if parts["roller"]["end_offset"] == 0.0 and parts["flange"]["rib_curvature"] == 0.0:
            # today's faces: none of the general-face fields (today's contact code, schema doc)
            del parts["roller"]["end_offset"]
            del parts["flange"]["rib_curvature"], parts["flange"]["rib_tangent_height"]
        return Bearing(**top, **{g: classes[g](**kw) for g, kw in parts.items()})

    def operating_point(self) -> OperatingPoint:
        """The `OperatingPoint` pytree in SI units (gravity 9.81 m/s^2 or 0)."""
        v = self._values
        return OperatingPoint(
            inner_speed=KEY_BY_PATH["operating.speed_rpm"].to_si(v["operating.speed_rpm"]),
            radial_load=v["operating.radial_load_N"],
            gravity=GRAVITY if v["operating.gravity"] else 0.0,
            misalignment=KEY_BY_PATH["operating.misalignment_mrad"].to_si(v["operating.misalignment_mrad"]),
            axial_load=v["operating.axial_load_N"],
            axial_freedom=1.0 if v["operating.inner_ring_axial_freedom"] else 0.0,
            tilt_freedom=1.0 if v["operating.inner_ring_tilt_freedom"] else 0.0,
        )

    @property
    def simulation(self) -> SimulationSettings:
        """The [simulation] settings."""
        return SimulationSettings(
            **{f.name: self._values[f"simulation.{f.name}"] for f in dataclasses.fields(SimulationSettings)}
        )

    # -- writing --------------------------------------------------------------------------------
    def to_toml(
        self,
        *,
        comments: bool = True,
        header: str | None = None,
        notes: Mapping[str, str] | None = None,
    ) -> str:
        """Every key as TOML, in schema order, then the `[uncertainty]` table if any; with
        `comments`, a line per key giving its meaning, symbol, unit and valid range, a line
        "ESTIMATED (+/- ...): rule" or "UNCERTAIN (+/- ...)" above each key of the uncertainty
        table, and the line `notes[key]` where given. `header` replaces the opening comment.
        Loading the text gives an equal `Config`."""
        notes = notes or {}
        top = _HEADER if header is None else header
        lines = [top.rstrip("\n")] if comments and top else []
        for section in _SECTIONS:
            if lines:
                lines.append("")
            lines.append(f"[{section}]")
            for key in KEYS:
                if key.section != section:
                    continue
                if comments:
                    lines.append(f"# {key.doc()}")
                    if key.path in self._uncertainty:
                        lines.append(f"# {self._uncertainty[key.path].comment(key.unit)}")
                    if key.path in notes:
                        lines.append(f"# {notes[key.path]}")
                lines.append(_toml_line(key, self._values[key.path]))
        table = uncertainty_toml(self._uncertainty)
        if table:
            lines.append("")
            if comments:
                lines.append(
                    "# Values known only roughly: +/- plus_minus in the key's unit; estimated = the rule."
                )
            lines.extend(table)
        return "\n".join(lines) + "\n"

    # -- dunder ---------------------------------------------------------------------------------
    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Config):
            return NotImplemented
        return self._values == other._values and self._uncertainty == other._uncertainty

    def __hash__(self) -> int:
        return hash((tuple(self._values.items()), tuple(self._uncertainty.items())))

    def __repr__(self) -> str:
        changed = self.changed()
        if not changed:
            return "Config(reference)"
        body = ", ".join(f"{p}={format_value(v)}" for p, v in changed.items())
        return f"Config(reference with {body})"


def _toml_line(key: Key, value: Any) -> str:
    """`name = value` with the value written by tomli_w (floats as repr: exact round trip); a
    list of names (`bearing.type`'s flanges) on one line."""
    if isinstance(value, tuple):
        return f"{key.name} = [" + ", ".join(tomli_w.dumps({"v": v})[4:].rstrip("\n") for v in value) + "]"
    return tomli_w.dumps({key.name: value}).rstrip("\n")


# -- loading -------------------------------------------------------------------------------------
_TOML_POS = re.compile(r"^(?P<msg>.*) \(at line (?P<line>\d+), column (?P<col>\d+)\)$")


def loads_config(text: str) -> Config:
    """Parse TOML text into a validated `Config`.

    A syntax error raises ConfigError whose field is the position ("line 3, column 9"). A UTF-8
    byte-order mark at the start (some Windows editors write one) is ignored.
    """
    text = text.removeprefix("\ufeff")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = _TOML_POS.match(str(exc))
        if m:
            where, msg = f"line {m['line']}, column {m['col']}", m["msg"]
        else:
            where, _, msg = str(exc).partition(" (at ")
            where, msg = (msg.rstrip(")") if msg else "document"), where
        raise ConfigError(where, f"TOML syntax error: {msg[:1].lower()}{msg[1:]}") from None
    return Config(data)


def load_config(path: str | os.PathLike[str] | None = None) -> Config:
    """Read and validate a TOML configuration file; None gives the reference configuration.

    An unreadable file raises ConfigError with field "file"."""
    if path is None:
        return reference_config()
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except OSError as exc:
        raise ConfigError("file", f"cannot read: {exc.strerror or exc}") from None
    try:
        text = raw.decode("utf-8-sig")  # without a leading byte-order mark
    except UnicodeDecodeError as exc:
        hint = (
            "; it starts with a UTF-16 byte-order mark: save it as UTF-8"
            if raw[:2] in (b"\xff\xfe", b"\xfe\xff")
            else ""
        )
        raise ConfigError("file", f"not UTF-8 text (byte {exc.start}){hint}") from None
    return loads_config(text)


def check_runnable(cfg: Config) -> None:
    """The checks a configuration needs to be simulated, beyond the range of each key: an arc
    end needs a finite end radius. `jaxbearing simulate` and `jaxbearing config check` both call
    this (one code path), after any command-line overrides. Raises ConfigError."""
    for end in cfg.simulation.ends:
        if end == "arc" and not math.isfinite(cfg["roller.end_radius_mm"]):
            raise ConfigError(
                "roller.end_radius_mm",
                f"inf (flat end) cannot be simulated as an arc end (simulation.end = "
                f'"{cfg.simulation.end}"): set simulation.end = "corner" (--end corner) or give '
                "a finite end radius",
            )


def reference_config() -> Config:
    """The embedded reference configuration: every key at its reference value (`KEYS`)."""
    return Config()


def reference_bearing() -> Bearing:
    """The embedded reference bearing of docs/model.md section 1, built from the reference values of
    the configuration schema (the one place they are written down, `io/_schema.py`).

    Representative, not the source study's bearing: the paper's Table 1 is not available. The
    values are an aero-engine mainshaft roller bearing chosen so that the paper's stated values
    (H_rf = 2 mm, contact-height limit 1.8 mm, R_end = 80 mm, theta_f = 1.6 deg,
    Delta_bf = 0.15 mm, L_b2 = 4.5 mm) give the same kind of design zone.
    """
    return Config().bearing()


def reference_operating_point() -> OperatingPoint:
    """20,000 rpm on the inner ring, 1000 N radial load, gravity on (the reference configuration)."""
    return Config().operating_point()
