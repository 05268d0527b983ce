"""Optional dependencies: plotting (matplotlib, extra "plot") and NetCDF datasets (xarray,
extra "sweep"). The core model, `simulate` and the gradients need neither; a command that does
gets a one-line error naming the extra to install instead of an ImportError traceback."""

from __future__ import annotations

import importlib

from .._errors import UserInputError

#: module -> the pip extra that installs it
EXTRAS = {"matplotlib": "plot", "xarray": "sweep"}


def optional_import(module: str):
    """Import `module` (a key of `EXTRAS`, or a submodule of one) or raise UserInputError."""
    top = module.partition(".")[0]
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name != top:
            raise
        raise UserInputError(
            f"{top} is not installed: this needs the '{EXTRAS[top]}' extra "
            f"(pip install 'jaxbearing[{EXTRAS[top]}]')"
        ) from None


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend (files only, no display)."""
    matplotlib = optional_import("matplotlib")
    matplotlib.use("Agg")
    return optional_import("matplotlib.pyplot")
