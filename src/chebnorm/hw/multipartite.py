"""Multipartite table-and-add evaluators (de Dinechin and Tisserand,
"Multipartite table methods", IEEE Trans. Computers 54(3), 2005), certified
by an exhaustive proof over every input code.

Architecture
------------
The unsigned ``W``-bit input code ``k`` (``x = lo + (hi - lo) k / 2**W``) is
cut into fields: ``A``, its top ``alpha`` bits, and ``m`` fields ``B_i`` of
``beta_i`` bits at bit positions ``p_i`` below (``B_0`` the lowest). The
output is one sum, truncated once::

    y = (TIV[A] + sum_i TO_i[C_i, B_i]) mod 2**S  >>  g

``TIV`` (table of initial values) holds ``f`` near the centre of ``A``'s
interval; ``TO_i`` (offset tables) hold ``f``'s change over field ``B_i``,
addressed by ``B_i`` and ``C_i``, the top ``gamma_i`` bits of ``A`` (the
slope only varies at that coarser scale). Every entry is an unsigned
integer in units of ``2**-(F + g)`` (``F`` the output's fractional bits,
``g`` guard bits); the output offset and the rounding constant ``2**(g-1)``
are folded into ``TIV``, so the hardware is ROMs and adders only, with no
sign handling. A *symmetric* offset table stores only the half ``B_i >=
2**(beta_i - 1)`` (one address bit less): for the other half the low bits
of ``B_i`` and the entry are complemented (``TO[C, mirror(B)] = 2**W_i - 1 -
TO[C, B]``, the one's-complement trick of the paper), exact by construction.

Tables
------
The real-valued tables are fitted to ``f`` on the grid of every code by
*midrange backfitting* (each table in turn takes the midrange of the
residual over the codes that share its entry -- the minimax choice for that
table alone), which finds the first-order terms of the paper and also the
curvature each field carries alone (Hsiao et al.'s refinement). They are
rounded to integers, then every integer entry is *tuned*: each TIV and TO
entry moves by the step that minimizes the largest final error of the codes
that read it (the codes reading one entry are disjoint from those reading
another entry of the same table, so the maximum never grows). This spends
the exhaustive check's knowledge of the final rounding: a design may pass
with fewer guard bits than the a priori budget asks.

Certification
-------------
``design_multipartite`` returns only a design whose exhaustive error was
proved: ``|y_k - f(x_k)|`` is bounded for every code against Arb
enclosures of ``f(x_k)`` (:mod:`chebnorm.hw.exhaustive`);
:meth:`MultipartiteDesign.budget` also states the a priori decomposition
(method, table rounding, final rounding).

>>> d = design_multipartite("1/sqrt(1+3*x)", ("0", "1"), 10, 10)
>>> d.y_format.frac_bits, d.certificate.upper < 2 ** -10
(10, True)
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from chebnorm.core.numeric import check_int, float_up
from chebnorm.core.textsafe import identifier
from chebnorm.core.display import field_rows, summary_html, summary_repr

from .exhaustive import ExhaustiveCheck, reference
from .fixed import QFormat
from .design_base import Design, register
from .trust import check, check_certificate, drafting, seal

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: the widest input of a multipartite design (the search fits every code)
MAX_MP_IN_BITS = 20
#: the widest output
MAX_MP_OUT_BITS = 32
#: the most offset tables the search tries
MAX_OFFSET_TABLES = 4
#: the a priori method-error estimates of :func:`_structures` (worst slope
#: variation times the field's half range, plus the cross terms) run about
#: twice the error backfitting reaches; they only rank and prune structures
_CALIBRATION = 0.55
#: backfitting rounds and tuning rounds
_FIT_ROUNDS = 12
_TUNE_ROUNDS = 3


@dataclass(frozen=True)
class OffsetTable:
    """One offset table ``TO_i``: field ``B_i`` is ``k[position + field_bits - 1
    : position]``, ``C_i`` the top ``slope_bits`` bits of the input; entries of
    ``width`` bits, index ``C * 2**(address bits of B) + B'`` (``B'`` = ``B``,
    or its low ``field_bits - 1`` bits, complemented when the top bit is 0,
    for a ``symmetric`` table).

    Attributes
    ----------
    position : int
        The lowest input bit of field ``B_i`` (0 .. ``in_bits - field_bits``).
    field_bits : int
        Bits of field ``B_i`` (at least 1; at least 2 when ``symmetric``).
    slope_bits : int
        Bits of ``C_i``, the top input bits that select the slope (0 ..
        ``tiv_bits``).
    symmetric : bool
        Only half the table is stored, the other half read complemented.
    width : int
        Bits per entry (1 .. ``sum_bits`` of the design).
    values : tuple of int
        The ``2**address_bits`` entries, each in ``0 .. 2**width - 1``
        (two's complement, taken modulo ``2**width``).

    Examples
    --------
    >>> t = OffsetTable(0, 3, 1, True, 2, (0, 1, 2, 3, 3, 2, 1, 0))
    >>> t.address_bits, t.rom_bits
    (3, 16)
    """

    position: int
    field_bits: int
    slope_bits: int
    symmetric: bool
    width: int
    values: tuple[int, ...]

    @property
    def address_bits(self) -> int:
        return self.slope_bits + self.field_bits - int(self.symmetric)

    @property
    def rom_bits(self) -> int:
        return 2 ** self.address_bits * self.width

    def lookup(self, k: np.ndarray, in_bits: int) -> np.ndarray:
        """The value this table adds for input codes ``k`` (int64)."""
        b = (k >> self.position) & ((1 << self.field_bits) - 1)
        c = k >> (in_bits - self.slope_bits)
        rom = np.asarray(self.values, dtype=np.int64)
        if not self.symmetric:
            return rom[(c << self.field_bits) | b]
        lb = self.field_bits - 1
        s = b >> lb
        low = b & ((1 << lb) - 1)
        addr = np.where(s == 1, low, ((1 << lb) - 1) ^ low)
        v = rom[(c << lb) | addr]
        return np.where(s == 1, v, ((1 << self.width) - 1) ^ v)


@register("multipartite")
@dataclass(frozen=True, eq=False)
class MultipartiteDesign(Design):
    """A certified multipartite evaluator (see the module docstring).

    ``tiv`` holds ``2**tiv_bits`` entries of ``sum_bits`` bits (the offset and
    the rounding constant folded in, taken modulo ``2**sum_bits``);
    ``certificate`` is the exhaustive proof of ``max |y - f(x)|``; ``parts``
    the a priori error decomposition (floats, rounded up).

    Attributes
    ----------
    name : str
        The module's name without its ``chebnorm_`` prefix (an identifier).
    expression : str
        ``f``, as text.
    variable : str
        The variable of ``expression``.
    interval : tuple of (str, str)
        ``(lo, hi)``: code ``k`` stands for ``lo + (hi - lo) k / 2**in_bits``.
    in_bits : int
        Input code width, 2 .. :data:`MAX_MP_IN_BITS`.
    out_bits : int
        Output code width, 1 .. :data:`MAX_MP_OUT_BITS`.
    y_format : QFormat
        The output's fixed-point format (fraction bits ``F``, offset code).
    guard_bits : int
        Bits below the output LSB carried in the sum and truncated, 0..16.
    tiv_bits : int
        The TIV's address bits (the top input field ``A``), 1 .. ``in_bits - 1``.
    sum_bits : int
        The adder's width, ``guard_bits + 1`` .. 62, with
        ``sum_bits - guard_bits <= out_bits``.
    tiv : tuple of int
        The ``2**tiv_bits`` table-of-initial-values entries, each in
        ``0 .. 2**sum_bits - 1``.
    offsets : tuple of OffsetTable
        The offset tables, whose fields cover the low ``in_bits - tiv_bits``
        input bits exactly, disjoint.
    max_error : float
        The error target met: the smaller of ``2**-F`` (faithful, a strict
        bound) and the requested ``max_error``.
    faithful : bool
        Whether ``|y - f(x)| < 2**-F`` was asked.
    certificate : ExhaustiveCheck
        The exhaustive proof of ``max |y - f(x)|`` over every code.
    parts : dict, default {}
        The a priori error decomposition (:meth:`budget`).

    Raises
    ------
    ValueError
        A hand-built design whose widths are out of range or whose tables do
        not match its fields (on construction).

    Examples
    --------
    >>> d = design_multipartite("1/sqrt(1+3*x)", ("0", "1"), 10, 10)
    >>> d.module_name, d.rom_bits < 2 ** 10 * 10, bool(d.evaluate([0])[0] == d.y_format.max_code
    ...                                                  or d.evaluate([0])[0] > 0)
    ('chebnorm_multipartite', True, True)
    """

    name: str
    expression: str
    variable: str
    interval: tuple[str, str]
    in_bits: int
    out_bits: int
    y_format: QFormat
    guard_bits: int
    tiv_bits: int
    sum_bits: int
    tiv: tuple[int, ...]
    offsets: tuple[OffsetTable, ...]
    max_error: float
    faithful: bool
    certificate: ExhaustiveCheck
    parts: dict = field(default_factory=dict)

    def _summary(self) -> list[tuple[str, object]]:
        return [("name", self.name), ("expression", self.expression),
                ("interval", self.interval), ("in_bits", self.in_bits),
                ("out_bits", self.out_bits), ("split", self.split),
                ("max_error", self.max_error), ("faithful", self.faithful)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    def __post_init__(self):
        _check_design(self)
        self.verify()

    def verify(self) -> "MultipartiteDesign":
        """Re-prove the design; return it unchanged, or raise ValueError.

        The exhaustive proof is recomputed from the design's own tables: the
        certificate's bound must be at least the recomputed one, the target
        ``max_error`` (and, when ``faithful``, one unit of y's last place,
        strictly) met, and the a priori budget not below the proved error.
        Proved once per content (:func:`chebnorm.hw.trust.check`).

        Returns
        -------
        MultipartiteDesign
            ``self``.

        Raises
        ------
        ValueError
            Naming the field that does not hold.
        """
        return check(self, _prove)

    architecture = "multipartite"
    degree = 1   # first-order offsets (the VHDL bench reads it for a latency of 1)

    @property
    def module_name(self) -> str:
        return f"chebnorm_{self.name}"

    @property
    def rom_bits(self) -> int:
        """Total ROM bits: ``2**tiv_bits * sum_bits + sum of the offset tables'``."""
        return 2 ** self.tiv_bits * self.sum_bits + sum(t.rom_bits for t in self.offsets)

    @property
    def split(self) -> str:
        """The field split, e.g. ``A9 | B3(C5,sym) B4(C3)`` (top field first)."""
        parts = [f"A{self.tiv_bits}"] + [
            f"B{t.field_bits}@{t.position}(C{t.slope_bits}{',sym' if t.symmetric else ''},"
            f"W{t.width})" for t in reversed(self.offsets)]
        return " ".join(parts)

    def evaluate(self, codes=None, *, wires: bool = False):
        """Output codes for input ``codes`` (default all ``2**in_bits``), exact
        integer arithmetic; with ``wires`` a dict of the intermediate values."""
        k = _codes(codes, self.in_bits)
        acc = np.asarray(self.tiv, dtype=np.int64)[k >> (self.in_bits - self.tiv_bits)]
        w = {"tiv": acc}
        for i, t in enumerate(self.offsets):
            w[f"to{i}"] = t.lookup(k, self.in_bits)
            acc = acc + w[f"to{i}"]
        w["sum"] = acc & ((1 << self.sum_bits) - 1)
        w["y"] = w["sum"] >> self.guard_bits
        return w if wires else w["y"]

    def measure(self) -> dict:
        """The exhaustive proof, recomputed: rigorous bounds of ``max |y - f(x)|``
        over every code (``upper``, ``lower``, the code ``at``)."""
        ref = reference(self.expression, self.interval, self.in_bits, self.variable)
        y = self.evaluate() + self.y_format.offset_code
        return ref.error_bounds(y, self.y_format.frac_bits)

    def budget(self) -> dict:
        """The error decomposition (floats rounded up): ``method`` (the
        real-valued tables against ``f``, every code), ``table_rounding``
        (largest distance of each integer entry from its real value, summed
        over the tables), ``final_rounding`` (the truncation, half an output
        LSB), their sum ``a_priori``; ``exhaustive`` (the proved maximum),
        ``target`` and ``y_lsb``."""
        lsb = 2.0 ** -self.y_format.frac_bits
        out = dict(self.parts)
        out.update({"exhaustive": self.certificate.upper, "target": self.max_error,
                    "y_lsb": lsb})
        return out

    def verilog(self, *, version: str = "", command: str | None = None) -> str:
        """The Verilog-2005 module (:func:`chebnorm.hw.hdl.tables.table_module`)."""
        from .hdl.tables import table_module
        return table_module(self, "verilog", version=version, command=command)

    def vhdl(self, *, version: str = "", command: str | None = None) -> str:
        """The VHDL-2008 entity (:func:`chebnorm.hw.hdl.tables.table_module`)."""
        from .hdl.tables import table_module
        return table_module(self, "vhdl", version=version, command=command)

    def hdl_files(self, language: str = "verilog") -> dict:
        """Module, bench and vectors (:func:`chebnorm.hw.hdl.tables.table_files`)."""
        from .hdl.tables import table_files
        return table_files(self, language)

    def features(self):
        """The cost model's inputs (:func:`chebnorm.hw.target_model.multipartite_features`)."""
        from .target_model import multipartite_features
        return multipartite_features(self)

    def cut_points(self) -> tuple[str, ...]:
        """``tables`` (after the table reads) and ``offsets`` (after the offsets' sum)."""
        return ("tables", "offsets")

    def cut_plans(self) -> list[tuple[int, ...]]:
        """After the table reads, then both."""
        return [(0,), (0, 1)]

    def with_cuts(self, cuts):
        """A :class:`~chebnorm.hw.pipeline.PipelinedTable` with registers at ``cuts``."""
        from .pipeline import PipelinedTable
        return PipelinedTable(self, cuts)


def _codes(codes, in_bits: int) -> np.ndarray:
    if codes is None:
        return np.arange(2 ** in_bits, dtype=np.int64)
    k = np.asarray(codes)
    if k.dtype.kind not in "iu" or k.size and (k.min() < 0 or k.max() >= 2 ** in_bits):
        raise ValueError(f"codes: accepted: integers 0 <= code < 2**{in_bits}")
    return k.astype(np.int64)


def _check_design(d: MultipartiteDesign) -> None:
    """Refuse a hand-built design whose tables do not match its fields."""
    w = d.in_bits
    check_int(w, "in_bits", 2, MAX_MP_IN_BITS)
    check_int(d.out_bits, "out_bits", 1, MAX_MP_OUT_BITS)
    check_int(d.tiv_bits, "tiv_bits", 1, w - 1)
    check_int(d.guard_bits, "guard_bits", 0, 16)
    check_int(d.sum_bits, "sum_bits", d.guard_bits + 1, 62)
    identifier(d.name, field="name")
    if len(d.tiv) != 2 ** d.tiv_bits or any(not 0 <= int(v) < 2 ** d.sum_bits for v in d.tiv):
        raise ValueError(f"tiv: accepted: {2 ** d.tiv_bits} entries in 0 .. 2**{d.sum_bits} - 1")
    covered = 0
    for t in d.offsets:
        check_int(t.field_bits, "field_bits", 1, w)
        check_int(t.position, "position", 0, w - t.field_bits)
        check_int(t.slope_bits, "slope_bits", 0, d.tiv_bits)
        check_int(t.width, "width", 1, d.sum_bits)
        if t.symmetric and t.field_bits < 2:
            raise ValueError("symmetric: accepted: a field of at least 2 bits")
        if t.address_bits < 1:
            raise ValueError("offset table: accepted: at least one address bit")
        if len(t.values) != 2 ** t.address_bits or any(
                not 0 <= int(v) < 2 ** t.width for v in t.values):
            raise ValueError(f"offset table values: accepted: {2 ** t.address_bits} entries in "
                             f"0 .. 2**{t.width} - 1")
        mask = ((1 << t.field_bits) - 1) << t.position
        if covered & mask:
            raise ValueError("offset tables: accepted: disjoint fields")
        covered |= mask
    if covered != (1 << (w - d.tiv_bits)) - 1:
        raise ValueError(f"offset tables: accepted: fields covering the low "
                         f"{w - d.tiv_bits} bits exactly")
    if d.out_bits < d.sum_bits - d.guard_bits:
        raise ValueError("sum_bits: accepted: sum_bits - guard_bits <= out_bits")


def _prove(d: MultipartiteDesign) -> None:
    """The certificate and the claims re-proved from the tables (ValueError)."""
    from chebnorm.core.numeric import format_up

    _check_design(d)
    yf = d.y_format
    if not isinstance(yf, QFormat) or yf.bits != d.out_bits or yf.signed:
        raise ValueError(f"y_format: accepted: an unsigned QFormat of out_bits = {d.out_bits} bits")
    check_int(yf.frac_bits, "y_format.frac_bits", -60, 60)
    if not isinstance(d.faithful, bool):
        raise ValueError(f"faithful {d.faithful!r}: accepted: True or False")
    ref = reference(d.expression, d.interval, d.in_bits, d.variable)
    proved = ref.error_bounds(d.evaluate() + yf.offset_code, yf.frac_bits)
    check_certificate(d.certificate, proved, 2 ** d.in_bits,
                      f"the multipartite design of {str(d.expression)[:60]}")
    up, lsb = d.certificate.upper, 2.0 ** -yf.frac_bits
    m = d.max_error
    if isinstance(m, bool) or not isinstance(m, (int, float)) or not math.isfinite(m) or m <= 0:
        raise ValueError(f"max_error {m!r}: accepted: a positive finite number")
    if d.faithful and not (up < lsb and m <= lsb):
        raise ValueError(f"faithful: claimed, but the proved error {format_up(up, '.6e')} is not "
                         f"below one unit of y's last place 2^-{yf.frac_bits} (or max_error "
                         f"{m!r} exceeds it); accepted: faithful=False")
    if not up <= m:
        raise ValueError(f"max_error: stated target {m!r}, but the proved error is "
                         f"{format_up(up, '.6e')}; accepted: a target the design meets")
    if not isinstance(d.parts, dict):
        raise ValueError("parts: accepted: a dict of the a priori budget")
    if d.parts:
        keys = ("method", "table_rounding", "final_rounding", "a_priori")
        vals = {k: d.parts.get(k) for k in keys}
        for k, v in vals.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
                    or v < 0:
                raise ValueError(f"parts[{k!r}] {v!r}: accepted: a finite number >= 0")
        if set(d.parts) != set(keys):
            raise ValueError(f"parts: keys {sorted(d.parts)}; accepted: {list(keys)}")
        if vals["a_priori"] < proved["lower"] or any(
                vals[k] > vals["a_priori"] for k in keys[:3]):
            raise ValueError(f"parts['a_priori'] {vals['a_priori']!r}: below a part or the proved "
                             f"error {proved['lower']!r}; accepted: a budget the design's error "
                             f"stays within")


# -- output format ---------------------------------------------------------------------

def output_format(mid: np.ndarray, out_bits: int, frac_bits: int | None = None) -> int:
    """The output's fractional bits: the most for which every value between
    ``floor(min f 2**F)`` and ``ceil(max f 2**F)`` has an ``out_bits``-bit
    code (with an offset), or ``frac_bits`` checked to fit.

    Parameters
    ----------
    mid : numpy.ndarray
        Values of ``f`` (e.g. at every input code), not empty.
    out_bits : int
        The output code width.
    frac_bits : int, optional
        A fraction-bit count to check instead of searching, -60..60.

    Returns
    -------
    int
        ``F`` in -60..60: ``frac_bits`` when given, else the largest that fits.

    Raises
    ------
    ValueError
        ``frac_bits`` out of range or too many for ``out_bits``, or no ``F``
        fits.

    Examples
    --------
    >>> output_format(np.array([0.5, 1.0]), 16)
    16
    """
    lo, hi = float(mid.min()), float(mid.max())

    def fits(f: int) -> bool:
        return math.ceil(hi * 2.0 ** f) - math.floor(lo * 2.0 ** f) <= 2 ** out_bits - 1

    if frac_bits is not None:
        frac_bits = check_int(frac_bits, "out_frac_bits", -60, 60)
        if not fits(frac_bits):
            raise ValueError(f"out_frac_bits = {frac_bits}: f spans [{lo:.6g}, {hi:.6g}], more "
                             f"than {out_bits} bits hold at that LSB; accepted: fewer "
                             f"fractional bits or more out_bits")
        return frac_bits
    for f in range(60, -61, -1):
        if fits(f):
            return f
    raise ValueError("f's range does not fit any output format")


# -- cost model --------------------------------------------------------------------

def table_luts(address_bits: int, width: int) -> int:
    """LUT6 estimate of a ROM on xc7: per output bit one LUT6 up to 6 address
    bits, ``2**(a - 6)`` above (MUXF7/MUXF8 join two and four of them for
    free), plus the LUTs that multiplex the MUXF8 outputs beyond 8 bits (a
    LUT6 is a 4:1 mux).

    Parameters
    ----------
    address_bits : int
        The ROM's address bits, >= 0.
    width : int
        Bits per entry, >= 0.

    Returns
    -------
    int
        The LUT6 count.

    Examples
    --------
    >>> table_luts(6, 10), table_luts(8, 10), table_luts(9, 10), table_luts(10, 1)
    (10, 40, 90, 17)
    """
    if address_bits <= 8:
        return width * (1 if address_bits <= 6 else 2 ** (address_bits - 6))
    return width * (2 ** (address_bits - 6) + math.ceil((2 ** (address_bits - 8) - 1) / 3))


def lut_cost(tiv_bits: int, sum_bits: int, offsets) -> int:
    """LUT6 estimate of a multipartite design: its ROMs (:func:`table_luts`),
    the address complements of symmetric tables, and the adders (one LUT a
    bit: the offsets summed first, then the TIV's full-width add).

    ``offsets``: ``(address_bits, width, field_bits, symmetric)`` per table.

    Parameters
    ----------
    tiv_bits : int
        The TIV's address bits.
    sum_bits : int
        The TIV's entry width (the final adder's width).
    offsets : iterable of (int, int, int, bool)
        ``(address_bits, width, field_bits, symmetric)`` per offset table.

    Returns
    -------
    int
        The LUT6 estimate.

    Examples
    --------
    >>> lut_cost(8, 18, [(6, 8, 4, False)])
    98
    """
    cost = table_luts(tiv_bits, sum_bits)
    widths = []
    for a, wd, fb, sym in offsets:
        cost += table_luts(a, wd) + ((fb - 1) if sym else 0)
        widths.append(wd)
    widths.sort()
    acc = 0
    for wd in widths[1:]:   # sum the offsets, narrowest first
        acc = max(acc, wd) + 1
        cost += acc
    return cost + (sum_bits if widths else 0)


# -- the search ----------------------------------------------------------------------

@dataclass
class _Problem:
    w: int
    out_bits: int
    F: int
    z: np.ndarray          # f(x_k) * 2**F (float64)
    limit: float           # the error target in output LSBs
    strict: bool
    slope: np.ndarray      # dz/du on the grid (u = k / 2**w)
    curv: float            # max |d2z/du2|


def _problem(ref, out_bits: int, F: int, limit: float, strict: bool) -> _Problem:
    w = ref.in_bits
    z = ref.mid * 2.0 ** F
    n = z.size
    d = np.diff(z) * n
    slope = np.concatenate([d, d[-1:]])
    curv = float(np.abs(np.diff(d)).max() * n) if n > 2 else 0.0
    return _Problem(w, out_bits, F, z, limit, strict, slope, curv)


def _fields(beta: int, m: int):
    """Compositions of ``beta`` into ``m`` positive field widths (LSB first)."""
    for cuts in itertools.combinations(range(1, beta), m - 1):
        bounds = (0, *cuts, beta)
        yield tuple(bounds[i + 1] - bounds[i] for i in range(m))


def _slope_ranges(p: _Problem, alpha: int) -> list[float]:
    """Half the range of the slope over each ``C`` interval of ``gamma`` bits
    (the worst interval), for gamma = 0 .. alpha."""
    return [float(np.ptp(p.slope.reshape(2 ** g, -1), axis=1).max() / 2) for g in range(alpha + 1)]


def _structures(p: _Problem, symmetric, max_tables: int):
    """Candidate (alpha, fields, gammas, syms, guard) with estimated error
    within reach of the target, ranked by estimated LUT cost."""
    out = []
    zmax = float(np.abs(p.slope).max())
    for alpha in range(1, p.w):
        beta = p.w - alpha
        ranges = _slope_ranges(p, alpha)
        for m in range(1, min(max_tables, beta) + 1):
            for bits in _fields(beta, m):
                pos = np.cumsum((0,) + bits[:-1])
                half = [(2 ** b - 1) / 2 * 2.0 ** (q - p.w) for b, q in zip(bits, pos)]
                cross = p.curv * sum(half[i] * half[j] for i in range(m) for j in range(i + 1, m))
                if cross > p.limit:
                    continue
                sym_opts = [symmetric] if symmetric is not None else [False, True]
                per_field = []
                for i in range(m):
                    opts = []
                    for sym in sym_opts:
                        if sym and bits[i] < 2:
                            continue
                        quad = p.curv * half[i] ** 2 / 4 if sym else 0.0
                        for g in range(alpha + 1):
                            e = ranges[g] * half[i] + quad
                            if e <= p.limit and g + bits[i] - int(sym) >= 1:
                                opts.append((g, sym, e))
                    # keep, per symmetry, the few cheapest slope widths
                    opts = [o for o in opts if o[0] <= min(
                        (q[0] for q in opts if q[1] == o[1]), default=0) + 3]
                    per_field.append(opts)
                if any(not o for o in per_field):
                    continue
                for combo in itertools.product(*per_field):
                    err = _CALIBRATION * (cross + sum(c[2] for c in combo))
                    if err + 0.5 > p.limit:
                        continue
                    offs = []
                    for i, (g, sym, _) in enumerate(combo):
                        span = 2 * zmax * half[i] * 2 + 2     # one guard bit
                        offs.append((g + bits[i] - int(sym), max(1, math.ceil(math.log2(span))),
                                     bits[i], sym))
                    cost = lut_cost(alpha, p.out_bits + 1, offs)
                    out.append((cost, alpha, bits, tuple(c[0] for c in combo),
                                tuple(c[1] for c in combo), err))
    out.sort(key=lambda c: (c[0], c[5]))
    return out


def _backfit(p: _Problem, alpha: int, bits, gammas, syms):
    """Real-valued tables (output LSB units) by midrange backfitting.

    The residual ``z - TIV - sum TO_i`` is kept on the grid of every code
    and updated by each table's change (one pass over the codes per table
    update, not one per table)."""
    m = len(bits)
    shape_b = tuple(2 ** b for b in reversed(bits))      # B_{m-1} .. B_0 axes
    tiv = np.zeros(2 ** alpha)
    offs = [np.zeros((2 ** g, 2 ** b)) for g, b in zip(gammas, bits)]
    # the residual, shaped (2**g, 2**(alpha - g)) + shape_b for every g at no cost
    res = np.array(p.z, dtype=np.float64).reshape((2 ** alpha,) + shape_b)

    def grid(i, values):
        """Table ``i``'s ``(2**g, 2**b)`` values broadcast onto the residual's axes."""
        g, b = gammas[i], bits[i]
        return values.reshape((2 ** g, 1) + tuple(
            2 ** b if j == i else 1 for j in reversed(range(m))))

    def fit_tiv():
        r = res.reshape(2 ** alpha, -1)
        delta = (r.max(axis=1) + r.min(axis=1)) / 2
        tiv[:] += delta
        r -= delta[:, None]

    best = None
    for _ in range(_FIT_ROUNDS):
        fit_tiv()
        for i in range(m):
            g, b = gammas[i], bits[i]
            r = res.reshape((2 ** g, 2 ** (alpha - g)) + shape_b)
            axes = (1,) + tuple(2 + j for j in range(m) if m - 1 - j != i)
            mr = (r.max(axis=axes) + r.min(axis=axes)) / 2        # (2**g, 2**b)
            old = offs[i].copy()
            if syms[i]:
                h = 2 ** (b - 1)
                delta = (mr[:, h:] - mr[:, h - 1::-1]) / 2
                offs[i][:, h:] += delta
                offs[i][:, :h] = -offs[i][:, h:][:, ::-1]
            else:
                offs[i] += mr
            r -= grid(i, offs[i] - old)
        fit_tiv()
        e = float(np.abs(res).max())
        if best is None or e < best[0] - 1e-12:
            best = (e, tiv.copy(), [o.copy() for o in offs])
        elif e >= best[0]:
            break
    return best


def _build(p: _Problem, alpha, bits, gammas, syms, guard, fitted):
    """Integer tables for one structure (``fitted``: its :func:`_backfit`),
    tuned on the exact final error; the float64 max error (output LSB
    units), the tables and the budget parts."""
    method, tiv_r, offs_r = fitted
    if method >= p.limit:
        return None
    scale = 2.0 ** guard
    w, m = p.w, len(bits)
    pos = np.cumsum((0,) + tuple(bits[:-1]))
    k = np.arange(2 ** w, dtype=np.int64)
    ints, widths, reals, shift = [], [], [], 0.0
    for i in range(m):
        o = offs_r[i] * scale
        if syms[i]:
            h = 2 ** (bits[i] - 1)
            up = o[:, h:]
            wd = max(1, math.ceil(math.log2(2 * float(np.abs(up).max()) + 2)))
            bias = (2 ** wd - 1) / 2
            real = up + bias
            shift -= bias
        else:
            bias = float(o.min())
            real = o - bias
            wd = max(1, math.ceil(math.log2(float(real.max()) + 1.5)))
            shift += bias
        ints.append(np.clip(np.rint(real), 0, 2 ** wd - 1).astype(np.int64).reshape(-1))
        widths.append(wd)
        reals.append(real.reshape(-1))
    tiv_real = tiv_r * scale + shift + (scale / 2 if guard else 0.0)
    tiv = np.rint(tiv_real).astype(np.int64)
    tabs = [_Table(int(pos[i]), bits[i], gammas[i], syms[i], widths[i], w) for i in range(m)]
    looks = [t.address(k) for t in tabs]
    err, y, tiv = _tune(p, alpha, guard, tiv, ints, widths, looks)
    dev_tiv = float(np.abs(tiv - tiv_real).max())
    if err >= p.limit or (p.strict is False and err > p.limit):
        return None
    ymin = int(y.min())
    if int(y.max()) - ymin > 2 ** p.out_bits - 1:
        return None
    tiv = tiv - (ymin << guard)
    total = tiv[k >> (w - alpha)] + sum(
        np.where(s, ints[i][a], (2 ** widths[i] - 1) - ints[i][a]) for i, (a, s) in enumerate(looks))
    sum_bits = max(guard + 1, int(total.max()).bit_length())
    if total.min() < 0 or sum_bits - guard > p.out_bits:
        return None
    tiv = tiv & ((1 << sum_bits) - 1)
    dev = [float(np.abs(ints[i] - reals[i]).max()) for i in range(m)]
    parts = {"method": method, "table_rounding": (sum(dev) + dev_tiv) / scale,
             "final_rounding": 0.5 if guard else 0.0}
    return err, ymin, tiv, ints, widths, tabs, sum_bits, parts


@dataclass
class _Table:
    position: int
    bits: int
    gamma: int
    sym: bool
    width: int
    w: int

    def address(self, k):
        """(address into the stored half, True where the entry is taken as is)."""
        b = (k >> self.position) & ((1 << self.bits) - 1)
        c = k >> (self.w - self.gamma)
        if not self.sym:
            return (c << self.bits) | b, np.ones(k.shape, dtype=bool)
        lb = self.bits - 1
        s = (b >> lb) == 1
        low = b & ((1 << lb) - 1)
        return (c << lb) | np.where(s, low, ((1 << lb) - 1) ^ low), s


def _tune(p: _Problem, alpha: int, guard: int, tiv, ints, widths, looks):
    """Move each integer entry by the step minimizing the largest error of the
    codes that read it; TIV first, then each offset table, a few rounds.
    (Exact integer sums: the offsets' sum is updated table by table.)"""
    w = p.w
    a_idx = np.arange(2 ** w, dtype=np.int64) >> (w - alpha)
    z = p.z
    # every entry is read by equally many codes: group them by sorting once
    orders = [np.argsort(a, kind="stable") for a, _ in looks]
    zs_all = [z[o] for o in orders]
    signs = [np.where(s, 1, -1)[o] for (_, s), o in zip(looks, orders)]

    def part(i):
        a, s = looks[i]
        return np.where(s, ints[i][a], (2 ** widths[i] - 1) - ints[i][a])

    parts = [part(i) for i in range(len(looks))]
    osum = sum(parts) if parts else np.zeros(2 ** w, dtype=np.int64)

    def errors(total):
        return np.abs((total >> guard) - z)

    span = 2 ** guard + 1
    for _ in range(_TUNE_ROUNDS):
        base = tiv[a_idx] + osum
        best_e = errors(base).reshape(2 ** alpha, -1).max(axis=1)
        best_d = np.zeros(2 ** alpha, dtype=np.int64)
        for d in range(-span, span + 1):
            if d == 0:
                continue
            e = errors(base + d).reshape(2 ** alpha, -1).max(axis=1)
            better = e < best_e - 1e-12
            best_e = np.where(better, e, best_e)
            best_d = np.where(better, d, best_d)
        tiv = tiv + best_d
        tiv_k = tiv[a_idx]
        for i in range(len(looks)):
            n = ints[i].size
            order, zs, sign = orders[i], zs_all[i], signs[i]
            tot = (tiv_k + osum)[order]
            cur = np.abs((tot >> guard) - zs).reshape(n, -1).max(axis=1)
            bd = np.zeros(n, dtype=np.int64)
            for d in (-2, -1, 1, 2):
                e = np.abs(((tot + d * sign) >> guard) - zs).reshape(n, -1).max(axis=1)
                ok = (ints[i] + d >= 0) & (ints[i] + d <= 2 ** widths[i] - 1)
                better = ok & (e < cur - 1e-12)
                cur = np.where(better, e, cur)
                bd = np.where(better, d, bd)
            ints[i] = ints[i] + bd
            new = part(i)
            osum = osum - parts[i] + new
            parts[i] = new
    total = tiv[a_idx] + osum
    y = total >> guard
    return float(np.abs(y - z).max()), y, tiv


def design_multipartite(expr, interval, in_bits: int, out_bits: int, *, max_error=None,
                        faithful: bool = True, var: str = "x", name: str = "multipartite",
                        out_frac_bits: int | None = None, symmetric: bool | None = None,
                        max_tables: int = MAX_OFFSET_TABLES, tries: int = 30,
                        select=None, count: int = 6) -> MultipartiteDesign:
    """The cheapest multipartite evaluator of ``expr`` on ``interval`` meeting
    the error target, proved over every input code.

    Parameters
    ----------
    expr, interval, var
        The function (text, read by :func:`chebnorm.approx.parse_function`)
        and its rational interval ``(lo, hi)``: code ``k`` of ``in_bits``
        bits stands for ``lo + (hi - lo) k / 2**in_bits``. ``var`` defaults
        to ``"x"``.
    in_bits, out_bits
        Input and output code widths (``2 <= in_bits <= 20``,
        ``1 <= out_bits <= 32``). The output
        LSB is ``2**-F`` with the largest ``F`` for which ``f``'s range has
        ``out_bits``-bit codes (with an offset), or ``out_frac_bits``.
    max_error, faithful
        ``faithful`` (default True): ``|y - f(x)| < 2**-F`` for every code;
        ``max_error`` (a positive finite number, default None):
        ``|y - f(x)| <= max_error``; both: the smaller. ``faithful=False``
        needs ``max_error``.
    name : str, default "multipartite"
        The module's name (an identifier; the module is ``chebnorm_<name>``).
    out_frac_bits : int, optional
        ``F`` fixed (-60..60, checked to fit ``out_bits``) instead of the largest.
    symmetric
        Offset tables stored halved (True), whole (False) or either (None,
        the default).
    max_tables, tries
        At most ``max_tables`` offset tables (1..4, default 4); up to
        ``tries`` structures (1..10000, default 30) are built and checked,
        cheapest estimate first.
    select, count
        ``select``: a function of a design returning its cost (e.g. LUTs
        from a synthesis run); it is called on the ``count`` certified
        candidates of least estimated cost (:func:`multipartite_candidates`)
        and the cheapest is returned. Default: the least estimate
        (:func:`lut_cost`). ``count``: 1..1000, default 6.

    Returns
    -------
    MultipartiteDesign
        With its exhaustive certificate.

    Raises
    ------
    ValueError
        An argument out of range (named), or no structure meets the target.

    See Also
    --------
    chebnorm.hw.plain_table.design_plain_table : one table of every output.
    chebnorm.hw.piecewise.design_piecewise : ROM of coefficients and a Horner datapath.
    chebnorm.hw.exhaustive : the exhaustive proof over every code.

    Notes
    -----
    The input code is cut into fields :math:`A` and :math:`B_i`; the
    output is one truncated sum of table lookups [1]_,

    .. math::

        y = \\left\\lfloor \\frac{\\left(\\mathrm{TIV}[A] + \\sum_i
            \\mathrm{TO}_i[C_i, B_i]\\right) \\bmod 2^{S}}{2^{g}} \\right\\rfloor,

    :math:`C_i` the top bits of :math:`A` (module docstring). The design
    returned is proved over every input code against Arb enclosures of
    :math:`f` (``certificate``).

    References
    ----------
    .. [1] F. de Dinechin, A. Tisserand, "Multipartite table methods", IEEE
       Transactions on Computers 54(3), 2005.

    Examples
    --------
    >>> d = design_multipartite("1/sqrt(1+3*x)", ("0", "1"), 10, 10)
    >>> d.certificate.upper < 2.0 ** -d.y_format.frac_bits, len(d.evaluate())
    (True, 1024)
    """
    found = multipartite_candidates(expr, interval, in_bits, out_bits, max_error=max_error,
                                    faithful=faithful, var=var, name=name,
                                    out_frac_bits=out_frac_bits, symmetric=symmetric,
                                    max_tables=max_tables, tries=tries,
                                    count=count if select is not None else 1)
    if select is None:
        return found[0]
    return min(found, key=lambda d: (select(d), _design_luts(d)))


def multipartite_candidates(expr, interval, in_bits: int, out_bits: int, *, max_error=None,
                            faithful: bool = True, var: str = "x", name: str = "multipartite",
                            out_frac_bits: int | None = None, symmetric: bool | None = None,
                            max_tables: int = MAX_OFFSET_TABLES, tries: int = 30,
                            count: int = 6) -> list[MultipartiteDesign]:
    """Up to ``count`` certified multipartite designs (arguments as
    :func:`design_multipartite`), least estimated LUT count first -- for a
    caller that prices each by synthesis (the estimate ranks them only
    roughly: yosys's ABC compresses some tables more than others).

    Parameters
    ----------
    expr, interval, in_bits, out_bits, max_error, faithful, var, name, out_frac_bits
        As in :func:`design_multipartite`.
    symmetric, max_tables, tries
        As in :func:`design_multipartite`.
    count : int, default 6
        The most designs returned, 1..1000.

    Returns
    -------
    list of MultipartiteDesign
        At least one, each with its exhaustive certificate, least estimated
        LUT count (:func:`lut_cost`) first, then fewest ROM bits.

    Raises
    ------
    ValueError
        An argument out of range (named), or no structure meets the target.

    Examples
    --------
    >>> ds = multipartite_candidates("1/sqrt(1+3*x)", ("0", "1"), 10, 10, count=2)
    >>> len(ds) >= 1 and all(d.certificate.upper < 2.0 ** -10 for d in ds)
    True
    """
    in_bits = check_int(in_bits, "in_bits", 2, MAX_MP_IN_BITS)
    out_bits = check_int(out_bits, "out_bits", 1, MAX_MP_OUT_BITS)
    max_tables = check_int(max_tables, "max_tables", 1, MAX_OFFSET_TABLES)
    tries = check_int(tries, "tries", 1, 10_000)
    count = check_int(count, "count", 1, 1000)
    name = identifier(name, field="name")
    if symmetric not in (None, True, False):
        raise ValueError("symmetric: accepted: None, True or False")
    if not faithful and max_error is None:
        raise ValueError("max_error: accepted: a positive number when faithful is False")
    ref = reference(expr, interval, in_bits, var)
    F = output_format(ref.mid, out_bits, out_frac_bits)
    limit, strict = _target(F, max_error, faithful)
    p = _problem(ref, out_bits, F, limit, strict)
    found = []
    for cand in _structures(p, symmetric, max_tables)[:tries]:
        _, alpha, bits, gammas, syms, _ = cand
        if found and cand[0] > 1.15 * found[0][0]:
            break   # ranked by estimate: the rest will not do better
        fitted = _backfit(p, alpha, bits, gammas, syms)
        if fitted[0] + 0.5 >= p.limit:
            continue
        for guard in range(1, 6):
            built = _build(p, alpha, bits, gammas, syms, guard, fitted)
            if built is None:
                continue
            d = _assemble(ref, p, name, str(expr), var, interval, out_bits, alpha, guard,
                          built, limit, strict, max_error, faithful)
            if d is not None:
                found.append((_design_luts(d), d.rom_bits, len(found), d))
                found.sort(key=lambda t: t[:3])
                break
    if not found:
        raise ValueError(f"no multipartite design of {in_bits} input bits meets the target "
                         f"{limit * 2.0 ** -F:.4e} at output LSB 2^-{F}; accepted: a larger "
                         f"max_error, fewer out_bits or more tries")
    return [t[3] for t in found[:count]]


def _target(F: int, max_error, faithful: bool):
    """The error limit in output LSBs and whether it is strict."""
    limits = []
    if faithful:
        limits.append((1.0, True))
    if max_error is not None:
        try:
            e = float(max_error)
        except (TypeError, ValueError):
            raise ValueError(f"max_error {max_error!r} is not a number; accepted: a positive "
                             f"number") from None
        if not (e > 0 and math.isfinite(e)):
            raise ValueError(f"max_error = {max_error!r}; accepted: a positive finite number")
        limits.append((e * 2.0 ** F, False))
    return min(limits)


def _design_luts(d: MultipartiteDesign) -> int:
    return lut_cost(d.tiv_bits, d.sum_bits, [(t.address_bits, t.width, t.field_bits, t.symmetric)
                                             for t in d.offsets])


def _assemble(ref, p, name, expr, var, interval, out_bits, alpha, guard, built, limit, strict,
              max_error, faithful):
    """The design of one built structure, or None when the proof fails."""
    err, ymin, tiv, ints, widths, tabs, sum_bits, parts = built
    offsets = tuple(OffsetTable(t.position, t.bits, t.gamma, t.sym, widths[i],
                                tuple(int(v) for v in ints[i])) for i, t in enumerate(tabs))
    F = p.F
    yf = QFormat(out_bits, F, offset_code=ymin)
    lsb = 2.0 ** -F
    target = float(limit * lsb)
    with drafting():
        proto = MultipartiteDesign(name, expr, var, (str(interval[0]), str(interval[1])), p.w,
                                   out_bits, yf, guard, alpha, sum_bits,
                                   tuple(int(v) for v in tiv), offsets, target, faithful,
                                   ExhaustiveCheck(math.inf, 0.0, 0, 0))
    proof = ExhaustiveCheck.of(ref.error_bounds(proto.evaluate() + ymin, F))
    if proof.upper > target or (strict and proof.upper >= target):
        return None
    total = {k: float_up(v * lsb) for k, v in parts.items()}
    total["a_priori"] = float_up(sum(v * lsb for v in parts.values()))
    with drafting():
        d = MultipartiteDesign(name, expr, var, proto.interval, p.w, out_bits, yf, guard, alpha,
                               sum_bits, proto.tiv, offsets, target, faithful, proof, total)
    return seal(d)
