"""`optimise` command line: `optimise run [...]`.

Objectives: `--objective steady` (default; `_steady`: the mean flange PV of settled running,
seeds, CIs, the dynamic corner margin, continuation, resume from DIR/checkpoint.npz,
verification on unseen seeds) and `--objective startup` (`_search`: the smooth peak PV of the
first 0.3 ms from a seated start, the old transient objective: fast, but it measures how hard
seated rollers are first driven onto their flanges, not how a design runs).

Prints per-iteration progress (objective, smallest constraint margin and which, design of every
start), the final design with its constraint status and the improvement over the starting
design; writes DIR/result.json and DIR/search_paths.png (search paths over the design-zone
feasibility map), both with the configuration, settings, seeds and command line that produced
them. Exit codes (`jaxbearing.cli.EXIT_CODES`): 0 success, 2 bad input or an unwritable --out
(one line on stderr, before anything is computed; a start design with Lambda_bf < 0 is refused),
3 no feasible design found (none in the bounds, or no iterate reached the zone), 4 the results
could not be written to --out and were kept in the fallback directory printed.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import pathlib
import sys

from jaxbearing import UserInputError

EXIT_INFEASIBLE = 3


def _floats(text: str, name: str) -> list[float]:
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise UserInputError(f"{name} = {text!r}: expected comma-separated numbers") from None
    if not vals or not all(math.isfinite(v) for v in vals):
        raise UserInputError(f"{name} = {text!r}: expected finite comma-separated numbers")
    return vals


def _pair(text: str | None, name: str):
    if text is None:
        return None
    v = _floats(text, name)
    if len(v) != 2:
        raise UserInputError(f"{name} = {text!r}: expected LOWER,UPPER")
    return v


#: defaults of the search settings that are not `SteadySettings` fields (per objective where
#: they differ); the help strings below and `problem_from_settings` both read them
SEARCH_DEFAULTS = {
    "starts": {"steady": 2, "startup": 4},
    "iterations": {"steady": 6, "startup": 20},
    "learning_rate": 0.08,
    "rtol": 1e-3,
    "atol": 1e-6,
    "temperature_GPa_m_s": 0.1,
    "min_clearance_mm": 0.0,
    "aggregate": "max",
    "objective": "steady",
}
OBJECTIVES = ("steady", "startup")
AGGREGATES = ("max", "mean")


def _range_text(pair, k: float) -> str:
    return f"{pair[0] * k:g},{pair[1] * k:g}"


def build_parser() -> argparse.ArgumentParser:
    from jaxbearing.cli import exit_codes_text
    from jaxbearing.flange import DEFAULT_FLANGE_LOAD

    from ._problem import DEFAULT_DURATION, Bounds
    from ._settings import ESTIMATORS, SteadySettings

    st, b, d = SteadySettings(), Bounds(), SEARCH_DEFAULTS
    mm, deg = 1e3, 180 / math.pi
    p = argparse.ArgumentParser(
        prog="optimise",
        description="Gradient-based design of arc-end rollers and flanges: minimise the mean "
        "flange PV of settled running (default; or the start-up peak PV with --objective startup) "
        "over R_end, layback angle and axial clearance inside the design zone.",
        epilog=exit_codes_text(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")

    r = sub.add_parser(
        "run",
        help="run the multi-start projected augmented-Lagrangian design search",
        description="Search the roller-end/flange design (end radius R_end, layback angle "
        "theta_f, axial clearance Delta_bf) that minimises, by default (--objective steady), the "
        "mean flange PV of settled running over seeds, with 95 % confidence intervals, inside the "
        "static design zone (relief, height limit, limited circle, actual axial clearance) and a "
        "dynamic corner margin; the best design is verified on unseen seeds. --objective startup "
        "minimises the smooth peak PV of short start-up runs instead (fast, but it measures the "
        "first impacts, not how a design runs). Several starts (projected augmented Lagrangian "
        "with Adam). Writes DIR/result.json (strict JSON: design, history, the configuration, "
        "settings, seeds and command that produced it) and DIR/search_paths.png; the steady "
        "search checkpoints every iteration in DIR/checkpoint.npz and resumes from it. --out is "
        "checked before anything is computed; results that cannot be written there go to a "
        "fallback directory (exit status 4).",
        epilog=exit_codes_text(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    r.add_argument(
        "--config",
        help="jaxbearing TOML configuration (bearing and operating point) (default: the embedded "
        "reference bearing)",
    )
    r.add_argument(
        "--bounds",
        dest="bounds_file",
        help="optimiser TOML file with [bounds], [constraints], [envelope], [search] sections; "
        "command-line options win (default: none)",
    )
    r.add_argument(
        "--end-radius-mm", help=f"R_end bounds LO,HI [mm] (default: {_range_text(b.end_radius, mm)})"
    )
    r.add_argument(
        "--layback-deg", help=f"theta_f bounds LO,HI [deg] (default: {_range_text(b.layback_angle, deg)})"
    )
    r.add_argument(
        "--clearance-mm", help=f"Delta_bf bounds LO,HI [mm] (default: {_range_text(b.axial_clearance, mm)})"
    )
    r.add_argument(
        "--min-clearance-mm",
        type=float,
        help=f"required actual axial clearance Lambda_bf [mm] (default: {d['min_clearance_mm']:g})",
    )
    r.add_argument(
        "--flange-load-N",
        type=float,
        help=f"flange load of the relief margin's contact ellipse [N] (default: {DEFAULT_FLANGE_LOAD:g})",
    )
    r.add_argument(
        "--speeds-rpm",
        help="operating speeds, e.g. 5000,15000,30000 (default: the configuration's operating.speed_rpm)",
    )
    r.add_argument(
        "--loads-N", help="radial loads, e.g. 500,1000 (default: the configuration's operating.radial_load_N)"
    )
    r.add_argument(
        "--weights", help="weights of the operating points (speeds x loads, speed-major) (default: equal)"
    )
    r.add_argument(
        "--aggregate",
        choices=AGGREGATES,
        help=f"robust objective over the operating points: smooth worst case (max) or weighted mean "
        f"(default: {d['aggregate']})",
    )
    r.add_argument(
        "--objective",
        metavar="{" + ",".join(OBJECTIVES) + "}",  # checked by the code: one-line errors
        help="steady: mean flange PV of settled running over seeds, verified on unseen seeds; "
        f"startup: smooth peak PV of the first {DEFAULT_DURATION * 1e3:g} ms (default: {d['objective']})",
    )
    r.add_argument(
        "--starts",
        type=int,
        help=f"number of starts (default: {d['starts']['steady']} steady, {d['starts']['startup']} startup)",
    )
    r.add_argument(
        "--iterations",
        type=int,
        help=f"iterations (default: {d['iterations']['steady']} steady, {d['iterations']['startup']} startup)",
    )
    r.add_argument(
        "--learning-rate",
        type=float,
        help=f"Adam step size in scaled units (default: {d['learning_rate']:g})",
    )
    r.add_argument("--seeds", type=int, help=f"steady: seeds per evaluation (default: {st.seeds})")
    r.add_argument(
        "--window-revs", type=int, help=f"steady: cage revolutions measured (default: {st.window_revs})"
    )
    r.add_argument(
        "--settle",
        help=f'steady: "auto" or a fixed settling time in ms before the window (default: {st.settle})',
    )
    r.add_argument(
        "--gradient-window-ms",
        type=float,
        help=f"steady: length of the short-window sensitivities [ms] (default: {st.gradient_window * 1e3:g})",
    )
    r.add_argument(
        "--estimator",
        metavar="{" + ",".join(ESTIMATORS) + "}",  # checked by `SteadySettings`: one-line errors
        help="steady: gradient estimator, frozen (frozen-load estimate from the settled states) or "
        f"window (short-window forward-mode sensitivities) (default: {st.estimator})",
    )
    r.add_argument(
        "--corner-margin-mm",
        type=float,
        help="steady: the largest contact radius this far inside the limited circle [mm] "
        f"(default: {st.corner_margin * mm:g})",
    )
    r.add_argument(
        "--statistic",
        metavar="{mean,peak,tail}",  # checked by `SteadySettings`: one-line errors
        help="steady: the flange PV statistic minimised, mean (over contact time), peak (its p-mean, "
        "p = 8, weighting the peaks) or tail (the mean of its worst 5 %%, bounding the p95 from "
        f"above) (default: {st.statistic})",
    )
    r.add_argument(
        "--clearance-step-mm",
        help="steady: half-step of the common-random-number central difference in Delta_bf [mm], "
        "extra members of every evaluation (three times the members), 0: off (the frozen-load "
        "estimator cannot see the clearance); auto: 0.01 where an operating point is misaligned "
        "by more than 1 mrad, where the clearance study found the slope significant, else off "
        f"(default: {st.clearance_step})",
    )
    r.add_argument(
        "--corner-constraint",
        metavar="{risk,prediction,mean}",  # checked by `SteadySettings`: one-line errors
        help="steady: the dynamic corner margin on the contact radius one revolution exceeds with "
        "probability --corner-risk-level at most, at 95 %% confidence (risk: the corner-contact risk "
        "bounded), on the upper 95 %% prediction bound of one revolution's largest contact radius "
        "(prediction) or on its expectation per revolution (mean) "
        f"(default: {st.corner_constraint})",
    )
    r.add_argument(
        "--choose",
        metavar="{safest,best}",  # checked by `SteadySettings`: one-line errors
        help="steady: the design returned: of the feasible designs statistically tied with the one of the "
        "lowest upper 95 %% bound of the objective, the one of the lowest corner-risk bound (safest), or "
        f"that one itself (best) (default: {st.choose})",
    )
    r.add_argument(
        "--skip-weight",
        type=float,
        help="steady, smooth max: an operating point whose weight in the objective stays below this is "
        f"not simulated, at most --recheck-every iterations in a row; 0: every point, every iteration "
        f"(default: {st.skip_weight:g})",
    )
    r.add_argument(
        "--recheck-every",
        type=int,
        help=f"steady: every operating point is simulated at least every N iterations (default: {st.recheck_every})",
    )
    r.add_argument(
        "--verify-seeds",
        type=int,
        help=f"steady: unseen seeds of the verification (default: {st.verify_seeds})",
    )
    r.add_argument(
        "--corner-risk-level",
        type=float,
        help="steady: the corner-contact risk per cage revolution the search keeps below (--corner-constraint "
        "risk) and the verification must bound (upper 95 %% bound) at every operating point, else the design "
        f"is reported unverified in the tail (default: {st.corner_risk_level:g})",
    )
    r.add_argument("--no-verify", action="store_true", help="steady: skip the verification (default: verify)")
    r.add_argument(
        "--workers",
        type=int,
        help=f"steady: processes; 0 = one per CPU (default: {st.workers}, one per CPU)",
    )
    r.add_argument(
        "--duration-ms",
        type=float,
        help=f"startup: simulated time per evaluation [ms] (default: {DEFAULT_DURATION * 1e3:g})",
    )
    r.add_argument("--rtol", type=float, help=f"solver rtol (default: {d['rtol']:g})")
    r.add_argument(
        "--atol",
        type=float,
        help=f"startup: solver atol on the scaled state, {d['atol']:g} = 10 nm, 10 um/s, 0.01 rad/s "
        f"(default: {d['atol']:g})",
    )
    r.add_argument("--out", default="optimise_out", help="output directory (default: %(default)s)")
    r.add_argument("--quiet", action="store_true", help="no per-iteration progress (default: progress shown)")
    r.set_defaults(func=run)
    return p


def _settings(args) -> dict:
    """Merge the optional TOML file with the command-line options (options win)."""
    from ._problem import load_optimise_toml

    s = load_optimise_toml(args.bounds_file) if args.bounds_file else {}
    for key, value in (
        ("end_radius_mm", _pair(args.end_radius_mm, "--end-radius-mm")),
        ("layback_angle_deg", _pair(args.layback_deg, "--layback-deg")),
        ("axial_clearance_mm", _pair(args.clearance_mm, "--clearance-mm")),
        ("min_clearance_mm", args.min_clearance_mm),
        ("flange_load_N", args.flange_load_N),
        ("speeds_rpm", _floats(args.speeds_rpm, "--speeds-rpm") if args.speeds_rpm else None),
        ("loads_N", _floats(args.loads_N, "--loads-N") if args.loads_N else None),
        ("weights", _floats(args.weights, "--weights") if args.weights else None),
        ("aggregate", args.aggregate),
        ("objective", args.objective),
        ("starts", args.starts),
        ("iterations", args.iterations),
        ("seeds", args.seeds),
        ("window_revs", args.window_revs),
        ("settle", args.settle),
        ("gradient_window_ms", args.gradient_window_ms),
        ("estimator", args.estimator),
        ("corner_margin_mm", args.corner_margin_mm),
        ("clearance_step_mm", args.clearance_step_mm),
        ("statistic", args.statistic),
        ("corner_constraint", args.corner_constraint),
        ("choose", args.choose),
        ("skip_weight", args.skip_weight),
        ("recheck_every", args.recheck_every),
        ("verify_seeds", args.verify_seeds),
        ("corner_risk_level", args.corner_risk_level),
        ("workers", args.workers),
        ("learning_rate", args.learning_rate),
        ("duration_ms", args.duration_ms),
        ("rtol", args.rtol),
        ("atol", args.atol),
    ):
        if value is not None:
            s[key] = value
    return s


def _positive(s: dict, key: str, default, kind=float, strict=True):
    v = s.get(key, default)
    try:
        v = kind(v)
    except (TypeError, ValueError):
        raise UserInputError(f"{key} = {v!r}: expected a {kind.__name__}") from None
    if not (math.isfinite(v) and (v > 0 if strict else v >= 0)):
        raise UserInputError(f"{key} = {v}: must be {'> 0' if strict else '>= 0'}")
    return v


def _clearance_step(s: dict):
    """`SteadySettings.clearance_step` from `clearance_step_mm`: "auto" (the default) or >= 0 mm."""
    v = s.get("clearance_step_mm", "auto")
    return "auto" if v == "auto" else _positive(s, "clearance_step_mm", 0.0, strict=False) * 1e-3


def problem_from_settings(bearing, op, s: dict):
    """DesignProblem and search options from merged settings (engineering units)."""
    from ._problem import DEFAULT_DURATION, bounds_from_engineering, make_problem

    bounds = bounds_from_engineering(
        s.get("end_radius_mm"), s.get("layback_angle_deg"), s.get("axial_clearance_mm")
    )
    problem = make_problem(
        bearing,
        op,
        bounds=bounds,
        speeds_rpm=s.get("speeds_rpm"),
        loads_N=s.get("loads_N"),
        weights=s.get("weights"),
        duration=_positive(s, "duration_ms", DEFAULT_DURATION * 1e3) * 1e-3,
        flange_load=_positive(s, "flange_load_N", 100.0),
        min_clearance=_positive(s, "min_clearance_mm", SEARCH_DEFAULTS["min_clearance_mm"], strict=False)
        * 1e-3,
        aggregate=s.get("aggregate", SEARCH_DEFAULTS["aggregate"]),
        temperature=_positive(s, "temperature_GPa_m_s", SEARCH_DEFAULTS["temperature_GPa_m_s"]),
        rtol=_positive(s, "rtol", SEARCH_DEFAULTS["rtol"]),
        atol=_positive(s, "atol", SEARCH_DEFAULTS["atol"]),
    )
    objective = objective_of(s)
    options = dict(
        num_starts=int(_positive(s, "starts", SEARCH_DEFAULTS["starts"][objective], int)),
        num_iterations=int(_positive(s, "iterations", SEARCH_DEFAULTS["iterations"][objective], int)),
        learning_rate=_positive(s, "learning_rate", SEARCH_DEFAULTS["learning_rate"]),
    )
    return problem, options


def objective_of(s: dict) -> str:
    objective = s.get("objective", SEARCH_DEFAULTS["objective"])
    if objective not in OBJECTIVES:
        raise UserInputError(f"objective = {objective!r}: must be 'steady' or 'startup'")
    return objective


def steady_settings_from(s: dict):
    """SteadySettings from merged settings (engineering units)."""
    from ._settings import SteadySettings

    st = SteadySettings()
    settle = s.get("settle", st.settle)
    if settle != "auto":
        settle = _positive({"settle": settle}, "settle", 0.0, strict=False)
    return SteadySettings(
        seeds=int(_positive(s, "seeds", st.seeds, int)),
        window_revs=int(_positive(s, "window_revs", st.window_revs, int)),
        settle=settle,
        gradient_window=_positive(s, "gradient_window_ms", st.gradient_window * 1e3) * 1e-3,
        estimator=s.get("estimator", st.estimator),
        corner_margin=_positive(s, "corner_margin_mm", st.corner_margin * 1e3, strict=False) * 1e-3,
        rtol=_positive(s, "rtol", SEARCH_DEFAULTS["rtol"]),
        workers=int(_positive(s, "workers", st.workers, int, strict=False)),
        verify_seeds=int(_positive(s, "verify_seeds", st.verify_seeds, int)),
        clearance_step=_clearance_step(s),
        statistic=s.get("statistic", st.statistic),
        corner_constraint=s.get("corner_constraint", st.corner_constraint),
        choose=s.get("choose", st.choose),
        skip_weight=_positive(s, "skip_weight", st.skip_weight, strict=False),
        recheck_every=int(_positive(s, "recheck_every", st.recheck_every, int)),
        corner_risk_level=float(s.get("corner_risk_level", st.corner_risk_level)),
    )


def _design_text(x) -> str:
    return f"R_end {x[0] * 1e3:7.2f} mm  theta_f {math.degrees(x[1]):6.3f} deg  Delta_bf {x[2] * 1e3:6.4f} mm"


def _margin_text(m) -> str:
    from jaxbearing.flange import MARGIN_NAMES

    return "  ".join(
        f"{n} {v * 1e3:+.4f} mm {'OK' if v > 0 else 'VIOLATED'}" for n, v in zip(MARGIN_NAMES, m)
    )


def _progress(quiet: bool, start_line):
    """The per-iteration progress callback of both searches: the best feasible objective, then
    one line per start (`start_line(j, info, margins, index of the smallest margin)`)."""
    import numpy as np

    def progress(it, info):
        if quiet:
            return
        best = info.best
        print(
            f"iter {it:3d}  best feasible {best:.4f} GPa m/s"
            if np.isfinite(best)
            else f"iter {it:3d}  best feasible   none yet"
        )
        for j in range(info.x.shape[0]):
            m = info.margins[j]
            print(f"   start {j}: " + start_line(j, info, m, int(np.argmin(m))))
        sys.stdout.flush()

    return progress


def run(args) -> int:
    import numpy as np

    from jaxbearing import load_config
    from jaxbearing.flange import MARGIN_NAMES
    from jaxbearing.io import check_output_dir, plausibility_warnings

    from ._plot import plot_search
    from ._search import search

    try:
        cfg = load_config(args.config)
    except UserInputError as exc:
        raise UserInputError(f"{args.config}: {exc}") from None
    bearing, op = cfg.bearing(), cfg.operating_point()
    s = _settings(args)
    problem, options = problem_from_settings(bearing, op, s)
    steady = steady_settings_from(s) if objective_of(s) == "steady" else None
    # every input is checked before --out is made, so a rejected command leaves no directory
    check_output_dir(args.out, "--out")
    for line in plausibility_warnings(cfg):
        print(f"warning: {line}", file=sys.stderr)
    check_start_design(cfg, problem)
    out = pathlib.Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserInputError(f"--out {args.out}: cannot create directory: {exc.strerror}") from None
    meta = _provenance(cfg, s, steady)

    if steady is not None:
        return run_steady(args, problem, options, steady, out, meta)
    k = problem.num_operating_points
    print(
        f"optimise: {options['num_starts']} starts x {k} operating point(s), "
        f"{options['num_iterations']} iterations, {problem.duration * 1e3:g} ms per evaluation "
        f"({problem.aggregate} over the envelope)"
    )

    def start_line(j, info, m, w):
        return (
            f"J {info.objective[j]:8.4f} GPa m/s  "
            f"min margin {MARGIN_NAMES[w]} {m[w] * 1e3:+.4f} mm  {_design_text(info.x[j])}"
            f"{'' if info.feasible[j] else '  (infeasible)'}"
        )

    progress = _progress(args.quiet, start_line)

    res = search(problem, callback=progress, **options)
    result = {**_result_json(problem, options, res), **meta}
    out, saved = _write_results(args.out, result, lambda d: plot_search(problem, res, d / "search_paths.png"))
    if saved:
        return saved
    plot_path = out / "search_paths.png"

    print(f"start design: {_design_text(res.start_design)}")
    print(f"  margins: {_margin_text(res.start_margins)}")
    if res.status == "no_feasible_design_in_bounds":
        print(
            "optimise: no feasible design exists within the bounds (every design-zone margin "
            "cannot be satisfied at once); widen the bounds or relax --min-clearance-mm",
            file=sys.stderr,
        )
        print(f"wrote {out / 'result.json'} and {plot_path}")
        return EXIT_INFEASIBLE
    if res.status == "no_feasible_iterate":
        print(
            "optimise: no iterate reached the feasible design zone (it exists within the bounds);"
            " try more --iterations or --starts",
            file=sys.stderr,
        )
        print(f"wrote {out / 'result.json'} and {plot_path}")
        return EXIT_INFEASIBLE
    print(
        f"final design: {_design_text(res.design)}  (start {res.best_start}, iteration {res.best_iteration})"
    )
    print(f"  margins: {_margin_text(res.margins)}  -> feasible")
    print(
        f"  smooth peak PV {res.objective:.4f} GPa m/s (start {res.start_objective:.4f}); "
        f"improvement {100 * res.improvement:.1f}%"
        + ("" if np.all(res.start_margins > 0) else " over an infeasible start")
    )
    print(
        f"  {res.num_model_evaluations} model evaluations (value + forward-mode gradient), "
        f"{res.wall_time_s:.1f} s (compile {res.compile_time_s:.1f} s)"
    )
    print(f"wrote {out / 'result.json'} and {plot_path}")
    return 0


def check_start_design(cfg, problem) -> None:
    """Refuse, in one line naming the keys, a start design whose actual axial clearance
    Lambda_bf is negative (the rollers do not fit between the flanges: no run of it means
    anything, and the search would start from a jammed bearing)."""
    from jaxbearing.flange import design_zone

    bearing = cfg.bearing()
    lam = float(design_zone(bearing, problem.flange_load).actual_axial_clearance)
    if not lam >= 0:
        raise UserInputError(
            f"flange.axial_clearance_mm = {cfg['flange.axial_clearance_mm']:g} mm with "
            f"roller.end_radius_mm = {cfg['roller.end_radius_mm']:g} mm and flange.layback_angle_deg = "
            f"{cfg['flange.layback_angle_deg']:g} deg: the start design's actual axial clearance "
            f"Lambda_bf = {lam * 1e3:+.4f} mm is negative (the rollers do not fit between the "
            "flanges); start from a design with Lambda_bf >= 0 (see `jaxbearing zone`)"
        )


def _provenance(cfg, s: dict, steady) -> dict:
    """What produced result.json (`jaxbearing.io.provenance`): version, command line, the full
    configuration in engineering units, the merged optimiser settings, the seeds; and the unit
    convention of its keys."""
    from jaxbearing.io import provenance

    seeds = None
    if steady is not None:
        seeds = {
            "search": list(range(steady.seeds)),
            "verification": list(
                range(steady.verify_first_seed, steady.verify_first_seed + steady.verify_seeds)
            ),
        }
    else:
        seeds = {"search": [0]}  # every evaluation starts from Perturbation(seed=0)
    meta = provenance(cfg, seeds=seeds)
    meta["optimiser_settings"] = dict(s)
    meta["units"] = (
        "in each key's suffix: _mm, _deg, _N, _rpm, _ms, _s, _GPa_m_s (GPa m/s), _Pa_m_s; "
        "margins in mm; design variables R_end [mm], theta_f [deg], Delta_bf [mm]; others dimensionless"
    )
    return meta


def _write_results(out, result: dict, plot) -> tuple[pathlib.Path, int]:
    """result.json and the plot into `out`, or into a fallback directory when that fails:
    (the directory used, 0 or `EXIT_RESULTS_ELSEWHERE` after one line naming it)."""
    from jaxbearing.cli import report_fallback
    from jaxbearing.io import write_json, write_or_fallback

    def write(d):
        write_json(d / "result.json", result)
        plot(d)

    used, reason = write_or_fallback(out, write)
    return used, report_fallback("optimise run", out, used, reason)


def run_steady(args, problem, options, settings, out, meta=None) -> int:
    """`optimise run --objective steady` (the default): `_steady.steady_search` with progress,
    checkpoint and resume in `out`, verification, result.json and the search-path plot."""

    from jaxbearing.run import MemberProgress

    from ._plot import plot_search
    from ._state import CHECKPOINT
    from ._steady import CONSTRAINT_NAMES, near_optimal_set, steady_search

    k = problem.num_operating_points
    print(
        f"optimise (steady running): {options['num_starts']} starts x {k} operating point(s), "
        f"{options['num_iterations']} iterations; each evaluation {settings.seeds} seeds, settle "
        f"{settings.settle}, {settings.window_revs}-revolution window, gradient from "
        f"{2 * settings.seeds} windows of {settings.gradient_window * 1e3:g} ms; checkpoint in {out}"
    )
    sys.stdout.flush()

    def start_line(j, info, m, w):
        lo, hi = info.ci[j]
        g = info.gradient[j]
        return (
            f"J {info.objective[j]:7.4f} [{lo:.4f}, {hi:.4f}] GPa m/s  "
            f"min margin {CONSTRAINT_NAMES[w]} {m[w] * 1e3:+.4f} mm  {_design_text(info.x[j])}  "
            f"dJ/du ({g[0]:+.3f}, {g[1]:+.3f}, {g[2]:+.3f})"
        )

    progress = _progress(args.quiet, start_line)

    # a line at least every 30 s while members settle: an evaluation takes minutes
    heartbeat = contextlib.nullcontext() if args.quiet else MemberProgress(30.0, label="   ")
    with heartbeat:
        res = steady_search(
            problem, settings, directory=out, callback=progress, verify=not args.no_verify, **options
        )
    if res.resumed_from >= 0 and not args.quiet:
        print(f"(resumed after iteration {res.resumed_from} from {out / CHECKPOINT})")
    result = {**_steady_result_json(problem, options, settings, res), **(meta or {})}
    out, saved = _write_results(out, result, lambda d: plot_search(problem, res, d / "search_paths.png"))
    if saved:
        return saved
    plot_path = out / "search_paths.png"
    if res.status != "ok":
        print(
            "optimise: no feasible design within the bounds"
            if res.status == "no_feasible_design_in_bounds"
            else "optimise: no iterate satisfied every static and dynamic margin; try more --iterations",
            file=sys.stderr,
        )
        print(f"wrote {out / 'result.json'} and {plot_path}")
        return EXIT_INFEASIBLE
    lo, hi = res.objective_ci
    print(
        f"final design: {_design_text(res.design)}  (start {res.best_start}, iteration {res.best_iteration})"
    )
    what = {"mean": "mean PV", "peak": "peak PV (p-mean)", "tail": "tail PV"}.get(settings.statistic, "PV")
    print(f"  steady {what} {res.objective:.4f} [{lo:.4f}, {hi:.4f}] GPa m/s (search seeds)")
    near = near_optimal_set(res)
    if near:
        binds = sorted({d.binding_margin for d in near})
        print(
            f"  near-optimal set: {len(near)} evaluated design(s) statistically tied with the best, "
            f"binding margin {', '.join(binds)} (result.json near_optimal; drawn on {plot_path.name}); "
            f"returned: the {settings.choose} of them"
        )
        for d in near[:5]:
            print(
                f"    {_design_text(d.design)}  J {d.objective:.4f} [{d.ci95[0]:.4f}, {d.ci95[1]:.4f}]  "
                f"corner risk <= {d.corner_risk:.2g}/rev  corner margin {d.corner_margin_m * 1e3:+.3f} mm"
            )
    v = res.verification
    if v:
        import numpy as np

        from jaxbearing.geometry import rad_s_to_rpm

        speeds = np.asarray(rad_s_to_rpm(np.asarray(problem.operating.inner_speed))).ravel()
        loads = np.asarray(problem.operating.radial_load).ravel()
        for k in range(problem.num_operating_points):
            where = f" at {speeds[k]:.0f} rpm, {loads[k]:.0f} N" if problem.num_operating_points > 1 else ""
            for name in ("reference", "optimum"):
                row = v[name] if "mean_pv_GPa_m_s" in v[name] else v[name]["per_operating_point"][k]
                label = name if where else f"{name:9s}"
                seeds = f"seeds {v['seeds'][0]}-{v['seeds'][-1]}"
                print(f"  verification {label}{where}: {_verified_text(row)} ({seeds})")
        if "mean_pv_lower_disjoint" in v:
            print(
                "  verified lower mean PV with disjoint 95 % CIs"
                f"{' at every operating point' if problem.num_operating_points > 1 else ''}: "
                f"{v['mean_pv_lower_disjoint']}"
            )
        tail = v.get("tail")
        if tail is not None:
            print(f"  {tail_text(tail)}")
    print(f"  {res.num_evaluations} settled ensembles, {res.wall_time_s:.1f} s wall")
    print(f"wrote {out / 'result.json'} and {plot_path}")
    return 0


def tail_text(tail: dict) -> str:
    """The verification's statement on the found design's corner-contact risk, in one line."""
    bound = (
        f"corner-contact risk of the found design at most {tail['upper_per_revolution']:.2g} per cage "
        f"revolution at every operating point (upper 95 % bound, {min(tail['revolutions_per_point'])} or more "
        "revolutions per point)"
    )
    if tail["verified"]:
        return f"{bound}: verified in the tail at {tail['level_per_revolution']:.2g} per revolution"
    return (
        f"{bound}: NOT verified in the tail at {tail['level_per_revolution']:.2g} per revolution "
        f"(that takes {tail['revolutions_needed']} revolutions per point without corner contact: "
        "more --verify-seeds, or an accelerator)"
    )


def _verified_text(row: dict) -> str:
    """One design's verification at one operating point, in one line."""
    e, c = row["mean_pv_GPa_m_s"], row["corner_contact_share"]

    def interval(name: str, key: str) -> str:
        v = row.get(key) or {}
        if None in (v.get("value"), v.get("ci95_low"), v.get("ci95_high")):
            return ""
        return f", {name} {v['value']:.3f} [{v['ci95_low']:.3f}, {v['ci95_high']:.3f}]"

    peak = interval("peak PV", "peak_pv_GPa_m_s") + interval("tail PV", "tail_pv_GPa_m_s")
    return (
        f"mean PV {e['value']:.4f} [{e['ci95_low']:.4f}, {e['ci95_high']:.4f}]{peak} GPa m/s, "
        f"corner share {c['value']:.3f}"
    )


def _engineering(x):
    if x is None:
        return None
    return {
        "end_radius_mm": float(x[0]) * 1e3,
        "layback_angle_deg": math.degrees(float(x[1])),
        "axial_clearance_mm": float(x[2]) * 1e3,
    }


def _steady_result_json(problem, options, settings, res) -> dict:
    import dataclasses

    import numpy as np

    from ._settings import CLEARANCE_MISALIGNMENT, CLEARANCE_STEP, clearance_step_for
    from ._steady import CONSTRAINT_NAMES, near_optimal_set

    h = res.history
    clearance_step = clearance_step_for(problem, settings)
    x = np.asarray(h.x) if len(h) else np.zeros((0, 0, 3))
    margins = np.asarray(h.margins) if len(h) else np.zeros((0, 0, 5))
    return {
        "objective_kind": "steady",
        "status": res.status,
        "feasible": bool(res.feasible),
        "design": _engineering(res.design),
        "objective_GPa_m_s": {
            "value": res.objective,
            "ci95_low": None if res.objective_ci is None else res.objective_ci[0],
            "ci95_high": None if res.objective_ci is None else res.objective_ci[1],
        },
        "start_design": _engineering(res.start_design),
        "verification": res.verification,
        "near_optimal": [
            {
                **_engineering(d.design),
                "objective_GPa_m_s": {"value": d.objective, "ci95_low": d.ci95[0], "ci95_high": d.ci95[1]},
                "iteration": d.iteration,
                "start": d.start,
                "binding_margin": d.binding_margin,
                "binding_margin_mm": d.binding_margin_m * 1e3,
                "corner_risk_per_revolution_upper95": None
                if not np.isfinite(d.corner_risk)
                else d.corner_risk,
                "corner_margin_mm": d.corner_margin_m * 1e3,
            }
            for d in near_optimal_set(res)
        ],
        "axial_clearance_effect": {
            "estimator_sees_it": False,
            "why": "the frozen-load estimator moves the flange in its own plane at a fixed load: its "
            "dJ/dDelta_bf is 0 by construction; Delta_bf moves only where a margin pushes it",
            "measured": "docs/model.md 17: the clearance study (significant only with the inner ring "
            "misaligned by 2 mrad)",
            **(
                {
                    "estimator_sees_it": True,
                    "why": "common-random-number central differences of the settled objective in "
                    f"Delta_bf (half-step {clearance_step * 1e3:g} mm, the same seeds from the same "
                    "states, extra members of every evaluation), used where significant at 5 % and 0 "
                    "otherwise: history gradient and gradient_stderr",
                }
                if clearance_step > 0
                else {}
            ),
            "step_mm": clearance_step * 1e3,
            "step_rule": f"clearance_step = {settings.clearance_step!r}: 'auto' takes "
            f"{CLEARANCE_STEP * 1e3:g} mm where an operating point is misaligned by more than "
            f"{CLEARANCE_MISALIGNMENT * 1e3:g} mrad, else 0 (off)",
            "moved": bool(
                res.design is not None and abs(float(res.design[2]) - float(res.start_design[2])) > 1e-12
            ),
        },
        "near_optimal_rule": (
            "every feasible design the search evaluated that is statistically tied with the best (its "
            "objective's 95 % interval reaches below the upper bound of the design of the lowest upper bound; "
            "search seeds), best first; binding_margin: its smallest margin; corner_risk_per_revolution_upper95: "
            "the upper 95 % bound of its corner-contact risk per cage revolution at its worst operating point"
        ),
        "choice_rule": (
            f"choose = {settings.choose!r}: 'safest' returns the tied design of the lowest corner-risk bound "
            "(then the largest dynamic corner margin), 'best' the one of the lowest upper bound of the objective"
        ),
        "bounds": problem.bounds.engineering(),
        "operating_points": [
            {"speed_rpm": float(w) * 60 / (2 * math.pi), "load_N": float(f)}
            for w, f in zip(
                np.asarray(problem.operating.inner_speed), np.asarray(problem.operating.radial_load)
            )
        ],
        "weights": [float(v) for v in np.asarray(problem.weights)],
        "aggregate": problem.aggregate,
        "settings": {
            k: (v if not isinstance(v, float) else float(v)) for k, v in dataclasses.asdict(settings).items()
        },
        "search": dict(options),
        "num_settled_ensembles": res.num_evaluations,
        "simulated_ms": float(np.sum(h.simulated_ms)) if len(h) else 0.0,
        "resumed_from_iteration": res.resumed_from,
        "wall_time_s": res.wall_time_s,
        "history": {
            "objective_GPa_m_s": np.asarray(h.objective).tolist(),
            "ci95_GPa_m_s": np.asarray(h.ci).tolist(),
            "gradient_per_unit_box": np.asarray(h.gradient).tolist(),
            "gradient_stderr": np.asarray(h.gradient_stderr).tolist(),
            "end_radius_mm": (x[..., 0] * 1e3).tolist(),
            "layback_angle_deg": np.degrees(x[..., 1]).tolist(),
            "axial_clearance_mm": (x[..., 2] * 1e3).tolist(),
            "margins_mm": {n: (margins[..., i] * 1e3).tolist() for i, n in enumerate(CONSTRAINT_NAMES)},
            "wall_s": np.asarray(h.wall_s).tolist(),
            "simulated_ms": np.asarray(h.simulated_ms).tolist(),
            # per iteration, start and operating point: simulated (True) or its last values reused
            "points_simulated": np.asarray(h.points_simulated, dtype=bool).tolist(),
        },
    }


def _result_json(problem, options, res) -> dict:
    import numpy as np

    from jaxbearing.flange import MARGIN_NAMES

    design = _engineering

    def margins(m):
        return None if m is None else {f"{n}_margin_mm": float(v) * 1e3 for n, v in zip(MARGIN_NAMES, m)}

    def fin(v):
        return float(v) if v is not None and np.isfinite(v) else None

    ops = problem.operating
    h = res.history
    return {
        "status": res.status,
        "feasible": bool(res.feasible),
        "design": design(res.design),
        "margins": margins(res.margins),
        "objective_GPa_m_s": fin(res.objective),
        "peak_pv_GPa_m_s": None if res.peak_pv is None else [float(v) for v in res.peak_pv],
        "start_design": design(res.start_design),
        "start_margins": margins(res.start_margins),
        "start_feasible": bool(np.all(res.start_margins > 0)),
        "start_objective_GPa_m_s": fin(res.start_objective),
        "improvement": fin(res.improvement),
        "bounds": problem.bounds.engineering(),
        "operating_points": [
            {"speed_rpm": float(w) * 60 / (2 * math.pi), "load_N": float(f)}
            for w, f in zip(np.asarray(ops.inner_speed), np.asarray(ops.radial_load))
        ],
        "weights": [float(v) for v in np.asarray(problem.weights)],
        "aggregate": problem.aggregate,
        "duration_ms": problem.duration * 1e3,
        "min_clearance_mm": problem.min_clearance * 1e3,
        "flange_load_N": problem.flange_load,
        "search": dict(options),
        "num_model_evaluations": res.num_model_evaluations,
        "wall_time_s": res.wall_time_s,
        "compile_time_s": res.compile_time_s,
        "history": {
            "objective_GPa_m_s": np.asarray(h["objective"]).tolist() if h else [],
            "end_radius_mm": (np.asarray(h["x"])[..., 0] * 1e3).tolist() if h else [],
            "layback_angle_deg": np.degrees(np.asarray(h["x"])[..., 1]).tolist() if h else [],
            "axial_clearance_mm": (np.asarray(h["x"])[..., 2] * 1e3).tolist() if h else [],
            "min_margin_mm": (np.asarray(h["margins"]).min(axis=-1) * 1e3).tolist() if h else [],
        },
    }


def main(argv: list[str] | None = None) -> int:
    from jaxbearing.cli import dispatch

    return dispatch(build_parser(), argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
