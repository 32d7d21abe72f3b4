"""Fitting, certification and quantization, checked against independent
computations: mpmath at 40 digits locating each extremum of the error by
root finding on its derivative, numpy's own Chebyshev interpolation, and the
equioscillation theorem."""

from __future__ import annotations


import mpmath
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st, example

from chebnorm.approx import (CoefficientTable, MAX_DEGREE, fit, fit_target, parse_function, quantize,
                             target_names, get_target)
from chebnorm.approx.certify import certify, TOL

WORKLOAD = (
    [("1/sqrt(2+x)", ("sqrt(2)", "2"), d) for d in range(1, 5)]
    + [("1/sqrt(2*(1+x))", ("0", "1"), d) for d in range(1, 5)]
    + [("sqrt(2*(1+x))/2", ("0", "1"), d) for d in range(1, 5)]
    + [("1/sqrt(x)", ("1/2", "2"), d) for d in range(1, 7)]
)


@pytest.fixture(autouse=True)
def _reset_mp():
    old = mpmath.mp.dps
    yield
    mpmath.mp.dps = old


def true_sup(expr: str, coefficients, lo: float, hi: float, kind: str = "abs", var="x"):
    """sup |g| by mpmath: every sign change of g' on a dense grid is refined
    by a 40-digit root finder; ends included. Independent of chebnorm's
    certification (no Arb, no Taylor forms)."""
    f = parse_function(expr, var).mpmath
    with mpmath.workdps(40):
        lo_m, hi_m = mpmath.mpf(lo), mpmath.mpf(hi)
        cs = [mpmath.mpf(c) for c in coefficients]

        def g(x):
            p = mpmath.polyval(cs[::-1], x)
            return p - f(x) if kind == "abs" else p / f(x) - 1

        dg = lambda x: mpmath.diff(g, x)
        xs = mpmath.linspace(lo_m, hi_m, 400)
        best = max(abs(g(lo_m)), abs(g(hi_m)))
        d = [dg(x) for x in xs]
        for a, b, da, db in zip(xs[:-1], xs[1:], d[:-1], d[1:]):
            if da * db <= 0:
                try:
                    r = mpmath.findroot(dg, (a, b), solver="anderson")
                except (ValueError, ZeroDivisionError):
                    r = (a + b) / 2
                if lo_m <= r <= hi_m:
                    best = max(best, abs(g(r)))
                best = max(best, abs(g(a)), abs(g(b)))
        return float(best)


class TestClaimC5:
    def test_chebyshev_degree2(self):
        t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 2, kind="chebyshev", var="z")
        # SPEC: coefficients 0.01422, -0.11881, 0.68076; abs 2.16e-5, rel 0.0040 %
        assert [round(c, 5) for c in t.coefficients] == [0.68076, -0.11881, 0.01422]
        assert round(t.max_abs_error, 7) == 2.16e-5
        assert round(100 * t.max_rel_error, 4) == 0.0040
        assert t.max_abs_error <= t.abs_error_bound <= (1 + TOL) * t.max_abs_error

    def test_minimax_degree2(self):
        t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 2, kind="minimax", var="z")
        assert t.max_abs_error == pytest.approx(2.016e-5, rel=1e-3)
        assert t.abs_error_bound >= t.max_abs_error

    def test_chebyshev_matches_numpy_interpolation(self):
        # numpy interpolates at the Chebyshev points of the first kind too
        t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 3, kind="chebyshev", var="z")
        lo, hi = t.interval_float
        ref = np.polynomial.Chebyshev.interpolate(lambda z: 1 / np.sqrt(2 + z), 3, domain=[lo, hi])
        x = np.linspace(lo, hi, 101)
        scale = np.sum(np.abs(t.coefficients) * hi ** np.arange(4))
        assert np.max(np.abs(t(x) - ref(x))) < 64 * np.finfo(float).eps * scale


@pytest.mark.parametrize("expr,interval,degree", WORKLOAD, ids=lambda v: str(v))
def test_workload_bound_is_rigorous_and_tight(expr, interval, degree):
    t = fit(expr, interval, degree, kind="minimax")
    lo, hi = t.interval_float
    sup = true_sup(expr, t.coefficients, lo, hi)
    assert sup <= t.abs_error_bound <= 1.01 * sup
    # the located maximum is a true value of |p - f|, so it cannot exceed the sup
    assert t.max_abs_error <= sup * (1 + 1e-12)
    sup_rel = true_sup(expr, t.coefficients, lo, hi, "rel")
    assert sup_rel <= t.rel_error_bound <= 1.01 * sup_rel


@pytest.mark.parametrize("expr,interval,degree", WORKLOAD[::3])
def test_minimax_equioscillates(expr, interval, degree):
    """The Remez result attains its maximum with alternating signs at
    degree + 2 points (Chebyshev's equioscillation theorem)."""
    t = fit(expr, interval, degree, kind="minimax")
    lo, hi = t.interval_float
    f = parse_function(expr).numpy
    x = np.linspace(lo, hi, 200001)
    e = t(x) - f(x)
    peaks = []
    for seg in np.array_split(np.arange(x.size), 50 * (degree + 2)):
        i = seg[np.argmax(np.abs(e[seg]))]
        peaks.append(e[i])
    # collapse same-sign runs to their largest member
    alt = [peaks[0]]
    for v in peaks[1:]:
        if np.sign(v) == np.sign(alt[-1]):
            alt[-1] = v if abs(v) > abs(alt[-1]) else alt[-1]
        else:
            alt.append(v)
    big = [v for v in alt if abs(v) > (1 - 1e-3) * t.max_abs_error]
    assert len(big) >= degree + 2


def test_relative_minimax_levels_relative_error():
    t_rel = fit("1/sqrt(x)", ("1/2", "2"), 3, kind="minimax", error="rel")
    t_abs = fit("1/sqrt(x)", ("1/2", "2"), 3, kind="minimax", error="abs")
    assert t_rel.max_rel_error < t_abs.max_rel_error
    assert t_rel.max_abs_error > t_abs.max_abs_error
    lo, hi = t_rel.interval_float
    assert true_sup("1/sqrt(x)", t_rel.coefficients, lo, hi, "rel") <= t_rel.rel_error_bound


@settings(max_examples=25, deadline=None)
@given(lo=st.floats(0.1, 3.0), width=st.floats(0.01, 3.0), degree=st.integers(0, 6),
       kind=st.sampled_from(["chebyshev", "minimax"]))
@example(lo=0.5, width=1.5, degree=6, kind="minimax")
@example(lo=0.1, width=0.01, degree=0, kind="chebyshev")
def test_no_point_exceeds_the_bound(lo, width, degree, kind):
    """An error bound that a denser check can exceed is a bug: 2000 random
    points evaluated at 40 digits never exceed it."""
    hi = lo + width
    t = fit("1/sqrt(x)", (lo, hi), degree, kind=kind)  # floats are taken exactly
    rng = np.random.default_rng(degree)
    with mpmath.workdps(40):
        cs = [mpmath.mpf(c) for c in t.coefficients[::-1]]
        pts = list(rng.uniform(lo, hi, 2000)) + [lo, hi]
        c, s = t.shift or (0.0, 1.0)   # basis="auto" may store powers of (x - c)/s
        worst = max(abs(mpmath.polyval(cs, (mpmath.mpf(x) - mpmath.mpf(c)) / mpmath.mpf(s))
                        - 1 / mpmath.sqrt(mpmath.mpf(x)))
                    for x in pts)
    assert float(worst) <= t.abs_error_bound


class TestQuantize:
    def test_rounded_integers_and_recertified_bound(self):
        t = fit_target("dichotomy", 2)
        q = quantize(t, 16, reoptimize=False)
        fp = q.fixed_point
        assert fp.method == "rounded"
        assert list(fp.integers) == [round(c * 2 ** 16) for c in t.coefficients]
        lo, hi = t.interval_float
        sup = true_sup("1/sqrt(2+z)", fp.coefficients, lo, hi, var="z")
        assert sup <= fp.abs_error_bound <= 1.01 * sup

    def test_reoptimized_is_no_worse(self):
        t = fit_target("dichotomy", 2)
        plain = quantize(t, 16, reoptimize=False).fixed_point
        best = quantize(t, 16).fixed_point
        assert best.abs_error_bound <= plain.abs_error_bound
        # at 16 bits greedy re-optimization keeps the error near the unquantized one
        assert best.abs_error_bound < 1.1 * t.abs_error_bound

    def test_overflow_is_rejected(self):
        t = fit("exp(x)", ("0", "1"), 3)
        with pytest.raises(ValueError, match=r"overflows int32.*accepted: coef_frac_bits <= 30"):
            quantize(t, 40)
        with pytest.raises(ValueError, match="non-negative"):
            quantize(t, -1)


class TestTable:
    def test_json_round_trip_and_determinism(self):
        a = fit_target("midpoint", 2, coef_frac_bits=20)
        b = fit_target("midpoint", 2, coef_frac_bits=20)
        assert a.to_json() == b.to_json()
        assert CoefficientTable.from_json(a.to_json()) == a

    def test_contract_fields(self):
        t = fit_target("eta_term", 1)
        d = t.to_dict()
        for key in ("schema_version", "name", "expression", "variable", "interval", "interval_float",
                    "degree", "kind", "error_kind", "coefficients", "abs_error_bound",
                    "rel_error_bound", "max_abs_error", "max_rel_error", "fixed_point", "provenance"):
            assert key in d
        assert d["interval"] == ["0", "1"]
        assert {"chebnorm", "numpy", "mpmath", "sympy", "python-flint", "command"} <= set(d["provenance"])

    @pytest.mark.parametrize("bad,match", [
        ("[]", "JSON object"), ('{"schema_version": 99}', "schema version 99"),
        ("{", "not valid JSON"), ('{"schema_version": 1}', "missing")])
    def test_bad_json(self, bad, match):
        with pytest.raises(ValueError, match=match):
            CoefficientTable.from_json(bad)


class TestTargets:
    def test_registry(self):
        assert target_names() == ["dichotomy", "eta_term", "midpoint", "rsqrt"]
        assert get_target("dichotomy").interval() == ("sqrt(2)", "2")
        assert get_target("midpoint").interval("pi/3") == ("1/2", "1")
        with pytest.raises(ValueError, match="unknown target 'foo'; accepted: dichotomy"):
            get_target("foo")
        with pytest.raises(ValueError, match="psi_max"):
            get_target("midpoint").interval("4")

    @pytest.mark.parametrize("name", ["dichotomy", "midpoint", "eta_term", "rsqrt"])
    def test_every_target_fits(self, name):
        t = fit_target(name, 2)
        assert t.name == f"{name}_d2"
        assert 0 < t.max_abs_error <= t.abs_error_bound


class TestBadInput:
    @pytest.mark.parametrize("args,match", [
        (("1/sqrt(x)", ("-1", "1"), 2), "not finite and real"),
        (("log(x)", ("0", "1"), 2), "not finite and real"),
        (("x", ("1", "0"), 2), "empty or reversed"),
        (("x", ("1", "1"), 2), "empty or reversed"),
        (("x", ("0", "1"), -1), "accepted: 0 <= degree <= 30"),
        (("x", ("0", "1"), MAX_DEGREE + 1), "accepted: 0 <= degree <= 30"),
        (("x", ("0", "1"), 2.5), "not an integer"),
        (("sqrt(", ("0", "1"), 2), "cannot parse expression"),
        (("x + y", ("0", "1"), 2), "unknown variable"),
        (("x", ("0", "oo"), 2), "not a finite real"),
        (("x", ("0", "foo"), 2), "not a constant"),
        (("x", ("0", "1", "2"), 2), "pair"),
    ])
    def test_value_errors(self, args, match):
        with pytest.raises(ValueError, match=match):
            fit(*args)

    def test_bad_kinds(self):
        with pytest.raises(ValueError, match="accepted: chebyshev, minimax"):
            fit("x", ("0", "1"), 1, kind="taylor")
        with pytest.raises(ValueError, match="accepted: abs, rel"):
            fit("x", ("0", "1"), 1, error="max")

    def test_relative_error_needs_a_nonvanishing_function(self):
        with pytest.raises(ValueError, match="vanishes"):
            fit("x - 1/2", ("0", "1"), 1, kind="minimax", error="rel")
        t = fit("x - 1/2", ("0", "1"), 1)  # abs fits still work, without a relative bound
        assert t.rel_error_bound is None

    def test_singularity_inside_is_found_by_certification(self):
        # 1/(x - 1/3) is infinite at a point the sampling grid never hits
        with pytest.raises(ValueError, match="not finite"):
            fit("1/(3*x - 1)", ("0", "1"), 1)


def test_certify_degree_zero_and_exact():
    fn = parse_function("x**2")
    import sympy as sp
    c = certify(fn, [0.0, 0.0, 1.0], sp.Integer(-1), sp.Integer(1))
    assert c.bound == 0.0
    c = certify(fn, [0.5], sp.Integer(0), sp.Integer(1))
    assert c.maximum == 0.5 and 0.5 <= c.bound <= 0.5 * (1 + TOL)
