"""Misalignment study (issue 14, item 5) on settled running: mean roller skew and mean flange
load against an imposed inner-ring misalignment (tilt about +Y, `OperatingPoint.misalignment`)
at the reference point (arc end, 20,000 rpm, 1000 N, gravity on; inner ring held axially and in
tilt).

Every misalignment is run as `jaxbearing.simulate(bearing, op, settle="auto", window_revs=...,
seeds=..., workers=...)`: from the skid start (the default) with projective steps of the cage
speed until the revolution-mean cage speed changes by less than 1e-3 between two revolutions
(cap 300 ms; docs/model.md 16), then a window of whole cage revolutions. Reported per case, over
the window, with 95 % intervals (Student-t over the seeds' means, N-1 dof):

* mean roller skew: `roller_skew_rad.mean_abs`, the time-mean of |e . e_tan| over rollers
  (skew measured against the bearing frame, i.e. against the fixed outer ring);
* mean flange load, two ways:
  - `total_flange_load_N`: the time-mean of the sum of all flange normal forces (all rollers,
    all four flanges), per cage revolution, computed here from the window histories;
  - `flange_force_N.mean`: the mean peak normal force of the flange contact events;
* how each seed settled (settled or cap hit, settling time, projective steps).

A step between neighbouring misalignments counts as resolved when the two intervals do not
overlap, or when the Welch 95 % interval of the difference of the means excludes 0 (both are
recorded).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]

import _common  # noqa: E402

NAME = "bench_misalignment"

FULL = {"misalignments_mrad": [0.0, 0.5, 1.0, 2.0], "window_revs": 4, "seeds": 4, "workers": 2}
#: reduced size (tests/test_misalignment_trend.py): one seed, a 2-revolution window
QUICK = {"misalignments_mrad": [0.0, 1.0, 2.0], "window_revs": 2, "seeds": 1, "workers": 1}


def case(misalignment_mrad: float, window_revs: int, seeds: int, workers: int) -> dict:
    """One misalignment: the settled run's skew and flange-load statistics with 95 % intervals."""
    import equinox as eqx
    import jax.numpy as jnp

    import jaxbearing as jb

    bearing = jb.reference_bearing()
    op = eqx.tree_at(
        lambda o: o.misalignment, jb.reference_operating_point(), jnp.asarray(misalignment_mrad * 1e-3)
    )
    start = time.perf_counter()
    result = jb.simulate(bearing, op, settle="auto", window_revs=window_revs, seeds=seeds, workers=workers)
    summary = jb.summarise(result)
    row = {
        "misalignment_mrad": misalignment_mrad,
        "status": summary["status"],
        "settled": summary["settled"],
        "settle_time_ms_max": summary["settle_time_ms"],
        "per_seed_settling": [
            {
                "seed": s["seed"],
                "settled": s["settled"],
                "settle_time_ms": s["settle_time_ms"],
                "cap_hit": not s["settled"],
                "projective_steps_rpm": s["projective_steps_rpm"],
                "start_cage_speed_rpm": s["start_cage_speed_rpm"],
                "revolution_cage_speed_rpm": s["revolution_cage_speed_rpm"],
            }
            for s in summary["per_seed"]
        ],
        "wall_s": time.perf_counter() - start,
    }
    if summary["status"] != "ok":
        return row
    means = _common.seed_means(result)
    total = _common.interval(means["total_flange_load_N"]) if seeds > 1 else None
    if total is None:  # one seed: batch means over the window's revolutions
        total = _common.interval(_common.seed_revolution_values(result)[0]["total_flange_load_N"])
    row["_per_seed"] = {
        "roller_skew_rad_mean_abs": means["roller_skew_rad.mean_abs"],
        "total_flange_load_N": means["total_flange_load_N"],
        "flange_event_peak_force_N_mean": means["flange_force_N.mean"],
    }
    row.update(
        {
            "window_ms": summary["window_ms"],
            "ci_method": summary["ci_method"],
            "roller_skew_rad_mean_abs": summary["roller_skew_rad"]["mean_abs"],
            "roller_skew_rad_max_abs": summary["roller_skew_rad"]["max_abs"],
            "total_flange_load_N": total,
            "per_seed_means": row["_per_seed"],
            "flange_event_peak_force_N_mean": summary["flange_force_N"]["mean"],
            "flange_contact_events_per_rev": summary["flange_contact_events_per_rev"],
            "cage_speed_rpm": summary["cage_speed_rpm"],
            "num_steps": summary["num_steps"],
            "solve_wall_s": summary["wall_time_s"],
        }
    )
    return row


def monotone(rows: list[dict], key: str) -> dict:
    """Whether the means increase with misalignment, and whether each step is resolved at 95 %:
    intervals not overlapping, or (with several seeds) the Welch interval of the difference
    excluding 0."""
    vals = [r[key] for r in rows]
    means = [v["value"] for v in vals]
    steps = []
    for (ra, a), (rb, b) in zip(zip(rows, vals), zip(rows[1:], vals[1:])):
        step = {
            "from_mrad": ra["misalignment_mrad"],
            "to_mrad": rb["misalignment_mrad"],
            "increase": b["value"] - a["value"],
            "intervals_disjoint": bool(
                a["ci95_high"] is not None and b["ci95_low"] is not None and b["ci95_low"] > a["ci95_high"]
            ),
        }
        sa, sb = ra.get("_per_seed", {}).get(key), rb.get("_per_seed", {}).get(key)
        if sa is not None and len(sa) > 1 and len(sb) > 1:
            step["difference_welch"] = _common.welch_difference(sa, sb)
            step["difference_excludes_0"] = step["difference_welch"]["ci95_low"] > 0
        else:
            step["difference_excludes_0"] = False
        step["resolved"] = step["intervals_disjoint"] or step["difference_excludes_0"]
        steps.append(step)
    return {
        "means": means,
        "increasing": all(b > a for a, b in zip(means, means[1:])),
        "every_step_resolved_at_95": all(s["resolved"] for s in steps),
        "steps": steps,
    }


def study(misalignments_mrad, window_revs, seeds, workers=1, log=print) -> dict:
    rows = []
    for m in misalignments_mrad:
        row = case(m, window_revs, seeds, workers)
        settle = ", ".join(
            f"seed {s['seed']}: {'settled' if s['settled'] else 'CAP HIT'} at {s['settle_time_ms']:.1f} ms"
            for s in row["per_seed_settling"]
        )
        log(
            f"misalignment {m:g} mrad: {row['status']} ({settle})"
            + (
                f", skew {row['roller_skew_rad_mean_abs']['value'] * 1e3:.4f} mrad, "
                f"total flange load {row['total_flange_load_N']['value']:.2f} N "
                f"({row['wall_s']:.0f} s)"
                if row["status"] == "ok"
                else ""
            )
        )
        rows.append(row)
    ok = all(r["status"] == "ok" for r in rows)
    trend = {}
    if ok:
        trend = {
            "roller_skew_mean_abs": monotone(rows, "roller_skew_rad_mean_abs"),
            "total_flange_load": monotone(rows, "total_flange_load_N"),
            "flange_event_peak_force_mean": monotone(rows, "flange_event_peak_force_N_mean"),
        }
    for r in rows:
        r.pop("_per_seed", None)
    return {"rows": rows, "trend": trend, "ok": ok, "all_settled": all(r["settled"] for r in rows)}


def _ci(est, scale=1.0, digits=3):
    if est["value"] is None:
        return "-"
    return (
        f"{est['value'] * scale:.{digits}f} [{est['ci95_low'] * scale:.{digits}f}, "
        f"{est['ci95_high'] * scale:.{digits}f}]"
    )


def main(quick: bool = False) -> dict:
    cfg = QUICK if quick else FULL
    started = time.perf_counter()
    out = study(**cfg, log=_common.log)
    result = {
        "quick": quick,
        "command": "python benchmarks/studies/bench_misalignment.py" + (" --quick" if quick else ""),
        "operating_point": "reference: arc end, 20000 rpm, 1000 N radial, gravity on; inner ring held axially and in tilt",
        "misalignment_axis": "inner-ring tilt about +Y (perpendicular to the radial load along +Z)",
        "settling": "settle='auto' from the skid start (projective steps), tolerance 1e-3, cap 300 ms",
        **cfg,
        **out,
        "benchmark_wall_s": time.perf_counter() - started,
        "machine": _common.machine_info(),
    }
    if out["ok"]:
        result["table"] = _common.format_table(
            f"Misalignment study, settled (auto) from the skid start: window {cfg['window_revs']} revs, "
            f"{cfg['seeds']} seed(s); mean [95 % CI]",
            [
                "misalignment mrad",
                "settled at ms",
                "mean |skew| mrad",
                "total flange load N",
                "event peak force N",
            ],
            [
                [
                    r["misalignment_mrad"],
                    ", ".join(
                        f"{s['settle_time_ms']:.1f}" + ("" if s["settled"] else " (cap)")
                        for s in r["per_seed_settling"]
                    ),
                    _ci(r["roller_skew_rad_mean_abs"], 1e3, 4),
                    _ci(r["total_flange_load_N"], 1.0, 2),
                    _ci(r["flange_event_peak_force_N_mean"], 1.0, 2),
                ]
                for r in out["rows"]
            ],
        )
        print(result["table"])
        for k, v in out["trend"].items():
            steps = "; ".join(
                f"{s['from_mrad']:g}->{s['to_mrad']:g}: {'resolved' if s['resolved'] else 'NOT resolved'}"
                for s in v["steps"]
            )
            print(f"{k}: increasing {v['increasing']}; {steps}")
    _common.write_json(NAME if not quick else NAME + "_quick", result)
    return result


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
