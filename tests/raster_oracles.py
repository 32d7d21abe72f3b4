"""Test-only oracles of the compiled engine's span set-up: the spans of
:func:`chebnorm.raster.scanline.setup_spans` without fragment arrays, numbered per
triangle (:func:`spans`) or per row (:func:`row_spans`), computed pair by pair with the
engine's :func:`span_geom` and :func:`span_write`.  The engine's own
:func:`chebnorm.raster.engines.numba.rasterize.row_spans` (geometry kept between its
passes, workspace arrays) is checked against them."""

from types import SimpleNamespace

import numpy as np

from chebnorm.raster.engines.numba.jit import njit, run, threads
from chebnorm.raster.engines.numba.rasterize import count_rows, row_buckets, span_geom, span_write
from chebnorm.raster.engines.numba.workspace import span_arrays, span_buffers


@njit(inline=True)
def _span_at(xy, attrs, width, i, r, n, write, tri, row, c0, count, m, t0, dt, left, right):
    """Row ``r`` of triangle ``i``: 1 if it is a span (written as span ``n`` when
    ``write``), else 0."""
    c, a, pa, qa, sa, p, q, sb, swap, xl, xr = span_geom(xy, i, r, width)
    if c <= 0:
        return 0
    if write:
        span_write(attrs, i, r, n, c, a, pa, qa, sa, p, q, sb, swap, xl, xr, tri, row, c0,
                    count, m, t0, dt, left, right)
    return 1


@njit()
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


@njit()
def _row_spans_part(xy, attrs, width, first, ids, rlo, rhi, write, row_start, tri, row, c0,
                    count, m, t0, dt, left, right):
    """:func:`_spans_part` row by row, rows ``rlo .. rhi-1`` (the triangles of each row
    from :func:`row_buckets`): with ``write`` False, each row's number of spans into
    ``row_start[r + 1]``; with ``write`` True, the spans from ``row_start[r]`` on."""
    for r in range(rlo, rhi):
        n = row_start[r] if write else 0
        for q in range(first[r], first[r + 1]):
            n += _span_at(xy, attrs, width, ids[q], r, n, write, tri, row, c0, count, m, t0,
                          dt, left, right)
        if not write:
            row_start[r + 1] = n


@njit()
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


def spans(xy, attrs, width, height):
    """The spans of :func:`.spans.setup_spans` without the fragment arrays, and the
    spans of each row: ``(namespace of tri, row, x0, count, m, t0, dt, left, right,
    row_start, by_row)``; row ``r``'s spans are ``by_row[row_start[r]:row_start[r+1]]``
    (in span order)."""
    xy = np.ascontiguousarray(xy, dtype=np.float64)
    attrs = np.ascontiguousarray(attrs, dtype=np.float64)
    r0, nrows = count_rows(np.ascontiguousarray(xy[..., 1]), int(height))
    T = len(nrows)
    Kc = attrs.shape[2]
    parts = _parts(nrows, threads())
    nvalid = np.zeros(T, np.int64)
    z1, z2 = np.zeros(1, np.int64), np.zeros((1, Kc))
    fixed = (xy, attrs, int(width), r0, nrows)
    run([(_spans_part, (*fixed, lo, hi, False, nvalid, nvalid, z1, z1, z1, z1, z1, z2[0], z2[0],
                         z2, z2)) for lo, hi in parts])
    start = np.cumsum(nvalid) - nvalid
    S = int(nvalid.sum())
    out = (np.empty(S, np.int64), np.empty(S, np.int64), np.empty(S, np.int64),
           np.empty(S, np.int64), np.empty(S, np.int64), np.empty(S), np.empty(S),
           np.empty((S, Kc)), np.empty((S, Kc)))
    run([(_spans_part, (*fixed, lo, hi, True, nvalid, start, *out)) for lo, hi in parts])
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


def row_spans(xy, attrs, width, height, reuse=False):
    """The spans of :func:`spans`, numbered row by row: row ``r``'s are
    ``row_start[r] .. row_start[r+1]-1``, in their :func:`spans` order (so ties of the
    z-test still go to the earliest fragment), ``by_row`` the identity. A frame reads
    each span's data once per row: in this order the reads are sequential instead of
    scattered over every triangle's spans (a third of the frame's time at 1024x1024).
    The :func:`spans` numbering is the order of ``(tri, row)``. ``reuse``: the arrays are
    views of this thread's :func:`span_buffers`, valid until its next ``reuse`` call.

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
    r0, nrows = count_rows(np.ascontiguousarray(xy[..., 1]), height)
    first, ids = row_buckets(r0, nrows, height)
    Kc = attrs.shape[2]
    # row ranges of about equal numbers of (row, triangle) pairs
    k = threads()
    cuts = [0] + [int(np.searchsorted(first, first[-1] * q / k)) for q in range(1, k)] + [height]
    parts = [(cuts[q], cuts[q + 1]) for q in range(k) if cuts[q] < cuts[q + 1]]
    row_start = np.zeros(height + 1, np.int64)
    z1, z2 = np.zeros(1, np.int64), np.zeros((1, Kc))
    fixed = (xy, attrs, int(width), first, ids)
    run([(_row_spans_part, (*fixed, lo, hi, False, row_start, z1, z1, z1, z1, z1, z2[0], z2[0],
                             z2, z2)) for lo, hi in parts])
    np.cumsum(row_start, out=row_start)
    S = int(row_start[-1])
    out = span_buffers(S, Kc) if reuse else span_arrays(S, Kc)
    run([(_row_spans_part, (*fixed, lo, hi, True, row_start, *out)) for lo, hi in parts])
    tri, row, c0, count, m, t0, dt, left, right = out
    return SimpleNamespace(tri=tri, row=row, x0=c0, count=count, m=m, t0=t0, dt=dt, left=left,
                           right=right, row_start=row_start, by_row=np.arange(S, dtype=np.int64))
