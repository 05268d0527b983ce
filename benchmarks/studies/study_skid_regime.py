"""The skid regime of the reference bearing (11 slices per raceway, seed 0 for the statics): the
static skid equilibrium's cage slip over speed x radial load, its balance of terms by zone
(`dynamics.skid_zones`), the onset load against SKF's minimum-load rule, the slip's sensitivity
to the traction curve and the oil fraction, the cage torque with the rollers in balance against
the cage speed (`dynamics.balanced_cage_torque`), and settled runs (2 seeds, 95 % intervals).

    taskset -c 1 python benchmarks/studies/study_skid_regime.py            # statics, 3.6 min on one core
    taskset -c 1 python benchmarks/studies/study_skid_regime.py --curves   # M(omega_c), about 1 min
    taskset -c 1 python benchmarks/studies/study_skid_regime.py --settled  # settled runs, 9.5 min
    python benchmarks/studies/study_skid_regime.py --plot   # docs/figures/skid_regime/skid_regime.png
"""

import dataclasses as dc
import json
import sys
from pathlib import Path

import jax
import numpy as np

import jaxbearing as jb
from jaxbearing.dynamics import Params, balanced_cage_torque, skid_balance, skid_zones
from jaxbearing.run import Perturbation, SteadySettings, skid_start, summarise_steady

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "benchmarks/results/skid_regime.json"
SPEEDS, LOADS = [5000, 10000, 15000, 17500, 20000, 25000, 30000], [250, 500, 1000, 2000, 4000]
SETTLED = [
    (15000, 1000, "skid"),
    (20000, 1000, "skid"),
    (20000, 1000, "quasi-static"),
    (30000, 1000, "skid"),
    (30000, 4000, "skid"),
]
RULE = {"k_r_kN": 0.1, "n_r_rpm": 7000.0, "d_m_mm": 85.0, "onset_slip": 0.05}  # SKF, 10 series
VARIANTS = {
    "D 0.03": {"traction_d": 0.03, "traction_a": -0.03},
    "D 0.05": {"traction_d": 0.05, "traction_a": -0.05},
}
VARIANTS |= {"peak 0.053 (B x0.75)": {"traction_b": 0.1896}, "peak 0.067 (B x1.25)": {"traction_b": 0.316}}
VARIANTS |= {"f_oil x0.5": {"oil_fraction": 0.025}, "f_oil x2": {"oil_fraction": 0.1}}
FRACTIONS = [*np.arange(0.55, 0.96, 0.05), 0.97, 0.98, 0.985, 0.99, 0.993, 0.996, 0.998, 0.999, 1.0]


def case(rpm, load, lub=None):
    b = dc.replace(jb.reference_bearing(), num_slices=11)
    b = b if lub is None else dc.replace(b, lubricant=dc.replace(b.lubricant, **lub))
    return b, dc.replace(
        jb.reference_operating_point(), inner_speed=jb.rpm_to_rad_s(rpm), radial_load=float(load)
    )


def static(rpm, load, lub=None):  # (slip, the balance by zone) of the static skid equilibrium
    b, op = case(rpm, load, lub)
    eq = skid_start(b, op, Perturbation(seed=0)).equilibrium
    z = skid_zones(skid_balance(eq.state, Params(bearing=b, operating=op)))
    terms = {f.name: float(getattr(z, f.name)) for f in dc.fields(z)} | {
        "cage_rpm": jb.rad_s_to_rpm(eq.cage_speed)
    }
    return 1 - float(eq.cage_speed / jb.kinematic_cage_speed(b, op)), terms


def curve(rpm):  # M(omega_c) at the equilibrium's positions, 1000 N
    b, op = case(rpm, 1000)
    eq, kin = skid_start(b, op, Perturbation(seed=0)).equilibrium, jb.kinematic_cage_speed(b, op)
    out = [
        jax.jit(balanced_cage_torque)(eq.state, Params(bearing=b, operating=op), f * kin) for f in FRACTIONS
    ]
    zones = [skid_zones(t) for _, t in out]
    return {"speed_rpm": rpm, "cage_speed_fraction": FRACTIONS, "torque_Nm": [float(m) for m, _ in out]} | {
        "inner_sliding_loaded": [float(z.inner_sliding_loaded) for z in zones]
    }


def onset(slips):  # the load below which the slip exceeds RULE onset_slip (log-linear); None: off the map
    s, x, cut = np.asarray(slips), np.log(LOADS), RULE["onset_slip"]
    if s[-1] > cut or s[0] < cut:
        return None
    i = int(np.argmax(s < cut))
    return float(np.exp(np.interp(cut, [s[i], s[i - 1]], [x[i], x[i - 1]])))


def main(argv):
    res = json.loads(OUT.read_text()) if OUT.exists() else {}
    if "--plot" in argv:
        return plot(res)
    if "--curves" in argv:
        res["cage_torque_curves_1000N"] = [curve(n) for n in (17500, 20000, 25000, 30000)]
    elif "--settled" in argv:  # 2 seeds, 2-revolution windows after the settling verdict
        res["settled"] = []
        for n, f, start in SETTLED:
            s = summarise_steady(
                jb.simulate(*case(n, f), settings=SteadySettings(seeds=2, window_revs=2, start=start))
            )
            keep = ("cage_slip", "cage_speed_rpm", "settled", "wall_time_s")
            res["settled"].append({"speed_rpm": n, "load_N": f, "start": start} | {k: s[k] for k in keep})
    else:
        grid = [[static(n, f) for f in LOADS] for n in SPEEDS]
        res["map"] = {"speeds_rpm": SPEEDS, "loads_N": LOADS, "slip": [[g[0] for g in row] for row in grid]}
        res["balance_1000N"] = [{"speed_rpm": n, **row[LOADS.index(1000)][1]} for n, row in zip(SPEEDS, grid)]
        rule = [
            RULE["k_r_kN"] * 1e3 * (6 + 4 * n / RULE["n_r_rpm"]) * (RULE["d_m_mm"] / 100) ** 2 for n in SPEEDS
        ]
        res["minimum_load"] = {
            "rule": RULE,
            "rule_N": rule,
            "onset_N": [onset(r) for r in res["map"]["slip"]],
        }
        res["sensitivity_1000N"] = [
            {"variant": k, "speed_rpm": n, "slip": static(n, 1000, v)[0]}
            for k, v in VARIANTS.items()
            for n in (20000, 30000)
        ]
    OUT.write_text(json.dumps(res, indent=1, default=float))


def plot(res):
    import matplotlib.pyplot as plt

    m, bal, fig, ax = res["map"], res["balance_1000N"], *plt.subplots(1, 4, figsize=(20, 4.5))
    for f, col in zip(m["loads_N"], np.array(m["slip"]).T):
        ax[0].plot(m["speeds_rpm"], 100 * col, "o-", label=f"{f} N, static")
    for s in res.get("settled", []):
        c, lo, hi = (100 * s["cage_slip"][k] for k in ("value", "ci95_low", "ci95_high"))
        ax[0].errorbar(
            s["speed_rpm"],
            c,
            yerr=[[c - lo], [hi - c]],
            fmt="kx" if s["start"] == "skid" else "r+",
            capsize=3,
        )
    for k in (
        "inner_traction_loaded",
        "outer_traction_loaded",
        "outer_traction_unloaded",
        "roller_drag",
        "cage_land",
        "cage_drag",
    ):
        ax[1].plot([b["speed_rpm"] for b in bal], [b[k] for b in bal], "o-", label=k)
    ax[2].plot(
        m["speeds_rpm"], res["minimum_load"]["rule_N"], "k--", label="SKF rule, k_r 0.1 kN, n_r 7,000 rpm"
    )
    ax[2].plot(
        m["speeds_rpm"], [v or np.nan for v in res["minimum_load"]["onset_N"]], "o-", label="model: 5 % slip"
    )
    for c in res.get("cage_torque_curves_1000N", []):
        ax[3].plot(c["cage_speed_fraction"], c["torque_Nm"], ".-", label=f"{c['speed_rpm']} rpm")
    ax[3].axhline(0, color="k", lw=0.5)
    labels = [
        ("shaft speed [rpm]", "cage slip [%] (x, +: settled, 95 %)"),
        ("shaft speed [rpm]", "torque about the axis, 1000 N [N m]"),
    ]
    labels += [
        ("shaft speed [rpm]", "radial load [N]"),
        ("cage speed / kinematic", "cage torque, rollers balanced [N m]"),
    ]
    for a, (x, y) in zip(ax, labels):
        a.set(xlabel=x, ylabel=y)
        a.legend(fontsize=7)
    ax[2].set_yscale("log")
    fig.tight_layout()
    fig.savefig(ROOT / "docs/figures/skid_regime/skid_regime.png", dpi=100)


if __name__ == "__main__":
    main(sys.argv[1:])
