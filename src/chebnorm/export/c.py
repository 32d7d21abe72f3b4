"""C99 header printer for a :class:`~chebnorm.approx.CoefficientTable`.

Table-driven over the floating types it emits (``double`` and ``float``):
each row gives the C type, the literal suffix, the function-name suffix and
the unit roundoff used in that type's evaluation-error bound.

Every header carries a banner (tool, version, generating command), an include
guard, coefficients as C99 hexadecimal floating literals (exact) with the
decimal value in a comment, Horner evaluators, and the bounds:

``<P>_ABS_ERROR_BOUND`` / ``<P>_REL_ERROR_BOUND``
    certified bounds of ``|p - f|`` and ``|p/f - 1|`` for the double
    coefficients evaluated exactly;
``<P>_EVAL_ERROR_BOUND`` / ``<P>_F_EVAL_ERROR_BOUND`` / ``<P>_Q_EVAL_ERROR_BOUND``
    bounds of ``|evaluator(x) - f(x)|`` for the double, float and (for a
    quantized table) integer evaluators on inputs in the interval, computed
    for the evaluator's own operation sequence by
    :func:`chebnorm.export.evalbound.horner_bound` (interval arithmetic on
    64 pieces of the interval, each rounding bounded by half an ulp of its
    largest possible result there, fused and unfused steps both covered):
    the certified bound plus the largest local coefficient-rounding and
    evaluation error. ``chebnorm export --proof`` writes one Gappa script per
    constant (:mod:`chebnorm.export.gappa`) proving it, and the header names
    it beside the constant. A float32 evaluator whose rounding dominates
    states instead its exhaustive certificate when that is smaller
    (:mod:`chebnorm.export.certificate`: every float32 input and every mix
    of fused and unfused steps run bit-exactly against a proved enclosure
    of ``f``); its comment says so and gives the a-priori bound the Gappa
    script proves.
``<P>_QUANT_ABS_ERROR_BOUND``, ``<P>_QUANT_EVAL_ERROR_BOUND`` (and ``_F_``)
    for a table whose ``quantized`` part is not a plain ``fixed_point`` (a
    floating format, one fractional width per power, chosen monomials or a
    fixed constant): ``<p>_quant_coeffs`` holds those coefficients exactly
    (zero for the powers left out) and ``<p>_quant`` / ``<p>_quant_f``
    evaluate them by Horner's rule; the float evaluator is emitted only when
    every coefficient is a float exactly, so its bound adds no coefficient
    rounding.

A table in the shifted basis (``table.shift = (c, s)``) gets ``<P>_CENTER``
and ``<P>_SCALE`` and evaluators that first form ``t = (x - c) * (1/s)`` (a
multiply by a power of two, exact; a division when ``s`` is not one); the
evaluation bounds then add the error of ``t`` (``c`` rounded to the type, the
subtraction unless Sterbenz's lemma makes it exact) times ``max |p'|``.

Text from the table or the command line never reaches the header raw: the
name must be an identifier (:func:`chebnorm.core.textsafe.identifier`, it
makes every symbol and macro), every other text goes through
:func:`~chebnorm.core.textsafe.comment_text` (it cannot end the comment,
continue a line or hold a trigraph), and numbers are printed from ``float``
and ``int`` values.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from chebnorm.approx import CoefficientTable
from chebnorm.core.textsafe import comment_text, identifier

from .evalbound import BINARY32, BINARY64, Evaluator, Piece, fixed_arithmetic
from ._docfrag import export_doc

# an implementation module of chebnorm.export: the API is what chebnorm.export exports
__all__: list[str] = []

#: The floating types a header evaluates in, one row each: the C type, the
#: literal suffix (``""`` or ``"f"``), the function-name suffix (``""`` or
#: ``"_f"``) and the unit roundoff ``u`` of the type (``2**-53``, ``2**-24``)
#: used in that evaluator's rounding bound.
FLOAT_TYPES = (
    ("double", "", "", 2.0 ** -53),
    ("float", "f", "_f", 2.0 ** -24),
)


def _count(value, field: str) -> int:
    """A non-negative int printed into code (so never text)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ValueError(f"{field}: expected a non-negative integer, got {value!r:.60}")
    return int(value)


def _checked_fixed(table: CoefficientTable):
    """The fixed-point part, its numbers checked: they are printed into code as
    ``int32_t`` literals and shift counts."""
    fp = table.fixed_point
    _count(fp.frac_bits, "fixed_point.frac_bits")
    if len(fp.integers) != len(table.coefficients):
        raise ValueError(f"fixed_point.integers: {len(fp.integers)} integers for "
                         f"{len(table.coefficients)} coefficients; expected as many")
    for k, q in enumerate(fp.integers):
        if isinstance(q, bool) or not isinstance(q, (int, np.integer)):
            raise ValueError(f"fixed_point.integers[{k}]: expected an integer, got {q!r:.60}")
        if not -2 ** 31 <= q < 2 ** 31:
            raise ValueError(f"fixed_point.integers[{k}]: {q} does not fit the header's int32_t; "
                             f"accepted: -2^31 <= q < 2^31 (quantize with fewer frac_bits)")
    return fp


def _literal(value: float, suffix: str) -> str:
    """Exact C99 hex literal, with the decimal in a comment."""
    value = float(value)  # a number, never text
    if suffix == "f":
        value = float(np.float32(value))
    return f"{value.hex()}{suffix} /* {value!r} */"


#: per literal suffix: the type's name, its largest finite number and half its
#: smallest subnormal (the absolute error of a product rounded to a subnormal)
_RANGE = {"": ("double", Fraction(float(np.finfo(np.float64).max)), Fraction(1, 2 ** 1075)),
          "f": ("float", Fraction(float(np.finfo(np.float32).max)), Fraction(1, 2 ** 150))}


def inner_interval(table: CoefficientTable) -> tuple[float, float]:
    """The table's exact interval rounded *inward* to doubles: the ``_LO`` and
    ``_HI`` a header prints, so every input between them lies in the
    certified interval (``interval_float``, the nearest doubles, may lie just
    outside: ``-0.1`` is below ``-1/10``).

    Parameters
    ----------
    table : CoefficientTable
        The table; its exact ``interval`` (text) is read with the reader of
        :func:`chebnorm.approx.fit`. Text no reader accepts (a table built
        by hand) falls back to ``interval_float`` unchanged.

    Returns
    -------
    tuple of (float, float)
        ``(lo, hi)``: the smallest double ``>=`` the exact lower endpoint and
        the largest double ``<=`` the exact upper one.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> t = fit("0.3*x", ("-0.1", "0"), 1)
    >>> t.interval_float[0] < inner_interval(t)[0] == math.nextafter(-0.1, 0)
    True
    """
    from chebnorm.approx.api import Interval

    try:
        iv = Interval(*table.interval)
    except (TypeError, ValueError):
        # text no reader accepts (a table built by hand and never verified):
        # the stored doubles, as before
        return tuple(float(v) for v in table.interval_float)
    return iv.lo_in, iv.hi_in


def _gamma(k: int, u: float) -> Fraction:
    uf = Fraction(u)
    return k * uf / (1 - k * uf)


def underflow_bound(n: int, max_t: Fraction, suffix: str, u: float) -> Fraction:
    """Bound of what gradual underflow adds to Horner's rule of degree ``n``
    in the type of ``suffix`` for ``|t| <= max_t``: each of the ``n``
    products may round to a subnormal with an absolute error up to half the
    smallest subnormal ``eta`` (sums of floats are exact there), later
    multiplied by ``|t|`` once per remaining step and by at most ``2n``
    factors ``1 + delta``: ``eta (1 + gamma_2n) sum_{j<n} max_t^j``.

    Parameters
    ----------
    n : int
        The degree (number of Horner steps), ``n >= 0``; ``0`` gives ``0``.
    max_t : Fraction
        A bound of ``|t|`` over the inputs, ``>= 0``.
    suffix : {"", "f"}
        The literal suffix naming the type: ``""`` double (``eta =
        2**-1075``), ``"f"`` float (``eta = 2**-150``).
    u : float
        The unit roundoff of that type (``2**-53`` or ``2**-24``), in
        ``(0, 1/(2n))``.

    Returns
    -------
    Fraction
        The exact bound, to be added to the rounding bound of
        :func:`horner_rounding_bound`.

    Raises
    ------
    KeyError
        When ``suffix`` is neither ``""`` nor ``"f"``.

    Notes
    -----
    With :math:`\\eta` half the smallest subnormal and
    :math:`\\gamma_k = k u / (1 - k u)`,

    .. math::

        \\Delta_{\\mathrm{underflow}} \\le \\eta\\,(1 + \\gamma_{2n})
        \\sum_{j=0}^{n-1} M^j, \\qquad |t| \\le M .

    References
    ----------
    .. [1] N. J. Higham, *Accuracy and Stability of Numerical Algorithms*,
       2nd ed., SIAM, 2002, chapter 2 (the model of arithmetic with
       underflow) and eq. (5.3).

    Examples
    --------
    >>> underflow_bound(2, Fraction(1), "f", 2.0 ** -24) < Fraction(3, 2 ** 150)
    True
    """
    eta = _RANGE[suffix][2]
    return eta * (1 + _gamma(2 * n, u)) * sum((max_t ** j for j in range(n)), Fraction(0))


def round_inward(lo: float, hi: float, suffix: str) -> tuple[float, float]:
    """``[lo, hi]`` rounded inward to the type of ``suffix`` (``"f"``: float32,
    every float32 between the results lies in ``[lo, hi]``; otherwise the
    doubles themselves).

    Parameters
    ----------
    lo, hi : float
        The interval's endpoints as doubles, ``lo <= hi`` (an empty result,
        ``lo > hi`` after rounding, is possible when no float32 lies between
        them).
    suffix : str
        ``"f"`` for float32; any other value leaves the doubles unchanged.

    Returns
    -------
    tuple of (float, float)
        The inward-rounded endpoints, as Python floats.

    Examples
    --------
    >>> round_inward(0.1, 0.2, "f")[0] >= 0.1, round_inward(0.1, 0.2, "")
    (True, (0.1, 0.2))
    """
    if suffix != "f":
        return lo, hi
    with np.errstate(over="ignore"):
        lo32, hi32 = np.float32(lo), np.float32(hi)
    if float(lo32) < lo:
        lo32 = np.nextafter(lo32, np.float32(np.inf), dtype=np.float32)
    if float(hi32) > hi:
        hi32 = np.nextafter(hi32, np.float32(-np.inf), dtype=np.float32)
    return float(lo32), float(hi32)


def _overflows(xs, cs, suffix: str, shift, parity):
    """Which of the inputs ``xs`` make the evaluator (Horner's rule in the type
    of ``suffix``, unfused, after the shift or in ``x*x``) meet a non-finite
    intermediate."""
    dt = np.float32 if suffix == "f" else np.float64
    with np.errstate(all="ignore"):
        x = np.asarray(xs, dtype=dt)
        bad = ~np.isfinite(x)
        t = x
        if shift is not None:
            c, s = dt(shift[0]), float(shift[1])
            t = (x - c) * dt(1 / s) if _is_power_of_two(s) else (x - c) / dt(s)
        if parity is not None:
            t = x * x
            cs = cs[parity::2]
        bad |= ~np.isfinite(t)
        acc = np.full_like(x, dt(cs[-1]))
        for c in reversed(cs[:-1]):
            prod = acc * t
            acc = prod + dt(c)
            bad |= ~np.isfinite(prod) | ~np.isfinite(acc)
        if parity:
            bad |= ~np.isfinite(acc * x)
    return bad


def _first_overflow(lo: float, hi: float, cs, suffix: str, shift=None, parity=None):
    """The smallest input found (on 4097 evenly spread points, then by
    bisection towards the last good one) at which the evaluator meets a
    non-finite intermediate, or None."""
    lo, hi = round_inward(lo, hi, suffix)
    if not lo <= hi:
        return None
    xs = np.unique(np.concatenate([np.linspace(lo, hi, 4097), [lo, hi]]))
    xs = np.clip(xs.astype(np.float32 if suffix == "f" else np.float64), lo, hi)
    bad = _overflows(xs, cs, suffix, shift, parity)
    if not bad.any():
        return None
    i = int(np.argmax(bad))
    if i == 0:
        return float(xs[0])
    good, worse = float(xs[i - 1]), float(xs[i])
    for _ in range(200):
        mid = float(np.asarray((good + worse) / 2, dtype=xs.dtype))
        if mid in (good, worse):
            break
        if _overflows([mid], cs, suffix, shift, parity)[0]:
            worse = mid
        else:
            good = mid
    return worse


def range_problem(coeffs, max_t: Fraction, suffix: str, u: float, *, where=None) -> str | None:
    """None when Horner's rule on ``coeffs`` in the type of ``suffix`` (fused
    or not) cannot meet a non-finite intermediate for ``|t| <= max_t``; else
    the reason (the first offending input when ``where = (lo, hi, shift,
    parity)`` lets it be searched for).

    Every computed intermediate is at most ``(1 + gamma_2n)(1 + u)`` times the
    exact ``sum_{j>=k} |c_j| max_t^(j-k)`` (and its product by ``max_t``),
    plus the underflow term: the evaluator stays finite when that is at most
    the type's largest number.

    Parameters
    ----------
    coeffs : sequence of float
        The coefficients in ascending powers; they are rounded to the type
        first (a coefficient that overflows it is reported).
    max_t : Fraction
        A bound of ``|t|`` over the inputs, ``>= 0``.
    suffix : {"", "f"}
        The literal suffix naming the type: double or float.
    u : float
        The unit roundoff of that type.
    where : tuple or None, optional
        ``(lo, hi, shift, parity)``: the input interval, the table's shift
        ``(c, s)`` or None, and the parity (0, 1) of an even/odd evaluator
        or None. Given, a possible overflow is searched for on 4097 points
        and by bisection, to name the first offending input. Default None.

    Returns
    -------
    str or None
        None when the evaluator is proven finite on ``|t| <= max_t``; else a
        sentence saying why not (the coefficient that is not finite, the
        first input found to overflow, or the reach of the bound).

    Raises
    ------
    KeyError
        When ``suffix`` is neither ``""`` nor ``"f"``.

    Notes
    -----
    The check bounds every intermediate :math:`\\hat a_k` of Horner's rule by

    .. math::

        |\\hat a_k| \\le (1 + \\gamma_{2n})(1 + u)
        \\sum_{j \\ge k} |c_j| M^{j-k} + \\Delta_{\\mathrm{underflow}},

    the magnitude bound behind Higham's eq. (5.3) [1]_.

    References
    ----------
    .. [1] N. J. Higham, *Accuracy and Stability of Numerical Algorithms*,
       2nd ed., SIAM, 2002, eq. (5.3).

    Examples
    --------
    >>> range_problem([0.0, 1e30], Fraction(10 ** 10), "f", 2.0 ** -24)
    'its intermediates may reach 1e+40 > 3.4e+38, the largest float'
    >>> range_problem([1.0, 2.0], Fraction(4), "f", 2.0 ** -24) is None
    True
    """
    tname, big, _ = _RANGE[suffix]
    cts = []
    for k, c in enumerate(coeffs):
        with np.errstate(over="ignore"):
            cts.append(float(np.float32(c)) if suffix == "f" else float(c))
        if not math.isfinite(cts[-1]):
            return f"coefficient {k} ({float(c):.6g}) is not finite in {tname}"
    n = len(cts) - 1
    a = abs(Fraction(cts[-1]))
    worst = a
    for c in reversed(cts[:-1]):
        prod = a * max_t
        a = prod + abs(Fraction(c))
        worst = max(worst, prod, a)
    reach = worst * (1 + _gamma(2 * n, u)) * (1 + Fraction(u)) + underflow_bound(n, max_t, suffix, u)
    if reach <= big:
        return None
    found = None if where is None else _first_overflow(where[0], where[1], cts, suffix,
                                                       *where[2:])
    if found is not None:
        return f"the {tname} evaluator overflows at x = {found!r}"
    return (f"its intermediates may reach {float(reach):.3g} > {float(big):.3g}, the largest "
            f"{tname}")


def interval_max_abs(table: CoefficientTable) -> Fraction:
    """A bound of ``|x|`` over the table's interval: the larger endpoint
    magnitude of its doubles, each padded outward by one ulp (they may lie
    just inside irrational true endpoints). The rounding bounds use it.

    Parameters
    ----------
    table : CoefficientTable
        The table; only its ``interval_float`` is read.

    Returns
    -------
    Fraction
        ``max(|lo^-|, |hi^+|)`` exactly, with ``lo^-``, ``hi^+`` the
        endpoints moved one ulp outward.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> interval_max_abs(fit("x", ("-2", "1"), 1)) > 2
    True
    """
    lo, hi = table.interval_float
    # the float endpoints may lie just inside irrational true endpoints: pad by one ulp
    lo = math.nextafter(lo, -math.inf)
    hi = math.nextafter(hi, math.inf)
    return max(abs(Fraction(lo)), abs(Fraction(hi)))


def horner_rounding_bound(coefficients, max_abs_x: Fraction, unit_roundoff: float) -> Fraction:
    """Rigorous bound of ``|fl(p(x)) - p(x)|`` for ``|x| <= max_abs_x``
    (``gamma_2n * sum |c_k| M^k``, ``gamma_k = k u / (1 - k u)``).

    Parameters
    ----------
    coefficients : sequence of float
        The coefficients ``c_0 .. c_n`` in ascending powers, each exactly
        representable in the evaluation type (the bound covers the
        arithmetic only, not rounding the coefficients).
    max_abs_x : Fraction
        ``M``, a bound of ``|x|`` over the inputs, ``>= 0``.
    unit_roundoff : float
        ``u`` of the evaluation type (``2**-53`` double, ``2**-24``
        float), with ``2 n u < 1``.

    Returns
    -------
    Fraction
        The exact bound; ``0`` for a constant (degree 0, no operation). It
        holds for the unfused and the fused (FMA) evaluation alike, and
        without underflow (add :func:`underflow_bound` for that).

    Notes
    -----
    Horner's rule with :math:`n` multiplications and :math:`n` additions,
    each rounded with relative error at most :math:`u`, satisfies
    (Higham [1]_, eq. 5.3)

    .. math::

        |p(x) - \\widehat{p}(x)| \\le \\gamma_{2n} \\sum_{k=0}^{n} |c_k|\\,|x|^k,
        \\qquad \\gamma_k = \\frac{k u}{1 - k u},

    and :math:`|x| \\le M` bounds the sum by :math:`\\sum_k |c_k| M^k`.

    References
    ----------
    .. [1] N. J. Higham, *Accuracy and Stability of Numerical Algorithms*,
       2nd ed., SIAM, 2002, eq. (5.3).

    Examples
    --------
    >>> b = horner_rounding_bound([1.0, 2.0, 3.0], Fraction(1), 2.0 ** -53)
    >>> b == 6 * Fraction(4, 2 ** 53 - 4)   # gamma_4 * (1 + 2 + 3)
    True
    """
    n = len(coefficients) - 1
    if n <= 0:
        return Fraction(0)
    u = Fraction(unit_roundoff)
    gamma = 2 * n * u / (1 - 2 * n * u)
    total = sum(abs(Fraction(c)) * max_abs_x ** k for k, c in enumerate(coefficients))
    return gamma * total


def _is_power_of_two(s: float) -> bool:
    return s > 0 and math.frexp(s)[0] == 0.5


def _to_type(value: float, suffix: str) -> float:
    return float(np.float32(value)) if suffix == "f" else float(value)


def _shift_error(table: CoefficientTable, coeffs, suffix: str, u: float):
    """For a shifted table evaluated in the type of ``suffix`` as
    ``t~ = (x - c_T) * (1/s)`` (or ``/ s``): a bound ``M`` of ``|t~|`` and the
    bound of ``|p(t~) - p(t)|`` from computing ``t`` (mean value theorem:
    ``max |p'| |t~ - t|``, ``|p'| <= sum k |a_k| M^(k-1)``)."""
    c, s = (Fraction(v) for v in table.shift)
    c_t = Fraction(_to_type(table.shift[0], suffix))
    lo, hi = (Fraction(v) for v in table.interval_float)
    pad = max(abs(lo), abs(hi)) * Fraction(2) ** -52  # the float endpoints within an ulp
    lo, hi = lo - pad, hi + pad
    reach = max(abs(lo - c_t), abs(hi - c_t))
    uf = Fraction(u)
    # x - c_T is exact (Sterbenz) when every x lies in [c_T/2, 2 c_T]
    sterbenz = (c_t > 0 and c_t / 2 <= lo and hi <= 2 * c_t) or (
        c_t < 0 and 2 * c_t <= lo and hi <= c_t / 2) or c_t == 0
    err = abs(c - c_t) / s + (0 if sterbenz else uf * reach / s)
    t_max = max(abs(lo - c), abs(hi - c)) / s
    if not _is_power_of_two(float(table.shift[1])):
        err += uf * (reach / s) * (1 + uf)  # the rounded division
    # an underflowing product: at most the smallest subnormal's half-spacing
    err += Fraction(2) ** (-150 if suffix == "f" else -1075)
    m = t_max + err
    slope = sum(k * abs(Fraction(a)) * m ** (k - 1) for k, a in enumerate(coeffs) if k > 0)
    return m, slope * err


def _check_fixed_ranges(table: CoefficientTable, max_abs_x: Fraction) -> None:
    fp = table.fixed_point
    x_q = max_abs_x * 2 ** fp.frac_bits
    if x_q >= 2 ** 63:
        raise ValueError(f"table {table.name!r}: x * 2^{fp.frac_bits} does not fit int64 on the "
                         f"interval; accepted: fewer fractional bits")
    parity = coefficient_parity(fp.integers)
    ints, var, var_q = list(fp.integers), max_abs_x, x_q
    if parity is not None:   # t_q = round(x_q^2 / 2^F), then Horner in t_q (times x_q)
        if x_q * x_q + 2 ** fp.frac_bits >= 2 ** 63:
            raise ValueError(f"table {table.name!r}: the integer square x_q * x_q overflows "
                             f"int64 with {fp.frac_bits} fractional bits; accepted: fewer "
                             f"fractional bits")
        ints = ints[parity::2]
        var = max_abs_x ** 2 + Fraction(1, 2 ** fp.frac_bits)
        var_q = var * 2 ** fp.frac_bits
    acc = Fraction(abs(ints[-1]))
    for q in reversed(ints[:-1]) if len(ints) > 1 else ():
        if acc * var_q + 2 ** fp.frac_bits >= 2 ** 63:
            raise ValueError(f"table {table.name!r}: the integer Horner product overflows int64 "
                             f"with {fp.frac_bits} fractional bits; accepted: fewer fractional bits")
        acc = acc * var + 1 + abs(q)
    if parity == 1 and acc * x_q + 2 ** fp.frac_bits >= 2 ** 63:
        raise ValueError(f"table {table.name!r}: the final integer product by x_q overflows "
                         f"int64 with {fp.frac_bits} fractional bits; accepted: fewer fractional "
                         f"bits")


def _fixed_evaluator(fp, fn: str, macro: str) -> list[str]:
    """Lines of the integer coefficient array and the integer Horner evaluator."""
    out = []
    w = out.append
    w("")
    w(f"/* Coefficients * 2^{fp.frac_bits} ({comment_text(fp.method)}), ascending powers. */")
    w(f"static const int32_t {fn}_q[{len(fp.integers)}] = {{")
    w("    " + ", ".join(f"INT32_C({q})" for q in fp.integers))
    w("};")
    w("")
    parity = coefficient_parity(fp.integers)
    powers = list(range(len(fp.integers)))
    var = "x_q"
    scheme = "" if parity is None else (f" over the {'odd' if parity else 'even'} powers, in "
                                        f"t_q = x_q * x_q / 2^{fp.frac_bits}")
    w(f"/* Integer Horner's rule{scheme}. x_q = x * 2^{fp.frac_bits} (x in [{macro}_LO, "
      f"{macro}_HI]);")
    w(f" * returns p(x) * 2^{fp.frac_bits}, each {'step' if parity is None else 'product'} "
      f"rounded to nearest (ties up) by an")
    w(" * arithmetic right shift (implementation-defined for negative values in C99;")
    w(f" * arithmetic on gcc and clang). |result / 2^{fp.frac_bits} - f(x)| <= {macro}_Q_EVAL_ERROR_BOUND. */")
    w(f"static inline int64_t {fn}_q_eval(int64_t x_q)")
    w("{")

    def rounded(product: str) -> str:
        if fp.frac_bits == 0:
            return product
        return f"(({product} + (INT64_C(1) << {fp.frac_bits - 1})) >> {fp.frac_bits})"

    if parity is not None:
        powers = powers[parity::2]
        var = "t_q"
        w(f"    int64_t t_q = {rounded('x_q * x_q')};")
    w(f"    int64_t acc = {fn}_q[{powers[-1]}];")
    for k in reversed(powers[:-1]):
        w(f"    acc = {rounded(f'acc * {var}')} + {fn}_q[{k}];")
    if len(powers) == 1:
        w(f"    (void){var};")
    w(f"    return {rounded('acc * x_q')};" if parity == 1 else "    return acc;")
    w("}")
    return out


def _eval_bound(table: CoefficientTable, coeffs, suffix: str, u: float, max_x: Fraction,
                name: str = "", constant: str = ""):
    """``(evaluator, None)``: the :class:`~chebnorm.export.evalbound.Evaluator`
    of the evaluator in the type of ``suffix`` (its tight bound:
    ``evaluator.bound()``); or ``(None, reason)`` when the evaluator can meet a
    non-finite intermediate on the interval (:func:`range_problem`)."""
    problem = range_problem(coeffs, Fraction(0), suffix, u)  # a coefficient out of range
    if problem is not None and problem.startswith("coefficient"):
        return None, problem
    cs = [float(np.float32(c)) for c in coeffs] if suffix == "f" else list(coeffs)
    if table.shift is not None:
        max_t, _ = _shift_error(table, cs, suffix, u)
    else:
        max_t = max_x
    parity = _table_parity(table, coeffs)
    if parity is None:
        problem = range_problem(cs, max_t, suffix, u,
                                where=(*inner_interval(table), table.shift, None))
    else:
        problem = evaluator_range_problem(table, cs, parity, suffix, u, max_x)
    if problem is not None:
        return None, problem
    shift = None
    if table.shift is not None:
        scale = float(table.shift[1])
        shift = (Fraction(table.shift[0]), Fraction(scale),
                 Fraction(_to_type(table.shift[0], suffix)), Fraction(_to_type(scale, suffix)),
                 _is_power_of_two(scale))
    lo, hi = inner_interval(table)
    piece = Piece(tuple(cs), tuple(float(c) for c in coeffs), Fraction(table.abs_error_bound),
                  lo, hi)
    return Evaluator(constant, name, BINARY32 if suffix == "f" else BINARY64, (piece,),
                     shift=shift, target=(table.expression, table.variable),
                     parity=_table_parity(table, coeffs)), None


def _table_parity(table: CoefficientTable, coeffs) -> int | None:
    """The parity of the float evaluators of the real coefficients (not in
    the shifted basis): :func:`coefficient_parity`."""
    return None if table.shift is not None else coefficient_parity(coeffs)


def _float_evaluator(table: CoefficientTable, coeffs, ctype: str, suffix: str, name: str,
                     macro: str) -> list[str]:
    """Horner's rule in ``ctype`` (in ``t = (x - c) * (1/s)`` for a shifted table)."""
    out = ["", f"/* Horner's rule in {ctype}; x must lie in [{macro}_LO, {macro}_HI]. */",
           f"static inline {ctype} {name}({ctype} x)", "{"]
    arg = "x"
    if table.shift is not None:
        arg = "t"
        center = _literal(_to_type(table.shift[0], suffix), suffix)
        scale = float(table.shift[1])
        if _is_power_of_two(scale):
            out.append(f"    {ctype} t = (x - {center}) * {_literal(1 / scale, suffix)};"
                       f"  /* exact scaling by 2^{-(math.frexp(scale)[1] - 1)} */")
        else:
            out.append(f"    {ctype} t = (x - {center}) / "
                       f"{_literal(_to_type(scale, suffix), suffix)};")
    out.append(f"    {ctype} acc = {_literal(coeffs[-1], suffix)};")
    for c in reversed(coeffs[:-1]):
        out.append(f"    acc = acc * {arg} + {_literal(c, suffix)};")
    if len(coeffs) == 1:
        out.append(f"    (void){arg};")
    return out + ["    return acc;", "}"]


def coefficient_parity(coeffs) -> int | None:
    """The parity of a coefficient list: the evaluators of one whose nonzero
    coefficients are all of odd (even) powers run ``x*q(x*x)`` (``q(x*x)``):
    the same polynomial, half the steps.

    Parameters
    ----------
    coeffs : sequence of numbers
        The coefficients in ascending powers (floats or integers).

    Returns
    -------
    int or None
        1 when every nonzero coefficient is of an odd power, 0 when of an
        even one; None otherwise, below degree 2 (``t = x*x`` saves nothing
        there) and for the zero polynomial.

    Examples
    --------
    >>> coefficient_parity([0.0, 1.0, 0.0, -1 / 6]), coefficient_parity([1.0, 0.0, 0.5])
    (1, 0)
    >>> coefficient_parity([1.0, 1.0, 0.0]) is None
    True
    """
    powers = {k for k, c in enumerate(coeffs) if c != 0}
    if len(coeffs) < 3 or not powers:
        return None
    for parity in (1, 0):
        if all(k % 2 == parity for k in powers):
            return parity
    return None


def _parity(q, degree: int) -> int | None:
    """1 when only odd powers are used (listed, or the others' coefficients
    zero), 0 when only even ones, else None."""
    powers = set(q.monomials) | ({0} if q.fixed_constant else set())
    for parity in (1, 0):
        if degree >= 2 and all(k % 2 == parity for k in powers):
            return parity
    return coefficient_parity([float(c) for c in q.coefficients])


def evaluator_range_problem(table, coeffs, parity, suffix: str, u: float, max_x: Fraction):
    """:func:`range_problem` of an evaluator of ``coeffs`` on the table's
    interval: Horner's rule in ``x``, or with ``parity`` in ``t = x*x`` over
    the coefficients of that parity (times ``x`` at the end when odd).

    Parameters
    ----------
    table : CoefficientTable
        The table (its inner interval is where the evaluator runs).
    coeffs : sequence of float
        The coefficients evaluated, ascending powers, in the type's values.
    parity : {None, 0, 1}
        None: Horner's rule in ``x``; 0 / 1: the even / odd scheme.
    suffix : {"", "f"}
        The C literal suffix of the type (double, float).
    u : float
        The type's unit roundoff.
    max_x : Fraction
        A bound of ``|x|`` on the interval.

    Returns
    -------
    str or None
        None when no intermediate can be non-finite, else why.
    """
    where = (*inner_interval(table), None, parity)
    if parity is None:
        return range_problem(coeffs, max_x, suffix, u, where=where)
    b = coeffs[parity::2]
    t_max = max_x ** 2 * (1 + Fraction(u)) + _RANGE[suffix][2]
    problem = range_problem(b, t_max, suffix, u, where=where)
    if problem is None and parity:  # the final product by x
        scaled = [0.0] + [float(c) for c in b]  # x * q(t) bounded as Horner one step on
        problem = range_problem(scaled, max(t_max, max_x), suffix, u, where=where)
    return problem


def _parity_evaluator(coeffs, parity: int, ctype: str, suffix: str, name: str,
                      macro: str) -> list[str]:
    """Horner's rule in ``t = x*x`` over the odd (times ``x``) or even coefficients."""
    b = coeffs[parity::2]
    kind = "odd" if parity else "even"
    out = ["", f"/* Horner's rule in {ctype} over the {kind} powers, in t = x*x; x must lie in",
           f" * [{macro}_LO, {macro}_HI]. */", f"static inline {ctype} {name}({ctype} x)", "{",
           f"    {ctype} t = x * x;", f"    {ctype} acc = {_literal(b[-1], suffix)};"]
    for c in reversed(b[:-1]):
        out.append(f"    acc = acc * t + {_literal(c, suffix)};")
    if len(b) == 1:
        out.append("    (void)t;")
    return out + [f"    return acc{' * x' if parity else ''};", "}"]


def _quantized_part(table: CoefficientTable, fn: str, macro: str, max_x: Fraction,
                    evaluators: list, proof: str) -> list[str]:
    """Bounds, exact coefficient array and Horner evaluators of ``table.quantized``
    (in ``x*x`` when only odd or only even powers are used)."""
    q = table.quantized
    coeffs = [float(c) for c in q.coefficients]
    if len(coeffs) != table.degree + 1 or not all(math.isfinite(c) for c in coeffs):
        raise ValueError(f"quantized: {len(coeffs)} finite coefficients expected for degree "
                         f"{table.degree}")
    if table.shift is not None:
        raise ValueError(f"table {table.name!r}: a quantized part in the shifted basis has no "
                         f"C evaluator; accepted: a shifted table without quantized")
    parity = _parity(q, table.degree)
    fmt = comment_text(q.format, max_length=20)
    out = ["", f"/* Quantized coefficients ({fmt}, {comment_text(q.method, max_length=20)}), "
           f"ascending powers of x (exact): certified |p_q - f| <= {float(q.abs_error_bound)!r}"
           + ("" if q.rel_error_bound is None else f", |p_q/f - 1| <= {float(q.rel_error_bound)!r}")
           + ". */"]
    w = out.append
    w(f"#define {macro}_QUANT_ABS_ERROR_BOUND {_literal(q.abs_error_bound, '')}")
    if q.rel_error_bound is not None:
        w(f"#define {macro}_QUANT_REL_ERROR_BOUND {_literal(q.rel_error_bound, '')}")
    emitted = []
    for row in FLOAT_TYPES:
        ctype, suffix, fsuffix, u = row
        if suffix == "f" and not all(_to_type(c, "f") == c for c in coeffs):
            continue
        problem = evaluator_range_problem(table, coeffs, parity, suffix, u, max_x)
        if problem is not None and suffix == "":
            raise ValueError(f"table {table.name!r}: the quantized coefficients have no double "
                             f"evaluator on the interval: {problem}; accepted: a table whose "
                             f"Horner evaluation stays within the double range")
        if problem is not None:
            w(f"/* No {ctype} evaluator of the quantized coefficients: {comment_text(problem)}. */")
            continue
        emitted.append(row)
        constant = f"{macro}_QUANT{fsuffix.upper()}_EVAL_ERROR_BOUND"
        piece = Piece(tuple(coeffs), tuple(coeffs), Fraction(q.abs_error_bound),
                      *inner_interval(table))
        ev = Evaluator(constant, f"{fn}_quant{fsuffix}", BINARY32 if suffix == "f" else BINARY64,
                       (piece,), parity=parity, target=(table.expression, table.variable))
        evaluators.append(ev)
        w(_bound_line(ev, proof))
    w(f"static const double {fn}_quant_coeffs[{len(coeffs)}] = {{")
    for k, c in enumerate(coeffs):
        w(f"    {_literal(c, '')}{',' if k < len(coeffs) - 1 else ''}  /* x^{k} */")
    w("};")
    for ctype, suffix, fsuffix, _ in emitted:
        name = f"{fn}_quant{fsuffix}"
        out += (_float_evaluator(table, coeffs, ctype, suffix, name, macro) if parity is None
                else _parity_evaluator(coeffs, parity, ctype, suffix, name, macro))
    return out


def banner_head(fn: str, table, command: str) -> list[str]:
    """The first lines of a generated header's banner comment: the file, the
    tool and version, the generating command and the table's own provenance
    (all text through :func:`~chebnorm.core.textsafe.comment_text`).

    Parameters
    ----------
    fn : str
        The function name (an identifier, ``chebnorm_<name>``); the file is
        named ``<fn>.h`` in the banner.
    table : CoefficientTable
        The table; its ``provenance["command"]`` is quoted (``"unknown"``
        when absent).
    command : str
        The command that generated the file; empty leaves its line out.

    Returns
    -------
    list of str
        The opening ``/*`` and the banner lines, without the closing ``*/``
        (the caller appends the rest of the banner).

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> head = banner_head("chebnorm_d1", fit("x", ("0", "1"), 1), "make */ evil")
    >>> head[1].startswith(" * chebnorm_d1.h -- generated by chebnorm "), "*/" in head[2]
    (True, False)
    """
    from chebnorm import __version__

    out = ["/*", f" * {fn}.h -- generated by chebnorm {comment_text(__version__)}; do not edit."]
    if command:
        out.append(f" * Command: {comment_text(command)}")
    out.append(f" * Table provenance: {comment_text(table.provenance.get('command', 'unknown'))}")
    return out


@export_doc
def c_header(table: CoefficientTable, command: str = "") -> str:
    """The C99 header text for ``table`` (see the module docstring).

    Parameters
    ----------
    table : CoefficientTable
        The table to print; its name must be an identifier (it makes
        ``chebnorm_<name>`` and ``CHEBNORM_<NAME>_*``).
    %(command)s

    Returns
    -------
    str
        The whole header, ending in a newline.

    Raises
    ------
    ValueError
        When the table cannot be printed as stated: a name that is not an
        identifier, a coefficient count other than ``degree + 1``, a
        fixed-point or quantized part in the shifted basis, fixed-point
        integers outside ``int32_t`` or whose Horner products overflow
        ``int64``, or a double evaluator that may overflow on the interval.

    Notes
    -----
    ``c_header_evaluators(table, command)`` returns the same text with the
    evaluators behind its bounds.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> h = c_header(fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 1, var="z", name="d1"))
    >>> "static inline double chebnorm_d1(double x)" in h
    True
    """
    return c_header_evaluators(table, command)[0]


def c_header_evaluators(table: CoefficientTable, command: str = "", proof: str = ""
                        ) -> tuple[str, list]:
    """The C99 header text and its :class:`~chebnorm.export.evalbound.Evaluator`
    list (one per stated evaluation bound).

    Parameters
    ----------
    table : CoefficientTable
    command : str
        The generating command stated in the banner.
    proof : str
        The stem of the Gappa proof files, named beside each bound (empty:
        none named).

    Returns
    -------
    tuple of (str, list of Evaluator)

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> text, evs = c_header_evaluators(fit("1/x", ("1", "2"), 2, name="inv"))
    >>> [e.constant for e in evs]
    ['CHEBNORM_INV_EVAL_ERROR_BOUND', 'CHEBNORM_INV_F_EVAL_ERROR_BOUND']
    """
    evaluators: list = []
    name = identifier(table.name, field="name")
    macro = f"CHEBNORM_{name.upper()}"
    fn = f"chebnorm_{name}"
    coeffs = list(table.coefficients)
    degree = _count(table.degree, "degree")
    if len(coeffs) != degree + 1:
        raise ValueError(f"coefficients: {len(coeffs)} numbers for degree {degree}; expected "
                         f"degree + 1 = {degree + 1}")
    max_x = interval_max_abs(table)
    shifted = table.shift is not None
    if shifted and table.fixed_point is not None:
        raise ValueError(f"table {table.name!r}: a fixed-point part in the shifted basis has no "
                         f"C evaluator; accepted: a shifted table without fixed_point")
    var, expr = comment_text(table.variable), comment_text(table.expression)
    lo_s, hi_s = (comment_text(v) for v in table.interval)
    lo_f, hi_f = (float(v) for v in table.interval_float)
    out = banner_head(fn, table, command)
    w = out.append
    w(f" * p({var}) ~ {expr} on [{lo_s}, {hi_s}] = [{lo_f!r}, {hi_f!r}]")
    powers = var if not shifted else (
        f"t = ({var} - {float(table.shift[0])!r})/{float(table.shift[1])!r}")
    w(f" * kind: {comment_text(table.kind)}, error kind: {comment_text(table.error_kind)}, "
      f"degree {degree}; coefficients in ascending powers of {powers}.")
    w(f" * Certified: |p - f| <= {float(table.abs_error_bound)!r}"
      + ("" if table.rel_error_bound is None else f", |p/f - 1| <= {float(table.rel_error_bound)!r}")
      + f"; located max |p - f| = {float(table.max_abs_error)!r} at {var} = "
        f"{float(table.max_abs_at)!r}.")
    w(" * The evaluators take their argument in the interval above; outside it no bound holds.")
    w(" */")
    w(f"#ifndef {macro}_H")
    w(f"#define {macro}_H")
    w("")
    w("#include <stdint.h>")
    w("")
    w(f"#define {macro}_DEGREE {degree}")
    lo_in, hi_in = inner_interval(table)  # rounded inward: every x between lies in the interval
    w(f"#define {macro}_LO {_literal(lo_in, '')}")
    w(f"#define {macro}_HI {_literal(hi_in, '')}")
    w(f"#define {macro}_ABS_ERROR_BOUND {_literal(table.abs_error_bound, '')}")
    if table.rel_error_bound is not None:
        w(f"#define {macro}_REL_ERROR_BOUND {_literal(table.rel_error_bound, '')}")
    if shifted:
        w(f"#define {macro}_CENTER {_literal(float(table.shift[0]), '')}")
        w(f"#define {macro}_SCALE {_literal(float(table.shift[1]), '')}")
    emitted = []
    for ctype, suffix, fsuffix, u in FLOAT_TYPES:
        bound, problem = _eval_bound(table, coeffs, suffix, u, max_x, f"{fn}{fsuffix}",
                                     f"{macro}{fsuffix.upper()}_EVAL_ERROR_BOUND")
        if problem is not None and suffix == "":
            raise ValueError(f"table {table.name!r} has no double evaluator on its interval: "
                             f"{problem}; accepted: a table whose Horner evaluation stays "
                             f"within the double range")
        if problem is not None:
            w(f"/* No {ctype} evaluator: {comment_text(problem)}. */")
            continue
        emitted.append((ctype, suffix, fsuffix))
        evaluators.append(bound)
        w(_bound_line(bound, proof))
    if table.fixed_point is not None:
        fp = _checked_fixed(table)
        _check_fixed_ranges(table, max_x)
        w(f"#define {macro}_FRAC_BITS {fp.frac_bits}")
        w(f"#define {macro}_Q_ABS_ERROR_BOUND {_literal(fp.abs_error_bound, '')}")
        qs = tuple(float(Fraction(q) / 2 ** fp.frac_bits) for q in fp.integers)
        ev = Evaluator(f"{macro}_Q_EVAL_ERROR_BOUND", f"{fn}_q_eval", fixed_arithmetic(fp.frac_bits),
                       (Piece(qs, qs, Fraction(fp.abs_error_bound), *inner_interval(table)),),
                       parity=coefficient_parity(fp.integers))
        evaluators.append(ev)
        w(_bound_line(ev, proof))
    w("")
    w(f"static const double {fn}_coeffs[{len(coeffs)}] = {{")
    for k, c in enumerate(coeffs):
        w(f"    {_literal(c, '')}{',' if k < len(coeffs) - 1 else ''}  /* {'t' if shifted else 'x'}^{k} */")
    w("};")
    parity = _table_parity(table, coeffs)
    for ctype, suffix, fsuffix in emitted:
        out += (_float_evaluator(table, coeffs, ctype, suffix, f"{fn}{fsuffix}", macro)
                if parity is None else
                _parity_evaluator(coeffs, parity, ctype, suffix, f"{fn}{fsuffix}", macro))
    if table.fixed_point is not None:
        out += _fixed_evaluator(table.fixed_point, fn, macro)
    elif table.quantized is not None:
        out += _quantized_part(table, fn, macro, max_x, evaluators, proof)
    w("")
    w(f"#endif /* {macro}_H */")
    return "\n".join(out) + "\n", evaluators


def _backed(ev, proof: str) -> str:
    """The comment naming the proof file of ``ev``'s constant (when proofs are written)."""
    return f"  /* proof: {comment_text(f'{proof}.{ev.constant}.gappa')} */" if proof else ""


def _bound_line(ev, proof: str) -> str:
    """``#define CONSTANT value`` and the evidence behind it: the Gappa proof
    of the interval bound, or the exhaustive certificate over every float32
    input (the proof file then proves the larger interval bound)."""
    from .certificate import stated_bound

    value, cert = stated_bound(ev)
    line = f"#define {ev.constant} {_literal(value, '')}"
    if cert is None:
        return line + _backed(ev, proof)
    proved = ev.bound().stated
    by = f" is proved by {comment_text(f'{proof}.{ev.constant}.gappa')}" if proof else ""
    return (line + f"  /* exhaustive: every float32 input and every fused/unfused mix checked"
            f" (chebnorm.export.certificate; chebnorm verify re-checks); the a-priori bound"
            f" {proved!r}" + by + " */")
