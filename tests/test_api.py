"""The top-level facade (``import chebnorm as cn``), rich display of tables
and renders, and the repository-wide checks of the public API: every public
callable has a docstring, no file refers to the engineers' shared folder."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import chebnorm as cn

REPO = Path(__file__).resolve().parent.parent


# -------------------------------------------------------------- facade
def test_acceptance_command_runs():
    code = ("import chebnorm as cn; t = cn.fit('1/sqrt(2+z)', ('sqrt(2)', '2'), 2, var='z'); "
            "print(t.abs_error_bound)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    bound = float(out.stdout)
    # claim C5: the degree-2 Chebyshev fit's error is 2.158e-5 (located), bound within 1 %
    assert 2.158e-5 <= bound <= 1.01 * 2.1582e-5


def test_import_is_lazy():
    """``import chebnorm`` must not import a stage (that is what keeps it fast)."""
    code = ("import sys, chebnorm; print(sorted(m for m in sys.modules if m.startswith('chebnorm.')"
            " or m in ('sympy', 'mpmath', 'flint', 'matplotlib', 'scipy')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_facade_names_are_the_stage_objects():
    from chebnorm import approx, export, hw, methods, raster
    assert cn.fit is approx.fit and cn.quantize is approx.quantize and cn.certify is approx.certify
    assert cn.CoefficientTable is approx.CoefficientTable and cn.target is approx.get_target
    assert cn.span_normals is methods.span_normals and cn.render is raster.render
    assert cn.export is export and cn.hw is hw and cn.methods is methods
    assert set(cn.__all__) <= set(dir(cn))
    for name in cn.__all__:
        getattr(cn, name)
    with pytest.raises(AttributeError, match="no attribute 'nonexistent'"):
        cn.nonexistent  # noqa: B018


def test_export_dispatches_over_every_format():
    t = cn.fit_target("dichotomy", 1)
    for fmt, (printer, _) in cn.export.TABLE_FORMATS.items():
        assert cn.export(t, fmt) == printer(t, "")
    # FORMATS lists every format the command line exports (issue 31: it listed five)
    assert list(cn.export.FORMATS) == ["c", "glsl", "hlsl", "json", "verilog", "vhdl", "wgsl"]
    assert cn.export.FORMATS["verilog"] == ".v" and cn.export.FORMATS["c"] == ".h"
    with pytest.raises(ValueError, match="accepted: .*c.*json"):
        cn.export(t, "nope")


def test_hw_report_is_callable():
    t = cn.fit_target("dichotomy", 1)
    r = cn.hw.report(t, 10, 10, coef_frac_bits=12, synth=False, gappa=False)
    assert isinstance(r, cn.hw.HardwareReport)
    assert r.checks["within_budget"]


# -------------------------------------------------------------- display
@pytest.fixture(scope="module")
def tables():
    plain = cn.fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 2, var="z")
    return plain, cn.quantize(plain, 14)


def test_repr_html_shows_the_bounds(tables):
    from chebnorm.core.numeric import format_up

    plain, quant = tables
    for t in (plain, quant):
        html_text = t._repr_html_()
        assert format_up(t.abs_error_bound, ".6e") in html_text
        assert format_up(t.rel_error_bound, ".6e") in html_text
        assert repr(t.coefficients[0]) in html_text and f"{t.max_abs_at!r}" in html_text
        assert format_up(t.abs_error_bound, ".6e") in t._repr_markdown_()
    q = quant._repr_html_()
    assert format_up(quant.fixed_point.abs_error_bound, ".6e") in q
    assert str(quant.fixed_point.integers[0]) in q
    assert "fixed point" not in plain._repr_html_()


def test_repr_escapes_untrusted_fields(tables):
    import json
    from dataclasses import replace

    # a file's free text (provenance) reaches the display through the reader
    d = tables[0].to_dict()
    d["provenance"] = {"command": "</table><script>alert(1)</script> | *x*"}
    t = cn.CoefficientTable.from_json(json.dumps(d))
    assert "<script" not in t._repr_html_() and "&lt;script&gt;" in t._repr_html_()
    # a table built in Python is validated as a file is: the name is refused there
    with pytest.raises(ValueError, match=r"^name: '<img src=x onerror=alert\(1\)>' is not an "
                                         r"identifier"):
        replace(tables[0], name="<img src=x onerror=alert(1)>")
    # and a table built past the checks (tests only) has every field escaped anyway
    from chebnorm.approx.contract import construction

    with construction("unchecked"):
        t = replace(tables[0], name="<img src=x onerror=alert(1)>", expression="a | b",
                    variable="<z>")
    html_text, md = t._repr_html_(), t._repr_markdown_()
    assert "<img" not in html_text and "&lt;img" in html_text and "<z>" not in html_text
    assert "<img" not in md and "&lt;img" in md and "a \\| b" in md


def test_error_curve_matches_float64_and_stays_under_the_bound(tables):
    plain, quant = tables
    x, g = plain.error_curve(401)
    f = 1.0 / np.sqrt(2.0 + x)
    p = np.polynomial.polynomial.polyval(x, plain.coefficients)
    # float64: each of p, f carries a few ulps of |f| <= 1/sqrt(2 + sqrt 2)
    assert np.max(np.abs(g - (p - f))) <= 8 * np.finfo(float).eps
    assert np.max(np.abs(g)) <= plain.abs_error_bound
    assert np.max(np.abs(g)) >= plain.max_abs_error * (1 - 1e-3)
    _, gr = plain.error_curve(401, "rel")
    assert np.max(np.abs(gr)) <= plain.rel_error_bound
    _, gq = quant.error_curve(401, fixed=True)
    assert np.max(np.abs(gq)) <= quant.fixed_point.abs_error_bound
    with pytest.raises(ValueError, match="no fixed-point part"):
        plain.error_curve(fixed=True)


def test_plot_returns_axes_with_the_bound(tables):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.axes import Axes

    plain, quant = tables
    ax = plain.plot()
    assert isinstance(ax, Axes)
    levels = {round(line.get_ydata()[0], 15) for line in ax.get_lines() if len(line.get_ydata()) == 2}
    assert round(plain.abs_error_bound, 15) in levels and round(-plain.abs_error_bound, 15) in levels
    _, ax2 = plt.subplots()
    assert quant.plot(ax=ax2, error="rel") is ax2
    plt.close("all")


def test_render_results_show_image_error_map_and_metrics():
    ref = cn.render("sphere", "phong", "exact", size=(20, 20), tess=6)
    test = cn.render("sphere", "phong", "none", size=(20, 20), tess=6)
    html_text = test._repr_html_()
    assert html_text.count("data:image/png;base64,") == 2 and "length error" in html_text
    view = cn.RenderComparison(test, ref, flip=False)
    v = view._repr_html_()
    assert v.count("data:image/png;base64,") == 3
    assert f"<td style='text-align:left'>{view.metrics.max_abs_8bit}</td>" in v
    m, _ = cn.compare(test, ref, flip=False)
    assert view.metrics == m


# ------------------------------------------------- repository-wide checks
def public_modules():
    names = ["chebnorm"] + sorted(m.name for m in pkgutil.walk_packages(cn.__path__, "chebnorm.")
                                  if not any(p.startswith("_") for p in m.name.split(".")))
    return names


def _exports(module) -> list[str]:
    """The module's ``__all__``, or without one the functions and classes it defines
    whose names do not start with ``_`` (a module without ``__all__`` exports them)."""
    if hasattr(module, "__all__"):
        return list(module.__all__)
    return [n for n, v in vars(module).items() if not n.startswith("_")
            and (inspect.isfunction(v) or inspect.isclass(v)) and v.__module__ == module.__name__]


def _has_docstring(obj) -> bool:
    doc = (inspect.getdoc(obj) or "").strip()
    if inspect.isclass(obj) and doc.startswith(f"{obj.__name__}("):
        return False  # the signature dataclasses write when the class has no docstring
    return bool(doc)


@pytest.mark.parametrize("module_name", public_modules())
def test_every_public_callable_has_a_docstring(module_name):
    """Every callable a public module exports (classes included) has a docstring."""
    module = importlib.import_module(module_name)
    missing = [name for name in _exports(module)
               if callable(getattr(module, name)) and not inspect.ismodule(getattr(module, name))
               and not _has_docstring(getattr(module, name))]
    assert missing == [], f"{module_name}: public callables without a docstring: {missing}"


#: spelled in two parts so that this file does not match itself
NEEDLES = (b"../" + b"shared", b"/work/" + b"shared")


def test_no_file_refers_to_the_shared_folder():
    files = subprocess.run(["git", "ls-files", "-z"], cwd=REPO, capture_output=True, check=True).stdout
    bad = []
    for rel in files.decode().split("\0"):
        path = REPO / rel
        if not rel or not path.is_file():
            continue
        data = path.read_bytes()
        if any(needle in data for needle in NEEDLES):
            bad.append(rel)
    assert bad == [], f"files that point at a folder users do not have: {bad}"
