"""The steady-running engine's throughput: settled members per hour at equal confidence
intervals, by strategy, measured in one run (issue 34, item 7).

Members: the reference bearing at 11 raceway slices (reduced size), 1000 N, `speeds` x
`seeds` (full: 2 speeds x 2 seeds; quick: 1 x 2), each from the skid start until the settling
verdict (tolerance 2e-3), then `window_revs` cage revolutions (full 4, quick 2). Every strategy
runs the same members with the same settings, so the intervals of what users read are equal by
construction (the table shows them: cage speed and expected largest PV per revolution, Student-t
over the seeds):

1. **per-case loop** (the baseline; what `simulate_steady` did before the engine): the members
   one after another in this process (`strategy="sequential"`);
2. **engine on a CPU** (its default there): one process per core, `workers = 2`
   (`strategy="processes"`);
3. **engine vmapped** (its default on an accelerator; here on the CPU for the record): every
   member's request of a round in one `vmap(solve_from)` (`strategy="vmap"`).

Members per hour = members / wall time without compilation (each strategy's compilation,
or loading from the persistent cache, is reported beside it). Ratios are against (1), measured in
the same run. On an accelerator (`jax.default_backend() != "cpu"`), the vmapped engine is also
timed against the batch size (`--batch-sizes 1,8,64,512,4096`; members = seeds of the reference
case; `--batch-sizes none` skips them), members per second per size, and one iteration of the 3-speed design search is timed
(`--search-iteration`: `optimise`'s `evaluate_starts`, 2 starts x 3 speeds (10,000, 20,000
and 30,000 rpm) x 4 seeds settled as one engine call, then the frozen-load gradients of their
48 trajectories as one vmapped program; twice: the first call compiles, the second continues
from the first's states as the search's next iteration does).

`--accelerator-only` skips the CPU strategies (on an accelerator, batch size 1 is the per-case
loop's baseline); `--results-dir DIR` writes the JSON there, after every batch size.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common  # noqa: E402

NAME = "bench_steady_engine"
FULL_TIMEOUT_S = 1800


def _members(speeds, seeds):
    import jaxbearing as jb
    from jaxbearing.run import Member

    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    op = jb.reference_operating_point()
    return [
        Member(bearing, dataclasses.replace(op, inner_speed=jb.rpm_to_rad_s(v)), jb.Perturbation(seed=k))
        for v in speeds
        for k in range(seeds)
    ]


def _intervals(engine, members, seeds):
    """Per speed: cage speed and expected largest PV per revolution, value and 95 % half-width."""
    import jaxbearing as jb

    out = []
    for i in range(0, len(members), seeds):
        runs = engine.runs[i : i + seeds]
        m = members[i]
        settings = jb.run.SteadySettings(window_revs=runs[0].edges.size - 1, tolerance=2e-3)
        block = jb.summarise_steady(
            jb.SteadyResult(runs, settings, "auto", "skid", 0.0, 0.0, m.bearing, m.operating)
        )
        row = {"speed_rpm": round(float(jb.rad_s_to_rpm(m.operating.inner_speed)))}
        for key, est in (
            ("cage_speed_rpm", block["cage_speed_rpm"]),
            ("pv_max_GPa_m_s", block["flange_pv_Pa_m_s"]["max"]),
        ):
            k = 1e-9 if key.startswith("pv") else 1.0
            half = 0.5 * (est["ci95_high"] - est["ci95_low"]) if est["ci95_low"] is not None else float("nan")
            row[key] = round(est["value"] * k, 4)
            row[key + "_half_width"] = round(half * k, 4)
        row["settled"] = all(r.settled for r in runs)
        out.append(row)
    return out


def main(
    quick: bool = False,
    batch_sizes: str | None = None,
    accelerator_only: bool = False,
    search_iteration: bool = False,
    results_dir: str | None = None,
) -> dict:
    import jax

    from jaxbearing.run import SteadySettings

    started = time.perf_counter()
    speeds = [20000.0] if quick else [15000.0, 20000.0]
    seeds = 2
    options = SteadySettings(window_revs=2 if quick else 4, tolerance=2e-3)
    data = {
        "machine": _common.machine_info(),
        "backend": jax.default_backend(),
        "quick": quick,
        "speeds_rpm": speeds,
        "seeds": seeds,
        "window_revs": options.window_revs,
        "num_slices": 11,
    }
    name = NAME if not quick else NAME + "_quick"
    if not accelerator_only:
        data.update(_strategies(options, speeds, seeds))
    if jax.default_backend() != "cpu" and batch_sizes != "none":
        sizes = [int(v) for v in (batch_sizes or "1,8,64,512,4096").split(",")]
        data["accelerator_batch_sizes"] = []
        for row in _batch_sizes(options, sizes):
            data["accelerator_batch_sizes"].append(row)
            _common.write_json(name, data, results_dir)
    if search_iteration:
        data["search_iteration"] = _search_iteration()
    data["wall_s"] = time.perf_counter() - started
    _common.write_json(name, data, results_dir)
    return data


def _strategies(options, speeds, seeds) -> dict:
    """The three strategies on the same members, in this run (module docstring)."""
    import jax

    from jaxbearing.run import settle_members

    members = _members(speeds, seeds)
    # the worker processes import jaxbearing from this checkout
    os.environ["PYTHONPATH"] = os.pathsep.join(
        [str(Path(__file__).resolve().parents[1]), os.environ.get("PYTHONPATH", "")]
    ).rstrip(os.pathsep)
    results, rows = {}, []
    for label, strategy, workers in (
        ("per-case loop (baseline)", "sequential", 1),
        ("engine, one process per core", "processes", 2),
        ("engine, vmapped members", "vmap", 1),
    ):
        _common.log(f"{NAME}: {label}: {len(members)} members")
        t0 = time.perf_counter()
        engine = settle_members(members, options.replace(strategy=strategy, workers=workers))
        end_to_end = time.perf_counter() - t0
        per_hour = len(members) / engine.wall_time_s * 3600
        results[strategy] = {
            "label": label,
            "members": len(members),
            "wall_s": engine.wall_time_s,
            "compile_s": engine.compile_time_s,
            "end_to_end_s": end_to_end,
            "members_per_hour": per_hour,
            "settled": all(r.settled for r in engine.runs),
            "num_steps": [r.num_steps for r in engine.runs],
            "intervals": _intervals(engine, members, seeds),
            "batch_times": dataclasses.asdict(engine.batch_times) if engine.batch_times else None,
        }
    base = results["sequential"]["members_per_hour"]
    for strategy, r in results.items():
        r["ratio_to_baseline"] = r["members_per_hour"] / base
        iv = r["intervals"][-1]
        rows.append(
            [
                r["label"],
                f"{r['members_per_hour']:.0f}",
                f"{r['ratio_to_baseline']:.2f}x",
                f"{r['wall_s']:.1f}",
                f"{r['compile_s']:.1f}",
                f"{iv['cage_speed_rpm']:.1f} +- {iv['cage_speed_rpm_half_width']:.1f}",
                f"{iv['pv_max_GPa_m_s']:.3g} +- {iv['pv_max_GPa_m_s_half_width']:.2g}",
            ]
        )
    table = _common.format_table(
        f"Settled members per hour, {len(members)} members (11 slices, {options.window_revs}-revolution window, "
        f"{seeds} seeds per speed), {jax.default_backend()}",
        [
            "strategy",
            "members/h",
            "vs loop",
            "wall [s]",
            "compile [s]",
            "cage rpm (last speed)",
            "PV max GPa m/s",
        ],
        rows,
    )
    print(table)
    return {"strategies": results, "table": table}


def _batch_sizes(options, sizes):
    """Members per second of the vmapped engine against the batch size (accelerators only),
    one row per size as it finishes."""
    from jaxbearing.run import settle_members

    for n in sizes:
        members = _members([20000.0], n)
        _common.log(f"{NAME}: vmapped batch of {n}")
        engine = settle_members(members, options.replace(strategy="vmap"))
        row = {
            "batch_size": n,
            "wall_s": engine.wall_time_s,
            "compile_s": engine.compile_time_s,
            "members_per_s": n / engine.wall_time_s,
            "members_per_hour": n / engine.wall_time_s * 3600,
            "settled_share": sum(r.settled for r in engine.runs) / n,
            "batch_times": dataclasses.asdict(engine.batch_times),
            "intervals": _intervals(engine, members, n),
        }
        print(row, flush=True)
        yield row


def _search_iteration() -> dict:
    """One iteration of the 3-speed design search, twice (module docstring)."""
    import jaxbearing as jb
    from optimise import SteadySettings, make_problem, start_points
    from optimise._evaluate import evaluate_starts

    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    problem = make_problem(bearing, jb.reference_operating_point(), speeds_rpm=[10000.0, 20000.0, 30000.0])
    settings = SteadySettings(seeds=4, window_revs=2)
    us = list(start_points(problem, 2))
    out, chains = {"starts": 2, "speeds_rpm": [10000, 20000, 30000], "seeds": 4, "calls": []}, [None, None]
    for call in ("first (compiles)", "second (continuation)"):
        _common.log(f"{NAME}: search iteration, {call}")
        t0 = time.perf_counter()
        evaluations = evaluate_starts(problem, settings, us, chains)
        wall = time.perf_counter() - t0
        chains = [ev.states for ev in evaluations]
        row = {
            "call": call,
            "wall_s": wall,
            "objective_GPa_m_s": [ev.objective for ev in evaluations],
            "gradient": [ev.gradient.tolist() for ev in evaluations],
            "simulated_ms": sum(ev.simulated_ms for ev in evaluations),
        }
        print(row, flush=True)
        out["calls"].append(row)
    return out


if __name__ == "__main__":
    main(
        quick="--quick" in sys.argv,
        batch_sizes=_common.option_value(sys.argv, "--batch-sizes"),
        accelerator_only="--accelerator-only" in sys.argv,
        search_iteration="--search-iteration" in sys.argv,
        results_dir=_common.option_value(sys.argv, "--results-dir"),
    )
