import jax

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
