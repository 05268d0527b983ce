"""The optimiser's own TOML file (`optimise run --bounds FILE`): its sections and keys in
engineering units, read into a flat dict with each value's type checked; the ranges are checked
where the settings are used (`Bounds`, `DesignProblem`, the steady search's settings)."""

from __future__ import annotations

import math
import tomllib

from jaxbearing import UserInputError

#: keys of the optional optimiser TOML file (engineering units), with their meaning
OPTIMISE_TOML_KEYS = {
    "bounds": (
        "end_radius_mm",
        "layback_angle_deg",
        "axial_clearance_mm",
        "end_offset_mm",
        "corner_radius_mm",
        "rib_curvature_per_m",
        "rib_tangent_height_mm",
        "flange_height_mm",
    ),
    "constraints": (
        "min_clearance_mm",
        "flange_load_N",
        "min_film_parameter",
        "max_flash_temperature_K",
        "max_friction_power_W",
    ),
    "envelope": (
        "speeds_rpm",
        "loads_N",
        "weights",
        "aggregate",
        "temperature_GPa_m_s",
        "skip_weight",
        "recheck_every",
        "uncertain_constants",
    ),
    "search": (
        "profile",
        "objective",
        "starts",
        "iterations",
        "learning_rate",
        "duration_ms",
        "rtol",
        "atol",
        "seeds",
        "window_revs",
        "settle",
        "gradient_window_ms",
        "estimator",
        "corner_margin_mm",
        "corner_constraint",
        "choose",
        "clearance_step_mm",
        "statistic",
        "verify_seeds",
        "corner_risk_level",
        "workers",
    ),
}


def load_optimise_toml(path: str) -> dict:
    """Read the optimiser's own small TOML file:

        [bounds]       end_radius_mm = [60, 120], layback_angle_deg = [1.0, 2.0],
                       axial_clearance_mm = [0.10, 0.30]; a profile search (any of these, or
                       [search] profile = true): end_offset_mm, corner_radius_mm,
                       rib_curvature_per_m, rib_tangent_height_mm, flange_height_mm
        [constraints]  min_clearance_mm = 0.0, flange_load_N = 100; steady, off unless given:
                       min_film_parameter (Lambda), max_flash_temperature_K,
                       max_friction_power_W
        [envelope]     speeds_rpm = [...], loads_N = [...], weights = [...],
                       aggregate = "max" | "mean", temperature_GPa_m_s = 0.1,
                       skip_weight = 1e-3, recheck_every = 3 (steady: the active set),
                       uncertain_constants = ["lubricant.traction_d", ...] (steady: every
                       point also at every corner of these constants' ranges)
        [search]       profile = true | false, objective = "steady" | "startup", starts, iterations, learning_rate,
                       rtol; steady: seeds, window_revs, settle, gradient_window_ms, estimator,
                       corner_margin_mm, corner_constraint, choose, clearance_step_mm, statistic,
                       verify_seeds, corner_risk_level, workers;
                       startup: duration_ms, atol

    Returns a flat dict {key: value}; unknown sections or keys raise UserInputError."""
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except OSError as exc:
        raise UserInputError(f"optimise file {path}: cannot read: {exc.strerror or exc}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise UserInputError(f"optimise file {path}: invalid TOML: {exc}") from None
    out = {}
    for section, table in data.items():
        if section not in OPTIMISE_TOML_KEYS or not isinstance(table, dict):
            raise UserInputError(
                f"optimise file {path}: unknown section [{section}] (valid: {', '.join(OPTIMISE_TOML_KEYS)})"
            )
        for key, value in table.items():
            if key not in OPTIMISE_TOML_KEYS[section]:
                raise UserInputError(
                    f"optimise file {path}: unknown key {section}.{key} "
                    f"(valid: {', '.join(OPTIMISE_TOML_KEYS[section])})"
                )
            out[key] = _checked_toml_value(path, f"{section}.{key}", key, value)
    return out


_PAIRS = OPTIMISE_TOML_KEYS["bounds"]
_LISTS = ("speeds_rpm", "loads_N", "weights")
_TEXTS = ("aggregate", "objective", "estimator", "statistic", "corner_constraint", "choose")
_INTS = ("starts", "iterations", "seeds", "window_revs", "verify_seeds", "workers", "recheck_every")
#: most values of an envelope list
_MAX_LIST = 1000


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _checked_toml_value(path, name: str, key: str, value):
    """The value of one optimiser-file key, of the right type (ranges are checked where the
    settings are used); one-line UserInputError naming the file and key otherwise."""

    def bad(expected: str):
        return UserInputError(f"optimise file {path}: {name} = {value!r}: expected {expected}")

    if key in _PAIRS:
        if not (isinstance(value, list) and len(value) == 2 and all(_is_number(v) for v in value)):
            raise bad("[lower, upper] (two numbers)")
        if not all(math.isfinite(v) for v in value):
            raise bad("two finite numbers")
    elif key in _LISTS:
        if not (
            isinstance(value, list) and 1 <= len(value) <= _MAX_LIST and all(_is_number(v) for v in value)
        ):
            raise bad(f"a list of 1 to {_MAX_LIST} numbers")
        if not all(math.isfinite(v) for v in value):
            raise bad("finite numbers")
    elif key in _TEXTS:
        if not isinstance(value, str):
            raise bad("a string")
    elif key in _INTS:
        if isinstance(value, bool) or not isinstance(value, int):
            raise bad("an integer")
    elif key == "uncertain_constants":
        if not (isinstance(value, list) and value and all(isinstance(v, str) for v in value)):
            raise bad("a list of configuration keys (strings)")
    elif key == "profile":
        if not isinstance(value, bool):
            raise bad("true or false")
    elif key == "settle":
        if value != "auto" and not _is_number(value):
            raise bad('"auto" or a settling time in ms')
    elif key == "clearance_step_mm":
        if value != "auto" and not _is_number(value):
            raise bad('"auto" or a half-step in mm')
    elif not _is_number(value):
        raise bad("a number")
    return value
