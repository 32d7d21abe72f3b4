"""``chebnorm export TABLE.json --format c|json|glsl|wgsl|hlsl|vhdl|verilog -o FILE``.

The software formats come from :mod:`chebnorm.export`; ``vhdl`` and
``verilog`` are fixed-point hardware, which the ``export`` stage does not
know (``export`` and ``hw`` are sibling stages), so the command dispatches
them to :mod:`chebnorm.hw` with the widths given by ``--in-bits`` and
``--out-bits``: FILE then holds the combinational evaluator and, for degree
>= 1, the pipelined one (``hw verilog --lang vhdl`` writes the benches too).
"""

from __future__ import annotations

from chebnorm.approx import CoefficientTable
from chebnorm.export import FORMATS, export_table

from ._common import command_line, deprecated_alias

HW_FORMATS = ("vhdl", "verilog")


def _all_formats() -> str:
    return ", ".join(sorted((*FORMATS, *HW_FORMATS)))


def register(sub) -> None:
    p = sub.add_parser("export", help="print a coefficient table as C, JSON, GLSL, WGSL, HLSL, "
                       "VHDL or Verilog")
    p.add_argument("table", metavar="TABLE.json")
    p.add_argument("--format", default="c", help=f"one of {_all_formats()} (default c)")
    p.add_argument("-o", "--output", metavar="FILE", required=True)
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


def run(args) -> int:
    if args.format not in FORMATS and args.format not in HW_FORMATS:
        raise ValueError(f"unknown export format {args.format!r}; accepted: {_all_formats()}")
    from chebnorm.approx.piecewise import is_piecewise_file

    if is_piecewise_file(args.table):
        return _run_piecewise(args)
    flags = {"in_bits": "--in-bits", "out_bits": "--out-bits", "coef_bits": "--coef-frac-bits",
             "acc_bits": "--acc-bits", "rounding": "--rounding"}
    hw_only = [flag for dest, flag in flags.items() if getattr(args, dest) is not None]
    if args.format in FORMATS and hw_only:
        raise ValueError(f"{', '.join(hw_only)} apply to --format vhdl or verilog only, not "
                         f"{args.format!r}")
    table = CoefficientTable.load(args.table)
    if args.format in FORMATS:
        export_table(table, args.format, args.output, command_line(args))
        return 0
    if args.in_bits is None or args.out_bits is None:
        raise ValueError(f"--format {args.format} needs --in-bits and --out-bits (input and "
                         f"output code widths); accepted: 1..20 and 1..32")
    from chebnorm import __version__
    from chebnorm.core.files import write_atomic
    from chebnorm.hw.report import analyze

    report = analyze(table, args.in_bits, args.out_bits, coef_bits=args.coef_bits,
                     acc_bits=args.acc_bits, rounding=args.rounding or "rne", gappa=False,
                     synth=False)
    d = report.design
    kw = dict(version=__version__, command=command_line(args), budget=report.budget)
    if args.format == "vhdl":
        from chebnorm.hw.vhdl import vhdl_module as comb, vhdl_pipelined_module as pipe
    else:
        from chebnorm.hw.verilog import verilog_module as comb, verilog_pipelined_module as pipe
    text = comb(d, **kw)
    if d.degree >= 1:
        text += "\n" + pipe(d, **kw)
    write_atomic(args.output, text)
    return 0


def _run_piecewise(args) -> int:
    from chebnorm.core.files import write_atomic
    from chebnorm.approx.piecewise import PiecewiseTable
    from chebnorm.export.c_piecewise import DEFAULT_C_IN_BITS, piecewise_c_header

    table = PiecewiseTable.load(args.table)
    dests = {"--in-bits": "in_bits", "--out-bits": "out_bits", "--coef-frac-bits": "coef_bits",
             "--acc-bits": "acc_bits", "--rounding": "rounding"}
    takes = {"c": ("--in-bits",), "verilog": ("--in-bits", "--out-bits")}.get(args.format, ())
    given = [flag for flag, dest in dests.items()
             if getattr(args, dest) is not None and flag not in takes]
    if given:
        raise ValueError(f"{', '.join(given)} does nothing with --format {args.format} of a "
                         f"piecewise table; accepted there: {' '.join(takes) or 'no width option'}")
    if args.format == "c":
        in_bits = DEFAULT_C_IN_BITS if args.in_bits is None else args.in_bits
        text = piecewise_c_header(table, command_line(args), in_bits=in_bits)
    elif args.format == "json":
        text = table.to_json()
    elif args.format == "verilog":
        from chebnorm import __version__
        from chebnorm.hw.piecewise import design_piecewise, piecewise_verilog

        if args.in_bits is None or args.out_bits is None:
            raise ValueError("--format verilog needs --in-bits and --out-bits (input and output "
                             "code widths)")
        text = piecewise_verilog(design_piecewise(table, args.in_bits, args.out_bits),
                                 version=__version__, command=command_line(args))
    else:
        raise ValueError(f"format {args.format!r} is not available for a piecewise table; "
                         f"accepted: c, json, verilog")
    write_atomic(args.output, text)
    return 0
