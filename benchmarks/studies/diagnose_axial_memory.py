"""Do the rollers' axial positions remember the start-up? (issue 13, the Delta_bf replication)

The one significant Delta_bf central difference (R_end 100 mm / theta_f 1.4 deg, seeds 0-7) did
not replicate with seeds 8-15 (opposite sign, `bench_steady_gradient.py --replicate-clearance`).
The hypothesis recorded then: a slow variable with almost no restoring force, plausibly the
rollers' axial positions between the flanges, carries the start-up history into the 2-revolution
windows of the design objective. This measures it on settled running at that design:

1. From the kept runs of both batches (`out/bench_steady_gradient/`, no simulation): the
   rollers' axial positions at the end of the base, plus and minus runs, per seed.
2. One settled run per seed (skid start, settle "auto", `WINDOW_REVS` window revolutions, seeds
   0-3 in two processes) with the roller axial positions sampled 1320 times per revolution:
   - the integrated autocorrelation time tau_int (Sokal's window, c = 5) of each roller's axial
     position, and of the roller-mean axial position (which flange the set of rollers leans to);
   - the share of time each roller rests against a flange stop (|x| within 5 um of the largest
     |x| seen);
   - the per-revolution smooth mean PV (the objective's integrand) and its lag-1 correlation
     over revolutions: memory the objective's 2-revolution windows would carry;
   - the trend of the per-revolution PV and cage speed over the window (least-squares slope
     per revolution, per seed, and the seeds' mean slope with a Student-t interval): does the
     bearing still drift after the settling criterion (revolution-mean cage speed within 1e-3)
     has passed?
Compared with the objective's window (2 revolutions): tau_int much longer than a window means a
window average depends on where the window starts, i.e. on the start-up history.

    python benchmarks/studies/diagnose_axial_memory.py      # about 3-5 minutes on 2 cores

Not a `bench_*` (not in `make bench`); writes benchmarks/results/diagnose_axial_memory.json.
"""

from __future__ import annotations

import math
import pathlib
import sys
import time

import numpy as np

sys.path[:0] = [
    str(pathlib.Path(__file__).resolve().parent),
    str(pathlib.Path(__file__).resolve().parents[1]),
]
import _common  # noqa: E402

NAME = "diagnose_axial_memory"
MM, DEG = 1e-3, math.pi / 180
DESIGN = (100 * MM, 1.4 * DEG, 0.15 * MM)  # bench_steady_gradient's "R100_t1.4"
WINDOW_REVS = 12
SEEDS = 4
KEPT = pathlib.Path(__file__).resolve().parents[2] / "out" / "bench_steady_gradient"
STOP_BAND = 5e-6  # [m] a roller within this of its extreme |x| rests against a flange


def integrated_autocorrelation_time(x: np.ndarray, c: float = 5.0) -> float:
    """tau_int = 1 + 2 sum_{k=1}^{M} rho(k) in samples, with Sokal's automatic window: the
    smallest M with M >= c tau_int(M) (Sokal 1997, "Monte Carlo methods in statistical
    mechanics", sec. 3). For white noise tau_int = 1; a window of W samples holds about
    W / tau_int independent ones."""
    x = np.asarray(x, float) - np.mean(x)
    n = len(x)
    var = np.dot(x, x) / n
    if n < 4 or var == 0:
        return float("nan")
    f = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[:n] / (n * var)
    tau = 1.0 + 2.0 * np.cumsum(acf[1:])  # tau_int(M) for M = 1 .. n-1
    closed = np.nonzero(np.arange(1, n) >= c * tau)[0]
    # the window never closed: longer than the series can tell
    return float(tau[closed[0]]) if closed.size else float("nan")


def slope_per_revolution(y) -> tuple[float, float]:
    """(least-squares slope of y against its index, its standard error)."""
    y = np.asarray(y, float)
    x = np.arange(len(y)) - (len(y) - 1) / 2
    slope = float(np.dot(x, y - y.mean()) / np.dot(x, x))
    r = y - y.mean() - slope * x
    return slope, float(np.sqrt(np.dot(r, r) / (len(y) - 2) / np.dot(x, x)))


def kept_runs() -> dict:
    """Final roller axial positions of the kept runs of both replication batches [um]."""
    out = {}
    for batch, seeds in (("full", "0-7"), ("rep8", "8-15")):
        runs = {}
        for part in ("base", "axial_clearance_plus", "axial_clearance_minus"):
            path = KEPT / f"{batch}_R100_t1.4_{part}.npz"
            if not path.exists():
                return {"missing": str(path)}
            from jaxbearing.io import load_tree

            r = load_tree(path, what="benchmark state")
            ax = np.array([np.asarray(s.rollers.axial) for s in r["final"]]) * 1e6
            runs[part] = dict(
                roller_mean_um=ax.mean(1).round(2).tolist(),
                roller_std_um=ax.std(1).round(2).tolist(),
                objective_GPa_m_s=(np.asarray(r["per_seed"]) / 1e9).round(4).tolist(),
            )
        plus = np.array(runs["axial_clearance_plus"]["roller_mean_um"])
        minus = np.array(runs["axial_clearance_minus"]["roller_mean_um"])
        runs["seeds"] = seeds
        runs["plus_minus_roller_mean_difference_um"] = (plus - minus).round(2).tolist()
        out[batch] = runs
    return out


def main() -> dict:
    import jaxbearing as jb
    from jaxbearing.design import STEADY_FUNCTIONALS
    from jaxbearing.flange import DesignVariables, with_design

    t0 = time.perf_counter()
    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    d = DesignVariables.from_array(np.asarray(DESIGN))
    b = with_design(bearing, d.end_radius, d.layback_angle, d.axial_clearance)
    _common.log(f"{NAME}: {SEEDS} seeds, skid start, settle auto, {WINDOW_REVS} window revolutions")
    res = jb.simulate_steady(
        b, op, seeds=SEEDS, window_revs=WINDOW_REVS, functionals=STEADY_FUNCTIONALS, workers=2
    )
    pv_ref = float(STEADY_FUNCTIONALS.pv_reference)
    per_seed = []
    for run in res.runs:
        w = run.window
        t = np.asarray(w["t"])
        dt = float(np.median(np.diff(t)))
        rev_s = float(np.mean(np.diff(run.edges)))
        ax = np.asarray(w["roller_axial"])  # (T, Z)
        taus = np.array([integrated_autocorrelation_time(ax[:, j]) for j in range(ax.shape[1])])
        tau_mean = integrated_autocorrelation_time(ax.mean(1))
        extreme = np.max(np.abs(ax))
        at_stop = np.mean(np.abs(ax) > extreme - STOP_BAND, axis=0)
        rev_pv = np.array([pv_ref * a / c if c > 0 else np.nan for a, c in run.window_integrals])
        lag1 = float(np.corrcoef(rev_pv[:-1], rev_pv[1:])[0, 1]) if len(rev_pv) > 2 else float("nan")
        rev_cage = np.asarray(run.revolution_speeds_rpm[-len(rev_pv) :])
        pv_slope, pv_slope_se = slope_per_revolution(rev_pv / 1e9)
        cage_slope, cage_slope_se = slope_per_revolution(rev_cage)
        per_seed.append(
            dict(
                seed=run.seed,
                settled=run.settled,
                settle_time_ms=run.settle_time * 1e3,
                revolution_ms=rev_s * 1e3,
                sample_interval_us=dt * 1e6,
                roller_tau_int_ms=dict(
                    median=float(np.nanmedian(taus) * dt * 1e3),
                    min=float(np.nanmin(taus) * dt * 1e3),
                    max=float(np.nanmax(taus) * dt * 1e3),
                    window_not_closed=int(np.sum(~np.isfinite(taus))),
                ),
                roller_mean_tau_int_ms=tau_mean * dt * 1e3,
                roller_mean_axial_um=dict(
                    start=float(ax[0].mean() * 1e6),
                    end=float(ax[-1].mean() * 1e6),
                    min=float(ax.mean(1).min() * 1e6),
                    max=float(ax.mean(1).max() * 1e6),
                ),
                largest_axial_um=float(extreme * 1e6),
                share_of_time_at_a_flange_stop=dict(
                    mean=float(at_stop.mean()), min=float(at_stop.min()), max=float(at_stop.max())
                ),
                revolution_pv_GPa_m_s=(rev_pv / 1e9).round(4).tolist(),
                revolution_pv_lag1_correlation=lag1,
                revolution_pv_slope_GPa_m_s_per_rev=dict(value=pv_slope, stderr=pv_slope_se),
                revolution_cage_speed_rpm=rev_cage.round(3).tolist(),
                revolution_cage_speed_slope_rpm_per_rev=dict(value=cage_slope, stderr=cage_slope_se),
                settle_revolution_cage_speed_rpm=np.asarray(run.revolution_speeds_rpm[: -len(rev_pv)])
                .round(3)
                .tolist(),
            )
        )
    trends = {
        name: _common.interval([s[key]["value"] for s in per_seed])
        for name, key in (
            ("pv_GPa_m_s_per_rev", "revolution_pv_slope_GPa_m_s_per_rev"),
            ("cage_speed_rpm_per_rev", "revolution_cage_speed_slope_rpm_per_rev"),
        )
    }
    result = dict(
        benchmark=NAME,
        design=dict(end_radius_mm=100.0, layback_angle_deg=1.4, axial_clearance_mm=0.15),
        window_revs=WINDOW_REVS,
        seeds=SEEDS,
        kept_runs=kept_runs(),
        settled_runs=per_seed,
        window_trend_mean_over_seeds=trends,
        wall_s=time.perf_counter() - t0,
    )
    for s in per_seed:
        print(
            f"seed {s['seed']}: rev {s['revolution_ms']:.2f} ms; axial tau_int per roller median "
            f"{s['roller_tau_int_ms']['median']:.2f} ms (max {s['roller_tau_int_ms']['max']:.2f}, "
            f"{s['roller_tau_int_ms']['window_not_closed']} unclosed); roller-mean tau_int "
            f"{s['roller_mean_tau_int_ms']:.2f} ms; at a stop {s['share_of_time_at_a_flange_stop']['mean']:.2f}; "
            f"rev-PV lag-1 corr {s['revolution_pv_lag1_correlation']:+.2f}"
        )
    print(f"window trends, mean over seeds with 95 % interval: {trends}")
    _common.write_json(NAME, result)
    return result


if __name__ == "__main__":
    main()
