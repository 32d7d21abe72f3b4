"""``chebnorm export TABLE.json --format c|json -o FILE``."""

from __future__ import annotations

from chebnorm.approx import CoefficientTable
from chebnorm.export import FORMATS, export_table

from ._common import command_line


def register(sub) -> None:
    p = sub.add_parser("export", help="print a coefficient table as a C header or JSON")
    p.add_argument("table", metavar="TABLE.json")
    p.add_argument("--format", default="c", help=f"one of {', '.join(sorted(FORMATS))} (default c)")
    p.add_argument("-o", "--output", metavar="FILE", required=True)
    p.set_defaults(func=run)


def run(args) -> int:
    if args.format not in FORMATS:
        raise ValueError(f"unknown export format {args.format!r}; accepted: {', '.join(sorted(FORMATS))}")
    table = CoefficientTable.load(args.table)
    export_table(table, args.format, args.output, command_line(args))
    return 0
