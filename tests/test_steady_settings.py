"""`run.SteadySettings`: every setting of settled running defined once, with its default, checked
in one place; the settling modes as objects, the command line's and the TOML files' text mapped
onto them in one place (`settling`, `steady_settings`)."""

import dataclasses
import inspect
import json

import pytest

import jaxbearing as jb
from jaxbearing import UserInputError
from jaxbearing.run import SettleAuto, SettleFixed, SettleOff, SteadySettings, settling, steady_settings

FIELDS = {f.name for f in dataclasses.fields(SteadySettings)}


def _entries():
    from jaxbearing import design, run

    return [
        run.simulate_steady,
        run.simulate_steady_points,
        run.settle_members,
        run.simulate,
        run.model_cage_speeds,
        design.steady_design_metrics,
        design.steady_design_metrics_points,
    ]


@pytest.mark.parametrize("entry", _entries(), ids=lambda f: f.__name__)
def test_public_entries_take_the_settings_and_declare_no_default_of_their_own(entry):
    """No public entry of settled running declares a setting of its own (a keyword named like a
    field of `SteadySettings` with a default): they take a `SteadySettings` (default: its
    defaults), and keywords naming its fields change it."""
    params = inspect.signature(entry).parameters
    own = sorted(n for n, p in params.items() if n in FIELDS and p.default is not inspect.Parameter.empty)
    assert own == [] or (entry.__name__ == "simulate" and own == ["settle"])
    assert "settings" in params


def test_the_command_line_and_the_sweep_files_default_to_the_one_definition():
    from jaxbearing.cli._main import build_parser
    from jaxbearing.sweep._spec import SETTLED_DEFAULTS, SweepSpec

    d = SteadySettings()
    sub = build_parser()._subparsers._group_actions[0].choices
    simulate = {a.dest: a.default for a in sub["simulate"]._actions}
    assert (simulate["window_revs"], simulate["seeds"], simulate["settle_tolerance"]) == (
        d.window_revs,
        d.seeds,
        d.tolerance,
    )
    assert (simulate["settle_cap_ms"], simulate["start"]) == (d.settle_cap_ms, d.start)
    assert sub["validate"]._option_string_actions["--window-revs"].default == d.window_revs
    assert SETTLED_DEFAULTS == {
        "settle": d.settle.value,
        "seeds": d.seeds,
        "window_revs": d.window_revs,
        "settle_tolerance": d.tolerance,
        "settle_cap_ms": d.settle_cap_ms,
        "start": d.start,
    }
    spec_defaults = {f.name: f.default for f in dataclasses.fields(SweepSpec) if f.name in SETTLED_DEFAULTS}
    assert spec_defaults == SETTLED_DEFAULTS


def test_settling_maps_text_onto_objects_in_one_place():
    assert settling("auto") == SettleAuto() and settling("off") == SettleOff()
    assert settling(5) == settling("5") == SettleFixed(5.0) and settling(SettleFixed(2.0)) == SettleFixed(2.0)
    assert SteadySettings(settle="0.5").settle == SettleFixed(0.5)
    assert [SettleAuto().value, SettleOff().value, SettleFixed(3.0).value] == ["auto", "off", 3.0]
    for bad, shown in (("soon", "'soon'"), (-4, "-4.0"), (float("nan"), "nan"), (True, "True")):
        with pytest.raises(
            UserInputError, match=rf'^settle = {shown}: must be "auto", "off" or a settling time >= 0 ms$'
        ):
            settling(bad)


@pytest.mark.parametrize(
    "change, message",
    [
        (dict(window_revs=1), r"^window_revs = 1.0: must be an integer >= 2"),
        (dict(window_revs=2.5), r"^window_revs = 2.5: must be an integer >= 2"),
        (dict(seeds=0), r"^seeds = 0.0: must be an integer >= 1"),
        (dict(tolerance=0.0), r"^settle_tolerance = 0.0: must be in \(0, 1\)"),
        (dict(settle_cap_ms=-1.0), r"^settle_cap_ms = -1.0: must be > 0 ms"),
        (dict(start="warm"), r"^start = 'warm': must be one of 'skid', 'quasi-static'"),
        (dict(rtol=2.0), r"^rtol = 2.0: must be in \(0, 1\)"),
        (dict(max_steps=0), r"^max_steps = 0.0: must be an integer >= 1"),
        (dict(solver="euler"), r"^solver = 'euler'"),
        (dict(strategy="gpu"), r"^strategy = 'gpu': must be one of 'auto'"),
        (dict(workers=0), r"^workers = 0.0: must be an integer >= 1"),
        (dict(continuation_settle_revs=-1), r"^continuation_settle_revs = -1.0: must be an integer >= 0"),
        (dict(window=4), r"^window: not a setting of settled running; the settings are settle, window_revs"),
    ],
)
def test_a_bad_setting_is_one_line_naming_it(change, message):
    with pytest.raises(UserInputError, match=message):
        SteadySettings().replace(**change)


def test_the_command_line_names_its_own_options():
    with pytest.raises(UserInputError, match=r"^--window-revs = 1.0: must be an integer >= 2"):
        steady_settings({"window_revs": "--window-revs"}, window_revs=1)
    with pytest.raises(UserInputError, match=r"^sweep.settle_tolerance = 2.0: must be in"):
        steady_settings({"settle_tolerance": "sweep.settle_tolerance"}, tolerance=2.0)
    s = steady_settings({}, settle="3", seeds=2.0)
    assert s.settle == SettleFixed(3.0) and s.seeds == 2 and isinstance(s.seeds, int)


def test_the_settings_record_is_json_and_says_how_it_settled():
    record = SteadySettings(settle=SettleFixed(0.5), seeds=3).record()
    assert json.loads(json.dumps(record)) == record
    assert record["settle"] == 0.5 and record["seeds"] == 3 and "functionals" not in record


def test_a_settled_simulate_takes_settings_or_their_fields():
    """`jaxbearing.simulate` with `settings` or a field of it is a settled run; a keyword that is
    neither a setting nor a keyword of the run is refused in one line before anything runs."""
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    with pytest.raises(UserInputError, match=r"^window: not a setting of settled running"):
        jb.simulate(b, op, settings=SteadySettings(), window=3)


def test_member_progress_counts_members_and_prints_on_time():
    """`MemberProgress`: while active, the dispatcher's member programs (`_reporting`) and the
    process pool (`parallel_map(on_done=...)`) count finished members; its thread prints the
    count, the elapsed time and an estimate of what remains at least every `interval` s."""
    import threading

    from jaxbearing.run import MemberProgress, parallel_map
    from jaxbearing.run._dispatch import _reporting
    from jaxbearing.run._member_progress import active_progress

    def program():
        answer = yield "request"
        return answer * 2

    lines = []
    printed = threading.Event()

    def say(line):
        lines.append(line)
        printed.set()

    assert active_progress() is None
    with MemberProgress(interval=0.05, label="  ", say=say) as progress:
        assert active_progress() is progress
        progress.started(3)
        assert progress.line().startswith("  members settled 0 of 3") and "no estimate" in progress.line()
        wrapped = _reporting(program())
        assert next(wrapped) == "request"
        with pytest.raises(StopIteration) as stop:
            wrapped.send(21)
        assert stop.value.value == 42 and progress.done == 1
        assert parallel_map(abs, [-1, -2], workers=1, on_done=progress.finished) == [1, 2]
        assert progress.done == 3 and "s left" in progress.line()
        assert printed.wait(60)  # the thread prints however loaded the machine is
    assert active_progress() is None
    assert lines and all(line.startswith("  members settled ") for line in lines)
    with pytest.raises(UserInputError, match=r"^interval = 0.0: must be > 0 s$"):
        MemberProgress(interval=0)
