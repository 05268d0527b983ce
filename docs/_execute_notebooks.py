"""Execute the tutorials for the documentation site (`make docs`).

    python docs/_execute_notebooks.py OUT_DIR [NAME ...]

Runs every notebook of `notebooks/` (or the named ones) top to bottom in the short setting
(`JAXBEARING_NOTEBOOK_SHORT=1`, the setting the tests run: short simulated durations, figures
under the gitignored `notebooks/figures/`), each in a fresh `python3` kernel from this
interpreter's environment, from the `notebooks/` folder, and writes the executed copy with its
outputs to OUT_DIR (the committed notebooks stay without outputs). A notebook whose executed
copy is newer than the notebook and than every file of `jaxbearing/`, `optimise/` and
`notebooks/_short.py` is not run again. Prints each notebook's wall time; exits 1 if a cell fails.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOKS = ROOT / "notebooks"


def newest_source() -> float:
    paths = [NOTEBOOKS / "_short.py", *ROOT.glob("jaxbearing/**/*.py"), *ROOT.glob("optimise/**/*.py")]
    return max(p.stat().st_mtime for p in paths)


def execute(path: Path, out: Path) -> float:
    import nbclient
    import nbformat

    nb = nbformat.read(path, as_version=4)
    start = time.perf_counter()
    client = nbclient.NotebookClient(
        nb, timeout=900, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOKS)}}
    )
    client.execute()
    wall = time.perf_counter() - start
    nbformat.write(nb, out)
    return wall


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__, file=sys.stderr)
        return 2
    out_dir = Path(argv[0])
    out_dir.mkdir(parents=True, exist_ok=True)
    names = set(argv[1:])
    os.environ["JAXBEARING_NOTEBOOK_SHORT"] = "1"
    # the kernel's inline backend embeds the figures in the outputs (Agg would not)
    os.environ["MPLBACKEND"] = "module://matplotlib_inline.backend_inline"
    os.environ.setdefault("EQX_ON_ERROR", "nan")  # lets the persistent compilation cache keep the programs
    sources = newest_source()
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        if names and path.stem not in names:
            continue
        out = out_dir / path.name
        if out.exists() and out.stat().st_mtime > max(path.stat().st_mtime, sources):
            print(f"{path.name}: up to date", flush=True)
            continue
        print(f"{path.name}: executing ...", flush=True)
        try:
            wall = execute(path, out)
        except Exception as exc:  # noqa: BLE001 - reported, the build fails
            print(f"{path.name}: FAILED: {type(exc).__name__}: {str(exc)[-2000:]}", file=sys.stderr)
            return 1
        print(f"{path.name}: {wall:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
