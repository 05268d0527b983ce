"""The profile variables' frozen-load gradients against common-random-number central differences
of settled running: the study benchmarks/studies/study_profile_gradients.py (`check`, its
`verdict`) at reduced size, 11 slices and 3 seeds at 20,000 rpm.

In the default suite, the end offset e (the new variable the settled PV feels most) at the first
of the study's designs; the flange height's estimate there is exactly zero (the contact stays
below the rib's top edge). Slow: all five new variables (e, R_cor, 1/R_rib, h_t, H_rf) at the
study's four designs, each row "agrees" (|FD| > 3 SE, the same sign, within 30 %), "consistent" (the
difference not significant, the estimate within 3 SE of it) or "not felt" (both exactly zero);
and the rib's tangent height h_t, which three seeds resolve at two of the four designs, with 8 seeds
and steps of 40 % of the box at the second design, where it agrees.
The full study and its measured rows: benchmarks/results/profile_gradient_check.json,
profile_gradient_check_8seeds_wide.json and profile_gradient_check_8seeds_conforming.json (the
rib curvature, which agrees with 8 seeds at the fourth design).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

STUDY = Path(__file__).resolve().parents[1] / "benchmarks" / "studies" / "study_profile_gradients.py"


def _study():
    spec = importlib.util.spec_from_file_location("study_profile_gradients", STUDY)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


study = _study()


def _show(label, out):
    for r in out["rows"]:
        print(
            f"{label}: {r['variable']}: frozen {r['frozen_load']:.3e} +- {r['frozen_load_se']:.1e}, "
            f"CRN {r['crn_difference']:.3e} +- {r['crn_difference_se']:.1e}: {r['verdict']}"
        )


def test_verdicts():
    assert study.verdict(-1.0, -1.2, 0.1) == "agrees"
    assert study.verdict(-1.0, -2.0, 0.1) == "disagrees"
    assert study.verdict(1.0, -1.2, 0.1) == "disagrees"
    assert study.verdict(0.5, 0.1, 0.2) == "consistent"
    assert study.verdict(5.0, 0.1, 0.2) == "inconsistent"
    assert study.verdict(0.0, 0.0, 0.0) == "not felt"


def test_end_offset_gradient_agrees_with_crn_differences():
    label = next(iter(study.DESIGNS))
    out = study.check(study.DESIGNS[label], variables=("end_offset_mm",), slices=11, seeds=3)
    _show(label, out)
    (row,) = out["rows"]
    assert row["significant"] and row["verdict"] == "agrees"
    assert out["frozen_load_gradient"]["flange_height_mm"] == 0.0


@pytest.mark.slow
@pytest.mark.parametrize("label", list(study.DESIGNS))
def test_every_new_variable_at_every_design(label):
    out = study.check(study.DESIGNS[label], slices=11, seeds=3)
    _show(label, out)
    assert all(r["verdict"] in ("agrees", "consistent", "not felt") for r in out["rows"])


@pytest.mark.slow
def test_tangent_height_agrees_with_a_wide_crn_difference():
    label = list(study.DESIGNS)[1]
    out = study.check(
        study.DESIGNS[label], variables=("rib_tangent_height_mm",), slices=11, seeds=8, step_fraction=0.4
    )
    _show(label, out)
    (row,) = out["rows"]
    assert row["significant"] and row["verdict"] == "agrees"
