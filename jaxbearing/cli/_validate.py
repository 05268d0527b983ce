"""`jaxbearing validate`: the model against measured cage speeds (the source study's Figure 16).

Reads a CSV of measured cage speeds at stated shaft speeds and radial loads (units in the header;
`jaxbearing.io.read_cage_speed_measurements`, examples/validation/README.md), runs settled
running at every point (`jaxbearing.run.model_cage_speeds`) and prints, per point, the model's
cage speed with its 95 % confidence interval, the measurement and the relative error. With
`--out DIR` (checked before any run) it writes `validation.csv` (a row per point, rewritten as
each point finishes, so a killed run keeps its finished points), `validation.json` (the rows,
the configuration, the command line, the seeds and the units) and `validation.png`.
"""

from __future__ import annotations

import csv
import io
import pathlib

from ..run import SteadySettings
from ._steady import _ci

#: columns of validation.csv (units in the names)
CSV_COLUMNS = (
    "line",
    "shaft_speed_rpm",
    "radial_load_N",
    "measured_cage_speed_rpm",
    "model_cage_speed_rpm",
    "model_ci95_low_rpm",
    "model_ci95_high_rpm",
    "relative_error",
    "relative_error_ci95_low",
    "relative_error_ci95_high",
    "measurement_inside_ci",
    "settled",
    "settle_time_ms",
    "window_ms",
    "status",
)


def register(sub) -> None:
    p = sub.add_parser(
        "validate",
        help="the model against measured cage speeds (CSV with units in its header)",
        description="Run settled running at every operating point of a CSV file of measured cage "
        "speeds (columns 'shaft speed [rpm]', 'radial load [N]', 'cage speed [rpm]'; "
        "examples/validation/README.md) and report the model's cage speed with its 95 % confidence "
        "interval, the measurement and the relative error; --out writes a table, a JSON record and "
        "the figure (the source study's Figure 16).",
    )
    p.add_argument("measurements", help="CSV file of measured cage speeds (units in the header)")
    p.add_argument(
        "--config", help="TOML configuration of the bearing (default: the embedded reference bearing)"
    )
    p.add_argument(
        "--end", default="arc", help='roller end type, "arc" or "corner" (flat end) (default: %(default)s)'
    )
    p.add_argument(
        "--settle",
        default="auto",
        help='"auto" (detect settling) or a settling time in ms (default: %(default)s)',
    )
    p.add_argument(
        "--seeds",
        type=float,
        default=2,
        help="seeded runs per point: the CI's samples (default: %(default)g)",
    )
    p.add_argument(
        "--window-revs",
        type=float,
        default=SteadySettings.window_revs,
        help="measurement window [cage revolutions] (default: %(default)g)",
    )
    p.add_argument(
        "--workers",
        type=float,
        default=None,
        help="processes for the seeds (default: one per CPU, at most --seeds)",
    )
    p.add_argument(
        "--out",
        help="output directory for validation.csv, validation.json and validation.png; checked "
        "before any run (default: none, nothing written)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress lines (default: progress shown)")
    p.set_defaults(func=run)


def _options(args) -> dict:
    """The settled-run options, checked (one line naming the option): the end type and the
    `SteadySettings` of every point."""
    from .._errors import UserInputError
    from ..run import available_cpus, steady_settings

    if args.end not in ("arc", "corner"):
        raise UserInputError(f"--end = {args.end!r}: must be 'arc' or 'corner'")
    if args.settle == "off":
        raise UserInputError(
            "--settle = 'off': must be \"auto\" or a settling time in ms (a validation compares settled running)"
        )
    workers = available_cpus() if args.workers is None else args.workers
    names = {"settle": "--settle", "window_revs": "--window-revs", "seeds": "--seeds", "workers": "--workers"}
    settings = steady_settings(
        names, settle=args.settle, window_revs=args.window_revs, seeds=args.seeds, workers=workers
    )
    return dict(end=args.end, settings=settings.replace(workers=min(settings.workers, settings.seeds)))


def _pct(v) -> str:
    return "-" if v is None else f"{v * 100:+.2f}"


def format_table(rows: list[dict]) -> str:
    """One line per point: speeds, load, measured and model cage speed [95 % CI], relative error."""
    head = (
        f"{'line':>5}{'shaft rpm':>11}{'load N':>9}{'measured rpm':>14}{'model rpm [95 % CI]':>32}"
        f"{'error %':>9}{'error % CI':>20}  in CI  settled"
    )
    out = [head, "-" * len(head)]
    for r in rows:
        model = _ci(r["model_cage_speed_rpm"], 1.0, ".1f")
        inside = {True: "yes", False: "no", None: "-"}[r["measurement_inside_ci"]]
        out.append(
            f"{r['line']:>5}{r['shaft_speed_rpm']:>11.0f}{r['radial_load_N']:>9.0f}"
            f"{r['measured_cage_speed_rpm']:>14.1f}{model:>32}{_pct(r['relative_error']):>9}"
            f"{'[' + _pct(r['relative_error_ci95_low']) + ', ' + _pct(r['relative_error_ci95_high']) + ']':>20}"
            f"  {inside:>5}  {str(r['settled']).lower()}"
        )
    return "\n".join(out)


def csv_text(rows: list[dict]) -> str:
    """validation.csv: `CSV_COLUMNS`, a row per point."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    for r in rows:
        m = r["model_cage_speed_rpm"]
        flat = {
            **r,
            "model_cage_speed_rpm": m["value"],
            "model_ci95_low_rpm": m["ci95_low"],
            "model_ci95_high_rpm": m["ci95_high"],
        }
        w.writerow(["" if flat[c] is None else flat[c] for c in CSV_COLUMNS])
    return buf.getvalue()


def _write(directory: pathlib.Path, rows, cfg, opts, source, final: bool) -> None:
    from ..io import atomic_write, provenance, write_json
    from ..run import plot_measured

    atomic_write(directory / "validation.csv", lambda f: f.write(csv_text(rows).encode()))
    if not final:
        return
    doc = {
        "measurements": str(source),
        "end": opts["end"],
        "settle": opts["settings"].settle.value,
        "window_revs": opts["settings"].window_revs,
        "points": rows,
        **provenance(cfg, seeds=list(range(opts["settings"].seeds))),
        "units": {
            "shaft_speed_rpm": "rpm",
            "radial_load_N": "N",
            "measured_cage_speed_rpm": "rpm",
            "model_cage_speed_rpm": "rpm",
            "kinematic_cage_speed_rpm": "rpm",
            "relative_error": "1 ((model - measured) / measured)",
            "cage_slip": "1",
            "settle_time_ms": "ms",
            "window_ms": "ms",
        },
    }
    write_json(directory / "validation.json", doc)
    plot_measured(directory / "validation.png", rows, title=f"Cage speed against {pathlib.Path(source).name}")


def run(args) -> int:
    from ..io import check_output_dir, read_cage_speed_measurements, write_or_fallback
    from ..run import model_cage_speeds
    from ._main import report_fallback
    from ._simulate import load_named_config

    opts = _options(args)
    cfg = load_named_config(args.config)
    points, ignored = read_cage_speed_measurements(args.measurements)
    if args.out is not None:
        check_output_dir(args.out, "--out")
    if ignored:
        print(f"{args.measurements}: ignored columns: {', '.join(repr(c) for c in ignored)}")
    done: list[dict] = []
    where = {"dir": pathlib.Path(args.out) if args.out is not None else None, "reason": None}

    def keep(row):
        done.append(row)
        if where["dir"] is not None:  # finished points are on disk as they finish
            used, reason = write_or_fallback(
                where["dir"], lambda d: _write(d, done, cfg, opts, args.measurements, False)
            )
            where["dir"], where["reason"] = used, where["reason"] or reason

    rows = model_cage_speeds(
        cfg,
        points,
        print_points=not args.no_progress,
        source=str(args.measurements),
        on_point=keep,
        **opts,
    )
    print(format_table(rows))
    if args.out is None:
        return 0 if all(r["status"] == "ok" for r in rows) else 1
    used, reason = write_or_fallback(
        where["dir"], lambda d: _write(d, rows, cfg, opts, args.measurements, True)
    )
    reason = where["reason"] or reason
    print(f"wrote {used}/validation.csv, validation.json, validation.png")
    code = report_fallback("jaxbearing validate", args.out, used, reason)
    if code:
        return code
    return 0 if all(r["status"] == "ok" for r in rows) else 1
