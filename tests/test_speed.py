"""Speed machinery of issue 12: the error norm of `solve`, the cacheable solve program (no host
callbacks; that failures still reach `status` is tests/test_dynamics.py's forced-failure test),
the compilation-cache switch and the process pool. The speed itself is measured by
benchmarks/ (bench_work_precision, bench_compile_cache, bench_ensemble), not here."""

from __future__ import annotations

import inspect
import operator
import os

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
import pytest

import jaxbearing as jb
from jaxbearing import UserInputError
from jaxbearing.run import (
    CACHE_ENV,
    RacewayNormalNorm,
    parallel_map,
    raceway_normal_norm,
)
from jaxbearing.run._compile_cache import (
    MIN_COMPILE_TIME_ENV,
    cache_dir_from_environment,
    default_cache_dir,
    enable_compilation_cache,
)
from jaxbearing.run._initial import kinematic_start


def _random_state(z=5):
    from jaxbearing.dynamics import state_scales

    template = state_scales(z, 0.05)
    leaves, treedef = jax.tree_util.tree_flatten(template)
    keys = jax.random.split(jax.random.PRNGKey(0), len(leaves))
    return jax.tree_util.tree_unflatten(
        treedef, [jax.random.normal(k, x.shape) for k, x in zip(keys, leaves)]
    )


def test_raceway_normal_norm_max_kind_is_the_max_norm_with_radial_tolerances_loosened():
    x = _random_state()
    assert float(raceway_normal_norm(x, 1.0, "max", 1.0)(x)) == float(optx.max_norm(x))
    norm = raceway_normal_norm(x, 100.0, "max", 1.0)
    assert isinstance(norm, RacewayNormalNorm)
    # a huge radial-velocity error of one roller counts 1/100
    big = jax.tree_util.tree_map(jnp.zeros_like, x)
    big = eqx.tree_at(lambda s: s.rollers.radial_velocity, big, jnp.zeros(5).at[2].set(50.0))
    np.testing.assert_allclose(float(norm(big)), 0.5)
    # an axial (flange-side) error counts in full
    big = eqx.tree_at(lambda s: s.rollers.axial, big, jnp.zeros(5).at[0].set(3.0))
    np.testing.assert_allclose(float(norm(big)), 3.0)


def test_rms_kind_is_the_rms_norm_over_the_bodies_coordinates():
    """sqrt(sum (w_i x_i)^2 / N) over the N coordinates of the rollers, cage and inner ring (not
    the accumulators); zero derivative at zero error."""
    x = _random_state()
    bodies = (x.rollers, x.cage, x.inner_ring)
    n = sum(v.size for v in jax.tree_util.tree_leaves(bodies))
    assert n == 12 * 5 + 16
    rms = raceway_normal_norm(x, 1.0, "rms", 1.0)
    np.testing.assert_allclose(float(rms(x)), float(optx.rms_norm(bodies)), rtol=1e-14)
    acc = eqx.tree_at(lambda s: s.accumulators, x, jax.tree_util.tree_map(lambda a: 1e3 * a, x.accumulators))
    assert float(rms(acc)) == float(rms(x))
    norm = raceway_normal_norm(x, 100.0, "rms", 1.0)
    zero = jax.tree_util.tree_map(jnp.zeros_like, x)
    one = eqx.tree_at(lambda s: s.rollers.radial_velocity, zero, jnp.zeros(5).at[2].set(50.0))
    one = eqx.tree_at(lambda s: s.rollers.axial, one, jnp.zeros(5).at[0].set(3.0))
    np.testing.assert_allclose(float(norm(one)), np.sqrt((0.5**2 + 3.0**2) / n), rtol=1e-14)
    grad = jax.grad(norm)(zero)
    assert all(bool(jnp.all(g == 0.0)) for g in jax.tree_util.tree_leaves(grad))
    with pytest.raises(ValueError, match="error norm kind 'l1'"):
        raceway_normal_norm(x, 1.0, "l1")


def test_default_norm_is_the_largest_rms_of_a_body():
    """max over bodies of each body's RMS: a roller's 12 coordinates, the cage's 6, the inner
    ring's 10 (accumulators left out); the raceway-normal coordinates and the rotations (each
    roller's orbital rate and angular velocity, the cage) 10x looser."""
    from jaxbearing.run._step_control import DEFAULT_ERROR_NORM, RACEWAY_NORMAL_LOOSEN, ROTATION_LOOSEN

    assert DEFAULT_ERROR_NORM == "body_rms" and RACEWAY_NORMAL_LOOSEN == ROTATION_LOOSEN == 10.0
    x = _random_state()
    norm = raceway_normal_norm(x)
    assert norm.kind == "body_rms"
    zero = jax.tree_util.tree_map(jnp.zeros_like, x)
    # roller 2: radial velocity 50 (counts 5) and axial 3; roller 0: axis component 2
    y = eqx.tree_at(lambda s: s.rollers.radial_velocity, zero, jnp.zeros(5).at[2].set(50.0))
    y = eqx.tree_at(lambda s: s.rollers.axial, y, jnp.zeros(5).at[2].set(3.0))
    y = eqx.tree_at(lambda s: s.rollers.axis, y, jnp.zeros((5, 3)).at[0, 1].set(2.0))
    np.testing.assert_allclose(float(norm(y)), np.sqrt((5.0**2 + 3.0**2) / 12), rtol=1e-14)
    # the cage alone: RMS over its 6 coordinates, 10x looser
    c = eqx.tree_at(lambda s: s.cage.speed, zero, jnp.asarray(6.0))
    np.testing.assert_allclose(float(norm(c)), 0.6 / np.sqrt(6), rtol=1e-14)
    # a roller's orbital rate and angular velocity count 1/10, its skew (axis) in full
    r = eqx.tree_at(lambda s: s.rollers.azimuth_rate, zero, jnp.zeros(5).at[1].set(30.0))
    r = eqx.tree_at(lambda s: s.rollers.angular_velocity, r, jnp.zeros((5, 3)).at[1, 0].set(40.0))
    np.testing.assert_allclose(float(norm(r)), np.sqrt((3.0**2 + 4.0**2) / 12), rtol=1e-14)
    r = eqx.tree_at(lambda s: s.rollers.axis, r, jnp.zeros((5, 3)).at[1, 2].set(5.0))
    np.testing.assert_allclose(float(norm(r)), np.sqrt((3.0**2 + 4.0**2 + 5.0**2) / 12), rtol=1e-14)
    # the accumulators do not count
    acc = eqx.tree_at(lambda s: s.accumulators, y, jax.tree_util.tree_map(lambda a: a + 1e3, y.accumulators))
    assert float(norm(acc)) == float(norm(y))
    # finite (zero) derivative at zero error, as for "rms"
    grad = jax.grad(norm)(zero)
    assert all(bool(jnp.all(g == 0.0)) for g in jax.tree_util.tree_leaves(grad))
    # a huge error of one roller is not diluted by the others: the norm of 26 rollers equals 5's
    x26 = _random_state(26)
    y26 = eqx.tree_at(
        lambda s: s.rollers.axial, jax.tree_util.tree_map(jnp.zeros_like, x26), jnp.zeros(26).at[7].set(3.0)
    )
    np.testing.assert_allclose(float(raceway_normal_norm(x26)(y26)), 3.0 / np.sqrt(12), rtol=1e-14)


def test_solve_refuses_an_unknown_error_norm_in_one_line():
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    with pytest.raises(
        UserInputError, match=r"error_norm = 'rmss': must be one of \('max', 'rms', 'body_rms'\)"
    ):
        jb.solve(b, op, 1e-6, error_norm="rmss")


@pytest.mark.parametrize("name", ["raceway_loosen", "rotation_loosen"])
@pytest.mark.parametrize("value", [0.0, -10.0, float("nan"), float("inf")])
def test_solve_refuses_a_loosening_that_is_not_positive_in_one_line(name, value):
    b, op = jb.reference_bearing(), jb.reference_operating_point()
    with pytest.raises(UserInputError, match=rf"{name} = .*must be"):
        jb.solve(b, op, 1e-6, **{name: value})


def test_default_atol_means_10_nm_10_um_s_and_0_01_rad_s():
    """docs/model.md 13: the default atol = 1e-6 of the scaled deviation state is 10 nm, 10 um/s,
    0.01 rad/s and 1e-8 in an axis component: deviations of that size scale to exactly 1e-6."""
    from jaxbearing.dynamics import Scaling, state_scales

    b, op = jb.reference_bearing(), jb.reference_operating_point()
    # `initial_state` without scatter (a zero-amplitude one), as its compiled program
    y0 = kinematic_start(b, op, jb.Perturbation(axial=0.0, skew=0.0))
    pitch_radius = b.pitch_diameter / 2
    scaling = Scaling(
        nominal=y0, scale=state_scales(b.num_rollers, pitch_radius), orbit_speed=jnp.asarray(0.0)
    )
    paths = (
        lambda s: s.rollers.radial,
        lambda s: s.rollers.axial_velocity,
        lambda s: s.rollers.angular_velocity,
        lambda s: s.rollers.axis,
        lambda s: s.cage.speed,
    )
    steps = (10e-9, 10e-6, 0.01, 1e-8, 10e-6 / pitch_radius)  # m, m/s, rad/s, -, 10 um/s at the pitch
    y = y0
    for path, step in zip(paths, steps):
        y = eqx.tree_at(path, y, path(y0) + step)
    scaled = scaling.scale_state(0.0, y)
    for path in paths:
        np.testing.assert_allclose(np.asarray(path(scaled)), 1e-6, rtol=1e-6)
    np.testing.assert_allclose(np.asarray(scaled.rollers.axial), 0.0, atol=1e-15)


def test_solve_program_has_no_host_callback():
    """JAX's persistent cache refuses programs with host callbacks; `solve` must contain none
    (equinox's checks are traced as NaN, `_compile_cache.checks_without_host_callbacks`)."""
    b, op = jb.reference_bearing(), jb.reference_operating_point()

    def run(d):
        return jb.solve(b, op, d, num_saves=3, max_steps=10)

    text = jax.jit(run).lower(1e-5).as_text()
    assert "callback" not in text
    # ... while diffrax itself puts its checks there under the default EQX_ON_ERROR
    import diffrax

    def plain(d):
        return diffrax.diffeqsolve(
            diffrax.ODETerm(lambda t, y, a: -y),
            diffrax.Tsit5(),
            0.0,
            d,
            1e-3,
            1.0,
            saveat=diffrax.SaveAt(ts=jnp.linspace(0.0, d, 3)),
            throw=False,
        ).ys

    assert "callback" in jax.jit(plain).lower(1.0).as_text()


def test_cache_directory_from_environment(monkeypatch, tmp_path):
    monkeypatch.delenv(CACHE_ENV, raising=False)
    assert cache_dir_from_environment() == default_cache_dir()
    for off in ("off", "0", "", "False"):
        monkeypatch.setenv(CACHE_ENV, off)
        assert cache_dir_from_environment() is None
    monkeypatch.setenv(CACHE_ENV, str(tmp_path / "c"))
    assert cache_dir_from_environment() == tmp_path / "c"


def test_the_cache_stores_every_compiled_program_unless_the_user_says_otherwise(monkeypatch):
    """Also the single operations eager code compiles (a second process compiles none of them
    again); JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS, JAX's own variable, wins."""
    option = "jax_persistent_cache_min_compile_time_secs"
    directory, before = jax.config.jax_compilation_cache_dir, getattr(jax.config, option)
    if not directory:
        pytest.skip("the compilation cache is off in this run")
    try:
        monkeypatch.delenv(MIN_COMPILE_TIME_ENV, raising=False)
        jax.config.update(option, 1.0)
        assert enable_compilation_cache(directory) is not None
        assert getattr(jax.config, option) == 0.0
        monkeypatch.setenv(MIN_COMPILE_TIME_ENV, "2")
        jax.config.update(option, 2.0)  # as JAX reads it from the environment when it starts
        enable_compilation_cache(directory)
        assert getattr(jax.config, option) == 2.0
    finally:
        jax.config.update(option, before)


def test_parallel_map_keeps_order_in_two_processes():
    assert parallel_map(operator.neg, [3, 1, 2], workers=2) == [-3, -1, -2]
    assert parallel_map(operator.neg, [4], workers=2) == [-4]  # one item: no pool


def test_one_thread_workers_add_only_the_flags_their_parent_lacks():
    """The workers' XLA flags are the parent's with the one-thread flags it lacks: JAX's
    persistent compilation cache keys its entries on the flags as written, so a parent that has
    them already (the test processes of `make test`) shares its compiled programs with its
    workers instead of each compiling them again."""
    from jaxbearing.run._ensemble import _ONE_THREAD_FLAGS, _with_flags

    assert _with_flags("", _ONE_THREAD_FLAGS) == _ONE_THREAD_FLAGS
    assert _with_flags(_ONE_THREAD_FLAGS, _ONE_THREAD_FLAGS) == _ONE_THREAD_FLAGS
    assert _with_flags("--xla_dump_to=d", "--a=1 --xla_dump_to=d") == "--xla_dump_to=d --a=1"


@pytest.mark.skipif(not hasattr(os, "sched_getaffinity"), reason="CPU affinity is Linux-only")
def test_parallel_map_pins_each_worker_to_one_cpu():
    """Every worker of a pool runs on one CPU of this process's set (its XLA threads with it),
    the workers in turn on the set's CPUs. (Both maps in one pool, `shared_workers`: a pool is two
    spawned processes that import JAX, a few seconds.)"""
    from jaxbearing.run import shared_workers
    from jaxbearing.run._ensemble import _pin_to_one_cpu

    mine = os.sched_getaffinity(0)
    cpus = sorted(mine)
    expected = [{cpus[i % len(cpus)]} for i in range(3)]
    with shared_workers(2):
        seen = parallel_map(os.sched_getaffinity, [0] * 6, workers=2)
        pinned = parallel_map(_affinity_after_pin, [(i, cpus) for i in range(3)], workers=2)
    assert all(len(cpus) == 1 and cpus <= mine for cpus in seen)
    assert pinned == expected
    _pin_to_one_cpu(0, [])  # no CPUs given: nothing to do
    assert os.sched_getaffinity(0) == mine


def _affinity_after_pin(args):
    from jaxbearing.run._ensemble import _pin_to_one_cpu

    _pin_to_one_cpu(*args)
    return os.sched_getaffinity(0)


def test_shared_workers_keep_one_pool_for_the_block():
    """Inside `shared_workers`, consecutive maps run in the same two processes (the pids the
    workers report); outside, every map starts processes of its own (two maps: each pool is two
    spawned processes that import JAX, a few seconds each)."""
    import os

    from jaxbearing.run import shared_workers

    def pids():  # the pids of one map of two workers
        return set(parallel_map(os.readlink, ["/proc/self"] * 4, workers=2))

    with shared_workers(2):
        first, second = pids(), pids()
    assert len(first | second) <= 2
    outside = [pids(), pids()]
    assert not outside[0] & outside[1] and not (outside[0] | outside[1]) & (first | second)
    with pytest.raises(UserInputError, match="workers = 0"):
        with shared_workers(0):
            pass


def test_parallel_map_in_an_unguarded_script_is_one_line_not_a_hang(tmp_path):
    """A script that calls parallel_map at top level (no `if __name__ == "__main__":`): every
    spawned worker re-runs the script on import and dies. The map ends with one line naming
    the cause instead of a pool restarting workers for ever."""
    import subprocess
    import sys

    script = tmp_path / "unguarded.py"
    script.write_text(
        "import operator\nfrom jaxbearing.run import parallel_map\n"
        "print(parallel_map(operator.neg, [1, 2], workers=2))\n"
    )
    proc = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=240)
    assert proc.returncode != 0
    last = proc.stderr.strip().splitlines()[-1]
    assert "workers = 2" in last and "__main__" in last


def test_workers_end_when_the_process_that_started_them_is_killed(tmp_path):
    """A sweep or search killed with SIGKILL (or by the out-of-memory killer) leaves no pool
    workers behind: each holds a JAX runtime and would otherwise wait for ever on a queue its
    dead parent can no longer close."""
    import os
    import subprocess
    import sys
    import time

    script = tmp_path / "killed.py"
    script.write_text(
        "import os, signal\nfrom jaxbearing.run import shared_workers, parallel_map\n"
        "def pid(_):\n    return os.getpid()\n"
        'if __name__ == "__main__":\n'
        "    with shared_workers(2):\n"
        "        print(*sorted(set(parallel_map(pid, range(8), workers=2))), flush=True)\n"
        "        os.kill(os.getpid(), signal.SIGKILL)\n"
    )
    # files, not pipes: surviving workers would hold a pipe open. stderr apart: the killed
    # process's resource tracker may warn there about the semaphores it leaked
    out, err = tmp_path / "out.txt", tmp_path / "err.txt"
    with out.open("w") as fo, err.open("w") as fe:
        proc = subprocess.run([sys.executable, str(script)], stdout=fo, stderr=fe, timeout=240)
    assert proc.returncode == -9, err.read_text()[-2000:]
    workers = [int(p) for p in out.read_text().split()]
    assert workers and os.getpid() not in workers

    def alive(pid):  # a zombie (ended, not yet reaped by whoever adopted it) counts as ended
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        try:
            with open(f"/proc/{pid}/stat") as f:
                return f.read().rsplit(")", 1)[1].split()[0] != "Z"
        except OSError:
            return True

    deadline = time.monotonic() + 30
    while any(map(alive, workers)) and time.monotonic() < deadline:
        time.sleep(0.1)
    left = [p for p in workers if alive(p)]
    for p in left:  # do not leave them to the next test either
        os.kill(p, 9)
    assert not left, f"workers {left} outlived the killed process"


def test_a_closed_over_bearing_costs_no_more_than_an_argument():
    """A caller's jit that closes over the bearing makes its arrays constants; XLA specialised
    the quasi-static Newton loops on them (0.21 s per start against 0.036 s) until
    `quasi_static` made them opaque (`jax.lax.optimization_barrier`). The same values to 1e-12
    (before, the specialised program's rounding differed beyond that too), the barrier in the
    closed-over program, and a closed-over start within 2x of the argument one (it was 6x): a
    ratio of the fastest of 7 calls each, the two programs called alternately so that a load on
    the machine slows both alike (no absolute wall-clock threshold)."""
    import time

    from jaxbearing.run import initial_state

    b, op = jb.reference_bearing(), jb.reference_operating_point()
    pert = jb.Perturbation(seed=0)
    as_argument = jax.jit(lambda bb: initial_state(bb, op, pert))
    closed_over = jax.jit(lambda _: initial_state(b, op, pert))
    zero = jnp.zeros(())
    assert "optimization_barrier" in closed_over.lower(zero).as_text()

    y_arg = jax.block_until_ready(as_argument(b))
    y_closed = jax.block_until_ready(closed_over(zero))
    for u, v in zip(jax.tree_util.tree_leaves(y_arg), jax.tree_util.tree_leaves(y_closed)):
        np.testing.assert_allclose(np.asarray(u), np.asarray(v), rtol=1e-12, atol=1e-300)

    def timed(f, x):
        t = time.perf_counter()
        jax.block_until_ready(f(x))
        return time.perf_counter() - t

    t_arg, t_closed = [], []
    for _ in range(7):
        t_arg.append(timed(as_argument, b))
        t_closed.append(timed(closed_over, zero))
    assert min(t_closed) < 2.0 * min(t_arg), (t_closed, t_arg)


def _toy_problem():
    """A damped oscillator and a decaying pair held as a dict pytree of mixed shapes, with a
    norm that reads the pytree (as `raceway_normal_norm` does)."""
    import diffrax

    y0 = {"x": jnp.array([1.0, 0.5]), "v": jnp.array([0.0, -0.2]), "pair": jnp.ones((2, 2))}

    def field(t, y, args):
        k, c = args
        return {"x": y["v"], "v": -k * y["x"] - c * y["v"], "pair": -c * y["pair"] * (1 + t)}

    def norm(y):
        assert isinstance(y, dict)  # the norm sees the pytree, not the flat vector
        return jnp.sqrt(jnp.mean(y["x"] ** 2) + 0.5 * jnp.mean(y["v"] ** 2) + jnp.max(y["pair"] ** 2))

    saveat = diffrax.SaveAt(
        subs=[
            diffrax.SubSaveAt(ts=jnp.linspace(0.0, 2.0, 7), fn=lambda t, y, a: {"x": y["x"], "t": t}),
            diffrax.SubSaveAt(t1=True),
        ]
    )
    controller = diffrax.PIDController(rtol=1e-6, atol=1e-8, pcoeff=0.3, icoeff=0.4, norm=norm)
    return field, y0, saveat, controller


def _toy_solve(args, flat: bool):
    import diffrax

    from jaxbearing.run._flat import flatten_problem

    field, y0, saveat, controller = _toy_problem()
    if flat:
        field, y0, saveat, controller = flatten_problem(field, y0, saveat, controller)
    sol = diffrax.diffeqsolve(
        diffrax.ODETerm(field),
        diffrax.Tsit5(),
        0.0,
        2.0,
        0.01,
        y0,
        args=args,
        saveat=saveat,
        stepsize_controller=controller,
        adjoint=diffrax.ForwardMode(),
    )
    return sol.ys, sol.stats["num_steps"]


def test_the_flat_state_solves_the_same_problem_as_the_pytree():
    """`_flat.flatten_problem`: the same steps, samples of the same structure and values, the
    same final state, and the same forward-mode derivative with respect to the arguments."""
    args = (jnp.array(4.0), jnp.array(0.3))
    (tree_ys, tree_steps), (flat_ys, flat_steps) = (_toy_solve(args, flat) for flat in (False, True))
    assert int(tree_steps) == int(flat_steps)
    assert jax.tree_util.tree_structure(tree_ys) == jax.tree_util.tree_structure(flat_ys)
    for a, b in zip(jax.tree_util.tree_leaves(tree_ys), jax.tree_util.tree_leaves(flat_ys)):
        np.testing.assert_allclose(b, a, rtol=1e-13, atol=1e-15)

    def final_x(args, flat):
        return _toy_solve(args, flat)[0][1]["x"][-1]

    tangent = (jnp.array(1.0), jnp.array(0.0))
    d_tree, d_flat = (jax.jvp(lambda a: final_x(a, flat), (args,), (tangent,))[1] for flat in (False, True))
    np.testing.assert_allclose(d_flat, d_tree, rtol=1e-12)


def test_the_library_solve_hands_diffrax_one_vector():
    """`scaled_diffeqsolve` flattens the state for the explicit solver only (the Rosenbrock-W
    solver's blocks are built from the `State`)."""
    import diffrax

    from jaxbearing.run import _simulate

    seen = []

    class Seen(Exception):
        pass

    def spy(term, solver, *args, y0, **kwargs):
        seen.append(
            (type(solver).__name__, jax.tree_util.tree_structure(y0).num_leaves, getattr(y0, "shape", None))
        )
        raise Seen

    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    original = diffrax.diffeqsolve
    try:
        diffrax.diffeqsolve = spy
        for solver in ("tsit5", "ros34pw2"):
            with pytest.raises(Seen):
                jax.eval_shape(
                    lambda b, s=solver: _simulate.solve(b, op, 1e-5, num_saves=2, solver=s), bearing
                )
    finally:
        diffrax.diffeqsolve = original
    (tsit5, n_tsit5, shape), (ros, n_ros, _) = seen
    assert tsit5 == "Tsit5" and n_tsit5 == 1 and len(shape) == 1
    assert ros != "Tsit5" and n_ros > 1


def test_start_up_transients_take_the_max_norm_and_settled_windows_the_per_roller_rms():
    """`solve` (fixed-duration runs, sweeps, trajectory gradients) builds its error norm from
    `TRANSIENT_ERROR_NORM`: the max norm, raceway-normal x100, rotations not loosened (the
    per-roller RMS with the rotations 10x looser gives spurious corner impacts there,
    benchmarks/results/diagnose_peak_spread.json); `prepare_from` (settled windows) from the per-roller
    RMS defaults."""
    from jaxbearing.run import (
        TRANSIENT_ERROR_NORM,
        TRANSIENT_RACEWAY_LOOSEN,
        TRANSIENT_ROTATION_LOOSEN,
        _simulate,
        _solve_from,
    )

    assert (TRANSIENT_ERROR_NORM, TRANSIENT_RACEWAY_LOOSEN, TRANSIENT_ROTATION_LOOSEN) == ("max", 100.0, 1.0)
    bearing, op = jb.reference_bearing(), jb.reference_operating_point()
    built = []

    class Built(Exception):
        pass

    def spy(*args, **kwargs):
        bound = inspect.signature(raceway_normal_norm).bind(*args, **kwargs)
        bound.apply_defaults()
        built.append({k: v for k, v in bound.arguments.items() if k != "state"})
        raise Built

    for module in (_simulate, _solve_from):
        original = module.raceway_normal_norm
        module.raceway_normal_norm = spy
        try:
            with pytest.raises(Built):
                if module is _simulate:
                    jax.eval_shape(lambda b: jb.run.solve(b, op, 1e-5, num_saves=2), bearing)
                else:
                    start = kinematic_start(bearing, op, jb.Perturbation())
                    _solve_from.prepare_from(
                        jb.dynamics.Params(bearing=bearing, operating=op), start, 1e-3, 1e-6
                    )
        finally:
            module.raceway_normal_norm = original
    transient, settled = ({k: v if k == "kind" else float(v) for k, v in b.items()} for b in built)
    assert transient == {"loosen": 100.0, "kind": "max", "rotation_loosen": 1.0}
    assert settled == {"loosen": 10.0, "kind": "body_rms", "rotation_loosen": 10.0}
