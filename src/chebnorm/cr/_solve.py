"""Coefficients by linear programming on rounding intervals, checked on
every input by the exact binary64 simulation (counterexample-guided)."""

from __future__ import annotations


import numpy as np

__all__: list[str] = []


def ro_interval(ro: np.ndarray, fmt):
    """(lo, hi, exact) of the open round-to-odd interval of each RO value
    (``exact``: f(x) = ro, the interval is the point itself)."""
    a = np.abs(ro)
    with np.errstate(all="ignore"):
        e = np.frexp(a)[1] - 1
        q = np.ldexp(1.0, np.maximum(e, fmt.emin) - fmt.precision - 1)
        n = a / q
        exact = (a == 0) | (np.mod(n, 2) == 0)
    lo = np.where(exact, ro, ro - q)
    hi = np.where(exact, ro, ro + q)
    return lo, hi, exact


def evaluate(form: str, c: np.ndarray, u: np.ndarray) -> np.ndarray:
    """P(u) in binary64, in the generated C's operation order."""
    c = np.asarray(c, dtype=np.float64)
    if form == "horner":
        p = np.full(u.shape, c[-1])
        for ci in c[-2::-1]:
            p = p * u + ci
        return p
    s = u * u
    q = np.full(u.shape, c[-1])
    for ci in c[-2::-1]:
        q = q * s + ci
    if form == "odd1":
        return u + u * (s * q)
    if form == "oddc":
        return u * q
    if form == "even1":
        return 1.0 + s * q
    raise ValueError(form)


def c_evaluate(form: str, arr: str, ncoef: int) -> str:
    """The C text computing ``p`` from ``u`` with coefficients ``arr[piece][i]``."""
    if form == "horner":
        s = f"        p = {arr}[piece][{ncoef - 1}];\n"
        for i in range(ncoef - 2, -1, -1):
            s += f"        p = p * u + {arr}[piece][{i}];\n"
        return s
    s = f"        double s = u * u;\n        double q = {arr}[piece][{ncoef - 1}];\n"
    for i in range(ncoef - 2, -1, -1):
        s += f"        q = q * s + {arr}[piece][{i}];\n"
    s += {"odd1": "        p = u + u * (s * q);\n", "oddc": "        p = u * q;\n",
          "even1": "        p = 1.0 + s * q;\n"}[form]
    return s


def _basis(form: str, u: np.ndarray, ncoef: int, fixed_c0):
    """(fixed part, columns) with P(u) = fixed + columns @ z (real arithmetic)."""
    cols = []
    if form == "horner":
        start = 1 if fixed_c0 is not None else 0
        fixed = np.full(u.shape, fixed_c0 if fixed_c0 is not None else 0.0)
        for i in range(start, ncoef):
            cols.append(u ** i)
    else:
        powers = {"odd1": 3, "oddc": 1, "even1": 2}[form]
        fixed = {"odd1": u, "oddc": np.zeros_like(u), "even1": np.ones_like(u)}[form]
        for i in range(ncoef):
            cols.append(u ** (2 * i + powers))
    return fixed, np.stack(cols, axis=1)


def _lp(fixed, cols, L, H):
    from scipy.optimize import linprog

    w = (H - L) / 2
    m = cols.shape[1]
    # variables z (m), t: maximise t s.t. L + t w <= fixed + cols z <= H - t w, rows / w
    a_up = np.hstack([cols / w[:, None], np.ones((len(w), 1))])
    b_up = (H - fixed) / w
    a_lo = np.hstack([-cols / w[:, None], np.ones((len(w), 1))])
    b_lo = -(L - fixed) / w
    # column scaling for conditioning
    scale = np.maximum(np.abs(cols).max(axis=0), 1e-300)
    a = np.vstack([a_up, a_lo])
    a[:, :m] /= scale
    res = linprog(np.r_[np.zeros(m), -1.0], A_ub=a, b_ub=np.r_[b_up, b_lo],
                  bounds=[(None, None)] * m + [(None, 1.0)], method="highs")
    if res.status != 0 or res.x[-1] <= 1e-9:
        return None
    return res.x[:m] / scale


def solve_piece(form, u, A, B, lo, hi, exact, ncoef_range, seed_count=96):
    """Coefficients (binary64) of one piece such that A + B*P(u) lies in
    (lo, hi) (or equals lo when exact) for every point, or None."""
    # interval on P (real), shrunk by the final addition's rounding
    with np.errstate(all="ignore"):
        Lp = (lo - A) / B
        Hp = (hi - A) / B
    Lp, Hp = np.minimum(Lp, Hp), np.maximum(Lp, Hp)
    slack = (np.abs(A) + np.abs(hi)) * 2.0 ** -52 / np.abs(B)
    fixed_c0 = None
    ex0 = exact & (u == 0)
    if (exact & (u != 0)).any():
        return None
    if ex0.any():
        vals = set(((lo[ex0] - A[ex0]) / B[ex0]).tolist())
        if len(vals) != 1:
            return None
        fixed_c0 = vals.pop()
    free = ~exact
    idx_all = np.flatnonzero(free)
    if len(idx_all) == 0:
        c = [fixed_c0 if fixed_c0 is not None else 0.0]
        return np.array(c + [0.0] * (ncoef_range[0] - 1))
    Lq = Lp + np.where(Hp - Lp > 4 * slack, slack, 0)
    Hq = Hp - np.where(Hp - Lp > 4 * slack, slack, 0)
    for ncoef in ncoef_range:
        order = idx_all[np.argsort(u[idx_all], kind="stable")]
        sel = order[np.unique(np.linspace(0, len(order) - 1, min(seed_count, len(order))).astype(int))]
        sel = set(sel.tolist())
        for _ in range(30):
            ix = np.array(sorted(sel))
            fixed, cols = _basis(form, u[ix], ncoef if form != "horner" else ncoef, fixed_c0)
            z = _lp(fixed, cols, Lq[ix], Hq[ix])
            if z is None:
                break
            c = (np.r_[fixed_c0, z] if form == "horner" and fixed_c0 is not None else z)
            c = c.astype(np.float64)
            y = A + B * evaluate(form, c, u)
            ok = np.where(exact, y == lo, (y > lo) & (y < hi))
            bad = np.flatnonzero(~ok)
            if len(bad) == 0:
                return c
            new = set(bad.tolist()) - sel
            if not new:
                break
            # the worst violators first, at most 64 a round
            sel |= set(sorted(new)[:: max(1, len(new) // 64)])
    return None
