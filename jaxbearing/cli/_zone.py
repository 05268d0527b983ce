"""`jaxbearing zone`: roller-end/flange design zone (the paper's Figure 14).

Prints the contact geometry of an aligned roller and each design margin with OK/VIOLATED; with
`--map` writes

- DIR/zone_height_map.png: contact height over end radius R_end (40..140 mm) x layback angle
  theta_f (0.5..3 deg), with the upper contact-height limit, the relief (lower) limit and the
  limited-circle line, the feasible region hatched and the current design marked;
- DIR/zone_clearance_map.png: actual axial clearance Lambda_bf over R_end x axial clearance
  Delta_bf (0..0.3 mm) at the current theta_f, with the Lambda_bf = 0 line.

Each map is one jit-compiled vmap over its grid (`jaxbearing._zone.design_zone_grid`).

Exit status 0 when the design is feasible, 3 (`EXIT_INFEASIBLE`) when it is outside the design
zone (the report says which margin is violated), 4 when the maps could not be written to --out
and went to the fallback directory printed. --out is checked before anything is computed.
"""

from __future__ import annotations

import math
import os

from .._errors import UserInputError

MM = 1e-3
#: map grids (engineering units) and resolution
END_RADIUS_RANGE_MM = (40.0, 140.0)
LAYBACK_RANGE_DEG = (0.5, 3.0)
CLEARANCE_RANGE_MM = (0.0, 0.3)
GRID_POINTS = 121


def register(sub) -> None:
    p = sub.add_parser(
        "zone",
        help="roller-end/flange design zone: contact height, clearance, margins (Figure 14)",
        description="Print the contact geometry of an aligned roller against its flange and each "
        "design-zone margin (relief, contact-height limit, limited circle, actual axial clearance) "
        "with OK/VIOLATED; with --map, draw the paper's Figure 14 maps. Exit status 3 when the "
        "design is outside the design zone.",
    )
    p.add_argument("--config", help="TOML configuration (default: embedded reference bearing)")
    p.add_argument(
        "--flange-load-N",
        type=float,
        dest="flange_load_N",
        default=None,
        help="flange normal load for the contact-ellipse half-width [N] (default 100)",
    )
    p.add_argument(
        "--map",
        action="store_true",
        help="write the two design-zone maps (PNG) into --out (default: no maps)",
    )
    p.add_argument(
        "--out",
        default=".",
        help="output directory for --map, checked before the maps are computed (default: %(default)s)",
    )
    p.set_defaults(func=run)


def _bearing(config):
    """The bearing of `--config` (the embedded reference bearing without it)."""
    return _config(config).bearing()


def _config(config):
    """The configuration of `--config` (the embedded reference configuration without it); its
    errors name the file."""
    from ..io import load_config

    try:
        return load_config(config)
    except UserInputError as exc:
        raise UserInputError(f"{config}: {exc}" if config is not None else str(exc)) from None


def _mm(x) -> str:
    return f"{float(x) / MM:10.4f} mm"


def zone_lines(bearing, zone, flange_load: float) -> list[str]:
    """The report printed by `jaxbearing zone` (lengths in mm)."""
    r, f = bearing.roller, bearing.flange

    def margin(name, value):
        ok = "OK" if float(value) > 0 else "VIOLATED"
        return f"    {name:<42}{_mm(value)}  {ok}"

    theta = float(f.layback_angle)
    end = f"{'flat (corner only)':>13}" if math.isinf(float(r.end_radius)) else _mm(r.end_radius)
    return [
        "Roller-end/flange design zone (aligned roller, pure rolling)",
        f"  end radius R_end                          {end}",
        f"  layback angle theta_f                     {math.degrees(theta):10.4f} deg",
        f"  axial clearance Delta_bf                  {_mm(f.axial_clearance)}",
        f"  flange load (contact ellipse)             {flange_load:10.1f} N",
        f"  contact radius rho_c                      {_mm(zone.contact_radius)}"
        + ("  (on the arc)" if float(zone.on_arc) > 0.5 else "  (on the corner)"),
        f"  corner contact radius (flat ends)         {_mm(zone.corner_contact_radius)}",
        f"  limited circle radius rho_lim             {_mm(zone.limited_circle_radius)}",
        f"  contact height h_c                        {_mm(zone.contact_height)}",
        f"  contact ellipse half-width (height)       {_mm(zone.ellipse_half_width)}",
        f"  arc protrusion e                          {_mm(zone.arc_protrusion)}",
        f"  actual axial clearance Lambda_bf          {_mm(zone.actual_axial_clearance)}",
        f"  seated gap (aligned roller, both ends)    {_mm(zone.seated_gap)}",
        "  margins (positive = feasible):",
        margin("relief: h_c - half-width - h_rel", zone.relief_margin),
        margin("height: h_up - h_c", zone.height_margin),
        margin("limited circle: rho_lim - rho_c", zone.limited_circle_margin),
        margin("clearance: Lambda_bf - minimum", zone.clearance_margin),
        f"  design: {'FEASIBLE' if bool(zone.feasible) else 'NOT FEASIBLE'}",
    ]


def zone_maps(bearing, flange_load: float, points: int = GRID_POINTS):
    """The two map grids: (r_mm, theta_deg, height_zone), (r_mm, clearance_mm, clearance_zone)."""
    import numpy as np

    from ..flange import design_zone_grid

    r_mm = np.linspace(*END_RADIUS_RANGE_MM, points)
    t_deg = np.linspace(*LAYBACK_RANGE_DEG, points)
    c_mm = np.linspace(*CLEARANCE_RANGE_MM, points)
    rr, tt = np.meshgrid(r_mm, t_deg)
    height = design_zone_grid(bearing, rr * MM, np.radians(tt), bearing.flange.axial_clearance, flange_load)
    rr2, cc = np.meshgrid(r_mm, c_mm)
    clear = design_zone_grid(bearing, rr2 * MM, bearing.flange.layback_angle, cc * MM, flange_load)
    return (r_mm, t_deg, height), (r_mm, c_mm, clear)


def _height_feasible(z):
    import numpy as np

    return (
        (np.asarray(z.relief_margin) > 0)
        & (np.asarray(z.height_margin) > 0)
        & (np.asarray(z.limited_circle_margin) > 0)
    )


def _draw_map(
    x, y, field, *, colorbar, contours, feasible, star, xlabel, ylabel, title, legend_loc, path, **contourf_kw
) -> str:
    """One design-zone map: filled `field` over (x, y), zero lines of each (margin, colour,
    label) in `contours`, the feasible region hatched, the current design `star` (or None)."""
    import numpy as np
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    from ..io import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5.5), dpi=110)
    cf = ax.contourf(x, y, field, **contourf_kw)
    fig.colorbar(cf, ax=ax, label=colorbar)
    handles = []
    for margin, colour, label in contours:
        ax.contour(x, y, np.asarray(margin), levels=[0.0], colors=colour, linewidths=2)
        handles.append(Line2D([], [], color=colour, lw=2, label=label))
    if feasible.any():
        ax.contourf(x, y, feasible.astype(float), levels=[0.5, 1.5], colors="none", hatches=["//"])
    handles.append(Patch(facecolor="none", edgecolor="k", hatch="//", label="feasible"))
    if star is not None:
        ax.plot(*([v] for v in star), marker="*", ms=16, color="magenta", mec="k", ls="none")
    handles.append(
        Line2D([], [], marker="*", ms=12, color="magenta", mec="k", ls="none", label="current design")
    )
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(handles=handles, loc=legend_loc, fontsize=8, framealpha=0.85)
    fig.savefig(path)
    plt.close(fig)
    return path


def write_maps(bearing, flange_load: float, out_dir: str) -> list[str]:
    """The paper's Figure 14 for `bearing`: contact height over (R_end, theta_f) and actual
    axial clearance over (R_end, Delta_bf), with the design-zone limits and the current design."""
    return draw_maps(bearing, flange_load, out_dir, zone_maps(bearing, flange_load))


def draw_maps(bearing, flange_load: float, out_dir, maps) -> list[str]:
    """Draw the two maps of `zone_maps` into `out_dir` (`write_maps`)."""
    import numpy as np
    from matplotlib.colors import TwoSlopeNorm

    out_dir = os.fspath(out_dir)
    os.makedirs(out_dir, exist_ok=True)
    (r_mm, t_deg, hz), (_, c_mm, cz) = maps
    r_now = float(bearing.roller.end_radius) / MM
    t_now = math.degrees(float(bearing.flange.layback_angle))
    c_now = float(bearing.flange.axial_clearance) / MM
    in_range = END_RADIUS_RANGE_MM[0] <= r_now <= END_RADIUS_RANGE_MM[1]
    # the limited-circle line is drawn from the arc contact radius R_end sin(theta_f), which
    # is smooth across it (the actual contact radius has a kink there); the relief line is
    # drawn only where the contact is on the arc (on the corner the ellipse is much narrower)
    rr, tt = np.meshgrid(r_mm * MM, np.radians(t_deg))
    arc_radius_margin = np.asarray(hz.limited_circle_radius) - rr * np.sin(tt)
    on_arc = np.asarray(hz.on_arc) > 0.5
    height = _draw_map(
        r_mm,
        t_deg,
        np.asarray(hz.contact_height) / MM,
        levels=24,
        cmap="viridis",
        colorbar="contact height h_c [mm]",
        contours=[
            (hz.height_margin, "tab:red", "upper limit h_c = h_up"),
            (
                np.where(on_arc, hz.relief_margin, np.nan),
                "tab:orange",
                "relief (lower) limit h_c - a = h_rel",
            ),
            (arc_radius_margin, "white", "limited circle rho_c = rho_lim"),
        ],
        feasible=_height_feasible(hz),
        star=(r_now, t_now) if in_range else None,
        xlabel="end radius R_end [mm]",
        ylabel="flange layback angle theta_f [deg]",
        title=f"Contact height (Delta_bf = {c_now:.3f} mm, flange load {flange_load:.0f} N)",
        legend_loc="upper right",
        path=os.path.join(out_dir, "zone_height_map.png"),
    )
    lam = np.asarray(cz.actual_axial_clearance) / MM
    span = max(float(np.max(np.abs(lam))), 1e-6)
    clearance = _draw_map(
        r_mm,
        c_mm,
        lam,
        levels=np.linspace(-span, span, 25),
        cmap="coolwarm_r",
        norm=TwoSlopeNorm(0.0, -span, span),
        colorbar="actual axial clearance Lambda_bf [mm]",
        contours=[(lam, "k", "Lambda_bf = 0 (contact line)")],
        feasible=np.asarray(cz.clearance_margin) > 0,
        star=(r_now, c_now) if in_range else None,
        xlabel="end radius R_end [mm]",
        ylabel="axial clearance Delta_bf [mm]",
        title=f"Actual axial clearance (theta_f = {t_now:.2f} deg)",
        legend_loc="lower right",
        path=os.path.join(out_dir, "zone_clearance_map.png"),
    )
    return [height, clearance]


def outside_zone_lines(bearing, zone) -> list[str]:
    """One line per violated design-zone margin (empty for a feasible design)."""
    why = {
        "relief_margin": "the contact ellipse reaches the flange relief (h_c - a_t < h_rel)",
        "height_margin": "the contact is above the contact-height limit (h_c > h_up)",
        "limited_circle_margin": "the contact is on the corner, not on the arc end (rho_c > rho_lim)",
        "clearance_margin": "the actual axial clearance Lambda_bf is negative: the roller does not fit "
        "between the flanges",
    }
    return [
        f"the design is outside the design zone (docs/model.md 6): {name.removesuffix('_margin')} "
        f"margin {float(getattr(zone, name)) / MM:+.4f} mm: {text}"
        for name, text in why.items()
        if not float(getattr(zone, name)) > 0
    ]


def run(args) -> int:
    import sys

    from ..flange import DEFAULT_FLANGE_LOAD, design_zone
    from ..io import check_output_dir, plausibility_warnings, write_or_fallback
    from ._main import EXIT_INFEASIBLE, report_fallback

    load = DEFAULT_FLANGE_LOAD if args.flange_load_N is None else args.flange_load_N
    if not (load > 0 and math.isfinite(load)):
        raise UserInputError(f"--flange-load-N = {load}: must be a finite load > 0 N")
    if args.map:
        check_output_dir(args.out, "--out")
    cfg = _config(args.config)
    for line in plausibility_warnings(cfg):
        print(f"warning: {line}", file=sys.stderr)
    bearing = cfg.bearing()
    zone = design_zone(bearing, load)
    print("\n".join(zone_lines(bearing, zone, load)))
    code = 0
    if args.map:
        maps = zone_maps(bearing, load)
        written: list[str] = []
        used, reason = write_or_fallback(
            args.out, lambda d: written.extend(draw_maps(bearing, load, d, maps))
        )
        for path in written[-2:]:
            print(f"wrote {path}")
        code = report_fallback("jaxbearing zone", args.out, used, reason)
    if not bool(zone.feasible):
        for line in outside_zone_lines(bearing, zone):
            print(f"jaxbearing zone: {line}", file=sys.stderr)
        return code or EXIT_INFEASIBLE
    return code
