"""The public entry points: size a unit of any registered kind, write its
files, report its cost."""

from __future__ import annotations

from dataclasses import dataclass

from chebnorm.approx import CoefficientTable
from chebnorm.core.display import field_rows, summary_html, summary_repr
from chebnorm.core.tools import which

from ..cost import Block
from ..fixed import check_width
from ..run_verilog import SynthResult, synthesize_text
from .base import MAX_COMP_BITS, MAX_UNIT_FRAC_BITS, UnitDesign, get_unit
from .bench import unit_testbench, unit_vector_file, unit_vectors

# an implementation module of chebnorm.hw.units: the API is what chebnorm.hw.units exports
__all__: list[str] = []


def design_unit(kind: str, *, frac_bits: int = 14, comp_bits: int | None = None,
                table: CoefficientTable | None = None, in_bits: int = 16,
                out_bits: int = 16, coef_bits: int | None = None, rounding: str | None = None,
                log_m: int = 4, guard: int | None = None) -> UnitDesign:
    """Size unit ``kind`` (a name of :func:`~chebnorm.hw.units.unit_names`) for
    ``F = frac_bits`` fractional bits and ``W = comp_bits`` (default ``F + 2``)
    bit components.

    ``table`` (with ``in_bits``, ``out_bits``, ``coef_bits``, ``rounding``)
    makes the polynomial evaluator of the dichotomy, quadratic and eta units;
    without it the unit's table as the method registry declares it
    (:func:`chebnorm.approx.method_registry.unit_tables`: degree 2, psi_max =
    pi/4) is fitted and quantized to ``out_bits + 4`` bits.
    ``rounding`` is the classic unit's quotient rounding (``"trunc"``, default,
    or ``"rne"``) or the evaluator's. ``log_m`` and ``guard`` (default
    ``2 log_m``, exact set-up) size the stepper. Raises ValueError naming the
    accepted range.

    >>> u = design_unit("stepper", frac_bits=6, log_m=2)
    >>> u.clocked, [p.name for p in u.outputs], u.sizes["v_bits"]
    (True, ['v_x', 'v_y', 'v_z'], 15)

    Parameters
    ----------
    kind : str
        A registered unit name: ``"classic"``, ``"dichotomy"``, ``"quadratic"``,
        ``"stepper"``, ``"eta"``.
    frac_bits : int, default 14
        ``F``, 1 to :data:`~chebnorm.hw.units.base.MAX_UNIT_FRAC_BITS` (26).
    comp_bits : int or None, default None
        ``W``, 2 to :data:`~chebnorm.hw.units.base.MAX_COMP_BITS` (28); None: ``F + 2``.
    table : CoefficientTable or None, default None
        The evaluator's table (dichotomy, quadratic, eta); it must approximate the unit's
        target function. None: fitted from the method registry.
    in_bits, out_bits : int, default 16
        The evaluator's input (1 to 20) and output (1 to 32) code widths.
    coef_bits : int or None, default None
        The evaluator's coefficient fractional bits; None: the table's own, or
        ``min(out_bits + 4, 30)`` for a fitted table.
    rounding : {"trunc", "rne"} or None, default None
        The classic unit's quotient rounding (None: ``"trunc"``) or the evaluator's
        (None: ``"rne"``).
    log_m : int, default 4
        The stepper's span ``m = 2**log_m`` pixels, 0 to
        :data:`~chebnorm.hw.units.base.MAX_LOG_M` (10).
    guard : int or None, default None
        The stepper's guard bits, 0 to :data:`~chebnorm.hw.units.base.MAX_GUARD` (24);
        None: ``2 * log_m``.

    Returns
    -------
    UnitDesign
        The sized unit.

    Raises
    ------
    ValueError
        If ``kind`` is unknown, a width is out of its range, the table does not fit the
        unit, or a register would exceed the 62-bit model.


    See Also
    --------
    analyze_unit : its cost model and, optionally, Yosys' cell count.
    unit_outputs : its Verilog module, test bench and vectors.
    chebnorm.hw.horner.design_horner : the polynomial evaluator inside the units that have one.

    Notes
    -----
    The units are the papers' normalization methods in hardware [1]_: the
    classic :math:`N / \\sqrt{N \\cdot N}`, the dichotomy midpoint
    :math:`(N_1 + N_2) / \\sqrt{2 + z}` with :math:`1/\\sqrt{2 + z}` by a
    Chebyshev polynomial, the quadratic span interpolator, its
    forward-difference stepper and the criterion :math:`\\eta`, each bit for
    bit equal to its kernel in :mod:`chebnorm.hw.datapaths`.

    References
    ----------
    .. [1] The four papers chebnorm reproduces (seeds 000 to 003), restated
       with their formulas re-derived in :doc:`/papers`.
    """
    spec = get_unit(kind)
    f = check_width(frac_bits, "frac_bits", 1, MAX_UNIT_FRAC_BITS)
    w = check_width(comp_bits if comp_bits is not None else f + 2, "comp_bits", 2, MAX_COMP_BITS)
    notes = []
    if w < f + 2:
        notes.append(f"comp-bits {w} < frac-bits + 2 = {f + 2}: +1.0 is not representable")
    return spec.design(f, w, notes, table=table, in_bits=in_bits, out_bits=out_bits,
                       coef_bits=coef_bits, rounding=rounding, log_m=log_m, guard=guard)


def unit_verilog(unit: UnitDesign, *, version: str = "", command: str | None = None) -> str:
    """The synthesizable Verilog-2005 text of ``unit`` at its generated widths:
    the unit module (its square root and dividers unrolled inside), then the
    polynomial evaluator it instantiates, if any (:meth:`UnitKind.vhdl
    <chebnorm.hw.units.UnitKind.vhdl>` prints the same netlist in VHDL).

    Parameters
    ----------
    unit : UnitDesign
        The sized unit (:func:`~chebnorm.hw.units.design_unit`).
    version : str, default ""
        chebnorm's version, stated in the banner (made comment-safe).
    command : str or None, default None
        The command line that made the file, stated in the banner (made comment-safe);
        None or empty: no such line.

    Returns
    -------
    str
        The Verilog-2005 text.

    Examples
    --------
    >>> v = unit_verilog(design_unit("dichotomy", frac_bits=6, in_bits=8, out_bits=8))
    >>> [line.split()[1] for line in v.splitlines() if line.startswith("module")]
    ['chebnorm_dichotomy_unit', 'chebnorm_dichotomy_d2']
    """
    return unit.spec.verilog(unit, version=version, command=command)


def unit_outputs(unit: UnitDesign, *, count: int = 2000, seed: int = 0, version: str = "",
                 command: str | None = None) -> dict[str, str]:
    """File name -> text: the unit's Verilog and VHDL (one netlist printed
    twice), a test bench in each language and the vectors both read.

    Parameters
    ----------
    unit : UnitDesign
        The sized unit (:func:`~chebnorm.hw.units.design_unit`).
    count : int, default 2000
        Realistic and random rows each, 1 to 10**6 (ignored when every input code is tested).
    seed : int, default 0
        The seed of the random rows (same seed, same files).
    version : str, default ""
        chebnorm's version, stated in the banner (made comment-safe).
    command : str or None, default None
        The command line that made the file, stated in the banner (made comment-safe);
        None or empty: no such line.

    Returns
    -------
    dict of str to str
        File name -> file text: ``NAME.v``, ``tb_NAME.v``, ``NAME.vhd``, ``tb_NAME.vhd``,
        ``NAME.hex``.

    Raises
    ------
    ValueError
        If ``count`` is out of range.

    Examples
    --------
    >>> sorted(unit_outputs(design_unit("classic", frac_bits=3, comp_bits=5)))  # doctest: +NORMALIZE_WHITESPACE
    ['chebnorm_classic_unit.hex', 'chebnorm_classic_unit.v', 'chebnorm_classic_unit.vhd',
     'tb_chebnorm_classic_unit.v', 'tb_chebnorm_classic_unit.vhd']
    """
    rows = unit_vectors(unit, count, seed)
    n = len(next(iter(rows.values())))
    name = unit.module_name
    return {f"{name}.v": unit_verilog(unit, version=version, command=command),
            f"tb_{name}.v": unit_testbench(unit, n),
            f"{name}.vhd": unit.spec.vhdl(unit, version=version, command=command),
            f"tb_{name}.vhd": unit_testbench(unit, n, language="vhdl"),
            f"{name}.hex": unit_vector_file(unit, rows)}


@dataclass(frozen=True)
class UnitReport:
    """A unit with its cost model and (when yosys ran) its cell count.

    Attributes
    ----------
    unit : UnitDesign
        The sized unit (:func:`~chebnorm.hw.units.design_unit`).
    block : Block
        The unit's datapath blocks with the cost estimate.
    synth : SynthResult or None
        Yosys's cell count; None when yosys did not run.

    Examples
    --------
    >>> r = analyze_unit(design_unit("classic", frac_bits=6), synth=False)
    >>> r.as_dict()["module"], r.synth is None, r.lines()[0]
    ('chebnorm_classic_unit', True, 'chebnorm_classic_unit: W = 8, F = 6: area ~845 FA (model), yosys not run')
    """

    unit: UnitDesign
    block: Block
    synth: SynthResult | None

    def _summary(self) -> list[tuple[str, object]]:
        return [("unit", self.unit.kind), ("module", self.unit.module_name),
                ("area_fa", self.block.cost.area),
                ("yosys_cells", None if self.synth is None else self.synth.cells)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

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
    """The unit's cost model and, with yosys installed and ``synth``, its cell count.

    Parameters
    ----------
    unit : UnitDesign
        The sized unit (:func:`~chebnorm.hw.units.design_unit`).
    synth : bool, default True
        Run yosys (when installed) for the cell count.

    Returns
    -------
    UnitReport
        The cost model and the cell count.

    Raises
    ------
    ValueError
        If yosys fails.

    Examples
    --------
    >>> r = analyze_unit(design_unit("stepper", frac_bits=6, log_m=2), synth=False)
    >>> len(r.block.cost.adders), len(r.block.cost.multipliers)
    (6, 0)
    """
    syn = None
    if synth and which("yosys") is not None:
        syn = synthesize_text(unit_verilog(unit), unit.module_name)
    return UnitReport(unit, unit.block, syn)
