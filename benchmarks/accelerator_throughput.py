"""Sweeps and settled ensembles on an accelerator (GPU), against the CPU of the same machine in
the same run.

Two parts (`--part sweep`, `--part ensemble`, or both):

1. **Sweep throughput.** The sweep's own batch (`jaxbearing.sweep.batch_runner`: `vmap(solve)`
   of the reference bearing, speeds spread over 15,000-25,000 rpm, from the quasi-static start,
   `bench_throughput.measure`) for batch sizes `--sizes` on the accelerator and `--cpu-sizes` on
   the host CPU (one XLA CPU device, the process's default threads), each over `--duration-ms`.
   Compile time is timed apart; the best of `--repeats` runs counts. The ratio is cases per
   second on the accelerator over cases per second of one case at a time on the CPU.
   Agreement: the batch of `AGREEMENT_BATCH` cases is solved on both over `AGREEMENT_MS` (before
   the trajectories of two roundings part) and the largest relative difference of every output
   history is reported.
2. **Settled ensemble.** From the settled states of seeds 0-3 (`bench_work_precision_settled.
   settled_start`: `simulate_steady`'s final state, read from that benchmark's cache), `--members`
   copies per seed, copy k > 0 with every roller moved axially by a uniform +-1 nm (numpy seed
   k), integrate the settled benchmark's window (2 cage revolutions, samples every 2 us) with
   the default integrator (Tsit5, rtol 1e-3, atol 1e-6, raceway-normal tolerances x100;
   `bench_work_precision_settled.window_solve`) as one vmapped program. The flange statistics of
   each member (`bench_work_precision.window_statistics`: mean and p95 PV, mean sliding speed
   over samples above 1 N; cage slip) are averaged per seed, and the ensemble mean with its
   95 % Student-t interval is taken over the 4 seeds (the copies of one seed share their first
   millisecond, so only the seeds are independent); it is compared with the tight CPU reference
   of `results/bench_work_precision_settled.json`, paired by seed as that benchmark compares
   its integrators (`paired_over_seeds`: the difference's interval contains 0 and the mean
   difference is under the reference's half-width). The same window of seed 0 is run once on
   the host CPU for the throughput ratio.

3. **Steady gradient samples** (`--part gradient`). The short-window gradient estimator
   (`jaxbearing.design.steady_gradient`, `optimise --estimator window`; the search's default is the
   frozen-load estimator, which does not differentiate the trajectory) integrates, from each settled state, a short window
   (`GRADIENT_WINDOW`, 1 ms) with three forward-mode tangents in (R_end, theta_f, Delta_bf)
   (`window_integrals` under `forward_jacobian`, as its per-sample program does), one process
   per core. Here the same copies of the 4 settled states (`--members` per seed) run as one
   vmapped program on the accelerator, and the samples are combined by the estimator's own
   ratio and jackknife (`_combine`); seed 0's state runs once on the host CPU, for the
   throughput ratio and for the difference of its (A, C) integrals and their Jacobian from
   the accelerator's member 0 (the same state).

    python benchmarks/accelerator_throughput.py [--part sweep|ensemble|gradient|all]
        [--sizes 1,8,64,512,4096] [--cpu-sizes 1,8] [--duration-ms 1] [--members 64]
        [--repeats 2] [--output PATH]

writes `results/accelerator_throughput.json` (or PATH) and prints a table. The committed results
came from `--part sweep --output benchmarks/results/accelerator_sweep.json` and `--part ensemble
--members 128 --output benchmarks/results/accelerator_ensemble.json` and `--part gradient
--members 128 --output benchmarks/results/accelerator_gradient.json` on an H100 (docs/performance.md, On a
GPU). Without an accelerator it stops with one line. It is not a `bench_*.py`, so `make bench`
(which runs where CI runs, on CPUs) does not run it.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common  # noqa: E402

NAME = "accelerator_throughput"
AGREEMENT_BATCH = 8
AGREEMENT_MS = 0.2
SEEDS = (0, 1, 2, 3)
#: axial displacement of the copies of a settled state [m] (uniform +- this, per roller)
COPY_NUDGE = 1e-9
ENSEMBLE_RTOL, ENSEMBLE_ATOL, ENSEMBLE_LOOSEN = 1e-3, 1e-6, 100.0
STATS = ("mean_pv", "p95_pv", "mean_sliding_speed", "cage_slip")


class UsageError(ValueError):
    """A command-line argument out of its range (printed as one usage line, exit 2)."""


def _sizes(text: str, name: str) -> tuple[int, ...]:
    try:
        sizes = tuple(int(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise UsageError(f"{name} must be comma-separated positive integers, got {text!r}") from None
    if not sizes or min(sizes) < 1:
        raise UsageError(f"{name} must be comma-separated positive integers, got {text!r}")
    return sizes


def accelerator():
    """The first non-CPU device, or None (`JAXBEARING_BENCH_GPU_ON_CPU=1`: the CPU itself, to
    try this script on a machine without one)."""
    import os

    import jax

    if os.environ.get("JAXBEARING_BENCH_GPU_ON_CPU") == "1":
        return jax.devices("cpu")[0]
    for backend in ("gpu", "tpu"):
        try:
            return jax.devices(backend)[0]
        except RuntimeError:
            continue
    return None


# -- sweep -------------------------------------------------------------------------------------
def _solve_batch(batch: int, duration: float, device):
    import jax
    from bench_throughput import _inputs

    from jaxbearing.sweep import batch_runner

    runner = batch_runner(50, 100_000, (device,))
    return jax.device_get(runner(*_inputs(batch, duration)))


def agreement(gpu, cpu) -> dict:
    """Largest relative difference, accelerator against CPU, of every history of one batch of
    `AGREEMENT_BATCH` cases over `AGREEMENT_MS` (max |a - c| / max |c| per history)."""
    import numpy as np

    a = _solve_batch(AGREEMENT_BATCH, AGREEMENT_MS * 1e-3, gpu)
    c = _solve_batch(AGREEMENT_BATCH, AGREEMENT_MS * 1e-3, cpu)
    out = {}
    for key in sorted(c.histories):
        x, y = np.asarray(a.histories[key], float), np.asarray(c.histories[key], float)
        scale = float(np.max(np.abs(y)))
        out[key] = float(np.max(np.abs(x - y)) / scale) if scale > 0 else float(np.max(np.abs(x)))
    steps = (np.asarray(a.num_steps).tolist(), np.asarray(c.num_steps).tolist())
    return {
        "batch": AGREEMENT_BATCH,
        "simulated_ms": AGREEMENT_MS,
        "max_relative_difference": out,
        "worst": max(out.values()),
        "steps_accelerator": steps[0],
        "steps_cpu": steps[1],
    }


def sweep_part(sizes, cpu_sizes, duration: float, repeats: int) -> dict:
    import jax
    from bench_throughput import measure

    gpu, cpu = accelerator(), jax.devices("cpu")[0]
    rows = []
    for device, batch_sizes in ((cpu, cpu_sizes), (gpu, sizes)):
        for n in batch_sizes:
            row = measure(n, duration, repeats=repeats, devices=(device,))
            rows.append(row)
            _common.log(
                f"{NAME}: {device.platform} batch {n}: {row['cases_per_s']:.3f} cases/s, "
                f"wall {row['wall_s']:.3f} s, compile {row['compile_s']:.1f} s"
            )
    base = next(r for r in rows if r["platform"] == "cpu" and r["batch_size"] == 1)
    for r in rows:
        r["throughput_vs_one_cpu_case"] = round(r["cases_per_s"] / base["cases_per_s"], 3)
    agree = agreement(gpu, cpu)
    _common.log(
        f"{NAME}: accelerator vs CPU over {AGREEMENT_MS} ms: worst relative difference {agree['worst']:.2e}"
    )
    return {"duration_ms": duration * 1e3, "repeats": repeats, "rows": rows, "agreement": agree}


# -- settled ensemble ----------------------------------------------------------------------------
def _copies(state, members: int):
    """`members` copies of one settled state; copy k > 0 with every roller's axial position
    moved by a uniform +-COPY_NUDGE (numpy seed k)."""
    import dataclasses

    import jax
    import numpy as np

    out = []
    for k in range(members):
        axial = np.asarray(state.rollers.axial)
        if k > 0:
            axial = axial + np.random.default_rng(k).uniform(-COPY_NUDGE, COPY_NUDGE, axial.shape)
        out.append(dataclasses.replace(state, rollers=dataclasses.replace(state.rollers, axial=axial)))
    return jax.tree_util.tree_map(lambda *xs: np.stack([np.asarray(x) for x in xs]), *out)


def _settled_copies(bearing, op, members: int):
    """(settled starts of `SEEDS` from `bench_work_precision_settled.settled_start`, their
    `members` copies each stacked seed after seed along one leading axis)."""
    import jax
    import numpy as np
    from bench_work_precision_settled import settled_start

    settled = {s: settled_start(bearing, op, s) for s in SEEDS}
    copies = [_copies(settled[s]["state"], members) for s in SEEDS]
    return settled, jax.tree_util.tree_map(lambda *xs: np.concatenate(xs), *copies)


def _compile_and_run(fn, *args):
    """(outputs on the host, compile s, run s) of `jax.jit(fn)` on `args` (placed on a device:
    the program runs there)."""
    import jax

    t0 = time.perf_counter()
    compiled = jax.jit(fn).lower(*args).compile()
    compile_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    out = jax.device_get(jax.block_until_ready(compiled(*args)))
    return out, compile_s, time.perf_counter() - t0


def ensemble_part(members: int) -> dict:
    import json

    import jax
    import jax.numpy as jnp
    import numpy as np
    from bench_work_precision import SAMPLE_DT, window_statistics
    from bench_work_precision_settled import paired_over_seeds, window_solve

    import jaxbearing as jb
    from jaxbearing.dynamics import Functionals, Params
    from jaxbearing.run import student_t_interval

    gpu, cpu = accelerator(), jax.devices("cpu")[0]
    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    params = Params(bearing=bearing, operating=op, functionals=Functionals())
    omega_kin = float(jb.kinematic_cage_speed(bearing, op))
    settled, stacked = _settled_copies(bearing, op, members)
    rpm = float(np.mean([v["info"]["last_revolution_cage_speed_rpm"] for v in settled.values()]))
    num_saves = int(round(2 * 60.0 / rpm / SAMPLE_DT)) + 1
    window = (num_saves - 1) * SAMPLE_DT
    f = jnp.asarray

    def one(p, s):
        hist, code, steps, rejected = window_solve(
            p, s, f(window), f(ENSEMBLE_RTOL), f(ENSEMBLE_ATOL), f(ENSEMBLE_LOOSEN), num_saves=num_saves
        )
        return hist, code, steps

    (hist, code, steps), compile_gpu, wall_gpu = _compile_and_run(
        jax.vmap(one, in_axes=(None, 0)), *jax.device_put((params, stacked), gpu)
    )
    _common.log(
        f"{NAME}: ensemble of {len(SEEDS) * members} in {wall_gpu:.1f} s (compile {compile_gpu:.1f} s)"
    )
    first = jax.tree_util.tree_map(lambda x: x[0], stacked)
    (hist_cpu, code_cpu, steps_cpu), compile_cpu, wall_cpu = _compile_and_run(
        one, *jax.device_put((params, first), cpu)
    )
    _common.log(f"{NAME}: one window on the CPU in {wall_cpu:.1f} s")

    n = len(SEEDS) * members
    per_member = [window_statistics({k: v[i] for k, v in hist.items()}, 0.0, omega_kin) for i in range(n)]
    ok = np.asarray(code) == 0
    per_seed = {
        s: {q: float(np.nanmean([per_member[j * members + k][q] for k in range(members)])) for q in STATS}
        for j, s in enumerate(SEEDS)
    }
    reference = json.loads((_common.RESULTS_DIR / "bench_work_precision_settled.json").read_text())
    comparison = {}
    for q in STATS:
        values = np.array([per_seed[s][q] for s in SEEDS])
        ref_values = np.array([reference["reference"][str(s)]["statistics"][q] for s in SEEDS])
        comparison[q] = {
            "ensemble": student_t_interval(values).as_dict(),
            "ensemble_members": student_t_interval(np.array([m[q] for m in per_member])).as_dict(),
            **paired_over_seeds(values, ref_values),
        }
    cpu_stats = window_statistics(hist_cpu, 0.0, omega_kin)
    throughput = {
        "accelerator_member_windows_per_s": n / wall_gpu,
        "cpu_member_windows_per_s": 1.0 / wall_cpu,
    }
    throughput["ratio"] = (
        throughput["accelerator_member_windows_per_s"] / throughput["cpu_member_windows_per_s"]
    )
    return {
        "seeds": list(SEEDS),
        "members_per_seed": members,
        "window_ms": window * 1e3,
        "num_saves": num_saves,
        "integrator": {"rtol": ENSEMBLE_RTOL, "atol": ENSEMBLE_ATOL, "raceway_loosen": ENSEMBLE_LOOSEN},
        "members_ok": int(ok.sum()),
        "max_steps_accelerator": int(np.max(steps)),
        "mean_steps_accelerator": float(np.mean(steps)),
        "steps_cpu_seed0": int(steps_cpu),
        "cpu_seed0_ok": int(code_cpu) == 0,
        "compile_s": {"accelerator_batch": compile_gpu, "cpu_one": compile_cpu},
        "wall_s": {"accelerator_batch": wall_gpu, "cpu_one": wall_cpu},
        "throughput": throughput,
        "per_seed": {str(s): v for s, v in per_seed.items()},
        "cpu_seed0_member0": cpu_stats,
        "accelerator_seed0_member0": per_member[0],
        "comparison": comparison,
    }


# -- steady gradient samples ---------------------------------------------------------------------
def gradient_part(members: int) -> dict:
    import diffrax
    import jax
    import jax.numpy as jnp
    import numpy as np

    import jaxbearing as jb
    from jaxbearing.design import GRADIENT_WINDOW, forward_jacobian
    from jaxbearing.design._steady_objective import _combine
    from jaxbearing.design._window_gradient import window_integrals
    from jaxbearing.flange import DesignVariables

    gpu, cpu = accelerator(), jax.devices("cpu")[0]
    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    x = jnp.asarray(DesignVariables.of(bearing).as_array(), float)
    _, stacked = _settled_copies(bearing, op, members)
    window = GRADIENT_WINDOW

    def one(b, o, start, v):
        def f(w):
            return window_integrals(
                b, o, start, w, window, rtol=1e-3, atol=1e-6, max_steps=200_000, adjoint=diffrax.ForwardMode()
            )

        return forward_jacobian(f, v)

    args_gpu = jax.device_put((bearing, op, stacked, x), gpu)
    (vals, jacs), compile_gpu, wall_gpu = _compile_and_run(
        jax.vmap(one, in_axes=(None, None, 0, None)), *args_gpu
    )
    n = len(SEEDS) * members
    _common.log(
        f"{NAME}: {n} gradient samples on the accelerator in {wall_gpu:.1f} s (compile {compile_gpu:.1f} s)"
    )
    first = jax.tree_util.tree_map(lambda a: a[0], stacked)
    (val_cpu, jac_cpu), compile_cpu, wall_cpu = _compile_and_run(
        one, *jax.device_put((bearing, op, first, x), cpu)
    )
    _common.log(f"{NAME}: one gradient sample on the CPU in {wall_cpu:.1f} s (compile {compile_cpu:.1f} s)")

    vals, jacs = np.asarray(vals), np.asarray(jacs)  # (n, 3), (n, 3 variables, 3 outputs)
    # as `steady_gradient` combines them: a failed sample's integrals are NaN (left out)
    samples = [(v[:2] if v[2] > 0.5 else np.full(2, np.nan), j[:, :2]) for v, j in zip(vals, jacs)]
    est = _combine(samples, window)
    per_seed = [_combine(samples[k * members : (k + 1) * members], window) for k in range(len(SEEDS))]

    def rel(a, b):
        a, b = np.asarray(a, float), np.asarray(b, float)
        return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))

    return {
        "seeds": list(SEEDS),
        "members_per_seed": members,
        "window_ms": window * 1e3,
        "samples_ok": int(np.sum(vals[:, 2] > 0.5)),
        "compile_s": {"accelerator_batch": compile_gpu, "cpu_one": compile_cpu},
        "wall_s": {"accelerator_batch": wall_gpu, "cpu_one": wall_cpu},
        "throughput": {
            "accelerator_samples_per_s": n / wall_gpu,
            "cpu_samples_per_s": 1.0 / wall_cpu,
            "ratio": n * wall_cpu / wall_gpu,
        },
        "estimate": {
            "value_Pa_m_s": est.value,
            "value_stderr": est.value_stderr,
            "gradient": est.gradient,
            "gradient_stderr": est.gradient_stderr,
            "num_samples": est.num_samples,
        },
        "per_seed_gradient": [e.gradient for e in per_seed],
        "cpu_vs_accelerator_member0": {
            "integrals_relative_difference": rel(vals[0, :2], np.asarray(val_cpu)[:2]),
            "jacobian_relative_difference": rel(jacs[0, :, :2], np.asarray(jac_cpu)[:, :2]),
        },
    }


# -- table -------------------------------------------------------------------------------------
def _table(result: dict) -> str:
    lines = []
    if "sweep" in result:
        sw = result["sweep"]
        keys = ("platform", "batch_size", "compile_s", "wall_s", "cases_per_s", "simulated_ms_per_s")
        keys += ("throughput_vs_one_cpu_case", "max_steps_taken", "cases_ok")
        header = (
            "device",
            "batch",
            "compile s",
            "wall s",
            "cases/s",
            "sim ms/s",
            "x one CPU case",
            "steps",
            "ok",
        )
        lines.append(
            _common.format_table(
                f"sweep batch, {sw['duration_ms']:g} ms per case from the quasi-static start ({result['device']})",
                header,
                [tuple(r[k] for k in keys) for r in sw["rows"]],
            )
        )
        lines.append(
            f"accelerator vs CPU, {AGREEMENT_BATCH} cases over {AGREEMENT_MS} ms: worst relative "
            f"difference of a history {sw['agreement']['worst']:.2e}"
        )
    if "ensemble" in result:
        en = result["ensemble"]
        lines.append(
            f"settled ensemble: {len(en['seeds'])} seeds x {en['members_per_seed']} members, window "
            f"{en['window_ms']:.2f} ms; accelerator {en['wall_s']['accelerator_batch']:.1f} s for the batch "
            f"({en['members_ok']} ok), CPU {en['wall_s']['cpu_one']:.1f} s for one window: "
            f"{en['throughput']['ratio']:.1f}x the CPU's windows per second"
        )
        rows = []
        for q in STATS:
            c = en["comparison"][q]
            e, r, d = c["ensemble"], c["reference"], c["difference"]
            rows.append(
                (q, e["value"], e["ci95_high"] - e["value"], r["value"], r["half_width"])
                + (d["value"], d["half_width"], c["agrees"])
            )
        header = (
            "statistic",
            "ensemble",
            "+-95%",
            "CPU reference",
            "+-95%",
            "paired diff",
            "+-95%",
            "agrees",
        )
        lines.append(
            _common.format_table(
                "settled statistics: accelerator ensemble (mean over seeds of the members' mean) vs the CPU tight reference",
                header,
                rows,
            )
        )
    if "gradient" in result:
        gr = result["gradient"]
        e = gr["estimate"]
        lines.append(
            f"steady gradient samples: {len(gr['seeds'])} seeds x {gr['members_per_seed']} members, window "
            f"{gr['window_ms']:g} ms, 3 forward-mode tangents; accelerator {gr['wall_s']['accelerator_batch']:.1f} s "
            f"for the batch ({gr['samples_ok']} ok), CPU {gr['wall_s']['cpu_one']:.1f} s for one sample: "
            f"{gr['throughput']['ratio']:.1f}x the CPU's samples per second\n"
            f"  estimate J = {e['value_Pa_m_s']:.4g} +- {e['value_stderr']:.2g} Pa m/s, dJ/dx = "
            + ", ".join(f"{g:.3g} +- {s:.2g}" for g, s in zip(e["gradient"], e["gradient_stderr"]))
            + f"\n  member 0 against the CPU: integrals {gr['cpu_vs_accelerator_member0']['integrals_relative_difference']:.1e},"
            f" Jacobian {gr['cpu_vs_accelerator_member0']['jacobian_relative_difference']:.1e} relative"
        )
    return "\n".join(lines)


def main(
    part: str = "all",
    sizes=(1, 8, 64, 512, 4096),
    cpu_sizes=(1, 8),
    duration_ms: float = 1.0,
    members: int = 64,
    repeats: int = 2,
    output: str | None = None,
) -> dict:
    import jax

    jax.config.update("jax_enable_x64", True)
    import jaxbearing  # noqa: F401  (x64, caches)

    device = accelerator()
    if device is None:
        raise UsageError("no accelerator: accelerator_throughput compares a GPU (or TPU) with the host CPU")
    result = {
        "benchmark": NAME,
        "device": f"{device.platform}: {device.device_kind}",
        "machine": _common.machine_info(),
    }
    if part in ("sweep", "all"):
        result["sweep"] = sweep_part(sizes, cpu_sizes, duration_ms * 1e-3, repeats)
    if part in ("ensemble", "all"):
        result["ensemble"] = ensemble_part(members)
    if part in ("gradient", "all"):
        result["gradient"] = gradient_part(members)
    result["table"] = _table(result)
    path = Path(output) if output else _common.RESULTS_DIR / f"{NAME}.json"
    _common.write_json(path.stem, result, path.parent)
    print(result["table"])
    return result


def _parse(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--part", choices=("sweep", "ensemble", "gradient", "all"), default="all")
    parser.add_argument("--sizes", default="1,8,64,512,4096")
    parser.add_argument("--cpu-sizes", default="1,8")
    parser.add_argument("--duration-ms", type=float, default=1.0)
    parser.add_argument("--members", type=int, default=64)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--output", default=None)
    args = parser.parse_args(argv)
    try:
        sizes, cpu_sizes = _sizes(args.sizes, "--sizes"), _sizes(args.cpu_sizes, "--cpu-sizes")
        if 1 not in cpu_sizes:
            raise UsageError(f"--cpu-sizes must include 1 (the baseline), got {args.cpu_sizes!r}")
        if not 0 < args.duration_ms <= 100:
            raise UsageError(f"--duration-ms must be in (0, 100], got {args.duration_ms}")
        if not 1 <= args.members <= 4096:
            raise UsageError(f"--members must be in [1, 4096], got {args.members}")
        if not 1 <= args.repeats <= 10:
            raise UsageError(f"--repeats must be in [1, 10], got {args.repeats}")
    except UsageError as e:
        parser.error(str(e))
    return dict(
        part=args.part,
        sizes=sizes,
        cpu_sizes=cpu_sizes,
        duration_ms=args.duration_ms,
        members=args.members,
        repeats=args.repeats,
        output=args.output,
    )


if __name__ == "__main__":
    try:
        main(**_parse(sys.argv[1:]))
    except UsageError as e:
        sys.exit(f"{NAME}: {e}")
