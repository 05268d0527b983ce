"""`optimise` command line: `optimise run [...]`.

Objectives: `--objective steady` (default; `_steady`: the mean flange PV of settled running,
seeds, CIs, the dynamic corner margin, continuation, resume from DIR/checkpoint.npz,
verification on unseen seeds) and `--objective startup` (`_search`: the smooth peak PV of the
first 0.3 ms from a seated start, the old transient objective: fast, but it measures how hard
seated rollers are first driven onto their flanges, not how a design runs).

Prints per-iteration progress (objective, smallest constraint margin and which, design of every
start), the final design with its constraint status and the improvement over the starting
design; writes DIR/result.json and DIR/search_paths.png (search paths over the design-zone
feasibility map). Exit codes: 0 success, 2 bad input (one line on stderr), 3 no feasible
design found (none in the bounds, or no iterate reached the zone).
"""

from __future__ import annotations

import argparse
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


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="optimise",
        description="Gradient-based design of arc-end rollers and flanges: minimise the smooth "
        "peak flange PV over R_end, layback angle and axial clearance inside the design zone.",
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    from jaxbearing.cli import exit_codes_text

    r = sub.add_parser(
        "run",
        help="run the multi-start projected augmented-Lagrangian search",
        description="Search the roller-end/flange design (end radius R_end, layback angle "
        "theta_f, axial clearance Delta_bf) that minimises the smooth peak flange PV of short "
        "dynamic runs over an envelope of speeds and loads, inside the design zone (relief, "
        "height limit, limited circle, actual axial clearance). Several starts run in parallel "
        "(projected augmented Lagrangian with Adam, forward-mode gradients through the solve). "
        "Writes DIR/result.json (strict JSON) and DIR/search_paths.png when the search ends; a "
        "killed run writes nothing and leaves earlier results as they were.",
        epilog=exit_codes_text(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    r.add_argument(
        "--config",
        help="jaxbearing TOML configuration (bearing and operating point; "
        "default: the embedded reference bearing)",
    )
    r.add_argument(
        "--bounds",
        dest="bounds_file",
        help="optimiser TOML file with [bounds], "
        "[constraints], [envelope], [search] sections (command-line options win)",
    )
    r.add_argument("--end-radius-mm", help="R_end bounds LO,HI [mm] (default 60,120)")
    r.add_argument("--layback-deg", help="theta_f bounds LO,HI [deg] (default 1.0,2.0)")
    r.add_argument("--clearance-mm", help="Delta_bf bounds LO,HI [mm] (default 0.10,0.30)")
    r.add_argument(
        "--min-clearance-mm", type=float, help="required actual axial clearance Lambda_bf [mm] (default 0)"
    )
    r.add_argument(
        "--flange-load-N",
        type=float,
        help="flange load of the relief margin's contact ellipse [N] (default 100)",
    )
    r.add_argument(
        "--speeds-rpm", help="operating speeds, e.g. 5000,15000,30000 (default: the configuration's speed)"
    )
    r.add_argument("--loads-N", help="radial loads, e.g. 500,1000 (default: the configuration's)")
    r.add_argument("--weights", help="weights of the operating points (speeds x loads, speed-major)")
    r.add_argument(
        "--aggregate",
        choices=("max", "mean"),
        help="robust objective: smooth worst case (max, default) or weighted mean",
    )
    r.add_argument(
        "--objective",
        help="steady (default): mean flange PV of settled running over seeds, verified on unseen "
        "seeds; startup: the old transient objective (smooth peak PV of the first 0.3 ms)",
    )
    r.add_argument("--starts", type=int, help="number of starts (default 2 steady, 4 startup)")
    r.add_argument("--iterations", type=int, help="iterations (default 6 steady, 20 startup)")
    r.add_argument("--learning-rate", type=float, help="Adam step size in scaled units (default 0.08)")
    r.add_argument("--seeds", type=int, help="steady: seeds per evaluation (default 4)")
    r.add_argument("--window-revs", type=int, help="steady: cage revolutions measured (default 2)")
    r.add_argument("--settle", help="steady: auto (default) or a fixed settling time in ms before the window")
    r.add_argument(
        "--gradient-window-ms",
        type=float,
        help="steady: length of the short-window sensitivities [ms] (default 1.0)",
    )
    r.add_argument(
        "--estimator",
        help="steady: gradient estimator, frozen-load (default) or short-window forward mode",
    )
    r.add_argument(
        "--corner-margin-mm",
        type=float,
        help="steady: the largest contact radius this far inside the limited circle (default 0.05)",
    )
    r.add_argument("--verify-seeds", type=int, help="steady: unseen seeds of the verification (default 4)")
    r.add_argument("--no-verify", action="store_true", help="steady: skip the verification")
    r.add_argument("--workers", type=int, help="steady: processes (default: one per CPU)")
    r.add_argument(
        "--duration-ms", type=float, help="startup: simulated time per evaluation [ms] (default 0.3)"
    )
    r.add_argument("--rtol", type=float, help="solver rtol (default 1e-3)")
    r.add_argument(
        "--atol",
        type=float,
        help="solver atol on the scaled state (default 1e-6: 10 nm, 10 um/s, 0.01 rad/s)",
    )
    r.add_argument("--out", default="optimise_out", help="output directory (default optimise_out)")
    r.add_argument("--quiet", action="store_true", help="no per-iteration progress")
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
        ("verify_seeds", args.verify_seeds),
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
        min_clearance=_positive(s, "min_clearance_mm", 0.0, strict=False) * 1e-3,
        aggregate=s.get("aggregate", "max"),
        temperature=_positive(s, "temperature_GPa_m_s", 0.1),
        rtol=_positive(s, "rtol", 1e-3),
        atol=_positive(s, "atol", 1e-6),
    )
    steady = objective_of(s) == "steady"
    options = dict(
        num_starts=int(_positive(s, "starts", 2 if steady else 4, int)),
        num_iterations=int(_positive(s, "iterations", 6 if steady else 20, int)),
        learning_rate=_positive(s, "learning_rate", 0.08),
    )
    return problem, options


def objective_of(s: dict) -> str:
    objective = s.get("objective", "steady")
    if objective not in ("steady", "startup"):
        raise UserInputError(f"objective = {objective!r}: must be 'steady' or 'startup'")
    return objective


def steady_settings_from(s: dict):
    """SteadySettings from merged settings (engineering units)."""
    from ._steady import SteadySettings

    settle = s.get("settle", "auto")
    if settle != "auto":
        settle = _positive({"settle": settle}, "settle", 0.0, strict=False)
    return SteadySettings(
        seeds=int(_positive(s, "seeds", 4, int)),
        window_revs=int(_positive(s, "window_revs", 2, int)),
        settle=settle,
        gradient_window=_positive(s, "gradient_window_ms", 1.0) * 1e-3,
        estimator=s.get("estimator", "frozen"),
        corner_margin=_positive(s, "corner_margin_mm", 0.05, strict=False) * 1e-3,
        rtol=_positive(s, "rtol", 1e-3),
        workers=int(_positive(s, "workers", 0, int, strict=False)),
        verify_seeds=int(_positive(s, "verify_seeds", 4, int)),
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
        best = info["best"]
        print(
            f"iter {it:3d}  best feasible {best:.4f} GPa m/s"
            if np.isfinite(best)
            else f"iter {it:3d}  best feasible   none yet"
        )
        for j in range(info["x"].shape[0]):
            m = info["margins"][j]
            print(f"   start {j}: " + start_line(j, info, m, int(np.argmin(m))))
        sys.stdout.flush()

    return progress


def run(args) -> int:
    import numpy as np

    from jaxbearing import load_config
    from jaxbearing.flange import MARGIN_NAMES
    from jaxbearing.io import write_json

    from ._plot import plot_search
    from ._search import search

    try:
        cfg = load_config(args.config)
    except UserInputError as exc:
        raise UserInputError(f"{args.config}: {exc}") from None
    bearing, op = cfg.bearing(), cfg.operating_point()
    s = _settings(args)
    problem, options = problem_from_settings(bearing, op, s)
    out = pathlib.Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserInputError(f"--out {args.out}: cannot create directory: {exc.strerror}") from None

    if objective_of(s) == "steady":
        return run_steady(args, problem, options, steady_settings_from(s), out)
    k = problem.num_operating_points
    print(
        f"optimise: {options['num_starts']} starts x {k} operating point(s), "
        f"{options['num_iterations']} iterations, {problem.duration * 1e3:g} ms per evaluation "
        f"({problem.aggregate} over the envelope)"
    )

    def start_line(j, info, m, w):
        return (
            f"J {info['objective'][j]:8.4f} GPa m/s  "
            f"min margin {MARGIN_NAMES[w]} {m[w] * 1e3:+.4f} mm  {_design_text(info['x'][j])}"
            f"{'' if info['feasible'][j] else '  (infeasible)'}"
        )

    progress = _progress(args.quiet, start_line)

    res = search(problem, callback=progress, **options)
    result = _result_json(problem, options, res)
    write_json(out / "result.json", result)
    plot_path = out / "search_paths.png"
    plot_search(problem, res, plot_path)

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


def run_steady(args, problem, options, settings, out) -> int:
    """`optimise run --objective steady` (the default): `_steady.steady_search` with progress,
    checkpoint and resume in `out`, verification, result.json and the search-path plot."""

    from jaxbearing.io import write_json

    from ._plot import plot_search
    from ._steady import CHECKPOINT, CONSTRAINT_NAMES, steady_search

    k = problem.num_operating_points
    print(
        f"optimise (steady running): {options['num_starts']} starts x {k} operating point(s), "
        f"{options['num_iterations']} iterations; each evaluation {settings.seeds} seeds, settle "
        f"{settings.settle}, {settings.window_revs}-revolution window, gradient from "
        f"{2 * settings.seeds} windows of {settings.gradient_window * 1e3:g} ms; checkpoint in {out}"
    )
    sys.stdout.flush()

    def start_line(j, info, m, w):
        lo, hi = info["ci"][j]
        g = info["gradient"][j]
        return (
            f"J {info['objective'][j]:7.4f} [{lo:.4f}, {hi:.4f}] GPa m/s  "
            f"min margin {CONSTRAINT_NAMES[w]} {m[w] * 1e3:+.4f} mm  {_design_text(info['x'][j])}  "
            f"dJ/du ({g[0]:+.3f}, {g[1]:+.3f}, {g[2]:+.3f})"
        )

    progress = _progress(args.quiet, start_line)

    res = steady_search(
        problem, settings, directory=out, callback=progress, verify=not args.no_verify, **options
    )
    if res.resumed_from >= 0 and not args.quiet:
        print(f"(resumed after iteration {res.resumed_from} from {out / CHECKPOINT})")
    write_json(out / "result.json", _steady_result_json(problem, options, settings, res))
    plot_path = out / "search_paths.png"
    plot_search(problem, res, plot_path)
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
    print(f"  steady mean PV {res.objective:.4f} [{lo:.4f}, {hi:.4f}] GPa m/s (search seeds)")
    v = res.verification
    if v:
        for name in ("reference", "optimum"):
            row = v[name] if "mean_pv_GPa_m_s" in v[name] else v[name]["per_operating_point"][0]
            e, c = row["mean_pv_GPa_m_s"], row["corner_contact_share"]
            print(
                f"  verification {name:9s} mean PV {e['value']:.4f} [{e['ci95_low']:.4f}, "
                f"{e['ci95_high']:.4f}] GPa m/s, corner share {c['value']:.3f} (seeds {v['seeds'][0]}-{v['seeds'][-1]})"
            )
        if "mean_pv_lower_disjoint" in v:
            print(f"  verified lower mean PV with disjoint 95 % CIs: {v['mean_pv_lower_disjoint']}")
    print(f"  {res.num_evaluations} settled ensembles, {res.wall_time_s:.1f} s wall")
    print(f"wrote {out / 'result.json'} and {plot_path}")
    return 0


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

    from ._steady import CONSTRAINT_NAMES

    h = res.history
    x = np.asarray(h["x"]) if len(h["x"]) else np.zeros((0, 0, 3))
    margins = np.asarray(h["margins"]) if len(h["margins"]) else np.zeros((0, 0, 5))
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
        "simulated_ms": float(np.sum(h["simulated_ms"])) if len(h["simulated_ms"]) else 0.0,
        "resumed_from_iteration": res.resumed_from,
        "wall_time_s": res.wall_time_s,
        "history": {
            "objective_GPa_m_s": np.asarray(h["objective"]).tolist(),
            "ci95_GPa_m_s": np.asarray(h["ci"]).tolist(),
            "gradient_per_unit_box": np.asarray(h["gradient"]).tolist(),
            "gradient_stderr": np.asarray(h["gradient_stderr"]).tolist(),
            "end_radius_mm": (x[..., 0] * 1e3).tolist(),
            "layback_angle_deg": np.degrees(x[..., 1]).tolist(),
            "axial_clearance_mm": (x[..., 2] * 1e3).tolist(),
            "margins_mm": {n: (margins[..., i] * 1e3).tolist() for i, n in enumerate(CONSTRAINT_NAMES)},
            "wall_s": np.asarray(h["wall_s"]).tolist(),
            "simulated_ms": np.asarray(h["simulated_ms"]).tolist(),
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
