"""The layout rules of docs/architecture.md, checked on the source so they stay true.

Each rule has a reason: modules of one idea stay short enough to read whole, functions short
enough to test, private names stay private, and imports only go down the layers so a part can
be used (and tested) without the ones above it.
"""

import ast
from pathlib import Path

import pytest

from conftest import LONGEST_FIRST, ROOT

SRC = ROOT / "src" / "hdwf"
MODULES = sorted(SRC.rglob("*.py"))
# Lower layers never import higher ones (``hdwf/__init__`` holds constants only).
LAYERS = ["common", "drive", "fe", "study", "validation", "report", "stages", "config", "cli"]
MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 80


def _name(path: Path) -> str:
    return ".".join(path.relative_to(SRC.parent).with_suffix("").parts).removesuffix(".__init__")


def _imports(path: Path) -> list[tuple[str, list[str], int]]:
    """(absolute module, imported names, line) of every ``import``/``from`` in ``path``."""
    package = _name(path) if path.name == "__init__.py" else _name(path).rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parent + ([node.module] if node.module else []))
            out.append((base, [a.name for a in node.names], node.lineno))
        elif isinstance(node, ast.Import):
            out += [(a.name, [], node.lineno) for a in node.names]
    return out


def _layer(module: str) -> int | None:
    parts = module.split(".")
    if parts[0] != "hdwf" or len(parts) < 2:
        return None
    return LAYERS.index(parts[1]) if parts[1] in LAYERS else None


def test_the_source_tree_is_found():
    assert len(MODULES) > 30, MODULES


def test_the_long_test_files_started_first_exist():
    # a renamed file would silently lose its early start under `pytest -n 2`
    assert [f for f in LONGEST_FIRST if not (ROOT / "tests" / f).is_file()] == []


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(SRC)))
def test_module_is_short(path):
    assert path.read_text().count("\n") <= MAX_MODULE_LINES


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(SRC)))
def test_functions_are_short(path):
    long = [f"{n.name} ({n.end_lineno - n.lineno + 1} lines)" for n in ast.walk(ast.parse(path.read_text()))
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and n.end_lineno - n.lineno + 1 > MAX_FUNCTION_LINES]
    assert not long


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(SRC)))
def test_no_private_name_of_another_module(path):
    own = _name(path)
    private = [f"line {line}: {mod}.{n}" for mod, names, line in _imports(path) for n in names
               if mod.startswith("hdwf") and mod != own and n.startswith("_") and not n.startswith("__")]
    assert not private


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(SRC)))
def test_imports_only_go_down(path):
    mine = _layer(_name(path))
    if mine is None:
        return
    upward = [f"line {line}: {mod}" for mod, _, line in _imports(path)
              if (theirs := _layer(mod)) is not None and theirs > mine]
    assert not upward


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(SRC)))
def test_library_knows_nothing_of_snakemake(path):
    assert not [m for m, _, _ in _imports(path) if m.split(".")[0] == "snakemake"]


@pytest.mark.parametrize("package", sorted(p.parent for p in SRC.rglob("__init__.py")),
                         ids=lambda p: str(p.relative_to(SRC.parent)))
def test_every_subpackage_says_its_job(package):
    doc = ast.get_docstring(ast.parse((package / "__init__.py").read_text()))
    assert doc and len(doc.split()) >= 10


def test_figures_are_drawn_only_by_stages_and_the_report():
    drawing = sorted(_name(p) for p in MODULES
                     if any(m.startswith("hdwf.report") for m, _, _ in _imports(p)))
    assert all(m.split(".")[1] in ("report", "stages") for m in drawing), drawing
