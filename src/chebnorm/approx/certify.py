"""Rigorous upper bounds of sup |p - f| and sup |p/f - 1| on an interval.

Method (branch and bound on order-4 Taylor forms in ball arithmetic)
--------------------------------------------------------------------
Let ``g = p - f`` (absolute) or ``g = p/f - 1`` (relative). On a subinterval
``X = [m - r, m + r]`` Taylor's theorem with the Lagrange remainder gives,
for every ``x = m + h`` in ``X``,

    g(x) = g0 + g1 h + g2 h^2 + g3 h^3 + g4(xi) h^4,  g_k = g^(k)(m)/k!,  xi in X,

so ``|g(x)| <= max_{|h|<=r} |g0 + g1 h + g2 h^2 + g3 h^3| + sup_X |g4| r^4``.
The point coefficients ``g0 .. g3`` and an enclosure of ``g4`` over the
whole ball ``X`` come from python-flint's ``arb_series`` (Taylor arithmetic
on Arb balls, every rounding error accounted for); the maximum of the cubic
is taken exactly (both ends and the critical points, the roots of its
derivative enclosed in ball arithmetic). The polynomial is evaluated with
its coefficients as exact binary numbers, so the bound is for the very
float64 coefficients that are stored and exported.

Subintervals are bisected until each upper bound is within ``(1 + tol)`` of
the best lower bound found (the largest ``|g|`` at a point; the search
starts from the largest ``|g|`` on a float64 grid, refined by Newton steps
in Arb, so that the pieces are compared with it from the first), so the returned
bound is rigorous and at most ``(1 + tol)`` times the true supremum. When a
cap stops the bisection first (``max_subintervals``, a piece narrower than
``2**-60`` of the interval, or an error below the working precision) the
bound is still rigorous but may be looser: ``Certificate.tight`` is then
False and ``Certificate.reason`` says which cap.

Where the Taylor form is not finite -- a function finite at an endpoint but
with singular derivatives there, such as ``sqrt(x)`` at 0 -- the piece is
bounded by plain ball evaluation of ``g`` over it (rigorous, coarser), and
bisected further if that is not tight enough. For a ball to start exactly at
the singular endpoint, that endpoint must be an exact binary number (0, 1,
1/2, ...).

Constants (``1/10``, ``pi``) are evaluated at the working precision (128 bits
by default), and the interval is enclosed at that precision too: the pieces
cover the exact interval.

Why Arb and not ``mpmath.iv``: Arb propagates rounding errors in C with
arbitrary precision and has Taylor-series arithmetic (``arb_series``) built
in, which is what makes the Taylor form -- and so a bound within a fraction
of a percent of the supremum -- cheap; ``mpmath.iv`` is pure Python, has no
series type, and its naive interval evaluation of ``p - f`` overestimates by
``|p'| + |f'|`` times the width, which would need millions of subintervals.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import sympy as sp
from flint import arb, arb_poly, arb_series, ctx

from chebnorm.core.numeric import arb_precision, ball_float_down, ball_float_up
from chebnorm.core.display import field_rows, summary_html, summary_repr

from .expr import Function1D, compile_arb

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

#: default relative tightness of certified bounds: bound <= (1 + TOL) * sup.
TOL = 2.0 ** -8


@dataclass(frozen=True)
class Certificate:
    """A certified bound and the located maximum it was compared with.

    ``bound`` is a float rounded upward: ``sup |g| <= bound``. ``maximum`` is
    ``|g(at)|`` at a located point ``at`` of the interval (a float inside it),
    so ``maximum <= sup |g| <= bound``. ``subintervals`` counts the pieces
    evaluated. ``tight`` is True when ``bound <= (1 + tol) * sup`` was
    reached; when a cap stopped the subdivision first it is False and
    ``reason`` says which (the bound is rigorous either way).

    Attributes
    ----------
    bound : float
        The certified upper bound of ``sup |g|`` (rounded upward).
    maximum : float
        ``|g(at)|``, a lower bound of the supremum.
    at : float
        The point of the interval where ``maximum`` was located.
    subintervals : int
        The number of pieces the interval was cut into.
    tight : bool, default True
        Whether ``bound <= (1 + tol) * sup |g|`` was reached.
    reason : str, default ""
        When not ``tight``: the cap that stopped the subdivision.
    """

    bound: float
    maximum: float
    at: float
    subintervals: int
    tight: bool = True
    reason: str = ""

    def _summary(self) -> list[tuple[str, object]]:
        return [("bound", self.bound), ("maximum", self.maximum), ("at", self.at),
                ("subintervals", self.subintervals), ("tight", self.tight)] + (
                    [("reason", self.reason)] if self.reason else [])

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html


def arb_enclose(value: sp.Expr) -> arb:
    """A ball enclosing a real sympy constant (``sqrt(2)``, ``2*cos(pi/4)``) at
    the current ``flint.ctx.prec``.

    Parameters
    ----------
    value : sympy.Expr
        A real constant expression (no free symbols) of the functions the
        certification engine supports.

    Returns
    -------
    flint.arb
        A ball containing ``value`` (cached per precision).

    Raises
    ------
    ValueError
        When ``value`` uses a function the engine does not support.
    """
    return _enclose(value, ctx.prec)


@functools.lru_cache(maxsize=1024)
def _enclose(value: sp.Expr, prec: int) -> arb:
    """:func:`arb_enclose` at ``prec`` bits, cached (balls are immutable)."""
    with arb_precision(prec):
        return compile_arb(value, sp.Dummy(), series=False)(arb(0))


def _coeffs(series: arb_series, n: int) -> list[arb]:
    """The first ``n`` Taylor coefficients (flint drops trailing zeros)."""
    c = series.coeffs()
    return (c + [arb(0)] * n)[:n]


def _horner(coeffs: Sequence[arb], x):
    acc = coeffs[-1] + 0 * x if len(coeffs) else 0 * x
    for c in reversed(coeffs[:-1]):
        acc = acc * x + c
    return acc


class PolyTaylor:
    """``p`` and its Taylor expansions ``p(x0 + h)``, by Horner in C.

    The k-th Taylor coefficient at ``x0`` is ``q_k(x0)`` with ``q_k =
    p^(k)/k!``, an arb_poly whose coefficients ``binomial(j, k) c_j`` are
    exact (a float times an integer below 2^28, at 128 bits); each is one
    ``arb_poly`` evaluation instead of a Python loop of series operations.
    """

    def __init__(self, coeffs: Sequence[arb], shift: tuple[float, float] | None = None):
        self.coeffs = list(coeffs)
        self.polys: list[arb_poly] = []
        # p(x) = q((x - c)/s): the k-th Taylor coefficient in x is q_k(t0) / s^k
        self.c, self.s = (arb(0), arb(1)) if shift is None else (arb(shift[0]), arb(shift[1]))
        self.shifted = shift is not None
        self.s_pow: list[arb] = [arb(1)]

    def _t(self, x):
        return (x - self.c) / self.s if self.shifted else x

    def _q(self, k: int) -> arb_poly:
        while len(self.polys) <= k:
            j = len(self.polys)
            c = self.coeffs
            self.polys.append(arb_poly([c[i] * math.comb(i, j) for i in range(j, len(c))]
                                       or [arb(0)]))
        return self.polys[k]

    def taylor(self, x0: arb, n: int) -> list[arb]:
        """The first ``n`` Taylor coefficients of ``p`` at ``x0`` (a ball)."""
        polys = self.polys
        if len(polys) < n:
            self._q(n - 1)
        if not self.shifted:
            return [polys[k](x0) for k in range(n)]
        while len(self.s_pow) < n:
            self.s_pow.append(self.s_pow[-1] * self.s)
        t0, s_pow = self._t(x0), self.s_pow
        return [polys[k](t0) / s_pow[k] for k in range(n)]

    def coefficient(self, x0: arb, k: int) -> arb:
        """The ``k``-th Taylor coefficient of ``p`` at ``x0`` alone."""
        q = self._q(k)
        if not self.shifted:
            return q(x0)
        return q(self._t(x0)) / self.s ** k

    def __call__(self, s):
        if isinstance(s, arb_series):
            c = s.coeffs()
            if len(c) == 2 and c[1] == 1:  # s = x0 + h, the only form certify builds
                return arb_series(self.taylor(c[0], s.prec), prec=s.prec)
            return _horner(self.coeffs, self._t(s))
        return self._q(0)(self._t(s))


def error_function(f, coeffs: Sequence[arb], kind: str, shift=None):
    """``g = p - f`` or ``p/f - 1`` for ``f`` an arb or arb_series function;
    nan wherever Arb cannot evaluate it (a division by a ball containing 0).
    With ``shift = (c, s)``, ``p(x) = sum coeffs[k] ((x - c)/s)^k``."""
    p = coeffs if isinstance(coeffs, PolyTaylor) else PolyTaylor(coeffs, shift)
    if kind == "abs":
        def g(s):
            return p(s) - f(s)
    elif kind == "rel":
        def g(s):
            return p(s) / f(s) - 1
    else:
        raise ValueError(f"error kind {kind!r} is not one of 'abs', 'rel'")

    def safe(s):
        try:
            return g(s)
        except (ValueError, ZeroDivisionError):
            if isinstance(s, arb_series):
                return arb_series([arb("nan")] * s.prec, prec=s.prec)
            return arb("nan")
    return safe


def _error_taylor(f_series, p: PolyTaylor, kind: str):
    """``(x0, n) ->`` the first ``n`` Taylor coefficients of ``g`` at the ball
    ``x0`` (all nan where Arb cannot evaluate it): the error function of
    :func:`error_function` without building the series of ``p``, for the
    subdivision's inner loop. Its attribute ``over(x0, n)`` gives the
    second and the last of them alone (over a piece: an enclosure of ``g'``,
    and the remainder term)."""
    if kind not in ("abs", "rel"):
        raise ValueError(f"error kind {kind!r} is not one of 'abs', 'rel'")
    nan = arb("nan")

    def f_at(x0: arb, n: int) -> arb_series:
        fs = f_series(arb_series([x0, 1], prec=n))
        fs = fs if isinstance(fs, arb_series) else arb_series([fs], prec=n)  # f constant
        if kind == "rel" and x0.rad() > 0:
            c = fs.coeffs()
            if not c or not c[0].is_finite() or c[0].contains(0):
                return _recentred(f_series, x0, n, fs)
        return fs

    def taylor(x0: arb, n: int) -> list[arb]:
        try:
            fs = f_at(x0, n)
            pc = p.taylor(x0, n)
            if kind == "rel":
                return _coeffs(arb_series(pc, prec=n) / fs - 1, n)
            fc = fs.coeffs()
            return [pc[k] - fc[k] for k in range(len(fc))] + pc[len(fc):]
        except (ValueError, ZeroDivisionError):
            return [nan] * n

    def over(x0: arb, n: int) -> tuple[arb, arb]:
        if kind == "rel":
            c = taylor(x0, n)
            return c[1], c[n - 1]
        try:
            fc = f_at(x0, n).coeffs() + [arb(0)] * n
            return (p.coefficient(x0, 1) - fc[1],
                    p.coefficient(x0, n - 1) - fc[n - 1])
        except (ValueError, ZeroDivisionError):
            return nan, nan

    taylor.over = over
    return taylor


def _recentred(f_series, x0: arb, n: int, naive: arb_series) -> arb_series:
    """The first ``n`` Taylor coefficients of ``f`` over the ball ``x0 = m + H``
    (``H = [-r, r]``) by a second-order expansion from the exact midpoint ``m``:
    ``f_k(x0) in f_k(m) + (k + 1) f_{k+1}(m) H + C(k + 2, 2) f_{k+2}(x0) H^2``,
    each intersected with the direct enclosure ``naive``. Where ``f`` is a
    cancellation (``1 - cos(x)`` near 0: ``x^2/2`` out of two numbers near 1) the
    direct enclosure of ``f(x0)`` is wider than ``f`` itself and holds 0 on every
    piece Arb can afford; the expansion's width is ``|f'(m)| r``, so the ratio
    ``p/f`` is enclosed once ``r`` is a fraction of the distance to the zero."""
    m = arb(x0.mid())
    h = arb(0, x0.rad())
    try:
        at_m = f_series(arb_series([m, 1], prec=n + 1))
        over = f_series(arb_series([x0, 1], prec=n + 2))
    except (ValueError, ZeroDivisionError):
        return naive
    cm = _coeffs(at_m if isinstance(at_m, arb_series) else arb_series([at_m], prec=n + 1),
                 n + 1)
    cx = _coeffs(over if isinstance(over, arb_series) else arb_series([over], prec=n + 2),
                 n + 2)
    direct = _coeffs(naive, n)
    h2 = h * h
    out = []
    for k in range(n):
        e = cm[k] + (k + 1) * cm[k + 1] * h + ((k + 2) * (k + 1) // 2) * cx[k + 2] * h2
        if not e.is_finite():
            e = direct[k]
        elif direct[k].is_finite():
            e = e.intersection(direct[k])
        out.append(e)
    return arb_series(out, prec=n)


def _quadratic_max(c0: arb, c1: arb, c2: arb, r: arb) -> arb:
    """An upper bound of max_{|h| <= r} |c0 + c1 h + c2 h^2| (balls allowed)."""
    ends = [abs(c0 - c1 * r + c2 * r * r), abs(c0 + c1 * r + c2 * r * r)]
    best = ends[0].upper().max(ends[1].upper())
    if c2.is_zero():  # a line: largest at an end
        return best
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


def _cubic_max(c0: arb, c1: arb, c2: arb, c3: arb, r: arb) -> arb:
    """An upper bound of max_{|h| <= r} |c0 + c1 h + c2 h^2 + c3 h^3| (balls
    allowed): both ends, and each critical point (a root of ``c1 + 2 c2 h +
    3 c3 h^2``, enclosed in ball arithmetic) whose ball meets ``[-r, r]``.
    Where the roots cannot be separated (``c3`` or the discriminant
    containing 0) the quadratic's maximum plus ``|c3| r^3``."""
    def cubic(h):
        return c0 + h * (c1 + h * (c2 + h * c3))

    # both ends: p(+-r) = even +- odd, so max |p(+-r)| = |even| + |odd|
    r2 = r * r
    best = (abs(c0 + c2 * r2) + abs(r * (c1 + c3 * r2))).upper()
    if not best.is_finite():  # some coefficient is not
        return best
    disc = c2 * c2 - 3 * c1 * c3
    if disc < 0:  # no real critical point: monotonic
        return best
    if c3.is_zero():
        return _quadratic_max(c0, c1, c2, r)
    if c3.contains(0) or not disc > 0:
        return best.max(_quadratic_max(c0, c1, c2, r) + abs(c3).upper() * (r * r * r))
    sq = disc.sqrt()
    if c2 > 0 or c2 < 0:  # the root pair without cancellation
        q = -(c2 + sq) if c2 > 0 else sq - c2
        roots = (q / (3 * c3), c1 / q)
    else:
        roots = ((sq - c2) / (3 * c3), -(c2 + sq) / (3 * c3))
    box = arb(0, r.upper())
    for h in roots:
        if h.overlaps(box):
            best = best.max(abs(cubic(h.intersection(box))).upper())
    return best


#: order of the Taylor forms of the subdivision: ``g`` to ``h^3`` at the
#: midpoint, the ``h^4`` term enclosed over the piece
ORDER = 4

#: order of the Taylor forms tried when |g| is far below |f| (see _high_order_upper)
HIGH_ORDER = 8


def _high_order_upper(g, a: arb, b: arb, m: arb, r: arb) -> arb:
    """An order-``HIGH_ORDER`` Taylor form of ``|g|`` on ``[a, b]``; ``g(x0,
    n)`` gives the first ``n`` Taylor coefficients at the ball ``x0``.

    ``g = g0 + .. + g3 h^3 + sum_{4 <= k <= n} g_k h^k + g_{n+1}(xi) h^{n+1}``:
    the cubic's maximum exactly, the middle terms by ``|g_k| r^k`` (point
    coefficients) and the remainder over the ball. When ``g`` is a tiny
    difference of large terms (an error at rounding level) the ball
    enclosure of ``g_4`` is dominated by the width of the ball times ``|f|``;
    the remainder's ``r^{n+1}`` shrinks that much faster than ``r^4``.
    """
    n = HIGH_ORDER
    c = g(m, n + 1)
    rest = g.over(a.union(b), n + 2)[1]
    upper = _cubic_max(c[0], c[1], c[2], c[3], r)
    rk = (r * r) * (r * r)
    for k in range(4, n + 1):
        upper = upper + abs(c[k]).upper() * rk
        rk = rk * r
    return upper + abs(rest).upper() * rk


def _ball(a: arb, b: arb, from_right: bool) -> arb:
    """A ball containing ``[a, b]`` whose lower end is exactly ``a`` (or, with
    ``from_right``, whose upper end is exactly ``b``) when that end is an
    exact binary number: ``a + [0, w]`` with ``[0, w]`` built by
    ``nonnegative_part``, so a function defined only from ``a`` on (``sqrt``
    at 0) can be evaluated on it."""
    width = (b - a).upper()
    span = arb(0).union(width).nonnegative_part()  # [0, >= b - a], lower end exactly 0
    return b - span if from_right else a + span


def certify(fn: Function1D, coefficients: Sequence[float], lo: sp.Expr, hi: sp.Expr,
            kind: str = "abs", tol: float = TOL, max_subintervals: int = 200_000,
            prec: int | None = None, shift: tuple[float, float] | None = None,
            *, abort_at: float | None = None) -> Certificate | None:
    """Certify ``sup_{x in [lo, hi]} |g(x)|`` for ``g = p - f`` or ``p/f - 1``.

    ``coefficients`` are the polynomial's float coefficients in ascending
    powers of ``x``; ``lo`` and ``hi`` are exact sympy constants. Constants
    and endpoints are evaluated at ``prec`` bits (default 128). Raises
    ValueError when ``g`` is not finite somewhere on the interval (``f`` is
    undefined, infinite, or -- for ``kind="rel"`` -- zero there), or when the
    interval holds no float64 number (the located maximum is reported at one).
    With ``shift = (c, s)`` (floats, ``s > 0``) the coefficients are in the
    shifted variable: ``p(x) = sum_k coefficients[k] ((x - c)/s)^k``, the
    quotient taken exactly. With ``abort_at`` (a float) it returns None as
    soon as the bound is proven to be at least ``abort_at`` (for ranking
    candidates against a known bound); otherwise the certificate is the one
    computed without it.

    Parameters
    ----------
    fn : Function1D
        The function ``f`` (from :func:`chebnorm.approx.expr.parse_function`).
    coefficients : sequence of float
        The polynomial's coefficients, ascending powers.
    lo, hi : sympy.Expr
        Exact endpoints, ``lo < hi``.
    kind : str, optional
        ``"abs"`` (``g = p - f``) or ``"rel"`` (``g = p/f - 1``).
    tol : float, optional
        The relative tightness aimed at: ``bound <= (1 + tol) sup |g|``.
    max_subintervals : int, optional
        A cap on the subdivision (the bound stays rigorous, ``tight`` False).
    prec : int, optional
        Working precision in bits (default 128).
    shift : tuple of (float, float), optional
        ``(c, s)``: coefficients in ``(x - c)/s``.
    abort_at : float, optional
        Stop (return None) once the bound is proven ``>= abort_at``.

    Returns
    -------
    Certificate or None
        The certified bound, the located maximum and where; None only with ``abort_at``.

    Raises
    ------
    ValueError
        When ``g`` is not finite somewhere on the interval, or the interval holds no float64.

    See Also
    --------
    chebnorm.fit : fits a polynomial and certifies it with this function.
    chebnorm.quantize : re-certifies rounded coefficients.
    Certificate : the result.

    Notes
    -----
    On a piece :math:`X = [m - r, m + r]` of the interval, Taylor's theorem
    with the Lagrange remainder gives, for :math:`x = m + h \\in X`,

    .. math::

        |g(x)| \\le \\max_{|h| \\le r} \\Bigl|\\sum_{k=0}^{3} g_k h^k\\Bigr|
            + \\sup_{\\xi \\in X} \\frac{|g^{(4)}(\\xi)|}{4!}\\, r^4,
        \\qquad g_k = \\frac{g^{(k)}(m)}{k!},

    with the :math:`g_k` and the enclosure of :math:`g^{(4)}` over :math:`X`
    computed in Arb ball arithmetic [2]_ and the cubic's maximum taken
    exactly. Pieces are bisected until each bound is within
    :math:`1 + \\mathrm{tol}` of the largest :math:`|g|` found at a point,
    so ``maximum <= sup |g| <= bound``, and ``bound <= (1 + tol) * maximum``
    when ``tight`` (module docstring). The polynomial is evaluated with its float64 coefficients as
    exact binary numbers: the bound is that of the stored coefficients.

    Sollya's ``supnorm`` [1]_ solves the same problem; ``tests/test_sollya.py``
    compares the two.

    References
    ----------
    .. [1] S. Chevillard, J. Harrison, M. Joldes, C. Lauter, "Efficient and
       accurate computation of upper bounds of approximation errors",
       Theoretical Computer Science 412(16), 2011; Sollya,
       https://www.sollya.org/
    .. [2] F. Johansson, "Arb: efficient arbitrary-precision midpoint-radius
       interval arithmetic", IEEE Transactions on Computers 66(8), 2017.

    Examples
    --------
    >>> from chebnorm.approx.expr import parse_function
    >>> import sympy as sp
    >>> c = certify(parse_function("x**2"), [0.0, 0.0, 1.0], sp.Integer(0), sp.Integer(1))
    >>> c.bound == 0.0, c.tight
    (True, True)

    ``sqrt`` is finite at 0 although its derivatives are not:

    >>> c = certify(parse_function("sqrt(x)"), [0.125, 1.0], sp.Integer(0), sp.Integer(1))
    >>> c.maximum, c.maximum <= c.bound <= (1 + TOL) * c.maximum
    (0.125, True)
    """
    lo, hi = _check_arguments(fn, coefficients, lo, hi, tol, max_subintervals, prec)
    with arb_precision(prec or 128):
        if shift is not None:
            if not isinstance(shift, (tuple, list)) or len(shift) != 2 or not all(
                    _is_real(v) for v in shift):
                raise ValueError(f"shift {shift!r}: accepted: None or a pair (center, scale) "
                                 f"of finite numbers, scale > 0")
            shift = (float(shift[0]), float(shift[1]))
            if not (math.isfinite(shift[0]) and math.isfinite(shift[1]) and shift[1] > 0):
                raise ValueError(f"shift {shift!r}: accepted: a finite center and a finite "
                                 f"positive scale")
        return _certify(fn, [float(c) for c in coefficients], lo, hi, kind, tol,
                        max_subintervals, shift, abort_at)


def _is_real(v) -> bool:
    import numbers

    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        return False
    try:
        return math.isfinite(float(v))
    except (OverflowError, ValueError):
        return False


def _check_arguments(fn, coefficients, lo, hi, tol, max_subintervals, prec):
    """Refuse :func:`certify`'s arguments of the wrong type or range, naming the
    argument; return ``(lo, hi)`` as sympy constants (int, float and text read
    exactly)."""
    from .expr import parse_number

    if not (callable(getattr(fn, "arb", None)) and callable(getattr(fn, "arb_series", None))):
        raise ValueError(f"fn of type {type(fn).__name__} is not accepted; accepted: a "
                         f"Function1D (chebnorm.approx.parse_function('exp(x)'))")
    if isinstance(coefficients, (str, bytes)) or not hasattr(coefficients, "__len__") \
            or not 1 <= len(coefficients) or not all(_is_real(c) for c in coefficients):
        raise ValueError(f"coefficients {coefficients!r:.80}: accepted: a non-empty sequence "
                         f"of finite numbers (ascending powers)")
    ends = []
    for name, v in (("lo", lo), ("hi", hi)):
        if isinstance(v, (str, int, float)) and not isinstance(v, bool):
            v = parse_number(v)
        if not isinstance(v, sp.Expr) or v.free_symbols or not v.is_finite or not v.is_real:
            raise ValueError(f"{name} {v!r:.80}: accepted: a finite real constant (a sympy "
                             f"constant, an int, a float or a text such as 'sqrt(2)')")
        ends.append(v)
    if not _is_real(tol) or tol <= 0:
        raise ValueError(f"tol {tol!r}: accepted: a finite number > 0")
    if isinstance(max_subintervals, bool) or not isinstance(max_subintervals, (int, np.integer)) \
            or max_subintervals < 1:
        raise ValueError(f"max_subintervals {max_subintervals!r}: accepted: an integer >= 1")
    if prec is not None and (isinstance(prec, bool) or not isinstance(prec, (int, np.integer))
                             or not 53 <= prec <= 100_000):
        raise ValueError(f"prec {prec!r}: accepted: None or an integer 53 <= prec <= 100000 "
                         f"(bits)")
    return ends[0], ends[1]


def _scale(fn: Function1D, kind: str, points) -> arb:
    """The size of ``f`` (abs) or 1 (rel), for the working-precision floor."""
    if kind == "rel":
        return arb(1)
    best = arb(0)
    for x in points:
        try:
            v = abs(fn.arb(x))
        except (ValueError, ZeroDivisionError):
            continue
        if v.is_finite():
            best = best.max(v.upper())
    return best if best > 0 else arb(1)


def _certify(fn, floats, lo, hi, kind, tol, max_subintervals, shift=None,
             abort_at: float | None = None) -> Certificate | None:
    """:func:`certify`'s work; with ``abort_at``, None once the bound (the largest
    of the located maximum and the accepted pieces' upper bounds) reaches it."""
    p = PolyTaylor([arb(c) for c in floats], shift)
    g = _error_taylor(fn.arb_series, p, kind)  # (x0, n) -> Taylor coefficients
    g_point = error_function(fn.arb, p, kind)
    lo_b, hi_b, lo_f, hi_f = _enclose_interval(lo, hi)
    a0, b0 = lo_b.lower(), hi_b.upper()
    edges = _edges(a0, b0, max(len(floats) - 1, 0))
    if kind == "rel":
        _refuse_sign_change(fn, edges, g_point)
    work = list(zip(edges[:-1], edges[1:]))
    min_width = (b0 - a0) * arb(2) ** -60
    # below this, |g| is rounding noise of the working precision
    scale = _scale(fn, kind, (a0, (a0 + b0) / 2, b0))
    floor = scale * arb(2) ** (24 - ctx.prec)
    # an error below this is a cancellation: order-4 forms converge too slowly
    tiny = scale * arb(2) ** -30

    # the largest |g| located first (float64 search, then Newton in Arb): the
    # pieces are compared with it from the start, and fewer are split
    start = _float_argmax(fn, floats, kind, shift, lo_f, hi_f)
    located = None if start is None else _locate_maximum(g, g_point, arb(start), lo_f, hi_f)
    best_lower, best_at = ((located[2], arb(located[1])) if located and located[2] > 0
                           else (arb(0), (a0 + b0) / 2))
    seeded_at = best_at
    if abort_at is not None and located is not None and located[0] >= abort_at:
        return None
    limit = None if abort_at is None else arb(abort_at)
    accepted_upper = arb(0)
    count = 0
    reasons: set[str] = set()
    # (upper, a, b, monotone) of the pieces evaluated, before the comparison
    pending: list[tuple[arb, arb, arb, bool]] = []
    while work or pending:
        for a, b in work:
            count += 1
            m = (a + b) / 2
            r = (b - a) / 2
            c0, c1, c2, c3 = g(m, ORDER)
            slope, rest = g.over(a.union(b), ORDER + 1)
            r2 = r * r
            upper = _cubic_max(c0, c1, c2, c3, r) + abs(rest).upper() * (r2 * r2)
            value = c0 if c0.is_finite() else g_point(m)
            if value.is_finite() and abs(value).lower() > best_lower:
                best_lower, best_at = abs(value).lower(), m
            if not upper.is_finite():
                # no Taylor form (singular derivatives): plain ball evaluation
                upper = abs(g_point(_ball(a, b, from_right=b is b0)))
            if not upper.is_finite():
                if (b - a) < min_width or count > max_subintervals:
                    end = (a, lo_b) if a is a0 else (b, hi_b) if b is b0 else None
                    raise _not_finite(kind, m, end, g_point)
                pending.append((arb("inf"), a, b, False))
                continue
            # g' of one sign on the piece: |g| is largest at one of its ends
            monotone = slope.is_finite() and not slope.contains(0)
            pending.append((upper.upper(), a, b, monotone))
        work = []
        target = best_lower * (1 + arb(tol))
        keep = []
        for upper, a, b, monotone in pending:
            if upper.is_finite() and upper > target and best_lower < tiny:
                upper = upper.min(_high_order_upper(g, a, b, (a + b) / 2, (b - a) / 2).upper())
            if monotone and upper > target:  # the ends' values, exact but for Arb's radii
                ends = abs(g_point(a)).upper().max(abs(g_point(b)).upper())
                if ends.is_finite():
                    upper = upper.min(ends)
            if not upper.is_finite():
                keep.append((upper, a, b))
            elif upper <= target:
                accepted_upper = accepted_upper.max(upper)
            elif upper <= floor:
                accepted_upper = accepted_upper.max(upper)
                reasons.add("the error is below the working precision "
                            f"(2^{24 - ctx.prec} relative to f)")
            elif (b - a) < min_width or count > max_subintervals:
                accepted_upper = accepted_upper.max(upper)
                reasons.add(f"the subdivision cap was reached ({count} pieces, "
                            f"max_subintervals={max_subintervals}, smallest piece 2^-60 "
                            f"of the interval)")
            else:
                keep.append((upper, a, b))
        pending = []
        if limit is not None and accepted_upper >= limit:
            return None
        for _, a, b in keep:
            m = arb(float(((a + b) / 2).mid()))
            if not (a < m < b):
                m = (a + b) / 2
            work.extend([(a, m), (m, b)])
    if located is None or best_at is not seeded_at:  # a piece's midpoint did better
        again = _locate_maximum(g, g_point, best_at, lo_f, hi_f)
        located = again if located is None or again[0] > located[0] else located
    maximum, at = located[0], located[1]
    bound = accepted_upper.max(arb(maximum))
    return Certificate(bound=ball_float_up(bound), maximum=maximum, at=at, subintervals=count,
                       tight=not reasons, reason="; ".join(sorted(reasons)))


def _enclose_interval(lo, hi) -> tuple[arb, arb, float, float]:
    """Balls of the exact endpoints and the floats nearest inside ``[lo, hi]``."""
    lo_b, hi_b = arb_enclose(lo), arb_enclose(hi)
    lo_f, hi_f = ball_float_up(lo_b), ball_float_down(hi_b)
    if not lo_f <= hi_f:
        raise ValueError(f"interval [{lo}, {hi}] holds no float64 number; accepted: an "
                         f"interval wider than one float64 spacing")
    return lo_b, hi_b, lo_f, hi_f


def _edges(a0: arb, b0: arb, degree: int) -> list[arb]:
    """The first pieces' ends: ``2 (degree + 2)`` equal pieces, split at exact
    binary points (the outer two ends keep the enclosing endpoints)."""
    pieces = 2 * (degree + 2)
    edges = [a0 + (b0 - a0) * arb(k) / pieces for k in range(pieces + 1)]
    return [a0] + [arb(float(e.mid())) for e in edges[1:-1]] + [b0]


def _refuse_sign_change(fn, points, g_point) -> None:
    """Raise :func:`certify`'s ValueError for ``p/f - 1`` at once when ``f`` is
    proven zero at one of ``points`` (balls) or of opposite signs at two: the
    subdivision would end in that error anyway (an enclosure of ``f`` over a
    piece where it takes both signs, or 0, contains 0, and no piece whose
    ratio is not finite is ever accepted), after bisecting down to ``2^-60``
    of the interval."""
    last = None
    for x in points:
        try:
            v = fn.arb(x)
        except (ValueError, ZeroDivisionError):
            continue
        if v.is_zero():
            raise _not_finite("rel", x, None, g_point)
        sign = 1 if v > 0 else -1 if v < 0 else 0
        if sign and last is not None and sign != last[0]:
            raise _not_finite("rel", (last[1] + x) / 2, None, g_point)
        if sign:
            last = (sign, x)


def _not_finite(kind: str, m: arb, end: tuple[arb, arb] | None, g_point) -> ValueError:
    """The true reason why ``g`` cannot be enclosed near ``m``; ``end`` is the
    interval's end point and the ball of the exact endpoint, when the piece
    touches an end."""
    what = "p/f - 1 (f is zero or undefined there)" if kind == "rel" else "f"
    exact = end is not None and end[1].is_exact()
    if end is not None:
        end = end[0]
    if exact and g_point(end).is_finite():
        return ValueError(
            f"{what} is finite at the endpoint x = {float(end.mid()):.17g} but its derivatives "
            f"are not, and ball arithmetic could not enclose it on a piece ending there (the "
            f"argument of sqrt, log or a power must be computed exactly from that endpoint, "
            f"as in sqrt(x) or sqrt(1 - x) on [0, 1]); accepted: a function whose Taylor "
            f"series or ball enclosure is finite on the whole interval")
    if end is not None and not exact:
        return ValueError(
            f"{what} cannot be enclosed near the endpoint x = {float(end.mid()):.17g}: it is "
            f"not finite and real there, or it is defined only from that endpoint, which is "
            f"not an exact binary number (ball arithmetic needs a margin around it); "
            f"accepted: a function defined and finite on the whole interval, whose singular "
            f"endpoint, if any, is a binary number such as 0 or 1")
    return ValueError(f"{what} is not finite and real near x = {float(m.mid()):.17g}; "
                      f"accepted: a function defined and finite on the whole interval")


def _locate_maximum(g, g_point, start: arb, lo: float, hi: float) -> tuple[float, float, arb]:
    """The largest ``|g|`` found at float points of ``[lo, hi]``: both ends,
    the float nearest ``start``, and Newton steps on ``g'`` from that one
    while ``|g|`` is concave, until a step moves less than ``2^-30`` of
    the interval (near a maximum a step changes the value by about its
    square; ``g(x0, n)``: Taylor coefficients, whose first is the value;
    ``g_point``: values). Returns ``(|g(at)|, at, lower)``, ``lower`` a rigorous lower
    bound of ``|g(at)|`` (0 when nothing was finite)."""
    best, best_at, best_lower = -1.0, lo, arb(0)

    def record(x: float, v: arb) -> None:
        nonlocal best, best_at, best_lower
        v = abs(v)
        if v.is_finite() and float(v.mid()) > best:
            best, best_at, best_lower = float(v.mid()), x, v.lower()

    first = min(max(float(start.mid()), lo), hi)
    for x in (first, lo, hi):
        record(x, g_point(arb(x)))
    x, small = first, 2.0 ** -30 * (hi - lo)
    for k in range(8):
        s = g(arb(x), 3)
        if k:
            record(x, s[0])
        if not (s[0].is_finite() and s[1].is_finite() and s[2].is_finite()):
            break
        if not ((s[0] > 0 and s[2] < 0) or (s[0] < 0 and s[2] > 0)):
            break  # |g| is not concave here: no nearby maximum for Newton
        nxt = min(max(x + float((-s[1] / (2 * s[2])).mid()), lo), hi)
        if abs(nxt - x) <= small:
            break
        x = nxt
    else:
        record(x, g_point(arb(x)))
    return max(best, 0.0), best_at, best_lower


#: points of the float64 search for the largest error (per degree + 2)
SEARCH_POINTS = 64


@functools.lru_cache(maxsize=64)
def _search_grid(f_np, lo: float, hi: float, n: int, shift):
    """The grid of :func:`_float_argmax` (``x``, the variable ``t`` of the
    polynomial, and ``f(x)``, read-only), cached: quantization certifies many
    candidates on one interval. None when ``f`` cannot be evaluated."""
    x = 0.5 * (lo + hi) - 0.5 * (hi - lo) * np.cos(np.pi * np.arange(n + 1) / n)
    x[0], x[-1] = lo, hi
    t = x if shift is None else (x - shift[0]) / shift[1]
    with np.errstate(all="ignore"):
        try:
            f = np.asarray(f_np(x), dtype=float)
        except (ArithmeticError, ValueError, TypeError):
            return None
    for a in (x, t, f):
        a.flags.writeable = False
    return x, t, f


def _float_argmax(fn, floats: Sequence[float], kind: str, shift, lo: float, hi: float
                  ) -> float | None:
    """Where ``|g|`` is largest on a float64 grid of ``[lo, hi]`` (Chebyshev
    points, ends included), or None when float64 cannot tell (``f`` has no
    numpy evaluator, nothing finite). A starting point only: nothing rigorous
    depends on it."""
    f_np = getattr(fn, "numpy", None)
    if f_np is None or not lo < hi:
        return None
    grid = _search_grid(f_np, lo, hi, SEARCH_POINTS * (len(floats) + 1), shift)
    if grid is None:
        return None
    x, t, f = grid
    with np.errstate(all="ignore"):
        p = np.polyval(np.asarray(floats[::-1], dtype=float), t) if floats else np.zeros_like(x)
        e = np.abs(p - f if kind == "abs" else p / f - 1)
    e[~np.isfinite(e)] = -1.0
    k = int(np.argmax(e))
    return float(x[k]) if e[k] >= 0 else None
