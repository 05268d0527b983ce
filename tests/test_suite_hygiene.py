"""The test suite checked by reading it (issue 37): every test asserts something, no test
compares elapsed wall time with a threshold a loaded machine can miss, and every option of
both command lines is invoked by some test.

* An assertion: an `assert` statement, `raise`, `pytest.raises` / `pytest.warns` /
  `pytest.fail`, a call whose name starts with `assert` (`np.testing.assert_allclose`,
  `assert_same_results`, ...), or a call of a function of the same file that asserts (found
  transitively).
* A wall-clock threshold: a comparison of a value derived from `time.perf_counter()`,
  `time.monotonic()` or `time.time()` (directly, or through names assigned from them) with a
  number below `WALL_LIMIT_S`, or with an expression that adds a number (an absolute slack such as
  `2 * t + 0.01`). Deadlines that only stop a hang (`time.monotonic() < deadline`) compare two
  times and pass; ratios of two measured times pass.
* Every option: `CLI_CHECKS` maps each option string of `jaxbearing` (`build_parser`) and
  `optimise` to the tests that invoke it and check its effect; this test fails when a parser has
  an option the map lacks, or a named test does not exist or does not contain the option string.
"""

from __future__ import annotations

import argparse
import ast
import pathlib

import pytest

TESTS = pathlib.Path(__file__).parent
TEST_FILES = sorted(TESTS.glob("test_*.py"))
#: a wall-clock comparison with a number below this many seconds is a flaky threshold
WALL_LIMIT_S = 30.0
_CLOCKS = {"perf_counter", "monotonic", "time", "perf_counter_ns", "monotonic_ns"}


def _call_name(node: ast.Call) -> str:
    f = node.func
    if isinstance(f, ast.Name):
        return f.id
    if isinstance(f, ast.Attribute):
        return f.attr
    return ""


def _qualified(node: ast.Call) -> str:
    parts, f = [], node.func
    while isinstance(f, ast.Attribute):
        parts.append(f.attr)
        f = f.value
    if isinstance(f, ast.Name):
        parts.append(f.id)
    return ".".join(reversed(parts))


def _asserts_directly(fn: ast.AST) -> bool:
    for node in ast.walk(fn):
        if isinstance(node, ast.Assert | ast.Raise):
            return True
        if isinstance(node, ast.Call):
            name, qual = _call_name(node), _qualified(node)
            if name.startswith("assert") or qual in ("pytest.raises", "pytest.warns", "pytest.fail"):
                return True
    return False


def _asserting_functions(tree: ast.Module) -> set[str]:
    """Names of the file's functions (any nesting) that assert, directly or through another."""
    functions = {n.name: n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)}
    asserting = {name for name, fn in functions.items() if _asserts_directly(fn)}
    changed = True
    while changed:
        changed = False
        for name, fn in functions.items():
            if name in asserting:
                continue
            called = {_call_name(c) for c in ast.walk(fn) if isinstance(c, ast.Call)}
            if called & asserting:
                asserting.add(name)
                changed = True
    return asserting


def _tests(tree: ast.Module):
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name.startswith("test_"):
            yield node
        elif isinstance(node, ast.ClassDef) and node.name.startswith("Test"):
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and item.name.startswith("test_"):
                    yield item


def unasserted_tests(source: str) -> list[str]:
    tree = ast.parse(source)
    asserting = _asserting_functions(tree)
    return [fn.name for fn in _tests(tree) if fn.name not in asserting]


def _is_clock_call(node: ast.AST) -> bool:
    return (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Attribute)
        and node.func.attr in _CLOCKS
        and isinstance(node.func.value, ast.Name)
        and node.func.value.id == "time"
    )


def _timed_names(fn: ast.AST) -> set[str]:
    """Names assigned (anywhere in `fn`) from an expression that reads a clock or a timed name."""
    timed: set[str] = set()
    changed = True
    while changed:
        changed = False
        for node in ast.walk(fn):
            if isinstance(node, ast.Assign | ast.AugAssign | ast.AnnAssign) and node.value is not None:
                if _reads_clock(node.value, timed):
                    targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                    for t in targets:
                        for n in ast.walk(t):
                            if isinstance(n, ast.Name) and n.id not in timed:
                                timed.add(n.id)
                                changed = True
    return timed


def _reads_clock(expr: ast.AST, timed: set[str]) -> bool:
    return any(_is_clock_call(n) or (isinstance(n, ast.Name) and n.id in timed) for n in ast.walk(expr))


def _number(node: ast.AST) -> float | None:
    if (
        isinstance(node, ast.Constant)
        and isinstance(node.value, int | float)
        and not isinstance(node.value, bool)
    ):
        return float(node.value)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        v = _number(node.operand)
        return None if v is None else -v
    return None


def _adds_a_number(node: ast.AST) -> bool:
    return any(
        isinstance(n, ast.BinOp)
        and isinstance(n.op, ast.Add | ast.Sub)
        and (_number(n.left) is not None or _number(n.right) is not None)
        for n in ast.walk(node)
    )


def wall_clock_thresholds(source: str) -> list[str]:
    """`name:line` of each comparison of a timed value with a short threshold (module docstring)."""
    tree = ast.parse(source)
    found = []
    for fn in ast.walk(tree):
        if not isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        timed = _timed_names(fn)
        for node in ast.walk(fn):
            if not isinstance(node, ast.Compare):
                continue
            operands = [node.left, *node.comparators]
            clocked = [o for o in operands if _reads_clock(o, timed)]
            if not clocked:
                continue
            others = [o for o in operands if o not in clocked]
            short = [v for v in map(_number, others) if v is not None and v < WALL_LIMIT_S]
            if short or any(_adds_a_number(o) for o in operands):
                found.append(f"{fn.name}:{node.lineno}")
    return found


# -- the checkers, on examples ----------------------------------------------------------------------
def test_checkers_find_what_they_look_for():
    """The two scans flag what they must and pass what they must (so a passing scan of the suite
    means something)."""
    bad = """
def helper():
    return 1
def test_nothing():
    helper()
def test_prints():
    print(1 == 1)
"""
    good = """
import numpy as np, pytest
def check(x):
    assert x
def outer(x):
    check(x)
def test_a():
    assert 1
def test_b():
    np.testing.assert_allclose(1, 1)
def test_c():
    with pytest.raises(ValueError):
        int("x")
def test_d():
    outer(1)
"""
    assert unasserted_tests(bad) == ["test_nothing", "test_prints"]
    assert unasserted_tests(good) == []
    timing = """
import time
def test_threshold():
    start = time.perf_counter()
    work()
    assert time.perf_counter() - start < 5
def test_slack():
    t0 = time.monotonic(); a = time.monotonic() - t0
    b = time.monotonic() - t0
    assert a < 2.0 * b + 0.01
def test_elapsed_name():
    t = time.time()
    elapsed = time.time() - t
    assert elapsed <= 0.3
def test_deadline():
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        pass
    assert True
def test_ratio():
    a = time.perf_counter()
    b = time.perf_counter()
    assert a < 2.0 * b
def test_long_limit():
    t = time.perf_counter()
    assert time.perf_counter() - t < 600
"""
    assert wall_clock_thresholds(timing) == ["test_threshold:6", "test_slack:10", "test_elapsed_name:14"]


# -- the suite ------------------------------------------------------------------------------------
@pytest.mark.parametrize("path", TEST_FILES, ids=lambda p: p.name)
def test_every_test_asserts(path):
    missing = unasserted_tests(path.read_text())
    assert not missing, f"{path.name}: tests without an assertion: {missing}"


@pytest.mark.parametrize("path", TEST_FILES, ids=lambda p: p.name)
def test_no_short_wall_clock_threshold(path):
    found = wall_clock_thresholds(path.read_text())
    assert not found, f"{path.name}: wall-clock thresholds below {WALL_LIMIT_S:g} s at {found}"


# -- every command-line option invoked --------------------------------------------------------------
#: (program, command, option) -> the tests (file::name) that invoke the option and check its
#: effect; the option string must appear in the test, in a fixture it takes or in a module-level
#: name it uses (`ARGS`, `_cli_args`)
_OVERRIDES = "test_cmd_simulate.py::test_command_line_overrides_win_over_the_file"
_DEMO = "test_cmd_simulate.py::test_demo_transient_writes_both_ends"
_DEFAULT_SETTLED = "test_cmd_simulate.py::test_simulate_settles_by_default_and_a_transient_is_explicit"
_AUTO = "test_settle.py::test_auto_settle_succeeds_and_reports_intervals"
_CAP = "test_settle.py::test_auto_settle_hitting_the_cap_is_not_silent"
_SETTLED_OPTIONS = "test_settle.py::test_settled_options_reach_the_run"
_STEADY_CLI = "test_optimise_steady.py::test_killed_run_resumes_with_the_same_result"
_OPT_FILE = "test_optimise.py::test_cli_settings_from_a_file_and_options_reach_the_problem"
_TWO_PROCESSES = "test_sweep_distributed.py::test_two_processes_match_single_process"
_VALIDATE = "test_validate.py::test_validate_writes_the_comparison"
_SENS_QUICK = "test_sensitivity.py::test_quick_cli_ranks_writes_and_agrees_with_a_finer_step"
_NEW = "test_config_new.py::test_config_new_writes_once_and_show_marks_estimates"
CLI_CHECKS = {
    ("jaxbearing", "demo", "--window-revs"): [
        "test_cmd_simulate.py::test_demo_settled_passes_its_window_to_the_run"
    ],
    ("jaxbearing", "demo", "--transient"): [_DEMO],
    ("jaxbearing", "demo", "--duration-ms"): [_DEMO],
    ("jaxbearing", "demo", "--out"): [_DEMO],
    ("jaxbearing", "demo", "--summary-only"): ["test_params.py::test_cli_demo_prints_summary"],
    ("jaxbearing", "config show", "--config"): ["test_config.py::test_config_show_merges_file"],
    **{
        ("jaxbearing", "config new", option): [_NEW]
        for option in (
            "--bore-mm",
            "--outside-diameter-mm",
            "--width-mm",
            "--series",
            "--type",
            "--num-rollers",
            "--roller-diameter-mm",
            "--roller-length-mm",
        )
    },
    ("jaxbearing", "config new", "--out"): [_NEW],
    ("jaxbearing", "config new", "--force"): [_NEW],
    ("jaxbearing", "validate", "--config"): [_VALIDATE],
    ("jaxbearing", "validate", "--end"): [_VALIDATE],
    ("jaxbearing", "validate", "--settle"): [_VALIDATE],
    ("jaxbearing", "validate", "--seeds"): [_VALIDATE],
    ("jaxbearing", "validate", "--window-revs"): [_VALIDATE],
    ("jaxbearing", "validate", "--workers"): [_VALIDATE],
    ("jaxbearing", "validate", "--no-progress"): [_VALIDATE],
    ("jaxbearing", "validate", "--out"): [
        _VALIDATE,
        "test_validate.py::test_an_interrupted_validation_keeps_its_finished_points",
    ],
    ("jaxbearing", "sensitivity", "--statistics"): [
        _SENS_QUICK,
    ],
    ("jaxbearing", "sensitivity", "--quick"): [_SENS_QUICK],
    ("jaxbearing", "sensitivity", "--out"): [_SENS_QUICK],
    ("jaxbearing", "sensitivity", "--seeds"): ["test_sensitivity.py::test_settled_options_reach_the_study"],
    ("jaxbearing", "sensitivity", "--window-revs"): [
        "test_sensitivity.py::test_settled_options_reach_the_study"
    ],
    ("jaxbearing", "zone", "--config"): ["test_zone.py::test_cli_zone_reads_a_config"],
    ("jaxbearing", "zone", "--flange-load-N"): ["test_zone.py::test_cli_zone_prints_margins_and_writes_maps"],
    ("jaxbearing", "zone", "--map"): ["test_zone.py::test_cli_zone_prints_margins_and_writes_maps"],
    ("jaxbearing", "zone", "--out"): ["test_zone.py::test_cli_zone_prints_margins_and_writes_maps"],
    ("jaxbearing", "simulate", "--config"): [_OVERRIDES],
    ("jaxbearing", "simulate", "--end"): [_OVERRIDES, _AUTO],
    ("jaxbearing", "simulate", "--speed-rpm"): [_OVERRIDES],
    ("jaxbearing", "simulate", "--load-N"): [_OVERRIDES],
    ("jaxbearing", "simulate", "--duration-ms"): [_OVERRIDES],
    ("jaxbearing", "simulate", "--out"): [_OVERRIDES, _AUTO],
    ("jaxbearing", "simulate", "--no-progress"): [_OVERRIDES],
    ("jaxbearing", "simulate", "--solver"): ["test_cmd_simulate.py::test_solver_reaches_the_run"],
    ("jaxbearing", "simulate", "--settle"): [_AUTO, _CAP, _DEFAULT_SETTLED],
    ("jaxbearing", "simulate", "--transient"): [_OVERRIDES, _DEFAULT_SETTLED],
    ("jaxbearing", "simulate", "--window-revs"): [_AUTO],
    ("jaxbearing", "simulate", "--seeds"): [_SETTLED_OPTIONS],
    ("jaxbearing", "simulate", "--settle-tolerance"): [_AUTO],
    ("jaxbearing", "simulate", "--workers"): [_SETTLED_OPTIONS],
    ("jaxbearing", "simulate", "--start"): [_AUTO, _CAP],
    ("jaxbearing", "simulate", "--settle-cap-ms"): [_CAP],
    ("jaxbearing", "sweep", "--out"): ["test_sweep.py::test_no_resume_recomputes_every_batch"],
    ("jaxbearing", "sweep", "--batch-size"): [
        "test_sweep.py::test_dry_run_lists_the_axes_and_computes_nothing"
    ],
    ("jaxbearing", "sweep", "--resume"): ["test_sweep.py::test_kill_and_resume"],
    ("jaxbearing", "sweep", "--no-resume"): ["test_sweep.py::test_no_resume_recomputes_every_batch"],
    ("jaxbearing", "sweep", "--coordinator"): [_TWO_PROCESSES],
    ("jaxbearing", "sweep", "--num-processes"): [_TWO_PROCESSES],
    ("jaxbearing", "sweep", "--process-id"): [_TWO_PROCESSES],
    ("jaxbearing", "sweep", "--wait-timeout-s"): ["test_sweep.py::test_wait_timeout_names_the_missing_batch"],
    ("jaxbearing", "sweep", "--wait-for-lock"): [
        "test_hardening.py::test_wait_for_lock_option_waits_for_the_other_sweep"
    ],
    ("jaxbearing", "sweep", "--dry-run"): ["test_sweep.py::test_dry_run_lists_the_axes_and_computes_nothing"],
    ("jaxbearing", "sweep", "--workers"): ["test_sweep.py::test_kill_and_resume"],
    ("jaxbearing", "sweep", "--no-progress"): ["test_sweep.py::test_no_resume_recomputes_every_batch"],
    ("jaxbearing", "plot", "--out"): ["test_sweep.py::test_plot_draws_every_figure_from_assembled_batches"],
    ("optimise", "run", "--config"): [_STEADY_CLI],
    ("optimise", "run", "--bounds"): [_OPT_FILE],
    ("optimise", "run", "--end-radius-mm"): ["test_optimise.py::test_cli_no_feasible_design_exits_nonzero"],
    ("optimise", "run", "--layback-deg"): [_OPT_FILE],
    ("optimise", "run", "--clearance-mm"): [_STEADY_CLI, "test_optimise.py::test_cli_end_to_end"],
    ("optimise", "run", "--min-clearance-mm"): [_OPT_FILE],
    ("optimise", "run", "--min-film-parameter"): [
        "test_optimise_profile.py::test_cli_limits_reach_the_settings"
    ],
    ("optimise", "run", "--max-friction-power-W"): [
        "test_optimise_profile.py::test_cli_limits_reach_the_settings"
    ],
    ("optimise", "run", "--max-flash-temperature-K"): [
        "test_optimise_profile.py::test_cli_limits_reach_the_settings"
    ],
    **{
        ("optimise", "run", option): ["test_optimise_profile.py::test_cli_profile_options_reach_the_problem"]
        for option in (
            "--profile",
            "--end-offset-mm",
            "--corner-radius-mm",
            "--rib-curvature-per-m",
            "--rib-tangent-height-mm",
            "--flange-height-mm",
        )
    },
    ("optimise", "run", "--flange-load-N"): [_OPT_FILE],
    ("optimise", "run", "--speeds-rpm"): [_OPT_FILE],
    ("optimise", "run", "--loads-N"): [_OPT_FILE],
    ("optimise", "run", "--weights"): [_OPT_FILE],
    ("optimise", "run", "--aggregate"): [_OPT_FILE],
    ("optimise", "run", "--objective"): [_OPT_FILE, "test_optimise.py::test_cli_end_to_end"],
    ("optimise", "run", "--starts"): [_STEADY_CLI, "test_optimise.py::test_cli_end_to_end"],
    ("optimise", "run", "--iterations"): [_STEADY_CLI, "test_optimise.py::test_cli_end_to_end"],
    ("optimise", "run", "--learning-rate"): [_OPT_FILE],
    ("optimise", "run", "--seeds"): [_STEADY_CLI],
    ("optimise", "run", "--window-revs"): [_STEADY_CLI],
    ("optimise", "run", "--settle"): [_STEADY_CLI],
    ("optimise", "run", "--gradient-window-ms"): [_STEADY_CLI],
    ("optimise", "run", "--estimator"): [_STEADY_CLI],
    ("optimise", "run", "--corner-margin-mm"): [_STEADY_CLI],
    ("optimise", "run", "--clearance-step-mm"): [_STEADY_CLI],
    ("optimise", "run", "--corner-constraint"): [_STEADY_CLI],
    ("optimise", "run", "--choose"): [_STEADY_CLI],
    ("optimise", "run", "--skip-weight"): [_STEADY_CLI],
    ("optimise", "run", "--recheck-every"): [_STEADY_CLI],
    ("optimise", "run", "--statistic"): [_STEADY_CLI],
    ("optimise", "run", "--verify-seeds"): [
        "test_optimise_steady.py::test_verify_seeds_option_reaches_the_verification"
    ],
    ("optimise", "run", "--uncertain-constants"): [
        "test_optimise_steady.py::test_uncertain_constants_run_every_point_at_every_corner"
    ],
    ("optimise", "run", "--corner-risk-level"): [
        "test_optimise_steady.py::test_tail_verification_needs_the_risk_bounded_at_every_operating_point"
    ],
    ("optimise", "run", "--no-verify"): [_STEADY_CLI],
    ("optimise", "run", "--workers"): [_STEADY_CLI],
    ("optimise", "run", "--duration-ms"): [_OPT_FILE, "test_optimise.py::test_cli_end_to_end"],
    ("optimise", "run", "--rtol"): [_OPT_FILE],
    ("optimise", "run", "--atol"): [_OPT_FILE],
    ("optimise", "run", "--out"): [_OPT_FILE, "test_optimise.py::test_cli_end_to_end"],
    ("optimise", "run", "--quiet"): [_STEADY_CLI],
}


def _options(parser: argparse.ArgumentParser, command: tuple[str, ...] = ()):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _options(sub, (*command, name))
        else:
            for option in action.option_strings:
                if option not in ("-h", "--help"):
                    yield " ".join(command), option


def _parser_options() -> set[tuple[str, str, str]]:
    from jaxbearing.cli._main import build_parser
    from optimise._cli import build_parser as build_optimise_parser

    return {("jaxbearing", c, o) for c, o in _options(build_parser())} | {
        ("optimise", c, o) for c, o in _options(build_optimise_parser())
    }


def _test_sources() -> dict[str, str]:
    """file::name -> the source of the test, of the fixtures of its file it takes and of the
    module-level functions and constants it names."""
    out = {}
    for path in TEST_FILES:
        text = path.read_text()
        tree = ast.parse(text)
        top = {}
        for node in tree.body:
            if isinstance(node, ast.FunctionDef):
                top[node.name] = ast.get_source_segment(text, node)
            elif isinstance(node, ast.Assign):
                for target in node.targets:
                    if isinstance(target, ast.Name):
                        top[target.id] = ast.get_source_segment(text, node)
        for fn in _tests(tree):
            used = {n.id for n in ast.walk(fn) if isinstance(n, ast.Name)} | {a.arg for a in fn.args.args}
            parts = [ast.get_source_segment(text, fn)] + [top[u] for u in sorted(used) if u in top]
            out[f"{path.name}::{fn.name}"] = "\n".join(parts)
    return out


def test_every_cli_option_is_invoked_by_a_named_test():
    options = _parser_options()
    assert not options - set(CLI_CHECKS), f"options no test invokes: {sorted(options - set(CLI_CHECKS))}"
    assert not set(CLI_CHECKS) - options, (
        f"checks of options that no longer exist: {set(CLI_CHECKS) - options}"
    )
    sources = _test_sources()
    for (_, _, option), tests in CLI_CHECKS.items():
        for ref in tests:
            assert ref in sources, f"{ref} (for {option}) does not exist"
            assert f'"{option}"' in sources[ref], f"{ref} does not invoke {option}"


def test_the_scheduling_tables_name_test_files():
    """`conftest.FILE_SECONDS` and `conftest.PROGRAM_GROUPS` name existing test files (a renamed
    file would silently drop out of the ordering or out of its group), each file in one group."""
    from conftest import FILE_SECONDS, PROGRAM_GROUPS

    names = {p.name for p in TEST_FILES}
    grouped = [name for group in PROGRAM_GROUPS for name in group]
    assert len(grouped) == len(set(grouped))
    named = set(FILE_SECONDS) | set(grouped)
    assert named <= names, named - names


#: history in library code: a date, an issue or work-item number, a path into the one-off studies
_HISTORY = (r"\b20\d\d-\d\d-\d\d\b", r"\b[Ii]ssue #?\d+", r"\bwork item\b", r"benchmarks/studies/")


def _library_history(text: str) -> list[str]:
    import re

    return [line.strip() for line in text.splitlines() if any(re.search(p, line) for p in _HISTORY)]


def test_library_code_carries_no_history():
    """Docstrings and comments of the library say what and why, never when or in which work item:
    no date, issue number or path into benchmarks/studies/ in jaxbearing/ or optimise/ (history
    is the changelog's and git's). The example header of a measurements file is data."""
    root = TESTS.parent
    found = {}
    for path in sorted(
        [*root.joinpath("jaxbearing").rglob("*.py"), *root.joinpath("optimise").rglob("*.py")]
    ):
        lines = _library_history(path.read_text())
        if path.name == "_measurements.py":
            lines = [line for line in lines if not line.startswith("# test rig")]
        if path.name == "_steady.py" and path.parent.name == "optimise":
            lines = [line for line in lines if '"study": ' not in line]  # the clearance study's record
        if lines:
            found[str(path.relative_to(root))] = lines
    assert not found, found
    study = "benchmarks/" + "studies/a_study"
    assert _library_history(f"measured 2026-11-26 (issue 13)\n{study}\nplain") == [
        "measured 2026-11-26 (issue 13)",
        study,
    ]
