"""Rigorous upper bounds of sup |p - f| and sup |p/f - 1| on an interval.

Method (branch and bound on order-3 Taylor forms in ball arithmetic)
--------------------------------------------------------------------
Let ``g = p - f`` (absolute) or ``g = p/f - 1`` (relative). On a subinterval
``X = [m - r, m + r]`` Taylor's theorem with the Lagrange remainder gives,
for every ``x = m + h`` in ``X``,

    g(x) = g0 + g1 h + g2 h^2 + g3(xi) h^3,   g_k = g^(k)(m)/k!,  xi in X,

so ``|g(x)| <= max_{|h|<=r} |g0 + g1 h + g2 h^2| + sup_X |g3| r^3``. The
point coefficients ``g0, g1, g2`` and an enclosure of ``g3`` over the whole
ball ``X`` come from python-flint's ``arb_series`` (Taylor arithmetic on
Arb balls, every rounding error accounted for); the maximum of the quadratic
is taken exactly (both ends and the vertex, in ball arithmetic). The
polynomial is evaluated with its coefficients as exact binary numbers, so the
bound is for the very float64 coefficients that are stored and exported.

Subintervals are bisected until each upper bound is within ``(1 + tol)`` of
the best lower bound found (the largest ``|g|`` at a point), so the returned
bound is rigorous and at most ``(1 + tol)`` times the true supremum.

Why Arb and not ``mpmath.iv``: Arb propagates rounding errors in C with
arbitrary precision and has Taylor-series arithmetic (``arb_series``) built
in, which is what makes the Taylor form -- and so a bound within a fraction
of a percent of the supremum -- cheap; ``mpmath.iv`` is pure Python, has no
series type, and its naive interval evaluation of ``p - f`` overestimates by
``|p'| + |f'|`` times the width, which would need millions of subintervals.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import sympy as sp
from flint import arb, arb_series, ctx

from .expr import Function1D, _arb_const

__all__ = ["Certificate", "certify", "arb_enclose"]

#: default relative tightness of certified bounds: bound <= (1 + TOL) * sup.
TOL = 2.0 ** -8


@dataclass(frozen=True)
class Certificate:
    """A certified bound and the located maximum it was compared with.

    ``bound`` is a float rounded upward: ``sup |g| <= bound``. ``maximum`` is
    ``|g(at)|`` at a located point (a lower bound of the supremum), so
    ``maximum <= sup |g| <= bound``. ``subintervals`` counts the Taylor forms
    evaluated.
    """

    bound: float
    maximum: float
    at: float
    subintervals: int


def arb_enclose(value: sp.Expr) -> arb:
    """A ball enclosing a real sympy constant (``sqrt(2)``, ``2*cos(pi/4)``)."""
    from .expr import _compile_arb

    dummy = sp.Symbol("_unused")
    if value.is_Number or value in (sp.pi, sp.E):
        return _arb_const(value)
    return _compile_arb(value, dummy, series=False)(arb(0))


def _float_up(x: arb) -> float:
    """The smallest float >= every point of the ball ``x``."""
    u = x.upper()
    f = float(u)
    while arb(f) < u:
        f = math.nextafter(f, math.inf)
    return f


def _float_down(x: arb) -> float:
    lo = x.lower()
    f = float(lo)
    while arb(f) > lo:
        f = math.nextafter(f, -math.inf)
    return f


def _coeffs(series: arb_series, n: int) -> list[arb]:
    """The first ``n`` Taylor coefficients (flint drops trailing zeros)."""
    c = series.coeffs()
    return (c + [arb(0)] * n)[:n]


def _horner(coeffs: Sequence[arb], x):
    acc = coeffs[-1] + 0 * x if len(coeffs) else 0 * x
    for c in reversed(coeffs[:-1]):
        acc = acc * x + c
    return acc


def _error_function(fn: Function1D, coeffs: Sequence[arb], kind: str):
    f = fn.arb_series

    if kind == "abs":
        def g(s):
            return _horner(coeffs, s) - f(s)
    elif kind == "rel":
        def g(s):
            return _horner(coeffs, s) / f(s) - 1
    else:
        raise ValueError(f"error kind {kind!r} is not one of 'abs', 'rel'")

    def safe(s):
        # Arb refuses to divide by a ball that contains 0: report "not finite"
        try:
            return g(s)
        except (ValueError, ZeroDivisionError):
            return arb_series([arb("nan")] * s.prec, prec=s.prec)
    return safe


def _quadratic_max(c0: arb, c1: arb, c2: arb, r: arb) -> arb:
    """An upper bound of max_{|h| <= r} |c0 + c1 h + c2 h^2| (balls allowed)."""
    ends = [abs(c0 - c1 * r + c2 * r * r), abs(c0 + c1 * r + c2 * r * r)]
    best = ends[0].upper().max(ends[1].upper())
    box = arb(0, r.upper())
    if c2.contains(0):
        inner = abs(c0 + c1 * box + c2 * (box * box))
        return best.max(inner.upper())
    hstar = -c1 / (2 * c2)
    if hstar.overlaps(box):
        h = hstar.intersection(box)
        inner = abs(c0 + c1 * h + c2 * (h * h))
        best = best.max(inner.upper())
    return best


def certify(fn: Function1D, coefficients: Sequence[float], lo: sp.Expr, hi: sp.Expr,
            kind: str = "abs", tol: float = TOL, max_subintervals: int = 200_000,
            prec: int | None = None) -> Certificate:
    """Certify ``sup_{x in [lo, hi]} |g(x)|`` for ``g = p - f`` or ``p/f - 1``.

    ``coefficients`` are the polynomial's float coefficients in ascending
    powers of ``x``; ``lo`` and ``hi`` are exact sympy constants. Raises
    ValueError when ``g`` is not finite somewhere on the interval (``f`` is
    undefined, infinite, or -- for ``kind="rel"`` -- zero there).

    >>> from chebnorm.approx.expr import parse_function
    >>> import sympy as sp
    >>> c = certify(parse_function("x**2"), [0.0, 0.0, 1.0], sp.Integer(0), sp.Integer(1))
    >>> c.bound == 0.0
    True
    """
    old_prec = ctx.prec
    try:
        ctx.prec = prec or 128
        return _certify(fn, [arb(float(c)) for c in coefficients], lo, hi, kind, tol,
                        max_subintervals)
    finally:
        ctx.prec = old_prec


def _certify(fn, coeffs, lo, hi, kind, tol, max_subintervals) -> Certificate:
    g = _error_function(fn, coeffs, kind)
    lo_b, hi_b = arb_enclose(lo), arb_enclose(hi)
    a0, b0 = lo_b.lower(), hi_b.upper()
    degree = max(len(coeffs) - 1, 0)
    pieces = 2 * (degree + 2)
    edges = [a0 + (b0 - a0) * arb(k) / pieces for k in range(pieces + 1)]
    # exact binary split points (the outer two keep the enclosing endpoints)
    edges = [a0] + [arb(float(e.mid())) for e in edges[1:-1]] + [b0]
    work = list(zip(edges[:-1], edges[1:]))
    min_width = (b0 - a0) * arb(2) ** -60

    best_lower = arb(0)
    best_at = float(a0.mid())
    accepted_upper = arb(0)
    count = 0
    # (upper, a, b) of subintervals bounded above more loosely than the target
    pending: list[tuple[arb, arb, arb]] = []
    while work or pending:
        for a, b in work:
            count += 1
            m = (a + b) / 2
            r = (b - a) / 2
            sm = g(arb_series([m, 1], prec=3))
            c0, c1, c2 = _coeffs(sm, 3)
            sx = g(arb_series([a.union(b), 1], prec=4))
            c3 = _coeffs(sx, 4)[3]
            upper = _quadratic_max(c0, c1, c2, r) + abs(c3).upper() * (r * r * r)
            if not upper.is_finite():
                if (b - a) < min_width or count > max_subintervals:
                    where = float(m.mid())
                    what = "p/f - 1 (f is zero or undefined there)" if kind == "rel" else "f"
                    raise ValueError(f"{what} is not finite and real near x = {where:.17g}; "
                                     f"accepted: a function defined and finite on the whole interval")
                pending.append((arb("inf"), a, b))
                continue
            if c0.is_finite():
                low = abs(c0).lower()
                if low > best_lower:
                    best_lower, best_at = low, float(m.mid())
            pending.append((upper.upper(), a, b))
        work = []
        target = best_lower * (1 + arb(tol))
        keep = []
        for upper, a, b in pending:
            if upper.is_finite() and (upper <= target or (b - a) < min_width
                                       or count > max_subintervals):
                accepted_upper = accepted_upper.max(upper)
            else:
                keep.append((upper, a, b))
        pending = []
        for _, a, b in keep:
            m = arb(float(((a + b) / 2).mid()))
            if not (a < m < b):
                m = (a + b) / 2
            work.extend([(a, m), (m, b)])
    lo_f, hi_f = _float_up(lo_b), _float_down(hi_b)
    for end in (lo_f, hi_f):  # the endpoints are often where the error peaks
        v = abs(_coeffs(g(arb_series([arb(end), 1], prec=1)), 1)[0])
        if v.is_finite() and v.lower() > best_lower:
            best_lower, best_at = v.lower(), end
    maximum, at = _refine_maximum(g, best_lower, best_at, lo_f, hi_f)
    bound = accepted_upper.max(arb(maximum))
    return Certificate(bound=_float_up(bound), maximum=maximum, at=at, subintervals=count)


def _refine_maximum(g, lower: arb, at: float, lo: float, hi: float) -> tuple[float, float]:
    """Newton steps on g' from the best point found, to locate the extremum."""
    best, best_at = float(lower), at
    x = at
    for _ in range(8):
        s = _coeffs(g(arb_series([arb(x), 1], prec=3)), 3)
        v = abs(s[0])
        if v.is_finite() and float(v.mid()) > best:
            best, best_at = float(v.mid()), x
        if s[2].contains(0) or not s[2].is_finite():
            break
        step = float((-s[1] / (2 * s[2])).mid())
        nxt = min(max(x + step, lo), hi)
        if nxt == x:
            break
        x = nxt
    return best, best_at


def dense_maximum(fn: Function1D, coefficients: Sequence[float], lo: float, hi: float,
                  kind: str = "abs", points: int = 20001) -> tuple[float, float]:
    """Float64 estimate of max |g| on a dense grid (for checks, not a bound)."""
    x = np.linspace(lo, hi, points)
    p = np.polynomial.polynomial.polyval(x, coefficients)
    f = fn.numpy(x)
    e = p - f if kind == "abs" else p / f - 1
    i = int(np.argmax(np.abs(e)))
    return float(abs(e[i])), float(x[i])
