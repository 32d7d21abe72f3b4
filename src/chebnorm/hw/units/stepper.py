"""``"stepper"``: the forward-difference stepper (seed 000, method 5),
clocked: on ``load`` it sets up ``v, d1, d2`` from ``G, P, Q`` for
``m = 2^LOG_M`` pixels, then ``v += d1; d1 += d2`` each cycle
(:func:`~chebnorm.hw.datapaths.forward_difference_setup`,
:func:`~chebnorm.hw.datapaths.forward_difference_codes`)."""

from __future__ import annotations

import numpy as np

from ..cost import Block
from ..datapaths import (forward_difference_codes, forward_difference_setup,
                         forward_difference_stepper)
from ..fixed import check_int64, check_width, signed_bits
from ..hdl.datapath import round_to
from ..hdl.netlist import (Add, Assign, Comment, Declare, Extend, Group, Output, Registers, Resize,
                           Select, Shl, Signal)
from .base import MAX_GUARD, MAX_LOG_M, Port, UnitDesign, UnitKind, put, register, vec, vec_ports
from .hdl import banner, unit_module

# an implementation module of chebnorm.hw.units: the API is what chebnorm.hw.units exports
__all__: list[str] = []


class StepperUnit(UnitKind):
    """The forward-difference stepper (see module docstring).

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("stepper", frac_bits=6, log_m=2)
    >>> z = [0] * 5
    >>> rows = {"load": [1, 0, 0, 0, 0], "g_x": [64] * 5, "g_y": z, "g_z": z, "p_x": z, "p_y": z,
    ...         "p_z": z, "q_x": z, "q_y": z, "q_z": z}
    >>> (u.evaluate(rows)["v_x"] / 2 ** (6 + u.guard)).tolist()   # G t^2 at t = 0, 1/4, ..., 1
    [0.0, 0.0625, 0.25, 0.5625, 1.0]
    """

    name = "stepper"
    clocked = True

    def design(self, f, w, notes, *, table, in_bits, out_bits, coef_bits, rounding, log_m,
               guard) -> UnitDesign:
        log_m = check_width(log_m, "log_m", 0, MAX_LOG_M)
        guard = check_width(guard if guard is not None else 2 * log_m, "guard", 0, MAX_GUARD)
        m = 1 << log_m
        big = 1 << (w - 1)
        d1 = -(-((big + big * m) << guard) // (m * m)) + 1
        d2 = -(-((2 * big) << guard) // (m * m)) + 1
        vmax = (big << guard) + m * d1 + m * m * d2
        vb, db = signed_bits(-vmax, vmax), signed_bits(-(d1 + m * d2), d1 + m * d2)
        check_int64(max(vb, db) + 2 * log_m + 1, "the stepper's registers")
        ports = ((Port("load", 1, False),) + vec_ports("g", w) + vec_ports("p", w)
                 + vec_ports("q", w) + vec_ports("v", vb, True))
        return UnitDesign(self.name, ports, f, w, log_m=log_m, guard=guard,
                          sizes={"v_bits": vb, "d_bits": db}, notes=tuple(notes))

    def evaluate(self, unit, g) -> dict:
        v0, d1, d2 = forward_difference_setup(vec(g, "g"), vec(g, "p"), vec(g, "q"), unit.log_m,
                                              unit.guard)
        # each load starts a span: forward_difference_codes gives its pixels
        starts = np.flatnonzero(g["load"]).tolist()
        if not starts or starts[0] != 0:
            raise ValueError("the stepper's first row must load; accepted: load=1 first")
        ends = starts[1:] + [len(g["load"])]
        out = {}
        put(out, "v", np.concatenate([forward_difference_codes(v0[a], d1[a], d2[a], b - a - 1)
                                      for a, b in zip(starts, ends)]))
        return out

    def block(self, unit) -> Block:
        return forward_difference_stepper(unit.comp_bits, unit.guard)

    def vector_rows(self, unit, rng, count) -> dict:
        """Spans of ``m + 1`` rows (a load, then ``m`` steps): the two extreme
        spans (every code at its minimum, then its maximum), then random ones."""
        m, w = 1 << unit.log_m, unit.comp_bits
        spans = -(-count // (m + 1))
        rows = {p.name: [] for p in unit.inputs}
        big = 1 << (w - 1)
        for s in range(spans):
            for j in range(m + 1):
                rows["load"].append(1 if j == 0 else 0)
                for n in ("g", "p", "q"):
                    for c in "xyz":
                        if s < 2:  # extreme spans first: all codes at their ends
                            v = -big if s == 0 else big - 1
                        else:
                            v = int(rng.integers(-big, big))
                        rows[f"{n}_{c}"].append(v)
        return {k: np.array(v, dtype=np.int64) for k, v in rows.items()}

    def modules(self, unit, *, version, command) -> list:
        w = unit.comp_bits
        vb, db = unit.sizes["v_bits"], unit.sizes["d_bits"]
        m = 1 << unit.log_m
        mod, views = unit_module(unit, banner(unit, version, command, [
            "forward-difference stepper of N(t) = G t^2 + P t + Q (seed 000, method 5),",
            "bit-for-bit chebnorm.hw.datapaths.forward_difference_setup/_codes: on load,",
            f"v = Q 2^{unit.guard}, d1 = R((G + P 2^{unit.log_m}) 2^{unit.guard} / 4^{unit.log_m}),"
            f" d2 = R(2 G 2^{unit.guard} / 4^{unit.log_m})",
            "(R: nearest-even); then each cycle v += d1, d1 += d2: additions only.",
            f"v has F + {unit.guard} fractional bits; registers sized for m = {m} steps after a "
            f"load."]))
        big = 1 << (w - 1)
        sh1 = 2 * unit.log_m - unit.guard
        aw = max(db, signed_bits(-big * (1 + m), (big - 1) * (1 + m))) + 1
        for c in "xyz":
            mod.statements += _component(unit, views, c, vb, db, aw, sh1)
        return [mod]


def _component(unit, views: dict, c: str, vb: int, db: int, aw: int, sh1: int) -> list:
    """Set-up, registers and step of component ``c``."""
    g, p, q = views[f"g_{c}"], views[f"p_{c}"], views[f"q_{c}"]
    load = views["load"]
    a1, a2 = Signal(f"a1_{c}", aw, signed=True), Signal(f"a2_{c}", aw, signed=True)
    v, d1, d2 = (Signal(f"{n}_{c}_r", b, signed=True) for n, b in (("v", vb), ("d1", db),
                                                                   ("d2", db)))
    vn, d1n, d2n = (Signal(f"{n}_{c}_next", b, signed=True) for n, b in (("v", vb), ("d1", db),
                                                                         ("d2", db)))
    e1, e2 = Signal(f"e1_{c}", db, signed=True), Signal(f"e2_{c}", db, signed=True)
    return [Comment(f"component {c}: set-up on load, then v += d1, d1 += d2"),
            Declare(v, reg=True), Declare(d1, reg=True), Declare(d2, reg=True),
            Assign(a1, Add((Extend(g, aw), Group(Shl(Extend(p, aw), unit.log_m))))),
            *_setup_shift(a1, e1, sh1),
            Assign(a2, Extend(g, aw)),
            *_setup_shift(a2, e2, sh1 - 1),
            Assign(vn, Select(load, Shl(Extend(q, vb), unit.guard), _sum(v, d1, vb))),
            Assign(d1n, Select(load, e1, _sum(d1, d2, db))),
            Assign(d2n, Select(load, e2, d2)),
            Registers(((v, vn), (d1, d1n), (d2, d2n)), label=f"step_{c}", declare=False),
            Output(v, port=views[f"v_{c}"])]


def _sum(a: Signal, b: Signal, width: int):
    """``a + b`` wrapped to ``width`` bits (``a`` has that width)."""
    if b.width <= width:
        return Add((a, Extend(b, width)) if b.width < width else (a, b))
    return Resize(Add((Extend(a, b.width), b)), width)


def _setup_shift(src: Signal, dst: Signal, sh: int) -> list:
    """``dst = R(src / 2^sh)`` (nearest-even) for ``sh > 0``, else ``src << -sh``."""
    if sh > 0:
        return round_to(src, dst.name, sh, dst.width, "rne")
    if dst.width >= src.width:
        return [Assign(dst, Shl(Extend(src, dst.width), -sh) if sh else Extend(src, dst.width))]
    return [Assign(dst, Resize(Shl(src, -sh), dst.width) if sh else Resize(src, dst.width))]


register(StepperUnit())
