"""Shader printers (GLSL, WGSL, HLSL) of a :class:`~chebnorm.approx.CoefficientTable`.

One table-driven printer serves the three languages, in the manner of
sympy's code printers: a :class:`ShaderLanguage` row gives the type name,
the literal suffix, the multiply-add built-in, the declaration syntax and
the qualifier that forbids reassociation; :func:`shader_source` prints any
row. Each output is a function to paste (or ``#include``) into a shader::

    GLSL 4.30 / ES 3.10   float chebnorm_NAME(float x)
    WGSL                  fn chebnorm_NAME(x: f32) -> f32
    HLSL (SM 5)           float chebnorm_NAME(float x)

with the coefficients as float32 literals that convert *exactly* (see
:func:`float32_literal`), Horner's rule through the language's multiply-add
(``fma`` in GLSL 4.x, ES 3.20 and WGSL; ``a * b + c`` in ES 3.10, which has
no ``fma``; ``mad`` in HLSL, whose ``fma`` is for double only), the interval and the bounds as constants, and a comment banner.

The float32 evaluation bound
----------------------------
``CHEBNORM_NAME_EVAL_ERROR_BOUND`` bounds ``|shader(x) - f(x)|`` for every
float32 ``x`` in ``[CHEBNORM_NAME_LO, CHEBNORM_NAME_HI]``; it is the
shader analogue of the C header's ``_F_EVAL_ERROR_BOUND``
(:func:`float32_eval_bound` gives its parts):

* the certified bound of ``|p - f|`` for the coefficients evaluated: the
  table's double coefficients, or its ``quantized`` ones when their format is
  binary16, bfloat16 or binary32 (each a float32 exactly);
* the float32 evaluation error, computed for the shader's operation sequence
  by :func:`chebnorm.export.evalbound.horner_bound` (the C header's
  ``_F_EVAL_ERROR_BOUND`` computation): on each of 64 pieces of the interval,
  the coefficients' rounding to float32 and every operation's rounding (half
  an ulp of its largest result there, or the ``2^-126`` a flushed subnormal
  result loses), each step bounded fused and unfused, so the bound covers the
  compiler fusing any subset of the steps (GLSL and WGSL allow it; HLSL's
  ``mad`` may be either);
* ``2^-126 max |p'|`` when a subnormal input may be flushed to 0 (the
  analysed interval then reaches 0, so the evaluation at 0 is covered).

:func:`shader_evaluator` gives the evaluator that
:func:`chebnorm.export.gappa.gappa_script` proves (``chebnorm export
--proof``); the script models IEEE binary32 without the flushes.

What the bound assumes of the driver, from the specifications: float32
``+``, ``-``, ``*`` correctly rounded (round to nearest) and ``fma``'s
accuracy "inherited from" ``a * b + c``, that is fused or two rounded
operations (GLSL 4.60 section 4.7.1 "Range and Precision"; ES 3.20 section
4.7 for ``highp``; the WGSL specification's "Floating Point Accuracy" table;
Direct3D 11's floating-point rules for HLSL), no other reassociation (the
accumulator is ``precise`` in GLSL 4.x / ES 3.20 and HLSL; WGSL has no such
qualifier, and a chain in which each step needs the previous one leaves
nothing to reassociate), and the inputs in ``[LO, HI]``. ``mediump`` (ES)
is not covered: declare the caller's precision ``highp``. Division, which the
spec lets be 2.5 ULP, is never used. The tests measure every float32 of the
interval (or 2^20 evenly spread when there are more) on Mesa's llvmpipe
(GLSL) and lavapipe (WGSL) against ``f`` and find the error inside the bound.
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal
from fractions import Fraction

import numpy as np

from chebnorm.approx import CoefficientTable
from chebnorm.core.textsafe import comment_text, identifier

from chebnorm.core.numeric import float_up, format_up

from .c import (coefficient_parity, evaluator_range_problem, inner_interval, interval_max_abs,
                range_problem, round_inward)
from .evalbound import BINARY32_FTZ, Evaluator, Piece
from ._docfrag import export_doc

# an implementation module of chebnorm.export: the API is what chebnorm.export exports
__all__: list[str] = []

U32 = Fraction(1, 2 ** 24)
_FLUSH = Fraction(1, 2 ** 126)  # largest magnitude a flushed subnormal float32 loses


@dataclass(frozen=True)
class ShaderLanguage:
    """One row of the printer's table (see the module docstring).

    ``const``/``function``/``acc`` are format strings with the fields shown in
    :data:`SHADER_LANGUAGES`; ``prelude``/``postlude`` wrap the function.

    Attributes
    ----------
    name : str
        The language's key in :data:`SHADER_LANGUAGES` (``"glsl"``, ...).
    title : str
        The language and version named in the banner.
    float_type : str
        The name of the 32-bit float type (``float``, ``f32``).
    suffix : str
        The float literal suffix (``""`` or ``"f"``).
    madd : str
        The multiply-add called in each Horner step (``fma``, ``mad``, or a
        macro with field ``{P}``, the macro prefix).
    const : str
        Format string of a constant declaration, fields ``{name}`` and
        ``{value}``.
    function : str
        Format string of the function's opening, field ``{fn}``.
    acc : str
        Format string of the accumulator's declaration (with the qualifier
        that forbids reassociation), fields ``{P}`` and ``{value}``.
    prelude, postlude : tuple of str, default ()
        Lines printed before and after the function, field ``{P}``.

    Examples
    --------
    >>> g = SHADER_LANGUAGES["wgsl"]
    >>> g.float_type, g.const.format(name="C0", value="1.0")
    ('f32', 'const C0: f32 = 1.0;')
    """

    name: str
    title: str
    float_type: str
    suffix: str
    madd: str
    const: str
    function: str
    acc: str
    prelude: tuple[str, ...] = ()
    postlude: tuple[str, ...] = ()


#: the shader languages the printer writes, by name (``glsl``, ``wgsl``, ``hlsl``)
SHADER_LANGUAGES = {
    "glsl": ShaderLanguage(
        name="glsl", title="GLSL 4.30 / GLSL ES 3.10", float_type="float", suffix="",
        madd="{P}_FMA",
        const="const float {name} = {value};",
        function="float {fn}(float x)\n{{",
        acc="    {P}_PRECISE float acc = {value};",
        prelude=("// fma() and precise (no reassociation) are core in GLSL 4.00 and ES 3.20; ES 3.10",
                 "// gets a * b + c, which the compiler may fuse or not: the bound covers both.",
                 "#if defined(GL_ES) && __VERSION__ < 320",
                 "#define {P}_PRECISE",
                 "#define {P}_FMA(a, b, c) ((a) * (b) + (c))",
                 "#else",
                 "#define {P}_PRECISE precise",
                 "#define {P}_FMA(a, b, c) fma(a, b, c)",
                 "#endif"),
        postlude=("#undef {P}_PRECISE", "#undef {P}_FMA")),
    "wgsl": ShaderLanguage(
        name="wgsl", title="WGSL (WebGPU)", float_type="f32", suffix="f", madd="fma",
        const="const {name}: f32 = {value};",
        function="fn {fn}(x: f32) -> f32 {{",
        acc="    var acc: f32 = {value};"),
    "hlsl": ShaderLanguage(
        name="hlsl", title="HLSL (Shader Model 5)", float_type="float", suffix="f", madd="mad",
        const="static const float {name} = {value};",
        function="float {fn}(float x)\n{{",
        acc="    precise float acc = {value};"),
}


def _round32(value: Fraction) -> float:
    """``value`` rounded to the nearest float32 (ties to even), exactly."""
    f = np.float32(float(value))  # within one float32 step of the answer
    for _ in range(3):
        down = np.nextafter(f, np.float32(-np.inf), dtype=np.float32)
        up = np.nextafter(f, np.float32(np.inf), dtype=np.float32)
        lo_mid = (Fraction(float(down)) + Fraction(float(f))) / 2
        hi_mid = (Fraction(float(f)) + Fraction(float(up))) / 2
        if value < lo_mid:
            f = down
        elif value > hi_mid:
            f = up
        elif value == lo_mid or value == hi_mid:
            even = f if (int(np.float32(f).view(np.uint32)) & 1) == 0 else None
            if even is None:
                f = down if value == lo_mid else up
            return float(f)
        else:
            return float(f)
    raise AssertionError("float32 rounding did not settle")  # unreachable: one step suffices


def float32_literal(value: float, suffix: str = "") -> str:
    """A decimal literal that converts exactly to ``float32(value)``.

    GLSL and HLSL have no hexadecimal floats, so the literal is decimal: the
    shortest that rounds to the float32 both directly (a correctly rounding
    compiler) and through a double first (a compiler reading ``strtod`` and
    then narrowing: double rounding); if the shortest fails either way, 9
    significant digits, then the exact decimal expansion, which always works.

    Parameters
    ----------
    value : float
        The number; it is rounded to float32 first (round to nearest even).
    suffix : str, optional
        Appended to the literal (``"f"`` for WGSL and HLSL). Default ``""``.

    Returns
    -------
    str
        A decimal literal in scientific notation (``d.ddde+XX``) whose value
        rounds to ``float32(value)`` directly and through a double.

    Raises
    ------
    ValueError
        When ``value`` is not finite in float32 (``|value| >= 3.4e38`` after
        rounding, an infinity or NaN).

    Examples
    --------
    >>> float32_literal(0.1), float32_literal(-1.5, "f"), float32_literal(0.0)
    ('1.0e-01', '-1.5e+00f', '0.0e+00')
    """
    with np.errstate(over="ignore"):
        target = np.float32(value)
    if not np.isfinite(target):
        raise ValueError(f"coefficient {value!r} is not finite in float32; accepted: "
                         f"|value| < 3.4e38")
    if target == 0:
        return f"0.0e+00{suffix}"
    tf = float(target)
    candidates = [np.format_float_scientific(target, unique=True, exp_digits=2),
                  np.format_float_scientific(target, precision=8, unique=False, exp_digits=2)]
    for s in candidates:
        s = s.replace(".e", ".0e")
        d = Fraction(Decimal(s))
        if _round32(d) == tf and float(np.float32(float(d))) == tf:
            return s + suffix
    exact = Decimal(tf)  # every float32 is a finite decimal
    s = f"{exact:e}"
    return s + suffix


@dataclass(frozen=True)
class ShaderBound:
    """Parts of the float32 bound of ``|shader(x) - f(x)|`` (module docstring).

    ``rounding`` is the evaluation part (float32 coefficients and Horner
    rounding together, with the proof headroom; ``coefficients`` is 0, kept
    for callers), ``flush`` the subnormal-input term; ``total`` is their sum
    with ``certified`` rounded up to a double, ``total32`` up to a float32
    (the value printed as a shader constant).

    Attributes
    ----------
    certified : Fraction
        The certified ``sup |p - f|`` of the coefficients evaluated (the
        double ones, or float32-exact quantized ones).
    coefficients : Fraction
        Always 0 (coefficient rounding is inside ``rounding``); kept for
        callers.
    rounding : Fraction
        The float32 coefficient and Horner rounding part, with the proof
        headroom (:data:`chebnorm.export.evalbound.PROOF_HEADROOM`).
    flush : Fraction
        ``2**-126 max |p'|`` when a subnormal input may be flushed to 0,
        else 0.
    total : float
        ``certified + rounding + flush`` rounded up to a double.
    total32 : float
        ``total`` rounded up to a float32: the shader's
        ``CHEBNORM_NAME_EVAL_ERROR_BOUND``.
    certificate : ExhaustiveCertificate or None, default None
        When the evaluation part is the exhaustive certificate of
        :func:`chebnorm.export.certificate.stated_bound` (every float32
        input, every fused/unfused mix) rather than the interval bound.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> b = float32_eval_bound(fit("1/x", ("1", "2"), 1, name="inv"))
    >>> b.certified + b.coefficients + b.rounding + b.flush <= Fraction(b.total) <= Fraction(b.total32)
    True
    """

    certified: Fraction
    coefficients: Fraction
    rounding: Fraction
    flush: Fraction
    total: float
    total32: float
    certificate: object = None


#: quantized formats whose every number is a float32 (used as they are)
_FLOAT32_FORMATS = ("binary16", "bfloat16", "binary32")


def _coefficients(table: CoefficientTable) -> tuple[list[float], Fraction, str]:
    """The coefficients a shader evaluates, their certified ``|p - f|`` bound
    and how they were chosen: a table quantized to a floating format a float32
    holds exactly gives those coefficients and their certified bound (nothing
    lost rounding them); any other table its double coefficients, rounded to
    float32 below."""
    q = table.quantized
    if q is not None and q.format in _FLOAT32_FORMATS:
        coeffs = [float(c) for c in q.coefficients]
        if all(float(np.float32(c)) == c for c in coeffs):
            return coeffs, Fraction(q.abs_error_bound), f"{q.format} coefficients ({q.method})"
    return ([float(c) for c in table.coefficients], Fraction(table.abs_error_bound),
            "double coefficients")


def float32_eval_bound(table: CoefficientTable) -> ShaderBound:
    """The float32 evaluation bound of the shader printers, fused or not.

    Parameters
    ----------
    table : CoefficientTable
        A table in plain powers of ``x`` (``basis="monomial"``) or of
        ``t = (x - c)/s`` (``basis="shifted"``, ``s`` a power of two: the
        shader forms ``t`` as ``(x - c32) * (1/s)``).

    Returns
    -------
    ShaderBound
        The bound's parts and its double and float32 round-ups.

    Raises
    ------
    ValueError
        When the table is in a shifted basis whose scale is not a power of
        two, its name is not an identifier, or its float32 Horner evaluation
        may overflow on the interval.

    Notes
    -----
    With :math:`A` the certified bound, :math:`L` the local bound of
    :func:`chebnorm.export.evalbound.horner_bound` (binary32, fused and
    unfused steps, subnormal results possibly flushed) and :math:`M` a bound
    of :math:`|x|`,

    .. math::

        |\\mathrm{shader}(x) - f(x)| \\le A + L\\,(1 + h)
            + [\\text{flush}]\\; 2^{-126} \\sum_{k \\ge 1} k |c_k| M^{k-1},

    :math:`h` the proof headroom; the a priori alternative is Higham's
    :math:`\\gamma_{2n} \\sum_k |c_k| M^k` [1]_ (eq. 5.3).

    References
    ----------
    .. [1] N. J. Higham, *Accuracy and Stability of Numerical Algorithms*,
       2nd ed., SIAM, 2002, eq. (5.3).

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> b = float32_eval_bound(fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 2, var="z", name="d2"))
    >>> b.certified < b.total <= b.total32 < 2.2e-5
    True
    """
    _check_shift(table)
    coeffs, certified, _ = _coefficients(table)
    m = interval_max_abs(table)
    # no bound for an evaluator that can overflow float32 on the interval (nor
    # for one whose flushed underflows the flush term below does not cover)
    if table.shift is None:
        problem = evaluator_range_problem(table, _float32s(coeffs), _parity32(table, coeffs), "f",
                                          float(U32), m)
    else:
        problem = range_problem(_float32s(coeffs), _shifted_max(table), "f", float(U32),
                                where=(*inner_interval(table), table.shift, None))
    if problem is not None:
        raise ValueError(f"table {table.name!r} has no float32 shader evaluator on its "
                         f"interval: {problem}; accepted: a table whose Horner evaluation stays "
                         f"within the float32 range (|values| < 3.4e38)")
    from .certificate import stated_bound

    ev = shader_evaluator(table)
    stated, cert = stated_bound(ev)
    lo32, hi32 = interval32(table)
    flush = Fraction(0)
    if lo32 < 2.0 ** -126 and hi32 > -2.0 ** -126:
        # a subnormal input x may be flushed to x' = 0, which lies in the
        # analysed interval (shader_evaluator): |shader(x') - p(x')| is within
        # the local bound, and |p(x') - p(x)| <= 2^-126 max |p'|
        # (shifted: p is in t = (x - c)/s, so |dt| <= 2^-126 / s and |t| <= its bound)
        scale, m = ((Fraction(1), m) if table.shift is None else
                    (1 / Fraction(table.shift[1]), _shifted_max(table)))
        flush = _FLUSH * scale * sum((k * abs(Fraction(c)) * m ** (k - 1)
                                      for k, c in enumerate(coeffs) if k), Fraction(0))
    total = Fraction(stated) + flush
    up = float_up(total)
    up32 = float(np.float32(up))
    if up32 < up:
        up32 = float(np.nextafter(np.float32(up32), np.float32(np.inf), dtype=np.float32))
    return ShaderBound(certified=certified, coefficients=Fraction(0),
                       rounding=Fraction(stated) - certified, flush=flush, total=up,
                       total32=up32, certificate=cert)


def _parity32(table: CoefficientTable, coeffs) -> int | None:
    """The parity of the shader's float32 coefficients (its evaluator is then
    ``x*q(x*x)`` or ``q(x*x)``): :func:`chebnorm.export.c.coefficient_parity`;
    None for a shifted table (its coefficients are in ``t``, not ``x``)."""
    return None if table.shift is not None else coefficient_parity(_float32s(coeffs))


def _check_shift(table: CoefficientTable) -> None:
    """Refuse a shifted table whose scale is not a power of two: the shaders
    form ``t = (x - c) * (1/s)`` with no division (which the shading
    languages let be 2.5 ulp) and no rounding of ``1/s``."""
    if table.shift is not None:
        s = float(table.shift[1])
        if not (s > 0 and np.frexp(s)[0] == 0.5):
            raise ValueError(f"table {table.name!r}: the shaders evaluate the shifted variable "
                             f"t = (x - c) * (1/s) with s a power of two; its s = {s!r}; "
                             f"accepted: a table fitted with basis='shifted' (s a power of two) "
                             f"or basis='monomial'")


def _shift_tuple(table: CoefficientTable):
    """``(c, s, c32, s32, True)``: the shifted variable of the float32
    evaluator, as :class:`~chebnorm.export.evalbound.Evaluator` takes it
    (``t = (x - c32) * (1/s)``, the product exact); None for a monomial table."""
    if table.shift is None:
        return None
    c, s = table.shift
    return (Fraction(c), Fraction(s), Fraction(float(np.float32(c))),
            Fraction(float(np.float32(s))), True)


def _shifted_max(table: CoefficientTable) -> Fraction:
    """A bound of ``|t|`` and of the float32 ``t`` of a shifted table over its
    interval: ``max |x - c| / s`` plus the shift's own error (the centre
    rounded to float32, the subtraction's half ulp, a flushed result)."""
    c, s = (Fraction(v) for v in table.shift)
    c32 = Fraction(float(np.float32(table.shift[0])))
    lo, hi = (Fraction(v) for v in inner_interval(table))
    reach = max(abs(lo - c32), abs(hi - c32))
    return (max(abs(lo - c), abs(hi - c)) + abs(c - c32) + reach * U32 + _FLUSH) / s


def _float32s(coeffs) -> list[float]:
    """The coefficients rounded to float32, a coefficient beyond its range as an
    infinity (which the range check refuses), without numpy's overflow warning."""
    with np.errstate(over="ignore"):
        return [float(np.float32(c)) for c in coeffs]


def shader_evaluator(table: CoefficientTable, constant: str = ""):
    """The :class:`~chebnorm.export.evalbound.Evaluator` of the shader
    function: float32 Horner's rule (fused or not, subnormals possibly
    flushed) on the float32 coefficients, over the float32 interval; in
    ``t = x*x`` over the nonzero coefficients when they are all of odd
    (then times ``x``) or all of even powers.

    Parameters
    ----------
    table : CoefficientTable
        The table; its name must be an identifier.
    constant : str, optional
        The bound's constant name. Default ``""``:
        ``CHEBNORM_<NAME>_EVAL_ERROR_BOUND``.

    Returns
    -------
    Evaluator
        One piece on the C header's inner interval (extended to 0 when a
        subnormal input may flush to it), arithmetic
        :data:`chebnorm.export.evalbound.BINARY32_FTZ`.

    Raises
    ------
    ValueError
        When the table's name is not an identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> shader_evaluator(fit("1/x", ("1", "2"), 1, name="inv")).arith.flush
    True
    """
    coeffs, certified, _ = _coefficients(table)
    c32 = tuple(float(np.float32(c)) for c in coeffs)
    # the C header's interval (its float32 inputs are the shader's), reaching 0
    # when a subnormal input may be flushed to it
    lo, hi = inner_interval(table)
    if 0 < lo < 2.0 ** -126:
        lo = 0.0
    elif -2.0 ** -126 < hi < 0:
        hi = 0.0
    piece = Piece(c32, tuple(coeffs), certified, lo, hi)
    name = identifier(table.name, field="table.name")
    _check_shift(table)
    return Evaluator(constant or f"CHEBNORM_{name.upper()}_EVAL_ERROR_BOUND",
                     f"chebnorm_{name}", BINARY32_FTZ, (piece,),
                     target=(table.expression, table.variable), parity=_parity32(table, coeffs),
                     shift=_shift_tuple(table))


def interval32(table: CoefficientTable) -> tuple[float, float]:
    """The table's interval rounded *inward* to float32: every float32 in it
    lies in the table's interval (the shaders' ``_LO``/``_HI`` and the GPU
    checks' input range).

    Parameters
    ----------
    table : CoefficientTable
        The table; its exact ``interval`` is read.

    Returns
    -------
    tuple of (float, float)
        ``(lo, hi)`` as Python floats holding float32 values.

    Examples
    --------
    >>> from fractions import Fraction
    >>> from chebnorm.approx import fit
    >>> lo, hi = interval32(fit("x", ("-0.1", "0"), 1))
    >>> Fraction(-1, 10) <= Fraction(lo) and hi == 0.0
    True
    """
    return round_inward(*inner_interval(table), "f")


@export_doc
def shader_source(table: CoefficientTable, language: str, command: str = "", *,
                  proof: str = "") -> str:
    """The shader function of ``table`` in ``language`` (glsl, wgsl or hlsl);
    ``proof``: the stem of the Gappa proof file named in the banner (empty:
    none).

    Parameters
    ----------
    %(shader_table)s
    language : {"glsl", "wgsl", "hlsl"}
        The shading language (a key of :data:`SHADER_LANGUAGES`).
    %(command)s
    proof : str, optional
        The stem of the Gappa proof file named beside the bound. Default
        ``""`` (none).

    Returns
    -------
    str
        The banner, the constants (``_LO``, ``_HI``, ``_ABS_ERROR_BOUND``,
        ``_EVAL_ERROR_BOUND``) and the function, ending in a newline.

    Raises
    ------
    ValueError
        When ``language`` is unknown, the table is in a shifted basis whose
        scale is not a power of two, its name is not an identifier, or its
        float32 evaluation may overflow (or its bound exceeds the float32
        range).

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 1, var="z", name="d1")
    >>> "float chebnorm_d1(float x)" in shader_source(t, "glsl")
    True
    >>> "fn chebnorm_d1(x: f32) -> f32 {" in shader_source(t, "wgsl")
    True
    """
    _check_shift(table)
    from chebnorm import __version__

    try:
        lang = SHADER_LANGUAGES[language]
    except KeyError:
        raise ValueError(f"unknown shader language {language!r}; accepted: "
                         f"{', '.join(SHADER_LANGUAGES)}") from None
    name = identifier(table.name, field="table.name")
    fn = f"chebnorm_{name}"
    big = f"CHEBNORM_{name.upper()}"
    coeffs, certified, source = _coefficients(table)
    bound = float32_eval_bound(table)
    if not np.isfinite(bound.total32):
        raise ValueError(f"table {table.name!r}: its float32 evaluation bound "
                         f"{format_up(bound.total, '.3g')} "
                         f"exceeds the float32 range; accepted: a bound below 3.4e38")
    lo32, hi32 = interval32(table)
    var = comment_text(table.variable, max_length=40)
    lit = lambda v: float32_literal(v, lang.suffix)  # noqa: E731
    out = []
    w = out.append
    w(f"// {fn} -- {lang.title} -- generated by chebnorm {__version__}; do not edit.")
    if command:
        w(f"// Command: {comment_text(command)}")
    w(f"// Table provenance: {comment_text(table.provenance.get('command', 'unknown'))}")
    w(f"// p({var}) ~ {comment_text(table.expression)} on "
      f"[{comment_text(table.interval[0], max_length=80)}, "
      f"{comment_text(table.interval[1], max_length=80)}]"
      f" = [{table.interval_float[0]!r}, {table.interval_float[1]!r}]")
    powers_of = var if table.shift is None else f"t = ({var} - c)/s"
    w(f"// {comment_text(table.kind, max_length=40)} fit of degree {table.degree}; coefficients"
      f" in ascending powers of {powers_of}, rounded to float32 (exact literals).")
    w(f"// Certified |p - f| <= {float(certified)!r} ({source}, exact arithmetic).")
    w(f"// {big}_EVAL_ERROR_BOUND bounds |{fn}(x) - f(x)| for float32 x in [{big}_LO, {big}_HI]:")
    if bound.certificate is None:
        w(f"//   certified {format_up(float(bound.certified), '.6e')} + float32 coefficients and "
          f"Horner rounding"
          f" {format_up(float(bound.rounding), '.6e')}")
        w("//   (chebnorm.export.evalbound: interval arithmetic on 64 pieces, each rounding half"
          " an ulp of its")
        w(f"//   largest result there, fused or not) + subnormal input flush "
          f"{format_up(float(bound.flush), '.3e')}."
          + (f" Proof: {comment_text(f'{proof}.{big}_EVAL_ERROR_BOUND.gappa')}" if proof else ""))
    else:
        w(f"//   the certified maximum of |{fn}(x) - f(x)| "
          f"{format_up(float(bound.certificate.maximum), '.6e')}"
          f" rounded up")
        w("//   (chebnorm.export.certificate: exhaustive, every float32 input and every fused/"
          "unfused mix run")
        w(f"//   bit-exactly against a proved enclosure of f) + subnormal input flush "
          f"{format_up(float(bound.flush), '.3e')}.")
        w(f"//   The a-priori bound {shader_evaluator(table).bound().stated!r} (interval "
          f"arithmetic) is proved"
          + (f" by {comment_text(f'{proof}.{big}_EVAL_ERROR_BOUND.gappa')}." if proof
             else " by its Gappa script."))
    w("// Assumes float32 (highp) with correctly rounded + and *, and a multiply-add that is fused"
      " or two roundings.")
    w("")
    for line in lang.prelude:
        w(line.format(P=big))
    w(lang.const.format(name=f"{big}_LO", value=lit(lo32)))
    w(lang.const.format(name=f"{big}_HI", value=lit(hi32)))
    w(lang.const.format(name=f"{big}_ABS_ERROR_BOUND", value=lit(_up_f32(float_up(certified)))))
    w(lang.const.format(name=f"{big}_EVAL_ERROR_BOUND", value=lit(bound.total32)))
    w("")
    parity = _parity32(table, coeffs)
    if table.shift is not None:
        c, sc = table.shift
        w(f"// Horner's rule in t = (x - {float(np.float32(c))!r}) * {1 / sc!r} (the product "
          f"exact); x must lie in [{big}_LO, {big}_HI].")
    elif parity is None:
        w(f"// Horner's rule; x must lie in [{big}_LO, {big}_HI].")
    else:
        w(f"// Horner's rule over the {'odd' if parity else 'even'} powers, in t = x*x; x must "
          f"lie in [{big}_LO, {big}_HI].")
    w(lang.function.format(fn=fn))
    arg, powers = "x", list(range(len(coeffs)))
    if table.shift is not None:
        arg = "t"
        w(lang.acc.replace(" acc", " t", 1).format(
            P=big, value=f"(x - {lit(table.shift[0])}) * {lit(1 / table.shift[1])}"))
    if parity is not None:
        arg, powers = "t", powers[parity::2]
        w(lang.acc.replace(" acc", " t", 1).format(P=big, value="x * x"))
    label = "x" if table.shift is None else "t"   # the power the coefficient multiplies
    w(lang.acc.format(P=big, value=lit(coeffs[powers[-1]])) + f"  // {label}^{powers[-1]}: "
      f"{float(np.float32(coeffs[powers[-1]])).hex()}")
    for k in reversed(powers[:-1]):
        w(f"    acc = {lang.madd.format(P=big)}(acc, {arg}, {lit(coeffs[k])});  // {label}^{k}: "
          f"{float(np.float32(coeffs[k])).hex()}")
    w("    return acc * x;" if parity == 1 else "    return acc;")
    w("}")
    for line in lang.postlude:
        w(line.format(P=big))
    return "\n".join(out) + "\n"


def _up_f32(value: float) -> float:
    """Smallest float32 >= ``value``."""
    f = np.float32(value)
    if float(f) < value:
        f = np.nextafter(f, np.float32(np.inf), dtype=np.float32)
    return float(f)


@export_doc
def glsl_source(table: CoefficientTable, command: str = "") -> str:
    """:func:`shader_source` in GLSL.

    Parameters
    ----------
    %(shader_table)s
    %(command)s

    Returns
    -------
    str
        ``shader_source(table, "glsl", command)``.

    Raises
    ------
    ValueError
        When the table is in a shifted basis whose scale is not a power of
        two, its name is not an identifier, or its float32 Horner evaluation
        may overflow on the interval.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> t = fit("1/x", ("1", "2"), 1, name="inv")
    >>> glsl_source(t) == shader_source(t, "glsl"), "float chebnorm_inv(float x)" in glsl_source(t)
    (True, True)
    """
    return shader_source(table, "glsl", command)


@export_doc
def wgsl_source(table: CoefficientTable, command: str = "") -> str:
    """:func:`shader_source` in WGSL.

    Parameters
    ----------
    %(shader_table)s
    %(command)s

    Returns
    -------
    str
        ``shader_source(table, "wgsl", command)``.

    Raises
    ------
    ValueError
        When the table is in a shifted basis whose scale is not a power of
        two, its name is not an identifier, or its float32 Horner evaluation
        may overflow on the interval.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> "fn chebnorm_inv(x: f32) -> f32" in wgsl_source(fit("1/x", ("1", "2"), 1, name="inv"))
    True
    """
    return shader_source(table, "wgsl", command)


@export_doc
def hlsl_source(table: CoefficientTable, command: str = "") -> str:
    """:func:`shader_source` in HLSL.

    Parameters
    ----------
    %(shader_table)s
    %(command)s

    Returns
    -------
    str
        ``shader_source(table, "hlsl", command)``.

    Raises
    ------
    ValueError
        When the table is in a shifted basis whose scale is not a power of
        two, its name is not an identifier, or its float32 Horner evaluation
        may overflow on the interval.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> "float chebnorm_inv(float x)" in hlsl_source(fit("1/x", ("1", "2"), 1, name="inv"))
    True
    """
    return shader_source(table, "hlsl", command)
