"""The oracle: f(x) with Arb, rounded to odd at p + 2 bits in the format's
exponent range (below ``2**emin`` the subnormal quantum, 2 bits finer), so
that one value rounds correctly to the format in every IEEE mode.

An Arb ball that contains a point of the round-to-odd grid at every
precision up to :data:`MAX_PREC` is an exact case: f(x) must then be that
grid point, and the function's ``exact`` rule (exp2 of an integer, log2 of a
power of two, sqrt of a square, ...) must say so, else the oracle fails."""

from __future__ import annotations

from fractions import Fraction
from math import isqrt

import numpy as np

from chebnorm.core.numeric import arb_precision

__all__: list[str] = []

#: the largest working precision tried before an ambiguous ball is an exact case
MAX_PREC = 4096


def _dyadic_sqrt(q: Fraction):
    """sqrt(q) when it is a dyadic rational, else None."""
    n, d = q.numerator, q.denominator
    rn, rd = isqrt(n), isqrt(d)
    if rn * rn == n and rd * rd == d:
        return Fraction(rn, rd)
    return None


def _is_pow2(q: Fraction):
    n, d = q.numerator, q.denominator
    if q > 0 and n & (n - 1) == 0 and d & (d - 1) == 0:
        return n.bit_length() - d.bit_length()
    return None


def _exact_exp2(q):
    return Fraction(2) ** int(q) if q.denominator == 1 else None


def _exact_log2(q):
    k = _is_pow2(q)
    return Fraction(k) if k is not None else None


def _exact_rsqrt(q):
    s = _dyadic_sqrt(q) if q > 0 else None
    return 1 / s if s is not None and _is_pow2(s) is not None else None


#: name -> (Arb evaluator (arb -> arb), exact rule (Fraction -> Fraction or None),
#: complement (arb -> arb, 1 - |f| for |x| large) or None)
def _arb_funcs():
    from flint import arb

    return {
        "exp": (lambda a: a.exp(), lambda q: Fraction(1) if q == 0 else None),
        "exp2": (lambda a: (a * arb(2).log()).exp(), _exact_exp2),
        "log": (lambda a: a.log(), lambda q: Fraction(0) if q == 1 else None),
        "log2": (lambda a: a.log() / arb(2).log(), _exact_log2),
        "sin": (lambda a: a.sin(), lambda q: Fraction(0) if q == 0 else None),
        "cos": (lambda a: a.cos(), lambda q: Fraction(1) if q == 0 else None),
        "tanh": (lambda a: a.tanh(), lambda q: Fraction(0) if q == 0 else None),
        "erf": (lambda a: a.erf(), lambda q: Fraction(0) if q == 0 else None),
        "sqrt": (lambda a: a.sqrt(), lambda q: _dyadic_sqrt(q) if q >= 0 else None),
        "rsqrt": (lambda a: a.rsqrt(), _exact_rsqrt),
    }


def _complement(name, a):
    """1 - |f(a)| for tanh and erf (computed without cancellation), else None."""
    if name == "erf":
        return abs(a).erfc()
    if name == "tanh":
        return 2 / ((2 * abs(a)).exp() + 1)
    return None


def _fraction(a) -> Fraction:
    man, exp = a.man_exp()
    man, exp = int(man), int(exp)
    return Fraction(man * 2 ** exp) if exp >= 0 else Fraction(man, 2 ** -exp)


def ro_quantum(v: Fraction, fmt) -> Fraction:
    """The round-to-odd grid spacing at |v| (p + 2 bits, subnormal quantum
    below 2**emin)."""
    v = abs(v)
    if v == 0:
        return Fraction(2) ** (fmt.emin - fmt.precision - 1)
    e = v.numerator.bit_length() - v.denominator.bit_length()
    if Fraction(2) ** e > v:
        e -= 1
    e = max(e, fmt.emin)
    return Fraction(2) ** (e - fmt.precision - 1)


def _ro_of_interval(lo: Fraction, hi: Fraction, fmt):
    """RO of every point of [lo, hi] (0 < lo <= hi) when they agree and no grid
    point lies in [lo, hi], else None."""
    q = ro_quantum(lo, fmt)
    if ro_quantum(hi, fmt) != q:
        return None
    n = lo / q
    nf = n.numerator // n.denominator
    if nf * q == lo or hi >= (nf + 1) * q:
        return None
    return (nf | 1) * q


def _round_fraction_odd(v: Fraction, fmt) -> Fraction:
    if v == 0:
        return v
    s = -1 if v < 0 else 1
    v = abs(v)
    q = ro_quantum(v, fmt)
    n = v / q
    nf = n.numerator // n.denominator
    return s * (nf * q if nf * q == v else (nf | 1) * q)


def oracle_value(name: str, x: float, fmt) -> float:
    """RO_{p+2}(f(x)) as a binary64 (exact); an overflow beyond 2**(emax+2)
    gives +-2**(emax+2)*(1 + 2**-(p+1)) (odd, above every finite value); f(x)
    undefined (log of a negative, ...) gives NaN. ``x`` finite."""
    from flint import arb

    funcs = _arb_funcs()
    f, exact = funcs[name][0], funcs[name][1]
    qx = Fraction(x)
    if name in ("log", "log2") and x < 0 or name in ("sqrt", "rsqrt") and x < 0:
        return float("nan")
    if name in ("log", "log2", "rsqrt") and x == 0:
        return -float("inf") if name != "rsqrt" else float(np.copysign(np.inf, x))
    big = Fraction(2) ** (fmt.emax + 2)
    overflow_value = float(big * (1 + Fraction(1, 2 ** (fmt.precision + 1))))
    scale = {"exp2": 1.0, "exp": 0.7}.get(name)  # 0.7 > ln 2: a safe side of each threshold
    if scale is not None and x >= (fmt.emax + 2) * scale:
        return overflow_value
    if scale is not None and x <= (fmt.emin - fmt.precision - 2) * scale:
        return fmt.q_min  # 0 < f(x) < q_min: round to odd gives q_min
    ex = exact(qx)
    if ex is not None:
        if ex == 0:
            return float(np.copysign(0.0, x)) if name in ("sin", "tanh", "erf", "sqrt") else 0.0
        if abs(ex) >= big:
            return overflow_value if ex > 0 else -overflow_value
        return float(_round_fraction_odd(ex, fmt))
    if name in ("tanh", "erf") and abs(x) >= 32:
        # 1 - |f| < 2 exp(-64) (tanh) or < exp(-1024) (erf): below 2**-(p+2)
        r = 1 - Fraction(1, 2 ** (fmt.precision + 2))
        return float(r if x > 0 else -r)
    prec = 64 + max(0, abs(int(np.frexp(x)[1])))
    while prec <= MAX_PREC:
        with arb_precision(prec):   # one scope per try: the process-wide lock
            a = arb(x)
            c = _complement(name, a)
            if c is not None:
                cu = _fraction(c.upper()) if c.upper().is_finite() else None
                q1 = Fraction(1, 2 ** (fmt.precision + 2))
                if cu is not None and cu < q1:  # 1 - q1 < |f| < 1: RO is 1 - q1
                    r = 1 - q1
                    return float(r if x > 0 else -r)
            v = f(a)
            if v.is_finite():
                lo, hi = _fraction(v.lower()), _fraction(v.upper())
                if lo > 0 or hi < 0:
                    s = 1 if lo > 0 else -1
                    alo, ahi = (lo, hi) if s > 0 else (-hi, -lo)
                    if alo >= big:
                        return overflow_value * s
                    r = _ro_of_interval(alo, ahi, fmt)
                    if r is not None:
                        return float(s * r)
        prec *= 2
    raise ArithmeticError(f"oracle: {name}({x!r}) is not resolved at {MAX_PREC} bits and is "
                          f"not a known exact case")


def oracle(name: str, fmt, values: np.ndarray) -> np.ndarray:
    """:func:`oracle_value` of every finite value; NaN and infinities map by
    the IEEE 754 / C99 Annex F rules of the function."""
    out = np.empty(len(values))
    for i, x in enumerate(values.tolist()):
        if x != x:
            out[i] = np.nan
        elif x in (np.inf, -np.inf):
            out[i] = _special_inf(name, x)
        else:
            out[i] = oracle_value(name, x, fmt)
    return out


def _special_inf(name, x):
    pos = x > 0
    table = {
        "exp": (np.inf, 0.0), "exp2": (np.inf, 0.0), "log": (np.inf, np.nan),
        "log2": (np.inf, np.nan), "sin": (np.nan, np.nan), "cos": (np.nan, np.nan),
        "tanh": (1.0, -1.0), "erf": (1.0, -1.0), "sqrt": (np.inf, np.nan), "rsqrt": (0.0, np.nan),
    }
    return table[name][0 if pos else 1]
