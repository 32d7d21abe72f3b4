"""Piecewise polynomial tables: fit, quantize and certify one polynomial per segment.

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
stated bound, as :class:`chebnorm.approx.CoefficientTable` does.

>>> t = fit_piecewise("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
>>> t.segment_count, t.degree, t.abs_error_bound < 2e-2
(4, 1, True)
>>> [str(e) for e in t.segment_bounds(0)]
['1', '7/4']
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np
import sympy as sp

from flint import arb

from chebnorm.core.numeric import arb_precision, check_int, signed_bits

from .certify import arb_enclose, certify
from .certify_batch import SegmentError, certify_batch
from .expr import Function1D, parse_function, parse_number
from .fitting import cheb_to_monomial, remez
from .table import _construction, _establish, _sealed, check_maximum, parse_json

__all__ = [
    "MAX_COEF_FRAC_BITS",
    "MAX_INDEX_BITS",
    "MAX_PIECEWISE_DEGREE",
    "PIECEWISE_KIND",
    "PIECEWISE_SCHEMA",
    "SEGMENT_BY",
    "PiecewiseSegment",
    "PiecewiseTable",
    "fit_piecewise",
    "is_piecewise_file",
    "parse_segments",
]

PIECEWISE_KIND = "chebnorm.piecewise_table"
PIECEWISE_SCHEMA = 1
#: at most 2**12 segments (a ROM of 4096 words)
MAX_INDEX_BITS = 12
MAX_PIECEWISE_DEGREE = 8
#: coefficients are integers / 2**F; |integer| < 2**52 keeps them exact doubles
MAX_COEF_FRAC_BITS = 48
MAX_COEF_INT_BITS = 52
SEGMENT_BY = ("uniform", "exponent")
FITS = ("minimax", "chebyshev")
ERRORS = ("abs", "rel")
MAX_EXPONENT_SPAN = 64
MAX_PIECEWISE_BYTES = 8 << 20
_DENSE = 257


@dataclass(frozen=True)
class PiecewiseSegment:
    """One segment: integer coefficients and the certified claims about them."""

    integers: tuple[int, ...]
    abs_error_bound: float
    max_abs_error: float
    rel_error_bound: float | None = None
    max_rel_error: float | None = None


@dataclass(frozen=True)
class PiecewiseTable:
    """The piecewise-table contract (see the module docstring)."""

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

    def __post_init__(self) -> None:
        """Check every field and re-prove every claim (see :meth:`verify`): a table
        built by hand or by ``dataclasses.replace`` is verified as a file is."""
        _establish(self, _own_fields, _prove)

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
        return _exact_log2(self.lo), _exact_log2(self.hi)

    @property
    def local_range(self) -> tuple[Fraction, Fraction]:
        """Range of the local variable: ``[0, 1]`` or ``[-1/2, 1/2]`` (centred)."""
        return (Fraction(-1, 2), Fraction(1, 2)) if self.centered else (Fraction(0), Fraction(1))

    def segment_bounds(self, s: int) -> tuple[sp.Expr, sp.Expr]:
        """Exact endpoints ``(a_s, b_s)`` of segment ``s``."""
        return _segment_bounds(self.segment_by, self.lo, self.hi, self.index_bits, s)

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
        x = np.asarray(x, dtype=float)
        lo_f, hi_f = float(self.lo), float(self.hi)
        if self.segment_by == "uniform":
            n = self.segment_count
            pos = (x - lo_f) / (hi_f - lo_f) * n
            s = np.clip(np.floor(pos), 0, n - 1).astype(int)
            t = pos - s
        else:
            m, e = np.frexp(x)
            e0 = int(math.log2(lo_f))
            per = 2 ** self.index_bits
            scaled = (2 * m - 1) * per
            j = np.clip(np.floor(scaled), 0, per - 1).astype(int)
            s = np.clip((e - 1 - e0) * per + j, 0, self.segment_count - 1)
            t = scaled - j
        if self.centered:
            t = t - 0.5
        coeffs = np.array([self.coefficients(i) for i in range(self.segment_count)])
        acc = coeffs[s, self.degree]
        for j in range(self.degree - 1, -1, -1):
            acc = acc * t + coeffs[s, j]
        return acc

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

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True, indent=1, allow_nan=False) + "\n"

    def save(self, path) -> None:
        """Write the JSON atomically."""
        from chebnorm.core.files import write_atomic

        write_atomic(path, self.to_json())

    @classmethod
    def from_dict(cls, d: Any) -> PiecewiseTable:
        """Read a table: every field checked, then every bound re-certified."""
        return cls(**_fields(d))

    @classmethod
    def from_json(cls, text: str) -> PiecewiseTable:
        """Parse strict JSON (a key given twice is refused) and read it with :meth:`from_dict`."""
        return cls.from_dict(parse_json(text, "piecewise table"))

    @classmethod
    def load(cls, path) -> PiecewiseTable:
        """Read and verify the table in ``path``; refusals start with the file name."""
        try:
            with open(path, "rb") as fh:
                raw = fh.read(MAX_PIECEWISE_BYTES + 1)
        except OSError as exc:
            raise ValueError(f"cannot read piecewise table {str(path)!r}: {exc.strerror}") from None
        if len(raw) > MAX_PIECEWISE_BYTES:
            raise ValueError(f"piecewise table {str(path)!r} is larger than "
                             f"{MAX_PIECEWISE_BYTES} bytes")
        try:
            return cls.from_json(raw.decode("utf-8"))
        except UnicodeDecodeError as exc:
            raise ValueError(f"piecewise table {str(path)!r} is not UTF-8 text (byte "
                             f"{exc.start})") from None
        except ValueError as exc:
            raise ValueError(f"piecewise table {str(path)!r}: {exc}") from None

    def verify(self) -> PiecewiseTable:
        """Re-certify every segment's stated bounds and the table's maxima; return self or raise.

        >>> t = fit_piecewise("x**3", ("0", "1"), 1, segments=2, coef_frac_bits=12)
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
        if not _sealed(self):
            _establish(self, _own_fields, _prove, mode="prove")
        return self


def _own_fields(cls, d) -> dict[str, Any]:
    """:func:`_fields` of a constructed table's fields (``d`` lacks the file's kind
    and schema)."""
    if isinstance(d, dict):
        d = {"kind": PIECEWISE_KIND, "schema": PIECEWISE_SCHEMA, **d}
    return _fields(d)


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
                                 f"{certs[s].bound:.2e}")
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



def _exact_log2(value: sp.Expr) -> int | None:
    """``e`` when ``value == 2**e`` exactly, else None."""
    r = sp.nsimplify(value) if not value.is_Rational else value
    if not r.is_Rational or r <= 0:
        return None
    p, q = int(r.p), int(r.q)
    if p & (p - 1) == 0 and q == 1:
        return p.bit_length() - 1
    if p == 1 and q & (q - 1) == 0:
        return -(q.bit_length() - 1)
    return None


def _segment_bounds(segment_by, lo, hi, index_bits, s):
    if segment_by == "uniform":
        n = 2 ** index_bits
        h = (hi - lo) / n
        return (lo + s * h, lo + (s + 1) * h)
    per = 2 ** index_bits
    e0 = _exact_log2(lo)
    e, j = divmod(s, per)
    base = sp.Integer(2) ** (e0 + e)
    return (base * (1 + sp.Rational(j, per)), base * (1 + sp.Rational(j + 1, per)))


def _segment_count(segment_by, lo, hi, index_bits) -> int:
    if segment_by == "uniform":
        return 2 ** index_bits
    return (_exact_log2(hi) - _exact_log2(lo)) * 2 ** index_bits


class _LocalFunction:
    """``t -> f(a + (b - a) t)`` (``t + 1/2`` when centred) in float64, for
    fitting and quantizing (certification composes in Arb, see
    :func:`_segment_balls`)."""

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


def parse_segments(text) -> int:
    """``"2^k"``, ``"2**k"`` or a power of two ``N`` -> ``k`` (index bits).

    >>> parse_segments("2^8"), parse_segments("16"), parse_segments(1)
    (8, 4, 0)
    """
    s = str(text).strip().replace("**", "^")
    try:
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

    >>> t = fit_piecewise("x**3", ("0", "1"), 1, segments=2, coef_frac_bits=12)
    >>> [c.bound <= s.abs_error_bound for c, s in zip(certify_segments(t), t.segments)]
    [True, True]
    """
    fn = parse_function(table.expression, table.variable)
    idx = list(range(table.segment_count)) if segments is None else [int(s) for s in segments]
    origins, widths = _segment_balls(table.segment_by, table.lo, table.hi, table.index_bits,
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


def _segment_balls(segment_by, lo, hi, index_bits, centered, segments):
    """Arb balls ``(o_s, w_s)`` with segment ``s`` = ``o_s + w_s t``, ``t`` in
    the local range (128 bits; exact for binary ends), without sympy per segment."""
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
            e0 = _exact_log2(lo)
            for s in segments:
                e, j = divmod(s, per)
                base = arb(2) ** (e0 + e)
                origins.append(base * (per + j) / per)
                widths.append(base / per)
        if centered:
            origins = [o + w / 2 for o, w in zip(origins, widths)]
        return origins, widths


def is_piecewise_file(path) -> bool:
    """True when the JSON file ``path`` declares ``kind`` = :data:`PIECEWISE_KIND`
    (so a consumer reads it with :meth:`PiecewiseTable.load`)."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_PIECEWISE_BYTES + 1)
        d = json.loads(raw.decode("utf-8"))
    except (OSError, ValueError, RecursionError):
        return False
    return isinstance(d, dict) and d.get("kind") == PIECEWISE_KIND


# -- fitting -------------------------------------------------------------------



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
    e0, e1 = _exact_log2(lo), _exact_log2(hi)
    if e0 is None or e1 is None:
        raise ValueError(f"segment-by exponent needs an interval [2^e0, 2^e1] of powers of "
                         f"two, got [{lo}, {hi}]; accepted: e.g. --interval 1/4 4")
    if not 1 <= e1 - e0 <= MAX_EXPONENT_SPAN:
        raise ValueError(f"segment-by exponent: {e1 - e0} binades; accepted: 1 to "
                         f"{MAX_EXPONENT_SPAN}")
    if (e1 - e0) * 2 ** index_bits > 2 ** MAX_INDEX_BITS:
        raise ValueError(f"segment-by exponent: {e1 - e0} binades x 2^{index_bits} = "
                         f"{(e1 - e0) * 2 ** index_bits} segments; accepted: at most "
                         f"2^{MAX_INDEX_BITS}")


def fit_piecewise(expr, interval, degree: int, *, segments=1, segment_by: str = "uniform",
                  coef_frac_bits: int = 24, centered: bool = False, fit: str = "minimax",
                  error: str = "abs", var: str = "x", name: str = "table",
                  command: str | None = None, progress=None) -> PiecewiseTable:
    """Fit, quantize and certify a piecewise polynomial table (module docstring).

    ``segments``: ``2**k`` (an int or ``"2^k"``) -- the whole interval's
    count for ``segment_by="uniform"``, the count per binade for
    ``"exponent"`` (then ``interval`` must be ``[2**e0, 2**e1]``).
    ``coef_frac_bits``: the common fixed-point format of all coefficients.
    ``progress``: optional callable run once per fitted segment (the
    certification of all segments together follows).

    >>> t = fit_piecewise("1/sqrt(x)", ("1/4", "4"), 2, segments=2, segment_by="exponent",
    ...                   coef_frac_bits=20, error="rel")
    >>> t.segment_count, t.rel_error_bound < 1e-3
    (8, True)
    """
    from chebnorm.core.textsafe import identifier

    name = identifier(name, field="name")
    index_bits = parse_segments(segments)
    degree = check_int(degree, "degree", 0, MAX_PIECEWISE_DEGREE)
    frac_bits = check_int(coef_frac_bits, "coef-frac-bits", 0, MAX_COEF_FRAC_BITS)
    if segment_by not in SEGMENT_BY:
        raise ValueError(f"segment-by {segment_by!r} is unknown; accepted: {', '.join(SEGMENT_BY)}")
    if fit not in FITS:
        raise ValueError(f"fit kind {fit!r} is unknown; accepted: {', '.join(FITS)}")
    if error not in ERRORS:
        raise ValueError(f"error kind {error!r} is unknown; accepted: {', '.join(ERRORS)}")
    if not isinstance(centered, bool):
        raise ValueError(f"centered {centered!r} is not a boolean")
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
    count = _segment_count(segment_by, lo, hi, index_bits)
    loc = (-0.5, 0.5) if centered else (0.0, 1.0)
    limit = 2 ** MAX_COEF_INT_BITS
    ints_all, bad_seg = [], None
    for s in range(count):
        a, b = _segment_bounds(segment_by, lo, hi, index_bits, s)
        g = _local_function(fn, a, b, centered=centered)
        with np.errstate(all="ignore"):
            try:
                probe = g.numpy(np.linspace(*loc, 65))
            except (ZeroDivisionError, OverflowError, TypeError):
                probe = np.array([np.nan])
        if not np.all(np.isfinite(probe)) or (error == "rel" and np.any(probe == 0)):
            bad_seg = s
            break
        with np.errstate(all="ignore"):
            coeffs = _fit_segment(g, degree, *loc, fit, error)
        big = max(abs(c) for c in coeffs)
        if big * 2.0 ** frac_bits >= limit:
            max_f = max(0, math.floor(math.log2(limit / big)) - 1)
            raise ValueError(f"coef-frac-bits {frac_bits} overflows the {MAX_COEF_INT_BITS}-bit "
                             f"coefficient integers (segment {s}: |c| = {big:.6g}); accepted: "
                             f"coef-frac-bits <= {max_f}")
        with np.errstate(all="ignore"):
            ints_all.append(_quantize_segment(g, coeffs, frac_bits, *loc, error))
        if progress is not None:
            progress()
    # the segments fitted so far, certified together; the first segment that
    # fails (or that the probe refused) is reported
    out, failed = _certify_fitted(fn, ints_all, frac_bits, error,
                                  _segment_balls(segment_by, lo, hi, index_bits, centered,
                                                 range(len(ints_all))), loc)
    if failed is not None and (bad_seg is None or failed < bad_seg):
        bad_seg = failed
    if bad_seg is not None:
        s = bad_seg
        a, b = _segment_bounds(segment_by, lo, hi, index_bits, s)
        what = "finite, real and nonzero" if error == "rel" else "finite and real"
        raise ValueError(f"{fn.expr} is not {what} on segment {s} = [{a}, {b}] of "
                         f"[{lo}, {hi}]; accepted: an interval where the function is {what}")
    from .api import _versions

    prov = dict(_versions())
    prov["command"] = command or (f"chebnorm.approx.fit_piecewise({str(fn.expr)!r}, "
                                  f"({sp.sstr(lo)!r}, {sp.sstr(hi)!r}), {degree}, "
                                  f"segments={2 ** index_bits}, segment_by={segment_by!r}, "
                                  f"coef_frac_bits={frac_bits}, centered={centered})")
    with _construction("fitted"):  # certified above: checked, not proved twice
        return PiecewiseTable(
            name=name, expression=sp.sstr(fn.expr), variable=fn.var.name,
            interval=(sp.sstr(lo), sp.sstr(hi)), segment_by=segment_by, index_bits=index_bits,
            degree=degree, centered=centered, fit=fit, error_kind=error,
            coef_frac_bits=frac_bits, segments=tuple(out),
            abs_error_bound=max(sg.abs_error_bound for sg in out),
            rel_error_bound=max(sg.rel_error_bound for sg in out) if error == "rel" else None,
            provenance=prov)


# -- reading ---------------------------------------------------------------------

_FIELDS = {"kind", "schema", "name", "expression", "variable", "interval", "segment_by",
           "index_bits", "degree", "centered", "fit", "error_kind", "coef_frac_bits",
           "abs_error_bound", "rel_error_bound", "segments", "provenance"}
_SEG_FIELDS = {"integers", "abs_error_bound", "max_abs_error", "rel_error_bound", "max_rel_error"}


def _bad(fieldname: str, expected: str, value) -> ValueError:
    shown = repr(value)
    shown = shown if len(shown) <= 60 else shown[:57] + "..."
    return ValueError(f"{fieldname}: expected {expected}, got {shown}")


def _num(value, fieldname: str, *, optional: bool = False) -> float | None:
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or value < 0:
        raise _bad(fieldname, "a finite number >= 0", value)
    return float(value)


def _int(value, fieldname: str, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
        raise _bad(fieldname, f"an integer in [{lo}, {hi}]", value)
    return value


def _str(value, fieldname: str, max_length: int = 1000) -> str:
    if not isinstance(value, str) or not value or len(value) > max_length:
        raise _bad(fieldname, f"a non-empty string of at most {max_length} characters", value)
    return value


def _fields(d) -> dict[str, Any]:
    """The keyword arguments of :class:`PiecewiseTable` from its JSON object, every
    field checked (a refusal names it), the top-level bounds derived from the
    segments' (no certification)."""
    from chebnorm.core import textsafe

    if not isinstance(d, dict):
        raise _bad("table", "a JSON object", d)
    if d.get("kind") != PIECEWISE_KIND:
        raise _bad("kind", repr(PIECEWISE_KIND), d.get("kind"))
    if d.get("schema") != PIECEWISE_SCHEMA:
        raise _bad("schema", str(PIECEWISE_SCHEMA), d.get("schema"))
    missing = sorted(_FIELDS - set(d))
    extra = sorted(set(d) - _FIELDS)
    if missing:
        raise ValueError(f"{missing[0]}: missing field")
    if extra:
        raise ValueError(f"{extra[0]}: unknown field; accepted: {', '.join(sorted(_FIELDS))}")
    name = textsafe.identifier(_str(d["name"], "name", 64), field="name")
    expression = _str(d["expression"], "expression")
    variable = _str(d["variable"], "variable", 64)
    if not variable.isidentifier():
        raise _bad("variable", "an identifier", variable)
    iv = d["interval"]
    if not isinstance(iv, list) or len(iv) != 2:
        raise _bad("interval", "an array of 2 strings", iv)
    interval = (_str(iv[0], "interval[0]"), _str(iv[1], "interval[1]"))
    segment_by = d["segment_by"]
    if segment_by not in SEGMENT_BY:
        raise _bad("segment_by", " or ".join(map(repr, SEGMENT_BY)), segment_by)
    index_bits = _int(d["index_bits"], "index_bits", 0, MAX_INDEX_BITS)
    degree = _int(d["degree"], "degree", 0, MAX_PIECEWISE_DEGREE)
    if not isinstance(d["centered"], bool):
        raise _bad("centered", "true or false", d["centered"])
    if d["fit"] not in FITS:
        raise _bad("fit", " or ".join(map(repr, FITS)), d["fit"])
    if d["error_kind"] not in ERRORS:
        raise _bad("error_kind", " or ".join(map(repr, ERRORS)), d["error_kind"])
    frac_bits = _int(d["coef_frac_bits"], "coef_frac_bits", 0, MAX_COEF_FRAC_BITS)
    try:
        fn = parse_function(expression, variable)
        del fn
    except ValueError as exc:
        raise ValueError(f"expression: {exc}") from None
    ends = []
    for i, text in enumerate(interval):
        try:
            ends.append(parse_number(text))
        except ValueError as exc:
            raise ValueError(f"interval[{i}]: {exc}") from None
    if not arb_enclose(ends[0]) < arb_enclose(ends[1]):
        raise ValueError(f"interval: [{interval[0]}, {interval[1]}] is empty or reversed")
    if segment_by == "exponent":
        e0, e1 = _exact_log2(ends[0]), _exact_log2(ends[1])
        if e0 is None or e1 is None or not 1 <= e1 - e0 <= MAX_EXPONENT_SPAN:
            raise _bad("interval", "powers of two [2^e0, 2^e1] for segment_by 'exponent'", iv)
    count = _segment_count(segment_by, ends[0], ends[1], index_bits)
    segs = d["segments"]
    if not isinstance(segs, list) or len(segs) != count:
        raise _bad("segments", f"an array of {count} segments", segs)
    out, rel = [], d["error_kind"] == "rel"
    for s, seg in enumerate(segs):
        where = f"segments[{s}]"
        if not isinstance(seg, dict) or set(seg) != _SEG_FIELDS:
            raise _bad(where, f"an object with fields {', '.join(sorted(_SEG_FIELDS))}", seg)
        ints = seg["integers"]
        if not isinstance(ints, list) or len(ints) != degree + 1:
            raise _bad(f"{where}.integers", f"an array of {degree + 1} integers", ints)
        for j, q in enumerate(ints):
            if isinstance(q, bool) or not isinstance(q, int) or abs(q) >= 2 ** MAX_COEF_INT_BITS:
                raise _bad(f"{where}.integers[{j}]",
                           f"an integer of magnitude below 2^{MAX_COEF_INT_BITS}", q)
        for key in ("rel_error_bound", "max_rel_error"):
            if not rel and seg[key] is not None:
                raise _bad(f"{where}.{key}", "null (error_kind is 'abs': the segments "
                           "certify no relative error)", seg[key])
        out.append(PiecewiseSegment(
            tuple(ints), _num(seg["abs_error_bound"], f"{where}.abs_error_bound"),
            _num(seg["max_abs_error"], f"{where}.max_abs_error"),
            _num(seg["rel_error_bound"], f"{where}.rel_error_bound", optional=not rel),
            _num(seg["max_rel_error"], f"{where}.max_rel_error", optional=not rel)))
    prov = d["provenance"]
    if not isinstance(prov, dict) or len(prov) > 32 or not all(
            isinstance(k, str) and isinstance(v, str) and len(k) <= 64 and len(v) <= 1000
            for k, v in prov.items()):
        raise _bad("provenance", "an object of at most 32 short strings", prov)
    return dict(
        name=name, expression=expression, variable=variable, interval=interval,
        segment_by=segment_by, index_bits=index_bits, degree=degree, centered=d["centered"],
        fit=d["fit"], error_kind=d["error_kind"], coef_frac_bits=frac_bits, segments=tuple(out),
        abs_error_bound=_derived(d["abs_error_bound"], "abs", out),
        rel_error_bound=_derived(d["rel_error_bound"], "rel" if rel else None, out),
        provenance=dict(prov))


def _derived(value, kind: str | None, segments) -> float | None:
    """The table's ``{kind}_error_bound``: exactly the largest segment bound
    (null when ``kind`` is None: error_kind 'abs' certifies no relative error)."""
    field_name = f"{kind or 'rel'}_error_bound"
    if kind is None:
        if value is not None:
            raise _bad(field_name, "null (error_kind is 'abs': the segments certify no "
                       "relative error)", value)
        return None
    stated = _num(value, field_name)
    top = max(getattr(seg, field_name) for seg in segments)
    if stated != top:
        raise ValueError(f"{field_name}: stated {stated!r} but the largest segment bound is "
                         f"{top!r}; accepted: exactly that (the table's bound is the "
                         f"segments')")
    return stated
