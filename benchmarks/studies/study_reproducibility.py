"""Does the documented design search give the same answer under other float roundings and
another worker count?

    python benchmarks/studies/study_reproducibility.py \
        --runs benchmarks/results/optimise_3speed_risk_run_idle.json,OTHER.json \
        --labels "2 workers, AVX-512",NAME --name optimise_3speed_reproducibility

Each run is the result.json of the same `optimise run` command (or a results file holding one),
made on a machine that differs in the instructions XLA may use (`XLA_FLAGS=--xla_cpu_max_isa=...`
changes vector widths and fused multiply-adds, hence the roundings of every step: the model is
chaotic, so members diverge after a few milliseconds as they would on another CPU) or in the
number of workers. Nothing is simulated here; the study reads the runs and reports, per run,
the returned design, its objective on the search's seeds, its verification at every speed (mean
and peak flange PV with 95 % intervals on the verification seeds, the corner-risk bound) and its
near-optimal set, and for every pair:

* `same_design`: the returned designs equal to 1e-6 mm / 1e-6 deg (the same answer bit for bit
  or nearly);
* `verified_mean_pv_overlap` / `verified_peak_pv_overlap`: at every speed the 95 % intervals of
  the two returned designs' verified mean (peak) PV overlap;
* `tail_verified_both`: both verifications bound the corner risk below the level at every speed;
* `design_in_other_set`: each returned design lies within the other run's near-optimal set's box
  (the per-variable range of its tied designs);
* `agree`: the verified objectives agree within their intervals and both designs are verified in
  the tail (the reproducibility the docs promise: the design set, not one point).

Writes results/NAME.json; about a second.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import sys

HERE = pathlib.Path(__file__).resolve()
sys.path.insert(0, str(HERE.parents[1]))

import _common  # noqa: E402

VARIABLES = ("end_radius_mm", "layback_angle_deg", "axial_clearance_mm")


def _interval(est: dict) -> list[float]:
    return [est["ci95_low"], est["ci95_high"]]


def _overlap(a: list[float], b: list[float]) -> bool:
    return a[0] <= b[1] and b[0] <= a[1]


def summarise(result: dict, label: str) -> dict:
    """One run: its design, objective, verification per speed and near-optimal set."""
    ver = result["verification"]
    speeds = [p.get("speed_rpm") for p in result["operating_points"]]
    rows = []
    for speed, found, ref in zip(
        speeds, ver["optimum"]["per_operating_point"], ver["reference"]["per_operating_point"]
    ):
        rows.append(
            {
                "speed_rpm": speed,
                "mean_pv_GPa_m_s": _interval(found["mean_pv_GPa_m_s"]),
                "peak_pv_GPa_m_s": _interval(found["peak_pv_GPa_m_s"]),
                "corner_risk_upper": found["corner_risk"]["upper"],
                "reference_mean_pv_GPa_m_s": _interval(ref["mean_pv_GPa_m_s"]),
                "reference_peak_pv_GPa_m_s": _interval(ref["peak_pv_GPa_m_s"]),
            }
        )
    tied = result["near_optimal"]
    box = {v: [min(d[v] for d in tied), max(d[v] for d in tied)] for v in VARIABLES}
    return {
        "label": label,
        "design": {v: result["design"][v] for v in VARIABLES},
        "objective_GPa_m_s": result["objective_GPa_m_s"],
        "verification_seeds": ver["seeds"],
        "per_speed": rows,
        "tail_verified": bool(ver["tail"]["verified"]),
        "risk_level_per_revolution": ver["tail"]["level_per_revolution"],
        "near_optimal": [
            {**{v: d[v] for v in VARIABLES}, "objective_GPa_m_s": d["objective_GPa_m_s"]} for d in tied
        ],
        "near_optimal_box": box,
        "wall_time_s": result.get("wall_time_s"),
        "conditions": result.get("conditions"),
    }


def _inside(design: dict, box: dict) -> bool:
    return all(box[v][0] - 1e-9 <= design[v] <= box[v][1] + 1e-9 for v in VARIABLES)


def compare(a: dict, b: dict) -> dict:
    """The agreement of two summarised runs (module docstring)."""
    same = all(abs(a["design"][v] - b["design"][v]) <= 1e-6 for v in VARIABLES)
    mean = [
        _overlap(x["mean_pv_GPa_m_s"], y["mean_pv_GPa_m_s"]) for x, y in zip(a["per_speed"], b["per_speed"])
    ]
    peak = [
        _overlap(x["peak_pv_GPa_m_s"], y["peak_pv_GPa_m_s"]) for x, y in zip(a["per_speed"], b["per_speed"])
    ]
    ref = [
        _overlap(x["reference_mean_pv_GPa_m_s"], y["reference_mean_pv_GPa_m_s"])
        for x, y in zip(a["per_speed"], b["per_speed"])
    ]
    tail = a["tail_verified"] and b["tail_verified"]
    return {
        "runs": [a["label"], b["label"]],
        "same_design": same,
        "verified_mean_pv_overlap": mean,
        "verified_peak_pv_overlap": peak,
        "reference_mean_pv_overlap": ref,
        "tail_verified_both": tail,
        "design_in_other_set": [
            _inside(a["design"], b["near_optimal_box"]),
            _inside(b["design"], a["near_optimal_box"]),
        ],
        "agree": all(mean) and tail,
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument(
        "--runs", required=True, help="comma-separated result files of the same optimise run command"
    )
    p.add_argument("--labels", required=True, help="comma-separated labels, one per run")
    p.add_argument("--name", default="optimise_3speed_reproducibility")
    args = p.parse_args(argv)
    paths = [pathlib.Path(s) for s in args.runs.split(",")]
    labels = args.labels.split(",")
    if len(labels) != len(paths):
        p.error(f"--labels: {len(labels)} labels for {len(paths)} runs; give one per run")
    runs = [summarise(json.loads(path.read_text()), label) for path, label in zip(paths, labels)]
    pairs = [compare(runs[i], runs[j]) for i in range(len(runs)) for j in range(i + 1, len(runs))]
    out = {
        "runs": runs,
        "files": [str(path) for path in paths],
        "pairs": pairs,
        "command": "python benchmarks/studies/study_reproducibility.py "
        + " ".join(sys.argv[1:] if argv is None else argv),
        "machine": _common.machine_info(),
    }
    for run in runs:
        d = run["design"]
        print(
            f"{run['label']}: {d['end_radius_mm']:.1f} mm / {d['layback_angle_deg']:.3f} deg / "
            f"{d['axial_clearance_mm']:.3f} mm, tail verified {run['tail_verified']}"
        )
        for row in run["per_speed"]:
            m, q = row["mean_pv_GPa_m_s"], row["peak_pv_GPa_m_s"]
            print(
                f"  {row['speed_rpm']:7.0f} rpm: mean PV [{m[0]:.3f}, {m[1]:.3f}], peak [{q[0]:.2f}, {q[1]:.2f}] GPa m/s, "
                f"risk <= {row['corner_risk_upper']:.2g}/rev"
            )
    for pair in pairs:
        print(
            f"{pair['runs'][0]} vs {pair['runs'][1]}: same design {pair['same_design']}, agree {pair['agree']}"
        )
    path = _common.write_json(args.name, out)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
