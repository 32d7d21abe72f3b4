"""The module graph of ``src/chebnorm`` (issue 27): no file-level import
cycles, and no private name crossing a module boundary.

The graph is built from the source with ``ast``, not by importing: an edge
``a -> b`` for every ``import`` or ``from ... import`` in ``a`` (at module
level or inside a function) that names module ``b`` of the package, or a name
defined in ``b``. A cycle is a strongly connected component of two or more
modules. A private name (``_x``, not a dunder) crosses a boundary when a
module imports it from another module (``from .m import _x``), imports a
``_module`` of the package, or reads ``m._x`` through a module it imported
(``from . import m`` / ``import chebnorm.m as m``). Tests are exempt: they may
reach into a module's internals.

``TestCheckerCatches`` writes each forbidden form into a small package and
shows the checker reports it, so these tests can fail.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parent.parent / "src"


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def modules(src: Path, package: str = "chebnorm") -> dict[str, tuple[Path, list[str]]]:
    """Dotted module name -> (file, the package parts relative imports start from)."""
    found = {}
    for path in sorted((src / package).rglob("*.py")):
        parts = list(path.relative_to(src).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
            pkg = parts
        else:
            pkg = parts[:-1]
        found[".".join(parts)] = (path, pkg)
    return found


def _base(node: ast.ImportFrom, pkg: list[str]) -> str:
    if not node.level:
        return node.module or ""
    base = pkg[:len(pkg) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def graph(src: Path, package: str = "chebnorm"):
    """``(edges, private)``: ``edges[a]`` the modules ``a`` imports; ``private`` a
    list of ``(module, line, text)`` for each private name crossing a boundary."""
    mods = modules(src, package)
    edges: dict[str, set[str]] = {m: set() for m in mods}
    private: list[tuple[str, int, str]] = []
    for name, (path, pkg) in mods.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        bound: dict[str, str] = {}  # local name -> module it stands for

        def link(target: str, line: int, text: str) -> None:
            """An edge to module ``target``; a private module is private to itself."""
            if target in mods and target != name:
                edges[name].add(target)
            if target != name and not name.startswith(target + ".") \
                    and any(_private(p) for p in target.split(".")):
                private.append((name, line, text))

        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.split(".")[0] != package:
                        continue
                    link(a.name, node.lineno, f"import {a.name}")
                    if a.asname:
                        bound[a.asname] = a.name
            elif isinstance(node, ast.ImportFrom):
                base = _base(node, pkg)
                if base.split(".")[0] != package:
                    continue
                for a in node.names:
                    full = f"{base}.{a.name}"
                    text = f"from {base} import {a.name}"
                    if full in mods:  # a submodule
                        link(full, node.lineno, text)
                        bound[a.asname or a.name] = full
                    else:  # a name defined in module `base`
                        link(base, node.lineno, text)
                        if _private(a.name) and base != name:
                            private.append((name, node.lineno, text))
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                    and node.value.id in bound and _private(node.attr) \
                    and bound[node.value.id] != name:
                private.append((name, node.lineno, f"{bound[node.value.id]}.{node.attr}"))
    return edges, sorted(set(private))


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of two or more modules (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    found = []
    counter = 0
    for root in sorted(edges):
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(edges[w]))))
                    break
                if w in on:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        found.append(sorted(comp))
    return found


# --- the real tree ----------------------------------------------------------------------------

def test_the_package_has_no_import_cycle():
    edges, _ = graph(SRC)
    assert len(edges) > 50
    assert cycles(edges) == []


def test_no_private_name_crosses_a_module():
    _, private = graph(SRC)
    assert private == []


# --- the checker can fail ------------------------------------------------------------------------

def _package(tmp_path: Path, files: dict[str, str]) -> Path:
    for rel, text in {"chebnorm/__init__.py": "", "chebnorm/a/__init__.py": "", **files}.items():
        path = tmp_path / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return tmp_path


class TestCheckerCatches:
    @pytest.mark.parametrize("x_text, y_text", [
        ("from . import y\n", "from . import x\n"),
        ("from .y import f\n", "def f(): pass\nfrom .x import g\n"),
        ("import chebnorm.a.y\n", "def f():\n    from chebnorm.a import x\n"),
        ("from ..a import y\n", "from .x import *\n"),
    ])
    def test_a_two_module_cycle(self, tmp_path, x_text, y_text):
        src = _package(tmp_path, {"chebnorm/a/x.py": x_text, "chebnorm/a/y.py": y_text})
        edges, _ = graph(src)
        assert cycles(edges) == [["chebnorm.a.x", "chebnorm.a.y"]]

    def test_a_longer_cycle_through_a_package(self, tmp_path):
        src = _package(tmp_path, {"chebnorm/a/x.py": "from . import y\n",
                                  "chebnorm/a/y.py": "from chebnorm import b\n",
                                  "chebnorm/b/__init__.py": "from chebnorm.a.x import f\n"})
        edges, _ = graph(src)
        assert cycles(edges) == [["chebnorm.a.x", "chebnorm.a.y", "chebnorm.b"]]

    def test_no_false_cycle(self, tmp_path):
        src = _package(tmp_path, {"chebnorm/a/x.py": "from . import y\n",
                                  "chebnorm/a/y.py": "import numpy\n"})
        edges, private = graph(src)
        assert cycles(edges) == [] and private == []

    @pytest.mark.parametrize("text, shown", [
        ("from .y import _f\n", "from chebnorm.a.y import _f"),
        ("from chebnorm.a.y import g, _f\n", "from chebnorm.a.y import _f"),
        ("def h():\n    from .y import _f\n", "from chebnorm.a.y import _f"),
        ("from . import y\nz = y._f\n", "chebnorm.a.y._f"),
        ("import chebnorm.a.y as m\nz = m._f()\n", "chebnorm.a.y._f"),
        ("from . import _z\n", "from chebnorm.a import _z"),
        ("from ._z import g\n", "from chebnorm.a._z import g"),
        ("import chebnorm.a._z\n", "import chebnorm.a._z"),
    ])
    def test_a_private_name(self, tmp_path, text, shown):
        src = _package(tmp_path, {"chebnorm/a/x.py": text, "chebnorm/a/y.py": "def _f(): pass\n",
                                  "chebnorm/a/_z.py": "def g(): pass\n"})
        _, private = graph(src)
        assert [(p[0], p[2]) for p in private] == [("chebnorm.a.x", shown)], private

    def test_own_private_names_are_fine(self, tmp_path):
        src = _package(tmp_path, {"chebnorm/a/x.py": "def _f(): pass\nz = _f()\n",
                                  "chebnorm/a/y.py": "from . import x\nz = x.f, x.__doc__\n"})
        _, private = graph(src)
        assert private == []
