"""Sweep results as one labelled `xarray.Dataset` (axes as coordinates), written to results.nc."""

from __future__ import annotations

import functools
import json
import os
import pathlib
from typing import Any

import numpy as np

from .._errors import UserInputError
from ..io import KEY_BY_PATH, atomic_write, optional_import
from ._batch import _ZONE_FIELDS, CI_SUFFIXES, SETTLED_SCALARS, case_inputs, variable_names
from ._spec import SweepSpec
from ._storage import batch_path, load_spec_from_dir, read_batch


# -- the dataset ---------------------------------------------------------------------------------
def design_zone_cases(spec: SweepSpec) -> dict[str, np.ndarray]:
    """Design-zone margins (`jaxbearing.design_zone`) of every case, vmapped, numpy (N,)."""
    import jax

    bearings = [case_inputs(spec, c)[0] for c in range(spec.num_cases)]
    stacked = jax.tree_util.tree_map(lambda *xs: np.stack(xs), *bearings)
    zone = jax.device_get(_zone_batch(stacked))
    out = {f"zone_{f}_m": np.asarray(getattr(zone, f), dtype=np.float64) for f in _ZONE_FIELDS}
    out["zone_feasible"] = np.asarray(zone.feasible, dtype=np.int8)
    return out


@functools.cache
def _zone_fn():
    import jax

    from ..flange import design_zone

    return jax.jit(jax.vmap(design_zone))


def _zone_batch(stacked):
    return _zone_fn()(stacked)


def _unit(name: str) -> str:
    """The unit of a dataset variable from its name (an interval's and a statistic's suffixes,
    `_ci95_low`, `_max`, ..., dropped)."""
    from ..io import unit_of

    for suffix in CI_SUFFIXES:
        name = name.removesuffix(suffix)
    while True:  # drop reductions ("_max", "_p95", "_mean_abs", ...) until a unit shows
        unit = unit_of(name)
        if unit != "1" or "_" not in name:
            return unit
        name = name.rpartition("_")[0]


def provenance_attrs(spec: SweepSpec) -> dict:
    """netCDF attributes (strings and numbers only) saying what produced the dataset: the package
    version, the command line, the base configuration in engineering units (JSON and TOML; the
    swept keys vary along the axes), the seeds (every case runs `Perturbation(seed=k)` for k in
    0 .. seeds-1; a transient sweep seed 0)."""
    from ..io import dumps_strict, provenance

    meta = provenance(spec.base, seeds=list(range(spec.seeds if spec.settled else 1)))
    return {
        "jaxbearing_version": str(meta["jaxbearing_version"]),
        "command": json.dumps(meta["command"]),
        "config": dumps_strict(meta["config"], indent=None),
        "config_toml": meta["config_toml"],
        "seeds": json.dumps(meta["seeds"]),
        "units_convention": "every variable and coordinate has a 'units' attribute ('1': dimensionless)",
    }


def _description(spec: SweepSpec, name: str) -> str:
    """The dataset's description of variable `name`."""
    if not spec.settled:
        return f"summarise()['{name}'] of the case, over its start-up transient"
    for suffix, side in (("_ci95_low", "lower"), ("_ci95_high", "upper")):
        if name.endswith(suffix):
            return f"{side} bound of the 95 % confidence interval of {name[: -len(suffix)]}"
    if name in SETTLED_SCALARS:
        return f"summarise_steady()['{name}'] of the case (settled running)"
    return (
        f"{name}: settled running, per cage revolution, mean over the window "
        f"({spec.seeds} seed(s); interval: {name}_ci95_low/_ci95_high)"
    )


def assemble(out_dir: str | os.PathLike, spec: SweepSpec | None = None):
    """Assemble DIR/results.nc from the batch files (all must exist) and return the Dataset."""
    xr = optional_import("xarray")

    out_dir = pathlib.Path(out_dir)
    spec = spec or load_spec_from_dir(out_dir)
    batches = []
    for b in range(spec.num_batches):
        data = read_batch(out_dir, spec, b)
        if data is None:
            raise UserInputError(
                f"{out_dir}: {batch_path(out_dir, b).name} is missing or "
                "damaged; run the sweep command again to compute it"
            )
        batches.append(data)
    cols = {k: np.concatenate([d[k] for d in batches]) for k in batches[0] if k not in ("spec_hash", "batch")}
    shape = spec.shape
    dims = spec.dims
    data_vars: dict[str, Any] = {}
    for name in variable_names(spec):
        data_vars[name] = (dims, cols[name].reshape(shape), {"description": _description(spec, name)})
    data_vars["status"] = (
        dims,
        cols["status"].astype(str).reshape(shape),
        {"description": '"ok" or the solver failure'},
    )
    data_vars["result_code"] = (
        dims,
        cols["result_code"].astype(np.int32).reshape(shape),
        {"description": "diffrax result code (0 = successful)"},
    )
    data_vars["contact_position"] = (
        dims + ("sample", "end_face_axis"),
        cols["contact_position"].reshape(shape + cols["contact_position"].shape[1:]),
        {
            "units": "m",
            "description": "flange contact points on the roller end face (roller "
            "frame y, z), evenly subsampled over all contact samples; NaN-padded",
        },
    )
    data_vars["contact_position_count"] = (
        dims,
        cols["contact_position_count"].astype(np.int32).reshape(shape),
        {"description": "valid samples"},
    )
    for name, values in design_zone_cases(spec).items():
        data_vars[name] = (
            dims,
            values.reshape(shape),
            {
                "description": "jaxbearing.design_zone of the case (aligned roller, "
                "flange load 100 N); margins > 0 are feasible"
            },
        )
    coords: dict[str, Any] = {}
    for a in spec.axes:
        unit = (KEY_BY_PATH[a.key].unit if a.key in KEY_BY_PATH else "") or "1"
        vals = np.asarray(a.values, dtype=str if a.key == "end" else float)
        coords[a.name] = (a.dim, vals, {"config_key": a.key, "units": unit})
    coords["end_face_axis"] = ("end_face_axis", np.array(["y", "z"]))
    for name, (_, _, attrs) in data_vars.items():
        attrs.setdefault("units", _unit(name))
    ds = xr.Dataset(data_vars, coords=coords)
    ds.attrs.update(provenance_attrs(spec))
    ds.attrs.update(
        spec_hash=spec.hash,
        spec=json.dumps(spec.canonical(), allow_nan=True),
        base_end=spec.base.simulation.end,
        running=spec.running,
        settle=str(spec.settle),
        window_revs=spec.window_revs,
        duration_ms=spec.base.simulation.duration_ms if not spec.settled else np.nan,
        num_saves=spec.num_saves,
        source="jaxbearing sweep",
    )
    path = out_dir / "results.nc"
    atomic_write(path, lambda f: f.write(ds.to_netcdf(None, engine="scipy")))
    return ds


def open_results(out_dir: str | os.PathLike):
    """DIR/results.nc as an xarray Dataset (assembled from the batch files first if missing)."""
    xr = optional_import("xarray")

    path = pathlib.Path(out_dir) / "results.nc"
    if not path.exists():
        return assemble(out_dir)
    try:
        with xr.open_dataset(path, engine="scipy") as ds:
            ds = ds.load()
    except Exception as exc:  # noqa: BLE001 - not a netCDF file of ours: one line naming it
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise UserInputError(f"{path}: not a sweep result file ({reason}); not loaded") from None
    if "spec" not in ds.attrs or "result_code" not in ds:
        raise UserInputError(f"{path}: not a sweep result file (no spec or result_code); not loaded")
    return ds
