"""Run every benchmark (`make bench`): ``python benchmarks/run_all.py [--quick] [--only a,b] [--list]``.

Discovers ``benchmarks/bench_*.py``; each module defines ``main(quick: bool) -> dict`` that
prints its table and writes its JSON under ``benchmarks/results/`` (the runner writes the
returned dict to ``results/<name>.json`` for a benchmark that wrote none). Every benchmark runs in a fresh
Python process (no compilation cache, memory or machine state leaks from one into the next; a
crash of one cannot take the others down), with a time limit. A failing benchmark is recorded
(its error in ``results/summary.json``) and the runner goes on; it exits 1 at the end if any
failed. ``results/summary.json`` holds the machine information (CPU count, load, platform,
versions, date), every benchmark's status, wall time and performance targets.

A benchmark's returned dict may carry ``"table"`` (its printed table, repeated in the final
report) and ``"targets"`` (``{key: {"target", "measured", "threshold", "reached"}}``, see
``_common.target``), which are collected into the summary.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path

BENCH_DIR = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH_DIR))

import _common  # noqa: E402

DEFAULT_TIMEOUT_S = {False: 900, True: 300}  # per benchmark: full, quick


def timeout_for(name: str, quick: bool) -> float:
    """A benchmark's time limit: its module's `FULL_TIMEOUT_S` in full mode where it declares one
    (studies that take longer than the default by design), else `DEFAULT_TIMEOUT_S`."""
    default = DEFAULT_TIMEOUT_S[quick]
    return default if quick else float(getattr(load(name), "FULL_TIMEOUT_S", default))


def discover(bench_dir: Path = BENCH_DIR) -> list[str]:
    """Names of the benchmark modules (bench_*.py), sorted."""
    return sorted(p.stem for p in bench_dir.glob("bench_*.py"))


def load(name: str, bench_dir: Path = BENCH_DIR):
    """Import benchmarks/<name>.py as a module."""
    spec = importlib.util.spec_from_file_location(name, bench_dir / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _child(name: str, quick: bool, status_file: str) -> int:
    """Run one benchmark in this (fresh) process; write its outcome to `status_file`."""
    start, started_at = time.perf_counter(), time.time()
    status = {"name": name, "ok": False}
    try:
        module = load(name)
        result = module.main(quick=quick)
        if not isinstance(result, dict):
            raise TypeError(f"{name}.main returned {type(result).__name__}, expected a dict")
        written = [
            p
            for p in Path(_common.RESULTS_DIR).glob("*.json")
            if p.name != "summary.json" and p.stat().st_mtime >= started_at
        ]
        if not written:  # the benchmark wrote no JSON of its own: keep what it returned
            written = [_common.write_json(name, result)]
        status["json"] = sorted(str(p.name) for p in written)
        status.update(ok=True, table=result.get("table"), targets=result.get("targets", {}))
    except BaseException as exc:  # noqa: BLE001 - recorded and reported by the parent
        status.update(error=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc())
        traceback.print_exc()
    status["wall_s"] = time.perf_counter() - start
    Path(status_file).write_text(json.dumps(_common._jsonable(status)))
    return 0 if status["ok"] else 1


def run_one(name: str, quick: bool, timeout: float) -> dict:
    """Run one benchmark in a fresh process; its output streams through to this terminal."""
    with tempfile.TemporaryDirectory() as tmp:
        status_file = os.path.join(tmp, "status.json")
        cmd = [sys.executable, str(Path(__file__).resolve()), "--child", name, "--status-file", status_file]
        if quick:
            cmd.append("--quick")
        start = time.perf_counter()
        try:
            proc = subprocess.run(cmd, timeout=timeout)
            code = proc.returncode
        except subprocess.TimeoutExpired:
            return {
                "name": name,
                "ok": False,
                "wall_s": time.perf_counter() - start,
                "error": f"timed out after {timeout:g} s",
            }
        if os.path.exists(status_file):
            status = json.loads(Path(status_file).read_text())
        else:
            status = {
                "name": name,
                "ok": False,
                "error": f"the process exited with code {code} without reporting (crashed or killed)",
            }
        status["process_wall_s"] = time.perf_counter() - start
        return status


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="short simulated times, few repeats")
    parser.add_argument(
        "--only", default=None, help="comma-separated benchmark names (bench_ prefix optional)"
    )
    parser.add_argument("--list", action="store_true", help="list the benchmarks and exit")
    parser.add_argument("--timeout", type=float, default=None, help="seconds per benchmark")
    parser.add_argument("--child", default=None, help=argparse.SUPPRESS)
    parser.add_argument("--status-file", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)

    if args.child:
        return _child(args.child, args.quick, args.status_file)
    names = discover()
    if args.list:
        print("\n".join(names))
        return 0
    if args.only:
        wanted = [w if w.startswith("bench_") else f"bench_{w}" for w in args.only.split(",") if w]
        unknown = [w for w in wanted if w not in names]
        if unknown:
            print(
                f"error: --only: unknown benchmark(s) {', '.join(unknown)}; available: {', '.join(names)}",
                file=sys.stderr,
            )
            return 2
        names = wanted

    machine = _common.machine_info()
    print(f"jaxbearing benchmarks ({'quick' if args.quick else 'full'}): {', '.join(names)}")
    print(
        f"machine: {machine['cpu_count']} CPUs ({machine['cpu_model']}), load {machine['load_average_1_5_15min']}, "
        f"jax {machine['jax']} on {machine['jax_backend']}, {machine['date_utc']}\n",
        flush=True,
    )
    start = time.perf_counter()
    statuses = []
    for name in names:
        print(f"=== {name} ===", flush=True)
        timeout = args.timeout if args.timeout is not None else timeout_for(name, args.quick)
        status = run_one(name, args.quick, timeout)
        statuses.append(status)
        print(
            f"=== {name}: {'ok' if status['ok'] else 'FAILED: ' + status.get('error', '?')} "
            f"({status.get('process_wall_s', 0.0):.1f} s) ===\n",
            flush=True,
        )
    total = time.perf_counter() - start

    summary = {
        "quick": args.quick,
        "machine": machine,
        "load_average_at_end": list(os.getloadavg()),
        "total_wall_s": total,
        "benchmarks": {
            s["name"]: {k: v for k, v in s.items() if k not in ("name", "table")} for s in statuses
        },
        "targets": {f"{s['name']}.{k}": t for s in statuses for k, t in (s.get("targets") or {}).items()},
        "failed": [s["name"] for s in statuses if not s["ok"]],
    }
    path = _common.write_json("summary", summary)

    print("=" * 100)
    for s in statuses:
        if s.get("table"):
            print(s["table"] + "\n")
    rows = [
        [s["name"], "ok" if s["ok"] else "FAILED", s.get("process_wall_s"), (s.get("error") or "")[:80]]
        for s in statuses
    ]
    print(
        _common.format_table(
            f"Benchmarks ({total:.0f} s in all)", ["benchmark", "status", "wall s", "error"], rows
        )
    )
    if summary["targets"]:
        trows = [
            [k, t["target"], t["measured"], t["threshold"], t["reached"]]
            for k, t in summary["targets"].items()
        ]
        print(
            _common.format_table(
                "Performance targets", ["key", "target", "measured", "threshold", "reached"], trows
            )
        )
    print(f"results: {path.parent}/")
    if summary["failed"]:
        print(
            f"{len(summary['failed'])} benchmark(s) failed: {', '.join(summary['failed'])}", file=sys.stderr
        )
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
