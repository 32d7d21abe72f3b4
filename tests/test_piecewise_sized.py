"""The sized piecewise architecture (issue 28): a width per ROM column, truncated
Horner steps, pipelining -- certified bound, bit-exact HDL, cycle-accurate pipelines."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.core.files import write_folder
from chebnorm.hw.hdl import hdl_files
from chebnorm.hw.piecewise import design_piecewise, shape_cost, sized_bound
from conftest import tool_missing

SPEC = ("1/sqrt(1+3*x)", ("0", "1"))


def _table(expr, interval, degree, segments, fc=20, centered=False):
    return piecewise_fit(expr, interval, degree, segments=segments, coef_frac_bits=fc,
                         centered=centered, name="sz")


def _datapath_error(d) -> list[Fraction]:
    """Exact max over each segment's codes of |y - p_s(t)|, p_s the table's polynomial
    in exact rationals -- computed independently of the interval analysis."""
    t = d.table
    L = d.local_bits
    y = d.evaluate()
    worst = [Fraction(0)] * t.segment_count
    for k in range(2 ** d.in_bits):
        s, low = k >> L, k & ((1 << L) - 1)
        tv = Fraction(low, 2 ** L) - (Fraction(1, 2) if t.centered else 0)
        p = sum(Fraction(q, 2 ** t.coef_frac_bits) * tv ** j
                for j, q in enumerate(t.segments[s].integers))
        yv = Fraction(d.y_format.offset_code + int(y[k]), 2 ** d.y_format.frac_bits)
        worst[s] = max(worst[s], abs(yv - p))
    return worst


@pytest.mark.parametrize("multipliers", ["full", "truncated"])
@pytest.mark.parametrize("expr, interval, degree, segments, centered, in_bits, out_bits", [
    ("1/sqrt(x)", ("1", "4"), 2, 8, False, 10, 10),
    ("1/sqrt(x)", ("1", "4"), 3, 4, True, 10, 12),
    ("exp(x)", ("0", "1"), 1, 16, False, 9, 10),
    ("sin(x)", ("-1", "1"), 2, 8, True, 10, 10),
    ("exp(x)", ("0", "1"), 0, 64, False, 8, 8),
])
def test_datapath_bound_covers_exact_error(expr, interval, degree, segments, centered,
                                           in_bits, out_bits, multipliers):
    """The per-segment interval bound of the truncated datapath encloses the exact
    error against the table's polynomial on every code; the total covers |y - f|."""
    t = _table(expr, interval, degree, segments, centered=centered)
    approx = max(s.abs_error_bound for s in t.segments)
    limit = approx + 2 ** -(out_bits - 2)
    d = design_piecewise(t, in_bits, out_bits, widths="auto", max_error=limit,
                         multipliers=multipliers)
    assert d.multipliers == multipliers
    _, (_, path, total) = sized_bound(t, (d.local_bits, degree, centered, d.coef_frac,
                                          d.t_keep, d.acc_frac, multipliers == "truncated",
                                          d.prod_frac))
    exact = _datapath_error(d)
    assert max(exact) <= path
    assert d.measure()["max_error"] <= d.budget()["total"] <= limit
    assert float(total) <= d.budget()["total"]


def test_auto_widths_are_locally_minimal():
    """Greedy: one bit less on any single width misses max_error or grows the area
    proxy (the search's own stopping rule, checked from outside)."""
    t = _table("1/sqrt(x)", ("1", "4"), 2, 8)
    limit = Fraction(1, 2 ** 10)
    d = design_piecewise(t, 12, 12, widths="auto", max_error=limit)
    assert Fraction(d.budget()["total"]) <= limit
    n = d.degree
    area = shape_cost(t, (d.local_bits, n, False, d.coef_frac, d.t_keep, d.acc_frac, False,
                          d.prod_frac), d.coefficients)
    base = {"coef_frac": list(d.coef_frac), "t_keep": list(d.t_keep),
            "acc_frac": list(d.acc_frac[1:n]), "prod_frac": list(d.prod_frac)}
    for key, lowest in (("coef_frac", -8), ("t_keep", 1), ("acc_frac", -8), ("prod_frac", -8)):
        for i in range(len(base[key])):
            if base[key][i] <= lowest:
                continue
            w = {k: list(v) for k, v in base.items()}
            w[key][i] -= 1
            shape = (d.local_bits, n, False, tuple(w["coef_frac"]), tuple(w["t_keep"]),
                     (d.acc_frac[0], *w["acc_frac"], w["coef_frac"][n]), False,
                     tuple(w["prod_frac"]))
            rom, bound = sized_bound(t, shape)
            assert bound[2] > limit or shape_cost(t, shape, rom) > area, (key, i)


def test_explicit_widths_and_coefficient_rerounding_enter_the_bound():
    """Lowering a coefficient's bits by hand widens the certified bound, which still
    covers the measured error (the re-rounding from Fc bits is paid in full)."""
    t = _table("1/sqrt(x)", ("1", "4"), 2, 4)
    wide = design_piecewise(t, 10, 10, widths={"coef_frac": (14, 14, 14), "t_keep": (6, 6),
                                               "acc_frac": (14,)})
    narrow = design_piecewise(t, 10, 10, widths={"coef_frac": (14, 14, 5), "t_keep": (6, 6),
                                                 "acc_frac": (14,)})
    assert narrow.budget()["total"] > wide.budget()["total"]
    for d in (wide, narrow):
        assert max(_datapath_error(d)) <= Fraction(d.budget()["datapath"])
        assert d.measure()["max_error"] <= d.budget()["total"]


def test_pipeline_does_not_change_values():
    t = _table("1/sqrt(x)", ("1", "4"), 2, 8)
    comb = design_piecewise(t, 10, 10, widths="auto", max_error=2 ** -8)
    pipe = design_piecewise(t, 10, 10, widths="auto", max_error=2 ** -8, pipeline="full")
    assert comb.latency == 0 and pipe.latency == 3 and pipe.cuts == (0, 1, 2)
    assert np.array_equal(comb.evaluate(), pipe.evaluate())
    assert design_piecewise(t, 10, 10, widths="auto", max_error=2 ** -8,
                            pipeline=[2, 0, 2]).cuts == (0, 2)


@pytest.mark.parametrize("kwargs, match", [
    (dict(widths={"coef_frac": (10, 10), "t_keep": (6, 6), "acc_frac": (10,)}), "widths"),
    (dict(widths={"coef_frac": (10, 10, 10)}), "widths"),
    (dict(widths="auto", max_error=-1.0), "max_error"),
    (dict(widths="auto", max_error=1e-12), "max_error"),
    (dict(widths="auto", max_error=1e-3, pipeline=(4,)), "pipeline cut"),
    (dict(widths="auto", max_error=1e-3, pipeline="all"), "pipeline"),
    (dict(pipeline="full"), "pipeline"),
    (dict(multipliers="truncated"), "multipliers"),
    (dict(widths="auto", max_error=1e-3, multipliers="booth"), "multipliers"),
])
def test_bad_input(kwargs, match):
    t = _table("1/sqrt(x)", ("1", "4"), 2, 4)
    with pytest.raises(ValueError, match=match):
        design_piecewise(t, 10, 10, **kwargs)


def _simulate(d, tmp_path, language):
    from chebnorm.hw.run_verilog import simulate
    from chebnorm.hw.run_vhdl import simulate_vhdl

    out = Path(tmp_path) / language
    write_folder(out, hdl_files(d, language))
    return (simulate if language == "verilog" else simulate_vhdl)(out, d)


#: the simulator each HDL needs
_SIMULATOR = {"verilog": "iverilog", "vhdl": "ghdl"}


@pytest.mark.parametrize("language", ["verilog", "vhdl"])
@pytest.mark.parametrize("expr, interval, degree, segments, centered, pipeline, multipliers", [
    ("1/sqrt(x)", ("1", "4"), 2, 8, False, None, "full"),
    ("1/sqrt(x)", ("1", "4"), 2, 8, False, None, "truncated"),
    ("1/sqrt(x)", ("1", "4"), 3, 4, True, (0, 2), "full"),
    ("1/sqrt(x)", ("1", "4"), 3, 4, True, (1,), "truncated"),
    ("exp(x)", ("0", "1"), 1, 1, False, "full", "full"),
    ("exp(x)", ("0", "1"), 0, 64, False, (0,), "full"),
    ("sin(x)", ("-1", "1"), 2, 16, True, (2,), "full"),
    ("sin(x)", ("-1", "1"), 2, 16, True, "full", "truncated"),
])
def test_hdl_bit_exact_small(tmp_path, language, expr, interval, degree, segments, centered,
                             pipeline, multipliers):
    if reason := tool_missing(_SIMULATOR[language]):
        pytest.skip(reason)
    t = _table(expr, interval, degree, segments, centered=centered)
    approx = max(s.abs_error_bound for s in t.segments)
    d = design_piecewise(t, 10, 10, widths="auto", max_error=approx + 2 ** -9,
                         pipeline=pipeline, multipliers=multipliers)
    if multipliers == "truncated":  # the truncated multiplier is really printed
        assert any(st["rows"] for st in d.sized_signals())
    sim = _simulate(d, tmp_path, language)
    assert sim.passed and sim.vectors == 1024 and sim.mismatches == 0, sim.line


@pytest.mark.parametrize("language, degree, segments, centered",
                         [("verilog", 2, 128, True), ("vhdl", 1, 256, False)])
def test_spec_16_bit_faithful_pipelined_exhaustive(tmp_path, language, degree, segments,
                                                   centered):
    """The issue-28 spec, 1/sqrt(1+3x) on [0, 1) at 16 bits, faithful, truncated
    multipliers, fully pipelined (the generic winner in Verilog, the xc7 LUT winner in
    VHDL): every one of the 65,536 codes simulated one per cycle matches the model after
    the latency, and the exact |y - f| stays below the certified bound < 2^-16."""
    if reason := tool_missing(_SIMULATOR[language]):
        pytest.skip(reason)
    t = piecewise_fit(*SPEC, degree, segments=segments, coef_frac_bits=26, centered=centered,
                      name="rs")
    d = design_piecewise(t, 16, 16, widths="auto", pipeline="full", multipliers="truncated")
    assert d.y_format.frac_bits == 16 and d.latency == degree + 1
    assert any(st["rows"] for st in d.sized_signals())
    assert d.budget()["total"] < 2 ** -16
    m = d.measure()
    assert m["max_error"] <= d.budget()["total"] and m["saturated"] == 0
    sim = _simulate(d, tmp_path, language)
    assert sim.passed and sim.vectors == 65536 and sim.mismatches == 0, sim.line


def test_faithful_default_out_of_reach_names_it():
    """The default target is faithful at y's last place; a table too coarse for it is
    refused (y's format is not silently coarsened to make the bound)."""
    t = _table("1/sqrt(x)", ("1", "4"), 2, 4)
    assert t.abs_error_bound > 2 ** -11
    with pytest.raises(ValueError, match="faithful"):
        design_piecewise(t, 12, 12, widths="auto")


@pytest.mark.parametrize("widths, multipliers, pipeline", [
    # a product shorter than its kept column (shifted left), a product truncated below G_1
    ({"coef_frac": (12, 9, 7), "t_keep": (4, 3), "acc_frac": (8,), "prod_frac": (14, 6)},
     "full", None),
    ({"coef_frac": (12, 9, 7), "t_keep": (6, 3), "acc_frac": (8,), "prod_frac": (9, 12)},
     "truncated", (1,)),
    ({"coef_frac": (8, 12, 7), "t_keep": (7, 7), "acc_frac": (14,), "prod_frac": (6, 6)},
     "truncated", "full"),
])
def test_explicit_widths_edge_shifts(tmp_path, widths, multipliers, pipeline):
    """Hand-given widths reaching every shift direction of the sized step: the bound
    covers the exact error on every code and both HDLs match the model bit for bit."""
    t = _table("1/sqrt(x)", ("1", "4"), 2, 8, centered=True)
    d = design_piecewise(t, 10, 10, widths=widths, multipliers=multipliers, pipeline=pipeline)
    steps = d.sized_signals()
    assert any(st["pshift"] < 0 for st in steps) or any(st["qshift"] > 0 for st in steps)
    assert max(_datapath_error(d)) <= Fraction(d.budget()["datapath"])
    assert d.measure()["max_error"] <= d.budget()["total"]
    for language in ("verilog", "vhdl"):
        if tool_missing(_SIMULATOR[language]) is None:
            sim = _simulate(d, tmp_path, language)
            assert sim.passed and sim.mismatches == 0, sim.line


@pytest.mark.parametrize("centered, truncated", [(True, True), (False, False)])
def test_sized_bound_cache_changes_nothing(centered, truncated):
    """sized_bound with a cache shared across shapes (as _auto_shape's greedy uses it)
    gives the same ROM and exact bounds as without: shapes that share their top
    steps reuse the cached states, shapes that differ anywhere above must not."""
    t = _table(*SPEC, 3, 8, fc=22, centered=centered)
    L = 12 - 3
    rng = np.random.default_rng(5)
    base = {"F": [16, 15, 14, 13], "T": [L, L - 1, L - 2], "G": [15, 14], "P": [15, 14, 13]}
    cache: dict = {}
    for _ in range(24):
        v = {k: [int(x) - int(rng.integers(0, 4)) for x in vals] for k, vals in base.items()}
        if rng.random() < 0.5:   # keep the top steps: the cache's hits
            for k in v:
                v[k][len(v[k]) // 2:] = base[k][len(v[k]) // 2:]
        F, T = tuple(v["F"]), tuple(max(x, 1) for x in v["T"])
        shape = (L, 3, centered, F, T, (12, *v["G"], F[3]), truncated, tuple(v["P"]))
        assert sized_bound(t, shape, cache=cache) == sized_bound(t, shape), shape
