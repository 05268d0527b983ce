"""Search paths over the design-zone feasibility map (matplotlib, Agg backend)."""

from __future__ import annotations

import dataclasses
import math
import pathlib

import numpy as np


def _draw_zone(ax, rr, tt, z) -> None:
    """The design zone `z` on the (R_end [mm], theta_f [deg]) grid `rr`, `tt`: the feasible
    region shaded, the zero line of each margin that changes sign on it."""
    feas = np.asarray(z.feasible, dtype=float)
    ax.contourf(rr, tt, feas, levels=[-0.5, 0.5, 1.5], colors=["#f2f2f2", "#b7e1b0"])
    styles = (
        ("relief_margin", "tab:red", "relief"),
        ("height_margin", "tab:blue", "height limit"),
        ("limited_circle_margin", "tab:purple", "limited circle"),
        ("clearance_margin", "tab:orange", "axial clearance"),
    )
    for field, colour, label in styles:
        m = np.asarray(getattr(z, field))
        if m.min() < 0 < m.max():
            ax.contour(rr, tt, m, levels=[0.0], colors=colour, linewidths=1.2)
            ax.plot([], [], color=colour, label=f"{label} margin = 0")


def _draw_corner_margin(ax, rr, tt, z, result, h) -> None:
    """A steady search's dynamic corner margin (five margins per iterate in the history `h`):
    its zero line, dashed, where it falls on the grid."""
    margins = np.asarray(h.get("margins", [])) if h else np.zeros(0)
    if margins.ndim == 3 and margins.shape[-1] >= 5 and getattr(result, "best_iteration", -1) >= 0:
        # steady search: the dynamic corner margin, with the skew excursion max - rho_c measured
        # at the final design: limited-circle margin = excursion + corner margin
        m = margins[result.best_iteration, result.best_start]
        offset = m[2] - m[4]
        lc = np.asarray(z.limited_circle_margin)
        if lc.min() < offset < lc.max():
            ax.contour(rr, tt, lc, levels=[offset], colors="tab:purple", linestyles="--", linewidths=1.2)
            ax.plot([], [], color="tab:purple", ls="--", label="dynamic corner margin = 0 (measured skew)")


def _draw_paths(ax, result, h) -> None:
    """Every start's path (its start a circle), the near-optimal designs as open diamonds and
    the final design as a star."""
    if h:
        xs = np.asarray(h["x"])  # (I, S, 3)
        for s in range(xs.shape[1]):
            (line,) = ax.plot(xs[:, s, 0] * 1e3, np.degrees(xs[:, s, 1]), "-", lw=1, marker=".", ms=3)
            ax.plot(xs[0, s, 0] * 1e3, math.degrees(xs[0, s, 1]), "o", color=line.get_color(), mfc="none")
    near = _near_optimal(result)
    if near:
        pts = np.asarray([d.design for d in near])
        ax.plot(
            pts[:, 0] * 1e3,
            np.degrees(pts[:, 1]),
            "D",
            mfc="none",
            mec="k",
            ms=7,
            ls="none",
            label=f"near-optimal: within the best's 95 % interval ({len(near)})",
        )
    if result.design is not None:
        ax.plot(
            result.design[0] * 1e3,
            math.degrees(result.design[1]),
            "*",
            color="k",
            ms=14,
            label="final design",
        )


def plot_search(problem, result, path) -> pathlib.Path:
    """Write a PNG of every start's path in (R_end, theta_f) over the feasibility map of the
    design zone (`jaxbearing.design_zone_grid`, at the final Delta_bf, or the start's when no
    feasible design was found): feasible region shaded, zero lines of each margin, starts as
    circles, the final design as a star, the near-optimal designs (`_steady.near_optimal_set`)
    as open diamonds. For a steady search (five margins per iterate), the
    dynamic corner margin's zero line too, dashed (`_steady`: the limited-circle margin equal to
    the skew excursion measured at the final design plus the corner margin). A profile search
    (eight variables) draws the start's and the found design's faces instead (`plot_faces`)."""
    from jaxbearing.io import pyplot

    if problem.num_variables != 3:  # a profile: the faces, not a map of two variables
        from ._faces_plot import plot_faces

        designs = {"start": result.start_design}
        if result.design is not None:
            designs["found"] = result.design
        return plot_faces(problem.bearing, designs, path)
    plt = pyplot()

    from ._problem import feasibility_map

    x_ref = result.design if result.design is not None else result.start_design
    r, t, z = feasibility_map(problem, float(x_ref[2]))
    rr, tt = np.meshgrid(r * 1e3, np.degrees(t), indexing="ij")
    fig, ax = plt.subplots(figsize=(7, 5))
    _draw_zone(ax, rr, tt, z)
    h = _history(result)
    _draw_corner_margin(ax, rr, tt, z, result, h)
    _draw_paths(ax, result, h)
    ax.set_xlabel("end radius R_end [mm]")
    ax.set_ylabel("layback angle theta_f [deg]")
    free_clearance = problem.bounds.upper[2] > problem.bounds.lower[2]
    ax.set_title(
        f"design zone at Delta_bf = {x_ref[2] * 1e3:.3f} mm (green: feasible) and search paths"
        + ("\n(projected: Delta_bf varies along them)" if free_clearance else ""),
        fontsize=9,
    )
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    path = pathlib.Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _near_optimal(result) -> list:
    """The steady search's near-optimal set (`_steady.near_optimal_set`); none for the startup
    search."""
    h = _history(result)
    margins = np.asarray(h.get("margins", [])) if h else np.zeros(0)
    if margins.ndim != 3 or margins.shape[-1] < 5:
        return []
    from ._steady import near_optimal_set

    return near_optimal_set(result)


def _history(result) -> dict:
    """The search's history as arrays by field name: the start-up search keeps a dict, the
    steady search a `_state.History` (empty: {})."""
    h = result.history
    if dataclasses.is_dataclass(h):
        return {f.name: getattr(h, f.name) for f in dataclasses.fields(h)} if len(h) else {}
    return h
