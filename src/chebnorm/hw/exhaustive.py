"""Rigorous values of ``f`` at every input code: the reference an exhaustive
proof of a table-based design compares against.

An unsigned ``W``-bit input code ``k`` stands for ``x_k = lo + (hi - lo) k /
2**W`` (``lo``, ``hi`` rational, so ``[lo, hi)`` is covered exactly).
:func:`reference` evaluates ``f(x_k)`` for every ``k`` in Arb ball
arithmetic (``x_k`` enters as an exact rational) and keeps, per code, a
float64 enclosure ``lo_k <= f(x_k) <= hi_k`` rounded outward with a margin
that covers every float conversion (:meth:`Reference.error_bounds` turns it
into a rigorous upper bound of ``max_k |y_k - f(x_k)|`` for output codes
``y``). Where the 64-bit ball is too wide (cancellation), the code is
re-evaluated at 256 and 1024 bits.

:func:`round_to_nearest` rounds ``f(x_k) * 2**F`` to the nearest integer for
every code and says whether it *proved* each choice: the enclosure lies on
one side of the midpoint, or (near a midpoint) a ball at up to 4096 bits
does, or the exact value is a tie (then ties go to even).

>>> r = reference("1/sqrt(1+3*x)", ("0", "1"), 8)
>>> float(r.lo[0]) <= 1.0 <= float(r.hi[0]), len(r.mid)
(True, 256)
>>> n, proved = round_to_nearest(r, 8)
>>> int(n[0]), int(n[255]), bool(proved.all())
(256, 128, True)
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import sympy as sp

from chebnorm.approx.expr import compare, parse_function, parse_number
from chebnorm.core.numeric import arb_precision, check_int
from chebnorm.core.display import field_rows, summary_html, summary_repr

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: the widest input an exhaustive proof runs over (2**24 Arb evaluations)
MAX_EXHAUSTIVE_BITS = 24
#: a ball is re-evaluated at higher precision when wider than this (relative)
_TIGHT = 2.0 ** -50
#: relative margin covering the float conversion of a ball's midpoint and radius
_MARGIN = 2.0 ** -50


def exact_endpoint(text, name: str = "interval") -> Fraction:
    """An interval endpoint as an exact rational (the input code maps onto
    ``[lo, hi)`` exactly); ValueError for an irrational one.

    >>> exact_endpoint("0.1"), exact_endpoint("1/4")
    (Fraction(1, 10), Fraction(1, 4))

    Parameters
    ----------
    text : str, int, fractions.Fraction or sympy number
        The endpoint, e.g. ``"0.1"``, ``"1/4"``, ``3``.
    name : str, default "interval"
        What the endpoint belongs to, for the message.

    Returns
    -------
    fractions.Fraction
        The endpoint exactly.

    Raises
    ------
    ValueError
        If the endpoint does not parse as a number or is irrational (``"pi"``,
        ``"sqrt(2)"``).
    """
    v = parse_number(text)
    if not v.is_Rational:
        raise ValueError(f"{name} endpoint {str(text)[:40]!r} is not rational; accepted for "
                         f"hardware: a rational endpoint (the input code maps onto [lo, hi) "
                         f"exactly)")
    return Fraction(int(v.p), int(v.q))


@dataclass(frozen=True, eq=False)
class Reference:
    """``f`` at every input code: ``mid`` (float64, for searching) and the
    rigorous enclosure ``lo <= f(x_k) <= hi`` (float64 arrays).

    ``x(k)`` is the exact rational input of code ``k``.

    >>> r = reference("x*x", ("1", "2"), 2)
    >>> r.x(1), float(r.mid[1]), bool(r.lo[1] <= 25 / 16 <= r.hi[1])
    (Fraction(5, 4), 1.5625, True)

    Attributes
    ----------
    expression : str
        The function ``f`` as given.
    variable : str
        The name of its variable.
    interval : tuple of (str, str)
        The endpoints ``(lo, hi)`` as given; both rational.
    in_bits : int
        Width ``W`` of the input code, 1 to :data:`MAX_EXHAUSTIVE_BITS`.
    mid : numpy.ndarray of float64
        Approximate ``f(x_k)`` per code (length ``2**in_bits``), for searching only.
    lo, hi : numpy.ndarray of float64
        Rigorous enclosure ``lo[k] <= f(x_k) <= hi[k]`` per code.
    """

    expression: str
    variable: str
    interval: tuple[str, str]
    in_bits: int
    mid: np.ndarray
    lo: np.ndarray
    hi: np.ndarray

    def x(self, code: int) -> Fraction:
        """The exact input ``x_k`` of code ``k``."""
        a, b = (exact_endpoint(v) for v in self.interval)
        return a + (b - a) * Fraction(int(code), 2 ** self.in_bits)

    def error_bounds(self, y, frac_bits: int) -> dict:
        """Rigorous bounds of ``max_k |y_k / 2**frac_bits - f(x_k)|`` over every
        code: ``upper`` (>= the true maximum), ``lower`` (<= it) and the code
        ``at`` where the upper bound is reached.

        ``y`` holds integer codes (already including any output offset),
        each exactly a float64 (``|y| < 2**53``).

        >>> r = reference("x", ("0", "1"), 4)
        >>> b = r.error_bounds(np.arange(16) * 2, 5)     # y = x exactly
        >>> b["upper"] < 1e-15, b["lower"] <= 0.0
        (True, True)
        """
        y = np.asarray(y, dtype=np.int64)
        if y.shape != self.mid.shape:
            raise ValueError(f"y: {y.size} codes; accepted: one per input code ({self.mid.size})")
        if np.abs(y).max(initial=0) >= 2 ** 53:
            raise ValueError("y: codes of 53 bits or more; accepted: |y| < 2**53")
        v = np.ldexp(y.astype(np.float64), -int(frac_bits))   # exact
        up = np.nextafter(np.maximum(v - self.lo, self.hi - v), np.inf)
        low = np.nextafter(np.maximum(v - self.hi, self.lo - v), -np.inf)
        at = int(np.argmax(up))
        return {"upper": float(up[at]), "lower": float(max(low.max(), 0.0)), "at": at,
                "codes": int(y.size)}


def reference(expression, interval, in_bits: int, var: str = "x") -> Reference:
    """Rigorous ``f(x_k)`` for all ``2**in_bits`` codes (see the module
    docstring); cached. ValueError when ``f`` is not finite at some code or
    an argument is out of range.

    >>> reference("1/x", ("0", "1"), 4)
    Traceback (most recent call last):
    ...
    ValueError: 1/x is not finite at x = 0 (code 0); accepted: an interval where the function is defined and finite at every input code

    Parameters
    ----------
    expression : str or sympy.Expr
        The function ``f`` of ``var``.
    interval : tuple or list of two endpoints
        ``(lo, hi)``, rational (strings like ``"0"``, ``"1/4"``, ``"0.1"``), ``lo < hi``.
    in_bits : int
        Input code width ``W``, 1 to :data:`MAX_EXHAUSTIVE_BITS` (24): ``2**W``
        evaluations.
    var : str, default "x"
        The variable of ``expression``.

    Returns
    -------
    Reference
        ``f`` at every code: float64 midpoints and a rigorous enclosure.

    Raises
    ------
    ValueError
        If ``in_bits`` is out of range, ``interval`` is not two rational endpoints with
        ``lo < hi``, ``expression`` does not parse, or ``f`` is not finite at some code.
    """
    in_bits = check_int(in_bits, "in_bits", 1, MAX_EXHAUSTIVE_BITS)
    if not (isinstance(interval, (tuple, list)) and len(interval) == 2):
        raise ValueError("interval: accepted: two endpoints (lo, hi)")
    lo, hi = (exact_endpoint(v) for v in interval)
    if not lo < hi:
        raise ValueError(f"interval [{lo}, {hi}] is empty; accepted: lo < hi")
    fn = parse_function(expression, var)
    return _reference(str(expression), var, (str(interval[0]), str(interval[1])), in_bits,
                      str(fn.expr))


@functools.lru_cache(maxsize=4)
def _reference(expression: str, var: str, interval: tuple[str, str], in_bits: int,
               _canonical: str) -> Reference:
    from flint import arb

    fn = parse_function(expression, var)
    g = fn.arb
    lo, hi = (exact_endpoint(v) for v in interval)
    n = 2 ** in_bits
    # x_k = (P + Q k) / D exactly, with integers P, Q, D
    den = lo.denominator * hi.denominator * n
    p = lo.numerator * hi.denominator * n
    q = hi.numerator * lo.denominator - lo.numerator * hi.denominator
    mids, rads = np.empty(n), np.empty(n)
    with arb_precision(64):
        dball = arb(den)
        for k in range(n):
            v = g(arb(p + q * k) / dball)
            if not (v.is_finite() and float(v.rad()) <= _TIGHT * max(abs(float(v.mid())), 1e-300)):
                v = _precise(g, p + q * k, den, expression, var, lo + (hi - lo) * Fraction(k, n), k)
            mids[k], rads[k] = float(v.mid()), float(v.rad())
    margin = rads * (1 + _MARGIN) + np.abs(mids) * _MARGIN + 1e-300
    return Reference(expression, var, interval, in_bits, mids,
                     np.nextafter(mids - margin, -np.inf), np.nextafter(mids + margin, np.inf))


def _precise(g, num: int, den: int, expression, var, x: Fraction, k: int):
    from flint import arb

    for prec in (256, 1024):
        with arb_precision(prec):
            v = g(arb(num) / arb(den))
            if v.is_finite() and float(v.rad()) <= _TIGHT * max(abs(float(v.mid())), 1e-300):
                return v
    raise ValueError(f"{expression} is not finite at {var} = {x} (code {k}); accepted: an "
                     f"interval where the function is defined and finite at every input code")


def round_to_nearest(ref: Reference, frac_bits: int):
    """``(n, proved)``: ``n[k]`` the integer nearest ``f(x_k) * 2**frac_bits``
    (ties to even) and ``proved[k]`` True when that choice is proved (the
    value is not within the enclosure of a midpoint, or a ball at up to 4096
    bits, or an exact evaluation, separates them).

    >>> r = reference("x/2", ("0", "1"), 3)      # x/2 = k/16: ties at odd k
    >>> n, proved = round_to_nearest(r, 3)
    >>> n.tolist(), bool(proved.all())
    ([0, 0, 1, 2, 2, 2, 3, 4], True)

    Parameters
    ----------
    ref : Reference
        The values ``f(x_k)`` from :func:`reference`.
    frac_bits : int
        Fractional bits ``F`` of the result, -1000 to 1000; the scaled values
        ``f(x_k) * 2**F`` must stay below ``2**50`` in magnitude.

    Returns
    -------
    n : numpy.ndarray of int64
        The nearest integer to ``f(x_k) * 2**F`` per code, ties to even.
    proved : numpy.ndarray of bool
        True where that rounding is proved.

    Raises
    ------
    ValueError
        If ``frac_bits`` is out of range or the scaled values do not fit 50 bits.
    """
    frac_bits = check_int(frac_bits, "frac_bits", -1000, 1000)
    slo = np.ldexp(ref.lo, frac_bits)
    shi = np.ldexp(ref.hi, frac_bits)
    if not (np.all(np.isfinite(slo)) and np.all(np.isfinite(shi))
            and max(np.abs(slo).max(), np.abs(shi).max()) < 2.0 ** 50):
        raise ValueError(f"frac_bits = {frac_bits}: the scaled values do not fit 50 bits; "
                         f"accepted: fewer fractional bits")
    n = np.floor(ref.mid * 2.0 ** frac_bits + 0.5).astype(np.int64)
    # proved when the enclosure lies strictly inside (n - 1/2, n + 1/2)
    proved = (slo > n - 0.5) & (shi < n + 0.5)
    for k in np.flatnonzero(~proved):
        n[k], proved[k] = _decide(ref, int(k), frac_bits)
    return n, proved


def _decide(ref: Reference, k: int, frac_bits: int) -> tuple[int, bool]:
    """Round one code near a midpoint: Arb at rising precision, then exactly."""
    from flint import arb

    fn = parse_function(ref.expression, ref.variable)
    x = ref.x(k)
    guess = int(math.floor(float(ref.mid[k]) * 2.0 ** frac_bits))
    for prec in (128, 512, 4096):
        with arb_precision(prec):
            v = fn.arb(arb(x.numerator) / arb(x.denominator)) * arb(2) ** frac_bits
            for m in (guess - 1, guess, guess + 1):
                if v > arb(m) + arb(1) / 2 and v < arb(m) + arb(3) / 2:
                    return m + 1, True
                if v > arb(m) - arb(1) / 2 and v < arb(m) + arb(1) / 2:
                    return m, True
    # a possible exact tie: decide by exact evaluation
    value = fn.expr.subs(fn.var, sp.Rational(x.numerator, x.denominator))
    for m in (guess - 1, guess, guess + 1):
        half = sp.Rational(2 * m + 1, 2 ** (frac_bits + 1)) if frac_bits >= 0 else \
            sp.Rational(2 * m + 1, 2) * sp.Integer(2) ** -frac_bits
        try:
            if compare(value, half) == 0:
                return (m if m % 2 == 0 else m + 1), True
        except ValueError:
            break
    return int(np.floor(float(ref.mid[k]) * 2.0 ** frac_bits + 0.5)), False


@dataclass(frozen=True)
class ExhaustiveCheck:
    """The outcome of an exhaustive proof: ``upper`` >= ``max_k |y_k - f(x_k)|``
    >= ``lower`` over all ``codes`` input codes, the upper bound reached at
    code ``at``.

    >>> ExhaustiveCheck.of({"upper": 1e-5, "lower": 9e-6, "at": 3, "codes": 16}).at
    3

    Attributes
    ----------
    upper : float
        Rigorous upper bound of ``max_k |y_k - f(x_k)|``.
    lower : float
        Lower bound of the same maximum (``>= 0``).
    at : int
        The input code where ``upper`` is reached.
    codes : int
        How many input codes were checked (``2**in_bits``).
    """

    upper: float
    lower: float
    at: int
    codes: int

    def _summary(self) -> list[tuple[str, object]]:
        return [("upper", self.upper), ("lower", self.lower), ("at", self.at),
                ("codes", self.codes)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    @classmethod
    def of(cls, bounds: dict) -> "ExhaustiveCheck":
        """From :meth:`Reference.error_bounds`'s dict."""
        return cls(float(bounds["upper"]), float(bounds["lower"]), int(bounds["at"]),
                   int(bounds["codes"]))
