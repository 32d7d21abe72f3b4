"""Span-normal, half-vector and shading kernels of the compiled engine (numba).

The numpy code of :func:`chebnorm.methods.span_normals` and of the numpy engine
(:mod:`chebnorm.raster.engines.numpy`) is the reference; this module computes the same
arrays, byte for byte, with loops compiled by :func:`.jit.njit`: every float operation
is the reference's, in the reference's order and dtype.  Transcendental functions
(``sin``, ``cos``, ``arccos``, ``log2``) are left to the same numpy ufuncs the reference
calls, on per-span (or per-pixel) arrays, so libm differences cannot enter.
``tests/test_raster_fast.py`` checks the identity on several meshes, modes, methods and
dtypes.

Kernels are matched by the registry's kernel *objects*
(:func:`chebnorm.methods.registry.method_kernel`), not by method names: a method
whose kernel has no compiled twin here runs on the numpy reference.
"""

from __future__ import annotations

import numpy as np

from chebnorm.methods import kernels as K
from chebnorm.methods.ops import NumpyOps
from chebnorm.methods.registry import method_kernel
from chebnorm.methods.spans import MAX_LEVELS, SpanNormals, check_span_input, span_normals

from ...scanline import Spans
from .jit import HAVE_NUMBA, njit

# an implementation module of chebnorm.raster.engines.numba: the API is what chebnorm.raster.engines.numba exports
__all__: list[str] = []


# ------------------------------------------------------------ span normals
@njit
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


@njit
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


@njit
def _slerp_args(offsets, psi, tc, one, arg_a, arg_b):
    S = offsets.shape[0] - 1
    for i in range(S):
        p = psi[i]
        for f in range(offsets[i], offsets[i + 1]):
            t = tc[f]
            arg_a[f] = (one - t) * p
            arg_b[f] = t * p


@njit
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


@njit
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


@njit
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


@njit
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


@njit
def dichotomy_denominators(nl, nr, levels, coeffs, exact, kc):
    """``(r, Lmax)``: ``r[i, lev]`` the reciprocal length of span ``i``'s
    midpoint sum at depth ``lev`` (``1/sqrt(z + 2)``, exact or by the table's
    polynomial in ``z``), stepped as ``z <- (z + 2) r``; ``Lmax`` the deepest
    level. kc[0] = 2 (in the dtype), kc[1] = 1; coeffs ascending, in the dtype."""
    S = levels.shape[0]
    Lmax = 0
    for i in range(S):
        Lmax = max(Lmax, levels[i])
    r = np.empty((S, max(Lmax, 1)), nl.dtype)
    dichotomy_denominators_into(nl, nr, levels, coeffs, exact, kc, r)
    return r, Lmax


@njit
def dichotomy_denominators_into(nl, nr, levels, coeffs, exact, kc, r):
    """:func:`dichotomy_denominators`' ``r`` written into ``r`` (at least ``(S, Lmax)``;
    a caller's buffer kept between frames, so no fresh pages)."""
    S = levels.shape[0]
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


@njit
def _dichotomy_kernel(offsets, nl, nr, levels, coeffs, exact, kc, tc, out):
    S = offsets.shape[0] - 1
    r, Lmax = dichotomy_denominators(nl, nr, levels, coeffs, exact, kc)
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
    """Whether the method's kernel (from the registry) has a compiled twin here.

    Parameters
    ----------
    method : str or MethodSpec
        A registered method.

    Returns
    -------
    bool
        True when a compiled twin exists.
    """
    kern = method_kernel(method)
    return HAVE_NUMBA and (id(kern) in _LINEAR_MODES or kern is K.SLERP or kern is K.QUADRATIC
                           or kern is K.ANGULAR or kern is K.DICHOTOMY)


def fast_span_normals(method, n_left, n_right, m, *, t0=None, dt=None, count=None, tables=None,
                      dtype=np.float64) -> SpanNormals:
    """:func:`chebnorm.methods.span_normals` (same arguments but ``angular_reanchor``,
    same checks and errors), compiled: the same bytes.

    Parameters
    ----------
    method, n_left, n_right, m, t0, dt, count, tables, dtype
        As in :func:`chebnorm.methods.span_normals`.

    Returns
    -------
    SpanNormals
        The same arrays as :func:`chebnorm.methods.span_normals`.

    Raises
    ------
    ValueError
        As :func:`chebnorm.methods.span_normals`.

    Examples
    --------
    >>> import numpy as np
    >>> from chebnorm.methods import span_normals
    >>> nl = np.array([[1.0, 0.0, 0.0]]); nr = np.array([[0.8, 0.0, 0.6]])
    >>> a = fast_span_normals("dichotomy", nl, nr, [5], dtype=np.float32)
    >>> bool((a.normals == span_normals("dichotomy", nl, nr, [5], dtype=np.float32).normals).all())
    True
    """
    if not supports(method):
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
        v, d1, d2 = quadratic_setup(ops, tuple(a), tuple(b), t0_arr.astype(dtype),
                                     dt_arr.astype(dtype), coeffs, bool((t0_arr == 0).all()))
        _quadratic_kernel(offsets, v, d1, d2, out)
    elif kern is K.ANGULAR:
        p0, p1, k2 = angular_setup(ops, tuple(a), tuple(b), t0_arr.astype(dtype),
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


def quadratic_setup(ops, nl, nr, t0, dt, coeffs, start_at_left):
    """The set-up of :func:`chebnorm.methods.kernels.quadratic_steps`, in its operation order.

    Parameters
    ----------
    ops : NumpyOps or DetOps
        The arithmetic backend.
    nl, nr : tuple of 3 arrays
        The spans' unit end normals.
    t0, dt : array
        First position and step per span.
    coeffs : sequence of float or None
        The midpoint table's coefficients (None: exact).
    start_at_left : bool
        The first pixel is ``N_l`` itself.

    Returns
    -------
    tuple
        The forward-difference state ``(v, d1, d2)`` per span.
    """
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


def angular_setup(ops, nl, nr, t0, dt, n, start_at_left):
    """The first two pixels of :func:`chebnorm.methods.kernels.angular_steps` (run by the
    kernel itself) and its recurrence factor ``2 cos(phi)``, in its operation order.

    Parameters
    ----------
    ops : NumpyOps or DetOps
        The arithmetic backend.
    nl, nr : tuple of 3 arrays
        The spans' unit end normals.
    t0, dt : array
        First position and step per span.
    n : array
        Pixels per span.
    start_at_left : bool
        The first pixel is ``N_l`` itself.

    Returns
    -------
    tuple
        The first two pixels and ``2 cos(phi)``, per span.
    """
    gen = K.angular_steps(ops, nl, nr, t0, dt, n, start_at_left=start_at_left)
    p0 = next(gen)
    p1 = next(gen) if n >= 2 else p0
    c = ops.minimum(K.dot(nl, nr), 1.0)
    k2 = ops.cos(ops.arccos(c) * dt) * 2.0
    return _stack(p0), _stack(p1), np.ascontiguousarray(k2)


# ---------------------------------------------------------------- shading
@njit
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
    columns ``col .. col+2``), as the numpy engine computes them.

    Parameters
    ----------
    sp : Spans
        The frame's spans.
    col : int
        The first attribute column of the positions.
    vis : numpy.ndarray
        Indices of the visible fragments.
    L : numpy.ndarray
        Unit direction toward the light.
    eye : numpy.ndarray
        The camera position.

    Returns
    -------
    numpy.ndarray
        Unit half vectors ``(P, 3)``.
    """
    return _half_vectors_kernel(sp.frag_span, sp.frag_t, np.ascontiguousarray(sp.left),
                                np.ascontiguousarray(sp.right), int(col),
                                np.asarray(vis, np.int64), np.asarray(L, np.float64),
                                np.asarray(eye, np.float64))


@njit
def _shade_kernel(ndotl, ndoth, N, pixel, tri_of, light, n_pixels):
    # light: I0, ka, kd, ks, shininess
    img = np.zeros(n_pixels, np.float64)
    mask = np.zeros(n_pixels, np.bool_)
    tri = np.full(n_pixels, -1, np.int32)     # the triangle map is int32 (MAX_FACES)
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
    coverage mask, the triangle map (-1 off the mesh) and ``|N|`` (NaN off the mesh).

    Parameters
    ----------
    ndotl, ndoth : numpy.ndarray
        ``N.L`` and ``N.H`` per visible fragment.
    N : numpy.ndarray
        The pixel normals ``(P, 3)``.
    pixel : numpy.ndarray
        Pixel index per visible fragment.
    tri_of : numpy.ndarray
        Triangle index per visible fragment.
    lighting : Lighting
        Blinn-Phong parameters.
    n_pixels : int
        Pixels of the image.

    Returns
    -------
    tuple of numpy.ndarray
        Flat ``(image, mask, triangle, |N|)`` maps of ``n_pixels``.
    """
    light = np.array([lighting.I0, lighting.ka, lighting.kd, lighting.ks, lighting.shininess],
                     np.float64)
    return _shade_kernel(np.ascontiguousarray(ndotl, np.float64),
                         np.ascontiguousarray(ndoth, np.float64),
                         np.ascontiguousarray(N, np.float64), np.asarray(pixel, np.int64),
                         np.asarray(tri_of, np.int64), light, int(n_pixels))
