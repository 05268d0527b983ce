"""Parameter sweeps at scale: vmapped batches of `solve`, sharded over devices and processes,
resumable, with labelled results.

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

Settled running (the default): every case settles and is measured over a window of whole cage
revolutions, for `seeds` seeded initial scatters, as members of the steady-running engine
(`jaxbearing.run.settle_members`; the options of `jaxbearing simulate`):

    [sweep]
    settle = "auto"           # "auto" (default: until the settling verdict), a settling time
                              # in ms, or "off": a start-up transient of simulation.duration_ms
    seeds = 2                 # seeded initial scatters per case (default 1)
    window_revs = 8           # cage revolutions measured after settling (default 8)
    settle_tolerance = 1e-3   # relative remaining drift of the cage speed (default 1e-3)
    settle_cap_ms = 300       # settling gives up here (reported, not settled; default 300)
    start = "skid"            # "skid" (default) or "quasi-static"

The dataset then holds, for every statistic, its value and 95 % interval (`NAME`,
`NAME_ci95_low`, `NAME_ci95_high`: batch means over revolutions for one seed, Student-t over
the seeds for several), and per case `settled`, `settle_time_ms`, `window_ms`, `seeds` and the
residual drift. With `settle = "off"` the cases are start-up transients of
`simulation.duration_ms` from the quasi-static start (one `vmap(solve)` per batch, below), and
the dataset and its figures say so (attribute `running` = "start-up transient").

Every axis key is a dotted configuration key (`jaxbearing config show`) or `end`. Every case is
built through `Config.replace`, i.e. re-validated, before anything is computed; a bad spec
raises `SweepSpecError` (a `UserInputError`: one line naming the axis). Keys that change array
shapes (`bearing.num_rollers`, `bearing.num_slices`) or the compiled program
(`bearing.flange_lubrication`, `simulation.max_steps`, `simulation.progress`) cannot be axes: run one sweep per value.
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
import numbers
from collections.abc import Mapping
from typing import Any

import numpy as np

from .._errors import UserInputError
from ..io import Config, format_value
from ..run import SteadySettings

#: format version of the batch files and the dataset (2: settled running and its options)
FORMAT_VERSION = 2
#: spec keys that cannot be axes, and why
_STATIC_KEYS = {
    "bearing.num_rollers": "it changes array shapes (static); run one sweep per value",
    "bearing.num_slices": "it changes array shapes (static); run one sweep per value",
    "bearing.flange_lubrication": "it selects the compiled flange friction law (static); run one sweep per value",
    "bearing.type": "axes take numbers and the bearing type is a name or a list of flanges; run one sweep per type",
    "simulation.max_steps": "it is a static argument of the compiled solve; set it in [base.simulation]",
    "simulation.progress": "progress is not a model parameter",
    "simulation.end": 'use the special axis "end" = ["arc", "corner"]',
}
_SWEEP_FIELDS = (
    "base",
    "mode",
    "zip",
    "batch_size",
    "num_saves",
    "max_positions",
    "settle",
    "seeds",
    "window_revs",
    "settle_tolerance",
    "settle_cap_ms",
    "start",
)
#: the settled-running fields of [sweep] and their defaults (those of `jaxbearing simulate`)
#: the settled-running keys of [sweep] and their defaults: those of `run.SteadySettings`
SETTLED_DEFAULTS = {
    "settle": SteadySettings.settle.value,
    "seeds": SteadySettings.seeds,
    "window_revs": SteadySettings.window_revs,
    "settle_tolerance": SteadySettings.tolerance,
    "settle_cap_ms": SteadySettings.settle_cap_ms,
    "start": SteadySettings.start,
}
_RANGE_FIELDS = ("start", "stop", "num")


class SweepSpecError(UserInputError):
    """A sweep spec is malformed; `axis` names the offending axis or spec field."""

    def __init__(self, axis: str, message: str):
        self.axis = axis
        super().__init__(f"{axis}: {message}")


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
    #: settled running (`SETTLED_DEFAULTS`; module docstring)
    settle: object = SETTLED_DEFAULTS["settle"]
    seeds: int = SETTLED_DEFAULTS["seeds"]
    window_revs: int = SETTLED_DEFAULTS["window_revs"]
    settle_tolerance: float = SETTLED_DEFAULTS["settle_tolerance"]
    settle_cap_ms: float = SETTLED_DEFAULTS["settle_cap_ms"]
    start: str = SETTLED_DEFAULTS["start"]

    @property
    def steady(self) -> SteadySettings:
        """How every case's members settle and measure (its step limit the configuration's)."""
        return SteadySettings(
            settle=self.settle,
            seeds=self.seeds,
            window_revs=self.window_revs,
            tolerance=self.settle_tolerance,
            settle_cap_ms=self.settle_cap_ms,
            start=self.start,
            max_steps=self.base.simulation.max_steps,
        )

    @property
    def settled(self) -> bool:
        """Whether the cases are settled running (else start-up transients)."""
        return self.settle != "off"

    @property
    def running(self) -> str:
        """What the statistics describe: "settled running" or "start-up transient"."""
        return "settled running" if self.settled else "start-up transient"

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
            "axes": [
                {"key": a.key, "name": a.name, "values": list(a.values), "dim": a.dim} for a in self.axes
            ],
            "dims": list(self.dims),
            "shape": list(self.shape),
            "batch_size": self.batch_size,
            "num_saves": self.num_saves,
            "max_positions": self.max_positions,
            **{k: getattr(self, k) for k in SETTLED_DEFAULTS},
        }

    @functools.cached_property
    def hash(self) -> str:
        text = json.dumps(self.canonical(), sort_keys=True, allow_nan=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    @classmethod
    def from_canonical(cls, data: Mapping) -> SweepSpec:
        if data.get("format") != FORMAT_VERSION:
            raise SweepSpecError(
                "spec.json",
                f"format {data.get('format')!r} is not "
                f"{FORMAT_VERSION}; written by another jaxbearing version",
            )
        axes = tuple(Axis(a["key"], a["name"], tuple(a["values"]), a["dim"]) for a in data["axes"])
        return cls(
            Config(data["base"]),
            axes,
            tuple(data["dims"]),
            tuple(data["shape"]),
            data["batch_size"],
            data["num_saves"],
            data["max_positions"],
            **{k: data[k] for k in SETTLED_DEFAULTS},
        )

    def with_batch_size(self, batch_size: int) -> SweepSpec:
        _positive_int("batch_size", batch_size)
        return dataclasses.replace(self, batch_size=int(batch_size))


#: most cases of one sweep (every case is validated when the spec is read; split larger sweeps)
MAX_CASES = 100_000
#: most saved samples per case and contact positions kept per case
MAX_SAVES = 1_000_000


def _positive_int(field: str, value, most: int = MAX_SAVES) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not 1 <= value <= most:
        raise SweepSpecError(field, f"{format_value(value)} must be an integer in [1, {most}]")
    return int(value)
