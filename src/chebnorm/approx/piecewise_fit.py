"""The piecewise fitter: fit, quantize and certify one polynomial per segment.

:func:`piecewise_fit` builds a :class:`chebnorm.approx.PiecewiseTable` (the
contract, its file format and its verification live in
:mod:`chebnorm.approx.piecewise_table`): each segment ``[a_s, b_s]`` is fitted
in its local variable (minimax by a few Remez exchanges, or Chebyshev
interpolation), rounded to the common format ``coef_frac_bits`` (plain
rounding, or the constant term re-centred on the error of the rounded higher
terms, the better on a grid), then all segments are certified together
(:func:`chebnorm.approx.certify_batch.certify_batch`) for exactly the stored
integers.

>>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
>>> t.segment_count, t.degree, t.abs_error_bound < 2e-2
(4, 1, True)
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from chebnorm.core.numeric import check_int
from chebnorm.core.textsafe import default_name

from .certify import arb_enclose
from .certify_batch import SegmentError, certify_batch
from .contract import construction
from .expr import AccurateFunction1D, Function1D, parse_function, parse_number
from .fitting import cheb_to_monomial, remez
from .piecewise_table import (PiecewiseSegment, PiecewiseTable, exact_log2, parse_segments,
                              segment_balls, segment_bounds, segment_count)
from .schema import (ERROR_KINDS as ERRORS, MAX_COEF_FRAC_BITS, MAX_COEF_INT_BITS,
                     MAX_EXPONENT_SPAN, MAX_INDEX_BITS, MAX_PIECEWISE_DEGREE,
                     PIECEWISE_FITS as FITS, SEGMENT_BY, versions)

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

#: points of the grid a segment's rounding is judged on
_DENSE = 257


class _LocalFunction:
    """``t -> f(a + (b - a) t)`` (``t + 1/2`` when centred) in float64, for
    fitting and quantizing (certification composes in Arb, see
    :func:`~chebnorm.approx.piecewise_table.segment_balls`)."""

    def __init__(self, fn: Function1D, a, b, centered: bool):
        self.fn = fn
        self.expr = fn.expr
        sh = 0.5 if centered else 0.0
        af, wf = float(sp.N(a, 20)), float(sp.N(b - a, 20))
        f_np = fn.numpy
        self.numpy = lambda t: f_np(af + wf * (np.asarray(t, dtype=float) + sh))

    def __str__(self) -> str:
        return f"{self.fn.expr} on a segment"


def _local_function(fn: Function1D, a, b, *, centered: bool) -> _LocalFunction:
    return _LocalFunction(fn, a, b, centered)


def _fit_segment(g: Function1D, degree: int, lo: float, hi: float, fit: str, error: str):
    """Float coefficients in the local variable on ``[lo, hi]``."""
    f_np = g.numpy
    if degree == 0 or fit == "chebyshev":
        nodes = np.cos(np.pi * (np.arange(degree + 1) + 0.5) / (degree + 1))
        x = 0.5 * (hi - lo) * nodes + 0.5 * (hi + lo)
        cheb = np.polynomial.chebyshev.chebfit(nodes, f_np(x), degree)
        if degree == 0 and fit == "minimax":
            grid = f_np(np.linspace(lo, hi, _DENSE))
            cheb = np.array([0.5 * (grid.max() + grid.min())])
    else:
        weight = (lambda v: np.ones_like(v)) if error == "abs" else (lambda v: 1 / np.abs(f_np(v)))
        # a few exchanges reach the minimax error to 1e-4; the rounding to the
        # common format dominates past that
        cheb = remez(f_np, weight, lo, hi, degree, max_iter=12, rtol=1e-4).cheb
    return cheb_to_monomial(cheb, lo, hi)


def _quantize_segment(g: Function1D, coeffs, frac_bits: int, lo: float, hi: float, error: str):
    """Integers: plain rounding, and rounding with the constant term re-centred
    on the dense error of the rounded higher terms; the better on a grid."""
    scale = 2.0 ** frac_bits
    plain = [int(round(c * scale)) for c in coeffs]
    v = np.linspace(lo, hi, _DENSE)
    f = g.numpy(v)

    def err(ints):
        p = np.polynomial.polynomial.polyval(v, np.array(ints, dtype=float) / scale)
        e = p - f if error == "abs" else p / f - 1
        return float(np.max(np.abs(e)))

    best = plain
    if len(coeffs) > 1:
        high = np.polynomial.polynomial.polyval(v, np.array([0] + plain[1:], dtype=float) / scale)
        if error == "abs":
            r = f - high
            c0 = 0.5 * (r.max() + r.min())
        else:  # minimise max |(c0 + high)/f - 1|: c0 levels (f - high)/f weighted by 1/f
            c0 = _level_rel(f, high)
        recentred = [int(round(c0 * scale))] + plain[1:]
        if err(recentred) < err(plain):
            best = recentred
    return best


def _level_rel(f, high) -> float:
    """The constant ``c`` minimising ``max |(c + high)/f - 1|`` (bisection on the level)."""
    lo_c, hi_c = float(np.min(f - high)) - 1.0, float(np.max(f - high)) + 1.0
    for _ in range(80):
        mid = 0.5 * (lo_c + hi_c)
        e = (mid + high) / f - 1
        if e.max() + e.min() > 0:
            hi_c = mid
        else:
            lo_c = mid
    return 0.5 * (lo_c + hi_c)


def _certify_fitted(fn, ints_all, frac_bits: int, error: str, balls, loc):
    """The segments fitted (integers ``ints_all``), certified all at once:
    ``(segments, None)``, or ``(None, s)`` with ``s`` the first segment where
    the error is not finite."""
    certs, bad_seg = {}, None
    qs = [[math.ldexp(i, -frac_bits) for i in ints] for ints in ints_all]
    for kind in ("abs", "rel") if error == "rel" else ("abs",):
        try:
            certs[kind] = certify_batch(fn, *balls, qs, loc, kind)
        except SegmentError as exc:
            bad_seg = exc.segment if bad_seg is None else min(bad_seg, exc.segment)
    if bad_seg is not None:
        return None, bad_seg
    out = []
    for s, ints in enumerate(ints_all):
        ca, cr = certs["abs"][s], certs["rel"][s] if error == "rel" else None
        out.append(PiecewiseSegment(tuple(ints), ca.bound, ca.maximum,
                                    None if cr is None else cr.bound,
                                    None if cr is None else cr.maximum))
    return out, None


def _check_binades(lo, hi, index_bits: int) -> None:
    """Refuse an exponent-indexed interval that is not [2^e0, 2^e1] of a few binades."""
    e0, e1 = exact_log2(lo), exact_log2(hi)
    if e0 is None or e1 is None:
        raise ValueError(f"segment_by exponent needs an interval [2^e0, 2^e1] of powers of "
                         f"two, got [{lo}, {hi}]; accepted: e.g. interval=('1/4', '4')")
    if not 1 <= e1 - e0 <= MAX_EXPONENT_SPAN:
        raise ValueError(f"segment_by exponent: {e1 - e0} binades; accepted: 1 to "
                         f"{MAX_EXPONENT_SPAN}")
    if (e1 - e0) * 2 ** index_bits > 2 ** MAX_INDEX_BITS:
        raise ValueError(f"segment_by exponent: {e1 - e0} binades x 2^{index_bits} = "
                         f"{(e1 - e0) * 2 ** index_bits} segments; accepted: at most "
                         f"2^{MAX_INDEX_BITS}")


def _checked(name, segments, degree, coef_frac_bits, segment_by, fit, error, centered):
    """The arguments of :func:`piecewise_fit` checked: ``(name, index_bits, degree,
    frac_bits)``."""
    from chebnorm.core.textsafe import identifier

    name = None if name is None else identifier(name, field="name")
    index_bits = parse_segments(segments)
    degree = check_int(degree, "degree", 0, MAX_PIECEWISE_DEGREE)
    frac_bits = check_int(coef_frac_bits, "coef_frac_bits", 0, MAX_COEF_FRAC_BITS)
    if segment_by not in SEGMENT_BY:
        raise ValueError(f"segment_by {segment_by!r} is unknown; accepted: {', '.join(SEGMENT_BY)}")
    if fit not in FITS:
        raise ValueError(f"fit kind {fit!r} is unknown; accepted: {', '.join(FITS)}")
    if error not in ERRORS:
        raise ValueError(f"error kind {error!r} is unknown; accepted: {', '.join(ERRORS)}")
    if not isinstance(centered, bool):
        raise ValueError(f"centered {centered!r} is not a boolean")
    return name, index_bits, degree, frac_bits


def _fit_all(fn, lo, hi, segment_by, index_bits, degree, frac_bits, centered, fit, error,
             progress):
    """The integers of every segment fitted in turn: ``(ints_all, s)``, with ``s`` the
    first segment where ``f`` is not finite (or zero, for ``error="rel"``), where the
    fitting stopped, or None."""
    loc = (-0.5, 0.5) if centered else (0.0, 1.0)
    limit = 2 ** MAX_COEF_INT_BITS
    ints_all = []
    for s in range(segment_count(segment_by, lo, hi, index_bits)):
        a, b = segment_bounds(segment_by, lo, hi, index_bits, s)
        g = _local_function(fn, a, b, centered=centered)
        with np.errstate(all="ignore"):
            try:
                probe = g.numpy(np.linspace(*loc, 65))
            except (ZeroDivisionError, OverflowError, TypeError):
                probe = np.array([np.nan])
        if error == "rel" and np.all(np.isfinite(probe)) and np.any(probe == 0):
            # float64 may read a zero that is a cancellation (1 - cos(x) near 0): fit
            # from the function's true values where they have no zero
            exact = _local_function(AccurateFunction1D(fn.expr, fn.var), a, b,
                                    centered=centered)
            with np.errstate(all="ignore"):
                again = exact.numpy(np.linspace(*loc, 65))
            if np.all(np.isfinite(again)) and np.all(again != 0):
                g, probe = exact, again
        if not np.all(np.isfinite(probe)) or (error == "rel" and np.any(probe == 0)):
            return ints_all, s
        with np.errstate(all="ignore"):
            coeffs = _fit_segment(g, degree, *loc, fit, error)
        big = max(abs(c) for c in coeffs)
        if big * 2.0 ** frac_bits >= limit:
            max_f = max(0, math.floor(math.log2(limit / big)) - 1)
            raise ValueError(f"coef_frac_bits {frac_bits} overflows the {MAX_COEF_INT_BITS}-bit "
                             f"coefficient integers (segment {s}: |c| = {big:.6g}); accepted: "
                             f"coef_frac_bits <= {max_f}")
        with np.errstate(all="ignore"):
            ints_all.append(_quantize_segment(g, coeffs, frac_bits, *loc, error))
        if progress is not None:
            progress()
    return ints_all, None


def piecewise_fit(expr, interval, degree: int, *, segments=1, segment_by: str = "uniform",
                  coef_frac_bits: int = 24, centered: bool = False, fit: str = "minimax",
                  error: str = "abs", var: str = "x", name: str | None = None,
                  command: str | None = None, progress=None) -> PiecewiseTable:
    """Fit, quantize and certify a piecewise polynomial table.

    Parameters
    ----------
    expr : str or Function1D
        The function ``f``.
    interval : pair
        ``(lo, hi)``, exact constants (``"1/4"``, ``"sqrt(2)"``).
    degree : int
        The degree of every segment's polynomial, 0 to 8.
    segments : int or str
        ``2**k`` (an int or ``"2^k"``): the whole interval's count for
        ``segment_by="uniform"``, the count per binade for ``"exponent"``
        (then ``interval`` must be ``[2**e0, 2**e1]``).
    segment_by : {"uniform", "exponent"}
        How the segments split the interval.
    coef_frac_bits : int
        The common fixed-point format of all coefficients (0 to 48).
    centered : bool
        Evaluate each segment in ``u = t - 1/2`` instead of ``t``.
    fit : {"minimax", "chebyshev"}
        How each segment is fitted.
    error : {"abs", "rel"}
        The error minimized and certified (``"rel"`` certifies both).
    var, name, command : str
        The variable of ``expr``; the table's name (an identifier; default: made
        from the expression, interval, degree and segment count, as
        :func:`chebnorm.core.textsafe.default_name`); the command recorded in its
        provenance.
    progress : callable, optional
        Run once per fitted segment (the certification of all segments together follows).

    Returns
    -------
    PiecewiseTable
        Every segment's bounds certified for exactly the stored integers.

    Raises
    ------
    ValueError
        Naming the argument and the accepted range, or the first segment where
        ``f`` is not finite and real (nonzero for ``error="rel"``).

    Examples
    --------
    >>> t = piecewise_fit("1/sqrt(x)", ("1/4", "4"), 2, segments=2, segment_by="exponent",
    ...                   coef_frac_bits=20, error="rel")
    >>> t.segment_count, t.rel_error_bound < 1e-3
    (8, True)
    """
    name, index_bits, degree, frac_bits = _checked(name, segments, degree, coef_frac_bits,
                                                   segment_by, fit, error, centered)
    try:
        lo_t, hi_t = interval
    except (TypeError, ValueError):
        raise ValueError(f"interval {interval!r} must be a pair (LO, HI)") from None
    fn = expr if isinstance(expr, Function1D) else parse_function(expr, var)
    lo, hi = parse_number(lo_t), parse_number(hi_t)
    if not arb_enclose(lo) < arb_enclose(hi):
        raise ValueError(f"interval [{lo}, {hi}] is empty or reversed; accepted: LO < HI")
    if segment_by == "exponent":
        _check_binades(lo, hi, index_bits)
    ints_all, bad_seg = _fit_all(fn, lo, hi, segment_by, index_bits, degree, frac_bits,
                                 centered, fit, error, progress)
    # the segments fitted so far, certified together; the first segment that
    # fails (or that the probe refused) is reported
    loc = (-0.5, 0.5) if centered else (0.0, 1.0)
    out, failed = _certify_fitted(fn, ints_all, frac_bits, error,
                                  segment_balls(segment_by, lo, hi, index_bits, centered,
                                                range(len(ints_all))), loc)
    if failed is not None and (bad_seg is None or failed < bad_seg):
        bad_seg = failed
    if bad_seg is not None:
        s = bad_seg
        a, b = segment_bounds(segment_by, lo, hi, index_bits, s)
        what = "finite, real and nonzero" if error == "rel" else "finite and real"
        raise ValueError(f"{fn.expr} is not {what} on segment {s} = [{a}, {b}] of "
                         f"[{lo}, {hi}]; accepted: an interval where the function is {what}")
    prov = dict(versions())
    prov["command"] = command or (f"chebnorm.approx.piecewise_fit({str(fn.expr)!r}, "
                                  f"({sp.sstr(lo)!r}, {sp.sstr(hi)!r}), {degree}, "
                                  f"segments={2 ** index_bits}, segment_by={segment_by!r}, "
                                  f"coef_frac_bits={frac_bits}, centered={centered})")
    with construction("fitted"):  # certified above: checked, not proved twice
        return PiecewiseTable(
            name=name or default_name(sp.sstr(fn.expr), (sp.sstr(lo), sp.sstr(hi)), degree,
                                      fn.var.name, segments=len(out)),
            expression=sp.sstr(fn.expr), variable=fn.var.name,
            interval=(sp.sstr(lo), sp.sstr(hi)), segment_by=segment_by, index_bits=index_bits,
            degree=degree, centered=centered, fit=fit, error_kind=error,
            coef_frac_bits=frac_bits, segments=tuple(out),
            abs_error_bound=max(sg.abs_error_bound for sg in out),
            rel_error_bound=max(sg.rel_error_bound for sg in out) if error == "rel" else None,
            provenance=prov)
