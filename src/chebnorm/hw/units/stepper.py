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
from ..hdl.verilog import round_lines
from .base import MAX_GUARD, MAX_LOG_M, Port, UnitDesign, UnitKind, put, register, vec, vec_ports
from .hdl import banner, ports_decl

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

    def verilog(self, unit, *, version, command) -> str:
        w, name = unit.comp_bits, unit.module_name
        vb, db = unit.sizes["v_bits"], unit.sizes["d_bits"]
        m = 1 << unit.log_m
        out = banner(unit, version, command, [
            "forward-difference stepper of N(t) = G t^2 + P t + Q (seed 000, method 5),",
            "bit-for-bit chebnorm.hw.datapaths.forward_difference_setup/_codes: on load,",
            "v = Q 2^GUARD, d1 = R((G + P 2^LOG_M) 2^GUARD / 4^LOG_M), d2 = R(2 G 2^GUARD / "
            "4^LOG_M)",
            "(R: nearest-even); then each cycle v += d1, d1 += d2: additions only.",
            f"v has F + GUARD fractional bits; registers sized for m = {m} steps after a load."])
        vdecl = {f"v_{c}": f"{vb - 1}" for c in "xyz"}
        vdecl.update({f"{n}_{c}": "W-1" for n in "gpq" for c in "xyz"})
        out += ["// Clocked: one pixel per rising edge of clk.",
                f"module {name} #(",
                f"    parameter W = {w},",
                f"    parameter LOG_M = {unit.log_m},",
                f"    parameter GUARD = {unit.guard}",
                ") ("]
        out += ports_decl(unit, vdecl)
        out += [");"]
        big = 1 << (w - 1)
        sh1 = 2 * unit.log_m - unit.guard
        aw = max(db, signed_bits(-big * (1 + m), (big - 1) * (1 + m))) + 1
        for c in "xyz":
            out += _component_lines(c, vb, db, aw, sh1)
        out += ["endmodule", ""]
        return "\n".join(out)


def _component_lines(c: str, vb: int, db: int, aw: int, sh1: int) -> list[str]:
    """Registers, set-up and step of component ``c``."""
    out = [f"    reg signed [{vb - 1}:0] v_{c}_r;",
           f"    reg signed [{db - 1}:0] d1_{c}, d2_{c};",
           f"    assign v_{c} = v_{c}_r;",
           f"    wire signed [{aw - 1}:0] a1_{c} = g_{c} + (p_{c} <<< LOG_M);"]
    out += _setup_shift(f"a1_{c}", f"e1_{c}", aw, sh1, db)
    out += [f"    wire signed [{aw - 1}:0] a2_{c} = g_{c};"]
    out += _setup_shift(f"a2_{c}", f"e2_{c}", aw, sh1 - 1, db)
    out += ["    always @(posedge clk)",
            "        if (load) begin",
            f"            v_{c}_r <= q_{c} <<< GUARD;",
            f"            d1_{c} <= e1_{c};",
            f"            d2_{c} <= e2_{c};",
            "        end else begin",
            f"            v_{c}_r <= v_{c}_r + d1_{c};",
            f"            d1_{c} <= d1_{c} + d2_{c};",
            "        end"]
    return out


def _setup_shift(src: str, dst: str, bits: int, sh: int, dst_bits: int) -> list[str]:
    if sh > 0:
        return round_lines(src, dst, bits, sh, dst_bits, "rne")
    return [f"    wire signed [{dst_bits - 1}:0] {dst} = {src} <<< {-sh};"]


register(StepperUnit())
