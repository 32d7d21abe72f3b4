"""The in-process command line for tests that check what reaches stderr.

In a ``python -m chebnorm`` process a Python warning the library lets escape is
printed on stderr, so a test asserting ``err == ""`` (or one line on stderr)
would catch it; in-process, pytest's own warning capture takes it instead.
:func:`run_cli_quiet` records every warning (all categories, every time) while
the command runs and fails when there is one, which is at least as strict as
reading a child's stderr; a traceback escapes :func:`conftest.run_cli` as the
exception itself and fails the test too.
"""

from __future__ import annotations

import warnings

from conftest import CliResult, run_cli


def run_cli_quiet(*argv, cwd=None) -> CliResult:
    """:func:`conftest.run_cli`, failing when the command raises a Python warning."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = run_cli(*argv, cwd=cwd)
    assert not caught, ("a Python warning would reach stderr: "
                        + "; ".join(f"{w.category.__name__}: {w.message} ({w.filename}:{w.lineno})"
                                    for w in caught))
    return result
