"""Flange traction, dry against mixed (issue 14, item 3): the measured consequence of switching
`bearing.flange_lubrication` from "dry" (constant mu_f = 0.08, the default: docs/model.md 5 and the
paper's setting) to "mixed" (mu = f_a(Lambda) mu_f + (1 - f_a(Lambda)) kappa(|u|), the
load-sharing law of docs/model.md 5.1) at the reference point, in settled running.

For each end type (arc, corner) and each law: `jaxbearing.simulate(bearing, op, settle="auto",
window_revs=4, seeds=4, workers=2)` from the skid start, as the settled reference table of docs/performance-history.md
(`jaxbearing simulate --settle auto --seeds 4`, benchmarks/results/settled_reference_4_seeds.json)
but with a window of 4 cage revolutions instead of 8 (the shared 2-core machine). Both laws are
run here with the same code, so the differences are not mixed up with code changes since that
file; the dry runs are also compared with it (reproduction check: the per-revolution statistics do
not depend on the window's length, only their intervals do).

Reported per case, 95 % intervals (Student-t over the 4 seeds' window means, 3 dof): flange PV
max (expected largest per cage revolution) and mean (over contact events) and mean over contact
time, flange friction force mu Q (mean over contact time; time-mean total over all contacts),
mean friction coefficient over contact time, flange normal force max and mean, cage speed and
slip, Lambda median, the share of contact time with Lambda < 1, roller skew; and for each
quantity the difference mixed - dry with its Welch 95 % interval (resolved when it excludes 0).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "bench_flange_lubrication"

FULL = {"seeds": 4, "window_revs": 4, "workers": 2, "ends": ("arc", "corner")}
QUICK = {"seeds": 2, "window_revs": 2, "workers": 2, "ends": ("arc",)}

#: (label, key of `_common.seed_means`, scale, unit)
QUANTITIES = (
    ("PV, max", "flange_pv_Pa_m_s.max", 1e-9, "GPa m/s"),
    ("PV, mean over events", "flange_pv_Pa_m_s.mean", 1e-9, "GPa m/s"),
    ("PV, mean over contact time", "flange_pv_contact_time_Pa_m_s.mean", 1e-9, "GPa m/s"),
    ("friction force mu Q, mean over contact time", "flange_friction_contact_time_N.mean", 1.0, "N"),
    ("friction force, time-mean total", "total_flange_friction_N", 1.0, "N"),
    ("friction coefficient, mean over contact time", "flange_friction_coefficient.mean", 1.0, "-"),
    ("normal force, max", "flange_force_N.max", 1.0, "N"),
    ("normal force, mean over events", "flange_force_N.mean", 1.0, "N"),
    ("normal force, time-mean total", "total_flange_load_N", 1.0, "N"),
    ("peak pressure, max", "flange_pressure_Pa.max", 1e-9, "GPa"),
    ("material sliding speed, mean", "flange_sliding_velocity_m_s.mean", 1.0, "m/s"),
    ("cage speed", "cage_speed_rpm", 1.0, "rpm"),
    ("cage slip", "cage_slip", 100.0, "%"),
    ("Lambda, median", "film_parameter.median", 1.0, "-"),
    ("share of contact time with Lambda < 1", "lambda_below_one_share", 100.0, "%"),
    ("roller skew, mean abs", "roller_skew_rad.mean_abs", 1e3, "mrad"),
)

REFERENCE_FILE = _common.RESULTS_DIR / "settled_reference_4_seeds.json"


def bearing_for(end: str, lubrication: str):
    """The reference bearing with `bearing.flange_lubrication` set through the configuration, and
    flat (corner) ends for "corner"."""
    import jaxbearing as jb

    config = jb.loads_config(f'[bearing]\nflange_lubrication = "{lubrication}"\n')
    bearing = config.bearing()
    return (bearing.with_flat_ends() if end == "corner" else bearing), config.operating_point()


def run_case(end: str, lubrication: str, seeds: int, window_revs: int, workers: int) -> dict:
    """One settled run: its summary, every statistic's per-seed means and their intervals."""
    import jaxbearing as jb

    bearing, op = bearing_for(end, lubrication)
    start = time.perf_counter()
    result = jb.simulate(bearing, op, settle="auto", window_revs=window_revs, seeds=seeds, workers=workers)
    summary = jb.summarise(result)
    out = {
        "end": end,
        "flange_lubrication": lubrication,
        "status": summary["status"],
        "settled": summary["settled"],
        "settle_time_ms_max": summary["settle_time_ms"],
        "per_seed_settling": [
            {k: s[k] for k in ("seed", "settled", "settle_time_ms", "projective_steps_rpm", "num_steps")}
            for s in summary["per_seed"]
        ],
        "window_ms": summary["window_ms"],
        "wall_s": time.perf_counter() - start,
        "solve_wall_s": summary["wall_time_s"],
        "compile_s": summary["compile_time_s"],
    }
    if summary["status"] != "ok":
        return out
    means = _common.seed_means(result)
    out["per_seed_means"] = {key: means[key] for _, key, _, _ in QUANTITIES}
    out["statistics"] = {key: _common.interval(means[key]) for _, key, _, _ in QUANTITIES}
    return out


def compare(dry: dict, mixed: dict) -> dict:
    """mixed - dry of every quantity: the two intervals, the Welch interval of the difference,
    the relative change of the means."""
    rows = {}
    for label, key, scale, unit in QUANTITIES:
        d, m = dry["statistics"][key], mixed["statistics"][key]
        diff = _common.welch_difference(dry["per_seed_means"][key], mixed["per_seed_means"][key])
        rows[key] = {
            "label": label,
            "unit": unit,
            "scale": scale,
            "dry": d,
            "mixed": m,
            "difference_mixed_minus_dry": diff,
            "relative_change": (m["value"] - d["value"]) / d["value"] if d["value"] else None,
        }
    return rows


def reproduction(dry: dict, end: str) -> dict:
    """The dry run against the committed settled reference (same command, earlier code): each
    quantity the file holds, its interval there and here."""
    import json

    ref = json.loads(REFERENCE_FILE.read_text())[end]
    out = {}
    for _, key, _, _ in QUANTITIES:
        group, _, red = key.partition(".")
        there = ref.get(group)
        if there is not None and red:
            there = there.get(red)
        if isinstance(there, dict) and "value" in there:
            here = dry["statistics"][key]
            overlap = here["ci95_low"] <= there["ci95_high"] and there["ci95_low"] <= here["ci95_high"]
            out[key] = {"reference_file": there, "this_run": here, "intervals_overlap": bool(overlap)}
    return out


def _fmt(est, scale):
    return f"{est['value'] * scale:.4g} [{est['ci95_low'] * scale:.4g}, {est['ci95_high'] * scale:.4g}]"


def main(quick: bool = False) -> dict:
    cfg = QUICK if quick else FULL
    started = time.perf_counter()
    cases, comparison, repro = {}, {}, {}
    for end in cfg["ends"]:
        for lub in ("dry", "mixed"):
            _common.log(f"{end} end, flange_lubrication = {lub!r}: settled run, {cfg['seeds']} seeds ...")
            case = run_case(end, lub, cfg["seeds"], cfg["window_revs"], cfg["workers"])
            _common.log(f"  {case['status']}, settled {case['settled']}, {case['wall_s']:.0f} s")
            cases[f"{end}_{lub}"] = case
        dry, mixed = cases[f"{end}_dry"], cases[f"{end}_mixed"]
        if dry["status"] == "ok" and mixed["status"] == "ok":
            comparison[end] = compare(dry, mixed)
            if not quick:
                repro[end] = reproduction(dry, end)
    result = {
        "quick": quick,
        "command": "python benchmarks/studies/bench_flange_lubrication.py" + (" --quick" if quick else ""),
        "equivalent_cli": (
            "jaxbearing simulate --settle auto --seeds 4 --workers 2 --end both, once with the default "
            'configuration and once with [bearing] flange_lubrication = "mixed"'
        ),
        "operating_point": "reference: 20000 rpm, 1000 N radial, gravity on, R_end 80 mm (arc) or flat (corner)",
        "settling": "settle='auto' from the skid start (projective steps), tolerance 1e-3, cap 300 ms",
        "seeds": cfg["seeds"],
        "window_revs": cfg["window_revs"],
        "workers": cfg["workers"],
        "ci_method": "Student-t over the seeds' window means (N-1 dof); differences: Welch",
        "cases": cases,
        "comparison_mixed_vs_dry": comparison,
        "dry_against_settled_reference_4_seeds": repro,
        "benchmark_wall_s": time.perf_counter() - started,
        "machine": _common.machine_info(),
    }
    tables = []
    for end, rows in comparison.items():
        tables.append(
            _common.format_table(
                f"{end} end: dry (mu_f 0.08) vs mixed, settled, {cfg['seeds']} seeds; mean [95 % CI]",
                ["quantity", "unit", "dry", "mixed", "mixed - dry [Welch 95 %]", "change"],
                [
                    [
                        r["label"],
                        r["unit"],
                        _fmt(r["dry"], r["scale"]),
                        _fmt(r["mixed"], r["scale"]),
                        _fmt(r["difference_mixed_minus_dry"], r["scale"])
                        + ("" if r["difference_mixed_minus_dry"]["resolved"] else " (n.s.)"),
                        "-" if r["relative_change"] is None else f"{100 * r['relative_change']:+.1f} %",
                    ]
                    for r in rows.values()
                ],
            )
        )
    result["tables"] = tables
    for t in tables:
        print(t)
    _common.write_json(NAME if not quick else NAME + "_quick", result)
    return result


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
