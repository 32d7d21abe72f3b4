"""Rasterization of the compiled engine: the spans of :func:`chebnorm.raster.scanline.setup_spans`
(fragment lists and z-buffer for every shading mode; the row-ordered spans of the fused
``phong`` frame), the front-facing triangle gather, and ``render``'s default camera
and projection, the same bits as the numpy reference (:mod:`chebnorm.raster.scanline`).
"""

from __future__ import annotations

import math
from functools import lru_cache
from types import SimpleNamespace

import numpy as np

from ...scanline import Spans, fit_camera
from ...scanline import project as reference_project
from .jit import HAVE_NUMBA, fma, njit, prefetch, run_with_caller, threads
from .workspace import scratch, setup_buffers, span_arrays, span_buffers

# an implementation module of chebnorm.raster.engines.numba: the API is what chebnorm.raster.engines.numba exports
__all__: list[str] = []


# --------------------------------------------------------------- span set-up
@njit
def count_rows(ys, height):
    """``(r0, nrows)``: the first pixel row and the number of rows (clipped to
    ``[0, height]``) of each triangle whose corner ``y`` are ``ys (T, 3)``, pixel centres
    at ``r + 0.5`` as :func:`chebnorm.raster.scanline.setup_spans` counts them."""
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


@njit
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


@njit
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

    Parameters
    ----------
    xy : numpy.ndarray
        Screen corners ``(T, 3, 2)``.
    attrs : numpy.ndarray
        Corner attributes ``(T, 3, K)``.
    width, height : int
        The image size.

    Returns
    -------
    Spans
        The same arrays as :func:`chebnorm.raster.setup_spans`.

    Examples
    --------
    >>> import numpy as np
    >>> from chebnorm.raster import setup_spans
    >>> xy = np.array([[[1.0, 1.0], [9.0, 2.0], [3.0, 8.0]]]); at = np.ones((1, 3, 1))
    >>> a, b = fast_setup_spans(xy, at, 10, 10), setup_spans(xy, at, 10, 10)
    >>> bool((a.frag_pixel == b.frag_pixel).all() and (a.frag_t == b.frag_t).all())
    True
    """
    xy = np.ascontiguousarray(xy, dtype=np.float64)
    attrs = np.ascontiguousarray(attrs, dtype=np.float64)
    r0, nrows = count_rows(np.ascontiguousarray(xy[..., 1]), int(height))
    tri, row, c0, count, m, t0, dt, left, right = _spans_kernel(
        xy, attrs, int(width), r0, nrows, int(nrows.sum()))
    offsets, frag_span, frag_pixel, frag_t = _fragments(row, c0, count, t0, dt, int(width))
    return Spans(tri, row, c0, count, m, t0, dt, left, right, offsets, frag_span, frag_pixel,
                 frag_t)


# ----------------------------------------------------------------- z-buffer
@njit
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
    attribute column 0; finite depths).

    Parameters
    ----------
    sp : Spans
        The frame's spans (depth ``1/w`` in attribute column 0).
    n_pixels : int
        Pixels of the image.

    Returns
    -------
    numpy.ndarray
        Indices of the visible fragments, sorted by pixel.
    """
    return _zbuffer_kernel(sp.frag_span, sp.frag_pixel, sp.frag_t,
                           np.ascontiguousarray(sp.left), np.ascontiguousarray(sp.right),
                           int(n_pixels))


@njit
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
    """``sp.lerp(cols)[sel]``, compiled, without interpolating the other fragments.

    Parameters
    ----------
    sp : Spans
        The frame's spans.
    cols : sequence of int
        Attribute columns.
    sel : numpy.ndarray
        The fragments wanted.

    Returns
    -------
    numpy.ndarray
        The interpolated attributes ``(len(sel), len(cols))``.
    """
    return _lerp_kernel(sp.frag_span, sp.frag_t, np.ascontiguousarray(sp.left),
                        np.ascontiguousarray(sp.right), np.asarray(cols, np.int64),
                        np.asarray(sel, np.int64))


# --------------------------------------------------------- triangle set-up
@njit()
def _front_faces(xy, faces, cull, tri):
    """``NumpyEngine.setup``'s front-facing triangles (ids into ``tri``, room for every
    face); their number."""
    n = 0
    for i in range(faces.shape[0]):
        a, b, c = faces[i, 0], faces[i, 1], faces[i, 2]
        area = ((xy[b, 0] - xy[a, 0]) * (xy[c, 1] - xy[a, 1])
                - (xy[c, 0] - xy[a, 0]) * (xy[b, 1] - xy[a, 1]))
        keep = area < 0 if cull else area != 0
        tri[n] = i
        n += keep
    return n


@njit()
def _gather_part(pos, nrm, xy, inv_w, faces, tri, lo, hi, corners, txy, attrs, tiw, tpos, tnrm):
    """Front triangles ``lo .. hi-1`` (ids ``tri``): their corners into the flat buffers
    ``txy``, ``attrs`` and (``corners``) ``tiw``, ``tpos``, ``tnrm``."""
    for k in range(lo, hi):
        i = tri[k]
        for v in range(3):
            q = faces[i, v]
            e = 3 * k + v
            txy[2 * e] = xy[q, 0]
            txy[2 * e + 1] = xy[q, 1]
            attrs[7 * e] = inv_w[q]
            for c in range(3):
                attrs[7 * e + 1 + c] = nrm[q, c]
                attrs[7 * e + 4 + c] = pos[q, c]
    if corners:
        for e in range(3 * lo, 3 * hi):
            tiw[e] = attrs[7 * e]
            for c in range(3):
                tnrm[3 * e + c] = attrs[7 * e + 1 + c]
                tpos[3 * e + c] = attrs[7 * e + 4 + c]


def gather_setup(mesh, xy, inv_w, cull, corners=True):
    """The per-triangle arrays of ``NumpyEngine.setup``, gathered in compiled code: front
    triangle ids, ``xy (T,3,2)``, ``inv_w (T,3)``, positions and normals ``(T,3,3)``, and
    the corner attributes of :func:`~chebnorm.raster.engines.numba.frame.phong`'s spans, ``[1/w, normal, position] (T,3,7)``:
    C-contiguous views of buffers kept between frames (:func:`.workspace.setup_buffers`).

    Parameters
    ----------
    mesh : Mesh
        The mesh.
    xy : numpy.ndarray
        Projected vertices ``(V, 2)``.
    inv_w : numpy.ndarray
        ``1/w`` per vertex.
    cull : bool
        Drop back-facing triangles.
    corners : bool, optional
        Also ``inv_w``, ``pos`` and ``nrm`` (False: None for those three, copies of
        ``attrs``' columns; the fused frame reads ``attrs`` alone).

    Returns
    -------
    tuple of numpy.ndarray
        ``(tri, xy, inv_w, pos, nrm, attrs)`` as described above.
    """
    faces = np.ascontiguousarray(mesh.faces, np.int64)
    bufs = setup_buffers(len(faces))
    xy = np.ascontiguousarray(xy, np.float64)
    b_tri, b_xy, b_attrs, b_iw, b_pos, b_nrm = bufs
    n = _front_faces(xy, faces, bool(cull), b_tri)
    k = min(threads(), max(1, n // 2048))       # the gather split over the threads
    cuts = [n * q // k for q in range(k + 1)]
    data = (np.ascontiguousarray(mesh.positions, np.float64),
            np.ascontiguousarray(mesh.normals, np.float64), xy,
            np.ascontiguousarray(inv_w, np.float64), faces, b_tri)
    run_with_caller([(_gather_part, (*data, cuts[q], cuts[q + 1], bool(corners), b_xy, b_attrs,
                                     b_iw, b_pos, b_nrm)) for q in range(k)])
    if not corners:
        return (b_tri[:n], b_xy[:6 * n].reshape(n, 3, 2), None, None, None,
                b_attrs[:21 * n].reshape(n, 3, 7))
    return (b_tri[:n], b_xy[:6 * n].reshape(n, 3, 2), b_iw[:3 * n].reshape(n, 3),
            b_pos[:9 * n].reshape(n, 3, 3), b_nrm[:9 * n].reshape(n, 3, 3),
            b_attrs[:21 * n].reshape(n, 3, 7))


# ------------------------------------------------------------- span set-up
@njit(inline=True)
def span_geom(xy, i, r, width):
    """Row ``r`` of triangle ``i`` as :func:`chebnorm.raster.scanline.setup_spans` finds it: ``(c, a, pa,
    qa, sa, p, q, sb, swap, xl, xr)``, ``c`` the pixel count (0: no span), ``a`` the first
    pixel, ``sa``, ``sb`` the positions along edges ``pa -> qa`` and ``p -> q``."""
    y0, y1, y2 = xy[i, 0, 1], xy[i, 1, 1], xy[i, 2, 1]
    y = r + 0.5
    # edges (0,1), (1,2), (2,0): hit when min <= y < max; the first and last hit
    # (``&``, not ``and``: no branch to mispredict, the hit edges change from span to span)
    h0 = (min(y0, y1) <= y) & (y < max(y0, y1))
    h1 = (min(y1, y2) <= y) & (y < max(y1, y2))
    h2 = (min(y2, y0) <= y) & (y < max(y2, y0))
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


@njit(inline=True)
def _span_attrs(attrs, i, n, pa, qa, sa, p, q, sb, swap, left, right, K):
    """The ``K`` end attributes of span ``n`` (see :func:`span_write`)."""
    for k in range(K):
        va = attrs[i, pa, k] + sa * (attrs[i, qa, k] - attrs[i, pa, k])
        vb = attrs[i, p, k] + sb * (attrs[i, q, k] - attrs[i, p, k])
        left[n, k] = vb if swap else va
        right[n, k] = va if swap else vb


@njit(inline=True)
def span_write(attrs, i, r, n, c, a, pa, qa, sa, p, q, sb, swap, xl, xr, tri, row, c0, count,
                m, t0, dt, left, right):
    """Span ``n``: row ``r`` of triangle ``i`` (from :func:`span_geom`)."""
    tri[n] = i
    row[n] = r
    c0[n] = a
    count[n] = c
    K = attrs.shape[2]
    # a column count known to the compiler unrolls the loop (the frame's 7 or 4 columns)
    if K == 7:
        _span_attrs(attrs, i, n, pa, qa, sa, p, q, sb, swap, left, right, 7)
    elif K == 4:
        _span_attrs(attrs, i, n, pa, qa, sa, p, q, sb, swap, left, right, 4)
    else:
        _span_attrs(attrs, i, n, pa, qa, sa, p, q, sb, swap, left, right, K)
    ws = xr - xl
    d = 1.0 / ws
    dt[n] = d
    t0[n] = ((a + 0.5) - xl) * d
    m[n] = np.int64(max(1.0, np.ceil(ws)))


@njit()
def row_span_set(xy, attrs, ids, q0, q1, r, width, tri, row, c0, count, m, t0, dt, left, right,
                 gi, gf):
    """Row ``r``'s spans of the triangles ``ids[q0:q1]`` (in that order, those without a
    pixel dropped) into ``tri, row, ... right`` from index 0, as :func:`span_geom` finds
    and :func:`span_write` writes them, in two passes: every triangle's edges and span
    ends first (kept in the scratch ``gi``, ``(8, M)`` int64, and ``gf``, ``(4, M)``
    float64), then the spans' attributes (``attrs`` C-contiguous; the first pass asks
    for each triangle's attributes, ``jit.prefetch``).  Each pass's iterations are
    independent of each other (one long chain of dependent loads, divisions and
    roundings per triangle otherwise).  Returns ``(spans, fragments)``."""
    n = 0
    nfrag = 0
    for q in range(q0, q1):
        i = ids[q]
        # the attributes the second pass reads, asked for now (a triangle's first row
        # finds them in the last-level cache at best)
        na = 3 * attrs.shape[2]
        for e in range(0, na, 8):
            prefetch(attrs, i * na + e)
        prefetch(attrs, i * na + na - 1)
        c, a, pa, qa, sa, p, qq, sb, swap, xl, xr = span_geom(xy, i, r, width)
        gi[0, n], gi[1, n], gi[2, n], gi[3, n] = i, c, a, pa
        gi[4, n], gi[5, n], gi[6, n], gi[7, n] = qa, p, qq, swap
        gf[0, n], gf[1, n], gf[2, n], gf[3, n] = sa, sb, xl, xr
        nfrag += c
        n += c > 0
    for k in range(n):
        span_write(attrs, gi[0, k], r, k, gi[1, k], gi[2, k], gi[3, k], gi[4, k], gf[0, k],
                   gi[5, k], gi[6, k], gf[1, k], gi[7, k] != 0, gf[2, k], gf[3, k], tri, row,
                   c0, count, m, t0, dt, left, right)
    return n, nfrag


@njit()
def row_buckets(r0, nrows, height):
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


@njit(inline=True)
def _ceil_div(a, b):
    """``ceil(a / b)`` for ``a >= 0``, ``b >= 1`` (a shift for 1 and 2 threads: an integer
    division per triangle costs more than the rest of its row count)."""
    if b == 1:
        return a
    if b == 2:
        return (a + 1) >> 1
    return (a + b - 1) // b


@njit()
def part_buckets(xy, height, part, parts):
    """:func:`row_buckets` of the rows ``part, part + parts, ...`` alone (a thread's rows
    of the frame), from the screen corners ``xy (T, 3, 2)`` (rows as :func:`count_rows`
    finds them): ``(first, ids, widest)``, the ``j``-th of those rows' triangles
    ``ids[first[j]:first[j+1]]`` in triangle order, ``widest`` the most triangles of a
    row.  Each thread finds its own rows' triangles: no serial pass over the frame."""
    T = xy.shape[0]
    nj = max((height - part + parts - 1) // parts, 0)
    first = np.zeros(nj + 1, np.int64)
    lo = np.empty(T, np.int64)
    hi = np.empty(T, np.int64)
    for i in range(T):
        y0, y1, y2 = xy[i, 0, 1], xy[i, 1, 1], xy[i, 2, 1]
        a = min(max(np.ceil(min(y0, y1, y2) - 0.5), 0.0), float(height))
        b = min(max(np.ceil(max(y0, y1, y2) - 0.5), 0.0), float(height))
        r0 = np.int64(a)
        r1 = max(np.int64(b), r0)
        # the first of this thread's rows at or after r0, and past the last one before r1
        j0 = _ceil_div(r0 - part, parts) if r0 > part else 0
        j1 = _ceil_div(r1 - part, parts) if r1 > part else 0
        lo[i] = j0
        hi[i] = j1
    # the rows' triangle counts as differences (two updates a triangle, not one a row:
    # neighbouring triangles share rows, and each update waits on the one before), then
    # summed into the counts and those into the buckets' starts
    for i in range(T):
        first[lo[i]] += 1
        first[hi[i]] -= 1
    widest = 0
    count = 0
    start = 0
    for j in range(nj):
        count += first[j]
        first[j] = start
        start += count
        widest = max(widest, count)
    first[nj] = start
    fill = first[:-1].copy()
    ids = np.empty(first[nj], np.int64)
    for i in range(T):
        for j in range(lo[i], hi[i]):
            ids[fill[j]] = i
            fill[j] += 1
    return first, ids, widest


# --------------------------------------------------------------- row spans
@njit()
def _row_geom_part(xy, width, first, ids, rlo, rhi, row_n, gc):
    """Rows ``rlo .. rhi-1`` of :func:`row_spans`: the pixel count ``gc`` of every (row,
    triangle) pair ``q`` of the row buckets (:func:`span_geom`) and each row's number of
    spans into ``row_n[r + 1]``.  Only the counts are kept: the write pass computes the
    geometry again (the same function, so the same bits), cheaper than writing and
    reading it back (56 bytes a pair)."""
    for r in range(rlo, rhi):
        n = 0
        for q in range(first[r], first[r + 1]):
            c = span_geom(xy, ids[q], r, width)[0]
            gc[q] = c
            n += c > 0
        row_n[r + 1] = n


@njit()
def _row_write_part(xy, width, attrs, first, ids, rlo, rhi, row_start, gc, tri, row, c0,
                    count, m, t0, dt, left, right):
    """Rows ``rlo .. rhi-1``: the spans of the pairs :func:`_row_geom_part` counted
    (:func:`span_geom`, :func:`span_write`), row ``r``'s from ``row_start[r]`` on."""
    for r in range(rlo, rhi):
        n = row_start[r]
        for q in range(first[r], first[r + 1]):
            if gc[q] <= 0:
                continue
            i = ids[q]
            c, a, pa, qa, sa, p, qq, sb, swap, xl, xr = span_geom(xy, i, r, width)
            span_write(attrs, i, r, n, c, a, pa, qa, sa, p, qq, sb, swap, xl, xr, tri, row,
                       c0, count, m, t0, dt, left, right)
            n += 1


def row_spans(xy, attrs, width, height, work=None):
    """The spans of :func:`chebnorm.raster.scanline.setup_spans` without the fragment
    arrays, numbered row by row: ``(namespace of tri, row, x0, count, m, t0, dt, left,
    right, row_start, by_row)``; row ``r``'s spans are ``row_start[r] ..
    row_start[r+1]-1``, in ``setup_spans``' order within the row (so ties of the z-test
    still go to the earliest fragment), ``by_row`` the identity.  A frame reads each
    span's data once per row: in this order the reads are sequential.  The count pass
    keeps only each (row, triangle) pair's pixel count, the write pass computes the
    pair's geometry again (less memory traffic than keeping it); with ``work`` (a
    :class:`.workspace.Workspace`, for the counts) the spans
    are views of this thread's :func:`.workspace.span_buffers`, valid until its next
    such call.  ``tests/raster_oracles.py`` holds the pair-by-pair oracle.

    Parameters
    ----------
    xy : numpy.ndarray
        Screen corners ``(T, 3, 2)``.
    attrs : numpy.ndarray
        Corner attributes ``(T, 3, K)``.
    width, height : int
        The image size.
    work : Workspace, optional
        Scratch arrays for the geometry.

    Returns
    -------
    types.SimpleNamespace
        The span arrays listed above.

    Examples
    --------
    >>> from chebnorm.raster.scanline import setup_spans
    >>> xy = np.array([[[0.0, 0.0], [8.0, 0.0], [0.0, 6.0]], [[1.0, 0.5], [7.0, 1.5], [2.0, 5.0]]])
    >>> a, b = row_spans(xy, np.ones((2, 3, 1)), 8, 6), setup_spans(xy, np.ones((2, 3, 1)), 8, 6)
    >>> o = np.lexsort((a.row, a.tri))     # a's spans in setup_spans' order
    >>> bool((np.diff(a.row) >= 0).all() and (a.t0[o] == b.t0).all() and (a.x0[o] == b.x0).all())
    True
    """
    xy = np.ascontiguousarray(xy, dtype=np.float64)
    attrs = np.ascontiguousarray(attrs, dtype=np.float64)
    height = int(height)
    r0, nrows = count_rows(np.ascontiguousarray(xy[..., 1]), height)
    first, ids = row_buckets(r0, nrows, height)
    Kc = attrs.shape[2]
    P = int(first[-1])
    # row ranges of about equal numbers of (row, triangle) pairs
    k = threads()
    cuts = [0] + [int(np.searchsorted(first, first[-1] * q / k)) for q in range(1, k)] + [height]
    parts = [(cuts[q], cuts[q + 1]) for q in range(k) if cuts[q] < cuts[q + 1]]
    row_start = scratch(work, "row_start", height + 1, np.int64)
    row_start[0] = 0
    gc = scratch(work, "gc", P, np.int64)
    run_with_caller([(_row_geom_part, (xy, int(width), first, ids, lo, hi, row_start, gc))
                     for lo, hi in parts])
    np.cumsum(row_start, out=row_start)
    S = int(row_start[-1])
    out = span_arrays(S, Kc) if work is None else span_buffers(S, Kc)
    run_with_caller([(_row_write_part, (xy, int(width), attrs, first, ids, lo, hi, row_start,
                                        gc, *out)) for lo, hi in parts])
    tri, row, c0, count, m, t0, dt, left, right = out
    return SimpleNamespace(tri=tri, row=row, x0=c0, count=count, m=m, t0=t0, dt=dt, left=left,
                           right=right, row_start=row_start, by_row=_identity(S))


#: the identity permutation of the longest frame so far (``by_row`` of row spans)
_IDENTITY = [np.arange(0, dtype=np.int64)]


def _identity(S):
    """``np.arange(S)`` (read only), a view of one kept array."""
    if len(_IDENTITY[0]) < S:
        a = np.arange(S + S // 4, dtype=np.int64)
        a.flags.writeable = False
        _IDENTITY[0] = a
    return _IDENTITY[0][:S]


# -------------------------------------------------------------- projection
@njit()
def _project(pts, eye, frame, fa, f, width, height, xy, inv_w):
    """:func:`chebnorm.raster.scanline.project` of ``pts (V, 3)``: ``(pts - eye) @ frame.T`` summed as
    OpenBLAS does (``fma(d2, F2, fma(d1, F1, d0 F0))``, checked by :func:`_gemm_fma`),
    then the reference's divisions; False if a point is not in front of the camera."""
    ok = True
    for i in range(pts.shape[0]):
        d0, d1, d2 = pts[i, 0] - eye[0], pts[i, 1] - eye[1], pts[i, 2] - eye[2]
        p0 = fma(d2, frame[0, 2], fma(d1, frame[0, 1], d0 * frame[0, 0]))
        p1 = fma(d2, frame[1, 2], fma(d1, frame[1, 1], d0 * frame[1, 0]))
        p2 = fma(d2, frame[2, 2], fma(d1, frame[2, 1], d0 * frame[2, 0]))
        w = -p2
        if w <= 1e-9:
            ok = False
        xy[i, 0] = ((fa * p0 / w) + 1) * 0.5 * width
        xy[i, 1] = (1 - (f * p1 / w)) * 0.5 * height
        inv_w[i] = 1.0 / w
    return ok


@lru_cache(maxsize=None)
def _gemm_fma() -> bool:
    """Whether numpy's ``(V, 3) @ (3, 3)`` sums as :func:`_project` does on this machine
    (random matrices of several sizes; one row goes elsewhere in numpy)."""
    if not HAVE_NUMBA:
        return False
    rng = np.random.default_rng(20261125)
    for n in (2, 3, 5, 8, 17, 100, 1001, 4099, 14112, 50000):
        pts, eye = rng.standard_normal((n, 3)), rng.standard_normal(3)
        frame = rng.standard_normal((3, 3))
        xy, inv_w = np.empty((n, 2)), np.empty(n)
        _project(pts, eye, frame, 1.0, 1.0, 2, 2, xy, inv_w)
        pc = (pts - eye) @ frame.T
        w = -pc[..., 2]
        ref = np.stack([(1.0 * pc[..., 0] / w + 1) * 0.5 * 2, (1 - 1.0 * pc[..., 1] / w) * 0.5 * 2],
                       -1)
        if (1.0 / w).tobytes() != inv_w.tobytes() or ref.tobytes() != xy.tobytes():
            return False
    return True


def project(camera, points, width, height):
    """:func:`chebnorm.raster.scanline.project` (the same bits and errors), compiled where
    :func:`_gemm_fma` holds.

    Parameters
    ----------
    camera : Camera
        The view.
    points : numpy.ndarray
        World points ``(..., 3)``.
    width, height : int
        The image size.

    Returns
    -------
    xy : numpy.ndarray
        Screen coordinates ``(..., 2)``.
    inv_w : numpy.ndarray
        ``1/w`` per point.

    Raises
    ------
    ValueError
        If a point is not in front of the camera.

    Examples
    --------
    >>> from chebnorm.raster.scanline import default_camera, project as ref
    >>> cam = default_camera((0.0, 0.0, 0.0), 1.0)
    >>> p = np.random.default_rng(1).standard_normal((50, 3)) * 0.3
    >>> all(a.tobytes() == b.tobytes() for a, b in zip(project(cam, p, 64, 48),
    ...                                                  ref(cam, p, 64, 48)))
    True
    """
    pts = np.asarray(points, float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 2 or not _gemm_fma():
        return reference_project(camera, points, width, height)
    frame = camera.frame()
    f = 1.0 / math.tan(camera.fov_y / 2)
    fa = f / (width / height)
    xy, inv_w = np.empty((len(pts), 2)), np.empty(len(pts))
    if not _project(np.ascontiguousarray(pts), np.asarray(camera.eye, float),
                    np.ascontiguousarray(frame), float(fa), float(f), float(width),
                    float(height), xy, inv_w):
        return reference_project(camera, points, width, height)
    return xy, inv_w


# ------------------------------------------------------------------ camera
#: {(width, height): (positions, camera)}: the default cameras of recent meshes
_CAMERAS: dict = {}


@njit()
def _same_bits(a, b):
    """Whether two int64 views hold the same bits."""
    if a.shape[0] != b.shape[0]:
        return False
    for i in range(a.shape[0]):
        if a[i] != b[i]:
            return False
    return True


def default_camera_of(positions, width, height):
    """``fit_camera(positions, width, height)``, remembered for the last few position
    arrays by value (a copy of the positions is kept and compared bit for bit).

    Parameters
    ----------
    positions : numpy.ndarray
        Vertex positions ``(V, 3)``.
    width, height : int
        The image size.

    Returns
    -------
    Camera
        The fitted camera.
    """
    pos = np.ascontiguousarray(positions, np.float64)
    key = (int(width), int(height))
    hit = _CAMERAS.get(key)
    if hit is not None and hit[0].shape == pos.shape and _same_bits(
            hit[0].reshape(-1).view(np.int64), pos.reshape(-1).view(np.int64)):
        return hit[1]
    cam = fit_camera(pos, width, height)
    if len(_CAMERAS) >= 8:
        _CAMERAS.clear()
    _CAMERAS[key] = (pos.copy(), cam)
    return cam
