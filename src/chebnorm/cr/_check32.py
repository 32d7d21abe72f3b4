"""The exhaustive binary32 check of a 1/sqrt: every float32 bit pattern (or
given ranges of them) run through compiled C and judged by an exact integer
test, independent of any floating-point arithmetic.

For a positive finite x = X 2^a (X < 2^24) and a candidate y = Y 2^c
(2^23 <= Y < 2^24), y is 1/sqrt(x) rounded to nearest-even iff 1/sqrt(x)
lies between the midpoints around y: x h^2 >= 1 for the upper midpoint
h = (2Y + 1) 2^(c-1) and x l^2 <= 1 for the lower one l = (2Y - 1) 2^(c-1)
(l = (4Y - 1) 2^(c-2) when Y = 2^23: the spacing below a power of two is
half), equality allowed only when Y is even. x h^2 = X (2Y+1)^2 2^(a+2c-2)
is compared with 1 as the integer X (2Y+1)^2 < 2^74 against 2^-(a+2c-2) in
unsigned __int128. 1/sqrt(x) of a positive finite float lies in
[2^-64, 2^75), so a correct y is always normal."""

from __future__ import annotations

import os
import tempfile
import time

__all__: list[str] = []

#: gcc flags of the check (no FMA contraction, IEEE semantics) and of OpenMP
CFLAGS = ("-std=gnu11", "-O2", "-ffp-contract=off", "-fno-fast-math")

_DRIVER = r"""#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
float %(fn)s(float x);

typedef unsigned __int128 u128;

/* the sign of v - 2^s for v > 0 */
static int cmp_pow2(u128 v, int s)
{
    if (s < 0) return 1;
    if (s >= 127) return -1;
    u128 p = (u128)1 << s;
    return v > p ? 1 : v < p ? -1 : 0;
}

/* 1 iff yb is 1/sqrt(x) rounded to nearest-even, for x = xb positive finite */
static int correct_positive(uint32_t xb, uint32_t yb)
{
    if (yb < 0x00800000u || yb >= 0x7f800000u) return 0; /* must be a positive normal */
    uint32_t ex = xb >> 23;
    u128 X = xb & 0x7fffffu;
    int a;
    if (ex == 0) a = -149;
    else { X |= 0x800000u; a = (int)ex - 150; }
    u128 Y = (yb & 0x7fffffu) | 0x800000u;
    int c = (int)(yb >> 23) - 150;
    int even = (int)(Y & 1u) == 0;
    u128 H = 2 * Y + 1;
    int up = cmp_pow2(X * H * H, -(a + 2 * c - 2));     /* x h^2 vs 1 */
    if (up < 0 || (up == 0 && !even)) return 0;
    int lo;
    if (Y == 0x800000u) { u128 L = 4 * Y - 1; lo = cmp_pow2(X * L * L, -(a + 2 * c - 4)); }
    else { u128 L = 2 * Y - 1; lo = cmp_pow2(X * L * L, -(a + 2 * c - 2)); }
    if (lo > 0 || (lo == 0 && !even)) return 0;
    return 1;
}

static int correct(uint32_t xb, uint32_t yb)
{
    int ynan = (yb & 0x7fffffffu) > 0x7f800000u;
    if ((xb & 0x7fffffffu) > 0x7f800000u) return ynan;   /* NaN -> NaN */
    if (xb == 0x00000000u) return yb == 0x7f800000u;      /* +0 -> +inf */
    if (xb == 0x80000000u) return yb == 0xff800000u;      /* -0 -> -inf */
    if (xb >> 31) return ynan;                            /* x < 0, -inf -> NaN */
    if (xb == 0x7f800000u) return yb == 0u;               /* +inf -> +0 */
    return correct_positive(xb, yb);
}

int main(int argc, char **argv)
{
    /* classes: 0 positive normal, 1 positive subnormal, 2 special (zeros, infinities, NaN, x < 0) */
    unsigned long long wrong[3] = {0, 0, 0}, seen[3] = {0, 0, 0};
    for (int r = 1; r + 1 < argc; r += 2) {
        unsigned long long lo = strtoull(argv[r], NULL, 16), hi = strtoull(argv[r + 1], NULL, 16);
        unsigned long long w0 = 0, w1 = 0, w2 = 0, s0 = 0, s1 = 0, s2 = 0;
        #pragma omp parallel for schedule(dynamic, 65536) reduction(+:w0,w1,w2,s0,s1,s2)
        for (unsigned long long i = lo; i < hi; i++) {
            uint32_t xb = (uint32_t)i, yb;
            float x, y;
            memcpy(&x, &xb, sizeof x);
            y = %(fn)s(x);
            memcpy(&yb, &y, sizeof yb);
            int ok = correct(xb, yb);
            if (xb >= 0x00800000u && xb < 0x7f800000u) { s0++; w0 += !ok; }
            else if (xb >= 1u && xb < 0x00800000u) { s1++; w1 += !ok; }
            else { s2++; w2 += !ok; }
            if (!ok && w0 + w1 + w2 <= 3) {
                #pragma omp critical
                printf("example %%08x got %%08x\n", (unsigned)xb, (unsigned)yb);
            }
        }
        wrong[0] += w0; wrong[1] += w1; wrong[2] += w2;
        seen[0] += s0; seen[1] += s1; seen[2] += s2;
    }
    printf("normal %%llu %%llu\nsubnormal %%llu %%llu\nspecial %%llu %%llu\n",
           seen[0], wrong[0], seen[1], wrong[1], seen[2], wrong[2]);
    return 0;
}
"""

#: every float32 bit pattern
ALL = ((0, 1 << 32),)


def _cpu_has_fma() -> bool:
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as fh:
            return any(line.startswith("flags") and " fma" in line for line in fh)
    except OSError:
        return False


def check_rsqrt32(source: str, header: str | None, fname: str, ranges=ALL, *,
                  timeout: float = 1800.0) -> dict:
    """Compile ``source`` (defining ``float fname(float)``) with the driver
    and run it over ``ranges`` of bit patterns (half-open ``(lo, hi)``).

    Returns ``{"normal": (inputs, wrong), "subnormal": ..., "special": ...,
    "seconds": wall time of the run, "examples": [...]}``."""
    from chebnorm.core.tools import require, run_tool

    gcc = require("gcc", "the exhaustive binary32 check")
    args = []
    for lo, hi in ranges:
        lo, hi = int(lo), int(hi)
        if not 0 <= lo <= hi <= 1 << 32:
            raise ValueError(f"ranges entry ({lo}, {hi}) is not accepted; accepted: "
                             f"0 <= lo <= hi <= 2**32")
        args += [f"{lo:x}", f"{hi:x}"]
    flags = [*CFLAGS, "-fopenmp"] + (["-mfma"] if _cpu_has_fma() else [])
    with tempfile.TemporaryDirectory(prefix="chebnorm-cr32-") as d:
        if header is not None:
            with open(os.path.join(d, f"{fname}.h"), "w", encoding="utf-8") as fh:
                fh.write(header)
        src = os.path.join(d, f"{fname}.c")
        with open(src, "w", encoding="utf-8") as fh:
            fh.write(source)
        drv = os.path.join(d, "driver.c")
        with open(drv, "w", encoding="utf-8") as fh:
            fh.write(_DRIVER % {"fn": fname})
        exe = os.path.join(d, "check32")
        run_tool([gcc, *flags, "-o", exe, src, drv, "-lm"], tool="gcc", timeout=120, check=True)
        t0 = time.perf_counter()
        proc = run_tool([exe, *args], tool="check32", timeout=timeout, check=True)
        seconds = time.perf_counter() - t0
    out = {"seconds": seconds, "examples": []}
    for line in proc.stdout.splitlines():
        parts = line.split()
        if parts and parts[0] == "example":
            out["examples"].append((int(parts[1], 16), int(parts[3], 16)))
        elif len(parts) == 3 and parts[0] in ("normal", "subnormal", "special"):
            out[parts[0]] = (int(parts[1]), int(parts[2]))
    if not all(k in out for k in ("normal", "subnormal", "special")):
        raise RuntimeError("the exhaustive binary32 check printed no count for every class")
    return out
