"""``chebnorm correctly-rounded EXPR --format FMT --arithmetic binary64|float32 [--fma|--no-fma] --lang c -o DIR [--check]``.

Generates a correctly rounded implementation of EXPR (exp, exp2, log, log2,
sin, cos, tanh, erf, sqrt, 1/sqrt) on a 16-bit format, proved on every input
in the five IEEE rounding modes by the exact simulation of the generated
code, and writes its C source and header into DIR; ``--check`` also compiles
them with gcc and runs them on every input in the four rounding modes C has.
``--format binary32 --arithmetic float32`` writes 1/sqrt with float
arithmetic only, correctly rounded to nearest; ``--check`` then runs it on
all 2^32 inputs against an exact integer test.
Exit status 0 when every output is correctly rounded, 1 when the compiled
check finds one that is not, 2 on bad input.
"""

from __future__ import annotations

import argparse
import os
import sys

__all__: list[str] = []


def register(sub) -> None:
    """Add the ``chebnorm correctly-rounded`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); the new parser's ``func``
        default is :func:`run`.
    """
    p = sub.add_parser("correctly-rounded", help="a correctly rounded 16-bit function, proved on "
                       "every input in the five rounding modes")
    p.add_argument("expr", metavar="EXPR", help="exp, exp2, log, log2, sin, cos, tanh, erf, sqrt "
                   "or 1/sqrt")
    p.add_argument("--format", default="binary16", help="binary16 (default), bfloat16, "
                   "'p,emin,emax' of at most 16 bits, or binary32 (1/sqrt, --arithmetic float32)")
    p.add_argument("--interval", nargs=2, metavar=("LO", "HI"), type=float, default=None,
                   help="prove only the finite inputs in [LO, HI] (default: every input)")
    p.add_argument("--arithmetic", default="binary64", help="binary64 (default) or float32 "
                   "(1/sqrt on binary32: float only)")
    p.add_argument("--fma", action=argparse.BooleanOptionalAction, default=None,
                   help="--arithmetic float32: fused multiply-adds (default) or, with --no-fma, "
                   "Dekker's exact products")
    p.add_argument("--lang", default="c", help="c (the only one for now)")
    p.add_argument("-o", "--output", metavar="DIR", required=True,
                   help="directory for the C source and header")
    p.add_argument("--check", action="store_true",
                   help="also compile with gcc and run on every input in RNE, RTZ, RUP, RDN")
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``chebnorm correctly-rounded``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (``args.argv``, set by
        :func:`chebnorm.cli.main`, is quoted in the files' provenance).

    Returns
    -------
    int
        0 when every output is correctly rounded (and, with ``--check``,
        the compiled code agrees), 1 when the compiled check finds a wrongly
        rounded output or no implementation is found (one line on stderr).

    Raises
    ------
    ValueError
        On a bad EXPR, --format, --arithmetic, --lang or --interval
        (:func:`chebnorm.cli.main` prints one line and exits with status 2).
    """
    from chebnorm.core.files import write_atomic
    from chebnorm.cr import correctly_rounded

    if args.arithmetic not in ("binary64", "float32"):
        raise ValueError(f"--arithmetic {args.arithmetic[:40]!r} is not accepted; accepted: "
                         f"binary64, float32 (1/sqrt on binary32)")
    if args.lang != "c":
        raise ValueError(f"--lang {args.lang[:40]!r} is not accepted; accepted: c (glsl, wgsl, "
                         f"hlsl are not implemented yet)")
    argv = getattr(args, "argv", None)
    command = " ".join(argv) if argv else ""
    try:
        result = correctly_rounded(args.expr, args.format, interval=args.interval,
                                   arithmetic=args.arithmetic,
                                   lang=args.lang, command=command, fma=args.fma)
    except ArithmeticError as exc:  # no implementation found: the one line, status 1
        print(f"chebnorm: correctly-rounded: {' '.join(str(exc).split())}", file=sys.stderr)
        return 1
    except ValueError as exc:
        msg = (str(exc).replace("expr ", "EXPR ", 1).replace("fmt ", "--format ", 1)
               .replace("interval ", "--interval ", 1).replace("arithmetic ", "--arithmetic ", 1)
               .replace("fma ", "--fma ", 1))
        raise ValueError(msg) from None
    os.makedirs(args.output, exist_ok=True)
    for name, text in sorted(result.files.items()):
        write_atomic(os.path.join(args.output, name), text)
    fig = result.figures
    if result.format == "binary32":
        return _binary32(result, args)
    wrong = ", ".join(f"{m} {n}" for m, n in fig["wrong"].items())
    print(f"{result.c_name}: {fig['inputs']} inputs, wrongly rounded (exact simulation): {wrong}; "
          f"generated in {fig['seconds']:.1f} s")
    if args.check:
        counts = result.check()
        print(f"{result.c_name}: compiled check (gcc): "
              + ", ".join(f"{m} {n}" for m, n in counts.items()))
        if any(counts.values()):
            print(f"chebnorm: correctly-rounded: the compiled {result.c_name} is wrongly rounded "
                  f"on {sum(counts.values())} outputs", file=sys.stderr)
            return 1
    return 0


def _binary32(result, args) -> int:
    """The summary (and, with --check, the exhaustive run) of binary32 1/sqrt."""
    print(f"{result.c_name}: 1/sqrt on binary32, float arithmetic only "
          f"({'fmaf' if result.figures['fma'] else 'Dekker products, no FMA'}): written to "
          f"{args.output}")
    if args.check:
        counts = result.check()
        got = result.figures["check"]
        print(f"{result.c_name}: compiled check (gcc, all 2^32 inputs, exact integer test): "
              + ", ".join(f"{k} {got[k][1]} wrong of {got[k][0]}"
                          for k in ("normal", "subnormal", "special"))
              + f"; {got['seconds']:.0f} s")
        if counts["RNE"]:
            print(f"chebnorm: correctly-rounded: the compiled {result.c_name} is wrongly rounded "
                  f"on {counts['RNE']} inputs", file=sys.stderr)
            return 1
    return 0
