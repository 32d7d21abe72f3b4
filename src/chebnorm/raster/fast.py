"""Compiled fast path of the rasterizer (numba, optional).

The numpy code of :mod:`.spans`, :mod:`.render` and :func:`chebnorm.methods.span_normals`
is the reference; this module computes the same arrays, byte for byte, with loops
compiled by numba (``cache=True``; no ``fastmath``, no ``parallel``: every float
operation is the reference's, in the reference's order and dtype, and LLVM does not
contract a multiply-add into an FMA without fast-math flags).  Transcendental
functions (``sin``, ``cos``, ``arccos``, ``log2``) are left to the same numpy ufuncs
the reference calls, on per-span (or per-pixel) arrays, so libm differences cannot
enter.  ``tests/test_raster_fast.py`` checks the identity on several meshes, modes,
methods and dtypes.

Without numba (:data:`HAVE_NUMBA` False) nothing here is used and :func:`render`
runs the numpy path.

Kernels are matched by the registry's kernel *objects*
(:func:`chebnorm.methods.registry.method_kernel`), not by method names: a method
whose kernel has no compiled twin here runs on the numpy reference.
"""

from __future__ import annotations

import numpy as np

from chebnorm.methods import kernels as K
from chebnorm.methods.ops import NumpyOps
from chebnorm.methods.registry import method_kernel
from chebnorm.methods.spans import MAX_LEVELS, SpanNormals, check_span_input

from .spans import Spans

try:  # pragma: no cover - exercised by whichever environment runs the tests
    import numba
    HAVE_NUMBA = True
except ImportError:  # pragma: no cover
    numba = None
    HAVE_NUMBA = False

__all__ = ["HAVE_NUMBA", "ENGINES", "resolve_engine", "supports", "fast_setup_spans",
           "fast_zbuffer", "fast_span_normals", "fast_lerp"]

#: accepted values of ``render(engine=...)``
ENGINES = ("auto", "numpy", "numba")


def resolve_engine(engine) -> str:
    """``"numpy"`` or ``"numba"``: what ``engine`` (``"auto"``, None, ``"numpy"``,
    ``"numba"``) means here; ``"numba"`` without numba installed is an error.

    >>> resolve_engine("numpy")
    'numpy'
    """
    if engine is None:
        engine = "auto"
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r}; accepted: {', '.join(ENGINES)}")
    if engine == "auto":
        return "numba" if HAVE_NUMBA else "numpy"
    if engine == "numba" and not HAVE_NUMBA:
        raise ValueError("engine 'numba' needs the numba package (pip install numba); "
                         "accepted without it: auto, numpy")
    return engine


def _njit(fn):
    if not HAVE_NUMBA:
        return fn
    return numba.njit(cache=True, nogil=True, fastmath=False, error_model="numpy")(fn)


# --------------------------------------------------------------- span set-up
@_njit
def _count_rows(ys, height):
    T = ys.shape[0]
    r0 = np.empty(T, np.int64)
    nrows = np.empty(T, np.int64)
    for i in range(T):
        ymin = min(ys[i, 0], ys[i, 1], ys[i, 2])
        ymax = max(ys[i, 0], ys[i, 1], ys[i, 2])
        a = min(max(np.ceil(ymin - 0.5), 0.0), float(height))
        b = min(max(np.ceil(ymax - 0.5), 0.0), float(height))
        r0[i] = np.int64(a)
        nrows[i] = max(np.int64(b) - np.int64(a), 0)
    return r0, nrows


@_njit
def _spans_kernel(xy, attrs, width, r0, nrows, n_max):
    T, _, Kc = attrs.shape
    tri = np.empty(n_max, np.int64)
    row = np.empty(n_max, np.int64)
    c0 = np.empty(n_max, np.int64)
    count = np.empty(n_max, np.int64)
    m = np.empty(n_max, np.int64)
    t0 = np.empty(n_max, np.float64)
    dt = np.empty(n_max, np.float64)
    left = np.empty((n_max, Kc), np.float64)
    right = np.empty((n_max, Kc), np.float64)
    ei = (0, 1, 2)
    ej = (1, 2, 0)
    aa = np.empty(Kc, np.float64)
    ab = np.empty(Kc, np.float64)
    n = 0
    for i in range(T):
        for r in range(r0[i], r0[i] + nrows[i]):
            y = r + 0.5
            nhit = 0
            e1 = -1
            e2 = -1
            for e in range(3):
                yi = xy[i, ei[e], 1]
                yj = xy[i, ej[e], 1]
                if min(yi, yj) <= y and y < max(yi, yj):
                    nhit += 1
                    if e1 < 0:
                        e1 = e
                    e2 = e
            if nhit != 2:
                continue
            # crossing of edge e1 (a) and e2 (b)
            p, q = ei[e1], ej[e1]
            s = (y - xy[i, p, 1]) / (xy[i, q, 1] - xy[i, p, 1])
            xa = xy[i, p, 0] + s * (xy[i, q, 0] - xy[i, p, 0])
            for k in range(Kc):
                aa[k] = attrs[i, p, k] + s * (attrs[i, q, k] - attrs[i, p, k])
            p, q = ei[e2], ej[e2]
            s = (y - xy[i, p, 1]) / (xy[i, q, 1] - xy[i, p, 1])
            xb = xy[i, p, 0] + s * (xy[i, q, 0] - xy[i, p, 0])
            for k in range(Kc):
                ab[k] = attrs[i, p, k] + s * (attrs[i, q, k] - attrs[i, p, k])
            swap = xb < xa
            xl = xb if swap else xa
            xr = xa if swap else xb
            a = np.int64(min(max(np.ceil(xl - 0.5), 0.0), float(width)))
            b = np.int64(min(max(np.ceil(xr - 0.5), 0.0), float(width)))
            c = max(b - a, 0)
            if c <= 0:
                continue
            tri[n] = i
            row[n] = r
            c0[n] = a
            count[n] = c
            for k in range(Kc):
                left[n, k] = ab[k] if swap else aa[k]
                right[n, k] = aa[k] if swap else ab[k]
            ws = xr - xl
            d = 1.0 / ws
            dt[n] = d
            t0[n] = ((a + 0.5) - xl) * d
            m[n] = np.int64(max(1.0, np.ceil(ws)))
            n += 1
    return (tri[:n], row[:n], c0[:n], count[:n], m[:n], t0[:n], dt[:n],
            left[:n].copy(), right[:n].copy())


@_njit
def _fragments(row, c0, count, t0, dt, width):
    S = count.shape[0]
    offsets = np.zeros(S + 1, np.int64)
    for i in range(S):
        offsets[i + 1] = offsets[i] + count[i]
    P = offsets[S]
    frag_span = np.empty(P, np.int64)
    frag_pixel = np.empty(P, np.int64)
    frag_t = np.empty(P, np.float64)
    for i in range(S):
        base = row[i] * width + c0[i]
        for j in range(count[i]):
            f = offsets[i] + j
            frag_span[f] = i
            frag_pixel[f] = base + j
            t = t0[i] + j * dt[i]
            frag_t[f] = min(max(t, 0.0), 1.0)
    return offsets, frag_span, frag_pixel, frag_t


def fast_setup_spans(xy, attrs, width: int, height: int) -> Spans:
    """:func:`chebnorm.raster.setup_spans`, compiled; the same arrays.

    >>> import numpy as np
    >>> from chebnorm.raster import setup_spans
    >>> xy = np.array([[[1.0, 1.0], [9.0, 2.0], [3.0, 8.0]]]); at = np.ones((1, 3, 1))
    >>> a, b = fast_setup_spans(xy, at, 10, 10), setup_spans(xy, at, 10, 10)
    >>> bool((a.frag_pixel == b.frag_pixel).all() and (a.frag_t == b.frag_t).all())
    True
    """
    xy = np.ascontiguousarray(xy, dtype=np.float64)
    attrs = np.ascontiguousarray(attrs, dtype=np.float64)
    r0, nrows = _count_rows(np.ascontiguousarray(xy[..., 1]), int(height))
    tri, row, c0, count, m, t0, dt, left, right = _spans_kernel(
        xy, attrs, int(width), r0, nrows, int(nrows.sum()))
    offsets, frag_span, frag_pixel, frag_t = _fragments(row, c0, count, t0, dt, int(width))
    return Spans(tri, row, c0, count, m, t0, dt, left, right, offsets, frag_span, frag_pixel,
                 frag_t)


# ----------------------------------------------------------------- z-buffer
@_njit
def _zbuffer_kernel(frag_span, frag_pixel, frag_t, left, right, n_pixels):
    best = np.full(n_pixels, -1, np.int64)
    bw = np.empty(n_pixels, np.float64)
    P = frag_pixel.shape[0]
    for f in range(P):
        s = frag_span[f]
        lo = left[s, 0]
        w = lo + frag_t[f] * (right[s, 0] - lo)
        p = frag_pixel[f]
        if best[p] < 0 or w > bw[p]:
            best[p] = f
            bw[p] = w
    n = 0
    for p in range(n_pixels):
        if best[p] >= 0:
            n += 1
    vis = np.empty(n, np.int64)
    n = 0
    for p in range(n_pixels):
        if best[p] >= 0:
            vis[n] = best[p]
            n += 1
    return vis


def fast_zbuffer(sp: Spans, n_pixels: int) -> np.ndarray:
    """``zbuffer(sp.frag_pixel, sp.lerp([0])[:, 0], n_pixels)``, compiled (depth in
    attribute column 0; finite depths)."""
    return _zbuffer_kernel(sp.frag_span, sp.frag_pixel, sp.frag_t,
                           np.ascontiguousarray(sp.left), np.ascontiguousarray(sp.right),
                           int(n_pixels))


@_njit
def _lerp_kernel(frag_span, frag_t, left, right, cols, sel):
    n = sel.shape[0]
    out = np.empty((n, cols.shape[0]), np.float64)
    for i in range(n):
        f = sel[i]
        s = frag_span[f]
        t = frag_t[f]
        for k in range(cols.shape[0]):
            c = cols[k]
            lo = left[s, c]
            out[i, k] = lo + t * (right[s, c] - lo)
    return out


def fast_lerp(sp: Spans, cols, sel) -> np.ndarray:
    """``sp.lerp(cols)[sel]``, compiled, without interpolating the other fragments."""
    return _lerp_kernel(sp.frag_span, sp.frag_t, np.ascontiguousarray(sp.left),
                        np.ascontiguousarray(sp.right), np.asarray(cols, np.int64),
                        np.asarray(sel, np.int64))


# ------------------------------------------------------------ span normals
@_njit
def _pixel_t(offsets, t0, dt, tc):
    """Pixel positions ``t0 + j dt`` (float64) and cast to the kernel's dtype (``tc``)."""
    S = offsets.shape[0] - 1
    t = np.empty(offsets[S], np.float64)
    for i in range(S):
        for j in range(offsets[i + 1] - offsets[i]):
            f = offsets[i] + j
            v = t0[i] + (f - offsets[i]) * dt[i]
            t[f] = v
            tc[f] = v
    return t


@_njit
def _linear_kernel(offsets, a, d, tc, mode, kc, out):
    # mode 0: none, 1: classic N/sqrt(N.N), 2: Newton, 3: Lyon; kc: constants in the dtype
    S = offsets.shape[0] - 1
    for i in range(S):
        a0, a1, a2 = a[0, i], a[1, i], a[2, i]
        d0, d1, d2 = d[0, i], d[1, i], d[2, i]
        for f in range(offsets[i], offsets[i + 1]):
            t = tc[f]
            n0 = a0 + t * d0
            n1 = a1 + t * d1
            n2 = a2 + t * d2
            if mode == 0:
                out[f, 0] = n0
                out[f, 1] = n1
                out[f, 2] = n2
                continue
            x = n0 * n0 + n1 * n1 + n2 * n2
            if mode == 1:
                r = np.sqrt(x)
                out[f, 0] = n0 / r
                out[f, 1] = n1 / r
                out[f, 2] = n2 / r
                continue
            if mode == 2:
                s = (kc[0] - x) * kc[1]
            else:
                s = (x * kc[2] - kc[3]) * x + kc[4]
            out[f, 0] = n0 * s
            out[f, 1] = n1 * s
            out[f, 2] = n2 * s


@_njit
def _slerp_args(offsets, psi, tc, one, arg_a, arg_b):
    S = offsets.shape[0] - 1
    for i in range(S):
        p = psi[i]
        for f in range(offsets[i], offsets[i + 1]):
            t = tc[f]
            arg_a[f] = (one - t) * p
            arg_b[f] = t * p


@_njit
def _slerp_combine(offsets, a, b, inv, sa, sb, out):
    S = offsets.shape[0] - 1
    for i in range(S):
        iv = inv[i]
        for f in range(offsets[i], offsets[i + 1]):
            wa = sa[f] * iv
            wb = sb[f] * iv
            out[f, 0] = a[0, i] * wa + b[0, i] * wb
            out[f, 1] = a[1, i] * wa + b[1, i] * wb
            out[f, 2] = a[2, i] * wa + b[2, i] * wb


@_njit
def _quadratic_kernel(offsets, v, d1, d2, out):
    S = offsets.shape[0] - 1
    for i in range(S):
        v0, v1, v2 = v[0, i], v[1, i], v[2, i]
        e0, e1, e2 = d1[0, i], d1[1, i], d1[2, i]
        f0, f1, f2 = d2[0, i], d2[1, i], d2[2, i]
        f = offsets[i]
        out[f, 0] = v0
        out[f, 1] = v1
        out[f, 2] = v2
        for f in range(offsets[i] + 1, offsets[i + 1]):
            v0 = v0 + e0
            v1 = v1 + e1
            v2 = v2 + e2
            e0 = e0 + f0
            e1 = e1 + f1
            e2 = e2 + f2
            out[f, 0] = v0
            out[f, 1] = v1
            out[f, 2] = v2


@_njit
def _angular_kernel(offsets, p0, p1, k2, out):
    S = offsets.shape[0] - 1
    for i in range(S):
        f = offsets[i]
        n = offsets[i + 1] - f
        a0, a1, a2 = p0[0, i], p0[1, i], p0[2, i]
        out[f, 0] = a0
        out[f, 1] = a1
        out[f, 2] = a2
        if n < 2:
            continue
        b0, b1, b2 = p1[0, i], p1[1, i], p1[2, i]
        out[f + 1, 0] = b0
        out[f + 1, 1] = b1
        out[f + 1, 2] = b2
        k = k2[i]
        for g in range(f + 2, f + n):
            c0 = b0 * k - a0
            c1 = b1 * k - a1
            c2 = b2 * k - a2
            a0, a1, a2 = b0, b1, b2
            b0, b1, b2 = c0, c1, c2
            out[g, 0] = b0
            out[g, 1] = b1
            out[g, 2] = b2


@_njit
def _dichotomy_node(nl, nr, r, i, L, k, res):
    """Node ``k`` of ``2**L + 1`` of span ``i`` (by descending the halving tree)."""
    top = np.int64(1) << L
    if k == 0:
        for c in range(3):
            res[c] = nl[c, i]
        return
    if k == top:
        for c in range(3):
            res[c] = nr[c, i]
        return
    A0, A1, A2 = nl[0, i], nl[1, i], nl[2, i]
    B0, B1, B2 = nr[0, i], nr[1, i], nr[2, i]
    lo = np.int64(0)
    hi = top
    for lev in range(L):
        mid = (lo + hi) >> 1
        rr = r[i, lev]
        M0 = (A0 + B0) * rr
        M1 = (A1 + B1) * rr
        M2 = (A2 + B2) * rr
        if k == mid:
            res[0] = M0
            res[1] = M1
            res[2] = M2
            return
        if k < mid:
            hi = mid
            B0, B1, B2 = M0, M1, M2
        else:
            lo = mid
            A0, A1, A2 = M0, M1, M2


@_njit
def _dichotomy_denominators(nl, nr, levels, coeffs, exact, kc):
    """``(r, Lmax)``: ``r[i, lev]`` the reciprocal length of span ``i``'s
    midpoint sum at depth ``lev`` (``1/sqrt(z + 2)``, exact or by the table's
    polynomial in ``z``), stepped as ``z <- (z + 2) r``; ``Lmax`` the deepest
    level. kc[0] = 2 (in the dtype), kc[1] = 1; coeffs ascending, in the dtype."""
    S = levels.shape[0]
    Lmax = 0
    for i in range(S):
        Lmax = max(Lmax, levels[i])
    r = np.empty((S, max(Lmax, 1)), nl.dtype)
    for i in range(S):
        z = (nl[0, i] * nr[0, i] + nl[1, i] * nr[1, i] + nl[2, i] * nr[2, i]) * kc[0]
        L = levels[i]
        for lev in range(L):
            s = z + kc[0]
            if exact:
                rr = kc[1] / np.sqrt(s)
            else:
                p = coeffs[coeffs.shape[0] - 1]
                for q in range(coeffs.shape[0] - 2, -1, -1):
                    p = p * z + coeffs[q]
                rr = p
            r[i, lev] = rr
            if lev < L - 1:
                z = s * rr
    return r, Lmax


@_njit
def _dichotomy_kernel(offsets, nl, nr, levels, coeffs, exact, kc, tc, out):
    S = offsets.shape[0] - 1
    r, Lmax = _dichotomy_denominators(nl, nr, levels, coeffs, exact, kc)
    # per level: does any pixel fall off the grid (then every pixel of the level is picked)
    off = np.zeros(Lmax + 1, np.bool_)
    for i in range(S):
        L = levels[i]
        scale = kc[2 + L]
        for f in range(offsets[i], offsets[i + 1]):
            u = tc[f] * scale
            if u - np.floor(u) != 0:
                off[L] = True
    na = np.empty(3, nl.dtype)
    nb = np.empty(3, nl.dtype)
    for i in range(S):
        L = levels[i]
        scale = kc[2 + L]
        top = np.int64(1) << L
        for f in range(offsets[i], offsets[i + 1]):
            u = tc[f] * scale
            kf = np.floor(u)
            fr = u - kf
            k = np.int64(kf)
            _dichotomy_node(nl, nr, r, i, L, k, na)
            if not off[L]:
                out[f, 0] = na[0]
                out[f, 1] = na[1]
                out[f, 2] = na[2]
                continue
            _dichotomy_node(nl, nr, r, i, L, min(k + 1, top), nb)
            out[f, 0] = na[0] + fr * (nb[0] - na[0])
            out[f, 1] = na[1] + fr * (nb[1] - na[1])
            out[f, 2] = na[2] + fr * (nb[2] - na[2])


_LINEAR_MODES = {id(K.NONE): 0, id(K.EXACT): 1, id(K.NEWTON): 2, id(K.LYON): 3}


def supports(method) -> bool:
    """Whether the method's kernel (from the registry) has a compiled twin here."""
    kern = method_kernel(method)
    return HAVE_NUMBA and (id(kern) in _LINEAR_MODES or kern is K.SLERP or kern is K.QUADRATIC
                           or kern is K.ANGULAR or kern is K.DICHOTOMY)


def fast_span_normals(method, n_left, n_right, m, *, t0=None, dt=None, count=None, tables=None,
                      dtype=np.float64) -> SpanNormals:
    """:func:`chebnorm.methods.span_normals` (same arguments but ``angular_reanchor``,
    same checks and errors), compiled: the same bytes.

    >>> import numpy as np
    >>> from chebnorm.methods import span_normals
    >>> nl = np.array([[1.0, 0.0, 0.0]]); nr = np.array([[0.8, 0.0, 0.6]])
    >>> a = fast_span_normals("dichotomy", nl, nr, [5], dtype=np.float32)
    >>> bool((a.normals == span_normals("dichotomy", nl, nr, [5], dtype=np.float32).normals).all())
    True
    """
    if not supports(method):
        from chebnorm.methods import span_normals
        return span_normals(method, n_left, n_right, m, t0=t0, dt=dt, count=count, tables=tables,
                            dtype=dtype)
    inp = check_span_input(method, n_left, n_right, m, t0=t0, dt=dt, count=count, tables=tables,
                           dtype=dtype)
    kern, dtype, nl, nr = inp.kernel, inp.dtype, inp.n_left, inp.n_right
    dt_arr, t0_arr, cnt, levels, coeffs = inp.dt, inp.t0, inp.count, inp.levels, inp.coefficients
    offsets = np.zeros(nl.shape[0] + 1, dtype=np.int64)
    np.cumsum(cnt, out=offsets[1:])
    P = int(offsets[-1])
    tc = np.empty(P, dtype)
    t = _pixel_t(offsets, t0_arr, dt_arr, tc)
    ops = NumpyOps(dtype)
    a = np.ascontiguousarray(nl.astype(dtype).T)
    b = np.ascontiguousarray(nr.astype(dtype).T)
    out = np.empty((P, 3), dtype=dtype)
    if id(kern) in _LINEAR_MODES:
        d = np.ascontiguousarray(np.stack(K.vsub(tuple(b), tuple(a))))
        kc = np.array([3.0, 0.5, 0.375, 1.25, 1.875], dtype)
        _linear_kernel(offsets, a, d, tc, _LINEAR_MODES[id(kern)], kc, out)
    elif kern is K.SLERP:
        st = kern.setup(ops, tuple(a), tuple(b), coeffs)
        arg_a, arg_b = np.empty(P, dtype), np.empty(P, dtype)
        _slerp_args(offsets, np.asarray(st["psi"], dtype), tc, dtype(1.0), arg_a, arg_b)
        _slerp_combine(offsets, a, b, np.asarray(st["inv"], dtype), ops.sin(arg_a),
                       ops.sin(arg_b), out)
    elif kern is K.QUADRATIC:
        v, d1, d2 = _quadratic_setup(ops, tuple(a), tuple(b), t0_arr.astype(dtype),
                                     dt_arr.astype(dtype), coeffs, bool((t0_arr == 0).all()))
        _quadratic_kernel(offsets, v, d1, d2, out)
    elif kern is K.ANGULAR:
        p0, p1, k2 = _angular_setup(ops, tuple(a), tuple(b), t0_arr.astype(dtype),
                                    dt_arr.astype(dtype), int(cnt.max()),
                                    bool((t0_arr == 0).all()))
        _angular_kernel(offsets, p0, p1, k2, out)
    else:  # dichotomy
        cf = np.array([0.0] if coeffs is None else [dtype(c) for c in coeffs], dtype)
        kc = np.array([2.0, 1.0] + [float(2 ** lv) for lv in range(MAX_LEVELS + 1)], dtype)
        _dichotomy_kernel(offsets, a, b, levels.astype(np.int64), cf, coeffs is None, kc, tc, out)
    return SpanNormals(normals=out, offsets=offsets, t=t)


def _stack(v):
    return np.ascontiguousarray(np.stack([np.broadcast_to(c, v[0].shape) for c in v]))


def _quadratic_setup(ops, nl, nr, t0, dt, coeffs, start_at_left):
    """The set-up of :func:`chebnorm.methods.kernels.quadratic_steps`, in its operation order."""
    x = K.dot(nl, nr)
    s = K.vadd(nl, nr)
    r = K.horner(ops, coeffs, x) if coeffs is not None else 1.0 / ops.sqrt((x + 1.0) * 2.0)
    nc4 = K.vmul(K.vmul(s, r), 4.0)
    g = K.vsub(K.vmul(s, 2.0), nc4)
    p = K.vsub(K.vsub(nc4, K.vmul(nl, 2.0)), s)
    h2 = dt * dt
    d2 = K.vmul(g, h2 * 2.0)
    if start_at_left:
        v = nl
        d1 = K.vadd(K.vmul(p, dt), K.vmul(g, h2))
    else:
        v = K.vadd(nl, K.vmul(K.vadd(p, K.vmul(g, t0)), t0))
        d1 = K.vadd(K.vmul(p, dt), K.vmul(g, (t0 * dt) * 2.0 + h2))
    return _stack(v), _stack(d1), _stack(d2)


def _angular_setup(ops, nl, nr, t0, dt, n, start_at_left):
    """The first two pixels of :func:`chebnorm.methods.kernels.angular_steps` (run by the
    kernel itself) and its recurrence factor ``2 cos(phi)``, in its operation order."""
    gen = K.angular_steps(ops, nl, nr, t0, dt, n, start_at_left=start_at_left)
    p0 = next(gen)
    p1 = next(gen) if n >= 2 else p0
    c = ops.minimum(K.dot(nl, nr), 1.0)
    k2 = ops.cos(ops.arccos(c) * dt) * 2.0
    return _stack(p0), _stack(p1), np.ascontiguousarray(k2)


# ---------------------------------------------------------------- shading
@_njit
def _half_vectors_kernel(frag_span, frag_t, left, right, c0, sel, L, eye):
    """``_unit(L + _unit(eye - P))`` at the fragments ``sel``, ``P`` interpolated from
    attribute columns ``c0 .. c0+2`` (the reference's operation order)."""
    n = sel.shape[0]
    H = np.empty((n, 3), np.float64)
    for i in range(n):
        f = sel[i]
        s = frag_span[f]
        t = frag_t[f]
        lo0, lo1, lo2 = left[s, c0], left[s, c0 + 1], left[s, c0 + 2]
        p0 = lo0 + t * (right[s, c0] - lo0)
        p1 = lo1 + t * (right[s, c0 + 1] - lo1)
        p2 = lo2 + t * (right[s, c0 + 2] - lo2)
        v0, v1, v2 = eye[0] - p0, eye[1] - p1, eye[2] - p2
        r = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
        v0, v1, v2 = v0 / r, v1 / r, v2 / r
        h0, h1, h2 = L[0] + v0, L[1] + v1, L[2] + v2
        r = np.sqrt(h0 * h0 + h1 * h1 + h2 * h2)
        H[i, 0] = h0 / r
        H[i, 1] = h1 / r
        H[i, 2] = h2 / r
    return H


def fast_half_vectors(sp: Spans, col: int, vis, L, eye) -> np.ndarray:
    """Per-pixel Blinn half vectors at the visible fragments (positions in attribute
    columns ``col .. col+2``), as :mod:`.render` computes them."""
    return _half_vectors_kernel(sp.frag_span, sp.frag_t, np.ascontiguousarray(sp.left),
                                np.ascontiguousarray(sp.right), int(col),
                                np.asarray(vis, np.int64), np.asarray(L, np.float64),
                                np.asarray(eye, np.float64))


@_njit
def _shade_kernel(ndotl, ndoth, N, pixel, tri_of, light, n_pixels):
    # light: I0, ka, kd, ks, shininess
    img = np.zeros(n_pixels, np.float64)
    mask = np.zeros(n_pixels, np.bool_)
    tri = np.full(n_pixels, -1, np.int64)
    nlen = np.full(n_pixels, np.nan, np.float64)
    I0, ka, kd, ks, sh = light[0], light[1], light[2], light[3], light[4]
    for i in range(pixel.shape[0]):
        a = ndotl[i]
        b = ndoth[i]
        a = a if (a >= 0.0 or a != a) else 0.0      # np.maximum(a, 0.0)
        b = b if (b >= 0.0 or b != b) else 0.0
        v = I0 * (ka + kd * a + ks * b ** sh)
        if v < 0.0:
            v = 0.0
        elif v > 1.0:
            v = 1.0
        p = pixel[i]
        img[p] = v
        mask[p] = True
        tri[p] = tri_of[i]
        nlen[p] = np.sqrt(N[i, 0] * N[i, 0] + N[i, 1] * N[i, 1] + N[i, 2] * N[i, 2])
    return img, mask, tri, nlen


def fast_shade(ndotl, ndoth, N, pixel, tri_of, lighting, n_pixels):
    """Blinn-Phong intensities clipped to [0, 1] scattered into the image, with the
    coverage mask, the triangle map (-1 off the mesh) and ``|N|`` (NaN off the mesh)."""
    light = np.array([lighting.I0, lighting.ka, lighting.kd, lighting.ks, lighting.shininess],
                     np.float64)
    return _shade_kernel(np.ascontiguousarray(ndotl, np.float64),
                         np.ascontiguousarray(ndoth, np.float64),
                         np.ascontiguousarray(N, np.float64), np.asarray(pixel, np.int64),
                         np.asarray(tri_of, np.int64), light, int(n_pixels))
