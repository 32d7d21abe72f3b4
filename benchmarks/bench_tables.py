"""Table-based designs on the FloPoCo comparison spec, priced by yosys.

Usage: python benchmarks/bench_tables.py [mp|plain]

Spec: f(x) = 1/sqrt(1 + 3x), x in [0, 1) as a 16-bit code, output LSB 2^-16,
faithful, combinational. ``mp``: design_multipartite choosing among its six
cheapest certified candidates by yosys ``synth_xilinx -family xc7 -nodsp``
LUTs; ``plain``: the correctly rounded plain table. Each winner is simulated
over all 65,536 codes in Icarus Verilog and GHDL, then synthesized with
``synth``, ``synth_xilinx -family xc7 -nodsp`` and ``synth_xilinx -family xc7``
(yosys in a private temporary folder, argument list, fixed script).
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from chebnorm.hw import design_multipartite, design_plain_table, simulate_table
from chebnorm.hw.run_verilog import tool_env

SPEC = ("1/sqrt(1+3*x)", ("0", "1"), 16, 16)
SCRIPTS = ("synth -top {top}", "synth_xilinx -family xc7 -nodsp -top {top}",
           "synth_xilinx -family xc7 -top {top}")


def yosys(text: str, top: str, script: str) -> dict:
    """Cell counts of ``script`` on ``text`` (yosys ``stat``)."""
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "design.v").write_text(text, encoding="utf-8")
        proc = subprocess.run(["yosys", "-q", "-p", f"read_verilog design.v; "
                               f"{script.format(top=top)}; tee -o stat.txt stat"],
                              cwd=tmp, env=tool_env(), capture_output=True, text=True,
                              timeout=3600, stdin=subprocess.DEVNULL)
        if proc.returncode != 0:
            raise RuntimeError(proc.stderr[-400:])
        out = (Path(tmp) / "stat.txt").read_text(encoding="utf-8")
    cells = {m.group(1): int(m.group(2)) for m in re.finditer(r"^\s+(\S+)\s+(\d+)\s*$", out, re.M)}
    cells["total"] = int(re.search(r"Number of cells:\s+(\d+)", out).group(1))
    cells["LUT"] = sum(v for k, v in cells.items() if re.fullmatch(r"LUT\d", k))
    return cells


def xc7_nodsp_luts(design) -> int:
    return yosys(design.verilog(), design.module_name, SCRIPTS[1])["LUT"]


def main(which: str) -> None:
    t = time.perf_counter()
    if which == "mp":
        d = design_multipartite(*SPEC, select=xc7_nodsp_luts)
        print(f"multipartite {d.split}, guard {d.guard_bits}, ROM {d.rom_bits} bits")
    else:
        d = design_plain_table(*SPEC)
        print(f"plain table, ROM {d.rom_bits} bits, correctly rounded: {d.correctly_rounded}")
    print(f"proved max |y - f(x)| <= {d.certificate.upper:.6e} over {d.certificate.codes} codes "
          f"({time.perf_counter() - t:.1f} s)")
    for language in ("verilog", "vhdl"):
        with tempfile.TemporaryDirectory() as tmp:
            print(language, simulate_table(d, tmp, language).line)
    for script in SCRIPTS:
        c = yosys(d.verilog(), d.module_name, script)
        keep = {k: v for k, v in sorted(c.items()) if k.startswith(("MUXF", "CARRY", "DSP", "RAM"))}
        print(f"{script.format(top='T')}: {c['total']} cells, {c['LUT']} LUT {keep}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "mp")
