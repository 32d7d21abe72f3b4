"""``"eta"``: ``eta = 3 - sum g(N_i.N_j)`` and ``skip = eta < thr`` (seed 003;
:func:`~chebnorm.hw.datapaths.eta_criterion`), ``g`` the evaluator of a
``sqrt(2(1+x))/2`` table, instantiated three times."""

from __future__ import annotations

import math

import numpy as np

from ..cost import Block
from ..datapaths import eta_criterion, eta_unit
from ..fixed import check_int64, signed_bits
from ..hdl.netlist import Assign, Compare, ConstDecl, Output, Resize, Signal, Sub, ZeroExt
from .base import Port, UnitDesign, register, vec, vec_ports
from .bench import codes, edges, near
from .evaluator import EvaluatorUnit, check_dot, dot_code
from .hdl import banner, evaluator, unit_module

# an implementation module of chebnorm.hw.units: the API is what chebnorm.hw.units exports
__all__: list[str] = []


class EtaUnit(EvaluatorUnit):
    """The normalization criterion (see module docstring).

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("eta", frac_bits=8, in_bits=10, out_bits=10)
    >>> n = {f"n{v}_{c}": [256 if c == "x" else 0] for v in "abc" for c in "xyz"}
    >>> out = u.evaluate({**n, "thr": [4]})   # three equal normals: eta ~ 0 < thr (codes), skip
    >>> int(out["skip"][0])
    1
    """

    name = "eta"
    pair = ("na", "nb")

    def size(self, f, w, notes, d) -> UnitDesign:
        check_dot(w, f, d)
        fy, ky, ymax = d.y_format.frac_bits, d.y_format.offset_code, d.y_format.max_code
        check_int64(fy + 3, "eta")
        elo, ehi = (3 << fy) - 3 * (ky + ymax), (3 << fy) - 3 * ky
        ew = signed_bits(min(elo, 0), max(ehi, 0))
        ports = (vec_ports("na", w) + vec_ports("nb", w) + vec_ports("nc", w)
                 + (Port("thr", ew, True),)
                 + (Port("eta", ew, True, True), Port("skip", 1, False, True)))
        return UnitDesign(self.name, ports, f, w, horner=d, sizes={"eta_bits": ew},
                          notes=tuple(notes))

    def evaluate(self, unit, g) -> dict:
        eta = eta_criterion(vec(g, "na"), vec(g, "nb"), vec(g, "nc"), unit.horner,
                            unit.frac_bits)
        return {"eta": eta, "skip": (eta < g["thr"]).astype(np.int64)}

    def block(self, unit) -> Block:
        return eta_unit(unit.horner, unit.comp_bits)

    def psi(self, lo: float) -> float:
        return math.acos(min(1.0, max(lo, 0.0)))

    def realistic_extra(self, unit, rng, a, b, psi, real, count) -> None:
        """A third normal ``nc`` near ``na``, and thresholds within 2 codes of eta."""
        c3 = near(rng, a, psi / 2)
        for i, c in enumerate("xyz"):
            real[f"nc_{c}"] = codes(c3[:, i], unit.frac_bits, unit.comp_bits)
        real["thr"] = np.zeros(count, dtype=np.int64)
        eta = unit.evaluate(real)["eta"]
        thr_port = [p for p in unit.inputs if p.name == "thr"][0]
        real["thr"] = np.clip(eta + rng.integers(-2, 3, count),
                              edges(thr_port)[0], edges(thr_port)[-1])

    def unit_netlist(self, unit, version, command):
        d = unit.horner
        ew = unit.sizes["eta_bits"]
        fy, ky = d.y_format.frac_bits, d.y_format.offset_code
        m, views = unit_module(unit, banner(unit, version, command, [
            "normalization criterion eta = 3 - g(Na.Nb) - g(Nb.Nc) - g(Na.Nc) (seed 003)",
            "and skip = eta < thr, bit-for-bit chebnorm.hw.datapaths.eta_criterion: each dot",
            "product exact, to the evaluator's input code (nearest-even, saturated), three",
            f"evaluators, the sum exact; eta and thr have {fy} fractional bits (value code / "
            f"2^{fy}).",
            "The eta width and the constants were sized for the generated widths."]))
        st = m.statements
        ys = []
        for a, b in (("na", "nb"), ("nb", "nc"), ("na", "nc")):
            tag = a[1] + b[1]
            dot, k = dot_code(unit, views, a, b, tag)
            st += dot + evaluator(unit, k, f"y_{tag}", f"poly_{tag}")
            ys.append(ZeroExt(Signal(f"y_{tag}", d.out_bits, logic=True)))
        sw = max(ew + 2, d.out_bits + 1)
        three = Signal("THREE_MINUS_KY", sw, signed=True)
        e, eta = Signal("e", sw, signed=True), Signal("eta_v", ew, signed=True)
        skip = Signal("skip_v", 1, logic=True, scalar=True)
        st += [ConstDecl(three, (3 << fy) - 3 * ky),
               Assign(e, Sub(Sub(Sub(three, ys[0]), ys[1]), ys[2])),
               Assign(eta, Resize(e, ew)),
               Assign(skip, Compare("<", eta, views["thr"])),
               Output(eta, port=views["eta"]), Output(skip, port=views["skip"])]
        return m


register(EtaUnit())
