"""Verilog printers: the evaluator of a :class:`~chebnorm.hw.horner.HornerDesign`
(combinational and pipelined) and of a
:class:`~chebnorm.hw.piecewise.PiecewiseDesign` (ROM + Horner) -- each the
netlist of :mod:`chebnorm.hw.hdl.datapath`, printed by
:func:`chebnorm.hw.hdl.netlist.verilog` --, their self-checking test benches,
and the text fragments the normalization units of :mod:`chebnorm.hw.units`
use.

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
from .bench import bench_ports, testbench
from .common import module_name, pipelined_name
from .datapath import (horner_netlist, output_stage, piecewise_netlist, round_to,
                       sized_piecewise_netlist)
from .netlist import Signal, statement_lines
from .netlist import verilog as _verilog
from .._docfrag import hw_doc

# an implementation module of chebnorm.hw.hdl: the API is what chebnorm.hw.hdl exports
__all__: list[str] = []


# -- fragments -------------------------------------------------------------------
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
    return [line for s in round_to(Signal(src, src_bits, signed=True), dst, shift, dst_bits, mode)
            for line in statement_lines(s, "verilog")[1]]



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
    stage = output_stage(Signal(top, top_bits, signed=True), top_frac, y_format, out_bits,
                         rounding, min_bits=min_bits)[1:]   # no comment line
    return [line for s in stage for line in statement_lines(s, "verilog")[1]] + ["endmodule", ""]



# -- Horner evaluator ---------------------------------------------------------------

@hw_doc
def verilog_module(design: HornerDesign, *, version: str = "", command: str | None = None,
                   budget=None) -> str:
    """The synthesizable Verilog-2005 module of ``design``.

    Parameters
    ----------
    %(horner_design)s
    %(version)s
    %(command)s
    %(budget)s

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
    return _verilog(horner_netlist(design, language="verilog", version=version, command=command,
                                   budget=budget))




@hw_doc
def verilog_pipelined_module(design: HornerDesign, *, version: str = "",
                             command: str | None = None, budget=None) -> str:
    """The pipelined variant of :func:`verilog_module`: the same datapath, bit
    for bit, with ``clk`` and one register stage after each Horner step (the
    delayed ``x`` travels beside the accumulator). Latency: ``degree`` cycles
    -- ``y`` after the ``degree``-th rising edge belongs to the ``x`` applied
    before the first; a new ``x`` can be applied every cycle.

    Parameters
    ----------
    %(horner_design)s
    %(version)s
    %(command)s
    %(budget)s

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
    ['parameter LATENCY = 1', 'always @(posedge clk) begin']
    """
    return _verilog(horner_netlist(design, pipelined=True, language="verilog", version=version,
                                   command=command, budget=budget))



@hw_doc
def verilog_pipelined_testbench(design: HornerDesign, vectors: str | None = None) -> str:
    """Exhaustive self-checking bench of the pipelined variant: one new input
    code per cycle; the output after edge ``i`` is checked against the model's
    answer for code ``i - LATENCY + 1`` (the first ``LATENCY - 1`` edges are
    the pipeline filling and are not checked).

    Parameters
    ----------
    %(horner_design)s
    %(vectors)s

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
    return testbench(bench_ports(design, pipelined_name(design), design.steps), "verilog", vectors)


@hw_doc
def verilog_testbench(design: HornerDesign, vectors: str | None = None) -> str:
    """A self-checking test bench comparing every input code with the model.

    Parameters
    ----------
    %(horner_design)s
    %(vectors)s

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
    return testbench(bench_ports(design, module_name(design)), "verilog", vectors)

# -- piecewise evaluator -------------------------------------------------------------

@hw_doc
def piecewise_verilog(d, *, version: str = "", command: str | None = None) -> str:
    """The synthesizable Verilog-2005 module of a piecewise design ``d``
    (:class:`~chebnorm.hw.piecewise.PiecewiseDesign`): ROM (a case on the
    index) + Horner.

    Parameters
    ----------
    d : PiecewiseDesign
        The piecewise design (:func:`~chebnorm.hw.piecewise.design_piecewise`); a sized
        one (``d.sized``) is printed by :func:`sized_piecewise_verilog`.
    %(version)s
    %(command)s

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
    return _verilog(piecewise_netlist(d, version=version, command=command))



# -- sized piecewise evaluator (a width per coefficient, truncated steps, pipelined) --------

@hw_doc
def sized_piecewise_verilog(d, *, version: str = "", command: str | None = None) -> str:
    """The Verilog-2005 module of a sized piecewise design ``d`` (``d.sized``):
    ROM columns of their own widths, each Horner step multiplying by the top
    ``T_j`` bits of ``t``, products and sums truncated by arithmetic shifts,
    and, when ``d.latency > 0``, a register stage at each cut point (``clk``
    port, ``LATENCY`` parameter): bit for bit
    :meth:`~chebnorm.hw.piecewise.PiecewiseDesign.evaluate`.

    Parameters
    ----------
    %(sized_piecewise)s
    %(version)s
    %(command)s

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
    return _verilog(sized_piecewise_netlist(d, version=version, command=command))




@hw_doc
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
    %(vectors)s

    Returns
    -------
    str
        The Verilog bench text.

    Raises
    ------
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.
    """
    return testbench(bench_ports(d, module_name(d), d.latency), "verilog", vectors)
