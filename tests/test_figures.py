"""The measured figures on the user pages: each registered number equals its results file's
(docs/figures.toml, docs/_figures.py, `make figures`), every registered results file exists with
the command that wrote it, and the pages a newcomer reads first carry no history (dated reruns,
commit hashes, load averages). Pure text, well under a second."""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: the pages that must read as current: no dates of reruns, no commit hashes, no machine loads
CURRENT_PAGES = [
    ROOT / "README.md",
    ROOT / "docs" / "getting-started.md",
    *sorted((ROOT / "docs" / "how-to").glob("*.md")),
]

DATE = re.compile(r"\b20\d\d-[01]\d-[0-3]\d\b")
#: 7-40 hexadecimal characters with at least one digit and one letter, as a commit hash is written
COMMIT = re.compile(r"(?<![\w./-])(?=[0-9a-f]*[0-9])(?=[0-9a-f]*[a-f])[0-9a-f]{7,40}(?![\w-])")
LOAD = re.compile(r"\bload average|\bat load \d|\bload \d+(\.\d+)? from\b", re.IGNORECASE)


def _figures_module():
    spec = importlib.util.spec_from_file_location("docs_figures", ROOT / "docs" / "_figures.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


figures_module = _figures_module()


def test_every_registered_results_file_exists_with_its_command():
    sources, figures = figures_module.load()
    assert figures, "docs/figures.toml registers no figure"
    missing = [s["file"] for s in sources.values() if not (ROOT / s["file"]).is_file()]
    assert not missing, f"registered results files that do not exist: {missing}"
    assert all(s.get("command", "").strip() for s in sources.values()), "a source without its command"
    unused = set(sources) - {f.source for f in figures}
    assert not unused, f"sources no figure uses: {sorted(unused)}"


def test_every_page_quotes_its_results_files():
    _, figures = figures_module.load()
    problems = figures_module.check(figures)
    assert not problems, (
        "pages that differ from their results files (`make figures` rewrites them):\n" + "\n".join(problems)
    )


def test_check_finds_a_changed_number_and_rewrites_it(tmp_path):
    """The checker is not blind: a page whose number differs from the file is reported, --write
    mends it, a page that no longer quotes the text is reported, and a missing file is named."""
    (tmp_path / "results.json").write_text(
        '{"run": {"wall_s": 513, "pv": {"value": 2.2205, "ci95_low": 2.19, "ci95_high": 2.2485}}}'
    )
    (tmp_path / "page.md").write_text("make test: 9 min 1 s in all.\n| PV | 2.22 [2.19, 2.30] GPa m/s |\n")
    registry = tmp_path / "figures.toml"
    registry.write_text(
        '[sources.run]\nfile = "results.json"\ncommand = "make test"\n'
        '[[figure]]\nsource = "run"\nvalues = ["run/wall_s"]\nformat = "min s"\npages = ["page.md"]\n'
        'text = "make test: {} in all."\n'
        '[[figure]]\nsource = "run"\nvalues = ["run/pv/*"]\nformat = ".2f"\npages = ["page.md"]\n'
        'text = "| PV | {} [{}, {}] GPa m/s |"\n'
    )
    _, figures = figures_module.load(registry, root=tmp_path)
    problems = figures_module.check(figures, root=tmp_path)
    assert len(problems) == 2 and "['9 min 1 s']" in problems[0] and "'2.30'" in problems[1], problems
    figures_module.check(figures, root=tmp_path, write=True)
    assert (
        tmp_path / "page.md"
    ).read_text() == "make test: 8 min 33 s in all.\n| PV | 2.22 [2.19, 2.25] GPa m/s |\n"
    assert figures_module.check(figures, root=tmp_path) == []
    (tmp_path / "page.md").write_text("make test: about 9 minutes.\n| PV | 2.22 [2.19, 2.25] GPa m/s |\n")
    assert any("no longer quotes" in p for p in figures_module.check(figures, root=tmp_path))
    (tmp_path / "results.json").unlink()
    assert all("does not exist" in p for p in figures_module.check(figures, root=tmp_path))


@pytest.mark.parametrize("path", CURRENT_PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_current_pages_carry_no_history(path):
    """Dated reruns, commit hashes and machine loads belong in docs/changelog.md and
    docs/performance-history.md, not on the pages that say how things are."""
    text = path.read_text()
    found = [m.group(0) for pattern in (DATE, COMMIT, LOAD) for m in pattern.finditer(text)]
    assert not found, f"{path.relative_to(ROOT)}: {found}"


def test_history_patterns_find_what_they_look_for():
    assert DATE.search("measured on 2026-11-26, nothing else")
    assert COMMIT.search("at 4ce89c0 from a fresh clone") and COMMIT.search("commit 07e31e8)")
    assert LOAD.search("(2026-11-25, load 2.8 from another test process)") and LOAD.search(
        "at load average 2"
    )
    for clean in (
        "1e-3",
        "deadbeef",
        "facade",
        "0x1f",
        "dJ/dDelta_bf",
        "10,816 members",
        "v0.10.2",
        "a1b2c3",
    ):
        assert not COMMIT.search(clean), clean
