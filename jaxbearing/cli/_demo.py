"""`jaxbearing demo`: summary of the embedded reference bearing."""

from __future__ import annotations


def register(sub) -> None:
    p = sub.add_parser(
        "demo",
        help="summarise the reference bearing and simulate it with arc and corner roller ends",
        description="Print the embedded reference bearing, then run it at 20,000 rpm and 1000 N "
        "with arc-end and corner-end rollers from the skid start until settled, measure a window of "
        "cage revolutions, and compare the flange contacts (with 95 % confidence intervals) with the "
        "source study.",
    )
    p.add_argument(
        "--window-revs",
        type=float,
        default=4,
        help="measurement window [cage revolutions] (default: %(default)g)",
    )
    p.add_argument(
        "--transient",
        action="store_true",
        help="instead: one fixed-duration run per end type from the quasi-static start (--duration-ms) "
        "(default: settled running from the skid start)",
    )
    p.add_argument(
        "--duration-ms",
        type=float,
        default=20.0,
        help="with --transient: simulated time per end type [ms] (default: %(default)g)",
    )
    p.add_argument(
        "--out", default="out/demo", help="output directory, checked before the solve (default: %(default)s)"
    )
    p.add_argument(
        "--summary-only",
        action="store_true",
        help="only print the bearing summary (default: summary, runs and outputs)",
    )
    p.set_defaults(func=run)


#: the source study's stated values (Machines 2025, 13(11), 993, section 3; docs/validation.md); its
#: sliding velocity is the roller's surface speed at the contact (docs/validation.md, "What differs")
PAPER = (
    ("peak pressure, max", "flange_pressure_Pa", "max", 1e-9, "GPa", "about 4.8", "below 0.2"),
    ("surface speed, mean", "flange_roller_surface_speed_m_s", "mean", 1.0, "m/s", "20", "13.5"),
    ("material sliding, mean", "flange_sliding_velocity_m_s", "mean", 1.0, "m/s", "-", "-"),
    ("PV, max", "flange_pv_Pa_m_s", "max", 1e-9, "GPa m/s", "-", "below 3"),
    ("contact force, max", "flange_force_N", "max", 1.0, "N", "slightly below arc", "-"),
)


def _paper_value(v, k: float) -> str:
    """A number, or a settled estimate {"value", "ci95_low", "ci95_high"} as value [low, high]."""
    if isinstance(v, dict):
        if v.get("value") is None:
            return "-"
        if v.get("ci95_low") is None:
            return format(v["value"] * k, ".3g")
        return f"{v['value'] * k:.3g} [{v['ci95_low'] * k:.3g}, {v['ci95_high'] * k:.3g}]"
    return "-" if v is None else format(v * k, ".3g")


def paper_table(summaries: dict) -> str:
    w = 24
    lines = [f"{'quantity':<24}{'unit':>9}{'corner':>{w}}{'paper':>20}{'arc':>{w}}{'paper':>12}"]
    for label, key, stat, k, unit, p_corner, p_arc in PAPER:
        vals = [_paper_value(summaries.get(end, {}).get(key, {}).get(stat), k) for end in ("corner", "arc")]
        lines.append(f"{label:<24}{unit:>9}{vals[0]:>{w}}{p_corner:>20}{vals[1]:>{w}}{p_arc:>12}")
    return "\n".join(lines)


def summary_lines(bearing, op) -> list[str]:
    from ..geometry import kinematic_cage_speed, rad_s_to_rpm

    r = bearing.roller
    i_ax, i_tr = (float(v) for v in bearing.roller_inertia)
    c_p, c_t = (float(v) for v in bearing.cage_inertia)
    return [
        "Reference bearing (representative aero-engine mainshaft bearing, not the paper's Table 1)",
        f"  pitch diameter            {float(bearing.pitch_diameter) * 1e3:9.3f} mm",
        f"  rollers                   {bearing.num_rollers} x D {float(r.diameter) * 1e3:.3f} mm"
        f" x L {float(r.length) * 1e3:.3f} mm, R_end {float(r.end_radius) * 1e3:.1f} mm",
        f"  roller mass               {float(bearing.roller_mass) * 1e3:9.4f} g",
        f"  roller inertia axial      {i_ax:9.4e} kg m^2",
        f"  roller inertia transverse {i_tr:9.4e} kg m^2",
        f"  cage mass                 {float(bearing.cage_mass) * 1e3:9.3f} g",
        f"  cage inertia polar        {c_p:9.4e} kg m^2",
        f"  cage inertia transverse   {c_t:9.4e} kg m^2",
        f"  inner ring speed          {float(rad_s_to_rpm(op.inner_speed)):9.1f} rpm",
        f"  radial load               {float(op.radial_load):9.1f} N",
        f"  kinematic cage speed      {float(rad_s_to_rpm(kinematic_cage_speed(bearing, op))):9.1f} rpm",
    ]


def run(args) -> int:

    from ..io import reference_config
    from . import _steady
    from ._simulate import format_table, run_cases, write_outputs

    cfg = reference_config().replace(**{"simulation.duration_ms": args.duration_ms, "simulation.end": "both"})
    print("\n".join(summary_lines(cfg.bearing(), cfg.operating_point())))
    if args.summary_only:
        return 0
    from ._simulate import _check_out

    _check_out(args.out)
    steady = None
    if not args.transient:
        from ..run import steady_settings

        steady = steady_settings({"window_revs": "--window-revs"}, window_revs=args.window_revs)
    print()
    results = run_cases(cfg, progress=True, steady=steady)
    summaries = {e: s for e, (_, s) in results.items()}
    print()
    print(_steady.format_table(summaries) if steady else format_table(summaries))
    print()
    what = "settled running, 95 % CI" if steady else f"a {args.duration_ms:g} ms start-up transient"
    print(
        f"Against the source study ({what}; its bearing differs: compare trends and magnitudes, see docs/validation.md):"
    )
    print(paper_table(summaries))
    from ..io import write_or_fallback
    from ._main import report_fallback

    used, reason = write_or_fallback(args.out, lambda d: write_outputs(d, results, cfg, steady))
    if reason is not None:
        return report_fallback("jaxbearing demo", args.out, used, reason)
    print(f"\nsummary.json, histories and plots written to {args.out}/")
    ok = all(s["status"] == "ok" for s in summaries.values())
    return 0 if ok and (steady is None or _steady.exit_code(summaries) == 0) else 1
