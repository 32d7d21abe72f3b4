"""What the compiled engine checks once per process against the numpy reference on this
machine, and the shortcuts those checks admit.

Two reductions of the reference are library calls whose summation order is the
library's: ``N @ L`` (BLAS ``gemv``) and ``einsum`` (``N . H``), and ``np.linalg.norm``.
:func:`calibrated` (and :func:`ends_orders` for the column slices of the end normals)
finds which explicit order of :func:`dot3` reproduces each (OpenBLAS's AVX2 kernel fuses
two of the three products); when none does, the fused frame is not used, so the bytes
never depend on the guess.  :func:`pow_calibrated` and :func:`trig_calibrated` admit
the frame's shortcuts for ``b ** n`` and float64 ``sin``/``cos``; :func:`det` is
:mod:`chebnorm.methods.detmath`'s sine, cosine and arc cosine, compiled, the same bits.
"""

from __future__ import annotations

import math
import platform
from functools import lru_cache

import numpy as np

from chebnorm.methods import detmath
from chebnorm.methods.ops import NumpyOps

from .jit import HAVE_NUMBA, f2i, fma, i2f, njit

# an implementation module of chebnorm.raster.engines.numba: the API is what chebnorm.raster.engines.numba exports
__all__: list[str] = []


# ------------------------------------------------------- reduction orders
@njit(inline=True)
def dot3(a0, a1, a2, b0, b1, b2, order):
    """``a . b`` in summation order ``order``: 0 ``(a0b0 + a1b1) + a2b2``,
    1 ``(a0b0 + a2b2) + a1b1``, 2 ``fma(a2, b2, fma(a0, b0, a1b1))``."""
    if order == 0:
        return (a0 * b0 + a1 * b1) + a2 * b2
    if order == 1:
        return (a0 * b0 + a2 * b2) + a1 * b1
    return fma(a2, b2, fma(a0, b0, a1 * b1))


@njit(inline=True)
def dot3_select(a0, a1, a2, b0, b1, b2, order):
    """:func:`dot3` without a branch: every order's sum computed, the one of ``order``
    selected (the same operations, so the same bits), so that a loop over pixels with
    ``order`` a run-time value still vectorizes."""
    p0 = a0 * b0
    p1 = a1 * b1
    p2 = a2 * b2
    one = order == 1
    x = p2 if one else p1
    y = p1 if one else p2
    r01 = (p0 + x) + y
    r2 = fma(a2, b2, fma(a0, b0, p1))
    return r2 if order == 2 else r01


@njit()
def dots(N, H, order):
    """Row-wise ``N[i] . H[i]`` of two (n, 3) arrays, summed in order ``order`` of
    :func:`dot3`."""
    out = np.empty(N.shape[0])
    for i in range(N.shape[0]):
        out[i] = dot3(N[i, 0], N[i, 1], N[i, 2], H[i, 0], H[i, 1], H[i, 2], order)
    return out


_ORDERS = (0, 1, 2)


@lru_cache(maxsize=None)
def calibrated():
    """``(order of N @ L, order of einsum N.H, order of |N|^2)`` on this machine (see
    :func:`dot3`), or None if some reduction matches none of the orders. Probed with
    random vectors of several lengths (>= 2: numpy sends one row elsewhere).

    >>> calibrated() is None or len(calibrated()) == 3
    True
    """
    if not HAVE_NUMBA:
        return None
    rng = np.random.default_rng(20261123)

    def probe(kind, order, n):
        N = rng.standard_normal((n, 3))
        H = rng.standard_normal((n, 3))
        if kind == "matmul":
            ref, got = N @ H[0], dots(N, np.broadcast_to(H[0], N.shape).copy(), order)
        elif kind == "einsum":
            ref, got = np.einsum("...k,...k->...", N, H), dots(N, H, order)
        else:
            ref, got = np.linalg.norm(N, axis=1), np.sqrt(dots(N, N, order))
        return ref.tobytes() == got.tobytes()
    return first_orders(("matmul", "einsum", "norm"), (2, 3, 5, 8, 17, 1000, 4099), probe)


def first_orders(kinds, cases, probe):
    """For each of ``kinds``, the first summation order of :func:`dot3` for which
    ``probe(kind, order, case)`` holds on every one of ``cases`` (tried in order, the
    next order at the first miss); None if some kind has none.

    Parameters
    ----------
    kinds : sequence
        The reductions to calibrate.
    cases : sequence
        The inputs each order must reproduce.
    probe : callable
        ``probe(kind, order, case) -> bool``: the order gives the reference's bits on the case.

    Returns
    -------
    dict or None
        ``{kind: order}``, or None when a kind has no such order.

    Examples
    --------
    >>> first_orders(("a", "b"), (1, 2), lambda kind, order, case: order == len(kind))
    (1, 1)
    """
    found = []
    for kind in kinds:
        ok = next((order for order in _ORDERS
                   if all(probe(kind, order, case) for case in cases)), None)
        if ok is None:
            return None
        found.append(ok)
    return tuple(found)


# ------------------------------------------------------ deterministic trig
@njit()
def _det64(kind, x, out):
    for i in range(x.shape[0]):
        v = x[i]
        out[i] = np.sin(v) if kind == 0 else (np.cos(v) if kind == 1 else np.arccos(v))


@njit(inline=True)
def f32_round(y):
    """``y`` (float64) rounded to float32, and whether that rounding could differ from
    the correctly rounded one (within 2**-16 ulp of a tie, at a power of two, zero,
    subnormal or not finite)."""
    r = np.float32(y)
    a = abs(np.float64(r))
    if not np.isfinite(y) or a < 2.0 ** -126 or not np.isfinite(a):
        return r, True
    m, e = math.frexp(a)
    if m == 0.5:
        return r, True
    ulp = math.ldexp(1.0, e - 24)
    frac = abs(y - np.float64(r)) / ulp
    return r, abs(frac - 0.5) < 2.0 ** -16


@njit()
def _det32(kind, x, out, hard):
    n = 0
    for i in range(x.shape[0]):
        v = np.float64(x[i])
        y = np.sin(v) if kind == 0 else (np.cos(v) if kind == 1 else np.arccos(v))
        r, h = f32_round(y)
        out[i] = r
        hard[i] = h
        n += h
    return n


_KINDS = {"sin": 0, "cos": 1, "arccos": 2}


def det(name: str, x):
    """``detmath.<name>(x)`` (``sin``, ``cos``, ``arccos``), the same bits, compiled:
    float64 by the C library (what :mod:`math` calls), float32 correctly rounded from
    it, the few arguments whose rounding is in doubt handed to :mod:`detmath`.

    Parameters
    ----------
    name : str
        ``"sin"``, ``"cos"`` or ``"arccos"``.
    x : numpy.ndarray
        The arguments (float32 or float64).

    Returns
    -------
    numpy.ndarray
        ``detmath.<name>(x)``, the same bits.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.linspace(-3, 3, 101, dtype=np.float32)
    >>> bool((det("sin", x) == detmath.sin(x)).all())
    True
    """
    arr = np.asarray(x)
    if not HAVE_NUMBA or not isinstance(x, np.ndarray) or arr.dtype not in (np.float32,
                                                                             np.float64):
        return getattr(detmath, name)(x)
    flat = np.ascontiguousarray(arr).ravel()
    out = np.empty_like(flat)
    if arr.dtype == np.float64:
        _det64(_KINDS[name], flat, out)
    else:
        hard = np.empty(flat.shape, np.bool_)
        if _det32(_KINDS[name], flat, out, hard):
            out[hard] = getattr(detmath, name)(flat[hard])
    return out.reshape(arr.shape)


class DetOps(NumpyOps):
    """:class:`NumpyOps` with :func:`det` for the transcendental functions.

    Parameters
    ----------
    dtype : numpy dtype, optional
        float32 or float64.
    """

    def sin(self, x):
        return det("sin", x)

    def cos(self, x):
        return det("cos", x)

    def arccos(self, x):
        return det("arccos", x)


# ------------------------------------------------------------ fast power
#: glibc's ``pow`` (ARM optimized-routines, glibc >= 2.28) is within 0.54 ulp of ``x**y``
#: ("Worst-case error: 0.54 ULP", e_pow.c). Where ``x**n`` (n an integer) is known to
#: within :data:`_POW_MARGIN` ulp of a double ``h``, every other double is more than
#: ``1 - 0.45 = 0.55`` ulp away, so ``pow`` returns ``h``: the reference's bits without
#: the call.  :func:`pow_calibrated` checks the claim against the reference's power
#: (:func:`chebnorm.methods.detmath.power`: the C library's ``pow``, not numpy's power
#: loop, which is SVML on AVX-512 machines) once per process and exponent; elsewhere
#: the frame calls ``pow``.
_POW_MARGIN = 0.45


#: The same comment derives the 0.54: ``ulperr_exp + 1024 Ln2 relerr_log 2**53`` with
#: ``ulperr_exp`` = 0.509 ulp (0.511 without fma) and ``relerr_log`` = 1.3 2**-68 (1.5
#: 2**-68 without fma); ``1024 Ln2`` is the largest ``|y log x|`` of a finite result, and
#: for a smaller ``|y log x|`` the bound is ``0.511 + |y log x| 1.5 2**-15`` ulp. Where
#: ``|n log b| <= `` :data:`_POW_NEAR_LOG` (``b >= exp(-64/n)``) that is below 0.514 ulp,
#: so a double within :data:`_POW_MARGIN_NEAR` = 0.48 ulp of ``b**n`` is what ``pow``
#: returns (every other double is more than 0.52 ulp away): 0.4 times as many calls as
#: with 0.45 (the low part is about uniform in ``[0, 0.5]`` ulp).
_POW_NEAR_LOG = 64.0


_POW_MARGIN_NEAR = 0.48


_POW_TINY = 2.0 ** -900    # double-double products stay normal above this


_POW_HUGE = 2.0 ** 1000


_POW_MAX_N = 1 << 16


@njit(inline=True)
def _dd_mul(h, l, bh, bl):
    """``(h + l) (bh + bl)`` as a normalized double-double (relative error below
    ``2**-102`` when nothing underflows)."""
    p = h * bh
    e = fma(h, bh, -p) + (h * bl + l * bh)
    hi = p + e
    return hi, e - (hi - p)


@njit()
def _pow_int(b, n, hh, ll, ok, out, nw):
    """``out[k] = b[k] ** n`` (``n >= 2`` an integer) with the bits of ``pow`` where
    ``ok[k]``: a double-double power by squaring (left to right), its high part where
    the low part is within :data:`_POW_MARGIN` ulp (:data:`_POW_MARGIN_NEAR` where
    ``b[k] >= exp(-_POW_NEAR_LOG / n)``); ``ok[k]`` False where the caller
    must call ``pow`` (the result near a rounding tie, at a power of two, tiny, huge
    or not finite, or ``b[k]`` NaN; a zero ``b[k]`` is ``pow``'s by C99 F.9.4.4)."""
    for k in range(nw):
        hh[k] = b[k]
        ll[k] = 0.0
    top = 0
    while (n >> (top + 1)) > 0:
        top += 1
    for bit in range(top - 1, -1, -1):
        for k in range(nw):
            hh[k], ll[k] = _dd_mul(hh[k], ll[k], hh[k], ll[k])
        if (n >> bit) & 1:
            for k in range(nw):
                hh[k], ll[k] = _dd_mul(hh[k], ll[k], b[k], 0.0)
    # |n log b| <= _POW_NEAR_LOG for b in [near, 1] (b <= 1 here: b > 1 takes the wide
    # margin); np.exp's rounding moves the cut by an ulp, far inside the bound's slack
    near = np.exp(-_POW_NEAR_LOG / n)
    odd = (n & 1) == 1
    for k in range(nw):
        x = b[k]
        h = hh[k]
        bits = f2i(h)
        ulp = i2f((((bits >> 52) & 0x7FF) - 52) << 52)
        margin = _POW_MARGIN_NEAR if (x >= near) & (x <= 1.0) else _POW_MARGIN
        # a zero base (a clipped N.H, often): C99 F.9.4.4 fixes pow(+-0, n) for an
        # integer n > 0: +-0 (the base) for odd n, +0 for even n; no call needed
        zero = x == 0.0
        ok[k] = zero | ((x >= _POW_TINY) & (h >= _POW_TINY) & (x <= _POW_HUGE)
                        & (h <= _POW_HUGE) & ((bits & 0xFFFFFFFFFFFFF) != 0)
                        & (abs(ll[k]) <= margin * ulp))
        out[k] = (x if odd else 0.0) if zero else h


@njit()
def powers(b, sh, fast, hh, ll, ok, out, nw):
    """``out[k] = b[k] ** sh`` with the reference's bits: numpy squares for ``sh == 2``
    and calls ``pow`` otherwise (``fast``: ``sh`` an integer whose shortcut
    :func:`pow_calibrated` accepted)."""
    if sh == 2.0:
        for k in range(nw):
            out[k] = b[k] * b[k]
        return
    if fast:
        _pow_int(b, np.int64(sh), hh, ll, ok, out, nw)
        for k in range(nw):
            if not ok[k]:
                out[k] = b[k] ** sh
        return
    for k in range(nw):
        out[k] = b[k] ** sh


@lru_cache(maxsize=64)
def pow_calibrated(sh: float) -> bool:
    """Whether the frame may take :func:`_pow_int`'s shortcut for the exponent ``sh``:
    ``sh`` an integer in ``[3, 2**16]``, numba installed, and the shortcut gave the
    reference's bits (:func:`chebnorm.methods.detmath.power`) on 1 + 20 000 probes (random bases in ``(0, 1]`` and numbers
    close to ``1``) on this machine.

    >>> pow_calibrated(32.0) == HAVE_NUMBA
    True
    >>> pow_calibrated(7.5), pow_calibrated(2.0)
    (False, False)
    """
    if not HAVE_NUMBA or not (3 <= sh <= _POW_MAX_N and sh == int(sh)):
        return False
    rng = np.random.default_rng(20261123)
    b = np.concatenate([rng.random(10_000), 1.0 - rng.random(10_000) * 2.0 ** -20, [1.0]])
    n = len(b)
    out, hh, ll = np.empty(n), np.empty(n), np.empty(n)
    ok = np.empty(n, np.bool_)
    powers(b, float(sh), True, hh, ll, ok, out, n)
    return out.tobytes() == detmath.power(b, float(sh)).tobytes() and bool(ok.mean() > 0.5)


# ------------------------------------------------------------- fast sine, cosine
#: glibc's ``sin`` and ``cos`` are within "~0.55 ULP" of the true value (s_sin.c, the IBM
#: Accurate Mathematical Library). :func:`trig64` knows ``sin(x)`` or ``cos(x)`` (``x`` in
#: ``[2**-500, 1.5]``) to about 2**-11 ulp; where the nearest double ``y`` is within
#: ``0.44`` ulp of it, every other double is more than ``0.56`` ulp away, so the library
#: returns ``y``: the reference's bits without the call. Elsewhere (about one argument in
#: eight) the call is made. :func:`trig_calibrated` checks the claim against
#: :func:`math.sin` and :func:`math.cos` once per process.
_TRIG_MARGIN = 0.44


_TRIG_LO = 2.0 ** -500


_TRIG_HI = 1.5


def _trig_table():
    """``sin(k/64)`` and ``cos(k/64)`` (``k = 0 .. 96``) as double-doubles: for ``sin``
    rows 0-3 ``(S, C)`` high and low, for ``cos`` rows 4-7 ``(C, -S)`` (mpmath at 160
    bits, each part rounded once)."""
    import mpmath

    n = int(_TRIG_HI * 64) + 1
    tab = np.empty((8, n))
    with mpmath.workprec(160):
        for k in range(n):
            c = mpmath.mpf(k) / 64
            sn, cs = mpmath.sin(c), mpmath.cos(c)
            for j, v in enumerate((sn, cs, cs, -sn)):
                hi = float(v)
                tab[2 * j, k], tab[2 * j + 1, k] = hi, float(v - mpmath.mpf(hi))
    return tab


_TRIG_TAB = _trig_table()


@njit()
def trig64(kind, x, out, ok, w, n):
    """``out[i] = sin(x[i])`` (``kind`` 0) or ``cos(x[i])`` (1), float64, with the bits
    of the C library's: with ``c = k/64`` nearest ``x`` and ``r = x - c`` (exact,
    ``|r| <= 1/128``), ``P(c) cos r + Q(c) sin r`` (``P, Q = sin, cos`` or ``cos, -sin``
    from a table, Taylor polynomials in ``r``), ``P + Q r`` summed as a double-double;
    the library's call where that value is within :data:`_TRIG_MARGIN` ulp of a rounding
    tie or at a power of two, or ``x`` is outside ``[2**-500, 1.5]``. ``w``: five scratch
    rows (the table look-up is a loop of its own, so the arithmetic vectorizes without
    gathers); ``ok[i]``: whether ``out[i]`` came without the call."""
    tab = _TRIG_TAB
    o = 4 * kind
    w0, w1, w2, w3, w4 = w[0], w[1], w[2], w[3], w[4]
    for i in range(n):
        v = x[i]
        k = np.int64(v * 64.0 + 0.5) if (v >= _TRIG_LO and v <= _TRIG_HI) else 0
        w0[i] = v - k * 0.015625
        w1[i], w2[i], w3[i], w4[i] = tab[o, k], tab[o + 1, k], tab[o + 2, k], tab[o + 3, k]
    for i in range(n):
        v = x[i]
        r, ph, pl, qh, ql = w0[i], w1[i], w2[i], w3[i], w4[i]
        r2 = r * r
        sr = r2 * r * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0
                                                              + r2 * (1.0 / 362880.0))))
        cm = r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 * (1.0 / 40320.0))))
        # P + Q r exactly as s1 + e1, then the small terms P (cos r - 1) + Q (sin r - r)
        p = qh * r
        pe = fma(qh, r, -p)
        s1 = ph + p
        bb = s1 - ph
        e1 = (ph - (s1 - bb)) + (p - bb)
        u = e1 + (pl + pe + ql * r + ph * cm + qh * sr + pl * cm)
        y = s1 + u
        e2 = (s1 - y) + u                        # the value - y, to about 2**-11 ulp
        bits = f2i(y)
        ulp = i2f((((bits >> 52) & 0x7FF) - 52) << 52)
        ok[i] = ((v >= _TRIG_LO) & (v <= _TRIG_HI) & ((bits & 0xFFFFFFFFFFFFF) != 0)
                 & (abs(e2) <= _TRIG_MARGIN * ulp))
        out[i] = y
    for i in range(n):
        if not ok[i]:
            out[i] = np.sin(x[i]) if kind == 0 else np.cos(x[i])


#: :func:`sin_small`'s range: ``sin`` of a double in ``[2**-500, 0.126)``.  There glibc's
#: ``sin`` (s_sin.c, glibc >= 2.28; older ones round correctly, which is stronger) returns
#: ``x`` below ``2**-26`` and otherwise ``do_sin``'s ``TAYLOR_SIN``: ``x + t`` rounded once,
#: ``t = ((s1 + xx (s2 + ...)) x) xx`` (``xx = x*x``, minimax ``s1 .. s5``; fused or not,
#: at most 5 roundings).  So the library returns the double nearest ``x + tau`` with
#: ``|tau - (sin x - x)| <= 8 u x**3/6 + 0.0006 x u`` (``u = 2**-53``; the second term
#: the polynomial's approximation error, 0.00055 x u at most on ``[0, 0.126]``, mpmath).
#: :func:`sin_small` computes ``y + e`` (``y = x + t`` rounded, ``e`` its rounding error,
#: exact by Fast2Sum) with a Taylor ``t`` of the same form, within the same bound
#: (approximation error 0.0013 x u).  As ``ulp(y) >= 0.997 x u`` here, the two values are
#: within ``(2.7 x**2 + 0.002)`` ulp of ``sin x`` each way; where ``|e|`` is at most
#: ``(0.496 - 3 x**2)`` ulp and ``y`` is not a power of two, the library's ``x + tau`` is
#: less than half an ulp from ``y``: it returns ``y``.  (Below ``2**-26``: ``|t| < 0.34``
#: ulp, so ``y = x``, the library's value.)  About one argument in 200 of ``0.02`` fails the
#: test (one in eight with :func:`trig64`'s library-wide 0.44), and :func:`sin_small`'s
#: loop has no table look-up: it vectorizes.  :func:`trig_calibrated` checks it too.
_SIN_SMALL = 0.126


_SIN_MARGIN = 0.496


_SIN_MARGIN_X2 = 3.0


@njit()
def sin_small(x, out, ok, n):
    """``out[i] = sin(x[i])``, float64, with the bits of the C library's (glibc): from
    the Taylor polynomial where the margin test above admits it (``x[i]`` in
    ``[2**-500, 0.126)``), the library's call elsewhere; ``ok[i]``: without the call."""
    for i in range(n):
        v = x[i]
        xx = v * v
        t = ((-1.0 / 6.0 + xx * (1.0 / 120.0 + xx * (-1.0 / 5040.0 + xx * (
            1.0 / 362880.0 + xx * (-1.0 / 39916800.0))))) * v) * xx
        y = v + t
        e = t - (y - v)          # exact (Fast2Sum, |t| < |v|)
        bits = f2i(y)
        ulp = i2f((((bits >> 52) & 0x7FF) - 52) << 52)
        ok[i] = ((v >= _TRIG_LO) & (v < _SIN_SMALL) & ((bits & 0xFFFFFFFFFFFFF) != 0)
                 & (abs(e) <= (_SIN_MARGIN - _SIN_MARGIN_X2 * xx) * ulp))
        out[i] = y
    for i in range(n):
        if not ok[i]:
            out[i] = np.sin(x[i])


@lru_cache(maxsize=1)
def trig_calibrated() -> bool:
    """Whether the frame may take :func:`trig64`'s and :func:`sin_small`'s shortcuts:
    numba installed, the C library glibc (the margins are its bounds), and the shortcuts
    gave :func:`math.sin`'s and :func:`math.cos`'s bits (the float64 reference's) on
    200 000 probes each on this machine (random arguments in ``(0, 1.5]``, small ones,
    table points ``k/64`` a few ulp either side, and arguments the shortcut hands to the
    library), :func:`sin_small` also on 100 000 more below 0.126 (and a few ulp either
    side of 0.126, ``2**-26`` and powers of two).

    >>> trig_calibrated() == HAVE_NUMBA
    True
    """
    if not HAVE_NUMBA or platform.libc_ver()[0] != "glibc":
        return False
    rng = np.random.default_rng(20261123)
    grid = np.arange(97) / 64.0
    near = (grid[:, None] * (1.0 + np.arange(-8, 9) * 2.0 ** -52)).ravel()
    x = np.concatenate([rng.random(150_000) * 1.5, rng.random(48_000) * 2.0 ** -6, near,
                        [0.0, -1e-3, 1.5, 1.6, 3.0, np.inf, np.nan]])
    n = len(x)
    out, ok, w = np.empty(n), np.empty(n, np.bool_), np.empty((5, n))
    for kind, fn in ((0, math.sin), (1, math.cos)):
        trig64(kind, x, out, ok, w, n)
        if not (_same(out, x, fn) and ok.mean() > 0.5):
            return False
    edges = np.array([_SIN_SMALL, 2.0 ** -26] + [2.0 ** -k for k in range(3, 40)])
    xs = np.concatenate([x, rng.random(50_000) * _SIN_SMALL, rng.random(50_000) * 0.02,
                         (edges[:, None] * (1.0 + np.arange(-8, 9) * 2.0 ** -52)).ravel()])
    out, ok = np.empty(len(xs)), np.empty(len(xs), np.bool_)
    sin_small(xs, out, ok, len(xs))
    return _same(out, xs, math.sin) and bool(ok[n:n + 100_000].mean() > 0.9)


def _same(out, x, fn):
    """Whether ``out`` is ``fn`` of ``x`` element by element, bit for bit (NaN where not
    finite)."""
    ref = np.fromiter((fn(v) if math.isfinite(v) else math.nan for v in x.tolist()),
                      np.float64, len(x))
    return bool(((out == ref) | (np.isnan(out) & np.isnan(ref))).all())


@lru_cache(maxsize=None)
def ends_orders():
    """``(order of einsum N_l.N_r, order of |N|)`` (see :func:`dot3`) that reproduce
    ``check_span_input`` and ``auto_tables`` on the end normals as ``render``
    passes them, ``_unit(left[:, [1, 2, 3]])``: a fancy-indexed column slice, laid out
    column-major, whose sums numpy runs in another order than on row-major rows (None:
    no order matches; then the reference runs).

    >>> o = ends_orders()
    >>> o is None or len(o) == 2
    True
    """
    if not HAVE_NUMBA:
        return None
    rng = np.random.default_rng(20261124)

    def probe(kind, order, case):
        n, kc = case
        a = rng.standard_normal((n, kc))[:, [1, 2, 3]]
        b = rng.standard_normal((n, kc))[:, [1, 2, 3]]
        ac, bc = np.ascontiguousarray(a), np.ascontiguousarray(b)
        if kind == "einsum":
            got = dots(ac, bc, order)
            return (np.einsum("ij,ij->i", a, b).tobytes() == got.tobytes()
                    and np.einsum("...k,...k->...", a, b).tobytes() == got.tobytes())
        got = np.sqrt(dots(ac, ac, order))
        return (np.linalg.norm(a, axis=-1, keepdims=True)[:, 0].tobytes() == got.tobytes()
                and np.linalg.norm(a, axis=1).tobytes() == got.tobytes())
    return first_orders(("einsum", "norm"), ((2, 7), (3, 4), (5, 7), (8, 7), (17, 4),
                                                   (1000, 7), (4099, 7), (20000, 4)), probe)
