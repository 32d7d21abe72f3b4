"""Finding and running an external tool (gcc, sollya, gappa, iverilog, vvp,
ghdl, yosys, nextpnr, glslangValidator) with a time limit: the one module that
looks tools up on ``PATH`` and starts processes.

:func:`which` finds a tool (None when it is not installed); :func:`require`
finds it or raises one :class:`~chebnorm.exceptions.ToolMissing` naming the
tool and the Debian package that installs it.

:func:`run_tool` is :func:`subprocess.run` with an argument list (never a
shell), output captured as text, and a time limit; a tool that runs longer
is stopped and reported as one :class:`~chebnorm.exceptions.ToolTimeout`
naming the tool and the limit; with ``check=True`` a non-zero exit status is
raised as one :class:`~chebnorm.exceptions.ToolFailed` (the tool, the status,
the end of its standard error). ``ToolTimeout`` is a ``ValueError`` (the
command line prints it as one line and exits with status 2, as for a tool
that fails) and a ``subprocess.TimeoutExpired`` (code that caught the latter
still does). The three classes live in :mod:`chebnorm.exceptions`.

>>> import sys
>>> run_tool([sys.executable, "-c", "print(6 * 7)"], tool="python", timeout=60).stdout
'42\\n'
>>> run_tool([sys.executable, "-c", "import time; time.sleep(5)"], tool="python", timeout=0.2)
Traceback (most recent call last):
...
chebnorm.exceptions.ToolTimeout: python did not finish within its time limit of 0.2 s; ...
"""

from __future__ import annotations

import contextlib
import multiprocessing
import shutil
import subprocess

from chebnorm.exceptions import ToolFailed, ToolMissing, ToolTimeout

from .progress import progress_bar

#: the Debian package that installs each tool chebnorm runs (:func:`require`'s message)
DEBIAN_PACKAGES = {
    "gcc": "gcc", "clang": "clang", "sollya": "sollya", "gappa": "gappa",
    "iverilog": "iverilog", "vvp": "iverilog", "ghdl": "ghdl", "yosys": "yosys",
    "nextpnr-ice40": "nextpnr-ice40", "icepack": "fpga-icestorm",
    "glslangValidator": "glslang-tools",
}


def which(name: str) -> str | None:
    """The path of the executable ``name`` on ``PATH``, or None when it is not
    installed (the one look-up of a tool in chebnorm).

    Parameters
    ----------
    name : str
        The executable's name (``"gcc"``, ``"yosys"``).

    Returns
    -------
    str or None
        Its full path, or None.

    Examples
    --------
    >>> which("no-such-tool-chebnorm") is None
    True
    """
    if not isinstance(name, str) or not name or "/" in name or "\\" in name:
        raise ValueError(f"name = {str(name)[:60]!r} is not a tool name; accepted: an executable's "
                         f"name without a folder (gcc, yosys)")
    return shutil.which(name)


def require(name: str, why: str = "") -> str:
    """The path of the executable ``name``, or :class:`~chebnorm.exceptions.ToolMissing`
    (one line naming the tool, what needs it and the Debian package to install).

    Parameters
    ----------
    name : str
        The executable's name.
    why : str, optional
        What needs it (``"the VHDL simulation"``), put in the message.

    Returns
    -------
    str
        Its full path.

    Raises
    ------
    chebnorm.exceptions.ToolMissing
        When ``name`` is not on ``PATH``.

    Examples
    --------
    >>> require("no-such-tool-chebnorm", "a doctest")
    Traceback (most recent call last):
    ...
    chebnorm.exceptions.ToolMissing: no-such-tool-chebnorm is not installed (needed for a doctest); accepted: install it (apt-get install no-such-tool-chebnorm)
    """
    exe = which(name)
    if exe is None:
        package = DEBIAN_PACKAGES.get(name, name)
        need = f" (needed for {' '.join(str(why).split())})" if why else ""
        raise ToolMissing(f"{name} is not installed{need}; accepted: install it "
                          f"(apt-get install {package})")
    return exe




def run_tool(argv, *, tool: str, timeout: float, check: bool = False,
             **kwargs) -> subprocess.CompletedProcess:
    """Run ``argv`` (a list: no shell) with output captured as text and stdin
    closed unless ``input`` is given; a run longer than ``timeout`` seconds is
    stopped and raised as :class:`~chebnorm.exceptions.ToolTimeout`.

    Parameters
    ----------
    argv : list of str
        The program and its arguments.
    tool : str
        The tool's name for the message (``"gcc"``, ``"ghdl -a"``).
    timeout : float
        Seconds allowed (> 0).
    check : bool, default False
        Raise :class:`~chebnorm.exceptions.ToolFailed` when the exit status is
        not 0 (else the caller judges it).
    **kwargs
        Further :func:`subprocess.run` arguments (``cwd``, ``env``, ``input``).

    Returns
    -------
    subprocess.CompletedProcess
        With ``stdout`` and ``stderr`` as text; the exit status is the
        caller's to judge unless ``check``.

    Raises
    ------
    chebnorm.exceptions.ToolTimeout
        When the tool runs longer than ``timeout``.
    chebnorm.exceptions.ToolFailed
        With ``check``, when the exit status is not 0.

    Examples
    --------
    >>> import sys
    >>> run_tool([sys.executable, "-c", "import sys; sys.exit(3)"], tool="python",
    ...          timeout=60).returncode
    3
    """
    if isinstance(argv, (str, bytes)):
        raise ValueError("argv must be a list of arguments (no shell); accepted: a list of str")
    if "input" not in kwargs:
        kwargs.setdefault("stdin", subprocess.DEVNULL)
    # on a terminal, say which tool runs (synthesis and place and route take a minute);
    # a worker process stays quiet: the parent's bar is on the same terminal
    quiet = multiprocessing.parent_process() is not None
    with progress_bar(1, f"chebnorm: running {tool}", unit="run") if not quiet \
            else contextlib.nullcontext() as bar:
        try:
            done = subprocess.run(list(argv), capture_output=True, text=True, timeout=timeout,
                                  **kwargs)
        except subprocess.TimeoutExpired as exc:
            raise ToolTimeout(tool, exc.cmd, timeout) from None
        if bar is not None:
            bar.update(1)
    if check and done.returncode != 0:
        raise ToolFailed(tool, done.returncode, done.stderr)
    return done
