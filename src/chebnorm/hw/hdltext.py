"""Verilog text fragments shared by the printers of :mod:`chebnorm.hw.verilog`
(one Horner evaluator) and :mod:`chebnorm.hw.piecewise` (ROM + Horner).

Each function returns Verilog-2005 source lines (indented four spaces, no
trailing newline); the callers join them. The widths are the callers' (sized
from exact ranges); the functions only range-check the constants they print.
"""

from __future__ import annotations

from .fixed import QFormat

__all__ = ["signed_literal", "round_lines", "saturating_output", "bench_verdict"]


def signed_literal(value: int, bits: int) -> str:
    """A sized signed decimal literal ``[-]BITS'sdMAGNITUDE``.

    Raises ValueError when ``value`` does not fit a signed ``bits``-bit word.

    >>> signed_literal(5, 4), signed_literal(-8, 4)
    ("4'sd5", "-4'sd8")
    >>> signed_literal(8, 4)
    Traceback (most recent call last):
    ...
    ValueError: constant 8 does not fit a signed 4-bit literal
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
    """
    lines = [f"    wire signed [{src_bits - 1}:0] {dst}_q = {src} >>> {shift};"]
    if mode == "trunc":
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
    """
    return ["        if (errors == 0)",
            f"            $display(\"PASS: %0d vectors, 0 mismatches ({name})\", COUNT);",
            "        else",
            f"            $display(\"FAIL: %0d vectors, %0d mismatches ({name})\", COUNT, errors);",
            "        $finish;",
            "    end",
            "endmodule", ""]
