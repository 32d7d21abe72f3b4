"""Running the generated VHDL in GHDL (:func:`simulate_vhdl`, VHDL-2008), and
the VHDL files of a :class:`~chebnorm.hw.report.HardwareReport`
(:func:`vhdl_outputs`).

The VHDL text itself comes from :mod:`chebnorm.hw.hdl` (the printers of
every design and language, bit-identical to the Verilog).
"""

from __future__ import annotations

import re
import shutil
import tempfile
from pathlib import Path

from .hdl import hdl_files
from .hdl.vhdl import VHDL_STD
from .run_verilog import SimResult
from chebnorm.core.tools import require, run_tool
from chebnorm.exceptions import ToolFailed
from ._docfrag import hw_doc

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []


def simulate_vhdl(directory, design, timeout: float = 600) -> SimResult:
    """Analyse ``NAME.vhd`` and ``tb_NAME.vhd`` in ``directory`` with GHDL
    (VHDL-2008), elaborate and run the bench; ``design``: a design, or the
    entity name. The bench leaves ``NAME_vhdl_y.hex`` in ``directory``.

    Parameters
    ----------
    directory : str or os.PathLike
        The folder holding ``NAME.vhd``, ``tb_NAME.vhd`` and the bench's vector file.
    design : object or str
        Anything with a ``module_name`` attribute, or the entity name itself.
    timeout : float, default 600
        Seconds allowed for each GHDL step (analyse, elaborate, run).

    Returns
    -------
    SimResult
        The bench's verdict (``passed`` False when some vector mismatched).

    Raises
    ------
    ValueError
        If ghdl is not installed, a GHDL step fails, or the bench prints no PASS/FAIL
        line.
    chebnorm.exceptions.ToolTimeout
        If a step runs longer than ``timeout`` (a ``ValueError``
        and a ``subprocess.TimeoutExpired``; one line naming the tool and the limit).
    """
    ghdl = require("ghdl", "this step")
    d = Path(directory)
    name = design if isinstance(design, str) else design.module_name
    with tempfile.TemporaryDirectory() as work:
        # GHDL runs in a folder of its own: its library (work-obj08.cf) records the paths
        # of the files it analysed, and the user's folder name may hold any character
        w = Path(work)
        for fname in (f"{name}.vhd", f"tb_{name}.vhd", f"{name}.hex"):
            if (d / fname).is_file():
                shutil.copyfile(d / fname, w / fname)
        std = [f"--std={VHDL_STD}"]
        for cmd in ([ghdl, "-a", *std, f"{name}.vhd"], [ghdl, "-a", *std, f"tb_{name}.vhd"],
                    [ghdl, "-e", *std, f"tb_{name}"]):
            proc = run_tool(cmd, tool=f"ghdl {cmd[1]}", timeout=timeout, cwd=w)
            if proc.returncode != 0:
                raise ToolFailed(f"ghdl {cmd[1]}", proc.returncode,
                                 proc.stdout + "\n" + proc.stderr, subject=name)
        run = run_tool([ghdl, "-r", *std, f"tb_{name}", "--ieee-asserts=disable-at-0"],
                       tool="ghdl -r", timeout=timeout, cwd=w)
        if (w / f"{name}_vhdl_y.hex").is_file():   # the bench's outputs, beside its inputs
            shutil.copyfile(w / f"{name}_vhdl_y.hex", d / f"{name}_vhdl_y.hex")
    text = run.stdout + run.stderr
    m = re.search(r"(PASS|FAIL): (\d+) vectors, (\d+) mismatches[^\n]*", text)
    if not m:
        raise ValueError(f"the VHDL test bench of {name} printed no PASS/FAIL line: "
                         f"{' '.join(text.split())[:300]}")
    return SimResult(passed=m.group(1) == "PASS", vectors=int(m.group(2)),
                     mismatches=int(m.group(3)), line=m.group(0))


@hw_doc
def vhdl_outputs(report, *, version: str = "", command: str | None = None,
                 pipelined: bool = False) -> dict[str, str]:
    """File name -> text of the VHDL entity, its bench and the vector file of a
    :class:`~chebnorm.hw.report.HardwareReport` (the VHDL twin of
    :func:`~chebnorm.hw.report.verilog_outputs`); with ``pipelined`` also the
    pipelined entity and its bench (:func:`chebnorm.hw.hdl.hdl_files` in VHDL).

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.report import analyze
    >>> r = analyze(fit_target("dichotomy", 1), 8, 8, coef_frac_bits=12, synth=False, gappa=False)
    >>> sorted(vhdl_outputs(r))
    ['chebnorm_dichotomy_d1.hex', 'chebnorm_dichotomy_d1.vhd', 'tb_chebnorm_dichotomy_d1.vhd']

    Parameters
    ----------
    report : HardwareReport
        The analysed design; its budget goes into the banner.
    %(version)s
    %(files_command)s
    pipelined : bool, default False
        Also write the pipelined entity and its bench.

    Returns
    -------
    dict of str to str
        File name -> file text.
    """
    return hdl_files(report.design, "vhdl", version=version, command=command,
                     budget=report.budget, pipelined=pipelined)
