"""Range reductions of the catalogue, written twice in the same operation
order: numpy (the exact simulation of binary64 C without FMA) and C text.

A kernel maps every input x (a binary64) either to a special result y, or to
(family, piece, u, A, B) with y = A + B * P_{family,piece}(u)."""

from __future__ import annotations

import math

import numpy as np

__all__: list[str] = []

LN2 = math.log(2.0)


def _hex(v: float) -> str:
    if v != v:
        return "NAN"
    if v in (math.inf, -math.inf):
        return "INFINITY" if v > 0 else "(-INFINITY)"
    return f"({float(v).hex()})"


def _split(c: float, bits: int):
    """c as hi + lo: hi with ``bits`` significant bits."""
    m, e = math.frexp(c)
    hi = math.ldexp(math.floor(m * 2 ** bits), e - bits)
    return hi, c - hi


class Kernel:
    """One function on one format: reduction, families, thresholds."""

    #: family name -> form ("horner", "odd1", "oddc", "even1")
    families: dict = {}

    def __init__(self, name, fmt, h=None):
        self.name, self.fmt = name, fmt
        self.h = h

    # numpy side returns (special mask, special y, fam (int), piece, u, A, B)
    def reduce(self, x):
        raise NotImplementedError

    def c_reduce(self) -> str:
        raise NotImplementedError

    def npieces(self, fam: str) -> int:
        return 1

    def c_tables(self) -> str:
        return ""


class Exact(Kernel):
    """sqrt and 1/sqrt: one or two correctly rounded binary64 operations."""

    families = {}

    def reduce(self, x):
        with np.errstate(all="ignore"):
            y = np.sqrt(x) if self.name == "sqrt" else 1.0 / np.sqrt(x)
        n = len(x)
        z = np.zeros(n)
        return np.ones(n, bool), y, np.zeros(n, int), np.zeros(n, int), z, z, z

    def c_reduce(self):
        return ("    return sqrt(x);\n" if self.name == "sqrt" else "    return 1.0 / sqrt(x);\n")


class Exp(Kernel):
    """2^x and e^x: integer/fraction split (Cody-Waite for e^x)."""

    families = {"E": "horner"}

    def __init__(self, name, fmt, h=0.125):
        super().__init__(name, fmt, h)
        f = fmt
        self.big = math.ldexp(1.0, f.emax + 2)
        self.tiny = math.ldexp(1.0, -(f.precision + 3))  # 0 < |x| < tiny: f(x) = 1 +- less than q
        if name == "exp2":
            self.t_hi, self.t_lo = float(f.emax + 2), float(f.emin - f.precision)
            self.r0 = 0.0
            self.n = int(round(1 / h))
        else:
            self.t_hi = float(np.nextafter((f.emax + 2) * LN2, np.inf))
            self.t_lo = float(np.nextafter((f.emin - f.precision) * LN2, -np.inf))
            self.l1, self.l2 = _split(LN2, 40)
            self.inv = 1 / LN2
            self.r0 = -h
            self.n = int(math.ceil((0.75 + h) / h))

    def npieces(self, fam):
        return self.n

    def reduce(self, x):
        f = self.fmt
        with np.errstate(all="ignore"):
            small = (np.abs(x) < self.tiny) & (x != 0)
            sp = np.isnan(x) | np.isinf(x) | (x >= self.t_hi) | (x < self.t_lo) | small
            ys = np.where(np.isnan(x), x, np.where(x == np.inf, np.inf, np.where(
                x == -np.inf, 0.0, np.where(x >= self.t_hi, self.big, f.q_min))))
            ys = np.where(small, np.where(x > 0, 1.0 + 2.0 ** -40, 1.0 - 2.0 ** -40), ys)
            xx = np.where(sp, 0.0, x)
            if self.name == "exp2":
                k = np.floor(xx)
                r = xx - k
            else:
                k = np.floor(xx * self.inv)
                r = (xx - k * self.l1) - k * self.l2
            j = ((r - self.r0) * (1 / self.h)).astype(np.int64)
            j = np.clip(j, 0, self.n - 1)
            u = r - (self.r0 + j * self.h)
            B = np.ldexp(1.0, k.astype(np.int64))
        return sp, ys, np.zeros(len(x), int), j, u, np.zeros(len(x)), B

    def c_reduce(self):
        f = self.fmt
        s = (f"    if (isnan(x)) return x;\n    if (isinf(x)) return x > 0 ? x : 0.0;\n"
             f"    if (x >= {_hex(self.t_hi)}) return {_hex(self.big)};\n"
             f"    if (x < {_hex(self.t_lo)}) return {_hex(f.q_min)};\n"
             f"    if (x != 0 && fabs(x) < {_hex(self.tiny)}) return x > 0 ? {_hex(1 + 2.0 ** -40)} : "
             f"{_hex(1 - 2.0 ** -40)};\n")
        if self.name == "exp2":
            s += "    double k = floor(x);\n    double r = x - k;\n"
        else:
            s += (f"    double k = floor(x * {_hex(self.inv)});\n"
                  f"    double r = (x - k * {_hex(self.l1)}) - k * {_hex(self.l2)};\n")
        s += (f"    int j = (int)((r - {_hex(self.r0)}) * {_hex(1 / self.h)});\n"
              f"    if (j < 0) j = 0;\n    if (j > {self.n - 1}) j = {self.n - 1};\n"
              f"    u = r - ({_hex(self.r0)} + (double)j * {_hex(self.h)});\n"
              f"    fam = 0; piece = j; A = 0.0; B = ldexp(1.0, (int)k);\n")
        return s


class Log(Kernel):
    """log2 and log: exponent/mantissa split, mantissa in [0.75, 1.5)."""

    families = {"L": "horner"}

    def __init__(self, name, fmt, h=1 / 16):
        super().__init__(name, fmt, h)
        self.r0 = -0.25
        self.n = int(round(0.75 / h))

    def npieces(self, fam):
        return self.n

    def reduce(self, x):
        with np.errstate(all="ignore"):
            sp = np.isnan(x) | (x <= 0) | np.isinf(x)
            ys = np.where(np.isnan(x), x, np.where(x < 0, np.nan, np.where(
                x == 0, -np.inf, np.inf)))
            xx = np.where(sp, 1.0, x)
            m, e = np.frexp(xx)
            m = m * 2.0
            e = (e - 1).astype(np.int64)
            hi = m >= 1.5
            m = np.where(hi, m * 0.5, m)
            e = np.where(hi, e + 1, e)
            r = m - 1.0
            j = np.clip(((r - self.r0) * (1 / self.h)).astype(np.int64), 0, self.n - 1)
            u = r - (self.r0 + j * self.h)
            ed = e.astype(np.float64)
            A = ed if self.name == "log2" else ed * LN2
        return sp, ys, np.zeros(len(x), int), j, u, A, np.ones(len(x))

    def c_reduce(self):
        a = "ed" if self.name == "log2" else f"ed * {_hex(LN2)}"
        return ("    if (isnan(x)) return x;\n    if (x < 0) return NAN;\n"
                "    if (x == 0) return -INFINITY;\n    if (isinf(x)) return x;\n"
                "    int e;\n    double m = frexp(x, &e);\n    m = m * 2.0;\n    e = e - 1;\n"
                "    if (m >= 1.5) { m = m * 0.5; e = e + 1; }\n    double r = m - 1.0;\n"
                f"    int j = (int)((r - {_hex(self.r0)}) * {_hex(1 / self.h)});\n"
                f"    if (j < 0) j = 0;\n    if (j > {self.n - 1}) j = {self.n - 1};\n"
                f"    u = r - ({_hex(self.r0)} + (double)j * {_hex(self.h)});\n"
                f"    double ed = (double)e;\n    fam = 0; piece = j; A = {a}; B = 1.0;\n")


class Trig(Kernel):
    """sin and cos: symmetry and reduction by pi/2 with quadrant selection;
    one polynomial for sin and one for cos on about [-pi/4, pi/4].

    Up to 2**18 (binary16): Cody-Waite with 33-bit parts of pi/2 (exact
    products). Beyond (bfloat16): x = M 2**E with M < 2**p an integer, and
    x 2/pi = M W[E] (mod 4) with W[E] = 2**E 2/pi mod 4 from a table of three
    binary64 parts of 52 - p bits (exact products), as Payne and Hanek."""

    families = {"S": "odd1", "C": "even1"}

    def __init__(self, name, fmt, h=None):
        super().__init__(name, fmt, h)
        p = fmt.precision
        self.tiny = math.ldexp(1.0, -(p // 2 + 3))
        from mpmath import floor as mfloor
        from mpmath import mp, mpf, pi
        self.inv = float(2 / math.pi)
        self.table = fmt.max_finite >= 2.0 ** 18
        with mp.workprec(300 + max(0, fmt.emax)):
            pio2 = pi / 2
            self.pio2 = float(pio2)
            self.p1 = math.ldexp(math.floor(math.ldexp(float(pio2), 33)), -33)
            rest = pio2 - self.p1
            m, e = math.frexp(float(rest))
            self.p2 = math.ldexp(math.floor(m * 2 ** 33), e - 33)
            self.p3 = float(rest - self.p2)
            if self.table:
                wb = 52 - p
                self.e_lo = -(p // 2 + 3) - p  # smallest E of a non-tiny input
                self.e_hi = fmt.emax - p + 1
                rows = []
                for E in range(self.e_lo, self.e_hi + 1):
                    w = mpf(2) ** E * 2 / pi
                    w = w - 4 * mfloor(w / 4)
                    parts = []
                    for _ in range(2):
                        if w == 0:
                            parts.append(0.0)
                            continue
                        m, e = math.frexp(float(w))
                        part = math.ldexp(math.floor(m * 2 ** wb), e - wb)
                        parts.append(part)
                        w = w - part
                    parts.append(float(w))
                    rows.append(parts)
                self.w = np.array(rows)

    def reduce(self, x):
        n = len(x)
        p = self.fmt.precision
        with np.errstate(all="ignore"):
            ax = np.abs(x)
            sp = np.isnan(x) | np.isinf(x) | (ax < self.tiny)
            if self.name == "sin":
                ysm = x - x * 2.0 ** -50
            else:
                ysm = np.full(n, 1.0 - 2.0 ** -40)
            ys = np.where(np.isnan(x), x, np.where(np.isinf(x), np.nan, np.where(
                x == 0, (x if self.name == "sin" else 1.0), ysm)))
            xx = np.where(sp, 1.0, x)
            if self.table:
                m, e = np.frexp(xx)
                M = np.ldexp(m, p)
                idx = np.clip(e - p - self.e_lo, 0, len(self.w) - 1)
                w1, w2, w3 = self.w[idx, 0], self.w[idx, 1], self.w[idx, 2]
                t1 = M * w1
                t2 = M * w2
                t3 = M * w3
                k = np.floor(t1 + 0.5)
                fr = ((t1 - k) + t2) + t3
                r = fr * self.pio2
            else:
                k = np.floor(xx * self.inv + 0.5)
                r = ((xx - k * self.p1) - k * self.p2) - k * self.p3
            q = (k.astype(np.int64)) & 3
            if self.name == "cos":
                q = (q + 1) & 3
            fam = np.where(q & 1 == 0, 0, 1)
            B = np.where(q >= 2, -1.0, 1.0)
        return sp, ys, fam, np.zeros(n, int), r, np.zeros(n), B

    def c_tables(self) -> str:
        if not self.table:
            return ""
        rows = ",\n".join("    {" + ", ".join(float(v).hex() for v in row) + "}" for row in self.w)
        return f"static const double CR_W[{len(self.w)}][3] = {{\n{rows}\n}};\n"

    def c_reduce(self):
        small = "x - x * 0x1p-50" if self.name == "sin" else _hex(1.0 - 2.0 ** -40)
        zero = "x" if self.name == "sin" else "1.0"
        shift = "" if self.name == "sin" else "    q = (q + 1) & 3;\n"
        p = self.fmt.precision
        s = ("    if (isnan(x)) return x;\n    if (isinf(x)) return NAN;\n"
             f"    if (x == 0) return {zero};\n    if (fabs(x) < {_hex(self.tiny)}) return {small};\n")
        if self.table:
            s += ("    int e;\n    double M = ldexp(frexp(x, &e), " + str(p) + ");\n"
                  f"    int i = e - {p} - ({self.e_lo});\n"
                  f"    if (i < 0) i = 0;\n    if (i > {len(self.w) - 1}) i = {len(self.w) - 1};\n"
                  "    double t1 = M * CR_W[i][0];\n    double t2 = M * CR_W[i][1];\n"
                  "    double t3 = M * CR_W[i][2];\n    double k = floor(t1 + 0.5);\n"
                  "    double fr = ((t1 - k) + t2) + t3;\n"
                  f"    double r = fr * {_hex(self.pio2)};\n")
        else:
            s += (f"    double k = floor(x * {_hex(self.inv)} + 0.5);\n"
                  f"    double r = ((x - k * {_hex(self.p1)}) - k * {_hex(self.p2)}) - k * {_hex(self.p3)};\n")
        return s + ("    int q = (int)((long long)k & 3);\n" + shift +
                    "    fam = (q & 1) ? 1 : 0; piece = 0; u = r; A = 0.0; B = q >= 2 ? -1.0 : 1.0;\n")


class Sigmoid(Kernel):
    """tanh and erf: odd symmetry, saturation where f rounds as +-1 does just
    below it, tiny arguments (tanh), uniform pieces on [0, saturation)."""

    def __init__(self, name, fmt, h=0.25, sat=None):
        super().__init__(name, fmt, h)
        self.families = {"T0": "odd1" if name == "tanh" else "oddc", "T": "horner"}
        p = fmt.precision
        self.tiny = math.ldexp(1.0, -(p // 2 + 3)) if name == "tanh" else 0.0
        self.sat = sat
        self.n = int(math.ceil(sat / h))
        self.one = 1.0 - 2.0 ** -40

    def npieces(self, fam):
        return 1 if fam == "T0" else self.n - 1

    def reduce(self, x):
        n = len(x)
        with np.errstate(all="ignore"):
            ax = np.abs(x)
            sp = np.isnan(x) | (ax >= self.sat) | (x == 0) | (ax < self.tiny)
            ys = np.where(np.isnan(x) | (x == 0), x, np.where(
                ax >= self.sat, np.copysign(np.where(np.isinf(x), 1.0, self.one), x),
                x - x * 2.0 ** -50))
            r = np.where(sp, 0.0, ax)
            j = np.clip((r * (1 / self.h)).astype(np.int64), 0, self.n - 1)
            fam = np.where(j == 0, 0, 1)
            u = np.where(j == 0, r, r - j * self.h)
            B = np.copysign(1.0, x)
        return sp, ys, fam, np.maximum(j - 1, 0), u, np.zeros(n), B

    def c_reduce(self):
        s = ("    if (isnan(x) || x == 0) return x;\n    double ax = fabs(x);\n"
             f"    if (isinf(x)) return copysign(1.0, x);\n"
             f"    if (ax >= {_hex(self.sat)}) return copysign({_hex(self.one)}, x);\n")
        if self.tiny:
            s += f"    if (ax < {_hex(self.tiny)}) return x - x * 0x1p-50;\n"
        s += (f"    int j = (int)(ax * {_hex(1 / self.h)});\n    if (j > {self.n - 1}) j = {self.n - 1};\n"
              f"    if (j == 0) {{ fam = 0; piece = 0; u = ax; }}\n"
              f"    else {{ fam = 1; piece = j - 1; u = ax - (double)j * {_hex(self.h)}; }}\n"
              "    A = 0.0; B = copysign(1.0, x);\n")
        return s


#: spelling of EXPR -> function name
NAMES = {"exp": "exp", "exp(x)": "exp", "e^x": "exp", "exp2": "exp2", "exp2(x)": "exp2",
         "2^x": "exp2", "log": "log", "log(x)": "log", "ln": "log", "log2": "log2",
         "log2(x)": "log2", "sin": "sin", "sin(x)": "sin", "cos": "cos", "cos(x)": "cos",
         "tanh": "tanh", "tanh(x)": "tanh", "erf": "erf", "erf(x)": "erf", "sqrt": "sqrt",
         "sqrt(x)": "sqrt", "rsqrt": "rsqrt", "1/sqrt": "rsqrt", "1/sqrt(x)": "rsqrt"}
#: the functions, in the order documented
FUNCTIONS = ("exp", "exp2", "log", "log2", "sin", "cos", "tanh", "erf", "sqrt", "rsqrt")


def make_kernel(name, fmt, level: int, ro=None, values=None) -> Kernel:
    """The kernel of ``name`` at refinement ``level`` (0, 1, 2: pieces halve)."""
    if name in ("sqrt", "rsqrt"):
        return Exact(name, fmt)
    if name in ("exp", "exp2"):
        return Exp(name, fmt, h=0.25 / 2 ** level)
    if name in ("log", "log2"):
        return Log(name, fmt, h=0.125 / 2 ** level)
    if name in ("sin", "cos"):
        return Trig(name, fmt)
    # tanh, erf: saturation from the oracle (every larger input rounds as 1 - q)
    one = 1.0 - 2.0 ** -(fmt.precision + 2)
    pos = (values > 0) & np.isfinite(values)
    bad = pos & (ro != one) & ~np.isnan(ro)  # NaN: outside the proved interval
    bad |= (values < 0) & np.isfinite(values) & (ro != -one) & ~np.isnan(ro)
    sat = float(np.abs(values[bad]).max()) if bad.any() else 0.0
    above = pos & (values > sat)
    sat = float(values[above].min()) if above.any() else 2 * sat
    return Sigmoid(name, fmt, h=0.5 / 2 ** level, sat=sat)
