"""Verification of a found design: the design and the reference re-simulated from the skid
start with seeds the search never used, at every operating point (docs/model.md 17).

The search uses seeds 0 .. seeds - 1; the verification `verify_seeds` seeds numbered from
`verify_first_seed` with windows of `verify_window_revs` revolutions. Each design's row holds
mean, p95, peak and tail PV over contact time and the corner-contact share with their 95 %
intervals, the corner margin, and the corner-contact risk per cage revolution with its bounds
(`jaxbearing.run.corner_risk`); `tail_verification` says whether that risk is bounded at the
user's level at every operating point.
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from jaxbearing.design import Statistic
from jaxbearing.flange import variables_from_array
from jaxbearing.run import Estimate, revolutions_needed

from ._evaluate import in_shared_pool, operating_points, settled_metrics
from ._problem import PV_SCALE, DesignProblem
from ._settings import SteadySettings


def _estimates(m, statistic: Statistic = Statistic.MEAN) -> dict:
    """One design's verification row: the issue's `mean_pv`, `p95_pv` [Pa m/s, SI] and
    `corner_contact_share`, each as value / ci95_low / ci95_high / n, and the same in the
    engineering units the documentation and the CLI print (GPa m/s, mm); the objective of
    `statistic` under its own key (`Statistic.key`: GPa m/s, or W for friction power)."""
    st = m.statistics
    nothing = Estimate(np.nan, np.nan, np.nan, 0)
    return {
        "mean_pv": _scaled(m.mean_pv, 1.0) | {"unit": "Pa m/s"},
        "p95_pv": _scaled(m.p95_pv, 1.0) | {"unit": "Pa m/s"},
        "mean_pv_GPa_m_s": _scaled(m.mean_pv),
        "p95_pv_GPa_m_s": _scaled(m.p95_pv),
        statistic.key: _scaled(m.objective, statistic.shown[0]),
        # the expected largest PV of a cage revolution (what the "peak" statistic aims at)
        "peak_pv_GPa_m_s": _scaled(nothing if st is None else st.flange_pv_Pa_m_s.max),
        # the mean of the worst 5 % of PV over contact time (the "tail" statistic)
        "tail_pv_GPa_m_s": _scaled(nothing if st is None else st.flange_pv_contact_time_Pa_m_s.tail95),
        "corner_contact_share": m.corner_contact_share.as_dict(),
        # what the faces are designed for besides PV (docs/model.md 5.5): total flange friction
        # power, the largest flash temperature rise of a contact event (mean per revolution),
        # and the film parameter Lambda (its 5th percentile over contact time)
        "friction_power_W": _scaled(nothing if st is None else st.flange_friction_power_W.total, 1.0),
        "flash_temperature_K": _scaled(nothing if st is None else st.flange_flash_temperature_K.max, 1.0),
        "film_parameter_p05": _scaled(nothing if st is None else st.film_parameter.p05, 1.0),
        "corner_margin_mm": _scaled(m.corner_margin, 1e-3),
        # the margin on the upper 95 % prediction bound of one revolution's largest contact radius
        "corner_margin_bound_mm": float(m.corner_margin_bound) * 1e3,
        # how far zero corner contact in these seeds bounds the tail (upper 95 % bounds)
        "corner_contact_bound": None if st is None else st.corner_contact_bound.as_dict(),
        # the probability per revolution of reaching the corner, with its bounds (`run.corner_risk`)
        "corner_risk": None if st is None or st.corner_risk is None else st.corner_risk.as_dict(),
        "settled": m.settled,
        "seeds": m.seeds,
    }


def _scaled(est: Estimate, unit: float = PV_SCALE) -> dict:
    """`est` divided by `unit`, as {"value", "ci95_low", "ci95_high", "n"} (None for NaN)."""
    d = est.as_dict()
    return {k: v if k == "n" or v is None else v / unit for k, v in d.items()}


@in_shared_pool
def verification(problem: DesignProblem, settings: SteadySettings, design, reference) -> dict:
    """The found design and the reference design re-simulated from the skid start with seeds
    the search never used (module docstring), at every operating point: both designs' points'
    seeds members of one call of the steady-running engine."""
    out = {
        "seeds": list(range(settings.verify_first_seed, settings.verify_first_seed + settings.verify_seeds))
    }
    ops = operating_points(problem)
    designs = [variables_from_array(jnp.asarray(x)) for x in (reference, design)]
    metrics = settled_metrics(
        problem,
        settings,
        list(range(len(ops))) * 2,
        [d for d in designs for _ in ops],
        verification=True,
        first_seed=settings.verify_first_seed,
    )
    for i, name in enumerate(("reference", "optimum")):
        rows = [_estimates(m, settings.statistic) for m in metrics[i * len(ops) : (i + 1) * len(ops)]]
        out[name] = rows[0] if len(rows) == 1 else {"per_operating_point": rows}
    refs = out["reference"].get("per_operating_point", [out["reference"]])
    opts = out["optimum"].get("per_operating_point", [out["optimum"]])

    def lower(key: str) -> list[bool]:  # per point: the optimum's interval below the reference's
        return [
            bool(
                None not in (r[key]["ci95_low"], o[key]["ci95_high"])
                and o[key]["ci95_high"] < r[key]["ci95_low"]
            )
            for r, o in zip(refs, opts)
        ]

    # at every operating point (the whole envelope)
    out["mean_pv_lower_disjoint"] = all(lower("mean_pv_GPa_m_s"))
    out["objective_lower_disjoint"] = all(lower(settings.statistic.key))
    if len(ops) > 1:
        out["mean_pv_lower_disjoint_per_operating_point"] = lower("mean_pv_GPa_m_s")
        out["objective_lower_disjoint_per_operating_point"] = lower(settings.statistic.key)
    # "not worse": the optimum's interval not wholly on the wrong side of the reference's
    out["friction_power_not_worse"] = all(
        _not_worse(r["friction_power_W"], o["friction_power_W"], higher_is_better=False)
        for r, o in zip(refs, opts)
    )
    out["film_parameter_not_worse"] = all(
        _not_worse(r["film_parameter_p05"], o["film_parameter_p05"], higher_is_better=True)
        for r, o in zip(refs, opts)
    )
    out["optimum_corner_contacts"] = any((o["corner_contact_share"].get("value") or 0.0) > 0 for o in opts)
    for name in ("reference", "optimum"):  # the weakest bound over the operating points
        rows = out[name].get("per_operating_point", [out[name]])
        bounds = [r["corner_contact_bound"] for r in rows if r.get("corner_contact_bound")]
        if bounds:
            out[f"{name}_corner_contact_per_revolution_upper95"] = max(
                b["per_revolution_upper95"] for b in bounds
            )
    out["tail"] = tail_verification(opts, settings.corner_risk_level)
    return out


def _not_worse(reference: dict, optimum: dict, *, higher_is_better: bool) -> bool:
    """Whether the optimum's 95 % interval is not wholly on the worse side of the reference's
    (unknown intervals count as not worse: nothing shows them worse)."""
    if None in (
        reference.get("ci95_low"),
        reference.get("ci95_high"),
        optimum.get("ci95_low"),
        optimum.get("ci95_high"),
    ):
        return True
    if higher_is_better:
        return bool(optimum["ci95_high"] >= reference["ci95_low"])
    return bool(optimum["ci95_low"] <= reference["ci95_high"])


def tail_verification(rows: list[dict], level: float) -> dict:
    """Whether the verification bounds the found design's corner-contact risk at `level` per
    cage revolution at every operating point: the largest upper bound of `run.corner_risk` over
    the points (one-sided 95 % or more), `verified` when it is at most `level`; else the design
    is unverified in the tail, and `revolutions_needed` says how many revolutions per point
    without corner contact would bound it by counting alone."""
    risks = [r.get("corner_risk") for r in rows]
    uppers = [r["upper"] if r and r.get("upper") is not None else 1.0 for r in risks]
    upper = max(uppers) if uppers else 1.0
    return {
        "level_per_revolution": float(level),
        "upper_per_revolution": float(upper),
        "methods": [r.get("method") if r else None for r in risks],
        "revolutions_per_point": [r.get("revolutions") if r else 0 for r in risks],
        "verified": bool(upper <= level),
        "revolutions_needed": revolutions_needed(level),
    }
