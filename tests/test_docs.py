"""The documentation: the site builds with `mkdocs build --strict` (a broken link, a missing page
or a missing reference fails it), the API reference lists every public name, the README stays a
front page, the tutorials say what they show and how long they take, and no file of the
repository refers to a file that does not exist.

The site is built here WITHOUT executing the notebooks (the committed notebooks, without
outputs): `make docs` executes them first (`docs/_execute_notebooks.py`) and points the build at
the executed copies, which is the same build with outputs. The build takes about 20-50 s."""

from __future__ import annotations

import importlib
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: the layers with an API page of their own (docs/reference/api/<name>.md)
LAYERS = ("geometry", "contact", "io", "flange", "forces", "dynamics", "run", "design", "sweep", "cli")
#: top-level folders whose files other files refer to by their path from the repository root
TOP = ("benchmarks", "docs", "examples", "notebooks", "jaxbearing", "optimise", "tests")
#: files written by commands, not kept in git (their mention is not a broken reference)
GENERATED = {"benchmarks/results/summary.json"}
EXTENSIONS = ("py", "md", "toml", "json", "ipynb", "png", "npz", "nc", "txt", "yml", "yaml", "pkl")


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    pytest.importorskip("mkdocs")
    pytest.importorskip("mkdocstrings")
    pytest.importorskip("mkdocs_jupyter")
    out = tmp_path_factory.mktemp("site")
    env = {k: v for k, v in os.environ.items() if k != "JAXBEARING_DOCS_NOTEBOOKS"}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    env["NO_MKDOCS_2_WARNING"] = "1"
    proc = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, (
        f"mkdocs build --strict failed:\n{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}"
    )
    return out


def _ids(html: str) -> set[str]:
    return set(re.findall(r'id="([^"]+)"', html))


def test_site_builds_strict_with_every_page(site):
    for page in ("index.html", "getting-started/index.html", "validation/index.html", "changelog/index.html"):
        assert (site / page).exists(), page
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        assert (site / "tutorials" / nb.stem / "index.html").exists(), f"tutorial {nb.stem} not rendered"


def test_api_reference_lists_every_public_name(site):
    """Every name of `jaxbearing.__all__`, of each layer's `__all__` and of `optimise.__all__`
    has an entry (its heading anchor, followed by its docstring) on its API page."""
    pages = {"jaxbearing": "jaxbearing", "optimise": "optimise"} | {f"jaxbearing.{m}": m for m in LAYERS}
    missing = []
    for module_name, page in pages.items():
        module = importlib.import_module(module_name)
        ids = _ids((site / "reference" / "api" / page / "index.html").read_text())
        missing += [f"{module_name}.{n}" for n in module.__all__ if f"{module_name}.{n}" not in ids]
    assert not missing, f"not in the API reference: {missing}"


def test_every_layer_has_an_api_page():
    import jaxbearing

    layers = {
        p.name
        for p in Path(jaxbearing.__file__).parent.iterdir()
        if p.is_dir() and (p / "__init__.py").exists()
    }
    assert layers == set(LAYERS), layers ^ set(LAYERS)


def test_configuration_reference_is_generated_from_the_schema(site):
    from jaxbearing.io._schema import KEYS

    html = (site / "how-to" / "configuration" / "index.html").read_text()
    missing = [k.path for k in KEYS if f"<code>{k.name}</code>" not in html]
    assert not missing, missing


def test_readme_is_a_front_page():
    text = (ROOT / "README.md").read_text()
    assert len(text.encode()) <= 12 * 1024, f"README.md is {len(text.encode())} bytes (at most 12 KB)"
    assert "make demo" in text and "make test" in text
    assert not re.search(r"\b(issue|session) \d+|#\d+\b", text, re.IGNORECASE), "internal work-item labels"


@pytest.mark.parametrize("path", sorted((ROOT / "notebooks").glob("*.ipynb")), ids=lambda p: p.stem)
def test_tutorial_starts_with_what_it_shows_and_how_long_it_takes(path):
    cell = json.loads(path.read_text())["cells"][0]
    text = "".join(cell["source"])
    assert cell["cell_type"] == "markdown" and text.startswith("# "), "first cell: a markdown title"
    assert re.search(r"\*\*Time\.\*\*", text), "the first cell says how long the notebook takes (**Time.**)"


def _texts():
    """(path, text, markdown) of every file whose references are checked; markdown: the part in
    which markdown links count (notebooks: their markdown cells)."""
    for p in [
        ROOT / "README.md",
        *sorted((ROOT / "docs").rglob("*.md")),
        *sorted(ROOT.glob("benchmarks/**/README.md")),
    ]:
        text = p.read_text()
        yield p, text, text
    for p in sorted((ROOT / "notebooks").glob("*.ipynb")):
        cells = json.loads(p.read_text())["cells"]
        text = "\n".join("".join(c["source"]) for c in cells)
        yield p, text, "\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "markdown")
    for pattern in (
        "jaxbearing/**/*.py",
        "optimise/**/*.py",
        "benchmarks/**/*.py",
        "tests/**/*.py",
        "examples/*.toml",
    ):
        for p in sorted(ROOT.glob(pattern)):
            yield p, p.read_text(), ""
    for name in ("Makefile", "pyproject.toml", "mkdocs.yml"):
        yield ROOT / name, (ROOT / name).read_text(), ""


def test_no_reference_to_a_file_that_does_not_exist():
    """Relative markdown links (README, docs, benchmarks' READMEs, the notebooks' text) resolve
    to a file, and every path written from the repository root (`docs/model.md`,
    `benchmarks/studies/bench_misalignment.py`, ...) in any file names one that exists."""
    link = re.compile(r"\]\(([^)\s]+)\)")
    tops, exts = "|".join(TOP), "|".join(EXTENSIONS)
    bare = re.compile(rf"(?<![\w./-])((?:{tops})/[\w./-]*\.(?:{exts}))\b")
    bad = []
    for path, text, markdown in _texts():
        where = path.relative_to(ROOT)
        for m in link.finditer(markdown):
            target = m.group(1).split("#")[0]
            if not target or "://" in target or target.startswith("mailto:"):
                continue
            resolved = path.parent / target
            if path.parent == ROOT / "docs" / "tutorials" and target.endswith(".ipynb"):
                resolved = ROOT / "notebooks" / target  # the tutorials are the notebooks (docs/_hooks.py)
            if not resolved.exists():
                bad.append(f"{where}: link {m.group(1)}")
        for m in bare.finditer(text):
            ref = m.group(1)
            if ref not in GENERATED and not (ROOT / ref).exists():
                bad.append(f"{where}: {ref}")
    assert not bad, "references to files that do not exist:\n" + "\n".join(sorted(set(bad)))


def test_readme_links_point_at_existing_anchors():
    """The README's links into docs/ name headings that exist (mkdocs checks the links inside
    docs/; the README is outside it)."""
    text = (ROOT / "README.md").read_text()
    bad = []
    for target, anchor in re.findall(r"\]\((docs/[^)#\s]+\.md)#([^)\s]+)\)", text):
        headings = re.findall(r"^#+\s+(.+?)\s*$", (ROOT / target).read_text(), re.MULTILINE)
        slugs = {re.sub(r"[^\w\- ]", "", h.lower()).strip().replace(" ", "-") for h in headings}
        if anchor not in slugs:
            bad.append(f"{target}#{anchor}")
    assert not bad, bad


def test_model_section_references_exist():
    """Every "docs/model.md N" (or "model.md, section N") in the code, the tests and the docs
    names a section heading that docs/model.md has."""
    heads = set()
    for line in (ROOT / "docs" / "model.md").read_text().splitlines():
        m = re.match(r"#+\s+([0-9]+[a-z]?(?:\.[0-9]+)?)[.\s]", line)
        if m:
            heads.add(m.group(1))
    files = [ROOT / "README.md"]
    for pattern in (
        "jaxbearing/**/*.py",
        "optimise/*.py",
        "tests/*.py",
        "docs/**/*.md",
        "benchmarks/**/*.py",
    ):
        files += ROOT.glob(pattern)
    ref = re.compile(r"model\.md(?:\]\([^)]*\))?,?\s+(?:sections?\s+)?([0-9]+[a-z]?(?:\.[0-9]+)?)\b")
    bad = [
        f"{p.relative_to(ROOT)}: section {m.group(1)}"
        for p in files
        for m in ref.finditer(p.read_text())
        if m.group(1) not in heads
    ]
    assert heads and not bad, bad
