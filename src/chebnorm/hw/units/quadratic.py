"""``"quadratic"``: ``x = N_l.N_r``, ``N_c = (N_l + N_r) p(x)`` and the
coefficients ``G, P, Q`` (seed 000, method 5;
:func:`~chebnorm.hw.datapaths.quadratic_midpoint`), ``p`` the evaluator of a
``1/sqrt(2(1+x))`` table."""

from __future__ import annotations

import math

from ..cost import Block
from ..datapaths import quadratic_midpoint, quadratic_midpoint_unit
from ..fixed import signed_bits
from .base import UnitDesign, put, register, vec, vec_ports
from ..hdl.netlist import Add, Assign, Const, Extend, Group, Mul, Output, Shl, Signal, Sub
from .evaluator import EvaluatorUnit, check_dot, dot_code, scale_lines, scaled_range
from .hdl import banner, evaluator, unit_module

# an implementation module of chebnorm.hw.units: the API is what chebnorm.hw.units exports
__all__: list[str] = []


class QuadraticUnit(EvaluatorUnit):
    """The quadratic-interpolation set-up (see module docstring).

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("quadratic", frac_bits=10, in_bits=10, out_bits=10)
    >>> g = {"nl_x": [1024], "nl_y": [0], "nl_z": [0], "nr_x": [0], "nr_y": [1024], "nr_z": [0]}
    >>> out = u.evaluate(g)
    >>> [int(out[f"g_{c}"][0] + out[f"p_{c}"][0] + out[f"q_{c}"][0]) for c in "xyz"]   # = N_r
    [0, 1024, 0]
    """

    name = "quadratic"
    pair = ("nl", "nr")

    def size(self, f, w, notes, d) -> UnitDesign:
        check_dot(w, f, d)
        lo, hi, yw = scaled_range(w, d)
        mw = signed_bits(lo, hi)
        a, b = -(1 << (w - 1)), (1 << (w - 1)) - 1
        gw = signed_bits(min(4 * a - 4 * hi, 4 * lo - 4 * b), max(4 * b - 4 * lo, 4 * hi - 4 * a))
        ports = (vec_ports("nl", w) + vec_ports("nr", w) + vec_ports("g", gw, True)
                 + vec_ports("p", gw, True) + vec_ports("q", w, True) + vec_ports("nc", mw, True))
        return UnitDesign(self.name, ports, f, w, horner=d,
                          sizes={"m_bits": mw, "yv_bits": yw, "g_bits": gw}, notes=tuple(notes))

    def evaluate(self, unit, g) -> dict:
        G, P, Q, nc = quadratic_midpoint(vec(g, "nl"), vec(g, "nr"), unit.horner, unit.frac_bits)
        out = {}
        put(out, "g", G), put(out, "p", P), put(out, "q", Q), put(out, "nc", nc)
        return out

    def block(self, unit) -> Block:
        return quadratic_midpoint_unit(unit.horner, unit.comp_bits)

    def psi(self, lo: float) -> float:
        return math.acos(min(1.0, lo))

    def unit_netlist(self, unit, version, command):
        d = unit.horner
        gw = unit.sizes["g_bits"]
        m, views = unit_module(unit, banner(unit, version, command, [
            "quadratic-interpolation set-up (seed 000, method 5), bit-for-bit",
            "chebnorm.hw.datapaths.quadratic_midpoint: x = Nl.Nr (exact) to the evaluator's",
            "input code (nearest-even, saturated), Nc = (Nl + Nr) p(x) (nearest-even),",
            "G = 2Nl + 2Nr - 4Nc, P = 4Nc - 3Nl - Nr, Q = Nl (exact), all F fractional bits.",
            "The output widths and the constants were sized for the generated widths."]))
        st = m.statements
        dot, k = dot_code(unit, views, "nl", "nr", "lr")
        st += dot + evaluator(unit, k, "y", "poly")
        st += scale_lines(unit, views, "nl", "nr", "nc", Signal("y", d.out_bits, logic=True))
        mw = unit.sizes["m_bits"]
        for c in "xyz":
            nl, nr = views[f"nl_{c}"], views[f"nr_{c}"]
            nc = Signal(f"nc_{c}_r", mw, signed=True)
            four_nc = Group(Shl(Extend(nc, gw), 2))
            g, p = Signal(f"g_{c}_v", gw, signed=True), Signal(f"p_{c}_v", gw, signed=True)
            st += [Assign(g, Sub(Group(Shl(Add((Extend(nl, gw), nr)), 1)), four_nc)),
                   Assign(p, Sub(Sub(four_nc, Extend(Mul(Const(3, 3), nl), gw)), Extend(nr, gw))),
                   Output(g, port=views[f"g_{c}"]), Output(p, port=views[f"p_{c}"]),
                   Output(nl, port=views[f"q_{c}"])]
        return m


register(QuadraticUnit())
