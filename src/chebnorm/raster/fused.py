"""Fused, parallel Phong frame (numba): visibility per scan line, then deferred shading.

:mod:`.render` (numpy) is the reference and :mod:`.fast` its compiled twin operation by
operation; this module computes the same ``phong`` frame, byte for byte, without
the full-frame intermediate arrays of those two paths (fragment lists, a frame-sized
z-buffer, per-fragment normals, half vectors and dot products):

1. triangle set-up and span set-up, compiled, the spans split over threads (the
   arithmetic of :func:`.spans.setup_spans`);
2. the method's checks and per-span set-up, the values and errors of
   :func:`chebnorm.methods.span_normals`'s, compiled and split over threads in
   :mod:`.fusedsetup` (the reference functions run where a check fails; sine, cosine
   and arc cosine with the bits of :mod:`chebnorm.methods.detmath`, see :func:`det`);
3. one pass per scan line, rows split across the cores (threads running the compiled
   kernels without the GIL, rows interleaved): a z-test of the
   line's spans in span order into a line buffer (the winning span of every pixel,
   ties to the earliest fragment as in :func:`.spans.zbuffer`), then each span's
   pixel normals by the method's kernel (stepping kernels step through every pixel
   of the span, the others are evaluated only where the span won) and, for the
   winners only, half vector, Blinn-Phong intensity, ``|N|`` and the triangle id,
   each output pixel written once.

Every float operation is the reference's, in its order and dtype (no ``fastmath``;
LLVM does not contract a multiply-add without it).  Two reductions of the reference
are library calls whose summation order is the library's: ``N @ L`` (BLAS ``gemv``)
and ``einsum`` (``N . H``).  :func:`calibrated` finds, once per process, which
explicit order reproduces each on this machine (OpenBLAS's AVX2 kernel fuses two of
the three products); when none does, :func:`phong` returns None and the caller
runs :mod:`.fast` instead, so the bytes never depend on the guess.
"""

from __future__ import annotations

import math
import os
import threading
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache
from types import SimpleNamespace

import numpy as np

from chebnorm.methods import detmath
from chebnorm.methods import kernels as K
from chebnorm.methods.ops import NumpyOps
from chebnorm.methods.registry import method_kernel
from chebnorm.methods.spans import MAX_LEVELS

from . import fast

try:  # pragma: no cover - exercised by whichever environment runs the tests
    import numba
    from llvmlite import ir as _ir
    from numba.core import types as _types
    from numba.core.extending import intrinsic as _intrinsic
    HAVE_NUMBA = True
except ImportError:  # pragma: no cover
    numba = None
    HAVE_NUMBA = False

__all__ = ["HAVE_NUMBA", "MODES", "supports", "calibrated", "det", "pow_calibrated",
           "first_orders", "trig_calibrated"]

#: kernel -> mode number of the fused kernel
MODES = {id(K.NONE): 0, id(K.EXACT): 1, id(K.NEWTON): 2, id(K.LYON): 3, id(K.SLERP): 4,
         id(K.QUADRATIC): 5, id(K.ANGULAR): 6, id(K.DICHOTOMY): 7}


def _njit(inline=False):
    """numba's ``njit`` (cached, no fast-math); ``inline``: inlined into its callers in
    numba's IR (per-pixel helpers: no call, no reference counting of the arrays passed
    in the inner loop)."""
    def deco(fn):
        if not HAVE_NUMBA:
            return fn
        return numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy",
                          inline="always" if inline else "never")(fn)
    return deco


if HAVE_NUMBA:
    @_intrinsic
    def _fma(typingctx, a, b, c):
        """``a * b + c`` rounded once (LLVM's ``fma``)."""
        sig = _types.float64(_types.float64, _types.float64, _types.float64)

        def codegen(context, builder, signature, args):
            d = _ir.DoubleType()
            fn = builder.module.declare_intrinsic("llvm.fma", [d], _ir.FunctionType(d, [d, d, d]))
            return builder.call(fn, args)
        return sig, codegen
else:  # pragma: no cover
    def _fma(a, b, c):
        raise RuntimeError("numba is not installed")


# ------------------------------------------------------- reduction orders
@_njit(inline=True)
def _dot3(a0, a1, a2, b0, b1, b2, order):
    """``a . b`` in summation order ``order``: 0 ``(a0b0 + a1b1) + a2b2``,
    1 ``(a0b0 + a2b2) + a1b1``, 2 ``fma(a2, b2, fma(a0, b0, a1b1))``."""
    if order == 0:
        return (a0 * b0 + a1 * b1) + a2 * b2
    if order == 1:
        return (a0 * b0 + a2 * b2) + a1 * b1
    return _fma(a2, b2, _fma(a0, b0, a1 * b1))


@_njit()
def _dots(N, H, order):
    out = np.empty(N.shape[0])
    for i in range(N.shape[0]):
        out[i] = _dot3(N[i, 0], N[i, 1], N[i, 2], H[i, 0], H[i, 1], H[i, 2], order)
    return out


_ORDERS = (0, 1, 2)


@lru_cache(maxsize=None)
def calibrated():
    """``(order of N @ L, order of einsum N.H, order of |N|^2)`` on this machine (see
    :func:`_dot3`), or None if some reduction matches none of the orders. Probed with
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
            ref, got = N @ H[0], _dots(N, np.broadcast_to(H[0], N.shape).copy(), order)
        elif kind == "einsum":
            ref, got = np.einsum("...k,...k->...", N, H), _dots(N, H, order)
        else:
            ref, got = np.linalg.norm(N, axis=1), np.sqrt(_dots(N, N, order))
        return ref.tobytes() == got.tobytes()
    return first_orders(("matmul", "einsum", "norm"), (2, 3, 5, 8, 17, 1000, 4099), probe)


def first_orders(kinds, cases, probe):
    """For each of ``kinds``, the first summation order of :func:`_dot3` for which
    ``probe(kind, order, case)`` holds on every one of ``cases`` (tried in order, the
    next order at the first miss); None if some kind has none.

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
@_njit()
def _det64(kind, x, out):
    for i in range(x.shape[0]):
        v = x[i]
        out[i] = np.sin(v) if kind == 0 else (np.cos(v) if kind == 1 else np.arccos(v))


@_njit(inline=True)
def _f32_round(y):
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


@_njit()
def _det32(kind, x, out, hard):
    n = 0
    for i in range(x.shape[0]):
        v = np.float64(x[i])
        y = np.sin(v) if kind == 0 else (np.cos(v) if kind == 1 else np.arccos(v))
        r, h = _f32_round(y)
        out[i] = r
        hard[i] = h
        n += h
    return n


_KINDS = {"sin": 0, "cos": 1, "arccos": 2}


def det(name: str, x):
    """``detmath.<name>(x)`` (``sin``, ``cos``, ``arccos``), the same bits, compiled:
    float64 by the C library (what :mod:`math` calls), float32 correctly rounded from
    it, the few arguments whose rounding is in doubt handed to :mod:`detmath`.

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


class _DetOps(NumpyOps):
    """:class:`NumpyOps` with :func:`det` for the transcendental functions."""

    def sin(self, x):
        return det("sin", x)

    def cos(self, x):
        return det("cos", x)

    def arccos(self, x):
        return det("arccos", x)


# --------------------------------------------------------- triangle set-up
@_njit()
def _gather_setup(pos, nrm, xy, inv_w, faces, cull):
    """``_setup`` of :mod:`.render`: front-facing triangles and their corners."""
    F = faces.shape[0]
    keep = np.empty(F, np.bool_)
    for i in range(F):
        a, b, c = faces[i, 0], faces[i, 1], faces[i, 2]
        area = ((xy[b, 0] - xy[a, 0]) * (xy[c, 1] - xy[a, 1])
                - (xy[c, 0] - xy[a, 0]) * (xy[b, 1] - xy[a, 1]))
        keep[i] = area < 0 if cull else area != 0
    n = 0
    for i in range(F):
        n += keep[i]
    tri = np.empty(n, np.int64)
    n = 0
    for i in range(F):
        if keep[i]:
            tri[n] = i
            n += 1
    txy = np.empty((n, 3, 2))
    attrs = np.empty((n, 3, 7))
    tiw = np.empty((n, 3))
    tpos = np.empty((n, 3, 3))
    tnrm = np.empty((n, 3, 3))
    for k in range(n):
        i = tri[k]
        for v in range(3):
            q = faces[i, v]
            txy[k, v, 0] = xy[q, 0]
            txy[k, v, 1] = xy[q, 1]
            attrs[k, v, 0] = inv_w[q]
            tiw[k, v] = inv_w[q]
            for c in range(3):
                attrs[k, v, 1 + c] = nrm[q, c]
                attrs[k, v, 4 + c] = pos[q, c]
                tnrm[k, v, c] = nrm[q, c]
                tpos[k, v, c] = pos[q, c]
    return tri, txy, attrs, tiw, tpos, tnrm


# ------------------------------------------------------------- span set-up
@_njit(inline=True)
def _span_geom(xy, i, r, width):
    """Row ``r`` of triangle ``i`` as :func:`.spans.setup_spans` finds it: ``(c, a, pa,
    qa, sa, p, q, sb, swap, xl, xr)``, ``c`` the pixel count (0: no span), ``a`` the first
    pixel, ``sa``, ``sb`` the positions along edges ``pa -> qa`` and ``p -> q``."""
    y0, y1, y2 = xy[i, 0, 1], xy[i, 1, 1], xy[i, 2, 1]
    y = r + 0.5
    # edges (0,1), (1,2), (2,0): hit when min <= y < max; the first and last hit
    h0 = min(y0, y1) <= y and y < max(y0, y1)
    h1 = min(y1, y2) <= y and y < max(y1, y2)
    h2 = min(y2, y0) <= y and y < max(y2, y0)
    if np.int64(h0) + np.int64(h1) + np.int64(h2) != 2:
        return 0, 0, 0, 0, 0.0, 0, 0, 0.0, False, 0.0, 0.0
    e1 = 0 if h0 else 1
    e2 = 2 if h2 else 1
    pa = e1
    qa = (e1 + 1) % 3
    sa = (y - xy[i, pa, 1]) / (xy[i, qa, 1] - xy[i, pa, 1])
    xa = xy[i, pa, 0] + sa * (xy[i, qa, 0] - xy[i, pa, 0])
    p = e2
    q = (e2 + 1) % 3
    sb = (y - xy[i, p, 1]) / (xy[i, q, 1] - xy[i, p, 1])
    xb = xy[i, p, 0] + sb * (xy[i, q, 0] - xy[i, p, 0])
    swap = xb < xa
    xl = xb if swap else xa
    xr = xa if swap else xb
    a = np.int64(min(max(np.ceil(xl - 0.5), 0.0), float(width)))
    b = np.int64(min(max(np.ceil(xr - 0.5), 0.0), float(width)))
    return max(b - a, 0), a, pa, qa, sa, p, q, sb, swap, xl, xr


@_njit(inline=True)
def _span_write(attrs, i, r, n, c, a, pa, qa, sa, p, q, sb, swap, xl, xr, tri, row, c0, count,
                m, t0, dt, left, right):
    """Span ``n``: row ``r`` of triangle ``i`` (from :func:`_span_geom`)."""
    tri[n] = i
    row[n] = r
    c0[n] = a
    count[n] = c
    for k in range(attrs.shape[2]):
        va = attrs[i, pa, k] + sa * (attrs[i, qa, k] - attrs[i, pa, k])
        vb = attrs[i, p, k] + sb * (attrs[i, q, k] - attrs[i, p, k])
        left[n, k] = vb if swap else va
        right[n, k] = va if swap else vb
    ws = xr - xl
    d = 1.0 / ws
    dt[n] = d
    t0[n] = ((a + 0.5) - xl) * d
    m[n] = np.int64(max(1.0, np.ceil(ws)))


@_njit(inline=True)
def _span_at(xy, attrs, width, i, r, n, write, tri, row, c0, count, m, t0, dt, left, right):
    """Row ``r`` of triangle ``i``: 1 if it is a span (written as span ``n`` when
    ``write``), else 0."""
    c, a, pa, qa, sa, p, q, sb, swap, xl, xr = _span_geom(xy, i, r, width)
    if c <= 0:
        return 0
    if write:
        _span_write(attrs, i, r, n, c, a, pa, qa, sa, p, q, sb, swap, xl, xr, tri, row, c0,
                    count, m, t0, dt, left, right)
    return 1


@_njit()
def _spans_part(xy, attrs, width, r0, nrows, lo, hi, write, nvalid, start, tri, row, c0, count,
                m, t0, dt, left, right):
    """The spans of :func:`.spans.setup_spans` of triangles ``lo .. hi-1``: with ``write``
    False, how many each triangle keeps (into ``nvalid``); with ``write`` True, the spans
    themselves, triangle ``i``'s from index ``start[i]`` on."""
    for i in range(lo, hi):
        n = start[i] if write else 0
        for r in range(r0[i], r0[i] + nrows[i]):
            n += _span_at(xy, attrs, width, i, r, n, write, tri, row, c0, count, m, t0, dt,
                          left, right)
        if not write:
            nvalid[i] = n


@_njit()
def _row_buckets(r0, nrows, height):
    """The triangles crossing each row, in triangle order: row ``r``'s are
    ``ids[first[r]:first[r+1]]``."""
    first = np.zeros(height + 1, np.int64)
    for i in range(r0.shape[0]):
        for r in range(r0[i], r0[i] + nrows[i]):
            first[r + 1] += 1
    for r in range(height):
        first[r + 1] += first[r]
    fill = first[:-1].copy()
    ids = np.empty(first[height], np.int64)
    for i in range(r0.shape[0]):
        for r in range(r0[i], r0[i] + nrows[i]):
            ids[fill[r]] = i
            fill[r] += 1
    return first, ids


@_njit()
def _row_spans_part(xy, attrs, width, first, ids, rlo, rhi, write, row_start, tri, row, c0,
                    count, m, t0, dt, left, right):
    """:func:`_spans_part` row by row, rows ``rlo .. rhi-1`` (the triangles of each row
    from :func:`_row_buckets`): with ``write`` False, each row's number of spans into
    ``row_start[r + 1]``; with ``write`` True, the spans from ``row_start[r]`` on."""
    for r in range(rlo, rhi):
        n = row_start[r] if write else 0
        for q in range(first[r], first[r + 1]):
            n += _span_at(xy, attrs, width, ids[q], r, n, write, tri, row, c0, count, m, t0,
                          dt, left, right)
        if not write:
            row_start[r + 1] = n


@_njit()
def _by_row(row, height):
    """The spans of each row, in span order: row ``r``'s are
    ``by_row[row_start[r]:row_start[r+1]]``."""
    n = row.shape[0]
    row_start = np.zeros(height + 1, np.int64)
    for s in range(n):
        row_start[row[s] + 1] += 1
    for r in range(height):
        row_start[r + 1] += row_start[r]
    fill = row_start[:-1].copy()
    by_row = np.empty(n, np.int64)
    for s in range(n):
        r = row[s]
        by_row[fill[r]] = s
        fill[r] += 1
    return row_start, by_row


# ------------------------------------------------------------ dichotomy prep
@_njit()
def _dichotomy_prep(nl, nr, levels, coeffs, exact, kc, t0, dt, count):
    """Per-span denominators of every level and, per depth, whether any pixel of any
    span is off the dyadic grid (then every pixel of that depth is picked), as
    :func:`.fast._dichotomy_kernel` computes them."""
    S = levels.shape[0]
    r, Lmax = fast._dichotomy_denominators(nl, nr, levels, coeffs, exact, kc)
    off = np.zeros(Lmax + 1, np.bool_)
    tcb = np.empty(1, nl.dtype)
    for i in range(S):
        L = levels[i]
        if off[L]:
            continue
        scale = kc[2 + L]
        for j in range(count[i]):
            tcb[0] = t0[i] + j * dt[i]
            u = tcb[0] * scale
            if u - np.floor(u) != 0:
                off[L] = True
                break
    return r, off


# ---------------------------------------------------------------- shading
@_njit(inline=True)
def _half(p0, p1, p2, e0, e1, e2, l0, l1, l2, order):
    """``_unit(L + _unit(eye - P))`` (:func:`.render._half_vectors`; ``|v|`` as
    ``np.linalg.norm`` sums, ``order``)."""
    v0, v1, v2 = e0 - p0, e1 - p1, e2 - p2
    r = np.sqrt(_dot3(v0, v1, v2, v0, v1, v2, order))
    v0, v1, v2 = v0 / r, v1 / r, v2 / r
    h0, h1, h2 = l0 + v0, l1 + v1, l2 + v2
    r = np.sqrt(_dot3(h0, h1, h2, h0, h1, h2, order))
    return h0 / r, h1 / r, h2 / r


@_njit(inline=True)
def _intensity(N0, N1, N2, h0, h1, h2, l0, l1, l2, order_l, order_h, I0, ka, kd, ks, sh):
    """``Lighting.intensity(N @ L, _dot(N, H))`` clipped to [0, 1] (``N @ L`` and the
    einsum summed in their calibrated orders)."""
    a = _dot3(N0, N1, N2, l0, l1, l2, order_l)
    b = _dot3(N0, N1, N2, h0, h1, h2, order_h)
    a = a if (a >= 0.0 or a != a) else 0.0      # np.maximum(a, 0.0)
    b = b if (b >= 0.0 or b != b) else 0.0
    # numpy squares for the exponent 2 (its fast scalar power), calls pow otherwise
    v = I0 * (ka + kd * a + ks * (b * b if sh == 2.0 else b ** sh))
    if v < 0.0:
        v = 0.0
    elif v > 1.0:
        v = 1.0
    return v


@_njit()
def _row_visibility(rr, width, row_start, by_row, c0, count, t0, dt, left, right, bw, bs):
    """Row ``rr``: in ``bs`` the winning span of each pixel (largest ``1/w``, ties to the
    earliest span; -1: none)."""
    for x in range(width):
        bs[x] = -1
    for k in range(row_start[rr], row_start[rr + 1]):
        s = by_row[k]
        lo = left[s, 0]
        dw = right[s, 0] - lo
        for j in range(count[s]):
            t = min(max(t0[s] + j * dt[s], 0.0), 1.0)
            w = lo + t * dw
            x = c0[s] + j
            if bs[x] < 0 or w > bw[x]:
                bs[x] = s
                bw[x] = w


@_njit(inline=True)
def _linear(mode, a0, a1, a2, d0, d1, d2, t, k0, k1, k2, k3, k4):
    """``N_l + t (N_r - N_l)`` normalized by mode 1 (``N/sqrt(N.N)``), 2 (Newton) or 3
    (Lyon), or not (0), as :func:`.fast._linear_kernel` (constants ``k`` in the dtype)."""
    n0 = a0 + t * d0
    n1 = a1 + t * d1
    n2 = a2 + t * d2
    if mode == 0:
        return n0, n1, n2
    if mode == 1:
        r = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        return n0 / r, n1 / r, n2 / r
    x = n0 * n0 + n1 * n1 + n2 * n2
    q = (k0 - x) * k1 if mode == 2 else (x * k2 - k3) * x + k4
    return n0 * q, n1 * q, n2 * q


@_njit(inline=True)
def _step(mode, j, v0, v1, v2, e0, e1, e2, f0, f1, f2, k2):
    """One step (``j >= 1``) of the stepping kernels: quadratic (mode 5, value ``v``,
    first and second differences ``e``, ``f``) or angular (mode 6, current ``v`` and
    previous ``e`` pixel, factor ``k2 = 2 cos(phi)``; at ``j = 1`` the second pixel is
    the given one)."""
    if mode == 5:
        return v0 + e0, v1 + e1, v2 + e2, e0 + f0, e1 + f1, e2 + f2
    if j == 1:
        return e0, e1, e2, v0, v1, v2
    return v0 * k2 - e0, v1 * k2 - e1, v2 * k2 - e2, v0, v1, v2


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
_POW_TINY = 2.0 ** -900    # double-double products stay normal above this
_POW_HUGE = 2.0 ** 1000
_POW_MAX_N = 1 << 16

if HAVE_NUMBA:
    @_intrinsic
    def _f2i(typingctx, x):
        """The bits of a float64 as an int64."""
        sig = _types.int64(_types.float64)

        def codegen(context, builder, signature, args):
            return builder.bitcast(args[0], _ir.IntType(64))
        return sig, codegen

    @_intrinsic
    def _i2f(typingctx, i):
        """The float64 whose bits are the int64 ``i``."""
        sig = _types.float64(_types.int64)

        def codegen(context, builder, signature, args):
            return builder.bitcast(args[0], _ir.DoubleType())
        return sig, codegen
else:  # pragma: no cover
    def _f2i(x):
        raise RuntimeError("numba is not installed")

    def _i2f(i):
        raise RuntimeError("numba is not installed")


@_njit(inline=True)
def _dd_mul(h, l, bh, bl):
    """``(h + l) (bh + bl)`` as a normalized double-double (relative error below
    ``2**-102`` when nothing underflows)."""
    p = h * bh
    e = _fma(h, bh, -p) + (h * bl + l * bh)
    hi = p + e
    return hi, e - (hi - p)


@_njit()
def _pow_int(b, n, hh, ll, ok, out, nw):
    """``out[k] = b[k] ** n`` (``n >= 2`` an integer) with the bits of ``pow`` where
    ``ok[k]``: a double-double power by squaring (left to right), its high part where
    the low part is within :data:`_POW_MARGIN` ulp; ``ok[k]`` False where the caller
    must call ``pow`` (the result near a rounding tie, at a power of two, tiny, huge
    or not finite, or ``b[k]`` NaN)."""
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
    for k in range(nw):
        x = b[k]
        h = hh[k]
        bits = _f2i(h)
        ulp = _i2f((((bits >> 52) & 0x7FF) - 52) << 52)
        ok[k] = ((x >= _POW_TINY) & (h >= _POW_TINY) & (x <= _POW_HUGE) & (h <= _POW_HUGE)
                 & ((bits & 0xFFFFFFFFFFFFF) != 0) & (abs(ll[k]) <= _POW_MARGIN * ulp))
        out[k] = h


@_njit()
def _powers(b, sh, fast, hh, ll, ok, out, nw):
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
    _powers(b, float(sh), True, hh, ll, ok, out, n)
    return out.tobytes() == detmath.power(b, float(sh)).tobytes() and bool(ok.mean() > 0.5)


# ------------------------------------------------------------- fast sine, cosine
#: glibc's ``sin`` and ``cos`` are within "~0.55 ULP" of the true value (s_sin.c, the IBM
#: Accurate Mathematical Library). :func:`_trig64` knows ``sin(x)`` or ``cos(x)`` (``x`` in
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


@_njit()
def _trig64(kind, x, out, ok, w, n):
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
        pe = _fma(qh, r, -p)
        s1 = ph + p
        bb = s1 - ph
        e1 = (ph - (s1 - bb)) + (p - bb)
        u = e1 + (pl + pe + ql * r + ph * cm + qh * sr + pl * cm)
        y = s1 + u
        e2 = (s1 - y) + u                        # the value - y, to about 2**-11 ulp
        bits = _f2i(y)
        ulp = _i2f((((bits >> 52) & 0x7FF) - 52) << 52)
        ok[i] = ((v >= _TRIG_LO) & (v <= _TRIG_HI) & ((bits & 0xFFFFFFFFFFFFF) != 0)
                 & (abs(e2) <= _TRIG_MARGIN * ulp))
        out[i] = y
    for i in range(n):
        if not ok[i]:
            out[i] = np.sin(x[i]) if kind == 0 else np.cos(x[i])


@lru_cache(maxsize=1)
def trig_calibrated() -> bool:
    """Whether the frame may take :func:`_trig64`'s shortcut: numba installed and the
    shortcut gave :func:`math.sin`'s and :func:`math.cos`'s bits (the float64
    reference's) on 200 000 probes each on this machine (random arguments in ``(0,
    1.5]``, small ones, table points ``k/64`` a few ulp either side, and arguments the
    shortcut hands to the library).

    >>> trig_calibrated() == HAVE_NUMBA
    True
    """
    if not HAVE_NUMBA:
        return False
    rng = np.random.default_rng(20261123)
    grid = np.arange(97) / 64.0
    near = (grid[:, None] * (1.0 + np.arange(-8, 9) * 2.0 ** -52)).ravel()
    x = np.concatenate([rng.random(150_000) * 1.5, rng.random(48_000) * 2.0 ** -6, near,
                        [0.0, -1e-3, 1.5, 1.6, 3.0, np.inf, np.nan]])
    n = len(x)
    out, ok, w = np.empty(n), np.empty(n, np.bool_), np.empty((5, n))
    for kind, fn in ((0, math.sin), (1, math.cos)):
        _trig64(kind, x, out, ok, w, n)
        ref = np.fromiter((fn(v) if math.isfinite(v) else math.nan for v in x.tolist()),
                          np.float64, n)
        if not (((out == ref) | (np.isnan(out) & np.isnan(ref))).all() and ok.mean() > 0.5):
            return False
    return True


# ---------------------------------------------------------------- shading rows
@_njit(inline=True)
def _clamp0(a):
    """``np.maximum(a, 0.0)`` (NaN kept)."""
    return a if (a >= 0.0 or a != a) else 0.0


@_njit()
def _dots_row(x0, x1, x2, y0, y1, y2, out, nw, order):
    """``out[k] = x[k] . y[k]`` in summation order ``order`` (one loop per order, so
    each vectorizes)."""
    if order == 0:
        for k in range(nw):
            out[k] = _dot3(x0[k], x1[k], x2[k], y0[k], y1[k], y2[k], 0)
    elif order == 1:
        for k in range(nw):
            out[k] = _dot3(x0[k], x1[k], x2[k], y0[k], y1[k], y2[k], 1)
    else:
        for k in range(nw):
            out[k] = _dot3(x0[k], x1[k], x2[k], y0[k], y1[k], y2[k], 2)


@_njit()
def _dotc_row(x0, x1, x2, c0, c1, c2, out, nw, order):
    """``out[k] = x[k] . c`` (``c`` one vector), in summation order ``order``."""
    if order == 0:
        for k in range(nw):
            out[k] = _dot3(x0[k], x1[k], x2[k], c0, c1, c2, 0)
    elif order == 1:
        for k in range(nw):
            out[k] = _dot3(x0[k], x1[k], x2[k], c0, c1, c2, 1)
    else:
        for k in range(nw):
            out[k] = _dot3(x0[k], x1[k], x2[k], c0, c1, c2, 2)


@_njit()
def _half_row(h0, h1, h2, e0, e1, e2, l0, l1, l2, nw, order):
    """``h[k] = _half(P[k])`` in place (``h`` holds the positions ``P`` on entry)."""
    if order == 0:
        for k in range(nw):
            h0[k], h1[k], h2[k] = _half(h0[k], h1[k], h2[k], e0, e1, e2, l0, l1, l2, 0)
    elif order == 1:
        for k in range(nw):
            h0[k], h1[k], h2[k] = _half(h0[k], h1[k], h2[k], e0, e1, e2, l0, l1, l2, 1)
    else:
        for k in range(nw):
            h0[k], h1[k], h2[k] = _half(h0[k], h1[k], h2[k], e0, e1, e2, l0, l1, l2, 2)


@_njit()
def _linear_row(mode, n0, n1, n2, a0, a1, a2, d0, d1, d2, tc, kc, out0, out1, out2, nw):
    """Modes 1 (``N/sqrt(N.N)``), 2 (Newton), 3 (Lyon) of :func:`_linear` on the row's
    winners (gathered ends ``a``, differences ``d`` and ``t`` in the dtype), results
    widened to float64 (one loop per mode, so each vectorizes)."""
    if mode == 1:
        for k in range(nw):
            m0, m1, m2 = _linear(1, a0[k], a1[k], a2[k], d0[k], d1[k], d2[k], tc[k], kc[0],
                                 kc[1], kc[2], kc[3], kc[4])
            out0[k], out1[k], out2[k] = np.float64(m0), np.float64(m1), np.float64(m2)
    elif mode == 2:
        for k in range(nw):
            m0, m1, m2 = _linear(2, a0[k], a1[k], a2[k], d0[k], d1[k], d2[k], tc[k], kc[0],
                                 kc[1], kc[2], kc[3], kc[4])
            out0[k], out1[k], out2[k] = np.float64(m0), np.float64(m1), np.float64(m2)
    else:
        for k in range(nw):
            m0, m1, m2 = _linear(3, a0[k], a1[k], a2[k], d0[k], d1[k], d2[k], tc[k], kc[0],
                                 kc[1], kc[2], kc[3], kc[4])
            out0[k], out1[k], out2[k] = np.float64(m0), np.float64(m1), np.float64(m2)


@_njit()
def _frame(width, height, mode, row_start, by_row, stri, c0, count, t0, dt, left, right,
           A, B, C, sc, sc2, levels, R, off, kc, kd, is64, face_id, per_pixel_h, Htri, L, eye,
           light, orders, part, parts, img, mask, tri_map, nlen):
    """The visibility and shading passes, one scan line at a time, on the rows
    ``part, part + parts, ...`` (threads run the parts at once: each writes every pixel
    of its own rows of the four output maps, the background where no fragment lands:
    0, False, -1, NaN). Returns the number of slerp float32 pixels whose
    sine needs :mod:`detmath` (marked ``-2 - span`` in the triangle map).

    Per row: the z-test (:func:`_row_visibility`), the winners listed in ``x`` order,
    then each quantity of the shading for all of them in one loop (gathers first, then
    loops of arithmetic alone, which LLVM vectorizes: ``sqrt`` and division are
    correctly rounded in every lane, so the bits are the scalar ones)."""
    hard = 0
    l0, l1, l2 = L[0], L[1], L[2]
    ey0, ey1, ey2 = eye[0], eye[1], eye[2]
    o2 = orders[2]
    W = width
    bw = np.empty(W)
    bs = np.empty(W, np.int64)
    wx = np.empty(W, np.int64)
    ws = np.empty(W, np.int64)
    wt = np.empty(W)
    tc = np.empty(W, A.dtype)
    ga = np.empty((6, W), A.dtype)
    sx = np.empty((3, W), A.dtype)
    n0, n1, n2 = np.empty(W), np.empty(W), np.empty(W)
    h0, h1, h2 = np.empty(W), np.empty(W), np.empty(W)
    av, bv, nl, pw = np.empty(W), np.empty(W), np.empty(W), np.empty(W)
    hh, ll = np.empty(W), np.empty(W)
    ok = np.empty(W, np.bool_)
    skip = np.zeros(W, np.bool_)
    nd = np.empty((3, _TREE_MAX + 1), A.dtype)
    sab = np.empty(2, A.dtype)
    sw = np.empty((9, W) if mode == 4 else (9, 1))
    for rr in range(part, height, parts):
        base = rr * W
        _row_visibility(rr, W, row_start, by_row, c0, count, t0, dt, left, right, bw, bs)
        nw = 0
        for x in range(W):
            # the background (overwritten where a fragment lands), the winners listed
            img[base + x] = 0.0
            mask[base + x] = False
            tri_map[base + x] = -1
            nlen[base + x] = np.nan
            if bs[x] >= 0:
                wx[nw] = x
                ws[nw] = bs[x]
                nw += 1
        if nw == 0:
            continue
        for k in range(nw):
            s = ws[k]
            tu = t0[s] + (wx[k] - c0[s]) * dt[s]
            tc[k] = tu                       # the reference's t.astype(dtype)
            wt[k] = min(max(tu, 0.0), 1.0)
        # the method's normals, widened to float64
        if mode == 0:
            for k in range(nw):
                s = ws[k]
                t = wt[k]
                lo1, lo2, lo3 = left[s, 1], left[s, 2], left[s, 3]
                n0[k] = lo1 + t * (right[s, 1] - lo1)
                n1[k] = lo2 + t * (right[s, 2] - lo2)
                n2[k] = lo3 + t * (right[s, 3] - lo3)
        elif mode <= 3:
            for k in range(nw):
                s = ws[k]
                for c in range(3):
                    ga[c, k] = A[c, s]
                    ga[3 + c, k] = B[c, s]
            _linear_row(mode, n0, n1, n2, ga[0], ga[1], ga[2], ga[3], ga[4], ga[5], tc, kc, n0,
                        n1, n2, nw)
        elif mode == 5 or mode == 6:
            _step_row(mode, rr, row_start, by_row, c0, count, A, B, C, sc, bs, sx, wx, n0, n1,
                      n2, nw)
        elif mode == 4:
            hard += _slerp_row(ws, tc, A, B, sc, sc2, kc, is64, light[6] != 0.0, sw, ok,
                               sab, skip, n0, n1, n2, nw)
        else:
            _dichotomy_row(ws, tc, count, A, B, R, levels, off, kd, nd, n0, n1, n2, nw)
        # half vectors
        if per_pixel_h:
            for k in range(nw):
                s = ws[k]
                t = wt[k]
                q0, q1, q2 = left[s, 4], left[s, 5], left[s, 6]
                h0[k] = q0 + t * (right[s, 4] - q0)
                h1[k] = q1 + t * (right[s, 5] - q1)
                h2[k] = q2 + t * (right[s, 6] - q2)
            _half_row(h0, h1, h2, ey0, ey1, ey2, l0, l1, l2, nw, o2)
        else:
            _tri_half_row(ws, stri, Htri, h0, h1, h2, nw)
        _light_row(base, n0, n1, n2, h0, h1, h2, L, light, orders, wx, ws, stri, face_id, av,
                   bv, nl, pw, hh, ll, ok, skip, img, mask, tri_map, nlen, nw)
    return hard


@_njit()
def _tri_half_row(ws, stri, Htri, h0, h1, h2, nw):
    """The per-triangle ``H`` of each winner's span, looked up once per run of a span's
    winners (they are adjacent)."""
    last = -1
    g0 = g1 = g2 = 0.0
    for k in range(nw):
        if ws[k] != last:
            last = ws[k]
            ft = stri[last]
            g0, g1, g2 = Htri[ft, 0], Htri[ft, 1], Htri[ft, 2]
        h0[k], h1[k], h2[k] = g0, g1, g2


@_njit()
def _light_row(base, n0, n1, n2, h0, h1, h2, L, light, orders, wx, ws, stri, face_id, av, bv, nl,
               pw, hh, ll, ok, skip, img, mask, tri_map, nlen, nw):
    """``Lighting.intensity(N @ L, N . H)`` clipped, and ``|N|``, at the row's winners, into
    the four maps (row offset ``base``)."""
    l0, l1, l2 = L[0], L[1], L[2]
    I0, ka, kdif, ks, sh = light[0], light[1], light[2], light[3], light[4]
    fastpow = light[5] != 0.0
    o0, o1, o2 = orders[0], orders[1], orders[2]
    _dotc_row(n0, n1, n2, l0, l1, l2, av, nw, o0)
    _dots_row(n0, n1, n2, h0, h1, h2, bv, nw, o1)
    _dots_row(n0, n1, n2, n0, n1, n2, nl, nw, o2)
    for k in range(nw):
        av[k] = _clamp0(av[k])
        bv[k] = _clamp0(bv[k])
        nl[k] = np.sqrt(nl[k])
    _powers(bv, sh, fastpow, hh, ll, ok, pw, nw)
    for k in range(nw):
        v = I0 * (ka + kdif * av[k] + ks * pw[k])
        av[k] = 0.0 if v < 0.0 else (1.0 if v > 1.0 else v)
    for k in range(nw):
        p = base + wx[k]
        if skip[k]:
            skip[k] = False
            tri_map[p] = -2 - ws[k]
            continue
        img[p] = av[k]
        mask[p] = True
        tri_map[p] = face_id[stri[ws[k]]]
        nlen[p] = nl[k]


@_njit()
def _step_row(mode, rr, row_start, by_row, c0, count, A, B, C, sc, bs, sx, wx, n0, n1, n2, nw):
    """Stepping kernels (5 quadratic, 6 angular) on row ``rr``: every pixel of each span
    in order, the winners' normals (in ``x`` order) widened to float64."""
    for q in range(row_start[rr], row_start[rr + 1]):
        s = by_row[q]
        x0 = c0[s]
        v0, v1, v2 = A[0, s], A[1, s], A[2, s]
        e0, e1, e2 = B[0, s], B[1, s], B[2, s]
        f0, f1, f2 = C[0, s], C[1, s], C[2, s]
        for j in range(count[s]):
            if j > 0:
                v0, v1, v2, e0, e1, e2 = _step(mode, j, v0, v1, v2, e0, e1, e2, f0, f1,
                                               f2, sc[s])
            if bs[x0 + j] == s:
                sx[0, x0 + j] = v0
                sx[1, x0 + j] = v1
                sx[2, x0 + j] = v2
    for k in range(nw):
        x = wx[k]
        n0[k] = np.float64(sx[0, x])
        n1[k] = np.float64(sx[1, x])
        n2[k] = np.float64(sx[2, x])


@_njit()
def _slerp_row(ws, tc, A, B, sc, sc2, kc, is64, fastsin, sw, ok, sab, skip, n0, n1, n2, nw):
    """Slerp (mode 4) at the row's winners; the number of float32 pixels whose sine is in
    doubt (``skip``: for :mod:`detmath`, see :func:`phong`). ``fastsin``: float64 sines
    by :func:`_trig64` (rows 0-3 of ``sw`` the arguments and sines, 4-8 its scratch)."""
    if is64 and fastsin:
        for k in range(nw):
            s = ws[k]
            sw[0, k] = (kc[5] - tc[k]) * sc[s]
            sw[1, k] = tc[k] * sc[s]
        _trig64(0, sw[0], sw[2], ok, sw[4:], nw)
        _trig64(0, sw[1], sw[3], ok, sw[4:], nw)
        for k in range(nw):
            s = ws[k]
            wa = sw[2, k] * sc2[s]
            wb = sw[3, k] * sc2[s]
            n0[k] = np.float64(A[0, s] * wa + B[0, s] * wb)
            n1[k] = np.float64(A[1, s] * wa + B[1, s] * wb)
            n2[k] = np.float64(A[2, s] * wa + B[2, s] * wb)
        return 0
    hard = 0
    for k in range(nw):
        s = ws[k]
        t_ = tc[k]
        arg_a = (kc[5] - t_) * sc[s]
        arg_b = t_ * sc[s]
        if is64:
            sab[0] = np.sin(arg_a)
            sab[1] = np.sin(arg_b)
        else:
            ra, ha = _f32_round(np.sin(np.float64(arg_a)))
            rb, hb = _f32_round(np.sin(np.float64(arg_b)))
            if ha or hb:     # a float32 sine for detmath (see phong)
                skip[k] = True
                hard += 1
                n0[k] = n1[k] = n2[k] = 0.0
                continue
            sab[0] = ra
            sab[1] = rb
        wa = sab[0] * sc2[s]
        wb = sab[1] * sc2[s]
        n0[k] = np.float64(A[0, s] * wa + B[0, s] * wb)
        n1[k] = np.float64(A[1, s] * wa + B[1, s] * wb)
        n2[k] = np.float64(A[2, s] * wa + B[2, s] * wb)
    return hard


@_njit()
def _dichotomy_row(ws, tc, count, A, B, R, levels, off, kd, nd, n0, n1, n2, nw):
    """Dichotomy (mode 7) at the row's winners."""
    cur = -1
    tree = False
    for k in range(nw):
        s = ws[k]
        lv = levels[s]
        if s != cur:    # a span's winners are adjacent: its tree once
            cur = s
            tree = (np.int64(1) << lv) <= min(4 * count[s] + 8, _TREE_MAX)
            if tree:
                _dichotomy_tree(A, B, R, s, lv, nd)
        if tree:
            m0, m1, m2 = _dichotomy_pick(nd, lv, off[lv], kd[2 + lv], tc[k])
        else:
            m0, m1, m2 = _dichotomy_px(A[0, s], A[1, s], A[2, s], B[0, s], B[1, s],
                                       B[2, s], R, s, lv, off[lv], kd[2 + lv], tc[k])
        n0[k], n1[k], n2[k] = np.float64(m0), np.float64(m1), np.float64(m2)


#: the dichotomy builds a span's whole halving tree when it has at most this many nodes
#: (and not many more than the span has pixels); deeper spans descend per pixel
_TREE_MAX = 1 << 12


@_njit(inline=True)
def _dichotomy_tree(A, B, R, i, L, nd):
    """Every node of span ``i``'s halving tree of depth ``L`` into ``nd[:, 0 .. 2**L]``:
    the midpoint of an interval at depth ``d`` is ``(A + B) R[i, d]`` of its ends, as
    :func:`_dichotomy_px` computes it on its way down."""
    top = np.int64(1) << L
    for c in range(3):
        nd[c, 0] = A[c, i]
        nd[c, top] = B[c, i]
    step = top
    for d in range(L):
        half = step >> 1
        r = R[i, d]
        for m in range(half, top, step):
            for c in range(3):
                nd[c, m] = (nd[c, m - half] + nd[c, m + half]) * r
        step = half


@_njit(inline=True)
def _dichotomy_pick(nd, L, need_b, scale, tc):
    """:func:`_dichotomy_px` from the span's whole tree ``nd``."""
    u = tc * scale
    kf = np.floor(u)
    fr = u - kf
    k = np.int64(kf)
    if not need_b:
        return nd[0, k], nd[1, k], nd[2, k]
    kb = min(k + 1, np.int64(1) << L)
    return (nd[0, k] + fr * (nd[0, kb] - nd[0, k]), nd[1, k] + fr * (nd[1, kb] - nd[1, k]),
            nd[2, k] + fr * (nd[2, kb] - nd[2, k]))


@_njit(inline=True)
def _dichotomy_px(a0, a1, a2, b0, b1, b2, R, i, L, need_b, scale, tc):
    """The pixel at ``tc`` of dichotomy span ``i`` (ends ``a``, ``b``, depth ``L``, ``scale =
    2**L`` in the dtype, denominators ``R[i]``): node ``k = floor(tc 2**L)`` of the
    halving tree, or (``need_b``: depth ``L`` off the grid in the frame) the linear pick
    between nodes ``k`` and ``min(k + 1, 2**L)``, as :func:`.fast._dichotomy_kernel`.
    Both nodes come from one descent of the tree: every midpoint on the way is
    ``(A + B) r`` of its interval's ends with the level's ``r``, as in the reference."""
    u = tc * scale
    kf = np.floor(u)
    fr = u - kf
    k = np.int64(kf)
    top = np.int64(1) << L
    lo = np.int64(0)
    hi = top
    lev = 0
    target = k
    n0 = n1 = n2 = a0        # node k, once found
    while True:
        if target == lo:
            v0, v1, v2 = a0, a1, a2
        elif target == hi:
            v0, v1, v2 = b0, b1, b2
        else:
            mid = (lo + hi) >> 1
            rr = R[i, lev]
            lev += 1
            m0 = (a0 + b0) * rr
            m1 = (a1 + b1) * rr
            m2 = (a2 + b2) * rr
            if target < mid:
                hi = mid
                b0, b1, b2 = m0, m1, m2
                continue
            lo = mid
            a0, a1, a2 = m0, m1, m2
            if target > mid:
                continue
            v0, v1, v2 = m0, m1, m2
        # the node ``target`` is v; [lo, hi] still holds target + 1 (or target == top)
        if target == k:
            n0, n1, n2 = v0, v1, v2
            if not need_b:
                return n0, n1, n2
            target = min(k + 1, top)
            continue
        return n0 + fr * (v0 - n0), n1 + fr * (v1 - n1), n2 + fr * (v2 - n2)


@_njit()
def _slerp_fixup(pix, span, sa, sb, width, c0, t0, dt, left, right, A, B, sc2, per_pixel_h,
                 Htri, stri, L, eye, light, orders, img, mask, tri_map, nlen, face_id):
    """Shade the slerp pixels whose sines :mod:`detmath` gave (``sa``, ``sb``), as
    :func:`_frame` does the others."""
    for q in range(pix.shape[0]):
        p = pix[q]
        s = span[q]
        j = p % width - c0[s]
        t = min(max(t0[s] + j * dt[s], 0.0), 1.0)
        wa = sa[q] * sc2[s]
        wb = sb[q] * sc2[s]
        N0 = np.float64(A[0, s] * wa + B[0, s] * wb)
        N1 = np.float64(A[1, s] * wa + B[1, s] * wb)
        N2 = np.float64(A[2, s] * wa + B[2, s] * wb)
        if per_pixel_h:
            q0, q1, q2 = left[s, 4], left[s, 5], left[s, 6]
            h0, h1, h2 = _half(q0 + t * (right[s, 4] - q0), q1 + t * (right[s, 5] - q1),
                               q2 + t * (right[s, 6] - q2), eye[0], eye[1], eye[2], L[0], L[1],
                               L[2], orders[2])
        else:
            ft = stri[s]
            h0, h1, h2 = Htri[ft, 0], Htri[ft, 1], Htri[ft, 2]
        img[p] = _intensity(N0, N1, N2, h0, h1, h2, L[0], L[1], L[2], orders[0], orders[1],
                            light[0], light[1], light[2], light[3], light[4])
        mask[p] = True
        tri_map[p] = face_id[stri[s]]
        nlen[p] = np.sqrt(_dot3(N0, N1, N2, N0, N1, N2, orders[2]))


# ------------------------------------------------------------------ driver
def supports(spec) -> bool:
    """Whether :func:`phong` renders method ``spec`` (its kernel has a fused twin, numba is
    installed and :func:`calibrated` found the reductions' orders).

    >>> from chebnorm.methods import get_method
    >>> supports(get_method("dichotomy")) == (HAVE_NUMBA and calibrated() is not None)
    True
    """
    return (HAVE_NUMBA and id(method_kernel(spec)) in MODES
            and calibrated() is not None)


def gather_setup(mesh, xy, inv_w, cull):
    """The per-triangle arrays of ``render._setup``, gathered in compiled code: front
    triangle ids, ``xy (T,3,2)``, ``inv_w (T,3)``, positions and normals ``(T,3,3)``, and
    the corner attributes of :func:`phong`'s spans, ``[1/w, normal, position] (T,3,7)``."""
    tri, txy, attrs, iw, pos, nrm = _gather_setup(
        np.ascontiguousarray(mesh.positions, np.float64),
        np.ascontiguousarray(mesh.normals, np.float64), np.ascontiguousarray(xy, np.float64),
        np.ascontiguousarray(inv_w, np.float64), np.ascontiguousarray(mesh.faces, np.int64),
        bool(cull))
    return tri, txy, iw, pos, nrm, attrs


def spans(xy, attrs, width, height):
    """The spans of :func:`.spans.setup_spans` without the fragment arrays, and the
    spans of each row: ``(namespace of tri, row, x0, count, m, t0, dt, left, right,
    row_start, by_row)``; row ``r``'s spans are ``by_row[row_start[r]:row_start[r+1]]``
    (in span order)."""
    xy = np.ascontiguousarray(xy, dtype=np.float64)
    attrs = np.ascontiguousarray(attrs, dtype=np.float64)
    r0, nrows = fast._count_rows(np.ascontiguousarray(xy[..., 1]), int(height))
    T = len(nrows)
    Kc = attrs.shape[2]
    parts = _parts(nrows, _threads())
    nvalid = np.zeros(T, np.int64)
    z1, z2 = np.zeros(1, np.int64), np.zeros((1, Kc))
    fixed = (xy, attrs, int(width), r0, nrows)
    _run([(_spans_part, (*fixed, lo, hi, False, nvalid, nvalid, z1, z1, z1, z1, z1, z2[0], z2[0],
                         z2, z2)) for lo, hi in parts])
    start = np.cumsum(nvalid) - nvalid
    S = int(nvalid.sum())
    out = (np.empty(S, np.int64), np.empty(S, np.int64), np.empty(S, np.int64),
           np.empty(S, np.int64), np.empty(S, np.int64), np.empty(S), np.empty(S),
           np.empty((S, Kc)), np.empty((S, Kc)))
    _run([(_spans_part, (*fixed, lo, hi, True, nvalid, start, *out)) for lo, hi in parts])
    tri, row, c0, count, m, t0, dt, left, right = out
    row_start, by_row = _by_row(row, int(height))
    return SimpleNamespace(tri=tri, row=row, x0=c0, count=count, m=m, t0=t0, dt=dt, left=left,
                           right=right, row_start=row_start, by_row=by_row)


def _parts(nrows, k):
    """Triangle ranges ``[(lo, hi), ...]`` of about equal numbers of rows, at most ``k``."""
    T = len(nrows)
    ends = np.cumsum(nrows)
    cuts = [0] + [int(np.searchsorted(ends, ends[-1] * q / k)) if T else 0
                  for q in range(1, k)] + [T]
    return [(cuts[q], cuts[q + 1]) for q in range(k) if cuts[q] < cuts[q + 1]]


def _span_arrays(S, Kc):
    """Arrays for ``S`` spans of ``Kc`` attributes: ``tri, row, x0, count, m, t0, dt, left,
    right``."""
    return (np.empty(S, np.int64), np.empty(S, np.int64), np.empty(S, np.int64),
            np.empty(S, np.int64), np.empty(S, np.int64), np.empty(S), np.empty(S),
            np.empty((S, Kc)), np.empty((S, Kc)))


#: per thread: {Kc: span arrays} kept between frames (see _span_buffers)
_SCRATCH = threading.local()
_SCRATCH_MAX = 1 << 21     # spans (about 350 MB); larger frames get fresh arrays


def _span_buffers(S, Kc):
    """:func:`_span_arrays` as views of buffers this thread keeps between frames: fresh
    pages cost as much as the span set-up itself (a page fault per 4 KiB in this VM,
    13 MB of spans at 1024x1024), reused ones nothing. Grown by a quarter when short."""
    cache = getattr(_SCRATCH, "spans", None)
    if cache is None:
        cache = _SCRATCH.spans = {}
    buf = cache.get(Kc)
    if buf is None or buf[0].shape[0] < S:
        if S > _SCRATCH_MAX:
            cache.pop(Kc, None)
            return _span_arrays(S, Kc)
        buf = cache[Kc] = _span_arrays(min(S + S // 4 + 64, _SCRATCH_MAX), Kc)
    return tuple(b[:S] for b in buf)


def row_spans(xy, attrs, width, height, reuse=False):
    """The spans of :func:`spans`, numbered row by row: row ``r``'s are
    ``row_start[r] .. row_start[r+1]-1``, in their :func:`spans` order (so ties of the
    z-test still go to the earliest fragment), ``by_row`` the identity. A frame reads
    each span's data once per row: in this order the reads are sequential instead of
    scattered over every triangle's spans (a third of the frame's time at 1024x1024).
    The :func:`spans` numbering is the order of ``(tri, row)``. ``reuse``: the arrays are
    views of this thread's :func:`_span_buffers`, valid until its next ``reuse`` call.

    >>> import numpy as np
    >>> xy = np.array([[[0.0, 0.0], [8.0, 0.0], [0.0, 6.0]], [[1.0, 0.5], [7.0, 1.5], [2.0, 5.0]]])
    >>> a, b = spans(xy, np.ones((2, 3, 1)), 8, 6), row_spans(xy, np.ones((2, 3, 1)), 8, 6)
    >>> old = np.lexsort((b.row, b.tri))          # b's spans in spans() order
    >>> bool((np.diff(b.row) >= 0).all()) and bool((b.t0[old] == a.t0).all())
    True
    """
    xy = np.ascontiguousarray(xy, dtype=np.float64)
    attrs = np.ascontiguousarray(attrs, dtype=np.float64)
    height = int(height)
    r0, nrows = fast._count_rows(np.ascontiguousarray(xy[..., 1]), height)
    first, ids = _row_buckets(r0, nrows, height)
    Kc = attrs.shape[2]
    # row ranges of about equal numbers of (row, triangle) pairs
    k = _threads()
    cuts = [0] + [int(np.searchsorted(first, first[-1] * q / k)) for q in range(1, k)] + [height]
    parts = [(cuts[q], cuts[q + 1]) for q in range(k) if cuts[q] < cuts[q + 1]]
    row_start = np.zeros(height + 1, np.int64)
    z1, z2 = np.zeros(1, np.int64), np.zeros((1, Kc))
    fixed = (xy, attrs, int(width), first, ids)
    _run([(_row_spans_part, (*fixed, lo, hi, False, row_start, z1, z1, z1, z1, z1, z2[0], z2[0],
                             z2, z2)) for lo, hi in parts])
    np.cumsum(row_start, out=row_start)
    S = int(row_start[-1])
    out = _span_buffers(S, Kc) if reuse else _span_arrays(S, Kc)
    _run([(_row_spans_part, (*fixed, lo, hi, True, row_start, *out)) for lo, hi in parts])
    tri, row, c0, count, m, t0, dt, left, right = out
    return SimpleNamespace(tri=tri, row=row, x0=c0, count=count, m=m, t0=t0, dt=dt, left=left,
                           right=right, row_start=row_start, by_row=np.arange(S, dtype=np.int64))


def _threads() -> int:
    """Threads to split a frame over: the CPUs this process may run on (at most 8)."""
    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        n = os.cpu_count() or 1
    return max(1, min(8, n))


#: the thread pool of this process: {pid: executor} (a forked child makes its own)
_POOL: dict = {}


def _pool():
    """This process's thread pool (a forked child makes its own)."""
    pool = _POOL.get(os.getpid())
    if pool is None:
        _POOL.clear()
        pool = _POOL[os.getpid()] = ThreadPoolExecutor(max_workers=_threads(),
                                                        thread_name_prefix="chebnorm-raster")
    return pool


def _run(jobs):
    """Run ``[(kernel, args), ...]`` (compiled with ``nogil``) at once on a thread pool;
    their results in order."""
    if len(jobs) == 1:
        return [jobs[0][0](*jobs[0][1])]
    futures = [_pool().submit(fn, *args) for fn, args in jobs]
    return [f.result() for f in futures]


def phong(st, spec, lighting, tables, dtype, tri_half, auto_tables):
    """The ``phong`` frame of ``render`` (setup ``st``, method entry ``spec``): ``(image,
    mask, triangle, normal_length, fragments, stats)``, or None when this path cannot
    promise the reference's bytes (then the caller takes :mod:`.fast`). ``tri_half`` and
    ``auto_tables`` are ``render``'s own helpers (per-triangle ``H``, table choice)."""
    orders = calibrated()
    if orders is None or id(method_kernel(spec)) not in MODES:
        return None
    from . import fusedsetup

    per_pixel_h = lighting.half_vector == "pixel"
    attrs = getattr(st, "attrs", None)   # [1/w, normal, position] of gather_setup
    if attrs is None:
        attrs = np.concatenate([st.inv_w[..., None], st.nrm, st.pos], axis=2)
    if not per_pixel_h:
        attrs = attrs[..., :4]
    work = fusedsetup.take()    # scratch arrays of an earlier frame (pages mapped)
    sp = fusedsetup.row_spans(st.xy, attrs, st.width, st.height, work)
    # the output maps: the memory of an earlier frame's once the user dropped it (else
    # 25 MB of fresh pages at 1024x1024); the frame writes every pixel of its rows
    maps = fusedsetup.output_maps(st.width * st.height)
    S = len(sp.count)
    stats = {}
    mode = MODES[id(method_kernel(spec))]
    # the unit end normals, the checks of check_span_input and the values it derives,
    # compiled (fusedsetup: the reference runs where a check fails)
    ends, dot_min = (fusedsetup.widest_dot(sp, spec, dtype, mode <= 3, work)
                     if S and (mode or spec.table is not None) else (None, None))
    tables = auto_tables(spec, sp, [[1, 2, 3]], tables, stats, dot_min=dot_min)
    dt_ = np.float64    # the computation's dtype, checked (as the reference) where spans use it
    if mode and S:
        dt_, coeffs, lv, A, B, start_left, count_max = fusedsetup.span_input(
            spec, sp, tables, dtype, ends, mode <= 3)
    else:
        A = B = np.zeros((3, 1), dt_)
    C = np.zeros((3, 1), dt_)
    sc = sc2 = np.zeros(1, dt_)
    levels = np.zeros(1, np.int64)
    R = np.zeros((1, 1), dt_)
    off = np.zeros(1, np.bool_)
    kd = np.zeros(1, dt_)
    if mode and S:
        dtype = dt_
        ops = _DetOps(dtype)    # modes 1-3: B is N_r - N_l (K.vsub(b, a)) in the dtype
        if mode == 4:       # K.SLERP.setup, compiled
            sc, sc2 = fusedsetup.method_setup(mode, A, B, None, None, coeffs, start_left,
                                              count_max, ops, work)
        elif mode == 5:     # fast._quadratic_setup, compiled
            A, B, C = fusedsetup.method_setup(mode, A, B, sp.t0.astype(dtype),
                                              sp.dt.astype(dtype), coeffs, start_left,
                                              count_max, ops, work)
        elif mode == 6:     # fast._angular_setup, compiled
            A, B, sc = fusedsetup.method_setup(mode, A, B, sp.t0.astype(dtype),
                                               sp.dt.astype(dtype), coeffs, start_left,
                                               count_max, ops, work)
        elif mode == 7:     # dichotomy
            cf = np.array([0.0] if coeffs is None else [dtype(c) for c in coeffs], dtype)
            kd = np.array([2.0, 1.0] + [float(2 ** lv) for lv in range(MAX_LEVELS + 1)], dtype)
            levels = np.ascontiguousarray(lv, np.int64)
            R, off = _dichotomy_prep(A, B, levels, cf, coeffs is None, kd, sp.t0, sp.dt,
                                     sp.count)
    kc = np.array([3.0, 0.5, 0.375, 1.25, 1.875, 1.0], dt_)
    C = np.ascontiguousarray(C)
    Htri = (np.ascontiguousarray(tri_half(st), np.float64) if not per_pixel_h
            else np.zeros((1, 3)))
    light = np.array([lighting.I0, lighting.ka, lighting.kd, lighting.ks, lighting.shininess,
                      float(pow_calibrated(float(lighting.shininess))),
                      float(mode == 4 and trig_calibrated())], np.float64)
    L = np.ascontiguousarray(st.L, np.float64)
    eye = np.asarray(st.camera.eye, np.float64)
    ords = np.array(orders, np.int64)
    face_id = np.ascontiguousarray(st.tri, np.int64)
    args = (sp.x0, sp.t0, sp.dt, sp.left, sp.right)
    img, mask, tri_map, nlen = maps
    common = (st.width, st.height, mode, sp.row_start, sp.by_row, sp.tri, sp.x0, sp.count,
              *args[1:], A, B, C, sc, sc2, levels, R, off, kc, kd, dt_ is np.float64, face_id,
              per_pixel_h, Htri, L, eye, light, ords)
    k = min(_threads(), st.height)
    nh = sum(_run([(_frame, (*common, q, k, *maps)) for q in range(k)]))
    if nh:
        pix = np.flatnonzero(tri_map < -1)
        span = -2 - tri_map[pix]
        j = pix % st.width - sp.x0[span]
        tc = (sp.t0[span] + j * sp.dt[span]).astype(dt_)
        psi = sc[span]
        sa, sb = detmath.sin((kc[5] - tc) * psi), detmath.sin(tc * psi)
        _slerp_fixup(pix, span, sa, sb, st.width, *args, A, B, sc2, per_pixel_h, Htri, sp.tri,
                     L, eye, light, ords, img, mask, tri_map, nlen, face_id)
    fusedsetup.give(work)
    fusedsetup.keep_maps(maps)
    if np.count_nonzero(mask) < 2:
        return None    # numpy computes N @ L for one row by another route than BLAS
    shape = (st.height, st.width)
    return (img.reshape(shape), mask.reshape(shape), tri_map.reshape(shape),
            nlen.reshape(shape), int(sp.count.sum()), stats)

