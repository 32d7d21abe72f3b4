"""``"classic"``: ``N / sqrt(N.N)`` (seed 000), bit-for-bit
:func:`~chebnorm.hw.datapaths.classic_normalize`: dot product, restoring
integer square root, three restoring dividers, floor or nearest-even
quotient; a netlist at the generated widths."""

from __future__ import annotations

import numpy as np

from ..cost import Block
from ..datapaths import classic_normalize, classic_unit
from ..fixed import check_int64
from .base import UnitDesign, UnitKind, put, register, vec, vec_ports
from .bench import codes, combinational_rows
from ..hdl.netlist import (Add, And, Assign, Bit, Comment, Compare, Concat, Const, Extend, Mul,
                           Neg, Or, Paren, ReduceOr, Resize, Select, Signal, Slice, Sub, ZeroExt)
from .hdl import banner, divide, isqrt, output, unit_module

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

    def modules(self, unit, *, version, command) -> list:
        f, w, rne = unit.frac_bits, unit.comp_bits, unit.rounding == "rne"
        m, ports = unit_module(unit, banner(unit, version, command, [
            "classic normalization u = n / sqrt(n.n) (seed 000), bit-for-bit",
            "chebnorm.hw.datapaths.classic_normalize: s = max(isqrt(n.n), 1),",
            f"u_i = (n_i << {f}) / s rounded to "
            f"{'nearest-even' if rne else 'floor'}; the square root and the",
            "dividers restoring, unrolled one result bit per step."]))
        st = m.statements
        st.append(Comment(f"n.n < 3 * 2^{2 * w - 2}: {2 * w + 1} bits; its root < 2^{w}"))
        prods = []
        for c in "xyz":
            n = ports[f"n_{c}"]
            prods.append(Signal(f"sq_{c}", 2 * w, signed=True))
            st.append(Assign(prods[-1], Mul(n, n)))
        dot = Signal("dot", 2 * w + 2, signed=True)
        st.append(Assign(dot, Add(tuple(Extend(p, 2 * w + 2) for p in prods))))
        st += isqrt(dot, w + 1, "root", "sr_")
        root, s = Signal("root", w + 1), Signal("s", w + 1)
        st.append(Assign(s, Select(Compare("==", root, Const(0, w + 1, signed=False)),
                                   Const(1, w + 1, signed=False), root)))
        for c in "xyz":
            st += _component(ports[f"n_{c}"], s, f, w, rne, f"{c}_")
            st += output(ports[f"u_{c}"], Signal(f"{c}_u", f + 2, logic=True))
        return [m]


def _component(n: Signal, s: Signal, f: int, w: int, rne: bool, pre: str) -> list:
    """One component: ``floor(n 2^F / s)``, then nearest-even when ``rne``;
    the result is the bit vector ``<pre>u``."""
    neg = Signal(f"{pre}neg", 1, logic=True, scalar=True)
    nn, mag = Signal(f"{pre}nn", w, signed=True), Signal(f"{pre}mag", w)
    a = Signal(f"{pre}a", w + f, logic=True)
    q, r = Signal(f"{pre}q", w + f), Signal(f"{pre}r", w + 1)
    nz = Signal(f"{pre}nz", 1, logic=True, scalar=True)
    qs, qn = Signal(f"{pre}qs", w + f + 1, signed=True), Signal(f"{pre}qn", w + f + 1, signed=True)
    qf = Signal(f"{pre}qf", w + f + 1, signed=True)
    out = [Comment(f"component {pre[0]}: floor(n 2^{f} / s)"),
           Assign(neg, Bit(n, w - 1)), Assign(nn, Neg(n)),
           Assign(mag, Select(neg, Resize(nn, w, signed=False), Resize(n, w, signed=False))),
           Assign(a, Concat((mag, Const(0, f, signed=False)))),
           *divide(a, s, q.name, r.name, f"{pre}dv_"),
           Assign(nz, ReduceOr(Slice(r, w, 0))),
           Comment("floor of a negative quotient: -(q + 1) when the remainder is not 0"),
           Assign(qs, ZeroExt(q)),
           Assign(qn, Neg(Paren(Add((ZeroExt(q), ZeroExt(nz, qualified=True)))))),
           Assign(qf, Select(neg, qn, qs))]
    u = Signal(f"{pre}u", f + 2, logic=True)
    if not rne:
        return out + [Assign(u, Slice(qf, f + 1, 0))]
    rf, r2, s2 = Signal(f"{pre}rf", w + 1), Signal(f"{pre}r2", w + 2), Signal(f"{pre}s2", w + 2)
    negnz, gt, eq = (Signal(f"{pre}{t}", 1, logic=True, scalar=True) for t in ("negnz", "gt", "eq"))
    inc, ur = Signal(f"{pre}inc", 1, logic=True, scalar=True), Signal(f"{pre}ur", w + f + 1,
                                                                     signed=True)
    return out + [
        Comment("nearest-even: the remainder of the floor quotient against s / 2"),
        Assign(negnz, And(neg, nz)),
        Assign(rf, Select(negnz, Sub(s, r), r)),
        Assign(r2, Concat((rf, Const(0, 1, signed=False)))),
        Assign(s2, Concat((Const(0, 1, signed=False), s))),
        Assign(gt, Compare(">", r2, s2)), Assign(eq, Compare("==", r2, s2)),
        Assign(inc, Or(gt, Paren(And(eq, Bit(qf, 0))))),
        Assign(ur, Add((qf, ZeroExt(inc, qualified=True)))),
        Assign(u, Slice(ur, f + 1, 0))]


register(ClassicUnit())
