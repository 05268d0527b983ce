import os

# One CPU per test process (`make test` runs two, `-n 2`): each pytest-xdist worker runs on its
# own CPU with single-threaded XLA, as the engine's own worker processes do
# (`jaxbearing.run._ensemble`), instead of two processes each spreading XLA's threads over both
# CPUs. JAXBEARING_TEST_PIN=0 switches it off. And XLA's older CPU emitters instead of its fusion
# emitters: a solve compiles in 14 s instead of 22-24 s and runs as fast, with the same numbers
# (benchmarks/results/diagnose_compile_flags.json), and compiling is about half of the suite's time.
# (XLA reads XLA_FLAGS up to the first token that is not a flag, such as the often-quoted
# `intra_op_parallelism_threads=1`, and ignores the rest.)
_WORKER = os.environ.get("PYTEST_XDIST_WORKER", "")
if (
    _WORKER.startswith("gw")
    and os.environ.get("JAXBEARING_TEST_PIN", "1") != "0"
    and hasattr(os, "sched_setaffinity")
):
    _cpus = sorted(os.sched_getaffinity(0))
    if len(_cpus) > 1:
        os.sched_setaffinity(0, {_cpus[int(_WORKER[2:]) % len(_cpus)]})
        os.environ["XLA_FLAGS"] = (
            os.environ.get("XLA_FLAGS", "")
            + " --xla_cpu_use_fusion_emitters=false --xla_cpu_multi_thread_eigen=false"
        ).strip()

import jax  # noqa: E402
import pytest  # noqa: E402

jax.config.update("jax_enable_x64", True)

#: seconds of test time per file in a cold-cache `make test` from a fresh clone on the 2-core
#: machine, nothing else running (`PYTEST_ADDOPTS=--junitxml=J.xml ../shared/tools/fresh-clone-test`
#: at c4d6d45, 1144 s in all, 9 min 48 s of pytest; docs/performance.md). Files not listed
#: take under 10 s. Since moved: the failed settled run (32 s there, 11.5 s of CPU measured in
#: test_settle alone and cold) from test_cmd_simulate to test_settle. Since cut (CPU seconds of
#: the file alone and cold, before and after, side by side on one core): test_steady_gradient
#: by 23 s (one integration per trajectory for every statistic, one vmapped program),
#: test_rosenbrock by 15 s (its Tsit5 program the settled runs'), test_validate by 1 s, test_speed by
#: 3 s (one worker pool fewer). Since added: test_profile_gradients (170 s alone on one core
#: beside another process, `pytest -p no:xdist tests/test_profile_gradients.py`).
FILE_SECONDS = {
    "test_profile_gradients.py": 170,
    "test_engine.py": 114,
    "test_notebooks.py": 98,
    "test_steady_gradient.py": 95,
    "test_optimise.py": 70,
    "test_settle.py": 69,
    "test_rosenbrock.py": 54,
    "test_cmd_simulate.py": 51,
    "test_speed.py": 46,
    "test_sweep_distributed.py": 44,
    "test_design.py": 33,
    "test_outputs.py": 30,
    "test_validate.py": 27,
    "test_dynamics.py": 27,
    "test_sweep.py": 27,
    "test_sensitivity.py": 25,
    "test_skid.py": 23,
    "test_quasistatic.py": 21,
    "test_flange_contact.py": 19,
    "test_flange_lubrication.py": 18,
    "test_misalignment.py": 18,
    "test_raceway.py": 18,
    "test_contact_hertz.py": 18,
    "test_steady_design.py": 17,
    "test_flange_arrangement.py": 13,
    "test_config_new.py": 13,
    "test_faces.py": 15,
}

#: files that compile the same programs, run by one process in this order (`make test`, the
#: scheduler below), the first to compile a program storing it for the others: run side by side,
#: two processes each compiled the same program (20-45 s each). test_settle compiles the
#: 11-slice skid start and settled members (and, from the stored start, the members of its failed
#: settled run, whose step limit is static), which notebook 05 (checked: after test_settle it
#: stores no skid start or settled-member program of its own), test_steady_design and
#: test_steady_gradient load (test_engine's settled sweep too, later, from the other process;
#: test_config_new's settled runs of three catalogue bearings with 26 rollers and 11 slices, last).
#: test_steady_gradient before the notebooks: notebook 05 then reads the skid starts of seeds
#: 0-2 of the 11-slice reference that its settled ensemble stored (the start cache,
#: `jaxbearing.run._start_cache`) and loads its frozen-load programs.
#: test_cmd_simulate compiles the full-size `simulate` with 4000 saves, which test_dynamics,
#: test_misalignment_trend, test_flange_arrangement, test_outputs and notebooks 01 and 02 (in the first group, which
#: reaches them after test_settle and test_steady_gradient) load; test_outputs compiles the reference sweep batch, which
#: test_sweep and test_sweep_distributed load.
PROGRAM_GROUPS = (
    (
        "test_settle.py",
        "test_steady_gradient.py",
        "test_notebooks.py",
        "test_steady_design.py",
        "test_config_new.py",
    ),
    (
        "test_cmd_simulate.py",
        "test_dynamics.py",
        "test_misalignment_trend.py",
        "test_flange_arrangement.py",
        "test_outputs.py",
        "test_sweep.py",
        "test_sweep_distributed.py",
    ),
)
_GROUP_OF = {name: (group[0], i) for group in PROGRAM_GROUPS for i, name in enumerate(group)}


def test_group(file_name: str) -> str:
    """The group a test file runs in: its own name, or the first file of its PROGRAM_GROUPS entry."""
    return _GROUP_OF.get(file_name, (file_name, 0))[0]


def group_seconds() -> dict:
    """Seconds of test time per group, from FILE_SECONDS."""
    out: dict = {}
    for name, seconds in FILE_SECONDS.items():
        out[test_group(name)] = out.get(test_group(name), 0) + seconds
    return out


@pytest.fixture(scope="session")
def small_sweep(tmp_path_factory):
    """The sweep of tests/sweeps/small.toml run uninterrupted, single device, in this process:
    (its DIR, its dataset). tests/test_sweep.py and tests/test_sweep_distributed.py compare
    against it; one process runs both (`PROGRAM_GROUPS`), so the sweep runs once."""
    import pathlib

    from jaxbearing.sweep import load_sweep_spec, run_sweep

    out = tmp_path_factory.mktemp("sweep-ref")
    spec = load_sweep_spec(pathlib.Path(__file__).parent / "sweeps" / "small.toml")
    return out, run_sweep(spec, out, progress=False)


def _file_name(nodeid: str) -> str:
    return nodeid.split("::", 1)[0].rsplit("/", 1)[-1]


def pytest_collection_modifyitems(config, items):
    """Groups slowest first, a group's files in their PROGRAM_GROUPS order, each file's tests
    together in their usual order."""
    seconds = group_seconds()

    def rank(item):
        group, position = _GROUP_OF.get(item.path.name, (item.path.name, 0))
        return -seconds.get(group, 0), position

    items.sort(key=rank)  # stable: the order within a file kept


@pytest.hookimpl(optionalhook=True)  # a pytest-xdist hook: unknown without it (-p no:xdist)
def pytest_xdist_make_scheduler(config, log):
    """`--dist loadfile` (`make test`) with whole groups instead of whole files: the two processes
    take groups in the order above, so the longest start first and the short files fill in at
    the end (longest-processing-time-first scheduling). pytest-xdist's own ordering, by the
    number of tests in a file, is switched off. (Its `--dist loadgroup` does not group with
    pytest 9.2, whose node ids it can no longer rename.)"""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class GroupScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return test_group(_file_name(nodeid))

    config.option.loadscopereorder = False
    return GroupScheduling(config, log)


# --- compile-time profile (opt-in): JAXBEARING_TEST_COMPILE_LOG=path.json records, per test, the
# seconds JAX spent tracing, lowering and compiling (jax.monitoring duration events), to see
# which tests pay for programs and which reuse them (docs/performance.md, issue 37): "programs"
# lists each compile by name and seconds, "built" each engine program (`compiled_program`) a
# test builds, by name, static arguments and a digest of its argument structure; the same
# program built by two tests is a compile a shared setting would save. "cache" lists each
# persistent-cache lookup (hit or miss, program, the key's end): a key missed by tests of two
# files, or by a test and a notebook kernel or subprocess, is a program both compiled.
# "skid": the start cache's key (its start) of each static skid start a test needs (one-at-a-time
# path), and whether it was "read" from the start cache or "solved".
# "started": when the test started (epoch seconds; "(session end)" when the process finished),
# which shows how evenly the two processes end.
_COMPILE_LOG = __import__("os").environ.get("JAXBEARING_TEST_COMPILE_LOG")
_compile_seconds: dict = {}
_current_test = ["(collection)"]

if _COMPILE_LOG:
    import jax.monitoring

    def _on_duration(event, seconds, fun_name=None, **_):
        if event.startswith("/jax/core/compile/"):
            per = _compile_seconds.setdefault(_current_test[0], {})
            key = event.rsplit("/", 1)[-1]
            per[key] = per.get(key, 0.0) + seconds
            if fun_name is not None:  # which program: the backend compiles, by name
                per.setdefault("programs", []).append([key, str(fun_name), round(seconds, 3)])

    jax.monitoring.register_event_duration_secs_listener(_on_duration)

    import hashlib

    import jaxbearing.run._compile_cache as _cc

    _plain_build = _cc._build

    def _logged_build(name, fn, in_tree, specs, static):  # which engine programs each test builds
        key = hashlib.sha256(repr((str(in_tree), specs)).encode()).hexdigest()[:8]
        per = _compile_seconds.setdefault(_current_test[0], {})
        per.setdefault("built", []).append([name, repr(static)[:200], key, len(specs)])
        return _plain_build(name, fn, in_tree, specs, static)

    _cc._build = _logged_build

    import jaxbearing.run._initial as _initial
    import jaxbearing.run._member as _member
    import jaxbearing.run._start_cache as _start_cache
    import jaxbearing.run._starts as _starts

    _plain_skid = _initial._static_skid_start

    def _logged_skid(bearing, op, perturbation):  # which static skid starts each test needs
        key = _start_cache.start_key("static", (bearing, op, _initial.traced_scatter(perturbation)))
        directory = _start_cache.start_cache_dir()
        stored = directory is not None and any(directory.glob(f"static-{key}.*"))
        per = _compile_seconds.setdefault(_current_test[0], {})
        per.setdefault("skid", []).append([key[:12], "read" if stored else "solved"])
        return _plain_skid(bearing, op, perturbation)

    _initial._static_skid_start = _member._static_skid_start = _starts._static_skid_start = _logged_skid

    import jax._src.compiler as _compiler

    def _cache_logger(kind, plain):  # which persistent-cache entries each test hit or missed
        def log(module_name, cache_key):
            per = _compile_seconds.setdefault(_current_test[0], {})
            per.setdefault("cache", []).append([kind, module_name, cache_key[-16:]])
            return plain(module_name, cache_key)

        return log

    _compiler.log_persistent_cache_hit = _cache_logger("hit", _compiler.log_persistent_cache_hit)
    _compiler.log_persistent_cache_miss = _cache_logger("miss", _compiler.log_persistent_cache_miss)


def pytest_runtest_setup(item):
    _current_test[0] = item.nodeid
    if _COMPILE_LOG:  # when each test started (epoch seconds): each process's timeline
        _compile_seconds.setdefault(item.nodeid, {})["started"] = __import__("time").time()


def pytest_sessionfinish(session):
    if _COMPILE_LOG:
        import json
        import os
        import time

        _compile_seconds["(session end)"] = {"started": time.time()}
        path = f"{_COMPILE_LOG}.{os.environ.get('PYTEST_XDIST_WORKER', 'main')}.json"
        with open(path, "w") as f:
            json.dump(_compile_seconds, f, indent=1)
