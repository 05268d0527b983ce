"""`jaxbearing sweep SPEC.toml --out DIR`: parameter sweeps in vmapped, sharded, resumable batches.

The spec format is documented in `jaxbearing.sweep` (`sweep/_spec.py`); multi-machine runs in docs/how-to/sweeps.md.
The spec is parsed and every case validated before JAX is initialised (so `jax.distributed`
can still be set up) and before anything is computed.
"""

from __future__ import annotations

import argparse
import sys


def register(sub) -> None:
    p = sub.add_parser(
        "sweep",
        help="run a parameter sweep (vmapped batches over all devices; resumable)",
        description="Run every case of a sweep spec as vmapped batches of the bearing solve, "
        "sharded over the local devices (and over processes with --coordinator), writing each "
        "finished batch to DIR/batches/ at once; the same command resumes a killed sweep. "
        "Results: DIR/results.nc (xarray Dataset: sweep axes as coordinates, summary statistics, "
        "status and design-zone margins of every case). DIR is locked while the sweep runs; "
        "batch files that do not load are moved to DIR/batches/damaged/ and computed again.",
    )
    p.add_argument("spec", help="sweep spec (TOML: [sweep], [base], [axes])")
    p.add_argument(
        "--out",
        required=True,
        help="output directory, checked before anything is computed (default: none; required)",
    )
    p.add_argument(
        "--batch-size",
        type=int,
        help="cases per vmapped batch, overrides the spec (default: sweep.batch_size of the spec, 8 if unset)",
    )
    p.add_argument(
        "--resume",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="skip batches already in DIR (default); --no-resume recomputes all",
    )
    p.add_argument(
        "--coordinator",
        help="jax.distributed coordinator HOST:PORT, process 0's address (default: env "
        "JAXBEARING_COORDINATOR; none: a single process)",
    )
    p.add_argument(
        "--num-processes",
        type=int,
        help="number of processes (default: env JAXBEARING_NUM_PROCESSES, else 1)",
    )
    p.add_argument(
        "--process-id",
        type=int,
        help="this process, 0..num-processes-1 (default: env JAXBEARING_PROCESS_ID, else 0)",
    )
    p.add_argument(
        "--wait-timeout-s",
        type=float,
        default=24 * 3600.0,
        help="process 0: how long to wait for the other processes' batches [s] (default: %(default)g)",
    )
    p.add_argument(
        "--wait-for-lock",
        type=float,
        nargs="?",
        const=float("inf"),
        default=0.0,
        metavar="SECONDS",
        help="when another sweep is writing into DIR, wait for it "
        "(up to SECONDS; no value: as long as it takes) instead of exiting with status 2 (default: do not wait)",
    )
    p.add_argument(
        "--dry-run",
        action="store_true",
        help="validate the spec, list the axes and the number of cases and batches, compute nothing "
        "(default: run the sweep)",
    )
    p.add_argument(
        "--workers",
        type=int,
        help="local worker processes that solve this process's batches (default: one per CPU on "
        "a CPU platform, 1 on an accelerator); results are bitwise the same for any number",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar (default: a progress bar)")
    p.set_defaults(func=run)


def default_workers(spec, num_processes: int) -> int:
    """One worker per CPU when the batches run on the CPU (one solve uses about one core), at
    most one per batch; 1 on an accelerator, whose one device runs the vmapped batch, and 1 when
    the sweep is already split over `jax.distributed` processes."""
    import jax

    from ..run import available_cpus

    if num_processes > 1 or jax.default_backend() != "cpu" or jax.local_device_count() > 1:
        return 1
    return max(1, min(available_cpus(), spec.num_batches))


def run(args) -> int:
    from ..io import check_arguments, check_output_dir, count, plausibility_warnings
    from ..sweep import ResultsElsewhere, initialize_distributed, load_sweep_spec, run_sweep
    from ._main import EXIT_RESULTS_ELSEWHERE

    if args.workers is not None:  # before anything is printed or started
        check_arguments({"workers": args.workers}, {"workers": count(1)})
    spec = load_sweep_spec(args.spec)
    if args.batch_size is not None:
        spec = spec.with_batch_size(args.batch_size)
    if not args.dry_run:
        check_output_dir(args.out, "--out")  # before jax.distributed and any solve
    print(
        f"sweep {args.spec}: {spec.num_cases} cases "
        f"({' x '.join(f'{d} {n}' for d, n in zip(spec.dims, spec.shape))}), "
        f"{spec.num_batches} batches of {spec.batch_size}; spec hash {spec.hash}",
        file=sys.stderr,
    )
    print(f"  {_running(spec)}", file=sys.stderr)
    if args.dry_run:
        for a in spec.axes:
            print(f"  {a.key} [{a.dim}]: {', '.join(map(str, a.values))}")
        return 0
    for line in plausibility_warnings(spec.base):
        print(f"warning: base configuration: {line}", file=sys.stderr)
    process_id, num_processes = initialize_distributed(args.coordinator, args.num_processes, args.process_id)
    import jax

    workers = args.workers if args.workers is not None else default_workers(spec, num_processes)
    print(
        f"process {process_id}/{num_processes}: {jax.local_device_count()} local device(s) "
        f"({jax.local_devices()[0].platform}), {workers} worker process(es)",
        file=sys.stderr,
    )
    try:
        ds = run_sweep(
            spec,
            args.out,
            workers=workers,
            resume=args.resume,
            process_id=process_id,
            num_processes=num_processes,
            progress=not args.no_progress,
            wait_timeout_s=args.wait_timeout_s,
            lock_wait_s=args.wait_for_lock,
        )
    except ResultsElsewhere as exc:
        print(f"jaxbearing sweep: error: {exc}", file=sys.stderr)
        return EXIT_RESULTS_ELSEWHERE
    if ds is None:
        print(f"process {process_id}: batches written to {args.out}/batches")
        return 0
    failed = int((ds["result_code"] != 0).sum())
    print(f"{spec.num_cases} cases ({failed} failed) written to {args.out}/results.nc")
    if failed:
        first = next(str(s) for s in ds["status"].values.ravel() if s != "ok")
        print(f"first failure: {first}", file=sys.stderr)
    return 0


def _running(spec) -> str:
    """What every case of `spec` computes, in one line."""
    if not spec.settled:
        return (
            f'START-UP TRANSIENTS (settle = "off"): {spec.base.simulation.duration_ms:g} ms from the '
            "quasi-static start, no intervals"
        )
    settle = "until the settling verdict" if spec.settle == "auto" else f"a fixed {spec.settle:g} ms"
    return (
        f"settled running: {spec.seeds} seed(s) per case from the {spec.start} start, {settle} "
        f"(tolerance {spec.settle_tolerance:g}, cap {spec.settle_cap_ms:g} ms), then {spec.window_revs} "
        "cage revolutions; every statistic with its 95 % interval"
    )
