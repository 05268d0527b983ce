"""Smoke test of the benchmark harness (benchmarks/): every module imports and exposes
`main(quick)`, the cheap self-checks pass, and the runner's discovery, JSON writing and failure
handling work. The benchmarks themselves are NOT run here (`make bench` runs them)."""

from __future__ import annotations

import inspect
import json
import math
import re
import sys
from pathlib import Path

import pytest

BENCH_DIR = Path(__file__).resolve().parents[1] / "benchmarks"
STUDIES_DIR = BENCH_DIR / "studies"
sys.path[:0] = [str(BENCH_DIR), str(STUDIES_DIR)]

import _common  # noqa: E402
import run_all  # noqa: E402

NAMES = run_all.discover()


def test_discovery_finds_this_issues_benchmarks():
    for name in ("bench_scipy", "bench_gradients", "bench_steady_engine"):
        assert name in NAMES


@pytest.mark.parametrize("name", NAMES)
def test_module_imports_and_has_main(name):
    module = run_all.load(name)
    params = inspect.signature(module.main).parameters
    assert "quick" in params, f"{name}.main must take `quick`"
    if hasattr(module, "self_check"):
        module.self_check()


@pytest.mark.parametrize("name", sorted(p.stem for p in STUDIES_DIR.glob("*.py")))
def test_study_imports_and_has_main(name):
    """The one-off studies under benchmarks/studies/ stay importable (their helpers come from
    benchmarks/)."""
    module = run_all.load(name, STUDIES_DIR)
    assert callable(getattr(module, "main", None)), f"studies/{name}.py must define main"


def test_benchmarks_top_level_holds_only_maintained_scripts():
    """At most 12 scripts at benchmarks/' top level: the runner, its helpers, every `bench_*` of
    `make bench`, and any other script documented in benchmarks/README.md as maintained."""
    scripts = sorted(p.name for p in BENCH_DIR.glob("*.py"))
    assert len(scripts) <= 12, scripts
    readme = (BENCH_DIR / "README.md").read_text()
    for name in scripts:
        if name in ("run_all.py", "_common.py") or name[:-3] in NAMES:
            continue
        assert f"`{name}`" in readme, f"{name}: neither in make bench nor documented as maintained"
    index = (STUDIES_DIR / "README.md").read_text()
    for p in STUDIES_DIR.glob("*.py"):
        assert f"`{p.name}`" in index, f"studies/{p.name} is missing from benchmarks/studies/README.md"


def test_every_results_file_has_the_script_that_writes_it():
    """benchmarks/results/ holds results only (no patches), each named after the script that
    writes it, or listed with its command in benchmarks/README.md's results table or in
    benchmarks/studies/README.md's index of removed studies."""
    readme = (BENCH_DIR / "README.md").read_text() + (STUDIES_DIR / "README.md").read_text()
    scripts = [p.stem for d in (BENCH_DIR, STUDIES_DIR) for p in d.glob("*.py")]
    writers = {
        "throughput": "bench_throughput",
        "gradients": "bench_gradients",
    }
    for path in sorted((BENCH_DIR / "results").iterdir()):
        assert path.suffix == ".json", f"{path.name}: not a results file"
        stem = path.stem
        named = any(stem == s or stem.startswith(s + "_") for s in scripts) or stem in writers
        if stem.startswith("accelerator_"):
            named = "accelerator_throughput" in scripts
        assert named or f"`{path.name}`" in readme, f"{path.name}: no script writes it"
    for stem, script in writers.items():
        assert script in scripts
    index = (STUDIES_DIR / "README.md").read_text()
    for name in re.findall(r"`([\w.-]+\.json)`", index):
        assert (BENCH_DIR / "results" / name).exists(), (
            f"benchmarks/studies/README.md names {name}: not in results/"
        )


def test_write_json_is_strict_json_with_machine_info(tmp_path):
    import numpy as np

    path = _common.write_json(
        "demo",
        {"x": np.float64(1.5), "a": np.arange(3), "nan": math.nan, "inf": math.inf},
        results_dir=tmp_path,
    )
    data = json.loads(path.read_text())
    assert data["x"] == 1.5 and data["a"] == [0, 1, 2] and data["nan"] is None and data["inf"] == "inf"
    assert data["benchmark"] == "demo"
    assert data["machine"]["cpu_count"] >= 1 and data["machine"]["jax"]
    assert not list(tmp_path.glob("*.tmp"))


def test_format_table_and_target():
    text = _common.format_table("T", ["a", "b"], [[1, 2.5], ["x", None]])
    assert text.splitlines()[0] == "T" and "2.5" in text and "-" in text
    assert _common.target("t", 3.0, 2.0, higher_is_better=True)["reached"]
    assert not _common.target("t", 0.5, 0.3, higher_is_better=False)["reached"]
    assert not _common.target("t", math.nan, 0.3, higher_is_better=False)["reached"]


def test_runner_records_failure_and_continues(tmp_path, monkeypatch):
    """A failing benchmark is recorded, the next one still runs, and the exit code is 1."""
    (tmp_path / "bench_a_fails.py").write_text("def main(quick=False):\n    raise ValueError('boom')\n")
    (tmp_path / "bench_b_ok.py").write_text(
        "def main(quick=False):\n    return {'table': 'B', 'targets': {'t': {'target': 't', 'measured': 1.0,"
        " 'threshold': 0.5, 'reached': True}}}\n"
    )
    results = tmp_path / "results"
    monkeypatch.setattr(_common, "RESULTS_DIR", results)
    monkeypatch.setattr(run_all, "discover", lambda bench_dir=tmp_path: ["bench_a_fails", "bench_b_ok"])

    def run_one(name, quick, timeout):  # in-process stand-in for the subprocess
        status_file = tmp_path / f"{name}.status"
        monkeypatch.setattr(run_all, "load", lambda n, bench_dir=tmp_path: _load(n, tmp_path))
        run_all._child(name, quick, str(status_file))
        return json.loads(status_file.read_text())

    monkeypatch.setattr(run_all, "run_one", run_one)
    assert run_all.main(["--quick"]) == 1
    summary = json.loads((results / "summary.json").read_text())
    assert summary["failed"] == ["bench_a_fails"]
    assert "boom" in summary["benchmarks"]["bench_a_fails"]["error"]
    assert summary["benchmarks"]["bench_b_ok"]["ok"]
    assert summary["targets"]["bench_b_ok.t"]["reached"]
    assert json.loads((results / "bench_b_ok.json").read_text())["table"] == "B"  # written by the runner


def _load(name, directory):
    import importlib.util

    spec = importlib.util.spec_from_file_location(name, directory / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_only_rejects_unknown_names(capsys):
    assert run_all.main(["--only", "no_such_bench"]) == 2
    assert "unknown benchmark" in capsys.readouterr().err


def test_long_studies_declare_their_own_time_limit():
    assert run_all.timeout_for("bench_work_precision_settled", quick=False) == 2400
    assert run_all.timeout_for("bench_work_precision_settled", quick=True) == run_all.DEFAULT_TIMEOUT_S[True]
    assert run_all.timeout_for("bench_scipy", quick=False) == run_all.DEFAULT_TIMEOUT_S[False]


def test_accelerator_throughput_checks_its_arguments_and_needs_an_accelerator(capsys, monkeypatch):
    import accelerator_throughput as at

    for argv in (["--sizes", "0,8"], ["--sizes", "a"], ["--cpu-sizes", "8"], ["--members", "0"]):
        with pytest.raises(SystemExit) as exc:
            at._parse(argv)
        assert exc.value.code == 2
        assert argv[0] in capsys.readouterr().err
    monkeypatch.delenv("JAXBEARING_BENCH_GPU_ON_CPU", raising=False)
    if at.accelerator() is None:
        with pytest.raises(at.UsageError, match="no accelerator"):
            at.main()


def test_accelerator_throughput_copies_differ_by_the_nudge_alone():
    import accelerator_throughput as at
    import jax
    import numpy as np

    import jaxbearing as jb
    from jaxbearing.run import initial_state

    bearing = jb.reference_bearing()
    shape = jax.eval_shape(lambda: initial_state(bearing, jb.reference_operating_point(), None))
    state = jax.tree_util.tree_map(lambda s: np.ones(s.shape, s.dtype), shape)
    copies = at._copies(state, 3)
    axial = np.asarray(copies.rollers.axial)
    assert axial.shape == (3, bearing.num_rollers)
    np.testing.assert_array_equal(axial[0], 1.0)  # copy 0 is the state itself
    assert 0 < np.max(np.abs(axial[1:] - 1.0)) <= at.COPY_NUDGE
    assert not np.array_equal(axial[1], axial[2])
    # every other coordinate is the state's, in every copy
    nudged = jax.tree_util.tree_map(lambda _: False, copies)
    nudged = _mark_axial(nudged)
    for leaf, ref, is_axial in zip(
        jax.tree_util.tree_leaves(copies),
        jax.tree_util.tree_leaves(state),
        jax.tree_util.tree_leaves(nudged),
        strict=True,
    ):
        if not is_axial:
            np.testing.assert_array_equal(np.asarray(leaf), np.broadcast_to(ref, np.shape(leaf)))


def _mark_axial(tree):
    """`tree` with the roller axial-position leaf set to True."""
    import equinox as eqx

    return eqx.tree_at(lambda t: t.rollers.axial, tree, True)
