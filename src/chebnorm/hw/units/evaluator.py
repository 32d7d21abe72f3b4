"""What the units with a polynomial evaluator share (dichotomy, quadratic,
eta): the table check and the evaluator's sizing, the realistic test rows,
the exact dot product to the evaluator's input code, the scaled sum
``(A + B) p`` (netlist statements) and the evaluator's netlist beside the unit's.

Their output offsets, widths and constants are sized, exactly, from the
extremes of every input code (see :mod:`chebnorm.hw.units`)."""

from __future__ import annotations

from abc import abstractmethod

from chebnorm.approx import CoefficientTable, fit_target
from chebnorm.core.textsafe import identifier

from ..fixed import check_int64, shift_round, signed_bits
from ..horner import HornerDesign, cover_frac_bits, design_horner
from ..hdl.datapath import horner_netlist, round_to
from ..hdl.netlist import (Add, Assign, Const, ConstDecl, Extend, Mul, Output, Shl, Signal, Sub,
                           ZeroExt)
from .base import UnitDesign, UnitKind, get_unit
from .bench import codes, combinational_rows, near
from .hdl import saturate, widen

# an implementation module of chebnorm.hw.units: the API is what chebnorm.hw.units exports
__all__: list[str] = []


def table_matches(kind: str, table: CoefficientTable) -> bool:
    """True when ``table`` approximates the function of unit ``kind``'s target
    (:data:`~chebnorm.hw.units.UNIT_TARGETS`), whatever its variable is called.

    Parameters
    ----------
    kind : str
        A registered unit name.
    table : CoefficientTable
        The candidate table.

    Returns
    -------
    bool
        True when the table's expression equals the target's (symbolically).

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> table_matches("dichotomy", fit("1/sqrt(2 + t)", ("sqrt(2)", "2"), 1, var="t"))
    True
    >>> table_matches("dichotomy", fit("1/sqrt(x)", ("1", "2"), 1))
    False
    """
    import sympy as sp

    from chebnorm.approx import get_target, parse_function

    target = get_target(get_unit(kind).target)
    want = parse_function(target.expression, target.variable)
    have = parse_function(table.expression, table.variable)
    return sp.simplify(have.expr.subs(have.var, want.var) - want.expr) == 0


def _unit_horner(kind: str, table, in_bits, out_bits, coef_bits, rounding) -> HornerDesign:
    spec = get_unit(kind).table_spec
    target_name = spec.target
    if table is None:
        table = fit_target(spec.target, spec.degree, psi_max=spec.psi_max)
        coef_bits = coef_bits if coef_bits is not None else min(out_bits + 4, 30)
    if not isinstance(table, CoefficientTable):
        raise ValueError(f"table {table!r} is not a CoefficientTable; accepted: a loaded table")
    if not table_matches(kind, table):
        from chebnorm.approx import get_target

        target = get_target(target_name)
        raise ValueError(f"table {table.name!r} approximates {table.expression}, but unit {kind!r} "
                         f"needs {target.expression} (target {target.name!r}); accepted: a table "
                         f"of that function")
    try:
        # the unit's input (a dot product, 2 cos(theta)) reaches the interval's top: the
        # covering mapping, whose codes include hi ("Input codes" in docs/hardware.md)
        d = design_horner(table, in_bits, out_bits, coef_bits=coef_bits, rounding=rounding,
                          name=table.name, x_frac_bits=cover_frac_bits(table, in_bits))
        identifier(d.name, field="table name")  # it names the evaluator module
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


def scaled_range(w: int, d: HornerDesign) -> tuple[int, int, int]:
    """Range of ``R((N1 + N2) (y + KY))`` over every code, and the width of ``y + KY``.

    Parameters
    ----------
    w : int
        Width of the vector components ``N1``, ``N2``.
    d : HornerDesign
        The evaluator whose output ``y`` scales the sum.

    Returns
    -------
    tuple of (int, int, int)
        The smallest and largest rounded product, and the signed width of ``y + KY``.

    Raises
    ------
    ValueError
        If the product exceeds the 62-bit model.

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("dichotomy", frac_bits=6, in_bits=8, out_bits=8)
    >>> scaled_range(u.comp_bits, u.horner)[2] == u.sizes["yv_bits"]
    True
    """
    ky, ymax, fy = d.y_format.offset_code, d.y_format.max_code, d.y_format.frac_bits
    yv = (ky, ky + ymax)
    s = (-(1 << w), (1 << w) - 2)
    prods = [a * b for a in s for b in yv]
    check_int64(signed_bits(min(prods), max(prods)), "the midpoint product (N1 + N2) * p")
    lo, hi = _rne_range(min(prods), max(prods), fy)
    return lo, hi, signed_bits(min(yv[0], 0), yv[1])


def dot_range(w: int) -> tuple[int, int]:
    """Range of the dot product of two 3-vectors of ``w``-bit codes.

    Parameters
    ----------
    w : int
        Width of each component, ``>= 1``.

    Returns
    -------
    tuple of (int, int)
        The smallest and largest dot product.

    Examples
    --------
    >>> dot_range(4)   # codes -8..7: 3 * (-8) * 7 .. 3 * (-8) * (-8)
    (-168, 192)
    """
    a, b = -(1 << (w - 1)), (1 << (w - 1)) - 1
    return 3 * a * b, 3 * a * a


def check_dot(w: int, f: int, d: HornerDesign) -> None:
    """Boundary check: the dot product, shifted to the evaluator's input, fits int64."""
    dlo, dhi = dot_range(w)
    check_int64(signed_bits(dlo, dhi) + max(0, d.x_format.frac_bits - 2 * f), "the dot product")


def dot_code(unit: UnitDesign, views: dict, a: str, b: str, tag: str) -> tuple[list, Signal]:
    """Statements: the exact dot product of vectors ``a``, ``b`` and its
    evaluator input code ``k_TAG`` (rounded to nearest-even, saturated).

    Parameters
    ----------
    unit : UnitDesign
        A unit with a polynomial evaluator (``unit.horner`` set).
    views : dict
        Port name -> its numeric signal (:func:`~chebnorm.hw.units.hdl.unit_module`).
    a, b : str
        The two vectors' port-name stems.
    tag : str
        Suffix of the declared signals (``dot_TAG``, ``k_TAG``, ...).

    Returns
    -------
    tuple of (list, Signal)
        Netlist statements, and the unsigned code ``k_TAG``.

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> from chebnorm.hw.units.hdl import unit_module
    >>> u = design_unit("eta", frac_bits=6, in_bits=8, out_bits=8)
    >>> st, k = dot_code(u, unit_module(u, [])[1], "na", "nb", "ab")
    >>> k.name, k.width, st[3].dst.name, st[3].dst.width
    ('k_ab', 8, 'dot_ab', 17)
    """
    d, f, w = unit.horner, unit.frac_bits, unit.comp_bits
    fx, k0, kmax = d.x_format.frac_bits, d.x_format.offset_code, 2 ** d.in_bits - 1
    dlo, dhi = dot_range(w)
    dw = signed_bits(dlo, dhi)
    st, prods = [], []
    for c in "xyz":
        prods.append(Signal(f"pr_{tag}_{c}", 2 * w, signed=True))
        st.append(Assign(prods[-1], Mul(views[f"{a}_{c}"], views[f"{b}_{c}"])))
    dot = Signal(f"dot_{tag}", dw, signed=True)
    st.append(Assign(dot, Add(tuple(Extend(p, dw) for p in prods))))
    sh = 2 * f - fx
    if sh > 0:
        rlo, rhi = _rne_range(dlo, dhi, sh)
        rw = signed_bits(rlo, rhi)
        st += round_to(dot, f"dr_{tag}", sh, rw, "rne")
    else:
        rlo, rhi = dlo << -sh, dhi << -sh
        rw = signed_bits(rlo, rhi)
        st.append(Assign(Signal(f"dr_{tag}", rw, signed=True),
                         Shl(Extend(dot, rw), -sh) if sh else Extend(dot, rw)))
    cw = signed_bits(min(rlo - k0, 0), max(rhi - k0, kmax)) + 1
    ww = max(cw, rw)
    dc = Signal(f"dc_{tag}", ww, signed=True)
    st.append(Assign(dc, Sub(Extend(Signal(f"dr_{tag}", rw, signed=True), ww), Const(k0, ww))))
    st += saturate(dc, kmax, d.in_bits, f"k_{tag}")
    return st, Signal(f"k_{tag}", d.in_bits)


def scale_lines(unit: UnitDesign, views: dict, a: str, b: str, out: str, ycode: Signal) -> list:
    """Statements: ``out_c = R((a_c + b_c) * (ycode + KY))`` for c in x, y, z
    (nearest-even), each driving the output port ``out_c``.

    Parameters
    ----------
    unit : UnitDesign
        A unit with a polynomial evaluator (``unit.horner`` set).
    views : dict
        Port name -> its numeric signal, or the output port
        (:func:`~chebnorm.hw.units.hdl.unit_module`).
    a, b : str
        The two vectors' port-name stems.
    out : str
        The output vector's stem.
    ycode : Signal
        The evaluator's output (a bit vector).

    Returns
    -------
    list
        Netlist statements.

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> from chebnorm.hw.units.hdl import unit_module
    >>> from chebnorm.hw.hdl.netlist import Signal
    >>> u = design_unit("dichotomy", frac_bits=6, in_bits=8, out_bits=8)
    >>> st = scale_lines(u, unit_module(u, [])[1], "n1", "n2", "m", Signal("y", 8, logic=True))
    >>> st[-1].port.name, st[-1].expr.name
    ('m_z', 'm_z_r')
    """
    d, w = unit.horner, unit.comp_bits
    yw, mw, fy = unit.sizes["yv_bits"], unit.sizes["m_bits"], d.y_format.frac_bits
    ky, yv = Signal("KY", yw, signed=True), Signal("yv", yw, signed=True)
    st = [ConstDecl(ky, unit.horner.y_format.offset_code)]
    st += widen(yv, Add((ZeroExt(ycode), ky)))
    for c in "xyz":
        sc, tc = Signal(f"s_{c}", w + 1, signed=True), Signal(f"t_{c}", w + 1 + yw, signed=True)
        st += [Assign(sc, Add((Extend(views[f"{a}_{c}"], w + 1), views[f"{b}_{c}"]))),
               Assign(tc, Mul(sc, yv))]
        st += round_to(tc, f"{out}_{c}_r", fy, mw, "rne")
        st.append(Output(Signal(f"{out}_{c}_r", mw, signed=True), port=views[f"{out}_{c}"]))
    return st


def _isfloat(s) -> bool:
    try:
        float(s)
        return True
    except (TypeError, ValueError):
        return False


class EvaluatorUnit(UnitKind):
    """A unit built around the evaluator of its table (:attr:`table_spec`, which
    the method registry declares);
    subclasses size it (:meth:`size`), add their realistic rows
    (:meth:`realistic_extra`) and build the unit's netlist (:meth:`unit_netlist`).

    Examples
    --------
    >>> from chebnorm.hw.units import get_unit
    >>> sorted(k for k in ("dichotomy", "classic", "quadratic", "stepper", "eta")
    ...        if isinstance(get_unit(k), EvaluatorUnit))
    ['dichotomy', 'eta', 'quadratic']
    """

    #: the two vector inputs of the realistic rows: unit normals at angles <= psi
    pair: tuple[str, str] = ("", "")

    def design(self, f, w, notes, *, table, in_bits, out_bits, coef_bits, rounding, log_m,
               guard) -> UnitDesign:
        d = _unit_horner(self.name, table, in_bits, out_bits, coef_bits, rounding or "rne")
        return self.size(f, w, notes, d)

    @abstractmethod
    def size(self, f: int, w: int, notes: list[str], d: HornerDesign) -> UnitDesign:
        """The design around the sized evaluator ``d``."""

    @abstractmethod
    def psi(self, lo: float) -> float:
        """Largest angle of the realistic rows for the table's lowest input ``lo``."""

    def realistic_extra(self, unit: UnitDesign, rng, a, b, psi: float, real: dict,
                        count: int) -> None:
        """Add the kind's other realistic inputs to ``real`` (default: none)."""

    def vector_rows(self, unit, rng, count) -> dict:
        f, w, d = unit.frac_bits, unit.comp_bits, unit.horner

        def realistic(rng, a):
            lo = float(d.table.interval[0]) if _isfloat(d.table.interval[0]) else \
                float(d.x_format.value(d.valid_codes[0]))
            psi = self.psi(lo)
            b = near(rng, a, psi)
            real = {}
            for i, c in enumerate("xyz"):
                real[f"{self.pair[0]}_{c}"] = codes(a[:, i], f, w)
                real[f"{self.pair[1]}_{c}"] = codes(b[:, i], f, w)
            self.realistic_extra(unit, rng, a, b, psi, real, count)
            return real
        return combinational_rows(unit, rng, count, realistic)

    @abstractmethod
    def unit_netlist(self, unit: UnitDesign, version: str, command: str | None):
        """The unit's netlist (banner included), which instantiates the evaluator."""

    def modules(self, unit, *, version, command) -> list:
        return [self.unit_netlist(unit, version, command), horner_netlist(unit.horner)]
