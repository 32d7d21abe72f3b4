"""Sphinx configuration of the chebnorm documentation.

Build (offline, warnings are errors)::

    python -m sphinx -W -b html docs docs/_build/html

The API reference is generated from the code (autosummary + autodoc, numpy
docstrings); the notebooks are copied into the gallery at build time and
rendered as stored (never executed); the paper figures are the committed
files under ``figures/``.
"""

from __future__ import annotations

import shutil
import sys
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
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_nb",
]

source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints"]
templates_path = ["_templates"]

# -- API reference --------------------------------------------------------
autosummary_generate = True
autosummary_ignore_module_all = False     # list exactly what __all__ exports
autosummary_imported_members = True
autodoc_default_options = {"members": True, "undoc-members": True, "show-inheritance": False}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()
add_module_names = False

# -- Markdown / notebooks: render what is stored, never run, never fetch ----
nb_execution_mode = "off"
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
intersphinx_mapping: dict = {}
# the CLI page includes a part of README.md, whose in-page links (#targets, ...)
# point at README sections outside that part: they work on the README itself
suppress_warnings = ["myst.xref_missing"]

# -- HTML -------------------------------------------------------------------
html_theme = "alabaster"
html_title = f"chebnorm {release}"
html_static_path: list[str] = []


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
    text = "\n".join(lines)
    out = DOCS / "gallery" / "figures.md"
    if not out.exists() or out.read_text(encoding="utf-8") != text:
        out.write_text(text, encoding="utf-8")


_copy_notebooks()
_write_figure_gallery()
# autosummary's pages are a build product: a module that moved or was removed must not
# leave its page behind (a stale page imports a name that no longer exists)
shutil.rmtree(DOCS / "generated", ignore_errors=True)
