"""The documentation site builds offline with warnings as errors and every
cross-reference resolved (nitpicky), its API reference lists every public name
of the facade and of every stage, math and notebooks render without a network,
and the notebook pages show their figures.

Skipped, with the reason, when the docs extra is not installed
(``pip install -e ".[docs]"``)."""

from __future__ import annotations

import importlib
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import one_at_a_time

# found, not imported: importing myst-nb and Sphinx costs the whole suite's collection 0.4 s
_DOCS_PACKAGES = {"sphinx": "sphinx", "numpydoc": "numpydoc", "myst_nb": "myst-nb", "furo": "furo",
                  "sphinx-mathjax-offline": "sphinx-mathjax-offline"}
_MISSING = [dist for mod, dist in _DOCS_PACKAGES.items() if importlib.util.find_spec(mod) is None]
if _MISSING:
    pytest.skip(f"{', '.join(_MISSING)} not installed (pip install -e '.[docs]')",
                allow_module_level=True)

REPO = Path(__file__).resolve().parent.parent
#: seconds a site build may take before it is taken for hung (it takes 100-120 s loaded)
BUILD_SECONDS = 300
#: builds tried before a hang fails the tests (see ``built``)
ATTEMPTS = 4
#: the module's tests get room for every attempt
pytestmark = pytest.mark.timeout(ATTEMPTS * BUILD_SECONDS + 300)
STAGES = ["chebnorm.exceptions", "chebnorm.core", "chebnorm.symbolic", "chebnorm.approx",
          "chebnorm.export", "chebnorm.methods", "chebnorm.hw", "chebnorm.raster"]


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    out = tmp_path_factory.mktemp("docs")
    # offline: no intersphinx fetch (CHEBNORM_DOCS_OFFLINE), as on a machine without network
    env = {**os.environ, "CHEBNORM_DOCS_OFFLINE": "1"}
    command = [sys.executable, "-m", "sphinx", "-W", "-n", "--keep-going", "-q", "-b", "html",
               "-d", str(out / "doctrees"), str(REPO / "docs"), str(out / "html")]
    # The build runs the notebooks in a Jupyter kernel, one kernel on the machine at a time.
    # A client has been seen waiting forever on an idle kernel (both connected, no message
    # pending; ipykernel 6.31 and 7.4 alike): a build that outlives BUILD_SECONDS (about 2x
    # its time on a loaded 2-core machine) is stopped and run again, up to ATTEMPTS times.
    # Notebooks already executed stay in the build's jupyter cache, so a rerun resumes.
    for attempt in range(1, ATTEMPTS + 1):
        with one_at_a_time("jupyter-kernel"):
            try:
                proc = subprocess.run(command, capture_output=True, text=True, cwd=REPO, env=env,
                                      timeout=BUILD_SECONDS)
                break
            except subprocess.TimeoutExpired:
                if attempt == ATTEMPTS:
                    pytest.fail(f"sphinx hung {ATTEMPTS} times for {BUILD_SECONDS} s "
                                f"(notebook execution)")
    assert proc.returncode == 0, f"sphinx -W failed:\n{proc.stderr[-4000:]}"
    return out / "html"


@pytest.mark.slow
def test_api_reference_lists_every_public_name(built):
    ids = set()
    for page in (built / "generated").glob("*.html"):
        ids |= set(re.findall(r'id="([^"]+)"', page.read_text(encoding="utf-8")))
    missing = []
    for mod in STAGES:
        for name in importlib.import_module(mod).__all__:
            if f"{mod}.{name}" not in ids and f"module-{mod}.{name}" not in ids:
                missing.append(f"{mod}.{name}")
    assert missing == []
    api = (built / "api.html").read_text(encoding="utf-8")
    import chebnorm
    for name in chebnorm._LAZY.values():  # the facade's table links to each re-exported object
        assert f"{name[0]}.{name[1]}" in api


@pytest.mark.slow
def test_site_has_the_papers_the_cli_and_the_gallery(built):
    papers = (built / "papers.html").read_text(encoding="utf-8")
    for claim in (f"C{i}" for i in range(1, 14)):
        assert f">{claim}<" in papers
    cli = re.sub(r"<[^>]+>", "", (built / "cli.html").read_text(encoding="utf-8"))
    assert "chebnorm fit EXPR" in cli and "chebnorm hw report" in cli
    figures = sorted(p.name for p in (REPO / "figures").glob("*/*.png"))
    assert figures and all((built / "_images" / name).exists() for name in figures)
    for nb in (REPO / "notebooks").glob("*.ipynb"):
        assert (built / "gallery" / "notebooks" / f"{nb.stem}.html").exists()


@pytest.mark.slow
def test_math_renders_from_the_site_itself(built):
    """MathJax is a file of the site, referenced by the pages that have math; no page
    loads a script from another host."""
    papers = (built / "papers.html").read_text(encoding="utf-8")
    assert re.search(r'<script[^>]+src="_static/mathjax/tex-chtml\.js', papers)
    assert (built / "_static" / "mathjax" / "tex-chtml.js").stat().st_size > 100_000
    assert 'class="math' in papers and r"\delta_d(\varphi)" in papers   # typeset in the browser
    for page in built.rglob("*.html"):
        scripts = re.findall(r'<script[^>]+src="([^"]+)"', page.read_text(encoding="utf-8"))
        assert [s for s in scripts if re.match(r"(https?:)?//", s)] == [], page


@pytest.mark.slow
def test_notebook_pages_show_their_figures(built):
    """Executed at build time: each notebook page holds its outputs, figures included."""
    for nb in (REPO / "notebooks").glob("*.ipynb"):
        page = (built / "gallery" / "notebooks" / f"{nb.stem}.html").read_text(encoding="utf-8")
        images = re.findall(r'<img[^>]+src="([^"]+\.png)"', page)
        assert images, f"{nb.name}: no figure on its page"
        for src in images:
            assert (built / "gallery" / "notebooks" / src).resolve().is_file(), src
        assert "cell_output" in page
        assert "interactive(children=" not in page   # a slider's text form is replaced by a note


@pytest.mark.slow
def test_site_pages(built):
    """Installation, contributor and changelog pages; the layer rule on the contributor
    page, not on the API page; the guide shows committed figures."""
    for name in ("installation", "contributing", "changelog"):
        assert (built / f"{name}.html").exists()
    text = lambda name: re.sub(r"<[^>]+>", "", (built / f"{name}.html").read_text(encoding="utf-8"))  # noqa: E731
    assert "layer rule" in text("contributing") and "tests/test_architecture.py" in text("contributing")
    assert "Where a change goes" in text("contributing")
    assert "Architecture: the layer rule" not in text("api") and "0. chebnorm.core" not in text("api")
    guide = (built / "guide.html").read_text(encoding="utf-8")
    assert re.findall(r'<img[^>]+src="_images/[^"]+\.png"', guide)


@pytest.mark.slow
def test_constants_show_their_own_description(built):
    """A constant re-exported by a stage shows the ``#:`` description where it is
    assigned, never the docstring of its value's type."""
    builtin = ("Built-in immutable sequence", "int([x]) -&gt; integer", "str(object=",
               "dict() -&gt; new empty dictionary", "float(x=0, /)")
    for page in built.rglob("*.html"):
        text = page.read_text(encoding="utf-8")
        assert not [b for b in builtin if b in text], page
    approx = re.sub(r"<[^>]+>", "", (built / "generated" / "chebnorm.approx.html").read_text(
        encoding="utf-8"))
    assert "the highest polynomial degree" in approx and "the registered approximation" in approx


@pytest.mark.slow
def test_absolute_values_in_displayed_math_stay_bars(built):
    """Docstrings' ``|x|`` is escaped for reStructuredText outside math only: inside a
    ``.. math::`` block an escaped bar would render as a norm."""
    pages = list((built / "generated").glob("*.html")) + list((built / "modules").glob("*.html"))
    blocks = [m for p in pages for m in re.findall(r'<div class="math[^"]*">(.*?)</div>',
                                                  p.read_text(encoding="utf-8"), re.S)]
    assert blocks and not [b for b in blocks if "\\|" in b]
    assert any("|\\mathrm{fl}(p(x)) - p(x)|" in b for b in blocks)


def _draws(source: str, drawers: set[str]) -> bool:
    """Whether a code cell draws a matplotlib figure when it runs: a call, outside a
    function body, of ``plt.show``, of a ``.plot`` method or of a function of the
    notebook that draws (``drawers``, updated with the functions this cell defines)."""
    import ast

    tree = ast.parse("\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!"))))

    def calls(nodes):
        for node in nodes:
            for sub in ast.walk(node):
                if isinstance(sub, ast.Call):
                    f = sub.func
                    if isinstance(f, ast.Attribute) and (f.attr == "plot" or (
                            f.attr == "show" and isinstance(f.value, ast.Name) and f.value.id == "plt")):
                        yield True
                    elif isinstance(f, ast.Name) and f.id in drawers:
                        yield True

    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and any(calls(node.body)):
            drawers.add(node.name)
    top = [n for n in tree.body if not isinstance(n, (ast.FunctionDef, ast.ClassDef))]
    return any(calls(top))


def _page_cells(page: str) -> list[dict]:
    """The code cells of a notebook's page in order: the section (heading) each is in,
    the images its output shows and whether it holds the widget note."""
    from html.parser import HTMLParser

    class Cells(HTMLParser):
        def __init__(self):
            super().__init__()
            self.cells, self.depth, self.cell_depth, self.section = [], 0, None, 0

        def handle_starttag(self, tag, attrs):
            classes = (dict(attrs).get("class") or "").split()
            if tag == "section":
                self.section += 1
            if tag == "div":
                self.depth += 1
                if self.cell_depth is None and "cell" in classes and "docutils" in classes:
                    self.cell_depth = self.depth
                    self.cells.append({"section": self.section, "images": 0, "widget_note": False})
            if self.cell_depth is not None:
                if tag == "img":
                    self.cells[-1]["images"] += 1
                if "widget-fallback" in classes:
                    self.cells[-1]["widget_note"] = True

        def handle_endtag(self, tag):
            if tag == "div":
                if self.cell_depth == self.depth:
                    self.cell_depth = None
                self.depth -= 1

    parser = Cells()
    parser.feed(page)
    return parser.cells


@pytest.mark.slow
def test_every_notebook_figure_is_on_its_page(built):
    """Each code cell of a notebook that draws a figure shows an image on its page, and
    a slider cell's note ("the static figure above shows the same") follows the cell that
    draws that figure: the static figure is drawn whether ipywidgets is installed or not."""
    import json

    for nb in sorted((REPO / "notebooks").glob("*.ipynb")):
        code = ["".join(c["source"]) for c in json.loads(nb.read_text(encoding="utf-8"))["cells"]
                if c["cell_type"] == "code"]
        cells = _page_cells((built / "gallery" / "notebooks" / f"{nb.stem}.html").read_text(encoding="utf-8"))
        assert len(cells) == len(code), f"{nb.name}: {len(cells)} cells on the page, {len(code)} in the notebook"
        drawers: set[str] = set()
        for i, (source, cell) in enumerate(zip(code, cells)):
            if _draws(source, drawers):
                assert cell["images"], f"{nb.name}, code cell {i}: draws a figure, none on the page"
            if cell["widget_note"]:   # the static figure is the previous cell's, in the same section
                above = cells[i - 1] if i else None
                assert above and above["section"] == cell["section"] and above["images"], \
                    f"{nb.name}, code cell {i}: 'the static figure above' but no figure just above"


def test_draws_finds_the_figures_of_a_cell():
    drawers: set[str] = set()
    assert not _draws("def f(n=1):\n    plt.plot([n])\n    plt.show()\n", drawers) and drawers == {"f"}
    assert _draws("f()", drawers) and _draws("t.plot()\nplt.show()", drawers)
    assert not _draws("if widgets:\n    widgets.interact(f, n=3)", drawers)
    assert not _draws("%matplotlib inline\nprint(1)", drawers)


@pytest.mark.slow
def test_facade_is_documented_under_the_names_users_type(built):
    """``chebnorm.fit`` (not ``chebnorm.approx.fit``) carries the documentation; the stage
    page lists ``chebnorm.approx.fit`` with a link to it; ``cn.export(...)`` and
    ``cn.hw.report(...)`` are documented as calls, and their module pages link there."""
    import chebnorm

    api = (built / "api.html").read_text(encoding="utf-8")
    for name, (module, attr) in chebnorm._LAZY.items():
        page = (built / "facade" / f"chebnorm.{name}.html").read_text(encoding="utf-8")
        assert f'id="chebnorm.{name}"' in page, name
        assert f'href="facade/chebnorm.{name}.html#chebnorm.{name}"' in api, name
        stage = (built / "generated" / f"{module}.html").read_text(encoding="utf-8")
        entry = stage.split(f'id="{module}.{attr}"', 1)[1].split("</dd>", 1)[0]
        assert f"#chebnorm.{name}" in entry, f"{module}.{attr} does not link to chebnorm.{name}"
        assert "Parameters" not in entry, f"{module}.{attr} is documented twice"
    fit = (built / "facade" / "chebnorm.fit.html").read_text(encoding="utf-8")
    assert "Parameters" in fit
    for call, module_page in (("export", "generated/chebnorm.export.html"),
                              ("hw.report", "modules/chebnorm.hw.report.html")):
        page = re.sub(r"<[^>]+>", "", (built / "facade" / f"chebnorm.{call}.html").read_text(encoding="utf-8"))
        assert f"{call}(table" in page and "Parameters" in page, call
        assert f'facade/chebnorm.{call}.html#facade-' in (built / module_page).read_text(encoding="utf-8")
