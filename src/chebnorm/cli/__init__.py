"""Stage 5: the ``chebnorm`` command line.

Each subcommand lives in its own module of this package and exposes
``register(subparsers)``, which adds its parser and sets ``func`` to a
function ``(args) -> int``. Errors the user can fix (``ValueError``,
``OSError``, among them :class:`chebnorm.core.files.WriteError` for an
output that cannot be written) end the program with status 2 and one line on
stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import warnings

from chebnorm.exceptions import UsageError

from .common import ascii_float, ascii_int, command_flags

__all__ = ["main", "build_parser", "UsageError"]

#: subcommand modules, in the order ``chebnorm --help`` lists them
SUBCOMMANDS = ("fit", "export", "targets", "methods", "render", "render_sweep", "hw", "design",
               "repro", "verify", "correctly_rounded")


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # every ``type=int`` / ``type=float`` reads ASCII digits only (Python's own
        # readers take other scripts' digits: int("\u0663") == 3)
        self.register("type", int, ascii_int)
        self.register("type", float, ascii_float)

    def error(self, message):  # argparse's own errors: one line, status 2
        # "chebnorm: error: " already starts the line: name a subcommand, not the program
        raise UsageError(message if self.prog == "chebnorm" else f"{self.prog}: {message}")


def build_parser() -> argparse.ArgumentParser:
    """The ``chebnorm`` argument parser, one subcommand per task (see the
    manual's command-line page, docs/cli.md).

    Returns
    -------
    argparse.ArgumentParser
        The parser, with one subparser per module of :data:`SUBCOMMANDS` (each
        sets ``func``, the function that runs it); its ``error`` raises
        :class:`UsageError` instead of exiting.

    >>> build_parser().prog
    'chebnorm'
    """
    from chebnorm import __version__

    parser = _Parser(prog="chebnorm", description="Certified polynomial fits and error analysis "
                     "for fast normal-vector normalization in Phong shading.")
    parser.add_argument("--version", action="version", version=f"chebnorm {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in SUBCOMMANDS:
        importlib.import_module(f"chebnorm.cli.{name}").register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line on ``argv`` (default ``sys.argv[1:]``) and return
    the exit status: 0 on success, 2 with one line on stderr on bad input, 141
    and nothing on stderr when the reader of the output went away (``| head``),
    as a program that SIGPIPE ends.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program name, e.g. ``["fit", "1/sqrt(x)",
        "--interval", "0.5", "1", "--degree", "3"]``; default (None):
        ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status: 0 on success; what the subcommand returns (1 when a
        check it runs fails, e.g. ``verify`` or ``hw verilog --simulate``); 2 on
        bad input (a ``ValueError`` or ``OSError``, reported as one line on stderr,
        never a traceback); 141 when stdout was closed early.

    >>> main(["no-such-command"])
    2
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    with warnings.catch_warnings():   # restores the caller's showwarning and filters
        warnings.showwarning = _one_line_warnings(warnings.showwarning)
        return _main(argv)


def _one_line_warnings(previous):
    """A ``warnings.showwarning`` that prints chebnorm's own warnings (FitWarning,
    FrequencyWarning, ...) as one ``chebnorm: warning:`` line each, once per command,
    and hands every other warning to ``previous``."""
    seen: set[str] = set()

    def show(message, category, filename, lineno, file=None, line=None):
        if not category.__module__.startswith("chebnorm"):
            return previous(message, category, filename, lineno, file, line)
        text = " ".join(str(message).split())
        if text not in seen:
            seen.add(text)
            print(f"chebnorm: warning: {text}", file=sys.stderr)
        return None
    return show


def _main(argv: list[str]) -> int:
    flags = None   # the command's flags by Python name, once it is parsed
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        flags = command_flags(parser, args)
        args.argv = ["chebnorm", *argv]
        return int(args.func(args) or 0)
    except BrokenPipeError:
        # the rest of the output has no reader: stop quietly, and point stdout at
        # /dev/null so the interpreter's flush at exit does not raise again
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141
    except (ValueError, OSError) as exc:
        text = str(exc)
        if isinstance(exc, OSError) and exc.strerror and exc.filename and "Errno" in text:
            text = f"{exc.filename}: {exc.strerror}"  # no "[Errno 13]" noise
        message = " ".join(text.split()) or type(exc).__name__
        from .fit import cli_words  # the library's ``in_bits``, ``basis='monomial'`` as flags

        message = cli_words(message, flags or {})
        print(f"chebnorm: error: {message}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("chebnorm: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
