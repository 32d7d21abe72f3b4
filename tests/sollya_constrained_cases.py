"""The constrained-fit comparison with Sollya 8 (issue 25), shared by
tests/test_sollya_constrained.py and ``python tests/sollya_constrained_cases.py``
(which prints the table): every case quantized by chebnorm and by Sollya's
``fpminimax`` (same powers, format, constant), and chebnorm's real fit against
Sollya's ``remez`` on the same powers, in one Sollya process.

Sollya's ``remez`` reports a degenerate, non-Haar system and does not converge
for odd powers on an interval containing 0, so the reference real fit is
posed as the Haar problem it is: odd (even) powers of an odd (even) ``f`` on
``[-a, a]`` are ``x^m q(x^2)``, a weighted fit of ``f(sqrt t)`` in ``t`` on
``[0, a^2]``; powers ``m..n`` on ``[0, b]`` are ``x^m q(x)``, a weighted fit on
``[0, b]`` (the lower end moved to 2^-80, where the error is below every
level here).
"""

from __future__ import annotations

import re
import time

from chebnorm.approx import fit, sollya

ODD7, ODD9, EVEN6, EVEN8 = (1, 3, 5, 7), (1, 3, 5, 7, 9), (0, 2, 4, 6), (0, 2, 4, 6, 8)
B64, B32 = ("binary64", None), ("binary32", None)
F28, F24, F20 = ("fixed", 28), ("fixed", 24), ("fixed", 20)

#: (expr, lo, hi, degree, monomials or None, fix_constant, (format, frac_bits), error)
CASES = [
    # the six rows of issue 25's table
    ("sin(x)", "-1/8", "1/8", 7, ODD7, False, B64, "abs"),
    ("sin(x)", "-1/8", "1/8", 7, ODD7, False, B32, "abs"),
    ("cos(x)", "-1/8", "1/8", 6, EVEN6, False, F28, "abs"),
    ("2**x", "0", "1", 6, None, True, B64, "abs"),
    ("tan(x)", "-1/4", "1/4", 7, ODD7, False, B64, "abs"),
    ("sin(x)", "-pi/4", "pi/4", 9, ODD9, False, B64, "abs"),
    # odd on symmetric intervals
    ("sin(x)", "-pi/4", "pi/4", 7, ODD7, False, F28, "abs"),
    ("sin(x)", "-pi/4", "pi/4", 7, ODD7, False, B32, "abs"),
    ("tan(x)", "-1/4", "1/4", 9, ODD9, False, B64, "abs"),
    ("tan(x)", "-1/4", "1/4", 7, ODD7, False, F28, "abs"),
    ("atan(x)", "-1", "1", 7, ODD7, False, B64, "abs"),
    ("atan(x)", "-1/2", "1/2", 9, ODD9, False, B64, "abs"),
    ("erf(x)", "-1/2", "1/2", 7, ODD7, False, B64, "abs"),
    ("erf(x)", "-1/2", "1/2", 7, ODD7, False, F28, "abs"),
    ("sinh(x)", "-1/2", "1/2", 7, ODD7, False, B64, "abs"),
    ("sinh(x)", "-1/2", "1/2", 7, ODD7, False, F24, "abs"),
    # odd on one-sided intervals
    ("sin(x)", "0", "pi/4", 7, ODD7, False, B64, "abs"),
    ("sin(x)", "0", "pi/4", 7, ODD7, False, F28, "abs"),
    ("tan(x)", "0", "1/4", 7, ODD7, False, B64, "abs"),
    ("atan(x)", "0", "1/2", 9, ODD9, False, B64, "abs"),
    ("erf(x)", "0", "1/2", 7, ODD7, False, B64, "abs"),
    ("sinh(x)", "0", "1/2", 7, ODD7, False, B64, "abs"),
    ("sinh(x)", "0", "1/2", 7, ODD7, False, F28, "abs"),
    # even
    ("cos(x)", "-pi/4", "pi/4", 6, EVEN6, False, B64, "abs"),
    ("cos(x)", "-pi/4", "pi/4", 6, EVEN6, False, B32, "abs"),
    ("cos(x)", "-pi/4", "pi/4", 8, EVEN8, False, F28, "abs"),
    ("exp(-x**2)", "-1", "1", 8, EVEN8, False, B64, "abs"),
    ("exp(-x**2)", "-1", "1", 8, EVEN8, False, F24, "abs"),
    ("cosh(x)", "-1/2", "1/2", 6, EVEN6, False, B64, "abs"),
    ("cosh(x)", "-1/2", "1/2", 6, EVEN6, False, F28, "abs"),
    ("cos(x)", "0", "pi/4", 6, EVEN6, False, B64, "abs"),
    ("cosh(x)", "-1/2", "1/2", 6, EVEN6, False, B64, "rel"),
    # a fixed constant
    ("2**x", "0", "1", 6, None, True, F28, "abs"),
    ("exp(x)", "0", "1/2", 5, None, True, B64, "abs"),
    ("exp(x)", "0", "1/2", 5, None, True, F28, "abs"),
    ("log(1+x)", "0", "1/2", 6, None, True, B64, "abs"),
    ("cos(x)", "-1/4", "1/4", 6, (2, 4, 6), True, B64, "abs"),
    ("exp(x)", "0", "1/4", 5, None, True, B32, "abs"),
    ("2**x", "0", "1", 6, None, True, B64, "rel"),
    # unconstrained (the minimax fit of all powers)
    ("exp(x)", "0", "1", 5, None, False, B64, "abs"),
    ("exp(x)", "0", "1", 7, None, False, B64, "abs"),
    ("exp(x)", "0", "1", 5, None, False, F28, "abs"),
    ("exp(x)", "0", "1", 6, None, False, B64, "rel"),
    ("log(1+x)", "0", "1", 6, None, False, B64, "abs"),
    ("log(1+x)", "0", "1", 6, None, False, F28, "abs"),
    ("atan(x)", "0", "1", 7, None, False, B64, "abs"),
    ("1/sqrt(x)", "1/4", "1", 5, None, False, B64, "rel"),
    ("1/sqrt(x)", "1/4", "1", 4, None, False, F24, "rel"),
    ("sqrt(x)", "1", "2", 5, None, False, B64, "abs"),
    ("sqrt(x)", "1", "2", 4, None, False, B32, "abs"),
    ("1/(1+x)", "0", "1", 6, None, False, B64, "abs"),
    ("1/(1+x)", "0", "1", 6, None, False, F28, "abs"),
    ("exp(x)", "-1/2", "1/2", 6, None, False, B64, "abs"),
    ("sin(x)", "0", "1", 6, None, False, B64, "abs"),
    ("cos(x)", "0", "1", 6, None, False, F28, "abs"),
    ("2**x", "0", "1", 6, None, False, B64, "abs"),
    ("2**x", "0", "1", 5, None, False, B32, "rel"),
    ("log(x)", "1", "2", 6, None, False, B64, "abs"),
    ("exp(x)", "0", "1", 4, None, False, F20, "abs"),
    ("tanh(x)", "0", "1", 7, None, False, B64, "abs"),
    ("asin(x)", "0", "1/2", 6, None, False, B64, "abs"),
    ("1/(2+x)", "-1", "1", 7, None, False, B64, "rel"),
]


def _powers(case) -> tuple[int, ...]:
    expr, lo, hi, n, mons, fix, _, _ = case
    mons = tuple(range(n + 1)) if mons is None else tuple(mons)
    return tuple(k for k in mons if not (fix and k == 0))


def _parity(case) -> int | None:
    """0 or 1 when the case is an even (odd) f with powers of that parity on [-a, a]."""
    expr, lo, hi, *_ = case
    if not lo.startswith("-") or lo[1:] != hi:
        return None
    ps = set(k % 2 for k in _powers(case))
    return ps.pop() if len(ps) == 1 else None


def remez_script(i: int, case, constant: float | None) -> str:
    """A Sollya script printing ``R<i> <sup of the weighted error>`` of Sollya's
    ``remez`` on the case's powers, posed as a Haar problem (module docstring)."""
    expr, lo, hi, n, mons, fix, _, kind = case
    f = sollya.function_text(expr)
    c0 = "0" if constant is None else sollya._exact(constant)
    pw = _powers(case)
    m = min(pw)
    par = _parity(case)
    ends = sollya.interval_text(lo, hi)[1:-1].split(";")
    if par is not None or (len(pw) > 1 and pw[1] - pw[0] == 2):
        assert list(pw) == list(range(m, max(pw) + 1, 2)) and (par is not None or lo[0] != "-")
        low = "1b-80" if par is not None else f"max(1b-80, ({ends[0]})^2)"
        dom = f"[{low};({ends[1]})^2]"
        g, w, deg = f"(F(sqrt(x)) - {c0})", f"sqrt(x)^{m}", (max(pw) - m) // 2
        fv = "F(sqrt(x))"
    else:
        assert list(pw) == list(range(m, max(pw) + 1))
        low = ends[0] if m == 0 else f"max(1b-80, {ends[0]})"
        dom, g, w, deg, fv = f"[{low};{ends[1]}]", f"(F(x) - {c0})", f"x^{m}", max(pw) - m, "F(x)"
    if kind == "rel":
        g, w = f"{g}/{fv}", f"{w}/{fv}"
    back = "x^2" if par is not None or (len(pw) > 1 and pw[1] - pw[0] == 2) else "x"
    return (f"F={f};\nd={dom};\ng={g};\nw={w};\np=remez(g, {deg}, d, w);\n"
            f"print(\"R{i}\", dirtyinfnorm(p*w - g, d));\n"
            f"P=horner(expand(x^{m} * p({back})));\n")


def run():
    """chebnorm (quantized and real) on every case, then Sollya on all at once.

    Returns (rows, seconds chebnorm, seconds Sollya); each row: the case, the
    quantized table, the real table, Sollya's fpminimax result dict and its
    remez error (float, or None when Sollya failed).
    """
    t0 = time.perf_counter()
    tables = []
    for case in CASES:
        expr, lo, hi, n, mons, fix, (fmt, bits), kind = case
        common = dict(kind="minimax", error=kind, monomials=mons, fix_constant=fix)
        q = fit(expr, (lo, hi), n, coef_format=fmt, coef_frac_bits=bits, **common)
        real = fit(expr, (lo, hi), n, **common) if (mons or fix) else fit(
            expr, (lo, hi), n, kind="minimax", error=kind)
        tables.append((case, q, real))
    t1 = time.perf_counter()
    parts = ["prec=300!;", "display=dyadic!;", "verbosity=0!;"]
    for i, (case, q, _) in enumerate(tables):
        parts.append(_fpminimax_script(i, case, q))
    out = sollya._run("\n".join(parts) + "\n", timeout=1200)
    t2 = time.perf_counter()
    rows = []
    num = r"[-+]?[0-9]+(?:b[-+]?[0-9]+)?"
    for i, (case, q, real) in enumerate(tables):
        got = {}
        for key in "RSK":
            m = re.search(rf"^{key}{i}\s+({num})(?:\s+({num}))?\s*$", out, re.M)
            got[key] = None if m is None else [float(sollya._dyadic(v)) for v in m.groups() if v]
        rows.append((case, q, real, got["S"], got["K"], got["R"] and got["R"][0]))
    return rows, t1 - t0, t2 - t1


def _fpminimax_script(i: int, case, q) -> str:
    """Sollya's remez (posed as a Haar problem), then fpminimax on the case's
    powers and format given that minimax polynomial, and the supnorms of its
    answer (``S<i> lower upper``) and of chebnorm's (``K<i> lower upper``)."""
    expr, lo, hi, n, mons, fix, (fmt, bits), kind = case
    qz = q.quantized
    c0 = qz.coefficients[0] if fix else None
    pw = _powers(case)
    if fmt == "fixed":
        fmts, what = [bits] * len(pw), "fixed"
    else:
        fmts, what = [sollya._SOLLYA_PRECISION[fmt]] * len(pw), "floating"
    mode = "absolute" if kind == "abs" else "relative"
    const = "0" if c0 is None else sollya._exact(c0)
    return (remez_script(i, case, c0).replace("display=decimal!;", "")
            + f"f=F(x);\nI={sollya.interval_text(lo, hi)};\n"
            + f"z=fpminimax(f, [|{','.join(map(str, pw))}|], [|{','.join(map(str, fmts))}|], I, "
            + f"{what}, {mode}, {const}, P);\n"
            + f"r=supnorm(z, f, I, {mode}, 2^-12);\nprint(\"S{i}\", inf(r), sup(r));\n"
            + f"k={sollya._poly(qz.coefficients)};\nr=supnorm(k, f, I, {mode}, 2^-12);\n"
            + f"print(\"K{i}\", inf(r), sup(r));\n")


def quantized_bound(q) -> float:
    return q.quantized.abs_error_bound if q.error_kind == "abs" else q.quantized.rel_error_bound


def real_error(t) -> float:
    return t.max_abs_error if t.error_kind == "abs" else t.max_rel_error


def label(case) -> str:
    expr, lo, hi, n, mons, fix, (fmt, bits), kind = case
    return (f"{expr} [{lo}, {hi}] d{n} {kind} {fmt}{bits or ''}"
            + (f" x^{','.join(map(str, mons))}" if mons else "") + (" c0" if fix else ""))


if __name__ == "__main__":
    rows, tc, ts = run()
    for case, q, real, sup, ours, rem in rows:
        theirs = sup[1] if sup else float("nan")
        print(f"{label(case)}: ours {quantized_bound(q):.4e} fpminimax {theirs:.4e} ratio "
              f"{quantized_bound(q) / theirs:.4f} | real {real_error(real):.5e} remez "
              f"{rem if rem is None else format(rem, '.5e')}")
    print(f"cases {len(rows)}, chebnorm {tc:.1f} s, sollya {ts:.1f} s")
