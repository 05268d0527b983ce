"""Short or full setting of the notebooks.

The notebooks run as tests (`tests/test_notebooks.py`) with the environment variable
JAXBEARING_NOTEBOOK_SHORT=1: short simulated durations, figures written to the gitignored
notebooks/figures/. Without it (the full setting) they reproduce the study: full durations,
figures written to docs/figures/ (the ones the documentation shows).

    from _short import SHORT, pick, figure_dir
    duration = pick(short=0.5e-3, full=20e-3)
"""

from __future__ import annotations

import os
import pathlib

#: environment variable that selects the short setting ("1", "true", "yes"; "0" or unset: full)
ENV_VAR = "JAXBEARING_NOTEBOOK_SHORT"

ROOT = pathlib.Path(__file__).resolve().parent.parent


def is_short() -> bool:
    """True when JAXBEARING_NOTEBOOK_SHORT is set to a true value."""
    value = os.environ.get(ENV_VAR, "").strip().lower()
    if value in ("", "0", "false", "no", "off"):
        return False
    if value in ("1", "true", "yes", "on"):
        return True
    raise ValueError(f"{ENV_VAR} = {value!r}: must be 1/true/yes/on or 0/false/no/off (or unset)")


SHORT = is_short()


def pick(short, full):
    """`short` in the short (test) setting, `full` otherwise."""
    return short if SHORT else full


def figure_dir(name: str) -> pathlib.Path:
    """Folder for a notebook's figures: docs/figures/<name> in the full setting (kept in git),
    notebooks/figures/<name> in the short setting (PNGs there are gitignored). Created."""
    base = ROOT / "notebooks" / "figures" if SHORT else ROOT / "docs" / "figures"
    path = base / name
    path.mkdir(parents=True, exist_ok=True)
    return path


def setting() -> str:
    """One line saying which setting is active (printed at the top of every notebook)."""
    kind = "SHORT (test) setting" if SHORT else "FULL setting"
    return f"{kind}: {ENV_VAR}={os.environ.get(ENV_VAR, '')!r}"
