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
from ..hdl.netlist import (Add, Assign, Comment, Const, Extend, Group, Output, Pad, Shl, Shr,
                           Signal, Sub, ZeroExt)
from .base import Port, UnitDesign, put, register, vec, vec_ports
from .evaluator import EvaluatorUnit, scale_lines, scaled_range
from .hdl import banner, evaluator, isqrt, saturate, unit_module

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

    def unit_netlist(self, unit, version, command):
        d = unit.horner
        m, views = unit_module(unit, banner(unit, version, command, [
            "dichotomy midpoint M = (N1 + N2) p(z), z = 2 cos(theta) (seed 000, method 4),",
            "and the next level's z' = sqrt(2 + z), bit-for-bit",
            "chebnorm.hw.datapaths.dichotomy_midpoint (product rounded to nearest-even by",
            f"the {d.y_format.frac_bits} fractional bits of p) and dichotomy_next_z (square root "
            "to nearest,",
            "code saturated). M has F fractional bits; the output widths and the constants",
            "were sized for the generated widths."]))
        st = m.statements
        st += evaluator(unit, views["z"], "y", "poly")
        st += scale_lines(unit, views, "n1", "n2", "m", Signal("y", d.out_bits, logic=True))
        st += _next_z(unit, views["z"], views["z_next"])
        return m


def _next_z(unit: UnitDesign, z: Signal, port: Signal) -> list:
    """Statements: ``z_next``, the code of ``sqrt(2 + z)`` rounded to nearest, saturated."""
    d = unit.horner
    fx, k0 = d.x_format.frac_bits, d.x_format.offset_code
    xmax = (2 << fx) + k0 + 2 ** d.in_bits - 1
    rad_bits = unsigned_bits(xmax) + fx + 2
    rw = (rad_bits + 1) // 2
    zw = signed_bits(min(-k0, 0), max((1 << rw) - k0, 2 ** d.in_bits)) + 1
    ww = max(zw, rw + 2)
    kmax = 2 ** d.in_bits - 1
    rad, r2 = Signal("rad", 2 * rw), Signal("r2", rw)
    zr, zd = Signal("zr", rw + 1), Signal("zd", ww, signed=True)
    return [Comment(f"z' = sqrt(2 + z): X = 2^{fx + 1} + K0 + z, root of X 2^{fx + 2} to "
                    "nearest = (isqrt + 1) >> 1"),
            Assign(rad, Shl(Group(Add((Const((2 << fx) + k0, 2 * rw, signed=False),
                                       Pad(z, 2 * rw)))), fx + 2)),
            *isqrt(rad, rw, r2.name, "sq_"),
            Assign(zr, Shr(Group(Add((Pad(r2, rw + 1), Const(1, rw + 1, signed=False)))), 1)),
            Assign(zd, Sub(Extend(ZeroExt(zr), ww), Const(k0, ww))),
            *saturate(zd, kmax, d.in_bits, "zn"),
            Output(Signal("zn", d.in_bits), port=port)]


register(DichotomyUnit())
