"""``chebnorm verify TABLE.json --format c|glsl|wgsl|hlsl [--variant V] [--json OUT]``.

Runs the exported evaluators over every input of the table's interval
(:func:`chebnorm.export.verify.verify`) and prints, per variant, the
measured maximum error, the bound the exported text states, their ratio, the
input count and the seconds. The stated bounds are read from what the
compiler builds, never from the text; ``--source FILE`` is compiled and
loaded into this process (code in it runs: a trusted file only). Exit status
0 when every variant ran and every stated bound holds, 1 when one is exceeded
or a variant could not be checked (one line on stderr naming them), 2 on bad
input.
"""

from __future__ import annotations

import json
import sys

from .vocab import MAX_INPUTS, VARIANTS, VERIFY_FORMATS


def register(sub) -> None:
    """Add the ``chebnorm verify`` subcommand.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``chebnorm`` parser (from
        ``argparse.ArgumentParser.add_subparsers``); the new parser's ``func``
        default is :func:`run`.
    """
    p = sub.add_parser("verify", help="run an exported evaluator over every float32 of its "
                       "interval and compare with its stated bound")
    p.add_argument("table", metavar="TABLE.json")
    p.add_argument("--format", default="c", help=f"one of {', '.join(VERIFY_FORMATS)} "
                   f"(default c)")
    p.add_argument("--variant", action="append", default=None,
                   help="a variant to run (repeatable; default all): "
                   + "; ".join(f"{f}: {', '.join(v)}" for f, v in VARIANTS.items()))
    p.add_argument("--inputs", default="all",
                   help=f"'all' (default: every input of the interval) or a count 2..{MAX_INPUTS} "
                   f"evenly spread")
    p.add_argument("--source", metavar="FILE", default=None,
                   help="check this exported file (as shipped) instead of exporting now; it "
                   "is compiled and loaded into this process, so code in it runs: a trusted "
                   "file only")
    p.add_argument("--json", metavar="OUT", default=None, help="write the results as JSON")
    p.add_argument("--markdown", action="store_true", help="print a Markdown table instead")
    p.set_defaults(func=run)


def _inputs(text: str):
    if text == "all":
        return "all"
    try:
        if not text.isascii():
            raise ValueError
        return int(text)
    except ValueError:
        raise ValueError(f"--inputs {text[:40]!r} is not accepted; accepted: all, or a count "
                         f"2..{MAX_INPUTS}") from None


def run(args) -> int:
    """Run ``chebnorm verify``: compile and run an exported evaluator over
    every float32 of its interval (or ``--inputs N`` of them) and compare the
    measured error with the table's stated bound.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``chebnorm verify`` (the options its
        :func:`register` declares; ``args.argv``, set by :func:`chebnorm.cli.main`,
        is the command quoted in provenance banners).

    Returns
    -------
    int
        The exit status: 0 when every evaluator ran and stays within its stated bound, 1
        (with one line on stderr) when one exceeds it or could not be checked (its bound
        not readable from the compiled object, or no tool, driver or runtime here to
        run it).

    Raises
    ------
    ValueError
        On an unknown ``--format`` or a bad ``--inputs`` (accepted: all, or a count)
        (:func:`chebnorm.cli.main` prints it as one line on stderr and exits with status
        2).
    """
    from chebnorm.approx import load_table
    from chebnorm.core.files import refuse_inputs, write_atomic
    from chebnorm.core.numeric import format_down, format_up
    from chebnorm.export.verify import verify

    if args.format not in VERIFY_FORMATS:
        raise ValueError(f"unknown format {args.format[:40]!r} for verify; accepted: "
                         f"{', '.join(VERIFY_FORMATS)}")
    inputs = _inputs(args.inputs)
    refuse_inputs({"--json": args.json}, {"TABLE.json": args.table, "--source": args.source})
    table = load_table(args.table)
    source = None
    if args.source is not None:
        with open(args.source, encoding="utf-8") as fh:
            source = fh.read()
    result = verify(table, args.format, variant=args.variant, inputs=inputs, source=source)
    if args.json is not None:
        write_atomic(args.json, json.dumps(result.to_dict(), sort_keys=True, indent=2,
                                           allow_nan=False) + "\n")
    print(result.markdown() if args.markdown else str(result), end="\n" if not args.markdown
          else "")
    bad, not_run = result.exceeded, result.not_run
    parts = []
    if bad:
        parts.append("stated bound exceeded: " + "; ".join(
            f"{v.evaluator} ({v.format} {v.variant}) measured {format_down(v.measured_max)} > "
            f"{v.bound_name} {format_up(v.stated_bound)}" for v in bad))
    if not_run:
        parts.append("not checked: " + "; ".join(
            f"{v.evaluator} ({v.format} {v.variant}): "
            f"{v.unchecked if v.unchecked is not None else v.skipped}" for v in not_run))
    if parts:
        print("chebnorm: verify: " + " | ".join(" ".join(p.split()) for p in parts),
              file=sys.stderr)
        return 1
    return 0
