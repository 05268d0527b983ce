"""Does the corner-contact risk estimate from a few members cover the rate measured from many?
``python benchmarks/studies/study_corner_risk.py`` (full size: 31 slices, 32 members of 32
window revolutions; hours on 2 CPU cores, minutes on an accelerator).

At a design near the corner, where corner contact is frequent enough to count by brute force
(default R_end 106.9 mm, theta_f 1.616 deg, Delta_bf 0.15 mm at 20,000 rpm: a design that met the
search's expected-maximum corner margin and touched the corner on further seeds, docs/model.md
17), settled members (seeds `--first-seed` ...) each give a window of whole cage revolutions; per
revolution the largest contact radius in contact over every roller and flange and the peak
flange PV (`jaxbearing.run.revolution_maxima`). Then:

* the brute-force rate: `jaxbearing.run.corner_risk` of every member (the counts);
* the few: the members split into disjoint groups of `--few`, each group's `corner_risk` with
  its bounds (one-sided 95 % each: a two-sided 90 % interval), and whether it covers the
  brute-force rate;
* the tail model at the limit over every member (`method="tail"`), beside the counts;
* the tail model at pseudo-limits: radii r below rho_lim where the pooled rate is observed
  (`--levels`, pooled exceedance rates), each group's estimate of P(M > r) against the pooled
  rate, with the method each group used (the tail fit extrapolates where a group saw none).

Members run in chunks of `--chunk` (one engine call each, `workers` = CPUs) and every finished
chunk is written, so an interrupted run keeps its members and a rerun with the same options
continues (`--analyse-only`: only the analysis of the stored members).

`--synthetic`: instead, the coverage of the bounds on synthetic maxima with known tails (beta,
Gumbel, GPD, normal; 100 replicates of 4 x 50 and 8 x 100 revolutions at P = 0.002 and 1e-4;
about 5 minutes), results/corner_risk_synthetic_coverage.json.

Options: `--design R_MM,THETA_DEG,CLEARANCE_MM`, `--speed-rpm V`, `--slices S` (default 31),
`--members N` (32), `--window-revs W` (32), `--first-seed S` (0), `--few K,..` (2,4: group sizes), `--chunk C` (2),
`--levels a,b,..` (0.2,0.1,0.05), `--name NAME`, `--results-dir DIR`, `--analyse-only`.
Results: results/corner_risk_validation.json (or results/NAME.json).
"""

from __future__ import annotations

import dataclasses
import json
import math
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]
import _common  # noqa: E402

NAME = "corner_risk_validation"
DESIGN = (106.9, 1.616, 0.15)  # mm, deg, mm


def _settings(args) -> dict:
    return {
        "design_mm_deg_mm": list(args["design"]),
        "speed_rpm": args["speed_rpm"],
        "slices": args["slices"],
        "window_revs": args["window_revs"],
        "first_seed": args["first_seed"],
    }


def _simulate_chunk(settings: dict, seeds: list[int]) -> list[dict]:
    """Settled members for `seeds` (one engine call): per member its per-revolution maxima."""
    import numpy as np

    import jaxbearing as jb
    from jaxbearing.flange import with_design
    from jaxbearing.run import (
        Perturbation,
        available_cpus,
        revolution_maxima,
        simulate_steady,
        window_statistics,
    )

    r, t, c = settings["design_mm_deg_mm"]
    bearing = with_design(
        dataclasses.replace(jb.reference_bearing(), num_slices=int(settings["slices"])),
        r * 1e-3,
        math.radians(t),
        c * 1e-3,
    )
    op = dataclasses.replace(
        jb.reference_operating_point(), inner_speed=jb.rpm_to_rad_s(settings["speed_rpm"])
    )
    result = simulate_steady(
        bearing,
        op,
        seeds=len(seeds),
        window_revs=int(settings["window_revs"]),
        perturbation=Perturbation(seed=int(seeds[0])),
        workers=available_cpus(),
    )
    out = []
    for run in result.runs:
        per_rev = window_statistics(run.window, run.edges, bearing, op) if run.measured else None
        m = revolution_maxima([per_rev]) if per_rev is not None else None
        out.append(
            {
                "seed": int(run.seed),
                "settled": bool(run.settled),
                "status": run.status,
                "contact_radius_max_m": np.asarray(m.contact_radius_m[0]).tolist() if m else [],
                "peak_pv_Pa_m_s": np.asarray(m.peak_pv_Pa_m_s[0]).tolist() if m else [],
            }
        )
    return out


def analyse(data: dict, few, levels) -> dict:
    """The brute-force rate, the few members' estimates and the pseudo-limit checks of the
    stored members (module docstring)."""
    import numpy as np

    from jaxbearing._errors import UserInputError
    from jaxbearing.run import corner_risk

    members = [m for m in data["members"] if m["status"] == "ok" and m["contact_radius_max_m"]]
    rho_lim = data["limited_circle_radius_m"]
    maxima = [np.asarray(m["contact_radius_max_m"]) for m in members]
    pv = [np.asarray(m["peak_pv_Pa_m_s"]) for m in members]
    pooled = np.concatenate(maxima)
    many = corner_risk(maxima, rho_lim, peak_pv=pv)
    rate = many.probability
    few_blocks = []
    for size in few:
        groups = [list(range(i, i + size)) for i in range(0, len(members) - size + 1, size)]
        rows = []
        for g in groups:
            est = corner_risk([maxima[i] for i in g], rho_lim, peak_pv=[pv[i] for i in g])
            rows.append(
                {
                    "seeds": [members[i]["seed"] for i in g],
                    "estimate": est.as_dict(),
                    "covers_brute_force_rate": bool(est.lower <= rate <= est.upper),
                }
            )
        few_blocks.append(
            {
                "members_per_group": size,
                "groups": rows,
                "covering": sum(r["covers_brute_force_rate"] for r in rows),
            }
        )
    groups = [list(range(i, i + few[0])) for i in range(0, len(members) - few[0] + 1, few[0])]
    pseudo = []
    for level in levels:
        r = float(np.quantile(pooled, 1 - level))
        true = float(np.mean(pooled > r))
        rows = []
        for g in groups:
            est = corner_risk([maxima[i] for i in g], r)
            rows.append(
                {
                    "seeds": [members[i]["seed"] for i in g],
                    "method": est.method,
                    "probability": est.probability,
                    "lower": est.lower,
                    "upper": est.upper,
                    "covers": bool(est.lower <= true <= est.upper),
                }
            )
        pseudo.append(
            {
                "pooled_rate_level": level,
                "radius_m": r,
                "pooled_rate": true,
                "pooled_estimate": corner_risk(maxima, r).as_dict(),
                "groups": rows,
                "covered": sum(x["covers"] for x in rows),
            }
        )
    subsets = _subset_coverage(maxima, rho_lim)
    try:  # the tail model at the limit over every member, beside the counts
        tail_model = corner_risk(maxima, rho_lim, method="tail").as_dict()
    except UserInputError as e:
        tail_model = {"error": str(e)}
    return {
        "members_used": len(members),
        "tail_model_at_the_limit": tail_model,
        "revolutions": int(pooled.size),
        "brute_force": many.as_dict(),
        "few": few_blocks,
        "pseudo_limits": pseudo,
        "subsets": subsets,
        "coverage_note": (
            "each estimate's bounds are one-sided at 95 % (a two-sided 90 % interval); a group 'covers' "
            "when its [lower, upper] contains the brute-force (pooled) rate"
        ),
    }


def _subset_coverage(maxima, rho_lim, draws: int = 300, sizes=((4, 4), (4, 2))) -> list[dict]:
    """How often the upper bound of `corner_risk` from a random subset of members x revolutions of
    the sizes the verification (4 x 4) and the search (4 x 2) use lies below the pooled rate, at
    rho_lim and at the 90 % and 95 % quantiles of the pooled maxima as limits (a fixed seed). An
    honest one-sided 95 % bound misses in at most 5 % of subsets on average."""
    import numpy as np

    from jaxbearing.run import corner_risk

    revs = min(len(m) for m in maxima)
    rows = np.array([np.nan_to_num(np.asarray(m[:revs], float)) for m in maxima])
    rng = np.random.default_rng(3)
    out = []
    for limit in (rho_lim, *np.quantile(rows, [0.9, 0.95])):
        rate = float(np.mean(rows > limit))
        for members, window in sizes:
            misses, methods = 0, {}
            for _ in range(draws):
                pick = rng.choice(rows.shape[0], members, replace=False)
                first = rng.integers(0, rows.shape[1] - window + 1)
                est = corner_risk(rows[pick, first : first + window], limit)
                misses += est.upper < rate
                methods[est.method] = methods.get(est.method, 0) + 1
            out.append(
                {
                    "limit_m": float(limit),
                    "pooled_rate": rate,
                    "members": members,
                    "revolutions_per_member": window,
                    "draws": draws,
                    "upper_below_rate": int(misses),
                    "methods": methods,
                }
            )
    return out


#: synthetic maxima with known tails: name -> (scipy distribution, shape arguments)
SYNTHETIC = {
    "beta(2,5)": ("beta", (2.0, 5.0)),
    "gumbel": ("gumbel_r", ()),
    "gpd(xi=-0.3)": ("genpareto", (-0.3,)),
    "normal": ("norm", ()),
}


def synthetic_coverage(replicates: int = 100, sizes=((4, 50), (8, 100)), targets=(0.002, 1e-4)) -> dict:
    """How often the bounds of `corner_risk` miss a known exceedance probability on
    maxima drawn from distributions with known tails (members x revolutions `sizes`, a fixed
    seed per case), at every exceedance probability of `targets`: the misses of each one-sided
    bound and the methods used."""
    import numpy as np
    from scipy import stats

    from jaxbearing.run import corner_risk

    out = []
    cases = [(name, target, size) for target in targets for name in SYNTHETIC for size in sizes]
    for name, target, (members, revs) in cases:
        dist, args = SYNTHETIC[name]
        law = getattr(stats, dist)(*args)
        limit = float(law.isf(target))
        rng = np.random.default_rng(12345)
        miss_up = miss_low = 0
        methods: dict = {}
        uppers = []
        for _ in range(replicates):
            x = law.rvs(size=(members, revs), random_state=rng)
            shift = max(0.0, -float(x.min()) + 1.0)  # radii are >= 0
            e = corner_risk(x + shift, limit + shift)
            methods[e.method] = methods.get(e.method, 0) + 1
            miss_up += e.upper < target
            miss_low += e.lower > target
            uppers.append(e.upper)
        row = {
            "distribution": name,
            "members": members,
            "revolutions_per_member": revs,
            "true_probability": target,
            "replicates": replicates,
            "upper_misses": int(miss_up),
            "lower_misses": int(miss_low),
            "methods": methods,
            "median_upper": float(np.median(uppers)),
            "rule_of_three": 1 - 0.05 ** (1 / (members * revs)),
        }
        _common.log(f"{name} {members}x{revs} p={target:g}: upper misses {miss_up}/{replicates}, {methods}")
        out.append(row)
    return {
        "cases": out,
        "allowed_misses_0999": int(stats.binom.ppf(0.999, replicates, 0.05)),
        "note": "an honest one-sided 95 % bound misses in at most 5 % of replicates",
    }


def main(
    design=DESIGN,
    speed_rpm: float = 20000.0,
    slices: int = 31,
    members: int = 32,
    window_revs: int = 32,
    first_seed: int = 0,
    few=(2, 4),
    chunk: int = 2,
    levels=(0.2, 0.1, 0.05),
    name: str = NAME,
    results_dir=None,
    analyse_only: bool = False,
) -> dict:
    t0 = time.perf_counter()
    settings = _settings(locals())
    out_dir = Path(results_dir) if results_dir is not None else _common.RESULTS_DIR
    path = out_dir / f"{name}.json"
    data = None
    if path.exists():
        stored = json.loads(path.read_text())
        if stored.get("settings") == settings:
            data = stored
    if data is None:
        import jaxbearing as jb
        from jaxbearing.flange import with_design
        from jaxbearing.geometry import limited_circle_radius

        r, t, c = design
        b = with_design(jb.reference_bearing(), r * 1e-3, math.radians(t), c * 1e-3)
        data = {
            "settings": settings,
            "limited_circle_radius_m": float(limited_circle_radius(b.roller)),
            "members": [],
            "simulation_wall_s": 0.0,
        }
    if not analyse_only:
        done = {m["seed"] for m in data["members"]}
        todo = [s for s in range(first_seed, first_seed + members) if s not in done]
        for i in range(0, len(todo), chunk):
            seeds = todo[i : i + chunk]
            if seeds != list(range(seeds[0], seeds[0] + len(seeds))):
                seeds = seeds[:1]
            c0 = time.perf_counter()
            data["members"] += _simulate_chunk(settings, seeds)
            data["simulation_wall_s"] += time.perf_counter() - c0
            _common.log(
                f"{name}: members {len(data['members'])}/{members} ({data['simulation_wall_s']:.0f} s)"
            )
            _common.write_json(name, data, results_dir)
    data["analysis"] = analyse(data, few, levels)
    data["command"] = "python benchmarks/studies/study_corner_risk.py " + " ".join(
        a for a in sys.argv[1:] if a != "--analyse-only"
    )
    data["analysis_wall_s"] = time.perf_counter() - t0
    a = data["analysis"]
    bf = a["brute_force"]
    _common.log(
        f"{name}: brute force {bf['exceedances']} of {bf['revolutions']} revolutions, p = {bf['probability']:.4f} "
        f"[{bf['lower']:.4f}, {bf['upper']:.4f}]; "
        + ", ".join(
            f"{b['covering']} of {len(b['groups'])} groups of {b['members_per_group']}" for b in a["few"]
        )
        + " cover it"
    )
    _common.write_json(name, data, results_dir)
    return data


def _parse(argv) -> dict:
    opt = _common.option_value
    kw: dict = {}
    if (v := opt(argv, "--design")) is not None:
        kw["design"] = tuple(float(x) for x in v.split(","))
    for key, conv in (
        ("speed-rpm", float),
        ("slices", int),
        ("members", int),
        ("window-revs", int),
        ("first-seed", int),
        ("chunk", int),
        ("name", str),
        ("results-dir", str),
    ):
        if (v := opt(argv, f"--{key}")) is not None:
            kw[key.replace("-", "_")] = conv(v)
    if (v := opt(argv, "--few")) is not None:
        kw["few"] = tuple(int(x) for x in v.split(","))
    if (v := opt(argv, "--levels")) is not None:
        kw["levels"] = tuple(float(x) for x in v.split(","))
    kw["analyse_only"] = "--analyse-only" in argv
    return kw


if __name__ == "__main__":
    if "--synthetic" in sys.argv:
        t0 = time.perf_counter()
        data = synthetic_coverage()
        data["command"] = "python benchmarks/studies/study_corner_risk.py --synthetic"
        data["wall_s"] = time.perf_counter() - t0
        _common.write_json("corner_risk_synthetic_coverage", data)
    else:
        main(**_parse(sys.argv[1:]))
