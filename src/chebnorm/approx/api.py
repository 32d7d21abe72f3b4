"""``fit`` and ``quantize``: the public entry points of the approximation stage."""

from __future__ import annotations

import functools
import math
import warnings

import numpy as np
import sympy as sp
from flint import arb

from chebnorm.core.numeric import ball_float_down, ball_float_up, format_down, format_up
from chebnorm.core.deprecation import renamed
from chebnorm.core.textsafe import default_name

from .certify import Certificate, certify
from .expr import AccurateFunction1D, Function1D, compare, enclose, parse_function, parse_number
from .fitting import (chebyshev_interpolant, cheb_to_monomial, minimax_powers, polish, remez,
                      shift_for)
from .contract import construction
from .schema import BASES, ERROR_KINDS, KINDS, MAX_DEGREE, versions
from .table import CoefficientTable, FixedPoint, Quantized
from chebnorm.exceptions import FitWarning

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []


def _warn(notes) -> None:
    for note in notes:
        warnings.warn(note, FitWarning, stacklevel=3)

# MAX_DEGREE, KINDS, ERROR_KINDS and BASES live in .schema (imported above, still
# importable from here)


class Interval:
    """Exact endpoints (sympy) with their float values. Internal.

    ``lo``/``hi`` are exact; ``lo_f``/``hi_f`` the nearest floats (stored in
    tables as ``interval_float``); ``lo_in``/``hi_in`` the floats nearest
    *inside* the interval (where it is sampled and its maximum located).
    ``binary`` names the endpoints given as Python floats, whose exact binary
    value is used (``0.1`` as a float is 3602879701896397/36028797018963968).

    Parameters
    ----------
    lo, hi : str, int, float, fractions.Fraction or sympy.Expr
        The endpoints, read by :func:`chebnorm.approx.expr.parse_number`: text
        such as ``"sqrt(2)"`` or ``"0.1"`` exactly, a float at its exact binary
        value. ``lo < hi``, both finite and below 2^1023 in magnitude.

    Attributes
    ----------
    lo, hi : sympy.Expr
        The exact endpoints.
    lo_f, hi_f : float
        The float64 nearest each endpoint.
    lo_in, hi_in : float
        The float64 nearest each endpoint inside the interval.
    binary : dict of str to float
        ``"LO"``/``"HI"`` -> the endpoint given as a Python float, if any.

    Raises
    ------
    ValueError
        When an endpoint cannot be read, is outside the float64 range, the
        interval is empty or reversed, or holds no float64 number.
    """

    def __init__(self, lo, hi):
        self.lo = parse_number(lo)
        self.hi = parse_number(hi)
        self.binary = {name: v for name, v in (("LO", lo), ("HI", hi))
                       if isinstance(v, (float, np.floating))}
        balls = []
        for name, value in (("LO", self.lo), ("HI", self.hi)):
            ball = enclose(value, 128)
            if ball is None or not abs(ball) < arb(2) ** 1023:
                raise ValueError(f"interval endpoint {name} = {value} is outside the float64 "
                                 f"range; accepted: a finite real number below 2^1023 in "
                                 f"magnitude")
            balls.append(ball)
        try:
            order = compare(self.lo, self.hi)
        except ValueError:
            order = 0
        if order >= 0:
            raise ValueError(f"interval [{self.lo}, {self.hi}] is empty or reversed: "
                             f"LO must be strictly less than HI")
        self.lo_f, self.hi_f = (_nearest_float(b) for b in balls)
        self.lo_in, self.hi_in = ball_float_up(balls[0]), ball_float_down(balls[1])
        if not self.lo_in <= self.hi_in:
            raise ValueError(f"interval [{self.lo}, {self.hi}] holds no float64 number; "
                             f"accepted: an interval wider than one float64 spacing")

    @property
    def strings(self) -> tuple[str, str]:
        return (sp.sstr(self.lo), sp.sstr(self.hi))

    def binary_note(self) -> str | None:
        """Which endpoints were binary floats, and their exact values (or None)."""
        if not self.binary:
            return None
        parts = [f"{name} = {float(v)!r} was given as a float64, used at its exact binary "
                 f"value {sp.sstr(self.lo if name == 'LO' else self.hi)}"
                 for name, v in self.binary.items()]
        return "; ".join(parts) + " (pass the text '0.1' for the exact decimal)"


def _nearest_float(ball: arb) -> float:
    """The float64 nearest the midpoint of a narrow ball."""
    mid = ball.mid()
    f = float(mid)
    best = min((f, math.nextafter(f, -math.inf), math.nextafter(f, math.inf)),
               key=lambda c: abs(arb(c) - mid))
    return best


@functools.lru_cache(maxsize=256)
def _complex_evaluator(var: sp.Symbol, expr: sp.Expr):
    """``expr`` as a numpy function of ``var`` in complex arithmetic (sympy's
    ``lambdify``), generated once per expression: a quantization that refits,
    or several fits of one function, reuse it."""
    return sp.lambdify(var, expr, ["scipy", "numpy"])


def check_interval(fn: Function1D, iv: Interval, samples: int = 2001) -> np.ndarray:
    """Sample ``f`` on the interval and reject it where it is not finite and real.

    The certification later proves finiteness on the whole interval; this check
    only gives an early, precise message.

    Parameters
    ----------
    fn : Function1D
        The function, evaluated in complex arithmetic (so that a square root of a
        negative number shows as non-real rather than NaN).
    iv : Interval
        The interval, sampled from ``iv.lo_in`` to ``iv.hi_in`` (both included).
    samples : int, optional
        The number of equally spaced samples, at least 2; default 2001.

    Returns
    -------
    numpy.ndarray
        The real parts of ``f`` at the samples, float64 of shape ``(samples,)``.

    Raises
    ------
    ValueError
        When ``f`` is infinite, NaN or non-real (imaginary part above ``1e-12``
        relative) at a sample, naming the first such point.
    """
    x = np.linspace(iv.lo_in, iv.hi_in, samples)
    x[0], x[-1] = iv.lo_in, iv.hi_in
    with np.errstate(all="ignore"):
        try:
            y = np.asarray(_complex_evaluator(fn.var, fn.expr)(x.astype(complex)), dtype=complex)
        except (ZeroDivisionError, OverflowError):
            y = np.full(x.shape, np.nan, dtype=complex)
        y = y * np.ones_like(x)
    bad = ~np.isfinite(y) | (np.abs(y.imag) > 1e-12 * np.maximum(1.0, np.abs(y.real)))
    if bad.any() and fn.removable is not None:
        # a removable singularity (sin(x)/x at 0): the continuous extension's value
        with np.errstate(all="ignore"):
            fixed = np.asarray(fn.numpy(x[bad]), dtype=float)
        y[bad] = np.where(np.isfinite(fixed), fixed, y[bad])
        bad[bad] = ~np.isfinite(fixed)
    if bad.any():
        where = x[np.argmax(bad)]
        raise ValueError(f"{fn.expr} is not finite and real on [{iv.lo}, {iv.hi}] "
                         f"(for example at {fn.var} = {where:.6g}); accepted: an interval "
                         f"where the function is defined, finite and real")
    return y.real


def _one_sign(fn, iv, samples: int) -> bool:
    """Whether ``f`` is proven nonzero and of one sign at the float samples of
    :func:`check_interval` in ball arithmetic (128 bits): float64 reads a zero or a
    sign change where ``f`` is a cancellation (``1 - cos(x)`` at ``x = 1e-8``)."""
    from flint import arb

    from chebnorm.core.numeric import arb_precision

    x = np.linspace(iv.lo_in, iv.hi_in, samples)
    x[0], x[-1] = iv.lo_in, iv.hi_in
    signs = set()
    with arb_precision(128):
        for v in x:
            try:
                y = fn.arb(arb(float(v)))
            except (ValueError, ZeroDivisionError):
                return False
            if not y.is_finite() or y.contains(0):
                return False
            signs.add(y > 0)
            if len(signs) > 1:
                return False
    return True


def _certify_both(fn, coeffs, iv, need_rel: bool, shift=None, tight: bool = False,
                  known: dict | None = None):
    """Certificates of the absolute and relative errors (None for the relative
    one where f vanishes, unless ``need_rel``); ``known``: kind -> a certificate
    already computed by the same call, reused."""
    if tight:  # monomial tables only (quantize refuses the shifted basis)
        from .rounding import certify_tight

        def cert(*a):
            return certify_tight(*a)
    else:
        def cert(*a):
            return certify(*a, shift=shift)
    known = {k: c for k, c in (known or {}).items() if c is not None}
    cert_abs = known.get("abs") or cert(fn, coeffs, iv.lo, iv.hi, "abs")
    try:
        cert_rel = known.get("rel") or cert(fn, coeffs, iv.lo, iv.hi, "rel")
    except ValueError:
        if need_rel:
            raise ValueError(f"relative error is undefined: {fn.expr} vanishes on "
                             f"[{iv.lo}, {iv.hi}]; accepted for error='rel': an interval "
                             f"where the function has no zero") from None
        cert_rel = None
    return cert_abs, cert_rel


def fit(expr, interval, degree: int | None = None, kind: str = "chebyshev", error: str = "abs", *,
        var: str = "x", name: str | None = None, coef_frac_bits=None,
        command: str | None = None, basis: str = "auto", coef_format: str | None = None,
        monomials=None, fix_constant: bool = False, segments=None, segment_by: str | None = None,
        centered: bool = False, max_error: float | None = None, frac_bits=None):
    """Fit a polynomial of ``degree`` to ``expr`` on ``interval`` and certify it.

    Every table carries rigorous bounds of both its absolute and its relative
    error (see :mod:`chebnorm.approx.certify`).

    Parameters
    ----------
    expr : str, sympy.Expr or callable
        The function ``f``: text such as ``"1/sqrt(2+z)"`` (decimals exact,
        see :func:`~chebnorm.approx.read_expression`), a sympy expression
        (its Floats at their exact binary values), or a Python callable of
        one argument built from arithmetic, numpy ufuncs (``np.exp`` itself),
        :mod:`math` and sympy functions, traced into a sympy expression
        (:func:`chebnorm.approx.trace.trace_callable`; floats in it are the
        doubles it computes with: ``np.pi`` is not ``pi``).
    interval : pair
        ``(lo, hi)``: exact constants as text (``"sqrt(2)"``, ``"0.1"`` is
        1/10), sympy numbers, ints, or floats (at their exact binary value).
    degree : int, optional
        ``0 <= degree <= MAX_DEGREE``. Give either ``degree`` or ``max_error``
        (exactly one of them).
    kind : {"chebyshev", "minimax"}, optional
        Interpolation at the Chebyshev nodes (mpmath), or the Remez exchange.
    error : {"abs", "rel"}, optional
        The error the minimax fit minimizes: ``|p - f|`` or ``|p/f - 1|``.
    var : str or sympy.Symbol, optional
        The variable of ``expr`` (default ``"x"``).
    name : str, optional
        The table's name, an identifier (it names generated code); default: made
        from the expression, interval and degree (``"rsqrt_1_4_d3"`` for
        ``fit("1/sqrt(x)", (1, 4), 3)``; :func:`chebnorm.core.textsafe.default_name`),
        so the exports of different fits coexist in one build.
    coef_frac_bits : int or sequence of int, optional
        Also quantize the coefficients to fixed point with this many
        fractional bits (one, or one per power): see :func:`quantize`. For a
        piecewise table, the one fixed-point format (default 24).
    command : str, optional
        The command recorded in ``provenance["command"]``.
    basis : {"auto", "monomial", "shifted"}, optional
        ``"shifted"`` stores the polynomial in ``t = (x - c)/s`` (``c`` the
        midpoint, ``s`` a power of two at least the half-width; recorded in
        ``table.shift``), well conditioned on narrow or offset intervals where
        plain powers of ``x`` lose accuracy. ``"auto"`` (the default) keeps
        plain powers unless their binary32 Horner evaluation would lose what
        the fit gained and the shifted basis does better
        (:mod:`chebnorm.approx.basis_choice`; the choice and its reason in
        ``table.basis_choice``); quantized, constrained and piecewise fits
        are in plain powers.
    coef_format : {"fixed", "binary16", "bfloat16", "binary32", "binary64"}, optional
        Also quantize the coefficients to this format (:func:`quantize`).
    monomials : sequence of int, optional
        Keep only these powers (e.g. ``(1, 3, 5)``).
    fix_constant : bool, optional
        Hold the constant coefficient at ``f(0)`` rounded to its format.
    segments : int or str, optional
        ``2**k`` segments, or ``"auto"`` with ``max_error``: a piecewise table instead
        (:func:`~chebnorm.approx.piecewise_fit.piecewise_fit`).
    segment_by : {"uniform", "exponent"}, optional
        How a piecewise table's segments are indexed.
    centered : bool, optional
        Piecewise: each segment's polynomial in ``t - 1/2``.
    max_error : float, optional
        Instead of ``degree``: the smallest degree whose certified error --
        ``|p - f|`` or ``|p/f - 1|`` as ``error``, of the quantized
        coefficients when a format is given -- is at most ``max_error``
        (a finite number > 0). Degrees that a de la Vallee Poussin lower
        bound rules out are not fitted; the others are fitted and certified
        from the lowest up. ``provenance["degree_search"]`` records every
        degree tried and why it lost. The search stops (ValueError) when
        four certified degrees in a row gain under 1% (the
        rounding floor of float64 coefficients), or at ``MAX_DEGREE``. Not
        with ``degree``, except with ``segments="auto"``: then the fewest
        segments (``2**k``) whose piecewise table of ``degree`` is certified
        to ``max_error`` (``provenance["segment_search"]``).
    frac_bits : int or sequence of int, optional
        The deprecated spelling of ``coef_frac_bits`` (a
        :class:`~chebnorm.core.deprecation.ChebnormDeprecationWarning`).

    Returns
    -------
    CoefficientTable or PiecewiseTable
        The certified table (a :class:`~chebnorm.approx.PiecewiseTable` with
        ``segments``, ``segment_by`` or ``centered``).

    Raises
    ------
    ValueError
        For an argument out of its accepted range (the message names the
        argument and the accepted values), an expression that cannot be
        read or traced, or a function that is not finite and real on the
        interval.

    Warns
    -----
    FitWarning
        The Remez exchange did not converge, a minimax fit lost to a simpler
        polynomial, a bound missed its tightness (the bounds still hold), or
        (``basis="auto"``) the float32 evaluator's estimated error exceeds 4x
        (fit + float32 rounding floor) in every basis.

    See Also
    --------
    quantize : round the coefficients and re-certify.
    chebnorm.approx.certify : the certificate of given coefficients.
    chebnorm.approx.piecewise_fit.piecewise_fit : the piecewise fit of ``segments``.
    chebnorm.export : the table as C, GLSL, WGSL, HLSL, Verilog, VHDL or JSON.
    chebnorm.hw.design_horner : a bit-accurate fixed-point evaluator of the table.

    Notes
    -----
    ``kind="chebyshev"`` interpolates :math:`f` at the :math:`n + 1`
    Chebyshev points of the first kind on :math:`[a, b]`,

    .. math::

        x_k = \\frac{a + b}{2} + \\frac{b - a}{2}
              \\cos\\frac{(2k + 1)\\pi}{2(n + 1)}, \\qquad k = 0, \\dots, n,

    so its error is at most :math:`2 + \\frac{2}{\\pi}\\log(n + 1)` times the
    best possible (one plus the Lebesgue constant of these points [1]_ [2]_).
    ``kind="minimax"`` runs the Remez exchange [1]_ for the polynomial of
    degree :math:`n` that minimizes

    .. math::

        \\max_{x \\in [a, b]} |p(x) - f(x)| \\quad\\text{or}\\quad
        \\max_{x \\in [a, b]} \\left|\\frac{p(x)}{f(x)} - 1\\right|

    (``error="abs"`` or ``"rel"``); its error equioscillates at :math:`n + 2`
    points (a :class:`FitWarning` when the exchange does not converge).
    Either way the stored float64 coefficients, as exact binary numbers, are
    certified by :func:`chebnorm.approx.certify` (the problem Sollya's
    ``supnorm`` solves [3]_): ``abs_error_bound`` and ``rel_error_bound``
    are rigorous upper bounds of the two maxima above.

    Choice of degree: each extra degree buys roughly a factor
    ``(hi - lo) / (4 * distance to the nearest singularity)`` of accuracy; far
    from 0 at high degree prefer ``basis="shifted"``.

    The first example is the degree-2 dichotomy polynomial of seed 000 [4]_.

    References
    ----------
    .. [1] L. N. Trefethen, *Approximation Theory and Approximation
       Practice*, SIAM, 2013 (Chebyshev interpolation, Lebesgue constants,
       the Remez algorithm).
    .. [2] T. J. Rivlin, *Chebyshev Polynomials*, 2nd ed., Wiley, 1990.
    .. [3] S. Chevillard, J. Harrison, M. Joldes, C. Lauter, "Efficient and
       accurate computation of upper bounds of approximation errors",
       Theoretical Computer Science 412(16), 2011; Sollya,
       https://www.sollya.org/
    .. [4] The four papers chebnorm reproduces (seeds 000 to 003), restated
       with their formulas re-derived in :doc:`/papers`.

    Examples
    --------
    Seed 000, method 4 (claim C5): the degree-2 Chebyshev fit of
    ``1/sqrt(2+z)`` on ``[sqrt(2), 2]``:

    >>> t = fit("1/sqrt(2+z)", ("sqrt(2)", 2), 2, var="z")
    >>> [round(c, 5) for c in t.coefficients]
    [0.68076, -0.11881, 0.01422]
    >>> round(t.max_abs_error, 7), t.abs_error_bound >= t.max_abs_error
    (2.16e-05, True)

    A callable is traced, a sympy expression taken as it is; both give the
    table of the text:

    >>> import numpy as np, sympy as sp
    >>> fit(np.exp, (0, 1), 5).coefficients == fit("exp(x)", (0, 1), 5).coefficients
    True
    >>> z = sp.Symbol("z")
    >>> fit(1 / sp.sqrt(2 + z), ("sqrt(2)", 2), 2, var=z) == t
    True

    The shifted basis where monomials lose accuracy:

    >>> m = fit("sin(x)", ("100", "101"), 12, kind="minimax", basis="monomial")
    >>> s = fit("sin(x)", ("100", "101"), 12, kind="minimax", basis="shifted")
    >>> s.shift, s.abs_error_bound < 1e-16, m.abs_error_bound > 1e-3
    ((100.5, 0.5), True, True)

    A piecewise table:

    >>> pw = fit("1/sqrt(x)", ("1", "4"), 2, kind="minimax", segments=16, coef_frac_bits=20)
    >>> pw.segment_count, 4e-5 < pw.abs_error_bound < 5e-5
    (16, True)
    """
    frac_bits = renamed(frac_bits, coef_frac_bits, "frac_bits", "coef_frac_bits", "fit")
    if max_error is not None or degree is None or segments == "auto":
        return _fit_max_error(expr, interval, degree, max_error, dict(
            kind=kind, error=error, var=var, name=name, coef_frac_bits=frac_bits, command=command,
            basis=basis, coef_format=coef_format, monomials=monomials,
            fix_constant=fix_constant, segments=segments, segment_by=segment_by,
            centered=centered))
    name = _table_name(name)
    expr, var = as_expression(expr, var)
    if segments is not None or segment_by is not None or centered:
        return _fit_segments(expr, interval, degree, kind, error, var=var, name=name,
                             frac_bits=frac_bits, command=command, basis=basis,
                             coef_format=coef_format, monomials=monomials,
                             fix_constant=fix_constant, segments=segments,
                             segment_by=segment_by, centered=centered)
    quantized = frac_bits is not None or coef_format is not None
    constrained = monomials is not None or fix_constant
    degree = _check_fit_args(degree, kind, error, basis, quantized, constrained)
    try:
        lo, hi = interval
    except (TypeError, ValueError):
        raise ValueError(f"interval {interval!r} must be a pair (LO, HI)") from None
    fn = expr if isinstance(expr, Function1D) else parse_function(expr, var)
    iv = Interval(lo, hi)
    samples = check_interval(fn, iv)
    if error == "rel" and (np.any(samples == 0) or np.ptp(np.sign(samples)) > 0):
        if not _one_sign(fn, iv, samples.size):
            raise ValueError(f"relative error is undefined: {fn.expr} vanishes on "
                             f"[{iv.lo}, {iv.hi}]; accepted for error='rel': an interval where "
                             f"the function has no zero")
        # float64 reads zeros that are not there: fit from the function's true values
        fn = AccurateFunction1D(fn.expr, fn.var)

    mons, fixc = monomials if constrained and not quantized else None, fix_constant and not quantized
    fitted, choice = None, None
    if basis == "auto":
        basis, fitted, choice = _auto_basis(fn, iv, degree, kind, error, mons, fixc,
                                            quantized or constrained)
    shift = shift_for(iv.lo_f, iv.hi_f) if basis == "shifted" else None
    coeffs, notes, extra, cert_abs, cert_rel = _real_fit(fn, iv, degree, kind, error, shift, mons,
                                                         fixc, fitted)
    _warn(notes)
    provenance = dict(versions())
    provenance.update(extra)
    provenance["command"] = command or (
        f"chebnorm.fit({str(fn.expr)!r}, {iv.strings!r}, {degree}, kind={kind!r}, "
        f"error={error!r}, var={var!r})")
    if iv.binary_note():
        provenance["binary_endpoints"] = iv.binary_note()
    if notes:
        provenance["warnings"] = " | ".join(notes)
    with construction("fitted"):  # certified above: checked, not proved twice
        table = CoefficientTable(
            name=name or default_name(sp.sstr(fn.expr), iv.strings, degree, fn.var.name),
            expression=sp.sstr(fn.expr), variable=fn.var.name,
            interval=iv.strings, interval_float=(iv.lo_f, iv.hi_f), degree=degree, kind=kind,
            error_kind=error, coefficients=tuple(coeffs),
            abs_error_bound=cert_abs.bound, rel_error_bound=None if cert_rel is None else cert_rel.bound,
            max_abs_error=cert_abs.maximum, max_abs_at=cert_abs.at,
            max_rel_error=None if cert_rel is None else cert_rel.maximum,
            max_rel_at=None if cert_rel is None else cert_rel.at,
            provenance=provenance, shift=shift, basis_choice=choice)
    if quantized:
        table = quantize(table, frac_bits, coef_format=coef_format or "fixed",
                         monomials=monomials, fix_constant=fix_constant)
    return table


def _function_on(expr, var, interval):
    """``(Function1D, Interval)`` of a search's expression and interval."""
    expr_in, var = as_expression(expr, var)
    fn = expr_in if isinstance(expr_in, Function1D) else parse_function(expr_in, var)
    try:
        lo, hi = interval
    except (TypeError, ValueError):
        raise ValueError(f"interval {interval!r} must be a pair (LO, HI)") from None
    return fn, Interval(lo, hi)


def _fit_max_error(expr, interval, degree, max_error, kw):
    """:func:`fit` with ``max_error``: the smallest degree whose certified error
    is at most ``max_error`` (see the parameter), the search recorded in
    ``provenance["degree_search"]``."""
    import dataclasses

    if degree is None and max_error is None:
        raise ValueError(f"degree is missing; accepted: an integer 0 <= degree <= "
                         f"{MAX_DEGREE}, or max_error=E (a finite number > 0) for the "
                         f"smallest degree whose certified error is at most E")
    if kw["segments"] == "auto":
        if degree is None or max_error is None:
            raise ValueError("segments='auto' needs both the degree and max_error: the "
                             "fewest segments whose certified error at that degree is at "
                             "most max_error; accepted: fit(expr, interval, degree, "
                             "segments='auto', max_error=E)")
    elif degree is not None and max_error is not None:
        raise ValueError(f"degree {degree!r} and max_error {max_error!r} are both given; "
                         f"accepted: one of them (max_error chooses the degree), or both with "
                         f"segments='auto' (max_error chooses the segment count)")
    if isinstance(max_error, bool) or not isinstance(max_error, (int, float, np.integer,
                                                                 np.floating)) \
            or not math.isfinite(float(max_error)) or not max_error > 0:
        raise ValueError(f"max_error {max_error!r}: accepted: a finite number > 0, e.g. "
                         f"1e-6 or 2**-20")
    if kw["segments"] == "auto":
        return _fit_segments_auto(expr, interval, degree, float(max_error), kw)
    if kw["segments"] is not None or kw["segment_by"] is not None or kw["centered"]:
        raise ValueError("max_error with segments, segment_by or centered: accepted: "
                         "max_error for one polynomial (give the degree and "
                         "segments='auto' for a piecewise table)")
    max_error = float(max_error)
    error = kw["error"]
    # the arguments are checked once, by a degree-0 check of fit's own
    quantized = kw["coef_frac_bits"] is not None or kw["coef_format"] is not None
    constrained = kw["monomials"] is not None or kw["fix_constant"]
    _check_fit_args(0, kw["kind"], error, kw["basis"], quantized, constrained)
    fn, iv = _function_on(expr, kw["var"], interval)
    check_interval(fn, iv)
    lower = degree_lower_bounds(fn, iv, error, MAX_DEGREE)
    mons = kw["monomials"]
    top = MAX_DEGREE
    first = 0
    if mons is not None:
        try:
            first = max(int(k) for k in mons)
        except (TypeError, ValueError):
            first = 0
    tried, bounds = [], []
    best = None
    for n in range(first, top + 1):
        if lower[n] > max_error:
            tried.append(f"{n}: ruled out (>= {format_down(lower[n], '.2e')})")
            continue
        table = fit(expr, interval, n, **{k: v for k, v in kw.items()
                                           if k not in ("segments", "segment_by", "centered")})
        bound = _delivered_bound(table, error)
        ok = bound is not None and bound <= max_error
        tried.append(f"{n}: certified {format_up(bound, '.3e')}" + (" <= E" if ok else " > E"))
        if ok:
            best = table
            break
        bounds.append(bound)
        if len(bounds) >= STALL_DEGREES and bounds[-STALL_DEGREES] <= 1.01 * min(
                bounds[-STALL_DEGREES:]):
            tried.append(f"stopped: {STALL_DEGREES} degrees in a row gained less than 1% "
                         f"(the float64 coefficients' rounding floor)")
            break
    if best is None:
        raise ValueError(f"no degree up to {MAX_DEGREE} reaches max_error {max_error:.6g} "
                         f"for {fn.expr} on [{iv.lo}, {iv.hi}] (tried: {'; '.join(tried[-4:])}); "
                         f"accepted: a larger max_error, or piecewise tables (segments)")
    provenance = dict(best.provenance)
    provenance["max_error"] = repr(max_error)
    provenance["degree_search"] = _search_text(tried, "degrees tried")
    with construction("fitted"):  # the same table, its search recorded
        return dataclasses.replace(best, provenance=provenance)


def _fit_segments_auto(expr, interval, degree, max_error: float, kw):
    """:func:`fit` with ``segments="auto"``: the fewest segments (``2**k``,
    ``k <= 12``) whose piecewise table of ``degree`` is certified to
    ``max_error``; counts whose best error per segment a de la Vallee Poussin
    bound puts above ``max_error`` are not fitted. The search is recorded in
    ``provenance["segment_search"]``."""
    import dataclasses

    from .piecewise_table import segment_bounds, segment_count

    error = kw["error"]
    fn, iv = _function_on(expr, kw["var"], interval)
    segment_by = kw["segment_by"] or "uniform"
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) \
            or not 0 <= degree <= MAX_DEGREE:
        raise ValueError(f"degree {degree!r}: accepted: an integer 0 <= degree <= {MAX_DEGREE}")
    tried = []
    fields = {k: v for k, v in kw.items() if k not in ("segments", "segment_by")}
    for k in range(0, 13):
        try:
            count = segment_count(segment_by, iv.lo, iv.hi, k)
        except ValueError:
            break
        lower = 0.0
        for s in range(count):
            a, b = (float(v) for v in segment_bounds(segment_by, iv.lo, iv.hi, k, s))
            lower = max(lower, _dlvp_bounds(fn, a, b, error, int(degree))[int(degree)])
            if lower > max_error:
                break
        if lower > max_error:
            tried.append(f"{count}: ruled out (>= {format_down(lower, '.2e')})")
            continue
        table = fit(expr, interval, degree, segments=2 ** k, segment_by=segment_by, **fields)
        bound = table.abs_error_bound if error == "abs" else table.rel_error_bound
        ok = bound is not None and bound <= max_error
        tried.append(f"{count}: certified {format_up(bound, '.3e')}" + (" <= E" if ok else " > E"))
        if ok:
            provenance = dict(table.provenance)
            provenance["max_error"] = repr(max_error)
            provenance["segment_search"] = _search_text(tried, "segment counts tried")
            with construction("fitted"):  # the same table, its search recorded
                return dataclasses.replace(table, provenance=provenance)
    raise ValueError(f"no segment count up to 2^12 reaches max_error {max_error:.6g} at "
                     f"degree {degree} for {fn.expr} on [{iv.lo}, {iv.hi}] (tried: "
                     f"{'; '.join(tried[-3:])}); accepted: a larger max_error, a higher "
                     f"degree or more coefficient bits (coef_frac_bits)")


def _search_text(tried: list[str], what: str) -> str:
    """The search's record for provenance (at most 1000 characters: the middle
    entries are elided when it would be longer). "ruled out (>= L)": a de la
    Vallee Poussin lower bound L of the best error above E; "certified B": the
    certified bound B of that fit, compared with E = ``max_error``."""
    head = f"{what}: "
    text = head + "; ".join(tried)
    k = len(tried)
    while len(text) > 1000 and k > 2:
        k -= 1
        text = head + "; ".join(tried[:k // 2] + ["..."] + tried[len(tried) - (k - k // 2):])
    return text


#: the degree search stops when this many certified degrees in a row gain under 1%
STALL_DEGREES = 4


def _delivered_bound(table, error: str) -> float | None:
    """The certified bound of the coefficients ``table`` delivers (quantized
    when it is), absolute or relative as ``error``."""
    q = table.quantized
    if q is not None:
        return q.abs_error_bound if error == "abs" else q.rel_error_bound
    fp = getattr(table, "fixed_point", None)
    if fp is not None:
        return fp.abs_error_bound if error == "abs" else getattr(fp, "rel_error_bound", None)
    return table.abs_error_bound if error == "abs" else table.rel_error_bound


def degree_lower_bounds(fn: Function1D, iv: Interval, error: str, top: int) -> list[float]:
    """Cheap lower bounds of the best error at each degree ``0..top`` (0 when
    none is found): de la Vallee Poussin's theorem on the Chebyshev
    interpolant of degree ``n``.

    If ``f - p`` (or ``(f - p)/f``) takes alternating signs at ``n + 2``
    ordered points, every polynomial of degree ``n`` has an error at least
    the smallest of those ``|f - p|``. ``p`` is the float64 Chebyshev
    interpolant truncated to degree ``n``, the points the extrema of
    ``T_{n+1}``; the bound is lowered by ``64`` units of float64's rounding
    of ``max |f|`` (relative: of 1) so that sampling noise never rules out a
    degree that could win. A pruning aid of the degree search: a degree it
    rules out would need an error above the bound.

    Parameters
    ----------
    fn : Function1D
        The function.
    iv : Interval
        The interval.
    error : {"abs", "rel"}
        The error measured.
    top : int
        The highest degree.

    Returns
    -------
    list of float
        ``top + 1`` lower bounds (0.0 where the signs do not alternate).
    """
    return _dlvp_bounds(fn, iv.lo_in, iv.hi_in, error, top)


def _dlvp_bounds(fn: Function1D, a: float, b: float, error: str, top: int) -> list[float]:
    """:func:`degree_lower_bounds` on the float interval ``[a, b]``."""
    m = min(max(2 * top + 8, 64), 256)
    k = np.arange(m)
    t_nodes = np.cos(np.pi * (k + 0.5) / m)
    with np.errstate(all="ignore"):
        fv = np.asarray(fn.numpy(0.5 * (a + b) + 0.5 * (b - a) * t_nodes), dtype=float)
    out = [0.0] * (top + 1)
    if not np.all(np.isfinite(fv)):
        return out
    # Chebyshev coefficients of the interpolant of degree m - 1 (discrete cosine transform)
    coef = np.array([2.0 / m * np.sum(fv * np.cos(np.pi * j * (k + 0.5) / m)) for j in range(m)])
    coef[0] /= 2
    scale = float(np.max(np.abs(fv))) or 1.0
    noise = 64 * 2.0 ** -52 * (scale if error == "abs" else 1.0) * max(1.0, np.sum(np.abs(coef)) / scale)
    for n in range(top + 1):
        t = np.cos(np.pi * np.arange(n + 2) / (n + 1))
        x = 0.5 * (a + b) + 0.5 * (b - a) * t
        with np.errstate(all="ignore"):
            f = np.asarray(fn.numpy(x), dtype=float)
            e = f - np.polynomial.chebyshev.chebval(t, coef[:n + 1])
            if error == "rel":
                e = e / f
        if not np.all(np.isfinite(e)):
            continue
        s = np.sign(e)
        if np.all(s[1:] == -s[:-1]) and np.all(s != 0):
            out[n] = max(0.0, float(np.min(np.abs(e))) - noise)
    # the best error does not grow with the degree: E_n >= E_{n+1} >= its bound
    for n in range(top - 1, -1, -1):
        out[n] = max(out[n], out[n + 1])
    return out


def as_expression(expr, var="x"):
    """``(expression, variable name)`` as :func:`fit` reads its ``expr`` and ``var``.

    Parameters
    ----------
    expr : str, sympy.Expr, Function1D or callable
        Text such as ``"exp(x)"`` and sympy expressions are returned as they
        are (:func:`~chebnorm.approx.parse_function` reads them); a callable
        (``np.exp``, ``lambda x: 1 / np.sqrt(x)``, a function using
        :mod:`math`) is traced into a sympy expression
        (:func:`chebnorm.approx.trace.trace_callable`).
    var : str or sympy.Symbol
        The variable (a Symbol stands for its name).

    Returns
    -------
    tuple
        ``(expr, name)``: ``expr`` text, a sympy expression or a Function1D;
        ``name`` the variable's name (str).

    Raises
    ------
    ValueError
        When ``var`` is neither a string nor a Symbol, or a callable cannot
        be traced (the message says to pass a string or a sympy expression).

    Examples
    --------
    >>> import numpy as np, sympy as sp
    >>> as_expression(np.exp, sp.Symbol("t"))
    (exp(t), 't')
    >>> as_expression("exp(x)", "x")
    ('exp(x)', 'x')
    """
    if isinstance(var, sp.Symbol):
        var = var.name
    if not isinstance(var, str):
        raise ValueError(f"var of type {type(var).__name__} is not accepted; accepted: a "
                         f"string naming the variable, such as 'x', or a sympy Symbol")
    if callable(expr) and not isinstance(expr, (str, sp.Basic, Function1D)):
        from chebnorm.core.textsafe import identifier

        from .trace import trace_callable

        expr = trace_callable(expr, sp.Symbol(identifier(var, field="var")))
    return expr, var


def _fit_real(fn, iv, degree, kind, error, shift, monomials, fix_constant):
    """``(coefficients, notes, provenance entries)`` of the real fit of
    :func:`fit` (constrained to ``monomials`` / ``fix_constant`` when given)."""
    if monomials is not None or fix_constant:
        mons = _monomials(monomials, degree, fix_constant)
        fixed = _fixed_constant(fn, "binary64", None) if fix_constant else {}
        return _constrained_fit(fn, iv, degree, mons, fixed, error, report=True)
    return _fit_coefficients(fn, iv, degree, kind, error, shift)


def _auto_basis(fn, iv, degree, kind, error, monomials, fix_constant, forced: bool):
    """``(basis, fitted, BasisChoice)`` of ``basis="auto"``: ``fitted`` the
    :func:`_fit_real` result in the chosen basis. The shifted basis is offered
    to a plain fit of degree >= 2 whose shift has a nonzero centre (a centre
    0 only scales by a power of two); its warning joins the fit's notes."""
    from .basis_choice import choose

    shift = shift_for(iv.lo_f, iv.hi_f)
    offer = not forced and degree >= 2 and shift[0] != 0
    fits = {}

    def candidates(basis):
        if basis == "shifted" and not offer:
            return None
        s = shift if basis == "shifted" else None
        fits[basis] = _fit_real(fn, iv, degree, kind, error, s, monomials, fix_constant)
        return fits[basis][0], s

    choice, note = choose(fn.numpy, iv.lo_f, iv.hi_f, candidates)
    coeffs, notes, extra = fits[choice.basis]
    if note and not forced:
        notes = [*notes, note]
    return choice.basis, (coeffs, notes, extra), choice


def _real_fit(fn, iv, degree, kind, error, shift, monomials, fix_constant, fitted=None):
    """The real coefficients of :func:`fit` (``fitted``: :func:`_fit_real`'s
    result, when already computed), their notes, provenance entries and
    certificates."""
    constrained = monomials is not None or fix_constant
    coeffs, notes, extra = fitted or _fit_real(fn, iv, degree, kind, error, shift, monomials,
                                               fix_constant)
    notes = list(notes)
    cert_abs, cert_rel = _certify_both(fn, coeffs, iv, error == "rel", shift)
    if kind == "minimax" or constrained:
        # a fit in fewer powers may lose to a lower-degree one: only the zero polynomial
        notes += _simpler_fit_notes(fn, iv, degree if not constrained else 0, error, cert_abs,
                                    cert_rel)
    notes += _certificate_notes(abs_error_bound=cert_abs, rel_error_bound=cert_rel)
    return coeffs, notes, extra, cert_abs, cert_rel


def _in_powers_of_x(table: CoefficientTable) -> CoefficientTable:
    """A table whose shifted basis ``basis="auto"`` chose, refitted in powers of
    ``x`` (what quantization rounds), its choice recorded as forced; any other
    table as it is (an explicitly shifted one is refused by the caller)."""
    if table.shift is None or table.basis_choice is None:
        return table
    import dataclasses

    from .basis_choice import BasisChoice, choose

    mono = fit(table.expression, table.interval, table.degree, kind=table.kind,
               error=table.error_kind, var=table.variable, name=table.name, basis="monomial",
               command=table.provenance.get("command"))
    fn = parse_function(table.expression, table.variable)
    only, _ = choose(fn.numpy, *mono.interval_float,
                     lambda b: (mono.coefficients, None) if b == "monomial" else None)
    choice = BasisChoice("monomial", f"quantized: coefficients in powers of x; {only.reason}",
                         only.floor, only.estimates)
    with construction("fitted"):
        return dataclasses.replace(mono, basis_choice=choice)


def _check_fit_args(degree, kind: str, error: str, basis: str, quantized: bool,
                    constrained: bool = False) -> int:
    """``degree`` as an int, after checking :func:`fit`'s arguments."""
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)):
        raise ValueError(f"degree {degree!r} is not an integer; accepted: 0 <= degree <= {MAX_DEGREE}")
    degree = int(degree)
    if not 0 <= degree <= MAX_DEGREE:
        raise ValueError(f"degree {degree} is out of range; accepted: 0 <= degree <= {MAX_DEGREE}")
    if kind not in KINDS:
        raise ValueError(f"kind {kind!r} is unknown; accepted: {', '.join(KINDS)}")
    if error not in ERROR_KINDS:
        raise ValueError(f"error kind {error!r} is unknown; accepted: {', '.join(ERROR_KINDS)}")
    if basis not in ("auto", *BASES):
        raise ValueError(f"basis {basis!r} is unknown; accepted: {', '.join(('auto', *BASES))}")
    if basis == "shifted" and (quantized or constrained):
        raise ValueError("quantized coefficients (coef_frac_bits, coef_format, monomials, "
                         "fix_constant) with basis shifted are not supported; accepted: "
                         "basis monomial for quantized tables")
    if constrained and not quantized and kind != "minimax":
        raise ValueError(f"kind {kind!r} with monomials or fix_constant and no coefficient "
                         f"format; accepted: kind 'minimax' (the best real polynomial in those "
                         f"powers), or a coef_frac_bits or coef_format to quantize")
    return degree


def _fit_segments(expr, interval, degree, kind, error, *, var, name, frac_bits, command, basis,
                  coef_format, monomials, fix_constant, segments, segment_by, centered):
    """:func:`fit` with ``segments``/``segment_by``/``centered``: a piecewise table."""
    from .piecewise_fit import piecewise_fit

    if basis not in ("auto", "monomial"):
        raise ValueError(f"basis {basis} applies to one polynomial; accepted with segments, "
                         f"segment_by or centered: basis monomial (centered evaluates each "
                         f"segment about its middle)")
    if coef_format not in (None, "fixed") or monomials is not None or fix_constant:
        raise ValueError("coef_format, monomials and fix_constant apply to one polynomial; "
                         "accepted with segments, segment_by or centered: fixed-point "
                         "coefficients (coef_frac_bits F, one integer)")
    if isinstance(frac_bits, (list, tuple)):
        raise ValueError(f"coef_frac_bits {','.join(map(str, frac_bits))}: piecewise tables share "
                         f"one format; accepted: one integer")
    return piecewise_fit(expr, tuple(interval), degree, segments=segments or 1,
                         segment_by=segment_by or "uniform",
                         coef_frac_bits=24 if frac_bits is None else frac_bits,
                         centered=centered, fit=kind, error=error, var=var,
                         name=name, command=command)


def _fit_coefficients(fn: Function1D, iv: Interval, degree: int, kind: str, error: str,
                      shift: tuple[float, float] | None):
    """The fitted float coefficients (in ``t = (x - c)/s`` with ``shift``),
    the notes on how the fit went and the provenance entries to add.

    A minimax fit of an even or odd ``f`` on a symmetric interval is the best
    polynomial in the powers of that parity (:func:`_constrained_fit`, which
    fits on the half interval): the plain exchange meets ``n + 3``
    alternation points there and need not converge."""
    notes, extra = [], {}
    parity = _parity(fn, iv) if kind == "minimax" and degree >= 1 else None
    if parity is not None:
        powers = tuple(range(0 if parity == "even" else 1, degree + 1, 2))
        coeffs, notes, extra = _constrained_fit(fn, iv, degree, powers, {}, error, report=True)
        extra = {"parity": f"{fn.expr} is {parity} on the symmetric interval: fitted in the "
                           f"{parity} powers {','.join(map(str, powers))} on [0, HI] "
                           f"(the best polynomial of degree {degree} has no other powers)"}
        if shift is not None:   # centre 0: t = x/s, s a power of two (exact)
            coeffs = [c * shift[1] ** k for k, c in enumerate(coeffs)]
        return coeffs, notes, extra
    if kind == "chebyshev" and shift is not None:
        c, s = (sp.Float(v, 60) for v in shift)
        f_mp = fn.mpmath
        coeffs = chebyshev_interpolant(lambda t: f_mp(c + s * t), sp.N((iv.lo - c) / s, 50),
                                       sp.N((iv.hi - c) / s, 50), degree)
    elif kind == "chebyshev":
        coeffs = chebyshev_interpolant(fn.mpmath, sp.N(iv.lo, 50), sp.N(iv.hi, 50), degree)
    else:
        f_np = fn.numpy
        weight = None if error == "abs" else (lambda x: 1.0 / np.abs(f_np(x)))
        res = remez(f_np, weight, iv.lo_f, iv.hi_f, degree)
        cheb = res.cheb
        polished = res.noise_limited and res.ref is not None and len(res.ref) == degree + 2
        if polished:
            # the float64 solve limits the error: re-solve the same reference in 50 digits
            cheb = polish(fn.mpmath, iv.lo_f, iv.hi_f, res.ref, degree, relative=error == "rel")
        coeffs = cheb_to_monomial(cheb, iv.lo_f, iv.hi_f, *(shift or (0.0, 1.0)))
        if not res.converged and not polished:
            # degenerate alternation (a nearly even or odd f, ...): the exchange on a
            # growing point set needs no alternation, and wins when it is better
            other = minimax_powers(fn, iv.lo_f, iv.hi_f, degree, tuple(range(degree + 1)),
                                   relative=error == "rel")
            if other.converged and other.max_error < res.max_error:
                c_s, s_s = shift or (0.0, 1.0)
                coeffs = other.coefficients if shift is None else _shifted(
                    other.coefficients, c_s, s_s)
                extra["exchange"] = ("the Remez exchange did not converge; the linear-programming "
                                     "exchange on a growing point set did")
            else:
                notes.append(
                    f"the Remez exchange did not converge: the coefficients are its best iterate "
                    f"(iteration {res.iterations}: levelled error {res.levelled:.3e}, largest "
                    f"error {res.max_error:.3e}), not the minimax polynomial, and kind chebyshev "
                    f"may be closer; the certified bounds hold")
    return coeffs, notes, extra


def _shifted(coeffs, c: float, s: float) -> list[float]:
    """Coefficients in ``x`` re-expressed in ``t = (x - c)/s`` (exact, rounded once)."""
    from flint import fmpq_poly

    from .fitting import exact_rational

    poly = fmpq_poly([exact_rational(v) for v in coeffs])
    out = poly(fmpq_poly([exact_rational(c), exact_rational(s)])).coeffs()
    return [int(q.p) / int(q.q) for q in out] + [0.0] * (len(coeffs) - len(out))


def _parity(fn: Function1D, iv: Interval) -> str | None:
    """``"even"`` or ``"odd"`` when ``f`` is (sympy proves ``f(-x) -+ f(x) = 0``)
    and the interval is symmetric about 0 (exactly); else None."""
    try:
        if sp.simplify(iv.lo + iv.hi) != 0:
            return None
    except (TypeError, ValueError):
        return None
    x = fn.var
    probe = np.array([0.3, 0.7, 0.9]) * iv.hi_f
    with np.errstate(all="ignore"):
        a = np.asarray(fn.numpy(probe), dtype=float) * np.ones(3)
        b = np.asarray(fn.numpy(-probe), dtype=float) * np.ones(3)
    scale = np.maximum(np.abs(a), 1e-300)
    for name, diff, sign in (("even", a - b, -1), ("odd", a + b, 1)):
        if np.all(np.abs(diff) <= 1e-12 * scale):   # quick numeric screen, then a proof
            mirrored = fn.expr.subs(x, -x)
            try:
                if sp.simplify(mirrored + sign * fn.expr) == 0:
                    return name
            except (TypeError, ValueError, RecursionError):
                return None
    return None


def _constrained_fit(fn, iv, degree, powers, fixed, error_kind, report: bool = False):
    """Real coefficients (all powers) of the minimax fit in the given powers,
    the ``fixed`` ones (power -> (mantissa, exponent)) held
    (:func:`~chebnorm.approx.fitting.minimax_powers`). On a symmetric interval
    where ``f`` and every power share a parity, it fits on ``[0, HI]`` (the
    same best polynomial, a Haar system there). With ``report``, also the
    notes and the provenance entries."""
    held = {k: math.ldexp(m, e) for k, (m, e) in fixed.items()}
    parity = _parity(fn, iv) if iv.lo_f < 0 < iv.hi_f else None
    want = {"even": 0, "odd": 1}.get(parity)
    half = want is not None and all(k % 2 == want for k in powers) and all(
        k % 2 == want or c == 0 for k, c in held.items())
    lo = 0.0 if half else iv.lo_f
    r = minimax_powers(fn, lo, iv.hi_f, degree, powers, fixed=held, relative=error_kind == "rel")
    if not report:
        return r.coefficients
    notes = [] if r.converged else [
        f"the minimax fit in the powers {','.join(map(str, powers))} did not converge: level "
        f"{r.level:.3e}, largest error {r.max_error:.3e} after {r.rounds} rounds; the "
        f"certified bounds hold"]
    extra = {"constraint": f"best polynomial in the powers {','.join(map(str, powers))}"
             + (f", p(0) held at f(0) rounded to binary64 = {held[0]!r}" if 0 in held else "")
             + (f" ({parity} f: fitted on [0, HI])" if half else "")}
    return r.coefficients, notes, extra


def _simpler_fit_notes(fn, iv, degree, error, cert_abs, cert_rel) -> list[str]:
    """A note when a (minimax) fit's located error exceeds the sampled error of
    the zero polynomial or of a Chebyshev interpolant of degree below ``degree``."""
    cert = cert_abs if error == "abs" else cert_rel
    if cert is None:
        return []
    x = np.cos(np.pi * np.arange(2001) / 2000)[::-1]
    xs = 0.5 * (iv.lo_f + iv.hi_f) + 0.5 * (iv.hi_f - iv.lo_f) * x
    with np.errstate(all="ignore"):
        fx = np.asarray(fn.numpy(xs), dtype=float) * np.ones_like(xs)
        w = np.ones_like(fx) if error == "abs" else 1.0 / np.abs(fx)
        ok = np.isfinite(fx) & np.isfinite(w)
        rivals = [("the zero polynomial", float(np.max(np.abs(w * fx)[ok])))]
        full = np.polynomial.chebyshev.chebinterpolate(
            lambda t: fn.numpy(0.5 * (iv.lo_f + iv.hi_f) + 0.5 * (iv.hi_f - iv.lo_f) * t)
            * np.ones_like(t), degree)
        for d in range(degree):
            e = w * (np.polynomial.chebyshev.chebval(x, full[:d + 1]) - fx)
            rivals.append((f"the degree-{d} Chebyshev interpolant", float(np.max(np.abs(e[ok])))))
    name, best = min(rivals, key=lambda r: r[1])
    if not cert.maximum > 1.01 * best:
        return []
    what = "|p - f|" if error == "abs" else "|p/f - 1|"
    return [f"the minimax fit is not minimax: its error {what} = {format_up(cert.maximum, '.3e')} "
            f"exceeds "
            f"that of {name} (sampled: {best:.3e}); the exchange failed on this problem "
            f"(try a lower degree or a narrower interval); the certified bounds hold"]


def _certificate_notes(**certs: Certificate | None) -> list[str]:
    """One warning per certificate that missed its ``(1 + tol)`` tightness."""
    return [f"{field} is rigorous but not within 1 + 2^-8 of the supremum: {c.reason}"
            for field, c in certs.items() if c is not None and not c.tight]


def warnings_of(table: CoefficientTable) -> list[str]:
    """The warnings a table's provenance carries (Remez not converged, a
    certificate that missed its tightness), one string each.

    Parameters
    ----------
    table : CoefficientTable
        A table from :func:`fit`, :func:`quantize` or a file.

    Returns
    -------
    list of str
        The warnings of ``table.provenance["warnings"]`` (split at ``" | "``),
        empty when there are none.

    Examples
    --------
    >>> warnings_of(fit("exp(x)", ("0", "1"), 2))
    []
    """
    text = table.provenance.get("warnings", "")
    return [w for w in text.split(" | ") if w]


def _check_table(table, argument: str) -> None:
    """Refuse anything but a :class:`CoefficientTable` as ``argument``."""
    if not isinstance(table, CoefficientTable):
        raise ValueError(f"{argument} of type {type(table).__name__} is not accepted; accepted: "
                         f"a CoefficientTable (from chebnorm.fit or CoefficientTable.load)")


def _check_frac_bits(frac_bits, coeffs, word_bits) -> None:
    if isinstance(frac_bits, bool) or not isinstance(frac_bits, (int, np.integer)) or frac_bits < 0:
        raise ValueError(f"coef_frac_bits {frac_bits!r} is not a non-negative integer")
    limit = 2 ** (word_bits - 1) - 1
    biggest = max(abs(c) for c in coeffs)
    if biggest == 0:
        return
    max_f = math.floor(math.log2((limit + 0.5) / biggest))
    if frac_bits > max_f + 1:  # past this, 2**frac_bits overflows a double: refuse exactly here
        raise ValueError(f"coef_frac_bits {frac_bits} overflows int{word_bits}: the largest "
                         f"coefficient, {biggest:.6g}, becomes more than 2^{word_bits - 1}; "
                         f"accepted: coef_frac_bits <= {max_f}")
    for k, c in enumerate(coeffs):
        if abs(round(math.ldexp(c, frac_bits))) > limit:
            raise ValueError(f"coef_frac_bits {frac_bits} overflows int{word_bits}: coefficient of "
                             f"x^{k} = {c:.6g} becomes {round(math.ldexp(c, frac_bits))}; "
                             f"accepted: coef_frac_bits <= {max_f}")


def _frac_list(frac_bits, degree: int, coeffs, word_bits: int) -> list[int]:
    """``frac_bits`` (an integer or one per power 0..degree) as a list, checked."""
    if isinstance(frac_bits, (list, tuple)):
        if len(frac_bits) != degree + 1:
            raise ValueError(f"coef_frac_bits list {list(frac_bits)} has {len(frac_bits)} entries; "
                             f"accepted: one integer, or degree + 1 = {degree + 1} integers "
                             f"(one per power 0..{degree})")
        for k, f in enumerate(frac_bits):
            _check_frac_bits(f, [coeffs[k]], word_bits)
        return [int(f) for f in frac_bits]
    _check_frac_bits(frac_bits, coeffs, word_bits)
    return [int(frac_bits)] * (degree + 1)


def _monomials(monomials, degree: int, fix_constant: bool) -> tuple[int, ...]:
    if monomials is None:
        monomials = range(degree + 1)
    try:
        mons = sorted({int(k) for k in monomials})
        ok = all(not isinstance(k, bool) and float(k) == int(k) for k in monomials)
    except (TypeError, ValueError):
        ok, mons = False, []
    if not ok or not mons or mons[0] < 0 or mons[-1] > degree:
        raise ValueError(f"monomials {monomials!r} are not powers of the variable in "
                         f"0..{degree}; accepted: a non-empty list such as 1,3,5 (at most the "
                         f"degree {degree})")
    repeated = sorted({int(k) for k in monomials if list(monomials).count(k) > 1})
    if repeated:
        raise ValueError(f"monomials {list(monomials)!r} repeat the power "
                         f"{', '.join(map(str, repeated))}; accepted: each power once, "
                         f"e.g. 1,3,5")
    if fix_constant and 0 in mons:
        mons.remove(0)
    return tuple(mons)


def quantize(table: CoefficientTable, coef_frac_bits=None, *, word_bits: int = 32,
             reoptimize: bool = True, coef_format: str = "fixed", monomials=None,
             fix_constant: bool = False, frac_bits=None) -> CoefficientTable:
    """Round the coefficients to a fixed or floating format and re-certify.

    Parameters
    ----------
    table : CoefficientTable
        A table in the monomial basis (from :func:`fit` or ``load``); one
        whose shifted basis ``basis="auto"`` chose is first refitted in
        powers of ``x``.
    coef_frac_bits : int or sequence of int, optional
        Fixed point (``coef_format="fixed"``, required there): coefficient
        ``k`` stored with ``coef_frac_bits`` fractional bits (one integer, or one
        per power ``0..degree``) as a ``word_bits``-bit integer.
    word_bits : int, optional
        ``2 <= word_bits <= 53``: the signed integer width of fixed point.
    reoptimize : bool, optional
        Choose the coefficients as Sollya's ``fpminimax`` does (default), or
        (False) only round each to nearest.
    coef_format : {"fixed", "binary16", "bfloat16", "binary32", "binary64"}, optional
        The format of every stored coefficient.
    monomials : sequence of int, optional
        Keep only these powers (e.g. ``(1, 3, 5)``).
    fix_constant : bool, optional
        Hold the constant coefficient at ``f(0)`` rounded to its format (so
        ``p(0) = f(0)`` when that is representable).
    frac_bits : int or sequence of int, optional
        The deprecated spelling of ``coef_frac_bits`` (a
        :class:`~chebnorm.core.deprecation.ChebnormDeprecationWarning`).

    Returns
    -------
    CoefficientTable
        ``table`` with ``quantized`` set (and ``fixed_point``: fixed format
        with one ``frac_bits``, all powers, free constant). Its own bound is
        :attr:`CoefficientTable.error_bound` (``quantized.abs_error_bound``);
        ``abs_error_bound`` stays the float coefficients'.

    Raises
    ------
    ValueError
        For a table that is not a CoefficientTable or was fitted with
        ``basis="shifted"``,
        a format or ``frac_bits`` out of range (naming the largest accepted
        ``frac_bits``), or when no rounding could be certified.

    See Also
    --------
    fit : fit and certify (``coef_frac_bits=`` / ``coef_format=`` quantize at once).
    chebnorm.hw.design_horner : fixed-point hardware of a quantized table.
    chebnorm.export : C and shader code of the table.

    Notes
    -----
    The error minimized is the table's ``error_kind``. With ``reoptimize``
    the coefficients are chosen by lattice reduction and a closest vector at
    Chebyshev points (see :mod:`chebnorm.approx.rounding`); plain rounding
    and the greedy refit (rounded from the highest power down, the lower ones
    refitted at Chebyshev nodes) compete: they are ranked by their sampled
    error and certified in that order while they can still win; the one with
    the smallest certified bound wins (``method`` names it; floating formats:
    within a factor 1 + 2^-20 of the smallest). Fixed formats are monotone in
    the bits: more fractional bits never certify a worse error. A table
    fitted with the same ``monomials`` / ``fix_constant`` (same held
    constant) is quantized from its own coefficients, otherwise the
    constrained real fit is computed first. When ``f`` is proved even or odd
    on a symmetric interval and the powers asked for (all of them by
    default) include the other parity, the powers of ``f``'s parity are
    quantized first (the other coefficients exact zeros, as in the best
    polynomial); the candidates of every power asked for then compete
    against that certified bound, so the answer is never worse than either.

    In fixed point (``coef_format="fixed"``) the stored polynomial is

    .. math::

        p_q(x) = \\sum_{j=0}^{n} q_j\\, 2^{-F_j} x^j, \\qquad
        q_j \\in \\mathbb{Z}, \\quad |q_j| \\le 2^{W - 1} - 1,

    with :math:`F_j` the ``frac_bits`` of power :math:`j` and :math:`W` =
    ``word_bits``; ``error_bound`` is a rigorous upper bound of
    :math:`\\max_{x \\in [a, b]} |p_q(x) - f(x)|` (of
    :math:`|p_q(x)/f(x) - 1|` for a relative table), certified as
    :func:`fit` certifies. Choosing the :math:`q_j` jointly by lattice
    reduction is the method of Brisebarre and Chevillard [1]_, which Sollya's
    ``fpminimax`` implements [2]_.

    References
    ----------
    .. [1] N. Brisebarre, S. Chevillard, "Efficient polynomial
       L-infinity approximations", 18th IEEE Symposium on Computer
       Arithmetic (ARITH 18), 2007.
    .. [2] S. Chevillard, M. Joldes, C. Lauter, "Sollya: an environment for
       the development of numerical codes", Mathematical Software (ICMS
       2010), LNCS 6327, Springer, 2010; https://www.sollya.org/

    Examples
    --------
    >>> t = quantize(fit("1/sqrt(2+z)", ("sqrt(2)", 2), 2, var="z"), 14)
    >>> t.fixed_point.integers, f"{t.error_bound:.3e}"
    ((11152, -1944, 232), '2.781e-05')
    >>> s = quantize(fit("sin(x)", ("0", "1"), 5), coef_format="binary32", monomials=(1, 3, 5))
    >>> s.quantized.mantissas[0::2], s.error_bound < 4e-6
    ((0, 0, 0), True)
    """
    frac_bits = renamed(frac_bits, coef_frac_bits, "frac_bits", "coef_frac_bits", "quantize")
    _check_table(table, "table")
    if isinstance(word_bits, bool) or not isinstance(word_bits, (int, np.integer)) \
            or not 2 <= word_bits <= 53:
        raise ValueError(f"word_bits {word_bits!r} is not accepted; accepted: an integer "
                         f"2 <= word_bits <= 53 (the coefficients stay exact doubles)")
    table.verify()  # a table changed behind the frozen dataclass's back is re-proved
    table = _in_powers_of_x(table)
    table.require_monomial("quantize")

    from .rounding import FORMATS, Problem, greedy as greedy_integers, round_coefficients

    if coef_format not in FORMATS:
        raise ValueError(f"coefficient format {coef_format!r} is unknown; accepted: "
                         f"{', '.join(FORMATS)}")
    n = table.degree
    fn = parse_function(table.expression, table.variable)
    iv = _table_interval(*table.interval)
    mons = _monomials(monomials, n, fix_constant)
    if coef_format == "fixed":
        if frac_bits is None:
            raise ValueError("coefficient format fixed needs coef_frac_bits (an integer, or one per "
                             "power); accepted: e.g. 14 or 14,16,18")
        fracs = _frac_list(frac_bits, n, table.coefficients, word_bits)
    elif frac_bits is not None:
        raise ValueError(f"coef_frac_bits applies to coefficient format fixed, not {coef_format}")
    else:
        fracs = None
    fixed = _fixed_constant(fn, coef_format, fracs[0] if coef_format == "fixed" else None) \
        if fix_constant else {}
    if not mons:
        raise ValueError("monomials: no free coefficient left (only the fixed constant)")
    real = list(table.coefficients)
    full_basis = mons == tuple(range(n + 1)) or (fix_constant and mons == tuple(range(1, n + 1)))
    if (not full_basis or fix_constant) and not _fitted_alike(table, mons, fixed):
        real = _constrained_fit(fn, iv, n, mons, fixed, table.error_kind)
    prob = Problem(fn=fn, lo=iv.lo, hi=iv.hi, lo_f=iv.lo_f, hi_f=iv.hi_f,
                    error_kind=table.error_kind, degree=n, powers=mons, fixed=fixed,
                    word_limit=2 ** (word_bits - 1) - 1 if coef_format == "fixed" else None)
    greedy = None
    if reoptimize and n >= 1 and mons == tuple(range(n + 1)):
        def greedy(quanta):
            return greedy_integers(prob, real, quanta)
    frac_arg = fracs if coef_format == "fixed" else None
    # f even or odd on a symmetric interval: the powers of its parity first (the
    # lattice over the nonzero powers, the others exact zeros), then every
    # candidate of all the requested powers, certified only where it can beat that
    incumbent = _parity_rounding(table, fn, iv, mons, fixed, coef_format, frac_arg,
                                 prob.word_limit) if reoptimize else None
    best = round_coefficients(prob, real, coef_format, frac_arg, greedy,
                              plain=not reoptimize, incumbent=incumbent)
    if best is None:
        raise ValueError(_no_rounding(coef_format, real, word_bits, fracs))
    coeffs = best.coefficients
    # the certificates that ranked the candidates (tight), so the stated bound
    # is the one the monotone chain compared (the winner's is reused: same call)
    ca, cr = _certify_both(fn, list(coeffs), iv, table.error_kind == "rel", tight=True,
                           known={"abs": best.abs_cert, "rel": best.rel_cert})
    return _with_quantized(table, best, ca, cr, coef_format, mons, fracs, word_bits,
                           fix_constant, full_basis)


def _parity_rounding(table, fn, iv, mons, fixed: dict, coef_format: str, frac_arg,
                     word_limit):
    """The best certified rounding in the powers among ``mons`` of the parity
    of ``f`` when ``f`` is proved even or odd on the (symmetric) interval and
    ``mons`` holds powers of the other parity too; None otherwise (or when
    none certifies). Its real fit is the table's when that is the parity fit,
    else the minimax fit in those powers."""
    from .rounding import Problem, round_coefficients

    if not iv.lo_f < 0 < iv.hi_f:
        return None
    want = {"even": 0, "odd": 1}.get(_parity(fn, iv))
    if want is None:
        return None
    sub = tuple(k for k in mons if k % 2 == want)
    # a held constant of the other parity is f(0) = 0 rounded: zero, dropped
    held = {k: v for k, v in fixed.items() if k % 2 == want or v[0] != 0}
    if not sub or sub == mons or any(k % 2 != want for k in held):
        return None
    n = table.degree
    real = (list(table.coefficients) if _fitted_alike(table, sub, held)
            else _constrained_fit(fn, iv, n, sub, held, table.error_kind))
    prob = Problem(fn=fn, lo=iv.lo, hi=iv.hi, lo_f=iv.lo_f, hi_f=iv.hi_f,
                   error_kind=table.error_kind, degree=n, powers=sub, fixed=held,
                   word_limit=word_limit)
    return round_coefficients(prob, real, coef_format, frac_arg)


@functools.lru_cache(maxsize=64)
def _table_interval(lo: str, hi: str) -> Interval:
    """The Interval of a table's endpoint strings (read only; kept: several
    formats or bit counts of one table parse its endpoints once)."""
    return Interval(lo, hi)


def _fitted_alike(table: CoefficientTable, mons, fixed: dict) -> bool:
    """True when ``table`` already holds the real fit quantize would compute:
    a minimax fit in the powers ``mons`` (``fit(..., monomials=...)``, or the
    parity fit of an even or odd ``f``: provenance ``constraint`` / ``parity``)
    whose other coefficients are zero and whose held constant is the one
    quantize holds (``fixed``). Only the starting point depends on it: the
    quantized coefficients are certified whatever it is."""
    prov = table.provenance
    if table.kind != "minimax" or not ("constraint" in prov or "parity" in prov):
        return False
    if (0 in fixed) != ("held at" in prov.get("constraint", "")):
        return False
    c = table.coefficients
    held = {k: math.ldexp(m, e) for k, (m, e) in fixed.items()}
    return all(c[k] == 0 for k in range(len(c)) if k not in mons and k not in held) and all(
        c[k] == v for k, v in held.items())


def _no_rounding(coef_format: str, real, word_bits: int, fracs) -> str:
    """Why no rounding to ``coef_format`` could be certified, naming the format's range."""
    from .rounding import FLOAT_FORMATS

    big = max(range(len(real)), key=lambda k: abs(real[k]))
    if coef_format in FLOAT_FORMATS:
        p, _, emax = FLOAT_FORMATS[coef_format]
        top = math.ldexp(2 - 2.0 ** (1 - p), emax)
        if abs(real[big]) > top:
            return (f"coefficient of x^{big} = {real[big]:.6g} overflows {coef_format} (largest "
                    f"finite {top:.6g}); accepted: coefficients within +-{top:.6g}, or another "
                    f"coefficient format")
        return f"no rounding of the coefficients to {coef_format} could be certified"
    return (f"no rounding of the coefficients to fixed point could be certified (every "
            f"candidate overflowed word_bits = {word_bits}: coefficient of x^{big} = "
            f"{real[big]:.6g} at {fracs[big]} fractional bits, or failed)")


def _with_quantized(table, best, ca, cr, coef_format, mons, fracs, word_bits, fix_constant,
                    full_basis) -> CoefficientTable:
    """The table with its ``quantized`` (and, where it fits, ``fixed_point``) part."""
    from dataclasses import replace

    from .rounding import normal_pair

    method = "lattice" if best.method.startswith("lattice") else best.method
    # tight=False there means missing 2^-20; warn only when 1 + 2^-8 is missed
    notes = _certificate_notes(**{
        k: c for k, c in (("quantized.abs_error_bound", ca), ("quantized.rel_error_bound", cr))
        if c is not None and c.bound > (1 + 2.0 ** -8) * c.maximum})
    quant = Quantized(
        format=coef_format, monomials=mons, mantissas=tuple(best.mantissas),
        exponents=tuple(best.exponents if coef_format != "fixed" else [-f for f in fracs]),
        frac_bits=tuple(fracs) if coef_format == "fixed" else None,
        word_bits=word_bits if coef_format == "fixed" else None, fixed_constant=fix_constant,
        method=method, abs_error_bound=ca.bound, rel_error_bound=None if cr is None else cr.bound,
        max_abs_error=ca.maximum, max_rel_error=None if cr is None else cr.maximum)
    if coef_format != "fixed":
        # odd mantissas (zero: 0 * 2^0): one spelling per number, within 2^53
        pairs = [normal_pair(m, e) for m, e in zip(quant.mantissas, quant.exponents)]
        quant = replace(quant, mantissas=tuple(m for m, _ in pairs),
                        exponents=tuple(e for _, e in pairs))
    fixed_point = None
    if coef_format == "fixed" and len(set(fracs)) == 1 and full_basis and not fix_constant:
        fixed_point = FixedPoint(frac_bits=fracs[0], integers=quant.mantissas,
                                 word_bits=word_bits, method=method, abs_error_bound=ca.bound,
                                 rel_error_bound=quant.rel_error_bound, max_abs_error=ca.maximum,
                                 max_rel_error=quant.max_rel_error)
    provenance = dict(table.provenance)
    if notes:
        _warn(notes)
        old = warnings_of(table)
        provenance["warnings"] = " | ".join(old + [n for n in notes if n not in old])
    with construction("fitted"):  # ``table`` verified, ``quant`` certified by quantize
        return replace(table, fixed_point=fixed_point, quantized=quant, provenance=provenance)


def _table_name(name) -> str | None:
    """``name`` checked where it enters: None stays None (the table is named after
    its expression, interval and degree once they are read), anything else must be
    an identifier (it becomes a C function, a macro, a Verilog module)."""
    from chebnorm.core.textsafe import identifier

    return None if name is None else identifier(name, field="name")


def _fixed_constant(fn, coef_format: str, frac0: int | None) -> dict:
    """``{0: (mantissa, exponent)}``: ``f(0)`` rounded to the constant's format."""
    from .rounding import round_to_float

    f0 = enclose(fn.expr.subs(fn.var, 0), 128)
    if f0 is None or not f0.is_finite():
        raise ValueError(f"fix_constant: {fn.expr} has no finite value at "
                         f"{fn.var} = 0; accepted only where f(0) is defined")
    c0 = float(f0.mid())
    if coef_format == "fixed":
        return {0: (round(math.ldexp(c0, frac0)), -frac0)}
    return {0: round_to_float(c0, coef_format)}
