"""CoefficientTable.plot draws every evaluator the table has, with room for its labels."""

import struct

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import chebnorm as cn  # noqa: E402


def _f32(v: float) -> float:
    return struct.unpack("f", struct.pack("f", v))[0]


@pytest.fixture(scope="module")
def sin32():
    return cn.fit("sin(x)", ("-pi/4", "pi/4"), 7, kind="minimax", coef_format="binary32")


def test_quantized_float_part_and_binary32_are_drawn(sin32):
    ax = sin32.plot()
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "binary32 coefficients" in labels
    assert any(label.startswith("binary32 Horner, measured") for label in labels)
    bound = [label for label in labels if label.startswith("its bound ")][0]
    assert float(bound.split()[-1]) >= sin32.quantized.abs_error_bound   # printed rounded up


def test_labels_fit_in_the_figure(sin32):
    ax = sin32.plot()
    fig = ax.figure
    fig.canvas.draw()
    box = fig.bbox
    for text in (ax.xaxis.label, ax.yaxis.label, ax.title):
        e = text.get_window_extent()
        assert box.x0 <= e.x0 and e.x1 <= box.x1 and box.y0 <= e.y0 and e.y1 <= box.y1


def test_binary32_curve_is_a_binary32_horner(sin32):
    x, g = sin32.error_curve(41, binary32=True)
    c = [_f32(v) for v in sin32.quantized.coefficients]
    for xi, gi in zip(x[::10], g[::10]):
        xs, acc = _f32(xi), c[-1]
        for ck in c[-2::-1]:
            acc = _f32(_f32(acc * xs) + ck)
        assert gi == pytest.approx(acc - np.sin(xs), abs=1e-15)


def test_fixed_point_drawn_as_before():
    q = cn.quantize(cn.fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 2, var="z"), 14)
    labels = [t.get_text() for t in q.plot(binary32=False).get_legend().get_texts()]
    assert "fixed point, 14 fractional bits" in labels
    assert not any("binary32" in label for label in labels)


def test_length_error_map_keeps_rounding_noise_black():
    import re

    from chebnorm.raster import render
    from chebnorm.raster.display import LENGTH_SCALE_FLOOR, render_html

    exact = render_html(render("sphere", "phong", "exact", size=(16, 16), tess=6))
    scale, largest = map(float, re.search(r"black 0, white ([0-9.e+-]+); largest ([0-9.e+-]+)",
                                          exact).groups())
    assert largest < 1e-12 and scale == pytest.approx(LENGTH_SCALE_FLOOR, rel=1e-2)
    newton = render_html(render("sphere", "phong", "newton", size=(16, 16), tess=6))
    scale, largest = map(float, re.search(r"white ([0-9.e+-]+); largest ([0-9.e+-]+)",
                                          newton).groups())
    assert scale == largest > LENGTH_SCALE_FLOOR


@pytest.mark.slow
@pytest.mark.requires_tool("yosys")
def test_design_plot_names_the_architecture_that_won(tmp_path, monkeypatch):
    """When another architecture beats the one-width search, the search's plot says
    so and circles its own best point under another name; synthesized points are
    drawn at the cost yosys measured."""
    import chebnorm.hw.piecewise_search as ps
    from conftest import run_cli

    seen = {}
    real = ps.pareto_png

    def spy(points, x, y, **kw):
        seen.update(kw, points=points, x=x)
        return real(points, x, y, **kw)

    monkeypatch.setattr(ps, "pareto_png", spy)
    r = run_cli("design", "log2(1+x)", "--interval", "0", "1", "--in-bits", "8", "--out-bits",
                "8", "--faithful", "-o", tmp_path / "d")
    assert r.code == 0, r.err
    winner = [line for line in r.out.splitlines() if "multipartite" in line]
    assert winner, r.out
    assert "winner: multipartite" in seen["title"] and seen["best"][1] == "best one-width piecewise"
    synthesized = [p for p in seen["points"] if p.yosys_cells is not None]
    assert synthesized and all(seen["measured"](p) == float(p.yosys_cells) for p in synthesized)
