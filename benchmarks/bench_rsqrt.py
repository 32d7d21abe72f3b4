"""Throughput of the float-only correctly rounded binary32 1/sqrt
(``chebnorm correctly-rounded 1/sqrt --format binary32 --arithmetic float32``)
against ``1.0f/sqrtf(x)``, ``(float)(1.0/sqrt((double)x))`` and, when its
source file is given, CORE-MATH's ``cr_rsqrtf``.

    python benchmarks/bench_rsqrt.py [--core-math path/to/rsqrtf.c] [--n 4194304] [--repeat 7]

One run, compiled code, same machine: every function is compiled by gcc
(-O2 -ffp-contract=off -fno-fast-math, -mfma when the CPU has FMA) in its own
translation unit and called on the same array of ``--n`` positive finite
float32 inputs (random bit patterns, seed 47: every binade, subnormals
included); the time of the fastest of ``--repeat`` passes is divided by n.
Prints one line per function (ns/call) and a JSON line with every figure,
the compiler version and the 1-minute load average before and after.
CORE-MATH's source is not shipped here: pass its ``src/binary32/rsqrt/rsqrtf.c``
(it needs binary64 arithmetic; its ``rsqrtf`` wrapper is renamed away).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import sys
import tempfile

HARNESS = r"""#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
%(decls)s
typedef float (*fn_t)(float);
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
int main(int argc, char **argv)
{
    size_t n = strtoull(argv[1], NULL, 10);
    int repeat = atoi(argv[2]);
    float *x = malloc(n * sizeof *x);
    uint64_t s = 47;
    for (size_t i = 0; i < n; i++) {
        uint32_t b;
        do { s = s * 6364136223846793005ULL + 1442695040888963407ULL; b = (uint32_t)(s >> 33); }
        while (b == 0 || b >= 0x7f800000u);
        memcpy(&x[i], &b, sizeof b);
    }
    static const fn_t fns[] = {%(fns)s};
    static const char *names[] = {%(names)s};
    for (size_t k = 0; k < sizeof fns / sizeof fns[0]; k++) {
        double best = 1e30;
        uint32_t acc = 0;
        for (int r = 0; r < repeat; r++) {
            double t0 = now();
            for (size_t i = 0; i < n; i++) { float y = fns[k](x[i]); uint32_t b; memcpy(&b, &y, sizeof b); acc ^= b; }
            double t = now() - t0;
            if (t < best) best = t;
        }
        printf("%%s %%.3f %%u\n", names[k], 1e9 * best / (double)n, (unsigned)acc);
    }
    return 0;
}
"""

#: the flags of chebnorm's exhaustive binary32 check
CFLAGS = ("-std=gnu11", "-O2", "-ffp-contract=off", "-fno-fast-math")


def cpu_has_fma() -> bool:
    """True when /proc/cpuinfo lists the fma flag."""
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as fh:
            return any(line.startswith("flags") and " fma" in line for line in fh)
    except OSError:
        return False


REFS = {
    "sqrtf": "#include <math.h>\nfloat ref_sqrtf(float x) { return 1.0f / sqrtf(x); }\n",
    "binary64": "#include <math.h>\nfloat ref_binary64(float x) { return (float)(1.0 / sqrt((double)x)); }\n",
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--core-math", metavar="FILE", help="CORE-MATH's rsqrtf.c")
    ap.add_argument("--n", type=int, default=1 << 22)
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args(argv)

    from chebnorm.core.tools import run_tool
    from chebnorm.cr import correctly_rounded

    flags = [*CFLAGS] + (["-mfma"] if cpu_has_fma() else [])
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="bench-rsqrt-") as d:
        units, fns = [], []
        for fma in (True, False):
            r = correctly_rounded("1/sqrt", "binary32", arithmetic="float32", fma=fma)
            tag = "fma" if fma else "nofma"
            sub = os.path.join(d, tag)
            os.makedirs(sub)
            for name, text in r.files.items():
                text = text.replace("cr_rsqrt_binary32", f"cr_rsqrt_binary32_{tag}")
                with open(os.path.join(sub, name.replace(".c", f"_{tag}.c").replace(
                        ".h", f"_{tag}.h")), "w", encoding="utf-8") as fh:
                    fh.write(text)
            units.append(os.path.join(sub, f"cr_rsqrt_binary32_{tag}.c"))
            fns.append((f"chebnorm float-only ({tag})", f"cr_rsqrt_binary32_{tag}"))
        for key, text in REFS.items():
            path = os.path.join(d, f"ref_{key}.c")
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(text)
            units.append(path)
        fns += [("1.0f/sqrtf(x)", "ref_sqrtf"), ("(float)(1.0/sqrt((double)x))", "ref_binary64")]
        if args.core_math:
            with open(args.core_math, encoding="utf-8") as fh:
                text = fh.read()
            text = re.sub(r"\bfloat rsqrtf\(", "float core_math_unused_rsqrtf(", text)
            path = os.path.join(d, "core_math_rsqrtf.c")
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(text)
            units.append(path)
            fns.append(("CORE-MATH cr_rsqrtf", "cr_rsqrtf"))
        harness = os.path.join(d, "harness.c")
        with open(harness, "w", encoding="utf-8") as fh:
            fh.write(HARNESS % {
                "decls": "\n".join(f"float {c}(float);" for _, c in fns),
                "fns": ", ".join(c for _, c in fns),
                "names": ", ".join(json.dumps(label) for label, _ in fns)})
        exe = os.path.join(d, "bench")
        run_tool(["gcc", *flags, "-o", exe, harness, *units, "-lm"], tool="gcc", timeout=300,
                 check=True)
        proc = run_tool([exe, str(args.n), str(args.repeat)], tool="bench", timeout=3600,
                        check=True)
        cc = run_tool(["gcc", "--version"], tool="gcc", timeout=60).stdout.splitlines()[0]
    rows = {}
    for line in proc.stdout.splitlines():
        label, ns, _ = line.rsplit(" ", 2)
        rows[label] = float(ns)
        print(f"{label:36s} {float(ns):8.2f} ns/call")
    print(json.dumps({"ns_per_call": rows, "n": args.n, "repeat": args.repeat, "cflags": flags,
                      "gcc": cc, "machine": platform.machine(),
                      "load_before": load0, "load_after": os.getloadavg()[0]}, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
