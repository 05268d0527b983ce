"""Programs traced once per machine (`jaxbearing.run.compiled_program`, issue 12 item 5): a second
process loads the `jax.export` artefact instead of tracing. A "second process" is simulated by
forgetting the in-process programs; whether the function was traced is counted at trace time."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxbearing.run import _compile_cache as cc


class Pair(eqx.Module):
    a: jax.Array
    b: jax.Array


@pytest.fixture
def programs(monkeypatch, tmp_path):
    """An empty program directory and no program in memory; `Pair`, a class of this test module,
    may be named by a stored program (only jaxbearing's, optimise's and optax's classes may be
    otherwise: `jaxbearing.io._tree.TRUSTED_PACKAGES`)."""
    from jaxbearing.io import _tree

    monkeypatch.setattr(_tree, "TRUSTED_PACKAGES", (*_tree.TRUSTED_PACKAGES, Pair.__module__))
    monkeypatch.setattr(cc, "program_cache_dir", lambda: tmp_path / "programs")
    monkeypatch.setattr(cc, "_PROGRAMS", {})
    return tmp_path / "programs"


def _traced_counter():
    calls = []

    def fn(pair: Pair, scale):
        calls.append(1)  # runs at trace time only
        return Pair(a=jnp.sin(pair.a) * scale, b=pair.b @ pair.b), {"sum": jnp.sum(pair.a)}

    return fn, calls


ARGS = (Pair(a=jnp.linspace(0.0, 1.0, 5), b=jnp.eye(3) * 2.0), 3.0)


def _expected():
    a, b = ARGS[0].a, ARGS[0].b
    return np.sin(a) * 3.0, b @ b, np.sum(a)


def _check(out):
    pair, extra = out
    sin_a, bb, s = _expected()
    assert isinstance(pair, Pair)
    np.testing.assert_allclose(pair.a, sin_a, rtol=1e-15)
    np.testing.assert_allclose(pair.b, bb, rtol=1e-15)
    np.testing.assert_allclose(extra["sum"], s, rtol=1e-15)


def test_second_process_loads_the_program_without_tracing(programs, monkeypatch):
    fn, calls = _traced_counter()
    first = cc.compiled_program("demo", fn, ARGS, static=("k", 1))
    _check(first(*ARGS))
    assert first.exported and len(calls) == 1
    assert len(list(programs.glob("demo-*.jaxexport"))) == 1

    monkeypatch.setattr(cc, "_PROGRAMS", {})  # a new process: nothing in memory
    second = cc.compiled_program("demo", fn, ARGS, static=("k", 1))
    _check(second(*ARGS))
    assert second.exported and len(calls) == 1  # not traced again

    assert cc.compiled_program("demo", fn, ARGS, static=("k", 1)) is second  # once per process


def test_other_static_arguments_or_shapes_make_another_program(programs):
    fn, calls = _traced_counter()
    cc.compiled_program("demo", fn, ARGS, static=1)
    cc.compiled_program("demo", fn, ARGS, static=2)
    longer = (Pair(a=jnp.zeros(6), b=jnp.eye(3)), 1.0)
    cc.compiled_program("demo", fn, longer, static=1)
    assert len(calls) == 3
    assert len(list(programs.glob("demo-*.jaxexport"))) == 3


def test_damaged_program_file_is_built_again(programs, monkeypatch):
    fn, calls = _traced_counter()
    cc.compiled_program("demo", fn, ARGS)
    (path,) = programs.glob("demo-*.jaxexport")
    path.write_bytes(b"cut short")
    monkeypatch.setattr(cc, "_PROGRAMS", {})
    with pytest.warns(UserWarning, match="not a stored program.*removed, the program is built again"):
        program = cc.compiled_program("demo", fn, ARGS)
    _check(program(*ARGS))
    assert len(calls) == 2
    assert path.stat().st_size > 100  # stored whole again


def test_program_with_a_host_callback_is_compiled_as_usual_from_one_trace(programs):
    calls = []

    def fn(x):
        calls.append(1)
        jax.debug.callback(lambda v: None, x)
        return 2 * x

    program = cc.compiled_program("callback", fn, (jnp.arange(3.0),))
    np.testing.assert_array_equal(program(jnp.arange(3.0)), [0.0, 2.0, 4.0])
    assert not program.exported
    assert len(calls) == 1  # the failed export's trace is reused
    assert not list(programs.glob("*.jaxexport"))


def test_least_recently_used_programs_are_evicted_beyond_the_bound(tmp_path):
    """`_evict`: oldest first until the folder fits; the program just stored stays even when it
    is the oldest; other files are not touched."""
    import os

    paths = [tmp_path / f"p{i}.jaxexport" for i in range(4)]
    for i, path in enumerate(paths):
        path.write_bytes(b"x" * 100)
        os.utime(path, (1000 + i, 1000 + i))
    other = tmp_path / "notes.txt"
    other.write_bytes(b"y" * 1000)
    cc._evict(tmp_path, keep=paths[0], max_bytes=250)
    assert [p.exists() for p in paths] == [True, False, False, True]
    assert other.exists()


def test_loading_a_program_marks_it_used(programs):
    """A program read by a second process becomes the most recently used (`_load` touches it)."""
    import os

    cc.compiled_program("touch", _traced_counter()[0], ARGS)
    (path,) = programs.glob("touch-*.jaxexport")
    os.utime(path, (1000, 1000))
    cc._PROGRAMS.clear()
    cc.compiled_program("touch", _traced_counter()[0], ARGS)
    assert path.stat().st_mtime > 1e9


def test_cache_off_stores_nothing(monkeypatch):
    monkeypatch.setattr(cc, "program_cache_dir", lambda: None)
    monkeypatch.setattr(cc, "_PROGRAMS", {})
    fn, calls = _traced_counter()
    program = cc.compiled_program("demo", fn, ARGS)
    _check(program(*ARGS))
    assert not program.exported


def test_a_genuine_error_of_the_function_is_raised(programs):
    def fn(x):
        raise ValueError("bad model input")

    with pytest.raises(ValueError, match="bad model input"):
        cc.compiled_program("broken", fn, (jnp.zeros(2),))


def test_simulate_in_a_second_process_is_not_traced():
    """The library end to end: a second process pointed at this process's cache directory loads
    `simulate`'s stored program (no trace of the vector field) and gives this process's numbers.
    This process is the first: it stores the program, or finds it stored (the full-size
    `simulate` with 4000 saves, which tests/test_cmd_simulate.py compiles and
    conftest.PROGRAM_GROUPS shares), so the test compiles nothing of its own. The second process
    then traces the vector field once on purpose (`jax.eval_shape`, no compilation): the trace
    counter works, so its zero for `simulate` means the program was loaded."""
    import jaxbearing as jb

    directory = cc.program_cache_dir()
    if directory is None:
        pytest.skip("the program cache is off (JAXBEARING_CACHE_DIR)")
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    here = np.asarray(jb.simulate(b, op, duration=2e-6, num_saves=4000).histories["cage_speed"])
    assert any(directory.glob("simulate-*"))
    script = textwrap.dedent(
        """
        import json
        import jax
        import numpy as np
        import jaxbearing as jb
        from jaxbearing.dynamics import Params, _field
        from jaxbearing.run import initial_state

        traces = []
        original = _field._roller_rates
        _field._roller_rates = lambda *a: (traces.append(1), original(*a))[1]
        b, op = jb.reference_bearing(), jb.reference_operating_point()
        r = jb.simulate(b, op, duration=2e-6, num_saves=4000)
        loaded = len(traces)
        jax.eval_shape(lambda: _field.physical_rates(0.0, initial_state(b, op, None), Params(b, op)))
        print(json.dumps({"traces": loaded, "counted": len(traces) - loaded,
                          "cage": np.asarray(r.histories["cage_speed"]).tolist()}))
        """
    )
    # this process's cache directory and XLA flags (in `make test` the older CPU emitters): JAX's
    # persistent cache keys its entries on the flags
    env = {
        "JAXBEARING_CACHE_DIR": str(directory.parent),
        "PATH": "/usr/bin:/bin",
        "HOME": os.environ.get("HOME", "/tmp"),
        "XLA_FLAGS": os.environ.get("XLA_FLAGS", ""),
    }
    done = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr[-2000:]
    second = json.loads(done.stdout.strip().splitlines()[-1])
    assert second["counted"] >= 1  # a trace of the field is counted
    assert second["traces"] == 0  # simulate's was not: its program was loaded
    assert np.array_equal(np.asarray(second["cage"]), here)


def test_design_jacobian_with_concrete_values_uses_a_stored_program(monkeypatch):
    """Concrete arguments go through `compiled_program` (its values are those of the traced
    path, which tests/test_design.py checks against central differences); under jit they do not."""
    import jaxbearing as jb
    from jaxbearing.design import _design
    from jaxbearing.flange import DesignVariables

    seen = []

    def stand_in(name, fn, args, static=()):
        seen.append((name, static))
        return lambda *a: "stored program"

    monkeypatch.setattr(_design, "compiled_program", stand_in)
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    design = DesignVariables.of(b)
    assert jb.design_jacobian(b, op, design, duration=1e-4, max_steps=10) == "stored program"
    assert seen[0][0] == "design_jacobian" and seen[0][1][0] == "forward"
    traced = jax.eval_shape(
        lambda x: jb.design_jacobian(b, op, DesignVariables.from_array(x), duration=1e-4), design.as_array()
    )
    assert len(seen) == 1 and traced[1].shape == (3, 3)
