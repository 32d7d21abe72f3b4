"""``chebnorm design``: the cheapest certified hardware evaluator meeting an error
bound; the flags of :func:`chebnorm.hw.design`, its files written, its lines printed."""

from __future__ import annotations

import re

from .common import command_line, max_error_value
from .parallel_options import add_parallel_args

#: the library's Python spellings of the options, as the command line says them
_PHRASES = (("with synth=True", "without --no-synth"), ("synth=True", "without --no-synth"),
            ("synth=False", "--no-synth"), ("correctly_rounded=True", "--correctly-rounded"),
            ("faithful=True", "--faithful"), ("max_error=E", "--max-error E"),
            ("index='exponent'", "--index exponent"), ("index='uniform'", "--index uniform"),
            ("frequency=None", "without --frequency"), ("device ice40", "--target ice40"),
            ("device '", "--target '"), ("max_segments, degrees", "max_segments, --degrees"),
            ("<= degrees <=", "<= --degrees <="), ("out_bits=N", "--out-bits N"),
            ("lsb=L", "--lsb L"), ("lsb >=", "--lsb >="), ("larger lsb", "larger --lsb"))
#: the options passed to :func:`chebnorm.hw.design` under their own names
_SAME = ("in_bits out_bits lsb faithful correctly_rounded frequency degrees max_segments index "
         "var name workers scheduler architecture simulate").split()
#: one-word arguments named at the start of a refusal
_LEADING = re.compile(r"^(frequency|degrees|max_segments|interval|var|name|lsb|architecture) ")


def register(sub) -> None:
    """Add the ``chebnorm design`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (``add_subparsers``); the
        new parser's ``func`` default is :func:`run`.
    """
    p = sub.add_parser("design", help="cheapest certified evaluator meeting an accuracy",
                       description="The cheapest certified evaluator (piecewise, multipartite, "
                       "table) meeting the accuracy at one output format, priced on a device; "
                       "the Pareto front as CSV and PNG, why the winner wins (chebnorm.hw.design).")
    p.add_argument("expr", metavar="EXPR", help='function in sympy syntax, e.g. "1/sqrt(x)"')
    p.add_argument("--var", default="x", help="the variable of EXPR (default x)")
    p.add_argument("--interval", nargs=2, metavar=("LO", "HI"), required=True,
                   help="rational endpoints: the code maps onto [LO, HI)")
    p.add_argument("--in-bits", type=int, required=True, help="input code width, 2..20")
    p.add_argument("--out-bits", type=int, help="output code width, 1..32 (alone: the finest "
                   "last place f's range fits; with --lsb: checked to hold that range)")
    p.add_argument("--lsb", type=int, metavar="L", help="the output's last place is 2^L for "
                   "every architecture (FloPoCo's lsbOut), -60..60; no --out-bits: derived")
    acc = p.add_mutually_exclusive_group(required=True)
    acc.add_argument("--max-error", metavar="E", help="certified bound on |y - f(x)|, > 0, e.g. 2^-16")
    acc.add_argument("--faithful", action="store_true", help="certified |y - f(x)| < 1 unit of "
                     "the output's last place (FloPoCo's contract)")
    acc.add_argument("--correctly-rounded", action="store_true",
                     help="every output code the proved rounding of f (a plain table)")
    p.add_argument("--degrees", type=int, nargs="+", default=[1, 2, 3], help="default 1 2 3")
    p.add_argument("--max-segments", default=None, metavar="2^k", help="largest segment count "
                   "tried, 2^0..2^min(12, in-bits - 1) (default 2^8, or 2^(in-bits - 1) when "
                   "in-bits <= 8: at most half the input codes)")
    p.add_argument("--no-synth", action="store_true", help="model estimate instead of yosys")
    p.add_argument("--target", "--device", dest="target", default="generic", metavar="T",
                   help="the FPGA priced on: generic (yosys cells; default), xc7, xc7-nodsp (LUT "
                   "equivalents: a DSP48E1 = 264.2 LUTs) or ice40 (with nextpnr-ice40 Fmax of "
                   "the winner); --device is the same flag")
    p.add_argument("--frequency", default=None, metavar="MHZ", help="pipeline the winner to "
                   "this clock (MHz > 0): registers at its stage boundaries until nextpnr-ice40's "
                   "Fmax (ice40) or the sta model's (xc7, xc7-nodsp) reaches it, or the highest "
                   "reached is said; the pipelined RTL is simulated over every input code")
    p.add_argument("--index", choices=("uniform", "exponent"), default="uniform", help="uniform "
                   "(default): the code maps onto [LO, HI), its top bits pick the segment; "
                   "exponent: 1/sqrt(x) only, x = code / 2^in-bits with --interval 2^-m 1, a "
                   "leading-zero count picks the binade pair, the output a mantissa (--out-bits) "
                   "and a shift (chebnorm.hw.exponent)")
    p.add_argument("--architecture", choices=("piecewise", "piecewise-sized", "multipartite",
                   "table"), help="only this architecture (default: every one competes)")
    p.add_argument("--simulate", action="store_true", help="the winner's Verilog simulated "
                   "over every input code (Icarus), its error measured against f's reference")
    p.add_argument("--name", default=None, help="module name (an identifier; default: from "
                   "EXPR, the interval, the widths and the accuracy, e.g. rsqrt_1_4_i8_o8_faithful, "
                   "so different designs' modules coexist in one build)")
    p.add_argument("-o", "--output", metavar="DIR", required=True,
                   help="folder for design_NAME.csv/.png (created if missing)")
    add_parallel_args(p)
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``chebnorm design``: :func:`chebnorm.hw.design` of the parsed flags,
    its files written into the folder ``-o`` (their paths printed), then its lines.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm design`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 on success.

    Raises
    ------
    ValueError
        When the output exists and is not a folder, or :func:`chebnorm.hw.design`
        refuses the spec or finds no design meeting it (in the command's words;
        :func:`chebnorm.cli.main` prints it as one line on stderr and exits with
        status 2). Nothing is written then.
    """
    from pathlib import Path

    from chebnorm import __version__
    from chebnorm.core.files import write_folder
    from chebnorm.hw.design_api import design

    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise ValueError(f"output {args.output!r} exists and is not a folder; accepted: a folder")
    max_error = None if args.max_error is None else max_error_value(args.max_error)
    try:
        res = design(args.expr, tuple(args.interval), max_error=max_error, device=args.target,
                     synth=not args.no_synth, **{k: getattr(args, k) for k in _SAME})
    except ValueError as exc:
        raise ValueError(cli_phrases(str(exc))) from None
    for path in write_folder(out, res.files(command=command_line(args), version=__version__)):
        print(path)
    print("\n".join(res.lines()))
    return 0


def cli_phrases(message: str) -> str:
    """A refusal of :func:`chebnorm.hw.design` in the words of ``chebnorm design``
    (``synth=False`` -> ``--no-synth``); :func:`chebnorm.cli.main` names the widths.

    Parameters
    ----------
    message : str
        The library's message.

    Returns
    -------
    str
        The message with the command line's spellings.

    >>> cli_phrases("frequency 9 needs an FPGA's timing; accepted: device ice40, with synth=True")
    "--frequency 9 needs an FPGA's timing; accepted: --target ice40, without --no-synth"
    """
    for python, flag in _PHRASES:  # e.g. device 'x' -> --target 'x'
        message = message.replace(python, flag)
    return _LEADING.sub(lambda m: f"--{m.group(1).replace('_', '-')} ", message)
