"""Issue 38, item 1: no file the project reads back can run code.

A crafted pickle (one that writes a marker file when unpickled) is planted wherever the project
reads a file back: the stored programs of the compile cache, the optimiser's checkpoints (steady
search and grid, the old `checkpoint.pkl` name included), the sweep's batch files, spec.json,
sweep.log, results.nc and lock file, the TOML inputs (configuration, sweep spec, optimiser file)
and the benchmarks' resume states (`jaxbearing.io.load_tree`). Each is refused in one line
naming the file (or, for the cache, treated as a miss with a warning), and the marker never
appears. Every check runs before any solve (seconds)."""

from __future__ import annotations

import ast
import pathlib
import pickle

import numpy as np
import pytest

from jaxbearing import UserInputError
from jaxbearing.io import TreeFileError, check_like, load_config, load_tree, save_tree

ROOT = pathlib.Path(__file__).resolve().parents[1]


class _Payload:
    """Unpickling this calls `Path(marker).write_text("pwned")`."""

    def __init__(self, marker: pathlib.Path):
        self.marker = marker

    def __reduce__(self):
        return (pathlib.Path(self.marker).write_text, ("pwned",))


def crafted(marker: pathlib.Path) -> bytes:
    return pickle.dumps(_Payload(marker))


@pytest.fixture
def plant(tmp_path):
    """plant(path) writes the crafted pickle at `path`; returns the marker it would create."""
    marker = tmp_path / "MARKER"

    def put(path: pathlib.Path) -> pathlib.Path:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(crafted(marker))
        return marker

    return put


def test_the_crafted_pickle_really_runs_code(tmp_path):
    """The test's payload is live: unpickling it creates the marker (so its absence below means
    the file was never unpickled)."""
    marker = tmp_path / "live"
    pickle.loads(crafted(marker))
    assert marker.read_text() == "pwned"


def _one_line(exc: BaseException, path: pathlib.Path) -> str:
    text = str(exc)
    assert "\n" not in text and str(path) in text, text
    return text


def test_load_tree_refuses_a_pickle_in_one_line(tmp_path, plant):
    path = tmp_path / "state.npz"
    marker = plant(path)
    with pytest.raises(TreeFileError) as e:
        load_tree(path, what="benchmark state")
    assert "not a benchmark state" in _one_line(e.value, path)
    assert not marker.exists()


def test_load_tree_round_trip_and_shape_check(tmp_path):
    import equinox as eqx
    import jax.numpy as jnp
    import optax

    from jaxbearing.dynamics import State  # noqa: F401 - a registered module class

    class _Local(eqx.Module):  # not importable by name: refused on load
        a: object

    tree = {
        "u": np.arange(6.0).reshape(2, 3),
        "opt": optax.adam(0.1).init(jnp.zeros(3)),
        (0, 1): [None, 1, 2.5, float("nan"), "s", (True, np.float32(3.0))],
    }
    path = tmp_path / "t.npz"
    save_tree(path, tree)
    back = load_tree(path)
    assert set(back) == set(tree) and back[(0, 1)][:3] == [None, 1, 2.5]
    assert np.isnan(back[(0, 1)][3]) and back[(0, 1)][5][1].dtype == np.float32
    check_like(back["opt"], tree["opt"], path)
    with pytest.raises(TreeFileError, match="shape"):
        check_like(np.zeros(4), np.zeros(3), path)
    save_tree(path, {"x": _Local(np.zeros(2))})
    with pytest.raises(TreeFileError, match="unknown class"):
        load_tree(path)
    with pytest.raises(TypeError):
        save_tree(path, {"x": np.array([object()])})
    # a class from outside jaxbearing, optimise and optax (here the standard library's) is
    # refused by name even though it is imported and a plain named tuple
    import inspect

    save_tree(path, {"x": inspect.getfullargspec(save_tree)})
    with pytest.raises(TreeFileError, match="unknown class"):
        load_tree(path)


def test_compile_cache_never_unpickles_a_planted_program(tmp_path, plant, monkeypatch):
    """A pickle at a stored program's path is a cache miss: removed, with a warning; the
    program is built again (here: `_load` returns None)."""
    from jaxbearing.run import _compile_cache as cc

    path = tmp_path / "programs" / "simulate-0123.jaxexport"
    marker = plant(path)
    with pytest.warns(UserWarning, match="not a stored program"):
        assert cc._load(path) is None
    assert not marker.exists() and not path.exists()


def test_steady_checkpoints_refuse_a_planted_pickle(tmp_path, plant):
    import optimise._state as steady

    for name in ("checkpoint.npz", "grid_checkpoint.npz"):
        path = tmp_path / name
        marker = plant(path)
        with pytest.raises(UserInputError) as e:
            steady.load_checkpoint(path)
        assert "not a checkpoint" in _one_line(e.value, path)
        assert not marker.exists()
    for name in ("checkpoint.pkl", "grid_checkpoint.pkl"):
        path = tmp_path / name
        marker = plant(path)
        with pytest.raises(UserInputError) as e:
            steady.refuse_legacy(path)
        assert "older version" in _one_line(e.value, path)
        assert not marker.exists()


def test_steady_checkpoint_of_the_wrong_shape_is_refused(tmp_path):
    import dataclasses

    import optimise._state as steady
    from optimise._envelope import Envelope

    template = steady.SearchState(
        iteration=-1,
        u=np.zeros((2, 3)),
        opt=[],
        lam=np.zeros((2, 5)),
        chains=[None, None],
        history=steady.History(),
        evaluations=0,
        envelope=Envelope.fresh(2, 1),
    )
    path = tmp_path / "checkpoint.npz"
    wrong = dataclasses.replace(template, u=np.zeros((3, 3)))
    with pytest.raises(TreeFileError, match="shape"):
        steady.checked_state(path, wrong, template, 4)
    with pytest.raises(UserInputError, match="its fields differ"):
        steady.checked_state(path, {"u": 1}, template, 4)
    with pytest.raises(UserInputError, match="iteration"):
        steady.checked_state(path, dataclasses.replace(template, iteration=9), template, 4)


def test_optimise_run_refuses_a_planted_checkpoint_in_one_line(tmp_path, plant, capsys):
    """Through the command line, before any evaluation: exit 2, one line naming the file."""
    from optimise._cli import main

    for name in ("checkpoint.pkl", "checkpoint.npz"):
        out = tmp_path / name.replace(".", "_")
        marker = plant(out / name)
        code = main(
            ["run", "--starts", "1", "--iterations", "1", "--workers", "1", "--no-verify", "--out", str(out)]
        )
        err = capsys.readouterr().err.strip()
        assert code == 2 and len(err.splitlines()) == 1 and str(out / name) in err, err
        assert not marker.exists()


def test_sweep_files_refuse_a_planted_pickle(tmp_path, plant):
    from jaxbearing.sweep import _storage
    from jaxbearing.sweep._dataset import open_results
    from jaxbearing.sweep._spec import SweepSpecError

    out = tmp_path / "sweep"
    # a batch file: does not load (never unpickled), so it is set aside and computed again
    batch = _storage.batch_path(out, 0)
    marker = plant(batch)
    with pytest.raises(_storage.DamagedBatch):
        _storage.load_batch_file(batch)
    moved = _storage.set_aside_damaged(out, [0])
    assert len(moved) == 1 and not batch.exists()
    # the log: lines that are not JSON records are skipped
    plant(out / "sweep.log")
    assert _storage.computed_batches(out) == []
    # spec.json: one line naming the file
    plant(out / "spec.json")
    with pytest.raises(SweepSpecError) as e:
        _storage.load_spec_from_dir(out)
    _one_line(e.value, out / "spec.json")
    # results.nc: one line naming the file
    plant(out / "results.nc")
    with pytest.raises(UserInputError) as e:
        open_results(out)
    assert "not a sweep result file" in _one_line(e.value, out / "results.nc")
    assert not marker.exists()


def test_lock_file_holding_a_pickle_is_not_unpickled(tmp_path, plant):
    from jaxbearing.io._lock import _holder

    path = tmp_path / ".lock"
    marker = plant(path)
    assert _holder(path) == {}
    assert not marker.exists()


def test_toml_inputs_refuse_a_planted_pickle(tmp_path, plant):
    from jaxbearing.sweep import load_sweep_spec
    from optimise._toml import load_optimise_toml

    path = tmp_path / "input.toml"
    marker = plant(path)
    for load in (load_config, load_sweep_spec, load_optimise_toml):
        with pytest.raises(UserInputError) as e:
            load(path)
        assert "\n" not in str(e.value)
    assert not marker.exists()


def _imports_pickle(path: pathlib.Path) -> bool:
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(
            a.name in ("pickle", "dill", "cloudpickle") for a in node.names
        ):
            return True
        if isinstance(node, ast.ImportFrom) and node.module in ("pickle", "dill", "cloudpickle"):
            return True
        if (
            isinstance(node, ast.Call)
            and getattr(node.func, "attr", None) == "load"
            and any(
                k.arg == "allow_pickle" and getattr(k.value, "value", None) is True for k in node.keywords
            )
        ):
            return True
    return False


def test_no_pickle_import_on_any_load_path():
    """No module of the package, the optimiser or the benchmarks imports pickle (or loads an
    array with allow_pickle=True)."""
    files = [*ROOT.glob("jaxbearing/**/*.py"), *ROOT.glob("optimise/*.py"), *ROOT.glob("benchmarks/*.py")]
    assert len(files) > 50
    assert [str(p.relative_to(ROOT)) for p in files if _imports_pickle(p)] == []
