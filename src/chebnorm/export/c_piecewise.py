"""C99 header printer for a :class:`~chebnorm.approx.PiecewiseTable`.

The header holds a ``static const double`` coefficient array (one row per
segment, exact: every coefficient is an integer times ``2**-F``), the index
computation and Horner's rule in the segment's local variable:

* uniform tables: ``double chebnorm_NAME(uint32_t k)`` takes the
  ``IN_BITS``-bit input code ``k`` (``x = lo + (hi - lo) k / 2**IN_BITS``),
  the segment is ``k >> (IN_BITS - K)``, ``t`` the low bits times
  ``2**-(IN_BITS - K)`` (exact), as the hardware does;
* exponent tables: ``double chebnorm_NAME(double x)`` on ``[lo, hi)``,
  segment from ``frexp``'s exponent and the mantissa's top bits, ``t`` the
  remaining mantissa bits (exact).

The local variable is computed exactly in both, so the bounds are
``<P>_ABS_ERROR_BOUND`` (the table's certified ``max_s sup |p_s - f|``) and
``<P>_EVAL_ERROR_BOUND``: ``max_s`` of the segment's certified bound plus
its local double Horner rounding bound (:mod:`chebnorm.export.evalbound`,
fused or not) -- as :func:`chebnorm.export.c_header`. Names pass through
:func:`chebnorm.core.textsafe.identifier`, other text through
``comment_text``; numbers are printed from floats and ints.

>>> from chebnorm.approx.piecewise_fit import piecewise_fit
>>> h = piecewise_c_header(piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, name="r"))
>>> "static inline double chebnorm_r(uint32_t k)" in h
True
"""

from __future__ import annotations

from fractions import Fraction

from chebnorm.approx.piecewise_table import PiecewiseTable
from chebnorm.core.textsafe import comment_text, identifier

from .c import banner_head, range_problem
from .evalbound import BINARY64, Evaluator, Piece
from ._docfrag import export_doc

# an implementation module of chebnorm.export: the API is what chebnorm.export exports
__all__: list[str] = []

#: The default width (bits) of a uniform table's input code ``k`` in the C
#: evaluator ``chebnorm_NAME(uint32_t k)``.
DEFAULT_C_IN_BITS = 24
#: The largest accepted width of that input code (it is a ``uint32_t``).
MAX_C_IN_BITS = 32
_U = 2.0 ** -53


def _lit(x: float) -> str:
    return "0.0" if x == 0 else f"{float(x).hex()} /* {x!r} */"


def piecewise_evaluator(table: PiecewiseTable, constant: str = ""):
    """The :class:`~chebnorm.export.evalbound.Evaluator` of the double
    evaluator: one piece per segment (its coefficients, certified bound and
    the range of its exact local variable ``t``), 64 subintervals each.

    Parameters
    ----------
    table : PiecewiseTable
        The piecewise table; its name must be an identifier.
    constant : str, optional
        The name of the bound's C macro. Default ``""``:
        ``CHEBNORM_<NAME>_EVAL_ERROR_BOUND``.

    Returns
    -------
    Evaluator
        The double (binary64) evaluator, its pieces on ``t`` in ``[0, 1]``
        (``[-1/2, 1/2]`` for a centered table).

    Raises
    ------
    ValueError
        When a segment's Horner evaluation may leave the double range
        (:func:`chebnorm.export.c.range_problem`), or the name is not an
        identifier.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> ev = piecewise_evaluator(piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, name="r"))
    >>> len(ev.pieces), ev.pieces[0].lo, ev.pieces[0].hi
    (4, 0.0, 1.0)
    """
    tlo, thi = (-0.5, 0.5) if table.centered else (0.0, 1.0)
    tmax = Fraction(1, 2) if table.centered else Fraction(1)
    pieces = []
    for s, seg in enumerate(table.segments):
        cs = tuple(float(c) for c in table.coefficients(s))
        problem = range_problem(cs, tmax, "", _U)
        if problem is not None:
            raise ValueError(f"table {table.name!r}, segment {s}: no double evaluator: {problem}; "
                             f"accepted: coefficients whose Horner evaluation stays within the "
                             f"double range")
        pieces.append(Piece(cs, cs, Fraction(seg.abs_error_bound), tlo, thi))
    name = identifier(table.name, field="name")
    return Evaluator(constant or f"CHEBNORM_{name.upper()}_EVAL_ERROR_BOUND", f"chebnorm_{name}",
                     BINARY64, tuple(pieces), subintervals=64)


def piecewise_eval_bound(table: PiecewiseTable) -> float:
    """Bound of ``|evaluator(x) - f(x)|`` for the double evaluator (module
    docstring): the largest over the segments of the certified bound plus the
    local rounding bound of :func:`chebnorm.export.evalbound.horner_bound`.

    Parameters
    ----------
    table : PiecewiseTable
        The piecewise table.

    Returns
    -------
    float
        The stated bound (rounded up to a double) of the header's
        ``<P>_EVAL_ERROR_BOUND``.

    Raises
    ------
    ValueError
        As :func:`piecewise_evaluator`.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=4, name="rs")
    >>> b = piecewise_eval_bound(t)
    >>> worst = max(s.abs_error_bound for s in t.segments)  # + Horner rounding in double
    >>> worst < b < worst + 1e-15
    True
    """
    return piecewise_evaluator(table).bound().stated


@export_doc
def piecewise_c_header(table: PiecewiseTable, command: str = "", *,
                       in_bits: int = DEFAULT_C_IN_BITS, proof: str = "") -> str:
    """The C99 header text for a piecewise table (see the module docstring).

    Parameters
    ----------
    table : PiecewiseTable
        The piecewise table; its name must be an identifier.
    %(command)s
    in_bits : int, optional
        For a uniform table: the width of the input code ``k`` the function
        takes, ``max(K, 1) <= in_bits <= 32`` with ``2**K`` segments.
        Default ``DEFAULT_C_IN_BITS`` (24). Ignored for an exponent table.
    proof : str, optional
        The stem of the Gappa proof files named beside the bound. Default
        ``""`` (none named).

    Returns
    -------
    str
        The whole header, ending in a newline.

    Raises
    ------
    ValueError
        When ``in_bits`` is out of range, the name is not an identifier, or
        a segment's evaluator may leave the double range.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> h = piecewise_c_header(piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=2, name="rs"))
    >>> [line for line in h.splitlines() if line.startswith(("#ifndef", "static inline"))]
    ['#ifndef CHEBNORM_RS_H', 'static inline double chebnorm_rs(uint32_t k)']
    """
    name = identifier(table.name, field="name")
    macro, fn = f"CHEBNORM_{name.upper()}", f"chebnorm_{name}"
    n, K, N = table.degree, table.index_bits, table.segment_count
    uniform = table.segment_by == "uniform"
    if uniform:
        if isinstance(in_bits, bool) or not isinstance(in_bits, int) or \
                not max(K, 1) <= in_bits <= MAX_C_IN_BITS:
            raise ValueError(f"in_bits = {in_bits!r} is out of range; accepted: {max(K, 1)} <= "
                             f"in_bits <= {MAX_C_IN_BITS} (the table has 2^{K} segments)")
    var, expr = comment_text(table.variable), comment_text(table.expression)
    lo_s, hi_s = (comment_text(v) for v in table.interval)
    out = banner_head(fn, table, command)
    w = out.append
    w(f" * Piecewise p({var}) ~ {expr} on [{lo_s}, {hi_s}): {N} segments "
      f"({comment_text(table.segment_by)}), degree {n}, {comment_text(table.fit)} fits, "
      f"coefficients integers * 2^-{table.coef_frac_bits},")
    w(f" * each polynomial in its segment's local variable t in "
      f"{'[-1/2, 1/2]' if table.centered else '[0, 1]'}.")
    w(f" * Certified: max over segments of |p_s - f| <= {table.abs_error_bound!r}"
      + ("" if table.rel_error_bound is None else f", |p_s/f - 1| <= {table.rel_error_bound!r}")
      + ".")
    w(" */")
    w(f"#ifndef {macro}_H")
    w(f"#define {macro}_H")
    w("")
    w("#include <stdint.h>")
    if not uniform:
        w("#include <math.h>")
    w("")
    w(f"#define {macro}_DEGREE {n}")
    w(f"#define {macro}_SEGMENTS {N}")
    w(f"#define {macro}_ABS_ERROR_BOUND {table.abs_error_bound!r}")
    if table.rel_error_bound is not None:
        w(f"#define {macro}_REL_ERROR_BOUND {table.rel_error_bound!r}")
    w(f"#define {macro}_EVAL_ERROR_BOUND {piecewise_eval_bound(table)!r}"
      + (f"  /* proof: {comment_text(f'{proof}.{macro}_EVAL_ERROR_BOUND.gappa')} */"
         if proof else ""))
    if uniform:
        w(f"#define {macro}_IN_BITS {in_bits}")
    w("")
    w(f"static const double {fn}_coeffs[{N}][{n + 1}] = {{")
    for s in range(N):
        row = ", ".join(_lit(c) for c in table.coefficients(s))
        w(f"    {{{row}}}{',' if s < N - 1 else ''}")
    w("};")
    w("")
    half = " - 0.5" if table.centered else ""
    if uniform:
        L = in_bits - K
        lo_v, hi_v = table.lo, table.hi
        w(f"/* k: {in_bits}-bit input code, x = {comment_text(str(lo_v))} + "
          f"({comment_text(str(hi_v - lo_v))}) * k / 2^{in_bits}. */")
        w(f"static inline double {fn}(uint32_t k)")
        w("{")
        mask = (1 << in_bits) - 1
        w(f"    k &= UINT32_C({mask});")
        w(f"    const double *c = {fn}_coeffs[k >> {L}];" if K > 0 else f"    const double *c = {fn}_coeffs[0];")
        w(f"    double t = (double)(k & UINT32_C({(1 << L) - 1})) * {float(2.0 ** -L).hex()}{half};")
    else:
        e0 = table.exponent_range[0]
        per = 2 ** K
        w(f"/* x in [{lo_s}, {hi_s}); segment from the exponent and the top {K} mantissa bits. */")
        w(f"static inline double {fn}(double x)")
        w("{")
        w("    int e;")
        w("    double m = frexp(x, &e);              /* x = m 2^e, m in [1/2, 1) */")
        w(f"    double u = (2.0 * m - 1.0) * {float(per)!r};  /* exact */")
        w("    long j = (long)u;")
        w(f"    long s = (long)(e - 1 - ({e0})) * {per} + j;")
        w("    if (s < 0) s = 0;")
        w(f"    if (s > {N - 1}) s = {N - 1};")
        w(f"    const double *c = {fn}_coeffs[s];")
        w(f"    double t = (u - (double)j){half};")
    w(f"    double acc = c[{n}];")
    for j in range(n - 1, -1, -1):
        w(f"    acc = acc * t + c[{j}];")
    if n == 0:
        w("    (void)t;")
    w("    return acc;")
    w("}")
    w("")
    w(f"#endif /* {macro}_H */")
    return "\n".join(out) + "\n"
