"""Piecewise tables (issue 13): every segment certified, bounds re-proved on load,
the C export and the ROM + Horner hardware checked against independent computations
(mpmath at 40 digits, gcc, Icarus Verilog)."""

from __future__ import annotations

import json
import subprocess
from fractions import Fraction

import mpmath
import numpy as np
import pytest

from chebnorm.approx.expr import parse_function
from chebnorm.approx.piecewise_table import PiecewiseTable, parse_segments
from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.export.c_piecewise import piecewise_c_header, piecewise_eval_bound
from chebnorm.hw.piecewise import design_piecewise, simulate_piecewise
from conftest import tool_missing
from quiet_cli import run_cli_quiet

RSQRT = parse_function("1/sqrt(x)")


def _dense_check(table, points=2001):
    """Every segment's stated bound covers a dense float64 sample of |p_s - f|
    (evaluated independently of the certifier: f through numpy on x)."""
    for s in range(table.segment_count):
        a, b = (float(v) for v in table.segment_bounds(s))
        t = np.linspace(*[float(v) for v in table.local_range], points)
        x = a + (b - a) * (t - float(table.local_range[0]))
        p = np.polynomial.polynomial.polyval(t, table.coefficients(s))
        err = np.max(np.abs(p - RSQRT.numpy(x)))
        seg = table.segments[s]
        assert seg.max_abs_error <= seg.abs_error_bound
        assert err <= seg.abs_error_bound * (1 + 1e-9) + 1e-15, (s, err, seg.abs_error_bound)


@pytest.mark.parametrize("k", range(9))
@pytest.mark.parametrize("degree", [1, 2, 3])
def test_rsqrt_every_segment_certified(k, degree):
    t = piecewise_fit("1/sqrt(x)", ("1", "4"), degree, segments=2 ** k, coef_frac_bits=24)
    assert t.segment_count == 2 ** k
    assert t.abs_error_bound == max(s.abs_error_bound for s in t.segments)
    if k in (0, 4, 8):
        _dense_check(t, 201 if k == 8 else 2001)


def test_more_segments_tighter():
    bounds = [piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=2 ** k,
                            coef_frac_bits=34).abs_error_bound for k in (0, 2, 4, 6)]
    # degree 2: the error falls like h^3 (64x per 4x segments) once h is small
    assert bounds[0] > bounds[1] > bounds[2] > 40 * bounds[3]


def test_centered_and_exponent_rel():
    t = piecewise_fit("1/sqrt(x)", ("1/4", "4"), 2, segments=4, segment_by="exponent",
                      centered=True, error="rel", coef_frac_bits=24)
    assert t.segment_count == 16 and t.rel_error_bound is not None
    x = np.linspace(0.25, 4, 5001, endpoint=False)
    rel = np.abs(t(x) * np.sqrt(x) - 1)
    assert rel.max() <= t.rel_error_bound * (1 + 1e-9)


def test_load_reproves_and_names_fields(tmp_path):
    t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="r")
    path = tmp_path / "r.json"
    t.save(path)
    assert PiecewiseTable.load(path) == t
    d = json.loads(path.read_text())
    d["segments"][2]["abs_error_bound"] = d["segments"][2]["max_abs_error"] / 2
    path.write_text(json.dumps(d))
    with pytest.raises(ValueError, match=r"segments\[2\]\.abs_error_bound"):
        PiecewiseTable.load(path)
    d = json.loads(t.to_json())
    d["segments"][1]["integers"][0] += 1000
    with pytest.raises(ValueError, match=r"segments\[1\]\.abs_error_bound"):
        PiecewiseTable.from_dict(d)
    d = json.loads(t.to_json())
    d["index_bits"] = 40
    with pytest.raises(ValueError, match=r"index_bits: expected an integer in \[0, 12\]"):
        PiecewiseTable.from_dict(d)
    d = json.loads(t.to_json())
    d["name"] = "x */ evil"
    with pytest.raises(ValueError, match="name"):
        PiecewiseTable.from_dict(d)


@pytest.mark.parametrize("kwargs, match", [
    ({"segments": "2^13"}, r"k = 13 is out of range; accepted: 0 <= k <= 12"),
    ({"segments": 3}, "not a power of two"),
    ({"degree": -1}, r"degree = -1 is out of range; accepted: 0 <= degree <= 8"),
    ({"coef_frac_bits": 60}, r"coef_frac_bits = 60 is out of range"),
    ({"interval": ("-1", "4")}, r"not finite and real on segment 0"),
    ({"segment_by": "exponent", "interval": ("1", "3")}, "powers of two"),
])
def test_bad_input(kwargs, match):
    args = {"interval": ("1", "4"), "degree": 2, "segments": 4}
    args.update(kwargs)
    interval, degree = args.pop("interval"), args.pop("degree")
    with pytest.raises(ValueError, match=match):
        piecewise_fit("1/sqrt(x)", interval, degree, **args)


def test_cli_errors_one_line(tmp_path):
    for extra in (["--segments", "2^13"], ["--segments", "4", "--degree", "-1"],
                  ["--segments", "4", "--interval", "-1", "4"]):
        argv = ["fit", "1/sqrt(x)", "--interval", "1", "4", "--degree", "2", *extra]
        r = run_cli_quiet(*argv, cwd=tmp_path)
        assert r.code == 2, r.err
        assert len(r.err.strip().splitlines()) == 1 and "accepted" in r.err


@pytest.mark.requires_tool("gcc")
@pytest.mark.parametrize("segment_by", ["uniform", "exponent"])
def test_c_export_within_eval_bound(tmp_path, segment_by):
    interval = ("1", "4") if segment_by == "uniform" else ("1/4", "4")
    t = piecewise_fit("1/sqrt(x)", interval, 2, segments=8, segment_by=segment_by,
                      coef_frac_bits=30, name="pw", centered=segment_by == "exponent")
    (tmp_path / "chebnorm_pw.h").write_text(piecewise_c_header(t, in_bits=12))
    if segment_by == "uniform":
        xs = [Fraction(1) + 3 * Fraction(k, 4096) for k in range(4096)]
        body = "for (uint32_t k = 0; k < 4096; k++) printf(\"%a\\n\", chebnorm_pw(k));"
    else:
        xs = [Fraction(np.ldexp(1.0, -2)) + Fraction(k, 2048) * Fraction(15, 4) for k in range(2048)]
        xs_text = ",".join(float(x).hex() for x in xs)
        body = (f"static const double xs[] = {{{xs_text}}}; for (int i = 0; i < 2048; i++) "
                "printf(\"%a\\n\", chebnorm_pw(xs[i]));")
    (tmp_path / "m.c").write_text("#include <stdio.h>\n#include \"chebnorm_pw.h\"\n"
                                  f"int main(void) {{ {body} return 0; }}\n")
    subprocess.run(["gcc", "-std=c99", "-O2", "-Wall", "-Werror", "m.c", "-o", "m", "-lm"],
                   cwd=tmp_path, check=True)
    out = subprocess.run(["./m"], cwd=tmp_path, check=True, capture_output=True, text=True).stdout
    ys = [float.fromhex(v) for v in out.split()]
    bound = piecewise_eval_bound(t)
    worst = 0
    with mpmath.workdps(40):
        for x, y in zip(xs, ys):
            xf = mpmath.mpf(float(x)) if segment_by == "exponent" else \
                mpmath.mpf(x.numerator) / x.denominator
            worst = max(worst, abs(mpmath.mpf(y) - 1 / mpmath.sqrt(xf)))
    assert worst <= bound, (float(worst), bound)
    assert bound < 2 * t.abs_error_bound


@pytest.mark.requires_tool("iverilog")
def test_rsqrt_256_segments_hardware_bit_exact(tmp_path):
    """Acceptance: 8-bit index, degree 2, 16-bit in / 16-bit out: iverilog matches the
    model on all 65,536 inputs and the measured error stays within the stated bound."""
    t = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=256, coef_frac_bits=24, name="rs")
    d = design_piecewise(t, 16, 16)
    sim = simulate_piecewise(d, tmp_path)
    assert sim.passed and sim.vectors == 65536 and sim.mismatches == 0, sim.line
    m = d.measure()
    b = d.budget()
    assert m["saturated"] == 0
    assert m["max_error"] <= b["total"]
    # the budget is tight: rounding dominates, measured within a factor 2
    assert b["total"] <= 2 * m["max_error"]
    print(f"measured max error {m['max_error']:.4e} <= stated bound {b['total']:.4e}")


@pytest.mark.requires_tool("iverilog")
@pytest.mark.parametrize("k, degree, centered", [(0, 3, False), (3, 1, True), (5, 2, True)])
def test_small_designs_bit_exact(tmp_path, k, degree, centered):
    t = piecewise_fit("1/sqrt(x)", ("1", "4"), degree, segments=2 ** k, coef_frac_bits=18,
                      centered=centered, name="sm")
    d = design_piecewise(t, 10, 12)
    sim = simulate_piecewise(d, tmp_path)
    assert sim.passed, sim.line
    assert d.measure()["max_error"] <= d.budget()["total"]


def test_parse_segments():
    assert parse_segments("2**3") == 3
    with pytest.raises(ValueError, match="k = -1"):
        parse_segments("2^-1")


def test_design_search_model_only():
    """The winner meets E with a certified bound, no cheaper meeting point exists,
    and the CSV and front are deterministic."""
    from chebnorm.hw.piecewise_search import search

    kw = dict(degrees=(1, 2), synth=False, progress=False, max_index_bits=6)
    r = search("1/sqrt(x)", ("1", "4"), 10, 10, 2e-3, **kw)
    w = r.winner
    assert w is not None and w.meets and w.total_bound <= 2e-3
    assert all(p.model_cost >= w.model_cost for p in r.points if p.meets)
    # the winner's design really meets the bound: measure it over every code
    d = r.designs[(w.degree, w.segments.bit_length() - 1, w.coef_frac_bits)]
    assert d.measure()["max_error"] <= w.total_bound
    assert any(p.pareto for p in r.points)
    assert r.csv() == search("1/sqrt(x)", ("1", "4"), 10, 10, 2e-3, **kw).csv()
    assert "winner:" in r.explain()[0]


def test_design_cli(tmp_path):
    argv = ["design", "1/sqrt(x)", "--interval", "1", "4", "--in-bits", "10", "--out-bits",
            "10", "--max-error", "2e-3", "--degrees", "1", "2", "--max-segments", "2^6",
            "--no-synth", "-o", str(tmp_path / "out")]
    r = run_cli_quiet(*argv)
    assert r.code == 0, r.err
    assert (tmp_path / "out" / "design_rsqrt_1_4_i10_o10_e_0p002.csv").read_text().startswith("degree,segments")
    assert (tmp_path / "out" / "design_rsqrt_1_4_i10_o10_e_0p002.png").stat().st_size > 1000
    assert "winner: degree" in r.out
    bad = argv[:]
    bad[bad.index("2e-3")] = "-1"
    r = run_cli_quiet(*bad)
    assert r.code == 2 and "max-error" in r.err
    assert len(r.err.strip().splitlines()) == 1


def test_cli_fit_export_hw(tmp_path):
    def cli(*argv, code=0):
        r = run_cli_quiet(*argv, cwd=tmp_path)
        assert r.code == code, r.err
        return r

    cli("fit", "1/sqrt(x)", "--interval", "1", "4", "--degree", "2", "--segments", "2^3",
        "--kind", "minimax", "--frac-bits", "20", "--name", "rs", "-o", "rs.json")
    t = PiecewiseTable.load(tmp_path / "rs.json")
    assert t.segment_count == 8
    cli("export", "rs.json", "-o", "rs.h", "--in-bits", "12")
    assert "chebnorm_rs_coeffs[8][3]" in (tmp_path / "rs.h").read_text()
    if tool_missing("iverilog") is None:
        r = cli("hw", "verilog", "rs.json", "--in-bits", "10", "--out-bits", "10", "-o", "hw",
                "--simulate")
        assert "PASS: 1024 vectors, 0 mismatches" in r.out
    r = cli("hw", "report", "rs.json", "--in-bits", "10", "--out-bits", "10", "--no-synth",
            "--json")
    rep = json.loads(r.out)
    assert rep["within_budget"] and rep["measured"]["max_error"] <= rep["budget"]["total"]
    r = cli("hw", "verilog", "rs.json", "--in-bits", "3", "--out-bits", "10", "-o", "hw", code=2)
    assert "--in-bits = 3 is out of range; accepted: 4 <= --in-bits <= 20" in r.err


def test_one_width_run_in_int64_only_where_proved_exact():
    """design_piecewise sizes the one-width datapath on every code with Python
    integers, or in int64 where _int64_fits proves no value can overflow: the
    same wires and the same design either way, and the proof is not vacuous (a
    degree-3 table at 30 coefficient bits, forced into int64 without it, wraps)."""
    import chebnorm.hw.piecewise as P

    k = np.arange(2 ** 16, dtype=np.int64)
    for expr, deg, seg, fc in (("1/sqrt(1+3*x)", 1, 256, 19), ("1/sqrt(1+3*x)", 3, 16, 22),
                               ("sin(x)", 3, 4, 30)):
        t = piecewise_fit(expr, ("0", "1"), deg, segments=seg, coef_frac_bits=fc)
        d = P.design_piecewise(t, 16, 18)
        keep = P._int64_fits
        P._int64_fits = lambda *a: False
        try:
            assert P.design_piecewise(t, 16, 18) == d
        finally:
            P._int64_fits = keep
        for fa, fy in ((10 ** 6, 0), (d.acc_frac_bits, d.y_format.frac_bits)):
            got = P._run(d, k.astype(object), fa, fy)
            exact = _run_objects(P, d, k, fa, fy)
            for key in ("top", "rounded"):
                assert [int(v) for v in got[key]] == [int(v) for v in exact[key]], (expr, fa)
    t = piecewise_fit("sin(x)", ("0", "1"), 3, segments=4, coef_frac_bits=30)
    d = P.design_piecewise(t, 16, 18)
    assert not P._int64_fits(d, 10 ** 6, 0)
    wrapped = P._run(d, k, 10 ** 6, 0)   # int64 forced: overflows
    exact = _run_objects(P, d, k, 10 ** 6, 0)
    assert [int(v) for v in wrapped["top"]] != [int(v) for v in exact["top"]]


def _run_objects(P, d, k, fa, fy):
    """P._run on Python integers throughout (the int64 shortcut switched off)."""
    keep = P._int64_fits
    P._int64_fits = lambda *a: False
    try:
        return P._run(d, k.astype(object), fa, fy)
    finally:
        P._int64_fits = keep
