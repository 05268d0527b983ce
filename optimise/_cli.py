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
import math
import pathlib
import sys

from jaxbearing import UserInputError

from ._cli_settings import (
    AGGREGATES,
    OBJECTIVES,
    SEARCH_DEFAULTS,
    _provenance,
    _settings,
    check_start_design,
    constant_corners,
    objective_of,
    problem_from_settings,
    steady_settings_from,
)


def _range_text(pair, k: float) -> str:
    return f"{pair[0] * k:g},{pair[1] * k:g}"


def build_parser() -> argparse.ArgumentParser:
    from jaxbearing.cli import exit_codes_text
    from jaxbearing.flange import DEFAULT_FLANGE_LOAD

    from ._bounds import PROFILE_TABLE, ProfileBounds
    from ._cli_settings import PROFILE_OPTIONS
    from ._problem import DEFAULT_DURATION, Bounds
    from ._settings import ESTIMATORS, SteadySettings

    st, b, pb, d = SteadySettings(), Bounds(), ProfileBounds(), SEARCH_DEFAULTS
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
        "theta_f, axial clearance Delta_bf; with --profile the eight variables of the roller end "
        "and rib faces) that minimises, by default (--objective steady), the "
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
        "--profile",
        action="store_true",
        default=None,
        help="search the eight profile variables (roller end and rib faces: R_end, e, R_cor, "
        "1/R_rib, h_t, theta_f, H_rf, Delta_bf; steady objective, frozen-load estimator) instead "
        "of R_end, theta_f, Delta_bf (default: off; on when a profile bound is given)",
    )
    for key, text in PROFILE_OPTIONS.items():
        pair = getattr(pb, next(v.name for v in PROFILE_TABLE if v.key == key))
        unit = next(v for v in PROFILE_TABLE if v.key == key)
        r.add_argument(
            "--" + key.replace("_", "-"),
            help=f"profile: {text} bounds LO,HI (default: {_range_text(pair, unit.scale)})",
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
        "--uncertain-constants",
        help="steady objective: run every operating point also at every corner of these model constants' "
        "ranges (comma-separated keys, e.g. lubricant.traction_d,lubricant.oil_fraction; ranges as "
        "`jaxbearing sensitivity` states them), so that the worst corner enters the objective "
        "(default: none)",
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
        help=f"number of starts (default: {d['starts']['steady']} steady, {d['starts']['profile']} with --profile, "
        f"{d['starts']['startup']} startup)",
    )
    r.add_argument(
        "--iterations",
        type=int,
        help=f"iterations (default: {d['iterations']['steady']} steady, {d['iterations']['profile']} with --profile, "
        f"{d['iterations']['startup']} startup)",
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
        metavar="{mean,peak,tail,friction}",  # checked by `SteadySettings`: one-line errors
        help="steady: the statistic minimised, of flange PV mean (over contact time), peak (its p-mean, "
        "p = 8, weighting the peaks) or tail (the mean of its worst 5 %%, bounding the p95 from "
        "above), or friction (the time-mean total flange friction power, in W; with --aggregate max "
        f"the temperature is then in W) (default: {st.statistic})",
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
    r.add_argument(
        "--min-film-parameter",
        type=float,
        help="steady: the film parameter Lambda the design must keep: the lower 95 %% bound of Lambda's 5th "
        "percentile over contact time at least this at every operating point (default: no limit)",
    )
    r.add_argument(
        "--max-flash-temperature-K",
        type=float,
        help="steady: the flash temperature rise at the rib the design must stay under [K]: the upper 95 %% "
        "bound of a revolution's largest rise at most this at every operating point (default: no limit)",
    )
    r.add_argument(
        "--max-friction-power-W",
        type=float,
        help="steady: the total flange friction power the design must stay under [W]: the upper 95 %% bound of "
        "its time mean at most this at every operating point; one point of the PV / friction-power front "
        "per value (default: no limit)",
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


def run(args) -> int:
    """`optimise run`: every input checked before --out is made, then the search of the chosen
    objective (`_cli_steady.run_steady` or `_cli_startup.run_startup`)."""
    from jaxbearing import load_config
    from jaxbearing.io import check_output_dir, plausibility_warnings

    from ._cli_startup import run_startup
    from ._cli_steady import run_steady
    from ._steady import check_profile_settings

    try:
        cfg = load_config(args.config)
    except UserInputError as exc:
        raise UserInputError(f"{args.config}: {exc}") from None
    bearing, op = cfg.bearing(), cfg.operating_point()
    s = _settings(args)
    problem, options = problem_from_settings(bearing, op, s, constant_corners=constant_corners(cfg, s))
    steady = steady_settings_from(s) if objective_of(s) == "steady" else None
    if steady is None and problem.num_variables != 3:
        raise UserInputError(
            "objective = 'startup': a profile search needs the steady objective (objective = 'steady')"
        )
    if steady is not None:
        check_profile_settings(problem, steady)
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
    return run_startup(args, problem, options, out, meta)


def main(argv: list[str] | None = None) -> int:
    from jaxbearing.cli import dispatch

    return dispatch(build_parser(), argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
