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
    ("flange_flash_temperature_K", "flash temperature", "K", 1.0),
    ("contact_height_m", "contact height", "mm", 1e3),
    ("contact_radius_m", "contact radius", "mm", 1e3),
)


def register(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="integrate the bearing dynamics and report roller-end/flange contacts",
        description="Integrate the whole-bearing dynamics and report the roller-end/flange contact "
        "statistics (paper Figure 7 quantities), cage speed and slip of settled running: from the skid "
        "start until settled, then over a window of cage revolutions with 95 % confidence intervals. "
        "--transient: one fixed-duration run from the quasi-static start instead (a start-up transient).",
    )
    p.add_argument("--config", help="TOML configuration (default: the embedded reference bearing)")
    p.add_argument(
        "--end",
        choices=_choices("simulation.end"),
        help="roller end type " + _from_config("simulation.end"),
    )
    p.add_argument(
        "--speed-rpm", type=float, help="inner-ring speed [rpm] " + _from_config("operating.speed_rpm")
    )
    p.add_argument(
        "--load-N",
        type=float,
        dest="load_N",
        help="radial load [N] " + _from_config("operating.radial_load_N"),
    )
    p.add_argument(
        "--duration-ms",
        type=float,
        help="with --transient: simulated time [ms] of the start-up transient "
        + _from_config("simulation.duration_ms"),
    )
    p.add_argument(
        "--out",
        help="output directory for summary.json (statistics, configuration, command, seeds, units), "
        "histories_<end>.npz and plots; checked before the solve (default: none, nothing written)",
    )
    p.add_argument(
        "--no-progress", action="store_true", help="no progress meter (default: simulation.progress)"
    )
    p.add_argument(
        "--solver",
        metavar="{" + ",".join(_choices("simulation.solver")) + "}",  # checked with the configuration
        help="time integrator " + _from_config("simulation.solver"),
    )
    _steady.add_arguments(p)
    p.set_defaults(func=run)


def _choices(path: str) -> tuple:
    from ..io import KEY_BY_PATH

    return tuple(KEY_BY_PATH[path].choices)


def _from_config(path: str) -> str:
    """ "(default: KEY of the configuration; reference VALUE)" for an option that overrides KEY."""
    from ..io import KEY_BY_PATH, format_value

    key = KEY_BY_PATH[path]
    value = format_value(key.default).strip('"')
    return f"(default: {path} of the configuration, {value}{' ' + key.unit if key.unit else ''} in the reference)"


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
    """--out must be a directory this process can write, or creatable as one (checked before
    anything is computed; nothing is left behind by the check: `jaxbearing.io.check_output_dir`)."""
    if out is not None:
        from ..io import check_output_dir

        check_output_dir(out, "--out")


def run_cases(cfg, progress: bool = True, steady=None) -> dict:
    """Run the configured end type(s); returns {end: (result, summary)}. `steady`: the
    `SteadySettings` of a settled run (`_steady.options`), None for a start-up transient."""
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
            what = "until settled" if steady else f"a {sim.duration_ms:g} ms start-up transient"
            print(f"[{end} end] simulating {what} ...", flush=True)
        # a fixed-duration run shows the host-side meter (`HostProgress`): the solve's own meter
        # is a host callback, which would make the program uncacheable (compiled in every process)
        meter = HostProgress() if progress and not steady else contextlib.nullcontext()
        solver = dict(rtol=sim.rtol, atol=sim.atol, max_steps=sim.max_steps, solver=sim.solver)
        with meter:
            if steady is None:
                res = simulate(b, op, duration=sim.duration_ms * 1e-3, progress=False, **solver)
            else:
                res = simulate(b, op, settings=steady.replace(progress=progress, **solver))
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
    span = max((summaries[e].get("simulated_time_s") or 0.0) for e in ends) * 1e3
    lines = [
        f"START-UP TRANSIENT: {span:g} ms from the quasi-static start, not settled running; statistics "
        "over the whole run, no confidence intervals (drop --transient for settled running)",
        head,
        "-" * len(head),
    ]
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
    """One line of film statistics over contact time (`jaxbearing.run.film_statistics`) and the
    time-mean friction power of all flanges (`jaxbearing.run.friction_power_statistics`)."""

    def num(v, k=1.0, fmt=".3g"):
        return "-" if v is None or not math.isfinite(v) else format(v * k, fmt)

    film, lam = s.get("flange_min_film_m", {}), s.get("film_parameter", {})
    power = s.get("flange_friction_power_W", {})
    return (
        f"[{end}] flange film: h_min min {num(film.get('min'), 1e6)} um; Lambda median "
        f"{num(lam.get('median'))}, p05 {num(lam.get('p05'))}; Lambda < 1 "
        f"{num(s.get('lambda_below_one_share'), 100, '.1f')} % of contact time; top-edge contact "
        f"{num(s.get('top_edge_contact_share'), 100, '.1f')} %; friction power (mean) "
        f"{num(power.get('total'))} W"
    )


def summary_document(results: dict, cfg=None, steady=None) -> dict:
    """summary.json: the statistics (one block, or one per end type), and what produced them
    (`jaxbearing.io.provenance`: package version, command line, the full configuration in
    engineering units, the seeds) and the unit of every quantity (`units`)."""
    from ..io import provenance, units_of

    summaries = {e: _strict_summary(s) for e, (_, s) in results.items()}
    doc = summaries[next(iter(summaries))] if len(summaries) == 1 else dict(summaries)
    if cfg is None:
        return doc
    first = next(iter(summaries.values()))
    seeds = list(range(steady.seeds)) if steady else [0]  # fixed run: Perturbation(seed=0)
    meta = provenance(cfg, seeds=seeds)
    meta["ends"] = list(summaries)
    if steady:
        meta["steady_options"] = steady.record()
    meta["units"] = units_of(first)
    for key in ("seeds",):  # a settled run's block already lists its seeds (the same list)
        if key in doc:
            meta.pop(key)
    clash = set(meta) & set(doc)
    if clash:  # pragma: no cover - the summary keys never use these names
        raise RuntimeError(f"summary keys {sorted(clash)} clash with the provenance keys")
    return {**doc, **meta}


def write_outputs(out_dir: pathlib.Path, results: dict, cfg=None, steady=None) -> None:
    """summary.json (`summary_document`), histories_<end>.npz and the plots into `out_dir`."""
    import numpy as np

    from ..io import write_json
    from ..run import plot_run

    out_dir.mkdir(parents=True, exist_ok=True)
    write_json(out_dir / "summary.json", summary_document(results, cfg, steady))
    for end, (res, _) in results.items():
        np.savez_compressed(out_dir / f"histories_{end}.npz", **res.histories)
    plot_run(out_dir, results)


def save_outputs(prog: str, out: str, results: dict, cfg, steady=None) -> int:
    """`write_outputs` into `out`, or into a fallback directory when that fails
    (`jaxbearing.io.write_or_fallback`); returns 0, or `EXIT_RESULTS_ELSEWHERE` after one line
    naming the fallback directory."""
    from ..io import write_or_fallback
    from ._main import report_fallback

    used, reason = write_or_fallback(out, lambda d: write_outputs(d, results, cfg, steady))
    if reason is None:
        print(f"results written to {out}")
    return report_fallback(prog, out, used, reason)


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
    steady = _steady.options(args)
    _check_out(args.out)
    warn_implausible(cfg)
    progress = cfg.simulation.progress and not args.no_progress
    results = run_cases(cfg, progress=progress, steady=steady)
    summaries = {e: s for e, (_, s) in results.items()}
    print(_steady.format_table(summaries) if steady else format_table(summaries))
    saved = save_outputs("jaxbearing simulate", args.out, results, cfg, steady) if args.out else 0
    if saved:
        return saved
    if steady:
        return _steady.exit_code(summaries)
    return 0 if all(s["status"] == "ok" for s in summaries.values()) else 1


def warn_implausible(cfg) -> None:
    """One line on stderr per value that is valid but almost certainly a unit slip
    (`jaxbearing.io.plausibility_warnings`), and per violated margin of the design zone of an
    arc-end run (`_zone.outside_zone_lines`)."""
    import sys

    from ..io import plausibility_warnings

    for line in plausibility_warnings(cfg):
        print(f"warning: {line}", file=sys.stderr)
    if cfg.simulation.end != "corner" and math.isfinite(cfg["roller.end_radius_mm"]):
        from ..flange import design_zone
        from ._zone import outside_zone_lines

        bearing = cfg.bearing()
        for line in outside_zone_lines(bearing, design_zone(bearing)):
            print(f"warning: {line}", file=sys.stderr)
