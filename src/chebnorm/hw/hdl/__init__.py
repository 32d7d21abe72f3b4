"""HDL text of a design, in each language: the one place that prints hardware.

A *design* is a sized, bit-accurate evaluator of a table:

* a :class:`~chebnorm.hw.horner.HornerDesign` (``design_horner``: one Horner
  evaluator of a :class:`~chebnorm.approx.CoefficientTable`), combinational
  or pipelined;
* a :class:`~chebnorm.hw.piecewise.PiecewiseDesign` (``design_piecewise``:
  coefficient ROM + one Horner datapath of a uniform
  :class:`~chebnorm.approx.PiecewiseTable`), combinational, or -- the sized
  architecture with ``pipeline=`` -- with registers at its cut points (the
  module then has ``clk`` and ``LATENCY``; its bench is clocked).

Each is built once as a netlist (:mod:`.datapath` over the IR of
:mod:`.netlist`) and printed in Verilog-2005 (:mod:`.verilog`) or VHDL-2008
(:mod:`.vhdl`), bit for bit the design's model, with an exhaustive self-checking bench that
reads the model's expected outputs (:func:`vector_file`). The banner is
written once (:mod:`.common`). ``chebnorm hw verilog``, ``chebnorm export
--format verilog|vhdl`` and :func:`chebnorm.hw.report.hdl_outputs` all call
:func:`module_text` / :func:`hdl_text` / :func:`hdl_files`; the simulators
are run by :mod:`chebnorm.hw.run_verilog` (Icarus Verilog, Yosys) and
:mod:`chebnorm.hw.run_vhdl` (GHDL).

>>> from chebnorm.approx import fit_target
>>> from chebnorm.hw.horner import design_horner
>>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
>>> sorted(hdl_files(d, "vhdl"))
['chebnorm_dichotomy_d1.hex', 'chebnorm_dichotomy_d1.vhd', 'tb_chebnorm_dichotomy_d1.vhd']
"""

from __future__ import annotations


from ..design_base import Design
from ..horner import HornerDesign
from ..trust import verify_design
from .common import (LANGUAGES, SUFFIX, check_language, comment_lines, horner_facts,
                     module_name, piecewise_facts, pipelined_name, vector_file)
from .verilog import (piecewise_clocked_testbench, piecewise_verilog, verilog_module,
                      verilog_pipelined_module, verilog_pipelined_testbench, verilog_testbench)
from .vhdl import (piecewise_vhdl, piecewise_vhdl_clocked_testbench, piecewise_vhdl_testbench,
                   vhdl_module, vhdl_pipelined_module, vhdl_pipelined_testbench, vhdl_testbench)
from .._docfrag import hw_doc

__all__ = ["LANGUAGES", "SUFFIX", "check_language", "is_piecewise", "module_text",
           "testbench_text", "hdl_text", "hdl_files", "banner_facts", "comment_lines",
           "module_name", "pipelined_name", "vector_file"]

#: (language, piecewise, pipelined) -> (module printer, bench printer)
_PRINTERS = {
    ("verilog", False, False): (verilog_module, verilog_testbench),
    ("verilog", False, True): (verilog_pipelined_module, verilog_pipelined_testbench),
    ("verilog", True, False): (piecewise_verilog, verilog_testbench),
    ("vhdl", False, False): (vhdl_module, vhdl_testbench),
    ("vhdl", False, True): (vhdl_pipelined_module, vhdl_pipelined_testbench),
    ("vhdl", True, False): (piecewise_vhdl, piecewise_vhdl_testbench),
}


def is_piecewise(design) -> bool:
    """True for a design of a piecewise table, False for a Horner design;
    ValueError for anything else.

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> is_piecewise(design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10))
    False

    Parameters
    ----------
    design : object
        The object to classify.

    Returns
    -------
    bool
        True for a piecewise design, False for a Horner design.

    Raises
    ------
    ValueError
        If ``design`` is neither.
    """
    if isinstance(design, HornerDesign):
        return False
    if isinstance(design, Design) and design.architecture in ("piecewise", "piecewise-sized"):
        return True
    raise ValueError(f"design: a {type(design).__name__} is not a design; accepted: a "
                     f"HornerDesign (design_horner) or a PiecewiseDesign (design_piecewise)")


def _printers(design, language: str, pipelined: bool):
    piecewise = is_piecewise(design)
    verify_design(design)   # changed since it was proved: proved again (or refused)
    check_language(language)
    if pipelined and piecewise:
        raise ValueError("pipelined: not available for a piecewise design; accepted: "
                         "pipelined=False (a piecewise design is pipelined by "
                         "design_piecewise(..., pipeline=...): its module is clocked)")
    if pipelined and design.degree < 1:
        raise ValueError(f"design {design.name!r} has degree 0: nothing to pipeline; accepted: "
                         f"degree >= 1")
    return _PRINTERS[language, piecewise, bool(pipelined)]


@hw_doc
def banner_facts(design, language: str = "verilog", *, version: str = "",
                 command: str | None = None, budget=None, pipelined: bool = False) -> list[str]:
    """The banner of ``design``'s module as text lines without comment marker
    (:func:`~chebnorm.hw.hdl.common.horner_facts` or
    :func:`~chebnorm.hw.hdl.common.piecewise_facts`); ``module_text`` starts
    with ``comment_lines(banner_facts(...), language)``.

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> text = module_text(d, "vhdl", version="1.0")
    >>> text.startswith("\\n".join(comment_lines(banner_facts(d, "vhdl", version="1.0"), "vhdl")))
    True

    Parameters
    ----------
    %(hdl_design)s
    %(language)s
    %(version)s
    %(command)s
    %(budget)s
    %(pipelined)s

    Returns
    -------
    list of str
        The banner lines, without comment marker (``""``: an empty comment line).

    Raises
    ------
    ValueError
        If ``design`` is not a Horner or piecewise design, ``language`` is unknown, or
        ``pipelined`` is asked for a piecewise or a degree-0 design.
    """
    _printers(design, language, pipelined)
    if is_piecewise(design):
        return piecewise_facts(design, version=version, command=command)
    return horner_facts(design, language, version=version, command=command, budget=budget,
                        pipelined=pipelined)


@hw_doc
def module_text(design, language: str = "verilog", *, pipelined: bool = False,
                version: str = "", command: str | None = None, budget=None) -> str:
    """The module (entity) of ``design`` in ``language``: ``"verilog"`` or
    ``"vhdl"``; with ``pipelined`` the pipelined variant ``chebnorm_NAME_pipe``
    (a Horner design of degree >= 1 only). ``budget``: a Horner design's
    :class:`~chebnorm.hw.budget.ErrorBudget` for the banner (a piecewise
    design states its own).

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> module_text(d) == verilog_module(d), module_text(d, "vhdl", pipelined=True) == vhdl_pipelined_module(d)
    (True, True)

    Parameters
    ----------
    %(hdl_design)s
    %(language)s
    %(pipelined)s
    %(version)s
    %(command)s
    %(budget)s

    Returns
    -------
    str
        The module (Verilog) or entity and architecture (VHDL) text, banner first.

    Raises
    ------
    ValueError
        If ``design`` is not a Horner or piecewise design, ``language`` is unknown, or
        ``pipelined`` is asked for a piecewise or a degree-0 design.
    """
    module, _ = _printers(design, language, pipelined)
    if is_piecewise(design):
        return module(design, version=version, command=command)
    return module(design, version=version, command=command, budget=budget)


@hw_doc
def testbench_text(design, language: str = "verilog", *, pipelined: bool = False,
                   vectors: str | None = None) -> str:
    """The exhaustive self-checking bench of :func:`module_text`'s module; it
    reads the expected outputs from ``vectors`` (default ``NAME.hex``, the
    text of :func:`vector_file`).

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> testbench_text(d, "vhdl").splitlines()[0]
    '-- tb_chebnorm_dichotomy_d1: exhaustive self-checking test bench of chebnorm_dichotomy_d1.'

    Parameters
    ----------
    %(hdl_design)s
    %(language)s
    %(pipelined)s
    %(vectors)s

    Returns
    -------
    str
        The bench: every input code applied, each output compared with the vector file.

    Raises
    ------
    ValueError
        If ``design`` is not a Horner or piecewise design, ``language`` is unknown, or
        ``pipelined`` is asked for a piecewise or a degree-0 design.
    ValueError
        If ``vectors`` is not an identifier (plus ``.hex``).
    """
    _, bench = _printers(design, language, pipelined)
    if is_piecewise(design) and design.latency > 0:
        bench = {"verilog": piecewise_clocked_testbench,
                 "vhdl": piecewise_vhdl_clocked_testbench}[language]
    return bench(design, vectors)


@hw_doc
def hdl_text(design, language: str = "verilog", *, version: str = "", command: str | None = None,
             budget=None) -> str:
    """The text ``chebnorm export --format verilog|vhdl`` writes: the
    combinational module and, for a Horner design of degree >= 1, the
    pipelined one after it (one file, both compile together).

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> hdl_text(d) == verilog_module(d) + "\\n" + verilog_pipelined_module(d)
    True

    Parameters
    ----------
    %(hdl_design)s
    %(language)s
    %(version)s
    %(command)s
    %(budget)s

    Returns
    -------
    str
        The combinational module, then (Horner, degree >= 1) the pipelined one.

    Raises
    ------
    ValueError
        If ``design`` is not a Horner or piecewise design, or ``language`` is unknown.
    """
    kw = dict(version=version, command=command, budget=budget)
    text = module_text(design, language, **kw)
    if not is_piecewise(design) and design.degree >= 1:
        text += "\n" + module_text(design, language, pipelined=True, **kw)
    return text


@hw_doc
def hdl_files(design, language: str = "verilog", *, version: str = "",
              command: str | None = None, budget=None, pipelined: bool = False) -> dict[str, str]:
    """File name -> text of the module, its test bench and its vector file in
    ``language`` (``NAME.v`` or ``NAME.vhd``, ``tb_NAME.v|.vhd``, ``NAME.hex``);
    with ``pipelined`` also those of ``chebnorm_NAME_pipe``. Both languages'
    benches read the same vector file.

    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> list(hdl_files(design_piecewise(t, 8, 8), "vhdl"))
    ['chebnorm_rs.vhd', 'tb_chebnorm_rs.vhd', 'chebnorm_rs.hex']

    Parameters
    ----------
    %(hdl_design)s
    %(language)s
    %(version)s
    %(command)s
    %(budget)s
    %(pipelined)s

    Returns
    -------
    dict of str to str
        File name -> file text.

    Raises
    ------
    ValueError
        If ``design`` is not a Horner or piecewise design, ``language`` is unknown, or
        ``pipelined`` is asked for a piecewise or a degree-0 design.
    """
    kw = dict(version=version, command=command, budget=budget)
    ext = SUFFIX[check_language(language)]
    _printers(design, language, pipelined)  # refuse before printing anything
    name = module_name(design)
    files = {f"{name}{ext}": module_text(design, language, **kw),
             f"tb_{name}{ext}": testbench_text(design, language),
             f"{name}.hex": vector_file(design)}
    if pipelined:
        pipe = pipelined_name(design)
        files[f"{pipe}{ext}"] = module_text(design, language, pipelined=True, **kw)
        files[f"tb_{pipe}{ext}"] = testbench_text(design, language, pipelined=True)
        files[f"{pipe}.hex"] = files[f"{name}.hex"]
    return files
