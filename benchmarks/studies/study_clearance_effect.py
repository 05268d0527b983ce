"""Where does the axial clearance matter? dJ/dDelta_bf over speed, misalignment and load (issue
35, item 1): ``python benchmarks/studies/study_clearance_effect.py``.

J is the design search's objective (the smooth mean flange PV over contact time of settled
running, docs/model.md 17). At every operating point and design:

1. K seeds settle from the skid start at the design (settling verdict, `window` revolutions);
2. from each seed's final state, the design with Delta_bf + h and with Delta_bf - h continue
   with the same seed (common random numbers: both shifted designs start from the same settled
   state), settle (verdict) and measure `window` revolutions;
3. dJ/dDelta_bf = mean over seeds of (J_k(+h) - J_k(-h)) / 2h, its paired standard error and
   Student-t 95 % interval; significant when the interval excludes 0. Also as a share of J per
   10 um, the scale of a design step.

All members of each step are one call of the steady-running engine (`jaxbearing.design.
steady_design_metrics_points`): on an accelerator one vmapped program, on a CPU one process
per core. Operating points, one factor at a time around 20,000 rpm / 1000 N / aligned:
speeds 10,000, 20,000, 30,000 rpm; misalignment 0, 1, 2 mrad (inner ring, tilt held); radial
loads 500, 1000, 4000 N. Designs: R_end / theta_f / Delta_bf = 100 mm / 1.4 deg / 0.15 mm (the
24-seed measurement of `optimise`'s CLEARANCE_EFFECT) and 94.3 mm / 1.84 deg / 0.15 mm (a
design the default search found). Defaults: K = 16, h = 0.01 mm, window 2, 31 slices: 2 x 7 x
16 = 224 members from the skid start, then 448 continuing, minutes on one GPU (10,800 settled
members per hour at 11 slices on an H200), hours on the 2-core CPU.

Options: `--seeds K`, `--step-mm H`, `--slices N`, `--window W`, `--points
speed|others|all|ref|misaligned` (the speed factor, the misalignment and load factors, all seven
points, the reference point alone, or 2 mrad alone and combined with 30,000 rpm and with 500 N),
`--designs 1|2` (the first design, or both), `--design 2` (the second alone), `--results-dir
DIR`. `--quick`: the reference point, one design, 4 seeds, 11 slices (a check of the script,
minutes on the CPU). Results: results/study_clearance_effect[_quick].json.
`--plot [RESULTS.json]` draws a results file (default results/study_clearance_effect.json) as
docs/figures/clearance_effect/clearance_effect.png: dJ/dDelta_bf as a share of J per 10 um at
every point and design, with its 95 % interval (filled where significant).
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from pathlib import Path

sys.path[:0] = [str(Path(__file__).resolve().parent), str(Path(__file__).resolve().parents[1])]
import _common  # noqa: E402

NAME = "study_clearance_effect"
DESIGNS = ((100.0, 1.4, 0.15), (94.3, 1.84, 0.15))  # R_end [mm], theta_f [deg], Delta_bf [mm]
REFERENCE_POINT = (20000.0, 0.0, 1000.0)  # speed [rpm], misalignment [mrad], radial load [N]


def operating_points(which: str) -> list[tuple[float, float, float]]:
    """(speed rpm, misalignment mrad, load N): one factor at a time around the reference."""
    speed, mis, load = REFERENCE_POINT
    speeds = [(v, mis, load) for v in (10000.0, 20000.0, 30000.0)]
    others = [(speed, m, load) for m in (1.0, 2.0)] + [(speed, mis, f) for f in (500.0, 4000.0)]
    # 2 mrad alone (where the one-factor study found the effect) and combined with the highest
    # speed and with the lightest load: does the effect hold at full slices and in combination?
    misaligned = [(speed, 2.0, load), (30000.0, 2.0, load), (speed, 2.0, 500.0)]
    groups = {"ref": [REFERENCE_POINT], "speed": speeds, "others": others, "all": speeds + others}
    groups["misaligned"] = misaligned
    if which not in groups:
        raise SystemExit(f"--points {which!r}: must be one of {', '.join(groups)}")
    return groups[which]


def _op(point):
    import jaxbearing as jb

    speed, mis, load = point
    return dataclasses.replace(
        jb.reference_operating_point(),
        inner_speed=jb.rpm_to_rad_s(speed),
        misalignment=mis * 1e-3,
        radial_load=load,
    )


def clearance_differences(per_plus, per_minus, h: float, objective: float) -> dict:
    """The paired central difference over seeds (module docstring, step 3)."""
    from scipy import stats

    from jaxbearing.design import paired_central_difference

    mean, se, n = paired_central_difference(per_plus, per_minus, h)
    half = float(stats.t.ppf(0.975, n - 1)) * se if n > 1 else math.nan
    return {
        "dJ_dDelta_bf_Pa_m_s_per_m": mean,
        "stderr": se,
        "ci95": [mean - half, mean + half],
        "seeds": n,
        "significant": bool(n > 1 and abs(mean) > half),
        "share_of_J_per_10um": mean * 10e-6 / objective if objective else math.nan,
    }


def main(
    quick: bool = False,
    seeds: int = 16,
    step_mm: float = 0.01,
    slices: int = 31,
    window: int = 2,
    points: str = "all",
    designs: int = 2,
    results_dir: str | None = None,
    design: int | None = None,
) -> dict:
    import numpy as np

    import jaxbearing as jb
    from jaxbearing.flange import DesignVariables

    if quick:
        seeds, slices, points, designs = 4, 11, "ref", 1
    operating_points(points)  # a bad --points is refused before anything runs
    started = time.perf_counter()
    bearing = dataclasses.replace(jb.reference_bearing(), num_slices=slices)
    chosen = [
        DesignVariables.from_array(np.array([r * 1e-3, math.radians(t), c * 1e-3]))
        for r, t, c in (DESIGNS[:designs] if design is None else [DESIGNS[design - 1]])
    ]
    h = step_mm * 1e-3
    kw = dict(seeds=seeds, window_revs=window, settle="auto", workers=_common_workers())
    data = {
        "seeds": seeds,
        "step_mm": step_mm,
        "num_slices": slices,
        "window_revs": window,
        "points": points,
        "rows": [],
        "base_s": 0.0,
        "shifted_s": 0.0,
        "backend": __import__("jax").default_backend(),
    }
    # `all` runs the speed factor, then the misalignment and load factors, writing the results
    # after each group: a long run never loses a finished group.
    for group in ("speed", "others") if points == "all" else (points,):
        rows, base_s, shifted_s = _group(bearing, chosen, operating_points(group), h, kw)
        data["rows"] += rows
        data["base_s"] += base_s
        data["shifted_s"] += shifted_s
        data["wall_s"] = time.perf_counter() - started
        data["groups_done"] = data.get("groups_done", []) + [group]
        _common.write_json(NAME + ("_quick" if quick else ""), data, results_dir)
    return data


def _group(bearing, chosen, pts, h, kw) -> tuple[list[dict], float, float]:
    """One group of operating points at every design: steps 1-3 of the module docstring, each
    step's members one call of the engine. Returns the rows and the two steps' wall times."""
    import numpy as np

    from jaxbearing.design import steady_design_metrics_points
    from jaxbearing.flange import DesignVariables

    seeds = kw["seeds"]
    ops = [_op(p) for p in pts]
    cases = [(d, op) for d in chosen for op in ops]
    _common.log(f"{NAME}: {len(cases)} cases x {seeds} seeds from the skid start")
    t0 = time.perf_counter()
    base = steady_design_metrics_points(bearing, [op for _, op in cases], [d for d, _ in cases], **kw)
    base_s = time.perf_counter() - t0

    def shifted(d, dh):
        x = np.asarray(d.as_array(), float)
        return DesignVariables.from_array(np.array([x[0], x[1], x[2] + dh]))

    _common.log(f"{NAME}: {2 * len(cases)} cases x {seeds} seeds continuing at Delta_bf +- h")
    t0 = time.perf_counter()
    pm = steady_design_metrics_points(
        bearing,
        [op for _, op in cases] * 2,
        [shifted(d, h) for d, _ in cases] + [shifted(d, -h) for d, _ in cases],
        initial_states=[m.final_states for m in base] * 2,
        **kw,
    )
    shifted_s = time.perf_counter() - t0
    rows = []
    for i, ((d, _), point) in enumerate(zip(cases, pts * len(chosen))):
        plus, minus = pm[i], pm[len(cases) + i]
        j = base[i].objective["value"]
        row = {
            "design": {
                "end_radius_mm": float(d.end_radius) * 1e3,
                "layback_angle_deg": math.degrees(float(d.layback_angle)),
                "axial_clearance_mm": float(d.axial_clearance) * 1e3,
            },
            "speed_rpm": point[0],
            "misalignment_mrad": point[1],
            "radial_load_N": point[2],
            "objective_Pa_m_s": base[i].objective,
            "settled": bool(base[i].settled and plus.settled and minus.settled),
            **clearance_differences(plus.objective_per_seed, minus.objective_per_seed, h, j),
        }
        rows.append(row)
        _common.log(
            f"{NAME}: {point}: dJ/dDelta_bf {row['dJ_dDelta_bf_Pa_m_s_per_m']:.3g} +- {row['stderr']:.2g} "
            f"({100 * row['share_of_J_per_10um']:.2f} % of J per 10 um), significant {row['significant']}"
        )
    return rows, base_s, shifted_s


FIGURE = (
    Path(__file__).resolve().parents[2] / "docs" / "figures" / "clearance_effect" / "clearance_effect.png"
)


def plot(results: str | Path | None = None, path: Path = FIGURE) -> Path:
    """The study's figure (module docstring, `--plot`): one column per operating point, one
    marker per design, the 95 % interval as a bar; hollow where not significant."""
    import json

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = json.loads(Path(results or _common.RESULTS_DIR / f"{NAME}.json").read_text())
    rows = data["rows"]
    labels = []
    for r in rows:
        label = (
            f"{r['speed_rpm'] / 1e3:.0f} krpm\n{r['misalignment_mrad']:g} mrad\n{r['radial_load_N']:.0f} N"
        )
        if label not in labels:
            labels.append(label)
    designs = []
    for r in rows:
        d = (r["design"]["end_radius_mm"], r["design"]["layback_angle_deg"])
        if d not in designs:
            designs.append(d)
    fig, ax = plt.subplots(figsize=(8.0, 4.2))
    for k, d in enumerate(designs):
        offset = (k - (len(designs) - 1) / 2) * 0.18
        color = f"C{k}"
        for r in rows:
            if (r["design"]["end_radius_mm"], r["design"]["layback_angle_deg"]) != d:
                continue
            j = r["objective_Pa_m_s"]["value"]
            x = (
                labels.index(
                    f"{r['speed_rpm'] / 1e3:.0f} krpm\n{r['misalignment_mrad']:g} mrad\n{r['radial_load_N']:.0f} N"
                )
                + offset
            )
            y = 100 * r["share_of_J_per_10um"]
            lo, hi = (100 * v * 10e-6 / j for v in r["ci95"])
            ax.plot([x, x], [lo, hi], color=color, lw=1.5)
            ax.plot(x, y, "o", color=color, mfc=color if r["significant"] else "white", ms=6)
        ax.plot([], [], "o", color=color, label=f"R_end {d[0]:g} mm, theta_f {d[1]:g} deg")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_xticks(range(len(labels)), labels, fontsize=8)
    ax.set_ylabel("dJ/dDelta_bf x 10 um / J  [%]")
    ax.set_title(
        f"Axial clearance effect on the mean flange PV ({data['seeds']} seeds, {data['num_slices']} slices, "
        f"95 % intervals; filled: significant)",
        fontsize=9,
    )
    ax.legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _common_workers() -> int:
    """One process per CPU on a CPU (the engine's default there); ignored on an accelerator."""
    from jaxbearing.run import available_cpus

    return available_cpus()


if __name__ == "__main__":
    argv = sys.argv
    if "--plot" in argv:
        i = argv.index("--plot")
        given = argv[i + 1] if i + 1 < len(argv) and not argv[i + 1].startswith("--") else None
        print(plot(given))
        raise SystemExit(0)

    def opt(name, kind, default):
        v = _common.option_value(argv, name)
        return default if v is None else kind(v)

    main(
        quick="--quick" in argv,
        seeds=opt("--seeds", int, 16),
        step_mm=opt("--step-mm", float, 0.01),
        slices=opt("--slices", int, 31),
        window=opt("--window", int, 2),
        points=opt("--points", str, "all"),
        designs=opt("--designs", int, 2),
        design=opt("--design", int, None),
        results_dir=_common.option_value(argv, "--results-dir"),
    )
