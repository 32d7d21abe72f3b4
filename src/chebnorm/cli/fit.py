"""``chebnorm fit``, ``chebnorm export`` and ``chebnorm targets`` live here and
in the sibling modules; this one fits and certifies one polynomial."""

from __future__ import annotations

import argparse
import re
import sys
import warnings

from .common import (ascii_int, cli_flags, command_line, deprecated_alias, max_error_value,
                     print_json)
from .vocab import COEF_FORMATS as FORMATS, MAX_DEGREE


def register(sub) -> None:
    """Add the ``chebnorm fit`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); the new parser's ``func``
        default is :func:`run`.
    """
    p = sub.add_parser("fit", help="fit and certify a polynomial",
                       description="Fit a polynomial to EXPR on [LO, HI] and certify its "
                       "absolute and relative error bounds.")
    p.add_argument("expr", metavar="EXPR", help='function of VAR, e.g. "1/sqrt(2+z)": numbers '
                   '(decimals exact), + - * / ** ^, pi, E, sqrt, exp, log, sin, ... (no other names)')
    p.add_argument("--var", default="x", help="the variable of EXPR (default x)")
    p.add_argument("--interval", nargs=2, metavar=("LO", "HI"), required=True,
                   help='exact endpoints, e.g. "sqrt(2)" 2 or 0.1 0.3 (decimals are exact)')
    p.add_argument("--degree", type=int, default=None,
                   help=f"0..{MAX_DEGREE} (or --max-error)")
    p.add_argument("--max-error", default=None, metavar="E",
                   help="instead of --degree: the smallest degree whose certified error "
                   "(|p - f|, or |p/f - 1| with --error rel; of the quantized coefficients "
                   "with a format) is <= E, e.g. 1e-6 or 2^-20; the degrees tried are printed")
    p.add_argument("--kind", default="chebyshev", help="chebyshev (default) or minimax")
    p.add_argument("--error", default="abs", help="error minimized by minimax: abs (default) or rel")
    p.add_argument("--coef-frac-bits", dest="frac_bits", type=_int_list, default=None,
                   metavar="F", help="also quantize the coefficients to F fractional bits "
                   "(fixed point), or F0,F1,...,Fn one per power 0..degree")
    deprecated_alias(p, "--frac-bits", "--coef-frac-bits", "frac_bits", type=_int_list,
                     metavar="F")
    p.add_argument("--coef-format", default=None, choices=FORMATS,
                   help="coefficient format: fixed (with --coef-frac-bits) or a floating format "
                   "binary16, bfloat16, binary32, binary64; coefficients chosen by lattice "
                   "reduction (as Sollya's fpminimax) and re-certified")
    p.add_argument("--monomials", type=_int_list, default=None, metavar="K,K,...",
                   help="keep only these powers, e.g. 1,3,5 (odd) or 0,2,4 (even)")
    p.add_argument("--fix-constant", action="store_true",
                   help="hold the constant coefficient at f(0) rounded to its format")
    p.add_argument("--segments", default=None, metavar="2^k",
                   help="piecewise table of 2^k segments, 0 <= k <= 12 (per binade with "
                   "--segment-by exponent); coefficients in one fixed-point format "
                   "(--coef-frac-bits, default 24); auto with --degree and --max-error: "
                   "the fewest segments certified to E")
    p.add_argument("--segment-by", default=None, choices=("uniform", "exponent"),
                   help="uniform (default: top k bits of the input) or exponent (a float's "
                   "exponent and top mantissa bits; interval [2^e0, 2^e1])")
    p.add_argument("--centered", action="store_true",
                   help="piecewise: evaluate each segment in t - 1/2 (smaller coefficients)")
    p.add_argument("--basis", default="auto", choices=("auto", "monomial", "shifted"),
                   help="auto (default): monomial unless its float32 Horner evaluation would "
                   "lose what the fit gained and shifted does better (the choice and why in "
                   "the table's basis_choice); monomial: powers of VAR; shifted: powers of "
                   "t = (VAR - c)/s, c the midpoint, s a power of two (well conditioned on "
                   "narrow or offset intervals, where monomials lose accuracy; exported to C, "
                   "not to hw/shaders)")
    p.add_argument("--name", default=None, help="table name: [A-Za-z_][A-Za-z0-9_]*, at "
                   "most 63 characters (it names the C function, shader and HDL module); "
                   "default: made from EXPR, the interval and the degree, e.g. rsqrt_1_4_d3")
    p.add_argument("--json", action="store_true", help="print the table as JSON on stdout")
    p.add_argument("-o", "--output", metavar="TABLE.json", help="write the table as JSON")
    # piecewise_fit, under fit --segments, calls --coef-frac-bits coef_frac_bits
    p.set_defaults(func=run, flag_names={"coef_frac_bits": "--coef-frac-bits"})
    # a value such as -1/8 or -pi/4 (after --interval) is an argument, not an
    # option: argparse takes a token starting with '-' for an option unless its
    # negative-number pattern matches, and this parser's only one-dash options
    # are -h and -o
    p._negative_number_matcher = _NOT_AN_OPTION


#: anything starting with one '-' except -h and -o (with or without a value)
_NOT_AN_OPTION = re.compile(r"^-(?![-ho]|$)")


def _int_list(text: str):
    """``14`` -> 14; ``1,3,5`` -> [1, 3, 5] (argparse type)."""
    try:
        parts = [ascii_int(p) for p in text.split(",")]
    except (ValueError, argparse.ArgumentTypeError):
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer or a comma-separated "
                                         f"list of integers in ASCII digits, e.g. 14 or "
                                         f"1,3,5") from None
    return parts[0] if len(parts) == 1 and "," not in text else parts


#: the library's argument names as this command's words (its messages name the
#: Python argument; the command line names the flag, as it always did)
_CLI_WORDS = re.compile(r"(?<![\w.])(coef_frac_bits|frac_bits|coef_format|segment_by|"
                        r"fix_constant|in_bits|out_bits)(?![\w\[])")
_CLI_PHRASES = (("set it with var=", "set it with --var"),
                ("interval=('1/4', '4')", "--interval 1/4 4"),
                ("basis='monomial'", "--basis monomial"),
                ("quantized with coef_frac_bits (chebnorm.fit(..., coef_frac_bits=F) or "
                 "chebnorm.quantize)",
                 "quantized with `chebnorm fit ... --coef-frac-bits F`"))


def cli_words(message: str, flags: dict[str, str] | None = None) -> str:
    """A library message with the argument names of the library as the command
    line spells them: with ``flags`` (:func:`chebnorm.cli.common.command_flags`,
    what :func:`chebnorm.cli.main` passes for every command) each name becomes
    its flag (``in_bits`` -> ``--in-bits``, ``coef_bits`` -> ``--coef-frac-bits``);
    without, the names of :func:`chebnorm.fit` lose their underscores
    (``frac_bits`` -> ``frac-bits``). The phrases of :func:`cli_phrases`
    (``var=`` -> ``--var``) are translated either way.

    Parameters
    ----------
    message : str
        A library's ValueError text (Python argument names).
    flags : dict of str to str, optional
        Python names to the command's flags.

    Returns
    -------
    str
        The text with the command line's words (a field of a table file, such as
        ``quantized.frac_bits``, is left as it is).

    Examples
    --------
    >>> cli_words("frac_bits 40 overflows int32; accepted: frac_bits <= 30")
    'frac-bits 40 overflows int32; accepted: frac-bits <= 30'
    >>> cli_words("frac_bits 40 overflows int32", {"frac_bits": "--coef-frac-bits"})
    '--coef-frac-bits 40 overflows int32'
    """
    if flags is not None:
        return cli_flags(cli_phrases(message), flags)
    return _CLI_WORDS.sub(lambda m: m.group(1).replace("_", "-"), cli_phrases(message))


def cli_phrases(message: str) -> str:
    """The phrases of library messages that name an argument by its Python
    spelling (``basis='monomial'``, ``var=``) as the flag (any command).

    Parameters
    ----------
    message : str
        A library's ValueError text.

    Returns
    -------
    str
        The text with those phrases as flags.

    Examples
    --------
    >>> cli_phrases("accepted: a table fitted with basis='monomial'")
    'accepted: a table fitted with --basis monomial'
    """
    for python, flag in _CLI_PHRASES:
        message = message.replace(python, flag)
    return message


def _fit_cli(args, **kw):
    """:func:`chebnorm.fit` with the command's arguments; its refusals in the CLI's words."""
    # its refusals name fit's arguments: chebnorm.cli.main says them as flags (cli_words)
    from chebnorm.approx import fit

    max_error = getattr(args, "max_error", None)
    if max_error is not None:
        kw["max_error"] = max_error_value(max_error, "1e-6 or 2^-20")
    return fit(args.expr, tuple(args.interval), args.degree, kind=args.kind,
               error=args.error, var=args.var, name=args.name, coef_frac_bits=args.frac_bits,
               command=command_line(args), basis=args.basis,
               coef_format=args.coef_format, fix_constant=args.fix_constant, **kw)


def _run_piecewise(args) -> int:
    from chebnorm.core.numeric import format_up
    table = _fit_cli(args, monomials=args.monomials, segments=args.segments or 1,
                     segment_by=args.segment_by or "uniform", centered=args.centered)
    if args.output:
        table.save(args.output)
    if args.json:
        print_json(table.to_dict())
    elif not args.output:
        print(f"{table.name}: {table.segment_count} {table.segment_by} segments, {table.fit} "
              f"degree {table.degree} of {table.expression} on [{table.interval[0]}, "
              f"{table.interval[1]}], coefficients * 2^-{table.coef_frac_bits}")
        if "segment_search" in table.provenance:
            print(f"--max-error {float(table.provenance['max_error']):.6e}, "
                  f"{table.provenance['segment_search']}")
        print(f"certified max over segments |p_s - f| <= {format_up(table.abs_error_bound, '.6e')}"
              + ("" if table.rel_error_bound is None
                 else f", |p_s/f - 1| <= {format_up(table.rel_error_bound, '.6e')}"))
    return 0


def run(args) -> int:
    """Run ``chebnorm fit``: fit and certify a polynomial (or, with
    ``--segments``, a piecewise table), print its report and write the table
    with ``-o``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm fit`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 on success.

    Raises
    ------
    ValueError
        On an argument :func:`chebnorm.fit` refuses (:func:`chebnorm.cli.main` prints
        it as one line on stderr with the command's flags, :func:`cli_words`, and exits
        with status 2).
    """
    from chebnorm.approx import FitWarning, warnings_of
    from chebnorm.core.textsafe import identifier

    if args.name is not None:  # before the fit: the name becomes C and HDL symbols
        identifier(args.name, field="--name")
    if args.degree is None and args.max_error is None:
        raise ValueError(f"the following arguments are required: --degree N (0..{MAX_DEGREE}), "
                         f"or --max-error E instead (the smallest degree whose certified error "
                         f"is <= E)")
    auto = args.segments == "auto"
    if auto and (args.degree is None or args.max_error is None):
        raise ValueError("--segments auto needs --degree N and --max-error E: the fewest "
                         "segments whose certified error at that degree is <= E")
    if args.degree is not None and args.max_error is not None and not auto:
        raise ValueError(f"--degree and --max-error are both given; accepted: one of --degree "
                         f"N (0..{MAX_DEGREE}) or --max-error E (the smallest degree whose "
                         f"certified error is <= E), or both with --segments auto")
    if args.max_error is not None and not auto and (
            args.segments is not None or args.segment_by is not None or args.centered):
        raise ValueError("--max-error with --segments, --segment-by or --centered: accepted: "
                         "--max-error for one polynomial, or --segments auto --degree N "
                         "--max-error E for the fewest segments")
    if args.segments is not None or args.segment_by is not None or args.centered:
        return _run_piecewise(args)
    mon = args.monomials
    if isinstance(mon, int):
        mon = [mon]
    with warnings.catch_warnings():
        # printed below from the table's provenance, once
        warnings.simplefilter("ignore", FitWarning)
        table = _fit(args, mon)
    for warning in warnings_of(table):
        print(f"chebnorm: warning: {warning}", file=sys.stderr)
    return _report(args, table)


def _fit(args, mon):
    return _fit_cli(args, monomials=mon)


def _report(args, table) -> int:
    from chebnorm.core.numeric import format_down, format_up
    if args.output:
        table.save(args.output)
    if args.json:
        print_json(table.to_dict())
    elif not args.output:
        print(f"{table.name}: {table.kind} degree {table.degree} fit of {table.expression} "
              f"on [{table.interval[0]}, {table.interval[1]}]")
        if "degree_search" in table.provenance:
            print(f"--max-error {float(table.provenance['max_error']):.6e}, "
                  f"{table.provenance['degree_search']}")
        powers_of = table.variable if table.shift is None else (
            f"t = ({table.variable} - {table.shift[0]!r})/{table.shift[1]!r}")
        if table.basis_choice is not None and table.shift is not None:
            print(f"basis: shifted, chosen by --basis auto "
                  f"({table.basis_choice.reason.split('. ')[0]})")
        print("coefficients (ascending powers of {}): {}".format(
            powers_of, ", ".join(f"{c:.17g}" for c in table.coefficients)))
        print(f"max |p - f|   = {format_down(table.max_abs_error, '.6e')} at {table.variable} = "
              f"{table.max_abs_at:.17g}; "
              f"certified bound {format_up(table.abs_error_bound, '.6e')}")
        if "binary_endpoints" in table.provenance:
            print(f"note: {table.provenance['binary_endpoints']}")
        if table.rel_error_bound is not None:
            print(f"max |p/f - 1| = {format_down(table.max_rel_error, '.6e')}; certified bound "
                  f"{format_up(table.rel_error_bound, '.6e')}")
        if table.fixed_point is not None:
            fp = table.fixed_point
            print(f"fixed point ({fp.frac_bits} fractional bits, {fp.method}): {list(fp.integers)}; "
                  f"certified |p_q - f| <= {format_up(fp.abs_error_bound, '.6e')}")
        elif table.quantized is not None:
            q = table.quantized
            what = (f"fixed point ({','.join(map(str, q.frac_bits))} fractional bits"
                    if q.format == "fixed" else f"{q.format} (coefficients")
            print(f"{what}, {q.method}): " + ", ".join(
                f"{m}*2^{e}" for k, (m, e) in enumerate(zip(q.mantissas, q.exponents))
                if k in q.monomials or (k == 0 and q.fixed_constant)))
            print(f"quantized: certified |p_q - f| <= {format_up(q.abs_error_bound, '.6e')}"
                  + ("" if q.rel_error_bound is None
                     else f", |p_q/f - 1| <= {format_up(q.rel_error_bound, '.6e')}"))
    return 0
