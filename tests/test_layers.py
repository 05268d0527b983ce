"""The package's architecture, checked: imports point down the layers, never across into
another subpackage's private modules, and the module import graph has no cycle
(docs/architecture.md)."""

from __future__ import annotations

import ast
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "jaxbearing"

#: bottom to top; a module may import its own layer's modules and any layer below
LAYERS = [
    "_errors",
    "contact",
    "geometry",
    "io",
    "flange",
    "forces",
    "dynamics",
    "run",
    "design",
    "sweep",
    "cli",
]
#: layers of equal rank may not import each other
RANK = {name: i for i, name in enumerate(LAYERS)}
RANK["forces"] = RANK["flange"]


def _module_name(path: pathlib.Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _imports(path: pathlib.Path) -> list[tuple[str, int, bool]]:
    """(absolute module imported, line, under TYPE_CHECKING) for every import in the file,
    function-level imports included."""
    name = _module_name(path)
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    tree = ast.parse(path.read_text())
    type_checking_lines: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for sub in ast.walk(node):
                type_checking_lines.add(getattr(sub, "lineno", -1))
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
                targets = [target] if node.module else [f"{target}.{a.name}" for a in node.names]
            else:
                targets = [node.module or ""]
            out += [(t, node.lineno, node.lineno in type_checking_lines) for t in targets]
        elif isinstance(node, ast.Import):
            out += [(a.name, node.lineno, node.lineno in type_checking_lines) for a in node.names]
    return [(t, line, tc) for t, line, tc in out if t.split(".")[0] == "jaxbearing"]


def _layer(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


FILES = sorted(PACKAGE.rglob("*.py"))


def test_every_subpackage_is_a_known_layer():
    found = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert found == set(LAYERS) - {"_errors"}, found
    top_modules = {p.stem for p in PACKAGE.glob("*.py")}
    assert top_modules == {"__init__", "_errors"}, top_modules


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_imports_point_down_and_use_public_names(path):
    source = _module_name(path)
    src_layer = _layer(source)
    if src_layer is None:  # jaxbearing/__init__.py: the public API may import everything
        return
    for target, line, type_checking in _imports(path):
        tgt_layer = _layer(target)
        if tgt_layer is None:
            pytest.fail(f"{path.name}:{line} imports the top-level package {target!r}")
        if tgt_layer == src_layer or type_checking:  # annotations only: no run-time dependency
            continue
        assert RANK[tgt_layer] < RANK[src_layer], (
            f"{source}:{line} imports {target}: layer {tgt_layer!r} is not below {src_layer!r}"
        )
        private = [p for p in target.split(".")[2:] if p.startswith("_")]
        if tgt_layer != "_errors":
            assert not private, f"{source}:{line} imports a private module of another layer: {target}"


def test_no_import_cycle_between_modules():
    graph: dict[str, set[str]] = {}
    for path in FILES:
        source = _module_name(path)
        deps = set()
        for target, _, type_checking in _imports(path):
            if type_checking:
                continue
            while target not in {_module_name(p) for p in FILES} and "." in target:
                target = target.rpartition(".")[0]  # from .x import name -> module x
            if target != source:
                deps.add(target)
        graph[source] = deps
    # a package's __init__ re-exports its modules: edges into a package count as edges into
    # the modules it imports, so cycles through __init__ files are found too
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for dep in sorted(graph.get(node, ())):
            if dep in (node.rpartition(".")[0],):  # a module's own package __init__ (parent)
                continue
            if state.get(dep) == 1:
                cycle = stack[stack.index(dep) :] + [dep]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if dep not in state:
                visit(dep)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node)


def test_optimise_uses_only_public_jaxbearing_names():
    for path in sorted((ROOT / "optimise").glob("*.py")):
        for target, line, _ in _imports(path):
            private = [p for p in target.split(".")[1:] if p.startswith("_")]
            assert not private, f"optimise/{path.name}:{line} imports private {target}"
