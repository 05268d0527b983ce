"""`jaxbearing simulate`: integrate the bearing, print the flange statistics, write results."""

from __future__ import annotations

import json
import math
import pathlib

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
        description="Integrate the whole-bearing dynamics from the quasi-static state and report the "
        "roller-end/flange contact statistics (paper Figure 7 quantities), cage speed and slip.",
    )
    p.add_argument("--config", help="TOML configuration (default: embedded reference bearing)")
    p.add_argument("--end", choices=("arc", "corner", "both"), help="roller end type (default: from config)")
    p.add_argument("--speed-rpm", type=float, help="inner-ring speed [rpm]")
    p.add_argument("--load-N", type=float, dest="load_N", help="radial load [N]")
    p.add_argument("--duration-ms", type=float, help="simulated time [ms]")
    p.add_argument("--out", help="output directory (summary.json, histories .npz, plots)")
    p.add_argument("--no-progress", action="store_true", help="no progress meter")
    _steady.add_arguments(p)
    p.set_defaults(func=run)


def _load(args):
    from ..io import load_config

    cfg = load_config(args.config)
    overrides = {}
    if args.speed_rpm is not None:
        overrides["operating.speed_rpm"] = args.speed_rpm
    if args.load_N is not None:
        overrides["operating.radial_load_N"] = args.load_N
    if args.duration_ms is not None:
        overrides["simulation.duration_ms"] = args.duration_ms
    if args.end is not None:
        overrides["simulation.end"] = args.end
    if overrides:
        cfg = cfg.replace(**overrides)
    return cfg


def run_cases(cfg, progress: bool = True, steady: dict | None = None) -> dict:
    """Run the configured end type(s); returns {end: (result, summary)}. `steady`: keyword
    arguments of a settled run (`_steady.options`)."""
    from ..run import simulate, summarise

    sim = cfg.simulation
    bearing = cfg.bearing()
    op = cfg.operating_point()
    ends = ("arc", "corner") if sim.end == "both" else (sim.end,)
    out = {}
    for end in ends:
        b = bearing.with_flat_ends() if end == "corner" else bearing
        if end == "arc" and not math.isfinite(float(b.roller.end_radius)):
            from .._errors import ConfigError

            raise ConfigError("roller.end_radius_mm", "inf (flat end) cannot be simulated as an arc end; use --end corner")
        if progress:
            what = "until settled" if steady else f"{sim.duration_ms:g} ms"
            print(f"[{end} end] simulating {what} ...", flush=True)
        res = simulate(
            b,
            op,
            duration=sim.duration_ms * 1e-3,
            rtol=sim.rtol,
            atol=sim.atol,
            max_steps=sim.max_steps,
            progress=progress,
            **(steady or {}),
        )
        out[end] = (res, summarise(res))
    return out


def format_table(summaries: dict) -> str:
    ends = list(summaries)
    lines = []
    head = f"{'quantity':<22}{'unit':>9}" + "".join(f"{e + ' max':>12}{e + ' mean':>12}{e + ' median':>13}" for e in ends)
    lines.append(head)
    lines.append("-" * len(head))
    for key, label, unit, k in _TABLE_ROWS:
        row = f"{label:<22}{unit:>9}"
        for e in ends:
            st = summaries[e][key]
            for stat, w in (("max", 12), ("mean", 12), ("median", 13)):
                v = st[stat]
                row += f"{'-' if v is None else format(v * k, '.4g'):>{w}}"
        lines.append(row)
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
    return "\n".join(lines)


def write_outputs(out_dir: pathlib.Path, results: dict) -> None:
    import numpy as np

    from ..run import plot_run

    out_dir.mkdir(parents=True, exist_ok=True)
    summaries = {e: s for e, (_, s) in results.items()}
    doc = summaries[next(iter(summaries))] if len(summaries) == 1 else dict(summaries)
    (out_dir / "summary.json").write_text(json.dumps(doc, indent=2, allow_nan=True))
    for end, (res, _) in results.items():
        np.savez_compressed(out_dir / f"histories_{end}.npz", **res.histories)
    plot_run(out_dir, results)


def run(args) -> int:
    cfg = _load(args)
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
