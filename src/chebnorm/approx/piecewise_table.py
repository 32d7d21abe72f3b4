"""Piecewise polynomial tables: the :class:`PiecewiseTable` contract, its file, its verification.

A :class:`PiecewiseTable` splits ``[lo, hi]`` into segments and stores, for
each, a polynomial in a *local* variable, with integer coefficients in one
common fixed-point format (``coef_frac_bits`` fractional bits):

* ``segment_by="uniform"``: ``2**k`` equal segments, the hardware way -- the
  input code's top ``k`` bits select the segment, its low bits are the local
  variable (FloPoCo's ``FixFunctionByPiecewisePoly``).
* ``segment_by="exponent"``: ``[lo, hi] = [2**e0, 2**e1]``, each binade split
  into ``2**m`` segments by the top ``m`` bits of the mantissa (a float's
  exponent and leading mantissa bits select the segment, as normalization
  units index ``1/sqrt`` tables).

Segment ``s`` covers ``[a_s, b_s]``; its polynomial is evaluated in
``t = (x - a_s) / (b_s - a_s)`` in ``[0, 1]``, or with ``centered=True`` in
``u = t - 1/2`` in ``[-1/2, 1/2]`` (smaller coefficients and a smaller Horner
rounding error). Coefficient ``j`` of segment ``s`` is exactly
``integers[s][j] / 2**coef_frac_bits``.

Every segment's error ``sup |p_s - f|`` (and ``sup |p_s/f - 1|`` for
``error="rel"``) is certified for exactly the stored integers, on the composed
function ``t -> f(a_s + (b_s - a_s) t)`` (the endpoints are exact rationals,
enclosed in Arb balls), all segments together by
:func:`chebnorm.approx.certify_batch.certify_batch` (one Taylor model per
segment in Arb, a vectorised branch and bound in float64 with every rounding
error accounted for; :func:`chebnorm.approx.certify` for a segment it cannot
settle); the table's bound is the maximum over the segments. Reading a table (:meth:`PiecewiseTable.load`,
``from_dict``) checks every field (a refusal names it) and re-certifies every
stated bound, as :class:`chebnorm.approx.CoefficientTable` does (both are kinds
of :class:`chebnorm.approx.contract.Table`). The fitter is
:func:`chebnorm.approx.piecewise_fit.piecewise_fit`.

>>> from chebnorm.approx.piecewise_fit import piecewise_fit
>>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
>>> t.segment_count, t.degree, t.abs_error_bound < 2e-2
(4, 1, True)
>>> [str(e) for e in t.segment_bounds(0)]
['1', '7/4']
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np
import sympy as sp

from flint import arb

from chebnorm.core.display import summary_repr
from chebnorm.core.numeric import arb_precision, format_up, signed_bits

from .certify import arb_enclose, certify
from .certify_batch import certify_batch
from .contract import Table
from .expr import parse_function, parse_number
from .schema import (ERROR_KINDS, MAX_COEF_FRAC_BITS, MAX_COEF_INT_BITS, MAX_EXPONENT_SPAN,
                     MAX_INDEX_BITS, MAX_PIECEWISE_BYTES, MAX_PIECEWISE_DEGREE, PIECEWISE_FITS,
                     PIECEWISE_KIND, PIECEWISE_SCHEMA, SEGMENT_BY, array, bad, boolean,
                     check_object, choice, integer, number, provenance, text)
from .table import check_maximum

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

#: the names these constants had here (they live in :mod:`chebnorm.approx.schema`)
FITS = PIECEWISE_FITS
ERRORS = ERROR_KINDS


@dataclass(frozen=True)
class PiecewiseSegment:
    """One segment: integer coefficients and the certified claims about them.

    Parameters
    ----------
    integers : tuple of int
        The ``degree + 1`` coefficients, ascending, as integers:
        coefficient ``j`` is ``integers[j] / 2**coef_frac_bits`` (the table's).
    abs_error_bound : float
        A rigorous bound of ``sup |p_s - f|`` on the segment (rounded upward).
    max_abs_error : float
        The largest ``|p_s - f|`` located on the segment (a lower bound of the
        supremum).
    rel_error_bound : float or None, optional
        A rigorous bound of ``sup |p_s/f - 1|``; default None (for an ``"abs"``
        table).
    max_rel_error : float or None, optional
        The largest ``|p_s/f - 1|`` located; default None.
    """

    integers: tuple[int, ...]
    abs_error_bound: float
    max_abs_error: float
    rel_error_bound: float | None = None
    max_rel_error: float | None = None


@dataclass(frozen=True)
class PiecewiseTable(Table):
    """A piecewise polynomial table with certified error bounds (see the module docstring).

    Attributes
    ----------
    name : str
        An identifier, used to name generated code.
    expression : str
        The approximated function ``f`` (sympy syntax).
    variable : str
        Its variable.
    interval : tuple of str
        The exact endpoints ``(lo, hi)`` as sympy strings.
    segment_by : str
        ``"uniform"`` (``2**index_bits`` equal segments) or ``"exponent"``
        (``2**index_bits`` segments per binade of ``[2**e0, 2**e1]``).
    index_bits : int
        The bits that select a segment (per binade for ``"exponent"``).
    degree : int
        The degree of every segment's polynomial.
    centered : bool
        Each polynomial is in ``u = t - 1/2`` in ``[-1/2, 1/2]`` instead of ``t`` in ``[0, 1]``.
    fit : str
        ``"minimax"`` or ``"chebyshev"``: how each segment was fitted.
    error_kind : str
        ``"abs"`` or ``"rel"``: the error minimized (``"rel"`` certifies both).
    coef_frac_bits : int
        Coefficient ``j`` of segment ``s`` is ``segments[s].integers[j] / 2**coef_frac_bits``.
    segments : tuple of PiecewiseSegment
        Each segment's integers and certified bounds and located maxima.
    abs_error_bound : float
        The largest segment ``abs_error_bound``: a rigorous bound of ``sup |p - f|``.
    rel_error_bound : float or None
        The largest segment ``rel_error_bound``; None when ``error_kind`` is ``"abs"``.
    provenance : dict of str to str
        Where the table came from (command, library versions).
    """

    name: str
    expression: str
    variable: str
    interval: tuple[str, str]
    segment_by: str
    index_bits: int
    degree: int
    centered: bool
    fit: str
    error_kind: str
    coef_frac_bits: int
    segments: tuple[PiecewiseSegment, ...]
    abs_error_bound: float
    rel_error_bound: float | None
    provenance: dict = field(default_factory=dict)

    WHAT = "piecewise table"
    MAX_BYTES = MAX_PIECEWISE_BYTES
    JSON_INDENT = 1

    def _summary(self) -> list[tuple[str, object]]:
        return [("name", self.name), ("expression", self.expression),
                ("interval", self.interval), ("segments", self.segment_count),
                ("segment_by", self.segment_by), ("degree", self.degree),
                ("coef_frac_bits", self.coef_frac_bits), ("abs_error_bound", self.abs_error_bound)]

    __repr__ = summary_repr

    # -- geometry ------------------------------------------------------------
    @property
    def segment_count(self) -> int:
        return len(self.segments)

    @property
    def lo(self) -> sp.Expr:
        return parse_number(self.interval[0])

    @property
    def hi(self) -> sp.Expr:
        return parse_number(self.interval[1])

    @property
    def exponent_range(self) -> tuple[int, int] | None:
        """``(e0, e1)`` with ``[lo, hi] = [2**e0, 2**e1]`` for exponent tables, else None."""
        if self.segment_by != "exponent":
            return None
        return exact_log2(self.lo), exact_log2(self.hi)

    @property
    def local_range(self) -> tuple[Fraction, Fraction]:
        """Range of the local variable: ``[0, 1]`` or ``[-1/2, 1/2]`` (centred)."""
        return (Fraction(-1, 2), Fraction(1, 2)) if self.centered else (Fraction(0), Fraction(1))

    def segment_bounds(self, s: int) -> tuple[sp.Expr, sp.Expr]:
        """Exact endpoints ``(a_s, b_s)`` of segment ``s``."""
        return segment_bounds(self.segment_by, self.lo, self.hi, self.index_bits, s)

    def coefficients(self, s: int) -> tuple[float, ...]:
        """Coefficients of segment ``s`` in its local variable (exact doubles)."""
        return tuple(math.ldexp(q, -self.coef_frac_bits) for q in self.segments[s].integers)

    def coefficient_word_bits(self) -> tuple[int, ...]:
        """Signed width of coefficient ``j`` over all segments (the ROM's word layout)."""
        out = []
        for j in range(self.degree + 1):
            vals = [seg.integers[j] for seg in self.segments]
            out.append(signed_bits(min(vals), max(vals)))
        return tuple(out)

    def __call__(self, x) -> np.ndarray:
        """Float64 evaluation at ``x`` (inside ``[lo, hi]``), for plots and checks."""
        s, t = self._locate(np.asarray(x, dtype=float))
        if self.centered:
            t = t - 0.5
        coeffs = np.array([self.coefficients(i) for i in range(self.segment_count)])
        acc = coeffs[s, self.degree]
        for j in range(self.degree - 1, -1, -1):
            acc = acc * t + coeffs[s, j]
        return acc

    # -- conversions (numpy, sympy) ---------------------------------------------
    def to_sympy(self):
        """The table as a sympy ``Piecewise`` in its variable, exactly.

        Segment ``s`` holds for ``a_s <= x < b_s`` (the last one up to and
        including ``hi``), as :meth:`__call__` locates it; its polynomial is
        in the local variable ``t = (x - a_s)/(b_s - a_s)`` (``t - 1/2``
        when ``centered``), with the exact coefficients
        ``integers[j] / 2**coef_frac_bits`` and the exact segment endpoints.
        Outside ``[lo, hi]`` the Piecewise is undefined (sympy's ``nan``).

        Returns
        -------
        sympy.Piecewise

        Examples
        --------
        >>> from chebnorm.approx.piecewise_fit import piecewise_fit
        >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=2, coef_frac_bits=8)
        >>> e = t.to_sympy()
        >>> len(e.args), float(e.subs("x", 3)) == float(t(3.0))
        (2, True)
        """
        x = sp.Symbol(self.variable)
        scale = sp.Integer(2) ** -self.coef_frac_bits
        pieces = []
        for s in range(self.segment_count):
            a, b = self.segment_bounds(s)
            t = (x - a) / (b - a) - (sp.Rational(1, 2) if self.centered else 0)
            poly = sp.Add(*(q * scale * t ** j for j, q in enumerate(self.segments[s].integers)))
            last = s == self.segment_count - 1
            cond = sp.And(x >= a, x <= b) if last else sp.And(x >= a, x < b)
            pieces.append((poly, cond))
        return sp.Piecewise(*pieces)

    def __array__(self, dtype=None, copy=None):
        """``np.asarray(table)``: the coefficients, shape ``(segments, degree + 1)``,
        float64: row ``s`` is :meth:`coefficients` ``(s)`` (each segment's, in its
        local variable, exactly ``integers / 2**coef_frac_bits``).

        >>> from chebnorm.approx.piecewise_fit import piecewise_fit
        >>> np.asarray(piecewise_fit("x**2", ("0", "1"), 1, segments=4)).shape
        (4, 2)
        """
        if copy is False:
            raise ValueError("a table's coefficients are copied into a new array; accepted: "
                             "copy=None or copy=True")
        return np.array([self.coefficients(s) for s in range(self.segment_count)],
                        dtype=np.float64 if dtype is None else dtype)

    def _locate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(s, t)``: the segment of each ``x`` and its local variable in ``[0, 1]``, in float64."""
        lo_f, hi_f = float(self.lo), float(self.hi)
        if self.segment_by == "uniform":
            n = self.segment_count
            pos = (x - lo_f) / (hi_f - lo_f) * n
            s = np.clip(np.floor(pos), 0, n - 1).astype(int)
            return s, pos - s
        m, e = np.frexp(x)
        e0 = int(math.log2(lo_f))
        per = 2 ** self.index_bits
        scaled = (2 * m - 1) * per
        j = np.clip(np.floor(scaled), 0, per - 1).astype(int)
        raw = (e - 1 - e0) * per + j
        s = np.clip(raw, 0, self.segment_count - 1)
        # x = hi = 2**e1 opens the next binade: it is the last segment's t = 1
        return s, np.where(raw > self.segment_count - 1, 1.0, scaled - j)

    # -- display and plots -------------------------------------------------------
    def _display_rows(self) -> list[tuple[str, str]]:
        """(label, plain text) pairs shown by the HTML and Markdown reprs."""
        lo, hi = self.interval
        local = "u = t - 1/2 in [-1/2, 1/2]" if self.centered else "t in [0, 1]"
        per = " per binade" if self.segment_by == "exponent" else ""
        rows = [
            ("function", f"{self.expression} of {self.variable}"),
            ("interval", f"[{lo}, {hi}]"),
            ("segments", f"{self.segment_count} ({self.segment_by}, 2^{self.index_bits}{per}); "
                         f"each in its local variable {local}"),
            ("degree, fit", f"{self.degree}, {self.fit} ({self.error_kind} error)"),
            ("coefficients", f"integers / 2^{self.coef_frac_bits}; signed widths "
                             + ", ".join(str(w) for w in self.coefficient_word_bits())),
            ("max |p - f|", self._worst("abs")),
        ]
        if self.rel_error_bound is not None:
            rows.append(("max |p/f - 1|", self._worst("rel")))
        if self.provenance:
            rows.append(("provenance", "; ".join(f"{k}: {v}"
                                                 for k, v in sorted(self.provenance.items()))))
        return rows

    def _worst(self, kind: str) -> str:
        """The largest located maximum over the segments, and the certified bound."""
        located = [getattr(seg, f"max_{kind}_error") for seg in self.segments]
        s = max(range(len(located)), key=located.__getitem__)
        return (f"{located[s]:.6e} in segment {s}; certified bound "
                f"{format_up(getattr(self, f'{kind}_error_bound'), '.6e')}")

    def error_curve(self, points: int = 801, error: str = "abs"):
        """``(x, g)``: the error ``g = p - f`` (``error="abs"``) or ``p/f - 1``
        (``"rel"``) at ``points`` equally spaced floats of the interval, each
        evaluated with the exact coefficients of its segment in mpmath at 40
        significant digits.

        >>> from chebnorm.approx.piecewise_fit import piecewise_fit
        >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
        >>> x, g = t.error_curve(201)
        >>> bool(abs(g).max() <= t.abs_error_bound)
        True
        """
        import mpmath

        if error not in ("abs", "rel"):
            raise ValueError(f"error must be 'abs' or 'rel'; got {error!r}")
        if not isinstance(points, int) or isinstance(points, bool) or points < 2:
            raise ValueError(f"points must be an integer >= 2; got {points!r}")
        f_mp = parse_function(self.expression, self.variable).mpmath
        x = np.linspace(float(self.lo), float(self.hi), points)
        g = np.empty(points)
        with mpmath.workdps(40):
            ends = {}
            for i, xi in enumerate(x):
                s = self._segment_of(float(xi))
                if s not in ends:
                    a, b = self.segment_bounds(s)
                    ends[s] = (mpmath.mpf(sp.N(a, 45)), mpmath.mpf(sp.N(b - a, 45)))
                a, w = ends[s]
                xm = mpmath.mpf(float(xi))
                t = (xm - a) / w - (mpmath.mpf(0.5) if self.centered else 0)
                p = mpmath.mpf(0)
                for c in reversed(self.coefficients(s)):
                    p = p * t + mpmath.mpf(c)
                f = f_mp(xm)
                g[i] = float(p - f) if error == "abs" else float(p / f - 1)
        return x, g

    def _segment_of(self, x: float) -> int:
        """The segment whose closed interval holds ``x`` (located in float64 as
        :meth:`__call__` does, then checked exactly)."""
        s = int(self._locate(np.array([x]))[0][0])
        xq = sp.Rational(x)
        for _ in range(self.segment_count):
            a, b = self.segment_bounds(s)
            if xq < a and s > 0:
                s -= 1
            elif xq > b and s < self.segment_count - 1:
                s += 1
            else:
                return s
        return s

    def plot(self, ax=None, error: str = "abs", points: int = 801):
        """Plot the error curve ``p - f`` (``error="rel"``: ``p/f - 1``) over the
        interval with the table's certified bound ``+-bound`` and each segment's
        own bound. Returns the matplotlib Axes.

        >>> import matplotlib
        >>> matplotlib.use("Agg")
        >>> from chebnorm.approx.piecewise_fit import piecewise_fit
        >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
        >>> type(t.plot(points=101)).__name__
        'Axes'
        """
        if error == "rel" and self.rel_error_bound is None:
            raise ValueError(f"table {self.name!r} has no relative error (error_kind is 'abs')")
        if ax is None:
            import matplotlib.pyplot as plt

            _, ax = plt.subplots(figsize=(6.4, 3.6))
        x, g = self.error_curve(points, error)
        bound = self.abs_error_bound if error == "abs" else self.rel_error_bound
        label = "p - f" if error == "abs" else "p/f - 1"
        ax.plot(x, g, color="C0", lw=1.0,
                label=f"{label} ({self.segment_count} segments of degree {self.degree})")
        ax.axhline(bound, color="C0", ls="--", lw=0.8, label=f"certified bound "
                                                             f"{format_up(bound, '.3e')}")
        ax.axhline(-bound, color="C0", ls="--", lw=0.8)
        for s, seg in enumerate(self.segments):
            a, b = (float(v) for v in self.segment_bounds(s))
            own = getattr(seg, f"{error}_error_bound")
            ax.hlines([own, -own], a, b, color="C1", ls=":", lw=0.8,
                      label="segment bounds" if s == 0 else None)
        ax.axhline(0.0, color="0.6", lw=0.5)
        ax.set_xlabel(self.variable)
        ax.set_ylabel(label)
        ax.set_title(f"{self.name}: {self.expression} on [{self.interval[0]}, "
                     f"{self.interval[1]}]", fontsize="medium")
        ax.legend(fontsize="small", loc="best")
        return ax

    # -- serialization -------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        d = {"kind": PIECEWISE_KIND, "schema": PIECEWISE_SCHEMA, "name": self.name,
             "expression": self.expression, "variable": self.variable,
             "interval": list(self.interval), "segment_by": self.segment_by,
             "index_bits": self.index_bits, "degree": self.degree, "centered": self.centered,
             "fit": self.fit, "error_kind": self.error_kind,
             "coef_frac_bits": self.coef_frac_bits,
             "abs_error_bound": self.abs_error_bound, "rel_error_bound": self.rel_error_bound,
             "segments": [{"integers": list(seg.integers),
                           "abs_error_bound": seg.abs_error_bound,
                           "max_abs_error": seg.max_abs_error,
                           "rel_error_bound": seg.rel_error_bound,
                           "max_rel_error": seg.max_rel_error} for seg in self.segments],
             "provenance": dict(self.provenance)}
        return d

    @classmethod
    def _file_fields(cls, d) -> dict[str, Any]:
        return _fields(d)

    @classmethod
    def _own_fields(cls, d) -> dict[str, Any]:
        """``d`` lacks the file's kind and schema."""
        if isinstance(d, dict):
            d = {"kind": PIECEWISE_KIND, "schema": PIECEWISE_SCHEMA, **d}
        return _fields(d)

    def _prove_claims(self) -> None:
        _prove(self)

    def verify(self) -> PiecewiseTable:
        """Re-certify every segment's stated bounds and the table's maxima; return self or raise.

        >>> from chebnorm.approx.piecewise_fit import piecewise_fit
        >>> t = piecewise_fit("x**3", ("0", "1"), 1, segments=2, coef_frac_bits=12)
        >>> t.verify() is t
        True
        >>> from dataclasses import replace
        >>> replace(t, segments=(replace(t.segments[0], abs_error_bound=1e-9),) + t.segments[1:])
        Traceback (most recent call last):
        ...
        ValueError: segments[0].abs_error_bound: stated 1.00e-09 but the certified error of segment 0 is 2.42e-02

        Every table is verified when it is constructed (a file, a hand-built
        table, ``dataclasses.replace``): this call costs a comparison when
        nothing changed since, and re-proves the table otherwise. The table's
        ``abs_error_bound`` (and ``rel_error_bound``) must be the largest
        segment bound, ``rel_error_bound`` null exactly when ``error_kind`` is
        ``"abs"`` (the segments then certify no relative error).
        """
        return super().verify()


def _prove(table: PiecewiseTable) -> None:
    """Re-certify every segment's stated bounds and located maxima (the fields,
    and the top-level bounds' derivation from the segments, were checked by
    :func:`_fields`)."""
    for kind in ("abs", "rel"):
        stated = [getattr(seg, f"{kind}_error_bound") for seg in table.segments]
        todo = [s for s, b in enumerate(stated) if b is not None]
        if not todo:
            continue
        certs = _segment_certificates(table, kind, stated, todo)
        for s in todo:
            bound, maximum = stated[s], getattr(table.segments[s], f"max_{kind}_error")
            if bound < certs[s].bound:
                raise ValueError(f"segments[{s}].{kind}_error_bound: stated {bound:.2e} but "
                                 f"the certified error of segment {s} is "
                                 f"{format_up(certs[s].bound, '.2e')}")
            check_maximum(f"segments[{s}].max_{kind}_error", maximum,
                          f"segments[{s}].{kind}_error_bound", bound, certs[s], "t")


def _segment_certificates(table: PiecewiseTable, kind: str, stated, todo) -> dict:
    """Certificates of the segments ``todo``, tightened where ``stated`` is below."""
    certs = dict(zip(todo, certify_segments(table, kind, segments=todo)))
    # a bound certified more tightly than the default needs a tighter proof:
    # the batch at 2^-14 and 2^-40 (bounds written before the batch existed
    # can be within 1e-15 of the maximum); last, the per-segment certifier
    # that wrote those, at its default and at 2^-14
    steps = [lambda redo: certify_segments(table, kind, 2.0 ** -14, segments=redo),
             lambda redo: certify_segments(table, kind, 2.0 ** -40, segments=redo),
             lambda redo: _certify_alone(table, kind, None, redo),
             lambda redo: _certify_alone(table, kind, 2.0 ** -14, redo)]
    for step in steps:
        redo = [s for s in todo if stated[s] < certs[s].bound]
        if not redo:
            break
        for s, cert in zip(redo, step(redo)):
            if cert.bound < certs[s].bound:
                certs[s] = cert
    return certs


# -- geometry ------------------------------------------------------------------



def exact_log2(value: sp.Expr) -> int | None:
    """``e`` when ``value == 2**e`` exactly, else None.

    Parameters
    ----------
    value : sympy.Expr
        A real constant.

    Returns
    -------
    int or None
        The exponent ``e``, or None when ``value`` is not a power of two.

    Examples
    --------
    >>> exact_log2(sp.Rational(1, 4)), exact_log2(sp.Integer(3))
    (-2, None)
    """
    r = sp.nsimplify(value) if not value.is_Rational else value
    if not r.is_Rational or r <= 0:
        return None
    p, q = int(r.p), int(r.q)
    if p & (p - 1) == 0 and q == 1:
        return p.bit_length() - 1
    if p == 1 and q & (q - 1) == 0:
        return -(q.bit_length() - 1)
    return None


def segment_bounds(segment_by, lo, hi, index_bits, s):
    """Exact endpoints ``(a_s, b_s)`` of segment ``s`` of ``[lo, hi]`` (sympy numbers).

    Parameters
    ----------
    segment_by : {"uniform", "exponent"}
        ``"uniform"``: ``2**index_bits`` equal segments of ``[lo, hi]``;
        ``"exponent"``: ``2**index_bits`` equal segments per binade, ``lo`` and
        ``hi`` powers of two.
    lo, hi : sympy.Expr
        The exact interval, ``lo < hi``.
    index_bits : int
        The bits that select a segment (per binade for ``"exponent"``), >= 0.
    s : int
        The segment index, ``0 <= s <`` :func:`segment_count`.

    Returns
    -------
    tuple of sympy.Expr
        ``(a_s, b_s)``, exact.

    Examples
    --------
    >>> segment_bounds("exponent", sp.Integer(1), sp.Integer(4), 1, 3)
    (3, 4)
    """
    if segment_by == "uniform":
        n = 2 ** index_bits
        h = (hi - lo) / n
        return (lo + s * h, lo + (s + 1) * h)
    per = 2 ** index_bits
    e0 = exact_log2(lo)
    e, j = divmod(s, per)
    base = sp.Integer(2) ** (e0 + e)
    return (base * (1 + sp.Rational(j, per)), base * (1 + sp.Rational(j + 1, per)))


def segment_count(segment_by, lo, hi, index_bits) -> int:
    """How many segments ``index_bits`` make of ``[lo, hi]`` (per binade for ``"exponent"``).

    Parameters
    ----------
    segment_by : {"uniform", "exponent"}
        How the interval is cut (see :func:`segment_bounds`).
    lo, hi : sympy.Expr
        The exact interval; powers of two for ``"exponent"``.
    index_bits : int
        The bits that select a segment, >= 0.

    Returns
    -------
    int
        ``2**index_bits``, times the number of binades for ``"exponent"``.

    Examples
    --------
    >>> segment_count("exponent", sp.Rational(1, 4), sp.Integer(4), 2)
    16
    """
    if segment_by == "uniform":
        return 2 ** index_bits
    return (exact_log2(hi) - exact_log2(lo)) * 2 ** index_bits


def parse_segments(text) -> int:
    """``"2^k"``, ``"2**k"`` or a power of two ``N`` -> ``k`` (index bits).

    Parameters
    ----------
    text : str or int
        ``"2^k"``, ``"2**k"`` or a power of two ``N >= 1`` (text or int).

    Returns
    -------
    int
        ``k``, in ``0 .. MAX_INDEX_BITS``.

    Raises
    ------
    ValueError
        When ``text`` is not of that form or ``k`` is out of range.

    Examples
    --------
    >>> parse_segments("2^8"), parse_segments("16"), parse_segments(1)
    (8, 4, 0)
    """
    s = str(text).strip().replace("**", "^")
    try:
        if not s.isascii() or "_" in s:  # int() reads other scripts' digits and 1_0
            raise ValueError
        if s.startswith("2^"):
            k = int(s[2:])
        else:
            n = int(s)
            if n < 1 or n & (n - 1):
                raise ValueError
            k = n.bit_length() - 1
    except ValueError:
        raise ValueError(f"segments {text!r} is not a power of two; accepted: 2^k or N = 2^k "
                         f"with 0 <= k <= {MAX_INDEX_BITS}") from None
    if not 0 <= k <= MAX_INDEX_BITS:
        raise ValueError(f"segments 2^{k}: k = {k} is out of range; accepted: 0 <= k <= "
                         f"{MAX_INDEX_BITS}")
    return k


def certify_segments(table: PiecewiseTable, kind: str = "abs", tol: float | None = None,
                     segments=None):
    """A :class:`~chebnorm.approx.Certificate` of ``sup |p_s - f|`` (or ``p_s/f - 1``)
    for every segment of ``table`` (or the indices ``segments``), at relative
    tightness ``tol`` (default the certifier's), all segments in one batch
    (:func:`chebnorm.approx.certify_batch.certify_batch`).

    Parameters
    ----------
    table : PiecewiseTable
        The table.
    kind : {"abs", "rel"}, optional
        The error certified, default ``"abs"``.
    tol : float or None, optional
        The relative tightness, a finite number > 0; default None (the
        certifier's :data:`~chebnorm.approx.certify.TOL`, 2^-8).
    segments : iterable of int, optional
        The segment indices; default None (every segment, in order).

    Returns
    -------
    list of Certificate
        One per segment certified, in the order of ``segments``; ``at`` is a
        point of the local variable.

    Raises
    ------
    ValueError
        When ``kind`` or ``tol`` is out of range, or the error is not finite on
        a segment.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("x**3", ("0", "1"), 1, segments=2, coef_frac_bits=12)
    >>> [c.bound <= s.abs_error_bound for c, s in zip(certify_segments(t), t.segments)]
    [True, True]
    """
    fn = parse_function(table.expression, table.variable)
    idx = list(range(table.segment_count)) if segments is None else [int(s) for s in segments]
    origins, widths = segment_balls(table.segment_by, table.lo, table.hi, table.index_bits,
                                     table.centered, idx)
    opts = {} if tol is None else {"tol": tol}
    return certify_batch(fn, origins, widths, [table.coefficients(s) for s in idx],
                         tuple(float(v) for v in table.local_range), kind, **opts)


def _certify_alone(table: PiecewiseTable, kind: str, tol: float | None, segments):
    """:func:`chebnorm.approx.certify` on each of ``segments`` in turn, exactly as
    tables were certified before :func:`certify_segments` batched them (the
    composed function built from the endpoints as below), so that their
    stated bounds still verify."""
    fn = parse_function(table.expression, table.variable)
    lo, hi = (sp.Rational(v) for v in table.local_range)
    sh = 0.5 if table.centered else 0.0
    f_series, f_point = fn.arb_series, fn.arb
    opts = {} if tol is None else {"tol": tol}
    out = []
    for s in segments:
        a, b = table.segment_bounds(s)
        a_b, w_b = arb_enclose(a), arb_enclose(b - a)
        g = _ArbLocal(lambda t, a_b=a_b, w_b=w_b: f_series(a_b + w_b * (t + sh)),
                      lambda t, a_b=a_b, w_b=w_b: f_point(a_b + w_b * (t + sh)))
        out.append(certify(g, table.coefficients(s), lo, hi, kind, **opts))
    return out


class _ArbLocal:
    def __init__(self, series, point):
        self.arb_series, self.arb = series, point


def segment_balls(segment_by, lo, hi, index_bits, centered, segments):
    """Arb balls ``(o_s, w_s)`` with segment ``s`` = ``o_s + w_s t``, ``t`` in
    the local range (128 bits; exact for binary ends), without sympy per segment,
    for the segments ``segments`` (indices).

    Parameters
    ----------
    segment_by : {"uniform", "exponent"}
        How the interval is cut (see :func:`segment_bounds`).
    lo, hi : sympy.Expr
        The exact interval; powers of two for ``"exponent"``.
    index_bits : int
        The bits that select a segment, >= 0.
    centered : bool
        The local variable is ``u`` in ``[-1/2, 1/2]`` (the origin is the
        segment's midpoint) instead of ``t`` in ``[0, 1]``.
    segments : iterable of int
        The segment indices.

    Returns
    -------
    tuple of list of flint.arb
        ``(origins, widths)``, one ball of each per segment.

    Examples
    --------
    >>> o, w = segment_balls("uniform", sp.Integer(1), sp.Integer(2), 1, False, [1])
    >>> float(o[0].mid()), float(w[0].mid())
    (1.5, 0.5)
    """
    with arb_precision(128):
        origins, widths = [], []
        if segment_by == "uniform":
            n = 2 ** index_bits
            lo_b, hi_b = arb_enclose(lo), arb_enclose(hi)
            w = (hi_b - lo_b) / n
            for s in segments:
                origins.append(lo_b + (hi_b - lo_b) * s / n)
                widths.append(w)
        else:
            per = 2 ** index_bits
            e0 = exact_log2(lo)
            for s in segments:
                e, j = divmod(s, per)
                base = arb(2) ** (e0 + e)
                origins.append(base * (per + j) / per)
                widths.append(base / per)
        if centered:
            origins = [o + w / 2 for o, w in zip(origins, widths)]
        return origins, widths


# -- reading ---------------------------------------------------------------------

_FIELDS = {"kind", "schema", "name", "expression", "variable", "interval", "segment_by",
           "index_bits", "degree", "centered", "fit", "error_kind", "coef_frac_bits",
           "abs_error_bound", "rel_error_bound", "segments", "provenance"}
_SEG_FIELDS = {"integers", "abs_error_bound", "max_abs_error", "rel_error_bound", "max_rel_error"}


def _either(choices) -> str:
    return " or ".join(map(repr, choices))


def _bits(value, field: str, hi: int) -> int:
    return integer(value, field, 0, hi, expected=f"an integer in [0, {hi}]")


def _read_header(d) -> dict[str, Any]:
    """The scalar fields of a piecewise table's JSON object, checked in file order."""
    from chebnorm.core.textsafe import identifier

    if not isinstance(d, dict):
        raise bad("table", "a JSON object", d)
    if d.get("kind") != PIECEWISE_KIND:
        raise bad("kind", repr(PIECEWISE_KIND), d.get("kind"))
    integer(d.get("schema"), "schema", PIECEWISE_SCHEMA, PIECEWISE_SCHEMA,
            expected=str(PIECEWISE_SCHEMA))
    check_object(d, "", _FIELDS, what="table")
    name = identifier(d["name"], field="name")
    expression = text(d["expression"], "expression")
    variable = text(d["variable"], "variable", 64)
    if not variable.isidentifier():
        raise bad("variable", "an identifier", variable)
    iv = array(d["interval"], "interval", "2 strings", length=2)
    return dict(
        name=name, expression=expression, variable=variable,
        interval=(text(iv[0], "interval[0]"), text(iv[1], "interval[1]")),
        segment_by=choice(d["segment_by"], "segment_by", SEGMENT_BY,
                          expected=_either(SEGMENT_BY)),
        index_bits=_bits(d["index_bits"], "index_bits", MAX_INDEX_BITS),
        degree=_bits(d["degree"], "degree", MAX_PIECEWISE_DEGREE),
        centered=boolean(d["centered"], "centered"),
        fit=choice(d["fit"], "fit", PIECEWISE_FITS, expected=_either(PIECEWISE_FITS)),
        error_kind=choice(d["error_kind"], "error_kind", ERROR_KINDS,
                          expected=_either(ERROR_KINDS)),
        coef_frac_bits=_bits(d["coef_frac_bits"], "coef_frac_bits", MAX_COEF_FRAC_BITS))


def _segment_total(h) -> int:
    """How many segments the header ``h`` describes (its expression, interval and,
    for ``"exponent"``, binades checked)."""
    try:
        parse_function(h["expression"], h["variable"])
    except ValueError as exc:
        raise ValueError(f"expression: {exc}") from None
    ends = []
    for i, end in enumerate(h["interval"]):
        try:
            ends.append(parse_number(end))
        except ValueError as exc:
            raise ValueError(f"interval[{i}]: {exc}") from None
    if not arb_enclose(ends[0]) < arb_enclose(ends[1]):
        raise ValueError(f"interval: [{h['interval'][0]}, {h['interval'][1]}] is empty or "
                         f"reversed")
    if h["segment_by"] == "exponent":
        e0, e1 = exact_log2(ends[0]), exact_log2(ends[1])
        if e0 is None or e1 is None or not 1 <= e1 - e0 <= MAX_EXPONENT_SPAN:
            raise bad("interval", "powers of two [2^e0, 2^e1] for segment_by 'exponent'",
                      list(h["interval"]))
    return segment_count(h["segment_by"], ends[0], ends[1], h["index_bits"])


def _read_segment(seg, where: str, degree: int, rel: bool) -> PiecewiseSegment:
    """Segment ``where``: its integers, and its relative claims null unless ``rel``."""
    if not isinstance(seg, dict) or set(seg) != _SEG_FIELDS:
        raise bad(where, f"an object with fields {', '.join(sorted(_SEG_FIELDS))}", seg)
    ints = array(seg["integers"], f"{where}.integers", f"{degree + 1} integers",
                 length=degree + 1)
    top = 2 ** MAX_COEF_INT_BITS - 1
    integers = tuple(integer(q, f"{where}.integers[{j}]", -top, top,
                             expected=f"an integer of magnitude below 2^{MAX_COEF_INT_BITS}")
                     for j, q in enumerate(ints))
    for key in ("rel_error_bound", "max_rel_error"):
        if not rel and seg[key] is not None:
            raise bad(f"{where}.{key}", "null (error_kind is 'abs': the segments "
                      "certify no relative error)", seg[key])
    return PiecewiseSegment(
        integers, number(seg["abs_error_bound"], f"{where}.abs_error_bound", nonneg=True),
        number(seg["max_abs_error"], f"{where}.max_abs_error", nonneg=True),
        number(seg["rel_error_bound"], f"{where}.rel_error_bound", nonneg=True,
               optional=not rel),
        number(seg["max_rel_error"], f"{where}.max_rel_error", nonneg=True, optional=not rel))


def _fields(d) -> dict[str, Any]:
    """The keyword arguments of :class:`PiecewiseTable` from its JSON object, every
    field checked (a refusal names it), the top-level bounds derived from the
    segments' (no certification)."""
    h = _read_header(d)
    count = _segment_total(h)
    segs = d["segments"]
    if not isinstance(segs, list) or len(segs) != count:
        raise bad("segments", f"an array of {count} segments", segs)
    rel = h["error_kind"] == "rel"
    out = tuple(_read_segment(seg, f"segments[{s}]", h["degree"], rel)
                for s, seg in enumerate(segs))
    prov = provenance(d["provenance"])
    return dict(h, segments=out,
                abs_error_bound=_derived(d["abs_error_bound"], "abs", out),
                rel_error_bound=_derived(d["rel_error_bound"], "rel" if rel else None, out),
                provenance=prov)


def _derived(value, kind: str | None, segments) -> float | None:
    """The table's ``{kind}_error_bound``: exactly the largest segment bound
    (null when ``kind`` is None: error_kind 'abs' certifies no relative error)."""
    field_name = f"{kind or 'rel'}_error_bound"
    if kind is None:
        if value is not None:
            raise bad(field_name, "null (error_kind is 'abs': the segments certify no "
                      "relative error)", value)
        return None
    stated = number(value, field_name, nonneg=True)
    top = max(getattr(seg, field_name) for seg in segments)
    if stated != top:
        raise ValueError(f"{field_name}: stated {stated!r} but the largest segment bound is "
                         f"{top!r}; accepted: exactly that (the table's bound is the "
                         f"segments')")
    return stated
