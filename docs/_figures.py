"""Every measured figure on a user page from its results file (`make figures`).

`docs/figures.toml` (data only) lists the results files (`[sources.NAME]`: `file`, the path from
the repository root, and `command`, the command that wrote it) and every quoted figure
(`[[figure]]`): its `source`, the `values` it quotes (paths into the file's JSON), a `scale` and
a `format`, and the `pages` and the `text` that quote it. `text` is the quoting text as it stands
on the page with `{}` for each number; each `{}` is filled, in order, with one value: a path
is `/`-separated keys and list indices (`verification/optimum/per_operating_point/2/mean_pv`),
a path ending in `/*` stands for an interval's three numbers (`value`, `ci95_low`,
`ci95_high`), and `A / B` is the ratio of two paths. Each value is multiplied by `scale` and
written with `format`: a Python format specification (`.2f`, `,.0f`, `.3g`) or `min s`
(seconds as "19 min 41 s", "10 min", "58 s"); a list gives one per entry of `values`.

    python docs/_figures.py            # check: every page's number equals its file's; exit 1 if not
    python docs/_figures.py --write    # rewrite the pages' numbers from the files

The check is also a test (tests/test_figures.py). It reads the figures that are registered; a
number on a page that no entry names is not seen, which is why the user pages quote few numbers,
each with the command that measured it.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
REGISTRY = ROOT / "docs" / "figures.toml"
#: what one `{}` of a quoting text matches: a number as the formats write it (`-1,234.5`, `2e-3`,
#: `19 min 41 s`, `10 min`, `58 s`)
_NUMBER = r"(-?\d[\d,]*(?:\.\d+)?(?:e[-+]?\d+)?(?: min(?: \d+ s)?| s)?)"


@dataclass(frozen=True)
class Figure:
    """One registered quotation: where its numbers come from and where they stand."""

    index: int
    source: str
    file: Path
    rel: str
    values: tuple[str, ...]
    scale: float
    formats: tuple[str, ...]
    pages: tuple[str, ...]
    text: str

    def label(self) -> str:
        return f"figure {self.index} ({self.text[:60]!r})"


def load(registry: Path = REGISTRY, root: Path = ROOT) -> tuple[dict[str, dict], list[Figure]]:
    """The sources and the figures of `registry` (its files relative to `root`); ValueError
    naming the entry when one is malformed."""
    data = tomllib.loads(registry.read_text())
    sources = data.get("sources", {})
    figures = []
    for i, entry in enumerate(data.get("figure", [])):
        where = f"{registry.name}: figure {i}"
        name = entry.get("source")
        if name not in sources:
            raise ValueError(f"{where}: source {name!r} is not one of [sources]")
        values = tuple(entry["values"])
        fmt = entry.get("format", ".3g")
        formats = tuple(fmt) if isinstance(fmt, list) else (fmt,) * len(values)
        if len(formats) != len(values):
            raise ValueError(f"{where}: {len(formats)} formats for {len(values)} values")
        text = entry["text"]
        if text.endswith("{}") or text.startswith("{}"):
            raise ValueError(f"{where}: text must not start or end with {{}} (its ends delimit the numbers)")
        figure = Figure(
            index=i,
            source=name,
            file=root / sources[name]["file"],
            rel=sources[name]["file"],
            values=values,
            scale=float(entry.get("scale", 1.0)),
            formats=formats,
            pages=tuple(entry["pages"]),
            text=text,
        )
        if text.count("{}") != len(_expanded(figure)):
            raise ValueError(
                f"{where}: text has {text.count('{}')} {{}} for {len(_expanded(figure))} numbers"
            )
        figures.append(figure)
    return sources, figures


def _expanded(figure: Figure) -> list[tuple[str, str]]:
    """(value spec, format) per number: an interval path `.../*` gives three."""
    out = []
    for spec, fmt in zip(figure.values, figure.formats):
        if spec.endswith("/*"):
            out += [(spec[:-1] + key, fmt) for key in ("value", "ci95_low", "ci95_high")]
        else:
            out.append((spec, fmt))
    return out


def _lookup(data, path: str) -> float:
    node = data
    for key in path.strip().strip("/").split("/"):
        node = node[int(key)] if isinstance(node, list) else node[key]
    if isinstance(node, bool) or not isinstance(node, (int, float)):
        raise TypeError(f"{path}: {node!r} is not a number")
    return float(node)


def _format(value: float, fmt: str) -> str:
    if fmt == "min s":
        minutes, seconds = divmod(round(value), 60)
        if not minutes:
            return f"{seconds} s"
        return f"{minutes} min {seconds} s" if seconds else f"{minutes} min"
    return format(value, fmt)


def expected(figure: Figure, cache: dict[Path, object] | None = None) -> list[str]:
    """The numbers of `figure` as its page should write them, from its results file."""
    cache = {} if cache is None else cache
    if figure.file not in cache:
        cache[figure.file] = json.loads(figure.file.read_text())
    data = cache[figure.file]
    out = []
    for spec, fmt in _expanded(figure):
        if " / " in spec:
            top, bottom = spec.split(" / ")
            value = _lookup(data, top) / _lookup(data, bottom)
        else:
            value = _lookup(data, spec)
        out.append(_format(value * figure.scale, fmt))
    return out


def _pattern(text: str) -> re.Pattern:
    """`text` with each `{}` a number; a text that ends a table row (`... |`) matches only at the
    end of a line, so that a row is not taken for the start of a longer one."""
    body = _NUMBER.join(re.escape(part) for part in text.split("{}"))
    return re.compile(rf"{body}$" if text.endswith("|") else body, re.MULTILINE)


def check(figures: list[Figure], root: Path = ROOT, write: bool = False) -> list[str]:
    """Problems, one line each: a missing results file, a value the file lacks, a page that no
    longer quotes a registered text, a quoted number that differs from the file. With `write`,
    differing numbers are rewritten on the page (the other problems remain)."""
    problems: list[str] = []
    cache: dict[Path, object] = {}
    pages: dict[str, str] = {}
    for figure in figures:
        rel = figure.rel
        if not figure.file.exists():
            problems.append(f"{figure.label()}: results file {rel} does not exist")
            continue
        try:
            numbers = expected(figure, cache)
        except (KeyError, IndexError, TypeError, ValueError) as err:
            problems.append(f"{figure.label()}: {rel} has no value {err}")
            continue
        pattern = _pattern(figure.text)
        for page in figure.pages:
            if page not in pages:
                pages[page] = (root / page).read_text()
            text = pages[page]
            found = list(pattern.finditer(text))
            if not found:
                problems.append(f"{page}: no longer quotes {figure.label()}")
                continue
            for m in reversed(found):
                quoted = list(m.groups())
                if quoted == numbers:
                    continue
                problems.append(f"{page}: {quoted} where {rel} gives {numbers} ({figure.label()})")
                if write:
                    for k in reversed(range(len(numbers))):
                        text = text[: m.start(k + 1)] + numbers[k] + text[m.end(k + 1) :]
            pages[page] = text
    if write:
        for page, text in pages.items():
            if (root / page).read_text() != text:
                (root / page).write_text(text)
    return problems


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--write", action="store_true", help="rewrite the pages' numbers from the results files"
    )
    args = parser.parse_args(argv)
    _, figures = load()
    problems = check(figures, write=args.write)
    for line in problems:
        print(line)
    numbers = sum(len(_expanded(f)) * len(f.pages) for f in figures)
    if args.write:
        print(
            f"{len(figures)} figures ({numbers} numbers on the pages); {len(problems)} rewritten or unresolved"
        )
        return 0 if all(": no longer quotes" not in p and "does not exist" not in p for p in problems) else 1
    print(
        f"{len(figures)} figures ({numbers} numbers on the pages): {'ok' if not problems else 'differences above'}"
    )
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
