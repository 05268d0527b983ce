"""Standard figures of a sweep (matplotlib, Agg), drawn from its labelled dataset.

* Figures 9-11 of the paper: peak pressure, sliding velocity and PV of the roller-end/flange
  contact versus inner-ring speed, arc and corner ends (needs the axis operating.speed_rpm; the
  `end` axis gives one line per end type). Solid: maximum over contact events; dashed: mean.
  Of a settled sweep these are the expected largest and mean of a cage revolution, with their
  95 % intervals as error bars; a start-up transient sweep's figures say so in their title.
* Figure 12: sliding velocity and PV versus the end radius R_end (roller.end_radius_mm) and
  versus the flange layback angle theta_f (flange.layback_angle_deg), arc ends.
* Figure 13: contact positions on the roller end face (roller frame, y along the radial
  direction, z circumferential) for several layback angles, end radii and central lengths
  (roller.central_length_mm), with the end-face outline D/2 and the limited circle
  rho_lim = R_ce R_end / (R_end - R_cor).

Dimensions a figure does not use are fixed at their first value (named in the title).
`plot_sweep` returns what it drew and, for each figure it could not draw, the missing axis.
"""

from __future__ import annotations

import json
import math
import pathlib

import numpy as np

from ..io import pyplot as _plt

_SPEED, _R_END = "operating.speed_rpm", "roller.end_radius_mm"
_LAYBACK, _CENTRAL = "flange.layback_angle_deg", "roller.central_length_mm"
_AXIS_LABEL = {
    _SPEED: "inner-ring speed [rpm]",
    _R_END: "end radius $R_{end}$ [mm]",
    _LAYBACK: r"layback angle $\theta_f$ [deg]",
    _CENTRAL: "central length $L_{b2}$ [mm]",
}
#: (variable stem, label, scale)
_PRESSURE = ("flange_pressure_Pa", "peak pressure [GPa]", 1e-9)
_SLIDING = ("flange_sliding_velocity_m_s", "sliding velocity [m/s]", 1.0)
_PV = ("flange_pv_Pa_m_s", "PV [GPa m/s]", 1e-9)


def coordinate_for(ds, key: str) -> str | None:
    """Name of the coordinate of `ds` that sweeps configuration key `key` (or "end")."""
    for name, coord in ds.coords.items():
        if coord.attrs.get("config_key") == key:
            return str(name)
    return None


def _fix_other_dims(ds, keep: set[str]):
    """Select the first index along every sweep dimension not in `keep`; (dataset, note)."""
    sweep_dims = [d for d in ds["status"].dims if d not in keep]
    notes = []
    for d in sweep_dims:
        sel = ds.isel({d: 0})
        notes += [f"{n} = {sel[n].values}" for n, c in ds.coords.items() if c.dims == (d,)]
        ds = sel
    return ds, ("; ".join(notes))


def _ends(ds):
    end = coordinate_for(ds, "end")
    if end is None:
        return [(ds.attrs.get("base_end", "arc"), ds)]
    dim = ds[end].dims[0]
    return [(str(ds[end].values[i]), ds.isel({dim: i})) for i in range(ds.sizes[dim])]


def _versus(ds, key: str):
    """(coordinate name, its dimension) of axis `key`."""
    name = coordinate_for(ds, key)
    return name, ds[name].dims[0]


def _line_figure(ds, key: str, panels, title: str, path: pathlib.Path, arc_only: bool = False):
    plt = _plt()
    name, dim = _versus(ds, key)
    end_name = coordinate_for(ds, "end")
    keep = {dim} | ({ds[end_name].dims[0]} if end_name else set())
    sub, note = _fix_other_dims(ds, keep)
    fig, axes = plt.subplots(1, len(panels), figsize=(4.6 * len(panels), 3.8), squeeze=False)
    for ax, (stem, label, k) in zip(axes[0], panels):
        for end, part in _ends(sub):
            if arc_only and end != "arc" and end_name is not None:
                continue
            order = np.argsort(part[name].values)
            x = part[name].values[order]
            for stat, style in (("max", "-o"), ("mean", "--s")):
                var = f"{stem}_{stat}"
                y = part[var].values[order] * k
                if f"{var}_ci95_low" in part:  # settled running: the 95 % intervals
                    low = part[f"{var}_ci95_low"].values[order] * k
                    high = part[f"{var}_ci95_high"].values[order] * k
                    err = np.vstack([np.abs(y - low), np.abs(high - y)])
                    ax.errorbar(x, y, yerr=err, fmt=style, label=f"{end} {stat}", ms=4, capsize=3)
                else:
                    ax.plot(x, y, style, label=f"{end} {stat}", ms=4)
        ax.set_xlabel(_AXIS_LABEL.get(key, name))
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"{title}, {running_label(ds)}" + (f"\n({note})" if note else ""), fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def running_label(ds) -> str:
    """What a sweep's statistics describe, as the figures say it: settled running with its
    intervals, or a start-up transient (also for datasets written before settled sweeps)."""
    if ds.attrs.get("running") == "settled running":
        n = len(json.loads(ds.attrs.get("seeds", "[0]")))
        how = f"{n} seeds" if n > 1 else "batch means over revolutions"
        return f"settled running, per cage revolution; bars: 95 % CI ({how})"
    return "START-UP TRANSIENT (not settled running)"


def _base_value(ds, path: str) -> float:
    spec = json.loads(ds.attrs["spec"])
    node = spec["base"]
    for part in path.split("."):
        node = node[part]
    return float(node)


def _positions_figure(ds, key: str, path: pathlib.Path, max_panels: int = 6):
    plt = _plt()
    name, dim = _versus(ds, key)
    end_name = coordinate_for(ds, "end")
    if end_name is not None and "arc" in ds[end_name].values:
        ds = ds.isel({ds[end_name].dims[0]: int(np.flatnonzero(ds[end_name].values == "arc")[0])})
    sub, note = _fix_other_dims(ds, {dim})
    n = sub.sizes[dim]
    idx = np.unique(np.linspace(0, n - 1, min(n, max_panels)).round().astype(int))
    fig, axes = plt.subplots(1, len(idx), figsize=(3.2 * len(idx), 3.5), squeeze=False)
    diameter = _base_value(ds, "roller.diameter_mm")
    corner = _base_value(ds, "roller.corner_radius_mm")
    t = np.linspace(0, 2 * np.pi, 200)
    for ax, i in zip(axes[0], idx):
        case = sub.isel({dim: int(i)})
        value = float(case[name].values)
        r_end = value if key == _R_END else _base_value(ds, _R_END)
        pts = case["contact_position"].values * 1e3
        pts = pts[np.isfinite(pts).all(axis=-1)]
        ax.plot(diameter / 2 * np.cos(t), diameter / 2 * np.sin(t), "k-", lw=0.8)
        if math.isfinite(r_end):
            r_ce = diameter / 2 - corner
            rho_lim = r_ce * r_end / (r_end - corner)
            ax.plot(rho_lim * np.cos(t), rho_lim * np.sin(t), "r--", lw=0.8, label="limited circle")
        if len(pts):
            ax.plot(pts[:, 0], pts[:, 1], ".", ms=3, label="contact")
        else:
            ax.text(0, 0, "no contact", ha="center", va="center", fontsize=8)
        ax.set_aspect("equal")
        ax.set_title(f"{name} = {value:g}", fontsize=9)
        ax.set_xlabel("y [mm]")
        ax.set_ylabel("z [mm]")
    axes[0][0].legend(fontsize=7, loc="lower left")
    fig.suptitle(
        f"Contact positions on the roller end face (cf. paper Fig. 13), {running_label(ds).split(';')[0]}"
        + (f"\n({note})" if note else ""),
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_sweep(ds, out_dir) -> tuple[list[tuple[str, pathlib.Path]], list[tuple[str, str]]]:
    """Draw every standard figure the sweep's axes allow into `out_dir`.

    Returns (drawn: [(figure, path)], skipped: [(figure, reason)])."""
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    drawn: list[tuple[str, pathlib.Path]] = []
    skipped: list[tuple[str, str]] = []
    has = {k: coordinate_for(ds, k) is not None for k in (_SPEED, _R_END, _LAYBACK, _CENTRAL, "end")}

    for fig_no, panel in ((9, _PRESSURE), (10, _SLIDING), (11, _PV)):
        label = f"Figure {fig_no} ({panel[1].split(' [')[0]} vs speed)"
        if not has[_SPEED]:
            skipped.append((label, f"needs the axis {_SPEED}"))
            continue
        path = out_dir / f"figure{fig_no}_{panel[0]}_vs_speed.png"
        ends = "arc and corner ends" if has["end"] else f"{ds.attrs.get('base_end')} end"
        _line_figure(
            ds, _SPEED, [panel], f"{panel[1].split(' [')[0]} vs speed, {ends} (cf. paper Fig. {fig_no})", path
        )
        drawn.append((label, path))

    for key, tag in ((_R_END, "end_radius"), (_LAYBACK, "layback_angle")):
        label = f"Figure 12 (sliding velocity and PV vs {tag.replace('_', ' ')})"
        if not has[key]:
            skipped.append((label, f"needs the axis {key}"))
            continue
        path = out_dir / f"figure12_vs_{tag}.png"
        _line_figure(
            ds,
            key,
            [_SLIDING, _PV],
            f"sliding velocity and PV vs {tag.replace('_', ' ')}, arc end (cf. paper Fig. 12)",
            path,
            arc_only=True,
        )
        drawn.append((label, path))

    for key, tag, plural in (
        (_LAYBACK, "layback_angle", "layback angles"),
        (_R_END, "end_radius", "end radii"),
        (_CENTRAL, "central_length", "central lengths"),
    ):
        label = f"Figure 13 (contact positions for several {plural})"
        if not has[key]:
            skipped.append((label, f"needs the axis {key}"))
            continue
        path = out_dir / f"figure13_contact_positions_vs_{tag}.png"
        _positions_figure(ds, key, path)
        drawn.append((label, path))
    return drawn, skipped
