"""Exhaustive certificates of float32 evaluators (RLIBM-style).

A float32 evaluator has finitely many inputs: every float32 of its interval.
:func:`float32_certificate` runs the evaluator's operation sequence on each
of them, bit-exactly, and compares it with a rigorous enclosure of ``f``;
the largest error seen (rounded up) is then a *proved* bound, a finite
domain checked exhaustively. It is usually much tighter than the interval
analysis of :mod:`chebnorm.export.evalbound`, which must assume that every
rounding of an evaluation reaches its worst case on one input at once.

The simulation
--------------
* ``+``, ``-``, ``*``, ``/`` on numpy float32 arrays are IEEE 754 binary32
  operations rounded to nearest even (no transcendental function is used);
* a fused multiply-add ``fma(a, t, c)`` of float32 numbers: ``a t`` is exact
  in binary64 (48 significand bits), the sum ``a t + c`` is formed by
  Knuth's TwoSum (its rounding error exactly), rounded to odd in binary64
  (the last bit set when the sum was inexact) and then rounded to float32:
  rounding to odd at 53 bits followed by rounding to nearest at 24 bits is
  the correctly rounded result, since ``53 >= 24 + 2`` (Boldo and
  Melquiond, "Emulation of FMA and correctly rounded sums: proved algorithms
  using rounding to odd", IEEE TC 57(4), 2008);
* every mix of fused and unfused Horner steps (a compiler may contract any
  subset): each step ``a -> fl(a t + c)`` and ``a -> fl(fl(a t) + c)`` is
  monotone in ``a`` for a fixed input (rounding is monotone), in the same
  direction, so the smallest and the largest value any mix can reach are
  carried step by step (two numbers per input, not ``2^n``); both are
  reached by some mix, so the error of every mix lies between theirs.

The reference
-------------
``f`` is enclosed on pieces of the interval by Taylor polynomials computed
in Arb (python-flint) at the centre ``m`` of each piece, with the Lagrange
remainder enclosed over the whole piece; the polynomial's coefficients are
rounded to doubles (their errors bounded in Arb) and evaluated in binary64
on ``h = x - m`` (exact: checked by TwoSum), its rounding bounded by
:func:`chebnorm.export.evalbound.horner_bound`. So ``|f(x) - q(x)| <= E``
on each piece with ``E`` proved (about ``1e-16 |f|``), and the certificate
is ``max_x |y(x) - q(x)| + E``, every operation rounded upward.

Examples
--------
>>> from fractions import Fraction
>>> from chebnorm.export.evalbound import BINARY32, Evaluator, Piece
>>> c = (1.0, 0.5)
>>> ev = Evaluator("C", "c", BINARY32, (Piece(c, c, Fraction(0), 1.0, 2.0),))
>>> cert = float32_certificate(ev, "1 + x/2")
>>> cert.inputs, cert.maximum <= 2.0 ** -23    # the only rounding: half an ulp of [1, 2]
(8388609, True)
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from chebnorm.core.progress import progress_bar

# an implementation module of chebnorm.export: the API is what chebnorm.export exports
__all__: list[str] = []

#: the most float32 inputs an evaluator is certified on exhaustively (beyond:
#: only the interval bound); 2^25 takes a few seconds
MAX_CERTIFIED_INPUTS = 2 ** 25

_CHUNK = 2 ** 20
_TAYLOR_TERMS = 12
_PREC = 128


@dataclass(frozen=True)
class ExhaustiveCertificate:
    """The exhaustive certificate of one float32 evaluator.

    Attributes
    ----------
    maximum : Fraction
        A proved upper bound of ``max |evaluator(x) - f(x)|`` over every
        float32 ``x`` of the interval and every mix of fused and unfused
        steps: the largest computed error plus the reference's proved error.
    stated : float
        ``maximum + 2**-48 max|f|`` rounded up to 12 significand bits (a
        short decimal): the value a header prints; the margin leaves room for
        a check whose own reference of ``f`` is a float64 or long double.
    inputs : int
        The float32 inputs checked.
    worst : float
        The input where the largest error was seen.
    reference_error : Fraction
        The largest proved ``|q(x) - f(x)|`` of the reference (included in
        ``maximum``).

    Examples
    --------
    >>> from chebnorm.export.evalbound import BINARY32, Evaluator, Piece
    >>> c = (1.0, 0.5)
    >>> cert = float32_certificate(
    ...     Evaluator("C", "c", BINARY32, (Piece(c, c, Fraction(0), 1.0, 1.5),)), "1 + x/2")
    >>> cert.maximum <= cert.stated and cert.reference_error < 1e-15
    True
    """

    maximum: Fraction
    stated: float
    inputs: int
    worst: float
    reference_error: Fraction


def _up12(v: Fraction) -> float:
    """``v > 0`` rounded up to 12 significand bits."""
    e = math.frexp(float(v))[1] - 12
    q = v / Fraction(2) ** e
    return float(Fraction(-(-q.numerator // q.denominator)) * Fraction(2) ** e)


def float32_range(lo: float, hi: float) -> tuple[int, int]:
    """The float32 numbers in ``[lo, hi]`` as a range of ordered integer keys.

    Parameters
    ----------
    lo, hi : float
        The interval (doubles, ``lo <= hi``).

    Returns
    -------
    tuple of (int, int)
        ``(k_lo, k_hi)``: the float32 ``x`` with key ``k`` (the bit pattern,
        negated for negative numbers; ``-0`` and ``+0`` share key 0) lie in
        ``[lo, hi]`` for ``k_lo <= k <= k_hi``; an empty range has
        ``k_lo > k_hi``.

    Examples
    --------
    >>> k0, k1 = float32_range(1.0, 2.0)
    >>> k1 - k0 + 1
    8388609
    """
    def key(v):
        b = int(np.array(v, dtype=np.float32).view(np.int32))
        return b if b >= 0 else -(b & 0x7FFFFFFF)

    l32, h32 = np.float32(lo), np.float32(hi)
    if float(l32) < lo:
        l32 = np.nextafter(l32, np.float32(np.inf))
    if float(h32) > hi:
        h32 = np.nextafter(h32, np.float32(-np.inf))
    return key(l32), key(h32)


def _from_keys(k: np.ndarray) -> np.ndarray:
    b = np.where(k < 0, (-k) | np.int64(0x80000000), k).astype(np.uint32)
    return b.view(np.float32)


def fma32(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The correctly rounded float32 ``a * b + c`` (one rounding), exactly.

    Parameters
    ----------
    a, b, c : numpy.ndarray of float32
        Finite operands (broadcast together).

    Returns
    -------
    numpy.ndarray of float32
        ``round_to_nearest_even(a b + c)``: the exact product in binary64,
        the exact sum by TwoSum rounded to odd in binary64, then rounded to
        float32 (correct since ``53 >= 24 + 2``).

    Examples
    --------
    >>> a = np.float32(1 + 2.0 ** -12)
    >>> float(fma32(a, a, np.float32(-1))) == 2.0 ** -11 + 2.0 ** -24   # a*a - 1 exactly
    True
    >>> float(a * a - np.float32(1)) == 2.0 ** -11                      # two roundings
    True
    """
    p = np.asarray(a, dtype=np.float64) * np.asarray(b, dtype=np.float64)  # exact
    c = np.asarray(c, dtype=np.float64)
    s = p + c
    bb = s - p
    err = (p - (s - bb)) + (c - bb)  # TwoSum: s + err = p + c exactly
    even = (np.asarray(s).view(np.int64) & 1) == 0
    towards = np.where(err > 0, np.inf, -np.inf)
    s = np.where((err != 0) & even, np.nextafter(s, towards), s)  # rounded to odd
    return np.asarray(s).astype(np.float32)


def _gradual_underflow() -> bool:
    """False when this thread's float arithmetic flushes subnormals (a library
    set FTZ/DAZ): the simulation would then not be IEEE's."""
    tiny = np.array([2.0 ** -140], dtype=np.float32)
    return bool((tiny * np.float32(0.5))[0] != 0 and (tiny / np.float32(2))[0] * 2 == tiny[0])


def _subnormal(v: np.ndarray) -> bool:
    a = np.abs(v)
    return bool(np.any((a > 0) & (a < np.float32(2.0 ** -126))))


def float32_simulation(ev, x, *, drop=None, pure=False):
    """The float32 evaluator ``ev`` run bit-exactly on the float32 inputs ``x``:
    the smallest and the largest result over every mix of fused and unfused
    Horner steps.

    Parameters
    ----------
    ev : Evaluator
        A one-piece binary32 evaluator.
    x : numpy.ndarray of float32
        Inputs.
    drop : int or "t", optional
        For the tests only: the product of Horner step ``drop`` (counted
        from the highest coefficient, 0 first) left unrounded in the unfused
        path (``"t"``: the square ``t = x*x`` rounded toward zero), so the
        simulation is no longer the evaluator.
    pure : bool, default False
        Return the every-step-unfused and every-step-fused results instead
        (what ``-ffp-contract=off`` and ``-ffp-contract=fast`` builds compute).

    Returns
    -------
    tuple of numpy.ndarray or None
        ``(lo, hi)`` as float64 arrays: every mix's result lies in
        ``[lo, hi]`` and both are some mix's (``pure``: ``(unfused,
        fused)``); None when a flushing arithmetic (``BINARY32_FTZ``) meets
        a subnormal value.

    Examples
    --------
    >>> from chebnorm.export.evalbound import BINARY32, Evaluator, Piece
    >>> ev = Evaluator("C", "c", BINARY32, (Piece((1.0, 0.1), (1.0, 0.1), Fraction(0), 1.0, 2.0),))
    >>> lo, hi = float32_simulation(ev, np.array([1.5], dtype=np.float32))
    >>> float(lo[0]) == float(np.float32(np.float32(0.1) * np.float32(1.5)) + np.float32(1.0))
    True
    """
    a = ev.arith
    if a.kind != "float" or a.precision != 24 or len(ev.pieces) != 1:
        raise ValueError(f"ev: a one-piece binary32 evaluator expected, got {a.kind} with "
                         f"{a.precision} bits and {len(ev.pieces)} pieces")
    cs = tuple(float(c) for c in ev.pieces[0].coeffs)
    if ev.parity is not None:
        cs = cs[ev.parity::2]
    lo, hi, subnormal = _simulate(np.asarray(x, dtype=np.float32), cs, ev.parity, ev.shift, drop,
                                  pure)
    return None if subnormal and a.flush else (lo, hi)


def _simulate(x, cs, parity, shift, drop, pure=False):
    """The smallest and largest float32 result over every fusion mix (float64
    arrays), and whether a subnormal value was met (a flushing arithmetic
    may then differ). ``pure``: the every-step-unfused and every-step-fused
    results instead of the smallest and largest."""
    f32 = np.float32
    seen = [x]
    if parity is not None:
        t = x * x
        if drop == "t":  # the mutation: t rounded toward zero
            exact = x.astype(np.float64) ** 2
            t = np.where(t.astype(np.float64) > exact, np.nextafter(t, f32(0)), t)
    elif shift is not None:
        _, s, c_t, s_t, exact = shift
        d = x - f32(c_t)
        t = d * f32(1 / s) if exact else d / f32(s_t)
        seen.append(d)
    else:
        t = x
    seen.append(t)

    def unfused(a, c, j):
        if drop == j:  # the mutation: this step's product left unrounded
            return (a.astype(np.float64) * t + c).astype(f32)
        prod = a * t
        seen.append(prod)
        return prod + c

    lo = hi = np.full_like(x, f32(cs[-1]))
    for j, c in enumerate(reversed(cs[:-1])):
        c = f32(c)
        if pure:
            lo, hi = unfused(lo, c, j), fma32(hi, t, np.full_like(hi, c))
        else:
            cand = [unfused(lo, c, j), unfused(hi, c, j),
                    fma32(lo, t, np.full_like(lo, c)), fma32(hi, t, np.full_like(hi, c))]
            lo, hi = np.minimum.reduce(cand), np.maximum.reduce(cand)
        seen += [lo, hi]
    if parity == 1:
        lo, hi = lo * x, hi * x
        if not pure:
            lo, hi = np.minimum(lo, hi), np.maximum(lo, hi)
        seen += [lo, hi]
    return lo.astype(np.float64), hi.astype(np.float64), any(_subnormal(v) for v in seen)


def _series_coeffs(s):
    """Coefficients of an Arb series; a constant function yields a plain ball."""
    return s.coeffs() if hasattr(s, "coeffs") else [s]


class _Reference:
    """Taylor pieces of ``f``: per piece the double coefficients and the proved
    bound of ``|q(x) - f(x)|`` (``None`` when Arb cannot enclose ``f``)."""

    def __init__(self, expression: str, variable: str, edges: np.ndarray):
        from flint import arb, arb_series

        from chebnorm.approx import parse_function
        from chebnorm.core.numeric import arb_precision, ball_float_up, float_up

        from .evalbound import BINARY64, horner_bound

        fn = parse_function(expression, variable)
        n = _TAYLOR_TERMS
        self.centres, self.coeffs, self.errors = [], [], []
        with arb_precision(_PREC):
            for a, b in zip(edges[:-1], edges[1:]):
                m = float(np.float32(0.5 * (a + b)))
                r = float_up(max(Fraction(m) - Fraction(float(a)), Fraction(float(b)) - Fraction(m)))
                try:
                    tc = _series_coeffs(fn.arb_series(arb_series([arb(m), 1], prec=n + 1)))
                    ball = arb(m, r)  # [m - r, m + r] contains the piece
                    rest = _series_coeffs(fn.arb_series(arb_series([ball, 1], prec=n + 1)))
                except (ValueError, ArithmeticError, TypeError):
                    raise _NoReference() from None
                tc = list(tc) + [arb(0)] * (n + 1 - len(tc))
                rest = list(rest) + [arb(0)] * (n + 1 - len(rest))
                if not all(v.is_finite() for v in tc + rest):
                    raise _NoReference()
                d = [float(v.mid()) for v in tc[:n]]
                rr = arb(r)
                err = abs(rest[n]) * rr ** n
                for k in range(n):
                    err += abs(tc[k] - arb(d[k])) * rr ** k
                e = Fraction(ball_float_up(err))
                e += horner_bound(d, d, Fraction(0), -r, r, BINARY64, subintervals=8).local
                self.centres.append(m)
                self.coeffs.append(d)
                self.errors.append(float_up(e))
        self.centres = np.array(self.centres)
        self.table = np.array(self.coeffs).T  # (n, pieces)

    def __call__(self, x64: np.ndarray, piece: np.ndarray) -> np.ndarray:
        m = self.centres[piece]
        h = x64 - m
        bb = h - x64
        if np.any((x64 - (h - bb)) + (-m - bb) != 0):  # TwoSum: h must be exact
            raise _NoReference()
        q = self.table[-1][piece]
        for k in range(_TAYLOR_TERMS - 2, -1, -1):
            q = q * h + self.table[k][piece]
        return q


class _NoReference(Exception):
    pass


def float32_certificate(ev, expression: str, variable: str = "x", *, drop=None
                        ) -> ExhaustiveCertificate | None:
    """The exhaustive certificate of a float32 evaluator.

    Parameters
    ----------
    ev : Evaluator
        A binary32 evaluator (:data:`~chebnorm.export.evalbound.BINARY32` or
        ``BINARY32_FTZ``) with one piece; its inputs are every float32 of
        the piece's ``[lo, hi]``.
    expression : str
        ``f``, as the table states it.
    variable : str, default "x"
        Its variable.
    drop : int or "t", optional
        For the tests only, as :func:`float32_simulation` takes it: a
        simulation that is no longer the evaluator (a wrong certificate a
        check must catch).

    Returns
    -------
    ExhaustiveCertificate or None
        None when the evaluator is not a one-piece binary32 one, has more
        than :data:`MAX_CERTIFIED_INPUTS` inputs, a flushing arithmetic
        meets a subnormal value, or Arb cannot enclose ``f`` on the interval.

    Examples
    --------
    >>> from chebnorm.export.evalbound import BINARY64, Evaluator, Piece
    >>> float32_certificate(Evaluator("C", "c", BINARY64,
    ...     (Piece((1.0,), (1.0,), Fraction(0), 1.0, 2.0),)), "1") is None
    True
    """
    a = ev.arith
    if a.kind != "float" or a.precision != 24 or len(ev.pieces) != 1:
        return None
    piece = ev.pieces[0]
    cert, subnormal = _certificate(tuple(float(c) for c in piece.coeffs), float(piece.lo),
                                   float(piece.hi), ev.parity, ev.shift, str(expression),
                                   str(variable), drop)
    return None if subnormal and a.flush else cert


@functools.lru_cache(maxsize=64)
def _certificate(cs, lo, hi, parity, shift, expression, variable, drop):
    """``(certificate or None, whether a subnormal value was met)``."""
    k_lo, k_hi = float32_range(lo, hi)
    count = k_hi - k_lo + 1
    if count <= 0 or count > MAX_CERTIFIED_INPUTS or not _gradual_underflow():
        return None, False
    if parity is not None:
        cs = cs[parity::2]
    x_lo, x_hi = (float(_from_keys(np.array([k]))[0]) for k in (k_lo, k_hi))
    pieces = 256
    edges = np.linspace(x_lo, x_hi, pieces + 1)
    edges[0], edges[-1] = x_lo, x_hi
    try:
        ref = _Reference(expression, variable, edges)
    except _NoReference:
        return None, False
    best, worst, subnormal, scale = Fraction(-1), x_lo, False, 0.0
    with progress_bar(count, f"chebnorm: float32 certificate on [{x_lo:.6g}, {x_hi:.6g}]",
                      unit="input") as bar:
        for start in range(k_lo, k_hi + 1, _CHUNK):
            stop = min(start + _CHUNK, k_hi + 1)
            got = _certify_chunk(start, stop, cs, parity, shift, drop, edges, ref)
            bar.update(stop - start)
            if got is None:
                return None, False
            chunk_best, chunk_worst, chunk_subnormal, chunk_scale = got
            subnormal = subnormal or chunk_subnormal
            scale = max(scale, chunk_scale)
            if chunk_best > best:
                best, worst = chunk_best, chunk_worst
    ref_err = Fraction(max(ref.errors))
    # stated: a margin of 2^-48 max|f| over the proved maximum, so that a check
    # with a float64 or long double reference (about 2^-53 |f|) has room
    stated = _up12(best + Fraction(scale) * Fraction(1, 2 ** 48))
    return ExhaustiveCertificate(maximum=best, stated=stated, inputs=count, worst=worst,
                                 reference_error=ref_err), subnormal


def _certify_chunk(start, stop, cs, parity, shift, drop, edges, ref):
    """The float32 inputs with keys ``start..stop-1``: ``(largest error as a
    Fraction, its input, whether a subnormal value was met, max |f|)``, or None
    when the reference cannot enclose ``f`` there."""
    pieces = len(edges) - 1
    x = _from_keys(np.arange(start, stop, dtype=np.int64))
    sim = _simulate(x, cs, parity, shift, drop)
    x64 = x.astype(np.float64)
    piece = np.clip(np.searchsorted(edges, x64, side="right") - 1, 0, pieces - 1)
    try:
        q = ref(x64, piece)
    except _NoReference:
        return None
    err = np.maximum(np.abs(sim[0] - q), np.abs(sim[1] - q))
    err = np.nextafter(err, np.inf)  # the subtraction's rounding
    err = np.nextafter(err + np.array(ref.errors)[piece], np.inf)
    i = int(np.argmax(err))
    return Fraction(float(err[i])), float(x[i]), sim[2], float(np.abs(q).max())


def stated_bound(ev) -> tuple[float, ExhaustiveCertificate | None]:
    """The bound an exporter prints for ``ev``, and the certificate behind it.

    The interval bound ``ev.bound().stated`` (proved by the Gappa script of
    :func:`chebnorm.export.gappa.gappa_script`) is always rigorous; for a
    float32 evaluator whose rounding dominates (``local > approximation``)
    and that names its ``target``, the exhaustive certificate is computed
    too and the smaller of the two is stated.

    Parameters
    ----------
    ev : Evaluator
        Any evaluator of :mod:`chebnorm.export.evalbound`.

    Returns
    -------
    tuple of (float, ExhaustiveCertificate or None)
        The value to print, and the certificate when it is that value (None:
        the interval bound is).

    Examples
    --------
    >>> from chebnorm.export.evalbound import BINARY32, Evaluator, Piece
    >>> c = (1.0, 0.5)
    >>> ev = Evaluator("C", "c", BINARY32, (Piece(c, c, Fraction(0), 1.0, 2.0),),
    ...                target=("1 + x/2", "x"))
    >>> value, cert = stated_bound(ev)
    >>> cert is not None and value == cert.stated < ev.bound().stated
    True
    """
    b = ev.bound()
    if not ev.target or not b.local > b.approximation:
        return b.stated, None
    cert = float32_certificate(ev, *ev.target)
    if cert is None or not cert.stated < b.stated:
        return b.stated, None
    return cert.stated, cert
