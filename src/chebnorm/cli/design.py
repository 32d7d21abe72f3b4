"""``chebnorm design``: the cheapest certified piecewise hardware meeting an error bound;
also the piecewise-table paths of ``chebnorm hw verilog`` and ``hw report``."""

from __future__ import annotations

import math

from .common import command_line, max_error_value, print_json, refuse_table_overwrite, shell_words
from .parallel_options import add_parallel_args, parallel_kwargs


def register(sub) -> None:
    """Add the ``chebnorm design`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); the new parser's ``func``
        default is :func:`run`.
    """
    p = sub.add_parser("design", help="cheapest certified piecewise evaluator meeting --max-error",
                       description="Search segments x degree x coefficient bits for the "
                       "cheapest piecewise ROM + Horner evaluator (yosys cells, or the model "
                       "estimate without yosys) whose certified error meets --max-error; write "
                       "the Pareto front as CSV and PNG and say why the winner wins.")
    p.add_argument("expr", metavar="EXPR", help='function in sympy syntax, e.g. "1/sqrt(x)"')
    p.add_argument("--var", default="x", help="the variable of EXPR (default x)")
    p.add_argument("--interval", nargs=2, metavar=("LO", "HI"), required=True,
                   help="rational endpoints: the input code maps onto [LO, HI)")
    p.add_argument("--in-bits", type=int, required=True, help="input code width, 2..20")
    p.add_argument("--out-bits", type=int, required=True, help="output code width, 1..32")
    acc = p.add_mutually_exclusive_group(required=True)
    acc.add_argument("--max-error", default=None, metavar="E",
                     help="certified bound on |y - f(x)|, > 0 (a number or e.g. 2^-16)")
    acc.add_argument("--faithful", action="store_true",
                     help="certified |y - f(x)| < 1 unit of the output's last place (FloPoCo's "
                     "contract)")
    acc.add_argument("--correctly-rounded", action="store_true",
                     help="every output code the proved rounding of f (a plain table)")
    p.add_argument("--degrees", type=int, nargs="+", default=[1, 2, 3], help="default 1 2 3")
    p.add_argument("--max-segments", default=None, metavar="2^k",
                   help="largest segment count tried, 2^0..2^min(12, in-bits - 1) (default "
                   "2^8, or 2^(in-bits - 1) when in-bits <= 8: at most half the input codes)")
    p.add_argument("--no-synth", action="store_true", help="model estimate instead of yosys")
    p.add_argument("--target", default="generic", metavar="T",
                   help="price by this target's mapping: generic (yosys cells; default), xc7, "
                   "xc7-nodsp (LUT equivalents: a DSP48E1 = 264.2 LUTs) or ice40 (with "
                   "nextpnr-ice40 Fmax of the winner)")
    p.add_argument("--frequency", default=None, metavar="MHZ",
                   help="pipeline the winner to this clock (MHz > 0): registers at its stage "
                   "boundaries until nextpnr-ice40's Fmax (ice40) or the sta model's (xc7, "
                   "xc7-nodsp) reaches it, or the highest reached is said; the pipelined RTL "
                   "is simulated cycle by cycle over every input code before it is written")
    p.add_argument("--index", choices=("uniform", "exponent"), default="uniform",
                   help="uniform (default): the code maps onto [LO, HI), its top bits pick "
                   "the segment; exponent: 1/sqrt(x) only, x = code / 2^in-bits with --interval "
                   "2^-m 1, a leading-zero count picks the binade pair, the output is a "
                   "mantissa (--out-bits) and a shift (chebnorm.hw.exponent)")
    p.add_argument("--name", default=None,
                   help="module name (an identifier; default: from EXPR, the interval, the "
                   "widths and the accuracy, e.g. rsqrt_1_4_i8_o8_faithful, so different "
                   "designs' modules coexist in one build)")
    p.add_argument("-o", "--output", metavar="DIR", required=True,
                   help="folder for design_NAME.csv/.png (created if missing)")
    add_parallel_args(p)
    p.set_defaults(func=run)


def run(args) -> int:
    """Run ``chebnorm design``: the cheapest certified piecewise evaluator
    (or, by synthesis, another architecture) meeting ``--max-error`` (or
    ``--faithful``/``--correctly-rounded``) on the target device, its CSV and
    Pareto plot written into the folder ``-o``, and the command that reproduces
    the winner.

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
        When the output exists and is not a folder, ``--max-error`` is not a finite
        number > 0, ``--frequency`` is given without a device's timing,
        ``--faithful``/``--correctly-rounded`` is combined with ``--no-synth``, or no
        design meets the accuracy asked (:func:`chebnorm.cli.main` prints it as one line
        on stderr and exits with status 2).
    """
    from pathlib import Path

    from chebnorm.core.textsafe import identifier
    from chebnorm.hw.targets import get_target

    if getattr(args, "name", None) is None:
        args = _with_default_name(args)
    if getattr(args, "index", "uniform") == "exponent":
        from .design_exponent import run_exponent

        return run_exponent(args)
    name = identifier(args.name, field="name")
    target = get_target(args.target).name
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise ValueError(f"output {args.output!r} exists and is not a folder; accepted: a folder")
    accuracy = ("faithful" if args.faithful else "correctly-rounded" if args.correctly_rounded
                else "max-error")
    max_error = max_error_value(args.max_error) if accuracy == "max-error" else None
    frequency = _frequency(args, target)
    if accuracy != "max-error" and args.no_synth:
        raise ValueError(f"--{accuracy} compares architectures by synthesis; accepted: without "
                         f"--no-synth (or --max-error E with --no-synth)")
    if args.no_synth:
        others, res = [], _search(args, name, target, max_error)
    else:
        others, res = _synth_both(args, name, target, accuracy, max_error)
        if res is None:   # correctly rounded: a plain table or nothing
            return _write_architectures(args, out, name, others, None)
    csv, png = res.csv(), res.plot_png()
    files = {f"design_{name}.csv": csv, f"design_{name}.png": png}
    synthesized = res.winner.target_cost is not None or res.winner.yosys_cells is not None
    best = _best_other(others)
    if best is not None and (best.cost.score < _score(res.winner) or not synthesized):
        # the plot shows the one-width search: say that another architecture won
        files[f"design_{name}.png"] = res.plot_png(
            winner="best one-width piecewise",
            note=f"winner: {best.architecture}, score {best.cost.score:.1f} (not on this plot)")
        return _write_architectures(args, out, name, others, res, files)
    # the winner's place and route may fail (too large for the device): before writing
    figures = winner_figures(res) if res.winner.target_cost is not None and \
        frequency is None else []
    if others:
        files[f"design_{name}_architectures.csv"] = _architectures_csv(others, res, winner=None)
    if frequency is not None:  # the one-width winner has no cut points: timed as it is
        figures, _ = _pipelined(args, _winner_design(res), frequency)
    write_folder_print(out, files)
    print("\n".join(res.explain()))
    w = res.winner
    if figures:
        print("\n".join(figures))
    for c in others:
        print(f"  {c.line()}" + (" -- costlier than the winner" if c.cost is not None else ""))
    fit = ["chebnorm", "fit", args.expr, "--var", args.var, "--interval", *args.interval,
           "--degree", w.degree, "--segments", w.segments, "--kind", "minimax",
           "--coef-frac-bits", w.coef_frac_bits, "-o", "T.json"]
    verilog = ["chebnorm", "hw", "verilog", "T.json", "--in-bits", args.in_bits, "--out-bits",
               args.out_bits, "-o", "DIR", "--simulate"]
    print(f"reproduce: {shell_words(fit)} && {shell_words(verilog)}")
    return 0


def _with_default_name(args):
    """A copy of ``args`` whose ``name`` is the spec's default
    (:func:`chebnorm.core.textsafe.design_name`): the expression, interval,
    widths, accuracy and index, so two designs' modules never collide."""
    import argparse

    from chebnorm.core.textsafe import design_name

    if getattr(args, "faithful", False):
        tags = ["faithful"]
    elif getattr(args, "correctly_rounded", False):
        tags = ["cr"]
    else:  # by value: 2^-6 and 0.015625 name the same design
        try:
            e = max_error_value(args.max_error)
        except ValueError:   # refused with its message by run()
            e = None
        m, k = math.frexp(e) if e is not None else (None, None)
        tags = ["e", str(args.max_error) if e is None else f"2^{k - 1}" if m == 0.5 else repr(e)]
    if getattr(args, "index", "uniform") == "exponent":
        tags.append("lz")
    name = design_name(args.expr, tuple(args.interval), args.in_bits, args.out_bits,
                       var=args.var, tags=tags)
    return argparse.Namespace(**dict(vars(args), name=name))


def _frequency(args, target):
    """``--frequency`` in MHz (None without it), checked with the target and synthesis."""
    if getattr(args, "frequency", None) is None:
        return None
    from chebnorm.hw.pipeline import check_frequency

    if not str(args.frequency).isascii():   # float() reads other scripts' digits
        raise ValueError(f"--frequency {str(args.frequency)[:40]!r}: accepted: a finite number "
                         f"of MHz > 0 in ASCII digits, e.g. 100")
    freq = check_frequency(args.frequency, "--frequency")
    if target == "generic" or args.no_synth:
        raise ValueError(f"--frequency {args.frequency} needs a device's timing; accepted: "
                         f"--target ice40, xc7 or xc7-nodsp, without --no-synth")
    return freq


def _pipelined(args, design, frequency):
    """Pipeline ``design`` to ``frequency`` (:mod:`chebnorm.hw.pipeline`) and
    simulate the pipelined RTL over every code (Icarus Verilog; GHDL too for
    its VHDL): (figure lines, the pipelined design). The shortfall, if any, is
    one warning line on stderr."""
    import sys
    import warnings

    from chebnorm.hw.pipeline import (FrequencyWarning, cut_names, pipeline_to_frequency,
                                      verify_pipelined)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FrequencyWarning)  # printed below, once
        res = pipeline_to_frequency(design, args.target, frequency)
    d = res.design
    tried = [f"{st.latency}: {st.fmax_mhz:.2f}"
             + (f" (after {', '.join(cut_names(design, st.cuts))})" if st.cuts else "")
             for st in res.steps]
    lines = [f"timing: {res.line()}", f"measured (latency: Fmax MHz): {', '.join(tried)}"]
    if res.latency > 0:
        sim = verify_pipelined(d)
        if not sim.passed:
            raise ValueError(f"internal: the pipelined RTL of {d.module_name} disagrees with the "
                             f"bit-accurate model ({sim.line}); nothing written")
        lines.append(f"cycle-accurate simulation (Icarus Verilog, every code): {sim.line}")
        vhdl = _verify_vhdl(d)
        if vhdl is not None:
            lines.append(f"cycle-accurate simulation (GHDL, every code): {vhdl}")
    if not res.met:
        print(f"chebnorm: warning: {res.shortfall()}", file=sys.stderr)
    return lines, d


def _verify_vhdl(d):
    """GHDL's verdict on the pipelined VHDL over every code (None without GHDL)."""
    import tempfile

    from chebnorm.core.tools import which

    if which("ghdl") is None:
        return None
    from pathlib import Path

    from chebnorm.hw.pipeline import design_files
    from chebnorm.hw.vhdl import simulate_vhdl

    with tempfile.TemporaryDirectory() as tmp:
        for fname, text in design_files(d, "vhdl").items():
            (Path(tmp) / fname).write_text(text, encoding="utf-8")
        res = simulate_vhdl(tmp, d)
    if not res.passed:
        raise ValueError(f"internal: the pipelined VHDL of {d.module_name} disagrees with the "
                         f"bit-accurate model ({res.line}); nothing written")
    return res.line


def _winner_design(res):
    """The one-width search's winning design."""
    return next(res.designs[k] for k, p in zip(sorted(res.designs), res.points)
                if p is res.winner)


def _search(args, name, target, max_error, bound=None, synth=None, workers=None):
    """The one-width piecewise Pareto search (:mod:`chebnorm.hw.piecewise_search`);
    ``bound``: the other architectures' best synthesized score (a point that
    cannot beat it is not synthesized); ``synth``: False for the model only
    (default: unless ``--no-synth``); ``workers``: instead of ``--workers``."""
    from chebnorm.approx.piecewise_table import parse_segments
    from chebnorm.core.numeric import format_up
    from chebnorm.hw.piecewise_search import search

    res = search(args.expr, tuple(args.interval), args.in_bits, args.out_bits, max_error,
                 degrees=args.degrees, max_index_bits=_max_index_bits(args, parse_segments),
                 var=args.var, synth=not args.no_synth if synth is None else synth,
                 name=name, target=target,
                 bound=bound, **dict(parallel_kwargs(args), **(
                     {} if workers is None else {"workers": workers, "scheduler": None})))
    if res.winner is None:  # one line, exit 2, nothing written (docs/cli.md)
        best = min(res.points, key=lambda p: p.total_bound)
        raise ValueError(f"no design meets --max-error {max_error:.4g}: the smallest "
                         f"certified error reached is {format_up(best.total_bound, '.4g')} "
                         f"(degree {best.degree}, "
                         f"{best.segments} segments, {best.coef_frac_bits} coefficient bits); "
                         f"accepted: a larger --max-error, or more --max-segments, --degrees "
                         f"or --out-bits")
    return res


def _synth_both(args, name, target, accuracy, max_error):
    """The other architectures and the one-width search, built and evaluated,
    then synthesized in one queue in order of their lower bounds, each skipped
    once it cannot beat the best score so far
    (:func:`chebnorm.hw.architectures.synthesize_with_search`).
    Returns ``(others, result)`` (``result`` None for a correctly rounded spec)."""
    from concurrent.futures import ThreadPoolExecutor

    from chebnorm.core.tools import which
    from chebnorm.hw.architectures import cheapest_candidates, synthesize_with_search

    built = _architectures(args, name, target, accuracy, max_error)
    if accuracy == "correctly-rounded" or which("yosys") is None:
        others = _synth_others(args, built, target)   # yosys missing: its error, one line
        if accuracy == "correctly-rounded":
            return others, None
    if accuracy == "faithful":  # the piecewise search's bound must stay below one ulp
        max_error = math.nextafter(min(c.ulp for c in built if c.ulp is not None), 0.0)
    # the search evaluates its points here, in one thread (no worker start-up to pay),
    # while yosys maps the first round of candidates; its points join from round two
    with ThreadPoolExecutor(max_workers=1) as pool:
        job = pool.submit(_search, args, name, target, max_error, synth=False, workers=1)
        try:
            others, res = synthesize_with_search(built, job, target, **parallel_kwargs(args))
        finally:
            job.cancel()
    return cheapest_candidates(others), res


def _architectures(args, name, target, accuracy, max_error):
    """The sized piecewise, multipartite and plain-table candidates, built and
    priced by the target's model (synthesized by :func:`_synth_others`)."""
    from chebnorm.hw.architectures import build_candidates

    degrees = sorted(set(args.degrees))
    # the sized search starts where a one-width design of each degree first meets the
    # error (a cheap model-only walk); four index bits below it when unknown
    return build_candidates(args.expr, tuple(args.interval), args.in_bits, args.out_bits,
                            accuracy=accuracy, max_error=max_error, degrees=degrees,
                            k_start={d: max(0, min(args.in_bits - 2, 3 + 2 * (3 - d)))
                                     for d in degrees},
                            var=args.var, name=name, target=target, **parallel_kwargs(args))


def _synth_others(args, others, target):
    """Synthesize the candidates the model cannot rule out (the cheapest model
    first), and keep the cheapest per degree."""
    from chebnorm.hw.architectures import cheapest_candidates, synthesize_candidates

    return cheapest_candidates(synthesize_candidates(others, target, **parallel_kwargs(args)))


def _score(point) -> float:
    """A search point's figure on its target (yosys cells on generic)."""
    if point.target_cost is not None:
        return point.target_cost.score
    return float(point.cost)


def _best_other(others):
    built = [c for c in others if c.design is not None and c.cost is not None]
    return min(built, key=lambda c: (c.cost.score, c.architecture)) if built else None


def _architectures_csv(others, res, winner) -> str:
    import csv as csvmod
    import io

    from chebnorm.core.numeric import format_up

    from chebnorm.core.textsafe import csv_cell

    buf = io.StringIO()
    w = csvmod.writer(buf, lineterminator="\n")
    w.writerow(["architecture", "description", "score", "cells", "luts", "dsps", "carries",
                "brams", "error", "ulp", "winner", "note"])
    if res is not None:
        p = res.winner
        c = p.target_cost
        w.writerow(["piecewise", csv_cell(p.describe()), f"{_score(p):.1f}",
                    "" if c is None else c.cells, "" if c is None else c.luts,
                    "" if c is None else c.dsps, "" if c is None else c.carries,
                    "" if c is None else c.brams, f"{format_up(p.total_bound, '.6e')}", "",
                    int(winner is None), ""])
    for o in others:
        c = o.cost
        w.writerow([o.architecture, csv_cell(o.description),
                    "" if c is None else f"{c.score:.1f}", "" if c is None else c.cells,
                    "" if c is None else c.luts, "" if c is None else c.dsps,
                    "" if c is None else c.carries, "" if c is None else c.brams,
                    "" if o.error is None else f"{format_up(o.error, '.6e')}",
                    "" if o.ulp is None else f"{o.ulp:.6e}", int(o is winner), csv_cell(o.note)])
    return buf.getvalue()


def _write_architectures(args, out, name, others, res, files=None) -> int:
    """A winner from another architecture: its Verilog and VHDL beside the CSVs."""
    from chebnorm import __version__
    from chebnorm.hw.targets import get_target

    best = _best_other(others)
    if best is None:
        raise ValueError("no architecture meets the accuracy asked (" + "; ".join(
            c.line() for c in others) + "); accepted: more --out-bits, or --faithful / "
            "--max-error instead of --correctly-rounded")
    files = dict(files or {})
    files[f"design_{name}_architectures.csv"] = _architectures_csv(others, res, best)
    d = best.design
    cmd = command_line(args)
    figures = []
    if getattr(args, "frequency", None) is not None:  # checked by _frequency
        from chebnorm.hw.pipeline import check_frequency

        figures, d = _pipelined(args, d, check_frequency(args.frequency))
    if hasattr(d, "vhdl"):
        files[f"{d.module_name}.v"] = d.verilog(version=__version__, command=cmd)
        files[f"{d.module_name}.vhd"] = d.vhdl(version=__version__, command=cmd)
    else:
        from chebnorm.hw.hdl import module_text

        files[f"{d.module_name}.v"] = module_text(d, "verilog", version=__version__, command=cmd)
        files[f"{d.module_name}.vhd"] = module_text(d, "vhdl", version=__version__, command=cmd)
    if not figures and get_target(args.target).name != "generic":  # may fail: before writing
        from chebnorm.hw.targets import target_figures

        fig = target_figures(best.verilog, d.module_name, args.target, cost=best.cost,
                             latency=getattr(d, "latency", 0))
        figures = [f"winner {fig['line']}", f"timing: {fig['timing']}"]
    write_folder_print(out, files)
    print(f"winner: {best.line()}")
    if figures:
        print("\n".join(figures))
    if res is not None:
        w = res.winner
        why = (f"score {_score(w):.1f}, costlier than the winner" if w.target_cost is not None
               or w.yosys_cells is not None else "not synthesized: its model cannot beat the "
               "winner")
        print(f"  piecewise (one width): {w.describe()} -- {why}")
    for c in others:
        if c is not best:
            print(f"  {c.line()}" + (" -- costlier than the winner" if c.cost is not None else ""))
    return 0


def write_folder_print(out, files) -> None:
    """Write ``files`` into the folder ``out`` (all or none) and print each path.

    Parameters
    ----------
    out : pathlib.Path
        The output folder (created if missing; see
        :func:`chebnorm.core.files.write_folder`).
    files : dict of str to (str or bytes)
        File name -> content, written in one step.
    """
    from chebnorm.core.files import write_folder

    for path in write_folder(out, dict(sorted(files.items()))):
        print(path)


def winner_figures(res) -> list[str]:
    """The winner's figures on the search's target: its mapping and its timing
    (nextpnr-ice40 Fmax on ice40, the yosys sta model on xc7).

    Parameters
    ----------
    res : chebnorm.hw.piecewise_search.SearchResult
        A finished one-width search whose winner has a target cost.

    Returns
    -------
    list of str
        Two lines: ``"winner ..."`` (the mapping) and ``"timing: ..."``.
    """
    from chebnorm.hw.targets import target_figures

    key = next(k for k, p in zip(sorted(res.designs), res.points) if p is res.winner)
    d = res.designs[key]
    fig = target_figures(_module_text(d), d.module_name, res.target, cost=res.winner.target_cost)
    return [f"winner {fig['line']}", f"timing: {fig['timing']}"]


def _module_text(d) -> str:
    from chebnorm.hw.hdl import module_text

    return module_text(d, "verilog")


def _max_index_bits(args, parse_segments) -> int:
    """``--max-segments`` as index bits k, checked against ``--in-bits`` (a
    segment needs two input codes at least); the default 2^8 shrinks to
    2^(in-bits - 1) for narrow inputs."""
    in_bits = args.in_bits if 2 <= args.in_bits <= 20 else None  # else search refuses it
    top = 12 if in_bits is None else min(12, in_bits - 1)
    if args.max_segments is None:
        return min(8, top)
    k = parse_segments(args.max_segments)
    if in_bits is not None and not 0 <= k <= top:
        raise ValueError(f"--max-segments {args.max_segments}: with --in-bits {in_bits} "
                         f"accepted: 2^0 .. 2^{top} (at most half the input codes, and 2^12)")
    return k


def _piecewise_design(args, table):
    """The hardware design of the piecewise ``table`` (read from ``args.table``)."""
    from chebnorm.hw.piecewise import design_piecewise

    for opt in ("coef_bits", "acc_bits", "x_frac_bits", "y_frac_bits"):
        if getattr(args, opt, None) is not None:
            raise ValueError(f"--{opt.replace('_', '-')} is not available for a piecewise table "
                             f"(its coefficient format is the table's; the widths are sized "
                             f"exactly); accepted: --in-bits and --out-bits")
    if getattr(args, "rounding", "rne") != "rne":
        raise ValueError(f"rounding {args.rounding!r}: a piecewise evaluator rounds to nearest "
                         f"even; accepted: rne")
    return design_piecewise(table, args.in_bits, args.out_bits)


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
        from chebnorm.hw.vhdl import simulate_vhdl as simulate
    else:
        from chebnorm.hw.verilog import simulate
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

        fig = target_figures(_module_text(d), d.module_name, args.target)
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
