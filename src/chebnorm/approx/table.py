"""The coefficient-table contract read by every consumer of chebnorm.

A :class:`CoefficientTable` is a polynomial ``p(x) = sum_k c_k x^k`` (ascending
powers of the original variable ``x``) approximating ``f(x)`` on ``[lo, hi]``,
with rigorous bounds of its absolute and relative error there, the located
maxima, an optional fixed-point version, and where it came from.

JSON schema (version 1): every field of the dataclasses below, floats written
with Python's shortest round-trip repr, keys sorted. The optional ``shift``
``[c, s]`` stores the polynomial in ``t = (x - c)/s`` instead (well
conditioned on narrow or offset intervals); tables without it read and write
exactly as before.

Tables are files people exchange, so reading one (:meth:`CoefficientTable.load`,
``from_json``, ``from_dict``) trusts nothing in it: every field is checked for
type and range, and every stated bound is re-certified for exactly the stored
coefficients (and fixed-point integers) against the stored expression and
interval (:meth:`CoefficientTable.verify`). A refusal is a ValueError that
names the field, e.g. ``coefficients[2]: expected a finite number, got 'abc'``
or ``abs_error_bound: stated 4.24e-03 but the coefficients' certified error is
4.79e-03``. At the registered degrees (1 to 3) verification takes milliseconds.
"""

from __future__ import annotations

import dataclasses
import math
from fractions import Fraction
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from chebnorm.core.display import summary_html, summary_repr
from chebnorm.core.numeric import format_down, format_up

from .basis_choice import BasisChoice, read_basis_choice
from .contract import Table
from .schema import MAX_TEXT  # noqa: F401  (the table's text limit, read from here)
from .schema import (ERROR_KINDS, FIXED_METHODS, KINDS, MAX_DEGREE, MAX_FRAC_BITS,
                     MAX_TABLE_BYTES, MAX_WORD_BITS, QUANT_FORMATS,
                     SCHEMA_VERSION, array, bad, boolean, check_object, choice, integer, number,
                     provenance, show, text)

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []


@dataclass(frozen=True)
class FixedPoint:
    """Coefficients rounded to ``frac_bits`` fractional bits.

    ``integers[k] / 2**frac_bits`` is the coefficient of ``x**k`` (exactly).
    ``word_bits`` is the signed integer width they are guaranteed to fit
    (two's complement). Bounds and maxima are those of the quantized
    polynomial, re-certified (evaluated exactly, without rounding inside
    Horner's rule). ``method`` is ``"rounded"`` (each coefficient rounded to
    nearest), ``"reoptimized"`` (coefficients rounded from the highest power
    down, the lower ones refitted after each rounding) or ``"lattice"``
    (lattice reduction and a closest vector, as Sollya's ``fpminimax``).

    Attributes
    ----------
    frac_bits : int
        Fractional bits ``F``.
    integers : tuple of int
        ``round(c_k 2**F)`` (re-optimized), ascending powers.
    word_bits : int
        The signed width every integer fits.
    method : str
        ``"rounded"``, ``"reoptimized"`` or ``"lattice"``.
    abs_error_bound : float
        Certified ``sup |p_q - f|`` of the quantized polynomial.
    rel_error_bound : float or None
        Certified ``sup |p_q/f - 1|`` (None when ``f`` vanishes).
    max_abs_error : float
        A located maximum of ``|p_q - f|``.
    max_rel_error : float or None
        A located maximum of ``|p_q/f - 1|``.
    """

    frac_bits: int
    integers: tuple[int, ...]
    word_bits: int
    method: str
    abs_error_bound: float
    rel_error_bound: float | None
    max_abs_error: float
    max_rel_error: float | None

    @property
    def coefficients(self) -> tuple[float, ...]:
        """The quantized coefficients as floats (exact)."""
        return tuple(math.ldexp(q, -self.frac_bits) for q in self.integers)

    def _summary(self) -> list[tuple[str, object]]:
        return [("frac_bits", self.frac_bits), ("integers", self.integers),
                ("word_bits", self.word_bits), ("method", self.method),
                ("abs_error_bound", self.abs_error_bound)]

    __repr__ = summary_repr
    _repr_html_ = summary_html


@dataclass(frozen=True)
class Quantized:
    """Coefficients stored in a fixed or floating format (``chebnorm.approx.quantize``).

    The coefficient of ``x**k`` is ``mantissas[k] * 2**exponents[k]`` exactly
    (zero for the powers not in ``monomials``). ``format`` is ``"fixed"``
    (then ``frac_bits[k]`` fractional bits per power, ``exponents[k] ==
    -frac_bits[k]``, and each mantissa fits a ``word_bits``-bit two's
    complement integer) or a floating format (``binary16``, ``bfloat16``,
    ``binary32``, ``binary64``: each coefficient a finite number of it).
    ``fixed_constant``: the constant coefficient is ``f(0)`` rounded to its
    format, not chosen by the fit. Bounds are re-certified for exactly these
    numbers. ``method`` names the candidate that won: ``"lattice"`` (LLL and
    nearest plane), ``"rounded"`` or ``"reoptimized"`` (greedy refit).

    Parameters
    ----------
    format : str
        ``"fixed"`` or one of ``"binary16"``, ``"bfloat16"``, ``"binary32"``,
        ``"binary64"``.
    monomials : tuple of int
        The powers of ``x`` whose coefficients are stored (the others are 0).
    mantissas : tuple of int
        The integer mantissa of each power ``0..degree``.
    exponents : tuple of int
        The power-of-two exponent of each power (``-frac_bits[k]`` in fixed
        point).
    frac_bits : tuple of int or None
        Fixed point: the fractional bits of each power; None for a floating
        format.
    word_bits : int or None
        Fixed point: the width of the two's complement words; None for a
        floating format.
    fixed_constant : bool
        Whether the constant coefficient is ``f(0)`` rounded, not fitted.
    method : str
        The candidate that won: ``"lattice"``, ``"rounded"`` or
        ``"reoptimized"``.
    abs_error_bound : float
        A rigorous bound of ``sup |p - f|`` for exactly these coefficients.
    rel_error_bound : float or None
        A rigorous bound of ``sup |p/f - 1|``; None where ``f`` vanishes on the
        interval.
    max_abs_error : float
        The largest ``|p - f|`` located (a lower bound of the supremum).
    max_rel_error : float or None
        The largest ``|p/f - 1|`` located; None with ``rel_error_bound``.
    """

    format: str
    monomials: tuple[int, ...]
    mantissas: tuple[int, ...]
    exponents: tuple[int, ...]
    frac_bits: tuple[int, ...] | None
    word_bits: int | None
    fixed_constant: bool
    method: str
    abs_error_bound: float
    rel_error_bound: float | None
    max_abs_error: float
    max_rel_error: float | None

    @property
    def coefficients(self) -> tuple[float, ...]:
        """The stored coefficients as floats (exact)."""
        return tuple(math.ldexp(m, e) for m, e in zip(self.mantissas, self.exponents))

    def _summary(self) -> list[tuple[str, object]]:
        return [("format", self.format), ("monomials", self.monomials),
                ("coefficients", self.coefficients), ("method", self.method),
                ("abs_error_bound", self.abs_error_bound)]

    __repr__ = summary_repr
    _repr_html_ = summary_html


@dataclass(frozen=True)
class CoefficientTable(Table):
    """A fitted polynomial with certified error bounds (see module docstring).

    ``interval`` holds the exact endpoints as sympy strings; ``interval_float``
    the nearest floats. ``abs_error_bound >= sup|p - f|`` and
    ``rel_error_bound >= sup|p/f - 1|`` are rigorous; ``max_abs_error`` is
    ``|p - f|`` at ``max_abs_at``, a located maximum (so a lower bound of the
    supremum). ``rel_*`` fields are None when ``f`` vanishes on the interval.

    Attributes
    ----------
    name : str
        An identifier (C, Verilog, VHDL, shaders): the generated names' prefix.
    expression : str
        The fitted function ``f``, sympy text.
    variable : str
        Its variable's name.
    interval : tuple of (str, str)
        The exact endpoints ``[lo, hi]``, sympy text.
    interval_float : tuple of (float, float)
        The nearest float64 endpoints.
    degree : int
        The polynomial's degree.
    kind : str
        How it was fitted: ``"chebyshev"`` (interpolation) or ``"minimax"`` (Remez).
    error_kind : str
        ``"abs"`` or ``"rel"``: the error the fit minimizes.
    coefficients : tuple of float
        Ascending powers of ``variable`` (of ``(x - c)/s`` when ``shift`` is set).
    abs_error_bound : float
        Certified ``sup |p - f|`` on the interval (rounded up).
    rel_error_bound : float or None
        Certified ``sup |p/f - 1|``; None when ``f`` vanishes on the interval.
    max_abs_error : float
        ``|p - f|`` at ``max_abs_at``: a located maximum, a lower bound of the supremum.
    max_abs_at : float
        Where it is attained.
    max_rel_error : float or None
        ``|p/f - 1|`` at ``max_rel_at`` (None with ``rel_error_bound``).
    max_rel_at : float or None
        Where it is attained.
    fixed_point : FixedPoint or None
        The coefficients in fixed point, re-certified (:func:`~chebnorm.approx.quantize`).
    provenance : dict of str to str
        The command and versions that made the table.
    schema_version : int
        The JSON contract's version.
    shift : tuple of (float, float) or None
        ``(c, s)`` of the shifted basis, or None for monomials in ``x``.
    quantized : Quantized or None
        Coefficients in a chosen format (fixed point per power or floating), re-certified.
    basis_choice : BasisChoice or None
        How ``fit(..., basis="auto")`` chose the basis, and why
        (:mod:`chebnorm.approx.basis_choice`); None for an explicit basis.

    Examples
    --------
    >>> t = CoefficientTable(name="sq", expression="x**2", variable="x",
    ...     interval=("0", "1"), interval_float=(0.0, 1.0), degree=2,
    ...     kind="chebyshev", error_kind="abs", coefficients=(0.0, 0.0, 1.0),
    ...     abs_error_bound=0.0, rel_error_bound=None, max_abs_error=0.0,
    ...     max_abs_at=0.0, max_rel_error=None, max_rel_at=None)
    >>> CoefficientTable.from_json(t.to_json()) == t
    True
    >>> float(t(0.5))
    0.25
    """

    name: str
    expression: str
    variable: str
    interval: tuple[str, str]
    interval_float: tuple[float, float]
    degree: int
    kind: str
    error_kind: str
    coefficients: tuple[float, ...]
    abs_error_bound: float
    rel_error_bound: float | None
    max_abs_error: float
    max_abs_at: float
    max_rel_error: float | None
    max_rel_at: float | None
    fixed_point: FixedPoint | None = None
    provenance: dict[str, str] = field(default_factory=dict)
    schema_version: int = SCHEMA_VERSION
    #: ``(c, s)``: the coefficients are in ``t = (x - c)/s`` (basis "shifted");
    #: None (the default, absent from the JSON): plain monomials in ``x``
    shift: tuple[float, float] | None = None
    quantized: Quantized | None = None
    #: how ``basis="auto"`` chose the basis (None, absent from the JSON: an explicit basis)
    basis_choice: BasisChoice | None = None

    WHAT = "coefficient table"
    MAX_BYTES = MAX_TABLE_BYTES
    TOO_LARGE_HINT = "; accepted: a table written by chebnorm (a few kB)"
    JSON_INDENT = 2

    def _summary(self) -> list[tuple[str, object]]:
        out = [("name", self.name), ("expression", self.expression),
               ("interval", self.interval), ("degree", self.degree), ("kind", self.kind),
               ("abs_error_bound", self.abs_error_bound)]
        if self.quantized is not None:
            out.append(("quantized_error_bound", self.quantized.abs_error_bound))
        return out

    __repr__ = summary_repr

    @property
    def basis(self) -> str:
        """``"monomial"`` (powers of ``x``) or ``"shifted"`` (powers of ``(x - c)/s``)."""
        return "monomial" if self.shift is None else "shifted"

    def require_monomial(self, consumer: str) -> None:
        """Raise a ValueError naming ``consumer`` when the table is not in
        plain monomials of ``x`` (what that consumer evaluates).

        >>> from chebnorm.approx import fit
        >>> fit("exp(x)", ("0", "1"), 2, basis="shifted").require_monomial("hw")
        Traceback (most recent call last):
        ...
        ValueError: table 'exp_0_1_d2' is stored in the shifted variable t = (x - 0.5)/0.5; hw: plain powers of x only; accepted: a table fitted with basis='monomial'
        """
        if self.shift is not None:
            c, s = self.shift
            raise ValueError(f"table {self.name!r} is stored in the shifted variable "
                             f"t = ({self.variable} - {c!r})/{s!r}; {consumer}: plain "
                             f"powers of {self.variable} only; accepted: a table fitted with "
                             f"basis='monomial'")

    # -- evaluation -------------------------------------------------------
    def __call__(self, x, dtype=np.float64):
        """Horner evaluation of the float coefficients in ``dtype`` (in the
        shifted variable ``(x - c) * (1/s)`` for a shifted table)."""
        x = np.asarray(x, dtype=dtype)
        if self.shift is not None:
            x = (x - dtype(self.shift[0])) * dtype(1 / self.shift[1])
        acc = np.full_like(x, self.coefficients[-1])
        for c in reversed(self.coefficients[:-1]):
            acc = acc * x + dtype(c)
        return acc

    def covers(self, lo: float, hi: float) -> bool:
        """True when ``[lo, hi]`` lies inside the table's interval."""
        return self.interval_float[0] <= lo and hi <= self.interval_float[1]

    # -- the quantized part's bound ------------------------------------------
    @property
    def quantized_error_bound(self) -> float | None:
        """The certified bound of ``sup |p_q - f|`` for the quantized coefficients
        (``quantized.abs_error_bound``), or None for a table that is not quantized.

        ``abs_error_bound`` stays the bound of the float ``coefficients`` (the
        JSON field, verified against them, and printed by the exporters next
        to the quantized one), so a quantized table names its own bound here
        and in :attr:`error_bound`.

        Examples
        --------
        >>> from chebnorm.approx import fit, quantize
        >>> q = quantize(fit("1/sqrt(2+z)", ("sqrt(2)", 2), 2, var="z"), 14)
        >>> q.quantized_error_bound == q.quantized.abs_error_bound > q.abs_error_bound
        True
        """
        return None if self.quantized is None else self.quantized.abs_error_bound

    @property
    def error_bound(self) -> float:
        """The certified bound of ``sup |p - f|`` for the coefficients the table
        delivers: the quantized ones' (:attr:`quantized_error_bound`) when the
        table is quantized, else the float ones' (``abs_error_bound``).

        Examples
        --------
        >>> from chebnorm.approx import fit, quantize
        >>> t = fit("exp(x)", ("0", "1"), 3)
        >>> t.error_bound == t.abs_error_bound
        True
        >>> q = quantize(t, 12)
        >>> q.error_bound == q.quantized.abs_error_bound
        True
        """
        q = self.quantized_error_bound
        return self.abs_error_bound if q is None else q

    # -- conversions (numpy, sympy) ---------------------------------------------
    def _coefficients_of(self, quantized: bool) -> tuple[float, ...]:
        if not quantized:
            return self.coefficients
        if self.quantized is None:
            raise ValueError(f"quantized=True: table {self.name!r} has no quantized part; "
                             f"accepted: quantized=False, or a table from chebnorm.quantize")
        return self.quantized.coefficients

    def to_polynomial(self, quantized: bool = False):
        """The polynomial as a :class:`numpy.polynomial.Polynomial` of ``x``.

        Parameters
        ----------
        quantized : bool, optional
            Use the quantized coefficients (``quantized.coefficients``)
            instead of the float ones (default).

        Returns
        -------
        numpy.polynomial.Polynomial
            The coefficients in ascending powers; for a shifted table (powers
            of ``t = (x - c)/s``) ``domain = [c - s, c + s]`` and ``window =
            [-1, 1]``, so that calling it with ``x`` maps ``x`` to ``t`` as
            the table does. ``symbol`` is the table's variable.

        Raises
        ------
        ValueError
            ``quantized=True`` on a table without a quantized part.

        Examples
        --------
        >>> from chebnorm.approx import fit
        >>> t = fit("exp(x)", ("0", "1"), 3)
        >>> p = t.to_polynomial()
        >>> bool(p(0.3) == t(0.3)), p.degree()
        (True, 3)
        >>> t = fit("sin(x)", ("100", "101"), 8, basis="shifted")
        >>> s = t.to_polynomial()
        >>> s.domain.tolist(), s.window.tolist(), bool(s(100.25) == t(100.25))
        ([100.0, 101.0], [-1.0, 1.0], True)
        """
        from numpy.polynomial import Polynomial

        coeffs = np.array(self._coefficients_of(quantized), dtype=np.float64)
        if self.shift is None:
            return Polynomial(coeffs, symbol=self.variable)
        c, s = self.shift
        return Polynomial(coeffs, domain=[c - s, c + s], window=[-1.0, 1.0],
                          symbol=self.variable)

    def to_chebyshev(self, quantized: bool = False):
        """The polynomial as a :class:`numpy.polynomial.Chebyshev` series on the interval.

        The change of basis is exact (rational arithmetic): each Chebyshev
        coefficient is the exact one rounded once to float64.

        Parameters
        ----------
        quantized : bool, optional
            Use the quantized coefficients instead of the float ones (default).

        Returns
        -------
        numpy.polynomial.Chebyshev
            ``domain = interval_float`` (``window = [-1, 1]``): calling it with
            ``x`` in the interval gives ``p(x)``.

        Raises
        ------
        ValueError
            ``quantized=True`` on a table without a quantized part.

        Examples
        --------
        >>> from chebnorm.approx import fit
        >>> t = fit("exp(x)", ("0", "1"), 3)
        >>> ch = t.to_chebyshev()
        >>> ch.domain.tolist(), bool(abs(ch(0.7) - t(0.7)) < 1e-15)
        ([0.0, 1.0], True)
        """
        from numpy.polynomial import Chebyshev

        lo, hi = self.interval_float
        series = _power_to_chebyshev(self._rational_power(quantized, Fraction(lo), Fraction(hi)))
        return Chebyshev([float(a) for a in series], domain=[lo, hi], symbol=self.variable)

    def _rational_power(self, quantized: bool, lo: Fraction, hi: Fraction) -> list[Fraction]:
        """Exact coefficients of ``p(m + h*u)`` in powers of ``u`` (``[lo, hi]`` -> ``[-1, 1]``)."""
        from flint import fmpq, fmpq_poly

        coeffs = [Fraction(c) for c in self._coefficients_of(quantized)]
        m, h = (lo + hi) / 2, (hi - lo) / 2
        x_of_u = fmpq_poly([fmpq(m.numerator, m.denominator), fmpq(h.numerator, h.denominator)])
        if self.shift is not None:  # t = (x - c)/s
            c, s = (Fraction(v) for v in self.shift)
            x_of_u = (x_of_u - fmpq(c.numerator, c.denominator)) / fmpq(s.numerator,
                                                                        s.denominator)
        poly = fmpq_poly([fmpq(c.numerator, c.denominator) for c in coeffs])(x_of_u)
        out = [Fraction(int(q.p), int(q.q)) for q in poly.coeffs()]
        return out + [Fraction(0)] * (len(coeffs) - len(out))

    def to_sympy(self, quantized: bool = False):
        """The polynomial as a sympy expression in the table's variable, exactly.

        Every coefficient is a double (or, quantized, ``m * 2**e``): it becomes
        the sympy Rational of exactly that value. A shifted table gives the
        sum of ``c_k * ((x - c)/s)**k`` (unexpanded; ``sympy.expand`` it for
        powers of ``x``, exactly).

        Parameters
        ----------
        quantized : bool, optional
            Use the quantized coefficients instead of the float ones (default).

        Returns
        -------
        sympy.Expr

        Raises
        ------
        ValueError
            ``quantized=True`` on a table without a quantized part.

        Examples
        --------
        >>> from chebnorm.approx import fit, quantize
        >>> q = quantize(fit("1/sqrt(2+z)", ("sqrt(2)", 2), 2, var="z"), 14)
        >>> q.to_sympy(quantized=True)
        29*z**2/2048 - 243*z/2048 + 697/1024
        """
        import sympy as sp

        x = sp.Symbol(self.variable)
        if self.shift is not None:
            c, s = (sp.Rational(*float(v).as_integer_ratio()) for v in self.shift)
            x = (x - c) / s
        return sp.Add(*(sp.Rational(*float(a).as_integer_ratio()) * x ** k
                        for k, a in enumerate(self._coefficients_of(quantized))))

    def __array__(self, dtype=None, copy=None):
        """``np.asarray(table)``: the float ``coefficients`` (ascending powers, in
        the table's basis: of ``x``, or of ``t = (x - c)/s`` for a shifted table)
        as a float64 array; :meth:`to_polynomial` and :meth:`to_chebyshev`
        give the polynomial itself.

        >>> from chebnorm.approx import fit
        >>> np.asarray(fit("exp(x)", ("0", "1"), 2)).shape
        (3,)
        """
        if copy is False:
            raise ValueError("a table's coefficients are copied into a new array; accepted: "
                             "copy=None or copy=True")
        return np.array(self.coefficients, dtype=np.float64 if dtype is None else dtype)

    # -- JSON ---------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["interval"] = list(self.interval)
        d["interval_float"] = list(self.interval_float)
        d["coefficients"] = list(self.coefficients)
        if self.shift is None:
            del d["shift"]  # plain monomials: the JSON of schema 1 as it always was
        else:
            d["shift"] = list(self.shift)
        if self.basis_choice is None:
            del d["basis_choice"]  # an explicit basis: the JSON as it always was
        if self.fixed_point is not None:
            d["fixed_point"]["integers"] = list(self.fixed_point.integers)
        if self.quantized is not None:
            for key in ("monomials", "mantissas", "exponents", "frac_bits"):
                if d["quantized"][key] is not None:
                    d["quantized"][key] = list(d["quantized"][key])
        else:
            del d["quantized"]
        return d

    @classmethod
    def _file_fields(cls, d) -> dict[str, Any]:
        """Each field is checked for type and range (a refusal names the field:
        ``coefficients[2]: expected a finite number, got 'abc'``)."""
        return _read_fields(cls, d)

    def _prove_claims(self) -> None:
        _verify(self)

    def verify(self) -> "CoefficientTable":
        """Re-prove every claim of the table; return it unchanged, or raise.

        Checks every field as :meth:`from_dict` does, then re-certifies the
        float coefficients (and the fixed-point integers) against
        ``expression`` on ``interval`` (:func:`chebnorm.approx.certify`):
        each stated bound must be at least a certified upper bound of the
        true supremum, re-certified more tightly when the first pass is
        looser than the statement (so a bound stated from a looser
        certification passes, a bound below the supremum never does); the
        located maxima must not exceed their bounds and must lie in the
        interval; ``interval_float`` must be the exact endpoints rounded to
        doubles (within one ulp). Raises :class:`ValueError` naming the field.

        >>> from chebnorm.approx import fit
        >>> t = fit("x**3", ("0", "1"), 2)
        >>> t.verify() == t
        True
        >>> from dataclasses import replace
        >>> replace(t, abs_error_bound=t.abs_error_bound / 2).verify()
        Traceback (most recent call last):
        ...
        ValueError: abs_error_bound: stated 1.56e-02 but the coefficients' certified error is 3.12e-02; |p - f| reaches 3.12e-02 at x = 0.0

        Every table is verified when it is constructed (a file, a hand-built
        table, ``dataclasses.replace``); this call costs a comparison when
        nothing changed since, and re-proves the table otherwise (fields set
        behind the frozen dataclass's back, an unpickled object).
        """
        return super().verify()

    # -- display (Jupyter) ----------------------------------------------------
    def _display_rows(self) -> list[tuple[str, str]]:
        """(label, plain text) pairs shown by the HTML and Markdown reprs."""
        lo, hi = self.interval
        rows = [
            ("function", f"{self.expression} of {self.variable}"),
            ("interval", f"[{lo}, {hi}] = [{self.interval_float[0]!r}, {self.interval_float[1]!r}]"),
            ("degree, kind", f"{self.degree}, {self.kind} ({self.error_kind} error)"),
            ("coefficients", ", ".join(repr(c) for c in self.coefficients)
             + f" (ascending powers of {self.variable})"),
            ("max |p - f|", f"{format_down(self.max_abs_error, '.6e')} at {self.variable} = "
                            f"{self.max_abs_at!r}; "
                            f"certified bound {format_up(self.abs_error_bound, '.6e')}"),
        ]
        if self.max_rel_error is not None and self.rel_error_bound is not None:
            rows.append(("max |p/f - 1|", f"{format_down(self.max_rel_error, '.6e')} at "
                                          f"{self.variable} = "
                                          f"{self.max_rel_at!r}; certified bound "
                                          f"{format_up(self.rel_error_bound, '.6e')}"))
        fp = self.fixed_point
        if fp is not None:
            rows.append(("fixed point", f"{fp.frac_bits} fractional bits, int{fp.word_bits}, "
                                        f"{fp.method}: " + ", ".join(str(q) for q in fp.integers)))
            rows.append(("fixed max |p - f|", f"{format_down(fp.max_abs_error, '.6e')}; certified "
                                              f"bound "
                                              f"{format_up(fp.abs_error_bound, '.6e')}"))
            if fp.max_rel_error is not None and fp.rel_error_bound is not None:
                rows.append(("fixed max |p/f - 1|", f"{format_down(fp.max_rel_error, '.6e')}; "
                                                    f"certified bound "
                                                    f"{format_up(fp.rel_error_bound, '.6e')}"))
        q = self.quantized
        if q is not None and fp is None:
            rows.append(("quantized", f"{q.format} ({q.method}), powers "
                                      f"{','.join(map(str, q.monomials))}: "
                                      + ", ".join(repr(c) for c in q.coefficients)))
            rows.append(("quantized max |p - f|", f"{format_down(q.max_abs_error, '.6e')}; "
                                                  f"certified bound "
                                                  f"{format_up(q.abs_error_bound, '.6e')}"))
        if self.provenance:
            rows.append(("provenance", "; ".join(f"{k}: {v}" for k, v in sorted(self.provenance.items()))))
        return rows

    def error_curve(self, points: int = 801, error: str = "abs", fixed: bool = False,
                    quantized: bool = False, binary32: bool = False):
        """``(x, g)``: the error ``g = p - f`` (``error="abs"``) or
        ``p/f - 1`` (``"rel"``) at ``points`` equally spaced floats of the
        interval, evaluated in mpmath at 40 significant digits (the float
        coefficients exactly, so even an error near zero keeps its digits).
        ``fixed=True`` uses the fixed-point coefficients, ``quantized=True`` the
        quantized ones in any format. ``binary32=True`` measures a binary32
        Horner evaluation instead (the coefficients, quantized ones if any,
        rounded to binary32, ``x`` rounded to binary32 and every step in
        binary32 without fma): a measurement at these points, not a bound (the
        exported evaluators state their bounds).

        >>> from chebnorm.approx import fit
        >>> t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 2, var="z")
        >>> x, g = t.error_curve(201)
        >>> bool(abs(g).max() <= t.abs_error_bound)
        True
        """
        import mpmath

        from .expr import parse_function

        if error not in ("abs", "rel"):
            raise ValueError(f"error must be 'abs' or 'rel'; got {error!r}")
        if not isinstance(points, int) or points < 2:
            raise ValueError(f"points must be an integer >= 2; got {points!r}")
        if fixed and self.fixed_point is None:
            raise ValueError(f"table {self.name!r} has no fixed-point part")
        if quantized and self.quantized is None:
            raise ValueError(f"table {self.name!r} has no quantized part")
        coeffs = (self.fixed_point.coefficients if fixed else
                  self.quantized.coefficients if quantized else self.coefficients)
        fn = parse_function(self.expression, self.variable)
        f_mp = fn.mpmath
        x = np.linspace(self.interval_float[0], self.interval_float[1], points)
        if binary32:
            if self.quantized is not None:
                coeffs = self.quantized.coefficients
            x = x.astype(np.float32).astype(np.float64)
            x = x[(x >= self.interval_float[0]) & (x <= self.interval_float[1])]
            c32 = np.array(coeffs, dtype=np.float64).astype(np.float32)
            x32 = x.astype(np.float32)
            if self.shift is not None:
                t32 = (x32 - np.float32(self.shift[0])) / np.float32(self.shift[1])
            else:
                t32 = x32
            acc = np.full_like(x32, c32[-1])
            for c in c32[-2::-1]:
                acc = (acc * t32).astype(np.float32) + c
            values = acc.astype(np.float64)
        g = np.empty(len(x))
        with mpmath.workdps(40):
            for i, xi in enumerate(x):
                xm = mpmath.mpf(float(xi))
                if binary32:
                    p = mpmath.mpf(float(values[i]))
                else:
                    p = mpmath.mpf(0)
                    tm = _local_mp(self, xm)   # the shifted variable of a shifted table
                    for c in reversed(coeffs):
                        p = p * tm + mpmath.mpf(c)
                f = f_mp(xm)
                g[i] = float(p - f) if error == "abs" else float(p / f - 1)
        return x, g

    def plot(self, ax=None, error: str = "abs", points: int = 801, binary32: bool = True):
        """Plot the error curve ``p - f`` (``error="rel"``: ``p/f - 1``) over
        the interval with the certified bound ``+-bound`` and the located
        maximum, and every evaluator the table has: its quantized part (fixed
        point or a float format) with its own certified bound, and (``binary32``)
        the error measured of a binary32 Horner evaluation. Bounds are printed
        rounded up. A new figure is laid out so that every label fits. Returns
        the matplotlib Axes.

        >>> import matplotlib
        >>> matplotlib.use("Agg")
        >>> from chebnorm.approx import fit
        >>> ax = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 1, var="z").plot()
        >>> type(ax).__name__
        'Axes'
        """

        if error == "rel" and self.rel_error_bound is None:
            raise ValueError(f"table {self.name!r} has no relative error (f vanishes on the interval)")
        if ax is None:
            import matplotlib.pyplot as plt

            _, ax = plt.subplots(figsize=(6.4, 3.8), layout="constrained")
        x, g = self.error_curve(points, error)
        bound = self.abs_error_bound if error == "abs" else self.rel_error_bound
        label = "p - f" if error == "abs" else "p/f - 1"
        ax.plot(x, g, color="C0", lw=1.2, label=f"{label} (degree {self.degree}, {self.kind})")
        ax.axhline(bound, color="C0", ls="--", lw=0.8,
                   label=f"certified bound {format_up(bound, '.3e')}")
        ax.axhline(-bound, color="C0", ls="--", lw=0.8)
        at = self.max_abs_at if error == "abs" else self.max_rel_at
        if at is not None:
            _, g_at = _point_error(self, at, error)
            ax.plot([at], [g_at], "o", color="C0", ms=4, label=f"located maximum at {at:.6g}")
        q = self.quantized
        q_bound = None if q is None else (q.abs_error_bound if error == "abs" else q.rel_error_bound)
        if q_bound is not None:
            _, gq = self.error_curve(points, error, quantized=True)
            what = (f"fixed point, {','.join(map(str, sorted(set(q.frac_bits))))} fractional bits"
                    if q.format == "fixed" else f"{q.format} coefficients")
            ax.plot(x, gq, color="C1", lw=1.0, label=what)
            ax.axhline(q_bound, color="C1", ls=":", lw=0.8,
                       label=f"its bound {format_up(q_bound, '.3e')}")
            ax.axhline(-q_bound, color="C1", ls=":", lw=0.8)
        if binary32:
            x32, g32 = self.error_curve(points, error, binary32=True)
            ax.plot(x32, g32, color="C2", lw=0.6, alpha=0.8,
                    label="binary32 Horner, measured (the export states its bound)")
        ax.axhline(0.0, color="0.6", lw=0.5)
        ax.set_xlabel(self.variable)
        ax.set_ylabel(label)
        ax.set_title(f"{self.name}: {self.expression} on [{self.interval[0]}, {self.interval[1]}]",
                     fontsize="medium")
        ax.legend(fontsize="small", loc="best")
        return ax


# -- reading: every field checked, each refusal naming its field ---------------

_OPTIONAL = {"fixed_point": None, "provenance": {}, "shift": None, "quantized": None,
             "basis_choice": None}


def _claims(d, prefix: str = "") -> dict[str, float | None]:
    """The error claims of ``d`` (a table, ``fixed_point`` or ``quantized``): the
    bounds and located maxima, the relative ones null together."""
    rel = number(d["rel_error_bound"], f"{prefix}rel_error_bound", optional=True, nonneg=True)
    max_rel = number(d["max_rel_error"], f"{prefix}max_rel_error", optional=True, nonneg=True)
    if (rel is None) != (max_rel is None):
        raise ValueError(f"{prefix}max_rel_error: must be null exactly when "
                         f"{prefix}rel_error_bound is null")
    return dict(abs_error_bound=number(d["abs_error_bound"], f"{prefix}abs_error_bound",
                                       nonneg=True),
                rel_error_bound=rel,
                max_abs_error=number(d["max_abs_error"], f"{prefix}max_abs_error", nonneg=True),
                max_rel_error=max_rel)


def _per_power(value, field: str, degree: int, read) -> tuple:
    """An array of degree + 1 integers, each read with ``read(item, name)``."""
    items = array(value, field, "integers")
    if len(items) != degree + 1:
        raise ValueError(f"{field}: {len(items)} integers for degree {degree}; "
                         f"expected degree + 1 = {degree + 1}")
    return tuple(read(v, f"{field}[{k}]") for k, v in enumerate(items))


def _check_word(field: str, word_bits: int, values, values_field: str) -> None:
    """Refuse a value of ``values`` that ``word_bits``-bit two's complement cannot hold."""
    for k, q in enumerate(values):
        if not -(1 << (word_bits - 1)) <= q < (1 << (word_bits - 1)):
            need = max(q.bit_length() + 1, (-q - 1).bit_length() + 1)
            raise ValueError(f"{field}: {word_bits} bits cannot hold {values_field}[{k}] = {q} "
                             f"(two's complement); accepted: word_bits >= {need}")


def _read_fixed(fp, degree: int) -> FixedPoint | None:
    if fp is None:
        return None
    check_object(fp, "fixed_point", [f.name for f in dataclasses.fields(FixedPoint)])
    frac_bits = integer(fp["frac_bits"], "fixed_point.frac_bits", 0, MAX_FRAC_BITS)
    word_bits = integer(fp["word_bits"], "fixed_point.word_bits", 2, MAX_WORD_BITS)
    ints = array(fp["integers"], "fixed_point.integers", "integers")
    integers = tuple(integer(q, f"fixed_point.integers[{k}]") for k, q in enumerate(ints))
    if len(integers) != degree + 1:
        raise ValueError(f"fixed_point.integers: {len(integers)} integers for degree {degree}; "
                         f"expected degree + 1 = {degree + 1}")
    _check_word("fixed_point.word_bits", word_bits, integers, "fixed_point.integers")
    claims = _claims(fp, "fixed_point.")
    return FixedPoint(frac_bits=frac_bits, integers=integers, word_bits=word_bits,
                      method=choice(fp["method"], "fixed_point.method", FIXED_METHODS), **claims)


def _exactly(c: float, m: int, e: int) -> bool:
    """True when the double ``c`` is exactly ``m * 2**e`` (integers: c = p/q, q a
    power of two)."""
    p, q = c.as_integer_ratio()
    return p * (1 << -e) == m * q if e < 0 else p == (m << e) * q


def _read_binary(q, degree: int) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """``quantized.mantissas`` and ``quantized.exponents``: each ``m * 2**e`` a double."""
    lim_m, lim_e = (1 << 53) - 1, 1100
    mants = _per_power(q["mantissas"], "quantized.mantissas", degree,
                       lambda v, f: integer(v, f, -lim_m, lim_m))
    exps = _per_power(q["exponents"], "quantized.exponents", degree,
                      lambda v, f: integer(v, f, -lim_e, lim_e))
    for k, (m, e) in enumerate(zip(mants, exps)):
        c = math.ldexp(m, e) if e < 1024 else math.inf
        if m and (not math.isfinite(c) or not _exactly(c, m, e)):
            raise ValueError(f"quantized.mantissas[{k}]: {m} * 2^{e} is not a double; accepted: "
                             f"a finite double (the certifier evaluates it exactly)")
    return mants, exps


def _read_format(q, fmt: str, degree: int, mants, exps):
    """``(frac_bits, word_bits)`` of a fixed format (None, None for a floating
    one), each coefficient checked against its format."""
    from .rounding import representable

    if fmt != "fixed":
        if q["frac_bits"] is not None or q["word_bits"] is not None:
            raise ValueError(f"quantized.frac_bits, quantized.word_bits: must be null for "
                             f"format {fmt}")
        for k in range(degree + 1):
            if not representable(mants[k], exps[k], fmt):
                raise ValueError(f"quantized.mantissas[{k}]: {mants[k]} * 2^{exps[k]} is not "
                                 f"a finite {fmt} number")
        return None, None
    frac_bits = _per_power(q["frac_bits"], "quantized.frac_bits", degree,
                           lambda v, f: integer(v, f, 0, MAX_FRAC_BITS))
    word_bits = integer(q["word_bits"], "quantized.word_bits", 2, MAX_WORD_BITS)
    for k in range(degree + 1):
        if mants[k] and exps[k] != -frac_bits[k]:
            raise ValueError(f"quantized.exponents[{k}]: {exps[k]} for a fixed-point "
                             f"coefficient with {frac_bits[k]} fractional bits; expected "
                             f"{-frac_bits[k]}")
        if not -(1 << (word_bits - 1)) <= mants[k] < (1 << (word_bits - 1)):
            raise ValueError(f"quantized.word_bits: {word_bits} bits cannot hold "
                             f"quantized.mantissas[{k}] = {mants[k]}")
    return frac_bits, word_bits


def _read_quantized(q, degree: int) -> Quantized | None:
    if q is None:
        return None
    check_object(q, "quantized", [f.name for f in dataclasses.fields(Quantized)])
    fmt = choice(q["format"], "quantized.format", QUANT_FORMATS)
    mon = array(q["monomials"], "quantized.monomials", "integers")
    monomials = tuple(integer(k, f"quantized.monomials[{i}]", 0, degree) for i, k in enumerate(mon))
    if not monomials or list(monomials) != sorted(set(monomials)):
        raise bad("quantized.monomials", f"increasing distinct powers in 0..{degree}", list(mon))
    mants, exps = _read_binary(q, degree)
    fixed_constant = boolean(q["fixed_constant"], "quantized.fixed_constant")
    for k in range(degree + 1):
        if k not in monomials and mants[k] != 0 and not (k == 0 and fixed_constant):
            raise ValueError(f"quantized.mantissas[{k}]: x^{k} is not among quantized.monomials "
                             f"{list(monomials)}, so its mantissa must be 0")
    frac_bits, word_bits = _read_format(q, fmt, degree, mants, exps)
    claims = _claims(q, "quantized.")
    return Quantized(format=fmt, monomials=monomials, mantissas=mants, exponents=exps,
                     frac_bits=frac_bits, word_bits=word_bits, fixed_constant=fixed_constant,
                     method=choice(q["method"], "quantized.method", FIXED_METHODS), **claims)


def _check_version(d) -> None:
    if not isinstance(d, dict):
        raise ValueError(f"a coefficient table must be a JSON object, got {show(d)}")
    version = d.get("schema_version")
    if isinstance(version, bool) or not isinstance(version, int) or version != SCHEMA_VERSION:
        raise ValueError(f"schema_version: schema version {show(version)} is not supported; "
                         f"accepted: {SCHEMA_VERSION}")


def _pair(value, field: str, what: str, explained: str) -> list:
    """A JSON array of two items (``what``; ``explained`` in the refusal of another length)."""
    items = array(value, field, what)
    if len(items) != 2:
        raise bad(field, explained, items)
    return items


def _read_rel(d) -> tuple[float | None, float | None, float | None]:
    """``rel_error_bound``, ``max_rel_error``, ``max_rel_at``: null together, and
    not null when the fit minimized the relative error."""
    rel = number(d["rel_error_bound"], "rel_error_bound", optional=True, nonneg=True)
    max_rel = number(d["max_rel_error"], "max_rel_error", optional=True, nonneg=True)
    max_rel_at = number(d["max_rel_at"], "max_rel_at", optional=True)
    if (rel is None) != (max_rel is None) or (rel is None) != (max_rel_at is None):
        raise ValueError("max_rel_error, max_rel_at: must be null exactly when "
                         "rel_error_bound is null")
    if rel is None and d["error_kind"] == "rel":
        raise ValueError("rel_error_bound: null, but error_kind is 'rel'; accepted: the "
                         "certified relative error of a fit that minimized it")
    return rel, max_rel, max_rel_at


def _read_shift(value) -> tuple[float, float] | None:
    if value is None:
        return None
    pair = _pair(value, "shift", "2 numbers [center, scale]", "an array of 2 numbers [center, scale]")
    shift = (number(pair[0], "shift[0]"), number(pair[1], "shift[1]", nonneg=True))
    if not shift[1] > 0:
        raise bad("shift[1]", "a positive number (the scale s of t = (x - c)/s)", pair[1])
    return shift


def _read_fields(cls, d) -> dict[str, Any]:
    """The fields of a table from its JSON object, every field checked (no
    certification): the keyword arguments of ``cls``. The checks run in a fixed
    order, so a table with several faults is refused for the same one each time."""
    from chebnorm.core.textsafe import identifier

    _check_version(d)
    check_object(d, "", [f.name for f in dataclasses.fields(cls)], optional=_OPTIONAL)
    d = {**_OPTIONAL, **d}
    degree = integer(d["degree"], "degree", 0, MAX_DEGREE)
    coeffs = array(d["coefficients"], "coefficients", "numbers")
    coefficients = tuple(number(c, f"coefficients[{k}]") for k, c in enumerate(coeffs))
    if len(coefficients) != degree + 1:
        raise ValueError(f"coefficients: {len(coefficients)} numbers for degree {degree}; "
                         f"expected degree + 1 = {degree + 1}")
    interval = _pair(d["interval"], "interval", "2 strings",
                     "an array of 2 strings (exact constants such as \"sqrt(2)\")")
    interval_float = _pair(d["interval_float"], "interval_float", "2 numbers",
                           "an array of 2 numbers")
    prov = provenance(d["provenance"])
    rel, max_rel, max_rel_at = _read_rel(d)
    shift = _read_shift(d["shift"])
    return dict(
        name=identifier(d["name"], field="name"),
        expression=text(d["expression"], "expression"),
        variable=identifier(d["variable"], field="variable"),
        interval=tuple(text(v, f"interval[{i}]") for i, v in enumerate(interval)),
        interval_float=tuple(number(v, f"interval_float[{i}]")
                             for i, v in enumerate(interval_float)),
        degree=degree, kind=choice(d["kind"], "kind", KINDS),
        error_kind=choice(d["error_kind"], "error_kind", ERROR_KINDS),
        coefficients=coefficients,
        abs_error_bound=number(d["abs_error_bound"], "abs_error_bound", nonneg=True),
        rel_error_bound=rel,
        max_abs_error=number(d["max_abs_error"], "max_abs_error", nonneg=True),
        max_abs_at=number(d["max_abs_at"], "max_abs_at"),
        max_rel_error=max_rel, max_rel_at=max_rel_at,
        fixed_point=_read_fixed(d["fixed_point"], degree),
        provenance=prov, schema_version=SCHEMA_VERSION, shift=shift,
        quantized=_read_quantized(d["quantized"], degree),
        basis_choice=read_basis_choice(d["basis_choice"], "monomial" if shift is None else "shifted",
                                       coefficients, shift,
                                       tuple(number(v, f"interval_float[{i}]")
                                             for i, v in enumerate(interval_float))))


# -- verifying: every stated bound re-proved for exactly the stored numbers -----

#: tolerances of the re-certification: the certifier's default first, then
#: tighter ones (each costs milliseconds at the registered degrees) until the
#: stated bound is shown or the last one (near double precision) fails
_TOLS = (None, 2.0 ** -16, 2.0 ** -24, 2.0 ** -32, 2.0 ** -40, 2.0 ** -50)
#: subinterval cap of the tighter passes (the first pass uses the certifier's)
_RETRY_SUBINTERVALS = 20_000


def _fmt2(a: float, b: float) -> tuple[str, str]:
    """``a`` and ``b`` with the fewest digits (at least 3) that tell them apart."""
    for digits in range(2, 17):
        sa, sb = f"{a:.{digits}e}", f"{b:.{digits}e}"
        if sa != sb or a == b:
            return sa, sb
    return repr(a), repr(b)


def _prove(field: str, stated: float, fn, coefficients, lo, hi, kind: str, what: str,
           shift=None):
    """Certify ``sup |g|`` (``g = p - f`` or ``p/f - 1``) until ``stated`` is
    shown to bound it; raise naming ``field`` when it cannot be."""
    from .certify import certify

    cert = None
    for tol in _TOLS:
        opts = {} if tol is None else {"tol": tol, "max_subintervals": _RETRY_SUBINTERVALS}
        try:
            cert = certify(fn, coefficients, lo, hi, kind, shift=shift, **opts)
        except ValueError as exc:
            raise ValueError(f"{field}: {what} cannot be certified: {exc}") from None
        if stated >= cert.bound:
            return cert
        # the located maximum is |g| at a point (a double within half an ulp of a
        # 128-bit ball): a statement one ulp below it is false, no tighter pass helps
        if stated < math.nextafter(cert.maximum, 0.0):
            break
    s, u = _fmt2(stated, cert.bound)
    msg = f"{field}: stated {s} but {what} is {u}"
    if stated < cert.maximum:
        g = "|p - f|" if kind == "abs" else "|p/f - 1|"
        msg += f"; {g} reaches {_fmt2(stated, cert.maximum)[1]} at {fn.var} = {cert.at!r}"
    raise ValueError(msg)


def _within(x: float, lo_ball, hi_ball) -> bool:
    """False only when ``x`` is provably outside ``[lo, hi]``."""
    from flint import arb

    return not (arb(x) < lo_ball or arb(x) > hi_ball)


def _verify(t: "CoefficientTable") -> "CoefficientTable":
    """Re-prove the claims of a table whose fields :func:`_read` checked."""
    import sympy as sp
    from flint import arb

    from .certify import arb_enclose
    from .expr import parse_function, parse_number

    try:
        fn = parse_function(t.expression, t.variable)
    except ValueError as exc:
        raise ValueError(f"expression: {exc}") from None
    ends = []
    for i, end in enumerate(t.interval):
        try:
            ends.append(parse_number(end))
        except ValueError as exc:
            raise ValueError(f"interval[{i}]: {exc}") from None
    lo, hi = ends
    balls = [arb_enclose(lo), arb_enclose(hi)]
    if not balls[0] < balls[1]:
        raise ValueError(f"interval: [{t.interval[0]}, {t.interval[1]}] is empty or reversed; "
                         f"accepted: interval[0] < interval[1]")
    for i, (ball, x, exact) in enumerate(zip(balls, t.interval_float, ends)):
        # the stored double must be a rounding of the exact endpoint (one ulp at most)
        if arb(math.nextafter(x, -math.inf)) > ball or arb(math.nextafter(x, math.inf)) < ball:
            raise ValueError(f"interval_float[{i}]: {x!r} is not interval[{i}] = {t.interval[i]} "
                             f"rounded to a double; accepted: {float(sp.N(exact, 30))!r}")
    for key, x in (("max_abs_at", t.max_abs_at), ("max_rel_at", t.max_rel_at)):
        if x is not None and not _within(x, *balls):
            raise ValueError(f"{key}: {t.variable} = {x!r} lies outside the interval "
                             f"[{t.interval[0]}, {t.interval[1]}]")
    parts = [("", t.coefficients, t, "the coefficients'")]
    if t.fixed_point is not None:
        parts.append(("fixed_point.", t.fixed_point.coefficients, t.fixed_point,
                      "the fixed-point coefficients'"))
    if t.quantized is not None:
        parts.append(("quantized.", t.quantized.coefficients, t.quantized,
                      f"the {t.quantized.format} coefficients'"))
    for prefix, coeffs, claims, whose in parts:
        for kind, bound, maximum in (("abs", claims.abs_error_bound, claims.max_abs_error),
                                     ("rel", claims.rel_error_bound, claims.max_rel_error)):
            if bound is None:
                continue
            what = f"{whose} certified {'relative ' if kind == 'rel' else ''}error"
            cert = _prove(f"{prefix}{kind}_error_bound", bound, fn, coeffs, lo, hi, kind, what,
                          t.shift)
            check_maximum(f"{prefix}max_{kind}_error", maximum, f"{prefix}{kind}_error_bound",
                          bound, cert, fn.var)
    for kind, stated, at in (("abs", t.max_abs_error, t.max_abs_at),
                             ("rel", t.max_rel_error, t.max_rel_at)):
        if at is not None:
            _check_at(kind, stated, at, fn, t)
    return t


def check_maximum(field: str, stated: float, bound_field: str, bound: float, cert,
                  var) -> None:
    """Refuse a located maximum ``stated`` (``field``) that is not one: above its
    stated bound, above the certified bound ``cert.bound`` of the supremum (so
    above the supremum), or below ``cert.maximum / (1 + TOL)`` (the certifier
    located ``|g| = cert.maximum``, and a certified located maximum is within
    ``1 + TOL`` of the supremum)."""
    from .certify import TOL

    if stated > bound:
        s, m = _fmt2(bound, stated)
        raise ValueError(f"{field}: the located maximum {m} exceeds {bound_field} = {s}")
    if stated > cert.bound:
        m, u = _fmt2(stated, cert.bound)
        raise ValueError(f"{field}: the located maximum {m} exceeds the certified bound {u} "
                         f"of the supremum; accepted: a value the error reaches")
    if stated < math.nextafter(cert.maximum / (1 + TOL), 0.0):
        m, u = _fmt2(stated, cert.maximum)
        raise ValueError(f"{field}: stated {m} but the error reaches {u} at {var} = "
                         f"{cert.at!r}; accepted: the located maximum, within 1 + 2^-8 of the "
                         f"supremum")


def _check_at(kind: str, stated: float, at: float, fn, t) -> None:
    """Refuse ``max_{kind}_error`` unless it is ``|g(max_{kind}_at)|`` (one ulp, and the
    enclosure's own width, allowed)."""
    from flint import arb

    from chebnorm.core.numeric import arb_precision

    from .certify import PolyTaylor, error_function

    with arb_precision(128):
        g = error_function(fn.arb, PolyTaylor([arb(c) for c in t.coefficients], t.shift), kind)
        v = abs(g(arb(at)))
        if not v.is_finite():
            raise ValueError(f"max_{kind}_at: the error cannot be evaluated at {t.variable} = "
                             f"{at!r}; accepted: the point where max_{kind}_error is reached")
        v = arb(v.mid(), 2 * v.rad())
        if arb(math.nextafter(stated, math.inf)) < v or arb(math.nextafter(stated, -math.inf)) > v:
            g_text = "|p - f|" if kind == "abs" else "|p/f - 1|"
            s, u = _fmt2(stated, float(v.mid()))
            raise ValueError(f"max_{kind}_error: stated {s} but {g_text} at max_{kind}_at = "
                             f"{at!r} is {u}; accepted: the error at the stated point")


def _point_error(table: CoefficientTable, at: float, error: str) -> tuple[float, float]:
    """``(at, g(at))`` evaluated like :meth:`CoefficientTable.error_curve`."""
    import mpmath

    from .expr import parse_function

    f_mp = parse_function(table.expression, table.variable).mpmath
    with mpmath.workdps(40):
        xm = mpmath.mpf(float(at))
        p = mpmath.mpf(0)
        tm = _local_mp(table, xm)
        for c in reversed(table.coefficients):
            p = p * tm + mpmath.mpf(c)
        f = f_mp(xm)
        return at, float(p - f) if error == "abs" else float(p / f - 1)


def _local_mp(table: CoefficientTable, xm):
    """``x`` (an mpmath number) in the table's variable: ``(x - c)/s`` when shifted."""
    import mpmath

    if table.shift is None:
        return xm
    return (xm - mpmath.mpf(table.shift[0])) / mpmath.mpf(table.shift[1])


def _power_to_chebyshev(coeffs: list[Fraction]) -> list[Fraction]:
    """Exact Chebyshev coefficients ``a`` with ``sum a_k T_k(u) = sum c_k u**k``."""
    n = len(coeffs) - 1
    cheb = [[Fraction(1)], [Fraction(0), Fraction(1)]]  # T_k in powers of u
    while len(cheb) <= n:
        a, b = cheb[-1], cheb[-2]
        nxt = [Fraction(0)] + [2 * v for v in a]
        for i, v in enumerate(b):
            nxt[i] -= v
        cheb.append(nxt)
    rest = list(coeffs)
    out = [Fraction(0)] * (n + 1)
    for k in range(n, -1, -1):
        out[k] = rest[k] / cheb[k][k]
        for i, v in enumerate(cheb[k]):
            rest[i] -= out[k] * v
    return out
