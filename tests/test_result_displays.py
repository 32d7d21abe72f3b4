"""Every result object shows itself briefly (issue 31): a short text repr (a
few fields, each shortened) and an HTML table of every field, escaped. The
hardware designs, budgets and measurements once dumped 300 to 25,000
characters of dataclass text."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
import sympy as sp

import chebnorm as cn
from chebnorm import hw
from chebnorm.approx import parse_function
from chebnorm.hw.architectures import Candidate
from chebnorm.hw.piecewise import design_piecewise
from chebnorm.hw.piecewise_search import search as hw_search
from chebnorm.hw.pipeline import PipelineResult
from chebnorm.hw.targets import TargetCost
from chebnorm.methods import angular_drift, count_ops
from chebnorm.raster.meshes import get_mesh

#: a repr is one short line
LIMIT = 250


@pytest.fixture(scope="module")
def results():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = cn.quantize(cn.fit("1/sqrt(2+x)", ("0", "1"), 2, name="rs"), 16)
        d = hw.design_horner(t, 10, 10)
        pw = cn.fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="pw")
        unit = hw.design_unit("classic", frac_bits=6)
        mp = hw.design_multipartite("1/sqrt(x)", ("1", "4"), 8, 8)
        search = hw_search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, degrees=(1, 2),
                           max_index_bits=4, synth=False, progress=False, workers=1)
        sw = hw.sweep("dichotomy", degrees=(1,), coef_bits=(10,), acc_bits=(14,), in_bits=6,
                      out_bits=6, synth=False, workers=1, progress=False)
        return [
            d, hw.error_budget(d), hw.measure(d), design_piecewise(pw, 8, 8), unit,
            hw.analyze_unit(unit, synth=False), mp,
            hw.design_plain_table("1/sqrt(x)", ("1", "4"), 8, 8),
            hw.design_exponent("1/sqrt(x)", ("1/4", "1"), 10, 10), sw, sw.points[0],
            hw.analyze_unit(unit, synth=False).block,
            cn.certify(parse_function("1/sqrt(2+x)"), t.coefficients, sp.Integer(0),
                       sp.Integer(1)),
            angular_drift(m=64), count_ops("exact", 16), get_mesh("teapot"), mp.certificate,
            # what synthesis returns, built by hand (no yosys here)
            TargetCost(target="xc7", cells=217, luts=134, dsps=1, carries=6, muxes=76, ffs=0,
                       brams=0, score=398.2, by_type={"LUT6": 80, "LUT5": 54}, levels=13,
                       delay_ns=7.737, timing_model="yosys sta"),
            PipelineResult(design=d, target="ice40", frequency_mhz=50.0, met=True, latency=2,
                           fmax_mhz=61.3, source="nextpnr-ice40", cost=None, steps=((0, 35.1),)),
            search, search.winner,
            Candidate("multipartite", "2 offset tables", mp, 1e-3, 2 ** -8, model=80.5,
                      model_rom=60.0),
        ]


def test_every_result_has_a_short_repr_and_an_html_table(results):
    names = set()
    for obj in results:
        name = type(obj).__name__
        names.add(name)
        text = repr(obj)
        assert text.startswith(name + "(") and "\n" not in text, text
        assert len(text) <= LIMIT, f"{name} repr is {len(text)} characters: {text[:300]}"
        html = obj._repr_html_()
        assert html.startswith("<table>") and f"<b>{name}</b>" in html
        # the table holds the whole record: every field by name
        for f in dataclasses.fields(obj):
            assert f"<th style='text-align:left'>{f.name}</th>" in html, (name, f.name)
    assert {"HornerDesign", "ErrorBudget", "Measurement", "PiecewiseDesign", "UnitDesign",
            "UnitReport", "MultipartiteDesign", "PlainTableDesign", "ExponentDesign",
            "SweepResult", "SweepPoint", "Block", "Certificate", "DriftReport", "OpCounts",
            "Mesh", "ExhaustiveCheck", "TargetCost", "PipelineResult", "SearchResult",
            "DesignPoint", "Candidate"} <= names


def test_repr_values_are_the_objects_own(results):
    d, budget, m = results[0], results[1], results[2]
    assert repr(d) == (f"HornerDesign(name='rs', degree=2, in_bits=10, out_bits=10, "
                       f"x_format='{d.x_format.q_name()}', y_format='{d.y_format.q_name()}', "
                       f"coef_frac_bits=16, rounding='rne')")
    assert f"total={budget.total:.6g}" in repr(budget)
    assert f"total={m.total:.6g}" in repr(m) and f"codes={m.codes}" in repr(m)


def test_html_escapes_user_text():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = cn.quantize(cn.fit("1/sqrt(2+x)", ("0", "1"), 1, name="rs"), 12)
        d = hw.design_horner(t, 6, 6)
    from chebnorm.hw.trust import drafting

    with pytest.raises(ValueError, match="^notes: stated"):   # not the sizing's own notes
        dataclasses.replace(d, notes=("<script>alert(1)</script>",))
    with drafting():   # the display alone, on a design left unchecked
        evil = dataclasses.replace(d, notes=("<script>alert(1)</script>",))
    html = evil._repr_html_()
    assert "<script>" not in html and "&lt;script&gt;" in html


def test_arrays_show_their_shape_not_their_values(results):
    drift = next(r for r in results if type(r).__name__ == "DriftReport")
    html = drift._repr_html_()
    assert f"array(shape={drift.t.shape}, {drift.t.dtype})" in html
    assert len(html) < 5000   # was 25,705 characters of repr
    mesh = next(r for r in results if type(r).__name__ == "Mesh")
    assert f"vertices={len(mesh.positions)}" in repr(mesh)
    assert isinstance(mesh.positions, np.ndarray)


@pytest.mark.requires_tool("gcc")
def test_verify_variants_display_briefly():
    from chebnorm.export.verify import verify

    t = cn.fit("1/sqrt(2+x)", ("0", "1"), 2, name="rs")
    result = verify(t, "c", inputs=1000)
    for v in result.variants:
        text = repr(v)
        assert text.startswith("VariantResult(") and len(text) <= LIMIT, text
        assert f"variant='{v.variant}'" in text and "<table>" in v._repr_html_()
