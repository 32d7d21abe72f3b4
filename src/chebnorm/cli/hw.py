"""``chebnorm hw verilog|report|sweep``: fixed-point hardware of a table."""

from __future__ import annotations

import json

from .common import (command_line, deprecated_alias, help_when_printed, print_json,
                     refuse_table_overwrite, refuse_unused)
from .parallel_options import add_parallel_args, parallel_kwargs
from .vocab import UNIT_NAMES


def _design_args(p) -> None:
    p.add_argument("table", metavar="TABLE.json")
    p.add_argument("--in-bits", type=int, required=True,
                   help="input code width W, 1..20: code k is x = LO + (HI - LO) k / 2^W on the "
                   "table's [LO, HI) as in chebnorm design, when HI - LO is a power of two "
                   "(see --x-frac-bits; docs/hardware.md, Input codes)")
    p.add_argument("--out-bits", type=int, required=True, help="output code width, 1..32")
    p.add_argument("--coef-frac-bits", dest="coef_bits", type=int, default=None, metavar="B",
                   help="coefficient fractional bits, 1..31 or fewer: the table's coefficients "
                   "must fit int32 (re-quantizes; default: the table's own)")
    deprecated_alias(p, "--coef-bits", "--coef-frac-bits", "coef_bits", type=int, metavar="B")
    p.add_argument("--acc-bits", type=int, default=None,
                   help="accumulator fractional bits (default: output's + 3)")
    p.add_argument("--rounding", default="rne", help="rne (default) or trunc")
    p.add_argument("--x-frac-bits", type=int, default=None, metavar="F",
                   help="input fractional bits; default W - log2(HI - LO) (every code valid) "
                   "when HI - LO is a power of two and LO a multiple of the step, else the "
                   "largest whose codes cover [LO, HI] (the report names the valid codes); "
                   "another F: the covering mapping x = (floor(LO 2^F) + k) / 2^F")
    p.add_argument("--y-frac-bits", type=int, default=None, help="default: the largest that fits")


def _unit_width_args(p) -> None:
    p.add_argument("--vector-frac-bits", dest="frac_bits", type=int, default=None, metavar="F",
                   help="unit: fractional bits F of the vector components, 1..26 (default 14)")
    deprecated_alias(p, "--frac-bits", "--vector-frac-bits", "frac_bits", type=int, metavar="F")
    p.add_argument("--comp-bits", type=int, default=None,
                   help="unit: signed component width W, 2..28 (default F + 2)")
    p.add_argument("--log-m", type=int, default=None, help="stepper: m = 2^LOG_M pixels, 0..10")
    p.add_argument("--guard", type=int, default=None,
                   help="stepper: guard bits, 0..24 (default 2 LOG_M: exact set-up)")


def _unit_table_help() -> str:
    from chebnorm.hw.units import UNIT_TARGETS  # the units' registry (a stage)

    targets = list(dict.fromkeys(UNIT_TARGETS.values()))
    return ("table of the unit's evaluator (default: the degree-2 fit of "
            f"{', '.join(targets[:-1])} or {targets[-1]} for psi_max = pi/4)")


def register(sub) -> None:
    """Add the ``chebnorm hw`` subcommand with its own subcommands ``verilog``, ``report``,
    ``unit`` and ``sweep``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); each of the four
        parsers of ``hw`` sets ``func``, its runner: :func:`run_verilog`,
        :func:`run_report`, :func:`run_unit` or :func:`run_sweep`.
    """
    hw = sub.add_parser("hw", help="bit-accurate hardware: Verilog, error budget, sweep",
                        description="Fixed-point Horner evaluators of a coefficient table: "
                        "Verilog checked in Icarus Verilog, sized by Yosys; error budgets "
                        "checked over every input code; design-space sweeps.")
    hsub = hw.add_subparsers(dest="hw_command", metavar="HW_COMMAND")
    hsub.required = True

    v = hsub.add_parser("verilog", help="write the module, its test bench and vectors")
    _design_args(v)
    v.add_argument("--lang", choices=("verilog", "vhdl"), default="verilog",
                   help="HDL of the module and bench: verilog (default; iverilog) or vhdl "
                   "(VHDL-2008, numeric_std, bit-identical; ghdl); both for coefficient and "
                   "piecewise tables")
    v.add_argument("-o", "--output", metavar="DIR", required=True, help="existing folder")
    v.add_argument("--simulate", action="store_true",
                   help="also run the test bench in iverilog (ghdl with --lang vhdl)")
    v.add_argument("--pipelined", action="store_true",
                   help="also write the pipelined variant chebnorm_NAME_pipe (clk, one register "
                   "per Horner step, latency = degree) and its bench")
    v.set_defaults(func=run_verilog)

    r = hsub.add_parser("report", help="error budget, measured errors, costs, Q formats")
    _design_args(r)
    r.add_argument("--json", action="store_true", help="print the report as JSON")
    r.add_argument("--no-synth", action="store_true", help="skip yosys")
    r.add_argument("--no-gappa", action="store_true", help="skip gappa")
    r.add_argument("--target", "--device", dest="target", default=None, metavar="T",
                   help="also map the evaluator on an FPGA device: generic, xc7, xc7-nodsp or "
                   "ice40: LUT/DSP/carry/RAM/FF, Fmax (ice40: nextpnr-ice40; xc7: a model) "
                   "and latency; --device is the same flag")
    r.add_argument("--unit", action="append", default=[], metavar="KIND",
                   help=f"also cost a normalization unit ({', '.join(UNIT_NAMES)}; "
                   "repeatable): model area beside yosys cells; units with an evaluator "
                   "use TABLE and its widths")
    _unit_width_args(r)
    r.set_defaults(func=run_report)

    u = hsub.add_parser("unit", help="Verilog and VHDL of a normalization unit, test benches, "
                        "vectors",
                        description="A normalization unit as synthesizable Verilog and VHDL "
                        "(one netlist, at the generated widths), bit-for-bit equal to the Python "
                        "kernels, with a self-checking test bench in each language.")
    u.add_argument("kind", choices=UNIT_NAMES)
    table = u.add_argument("--table", metavar="TABLE.json", default=None,
                           help="table of the unit's evaluator (default: the degree-2 fit of "
                           "its registered target for psi_max = pi/4)")
    help_when_printed(u, table, _unit_table_help)
    u.add_argument("--in-bits", type=int, default=16, help="evaluator input width, 1..20")
    u.add_argument("--out-bits", type=int, default=16, help="evaluator output width, 1..32")
    u.add_argument("--coef-frac-bits", dest="coef_bits", type=int, default=None, metavar="B",
                   help="coefficient fractional bits (default: the table's own, or out-bits + 4 "
                   "for the default table)")
    deprecated_alias(u, "--coef-bits", "--coef-frac-bits", "coef_bits", type=int, metavar="B")
    u.add_argument("--rounding", default=None,
                   help="classic: trunc (default) or rne quotient; others: the evaluator's")
    _unit_width_args(u)
    u.add_argument("--vectors", type=int, default=5000,
                   help="random and realistic rows each (default 5000; all codes when the "
                   "inputs have at most 16 bits)")
    u.add_argument("--seed", type=int, default=0)
    u.add_argument("-o", "--output", metavar="DIR", required=True, help="existing folder")
    u.add_argument("--simulate", action="store_true",
                   help="also run the test benches in iverilog and, when installed, ghdl")
    u.add_argument("--synth", action="store_true", help="also count cells with yosys")
    u.set_defaults(func=run_unit)

    s = hsub.add_parser("sweep", help="degree x coefficient bits x datapath bits vs area")
    s.add_argument("--target", default=None, help="registered target (default dichotomy)")
    s.add_argument("--psi-max", default=None, help="largest angle between normals (default pi/4)")
    s.add_argument("--degrees", type=int, nargs="+", default=None, help="1..4 (default 1 2 3 4)")
    s.add_argument("--coef-frac-bits", dest="coef_bits", type=int, nargs="+", default=None,
                   metavar="B", help="coefficient fractional bits to try (default 10 14 18)")
    deprecated_alias(s, "--coef-bits", "--coef-frac-bits", "coef_bits", type=int, nargs="+",
                     metavar="B")
    s.add_argument("--acc-bits", type=int, nargs="+", default=None, help="default 14 18")
    s.add_argument("--in-bits", type=int, default=12, help="default 12")
    s.add_argument("--out-bits", type=int, default=12, help="default 12")
    s.add_argument("--rounding", default=None, help="rne (default) or trunc")
    s.add_argument("--no-synth", action="store_true", help="area estimate instead of yosys cells")
    s.add_argument("--segments", nargs="+", default=None, metavar="2^k",
                   help="piecewise sweep of EXPR (--expr, --interval): segment counts x "
                   "--degrees x --coef-frac-bits (see chebnorm design)")
    s.add_argument("--expr", default=None, help="piecewise sweep: the function (default 1/sqrt(x))")
    s.add_argument("--interval", nargs=2, default=None, metavar=("LO", "HI"),
                   help="piecewise sweep: rational endpoints (default 1 4)")
    s.add_argument("-o", "--output", metavar="DIR", required=True, help="existing folder")
    add_parallel_args(s)
    s.set_defaults(func=run_sweep)


def _coefficient_table(table, path, command: str):
    """``table`` (read from ``path``), refused naming ``command`` when it is a
    piecewise table."""
    from chebnorm.approx import CoefficientTable

    if not isinstance(table, CoefficientTable):
        raise ValueError(f"piecewise table {str(path)!r}: {command} reads a coefficient "
                         f"table; accepted: a table fitted without --segments, --segment-by "
                         f"and --centered")
    return table


def _analyze(args, table, synth: bool, gappa: bool):
    from chebnorm.hw.report import analyze

    return analyze(table, args.in_bits, args.out_bits, coef_frac_bits=args.coef_bits,
                   acc_bits=args.acc_bits, rounding=args.rounding, x_frac_bits=args.x_frac_bits,
                   y_frac_bits=args.y_frac_bits, gappa=gappa, synth=synth)


def _simulator(language: str):
    """The runner of ``language``'s benches: Icarus Verilog or GHDL."""
    if language == "vhdl":
        from chebnorm.hw.run_vhdl import simulate_vhdl
        return simulate_vhdl
    from chebnorm.hw.run_verilog import simulate
    return simulate


def run_verilog(args) -> int:
    """Run ``chebnorm hw verilog``: write the Verilog (or with
    ``--lang vhdl`` VHDL) module of a table, its test bench, vectors and report
    into the folder ``-o``; a piecewise table goes to
    :func:`hw_verilog`.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm hw verilog`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 on success, 1 when ``--simulate`` finds a mismatch.

    Raises
    ------
    ValueError
        When the output exists and is not a folder, or ``--pipelined`` is asked of a
        degree-0 table (:func:`chebnorm.cli.main` prints it as one line on stderr and
        exits with status 2).
    """
    from chebnorm import __version__
    from chebnorm.hw.hdl import pipelined_name
    from chebnorm.approx import PiecewiseTable, load_table
    from chebnorm.hw.report import hdl_outputs, write_outputs

    _check_output(args.output)
    table = load_table(args.table)
    if isinstance(table, PiecewiseTable):
        return hw_verilog(args, table)
    report = _analyze(args, table, synth=False, gappa=False)
    if args.pipelined and report.design.degree < 1:
        raise ValueError(f"table {report.design.table.name!r} has degree 0: nothing to "
                         f"pipeline; accepted: --pipelined with degree >= 1")
    # --lang vhdl: the same design as VHDL, simulated by GHDL
    files = hdl_outputs(report, args.lang, version=__version__, command=command_line(args),
                        pipelined=args.pipelined)
    files[f"{report.design.module_name}_report.json"] = json.dumps(
        report.as_dict(), sort_keys=True, indent=2, allow_nan=False) + "\n"
    refuse_table_overwrite(args, files)
    for path in write_outputs(args.output, files):
        print(path)
    if args.simulate:
        simulate = _simulator(args.lang)
        names = [report.design.module_name] + \
            ([pipelined_name(report.design)] if args.pipelined else [])
        ok = True
        for name in names:
            res = simulate(args.output, name)
            print(res.line)
            ok = ok and res.passed
        return 0 if ok else 1
    return 0


def _unit(args, kind, table=None, rounding=...):
    """The unit ``kind`` of the command's widths (``rounding``: instead of ``--rounding``)."""
    from chebnorm.hw.units import design_unit

    rounding = args.rounding if rounding is ... else rounding
    return design_unit(kind, frac_bits=14 if args.frac_bits is None else args.frac_bits,
                       comp_bits=args.comp_bits, table=table,
                       in_bits=args.in_bits, out_bits=args.out_bits, coef_bits=args.coef_bits,
                       rounding=rounding, log_m=4 if args.log_m is None else args.log_m,
                       guard=args.guard)


def _refuse_unit_options(args, kinds) -> None:
    """--log-m and --guard size the stepper; the unit widths size a unit: refused
    where no such unit is asked for (they would do nothing)."""
    if "stepper" not in kinds:
        refuse_unused(args, "to the stepper unit (--unit stepper)",
                      **{"--log-m": "log_m", "--guard": "guard"})
    if not kinds:
        refuse_unused(args, "with --unit KIND", **{"--vector-frac-bits": "frac_bits",
                                                   "--comp-bits": "comp_bits"})


def run_report(args) -> int:
    """Run ``chebnorm hw report``: the error budget by part, the measured
    error, the cost and the Q formats of a table's hardware evaluator (a
    piecewise table goes to :func:`hw_report`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm hw report`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 on success.

    Raises
    ------
    ValueError
        On an unknown ``--target``, a ``--target`` with ``--no-synth``, or an option
        that does nothing for the table given (:func:`chebnorm.cli.main` prints it as
        one line on stderr and exits with status 2).
    """
    from chebnorm.approx import PiecewiseTable, load_table
    from chebnorm.hw.units import analyze_unit, get_unit, table_matches

    for kind in args.unit:
        get_unit(kind)  # refuses an unknown name, listing the registered ones
    _refuse_unit_options(args, args.unit)
    check_report_target(args)
    table = load_table(args.table)
    if isinstance(table, PiecewiseTable) and not args.unit:
        return hw_report(args, table)
    table = _coefficient_table(table, args.table, "hw report --unit")
    report = _analyze(args, table, synth=not args.no_synth, gappa=not args.no_gappa)
    fig = None
    if args.target is not None:
        from chebnorm.hw.hdl import module_text
        from chebnorm.hw.targets import target_figures

        fig = target_figures(module_text(report.design), report.design.module_name,
                             args.target)
    units = []
    for kind in dict.fromkeys(args.unit):
        has_evaluator = get_unit(kind).target is not None
        # --rounding is the evaluator's; the classic unit keeps its own default quotient
        rounding = args.rounding if has_evaluator else None
        # a unit whose function is not the report's table gets its own target's table
        table = report.design.table
        if has_evaluator and not table_matches(kind, table):
            table = None
        unit = _unit(args, kind, table=table, rounding=rounding)
        units.append(analyze_unit(unit, synth=not args.no_synth))
    if args.json:
        d = report.as_dict()
        if units:
            d["units"] = [u.as_dict() for u in units]
        if fig is not None:
            d["target"] = {k: v for k, v in fig.items() if k not in ("line", "timing")}
        print_json(d)
    else:
        print("\n".join(report.lines()))
        if fig is not None:
            print(f"target {fig['line']}")
            print(f"timing: {fig['timing']}")
        for u in units:
            print("\n".join(u.lines()))
    return 0


def check_report_target(args) -> None:
    """``hw report --target T``: a registered target, and synthesis allowed.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``hw report`` command line; nothing is checked when it has no
        ``target`` or it is None.

    Raises
    ------
    ValueError
        When ``args.target`` is not a registered device target, or is given with
        ``--no-synth`` (the target's mapping needs yosys).
    """
    if getattr(args, "target", None) is None:
        return
    from chebnorm.hw.targets import get_target

    get_target(args.target)
    if args.no_synth:
        raise ValueError(f"--target {args.target} maps the design with yosys; accepted: "
                         f"--target without --no-synth")


def run_unit(args) -> int:
    """Run ``chebnorm hw unit``: the Verilog and VHDL of a normalization unit
    (``--kind``), their test benches, vectors and report written into the folder
    ``-o``, simulated with ``--simulate`` (Icarus Verilog, and GHDL when installed).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm hw unit`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 on success, 1 when ``--simulate`` finds a mismatch.

    Raises
    ------
    ValueError
        When the output exists and is not a folder, ``--table`` is a piecewise table, or
        an option does not apply to the unit's kind (:func:`chebnorm.cli.main` prints it
        as one line on stderr and exits with status 2).
    """
    from chebnorm import __version__
    from chebnorm.hw.report import write_outputs
    from chebnorm.hw.units import analyze_unit, unit_outputs
    from chebnorm.approx import load_table
    from chebnorm.core.tools import which
    from chebnorm.hw.run_verilog import simulate

    _check_output(args.output)
    _refuse_unit_options(args, [args.kind])
    table = (_coefficient_table(load_table(args.table), args.table, "hw unit --table")
             if args.table else None)
    unit = _unit(args, args.kind, table)
    rep = analyze_unit(unit, synth=args.synth)
    files = unit_outputs(unit, count=args.vectors, seed=args.seed, version=__version__,
                         command=command_line(args))
    files[f"{unit.module_name}_report.json"] = json.dumps(
        rep.as_dict(), sort_keys=True, indent=2, allow_nan=False) + "\n"
    refuse_table_overwrite(args, files)
    for path in write_outputs(args.output, files):
        print(path)
    print("\n".join(rep.lines()))
    if args.simulate:
        results = [("Icarus Verilog", simulate(args.output, unit))]
        if which("ghdl") is not None:   # the VHDL beside it, when GHDL is installed
            from chebnorm.hw.run_vhdl import simulate_vhdl

            results.append(("GHDL", simulate_vhdl(args.output, unit)))
        for simulator, res in results:   # one verdict per language, each naming its simulator
            print(f"{res.line} [{simulator}]")
        return 0 if all(res.passed for _, res in results) else 1
    return 0


def run_sweep(args) -> int:
    """Run ``chebnorm hw sweep``: the grid of degree x coefficient bits x
    datapath bits of a target against area (or, with ``--segments``, the
    piecewise grid of :func:`hw_sweep_piecewise`), its CSV
    and Pareto plot written into the folder ``-o``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm hw sweep`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 on success.

    Raises
    ------
    ValueError
        When the output exists and is not a folder, an option of the other sweep is
        given, or ``--psi-max`` is out of the target's range (:func:`chebnorm.cli.main`
        prints it as one line on stderr and exits with status 2).
    """

    from chebnorm.core.numeric import format_down

    from pathlib import Path

    from chebnorm.approx import get_target
    from chebnorm.core.files import write_folder
    from chebnorm.hw.sweep import DEFAULT_ACC_BITS, DEFAULT_COEF_BITS, DEFAULT_DEGREES, sweep

    out = Path(args.output)
    _check_output(out)
    if args.segments is not None:
        refuse_unused(args, "to the target sweep (without --segments)", **{
            "--target": "target", "--psi-max": "psi_max", "--acc-bits": "acc_bits",
            "--rounding": "rounding"})
        return hw_sweep_piecewise(args)
    refuse_unused(args, "to the piecewise sweep (with --segments)",
                  **{"--expr": "expr", "--interval": "interval"})
    args.target = "dichotomy" if args.target is None else args.target
    args.psi_max = "pi/4" if args.psi_max is None else args.psi_max
    get_target(args.target).interval(args.psi_max)  # read --psi-max (exactly, safely) up front
    res = sweep(args.target, degrees=args.degrees or DEFAULT_DEGREES,
                coef_bits=args.coef_bits or DEFAULT_COEF_BITS,
                acc_bits=args.acc_bits or DEFAULT_ACC_BITS, in_bits=args.in_bits,
                out_bits=args.out_bits, rounding=args.rounding or "rne", psi_max=args.psi_max,
                synth=not args.no_synth, workers=args.workers, scheduler=args.scheduler)
    csv, png = res.csv(), res.plot_png()
    stem = f"sweep_{args.target}"  # only now: nothing is created when the sweep fails
    write_folder(out, {f"{stem}.csv": csv, f"{stem}.png": png})
    print(out / f"{stem}.csv")
    print(out / f"{stem}.png")
    best = res.cheapest
    if best is None:
        print("no design stays at or under half a level of 8-bit shading")
    else:
        area = f"{best.yosys_cells} yosys cells" if best.yosys_cells is not None else \
            f"~{best.area_fa:.0f} FA (estimate)"
        print(f"cheapest design at or under half a level: degree {best.degree}, coefficient "
              f"bits {best.coef_bits}, accumulator bits {best.acc_bits or '-'}: {area}, "
              f"{format_down(best.shading_levels, '.4f')} levels, "
              f"{format_down(best.max_error_lsb, '.2f')} LSB")
    return 0


def _check_output(path) -> None:
    """-o DIR: an existing folder, or a new one to create once everything has passed."""
    from pathlib import Path

    p = Path(path)
    if p.exists() and not p.is_dir():
        raise ValueError(f"output {str(path)!r} exists and is not a folder; accepted: a folder "
                         f"(created if missing)")


def _piecewise_design(args, table):
    """The hardware design of the piecewise ``table`` (read from ``args.table``)."""
    from chebnorm.hw.piecewise import design_piecewise

    for opt in ("coef_bits", "acc_bits", "x_frac_bits"):
        if getattr(args, opt, None) is not None:
            raise ValueError(f"--{opt.replace('_', '-')} is not available for a piecewise table "
                             f"(its coefficient format is the table's; the widths are sized "
                             f"exactly); accepted: --in-bits, --out-bits and --y-frac-bits")
    if getattr(args, "rounding", "rne") != "rne":
        raise ValueError(f"rounding {args.rounding!r}: a piecewise evaluator rounds to nearest "
                         f"even; accepted: rne")
    # --y-frac-bits: the output's last place 2^-F stated (chebnorm design --lsb -F)
    return design_piecewise(table, args.in_bits, args.out_bits,
                            out_frac_bits=getattr(args, "y_frac_bits", None))


def hw_verilog(args, table) -> int:
    """``chebnorm hw verilog`` of a piecewise table (called by :mod:`chebnorm.cli.hw`).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``hw verilog`` command line.
    table : chebnorm.approx.PiecewiseTable
        The table read from ``args.table``.

    Returns
    -------
    int
        The exit status: 0, or 1 when ``--simulate`` finds a mismatch.

    Raises
    ------
    ValueError
        When an option does not apply to a piecewise table (``--pipelined``,
        ``--coef-bits``-style widths, a rounding other than to nearest).
    """
    from pathlib import Path

    from chebnorm import __version__
    from chebnorm.core.files import write_folder
    from chebnorm.hw.piecewise import piecewise_outputs

    if getattr(args, "pipelined", False):
        raise ValueError("--pipelined is not available for a piecewise table; accepted: the "
                         "combinational evaluator")
    language = getattr(args, "lang", "verilog")  # VHDL: the same design, simulated by GHDL
    if language == "vhdl":
        from chebnorm.hw.run_vhdl import simulate_vhdl as simulate
    else:
        from chebnorm.hw.run_verilog import simulate
    d = _piecewise_design(args, table)
    files = piecewise_outputs(d, version=__version__, command=command_line(args),
                              language=language)
    out = Path(args.output)
    refuse_table_overwrite(args, files)
    for path in write_folder(out, dict(sorted(files.items()))):
        print(path)
    if args.simulate:
        res = simulate(out, d)
        print(res.line)
        return 0 if res.passed else 1
    return 0


def hw_report(args, table) -> int:
    """``chebnorm hw report`` of a piecewise table: error budget by part, measured error, cells.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``hw report`` command line.
    table : chebnorm.approx.PiecewiseTable
        The table read from ``args.table``.

    Returns
    -------
    int
        The exit status, 0.

    Raises
    ------
    ValueError
        When an option does not apply to a piecewise table (the coefficient
    and datapath widths, a ``--rounding`` other than rne).
    """
    from chebnorm.core.numeric import format_down, format_up
    from chebnorm.hw.piecewise import piecewise_cells
    from chebnorm.hw.piecewise_search import model_cost

    d = _piecewise_design(args, table)
    b, m = d.budget(), d.measure()
    cells = None if args.no_synth else piecewise_cells(d).cells
    rep = {"module": d.module_name, "segments": d.table.segment_count, "degree": d.degree,
           "in_bits": d.in_bits, "out_bits": d.out_bits,
           "coef_frac_bits": d.table.coef_frac_bits, "rom_word_bits": list(d.rom_bits),
           "acc_frac_bits": d.acc_frac_bits, "y_format": d.y_format.as_dict(), "budget": b,
           "measured": m, "within_budget": m["max_error"] <= b["total"],
           "model_cost": model_cost(d), "yosys_cells": cells}
    fig = None
    if getattr(args, "target", None) is not None:
        from chebnorm.hw.targets import target_figures

        from chebnorm.hw.hdl import module_text

        fig = target_figures(module_text(d, "verilog"), d.module_name, args.target)
        rep["target"] = {k: v for k, v in fig.items() if k not in ("line", "timing")}
    if args.json:
        rep["y_format"]["offset"] = float(rep["y_format"]["offset"])
        print_json(rep)
        return 0
    print(f"{d.module_name}: {d.table.segment_count} segments x degree {d.degree}, "
          f"{d.in_bits}-bit in / {d.out_bits}-bit out, ROM words {list(d.rom_bits)} bits")
    print(f"error budget |y - f(x)| <= {format_up(b['total'], '.4e')} = approximation "
          f"{format_up(b['approximation'], '.4e')} + Horner rounding "
          f"{format_up(b['horner_rounding'], '.4e')} + output "
          f"rounding {format_up(b['output_rounding'], '.4e')} "
          f"({format_up(b['total'] / b['y_lsb'], '.3f')} LSB)")
    print(f"measured over all {m['codes']} codes: max |y - f(x)| = "
          f"{format_down(m['max_error'], '.4e')} at code "
          f"{m['at_code']} ({'within' if rep['within_budget'] else 'OVER'} the budget)")
    print(f"cost: {'-' if cells is None else cells} yosys cells, model {rep['model_cost']:.0f}")
    if fig is not None:
        print(f"target {fig['line']}")
        print(f"timing: {fig['timing']}")
    return 0


def hw_sweep_piecewise(args) -> int:
    """``chebnorm hw sweep --segments ...``: the piecewise grid, CSV and Pareto plot.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``hw sweep`` command line (with ``--segments``).

    Returns
    -------
    int
        The exit status, 0.

    Raises
    ------
    ValueError
        When a ``--segments`` value is not a power of two in range, or the grid's
    expression (``--expr``, default ``1/sqrt(x)``), interval (default 1 to 4)
    or widths are refused by :func:`chebnorm.hw.piecewise_search.grid`.
    """
    from pathlib import Path

    from chebnorm.core.files import write_folder
    from chebnorm.approx.piecewise_table import parse_segments
    from chebnorm.hw.piecewise_search import grid

    res = grid(args.expr or "1/sqrt(x)", tuple(args.interval or ("1", "4")), args.in_bits,
               args.out_bits, index_bits=[parse_segments(v) for v in args.segments],
               degrees=args.degrees or (1, 2, 3), coef_frac_bits=args.coef_bits or (12, 16, 20),
               synth=not args.no_synth, **parallel_kwargs(args))
    out = Path(args.output)
    write_folder(out, {"sweep_piecewise.csv": res.csv(), "sweep_piecewise.png": res.plot_png()})
    print(out / "sweep_piecewise.csv")
    print(out / "sweep_piecewise.png")
    return 0
