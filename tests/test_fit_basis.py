"""Shifted basis (issue 13), the faster Remez and its high-precision polish (issue 16).

Independent checks: mpmath at 50 digits for f and for the stored polynomial,
gcc for the emitted C, the de la Vallee Poussin alternation for the minimax
property."""

import math
import subprocess

import mpmath
import pytest

from chebnorm.approx import CoefficientTable, fit, parse_function, parse_number
from chebnorm.approx.fitting import cheb_to_monomial, remez, shift_for
from chebnorm.export.c import c_header


def _p_exact(table, x):
    """The stored polynomial at x in 50-digit arithmetic (coefficients exact)."""
    with mpmath.workdps(50):
        t = mpmath.mpf(x)
        if table.shift is not None:
            t = (t - mpmath.mpf(table.shift[0])) / mpmath.mpf(table.shift[1])
        return sum(mpmath.mpf(c) * t ** k for k, c in enumerate(table.coefficients))


def _dense_max(table, f_mp, lo, hi, n=801):
    with mpmath.workdps(50):
        xs = [lo + (hi - lo) * k / (n - 1) for k in range(n)]
        return max(abs(_p_exact(table, x) - f_mp(mpmath.mpf(x))) for x in xs)


def test_shift_for_power_of_two_and_covering():
    for lo, hi in [(1e6, 1e6 + 1), (0.0, 1.0), (-3.0, 5.0), (2 ** 0.5, 2.0), (100.0, 101.0)]:
        c, s = shift_for(lo, hi)
        assert math.frexp(s)[0] == 0.5  # a power of two
        assert abs(lo - c) <= s and abs(hi - c) <= s  # |t| <= 1 on the interval
        assert s / 2 < max(c - lo, hi - c)  # the smallest such power


@pytest.mark.parametrize("kind", ["minimax", "chebyshev"])
def test_log_offset_interval_shifted_is_certified_at_rounding_level(kind):
    t = fit("log(x)", ("1000000", "1000001"), 6, kind=kind, basis="shifted")
    assert t.shift == (1000000.5, 0.5)
    # f ~ 13.8: half an ulp of the constant term is 8.9e-16; allow a few
    assert t.abs_error_bound < 4 * 2 ** -53 * 16
    dense = _dense_max(t, mpmath.log, 1e6, 1e6 + 1)
    assert dense <= t.abs_error_bound
    assert t.max_abs_error <= t.abs_error_bound <= (1 + 2 ** -8) * t.max_abs_error


def test_shifted_beats_monomial_where_monomials_are_ill_conditioned():
    mono = fit("sin(x)", ("100", "101"), 12, kind="minimax", basis="monomial")
    shifted = fit("sin(x)", ("100", "101"), 12, kind="minimax", basis="shifted")
    assert mono.shift is None and mono.abs_error_bound > 1e-3
    assert shifted.abs_error_bound < 1e-15
    assert _dense_max(shifted, mpmath.sin, 100.0, 101.0) <= shifted.abs_error_bound


def test_json_round_trip_and_default_tables_unchanged():
    plain = fit("exp(x)", ("0", "1"), 3)
    assert "shift" not in plain.to_dict() and plain.basis == "monomial"
    s = fit("exp(x)", ("0", "1"), 3, basis="shifted")
    d = s.to_dict()
    assert d["shift"] == [0.5, 0.5]
    assert CoefficientTable.from_json(s.to_json()) == s
    # the shift is part of what is verified: dropping it breaks the bound
    d2 = dict(d)
    del d2["shift"]
    with pytest.raises(ValueError, match="abs_error_bound"):
        CoefficientTable.from_dict(d2)
    for bad, msg in (([1.0, 0.0], "shift\\[1\\]"), ([1.0], "shift"), ("a", "shift"),
                     ([1.0, -2.0], "shift\\[1\\]")):
        with pytest.raises(ValueError, match=msg):
            CoefficientTable.from_dict({**d, "shift": bad})


def test_consumers_without_shifted_evaluation_refuse(tmp_path):
    # the shaders and the Verilog/VHDL evaluators take the shifted variable
    # (tests/test_export_shifted_shaders.py, tests/test_hdl_schemes.py)
    with pytest.raises(ValueError, match="basis shifted"):
        fit("exp(x)", ("0", "1"), 2, basis="shifted", coef_frac_bits=12)


@pytest.mark.requires_tool("gcc")
def test_c_shifted_evaluator_within_its_bound(tmp_path):
    t = fit("log(x)", ("1000000", "1000001"), 6, kind="minimax", basis="shifted", name="lg")
    (tmp_path / "lg.h").write_text(c_header(t))
    (tmp_path / "m.c").write_text(
        '#include <stdio.h>\n#include "lg.h"\nint main(void){for(int k=0;k<=1000;k++){'
        'double x=1000000.0+k/1000.0; printf("%a %a %a\\n",x,chebnorm_lg(x),'
        '(double)chebnorm_lg_f((float)x));}\n'
        'printf("%a %a\\n",CHEBNORM_LG_EVAL_ERROR_BOUND,CHEBNORM_LG_F_EVAL_ERROR_BOUND);}\n')
    subprocess.run(["gcc", "-O2", "-std=c99", "-o", str(tmp_path / "m"), str(tmp_path / "m.c")],
                   check=True)
    lines = subprocess.run([str(tmp_path / "m")], capture_output=True, text=True,
                           check=True).stdout.split("\n")
    bd, bf = (float.fromhex(v) for v in lines[-2].split())
    # Horner's gamma_2n * sum |a_k| with |t| <= 1, sum |a_k| ~ |f| < 16, plus the fit's bound
    assert bd <= 2 * (2 * 6 * 2 ** -53) * 16
    with mpmath.workdps(40):
        for line in lines[:-2]:
            x, yd, yf = (float.fromhex(v) for v in line.split())
            assert abs(mpmath.mpf(yd) - mpmath.log(x)) <= bd
            xf = float(__import__("numpy").float32(x))
            assert abs(mpmath.mpf(yf) - mpmath.log(xf)) <= bf


def _workload():
    from benchmarks.bench_fit import WORKLOAD
    return WORKLOAD


@pytest.mark.parametrize("case", range(18))
def test_remez_equioscillates(case):
    """de la Vallee Poussin: alternating errors at the reference, and the
    smallest of them within rtol of the certified sup: minimax to that rtol."""
    expr, (lo, hi), d = _workload()[case]
    fn = parse_function(expr)
    lo_f, hi_f = float(parse_number(lo)), float(parse_number(hi))
    res = remez(fn.numpy, None, lo_f, hi_f, d)
    assert res.converged and len(res.ref) == d + 2
    t = fit(expr, (lo, hi), d, kind="minimax", basis="monomial")  # the powers of x compared
    assert list(t.coefficients) == cheb_to_monomial(res.cheb, lo_f, hi_f)
    with mpmath.workdps(40):
        errs = []
        for u in res.ref:
            x = mpmath.mpf((hi_f - lo_f) / 2) * mpmath.mpf(float(u)) + mpmath.mpf((hi_f + lo_f) / 2)
            errs.append(sum(mpmath.mpf(c) * x ** k for k, c in enumerate(t.coefficients))
                        - fn.mpmath(x))
    assert all(a * b < 0 for a, b in zip(errs, errs[1:]))
    # the levelled errors agree to 1e-6 with the certified supremum (minimax to 1e-6)
    assert min(abs(e) for e in errs) >= (1 - 1e-6) * t.abs_error_bound / (1 + 2 ** -8)


def test_polish_high_degree_reaches_rounding_level():
    t = fit("exp(x)", ("0", "1"), 25, kind="minimax")
    assert t.abs_error_bound < 2 ** -53  # the float64 exchange alone stopped at 4e-15
    assert "did not converge" not in t.provenance.get("warnings", "")
