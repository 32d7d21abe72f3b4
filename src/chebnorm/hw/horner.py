"""A bit-accurate fixed-point Horner evaluator built from a quantized table.

The datapath (``n`` = degree, ``q_j`` the table's fixed-point integers with
``Fc`` fractional bits, ``x = (K0 + k) / 2**Fx`` for the input code ``k``)::

    a_n     = q_n / 2**Fc                                   (exact)
    a_j     = R_Fa(a_{j+1} * x + q_j / 2**Fc),   j = n-1 .. 1
    y_raw   = R_Fy(a_1 * x + q_0 / 2**Fc) - Oy,  y = saturate(y_raw)

Two variants keep that datapath with another Horner variable ``v`` (the
design's ``scheme``): when every nonzero coefficient is of one parity,
``v = R(x*x)`` (squared once, exact or rounded two bits past the
accumulators) and Horner's rule runs over the nonzero coefficients only,
times ``x`` once at the end when odd; for a table in the shifted basis
``t = (x - c)/s`` (``s`` a power of two), ``v = (x - c')/s`` (one
subtraction; ``c' = c`` when ``c`` has few enough fractional bits).

Each step is a multiply-add done exactly, then one rounding (``R_F``: to
``F`` fractional bits, ``"trunc"`` or ``"rne"``); the output offset ``Oy``
is subtracted after rounding (exactly, it is a multiple of ``2**-Fy``).
Every intermediate wire is sized from its exact range over *all*
``2**in_bits`` input codes, so nothing but the output ever overflows, and
the output saturates.

Input codes (docs/hardware.md, "Input codes"): the ``W``-bit code ``k``
stands for ``x_k = lo + (hi - lo) k / 2**W`` on ``[lo, hi)``, as in
``chebnorm design`` and :mod:`chebnorm.hw.exhaustive`, whenever that is a
fixed-point format (``hi - lo`` a power of two, ``lo`` a multiple of the
step: ``Fx = W - log2(hi - lo)``, :func:`code_frac_bits`); every code is
then valid. Otherwise the format *covers* ``[lo, hi]`` with the largest
``Fx`` (:func:`cover_frac_bits`) and codes whose value lies outside the
table's interval are *invalid*: the circuit still answers (and the test
bench checks it), but the error budget holds on the valid codes, whose range
:attr:`HornerDesign.valid_codes` reports. An explicit ``x_frac_bits`` other
than the input-code one asks for the covering mapping.

>>> from chebnorm.approx import fit_target
>>> d = design_horner(fit_target("dichotomy", 2), 16, 16, coef_bits=20)
>>> d.x_format.frac_bits, d.y_format.frac_bits, d.valid_codes
(16, 20, (1, 38391))
>>> y = d.evaluate([1, 38391])
>>> [round(float(d.y_format.value(c)), 6) for c in y]
[0.541176, 0.50002]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from fractions import Fraction

import numpy as np
import sympy as sp

from chebnorm.approx import CoefficientTable, parse_number, quantize
from chebnorm.core.textsafe import identifier
from chebnorm.core.display import field_rows, summary_html, summary_repr

from .design_base import Design, provided, register
from .trust import check, drafting, seal
from .fixed import (QFormat, ROUNDINGS, check_int64, check_width, shift_round, signed_bits,
                    unsigned_bits)

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: widest input code of a Horner design (its model and test bench run all ``2**in_bits`` codes)
MAX_IN_BITS = 20
#: widest output code of a Horner design
MAX_OUT_BITS = 32
#: largest number of fractional bits of the coefficients, the input and the output formats (and
#: the bound of their negative counterparts)
MAX_FRAC_BITS = 40


@dataclass(frozen=True)
class Stage:
    """One Horner step ``a_j = R(a_{j+1} * x + c_j)`` with its exact widths.

    ``product_bits``/``sum_bits``: signed widths of ``a_{j+1} * xs`` and of the
    aligned sum (``sum_frac_bits`` fractional bits); ``out_bits``: width of
    the rounded result with ``out_frac_bits`` fractional bits;
    ``coef_shifted``: the integer added, ``q_j`` aligned to the sum.

    Attributes
    ----------
    power : int
        ``j``: the power of ``x`` whose coefficient this step adds (``n-1`` down to 0).
    acc_bits : int
        Signed width of the incoming accumulator ``a_{j+1}``.
    product_bits : int
        Signed width of the exact product ``a_{j+1} * xs``.
    product_shift : int
        Left shift aligning the product to the sum's fractional bits (``>= 0``).
    coef_shifted : int
        The integer added: ``q_j`` aligned to ``sum_frac_bits``.
    sum_bits : int
        Signed width of the exact sum.
    sum_frac_bits : int
        Fractional bits of the exact sum.
    out_bits : int
        Signed width of the rounded result ``a_j``.
    out_frac_bits : int
        Fractional bits of ``a_j`` (the accumulator's, or the output's at ``j = 0``).
    round_shift : int
        Bits dropped by the rounding: ``sum_frac_bits - out_frac_bits`` (``>= 0``).
    operand : {"v", "x"}, default "v"
        What ``a_{j+1}`` is multiplied by: the Horner variable ``v`` (``x``
        itself for plain powers, ``x*x`` rounded for a one-parity design),
        or ``x`` in the last step of an odd design (``y = x * q(x*x)``).

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> d = design_horner(fit_target("dichotomy", 2), 10, 10, coef_bits=14)
    >>> [(s.power, s.sum_bits, s.out_frac_bits) for s in d.stages]
    [(1, 22, 17), (0, 28, 27)]
    """

    power: int
    acc_bits: int
    product_bits: int
    product_shift: int
    coef_shifted: int
    sum_bits: int
    sum_frac_bits: int
    out_bits: int
    out_frac_bits: int
    round_shift: int
    operand: str = "v"


#: the evaluation schemes of a Horner design: Horner's rule in ``x``; in ``v = R(x*x)`` over
#: the even powers; ``x`` times Horner's rule in ``v = R(x*x)`` over the odd powers; in
#: ``v = (x - c')/s`` for a table in the shifted basis (``c'``: ``c`` to the datapath's bits)
SCHEMES = ("monomial", "even", "odd", "shifted")


@register("horner")
@dataclass(frozen=True)
class HornerDesign(Design):
    """A fully sized fixed-point polynomial evaluator (see module docstring).

    Attributes
    ----------
    name : str
        The design's name (the HDL module name is derived from it).
    table : CoefficientTable
        The (re-)quantized table the datapath evaluates.
    in_bits : int
        Width of the unsigned input code, 1 to :data:`MAX_IN_BITS`.
    out_bits : int
        Width of the unsigned output code, 1 to :data:`MAX_OUT_BITS`.
    rounding : {"rne", "trunc"}
        Rounding of every step (:data:`~chebnorm.hw.fixed.ROUNDINGS`).
    x_format : QFormat
        The input format: code ``k`` stands for ``(offset_code + k) / 2**Fx``
        (``lo + (hi - lo) k / 2**in_bits`` when the interval allows; module docstring).
    y_format : QFormat
        The output format.
    coef_frac_bits : int
        ``Fc``: fractional bits of the coefficients.
    integers : tuple of int
        The coefficients ``q_j`` (``c_j = q_j / 2**Fc``), lowest power first.
    acc_frac_bits : int
        ``Fa``: fractional bits of the intermediate accumulators.
    xs_bits : int
        Signed width of the input value ``xs = K0 + k`` fed to the multipliers.
    stages : tuple of Stage
        The Horner steps, highest power first (empty for degree 0).
    top_bits : int
        Signed width of the last step's rounded sum, before the offset and saturation.
    raw_bits : int
        Signed width of ``y_raw`` (after subtracting the output offset).
    valid_codes : tuple of (int, int)
        First and last input code whose value lies in the table's interval
        (every code, ``(0, 2**in_bits - 1)``, under the input-code mapping).
    notes : tuple of str, default ()
        Remarks on the sizing, for the report.
    scheme : {"monomial", "even", "odd", "shifted"}, default "monomial"
        :data:`SCHEMES`: Horner's rule in ``x``, or, when every nonzero
        coefficient is of one parity (degree >= 2), Horner's rule over those
        coefficients in the variable ``v = R(x*x)`` (times ``x`` once at
        the end when odd), or, for a table in the shifted basis
        ``t = (x - c)/s``, Horner's rule in ``v = (x - c')/s`` (``c'``:
        ``c`` to the datapath's fractional bits, ``c`` itself when short).
    v_frac_bits : int or None, default None
        Fractional bits of the Horner variable ``v`` (``x_format.frac_bits``
        for ``"monomial"``).
    v_bits : int, default 0
        Signed width of ``v`` (``xs_bits`` for ``"monomial"``).
    v_round_shift : int, default 0
        Bits dropped from the exact square ``xs * xs`` (``2 Fx`` fractional
        bits) to make ``v``; 0 when the square is kept exact.
    v_error : Fraction, default 0
        The exact ``max |v - x*x|`` (``|c - c'|/s`` when shifted) over the valid
        codes (0 for ``"monomial"``).
    v_shift : int, default 0
        Shifted scheme: ``v``'s integer is ``(xs << v_shift) - v_offset``.
    v_offset : int, default 0
        Shifted scheme: ``c' * 2**(Fx + v_shift)``.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> d = design_horner(fit_target("dichotomy", 2), 10, 10, coef_bits=14)
    >>> d.module_name, d.x_format.q_name(), d.valid_codes
    ('chebnorm_dichotomy_d2', 'UQ0.10', (1, 600))
    >>> bool(np.all(d.evaluate() <= d.y_format.max_code))
    True
    """

    name: str
    table: CoefficientTable
    in_bits: int
    out_bits: int
    rounding: str
    x_format: QFormat
    y_format: QFormat
    coef_frac_bits: int
    integers: tuple[int, ...]
    acc_frac_bits: int
    xs_bits: int
    stages: tuple[Stage, ...]
    top_bits: int
    raw_bits: int
    #: ``(lo, hi)``: the input codes whose values lie in the table's interval (the error budget holds on them)
    valid_codes: tuple[int, int]
    notes: tuple[str, ...] = field(default_factory=tuple)
    scheme: str = "monomial"
    v_frac_bits: int | None = None
    v_bits: int = 0
    v_round_shift: int = 0
    v_error: Fraction = Fraction(0)
    v_shift: int = 0
    v_offset: int = 0

    def _summary(self) -> list[tuple[str, object]]:
        return [("name", self.name), ("degree", self.degree), ("in_bits", self.in_bits),
                ("out_bits", self.out_bits), ("x_format", self.x_format.q_name()),
                ("y_format", self.y_format.q_name()), ("coef_frac_bits", self.coef_frac_bits),
                ("rounding", self.rounding)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    def __post_init__(self):
        self.verify()

    def verify(self) -> "HornerDesign":
        """Re-prove the design; return it unchanged, or raise ValueError: the
        table re-verified and the datapath sized again from it and the
        design's own formats (every field must be what :func:`design_horner`
        gives). Proved once per content (:func:`chebnorm.hw.trust.check`).

        Returns
        -------
        HornerDesign
            ``self``.

        Raises
        ------
        ValueError
            Naming the field that does not hold.
        """
        return check(self, _prove)

    @property
    def degree(self) -> int:
        return len(self.integers) - 1

    architecture = "horner"

    @property
    def module_name(self) -> str:
        return f"chebnorm_{self.name}"

    # -- the Design interface ----------------------------------------------------
    # chebnorm.hw.hdl and chebnorm.hw.budget import this module: their functions are
    # provided to it (chebnorm.hw.design_base.provide) instead of imported
    def budget(self) -> dict:
        """The certified budget (:func:`chebnorm.hw.budget.error_budget`) as a dict."""
        return provided("horner.error_budget")(self).as_dict()

    def measure(self) -> dict:
        """The errors over every valid code (:func:`chebnorm.hw.budget.measure`) as a dict."""
        return provided("horner.measure")(self).as_dict()

    def features(self):
        """The cost model's inputs (:func:`chebnorm.hw.target_model.horner_features`)."""
        from .target_model import horner_features

        return horner_features(self)

    def cut_points(self) -> tuple[str, ...]:
        """None: the registered Horner pipeline is the ``pipelined`` variant of the printers."""
        return ()

    def verilog(self, *, version: str = "", command: str | None = None) -> str:
        """The Verilog-2005 module (:func:`chebnorm.hw.hdl.module_text`)."""
        return provided("horner.module_text")(self, "verilog", version=version, command=command)

    def vhdl(self, *, version: str = "", command: str | None = None) -> str:
        """The VHDL-2008 entity (:func:`chebnorm.hw.hdl.module_text`)."""
        return provided("horner.module_text")(self, "vhdl", version=version, command=command)

    def hdl_files(self, language: str = "verilog") -> dict:
        """Module, bench and vectors (:func:`chebnorm.hw.hdl.hdl_files`)."""
        return provided("horner.hdl_files")(self, language)

    @property
    def parity(self) -> int | None:
        """1 for an odd design, 0 for an even one, None for plain Horner in ``x``."""
        return {"odd": 1, "even": 0}.get(self.scheme)

    @property
    def horner_integers(self) -> tuple[int, ...]:
        """The integers Horner's rule runs over, lowest first: ``integers``
        for ``"monomial"``; the even-power ones for ``"even"``; for ``"odd"``
        a 0 then the odd-power ones (the last step multiplies by ``x`` and
        adds nothing)."""
        if self.scheme == "even":
            return self.integers[0::2]
        if self.scheme == "odd":
            return (0,) + self.integers[1::2]
        return self.integers

    @property
    def steps(self) -> int:
        """Number of Horner steps (multiply-adds): the pipeline's latency."""
        return len(self.stages)

    @property
    def multipliers(self) -> int:
        """Number of multipliers of the datapath: one per step, plus the
        squarer ``x*x`` of a one-parity design."""
        return len(self.stages) + (self.scheme in ("even", "odd"))

    @property
    def variable_frac_bits(self) -> int:
        """Fractional bits of the Horner variable ``v``."""
        return self.x_format.frac_bits if self.v_frac_bits is None else self.v_frac_bits

    @property
    def variable_bits(self) -> int:
        """Signed width of the Horner variable ``v``."""
        return self.xs_bits if self.scheme == "monomial" else self.v_bits

    # -- bit-accurate model --------------------------------------------------
    def evaluate(self, codes=None, *, intermediates: bool = False):
        """Output codes of the circuit for input ``codes`` (default: all).

        Returns an int64 array; with ``intermediates`` a dict holding every
        wire as well (``xs``, ``a<j>``, ``raw``, ``y``, ``overflow``).
        """
        if codes is None:
            codes = np.arange(2 ** self.in_bits, dtype=np.int64)
        k = np.asarray(codes, dtype=np.int64)
        wires = _run(self, k)
        return wires if intermediates else wires["y"]

    def exact_numerators(self, codes) -> tuple[np.ndarray, int]:
        """``p_q(x_k)`` exactly as ``(N_k, D)``: value ``N_k / 2**D`` (object ints);
        for a shifted table ``p_q`` at the exact ``t = (x_k - c)/s``."""
        n = self.degree
        fx, fc = self.x_format.frac_bits, self.coef_frac_bits
        xs = np.asarray(codes, dtype=np.int64).astype(object) + self.x_format.offset_code
        if self.table.shift is not None:
            xs, fx = _exact_shifted(xs, fx, self.table.shift)
        acc = np.full(xs.shape, self.integers[n], dtype=object)
        for j in range(n - 1, -1, -1):
            acc = acc * xs + self.integers[j] * 2 ** ((n - j) * fx)
        return acc, fc + n * fx

    def max_abs_x(self) -> Fraction:
        lo, hi = self.valid_codes
        return max(abs(self.x_format.value(lo)), abs(self.x_format.value(hi)))


def _exact_shifted(xs, fx: int, shift):
    """``(T, F)``: the exact ``t = (x - c)/s`` as ``T / 2**F`` for ``x = xs / 2**fx``."""
    c, s = Fraction(shift[0]), Fraction(shift[1])
    e = s.numerator.bit_length() - s.denominator.bit_length()   # s = 2**e
    fc0 = c.denominator.bit_length() - 1
    g = max(fx, fc0)
    t = xs * 2 ** (g - fx) - int(c * 2 ** g)
    f = g + e
    if f < 0:
        return t * 2 ** -f, 0
    return t, f


def _variable(scheme: str, xs, round_shift: int, rounding: str, shift: int = 0, offset: int = 0):
    """The Horner variable's integers: ``xs`` itself, ``R(xs * xs)``, or
    ``(xs << shift) - offset``."""
    if scheme == "monomial":
        return xs
    if scheme == "shifted":
        return (xs << shift) - offset
    sq = xs * xs
    return shift_round(sq, round_shift, rounding) if round_shift else sq


def _run(d: HornerDesign, k: np.ndarray) -> dict:
    xs = k + d.x_format.offset_code
    v = _variable(d.scheme, xs, d.v_round_shift, d.rounding, d.v_shift, d.v_offset)
    wires = {"xs": xs, "v": v}
    ints = d.horner_integers
    n = len(ints) - 1
    if n == 0:
        top = np.full(k.shape, ints[0], dtype=np.int64)
        top_frac = d.coef_frac_bits
    else:
        acc = np.full(k.shape, ints[n], dtype=np.int64)
        for st in d.stages[:-1]:
            t = ((acc * (xs if st.operand == "x" else v)) << st.product_shift) + st.coef_shifted
            acc = shift_round(t, st.round_shift, d.rounding)
            wires[f"a{st.power}"] = acc
        last = d.stages[-1]
        top = ((acc * (xs if last.operand == "x" else v)) << last.product_shift) \
            + last.coef_shifted
        top_frac = last.sum_frac_bits
    wires["top"] = top
    shift = top_frac - d.y_format.frac_bits
    rounded = shift_round(top, shift, d.rounding) if shift >= 0 else top << -shift
    raw = rounded - d.y_format.offset_code
    wires["raw"] = raw
    wires["overflow"] = (raw < 0) | (raw > d.y_format.max_code)
    wires["y"] = np.clip(raw, 0, d.y_format.max_code)
    return wires


# -- construction ------------------------------------------------------------

#: :func:`chebnorm.approx.quantize` stores coefficients as int32 integers
COEF_WORD_BITS = 32


def _check_table(table) -> None:
    """Refuse anything but a :class:`CoefficientTable` in powers of ``x`` or of
    ``t = (x - c)/s`` with ``s`` a power of two (ValueError)."""
    if not isinstance(table, CoefficientTable):
        raise ValueError(f"table of type {type(table).__name__} is not accepted; accepted: a "
                         f"CoefficientTable (chebnorm.fit, or CoefficientTable.load)")
    if table.shift is not None:
        s = Fraction(table.shift[1])
        if s.numerator & (s.numerator - 1) or s.denominator & (s.denominator - 1):
            raise ValueError(f"table {table.name!r} is stored in t = ({table.variable} - "
                             f"{table.shift[0]!r})/{table.shift[1]!r}; the hardware Horner "
                             f"evaluator divides by a power of two only; accepted: a table "
                             f"fitted with basis='shifted' (s a power of two) or "
                             f"basis='monomial'")


def max_coef_bits(table: CoefficientTable) -> int:
    """Largest ``coef_bits`` for which every coefficient of ``table`` still fits
    the signed 32-bit integers of :func:`chebnorm.approx.quantize` (at most
    :data:`MAX_FRAC_BITS`; about 31 minus the binary exponent of the
    largest coefficient).

    >>> from chebnorm.approx import fit_target
    >>> max_coef_bits(fit_target("dichotomy", 2))   # largest |c_j| ~ 0.68
    31

    Parameters
    ----------
    table : CoefficientTable
        The table whose coefficients are to be quantized.

    Returns
    -------
    int
        The largest accepted ``coef_bits``, 0 to :data:`MAX_FRAC_BITS` (0: none fits).
    """
    _check_table(table)
    limit = 2 ** (COEF_WORD_BITS - 1) - 1
    best = 0
    for f in range(1, MAX_FRAC_BITS + 1):
        if all(abs(round(math.ldexp(float(c), f))) <= limit for c in table.coefficients):
            best = f
    return best


def check_coef_bits(table: CoefficientTable, coef_bits) -> int:
    """Boundary check of ``coef_bits`` against the table's int32 coefficient limit.

    Parameters
    ----------
    table : CoefficientTable
        The table the coefficients come from.
    coef_bits : int
        Fractional bits of the quantized coefficients; accepted: 1 to
        ``max_coef_bits(table)``.

    Returns
    -------
    int
        ``coef_bits``, checked.

    Raises
    ------
    ValueError
        If ``coef_bits`` is not an integer or out of range, or no width fits the table.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> t = fit_target("dichotomy", 2)
    >>> check_coef_bits(t, 14)
    14
    >>> check_coef_bits(t, 40)
    Traceback (most recent call last):
    ...
    ValueError: coef_bits = 40 is out of range; accepted: 1 <= coef_bits <= 31 (quantized coefficients are signed 32-bit integers and the largest of table 'dichotomy_d2' is 0.680756)
    """
    hi = max_coef_bits(table)
    if hi < 1:
        raise ValueError(f"table {table.name!r}: its largest coefficient does not fit a signed "
                         f"{COEF_WORD_BITS}-bit integer at any coef_bits; accepted: a table with "
                         f"coefficients under 2^{COEF_WORD_BITS - 2}")
    if isinstance(coef_bits, bool) or not isinstance(coef_bits, (int, np.integer)):
        return check_width(coef_bits, "coef_bits", 1, hi)  # raises: not an integer
    if not 1 <= int(coef_bits) <= hi:
        big = max(abs(float(c)) for c in table.coefficients)
        raise ValueError(f"coef_bits = {coef_bits} is out of range; accepted: 1 <= coef_bits "
                         f"<= {hi} (quantized coefficients are signed {COEF_WORD_BITS}-bit "
                         f"integers and the largest of table {table.name!r} is {big:.6g})")
    return int(coef_bits)


def _quantize_shifted(table: CoefficientTable, coef_bits: int) -> CoefficientTable:
    """A shifted table with a fixed-point part: each coefficient (of ``t``)
    rounded to nearest at ``coef_bits``, ``sup |p_q - f|`` certified
    (:func:`chebnorm.approx.quantize` takes plain powers of ``x`` only)."""
    import dataclasses

    from chebnorm.approx import FixedPoint, parse_function
    from chebnorm.approx.certify import certify

    ints = tuple(round(Fraction(c) * 2 ** coef_bits) for c in table.coefficients)
    fn = parse_function(table.expression, table.variable)
    lo, hi = (parse_number(v) for v in table.interval)
    cert = certify(fn, [math.ldexp(q, -coef_bits) for q in ints], lo, hi, "abs",
                   shift=table.shift)
    fp = FixedPoint(frac_bits=coef_bits, integers=ints, word_bits=COEF_WORD_BITS,
                    method="rounded", abs_error_bound=cert.bound, rel_error_bound=None,
                    max_abs_error=cert.maximum, max_rel_error=None)
    return dataclasses.replace(table, fixed_point=fp)


def _require_fixed_point(table: CoefficientTable, coef_bits):
    if coef_bits is not None and table.shift is not None:
        coef_bits = check_coef_bits(table, coef_bits)
        if table.fixed_point is None or table.fixed_point.frac_bits != coef_bits:
            table = _quantize_shifted(table, coef_bits)
        return table
    if coef_bits is not None:
        coef_bits = check_coef_bits(table, coef_bits)
        if table.fixed_point is None or table.fixed_point.frac_bits != coef_bits:
            table = quantize(table, coef_bits)
        return table
    if table.fixed_point is None and table.shift is not None:
        raise ValueError(f"table {table.name!r} (shifted basis) has no fixed-point part; "
                         f"accepted: coef_bits (1 <= coef_bits <= {max_coef_bits(table)}) to "
                         f"round its coefficients of t = (x - c)/s here")
    if table.fixed_point is None:
        raise ValueError(f"table {table.name!r} has no fixed-point part; accepted: a table "
                         f"quantized with coef_frac_bits (chebnorm.fit(..., coef_frac_bits=F) or "
                         f"chebnorm.quantize), or give coef_bits (1 <= coef_bits <= "
                         f"{max_coef_bits(table)}) to quantize it here")
    return table


def _interval_rationals(table: CoefficientTable):
    """The table's endpoints as exact Fractions, or None when one is irrational."""
    lo, hi = (parse_number(v) for v in table.interval)
    if not (lo.is_Rational and hi.is_Rational):
        return None
    return Fraction(int(lo.p), int(lo.q)), Fraction(int(hi.p), int(hi.q))


def code_frac_bits(table: CoefficientTable, in_bits: int) -> int | None:
    """The ``x_frac_bits`` of the input-code convention on the table's interval,
    or None when that convention is not a fixed-point format there.

    A ``W``-bit input code ``k`` stands for ``x_k = lo + (hi - lo) k / 2**W``
    on ``[lo, hi)`` (as ``chebnorm design`` and :mod:`chebnorm.hw.exhaustive`
    map it). That is the format ``x = (K0 + k) / 2**F`` exactly when
    ``hi - lo = 2**(W - F)`` and ``lo`` is a multiple of ``2**-F``: then
    ``F = W - log2(hi - lo)`` is returned (``|F| <=`` :data:`MAX_FRAC_BITS`),
    and every code ``0 .. 2**W - 1`` lies in the interval.

    Parameters
    ----------
    table : CoefficientTable
        The table whose interval the codes map onto.
    in_bits : int
        The width ``W`` of the input code, 1 to :data:`MAX_IN_BITS`.

    Returns
    -------
    int or None
        ``F``, or None when ``hi - lo`` is not a power of two, ``lo`` is not a
        multiple of ``2**-F``, an endpoint is irrational, or ``|F|`` exceeds
        :data:`MAX_FRAC_BITS`.

    Raises
    ------
    ValueError
        If ``in_bits`` is out of range.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> code_frac_bits(fit("exp(x)", ("0", "1"), 2), 12)       # x_k = k / 2^12
    12
    >>> code_frac_bits(fit("exp(x)", ("1", "3"), 2), 12)       # x_k = 1 + 2 k / 2^12
    11
    >>> code_frac_bits(fit("exp(x)", ("0", "3"), 2), 12) is None   # width 3: not a power of two
    True
    """
    in_bits = check_width(in_bits, "in_bits", 1, MAX_IN_BITS)
    ends = _interval_rationals(table)
    if ends is None:
        return None
    lo, hi = ends
    width = hi - lo
    if width <= 0 or width.numerator & (width.numerator - 1) or \
            width.denominator & (width.denominator - 1):
        return None
    e = width.numerator.bit_length() - width.denominator.bit_length()   # width = 2**e
    f = in_bits - e
    if abs(f) > MAX_FRAC_BITS or (lo * Fraction(2) ** f).denominator != 1:
        return None
    return f


def cover_frac_bits(table: CoefficientTable, in_bits: int) -> int:
    """The largest ``x_frac_bits`` whose ``2**in_bits`` codes cover the closed
    interval ``[lo, hi]`` with the offset ``floor(lo * 2**F)`` (the covering
    mapping: ``hi`` itself is a code, some codes may lie outside).

    Passed as ``x_frac_bits`` to :func:`design_horner` it gives the covering
    mapping, for an input that reaches ``hi`` (a dot product of unit vectors
    reaching 1, in the normalization units); see "Input codes" in
    docs/hardware.md.

    Parameters
    ----------
    table : CoefficientTable
        The table whose interval the codes must cover.
    in_bits : int
        The width of the input code, 1 to :data:`MAX_IN_BITS`.

    Returns
    -------
    int
        The fractional bits, ``-MAX_FRAC_BITS`` to :data:`MAX_FRAC_BITS`.

    Raises
    ------
    ValueError
        If ``in_bits`` is out of range, or no such format exists.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> cover_frac_bits(fit("exp(x)", ("0", "1"), 2), 12)   # codes 0..2048 of 4096 in [0, 1]
    11
    """
    in_bits = check_width(in_bits, "in_bits", 1, MAX_IN_BITS)
    lo, hi = (parse_number(v) for v in table.interval)
    width = float(sp.N(hi - lo, 20))
    f = min(MAX_FRAC_BITS, in_bits - math.floor(math.log2(width)) + 1)
    while f >= -MAX_FRAC_BITS:
        if _covers(lo, hi, in_bits, f)[1]:
            return f
        f -= 1
    raise ValueError(f"table {table.name!r}: no input format of {in_bits} bits covers "
                     f"[{table.interval[0]}, {table.interval[1]}]; accepted: more input bits")


def _covers(lo, hi, in_bits: int, f: int):
    """``(K0, ok)``: the covering offset ``floor(lo * 2**f)`` and whether codes
    ``0 .. 2**in_bits - 1`` from it reach ``hi``."""
    k0 = int(sp.floor(lo * sp.Integer(2) ** f))
    return k0, (sp.Integer(k0 + 2 ** in_bits - 1) / sp.Integer(2) ** f) >= hi


def _x_format(table: CoefficientTable, in_bits: int, x_frac_bits):
    """The input format and the valid codes (module docstring, "Input codes" in
    docs/hardware.md): the input-code mapping onto ``[lo, hi)`` when it is a
    fixed-point format (:func:`code_frac_bits`) and ``x_frac_bits`` is None or
    its ``F``; else the covering mapping (:func:`cover_frac_bits`, or the
    ``x_frac_bits`` given, refused when its codes do not reach ``hi``)."""
    lo, hi = (parse_number(v) for v in table.interval)
    span_codes = 2 ** in_bits - 1
    fc = code_frac_bits(table, in_bits)
    if x_frac_bits is not None:
        x_frac_bits = check_width(x_frac_bits, "x_frac_bits", -MAX_FRAC_BITS, MAX_FRAC_BITS)
    if fc is not None and x_frac_bits in (None, fc):
        k0 = int(_interval_rationals(table)[0] * Fraction(2) ** fc)
        return QFormat(bits=in_bits, frac_bits=fc, offset_code=k0, signed=False), (0, span_codes)
    if x_frac_bits is None:
        f = cover_frac_bits(table, in_bits)
        k0 = _covers(lo, hi, in_bits, f)[0]
    else:
        f = x_frac_bits
        k0, ok = _covers(lo, hi, in_bits, f)
        if not ok:
            best = cover_frac_bits(table, in_bits)
            cover_hi = float((k0 + span_codes) / sp.Integer(2) ** f)
            codes = "" if fc is None else (f"x_frac_bits = {fc} (the codes map onto "
                                           f"[{table.interval[0]}, {table.interval[1]})), ")
            raise ValueError(f"table {table.name!r}: interval [{table.interval[0]}, "
                             f"{table.interval[1]}] does not fit the input format of {in_bits} "
                             f"bits with {f} fractional bits (codes cover "
                             f"[{float(k0 / sp.Integer(2) ** f):.9g}, {cover_hi:.9g}]); accepted: "
                             f"{codes}x_frac_bits <= {best}, or more input bits")
    fmt = QFormat(bits=in_bits, frac_bits=f, offset_code=k0, signed=False)
    scale = sp.Integer(2) ** f
    k_lo = max(0, int(sp.ceiling(lo * scale)) - k0)
    k_hi = min(span_codes, int(sp.floor(hi * scale)) - k0)
    if k_lo > k_hi:
        raise ValueError(f"table {table.name!r}: no input code falls inside [{table.interval[0]}, "
                         f"{table.interval[1]}] with {in_bits} bits and {f} fractional bits; "
                         f"accepted: more input bits or fractional bits")
    return fmt, (k_lo, k_hi)


#: the words of :func:`_stages`' refusal of more datapath bits than the exact sum has
_PAST_EXACT = "exceed the exact sum's"


def _stages(integers, fc, fa, fx, xs_lo, xs_hi, k_all_xs, rounding, variable=None, odd=False):
    """Size the Horner steps exactly by running them over all codes
    (``variable``: ``(v, fv, v_bits)`` of the Horner variable when it is not
    ``x``; ``odd``: the last step multiplies by ``x``)."""
    n = len(integers) - 1
    stages = []
    acc = np.full(k_all_xs.shape, integers[n], dtype=np.int64)
    acc_frac = fc
    acc_bits = signed_bits(integers[n], integers[n])
    xs_bits = signed_bits(xs_lo, xs_hi)
    for j in range(n - 1, -1, -1):
        by_x = variable is None or (odd and j == 0)
        op, fop, op_bits = (k_all_xs, fx, xs_bits) if by_x else variable
        check_int64(acc_bits + op_bits, f"the product a_{j + 1} * {'x' if by_x else 'v'}")
        prod = acc * op
        prod_frac = acc_frac + fop
        s = max(prod_frac, fc)
        check_int64(signed_bits(int(prod.min()), int(prod.max())) + s - prod_frac + 1,
                    f"the sum of step {j}")
        pshift = s - prod_frac
        coef = integers[j] << (s - fc)
        t = (prod << pshift) + coef
        p_lo, p_hi = int(prod.min()) << pshift, int(prod.max()) << pshift
        sum_bits = signed_bits(min(p_lo, int(t.min()), coef), max(p_hi, int(t.max()), coef))
        if j > 0:
            rshift = s - fa
            if rshift < 0:
                raise ValueError(f"datapath frac bits {fa} exceed the exact sum's {s} fractional "
                                 f"bits at step {j}; accepted: acc_bits <= {s}")
            acc = shift_round(t, rshift, rounding)
            out_bits = signed_bits(int(acc.min()), int(acc.max()))
            out_frac = fa
        else:
            rshift, out_bits, out_frac = 0, sum_bits, s
            acc = t
        stages.append(Stage(power=j, acc_bits=acc_bits,
                            product_bits=signed_bits(int(prod.min()), int(prod.max())),
                            product_shift=pshift, coef_shifted=int(coef), sum_bits=sum_bits,
                            sum_frac_bits=s, out_bits=out_bits, out_frac_bits=out_frac,
                            round_shift=rshift,
                            operand="x" if by_x and variable is not None else "v"))
        acc_bits, acc_frac = out_bits, out_frac
    return tuple(stages), acc


def design_horner(table: CoefficientTable, in_bits: int, out_bits: int, *,
                  coef_bits: int | None = None, acc_bits: int | None = None,
                  rounding: str = "rne", x_frac_bits: int | None = None,
                  y_frac_bits: int | None = None, guard_bits: int = 3,
                  name: str | None = None, parity: bool = True) -> HornerDesign:
    """Size a fixed-point Horner evaluator of ``table`` (see module docstring).

    ``in_bits``/``out_bits``: widths of the unsigned codes ``x`` and ``y``;
    ``coef_bits``: fractional bits of the coefficients (re-quantizes the
    table with :func:`chebnorm.approx.quantize`; default: the table's own
    fixed-point part); ``acc_bits``: fractional bits of the intermediate
    accumulators (default ``y_frac_bits + guard_bits``); ``x_frac_bits``
    defaults to the input-code mapping ``x_k = lo + (hi - lo) k / 2**in_bits``
    when the interval allows it, else to the largest covering the interval
    ("Input codes" in docs/hardware.md); ``y_frac_bits`` to the largest the
    output range allows. Raises ValueError naming the problem and the
    accepted range.

    The bit-accurate model stays within the certified budget on every code:

    >>> import numpy as np
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.budget import error_budget
    >>> d = design_horner(fit_target("dichotomy", 2), 12, 12, coef_bits=16)
    >>> k = np.arange(d.valid_codes[0], d.valid_codes[1] + 1)
    >>> x, y = d.x_format.values(k), d.y_format.values(d.evaluate(k))
    >>> bool(np.max(np.abs(y - 1 / np.sqrt(2 + x))) <= error_budget(d).total)
    True

    Parameters
    ----------
    table : CoefficientTable
        A fitted table (with a fixed-point part unless ``coef_bits`` is given).
    in_bits : int
        Width of the unsigned input code ``x``, 1 to :data:`MAX_IN_BITS` (20).
    out_bits : int
        Width of the unsigned output code ``y``, 1 to :data:`MAX_OUT_BITS` (32).
    coef_bits : int or None, default None
        Fractional bits of the coefficients, 1 to ``max_coef_bits(table)``: re-quantizes
        the table; None keeps the table's own fixed-point part.
    acc_bits : int or None, default None
        Fractional bits of the intermediate accumulators, 1 to ``MAX_FRAC_BITS + 20``;
        None means ``y_frac_bits + guard_bits``.
    rounding : {"rne", "trunc"}, default "rne"
        Rounding of every step: to nearest, ties to even, or toward minus infinity.
    x_frac_bits : int or None, default None
        Fractional bits of the input, ``-MAX_FRAC_BITS`` to :data:`MAX_FRAC_BITS`.
        None: the input-code mapping ``x_k = lo + (hi - lo) k / 2**in_bits`` on
        ``[lo, hi)`` (every code valid) when ``hi - lo`` is a power of two and
        ``lo`` a multiple of the step (:func:`code_frac_bits`), else the largest
        whose codes cover ``[lo, hi]`` (:func:`cover_frac_bits`; codes outside
        the interval are invalid). Given: :func:`code_frac_bits` is that same
        input-code mapping, any other value the covering mapping with it
        (refused when its codes do not reach ``hi``). See "Input codes" in
        docs/hardware.md.
    y_frac_bits : int or None, default None
        Fractional bits of the output, ``-MAX_FRAC_BITS`` to ``MAX_FRAC_BITS + 20``;
        None takes the largest for which ``out_bits`` holds the output range.
    guard_bits : int, default 3
        Extra accumulator bits beyond the output's, 0 to 32 (used when ``acc_bits`` is None).
    name : str or None, default None
        The design's name; None uses the table's.
    parity : bool, default True
        When every nonzero coefficient is of one parity (degree >= 2; odd:
        at least two of them), evaluate ``q(v)`` or ``x * q(v)`` with
        ``v = R(x*x)`` (scheme ``"even"``/``"odd"``: half the Horner steps);
        False: plain Horner in ``x``.

    Returns
    -------
    HornerDesign
        The sized datapath.

    Raises
    ------
    ValueError
        If a width is out of its range, ``rounding`` is unknown, the table has no
        fixed-point part (and no ``coef_bits``), no input code falls in the interval,
        ``out_bits`` cannot hold the outputs, or a wire exceeds the 62-bit model.


    See Also
    --------
    chebnorm.hw.budget.error_budget : the certified error of the design.
    chebnorm.hw.budget.measure : its error over every valid input code.
    chebnorm.hw.report.analyze : design, budget, measure and synthesize at once.
    chebnorm.hw.hdl.module_text : its Verilog or VHDL.

    Notes
    -----
    The datapath (module docstring), for the input code :math:`k`, the
    value :math:`x = (K_0 + k)\\, 2^{-F_x}` and the quantized coefficients
    :math:`q_j 2^{-F_c}`:

    .. math::

        a_n = q_n 2^{-F_c}, \\qquad
        a_j = R_{F_a}\\!\\left(a_{j+1} x + q_j 2^{-F_c}\\right)\\ (j = n-1, \\dots, 1),
        \\qquad y = R_{F_y}\\!\\left(a_1 x + q_0 2^{-F_c}\\right),

    each multiply-add exact and :math:`R_F` one rounding to :math:`F`
    fractional bits; every wire is sized from its exact range over all
    :math:`2^{W}` codes, as FloPoCo sizes its polynomial evaluators [1]_ [2]_.
    Its certified error budget is :func:`~chebnorm.hw.budget.error_budget`.

    References
    ----------
    .. [1] F. de Dinechin, B. Pasca, "Designing custom arithmetic data paths
       with FloPoCo", IEEE Design & Test of Computers 28(4), 2011.
    .. [2] F. de Dinechin, M. Joldes, B. Pasca, "Automatic generation of
       polynomial-based hardware architectures for function evaluation",
       IEEE ASAP 2010.
    """
    _check_table(table)
    table.verify()   # a table changed behind its back is proved again (or refused)
    with drafting():
        d = _design_horner_or_plain(table, in_bits, out_bits, coef_bits=coef_bits,
                                    acc_bits=acc_bits, rounding=rounding,
                                    x_frac_bits=x_frac_bits, y_frac_bits=y_frac_bits,
                                    guard_bits=guard_bits, name=name, parity=parity)
    return seal(d)


def _prove(d: HornerDesign) -> None:
    """The table re-verified, the datapath sized again from it and the
    design's formats: every field must match (ValueError naming the first)."""
    identifier(d.name, field="name")
    _check_table(d.table)
    d.table.verify()
    xf, yf = d.x_format, d.y_format
    if not isinstance(xf, QFormat) or not isinstance(yf, QFormat):
        raise ValueError("x_format, y_format: accepted: QFormat")
    # the parity scheme as it was asked: one parity in v = x*x, or plain Horner because
    # it was asked (parity=False) or because the square did not fit (a note says so)
    parity = d.scheme in ("even", "odd") or any(_NO_PARITY in n for n in d.notes)
    with drafting():
        ref = _design_horner_or_plain(d.table, d.in_bits, d.out_bits, coef_bits=None,
                                      acc_bits=d.acc_frac_bits if d.degree >= 2 else None,
                                      rounding=d.rounding, x_frac_bits=xf.frac_bits,
                                      y_frac_bits=yf.frac_bits, guard_bits=3, name=d.name,
                                      parity=parity)
    for f in fields(d):
        mine, theirs = getattr(d, f.name), getattr(ref, f.name)
        if f.name != "table" and (type(mine) is not type(theirs) or mine != theirs):
            text = repr(mine)
            raise ValueError(f"{f.name}: stated {text[:60]}, but the table and the design's "
                             f"formats give {repr(theirs)[:60]}; accepted: the design "
                             f"design_horner sizes")


def _design_horner(table, in_bits, out_bits, *, coef_bits, acc_bits, rounding, x_frac_bits,
                   y_frac_bits, guard_bits, name, parity=True) -> HornerDesign:
    """:func:`design_horner`'s sizing (its drafts unchecked)."""
    _check_table(table)
    in_bits = check_width(in_bits, "in_bits", 1, MAX_IN_BITS)
    out_bits = check_width(out_bits, "out_bits", 1, MAX_OUT_BITS)
    if rounding not in ROUNDINGS:
        raise ValueError(f"rounding {rounding!r} is unknown; accepted: {', '.join(ROUNDINGS)}")
    if acc_bits is not None:
        acc_bits = check_width(acc_bits, "acc_bits", 1, MAX_FRAC_BITS + 20)
    if y_frac_bits is not None:
        y_frac_bits = check_width(y_frac_bits, "y_frac_bits", -MAX_FRAC_BITS, MAX_FRAC_BITS + 20)
    guard_bits = check_width(guard_bits, "guard_bits", 0, 32)
    name = name or table.name
    identifier(name, field="table name")
    table = _require_fixed_point(table, coef_bits)
    fp = table.fixed_point
    integers, fc = tuple(int(q) for q in fp.integers), fp.frac_bits
    x_fmt, valid = _x_format(table, in_bits, x_frac_bits)
    fx = x_fmt.frac_bits
    all_k = np.arange(2 ** in_bits, dtype=np.int64)
    xs_all = all_k + x_fmt.offset_code
    xs_lo, xs_hi = x_fmt.offset_code, x_fmt.offset_code + 2 ** in_bits - 1
    notes = []

    # exact range of p_q on the valid codes fixes the output format
    proto = HornerDesign(name=name, table=table, in_bits=in_bits, out_bits=out_bits,
                         rounding=rounding, x_format=x_fmt, y_format=QFormat(out_bits, 0),
                         coef_frac_bits=fc, integers=integers, acc_frac_bits=0, xs_bits=0,
                         stages=(), top_bits=0, raw_bits=0, valid_codes=valid)
    num, den = proto.exact_numerators(np.arange(valid[0], valid[1] + 1))
    v_lo, v_hi = Fraction(int(num.min()), 2 ** den), Fraction(int(num.max()), 2 ** den)
    span = v_hi - v_lo
    if y_frac_bits is None:
        fy = out_bits + (-math.floor(math.log2(span)) if span > 0 else MAX_FRAC_BITS)
        fy = min(fy, MAX_FRAC_BITS)
        candidates = range(fy, -MAX_FRAC_BITS - 1, -1)
    else:
        candidates = [y_frac_bits]
    scheme = "monomial"
    if parity is not True and parity is not False:
        raise ValueError(f"parity = {parity!r} is not accepted; accepted: True or False")
    if table.shift is not None:
        scheme = "shifted"
    elif parity and _integer_parity(integers) is not None and \
            (_integer_parity(integers) == 0 or len(integers[1::2]) >= 2):
        scheme = ("even", "odd")[_integer_parity(integers)]
        check_int64(2 * signed_bits(xs_lo, xs_hi), "the square x * x")
    horner = (integers[0::2] if scheme == "even" else (0,) + integers[1::2]
              if scheme == "odd" else integers)
    v_info = (None, 0, 0, Fraction(0))
    for fy in candidates:
        fa = acc_bits if acc_bits is not None else max(fy + guard_bits, 1)
        try:
            variable = None
            if scheme == "shifted":
                v_info = _shifted(xs_all, fx, fa, table.shift, xs_lo, xs_hi)
                variable = v_info[0]
            elif scheme != "monomial":
                v_info = _square(xs_all, fx, fa, rounding, valid)
                variable = v_info[0]
            if len(horner) > 1:
                stages, top = _stages(horner, fc, fa, fx, xs_lo, xs_hi, xs_all, rounding,
                                      variable=variable, odd=scheme == "odd")
        except ValueError as exc:
            # an output of (almost) no span -- a constant -- starts fy at the most
            # fractional bits, past the exact sum's (the message of _stages): try fewer
            if acc_bits is not None or fy == candidates[-1] or \
                    _PAST_EXACT not in str(exc):
                raise
            continue
        if len(horner) > 1:
            top_frac = stages[-1].sum_frac_bits
        else:
            stages, top, top_frac = (), np.full(all_k.shape, integers[0], dtype=np.int64), fc
        shift = top_frac - fy
        check_int64(signed_bits(int(top.min()), int(top.max())) + max(0, -shift), "the output")
        rounded = shift_round(top, shift, rounding) if shift >= 0 else top << -shift
        r_valid = rounded[valid[0]:valid[1] + 1]
        y_off = int(r_valid.min())
        if int(r_valid.max()) - y_off <= 2 ** out_bits - 1:
            break
        if y_frac_bits is not None:
            lo_v, hi_v = float(v_lo), float(v_hi)
            raise ValueError(f"out_bits {out_bits} with y_frac_bits {fy} cannot hold the outputs "
                             f"[{lo_v:.9g}, {hi_v:.9g}] of {name!r} (they need "
                             f"{unsigned_bits(int(r_valid.max()) - y_off)} bits); accepted: "
                             f"fewer y_frac_bits or more out_bits")
    raw = rounded - y_off
    y_fmt = QFormat(bits=out_bits, frac_bits=fy, offset_code=y_off, signed=False)
    raw_bits = signed_bits(min(int(raw.min()), 0), max(int(raw.max()), y_fmt.max_code))
    n_sat = int(((raw < 0) | (raw > y_fmt.max_code)).sum())
    n_valid = valid[1] - valid[0] + 1
    if n_valid < 2 ** in_bits:
        notes.append(f"{n_valid} of {2 ** in_bits} input codes lie in the table's interval "
                     f"(codes {valid[0]}..{valid[1]}); the budget holds there, the other codes "
                     f"are evaluated (and saturate where needed) but not guaranteed")
    if n_sat:
        notes.append(f"{n_sat} input codes outside the valid range saturate the output")
    return HornerDesign(name=name, table=table, in_bits=in_bits, out_bits=out_bits,
                        rounding=rounding, x_format=x_fmt, y_format=y_fmt, coef_frac_bits=fc,
                        integers=integers, acc_frac_bits=fa if len(horner) > 2 else fy,
                        xs_bits=signed_bits(xs_lo, xs_hi), stages=stages,
                        top_bits=signed_bits(int(top.min()), int(top.max())), raw_bits=raw_bits,
                        valid_codes=valid, notes=tuple(notes), scheme=scheme,
                        v_frac_bits=None if variable is None else variable[1],
                        v_bits=0 if variable is None else variable[2],
                        v_round_shift=v_info[1] if scheme != "shifted" else 0,
                        v_error=v_info[3],
                        v_shift=v_info[1] if scheme == "shifted" else 0,
                        v_offset=v_info[2] if scheme == "shifted" else 0)


#: the note of a design that evaluates Horner's rule in x although its table has one parity
_NO_PARITY = "Horner's rule in x, not over one parity in v = x*x"


def _design_horner_or_plain(table, in_bits, out_bits, *, coef_bits, acc_bits, rounding,
                            x_frac_bits, y_frac_bits, guard_bits, name, parity) -> HornerDesign:
    """:func:`_design_horner`, falling back to plain Horner in ``x`` (with a note)
    where the one-parity datapath would exceed the 62-bit model."""
    options = dict(coef_bits=coef_bits, acc_bits=acc_bits, rounding=rounding,
                   x_frac_bits=x_frac_bits, y_frac_bits=y_frac_bits, guard_bits=guard_bits,
                   name=name)
    try:
        return _design_horner(table, in_bits, out_bits, parity=parity, **options)
    except ValueError as exc:
        # the square's datapath is wider than Horner's rule in x (its products are by a
        # v of about twice x's bits): where it exceeds the 62-bit model, plain Horner
        if parity is not True or "bit-accurate model" not in str(exc):
            raise
        d = _design_horner(table, in_bits, out_bits, parity=False, **options)
        import dataclasses

        return dataclasses.replace(d, notes=d.notes + (
            f"{_NO_PARITY}: {exc}",))


def _integer_parity(integers) -> int | None:
    """1 (0) when every nonzero integer is of an odd (even) power and the
    degree is at least 2; else None (as the C and shader evaluators decide)."""
    powers = {k for k, q in enumerate(integers) if q}
    if len(integers) < 3 or not powers:
        return None
    for parity in (1, 0):
        if all(k % 2 == parity for k in powers):
            return parity
    return None


def _shifted(xs_all, fx: int, fa: int, shift, xs_lo: int, xs_hi: int):
    """The Horner variable ``v = (x - c')/s`` of a shifted table:
    ``((v, fv, v_bits), m, C, v_error)`` with ``v``'s integers
    ``(xs << m) - C``. ``c' = C / 2**G`` is ``c`` itself when it has at
    most ``max(Fx, Fa + 2 - e)`` fractional bits (``s = 2**e``), else ``c``
    rounded to them (``v`` then two bits finer than the accumulators), and
    ``v_error = |c - c'| / s`` exactly."""
    c, s = Fraction(shift[0]), Fraction(shift[1])
    e = s.numerator.bit_length() - s.denominator.bit_length()
    fc0 = c.denominator.bit_length() - 1
    g = max(fx, min(fc0, fa + 2 - e))
    m = g - fx
    offset = round(c * 2 ** g)
    check_int64(signed_bits(xs_lo, xs_hi) + m + 1, "the shifted input x - c")
    check_int64(signed_bits(min(xs_lo << m, offset), max(xs_hi << m, offset)) + 1,
                "the shifted input x - c")
    v = (xs_all << m) - offset
    return ((v, g + e, signed_bits(int(v.min()), int(v.max()))), m, offset,
            abs(c - Fraction(offset, 2 ** g)) / s)


def _square(xs_all, fx: int, fa: int, rounding: str, valid):
    """The Horner variable ``v = R(xs * xs)`` of a one-parity design:
    ``((v, fv, v_bits), round_shift, None, v_error)``. The square has
    ``2 Fx`` fractional bits; it keeps at most ``Fa + 2`` of them (two more
    than the accumulators), and ``v_error`` is the exact largest
    ``|v - x*x|`` over the valid codes."""
    sq = xs_all * xs_all
    fv = min(2 * fx, fa + 2)
    rs = 2 * fx - fv
    v = shift_round(sq, rs, rounding) if rs else sq
    lo, hi = valid
    err = np.abs((v[lo:hi + 1] << rs) - sq[lo:hi + 1]) if rs else np.zeros(1, dtype=np.int64)
    return ((v, fv, signed_bits(int(v.min()), int(v.max()))), rs, None,
            Fraction(int(err.max()), 2 ** (2 * fx)))
