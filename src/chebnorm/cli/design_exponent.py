"""``chebnorm design "1/sqrt(x)" --index exponent``: the normalization unit's
reciprocal square root indexed by exponent (:mod:`chebnorm.hw.exponent`),
one sized design per degree, synthesized on the target, the cheapest wins."""

from __future__ import annotations

import math

from .common import command_line, max_error_value


def run_exponent(args) -> int:
    """Design, price and write the exponent-indexed ``1/sqrt`` evaluator.

    ``--interval 2^-m 1``: codes ``k >= 2^(in_bits - m)`` of ``x = k / 2^in_bits``;
    ``--out-bits``: the mantissa's width; ``--faithful`` (mantissa error < one
    unit of its last place) or ``--max-error E`` (on the mantissa; the relative
    error is below ``2E``). Writes ``chebnorm_NAME.v`` / ``.vhd`` (core and
    top), the exhaustive benches and vectors, and
    ``design_NAME_architectures.csv``; prints the winner and why the others lose.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``chebnorm design`` arguments with ``index == "exponent"``
        (EXPR ``1/sqrt(x)``, ``interval`` ``2^-m 1`` with ``1 <= m <= in_bits``,
        ``in_bits`` 4..20, ``out_bits``, the accuracy, ``degrees``, ``target``,
        ``name``, ``output``).

    Returns
    -------
    int
        The exit status: 0 once the winner is written.

    Raises
    ------
    ValueError
        For an expression other than ``1/sqrt(x)``, a low end of 0, widths out
        of range or ``--correctly-rounded``, or when no degree meets the
        accuracy (:func:`chebnorm.cli.main` prints it as one line on stderr
        and exits with status 2).
    """
    from pathlib import Path

    from chebnorm import __version__
    from chebnorm.core.textsafe import identifier
    from chebnorm.hw.exponent import design_exponent
    from chebnorm.hw.hdl.exponent import exponent_files
    from chebnorm.hw.targets import get_target, synthesize_target, target_figures

    from chebnorm.core.files import write_folder

    name = identifier(args.name, field="name")
    target = get_target(args.target).name
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise ValueError(f"output {args.output!r} exists and is not a folder; accepted: a folder")
    if getattr(args, "frequency", None) is not None:   # never silently ignored
        raise ValueError(f"--frequency {str(args.frequency)[:40]}: not available with --index "
                         f"exponent (its winner is written combinational); accepted: without "
                         f"--frequency, or --index uniform")
    if args.correctly_rounded:
        raise ValueError("--correctly-rounded: not available with --index exponent (the "
                         "mantissa is faithful at best); accepted: --faithful or --max-error E")
    max_error = max_error_value(args.max_error) if args.max_error is not None else None
    degrees = sorted(set(args.degrees))
    bad = [d for d in degrees if not 1 <= d <= 3]
    if bad:
        raise ValueError(f"--degrees {bad[0]}: accepted with --index exponent: 1, 2 or 3")
    mult = "full" if target == "xc7" else "truncated"
    found, notes = [], []
    for degree in degrees:
        try:
            d = design_exponent(args.expr, tuple(args.interval), args.in_bits, args.out_bits,
                                degree=degree, max_error=max_error, multipliers=mult,
                                name=name, var=args.var)
        except ValueError as exc:
            if degree == degrees[0] and len(degrees) == 1 or "max_error" not in str(exc):
                raise
            notes.append(f"degree {degree}: {exc}")
            continue
        cost = None if args.no_synth else synthesize_target(d.verilog(), d.module_name, target)
        found.append((d, cost))
    if not found:
        raise ValueError("no degree meets the accuracy: " + "; ".join(notes)
                         + "; accepted: a larger --max-error or more --out-bits")

    def score(item):
        d, cost = item
        proxy = sum(d.core.rom_bits) << d.core.index_bits
        return (cost.score if cost is not None else proxy, d.degree)

    best = min(found, key=score)
    d, cost = best
    cmd = command_line(args)
    files = {f"{d.module_name}.v": d.verilog(version=__version__, command=cmd),
             f"{d.module_name}.vhd": d.vhdl(version=__version__, command=cmd)}
    for lang in ("verilog", "vhdl"):
        for fname, text in exponent_files(d, lang).items():
            if fname.startswith("tb_") or fname.endswith(".hex"):
                files[fname] = text
    files[f"design_{name}_architectures.csv"] = _csv(found, best)
    figures = []
    if cost is not None and target != "generic":  # before writing: place and route may fail
        fig = target_figures(d.verilog(), d.module_name, target, cost=cost, latency=d.latency)
        figures = [f"winner {fig['line']}", f"timing: {fig['timing']}"]
    for path in write_folder(out, dict(sorted(files.items()))):
        print(path)
    print(f"winner: {_line(d, cost)}")
    if figures:
        print("\n".join(figures))
    for other in found:
        if other is not best:
            print(f"  {_line(*other)} -- costlier than the winner")
    for note in notes:
        print(f"  {note}")
    return 0


def _line(d, cost) -> str:
    from chebnorm.core.numeric import format_up
    b = d.budget()
    c = "not synthesized" if cost is None else cost.line()
    return (f"exponent: degree {d.degree}, {d.core.table.segment_count} segments on [1, 4) "
            f"({d.core.table.segment_count // 2} per binade), mantissa {d.mant_bits} bits + "
            f"shift {d.shift_bits} bits: {c}; certified mantissa error "
            f"{format_up(b['mantissa'], '.4e')} "
            f"({format_up(b['mantissa'] * 2.0 ** d.frac_bits, '.3f')} ulp), relative < "
            f"{format_up(b['relative'], '.4e')}")


def _csv(found, best) -> str:
    import csv as csvmod
    import io

    from chebnorm.core.numeric import format_up

    buf = io.StringIO()
    w = csvmod.writer(buf, lineterminator="\n")
    w.writerow(["architecture", "degree", "segments", "score", "cells", "luts", "dsps",
                "carries", "brams", "mantissa_error", "ulp", "winner"])
    for d, c in found:
        w.writerow(["exponent", d.degree, d.core.table.segment_count,
                    "" if c is None else f"{c.score:.1f}", "" if c is None else c.cells,
                    "" if c is None else c.luts, "" if c is None else c.dsps,
                    "" if c is None else c.carries, "" if c is None else c.brams,
                    format_up(d.budget()['mantissa'], '.6e'),
                    f"{math.ldexp(1.0, -d.frac_bits):.6e}",
                    int(d is best[0])])
    return buf.getvalue()
