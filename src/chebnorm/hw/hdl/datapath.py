"""Designs as netlists (:mod:`chebnorm.hw.hdl.netlist`): each datapath is
built once, and :func:`~chebnorm.hw.hdl.netlist.verilog` and
:func:`~chebnorm.hw.hdl.netlist.vhdl` print it.

* :func:`round_to` -- ``dst = R(src / 2^shift)``, floor or round to nearest even;
* :func:`output_stage` -- round the last sum to y's fractional bits, remove
  y's offset code, saturate into the port ``y``;
* :func:`sized_piecewise_netlist` -- the sized piecewise evaluator (ROM,
  truncated Horner steps, pipeline registers at the design's cut points).

>>> from chebnorm.approx.piecewise_fit import piecewise_fit
>>> from chebnorm.hw.piecewise import design_piecewise
>>> from chebnorm.hw.hdl.netlist import evaluate
>>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=4, coef_frac_bits=16, name="rs")
>>> d = design_piecewise(t, 8, 8, widths="auto", max_error=2 ** -5)
>>> m = sized_piecewise_netlist(d)
>>> [evaluate(m, k)["y"] for k in range(4)] == d.evaluate()[:4].tolist()
True
"""

from __future__ import annotations

from .common import module_name, piecewise_facts
from .netlist import (Add, And, Assign, Bit, BitVec, Comment, Concat, ConstDecl, Extend, Gate,
                      Group, Module, Mul, Neg, Not, Or, Paren, ReduceOr, Registers, Resize, Rom,
                      Saturate, Shl, Shr, Signal, Slice, Sub, ZeroExt)

__all__ = ["round_to", "output_stage", "sized_piecewise_netlist"]


def _sig(name: str, width: int) -> Signal:
    return Signal(name, width, signed=True)


def round_to(src: Signal, dst: str, shift: int, dst_bits: int, mode: str) -> list:
    """Statements declaring ``dst = R(src / 2^shift)``: ``mode`` ``"trunc"``
    (floor, an arithmetic shift) or ``"rne"`` (round to nearest, ties to even,
    from the guard bit, the sticky bits and the kept LSB), as
    :func:`chebnorm.hw.fixed.shift_round` computes it.

    Parameters
    ----------
    src : Signal
        The signed value.
    dst : str
        The rounded signal's name (``DST_q``, ``DST_inc``, ``DST_x`` are declared too).
    shift : int
        Bits to drop, ``>= 0``.
    dst_bits : int
        Width of ``dst`` (wide enough for the rounded value plus the increment).
    mode : {"trunc", "rne"}
        The rounding.

    Returns
    -------
    list
        Netlist statements; the last declares ``dst``.
    """
    out = []
    if mode != "trunc" and shift + 1 > src.width:   # the round bit lies above src: extend it
        x = _sig(f"{dst}_x", shift + 1)
        out.append(Assign(x, Extend(src, shift + 1)))
        src = x
    q = _sig(f"{dst}_q", src.width)
    out.append(Assign(q, Shr(src, shift)))
    if mode == "trunc" or shift == 0:  # nothing dropped: nothing to round
        return out + [Assign(_sig(dst, dst_bits), Resize(q, dst_bits))]
    inc = Signal(f"{dst}_inc", 1, logic=True)
    kept = Bit(q, 0)
    if shift >= 2:
        kept = Or(Paren(ReduceOr(Slice(src, shift - 2, 0))), kept)
    out.append(Assign(inc, And(Bit(src, shift - 1), Paren(kept))))
    w = max(dst_bits, src.width, 2)
    return out + [Assign(_sig(dst, dst_bits),
                         Resize(Add((Resize(q, w), ZeroExt(inc, qualified=True))), dst_bits))]


def output_stage(top: Signal, top_frac: int, y_format, out_bits: int, rounding: str, *,
                 min_bits: int = 0) -> list:
    """The evaluator's last statements: round ``top`` (``top_frac``
    fractional bits) to ``y_format``'s, subtract its offset code and saturate
    into ``y``. The working width is the smallest that holds every step, and
    at least ``min_bits``.

    Parameters
    ----------
    top : Signal
        The last sum (signed).
    top_frac : int
        Its fractional bits.
    y_format : QFormat
        The output format (fractional bits, offset code, ``max_code``).
    out_bits : int
        Width of ``y``.
    rounding : {"trunc", "rne"}
        Rounding to ``y_format.frac_bits`` when ``top_frac`` is larger.
    min_bits : int, default 0
        A lower bound of the working width.

    Returns
    -------
    list
        Netlist statements, ending with :class:`~chebnorm.hw.hdl.netlist.Saturate`.
    """
    shift = top_frac - y_format.frac_bits
    rw = max(min_bits, top.width + max(0, -shift) + 1, out_bits + 2,
             y_format.offset_code.bit_length() + 2)
    out = [Comment(f"output: round to {y_format.frac_bits} fractional bits, remove the offset, "
                   f"saturate")]
    r = _sig("r", rw)
    if shift > 0:
        out += round_to(top, "r", shift, rw, rounding)
    elif shift == 0:
        out.append(Assign(r, Resize(top, rw)))
    else:
        out.append(Assign(r, Shl(Resize(top, rw), -shift)))
    ky, ymax, raw = _sig("KY", rw), _sig("YMAX", rw), _sig("raw", rw)
    return out + [ConstDecl(ky, y_format.offset_code), ConstDecl(ymax, y_format.max_code),
                  Assign(raw, Sub(r, ky)), Saturate(raw, ymax)]


def _truncated_rows(st: dict, a: Signal, low: Signal) -> list:
    """The truncated multiplier ``q_j`` of a sized step: one row per bit of
    ``t_j``'s code, ``a`` floored at column ``P`` (an arithmetic shift), gated by
    the bit (the inverted top bit, negated row, when ``t`` is centred), all rows
    added modulo ``2^qw`` (the exact sum fits ``qw`` bits)."""
    j, qw, aw = st["j"], st["qw"], a.width
    out, terms = [], []
    na = _sig(f"na{j}", aw + 1)
    if any(neg for _, _, neg in st["rows"]):
        out.append(Assign(na, Neg(Resize(a, aw + 1))))
    for i, sh, neg in st["rows"]:
        src = na if neg else a
        wide = max(src.width, qw)
        expr = (Resize(Shr(Resize(src, wide), sh), qw) if sh > 0 else
                Shl(Resize(src, qw), -sh) if sh < 0 else Resize(src, qw))
        r, m = _sig(f"r{j}_{i}", qw), _sig(f"m{j}_{i}", qw)
        out += [Assign(r, expr), Assign(m, Gate(r, Bit(low, st["tshift"] + i), on=not neg))]
        terms.append(m)
    out.append(Assign(_sig(f"q{j}", qw), terms[0] if len(terms) == 1 else Add(tuple(terms))))
    return out


def sized_piecewise_netlist(d, *, version: str = "", command: str | None = None) -> Module:
    """The netlist of a sized piecewise design ``d`` (``d.sized``): ROM
    columns of their own widths, each Horner step multiplying by the top
    ``T_j`` bits of ``t`` (full or truncated multiplier), products and sums
    truncated by arithmetic shifts, and a register stage at each cut point
    (``d.cuts``, ``d.mult_cuts``): bit for bit
    :meth:`~chebnorm.hw.piecewise.PiecewiseDesign.evaluate`.

    Parameters
    ----------
    d : PiecewiseDesign
        A sized piecewise design (``design_piecewise(..., widths="auto")``, ``d.sized``).
    version : str, default ""
        chebnorm's version, stated in the banner (made comment-safe).
    command : str or None, default None
        The command line that made the file, stated in the banner (made comment-safe);
        None or empty: no such line.

    Returns
    -------
    Module
        The netlist (latency ``d.latency``).
    """
    t = d.table
    n, L, K = t.degree, d.local_bits, d.index_bits
    m = Module(module_name(d), d.in_bits, d.out_bits,
               facts=piecewise_facts(d, version=version, command=command), latency=d.latency)
    out = m.statements
    x = m.x
    low = Signal("low", L, logic=True)
    out.append(Assign(low, Slice(x, L - 1, 0)))
    cols = [_sig(f"c{j}", d.rom_bits[j]) for j in range(n + 1)]
    if K == 0:
        out += [Assign(c, _const(d.coefficients[0][j], c.width)) for j, c in enumerate(cols)]
    else:
        out.append(Rom(Signal("idx", K), Slice(x, d.in_bits - 1, L), tuple(cols),
                       tuple(tuple(int(q) for q in row) for row in d.coefficients)))
    # live signals, in order: name -> the signal that carries it now; registered at each cut
    cur = {"low": low, **{c.name: c for c in cols}}
    acc = f"c{n}"

    def cut(stage) -> None:
        pairs = []
        for key, s in cur.items():
            r = Signal(f"{key}_r{stage}", s.width, s.signed, s.logic)
            pairs.append((r, s))
            cur[key] = r
        out.append(Registers(tuple(pairs)))

    if 0 in d.cuts:
        cut(0)
    for i, st in enumerate(d.sized_signals(), start=1):
        j, T = st["j"], st["T"]
        lo = cur["low"]
        out.append(Comment(f"step {j}: a{j} = (((a{j + 1} * t{j}) {{shr}} {st['pshift']}) {{shl}} "
                           f"{st['qshift']} + c{j} {{shl}} {st['cshift']}) {{shr}} {st['ashift']}, "
                           f"t{j} = top {T} bits of t"
                           + (", truncated multiplier" if st["rows"] else "")))
        tj = _sig(f"t{j}", st["tw"])
        if t.centered:   # the top bit inverted is the sign of t - 1/2
            top = (Not(BitVec(lo, L - 1)),) + ((Slice(lo, L - 2, L - T),) if T > 1 else ())
            out.append(Assign(tj, Concat(top)))
        else:
            out.append(Assign(tj, ZeroExt(Slice(lo, L - 1, L - T))))
        a = cur[acc]
        q = _sig(f"q{j}", st["qw"])
        if st["rows"]:
            out += _truncated_rows(st, a, lo)
        else:
            p = _sig(f"p{j}", st["pw"])
            ps = st["pshift"]
            out += [Assign(p, Resize(Mul(a, tj), p.width)),
                    Assign(q, Resize(Shr(p, ps), q.width) if ps > 0 else
                           Shl(Resize(p, q.width), -ps) if ps < 0 else Resize(p, q.width))]
        if i in getattr(d, "mult_cuts", ()):  # a register between the multiply and the add
            cur.pop(acc, None)
            if j == 0:
                cur.pop("low", None)
            cur[q.name] = q
            cut(f"m{i}")
            q = cur.pop(q.name)
        c = cur.pop(f"c{j}")
        ctx = max(st["qw"], st["sw"], c.width)
        qv = Group(Shl(Resize(q, ctx), st["qshift"])) if st["qshift"] else Resize(q, ctx)
        cv = Group(Shl(Resize(c, ctx), st["cshift"]) if st["cshift"] else Resize(c, ctx))
        s = _sig(f"s{j}", st["sw"])
        out.append(Assign(s, Resize(Add((qv, cv)), s.width)))
        aj = _sig(f"a{j}", st["aw"])
        out.append(Assign(aj, Resize(Shr(s, st["ashift"]), aj.width) if st["ashift"]
                          else Resize(s, aj.width)))
        cur.pop(acc, None)
        acc = aj.name
        cur[acc] = aj
        if j == 0:
            cur.pop("low", None)
        if i in d.cuts:
            cut(i)
    if n == 0:
        f0, g0 = d.coef_frac[0], d.acc_frac[0]
        wide = Resize(cur["c0"], d.rom_bits[0] + max(0, g0 - f0))
        a0 = _sig("a0", wide.width)
        out.append(Assign(a0, Shr(wide, f0 - g0) if f0 > g0 else
                          Shl(wide, g0 - f0) if g0 > f0 else wide))
        cur[acc] = a0
    top = cur[acc]
    out += output_stage(top, d.y_format.frac_bits, d.y_format, d.out_bits, "trunc")
    return m


def _const(value, width):
    from .netlist import Const
    return Const(int(value), width)
