"""Standard figures of one simulation run (matplotlib, Agg backend).

* flange_boxplots.png: force, peak pressure, sliding velocity and PV per contact event, arc vs
  corner (the paper's Figure 7);
* contact_positions.png: contact points on the roller end face with the limited circle
  (the paper's Figure 8);
* cage_speed.png: cage speed over time against the kinematic cage speed.
"""

from __future__ import annotations

import pathlib

import numpy as np

from ..io import pyplot as _plt
from ._summary import SETTLED_LABEL, TRANSIENT_LABEL


def plot_run(out_dir: pathlib.Path, results: dict) -> list[pathlib.Path]:
    """The figures of `results` ({end: (result, summary)}) in `out_dir`, for the runs that have
    histories (a failed settled run may have none); the files written."""
    from ..geometry import kinematic_cage_speed, limited_circle_radius, rad_s_to_rpm
    from ._summary import contact_events

    plt = _plt()
    out_dir = pathlib.Path(out_dir)
    files = []
    # a settled run whose solve failed before its window has no histories: nothing to draw
    results = {end: rs for end, rs in results.items() if rs[0].histories}
    if not results:
        return files
    events = {end: contact_events(res.histories) for end, (res, _) in results.items()}
    label = _running_label(results)

    fig, axes = plt.subplots(1, 4, figsize=(14, 3.6))
    panels = (
        ("flange_force_N", "contact force [N]", 1.0),
        ("flange_pressure_Pa", "peak pressure [GPa]", 1e-9),
        ("flange_sliding_velocity_m_s", "sliding velocity [m/s]", 1.0),
        ("flange_pv_Pa_m_s", "PV [GPa m/s]", 1e-9),
    )
    for ax, (key, label, k) in zip(axes, panels):
        data = [events[e][key] * k for e in events]
        if all(d.size for d in data):
            ax.boxplot(data, showmeans=True)
            ax.set_xticks(range(1, len(events) + 1), list(events))
        else:
            ax.text(0.5, 0.5, "no contact events", ha="center", transform=ax.transAxes)
        ax.set_ylabel(label)
    fig.suptitle(f"Roller end / flange contact events (cf. paper Fig. 7), {label}")
    fig.tight_layout()
    files.append(out_dir / "flange_boxplots.png")
    fig.savefig(files[-1], dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(1, len(results), figsize=(4.5 * len(results), 4.2), squeeze=False)
    for ax, (end, (res, _)) in zip(axes[0], results.items()):
        h = res.histories
        q = np.asarray(h["flange_force"])
        pos = np.asarray(h["end_face_position"])[q > 1.0]
        if pos.size:
            ax.plot(pos[:, 0] * 1e3, pos[:, 1] * 1e3, ".", ms=2, alpha=0.5, label="contact points")
        rho = float(limited_circle_radius(res.bearing.roller)) * 1e3
        phi = np.linspace(0, 2 * np.pi, 200)
        ax.plot(rho * np.cos(phi), rho * np.sin(phi), "r-", lw=1, label="limited circle")
        ax.set_aspect("equal")
        ax.set_xlabel("y on end face [mm]")
        ax.set_ylabel("z on end face [mm]")
        ax.set_title(f"{end} end (cf. paper Fig. 8)\n{label}", fontsize=9)
        ax.legend(loc="upper right", fontsize=7)
    fig.tight_layout()
    files.append(out_dir / "contact_positions.png")
    fig.savefig(files[-1], dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 3.6))
    for end, (res, _) in results.items():
        h = res.histories
        ax.plot(np.asarray(h["t"]) * 1e3, rad_s_to_rpm(np.asarray(h["cage_speed"])), label=end)
    res0 = next(iter(results.values()))[0]
    ax.axhline(
        float(rad_s_to_rpm(kinematic_cage_speed(res0.bearing, res0.operating))),
        color="k",
        ls="--",
        label="kinematic",
    )
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("cage speed [rpm]")
    ax.set_title(f"cage speed, {label}", fontsize=9)
    ax.legend()
    fig.tight_layout()
    files.append(out_dir / "cage_speed.png")
    fig.savefig(files[-1], dpi=110)
    plt.close(fig)
    return files


def _running_label(results: dict) -> str:
    """What the runs' figures show: "START-UP TRANSIENT" (a fixed-duration run), the settled
    window, or a window that did not settle (`summarise`'s "running")."""
    running = {s.get("running", TRANSIENT_LABEL) for _, s in results.values()}
    if TRANSIENT_LABEL in running:
        return "START-UP TRANSIENT (not settled running)"
    if running == {SETTLED_LABEL}:
        return "settled running (measurement window)"
    return "window NOT SETTLED"


def plot_measured(path, rows: list[dict], title: str = "") -> pathlib.Path:
    """The model against measured cage speeds (`model_cage_speeds`' rows): cage speed over shaft
    speed, measured points against the settled model with its 95 % interval, one colour per
    radial load (left); the relative error (model - measured) / measured with its interval
    (right). The source study's Figure 16 layout."""
    plt = _plt()
    path = pathlib.Path(path)
    fig, (ax, axe) = plt.subplots(1, 2, figsize=(11, 4.2))
    loads = sorted({r["radial_load_N"] for r in rows})
    for i, load in enumerate(loads):
        sel = sorted((r for r in rows if r["radial_load_N"] == load), key=lambda r: r["shaft_speed_rpm"])
        colour = f"C{i % 10}"
        n = np.array([r["shaft_speed_rpm"] for r in sel])
        meas = np.array([r["measured_cage_speed_rpm"] for r in sel])
        est = [r["model_cage_speed_rpm"] for r in sel]
        val = np.array([np.nan if e["value"] is None else e["value"] for e in est])
        lo = np.array([np.nan if e["ci95_low"] is None else e["ci95_low"] for e in est])
        hi = np.array([np.nan if e["ci95_high"] is None else e["ci95_high"] for e in est])
        ax.plot(n, meas, "o", color=colour, mfc="none", label=f"measured, {load:g} N")
        ax.errorbar(
            n,
            val,
            yerr=[val - lo, hi - val],
            fmt="-s",
            ms=3,
            capsize=3,
            color=colour,
            label=f"model (95 % CI), {load:g} N",
        )
        err = np.array([np.nan if r["relative_error"] is None else r["relative_error"] for r in sel]) * 100
        elo = (
            np.array(
                [
                    np.nan if r["relative_error_ci95_low"] is None else r["relative_error_ci95_low"]
                    for r in sel
                ]
            )
            * 100
        )
        ehi = (
            np.array(
                [
                    np.nan if r["relative_error_ci95_high"] is None else r["relative_error_ci95_high"]
                    for r in sel
                ]
            )
            * 100
        )
        axe.errorbar(
            n, err, yerr=[err - elo, ehi - err], fmt="s", ms=3, capsize=3, color=colour, label=f"{load:g} N"
        )
    ax.set_xlabel("shaft speed [rpm]")
    ax.set_ylabel("cage speed [rpm]")
    ax.legend(fontsize=7)
    axe.axhline(0.0, color="k", lw=0.8)
    axe.set_xlabel("shaft speed [rpm]")
    axe.set_ylabel("relative error, model - measured [%]")
    axe.legend(fontsize=7)
    fig.suptitle(title or "Cage speed: model (settled running, 95 % CI) against measurement")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
