"""Helpers shared by the subcommands."""

from __future__ import annotations

import argparse
import json
import re
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


#: an integer as the command line accepts it: ASCII digits, an optional sign
_ASCII_INT = re.compile(r"[+-]?[0-9]+")


def ascii_int(text) -> int:
    """An integer of the command line, in ASCII digits only (argparse type).

    Python's ``int`` also reads other scripts' digits (``int("\u0663") == 3``)
    and underscores (``int("1_0") == 10``); a number on the command line is
    taken only as it is printed back.

    Parameters
    ----------
    text : str
        The value as typed.

    Returns
    -------
    int
        Its value.

    Raises
    ------
    argparse.ArgumentTypeError
        When ``text`` holds a character outside ASCII (its message says so).
    ValueError
        When ``text`` is not an optional sign followed by ASCII digits (argparse
        reports it as ``invalid int value``).

    >>> ascii_int("-12")
    -12
    """
    if isinstance(text, str) and not text.isascii():
        raise argparse.ArgumentTypeError(f"invalid int value: {text!r}; accepted: ASCII "
                                         f"digits 0-9")
    if not isinstance(text, str) or not _ASCII_INT.fullmatch(text.strip()):
        raise ValueError(f"{text!r} is not an integer in ASCII digits")
    return int(text)


def ascii_float(text) -> float:
    """A float of the command line, in ASCII characters only (argparse type).

    Parameters
    ----------
    text : str
        The value as typed.

    Returns
    -------
    float
        Its value (``float(text)``).

    Raises
    ------
    argparse.ArgumentTypeError
        When ``text`` holds a character outside ASCII (another script's digits,
        which ``float`` would read).
    ValueError
        When ``text`` holds an underscore or is not a number (argparse reports it
        as ``invalid float value``).

    >>> ascii_float("1e-3")
    0.001
    """
    if isinstance(text, str) and not text.isascii():
        raise argparse.ArgumentTypeError(f"invalid float value: {text!r}; accepted: ASCII "
                                         f"digits 0-9")
    if not isinstance(text, str) or "_" in text:
        raise ValueError(f"{text!r} is not a number in ASCII digits")
    return float(text)


def shell_words(words) -> str:
    """A command for a POSIX shell: each word ``shlex.quote``-d, joined by spaces
    (``shlex.split`` gives the words back, as text).

    Parameters
    ----------
    words : iterable
        The command's words (numbers are written with ``str``).

    Returns
    -------
    str
        The quoted command line.

    >>> shell_words(["chebnorm", "fit", "1/sqrt(x)", "--interval", "(1)", 4])
    "chebnorm fit '1/sqrt(x)' --interval '(1)' 4"
    """
    return " ".join(shlex.quote(str(w)) for w in words)


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


def command_flags(parser, args) -> dict[str, str]:
    """The flags of the (sub)command ``args`` was parsed for, keyed by the
    Python name they store into: ``{"in_bits": "--in-bits", "coef_bits":
    "--coef-frac-bits", ...}``.

    Only names with an underscore are listed (``in_bits``, ``log_m``): they
    are the library's argument names, unambiguous in a message, where a
    one-word name (``error``, ``name``, ``interval``) is also plain English.
    A deprecated spelling (:func:`deprecated_alias`) never stands for a name.
    A parser may add names of its own with the default ``flag_names`` (a dict),
    for a library function under the command that calls a flag's value
    differently (``piecewise_fit``'s ``coef_frac_bits`` is ``fit``'s ``frac_bits``).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The top-level parser (:func:`chebnorm.cli.build_parser`).
    args : argparse.Namespace
        What it parsed: the chosen subcommands are read from it.

    Returns
    -------
    dict of str to str
        Each destination's flag (its longest ``--`` spelling).

    Examples
    --------
    >>> from chebnorm.cli import build_parser
    >>> p = build_parser()
    >>> flags = command_flags(p, p.parse_args(["hw", "verilog", "t.json", "--in-bits", "8",
    ...                                        "--out-bits", "8", "-o", "."]))
    >>> flags["in_bits"], flags["coef_bits"]
    ('--in-bits', '--coef-frac-bits')
    """
    flags: dict[str, str] = {}
    while parser is not None:
        sub = None
        for action in parser._actions:
            if isinstance(action.choices, dict):   # the subcommands' action
                sub = action.choices.get(getattr(args, action.dest, None))
                continue
            longs = [o for o in action.option_strings if o.startswith("--")]
            if longs and "_" in action.dest and not isinstance(action, _DeprecatedFlag):
                flags.setdefault(action.dest, max(longs, key=len))
        flags.update(parser.get_default("flag_names") or {})
        parser = sub
    return flags


def cli_flags(message: str, flags: dict[str, str]) -> str:
    """A library message, which names the Python arguments (``in_bits``), with
    the command line's flags instead (``--in-bits``).

    A name inside a longer identifier or a dotted field of a file
    (``quantized.frac_bits``) or an exponent (``2^in_bits``) is left alone.

    Parameters
    ----------
    message : str
        A ValueError's text from the library.
    flags : dict of str to str
        Python names to flags (:func:`command_flags`).

    Returns
    -------
    str
        The message in the command's words.

    Examples
    --------
    >>> cli_flags("in_bits = 40 is out of range; accepted: 1 <= in_bits <= 20",
    ...           {"in_bits": "--in-bits"})
    '--in-bits = 40 is out of range; accepted: 1 <= --in-bits <= 20'
    >>> cli_flags("field quantized.frac_bits is missing", {"frac_bits": "--coef-frac-bits"})
    'field quantized.frac_bits is missing'
    """
    if not flags:
        return message
    names = "|".join(re.escape(n) for n in sorted(flags, key=len, reverse=True))
    return re.sub(rf"(?<![\w.^])({names})(?![\w\[])", lambda m: flags[m.group(1)], message)


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
#: default of --q: one step of an 8-bit channel
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


def help_when_printed(parser, action, text) -> None:
    """Set ``action``'s help to ``text()`` when ``parser``'s help is printed, not
    when it is built: for a help that names what a stage registers (building the
    parsers imports no stage, so ``--help`` answers at once).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The (sub)command's parser.
    action : argparse.Action
        One of its arguments (what ``add_argument`` returned).
    text : callable
        Called with no argument when the help is printed; returns the help text.
    """
    format_help = parser.format_help

    def formatted():
        action.help = text()
        return format_help()

    parser.format_help = formatted


def max_error_value(text, example: str = "1e-5 or 2^-16") -> float:
    """``--max-error`` as a positive float: a number or an exact expression such
    as ``2^-20``.

    Parameters
    ----------
    text : str
        The flag's value as typed.
    example : str, optional
        Accepted values quoted in the refusal.

    Returns
    -------
    float
        The value, finite and > 0.

    Raises
    ------
    ValueError
        Naming ``--max-error`` and what it accepts.
    """
    import math

    from chebnorm.approx import parse_number

    try:
        value = float(parse_number(str(text).replace("^", "**")))
    except (ValueError, TypeError, OverflowError):
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"--max-error {text!r}: accepted: a finite number > 0, e.g. {example}")
    return value


def refuse_table_overwrite(args, files) -> None:
    """Refuse (exit 2) a file of ``files`` that ``-o DIR`` would write over the
    command's input table (``args.table``).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: its ``output`` folder and ``table`` (if any).
    files : iterable of str
        The names the command writes into the folder.

    Raises
    ------
    ValueError
        Naming ``-o`` and the input it would replace.
    """
    from pathlib import Path

    from chebnorm.core.files import refuse_inputs

    for name in files:
        refuse_inputs({"-o": Path(args.output) / name}, {"TABLE.json": getattr(args, "table", None)})
