"""Running the generated Verilog: Icarus Verilog (:func:`simulate`) and Yosys
(:func:`synthesize`), each in a private temporary folder.

The Verilog text itself comes from :mod:`chebnorm.hw.hdl` (the printers of
every design and language).
"""

from __future__ import annotations

import os
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path
from chebnorm.core.tools import require, run_tool
from chebnorm.exceptions import ToolFailed


# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []


@dataclass(frozen=True)
class SimResult:
    """Outcome of an Icarus Verilog run of the test bench.

    Attributes
    ----------
    passed : bool
        True when the bench printed ``PASS`` (every vector matched).
    vectors : int
        How many input vectors the bench checked.
    mismatches : int
        How many outputs differed from the model.
    line : str
        The bench's verdict line, e.g. ``"PASS: 256 vectors, 0 mismatches (NAME)"``.
    """

    passed: bool
    vectors: int
    mismatches: int
    line: str


@dataclass(frozen=True)
class SynthResult:
    """``yosys synth; stat`` of one module: total cells and cells by type.

    Attributes
    ----------
    cells : int
        Total number of cells after ``synth``.
    by_type : dict of str to int
        Cell type (``$_AND_``, ``$_DFF_P_``, ...) -> count.
    """

    cells: int
    by_type: dict


def _need(tool: str) -> str:
    return require(tool, "this step")


def tool_env() -> dict[str, str]:
    """The environment for a tool run in a private temporary folder (``cwd``):
    the caller's, with ``TMPDIR`` set to ``"."`` and ``TMP``/``TEMP`` removed.

    yosys pastes ``TMPDIR`` into the shell command that starts ABC, and
    Icarus Verilog into the ``sh`` command lines of its preprocessor and
    compiler (inside double quotes): a ``TMPDIR`` holding ``;`` or ``"``
    would run commands. The relative ``"."`` (the private folder) carries no
    text from the caller.

    >>> tool_env()["TMPDIR"], "TMP" in tool_env()
    ('.', False)

    Returns
    -------
    dict of str to str
        A copy of ``os.environ`` with ``TMPDIR="."`` and without ``TMP``/``TEMP``.
    """
    env = {k: v for k, v in os.environ.items() if k not in ("TMPDIR", "TMP", "TEMP")}
    env["TMPDIR"] = "."
    return env


def simulate(directory, design, timeout: float = 600) -> SimResult:
    """Compile and run ``tb_M.v`` and ``M.v`` in ``directory`` with Icarus Verilog;
    ``design``: anything with a ``module_name`` (a design, a unit), or the name ``M``.

    The two files are compiled from copies in a private temporary folder
    (``cwd``, with :func:`tool_env`), so no path and no environment variable
    reaches Icarus's internal shell commands; the bench then runs in
    ``directory`` (where its vector file is).

    Parameters
    ----------
    directory : str or os.PathLike
        The folder holding ``M.v``, ``tb_M.v`` and the bench's vector file.
    design : object or str
        Anything with a ``module_name`` attribute, or the module name ``M`` itself.
    timeout : float, default 600
        Seconds allowed for the compilation and for the run, each.

    Returns
    -------
    SimResult
        The bench's verdict (``passed`` False when some vector mismatched).

    Raises
    ------
    ValueError
        If iverilog or vvp is not installed, a file cannot be read, iverilog fails, or
        the bench prints no PASS/FAIL line.
    chebnorm.exceptions.ToolTimeout
        If a step runs longer than ``timeout`` (a ``ValueError``
        and a ``subprocess.TimeoutExpired``; one line naming the tool and the limit).
    """
    iverilog, vvp = _need("iverilog"), _need("vvp")
    d = Path(directory)
    name = design if isinstance(design, str) else design.module_name
    with tempfile.TemporaryDirectory() as tmp:
        for src, dst in ((f"tb_{name}.v", "tb.v"), (f"{name}.v", "dut.v")):
            try:
                (Path(tmp) / dst).write_bytes((d / src).read_bytes())
            except OSError as exc:
                raise ValueError(f"cannot read {str(d / src)!r}: {exc.strerror}") from None
        comp = run_tool([iverilog, "-g2005", "-Wall", "-o", "sim.vvp", "tb.v", "dut.v"],
                        tool="iverilog", timeout=timeout, cwd=tmp, env=tool_env())
        if comp.returncode != 0:
            raise ToolFailed("iverilog", comp.returncode, comp.stderr, subject=name)
        run = run_tool([vvp, "-n", str(Path(tmp) / "sim.vvp")], tool="vvp", timeout=timeout,
                       cwd=d)
    m = re.search(r"^(PASS|FAIL): (\d+) vectors, (\d+) mismatches.*$", run.stdout, re.M)
    if not m:
        raise ValueError(f"the test bench of {name} printed no PASS/FAIL line: "
                         f"{' '.join((run.stdout + run.stderr).split())[:300]}")
    return SimResult(passed=m.group(1) == "PASS", vectors=int(m.group(2)),
                     mismatches=int(m.group(3)), line=m.group(0))


_TOP = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def synthesize(path, top: str, timeout: float = 600) -> SynthResult:
    """Synthesize module ``top`` of the Verilog file ``path`` with yosys
    (``synth -top TOP; stat``) and read the cell count.

    No path and no environment variable ever reaches yosys's command text:
    the file is copied into a fresh temporary folder as ``design.v`` and
    yosys runs there (``cwd``, with :func:`tool_env`: its ABC step builds a
    shell command from ``TMPDIR``) on the fixed script
    ``read_verilog design.v; synth -top TOP; stat``, ``top`` an identifier.

    Parameters
    ----------
    path : str or os.PathLike
        The Verilog file.
    top : str
        The module to synthesize, a Verilog identifier ``[A-Za-z_][A-Za-z0-9_]*``.
    timeout : float, default 600
        Seconds allowed for yosys.

    Returns
    -------
    SynthResult
        The cell counts of ``stat``.

    Raises
    ------
    ValueError
        when ``top`` is not a Verilog identifier, yosys is missing or fails
        (its messages), or prints no cell count.
    """
    if not isinstance(top, str) or not _TOP.fullmatch(top):
        raise ValueError(f"top: {str(top)[:60]!r} is not a module name; accepted: a Verilog "
                         f"identifier [A-Za-z_][A-Za-z0-9_]*")
    yosys = _need("yosys")
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "design.v").write_bytes(Path(path).read_bytes())
        proc = run_tool([yosys, "-p", f"read_verilog design.v; synth -top {top}; stat"],
                        tool="yosys", timeout=timeout, cwd=tmp, env=tool_env())
    if proc.returncode != 0:  # yosys prints its errors on both streams
        raise ToolFailed("yosys", proc.returncode, proc.stdout[-300:] + "\n" + proc.stderr,
                         subject=top)
    text = proc.stdout
    start = text.rfind("Number of cells:")
    if start < 0:
        raise ValueError(f"yosys printed no cell count for {top}")
    cells = int(text[start:].split(":")[1].split()[0])
    by_type = {}
    for m in re.finditer(r"^\s+(\$\S+)\s+(\d+)\s*$", text[start:], re.M):
        by_type[m.group(1)] = int(m.group(2))
    return SynthResult(cells=cells, by_type=by_type)


def synthesize_text(verilog: str, top: str, timeout: float = 600) -> SynthResult:
    """:func:`synthesize` of Verilog text (yosys reads it in a temporary
    folder, by a fixed relative name).

    Parameters
    ----------
    verilog : str
        The Verilog source.
    top : str
        The module to synthesize, a Verilog identifier.
    timeout : float, default 600
        Seconds allowed for yosys.

    Returns
    -------
    SynthResult
        The cell counts of ``stat``.

    Raises
    ------
    ValueError
        As :func:`synthesize`: ``top`` not an identifier, yosys missing or failing.
    """
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "input.v"
        f.write_text(verilog, encoding="utf-8")
        return synthesize(f, top, timeout)
