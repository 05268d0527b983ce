"""`optimise run`: the merged settings (command line over the TOML file over the defaults)
turned into the design problem and the search settings, each value checked in one line."""

from __future__ import annotations

import math

from jaxbearing import UserInputError


def _floats(text: str, name: str) -> list[float]:
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise UserInputError(f"{name} = {text!r}: expected comma-separated numbers") from None
    if not vals or not all(math.isfinite(v) for v in vals):
        raise UserInputError(f"{name} = {text!r}: expected finite comma-separated numbers")
    return vals


def _pair(text: str | None, name: str):
    if text is None:
        return None
    v = _floats(text, name)
    if len(v) != 2:
        raise UserInputError(f"{name} = {text!r}: expected LOWER,UPPER")
    return v


#: the profile variables' bounds options (beyond R_end, theta_f, Delta_bf), by TOML key
PROFILE_OPTIONS = {
    "end_offset_mm": "end offset e [mm]",
    "corner_radius_mm": "corner radius R_cor [mm]",
    "rib_curvature_per_m": "rib curvature 1/R_rib [1/m] (0: the cone)",
    "rib_tangent_height_mm": "rib tangent height h_t [mm]",
    "flange_height_mm": "flange height H_rf [mm]",
}

#: defaults of the search settings that are not `SteadySettings` fields (per objective where
#: they differ); the help strings below and `problem_from_settings` both read them
SEARCH_DEFAULTS = {
    # profile: the steady search over the eight profile variables, as examples/optimise_profile.toml
    # (one start of three: docs/how-to/profile-design.md, "The default search at full size")
    "starts": {"steady": 2, "startup": 4, "profile": 1},
    # steady: 4, as examples/optimise.toml; the best design of the runs with more came by the
    # third iteration (docs/how-to/design-search.md)
    "iterations": {"steady": 4, "startup": 20, "profile": 3},
    "learning_rate": 0.08,
    "rtol": 1e-3,
    "atol": 1e-6,
    "temperature_GPa_m_s": 0.1,
    "min_clearance_mm": 0.0,
    "aggregate": "max",
    "objective": "steady",
}
OBJECTIVES = ("steady", "startup")
AGGREGATES = ("max", "mean")


def _settings(args) -> dict:
    """Merge the optional TOML file with the command-line options (options win)."""
    from ._toml import load_optimise_toml

    s = load_optimise_toml(args.bounds_file) if args.bounds_file else {}
    for key, value in (
        ("end_radius_mm", _pair(args.end_radius_mm, "--end-radius-mm")),
        ("layback_angle_deg", _pair(args.layback_deg, "--layback-deg")),
        ("axial_clearance_mm", _pair(args.clearance_mm, "--clearance-mm")),
        *((key, _pair(getattr(args, key), "--" + key.replace("_", "-"))) for key in PROFILE_OPTIONS),
        ("profile", args.profile),
        ("min_clearance_mm", args.min_clearance_mm),
        ("flange_load_N", args.flange_load_N),
        ("speeds_rpm", _floats(args.speeds_rpm, "--speeds-rpm") if args.speeds_rpm else None),
        ("loads_N", _floats(args.loads_N, "--loads-N") if args.loads_N else None),
        ("weights", _floats(args.weights, "--weights") if args.weights else None),
        (
            "uncertain_constants",
            [k.strip() for k in args.uncertain_constants.split(",")] if args.uncertain_constants else None,
        ),
        ("aggregate", args.aggregate),
        ("objective", args.objective),
        ("starts", args.starts),
        ("iterations", args.iterations),
        ("seeds", args.seeds),
        ("window_revs", args.window_revs),
        ("settle", args.settle),
        ("gradient_window_ms", args.gradient_window_ms),
        ("estimator", args.estimator),
        ("corner_margin_mm", args.corner_margin_mm),
        ("clearance_step_mm", args.clearance_step_mm),
        ("statistic", args.statistic),
        ("corner_constraint", args.corner_constraint),
        ("choose", args.choose),
        ("skip_weight", args.skip_weight),
        ("recheck_every", args.recheck_every),
        ("verify_seeds", args.verify_seeds),
        ("corner_risk_level", args.corner_risk_level),
        ("min_film_parameter", args.min_film_parameter),
        ("max_flash_temperature_K", args.max_flash_temperature_K),
        ("max_friction_power_W", args.max_friction_power_W),
        ("workers", args.workers),
        ("learning_rate", args.learning_rate),
        ("duration_ms", args.duration_ms),
        ("rtol", args.rtol),
        ("atol", args.atol),
    ):
        if value is not None:
            s[key] = value
    return s


def _positive(s: dict, key: str, default, kind=float, strict=True):
    v = s.get(key, default)
    try:
        v = kind(v)
    except (TypeError, ValueError):
        raise UserInputError(f"{key} = {v!r}: expected a {kind.__name__}") from None
    if not (math.isfinite(v) and (v > 0 if strict else v >= 0)):
        raise UserInputError(f"{key} = {v}: must be {'> 0' if strict else '>= 0'}")
    return v


def _clearance_step(s: dict):
    """`SteadySettings.clearance_step` from `clearance_step_mm`: "auto" (the default) or >= 0 mm."""
    v = s.get("clearance_step_mm", "auto")
    return "auto" if v == "auto" else _positive(s, "clearance_step_mm", 0.0, strict=False) * 1e-3


def constant_corners(cfg, s: dict):
    """(name, bearing) of every corner of `uncertain_constants`' ranges and the nominal point
    (`jaxbearing.design.robustness_corners`), or None without; only the steady objective runs
    them (one line otherwise)."""
    keys = s.get("uncertain_constants")
    if not keys:
        return None
    if objective_of(s) != "steady":
        raise UserInputError(
            f"uncertain_constants = {keys}: only the steady objective runs a bearing per operating point "
            "(objective = 'steady')"
        )
    from jaxbearing.design import robustness_corners

    try:
        _, _, corners = robustness_corners(cfg, keys)
    except UserInputError as exc:
        raise UserInputError(f"uncertain_constants: {exc}") from None
    return [(corner.name, c.bearing()) for corner, c in corners]


def bounds_of(s: dict):
    """The search box from merged settings: `ProfileBounds` when `profile` is set or a profile
    variable's bounds are given, else `Bounds` (R_end, theta_f, Delta_bf)."""
    from ._bounds import Bounds, ProfileBounds, box_from_engineering

    profile = bool(s.get("profile")) or any(s.get(key) is not None for key in PROFILE_OPTIONS)
    kind = ProfileBounds if profile else Bounds
    return box_from_engineering(kind, {v.key: s.get(v.key) for v in kind.TABLE})


def problem_from_settings(bearing, op, s: dict, constant_corners=None):
    """DesignProblem and search options from merged settings (engineering units);
    `constant_corners`: see `make_problem`."""
    from ._problem import DEFAULT_DURATION, make_problem

    bounds = bounds_of(s)
    problem = make_problem(
        bearing,
        op,
        bounds=bounds,
        speeds_rpm=s.get("speeds_rpm"),
        loads_N=s.get("loads_N"),
        weights=s.get("weights"),
        constant_corners=constant_corners,
        duration=_positive(s, "duration_ms", DEFAULT_DURATION * 1e3) * 1e-3,
        flange_load=_positive(s, "flange_load_N", 100.0),
        min_clearance=_positive(s, "min_clearance_mm", SEARCH_DEFAULTS["min_clearance_mm"], strict=False)
        * 1e-3,
        aggregate=s.get("aggregate", SEARCH_DEFAULTS["aggregate"]),
        temperature=_positive(s, "temperature_GPa_m_s", SEARCH_DEFAULTS["temperature_GPa_m_s"]),
        rtol=_positive(s, "rtol", SEARCH_DEFAULTS["rtol"]),
        atol=_positive(s, "atol", SEARCH_DEFAULTS["atol"]),
    )
    objective = objective_of(s)
    kind = "profile" if objective == "steady" and problem.num_variables != 3 else objective
    options = dict(
        num_starts=int(_positive(s, "starts", SEARCH_DEFAULTS["starts"][kind], int)),
        num_iterations=int(_positive(s, "iterations", SEARCH_DEFAULTS["iterations"][kind], int)),
        learning_rate=_positive(s, "learning_rate", SEARCH_DEFAULTS["learning_rate"]),
    )
    return problem, options


def objective_of(s: dict) -> str:
    objective = s.get("objective", SEARCH_DEFAULTS["objective"])
    if objective not in OBJECTIVES:
        raise UserInputError(f"objective = {objective!r}: must be 'steady' or 'startup'")
    return objective


def steady_settings_from(s: dict):
    """SteadySettings from merged settings (engineering units)."""
    from ._settings import SteadySettings

    st = SteadySettings()
    settle = s.get("settle", st.settle)
    if settle != "auto":
        settle = _positive({"settle": settle}, "settle", 0.0, strict=False)
    return SteadySettings(
        seeds=int(_positive(s, "seeds", st.seeds, int)),
        window_revs=int(_positive(s, "window_revs", st.window_revs, int)),
        settle=settle,
        gradient_window=_positive(s, "gradient_window_ms", st.gradient_window * 1e3) * 1e-3,
        estimator=s.get("estimator", st.estimator),
        corner_margin=_positive(s, "corner_margin_mm", st.corner_margin * 1e3, strict=False) * 1e-3,
        rtol=_positive(s, "rtol", SEARCH_DEFAULTS["rtol"]),
        workers=int(_positive(s, "workers", st.workers, int, strict=False)),
        verify_seeds=int(_positive(s, "verify_seeds", st.verify_seeds, int)),
        clearance_step=_clearance_step(s),
        statistic=s.get("statistic", st.statistic),
        corner_constraint=s.get("corner_constraint", st.corner_constraint),
        choose=s.get("choose", st.choose),
        skip_weight=_positive(s, "skip_weight", st.skip_weight, strict=False),
        recheck_every=int(_positive(s, "recheck_every", st.recheck_every, int)),
        corner_risk_level=float(s.get("corner_risk_level", st.corner_risk_level)),
        min_film_parameter=_optional_positive(s, "min_film_parameter"),
        max_flash_temperature=_optional_positive(s, "max_flash_temperature_K"),
        max_friction_power=_optional_positive(s, "max_friction_power_W"),
    )


def _optional_positive(s: dict, key: str) -> float | None:
    """A limit that is off unless given (> 0 when given)."""
    return None if s.get(key) is None else _positive(s, key, None)


def check_start_design(cfg, problem) -> None:
    """Refuse, in one line naming the keys, a start design whose actual axial clearance
    Lambda_bf is negative (the rollers do not fit between the flanges: no run of it means
    anything, and the search would start from a jammed bearing)."""
    from jaxbearing.flange import design_zone

    bearing = cfg.bearing()
    lam = float(design_zone(bearing, problem.flange_load).actual_axial_clearance)
    if not lam >= 0:
        raise UserInputError(
            f"flange.axial_clearance_mm = {cfg['flange.axial_clearance_mm']:g} mm with "
            f"roller.end_radius_mm = {cfg['roller.end_radius_mm']:g} mm and flange.layback_angle_deg = "
            f"{cfg['flange.layback_angle_deg']:g} deg: the start design's actual axial clearance "
            f"Lambda_bf = {lam * 1e3:+.4f} mm is negative (the rollers do not fit between the "
            "flanges); start from a design with Lambda_bf >= 0 (see `jaxbearing zone`)"
        )


def _provenance(cfg, s: dict, steady) -> dict:
    """What produced result.json (`jaxbearing.io.provenance`): version, command line, the full
    configuration in engineering units, the merged optimiser settings, the seeds; and the unit
    convention of its keys."""
    from jaxbearing.io import provenance

    seeds = None
    if steady is not None:
        seeds = {
            "search": list(range(steady.seeds)),
            "verification": list(
                range(steady.verify_first_seed, steady.verify_first_seed + steady.verify_seeds)
            ),
        }
    else:
        seeds = {"search": [0]}  # every evaluation starts from Perturbation(seed=0)
    meta = provenance(cfg, seeds=seeds)
    meta["optimiser_settings"] = dict(s)
    meta["units"] = (
        "in each key's suffix: _mm, _deg, _N, _rpm, _ms, _s, _GPa_m_s (GPa m/s), _Pa_m_s; "
        "margins in mm; design variables R_end [mm], theta_f [deg], Delta_bf [mm]; others dimensionless"
    )
    return meta
