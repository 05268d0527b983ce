"""Parameter sweeps at scale: vmapped batches of `solve`, sharded over devices and processes,
resumable, with labelled results (issue 6).

A sweep spec (TOML) names a base configuration and the axes to vary, in engineering units:

    [sweep]
    base = "bearing.toml"     # a config file relative to the spec; omitted = reference bearing
    mode = "grid"             # "grid" (every combination, default) or "zip" (axes side by side)
    zip = [["operating.speed_rpm", "operating.radial_load_N"]]  # optional zipped groups in a grid
    batch_size = 8            # cases per vmapped batch (all local devices together)
    num_saves = 400           # samples of the flange-contact histories per case
    max_positions = 500       # contact positions (y, z) kept per case for Figure 13

    [base.simulation]         # inline [base.*] tables override the base configuration
    duration_ms = 2.0

    [axes]
    "operating.speed_rpm" = [10000, 20000, 30000]
    "roller.end_radius_mm" = { start = 60, stop = 120, num = 4 }   # inclusive linspace
    end = ["arc", "corner"]   # special axis: corner = Bearing.with_flat_ends()

Every axis key is a dotted configuration key (`jaxbearing config show`) or `end`. Every case is
built through `Config.replace`, i.e. re-validated, before anything is computed; a bad spec
raises `SweepSpecError` (a `UserInputError`: one line naming the axis). Keys that change array
shapes (`bearing.num_rollers`, `bearing.num_slices`) or the compiled program
(`simulation.max_steps`, `simulation.progress`) cannot be axes: run one sweep per value.
`simulation.duration_ms`, `simulation.rtol` and `simulation.atol` can (they are traced). Without
an `end` axis the base's `simulation.end` decides; "both" (the reference) adds the axis
`end = ["arc", "corner"]`.

Execution (`run_sweep`): the cases, in C order over the dimensions, are cut into batches of
`batch_size`; batch `k` belongs to process `k % num_processes` (deterministic). A batch is one
call of `jax.vmap(solve)` under `jax.shard_map` over a 1-D mesh of the process's local devices
(the batch padded with copies of its last case to a multiple of the device count; the last batch
padded to the full size, so every batch reuses one compilation). Each finished batch is written
at once and atomically (temporary file + `os.replace`) to `DIR/batches/batch_NNNNN.npz` with its
case indices and the spec hash; a restarted sweep skips every valid batch file, so a sweep killed
at any moment (SIGKILL included) ends, when started again with the same command, with exactly
the results of an uninterrupted run. A case whose solve fails (diffrax result != successful) is
recorded with its status and NaN statistics; it never stops the sweep. Every computed batch is
appended to `DIR/sweep.log` (JSON lines).

Results (`assemble`): one `xarray.Dataset`, `DIR/results.nc` (netCDF3 through scipy), with the
sweep axes as coordinates (zipped axes share one dimension), the `summarise` statistics of every
case (`flange_pv_Pa_m_s_max`, ...), `status`, the design-zone margins of every case
(`jaxbearing.design_zone`, aligned roller, flange load 100 N) and a sample of up to
`max_positions` contact positions on the roller end face per case (`contact_position`,
roller frame, m; NaN-padded).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
import numbers
import os
import pathlib
import sys
import time
import tomllib
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ._config import Config, load_config
from ._errors import ConfigError, UserInputError
from ._validation import KEY_BY_PATH, KEYS, format_value, type_name

#: format version of the batch files and the dataset
FORMAT_VERSION = 1
#: spec keys that cannot be axes, and why
_STATIC_KEYS = {
    "bearing.num_rollers": "it changes array shapes (static); run one sweep per value",
    "bearing.num_slices": "it changes array shapes (static); run one sweep per value",
    "simulation.max_steps": "it is a static argument of the compiled solve; set it in "
    "[base.simulation]",
    "simulation.progress": "progress is not a model parameter",
    "simulation.end": "use the special axis \"end\" = [\"arc\", \"corner\"]",
}
_SWEEP_FIELDS = ("base", "mode", "zip", "batch_size", "num_saves", "max_positions")
_RANGE_FIELDS = ("start", "stop", "num")
#: summary quantities with max/mean/median/min statistics over contact events
_EVENT_STATS = (
    "flange_force_N",
    "flange_pressure_Pa",
    "flange_sliding_velocity_m_s",
    "flange_pv_Pa_m_s",
    "contact_height_m",
    "contact_radius_m",
)
_STATS = ("max", "mean", "median", "min")
#: scalar summary quantities (summary.json keys) stored per case
_SCALARS = (
    "cage_speed_rpm",
    "kinematic_cage_speed_rpm",
    "cage_slip",
    "flange_contact_events",
    "on_arc_fraction",
    "smooth_peak_pv_Pa_m_s",
    "smooth_max_contact_height_m",
    "num_steps",
    "num_rejected_steps",
    "simulated_time_s",
)
#: kept even for failed cases (the rest become NaN)
_KEPT_ON_FAILURE = ("kinematic_cage_speed_rpm", "num_steps", "num_rejected_steps", "simulated_time_s")
#: design-zone fields stored per case (name in the dataset: zone_<field>_m)
_ZONE_FIELDS = (
    "contact_height",
    "contact_radius",
    "actual_axial_clearance",
    "relief_margin",
    "height_margin",
    "limited_circle_margin",
    "clearance_margin",
)
#: normal force above which a sample counts as a flange contact [N] (as `summarise`)
CONTACT_THRESHOLD = 1.0


class SweepSpecError(UserInputError):
    """A sweep spec is malformed; `axis` names the offending axis or spec field."""

    def __init__(self, axis: str, message: str):
        self.axis = axis
        super().__init__(f"{axis}: {message}")


def variable_names() -> tuple[str, ...]:
    """Names of the per-case float variables of the dataset (besides status, result_code,
    contact positions and the design zone)."""
    return _SCALARS + tuple(f"{q}_{s}" for q in _EVENT_STATS for s in _STATS)


# -- the spec ------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True)
class Axis:
    """One swept parameter: `key` (dotted config key or "end"), coordinate `name` in the
    dataset, its `values` (engineering units) and the dataset dimension `dim` it runs along."""

    key: str
    name: str
    values: tuple
    dim: str


@dataclasses.dataclass(frozen=True)
class SweepSpec:
    """A validated sweep: base configuration, axes, dimensions and run settings.

    Cases are numbered in C order over `dims` (sizes `shape`); zipped axes share a dimension.
    Build one with `load_sweep_spec` / `loads_sweep_spec`; `canonical()` is the JSON form stored
    as DIR/spec.json and `hash` its SHA-256.
    """

    base: Config
    axes: tuple[Axis, ...]
    dims: tuple[str, ...]
    shape: tuple[int, ...]
    batch_size: int = 8
    num_saves: int = 400
    max_positions: int = 500

    @property
    def num_cases(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64))

    @property
    def num_batches(self) -> int:
        return -(-self.num_cases // self.batch_size)

    def batch_cases(self, batch: int) -> np.ndarray:
        """Case indices of `batch`."""
        return np.arange(batch * self.batch_size, min((batch + 1) * self.batch_size, self.num_cases))

    def case_values(self, case: int) -> dict[str, Any]:
        """{axis key: value} of case number `case`."""
        index = np.unravel_index(case, self.shape)
        pos = dict(zip(self.dims, (int(i) for i in index)))
        return {a.key: a.values[pos[a.dim]] for a in self.axes}

    def case_config(self, case: int) -> tuple[Config, str]:
        """(validated configuration, end type) of case number `case`."""
        values = self.case_values(case)
        end = values.pop("end", self.base.simulation.end)
        return (self.base.replace(**values) if values else self.base), end

    def canonical(self) -> dict:
        return {
            "format": FORMAT_VERSION,
            "base": self.base.to_dict(),
            "axes": [{"key": a.key, "name": a.name, "values": list(a.values), "dim": a.dim}
                     for a in self.axes],
            "dims": list(self.dims),
            "shape": list(self.shape),
            "batch_size": self.batch_size,
            "num_saves": self.num_saves,
            "max_positions": self.max_positions,
        }

    @functools.cached_property
    def hash(self) -> str:
        text = json.dumps(self.canonical(), sort_keys=True, allow_nan=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    @classmethod
    def from_canonical(cls, data: Mapping) -> "SweepSpec":
        if data.get("format") != FORMAT_VERSION:
            raise SweepSpecError("spec.json", f"format {data.get('format')!r} is not "
                                 f"{FORMAT_VERSION}; written by another jaxbearing version")
        axes = tuple(Axis(a["key"], a["name"], tuple(a["values"]), a["dim"]) for a in data["axes"])
        return cls(Config(data["base"]), axes, tuple(data["dims"]), tuple(data["shape"]),
                   data["batch_size"], data["num_saves"], data["max_positions"])

    def with_batch_size(self, batch_size: int) -> "SweepSpec":
        _positive_int("batch_size", batch_size)
        return dataclasses.replace(self, batch_size=int(batch_size))


def _positive_int(field: str, value) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
        raise SweepSpecError(field, f"{format_value(value)} must be an integer >= 1")
    return int(value)


def _wrong_unit(path: str) -> str | None:
    """'roller.end_radius_m' -> a message pointing at roller.end_radius_mm (engineering units)."""
    section, _, name = path.rpartition(".")
    for key in KEYS:
        if key.section != section or not key.unit or key.name == name:
            continue
        stem = key.name[: len(key.name) - len(key.path.rpartition("_")[2]) - 1]
        if "_" in key.name and name.startswith(stem + "_"):
            return (f"wrong unit suffix: configuration keys are in engineering units with the "
                    f"unit in the name; use {key.path} [{key.unit}]")
    return None


def _axis_values(key: str, raw) -> tuple:
    """The values of one axis: a list, or a range table {start, stop, num} (inclusive)."""
    if isinstance(raw, Mapping):
        unknown = [k for k in raw if k not in _RANGE_FIELDS]
        if unknown:
            raise SweepSpecError(key, f"unknown range field {unknown[0]!r}; a range is "
                                 "{ start = ..., stop = ..., num = ... } (stop included)")
        missing = [k for k in _RANGE_FIELDS if k not in raw]
        if missing:
            raise SweepSpecError(key, f"range is missing {missing[0]!r}; a range is "
                                 "{ start = ..., stop = ..., num = ... } (stop included)")
        num = raw["num"]
        if isinstance(num, bool) or not isinstance(num, numbers.Integral):
            raise SweepSpecError(key, f"range num must be an integer, got {type_name(num)}")
        if num < 1:
            raise SweepSpecError(key, f"empty axis: range num = {num} (must be >= 1)")
        for f in ("start", "stop"):
            v = raw[f]
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(v):
                raise SweepSpecError(key, f"range {f} must be a finite number, got "
                                     f"{type_name(v)} {format_value(v)}")
        return tuple(float(v) for v in np.linspace(raw["start"], raw["stop"], num))
    if isinstance(raw, (list, tuple)):
        if not raw:
            raise SweepSpecError(key, "empty axis: give at least one value")
        return tuple(raw)
    raise SweepSpecError(key, f"expected a list of values or a range table "
                         f"{{start, stop, num}}, got {type_name(raw)} {format_value(raw)}")


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
    """A validated `SweepSpec` from the parsed TOML of a spec (see the module docstring).

    Every case is validated through `Config.replace`; errors name the axis."""
    unknown = [k for k in data if k not in ("sweep", "base", "axes")]
    if unknown:
        raise SweepSpecError(unknown[0], "unknown table; a sweep spec has [sweep], [base] "
                             "and [axes]")
    sweep = data.get("sweep", {})
    if not isinstance(sweep, Mapping):
        raise SweepSpecError("sweep", f"expected a table, got {type_name(sweep)}")
    for k in sweep:
        if k not in _SWEEP_FIELDS:
            import difflib

            near = difflib.get_close_matches(k, _SWEEP_FIELDS, n=1)
            hint = f"did you mean sweep.{near[0]}?" if near else "valid: " + ", ".join(_SWEEP_FIELDS)
            raise SweepSpecError(f"sweep.{k}", f"unknown field; {hint}")

    # base configuration: file (relative to the spec) and/or inline [base] tables
    base_ref = sweep.get("base", "reference")
    if not isinstance(base_ref, str):
        raise SweepSpecError("sweep.base", f"expected a config file path or \"reference\", "
                             f"got {type_name(base_ref)}")
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
    inline = data.get("base", {})
    if inline:
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
            base = Config(merged)
        except ConfigError as exc:
            raise SweepSpecError(f"base.{exc.field}", str(exc).partition(": ")[2]) from None

    axes_raw = data.get("axes", {})
    if not isinstance(axes_raw, Mapping):
        raise SweepSpecError("axes", f"expected a table of axes, got {type_name(axes_raw)}")
    # TOML dotted keys without quotes arrive nested: {"operating": {"speed_rpm": [...]}}
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
        raise SweepSpecError("axes", "no axes: give at least one, e.g. "
                             "\"operating.speed_rpm\" = [10000, 20000]")
    values: dict[str, tuple] = {}
    for key, raw in flat.items():
        _check_axis_key(key)
        vals = _axis_values(key, raw)
        if key == "end":
            bad = [v for v in vals if v not in ("arc", "corner")]
            if bad:
                raise SweepSpecError("end", f"{format_value(bad[0])} is not a roller end type; "
                                     "values are \"arc\" and \"corner\"")
        else:
            cfg_key = KEY_BY_PATH[key]
            for v in vals:
                if isinstance(v, str):
                    raise SweepSpecError(key, f"expected numbers [{cfg_key.unit}], got string "
                                         f"{format_value(v)}; units are part of the key name")
            vals = tuple(cfg_key.kind(v) if cfg_key.kind is float and not isinstance(v, bool)
                         else v for v in vals)
        if len(set(vals)) != len(vals):
            dup = next(v for v in vals if vals.count(v) > 1)
            raise SweepSpecError(key, f"value {format_value(dup)} appears twice")
        values[key] = vals
    if "end" not in values and base.simulation.end == "both":
        values["end"] = ("arc", "corner")

    # dimensions: every axis its own, unless zipped
    mode = sweep.get("mode", "grid")
    if mode not in ("grid", "zip"):
        raise SweepSpecError("sweep.mode", f"{format_value(mode)} is not \"grid\" or \"zip\"")
    groups_raw = sweep.get("zip", [])
    if mode == "zip":
        if groups_raw:
            raise SweepSpecError("sweep.zip", "give either mode = \"zip\" (all axes zipped) or "
                                 "zip groups, not both")
        groups = [list(values)]
    else:
        if not isinstance(groups_raw, list) or not all(isinstance(g, list) for g in groups_raw):
            raise SweepSpecError("sweep.zip", "expected a list of lists of axis keys")
        groups = [list(g) for g in groups_raw]
    grouped: dict[str, int] = {}
    for gi, group in enumerate(groups):
        for key in group:
            if key not in values:
                raise SweepSpecError("sweep.zip", f"{key!r} is not an axis (axes: "
                                     f"{', '.join(values)})")
            if key in grouped:
                raise SweepSpecError("sweep.zip", f"{key!r} is in two zip groups")
            grouped[key] = gi
        lengths = {key: len(values[key]) for key in group}
        if len(set(lengths.values())) > 1:
            first = group[0]
            other = next(k for k in group if lengths[k] != lengths[first])
            raise SweepSpecError(other, f"zipped axes must have equal lengths: {other} has "
                                 f"{lengths[other]} values, {first} has {lengths[first]}")
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

    spec = SweepSpec(
        base=base,
        axes=tuple(axes),
        dims=tuple(dims),
        shape=tuple(shape),
        batch_size=_positive_int("sweep.batch_size", sweep.get("batch_size", 8)),
        num_saves=_positive_int("sweep.num_saves", sweep.get("num_saves", 400)),
        max_positions=_positive_int("sweep.max_positions", sweep.get("max_positions", 500)),
    )
    validate_cases(spec)
    return spec


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
            raise SweepSpecError(axis or " + ".join(values),
                                 f"case {case} ({shown}) is invalid: {exc}") from None
        if end == "arc" and not math.isfinite(cfg["roller.end_radius_mm"]):
            axis = "roller.end_radius_mm" if "roller.end_radius_mm" in values else "end"
            raise SweepSpecError(axis, f"case {case}: end = \"arc\" needs a finite "
                                 "roller.end_radius_mm (inf is the flat end); use end = \"corner\"")


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


# -- batched solve -------------------------------------------------------------------------------
def _case_inputs(spec: SweepSpec, case: int):
    """(bearing, operating point, duration, rtol, atol) of one case, SI, numpy leaves."""
    import jax

    cfg, end = spec.case_config(case)
    bearing = cfg.bearing()
    if end == "corner":
        bearing = bearing.with_flat_ends()
    sim = cfg.simulation
    inputs = (bearing, cfg.operating_point(), sim.duration, sim.rtol, sim.atol)
    return jax.tree_util.tree_map(lambda x: np.asarray(x, dtype=np.float64), inputs)


def stack_cases(cases: Sequence) -> Any:
    """Stack per-case pytrees along a new leading axis (`jnp.stack` of every float leaf)."""
    import jax
    import jax.numpy as jnp

    return jax.tree_util.tree_map(lambda *xs: jnp.stack(xs), *cases)


@functools.cache
def batch_runner(num_saves: int, max_steps: int, devices: tuple):
    """A jit-compiled `vmap(solve)` sharded with `jax.shard_map` over a 1-D mesh of `devices`
    (axis "cases"): each device integrates its slice of the batch. Takes stacked
    (bearing, op, duration, rtol, atol) whose leading axis is a multiple of len(devices)."""
    import jax
    from jax.sharding import Mesh, PartitionSpec

    from ._simulate import solve

    def one(bearing, op, duration, rtol, atol):
        return solve(bearing, op, duration, num_saves=num_saves, rtol=rtol, atol=atol,
                     max_steps=max_steps, progress=False)

    mesh = Mesh(np.asarray(devices), ("cases",))
    spec = PartitionSpec("cases")
    sharded = jax.shard_map(jax.vmap(one), mesh=mesh, in_specs=(spec,) * 5, out_specs=spec,
                            check_vma=False)
    return jax.jit(sharded)


def padded_size(batch_size: int, num_devices: int) -> int:
    """Batch size rounded up to a multiple of the device count."""
    return -(-batch_size // num_devices) * num_devices


def solve_batch(spec: SweepSpec, cases: Sequence[int], devices: Sequence | None = None) -> dict:
    """Solve the cases `cases` as one sharded, vmapped batch; per-case summaries (numpy)."""
    import jax

    devices = tuple(jax.local_devices() if devices is None else devices)
    size = padded_size(spec.batch_size, len(devices))
    inputs = [_case_inputs(spec, int(c)) for c in cases]
    inputs += [inputs[-1]] * (size - len(inputs))  # pad with copies of the last case
    stacked = jax.tree_util.tree_map(lambda *xs: np.stack(xs), *inputs)
    runner = batch_runner(spec.num_saves, spec.base.simulation.max_steps, devices)
    sol = jax.device_get(runner(*stacked))
    rows = [_summarise_case(spec, jax.tree_util.tree_map(lambda a: a[i], sol), inputs[i])
            for i in range(len(cases))]
    out = {"case_index": np.asarray(cases, dtype=np.int64)}
    for key in rows[0]:
        out[key] = np.stack([r[key] for r in rows])
    return out


def _summarise_case(spec: SweepSpec, sol, inputs) -> dict:
    from ._dynamics import Functionals
    from ._simulate import _result
    from ._summary import summarise

    bearing, op, duration, _, _ = inputs
    res = _result(sol, bearing, op, Functionals(), float(duration), float("nan"), float("nan"))
    summary = summarise(res, threshold=CONTACT_THRESHOLD)
    row: dict[str, Any] = {}
    for key in _SCALARS:
        v = summary[key]
        row[key] = np.float64(np.nan if v is None else v)
    for q in _EVENT_STATS:
        for s in _STATS:
            v = summary[q][s]
            row[f"{q}_{s}"] = np.float64(np.nan if v is None else v)
    if not res.ok:
        for key in row:
            if key not in _KEPT_ON_FAILURE:
                row[key] = np.float64(np.nan)
    row["status"] = np.asarray(res.status)
    row["result_code"] = np.int32(int(sol.result))
    # compact sample of contact positions on the end face (roller frame y, z [m])
    h = res.histories
    points = np.full((spec.max_positions, 2), np.nan)
    count = 0
    if res.ok and len(h["t"]):
        mask = np.asarray(h["flange_force"]) > CONTACT_THRESHOLD  # (T, Z, 4)
        pos = np.asarray(h["end_face_position"])[mask]  # (K, 2)
        if len(pos) > spec.max_positions:
            pos = pos[np.linspace(0, len(pos) - 1, spec.max_positions).round().astype(int)]
        count = len(pos)
        points[:count] = pos
    row["contact_position"] = points
    row["contact_position_count"] = np.int32(count)
    return row


# -- files ---------------------------------------------------------------------------------------
def batch_path(out_dir: pathlib.Path, batch: int) -> pathlib.Path:
    return pathlib.Path(out_dir) / "batches" / f"batch_{batch:05d}.npz"


def _atomic_write(path: pathlib.Path, write) -> None:
    """Write through `write(file)` to a temporary file next to `path`, fsync, os.replace."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    with open(tmp, "wb") as f:
        write(f)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def write_batch(out_dir: pathlib.Path, spec: SweepSpec, batch: int, data: dict) -> pathlib.Path:
    path = batch_path(out_dir, batch)
    _atomic_write(path, lambda f: np.savez(f, spec_hash=np.asarray(spec.hash),
                                           batch=np.int64(batch), **data))
    return path


def read_batch(out_dir: pathlib.Path, spec: SweepSpec, batch: int) -> dict | None:
    """The contents of a finished batch file, or None if it is missing, unreadable, of another
    spec or of other cases."""
    path = batch_path(out_dir, batch)
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}
    except (OSError, ValueError, EOFError, KeyError):
        return None
    if str(data.get("spec_hash")) != spec.hash:
        return None
    if not np.array_equal(data.get("case_index"), spec.batch_cases(batch)):
        return None
    return data


def _log(out_dir: pathlib.Path, record: dict) -> None:
    line = json.dumps(record) + "\n"
    fd = os.open(pathlib.Path(out_dir) / "sweep.log", os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
    try:
        os.write(fd, line.encode())
    finally:
        os.close(fd)


def computed_batches(out_dir: str | os.PathLike) -> list[int]:
    """Batch indices computed so far, from DIR/sweep.log, one entry per computation."""
    path = pathlib.Path(out_dir) / "sweep.log"
    if not path.exists():
        return []
    out = []
    for line in path.read_text().splitlines():
        try:
            rec = json.loads(line)
        except json.JSONDecodeError:
            continue  # a line cut by a kill
        if rec.get("event") == "batch":
            out.append(int(rec["batch"]))
    return out


def _prepare_dir(out_dir: pathlib.Path, spec: SweepSpec, resume: bool, process_id: int) -> None:
    """Create DIR and DIR/spec.json; a DIR holding another sweep is an error when resuming."""
    out_dir.mkdir(parents=True, exist_ok=True)
    spec_file = out_dir / "spec.json"
    if spec_file.exists() and resume:
        try:
            old = json.loads(spec_file.read_text())
        except (OSError, json.JSONDecodeError):
            old = None
        if old is not None and old.get("hash") != spec.hash:
            raise SweepSpecError(
                "--out", f"{out_dir} holds another sweep (spec hash {old.get('hash')}, this one "
                f"{spec.hash}; the spec or --batch-size changed); use another --out or --no-resume")
    if process_id == 0:
        doc = {"hash": spec.hash, "spec": spec.canonical()}
        _atomic_write(spec_file, lambda f: f.write(json.dumps(doc, indent=1, allow_nan=True).encode()))
        if not resume:
            (out_dir / "results.nc").unlink(missing_ok=True)


def load_spec_from_dir(out_dir: str | os.PathLike) -> SweepSpec:
    """The spec of the sweep in DIR (from DIR/spec.json)."""
    path = pathlib.Path(out_dir) / "spec.json"
    try:
        doc = json.loads(path.read_text())
    except OSError:
        raise SweepSpecError("DIR", f"{out_dir} is not a sweep directory (no spec.json)") from None
    return SweepSpec.from_canonical(doc["spec"])


# -- progress ------------------------------------------------------------------------------------
class _Progress:
    """Plain-text progress over cases on stderr (one line per finished batch)."""

    def __init__(self, total: int, done: int, enabled: bool, prefix: str):
        self.total, self.done, self.enabled, self.prefix = total, done, enabled, prefix
        self.start = time.perf_counter()
        self.start_done = done
        self.show()

    def show(self) -> None:
        if not self.enabled:
            return
        width = 30
        frac = self.done / self.total if self.total else 1.0
        bar = "#" * int(width * frac) + "." * (width - int(width * frac))
        el = time.perf_counter() - self.start
        rate = (self.done - self.start_done) / el if el > 0 and self.done > self.start_done else 0
        eta = f", ETA {(self.total - self.done) / rate:.0f} s" if rate else ""
        print(f"{self.prefix}[{bar}] {self.done}/{self.total} cases ({frac:.0%}), "
              f"{el:.1f} s{eta}", file=sys.stderr, flush=True)

    def update(self, n: int) -> None:
        self.done += n
        self.show()


# -- driver --------------------------------------------------------------------------------------
def assigned_batches(spec: SweepSpec, process_id: int, num_processes: int) -> list[int]:
    """The batches of process `process_id`: batch k belongs to process k % num_processes."""
    return [b for b in range(spec.num_batches) if b % num_processes == process_id]


def run_sweep(
    spec: SweepSpec,
    out_dir: str | os.PathLike,
    *,
    resume: bool = True,
    process_id: int = 0,
    num_processes: int = 1,
    progress: bool = True,
    assemble_results: bool = True,
    wait_timeout_s: float = 24 * 3600.0,
    devices: Sequence | None = None,
):
    """Run (or finish) the sweep `spec` into `out_dir`; returns the assembled dataset (process 0)
    or None (other processes, or `assemble_results=False`).

    This process computes its batches (k % num_processes == process_id) that have no valid batch
    file (all of them with `resume=False`), writing each as it finishes. Process 0 then waits up
    to `wait_timeout_s` for every other batch file and assembles DIR/results.nc.
    """
    out_dir = pathlib.Path(out_dir)
    _prepare_dir(out_dir, spec, resume, process_id)
    mine = assigned_batches(spec, process_id, num_processes)
    todo = [b for b in mine if not resume or read_batch(out_dir, spec, b) is None]
    n_mine = sum(len(spec.batch_cases(b)) for b in mine)
    n_todo = sum(len(spec.batch_cases(b)) for b in todo)
    prefix = f"sweep[{process_id}/{num_processes}] " if num_processes > 1 else "sweep "
    bar = _Progress(n_mine, n_mine - n_todo, progress, prefix)
    for b in todo:
        cases = spec.batch_cases(b)
        start = time.perf_counter()
        data = solve_batch(spec, cases, devices)
        write_batch(out_dir, spec, b, data)
        _log(out_dir, {"event": "batch", "batch": b, "process": process_id,
                       "cases": [int(cases[0]), int(cases[-1])],
                       "failed": int(np.sum(data["result_code"] != 0)),
                       "wall_s": round(time.perf_counter() - start, 3)})
        bar.update(len(cases))
    if process_id != 0 or not assemble_results:
        return None
    missing = _wait_for_batches(out_dir, spec, wait_timeout_s, progress)
    if missing:
        raise UserInputError(
            f"{len(missing)} batch file(s) of {out_dir} still missing after {wait_timeout_s:g} s "
            f"(first: {batch_path(out_dir, missing[0]).name}); run the same command again to "
            "finish them")
    return assemble(out_dir, spec)


def missing_batches(out_dir: str | os.PathLike, spec: SweepSpec) -> list[int]:
    return [b for b in range(spec.num_batches) if read_batch(pathlib.Path(out_dir), spec, b) is None]


def _wait_for_batches(out_dir, spec, timeout_s, progress) -> list[int]:
    deadline = time.monotonic() + timeout_s
    told = False
    while True:
        missing = missing_batches(out_dir, spec)
        if not missing or time.monotonic() >= deadline:
            return missing
        if progress and not told:
            print(f"sweep: waiting for {len(missing)} batch(es) from the other processes",
                  file=sys.stderr, flush=True)
            told = True
        time.sleep(0.5)


# -- the dataset ---------------------------------------------------------------------------------
def design_zone_cases(spec: SweepSpec) -> dict[str, np.ndarray]:
    """Design-zone margins (`jaxbearing.design_zone`) of every case, vmapped, numpy (N,)."""
    import jax

    bearings = [_case_inputs(spec, c)[0] for c in range(spec.num_cases)]
    stacked = jax.tree_util.tree_map(lambda *xs: np.stack(xs), *bearings)
    zone = jax.device_get(_zone_batch(stacked))
    out = {f"zone_{f}_m": np.asarray(getattr(zone, f), dtype=np.float64) for f in _ZONE_FIELDS}
    out["zone_feasible"] = np.asarray(zone.feasible, dtype=np.int8)
    return out


@functools.cache
def _zone_fn():
    import jax

    from ._zone import design_zone

    return jax.jit(jax.vmap(design_zone))


def _zone_batch(stacked):
    return _zone_fn()(stacked)


def assemble(out_dir: str | os.PathLike, spec: SweepSpec | None = None):
    """Assemble DIR/results.nc from the batch files (all must exist) and return the Dataset."""
    import xarray as xr

    out_dir = pathlib.Path(out_dir)
    spec = spec or load_spec_from_dir(out_dir)
    batches = []
    for b in range(spec.num_batches):
        data = read_batch(out_dir, spec, b)
        if data is None:
            raise UserInputError(f"{out_dir}: {batch_path(out_dir, b).name} is missing; run "
                                 "the sweep command again to compute it")
        batches.append(data)
    cols = {k: np.concatenate([d[k] for d in batches]) for k in batches[0]
            if k not in ("spec_hash", "batch")}
    shape = spec.shape
    dims = spec.dims
    data_vars: dict[str, Any] = {}
    for name in variable_names():
        attrs = {"description": f"summarise()['{name}'] of the case"}
        data_vars[name] = (dims, cols[name].reshape(shape), attrs)
    data_vars["status"] = (dims, cols["status"].astype(str).reshape(shape),
                           {"description": "\"ok\" or the solver failure"})
    data_vars["result_code"] = (dims, cols["result_code"].astype(np.int32).reshape(shape),
                                {"description": "diffrax result code (0 = successful)"})
    data_vars["contact_position"] = (
        dims + ("sample", "end_face_axis"),
        cols["contact_position"].reshape(shape + cols["contact_position"].shape[1:]),
        {"units": "m", "description": "flange contact points on the roller end face (roller "
         "frame y, z), evenly subsampled over all contact samples; NaN-padded"})
    data_vars["contact_position_count"] = (dims, cols["contact_position_count"].astype(np.int32)
                                           .reshape(shape), {"description": "valid samples"})
    for name, values in design_zone_cases(spec).items():
        data_vars[name] = (dims, values.reshape(shape),
                           {"description": "jaxbearing.design_zone of the case (aligned roller, "
                            "flange load 100 N); margins > 0 are feasible"})
    coords: dict[str, Any] = {}
    for a in spec.axes:
        unit = KEY_BY_PATH[a.key].unit if a.key in KEY_BY_PATH else ""
        vals = np.asarray(a.values, dtype=str if a.key == "end" else float)
        coords[a.name] = (a.dim, vals, {"config_key": a.key, "units": unit})
    coords["end_face_axis"] = ("end_face_axis", np.array(["y", "z"]))
    ds = xr.Dataset(data_vars, coords=coords)
    ds.attrs.update(
        spec_hash=spec.hash,
        spec=json.dumps(spec.canonical(), allow_nan=True),
        base_end=spec.base.simulation.end,
        duration_ms=spec.base.simulation.duration_ms,
        num_saves=spec.num_saves,
        source="jaxbearing sweep (issue 6)",
    )
    path = out_dir / "results.nc"
    _atomic_write(path, lambda f: f.write(ds.to_netcdf(None, engine="scipy")))
    return ds


def open_results(out_dir: str | os.PathLike):
    """DIR/results.nc as an xarray Dataset (assembled from the batch files first if missing)."""
    import xarray as xr

    path = pathlib.Path(out_dir) / "results.nc"
    if not path.exists():
        return assemble(out_dir)
    with xr.open_dataset(path, engine="scipy") as ds:
        return ds.load()


def initialize_distributed(coordinator: str | None, num_processes: int | None,
                           process_id: int | None) -> tuple[int, int]:
    """`jax.distributed.initialize` from explicit values or the environment variables
    JAXBEARING_COORDINATOR, JAXBEARING_NUM_PROCESSES, JAXBEARING_PROCESS_ID. Returns
    (process_id, num_processes); (0, 1) without a coordinator. Must run before JAX computes."""
    coordinator = coordinator or os.environ.get("JAXBEARING_COORDINATOR")
    if num_processes is None and "JAXBEARING_NUM_PROCESSES" in os.environ:
        num_processes = _env_int("JAXBEARING_NUM_PROCESSES")
    if process_id is None and "JAXBEARING_PROCESS_ID" in os.environ:
        process_id = _env_int("JAXBEARING_PROCESS_ID")
    if not coordinator:
        if (num_processes or 1) > 1:
            raise UserInputError("--num-processes > 1 needs --coordinator HOST:PORT "
                                 "(or JAXBEARING_COORDINATOR)")
        return 0, 1
    if num_processes is None or process_id is None:
        raise UserInputError("--coordinator needs --num-processes and --process-id (or "
                             "JAXBEARING_NUM_PROCESSES and JAXBEARING_PROCESS_ID)")
    if num_processes < 1 or not 0 <= process_id < num_processes:
        raise UserInputError(f"--process-id {process_id} must be in [0, --num-processes "
                             f"{num_processes})")
    import jax
    from jax._src import xla_bridge

    if xla_bridge.backends_are_initialized():
        raise UserInputError("jax.distributed must be initialised before JAX computes anything: "
                             "start the distributed sweep in a fresh process")
    jax.distributed.initialize(coordinator_address=coordinator, num_processes=num_processes,
                               process_id=process_id)
    return jax.process_index(), jax.process_count()


def _env_int(name: str) -> int:
    try:
        return int(os.environ[name])
    except ValueError:
        raise UserInputError(f"{name}={os.environ[name]!r} is not an integer") from None


__all__ = [
    "Axis",
    "SweepSpec",
    "SweepSpecError",
    "assemble",
    "batch_runner",
    "computed_batches",
    "load_sweep_spec",
    "loads_sweep_spec",
    "open_results",
    "run_sweep",
    "solve_batch",
    "stack_cases",
]
