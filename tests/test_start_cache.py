"""The start cache (`jaxbearing.run._start_cache`): a stored skid start is the very start the
solve returns, bit for bit; its key moves with every input and setting of the solve; a member
whose pre-start is stored starts from it without integrating a burst; and a file that is not a
stored start is removed, never executed. At 11 slices, the `test_settle` configuration."""

import dataclasses
import pickle
import warnings

import jax
import numpy as np
import pytest

import jaxbearing as jb
import jaxbearing.run._initial as initial
import jaxbearing.run._start_cache as start_cache
from jaxbearing.dynamics import Functionals
from jaxbearing.run import Member, Perturbation, SteadySettings
from jaxbearing.run._member import member_steps, pre_start_key


@pytest.fixture
def starts(tmp_path, monkeypatch):
    """A start cache of this test's own (the compiled programs stay in the session's cache)."""
    monkeypatch.setattr(start_cache, "start_cache_dir", lambda: tmp_path / "starts")
    return tmp_path / "starts"


def _case(seed=0):
    b = dataclasses.replace(jb.reference_bearing(), num_slices=11)
    return b, jb.reference_operating_point(), Perturbation(seed=seed)


def _leaves(tree):
    return [np.asarray(x) for x in jax.tree_util.tree_leaves(tree)]


def test_a_stored_static_start_is_the_solved_one_bit_for_bit(starts, monkeypatch):
    b, op, p = _case()
    solved = initial._static_skid_start(b, op, p)  # solved (an empty cache), then stored
    (stored,) = starts.glob("static-*.start.npz")

    def no_solve(*args, **kwargs):
        raise AssertionError("a stored start was solved again")

    monkeypatch.setattr(initial, "compiled_program", no_solve)
    loaded = initial._static_skid_start(b, op, p)
    assert type(loaded) is type(solved) and jax.tree_util.tree_structure(
        loaded
    ) == jax.tree_util.tree_structure(solved)
    for a, c in zip(_leaves(loaded), _leaves(solved)):
        assert a.dtype == c.dtype and np.array_equal(a, c)
    assert loaded.plateau_speed == solved.plateau_speed and stored.stat().st_size > 0


def test_the_pre_start_key_moves_with_every_input_and_setting():
    """What the pre-start's integration depends on (`_solve_from._integrator`) is in its key."""
    b, op, p = _case()
    options = SteadySettings()
    base = pre_start_key(Member(b, op, p), options)
    changed = [
        pre_start_key(Member(b, op, Perturbation(seed=1)), options),
        pre_start_key(Member(b, op, dataclasses.replace(p, skew=2e-4)), options),
        pre_start_key(Member(dataclasses.replace(b, num_slices=13), op, p), options),
        pre_start_key(Member(b, op, p, rtol=5e-4), options),
        pre_start_key(Member(b, op, p), options.replace(atol=1e-7)),
        pre_start_key(Member(b, op, p), options.replace(saves_per_rev=options.saves_per_rev + 1)),
        pre_start_key(Member(b, op, p), options.replace(max_steps=options.max_steps + 1)),
        pre_start_key(Member(b, op, p), options.replace(solver="ros34pw2")),
        pre_start_key(
            Member(b, op, p),
            options.replace(functionals=Functionals(pv_exponent=1.0)),
        ),
    ]
    assert pre_start_key(Member(b, op, p), SteadySettings()) == base  # deterministic
    assert len({base, *changed}) == len(changed) + 1
    # not a setting of the pre-start: how the member settles and measures afterwards
    assert pre_start_key(Member(b, op, p), options.replace(window_revs=7, settle=0.5)) == base


def test_a_member_with_a_stored_pre_start_starts_from_it(starts):
    """The member's first integration request continues from the stored start: no pre-start
    burst is integrated (its first burst would start from the static state)."""
    b, op, p = _case()
    options = SteadySettings(settle=0.5, window_revs=2)
    member = Member(b, op, p)
    static = initial._static_skid_start(b, op, p)
    moved = initial.along_slow_mode(static.state, 1.0)
    stored = dataclasses.replace(static, state=moved, pre_start_status="ok", drift_speeds=(1.0, 2.0))
    start_cache.store_start("pre-start", pre_start_key(member, options), stored)
    state, duration = next(member_steps(member, options, stored_start=True))
    assert all(np.array_equal(a, c) for a, c in zip(_leaves(state), _leaves(moved)))
    assert duration == pytest.approx(0.5e-3)  # the settling, not a burst of 0.75 revolutions
    # without the cache (the vmapped path) the member integrates its pre-start from the static state
    state, duration = next(member_steps(member, options))
    assert all(np.array_equal(a, c) for a, c in zip(_leaves(state), _leaves(static.state)))
    assert duration == pytest.approx(0.75 * 2 * np.pi / abs(float(static.state.cage.speed)))


def test_a_file_that_is_not_a_start_is_removed_not_executed(starts, tmp_path):
    key = "0" * 40
    starts.mkdir()
    planted = starts / f"static-{key}.start.npz"
    marker = tmp_path / "ran"
    planted.write_bytes(pickle.dumps(eval, protocol=2) + str(marker).encode())
    with pytest.warns(UserWarning, match="not a stored skid start"):
        assert start_cache.load_start("static", key, initial.SkidStart) is None
    assert not planted.exists() and not marker.exists()
    # data, but not a skid start
    jb.io.save_tree(planted, {"state": np.zeros(3)})
    with pytest.warns(UserWarning, match="not a stored skid start"):
        assert start_cache.load_start("static", key, initial.SkidStart) is None
    assert not planted.exists()


def test_with_the_cache_off_nothing_is_stored(monkeypatch, tmp_path):
    monkeypatch.setattr(start_cache, "start_cache_dir", lambda: None)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        start_cache.store_start("static", "0" * 40, object())
        assert start_cache.load_start("static", "0" * 40, initial.SkidStart) is None
    assert list(tmp_path.iterdir()) == []
