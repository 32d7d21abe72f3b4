"""``"dichotomy"``: ``M = (N1 + N2) p(z)`` and ``z' = sqrt(2 + z)`` (seed 000,
method 4; :func:`~chebnorm.hw.datapaths.dichotomy_midpoint`,
:func:`~chebnorm.hw.datapaths.dichotomy_next_z`), the polynomial ``p`` the
generated evaluator of a ``1/sqrt(2+z)`` table."""

from __future__ import annotations

import math

import numpy as np

from ..cost import Block
from ..datapaths import dichotomy_midpoint, dichotomy_next_z, dichotomy_unit
from ..fixed import signed_bits, unsigned_bits
from ..hdl.netlist import signed_literal
from .base import Port, UnitDesign, put, register, vec, vec_ports
from .evaluator import EvaluatorUnit, ky_localparam, scale_lines, scaled_range
from .hdl import banner, isqrt_module, ports_decl

# an implementation module of chebnorm.hw.units: the API is what chebnorm.hw.units exports
__all__: list[str] = []


class DichotomyUnit(EvaluatorUnit):
    """The dichotomy midpoint and next level (see module docstring).

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("dichotomy", frac_bits=12, in_bits=12, out_bits=12)
    >>> d = u.horner
    >>> c = np.cos(np.pi / 4)
    >>> n2 = np.rint(4096 * np.array([c, c, 0])).astype(int)
    >>> k = int(np.rint((2 * c - float(d.x_format.offset)) * 2 ** d.x_format.frac_bits))
    >>> g = {"n1_x": [4096], "n1_y": [0], "n1_z": [0], "z": [k],
    ...      "n2_x": [n2[0]], "n2_y": [n2[1]], "n2_z": [0]}
    >>> out = u.evaluate(g)   # the normal half-way, at 22.5 degrees
    >>> exact = np.rint(4096 * np.array([np.cos(np.pi / 8), np.sin(np.pi / 8)])).astype(int)
    >>> [int(out["m_x"][0]), int(out["m_y"][0])], exact.tolist()
    ([3784, 1567], [3784, 1567])
    """

    name = "dichotomy"
    pair = ("n1", "n2")

    def size(self, f, w, notes, d) -> UnitDesign:
        lo, hi, yw = scaled_range(w, d)
        mw = signed_bits(lo, hi)
        ports = vec_ports("n1", w) + vec_ports("n2", w) + (Port("z", d.in_bits, False),) + \
            vec_ports("m", mw, True) + (Port("z_next", d.in_bits, False, True),)
        return UnitDesign(self.name, ports, f, w, horner=d, sizes={"m_bits": mw, "yv_bits": yw},
                          notes=tuple(notes))

    def evaluate(self, unit, g) -> dict:
        out = {}
        put(out, "m", dichotomy_midpoint(vec(g, "n1"), vec(g, "n2"), g["z"], unit.horner,
                                         unit.frac_bits))
        out["z_next"] = dichotomy_next_z(g["z"], unit.horner)
        return out

    def block(self, unit) -> Block:
        return dichotomy_unit(unit.horner, unit.comp_bits)

    def psi(self, lo: float) -> float:
        return math.acos(min(1.0, lo / 2))

    def realistic_extra(self, unit, rng, a, b, psi, real, count) -> None:
        d = unit.horner
        z = 2 * np.sum(a * b, axis=1)
        real["z"] = np.clip(np.rint((z - float(d.x_format.offset)) * 2.0 ** d.x_format.frac_bits),
                            *d.valid_codes).astype(np.int64)

    def module_lines(self, unit, version, command) -> list[str]:
        d, w, name = unit.horner, unit.comp_bits, unit.module_name
        out = banner(unit, version, command, [
            "dichotomy midpoint M = (N1 + N2) p(z), z = 2 cos(theta) (seed 000, method 4),",
            "and the next level's z' = sqrt(2 + z), bit-for-bit",
            "chebnorm.hw.datapaths.dichotomy_midpoint (product rounded to nearest-even by",
            f"the {d.y_format.frac_bits} fractional bits of p) and dichotomy_next_z (square root "
            "to nearest,",
            "code saturated). M has F fractional bits. Output widths W+c and the constants",
            "were sized for the generated widths."])
        mw = unit.sizes["m_bits"]
        widths = {f"m_{c}": f"W+{mw - w - 1}" for c in "xyz"}
        widths.update({f"n{i}_{c}": "W-1" for i in (1, 2) for c in "xyz"})
        out += ["// Combinational.",
                f"module {name} #(",
                f"    parameter W = {w}",
                ") ("]
        out += ports_decl(unit, widths)
        out += [");"]
        out += [f"    wire [{d.out_bits - 1}:0] y;",
                f"    {d.module_name} poly (.x(z), .y(y));",
                ky_localparam(unit)]
        out += scale_lines(unit, "n1", "n2", "m", "y")
        out += _next_z_lines(unit)
        out += ["endmodule", ""]
        out += isqrt_module(f"{name}_isqrt")
        return out


def _next_z_lines(unit: UnitDesign) -> list[str]:
    """Lines: ``z_next``, the code of ``sqrt(2 + z)`` rounded to nearest, saturated."""
    d, name = unit.horner, unit.module_name
    fx, k0 = d.x_format.frac_bits, d.x_format.offset_code
    xmax = (2 << fx) + k0 + 2 ** d.in_bits - 1
    rad_bits = unsigned_bits(xmax) + fx + 2
    rw = (rad_bits + 1) // 2
    zw = signed_bits(min(-k0, 0), max((1 << rw) - k0, 2 ** d.in_bits)) + 1
    kmax = 2 ** d.in_bits - 1
    return [f"    // z' = sqrt(2 + z): X = 2^{fx + 1} + K0 + z, root of X 2^{fx + 2} to "
            "nearest = (isqrt + 1) >> 1",
            f"    wire [{2 * rw - 1}:0] rad = ({2 * rw}'d{(2 << fx) + k0} + z) << {fx + 2};",
            f"    wire [{rw - 1}:0] r2;",
            f"    {name}_isqrt #(.RW({rw})) sq (.v(rad), .r(r2));",
            f"    wire [{rw}:0] zr = ({{1'b0, r2}} + 1'b1) >> 1;",
            f"    wire signed [{zw - 1}:0] zd = $signed({{1'b0, zr}}) - {signed_literal(k0, zw)};",
            f"    assign z_next = zd[{zw - 1}] ? {d.in_bits}'d0 : (zd > {signed_literal(kmax, zw)}) ? "
            f"{d.in_bits}'d{kmax} : zd[{d.in_bits - 1}:0];"]


register(DichotomyUnit())
