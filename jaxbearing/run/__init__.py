"""Runs of the model: the solve, the simulation result, statistics, settled running, plots.

- `solve` (pure, jit/vmap/grad-able diffrax integration of the scaled state), `simulate`
  (compiled, with wall times and a `SimulationResult`), `simulation_result`,
  `flange_functionals` (smooth peak PV and contact heights for gradients), `Perturbation`
  (seeded initial roller scatter), `initial_state`, `skid_start` (the speeds of steady running,
  `STARTS`), `smooth_functionals`, `result_code` and
  `RESULT_NAMES` (the outcome code of a solve), `SolveProgress` (the text progress meter
  inside a solve) and `HostProgress` (the same from the calling process: cacheable programs);
- statistics: `contact_events`, `summarise`, `film_statistics` (film over contact time,
  `FILM_KEYS`; a sample is contact above `CONTACT_THRESHOLD`), `friction_power_statistics`
  (time-mean friction power per flange and in total, `FRICTION_POWER_KEYS`); of settled running with 95 %
  confidence intervals as a typed object, `SettledStatistics` (fields of `Estimate`s, groups of `Reductions`:
  `PerEvent`, `ContactRadius`, `ContactTimePV`, `CornerShare`, `FrictionPower`; `SteadyResult.statistics()`,
  `settled_statistics`; its summary block `steady_statistics`), `revolution_statistics`, `confidence_intervals`,
  `batch_means`, `student_t_interval`, `Estimate`, `tail_mean` (the mean above the
  `TAIL_LEVEL` quantile); how often the contact reached the corner,
  with upper bounds: `corner_contact_bound`, `upper_probability_bound`; the prediction bound
  of one revolution's largest contact radius: `max_contact_radius_bound`; the corner-contact
  risk per revolution with its confidence bounds (counting, a generalised Pareto tail with a
  profile-likelihood interval, or a normal model from few revolutions): `corner_risk`
  (`CornerRisk`, `TailFit`, `NormalTail`, `ConditionalPeak`), from a settled run
  `steady_corner_risk` (or its members' statistics, `corner_risk_of_revolutions`; in the summary
  as `corner_risk`), its data `revolution_maxima` / `steady_revolution_maxima`
  (`RevolutionMaxima`); the contact radius kept below at a risk level with a confidence,
  `tolerance_bound` (`tolerance_factor`);
  `revolutions_needed`, `clopper_pearson`, `cluster_design_effect`;
- settled running: `simulate_steady` (settling detection over cage revolutions, a window,
  seeds), `simulate_steady_points` (the same at several operating points, one engine call),
  `summarise_steady`; the steady-running engine under it, `settle_members` (many
  `Member`s, each a case and a seed, with one `SteadySettings`: one after another, one process per
  core, or vmapped on accelerators, `STRATEGIES`, `choose_strategy`, `stack_trees`; an
  `EngineRun`; the members' starts resolved in one step, `resolve_starts`; the one member
  dispatcher, `map_members`, which the gradient estimators use too) and `window_statistics`
  (`revolution_statistic_keys`); `solve_from` / `prepare_from` (continue from any state),
  `scaled_diffeqsolve` (diffrax's integration of the scaled state that `solve` and `solve_from`
  run, for callers that build their own programs around it); `SteadySettings`, the one
  definition of every setting of settled running and its defaults, with the settling modes
  `SettleAuto`, `SettleFixed`, `SettleOff` (`settling` maps the command line's and the TOML
  files' text onto them); a member's program speaks `Request` and `Answer` in its `Phase`s; `MemberProgress`
  (a `with` block: members settled of the total, elapsed, an estimate of what remains, every
  30 s while the engine runs);
- `plot_run`: the figures of one run;
- against measurements: `model_cage_speeds` (a settled run at every measured operating point,
  the relative error with its interval) and its figure `plot_measured`;
- speed: `raceway_normal_norm` (the error norm of settled windows, `prepare_from`; `solve`'s
  is `TRANSIENT_ERROR_NORM`), `enable_compilation_cache` (JAX's
  persistent cache in a user directory, `$JAXBEARING_CACHE_DIR`; on at import),
  `compiled_program` (a program compiled once per process and traced once per machine:
  `jax.export` artefacts in `program_cache_dir`; `checks_without_host_callbacks` traces
  equinox's run-time checks so that such a program can be stored), `start_cache_dir` (skid
  starts solved once per machine, data-only files read back bit for bit),
  `parallel_map` / `simulate_ensemble` (independent cases, one process per core),
  `as_completed_map` (the same, each result as it finishes: the sweep's batches),
  `shared_workers` (one pool for every `parallel_map` of a block).

Design metrics and gradients through these runs live one layer up, in `jaxbearing.design`.

May import: `jaxbearing._errors`, `contact`, `geometry`, `io`, `flange`, `forces`, `dynamics`.
"""

from ._compile_cache import (
    CACHE_ENV,
    checks_without_host_callbacks,
    compiled_program,
    enable_compilation_cache,
    program_cache_dir,
)
from ._corner_risk import (
    ConditionalPeak,
    CornerRisk,
    RevolutionMaxima,
    corner_risk,
    corner_risk_of_revolutions,
    revolution_maxima,
)
from ._dispatch import EngineRun, settle_members
from ._engine import STRATEGIES, choose_strategy, stack_trees
from ._ensemble import as_completed_map, available_cpus, parallel_map, shared_workers, simulate_ensemble
from ._initial import STARTS, Perturbation, SkidStart, initial_state, skid_start
from ._measured import model_cage_speeds
from ._member import Answer, Member, Phase, Request, SeedRun
from ._member_progress import MemberProgress
from ._normal_tail import NormalTail, tolerance_bound, tolerance_factor
from ._plots import plot_measured, plot_run
from ._progress import HostProgress, SolveProgress
from ._proportions import CORNER_RISK_CONFIDENCE, clopper_pearson, cluster_design_effect, revolutions_needed
from ._result import (
    RESULT_NAMES,
    SimulationResult,
    Solution,
    result_code,
    simulation_result,
    smooth_functionals,
)
from ._settings import (
    SAVES_PER_REV,
    SETTLE_CAP_MS,
    SETTLE_TOLERANCE,
    SettleAuto,
    SettleFixed,
    SettleOff,
    Settling,
    SteadySettings,
    settling,
    steady_settings,
)
from ._settle import (
    SteadyResult,
    simulate,
    simulate_steady,
    simulate_steady_points,
    summarise,
    summarise_steady,
)
from ._settled_statistics import (
    ContactRadius,
    ContactTimePV,
    CornerShare,
    FrictionPower,
    PerEvent,
    Reductions,
    SettledStatistics,
    settled_statistics,
    steady_statistics,
)
from ._simulate import SolveArgs, flange_functionals, scaled_diffeqsolve, scaled_field, solve
from ._solve_from import prepare_from, solve_from
from ._start_cache import start_cache_dir
from ._starts import map_members, resolve_starts
from ._statistics import (
    TAIL_LEVEL,
    CornerCount,
    Estimate,
    PredictionBound,
    batch_means,
    confidence_intervals,
    corner_contact_bound,
    max_contact_radius_bound,
    revolution_statistic_keys,
    revolution_statistics,
    steady_corner_risk,
    steady_revolution_maxima,
    student_t_interval,
    tail_mean,
    upper_probability_bound,
    window_statistics,
)
from ._step_control import (
    DEFAULT_ERROR_NORM,
    ERROR_NORMS,
    RACEWAY_NORMAL_LOOSEN,
    ROTATION_LOOSEN,
    TRANSIENT_ERROR_NORM,
    TRANSIENT_RACEWAY_LOOSEN,
    TRANSIENT_ROTATION_LOOSEN,
    RacewayNormalNorm,
    raceway_normal_norm,
)
from ._summary import (
    CONTACT_THRESHOLD,
    FILM_KEYS,
    FRICTION_POWER_KEYS,
    contact_events,
    film_statistics,
    friction_power_statistics,
)
from ._tail_fit import MIN_TAIL_REVOLUTIONS, TailFit

__all__ = [
    "CONTACT_THRESHOLD",
    "SETTLE_CAP_MS",
    "SETTLE_TOLERANCE",
    "prepare_from",
    "as_completed_map",
    "available_cpus",
    "STARTS",
    "SkidStart",
    "FILM_KEYS",
    "FRICTION_POWER_KEYS",
    "RESULT_NAMES",
    "CACHE_ENV",
    "DEFAULT_ERROR_NORM",
    "ERROR_NORMS",
    "RACEWAY_NORMAL_LOOSEN",
    "ROTATION_LOOSEN",
    "TRANSIENT_ERROR_NORM",
    "TRANSIENT_RACEWAY_LOOSEN",
    "TRANSIENT_ROTATION_LOOSEN",
    "RacewayNormalNorm",
    "enable_compilation_cache",
    "compiled_program",
    "checks_without_host_callbacks",
    "program_cache_dir",
    "start_cache_dir",
    "parallel_map",
    "shared_workers",
    "raceway_normal_norm",
    "simulate_ensemble",
    "Estimate",
    "Perturbation",
    "SeedRun",
    "SimulationResult",
    "Solution",
    "SolveProgress",
    "HostProgress",
    "SteadyResult",
    "SolveArgs",
    "batch_means",
    "confidence_intervals",
    "contact_events",
    "film_statistics",
    "friction_power_statistics",
    "flange_functionals",
    "initial_state",
    "skid_start",
    "model_cage_speeds",
    "plot_measured",
    "plot_run",
    "result_code",
    "revolution_statistics",
    "scaled_field",
    "scaled_diffeqsolve",
    "simulate",
    "simulate_steady",
    "simulation_result",
    "smooth_functionals",
    "solve",
    "solve_from",
    "steady_statistics",
    "map_members",
    "resolve_starts",
    "settled_statistics",
    "SettledStatistics",
    "PerEvent",
    "Reductions",
    "ContactRadius",
    "ContactTimePV",
    "CornerShare",
    "FrictionPower",
    "CornerCount",
    "PredictionBound",
    "student_t_interval",
    "tail_mean",
    "TAIL_LEVEL",
    "corner_contact_bound",
    "max_contact_radius_bound",
    "upper_probability_bound",
    "CORNER_RISK_CONFIDENCE",
    "MIN_TAIL_REVOLUTIONS",
    "ConditionalPeak",
    "CornerRisk",
    "RevolutionMaxima",
    "TailFit",
    "clopper_pearson",
    "cluster_design_effect",
    "corner_risk",
    "corner_risk_of_revolutions",
    "revolution_maxima",
    "revolutions_needed",
    "steady_corner_risk",
    "steady_revolution_maxima",
    "tolerance_bound",
    "tolerance_factor",
    "NormalTail",
    "summarise",
    "summarise_steady",
    "EngineRun",
    "Member",
    "SteadySettings",
    "SettleAuto",
    "SettleFixed",
    "SettleOff",
    "Settling",
    "settling",
    "steady_settings",
    "SAVES_PER_REV",
    "Answer",
    "Request",
    "Phase",
    "MemberProgress",
    "STRATEGIES",
    "choose_strategy",
    "stack_trees",
    "settle_members",
    "simulate_steady_points",
    "revolution_statistic_keys",
    "window_statistics",
]
