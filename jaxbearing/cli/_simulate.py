"""`jaxbearing simulate`: integrate the bearing, print the flange statistics, write results."""

from __future__ import annotations

import contextlib
import math
import pathlib

from .._errors import UserInputError
from . import _steady

_TABLE_ROWS = (
    ("flange_force_N", "flange force", "N", 1.0),
    ("flange_pressure_Pa", "peak pressure", "GPa", 1e-9),
    ("flange_sliding_velocity_m_s", "sliding velocity", "m/s", 1.0),
    ("flange_pv_Pa_m_s", "PV", "GPa m/s", 1e-9),
    ("contact_height_m", "contact height", "mm", 1e3),
    ("contact_radius_m", "contact radius", "mm", 1e3),
)


def register(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="integrate the bearing dynamics and report roller-end/flange contacts",
        description="Integrate the whole-bearing dynamics and report the roller-end/flange contact "
        "statistics (paper Figure 7 quantities), cage speed and slip: with --settle, from the skid "
        "start until settled, then over a window of cage revolutions with 95 % confidence intervals; "
        "without it, one fixed-duration run from the quasi-static start.",
    )
    p.add_argument("--config", help="TOML configuration (default: embedded reference bearing)")
    p.add_argument("--end", choices=("arc", "corner", "both"), help="roller end type (default: from config)")
    p.add_argument("--speed-rpm", type=float, help="inner-ring speed [rpm]")
    p.add_argument("--load-N", type=float, dest="load_N", help="radial load [N]")
    p.add_argument("--duration-ms", type=float, help="simulated time [ms]")
    p.add_argument("--out", help="output directory (summary.json, histories .npz, plots)")
    p.add_argument("--no-progress", action="store_true", help="no progress meter")
    p.add_argument("--solver", help="time integrator: tsit5 (default) or ros34pw2 (simulation.solver)")
    _steady.add_arguments(p)
    p.set_defaults(func=run)


#: command-line option -> the configuration key it overrides
_OVERRIDES = {
    "speed_rpm": ("--speed-rpm", "operating.speed_rpm"),
    "load_N": ("--load-N", "operating.radial_load_N"),
    "duration_ms": ("--duration-ms", "simulation.duration_ms"),
    "end": ("--end", "simulation.end"),
    "solver": ("--solver", "simulation.solver"),
}


def _load(args):
    """The configuration to run: the file (errors name it), the overrides (errors name the
    option), and the checks a run needs (`check_runnable`, as `config check` does)."""
    from ..io import check_runnable

    cfg = load_named_config(args.config)
    overrides = {
        key: getattr(args, attr) for attr, (_, key) in _OVERRIDES.items() if getattr(args, attr) is not None
    }
    try:
        cfg = cfg.replace(**overrides) if overrides else cfg
    except UserInputError as exc:
        raise _named(
            exc, next((opt for opt, key in _OVERRIDES.values() if key == getattr(exc, "field", None)), None)
        ) from None
    try:
        check_runnable(cfg)
    except UserInputError as exc:
        raise _named(exc, args.config) from None
    return cfg


def _named(exc: Exception, where: str | None) -> UserInputError:
    """The error with `where` (a file or option) in front of its one line."""
    return UserInputError(f"{where}: {exc}" if where else str(exc))


def load_named_config(path):
    """`load_config(path)` whose errors start with the file name."""
    from ..io import load_config

    try:
        return load_config(path)
    except UserInputError as exc:
        raise _named(exc, str(path) if path is not None else None) from None


def _check_out(out: str | None) -> None:
    """--out must be a directory or creatable as one (checked before anything is computed)."""
    if out is None:
        return
    path = pathlib.Path(out)
    if path.exists() and not path.is_dir():
        raise UserInputError(f"--out {out}: exists and is not a directory; name a directory")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserInputError(f"--out {out}: cannot create the directory: {exc.strerror or exc}") from None


def run_cases(cfg, progress: bool = True, steady: dict | None = None) -> dict:
    """Run the configured end type(s); returns {end: (result, summary)}. `steady`: keyword
    arguments of a settled run (`_steady.options`)."""
    from ..io import check_runnable
    from ..run import HostProgress, simulate, summarise

    sim = cfg.simulation
    bearing = cfg.bearing()
    op = cfg.operating_point()
    ends = ("arc", "corner") if sim.end == "both" else (sim.end,)
    out = {}
    check_runnable(cfg)
    for end in ends:
        b = bearing.with_flat_ends() if end == "corner" else bearing
        if progress:
            what = "until settled" if steady else f"{sim.duration_ms:g} ms"
            print(f"[{end} end] simulating {what} ...", flush=True)
        # a fixed-duration run shows the host-side meter (`HostProgress`): the solve's own meter
        # is a host callback, which would make the program uncacheable (compiled in every process)
        meter = HostProgress() if progress and not steady else contextlib.nullcontext()
        with meter:
            res = simulate(
                b,
                op,
                duration=sim.duration_ms * 1e-3,
                rtol=sim.rtol,
                atol=sim.atol,
                max_steps=sim.max_steps,
                progress=progress and bool(steady),
                solver=sim.solver,
                **(steady or {}),
            )
        if isinstance(meter, HostProgress):
            meter.close(1.0 if res.ok else min(res.reached_time / (sim.duration_ms * 1e-3), 0.999))
        out[end] = (res, summarise(res))
    return out


#: mark after a value of a failed run in the table
FAILED_MARK = "!"


def _cell(v, k: float, failed: bool) -> str:
    if v is None or not math.isfinite(v):
        return "-"
    return format(v * k, ".4g") + (FAILED_MARK if failed else "")


def format_table(summaries: dict) -> str:
    """Max / mean / median of every flange quantity per end type; a value of a failed run is
    marked with FAILED_MARK and explained under the table."""
    ends = list(summaries)
    failed = {e: summaries[e]["status"] != "ok" for e in ends}
    stats = ("max", "mean", "median")
    widths = {e: max(12, len(f"{e} median") + 2) for e in ends}
    head = f"{'quantity':<22}{'unit':>9}" + "".join(
        f"{e + ' ' + st:>{widths[e]}}" for e in ends for st in stats
    )
    lines = [head, "-" * len(head)]
    for key, label, unit, k in _TABLE_ROWS:
        row = f"{label:<22}{unit:>9}"
        for e in ends:
            row += "".join(f"{_cell(summaries[e][key][st], k, failed[e]):>{widths[e]}}" for st in stats)
        lines.append(row)
    for e in ends:
        if failed[e]:
            lines.append(
                f"{FAILED_MARK} [{e}] the run failed: statistics cover only the simulated "
                "time before the failure and are not reliable"
            )
    lines.append("")
    for e in ends:
        s = summaries[e]
        arc = s["on_arc_fraction"]
        lines.append(
            f"[{e}] status {s['status']}; flange contact events {s['flange_contact_events']}; "
            f"on arc {'-' if arc is None else format(arc, '.0%')}; cage {s['cage_speed_rpm']:.1f} rpm "
            f"(kinematic {s['kinematic_cage_speed_rpm']:.1f}, slip {s['cage_slip']:.2%}); "
            f"{s['num_steps']} steps, wall {s['wall_time_s']:.1f} s (+ compile {s['compile_time_s']:.1f} s)"
        )
        lines.append(_film_line(e, s))
    return "\n".join(lines)


def _film_line(end: str, s: dict) -> str:
    """One line of film statistics over contact time (`jaxbearing.run.film_statistics`)."""

    def num(v, k=1.0, fmt=".3g"):
        return "-" if v is None or not math.isfinite(v) else format(v * k, fmt)

    film, lam = s.get("flange_min_film_m", {}), s.get("film_parameter", {})
    return (
        f"[{end}] flange film: h_min min {num(film.get('min'), 1e6)} um; Lambda median "
        f"{num(lam.get('median'))}, p05 {num(lam.get('p05'))}; Lambda < 1 "
        f"{num(s.get('lambda_below_one_share'), 100, '.1f')} % of contact time; top-edge contact "
        f"{num(s.get('top_edge_contact_share'), 100, '.1f')} %"
    )


def write_outputs(out_dir: pathlib.Path, results: dict) -> None:
    import numpy as np

    from ..io import write_json
    from ..run import plot_run

    out_dir.mkdir(parents=True, exist_ok=True)
    summaries = {e: _strict_summary(s) for e, (_, s) in results.items()}
    doc = summaries[next(iter(summaries))] if len(summaries) == 1 else dict(summaries)
    write_json(out_dir / "summary.json", doc)
    for end, (res, _) in results.items():
        np.savez_compressed(out_dir / f"histories_{end}.npz", **res.histories)
    plot_run(out_dir, results)


def _strict_summary(summary: dict) -> dict:
    """A summary block as strict JSON: non-finite values null with their reason
    (`jaxbearing.io.with_null_reasons`); a failed run gets a `warning` on its statistics."""
    from ..io import with_null_reasons

    block = dict(summary)
    failed = block.get("status", "ok") != "ok"
    if failed:
        block["warning"] = (
            "the run failed: statistics cover only the simulated time before the failure and are not reliable"
        )
    return with_null_reasons(block, "the run failed (see status)" if failed else "no value")


def run(args) -> int:
    cfg = _load(args)
    _check_out(args.out)
    progress = cfg.simulation.progress and not args.no_progress
    steady = _steady.options(args)
    results = run_cases(cfg, progress=progress, steady=steady)
    summaries = {e: s for e, (_, s) in results.items()}
    print(_steady.format_table(summaries) if steady else format_table(summaries))
    if args.out:
        write_outputs(pathlib.Path(args.out), results)
        print(f"results written to {args.out}")
    if steady:
        return _steady.exit_code(summaries)
    return 0 if all(s["status"] == "ok" for s in summaries.values()) else 1
