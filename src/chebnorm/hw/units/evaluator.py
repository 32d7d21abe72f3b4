"""What the units with a polynomial evaluator share (dichotomy, quadratic,
eta): the table check and the evaluator's sizing, the realistic test rows,
the exact dot product to the evaluator's input code, the scaled sum
``(A + B) p`` and the evaluator module appended to the unit's text.

Their output offsets, widths and constants are sized, exactly, from the
extremes of every input code (see :mod:`chebnorm.hw.units`)."""

from __future__ import annotations

from abc import abstractmethod

from chebnorm.approx import CoefficientTable, fit_target
from chebnorm.core.textsafe import identifier

from ..fixed import check_int64, shift_round, signed_bits
from ..horner import HornerDesign, cover_frac_bits, design_horner
from ..hdl.netlist import signed_literal
from ..hdl.verilog import round_lines
from ..hdl.verilog import verilog_module
from .base import UnitDesign, UnitKind, get_unit
from .bench import codes, combinational_rows, near

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


def dot_code(unit: UnitDesign, a: str, b: str, tag: str) -> list[str]:
    """Lines: the exact dot product of vectors ``a``, ``b`` and its input code ``k_tag``.

    Parameters
    ----------
    unit : UnitDesign
        A unit with a polynomial evaluator (``unit.horner`` set).
    a, b : str
        The two vectors' port-name stems.
    tag : str
        Suffix of the declared wires (``dot_TAG``, ``k_TAG``).

    Returns
    -------
    list of str
        Verilog lines: the dot product, its rounding to the evaluator's input
        fractional bits, and the saturated input code ``k_TAG``.

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("eta", frac_bits=6, in_bits=8, out_bits=8)
    >>> dot_code(u, "na", "nb", "ab")[0]
    '    wire signed [16:0] dot_ab = na_x * nb_x + na_y * nb_y + na_z * nb_z;'
    """
    d, f, w = unit.horner, unit.frac_bits, unit.comp_bits
    fx, k0, kmax = d.x_format.frac_bits, d.x_format.offset_code, 2 ** d.in_bits - 1
    dlo, dhi = dot_range(w)
    dw = signed_bits(dlo, dhi)
    lines = [f"    wire signed [{dw - 1}:0] dot_{tag} = {a}_x * {b}_x + {a}_y * {b}_y + "
             f"{a}_z * {b}_z;"]
    sh = 2 * f - fx
    if sh > 0:
        rlo, rhi = _rne_range(dlo, dhi, sh)
        rw = signed_bits(rlo, rhi)
        lines += round_lines(f"dot_{tag}", f"dr_{tag}", dw, sh, rw, "rne")
    else:
        rlo, rhi = dlo << -sh, dhi << -sh
        rw = signed_bits(rlo, rhi)
        lines.append(f"    wire signed [{rw - 1}:0] dr_{tag} = dot_{tag} <<< {-sh};")
    cw = signed_bits(min(rlo - k0, 0), max(rhi - k0, kmax)) + 1
    lines += [f"    wire signed [{cw - 1}:0] dc_{tag} = dr_{tag} - {signed_literal(k0, cw)};",
              f"    wire [{d.in_bits - 1}:0] k_{tag} = dc_{tag}[{cw - 1}] ? {d.in_bits}'d0 : "
              f"(dc_{tag} > {signed_literal(kmax, cw)}) ? {d.in_bits}'d{kmax} : dc_{tag}[{d.in_bits - 1}:0];"]
    return lines


def scale_lines(unit: UnitDesign, a: str, b: str, out: str, ycode: str) -> list[str]:
    """Lines: ``out_c = R((a_c + b_c) * (ycode + KY))`` for c in x, y, z.

    Parameters
    ----------
    unit : UnitDesign
        A unit with a polynomial evaluator (``unit.horner`` set).
    a, b : str
        The two vectors' port-name stems.
    out : str
        The output vector's stem.
    ycode : str
        The evaluator's output wire.

    Returns
    -------
    list of str
        Verilog lines, rounding to nearest-even.

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("dichotomy", frac_bits=6, in_bits=8, out_bits=8)
    >>> scale_lines(u, "n1", "n2", "m", "y")[-1]
    '    assign m_z = m_z_r;'
    """
    d, w = unit.horner, unit.comp_bits
    yw, mw, fy = unit.sizes["yv_bits"], unit.sizes["m_bits"], d.y_format.frac_bits
    lines = [f"    wire signed [{yw - 1}:0] yv = $signed({{1'b0, {ycode}}}) + KY;"]
    for c in "xyz":
        lines += [f"    wire signed [W:0] s_{c} = {a}_{c} + {b}_{c};",
                  f"    wire signed [W+{yw}:0] t_{c} = s_{c} * yv;"]
        lines += round_lines(f"t_{c}", f"{out}_{c}_r", w + 1 + yw, fy, mw, "rne")
        lines.append(f"    assign {out}_{c} = {out}_{c}_r;")
    return lines


def ky_localparam(unit: UnitDesign) -> str:
    """Line: the evaluator's output offset ``KY`` as a signed constant."""
    yw = unit.sizes["yv_bits"]
    return (f"    localparam signed [{yw - 1}:0] KY = "
            f"{signed_literal(unit.horner.y_format.offset_code, yw)};")


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
    (:meth:`realistic_extra`) and write the unit module (:meth:`module_lines`).

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
    def module_lines(self, unit: UnitDesign, version: str, command: str | None) -> list[str]:
        """The unit module (banner included) and its helpers, before the evaluator."""

    def verilog(self, unit, *, version, command) -> str:
        ev = verilog_module(unit.horner, version=version)
        return "\n".join(self.module_lines(unit, version, command)) + ev
