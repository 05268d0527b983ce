"""Do the profile variables' gradients agree with common-random-number differences?

    python benchmarks/studies/study_profile_gradients.py --slices 11 --seeds 6 \
        --name profile_gradient_check

At each of four profile designs (`DESIGNS`, inside the box of examples/optimise_profile.toml,
the faces general: a torus end, a concave rib; `--designs` picks some by position) the reference bearing at `--slices` slices and
its operating point (20,000 rpm, 1000 N) settles `--seeds` seeds from the skid start (`design.steady_design_metrics`, a
`--window-revs` window); the frozen-load estimator (`design.frozen_load_gradients`) gives the
gradient of the settled mean flange PV in all eight variables from those settled states. For
each variable of `--variables` (default: the five the three-variable search does not have), both
designs x +- h continue from the same settled states with the same seeds (one engine call for
all of them) and their paired central difference (`design.paired_central_difference`) is the
reference the estimate is compared with: significant (|FD| > 3 SE), the same sign, within 30 %.
`--statistic` differentiates another settled statistic than the mean PV (e.g. "friction", the
time-mean total flange friction power), `--variables` may name any of the eight.
h is `STEP_FRACTION` of the variable's box range, as the theta_f check in
tests/test_steady_gradient.py (`--step-fraction` for another: a variable whose effect the seeds
barely resolve is resolved by a wider step, the difference then a secant).

Verdicts (`verdict`): "agrees" (significant, same sign, within 30 %), "consistent" (the
difference not significant and the estimate within 3 SE of it), "not felt" (the runs of both
steps bitwise equal and the estimate exactly zero: the flange height while the contact stays
below the rib's top edge, as the design zone demands), "disagrees" or "inconsistent".

Writes results/NAME.json after every design (a rerun with the same options continues; a design
of the file no longer in `DESIGNS` is kept): per design and variable the estimate, its standard error, the paired
difference, its standard error and the verdict. tests/test_profile_gradients.py runs `check`
at reduced size: the end offset at one design in `make test`, every variable at the four
designs with `make test-slow`.
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

#: four designs [engineering units, PROFILE_TABLE order: R_end mm, e mm, R_cor mm, 1/R_rib
#: 1/m, h_t mm, theta_f deg, H_rf mm, Delta_bf mm], inside examples/optimise_profile.toml's box
#: with every variable at least one step from its bounds
#: and inside the static design zone (`flange.zone_margins` all positive)
DESIGNS = {
    "torus end, concave rib": (80.0, 0.3, 0.4, 1.0, 0.5, 1.6, 2.0, 0.15),
    "larger end radius, half-curved rib": (90.0, 0.2, 0.45, 2.5, 0.8, 1.5, 2.1, 0.15),
    "small end radius, more curved rib": (70.0, 0.7, 0.5, 3.5, 1.0, 1.3, 2.2, 0.2),
    # towards the held-load design (docs/how-to/profile-design.md, "Below the three-variable
    # optimum"): a large torus end conforming with a concave rib, where the rib curvature acts
    "conforming torus end on a concave rib": (110.0, 0.6, 0.35, 3.5, 0.3, 1.25, 2.1, 0.15),
}

#: the variables the three-variable search does not have
NEW_VARIABLES = (
    "end_offset_mm",
    "corner_radius_mm",
    "rib_curvature_per_m",
    "rib_tangent_height_mm",
    "flange_height_mm",
)

#: each variable's difference step: this fraction of its box range (theta_f's check: 15 %)
STEP_FRACTION = 0.15


def steps(variables, fraction: float = STEP_FRACTION) -> dict:
    """The difference step [SI] of each variable: `fraction` of its default box range."""
    from optimise import ProfileBounds

    bounds = ProfileBounds()
    keys = [v.key for v in bounds.TABLE]
    width = bounds.upper - bounds.lower
    return {k: fraction * float(width[keys.index(k)]) for k in variables}


def check(
    design_mm,
    *,
    variables=NEW_VARIABLES,
    slices=11,
    seeds=6,
    window_revs=2,
    workers=1,
    statistic="mean",
    step_fraction=STEP_FRACTION,
):
    """One design's rows: per variable the frozen-load estimate of d(mean PV)/dx with its
    standard error, the paired CRN central difference with its standard error and the verdict
    (module docstring). `design_mm`: the eight values in engineering units; `statistic`: the
    settled statistic (`design.Statistic`: the mean PV by default, or e.g. "friction");
    `step_fraction`: the half-step as a fraction of each variable's box range (both steps must
    stay inside the box, else a one-line error)."""
    import jaxbearing as jb
    from jaxbearing.design import (
        frozen_load_gradients,
        paired_central_difference,
        steady_design_metrics,
        steady_design_metrics_points,
    )
    from jaxbearing.flange import MARGIN_NAMES, ProfileVariables, zone_margins
    from optimise import ProfileBounds

    keys = [v.key for v in ProfileBounds.TABLE]
    x = ProfileBounds.from_engineering(design_mm)
    b = dataclasses.replace(jb.reference_bearing(), num_slices=slices)
    op = jb.reference_operating_point()
    design = ProfileVariables.from_array(x)
    h = steps(variables, step_fraction)
    bounds = ProfileBounds()
    for k in variables:
        i = keys.index(k)
        if x[i] - h[k] < bounds.lower[i] - 1e-15 or x[i] + h[k] > bounds.upper[i] + 1e-15:
            raise SystemExit(
                f"step_fraction = {step_fraction}: {k} = {design_mm[i]} +- the step leaves the box "
                f"[{bounds.lower[i]:g}, {bounds.upper[i]:g}] (SI); use a smaller fraction"
            )
    base = steady_design_metrics(
        b,
        op,
        design,
        settle=0.005,
        seeds=seeds,
        window_revs=window_revs,
        workers=workers,
        statistic=statistic,
    )
    (g,) = frozen_load_gradients([(b, op, design, base.sample_states)], workers=workers, statistic=statistic)
    shifted = []
    for k in variables:
        for sign in (1.0, -1.0):
            xs = x.copy()
            xs[keys.index(k)] += sign * h[k]
            shifted.append(ProfileVariables.from_array(xs))
    runs = steady_design_metrics_points(
        b,
        [op] * len(shifted),
        shifted,
        initial_states=[base.final_states] * len(shifted),
        settle=0.0035,
        seeds=seeds,
        window_revs=window_revs,
        workers=workers,
        statistic=statistic,
    )
    rows = []
    for j, k in enumerate(variables):
        fd, se, n = paired_central_difference(
            runs[2 * j].objective_per_seed, runs[2 * j + 1].objective_per_seed, h[k]
        )
        i = keys.index(k)
        est, est_se = float(g.gradient[i]), float(g.gradient_stderr[i])
        significant = bool(abs(fd) > 3 * se)
        rows.append(
            {
                "variable": k,
                "step_si": h[k],
                "frozen_load": est,
                "frozen_load_se": est_se,
                "crn_difference": fd,
                "crn_difference_se": se,
                "paired_seeds": n,
                "significant": significant,
                "verdict": verdict(est, fd, se),
            }
        )
    return {
        "design": dict(zip(keys, map(float, design_mm))),
        "zone_margins_m": dict(zip(MARGIN_NAMES, map(float, zone_margins(b, design)))),
        "corner_contact_share": base.corner_contact_share.as_dict(),
        # the settled objective [SI]: mean PV in Pa m/s, or the statistic's (friction power in W)
        ("mean_pv_Pa_m_s" if statistic == "mean" else f"{statistic}_objective_si"): base.objective.as_dict(),
        "frozen_load_gradient": dict(zip(keys, map(float, g.gradient))),
        "rows": rows,
    }


def verdict(estimate: float, fd: float, se: float) -> str:
    """How an estimate compares with a paired difference FD +- SE: "agrees" (|FD| > 3 SE, the
    same sign, within 30 % of FD), "disagrees" (significant otherwise), "consistent" (not
    significant, the estimate within 3 SE of FD: the difference cannot tell them apart), "not
    felt" (both exactly zero: the settled running does not depend on the variable there) or
    "inconsistent" (not significant, the estimate more than 3 SE off)."""
    if fd == 0.0 and se == 0.0 and estimate == 0.0:
        return "not felt"
    if abs(fd) > 3 * se:
        same = np.sign(estimate) == np.sign(fd) and abs(estimate - fd) <= 0.3 * abs(fd)
        return "agrees" if same else "disagrees"
    return "consistent" if abs(estimate - fd) <= 3 * se else "inconsistent"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--slices", type=int, default=11)
    p.add_argument("--seeds", type=int, default=6)
    p.add_argument("--window-revs", type=int, default=2)
    p.add_argument("--variables", default=",".join(NEW_VARIABLES))
    p.add_argument("--designs", default="0,1,2", help="which of DESIGNS, by position (0-3)")
    p.add_argument(
        "--statistic", default="mean", help="the settled statistic differentiated (optimise run --statistic)"
    )
    p.add_argument("--workers", type=int, default=1)
    p.add_argument(
        "--step-fraction",
        type=float,
        default=STEP_FRACTION,
        help=f"each half-step as a fraction of the variable's box range (default {STEP_FRACTION}); "
        "larger resolves a variable of weak effect, as a secant",
    )
    p.add_argument("--name", default="profile_gradient_check")
    args = p.parse_args(argv)
    variables = tuple(args.variables.split(","))
    settings = {k: v for k, v in vars(args).items() if k not in ("name", "designs", "step_fraction")}
    path = _common.RESULTS_DIR / f"{args.name}.json"
    out = json.loads(path.read_text()) if path.exists() else {}
    if out.get("settings") != settings or out.get("step_fraction") != args.step_fraction:
        out = {"settings": settings, "step_fraction": args.step_fraction, "designs": {}}
    t0 = time.perf_counter()
    chosen = [list(DESIGNS)[int(i)] for i in args.designs.split(",")]
    for label, design in DESIGNS.items():
        if label in out["designs"] or label not in chosen:
            continue
        out["designs"][label] = check(
            design,
            variables=variables,
            slices=args.slices,
            seeds=args.seeds,
            window_revs=args.window_revs,
            workers=args.workers,
            statistic=args.statistic,
            step_fraction=args.step_fraction,
        )
        for r in out["designs"][label]["rows"]:
            _common.log(
                f"{label}: {r['variable']}: frozen {r['frozen_load']:.3e} +- {r['frozen_load_se']:.1e}, "
                f"CRN {r['crn_difference']:.3e} +- {r['crn_difference_se']:.1e}: {r['verdict']}"
            )
        out["seconds"] = time.perf_counter() - t0
        out["command"] = " ".join(
            ["python", "benchmarks/studies/study_profile_gradients.py", *(argv or sys.argv[1:])]
        )
        out["machine"] = _common.machine_info()
        _common.write_json(args.name, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
