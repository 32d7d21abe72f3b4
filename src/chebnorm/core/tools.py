"""Running an external tool (gcc, sollya, gappa, iverilog, vvp, ghdl, yosys,
nextpnr, glslangValidator) with a time limit.

:func:`run_tool` is :func:`subprocess.run` with an argument list (never a
shell), output captured as text, and a time limit; a tool that runs longer
is stopped and reported as one :class:`ToolTimeout` naming the tool and the
limit. ``ToolTimeout`` is a ``ValueError`` (the command line prints it as one
line and exits with status 2, as for a tool that fails) and a
``subprocess.TimeoutExpired`` (code that caught the latter still does).

>>> import sys
>>> run_tool([sys.executable, "-c", "print(6 * 7)"], tool="python", timeout=60).stdout
'42\\n'
>>> run_tool([sys.executable, "-c", "import time; time.sleep(5)"], tool="python", timeout=0.2)
Traceback (most recent call last):
...
chebnorm.core.tools.ToolTimeout: python did not finish within its time limit of 0.2 s; ...
"""

from __future__ import annotations

import subprocess

__all__ = ["run_tool", "ToolTimeout"]


class ToolTimeout(subprocess.TimeoutExpired, ValueError):
    """An external tool stopped at its time limit: the message names the tool
    and the limit (one line).

    Parameters
    ----------
    tool : str
        The tool's name as the user knows it (``"gappa"``, ``"ghdl -r"``).
    cmd : list of str
        The argument list that ran.
    timeout : float
        The limit, in seconds.

    Examples
    --------
    >>> str(ToolTimeout("gappa", ["gappa"], 60))[:52]
    'gappa did not finish within its time limit of 60 s; '
    >>> isinstance(ToolTimeout("gappa", ["gappa"], 60), ValueError)
    True
    """

    def __init__(self, tool: str, cmd, timeout: float):
        super().__init__(cmd, timeout)
        self.tool = tool

    def __str__(self) -> str:
        return (f"{self.tool} did not finish within its time limit of {self.timeout:g} s; "
                f"accepted: a smaller problem, or a larger timeout where the function "
                f"takes one")


def run_tool(argv, *, tool: str, timeout: float, **kwargs) -> subprocess.CompletedProcess:
    """Run ``argv`` (a list: no shell) with output captured as text and stdin
    closed unless ``input`` is given; a run longer than ``timeout`` seconds is
    stopped and raised as :class:`ToolTimeout`.

    Parameters
    ----------
    argv : list of str
        The program and its arguments.
    tool : str
        The tool's name for the message (``"gcc"``, ``"ghdl -a"``).
    timeout : float
        Seconds allowed (> 0).
    **kwargs
        Further :func:`subprocess.run` arguments (``cwd``, ``env``, ``input``).

    Returns
    -------
    subprocess.CompletedProcess
        With ``stdout`` and ``stderr`` as text; the exit status is the
        caller's to judge.

    Raises
    ------
    ToolTimeout
        When the tool runs longer than ``timeout``.

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
    try:
        return subprocess.run(list(argv), capture_output=True, text=True, timeout=timeout,
                              **kwargs)
    except subprocess.TimeoutExpired as exc:
        raise ToolTimeout(tool, exc.cmd, timeout) from None
