"""The batched certifier of piecewise tables (issue 13) against independent
computations: mpmath at 40 digits on a dense grid of every segment, the
per-segment certifier (``certify``, one branch and bound in Arb per segment)
and Sollya's ``supnorm`` (skipped without sollya)."""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy as sp
from flint import ctx

from chebnorm.approx import certify, sollya
from chebnorm.approx.certify import TOL, arb_enclose
from chebnorm.approx.certify_batch import SegmentError, certify_batch
from chebnorm.approx.expr import parse_function
from chebnorm.approx.piecewise_table import certify_segments
from chebnorm.approx.piecewise_fit import piecewise_fit


class _Composed:
    """``t -> f(o + w t)`` for the per-segment certifier (o, w exact sympy numbers)."""

    def __init__(self, fn, o, w):
        old, ctx.prec = ctx.prec, 128  # the certifier's working precision
        try:
            ob, wb = arb_enclose(o), arb_enclose(w)
        finally:
            ctx.prec = old
        self.arb_series = lambda s: fn.arb_series(ob + wb * s)
        self.arb = lambda x: fn.arb(ob + wb * x)


def _ends(table, s):
    a, b = table.segment_bounds(s)
    return (a + (b - a) / 2 if table.centered else a), b - a


def _mp_errors(expr, var, table, s, kind, points):
    """``|g_s|`` at ``points`` values of t, in mpmath at 40 digits."""
    f = sp.lambdify(sp.Symbol(var), sp.sympify(expr), "mpmath")
    out = []
    with mpmath.workdps(40):
        o, w = (mpmath.mpf(str(sp.N(v, 50))) for v in _ends(table, s))
        for t in points:
            tm = mpmath.mpf(t)
            x = o + w * tm
            p = mpmath.polyval(list(reversed([mpmath.mpf(c) for c in table.coefficients(s)])), tm)
            fx = f(x)
            out.append(abs(p - fx) if kind == "abs" else abs(p / fx - 1))
    return out


TABLES = [
    # (expression, interval, degree, segments, options, kind)
    ("1/sqrt(x)", ("1", "4"), 2, 256, {}, "abs"),
    ("1/sqrt(x)", ("1/4", "4"), 2, 8, {"segment_by": "exponent", "centered": True,
                                       "error": "rel"}, "rel"),
    ("exp(x)", ("0", "1"), 3, 16, {"coef_frac_bits": 40}, "abs"),
    ("atan(x)", ("-1", "1"), 1, 32, {"centered": True}, "abs"),
    ("sqrt(x)", ("1/64", "1"), 2, 16, {}, "abs"),  # near a singularity: high orders
    ("1/sqrt(x)", ("1", "4"), 2, 1, {}, "abs"),  # one wide segment: the per-segment path
    ("log(x)", ("2", "sqrt(5)"), 2, 8, {"error": "rel"}, "rel"),  # an irrational end
]


@pytest.fixture(scope="module", params=range(len(TABLES)), ids=lambda i: TABLES[i][0])
def case(request):
    expr, interval, degree, segments, opts, kind = TABLES[request.param]
    return piecewise_fit(expr, interval, degree, segments=segments, **opts), kind


@pytest.mark.parametrize("tol", [TOL, 2.0 ** -20])
def test_bounds_cover_mpmath_dense_grid(case, tol):
    table, kind = case
    certs = certify_segments(table, kind, tol)
    n = table.segment_count
    grid = np.linspace(*[float(v) for v in table.local_range], 65 if n > 64 else 401)
    for s in range(n) if n <= 64 else range(0, n, 5):
        c = certs[s]
        errs = _mp_errors(table.expression, table.variable, table, s, kind, [*grid, c.at])
        assert max(errs) <= c.bound, (s, max(errs), c.bound)
        # the located maximum is |g(at)|, rounded (down by the batch: one rounding and
        # one step; to nearest by
        # the per-segment certifier the batch hands a segment to)
        assert abs(c.maximum - errs[-1]) <= 2.0 ** -51 * errs[-1]  # 1.5 ulp at most
        assert c.tight and c.bound <= (1 + tol) * c.maximum + 1e-300


def test_agrees_with_per_segment_certify(case):
    """Both certifiers are rigorous: each bound covers the other's located maximum."""
    table, kind = case
    fn = parse_function(table.expression, table.variable)
    lo, hi = (sp.Rational(v) for v in table.local_range)
    certs = certify_segments(table, kind, 2.0 ** -12)
    step = max(1, table.segment_count // 16)
    for s in range(0, table.segment_count, step):
        ref = certify(_Composed(fn, *_ends(table, s)), table.coefficients(s), lo, hi, kind,
                      tol=2.0 ** -12)
        assert ref.maximum <= certs[s].bound and certs[s].maximum <= ref.bound, s
        assert certs[s].bound <= (1 + 2.0 ** -12) * ref.bound, s


def test_random_coefficients_vs_mpmath():
    """Perturbed coefficients (seeded) give error curves of every shape."""
    rng = np.random.default_rng(13)
    fn = parse_function("1/sqrt(x)")
    n = 40
    origins = [Fraction(1) + Fraction(3 * s, n) for s in range(n)]
    w = Fraction(3, n)
    coeffs = []
    for o in origins:
        x0 = float(o)
        base = [x0 ** -0.5, -0.5 * x0 ** -1.5 * float(w), 0.375 * x0 ** -2.5 * float(w) ** 2]
        coeffs.append([c + rng.normal(scale=10.0 ** rng.uniform(-9, -5)) for c in base])
    certs = certify_batch(fn, origins, [w] * n, coeffs, (0, 1), "abs", 2.0 ** -16)
    grid = np.linspace(0, 1, 257)
    with mpmath.workdps(40):
        for o, cs, c in zip(origins, coeffs, certs):
            worst = max(abs(mpmath.polyval([mpmath.mpf(v) for v in reversed(cs)], mpmath.mpf(t))
                            - 1 / mpmath.sqrt(mpmath.mpf(o.numerator) / o.denominator
                                              + mpmath.mpf(3) / n * mpmath.mpf(t)))
                        for t in grid)
            assert c.maximum <= c.bound <= (1 + 2.0 ** -16) * c.maximum
            assert worst <= c.bound


def test_exact_fit_has_zero_bound():
    # (1/2 + t/2)^2 is p exactly: the error is 0 and so is the bound
    c, = certify_batch(parse_function("x**2"), [Fraction(1, 2)], [Fraction(1, 2)],
                       [[0.25, 0.5, 0.25]])
    assert c.bound == 0.0 and c.maximum == 0.0


def test_not_finite_names_the_segment():
    fn = parse_function("1/x")
    with pytest.raises(SegmentError) as info:
        certify_batch(fn, [-2, -1, 0, 1], [1, 1, 1, 1], [[1.0]] * 4)
    assert info.value.segment in (1, 2) and "not finite" in str(info.value)


def test_bad_arguments():
    fn = parse_function("exp(x)")
    with pytest.raises(ValueError, match="error kind 'max'"):
        certify_batch(fn, [0], [1], [[1.0]], kind="max")
    with pytest.raises(ValueError, match="one of each per segment"):
        certify_batch(fn, [0, 1], [1], [[1.0]])
    with pytest.raises(ValueError, match="tol"):
        certify_batch(fn, [0], [1], [[1.0]], tol=0)
    with pytest.raises(ValueError, match="local interval"):
        certify_batch(fn, [0], [1], [[1.0]], local=(0.1, 0.2))


def test_flint_context_restored():
    prec, cap = ctx.prec, ctx.cap
    certify_batch(parse_function("exp(x)"), [0], [1], [[1.0, 1.0, 0.5]])
    assert (ctx.prec, ctx.cap) == (prec, cap)


@pytest.mark.skipif(not sollya.available(), reason="sollya is not installed")
def test_against_sollya_supnorm():
    """Sollya's certified enclosure of sup |p_s - f| (accuracy 2^-20) on a few
    segments of the 256-segment benchmark table meets ours."""
    table = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=256, coef_frac_bits=24)
    tol = 2.0 ** -20
    certs = certify_segments(table, "abs", tol)
    t = sp.Symbol("t")
    for s in (0, 97, 255):
        o, w = _ends(table, s)
        expr = sp.sstr(1 / sp.sqrt(o + w * t))
        theirs = sollya.supnorm(expr, "t", table.coefficients(s), "0", "1", accuracy=tol)
        assert theirs.lower <= certs[s].bound and certs[s].maximum <= theirs.upper
        # as tight as what Sollya is asked for
        assert certs[s].bound <= (1 + tol) * theirs.upper
        assert math.isfinite(theirs.upper)


def test_tables_certified_one_segment_at_a_time_still_load():
    """Bounds written by the per-segment certifier (tables saved before the
    batch) can be tighter than the batch's at its default: verify escalates."""
    from dataclasses import replace

    table = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=16, coef_frac_bits=24)
    fn = parse_function(table.expression)
    segs = []
    for s, seg in enumerate(table.segments):
        c = certify(_Composed(fn, *_ends(table, s)), table.coefficients(s), sp.Integer(0),
                    sp.Integer(1), "abs")
        segs.append(replace(seg, abs_error_bound=c.bound, max_abs_error=c.maximum))
    old = replace(table, segments=tuple(segs),
                  abs_error_bound=max(s.abs_error_bound for s in segs))
    assert old.verify() is old


def test_below_float_resolution_goes_to_certify():
    fn = parse_function("exp(x)")
    c, = certify_batch(fn, [0], [Fraction(1, 8)], [[1.0, 0.125, 0.0078125]], tol=2.0 ** -45)
    assert c.tight and c.maximum <= c.bound <= (1 + 2.0 ** -45) * c.maximum
