"""``"classic"``: ``N / sqrt(N.N)`` (seed 000), bit-for-bit
:func:`~chebnorm.hw.datapaths.classic_normalize`: dot product, restoring
integer square root, three restoring dividers, floor or nearest-even
quotient. Fully parametric (``W``, ``F``, ``RNE``)."""

from __future__ import annotations

import numpy as np

from ..cost import Block
from ..datapaths import classic_normalize, classic_unit
from ..fixed import check_int64
from .base import UnitDesign, UnitKind, put, register, vec, vec_ports
from .bench import codes, combinational_rows
from .hdl import banner, isqrt_module, ports_decl

# an implementation module of chebnorm.hw.units: the API is what chebnorm.hw.units exports
__all__: list[str] = []

ROUNDINGS = ("trunc", "rne")


class ClassicUnit(UnitKind):
    """The classic unit (see module docstring).

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("classic", frac_bits=12)
    >>> n = np.array([3 << 10, 4 << 10, 0])   # (0.75, 1, 0): length 1.25
    >>> out = u.evaluate({"n_x": n[:1], "n_y": n[1:2], "n_z": n[2:]})
    >>> [int(out[f"u_{c}"][0]) for c in "xy"], [int(0.6 * 4096), int(0.8 * 4096)]
    ([2457, 3276], [2457, 3276])
    """

    name = "classic"

    def design(self, f, w, notes, *, table, in_bits, out_bits, coef_bits, rounding, log_m,
               guard) -> UnitDesign:
        rounding = rounding or "trunc"
        if rounding not in ROUNDINGS:
            raise ValueError(f"rounding {rounding!r} is unknown; accepted: {', '.join(ROUNDINGS)}")
        check_int64(w + f, "the classic unit's dividend N << F")
        ports = vec_ports("n", w) + vec_ports("u", f + 2, True)
        return UnitDesign(self.name, ports, f, w, rounding=rounding, notes=tuple(notes))

    def evaluate(self, unit, g) -> dict:
        out = {}
        put(out, "u", classic_normalize(vec(g, "n"), unit.frac_bits, unit.rounding))
        return out

    def block(self, unit) -> Block:
        return classic_unit(unit.comp_bits, unit.frac_bits)

    def vector_rows(self, unit, rng, count) -> dict:
        f, w = unit.frac_bits, unit.comp_bits

        def realistic(rng, a):
            n = a * rng.uniform(0.5, 1.0, (count, 1))
            n[:6] = np.eye(3).repeat(2, 0)[:6] * np.array([1, -1] * 3)[:, None]
            return {f"n_{c}": codes(n[:, i], f, w) for i, c in enumerate("xyz")}
        return combinational_rows(unit, rng, count, realistic)

    def verilog(self, unit, *, version, command) -> str:
        name = unit.module_name
        out = banner(unit, version, command, [
            "classic normalization u = n / sqrt(n.n) (seed 000), bit-for-bit",
            "chebnorm.hw.datapaths.classic_normalize: s = max(isqrt(n.n), 1),",
            "u_i = (n_i << F) / s rounded to floor (RNE = 0) or nearest-even (RNE = 1).",
            "Every width below is an expression of the parameters W, F (W >= 2, F >= 1)."])
        out += ["// Combinational.",
                f"module {name} #(",
                f"    parameter W = {unit.comp_bits},",
                f"    parameter F = {unit.frac_bits},",
                f"    parameter RNE = {int(unit.rounding == 'rne')}",
                ") ("]
        out += ports_decl(unit, {"n_x": "W-1", "n_y": "W-1", "n_z": "W-1",
                                 "u_x": "F+1", "u_y": "F+1", "u_z": "F+1"})
        out += [");",
                "    // n.n < 3 * 2^(2W-2): 2W+1 bits; its root < 2^W",
                "    wire signed [2*W+1:0] dot = n_x * n_x + n_y * n_y + n_z * n_z;",
                "    wire [W:0] root;",
                f"    {name}_isqrt #(.RW(W + 1)) sq (.v(dot), .r(root));",
                "    wire [W:0] s = (root == 0) ? 1 : root;"]
        for c in "xyz":
            out.append(f"    {name}_comp #(.W(W), .F(F), .RNE(RNE)) c_{c} (.n(n_{c}), .s(s), "
                       f".u(u_{c}));")
        out += ["endmodule", ""]
        out += _component_module(f"{name}_comp", f"{name}_div")
        out += isqrt_module(f"{name}_isqrt") + _div_module(f"{name}_div")
        return "\n".join(out)


def _component_module(name: str, div: str) -> list[str]:
    """Module ``name``: one component ``floor(n 2^F / s)``, then nearest-even if RNE."""
    return [
        f"// {name}: one component, floor(n 2^F / s), then nearest-even if RNE.",
        f"module {name} #(parameter W = 16, parameter F = 14, parameter RNE = 0) (",
        "    input  wire signed [W-1:0] n,",
        "    input  wire [W:0]          s,",
        "    output wire signed [F+1:0] u",
        ");",
        "    wire neg = n[W-1];",
        "    wire [W-1:0] mag = neg ? -n : n;",
        "    wire [W+F-1:0] q;",
        "    wire [W:0] r;",
        f"    {div} #(.NB(W + F), .DB(W + 1)) dv (.a({{mag, {{F{{1'b0}}}}}}), "
        ".d(s), .q(q), .r(r));",
        "    wire nz = |r;",
        "    // floor of a negative quotient: -(q + 1) when the remainder is not 0",
        "    wire signed [W+F:0] qf = neg ? -$signed({1'b0, q} + nz) : $signed({1'b0, q});",
        "    wire [W:0] rf = (neg && nz) ? s - r : r;",
        "    wire [W+1:0] r2 = {rf, 1'b0};",
        "    wire inc = (RNE != 0) && ((r2 > {1'b0, s}) || ((r2 == {1'b0, s}) && qf[0]));",
        "    wire signed [W+F:0] ur = qf + $signed({1'b0, inc});",
        "    assign u = ur[F+1:0];",
        "endmodule", ""]


def _div_module(name: str) -> list[str]:
    """Module ``name``: unsigned restoring divider, quotient and remainder."""
    return [
        f"// {name}: unsigned a / d and a % d (d > 0), restoring (combinational).",
        f"module {name} #(parameter NB = 16, parameter DB = 8) (",
        "    input  wire [NB-1:0] a,",
        "    input  wire [DB-1:0] d,",
        "    output reg  [NB-1:0] q,",
        "    output reg  [DB-1:0] r",
        ");",
        "    reg [DB:0] rem;",
        "    integer i;",
        "    always @* begin",
        "        rem = 0;",
        "        q = 0;",
        "        for (i = NB - 1; i >= 0; i = i - 1) begin",
        "            rem = {rem[DB-1:0], a[i]};",
        "            if (rem >= {1'b0, d}) begin",
        "                rem = rem - {1'b0, d};",
        "                q[i] = 1'b1;",
        "            end",
        "        end",
        "        r = rem[DB-1:0];",
        "    end",
        "endmodule", ""]


register(ClassicUnit())
