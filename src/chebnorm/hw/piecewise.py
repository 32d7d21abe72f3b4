"""Hardware of a uniform piecewise table: a coefficient ROM and one shared Horner datapath.

The input is an unsigned ``W``-bit code ``k`` standing for
``x = lo + (hi - lo) * k / 2**W`` (so ``[lo, hi)`` is covered exactly, as in
FloPoCo's ``FixFunctionByPiecewisePoly``). With ``2**K`` segments the top
``K`` bits of ``k`` address the ROM, the low ``L = W - K`` bits are the local
variable ``t = low / 2**L`` in ``[0, 1)`` (``t - 1/2`` when the table is
centred): exactly the variable each segment's polynomial was certified in.
An exponent table (``2**m`` segments per binade of ``[lo, hi)``, both powers
of two) is indexed the same way, so its code stands for ``x = lo * 2**e *
(1 + u / 2**(L + m))`` with ``e`` the code's top bits and ``u`` the rest
(:meth:`PiecewiseDesign.x_values`; the banner states it).
The datapath, for coefficients ``q_j`` (``Fc`` fractional bits) read from
the ROM::

    a_n = q_n
    a_j = R_Fa(a_{j+1} * t + q_j),        j = n-1 .. 1
    y   = sat(R_Fy(a_1 * t + q_0) - Oy)

each multiply-add exact, then one rounding (round to nearest even); every wire
is sized from its exact range over all ``2**W`` codes. The error of ``y``
against ``f(x)`` is bounded by the table's certified bound plus
``sum_{j=1}^{n-1} 2**-(Fa+1) |t|_max^j`` plus ``2**-(Fy+1)`` (a rounding of
``a_j`` reaches the output multiplied by ``t^j``); :meth:`PiecewiseDesign.measure`
compares it, code by code and in 40-digit arithmetic, with ``f``.

The *sized* architecture (``design_piecewise(..., widths="auto" | {...})``)
gives every ROM column its own fractional bits ``F_j`` (the
coefficients re-rounded from the table's ``Fc``), multiplies step ``j`` by
the top ``T_j`` bits of ``t`` only, and truncates (floors) products and sums
to ``G_j`` fractional bits -- with ``multipliers="truncated"`` the
partial-product columns below the kept ones are never formed. No rounding
adder anywhere: each segment's ROM coefficients are chosen to centre that
segment's error interval (the truncations' bias is paid in the ROM).
:func:`sized_bound` certifies it per segment in exact integer interval
arithmetic; ``widths="auto"`` lowers the widths greedily while the certified
total meets ``max_error`` (default: faithful). ``pipeline=`` puts registers
after the ROM and after chosen multiply-adds (``latency`` cycles, one result
per cycle); Verilog and VHDL of every variant are bit-identical to
:meth:`PiecewiseDesign.evaluate`. ``widths=None`` (the default) keeps the
one-width design and its outputs unchanged.

>>> from chebnorm.approx.piecewise_fit import piecewise_fit
>>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
>>> d = design_piecewise(t, 8, 8)
>>> d.y_format.frac_bits, d.budget()["total"] >= d.measure()["max_error"]
(9, True)
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import NamedTuple

import mpmath
import numpy as np

from chebnorm.approx.expr import parse_function, parse_number
from chebnorm.approx.piecewise_table import PiecewiseTable
from chebnorm.core.numeric import float_up, format_up
from chebnorm.core.textsafe import identifier
from chebnorm.core.display import field_rows, summary_html, summary_repr

from .fixed import (
    QFormat,
    check_int64,
    check_width,
    rounding_error_bound,
    shift_round,
    signed_bits,
)
from .hdl import hdl_files, module_text, testbench_text
from .design_base import Design, register
from .trust import check, drafting, seal
from .run_verilog import simulate, synthesize_text
from ._docfrag import hw_doc

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: the widest input code of a piecewise design (the model evaluates every code)
MAX_PW_IN_BITS = 20
#: the widest output code of a piecewise design
MAX_PW_OUT_BITS = 32
#: the one-width design's rounding after each Horner step: round to nearest, ties to even
ROUNDING = "rne"


@register("piecewise", "piecewise-sized")
@dataclass(frozen=True)
class PiecewiseDesign(Design):
    """A sized ROM + Horner evaluator of a uniform :class:`PiecewiseTable`.

    Built by :func:`design_piecewise`; two architectures share the class: the
    one-width design (one ROM width for every coefficient, an exact product
    and a rounding to nearest after each step) and the *sized* one (a width
    per coefficient, ``t`` and products truncated: ``sized`` is True).

    Attributes
    ----------
    name : str
        The module's name without its ``chebnorm_`` prefix (an identifier).
    table : PiecewiseTable
        The uniform (or ``2**m``-segment exponent) table evaluated.
    in_bits : int
        Input code width, ``index_bits + 1`` .. :data:`MAX_PW_IN_BITS`.
    out_bits : int
        Output code width, 1 .. :data:`MAX_PW_OUT_BITS`.
    local_bits : int
        ``L = in_bits - index_bits``: the low input bits, the local variable ``t``.
    acc_frac_bits : int
        One-width design: fractional bits of the accumulators (y's plus the
        guard bits).
    y_format : QFormat
        The output's format: ``out_bits`` bits, fraction bits ``Fy``, offset code.
    rom_bits : tuple of int
        Bits of each ROM column ``j = 0..n``.
    t_bits : int
        Width of ``t`` as multiplied (one-width: ``L + 2``, sign included;
        sized: ``max(T_j) + 1``).
    widths : tuple of (int, int, int)
        Per Horner step ``j = n-1 .. 0``: the widths of its product, sum and
        output.
    top_frac_bits : int
        Fractional bits of the exact top accumulator (one-width design).
    rounding : str, default "rne"
        The one-width design's rounding after each step (:data:`ROUNDING`).
    coef_frac : tuple of int, default ()
        Sized: ``F_j``, fractional bits of ROM column ``j = 0..n`` (empty: one-width).
    t_keep : tuple of int, default ()
        Sized: ``T_j``, the top bits of ``t`` step ``j`` multiplies by.
    acc_frac : tuple of int, default ()
        Sized: ``G_j``, fractional bits of accumulator ``a_j`` (``G_0`` is y's).
    coefficients : tuple of tuple of int, default ()
        Sized: per segment the ROM integers ``c_j`` (value ``c_j / 2**F_j``),
        chosen by :func:`sized_bound`.
    cuts : tuple of int, default ()
        Pipeline registers: ``0`` after the ROM read, ``i`` after step ``i``.
    mult_cuts : tuple of int, default ()
        Registers between the multiply and the add of step ``i``.
    multipliers : str, default "full"
        ``"full"`` or ``"truncated"`` (partial-product columns below ``P_j``
        dropped).
    prod_frac : tuple of int, default ()
        Sized: ``P_j``, fractional bits kept of product ``j`` (empty: the default of
        :func:`sized_steps`).
    q_bits : tuple of int, default ()
        Sized, per step ``j = n-1 .. 0``: width of the truncated product.
    bound : tuple of Fraction, default ()
        Sized: the exact certified ``(approximation, datapath, total)``
        bounds (:func:`sized_bound`).

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8)
    >>> d.index_bits, d.local_bits, d.module_name
    (2, 6, 'chebnorm_rs')
    >>> [float(x) for x in d.x_values([0, 255])]
    [1.0, 3.98828125]
    >>> y = [float(d.y_format.value(c)) for c in d.evaluate([0, 255])]
    >>> [round(v, 3) for v in y]   # 1/sqrt(x), degree 1 on 4 segments: 1e-2 off
    [0.986, 0.5]
    >>> abs(y[0] - 1) <= d.budget()["total"], abs(y[1] - 3.98828125 ** -0.5) <= d.budget()["total"]
    (True, True)
    """

    name: str
    table: PiecewiseTable
    in_bits: int
    out_bits: int
    local_bits: int
    acc_frac_bits: int
    y_format: QFormat
    rom_bits: tuple[int, ...]
    t_bits: int
    widths: tuple[tuple[int, int, int], ...]   # per step j=n-1..0: (product, sum, out)
    top_frac_bits: int
    rounding: str = ROUNDING
    # the sized architecture (empty: one width for every coefficient, RNE after each step)
    coef_frac: tuple[int, ...] = ()      # F_j, j = 0..n: fractional bits of ROM column j
    t_keep: tuple[int, ...] = ()         # T_j, j = 0..n-1: top bits of t step j multiplies by
    acc_frac: tuple[int, ...] = ()       # G_j, j = 0..n: fractional bits of a_j (G_0 = y's)
    coefficients: tuple[tuple[int, ...], ...] = ()   # per segment, c_j / 2^F_j
    cuts: tuple[int, ...] = ()           # pipeline registers: 0 after the ROM, i after step i
    mult_cuts: tuple[int, ...] = ()      # registers between the multiply and the add of step i
    multipliers: str = "full"            # "truncated": partial-product columns below P dropped
    prod_frac: tuple[int, ...] = ()      # P_j, j = 0..n-1: fractional bits kept of product j
    q_bits: tuple[int, ...] = ()         # per step j = n-1..0: width of the truncated product
    bound: tuple[Fraction, Fraction, Fraction] = ()  # (approximation, datapath, total)

    def _summary(self) -> list[tuple[str, object]]:
        return [("name", self.name), ("segments", self.table.segment_count),
                ("degree", self.degree), ("in_bits", self.in_bits), ("out_bits", self.out_bits),
                ("latency", self.latency), ("multipliers", self.multipliers)] + (
                    [("total_bound", float(self.bound[2]))] if self.bound else [])

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    def __post_init__(self):
        self.verify()

    def verify(self) -> "PiecewiseDesign":
        """Re-prove the design; return it unchanged, or raise ValueError.

        The table is re-verified, then the datapath is sized again from the
        table and the design's own widths (:func:`design_piecewise`'s rules;
        the sized architecture's ROM and certified bound by
        :func:`sized_bound`): every field must be what that gives (a ROM
        coefficient, a wire width, the output format or the bound changed
        alone is refused). Proved once per content
        (:func:`chebnorm.hw.trust.check`): called again after a change behind
        the frozen dataclass's back, it proves again.

        Returns
        -------
        PiecewiseDesign
            ``self``.

        Raises
        ------
        ValueError
            Naming the field that does not hold.
        """
        return check(self, _prove)

    @property
    def module_name(self) -> str:
        return f"chebnorm_{self.name}"

    @property
    def degree(self) -> int:
        return self.table.degree

    @property
    def architecture(self) -> str:
        """``"piecewise-sized"`` for the sized architecture, else ``"piecewise"``."""
        return "piecewise-sized" if self.sized else "piecewise"

    # -- the Design interface ----------------------------------------------------
    def features(self):
        """The cost model's inputs (:func:`chebnorm.hw.target_model.piecewise_features`)."""
        from .target_model import piecewise_features

        return piecewise_features(self)

    def cut_points(self) -> tuple[str, ...]:
        """``rom`` (after the ROM read), then ``mulI`` and ``addI`` (after the
        ``I``-th multiply and add), for the sized and the one-width datapath."""
        return ("rom",) + tuple(f"{op}{i}" for i in range(1, self.degree + 1)
                                for op in ("mul", "add"))

    def cut_plans(self) -> list[tuple[int, ...]]:
        """Per latency ``1, 2, ...`` the cut set whose heaviest stage (by
        :data:`chebnorm.hw.pipeline.STAGE_WEIGHTS`) is the lightest, ties to the
        earliest cuts."""
        from itertools import combinations

        from .pipeline import STAGE_WEIGHTS

        n = self.degree
        # stage k sits before position k: the ROM, a multiply and an add per step, the output
        weights = ([STAGE_WEIGHTS["rom"]] + [STAGE_WEIGHTS["mul"], STAGE_WEIGHTS["add"]] * n
                   + [STAGE_WEIGHTS["output"]])

        def worst(cuts) -> float:
            edges = [0, *[c + 1 for c in cuts], len(weights)]
            return max(sum(weights[a:b]) for a, b in zip(edges, edges[1:]))

        return [min(combinations(range(2 * n + 1), m), key=lambda c: (worst(c), c))
                for m in range(1, 2 * n + 2)]

    def with_cuts(self, cuts) -> "PiecewiseDesign":
        """Registers at positions ``cuts`` (0 after the ROM, ``2i - 1`` after the
        ``i``-th multiply, ``2i`` after the ``i``-th add): ``cuts`` and ``mult_cuts``."""
        cuts = tuple(sorted(set(cuts)))
        top = 2 * self.degree
        if any(isinstance(c, bool) or not isinstance(c, int) or not 0 <= c <= top for c in cuts):
            raise ValueError(f"cuts {list(cuts)[:8]}: accepted: integers 0..{top} (0 after the "
                             f"ROM, 2i-1 after the i-th multiply, 2i after the i-th add)")
        return replace(self, cuts=tuple(c // 2 for c in cuts if c % 2 == 0),
                       mult_cuts=tuple((c + 1) // 2 for c in cuts if c % 2 == 1))

    def combinational(self) -> "PiecewiseDesign":
        """The design without its pipeline registers."""
        return replace(self, cuts=(), mult_cuts=())

    def verilog(self, *, version: str = "", command: str | None = None) -> str:
        """The Verilog-2005 module (:func:`chebnorm.hw.hdl.module_text`)."""
        return module_text(self, "verilog", version=version, command=command)

    def vhdl(self, *, version: str = "", command: str | None = None) -> str:
        """The VHDL-2008 entity (:func:`chebnorm.hw.hdl.module_text`)."""
        return module_text(self, "vhdl", version=version, command=command)

    def hdl_files(self, language: str = "verilog") -> dict:
        """Module, bench and vectors (:func:`chebnorm.hw.hdl.hdl_files`)."""
        return hdl_files(self, language)

    @property
    def sized(self) -> bool:
        """True for the sized architecture (a width per coefficient, truncated steps)."""
        return bool(self.coef_frac)

    @property
    def latency(self) -> int:
        """Clock cycles from ``x`` to ``y``: the number of pipeline registers (0: combinational)."""
        return len(self.cuts) + len(self.mult_cuts)

    @property
    def index_bits(self) -> int:
        """The ROM address bits: ``log2`` of the segment count (a uniform table's
        ``index_bits``; an exponent table's binade bits plus its bits per binade)."""
        return (self.table.segment_count - 1).bit_length()

    def sized_signals(self) -> list[dict]:
        """The sized datapath's steps ``j = n-1 .. 0`` for the HDL printers:
        :func:`sized_steps`' shifts plus the widths of ``t_j`` (``tw``),
        ``p_j``, ``q_j``, ``s_j`` and ``a_j`` (``pw``, ``qw``, ``sw``, ``aw``)."""
        out = []
        for st, (pw, sw, ow) in zip(sized_steps(_shape(self)), self.widths):
            T = self.t_keep[st["j"]]
            ps = st["pshift"]
            qw = self.q_bits[len(out)] if self.q_bits else (
                max(pw - ps, 2) if ps >= 0 else pw - ps)
            out.append(dict(st, T=T, tw=T if self.table.centered else T + 1, pw=pw, qw=qw,
                            sw=sw, aw=ow))
        return out

    def _rom(self, dtype=np.int64) -> np.ndarray:
        if self.sized:
            return np.array(self.coefficients, dtype=dtype)
        return np.array([seg.integers for seg in self.table.segments], dtype=dtype)

    def _t(self, k: np.ndarray) -> np.ndarray:
        low = k & ((1 << self.local_bits) - 1)
        return low - (1 << (self.local_bits - 1)) if self.table.centered else low

    def evaluate(self, codes=None, *, wires: bool = False):
        """Output codes for input ``codes`` (default: all ``2**in_bits``)."""
        k = np.arange(2 ** self.in_bits, dtype=np.int64) if codes is None \
            else np.asarray(codes, dtype=np.int64)
        if self.sized:
            w = _run_sized(self._rom(k.dtype), k, _shape(self))
        else:
            w = _run(self, k, self.acc_frac_bits, self.y_format.frac_bits)
        raw = w["rounded"] - self.y_format.offset_code
        w["raw"] = raw
        w["y"] = np.clip(raw, 0, self.y_format.max_code)
        return w if wires else w["y"]

    def x_values(self, codes) -> list[Fraction]:
        """Exact ``x`` of each code: segment ``s = k >> L`` of the table, ``x = a_s
        + (b_s - a_s) * low / 2^L`` (uniform: ``lo + (hi - lo) * k / 2^in_bits``)."""
        L = self.local_bits
        ends = {}
        out = []
        for c in codes:
            s = int(c) >> L
            if s not in ends:
                ends[s] = tuple(Fraction(int(e.p), int(e.q)) for e in self.table.segment_bounds(s))
            a, b = ends[s]
            out.append(a + (b - a) * Fraction(int(c) & ((1 << L) - 1), 2 ** L))
        return out

    def budget(self) -> dict:
        """Certified bound of ``|y - f(x)|`` over all codes, by part (floats rounded up).

        The sized architecture's bound is per segment (:func:`sized_bound`):
        ``total`` is the largest over the segments of the segment's certified
        approximation bound plus its datapath bound (coefficient re-rounding,
        truncated ``t``, truncated products and sums, the output truncation);
        ``datapath`` the largest datapath bound; ``output_rounding`` is
        ``2^-(Fy+1)`` and ``horner_rounding`` the rest of ``datapath``, so
        that the parts add up to at least ``total``.
        """
        if self.sized:
            approx, path, total = self.bound
            out = Fraction(2) ** -(self.y_format.frac_bits + 1)
            return {"approximation": float_up(approx),
                    "horner_rounding": float_up(max(path - out, Fraction(0))),
                    "output_rounding": float_up(out), "datapath": float_up(path),
                    "total": float_up(total),
                    "y_lsb": float(Fraction(2) ** -self.y_format.frac_bits)}
        tmax = Fraction(1, 2) if self.table.centered else Fraction(1)
        fa = self.acc_frac_bits
        steps = [rounding_error_bound(fa, self.rounding) * tmax ** j
                 for j in range(1, self.degree)]
        out = rounding_error_bound(self.y_format.frac_bits, self.rounding)
        approx = Fraction(self.table.abs_error_bound)
        total = approx + sum(steps, Fraction(0)) + out
        return {"approximation": self.table.abs_error_bound,
                "horner_rounding": float_up(sum(steps, Fraction(0))), "output_rounding": float_up(out),
                "total": float_up(total), "y_lsb": float(Fraction(2) ** -self.y_format.frac_bits)}

    def measure(self, codes=None) -> dict:
        """Exact ``max |y - f(x)|`` over ``codes`` (default all), f at 40 digits."""
        k = np.arange(2 ** self.in_bits) if codes is None else np.asarray(codes)
        y = self.evaluate(k)
        fn = parse_function(self.table.expression, self.table.variable)
        f = fn.mpmath
        yf = self.y_format
        worst, at = mpmath.mpf(0), 0
        with mpmath.workdps(40):
            for code, x, yc in zip(k, self.x_values(k), y):
                v = mpmath.mpf(yf.offset_code + int(yc)) / 2 ** yf.frac_bits
                e = abs(v - f(mpmath.mpf(x.numerator) / x.denominator))
                if e > worst:
                    worst, at = e, int(code)
        return {"max_error": float(worst), "at_code": at, "codes": len(k),
                "saturated": int(((self.evaluate(k, wires=True)["raw"] < 0)
                                  | (self.evaluate(k, wires=True)["raw"] > yf.max_code)).sum())}


def _exact(text: str) -> Fraction:
    v = parse_number(text)
    if not v.is_Rational:
        raise ValueError(f"interval endpoint {text!r} is not rational; accepted for hardware: "
                         f"a rational endpoint (the input code maps onto [lo, hi) exactly)")
    return Fraction(int(v.p), int(v.q))


def _int64_fits(d, fa, fy) -> bool:
    """Whether :func:`_run` at ``fa``/``fy`` stays exact in int64 for every code:
    the same operations on magnitude bounds (Python integers: ``|t| <= 2^L``,
    ``|v >> s| <= |v| >> s``, a rounding adds 1), every value and every
    ``2^shift`` of a rounding below ``2^62``, every rounding shift below 62
    (numpy's ``>>`` floors like Python's at any shift; ``<<`` would wrap)."""
    limit = 1 << 62
    cols = [max(abs(int(v)) for v in col) for col in zip(*(seg.integers
                                                           for seg in d.table.segments))]
    fc, n, L = d.table.coef_frac_bits, d.table.degree, d.local_bits
    tmax = 1 << L
    acc, accf = cols[n], fc
    bounds = [acc, tmax]
    for j in range(n - 1, -1, -1):
        prod = acc * tmax
        pf = accf + L
        sf = max(pf, fc)
        total = (prod << (sf - pf)) + (cols[j] << (sf - fc))
        bounds += [prod, total]
        if j > 0:
            f_out = min(fa, sf)
            sh = sf - f_out
            if sh >= 62:
                return False
            acc, accf = (total >> sh) + 1, f_out
            bounds += [acc, total + (1 << sh)]
        else:
            acc, accf = total, sf
    shift = accf - fy
    if shift >= 62:
        return False
    bounds.append((acc >> shift) + 1 + (1 << max(shift, 0)) if shift >= 0 else acc << -shift)
    return max(bounds) < limit


def _run(d, k, fa, fy) -> dict:
    """The one-width datapath's wires for codes ``k`` at ``fa`` accumulator and
    ``fy`` output fractional bits; an object array of ``k`` is run in int64
    instead whenever :func:`_int64_fits` proves it exact (the same integers)."""
    if k.dtype == object and _int64_fits(d, fa, fy):
        k = k.astype(np.int64)
    rom = d._rom(k.dtype)
    s = (k >> d.local_bits).astype(np.int64)
    t = d._t(k)
    fc = d.table.coef_frac_bits
    n = d.table.degree
    acc, accf = rom[s, n], fc
    w = {"t": t, "s": s}
    for j in range(n - 1, -1, -1):
        prod = acc * t
        pf = accf + d.local_bits
        sf = max(pf, fc)
        total = (prod << (sf - pf)) + (rom[s, j] << (sf - fc))
        w[f"p{j}"], w[f"s{j}"] = prod, total
        if j > 0:
            f_out = min(fa, sf)
            acc = shift_round(total, sf - f_out, ROUNDING)
            accf = f_out
            w[f"a{j}"] = acc
        else:
            acc, accf = total, sf
    if n == 0:
        acc = rom[s, 0]
    w["top"], w["top_frac"] = acc, accf
    shift = accf - fy
    w["rounded"] = shift_round(acc, shift, ROUNDING) if shift >= 0 else acc << -shift
    return w


# -- the sized architecture: a width per coefficient, truncated Horner steps ---------

class _Shape(NamedTuple):
    """The sized datapath's widths: local bits ``L``, degree ``n``, centred
    ``t``, and ``F`` (per ROM column), ``T`` (per step), ``G`` (per accumulator)."""

    L: int
    n: int
    centered: bool
    F: tuple[int, ...]
    T: tuple[int, ...]
    G: tuple[int, ...]
    truncated: bool = False   # truncated multipliers: partial-product columns dropped
    P: tuple[int, ...] = ()   # per step j: fractional bits kept of the product (default X)


def _shape(d: PiecewiseDesign) -> _Shape:
    return _Shape(d.local_bits, d.degree, d.table.centered, d.coef_frac, d.t_keep, d.acc_frac,
                  d.multipliers == "truncated", d.prod_frac)


def sized_steps(shape) -> list[dict]:
    """The shifts of each step ``j = n-1 .. 0`` of the sized datapath::

        t_j = low >> tshift (- 2^(T_j - 1) when centred)   T_j fractional bits
        p_j = a_{j+1} * t_j                                 pf = G_{j+1} + T_j
        q_j = p_j >> pshift  (<< -pshift when negative)     P_j
        s_j = (q_j << qshift) + (c_j << cshift)             X = max(P_j, F_j, G_j)
        a_j = s_j >> ashift                                  G_j

    every right shift a floor (drops bits, no rounding adder); the bias is
    paid for in the coefficients (:func:`sized_bound` centres each segment's
    error). ``P_j`` defaults to ``max(G_j, F_j)``.

    Parameters
    ----------
    shape : tuple
        The datapath's widths ``(L, n, centered, F, T, G[, truncated, P])``:
        local bits, degree, centred ``t``, and the tuples ``F`` (``n + 1``
        columns), ``T`` (``n`` steps), ``G`` (``n + 1`` accumulators),
        whether the multipliers are truncated and ``P`` (``n`` steps; empty
        or absent: the default).

    Returns
    -------
    list of dict
        One dict per step ``j = n-1 .. 0`` with the keys ``j``, ``tshift``,
        ``pf``, ``P``, ``X``, ``pshift``, ``qshift``, ``cshift``, ``ashift``
        (ints) and ``rows``: for a truncated multiplier the partial-product
        rows ``(i, shift, negated)`` of :func:`truncated_product`, else ``()``.

    Examples
    --------
    >>> st = sized_steps(_Shape(8, 1, False, (10, 6), (5,), (9, 6)))[0]
    >>> st["pf"], st["X"], st["pshift"], st["cshift"], st["ashift"]   # pf = G_1 + T_0
    (11, 10, 1, 0, 1)
    """
    L, n, _, F, T, G = shape[:6]
    P = shape[7] if len(shape) > 7 and shape[7] else None
    out = []
    for j in range(n - 1, -1, -1):
        pf = G[j + 1] + T[j]
        Pj = P[j] if P else max(G[j], F[j])
        X = max(Pj, G[j], F[j])
        st = {"j": j, "tshift": L - T[j], "pf": pf, "P": Pj, "X": X, "pshift": pf - Pj,
              "qshift": X - Pj, "cshift": X - F[j], "ashift": X - G[j], "rows": ()}
        if len(shape) > 6 and shape[6] and pf > Pj:
            # row i of the multiplier: bit i of t's code times a_{j+1} * 2^i, every bit
            # below column P dropped (a floor: a >> (pshift - i)); centred, the top row
            # is -a_{j+1} * 2^(T-1) gated by the inverted top bit (t = code - 2^(T-1))
            st["rows"] = tuple((i, pf - Pj - i, bool(shape[2]) and i == T[j] - 1)
                               for i in range(T[j]))
        out.append(st)
    return out


def truncated_product(a, bits, rows):
    """``sum_i bit_i * floor(+-a * 2^-shift_i)`` over ``rows = (i, shift, negated)``:
    the truncated multiplier (``bits(i)`` gives row i's enabling bit, 0 or 1).

    Parameters
    ----------
    a : int or numpy.ndarray of int
        The multiplicand ``a_{j+1}`` (integer codes).
    bits : callable
        ``bits(i)``: bit ``i`` of ``t``'s code, 0 or 1 (an int or an integer
        array broadcasting with ``a``).
    rows : iterable of (int, int, bool)
        ``(i, shift, negated)`` per row (:func:`sized_steps`' ``rows``); a
        negative ``shift`` shifts left.

    Returns
    -------
    int or numpy.ndarray of int
        The truncated product, in ``a``'s type (0 for no rows).

    Examples
    --------
    >>> truncated_product(7, lambda i: 1, ((0, 2, False), (1, 1, False)))   # 7>>2 + 7>>1
    4
    """
    q = 0
    for i, sh, neg in rows:
        q = q + bits(i) * _shift(-a if neg else a, sh)
    return q


def _shift(v, sh: int):
    return v >> sh if sh >= 0 else v << -sh


def _run_sized(rom, k, shape: _Shape, upto: int = -1) -> dict:
    """Wires of the sized datapath for codes ``k`` (ROM ``rom[segment, j]``);
    ``upto``: stop after the step computing ``a_upto``."""
    L, n, centered, F, T, G = shape[:6]
    s = k >> L
    low = k & ((1 << L) - 1)
    acc = rom[s, n]
    w = {"s": s, f"a{n}": acc}
    for st in sized_steps(shape):
        j = st["j"]
        tj = low >> st["tshift"]
        if centered:
            tj = tj - (1 << (T[j] - 1))
        p = acc * tj
        if st["rows"]:
            code = low >> st["tshift"]
            top = T[j] - 1

            def bit(i, code=code, top=top):
                b = (code >> i) & 1
                return 1 - b if centered and i == top else b

            q = truncated_product(acc, bit, st["rows"])
        else:
            q = _shift(p, st["pshift"])
        sm = (q << st["qshift"]) + (rom[s, j] << st["cshift"])
        acc = sm >> st["ashift"]
        w.update({f"t{j}": tj, f"p{j}": p, f"q{j}": q, f"s{j}": sm, f"a{j}": acc})
        if j == upto:
            return w
    if n == 0:
        acc = _shift(acc, F[0] - G[0])
        w["a0"] = acc
    w["rounded"] = acc
    return w


def _fast_step(acc, low, c, st, centered: bool, Tj: int, lowbits: dict):
    """``a_j`` of one step of :func:`_run_sized` (the same integers, fewer passes:
    the truncated multiplier's row bits are bits of ``low``, cached in ``lowbits``)."""
    if st["rows"]:
        top = Tj - 1
        q = 0
        for i, sh, neg in st["rows"]:
            b = st["tshift"] + i
            if b not in lowbits:
                lowbits[b] = (low >> b) & 1
            bit = 1 - lowbits[b] if centered and i == top else lowbits[b]
            q = q + bit * _shift(-acc if neg else acc, sh)
    else:
        tj = low >> st["tshift"]
        if centered:
            tj = tj - (1 << (Tj - 1))
        q = _shift(acc * tj, st["pshift"])
    return ((q << st["qshift"]) + (c << st["cshift"])) >> st["ashift"]


def _prefix_key(shape, D: int, j: int) -> tuple:
    """What the bound's state after step ``j`` depends on: ``D`` and the widths of
    steps ``n-1 .. j`` (their ``F``, ``T``, ``G`` and product widths)."""
    L, n, centered, F, T, G = shape[:6]
    P = shape[7] if len(shape) > 7 and shape[7] else ()
    trunc = bool(len(shape) > 6 and shape[6])
    return (D, L, n, bool(centered), trunc, tuple(F[j:]), tuple(T[j:]), tuple(G[j:]),
            tuple(P[j:]) if P else None)


#: prefix states kept by one :func:`sized_bound` cache (each holds one wire over all codes)
_PREFIX_CACHE_SIZE = 48


def sized_bound(table: PiecewiseTable, shape, codes=None, cache: dict | None = None):
    """Choose the ROM and certify the sized datapath, segment by segment.

    Returns ``(rom, (approximation, datapath, total))``: ``rom[s][j]`` the
    coefficient ``c_j`` of segment ``s`` with ``F_j`` fractional bits, and
    exact (Fraction) bounds. For each segment the error ``e_j = a_j - â_j``
    of each accumulator against the exact Horner value ``â_j`` of the table's
    polynomial (coefficients ``q_j / 2^Fc``, local variable ``t``) is enclosed
    in an interval, from the top::

        e_n = c_n / 2^F_n - q_n / 2^Fc
        e_j = e_{j+1} * t - a_{j+1} * tau_j - pi_j - sigma_j + delta_j

    with ``t`` in its segment range, ``a_{j+1}`` in its exact range over the
    segment's codes (the model's wires), ``tau_j`` in ``[0, 2^-T_j - 2^-L]``
    (``t`` truncated), ``pi_j`` in ``[0, 2^-X - 2^-pf]`` (the product
    truncated), ``sigma_j`` in ``[0, 2^-G_j - 2^-X]`` (the sum truncated)
    and ``delta_j = c_j / 2^F_j - q_j / 2^Fc``, where ``c_j`` is chosen as
    the ``F_j``-bit value nearest ``q_j / 2^Fc`` minus the middle of the rest
    of ``e_j``'s interval (the truncations' bias is paid in the ROM, for
    free). ``a_0`` is y's code: ``|y - f| <= approx_s + max |e_0|`` on
    segment ``s``, rigorously (every term is enclosed; no floating point).
    ``cache``: a dict kept by the caller across calls on one ``table`` and
    ``codes`` (the states after each step, shared by shapes of equal top steps;
    the results are the same integers with or without it).

    Parameters
    ----------
    table : PiecewiseTable
        The table (its coefficients ``q_j / 2^Fc`` and certified bounds).
    shape : tuple
        The datapath's widths, as :func:`sized_steps` reads them.
    codes : numpy.ndarray of int, optional
        The input codes the ranges are taken over (default: every code of
        every segment).
    cache : dict, optional
        A dict the caller keeps across calls with one ``table`` and ``codes``
        (the states after each step); None: no cache.

    Returns
    -------
    rom : list of tuple of int
        ``rom[s][j]``: coefficient ``c_j`` of segment ``s``, with ``F_j``
        fractional bits.
    bounds : tuple of Fraction
        ``(approximation, datapath, total)``: the largest over the segments,
        exact; ``total`` is the largest per-segment sum, so ``total <=
        approximation + datapath``.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
    >>> rom, (a, p, tot) = sized_bound(t, _Shape(6, 1, False, (10, 8), (6,), (8, 8)))
    >>> len(rom), tot <= a + p, p < Fraction(1, 2 ** 8)
    (4, True, True)
    """
    L, n, centered, F, T, G = shape[:6]
    fc = table.coef_frac_bits
    nseg = table.segment_count
    k = np.arange(nseg << L, dtype=np.int64) if codes is None else codes
    # every interval end is an integer in units of 2^-D (D above every fractional
    # width in play); products with t are rounded outward back to 2^-D (rigorous)
    D = max([fc, L, *F, *G, *(shape[7] if len(shape) > 7 else ())]
            + [G[j + 1] + T[j] for j in range(n)]) + 4
    Q = [np.array([seg.integers[j] for seg in table.segments], dtype=object) << (D - fc)
         for j in range(n + 1)]
    tl = -(1 << (L - 1)) if centered else 0          # t's range in units of 2^-L
    th = (1 << L) - 1 + tl
    rom = np.zeros((nseg, n + 1), dtype=object)

    def nearest(v, sh):  # round(v / 2^sh), ties up; sh >= 1
        return (v + (1 << (sh - 1))) >> sh

    lo = hi = None
    if n > 0:
        rom[:, n] = nearest(Q[n], D - F[n])
        lo = hi = (rom[:, n] << (D - F[n])) - Q[n]
    # the walk keeps a_{j+1} over every code from step to step (one step each);
    # ``cache`` (one table, one ``codes``) keeps the state after each step, keyed by
    # what it depends on, so shapes sharing their top steps share that work
    low = k & ((1 << L) - 1)
    seg = k >> L
    lowbits = cache.setdefault("lowbits", {}) if cache is not None else {}
    acc = None
    steps = sized_steps(shape)
    start = 0
    if cache is not None:
        for idx in range(len(steps) - 1, -1, -1):
            key = _prefix_key(shape, D, steps[idx]["j"])
            hit = cache.pop(key, None)
            if hit is not None:
                cache[key] = hit   # most recently used: kept longest
                cols, lo, hi, acc = hit
                for jj, col in cols.items():
                    rom[:, jj] = col
                start = idx + 1
                break
    for idx in range(start, len(steps)):
        st = steps[idx]
        j = st["j"]
        if acc is None:
            acc = _int_rom(rom)[seg, n]
        a = acc.reshape(nseg, -1)
        amin, amax = a.min(axis=1).astype(object), a.max(axis=1).astype(object)
        prods = (lo * tl, lo * th, hi * tl, hi * th)
        plo = np.minimum(np.minimum(prods[0], prods[1]), np.minimum(prods[2], prods[3])) >> L
        phi = -(-np.maximum(np.maximum(prods[0], prods[1]), np.maximum(prods[2], prods[3])) >> L)
        taum = (1 << (L - T[j])) - 1                      # tau_j's top in units of 2^-L
        at_lo, at_hi = np.minimum(amin * taum, 0), np.maximum(amax * taum, 0)
        sh = D - G[j + 1] - L
        if sh >= 0:
            at_lo, at_hi = at_lo << sh, at_hi << sh
        else:
            at_lo, at_hi = at_lo >> -sh, -(-at_hi >> -sh)
        if st["rows"]:  # each truncated row floors: error in (-(1 - 2^-shift), 0] ulps of P
            pi = sum((1 << (D - st["P"])) - (1 << (D - st["P"] - sh))
                     for _, sh, _ in st["rows"] if sh > 0)
        elif st["pshift"] > 0:
            pi = (1 << (D - st["P"])) - (1 << (D - st["pf"]))
        else:
            pi = 0
        sigma = (1 << (D - G[j])) - (1 << (D - st["X"]))
        lo, hi = plo - at_hi - pi - sigma, phi - at_lo
        rom[:, j] = nearest(2 * Q[j] - (lo + hi), D + 1 - F[j])
        d = (rom[:, j] << (D - F[j])) - Q[j]
        lo, hi = lo + d, hi + d
        if j > 0:  # a_j, the next step's a_{j+1}: the model's integers (_run_sized)
            col = _int_rom(rom[:, j:j + 1])[:, 0]
            if col.dtype != object and acc.dtype == object:
                col = col.astype(object)
            elif col.dtype == object and acc.dtype != object:
                acc = acc.astype(object)
            acc = _fast_step(acc, low, col[seg], st, centered, T[j], lowbits)
        else:
            acc = None
        if cache is not None:
            cache[_prefix_key(shape, D, j)] = ({jj: rom[:, jj].copy() for jj in range(j, n + 1)},
                                               lo, hi, acc)
            keys = [key for key in cache if key != "lowbits"]
            if len(keys) > _PREFIX_CACHE_SIZE:
                del cache[keys[0]]
    if n == 0:  # y = c_0 shifted to G_0 bits: a truncation when F_0 > G_0
        sigma = max(0, (1 << (D - G[0])) - (1 << (D - F[0])))
        rom[:, 0] = nearest(Q[0] + sigma // 2, D - F[0])
        d = (rom[:, 0] << (D - F[0])) - Q[0]
        lo, hi = d - sigma, d
    # per segment approximation + datapath, in integers (floats are dyadic: exact)
    approx = [Fraction(seg.abs_error_bound) for seg in table.segments]
    M = max([D] + [a_.denominator.bit_length() - 1 for a_ in approx])
    path = [max(-int(x), int(y)) for x, y in zip(lo, hi)]
    total = max(a_.numerator * (1 << (M - a_.denominator.bit_length() + 1)) + (p_ << (M - D))
                for a_, p_ in zip(approx, path))
    return [tuple(int(v) for v in row) for row in rom], (max(approx), Fraction(max(path), 2 ** D),
                                                         Fraction(total, 2 ** M))


def _int_rom(rom) -> np.ndarray:
    """The ROM as int64 when every value fits (the model's fast path), else Python ints."""
    vals = [int(v) for v in rom.ravel()]
    if vals and max(abs(v) for v in vals) < 2 ** 40:
        return np.array(vals, dtype=np.int64).reshape(rom.shape)
    return np.array(vals, dtype=object).reshape(rom.shape)


def _check_sized_widths(widths, n: int, L: int, centered: bool, fy: int,
                        truncated: bool = False) -> _Shape:
    """``widths`` (a mapping with ``coef_frac``, ``t_keep``, ``acc_frac``) as a shape."""
    if not isinstance(widths, dict) or not {"coef_frac", "t_keep", "acc_frac"} <= set(widths) \
            or not set(widths) <= {"coef_frac", "t_keep", "acc_frac", "prod_frac"}:
        raise ValueError("widths: expected None, 'auto' or a dict with keys coef_frac (n+1 "
                         "values), t_keep (n values), acc_frac (n-1 values, for a_1..a_{n-1}) "
                         "and optionally prod_frac (n values)")
    P = tuple(check_width(v, "widths prod_frac", -8, 62) for v in widths.get("prod_frac", ()))
    if P and len(P) != n:
        raise ValueError(f"widths: degree {n} needs {n} prod_frac values; got {len(P)}")
    F = tuple(check_width(v, "widths coef_frac", -8, 62) for v in widths["coef_frac"])
    T = tuple(check_width(v, "widths t_keep", 1, L) for v in widths["t_keep"])
    A = tuple(check_width(v, "widths acc_frac", -8, 62) for v in widths["acc_frac"])
    if len(F) != n + 1 or len(T) != n or len(A) != max(n - 1, 0):
        raise ValueError(f"widths: degree {n} needs {n + 1} coef_frac, {n} t_keep and "
                         f"{max(n - 1, 0)} acc_frac values; got {len(F)}, {len(T)}, {len(A)}")
    return _Shape(L, n, centered, F, T, (fy,) + A + ((F[n],) if n > 0 else ()), truncated, P)


def _sized_design(proto: PiecewiseDesign, shape: _Shape, cuts=()) -> PiecewiseDesign | None:
    """The sized design of ``shape``, or None when y's range does not fit ``out_bits``."""
    t = proto.table
    rom, bound = sized_bound(t, shape)
    rom_i = _int_rom(np.array(rom, dtype=object))
    k = np.arange(2 ** proto.in_bits, dtype=np.int64)
    w = _run_sized(rom_i, k, shape)
    r = w["rounded"]
    y_off = int(r.min())
    if int(r.max()) - y_off > 2 ** proto.out_bits - 1:
        return None
    n, L = shape.n, shape.L
    widths, q_bits = [], []
    for st in sized_steps(shape):
        j = st["j"]
        p, sm, a = w[f"p{j}"], w[f"s{j}"], w[f"a{j}"]
        q_bits.append(max(signed_bits(int(w[f"q{j}"].min()), int(w[f"q{j}"].max())), 2))
        for key in ("p", "q", "s"):
            v = w[f"{key}{j}"]
            check_int64(signed_bits(int(v.min()), int(v.max())) + 1,
                        f"wire {key}{j} of the sized Horner datapath")
        widths.append((max(signed_bits(int(p.min()), int(p.max())), 2),
                       max(signed_bits(int(sm.min()), int(sm.max())), 2),
                       max(signed_bits(int(a.min()), int(a.max())), 2)))
    cols = np.array(rom, dtype=object).reshape(len(rom), n + 1)
    rom_bits = tuple(max(signed_bits(int(min(cols[:, j])), int(max(cols[:, j]))), 2)
                     for j in range(n + 1))
    return replace(proto, acc_frac_bits=max(shape.G[1:n], default=shape.G[0]),
                   y_format=QFormat(proto.out_bits, shape.G[0], offset_code=y_off),
                   rom_bits=rom_bits, t_bits=max(shape.T, default=L) + 1,
                   widths=tuple(widths), top_frac_bits=shape.G[0], rounding="trunc",
                   coef_frac=shape.F, t_keep=shape.T, acc_frac=shape.G,
                   coefficients=tuple(rom), cuts=tuple(cuts), bound=bound,
                   multipliers="truncated" if len(shape) > 6 and shape[6] else "full",
                   prod_frac=tuple(st["P"] for st in sorted(sized_steps(shape),
                                                            key=lambda st: st["j"])),
                   q_bits=tuple(q_bits))


def _meets(bound, max_error: Fraction, strict: bool) -> bool:
    return bound[2] < max_error if strict else bound[2] <= max_error


#: the greedy's default area proxy: Yosys cells per ROM bit against one per
#: partial-product bit (as hw.piecewise_search's model)
ROM_WEIGHT = 0.15


def shape_cost(table: PiecewiseTable, shape, rom, rom_weight: float = ROM_WEIGHT) -> float:
    """Area proxy of a sized datapath with ROM ``rom`` (:func:`sized_bound`):
    ROM bits x ``rom_weight`` plus ``a x b`` per ``a x b`` multiplier (the
    kept partial-product bits of a truncated one) plus each sum's
    width, the widths from the exact wire ranges over all codes (one model run).

    Parameters
    ----------
    table : PiecewiseTable
        The table (its segment count).
    shape : tuple
        The datapath's widths (:func:`sized_steps`).
    rom : sequence of sequence of int
        The ROM, per segment its coefficient integers (:func:`sized_bound`).
    rom_weight : float, default ROM_WEIGHT
        The price of one ROM bit against one partial-product bit (finite, >= 0).

    Returns
    -------
    float
        The area proxy, in partial-product-bit units.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
    >>> sh = _Shape(6, 1, False, (10, 8), (6,), (8, 8))
    >>> shape_cost(t, sh, sized_bound(t, sh)[0]) > 0
    True
    """
    L, n = shape[0], shape[1]
    rom_i = _int_rom(np.array(rom, dtype=object))
    # a proxy: the wires' ranges on each segment's first, middle and last codes
    local = np.array(sorted({0, 1, 1 << (L - 1), (1 << L) - 2, (1 << L) - 1}), dtype=np.int64)
    seg = np.arange(table.segment_count, dtype=np.int64) << L
    w = _run_sized(rom_i, (seg[:, None] + local[None, :]).ravel(), shape)

    def bits(v) -> int:
        return signed_bits(int(v.min()), int(v.max()))

    cost = rom_weight * len(rom) * sum(bits(rom_i[:, j]) for j in range(n + 1))
    for st in sized_steps(shape):
        j = st["j"]
        aw = bits(w[f"a{j + 1}"])
        mul = (sum(max(aw - sh, 1) for _, sh, _ in st["rows"]) if st["rows"]
               else aw * bits(w[f"t{j}"]))
        cost += mul + bits(w[f"s{j}"])
    return float(cost)


def _auto_shape(proto: PiecewiseDesign, fy: int, max_error: Fraction, strict: bool,
                truncated: bool = False, rom_weight: float = ROM_WEIGHT) -> _Shape:
    """Greedy widths: start from ``Fy + 6`` fractional bits for every column and
    accumulator and every bit of ``t`` (or, when that misses ``max_error``,
    generous: the table's ``Fc`` for every column, ``Fy + 8`` accumulator
    bits); then, round after round, try each width one bit lower and keep,
    among the changes whose certified bound still meets ``max_error``, the one
    that saves the most area (:func:`shape_cost`) per unit of error budget it
    spends (a change that saves nothing only when no other is left, one that
    costs area never; ties: the highest-order width first), until none is
    left. Then trade: one width one bit higher, the descent again without it;
    kept when the area drops. The result: no width can be one bit lower
    without missing ``max_error`` or growing the area."""
    t = proto.table
    n, L, fc = t.degree, proto.local_bits, t.coef_frac_bits
    start = {("F", j): max(fc, fy + 2) for j in range(n + 1)}
    start.update({("T", j): L for j in range(n)})
    start.update({("G", j): fy + 8 for j in range(1, n)})
    start.update({("P", j): fy + 8 for j in range(n)})
    floors = {"F": -8, "T": 1, "G": -8, "P": -8}
    ceils = {"F": 62, "T": L, "G": 62, "P": 62}
    # highest order first: F_n .. F_0, T_{n-1} .. T_0, P_{n-1} .. P_0, G_{n-1} .. G_1
    order = sorted(start, key=lambda key: ("FTPG".index(key[0]), -key[1]))
    memo: dict = {}
    bound_cache: dict = {}   # sized_bound's states of shared top steps

    def shape(v):
        F = tuple(v["F", j] for j in range(n + 1))
        G = (fy,) + tuple(v["G", j] for j in range(1, n)) + ((F[n],) if n > 0 else ())
        return _Shape(L, n, t.centered, F, tuple(v["T", j] for j in range(n)), G, truncated,
                      tuple(v["P", j] for j in range(n)))

    def judge(v):  # (meets, area, certified total), memoised
        key = tuple(v[k] for k in order)
        if key not in memo:
            rom, b = sized_bound(t, shape(v), cache=bound_cache)
            ok = _meets(b, max_error, strict)
            memo[key] = (ok, shape_cost(t, shape(v), rom, rom_weight) if ok else math.inf, b[2])
        return memo[key]

    def descend(cur, frozen=None):
        _, cost, bound = judge(cur)
        while True:
            best = None
            for key in order:
                if key == frozen or cur[key] <= floors[key[0]]:
                    continue
                trial = dict(cur)
                trial[key] -= 1
                ok, c, b = judge(trial)
                if not ok or c > cost:
                    continue
                # area saved per unit of the error budget spent (free moves last)
                saved, spent = cost - c, b - bound
                score = (True, saved / spent if spent > 0 else math.inf) if saved > 0 \
                    else (False, -spent)
                if best is None or score > best[0]:
                    best = (score, trial)
            if best is None:
                return cur
            cur = best[1]
            _, cost, bound = judge(cur)

    # a moderate start (6 guard bits everywhere) saves most of the walk down when it meets
    cur = {key: (min(v, fy + 6) if key[0] in "FGP" else v) for key, v in start.items()}
    if not judge(cur)[0]:
        cur = dict(start)
    ok, _, total = judge(cur)
    if not ok:
        approx = max(Fraction(seg.abs_error_bound) for seg in t.segments)
        raise ValueError(f"max_error {float(max_error):.6e} is not met even with generous widths "
                         f"(certified {format_up(float(total), '.6e')}; approximation "
                         f"{format_up(float(approx), '.6e')}); "
                         f"accepted: a table whose approximation bound leaves room for rounding")
    cur = descend(cur)
    for _ in range(2):  # trades, while one pays
        gained = False
        for key in order:
            if cur[key] >= ceils[key[0]]:
                continue
            up = dict(cur)
            up[key] += 1
            trial = descend(up, frozen=key)
            if judge(trial)[1] < judge(cur)[1]:
                cur, gained = trial, True
        if not gained:
            break
    return shape(descend(cur))


def _check_mult_cuts(mult, n: int) -> tuple[int, ...]:
    """``mult_cuts`` checked: a sorted tuple of distinct steps ``1..n``."""
    if not isinstance(mult, tuple) or any(
            isinstance(c, bool) or not isinstance(c, int) or not 1 <= c <= n
            for c in mult) or list(mult) != sorted(set(mult)):
        raise ValueError(f"mult_cuts {_short(mult)}: accepted: sorted distinct steps 1..{n}")
    return mult


def _check_cuts(pipeline, n: int) -> tuple[int, ...]:
    if pipeline is None:
        return ()
    if pipeline == "full":
        return tuple(range(n + 1))
    if isinstance(pipeline, (str, bytes)) or not hasattr(pipeline, "__iter__"):
        raise ValueError(f"pipeline: {pipeline!r}; accepted: None, 'full' or cut points in "
                         f"0..{n} (0 after the ROM, i after the i-th multiply-add)")
    cuts = sorted({check_width(c, "pipeline cut", 0, n) for c in pipeline})
    return tuple(cuts)


def design_piecewise(table: PiecewiseTable, in_bits: int, out_bits: int, *,
                     guard_bits: int = 2, name: str | None = None, widths=None,
                     max_error=None, pipeline=None, multipliers: str = "full",
                     rom_weight: float = ROM_WEIGHT,
                     out_frac_bits: int | None = None) -> PiecewiseDesign:
    """Size the ROM + Horner evaluator of a uniform piecewise ``table``.

    ``in_bits`` must exceed the table's index bits (the rest is the local
    variable). Raises ValueError naming the value and the accepted range.

    Parameters
    ----------
    table : PiecewiseTable
        A uniform table (its coefficients ``q_j / 2^Fc``).
    in_bits, out_bits : int
        Widths of the input code and of the output code.
    guard_bits : int
        ``widths=None`` only: the accumulators carry ``y_frac_bits +
        guard_bits`` fractional bits, rounded to nearest after each step.
    name : str, optional
        Module name stem (default: the table's name).
    widths : None, "auto" or dict
        None (default, today's architecture): one ROM width for every
        coefficient, an exact product and a rounding after each step.
        Otherwise the *sized* architecture (:func:`sized_steps`): ROM column
        ``j`` with its own ``F_j`` fractional bits, step ``j`` multiplying by
        the top ``T_j`` bits of ``t``, products and sums truncated (floors;
        the bias is paid in the ROM coefficients) to ``G_j`` accumulator
        bits, the last one to y's. ``"auto"``: the greedy search of
        :func:`_auto_shape` under ``max_error``; a dict ``{"coef_frac":
        (F_0..F_n), "t_keep": (T_0..T_{n-1}), "acc_frac": (G_1..G_{n-1})}``
        gives them. Every width change enters the certified bound
        (:func:`sized_bound`).
    max_error : float or str, optional
        ``widths="auto"``: the certified total must be ``<= max_error``;
        default: faithful, ``< 2^-Fy`` (one unit of y's last place), with
        ``Fy`` the most fractional bits of y at which that is reachable and
        y's range fits ``out_bits``.
    pipeline : None, "full" or iterable of int
        Sized architecture only: register cut points, ``0`` after the ROM
        read, ``i`` after the ``i``-th multiply-add; ``"full"``: all
        ``degree + 1``. ``latency`` is their number; the values are those of
        the combinational datapath, ``latency`` cycles later.
    multipliers : "full" or "truncated"
        Sized architecture only: ``"full"`` multiplies exactly and then drops
        the product's bits below ``X_j``; ``"truncated"`` never forms them:
        each partial-product row is floored at column ``X_j``
        (:func:`truncated_product`), the rows' errors enter the bound.
    rom_weight : float
        ``widths="auto"``: the greedy's price of one ROM bit against one
        partial-product bit (:func:`shape_cost`; default :data:`ROM_WEIGHT`,
        generic Yosys cells; an FPGA whose LUT6 holds 64 ROM bits wants less);
        a finite number >= 0.

    Returns
    -------
    PiecewiseDesign
        The sized design, its bound certified (:meth:`PiecewiseDesign.budget`).

    Raises
    ------
    ValueError
        ``table`` is not a :class:`PiecewiseTable` or not uniform (nor an
        exponent table of ``2**m`` segments), an interval endpoint is not
        rational; ``in_bits`` outside ``index_bits + 1`` .. 20, ``out_bits``
        outside 1..32, ``guard_bits`` outside 0..16, ``name`` not an
        identifier; ``multipliers`` not ``"full"``/``"truncated"``, a bad
        ``widths`` dict, ``pipeline`` cuts outside 0..degree, ``pipeline``
        or ``multipliers`` without ``widths``; ``max_error`` not a positive
        finite number (or rational text) or out of reach; ``rom_weight``
        negative or not finite; a wire wider than 64 bits; y's range does
        not fit ``out_bits``.

    See Also
    --------
    chebnorm.hw.horner.design_horner : one polynomial over the whole interval.
    chebnorm.hw.piecewise_search.search : the ``chebnorm design`` search over tables and widths.
    chebnorm.hw.hdl.module_text : the design's Verilog or VHDL.

    Notes
    -----
    The :math:`W`-bit code :math:`k` stands for
    :math:`x = a + (b - a)\\, k\\, 2^{-W}`; its top :math:`K` bits address the
    ROM of segment coefficients and the low :math:`L = W - K` bits are the
    local variable :math:`t = (k \\bmod 2^L)\\, 2^{-L}`, as in FloPoCo's
    ``FixFunctionByPiecewisePoly`` [1]_ [2]_. With the one-width design

    .. math::

        |y - f(x)| \\le \\varepsilon_{\\mathrm{table}}
        + \\sum_{j=1}^{n-1} 2^{-(F_a + 1)} \\max |t|^j + 2^{-(F_y + 1)}

    (module docstring); the sized design (``widths``) is certified per
    segment by :func:`sized_bound`.

    References
    ----------
    .. [1] F. de Dinechin, B. Pasca, "Designing custom arithmetic data paths
       with FloPoCo", IEEE Design & Test of Computers 28(4), 2011.
    .. [2] F. de Dinechin, M. Joldes, B. Pasca, "Automatic generation of
       polynomial-based hardware architectures for function evaluation",
       IEEE ASAP 2010.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8)
    >>> d.measure()["max_error"] <= d.budget()["total"]
    True
    >>> design_piecewise(t, 2, 8)
    Traceback (most recent call last):
    ...
    ValueError: in_bits = 2 is out of range; accepted: 3 <= in_bits <= 20
    """
    if not isinstance(table, PiecewiseTable):
        raise ValueError("design_piecewise needs a PiecewiseTable")
    table.verify()   # a table changed behind its back is proved again (or refused)
    with drafting():
        d = _design_piecewise(table, in_bits, out_bits, guard_bits, name, widths, max_error,
                              pipeline, multipliers, rom_weight, out_frac_bits)
    return seal(d)


def _design_piecewise(table, in_bits, out_bits, guard_bits, name, widths, max_error, pipeline,
                      multipliers, rom_weight, out_frac_bits=None) -> PiecewiseDesign:
    """:func:`design_piecewise`'s sizing (its drafts unchecked)."""
    nseg = table.segment_count
    if table.segment_by != "uniform" and nseg & (nseg - 1):
        raise ValueError(f"table {table.name!r} is segmented by {table.segment_by} into {nseg} "
                         f"segments; accepted for hardware: a uniform table, or an exponent "
                         f"table of 2^m segments (the code's top bits index it)")
    K = (nseg - 1).bit_length()
    in_bits = check_width(in_bits, "in_bits", K + 1, MAX_PW_IN_BITS)
    out_bits = check_width(out_bits, "out_bits", 1, MAX_PW_OUT_BITS)
    guard_bits = check_width(guard_bits, "guard_bits", 0, 16)
    name = identifier(name or table.name, field="name")
    for v in table.interval:
        _exact(v)
    L = in_bits - K
    rom_bits = table.coefficient_word_bits()
    proto = PiecewiseDesign(name, table, in_bits, out_bits, L, 0, QFormat(out_bits, 0), rom_bits,
                            L + 2, (), 0)
    # sized with Python integers (no overflow possible), then checked to fit the
    # int64 model: first the exact polynomial values (no rounding) fix y's format
    k = np.arange(2 ** in_bits, dtype=np.int64).astype(object)
    exact = _run(proto, k, 10 ** 6, 0)
    top, tf = exact["top"], exact["top_frac"]
    span = Fraction(int(top.max()) - int(top.min()), 2 ** tf)
    fy_max = out_bits - (math.floor(math.log2(span)) if span > 0 else -8)
    if out_frac_bits is not None:   # the output's last place stated: checked, never moved
        fy = check_width(out_frac_bits, "out_frac_bits", -60, 60)
        fys = [fy]
    else:
        fys = list(range(min(fy_max, 60), -60, -1))
    for fy in fys:
        fa = fy + guard_bits
        w = _run(proto, k, fa, fy)
        r = w["rounded"]
        y_off = int(r.min())
        if int(r.max()) - y_off <= 2 ** out_bits - 1:
            break
    else:
        if widths is None:
            raise ValueError(f"out_bits = {out_bits}: y's range at out_frac_bits {fy} (last "
                             f"place 2^{-fy}) needs {(int(r.max()) - y_off).bit_length()} "
                             f"bits; accepted: more out_bits or fewer out_frac_bits")
    if widths is not None:
        if multipliers not in ("full", "truncated"):
            raise ValueError(f"multipliers {multipliers!r}; accepted: 'full', 'truncated'")
        return _design_sized(proto, fy, widths, max_error, pipeline, multipliers == "truncated",
                             span, _check_weight(rom_weight), fixed=out_frac_bits is not None)
    if pipeline is not None or multipliers != "full":
        raise ValueError("pipeline, multipliers: need the sized architecture; accepted: "
                         "widths='auto' or a widths dict with them, or their defaults")
    return _uniform_design(proto, w, fa, fy, y_off)


def _short(v) -> str:
    text = repr(v)
    return text if len(text) <= 80 else text[:77] + "..."


def _prove(d: PiecewiseDesign) -> None:
    """The table re-verified and the design sized again from it and its own
    widths: every field must match (ValueError naming the first that does not)."""
    t = d.table
    if not isinstance(t, PiecewiseTable):
        raise ValueError(f"table: a {type(t).__name__}; accepted: a PiecewiseTable")
    t.verify()
    identifier(d.name, field="name")
    n = t.degree
    K = (t.segment_count - 1).bit_length()
    W = check_width(d.in_bits, "in_bits", K + 1, MAX_PW_IN_BITS)
    check_width(d.out_bits, "out_bits", 1, MAX_PW_OUT_BITS)
    if not isinstance(d.y_format, QFormat):
        raise ValueError(f"y_format: a {type(d.y_format).__name__}; accepted: a QFormat")
    with drafting():
        if d.sized:
            L = W - K
            if d.multipliers not in ("full", "truncated"):
                raise ValueError(f"multipliers {d.multipliers!r}; accepted: 'full', 'truncated'")
            if not isinstance(d.acc_frac, tuple) or len(d.acc_frac) != n + 1:
                raise ValueError(f"acc_frac {_short(d.acc_frac)}: accepted: {n + 1} widths "
                                 f"G_0 .. G_{n}")
            fy = check_width(d.acc_frac[0], "acc_frac G_0 (y's fractional bits)", -60, 62)
            shape = _check_sized_widths({"coef_frac": d.coef_frac, "t_keep": d.t_keep,
                                         "acc_frac": d.acc_frac[1:n],
                                         "prod_frac": d.prod_frac}, n, L, t.centered, fy,
                                        d.multipliers == "truncated")
            cuts = _check_cuts(d.cuts, n)
            mult = _check_mult_cuts(d.mult_cuts, n)
            proto = PiecewiseDesign(d.name, t, W, d.out_bits, L, 0, QFormat(d.out_bits, 0),
                                    t.coefficient_word_bits(), L + 2, (), 0)
            ref = _sized_design(proto, shape, cuts)
            if ref is None:
                raise ValueError(f"out_bits = {d.out_bits}: y's range at {fy} fractional bits "
                                 f"does not fit; accepted: the widths design_piecewise sized")
            ref = replace(ref, mult_cuts=mult)
        else:
            guard = d.acc_frac_bits - d.y_format.frac_bits \
                if isinstance(d.acc_frac_bits, int) and isinstance(d.y_format.frac_bits, int) \
                else None
            if guard is None or not 0 <= guard <= 16:
                raise ValueError(f"acc_frac_bits {_short(d.acc_frac_bits)}: accepted: y's "
                                 f"fractional bits plus 0 .. 16 guard bits")
            ref = _design_piecewise(t, W, d.out_bits, guard, d.name, None, None, None, "full",
                                    ROM_WEIGHT, d.y_format.frac_bits)
            # pipeline registers (chebnorm.hw.pipeline.with_cuts): the same values, later
            ref = replace(ref, cuts=_check_cuts(d.cuts, n),
                          mult_cuts=_check_mult_cuts(d.mult_cuts, n))
    for f in dataclasses.fields(d):
        if f.name == "table":
            continue
        mine, theirs = getattr(d, f.name), getattr(ref, f.name)
        if type(mine) is not type(theirs) or mine != theirs:
            raise ValueError(f"{f.name}: stated {_short(mine)}, but the table and the design's "
                             f"widths give {_short(theirs)}; accepted: the design "
                             f"design_piecewise sizes")


def _uniform_design(proto: PiecewiseDesign, w: dict, fa: int, fy: int,
                    y_off: int) -> PiecewiseDesign:
    """The one-width design from the wires ``w`` of its datapath at ``fa``
    accumulator and ``fy`` output fractional bits (each wire checked for int64)."""
    table, L = proto.table, proto.local_bits
    for key, v in w.items():
        if key[0] in "psa" and key != "s":
            check_int64(signed_bits(int(v.min()), int(v.max())) + 1,
                        f"wire {key} of the Horner datapath ({table.coef_frac_bits} coefficient "
                        f"fractional bits, {L} local bits)")
    widths = []
    n = table.degree
    for j in range(n - 1, -1, -1):
        p, s = w[f"p{j}"], w[f"s{j}"]
        out = w.get(f"a{j}", s)
        widths.append((max(signed_bits(int(p.min()), int(p.max())), 2),
                       max(signed_bits(int(s.min()), int(s.max())), 2),
                       max(signed_bits(int(out.min()), int(out.max())), 2)))
        check_int64(widths[-1][1], f"the sum of Horner step {j}")
    return replace(proto, acc_frac_bits=fa, y_format=QFormat(proto.out_bits, fy, offset_code=y_off),
                   widths=tuple(widths), top_frac_bits=int(w["top_frac"]))


def _design_sized(proto: PiecewiseDesign, fy: int, widths, max_error, pipeline,
                  truncated: bool = False, span: Fraction = Fraction(0),
                  rom_weight: float = ROM_WEIGHT, fixed: bool = False) -> PiecewiseDesign:
    """:func:`design_piecewise` with ``widths`` given: y's fractional bits
    lowered from the uniform design's ``fy`` until y's range fits (``span``:
    the exact polynomial's range of values); ``fixed``: ``fy`` only (stated)."""
    t = proto.table
    n, L = t.degree, proto.local_bits
    cuts = _check_cuts(pipeline, n)
    if max_error is None:
        limit, strict = None, True
    else:
        limit, strict = _error_limit(max_error), False
    failed = None
    for f in range(fy, fy - (1 if fixed else 8), -1):
        lim = Fraction(2) ** -f if limit is None else limit
        if widths == "auto":
            try:  # faithful at fewer fractional bits of y may still be reachable
                shape = _auto_shape(proto, f, lim, strict, truncated, rom_weight)
            except ValueError as exc:
                # only where y's range is tight at f bits is f given up for fewer bits
                # (else max_error is out of reach and y keeps its last place)
                if fixed or span * Fraction(2) ** f + 2 <= 2 ** proto.out_bits - 1:
                    if limit is None:
                        raise ValueError(f"max_error None (faithful: error < 2^-{f}, y's last "
                                         f"place): {exc}") from None
                    raise
                failed = failed or exc
                continue
        else:
            shape = _check_sized_widths(widths, n, L, t.centered, f, truncated)
        d = _sized_design(proto, shape, cuts)
        if d is not None:
            return d
    if failed is not None:
        raise failed
    raise ValueError(f"out_bits = {proto.out_bits}: y's range does not fit" + (
        f" at out_frac_bits {fy}" if fixed else "") + "; accepted: more bits")


def _check_weight(w) -> float:
    if isinstance(w, bool) or not isinstance(w, (int, float)) or not math.isfinite(w) or w < 0:
        raise ValueError(f"rom_weight {w!r}: accepted a finite number >= 0")
    return float(w)


def _error_limit(max_error) -> Fraction:
    if isinstance(max_error, str):
        v = parse_number(max_error)
        if not v.is_Rational or v <= 0:
            raise ValueError(f"max_error {max_error!r}: accepted a positive rational (2^-16, 1e-5)")
        return Fraction(int(v.p), int(v.q))
    if isinstance(max_error, bool) or not isinstance(max_error, (int, float, Fraction)) or \
            not math.isfinite(max_error) or max_error <= 0:
        raise ValueError(f"max_error {max_error!r}: accepted a positive finite number")
    return Fraction(max_error)


# -- HDL (printed by chebnorm.hw.hdl) ----------------------------------------------

@hw_doc
def piecewise_verilog(d: PiecewiseDesign, *, version: str = "", command: str | None = None) -> str:
    """The synthesizable Verilog-2005 module: ROM (a case on the index) + Horner
    (:func:`chebnorm.hw.hdl.module_text` in Verilog).

    Parameters
    ----------
    d : PiecewiseDesign
        The design.
    %(version)s
    %(command)s

    Returns
    -------
    str
        The module ``chebnorm_<name>``'s Verilog text.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8)
    >>> v = piecewise_verilog(d)
    >>> v.count("2'd"), "module chebnorm_rs" in v   # one ROM row per segment
    (4, True)
    """
    return module_text(d, "verilog", version=version, command=command)


@hw_doc
def piecewise_testbench(d: PiecewiseDesign, language: str = "verilog") -> str:
    """The exhaustive self-checking bench (expected codes from ``d.evaluate``).

    Parameters
    ----------
    d : PiecewiseDesign
        The design.
    %(language)s

    Returns
    -------
    str
        The bench ``tb_chebnorm_<name>``'s text (it reads the ``.hex`` vectors
        of :func:`piecewise_outputs`).

    Raises
    ------
    ValueError
        ``language`` is neither ``"verilog"`` nor ``"vhdl"``.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8)
    >>> piecewise_testbench(d).splitlines()[0]
    '// tb_chebnorm_rs: exhaustive self-checking test bench of chebnorm_rs.'
    """
    return testbench_text(d, language)


@hw_doc
def piecewise_outputs(d: PiecewiseDesign, *, version: str = "", command: str | None = None,
                      language: str = "verilog") -> dict[str, str]:
    """``{file name: text}``: the module, its bench and the expected-output
    vectors, in ``language`` (``"verilog"`` or ``"vhdl"``;
    :func:`chebnorm.hw.hdl.hdl_files`).

    Parameters
    ----------
    d : PiecewiseDesign
        The design.
    version, command
        As in :func:`piecewise_verilog`.
    %(language)s

    Returns
    -------
    dict of str to str
        File name to text: ``chebnorm_<name>.v`` (or ``.vhd``), its bench
        ``tb_chebnorm_<name>.v`` (or ``.vhd``) and ``chebnorm_<name>.hex``,
        the expected output of every input code.

    Raises
    ------
    ValueError
        ``language`` is neither ``"verilog"`` nor ``"vhdl"``.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8)
    >>> files = piecewise_outputs(d)
    >>> sorted(files), len(files["chebnorm_rs.hex"].split()) == 2 ** 8
    (['chebnorm_rs.hex', 'chebnorm_rs.v', 'tb_chebnorm_rs.v'], True)
    >>> sorted(piecewise_outputs(d, language="vhdl"))
    ['chebnorm_rs.hex', 'chebnorm_rs.vhd', 'tb_chebnorm_rs.vhd']
    """
    return hdl_files(d, language, version=version, command=command)


def piecewise_cells(d: PiecewiseDesign):
    """Yosys ``synth; stat`` of the module (a :class:`~chebnorm.hw.run_verilog.SynthResult`).

    Parameters
    ----------
    d : PiecewiseDesign
        The design.

    Returns
    -------
    SynthResult
        The cell counts of its Verilog module
        (:func:`chebnorm.hw.run_verilog.synthesize_text`).

    Raises
    ------
    ValueError
        Yosys is missing or fails.
    """
    return synthesize_text(piecewise_verilog(d), d.module_name)


def simulate_piecewise(d: PiecewiseDesign, directory):
    """Write the outputs into ``directory`` and run the bench in Icarus Verilog.

    Parameters
    ----------
    d : PiecewiseDesign
        The design.
    directory : str or os.PathLike
        The folder to write the Verilog files of :func:`piecewise_outputs` into
        (created if missing; files of the same names are replaced).

    Returns
    -------
    SimResult
        The bench's verdict (:func:`chebnorm.hw.run_verilog.simulate`).

    Raises
    ------
    ValueError
        ``directory`` cannot be written (a ``WriteError``, also an ``OSError``),
        or Icarus Verilog is missing or fails.
    """
    from pathlib import Path

    from chebnorm.core.files import write_folder

    write_folder(Path(directory), piecewise_outputs(d))
    return simulate(directory, d)
