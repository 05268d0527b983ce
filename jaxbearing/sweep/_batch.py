"""One batch of sweep cases: stacked inputs, `vmap(solve)` sharded over local devices, per-case summary rows."""

from __future__ import annotations

import dataclasses
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
    "flange_flash_temperature_K",
)
_STATS = ("max", "mean", "median", "min")
#: the time-mean friction power of each flange and in total (summary key, its parts)
_POWER = "flange_friction_power_W"
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


#: per-case float variables of a settled sweep besides the statistics and their intervals
SETTLED_SCALARS = (
    "kinematic_cage_speed_rpm",
    "settled",
    "settle_time_ms",
    "window_ms",
    "seeds",
    "residual_drift_rpm",
    "residual_drift_bound_rpm",
    "num_steps",
)
#: the interval variables of a statistic NAME: NAME_ci95_low, NAME_ci95_high
CI_SUFFIXES = ("_ci95_low", "_ci95_high")


def statistic_names() -> tuple[str, ...]:
    """The settled statistics' dataset names: `run.revolution_statistic_keys` with "." -> "_"
    ("flange_pv_Pa_m_s.max" -> "flange_pv_Pa_m_s_max": the expected largest PV of a cage
    revolution)."""
    from ..run import revolution_statistic_keys

    return tuple(k.replace(".", "_") for k in revolution_statistic_keys())


def variable_names(spec: SweepSpec | None = None) -> tuple[str, ...]:
    """Names of the per-case float variables of the dataset (besides status, result_code,
    contact positions and the design zone): of a start-up transient sweep, or (`spec.settled`)
    of a settled one, every statistic with its interval."""
    if spec is not None and spec.settled:
        stats = statistic_names()
        return SETTLED_SCALARS + stats + tuple(n + c for n in stats for c in CI_SUFFIXES)
    from ..run import FRICTION_POWER_KEYS

    power = tuple(k.replace(".", "_") for k in FRICTION_POWER_KEYS)
    return _SCALARS + tuple(f"{q}_{s}" for q in _EVENT_STATS for s in _STATS) + power


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

        if len(self._devices) == 1 and self._devices[0] == jax.local_devices()[0]:
            # one device (also one process of several, each with one device): the plain vmap,
            # stored by `compiled_program` (traced once per machine)
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
    """Solve the cases `cases`: settled (`settle_batch`) or, with `settle = "off"`, as one
    sharded, vmapped batch of start-up transients; per-case summaries (numpy)."""
    import jax

    if spec.settled:
        return settle_batch(spec, cases, devices)

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
    for part, v in summary[_POWER].items():
        row[f"{_POWER}_{part}"] = np.float64(np.nan if v is None else v)
    if not res.ok:
        for key in row:
            if key not in _KEPT_ON_FAILURE:
                row[key] = np.float64(np.nan)
    row["status"] = np.asarray(res.status)
    row["result_code"] = np.int32(int(sol.result))
    # compact sample of contact positions on the end face (roller frame y, z [m])
    row.update(_position_columns(_positions(res.histories if res.ok else {}, spec.max_positions), spec))
    return row


def _evenly(points: np.ndarray, most: int) -> np.ndarray:
    """At most `most` of `points`, evenly spaced over them."""
    if len(points) > most:
        points = points[np.linspace(0, len(points) - 1, most).round().astype(int)]
    return points


def _positions(histories: dict, max_positions: int) -> np.ndarray:
    """Up to `max_positions` flange contact points on the end face (roller frame y, z [m]),
    evenly subsampled over the contact samples of `histories` (none for empty histories)."""
    if not histories or not len(histories.get("t", ())):
        return np.zeros((0, 2))
    mask = np.asarray(histories["flange_force"]) > CONTACT_THRESHOLD  # (T, Z, 4)
    return _evenly(np.asarray(histories["end_face_position"])[mask], max_positions)  # (K, 2)


def _position_columns(pos: np.ndarray, spec: SweepSpec) -> dict:
    """A case's `contact_position` (NaN-padded to `spec.max_positions`) and its count."""
    points = np.full((spec.max_positions, 2), np.nan)
    points[: len(pos)] = pos
    return {"contact_position": points, "contact_position_count": np.int32(len(pos))}


# -- settled running -----------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class _SweepReduce:
    """What a sweep keeps of a member's settled run (picklable reducer of
    `run.settle_members`): its `window_statistics` and a sample of contact positions; the
    window's histories and states are dropped."""

    max_positions: int

    def __call__(self, run, member):
        from ..run import window_statistics

        if run.status == "ok" and run.window:
            per_rev = window_statistics(
                run.window, run.edges, member.bearing, member.operating, CONTACT_THRESHOLD
            )
            extras = {"positions": _positions(run.window, self.max_positions)}
        else:
            per_rev, extras = None, {"positions": np.zeros((0, 2))}
        return dataclasses.replace(
            run, window={}, per_revolution=per_rev, extras=extras, window_start_state=None, final_state=None
        )


def case_members(spec: SweepSpec, case: int) -> list:
    """The members of case number `case` (`run.Member`): one per seed, with the case's
    tolerances."""
    from ..run import Member, Perturbation

    cfg, end = spec.case_config(case)
    bearing = cfg.bearing()
    if end == "corner":
        bearing = bearing.with_flat_ends()
    op, sim = cfg.operating_point(), cfg.simulation
    return [
        Member(bearing, op, Perturbation(seed=k), rtol=sim.rtol, atol=sim.atol) for k in range(spec.seeds)
    ]


def settle_batch(spec: SweepSpec, cases: Sequence[int], devices: Sequence | None = None) -> dict:
    """Settle and measure the cases `cases` (every seed of each a member of one call of the
    steady-running engine, `run.settle_members`: vmapped over `devices` on an accelerator, one
    member after another on a CPU); per-case rows of statistics with their 95 % intervals."""
    from ..run import settle_members

    members = [m for c in cases for m in case_members(spec, int(c))]
    engine = settle_members(members, spec.steady, devices=devices, reduce=_SweepReduce(spec.max_positions))
    rows = []
    for k, case in enumerate(cases):
        runs = engine.runs[k * spec.seeds : (k + 1) * spec.seeds]
        rows.append(_settled_row(spec, runs, members[k * spec.seeds]))
    out = {"case_index": np.asarray(cases, dtype=np.int64)}
    for key in rows[0]:
        out[key] = np.stack([r[key] for r in rows])
    return out


def _settled_row(spec: SweepSpec, runs, member) -> dict:
    from ..run import Estimate, SteadyResult, revolution_statistic_keys, summarise_steady

    steady = spec.steady
    result = SteadyResult(
        runs=list(runs),
        settings=steady,
        settle_mode=steady.settle.mode,
        start=spec.start,
        wall_time_s=float("nan"),
        compile_time_s=float("nan"),
        bearing=member.bearing,
        operating=member.operating,
    )
    stats = result.statistics(CONTACT_THRESHOLD)
    block = summarise_steady(result, threshold=CONTACT_THRESHOLD, statistics=stats)
    estimates = {} if stats is None else stats.estimates()
    nothing = Estimate(np.nan, np.nan, np.nan, 0)

    def num(v):
        return np.float64(np.nan if v is None else v)

    row: dict[str, Any] = {
        "kinematic_cage_speed_rpm": num(block["kinematic_cage_speed_rpm"]),
        "settled": np.float64(block["settled"]),
        "settle_time_ms": num(block["settle_time_ms"]),
        "window_ms": num(block["window_ms"]),
        "seeds": np.float64(len(runs)),
        "residual_drift_rpm": num(block.get("residual_drift_rpm")),
        "residual_drift_bound_rpm": num(block.get("residual_drift_bound_rpm")),
        "num_steps": np.float64(block["num_steps"]),
    }
    for key in revolution_statistic_keys():
        est = estimates.get(key, nothing)
        name = key.replace(".", "_")
        row[name] = np.float64(est.value)
        row[name + "_ci95_low"] = np.float64(est.ci95_low)
        row[name + "_ci95_high"] = np.float64(est.ci95_high)
    row["status"] = np.asarray(result.status)
    row["result_code"] = np.int32(0 if result.ok else 1)
    pos = np.concatenate([r.extras.get("positions", np.zeros((0, 2))) for r in runs])
    row.update(_position_columns(_evenly(pos, spec.max_positions), spec))
    return row
