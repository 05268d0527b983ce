"""One batch of sweep cases: stacked inputs, `vmap(solve)` sharded over local devices, per-case summary rows."""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import numpy as np

from ._spec import SweepSpec

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


def variable_names() -> tuple[str, ...]:
    """Names of the per-case float variables of the dataset (besides status, result_code,
    contact positions and the design zone)."""
    return _SCALARS + tuple(f"{q}_{s}" for q in _EVENT_STATS for s in _STATS)


# -- batched solve -------------------------------------------------------------------------------
def case_inputs(spec: SweepSpec, case: int):
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
class BatchRunner:
    """The compiled batch of `batch_runner`: `runner(*stacked)` solves the cases,
    `runner.compile(*stacked)` returns the compiled program alone (for timing)."""

    def __init__(self, one, num_saves: int, max_steps: int, devices: tuple):
        self._one, self._static, self._devices = one, (num_saves, max_steps), devices

    def compile(self, *stacked):
        import jax

        from ..run import compiled_program

        if len(self._devices) == 1 and jax.process_count() == 1 and self._devices[0] == jax.devices()[0]:
            # one device: the plain vmap, stored by `compiled_program` (traced once per machine)
            return compiled_program("sweep_batch", jax.vmap(self._one), stacked, self._static)
        from jax.sharding import Mesh, PartitionSpec

        mesh = Mesh(np.asarray(self._devices), ("cases",))
        spec = PartitionSpec("cases")
        sharded = jax.shard_map(
            jax.vmap(self._one), mesh=mesh, in_specs=(spec,) * 5, out_specs=spec, check_vma=False
        )
        return jax.jit(sharded).lower(*stacked).compile()

    def __call__(self, *stacked):
        return self.compile(*stacked)(*stacked)


def batch_runner(num_saves: int, max_steps: int, devices: tuple) -> BatchRunner:
    """`vmap(solve)` of stacked (bearing, op, duration, rtol, atol) whose leading axis is a
    multiple of len(devices): on one device the vmap itself (`compiled_program`: once per
    process, traced once per machine), on several a `jax.shard_map` over a 1-D mesh of `devices`
    (axis "cases"), each device integrating its slice of the batch."""
    from ..run import solve

    def one(bearing, op, duration, rtol, atol):
        return solve(
            bearing,
            op,
            duration,
            num_saves=num_saves,
            rtol=rtol,
            atol=atol,
            max_steps=max_steps,
            progress=False,
        )

    return BatchRunner(one, num_saves, max_steps, tuple(devices))


def padded_size(batch_size: int, num_devices: int) -> int:
    """Batch size rounded up to a multiple of the device count."""
    return -(-batch_size // num_devices) * num_devices


def solve_batch(spec: SweepSpec, cases: Sequence[int], devices: Sequence | None = None) -> dict:
    """Solve the cases `cases` as one sharded, vmapped batch; per-case summaries (numpy)."""
    import jax

    devices = tuple(jax.local_devices() if devices is None else devices)
    size = padded_size(spec.batch_size, len(devices))
    inputs = [case_inputs(spec, int(c)) for c in cases]
    inputs += [inputs[-1]] * (size - len(inputs))  # pad with copies of the last case
    stacked = jax.tree_util.tree_map(lambda *xs: np.stack(xs), *inputs)
    runner = batch_runner(spec.num_saves, spec.base.simulation.max_steps, devices)
    sol = jax.device_get(runner(*stacked))
    rows = [
        _summarise_case(spec, jax.tree_util.tree_map(lambda a: a[i], sol), inputs[i])
        for i in range(len(cases))
    ]
    out = {"case_index": np.asarray(cases, dtype=np.int64)}
    for key in rows[0]:
        out[key] = np.stack([r[key] for r in rows])
    return out


def _summarise_case(spec: SweepSpec, sol, inputs) -> dict:
    from ..dynamics import Functionals
    from ..run import simulation_result, summarise

    bearing, op, duration, _, _ = inputs
    res = simulation_result(sol, bearing, op, Functionals(), float(duration), float("nan"), float("nan"))
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
