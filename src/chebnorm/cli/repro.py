"""``chebnorm repro [NAME ...]``: the main job.

Regenerates every output under ``figures/`` (``-o`` to change): the
coefficient tables and C headers of every registered target (job
``coefficients``, part of the library), and every job that the paper
reproduction registers through the ``chebnorm.repro`` entry point (the
library does not import it by name). Each job writes its files atomically,
so an interrupted run keeps every file that was finished.
"""

from __future__ import annotations

import time
from importlib.metadata import entry_points
from pathlib import Path

from chebnorm.approx import TARGETS, fit_target, target_names
from chebnorm.export import c_header, json_text
from chebnorm.approx.files import write_atomic

#: fractional bits of the fixed-point part of the exported tables
EXPORT_FRAC_BITS = 24


def export_coefficients(out: Path) -> list[Path]:
    """Every registered target at each of its degrees: JSON table and C header."""
    folder = out / "coefficients"
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for name in target_names():
        for degree in TARGETS[name].degrees:
            table = fit_target(name, degree, frac_bits=EXPORT_FRAC_BITS)
            cmd = "chebnorm repro coefficients"
            for text, path in ((json_text(table, cmd), folder / f"{table.name}.json"),
                               (c_header(table, cmd), folder / f"chebnorm_{table.name}.h")):
                write_atomic(path, text)
                written.append(path)
    return written


def jobs() -> dict:
    """All jobs by name: the library's own, then the registered ones."""
    found = {"coefficients": export_coefficients}
    for ep in sorted(entry_points(group="chebnorm.repro"), key=lambda e: e.name):
        registry = ep.load()
        for name in sorted(registry):
            if name in found:
                raise ValueError(f"repro job {name!r} is registered twice")
            found[name] = registry[name]
    return found


def register(sub) -> None:
    p = sub.add_parser("repro", help="regenerate every figure, table, ledger and coefficient header",
                       description=__doc__.splitlines()[0])
    p.add_argument("names", nargs="*", metavar="NAME", help="jobs to run (default: all); see --list")
    p.add_argument("-o", "--output", default="figures", help="output folder (default figures)")
    p.add_argument("--list", action="store_true", help="list the jobs and exit")
    p.set_defaults(func=run)


def run(args) -> int:
    from tqdm import tqdm

    available = jobs()
    if args.list:
        for name in available:
            print(name)
        return 0
    unknown = [n for n in args.names if n not in available]
    if unknown:
        raise ValueError(f"unknown repro job(s) {', '.join(unknown)}; accepted: {', '.join(available)}")
    selected = args.names or list(available)
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    count = 0
    bar = tqdm(selected, desc="chebnorm repro", unit="job", disable=None)
    for name in bar:
        bar.set_postfix_str(name)
        count += len(available[name](out) or [])
    print(f"chebnorm repro: {len(selected)} job(s), {count} file(s) under {out}/ "
          f"in {time.perf_counter() - start:.1f} s")
    return 0
