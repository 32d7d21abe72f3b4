"""Issue 25's speed work on ``quantize``: the shortcuts give the answers of
the full computation (the speed itself is measured in benchmarks/bench_fit.py
--quantize, never here)."""

from __future__ import annotations

import math

import pytest
import sympy as sp

from chebnorm.approx import fit, parse_function, quantize
from chebnorm.approx.certify import certify
from chebnorm.approx.rounding import SELECT_TOL, representable


def test_binary64_zero_coefficient_keeps_its_quantum():
    """A lattice candidate with a zero coefficient set that power's floating
    quantum to 2^-1074, and rounding the real coefficient to it overflowed
    (OverflowError: math range error)."""
    base = fit("1/sqrt(x)", ("1", "2"), 8, kind="minimax", error="rel")
    q = quantize(base, coef_format="binary64")
    assert all(representable(m, e, "binary64")
               for m, e in zip(q.quantized.mantissas, q.quantized.exponents))
    # at least as good as each coefficient rounded to nearest binary64
    plain = quantize(base, coef_format="binary64", reoptimize=False)
    assert q.quantized.rel_error_bound <= plain.quantized.rel_error_bound


@pytest.mark.parametrize("expr, lo, hi", [("sin(x)", "-1/4", "1/4"), ("log(1+x)", "0", "1"),
                                          ("x - 1/3", "0", "1")])
def test_relative_error_refused_where_f_vanishes(expr, lo, hi):
    """f of both signs, or exactly 0 at a point: p/f - 1 is refused with the
    certifier's ValueError (at once; it bisected to 2^-60 of the interval first)."""
    fn = parse_function(expr)
    with pytest.raises(ValueError, match=r"p/f - 1 \(f is zero or undefined there\)"):
        certify(fn, [0.0, 1.0], sp.sympify(lo), sp.sympify(hi), "rel")


@pytest.mark.parametrize("expr, coeffs, kind", [
    ("exp(x)", [1.0, 1.0, 0.5, 0.1666], "abs"),
    ("exp(x)", [1.0, 1.0, 0.5, 0.1666], "rel"),
    ("1/sqrt(x)", [2.0, -1.5, 0.5], "rel"),
    ("atan(x)", [0.0, 0.995, 0.0, -0.29], "abs")])
def test_abort_at_is_exact(expr, coeffs, kind):
    """certify(..., abort_at=t) is either the very certificate, or None when
    the bound is at least t (then it cannot beat a bound t)."""
    fn = parse_function(expr)
    lo, hi = (sp.Rational(1, 4), sp.Integer(1))
    full = certify(fn, coeffs, lo, hi, kind, tol=SELECT_TOL)
    for t in (0.5 * full.maximum, full.maximum, full.bound, math.nextafter(full.bound, 1.0),
              2 * full.bound):
        got = certify(fn, coeffs, lo, hi, kind, tol=SELECT_TOL, abort_at=t)
        assert got == full or (got is None and full.bound >= t), (t, got)
    assert certify(fn, coeffs, lo, hi, kind, tol=SELECT_TOL, abort_at=0.5 * full.maximum) is None
    assert certify(fn, coeffs, lo, hi, kind, tol=SELECT_TOL, abort_at=2 * full.bound) == full


def test_batched_sampled_errors_are_the_same_floats():
    """The sampler's batched errors (ranking the candidates) equal its
    one-at-a-time errors bit for bit, zero coefficients included."""
    import random

    from chebnorm.approx.rounding import Problem as _Problem, _Sampler

    fn = parse_function("exp(x)")
    prob = _Problem(fn=fn, lo=sp.Integer(0), hi=sp.Integer(1), lo_f=0.0, hi_f=1.0,
                    error_kind="rel", degree=4, powers=(0, 1, 2, 3, 4), fixed={},
                    word_limit=None)
    sampler = _Sampler(prob)
    rng = random.Random(25)
    rows = [[rng.choice([0.0, rng.uniform(-2, 2)]) for _ in range(5)] for _ in range(70)]
    rows.append([1.0, 1.0, 0.5, 0.16666666666666666, 0.041666666666666664])
    assert sampler.errors(rows) == [sampler.error(r) for r in rows]


def test_lattice_resolves_the_residual_cos_28_bits():
    """cos(x) on [-1/8, 1/8], even powers, 28 fractional bits: the lattice scaled
    f itself to 62-bit integers, leaving the x^6 column a few bits, and Babai's
    answers were quanta off; plain rounding won with 1.023e-13. Sollya 8's
    fpminimax (powers 0,2,4,6, fixed 28, on [0, 1/8]) returns the integers
    below, whose supnorm on [-1/8, 1/8] is 5.18950e-14."""
    base = fit("cos(x)", ("-1/8", "1/8"), 6, kind="minimax")
    q = quantize(base, 28, monomials=(0, 2, 4, 6))
    fpminimax = [1, 0, -0.5, 0, math.ldexp(11184810, -28), 0, math.ldexp(-372684, -28)]
    fn = parse_function("cos(x)")
    theirs = certify(fn, fpminimax, sp.Rational(-1, 8), sp.Rational(1, 8), tol=SELECT_TOL)
    assert q.quantized.abs_error_bound <= theirs.bound * (1 + SELECT_TOL)


def test_table_fitted_with_the_powers_is_not_refitted(monkeypatch):
    """A table fitted with ``monomials`` (and a binary64 fixed constant) already
    holds the constrained real fit: quantize starts from it, and the answer is
    the one it gives after refitting itself."""
    from chebnorm.approx import api

    cases = [("sin(x)", ("-1/8", "1/8"), 7, dict(monomials=(1, 3, 5, 7))),
             ("2^x", ("0", "1"), 6, dict(fix_constant=True))]
    for expr, iv, d, kw in cases:
        plain = quantize(fit(expr, iv, d, kind="minimax"), coef_format="binary64", **kw)
        fitted = fit(expr, iv, d, kind="minimax", **kw)
        calls = []
        real_fit = api._constrained_fit
        monkeypatch.setattr(api, "_constrained_fit", lambda *a, **k: calls.append(a) or
                            real_fit(*a, **k))
        again = quantize(fitted, coef_format="binary64", **kw)
        monkeypatch.setattr(api, "_constrained_fit", real_fit)
        assert calls == [], expr
        assert again.quantized.mantissas == plain.quantized.mantissas, expr
        assert again.quantized.abs_error_bound == plain.quantized.abs_error_bound


def _problem(expr, lo, hi, degree, kind, powers, fixed=None):
    from chebnorm.approx.api import Interval
    from chebnorm.approx.rounding import Problem as _Problem

    iv = Interval(lo, hi)
    return _Problem(fn=parse_function(expr), lo=iv.lo, hi=iv.hi, lo_f=iv.lo_f, hi_f=iv.hi_f,
                    error_kind=kind, degree=degree, powers=powers, fixed=fixed or {},
                    word_limit=None)


@pytest.mark.parametrize("expr, lo, hi, kind, powers, fixed", [
    ("exp(x)", "0", "1", "abs", (0, 1), None),
    ("1/sqrt(x)", "1/4", "1", "rel", (0, 1), None),
    ("sin(x)", "-1", "1", "abs", (1, 3), None),
    ("log(1+x)", "0", "1", "abs", (1, 2), {0: (0, 0)}),
])
def test_grid_lower_bound_holds_for_every_grid_polynomial(expr, lo, hi, kind, powers, fixed):
    """The bound that lets the fixed-point pool skip bit counts: no polynomial
    on the grid (every one within +-10 quanta of the real fit, enumerated) has
    a smaller error, measured on 20001 points (at most its true supremum), and
    the bound is not vacuous (positive at some grid)."""
    import itertools

    import numpy as np

    from chebnorm.approx.api import fit as fit_real
    from chebnorm.approx.rounding import _grid_lower_bounds

    degree = max(powers)
    prob = _problem(expr, lo, hi, degree, kind, powers, fixed)
    real = fit_real(expr, (lo, hi), degree, kind="minimax", error=kind,
                    monomials=powers, fix_constant=bool(fixed)).coefficients
    fracs = [6] * (degree + 1)
    bound_at = _grid_lower_bounds(prob, fracs)
    x = np.linspace(prob.lo_f, prob.hi_f, 20001)[1:-1]
    fx = prob.fn.numpy(x)
    held = sum(math.ldexp(m, e) * x ** k for k, (m, e) in prob.fixed.items())
    seen_positive = False
    for level in range(7):
        lb = bound_at(level)
        seen_positive |= lb > 0
        q = 2.0 ** (level - 6)
        centre = [round(real[k] / q) for k in powers]
        best = math.inf
        for offs in itertools.product(range(-10, 11), repeat=len(powers)):
            p = held + sum((c + o) * q * x ** k for c, o, k in zip(centre, offs, powers))
            err = np.abs(p - fx) / (np.abs(fx) if kind == "rel" else 1.0)
            best = min(best, float(np.max(err)))
        assert lb <= best, (level, lb, best)
    assert seen_positive


def test_error_at_the_peaks_is_a_tight_lower_bound():
    """What lets a floating format skip candidates: the error in ball
    arithmetic at the refined peaks of the error is at most the certified
    bound (a lower bound of the supremum) and within 1e-9 of the maximum the
    certifier located (or above it: the peaks are found independently; the
    float samples' allowance was 3.5e-7 relative here)."""
    from chebnorm.approx.rounding import _error_at, _peaks, _Sampler

    base = fit("1/sqrt(x)", ("1", "2"), 8, kind="minimax", error="rel")
    prob = _problem("1/sqrt(x)", "1", "2", 8, "rel", tuple(range(9)))
    coeffs = tuple(base.coefficients)
    cert = certify(prob.fn, list(coeffs), prob.lo, prob.hi, "rel", tol=SELECT_TOL)
    low = _error_at(prob, _peaks(prob, _Sampler(prob), coeffs), coeffs)
    assert low <= cert.bound
    assert low >= cert.maximum * (1 - 1e-9)


def test_shared_sample_grid_is_the_one_computed_afresh():
    """The sampler's grid (points, f, weights, powers, its sorted and thinned
    views) is shared by every quantization of one function on one interval:
    it holds the floats computed afresh here as the sampler computed them
    before the sharing, the batched errors on it are those floats' errors,
    and nothing can change it."""
    import numpy as np

    from chebnorm.approx.rounding import Problem as _Problem, _Sampler, chebyshev_nodes
    from chebnorm.core import clib

    fn = parse_function("1/sqrt(x)")
    prob = _Problem(fn=fn, lo=sp.Rational(1, 4), hi=sp.Integer(1), lo_f=0.25, hi_f=1.0,
                    error_kind="rel", degree=5, powers=(0, 1, 2, 3, 4, 5), fixed={},
                    word_limit=None)
    samplers = [_Sampler(prob), _Sampler(prob)]
    assert samplers[0].grid is samplers[1].grid          # shared, not recomputed
    x = np.clip(np.concatenate([np.linspace(0.25, 1.0, 4097),
                                chebyshev_nodes(0.25, 1.0, 2048)]), 0.25, 1.0)
    f = np.array([1 / math.sqrt(v) for v in x])
    ok = (x > 0.25) & (x < 1.0)
    x, f = x[ok], f[ok]
    w = 1 / np.abs(f)
    coeffs = [[3.1, -6.2, 8.4, -6.9, 3.0, -0.5], [3.0, -6.0, 8.0, -7.0, 3.0, 0.0]]
    for s in samplers + [samplers[0].thinned(), samplers[0].ordered()]:
        assert s.x.tobytes() in (x.tobytes(), x[::16].tobytes(), np.sort(x).tobytes())
        idx = np.searchsorted(np.sort(x), s.x)
        order = np.argsort(x)
        assert s.f.tobytes() == f[order][idx].tobytes()
        assert s.w.tobytes() == w[order][idx].tobytes()
        powers = [np.ones_like(s.x)]     # x^k: the rounded products (..(x * x) ..) * x
        for k in range(1, 6):
            powers.append(powers[-1] * s.x)
        for k in range(6):
            assert s.xp[k].tobytes() == powers[k].tobytes()
            # within (k - 1) 2^-53 of the C library's pow, the samplers' allowance
            assert np.all(np.abs(s.xp[k] - clib.power(s.x, k))
                          <= max(k - 1, 0) * 2.0 ** -52 * np.abs(s.xp[k]))
        for c in coeffs:   # the error as the sampler defines it, term by term
            p, mag = np.zeros_like(s.x), np.zeros_like(s.x)
            for k, v in enumerate(c):
                if v:
                    p += v * powers[k]
                    mag += np.abs(v * powers[k])
            want = float(np.max(s.w * (np.abs(p - s.f) - 2.0 ** -50 * (mag + np.abs(s.f)))))
            assert s.errors([c]) == [want] == [s.error(c)]
        for a in (s.x, s.f, s.w, s.xp[3]):
            with pytest.raises(ValueError):
                a[0] = 0.0


def test_quantize_with_shared_grids_gives_the_same_table():
    """A quantization with every shared grid computed afresh and one reusing
    them write the same bytes (fixed point with the greedy refit, a float
    format with the lattice rounds, the parity sub-basis)."""
    from chebnorm.approx import rounding

    cases = [("exp(x)", ("0", "1"), 5, dict(coef_frac_bits=20)),
             ("atan(x)", ("-1", "1"), 7, dict(coef_format="binary32")),
             ("1/sqrt(x)", ("1/4", "1"), 4, dict(coef_format="binary16"))]
    for expr, iv, d, kw in cases:
        base = fit(expr, iv, d, kind="minimax")
        rounding._sample_grid.cache_clear()
        rounding._greedy_nodes.cache_clear()
        cold = quantize(base, **kw)
        warm = quantize(base, **kw)
        assert cold.to_json() == warm.to_json(), expr


def test_to_monomial_is_cheb_to_monomial_bit_for_bit():
    """The greedy refit's conversion (integers over one common denominator) rounds
    the same exact rationals as ``cheb_to_monomial`` (fmpq polynomials): the same
    floats, on awkward intervals (denominators with factors of 3, pi/4 rounded)
    and coefficients from 1e-300 to 1e3 (zeros and signs included)."""
    import random

    import numpy as np

    from chebnorm.approx.fitting import cheb_to_monomial
    from chebnorm.approx.rounding import Problem as _Problem, _to_monomial

    rng = random.Random(41)
    for _ in range(300):
        lo = rng.choice([0.0, 0.25, 1.0, -math.pi / 4, -1.0, -0.125])
        hi = lo + rng.choice([1.0, 0.75, math.pi / 2, 3.0, 0.25])
        n = rng.randint(1, 11)
        cheb = [0.0 if rng.random() < 0.1 else
                rng.uniform(-1, 1) * 10.0 ** rng.randint(-300, 3) for _ in range(n)]
        prob = _Problem(fn=None, lo=sp.Float(lo), hi=sp.Float(hi), lo_f=lo, hi_f=hi,
                        error_kind="abs", degree=n - 1, powers=tuple(range(n)), fixed={},
                        word_limit=None)
        got = _to_monomial(prob, np.array(cheb))
        assert [v.hex() for v in got] == [v.hex() for v in cheb_to_monomial(cheb, lo, hi)]


@pytest.mark.parametrize("expr, lo, hi, degree, quantum", [
    ("log(1+x)", 0.0, 1.0, 8, -24), ("exp(x)", -0.5, 0.5, 6, -20),
    ("1/sqrt(x)", 0.25, 1.0, 5, -12), ("atan(x)", 0.0, 1.0, 9, -28)])
def test_greedy_sums_as_the_plain_loop(expr, lo, hi, degree, quantum):
    """The greedy refit's running sums (``add.accumulate``) give the integers of
    the plain loop: residual ``f - sum(c_j x^j)`` from the highest power down,
    each Chebyshev coefficient a left-to-right sum of products, converted by
    ``cheb_to_monomial``."""
    import numpy as np

    from chebnorm.approx.fitting import cheb_to_monomial
    from chebnorm.approx.rounding import Problem as _Problem, greedy
    from chebnorm.core import clib

    fn = parse_function(expr)
    real = list(fit(expr, (sp.nsimplify(lo), sp.nsimplify(hi)), degree, kind="minimax",
                    basis="monomial").coefficients)
    quanta = [quantum - k for k in range(degree + 1)]
    prob = _Problem(fn=fn, lo=sp.nsimplify(lo), hi=sp.nsimplify(hi), lo_f=lo, hi_f=hi,
                    error_kind="abs", degree=degree, powers=tuple(range(degree + 1)),
                    fixed={}, word_limit=None)
    current, ints = list(real), {}
    for k in range(degree, -1, -1):
        ints[k] = round(math.ldexp(current[k], -quanta[k]))
        if k == 0:
            break
        t = np.polynomial.chebyshev.chebpts1(k)
        x = 0.5 * (lo + hi) + 0.5 * (hi - lo) * t
        resid = np.asarray(fn.numpy(x), dtype=float)
        acc = np.zeros_like(x)
        for j in range(degree, k - 1, -1):
            acc = acc + math.ldexp(ints[j], quanta[j]) * clib.power(x, j)
        resid = resid - acc
        vt = np.polynomial.chebyshev.chebvander(t, k - 1).T
        cheb = np.zeros(k)
        for i in range(k):
            s = vt[i, 0] * resid[0]
            for j in range(1, k):
                s = s + vt[i, j] * resid[j]
            cheb[i] = s
        cheb[0] /= k
        cheb[1:] /= 0.5 * k
        current = cheb_to_monomial(cheb, lo, hi) + [math.ldexp(ints[j], quanta[j])
                                                    for j in range(k, degree + 1)]
    assert greedy(prob, real, quanta) == [ints[k] for k in range(degree + 1)]


def test_power_of_an_array_exponent_is_math_pow_element_by_element():
    """``clib.power`` with an array of exponents (``2^x`` on the sample grids) is
    ``math.pow`` of each pair; where one pair raises (a negative base, an
    overflow) every element still is, and that one numpy's NaN or infinity."""
    import numpy as np

    from chebnorm.core import clib

    x = np.linspace(-3.0, 3.0, 1001)
    assert clib.power(2.0, x).tolist() == [math.pow(2.0, v) for v in x]
    assert clib.power(x, 3.5)[x >= 0].tolist() == [math.pow(v, 3.5) for v in x if v >= 0]
    bases = np.array([2.0, -8.0, 10.0, 0.5])
    exps = np.array([0.5, 1 / 3, 400.0, -3.0])
    got = clib.power(bases, exps)
    assert got[0] == math.pow(2.0, 0.5) and got[3] == math.pow(0.5, -3.0)
    assert math.isnan(got[1]) and got[2] == math.inf


@pytest.mark.parametrize("mantissa, exponent, ok", [
    (3, -2, True), (-5, 7, True), ((1 << 53) - 1, -1075, False), (3, -1075, False),
    ((1 << 52) + 1, -1074, True), (-((1 << 53) - 1), -1076, False), (1, -1074, True),
    ((1 << 53) - 1, -1074, True)])
def test_quantized_coefficient_must_be_a_double(mantissa, exponent, ok):
    """The contract's integer check of ``m * 2^e`` against the double it rounds
    to refuses exactly what the rational (Fraction) comparison refuses."""
    from fractions import Fraction

    from chebnorm.approx import CoefficientTable

    t = quantize(fit("exp(x)", ("0", "1"), 2, kind="minimax"), coef_format="binary64")
    d = t.to_dict()
    d["quantized"]["mantissas"][1], d["quantized"]["exponents"][1] = mantissa, exponent
    c = math.ldexp(mantissa, exponent)
    assert ok == (Fraction(c) == Fraction(mantissa) * Fraction(2) ** exponent)
    if ok:   # exact: refused later (a changed coefficient), never as "not a double"
        with pytest.raises(ValueError) as err:
            CoefficientTable.from_dict(d)
        assert "is not a double" not in str(err.value)
    else:
        with pytest.raises(ValueError, match=r"quantized.mantissas\[1\]: .* is not a double"):
            CoefficientTable.from_dict(d)
