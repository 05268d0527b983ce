"""The model against measured cage speeds: a settled run at every measured operating point
(the source study's Figure 16 workflow; docs/validation.md, "Against your measurements").

`model_cage_speeds` runs each point of `io.read_cage_speed_measurements` as settled running
(`simulate_steady`: skid start, settling detection, a window of cage revolutions over seeded
initial scatters) and returns, per point, the model's cage speed with its 95 % confidence
interval, the relative error against the measurement, its interval, and whether the
measurement lies inside the model's interval. The configuration supplies every other input (the
bearing, the lubricant, the roller end, the solver); each point replaces only
`operating.speed_rpm` and `operating.radial_load_N`, checked against the configuration's ranges.
"""

from __future__ import annotations

import math

from .._errors import UserInputError
from ._settings import SteadySettings
from ._settle import simulate_steady, summarise_steady


def _point_config(cfg, point, source: str):
    """The configuration at a measured point; range errors name the file's line."""
    from ..io import check_runnable

    try:
        out = cfg.replace(
            **{"operating.speed_rpm": point.shaft_speed_rpm, "operating.radial_load_N": point.radial_load_N}
        )
        check_runnable(out)
    except UserInputError as exc:
        raise UserInputError(f"{source} line {point.line}: {exc}") from None
    return out


def model_cage_speeds(
    cfg,
    points,
    settings: SteadySettings | None = None,
    *,
    end: str = "arc",
    print_points: bool = False,
    source: str = "measurements",
    on_point=None,
) -> list[dict]:
    """One row per measured point (module docstring): `shaft_speed_rpm`, `radial_load_N`,
    `measured_cage_speed_rpm`, `model_cage_speed_rpm` ({value, ci95_low, ci95_high}),
    `relative_error` ((model - measured) / measured, with `relative_error_ci95_low/high` from
    the model's interval), `measurement_inside_ci`, `kinematic_cage_speed_rpm`, `cage_slip`,
    `settled`, `settle_time_ms`, `window_ms`, `status`, `line`. `settings`: how each point is
    settled and measured (`SteadySettings`; the configuration's solver options replace its
    tolerances, step limit and solver). `end`: "arc" or "corner" (flat ends with the corner
    radius). `print_points`: a line as each point starts. Every point's configuration is checked
    before the first run. `on_point(row)` is called as each point finishes (to keep finished
    work)."""
    if end not in ("arc", "corner"):
        raise UserInputError(f"end = {end!r}: must be 'arc' or 'corner'")
    settings = settings if settings is not None else SteadySettings()
    configs = [_point_config(cfg, p, source) for p in points]  # every point checked before any run
    rows = []
    for point, pcfg in zip(points, configs):
        bearing = pcfg.bearing()
        bearing = bearing.with_flat_ends() if end == "corner" else bearing
        sim = pcfg.simulation
        if print_points:
            n = settings.seeds
            print(
                f"[line {point.line}] {point.shaft_speed_rpm:g} rpm, {point.radial_load_N:g} N: settled run "
                f"({n} seed{'s' if n != 1 else ''}) ...",
                flush=True,
            )
        result = simulate_steady(
            bearing,
            pcfg.operating_point(),
            settings.replace(rtol=sim.rtol, atol=sim.atol, max_steps=sim.max_steps, solver=sim.solver),
        )
        s = summarise_steady(result)
        est = s.get("cage_speed_rpm") or {}
        measured = point.cage_speed_rpm
        value, lo, hi = (est.get(k) for k in ("value", "ci95_low", "ci95_high"))

        def rel(v):
            return None if v is None or not math.isfinite(v) else (v - measured) / measured

        row = {
            "line": point.line,
            "shaft_speed_rpm": point.shaft_speed_rpm,
            "radial_load_N": point.radial_load_N,
            "measured_cage_speed_rpm": measured,
            "model_cage_speed_rpm": {"value": value, "ci95_low": lo, "ci95_high": hi},
            "relative_error": rel(value),
            "relative_error_ci95_low": rel(lo),
            "relative_error_ci95_high": rel(hi),
            "measurement_inside_ci": None if lo is None or hi is None else bool(lo <= measured <= hi),
            "kinematic_cage_speed_rpm": s["kinematic_cage_speed_rpm"],
            "cage_slip": (s.get("cage_slip") or {}).get("value"),
            "settled": s["settled"],
            "settle_time_ms": s["settle_time_ms"],
            "window_ms": s["window_ms"],
            "seeds": s["seeds"],
            "status": s["status"],
        }
        rows.append(row)
        if on_point is not None:
            on_point(row)
    return rows
