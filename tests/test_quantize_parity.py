"""Quantizing an even or odd f on a symmetric interval with no ``monomials``
(issue 41): the parity sub-basis is searched in every format, the other
coefficients are exact zeros, and the answer is never worse than the
full-basis search alone. The Sollya figures are those of
``fpminimax(f, n, [|p...|], I, floating, absolute)`` + ``supnorm`` (Sollya
8.0, upper ends; tests/sollya_parity_cases.py recomputes them)."""

from __future__ import annotations

import pytest

from chebnorm.approx import api, fit, quantize

pytestmark = pytest.mark.filterwarnings("ignore::chebnorm.approx.FitWarning")

#: issue 41's table: (expr, interval, degree, format, Sollya's fpminimax supnorm upper end)
ISSUE = [
    ("sin(x)", ("-pi/4", "pi/4"), 7, "binary32", 1.8129e-09),
    ("tan(x)", ("-1/4", "1/4"), 7, "binary32", 5.5383e-10),
    ("cos(x)", ("-pi/4", "pi/4"), 8, "binary32", 1.0885e-10),
    ("sinh(x)", (-1, 1), 7, "bfloat16", 1.9342e-05),
    ("cosh(x)", ("-1/2", "1/2"), 6, "binary32", 1.0212e-09),
]


@pytest.mark.parametrize("expr, iv, n, fmt, sollya", ISSUE)
def test_issue_table_within_fpminimax(expr, iv, n, fmt, sollya):
    q = fit(expr, iv, n, kind="minimax", coef_format=fmt)
    # the figures are printed to 5 digits: one unit of the last one
    assert q.error_bound <= 1.01 * sollya + 1e-4 * sollya
    assert all(m == 0 for k, m in enumerate(q.quantized.mantissas) if k % 2 != n % 2)
    assert q.quantized.monomials == tuple(range(n + 1))


@pytest.mark.parametrize("fmt, frac", [("fixed", 24), ("binary16", None), ("bfloat16", None),
                                       ("binary32", None), ("binary64", None)])
def test_every_format_matches_the_listed_powers(fmt, frac):
    """No monomials on an odd f is as good as listing its odd powers."""
    t = fit("tan(x)", ("-1/4", "1/4"), 7, kind="minimax")
    full = quantize(t, frac, coef_format=fmt)
    odd = quantize(t, frac, coef_format=fmt, monomials=(1, 3, 5, 7))
    assert full.quantized.mantissas[0::2] == (0, 0, 0, 0)
    assert full.error_bound <= odd.error_bound


@pytest.mark.parametrize("kind, fmt, frac", [("minimax", "binary32", None),
                                             ("chebyshev", "binary32", None),
                                             ("minimax", "fixed", 20)])
def test_never_worse_than_the_full_basis_alone(monkeypatch, kind, fmt, frac):
    t = fit("cos(x)", ("-1", "1"), 6, kind=kind)
    both = quantize(t, frac, coef_format=fmt)
    monkeypatch.setattr(api, "_parity_rounding", lambda *a, **k: None)
    alone = quantize(t, frac, coef_format=fmt)
    assert both.error_bound <= alone.error_bound
    if fmt == "binary32":       # measured: 1.05x (minimax) and 2.0x (chebyshev) better
        assert both.error_bound < alone.error_bound


def test_held_constant_and_mixed_powers():
    # an odd f's held constant is f(0) = 0: the odd powers still carry it
    s = fit("sin(x)", ("-pi/4", "pi/4"), 7, kind="minimax", coef_format="binary32",
            fix_constant=True)
    assert s.quantized.mantissas[0::2] == (0, 0, 0, 0) and s.error_bound <= 1.01 * ISSUE[0][4]
    # an even f's held constant stays, the even powers above it are searched
    c = fit("cos(x)", ("-pi/4", "pi/4"), 8, kind="minimax", coef_format="binary32",
            fix_constant=True)
    assert c.quantized.mantissas[1::2] == (0, 0, 0, 0) and c.quantized.mantissas[0] == 1
    assert c.error_bound <= 1.01 * ISSUE[2][4]
    # powers of both parities listed: the odd ones among them are searched first
    m = fit("sin(x)", ("-pi/4", "pi/4"), 7, kind="minimax", coef_format="binary32",
            monomials=(1, 2, 3, 5, 7))
    assert m.quantized.mantissas[2] == 0 and m.error_bound <= 1.01 * ISSUE[0][4]
