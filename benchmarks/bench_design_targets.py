"""Wall time of ``chebnorm design`` on the issue-28 spec for every FPGA target
(search, synthesis of the front on the target, and the winner's timing run).

    python benchmarks/bench_design_targets.py [--targets generic xc7 ...]

Prints one JSON line per target: the wall and CPU seconds of the whole
command (a child process), its winner line and its timing line. Compare runs
side by side in one session: the machine's load moves the absolute figures.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

SPEC = ["1/sqrt(1+3*x)", "--interval", "0", "1", "--in-bits", "16", "--out-bits", "16",
        "--max-error", "1.52587890625e-05"]


def run(target: str) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "chebnorm", "design", *SPEC, "--target",
                               target, "-o", os.path.join(tmp, "out")], capture_output=True,
                              text=True, stdin=subprocess.DEVNULL)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    lines = proc.stdout.splitlines()
    pick = [ln for ln in lines if ln.startswith(("winner", "timing"))]
    return {"target": target, "status": proc.returncode, "wall_s": round(wall, 1),
            "cpu_s": round(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, 1),
            "load": os.getloadavg()[0], "lines": pick}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--targets", nargs="+", default=["generic", "xc7", "xc7-nodsp", "ice40"])
    args = ap.parse_args(argv)
    for t in args.targets:
        print(json.dumps(run(t), sort_keys=True), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
