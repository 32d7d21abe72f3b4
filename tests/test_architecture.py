"""The layer rule of :data:`chebnorm.LAYERS`: a stage imports only the stages
listed for it, the package root loads no stage at import time (a lazy
``__getattr__`` facade is allowed), no stage uses another stage's private
names, the library never imports paper_repro or benchmarks, and those two use
the public API only.

The checker reads every import form (``import``, ``from ... import``, relative
imports at any level, imports inside functions, ``importlib.import_module`` /
``__import__`` with a literal name or an f-string with a literal prefix, and
attribute chains such as ``chebnorm.raster.render`` after ``import
chebnorm``). ``TestCheckerCatches`` injects each forbidden form into a copy of
the tree and shows the checker reports it.
"""

from __future__ import annotations

import ast
import functools
import shutil
from pathlib import Path

import pytest

import chebnorm

#: the source tree these tests sit in (not the installed package, which may be a copy
#: in site-packages after ``pip install .``)
REPO = Path(__file__).resolve().parent.parent
PACKAGE = REPO / "src" / "chebnorm"
CLIENTS = ("paper_repro", "benchmarks")  # public-API users outside the library
IMPORTERS = {"import_module", "__import__"}
#: the only places allowed an import whose module name is computed, and why;
#: what they may load is checked separately (test_registry_kernels_obey_layers)
DYNAMIC_IMPORTS = {
    "chebnorm/methods/registry.py": "span kernels named by method registry entries "
                                    "('module:attribute' strings, also from plugins)",
}


def read_layers(package: Path) -> dict[str, tuple[str, ...]]:
    """The ``LAYERS`` literal of ``package/__init__.py`` (the one written rule)."""
    return _layers_of((package / "__init__.py").read_text(encoding="utf-8"), package)


def _layers_of(text: str, where) -> dict[str, tuple[str, ...]]:
    tree = ast.parse(text)
    for node in tree.body:
        if isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if any(isinstance(t, ast.Name) and t.id == "LAYERS" for t in targets):
                return {k: tuple(v) for k, v in ast.literal_eval(node.value).items()}
    raise AssertionError(f"{where}/__init__.py defines no literal LAYERS")


def _root_names(text: str) -> set[str]:
    """Names the package root (source ``text``) binds at import time (module level,
    not inside a function such as the lazy ``__getattr__``)."""
    tree = ast.parse(text)
    names = set()

    def walk(node):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
            return  # its body runs later, if ever
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
        for child in ast.iter_child_nodes(node):
            walk(child)

    walk(tree)
    return names


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


class _Visitor(ast.NodeVisitor):
    """Collects ``(lineno, dotted name, how)`` for every reference to a module
    or attribute of ``chebnorm`` (and the first part of any other import)."""

    def __init__(self, package_parts: list[str]):
        self.package_parts = package_parts  # e.g. ["chebnorm", "hw"] for chebnorm/hw/x.py
        self.refs: list[tuple[int, str, str]] = []
        self.bound: dict[str, str] = {}  # local name -> dotted chebnorm target
        self.func_stack: list[str] = []

    def _resolve(self, module: str | None, level: int) -> str:
        if level == 0:
            return module or ""
        base = self.package_parts[:len(self.package_parts) - (level - 1)]
        return ".".join(base + ([module] if module else []))

    def _add(self, node, name: str, how: str) -> None:
        self.refs.append((node.lineno, name, how, tuple(self.func_stack)))

    def visit_FunctionDef(self, node):
        self.func_stack.append(node.name)
        self.generic_visit(node)
        self.func_stack.pop()

    visit_AsyncFunctionDef = visit_FunctionDef

    def visit_Import(self, node):
        for a in node.names:
            self._add(node, a.name, "import")
            if a.asname:
                self.bound[a.asname] = a.name
            else:
                self.bound[a.name.split(".")[0]] = a.name.split(".")[0]

    def visit_ImportFrom(self, node):
        base = self._resolve(node.module, node.level)
        for a in node.names:
            # "from chebnorm import raster" / "from .. import raster" name the
            # submodule; "from chebnorm.raster import render" names an attribute
            full = f"{base}.{a.name}" if base else a.name
            self._add(node, full, "from-import")
            self.bound[a.asname or a.name] = full

    def visit_Call(self, node):
        f = node.func
        name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""
        if name in IMPORTERS and node.args:
            arg = node.args[0]
            if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                self._add(node, arg.value, f"{name}()")
            elif isinstance(arg, ast.JoinedStr) and arg.values and \
                    isinstance(arg.values[0], ast.Constant):
                prefix = arg.values[0].value  # f"chebnorm.cli.{name}": checked up to the brace
                self._add(node, prefix.rstrip("."), f"{name}(f-string)")
            else:
                self._add(node, "<dynamic>", f"{name}()")
        self.generic_visit(node)

    def visit_Attribute(self, node):
        chain = []
        cur = node
        while isinstance(cur, ast.Attribute):
            chain.append(cur.attr)
            cur = cur.value
        if isinstance(cur, ast.Name) and cur.id in self.bound:
            target = self.bound[cur.id]
            if target == "chebnorm" or target.startswith("chebnorm."):
                self._add(node, ".".join([target, *reversed(chain)]), "attribute")
                return  # the inner Attribute nodes are prefixes of this chain
        self.generic_visit(node)


@functools.lru_cache(maxsize=None)
def references(text: str, package_parts: tuple[str, ...], filename: str = "<source>"):
    """The references of one module's source (cached: the injection tests check
    trees that differ from the pristine one in a single file)."""
    v = _Visitor(list(package_parts))
    v.visit(ast.parse(text, filename=filename))
    return tuple(v.refs)


class Tree:
    """A source tree on disk, with files replaced or added in memory
    (``overlay``: path relative to ``root``, POSIX form -> text)."""

    def __init__(self, root: Path, overlay: dict[str, str] | None = None):
        self.root = Path(root)
        self.overlay = dict(overlay or {})

    def read(self, rel: str) -> str:
        if rel in self.overlay:
            return self.overlay[rel]
        return (self.root / rel).read_text(encoding="utf-8")

    def exists(self, rel: str) -> bool:
        return rel in self.overlay or (self.root / rel).is_file()

    def py_files(self, folder: str) -> list[str]:
        base = self.root / folder
        found = {p.relative_to(self.root).as_posix() for p in base.rglob("*.py")} \
            if base.is_dir() else set()
        found |= {k for k in self.overlay if k.startswith(folder + "/") and k.endswith(".py")}
        return sorted(found)

    def appended(self, rel: str, line: str) -> "Tree":
        """This tree with ``line`` appended to the file ``rel`` (created if missing)."""
        old = self.read(rel) if self.exists(rel) else ""
        return Tree(self.root, {**self.overlay, rel: old + "\n" + line + "\n"})


def layer_violations(repo) -> list[str]:
    """Every breach of the layer rule in the tree at ``repo`` (a folder, or a
    :class:`Tree`, with ``src/chebnorm`` and optionally ``paper_repro/``,
    ``benchmarks/``)."""
    tree = repo if isinstance(repo, Tree) else Tree(repo)
    init = tree.read("src/chebnorm/__init__.py")
    layers = _layers_of(init, tree.root / "src" / "chebnorm")
    root_names = _root_names(init)
    bad = []
    for relpath in tree.py_files("src/chebnorm"):
        rel = Path(relpath).relative_to("src/chebnorm")
        parts = ["chebnorm", *rel.parent.parts]
        where = f"chebnorm/{rel.as_posix()}"
        if len(rel.parts) == 1:
            # a module at the root is a stage when LAYERS names it (chebnorm/exceptions.py)
            stage = {"__init__.py": "<root>", "__main__.py": "<main>"}.get(
                rel.name, rel.stem if rel.stem in layers else None)
            if stage is None:
                bad.append(f"{where}: a module at the package root outside LAYERS")
                continue
        else:
            stage = rel.parts[0]
            if stage not in layers:
                bad.append(f"{where}: stage {stage!r} is not declared in LAYERS")
                continue
        for line, name, how, funcs in references(tree.read(relpath), tuple(parts), relpath):
            head = name.split(".")
            loc = f"{where}:{line}: {how} {name}"
            if head[0] in CLIENTS:
                bad.append(f"{loc}: the library never imports {head[0]}")
                continue
            if name == "<dynamic>" and where in DYNAMIC_IMPORTS:
                continue
            if name == "<dynamic>":
                bad.append(f"{loc}: an import whose module name is not a literal cannot be checked")
                continue
            if head[0] != "chebnorm" or len(head) == 1:
                continue
            target = head[1]
            if stage == "<main>":
                continue  # the program entry may import the CLI (and anything)
            if stage == "<root>":
                if target in layers and funcs[:1] != ("__getattr__",):
                    bad.append(f"{loc}: the package root imports a stage at import time "
                               "(only a lazy module-level __getattr__ may)")
                continue
            if target in layers:
                if target != stage and target not in layers[stage]:
                    bad.append(f"{loc}: stage {stage!r} may import only "
                               f"{', '.join(layers[stage]) or 'no stage'}")
                elif target != stage and any(_private(p) for p in head[2:]):
                    bad.append(f"{loc}: private name of another stage")
            elif _private(target):
                bad.append(f"{loc}: private name of the package root")
            elif target not in root_names:
                bad.append(f"{loc}: chebnorm.{target} is not a stage nor a name the root "
                           "binds at import time (a lazy facade name): import the stage module")
    for client in CLIENTS:
        for relpath in tree.py_files(client):
            rel = Path(relpath)
            parts = tuple(rel.parent.parts)
            for line, name, how, _ in references(tree.read(relpath), parts, relpath):
                head = name.split(".")
                if head[0] == "chebnorm" and any(_private(p) for p in head[1:]):
                    bad.append(f"{rel.as_posix()}:{line}: {how} {name}: {client} uses the public "
                               "API only")
    return bad


# --- the real tree ----------------------------------------------------------------------------

def test_layers_is_the_package_constant():
    assert read_layers(PACKAGE) == chebnorm.LAYERS
    stages = sorted([p.name for p in PACKAGE.iterdir()
                     if p.is_dir() and (p / "__init__.py").exists()]
                    + [p.stem for p in PACKAGE.glob("*.py")
                       if p.name not in ("__init__.py", "__main__.py")])
    assert stages == sorted(chebnorm.LAYERS)
    for stage, allowed in chebnorm.LAYERS.items():  # a DAG: no stage allows itself or a cycle
        assert stage not in allowed
        for other in allowed:
            assert stage not in chebnorm.LAYERS[other], (stage, other)


def test_docstring_names_the_allowed_imports():
    doc = chebnorm.__doc__
    assert "imports core, symbolic, approx and methods (not hw, not export)" in doc
    assert chebnorm.LAYERS["raster"] == ("exceptions", "core", "symbolic", "approx", "methods")
    assert "imports core, symbolic, approx, hw" in doc
    assert chebnorm.LAYERS["export"] == ("exceptions", "core", "symbolic", "approx", "hw")
    assert "the floor every stage" in doc and "imports nothing of chebnorm" in doc


def test_exceptions_is_the_floor():
    """chebnorm.exceptions may be imported by every stage and imports no stage."""
    assert chebnorm.LAYERS["exceptions"] == ()
    for stage, allowed in chebnorm.LAYERS.items():
        assert stage == "exceptions" or "exceptions" in allowed, stage


def test_tree_obeys_the_layer_rule():
    assert layer_violations(REPO) == []


def test_registry_kernels_obey_layers():
    """The dynamic import of DYNAMIC_IMPORTS loads kernels that methods may import."""
    from chebnorm.approx.method_registry import registered_methods

    stage = "methods"
    for spec in registered_methods():
        if isinstance(spec.kernel, str):
            head = spec.kernel.partition(":")[0].split(".")
            assert head[0] == "chebnorm" and (head[1] == stage
                                              or head[1] in chebnorm.LAYERS[stage]), spec
            assert not any(_private(p) for p in head[2:]), spec


# --- the checker cannot be fooled: inject each bad form into a copy -------------------------

def _copy_tree(tmp_path: Path) -> Path:
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    shutil.copytree(PACKAGE, tmp_path / "src" / "chebnorm", ignore=ignore)
    for client in CLIENTS:
        if (REPO / client).is_dir():
            shutil.copytree(REPO / client, tmp_path / client,
                            ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "*.json",
                                                          "*.md", "c"))
    return tmp_path


INJECTIONS = [
    # (file, line appended, what the report must mention)
    ("src/chebnorm/hw/fixed.py", "from chebnorm import raster", "chebnorm.raster"),
    ("src/chebnorm/hw/fixed.py", "from .. import raster", "chebnorm.raster"),
    ("src/chebnorm/hw/fixed.py", "from ..raster import render", "chebnorm.raster.render"),
    ("src/chebnorm/hw/fixed.py", "import chebnorm.raster.render", "chebnorm.raster.render"),
    ("src/chebnorm/hw/fixed.py", "import chebnorm\nx = chebnorm.raster.render", "chebnorm.raster.render"),
    ("src/chebnorm/hw/fixed.py", "import chebnorm as cn\nx = cn.cli.main", "chebnorm.cli.main"),
    ("src/chebnorm/hw/fixed.py", "import importlib\nm = importlib.import_module('chebnorm.raster')",
     "import_module() chebnorm.raster"),
    ("src/chebnorm/hw/fixed.py", "from importlib import import_module\nm = import_module('chebnorm.cli')",
     "import_module() chebnorm.cli"),
    ("src/chebnorm/hw/fixed.py", "m = __import__('chebnorm.raster.meshes')",
     "__import__() chebnorm.raster.meshes"),
    ("src/chebnorm/hw/fixed.py", "import importlib\nm = importlib.import_module(f'chebnorm.raster.{1}')",
     "chebnorm.raster"),
    ("src/chebnorm/hw/fixed.py", "import importlib\nname = 'x'\nm = importlib.import_module(name)",
     "<dynamic>"),
    ("src/chebnorm/hw/fixed.py", "def f():\n    from chebnorm.raster import render\n    return render",
     "chebnorm.raster.render"),
    ("src/chebnorm/hw/fixed.py", "class K:\n    def f(self):\n        import chebnorm.methods\n",
     "chebnorm.methods"),
    ("src/chebnorm/symbolic/symbols.py", "from chebnorm.approx import fit", "chebnorm.approx.fit"),
    ("src/chebnorm/approx/targets.py", "from ..symbolic import _algebra", "chebnorm.symbolic._algebra"),
    ("src/chebnorm/raster/scanline.py", "from chebnorm.hw import fixed", "chebnorm.hw.fixed"),
    ("src/chebnorm/raster/scanline.py", "from chebnorm import fit", "chebnorm.fit"),
    ("src/chebnorm/methods/ops.py", "import paper_repro.style", "paper_repro"),
    ("src/chebnorm/methods/ops.py", "import importlib\nm = importlib.import_module('benchmarks.run')",
     "benchmarks"),
    ("src/chebnorm/__init__.py", "from . import approx", "the package root imports a stage"),
    ("src/chebnorm/__init__.py", "from chebnorm.approx import fit", "the package root imports a stage"),
    ("src/chebnorm/__init__.py", "import chebnorm.raster", "the package root imports a stage"),
    ("src/chebnorm/__init__.py", "def helper():\n    from chebnorm.raster import render\n",
     "the package root imports a stage"),
    ("paper_repro/style.py", "from chebnorm.approx._io import write_atomic", "chebnorm.approx._io"),
    ("paper_repro/style.py", "from chebnorm.approx.sollya import _sollya_expr",
     "chebnorm.approx.sollya._sollya_expr"),
    ("paper_repro/style.py", "from chebnorm.approx import sollya\nf = sollya._interval",
     "chebnorm.approx.sollya._interval"),
    ("benchmarks/bench_fit.py", "import chebnorm.symbolic._checks", "chebnorm.symbolic._checks"),
    ("benchmarks/bench_fit.py", "import importlib\nm = importlib.import_module('chebnorm.hw._x')",
     "chebnorm.hw._x"),
    ("src/chebnorm/newstage/__init__.py", "x = 1", "stage 'newstage' is not declared"),
    ("src/chebnorm/exceptions.py", "from chebnorm.core import tools", "chebnorm.core.tools"),
    ("src/chebnorm/exceptions.py", "def f():\n    from .core.files import write_atomic\n",
     "stage 'exceptions' may import only no stage"),
    ("src/chebnorm/helpers.py", "x = 1", "a module at the package root outside LAYERS"),
]


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    return _copy_tree(tmp_path_factory.mktemp("pristine"))


class TestCheckerCatches:
    def test_copy_is_clean(self, pristine):
        assert layer_violations(pristine) == []

    @pytest.mark.parametrize("relpath,line,needle", INJECTIONS,
                             ids=[f"{i}-{p.split('/')[-1]}" for i, (p, _, _) in enumerate(INJECTIONS)])
    def test_injected_import_is_reported(self, pristine, relpath, line, needle):
        bad = layer_violations(Tree(pristine).appended(relpath, line))
        assert bad, f"{line!r} in {relpath} went unnoticed"
        if needle is not None:
            assert any(needle in b for b in bad), bad
        assert all(relpath.split("/")[-1] in b or relpath.split("/")[-2] in b for b in bad), bad

    def test_the_overlay_is_what_is_checked(self, pristine, tmp_path):
        """An injection written to a real copy of the tree is reported the same as
        through the in-memory overlay the other tests use."""
        relpath, line = "src/chebnorm/hw/fixed.py", "from chebnorm import raster"
        tree = tmp_path / "tree"
        shutil.copytree(pristine, tree)
        target = tree / relpath
        target.write_text(target.read_text(encoding="utf-8") + "\n" + line + "\n", encoding="utf-8")
        on_disk = layer_violations(tree)
        assert on_disk and on_disk == layer_violations(Tree(pristine).appended(relpath, line))

    def test_lazy_facade_in_root_is_allowed(self, pristine):
        tree = Tree(pristine).appended("src/chebnorm/__init__.py", '''

def __getattr__(name):
    """Lazy facade: cn.fit imports chebnorm.approx on first use."""
    if name == "fit":
        from chebnorm.approx import fit
        return fit
    import importlib
    if name == "render":
        return importlib.import_module("chebnorm.raster").render
    raise AttributeError(name)
''')
        assert layer_violations(tree) == []
        # ... but a stage may not reach a later one through a facade name
        tree = tree.appended("src/chebnorm/raster/scanline.py", "import chebnorm\nf = chebnorm.fit")
        assert any("chebnorm.fit is not a stage" in b for b in layer_violations(tree))

    def test_rule_comes_from_layers(self, pristine):
        """Widening LAYERS (raster may import hw) makes that import legal: the
        checker has no rule of its own."""
        tree = Tree(pristine).appended("src/chebnorm/raster/scanline.py", "from chebnorm.hw import fixed")
        assert layer_violations(tree) != []
        init = "src/chebnorm/__init__.py"
        text = tree.read(init)
        old = '"raster": ("exceptions", "core", "symbolic", "approx", "methods"),'
        assert old in text
        widened = Tree(pristine, {**tree.overlay, init: text.replace(
            old, '"raster": ("exceptions", "core", "symbolic", "approx", "methods", "hw"),')})
        assert layer_violations(widened) == []
