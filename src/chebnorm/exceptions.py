"""Every public exception and warning class of chebnorm, in one module.

The floor of the layer rule (:data:`chebnorm.LAYERS`): every stage may import
this module, and it imports nothing of chebnorm. The stages re-export the
classes where they were first defined (``chebnorm.approx.FitWarning is
chebnorm.exceptions.FitWarning``), so either import works.

Errors a user can fix derive from ``ValueError`` (the command line prints them
as one line and exits with status 2); warnings derive from ``UserWarning`` or
``DeprecationWarning`` and are issued with ``warnings.warn``.

* :class:`FitWarning` -- a fit or quantization that is not what it claims.
* :class:`ChebnormDeprecationWarning` -- an old spelling that still works.
* :class:`FrequencyWarning` -- an asked clock frequency that was not reached.
* :class:`NumbaCompileWarning` -- numba is compiling the raster kernels.
* :class:`UndefinedError` -- a function without a value at a point.
* :class:`SegmentError` -- a segment that cannot be certified.
* :class:`WriteError` -- a destination that cannot be written.
* :class:`UsageError` -- a command-line error found by the CLI itself.
* :class:`ToolMissing`, :class:`ToolFailed`, :class:`ToolTimeout` -- an
  external tool (gcc, sollya, gappa, iverilog, ghdl, yosys, ...) that is not
  installed, exited with an error, or ran past its time limit
  (:mod:`chebnorm.core.tools` finds and runs them).
* :class:`FrameUnsupported` -- a frame a raster engine cannot draw in one go.

>>> import chebnorm.approx, chebnorm.exceptions
>>> chebnorm.approx.FitWarning is chebnorm.exceptions.FitWarning
True
"""

from __future__ import annotations

# for the base class of ToolTimeout only (code that caught the standard library's
# timeout still does); chebnorm.core.tools is where tools are found and run
import subprocess

__all__ = ["FitWarning", "ChebnormDeprecationWarning", "FrequencyWarning", "NumbaCompileWarning",
           "UndefinedError", "SegmentError", "WriteError", "UsageError", "ToolMissing",
           "ToolFailed", "ToolTimeout", "FrameUnsupported"]


# -- warnings ---------------------------------------------------------------------------------

class FitWarning(UserWarning):
    """A fit or a quantization that is not what it claims to be: the Remez
    exchange did not converge, a minimax fit's error exceeds that of a
    simpler polynomial, or a certified bound missed its tightness. The same
    text is recorded in the table's ``provenance["warnings"]``
    (:func:`chebnorm.approx.warnings_of`); ``chebnorm fit`` prints it as
    ``chebnorm: warning: ...``."""


class ChebnormDeprecationWarning(DeprecationWarning):
    """An old spelling that still works in this release and goes in the next: the
    message names the new one (``fit(frac_bits=)`` is ``fit(coef_frac_bits=)``)."""


class FrequencyWarning(UserWarning):
    """The asked clock frequency was not reached (the highest reached is named).

    >>> issubclass(FrequencyWarning, UserWarning)
    True
    """


class NumbaCompileWarning(UserWarning):
    """numba is compiling the raster engine's kernels (the first render of a kind
    on this machine; numba caches them on disk for later processes). Issued once
    per process, and only when the compile takes a while
    (:data:`chebnorm.raster.engines.numba.jit.ANNOUNCE_AFTER`); ``render``
    compiles before starting its clock, so its ``seconds`` do not count it
    (``RenderResult.compile_seconds`` does)."""


# -- errors -------------------------------------------------------------------------------------

class UndefinedError(ValueError, ZeroDivisionError):
    """The function has no value at a point (a ValueError for callers, and
    still a ZeroDivisionError for code that catches that).

    Examples
    --------
    >>> import mpmath
    >>> from chebnorm.approx.expr import parse_function
    >>> parse_function("exp(-1/x**2)").mpmath(mpmath.mpf(0))
    Traceback (most recent call last):
    ...
    chebnorm.exceptions.UndefinedError: exp(-1/x**2) is undefined at x = 0.0 (a division by zero); accepted: ...
    """


class SegmentError(ValueError):
    """``g_s`` cannot be certified on segment ``segment`` (the message says why).

    Parameters
    ----------
    segment : int
        The segment's index.
    message : str
        Why it cannot be certified.
    """

    def __init__(self, segment: int, message: str):
        super().__init__(message)
        self.segment = segment


class WriteError(OSError, ValueError):
    """A destination chebnorm cannot write: the message names the path the
    caller gave (never a temporary file) and the reason. It is an ``OSError``
    and a ``ValueError``, so the command line reports it as a user error
    (exit status 2, one line).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from chebnorm.core.files import write_atomic
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     try:
    ...         write_atomic(pathlib.Path(tmp) / "missing" / "t.txt", "x")
    ...     except WriteError as exc:
    ...         print(isinstance(exc, ValueError), isinstance(exc, OSError))
    True True
    """


class UsageError(ValueError):
    """A user error detected by the CLI itself."""


class ToolMissing(RuntimeError, ValueError):
    """An optional tool or driver is not available: one line naming it and how
    to install it (:func:`chebnorm.core.tools.require`).

    A ``RuntimeError`` (as it always was) and a ``ValueError`` (the command
    line reports it as one line, exit status 2, as it did the ``ValueError``
    the hardware steps raised for a missing tool).

    Examples
    --------
    >>> issubclass(ToolMissing, RuntimeError), issubclass(ToolMissing, ValueError)
    (True, True)
    """


class ToolFailed(RuntimeError, ValueError):
    """An external tool exited with a non-zero status: one line naming the tool,
    the status and the last lines of its standard error.

    A ``RuntimeError`` and a ``ValueError``, as :class:`ToolMissing`.

    Parameters
    ----------
    tool : str
        The tool's name as the user knows it (``"sollya"``, ``"ghdl -a"``).
    returncode : int
        Its exit status.
    stderr : str, optional
        What it printed on standard error (or its messages, where the tool
        prints them on standard output); the last lines (at most
        :attr:`TAIL` characters, joined into one line) are quoted.
    subject : str, optional
        What it was run on (a module, an entity), named in the message.

    Examples
    --------
    >>> str(ToolFailed("sollya", 3, "line 1\\nerror: bad\\n"))
    'sollya failed (exit status 3): line 1 error: bad'
    >>> str(ToolFailed("yosys", 1, "ERROR: syntax error", subject="top"))
    'yosys failed on top (exit status 1): ERROR: syntax error'
    >>> ToolFailed("gappa", 1).returncode
    1
    """

    #: characters of the tool's standard error quoted at most
    TAIL = 300

    def __init__(self, tool: str, returncode: int, stderr: str = "", *, subject: str = ""):
        tail = " ".join(str(stderr or "")[-self.TAIL:].split())
        on = f" on {subject}" if subject else ""
        super().__init__(f"{tool} failed{on} (exit status {returncode})"
                         + (f": {tail}" if tail else ""))
        self.tool = tool
        self.returncode = returncode
        self.stderr = stderr
        self.subject = subject


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


class FrameUnsupported(Exception):
    """Raised by :meth:`chebnorm.raster.engines.base.Engine.phong_frame` when the
    frame it was asked for is one whose reference bytes it cannot promise; the
    caller draws the frame step by step."""
