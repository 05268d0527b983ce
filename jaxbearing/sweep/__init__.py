"""Parameter sweeps at scale: spec, batched and sharded execution, storage, dataset, plots.

- the spec (TOML in engineering units): `SweepSpec`, `Axis`, `SweepSpecError`,
  `load_sweep_spec`, `loads_sweep_spec`, `build_spec`;
- execution: `run_sweep` (batches of `jax.vmap(solve)` under `shard_map`, resumable),
  `solve_batch`, `batch_runner`, `stack_cases`; processes and machines:
  `initialize_distributed`;
- storage: one atomic file per finished batch (`computed_batches`, `missing_batches`); batches
  that cannot be written into DIR go to a fallback directory (`ResultsElsewhere`);
- results: `assemble` / `open_results` (one `xarray.Dataset`), `plot_sweep` (Figures 9-13).

May import: every layer below (`run` and down).
"""

from ._batch import CONTACT_THRESHOLD, batch_runner, padded_size, solve_batch, stack_cases, variable_names
from ._dataset import assemble, open_results
from ._distributed import initialize_distributed
from ._driver import ResultsElsewhere, assigned_batches, missing_batches, run_sweep
from ._parse import build_spec, load_sweep_spec, loads_sweep_spec, validate_cases
from ._plots import coordinate_for, plot_sweep
from ._spec import FORMAT_VERSION, Axis, SweepSpec, SweepSpecError
from ._storage import batch_path, computed_batches, load_spec_from_dir, read_batch, write_batch

__all__ = [
    "CONTACT_THRESHOLD",
    "FORMAT_VERSION",
    "ResultsElsewhere",
    "Axis",
    "SweepSpec",
    "SweepSpecError",
    "assemble",
    "assigned_batches",
    "batch_path",
    "batch_runner",
    "build_spec",
    "computed_batches",
    "coordinate_for",
    "initialize_distributed",
    "load_spec_from_dir",
    "load_sweep_spec",
    "loads_sweep_spec",
    "missing_batches",
    "open_results",
    "padded_size",
    "plot_sweep",
    "read_batch",
    "run_sweep",
    "solve_batch",
    "stack_cases",
    "validate_cases",
    "variable_names",
    "write_batch",
]
