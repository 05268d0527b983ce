"""The profile search's figures: the faces it found, and the PV / friction-power front.

    python benchmarks/studies/study_profile_design.py faces \
        --design 83.829,0.0540063,0.360549,0.230176,0,1.64406,2,0.149999 \
        --plot docs/figures/profile_design/faces.png
    python benchmarks/studies/study_profile_design.py front --runs mean:none,friction:none,mean:24 \
        --name profile_front --plot docs/figures/profile_design/front.png

`faces`: the meridians of the reference bearing's faces, of the three-variable optimum (`--three`, R_end
[mm], theta_f [deg], Delta_bf [mm], the reference's other faces) and of a profile design,
`--design` (eight values in the order and units of `optimise.ProfileBounds`: R_end mm, e mm,
R_cor mm, 1/R_rib 1/m, h_t mm, theta_f deg, H_rf mm, Delta_bf mm), to scale and as deviations
from the flat end plane and from the cone (`optimise._faces_plot.plot_faces`). Draws only:
nothing is simulated.
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
sys.path.insert(0, str(HERE.parent))

import _common  # noqa: E402

#: the three-variable optimum the profile design is compared with (design-search how-to)
THREE_VARIABLE_OPTIMUM = "101.6,1.527,0.140"


def faces(args) -> int:
    import jaxbearing as jb
    from jaxbearing.flange import ProfileVariables
    from optimise import Bounds, ProfileBounds
    from optimise._faces_plot import plot_faces

    bearing = jb.reference_bearing()
    designs = {
        "reference": np.asarray(ProfileVariables.of(bearing).as_array()),
        "three-variable optimum": _three_as_profile(bearing, Bounds.from_engineering(_values(args.three))),
        "profile design": ProfileBounds.from_engineering(_values(args.design)),
    }
    pathlib.Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
    print(f"wrote {plot_faces(bearing, designs, args.plot)}")
    return 0


def _values(text: str) -> list[float]:
    return [float(v) for v in text.split(",")]


def _three_as_profile(bearing, x) -> np.ndarray:
    from jaxbearing.flange import DesignVariables, ProfileVariables

    return np.asarray(ProfileVariables.from_design(DesignVariables.from_array(x), bearing).as_array())


def _worst(rows: list, key: str) -> dict:
    """The operating point's row of the largest value of `key` (the worst speed)."""
    return max(rows, key=lambda r: r[key]["value"])


#: what a front point keeps of a verification row
_KEPT = ("mean_pv_GPa_m_s", "friction_power_W", "film_parameter_p05", "corner_contact_share")


def front(args) -> int:
    """The epsilon-constraint runs: per run "STATISTIC:LIMIT" of `--runs` the profile search
    (`optimise.steady_search`, `--starts` x `--iterations`, checkpointed under
    `--work`) on the problem of study_gradient_free.py --profile (`--slices`, `--speeds-rpm`,
    `--seeds`), minimising STATISTIC ("mean": mean PV, "friction": total flange friction power)
    with the friction power's upper 95 % bound held below LIMIT [W] ("none": no limit); its
    design verified on the verification seeds (`--verify-seeds`). Per run the found design's and
    the reference's mean PV and friction power with their 95 % intervals at the worst speed.
    Written after every run; a rerun with the same options skips the runs done."""
    import study_gradient_free

    from jaxbearing.design import Statistic
    from optimise import Choice, steady_search

    problem, settings = study_gradient_free._problem(argparse.Namespace(profile=True, **vars(args)))
    options = {k: v for k, v in vars(args).items() if k not in ("name", "plot", "what", "runs", "work")}
    path = _common.RESULTS_DIR / f"{args.name}.json"

    def done() -> dict:  # the runs written so far with these options (another process may add some)
        out = json.loads(path.read_text()) if path.exists() else {}
        return out if out.get("options") == options else {"options": options, "runs": {}}

    for run in args.runs.split(","):
        if run in done()["runs"]:
            _with_history(args, run, done())
            continue
        statistic, _, text = run.partition(":")
        limit = None if text in ("", "none") else float(text)
        t0 = time.perf_counter()
        res = steady_search(
            problem,
            dataclasses.replace(
                settings, statistic=Statistic(statistic), max_friction_power=limit, choose=Choice(args.choose)
            ),
            num_starts=args.starts,
            num_iterations=args.iterations,
            directory=pathlib.Path(args.work) / run.replace(":", "_"),
        )
        point = {"statistic": statistic, "max_friction_power_W": limit, "found": res.design is not None}
        point["wall_s"] = time.perf_counter() - t0
        if res.design is not None:
            v = res.verification.as_json()
            point["design"] = problem.bounds.engineering_values(res.design)
            for name in ("optimum", "reference"):
                worst = _worst(v[name].get("per_operating_point", [v[name]]), "mean_pv_GPa_m_s")
                point[name] = {k: worst[k] for k in _KEPT}
        point["command"] = " ".join(["python", "benchmarks/studies/study_profile_design.py", *sys.argv[1:]])
        out = done()
        out["runs"][run] = point
        out["machine"] = _common.machine_info()
        _common.write_json(args.name, out)
        _common.log(f"run {run}: {point.get('optimum')}")
        _with_history(args, run, done())
    if args.plot:
        _plot_front(done()["runs"], args.plot)
    return 0


def _with_history(args, run: str, out: dict) -> None:
    """Add to `run`'s point the search's history from its checkpoint (per iteration, start 0:
    the objective with its interval, the gradient per unit box with its standard error, the
    dynamic corner margin in mm and the friction limit's margin in W), unless it is there; the
    search itself is not run again."""
    from optimise._state import load_checkpoint

    point = out["runs"][run]
    path = pathlib.Path(args.work) / run.replace(":", "_") / "checkpoint.npz"
    if "history" in point or not path.exists():
        return
    h = load_checkpoint(path)["state"].history
    point["history"] = {
        "objective": np.asarray(h.objective)[:, 0].tolist(),
        "ci95": np.asarray(h.ci)[:, 0].tolist(),
        "gradient_per_unit_box": np.asarray(h.gradient)[:, 0].tolist(),
        "gradient_stderr": np.asarray(h.gradient_stderr)[:, 0].tolist(),
        "dynamic_corner_margin_mm": (np.asarray(h.margins)[:, 0, 4] * 1e3).tolist(),
        # the friction limit's margin (limit - upper 95 % bound) [W], where a limit was set
        **(
            {"friction_limit_margin_W": np.asarray(h.margins)[:, 0, 5].tolist()}
            if point["max_friction_power_W"]
            else {}
        ),
        "variables": [v.key for v in _profile_table()],
    }
    _common.write_json(args.name, out)


def _profile_table():
    from optimise import ProfileBounds

    return ProfileBounds.TABLE


def _errorbar(ax, row: dict, **style) -> None:
    f, q = row["friction_power_W"], row["mean_pv_GPa_m_s"]
    ax.errorbar(
        f["value"],
        q["value"],
        xerr=[[f["value"] - f["ci95_low"]], [f["ci95_high"] - f["value"]]],
        yerr=[[q["value"] - q["ci95_low"]], [q["ci95_high"] - q["value"]]],
        **style,
    )


def _plot_front(runs: dict, path: str) -> None:
    from jaxbearing.io import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4.2))
    found = {k: r for k, r in runs.items() if r["found"]}
    for k, r in found.items():
        _errorbar(ax, r["optimum"], fmt="o", color="C0", label=None)
        what = "min PV" if r["statistic"] == "mean" else "min friction"
        limit = "" if r["max_friction_power_W"] is None else f", P <= {r['max_friction_power_W']:g} W"
        f, q = r["optimum"]["friction_power_W"]["value"], r["optimum"]["mean_pv_GPa_m_s"]["value"]
        ax.annotate(what + limit, (f, q), textcoords="offset points", xytext=(6, 6), fontsize=8)
    if found:
        _errorbar(ax, next(iter(found.values()))["reference"], fmt="s", color="C1", label="reference design")
        ax.legend(fontsize=8)
    ax.set_xlabel("total flange friction power [W] (verified, worst speed)")
    ax.set_ylabel("mean flange PV [GPa m/s] (verified, worst speed)")
    ax.set_title("Profile searches: verified mean PV against friction power")
    fig.tight_layout()
    pathlib.Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="what", required=True)
    f = sub.add_parser("faces")
    f.add_argument("--design", required=True, help="the profile design: eight values (module docstring)")
    f.add_argument("--three", default=THREE_VARIABLE_OPTIMUM)
    f.add_argument("--plot", required=True)
    r = sub.add_parser("front")
    r.add_argument(
        "--runs", default="mean:none", help="STATISTIC:LIMIT_W, comma-separated (front's docstring)"
    )
    r.add_argument("--speeds-rpm", default="30000")
    r.add_argument("--slices", type=int, default=11)
    r.add_argument("--seeds", type=int, default=2)
    r.add_argument("--verify-seeds", type=int, default=4)
    r.add_argument("--starts", type=int, default=1)
    r.add_argument("--iterations", type=int, default=3)
    r.add_argument("--choose", default="best", help="which tied design a run returns (optimise run --choose)")
    r.add_argument("--name", default="profile_front")
    r.add_argument("--work", default="runs/profile_front", help="checkpoint folder of the searches")
    r.add_argument("--plot", default="")
    args = p.parse_args(argv)
    return faces(args) if args.what == "faces" else front(args)


if __name__ == "__main__":
    sys.exit(main())
