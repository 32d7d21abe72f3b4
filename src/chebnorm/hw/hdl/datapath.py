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

from .common import (horner_facts, module_name, piecewise_facts, pipelined_name, shifted_width,
                     step_comment, variable_name)
from .netlist import (Add, And, Assign, Bit, BitVec, Comment, Concat, Const, ConstDecl, Cut,
                      Extend, Gate, Group, Module, Mul, Neg, Not, Or, Paren, ReduceOr, Resize, Rom, Saturate, Shl, Shr, Signal, Slice, Sub, ZeroExt)
from .._docfrag import hw_doc

# an implementation module of chebnorm.hw.hdl: the API is what chebnorm.hw.hdl exports
__all__: list[str] = []


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
    inc = Signal(f"{dst}_inc", 1, logic=True, scalar=True)
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


def _rom(d, m: Module, cols: list, rows) -> list:
    """The coefficient ROM: ``c_j`` of the segment the top bits of ``x`` index
    (one segment: the constants themselves)."""
    L, K = d.local_bits, d.index_bits
    if K == 0:  # one segment: constants (a case on no input would never run)
        return [Assign(c, _const(rows[0][j], c.width)) for j, c in enumerate(cols)]
    return [Rom(Signal("idx", K), Slice(m.x, d.in_bits - 1, L), tuple(cols),
                tuple(tuple(int(q) for q in row) for row in rows))]


@hw_doc
def piecewise_netlist(d, *, version: str = "", command: str | None = None) -> Module:
    """The netlist of a (one-width) piecewise design ``d``: the coefficient
    ROM indexed by the top bits of ``x`` and one Horner datapath in the local
    variable ``t``, rounding after each multiply-add, the saturating output,
    and a register stage at each cut point (``0`` in ``d.cuts``: after the ROM
    read; ``i`` in ``d.mult_cuts``: after step ``i``'s multiply; ``i`` in
    ``d.cuts``: after its add and rounding), the values ``d.latency`` cycles later.

    Parameters
    ----------
    d : PiecewiseDesign
        The piecewise design (:func:`~chebnorm.hw.piecewise.design_piecewise`), not sized.
    %(version)s
    %(command)s

    Returns
    -------
    Module
        The netlist (latency ``d.latency``).
    """
    t = d.table
    n, L, fc = t.degree, d.local_bits, t.coef_frac_bits
    m = Module(module_name(d), d.in_bits, d.out_bits, latency=d.latency,
               facts=piecewise_facts(d, version=version, command=command))
    out = m.statements
    low = Signal("low", L, logic=True)
    tv = _sig("t", d.t_bits)
    code = ZeroExt(low, zeros=2)
    out += [Assign(low, Slice(m.x, L - 1, 0)),
            Assign(tv, Sub(code, Const(1 << (L - 1), tv.width)) if t.centered else code)]
    cols = [_sig(f"c{j}", d.rom_bits[j]) for j in range(n + 1)]
    out += _rom(d, m, cols, [seg.integers for seg in t.segments])
    if 0 in d.cuts:
        out.append(Cut(0))
    prev, prev_frac = cols[n], fc
    for i, j in enumerate(range(n - 1, -1, -1)):
        pw, sw, ow = d.widths[i]
        pf = prev_frac + L
        sf = max(pf, fc)
        p, s = _sig(f"p{j}", pw), _sig(f"s{j}", sw)
        out += [Comment(f"step {j}: a{j} = R(a{j + 1} * t + c{j}), {sf} fractional bits"),
                Assign(p, Resize(Mul(prev, tv), pw))]
        if i + 1 in d.mult_cuts:  # a register between the multiply and the add
            out.append(Cut(f"m{i + 1}"))
        # the sum taken mod 2^sw: the same bits as in Verilog's wider context
        terms = tuple(Group(Shl(Resize(v, sw), sh) if sh else Resize(v, sw))
                      for v, sh in ((p, sf - pf), (cols[j], sf - fc)))
        out.append(Assign(s, Add(terms)))
        if j > 0:
            f_out = min(d.acc_frac_bits, sf)
            if sf > f_out:
                out += round_to(s, f"a{j}", sf - f_out, ow, d.rounding)
            else:
                out.append(Assign(_sig(f"a{j}", ow), Resize(s, ow)))
            prev, prev_frac = _sig(f"a{j}", ow), f_out
        else:
            prev, prev_frac = s, sf
        if i + 1 in d.cuts:
            out.append(Cut(i + 1))
    out += output_stage(prev, prev_frac, d.y_format, d.out_bits, d.rounding)
    return m


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


@hw_doc
def sized_piecewise_netlist(d, *, version: str = "", command: str | None = None) -> Module:
    """The netlist of a sized piecewise design ``d`` (``d.sized``): ROM
    columns of their own widths, each Horner step multiplying by the top
    ``T_j`` bits of ``t`` (full or truncated multiplier), products and sums
    truncated by arithmetic shifts, and a register stage at each cut point
    (``d.cuts``, ``d.mult_cuts``): bit for bit
    :meth:`~chebnorm.hw.piecewise.PiecewiseDesign.evaluate`.

    Parameters
    ----------
    %(sized_piecewise)s
    %(version)s
    %(command)s

    Returns
    -------
    Module
        The netlist (latency ``d.latency``).
    """
    t = d.table
    n, L = t.degree, d.local_bits
    m = Module(module_name(d), d.in_bits, d.out_bits,
               facts=piecewise_facts(d, version=version, command=command), latency=d.latency)
    out = m.statements
    x = m.x
    low = Signal("low", L, logic=True)
    out.append(Assign(low, Slice(x, L - 1, 0)))
    cols = [_sig(f"c{j}", d.rom_bits[j]) for j in range(n + 1)]
    out += _rom(d, m, cols, d.coefficients)
    a = cols[n]   # the accumulator: c_n, then a_j
    if 0 in d.cuts:
        out.append(Cut(0))
    for i, st in enumerate(d.sized_signals(), start=1):
        j, T = st["j"], st["T"]
        out.append(Comment(f"step {j}: a{j} = (((a{j + 1} * t{j}) {{shr}} {st['pshift']}) {{shl}} "
                           f"{st['qshift']} + c{j} {{shl}} {st['cshift']}) {{shr}} {st['ashift']}, "
                           f"t{j} = top {T} bits of t"
                           + (", truncated multiplier" if st["rows"] else "")))
        tj = _sig(f"t{j}", st["tw"])
        if t.centered:   # the top bit inverted is the sign of t - 1/2
            top = (Not(BitVec(low, L - 1)),) + ((Slice(low, L - 2, L - T),) if T > 1 else ())
            out.append(Assign(tj, Concat(top)))
        else:
            out.append(Assign(tj, ZeroExt(Slice(low, L - 1, L - T))))
        q = _sig(f"q{j}", st["qw"])
        if st["rows"]:
            out += _truncated_rows(st, a, low)
        else:
            p = _sig(f"p{j}", st["pw"])
            ps = st["pshift"]
            out += [Assign(p, Resize(Mul(a, tj), p.width)),
                    Assign(q, Resize(Shr(p, ps), q.width) if ps > 0 else
                           Shl(Resize(p, q.width), -ps) if ps < 0 else Resize(p, q.width))]
        if i in d.mult_cuts:  # a register between the multiply and the add
            out.append(Cut(f"m{i}"))
        c = cols[j]
        ctx = max(st["qw"], st["sw"], c.width)
        qv = Group(Shl(Resize(q, ctx), st["qshift"])) if st["qshift"] else Resize(q, ctx)
        cv = Group(Shl(Resize(c, ctx), st["cshift"]) if st["cshift"] else Resize(c, ctx))
        s = _sig(f"s{j}", st["sw"])
        out.append(Assign(s, Resize(Add((qv, cv)), s.width)))
        a = _sig(f"a{j}", st["aw"])
        out.append(Assign(a, Resize(Shr(s, st["ashift"]), a.width) if st["ashift"]
                          else Resize(s, a.width)))
        if i in d.cuts:
            out.append(Cut(i))
    if n == 0:
        f0, g0 = d.coef_frac[0], d.acc_frac[0]
        wide = Resize(cols[0], d.rom_bits[0] + max(0, g0 - f0))
        a = _sig("a0", wide.width)
        out.append(Assign(a, Shr(wide, f0 - g0) if f0 > g0 else
                          Shl(wide, g0 - f0) if g0 > f0 else wide))
    out += output_stage(a, d.y_format.frac_bits, d.y_format, d.out_bits, "trunc")
    return m


def _const(value, width):
    return Const(int(value), width)


def _variable(design, xs: Signal, v: str) -> list:
    """The Horner variable of a one-parity design, ``v = R(xs * xs)``, or of a
    shifted one, ``v = (xs << m) - C``; nothing for plain Horner in ``x``."""
    if design.scheme == "monomial":
        return []
    vw = design.variable_bits
    if design.scheme == "shifted":
        sw, m = shifted_width(design), design.v_shift
        c, d = _sig(f"{v}_C", sw), _sig(f"{v}_d", sw)
        wide = Group(Shl(Resize(xs, sw), m)) if m else Resize(xs, sw)
        return [Comment(f"{v} = (x - c') / s times 2^{design.variable_frac_bits}, c' = "
                        f"{design.v_offset} / 2^{design.x_format.frac_bits + m}"),
                ConstDecl(c, design.v_offset), Assign(d, Sub(wide, c)),
                Assign(_sig(v, vw), Resize(d, vw))]
    rs = design.v_round_shift
    sq = _sig(f"{v}_sq", 2 * design.xs_bits)
    out = [Comment(f"{v}: x*x with {design.variable_frac_bits} fractional bits "
                   f"({'rounded' if rs else 'exact'}); Horner's rule over the {design.scheme} "
                   f"powers in it"),
           Assign(sq, Mul(xs, xs))]
    if rs:
        return out + round_to(sq, v, rs, vw, design.rounding)
    return out + [Assign(_sig(v, vw), Resize(sq, vw))]


def _horner_step(design, st, prev: Signal, xs: Signal) -> list:
    """One Horner step ``a_j = R(a_{j+1} * x + q_j)`` (``prev``: a_{j+1})."""
    j = st.power
    p, c, t = _sig(f"p{j}", st.product_bits), _sig(f"C{j}", st.sum_bits), _sig(f"t{j}", st.sum_bits)
    wide = Resize(p, st.sum_bits)
    out = [Comment(f"step {j}: {step_comment(design, st)} with {st.sum_frac_bits} -> "
                   f"{st.out_frac_bits} fractional bits"),
           Assign(p, Resize(Mul(prev, xs), p.width)), ConstDecl(c, st.coef_shifted),
           Assign(t, Add((Group(Shl(wide, st.product_shift) if st.product_shift else wide), c)))]
    if j > 0:
        out += round_to(t, f"a{j}", st.round_shift, st.out_bits, design.rounding)
    return out


@hw_doc
def horner_netlist(design, *, pipelined: bool = False, language: str | None = None,
                   version: str = "", command: str | None = None, budget=None) -> Module:
    """The netlist of a Horner evaluator
    (:class:`~chebnorm.hw.horner.HornerDesign`): the input code offset to
    ``x``'s value, the Horner variable (``x``, ``x*x`` or ``(x - c')/s``), one
    multiply-add-round per step, the saturating output; with ``pipelined`` a
    register stage after each step (``x`` and ``v`` travel beside the
    accumulator when a later step reads them) and one on the last sum,
    latency ``design.steps``: the combinational netlist with cuts
    (:func:`~chebnorm.hw.hdl.netlist.schedule` places the registers).

    Parameters
    ----------
    %(horner_design)s
    pipelined : bool, default False
        The pipelined variant ``chebnorm_NAME_pipe`` (degree >= 1).
    language : {"verilog", "vhdl"} or None, default None
        The banner's language (it names parameters or generics); None: both.
    %(version)s
    %(command)s
    budget : ErrorBudget or None, default None
        The certified budget stated in the banner; None: not stated.

    Returns
    -------
    Module
        The netlist.

    Raises
    ------
    ValueError
        If ``pipelined`` is asked for a degree-0 design.
    """
    if pipelined and design.degree < 1:
        raise ValueError(f"design {design.name!r} has degree 0: nothing to pipeline; accepted: "
                         f"degree >= 1")
    facts = {lang: horner_facts(design, lang, version=version, command=command, budget=budget,
                                pipelined=pipelined)
             for lang in ((language,) if language else ("verilog", "vhdl"))}
    m = Module(pipelined_name(design) if pipelined else module_name(design), design.in_bits,
               design.out_bits, facts=facts, latency=design.steps if pipelined else 0)
    out = []
    xf, xw = design.x_format, design.xs_bits
    k0, xs = _sig("K0", xw), _sig("xs", xw)
    out += [Comment(f"x value times 2^{xf.frac_bits}"), ConstDecl(k0, xf.offset_code),
            Assign(xs, Add((Resize(ZeroExt(m.x, char=True), xw), k0)))]
    out += _variable(design, xs, "v")
    n = len(design.horner_integers) - 1
    if n == 0:
        top = _sig("top", max(design.top_bits, 2))
        out.append(Assign(top, Const(int(design.integers[0]), top.width)))
        top_frac = design.coef_frac_bits
    else:
        aw = max(design.stages[0].acc_bits, 2)
        prev = _sig(f"A{n}", aw)
        out.append(ConstDecl(prev, design.horner_integers[n]))
        var = {"xs": xs, "v": _sig("v", design.variable_bits)}
        for s, st in enumerate(design.stages):
            j = st.power
            out += _horner_step(design, st, prev, var[variable_name(design, st)])
            if j > 0:
                prev = _sig(f"a{j}", st.out_bits)
                if pipelined:   # a register stage after each step
                    out.append(Cut(s + 1))
        last = design.stages[-1]
        top, top_frac = _sig("top", last.sum_bits), last.sum_frac_bits
        if pipelined:
            out.append(Cut(len(design.stages)))
        out.append(Assign(top, _sig("t0", last.sum_bits)))
    out += output_stage(top, top_frac, design.y_format, design.out_bits, design.rounding,
                        min_bits=design.raw_bits)
    m.statements[:] = out
    return m
