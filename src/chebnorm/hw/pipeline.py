"""Pipelining a design to a clock frequency, FloPoCo-style (``design --frequency``).

:func:`pipeline_to_frequency` starts from the combinational module, measures
its Fmax on the target and adds pipeline registers at the most useful stage
boundaries (:func:`cut_plans`) until the asked frequency is met or no cut is
left; the result is the first plan (fewest registers) that meets it, or the
fastest one measured when none does (with a :class:`FrequencyWarning`).

Timing, per target (:mod:`chebnorm.hw.targets`):

* ``ice40``: nextpnr-ice40's Fmax after place and route on the HX8K
  (``ct256``, placer seed fixed), the module between input and output
  registers -- a real figure;
* ``xc7`` / ``xc7-nodsp``: the model -- yosys ``sta`` over the 7-series cell
  delays, no routing (optimistic: it ranks, it does not sign off);
* ``generic`` has no device and no time: refused.

Cut points of a piecewise design (:class:`~chebnorm.hw.piecewise.PiecewiseDesign`,
one-width or sized): after the ROM read, after each multiply, after each add
(with its rounding; the values are unchanged, ``latency`` cycles later). The plans balance the stages
by a weight per stage (:data:`STAGE_WEIGHTS`: a multiply weighs two ROM reads
or two adds). A multipartite design (:class:`PipelinedTable`)
has two: after the table reads, after the offsets' sum. A plain table
(:class:`PipelinedTable` too) has two: its ROM output registered (a synchronous
read: block RAM in yosys) and its address registered. Any other design has none
(its plan list is empty: only the combinational module is measured).

:func:`verify_pipelined` simulates the pipelined module cycle by cycle over
every input code in Icarus Verilog (one code per clock; output ``i`` checked
against the bit-accurate model's value of code ``i - latency``).
"""

from __future__ import annotations

import math
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

from chebnorm.core.display import field_rows, summary_html, summary_repr
from chebnorm.exceptions import FrequencyWarning

from .design_base import Design
from .hdl.tables import table_cuts, table_files, table_module
from .targets import fmax_ice40, get_target, synthesize_target
from ._docfrag import hw_doc

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: relative delay of a stage: the ROM read, a multiply, an add, the output saturation
STAGE_WEIGHTS = {"rom": 1.0, "mul": 2.0, "add": 1.0, "output": 0.5}
#: nextpnr's timing-driven placement aims at most at this frequency (its range)
MAX_PNR_MHZ = 1000.0


def check_frequency(value, name: str = "frequency") -> float:
    """``value`` as a frequency in MHz: a finite number > 0 (text such as ``"250"``
    is read as a number).

    Parameters
    ----------
    value : float, int or str
        The frequency in MHz; must be finite and ``> 0``.
    name : str, default "frequency"
        The argument's name, for the message.

    Returns
    -------
    float
        ``value`` as a float.

    Raises
    ------
    ValueError
        naming ``name`` and the accepted range.

    >>> check_frequency("125.5")
    125.5
    >>> check_frequency(0)
    Traceback (most recent call last):
    ...
    ValueError: frequency 0: accepted: a finite number of MHz > 0, e.g. 100
    """
    v = math.nan
    if not isinstance(value, bool):
        try:
            v = float(value)
        except (TypeError, ValueError, OverflowError):
            v = math.nan
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name} {str(value)[:40]}: accepted: a finite number of MHz > 0, "
                         f"e.g. 100")
    return v


def _pipelinable(design) -> bool:
    return isinstance(design, Design) and bool(design.cut_points())


#: the cut points of the table designs :class:`PipelinedTable` pipelines
_TABLE_CUT_POINTS = (("tables", "offsets"), ("address", "rom"))


def _base(design):
    """``design`` without pipeline registers."""
    return design.combinational()


class PipelinedTable(Design):
    """A multipartite design or a plain table with pipeline registers at ``cuts``
    (multipartite, :data:`chebnorm.hw.hdl.tables.TABLE_CUTS`: ``0`` after the table
    reads, ``1`` after the offsets' sum; plain table,
    :data:`chebnorm.hw.hdl.tables.PLAIN_TABLE_CUTS`: ``0`` the address register,
    ``1`` the ROM output register); every other attribute is the design's (same
    values, ``latency`` cycles later).

    >>> from chebnorm.hw.multipartite import design_multipartite
    >>> p = PipelinedTable(design_multipartite("1/sqrt(1+3*x)", ("0", "1"), 8, 8), (0, 1))
    >>> p.latency, p.module_name, "parameter LATENCY = 2" in p.verilog()
    (2, 'chebnorm_multipartite', True)

    Parameters
    ----------
    base : MultipartiteDesign or PlainTableDesign
        The combinational design, from
        :func:`~chebnorm.hw.multipartite.design_multipartite` or
        :func:`~chebnorm.hw.plain_table.design_plain_table`.
    cuts : iterable of int
        Sorted register positions among 0 and 1 (above); the latency is ``len(cuts)``.

    Raises
    ------
    ValueError
        If ``base`` is not a table design or ``cuts`` is not such a set.
    """

    def __init__(self, base, cuts):
        if not isinstance(base, Design) or base.cut_points() not in _TABLE_CUT_POINTS \
                or base.combinational() is not base:
            raise ValueError(f"base: a {type(base).__name__}; accepted: a MultipartiteDesign "
                             f"or a PlainTableDesign")
        self.base = base
        self.cuts = tuple(cuts)
        table_cuts(self)  # checked

    def __getattr__(self, name):
        if name == "base":  # not yet set (copy, pickle): no recursion
            raise AttributeError(name)
        return getattr(self.base, name)

    @property
    def latency(self) -> int:
        """Clock cycles from ``x`` to ``y``."""
        return len(self.cuts)

    # -- the Design interface: the base's, but for the registers -----------------
    @property
    def architecture(self) -> str:
        """The base's architecture."""
        return self.base.architecture

    @property
    def module_name(self) -> str:
        """The base's module name."""
        return self.base.module_name

    def verify(self) -> "PipelinedTable":
        """Re-prove the base design; return ``self``."""
        self.base.verify()
        return self

    def evaluate(self, codes=None, **kw):
        """The base's output codes (``latency`` cycles later in the circuit)."""
        return self.base.evaluate(codes, **kw)

    def budget(self) -> dict:
        """The base's certified budget (registers change no value)."""
        return self.base.budget()

    def measure(self) -> dict:
        """The base's measured error."""
        return self.base.measure()

    def features(self):
        """The base's cost model inputs (the registers are not priced)."""
        return self.base.features()

    def cut_points(self) -> tuple[str, ...]:
        """The base's cut points."""
        return self.base.cut_points()

    def cut_plans(self) -> list[tuple[int, ...]]:
        """The base's cut plans."""
        return self.base.cut_plans()

    def with_cuts(self, cuts) -> "PipelinedTable":
        """The base with registers at ``cuts`` instead."""
        return PipelinedTable(self.base, cuts)

    def combinational(self):
        """The base design."""
        return self.base

    def state(self) -> dict:
        """The base and the cuts."""
        return {"base": self.base, "cuts": self.cuts}

    def hdl_files(self, language: str = "verilog") -> dict:
        """Module, clocked bench and vectors (:func:`chebnorm.hw.hdl.tables.table_files`)."""
        return table_files(self, language)

    def verilog(self, *, version: str = "", command: str | None = None) -> str:
        """The pipelined Verilog-2005 module (:func:`chebnorm.hw.hdl.tables.table_module`)."""
        return table_module(self, "verilog", version=version, command=command)

    def vhdl(self, *, version: str = "", command: str | None = None) -> str:
        """The pipelined VHDL-2008 entity (:func:`chebnorm.hw.hdl.tables.table_module`)."""
        return table_module(self, "vhdl", version=version, command=command)


def _verilog(design) -> str:
    return design.verilog()


@hw_doc
def design_files(design, language: str = "verilog") -> dict:
    """File name -> text of ``design``'s module, its exhaustive bench (clocked
    when pipelined) and its vector file in ``language``.

    >>> from chebnorm.hw.multipartite import design_multipartite
    >>> sorted(design_files(PipelinedTable(design_multipartite("1/sqrt(1+3*x)", ("0", "1"),
    ...                                                        8, 8), (0,)), "vhdl"))
    ['chebnorm_multipartite.hex', 'chebnorm_multipartite.vhd', 'tb_chebnorm_multipartite.vhd']

    Parameters
    ----------
    design : HornerDesign, PiecewiseDesign, MultipartiteDesign, PlainTableDesign or PipelinedTable
        The design to print (combinational or with cuts).
    %(language)s

    Returns
    -------
    dict of str to str
        File name -> file text: the module, its test bench and its vector file.

    Raises
    ------
    ValueError
        If ``language`` is not ``"verilog"`` or ``"vhdl"``.
    """
    return design.hdl_files(language)


def cut_plans(design) -> list[tuple[int, ...]]:
    """The cut sets tried, one per latency ``1, 2, ...``, as *positions*: for
    a piecewise design of degree ``n`` (one-width or sized), ``0`` after the ROM read,
    ``2i - 1`` after the ``i``-th multiply, ``2i`` after the ``i``-th add
    (:func:`cut_names`); for each count of registers the set whose heaviest
    stage (by :data:`STAGE_WEIGHTS`) is the lightest, ties to the earliest
    cuts. A multipartite design: ``[(0,), (0, 1)]`` (after the table reads,
    after the offsets' sum); a plain table: ``[(1,), (0, 1)]`` (the ROM output
    registered, then the address too). Empty for a design without cut points.

    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8, widths="auto", max_error=2 ** -5)
    >>> [cut_names(d, p) for p in cut_plans(d)]
    [['mul1'], ['rom', 'mul1'], ['rom', 'mul1', 'add1']]
    >>> cut_plans(design_piecewise(t, 8, 8))     # the one-width design: the same points
    [(1,), (0, 1), (0, 1, 2)]

    Parameters
    ----------
    design : object
        A design of :mod:`chebnorm.hw`; a piecewise design, a multipartite
        design and a plain table have cut points.

    Returns
    -------
    list of tuple of int
        The cut positions per latency 1, 2, ..., or ``[]``.
    """
    if not _pipelinable(design):
        return []
    return list(design.cut_plans())


def cut_names(design, cuts) -> list[str]:
    """Names of cut positions: ``rom``, ``mulI``, ``addI`` (piecewise),
    ``tables``, ``offsets`` (multipartite) or ``address``, ``rom`` (plain table).

    >>> from chebnorm.hw.multipartite import design_multipartite
    >>> cut_names(design_multipartite("1/sqrt(1+3*x)", ("0", "1"), 8, 8), (0, 1))
    ['tables', 'offsets']

    Parameters
    ----------
    design : Design
        A design with cut points
        (:meth:`~chebnorm.hw.design_base.Design.cut_points`): a sized piecewise
        design or a multipartite design.
    cuts : iterable of int
        Cut positions, as :func:`cut_plans` gives them.

    Returns
    -------
    list of str
        One name per position, in order.

    Raises
    ------
    ValueError
        A position is not one of the design's cut points.
    """
    points = design.cut_points()
    cuts = list(cuts)
    if cuts and not points:
        raise ValueError(f"design: a {type(design).__name__} has no pipeline cut points; "
                         f"accepted: a design with cut points")
    if any(isinstance(c, bool) or not isinstance(c, int) or not 0 <= c < len(points)
           for c in cuts):
        raise ValueError(f"cuts {cuts[:8]}: accepted: positions 0..{len(points) - 1} "
                         f"({', '.join(points)})")
    return [points[c] for c in cuts]


def with_cuts(design, cuts):
    """``design`` with pipeline registers at the positions ``cuts``
    (:func:`cut_plans`; the same values, ``len(cuts)`` cycles later);
    ValueError for a design without cut points or a position out of range.

    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = with_cuts(design_piecewise(t, 8, 8, widths="auto", max_error=2 ** -5), (0, 1))
    >>> d.cuts, d.mult_cuts, d.latency
    ((0,), (1,), 2)

    Parameters
    ----------
    design : object
        A piecewise design (:func:`~chebnorm.hw.piecewise.design_piecewise`, one-width
        or sized), a multipartite design or a plain table, combinational or already
        pipelined (its cuts are replaced).
    cuts : iterable of int
        Register positions, in any order (duplicates count once): 0 to ``2 * degree``
        for a piecewise design (0 after the ROM, ``2i - 1`` after the ``i``-th
        multiply, ``2i`` after the ``i``-th add); 0 and 1 for a multipartite design
        or a plain table.

    Returns
    -------
    PiecewiseDesign or PipelinedTable
        A new design with the cuts (a piecewise design stays one; a table design
        becomes a :class:`PipelinedTable`), ``latency == len(cuts)``.

    Raises
    ------
    ValueError
        If the design has no cut points, ``cuts`` is not iterable, or a position is out
        of range.
    """
    if not _pipelinable(design):
        raise ValueError(f"design: a {type(design).__name__} has no pipeline cut points; "
                         f"accepted: a piecewise design (design_piecewise), a multipartite "
                         f"design or a plain table")
    if isinstance(cuts, (str, bytes)) or not hasattr(cuts, "__iter__"):
        raise ValueError(f"cuts {cuts!r}: accepted: an iterable of cut positions")
    cuts = tuple(sorted(set(cuts)))
    return design.with_cuts(cuts)


@dataclass(frozen=True)
class PipelineStep:
    """One measured plan: its cut positions, latency and Fmax in MHz.

    >>> PipelineStep((1,), 1, 46.9).latency
    1

    Attributes
    ----------
    cuts : tuple of int
        The cut positions (:func:`cut_plans`); ``()`` for the combinational design.
    latency : int
        Clock cycles from input to output, ``len(cuts)``.
    fmax_mhz : float
        The Fmax measured on the target, MHz.
    """

    cuts: tuple[int, ...]
    latency: int
    fmax_mhz: float


@dataclass(frozen=True)
class PipelineResult:
    """The outcome of :func:`pipeline_to_frequency`.

    Attributes
    ----------
    design : object
        The design chosen (with its cuts): the first plan meeting the
        frequency, else the fastest measured (fewest registers on a tie).
    target : str
        The target timed.
    frequency_mhz : float
        The frequency asked.
    met : bool
        Whether ``fmax_mhz >= frequency_mhz``.
    latency : int
        Clock cycles from input to output (0: combinational).
    fmax_mhz : float
        The chosen design's Fmax.
    source : str
        Where the figure comes from (nextpnr-ice40 or the sta model).
    cost : TargetCost
        The chosen module's mapping on the target (its FFs are the extra
        flip-flops: the combinational module has none).
    steps : tuple of PipelineStep
        Every plan measured, in order.

    Examples
    --------
    >>> from chebnorm.hw.targets import cost_from_types
    >>> r = PipelineResult(None, "ice40", 80.0, False, 1, 61.5, "nextpnr-ice40",
    ...                    cost_from_types("ice40", {"SB_LUT4": 90, "SB_DFF": 12}),
    ...                    (PipelineStep((), 0, 40.0), PipelineStep((1,), 1, 61.5)))
    >>> r.extra_ffs
    12
    >>> r.shortfall()
    '80 MHz not reached: the highest is 61.50 MHz at latency 1 (no more cut points; MHz per latency 0: 40.00, 1: 61.50; nextpnr-ice40)'
    """

    design: object
    target: str
    frequency_mhz: float
    met: bool
    latency: int
    fmax_mhz: float
    source: str
    cost: object
    steps: tuple

    def _summary(self) -> list[tuple[str, object]]:
        return [("target", self.target), ("frequency_mhz", self.frequency_mhz),
                ("met", self.met), ("latency", self.latency), ("fmax_mhz", self.fmax_mhz),
                ("source", self.source)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    @property
    def extra_ffs(self) -> int:
        """Flip-flops the pipeline adds (the mapped module's FFs)."""
        return int(self.cost.ffs)

    def line(self) -> str:
        """One line: latency, Fmax, the asked frequency and the extra FFs."""
        verdict = "met" if self.met else "NOT met"
        return (f"pipelined for {self.frequency_mhz:g} MHz ({verdict}): latency {self.latency} "
                f"cycle{'' if self.latency == 1 else 's'}, Fmax {self.fmax_mhz:.2f} MHz ({self.source}), {self.extra_ffs} extra "
                f"FFs; {self.cost.line()}")

    def shortfall(self) -> str:
        """The one-line message when the frequency is not met (empty when met)."""
        if self.met:
            return ""
        tried = ", ".join(f"{s.latency}: {s.fmax_mhz:.2f}" for s in self.steps)
        why = ("no more cut points" if len(self.steps) > 1 else
               "this architecture has no pipeline cut points")
        return (f"{self.frequency_mhz:g} MHz not reached: the highest is {self.fmax_mhz:.2f} MHz "
                f"at latency {self.latency} ({why}; MHz per latency {tried}; {self.source})")


def _timing(design, target: str, frequency: float, seed: int):
    """(Fmax MHz, source, TargetCost or None) of ``design``'s module on ``target``."""
    text = _verilog(design)
    top = design.module_name
    clocked = design.latency > 0
    if target == "ice40":
        f = fmax_ice40(text, top, clocked=clocked, freq_mhz=min(frequency, MAX_PNR_MHZ),
                       seed=seed)
        return f, f"nextpnr-ice40, HX8K ct256, placed and routed, seed {seed}", None
    cost = synthesize_target(text, top, target, timing=True)
    if not cost.delay_ns:
        raise ValueError(f"yosys sta gave no delay for {top}")
    return (1000.0 / cost.delay_ns,
            "model: yosys sta, Artix-7 cell delays without routing (optimistic)", cost)


def pipeline_to_frequency(design, target: str, frequency_mhz, *, seed: int = 1,
                          warn: bool = True) -> PipelineResult:
    """Pipeline ``design`` until its Fmax on ``target`` reaches ``frequency_mhz``.

    Parameters
    ----------
    design : object
        A design of :mod:`chebnorm.hw` (combinational). A piecewise design
        (one-width or sized), a multipartite design and a plain table have cut points
        (:func:`cut_plans`); any other is measured as it is.
    target : str
        ``ice40`` (nextpnr-ice40 Fmax), ``xc7`` or ``xc7-nodsp`` (the sta
        model); ``generic`` has no time and is refused.
    frequency_mhz : float
        The clock asked, MHz (:func:`check_frequency`).
    seed : int
        nextpnr-ice40's placer seed (same seed, same figure).
    warn : bool
        Issue a :class:`FrequencyWarning` when the frequency is not reached.

    Returns
    -------
    PipelineResult

    Raises
    ------
    ValueError
        for a bad frequency, the ``generic`` target, or a tool failure.

    Examples
    --------
    >>> from chebnorm.hw.multipartite import design_multipartite
    >>> d = design_multipartite("1/sqrt(1+3*x)", ("0", "1"), 8, 8)
    >>> pipeline_to_frequency(d, "generic", 100)
    Traceback (most recent call last):
    ...
    ValueError: target 'generic' has no device and no clock (gate depth only); accepted for a frequency: ice40 (nextpnr-ice40), xc7 or xc7-nodsp (the sta delay model)
    """
    freq = check_frequency(frequency_mhz, "frequency_mhz")
    t = get_target(target)
    if t.timing not in ("nextpnr", "sta"):
        raise ValueError(f"target {t.name!r} has no device and no clock (gate depth only); "
                         f"accepted for a frequency: ice40 (nextpnr-ice40), xc7 or xc7-nodsp "
                         f"(the sta delay model)")
    base = _base(design)
    plans = [()] + cut_plans(base)
    steps, measured = [], []
    for cuts in plans:
        d = with_cuts(base, cuts) if cuts else base
        fmax, source, cost = _timing(d, t.name, freq, seed)
        steps.append(PipelineStep(tuple(cuts), len(cuts), round(fmax, 2)))
        measured.append((d, fmax, cost))
        if fmax >= freq:
            break
    # the first plan meeting the frequency (the loop stopped there), else the fastest
    i = len(measured) - 1 if measured[-1][1] >= freq else \
        max(range(len(measured)), key=lambda k: (measured[k][1], -k))
    d, fmax, cost = measured[i]
    if cost is None:
        cost = synthesize_target(_verilog(d), d.module_name, t.name)
    res = PipelineResult(d, t.name, freq, fmax >= freq, len(steps[i].cuts), round(fmax, 2),
                         source, cost, tuple(steps))
    if warn and not res.met:
        warnings.warn(res.shortfall(), FrequencyWarning, stacklevel=2)
    return res


def verify_pipelined(design, *, bench_design=None):
    """Simulate ``design``'s module in Icarus Verilog over every input code, one
    code per clock cycle, each output checked against the bit-accurate model
    ``latency`` cycles later (combinational: every code at once).

    ``bench_design``: print the bench of this design instead (same module
    name and model, another latency) -- a deliberately wrong bench, which
    must fail (the mutation test of the check itself).

    Parameters
    ----------
    design : object
        A design of :mod:`chebnorm.hw`, combinational or pipelined.
    bench_design : object or None, default None
        A design whose test bench replaces ``design``'s (the mutation test); None
        checks ``design`` with its own bench.

    Returns
    -------
    chebnorm.hw.run_verilog.SimResult

    Examples
    --------
    >>> from chebnorm.core.tools import which
    >>> from chebnorm.hw.multipartite import design_multipartite
    >>> d = with_cuts(design_multipartite("1/sqrt(1+3*x)", ("0", "1"), 8, 8), (0, 1))
    >>> if which("iverilog"):
    ...     print(verify_pipelined(d).line)
    ...     print(verify_pipelined(d, bench_design=with_cuts(d, (0,))).passed)
    ... else:
    ...     print("PASS: 256 vectors, 0 mismatches (chebnorm_multipartite, latency 2)")
    ...     print(False)
    PASS: 256 vectors, 0 mismatches (chebnorm_multipartite, latency 2)
    False
    """
    from .run_verilog import simulate

    files = design_files(design, "verilog")
    if bench_design is not None:
        bench = design_files(bench_design, "verilog")
        files = {k: (bench[k] if k.startswith("tb_") else v) for k, v in files.items()}
    with tempfile.TemporaryDirectory() as tmp:
        for name, text in files.items():
            (Path(tmp) / name).write_text(text, encoding="utf-8")
        return simulate(tmp, design)
