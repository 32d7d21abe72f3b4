"""The parameter blocks that many docstrings of :mod:`chebnorm.hw` share, written
once (:func:`chebnorm.core.docfrag.docstring`): a docstring holds ``%(name)s`` alone
on a line where the block goes, and its function or class is decorated with
:data:`hw_doc`."""

from __future__ import annotations

from ..core.docfrag import docstring

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: placeholder name -> parameter block (``name : type`` line, description indented by four)
HW_FRAGMENTS = {
    "version": '''\
version : str, default ""
    chebnorm's version, stated in the banner (made comment-safe).''',
    "command": '''\
command : str or None, default None
    The command line that made the file, stated in the banner (made comment-safe);
    None or empty: no such line.''',
    "files_command": '''\
command : str or None, default None
    The command line that made the files, for the banner (None: no line).''',
    "language": '''\
language : {"verilog", "vhdl"}, default "verilog"
    The HDL.''',
    "language_required": '''\
language : {"verilog", "vhdl"}
    The HDL.''',
    "budget": '''\
budget : ErrorBudget or None, default None
    A Horner design's certified budget (:func:`~chebnorm.hw.budget.error_budget`),
    stated in the banner; None: not stated. A piecewise design states its own.''',
    "vectors": '''\
vectors : str or None, default None
    The vector file the bench reads: an identifier, optionally with ``.hex``; None:
    ``NAME.hex``.''',
    "pipelined": '''\
pipelined : bool, default False
    The pipelined variant ``chebnorm_NAME_pipe`` (one register per Horner step; a
    Horner design of degree >= 1 only).''',
    "horner_design": '''\
design : HornerDesign
    The Horner evaluator (:func:`~chebnorm.hw.horner.design_horner`).''',
    "hdl_design": '''\
design : HornerDesign or PiecewiseDesign
    The design to print: a Horner evaluator
    (:func:`~chebnorm.hw.horner.design_horner`) or a piecewise ROM + Horner one
    (:func:`~chebnorm.hw.piecewise.design_piecewise`).''',
    "table_design": '''\
design : MultipartiteDesign, PlainTableDesign or PipelinedTable
    The table design (:func:`~chebnorm.hw.multipartite.design_multipartite`,
    :func:`~chebnorm.hw.plain_table.design_plain_table`, or a multipartite one with
    pipeline cuts).''',
    "sized_piecewise": '''\
d : PiecewiseDesign
    A sized piecewise design (``design_piecewise(..., widths="auto")``, ``d.sized``).''',
    "component_width": '''\
w : int
    Signed width of a vector component, ``>= 1`` (``frac_bits + 2`` holds ``[-2, 2)``).''',
    "frac_bits": '''\
frac_bits : int
    ``F``: fractional bits of the vector components, ``>= 0``.''',
    "target": '''\
target : str
    A target name (:func:`chebnorm.hw.targets.target_names`).''',
}

#: the decorator that fills :data:`HW_FRAGMENTS` into a docstring
hw_doc = docstring(**HW_FRAGMENTS)
