"""Fit-and-certify benchmark: chebnorm against Sollya on the 18-case workload.

Runs, in one process and one sitting:
* chebnorm: the Remez fit (exchange, the 50-digit polish when float64 limits
  it, and the float64 monomial coefficients, ``chebnorm.approx.fitting``),
  then certification of sup|p - f| at relative tightness TIGHT
  (bound <= (1 + TIGHT) * sup), timed separately and summed;
  besides, the public ``fit()`` end to end (parsing, the fit and *two*
  certificates, absolute and relative, at 2^-8);
* Sollya (when installed): ``remez`` then ``supnorm(..., absolute, TIGHT)``
  on the same cases, in one sollya process, each part timed by Sollya's own
  ``time()``; so each ratio compares like with like.

Piecewise workload: certify every segment of the 256-segment
degree-2 table of ``1/sqrt(x)`` on [1, 4) (24-bit fixed-point coefficients)
with the batched certifier (``certify_segments``), against one Sollya process
running ``supnorm`` on each segment's composed function ``f(a_s + h t)``, t in
[0, 1], same coefficients, same tightness; and, for reference, chebnorm's
``certify`` run on one segment after another (one run).

Quantization workload (printed last by the plain text run, ``--quantize`` runs it alone): 48 cases (fixed point
8..28 bits, binary16/bfloat16/binary32/binary64, degrees 2..10, odd and even
powers, a fixed constant; 1/sqrt, exp, sin, cos, atan, log(1+x), 2^x, erf, tan;
absolute and relative error). chebnorm: ``quantize`` of a table fitted before
the timer as a user fits it, with the case's powers and fixed constant
(``fit(..., kind="minimax", monomials=..., fix_constant=...)``), so quantize
starts from its real coefficients; where the constant quantize holds (f(0) in
the case's format) is not the fit's (f(0) in binary64), quantize refits,
and that refit is timed with it. Sollya's fpminimax runs its own real fit (timed);
Sollya: in one process, per case ``fpminimax`` then ``supnorm`` at 2^-20 of its
result, each timed by Sollya's ``time()``. Prints per case the seconds, the
ratio, both certified bounds and chebnorm's reference bound
(benchmarks/quantize_bounds_before.json); exit status 1 if the bound of the
case's error kind got worse than that by more than 0.1 %.

Usage: python benchmarks/bench_fit.py [--json] [--repeat N] [--tight T ...] [--piecewise-only]
                                      [--high-degree] [--quantize]
Columns of the 18-case table, seconds summed over the cases, medians of the
``--repeat`` runs (each run does every case once; on both sides parsing the
expression and the interval happens outside the timers):
* fit: chebnorm ``remez`` (float64 exchange to its convergence criterion:
  largest and levelled error within 1e-8 of each other), ``polish`` when the
  exchange is noise limited, ``cheb_to_monomial`` (exact, rounded once);
  Sollya ``remez(f, d, dom)``;
* certify: chebnorm ``certify(fn, coeffs, lo, hi, "abs", tol=T)``, a rigorous
  upper bound of sup|p - f| with bound <= (1 + T) * (located maximum); Sollya
  ``supnorm(p, f, dom, absolute, T)``, an enclosure [l, u] with u/l - 1 <= T;
* both: the median of each run's fit + certify (not the sum of the medians);
* fit(): chebnorm only, the public ``fit()`` end to end (see above);
* worst bound/max-1: the loosest certificate seen (Sollya: u/l - 1).
The speed-up row divides Sollya's column by chebnorm's. A warm-up ``fit()``
of each case before the timed runs compiles its evaluators and Arb encloses
its endpoints (cached, as Sollya holds ``f`` and ``dom`` evaluated); the
exchange's search grid is a per-degree constant, computed in the first run.
Not a test: timings are printed, nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

from chebnorm.approx import fit, parse_function, parse_number, sollya
from chebnorm.approx.certify import certify
from chebnorm.approx.fitting import cheb_to_monomial, polish, remez

WORKLOAD = (
    [("1/sqrt(2+x)", ("sqrt(2)", "2"), d) for d in range(1, 5)]
    + [("1/sqrt(2*(1+x))", ("0", "1"), d) for d in range(1, 5)]
    + [("sqrt(2*(1+x))/2", ("0", "1"), d) for d in range(1, 5)]
    + [("1/sqrt(x)", ("1/2", "2"), d) for d in range(1, 7)]
)
#: the high-degree cases (``--high-degree``)
HIGH_DEGREE = tuple((expr, ("0", "1"), d) for expr in ("exp(x)", "atan(x)") for d in (20, 25, 30))


def run_chebnorm(tight: float, workload=WORKLOAD):
    """Seconds: fit, certify, public fit() end to end; worst bound/max - 1."""
    fits, certs, ends, worst_ratio = [], [], [], 0.0
    for expr, (lo, hi), d in workload:
        fn = parse_function(expr)
        lo_x, hi_x = parse_number(lo), parse_number(hi)
        lo_f, hi_f = float(lo_x), float(hi_x)
        t0 = time.perf_counter()
        res = remez(fn.numpy, None, lo_f, hi_f, d)
        cheb = res.cheb
        if res.noise_limited:  # as fit() does: re-solve in 50 digits (high degree)
            cheb = polish(fn.mpmath, lo_f, hi_f, res.ref, d)
        coeffs = cheb_to_monomial(cheb, lo_f, hi_f)
        t1 = time.perf_counter()
        c = certify(fn, coeffs, lo_x, hi_x, "abs", tol=tight)
        t2 = time.perf_counter()
        fit(expr, (lo, hi), d, kind="minimax")
        t3 = time.perf_counter()
        fits.append(t1 - t0)
        certs.append(t2 - t1)
        ends.append(t3 - t2)
        worst_ratio = max(worst_ratio, c.bound / c.maximum - 1)
    return sum(fits), sum(certs), sum(ends), worst_ratio


def _run_sollya(lines: list[str]) -> tuple[str, float]:
    """Run one Sollya script (its lines) in one process: its output and wall seconds."""
    with tempfile.NamedTemporaryFile("w", suffix=".sollya", delete=False) as fh:
        fh.write("\n".join(lines) + "\n")
    t0 = time.perf_counter()
    try:
        out = subprocess.run(["sollya", "--warnonstderr", fh.name], capture_output=True, text=True,
                             stdin=subprocess.DEVNULL).stdout
    finally:
        os.unlink(fh.name)
    wall = time.perf_counter() - t0
    return out, wall


def run_sollya(tight: float, workload=WORKLOAD):
    lines = ["prec=200!;", "display=decimal!;", "tr=0; ts=0; w=0;"]
    for k, (expr, (lo, hi), d) in enumerate(workload):
        f = sollya.function_text(expr, "x")
        dom = sollya.interval_text(lo, hi)
        lines += [f"f={f};", f"d={dom};",
                  f"t=time(p=remez(f, {d}, d)); tr=tr+t;",
                  f"t=time(r=supnorm(p, f, d, absolute, {tight!r})); ts=ts+t;",
                  "w=max(w, sup(r)/inf(r)-1);"]
    lines += ['print("TIMES", tr, ts, w);', "quit;"]
    out, wall = _run_sollya(lines)
    m = re.search(r"TIMES\s+(\S+)\s+(\S+)\s+(\S+)", out)
    if m is None:
        raise RuntimeError(f"sollya printed no timing line; its output began: {out[:200]!r}")
    return float(m.group(1)), float(m.group(2)), float(m.group(3)), wall


PIECEWISE = ("1/sqrt(x)", ("1", "4"), 2, 256, 24)


def run_piecewise_chebnorm(table, tight: float):
    """Seconds to certify every segment (the batch, ``certify_segments``);
    worst bound/max - 1; the table's bound."""
    from chebnorm.approx.piecewise_table import certify_segments

    t0 = time.perf_counter()
    certs = certify_segments(table, tol=tight)
    elapsed = time.perf_counter() - t0
    return elapsed, max(c.bound / c.maximum - 1 for c in certs), max(c.bound for c in certs)


class _Segment:
    """``t -> f(a + (b - a) t)`` in Arb balls, for ``certify`` one segment at a time."""

    def __init__(self, fn, a, b):
        from flint import ctx

        from chebnorm.approx.certify import arb_enclose

        old, ctx.prec = ctx.prec, 128  # the certifier's working precision
        try:
            a_b, w_b = arb_enclose(a), arb_enclose(b - a)
        finally:
            ctx.prec = old
        self.arb_series = lambda s: fn.arb_series(a_b + w_b * s)
        self.arb = lambda x: fn.arb(a_b + w_b * x)


def run_piecewise_per_segment(table, tight: float):
    """Seconds for the same certificates from ``certify``, one segment after
    another (the path before the batch); the table's bound."""
    import sympy as sp

    fn = parse_function(table.expression, table.variable)
    lo, hi = (sp.Rational(v) for v in table.local_range)
    t0 = time.perf_counter()
    certs = [certify(_Segment(fn, *table.segment_bounds(s)), table.coefficients(s), lo, hi,
                     "abs", tol=tight) for s in range(table.segment_count)]
    return time.perf_counter() - t0, max(c.bound for c in certs)


def run_piecewise_sollya(table, tight: float):
    import sympy as sp

    expr = sollya.function_text(table.expression, table.variable)
    lines = ["prec=200!;", "display=decimal!;", f"f={expr};", "ts=0; w=0; b=0;"]
    for s in range(table.segment_count):
        a, b = table.segment_bounds(s)
        ints = table.segments[s].integers
        poly = " + ".join(f"({q})*2^(-{table.coef_frac_bits})*x^{j}" for j, q in enumerate(ints))
        lines += [f"g=f(({sp.sstr(a)}) + ({sp.sstr(b - a)})*x);".replace("**", "^"), f"p={poly};",
                  f"t=time(r=supnorm(p, g, [0;1], absolute, {tight!r})); ts=ts+t;",
                  "w=max(w, sup(r)/inf(r)-1); b=max(b, sup(r));"]
    lines += ['print("TIMES", ts, w, b);', "quit;"]
    out, wall = _run_sollya(lines)
    m = re.search(r"TIMES\s+(\S+)\s+(\S+)\s+(\S+)", out)
    if m is None:
        raise RuntimeError(f"sollya printed no timing line; its output began: {out[:200]!r}")
    return float(m.group(1)), float(m.group(2)), float(m.group(3)), wall


def piecewise_rows(tights, repeat: int) -> list[dict]:
    from chebnorm.approx.piecewise_fit import piecewise_fit

    expr, interval, degree, segments, frac = PIECEWISE
    table = piecewise_fit(expr, interval, degree, segments=segments, coef_frac_bits=frac)
    rows = []
    for tight in tights:
        # ours takes tens of milliseconds: more repeats steady the median on a loaded machine
        ours = [run_piecewise_chebnorm(table, tight) for _ in range(max(repeat, 7))]
        single = run_piecewise_per_segment(table, tight)
        row = {"workload": f"piecewise {segments} x degree {degree} {expr} on [{interval[0]}, "
                           f"{interval[1]})", "tightness": tight,
               "chebnorm_certify_s": statistics.median(o[0] for o in ours),
               "chebnorm_worst_bound_over_max": max(o[1] for o in ours),
               "chebnorm_bound": ours[0][2], "load_average_1min": os.getloadavg()[0],
               "chebnorm_per_segment_certify_s": single[0],
               "chebnorm_per_segment_bound": single[1]}
        if sollya.available():
            try:
                theirs = [run_piecewise_sollya(table, tight) for _ in range(repeat)]
                row.update({"sollya_supnorm_s": statistics.median(t[0] for t in theirs),
                            "sollya_worst_upper_over_lower": max(t[1] for t in theirs),
                            "sollya_bound": theirs[0][2],
                            "sollya_wall_s": statistics.median(t[3] for t in theirs)})
                row["certify_speedup"] = row["sollya_supnorm_s"] / row["chebnorm_certify_s"]
            except (RuntimeError, OSError) as exc:
                row["sollya"] = f"sollya run failed: {exc}"
        else:
            row["sollya"] = "not installed: apt-get install sollya to compare"
        rows.append(row)
    return rows


# ------------------------------------------------------------ quantization
ODD5, ODD7, ODD9 = (1, 3, 5), (1, 3, 5, 7), (1, 3, 5, 7, 9)
EV4, EV6, EV8 = (0, 2, 4), (0, 2, 4, 6), (0, 2, 4, 6, 8)
PI4 = ("-pi/4", "pi/4")
#: (expression, interval, degree, error, format, frac bits, monomials, fix_constant)
QUANT_WORKLOAD = [
 ("1/sqrt(x)", ("1/4","1"), 2, "rel", "fixed", 8, None, False),
 ("1/sqrt(x)", ("1/4","1"), 3, "rel", "fixed", 12, None, False),
 ("1/sqrt(x)", ("1","2"), 4, "abs", "fixed", 16, None, False),
 ("1/sqrt(x)", ("1","2"), 5, "abs", "fixed", 20, None, False),
 ("1/sqrt(x)", ("1","2"), 10, "rel", "fixed", 28, None, False),
 ("exp(x)", ("0","1"), 2, "abs", "fixed", 8, None, False),
 ("exp(x)", ("0","1"), 3, "abs", "fixed", 12, None, False),
 ("exp(x)", ("0","1"), 5, "abs", "fixed", 20, None, False),
 ("exp(x)", ("0","1"), 7, "rel", "fixed", 28, None, False),
 ("exp(x)", ("-1/2","1/2"), 6, "abs", "fixed", 24, None, False),
 ("sin(x)", PI4, 7, "abs", "fixed", 16, ODD7, False),
 ("sin(x)", PI4, 9, "abs", "fixed", 28, ODD9, False),
 ("sin(x)", ("0","pi/4"), 5, "abs", "fixed", 24, ODD5, False),
 ("cos(x)", PI4, 6, "abs", "fixed", 24, EV6, False),
 ("cos(x)", ("-1/8","1/8"), 6, "abs", "fixed", 28, EV6, False),
 ("cos(x)", PI4, 4, "abs", "fixed", 12, EV4, False),
 ("atan(x)", ("-1","1"), 7, "abs", "fixed", 16, ODD7, False),
 ("atan(x)", ("0","1"), 5, "abs", "fixed", 20, None, False),
 ("atan(x)", ("0","1/4"), 9, "abs", "fixed", 28, ODD9, False),
 ("log(1+x)", ("0","1"), 5, "abs", "fixed", 16, None, False),
 ("log(1+x)", ("0","1"), 8, "abs", "fixed", 24, None, True),
 ("log(1+x)/log(2)", ("0","1"), 6, "abs", "fixed", 20, None, False),
 ("2^x", ("0","1"), 4, "abs", "fixed", 16, None, True),
 ("2^x", ("0","1"), 6, "rel", "fixed", 24, None, False),
 ("erf(x)", ("0","1"), 7, "abs", "fixed", 20, ODD7, False),
 ("erf(x)", ("-1","1"), 9, "abs", "fixed", 24, ODD9, False),
 ("exp(x)", ("0","1"), 4, "abs", "binary16", None, None, False),
 ("exp(x)", ("0","1"), 6, "rel", "binary32", None, None, False),
 ("exp(x)", ("0","1"), 10, "abs", "binary64", None, None, False),
 ("1/sqrt(x)", ("1/4","1"), 4, "rel", "binary16", None, None, False),
 ("1/sqrt(x)", ("1","2"), 6, "rel", "binary32", None, None, False),
 ("1/sqrt(x)", ("1","2"), 8, "rel", "binary64", None, None, False),
 ("sin(x)", ("-1/8","1/8"), 7, "abs", "binary64", None, ODD7, False),
 ("sin(x)", ("-1/8","1/8"), 7, "abs", "binary32", None, ODD7, False),
 ("sin(x)", PI4, 9, "abs", "binary64", None, ODD9, False),
 ("cos(x)", PI4, 8, "abs", "binary32", None, EV8, False),
 ("cos(x)", PI4, 6, "abs", "bfloat16", None, EV6, False),
 ("atan(x)", ("0","1"), 8, "abs", "binary32", None, None, False),
 ("atan(x)", ("-1","1"), 9, "abs", "binary64", None, ODD9, False),
 ("log(1+x)", ("0","1"), 6, "abs", "bfloat16", None, None, False),
 ("log(1+x)", ("0","1"), 9, "abs", "binary64", None, None, False),
 ("2^x", ("0","1"), 6, "abs", "binary64", None, None, True),
 ("2^x", ("0","1"), 5, "rel", "binary32", None, None, False),
 ("2^x", ("0","1"), 3, "abs", "binary16", None, None, False),
 ("erf(x)", ("0","1"), 8, "abs", "binary32", None, None, False),
 ("erf(x)", ("-1","1"), 7, "abs", "binary64", None, ODD7, False),
 ("tan(x)", ("-1/4","1/4"), 7, "abs", "binary64", None, ODD7, False),
 ("exp(x)", ("0","1"), 2, "rel", "bfloat16", None, None, False),
]
#: quantize's reference bounds on QUANT_WORKLOAD (none may get worse)
QUANT_BEFORE = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                            "quantize_bounds_before.json")


#: relative tolerance of that check (candidates are ranked by sampled
#: error and only the best few certified, no longer all of them)
QUANT_TOLERANCE = 1e-3


def _quant_label(case) -> str:
    expr, iv, d, err, fmt, bits, mons, fc = case
    return f"{expr} {iv} d{d} {err} {fmt}{bits or ''} {mons} {fc}"


def _sollya_fit_domain(case) -> str:
    """The domain Sollya's fpminimax is given: the case's interval, except where
    its Remez step meets a degenerate (non-Haar) system, as it does on every
    case here whose powers all vanish at 0 on an interval containing 0, or that
    has one parity on a symmetric interval ("the algorithm does not converge",
    after 1-3 s): there the half interval ``[2^-40, hi]`` (odd powers, or no
    constant) or ``[0, hi]`` (even powers), as a Sollya user does; the error
    is the same by symmetry. supnorm always runs on the whole interval."""
    expr, (lo, hi), d, err, fmt, bits, mons, fc = case
    powers = [k for k in (mons or range(d + 1)) if not (fc and k == 0)]
    sym = parse_number(lo) == -parse_number(hi)
    parity = {k % 2 for k in powers}
    if sym and len(parity) == 1:
        lo = "0" if parity == {0} else "2^(-40)"
    elif parse_number(lo) == 0 and 0 not in powers:
        lo = "2^(-40)"
    return sollya.interval_text(lo, hi).replace("2**(-40)", "2^(-40)")


#: Sollya's precision (floating) of each floating format
SOLLYA_PRECISION = {"binary16": 11, "bfloat16": 8, "binary32": 24, "binary64": 53}


def run_quantize_sollya(constants, workload=QUANT_WORKLOAD, tight: float = 2.0 ** -20):
    """One sollya process: per case ``fpminimax`` then ``supnorm`` of the result
    (the case's error kind, at ``tight``), each timed by Sollya's ``time()``;
    ``constants[i]``: the float p(0) is held at in a fix_constant case (f(0)
    rounded to its format, as quantize holds it), else None.
    Returns per case (seconds, upper bound) or (seconds, None) when Sollya failed;
    and the wall time of the process."""
    lines = ["prec=300!;", "display=decimal!;", "verbosity=0!;"]
    for i, case in enumerate(workload):
        expr, (lo, hi), d, err, fmt, bits, mons, fc = case
        powers = [k for k in (mons or range(d + 1)) if not (fc and k == 0)]
        mode = "absolute" if err == "abs" else "relative"
        width = bits if fmt == "fixed" else SOLLYA_PRECISION[fmt]
        kind = "fixed" if fmt == "fixed" else "floating"
        cons = ""
        if fc:  # the constrained part: p(0), exactly
            num, den = float(constants[i]).as_integer_ratio()
            cons = f", ({num}*2^({1 - den.bit_length()}))"
        lines += [f"f={sollya.function_text(expr)};", f"d={sollya.interval_text(lo, hi)};",
                  f"t1=time(p=fpminimax(f, [|{','.join(map(str, powers))}|], "
                  f"[|{','.join([str(width)] * len(powers))}|], {_sollya_fit_domain(case)}, "
                  f"{kind}, {mode}{cons}));",
                  f"t2=time(r=supnorm(p, f, d, {mode}, {tight!r}));",
                  f'print("Q{i}", t1 + t2, sup(r));']
    lines.append("quit;")
    out, wall = _run_sollya(lines)
    rows = []
    for i in range(len(workload)):
        m = re.search(rf"^Q{i}\s+(\S+)\s+(\S+)\s*$", out, re.M)
        if m is None:
            raise RuntimeError(f"sollya printed no line for case {i}; its output began: "
                               f"{out[:200]!r}")
        sup = None if m.group(2) == "error" else float(m.group(2))
        rows.append((float(m.group(1)), sup))
    return rows, wall


def quantize_tables(workload=QUANT_WORKLOAD):
    """The real fits (minimax, the case's error kind), made before any timer as a
    user makes them: with the case's powers and fixed constant
    (``fit(..., monomials=..., fix_constant=...)``), so quantize starts from
    them. Where the constant quantize holds (f(0) rounded to the case's format)
    differs from the fit's (f(0) in binary64), quantize refits, timed."""
    return [fit(expr, iv, d, kind="minimax", error=err, monomials=mons, fix_constant=fc)
            for expr, iv, d, err, fmt, bits, mons, fc in workload]


def run_quantize_chebnorm(tables, workload=QUANT_WORKLOAD):
    """Seconds of each ``quantize`` (the real fit excluded: ``tables`` are made
    before, with the case's powers; a refit that quantize runs itself, for a
    constant held in another format, is included), the certified bound of the case's error kind and
    both bounds, and the held constant p(0) (fix_constant) or None."""
    from chebnorm.approx import quantize

    rows = []
    for table, (expr, iv, d, err, fmt, bits, mons, fc) in zip(tables, workload):
        t0 = time.perf_counter()
        q = quantize(table, bits, coef_format=fmt, monomials=mons, fix_constant=fc,
                     word_bits=53)
        dt = time.perf_counter() - t0
        qq = q.quantized
        rows.append({"seconds": dt,
                     "bound": qq.abs_error_bound if err == "abs" else qq.rel_error_bound,
                     "abs_error_bound": qq.abs_error_bound,
                     "rel_error_bound": qq.rel_error_bound, "method": qq.method,
                     "constant": qq.coefficients[0] if fc else None})
    return rows


def quantize_rows(repeat: int) -> dict:
    """The quantization workload: chebnorm's quantize against Sollya's fpminimax +
    supnorm, per case (medians of ``repeat`` runs), with the bound check."""
    workload = QUANT_WORKLOAD
    tables = quantize_tables(workload)
    ours = [run_quantize_chebnorm(tables, workload) for _ in range(repeat)]
    theirs = None
    note = None
    if sollya.available():
        try:
            constants = [r["constant"] for r in ours[0]]
            theirs = [run_quantize_sollya(constants, workload) for _ in range(repeat)]
        except (RuntimeError, OSError) as exc:
            note = f"sollya run failed: {exc}"
    else:
        note = "not installed: apt-get install sollya to compare"
    with open(QUANT_BEFORE) as fh:
        before = json.load(fh)["cases"]
    cases = []
    for i, case in enumerate(workload):
        label = _quant_label(case)
        row = {"case": label,
               "chebnorm_s": statistics.median(o[i]["seconds"] for o in ours),
               "chebnorm_bound": ours[0][i]["bound"], "chebnorm_method": ours[0][i]["method"]}
        old = before.get(label)
        if old is not None:
            row["bound_before"] = old[f"{case[3]}_error_bound"]
            # the bound quantize minimizes (the case's error kind) may not exceed the
            # one before by more than QUANT_TOLERANCE (the other kind's bound is a
            # by-product: the candidate ranking does not look at it)
            k = f"{case[3]}_error_bound"
            row["worse_than_before"] = ours[0][i][k] is None or \
                ours[0][i][k] > (1 + QUANT_TOLERANCE) * old[k]
        if theirs:
            row["sollya_s"] = statistics.median(t[0][i][0] for t in theirs)
            row["sollya_bound"] = theirs[0][0][i][1]
            row["speedup"] = row["sollya_s"] / row["chebnorm_s"]
        cases.append(row)
    out = {"workload": f"quantize, {len(workload)} cases", "cases": cases,
           "chebnorm_total_s": sum(r["chebnorm_s"] for r in cases),
           "worse_than_before": [r["case"] for r in cases if r.get("worse_than_before")],
           "load_average_1min": os.getloadavg()[0]}
    if theirs:
        out["sollya_total_s"] = sum(r["sollya_s"] for r in cases)
        out["sollya_wall_s"] = statistics.median(t[1] for t in theirs)
        out["sollya_failed"] = [r["case"] for r in cases if r["sollya_bound"] is None]
        out["total_speedup"] = out["sollya_total_s"] / out["chebnorm_total_s"]
        out["median_speedup"] = statistics.median(r["speedup"] for r in cases)
    else:
        out["sollya"] = note
    return out


def print_quantize(q: dict) -> None:
    print(f"{q['workload']} (load average {q['load_average_1min']:.2f}); seconds per case, "
          f"bounds of the case's error kind (chebnorm certified; Sollya supnorm's upper)")
    print(f"{'chebnorm':>9} {'sollya':>8} {'ratio':>7}  {'chebnorm bound':>14} {'before':>11} "
          f"{'sollya bound':>12}  case")
    for r in q["cases"]:
        sol = (f"{r['sollya_s']:8.3f} {r['speedup']:6.2f}x" if "sollya_s" in r
               else f"{'':8} {'':7}")
        sb = r.get("sollya_bound")
        sb = "failed" if "sollya_s" in r and sb is None else "" if sb is None else f"{sb:.5e}"
        print(f"{r['chebnorm_s']:9.3f} {sol}  {r['chebnorm_bound']:14.5e} "
              f"{r.get('bound_before', float('nan')):11.5e} {sb:>12}  {r['case']}")
    line = f"total: chebnorm quantize {q['chebnorm_total_s']:.3f} s"
    if "sollya_total_s" in q:
        line += (f", Sollya fpminimax + supnorm {q['sollya_total_s']:.3f} s; speed-up "
                 f"{q['total_speedup']:.2f}x in total, median {q['median_speedup']:.2f}x; "
                 f"Sollya failed on {len(q['sollya_failed'])} case(s)")
    else:
        line += f"; {q['sollya']}"
    print(line)
    print("bounds: " + ("none worse than the reference bounds by more than "
                        f"{QUANT_TOLERANCE:.1%}" if not
                        q["worse_than_before"] else "WORSE than the reference: "
                        + "; ".join(q["worse_than_before"])))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tight", type=float, nargs="+", default=[2.0 ** -8, 2.0 ** -20])
    ap.add_argument("--piecewise-only", action="store_true",
                    help="run only the piecewise workload")
    ap.add_argument("--high-degree", action="store_true",
                    help="the workload exp(x), atan(x) on [0, 1] at degree 20, 25, 30 instead")
    ap.add_argument("--quantize", action="store_true",
                    help="run only the quantization workload: quantize against "
                         "Sollya's fpminimax + supnorm; exit status 1 if a bound got worse")
    args = ap.parse_args(argv)
    if args.quantize:
        q = quantize_rows(args.repeat)
        if args.json:
            print(json.dumps(q, indent=2, sort_keys=True))
        else:
            print_quantize(q)
        return 1 if q["worse_than_before"] else 0
    workload = HIGH_DEGREE if args.high_degree else WORKLOAD
    for expr, (lo, hi), d in workload:  # warm-up: imports, compiled functions
        fit(expr, (lo, hi), 1)
    results = []
    for tight in ([] if args.piecewise_only else args.tight):
        ours = [run_chebnorm(tight, workload) for _ in range(args.repeat)]
        row = {"tightness": tight, "cases": len(workload),
               "chebnorm_fit_s": statistics.median(o[0] for o in ours),
               "chebnorm_certify_s": statistics.median(o[1] for o in ours),
               "chebnorm_fit_and_certify_s": statistics.median(o[0] + o[1] for o in ours),
               "chebnorm_fit_api_s": statistics.median(o[2] for o in ours),
               "chebnorm_worst_bound_over_max": max(o[3] for o in ours)}
        theirs = None
        if sollya.available():
            try:
                theirs = [run_sollya(tight, workload) for _ in range(args.repeat)]
            except (RuntimeError, OSError) as exc:
                row["sollya"] = f"sollya run failed: {exc}"
        if theirs:
            row.update({"sollya_remez_s": statistics.median(t[0] for t in theirs),
                        "sollya_supnorm_s": statistics.median(t[1] for t in theirs),
                        "sollya_remez_and_supnorm_s": statistics.median(t[0] + t[1] for t in theirs),
                        "sollya_worst_upper_over_lower": max(t[2] for t in theirs),
                        "sollya_wall_s": statistics.median(t[3] for t in theirs)})
            row["fit_speedup"] = row["sollya_remez_s"] / row["chebnorm_fit_s"]
            row["certify_speedup"] = row["sollya_supnorm_s"] / row["chebnorm_certify_s"]
            row["fit_and_certify_speedup"] = (row["sollya_remez_and_supnorm_s"]
                                              / row["chebnorm_fit_and_certify_s"])
        elif "sollya" not in row:
            row["sollya"] = "not installed: apt-get install sollya to compare"
        results.append(row)
    pw = [] if args.high_degree else piecewise_rows(args.tight, args.repeat)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    if args.json:
        print(json.dumps(results + pw, indent=2, sort_keys=True))
    else:
        print(f"load average (1 min) {load:.2f}; {len(workload)} cases, medians of "
              f"{args.repeat} runs, seconds")
        print(f"{'tightness':>10} {'':9} {'fit':>7} {'certify':>8} {'both':>7} {'fit()':>7}  worst bound/max-1")
        for r in results:
            print(f"{r['tightness']:10.3g} {'chebnorm':9} {r['chebnorm_fit_s']:7.3f} "
                  f"{r['chebnorm_certify_s']:8.3f} {r['chebnorm_fit_and_certify_s']:7.3f} "
                  f"{r['chebnorm_fit_api_s']:7.3f}  {r['chebnorm_worst_bound_over_max']:.2e}")
            if "sollya_supnorm_s" in r:
                print(f"{'':10} {'sollya':9} {r['sollya_remez_s']:7.3f} {r['sollya_supnorm_s']:8.3f} "
                      f"{r['sollya_remez_and_supnorm_s']:7.3f} {'':7}  "
                      f"{r['sollya_worst_upper_over_lower']:.2e}")
                print(f"{'':10} {'speed-up':9} {r['fit_speedup']:6.1f}x {r['certify_speedup']:7.1f}x "
                      f"{r['fit_and_certify_speedup']:6.1f}x")
            else:
                print(f"{'':10} {r['sollya']}")
        for r in pw:
            print(f"{r['workload']}, tightness {r['tightness']:.3g}: chebnorm certify "
                  f"{r['chebnorm_certify_s']:.3f} s (worst bound/max - 1 = "
                  f"{r['chebnorm_worst_bound_over_max']:.2e}, bound {r['chebnorm_bound']:.6e}); "
                  f"load average {r['load_average_1min']:.2f}")
            print(f"  chebnorm one segment at a time (certify) "
                  f"{r['chebnorm_per_segment_certify_s']:.3f} s (bound "
                  f"{r['chebnorm_per_segment_bound']:.6e}); the batch is "
                  f"{r['chebnorm_per_segment_certify_s'] / r['chebnorm_certify_s']:.1f}x faster")
            if "sollya_supnorm_s" in r:
                print(f"  sollya supnorm {r['sollya_supnorm_s']:.3f} s (worst upper/lower - 1 = "
                      f"{r['sollya_worst_upper_over_lower']:.2e}, bound {r['sollya_bound']:.6e}); "
                      f"speed-up {r['certify_speedup']:.1f}x")
            else:
                print(f"  {r['sollya']}")
    if not (args.json or args.piecewise_only or args.high_degree):
        # the whole text run prints the quantization workload last
        q = quantize_rows(args.repeat)
        print_quantize(q)
        return 1 if q["worse_than_before"] else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
