"""What do the gradients buy? The gradient search against random search and CMA-ES at equal cost.

    python benchmarks/studies/study_gradient_free.py --speeds-rpm 30000 --slices 11 --seeds 2 \
        --repeats 3 --population 6 --name study_gradient_free_30000rpm_11slices
    python benchmarks/studies/study_gradient_free.py --quick   (a minute: 5 slices, tiny budget)

One problem for all: the reference bearing at `--slices` slices, 1000 N, `--speeds-rpm`, the box
of examples/optimise.toml (`--profile`: the eight variables of examples/optimise_profile.toml),
`--seeds` seeds per design and every other setting the default of `optimise.SteadySettings`
(the risk constraint). The gradient search (`optimise.steady_search`,
`--starts` x `--iterations`) runs once; random search and CMA-ES
(`optimise.gradient_free_search`, a generation of `--population` designs per engine call) run
`--repeats` times each (seeds 0, 1, ...) with the settled members the gradient search spent as
their budget (`--budget-members` to set it). `--methods held` adds the held-load search once
(`_held_run`: settle, hold the contacts, SLSQP on the held-load objective, settle again,
`--held-rounds` holds; deterministic given the seeds). Members are counted where every search simulates:
each call of `optimise._evaluate.settled_metrics` adds its designs x seeds (the gradient
search's clearance differences included). Every returned design is then verified on seeds 1000..
(`optimise.verification`, `--verify-seeds`, 4-revolution windows).

Per run: the best-so-far objective (search seeds; the design the run would return had it stopped)
against members, the returned design, its verified objective with its 95 % interval, and the
members at which the run's best-so-far first reached the median of CMA-ES's final objectives
(`members_to_cmaes_final`). With `--profile`, the three-variable optimum
(`THREE_VARIABLE_OPTIMUM`, the bearing's own R_cor, flat rib and spherical end) is verified the
same way once (`three_variable_optimum`), so the figure shows where the profile designs stand
against it. Writes results/NAME.json (every finished run kept: a rerun with the
same options continues, also with another `--repeats`) and, with `--plot PATH`, the curves with the verified objectives as
bars at the members spent.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve()
sys.path.insert(0, str(HERE.parents[1]))

import _common  # noqa: E402

ROOT = HERE.parents[2]

#: the three-variable search's optimum (R_end [mm], theta_f [deg], Delta_bf [mm]): docs/how-to
#: "Design the roller end and rib profiles", the design a profile has to beat
THREE_VARIABLE_OPTIMUM = (101.6, 1.527, 0.140)


def _problem(args):
    """The problem and settings `optimise run --bounds examples/optimise.toml` builds (with
    `--profile`: examples/optimise_profile.toml, the eight profile variables), at `--slices`,
    `--speeds-rpm`, `--seeds` and `--verify-seeds`."""
    import jaxbearing as jb
    from optimise import load_optimise_toml
    from optimise._cli_settings import problem_from_settings, steady_settings_from

    example = "optimise_profile.toml" if args.profile else "optimise.toml"
    spec = load_optimise_toml(str(ROOT / "examples" / example))
    spec |= dict(
        speeds_rpm=[float(v) for v in args.speeds_rpm.split(",")],
        seeds=args.seeds,
        verify_seeds=args.verify_seeds,
    )
    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=args.slices)
    problem, _ = problem_from_settings(bearing, jb.reference_operating_point(), spec)
    return problem, steady_settings_from(spec)


class _Counter:
    """Counts the settled members of every call of `settled_metrics` (the one door to the engine)."""

    def __init__(self):
        from optimise import _evaluate

        self.module, self.original, self.members = _evaluate, _evaluate.settled_metrics, 0

    def __enter__(self):
        def counted(problem, settings, points, designs, **kwargs):
            if not kwargs.get("verification"):
                self.members += len(points) * settings.seeds
            return self.original(problem, settings, points, designs, **kwargs)

        self.module.settled_metrics = counted
        return self

    def __exit__(self, *exc):
        self.module.settled_metrics = self.original


def _gradient_run(problem, settings, args) -> dict:
    from optimise import steady_search

    marks = []
    with _Counter() as count:
        res = steady_search(
            problem,
            settings,
            num_starts=args.starts,
            num_iterations=args.iterations,
            callback=lambda it, report: marks.append(count.members),
            verify=False,
        )
    h = res.history
    ci = np.asarray(h.ci, float)
    feasible = np.all(np.asarray(h.margins, float) > 0, axis=-1) & np.isfinite(np.asarray(h.objective, float))
    curve, best = [], None
    for it in range(ci.shape[0]):
        for s in range(ci.shape[1]):
            if feasible[it, s] and (best is None or ci[it, s, 1] < ci[best][1]):
                best = (it, s)
        curve.append(float(np.asarray(h.objective, float)[best]) if best is not None else None)
    return dict(
        method="gradient",
        repeat=0,
        members_curve=marks,
        best_curve=curve,
        design=None if res.design is None else np.asarray(res.design).tolist(),
        objective=res.objective,
        members=count.members,
    )


def _held_run(problem, settings, args) -> dict:
    """The held-load search (`optimise.held_load_search`, `--held-rounds` holds of
    `--held-window-ms` windows, `--held-maxiter` SLSQP iterations) from the bearing's own
    design; its settled members counted as every search's."""
    from optimise import held_load_search

    marks = []

    def log(line):
        marks.append(count.members)
        _common.log(line)

    with _Counter() as count:
        res = held_load_search(
            problem,
            settings,
            rounds=args.held_rounds,
            window_ms=args.held_window_ms,
            maxiter=args.held_maxiter,
            log=log,
        )
    curve = [None if not np.isfinite(v) else float(v) for v in res.best_so_far()]
    b = res.best
    return dict(
        method="held",
        repeat=0,
        members_curve=marks,
        best_curve=curve,
        design=None if b < 0 else res.designs[b].tolist(),
        objective=None if b < 0 else float(res.objective[b]),
        members=count.members,
        rounds=[dict(design=d.tolist(), objective=float(o)) for d, o in zip(res.designs, res.objective)],
    )


def _free_run(problem, settings, method, repeat, budget, args) -> dict:
    from optimise import gradient_free_search

    with _Counter() as count:
        res = gradient_free_search(problem, settings, method, budget, seed=repeat, population=args.population)
    members, curve = res.best_so_far()
    b = res.best
    return dict(
        method=method,
        repeat=repeat,
        members_curve=members.tolist(),
        best_curve=[None if not np.isfinite(v) else float(v) for v in curve],
        design=None if b < 0 else res.x[b].tolist(),
        objective=None if b < 0 else float(res.objective[b]),
        members=count.members,
        designs_drawn=len(res.x),
        designs_simulated=int(res.simulated.sum()),
    )


def _verified(problem, settings, run) -> None:
    from optimise import verification

    if run["design"] is None or "verified" in run:
        return
    from optimise import start_points

    # the search's own reference: the bearing's design of the problem's kind (3 or 8 variables)
    reference = np.asarray(problem.bounds.from_scaled(start_points(problem, 1)[0]))
    v = verification(problem, settings, np.asarray(run["design"]), reference).as_json()
    rows = v["optimum"].get("per_operating_point", [v["optimum"]])
    run["verified"] = [r["objective_GPa_m_s"] for r in rows]
    run["verified_reference"] = [
        r["objective_GPa_m_s"] for r in v["reference"].get("per_operating_point", [v["reference"]])
    ]


def _three_variable_optimum(problem) -> np.ndarray:
    """`THREE_VARIABLE_OPTIMUM` as the eight profile variables [SI]: the bearing's own profile
    (sphere, cone, its corner radius and flange height) with R_end, theta_f and Delta_bf set
    (`flange.ProfileVariables.from_design`)."""
    from jaxbearing.flange import DesignVariables, ProfileVariables

    r_end, theta, delta = THREE_VARIABLE_OPTIMUM
    design = DesignVariables(r_end * 1e-3, np.deg2rad(theta), delta * 1e-3)
    return np.array(ProfileVariables.from_design(design, problem.bearing).as_array(), dtype=float)


def _verified_optimum(problem, settings, out) -> None:
    """Verify the three-variable optimum once, as every run's design (`_verified`)."""
    if "three_variable_optimum" in out:
        return
    run = {"design": _three_variable_optimum(problem).tolist()}
    _verified(problem, settings, run)
    out["three_variable_optimum"] = {"design_mm_deg_mm": list(THREE_VARIABLE_OPTIMUM), **run}


def _reach(run, target) -> int | None:
    for m, v in zip(run["members_curve"], run["best_curve"]):
        if v is not None and v <= target:
            return int(m)
    return None


#: the methods' names in the figure's legend
_LABELS = {"held": "held-load search"}


def _plot(out, path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.6, 4.0))
    colours = {"gradient": "C0", "random": "C1", "cmaes": "C2", "held": "C3"}
    for run in out["runs"]:
        c = colours[run["method"]]
        y = [np.nan if v is None else v for v in run["best_curve"]]
        ax.step(
            run["members_curve"],
            y,
            where="post",
            color=c,
            alpha=0.8,
            label=_LABELS.get(run["method"], run["method"]) if run["repeat"] == 0 else None,
            marker="s" if run["method"] == "held" else None,
        )
        if run.get("verified"):
            e = run["verified"][0]
            ax.errorbar(
                run["members"],
                e["value"],
                yerr=[[e["value"] - e["ci95_low"]], [e["ci95_high"] - e["value"]]],
                fmt="o",
                color=c,
                capsize=3,
            )
    ref = next((r["verified_reference"][0] for r in out["runs"] if r.get("verified_reference")), None)
    if ref is not None:
        ax.axhline(ref["value"], color="0.5", linestyle="--", label="start design, verified")
    opt = out.get("three_variable_optimum", {}).get("verified")
    if opt:
        ax.axhline(opt[0]["value"], color="k", linestyle=":", label="three-variable optimum, verified")
        ax.axhspan(opt[0]["ci95_low"], opt[0]["ci95_high"], color="k", alpha=0.08)
    ax.set_xlabel("settled members simulated")
    ax.set_ylabel("objective [GPa m/s]")
    ax.set_title("lines: best so far on the search's seeds; dots: verified on unseen seeds", fontsize=9)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(path, dpi=120)


#: options a rerun may change and still continue the file's runs: the repeats (fewer: the
#: later repeats' runs move to `runs_left_out`; more: they run), the gradient-free methods run,
#: where the figure goes and the held-load search's settings
_ANY = ("repeats", "plot", "methods", "held_rounds", "held_window_ms", "held_maxiter")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--speeds-rpm", default="30000")
    p.add_argument("--slices", type=int, default=11)
    p.add_argument("--seeds", type=int, default=2)
    p.add_argument("--verify-seeds", type=int, default=4)
    p.add_argument("--starts", type=int, default=2)
    p.add_argument("--iterations", type=int, default=4)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--population", type=int, default=6)
    p.add_argument("--methods", default="cmaes,random", help="the gradient-free methods run, in order")
    p.add_argument("--budget-members", type=int, default=0, help="0: what the gradient search spent")
    p.add_argument("--held-rounds", type=int, default=2, help="held-load search: re-holds after the first")
    p.add_argument("--held-window-ms", type=float, default=1.0, help="held-load search: window per seed")
    p.add_argument("--held-maxiter", type=int, default=40, help="held-load search: SLSQP iterations")
    p.add_argument("--name", default="study_gradient_free")
    p.add_argument("--plot", default="", help="where to draw the figure (PNG); none by default")
    p.add_argument("--quick", action="store_true")
    p.add_argument(
        "--profile", action="store_true", help="the eight profile variables (examples/optimise_profile.toml)"
    )
    args = p.parse_args(argv)
    if args.quick:
        args.slices, args.seeds, args.verify_seeds = 5, 2, 2
        args.starts, args.iterations, args.repeats = 1, 1, 1
        args.population, args.name = 3, args.name + "_quick"
    t0 = time.perf_counter()
    problem, settings = _problem(args)
    path = _common.RESULTS_DIR / f"{args.name}.json"
    options = {k: v for k, v in vars(args).items() if k != "name"}
    out = json.loads(path.read_text()) if path.exists() else {}
    if {k: v for k, v in out.get("options", {}).items() if k not in _ANY} != {
        k: v for k, v in options.items() if k not in _ANY
    }:
        out = {"options": options, "runs": []}
    out["options"] = options
    kept = [r for r in out["runs"] if r["method"] == "gradient" or r["repeat"] < args.repeats]
    out["runs_left_out"] = out.get("runs_left_out", []) + [r for r in out["runs"] if r not in kept]
    out["runs"] = kept
    done = {(r["method"], r["repeat"]) for r in out["runs"]}
    methods = args.methods.split(",")
    # the held-load search is deterministic given its seeds: one run, as the gradient search
    jobs = [("gradient", 0)] + [(m, 0 if m == "held" else k) for m in methods for k in range(args.repeats)]
    jobs = list(dict.fromkeys(jobs))
    for method, repeat in jobs:
        if (method, repeat) in done:
            continue
        if method == "gradient":
            run = _gradient_run(problem, settings, args)
        elif method == "held":
            run = _held_run(problem, settings, args)
        else:
            budget = args.budget_members or next(
                r["members"] for r in out["runs"] if r["method"] == "gradient"
            )
            run = _free_run(problem, settings, method, repeat, budget, args)
        _verified(problem, settings, run)
        out["runs"].append(run)
        _common.log(f"{method} {repeat}: objective {run['objective']}, {run['members']} members")
        _common.write_json(args.name, out)
    if args.profile:
        _verified_optimum(problem, settings, out)
        _common.write_json(args.name, out)
    finals = [r["objective"] for r in out["runs"] if r["method"] == "cmaes" and r["objective"] is not None]
    target = float(np.median(finals)) if finals else None
    for run in out["runs"]:
        run["members_to_cmaes_final"] = None if target is None else _reach(run, target)
    out["cmaes_final_median"] = target
    out["command"] = "python benchmarks/studies/study_gradient_free.py " + " ".join(
        sys.argv[1:] if argv is None else argv
    )
    out["machine"] = _common.machine_info()
    out["wall_s_last_call"] = time.perf_counter() - t0
    _common.write_json(args.name, out)
    if args.plot:
        _plot(out, args.plot)
    for run in out["runs"]:
        print(
            f"{run['method']:8s} {run['repeat']}: {run['members']} members, objective {run['objective']}, "
            f"reached CMA-ES's median final at {run['members_to_cmaes_final']}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
