"""Is the default 3-speed design better than the reference whatever the model's unmeasured
constants are? `jaxbearing.design.robustness` of the design found by the default search
(`optimise_3speed_risk_run.json`; `--design-file` for another) against the reference bearing's own design,
at every corner of the traction asymptote D and the oil fraction (which carries the drag
coefficient), ranges as `jaxbearing.design.sensitivity_inputs` states them, and every speed of
`examples/optimise.toml`'s envelope, settled, on seeds from 5000 (never used by the search or
its verification). Writes benchmarks/results/study_robust_design.json.

    taskset -c 1 python benchmarks/studies/study_robust_design.py [--slices 11] [--seeds 3] [--window-revs 4]

Options: --slices (default 31), --seeds (4), --window-revs (4), --first-seed (5000), --out (the
results file). The size run for the docs is in the results file (`command`). What chose the
size, one settled member timed at 11 and at 31 slices, is in `study_robust_design.json`
(`size_choice`; measured by an earlier version of this script, in git history).
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import jaxbearing as jb
from jaxbearing.design import robustness, write_robustness_json
from jaxbearing.flange import DesignVariables
from jaxbearing.io import reference_config
from jaxbearing.run import SteadySettings

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "benchmarks/results/study_robust_design.json"
DESIGN_FILE = ROOT / "benchmarks/results/optimise_3speed_risk_run.json"
ENVELOPE_FILE = ROOT / "examples/optimise.toml"


def parse(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--slices", type=int, default=31, help="slices per raceway (default 31)")
    p.add_argument("--seeds", type=int, default=4, help="seeds per ensemble (default 4)")
    p.add_argument("--window-revs", type=int, default=4, help="cage revolutions measured (default 4)")
    p.add_argument("--first-seed", type=int, default=5000, help="first seed (default 5000)")
    p.add_argument("--out", type=Path, default=OUT, help="results file (default the study's)")
    p.add_argument(
        "--design-file",
        type=Path,
        default=DESIGN_FILE,
        help="a search's result.json whose design is checked (default the 3-speed default run's)",
    )
    return p.parse_args(argv)


def default_design(path: Path = DESIGN_FILE) -> DesignVariables:
    import json

    d = json.loads(path.read_text())["design"]
    return DesignVariables(
        d["end_radius_mm"] * 1e-3, math.radians(d["layback_angle_deg"]), d["axial_clearance_mm"] * 1e-3
    )


def envelope(cfg):
    speeds = tomllib.loads(ENVELOPE_FILE.read_text())["envelope"]["speeds_rpm"]
    op = cfg.operating_point()
    return [op.__class__(**{**vars(op), "inner_speed": jb.rpm_to_rad_s(float(s))}) for s in speeds]


def commit() -> str:
    try:
        head = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True, check=True
        )
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--", "jaxbearing"], cwd=ROOT, capture_output=True, text=True
        )
        return head.stdout.strip() + ("+uncommitted" if dirty.stdout.strip() else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def main(argv=None) -> int:
    args = parse(sys.argv[1:] if argv is None else argv)
    cfg = reference_config().replace({"bearing.num_slices": args.slices})
    settings = SteadySettings(seeds=args.seeds, window_revs=args.window_revs, progress=True)
    started_at = commit()
    t = time.perf_counter()
    res = robustness(
        cfg,
        default_design(args.design_file),
        ops=envelope(cfg),
        settings=settings,
        first_seed=args.first_seed,
    )
    wall = time.perf_counter() - t
    command = "taskset -c 1 python benchmarks/studies/study_robust_design.py " + " ".join(
        sys.argv[1:] if argv is None else argv
    )
    write_robustness_json(res, args.out, command=command.strip(), commit=started_at, wall_time_s=wall)
    print(table(res))
    print(f"wrote {args.out} ({wall / 60:.1f} min)")
    return 0


def table(res) -> str:
    """The results as a Markdown table (GPa m/s, 95 % intervals), the verdict below."""

    def f(e):
        return f"{e.value * 1e-9:.3f} [{e.ci95_low * 1e-9:.3f}, {e.ci95_high * 1e-9:.3f}]"

    lines = [
        "| constants | speed | reference mean PV | design mean PV | reference peak PV | design peak PV | cage slip (reference) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in res.rows:
        c, (rpm, _) = res.corners[r.corner], res.points[r.point]
        lines.append(
            f"| {c.name} | {rpm:,.0f} rpm | {f(r.reference_mean_pv)} | "
            f"{'**' * r.mean_pv_lower}{f(r.design_mean_pv)}{'**' * r.mean_pv_lower} | {f(r.reference_peak_pv)} | "
            f"{'**' * r.peak_pv_lower}{f(r.design_peak_pv)}{'**' * r.peak_pv_lower} | "
            f"{100 * r.reference_cage_slip.value:.1f} % |"
        )
    lines.append(f"lower everywhere: {res.lower_everywhere}; not lower: {list(res.not_lower)}")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main())
