"""The degree for an error (issue 41): ``fit(expr, interval, max_error=E)`` and
``chebnorm fit --max-error E`` return the smallest degree certified to reach E;
``segments="auto"`` the fewest segments.

"Smallest" is checked independently of chebnorm's certificates: below the returned
degree, de la Vallee Poussin's theorem evaluated in mpmath (alternating errors of
one polynomial at d + 1 points, all larger than E) proves that *no* polynomial of
that degree reaches E.
"""

from __future__ import annotations

import json
import math

import mpmath
import numpy as np
import pytest

import chebnorm as cn
from chebnorm.approx.api import Interval, degree_lower_bounds
from chebnorm.approx.expr import parse_function
from chebnorm.cli import main


def _errors(coefficients, ref, xs):
    with mpmath.workprec(120):
        return [sum(mpmath.mpf(c) * mpmath.mpf(x) ** k for k, c in enumerate(coefficients))
                - ref(mpmath.mpf(x)) for x in xs]


def _alternation_lower_bound(coefficients, ref, lo, hi, degree):
    """de la Vallee Poussin in mpmath: the largest |e| on each run of one sign of
    ``e = p - f`` on a dense grid; with ``degree + 2`` runs, every polynomial of
    ``degree`` has error >= the smallest of those maxima. 0 when fewer runs."""
    xs = np.linspace(lo, hi, 4001)
    e = _errors(coefficients, ref, xs)
    runs, sign = [], 0
    for v in e:
        s = 1 if v > 0 else -1 if v < 0 else 0
        if s == 0:
            continue
        if s != sign:
            runs.append(abs(v))
            sign = s
        else:
            runs[-1] = max(runs[-1], abs(v))
    return float(min(runs)) if len(runs) >= degree + 2 else 0.0


def test_exp_smallest_degree_for_2_to_the_minus_24():
    E = 2.0 ** -24
    t = cn.fit("exp(x)", (0, 1), max_error=E)
    d = t.degree
    # the returned fit reaches E, checked on a dense grid in mpmath
    worst = max(abs(v) for v in _errors(t.coefficients, mpmath.exp, np.linspace(0, 1, 2001)))
    assert worst <= t.abs_error_bound <= E
    # no polynomial of degree d - 1 reaches E: alternation of the best one, in mpmath
    below = cn.fit("exp(x)", (0, 1), d - 1, kind="minimax")
    assert _alternation_lower_bound(below.coefficients, mpmath.exp, 0, 1, d - 1) > E
    assert d == 6
    # the search is recorded: every degree up to d, each ruled out or certified
    search = t.provenance["degree_search"].removeprefix("degrees tried: ").split("; ")
    assert [int(s.split(":")[0]) for s in search] == list(range(d + 1))
    assert all("ruled out" in s for s in search[:-1]) and "certified" in search[-1]
    assert float(t.provenance["max_error"]) == E


def test_lower_bounds_are_below_every_polynomial_error():
    """The pruning bounds never exceed the error of an actual polynomial of that degree
    (the minimax fit's error, measured in mpmath): a degree they rule out cannot win."""
    for expr, ref, (lo, hi) in (("exp(x)", mpmath.exp, (0, 1)),
                                ("cos(x)", mpmath.cos, (-1, 1)),
                                ("1/sqrt(x)", lambda x: 1 / mpmath.sqrt(x), (1, 4))):
        fn = parse_function(expr)
        lower = degree_lower_bounds(fn, Interval(lo, hi), "abs", 10)
        assert lower[2] > 0
        for n in range(11):
            p = cn.fit(expr, (lo, hi), n, kind="minimax")
            actual = max(abs(v) for v in _errors(p.coefficients, ref, np.linspace(lo, hi, 301)))
            assert lower[n] <= actual, (expr, n, lower[n], actual)


def test_quantized_error_decides():
    """With a format the bound compared with E is the quantized coefficients'; one
    degree lower, quantized in the same format, does not reach E."""
    E = 2.0 ** -20
    t = cn.fit("exp(x)", (0, 1), max_error=E, kind="minimax", coef_format="binary32")
    assert t.quantized.abs_error_bound <= E
    lower = cn.fit("exp(x)", (0, 1), t.degree - 1, kind="minimax", coef_format="binary32")
    assert lower.quantized.abs_error_bound > E
    below = cn.fit("exp(x)", (0, 1), t.degree - 1, kind="minimax")
    assert _alternation_lower_bound(below.coefficients, mpmath.exp, 0, 1, t.degree - 1) > E


def test_relative_error_and_removable_singularity():
    t = cn.fit("1/sqrt(x)", (1, 4), max_error=1e-6, kind="minimax", error="rel")
    assert t.rel_error_bound <= 1e-6
    assert cn.fit("1/sqrt(x)", (1, 4), t.degree - 1, kind="minimax",
                  error="rel").rel_error_bound > 1e-6
    s = cn.fit("sin(x)/x", (-1, 1), max_error=1e-10, kind="minimax")
    assert s.degree == 8 and s.abs_error_bound <= 1e-10
    assert _alternation_lower_bound(
        cn.fit("sin(x)/x", (-1, 1), 7, kind="minimax").coefficients,
        lambda x: mpmath.sinc(x), -1, 1, 7) > 1e-10


def test_segments_auto_fewest_segments():
    E = 1e-5
    t = cn.fit("1/sqrt(x)", (1, 4), 2, kind="minimax", segments="auto", max_error=E,
               coef_frac_bits=24)
    assert t.abs_error_bound <= E
    half = cn.fit("1/sqrt(x)", (1, 4), 2, kind="minimax", segments=t.segment_count // 2,
                  coef_frac_bits=24)
    assert half.abs_error_bound > E
    search = t.provenance["segment_search"].removeprefix("segment counts tried: ").split("; ")
    assert int(search[-1].split(":")[0]) == t.segment_count and "certified" in search[-1]


@pytest.mark.parametrize("kwargs,needle", [
    (dict(degree=3, max_error=1e-3), "both given"),
    (dict(), "degree is missing"),
    (dict(max_error=0.0), "max_error 0.0: accepted: a finite number > 0"),
    (dict(max_error=-1e-3), "accepted: a finite number > 0"),
    (dict(max_error=math.nan), "accepted: a finite number > 0"),
    (dict(max_error=math.inf), "accepted: a finite number > 0"),
    (dict(max_error="1e-3"), "accepted: a finite number > 0"),
    (dict(max_error=True), "accepted: a finite number > 0"),
    (dict(max_error=1e-3, segments=4), "accepted: max_error for one polynomial"),
    (dict(degree=2, segments="auto"), "needs both the degree and max_error"),
    (dict(max_error=1e-300), "no degree up to 30 reaches max_error"),
    (dict(max_error=1e-19, kind="minimax"), "no degree up to 30 reaches max_error"),
])
def test_bad_arguments(kwargs, needle):
    with pytest.raises(ValueError, match=needle.replace("(", r"\(")):
        cn.fit("exp(x)", (0, 1), **kwargs)


def test_cli_max_error(capsys):
    assert main(["fit", "exp(x)", "--interval", "0", "1", "--max-error", "2^-24"]) == 0
    out = capsys.readouterr().out
    assert "chebyshev degree 6 fit of exp(x)" in out
    assert "--max-error 5.960464e-08, degrees tried: 0: ruled out (>= 7.53e-01)" in out
    assert main(["fit", "exp(x)", "--interval", "0", "1", "--max-error", "2^-24",
                 "--kind", "minimax", "--coef-format", "binary32", "--json"]) == 0
    table = json.loads(capsys.readouterr().out)
    assert table["degree"] == 6 and "degree_search" in table["provenance"]
    assert table["quantized"]["abs_error_bound"] <= 2.0 ** -24


def test_cli_segments_auto(capsys):
    assert main(["fit", "1/sqrt(x)", "--interval", "1", "4", "--degree", "2", "--kind", "minimax",
                 "--segments", "auto", "--max-error", "1e-5"]) == 0
    out = capsys.readouterr().out
    assert "--max-error 1.000000e-05, segment counts tried: 1: ruled out" in out
    assert "32 uniform segments" in out


@pytest.mark.parametrize("argv,needle", [
    (["--max-error", "0"], "--max-error '0': accepted: a finite number > 0"),
    (["--max-error", "2^"], "accepted: a finite number > 0"),
    (["--max-error", "1e-3", "--degree", "3"], "--degree and --max-error are both given"),
    ([], "required: --degree"),
    (["--max-error", "1e-3", "--segments", "4"], "--max-error with --segments"),
    (["--segments", "auto", "--degree", "2"], "--segments auto needs --degree N and --max-error E"),
])
def test_cli_bad_max_error(argv, needle, capsys):
    assert main(["fit", "exp(x)", "--interval", "0", "1", *argv]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], captured.err
    assert "Traceback" not in captured.err and captured.out == ""
