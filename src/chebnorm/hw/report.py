"""One call from a table to a checked design: budget, exhaustive
measurement, gappa, yosys, costs; and the files of its HDL outputs
(printed by :mod:`chebnorm.hw.hdl`).

The module is callable: ``chebnorm.hw.report(table, in_bits, out_bits, ...)``
is :func:`analyze` (what ``chebnorm hw report`` prints).

>>> from chebnorm.approx import fit_target
>>> import chebnorm.hw
>>> chebnorm.hw.report(fit_target("dichotomy", 1), 10, 10, coef_frac_bits=12, synth=False, gappa=False).checks["within_budget"]
True
>>> r = analyze(fit_target("dichotomy", 2), 12, 12, coef_frac_bits=16, synth=False, gappa=False)
>>> r.checks["within_budget"], r.checks["budget_within_2x"]
(True, True)
"""

from __future__ import annotations

import sys
import types
from dataclasses import dataclass
from pathlib import Path

from chebnorm.approx import CoefficientTable
from chebnorm.core.display import summary_html, summary_repr
from chebnorm.core.deprecation import renamed
from chebnorm.core.files import write_folder
from chebnorm.core.numeric import format_down, format_up

from .budget import ErrorBudget, Measurement, error_budget, measure
from .cost import Block
from .datapaths import horner_block
from .horner import HornerDesign, design_horner
from .hdl import hdl_files, module_text
from .run_verilog import SynthResult, synthesize_text
from ._docfrag import hw_doc

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []


@dataclass(frozen=True)
class HardwareReport:
    """A sized design with its certified budget, its exhaustive measurement,
    its cost block and (when yosys ran) its cell count.

    Attributes
    ----------
    design : HornerDesign
        The sized datapath.
    budget : ErrorBudget
        Its certified error budget.
    measurement : Measurement
        Its errors measured over every valid input code.
    block : Block
        Its datapath blocks with their cost estimate.
    synth : SynthResult or None
        Yosys's cell count of the generated Verilog; None when yosys did not run.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> r = analyze(fit_target("dichotomy", 1), 8, 8, coef_frac_bits=12, synth=False, gappa=False)
    >>> all(r.checks.values()), r.as_dict()["module"]
    (True, 'chebnorm_dichotomy_d1')
    """

    design: HornerDesign
    budget: ErrorBudget
    measurement: Measurement
    block: Block
    synth: SynthResult | None

    @property
    def checks(self) -> dict:
        """Each part of the budget checked on its own (all should be True).

        * ``within_budget``: measured ``max |y - f|`` <= ``total``;
        * ``budget_within_2x``: ``total <= 2 * measured``;
        * ``quantization_consistent``: the re-certified bounds of ``p`` and
          ``p_q`` agree within the certified ``sup |p_q - p|`` (triangle
          inequality, both ways), and the measured ``max |p_q - p|`` stays under it;
        * ``rounding_within_bound``: the exact enumerated ``max |y - p_q|``
          (and each step's own rounding) stays within its analytic bound,
          and within gappa's when gappa ran;
        * ``no_overflow``: no valid code saturates the output.
        """
        b, m, t = self.budget, self.measurement, self.design.table
        fp = t.fixed_point
        eps = 1e-15  # float64 evaluation of f in the measurement
        steps_ok = all(s <= float(st) for s, st in zip(
            m.step_rounding, [_local(st, self.design) for st in self.design.stages[:-1]]))
        return {
            "within_budget": m.total <= b.total + eps,
            "budget_within_2x": b.total <= 2 * m.total,
            "quantization_consistent": (fp.max_abs_error <= t.abs_error_bound + b.quantization
                                        and t.max_abs_error <= fp.abs_error_bound + b.quantization
                                        and m.quantization <= b.quantization + eps),
            "rounding_within_bound": (m.rounding <= b.rounding and steps_ok
                                      and (b.gappa_rounding is None
                                           or m.rounding <= b.gappa_rounding)),
            "no_overflow": m.overflows == 0,
        }

    def _summary(self) -> list[tuple[str, object]]:
        d = self.design
        return [("module", d.module_name), ("degree", d.degree), ("in_bits", d.in_bits),
                ("out_bits", d.out_bits), ("total_error_bound", self.budget.total),
                ("measured_max_error", self.measurement.total),
                ("checks_pass", all(self.checks.values()))]

    def _display_rows(self) -> list[tuple[str, object]]:
        return [(f"line {i + 1}", line) for i, line in enumerate(self.lines())]

    __repr__ = summary_repr
    _repr_html_ = summary_html

    def as_dict(self) -> dict:
        d, b = self.design, self.budget
        return {
            "module": d.module_name, "table": d.table.name, "expression": d.table.expression,
            "interval": list(d.table.interval), "degree": d.degree,
            "in_bits": d.in_bits, "out_bits": d.out_bits, "rounding": d.rounding,
            "x_format": {"frac_bits": d.x_format.frac_bits, "offset": float(d.x_format.offset),
                         "offset_code": d.x_format.offset_code, "q": d.x_format.q_name()},
            "y_format": {"frac_bits": d.y_format.frac_bits, "offset": float(d.y_format.offset),
                         "offset_code": d.y_format.offset_code, "q": d.y_format.q_name()},
            "coef_frac_bits": d.coef_frac_bits, "coefficients_q": list(d.integers),
            "acc_frac_bits": d.acc_frac_bits, "valid_codes": list(d.valid_codes),
            "scheme": d.scheme, "multipliers": d.multipliers,
            "total_error_bound": b.total, "budget": b.as_dict(),
            "measured": self.measurement.as_dict(), "checks": self.checks,
            "cost": self.block.as_dict(),
            "yosys_cells": None if self.synth is None else self.synth.cells,
            "notes": list(d.notes),
        }

    def lines(self) -> list[str]:
        d, b, m = self.design, self.budget, self.measurement
        xf, yf = d.x_format, d.y_format
        out = [f"{d.module_name}: degree {d.degree}, x {d.in_bits} bits, y {d.out_bits} bits, "
               f"coefficients {d.coef_frac_bits} fractional bits, rounding {d.rounding}",
               f"x_format: code k -> {float(xf.offset)!r} + k / 2^{xf.frac_bits}; valid codes "
               f"{d.valid_codes[0]}..{d.valid_codes[1]}",
               f"y_format: code k -> {float(yf.offset)!r} + k / 2^{yf.frac_bits} "
               f"(1 LSB = {b.y_lsb:.6e})",
               "error budget (bound | measured over every valid code):",
               f"  approximation   {format_up(b.approximation, '.6e')} | "
               f"{format_down(m.approximation, '.6e')}",
               f"  quantization    {format_up(b.quantization, '.6e')} | "
               f"{format_down(m.quantization, '.6e')}  "
               f"(p_q re-certified {format_up(b.quantized, '.6e')})"]
        for st, (bound, meas) in zip(d.stages[:-1], zip(b.rounding_steps, m.step_rounding)):
            out.append(f"  rounding a{st.power}     {format_up(bound, '.6e')} (local "
                       f"{format_up(_local(st, d), '.6e')}) "
                       f"| local {format_down(meas, '.6e')}")
        if d.scheme == "shifted":
            out.append(f"  shift rounding  {format_up(b.variable_rounding, '.6e')} (v = (x - c')/s "
                       f"with {d.variable_frac_bits} fractional bits)")
        elif d.scheme != "monomial":
            out.append(f"  square rounding {format_up(b.variable_rounding, '.6e')} (v = x*x with "
                       f"{d.variable_frac_bits} fractional bits; {d.scheme} powers, "
                       f"{d.multipliers} multipliers)")
        out += [f"  output rounding {format_up(b.output_rounding, '.6e')}",
                f"  rounding total  {format_up(b.rounding, '.6e')} | "
                f"{format_down(m.rounding, '.6e')}"
                + ("" if b.gappa_rounding is None
                   else f"  (gappa {format_up(b.gappa_rounding, '.6e')})"),
                f"  total           {format_up(b.total, '.6e')} | {format_down(m.total, '.6e')}  "
                f"({format_up(b.total / b.y_lsb, '.3f')} | {format_down(m.total_lsb, '.3f')} LSB; "
                f"ratio {b.total / m.total:.3f})",
                f"  shading error   {format_down(m.shading_levels, '.4f')} levels of 8-bit output"
                if m.shading_levels is not None else
                "  shading error   - (f is zero at a valid code: no relative error)",
                "checks: " + ", ".join(f"{k}={v}" for k, v in self.checks.items())]
        out += self.block.lines(depth=True)
        if self.synth is not None:
            out.append(f"yosys: {self.synth.cells} cells")
        out += [f"note: {n}" for n in d.notes]
        return out


def _local(stage, design) -> float:
    from .fixed import rounding_error_bound
    return float(rounding_error_bound(stage.out_frac_bits, design.rounding, stage.round_shift))


def analyze(table: CoefficientTable, in_bits: int, out_bits: int, *, coef_frac_bits=None,
            acc_bits=None, rounding: str = "rne", x_frac_bits=None, y_frac_bits=None,
            gappa: bool = True, synth: bool = True, coef_bits=None) -> HardwareReport:
    """Design, budget, measure (exhaustively) and optionally synthesize.

    Parameters
    ----------
    table : CoefficientTable
        A fitted monomial table.
    in_bits, out_bits : int
        Input (1 to 20) and output (1 to 32) code widths.
    coef_frac_bits : int or None, default None
        Coefficient fractional bits (1 to :func:`~chebnorm.hw.horner.max_coef_bits`);
        None keeps the table's fixed-point part.
    acc_bits : int or None, default None
        Accumulator fractional bits, 1 to 60; None: ``y_frac_bits + 3``.
    rounding : {"rne", "trunc"}, default "rne"
        Rounding of every datapath step.
    x_frac_bits, y_frac_bits : int or None, default None
        Fractional bits of the input and output formats. ``x_frac_bits`` None: the
        input code ``k`` stands for ``lo + (hi - lo) k / 2**in_bits`` on ``[lo, hi)``,
        every code valid, as in ``chebnorm design``, when ``hi - lo`` is a power of
        two and ``lo`` a multiple of the step; else the largest format covering
        ``[lo, hi]`` (the report names the valid codes). Any other ``x_frac_bits``
        asks for the covering mapping with it ("Input codes" in docs/hardware.md;
        :func:`~chebnorm.hw.horner.design_horner`). ``y_frac_bits`` None: the
        largest for which ``out_bits`` holds the output range.
    gappa : bool, default True
        Cross-check the rounding bound with gappa when it is installed.
    synth : bool, default True
        Synthesize the Verilog with yosys (when installed) for the cell count.
    coef_bits : int or None, default None
        The deprecated spelling of ``coef_frac_bits``.

    Returns
    -------
    HardwareReport
        The design with its budget, measurement, cost and cell count.

    Raises
    ------
    ValueError
        If ``table`` fails its re-verification (a field changed since it was made), an
        argument is out of range (:func:`~chebnorm.hw.horner.design_horner`), or gappa
        or yosys fails.

    See Also
    --------
    chebnorm.hw.horner.design_horner : the datapath alone.
    chebnorm.hw.budget.error_budget : the certified budget alone.
    chebnorm.hw.piecewise.design_piecewise : the piecewise (ROM + Horner) design.

    Notes
    -----
    ``checks`` holds when the exhaustive measurement stays within the
    certified budget,

    .. math::

        \\max_{k \\text{ valid}} |y_k - f(x_k)| \\le
        \\min(\\varepsilon_{a} + \\varepsilon_{q},\\ \\varepsilon_{pq})
        + \\sum_{j=1}^{n-1} \\rho_j \\max_k |x_k|^j + \\rho_{\\mathrm{out}}

    (:func:`~chebnorm.hw.budget.error_budget`), and within Gappa's bound of
    the rounding part when gappa ran [1]_; ``block`` is the cost model of
    :mod:`chebnorm.hw.cost`, ``synth`` Yosys' cell count.

    References
    ----------
    .. [1] G. Melquiond, Gappa, https://gappa.gitlabpages.inria.fr/ ;
       F. de Dinechin, C. Lauter, G. Melquiond, "Certifying the
       floating-point implementation of an elementary function using
       Gappa", IEEE Transactions on Computers 60(2), 2011.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> r = analyze(fit_target("dichotomy", 2), 10, 10, coef_frac_bits=14, synth=False, gappa=False)
    >>> r.measurement.total <= r.budget.total, r.synth is None
    (True, True)
    """
    coef_bits = renamed(coef_bits, coef_frac_bits, "coef_bits", "coef_frac_bits", "analyze")
    if isinstance(table, CoefficientTable):
        table.verify()  # a comparison, or a re-proof of fields changed since construction
    design = design_horner(table, in_bits, out_bits, coef_bits=coef_bits, acc_bits=acc_bits,
                           rounding=rounding, x_frac_bits=x_frac_bits, y_frac_bits=y_frac_bits)
    from chebnorm.core.tools import which
    budget = error_budget(design, gappa=gappa and which("gappa") is not None)
    meas = measure(design)
    syn = None
    if synth and which("yosys") is not None:
        syn = synthesize_text(module_text(design), design.module_name)
    return HardwareReport(design, budget, meas, horner_block(design), syn)


@hw_doc
def hdl_outputs(report: HardwareReport, language: str = "verilog", *, version: str = "",
                command: str | None = None, pipelined: bool = False) -> dict[str, str]:
    """File name -> text of the module, its test bench and its vector file in
    ``language`` (``"verilog"``: ``NAME.v``; ``"vhdl"``: ``NAME.vhd``); with
    ``pipelined`` also those of the pipelined variant ``chebnorm_NAME_pipe``.
    Both languages' benches read the same vector file ``NAME.hex``
    (:func:`chebnorm.hw.hdl.hdl_files` of the report's design and budget).

    >>> from chebnorm.approx import fit_target
    >>> r = analyze(fit_target("dichotomy", 1), 8, 8, coef_frac_bits=12, synth=False, gappa=False)
    >>> sorted(hdl_outputs(r, "vhdl", pipelined=True))  # doctest: +NORMALIZE_WHITESPACE
    ['chebnorm_dichotomy_d1.hex', 'chebnorm_dichotomy_d1.vhd', 'chebnorm_dichotomy_d1_pipe.hex',
     'chebnorm_dichotomy_d1_pipe.vhd', 'tb_chebnorm_dichotomy_d1.vhd',
     'tb_chebnorm_dichotomy_d1_pipe.vhd']
    >>> hdl_outputs(r, "vhdl")["chebnorm_dichotomy_d1.hex"] == hdl_outputs(r)["chebnorm_dichotomy_d1.hex"]
    True

    Parameters
    ----------
    report : HardwareReport
        The analysed design; its budget goes into the banner.
    %(language)s
    %(version)s
    %(files_command)s
    pipelined : bool, default False
        Also write the pipelined variant.

    Returns
    -------
    dict of str to str
        File name -> file text.

    Raises
    ------
    ValueError
        If ``language`` is not ``"verilog"`` or ``"vhdl"``.
    """
    return hdl_files(report.design, language, version=version, command=command,
                     budget=report.budget, pipelined=pipelined)


@hw_doc
def verilog_outputs(report: HardwareReport, *, version: str = "", command: str | None = None,
                    pipelined: bool = False) -> dict[str, str]:
    """File name -> text of the module, its test bench and its vector file; with
    ``pipelined`` also those of the pipelined variant ``chebnorm_NAME_pipe``
    (:func:`hdl_outputs` in Verilog).

    >>> from chebnorm.approx import fit_target
    >>> r = analyze(fit_target("dichotomy", 1), 8, 8, coef_frac_bits=12, synth=False, gappa=False)
    >>> sorted(verilog_outputs(r))
    ['chebnorm_dichotomy_d1.hex', 'chebnorm_dichotomy_d1.v', 'tb_chebnorm_dichotomy_d1.v']

    Parameters
    ----------
    report : HardwareReport
        The analysed design; its budget goes into the banner.
    %(version)s
    %(files_command)s
    pipelined : bool, default False
        Also write the pipelined variant.

    Returns
    -------
    dict of str to str
        File name -> file text.
    """
    return hdl_outputs(report, "verilog", version=version, command=command, pipelined=pipelined)


def write_outputs(directory, files: dict[str, str]) -> list[Path]:
    """Write every file into ``directory`` (created if missing), all or none
    (:func:`chebnorm.core.files.write_folder`): nothing is half-written.

    Parameters
    ----------
    directory : str or os.PathLike
        The folder to write into (created with its parents if missing).
    files : dict of str to str
        File name (a plain name, no folder) -> text.

    Returns
    -------
    list of pathlib.Path
        The paths written, in the order of ``files``.

    Raises
    ------
    chebnorm.core.files.WriteError
        If a file cannot be written (a ``ValueError`` and an ``OSError``; nothing is
        left behind).

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> import tempfile
    >>> r = analyze(fit_target("dichotomy", 1), 8, 8, coef_frac_bits=12, synth=False, gappa=False)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print([p.name for p in write_outputs(tmp, verilog_outputs(r))])
    ['chebnorm_dichotomy_d1.v', 'tb_chebnorm_dichotomy_d1.v', 'chebnorm_dichotomy_d1.hex']
    """
    return write_folder(directory, files)


class _CallableModule(types.ModuleType):
    """``chebnorm.hw.report`` is callable: ``chebnorm.hw.report(table, 12, 12)``."""

    def __call__(self, table: CoefficientTable, in_bits: int, out_bits: int, **options) -> HardwareReport:
        return analyze(table, in_bits, out_bits, **options)


sys.modules[__name__].__class__ = _CallableModule
