"""Sphinx configuration of the chebnorm documentation.

Build (offline, nitpicky, warnings are errors)::

    python -m sphinx -W -n -b html docs docs/_build/html

The API reference is generated from the code (autosummary + autodoc, numpydoc
docstrings): a page per stage (its ``__all__``) and a page per module (the
public names it defines that its stage does not re-export). The notebooks are
copied into the gallery and executed by the build, their outputs cached by
jupyter-cache under ``docs/_build/.jupyter_cache`` (a notebook runs again only
when its code changes). Math is typeset by a MathJax shipped with the
``sphinx-mathjax-offline`` package and copied into the site, so pages need no
network. Intersphinx links to Python, numpy, sympy and mpmath are made only
when their inventories can be fetched (or were fetched before, into
``docs/_build/_inventories``); offline, such names render as plain code.
"""

from __future__ import annotations

import importlib
import inspect
import os
import pkgutil
import re
import shutil
import socket
import sys
import urllib.request
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT))

import chebnorm  # noqa: E402

project = "chebnorm"
author = "the chebnorm authors"
copyright = "2026, the chebnorm authors"
release = chebnorm.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_nb",
    # MathJax 3 shipped inside the package, copied to _static/mathjax: math without a CDN
    "sphinx-mathjax-offline",
]

source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
# fragments included by a page: _layer_rule.rst (contributing.md), _cli (cli.md), _bench
# (benchmarks.md), facade/_table.rst (api.rst)
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints", "_layer_rule.rst", "_cli", "_bench",
                    "facade/_table.rst"]
templates_path = ["_templates"]

# every cross-reference must resolve (python -m sphinx -n); see _resolve_in_defining_module
nitpicky = True
nitpick_ignore_regex = [
    # Names of other projects. They link through intersphinx when the inventories are
    # reachable; offline they have no target in this site and render as code.
    ("py:.*", r"(math|abc|typing|collections|enum|dataclasses|pathlib|concurrent|io|os|subprocess)(\..*)?"),
    ("py:.*", r"(numpy|np|sympy|sp|mpmath|scipy|flint|matplotlib|PIL|numba|trimesh)(\..*)?"),
    ("py:.*", r"(ABC|Enum|IntEnum|NamedTuple|Path|Axes|Figure|ndarray|Symbol|Expr|Rational|Basic)"),
    ("py:.*", r"(mpf|mpc|arb|arb_poly|fmpq|fmpz|Future|Executor|Callable|Iterable|Iterator|Sequence|Mapping)"),
    ("py:.*", r"(int|float|str|bytes|bool|dict|list|tuple|set|frozenset|object|type|callable|None|complex)"),
    ("py:.*", r"(ValueError|TypeError|OSError|RuntimeError|KeyError|UserWarning|Warning|Exception)"),
]

# -- API reference --------------------------------------------------------
autosummary_generate = True
autosummary_ignore_module_all = False     # list exactly what __all__ exports
autosummary_imported_members = True
autodoc_default_options = {"members": True, "undoc-members": True, "show-inheritance": False}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()
numpydoc_xref_param_type = False
add_module_names = False

# -- Markdown / notebooks ----------------------------------------------------
# Executed at build time; outputs cached per notebook (keyed on its code), in one place
# for every build directory, so a rebuild (and the docs test) reuses them.
nb_execution_mode = "cache"
nb_execution_cache_path = str(DOCS / "_build" / ".jupyter_cache")
nb_execution_timeout = 600
nb_execution_raise_on_error = True
nb_execution_show_tb = True
# ipywidgets' views need the widget manager's JavaScript from a CDN: show their static
# fallback instead (each notebook draws its static figure before it adds sliders)
nb_mime_priority_overrides = [("html", "application/vnd.jupyter.widget-view+json", None),
                              ("html", "application/vnd.jupyter.widget-state+json", None)]
nb_ipywidgets_js: dict = {}  # and never load require.js or the widget manager from a CDN
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# -- Intersphinx: only inventories that can be had; never a warning offline ----------
INVENTORIES = {
    "python": "https://docs.python.org/3/",
    "numpy": "https://numpy.org/doc/stable/",
    "sympy": "https://docs.sympy.org/latest/",
    "mpmath": "https://mpmath.org/doc/current/",
}
INVENTORY_CACHE = DOCS / "_build" / "_inventories"


def _inventory(name: str, url: str) -> str | None:
    """The local path of ``name``'s ``objects.inv``: fetched now when the host answers
    within two seconds, else an earlier fetch; None when neither (offline, first build).
    ``CHEBNORM_DOCS_OFFLINE=1`` skips the network."""
    path = INVENTORY_CACHE / f"{name}.inv"
    if os.environ.get("CHEBNORM_DOCS_OFFLINE") != "1":
        host = re.match(r"https://([^/]+)/", url).group(1)
        try:
            socket.create_connection((host, 443), timeout=2).close()
            with urllib.request.urlopen(url + "objects.inv", timeout=10) as resp:
                data = resp.read()
            INVENTORY_CACHE.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        except OSError:
            pass
    return str(path) if path.is_file() else None


intersphinx_mapping = {name: (url, inv) for name, url in INVENTORIES.items()
                       if (inv := _inventory(name, url)) is not None}
intersphinx_timeout = 5

# -- HTML -------------------------------------------------------------------
html_theme = "furo"
html_title = f"chebnorm {release}"
html_static_path = ["_static"]
html_search_scorer = str(DOCS / "_static" / "scorer.js")  # attributes after functions and pages
html_css_files = ["wide.css"]


def _copy_notebooks() -> None:
    """Copy notebooks/*.ipynb into the gallery (a build product, git-ignored)."""
    out = DOCS / "gallery" / "notebooks"
    out.mkdir(parents=True, exist_ok=True)
    for nb in sorted((ROOT / "notebooks").glob("*.ipynb")):
        target = out / nb.name
        if not target.exists() or target.read_bytes() != nb.read_bytes():
            shutil.copyfile(nb, target)


#: the paper figures shown in the gallery, in this order (topic directories of figures/)
FIGURE_TOPICS = {
    "criterion": "Seed 003: the normalization criterion",
    "normalization": "Seed 000: fast normalization methods",
    "highlight": "Seed 002: highlights for Gouraud shading",
    "bump": "Seed 001: bump mapping on Phong hardware",
    "shaders": "Exported shaders on a real driver (written by figures/shaders/shader_demo.py)",
}


def _markdown_text(text: str) -> str:
    """Caption text shown literally in MyST (punctuation escaped)."""
    return "".join("\\" + ch if ch in "\\`*_[]<>|{}$" else ch for ch in " ".join(text.split()))


def _write_if_changed(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` unless it holds it already (keeps Sphinx's cache)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


def _write_figure_gallery() -> None:
    """gallery/figures.md: every committed figure with its caption file (a
    build product, git-ignored; regenerated on each build so it follows
    ``chebnorm repro``)."""
    lines = ["# Paper figures", "",
             "Every figure that `chebnorm repro` writes under `figures/`, with its caption. "
             "Each has its data beside it (`.csv`) and an SVG version.", ""]
    for topic, title in FIGURE_TOPICS.items():
        pngs = sorted((ROOT / "figures" / topic).glob("*.png"))
        if not pngs:
            continue
        lines += [f"## {title}", ""]
        for png in pngs:
            caption_file = png.with_suffix(".txt")
            caption = caption_file.read_text(encoding="utf-8") if caption_file.exists() else png.stem
            lines += [f"```{{figure}} ../../figures/{topic}/{png.name}", f":alt: {png.stem}",
                      ":width: 100%", "", f"`figures/{topic}/{png.name}`: {_markdown_text(caption)}",
                      "```", ""]
    _write_if_changed(DOCS / "gallery" / "figures.md", "\n".join(lines))


def _subparsers(parser):
    """``(name, parser)`` of each subcommand of ``parser``, in the order they were added."""
    import argparse

    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return list(action.choices.items())
    return []


def _write_cli_help() -> None:
    """_cli/COMMAND.txt: each command's ``--help`` (``hw_verilog.txt`` for
    ``hw verilog``), printed 88 columns wide whatever the terminal, so the CLI page
    shows exactly what the parser accepts."""
    from chebnorm.cli import build_parser

    saved = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = "88"
    try:
        for name, sub in _subparsers(build_parser()):
            nested = _subparsers(sub)
            for sub_name, leaf in nested or [(None, sub)]:
                stem = name if sub_name is None else f"{name}_{sub_name}"
                _write_if_changed(DOCS / "_cli" / f"{stem}.txt", leaf.format_help())
    finally:
        if saved is None:
            os.environ.pop("COLUMNS", None)
        else:
            os.environ["COLUMNS"] = saved


STAGES = ("core", "symbolic", "approx", "export", "methods", "hw", "raster")


def _stage_modules() -> dict[str, list[str]]:
    """Every public module below each stage (no ``_name`` part), in name order,
    without the modules a stage's ``__all__`` exports (autosummary pages those)."""
    out = {}
    for stage in STAGES:
        pkg = importlib.import_module(f"chebnorm.{stage}")
        exported = {getattr(pkg, n).__name__ for n in pkg.__all__ if inspect.ismodule(getattr(pkg, n))}
        names = [m.name for m in pkgutil.walk_packages(pkg.__path__, f"chebnorm.{stage}.")
                 if not any(part.startswith("_") for part in m.name.split("."))]
        out[stage] = sorted(n for n in names if n not in exported)
    return out


def _stage_api_modules() -> dict[str, list[str]]:
    """The modules each stage's ``__all__`` exports that have no ``__all__`` themselves:
    every public name they define is public (``chebnorm.core.files.write_atomic``)."""
    out = {}
    for stage in STAGES:
        pkg = importlib.import_module(f"chebnorm.{stage}")
        mods = [getattr(pkg, n) for n in pkg.__all__ if inspect.ismodule(getattr(pkg, n))]
        out[stage] = sorted(m.__name__ for m in mods if not hasattr(m, "__all__"))
    return out


def _module_page(modname: str) -> str:
    """The page of one module: the public names it defines, except those its stage
    re-exports (documented once, on the stage's page, and linked from here)."""
    stage = ".".join(modname.split(".")[:2])
    pkg = importlib.import_module(stage)
    mod = importlib.import_module(modname)
    # what it exports, and every public name it defines (an implementation module's
    # __all__ is empty: its stage exports the API)
    own = list(getattr(mod, "__all__", None) or [])
    own += [n for n, v in vars(mod).items() if not n.startswith("_") and n not in own
            and getattr(v, "__module__", None) == modname]
    # the names this module shares with its stage (the same object): documented there
    shown = [n for n in own if n in pkg.__all__ and getattr(mod, n, None) is getattr(pkg, n)
             and (inspect.isfunction(getattr(pkg, n)) or inspect.isclass(getattr(pkg, n)))]
    lines = [modname, "=" * len(modname), ""]
    if modname in FACADE_CALLS:
        label = "facade-" + modname.removeprefix("chebnorm.").replace(".", "-")
        lines += [f"The module is callable: :ref:`cn.{modname.removeprefix('chebnorm.')}(...) <{label}>` "
                  "on the API page.", ""]
    if hasattr(pkg, modname.split(".")[2]) and not inspect.ismodule(getattr(pkg, modname.split(".")[2])) \
            and len(modname.split(".")) == 3:
        # the stage exports a function of the module's name (chebnorm.approx.certify):
        # one full name, two objects; the stage's function keeps the name, and this
        # page shows the module's text and documents its other names one by one
        from sphinx.pycode import ModuleAnalyzer
        attrs = {name for (cls, name) in ModuleAnalyzer.for_module(modname).find_attr_docs() if cls == ""}
        members = sorted(n for n, v in vars(mod).items() if not n.startswith("_") and n not in shown
                         and (getattr(v, "__module__", None) == modname and not inspect.ismodule(v)
                              or n in attrs))
        lines += [f".. automodule:: {modname}", "   :no-index:", "", f".. currentmodule:: {modname}", ""]
        for n in members:
            v = getattr(mod, n)
            kind = "class" if inspect.isclass(v) else "function" if callable(v) else "data"
            lines += [f".. auto{kind}:: {modname}.{n}", ""]
    else:
        lines += [f".. automodule:: {modname}", "   :members:", "   :undoc-members:", "   :ignore-module-all:"]
        if shown:
            lines.append(f"   :exclude-members: {', '.join(shown)}")
        lines.append("")
    if shown:
        lines += [f"Defined here and documented with :mod:`{stage}`:", ""]
        facade = {id(obj): f"chebnorm.{name}" for name, obj, _path in _facade()}
        lines += [f"* :obj:`{facade.get(id(getattr(pkg, n)), f'{stage}.{n}')}`" for n in shown]
        lines.append("")
    del mod
    return "\n".join(lines)


def _write_module_pages() -> None:
    """modules/*.rst and modules/index.rst (build products, git-ignored)."""
    out = DOCS / "modules"
    by_stage = _stage_modules()
    wanted = {f"{m}.rst" for mods in by_stage.values() for m in mods} | {"index.rst"}
    if out.is_dir():
        for old in out.glob("*.rst"):
            if old.name not in wanted:
                old.unlink()
    index = ["Modules", "=======", "",
             "Every public module of every stage, with the names it defines that its stage",
             "does not export (those are on the stage's page). Import the stage's names from",
             "the stage: a module's other names are the stage's implementation, shown here for",
             "readers of the code, and may change.", ""]
    for stage, mods in by_stage.items():
        if not mods:
            continue
        title = f"chebnorm.{stage}"
        index += [title, "-" * len(title), "", ".. toctree::", "   :maxdepth: 1", ""]
        index += [f"   {m}" for m in mods]
        index.append("")
        for m in mods:
            _write_if_changed(out / f"{m}.rst", _module_page(m))
    _write_if_changed(out / "index.rst", "\n".join(index))


def _write_layer_rule() -> None:
    """_layer_rule.rst: the layer rule section of the package docstring (the one place
    it is written), for the contributor page (a build product, git-ignored)."""
    doc = inspect.cleandoc(chebnorm.__doc__)
    start = doc.index("Architecture: the layer rule")
    end = doc.index("The everyday names, one import away")
    body = doc[start:end].split("\n", 2)[2]  # without the title and its underline
    body = body.replace(":data:`LAYERS`", ":data:`~chebnorm.LAYERS`")
    _write_if_changed(DOCS / "_layer_rule.rst", body.strip() + "\n")


# -- The facade: documented under the names users type ------------------------------

#: the callable stages of the facade: module -> (the object whose docstring the call
#: shows, the call's summary on the API page)
FACADE_CALLS = {
    "chebnorm.export": ("chebnorm.export.__call__",
                        "The text of a table in a format (:func:`chebnorm.export.export_text`)."),
    "chebnorm.hw.report": ("chebnorm.hw.analyze",
                           "The bit-accurate hardware report of a table (:func:`chebnorm.hw.analyze`)."),
}


def _facade() -> list[tuple[str, object, str]]:
    """``(name, object, stage path)`` of each facade name, in ``chebnorm.__all__``'s
    order (``("target", get_target, "chebnorm.approx.get_target")``)."""
    return [(name, getattr(chebnorm, name), ".".join(chebnorm._LAZY[name]))
            for name in chebnorm.__all__ if name in chebnorm._LAZY]


def _kind(obj) -> str:
    """The Python domain's directive for ``obj``: function, exception or class."""
    if inspect.isclass(obj):
        return "exception" if issubclass(obj, BaseException) else "class"
    return "function"


def _summary(obj) -> str:
    """The first sentence of ``obj``'s docstring, on one line."""
    first = (inspect.getdoc(obj) or "").split("\n\n")[0]
    text = " ".join(first.split())
    end = re.search(r"\.(\s|$)", text)
    return text[:end.start() + 1] if end else text


def _facade_stubs() -> dict[str, list[dict]]:
    """For each module whose ``__all__`` exports a facade object: the entries its page
    shows in place of the object's documentation (a signature and a link to the
    facade's entry), passed to the autosummary module template."""
    stubs: dict[str, list[dict]] = {}
    facade = _facade()
    for modname in sorted(m for m in sys.modules if m == "chebnorm" or m.startswith("chebnorm.")):
        mod = sys.modules[modname]
        if modname == "chebnorm" or not isinstance(getattr(mod, "__all__", None), (list, tuple)):
            continue
        for name in mod.__all__:
            value = getattr(mod, name, None)
            for facade_name, obj, _path in facade:
                if value is obj:
                    kind = _kind(obj)
                    sig = ""
                    if kind == "function":
                        try:   # without annotations, as autodoc shows signatures here
                            plain = inspect.signature(obj)
                            sig = str(plain.replace(
                                parameters=[p.replace(annotation=p.empty) for p in plain.parameters.values()],
                                return_annotation=plain.empty))
                        except (TypeError, ValueError):
                            sig = "(...)"
                    role = {"function": "func", "class": "class", "exception": "exc"}[kind]
                    stubs.setdefault(modname, []).append(
                        {"name": name, "kind": kind, "sig": sig, "role": role,
                         "facade": f"chebnorm.{facade_name}", "short": facade_name})
    return stubs


def _write_facade_pages() -> None:
    """facade/*.rst: a page per facade name (``chebnorm.fit``, ``chebnorm.export``,
    ``chebnorm.hw.report``) and facade/_table.rst, the table of the API page (build
    products, git-ignored)."""
    out = DOCS / "facade"
    pages = {}
    rows = []
    for name, obj, path in _facade():
        full = f"chebnorm.{name}"
        kind = _kind(obj)
        pages[full] = "\n".join([full, "=" * len(full), "", ".. currentmodule:: chebnorm", "",
                                 f".. auto{kind}:: {name}", ""])
        role = {"function": "func", "class": "class", "exception": "exc"}[kind]
        rows.append((f":{role}:`{name} <{full}>`", f"{_summary(obj)} (``{path}``)"))
    for modname, (_doc, summary) in FACADE_CALLS.items():
        label = "facade-" + modname.removeprefix("chebnorm.").replace(".", "-")
        short = modname.removeprefix("chebnorm.")
        pages[modname] = "\n".join([
            f".. _{label}:", "", modname, "=" * len(modname), "", ".. currentmodule:: chebnorm", "",
            f"The module :mod:`{modname}` is callable, ``cn.{short}(...)``: {summary[0].lower()}{summary[1:]}", "",
            f".. facade-call:: {modname}", ""])
        rows.append((f":ref:`{short}(...) <{label}>`", f"{summary} (calling :mod:`{modname}`)"))
    wanted = {f"{p}.rst" for p in pages} | {"_table.rst"}
    if out.is_dir():
        for old in out.glob("*.rst"):
            if old.name not in wanted:
                old.unlink()
    for full, text in pages.items():
        _write_if_changed(out / f"{full}.rst", text)
    table = [".. list-table::", "   :header-rows: 1", "   :widths: 25 75", "",
             "   * - ``cn.``", "     - what it is (the same object's name in its stage)"]
    for name_cell, summary in rows:
        table += [f"   * - {name_cell}", f"     - {summary}"]
    table += ["", ".. toctree::", "   :hidden:", ""] + [f"   facade/{full}" for full in pages]
    _write_if_changed(out / "_table.rst", "\n".join(table) + "\n")


def _write_bench_tables() -> None:
    """_bench/NAME.md: the tables of the benchmarks page, printed from the committed
    result files of ``benchmarks/`` by ``_benchtables.py`` (build products, git-ignored)."""
    sys.path.insert(0, str(DOCS))
    try:
        import _benchtables
    finally:
        sys.path.remove(str(DOCS))
    for name, printer in _benchtables.TABLES.items():
        _write_if_changed(DOCS / "_bench" / f"{name}.md", printer())


_copy_notebooks()
_write_figure_gallery()
_write_bench_tables()
_write_cli_help()
_write_layer_rule()
_write_facade_pages()
# autosummary's pages are a build product: a module that moved or was removed must not
# leave its page behind (a stale page imports a name that no longer exists)
shutil.rmtree(DOCS / "generated", ignore_errors=True)
_write_module_pages()
# the stage pages list a facade object with a link to its entry (docs/_templates/autosummary)
autosummary_context = {
    "facade_stubs": _facade_stubs(),
    # a module a stage exports without an __all__ of its own (chebnorm.core.files): its page
    # documents the names it defines (autosummary would list its imports too)
    "plain_modules": sorted(m for mods in _stage_api_modules().values() for m in mods),
    "facade_calls": {m: "facade-" + m.removeprefix("chebnorm.").replace(".", "-") for m in FACADE_CALLS},
}


# -- cross-references resolved where the docstring's module would resolve them ------

_DOC_SOURCE = re.compile(r"docstring of ([\w.]+)")


def _documented_names(env) -> dict[int, tuple[str, str]]:
    """id(object) -> (objtype, documented full name), for every documented Python object."""
    cache = getattr(env, "_chebnorm_documented", None)
    if cache is not None:
        return cache
    cache = {}
    py = env.get_domain("py")
    for name, _dispname, objtype, _doc, _anchor, _prio in py.get_objects():
        obj = sys.modules.get(name) if objtype == "module" else _lookup(name)
        if obj is None:
            continue
        if isinstance(obj, (int, float, str, bytes, bool, tuple, frozenset)):
            # values that may be shared by identity: keyed by (last name, id)
            cache.setdefault((name.rsplit(".", 1)[-1], id(obj)), (objtype, name))
        elif objtype != "module" and name.count(".") == 1:
            cache[id(obj)] = (objtype, name)   # the facade's entry (chebnorm.fit) before its stage's
        else:
            cache.setdefault(id(obj), (objtype, name))
    env._chebnorm_documented = cache
    return cache


def _lookup(dotted: str):
    """The object a dotted name denotes, as Python resolves it: attributes from the
    top-level module down (``chebnorm.approx.piecewise_fit`` is the function the
    stage exports, not the module of that name), else an imported module and
    attributes below it; None when neither. A method is its function."""
    obj = _walk(dotted)
    if obj is None:
        obj = _import_walk(dotted)
    return getattr(obj, "__func__", obj)


def _walk(dotted: str):
    parts = dotted.split(".")
    try:
        obj = importlib.import_module(parts[0])
        for part in parts[1:]:
            obj = getattr(obj, part)
    except (ImportError, AttributeError):
        return None
    return obj


def _import_walk(dotted: str):
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except Exception:  # noqa: BLE001 - any import failure: not a module name
            continue
        try:
            for attr in parts[i:]:
                obj = getattr(obj, attr)
        except AttributeError:
            return None
        return obj
    return None


#: the role that finds a documented object of each type (one name may be a module and a function)
_ROLE = {"function": "func", "class": "class", "exception": "exc", "data": "data", "attribute": "attr",
         "method": "meth", "property": "attr", "module": "mod"}

_CODE_OR_ROLE = re.compile(r"(``.*?``|:[\w:]+:`[^`]*`|`[^`]*`_?)")
_BARS = re.compile(r"(?<![\\\w])\|([^|\n]*?[^|\s\\])\|(?!\w)")


def _escape_bars(app, what, name, obj, options, lines):
    """Docstrings write ``|p - f|`` for an absolute value: in reStructuredText that
    is a substitution reference. Escape such bars outside code, roles and tables."""
    math_indent = None   # inside a ``.. math::`` block: LaTeX, where \| is a norm bar
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if math_indent is not None:
            if not stripped or indent > math_indent:
                continue
            math_indent = None
        if stripped.startswith(".. math::"):
            math_indent = indent
            continue
        if "|" not in line or stripped.startswith(("|", "+")):
            continue
        parts = _CODE_OR_ROLE.split(line)
        lines[i] = "".join(p if k % 2 else _BARS.sub(r"\\|\1\\|", p) for k, p in enumerate(parts))


_ATTR_DOCS: dict[str, dict] = {}


def _attr_docs(modname: str) -> dict:
    """The ``#:`` descriptions of a module's assignments, by name (cached)."""
    if modname not in _ATTR_DOCS:
        from sphinx.pycode import ModuleAnalyzer
        try:
            found = ModuleAnalyzer.for_module(modname).find_attr_docs()
        except Exception:  # noqa: BLE001 - no source
            found = {}
        _ATTR_DOCS[modname] = {n: list(v) for (cls, n), v in found.items() if cls == ""}
    return _ATTR_DOCS[modname]


def _constant_doc(app, what, name, obj, options, lines):
    """A constant a stage re-exports (``chebnorm.approx.COEF_FORMATS``) has its ``#:``
    description where it is assigned, not in the stage: autodoc then falls back to the
    docstring of the value's type (tuple's, int's), or to nothing. Use the description
    of the module that assigns it (under any name: ``COEF_FORMATS`` is ``FORMATS`` of
    ``chebnorm.approx.rounding``), or nothing."""
    if what not in ("data", "attribute") or "." not in name:
        return
    typedoc = inspect.getdoc(type(obj)) or ""
    # numpydoc has already reshaped the lines: look for the type's first line near the top
    head = " ".join(line.strip() for line in lines[:6])
    builtin_value = type(obj).__module__ == "builtins"   # its docstring is never the constant's
    if lines and not builtin_value and not (typedoc and typedoc.splitlines()[0].strip() in head):
        return
    modname, short = name.rsplit(".", 1)
    cands = sorted(m for m in sys.modules if m == modname or m.startswith(modname + "."))
    for cand in cands:
        docs = _attr_docs(cand)
        mod = sys.modules[cand]
        names = [short] + sorted(n for n in docs if n != short)
        for attr in names:
            if attr in docs and getattr(mod, attr, None) is obj and \
                    (attr == short or not isinstance(obj, (int, float, bool))):
                lines[:] = [line for line in docs[attr] if line.strip()]
                _escape_bars(app, what, name, obj, options, lines)
                return
    lines[:] = []


def _resolve_in_defining_module(app, env, node, contnode):
    """A reference in a docstring means the name in the module that defines the
    docstring (``dot_to_code`` in ``chebnorm.hw.datapaths``), wherever the
    docstring is shown; link it to the page where that object is documented."""
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip("~.")
    contexts = [""]
    source = _DOC_SOURCE.search(str(node.source or ""))
    if source:
        parts = source.group(1).split(".")
        contexts += [".".join(parts[:i]) for i in range(len(parts), 0, -1)]
    for key in ("py:class", "py:module"):
        if node.get(key):
            contexts.append(node[key])
    documented = _documented_names(env)
    py = env.get_domain("py")
    for ctx in contexts:
        obj = _lookup(f"{ctx}.{target}" if ctx else target)
        if obj is None and "." in target:
            # a dataclass field without a default is no class attribute: link the
            # field's entry under the documented name of its class
            owner, attr = target.rsplit(".", 1)
            cls = _lookup(f"{ctx}.{owner}" if ctx else owner)
            hit = documented.get(id(cls)) if inspect.isclass(cls) else None
            if hit is not None and f"{hit[1]}.{attr}" in py.objects:
                return py.resolve_xref(env, node["refdoc"], app.builder, "attr", f"{hit[1]}.{attr}",
                                       node, contnode)
        if obj is None:
            continue
        if inspect.ismodule(obj):
            if obj.__name__ in env.get_domain("py").modules:
                return env.get_domain("py").resolve_xref(env, node["refdoc"], app.builder, "mod",
                                                         obj.__name__, node, contnode)
            continue
        hit = documented.get(id(obj)) or documented.get((target.rsplit(".", 1)[-1], id(obj)))
        if hit is not None:
            return py.resolve_xref(env, node["refdoc"], app.builder, _ROLE.get(hit[0], "obj"), hit[1],
                                   node, contnode)
        if target.rsplit(".", 1)[-1].startswith("_"):
            # a private helper of the defining module: never documented by design, so
            # the name is shown as code (it exists: _lookup found it)
            return contnode
    # a bare name documented exactly once in the site (an autosummary line of the facade)
    if "." not in target:
        names = {name for _t, name in documented.values() if name.rsplit(".", 1)[-1] == target}
        if len(names) == 1:
            name = names.pop()
            objtype = next(t for t, n in documented.values() if n == name)
            return py.resolve_xref(env, node["refdoc"], app.builder, _ROLE.get(objtype, "obj"), name,
                                   node, contnode)
    return None


def _forget_documented(app, env):
    """The map of documented objects is rebuilt for each build (the environment is
    pickled between builds)."""
    if hasattr(env, "_chebnorm_documented"):
        del env._chebnorm_documented


def _widget_fallback(app, doctree):
    """An executed notebook's slider cell shows ipywidgets' text form,
    ``interactive(children=(IntSlider(...` (the live widget needs a kernel): say so
    instead (the static figure drawn before it stays)."""
    from docutils import nodes

    for block in list(doctree.findall(nodes.literal_block)):
        if block.astext().startswith("interactive(children="):
            note = nodes.paragraph(text="Sliders here in Jupyter (with ipywidgets installed); "
                                        "the static figure above shows the same.")
            note["classes"].append("widget-fallback")
            block.replace_self(note)


def _facade_call_directive():
    """The ``facade-call`` directive: ``.. facade-call:: chebnorm.export`` shows the call of
    a callable module under the name users type (``export(table, fmt=None, ...)``), with
    the docstring of :data:`FACADE_CALLS`' object, processed as autodoc would (numpydoc).
    Not indexed: the module keeps its name in the Python domain."""
    from docutils.statemachine import StringList
    from sphinx.util.docutils import SphinxDirective
    from sphinx.util.parsing import nested_parse_to_nodes

    class FacadeCall(SphinxDirective):
        required_arguments = 1

        def run(self):
            modname = self.arguments[0]
            call = type(importlib.import_module(modname)).__call__
            documented = _lookup(FACADE_CALLS[modname][0])
            documented = getattr(documented, "__func__", documented)
            lines = (inspect.getdoc(documented) or "").splitlines()
            self.env.app.emit("autodoc-process-docstring", "function", modname, documented, {}, lines)
            sig = inspect.signature(call)
            sig = sig.replace(parameters=[p.replace(annotation=p.empty) for p in list(sig.parameters.values())[1:]],
                              return_annotation=sig.empty)
            params = str(sig).replace("'", '"')
            text = [f".. py:function:: {modname.removeprefix('chebnorm.')}{params}", "   :no-index:", ""]
            text += [f"   {line}" if line.strip() else "" for line in lines]
            source = f"docstring of {documented.__module__}.{documented.__qualname__}"
            return nested_parse_to_nodes(self.state, StringList(text, source=source))

    return FacadeCall


def _facade_context(app, doctree):
    """A facade page (``facade/chebnorm.fit``) shows a docstring written in its stage
    (``:mod:`.kernels``` in ``chebnorm.methods``): its references are resolved in the
    stage, as on the stage's page, not in ``chebnorm``."""
    from sphinx import addnodes

    docname = app.env.docname
    if not docname.startswith("facade/"):
        return
    full = docname.split("/", 1)[1]
    name = full.removeprefix("chebnorm.")
    context = chebnorm._LAZY[name][0] if name in chebnorm._LAZY else FACADE_CALLS[full][0].rsplit(".", 1)[0]
    for node in doctree.findall(addnodes.pending_xref):
        if node.get("refdomain") == "py" and node.get("py:module") in (None, "chebnorm"):
            node["py:module"] = context


def _facade_links(app, doctree, docname):
    """A link to a stage's entry of a facade object (``chebnorm.approx.fit``, a signature
    and a link) goes to the facade's entry (``chebnorm.fit``), where it is documented."""
    from docutils import nodes

    targets = {f"{mod}.{stub['name']}": stub["facade"]
               for mod, stubs in autosummary_context["facade_stubs"].items() for stub in stubs}
    for ref in doctree.findall(nodes.reference):
        uri = ref.get("refuri") or ""
        anchor = uri.rsplit("#", 1)[-1] if "#" in uri else ref.get("refid")   # refid: on the same page
        if anchor in targets:
            ref.attributes.pop("refid", None)
            full = targets[anchor]
            ref["refuri"] = app.builder.get_relative_uri(docname, f"facade/{full}") + f"#{full}"


def setup(app):
    """Register the reference resolver and the ``facade-call`` directive."""
    app.add_directive("facade-call", _facade_call_directive())
    app.connect("doctree-read", _facade_context)
    app.connect("doctree-resolved", _facade_links)
    app.connect("doctree-read", _widget_fallback)
    app.connect("env-updated", _forget_documented)
    app.connect("missing-reference", _resolve_in_defining_module, priority=900)
    app.connect("autodoc-process-docstring", _escape_bars)
    app.connect("autodoc-process-docstring", _constant_doc)
