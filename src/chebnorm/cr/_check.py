"""The exhaustive check: compile the generated C with gcc (no FMA
contraction) and run it on every input of the format in the four rounding
modes C has, against the oracle."""

from __future__ import annotations

import os
import tempfile

import numpy as np

from ._formats import C_MODES

__all__: list[str] = []

#: the compiler flags the generated code is checked with (and documented for)
CFLAGS = ("-std=c11", "-O2", "-ffp-contract=off", "-frounding-math", "-fno-fast-math")

_DRIVER = """#include <fenv.h>
#include <stdint.h>
#include <stdio.h>
#include "{header}"
int main(int argc, char **argv)
{{
    static const int modes[4] = {{FE_TONEAREST, FE_TOWARDZERO, FE_UPWARD, FE_DOWNWARD}};
    static const char *names[4] = {{"RNE", "RTZ", "RUP", "RDN"}};
    const unsigned long n = {n}UL;
    FILE *f = fopen(argv[1], "rb");
    if (!f) return 3;
    static uint32_t want[4][{n}];
    if (fread(want, sizeof(uint32_t), 4 * n, f) != 4 * n) return 4;
    fclose(f);
    for (int k = 0; k < 4; k++) {{
        unsigned long wrong = 0, lost = 0;
        fesetround(modes[k]);
        for (unsigned long i = 0; i < n; i++) {{
            uint32_t got = {fn}(({ctype})i);
            uint32_t w = want[k][i];
            if (w == 0xffffffffu) continue; /* outside the proved interval */
            int wnan = (w & {inf}u) == {inf}u && (w & {mant}u);
            int gnan = (got & {inf}u) == {inf}u && (got & {mant}u);
            if (wnan ? !gnan : got != w) {{
                if (wrong < 3) printf("example %s %lx got %lx want %lx\\n", names[k], i,
                                      (unsigned long)got, (unsigned long)w);
                wrong++;
            }}
            if (fegetround() != modes[k]) lost++;
        }}
        fesetround(FE_TONEAREST);
        printf("%s %lu %lu\\n", names[k], wrong, lost);
    }}
    return 0;
}}
"""


def check_c(source: str, header: str, fname: str, fmt, ro: np.ndarray, *, domain=None,
            timeout=300.0):
    """Compile ``source`` and run it over every input in RNE, RTZ, RUP, RDN.

    Returns {mode: wrongly rounded count} (a mode whose rounding the function
    did not restore counts every input as wrong)."""
    from chebnorm.core.tools import require, run_tool

    gcc = require("gcc", "the exhaustive check of correctly rounded functions")
    n = 1 << fmt.bits
    want = np.stack([fmt.round(ro, m) for m in C_MODES]).astype(np.uint32)
    if domain is not None:
        want[:, ~domain] = 0xFFFFFFFF
    with tempfile.TemporaryDirectory(prefix="chebnorm-cr-") as d:
        hname = f"{fname}.h"
        with open(os.path.join(d, hname), "w", encoding="utf-8") as fh:
            fh.write(header)
        with open(os.path.join(d, f"{fname}.c"), "w", encoding="utf-8") as fh:
            fh.write(source)
        with open(os.path.join(d, "driver.c"), "w", encoding="utf-8") as fh:
            fh.write(_DRIVER.format(header=hname, n=n, fn=fname, ctype=fmt.ctype,
                                    inf=fmt.inf_bits, mant=(1 << (fmt.precision - 1)) - 1))
        want.tofile(os.path.join(d, "want.bin"))
        exe = os.path.join(d, "check")
        run_tool([gcc, *CFLAGS, "-o", exe, os.path.join(d, f"{fname}.c"),
                  os.path.join(d, "driver.c"), "-lm"], tool="gcc", timeout=timeout, check=True)
        proc = run_tool([exe, os.path.join(d, "want.bin")], tool="check", timeout=timeout,
                        check=True)
    out = {}
    for line in proc.stdout.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[0] in C_MODES:
            out[parts[0]] = int(parts[1]) + (n if int(parts[2]) else 0)
    if set(out) != set(C_MODES):
        raise RuntimeError("the exhaustive check printed no count for every mode")
    return out
