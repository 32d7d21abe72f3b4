"""The module graph of ``src/chebnorm`` (issue 27): no file-level import
cycles, and no private name crossing a stage boundary (issue 45).

The graph is built from the source with ``ast``, not by importing: an edge
``a -> b`` for every ``import`` or ``from ... import`` in ``a`` (at module
level or inside a function) that names module ``b`` of the package, or a name
defined in ``b``. A cycle is a strongly connected component of two or more
modules. A stage is a top-level part of the package (``chebnorm.hw`` with
everything below it, ``chebnorm.exceptions``, the facade ``chebnorm`` itself).
The modules of one stage share their private helpers; a private name (``_x``,
not a dunder) crosses a boundary when a module imports it from a module of
another stage (``from ..approx.m import _x``), imports a ``_module`` of another
stage, or reads ``m._x`` through a module of another stage it imported
(``from chebnorm.approx import m`` / ``import chebnorm.approx.m as m``). Tests
are exempt: they may reach into a module's internals.

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


def stage(module: str) -> str:
    """The stage a dotted module name belongs to: ``chebnorm.hw.units.base`` ->
    ``chebnorm.hw``; the facade ``chebnorm`` is its own."""
    return ".".join(module.split(".")[:2])


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
    list of ``(module, line, text)`` for each private name crossing a stage boundary."""
    mods = modules(src, package)
    edges: dict[str, set[str]] = {m: set() for m in mods}
    private: list[tuple[str, int, str]] = []
    for name, (path, pkg) in mods.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        bound: dict[str, str] = {}  # local name -> module it stands for

        def link(target: str, line: int, text: str) -> None:
            """An edge to module ``target``; a private module is private to its stage."""
            if target in mods and target != name:
                edges[name].add(target)
            if stage(target) != stage(name) and any(_private(p) for p in target.split(".")):
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
                        if _private(a.name) and stage(base) != stage(name):
                            private.append((name, node.lineno, text))
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                    and node.value.id in bound and _private(node.attr) \
                    and stage(bound[node.value.id]) != stage(name):
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


def test_no_private_name_crosses_a_stage():
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
        ("from ..a.y import _f\n", "from chebnorm.a.y import _f"),
        ("from chebnorm.a.y import g, _f\n", "from chebnorm.a.y import _f"),
        ("def h():\n    from ..a.y import _f\n", "from chebnorm.a.y import _f"),
        ("from ..a import y\nz = y._f\n", "chebnorm.a.y._f"),
        ("import chebnorm.a.y as m\nz = m._f()\n", "chebnorm.a.y._f"),
        ("from ..a import _z\n", "from chebnorm.a import _z"),
        ("from ..a._z import g\n", "from chebnorm.a._z import g"),
        ("import chebnorm.a._z\n", "import chebnorm.a._z"),
        ("from ..a.sub.w import _f\n", "from chebnorm.a.sub.w import _f"),
    ])
    def test_a_private_name_of_another_stage(self, tmp_path, text, shown):
        src = _package(tmp_path, {"chebnorm/b/__init__.py": "", "chebnorm/b/x.py": text,
                                  "chebnorm/a/y.py": "def _f(): pass\n", "chebnorm/a/_z.py": "def g(): pass\n",
                                  "chebnorm/a/sub/__init__.py": "", "chebnorm/a/sub/w.py": "def _f(): pass\n"})
        _, private = graph(src)
        assert [(p[0], p[2]) for p in private] == [("chebnorm.b.x", shown)], private

    @pytest.mark.parametrize("path, text, shown", [
        ("chebnorm/__init__.py", "from .a.y import _f\n", "from chebnorm.a.y import _f"),
        ("chebnorm/m.py", "from .a import y\nz = y._f\n", "chebnorm.a.y._f"),
    ])
    def test_the_facade_and_a_top_level_module_are_stages_too(self, tmp_path, path, text, shown):
        src = _package(tmp_path, {path: text, "chebnorm/a/y.py": "def _f(): pass\n"})
        _, private = graph(src)
        module = path.removesuffix(".py").removesuffix("/__init__").replace("/", ".")
        assert [(p[0], p[2]) for p in private] == [(module, shown)], private

    @pytest.mark.parametrize("path, text", [
        ("chebnorm/a/x.py", "from .y import _f\n"),
        ("chebnorm/a/x.py", "from chebnorm.a.y import g, _f\n"),
        ("chebnorm/a/x.py", "def h():\n    from .y import _f\n"),
        ("chebnorm/a/x.py", "from . import y\nz = y._f\n"),
        ("chebnorm/a/x.py", "import chebnorm.a.y as m\nz = m._f()\n"),
        ("chebnorm/a/x.py", "from . import _z\n"),
        ("chebnorm/a/x.py", "from ._z import g\n"),
        ("chebnorm/a/x.py", "import chebnorm.a._z\n"),
        ("chebnorm/a/sub/w.py", "from ..y import _f\nfrom .._z import g\n"),
        ("chebnorm/a/__init__.py", "from .y import _f\nfrom ._z import g\n"),
    ])
    def test_a_private_name_inside_its_stage_is_fine(self, tmp_path, path, text):
        src = _package(tmp_path, {path: text, "chebnorm/a/y.py": "def _f(): pass\n",
                                  "chebnorm/a/_z.py": "def g(): pass\n", "chebnorm/a/sub/__init__.py": "",
                                  **({} if path.endswith("w.py") else {"chebnorm/a/sub/w.py": ""})})
        edges, private = graph(src)
        assert private == []
        assert edges[path.removesuffix(".py").removesuffix("/__init__").replace("/", ".")]  # it was read

    def test_own_private_names_are_fine(self, tmp_path):
        src = _package(tmp_path, {"chebnorm/a/x.py": "def _f(): pass\nz = _f()\n",
                                  "chebnorm/a/y.py": "from . import x\nz = x.f, x.__doc__\n"})
        _, private = graph(src)
        assert private == []
