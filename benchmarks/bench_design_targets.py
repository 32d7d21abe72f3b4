"""Wall time of ``chebnorm design`` on the FloPoCo comparison spec (``1/sqrt(1+3x)`` on [0, 1), 16 bits) for every FPGA target
(search, synthesis on the target, and the winner's timing run).

    python benchmarks/bench_design_targets.py [--targets generic xc7 ...] [--repeat 3]
                                              [--json benchmarks/design_targets_results.json]

The spec: f(x) = 1/sqrt(1 + 3x), x in [0, 1) as a 16-bit code, 16 output bits,
``--faithful``. Each target's command runs ``--repeat`` times in a child
process; the best wall time is kept, with the child's user + sys CPU seconds
of that run and the 1-minute load average before and after it (other work on
the machine moves the wall figures: the CPU time is the steadier one). Prints
one JSON line per target (its winner and timing lines too) and writes them
all to the JSON file (sorted keys).

    python benchmarks/bench_design_targets.py --markdown [--json FILE]

prints the manual's table of the spec per target (docs/hardware.md) from the JSON file (no run):
``tests/test_readme_figures.py`` checks that docs/hardware.md shows these rows.

    python benchmarks/bench_design_targets.py --calibrate [--bits 16 12] [--targets ...]

measures instead what the pruning of ``design`` relies on
(``chebnorm.hw.architectures.PRUNE_SPREAD``): every candidate the
architectures' search builds for the spec at each width (``--expr`` for other
functions on [0, 1)), synthesized without pruning, one JSON line each with its
model score, the ROM part of it, its yosys score and their ratio; all rows go
to ``benchmarks/prune_calibration.json`` (``--calibration-json``), which
tests/test_design_architectures.py holds PRUNE_SPREAD to.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import resource
import subprocess
import sys
import tempfile
import time

SPEC = ["1/sqrt(1+3*x)", "--interval", "0", "1", "--in-bits", "16", "--out-bits", "16",
        "--faithful"]
HERE = os.path.dirname(os.path.abspath(__file__))


def run_once(target: str) -> dict:
    """One ``design`` run for ``target``: wall and CPU seconds, load, the winner lines."""
    with tempfile.TemporaryDirectory() as tmp:
        load0 = os.getloadavg()[0]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "chebnorm", "design", *SPEC, "--target",
                               target, "-o", os.path.join(tmp, "out")], capture_output=True,
                              text=True, stdin=subprocess.DEVNULL)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    lines = proc.stdout.splitlines()
    pick = [ln for ln in lines if ln.startswith(("winner", "timing"))]
    return {"target": target, "status": proc.returncode, "wall_s": round(wall, 2),
            "cpu_s": round(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime,
                           2),
            "load_before": round(load0, 2), "load_after": round(os.getloadavg()[0], 2),
            "lines": pick, "stderr": proc.stderr.strip().splitlines()[-1:]}


def run(target: str, repeat: int) -> dict:
    """The best of ``repeat`` runs (least wall time), with every run's wall and CPU."""
    runs = [run_once(target) for _ in range(repeat)]
    best = min(runs, key=lambda r: (r["status"] != 0, r["wall_s"]))
    best = dict(best)
    best["walls_s"] = [r["wall_s"] for r in runs]
    best["cpus_s"] = [r["cpu_s"] for r in runs]
    return best


def calibrate(bits: int, target: str, expr: str = "1/sqrt(1+3*x)") -> list[dict]:
    """Model against yosys for every built candidate of ``expr`` on [0, 1) at ``bits`` bits."""
    from chebnorm.hw.architectures import build_candidates, synthesize_candidates

    ks = {d: max(0, min(bits - 2, 3 + 2 * (3 - d))) for d in (1, 2, 3)}  # as design does
    cands = build_candidates(expr, ("0", "1"), bits, bits, accuracy="faithful",
                             k_start=ks, target=target, workers=None)
    rows = []
    for c in synthesize_candidates(cands, target, prune=False, workers=None):
        if c.cost is not None:
            rows.append({"bits": bits, "expr": expr, "target": target,
                         "architecture": c.architecture,
                         "description": c.description, "model": round(c.model, 1),
                         "model_rom": round(c.model_rom, 1),
                         "yosys": round(c.cost.score, 1),
                         "ratio": round(c.model / c.cost.score, 3)})
    return rows


#: the cell kinds of ``design``'s cost line, as each FPGA family names them
CELL_NAMES = {"xc7": ("LUT", "DSP48E1", "CARRY4", "MUXF"),
              "xc7-nodsp": ("LUT", "DSP48E1", "CARRY4", "MUXF"),
              "ice40": ("SB_LUT4", "DSP", "SB_CARRY", "MUX")}


def winner_text(line: str, target: str) -> str:
    """The manual's words for the winner of ``design``'s first ``winner:`` line."""
    arch = line.split("winner: ", 1)[1].split(f": {target}:", 1)[0]
    arch = re.sub(r",? \(?ROM \d+ bits\)?", "", arch)
    if arch.startswith("piecewise-sized: "):
        return "sized piecewise, " + arch[len("piecewise-sized: "):]
    if arch.startswith("degree "):
        return "one width, " + arch
    return arch.replace(": ", ", ", 1)


def cost_text(line: str, target: str) -> str:
    """``1,502 cells`` or ``134 LUT + 1 DSP48E1 + ... (score 398.2)`` from a winner line."""
    if target == "generic":
        cells = int(re.search(r"(\d+) cells", line).group(1))
        return f"{cells:,} cells"
    m = re.search(r"(\d+) LUT, (\d+) DSP, (\d+) carry, (\d+) mux, .*?score ([\d.]+)", line)
    counts, score = [int(v) for v in m.groups()[:4]], float(m.group(5))
    text = " + ".join(f"{n:,} {name}" for n, name in zip(counts, CELL_NAMES[target]) if n)
    return text + ("" if score == counts[0] else f" (score {score:.1f})")


def timing_text(lines: list[str]) -> str:
    """The winner's timing, three significant digits, and how it was had."""
    timing = [ln for ln in lines if ln.startswith("timing:")]
    if not timing:
        return "(no device)"
    m = re.search(r"Fmax (~ )?([\d.]+) MHz \((model|nextpnr-ice40)", timing[0])
    if m.group(3) == "model":
        return f"Fmax ~ {float(m.group(2)):.3g} MHz (model, no routing)"
    return f"{float(m.group(2)):.3g} MHz (nextpnr-ice40)"


def markdown(doc: dict) -> str:
    """The manual's table of the spec, one row per target of ``doc`` (the JSON file).

    >>> doc = {"results": [{"target": "generic", "wall_s": 56.83, "cpu_s": 33.56, "lines": [
    ...     "winner: piecewise-sized: degree 2, 128 centred segments, ROM 4608 bits, "
    ...     "truncated multipliers: generic: 1502 cells; certified error 1.5e-05"]}]}
    >>> print(markdown(doc).splitlines()[-1])
    | generic | sized piecewise, degree 2, 128 centred segments, truncated multipliers | 1,502 cells | (no device) | 57 s / 34 s |
    """
    rows = ["| target | winner | cells / LUT, DSP, carry, MUXF | timing | wall / CPU time |",
            "|---|---|---|---|---|"]
    for r in doc["results"]:
        t, lines = r["target"], r["lines"]
        rows.append(f"| {t} | {winner_text(lines[0], t)} | {cost_text(lines[0], t)} | "
                    f"{timing_text(lines)} | {round(r['wall_s'])} s / {round(r['cpu_s'])} s |")
    return "\n".join(rows) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--targets", nargs="+", default=["generic", "xc7", "xc7-nodsp", "ice40"])
    ap.add_argument("--repeat", type=int, default=3, help="runs per target (best kept)")
    ap.add_argument("--json", default=os.path.join(HERE, "design_targets_results.json"),
                    help="where to write the results ('' for nowhere)")
    ap.add_argument("--markdown", action="store_true",
                    help="print the manual's table from the --json file (no run)")
    ap.add_argument("--calibrate", action="store_true",
                    help="model against yosys for every candidate (no timing)")
    ap.add_argument("--bits", nargs="+", type=int, default=[16, 12],
                    help="--calibrate: the spec's input and output widths")
    ap.add_argument("--expr", nargs="+", default=["1/sqrt(1+3*x)"],
                    help="--calibrate: the functions of x on [0, 1)")
    ap.add_argument("--calibration-json", default=os.path.join(HERE, "prune_calibration.json"),
                    help="--calibrate: where to write the rows ('' for nowhere)")
    args = ap.parse_args(argv)
    if args.markdown:
        with open(args.json, encoding="utf-8") as fh:
            print(markdown(json.load(fh)), end="")
        return 0
    if args.calibrate:
        rows = []
        for e in args.expr:
            for b in args.bits:
                for t in args.targets:
                    for row in calibrate(b, t, e):
                        rows.append(row)
                        print(json.dumps(row, sort_keys=True), flush=True)
        if args.calibration_json:
            with open(args.calibration_json, "w", encoding="utf-8") as fh:
                json.dump({"rows": rows}, fh, indent=1, sort_keys=True)
                fh.write("\n")
        return 0
    if args.repeat < 1:
        ap.error(f"--repeat {args.repeat}: accepted: 1 or more")
    results = []
    for t in args.targets:
        r = run(t, args.repeat)
        results.append(r)
        print(json.dumps(r, sort_keys=True), flush=True)
    if args.json:
        doc = {"command": "chebnorm design " + " ".join(SPEC) + " --target T -o DIR",
               "cores": os.cpu_count(), "machine": platform.machine(),
               "python": platform.python_version(), "repeat": args.repeat,
               "results": results}
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(doc, fh, indent=1, sort_keys=True)
            fh.write("\n")
    return 0 if all(r["status"] == 0 for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
