"""Flange contact events and their statistics (the quantities of the paper's Figure 7).

A contact event is a maximal run of saved samples in which one roller presses on one flange
(normal force above `threshold`). Each event contributes its peak force, peak pressure, peak PV,
its sliding speed, contact height and contact radius at the instant of peak force, and whether
that instant lies on the arc. Statistics are max / mean / median / min over events.
"""

from __future__ import annotations

import numpy as np

from ..geometry import kinematic_cage_speed, rad_s_to_rpm

#: summary.json key -> history key, reduction within one event
_EVENT_QUANTITIES = {
    "flange_force_N": ("flange_force", "max"),
    "flange_pressure_Pa": ("flange_pressure", "max"),
    "flange_sliding_velocity_m_s": ("flange_sliding_speed", "at_peak"),
    # the paper's Figure 7c definition: the roller's own surface speed at the contact point
    "flange_roller_surface_speed_m_s": ("flange_roller_surface_speed", "at_peak"),
    "flange_pv_Pa_m_s": ("flange_pv", "max"),
    "contact_height_m": ("contact_height", "at_peak"),
    "contact_radius_m": ("contact_radius", "at_peak"),
}


def contact_events(histories: dict, threshold: float = 1.0) -> dict[str, np.ndarray]:
    """Per-event values of every quantity in `_EVENT_QUANTITIES` plus `on_arc`, `roller`, `flange`."""
    q = np.asarray(histories["flange_force"])  # (T, Z, 4)
    t_n, z, f = q.shape
    out: dict[str, list] = {k: [] for k in _EVENT_QUANTITIES}
    out.update(on_arc=[], roller=[], flange=[], time=[])
    if t_n == 0:
        return {k: np.asarray(v) for k, v in out.items()}
    active = q > threshold
    for j in range(z):  # post-processing in numpy, outside traced code
        for k in range(f):
            a = active[:, j, k]
            if not a.any():
                continue
            edges = np.diff(np.concatenate([[0], a.astype(np.int8), [0]]))
            starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
            for s, e in zip(starts, ends):
                seg = slice(s, e)
                i_peak = s + int(np.argmax(q[seg, j, k]))
                for key, (hk, how) in _EVENT_QUANTITIES.items():
                    h = np.asarray(histories[hk])[:, j, k]
                    out[key].append(h[seg].max() if how == "max" else h[i_peak])
                out["on_arc"].append(float(np.asarray(histories["on_arc"])[i_peak, j, k] > 0.5))
                out["roller"].append(j)
                out["flange"].append(k)
                out["time"].append(float(histories["t"][i_peak]))
    return {k: np.asarray(v) for k, v in out.items()}


def _stats(values: np.ndarray) -> dict:
    if values.size == 0:
        return {"max": None, "mean": None, "median": None, "min": None}
    return {
        "max": float(np.max(values)),
        "mean": float(np.mean(values)),
        "median": float(np.median(values)),
        "min": float(np.min(values)),
    }


def summarise(result, threshold: float = 1.0) -> dict:
    """The summary.json block of one run (keys documented in the `simulate` command)."""
    h = result.histories
    events = contact_events(h, threshold)
    kin = float(rad_s_to_rpm(kinematic_cage_speed(result.bearing, result.operating)))
    cage = np.asarray(h["cage_speed"])
    # cage speed averaged over the second half of the run (after the start transient)
    cage_rpm = float(rad_s_to_rpm(np.mean(cage[len(cage) // 2 :]))) if cage.size else float("nan")
    block = {
        "status": result.status,
        "cage_speed_rpm": cage_rpm,
        "kinematic_cage_speed_rpm": kin,
        "cage_slip": (kin - cage_rpm) / kin if kin else float("nan"),
        "flange_contact_events": int(events["roller"].size),
        "on_arc_fraction": float(np.mean(events["on_arc"])) if events["on_arc"].size else None,
        "smooth_peak_pv_Pa_m_s": result.smooth_peak_pv,
        "smooth_max_contact_height_m": result.smooth_max_contact_height,
        "num_steps": result.num_steps,
        "num_rejected_steps": result.num_rejected_steps,
        "wall_time_s": result.wall_time_s,
        "compile_time_s": result.compile_time_s,
        "simulated_time_s": result.reached_time,
    }
    for key in _EVENT_QUANTITIES:
        block[key] = _stats(events[key])
    return block
