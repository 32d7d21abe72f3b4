"""Issue 44: one input-code convention for every hardware path.

The W-bit code k stands for x_k = lo + (hi - lo) k / 2**W on [lo, hi) in
``hw.report``/``design_horner``, ``hw verilog``, ``design`` (the piecewise
path) and the exhaustive proofs (chebnorm.hw.exhaustive) whenever that is a
fixed-point format; an explicit ``x_frac_bits`` keeps the covering mapping the
Horner path used by default before; a width that is not a power of two keeps
the covering mapping, with the valid codes reported ("Input codes" in
docs/hardware.md).
"""

from __future__ import annotations

import dataclasses
import json
from fractions import Fraction

import numpy as np
import pytest

import chebnorm as cn
from chebnorm.approx import piecewise_fit
from chebnorm.hw.exhaustive import reference
from chebnorm.hw.fixed import QFormat
from chebnorm.hw.horner import code_frac_bits, cover_frac_bits, design_horner
from chebnorm.hw.piecewise import design_piecewise
from chebnorm.hw.report import analyze, hdl_outputs, write_outputs
from conftest import requires_tool, run_cli

EXPR = "1/sqrt(1+x)"


@pytest.fixture(scope="module")
def unit_table():
    return cn.fit(EXPR, ("0", "1"), 3, coef_frac_bits=20, name="rs")


@pytest.fixture(scope="module")
def unit_report(unit_table):
    return analyze(unit_table, 12, 12, synth=False, gappa=False)


def _codes_x(design, codes):
    return [design.x_format.value(int(k)) for k in codes]


def test_report_on_unit_interval_uses_every_code(unit_report):
    """The issue's case: [0, 1], 12 bits: all 4096 codes valid, x_k = k / 2^12."""
    d = unit_report.design
    assert d.x_format == QFormat(bits=12, frac_bits=12, offset_code=0, signed=False)
    assert d.valid_codes == (0, 4095)
    assert not any("input codes lie" in n for n in d.notes)
    assert unit_report.measurement.codes == 4096
    k = range(4096)
    assert _codes_x(d, k) == [Fraction(i, 4096) for i in k]
    assert all(unit_report.checks.values()), unit_report.checks
    text = "\n".join(unit_report.lines())
    assert "x_format: code k -> 0.0 + k / 2^12; valid codes 0..4095" in text


def test_same_x_as_design_and_the_exhaustive_reference(unit_report):
    """Horner's x_k is hw/exhaustive.py's x_k and the piecewise (design) path's."""
    d = unit_report.design
    ref = reference(EXPR, ("0", "1"), 12)
    pw = design_piecewise(piecewise_fit(EXPR, ("0", "1"), 2, segments=2 ** 2,
                                        coef_frac_bits=20, name="rs_pw"), 12, 12)
    k = list(range(4096))
    mine = _codes_x(d, k)
    assert mine == [ref.x(i) for i in k]
    assert mine == pw.x_values(k)


def test_measured_error_over_every_code_is_within_the_budget(unit_report):
    """Against Arb enclosures of f at every x_k (not the report's own float64
    measurement): the rigorous upper bound of max_k |y_k - f(x_k)| stays under
    the certified total, and the exact rounding error under its bound."""
    d, b = unit_report.design, unit_report.budget
    y = d.evaluate() + d.y_format.offset_code
    bounds = reference(EXPR, ("0", "1"), 12).error_bounds(y, d.y_format.frac_bits)
    assert bounds["codes"] == 4096
    assert bounds["upper"] <= b.total
    assert unit_report.measurement.rounding <= b.rounding


def test_explicit_code_frac_bits_is_the_default(unit_table, unit_report):
    """x_frac_bits = 12 was refused; it is the input-code mapping itself."""
    d = design_horner(unit_table, 12, 12, x_frac_bits=12)
    assert d == unit_report.design
    assert code_frac_bits(unit_table, 12) == 12


def test_explicit_x_frac_bits_keeps_the_old_mapping(unit_table):
    d = design_horner(unit_table, 12, 12, x_frac_bits=11)
    assert d.x_format == QFormat(bits=12, frac_bits=11, offset_code=0, signed=False)
    assert d.valid_codes == (0, 2048)
    assert _codes_x(d, [0, 1, 2048, 4095]) == [0, Fraction(1, 2048), 1, Fraction(4095, 2048)]
    assert any(n.startswith("2049 of 4096 input codes lie in the table's interval") for n in d.notes)
    assert cover_frac_bits(unit_table, 12) == 11
    r = analyze(unit_table, 12, 12, x_frac_bits=11, synth=False, gappa=False)
    assert r.measurement.codes == 2049 and all(r.checks.values())


def test_x_frac_bits_past_both_mappings_is_refused(unit_table):
    with pytest.raises(ValueError, match=r"accepted: x_frac_bits = 12 \(the codes map onto "
                                         r"\[0, 1\)\), x_frac_bits <= 11, or more input bits"):
        design_horner(unit_table, 12, 12, x_frac_bits=13)


@pytest.mark.parametrize("interval,bits,frac,offset", [
    (("1", "2"), 10, 10, 1024),        # x_k = 1 + k / 2^10
    (("-1", "1"), 10, 9, -512),        # x_k = -1 + 2 k / 2^10
    (("1/4", "1/2"), 8, 10, 256),      # x_k = 1/4 + k / 2^10
])
def test_power_of_two_widths(interval, bits, frac, offset):
    t = cn.fit("exp(x)", interval, 3, coef_frac_bits=20, name="e")
    d = design_horner(t, bits, 14)
    assert (d.x_format.frac_bits, d.x_format.offset_code, d.valid_codes) == \
        (frac, offset, (0, 2 ** bits - 1))
    ref = reference("exp(x)", interval, bits)
    assert _codes_x(d, range(2 ** bits)) == [ref.x(k) for k in range(2 ** bits)]


@pytest.mark.parametrize("interval,bits,frac,valid", [
    (("0", "3"), 12, 10, (0, 3072)),         # width 3: not a power of two
    (("1/3", "4/3"), 12, 11, (1, 2048)),     # width 1, but lo is not a multiple of 2^-12
])
def test_other_intervals_cover_and_report_the_valid_codes(interval, bits, frac, valid):
    """Documented: the covering mapping (largest x_frac_bits whose codes reach
    hi), the valid codes named in a note, the budget holding on them."""
    t = cn.fit("exp(x)", interval, 4, coef_frac_bits=20, name="e")
    assert code_frac_bits(t, bits) is None
    r = analyze(t, bits, 16, synth=False, gappa=False)
    d = r.design
    assert d.x_format.frac_bits == frac == cover_frac_bits(t, bits)
    assert d.valid_codes == valid
    lo, hi = (Fraction(v) for v in interval)
    x = _codes_x(d, range(2 ** bits))
    inside = [k for k, v in enumerate(x) if lo <= v <= hi]
    assert (inside[0], inside[-1]) == valid and len(inside) == valid[1] - valid[0] + 1
    n = valid[1] - valid[0] + 1
    assert any(note.startswith(f"{n} of {2 ** bits} input codes lie in the table's interval "
                               f"(codes {valid[0]}..{valid[1]})") for note in d.notes)
    assert r.measurement.codes == n and all(r.checks.values()), r.checks


def test_irrational_endpoint_covers():
    t = cn.fit_target("dichotomy", 2)
    assert code_frac_bits(t, 12) is None
    d = design_horner(t, 12, 12, coef_bits=16)
    assert d.valid_codes[1] - d.valid_codes[0] + 1 < 4096


def test_trust_reproof_follows_the_convention(unit_report):
    """A design re-proved from its fields gets the same mapping; one claiming
    the old offset/valid codes with the new format is refused."""
    d = unit_report.design
    assert d.verify() is d
    with pytest.raises(ValueError, match="valid_codes"):
        dataclasses.replace(d, valid_codes=(0, 2048))
    with pytest.raises(ValueError, match="x_format"):
        dataclasses.replace(d, x_format=QFormat(bits=12, frac_bits=12, offset_code=1))


def test_cli_report_default_and_explicit(tmp_path, unit_table):
    unit_table.save(tmp_path / "rs.json")
    base = ("hw", "report", str(tmp_path / "rs.json"), "--in-bits", "12", "--out-bits", "12",
            "--no-synth", "--no-gappa", "--json")
    res = run_cli(*base)
    assert res.code == 0, res.err
    d = json.loads(res.out)
    assert d["x_format"]["frac_bits"] == 12 and d["x_format"]["offset_code"] == 0
    assert d["valid_codes"] == [0, 4095] and d["measured"]["codes"] == 4096
    assert all(d["checks"].values())
    old = json.loads(run_cli(*base, "--x-frac-bits", "11").out)
    assert old["x_format"]["frac_bits"] == 11 and old["valid_codes"] == [0, 2048]
    bad = run_cli(*base, "--x-frac-bits", "13")
    assert bad.code == 2 and bad.out == ""
    assert len(bad.err.strip().splitlines()) == 1 and "Traceback" not in bad.err
    assert "--x-frac-bits = 12 (the codes map onto [0, 1))" in bad.err
    assert "--x-frac-bits <= 11" in bad.err


@requires_tool("iverilog", "vvp")
def test_verilog_bench_runs_every_code(tmp_path, unit_table):
    from chebnorm.hw.run_verilog import simulate

    r = analyze(unit_table, 9, 10, synth=False, gappa=False)
    assert r.design.valid_codes == (0, 511)
    write_outputs(tmp_path, hdl_outputs(r, "verilog", pipelined=True))
    for name in (r.design.module_name, r.design.module_name + "_pipe"):
        res = simulate(tmp_path, name)
        assert res.passed and res.vectors == 512 and res.mismatches == 0, res.line
    text = (tmp_path / f"{r.design.module_name}.v").read_text()
    assert "value = 0.0 + k / 2^9" in text and "Valid input codes 0..511" in text


@requires_tool("ghdl")
def test_vhdl_bench_runs_every_code(tmp_path, unit_table):
    from chebnorm.hw.run_vhdl import simulate_vhdl

    r = analyze(unit_table, 9, 10, synth=False, gappa=False)
    write_outputs(tmp_path, hdl_outputs(r, "vhdl"))
    res = simulate_vhdl(tmp_path, r.design.module_name)
    assert res.passed and res.vectors == 512, res.line


@requires_tool("gappa")
def test_gappa_bounds_the_rounding_over_every_code(unit_table):
    r = analyze(unit_table, 12, 12, synth=False, gappa=True)
    b, m = r.budget, r.measurement
    assert b.gappa_rounding is not None
    assert m.codes == 4096 and m.rounding <= b.gappa_rounding
    assert r.checks["rounding_within_bound"]


def test_units_keep_the_covering_mapping():
    """The eta unit's dot product reaches 1 = hi: its evaluator covers [0, 1]."""
    from chebnorm.hw.units import design_unit

    u = design_unit("eta", frac_bits=8, in_bits=10, out_bits=10)
    d = u.horner
    assert d.x_format.frac_bits == 9 and d.valid_codes == (0, 512)
    assert d.x_format.value(d.valid_codes[1]) == 1
    assert np.all(d.evaluate() <= d.y_format.max_code)
