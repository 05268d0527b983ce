"""MkDocs hooks of the documentation site (`mkdocs.yml` -> `hooks`).

- The tutorials are the notebooks of `notebooks/`: they are added to the site as
  `tutorials/<name>.ipynb` (rendered by mkdocs-jupyter). `make docs` first executes them into
  `build/notebooks/` (`docs/_execute_notebooks.py`) and points `JAXBEARING_DOCS_NOTEBOOKS` there,
  so the site shows their outputs and figures; without it (a plain `mkdocs build`, the test of
  the build) the committed notebooks, without outputs, are used.
- `<!-- generated: configuration-keys -->` in a page is replaced by the table of every
  configuration key, generated from the key schema (`jaxbearing.io._schema.KEYS`) at build time.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from mkdocs.plugins import event_priority
from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parent.parent
#: environment variable naming the folder of (executed) notebooks the tutorials are built from
NOTEBOOKS_ENV = "JAXBEARING_DOCS_NOTEBOOKS"
CONFIG_MARKER = "<!-- generated: configuration-keys -->"


def notebook_dir() -> Path:
    folder = os.environ.get(NOTEBOOKS_ENV, "").strip()
    return Path(folder).resolve() if folder else ROOT / "notebooks"


@event_priority(100)  # before mkdocs-jupyter turns .ipynb files into pages
def on_files(files, config):
    source = notebook_dir()
    staging = ROOT / "build" / "docs-tutorials"  # src_dir of the tutorial pages
    (staging / "tutorials").mkdir(parents=True, exist_ok=True)
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        path = source / nb.name
        if not path.exists():
            raise FileNotFoundError(f"{path}: missing ({NOTEBOOKS_ENV}={source}); run `make docs`")
        shutil.copyfile(path, staging / "tutorials" / nb.name)
        files.append(
            File(f"tutorials/{nb.name}", str(staging), config["site_dir"], config["use_directory_urls"])
        )
    return files


def configuration_table() -> str:
    """Markdown tables of every configuration key, one per section, from the schema."""
    from jaxbearing.io._keys import format_value
    from jaxbearing.io._schema import KEYS

    out: list[str] = []
    section = None
    for key in KEYS:
        if key.section != section:
            section = key.section
            out += [
                "",
                f"### `[{section}]`",
                "",
                "| key | symbol | unit | reference value | meaning and valid range |",
                "|---|---|---|---|---|",
            ]
        symbol = f"`{key.symbol}`" if key.symbol else ""
        meaning = key.doc().replace("|", "\\|")
        default = format_value(key.default).replace("|", "\\|")
        out.append(f"| `{key.name}` | {symbol} | {key.unit} | `{default}` | {meaning} |")
    return "\n".join(out) + "\n"


def on_page_markdown(markdown, page, config, files):
    if CONFIG_MARKER in markdown:
        markdown = markdown.replace(CONFIG_MARKER, configuration_table())
    return markdown
