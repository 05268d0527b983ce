"""Settled runs on the command line: the `--settle` options of `simulate` and their table.

`jaxbearing simulate` settles by default (`--settle auto`; a settling time MS in ms is the
other choice); a start-up transient is the explicit `--transient` (or `--settle off`), and its
table, summary.json (`running`) and plots say so. A settled run (`jaxbearing.run.simulate_steady`):
skid start (`--start skid`, default: the speeds of steady running, then projective steps of the
cage speed while settling; `--start quasi-static`: kinematic speeds), settling (`auto`: until
the remaining drift of the cage speed, the trend of the last 4-8 revolution means times the slow
mode's time constant, is below `--settle-tolerance`, at most `--settle-cap-ms`; docs/model.md
16; MS: a fixed settling time), then a window of `--window-revs` revolutions for each of
`--seeds` seeds. Every statistic is printed with its 95 % confidence interval.
"""

from __future__ import annotations

import numpy as np

from ..run import SteadySettings

_ROWS = (
    ("flange_force_N", "flange force", "N", 1.0),
    ("flange_pressure_Pa", "peak pressure", "GPa", 1e-9),
    ("flange_sliding_velocity_m_s", "sliding velocity", "m/s", 1.0),
    ("flange_roller_surface_speed_m_s", "surface speed (paper)", "m/s", 1.0),
    ("flange_pv_Pa_m_s", "PV", "GPa m/s", 1e-9),
    ("flange_flash_temperature_K", "flash temperature rise", "K", 1.0),
    ("contact_height_m", "contact height", "mm", 1e3),
    ("contact_radius_m", "contact radius", "mm", 1e3),
)


def add_arguments(p) -> None:
    g = p.add_argument_group("settled running (statistics with 95 % confidence intervals)")
    g.add_argument(
        "--settle",
        help='"auto" (until the settling verdict), a settling time in ms, or "off" (the same as '
        "--transient) (default: auto)",
    )
    g.add_argument(
        "--transient",
        action="store_true",
        help="instead: a start-up transient, one fixed-duration run of --duration-ms from the "
        "quasi-static start, labelled as such (default: settled running)",
    )
    g.add_argument(
        "--window-revs",
        type=float,
        default=SteadySettings.window_revs,
        help="measurement window [cage revolutions] (default: %(default)g)",
    )
    g.add_argument(
        "--seeds",
        type=float,
        default=SteadySettings.seeds,
        help="independent seeded runs, seeds 0 .. N-1 (default: %(default)g: batch means)",
    )
    g.add_argument(
        "--settle-tolerance",
        type=float,
        default=SteadySettings.tolerance,
        help="largest remaining drift of the cage speed, relative, that counts as settled: the drift of the "
        "last 4-8 revolution means times the slow mode's time constant (default: %(default)g)",
    )
    g.add_argument(
        "--workers",
        type=float,
        default=None,
        help="processes for the seeds (default: one per CPU, at most --seeds)",
    )
    g.add_argument(
        "--start",
        default=SteadySettings.start,
        help='"skid" (skid equilibrium, projective steps of the cage speed) or "quasi-static" (default: %(default)s)',
    )
    g.add_argument(
        "--settle-cap-ms",
        type=float,
        default=SteadySettings.settle_cap_ms,
        help="longest settling time [ms] (default: %(default)g)",
    )


def options(args):
    """The `SteadySettings` of a settled run (the default), checked (one line naming the
    option); None for a start-up transient (`--transient` or `--settle off`). `--duration-ms`
    belongs to a transient: given for a settled run, it is an error (one line), not silently
    ignored."""
    from .._errors import UserInputError
    from ..run import available_cpus, steady_settings

    transient = args.transient or args.settle == "off"
    if args.transient and args.settle not in (None, "off"):
        raise UserInputError(
            f"--transient: cannot be combined with --settle {args.settle} (a transient is not settled)"
        )
    if transient:
        return None
    if getattr(args, "duration_ms", None) is not None:
        raise UserInputError(
            f"--duration-ms = {args.duration_ms:g}: sets the length of a start-up transient; add "
            "--transient (a settled run lasts until settled, then --window-revs revolutions)"
        )
    names = {
        "settle": "--settle",
        "window_revs": "--window-revs",
        "seeds": "--seeds",
        "settle_tolerance": "--settle-tolerance",
        "settle_cap_ms": "--settle-cap-ms",
        "start": "--start",
        "workers": "--workers",
    }
    return steady_settings(
        names,
        settle="auto" if args.settle is None else args.settle,
        window_revs=args.window_revs,
        seeds=args.seeds,
        tolerance=args.settle_tolerance,
        settle_cap_ms=args.settle_cap_ms,
        start=args.start,
        workers=available_cpus() if args.workers is None else args.workers,
    )


def _ci(est, k, fmt=".4g") -> str:
    if not isinstance(est, dict) or est.get("value") is None:
        return "-"
    if est.get("ci95_low") is None:
        return f"{est['value'] * k:{fmt}} (no CI)"
    return f"{est['value'] * k:{fmt}} [{est['ci95_low'] * k:{fmt}}, {est['ci95_high'] * k:{fmt}}]"


def _rpm(value) -> str:
    """A residual drift [rpm] for the table ('-' where none was estimated)."""
    return "-" if value is None else f"{value:.1f}"


def format_table(summaries: dict) -> str:
    """Statistic per row, one column per end type: value [95 % CI]. A run whose solve failed
    before its window was measured has no statistics: it gets one line saying why it failed
    (`_failure_line`), and the table only the end types that were measured."""
    failed = {e: _failure_line(e, s) for e, s in summaries.items() if s.get("status", "ok") != "ok"}
    measured = {e: s for e, s in summaries.items() if e not in failed or s.get("window_ms", 0.0) > 0.0}
    if not measured:
        return "\n".join(failed.values())
    return "\n".join([_statistics_table(measured), *failed.values()])


def _failure_line(end: str, s: dict) -> str:
    """One line for a failed settled run: the end type, the solver's reason and where it failed."""
    return f"[{end}] FAILED: {s['status'].removeprefix('failed: ')}; no statistics (summary.json has the run's record)"


def _statistics_table(summaries: dict) -> str:
    ends = list(summaries)
    w = 36
    head = f"{'quantity (per cage revolution)':<34}{'unit':>8}" + "".join(f"{e:>{w}}" for e in ends)
    lines = [head, "-" * len(head)]
    for key, label, unit, k in _ROWS:
        for stat in ("max", "mean", "median", "p95"):
            row = f"{label + ', ' + stat:<34}{unit:>8}"
            for e in ends:
                row += f"{_ci(summaries[e].get(key, {}).get(stat), k):>{w}}"
            lines.append(row)
    extra = (
        ("contact radius, p99", "mm", lambda s: s.get("contact_radius_m", {}).get("p99"), 1e3),
        (
            "contact radius, max in contact",
            "mm",
            lambda s: s.get("contact_radius_m", {}).get("max_in_contact"),
            1e3,
        ),
        ("corner-contact share, time", "%", lambda s: s.get("corner_contact_share", {}).get("time"), 100.0),
        (
            "corner-contact share, events",
            "%",
            lambda s: s.get("corner_contact_share", {}).get("events"),
            100.0,
        ),
        ("min film h_min, min", "um", lambda s: s.get("flange_min_film_m", {}).get("min"), 1e6),
        ("film parameter Lambda, median", "", lambda s: s.get("film_parameter", {}).get("median"), 1.0),
        ("film parameter Lambda, p05", "", lambda s: s.get("film_parameter", {}).get("p05"), 1.0),
        ("Lambda < 1 share, time", "%", lambda s: s.get("lambda_below_one_share"), 100.0),
        *_friction_power_rows(),
        ("top-edge contact share, time", "%", lambda s: s.get("top_edge_contact_share"), 100.0),
        ("cage speed", "rpm", lambda s: s.get("cage_speed_rpm"), 1.0),
        ("cage slip", "%", lambda s: s.get("cage_slip"), 100.0),
        ("roller skew, mean |.|", "mrad", lambda s: s.get("roller_skew_rad", {}).get("mean_abs"), 1e3),
        ("roller skew, max |.|", "mrad", lambda s: s.get("roller_skew_rad", {}).get("max_abs"), 1e3),
    )
    for label, unit, get, k in extra:
        lines.append(f"{label:<34}{unit:>8}" + "".join(f"{_ci(get(summaries[e]), k):>{w}}" for e in ends))
    lines.append("")
    for e in ends:
        s = summaries[e]
        rho = s.get("limited_circle_radius_m")
        drift = ""
        if s.get("residual_drift_rpm") is not None:
            drift = (
                f"; residual drift {_rpm(s['residual_drift_rpm'])} rpm, "
                f"bound {_rpm(s.get('residual_drift_bound_rpm'))} rpm"
            )
        lines.append(
            f"[{e}] status {s['status']}; settled {str(s['settled']).lower()} ({s['settle_mode']}, "
            f"{s['settle_time_ms']:.1f} ms{drift}); window {s['window_revs']} revolutions = {s['window_ms']:.1f} ms; "
            f"seeds {len(s['seeds'])}; CI: {s.get('ci_method', '-')}; rho_lim "
            f"{'-' if rho is None else format(rho * 1e3, '.3f')} mm; wall {s['wall_time_s']:.1f} s "
            f"(+ compile {s['compile_time_s']:.1f} s)"
        )
        steps = [f"{j:+.1f}" for r in s.get("per_seed", []) for j in r.get("projective_steps_rpm", [])]
        starts = [r.get("start_cage_speed_rpm") for r in s.get("per_seed", [])]
        if s.get("start") == "skid" and starts:
            lines.append(
                f"[{e}] skid start: cage {np.nanmean(starts):.1f} rpm; projective steps of the cage speed "
                f"[rpm]: {', '.join(steps) or 'none'}"
            )
        if s["settle_mode"] == "auto" and not s["settled"] and s["status"] == "ok":
            lines.append(
                f"[{e}] NOT SETTLED: the cage speed's remaining drift (up to "
                f"{_rpm(s.get('residual_drift_bound_rpm'))} rpm) still exceeded {s['settle_tolerance']:.2g} "
                f"of it at the cap of {s['settle_cap_ms']:.0f} ms; the statistics come from a transient "
                "(fix a settling time with --settle MS)"
            )
    return "\n".join(lines)


#: the friction-power rows of the settled table: (label, summary key of the flange or the total)
_FRICTION_POWER_ROWS = (
    ("friction power, total", "total"),
    ("friction power, inner -X", "inner_neg_x"),
    ("friction power, inner +X", "inner_pos_x"),
    ("friction power, outer -X", "outer_neg_x"),
    ("friction power, outer +X", "outer_pos_x"),
)


def _friction_power_rows() -> tuple:
    """(label, unit, getter, scale) of the time-mean friction power per flange and in total [W]."""
    return tuple(
        (label, "W", lambda s, n=name: s.get("flange_friction_power_W", {}).get(n), 1.0)
        for label, name in _FRICTION_POWER_ROWS
    )


def exit_code(summaries: dict) -> int:
    """0 when every end type ran and (with --settle auto) settled; 1 otherwise."""
    ok = all(s["status"] == "ok" for s in summaries.values())
    settled = all(s["settled"] or s["settle_mode"] != "auto" for s in summaries.values())
    return 0 if ok and settled else 1
