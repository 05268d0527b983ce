import jax

jax.config.update("jax_enable_x64", True)

#: test files slowest first (seconds in a cold-cache suite on the 2-core machine, 2026-11-24:
#: notebooks 391, steady_gradient 418 with its CRN check, since made slow, optimise 177, skid 119,
#: settle 118, sweep_distributed 105, misalignment 84, dynamics 78, design 77, sweep 72,
#: steady_design 68). `make test` runs `-n 2 --dist loadfile`: the two processes take whole
#: files in collection order, so the longest start first and the short files fill in at the end
#: (longest-processing-time-first scheduling). Unlisted files follow in their usual order.
SLOWEST_FILES_FIRST = (
    "test_notebooks.py",
    "test_steady_gradient.py",
    "test_optimise.py",
    "test_skid.py",
    "test_settle.py",
    "test_sweep_distributed.py",
    "test_misalignment.py",
    "test_dynamics.py",
    "test_design.py",
    "test_sweep.py",
    "test_steady_design.py",
)


def pytest_collection_modifyitems(config, items):
    rank = {name: i for i, name in enumerate(SLOWEST_FILES_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: order within a file kept
