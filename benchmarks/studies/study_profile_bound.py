"""How far below the three-variable optimum can a profile go at the optimum's own loads?

    python benchmarks/studies/study_profile_bound.py --slices 11 --seeds 4 --name profile_bound

Which constraint binds. The three-variable optimum (101.6 mm / 1.527 deg / 0.140 mm, the
bearing's own corner radius, flange height, spherical end and cone rib) settles `--seeds` seeds
at every speed of examples/optimise_profile.toml (10,000-30,000 rpm, 1000 N; skid start, settled
by the verdict, a `--window-revs` window: `design.steady_design_metrics_points`), and a plain
solve of `--window-ms` from each of its settled states (the window's start and end) saves
`--saves-per-ms` states per ms (`design.trajectory_states`). Holding every saved pose, velocity
and flange load (`design.held_contacts`), the held-load objective (`design.held_readouts`,
docs/model.md 17) gives the settled mean and peak flange PV of any profile design of the eight
variables, and the distance of its largest held contact radius from the limited circle. That
distance must be at least the optimum's own ("as safe"), at least the search's corner margin
of 0.05 mm ("margin") or is not constrained ("none"); the static zone margins
(`flange.zone_margins`) are >= 0 in every case. At the optimum the held mean PV is also the
frozen-load estimate of the same windows (`design.frozen_load_gradients`), recorded beside it
as a check.

Per corner rule, SLSQP over the box of examples/optimise_profile.toml (scaled to [0, 1]^8) from
the optimum and from `--starts` designs (the best gradient-free designs of
results/study_gradient_free_profile_30000rpm_11slices.json, then Halton points) minimises, for
every speed alone, J at that speed against the optimum's, and once the largest of the three
ratios (every speed at once: what acceptance demands). A ratio near 1 under "as safe" is the
finding "no profile does better at these loads"; the same ratio under "none" says how much the
corner costs. What the held loads leave out: how a design changes the loads and the poses (the
dynamics); a design the held minimum calls better is a candidate for settled running on unseen
seeds (`study_unseen_seeds.py`), not a result. The evaluator and the SLSQP step are
`optimise.held_load_search`'s (`optimise/_held_load.py`).

Writes results/NAME.json: the settings, per speed the optimum's settled mean PV, its held mean
PV and the frozen-load estimate, the held ratios of the starts, and per rule and objective the
best ratio, the design (engineering units), its zone margins and the variables at a bound.
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

#: the three-variable search's optimum (R_end [mm], theta_f [deg], Delta_bf [mm])
THREE_VARIABLE_OPTIMUM = (101.6, 1.527, 0.140)
RULES = ("as safe", "margin", "none")


def _optimum_si(bearing) -> np.ndarray:
    """The three-variable optimum as the eight profile variables [SI]
    (`flange.ProfileVariables.from_design`: the bearing's other faces)."""
    from jaxbearing.flange import DesignVariables, ProfileVariables

    r_end, theta, delta = THREE_VARIABLE_OPTIMUM
    design = DesignVariables(r_end * 1e-3, np.deg2rad(theta), delta * 1e-3)
    return np.array(ProfileVariables.from_design(design, bearing).as_array(), dtype=float)


def _settle(bearing, ops, x0, args):
    from jaxbearing.design import (
        frozen_load_gradients,
        held_contacts,
        steady_design_metrics_points,
        trajectory_states,
    )
    from jaxbearing.flange import ProfileVariables
    from jaxbearing.run import SteadySettings

    design = ProfileVariables.from_array(x0)
    settings = SteadySettings(seeds=args.seeds, window_revs=args.window_revs)
    metrics = steady_design_metrics_points(
        bearing, ops, [design] * len(ops), settings, first_seed=args.first_seed
    )
    general = design.apply(bearing)
    n = max(1, int(round(args.window_ms * args.saves_per_ms)))
    held = []
    for op, m in zip(ops, metrics):
        import jax

        trajectories = []
        for state in m.sample_states:
            ys, code = trajectory_states(general, op, state, args.window_ms * 1e-3, n)
            if int(code) == 0:
                trajectories.append(ys)
        states = jax.tree_util.tree_map(lambda *a: np.concatenate(a), *trajectories)
        held.append(held_contacts(bearing, op, design, states))
    # the search's frozen-load estimate of the same windows: the held J at x0 must equal it
    estimates = frozen_load_gradients(
        [(bearing, op, design, m.sample_states) for op, m in zip(ops, metrics)],
        window=args.window_ms * 1e-3,
        saves_per_ms=args.saves_per_ms,
    )
    return metrics, held, [g.value / 1e9 for g in estimates]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--slices", type=int, default=11)
    p.add_argument("--seeds", type=int, default=4)
    p.add_argument("--first-seed", type=int, default=0)
    p.add_argument("--window-revs", type=int, default=2)
    p.add_argument("--window-ms", type=float, default=2.0)
    p.add_argument("--saves-per-ms", type=int, default=100)
    p.add_argument("--starts", type=int, default=4, help="starts besides the optimum")
    p.add_argument("--maxiter", type=int, default=60, help="SLSQP iterations per start")
    p.add_argument("--rules", default=",".join(RULES), help="corner rules: " + ", ".join(RULES))
    p.add_argument(
        "--objectives", default="every speed,10000,20000,30000", help="'every speed' and single speeds [rpm]"
    )
    p.add_argument("--name", default="profile_bound")
    args = p.parse_args(argv)

    import jaxbearing as jb
    from jaxbearing.flange import ProfileVariables, zone_margins
    from jaxbearing.geometry import rpm_to_rad_s
    from optimise import ProfileBounds
    from optimise._held_load import held_evaluator, held_minimum
    from optimise._problem import halton_points

    t0 = time.perf_counter()
    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=args.slices)
    speeds = (10000.0, 20000.0, 30000.0)
    op0 = jb.reference_operating_point()
    ops = [dataclasses.replace(op0, inner_speed=np.asarray(rpm_to_rad_s(v))) for v in speeds]
    box = ProfileBounds()  # = the box of examples/optimise_profile.toml
    lower, upper = np.asarray(box.lower, float), np.asarray(box.upper, float)
    x0 = _optimum_si(bearing)
    u0 = (x0 - lower) / (upper - lower)
    metrics, held, frozen = _settle(bearing, ops, x0, args)
    _common.log(
        f"settled in {time.perf_counter() - t0:.0f} s; held contacts {[h.load.shape[0] for h in held]}"
    )

    at = held_evaluator(
        bearing,
        held,
        lower,
        upper,
        lambda u: zone_margins(
            bearing, ProfileVariables.from_array(lower + u * (upper - lower)), flange_load=100.0
        ),
    )
    r0, _ = at(u0)
    ref = r0[:9].reshape(3, 3)
    _common.log(f"optimum held: mean {ref[:, 0]}, peak {ref[:, 1]}, corner distance {ref[:, 2]} m")

    keys = [v.key for v in ProfileBounds.TABLE]
    starts = [("three-variable optimum", u0)]
    free = ROOT / "benchmarks" / "results" / "study_gradient_free_profile_30000rpm_11slices.json"
    if free.exists():
        runs = [
            r for r in json.loads(free.read_text())["runs"] if r.get("verified") and r["method"] != "gradient"
        ]
        runs.sort(key=lambda r: r["verified"][0]["value"])
        for r in runs[: min(2, args.starts)]:
            starts.append(
                (f"{r['method']} {r['repeat']}", (np.asarray(r["design"]) - lower) / (upper - lower))
            )
    for k, h in enumerate(halton_points(max(0, args.starts - len(starts) + 1), 8)):
        starts.append((f"Halton {k}", np.asarray(h)))

    start_ratios = {label: [float(at(u)[0][3 * i] / ref[i, 0]) for i in range(3)] for label, u in starts}

    def corner_floor(rule):
        if rule == "as safe":
            return ref[:, 2]
        if rule == "margin":
            return np.full(3, 0.05e-3)
        return None

    results = []
    for rule in args.rules.split(","):
        floor = corner_floor(rule)
        for target in args.objectives.split(","):
            best = None
            for label, u_start in starts:
                speeds_idx = [0, 1, 2] if target == "every speed" else [speeds.index(float(target))]
                u, res = held_minimum(at, ref[:, 0], u_start, speeds_idx, floor, args.maxiter)
                r, _ = at(u)
                feasible = bool(
                    np.all(r[9:] >= -1e-9) and (floor is None or np.all(r[2:9:3] - floor >= -1e-9))
                )
                ratios = [float(r[3 * i] / ref[i, 0]) for i in range(3)]
                worst = max(ratios[i] for i in speeds_idx)
                row = {
                    "rule": rule,
                    "objective": target,
                    "start": label,
                    "ratio": worst,
                    "mean_pv_ratios": ratios,
                    "peak_pv_ratios": [float(r[3 * i + 1] / ref[i, 1]) for i in range(3)],
                    "corner_distance_mm": [float(r[3 * i + 2] * 1e3) for i in range(3)],
                    "zone_margins_mm": [float(v * 1e3) for v in r[9:]],
                    "feasible": feasible,
                    "iterations": int(res.nit),
                    "design": box.engineering_values(lower + u * (upper - lower)),
                    "bounds_active": [k for k, v in zip(keys, u) if v < 1e-6 or v > 1 - 1e-6],
                }
                _common.log(f"{rule} / {target} from {label}: ratio {worst:.4f} feasible {feasible}")
                if feasible and (best is None or worst < best["ratio"]):
                    best = row
            results.append(best or {"rule": rule, "objective": target, "ratio": None})
    out = {
        "settings": {k: v for k, v in vars(args).items() if k != "name"},
        "three_variable_optimum": list(THREE_VARIABLE_OPTIMUM),
        "speeds_rpm": list(speeds),
        "settled_mean_pv_GPa_m_s": [
            {k: v / 1e9 for k, v in m.mean_pv.as_dict().items() if k in ("value", "ci95_low", "ci95_high")}
            for m in metrics
        ],
        "held_samples": [int(h.load.shape[0]) for h in held],
        "held_weight_share": [h.weight_share for h in held],
        "held_mean_pv_GPa_m_s": ref[:, 0].tolist(),
        "frozen_estimate_mean_pv_GPa_m_s": frozen,
        "held_peak_pv_GPa_m_s": ref[:, 1].tolist(),
        "held_corner_distance_mm": (ref[:, 2] * 1e3).tolist(),
        "start_mean_pv_ratios": start_ratios,
        "bounds": results,
        "wall_s": time.perf_counter() - t0,
        "command": "python benchmarks/studies/study_profile_bound.py "
        + " ".join(sys.argv[1:] if argv is None else argv),
        "machine": _common.machine_info(),
    }
    _common.write_json(args.name, out)
    for row in results:
        print(row.get("rule"), "/", row.get("objective"), ":", row.get("ratio"), row.get("mean_pv_ratios"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
