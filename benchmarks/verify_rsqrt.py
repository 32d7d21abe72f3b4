"""The manual's "Verify an exported evaluator" table (docs/formats.md): ``chebnorm verify`` on
the committed ``rsqrt_d3`` table, every float32 of its interval.

    python benchmarks/verify_rsqrt.py            # print the Markdown table
    python benchmarks/verify_rsqrt.py --write    # and rewrite it in docs/formats.md

Runs :func:`chebnorm.export.verify.verify` for ``c`` (every variant the
header defines: double and float, unfused and fused, the fixed-point
evaluator), ``glsl`` (llvmpipe) and ``wgsl`` (lavapipe), and prints one row per
evaluator: measured maximum and where, the stated bound read from the
exported text, their ratio and the input count (no times: the table is
deterministic; ``chebnorm verify`` prints the seconds). ``--write`` replaces the text
between ``<!-- verify-rsqrt-start -->`` and ``<!-- verify-rsqrt-end -->`` in
docs/formats.md (the stated column follows whatever the exporters state today).
Exit status 1 when a stated bound is exceeded.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from chebnorm.approx import load_table
from chebnorm.core.numeric import format_down, format_up
from chebnorm.export.verify import verify

ROOT = Path(__file__).resolve().parent.parent
TABLE = ROOT / "figures" / "coefficients" / "rsqrt_d3.json"
START, END = "<!-- verify-rsqrt-start -->", "<!-- verify-rsqrt-end -->"


def row_text(fmt: str, v) -> str:
    """One Markdown row of a :class:`~chebnorm.export.verify.VariantResult`."""
    if v.unchecked is not None:
        return f"| {fmt} | {v.variant} | `{v.evaluator}` | NOT CHECKED: {v.unchecked} | | | | |"
    if v.skipped is not None:
        return f"| {fmt} | {v.variant} | `{v.evaluator}` | skipped: {v.skipped} | | | | |"
    # the measured maximum rounded down, the stated bound up, at the digits shown
    return (f"| {fmt} | {v.variant} | `{v.evaluator}` | {format_down(v.measured_max, '.3e')} | "
            f"{v.argmax!r} | {format_up(v.stated_bound, '.3e')} (`{v.bound_name}`) | "
            f"{v.ratio:.3f} | {v.count:,} |")


def table_text() -> tuple[str, bool]:
    """The Markdown table and whether every stated bound held."""
    table = load_table(TABLE)
    rows = ["| format | variant | evaluator | measured max | argmax x | stated bound | ratio | "
            "inputs |", "|---|---|---|---|---|---|---|---|"]
    ok = True
    for fmt in ("c", "glsl", "wgsl"):
        result = verify(table, fmt)
        ok &= result.passed
        rows += [row_text(fmt, v) for v in result.variants]
    return "\n".join(rows) + "\n", ok


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--write", action="store_true", help="rewrite the table in docs/formats.md")
    args = p.parse_args(argv)
    text, ok = table_text()
    print(text, end="")
    if args.write:
        readme = ROOT / "docs" / "formats.md"
        old = readme.read_text(encoding="utf-8")
        if START not in old or END not in old:
            print(f"docs/formats.md has no {START} ... {END} block", file=sys.stderr)
            return 2
        head, rest = old.split(START, 1)
        _, tail = rest.split(END, 1)
        readme.write_text(f"{head}{START}\n{text}{END}{tail}", encoding="utf-8")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
