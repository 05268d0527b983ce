"""The corner-contact risk estimate (`jaxbearing.run.corner_risk`, docs/model.md 16) on synthetic
per-revolution maxima whose exceedance probability is known in closed form: the counting bounds
against the Clopper-Pearson closed form, the revolution count of the rule of three, the
generalised Pareto fit against known (xi, sigma), the coverage of the bounds over replicates
(fixed seeds; the tolerance is binomial: an honest one-sided 95 % bound misses in at most 5 % of
replicates, and the test fails only beyond the 0.999 quantile of that count), input errors. And
the estimate on settled dynamics: members of the corner-risk study
(benchmarks/results/corner_risk_validation.json, raw per-revolution maxima) split into a few and
the rest."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from jaxbearing._errors import UserInputError
from jaxbearing.run import (
    MIN_TAIL_REVOLUTIONS,
    clopper_pearson,
    cluster_design_effect,
    corner_risk,
    revolution_maxima,
    revolutions_needed,
)
from jaxbearing.run._normal_tail import tolerance_bound, tolerance_factor

STUDY = Path(__file__).resolve().parents[1] / "benchmarks" / "results" / "corner_risk_validation.json"


def _misses_allowed(replicates: int, miss_rate: float = 0.05) -> int:
    """The 0.999 quantile of the number of misses of an honest bound over `replicates`."""
    return int(stats.binom.ppf(0.999, replicates, miss_rate))


def test_counting_is_clopper_pearson_for_one_member():
    """One member (no clusters): the bounds are the Clopper-Pearson beta quantiles of x of n."""
    x = np.full(120, 1.0)
    x[[3, 50, 51, 99]] = 2.0  # 4 of 120 beyond 1.5
    r = corner_risk(x, 1.5)
    assert r.method == "count" and r.exceedances == 4 and r.revolutions == 120
    assert r.probability == pytest.approx(4 / 120)
    assert r.upper == pytest.approx(stats.beta.ppf(0.95, 5, 116), rel=1e-12)
    assert r.lower == pytest.approx(stats.beta.ppf(0.05, 4, 117), rel=1e-12)
    assert clopper_pearson(0, 10) == (0.0, pytest.approx(1 - 0.05 ** (1 / 10)))


def test_not_enough_data_gives_the_rule_of_three():
    """No revolution at the corner, too few revolutions in contact for either model (or no
    spread): no extrapolation, the upper bound 1 - (1 - c)^(1/n)."""
    x = np.zeros((4, 10))
    x[0, :2] = [0.5, 0.7]  # two revolutions in contact: the normal model needs three
    r = corner_risk(x, 2.0, confidence=0.9)
    assert r.method == "not enough data" and r.probability == 0.0 and r.lower == 0.0
    assert r.upper == pytest.approx(1 - 0.1 ** (1 / 40), rel=1e-12)
    assert r.bounded_below(0.06) and not r.bounded_below(0.05)
    assert MIN_TAIL_REVOLUTIONS == 100
    flat = np.full((4, 50), 0.9)  # 200 revolutions, all alike: no spread to fit
    r = corner_risk(flat, 1.0)
    assert r.method == "not enough data" and r.upper == pytest.approx(1 - 0.05 ** (1 / 200))


def test_tolerance_factor_is_the_published_one():
    """The one-sided normal tolerance factor (noncentral t): Natrella (1963), Experimental
    Statistics, NBS Handbook 91, Table A-7: n = 10, 95 % confidence, 99 % and 90 % coverage
    3.981 and 2.355; n = 20, 99 %: 3.295."""
    assert tolerance_factor(10, 0.01, 0.95) == pytest.approx(3.981, abs=6e-4)
    assert tolerance_factor(10, 0.10, 0.95) == pytest.approx(2.355, abs=6e-4)
    assert tolerance_factor(20, 0.01, 0.95) == pytest.approx(3.295, abs=6e-4)


def test_normal_method_from_few_revolutions_covers_the_true_risk():
    """None at the corner and fewer than MIN_TAIL_REVOLUTIONS: the normal model. On normal
    maxima of known p = Phi(-3) (limit 3 sigma above the mean), 4 members x 4 revolutions, the
    upper bound lies below p in at most the nominal 5 % of 400 samples (binomial 0.999 tolerance:
    32); p^ is Phi(-k) of the sample's k; the tolerance bound at the level of p lies above the
    limit exactly when the risk bound exceeds it."""
    rng = np.random.default_rng(7)
    p_true = float(stats.norm.sf(3.0))
    misses, methods = 0, set()
    for _ in range(400):
        x = 1.0 + 0.1 * rng.standard_normal((4, 4))
        r = corner_risk(x, 1.3)
        methods.add(r.method)
        misses += r.upper < p_true
        if r.method == "count":  # a revolution beyond the limit (about 2 % of samples): counted
            continue
        assert r.probability == pytest.approx(stats.norm.sf(r.normal.k), rel=1e-12)
        assert r.lower <= r.probability <= r.upper
    assert methods == {"normal", "count"} and misses <= 32
    x = 1.0 + 0.1 * rng.standard_normal((4, 4))
    r = corner_risk(x, 1.3)
    # the exact tolerance factor is below its normal approximation: at the approximate bound's
    # level, the tolerance bound lies inside the limit
    assert r.upper < 0.5 and tolerance_bound(x, r.upper * 1.01, 0.95) < 1.3


@pytest.mark.parametrize("level, confidence", [(1e-3, 0.95), (1e-2, 0.95), (1e-4, 0.99), (0.05, 0.9)])
def test_revolutions_needed_is_the_closed_form(level, confidence):
    """n = ceil(ln(1 - c) / ln(1 - level)); with n clean revolutions the bound is at the level,
    with n - 1 above it."""
    n = revolutions_needed(level, confidence)
    assert n == math.ceil(math.log(1 - confidence) / math.log(1 - level))
    assert clopper_pearson(0, n, confidence)[1] <= level < clopper_pearson(0, n - 1, confidence)[1]
    if (level, confidence) == (1e-3, 0.95):
        assert n == 2995


def test_design_effect_of_clustered_counts():
    """All exceedances in one member of four: the between-member variance of the ratio
    estimator (closed form) over the binomial one, and wider bounds than independent counting."""
    counts, sizes = np.array([8, 0, 0, 0]), np.array([20, 20, 20, 20])
    p = 8 / 80
    var = 4 / 3 * np.sum((counts - p * sizes) ** 2) / 80**2
    assert cluster_design_effect(counts, sizes) == pytest.approx(var / (p * (1 - p) / 80))
    x = np.zeros((4, 20))
    x[0, :8] = 2.0
    clustered = corner_risk(x, 1.0)
    independent = clopper_pearson(8, 80)
    assert (
        clustered.design_effect > 1 and clustered.upper > independent[1] and clustered.lower < independent[0]
    )
    assert cluster_design_effect([0, 0], [5, 5]) == 1.0


def test_gpd_fit_recovers_known_shape_and_scale():
    """Maxima drawn from a GPD(xi, sigma) from 0: above u the excess is GPD(xi, sigma + xi u)
    (threshold stability; Coles 2001, sec. 4.2.2); the fit is within 4 standard errors
    (Fisher information: var xi ~ (1 + xi)^2 / k, var sigma ~ 2 sigma^2 (1 + xi) / k)."""
    rng = np.random.default_rng(7)
    for xi, sigma in ((-0.25, 1e-3), (0.1, 2e-3)):
        x = stats.genpareto.rvs(xi, scale=sigma, size=(8, 500), random_state=rng)
        r = corner_risk(x, 50 * sigma)
        assert r.method == "tail"
        t = r.tail
        k = t.exceedances
        assert k == math.ceil(0.15 * 4000)
        su = sigma + xi * t.threshold_m
        assert abs(t.shape - xi) < 4 * (1 + xi) / math.sqrt(k)
        assert abs(t.scale_m - su) < 4 * su * math.sqrt(2 * (1 + xi) / k)
        assert (t.endpoint_m == pytest.approx(t.threshold_m - t.scale_m / t.shape)) if t.shape < 0 else True


def test_counting_bounds_cover_at_the_nominal_rate():
    """200 replicates of 8 members x 25 revolutions of normal maxima, P(M > r) = 0.05: each
    one-sided bound misses in at most 5 % of replicates (binomial tolerance); and members with
    their own rates (beta-distributed around 0.05: dependent revolutions) are covered too."""
    rng = np.random.default_rng(2024)
    r = stats.norm.isf(0.05)
    reps = 200
    up = lo = 0
    for _ in range(reps):
        e = corner_risk(rng.standard_normal((8, 25)) + 10.0, r + 10.0)
        up += e.upper < 0.05
        lo += e.lower > 0.05
    assert up <= _misses_allowed(reps) and lo <= _misses_allowed(reps)
    up = 0
    for _ in range(reps):
        rates = rng.beta(0.5, 9.5, size=(8, 1))  # mean 0.05, strongly varying by member
        e = corner_risk((rng.random((8, 25)) < rates).astype(float), 0.5)
        up += e.upper < 0.05
    assert up <= _misses_allowed(reps)


def test_tail_bounds_cover_an_unseen_probability():
    """100 replicates of 4 members x 50 revolutions of beta(2, 5) maxima (a bounded tail, xi =
    -1/5), limit where P(M > r) = 0.002: two thirds of the replicates see no exceedance and
    extrapolate (method "tail"); the upper bound misses in at most 5 % of replicates
    (binomial tolerance), and the extrapolated bound is typically below the rule of three (here 0.011 against
    0.015: with 200 revolutions the tail fit adds little to counting).
    (The point estimate is not checked: given no exceedance it is biased low, 0 when the fitted
    tail ends below the limit.)"""
    rng = np.random.default_rng(12345)
    target = 0.002
    r = stats.beta.isf(target, 2, 5)
    reps = 100
    up, methods, tail_uppers = 0, [], []
    for _ in range(reps):
        e = corner_risk(stats.beta.rvs(2, 5, size=(4, 50), random_state=rng) * 4e-3, r * 4e-3)
        methods.append(e.method)
        up += e.upper < target
        if e.method == "tail":
            tail_uppers.append(e.upper)
            assert e.lower <= e.probability <= e.upper and e.upper <= 1
    assert methods.count("tail") > reps / 2
    assert up <= _misses_allowed(reps)
    assert np.median(tail_uppers) < 1 - 0.05 ** (1 / 200)  # the rule of three of 200 revolutions


def test_endpoint_below_the_limit_gives_zero_with_an_honest_bound():
    """Uniform maxima (a hard endpoint at 1) and a limit beyond it: the fitted tail ends below
    the limit (p^ = 0), the upper bound stays at or below the counting bound and the lower bound
    is 0."""
    rng = np.random.default_rng(3)
    e = corner_risk(rng.random((8, 100)), 1.2)
    assert e.method == "tail" and e.probability == 0.0 and e.lower == 0.0
    assert 0.0 <= e.upper <= e.counting_upper
    assert e.tail.endpoint_m < 1.2


def test_peak_pv_given_contact():
    """The expected peak PV of the revolutions that reached the corner, Student-t interval."""
    x = np.array([[1.0, 2.0, 1.0, 2.0], [2.0, 1.0, 1.0, 1.0]])
    pv = np.array([[5.0, 40.0, 6.0, 50.0], [60.0, 5.0, 5.0, 5.0]])
    e = corner_risk(x, 1.5, peak_pv=pv)
    peak = e.peak_pv_given_contact
    assert peak.revolutions == 3 and peak.value == pytest.approx(50.0)
    half = stats.t.ppf(0.975, 2) * 10.0 / math.sqrt(3)
    assert (peak.low, peak.high) == (pytest.approx(50 - half), pytest.approx(50 + half))
    assert json.dumps(e.as_dict())


def test_revolution_maxima_from_window_statistics():
    """Revolutions without contact count as 0; revolutions without a cage speed are left out."""
    per_rev = {
        "cage_speed_rpm": np.array([8000.0, np.nan, 8000.0]),
        "contact_radius_m.max_in_contact": np.array([3.1e-3, 3.0e-3, np.nan]),
        "flange_pv_Pa_m_s.max": np.array([6e9, 5e9, np.nan]),
    }
    m = revolution_maxima([per_rev])
    np.testing.assert_array_equal(m.contact_radius_m[0], [3.1e-3, 0.0])
    np.testing.assert_array_equal(m.peak_pv_Pa_m_s[0], [6e9, 0.0])


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"maxima": [[1.0, np.nan]]}, "maxima"),
        ({"maxima": [[1.0, -1.0]]}, "maxima"),
        ({"maxima": []}, "maxima"),
        ({"maxima": np.zeros((2, 2, 2))}, "maxima"),
        ({"maxima": [[1.0, "a"]]}, "maxima"),
        ({"maxima": 3.0}, "maxima"),
        ({"rho_lim": -1.0}, "rho_lim"),
        ({"rho_lim": np.inf}, "rho_lim"),
        ({"confidence": 1.0}, "confidence"),
        ({"confidence": 0.0}, "confidence"),
        ({"confidence": np.nan}, "confidence"),
        ({"peak_pv": [[1.0]]}, "peak_pv"),
        ({"peak_pv": [[1.0, -2.0]]}, "peak_pv"),
    ],
)
def test_bad_input_one_line(kwargs, name):
    args = {"maxima": [[1.0, 2.0]], "rho_lim": 1.5, "confidence": 0.95} | kwargs
    pv = args.pop("peak_pv", None)
    with pytest.raises(UserInputError) as e:
        corner_risk(args["maxima"], args["rho_lim"], args["confidence"], peak_pv=pv)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(name) and "must" in msg


@pytest.mark.parametrize("level, confidence, name", [(0.0, 0.95, "level"), (1e-3, 1.5, "confidence")])
def test_revolutions_needed_bad_input(level, confidence, name):
    with pytest.raises(UserInputError, match=f"^{name} = .*: must be"):
        revolutions_needed(level, confidence)


def test_few_members_cover_the_rate_of_many_on_settled_dynamics():
    """The corner-risk study's settled members at a design near the corner (raw per-revolution
    maxima of the contact radius, stored with the command that made them): the estimate of every
    disjoint pair of members covers the rate counted over all the others (brute force), and the
    rate over all members lies inside the estimate's bounds of every pair in all but at most one
    pair per 10 (two-sided 90 % intervals)."""
    data = json.loads(STUDY.read_text())
    rho_lim = data["limited_circle_radius_m"]
    members = [np.asarray(m["contact_radius_max_m"]) for m in data["members"] if m["contact_radius_max_m"]]
    assert len(members) >= 6
    pooled = np.concatenate(members)
    rate = float(np.mean(pooled > rho_lim))
    assert rate > 0  # the design is near enough the corner to count it
    pairs = [members[i : i + 2] for i in range(0, len(members) - 1, 2)]
    missed = 0
    for k, pair in enumerate(pairs):
        e = corner_risk(pair, rho_lim)
        others = np.concatenate([m for j, p in enumerate(pairs) if j != k for m in p])
        held_out = float(np.mean(others > rho_lim))
        missed += not (e.lower <= held_out <= e.upper)
    assert missed <= max(1, len(pairs) // 10)


def test_settled_summary_reports_the_corner_risk():
    """`steady_statistics` (summary.json of a settled run) holds the corner risk of its members'
    revolutions: counted where a revolution reached the corner, with the peak PV given contact."""
    import jaxbearing as jb
    from jaxbearing.geometry import limited_circle_radius
    from jaxbearing.run import steady_statistics

    b, op = jb.reference_bearing(), jb.reference_operating_point()
    rho = float(limited_circle_radius(b.roller))
    per_rev = [
        {
            "cage_speed_rpm": np.full(4, 8400.0),
            "contact_radius_m.max_in_contact": np.array([3.0e-3, rho + 1e-7, 3.1e-3, np.nan]),
            "flange_pv_Pa_m_s.max": np.array([6e9, 50e9, 6e9, np.nan]),
        }
        for _ in range(2)
    ]
    block = steady_statistics([], [], b, op, per_revolution=per_rev)["corner_risk"]
    assert block["method"] == "count" and block["exceedances"] == 2 and block["revolutions"] == 8
    assert block["peak_pv_given_contact"]["value"] == pytest.approx(50e9)
    assert json.dumps(block)


@pytest.mark.slow
def test_few_members_cover_the_rate_of_many_on_fresh_dynamics(tmp_path):
    """The corner-risk study run afresh at a small size (11 slices, 6 members of 8 revolutions
    at 106.9 mm / 1.616 deg / 0.15 mm, 20,000 rpm; 6 min 6 s on the 2-core machine beside another
    process): the corner is
    reached, and every pair's bounds and both groups of three cover the rate of all six."""
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "studies" / "study_corner_risk.py"
    spec = importlib.util.spec_from_file_location("study_corner_risk", path)
    study = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(study)
    data = study.main(slices=11, members=6, window_revs=8, few=(2, 3), results_dir=tmp_path, name="fresh")
    a = data["analysis"]
    assert a["brute_force"]["exceedances"] > 0
    for block in a["few"]:
        assert block["covering"] == len(block["groups"])


def test_tail_piling_up_at_an_edge_falls_back_to_counting():
    """Maxima whose density rises towards an edge (70 % spread below 0.9, 30 % within 5e-3 of
    1: the contact radius running to the arc's edge) are unlike any GPD the fit allows: the shape
    sits at its bound and the upper bound is at least the counting bound, whatever the
    extrapolation says; with
    `method="tail"` the fit is also reported where revolutions passed the limit."""
    rng = np.random.default_rng(11)
    x = np.concatenate([rng.uniform(0.0, 0.9, 280), rng.uniform(0.995, 1.0, 120)]).reshape(4, 100)
    e = corner_risk(x, 1.0 + 1e-6)
    assert e.method == "tail" and e.tail.at_shape_bound
    assert e.upper >= e.counting_upper
    x[0, :3] = 1.0 + 2e-6
    forced = corner_risk(x, 1.0 + 1e-6, method="tail")
    assert forced.method == "tail" and forced.exceedances == 3 and forced.tail is not None
    with pytest.raises(UserInputError, match="^maxima: 8 revolutions"):
        corner_risk(np.ones(8), 1.0, method="tail")
    with pytest.raises(UserInputError, match="^method = 'fit'"):
        corner_risk(np.ones(8), 1.0, method="fit")


def test_steady_corner_risk_of_a_settled_result():
    """`steady_corner_risk` reads every measured member's per-revolution statistics and the
    bearing's limited circle; a result without a measured member is a one-line error."""
    import types

    import jaxbearing as jb
    from jaxbearing.geometry import limited_circle_radius
    from jaxbearing.run import SeedRun, steady_corner_risk

    b, op = jb.reference_bearing(), jb.reference_operating_point()
    rho = float(limited_circle_radius(b.roller))

    def member(seed, radii, status="ok"):
        per_rev = {
            "cage_speed_rpm": np.full(len(radii), 8400.0),
            "contact_radius_m.max_in_contact": np.asarray(radii),
            "flange_pv_Pa_m_s.max": np.full(len(radii), 6e9),
        }
        return SeedRun(seed, {}, np.zeros(0), 0.0, True, [], [], status, 0, per_revolution=per_rev)

    runs = [member(0, [3.0e-3, rho + 1e-7]), member(1, [3.1e-3, 3.2e-3]), member(2, [rho + 1e-7], "failed")]
    result = types.SimpleNamespace(runs=runs, bearing=b, operating=op)
    risk = steady_corner_risk(result)
    assert (risk.revolutions, risk.members, risk.exceedances, risk.method) == (4, 2, 1, "count")
    with pytest.raises(UserInputError, match="^result: no member"):
        steady_corner_risk(types.SimpleNamespace(runs=runs[2:], bearing=b, operating=op))


@pytest.mark.parametrize(
    "name",
    [
        "corner_risk_validation_105mm",
        "corner_risk_validation_105mm_31slices",
        "corner_risk_validation_31slices",
    ],
)
def test_normal_method_covers_the_brute_force_rate_on_the_dynamics(name):
    """The normal model on the settled dynamics where the corner rate is observable: 105 mm /
    1.6 deg at 20,000 rpm (11 slices, 8 members x 16 revolutions, 7 of 128 at the corner;
    benchmarks/results/corner_risk_validation_105mm.json) and, at full size, 106.9 mm / 1.616 deg
    at 20,000 rpm (31 slices, 32 members x 16 revolutions, 228 of 512 at the corner;
    corner_risk_validation_31slices.json) and 105 mm / 1.6 deg (31 slices, 16 x 16, 20 of 256;
    corner_risk_validation_105mm_31slices.json). From 4 members x 4 revolutions (the verification's
    size) and 4 x 2 (the search's), the upper bound lies below the pooled rate in at most 5 % of
    300 random subsets (binomial 0.999 tolerance: 26), also at lower limits (the 90 % and 95 %
    quantiles of the maxima)."""
    doc = json.loads(STUDY.with_name(f"{name}.json").read_text())
    rows = np.array([np.nan_to_num(np.asarray(m["contact_radius_max_m"], float)) for m in doc["members"]])
    rho_lim = doc["limited_circle_radius_m"]
    rng = np.random.default_rng(3)
    for limit in (rho_lim, *np.quantile(rows, [0.9, 0.95])):
        rate = float(np.mean(rows > limit))
        for members, revs in ((4, 4), (4, 2)):
            misses = 0
            for _ in range(300):
                pick = rng.choice(rows.shape[0], members, replace=False)
                first = rng.integers(0, rows.shape[1] - revs + 1)
                sub = rows[pick, first : first + revs]
                misses += corner_risk(sub, limit).upper < rate
            assert misses <= 26, (limit, members, revs, misses)
