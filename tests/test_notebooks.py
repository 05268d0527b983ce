"""Every notebook in notebooks/ runs top to bottom in the short setting, and is committed with
its outputs stripped.

The notebooks read JAXBEARING_NOTEBOOK_SHORT (notebooks/_short.py): with it set they simulate
fractions of a millisecond and write their figures to the gitignored notebooks/figures/; the
full setting (unset) reproduces the study and writes docs/figures/. Each notebook runs in its own
`python3` kernel from this interpreter's environment (jupyter_client starts the native kernel
with `sys.executable`), with MPLBACKEND=Agg, from the notebooks/ folder, so `import _short`
works as it does in Jupyter. New notebooks are picked up by the glob.

Compile time. Each kernel would compile the whole-bearing solve afresh (10-60 s on 2 cores).
The kernels inherit this process's environment and so use the persistent caches every other
test uses: jaxbearing's own (`$JAXBEARING_CACHE_DIR`, default `~/.cache/jaxbearing/xla`, with
its stored programs, `jaxbearing.run.compiled_program`), or the caller's
JAX_COMPILATION_CACHE_DIR when one is set. So a second run of the suite on a machine, or a
notebook whose programs another test built, does not trace and compile them again.
EQX_ON_ERROR=nan: equinox's runtime checks otherwise compile to host callbacks, and XLA does not
persist executables that contain them. The notebooks assert `result.ok` after every solve, so a
failed solve still fails here.
"""

from __future__ import annotations

import pathlib

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

NOTEBOOK_DIR = pathlib.Path(__file__).resolve().parent.parent / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("*.ipynb"))
#: seconds per cell: a compile of the whole-bearing solve takes 10-60 s on a 2-core CPU
CELL_TIMEOUT = 600


def _ids(path: pathlib.Path) -> str:
    return path.stem


def test_notebooks_exist():
    names = {p.stem for p in NOTEBOOKS}
    assert {"01_quickstart", "02_arc_vs_corner", "04_design_zone", "06_your_own_bearing"} <= names, names


@pytest.mark.parametrize("path", NOTEBOOKS, ids=_ids)
def test_outputs_stripped(path):
    """Committed notebooks carry no outputs and no execution counts (clean diffs, no stale
    numbers presented as results)."""
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    dirty = [
        i
        for i, cell in enumerate(nb.cells)
        if cell.cell_type == "code" and (cell.outputs or cell.execution_count is not None)
    ]
    assert not dirty, (
        f"{path.name}: code cells {dirty} have outputs or execution counts; strip them "
        "(e.g. jupyter nbconvert --clear-output --inplace)"
    )


@pytest.mark.parametrize("path", NOTEBOOKS, ids=_ids)
def test_notebook_runs(path, monkeypatch):
    """Execute the notebook top to bottom in the short setting; any cell error fails the test
    (nbclient raises CellExecutionError with the cell's traceback)."""
    monkeypatch.setenv("JAXBEARING_NOTEBOOK_SHORT", "1")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setenv("EQX_ON_ERROR", "nan")
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(
        nb,
        timeout=CELL_TIMEOUT,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOK_DIR)}},
    )
    client.execute()
    errors = [
        out
        for cell in nb.cells
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
        if out.get("output_type") == "error"
    ]
    assert not errors, f"{path.name}: {errors[0].get('ename')}: {errors[0].get('evalue')}"
