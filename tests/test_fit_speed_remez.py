"""The vectorized Remez exchange and the faster certifier (issue 16), checked
against independent computations: mpmath at 40 digits on a dense grid with
each extremum refined by a root finder (the fit is minimax to the exchange's
convergence criterion; the certificate is at least the supremum and within
its tightness), exact rationals (``fractions``) for the basis change, mpmath's
own LU solve for the polish, and dense high-precision sampling for the exact
maximum of a cubic. No timings: ``benchmarks/bench_fit.py`` measures those.
"""

from __future__ import annotations

import math
import random
from fractions import Fraction

import mpmath
import numpy as np
import pytest
from flint import arb, ctx

from benchmarks.bench_fit import WORKLOAD
from chebnorm.approx import parse_function, parse_number
from chebnorm.approx.certify import _cubic_max, certify
from chebnorm.approx.fitting import (_peaks, _sign_runs, cheb_to_monomial, polish, remez)

EPS = np.finfo(float).eps
#: the exchange's default convergence criterion: (largest - levelled) <= RTOL * largest
RTOL = 1e-8


def _error(fn, coeffs, x):
    """p(x) - f(x) in the current mpmath precision, coefficients exact."""
    return mpmath.polyval([mpmath.mpf(c) for c in reversed(coeffs)], x) - fn.mpmath(x)


def _sup(fn, coeffs, lo: float, hi: float, n: int = 2001) -> mpmath.mpf:
    """sup |p - f| at 40 digits: a dense grid, every interior grid maximum of
    |e| refined by the secant method on e' (mpmath's numerical derivative),
    and both ends."""
    with mpmath.workdps(40):
        lo_m, hi_m = mpmath.mpf(lo), mpmath.mpf(hi)
        xs = [lo_m + (hi_m - lo_m) * k / (n - 1) for k in range(n)]
        a = [abs(_error(fn, coeffs, x)) for x in xs]
        best = max(a[0], a[-1])
        de = lambda x: mpmath.diff(lambda y: _error(fn, coeffs, y), x)
        for k in range(1, n - 1):
            if a[k] >= a[k - 1] and a[k] >= a[k + 1]:
                try:
                    r = mpmath.findroot(de, (xs[k - 1], xs[k + 1]), solver="secant")
                except (ValueError, ZeroDivisionError):
                    r = xs[k]
                r = min(max(r, xs[k - 1]), xs[k + 1])
                best = max(best, a[k], abs(_error(fn, coeffs, r)))
        return best


def _rounding(cheb, coeffs, lo: float, hi: float) -> float:
    """A bound of |p_float - p_exact| on [lo, hi]: each monomial coefficient
    is the exact one rounded to nearest (half an ulp) times max |x|^k."""
    xmax = max(abs(lo), abs(hi))
    return sum(0.5 * np.spacing(abs(c)) * xmax ** k for k, c in enumerate(coeffs))


@pytest.mark.slow
@pytest.mark.parametrize("case", range(len(WORKLOAD)), ids=lambda k: f"{WORKLOAD[k]}")
def test_fit_is_minimax_to_the_criterion(case):
    """de la Vallee Poussin: the smallest alternating error at the reference
    is a lower bound of the minimax error E*, the supremum an upper bound,
    so sup - min <= (criterion) bounds the distance to the true minimax.
    The criterion: RTOL of the float64 exchange, plus the monomial
    coefficients' rounding (twice: it moves both ends), plus float64's
    resolution of the errors the exchange compared (a few ulps of |f|)."""
    expr, (lo, hi), d = WORKLOAD[case]
    fn = parse_function(expr)
    lo_f, hi_f = float(parse_number(lo)), float(parse_number(hi))
    res = remez(fn.numpy, None, lo_f, hi_f, d)
    assert res.converged and not res.noise_limited and len(res.ref) == d + 2
    coeffs = cheb_to_monomial(res.cheb, lo_f, hi_f)
    with mpmath.workdps(40):
        xs = [mpmath.mpf((hi_f - lo_f) / 2) * mpmath.mpf(float(u)) + mpmath.mpf((hi_f + lo_f) / 2)
              for u in res.ref]
        errs = [_error(fn, coeffs, x) for x in xs]
    assert all(a * b < 0 for a, b in zip(errs, errs[1:])), "the reference alternates"
    low = min(abs(e) for e in errs)
    sup = _sup(fn, coeffs, lo_f, hi_f)
    fmax = max(abs(float(fn.mpmath(mpmath.mpf(x)))) for x in np.linspace(lo_f, hi_f, 101))
    slack = RTOL * float(sup) + 2 * _rounding(res.cheb, coeffs, lo_f, hi_f) + 16 * EPS * fmax
    assert float(sup - low) <= slack
    # the exchange's own figures are those of the polynomial to the same slack
    assert abs(res.max_error - float(sup)) <= slack


@pytest.mark.slow
@pytest.mark.parametrize("tight", [2.0 ** -8, 2.0 ** -20])
def test_certificates_bound_the_dense_supremum(tight):
    """The benchmark's certificates: never below the supremum found by the
    dense 40-digit search, and within their tightness of the located
    maximum (itself never above that supremum)."""
    for expr, (lo, hi), d in WORKLOAD:
        fn = parse_function(expr)
        lo_x, hi_x = parse_number(lo), parse_number(hi)
        lo_f, hi_f = float(lo_x), float(hi_x)
        coeffs = cheb_to_monomial(remez(fn.numpy, None, lo_f, hi_f, d).cheb, lo_f, hi_f)
        c = certify(fn, coeffs, lo_x, hi_x, "abs", tol=tight)
        sup = float(_sup(fn, coeffs, lo_f, hi_f, n=401))
        assert sup <= c.bound, (expr, d)
        assert c.maximum <= sup * (1 + 1e-12), (expr, d)
        assert c.tight and c.bound <= (1 + tight) * c.maximum, (expr, d)


def _monomial_by_fractions(cheb, lo, hi, center=0.0, scale=1.0):
    """The basis change written out in Python's exact rationals: T_k by the
    recurrence, then u = (2 (center + scale t) - lo - hi)/(hi - lo)."""
    n = len(cheb)
    polys = [[Fraction(1)], [Fraction(0), Fraction(1)]]
    while len(polys) < n:
        a, b = polys[-1], polys[-2]
        c = [Fraction(0)] + [2 * v for v in a]
        for i, v in enumerate(b):
            c[i] -= v
        polys.append(c)
    in_u = [Fraction(0)] * n
    for k, ck in enumerate(cheb):
        if isinstance(ck, mpmath.mpf):
            sign, man, exp, _ = ck._mpf_
            ck = (-1) ** sign * Fraction(int(man)) * Fraction(2) ** int(exp)
        else:
            ck = Fraction(float(ck))
        for i, v in enumerate(polys[k]):
            in_u[i] += ck * v
    lo, hi, center, scale = (Fraction(float(v)) for v in (lo, hi, center, scale))
    alpha, beta = 2 * scale / (hi - lo), (2 * center - lo - hi) / (hi - lo)
    out = [Fraction(0)] * n
    for i in range(n):  # u^i = (alpha t + beta)^i by the binomial theorem
        for j in range(i + 1):
            out[j] += in_u[i] * math.comb(i, j) * alpha ** j * beta ** (i - j)
    return [float(v) for v in out]


def test_basis_change_matches_exact_rationals():
    rng = random.Random(16)
    for trial in range(300):
        n = rng.randint(1, 31)
        cheb = [rng.uniform(-1, 1) * 10.0 ** rng.randint(-20, 2) for _ in range(n)]
        if trial % 3 == 0:
            with mpmath.workdps(50):
                cheb = [mpmath.mpf(c) / 3 for c in cheb]
        lo = rng.uniform(-5, 5)
        hi = lo + rng.choice([1e-6, 0.5, 1.0, 3.0, 1e3]) * rng.random() + 1e-9
        shift = () if trial % 2 else (0.5 * lo + 0.5 * hi, 2.0 ** rng.randint(-3, 3))
        assert cheb_to_monomial(cheb, lo, hi, *shift) == _monomial_by_fractions(cheb, lo, hi, *shift)


@pytest.mark.parametrize("expr,interval,degree,relative",
                         [("exp(x)", (0.0, 1.0), 20, False), ("atan(x)", (0.0, 1.0), 25, False),
                          ("1/sqrt(x)", (0.5, 2.0), 6, True)])
def test_polish_solves_the_levelled_system(expr, interval, degree, relative):
    """The Arb solve against mpmath's LU at 60 digits: the same solution to
    the 50 digits asked for (relative to the largest coefficient)."""
    fn = parse_function(expr)
    lo, hi = interval
    res = remez(fn.numpy, None, lo, hi, degree)
    ours = polish(fn.mpmath, lo, hi, res.ref, degree, relative=relative)
    with mpmath.workdps(60):
        rows, rhs = [], []
        for i, u in enumerate(res.ref):
            u = mpmath.mpf(float(u))
            fx = fn.mpmath((mpmath.mpf(hi) - lo) / 2 * u + (mpmath.mpf(hi) + lo) / 2)
            rows.append([mpmath.chebyt(k, u) for k in range(degree + 1)]
                        + [(-1) ** i * (abs(fx) if relative else 1)])
            rhs.append(fx)
        theirs = mpmath.lu_solve(mpmath.matrix(rows), mpmath.matrix(rhs))
        scale = max(abs(theirs[k]) for k in range(degree + 1))
        assert max(abs(ours[k] - theirs[k]) for k in range(degree + 1)) <= scale * mpmath.mpf(10) ** -45


def test_cubic_max_is_an_exact_upper_bound():
    """Against dense 60-digit sampling plus the critical points solved by
    mpmath: never below the maximum, and above it by no more than the balls'
    own radii (the bound is exact for exact coefficients)."""
    rng = random.Random(3)
    old = ctx.prec
    ctx.prec = 128
    try:
        for trial in range(300):
            c = [rng.uniform(-1, 1) * 10.0 ** rng.randint(-6, 1) for _ in range(4)]
            if trial % 5 == 0:
                c[3] = 0.0  # a quadratic
            if trial % 7 == 0:
                c[2] = 0.0
            if trial % 11 == 0:  # a double critical point: discriminant 0
                c[1] = c[2] ** 2 / (3 * c[3]) if c[3] else c[1]
            r = rng.choice([1e-3, 0.1, 1.0, 3.0])
            got = _cubic_max(*(arb(v) for v in c), arb(r))
            assert got.is_finite()
            with mpmath.workdps(60):
                cm = [mpmath.mpf(v) for v in c]
                p = lambda h: cm[0] + h * (cm[1] + h * (cm[2] + h * cm[3]))
                pts = [mpmath.mpf(r) * (2 * k / 200 - 1) for k in range(201)]
                disc = cm[2] ** 2 - 3 * cm[1] * cm[3]
                if cm[3] != 0 and disc >= 0:  # p' = 3 c3 h^2 + 2 c2 h + c1
                    pts += [h for h in ((-cm[2] + s * mpmath.sqrt(disc)) / (3 * cm[3])
                                        for s in (1, -1)) if abs(h) <= r]
                elif cm[2] != 0 and abs(cm[1] / (2 * cm[2])) <= r:
                    pts.append(-cm[1] / (2 * cm[2]))
                true = max(abs(p(h)) for h in pts)
                man, exp = got.upper().man_exp()  # the upper end, exactly
                upper = mpmath.mpf((int(man), int(exp)))
                assert true <= upper
                assert upper <= true * (1 + mpmath.mpf(2) ** -100)
    finally:
        ctx.prec = old


def test_peaks_locate_maxima_between_grid_points():
    """Errors shaped like the exchange's (cosines in theta): the located
    point is within O(h^4) of the true one, ends stay put exactly."""
    rng = np.random.default_rng(5)
    theta = np.pi * np.arange(4000, -1, -1) / 4000
    h = np.pi / 4000
    for _ in range(50):
        k = rng.integers(2, 30)
        shift = rng.uniform(0, np.pi / k)
        e = rng.uniform(1e-8, 1) * np.cos(k * (theta - shift))
        idx = np.array(_sign_runs(e)[0])
        u = np.array(_peaks(e, idx.tolist()))
        located = theta[idx] - u * h
        inner = (idx > 0) & (idx < 4000)
        true = shift + np.round((located - shift) * k / np.pi) * np.pi / k
        assert np.max(np.abs(located - true)[inner]) < 1e-9
        assert np.all(u[~inner] == 0)


def test_sign_runs_vectorized_path_matches_the_loop():
    rng = np.random.default_rng(9)
    for size in (10, 100, 4001):
        e = rng.normal(size=size)
        e[rng.integers(0, size, size // 10)] = 0.0
        pos = e >= 0
        want, start = [], 0
        for i in range(1, size + 1):
            if i == size or pos[i] != pos[start]:
                want.append(start + int(np.argmax(np.abs(e[start:i]))))
                start = i
        assert _sign_runs(e)[0] == want
