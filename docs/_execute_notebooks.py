"""Execute the tutorials for the documentation site (`make docs`).

    python docs/_execute_notebooks.py OUT_DIR [NAME ...] [--force]

Runs every notebook of `notebooks/` (or the named ones) top to bottom in the short setting
(`JAXBEARING_NOTEBOOK_SHORT=1`, the setting the tests run: short simulated durations, figures
under the gitignored `notebooks/figures/`), each in a fresh `python3` kernel from this
interpreter's environment, from the `notebooks/` folder, and writes the executed copy with its
outputs to OUT_DIR (the committed notebooks stay without outputs). A notebook whose executed
copy has the same code cells and was run on the same code of `jaxbearing/`, `optimise/` and
`notebooks/_short.py` (compared without docstrings and comments) is not run again; an edit of
its text only is copied into it. `--force` runs every one. Prints each
notebook's wall time; exits 1 if a cell fails.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOKS = ROOT / "notebooks"


def code_hash() -> str:
    """Hash of the code the notebooks run: every module of jaxbearing/ and optimise/ and
    notebooks/_short.py, parsed, without docstrings (comments are not in the syntax tree)."""
    import ast
    import hashlib

    digest = hashlib.sha256()
    paths = [NOTEBOOKS / "_short.py", *ROOT.glob("jaxbearing/**/*.py"), *ROOT.glob("optimise/**/*.py")]
    for path in sorted(paths):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            body = getattr(node, "body", None)
            if (
                isinstance(body, list)
                and body
                and isinstance(body[0], ast.Expr)
                and isinstance(body[0].value, ast.Constant)
                and isinstance(body[0].value.value, str)
            ):
                body[0] = ast.Pass()
        digest.update(str(path.relative_to(ROOT)).encode() + ast.dump(tree).encode())
    return digest.hexdigest()


def refresh_text(path: Path, out: Path, code: str) -> bool:
    """True if the executed copy `out` was run on `code` and has the code cells of `path`; then
    its markdown cells are brought up to date from `path` (no execution needed)."""
    import nbformat

    nb, done = nbformat.read(path, as_version=4), nbformat.read(out, as_version=4)
    if done.metadata.get("jaxbearing_docs", {}).get("code_hash") != code:
        return False
    if [(c.cell_type, c.source) for c in nb.cells if c.cell_type == "code"] != [
        (c.cell_type, c.source) for c in done.cells if c.cell_type == "code"
    ] or len(nb.cells) != len(done.cells):
        return False
    changed = False
    for cell, old in zip(nb.cells, done.cells):
        if cell.cell_type != "code" and cell.source != old.source:
            old.source, changed = cell.source, True
    if changed:
        nbformat.write(done, out)
    return True


def execute(path: Path, out: Path, code: str) -> float:
    import nbclient
    import nbformat

    nb = nbformat.read(path, as_version=4)
    start = time.perf_counter()
    client = nbclient.NotebookClient(
        nb, timeout=900, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOKS)}}
    )
    client.execute()
    wall = time.perf_counter() - start
    nb.metadata["jaxbearing_docs"] = {"code_hash": code, "wall_time_s": round(wall, 1)}
    nbformat.write(nb, out)
    return wall


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__, file=sys.stderr)
        return 2
    force = "--force" in argv
    argv = [a for a in argv if a != "--force"]
    out_dir = Path(argv[0])
    out_dir.mkdir(parents=True, exist_ok=True)
    names = set(argv[1:])
    os.environ["JAXBEARING_NOTEBOOK_SHORT"] = "1"
    # the kernel's inline backend embeds the figures in the outputs (Agg would not)
    os.environ["MPLBACKEND"] = "module://matplotlib_inline.backend_inline"
    os.environ.setdefault("EQX_ON_ERROR", "nan")  # lets the persistent compilation cache keep the programs
    code = code_hash()
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        if names and path.stem not in names:
            continue
        out = out_dir / path.name
        if not force and out.exists() and refresh_text(path, out, code):
            print(f"{path.name}: up to date", flush=True)
            continue
        print(f"{path.name}: executing ...", flush=True)
        try:
            wall = execute(path, out, code)
        except Exception as exc:  # noqa: BLE001 - reported, the build fails
            print(f"{path.name}: FAILED: {type(exc).__name__}: {str(exc)[-2000:]}", file=sys.stderr)
            return 1
        print(f"{path.name}: {wall:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
