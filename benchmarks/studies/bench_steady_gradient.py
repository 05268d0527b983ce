"""Gradient estimators of the steady design objective against common-random-number central
differences (issue 13, item 2): ``python benchmarks/studies/bench_steady_gradient.py [--quick]``.

Objective J(d): the smooth mean flange PV over contact time of settled running
(`jaxbearing.design.steady_design_metrics(...).objective`), reference bearing, 20,000 rpm, 1000 N.

At three designs (the reference R_end 80 mm / theta_f 1.6 deg; R_end 70 mm / 1.8 deg; R_end
100 mm / 1.4 deg; Delta_bf 0.15 mm for all):

1. settled states of `SEEDS` seeds: the reference from the skid start (settle auto), the other
   designs continuing from the reference's settled states (settle auto), then a
   `WINDOW_REVS`-revolution window: J with its Student-t CI;
2. the truth: common-random-number central differences, per variable, steps of `FD_STEP` of its
   range (R_end 60-120 mm, theta_f 1.0-2.0 deg, Delta_bf 0.10-0.30 mm, the optimiser's default
   box): both designs d +- h e_i continue from the SAME settled states of d (the same seeds),
   settle one cage revolution, measure the window; per seed (J+ - J-) / 2h, mean and standard
   error over the seeds (paired). Significant where |FD| > 2 SE;
3. the estimators, from the 2 x SEEDS settled states of d (window start and end of every seed):
   the frozen-load estimator (`frozen_load_gradient`, 1 ms trajectories) and the short-window
   forward-mode sensitivities (`steady_gradient`) at windows `WINDOWS`;
4. the growth of the tangents from one settled state (`tangent_growth`, 2 ms): the finite-time
   Lyapunov exponent (least-squares slope of log|tangent| over the window).

Acceptance (issue 13): for each variable, the estimator agrees in sign with the FD wherever the
FD is significant, and in magnitude within 30 %.

Results go to benchmarks/results/bench_steady_gradient.json; every finished design is written
at once (a killed run keeps it and resumes from it: the settled states of finished steps are
kept in out/bench_steady_gradient/, which git ignores).
"""

from __future__ import annotations

import json
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

NAME = "bench_steady_gradient"
MM, DEG = 1e-3, math.pi / 180
DESIGNS = {
    "reference": (80 * MM, 1.6 * DEG, 0.15 * MM),
    "R70_t1.8": (70 * MM, 1.8 * DEG, 0.15 * MM),
    "R100_t1.4": (100 * MM, 1.4 * DEG, 0.15 * MM),
}
RANGES = np.array([60 * MM, 1.0 * DEG, 0.2 * MM])  # widths of the optimiser's default box
VARIABLES = ("end_radius", "layback_angle", "axial_clearance")
FD_STEP = 0.04
SEEDS = 8
WINDOW_REVS = 2
WINDOWS = (0.1e-3, 0.25e-3)
FROZEN_WINDOW = 1.0e-3
STATE_DIR = pathlib.Path(__file__).resolve().parents[2] / "out" / NAME
WORKERS = 2


def _cached(key: str, compute):
    """compute() once; its result kept in STATE_DIR as data (`jaxbearing.io.save_tree`, an
    `.npz`, never a pickle) for a resume after a kill."""
    from jaxbearing.io import load_tree, save_tree

    path = STATE_DIR / f"{key}.npz"
    if path.exists():
        return load_tree(path, what="benchmark state")
    value = compute()
    save_tree(path, value)
    return value


def _settled(bearing, op, x, seeds, window_revs, settle, states, first_seed=0):
    """(per-seed objective [Pa m/s], sample states, final states, wall s) of design x."""
    import jaxbearing as jb
    from jaxbearing.flange import DesignVariables

    t0 = time.perf_counter()
    m = jb.steady_design_metrics(
        bearing,
        op,
        DesignVariables.from_array(np.asarray(x)),
        seeds=seeds,
        window_revs=window_revs,
        settle=settle,
        initial_states=states,
        first_seed=first_seed,
        workers=WORKERS,
    )
    return dict(
        per_seed=m.objective_per_seed,
        objective=m.objective,
        settled=m.settled,
        samples=m.sample_states,
        final=m.final_states,
        wall_s=time.perf_counter() - t0,
    )


def _fd(base_x, i, h, bearing, op, states, key, seeds, settle, window_revs, first_seed=0):
    plus, minus = np.array(base_x), np.array(base_x)
    plus[i] += h
    minus[i] -= h
    rp = _cached(
        f"{key}_{VARIABLES[i]}_plus",
        lambda: _settled(bearing, op, plus, seeds, window_revs, settle, states, first_seed),
    )
    rm = _cached(
        f"{key}_{VARIABLES[i]}_minus",
        lambda: _settled(bearing, op, minus, seeds, window_revs, settle, states, first_seed),
    )
    d = (np.asarray(rp["per_seed"]) - np.asarray(rm["per_seed"])) / (2 * h)
    d = d[np.isfinite(d)]
    return _paired(d, h, rp["wall_s"] + rm["wall_s"])


def _paired(d, h, wall_s) -> dict:
    """Mean and standard error of per-seed differences `d`; significant where |mean| > 2 SE."""
    d = np.asarray(d, dtype=float)
    se = float(np.std(d, ddof=1) / np.sqrt(d.size)) if d.size > 1 else float("nan")
    return dict(
        value=float(np.mean(d)),
        stderr=se,
        significant=bool(abs(np.mean(d)) > 2 * se),
        step=h,
        seeds=int(d.size),
        wall_s=wall_s,
        per_seed=d.tolist(),
    )


def _agreement(estimate, fd) -> dict:
    if not fd["significant"]:
        return dict(checked=False, sign=None, within_30pct=None, relative_error=None)
    rel = abs(estimate - fd["value"]) / abs(fd["value"])
    return dict(
        checked=True,
        sign=bool(np.sign(estimate) == np.sign(fd["value"])),
        within_30pct=bool(rel <= 0.3),
        relative_error=float(rel),
    )


def _ftle(ts, norms) -> float:
    """Least-squares slope of log(norm) over the saves after the first (1/s), mean over the
    three design directions."""
    keep = ts > 0
    return float(np.mean([np.polyfit(ts[keep], np.log(n[keep]), 1)[0] for n in norms]))


def main(
    quick: bool = False, *, tag: str | None = None, short_windows: bool = True, into: str | None = None
) -> dict:
    """The study (module docstring). `tag` names its kept runs in STATE_DIR (default "quick" or
    "full"); `short_windows=False` leaves out the short-window estimators and the tangent growth;
    `into` writes the result under that key of the existing JSON instead of replacing it."""
    import jaxbearing as jb
    from jaxbearing.design import frozen_load_gradient, steady_gradient, tangent_growth
    from jaxbearing.flange import DesignVariables

    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    seeds = 2 if quick else SEEDS
    designs = dict(list(DESIGNS.items())[:1]) if quick else DESIGNS
    windows = (WINDOWS[:1] if quick else WINDOWS) if short_windows else ()
    tag = tag or ("quick" if quick else "full")
    t_start = time.perf_counter()
    ref_x = np.array(DESIGNS["reference"])
    ref = _cached(
        f"{tag}_reference_base", lambda: _settled(bearing, op, ref_x, seeds, WINDOW_REVS, "auto", None)
    )
    out = {"benchmark": NAME, "quick": quick, "machine": _common.machine_info(), "designs": {}}
    rows = []
    for name, x in designs.items():
        x = np.array(x)
        _common.log(f"{NAME}: design {name}")
        base = (
            ref
            if name == "reference"
            else _cached(
                f"{tag}_{name}_base",
                lambda: _settled(bearing, op, x, seeds, WINDOW_REVS, "auto", ref["final"]),
            )
        )
        d = DesignVariables.from_array(x)
        b = d.apply(bearing)
        rev_ms = 2 * math.pi / abs(float(np.asarray(base["final"][0].cage.speed))) * 1e3
        fd = [
            _fd(
                x,
                i,
                FD_STEP * RANGES[i],
                bearing,
                op,
                base["final"],
                f"{tag}_{name}",
                seeds,
                rev_ms,
                WINDOW_REVS,
            )
            for i in range(3)
        ]
        t0 = time.perf_counter()
        frozen = frozen_load_gradient(b, op, d, base["samples"], window=FROZEN_WINDOW, workers=WORKERS)
        frozen_wall = time.perf_counter() - t0
        short = {}
        for w in windows:
            t0 = time.perf_counter()
            g = steady_gradient(b, op, d, base["samples"], window=w, workers=WORKERS)
            short[w] = (g, time.perf_counter() - t0)
        if short_windows:
            t0 = time.perf_counter()
            ts, norms = tangent_growth(
                b, op, d, base["samples"][0], 1.0e-3 if quick else 2.0e-3, num_saves=21
            )
            growth = dict(t_s=ts.tolist(), norms=norms.tolist(), ftle_per_s=_ftle(ts, norms))
            growth["wall_s"] = time.perf_counter() - t0
        else:
            growth = None

        def est(g, wall):
            return dict(
                value=g.value,
                gradient=g.gradient.tolist(),
                stderr=g.gradient_stderr.tolist(),
                samples=g.num_samples,
                wall_s=wall,
                agreement={v: _agreement(g.gradient[i], fd[i]) for i, v in enumerate(VARIABLES)},
            )

        entry = dict(
            design={
                "end_radius_mm": x[0] / MM,
                "layback_angle_deg": x[1] / DEG,
                "axial_clearance_mm": x[2] / MM,
            },
            objective_Pa_m_s=base["objective"],
            settled=base["settled"],
            base_wall_s=base["wall_s"],
            central_difference={v: fd[i] for i, v in enumerate(VARIABLES)},
            frozen_load=est(frozen, frozen_wall) | {"window_s": FROZEN_WINDOW},
            short_window={
                f"{w * 1e3:g}_ms": est(g, wall) | {"window_s": w} for w, (g, wall) in short.items()
            },
            tangent_growth=growth,
        )
        out["designs"][name] = entry
        for i, v in enumerate(VARIABLES):
            f = fd[i]
            rows.append(
                [
                    name,
                    v,
                    f"{f['value']:.3e} +- {f['stderr']:.1e}{'' if f['significant'] else ' (n.s.)'}",
                    f"{frozen.gradient[i]:.3e} +- {frozen.gradient_stderr[i]:.1e}",
                ]
                + [f"{g.gradient[i]:.3e} +- {g.gradient_stderr[i]:.1e}" for g, _ in short.values()]
            )
        _write(out | {"partial": True}, into)
    checks = [
        a for e in out["designs"].values() for a in e["frozen_load"]["agreement"].values() if a["checked"]
    ]
    out["frozen_load_acceptance"] = dict(
        checked=len(checks),
        sign=sum(bool(a["sign"]) for a in checks),
        within_30pct=sum(bool(a["within_30pct"]) for a in checks),
    )
    out["wall_time_s"] = time.perf_counter() - t_start
    out["table"] = _common.format_table(
        "dJ/dx of the steady mean PV [Pa m/s per m or rad]: CRN central difference vs estimators",
        ["design", "variable", f"CRN FD ({seeds} seeds)", "frozen load"]
        + [f"short window {w * 1e3:g} ms" for w in windows],
        rows,
    )
    print(out["table"])
    _write(out, into)
    return out


def _results() -> dict:
    """The study's JSON as written so far ({} before the first write)."""
    path = _common.RESULTS_DIR / f"{NAME}.json"
    return json.loads(path.read_text()) if path.exists() else {}


def _write(out: dict, into: str | None) -> None:
    """Write the study's JSON, or put `out` under the key `into` of the existing one."""
    if into is None:
        _common.write_json(NAME, out)
        return
    _common.write_json(NAME, _results() | {into: out})


REPLICATE = "R100_t1.4"
REPLICATE_FIRST_SEED = 8


def replicate_clearance(first_seed: int = REPLICATE_FIRST_SEED) -> dict:
    """The one significant Delta_bf difference (R_end 100 mm / theta_f 1.4 deg, seeds 0-7)
    repeated with 8 new seeds (8-15) by the same protocol (skid start at the reference design,
    continuation to the design, CRN central difference), with the frozen-load estimate from the
    new states, and the 16-seed pooled difference: is it a property of the design or a
    2.9-sigma draw among nine checks? ``python benchmarks/studies/bench_steady_gradient.py
    --replicate-clearance`` (needs the full study's results for seeds 0-7).

    ``--first-seed N`` runs seeds N .. N+7 instead (written under
    ``clearance_replication_seeds_N_M``); N = 0 repeats the first batch's seeds with today's
    code, whose start-up path (skid pre-start) differs from the one the first batch ran."""
    import jaxbearing as jb
    from jaxbearing.design import frozen_load_gradient
    from jaxbearing.flange import DesignVariables

    if not (STATE_DIR / f"full_{REPLICATE}_axial_clearance_plus.npz").exists():
        raise SystemExit(f"{STATE_DIR}: the first study's runs are missing; run the full study first")
    first = _results()["designs"][REPLICATE]["central_difference"]["axial_clearance"]
    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    t_start = time.perf_counter()
    s0 = int(first_seed)
    ref_x, x = np.array(DESIGNS["reference"]), np.array(DESIGNS[REPLICATE])
    ref = _cached(
        f"rep{s0}_reference_base",
        lambda: _settled(bearing, op, ref_x, SEEDS, WINDOW_REVS, "auto", None, s0),
    )
    base = _cached(
        f"rep{s0}_{REPLICATE}_base",
        lambda: _settled(bearing, op, x, SEEDS, WINDOW_REVS, "auto", ref["final"], s0),
    )
    rev_ms = 2 * math.pi / abs(float(np.asarray(base["final"][0].cage.speed))) * 1e3
    i, h = 2, FD_STEP * RANGES[2]
    fd = _fd(x, i, h, bearing, op, base["final"], f"rep{s0}_{REPLICATE}", SEEDS, rev_ms, WINDOW_REVS, s0)
    d = DesignVariables.from_array(x)
    frozen = frozen_load_gradient(
        d.apply(bearing), op, d, base["samples"], window=FROZEN_WINDOW, workers=WORKERS
    )
    # seeds 0-7 per seed, from the first study's kept runs (out/bench_steady_gradient/)
    first_d = _fd(x, i, h, bearing, op, None, f"full_{REPLICATE}", SEEDS, rev_ms, WINDOW_REVS)["per_seed"]
    pooled = _paired(np.concatenate([first_d, fd["per_seed"]]), h, 0.0)
    rep = dict(
        design=REPLICATE,
        variable="axial_clearance",
        seeds=list(range(s0, s0 + SEEDS)),
        objective_Pa_m_s=base["objective"],
        central_difference_seeds_0_7=first,
        central_difference=fd,
        central_difference_pooled_16=pooled,
        frozen_load=dict(
            gradient=frozen.gradient.tolist(),
            stderr=frozen.gradient_stderr.tolist(),
            agreement_new_seeds=_agreement(frozen.gradient[i], fd),
            agreement_pooled=_agreement(frozen.gradient[i], pooled),
        ),
        wall_time_s=time.perf_counter() - t_start,
    )
    key = (
        "clearance_replication"
        if s0 == REPLICATE_FIRST_SEED
        else f"clearance_replication_seeds_{s0}_{s0 + SEEDS - 1}"
    )
    _write(rep, key)
    print(json.dumps({k: v for k, v in rep.items() if k != "central_difference_seeds_0_7"}, indent=1))
    return rep


def pool_clearance() -> dict:
    """The Delta_bf differences at R_end 100 mm / theta_f 1.4 deg of every batch run on today's
    code (`--replicate-clearance --first-seed 0, 8, 16`) pooled: per-seed mean, paired standard
    error and Student-t interval over all seeds, and a one-way ANOVA across the batches (are
    they draws of one distribution?). No simulation: reads the JSON. ``--pool-clearance``."""
    from scipy import stats

    out = _results()
    keys = [k for k in out if k.startswith("clearance_replication")]
    batches = {out[k]["seeds"][0]: np.asarray(out[k]["central_difference"]["per_seed"]) for k in keys}
    per_seed = np.concatenate([batches[s0] for s0 in sorted(batches)])
    anova = stats.f_oneway(*[batches[s0] for s0 in sorted(batches)])
    pooled = _paired(per_seed, FD_STEP * RANGES[2], 0.0) | {
        "ci95": _common.interval(per_seed),
        "first_seeds_of_batches": sorted(batches),
        "anova_between_batches": {"F": float(anova.statistic), "p": float(anova.pvalue)},
        "frozen_load_per_batch": {
            str(out[k]["seeds"][0]): out[k]["frozen_load"]["gradient"][2] for k in keys
        },
    }
    pooled["frozen_load_agreement"] = _agreement(
        float(np.mean(list(pooled["frozen_load_per_batch"].values()))), pooled
    )
    _write(pooled, "clearance_pooled_today")
    print(json.dumps({k: v for k, v in pooled.items() if k != "per_seed"}, indent=1))
    return pooled


if __name__ == "__main__":
    if "--replicate-clearance" in sys.argv:
        first = REPLICATE_FIRST_SEED
        value = _common.option_value(sys.argv, "--first-seed")
        if value is not None:
            if not value.isdigit():
                raise SystemExit(f"--first-seed {value!r}: must be an integer >= 0")
            first = int(value)
        replicate_clearance(first)
    elif "--pool-clearance" in sys.argv:
        pool_clearance()
    elif "--today" in sys.argv:
        # the whole check again on today's code (seeds 0-7; the kept runs of --replicate-clearance
        # --first-seed 0 are reused), frozen-load estimator only, under "today_code"
        main(tag="rep0", short_windows=False, into="today_code")
    else:
        main(quick="--quick" in sys.argv)
