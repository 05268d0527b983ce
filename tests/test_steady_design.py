"""The steady-running design objective (issue 13, item 1) at a reduced size: 11 slices per
raceway, a fixed 0.5 ms settling time, a 2-revolution window, 2 seeds."""

import dataclasses
import math

import numpy as np
import pytest

import jaxbearing as jb
from jaxbearing import UserInputError
from jaxbearing.flange import MARGIN_NAMES, DesignVariables


@pytest.fixture(scope="module")
def small():
    return dataclasses.replace(jb.reference_bearing(), num_slices=11), jb.reference_operating_point()


def test_steady_design_metrics_report_intervals_and_margins(small):
    b, op = small
    design = DesignVariables(end_radius=0.08, layback_angle=1.6 * math.pi / 180, axial_clearance=0.15e-3)
    # a settling time given as text is a settling time (it once ran as "auto", two revolutions more)
    m = jb.steady_design_metrics(b, op, design, seeds=2, window_revs=2, settle="0.5", first_seed=5)
    assert m.seeds == [5, 6] and m.settled
    # the mean's accumulators give the tail statistic and the friction power too, from the same
    # runs; not the peak's
    assert set(m.objectives_per_seed) == {"mean", "tail", "friction"}
    # each seed's friction power is its own time mean; with equal windows their mean is the
    # settled statistic over every revolution of both seeds
    friction = np.asarray(m.objectives_per_seed["friction"])
    assert np.all(friction > 0)
    assert np.mean(friction) == pytest.approx(m.statistics.flange_friction_power_W.total.value, rel=1e-9)
    assert m.objectives_per_seed["mean"] == m.objective_per_seed
    assert (
        all(np.isfinite(m.objectives_per_seed["tail"]))
        and m.objectives_per_seed["tail"] != m.objective_per_seed
    )
    assert m.summary["settle_mode"] == "fixed" and m.summary["settle_time_ms"] == pytest.approx(0.5)
    for est in (m.mean_pv, m.p95_pv, m.corner_contact_share, m.corner_margin):
        assert est.ci95_low <= est.value <= est.ci95_high and est.n == 2
    assert 0 < m.mean_pv.value < m.p95_pv.value
    # the arc end at R_end 80 mm keeps its contacts inside the limited circle
    assert m.corner_contact_share.value == 0.0 and m.corner_margin.value > 0
    st = m.statistics
    rho_lim = st.limited_circle_radius_m
    widest = st.contact_radius_m.max_in_contact.value
    assert widest >= st.contact_radius_m.p99.value
    assert m.corner_margin.value == pytest.approx(rho_lim - jb.design.CORNER_MARGIN - widest)
    # the prediction bound of one further revolution over the 4 revolutions lies above their mean
    bound = st.max_contact_radius_bound
    assert bound.revolutions == 4 and bound.value > widest
    assert m.corner_margin_bound == pytest.approx(rho_lim - jb.design.CORNER_MARGIN - bound.value)
    # the summary is written from the same statistics
    assert m.summary["contact_radius_m"]["max_in_contact"]["value"] == widest
    assert set(m.static_margins) == set(MARGIN_NAMES)
    assert m.design["axial_clearance_m"] == pytest.approx(0.15e-3)


def test_bad_design_or_margin_is_one_line(small):
    b, op = small
    with pytest.raises(UserInputError, match="design.end_radius"):
        jb.steady_design_metrics(
            b, op, DesignVariables(end_radius=1e-3, layback_angle=0.03, axial_clearance=1e-4)
        )
    good = DesignVariables(end_radius=0.08, layback_angle=0.03, axial_clearance=1e-4)
    with pytest.raises(UserInputError, match="corner_margin"):
        jb.steady_design_metrics(b, op, good, corner_margin=-1.0)
