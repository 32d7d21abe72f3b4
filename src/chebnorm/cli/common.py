"""Helpers shared by the subcommands."""

from __future__ import annotations

import argparse
import json
import shlex
import sys


def command_line(args) -> str:
    """The command that made an output, for provenance banners.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments; their ``argv`` (set by :func:`chebnorm.cli.main`) is
        the full command line, default ``["chebnorm"]`` when absent.

    Returns
    -------
    str
        The words of ``args.argv`` shell-quoted (``shlex.quote``) and joined
        by spaces, e.g. ``"chebnorm fit 'x^2' --degree 3"``.
    """
    return " ".join(shlex.quote(a) for a in getattr(args, "argv", ["chebnorm"]))


def print_json(obj) -> None:
    """Deterministic JSON on stdout: sorted keys, shortest float repr.

    Parameters
    ----------
    obj : object
        A JSON-serializable value (dicts, lists, str, int, finite float, bool,
        None), printed with sorted keys and an indent of 2.

    Raises
    ------
    ValueError
        When ``obj`` holds a NaN or an infinity (``allow_nan=False``).
    TypeError
        When ``obj`` holds a value JSON cannot represent.
    """
    print(json.dumps(obj, sort_keys=True, indent=2, allow_nan=False))


class _DeprecatedFlag(argparse.Action):
    """Stores like the flag it stands for, and says once on stderr that the
    old spelling goes away."""

    def __init__(self, option_strings, dest, new_flag=None, **kwargs):
        self.new_flag = new_flag
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"chebnorm: warning: {option_string} is deprecated and will be removed in the next "
              f"release; use {self.new_flag}", file=sys.stderr)
        setattr(namespace, self.dest, values)


def deprecated_alias(parser, old: str, new: str, dest: str, **kwargs) -> None:
    """Add ``old`` as a deprecated spelling of option ``new`` (same ``dest``,
    same type): it still works for one release and prints one warning line.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The (sub)command's parser, which already has (or will have) ``new``.
    old : str
        The old flag, e.g. ``"--frac-bits"``.
    new : str
        The flag that replaces it, named in the warning.
    dest : str
        The attribute of the parsed namespace both flags store into.
    **kwargs
        Further ``argparse.ArgumentParser.add_argument`` arguments (``type``,
        ``metavar``, ...), as given to ``new``.
    """
    parser.add_argument(old, dest=dest, action=_DeprecatedFlag, new_flag=new,
                        help=f"deprecated spelling of {new}", **kwargs)


def refuse_unused(args, where: str, **flags) -> None:
    """Refuse options given where they do nothing: ``flags`` maps each option
    (``"--log-m"``) to its argparse ``dest``; an option whose value is not None
    was given (its default is None), and the error names it and ``where`` it
    applies (one line, exit 2).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.
    where : str
        Where the options do apply, completing "it applies only ...", e.g.
        ``"with --shading split-gouraud"``.
    **flags : str
        Each option's flag (keyword) mapped to its ``dest`` in ``args``; the
        option counts as given when that attribute exists and is not None.

    Raises
    ------
    ValueError
        When one or more of the options were given, naming them all.

    >>> import argparse
    >>> refuse_unused(argparse.Namespace(q=None), "with --shading split-gouraud", **{"--q": "q"})
    >>> refuse_unused(argparse.Namespace(q=0.1), "with --shading split-gouraud", **{"--q": "q"})
    Traceback (most recent call last):
    ...
    ValueError: --q does nothing here; it applies only with --shading split-gouraud
    """
    given = [flag for flag, dest in flags.items() if getattr(args, dest, None) is not None]
    if given:
        verb = "does" if len(given) == 1 else "do"
        raise ValueError(f"{', '.join(given)} {verb} nothing here; it applies only {where}")


#: defaults of --eta-threshold and --q (None in the parser, so that a given value
#: can be told from the default)
ETA_THRESHOLD = 0.005
Q_THRESHOLD = 1.0 / 255.0


def add_lighting_options(p, engine_help: str) -> None:
    """The options ``render`` and ``render-sweep`` share: ``--half-vector``,
    ``--eta-threshold``, ``--q`` and ``--engine``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The subcommand's parser. ``--eta-threshold`` and ``--q`` default to None
        (so a given value can be told from the defaults :data:`ETA_THRESHOLD` and
        :data:`Q_THRESHOLD`).
    engine_help : str
        The help text of ``--engine`` (auto, numpy or numba; default auto).
    """
    p.add_argument("--half-vector", default="pixel", choices=("pixel", "triangle"),
                   help="H per pixel (default) or constant per triangle")
    p.add_argument("--eta-threshold", type=float, default=None,
                   help="adaptive: skip normalization where eta < this (default 0.005)")
    p.add_argument("--q", type=float, default=None,
                   help="split-gouraud: specular threshold at edge maxima (default 1/255)")
    p.add_argument("--engine", default="auto", choices=("auto", "numpy", "numba"),
                   help=engine_help)
