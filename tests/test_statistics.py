"""Confidence intervals of settled running (jaxbearing.run._statistics) against closed forms:
coverage of the batch-means and Student-t intervals over many synthetic replicates with a known
mean, and the per-revolution statistics of a synthetic history built by hand. No solve."""

import numpy as np
import pytest

from jaxbearing.run import Estimate, batch_means, revolution_statistics, student_t_interval


def _coverage(intervals, mean):
    return np.mean([(e.ci95_low <= mean <= e.ci95_high) for e in intervals])


def test_student_t_interval_coverage_iid_normal():
    rng = np.random.default_rng(1)
    est = [student_t_interval(rng.normal(3.0, 2.0, size=6)) for _ in range(4000)]
    # binomial standard error of the coverage with 4000 replicates: 0.0034
    assert abs(_coverage(est, 3.0) - 0.95) < 0.015


def test_student_t_interval_closed_form():
    e = student_t_interval([1.0, 2.0, 3.0])
    # mean 2, s = 1, t_{2,0.975} = 4.30265273 (tables)
    assert e.value == pytest.approx(2.0)
    assert e.half_width == pytest.approx(4.30265273 / np.sqrt(3.0), rel=1e-8)
    assert np.isnan(student_t_interval([1.0]).ci95_low)
    assert student_t_interval([np.nan, 5.0, 7.0]).n == 2


def _ar1(rng, n, phi, mean, reps):
    x = np.empty((reps, n))
    x[:, 0] = rng.normal(size=reps) / np.sqrt(1 - phi**2)
    eps = rng.normal(size=(reps, n))
    for i in range(1, n):
        x[:, i] = phi * x[:, i - 1] + eps[:, i]
    return mean + x


def test_batch_means_coverage_ar1():
    """AR(1) with phi = 0.9 (correlation time ~10 samples) in batches of 200 samples: batch means
    are nearly independent and the 95 % interval covers the true mean about 95 % of the time,
    whereas the naive i.i.d. interval over all samples covers it far less often."""
    rng = np.random.default_rng(7)
    series = _ar1(rng, 4000, 0.9, mean=-1.5, reps=1000)
    est = [batch_means(s, 20) for s in series]
    assert abs(_coverage(est, -1.5) - 0.95) < 0.025
    naive = [student_t_interval(s) for s in series]
    assert _coverage(naive, -1.5) < 0.6


def test_widest_contact_sees_what_the_p99_misses():
    """A long contact inside the limited circle with one sample on the corner: the p99 of the
    contact radius stays inside, the largest contact radius (the dynamic corner margin's
    statistic) and the corner share see it."""
    edges = [0.0, 0.01, 0.02]
    hist = _history(edges, 400)
    force, radius = hist["flange_force"], hist["contact_radius"]
    force[:] = 0.0
    force[50:250, 0, 0] = 5.0  # 200 touching samples in revolution 0
    force[450:650, 0, 0] = 5.0  # and in revolution 1
    radius[:] = 3.0e-3
    radius[100, 0, 0] = 3.5e-3  # one corner sample in revolution 0
    s = revolution_statistics(hist, edges, rho_lim=3.2e-3, kinematic_speed=120.0)
    assert s["contact_radius_m.p99"][0] < 3.2e-3
    np.testing.assert_allclose(s["contact_radius_m.max_in_contact"], [3.5e-3, 3.0e-3])
    np.testing.assert_allclose(s["corner_contact_share.time"], [1 / 200, 0.0])


def test_batch_means_rejects_too_few_batches():
    with pytest.raises(ValueError, match="num_batches"):
        batch_means(np.ones(10), 1)


def _history(edges, period_samples, z=2):
    """Two revolutions; roller 0 touches flange 0 once per revolution with a triangular force
    pulse (peak 10 N in revolution 0, 20 N in revolution 1), on the corner in revolution 1 only."""
    n = period_samples * (len(edges) - 1)
    t = np.linspace(edges[0], edges[-1], n, endpoint=False)
    shape = (n, z, 4)
    force = np.zeros(shape)
    radius = np.full(shape, 3.0e-3)
    for rev, peak in enumerate((10.0, 20.0)):
        i0 = rev * period_samples + 10
        force[i0 : i0 + 5, 0, 0] = peak * np.array([0.2, 0.6, 1.0, 0.6, 0.2])
        if rev == 1:
            radius[i0 : i0 + 5, 0, 0] = 3.5e-3
    zeros = np.zeros(shape)
    return dict(
        t=t,
        flange_force=force,
        flange_pressure=force * 1e7,
        flange_sliding_speed=zeros + 2.0,
        flange_roller_surface_speed=zeros + 3.0,
        flange_pv=force * 2e7,
        contact_height=zeros + 1e-3,
        contact_radius=radius,
        on_arc=(radius < 3.2e-3).astype(float),
        cage_speed=np.where(t < edges[1], 100.0, 110.0),
        roller_skew=np.full((n, z), -1e-4),
    )


def test_revolution_statistics_closed_form():
    edges = [0.0, 0.01, 0.02]
    hist = _history(edges, 100)
    s = revolution_statistics(hist, edges, rho_lim=3.2e-3, kinematic_speed=120.0)
    np.testing.assert_allclose(s["flange_force_N.max"], [10.0, 20.0])
    np.testing.assert_allclose(s["flange_pv_Pa_m_s.max"], [2e8, 4e8])
    np.testing.assert_allclose(s["flange_sliding_velocity_m_s.mean"], [2.0, 2.0])
    np.testing.assert_allclose(s["corner_contact_share.events"], [0.0, 1.0])
    # forces above the 1 N threshold: 0.6, 1.0, 0.6 x peak... all 5 samples for both pulses
    np.testing.assert_allclose(s["corner_contact_share.time"], [0.0, 1.0])
    np.testing.assert_allclose(s["contact_radius_m.p99"], [3.0e-3, 3.5e-3])
    np.testing.assert_allclose(s["contact_radius_m.max_in_contact"], [3.0e-3, 3.5e-3])
    # PV over contact time: the five samples (0.2, 0.6, 1, 0.6, 0.2) x 2e7 x peak; p95 by linear
    # interpolation 1.2e8 + 0.8 x 0.8e8 (x 2 in revolution 1); the tail mean: the one sample above
    np.testing.assert_allclose(s["flange_pv_contact_time_Pa_m_s.mean"], [1.04e8, 2.08e8])
    np.testing.assert_allclose(s["flange_pv_contact_time_Pa_m_s.p95"], [1.84e8, 3.68e8])
    np.testing.assert_allclose(s["flange_pv_contact_time_Pa_m_s.tail95"], [2e8, 4e8])
    rpm = 60 / (2 * np.pi)
    np.testing.assert_allclose(s["cage_speed_rpm"], [100 * rpm, 110 * rpm])
    np.testing.assert_allclose(s["cage_slip"], [1 - 100 / 120, 1 - 110 / 120])
    np.testing.assert_allclose(s["roller_skew_rad.max_abs"], [1e-4, 1e-4])
    assert isinstance(student_t_interval(s["flange_force_N.max"]), Estimate)


def test_upper_probability_bound_is_clopper_pearson():
    """The one-sided 95 % Clopper-Pearson bound: with no event in n trials exactly
    1 - 0.05^(1/n) (about 3/n: the rule of three), 1 with every trial an event, and the bound
    P(X <= k | p) = 0.05 of the binomial in between."""
    from scipy import stats

    from jaxbearing.run._statistics import upper_probability_bound

    for n in (1, 8, 16, 100):
        assert upper_probability_bound(0, n) == pytest.approx(1 - 0.05 ** (1 / n), rel=1e-12)
    assert upper_probability_bound(0, 1000) == pytest.approx(3 / 1000, rel=0.01)
    assert upper_probability_bound(5, 5) == 1.0 and np.isnan(upper_probability_bound(0, 0))
    p = upper_probability_bound(3, 40)
    assert stats.binom.cdf(3, 40, p) == pytest.approx(0.05, rel=1e-9)


def test_corner_contact_bound_counts_revolutions_and_seeds():
    """Revolutions whose largest contact radius lies beyond the limited circle, over the
    measured revolutions (a NaN cage speed is no revolution; a NaN radius, no contact)."""
    from jaxbearing.run._statistics import corner_contact_bound, upper_probability_bound

    rho = 2.0e-3
    seeds = [
        {
            "cage_speed_rpm": np.array([1.0, 1.0, 1.0, 1.0]),
            "contact_radius_m.max_in_contact": np.array([1e-3, np.nan, 2.1e-3, 1.9e-3]),
        },
        {
            "cage_speed_rpm": np.array([1.0, 1.0, np.nan, 1.0]),
            "contact_radius_m.max_in_contact": np.array([1e-3, 1e-3, 3e-3, 1e-3]),
        },
    ]
    b = corner_contact_bound(seeds, rho)
    assert (b.revolutions, b.revolutions_with_corner_contact) == (7, 1)
    assert (b.seeds, b.seeds_with_corner_contact) == (2, 1)
    assert b.per_revolution_upper95 == upper_probability_bound(1, 7)
    assert b.per_seed_upper95 == upper_probability_bound(1, 2)


def test_max_contact_radius_bound_is_the_normal_prediction_bound():
    """The upper prediction bound of one further revolution's largest contact radius: the
    closed form m + t_{0.95, N-1} s sqrt(1 + 1/N) over every finite revolution of every seed, NaN
    below two revolutions; and its coverage: for normal per-revolution maxima, a further
    revolution exceeds the bound of 8 revolutions (4 seeds x 2, the search's ensemble) in 5 % of
    20,000 independent trials (binomial standard error 0.15 %)."""
    from scipy import stats

    from jaxbearing.run._statistics import max_contact_radius_bound

    seeds = [
        {"contact_radius_m.max_in_contact": np.array([1.0e-3, np.nan, 1.2e-3])},
        {"contact_radius_m.max_in_contact": np.array([1.1e-3, 0.9e-3])},
    ]
    x = np.array([1.0e-3, 1.2e-3, 1.1e-3, 0.9e-3])
    b = max_contact_radius_bound(seeds)
    expected = x.mean() + stats.t.ppf(0.95, 3) * x.std(ddof=1) * np.sqrt(1 + 1 / 4)
    assert b.value == pytest.approx(expected, rel=1e-12) and b.revolutions == 4
    assert np.isnan(max_contact_radius_bound([{"contact_radius_m.max_in_contact": np.array([1e-3])}]).value)
    rng = np.random.default_rng(0)
    trials = 20_000
    draws = rng.normal(2.0e-3, 0.03e-3, size=(trials, 9))
    exceeded = sum(
        draws[i, 8] > max_contact_radius_bound([{"contact_radius_m.max_in_contact": draws[i, :8]}]).value
        for i in range(trials)
    )
    assert abs(exceeded / trials - 0.05) < 4 * np.sqrt(0.05 * 0.95 / trials)


def test_settled_statistics_has_every_statistic_as_a_field_and_writes_the_summary_from_them():
    """`SettledStatistics`: every per-revolution statistic (`revolution_statistic_keys`) is one
    field (`estimates()` names each once), each the Student-t interval over the seeds of the
    seeds' means; the summary block (`as_dict`) nests the same numbers by group and reduction."""
    import jaxbearing as jb
    from jaxbearing.run import SettledStatistics, revolution_statistic_keys, settled_statistics

    rng = np.random.default_rng(3)
    keys = revolution_statistic_keys()
    seeds = [{k: rng.uniform(1.0, 2.0, size=3) for k in keys} for _ in range(3)]
    for s in seeds:
        s["contact_radius_m.max_in_contact"] = rng.uniform(1e-3, 2e-3, size=3)
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    st = settled_statistics([], [], b, op, per_revolution=seeds)
    assert isinstance(st, SettledStatistics)
    est = st.estimates()
    assert list(sorted(est)) == sorted(keys)
    x = [float(np.mean(s["flange_pv_Pa_m_s.max"])) for s in seeds]
    assert st.flange_pv_Pa_m_s.max.value == pytest.approx(np.mean(x), rel=1e-12)
    assert st.flange_pv_Pa_m_s.max.n == 3 and st.cage_slip is est["cage_slip"]
    block = st.as_dict()
    for key in keys:
        group, _, red = key.partition(".")
        got = block[group][red] if red else block[group]
        assert got == est[key].as_dict()
    assert block["max_contact_radius_bound"]["revolutions"] == 9
    assert block["limited_circle_radius_m"] == st.limited_circle_radius_m
