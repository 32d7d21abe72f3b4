"""Generation: oracle, kernel, coefficients, exact simulation in all five
modes, and the C text."""

from __future__ import annotations

import time

import numpy as np

from ._formats import MODES
from ._kernels import make_kernel
from ._oracle import oracle
from ._solve import c_evaluate, evaluate, ro_interval, solve_piece

__all__: list[str] = []

#: coefficient counts tried for each piece, in order
NCOEF = {"horner": range(3, 11), "odd1": range(1, 9), "oddc": range(2, 10), "even1": range(1, 9)}
MAX_LEVEL = 3


def simulate(kernel, coefs, x):
    """y (binary64) of every input, exactly as the generated C computes it."""
    sp, ys, fam, piece, u, A, B = kernel.reduce(x)
    y = ys.copy()
    for fi, (fname, form) in enumerate(kernel.families.items()):
        table = coefs[fname]
        for j in range(len(table)):
            m = ~sp & (fam == fi) & (piece == j)
            if m.any():
                y[m] = A[m] + B[m] * evaluate(form, table[j], u[m])
    return y


def wrong_counts(fmt, y, ro, domain=None):
    """Wrongly rounded outputs of y against the oracle, per mode (NaN = NaN),
    counted on ``domain`` (a mask; default every input)."""
    out = {}
    for mode in MODES:
        got, want = fmt.round(y, mode), fmt.round(ro, mode)
        nan_g = np.isnan(y)
        nan_w = np.isnan(ro)
        bad = np.where(nan_w, ~nan_g, got != want)
        if domain is not None:
            bad &= domain
        out[mode] = int(np.count_nonzero(bad))
    return out


def domain_mask(x, interval):
    """The inputs proved: all, or the finite ones in [lo, hi]."""
    if interval is None:
        return np.ones(len(x), bool)
    lo, hi = interval
    with np.errstate(invalid="ignore"):
        return np.isfinite(x) & (x >= lo) & (x <= hi)


def build(name, fmt, interval=None):
    """(kernel, coefficients, figures, oracle values, domain) for ``name`` on
    ``fmt`` (every input, or the finite inputs of ``interval``)."""
    t0 = time.perf_counter()
    bits = fmt.all_bits()
    x_all = fmt.decode(bits)
    dom = domain_mask(x_all, interval)
    # outside the domain the oracle is not asked (the value stands for "any")
    x = np.where(dom, x_all, np.nan)
    ro = oracle(name, fmt, x)
    x = x_all
    t_oracle = time.perf_counter() - t0
    lo, hi, exact = ro_interval(ro, fmt)
    for level in range(MAX_LEVEL + 1):
        kernel = make_kernel(name, fmt, level, ro=ro, values=x)
        sp, ys, fam, piece, u, A, B = kernel.reduce(x)
        coefs, ok = {}, True
        for fi, (fname, form) in enumerate(kernel.families.items()):
            table = []
            for j in range(kernel.npieces(fname)):
                m = ~sp & (fam == fi) & (piece == j) & dom
                if not m.any():
                    table.append(np.zeros(1))
                    continue
                c = solve_piece(form, u[m], A[m], B[m], lo[m], hi[m], exact[m], NCOEF[form])
                if c is None:
                    ok = False
                    break
                table.append(c)
            if not ok:
                break
            # one width per family: zero highest coefficients change nothing in Horner's
            # rule (0 * u + c is c), and the simulation below runs the padded table
            width = max(len(c) for c in table)
            table = [np.r_[c, np.zeros(width - len(c))] for c in table]
            coefs[fname] = table
        if ok:
            y = simulate(kernel, coefs, x)
            wrong = wrong_counts(fmt, y, ro, dom)
            figures = {"inputs": int(dom.sum()), "wrong": wrong, "level": level,
                       "oracle_seconds": t_oracle,
                       "seconds": time.perf_counter() - t0,
                       "pieces": {f: len(t) for f, t in coefs.items()},
                       "coefficients": {f: (len(t[0]) if t else 0) for f, t in coefs.items()}}
            if sum(wrong.values()) == 0:
                return kernel, coefs, figures, ro, dom
    raise ArithmeticError(f"{name} on {fmt.name}: no piecewise polynomial found up to level "
                          f"{MAX_LEVEL}")


def c_source(kernel, coefs, fmt, fname, header_name, banner) -> str:
    """The C source of the correctly rounded function."""
    p, bits = fmt.precision, fmt.bits
    lines = [banner, "#include <fenv.h>", "#include <math.h>", "#include <stdint.h>",
             "#include <string.h>", f'#include "{header_name}"', "",
             "#pragma STDC FENV_ACCESS ON", ""]
    for fi, (fam, form) in enumerate(kernel.families.items()):
        table = coefs.get(fam, [])
        if not table:
            continue
        rows = ",\n".join("    {" + ", ".join(c.hex() for c in map(float, row)) + "}"
                          for row in table)
        lines.append(f"static const double CR_{fam}[{len(table)}][{len(table[0])}] = {{\n{rows}\n}};")
    lines.append(kernel.c_tables())
    body = kernel.c_reduce()
    core = ["static double cr_core(double x)", "{"]
    if kernel.families:
        core.append("    int fam, piece;\n    double u, A, B, p;")
    core.append(body.rstrip("\n"))
    if kernel.families:
        for fi, (fam, form) in enumerate(kernel.families.items()):
            table = coefs[fam]
            kw = "if" if fi == 0 else "else if"
            core.append(f"    {kw} (fam == {fi}) {{\n" + c_evaluate(form, f"CR_{fam}", len(table[0]))
                        + "    }")
        core.append("    else p = 0.0;")
        core.append("    return A + B * p;")
    core.append("}")
    lines += core
    lines.append(_ROUND_C.format(P1=p - 1, BITS1=bits - 1, EMIN=fmt.emin, EMAX=fmt.emax,
                                 INF=fmt.inf_bits, NAN=fmt.nan_bits))
    ctype = fmt.ctype
    lines.append(f"""{ctype} {fname}({ctype} xbits)
{{
    uint32_t b = xbits;
    uint32_t s = b >> {bits - 1}, e = (b >> {p - 1}) & {(1 << fmt.exp_bits) - 1}u, m = b & {(1 << (p - 1)) - 1}u;
    double x;
    if (e == {(1 << fmt.exp_bits) - 1}u) x = m ? NAN : INFINITY;
    else if (e == 0) x = ldexp((double)m, {fmt.emin - p + 1});
    else x = ldexp((double)(m | {1 << (p - 1)}u), (int)e - {fmt.emax + p - 1});
    if (s) x = -x;
    int mode = fegetround();
    if (mode != FE_TONEAREST) fesetround(FE_TONEAREST);
    volatile double y = cr_core(x);
    if (mode != FE_TONEAREST) fesetround(mode);
    return ({ctype})cr_round(y, mode);
}}
""")
    return "\n".join(lines)


_ROUND_C = """
/* y rounded to the format in the caller's rounding mode (integer arithmetic
   on the binary64 encoding: one rounding, no double rounding) */
static uint32_t cr_round(double y, int mode)
{{
    uint64_t b;
    memcpy(&b, &y, sizeof b);
    uint32_t sign = (uint32_t)(b >> 63);
    uint64_t ab = b & 0x7fffffffffffffffULL;
    int away = mode == FE_UPWARD ? !sign : mode == FE_DOWNWARD ? (int)sign : mode != FE_TOWARDZERO;
    uint64_t mag;
    if (ab > 0x7ff0000000000000ULL) return {NAN}u;
    if (ab == 0x7ff0000000000000ULL) mag = {INF}u;
    else if (ab == 0) mag = 0;
    else {{
        int e = (int)(ab >> 52) - 1023;
        uint64_t m = (ab & 0xfffffffffffffULL) | (1ULL << 52);
        if ((ab >> 52) == 0) {{ e = -1022; m = ab; }}
        if (e > {EMAX}) mag = away ? {INF}u : {INF}u - 1u;
        else {{
            int ee = e < {EMIN} ? {EMIN} : e;
            int sh = (ee - {P1}) - (e - 52);
            uint64_t n;
            int sticky, above, tie, inc;
            if (sh > 60) {{ n = 0; sticky = m != 0; above = 0; tie = 0; }}
            else {{
                uint64_t rem = m & ((1ULL << sh) - 1), half = 1ULL << (sh - 1);
                n = m >> sh; sticky = rem != 0; above = rem > half; tie = rem == half;
            }}
            if (mode == FE_TOWARDZERO) inc = 0;
            else if (mode == FE_UPWARD) inc = sticky && !sign;
            else if (mode == FE_DOWNWARD) inc = sticky && sign;
            else inc = above || (tie && (n & 1));
            n += (uint64_t)inc;
            mag = ((uint64_t)(ee - ({EMIN})) << {P1}) + n;
            if (mag >= {INF}u) mag = away ? {INF}u : {INF}u - 1u;
        }}
    }}
    return (uint32_t)mag | (sign << {BITS1});
}}
"""
