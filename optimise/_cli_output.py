"""`optimise run`: the lines it prints and the files it writes, shared by both objectives."""

from __future__ import annotations

import math
import pathlib
import sys

from jaxbearing.cli import EXIT_INFEASIBLE  # noqa: F401  (3: no feasible design; `jaxbearing.cli.EXIT_CODES`)


def _design_text(x) -> str:
    return f"R_end {x[0] * 1e3:7.2f} mm  theta_f {math.degrees(x[1]):6.3f} deg  Delta_bf {x[2] * 1e3:6.4f} mm"


def _margin_text(m) -> str:
    from jaxbearing.flange import MARGIN_NAMES

    return "  ".join(
        f"{n} {v * 1e3:+.4f} mm {'OK' if v > 0 else 'VIOLATED'}" for n, v in zip(MARGIN_NAMES, m)
    )


def _progress(quiet: bool, start_line):
    """The per-iteration progress callback of both searches: the best feasible objective, then
    one line per start (`start_line(j, info, margins, index of the smallest margin)`)."""
    import numpy as np

    def progress(it, info):
        if quiet:
            return
        best = info.best
        print(
            f"iter {it:3d}  best feasible {best:.4f} GPa m/s"
            if np.isfinite(best)
            else f"iter {it:3d}  best feasible   none yet"
        )
        for j in range(info.x.shape[0]):
            m = info.margins[j]
            print(f"   start {j}: " + start_line(j, info, m, int(np.argmin(m))))
        sys.stdout.flush()

    return progress


def _write_results(out, result: dict, plot) -> tuple[pathlib.Path, int]:
    """result.json and the plot into `out`, or into a fallback directory when that fails:
    (the directory used, 0 or `EXIT_RESULTS_ELSEWHERE` after one line naming it)."""
    from jaxbearing.cli import report_fallback
    from jaxbearing.io import write_json, write_or_fallback

    def write(d):
        write_json(d / "result.json", result)
        plot(d)

    used, reason = write_or_fallback(out, write)
    return used, report_fallback("optimise run", out, used, reason)


def _engineering(x):
    if x is None:
        return None
    return {
        "end_radius_mm": float(x[0]) * 1e3,
        "layback_angle_deg": math.degrees(float(x[1])),
        "axial_clearance_mm": float(x[2]) * 1e3,
    }
