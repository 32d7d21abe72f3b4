"""The coefficient-format comparison with Sollya's fpminimax (shared by
tests/test_formats.py and the figure in docs/formats.md): one Sollya process for all cases.

Run ``python tests/formats_cases.py`` for the table of ratios.
"""

from __future__ import annotations

import time

from chebnorm.approx import fit, get_target, quantize, sollya, target_names

#: (expression, variable, interval, degree, kind, error, monomials)
PROBLEMS = [
    ("exp(x)", "x", ("0", "1"), 4, "minimax", "abs", None),
    ("exp(x)", "x", ("0", "1"), 6, "minimax", "rel", None),
    ("log(1+x)/log(2)", "x", ("0", "1"), 5, "minimax", "abs", None),
    ("atan(x)", "x", ("0", "1"), 5, "minimax", "abs", None),
    ("sin(x)", "x", ("-pi/4", "pi/4"), 7, "minimax", "abs", (1, 3, 5, 7)),
    ("1/sqrt(x)", "x", ("1/4", "1"), 4, "minimax", "rel", None),
] + [(get_target(n).expression, get_target(n).variable, get_target(n).interval("pi/4"), 3,
      "minimax", "abs", None) for n in target_names()]

#: fixed formats as fractional bits; floating by name
FORMATS = [("fixed", 16), ("fixed", 24), ("binary16", None), ("bfloat16", None),
           ("binary32", None)]


def run():
    """Quantize every case with chebnorm, then run Sollya on all of them at once.

    Returns (rows, seconds_chebnorm, seconds_sollya); each row: case label,
    the chebnorm table, Sollya's result dict (or None).
    """
    tables = []
    t0 = time.perf_counter()
    for expr, var, iv, degree, kind, error, mons in PROBLEMS:
        base = fit(expr, iv, degree, kind=kind, error=error, var=var)
        for fmt, bits in FORMATS:
            q = quantize(base, bits, coef_format=fmt, monomials=mons, word_bits=53)
            label = f"{expr} [{iv[0]}, {iv[1]}] d{degree} {error} {fmt}{bits or ''}" + (
                f" x^{','.join(map(str, mons))}" if mons else "")
            tables.append((label, q))
    t1 = time.perf_counter()
    cases = [sollya.FpminimaxCase(
        expr=q.expression, var=q.variable, lo=q.interval[0], hi=q.interval[1],
        monomials=q.quantized.monomials, coef_format=q.quantized.format,
        frac_bits=q.quantized.frac_bits, kind=q.error_kind, check=q.quantized.coefficients)
        for _, q in tables]
    results = sollya.fpminimax(cases)
    t2 = time.perf_counter()
    return [(label, q, r) for (label, q), r in zip(tables, results)], t1 - t0, t2 - t1


def bound_of(q):
    return q.quantized.abs_error_bound if q.error_kind == "abs" else q.quantized.rel_error_bound


def summary(rows):
    """(cases, better, ties, worse, worst ratio): ``better`` when chebnorm's
    supnorm is provably below fpminimax's (its upper enclosure below theirs
    by more than the enclosures' widths), ``worse`` when provably above,
    ``ties`` otherwise; ratio of the upper enclosures."""
    better = ties = worse = 0
    worst = 0.0
    for _, q, r in rows:
        theirs = r["sup"]
        # when Sollya's supnorm cannot enclose chebnorm's error (it fails, for
        # example, when the maximum is attained exactly at an endpoint), chebnorm's
        # own certified bound stands in for both ends: this only counts against it
        b = bound_of(q)
        ours = r["check_sup"] or sollya.SollyaSupnorm(b, b)
        if ours.upper < theirs.lower:
            better += 1
        elif ours.lower > theirs.upper:
            worse += 1
        else:
            ties += 1
        worst = max(worst, ours.upper / theirs.upper)
    unchecked = sum(r["check_sup"] is None for _, _, r in rows)
    return len(rows), better, ties, worse, worst, unchecked


if __name__ == "__main__":
    rows, tc, ts = run()
    for label, q, r in rows:
        if r is None or r["check_sup"] is None:
            print(f"{label}: ours {bound_of(q):.5e} (certified; Sollya's supnorm failed) "
                  f"sollya {r and r['sup'].upper:.5e}")
            continue
        print(f"{label}: ours {r['check_sup'].upper:.5e} sollya {r['sup'].upper:.5e} "
              f"ratio {r['check_sup'].upper / r['sup'].upper:.6f} ({q.quantized.method})")
    print("cases %d, better %d, ties %d, worse %d, worst ratio %.6f, not enclosed by "
          "Sollya %d" % summary(rows))
    print(f"chebnorm {tc:.1f} s, sollya {ts:.1f} s")
