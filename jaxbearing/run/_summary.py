"""Flange contact events and their statistics (the quantities of the paper's Figure 7).

A contact event is a maximal run of saved samples in which one roller presses on one flange
(normal force above `threshold`). Each event contributes its peak force, peak pressure, peak PV,
its sliding speed, contact height and contact radius at the instant of peak force, and whether
that instant lies on the arc. Statistics are max / mean / median / min over events.

Film statistics (`film_statistics`) are taken over CONTACT TIME instead: over every saved sample
(uniform in time) in which a roller presses on a flange, i.e. each (sample, roller, flange)
with normal force above `threshold`: the minimum film h_min (min, p05, median), the central film
(min, median), the film parameter Lambda (mean, median, p05, min), `lambda_below_one_share`
(share of contact time with Lambda < 1, boundary lubrication), `top_edge_contact_share` (share
of contact time with the contact point above the flange height: computed on a flange that is
not there) and the largest tangent-plane error at a contact, `flange_face_error_max_m`
(docs/model.md 5.2). Histories without these keys (older runs) give None.

Friction power (`friction_power_statistics`) is a time-mean over every sample, per flange and in
total; the flash temperature rise at the rib is an event quantity, each event's largest
(docs/model.md 5.5).
"""

from __future__ import annotations

import numpy as np

from ..geometry import kinematic_cage_speed, rad_s_to_rpm

#: the normal force above which a saved contact sample is contact (contact time, events and the
#: settled statistics; the tail statistic's indicator) [N]
CONTACT_THRESHOLD = 1.0

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
    # the largest flash temperature rise at the rib during the event (docs/model.md 5.5)
    "flange_flash_temperature_K": ("flange_flash_temperature", "max"),
}


def contact_events(histories: dict, threshold: float = CONTACT_THRESHOLD) -> dict[str, np.ndarray]:
    """Per-event values of every quantity in `_EVENT_QUANTITIES` plus `on_arc`, `roller`, `flange`
    (NaN for a quantity the histories lack: older runs)."""
    q = np.asarray(histories["flange_force"])  # (T, Z, 4)
    nan = np.full(q.shape, np.nan)
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
                    h = np.asarray(histories.get(hk, nan))[:, j, k]
                    out[key].append(h[seg].max() if how == "max" else h[i_peak])
                out["on_arc"].append(float(np.asarray(histories["on_arc"])[i_peak, j, k] > 0.5))
                out["roller"].append(j)
                out["flange"].append(k)
                out["time"].append(float(histories["t"][i_peak]))
    return {k: np.asarray(v) for k, v in out.items()}


#: film statistics over contact time: summary key -> (history key, reductions)
FILM_QUANTITIES = {
    "flange_min_film_m": ("flange_min_film", ("min", "p05", "median")),
    "flange_central_film_m": ("flange_central_film", ("min", "median")),
    "film_parameter": ("flange_film_parameter", ("mean", "median", "p05", "min")),
}
_REDUCE = {
    "min": np.min,
    "max": np.max,
    "mean": np.mean,
    "median": np.median,
    "p05": lambda v: np.percentile(v, 5.0),
}
#: scalar film statistics over contact time (share of contact samples, or the largest value)
FILM_SCALARS = ("lambda_below_one_share", "top_edge_contact_share", "flange_face_error_max_m")
#: every key of `film_statistics`
FILM_KEYS = tuple(f"{k}.{r}" for k, (_, reds) in FILM_QUANTITIES.items() for r in reds) + FILM_SCALARS


def film_statistics(histories: dict, threshold: float = CONTACT_THRESHOLD) -> dict[str, float]:
    """Film statistics over contact time (module docstring), flat: "flange_min_film_m.min",
    ..., "lambda_below_one_share", "top_edge_contact_share", "flange_face_error_max_m". NaN
    where there is no contact sample or the histories lack the quantity."""
    out = dict.fromkeys(FILM_KEYS, np.nan)
    q = np.asarray(histories["flange_force"])
    touching = q > threshold
    if not touching.any():
        return out

    def at_contact(key):
        return np.asarray(histories[key])[touching] if key in histories else None

    for name, (hk, reds) in FILM_QUANTITIES.items():
        v = at_contact(hk)
        if v is not None:
            for r in reds:
                out[f"{name}.{r}"] = float(_REDUCE[r](v))
    lam, top, err = (at_contact(k) for k in ("flange_film_parameter", "flange_top_edge", "flange_face_error"))
    if lam is not None:
        out["lambda_below_one_share"] = float(np.mean(lam < 1.0))
    if top is not None:
        out["top_edge_contact_share"] = float(np.mean(top > 0.5))
    if err is not None:
        out["flange_face_error_max_m"] = float(np.max(err))
    return out


#: the flanges' names in the friction-power statistics, in `flange.FLANGE_ORDER` (inner -X,
#: inner +X, outer -X, outer +X), and their total
FRICTION_POWER_NAMES = ("inner_neg_x", "inner_pos_x", "outer_neg_x", "outer_pos_x", "total")
#: every key of `friction_power_statistics`
FRICTION_POWER_KEYS = tuple(f"flange_friction_power_W.{n}" for n in FRICTION_POWER_NAMES)


def friction_power_statistics(histories: dict) -> dict[str, float]:
    """The time-mean friction power [W] over the samples of `histories` (equally spaced in
    time), of each flange (summed over the rollers, `flange.flange_friction_power`) and in total:
    "flange_friction_power_W.inner_neg_x", ..., ".total" (`FRICTION_POWER_KEYS`). NaN without
    samples or without the quantity (older runs)."""
    power = histories.get("flange_friction_power")
    if power is None or not np.asarray(power).size:
        return dict.fromkeys(FRICTION_POWER_KEYS, np.nan)
    per_flange = np.mean(np.sum(np.asarray(power), axis=1), axis=0)  # (T, Z, 4) -> (4,)
    return dict(zip(FRICTION_POWER_KEYS, (*map(float, per_flange), float(np.sum(per_flange)))))


def _none_if_nan(x: float):
    return None if not np.isfinite(x) else float(x)


def _stats(values: np.ndarray) -> dict:
    """max / mean / median / min of the finite `values` (None without any)."""
    values = values[np.isfinite(values)]
    if values.size == 0:
        return {"max": None, "mean": None, "median": None, "min": None}
    return {
        "max": float(np.max(values)),
        "mean": float(np.mean(values)),
        "median": float(np.median(values)),
        "min": float(np.min(values)),
    }


#: what a fixed-duration run's statistics describe (summary key "running"; tables and plots)
TRANSIENT_LABEL = "start-up transient"
#: ... and a settled run's, when the settling verdict passed (else `UNSETTLED_LABEL`)
SETTLED_LABEL = "settled running"
UNSETTLED_LABEL = "not settled (see settled and residual_drift_rpm)"
#: ... and a settled run whose solve failed before its window was measured
FAILED_LABEL = "failed (see status)"


def summarise(result, threshold: float = CONTACT_THRESHOLD) -> dict:
    """The summary.json block of one run (keys documented in the `simulate` command)."""
    h = result.histories
    events = contact_events(h, threshold)
    kin = float(rad_s_to_rpm(kinematic_cage_speed(result.bearing, result.operating)))
    cage = np.asarray(h["cage_speed"])
    # cage speed averaged over the second half of the run (after the start transient)
    cage_rpm = float(rad_s_to_rpm(np.mean(cage[len(cage) // 2 :]))) if cage.size else float("nan")
    block = {
        "running": TRANSIENT_LABEL,
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
    film = film_statistics(h, threshold)
    for name, (_, reds) in FILM_QUANTITIES.items():
        block[name] = {r: _none_if_nan(film[f"{name}.{r}"]) for r in reds}
    for name in FILM_SCALARS:
        block[name] = _none_if_nan(film[name])
    power = friction_power_statistics(h)
    block["flange_friction_power_W"] = {k.partition(".")[2]: _none_if_nan(v) for k, v in power.items()}
    return block
