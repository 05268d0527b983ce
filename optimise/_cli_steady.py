"""`optimise run --objective steady` (the default): the design search on steady running with
progress, checkpoint and resume, verification, result.json and the search-path plot."""

from __future__ import annotations

import contextlib
import math
import sys

from ._cli_output import EXIT_INFEASIBLE, _design_text, _engineering, _progress, _write_results


def run_steady(args, problem, options, settings, out, meta=None) -> int:
    """`optimise run --objective steady` (the default): `_steady.steady_search` with progress,
    checkpoint and resume in `out`, verification, result.json and the search-path plot."""

    from jaxbearing.run import MemberProgress

    from ._plot import plot_search
    from ._state import CHECKPOINT
    from ._steady import constraint_names, steady_search

    k = problem.num_operating_points
    print(
        f"optimise (steady running): {options['num_starts']} starts x {k} operating point(s), "
        f"{options['num_iterations']} iterations; each evaluation {settings.seeds} seeds, settle "
        f"{settings.settle}, {settings.window_revs}-revolution window, gradient from "
        f"{2 * settings.seeds} windows of {settings.gradient_window * 1e3:g} ms; checkpoint in {out}"
    )
    sys.stdout.flush()

    names = constraint_names(settings)
    unit = settings.statistic.shown[1]

    def start_line(j, info, m, w):
        lo, hi = info.ci[j]
        g = info.gradient[j]
        return (
            f"J {info.objective[j]:7.4f} [{lo:.4f}, {hi:.4f}] {unit}  "
            f"min margin {names[w]} {_margin_value(names[w], m[w])}  {_design_text(info.x[j])}  "
            f"dJ/du ({', '.join(f'{v:+.3f}' for v in g)})"
        )

    progress = _progress(args.quiet, start_line, unit)

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
    _print_found(res, settings, plot_path)
    if res.verification is not None:
        _print_verification(problem, res.verification)
    print(f"  {res.num_evaluations} settled ensembles, {res.wall_time_s:.1f} s wall")
    print(f"wrote {out / 'result.json'} and {plot_path}")
    return 0


def _print_found(res, settings, plot_path) -> None:
    """The returned design, its objective and the near-optimal set, each member with its corner
    risk and margin."""
    from ._steady import near_optimal_set

    lo, hi = res.objective_ci
    print(
        f"final design: {_design_text(res.design)}  (start {res.best_start}, iteration {res.best_iteration})"
    )
    what = {"mean": "mean PV", "peak": "peak PV (p-mean)", "tail": "tail PV", "friction": "friction power"}
    unit = settings.statistic.shown[1]
    print(
        f"  steady {what[settings.statistic]} {res.objective:.4f} [{lo:.4f}, {hi:.4f}] {unit} (search seeds)"
    )
    near = near_optimal_set(res)
    if not near:
        return
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


def _print_verification(problem, v) -> None:
    """Both designs at every operating point on the verification's seeds (`Verification`), the
    verdict on the mean PV and on the tail."""

    seeds = f"seeds {v.seeds[0]}-{v.seeds[-1]}"
    for k in range(problem.num_operating_points):
        where = f" at {problem.point_label(k)}" if problem.num_operating_points > 1 else ""
        for name, points in (("reference", v.reference), ("optimum", v.optimum)):
            label = name if where else f"{name:9s}"
            print(f"  verification {label}{where}: {_verified_text(points[k])} ({seeds})")
    print(
        "  verified lower mean PV with disjoint 95 % CIs"
        f"{' at every operating point' if problem.num_operating_points > 1 else ''}: "
        f"{v.mean_pv_lower_disjoint}"
    )
    print(f"  {tail_text(v.tail)}")


def tail_text(tail) -> str:
    """The verification's statement on the found design's corner-contact risk
    (`TailVerification`), in one line."""
    methods = sorted({m for m in tail.methods if m})
    model = {
        "normal": "a normal model of the per-revolution largest contact radius",
        "tail": "a generalised Pareto tail",
        "count": "counted corner contacts",
        "not enough data": "the counts alone",
    }
    how = " and ".join(model.get(m, m) for m in methods) or "no measured revolution"
    bound = (
        f"corner-contact risk of the found design at most {tail.upper_per_revolution:.2g} per cage "
        f"revolution at every operating point (upper 95 % bound from {how}, "
        f"{min(tail.revolutions_per_point)} or more revolutions per point)"
    )
    if tail.verified:
        return f"{bound}: verified in the tail at {tail.level_per_revolution:.2g} per revolution"
    return (
        f"{bound}: NOT verified in the tail at {tail.level_per_revolution:.2g} per revolution "
        "(more revolutions per point narrow the bound: more --verify-seeds, or an accelerator; by counting "
        f"alone it takes {tail.revolutions_needed} revolutions per point without corner contact)"
    )


def _verified_text(point) -> str:
    """One design's verification at one operating point (`VerifiedPoint`), in one line."""
    from ._problem import PV_SCALE as GPA  # Pa m/s per GPa m/s

    e = point.mean_pv

    def interval(name: str, est) -> str:
        if not all(map(math.isfinite, (est.value, est.ci95_low, est.ci95_high))):
            return ""
        return f", {name} {est.value / GPA:.3f} [{est.ci95_low / GPA:.3f}, {est.ci95_high / GPA:.3f}]"

    peak = interval("peak PV", point.peak_pv) + interval("tail PV", point.tail_pv)
    return (
        f"mean PV {e.value / GPA:.4f} [{e.ci95_low / GPA:.4f}, {e.ci95_high / GPA:.4f}]{peak} GPa m/s, "
        f"corner share {point.corner_contact_share.value:.3f}"
    )


def _steady_result_json(problem, options, settings, res) -> dict:
    """result.json of the steady search: the design and its objective, the verification, the
    near-optimal set, the clearance's treatment, the problem, the settings and the history."""
    import dataclasses

    import numpy as np

    from ._steady import constraint_names

    h = res.history
    return {
        "objective_kind": "steady",
        "status": res.status,
        "feasible": bool(res.feasible),
        "design": _engineering(res.design),
        settings.statistic.key: {
            "value": res.objective,
            "ci95_low": None if res.objective_ci is None else res.objective_ci[0],
            "ci95_high": None if res.objective_ci is None else res.objective_ci[1],
        },
        "start_design": _engineering(res.start_design),
        "verification": None if res.verification is None else res.verification.as_json(),
        "near_optimal": _near_optimal_json(res, settings.statistic.key),
        "axial_clearance_effect": _clearance_json(problem, settings, res),
        "near_optimal_rule": (
            "every feasible design the search evaluated that is statistically tied with the best (its "
            "objective's 95 % interval reaches below the upper bound of the design of the lowest upper bound; "
            "search seeds), best first; binding_margin: its smallest margin; corner_risk_per_revolution_upper95: "
            "the upper 95 % bound of its corner-contact risk per cage revolution at its worst operating point"
        ),
        "choice_rule": (
            f"choose = {settings.choose.value!r}: 'safest' returns the tied design of the lowest corner-risk bound "
            "(then the largest dynamic corner margin), 'best' the one of the lowest upper bound of the objective"
        ),
        "bounds": problem.bounds.engineering(),
        "operating_points": [
            {"speed_rpm": float(w) * 60 / (2 * math.pi), "load_N": float(f)}
            | ({} if problem.point_constants is None else {"constants": problem.point_constants[k]})
            for k, (w, f) in enumerate(
                zip(np.asarray(problem.operating.inner_speed), np.asarray(problem.operating.radial_load))
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
        "history": _history_json(h, problem.bounds, constraint_names(settings), settings.statistic.key),
    }


def _near_optimal_json(res, key: str) -> list:
    import numpy as np

    from ._steady import near_optimal_set

    return [
        {
            **_engineering(d.design),
            key: {"value": d.objective, "ci95_low": d.ci95[0], "ci95_high": d.ci95[1]},
            "iteration": d.iteration,
            "start": d.start,
            "binding_margin": d.binding_margin,
            "binding_margin_mm": d.binding_margin_m * 1e3,
            "corner_risk_per_revolution_upper95": float(d.corner_risk)
            if np.isfinite(d.corner_risk)
            else None,
            "corner_margin_mm": d.corner_margin_m * 1e3,
        }
        for d in near_optimal_set(res)
    ]


def _clearance_json(problem, settings, res) -> dict:
    """How the search treated Delta_bf: the estimator cannot see it; where the envelope is
    misaligned, a common-random-number difference does."""
    from ._settings import CLEARANCE_MISALIGNMENT, CLEARANCE_STEP, clearance_step_for

    step = clearance_step_for(problem, settings)
    ci = problem.bounds.clearance_index
    seen = {
        "estimator_sees_it": True,
        "why": "common-random-number central differences of the settled objective in "
        f"Delta_bf (half-step {step * 1e3:g} mm, the same seeds from the same "
        "states, extra members of every evaluation), used where significant at 5 % and 0 "
        "otherwise: history gradient and gradient_stderr",
    }
    return {
        "estimator_sees_it": False,
        "why": "the frozen-load estimator moves the flange in its own plane at a fixed load: its "
        "dJ/dDelta_bf is 0 by construction; Delta_bf moves only where a margin pushes it",
        "measured": "docs/model.md 17: the clearance study (significant only with the inner ring "
        "misaligned by 2 mrad)",
        **(seen if step > 0 else {}),
        "step_mm": step * 1e3,
        "step_rule": f"clearance_step = {settings.clearance_step!r}: 'auto' takes "
        f"{CLEARANCE_STEP * 1e3:g} mm where an operating point is misaligned by more than "
        f"{CLEARANCE_MISALIGNMENT * 1e3:g} mrad, else 0 (off)",
        "moved": bool(
            res.design is not None and abs(float(res.design[ci]) - float(res.start_design[ci])) > 1e-12
        ),
    }


def _margin_value(name: str, value: float) -> str:
    """One margin in its unit: mm for the geometric ones, Lambda or K for the limits."""
    if name == "film_parameter":
        return f"{value:+.3f}"
    if name == "flash_temperature":
        return f"{value:+.1f} K"
    if name == "friction_power":
        return f"{value:+.2f} W"
    return f"{value * 1e3:+.4f} mm"


def _history_json(h, bounds, names, key: str = "objective_GPa_m_s") -> dict:
    """The search's history in engineering units (per iteration and start): every design
    variable by its key (`end_radius_mm`, ...), the objective under `key` (`Statistic.key`)."""
    import numpy as np

    from ._steady import CONSTRAINT_NAMES

    x = np.asarray(h.x) if len(h) else np.zeros((0, 0, len(bounds.names)))
    margins = np.asarray(h.margins) if len(h) else np.zeros((0, 0, len(names)))
    limits = {
        {
            "film_parameter": "film_parameter",
            "flash_temperature": "flash_temperature_K",
            "friction_power": "friction_power_W",
        }[n]: margins[..., i].tolist()
        for i, n in enumerate(names)
        if i >= len(CONSTRAINT_NAMES)
    }
    return {
        key: np.asarray(h.objective).tolist(),
        "ci95" + key.removeprefix("objective"): np.asarray(h.ci).tolist(),
        "gradient_per_unit_box": np.asarray(h.gradient).tolist(),
        "gradient_stderr": np.asarray(h.gradient_stderr).tolist(),
        **{var.key: (x[..., i] * var.scale).tolist() for i, var in enumerate(bounds.TABLE)},
        "margins_mm": {n: (margins[..., i] * 1e3).tolist() for i, n in enumerate(CONSTRAINT_NAMES)},
        # the limits' margins in their own units (Lambda - limit; limit - K), when set
        **({"limit_margins": limits} if limits else {}),
        # the upper 95 % bound of the corner-contact risk per revolution, worst operating point
        "corner_risk_per_revolution_upper95": np.asarray(h.corner_risk, float).tolist(),
        "wall_s": np.asarray(h.wall_s).tolist(),
        "simulated_ms": np.asarray(h.simulated_ms).tolist(),
        # per iteration, start and operating point: simulated (True) or its last values reused
        "points_simulated": np.asarray(h.points_simulated, dtype=bool).tolist(),
    }
