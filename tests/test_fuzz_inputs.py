"""Issue 38: hypothesis fuzzing of the sweep spec and the optimiser's TOML file, as
tests/test_validation.py and tests/test_properties.py fuzz the configuration: random specs and
files through TOML text are either accepted with finite values or refused with a one-line
`UserInputError`; never a traceback of another kind, a hang (each example runs under
`signal.alarm`) or a silent NaN. Parsing and validation only, no solve.

Examples: 30 per test in the default run; the `slow` run has 200 per test
(`make test-slow`)."""

from __future__ import annotations

import math

import pytest
import tomli_w
from _timeouts import time_limit
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

import jaxbearing as jb
from jaxbearing import UserInputError
from jaxbearing.io import KEYS
from jaxbearing.sweep import loads_sweep_spec
from jaxbearing.sweep._spec import _SWEEP_FIELDS
from optimise._toml import OPTIMISE_TOML_KEYS, load_optimise_toml


def _settings(n: int):
    return settings(
        max_examples=n,
        deadline=None,
        derandomize=n < 200,
        suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    )


SCALAR = st.one_of(
    st.floats(),
    st.floats(-1e5, 1e5),
    st.integers(-5, 40),
    st.integers(-(10**20), 10**20),
    st.booleans(),
    st.text(max_size=6),
    st.sampled_from(["arc", "corner", "both", "auto", "max", "mean", "steady", "startup", "frozen"]),
)
VALUE = st.one_of(SCALAR, st.lists(SCALAR, max_size=3))
FLOAT_KEYS = [k.path for k in KEYS if k.kind is float]
AXIS_KEY = st.one_of(
    st.sampled_from(FLOAT_KEYS),
    st.sampled_from(
        ["end", "bearing.num_rollers", "simulation.max_steps", "roller.end_radius_m", "nonsense"]
    ),
)
RANGE = st.fixed_dictionaries(
    {
        "start": SCALAR,
        "stop": SCALAR,
        "num": st.one_of(st.integers(-3, 5), st.integers(10**6, 10**18), SCALAR),
    },
    optional={"step": SCALAR},
)
AXIS_VALUES = st.one_of(st.lists(SCALAR, max_size=4), RANGE, SCALAR)
SECTIONS = sorted({k.section for k in KEYS})
BASE = st.one_of(
    st.just({}),
    st.dictionaries(
        st.sampled_from(SECTIONS),
        st.dictionaries(st.sampled_from(sorted({k.name for k in KEYS}) + ["bogus"]), SCALAR, max_size=2),
        max_size=2,
    ),
)
SWEEP = st.dictionaries(
    st.sampled_from([*_SWEEP_FIELDS, "bogus"]),
    st.one_of(VALUE, st.lists(st.lists(st.sampled_from(FLOAT_KEYS[:4]), max_size=2), max_size=2)),
    max_size=3,
)
RANDOM_SPEC = st.fixed_dictionaries(
    {"axes": st.dictionaries(AXIS_KEY, AXIS_VALUES, max_size=3)},
    optional={"sweep": SWEEP, "base": BASE, "bogus": st.just({"x": 1})},
)
#: plausible axes (key -> range of valid values), so that many specs are accepted and some are
#: broken by one bad value
PLAUSIBLE = {
    "operating.speed_rpm": (1000.0, 30000.0),
    "operating.radial_load_N": (100.0, 5000.0),
    "roller.end_radius_mm": (40.0, 140.0),
    "flange.layback_angle_deg": (0.5, 3.0),
    "simulation.duration_ms": (0.1, 5.0),
}
BAD = st.sampled_from([math.nan, math.inf, -math.inf, -1.0, 0.0, "1.0", True, 1e300])


@st.composite
def plausible_specs(draw):
    axes = {}
    for key in draw(st.lists(st.sampled_from(sorted(PLAUSIBLE)), min_size=1, max_size=3, unique=True)):
        lo, hi = PLAUSIBLE[key]
        if draw(st.booleans()):
            values = draw(st.lists(st.floats(lo, hi), min_size=1, max_size=4, unique=True))
            if draw(st.integers(0, 4)) == 0:  # one bad value
                values[draw(st.integers(0, len(values) - 1))] = draw(BAD)
            axes[key] = values
        else:
            axes[key] = {
                "start": draw(st.floats(lo, hi)),
                "stop": draw(st.floats(lo, hi)),
                "num": draw(st.integers(1, 4)),
            }
    if draw(st.booleans()):
        axes["end"] = draw(st.sampled_from([["arc"], ["arc", "corner"], ["corner", "flat"]]))
    sweep = {"batch_size": draw(st.one_of(st.integers(1, 8), BAD))} if draw(st.booleans()) else {}
    if len(axes) > 1 and draw(st.integers(0, 3)) == 0:
        sweep["mode"] = "zip"
    return {"sweep": sweep, "axes": axes}


SPEC = st.one_of(RANDOM_SPEC, plausible_specs())


def _toml(data) -> str:
    try:
        return tomli_w.dumps(data)
    except (TypeError, ValueError):
        assume(False)


def _check_spec(data, tmp_path):
    data = dict(data)
    sweep = dict(data.get("sweep", {}))
    if sweep.get("base") not in (None, "reference"):
        sweep["base"] = str(sweep["base"])  # a file name relative to tmp_path: absent or not a config
    if sweep:
        data["sweep"] = sweep
    text = _toml(data)
    with time_limit():
        try:
            spec = loads_sweep_spec(text, base_dir=tmp_path)
        except UserInputError as exc:
            assert "\n" not in str(exc)
            event("refused")
            return
    event("accepted")
    # accepted: every swept value is a finite number (inf only as a flat end), or an end type
    for axis in spec.axes:
        for v in axis.values:
            if axis.key == "end":
                assert v in ("arc", "corner")
            else:
                assert isinstance(v, (int, float)) and not isinstance(v, bool)
                assert math.isfinite(v) or (axis.key == "roller.end_radius_mm" and v == math.inf)
    assert 1 <= spec.num_cases <= 100_000


@_settings(30)
@given(data=SPEC)
def test_sweep_spec_fuzz(data, tmp_path):
    _check_spec(data, tmp_path)


@pytest.mark.slow
@_settings(200)
@given(data=SPEC)
def test_sweep_spec_fuzz_200(data, tmp_path):
    _check_spec(data, tmp_path)


TOML_SECTION = st.sampled_from([*OPTIMISE_TOML_KEYS, "bogus"])


@st.composite
def optimiser_files(draw):
    out = {}
    for section in draw(st.lists(TOML_SECTION, max_size=3, unique=True)):
        names = [*OPTIMISE_TOML_KEYS.get(section, ()), "bogus"]
        keys = draw(st.lists(st.sampled_from(names), max_size=4, unique=True))
        out[section] = {k: draw(VALUE) for k in keys}
    return out


BEARING, OP = jb.reference_bearing(), jb.reference_operating_point()


def _check_optimiser_file(data, tmp_path):
    from optimise._cli import objective_of, problem_from_settings, steady_settings_from

    path = tmp_path / "optimise.toml"
    path.write_text(_toml(data))
    with time_limit():
        try:
            s = load_optimise_toml(str(path))
            problem, options = problem_from_settings(BEARING, OP, s)
            steady = steady_settings_from(s) if objective_of(s) == "steady" else None
        except UserInputError as exc:
            assert "\n" not in str(exc)
            event("refused")
            return
    event("accepted")
    # accepted: no NaN or infinity anywhere in what the search will use
    import numpy as np

    for v in (problem.duration, problem.flange_load, problem.min_clearance, problem.rtol, problem.atol):
        assert math.isfinite(v)
    assert np.all(np.isfinite(np.asarray(problem.weights)))
    assert np.all(np.isfinite(np.asarray(problem.operating.inner_speed)))
    assert np.all(np.isfinite(np.asarray(problem.operating.radial_load)))
    assert np.all(np.isfinite(problem.bounds.lower)) and np.all(np.isfinite(problem.bounds.upper))
    assert all(math.isfinite(float(v)) for v in options.values())
    if steady is not None:
        assert math.isfinite(steady.gradient_window) and math.isfinite(steady.corner_margin)


@_settings(30)
@given(data=optimiser_files())
def test_optimiser_toml_fuzz(data, tmp_path):
    _check_optimiser_file(data, tmp_path)


@pytest.mark.slow
@_settings(200)
@given(data=optimiser_files())
def test_optimiser_toml_fuzz_200(data, tmp_path):
    _check_optimiser_file(data, tmp_path)
