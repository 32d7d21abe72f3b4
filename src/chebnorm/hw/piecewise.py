"""Hardware of a uniform piecewise table: a coefficient ROM and one shared Horner datapath.

The input is an unsigned ``W``-bit code ``k`` standing for
``x = lo + (hi - lo) * k / 2**W`` (so ``[lo, hi)`` is covered exactly, as in
FloPoCo's ``FixFunctionByPiecewisePoly``). With ``2**K`` segments the top
``K`` bits of ``k`` address the ROM, the low ``L = W - K`` bits are the local
variable ``t = low / 2**L`` in ``[0, 1)`` (``t - 1/2`` when the table is
centred): exactly the variable each segment's polynomial was certified in.
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

>>> from chebnorm.approx.piecewise_fit import piecewise_fit
>>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
>>> d = design_piecewise(t, 8, 8)
>>> d.y_format.frac_bits, d.budget()["total"] >= d.measure()["max_error"]
(9, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import mpmath
import numpy as np

from chebnorm.approx.expr import parse_function, parse_number
from chebnorm.approx.piecewise_table import PiecewiseTable
from chebnorm.core.numeric import float_up
from chebnorm.core.textsafe import identifier

from .fixed import (
    QFormat,
    check_int64,
    check_width,
    rounding_error_bound,
    shift_round,
    signed_bits,
)
from .hdl import hdl_files, module_text, testbench_text
from .verilog import simulate, synthesize_text

__all__ = [
    "MAX_PW_IN_BITS",
    "PiecewiseDesign",
    "design_piecewise",
    "piecewise_cells",
    "piecewise_outputs",
    "piecewise_testbench",
    "piecewise_verilog",
    "simulate_piecewise",
]

MAX_PW_IN_BITS = 20
MAX_PW_OUT_BITS = 32
ROUNDING = "rne"


@dataclass(frozen=True)
class PiecewiseDesign:
    """A sized ROM + Horner evaluator of a uniform :class:`PiecewiseTable`.

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

    @property
    def module_name(self) -> str:
        return f"chebnorm_{self.name}"

    @property
    def degree(self) -> int:
        return self.table.degree

    @property
    def index_bits(self) -> int:
        return self.table.index_bits

    def _rom(self, dtype=np.int64) -> np.ndarray:
        return np.array([seg.integers for seg in self.table.segments], dtype=dtype)

    def _t(self, k: np.ndarray) -> np.ndarray:
        low = k & ((1 << self.local_bits) - 1)
        return low - (1 << (self.local_bits - 1)) if self.table.centered else low

    def evaluate(self, codes=None, *, wires: bool = False):
        """Output codes for input ``codes`` (default: all ``2**in_bits``)."""
        k = np.arange(2 ** self.in_bits, dtype=np.int64) if codes is None \
            else np.asarray(codes, dtype=np.int64)
        w = _run(self, k, self.acc_frac_bits, self.y_format.frac_bits)
        raw = w["rounded"] - self.y_format.offset_code
        w["raw"] = raw
        w["y"] = np.clip(raw, 0, self.y_format.max_code)
        return w if wires else w["y"]

    def x_values(self, codes) -> list[Fraction]:
        lo, hi = (_exact(v) for v in self.table.interval)
        return [lo + (hi - lo) * Fraction(int(c), 2 ** self.in_bits) for c in codes]

    def budget(self) -> dict:
        """Certified bound of ``|y - f(x)|`` over all codes, by part (floats rounded up)."""
        tmax = Fraction(1, 2) if self.table.centered else Fraction(1)
        fa = self.acc_frac_bits
        steps = [rounding_error_bound(fa, self.rounding) * tmax ** j
                 for j in range(1, self.degree)]
        out = rounding_error_bound(self.y_format.frac_bits, self.rounding)
        approx = Fraction(self.table.abs_error_bound)
        total = approx + sum(steps, Fraction(0)) + out
        return {"approximation": self.table.abs_error_bound,
                "horner_rounding": float_up(sum(steps, Fraction(0))), "output_rounding": float_up(out),
                "total": float_up(total), "y_lsb": float(Fraction(1, 2 ** self.y_format.frac_bits))}

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


def _run(d, k, fa, fy) -> dict:
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


def design_piecewise(table: PiecewiseTable, in_bits: int, out_bits: int, *,
                     guard_bits: int = 2, name: str | None = None) -> PiecewiseDesign:
    """Size the ROM + Horner evaluator of a uniform piecewise ``table``.

    ``in_bits`` must exceed the table's index bits (the rest is the local
    variable); the accumulators carry ``y_frac_bits + guard_bits`` fractional
    bits. Raises ValueError naming the value and the accepted range.

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
    ValueError: in-bits = 2 is out of range; accepted: 3 <= in-bits <= 20
    """
    if not isinstance(table, PiecewiseTable):
        raise ValueError("design_piecewise needs a PiecewiseTable")
    if table.segment_by != "uniform":
        raise ValueError(f"table {table.name!r} is segmented by {table.segment_by}; accepted "
                         f"for hardware: a uniform table (the input code's top bits index it)")
    in_bits = check_width(in_bits, "in-bits", table.index_bits + 1, MAX_PW_IN_BITS)
    out_bits = check_width(out_bits, "out-bits", 1, MAX_PW_OUT_BITS)
    guard_bits = check_width(guard_bits, "guard-bits", 0, 16)
    name = identifier(name or table.name, field="name")
    for v in table.interval:
        _exact(v)
    L = in_bits - table.index_bits
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
    for fy in range(min(fy_max, 60), -60, -1):
        fa = fy + guard_bits
        w = _run(proto, k, fa, fy)
        r = w["rounded"]
        y_off = int(r.min())
        if int(r.max()) - y_off <= 2 ** out_bits - 1:
            break
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
    return PiecewiseDesign(name, table, in_bits, out_bits, L, fa,
                           QFormat(out_bits, fy, offset_code=y_off), rom_bits, L + 2,
                           tuple(widths), int(w["top_frac"]))


# -- HDL (printed by chebnorm.hw.hdl) ----------------------------------------------

def piecewise_verilog(d: PiecewiseDesign, *, version: str = "", command: str | None = None) -> str:
    """The synthesizable Verilog-2005 module: ROM (a case on the index) + Horner
    (:func:`chebnorm.hw.hdl.module_text` in Verilog).

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


def piecewise_testbench(d: PiecewiseDesign, language: str = "verilog") -> str:
    """The exhaustive self-checking bench (expected codes from :meth:`evaluate`).

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8)
    >>> piecewise_testbench(d).splitlines()[0]
    '// tb_chebnorm_rs: exhaustive self-checking test bench of chebnorm_rs.'
    """
    return testbench_text(d, language)


def piecewise_outputs(d: PiecewiseDesign, *, version: str = "", command: str | None = None,
                      language: str = "verilog") -> dict[str, str]:
    """``{file name: text}``: the module, its bench and the expected-output
    vectors, in ``language`` (``"verilog"`` or ``"vhdl"``;
    :func:`chebnorm.hw.hdl.hdl_files`).

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
    """Yosys ``synth; stat`` of the module (a :class:`~chebnorm.hw.verilog.SynthResult`)."""
    return synthesize_text(piecewise_verilog(d), d.module_name)


def simulate_piecewise(d: PiecewiseDesign, directory):
    """Write the outputs into ``directory`` and run the bench in Icarus Verilog."""
    from pathlib import Path

    from chebnorm.core.files import write_folder

    write_folder(Path(directory), piecewise_outputs(d))
    return simulate(directory, d)
