"""`optimise run`: the lines it prints and the files it writes, shared by both objectives."""

from __future__ import annotations

import math
import pathlib
import sys

from jaxbearing.cli import EXIT_INFEASIBLE  # noqa: F401  (3: no feasible design; `jaxbearing.cli.EXIT_CODES`)


def _design_text(x) -> str:
    """A design array in engineering units: (R_end, theta_f, Delta_bf), or a profile's eight."""
    if len(x) == 3:
        return f"R_end {x[0] * 1e3:7.2f} mm  theta_f {math.degrees(x[1]):6.3f} deg  Delta_bf {x[2] * 1e3:6.4f} mm"
    r_end, e, r_cor, kappa, h_t, theta, h_rf, clearance = (float(v) for v in x)
    return (
        f"R_end {r_end * 1e3:7.2f} mm  e {e * 1e3:5.3f} mm  R_cor {r_cor * 1e3:5.3f} mm  "
        f"1/R_rib {kappa:5.3f} 1/m  h_t {h_t * 1e3:5.3f} mm  theta_f {math.degrees(theta):6.3f} deg  "
        f"H_rf {h_rf * 1e3:5.3f} mm  Delta_bf {clearance * 1e3:6.4f} mm"
    )


def _margin_text(m) -> str:
    from jaxbearing.flange import MARGIN_NAMES

    return "  ".join(
        f"{n} {v * 1e3:+.4f} mm {'OK' if v > 0 else 'VIOLATED'}" for n, v in zip(MARGIN_NAMES, m)
    )


def _progress(quiet: bool, start_line, unit: str = "GPa m/s"):
    """The per-iteration progress callback of both searches: the best feasible objective (in
    `unit`), then one line per start (`start_line(j, info, margins, index of the smallest
    margin)`)."""
    import numpy as np

    def progress(it, info):
        if quiet:
            return
        best = info.best
        print(
            f"iter {it:3d}  best feasible {best:.4f} {unit}"
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
    """A design array by its engineering keys (`end_radius_mm`, ...), three or eight."""
    if x is None:
        return None
    from ._bounds import DESIGN_TABLE, PROFILE_TABLE

    table = DESIGN_TABLE if len(x) == 3 else PROFILE_TABLE
    return {var.key: float(v) * var.scale for var, v in zip(table, x)}
