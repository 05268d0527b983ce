import os

# One CPU per test process (`make test` runs two, `-n 2`): each pytest-xdist worker runs on its
# own CPU with single-threaded XLA, as the engine's own worker processes do
# (`jaxbearing.run._ensemble`), instead of two processes each spreading XLA's threads over both
# CPUs. JAXBEARING_TEST_PIN=0 switches it off.
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
            + " --xla_cpu_multi_thread_eigen=false intra_op_parallelism_threads=1"
        ).strip()

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

#: test files slowest first. Seconds of test time per file in a cold-cache `make test` from a
#: fresh clone on the 2-core machine, nothing else running (2026-11-26, cb481c4, junit; 1881 s
#: in all, 15 min 58 s of pytest; docs/performance.md): notebooks 173, engine 165,
#: steady_gradient 137, rosenbrock 136, optimise 113, optimise_steady 79, speed 78, sweep 73,
#: settle 72, cmd_simulate 72, design 71, sweep_distributed 68, outputs 65, validate 52,
#: flange_lubrication 49, flange_contact 48, dynamics 47, misalignment 42, contact_hertz 40,
#: program_cache 35, raceway 33, skid 33, quasistatic 33 (outputs 65 last, below). `make test` runs `-n 2 --dist
#: loadfile`: the two processes take whole files in collection order, so the longest start
#: first and the short files fill in at the end (longest-processing-time-first scheduling).
#: Unlisted files follow in their usual order.
SLOWEST_FILES_FIRST = (
    "test_notebooks.py",
    "test_engine.py",
    "test_steady_gradient.py",
    "test_rosenbrock.py",
    "test_optimise.py",
    "test_optimise_steady.py",
    "test_speed.py",
    "test_sweep.py",
    "test_settle.py",
    "test_cmd_simulate.py",
    "test_design.py",
    "test_sweep_distributed.py",
    "test_validate.py",
    "test_flange_lubrication.py",
    "test_flange_contact.py",
    "test_dynamics.py",
    "test_misalignment.py",
    "test_contact_hertz.py",
    "test_program_cache.py",
    "test_raceway.py",
    "test_skid.py",
    "test_quasistatic.py",
    # after test_sweep.py, whose first test stores the sweep program this file's fallback test
    # loads: run side by side, both processes compiled it (22 s each)
    "test_outputs.py",
)


def pytest_collection_modifyitems(config, items):
    rank = {name: i for i, name in enumerate(SLOWEST_FILES_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: order within a file kept


# --- compile-time profile (opt-in): JAXBEARING_TEST_COMPILE_LOG=path.json records, per test, the
# seconds JAX spent tracing, lowering and compiling (jax.monitoring duration events), to see
# which tests pay for programs and which reuse them (docs/performance.md, issue 37): "programs"
# lists each compile by name and seconds, "built" each engine program (`compiled_program`) a
# test builds, by name, static arguments and a digest of its argument structure; the same
# program built by two tests is a compile a shared setting would save.
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


def pytest_runtest_setup(item):
    _current_test[0] = item.nodeid


def pytest_sessionfinish(session):
    if _COMPILE_LOG:
        import json
        import os

        path = f"{_COMPILE_LOG}.{os.environ.get('PYTEST_XDIST_WORKER', 'main')}.json"
        with open(path, "w") as f:
            json.dump(_compile_seconds, f, indent=1)
