"""FPGA targets: what a design costs on a device, by yosys's own mapping, and how fast it runs.

A :class:`Target` names one yosys flow (a frozen registry, :data:`TARGETS`):

* ``generic``: ``synth -top T`` -- yosys's generic gates (``$_AND_``, ``$_MUX_``,
  ...), today's cell count; the score is the cell count.
* ``xc7``: ``synth_xilinx -family xc7 -top T`` -- Xilinx 7-series LUT1..LUT6,
  ``DSP48E1``, ``CARRY4``, ``MUXF7``/``MUXF8``, ``FD*``, ``RAMB18E1``/``RAMB36E1``.
* ``xc7-nodsp``: the same with ``-nodsp`` (every multiplier in LUTs and carry chains).
* ``ice40``: ``synth_ice40 -top T`` -- Lattice iCE40 ``SB_LUT4``, ``SB_CARRY``,
  ``SB_DFF*``, ``SB_RAM40_4K`` (the HX8K has no ``SB_MAC16``).

**Score** (one number per target, in *LUT equivalents of the device budget*):
a hard block counts as the share of the device it takes, in LUTs: the device's
LUT count divided by its count of that block. On the Artix-7 ``xc7a100t``
(63,400 LUTs, 126,800 flip-flops, 240 ``DSP48E1``, 135 ``RAMB36E1`` = 270
``RAMB18E1``) one DSP48E1 is 63,400 / 240 = 264.2 LUTs, a RAMB36E1 469.6, a
RAMB18E1 234.8 and a flip-flop 0.5; on the iCE40 HX8K (7,680 LUT4, 7,680
flip-flops, 32 ``SB_RAM40_4K``) a RAM block is 240 LUTs and a flip-flop 1.
Carry cells (``CARRY4``, ``SB_CARRY``) and the wide multiplexers
(``MUXF7``/``MUXF8``) are reported but score 0: they sit in the slice (logic
cell) beside the LUTs that feed them, which are already counted. Input/output
buffers (``IBUF``/``OBUF``, inserted by ``synth_xilinx``) are not logic and
score 0, nor does ``INV`` (yosys's 7-series inverter, which the vendor flow
folds into the neighbouring LUT). ``generic`` scores its cell count. A score
compares designs on one target; comparing against a peer's design, never
spend more DSPs than the peer (a DSP-rich design can win on score while not
fitting beside the rest).

**Timing**: on ``ice40`` the real figure, place and route by nextpnr-ice40
(:func:`fmax_ice40`, HX8K ``ct256``, the module between input and output
registers). On ``xc7`` a *model*: yosys ``sta`` over yosys's own 7-series cell
library (``+/xilinx/cells_sim.v``, whose ``specify`` delays come from Project
X-Ray's Artix-7 timing database, maximum delays) of the synthesized netlist --
the sum of the cell delays along the longest path, **without routing**: an
optimistic figure for that netlist (``delay_ns``), with the number of cells on
that path (``levels``); real routing adds a net delay per level, and the vendor
tool maps differently. It ranks designs; it is not a sign-off. On ``generic``
the model is the depth in gates (``ltp -noff``: the longest topological path,
flip-flops cut), no time.

Every tool runs in a private temporary folder (``cwd``) with
:func:`chebnorm.hw.run_verilog.tool_env`, on argument lists and fixed relative file
names: no path and no environment variable reaches a command text.
"""

from __future__ import annotations

import json
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from chebnorm.core.display import field_rows, summary_html, summary_repr

from .hdl import netlist
from .run_verilog import tool_env
from chebnorm.core.tools import require, run_tool
from chebnorm.exceptions import ToolFailed

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

_ID = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


@dataclass(frozen=True)
class Target:
    """One synthesis flow: its name, the yosys command that maps the design, what
    its statistics mean, and the score weights (LUT equivalents per block).

    Attributes
    ----------
    name : str
        The target's name (a key of :data:`TARGETS`).
    synth : str
        The yosys command that maps the design, ``{top}`` standing for the
        module name (:meth:`script` fills it in).
    meaning : str
        What the mapped cells are, in words.
    device : str
        The device whose counts give the weights (a key of
        :data:`DEVICE_WEIGHTS`, or ``"none"``).
    weights : dict of str to float, default {}
        LUT equivalents per cell class (``lut``, ``ff``, ``dsp``, ``bram18``,
        ``bram36``); empty for ``generic`` (its score counts cells).
    timing : str, default ""
        The delay model: ``"nextpnr"`` (place and route), ``"sta"`` (cell
        delays, no routing) or ``"ltp"`` (gate depth).
    fast : str, default ""
        The same flow without the parts that cannot change the result for a
        design of plain RTL (empty: none): on ``xc7``, ``synth_xilinx``'s
        ``begin`` step reads the 328 blackbox modules of ``cells_xtra.v``
        besides ``cells_sim.v`` (43 % of a run); a design that instantiates
        no primitive needs only ``cells_sim.v``, which declares every cell the
        mapping produces (LUTs, CARRY4, MUXF7/8, DSP48E1, RAMB18E1/36E1,
        flip-flops). :func:`synthesize_target` runs it first and the full
        ``synth`` when yosys then misses a module.

    Examples
    --------
    >>> t = get_target("xc7-nodsp")
    >>> t.script("m"), round(t.weights["dsp"], 1), t.timing
    ('synth_xilinx -family xc7 -nodsp -top m', 264.2, 'sta')
    """

    name: str
    synth: str          # the yosys command, "{top}" replaced by the module name
    meaning: str
    device: str
    weights: dict = field(default_factory=dict)   # cell class -> LUT equivalents
    timing: str = ""    # "nextpnr", "sta" (cell delays, no routing) or "ltp" (gate depth)
    fast: str = ""      # the same mapping without the unneeded library reads ("" for none)

    def script(self, top: str) -> str:
        return self.synth.format(top=top)

    def fast_script(self, top: str) -> str:
        """The :attr:`fast` flow for ``top`` (the full :meth:`script` when there is none)."""
        return (self.fast or self.synth).format(top=top)


#: LUT equivalents per hard block, from the device counts (module docstring)
DEVICE_WEIGHTS = {
    "xc7a100t": {"lut": 1.0, "ff": 63400 / 126800, "dsp": 63400 / 240,
                 "bram18": 63400 / 270, "bram36": 63400 / 135},
    "ice40-hx8k": {"lut": 1.0, "ff": 7680 / 7680, "dsp": 0.0, "bram18": 7680 / 32,
                   "bram36": 7680 / 32},
}

# synth_xilinx's begin step with cells_sim.v only (Target.fast), then the rest of it
_XC7_FAST = ("read_verilog -lib -specify +/xilinx/cells_sim.v; hierarchy -check -top {{top}}; "
             "synth_xilinx -family xc7{opts} -top {{top}} -run prepare:")

#: the registered targets, name to :class:`Target`, in the order :func:`target_names` lists
TARGETS = {
    "generic": Target("generic", "synth -top {top}", "yosys generic gate cells", "none",
                      {}, "ltp"),
    "xc7": Target("xc7", "synth_xilinx -family xc7 -top {top}",
                  "Xilinx 7-series LUT1..6, DSP48E1, CARRY4, MUXF7/8, FD*, RAMB18/36",
                  "xc7a100t", DEVICE_WEIGHTS["xc7a100t"], "sta",
                  _XC7_FAST.format(opts="")),
    "xc7-nodsp": Target("xc7-nodsp", "synth_xilinx -family xc7 -nodsp -top {top}",
                        "Xilinx 7-series without DSP48E1: multipliers in LUTs and CARRY4",
                        "xc7a100t", DEVICE_WEIGHTS["xc7a100t"], "sta",
                        _XC7_FAST.format(opts=" -nodsp")),
    "ice40": Target("ice40", "synth_ice40 -top {top}",
                    "Lattice iCE40 SB_LUT4, SB_CARRY, SB_DFF*, SB_RAM40_4K",
                    "ice40-hx8k", DEVICE_WEIGHTS["ice40-hx8k"], "nextpnr"),
}


def target_names() -> list[str]:
    """The registered target names, in registry order.

    Returns
    -------
    list of str
        The keys of :data:`TARGETS`.

    Examples
    --------
    >>> target_names()
    ['generic', 'xc7', 'xc7-nodsp', 'ice40']
    """
    return list(TARGETS)


def get_target(name) -> Target:
    """The registered :class:`Target` called ``name``.

    Parameters
    ----------
    name : str
        One of :func:`target_names` (exact spelling).

    Returns
    -------
    Target
        The registry's entry.

    Raises
    ------
    ValueError
        ``name`` is not a str or not registered; the message names the value
        and the accepted names.

    Examples
    --------
    >>> get_target("xc7").device
    'xc7a100t'
    >>> get_target("xc9")
    Traceback (most recent call last):
    ...
    ValueError: target 'xc9' is not known; accepted: generic, xc7, xc7-nodsp, ice40
    """
    if not isinstance(name, str) or name not in TARGETS:
        raise ValueError(f"target {str(name)[:40]!r} is not known; accepted: "
                         f"{', '.join(TARGETS)}")
    return TARGETS[name]


def _cell_class(cell: str) -> str:
    """The class of a mapped cell type: lut, dsp, carry, mux, ff, bram18, bram36, io, other."""
    c = cell.lstrip("\\")
    if re.fullmatch(r"LUT[1-6]|SB_LUT4", c):
        return "lut"
    if c in ("DSP48E1", "SB_MAC16"):
        return "dsp"
    if c in ("CARRY4", "SB_CARRY"):
        return "carry"
    if c in ("MUXF7", "MUXF8"):
        return "mux"
    if re.fullmatch(r"FD[A-Z]*|SB_DFF[A-Z]*|\$_S?DFF[A-Z0-9_]*|\$_DFFE?_[A-Z0-9_]*", c):
        return "ff"
    if c in ("RAMB18E1", "SB_RAM40_4K"):
        return "bram18"
    if c == "RAMB36E1":
        return "bram36"
    if c in ("IBUF", "OBUF", "BUFG", "IBUFG", "SB_IO", "SB_GB"):
        return "io"
    return "other"


@dataclass(frozen=True)
class TargetCost:
    """Yosys's mapping of one module on one target: cells by class and type, the
    score (module docstring: LUT equivalents, or cells on ``generic``) and,
    when asked, the timing model (``levels``, ``delay_ns``; ``fmax_mhz`` only
    from nextpnr, see :func:`fmax_ice40`).

    Attributes
    ----------
    target : str
        The target's name.
    cells : int
        Every mapped cell, all types.
    luts, dsps, carries, muxes, ffs : int
        Cells of each class (LUTs, DSP blocks, carry chains, MUXF7/8,
        flip-flops).
    brams : int
        Block RAMs (18 and 36 kbit counted alike).
    score : float
        Cells on ``generic``; else the LUT equivalents
        ``sum(weights[class] * count)`` (:attr:`Target.weights`).
    by_type : dict of str to int
        Yosys' cell counts by cell type.
    levels : int or None, default None
        The timing model's path length in cells (None: no timing asked).
    delay_ns : float or None, default None
        The ``sta`` model's path delay in ns (xc7 only).
    timing_model : str, default ""
        Which delay model gave ``levels``/``delay_ns``, in words.
    netlist : str, default ""
        The mapped netlist (yosys RTLIL) when :func:`synthesize_target` was
        asked to keep it, for a later :func:`sta_from_netlist`; not compared,
        not in the repr.

    Examples
    --------
    >>> c = cost_from_types("ice40", {"SB_LUT4": 90, "SB_CARRY": 12, "SB_RAM40_4K": 1})
    >>> c.line()
    'ice40: 90 LUT, 0 DSP, 12 carry, 0 mux, 0 FF, 1 RAM; score 330.0 LUT equivalents'
    """

    target: str
    cells: int
    luts: int
    dsps: int
    carries: int
    muxes: int
    ffs: int
    brams: int
    score: float
    by_type: dict
    levels: int | None = None
    delay_ns: float | None = None
    timing_model: str = ""
    netlist: str = field(default="", repr=False, compare=False)

    def _summary(self) -> list[tuple[str, object]]:
        return [("target", self.target), ("cells", self.cells), ("luts", self.luts),
                ("dsps", self.dsps), ("score", self.score), ("delay_ns", self.delay_ns)]

    def _display_rows(self) -> list[tuple[str, object]]:
        return [(k, f"{len(v)} characters of RTLIL" if k == "netlist" else v)
                for k, v in field_rows(self)]

    __repr__ = summary_repr
    _repr_html_ = summary_html

    def as_dict(self) -> dict:
        """Plain fields for JSON (sorted cell types)."""
        return {"target": self.target, "cells": self.cells, "luts": self.luts,
                "dsps": self.dsps, "carries": self.carries, "muxes": self.muxes,
                "ffs": self.ffs, "brams": self.brams, "score": round(self.score, 1),
                "by_type": dict(sorted(self.by_type.items())), "levels": self.levels,
                "delay_ns": self.delay_ns, "timing_model": self.timing_model}

    def line(self) -> str:
        """One text line: the counts and the score."""
        if self.target == "generic":
            return f"generic: {self.cells} cells"
        return (f"{self.target}: {self.luts} LUT, {self.dsps} DSP, {self.carries} carry, "
                f"{self.muxes} mux, {self.ffs} FF, {self.brams} RAM; score {self.score:.1f} "
                f"LUT equivalents")


def cost_from_types(target: str, by_type: dict) -> TargetCost:
    """A :class:`TargetCost` of cell counts ``by_type`` (yosys ``stat``) on ``target``.

    Parameters
    ----------
    target : str
        One of :func:`target_names`.
    by_type : dict of str to int
        Cell type (``LUT6``, ``SB_CARRY``, ``$_AND_``, ...; a leading backslash
        is ignored) to count; a type of no known class counts only in
        ``cells``.

    Returns
    -------
    TargetCost
        The counts by class and the score; no timing.

    Raises
    ------
    ValueError
        ``target`` is not registered.

    Examples
    --------
    >>> c = cost_from_types("xc7", {"LUT6": 60, "LUT2": 4, "DSP48E1": 2, "CARRY4": 6,
    ...                             "IBUF": 16, "OBUF": 16})
    >>> c.luts, c.dsps, round(c.score, 1)
    (64, 2, 592.3)
    """
    t = get_target(target)
    counts = {"lut": 0, "dsp": 0, "carry": 0, "mux": 0, "ff": 0, "bram18": 0, "bram36": 0}
    for cell, n in by_type.items():
        k = _cell_class(cell)
        if k in counts:
            counts[k] += int(n)
    cells = sum(int(n) for n in by_type.values())
    if target == "generic":
        score = float(cells)
    else:
        score = float(sum(t.weights.get(k, 0.0) * counts[k] for k in counts))
    return TargetCost(target, cells, counts["lut"], counts["dsp"], counts["carry"],
                      counts["mux"], counts["ff"], counts["bram18"] + counts["bram36"], score,
                      dict(by_type))


def _check_top(top) -> str:
    if not isinstance(top, str) or not _ID.fullmatch(top):
        raise ValueError(f"top: {str(top)[:60]!r} is not a module name; accepted: a Verilog "
                         f"identifier [A-Za-z_][A-Za-z0-9_]*")
    return top


#: yosys's report of an ABC child killed by a signal (an abort, not a verdict on the netlist)
_ABC_CRASH = re.compile(r"ERROR: ABC: execution of command .* failed: return code (13[0-9]|14[0-9])")


def _run(argv: list[str], cwd: str, what: str, timeout: float) -> str:
    proc = run_tool(argv, tool=what, timeout=timeout, cwd=cwd, env=tool_env())
    if proc.returncode != 0 and _ABC_CRASH.search(proc.stdout + proc.stderr):
        # ABC, run by yosys as a child, now and then aborts on a loaded machine: the same
        # script once more (a second crash, or any other failure, is reported)
        proc = run_tool(argv, tool=what, timeout=timeout, cwd=cwd, env=tool_env())
    if proc.returncode != 0:  # yosys and nextpnr print their errors on both streams
        raise ToolFailed(what, proc.returncode, proc.stdout[-300:] + "\n" + proc.stderr)
    return proc.stdout


def _yosys(tmp: str, script: str, what: str, timeout: float) -> str:
    return _run([require("yosys", "this step"), "-p", script], tmp, f"yosys ({what})", timeout)


def _stat(tmp: str, top: str) -> dict:
    data = json.loads((Path(tmp) / "stat.json").read_text(encoding="utf-8"))
    mods = data.get("modules", {})
    m = mods.get("\\" + top) or mods.get(top) or data.get("design") or {}
    if "num_cells_by_type" not in m:
        raise ValueError(f"yosys printed no cell statistics for {top}")
    return {str(k): int(v) for k, v in m["num_cells_by_type"].items()}


def _sta(text: str) -> tuple[int, float]:
    """(cells on the critical path, its arrival time in ns) from yosys ``sta``."""
    m = re.search(r"Latest arrival time in '[^']*' is (\d+):", text)
    if not m:
        raise ValueError("yosys sta printed no arrival time")
    rest = text[m.end():].split("Arrival histogram", 1)[0]
    levels = sum(1 for t in re.findall(r"\((\w+)\.\w+(?:\[\d+\])?->\w+\)", rest)
                 if _cell_class(t) not in ("io",))
    return levels, int(m.group(1)) / 1000.0


def _ltp(text: str) -> int:
    m = re.search(r"Longest topological path in \S+ \(length=(\d+)\)", text)
    if not m:
        raise ValueError("yosys ltp printed no path length")
    return int(m.group(1))


def synthesize_target(verilog_text: str, top: str, target: str = "generic", *,
                      timing: bool = False, timeout: float = 600,
                      netlist: bool = False) -> TargetCost:
    """Synthesize module ``top`` of ``verilog_text`` for ``target`` and count its cells.

    Parameters
    ----------
    verilog_text : str
        Verilog source holding ``top`` (and the modules it instantiates).
    top : str
        The module to synthesize (a Verilog identifier).
    target : str
        A name of :data:`TARGETS`.
    timing : bool
        Also run the target's delay model on the netlist (xc7: ``sta`` cell
        delays without routing; generic: ``ltp -noff`` gate depth; ice40: the
        gate-depth model too -- its real timing is :func:`fmax_ice40`).
    timeout : float
        Seconds allowed to yosys.
    netlist : bool
        Keep the mapped netlist in the result (``TargetCost.netlist``), so the
        ``sta`` model can be run later on the one design that needs it
        (:func:`sta_from_netlist`: 0.3 s instead of 0.3-0.5 s in every run).

    Returns
    -------
    TargetCost
        The cell counts and score, with ``levels``, ``delay_ns`` and
        ``timing_model`` when ``timing``.

    Raises
    ------
    ValueError
        for an unknown target, a ``top`` that is not an identifier, a missing
        yosys, or a yosys failure (its messages).
    """
    t = get_target(target)
    top = _check_top(top)
    if not isinstance(verilog_text, str):
        raise ValueError("verilog_text: not a str; accepted: Verilog source text")
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "design.v").write_text(verilog_text, encoding="utf-8")
        tail = "; tee -q -o stat.json stat -json"
        if netlist:
            tail += "; write_rtlil net.il"
        if timing and t.timing == "sta":
            tail += "; read_verilog -lib -specify +/xilinx/cells_sim.v; sta"
        elif timing:
            tail += "; ltp -noff"
        what = f"{t.name} synthesis of {top}"
        try:
            out = _yosys(tmp, f"read_verilog design.v; {t.fast_script(top)}{tail}", what,
                         timeout)
        except ValueError as e:   # a primitive only cells_xtra.v declares: the full flow
            if not t.fast or "is not part of the design" not in str(e):
                raise
            out = _yosys(tmp, f"read_verilog design.v; {t.script(top)}{tail}", what, timeout)
        by_type = _stat(tmp, top)
        kept = (Path(tmp) / "net.il").read_text(encoding="utf-8") if netlist else ""
    cost = cost_from_types(t.name, by_type)
    if kept:
        from dataclasses import replace

        cost = replace(cost, netlist=kept)
    if timing and t.timing == "sta":
        levels, ns = _sta(out)
        return _with_timing(cost, levels, ns, "yosys sta: xc7 cell delays, no routing (model)")
    if timing:
        return _with_timing(cost, _ltp(out), None, "yosys ltp -noff: gate depth (model)")
    return cost


def sta_from_netlist(cost: TargetCost, *, timeout: float = 600) -> TargetCost:
    """The ``sta`` delay model of a design synthesized with ``netlist=True``, run
    on its kept netlist (the same figures as ``synthesize_target(...,
    timing=True)`` gives in the synthesis run itself; tested).

    Parameters
    ----------
    cost : TargetCost
        From :func:`synthesize_target` with ``netlist=True`` on a target whose
        delay model is ``sta`` (xc7, xc7-nodsp).
    timeout : float
        Seconds allowed to yosys.

    Returns
    -------
    TargetCost
        ``cost`` with ``levels``, ``delay_ns`` and ``timing_model``.

    Raises
    ------
    ValueError
        ``cost`` has no netlist, its target has no ``sta`` model, or yosys fails.

    Examples
    --------
    >>> sta_from_netlist(cost_from_types("xc7", {"LUT6": 1}))
    Traceback (most recent call last):
    ...
    ValueError: cost: no kept netlist of an xc7 synthesis; accepted: synthesize_target(..., netlist=True) on xc7 or xc7-nodsp
    """
    t = get_target(cost.target)
    if t.timing != "sta" or not cost.netlist:
        raise ValueError("cost: no kept netlist of an xc7 synthesis; accepted: "
                         "synthesize_target(..., netlist=True) on xc7 or xc7-nodsp")
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "net.il").write_text(cost.netlist, encoding="utf-8")
        out = _yosys(tmp, "read_rtlil net.il; read_verilog -lib -specify "
                     "+/xilinx/cells_sim.v; sta", f"{t.name} sta", timeout)
    levels, ns = _sta(out)
    return _with_timing(cost, levels, ns, "yosys sta: xc7 cell delays, no routing (model)")


def _with_timing(cost: TargetCost, levels, ns, model: str) -> TargetCost:
    from dataclasses import replace

    return replace(cost, levels=levels, delay_ns=ns, timing_model=model)


def module_ports(verilog_text: str, top: str, *,
                 timeout: float = 600) -> list[tuple[str, str, int]]:
    """``[(name, "input"|"output", width)]`` of module ``top``, as yosys elaborates it
    (parameters at their defaults), in declaration order.

    Parameters
    ----------
    verilog_text : str
        Verilog source holding ``top``.
    top : str
        The module (a Verilog identifier ``[A-Za-z_][A-Za-z0-9_]*``).
    timeout : float, default 600
        Seconds allowed to yosys.

    Returns
    -------
    list of (str, str, int)
        Each port's name, direction (``"input"`` or ``"output"``) and width in bits.

    Raises
    ------
    ValueError
        when ``top`` is not an identifier, yosys is missing or fails, ``top``
        is missing, a port is ``inout`` or its name is not a plain identifier.
    """
    top = _check_top(top)
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "design.v").write_text(verilog_text, encoding="utf-8")
        _yosys(tmp, f"read_verilog design.v; hierarchy -top {top}; proc; write_json ports.json",
               f"ports of {top}", timeout)
        data = json.loads((Path(tmp) / "ports.json").read_text(encoding="utf-8"))
    mod = data.get("modules", {}).get(top)
    if mod is None:
        raise ValueError(f"yosys found no module {top!r}")
    ports = []
    for name, p in mod.get("ports", {}).items():
        if p.get("direction") not in ("input", "output"):
            raise ValueError(f"port {name!r} of {top} is {p.get('direction')}; accepted: "
                             f"input and output ports")
        if not _ID.fullmatch(name):
            raise ValueError(f"port {name[:40]!r} of {top} is not a plain identifier")
        ports.append((name, p["direction"], len(p["bits"])))
    return ports


#: the name of the register wrapper module :func:`register_wrapper` writes
WRAP = "chebnorm_fmax_wrap"


def register_wrapper(top: str, ports, *, clocked: bool) -> str:
    """A module ``chebnorm_fmax_wrap`` that puts ``top`` between input and output
    registers on a clock ``clk`` (so every path of ``top`` is register to
    register); with ``clocked`` the module's own 1-bit input ``clk`` gets the clock.

    Parameters
    ----------
    top : str
        The wrapped module's name (a Verilog identifier).
    ports : iterable of (str, str, int)
        Its ports as :func:`module_ports` lists them.
    clocked : bool
        ``top`` has a 1-bit input ``clk`` of its own, driven by the wrapper's clock.

    Returns
    -------
    str
        The Verilog text of the wrapper (no trailing newline), printed from
        its netlist (:func:`wrapper_netlist`): inputs concatenated into
        ``pin_i``, outputs into ``pin_o``, in port order.

    Raises
    ------
    ValueError
        ``top`` is not an identifier, ``clocked`` without a 1-bit input
        ``clk``, or no input or no output port (besides ``clk``).

    Examples
    --------
    >>> print(register_wrapper("m", [("x", "input", 2), ("y", "output", 3)], clocked=False))
    module chebnorm_fmax_wrap (
        input  wire clk,
        input  wire [1:0] pin_i,
        output wire [2:0] pin_o
    );
        wire [2:0] out_w;
        reg [1:0] in_r;
        reg [2:0] out_r;
        always @(posedge clk) begin
            in_r <= pin_i;
            out_r <= out_w;
        end
        m dut (.x(in_r[1:0]), .y(out_w[2:0]));
        assign pin_o = out_r;
    endmodule
    """
    top = _check_top(top)
    ins = [(n, w) for n, d, w in ports if d == "input" and not (clocked and n == "clk")]
    outs = [(n, w) for n, d, w in ports if d == "output"]
    if clocked and not any(n == "clk" and d == "input" and w == 1 for n, d, w in ports):
        raise ValueError(f"module {top} has no 1-bit input clk; accepted: clocked=True only "
                         f"for a module clocked by an input named clk")
    if not ins or not outs:
        raise ValueError(f"module {top} needs an input and an output port to be timed")
    return netlist.verilog(wrapper_netlist(top, ins, outs, clocked=clocked)).rstrip("\n")


def wrapper_netlist(top: str, ins, outs, *, clocked: bool) -> netlist.Module:
    """The netlist of :func:`register_wrapper`: ports ``clk``, ``pin_i``,
    ``pin_o``; registers ``in_r`` and ``out_r``; the instance ``dut`` of ``top``.

    Parameters
    ----------
    top : str
        The wrapped module's name (an identifier).
    ins, outs : list of (str, int)
        Its input ports (without ``clk``) and output ports, name and width, in order.
    clocked : bool
        ``top``'s input ``clk`` is connected to the clock.

    Returns
    -------
    chebnorm.hw.hdl.netlist.Module
        The wrapper (printable in Verilog and VHDL).

    Examples
    --------
    >>> m = wrapper_netlist("m", [("x", 2)], [("y", 3)], clocked=False)
    >>> [p.signal.name for p in m.ports]
    ['clk', 'pin_i', 'pin_o']
    """
    nl = netlist
    wi, wo = sum(w for _, w in ins), sum(w for _, w in outs)
    clk = nl.Signal("clk", 1, logic=True, scalar=True)
    pin_i, pin_o = nl.Signal("pin_i", wi, logic=True), nl.Signal("pin_o", wo, logic=True)
    in_r, out_w = nl.Signal("in_r", wi, logic=True), nl.Signal("out_w", wo, logic=True)
    out_r = nl.Signal("out_r", wo, logic=True)
    conns, lo = [], 0
    for n, w in ins:
        conns.append((n, "input", w, nl.Slice(in_r, lo + w - 1, lo)))
        lo += w
    lo = 0
    for n, w in outs:
        conns.append((n, "output", w, nl.Slice(out_w, lo + w - 1, lo)))
        lo += w
    if clocked:
        conns.insert(0, ("clk", "input", 1, clk))
    return nl.Module(WRAP, wi, wo, ports=(nl.Port(clk), nl.Port(pin_i), nl.Port(pin_o, True)),
                     statements=[nl.Declare(out_w),
                                 nl.Registers(((in_r, pin_i), (out_r, out_w))),
                                 nl.Instance(top, "dut", tuple(conns)),
                                 nl.Output(out_r, port=pin_o)])


#: user I/O pins of the iCE40 HX8K in the ct256 package
ICE40_IO = 206


def fmax_ice40(verilog_text: str, top: str, *, clocked: bool = False, freq_mhz: float = 100.0,
               seed: int = 1, timeout: float = 900) -> float:
    """Fmax in MHz of module ``top`` after place and route on an iCE40 HX8K
    (``ct256``) by nextpnr-ice40: the module between input and output
    registers (:func:`register_wrapper`), synthesized by ``synth_ice40``;
    the figure is nextpnr's "Max frequency" of the clock (its ``--report``).

    ``freq_mhz`` is the target nextpnr's timing-driven placement aims at
    (missing it is not an error here: the achieved figure is returned);
    ``seed`` fixes the placer (same seed, same result; seeds 1 and 2 gave 25.2
    and 23.1 MHz for a 16-bit degree-2 design of 1/sqrt(1 + 3x)).

    Parameters
    ----------
    verilog_text : str
        Verilog source holding ``top``.
    top : str
        The module to place and route (a Verilog identifier).
    clocked : bool, default False
        ``top`` is clocked by its own 1-bit input ``clk`` (see
        :func:`register_wrapper`).
    freq_mhz : float, default 100.0
        The frequency nextpnr aims at, ``0 < freq_mhz <= 1000``.
    seed : int, default 1
        The placer's seed, ``0 .. 2**31 - 1``.
    timeout : float, default 900
        Seconds allowed to each of yosys and nextpnr-ice40.

    Returns
    -------
    float
        The achieved Fmax in MHz (the slowest clock's, of nextpnr's report).

    Raises
    ------
    ValueError
        ``freq_mhz`` or ``seed`` out of range, or yosys or nextpnr-ice40
        missing or failing (e.g. the design does not fit the HX8K, or needs
        more than :data:`ICE40_IO` = 206 I/O pins).
    """
    if isinstance(freq_mhz, bool) or not isinstance(freq_mhz, (int, float)) or \
            not 0 < freq_mhz <= 1000:
        raise ValueError(f"freq_mhz {freq_mhz!r} is out of range; accepted: 0 < MHz <= 1000")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2 ** 31:
        raise ValueError(f"seed {seed!r} is out of range; accepted: an integer 0 .. 2^31 - 1")
    ports = module_ports(verilog_text, top)
    wrapper = register_wrapper(top, ports, clocked=clocked)
    pins = 1 + sum(w for n, _, w in ports if not (clocked and n == "clk"))
    if pins > ICE40_IO:
        raise ValueError(f"module {top} needs {pins} I/O pins; accepted: at most {ICE40_IO} "
                         f"(iCE40 HX8K ct256)")
    pnr = require("nextpnr-ice40", "this step")
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "design.v").write_text(verilog_text + "\n" + wrapper + "\n",
                                            encoding="utf-8")
        _yosys(tmp, f"read_verilog design.v; synth_ice40 -top {WRAP} -json ice40.json",
               f"ice40 synthesis of {top}", timeout)
        _run([pnr, "--hx8k", "--package", "ct256", "--json", "ice40.json", "--freq",
              f"{float(freq_mhz):g}", "--seed", str(seed), "--timing-allow-fail", "--report",
              "report.json", "-q"], tmp, f"nextpnr-ice40 on {top}", timeout)
        rep = json.loads((Path(tmp) / "report.json").read_text(encoding="utf-8"))
    fmax = rep.get("fmax", {})
    if not fmax:
        raise ValueError(f"nextpnr-ice40 reported no clock frequency for {top}")
    return float(min(v["achieved"] for v in fmax.values()))


def target_figures(verilog_text: str, top: str, target: str, *, clocked: bool = False,
                   latency: int = 0, cost: TargetCost | None = None) -> dict:
    """Everything ``hw report --target`` and ``design --target`` print of module
    ``top`` on ``target``: the :class:`TargetCost` fields, the timing (ice40:
    nextpnr-ice40 Fmax, ``fmax_source`` "nextpnr-ice40"; xc7: the ``sta``
    cell-delay model, ``fmax_mhz`` labelled "model" (no routing); generic: the
    gate depth only) and the latency in clock cycles; ``line`` and ``timing``
    are the text lines. ``cost``: this module's :func:`synthesize_target` on
    ``target`` with ``timing``, when already known (not synthesized again).

    Parameters
    ----------
    verilog_text : str
        Verilog source holding ``top``.
    top : str
        The module (a Verilog identifier).
    target : str
        One of :func:`target_names`.
    clocked : bool, default False
        ``top`` has its own 1-bit input ``clk`` (ice40 Fmax only).
    latency : int, default 0
        The module's latency in clock cycles, as reported.
    cost : TargetCost, optional
        This module's synthesis on ``target`` with timing; used when its
        ``target`` matches and it has ``levels``, else the module is
        synthesized again.

    Returns
    -------
    dict
        :meth:`TargetCost.as_dict` plus ``latency_cycles``, ``fmax_mhz``
        (float, or None on ``generic`` or without a delay), ``fmax_source``,
        ``line`` and ``timing`` (the two text lines).

    Raises
    ------
    ValueError
        An unknown target, a bad ``top``, or a tool missing or failing
        (:func:`synthesize_target`, :func:`fmax_ice40`).
    """
    t = get_target(target)
    if cost is not None and cost.target == t.name and cost.levels is None and cost.netlist \
            and t.timing == "sta":
        cost = sta_from_netlist(cost)
    if cost is None or cost.target != t.name or cost.levels is None:
        cost = synthesize_target(verilog_text, top, t.name, timing=True)
    d = cost.as_dict()
    d["latency_cycles"] = int(latency)
    if t.timing == "nextpnr":
        d["fmax_mhz"] = round(fmax_ice40(verilog_text, top, clocked=clocked), 2)
        d["fmax_source"] = "nextpnr-ice40: iCE40 HX8K ct256, placed and routed, seed 1"
        timing = f"Fmax {d['fmax_mhz']:.2f} MHz ({d['fmax_source']})"
    elif t.timing == "sta":
        d["fmax_mhz"] = round(1000.0 / cost.delay_ns, 2) if cost.delay_ns else None
        d["fmax_source"] = "model: yosys sta, Artix-7 cell delays without routing (optimistic)"
        timing = (f"Fmax ~ {d['fmax_mhz']:.2f} MHz ({d['fmax_source']}; {cost.delay_ns:.3f} ns "
                  f"over {cost.levels} cells)")
    else:
        d["fmax_mhz"], d["fmax_source"] = None, "none: generic cells have no device"
        timing = f"{cost.levels} gate levels (model: yosys ltp -noff; no device, no MHz)"
    timing += f", latency {int(latency)} cycles"
    d["line"], d["timing"] = cost.line(), timing
    return d
