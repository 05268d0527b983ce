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
#: fresh clone on the 2-core machine, nothing else running (2026-11-26, 07e31e8, junit; 2233 s
#: in all, 19 min 05 s of pytest; docs/performance.md): engine 273, notebooks 212,
#: steady_gradient 208, optimise_steady 205, optimise 142, rosenbrock 118, validate 97, outputs
#: 72, speed 71, design 70, cmd_simulate 69, sweep_distributed 63, sweep 60, dynamics 52,
#: flange_contact 49, settle 45, flange_lubrication 44, skid 43, misalignment 39, program_cache
#: 37, quasistatic 30. `make test` runs `-n 2 --dist loadfile`: the two processes take whole
#: files in collection order, so the longest start first and the short files fill in at the
#: end (longest-processing-time-first scheduling). Unlisted files follow in their usual order.
SLOWEST_FILES_FIRST = (
    "test_engine.py",
    "test_notebooks.py",
    "test_steady_gradient.py",
    "test_optimise_steady.py",
    "test_optimise.py",
    "test_rosenbrock.py",
    "test_validate.py",
    "test_outputs.py",
    "test_speed.py",
    "test_design.py",
    "test_cmd_simulate.py",
    "test_sweep_distributed.py",
    "test_sweep.py",
    "test_dynamics.py",
    "test_flange_contact.py",
    "test_settle.py",
    "test_flange_lubrication.py",
    "test_skid.py",
    "test_misalignment.py",
    "test_program_cache.py",
    "test_quasistatic.py",
)


def pytest_collection_modifyitems(config, items):
    rank = {name: i for i, name in enumerate(SLOWEST_FILES_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: order within a file kept


# --- compile-time profile (opt-in): JAXBEARING_TEST_COMPILE_LOG=path.json records, per test, the
# seconds JAX spent tracing, lowering and compiling (jax.monitoring duration events), to see
# which tests pay for programs and which reuse them (docs/performance.md, issue 37).
_COMPILE_LOG = __import__("os").environ.get("JAXBEARING_TEST_COMPILE_LOG")
_compile_seconds: dict = {}
_current_test = ["(collection)"]

if _COMPILE_LOG:
    import jax.monitoring

    def _on_duration(event, seconds, **_):
        if event.startswith("/jax/core/compile/"):
            per = _compile_seconds.setdefault(_current_test[0], {})
            key = event.rsplit("/", 1)[-1]
            per[key] = per.get(key, 0.0) + seconds

    jax.monitoring.register_event_duration_secs_listener(_on_duration)


def pytest_runtest_setup(item):
    _current_test[0] = item.nodeid


def pytest_sessionfinish(session):
    if _COMPILE_LOG:
        import json
        import os

        path = f"{_COMPILE_LOG}.{os.environ.get('PYTEST_XDIST_WORKER', 'main')}.json"
        with open(path, "w") as f:
            json.dump(_compile_seconds, f, indent=1)
