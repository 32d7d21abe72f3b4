"""The full-basis parity comparison with Sollya 8 (issue 41), shared by
tests/test_sollya_parity.py and ``python tests/sollya_parity_cases.py`` (which
prints the table): an odd or even ``f`` on a symmetric interval quantized to a
floating format with NO ``monomials`` given -- what a new user types -- by
chebnorm (``fit(..., kind="minimax", coef_format=...)``) and by Sollya's
``fpminimax(f, n, [|p...|], I, floating, absolute)`` with the full degree
(what the same user types there), in one Sollya process. Sollya also bounds
chebnorm's own polynomial (``supnorm``), whose lower end chebnorm's certified
bound must not undercut.
"""

from __future__ import annotations

import re
import time
import warnings

from chebnorm.approx import fit, sollya

B16, BF16, B32, B64 = "binary16", "bfloat16", "binary32", "binary64"

#: (expr, lo, hi, degree, format): odd and even f, symmetric intervals, all powers
CASES = [
    # the five rows of issue 41's table
    ("sin(x)", "-pi/4", "pi/4", 7, B32),
    ("tan(x)", "-1/4", "1/4", 7, B32),
    ("cos(x)", "-pi/4", "pi/4", 8, B32),
    ("sinh(x)", "-1", "1", 7, BF16),
    ("cosh(x)", "-1/2", "1/2", 6, B32),
    # odd
    ("sin(x)", "-1/2", "1/2", 5, B32),
    ("sin(x)", "-pi/4", "pi/4", 8, B32),
    ("sin(x)", "-pi/4", "pi/4", 9, B64),
    ("sin(x)", "-1", "1", 7, B16),
    ("tan(x)", "-1/4", "1/4", 9, B64),
    ("tan(x)", "-1/2", "1/2", 7, B32),
    ("atan(x)", "-1/2", "1/2", 9, B32),
    ("atan(x)", "-1/4", "1/4", 7, B64),
    ("atan(x)", "-1", "1", 11, B32),
    ("erf(x)", "-1/2", "1/2", 7, B32),
    ("erf(x)", "-1", "1", 9, B64),
    ("sinh(x)", "-1/2", "1/2", 5, B32),
    ("sinh(x)", "-1", "1", 9, B64),
    ("x*exp(-x**2)", "-1/2", "1/2", 7, B32),
    ("x*exp(-x**2)", "-1", "1", 9, B64),
    ("x*exp(-x**2)", "-1/4", "1/4", 5, BF16),
    # even
    ("cos(x)", "-1/2", "1/2", 6, B32),
    ("cos(x)", "-pi/4", "pi/4", 7, B32),
    ("cos(x)", "-pi/4", "pi/4", 10, B64),
    ("cos(x)", "-1", "1", 6, BF16),
    ("cosh(x)", "-1", "1", 8, B64),
    ("cosh(x)", "-1/2", "1/2", 4, B16),
    ("exp(-x**2)", "-1/2", "1/2", 6, B32),
    ("exp(-x**2)", "-1", "1", 10, B64),
]

ODD = ("sin(x)", "tan(x)", "atan(x)", "erf(x)", "sinh(x)", "x*exp(-x**2)")
EVEN = ("cos(x)", "cosh(x)", "exp(-x**2)")


def label(case) -> str:
    expr, lo, hi, n, fmt = case
    return f"{expr} [{lo}, {hi}] d{n} {fmt}"


def _script(i: int, case, table) -> str:
    """Sollya's fpminimax on the full degree (``S<i> lower upper`` of its
    supnorm) and the supnorm of chebnorm's quantized polynomial (``K<i>``)."""
    expr, lo, hi, n, fmt = case
    p = sollya._SOLLYA_PRECISION[fmt]
    return (f"f={sollya.function_text(expr)};\nI={sollya.interval_text(lo, hi)};\n"
            f"z=fpminimax(f, {n}, [|{p}...|], I, floating, absolute);\n"
            f"r=supnorm(z, f, I, absolute, 2^-12);\nprint(\"S{i}\", inf(r), sup(r));\n"
            f"k={sollya._poly(table.quantized.coefficients)};\n"
            f"r=supnorm(k, f, I, absolute, 2^-12);\nprint(\"K{i}\", inf(r), sup(r));\n")


def run():
    """chebnorm on every case, then Sollya on all at once.

    Returns (rows, seconds chebnorm, seconds Sollya); each row: the case, the
    quantized table, Sollya's fpminimax supnorm [lower, upper] and Sollya's
    supnorm [lower, upper] of chebnorm's polynomial (None when Sollya failed).
    """
    t0 = time.perf_counter()
    tables = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for case in CASES:
            expr, lo, hi, n, fmt = case
            tables.append((case, fit(expr, (lo, hi), n, kind="minimax", coef_format=fmt)))
    t1 = time.perf_counter()
    parts = ["prec=300!;", "display=dyadic!;", "verbosity=0!;"]
    parts += [_script(i, case, q) for i, (case, q) in enumerate(tables)]
    out = sollya._run("\n".join(parts) + "\n", timeout=1200)
    t2 = time.perf_counter()
    num = r"[-+]?[0-9]+(?:b[-+]?[0-9]+)?"
    rows = []
    for i, (case, q) in enumerate(tables):
        got = {}
        for key in "SK":
            m = re.search(rf"^{key}{i}\s+({num})\s+({num})\s*$", out, re.M)
            got[key] = None if m is None else [float(sollya._dyadic(v)) for v in m.groups()]
        rows.append((case, q, got["S"], got["K"]))
    return rows, t1 - t0, t2 - t1


if __name__ == "__main__":
    rows, tc, ts = run()
    for case, q, sup, ours in rows:
        theirs = sup[1] if sup else float("nan")
        b = q.quantized.abs_error_bound
        print(f"{label(case)}: ours {b:.4e} ({q.quantized.method}) fpminimax {theirs:.4e} "
              f"ratio {b / theirs:.4f}")
    print(f"cases {len(rows)}, chebnorm {tc:.1f} s, sollya {ts:.1f} s")
