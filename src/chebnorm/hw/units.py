"""Verilog normalization units, bit-for-bit equal to the kernels of
:mod:`chebnorm.hw.datapaths`, with self-checking test benches and costs.

Units (``kind``), each one module ``chebnorm_<kind>_unit``:

* ``"classic"`` -- ``N / sqrt(N.N)`` (:func:`~chebnorm.hw.datapaths.classic_normalize`):
  dot product, restoring integer square root, three restoring dividers,
  floor or nearest-even quotient. Fully parametric (``W``, ``F``, ``RNE``).
* ``"dichotomy"`` -- ``M = (N1 + N2) p(z)`` and ``z' = sqrt(2 + z)``
  (:func:`~chebnorm.hw.datapaths.dichotomy_midpoint`,
  :func:`~chebnorm.hw.datapaths.dichotomy_next_z`), the polynomial ``p``
  the generated evaluator of a ``1/sqrt(2+z)`` table.
* ``"quadratic"`` -- ``x = N_l.N_r``, ``N_c = (N_l + N_r) p(x)`` and the
  coefficients ``G, P, Q`` (:func:`~chebnorm.hw.datapaths.quadratic_midpoint`),
  ``p`` the evaluator of a ``1/sqrt(2(1+x))`` table.
* ``"stepper"`` -- the forward-difference stepper, clocked: on ``load`` it
  sets up ``v, d1, d2`` from ``G, P, Q`` for ``m = 2^LOG_M`` pixels, then
  ``v += d1; d1 += d2`` each cycle
  (:func:`~chebnorm.hw.datapaths.forward_difference_setup`,
  :func:`~chebnorm.hw.datapaths.forward_difference_codes`).
* ``"eta"`` -- ``eta = 3 - sum g(N_i.N_j)`` and ``skip = eta < thr``
  (:func:`~chebnorm.hw.datapaths.eta_criterion`), ``g`` the evaluator of a
  ``sqrt(2(1+x))/2`` table, instantiated three times.

Vector components are signed ``W``-bit codes with ``F`` fractional bits
(``W = F + 2`` holds ``[-2, 2)``; unit vectors need ``W >= F + 2``), ports
``<name>_x``, ``<name>_y``, ``<name>_z``.

Widths: ``W`` (and ``F``, ``RNE``, ``LOG_M``, ``GUARD``) are Verilog
parameters. In the classic unit every width inside is an expression of them.
In the others the evaluator's constants, the output offsets and the output
widths (written ``W+c``) were sized for the generated widths, exactly, from
the extremes of every input code: regenerate to change them. Every output
is wide enough to hold the kernel's exact result for *every* input code,
so the model and the circuit agree everywhere, not only on unit normals.

The test bench reads rows ``{inputs, expected outputs}`` made by the Python
kernels (seeded random vectors, realistic normals, edge cases; every input
code when the inputs have at most 16 bits) from ``chebnorm_<kind>_unit.hex``
and prints one ``PASS:``/``FAIL:`` line.

>>> u = design_unit("classic", frac_bits=3, comp_bits=5)
>>> [(p.name, p.bits) for p in u.ports]
[('n_x', 5), ('n_y', 5), ('n_z', 5), ('u_x', 5), ('u_y', 5), ('u_z', 5)]
>>> u.evaluate({"n_x": np.array([6]), "n_y": np.array([8]), "n_z": np.array([0])})["u_x"]
array([4])
"""

from __future__ import annotations

import math
import shutil
from dataclasses import dataclass, field

import numpy as np

from chebnorm.approx import CoefficientTable, fit_target

from .cost import Block
from .datapaths import (classic_normalize, classic_unit, dichotomy_midpoint, dichotomy_next_z,
                        dichotomy_unit, eta_criterion, eta_unit, forward_difference_setup,
                        forward_difference_codes, forward_difference_stepper,
                        quadratic_midpoint, quadratic_midpoint_unit)
from .fixed import check_int64, check_width, shift_round, signed_bits, unsigned_bits
from .horner import HornerDesign, design_horner
from .verilog import SynthResult, _lit, _round, synthesize_text, verilog_module

__all__ = ["UNIT_KINDS", "UNIT_TARGETS", "table_matches", "Port", "UnitDesign", "UnitReport", "design_unit",
           "unit_vectors", "unit_verilog", "unit_testbench", "unit_vector_file",
           "unit_outputs", "analyze_unit", "MAX_COMP_BITS", "MAX_UNIT_FRAC_BITS"]

UNIT_KINDS = ("dichotomy", "classic", "quadratic", "stepper", "eta")
#: the coefficient-table target each unit's polynomial evaluator approximates
UNIT_TARGETS = {"dichotomy": "dichotomy", "quadratic": "midpoint", "eta": "eta_term"}
MAX_COMP_BITS = 28
MAX_UNIT_FRAC_BITS = 26
MAX_LOG_M = 10
MAX_GUARD = 24
#: input spaces up to this many bits are tested exhaustively
EXHAUSTIVE_BITS = 16


@dataclass(frozen=True)
class Port:
    """One port: ``bits`` wide, two's complement when ``signed``."""

    name: str
    bits: int
    signed: bool = True
    output: bool = False


def _vec(name: str, bits: int, output: bool = False, signed: bool = True) -> tuple[Port, ...]:
    return tuple(Port(f"{name}_{c}", bits, signed, output) for c in "xyz")


@dataclass(frozen=True)
class UnitDesign:
    """A sized normalization unit (see module docstring); ``evaluate`` is the
    bit-accurate model, :func:`unit_verilog` its circuit."""

    kind: str
    ports: tuple[Port, ...]
    frac_bits: int
    comp_bits: int
    horner: HornerDesign | None = None
    rounding: str = "rne"
    log_m: int = 0
    guard: int = 0
    sizes: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    @property
    def module_name(self) -> str:
        return f"chebnorm_{self.kind}_unit"

    @property
    def clocked(self) -> bool:
        return self.kind == "stepper"

    @property
    def inputs(self) -> tuple[Port, ...]:
        return tuple(p for p in self.ports if not p.output)

    @property
    def outputs(self) -> tuple[Port, ...]:
        return tuple(p for p in self.ports if p.output)

    @property
    def block(self) -> Block:
        """The cost model of the unit (:mod:`chebnorm.hw.datapaths`)."""
        w = self.comp_bits
        if self.kind == "classic":
            return classic_unit(w, self.frac_bits)
        if self.kind == "dichotomy":
            return dichotomy_unit(self.horner, w)
        if self.kind == "quadratic":
            return quadratic_midpoint_unit(self.horner, w)
        if self.kind == "stepper":
            return forward_difference_stepper(w, self.guard)
        return eta_unit(self.horner, w)

    def evaluate(self, inputs: dict) -> dict:
        """Outputs (name -> int64 array) for input arrays (name -> codes); for the
        clocked stepper, one row per cycle, outputs as seen after each edge."""
        g = {k: np.asarray(v, dtype=np.int64) for k, v in inputs.items()}
        vec = lambda n: np.stack([g[f"{n}_{c}"] for c in "xyz"], axis=-1)
        out = {}

        def put(name, arr):
            for i, c in enumerate("xyz"):
                out[f"{name}_{c}"] = arr[..., i]
        if self.kind == "classic":
            put("u", classic_normalize(vec("n"), self.frac_bits, self.rounding))
        elif self.kind == "dichotomy":
            put("m", dichotomy_midpoint(vec("n1"), vec("n2"), g["z"], self.horner,
                                        self.frac_bits))
            out["z_next"] = dichotomy_next_z(g["z"], self.horner)
        elif self.kind == "quadratic":
            G, P, Q, nc = quadratic_midpoint(vec("nl"), vec("nr"), self.horner, self.frac_bits)
            put("g", G), put("p", P), put("q", Q), put("nc", nc)
        elif self.kind == "eta":
            eta = eta_criterion(vec("na"), vec("nb"), vec("nc"), self.horner, self.frac_bits)
            out["eta"], out["skip"] = eta, (eta < g["thr"]).astype(np.int64)
        else:
            v0, d1, d2 = forward_difference_setup(vec("g"), vec("p"), vec("q"), self.log_m,
                                                  self.guard)
            # each load starts a span: forward_difference_codes gives its pixels
            starts = np.flatnonzero(g["load"]).tolist()
            if not starts or starts[0] != 0:
                raise ValueError("the stepper's first row must load; accepted: load=1 first")
            ends = starts[1:] + [len(g["load"])]
            put("v", np.concatenate([forward_difference_codes(v0[a], d1[a], d2[a], b - a - 1)
                                     for a, b in zip(starts, ends)]))
        return out


def _check_kind(kind: str) -> str:
    if kind not in UNIT_KINDS:
        raise ValueError(f"unit {kind!r} is unknown; accepted: {', '.join(UNIT_KINDS)}")
    return kind


def table_matches(kind: str, table: CoefficientTable) -> bool:
    """True when ``table`` approximates the function of unit ``kind``'s target
    (:data:`UNIT_TARGETS`), whatever its variable is called."""
    import sympy as sp

    from chebnorm.approx import get_target, parse_function

    target = get_target(UNIT_TARGETS[kind])
    want = parse_function(target.expression, target.variable)
    have = parse_function(table.expression, table.variable)
    return sp.simplify(have.expr.subs(have.var, want.var) - want.expr) == 0


def _unit_horner(kind: str, table, in_bits, out_bits, coef_bits, rounding) -> HornerDesign:
    if table is None:
        table = fit_target(UNIT_TARGETS[kind], 2)
        coef_bits = coef_bits if coef_bits is not None else min(out_bits + 4, 30)
    if not isinstance(table, CoefficientTable):
        raise ValueError(f"table {table!r} is not a CoefficientTable; accepted: a loaded table")
    if not table_matches(kind, table):
        from chebnorm.approx import get_target

        target = get_target(UNIT_TARGETS[kind])
        raise ValueError(f"table {table.name!r} approximates {table.expression}, but unit {kind!r} "
                         f"needs {target.expression} (target {target.name!r}); accepted: a table "
                         f"of that function")
    try:
        d = design_horner(table, in_bits, out_bits, coef_bits=coef_bits, rounding=rounding,
                          name=table.name)
    except ValueError as e:
        raise ValueError(f"the evaluator of unit {kind!r}: {e}") from None
    if d.x_format.frac_bits < 0 or d.y_format.frac_bits < 1:
        raise ValueError(f"unit {kind!r} needs an input format with >= 0 and an output with "
                         f">= 1 fractional bits; table {table.name!r} gives "
                         f"{d.x_format.frac_bits} and {d.y_format.frac_bits}; accepted: more "
                         f"input or output bits")
    return d


def _rne_range(lo: int, hi: int, shift: int) -> tuple[int, int]:
    return int(shift_round(lo, shift, "rne")), int(shift_round(hi, shift, "rne"))


def _scaled_range(w: int, d: HornerDesign) -> tuple[int, int, int]:
    """Range of ``R((N1 + N2) (y + KY))`` over every code, and the width of ``y + KY``."""
    ky, ymax, fy = d.y_format.offset_code, d.y_format.max_code, d.y_format.frac_bits
    yv = (ky, ky + ymax)
    s = (-(1 << w), (1 << w) - 2)
    prods = [a * b for a in s for b in yv]
    check_int64(signed_bits(min(prods), max(prods)), "the midpoint product (N1 + N2) * p")
    lo, hi = _rne_range(min(prods), max(prods), fy)
    return lo, hi, signed_bits(min(yv[0], 0), yv[1])


def _dot_range(w: int) -> tuple[int, int]:
    a, b = -(1 << (w - 1)), (1 << (w - 1)) - 1
    return 3 * a * b, 3 * a * a


def design_unit(kind: str, *, frac_bits: int = 14, comp_bits: int | None = None,
                table: CoefficientTable | None = None, in_bits: int = 16,
                out_bits: int = 16, coef_bits: int | None = None, rounding: str | None = None,
                log_m: int = 4, guard: int | None = None) -> UnitDesign:
    """Size unit ``kind`` (:data:`UNIT_KINDS`) for ``F = frac_bits`` fractional
    bits and ``W = comp_bits`` (default ``F + 2``) bit components.

    ``table`` (with ``in_bits``, ``out_bits``, ``coef_bits``, ``rounding``)
    makes the polynomial evaluator of the dichotomy, quadratic and eta units;
    without it the degree-2 table of :data:`UNIT_TARGETS` is fitted (psi_max
    = pi/4) and quantized to ``out_bits + 4`` bits. ``rounding`` is the
    classic unit's quotient rounding (``"trunc"``, default, or ``"rne"``) or
    the evaluator's. ``log_m`` and ``guard`` (default ``2 log_m``, exact
    set-up) size the stepper. Raises ValueError naming the accepted range.
    """
    _check_kind(kind)
    f = check_width(frac_bits, "frac-bits", 1, MAX_UNIT_FRAC_BITS)
    w = check_width(comp_bits if comp_bits is not None else f + 2, "comp-bits", 2, MAX_COMP_BITS)
    notes = []
    if w < f + 2:
        notes.append(f"comp-bits {w} < frac-bits + 2 = {f + 2}: +1.0 is not representable")
    if kind == "classic":
        rounding = rounding or "trunc"
        if rounding not in ("trunc", "rne"):
            raise ValueError(f"rounding {rounding!r} is unknown; accepted: trunc, rne")
        check_int64(w + f, "the classic unit's dividend N << F")
        ports = _vec("n", w) + _vec("u", f + 2, True)
        return UnitDesign(kind, ports, f, w, rounding=rounding, notes=tuple(notes))
    if kind == "stepper":
        log_m = check_width(log_m, "log-m", 0, MAX_LOG_M)
        guard = check_width(guard if guard is not None else 2 * log_m, "guard", 0, MAX_GUARD)
        m = 1 << log_m
        big = 1 << (w - 1)
        d1 = -(-((big + big * m) << guard) // (m * m)) + 1
        d2 = -(-((2 * big) << guard) // (m * m)) + 1
        vmax = (big << guard) + m * d1 + m * m * d2
        vb, db = signed_bits(-vmax, vmax), signed_bits(-(d1 + m * d2), d1 + m * d2)
        check_int64(max(vb, db) + 2 * log_m + 1, "the stepper's registers")
        ports = ((Port("load", 1, False),) + _vec("g", w) + _vec("p", w) + _vec("q", w)
                 + _vec("v", vb, True))
        return UnitDesign(kind, ports, f, w, log_m=log_m, guard=guard,
                          sizes={"v_bits": vb, "d_bits": db}, notes=tuple(notes))
    d = _unit_horner(kind, table, in_bits, out_bits, coef_bits, rounding or "rne")
    if kind == "dichotomy":
        lo, hi, yw = _scaled_range(w, d)
        mw = signed_bits(lo, hi)
        ports = _vec("n1", w) + _vec("n2", w) + (Port("z", d.in_bits, False),) + \
            _vec("m", mw, True) + (Port("z_next", d.in_bits, False, True),)
        return UnitDesign(kind, ports, f, w, horner=d, sizes={"m_bits": mw, "yv_bits": yw},
                          notes=tuple(notes))
    dlo, dhi = _dot_range(w)
    check_int64(signed_bits(dlo, dhi) + max(0, d.x_format.frac_bits - 2 * f), "the dot product")
    if kind == "quadratic":
        lo, hi, yw = _scaled_range(w, d)
        mw = signed_bits(lo, hi)
        a, b = -(1 << (w - 1)), (1 << (w - 1)) - 1
        gw = signed_bits(min(4 * a - 4 * hi, 4 * lo - 4 * b), max(4 * b - 4 * lo, 4 * hi - 4 * a))
        ports = (_vec("nl", w) + _vec("nr", w) + _vec("g", gw, True) + _vec("p", gw, True)
                 + _vec("q", w, True) + _vec("nc", mw, True))
        return UnitDesign(kind, ports, f, w, horner=d,
                          sizes={"m_bits": mw, "yv_bits": yw, "g_bits": gw}, notes=tuple(notes))
    fy, ky, ymax = d.y_format.frac_bits, d.y_format.offset_code, d.y_format.max_code
    check_int64(fy + 3, "eta")
    elo, ehi = (3 << fy) - 3 * (ky + ymax), (3 << fy) - 3 * ky
    ew = signed_bits(min(elo, 0), max(ehi, 0))
    ports = (_vec("na", w) + _vec("nb", w) + _vec("nc", w) + (Port("thr", ew, True),)
             + (Port("eta", ew, True, True), Port("skip", 1, False, True)))
    return UnitDesign(kind, ports, f, w, horner=d, sizes={"eta_bits": ew}, notes=tuple(notes))


# -- test vectors ---------------------------------------------------------------------

def _unit_normals(rng, n: int, f: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _near(rng, a: np.ndarray, psi: float) -> np.ndarray:
    """Unit vectors at angles in [0, psi] from the rows of ``a``."""
    t = rng.normal(size=a.shape)
    t -= np.sum(t * a, axis=1, keepdims=True) * a
    t /= np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-300)
    th = rng.uniform(0, psi, (len(a), 1))
    th[:4, 0] = [0.0, psi, psi / 2, 1e-3][:len(a)]
    return a * np.cos(th) + t * np.sin(th)


def _codes(v: np.ndarray, f: int, w: int) -> np.ndarray:
    return np.clip(np.rint(v * 2.0 ** f), -(1 << (w - 1)), (1 << (w - 1)) - 1).astype(np.int64)


def _rand(rng, n: int, port: Port) -> np.ndarray:
    lo = -(1 << (port.bits - 1)) if port.signed else 0
    hi = (1 << (port.bits - 1)) if port.signed else (1 << port.bits)
    return rng.integers(lo, hi, n, dtype=np.int64)


def _edges(port: Port) -> list[int]:
    if port.signed:
        b = port.bits
        return sorted({-(1 << (b - 1)), -1, 0, 1, (1 << (b - 1)) - 1})
    return sorted({0, 1, (1 << port.bits) - 1})


def unit_vectors(unit: UnitDesign, count: int = 2000, seed: int = 0) -> dict:
    """Input rows (name -> int64 array) for the test bench of ``unit``: every
    input code when the inputs have at most 16 bits; else edge cases (each
    input takes each of its extreme codes -- min, -1, 0, 1, max -- while the
    others cycle through theirs), ``count`` realistic rows
    (quantized unit normals at angles inside the table's interval, and
    their ``z``/threshold) and ``count`` rows of uniformly random codes."""
    count = check_width(count, "vectors", 1, 10 ** 6)
    rng = np.random.default_rng(seed)
    ins = unit.inputs
    f, w = unit.frac_bits, unit.comp_bits
    if unit.clocked:
        return _stepper_rows(unit, rng, -(-count // ((1 << unit.log_m) + 1)))
    if sum(p.bits for p in ins) <= EXHAUSTIVE_BITS:
        grids = np.meshgrid(*[np.arange(_edges(p)[0], _edges(p)[-1] + 1) for p in ins],
                            indexing="ij")
        return {p.name: g.ravel().astype(np.int64) for p, g in zip(ins, grids)}
    rows = {p.name: [] for p in ins}

    def add(d):
        for k in rows:
            rows[k].append(np.asarray(d[k], dtype=np.int64))
    # edge cases: each input takes each of its extreme codes, the others cycle through theirs
    edges = [_edges(p) for p in ins]
    n_edge = max(len(e) for e in edges) * 8
    for j in range(n_edge):
        add({p.name: [e[(j + i * (j // len(e) + 1)) % len(e)]] for i, (p, e) in
             enumerate(zip(ins, edges))})
    # realistic rows
    a = _unit_normals(rng, count, f)
    real = {}
    if unit.kind == "classic":
        n = a * rng.uniform(0.5, 1.0, (count, 1))
        n[:6] = np.eye(3).repeat(2, 0)[:6] * np.array([1, -1] * 3)[:, None]
        for i, c in enumerate("xyz"):
            real[f"n_{c}"] = _codes(n[:, i], f, w)
    else:
        d = unit.horner
        lo = float(d.table.interval[0]) if _isfloat(d.table.interval[0]) else \
            float(d.x_format.value(d.valid_codes[0]))
        psi = {"dichotomy": math.acos(min(1.0, lo / 2)), "quadratic": math.acos(min(1.0, lo)),
               "eta": math.acos(min(1.0, max(lo, 0.0)))}[unit.kind]
        b = _near(rng, a, psi)
        names = {"dichotomy": ("n1", "n2"), "quadratic": ("nl", "nr"), "eta": ("na", "nb")}
        for i, c in enumerate("xyz"):
            real[f"{names[unit.kind][0]}_{c}"] = _codes(a[:, i], f, w)
            real[f"{names[unit.kind][1]}_{c}"] = _codes(b[:, i], f, w)
        if unit.kind == "dichotomy":
            z = 2 * np.sum(a * b, axis=1)
            real["z"] = np.clip(np.rint((z - float(d.x_format.offset)) * 2.0 ** d.x_format.frac_bits),
                                *d.valid_codes).astype(np.int64)
        if unit.kind == "eta":
            c3 = _near(rng, a, psi / 2)
            for i, c in enumerate("xyz"):
                real[f"nc_{c}"] = _codes(c3[:, i], f, w)
            real["thr"] = np.zeros(count, dtype=np.int64)
            eta = unit.evaluate(real)["eta"]
            real["thr"] = eta + rng.integers(-2, 3, count)
            thr_port = [p for p in ins if p.name == "thr"][0]
            real["thr"] = np.clip(real["thr"], *(_edges(thr_port)[0], _edges(thr_port)[-1]))
    add(real)
    add({p.name: _rand(rng, count, p) for p in ins})
    return {k: np.concatenate(v) for k, v in rows.items()}


def _isfloat(s) -> bool:
    try:
        float(s)
        return True
    except (TypeError, ValueError):
        return False


def _stepper_rows(unit: UnitDesign, rng, spans: int) -> dict:
    m, w = 1 << unit.log_m, unit.comp_bits
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


# -- Verilog ----------------------------------------------------------------------------

def _ports_decl(unit: UnitDesign, widths: dict) -> list[str]:
    lines = []
    if unit.clocked:
        lines.append("    input  wire clk,")
    ports = unit.ports
    for i, p in enumerate(ports):
        sgn = "signed " if p.signed and p.bits > 1 else ""
        rng_ = widths.get(p.name, f"{p.bits - 1}")
        decl = f"[{rng_}:0] " if p.bits > 1 else ""
        lines.append(f"    {'output' if p.output else 'input '} wire {sgn}{decl}{p.name}"
                     f"{',' if i < len(ports) - 1 else ''}")
    return lines


def _isqrt_module(name: str) -> list[str]:
    return [
        f"// {name}: floor(sqrt(v)), restoring, one result bit per step (combinational).",
        f"module {name} #(parameter RW = 8) (",
        "    input  wire [2*RW-1:0] v,",
        "    output reg  [RW-1:0]   r",
        ");",
        "    reg [RW+1:0] rem, trial;",
        "    integer i;",
        "    always @* begin",
        "        rem = 0;",
        "        r = 0;",
        "        for (i = RW - 1; i >= 0; i = i - 1) begin",
        "            rem = {rem[RW-1:0], v[2*i+1], v[2*i]};",
        "            trial = {r, 2'b01};",
        "            if (rem >= trial) begin",
        "                rem = rem - trial;",
        "                r = (r << 1) | 1'b1;",
        "            end else",
        "                r = r << 1;",
        "        end",
        "    end",
        "endmodule", ""]


def _div_module(name: str) -> list[str]:
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


def _banner(unit: UnitDesign, version: str, command: str | None, what: list[str]) -> list[str]:
    lines = [f"// {unit.module_name}: {what[0]}", *[f"//   {w}" for w in what[1:]],
             f"// Generated by chebnorm {version}; do not edit."]
    if command:
        lines.append(f"// Command: {command}")
    lines.append(f"// Components: signed W = {unit.comp_bits}-bit codes, value = code / 2^"
                 f"{unit.frac_bits} (F = {unit.frac_bits}); ports <name>_x, _y, _z.")
    if unit.horner is not None:
        d = unit.horner
        xf, yf = d.x_format, d.y_format
        lines += [f"// Evaluator {d.module_name} (below): p ~ {d.table.expression} on "
                  f"[{d.table.interval[0]}, {d.table.interval[1]}], degree {d.degree};",
                  f"//   x code k -> {float(xf.offset)!r} + k / 2^{xf.frac_bits}, y code k -> "
                  f"{float(yf.offset)!r} + k / 2^{yf.frac_bits}."]
    for n in unit.notes:
        lines.append(f"// Note: {n}")
    return lines


def _dot_code(unit: UnitDesign, a: str, b: str, tag: str) -> list[str]:
    """Lines: the exact dot product of vectors ``a``, ``b`` and its input code ``k_tag``."""
    d, f, w = unit.horner, unit.frac_bits, unit.comp_bits
    fx, k0, kmax = d.x_format.frac_bits, d.x_format.offset_code, 2 ** d.in_bits - 1
    dlo, dhi = _dot_range(w)
    dw = signed_bits(dlo, dhi)
    lines = [f"    wire signed [{dw - 1}:0] dot_{tag} = {a}_x * {b}_x + {a}_y * {b}_y + "
             f"{a}_z * {b}_z;"]
    sh = 2 * f - fx
    if sh > 0:
        rlo, rhi = _rne_range(dlo, dhi, sh)
        rw = signed_bits(rlo, rhi)
        lines += _round(f"dot_{tag}", f"dr_{tag}", dw, sh, rw, "rne")
    else:
        rlo, rhi = dlo << -sh, dhi << -sh
        rw = signed_bits(rlo, rhi)
        lines.append(f"    wire signed [{rw - 1}:0] dr_{tag} = dot_{tag} <<< {-sh};")
    cw = signed_bits(min(rlo - k0, 0), max(rhi - k0, kmax)) + 1
    lines += [f"    wire signed [{cw - 1}:0] dc_{tag} = dr_{tag} - {_lit(k0, cw)};",
              f"    wire [{d.in_bits - 1}:0] k_{tag} = dc_{tag}[{cw - 1}] ? {d.in_bits}'d0 : "
              f"(dc_{tag} > {_lit(kmax, cw)}) ? {d.in_bits}'d{kmax} : dc_{tag}[{d.in_bits - 1}:0];"]
    return lines


def _scale_lines(unit: UnitDesign, a: str, b: str, out: str, ycode: str) -> list[str]:
    """Lines: ``out_c = R((a_c + b_c) * (ycode + KY))`` for c in x, y, z."""
    d, w = unit.horner, unit.comp_bits
    yw, mw, fy = unit.sizes["yv_bits"], unit.sizes["m_bits"], d.y_format.frac_bits
    lines = [f"    wire signed [{yw - 1}:0] yv = $signed({{1'b0, {ycode}}}) + KY;"]
    for c in "xyz":
        lines += [f"    wire signed [W:0] s_{c} = {a}_{c} + {b}_{c};",
                  f"    wire signed [W+{yw}:0] t_{c} = s_{c} * yv;"]
        lines += _round(f"t_{c}", f"{out}_{c}_r", w + 1 + yw, fy, mw, "rne")
        lines.append(f"    assign {out}_{c} = {out}_{c}_r;")
    return lines


def unit_verilog(unit: UnitDesign, *, version: str = "", command: str | None = None) -> str:
    """The synthesizable Verilog-2005 text of ``unit``: the unit module, then
    its helper modules (square root, divider, polynomial evaluator)."""
    k, w, f = unit.kind, unit.comp_bits, unit.frac_bits
    name = unit.module_name
    d = unit.horner
    if k == "classic":
        out = _banner(unit, version, command, [
            "classic normalization u = n / sqrt(n.n) (seed 000), bit-for-bit",
            "chebnorm.hw.datapaths.classic_normalize: s = max(isqrt(n.n), 1),",
            "u_i = (n_i << F) / s rounded to floor (RNE = 0) or nearest-even (RNE = 1).",
            "Every width below is an expression of the parameters W, F (W >= 2, F >= 1)."])
        out += ["// Combinational.",
                f"module {name} #(",
                f"    parameter W = {w},",
                f"    parameter F = {f},",
                f"    parameter RNE = {int(unit.rounding == 'rne')}",
                ") ("]
        out += _ports_decl(unit, {"n_x": "W-1", "n_y": "W-1", "n_z": "W-1",
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
        out += ["endmodule", "",
                f"// {name}_comp: one component, floor(n 2^F / s), then nearest-even if RNE.",
                f"module {name}_comp #(parameter W = 16, parameter F = 14, parameter RNE = 0) (",
                "    input  wire signed [W-1:0] n,",
                "    input  wire [W:0]          s,",
                "    output wire signed [F+1:0] u",
                ");",
                "    wire neg = n[W-1];",
                "    wire [W-1:0] mag = neg ? -n : n;",
                "    wire [W+F-1:0] q;",
                "    wire [W:0] r;",
                f"    {name}_div #(.NB(W + F), .DB(W + 1)) dv (.a({{mag, {{F{{1'b0}}}}}}), "
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
        out += _isqrt_module(f"{name}_isqrt") + _div_module(f"{name}_div")
        return "\n".join(out)
    if k == "stepper":
        vb, db = unit.sizes["v_bits"], unit.sizes["d_bits"]
        m = 1 << unit.log_m
        out = _banner(unit, version, command, [
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
        out += _ports_decl(unit, vdecl)
        out += [");"]
        big = 1 << (w - 1)
        sh1 = 2 * unit.log_m - unit.guard
        sh2 = sh1 - 1
        aw = max(db, signed_bits(-big * (1 + m), (big - 1) * (1 + m))) + 1
        for c in "xyz":
            out += [f"    reg signed [{vb - 1}:0] v_{c}_r;",
                    f"    reg signed [{db - 1}:0] d1_{c}, d2_{c};",
                    f"    assign v_{c} = v_{c}_r;",
                    f"    wire signed [{aw - 1}:0] a1_{c} = g_{c} + (p_{c} <<< LOG_M);"]
            out += _setup_shift(f"a1_{c}", f"e1_{c}", aw, sh1, db)
            out += [f"    wire signed [{aw - 1}:0] a2_{c} = g_{c};"]
            out += _setup_shift(f"a2_{c}", f"e2_{c}", aw, sh2, db)
            out += ["    always @(posedge clk)",
                    "        if (load) begin",
                    f"            v_{c}_r <= q_{c} <<< GUARD;",
                    f"            d1_{c} <= e1_{c};",
                    f"            d2_{c} <= e2_{c};",
                    "        end else begin",
                    f"            v_{c}_r <= v_{c}_r + d1_{c};",
                    f"            d1_{c} <= d1_{c} + d2_{c};",
                    "        end"]
        out += ["endmodule", ""]
        return "\n".join(out)
    # units with an evaluator
    ev = verilog_module(d, version=version).replace("\n// Generated by", "\n// Generated by", 1)
    if k == "dichotomy":
        xf = d.x_format
        fx, k0 = xf.frac_bits, xf.offset_code
        xmax = (2 << fx) + k0 + 2 ** d.in_bits - 1
        rad_bits = unsigned_bits(xmax) + fx + 2
        rw = (rad_bits + 1) // 2
        zw = signed_bits(min(-k0, 0), max((1 << rw) - k0, 2 ** d.in_bits)) + 1
        kmax = 2 ** d.in_bits - 1
        out = _banner(unit, version, command, [
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
        out += _ports_decl(unit, widths)
        out += [");"]
        out += [f"    wire [{d.out_bits - 1}:0] y;",
                f"    {d.module_name} poly (.x(z), .y(y));",
                f"    localparam signed [{unit.sizes['yv_bits'] - 1}:0] KY = "
                f"{_lit(d.y_format.offset_code, unit.sizes['yv_bits'])};"]
        out += _scale_lines(unit, "n1", "n2", "m", "y")
        out += [f"    // z' = sqrt(2 + z): X = 2^{fx + 1} + K0 + z, root of X 2^{fx + 2} to "
                "nearest = (isqrt + 1) >> 1",
                f"    wire [{2 * rw - 1}:0] rad = ({2 * rw}'d{(2 << fx) + k0} + z) << {fx + 2};",
                f"    wire [{rw - 1}:0] r2;",
                f"    {name}_isqrt #(.RW({rw})) sq (.v(rad), .r(r2));",
                f"    wire [{rw}:0] zr = ({{1'b0, r2}} + 1'b1) >> 1;",
                f"    wire signed [{zw - 1}:0] zd = $signed({{1'b0, zr}}) - {_lit(k0, zw)};",
                f"    assign z_next = zd[{zw - 1}] ? {d.in_bits}'d0 : (zd > {_lit(kmax, zw)}) ? "
                f"{d.in_bits}'d{kmax} : zd[{d.in_bits - 1}:0];",
                "endmodule", ""]
        out += _isqrt_module(f"{name}_isqrt")
        return "\n".join(out) + ev
    if k == "quadratic":
        mw, gw = unit.sizes["m_bits"], unit.sizes["g_bits"]
        out = _banner(unit, version, command, [
            "quadratic-interpolation set-up (seed 000, method 5), bit-for-bit",
            "chebnorm.hw.datapaths.quadratic_midpoint: x = Nl.Nr (exact) to the evaluator's",
            "input code (nearest-even, saturated), Nc = (Nl + Nr) p(x) (nearest-even),",
            "G = 2Nl + 2Nr - 4Nc, P = 4Nc - 3Nl - Nr, Q = Nl (exact), all F fractional bits.",
            "Output widths W+c and the constants were sized for the generated widths."])
        widths = {f"{n}_{c}": "W-1" for n in ("nl", "nr", "q") for c in "xyz"}
        widths.update({f"nc_{c}": f"W+{mw - w - 1}" for c in "xyz"})
        widths.update({f"{n}_{c}": f"W+{gw - w - 1}" for n in "gp" for c in "xyz"})
        out += ["// Combinational.", f"module {name} #(", f"    parameter W = {w}", ") ("]
        out += _ports_decl(unit, widths)
        out += [");"]
        out += _dot_code(unit, "nl", "nr", "lr")
        out += [f"    wire [{d.out_bits - 1}:0] y;",
                f"    {d.module_name} poly (.x(k_lr), .y(y));",
                f"    localparam signed [{unit.sizes['yv_bits'] - 1}:0] KY = "
                f"{_lit(d.y_format.offset_code, unit.sizes['yv_bits'])};"]
        out += _scale_lines(unit, "nl", "nr", "nc", "y")
        for c in "xyz":
            out += [f"    assign g_{c} = ((nl_{c} + nr_{c}) <<< 1) - (nc_{c} <<< 2);",
                    f"    assign p_{c} = (nc_{c} <<< 2) - 3 * nl_{c} - nr_{c};",
                    f"    assign q_{c} = nl_{c};"]
        out += ["endmodule", ""]
        return "\n".join(out) + ev
    # eta
    ew = unit.sizes["eta_bits"]
    fy, ky = d.y_format.frac_bits, d.y_format.offset_code
    out = _banner(unit, version, command, [
        "normalization criterion eta = 3 - g(Na.Nb) - g(Nb.Nc) - g(Na.Nc) (seed 003)",
        "and skip = eta < thr, bit-for-bit chebnorm.hw.datapaths.eta_criterion: each dot",
        "product exact, to the evaluator's input code (nearest-even, saturated), three",
        f"evaluators, the sum exact; eta and thr have {fy} fractional bits (value code / 2^{fy}).",
        "The eta width and the constants were sized for the generated widths."])
    widths = {f"{n}_{c}": "W-1" for n in ("na", "nb", "nc") for c in "xyz"}
    out += ["// Combinational.", f"module {name} #(", f"    parameter W = {w}", ") ("]
    out += _ports_decl(unit, widths)
    out += [");"]
    sw = ew + 2
    terms = []
    for a, b in (("na", "nb"), ("nb", "nc"), ("na", "nc")):
        tag = a[1] + b[1]
        out += _dot_code(unit, a, b, tag)
        out += [f"    wire [{d.out_bits - 1}:0] y_{tag};",
                f"    {d.module_name} poly_{tag} (.x(k_{tag}), .y(y_{tag}));"]
        terms.append(f"$signed({{1'b0, y_{tag}}})")
    out += [f"    localparam signed [{sw - 1}:0] THREE_MINUS_KY = {_lit((3 << fy) - 3 * ky, sw)};",
            f"    wire signed [{sw - 1}:0] e = THREE_MINUS_KY - {' - '.join(terms)};",
            f"    assign eta = e[{ew - 1}:0];",
            "    assign skip = eta < thr;",
            "endmodule", ""]
    return "\n".join(out) + ev


def _setup_shift(src: str, dst: str, bits: int, sh: int, dst_bits: int) -> list[str]:
    if sh > 0:
        return _round(src, dst, bits, sh, dst_bits, "rne")
    return [f"    wire signed [{dst_bits - 1}:0] {dst} = {src} <<< {-sh};"]


# -- test bench -----------------------------------------------------------------------

def _layout(unit: UnitDesign) -> tuple[list[tuple[Port, int, int]], int]:
    """Each port's ``[hi:lo]`` in a vector row, inputs first from the MSB."""
    total = sum(p.bits for p in unit.ports)
    pos, out = total, []
    for p in unit.ports:
        out.append((p, pos - 1, pos - p.bits))
        pos -= p.bits
    return out, total


def unit_vector_file(unit: UnitDesign, inputs: dict) -> str:
    """Rows ``{inputs, expected outputs}`` in hex (``$readmemh``)."""
    outs = unit.evaluate(inputs)
    layout, total = _layout(unit)
    vals = {**inputs, **outs}
    n = len(next(iter(inputs.values())))
    row = [0] * n
    for p, hi, lo in layout:
        v = np.asarray(vals[p.name], dtype=np.int64)
        vmin = -(1 << (p.bits - 1)) if p.signed else 0
        vmax = (1 << (p.bits - 1)) - 1 if p.signed else (1 << p.bits) - 1
        if v.min() < vmin or v.max() > vmax:
            raise ValueError(f"{unit.module_name}: {p.name} takes {int(v.min())}..{int(v.max())}, "
                             f"outside its {p.bits}-bit port (internal sizing error)")
        mask = (1 << p.bits) - 1
        for i, x in enumerate(v.tolist()):
            row[i] |= (x & mask) << lo
    digits = (total + 3) // 4
    return "".join(f"{r:0{digits}x}\n" for r in row)


def unit_testbench(unit: UnitDesign, count: int, vectors: str | None = None) -> str:
    """A self-checking test bench of ``count`` rows read from ``vectors``."""
    name = unit.module_name
    vectors = vectors or f"{name}.hex"
    layout, total = _layout(unit)
    ins = [(p, hi, lo) for p, hi, lo in layout if not p.output]
    outs = [(p, hi, lo) for p, hi, lo in layout if p.output]
    ohi, olo = outs[0][1], outs[-1][2]
    lines = [f"// tb_{name}: self-checking test bench of {name}.",
             f"// Rows {{inputs, expected outputs}} come from the chebnorm bit-accurate model "
             f"({vectors}).",
             "`timescale 1ns/1ps",
             f"module tb_{name};",
             f"    localparam COUNT = {count};",
             f"    reg [{total - 1}:0] vec [0:COUNT-1];",
             f"    reg [{total - 1}:0] row;"]
    if unit.clocked:
        lines.append("    reg clk;")
    for p, _, _ in ins:
        lines.append(f"    reg {'signed ' if p.signed and p.bits > 1 else ''}"
                     f"[{p.bits - 1}:0] {p.name};")
    for p, _, _ in outs:
        lines.append(f"    wire {'signed ' if p.signed and p.bits > 1 else ''}"
                     f"[{p.bits - 1}:0] {p.name};")
    conns = ([".clk(clk)"] if unit.clocked else []) + [f".{p.name}({p.name})" for p in unit.ports]
    got = "{" + ", ".join(p.name for p, _, _ in outs) + "}"
    lines += [f"    {name} dut ({', '.join(conns)});",
              "    integer i, errors;",
              "    initial begin",
              f"        $readmemh(\"{vectors}\", vec);",
              "        errors = 0;"]
    if unit.clocked:
        lines.append("        clk = 0;")
    lines.append("        for (i = 0; i < COUNT; i = i + 1) begin")
    lines.append("            row = vec[i];")
    for p, hi, lo in ins:
        lines.append(f"            {p.name} = row[{hi}:{lo}];")
    lines += (["            #1 clk = 1;", "            #1;"] if unit.clocked
              else ["            #1;"])
    lines += [f"            if ({got} !== row[{ohi}:{olo}]) begin",
              "                errors = errors + 1;",
              "                if (errors <= 10)",
              f"                    $display(\"MISMATCH row %0d: got %h expected %h\", i, {got}, "
              f"row[{ohi}:{olo}]);",
              "            end"]
    if unit.clocked:
        lines.append("            clk = 0;")
    lines += ["        end",
              "        if (errors == 0)",
              f"            $display(\"PASS: %0d vectors, 0 mismatches ({name})\", COUNT);",
              "        else",
              f"            $display(\"FAIL: %0d vectors, %0d mismatches ({name})\", COUNT, errors);",
              "        $finish;",
              "    end",
              "endmodule", ""]
    return "\n".join(lines)


def unit_outputs(unit: UnitDesign, *, count: int = 2000, seed: int = 0, version: str = "",
                 command: str | None = None) -> dict[str, str]:
    """File name -> text: the unit's Verilog, its test bench and its vectors."""
    rows = unit_vectors(unit, count, seed)
    n = len(next(iter(rows.values())))
    name = unit.module_name
    return {f"{name}.v": unit_verilog(unit, version=version, command=command),
            f"tb_{name}.v": unit_testbench(unit, n),
            f"{name}.hex": unit_vector_file(unit, rows)}


@dataclass(frozen=True)
class UnitReport:
    """A unit with its cost model and (when yosys ran) its cell count."""

    unit: UnitDesign
    block: Block
    synth: SynthResult | None

    def as_dict(self) -> dict:
        u = self.unit
        return {"unit": u.kind, "module": u.module_name, "frac_bits": u.frac_bits,
                "comp_bits": u.comp_bits,
                "evaluator": None if u.horner is None else u.horner.module_name,
                "ports": {p.name: {"bits": p.bits, "signed": p.signed,
                                   "dir": "output" if p.output else "input"} for p in u.ports},
                "area_fa": self.block.cost.area, "cost": self.block.as_dict(),
                "yosys_cells": None if self.synth is None else self.synth.cells,
                "notes": list(u.notes)}

    def lines(self) -> list[str]:
        u = self.unit
        cells = "yosys not run" if self.synth is None else f"{self.synth.cells} yosys cells"
        return [f"{u.module_name}: W = {u.comp_bits}, F = {u.frac_bits}: area ~"
                f"{self.block.cost.area:.0f} FA (model), {cells}"] + \
            ["  " + ln for ln in self.block.lines()]


def analyze_unit(unit: UnitDesign, *, synth: bool = True) -> UnitReport:
    """The unit's cost model and, with yosys installed and ``synth``, its cell count."""
    syn = None
    if synth and shutil.which("yosys") is not None:
        syn = synthesize_text(unit_verilog(unit), unit.module_name)
    return UnitReport(unit, unit.block, syn)
