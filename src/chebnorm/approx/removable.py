"""Removable singularities: ``f = N/D`` where ``N`` and ``D`` vanish together.

``sin(x)/x``, ``(exp(x) - 1)/x``, ``log(1 + x)/x``, ``(1 - cos(x))/x^2``,
``x/sin(x)`` are 0/0 at ``x = 0`` but extend to analytic functions there.
This module gives :class:`~chebnorm.approx.expr.Function1D` evaluators of
that extension, rigorous in ball arithmetic; nothing is sampled.

The point and its order (proved symbolically)
---------------------------------------------
``f`` is written ``N/D`` (``sympy.together``, then ``sympy.fraction``). The
candidate points are the real zeros of ``D`` (``sympy.solveset``; for a
periodic ``D`` such as ``sin(x)``, those in a window ``[-W, W]`` around the
evaluated balls). A zero ``x0`` is *removable* when, for some ``k >= 1``,

* ``D(x0) = D'(x0) = ... = D^(k-1)(x0) = 0`` and ``N^(i)(x0) = 0`` for
  ``i < k``, each proved by sympy reducing the derivative at ``x0`` to the
  exact integer 0 (``simplify``; anything it cannot reduce is not taken as
  zero), and
* ``D^(k)(x0) / k!`` is enclosed by an Arb ball that excludes 0.

A true pole (``1/x``: ``N(0) = 1``) is not removable and is still refused
where it was before.

The enclosure near the point (Taylor's theorem, integral remainder)
-------------------------------------------------------------------
With ``h = x - x0`` and ``N`` vanishing to order ``k`` at ``x0``,
``Ñ(x) = N(x)/h^k = int_0^1 N^(k)(x0 + t h) (1 - t)^(k-1)/(k-1)! dt``, and
differentiating under the integral,

    Ñ^(j)(x)/j! = int_0^1 [N^(k+j)(x0 + t h)/(k+j)!] w_j(t) dt,
    w_j(t) = t^j (1 - t)^(k-1) (k+j)! / (j! (k-1)!),

a weighted mean (``w_j >= 0``, ``int w_j = 1``, a Beta density) of
``N^(k+j)/(k+j)!`` over the segment ``[x0, x]``. So for every ``x`` of a
ball ``B``, the ``j``-th Taylor coefficient of ``Ñ`` at ``x`` lies in the
``(k+j)``-th Taylor coefficient of ``N`` enclosed by Arb's ``arb_series``
over the hull of ``B`` and ``x0`` (an interval is convex). Likewise ``D̃ =
D/h^k``; ``f = Ñ/D̃`` off ``x0`` and, by continuity, at ``x0``. The series
quotient of these enclosures (ball arithmetic on enclosures of the exact
Taylor coefficients) encloses the Taylor coefficients of ``f`` at every
point of ``B``. Where ``D̃`` is not proved nonzero on the hull (another zero
of ``D`` nearby) the result is NaN, and callers bisect.

Where the plain evaluation of ``N/D`` is finite too (a ball near, but not
containing, ``x0``), both enclosures hold and their intersection is
returned. Point values near ``x0`` (the float64 and mpmath evaluators) use
the Taylor polynomial at ``x0`` with Lagrange's remainder enclosed over the
segment, which avoids the cancellation of ``N/D`` there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import sympy as sp
from flint import arb, arb_series, ctx

from chebnorm.core.numeric import arb_precision

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

#: highest order of a common zero that is looked for
MAX_ORDER = 8
#: most zeros of the denominator examined in one window, and their largest size
MAX_POINTS, MAX_OPS = 16, 40
#: terms of the Taylor polynomial at x0 used for point values
POINT_TERMS = 40
#: a ball closer than this (relative to max(1, |x0|)) to x0 is also evaluated
#: by the Taylor enclosure, and the two enclosures intersected
NEAR = 2.0 ** -12


def _is_exact_zero(value: sp.Expr) -> bool:
    """True only when sympy reduces ``value`` to the integer 0."""
    if value == 0:
        return True
    if value.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
        return False
    try:
        return sp.simplify(value) == 0
    except Exception:  # noqa: BLE001 -- sympy failing to decide is "not proved"
        return False


@dataclass
class _Point:
    """A proved removable point ``x0`` where ``N`` and ``D`` vanish to order ``k``."""

    x0: sp.Expr
    k: int
    x0_float: float
    constant: Callable  # x0 as a ball at the working precision
    cache: dict = field(default_factory=dict)

    def ball(self) -> arb:
        key = ("ball", ctx.prec)
        b = self.cache.get(key)
        if b is None:
            b = self.cache[key] = self.constant(arb(0))
        return b


class Removable:
    """The removable points of ``expr = N/D`` and rigorous evaluators around them.

    Internal: built by :func:`analyse`, used by
    :class:`~chebnorm.approx.expr.Function1D`.

    Parameters
    ----------
    expr : sympy.Expr
        The function.
    var : sympy.Symbol
        Its variable.
    num, den : sympy.Expr
        ``expr == num/den``, ``den`` depending on ``var``.
    compile_arb : callable
        :func:`chebnorm.approx.expr.compile_arb`.
    enclose : callable
        :func:`chebnorm.approx.expr.enclose`.
    """

    def __init__(self, expr: sp.Expr, var: sp.Symbol, num: sp.Expr, den: sp.Expr,
                 compile_arb: Callable, enclose: Callable):
        self.compile_arb, self.enclose = compile_arb, enclose
        self.expr, self.var, self.num, self.den = expr, var, num, den
        self.num_series = compile_arb(num, var, series=True)
        self.den_series = compile_arb(den, var, series=True)
        self._global: tuple[_Point, ...] | None = None
        self._windows: dict[int, tuple[_Point, ...]] = {}
        self._proved: dict[sp.Expr, _Point | None] = {}

    # ------------------------------------------------------------ the points
    def _prove(self, x0: sp.Expr) -> _Point | None:
        if x0 in self._proved:
            return self._proved[x0]
        enclose = self.enclose
        point = None
        ball = enclose(x0, 128)
        if ball is not None and abs(ball) < arb(2) ** 1000:
            x, num, den = self.var, self.num, self.den
            for k in range(MAX_ORDER + 1):
                dk = den.subs(x, x0) if k == 0 else sp.diff(den, x, k).subs(x, x0)
                if _is_exact_zero(dk):
                    nk = num.subs(x, x0) if k == 0 else sp.diff(num, x, k).subs(x, x0)
                    if not _is_exact_zero(nk):
                        break  # a pole (or undecided): not removable
                    continue
                d_ball = enclose(dk, 128)
                if k >= 1 and d_ball is not None and not d_ball.contains(0):
                    point = _Point(x0, k, float(ball.mid()),
                                   self.compile_arb(x0, sp.Dummy(), series=False))
                break
        self._proved[x0] = point
        return point

    def _solve(self, domain) -> tuple[list[sp.Expr], bool]:
        """Real zeros of ``den`` in ``domain``; ``(zeros, complete)``. A polynomial
        ``den``: the real roots of its linear and quadratic factors (a common zero
        of higher algebraic degree is not looked for)."""
        if self.den.is_polynomial(self.var):
            try:
                _, factors = sp.factor_list(self.den, self.var)
            except Exception:  # noqa: BLE001
                return [], True
            zeros = []
            for fac, _ in factors:
                if sp.degree(fac, self.var) <= 2:
                    zeros += [z for z in sp.roots(fac, self.var, filter="R")
                              if domain.contains(z) is sp.true]
            return zeros[:MAX_POINTS], True
        try:
            sol = sp.solveset(self.den, self.var, domain)
        except Exception:  # noqa: BLE001 -- sympy gives up: no point is proved
            return [], False
        if sol is sp.S.EmptySet:
            return [], True
        if isinstance(sol, sp.FiniteSet):
            # a root sympy cannot write in closed form (CRootOf) or a large radical
            # is not tried: proving N zero there is out of simplify's reach
            return [z for z in list(sol)[:MAX_POINTS] if z.is_real is not False
                    and not z.free_symbols and not z.has(sp.CRootOf)
                    and sp.count_ops(z) <= MAX_OPS], True
        return [], False

    def points(self, lo: float, hi: float) -> tuple[_Point, ...]:
        """The proved removable points in ``[lo, hi]`` (floats, a slight margin)."""
        if self._global is None:
            zeros, complete = self._solve(sp.S.Reals)
            self._global = tuple(p for p in map(self._prove, zeros) if p) if complete else ()
            self._complete = complete
        if self._complete:
            cands = self._global
        else:
            top = max(abs(lo), abs(hi), 1.0)
            if not math.isfinite(top):
                return ()
            e = math.frexp(top)[1]
            cands = self._windows.get(e)
            if cands is None:
                w = sp.Integer(2) ** e
                zeros, _ = self._solve(sp.Interval(-w, w))
                cands = self._windows[e] = tuple(p for p in map(self._prove, zeros) if p)
        margin = NEAR
        return tuple(p for p in cands
                     if lo - margin * max(1.0, abs(p.x0_float)) <= p.x0_float
                     <= hi + margin * max(1.0, abs(p.x0_float)))

    @property
    def any_points(self) -> bool:
        """Whether some removable point may exist (False: plain evaluation only)."""
        self.points(0.0, 0.0)
        return bool(self._global) or not self._complete

    # --------------------------------------------------- Taylor enclosures
    def taylor(self, point: _Point, ball: arb, n: int) -> list[arb] | None:
        """Enclosures of the first ``n`` Taylor coefficients of ``f`` valid at
        every point of ``ball`` (None where the quotient is not proved finite)."""
        k = point.k
        hull = ball.union(point.ball())
        old_cap = ctx.cap
        ctx.cap = max(old_cap, k + n + 1)  # python-flint truncates series at ctx.cap terms
        try:
            s = arb_series([hull, 1], prec=k + n)
            ns, ds = self.num_series(s), self.den_series(s)
            if any(isinstance(t, arb_series) and t.prec < k + n for t in (ns, ds)):
                return None  # truncated: a missing coefficient is not a zero
            nc = _coeffs(ns, k + n)[k:]
            dc = _coeffs(ds, k + n)[k:]
            q = arb_series(nc, prec=n) / arb_series(dc, prec=n)
        except (ValueError, ZeroDivisionError):
            return None
        finally:
            ctx.cap = old_cap
        out = _coeffs(q, n)
        return out if all(c.is_finite() for c in out) else None

    def at_point(self, point: _Point, n: int) -> list[arb] | None:
        """The first ``n`` Taylor coefficients of ``f`` at ``x0`` itself (cached)."""
        key = ("coef", ctx.prec, n)
        c = point.cache.get(key)
        if c is None:
            c = point.cache[key] = self.taylor(point, point.ball(), n)
        return c

    def value_near(self, point: _Point, y: arb, terms: int) -> arb | None:
        """``f(y)`` for ``y`` near ``x0``: the Taylor polynomial of ``f`` at ``x0``
        of ``terms`` terms plus Lagrange's remainder, enclosed over ``[x0, y]``."""
        c = self.at_point(point, terms)
        rest = self.taylor(point, y, terms + 1)
        if c is None or rest is None:
            return None
        h = y - point.ball()
        acc = rest[terms]
        for coef in reversed(c):
            acc = acc * h + coef
        return acc

    # ----------------------------------------------------------- evaluators
    def wrap_arb(self, plain: Callable) -> Callable:
        def value(v):
            if isinstance(v, arb_series):
                return self._series(plain, v)
            return self._plain(plain, v)
        return value

    def _near(self, c0: arb) -> tuple[_Point, bool] | None:
        if not c0.is_finite():
            return None
        lo, hi = float(c0.lower()), float(c0.upper())
        pts = self.points(lo, hi)
        if not pts:
            return None
        p = min(pts, key=lambda q: abs(q.x0_float - 0.5 * (lo + hi)))
        return p, c0.overlaps(p.ball())

    def _plain(self, plain: Callable, v):
        try:
            direct = plain(v)
        except (ValueError, ZeroDivisionError):
            direct = None
        if not isinstance(v, arb):
            return direct if direct is not None else plain(v)
        near = self._near(v)
        if near is None:
            if direct is None:
                return plain(v)
            return direct
        point, inside = near
        ok = direct is not None and direct.is_finite()
        if inside or v.rad() > 0:
            t = self.taylor(point, v, 1)
            t = None if t is None else t[0]
        else:  # a narrow ball near x0: Taylor polynomial at x0 with remainder
            terms = max(4, min(POINT_TERMS * 2, ctx.prec // 4))
            t = self.value_near(point, v, terms)
        if t is None or not t.is_finite():
            return direct if ok else arb("nan")
        return _meet(direct, t) if ok else t

    def _series(self, plain: Callable, s: arb_series):
        n = s.prec
        c = s.coeffs()
        c0 = c[0] if c else arb(0)
        try:
            direct = plain(s)
        except (ValueError, ZeroDivisionError):
            direct = None
        ok = direct is not None and all(x.is_finite() for x in _coeffs(direct, n))
        near = self._near(c0)
        if near is None:
            return direct if direct is not None else arb_series([arb("nan")] * n, prec=n)
        point, inside = near
        t = self.taylor(point, c0, n)
        if t is None:
            return direct if ok else arb_series([arb("nan")] * n, prec=n)
        rest = (c + [arb(0)] * n)[1:n]
        if not rest or (rest[0] == 1 and all(r == 0 for r in rest[1:])):
            out = arb_series(t, prec=n)
        else:  # f(c0 + u) = sum F_j u^j, u = s - c0 with no constant term
            u = arb_series([arb(0)] + rest, prec=n)
            out = arb_series([t[-1]], prec=n)
            for coef in reversed(t[:-1]):
                out = out * u + coef
        if not ok:
            return out
        a, b = _coeffs(direct, n), _coeffs(out, n)
        return arb_series([_meet(x, y) for x, y in zip(a, b)], prec=n)

    def wrap_mpmath(self, plain: Callable, arb_value: Callable) -> Callable:
        import mpmath

        def value(x):
            if isinstance(x, (mpmath.mpf, int, float)) and not isinstance(x, bool):
                xf = float(x)
                pts = self.points(xf, xf) if math.isfinite(xf) else ()
                if pts:
                    return self._mp_value(mpmath.mpf(x), arb_value)
            try:
                return plain(x)
            except ZeroDivisionError:
                if isinstance(x, (mpmath.mpf, int, float)):
                    return self._mp_value(mpmath.mpf(x), arb_value)
                raise
        return value

    def _mp_value(self, x, arb_value: Callable):
        import mpmath

        sign, man, exp, _ = x._mpf_ if x != 0 else (0, 0, 0, 0)
        xa = arb(-int(man) if sign else int(man)) * arb(2) ** int(exp) if man else arb(0)
        prec = mpmath.mp.prec + 64
        while prec <= 8 * (mpmath.mp.prec + 64):
            with arb_precision(prec):
                v = arb_value(xa)
                if v.is_finite() and (v.rad() == 0 or v.rad() < abs(v.mid()) * arb(2) ** -(
                        mpmath.mp.prec + 8) or abs(v).upper() < arb(2) ** -(mpmath.mp.prec + 8)):
                    m, e = v.mid().man_exp()
                    return mpmath.mpf((int(m), int(e)))
            prec *= 2
        raise ValueError(f"{self.expr} could not be evaluated at {self.var} = {x}")

    def wrap_numpy(self, plain: Callable, arb_value: Callable) -> Callable:
        def value(x):
            x = np.asarray(x, dtype=float)
            shape = x.shape
            flat_x = np.array(x.reshape(-1))
            with np.errstate(all="ignore"):
                flat_y = np.array(plain(flat_x), dtype=float) * np.ones_like(flat_x)
            y = flat_y.reshape(shape)  # a view: the corrections below show in it
            fin = flat_x[np.isfinite(flat_x)]
            if fin.size == 0:
                return y
            for p in self.points(float(fin.min()), float(fin.max())):
                radius, poly = self._float_taylor(p, arb_value)
                scale = max(1.0, abs(p.x0_float))
                h = flat_x - p.x0_float
                close = np.abs(h) <= radius * scale
                if poly is not None and close.any():
                    flat_y[close] = np.polynomial.polynomial.polyval(h[close], poly)
                # anything else still not finite near x0, or too near for float64
                slow = (~close & (np.abs(h) <= 2.0 ** -4 * scale)) if poly is None else (
                    ~np.isfinite(flat_y) & (np.abs(h) <= 2.0 ** -4 * scale))
                for i in np.flatnonzero(slow):
                    with arb_precision(128):
                        flat_y[i] = float(arb_value(arb(float(flat_x[i]))).mid())
            return y
        return value

    def _float_taylor(self, point: _Point, arb_value: Callable):
        """``(radius, coefficients)``: the float64 Taylor polynomial of ``f`` at
        ``x0`` and the largest radius (a power of two, relative to
        ``max(1, |x0|)``) where it agrees with Arb at 2^-52 relative; ``(0,
        None)`` when no radius down to 2^-16 does (then points near ``x0`` are
        evaluated in Arb one by one). A sampling aid: nothing rigorous depends
        on it."""
        key = "float_taylor"
        if key in point.cache:
            return point.cache[key]
        result = (0.0, None)
        with arb_precision(192):
            c = self.at_point(point, POINT_TERMS)
            if c is not None:
                poly = np.array([float(x.mid()) for x in c])
                scale = max(1.0, abs(point.x0_float))
                for e in range(0, 17):
                    r = 2.0 ** -e * scale
                    good = True
                    for frac in (1.0, 0.75, 0.5, -0.5, -0.75, -1.0):
                        h = frac * r
                        ref = arb_value(arb(point.x0_float + h))
                        if not ref.is_finite():
                            good = False
                            break
                        got = np.polynomial.polynomial.polyval(h, poly)
                        want = float(ref.mid())
                        if not abs(got - want) <= 2.0 ** -52 * max(abs(want), 1e-300) * 4:
                            good = False
                            break
                    if good:
                        result = (2.0 ** -e, poly)
                        break
        point.cache[key] = result
        return result


def _coeffs(series, n: int) -> list[arb]:
    if not isinstance(series, arb_series):
        return ([series] + [arb(0)] * n)[:n]
    c = series.coeffs()
    return (c + [arb(0)] * n)[:n]


def _meet(a: arb, b: arb) -> arb:
    """The intersection of two enclosures of one number (``a`` if they do not
    meet, which only a wrong enclosure could cause)."""
    if not (a.is_finite() and b.is_finite()):
        return b if b.is_finite() else a
    try:
        return a.intersection(b)
    except ValueError:
        return a


def analyse(expr: sp.Expr, var: sp.Symbol, compile_arb: Callable,
            enclose: Callable) -> Removable | None:
    """The removable-singularity evaluators of ``expr``, or None when ``expr``
    has no denominator in ``var`` (or none of its zeros is removable).

    Parameters
    ----------
    expr : sympy.Expr
        The function.
    var : sympy.Symbol
        Its variable.
    compile_arb, enclose : callable
        The Arb compiler and constant enclosure of :mod:`chebnorm.approx.expr`
        (passed in: this module is imported by that one).

    Returns
    -------
    Removable or None
        The analysis; None when plain evaluation is all there is.
    """
    if not any(p.exp.is_negative and p.base.has(var) for p in expr.atoms(sp.Pow)):
        return None
    try:
        num, den = sp.fraction(sp.together(expr))
    except Exception:  # noqa: BLE001
        return None
    if not den.has(var) or not num.has(var):
        return None  # no denominator, or a constant numerator: every zero of D is a pole
    try:
        r = Removable(expr, var, num, den, compile_arb, enclose)
        if not r.any_points:
            return None
    except ValueError:  # an operation the Arb compiler does not know
        return None
    return r
