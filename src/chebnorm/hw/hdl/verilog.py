"""Verilog printers: the evaluator of a :class:`~chebnorm.hw.horner.HornerDesign`
(combinational and pipelined) and of a
:class:`~chebnorm.hw.piecewise.PiecewiseDesign` (ROM + Horner), their
self-checking test benches, and the text fragments they (and the
normalization units of :mod:`chebnorm.hw.units`) share.

The module follows one port contract::

    module chebnorm_NAME #(parameter IN_BITS = W, parameter OUT_BITS = V)
        (input wire [IN_BITS-1:0] x, output wire [OUT_BITS-1:0] y);

combinational, unsigned codes, formats in the header comment
(:mod:`chebnorm.hw.hdl.common`). The widths are parameters so that
instantiations read naturally, but the constants inside were sized for the
generated values: regenerate to change them.

The test bench reads the expected output of every input code, made by the
Python bit-accurate model, from ``chebnorm_NAME.hex`` (``$readmemh``),
counts mismatches and prints one ``PASS:``/``FAIL:`` line. The fragments
return Verilog-2005 source lines (indented four spaces, no trailing
newline); the widths are the callers' (sized from exact ranges), the
fragments only range-check the constants they print.
"""

from __future__ import annotations

from ..fixed import QFormat
from ..horner import HornerDesign
from .common import (shifted_width, step_comment, variable_name)
from .common import (comment_lines, horner_facts, module_name, piecewise_facts, pipelined_name,
                     vectors_name)

# an implementation module of chebnorm.hw.hdl: the API is what chebnorm.hw.hdl exports
__all__: list[str] = []


# -- fragments -------------------------------------------------------------------
def signed_literal(value: int, bits: int) -> str:
    """A sized signed decimal literal ``[-]BITS'sdMAGNITUDE``.

    Raises ValueError when ``value`` does not fit a signed ``bits``-bit word.

    >>> signed_literal(5, 4), signed_literal(-8, 4)
    ("4'sd5", "-4'sd8")
    >>> signed_literal(8, 4)
    Traceback (most recent call last):
    ...
    ValueError: constant 8 does not fit a signed 4-bit literal

    Parameters
    ----------
    value : int
        The constant.
    bits : int
        The literal's width, ``>= 1``; ``value`` must lie in ``[-2**(bits-1), 2**(bits-1) - 1]``.

    Returns
    -------
    str
        The literal, e.g. ``"4'sd5"`` or ``"-4'sd8"``.

    Raises
    ------
    ValueError
        If ``value`` does not fit a signed ``bits``-bit word.
    """
    if not -(1 << (bits - 1)) <= value < (1 << (bits - 1)):
        raise ValueError(f"constant {value} does not fit a signed {bits}-bit literal")
    return f"{'-' if value < 0 else ''}{bits}'sd{abs(value)}"


def round_lines(src: str, dst: str, src_bits: int, shift: int, dst_bits: int,
                mode: str) -> list[str]:
    """Lines declaring ``dst = R(src / 2^shift)``: ``mode`` ``"trunc"`` (floor,
    an arithmetic shift) or ``"rne"`` (round to nearest, ties to even, from
    the guard bit, the sticky bits and the kept LSB), as
    :func:`chebnorm.hw.fixed.shift_round` computes it. ``shift >= 1``.

    >>> print("\\n".join(round_lines("s", "a", 12, 3, 10, "rne")))
        wire signed [11:0] a_q = s >>> 3;
        wire a_inc = s[2] & ((|s[1:0]) | a_q[0]);
        wire signed [9:0] a = a_q + $signed({1'b0, a_inc});
    >>> round_lines("s", "a", 12, 1, 11, "trunc")[-1]
    '    wire signed [10:0] a = a_q;'

    Parameters
    ----------
    src : str
        The signed wire to round.
    dst : str
        The name of the rounded wire (``DST_q`` and ``DST_inc`` are declared too).
    src_bits : int
        Width of ``src``.
    shift : int
        Bits to drop, ``>= 0``.
    dst_bits : int
        Width of ``dst`` (wide enough for the rounded value plus the increment).
    mode : {"trunc", "rne"}
        Rounding mode (:data:`~chebnorm.hw.fixed.ROUNDINGS`).

    Returns
    -------
    list of str
        Verilog declaration lines, indented by four spaces.
    """
    lines = []
    if mode != "trunc" and shift + 1 > src_bits:   # the round bit lies above src: extend it
        lines.append(f"    wire signed [{shift}:0] {dst}_x = {src};")
        src, src_bits = f"{dst}_x", shift + 1
    lines.append(f"    wire signed [{src_bits - 1}:0] {dst}_q = {src} >>> {shift};")
    if mode == "trunc" or shift == 0:  # nothing dropped: nothing to round
        lines.append(f"    wire signed [{dst_bits - 1}:0] {dst} = {dst}_q;")
        return lines
    sticky = f"(|{src}[{shift - 2}:0]) | " if shift >= 2 else ""
    lines.append(f"    wire {dst}_inc = {src}[{shift - 1}] & ({sticky}{dst}_q[0]);")
    lines.append(f"    wire signed [{dst_bits - 1}:0] {dst} = {dst}_q + $signed({{1'b0, {dst}_inc}});")
    return lines


def saturating_output(top: str, top_bits: int, top_frac: int, y_format: QFormat, out_bits: int,
                      rounding: str, *, min_bits: int = 0) -> list[str]:
    """The evaluator's last lines, through ``endmodule``: round the signed
    wire ``top`` (``top_bits`` wide, ``top_frac`` fractional bits) to
    ``y_format``'s fractional bits, subtract its offset code and saturate
    into the ``OUT_BITS``-wide unsigned port ``y``. The working width is the
    smallest that holds every step, and at least ``min_bits``.

    >>> lines = saturating_output("t0", 14, 12, QFormat(8, 8, offset_code=256), 8, "rne")
    >>> print("\\n".join(lines[-4:-2]))
        wire signed [14:0] raw = r - KY;
        assign y = raw[14] ? {OUT_BITS{1'b0}} : (raw > YMAX) ? {OUT_BITS{1'b1}} : raw[OUT_BITS-1:0];

    Parameters
    ----------
    top : str
        The last sum's signed wire.
    top_bits : int
        Its width.
    top_frac : int
        Its fractional bits.
    y_format : QFormat
        The output format (fractional bits, offset code, ``max_code``).
    out_bits : int
        Width of the output port ``y``.
    rounding : {"trunc", "rne"}
        Rounding to ``y_format.frac_bits`` when ``top_frac`` is larger.
    min_bits : int, default 0
        A lower bound of the working width.

    Returns
    -------
    list of str
        Verilog lines, ending with ``endmodule`` and an empty line.

    Raises
    ------
    ValueError
        If the offset code or ``max_code`` does not fit the working width (not expected: the
        width is chosen to hold them).
    """
    shift = top_frac - y_format.frac_bits
    rw = max(min_bits, top_bits + max(0, -shift) + 1, out_bits + 2,
             y_format.offset_code.bit_length() + 2)
    if shift > 0:
        out = round_lines(top, "r", top_bits, shift, rw, rounding)
    elif shift == 0:
        out = [f"    wire signed [{rw - 1}:0] r = {top};"]
    else:
        out = [f"    wire signed [{rw - 1}:0] r = {top} <<< {-shift};"]
    out += [f"    localparam signed [{rw - 1}:0] KY = {signed_literal(y_format.offset_code, rw)};",
            f"    localparam signed [{rw - 1}:0] YMAX = {signed_literal(y_format.max_code, rw)};",
            f"    wire signed [{rw - 1}:0] raw = r - KY;",
            f"    assign y = raw[{rw - 1}] ? {{OUT_BITS{{1'b0}}}} : "
            f"(raw > YMAX) ? {{OUT_BITS{{1'b1}}}} : raw[OUT_BITS-1:0];",
            "endmodule", ""]
    return out


def bench_verdict(name: str) -> list[str]:
    """The last lines of an exhaustive test bench of ``name`` that counted
    ``errors`` over ``COUNT`` vectors: print the one ``PASS:``/``FAIL:`` line
    the simulation runners read, then ``$finish``.

    >>> print("\\n".join(bench_verdict("chebnorm_f")[:2]))
            if (errors == 0)
                $display("PASS: %0d vectors, 0 mismatches (chebnorm_f)", COUNT);

    Parameters
    ----------
    name : str
        The module name printed in the verdict (an identifier).

    Returns
    -------
    list of str
        Verilog lines, ending with ``endmodule`` and an empty line.
    """
    return ["        if (errors == 0)",
            f"            $display(\"PASS: %0d vectors, 0 mismatches ({name})\", COUNT);",
            "        else",
            f"            $display(\"FAIL: %0d vectors, %0d mismatches ({name})\", COUNT, errors);",
            "        $finish;",
            "    end",
            "endmodule", ""]


# -- Horner evaluator ---------------------------------------------------------------

def verilog_module(design: HornerDesign, *, version: str = "", command: str | None = None,
                   budget=None) -> str:
    """The synthesizable Verilog-2005 module of ``design``.

    Parameters
    ----------
    design : HornerDesign
        The Horner evaluator (:func:`~chebnorm.hw.horner.design_horner`).
    version : str, default ""
        chebnorm's version, stated in the banner (made comment-safe).
    command : str or None, default None
        The command line that made the file, stated in the banner (made comment-safe);
        None or empty: no such line.
    budget : ErrorBudget or None, default None
        A Horner design's certified budget (:func:`~chebnorm.hw.budget.error_budget`),
        stated in the banner; None: not stated. A piecewise design states its own.

    Returns
    -------
    str
        The Verilog-2005 text, banner first.

    Raises
    ------
    ValueError
        If the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> v = verilog_module(d)
    >>> [line for line in v.splitlines() if line.startswith(("module", "    input", "    output"))]
    ['module chebnorm_dichotomy_d1 #(', '    input  wire [IN_BITS-1:0]  x,', '    output wire [OUT_BITS-1:0] y']
    """
    xf, yf = design.x_format, design.y_format
    n = design.degree
    out = comment_lines(horner_facts(design, "verilog", version=version, command=command,
                                     budget=budget), "verilog")
    out += [f"module {module_name(design)} #(",
            f"    parameter IN_BITS = {design.in_bits},",
            f"    parameter OUT_BITS = {design.out_bits}",
            ") (",
            "    input  wire [IN_BITS-1:0]  x,",
            "    output wire [OUT_BITS-1:0] y",
            ");"]
    xw = design.xs_bits
    out += [f"    // x value times 2^{xf.frac_bits}",
            f"    localparam signed [{xw - 1}:0] K0 = {signed_literal(xf.offset_code, xw)};",
            f"    wire signed [{xw - 1}:0] xs = $signed({{1'b0, x}}) + K0;"]
    out += _variable_lines(design, "xs", "v")
    n = len(design.horner_integers) - 1
    if n == 0:
        top_bits = max(design.top_bits, 2)
        out.append(f"    wire signed [{top_bits - 1}:0] top = {signed_literal(design.integers[0], top_bits)};")
        top_frac = design.coef_frac_bits
    else:
        aw = max(design.stages[0].acc_bits, 2)
        out.append(f"    localparam signed [{aw - 1}:0] A{n} = "
                   f"{signed_literal(design.horner_integers[n], aw)};")
        prev = f"A{n}"
        for st in design.stages:
            j = st.power
            out.append(f"    // step {j}: {step_comment(design, st)}"
                       f" with {st.sum_frac_bits} -> {st.out_frac_bits} fractional bits")
            out += _horner_step(design, st, prev, variable_name(design, st))
            if j > 0:
                prev = f"a{j}"
        top_bits, top_frac = design.stages[-1].sum_bits, design.stages[-1].sum_frac_bits
        out.append(f"    wire signed [{top_bits - 1}:0] top = t0;")
    out += _output_stage(design, yf, top_bits, top_frac)
    return "\n".join(out)



def _variable_lines(design: HornerDesign, xs: str, v: str) -> list[str]:
    """The Horner variable ``v = R(xs * xs)`` of a one-parity design (no
    lines for plain Horner in ``x``)."""
    if design.scheme == "monomial":
        return []
    if design.scheme == "shifted":
        return _shifted_lines(design, xs, v)
    sw, vw, rs = 2 * design.xs_bits, design.variable_bits, design.v_round_shift
    out = [f"    // {v}: x*x with {design.variable_frac_bits} fractional bits "
           f"({'rounded' if rs else 'exact'}); Horner's rule over the {design.scheme} powers in it",
           f"    wire signed [{sw - 1}:0] {v}_sq = {xs} * {xs};"]
    if rs:
        return out + round_lines(f"{v}_sq", v, sw, rs, vw, design.rounding)
    return out + [f"    wire signed [{vw - 1}:0] {v} = {v}_sq;"]


def _shifted_lines(design: HornerDesign, xs: str, v: str) -> list[str]:
    """``v = (xs << m) - C``: the shifted table's variable ``(x - c')/s``."""
    sw, m = shifted_width(design), design.v_shift
    shifted = f"({xs} <<< {m})" if m else xs
    return [f"    // {v} = (x - c') / s times 2^{design.variable_frac_bits}, c' = "
            f"{design.v_offset} / 2^{design.x_format.frac_bits + m}",
            f"    localparam signed [{sw - 1}:0] {v}_C = {signed_literal(design.v_offset, sw)};",
            f"    wire signed [{sw - 1}:0] {v}_d = {shifted} - {v}_C;",
            f"    wire signed [{design.variable_bits - 1}:0] {v} = {v}_d;"]


def _horner_step(design: HornerDesign, st, prev: str, xs: str) -> list[str]:
    """One Horner step ``a_j = R(a_{j+1} * x + q_j)``, shared by the
    combinational and pipelined evaluators (``prev``: a_{j+1}; ``xs``: x)."""
    j = st.power
    shift = f" <<< {st.product_shift}" if st.product_shift else ""
    out = [f"    wire signed [{st.product_bits - 1}:0] p{j} = {prev} * {xs};",
           f"    localparam signed [{st.sum_bits - 1}:0] C{j} = {signed_literal(st.coef_shifted, st.sum_bits)};",
           f"    wire signed [{st.sum_bits - 1}:0] t{j} = (p{j}{shift}) + C{j};"]
    if j > 0:
        out += round_lines(f"t{j}", f"a{j}", st.sum_bits, st.round_shift, st.out_bits, design.rounding)
    return out

def _output_stage(design: HornerDesign, yf, top_bits: int, top_frac: int) -> list[str]:
    """The evaluator's last lines, shared by the combinational and pipelined
    modules: round ``top`` to y's fractional bits, remove y's offset, saturate."""
    return ([f"    // output: round to {yf.frac_bits} fractional bits, remove the offset, saturate"]
            + saturating_output("top", top_bits, top_frac, yf, design.out_bits, design.rounding,
                                min_bits=design.raw_bits))


def verilog_pipelined_module(design: HornerDesign, *, version: str = "",
                             command: str | None = None, budget=None) -> str:
    """The pipelined variant of :func:`verilog_module`: the same datapath, bit
    for bit, with ``clk`` and one register stage after each Horner step (the
    delayed ``x`` travels beside the accumulator). Latency: ``degree`` cycles
    -- ``y`` after the ``degree``-th rising edge belongs to the ``x`` applied
    before the first; a new ``x`` can be applied every cycle.

    Parameters
    ----------
    design : HornerDesign
        The Horner evaluator (:func:`~chebnorm.hw.horner.design_horner`).
    version : str, default ""
        chebnorm's version, stated in the banner (made comment-safe).
    command : str or None, default None
        The command line that made the file, stated in the banner (made comment-safe);
        None or empty: no such line.
    budget : ErrorBudget or None, default None
        A Horner design's certified budget (:func:`~chebnorm.hw.budget.error_budget`),
        stated in the banner; None: not stated. A piecewise design states its own.

    Returns
    -------
    str
        The Verilog-2005 text of ``chebnorm_NAME_pipe``, banner first.

    Raises
    ------
    ValueError
        If the design has degree 0 (nothing to pipeline).
    ValueError
        If the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> v = verilog_pipelined_module(d)
    >>> [line.strip() for line in v.splitlines() if "LATENCY =" in line or "posedge" in line]
    ['parameter LATENCY = 1', 'always @(posedge clk) top <= t0;']
    """
    n = design.degree
    if n < 1:
        raise ValueError(f"design {design.name!r} has degree 0: nothing to pipeline; accepted: "
                         f"degree >= 1")
    xf, yf = design.x_format, design.y_format
    name = pipelined_name(design)
    out = comment_lines(horner_facts(design, "verilog", version=version, command=command,
                                     budget=budget, pipelined=True), "verilog")
    out += [f"module {name} #(",
            f"    parameter IN_BITS = {design.in_bits},",
            f"    parameter OUT_BITS = {design.out_bits},",
            f"    parameter LATENCY = {design.steps}",
            ") (",
            "    input  wire                clk,",
            "    input  wire [IN_BITS-1:0]  x,",
            "    output wire [OUT_BITS-1:0] y",
            ");"]
    xw = design.xs_bits
    out += [f"    localparam signed [{xw - 1}:0] K0 = {signed_literal(xf.offset_code, xw)};",
            f"    wire signed [{xw - 1}:0] xs0 = $signed({{1'b0, x}}) + K0;"]
    out += _variable_lines(design, "xs0", "v0")
    vw, square = design.variable_bits, design.scheme != "monomial"   # v travels beside x
    n = len(design.horner_integers) - 1
    aw = max(design.stages[0].acc_bits, 2)
    out.append(f"    localparam signed [{aw - 1}:0] A{n} = "
               f"{signed_literal(design.horner_integers[n], aw)};")
    prev = f"A{n}"
    for s, st in enumerate(design.stages):
        j = st.power
        out.append(f"    // stage {s + 1}: {step_comment(design, st)}")
        out += _horner_step(design, st, prev, f"{variable_name(design, st)}{s}")
        if j > 0:
            out += [f"    reg signed [{st.out_bits - 1}:0] a{j}_r;",
                    f"    reg signed [{xw - 1}:0] xs{s + 1};"]
            out += [f"    reg signed [{vw - 1}:0] v{s + 1};"] if square else []
            out += ["    always @(posedge clk) begin",
                    f"        a{j}_r <= a{j};",
                    f"        xs{s + 1} <= xs{s};"]
            out += [f"        v{s + 1} <= v{s};"] if square else []
            out += ["    end"]
            prev = f"a{j}_r"
    top_bits, top_frac = design.stages[-1].sum_bits, design.stages[-1].sum_frac_bits
    out += [f"    reg signed [{top_bits - 1}:0] top;",
            "    always @(posedge clk) top <= t0;"]
    out += _output_stage(design, yf, top_bits, top_frac)
    return "\n".join(out)


def verilog_pipelined_testbench(design: HornerDesign, vectors: str | None = None) -> str:
    """Exhaustive self-checking bench of the pipelined variant: one new input
    code per cycle; the output after edge ``i`` is checked against the model's
    answer for code ``i - LATENCY + 1`` (the first ``LATENCY - 1`` edges are
    the pipeline filling and are not checked).

    Parameters
    ----------
    design : HornerDesign
        The Horner evaluator (:func:`~chebnorm.hw.horner.design_horner`).
    vectors : str or None, default None
        The vector file the bench reads: an identifier, optionally with ``.hex``; None:
        ``NAME.hex``.

    Returns
    -------
    str
        The Verilog-2005 bench text.

    Raises
    ------
    ValueError
        If the design has degree 0 (nothing to pipeline).
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> verilog_pipelined_testbench(d).splitlines()[0]
    '// tb_chebnorm_dichotomy_d1_pipe: exhaustive self-checking test bench of chebnorm_dichotomy_d1_pipe, latency 1.'
    """
    return _clocked_bench(design, pipelined_name(design), design.steps, vectors)


def _clocked_bench(design, name: str, n: int, vectors: str | None) -> str:
    """The exhaustive bench of clocked module ``name`` of latency ``n``."""
    vectors = vectors_name(name, vectors)
    count = 2 ** design.in_bits
    return "\n".join([
        f"// tb_{name}: exhaustive self-checking test bench of {name}, latency {n}.",
        f"// Expected outputs come from the chebnorm bit-accurate model ({vectors}).",
        "`timescale 1ns/1ps",
        f"module tb_{name};",
        f"    localparam IN_BITS = {design.in_bits};",
        f"    localparam OUT_BITS = {design.out_bits};",
        f"    localparam LATENCY = {n};",
        f"    localparam COUNT = {count};",
        "    reg clk;",
        "    reg  [IN_BITS-1:0]  x;",
        "    wire [OUT_BITS-1:0] y;",
        "    reg  [OUT_BITS-1:0] expected [0:COUNT-1];",
        "    integer i, errors, checked;",
        f"    {name} #(.IN_BITS(IN_BITS), .OUT_BITS(OUT_BITS), .LATENCY(LATENCY)) dut "
        "(.clk(clk), .x(x), .y(y));",
        "    initial begin",
        f"        $readmemh(\"{vectors}\", expected);",
        "        errors = 0;",
        "        checked = 0;",
        "        clk = 0;",
        "        for (i = 0; i < COUNT + LATENCY - 1; i = i + 1) begin",
        "            x = (i < COUNT) ? i : 0;",
        "            #1 clk = 1;",
        "            #1;",
        "            if (i >= LATENCY - 1) begin",
        "                checked = checked + 1;",
        "                if (y !== expected[i - LATENCY + 1]) begin",
        "                    errors = errors + 1;",
        "                    if (errors <= 10)",
        "                        $display(\"MISMATCH x=%h y=%h expected=%h\", i - LATENCY + 1, y,",
        "                                 expected[i - LATENCY + 1]);",
        "                end",
        "            end",
        "            clk = 0;",
        "        end",
        "        if (errors == 0)",
        f"            $display(\"PASS: %0d vectors, 0 mismatches ({name}, latency %0d)\", "
        "checked, LATENCY);",
        "        else",
        f"            $display(\"FAIL: %0d vectors, %0d mismatches ({name})\", checked, errors);",
        "        $finish;",
        "    end",
        "endmodule", ""])


def verilog_testbench(design: HornerDesign, vectors: str | None = None) -> str:
    """A self-checking test bench comparing every input code with the model.

    Parameters
    ----------
    design : HornerDesign
        The Horner evaluator (:func:`~chebnorm.hw.horner.design_horner`).
    vectors : str or None, default None
        The vector file the bench reads: an identifier, optionally with ``.hex``; None:
        ``NAME.hex``.

    Returns
    -------
    str
        The Verilog-2005 bench text.

    Raises
    ------
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> tb = verilog_testbench(d)
    >>> tb.splitlines()[0]
    '// tb_chebnorm_dichotomy_d1: exhaustive self-checking test bench of chebnorm_dichotomy_d1.'
    >>> '$readmemh("chebnorm_dichotomy_d1.hex", expected);' in tb
    True
    """
    name = module_name(design)
    vectors = vectors_name(name, vectors)
    count = 2 ** design.in_bits
    return "\n".join([
        f"// tb_{name}: exhaustive self-checking test bench of {name}.",
        f"// Expected outputs come from the chebnorm bit-accurate model ({vectors}).",
        "`timescale 1ns/1ps",
        f"module tb_{name};",
        f"    localparam IN_BITS = {design.in_bits};",
        f"    localparam OUT_BITS = {design.out_bits};",
        f"    localparam COUNT = {count};",
        "    reg  [IN_BITS-1:0]  x;",
        "    wire [OUT_BITS-1:0] y;",
        "    reg  [OUT_BITS-1:0] expected [0:COUNT-1];",
        "    integer i, errors;",
        f"    {name} #(.IN_BITS(IN_BITS), .OUT_BITS(OUT_BITS)) dut (.x(x), .y(y));",
        "    initial begin",
        f"        $readmemh(\"{vectors}\", expected);",
        "        errors = 0;",
        "        for (i = 0; i < COUNT; i = i + 1) begin",
        "            x = i;",
        "            #1;",
        "            if (y !== expected[i]) begin",
        "                errors = errors + 1;",
        "                if (errors <= 10)",
        "                    $display(\"MISMATCH x=%h y=%h expected=%h\", x, y, expected[i]);",
        "            end",
        "        end",
        *bench_verdict(name)])


# -- piecewise evaluator -------------------------------------------------------------

def piecewise_verilog(d, *, version: str = "", command: str | None = None) -> str:
    """The synthesizable Verilog-2005 module of a piecewise design ``d``
    (:class:`~chebnorm.hw.piecewise.PiecewiseDesign`): ROM (a case on the
    index) + Horner.

    Parameters
    ----------
    d : PiecewiseDesign
        The piecewise design (:func:`~chebnorm.hw.piecewise.design_piecewise`); a sized
        one (``d.sized``) is printed by :func:`sized_piecewise_verilog`.
    version : str, default ""
        chebnorm's version, stated in the banner (made comment-safe).
    command : str or None, default None
        The command line that made the file, stated in the banner (made comment-safe);
        None or empty: no such line.

    Returns
    -------
    str
        The Verilog-2005 text, banner first.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8)
    >>> v = piecewise_verilog(d)
    >>> v.count("2'd"), "module chebnorm_rs" in v   # one ROM row per segment
    (4, True)
    """
    if d.sized:
        return sized_piecewise_verilog(d, version=version, command=command)
    t = d.table
    n, L, K, fc = t.degree, d.local_bits, d.index_bits, t.coef_frac_bits
    yf = d.y_format
    mod = module_name(d)
    out = comment_lines(piecewise_facts(d, version=version, command=command), "verilog")
    out += [f"module {mod} #(",
            f"    parameter IN_BITS = {d.in_bits},",
            f"    parameter OUT_BITS = {d.out_bits}",
            ") (",
            "    input  wire [IN_BITS-1:0]  x,",
            "    output wire [OUT_BITS-1:0] y",
            ");",
            f"    wire [{L - 1}:0] low = x[{L - 1}:0];"]
    tw = d.t_bits
    if t.centered:
        out.append(f"    wire signed [{tw - 1}:0] t = $signed({{2'b00, low}}) - "
                   f"{signed_literal(1 << (L - 1), tw)};")
    else:
        out.append(f"    wire signed [{tw - 1}:0] t = $signed({{2'b00, low}});")
    regs = [f"c{j}" for j in range(n + 1)]
    if K == 0:  # one segment: constants (an always block with no input would never run)
        for j in range(n + 1):
            out.append(f"    wire signed [{d.rom_bits[j] - 1}:0] c{j} = "
                       f"{signed_literal(t.segments[0].integers[j], d.rom_bits[j])};")
    else:
        for j in range(n + 1):
            out.append(f"    reg signed [{d.rom_bits[j] - 1}:0] c{j};")
        out += [f"    wire [{K - 1}:0] idx = x[{d.in_bits - 1}:{L}];",
                "    always @(*) begin",
                "        case (idx)"]
        for s, seg in enumerate(t.segments):
            body = " ".join(f"{regs[j]} = {signed_literal(q, d.rom_bits[j])};"
                            for j, q in enumerate(seg.integers))
            out.append(f"            {K}'d{s}: begin {body} end")
        out += ["        endcase", "    end"]
    prev, prev_frac = f"c{n}", fc
    for i, j in enumerate(range(n - 1, -1, -1)):
        pw, sw, ow = d.widths[i]
        pf = prev_frac + L
        sf = max(pf, fc)
        out.append(f"    // step {j}: a{j} = R(a{j + 1} * t + c{j}), {sf} fractional bits")
        out.append(f"    wire signed [{pw - 1}:0] p{j} = {prev} * t;")
        sh_p = f" <<< {sf - pf}" if sf > pf else ""
        sh_c = f" <<< {sf - fc}" if sf > fc else ""
        out.append(f"    wire signed [{sw - 1}:0] s{j} = (p{j}{sh_p}) + (c{j}{sh_c});")
        if j > 0:
            f_out = min(d.acc_frac_bits, sf)
            if sf > f_out:
                out += round_lines(f"s{j}", f"a{j}", sw, sf - f_out, ow, d.rounding)
            else:
                out.append(f"    wire signed [{ow - 1}:0] a{j} = s{j};")
            prev, prev_frac = f"a{j}", f_out
        else:
            prev, prev_frac = f"s{j}", sf
    top_bits = d.widths[-1][1] if n > 0 else d.rom_bits[0]
    out += saturating_output(prev, top_bits, prev_frac, yf, d.out_bits, d.rounding)
    return "\n".join(out)


# -- sized piecewise evaluator (a width per coefficient, truncated steps, pipelined) --------

def sized_piecewise_verilog(d, *, version: str = "", command: str | None = None) -> str:
    """The Verilog-2005 module of a sized piecewise design ``d`` (``d.sized``):
    ROM columns of their own widths, each Horner step multiplying by the top
    ``T_j`` bits of ``t``, products and sums truncated by arithmetic shifts,
    and, when ``d.latency > 0``, a register stage at each cut point (``clk``
    port, ``LATENCY`` parameter): bit for bit
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
    str
        The Verilog-2005 text, banner first.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8, widths="auto", max_error=2 ** -5, pipeline="full")
    >>> v = sized_piecewise_verilog(d)
    >>> v.count("always @(posedge clk)"), "parameter LATENCY = 3" in v
    (3, True)
    """
    t = d.table
    n, L, K = t.degree, d.local_bits, d.index_bits
    mod = module_name(d)
    clocked = d.latency > 0
    out = comment_lines(piecewise_facts(d, version=version, command=command), "verilog")
    out += [f"module {mod} #(",
            f"    parameter IN_BITS = {d.in_bits},",
            f"    parameter OUT_BITS = {d.out_bits}" + ("," if clocked else ""),
            *([f"    parameter LATENCY = {d.latency}"] if clocked else []),
            ") (",
            *(["    input  wire                clk,"] if clocked else []),
            "    input  wire [IN_BITS-1:0]  x,",
            "    output wire [OUT_BITS-1:0] y",
            ");",
            f"    wire [{L - 1}:0] low = x[{L - 1}:0];"]
    if K == 0:
        for j in range(n + 1):
            out.append(f"    wire signed [{d.rom_bits[j] - 1}:0] c{j} = "
                       f"{signed_literal(d.coefficients[0][j], d.rom_bits[j])};")
    else:
        out += [f"    reg signed [{d.rom_bits[j] - 1}:0] c{j};" for j in range(n + 1)]
        out += [f"    wire [{K - 1}:0] idx = x[{d.in_bits - 1}:{L}];",
                "    always @(*) begin",
                "        case (idx)"]
        for s, row in enumerate(d.coefficients):
            body = " ".join(f"c{j} = {signed_literal(q, d.rom_bits[j])};"
                            for j, q in enumerate(row))
            out.append(f"            {K}'d{s}: begin {body} end")
        out += ["        endcase", "    end"]
    # live signals: name -> (width, signed); registered at each cut point
    live = {"low": (L, False), **{f"c{j}": (d.rom_bits[j], True) for j in range(n + 1)}}
    cur = {k: k for k in live}
    acc, accw = f"c{n}", d.rom_bits[n]

    def cut(stage) -> None:
        regs = []
        for key, (w, sgn) in live.items():
            r = f"{key}_r{stage}"
            out.append(f"    reg {'signed ' if sgn else ''}[{w - 1}:0] {r};")
            regs.append(f"        {r} <= {cur[key]};")
            cur[key] = r
        out.extend(["    always @(posedge clk) begin", *regs, "    end"])

    if 0 in d.cuts:
        cut(0)
    for i, st in enumerate(d.sized_signals(), start=1):
        j, T = st["j"], st["T"]
        lo = cur["low"]
        out.append(f"    // step {j}: a{j} = (((a{j + 1} * t{j}) >>> {st['pshift']}) <<< {st['qshift']}"
                   f" + c{j} <<< {st['cshift']}) >>> {st['ashift']}, t{j} = top {T} bits of t"
                   + (", truncated multiplier" if st["rows"] else ""))
        if t.centered:
            bits = f"~{lo}[{L - 1}]" if T == 1 else f"{{~{lo}[{L - 1}], {lo}[{L - 2}:{L - T}]}}"
            out.append(f"    wire signed [{st['tw'] - 1}:0] t{j} = {bits};")
        else:
            out.append(f"    wire signed [{st['tw'] - 1}:0] t{j} = $signed({{1'b0, {lo}[{L - 1}:{L - T}]}});")
        if st["rows"]:
            out += _truncated_rows(st, cur[acc], accw, lo)
        else:
            out.append(f"    wire signed [{st['pw'] - 1}:0] p{j} = {cur[acc]} * t{j};")
            ps = st["pshift"]
            shift = f" >>> {ps}" if ps > 0 else (f" <<< {-ps}" if ps < 0 else "")
            out.append(f"    wire signed [{st['qw'] - 1}:0] q{j} = p{j}{shift};")
        q = f"q{j}"
        if i in getattr(d, "mult_cuts", ()):  # a register between the multiply and the add
            live.pop(acc, None)
            cur.pop(acc, None)
            if j == 0:
                live.pop("low", None)
            live[q], cur[q] = (st["qw"], True), q
            cut(f"m{i}")
            q = cur.pop(q)
            del live[f"q{j}"]
        cs = f" <<< {st['cshift']}" if st["cshift"] else ""
        qs = f"({q} <<< {st['qshift']})" if st["qshift"] else q
        out.append(f"    wire signed [{st['sw'] - 1}:0] s{j} = {qs} + ({cur[f'c{j}']}{cs});")
        ash = f" >>> {st['ashift']}" if st["ashift"] else ""
        out.append(f"    wire signed [{st['aw'] - 1}:0] a{j} = s{j}{ash};")
        del live[f"c{j}"], cur[f"c{j}"]
        live.pop(acc, None)
        cur.pop(acc, None)
        acc, accw = f"a{j}", st["aw"]
        live[acc], cur[acc] = (st["aw"], True), acc
        if j == 0:
            live.pop("low", None)
        if i in d.cuts:
            cut(i)
    top_bits = d.widths[-1][2] if n > 0 else d.rom_bits[0]
    if n == 0:
        f0, g0 = d.coef_frac[0], d.acc_frac[0]
        sh = f" >>> {f0 - g0}" if f0 > g0 else (f" <<< {g0 - f0}" if g0 > f0 else "")
        top_bits = d.rom_bits[0] + max(0, g0 - f0)
        out.append(f"    wire signed [{top_bits - 1}:0] a0 = {cur['c0']}{sh};")
        acc = "a0"
        cur[acc] = acc
    out += saturating_output(cur[acc], top_bits, d.y_format.frac_bits, d.y_format, d.out_bits,
                             "trunc")
    return "\n".join(out)


def _truncated_rows(st: dict, a: str, aw: int, low: str) -> list[str]:
    """The truncated multiplier ``q_j`` of a sized step: one row per bit of
    ``t_j``'s code, ``a`` floored at column ``P`` (an arithmetic shift), gated by
    the bit (the inverted top bit, negated row, when ``t`` is centred), all
    rows added modulo ``2^qw`` (the exact sum fits ``qw`` bits)."""
    j, qw = st["j"], st["qw"]
    out, terms = [], []
    if any(neg for _, _, neg in st["rows"]):
        out.append(f"    wire signed [{aw}:0] na{j} = -{a};")
    for i, sh, neg in st["rows"]:
        src = f"na{j}" if neg else a
        expr = f"{src} >>> {sh}" if sh > 0 else (f"{src} <<< {-sh}" if sh < 0 else src)
        bit = f"{low}[{st['tshift'] + i}]"
        out += [f"    wire signed [{qw - 1}:0] r{j}_{i} = {expr};",
                f"    wire [{qw - 1}:0] m{j}_{i} = r{j}_{i} & {{{qw}{{{'~' if neg else ''}{bit}}}}};"]
        terms.append(f"m{j}_{i}")
    out.append(f"    wire signed [{qw - 1}:0] q{j} = {' + '.join(terms)};")
    return out


def piecewise_clocked_testbench(d, vectors: str | None = None) -> str:
    """Exhaustive bench of a pipelined piecewise module (``d.latency > 0``):
    one code per cycle, the output after edge ``i`` checked against the
    model's answer for code ``i - LATENCY + 1``.

    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8, widths="auto", max_error=2 ** -5, pipeline=(0,))
    >>> piecewise_clocked_testbench(d).splitlines()[0]
    '// tb_chebnorm_rs: exhaustive self-checking test bench of chebnorm_rs, latency 1.'

    Parameters
    ----------
    d : PiecewiseDesign
        A sized piecewise design with pipeline cuts (``d.latency > 0``).
    vectors : str or None, default None
        The vector file the bench reads: an identifier, optionally with ``.hex``; None:
        ``NAME.hex``.

    Returns
    -------
    str
        The Verilog bench text.

    Raises
    ------
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.
    """
    return _clocked_bench(d, module_name(d), d.latency, vectors)
