"""VHDL printers: the combinational and the pipelined evaluator of a
:class:`~chebnorm.hw.horner.HornerDesign` and the evaluator of a
:class:`~chebnorm.hw.piecewise.PiecewiseDesign` (ROM + Horner), each the
netlist of :mod:`chebnorm.hw.hdl.datapath` that the Verilog printers print
too, printed by :func:`chebnorm.hw.hdl.netlist.vhdl`, and their
self-checking test benches (:func:`chebnorm.hw.run_vhdl.simulate_vhdl` runs
them in GHDL).

The entities follow the Verilog port contract::

    entity chebnorm_NAME is
        generic (IN_BITS : natural := W; OUT_BITS : natural := V);
        port (x : in std_logic_vector(IN_BITS-1 downto 0);
              y : out std_logic_vector(OUT_BITS-1 downto 0));

(``chebnorm_NAME_pipe`` adds ``clk`` and the generic ``LATENCY``; a
piecewise entity has the ports of the combinational one). The
datapath is written in ``ieee.numeric_std`` ``signed`` arithmetic with the
widths of the Verilog wires, and every width change goes through one
function, ``wrap``, that does what a Verilog assignment does: sign-extend
to a wider wire, keep the low bits of a narrower one. So the two HDLs agree
bit for bit even where a wire would overflow (which the sizing rules out
anyway). Constants are printed as bit strings (VHDL's ``integer`` may hold
only 32 bits) with their decimal value in a comment.

The test bench reads the bit-accurate model's expected outputs from the
same ``chebnorm_NAME.hex`` as the Verilog bench (one hex word a line),
checks every input code, writes the outputs it saw to
``chebnorm_NAME_vhdl_y.hex`` (so the two simulators' outputs can be
compared code for code) and reports one ``PASS:``/``FAIL:`` line. VHDL-2008
(``ghdl --std=08``).
"""

from __future__ import annotations


from ..horner import HornerDesign
from .bench import bench_ports, testbench
from .common import module_name, pipelined_name
from .datapath import horner_netlist, piecewise_netlist, sized_piecewise_netlist
from .netlist import vhdl as _vhdl
from .._docfrag import hw_doc

# an implementation module of chebnorm.hw.hdl: the API is what chebnorm.hw.hdl exports
__all__: list[str] = []

#: the VHDL standard of the printed text (``ghdl --std=08``)
VHDL_STD = "08"


@hw_doc
def vhdl_module(design: HornerDesign, *, version: str = "", command: str | None = None,
                budget=None) -> str:
    """The combinational VHDL evaluator of ``design`` (see the module docstring).

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 2), 8, 8, coef_bits=12)
    >>> "entity chebnorm_dichotomy_d2 is" in vhdl_module(d)
    True

    Parameters
    ----------
    %(horner_design)s
    %(version)s
    %(command)s
    %(budget)s

    Returns
    -------
    str
        The VHDL-2008 text, banner first.

    Raises
    ------
    ValueError
        If the design's name is not a safe identifier.
    """
    return _vhdl(horner_netlist(design, language="vhdl", version=version, command=command,
                                budget=budget))



@hw_doc
def vhdl_pipelined_module(design: HornerDesign, *, version: str = "",
                          command: str | None = None, budget=None) -> str:
    """The pipelined VHDL evaluator ``chebnorm_NAME_pipe``: the datapath of
    :func:`vhdl_module` with one register stage after each Horner step, as
    :func:`~chebnorm.hw.hdl.verilog.verilog_pipelined_module` (latency ``degree``).

    Parameters
    ----------
    %(horner_design)s
    %(version)s
    %(command)s
    %(budget)s

    Returns
    -------
    str
        The VHDL-2008 text of ``chebnorm_NAME_pipe``, banner first.

    Raises
    ------
    ValueError
        If the design has degree 0 (nothing to pipeline).
    ValueError
        If the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> v = vhdl_pipelined_module(d)
    >>> [line.strip() for line in v.splitlines() if line.startswith("entity")]
    ['entity chebnorm_dichotomy_d1_pipe is']
    """
    return _vhdl(horner_netlist(design, pipelined=True, language="vhdl", version=version,
                                command=command, budget=budget))



@hw_doc
def vhdl_testbench(design: HornerDesign, vectors: str | None = None) -> str:
    """Exhaustive self-checking bench of :func:`vhdl_module` (every input code).

    Parameters
    ----------
    %(horner_design)s
    %(vectors)s

    Returns
    -------
    str
        The VHDL-2008 bench text.

    Raises
    ------
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> tb = vhdl_testbench(d)
    >>> "chebnorm_dichotomy_d1.hex" in tb, "chebnorm_dichotomy_d1_vhdl_y.hex" in tb
    (True, True)
    """
    return testbench(bench_ports(design, design.module_name), "vhdl", vectors)


@hw_doc
def vhdl_pipelined_testbench(design: HornerDesign, vectors: str | None = None) -> str:
    """Exhaustive bench of the pipelined entity: one code per cycle, the output
    after edge ``i`` checked against code ``i - LATENCY + 1``.

    Parameters
    ----------
    %(horner_design)s
    %(vectors)s

    Returns
    -------
    str
        The VHDL-2008 bench text.

    Raises
    ------
    ValueError
        If the design has degree 0 (nothing to pipeline).
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> [line.strip() for line in vhdl_pipelined_testbench(d).splitlines() if "LATENCY" in line][:1]
    ['constant LATENCY  : natural := 1;']
    """
    return testbench(bench_ports(design, pipelined_name(design), design.steps), "vhdl", vectors)


# -- piecewise evaluator -------------------------------------------------------------

@hw_doc
def piecewise_vhdl(d, *, version: str = "", command: str | None = None) -> str:
    """The VHDL-2008 entity of a piecewise design ``d``
    (:class:`~chebnorm.hw.piecewise.PiecewiseDesign`): the coefficient ROM
    indexed by the top bits of ``x`` and the Horner datapath in the local
    variable, bit for bit the module of
    :func:`~chebnorm.hw.hdl.verilog.piecewise_verilog` (the same wire widths;
    every width change through ``wrap``, as a Verilog assignment).

    Parameters
    ----------
    d : PiecewiseDesign
        The piecewise design (:func:`~chebnorm.hw.piecewise.design_piecewise`); a sized
        one (``d.sized``) is printed by :func:`sized_piecewise_vhdl`.
    %(version)s
    %(command)s

    Returns
    -------
    str
        The VHDL-2008 text, banner first.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> v = piecewise_vhdl(design_piecewise(t, 8, 8))
    >>> v.count("-- segment "), "entity chebnorm_rs is" in v   # one ROM row per segment and power
    (8, True)
    """
    if d.sized:
        return sized_piecewise_vhdl(d, version=version, command=command)
    return _vhdl(piecewise_netlist(d, version=version, command=command))



@hw_doc
def piecewise_vhdl_testbench(d, vectors: str | None = None) -> str:
    """Exhaustive self-checking bench of :func:`piecewise_vhdl` (every input
    code against the model's ``NAME.hex``, as the Verilog bench).

    Parameters
    ----------
    d : PiecewiseDesign
        The piecewise design (:func:`~chebnorm.hw.piecewise.design_piecewise`).
    %(vectors)s

    Returns
    -------
    str
        The VHDL bench text.

    Raises
    ------
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> piecewise_vhdl_testbench(design_piecewise(t, 8, 8)).splitlines()[0]
    '-- tb_chebnorm_rs: exhaustive self-checking test bench of chebnorm_rs.'
    """
    return testbench(bench_ports(d, module_name(d)), "vhdl", vectors)


@hw_doc
def sized_piecewise_vhdl(d, *, version: str = "", command: str | None = None) -> str:
    """The VHDL-2008 entity of a sized piecewise design ``d`` (``d.sized``),
    bit for bit :func:`~chebnorm.hw.hdl.verilog.sized_piecewise_verilog`
    (the same wire widths, the same cut registers; every width change
    through ``wrap``).

    Parameters
    ----------
    %(sized_piecewise)s
    %(version)s
    %(command)s

    Returns
    -------
    str
        The VHDL-2008 text, banner first.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=4, coef_frac_bits=16, name="rs")
    >>> v = sized_piecewise_vhdl(design_piecewise(t, 8, 8, widths="auto", max_error=2 ** -5, pipeline=(0, 2)))
    >>> v.count("rising_edge(clk)"), "LATENCY  : natural := 2" in v
    (2, True)
    """
    return _vhdl(sized_piecewise_netlist(d, version=version, command=command))




@hw_doc
def piecewise_vhdl_clocked_testbench(d, vectors: str | None = None) -> str:
    """Exhaustive bench of a pipelined piecewise entity (``d.latency > 0``):
    one code per cycle, the output after edge ``i`` checked against code
    ``i - LATENCY + 1``.

    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8, widths="auto", max_error=2 ** -5, pipeline="full")
    >>> [ln.strip() for ln in piecewise_vhdl_clocked_testbench(d).splitlines() if "LATENCY  :" in ln]
    ['constant LATENCY  : natural := 2;']

    Parameters
    ----------
    d : PiecewiseDesign
        A sized piecewise design with pipeline cuts (``d.latency > 0``).
    %(vectors)s

    Returns
    -------
    str
        The VHDL bench text.

    Raises
    ------
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.
    """
    return testbench(bench_ports(d, module_name(d), d.latency), "vhdl", vectors)
