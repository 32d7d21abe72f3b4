"""Issue 25: real fits on a set of powers, parity, honest warnings, CLI endpoints."""

from __future__ import annotations

import warnings

import pytest

from chebnorm.approx import FitWarning, fit, warnings_of
from quiet_cli import run_cli_quiet


def test_symmetric_even_and_odd_minimax_converge_without_warning():
    # Sollya remez (posed in t = x^2): 2.7576677e-8, 9.99250e-6, 8.13710e-5
    for args, sollya in ((("cos(x)", ("-pi/4", "pi/4"), 6), 2.7576677e-8),
                         (("exp(-x^2)", ("-1", "1"), 8), 9.99250e-6),
                         (("atan(x)", ("-1", "1"), 7), 8.13710e-5)):
        with warnings.catch_warnings():
            warnings.simplefilter("error", FitWarning)
            t = fit(*args, kind="minimax")
        assert warnings_of(t) == [] and "parity" in t.provenance
        assert abs(t.max_abs_error / sollya - 1) < 1e-3


def test_monomials_without_a_format_give_the_real_constrained_fit():
    t = fit("sin(x)", ("-1/8", "1/8"), 7, kind="minimax", monomials=(1, 3, 5, 7))
    assert t.quantized is None and t.coefficients[0::2] == (0.0, 0.0, 0.0, 0.0)
    assert t.abs_error_bound < 8.1e-17            # Sollya remez: 8.0171e-17 (was 4.7e-8)
    c = fit("2^x", ("0", "1"), 6, kind="minimax", fix_constant=True)
    assert c.coefficients[0] == 1.0 and c.abs_error_bound < 2.89e-9   # Sollya: 2.8790e-9
    with pytest.raises(ValueError, match="kind 'chebyshev' with monomials"):
        fit("sin(x)", ("0", "1"), 3, monomials=(1, 3))


def test_a_minimax_fit_worse_than_zero_says_so():
    # in plain powers the coefficients rounded to doubles lose everything (the
    # shifted basis that basis="auto" takes here stays near the zero polynomial's error)
    with pytest.warns(FitWarning, match="zero polynomial"):
        t = fit("sin(1/x)", ("0.001", "1"), 30, kind="minimax", basis="monomial")
    assert any("zero polynomial" in w for w in warnings_of(t))


def test_cli_negative_endpoints_and_one_warning_line():
    for lo, hi in (("-1/8", "1/8"), ("-pi/4", "pi/4"), ("(-1/8)", "1/8")):
        r = run_cli_quiet("fit", "sin(x)", "--interval", lo, hi, "--degree", "5", "--kind",
                          "minimax", "--json")
        assert r.code == 0, r.err
    # quiet: a FitWarning escaping as a Python warning (a second "zero polynomial"
    # line in a console) fails the test
    r = run_cli_quiet("fit", "sin(1/x)", "--interval", "0.001", "1", "--degree", "30", "--kind",
                      "minimax", "--basis", "monomial")
    assert r.code == 0
    lines = [ln for ln in r.err.splitlines() if "zero polynomial" in ln]
    assert len(lines) == 1 and lines[0].startswith("chebnorm: warning: ")


def test_float_format_overflow_names_the_format():
    with pytest.raises(ValueError, match=r"overflows binary16 \(largest finite 65504\)"):
        fit("1e6*x", ("0", "1"), 1, kind="minimax", coef_format="binary16")
