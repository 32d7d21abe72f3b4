"""The function names a designer types (log2, log10, exp2, expm1, log1p, rsqrt,
sinpi, cospi) read as the functions they name: each fit's certified bound holds
against mpmath's own implementation of that function, on a dense grid."""

import mpmath as mp
import numpy as np
import pytest

import chebnorm as cn

REFERENCE = {
    "log2(1+x)": lambda x: mp.log(1 + x, 2),
    "log10(x)": lambda x: mp.log10(x),
    "exp2(x)": lambda x: mp.power(2, x),
    "expm1(x)": lambda x: mp.expm1(x),
    "log1p(x)": lambda x: mp.log1p(x),
    "rsqrt(x)": lambda x: 1 / mp.sqrt(x),
    "sinpi(x)": lambda x: mp.sinpi(x),
    "cospi(x)": lambda x: mp.cospi(x),
}


@pytest.mark.parametrize("expr", sorted(REFERENCE))
def test_designer_name_means_its_function(expr):
    t = cn.fit(expr, ("1/2", "1"), 6, basis="monomial")  # coefficients in powers of x
    xs = np.linspace(0.5, 1.0, 2001)
    with mp.workdps(40):
        worst = max(abs(mp.polyval(list(reversed([mp.mpf(c) for c in t.coefficients])),
                                   mp.mpf(x)) - REFERENCE[expr](mp.mpf(x))) for x in xs)
    assert worst <= t.abs_error_bound
    assert worst >= t.abs_error_bound / 2   # the same function, not a neighbour


def test_designer_names_in_the_cli(capsys):
    from conftest import run_cli

    r = run_cli("fit", "log2(1+x)", "--interval", "0", "1", "--degree", "5")
    assert r.code == 0 and "log(x + 1)/log(2)" in r.out


def test_designer_names_cannot_be_the_variable():
    with pytest.raises(ValueError, match="log2"):
        cn.fit("log2 + 1", (1, 2), 2, var="log2")
