"""``chebnorm export TABLE.json --format c|json|glsl|wgsl|hlsl|vhdl|verilog -o FILE``.

Every format is printed by :mod:`chebnorm.export` (the one place per output
format); this command reads the table (either kind), refuses flags the
format does not take (naming the flags), and writes the text atomically.
``vhdl`` and ``verilog`` are fixed-point hardware sized by ``--in-bits`` and
``--out-bits``: FILE then holds the combinational evaluator and, for a
coefficient table of degree >= 1, the pipelined one (``hw verilog`` writes
the benches too).
"""

from __future__ import annotations

from .common import command_line, deprecated_alias
from .vocab import EXPORT_FORMATS

#: export option -> (argparse dest, flag)
_FLAGS = {"in_bits": ("in_bits", "--in-bits"), "out_bits": ("out_bits", "--out-bits"),
          "coef_frac_bits": ("coef_bits", "--coef-frac-bits"),
          "acc_bits": ("acc_bits", "--acc-bits"), "rounding": ("rounding", "--rounding")}


def _all_formats() -> str:
    return ", ".join(EXPORT_FORMATS)


def register(sub) -> None:
    """Add the ``chebnorm export`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); the new parser's ``func``
        default is :func:`run`.
    """
    p = sub.add_parser("export", help="print a coefficient table as C, JSON, GLSL, WGSL, HLSL, "
                       "VHDL or Verilog")
    p.add_argument("table", metavar="TABLE.json")
    p.add_argument("--format", default="c", help=f"one of {_all_formats()} (default c)")
    p.add_argument("-o", "--output", metavar="FILE", required=True)
    p.add_argument("--proof", action="store_true",
                   help="also write a Gappa script per stated evaluation bound beside FILE "
                   "(FILE.CONSTANT.gappa; formats c, glsl, wgsl, hlsl)")
    hw = p.add_argument_group("vhdl and verilog (fixed point; see chebnorm hw verilog)")
    hw.add_argument("--in-bits", type=int, default=None,
                    help="input code width, 1..20 (a piecewise table's C export: 1..32, "
                    "default 24)")
    hw.add_argument("--out-bits", type=int, default=None, help="output code width, 1..32")
    hw.add_argument("--coef-frac-bits", dest="coef_bits", type=int, default=None,
                    help="coefficient fractional bits (default: the table's own)")
    deprecated_alias(hw, "--coef-bits", "--coef-frac-bits", "coef_bits", type=int)
    hw.add_argument("--acc-bits", type=int, default=None,
                    help="accumulator fractional bits (default: output's + 3)")
    hw.add_argument("--rounding", default=None, help="rne (default) or trunc")
    p.set_defaults(func=run)


def _given(args) -> dict:
    """The export options whose flags were given (option name -> value)."""
    return {opt: getattr(args, dest) for opt, (dest, _) in _FLAGS.items()
            if getattr(args, dest) is not None}


def run(args) -> int:
    """Run ``chebnorm export``: write a coefficient table in one of the export
    formats (C, JSON, GLSL, WGSL, HLSL, Verilog, VHDL) into ``-o FILE``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm export`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 on success.

    Raises
    ------
    ValueError
        On an unknown ``--format``, an option given that does nothing with that format,
        a hardware format without ``--in-bits``/``--out-bits``, or a table the exporter
        refuses (:func:`chebnorm.cli.main` prints it as one line on stderr, the
        library's argument names as the command's flags, and exits with status 2).
    """
    from chebnorm.approx import PiecewiseTable, load_table
    from chebnorm.core.files import refuse_inputs
    from chebnorm.export import HDL_FORMATS, export_table, export_with_proofs, options_for

    if args.format not in EXPORT_FORMATS:
        raise ValueError(f"unknown export format {args.format!r}; accepted: {_all_formats()}")
    given = _given(args)
    inputs = {"TABLE.json": args.table}
    refuse_inputs({"-o": args.output}, inputs)
    table = load_table(args.table)
    if isinstance(table, PiecewiseTable):
        takes = options_for(table, args.format) if args.format in ("c", "json", *HDL_FORMATS) \
            else ()
        extra = [_FLAGS[o][1] for o in given if o not in takes]
        if extra:
            raise ValueError(f"{', '.join(extra)} does nothing with --format {args.format} of a "
                             f"piecewise table; accepted there: "
                             f"{' '.join(_FLAGS[o][1] for o in takes) or 'no width option'}")
    else:
        if args.format not in HDL_FORMATS and given:
            raise ValueError(f"{', '.join(_FLAGS[o][1] for o in given)} apply to --format vhdl "
                             f"or verilog only, not {args.format!r}")
    if args.format in HDL_FORMATS and ("in_bits" not in given or "out_bits" not in given):
        accepted = "" if isinstance(table, PiecewiseTable) else "; accepted: 1..20 and 1..32"
        raise ValueError(f"--format {args.format} needs --in-bits and --out-bits (input and "
                         f"output code widths){accepted}")
    # the library names its arguments (in_bits): chebnorm.cli.main says them as flags
    if args.proof:
        export_with_proofs(table, args.format, args.output, command_line(args), inputs=inputs,
                           **given)
    else:
        export_table(table, args.format, args.output, command_line(args), **given)
    return 0
