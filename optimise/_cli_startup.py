"""`optimise run --objective startup`: the gradient search on the start-up transient's smooth
peak PV, its progress lines and result.json."""

from __future__ import annotations

import math
import sys

from ._cli_output import EXIT_INFEASIBLE, _design_text, _engineering, _margin_text, _progress, _write_results

#: why the start-up search found no design, by its status: the line it prints
_INFEASIBLE = {
    "no_feasible_design_in_bounds": "no feasible design exists within the bounds (every design-zone margin "
    "cannot be satisfied at once); widen the bounds or relax --min-clearance-mm",
    "no_feasible_iterate": "no iterate reached the feasible design zone (it exists within the bounds);"
    " try more --iterations or --starts",
}


def run_startup(args, problem, options, out, meta) -> int:
    """The start-up search (`_search.search`) with progress, result.json and the plot."""
    import numpy as np

    from jaxbearing.flange import MARGIN_NAMES

    from ._plot import plot_search
    from ._search import search

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
    if res.status in _INFEASIBLE:
        print(f"optimise: {_INFEASIBLE[res.status]}", file=sys.stderr)
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


def _result_json(problem, options, res) -> dict:
    import numpy as np

    from jaxbearing.flange import MARGIN_NAMES
    from jaxbearing.io import finite_or_none as fin

    design = _engineering

    def margins(m):
        return None if m is None else {f"{n}_margin_mm": float(v) * 1e3 for n, v in zip(MARGIN_NAMES, m)}

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
