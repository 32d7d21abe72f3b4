"""The fused, parallel ``phong`` frame of the compiled engine: visibility per scan line,
then deferred shading.

The numpy engine (:mod:`chebnorm.raster.engines.numpy`) is the reference and the
compiled engine's step-by-step path (:mod:`~chebnorm.raster.engines.numba.rasterize`, :mod:`~chebnorm.raster.engines.numba.kernels`) its twin
operation by operation; this module computes the same ``phong`` frame, byte for byte,
without the full-frame intermediate arrays of those two paths (fragment lists, a
frame-sized z-buffer, per-fragment normals, half vectors and dot products):

1. triangle set-up and span set-up, compiled, the spans split over threads
   (:func:`.rasterize.row_spans`, the arithmetic of :func:`chebnorm.raster.scanline.setup_spans`);
2. the method's checks and per-span set-up, the values and errors of
   :func:`chebnorm.methods.span_normals`'s, compiled and split over threads in
   :mod:`.setup` (the reference functions run where a check fails; sine, cosine
   and arc cosine with the bits of :mod:`chebnorm.methods.detmath`, see
   :func:`.calibration.det`);
3. one pass per scan line, rows split across the cores (threads running the compiled
   kernels without the GIL, rows interleaved): a z-test of the
   line's spans in span order into a line buffer (the winning span of every pixel,
   ties to the earliest fragment as in :func:`chebnorm.raster.scanline.zbuffer`), then each
   span's pixel normals by the method's kernel (stepping kernels step through every
   pixel of the span, the others are evaluated only where the span won) and, for the
   winners only, half vector, Blinn-Phong intensity, ``|N|`` and the triangle id,
   into the line's own maps (in the cache), which are then streamed to the frame's
   (:func:`_stream_row`: non-temporal stores, so a map line is written without first
   being read; the frame's 25 bytes a pixel are its largest memory traffic).

In float64 (and for the linear methods in float32 too) the three steps run row by row
instead (:func:`_frame_rows`): each thread builds a scan line's spans, their checks and
the method's set-up in row-sized arrays and draws the line at once, so no frame-sized
span array is written or read. What the set-up needs from the whole frame (the table
of the dichotomy and the quadratic, chosen by the widest span; whether a span starts
past its left end; whether a span has two pixels; the dichotomy's depths off the dyadic
grid) is assumed and checked once every row is done; where an assumption fails, the
frame is drawn again by steps 1-3 (the table assumed is the last such frame's, so this
happens on the first frame of a kind).

Every float operation is the reference's, in its order and dtype (no ``fastmath``).
The library reductions (``N @ L``, ``einsum``, ``norm``) are summed in the orders
:func:`.calibration.calibrated` found; :func:`supports` says whether the frame can
promise the reference's bytes for a method, and :func:`phong` raises
:class:`chebnorm.raster.engines.base.FrameUnsupported` when a frame turns out not to
(then the caller takes the step-by-step path).
"""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np

from chebnorm.methods import detmath
from chebnorm.methods import kernels as K
from chebnorm.methods.registry import method_kernel
from chebnorm.methods.spans import MAX_LEVELS, check_dtype, span_levels

from ..base import FrameUnsupported, ModeResult, auto_tables, triangle_half_vectors
from .calibration import (DetOps, calibrated, dot3, dot3_select, ends_orders, f32_round,
                          pow_calibrated, powers, sin_small, trig_calibrated)
from .jit import (HAVE_NUMBA, njit, objmode, run, run_with_caller, store_fence, stream16,
                  threads, unowned)
from .kernels import dichotomy_denominators_into
from .rasterize import part_buckets, row_span_set, row_spans
from .setup import (DEPTH_THRESHOLDS, angular_part, clear_table, cos_range, ends_part,
                    quadratic_part, slerp_part, end_checks, levels_calibrated, method_setup,
                    setup_consts, span_input, span_level_libm, widest_dot)
from .workspace import give, keep_maps, output_maps, scratch, take

# an implementation module of chebnorm.raster.engines.numba: the API is what chebnorm.raster.engines.numba exports
__all__: list[str] = []


#: kernel -> mode number of the fused kernel
MODES = {id(K.NONE): 0, id(K.EXACT): 1, id(K.NEWTON): 2, id(K.LYON): 3, id(K.SLERP): 4,
         id(K.QUADRATIC): 5, id(K.ANGULAR): 6, id(K.DICHOTOMY): 7}


# ------------------------------------------------------------ dichotomy prep
@njit()
def _dichotomy_prep(nl, nr, levels, coeffs, exact, kc, t0, dt, count, Lmax, r):
    """Per-span denominators of every level into ``r`` (``(S, max(Lmax, 1))``, ``Lmax``
    the deepest level) and, per depth, whether any pixel of any span is off the dyadic
    grid (then every pixel of that depth is picked), as the dichotomy kernel of
    :mod:`.kernels` computes them."""
    dichotomy_denominators_into(nl, nr, levels, coeffs, exact, kc, r)
    off = np.zeros(Lmax + 1, np.bool_)
    _off_grid(levels, kc, t0, dt, count, np.empty(1, nl.dtype), off)
    return off


def _span_level(dt, t0, count, cos):
    """The reference's dichotomy depth of one span (:func:`chebnorm.methods.spans.span_levels`,
    the C library's ``log2`` and ``arccos``), for :func:`_reference_level`."""
    return int(span_levels(np.array([dt]), np.array([t0]), np.array([count], np.int64),
                           np.array([cos]))[0])


@njit(nogil=False)
def _reference_level(dt, t0, count, cos):
    """:func:`_span_level` from compiled code (the interpreter, under the GIL: a span whose
    ``log2(1/dt)`` is near an integer or whose cosine is near a depth threshold, a few
    per frame)."""
    with objmode(lv="int64"):
        lv = _span_level(dt, t0, count, cos)
    return lv


@njit()
def _off_grid(levels, kc, t0, dt, count, tcb, off):
    """``off[L]`` set where a pixel of a span of depth ``L`` (spans ``0 .. len(levels)-1``)
    is off the dyadic grid of that depth (``t`` in the dtype of ``tcb``, its scratch;
    depths already set are not looked at again)."""
    for i in range(levels.shape[0]):
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


# ---------------------------------------------------------------- shading
@njit(inline=True)
def _half(p0, p1, p2, e0, e1, e2, l0, l1, l2, order):
    """``_unit(L + _unit(eye - P))`` (:func:`chebnorm.raster.engines.base.half_vectors`; ``|v|`` as
    ``np.linalg.norm`` sums, ``order``)."""
    v0, v1, v2 = e0 - p0, e1 - p1, e2 - p2
    r = np.sqrt(dot3(v0, v1, v2, v0, v1, v2, order))
    v0, v1, v2 = v0 / r, v1 / r, v2 / r
    h0, h1, h2 = l0 + v0, l1 + v1, l2 + v2
    r = np.sqrt(dot3(h0, h1, h2, h0, h1, h2, order))
    return h0 / r, h1 / r, h2 / r


@njit(inline=True)
def _intensity(N0, N1, N2, h0, h1, h2, l0, l1, l2, order_l, order_h, I0, ka, kd, ks, sh):
    """``Lighting.intensity(N @ L, _dot(N, H))`` clipped to [0, 1] (``N @ L`` and the
    einsum summed in their calibrated orders)."""
    a = dot3(N0, N1, N2, l0, l1, l2, order_l)
    b = dot3(N0, N1, N2, h0, h1, h2, order_h)
    a = a if (a >= 0.0 or a != a) else 0.0      # np.maximum(a, 0.0)
    b = b if (b >= 0.0 or b != b) else 0.0
    # numpy squares for the exponent 2 (its fast scalar power), calls pow otherwise
    v = I0 * (ka + kd * a + ks * (b * b if sh == 2.0 else b ** sh))
    if v < 0.0:
        v = 0.0
    elif v > 1.0:
        v = 1.0
    return v


@njit()
def _row_visibility(width, k0, k1, c0, count, t0, dt, left, right, bw, bs, tx):
    """The winning span of each pixel of a row in ``bs`` (spans ``k0 .. k1-1``, the row's
    in ``setup_spans``' order: largest ``1/w``, ties to the earliest span; -1: none) and
    its ``t`` (unclipped, float64) in ``tx``, over the row's covered range ``[xlo,
    xhi)``, which it returns (``bs`` and ``tx`` are not written outside it; ``xlo >=
    xhi``: no span)."""
    xlo = width
    xhi = 0
    for s in range(k0, k1):
        xlo = min(xlo, c0[s])
        xhi = max(xhi, c0[s] + count[s])
    bv = bs[xlo:max(xhi, xlo)]     # a view from 0: a plain fill (no negative-index check)
    for x in range(bv.shape[0]):
        bv[x] = -1
    for s in range(k0, k1):
        lo = left[s, 0]
        dw = right[s, 0] - lo
        a = t0[s]
        d = dt[s]
        x0 = c0[s]
        for j in range(count[s]):
            # j (below 2**31: at most the width) through int32, which converts to float64
            # four lanes at a time (an int64 one lane at a time); the same value
            tu = a + np.float64(np.int32(j)) * d
            t = min(max(tu, 0.0), 1.0)
            w = lo + t * dw
            x = np.uint64(x0 + j)    # unsigned: no negative-index wrap-around in the loop
            win = (bs[x] < 0) | (w > bw[x])    # selects, not branches (bw[x] unset where
            bs[x] = s if win else bs[x]        # bs[x] < 0: the ``|`` makes it moot)
            bw[x] = w if win else bw[x]
            tx[x] = tu if win else tx[x]
    return xlo, xhi


@njit()
def _row_background(tri_map, nlen, base, width, want):
    """The background of a row's extra maps (-1, NaN; overwritten where a fragment lands):
    the triangle map where ``want & 1``, the ``|N|`` map where ``want & 2``."""
    if want & 1:
        trow = tri_map[base:base + width]     # row views: a plain fill (no index checks)
        for x in range(width):
            trow[x] = -1
    if want & 2:
        nrow = nlen[base:base + width]
        for x in range(width):
            nrow[x] = np.nan


@njit()
def _row_winners(bs, tx, xlo, xhi, wx, ws, tc, wt, width, img, mask, base):
    """The covered pixels of a row in ``x`` order (``wx``) with their spans (``ws``),
    their ``t`` in the dtype (``tc``: the reference's ``t.astype(dtype)``) and clipped to
    [0, 1] in float64 (``wt``), from :func:`_row_visibility`'s ``bs``, ``tx`` over its
    range ``[xlo, xhi)``; their number.  Also the row's image background (0, overwritten
    where a fragment lands) and its mask (``bs[x] >= 0``, False outside the range) from
    offset ``base``.  Branch-free: every ``x`` of the range is written, the count
    advances where ``bs[x] >= 0`` (``wx``, ``ws``, ``tc``, ``wt`` have room for the whole
    row)."""
    irow = img[base:base + width]      # row views: indices known >= 0 (a plain fill)
    mrow = mask[base:base + width]
    for x in range(width):
        irow[x] = 0.0
        mrow[x] = False
    nw = 0
    for x in range(xlo, xhi):
        s = bs[x]
        wx[nw] = x
        ws[nw] = s
        wt[nw] = tx[x]
        mrow[x] = s >= 0
        nw += s >= 0
    for k in range(nw):
        tu = wt[k]
        tc[k] = tu                       # the reference's t.astype(dtype)
        wt[k] = min(max(tu, 0.0), 1.0)
    return nw


@njit(inline=True)
def _linear(mode, a0, a1, a2, d0, d1, d2, t, k0, k1, k2, k3, k4):
    """``N_l + t (N_r - N_l)`` normalized by mode 1 (``N/sqrt(N.N)``), 2 (Newton) or 3
    (Lyon), or not (0), as the linear kernel of :mod:`.kernels` (constants ``k`` in the dtype)."""
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


@njit(inline=True)
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


# ---------------------------------------------------------------- shading rows
@njit(inline=True)
def _clamp0(a):
    """``np.maximum(a, 0.0)`` (NaN kept)."""
    return a if (a >= 0.0 or a != a) else 0.0


@njit()
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


@njit()
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


@njit()
def _row_buffers(width, A, mode):
    """A thread's scratch rows for :func:`_row_pass` (``A``: an array in the method's
    dtype): ``(bw, bs, wx, ws, wt, tc, ga, sx, n0, n1, n2, h0, h1, h2, av, bv, nl, pw, hh,
    ll, ok, skip, nd, sab, sw)``."""
    W = width
    return (np.empty(W), np.empty(W, np.int64), np.empty(W, np.int64), np.empty(W, np.int64),
            np.empty(W), np.empty(W, A.dtype), np.empty((6, W), A.dtype),
            np.empty((3, W), A.dtype), np.empty(W), np.empty(W), np.empty(W), np.empty(W),
            np.empty(W), np.empty(W), np.empty(W), np.empty(W), np.empty(W), np.empty(W),
            np.empty(W), np.empty(W), np.empty(W, np.bool_), np.zeros(W, np.bool_),
            np.empty((3, _TREE_MAX + 1), A.dtype), np.empty(2, A.dtype),
            np.empty((9, W) if mode == 4 else (9, 1)))


@njit(inline=True)
def _row_pass(rr, width, k0, k1, mode, spans, meth, shade, is64, per_pixel_h, want, maps, stop,
              buf):
    """Row ``rr`` of the maps ``maps`` from the row's spans ``k0 .. k1-1`` (in
    ``setup_spans``' order; the frame loops pass row 0 of one line's maps, streamed to
    the frame's afterwards): the z-test (:func:`_row_visibility`), the background and
    the winners listed in ``x`` order (:func:`_row_winners`), then each quantity of the
    shading for all of them in one loop (gathers first, then loops of arithmetic alone,
    which LLVM vectorizes: ``sqrt`` and division are correctly rounded in every lane, so
    the bits are the scalar ones).
    Returns ``(covered pixels, slerp float32 pixels whose sine needs detmath)``.

    ``stop`` (profiling only, :func:`stage_times`): 0 draws the row; 1, 2, 3 stop after
    its visibility and background, its normals, its half vectors.

    Inlined into its callers (numba's IR), with its arrays in tuples (``spans``: ``(stri,
    c0, count, t0, dt, left, right)``, ``meth``: ``(A, B, C, sc, sc2, levels, R, off, kc,
    kd)``, ``shade``: ``(face_id, Htri, L, eye, light, orders)``, ``maps``: ``(img, mask,
    tri_map, nlen)``) made once per frame: no call per row for itself.  The kernels it
    calls are not inlined; its callers hand it views that count no references
    (:func:`.jit.unowned`), so those calls do no atomic operations on reference counts
    both threads share."""
    stri, c0, count, t0, dt, left, right = spans
    A, B, C, sc, sc2, levels, R, off, kc, kd = meth
    face_id, Htri, L, eye, light, orders = shade
    img, mask, tri_map, nlen = maps
    (bw, bs, wx, ws, wt, tc, ga, sx, n0, n1, n2, h0, h1, h2, av, bv, nl, pw, hh, ll, ok, skip,
     nd, sab, sw) = buf
    W = width
    base = rr * W
    xlo, xhi = _row_visibility(W, k0, k1, c0, count, t0, dt, left, right, bw, bs, av)
    nw = _row_winners(bs, av, xlo, xhi, wx, ws, tc, wt, W, img, mask, base)
    if want:
        _row_background(tri_map, nlen, base, W, want)
    if nw == 0:
        return 0, 0
    if stop == 1:
        return nw, 0
    hard = 0
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
        _step_row(mode, k0, k1, c0, count, A, B, C, sc, bs, sx, wx, n0, n1, n2, nw)
    elif mode == 4:
        hard = _slerp_row(ws, tc, A, B, sc, sc2, kc, is64, light[6] != 0.0, sw, ok, sab, skip,
                          n0, n1, n2, nw)
    else:
        _dichotomy_row(ws, tc, count, A, B, R, levels, off, kd, nd, n0, n1, n2, nw)
    if stop == 2:
        return nw, hard
    # half vectors
    if per_pixel_h:
        for k in range(nw):
            s = ws[k]
            t = wt[k]
            q0, q1, q2 = left[s, 4], left[s, 5], left[s, 6]
            h0[k] = q0 + t * (right[s, 4] - q0)
            h1[k] = q1 + t * (right[s, 5] - q1)
            h2[k] = q2 + t * (right[s, 6] - q2)
        _half_row(h0, h1, h2, eye[0], eye[1], eye[2], L[0], L[1], L[2], nw, orders[2])
    else:
        _tri_half_row(ws, stri, Htri, h0, h1, h2, nw)
    if stop == 3:
        return nw, hard
    _light_row(base, n0, n1, n2, h0, h1, h2, L, light, orders, wx, ws, stri, face_id, av, bv,
               nl, pw, hh, ll, ok, skip, hard, img, tri_map, nlen, want, nw)
    return nw, hard


@njit()
def _frame(width, height, mode, row_start, stri, c0, count, t0, dt, left, right, A, B, C, sc,
           sc2, levels, R, off, kc, kd, is64, face_id, per_pixel_h, Htri, L, eye, light, orders,
           want, part, parts, img, mask, tri_map, nlen, stop):
    """The visibility and shading passes over the frame's spans (numbered row by row,
    row ``r``'s ``row_start[r] .. row_start[r+1]-1``), one scan line at a time
    (:func:`_row_pass`), on the rows ``part, part + parts, ...`` (threads run the parts at
    once: each writes every pixel of its own rows of the output maps, the background where
    no fragment lands: 0, False, -1, NaN; the triangle map only where ``want & 1``, the
    ``|N|`` map only where ``want & 2``). Returns the number of slerp float32 pixels whose
    sine needs :mod:`detmath` (marked ``-2 - span`` in the triangle map)."""
    buf_own = _row_buffers(width, A, mode)
    buf = unowned(buf_own)     # views that count no references (as in _frame_rows)
    spans = unowned((stri, c0, count, t0, dt, left, right))
    meth = unowned((A, B, C, sc, sc2, levels, R, off, kc, kd))
    shade = unowned((face_id, Htri, L, eye, light, orders))
    img, mask, tri_map, nlen = unowned((img, mask, tri_map, nlen))
    # the row's maps, drawn here and then streamed to the frame's (as in _frame_rows)
    rows_own = (np.empty(width), np.empty(width, np.bool_), np.empty(width, tri_map.dtype),
                np.empty(width))
    rmaps = unowned(rows_own)
    hard = 0
    for rr in range(part, height, parts):
        k0, k1 = row_start[rr], row_start[rr + 1]
        hard += _row_pass(0, width, k0, k1, mode, spans, meth, shade, is64, per_pixel_h, want,
                          rmaps, stop, buf)[1]
        base = rr * width
        _stream_row(img, base, rmaps[0], width)
        _stream_row(mask, base, rmaps[1], width)
        if want & 1:
            _stream_row(tri_map, base, rmaps[2], width)
        if want & 2:
            _stream_row(nlen, base, rmaps[3], width)
    store_fence()     # the streamed rows, visible to the caller
    _keep(buf_own, rows_own)
    return hard


@njit()
def _frame_rows(width, height, mode, xy, attrs, eorders, proto, kc, face_id, per_pixel_h, Htri,
                L, eye, light, orders, want, quick, cf, kd, ks, part, parts, img, mask,
                tri_map, nlen, out, fout, offs, stop):
    """The whole frame of a linear method (modes 0-3), slerp (4), quadratic (5), angular
    (6) or dichotomy (7), scan line by scan line, on the rows ``part, part + parts, ...``:
    each row's spans (:func:`.rasterize.row_span_set` on the triangles crossing it,
    found by :func:`.rasterize.part_buckets`, in triangle order as
    :func:`.rasterize.row_spans` numbers them) into row-sized arrays, their unit end
    normals and the checks of ``check_span_input`` (:func:`.setup.end_checks`, modes 1-6;
    :func:`.setup.ends_part` for modes 5 and 7, which also need the cosines and the
    dichotomy depths; normals in the dtype of ``proto``), the method's per-span set-up
    (modes 4-7: :func:`.setup.slerp_part`, :func:`.setup.quadratic_part` with the
    table's coefficients ``cf`` (ascending; ``cf`` empty: exact),
    :func:`.setup.angular_part`, the dichotomy's denominators
    (:func:`.kernels.dichotomy_denominators_into`, ``kd`` its constants; ``ks``:
    :func:`.setup.setup_consts` in the dtype); ``quick``: the
    float64 sines by the library-exact shortcuts), then :func:`_row_pass`. The spans
    never leave the cache: no frame-sized span arrays are written or read.

    The set-up of modes 5-7 depends on facts about the whole frame: whether every span
    starts at its left end (``t0 == 0``), whether any span has two pixels or more, the
    table (modes 5 and 7), chosen by the smallest ``N_l.N_r`` and cosine of all spans,
    and (mode 7) per depth whether any pixel of the frame is off the dyadic grid. The rows
    assume the usual answers (no, yes, the table ``cf``, every depth off the grid) and
    report the facts: ``out``: [1 a check failed (then the frame stops: the caller draws
    it step by step, with the reference's errors), 2 a set-up value the shortcuts cannot
    promise (the frame stops: the caller draws it with the frame-sized spans),
    fragments, covered pixels, any ``t0 != 0``, largest span, any span deeper than 0];
    ``fout``: [smallest ``N_l.N_r``, smallest cosine clipped to [-1, 1] (mode 7: of the
    spans deeper than 0)]; ``offs`` (mode 7, ``(2, MAX_LEVELS + 1)``): per depth, whether
    a span has it, whether a pixel is off its grid. ``stop`` 4 (profiling): the rows'
    spans, checks and set-up alone."""
    Kc = attrs.shape[2]
    first, ids, widest = part_buckets(xy, height, part, parts)
    M = max(widest, 1)
    ltri, lrow, lc0 = np.empty(M, np.int64), np.empty(M, np.int64), np.empty(M, np.int64)
    lcount, lm = np.empty(M, np.int64), np.empty(M, np.int64)
    lt0, ldt = np.empty(M), np.empty(M)
    lleft, lright = np.empty((M, Kc)), np.empty((M, Kc))
    lA, lB = np.empty((3, M), proto.dtype), np.empty((3, M), proto.dtype)
    C = np.zeros((3, 1), proto.dtype)
    levels = np.zeros(1, np.int64)
    R = np.zeros((1, 1), proto.dtype)
    off = np.zeros(1, np.bool_)
    # modes 4 and 6: the per-span set-up (slerp: psi, 1/sin psi; angular: the first two
    # pixels and 2 cos phi) with the constants ks (setup_consts)
    sc, sc2 = np.zeros(M, proto.dtype), np.zeros(M, proto.dtype)
    hard = np.zeros(M, np.bool_)
    P0, P1 = np.empty((3, M), proto.dtype), np.empty((3, M), proto.dtype)
    P2 = np.empty((3, M), proto.dtype)
    lcos, llev, ldd = np.empty(M), np.zeros(M, np.int64), np.empty(M)
    red = np.zeros(5)
    exact = cf.shape[0] == 0
    cfx = np.zeros(1, proto.dtype) if exact else cf
    dmin = np.inf
    clo = np.inf
    deep = False
    Rr = np.empty((M, MAX_LEVELS), proto.dtype)     # the dichotomy's denominators
    offall = np.ones(MAX_LEVELS + 1, np.bool_)      # assumed: every depth off the grid
    tcb = np.empty(1, proto.dtype)
    gi, gf = np.empty((8, M), np.int64), np.empty((4, M))     # row_span_set's scratch
    is64 = proto.itemsize == 8
    # the row pass's arrays: the row's spans, the method's (the set-up's where it has
    # one: quadratic v, d1, d2; angular p0, p1), the shading's, the maps
    buf_own = _row_buffers(width, lA, mode)
    # the row's maps, drawn here and then streamed to the frame's (_stream_row)
    rimg, rmask = np.empty(width), np.empty(width, np.bool_)
    rtri, rnlen = np.empty(width, tri_map.dtype), np.empty(width)
    # the loop's arrays as views that count no references (jit.unowned): the row loop
    # passes them to kernels that are not inlined, and two threads counting references
    # to the same arrays bounce those counts' cache lines between the cores.  The
    # arguments are the caller's; ``own`` and ``buf_own`` keep the rest alive (_keep)
    own = (ltri, lrow, lc0, lcount, lm, lt0, ldt, lleft, lright, lA, lB, C, levels, R, off,
           sc, sc2, hard, P0, P1, P2, lcos, llev, red, cfx, Rr, offall, tcb, first, ids, gi, gf,
           ldd, rimg, rmask, rtri, rnlen)
    (ltri, lrow, lc0, lcount, lm, lt0, ldt, lleft, lright, lA, lB, C, levels, R, off, sc, sc2,
     hard, P0, P1, P2, lcos, llev, red, cfx, Rr, offall, tcb, first, ids, gi, gf,
     ldd, rimg, rmask, rtri, rnlen) = unowned(own)
    buf = unowned(buf_own)
    (xy, attrs, eorders, kc, face_id, Htri, L, eye, light, orders, cf, kd, ks, img, mask,
     tri_map, nlen, out, fout, offs) = unowned((xy, attrs, eorders, kc, face_id, Htri, L, eye,
                                                light, orders, cf, kd, ks, img, mask, tri_map,
                                                nlen, out, fout, offs))
    Am, Bm = (P0, P1) if mode == 5 or mode == 6 else (lA, lB)
    spans = (ltri, lc0, lcount, lt0, ldt, lleft, lright)
    if mode == 7:
        meth = (Am, Bm, C, sc, sc2, llev, Rr, offall, kc, kd)
    else:
        meth = (Am, Bm, P2 if mode == 5 else C, sc, sc2, levels, R, off, kc, kd)
    shade = (face_id, Htri, L, eye, light, orders)
    rmaps = (rimg, rmask, rtri, rnlen)
    nfrag = 0
    ncov = 0
    t0nz = False
    cmax = 0
    for jr in range(first.shape[0] - 1):
        rr = part + jr * parts
        n, c = row_span_set(xy, attrs, ids, first[jr], first[jr + 1], rr, width, ltri, lrow,
                            lc0, lcount, lm, lt0, ldt, lleft, lright, gi, gf)
        nfrag += c
        if (mode == 5 or mode == 7) and n > 0:
            tree = mode == 7
            ends_part(lleft, lright, lm, lt0, ldt, lcount, eorders[0], eorders[1], tree,
                       DEPTH_THRESHOLDS if tree else _NO_THRESHOLDS, 0, n, lA, lB, False, lcos,
                       llev, hard, red, ldd)
            if red[0] != 0.0:
                out[0] = 1
                store_fence()
                return
            if red[4] != 0.0:     # depths the reference's span_levels must compute
                for s in range(n):
                    if hard[s]:
                        lv = span_level_libm(ldt[s], lt0[s], lcount[s], lcos[s])
                        if lv < 0:     # 1/dt not a finite normal number
                            lv = _reference_level(ldt[s], lt0[s], lcount[s], lcos[s])
                        llev[s] = lv
                        if lv > MAX_LEVELS:
                            out[0] = 1
                            store_fence()
                            return
            dmin = min(dmin, red[1])
            lo, lo_deep, dp = cos_range(lcos, llev, tree, n)   # (tree: of the spans deeper
            clo = min(clo, lo_deep if tree else lo)             # than 0)
            deep |= dp
            if tree:
                dichotomy_denominators_into(lA, lB, llev[:n], cfx, exact, kd, Rr)
                for s in range(n):
                    offs[0, llev[s]] = True
                _off_grid(llev[:n], kd, lt0, ldt, lcount, tcb, offs[1])
        elif mode >= 1 and n > 0:
            if not end_checks(lleft, lright, lm, lt0, ldt, lcount, eorders[0], eorders[1], n,
                              lA, lB, mode <= 3):
                out[0] = 1
                store_fence()
                return
        if mode >= 4:
            for s in range(n):
                t0nz |= lt0[s] != 0.0
                cmax = max(cmax, lcount[s])
        if mode == 4 and n > 0:
            if slerp_part(lA, lB, ks, is64, quick, 0, n, sc, sc2, hard):
                out[0] = 2
                store_fence()
                return
        elif mode == 5 and n > 0:
            quadratic_part(lA, lB, lt0, ldt, ks, cfx, exact, False, 0, n, P0, P1, P2)
        elif mode == 6 and n > 0:
            if angular_part(lA, lB, lt0, ldt, ks, is64, quick, True, False, 0, n, P0, P1, sc,
                             hard):
                out[0] = 2
                store_fence()
                return
        if stop == 4:
            continue
        # the row into the row's maps (row 0 of them), then streamed to the frame's
        ncov += _row_pass(0, width, 0, n, mode, spans, meth, shade, is64, per_pixel_h, want,
                          rmaps, stop, buf)[0]
        base = rr * width
        _stream_row(img, base, rimg, width)
        _stream_row(mask, base, rmask, width)
        if want & 1:
            _stream_row(tri_map, base, rtri, width)
        if want & 2:
            _stream_row(nlen, base, rnlen, width)
    store_fence()     # the streamed rows, visible to the caller
    out[0] = 0
    out[1] = nfrag
    out[2] = ncov
    out[3] = t0nz
    out[4] = cmax
    out[5] = deep
    fout[0] = dmin
    fout[1] = clo
    _keep(own, buf_own)


@njit()
def _stream_row(dst, start, src, n):
    """``dst[start:start + n] = src[:n]`` (the same dtype, both C-contiguous), the
    16-byte aligned middle with non-temporal stores (``jit.stream16``: a map's line
    is written without first being read into the cache, which the frame's 25 bytes a
    pixel would otherwise cost twice); the caller fences (``jit.store_fence``)."""
    isz = dst.itemsize
    a = np.int64(dst.ctypes.data) + start * isz
    head = min(((16 - (a & 15)) & 15) // isz, n)
    for x in range(head):
        dst[start + x] = src[x]
    s0 = head * isz
    nb = (n - head) * isz
    body = nb - nb % 16
    d0 = start * isz + s0
    for o in range(0, body, 16):
        stream16(dst, d0 + o, src, s0 + o)
    for x in range(head + body // isz, n):
        dst[start + x] = src[x]


@njit()
def _keep(own, buf):
    """Nothing: a use of :func:`_frame_rows`' (:func:`_frame`'s) owners after its loop, so
    numba releases them only then (the loop works on views of them that count no
    references)."""
    return None


@njit()
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


@njit()
def _light_row(base, n0, n1, n2, h0, h1, h2, L, light, orders, wx, ws, stri, face_id, av, bv, nl,
               pw, hh, ll, ok, skip, nskip, img, tri_map, nlen, want, nw):
    """``Lighting.intensity(N @ L, N . H)`` clipped, and ``|N|``, at the row's winners, into
    the maps (row offset ``base``; the triangle map where ``want & 1``, the ``|N|`` map
    where ``want & 2``; a ``skip`` pixel's triangle entry is ``-2 - span``, its other
    entries are the fix-up's to overwrite; ``nskip``: how many there are)."""
    l0, l1, l2 = L[0], L[1], L[2]
    I0, ka, kdif, ks, sh = light[0], light[1], light[2], light[3], light[4]
    fastpow = light[5] != 0.0
    o0, o1, o2 = orders[0], orders[1], orders[2]
    for k in range(nw):     # one vectorized loop: the orders selected, not branched on
        N0, N1, N2 = n0[k], n1[k], n2[k]
        av[k] = _clamp0(dot3_select(N0, N1, N2, l0, l1, l2, o0))
        bv[k] = _clamp0(dot3_select(N0, N1, N2, h0[k], h1[k], h2[k], o1))
    if want & 2:
        for k in range(nw):
            nl[k] = np.sqrt(dot3_select(n0[k], n1[k], n2[k], n0[k], n1[k], n2[k], o2))
    powers(bv, sh, fastpow, hh, ll, ok, pw, nw)
    for k in range(nw):
        v = I0 * (ka + kdif * av[k] + ks * pw[k])
        av[k] = 0.0 if v < 0.0 else (1.0 if v > 1.0 else v)
    for k in range(nw):     # (the mask is :func:`_row_winners`')
        img[np.uint64(base + wx[k])] = av[k]
    if want & 1:
        for k in range(nw):
            tri_map[np.uint64(base + wx[k])] = face_id[stri[ws[k]]]
    if want & 2:
        for k in range(nw):
            nlen[np.uint64(base + wx[k])] = nl[k]
    if nskip == 0:
        return
    for k in range(nw):
        if skip[k]:
            skip[k] = False
            tri_map[base + wx[k]] = -2 - ws[k]


@njit()
def _step_row(mode, k0, k1, c0, count, A, B, C, sc, bs, sx, wx, n0, n1, n2, nw):
    """Stepping kernels (5 quadratic, 6 angular) on a row (spans ``k0 .. k1-1``): every
    pixel of each span in order, the winners' normals (in ``x`` order) widened to float64."""
    for s in range(k0, k1):
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


@njit()
def _slerp_row(ws, tc, A, B, sc, sc2, kc, is64, fastsin, sw, ok, sab, skip, n0, n1, n2, nw):
    """Slerp (mode 4) at the row's winners; the number of float32 pixels whose sine is in
    doubt (``skip``: for :mod:`detmath`, see :func:`phong`). ``fastsin``: float64 sines
    by :func:`sin_small` (rows 0-3 of ``sw`` the arguments and sines)."""
    if is64 and fastsin:
        for k in range(nw):
            s = ws[k]
            sw[0, k] = (kc[5] - tc[k]) * sc[s]
            sw[1, k] = tc[k] * sc[s]
        sin_small(sw[0], sw[2], ok, nw)
        sin_small(sw[1], sw[3], ok, nw)
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
            ra, ha = f32_round(np.sin(np.float64(arg_a)))
            rb, hb = f32_round(np.sin(np.float64(arg_b)))
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


@njit()
def _dichotomy_row(ws, tc, count, A, B, R, levels, off, kd, nd, n0, n1, n2, nw):
    """Dichotomy (mode 7) at the row's winners: per run of one span's winners (a span's
    winners are adjacent) its whole halving tree (:func:`_dichotomy_tree`, when small
    enough), then each pixel's pick (:func:`_dichotomy_pick`); deeper spans descend per
    pixel (:func:`_dichotomy_px`). ``nd``: the thread's scratch (``3 (_TREE_MAX + 1)``
    elements), used flat: node ``m`` at ``3 m .. 3 m + 2``."""
    w = nd.reshape(-1)
    k = 0
    while k < nw:
        s = ws[k]
        lv = levels[s]
        need = off[lv]
        scale = kd[2 + lv]
        tree = (np.int64(1) << lv) <= min(4 * count[s] + 8, _TREE_MAX)
        if tree:
            _dichotomy_tree(A, B, R, s, lv, w)
        while True:     # the run of span s's winners (one loop: one exit to mispredict)
            q = np.uint64(k)
            if tree:
                m0, m1, m2 = _dichotomy_pick(w, lv, need, scale, tc[q])
            else:
                m0, m1, m2 = _dichotomy_px(A[0, s], A[1, s], A[2, s], B[0, s], B[1, s],
                                           B[2, s], R, s, lv, need, scale, tc[q])
            n0[q], n1[q], n2[q] = np.float64(m0), np.float64(m1), np.float64(m2)
            k += 1
            if k >= nw or ws[np.uint64(k)] != s:
                break


#: no dichotomy depth thresholds (:func:`.setup.ends_part` of a method without a tree)
_NO_THRESHOLDS = np.zeros(1)


#: the dichotomy builds a span's whole halving tree when it has at most this many nodes
#: (and not many more than the span has pixels); deeper spans descend per pixel
_TREE_MAX = 1 << 12
_TREE_LEVELS = 12


def _bfs_nodes(levels):
    """The inner nodes of a halving tree of depth ``levels`` in breadth-first order (every
    node after both ends of its interval): ``(3 m, 3 half, depth)`` per node ``m`` (the
    midpoint of ``[m - half, m + half]``), unsigned. A tree of depth ``L`` is the first
    ``2**L - 1`` of them, ``3 m`` and ``3 half`` shifted right by ``levels - L``."""
    m, h, d = [], [], []
    for lev in range(levels):
        half = 1 << (levels - 1 - lev)
        for p in range(1 << lev):
            m.append(3 * (2 * p + 1) * half)
            h.append(3 * half)
            d.append(lev)
    return (np.array(m, np.uint64), np.array(h, np.uint64), np.array(d, np.uint64))


_BFS_M3, _BFS_H3, _BFS_D = _bfs_nodes(_TREE_LEVELS)
_U1, _U2 = np.uint64(1), np.uint64(2)


@njit(inline=True)
def _dichotomy_tree(A, B, R, i, L, w):
    """Every node of span ``i``'s halving tree of depth ``L`` into ``w[3 m .. 3 m + 2]``,
    ``m = 0 .. 2**L``: the midpoint of an interval at depth ``d`` is ``(A + B) R[i, d]``
    of its ends, as :func:`_dichotomy_px` computes it on its way down; the nodes in
    breadth-first order from a table (one loop, no per-level loops and their divisions)."""
    top = np.int64(1) << L
    sh = np.uint64(_TREE_LEVELS - L)
    iu = np.uint64(i)
    t3 = np.uint64(3 * top)
    w[0], w[1], w[2] = A[0, iu], A[1, iu], A[2, iu]
    w[t3], w[t3 + _U1], w[t3 + _U2] = B[0, iu], B[1, iu], B[2, iu]
    for t in range(top - 1):
        tu = np.uint64(t)
        m = _BFS_M3[tu] >> sh
        h = _BFS_H3[tu] >> sh
        r = R[iu, _BFS_D[tu]]
        lo = m - h
        hi = m + h
        w[m] = (w[lo] + w[hi]) * r
        w[m + _U1] = (w[lo + _U1] + w[hi + _U1]) * r
        w[m + _U2] = (w[lo + _U2] + w[hi + _U2]) * r


@njit(inline=True)
def _dichotomy_pick(w, L, need_b, scale, tc):
    """:func:`_dichotomy_px` from the span's whole tree ``w`` (node ``m`` at ``3 m``); a
    node index ``k = -1`` is the reference's numpy index: node ``2**L``."""
    u = tc * scale
    kf = np.floor(u)
    fr = u - kf
    k = np.int64(kf)
    top = np.int64(1) << L
    a = np.uint64(3 * (k + (top + 1 if k < 0 else 0)))
    a1, a2 = a + _U1, a + _U2
    if not need_b:
        return w[a], w[a1], w[a2]
    b = np.uint64(3 * min(k + 1, top))
    b1, b2 = b + _U1, b + _U2
    return (w[a] + fr * (w[b] - w[a]), w[a1] + fr * (w[b1] - w[a1]),
            w[a2] + fr * (w[b2] - w[a2]))


@njit(inline=True)
def _dichotomy_px(a0, a1, a2, b0, b1, b2, R, i, L, need_b, scale, tc):
    """The pixel at ``tc`` of dichotomy span ``i`` (ends ``a``, ``b``, depth ``L``, ``scale =
    2**L`` in the dtype, denominators ``R[i]``): node ``k = floor(tc 2**L)`` of the
    halving tree, or (``need_b``: depth ``L`` off the grid in the frame) the linear pick
    between nodes ``k`` and ``min(k + 1, 2**L)``, as the dichotomy kernel of :mod:`.kernels`.
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


@njit()
def _slerp_fixup(pix, span, sa, sb, width, c0, t0, dt, left, right, A, B, sc2, per_pixel_h,
                 Htri, stri, L, eye, light, orders, img, mask, tri_map, nlen, face_id, want):
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
        tri_map[p] = face_id[stri[s]]     # the marks of the hard pixels overwritten
        if want & 2:
            nlen[p] = np.sqrt(dot3(N0, N1, N2, N0, N1, N2, orders[2]))


# ------------------------------------------------------------------ driver
def _no_clock(name):
    """The stage recorder of an unprofiled frame."""


def supports(spec) -> bool:
    """Whether :func:`phong` renders method ``spec`` (its kernel has a fused twin, numba is
    installed and :func:`calibrated` found the reductions' orders).

    Parameters
    ----------
    spec : MethodSpec
        A method's registry entry.

    Returns
    -------
    bool
        True when the fused frame renders it.

    Examples
    --------
    >>> from chebnorm.methods import get_method
    >>> supports(get_method("dichotomy")) == (HAVE_NUMBA and calibrated() is not None)
    True
    """
    return (HAVE_NUMBA and id(method_kernel(spec)) in MODES
            and calibrated() is not None)


def _dichotomy_consts(dtype):
    """The dichotomy's constants ``kd`` in ``dtype``: ``[2, 1, 2**0, ..., 2**MAX_LEVELS]``
    (:func:`.kernels.dichotomy_denominators_into`, :func:`_off_grid`)."""
    return np.array([2.0, 1.0] + [float(2 ** lv) for lv in range(MAX_LEVELS + 1)], dtype)


def _mode_arrays(mode, spec, sp, tables, dtype, ends, work):
    """The per-span arrays of method ``mode`` the frame's kernels take: ``(dtype, A, B,
    C, sc, sc2, levels, R, off, kd)`` (placeholders of size 1 where the mode has none;
    ``dtype`` the computation's, checked as the reference checks it where spans use it)."""
    S = len(sp.count)
    dt_ = np.float64    # the computation's dtype, checked (as the reference) where spans use it
    if mode and S:
        dt_, coeffs, lv, A, B, start_left, count_max = span_input(
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
        ops = DetOps(dtype)    # modes 1-3: B is N_r - N_l (K.vsub(b, a)) in the dtype
        if mode == 4:       # K.SLERP.setup, compiled
            sc, sc2 = method_setup(mode, A, B, None, None, coeffs, start_left, count_max,
                                   ops, work)
        elif mode in (5, 6):
            # sp.t0.astype(dtype), sp.dt.astype(dtype) in kept memory (no fresh pages)
            t0c, dtc = scratch(work, "t0c", S, dtype), scratch(work, "dtc", S, dtype)
            t0c[...] = sp.t0
            dtc[...] = sp.dt
            if mode == 5:   # quadratic_setup, compiled
                A, B, C = method_setup(mode, A, B, t0c, dtc, coeffs, start_left, count_max,
                                       ops, work)
            else:           # angular_setup, compiled
                A, B, sc = method_setup(mode, A, B, t0c, dtc, coeffs, start_left, count_max,
                                        ops, work)
        elif mode == 7:     # dichotomy
            cf = np.array([0.0] if coeffs is None else [dtype(c) for c in coeffs], dtype)
            kd = _dichotomy_consts(dtype)
            levels = np.ascontiguousarray(lv, np.int64)
            lmax = int(levels.max())
            # the frame's denominators in kept memory (fresh ones: 2000 page faults a frame)
            R = scratch(work, "dichotomy_r", (S, max(lmax, 1)), dtype)
            off = _dichotomy_prep(A, B, levels, cf, coeffs is None, kd, sp.t0, sp.dt,
                                  sp.count, lmax, R)
    return dt_, A, B, C, sc, sc2, levels, R, off, kd


def phong(st, spec, lighting, tables, dtype, extra_maps=True):
    """The ``phong`` frame of ``render`` as a
    :class:`~chebnorm.raster.engines.base.ModeResult`: set-up ``st`` (with ``L``),
    method entry ``spec`` (:func:`supports` holds for it), ``lighting``, and ``tables``,
    ``dtype`` as ``render`` passes them to the span interpolator.

    Raises
    ------
    chebnorm.raster.engines.base.FrameUnsupported
        Where this path cannot promise the reference's bytes (the caller then draws the
        frame step by step).

    Parameters
    ----------
    st : Setup
        The frame's set-up, with ``L``.
    spec : MethodSpec
        The normalization method's registry entry.
    lighting : Lighting
        Blinn-Phong parameters.
    tables : dict or None
        Coefficient tables by method name.
    dtype : numpy dtype
        The span interpolator's arithmetic.
    extra_maps : bool, optional
        Also the triangle and ``|N|`` maps (False: the result's ``triangle`` and
        ``normal_length`` are None, and the frame neither computes nor writes them).

    Returns
    -------
    ModeResult
        The frame, the same bytes as the numpy engine's.
    """
    return _phong(st, spec, lighting, tables, dtype, None, extra_maps)


def _phong(st, spec, lighting, tables, dtype, clock, extra_maps=True):
    """:func:`phong`; ``clock`` (None, or :func:`stage_times`' stage recorder) is called
    with each stage's name once the stage is done."""
    tick = clock or _no_clock
    orders = calibrated()
    if orders is None or id(method_kernel(spec)) not in MODES:
        raise FrameUnsupported("no calibrated reduction orders or no fused kernel")
    per_pixel_h = lighting.half_vector == "pixel"
    attrs = getattr(st, "attrs", None)   # [1/w, normal, position] of gather_setup
    if attrs is None:
        attrs = np.concatenate([st.inv_w[..., None], st.nrm, st.pos], axis=2)
    if not per_pixel_h:
        attrs = attrs[..., :4]
    mode = MODES[id(method_kernel(spec))]
    dt_ = _rows_dtype(spec, mode, dtype)
    if dt_ is not None:     # no table: the frame row by row, spans and all
        res = _phong_rows(st, lighting, attrs, mode, dt_, orders, clock, extra_maps, spec,
                          tables)
        if res is not None:
            return res
        # the rows' assumptions did not hold: the frame with the frame-sized spans
    work = take()    # scratch arrays of an earlier frame (pages mapped)
    sp = row_spans(st.xy, attrs, st.width, st.height, work)
    tick("spans")
    # the output maps: the memory of an earlier frame's once the user dropped it (else
    # 25 MB of fresh pages at 1024x1024); the frame writes every pixel of its rows of
    # the maps it fills (a map it does not fill is never touched: no pages mapped)
    maps = output_maps(st.width * st.height)
    S = len(sp.count)
    stats = {}
    # the unit end normals, the checks of check_span_input and the values it derives,
    # compiled (.setup: the reference runs where a check fails)
    ends, dot_min = (widest_dot(sp, spec, dtype, mode <= 3, work)
                     if S and (mode or spec.table is not None) else (None, None))
    tables = auto_tables(spec, sp, [[1, 2, 3]], tables, stats, dot_min=dot_min)
    tick("ends")
    dt_, A, B, C, sc, sc2, levels, R, off, kd = _mode_arrays(mode, spec, sp, tables, dtype,
                                                             ends, work)
    C = np.ascontiguousarray(C)
    kc, Htri, light, L, eye, ords, face_id = _frame_args(st, lighting, mode, dt_, orders)
    # maps filled: 1 triangle, 2 |N| (the float32 slerp marks its hard pixels in the
    # triangle map, so it fills that one anyway)
    want = 3 if extra_maps else (1 if mode == 4 and dt_ is not np.float64 else 0)
    args = (sp.x0, sp.t0, sp.dt, sp.left, sp.right)
    img, mask, tri_map, nlen = maps
    common = (st.width, st.height, mode, sp.row_start, sp.tri, sp.x0, sp.count,
              *args[1:], A, B, C, sc, sc2, levels, R, off, kc, kd, dt_ is np.float64, face_id,
              per_pixel_h, Htri, L, eye, light, ords, want)
    k = min(threads(), st.height)
    tick("method set-up")
    if clock is not None:     # the frame's passes, cumulatively, for stage_times
        for stop, name in ((1, "visibility"), (2, "normals"), (3, "half vectors")):
            run([(_frame, (*common, q, k, *maps, stop)) for q in range(k)])
            tick(name)
    # ``stop`` passed (0) as stage_times passes it: one compiled signature, not two
    nh = sum(run_with_caller([(_frame, (*common, q, k, *maps, 0)) for q in range(k)]))
    if nh:
        pix = np.flatnonzero(tri_map < -1)
        span = -2 - tri_map[pix]
        j = pix % st.width - sp.x0[span]
        tc = (sp.t0[span] + j * sp.dt[span]).astype(dt_)
        psi = sc[span]
        sa, sb = detmath.sin((kc[5] - tc) * psi), detmath.sin(tc * psi)
        _slerp_fixup(pix, span, sa, sb, st.width, *args, A, B, sc2, per_pixel_h, Htri, sp.tri,
                     L, eye, light, ords, img, mask, tri_map, nlen, face_id, want)
    give(work)
    keep_maps(maps)
    tick("shading")
    if np.count_nonzero(mask) < 2:
        # numpy computes N @ L for one row by another route than BLAS
        raise FrameUnsupported("fewer than two pixels covered")
    shape = (st.height, st.width)
    extra = (tri_map.reshape(shape), nlen.reshape(shape)) if extra_maps else (None, None)
    return ModeResult(img.reshape(shape), mask.reshape(shape), int(sp.count.sum()), stats,
                      triangle=extra[0], normal_length=extra[1])


def _rows_dtype(spec, mode, dtype):
    """The dtype of a method's row-by-row frame (:func:`_frame_rows`): float64 for
    ``none`` (mode 0, no checks), ``check_dtype(dtype)`` for modes 1-3, float64 for
    modes 4-7 in float64; None where the frame takes the frame-sized span arrays instead
    (modes 4-7 in float32, whose set-up may need the reference's functions; the
    dichotomy without :func:`.setup.levels_calibrated`; a method with a table of another
    kind; no :func:`.calibration.ends_orders`; a dtype the
    reference refuses, which it then refuses with its own error)."""
    if spec.table is not None and mode not in (5, 7):
        return None
    if mode == 0:
        return np.float64
    if ends_orders() is None:
        return None
    try:
        dt_ = check_dtype(dtype)
    except (TypeError, ValueError):
        return None
    if mode >= 4 and dt_ is not np.float64:
        return None
    if mode == 7 and not levels_calibrated():
        return None
    return dt_


def _frame_args(st, lighting, mode, dt_, orders, light_only=False):
    """The constant arrays every frame kernel takes: ``(kc, Htri, light, L, eye, ords,
    face_id)`` (``light_only``: those of this frame alone, ``(Htri, L, eye, face_id)``;
    :func:`_rows_consts` has the others)."""
    per_pixel_h = lighting.half_vector == "pixel"
    Htri = (np.ascontiguousarray(triangle_half_vectors(st), np.float64) if not per_pixel_h
            else _NO_HTRI)
    L = np.ascontiguousarray(st.L, np.float64)
    eye = np.asarray(st.camera.eye, np.float64)
    face_id = np.ascontiguousarray(st.tri, np.int64)
    if light_only:
        return Htri, L, eye, face_id
    kc, light, ords = _rows_consts(mode, dt_, lighting, orders)[:3]
    return kc, Htri, light, L, eye, ords, face_id


#: the triangle half vectors' placeholder of a frame with per-pixel half vectors (read
#: by no kernel)
_NO_HTRI = np.zeros((1, 3))

#: :func:`_rows_consts`' arrays by what they depend on (at most :data:`_CONSTS_KEPT`)
_CONSTS: dict = {}


_CONSTS_KEPT = 64


def _rows_consts(mode, dt_, lighting, orders):
    """The constant arrays of a frame's kernels that depend on the method, dtype,
    lighting and reduction orders alone, made once: ``(kc, light, ords, eorders, quick,
    cf, kd, proto, ks)`` (``cf`` empty: the quadratic's table is the frame's).  The
    kernels only read them; every frame of a kind shares them (after a frame the
    interpreter's and numpy's code is out of the cache: each small array made costs
    microseconds)."""
    light_key = (float(lighting.I0), float(lighting.ka), float(lighting.kd),
                 float(lighting.ks), float(lighting.shininess))
    key = (mode, np.dtype(dt_).char, light_key, tuple(orders))
    got = _CONSTS.get(key)
    if got is not None:
        return got
    kc = np.array([3.0, 0.5, 0.375, 1.25, 1.875, 1.0], dt_)
    light = np.array([*light_key, float(pow_calibrated(light_key[4])),
                      float(mode == 4 and trig_calibrated())], np.float64)
    eo = ends_orders() if mode else None
    eorders = np.array(eo if eo is not None else (0, 0), np.int64)
    quick = bool(mode in (4, 6) and dt_ is np.float64 and trig_calibrated())
    got = (kc, light, np.array(orders, np.int64), eorders, quick, np.zeros(0, dt_),
           _dichotomy_consts(dt_), np.zeros(1, dt_), setup_consts(dt_))
    if len(_CONSTS) >= _CONSTS_KEPT:
        _CONSTS.clear()
    _CONSTS[key] = got
    return got


#: the quadratic's table of the last frame, by (method, image size, triangles): the rows
#: assume it again (the table is chosen by every span of the frame, known only once the
#: rows are done; a frame where it does not hold is drawn again, with the frame-sized
#: spans); at most :data:`_TABLE_GUESSES` kinds of frame are remembered
_TABLE_GUESS: dict = {}


_TABLE_GUESSES = 64


def _rows_table(spec, tables, st):
    """The quadratic's table the rows assume: ``(key, table)``; the caller's where it
    gave one, else the last such frame's (the default table the first time)."""
    key = (spec.name, int(st.width), int(st.height), len(st.xy))
    if tables is not None:    # the caller's (or the default where it gave none for it)
        return key, clear_table(spec, tables, None)[1]
    if len(_TABLE_GUESS) > _TABLE_GUESSES:
        _TABLE_GUESS.clear()
    if key not in _TABLE_GUESS:
        _TABLE_GUESS[key] = clear_table(spec, None, None)[1]
    return key, _TABLE_GUESS[key]


def _table_holds(spec, tables, guess, key, dmin, clo, stats):
    """Whether the table the rows assumed (``guess``) is the one the frame's spans choose
    (``auto_tables`` on the smallest ``N_l.N_r``, ``dmin``, then ``span_input``'s
    coverage test on the smallest cosine, ``clo``); fills ``stats`` as ``auto_tables``
    does and remembers the frame's table for the next frame."""
    one = SimpleNamespace(count=(1,))    # auto_tables reads len(sp.count) alone here
    tabs = auto_tables(spec, one, [[1, 2, 3]], tables, stats, dot_min=dmin)
    clear, table = clear_table(spec, tabs, clo)
    if not clear:
        return False      # resolve_table decides: the frame-sized spans
    if tables is None:
        _TABLE_GUESS[key] = table
    if table is None or guess is None:
        return table is guess
    return table is guess or (np.asarray(table.coefficients, np.float64).tobytes()
                              == np.asarray(guess.coefficients, np.float64).tobytes())


def _phong_rows(st, lighting, attrs, mode, dt_, orders, clock, extra_maps, spec=None,
                tables=None):
    """:func:`phong` of a method drawn row by row (modes 0-6; ``dt_`` from
    :func:`_rows_dtype`): the row buckets, then :func:`_frame_rows` on the threads (every
    row's spans, checks, set-up, visibility and shading in one pass); FrameUnsupported
    where a check fails (the step by step path then gives the reference's errors); None
    where the frame-sized spans must draw it instead (a set-up value the shortcuts cannot
    promise, or the rows' assumptions about the whole frame did not hold)."""
    tick = clock or _no_clock
    per_pixel_h = lighting.half_vector == "pixel"
    xy = np.ascontiguousarray(st.xy, np.float64)
    attrs = np.ascontiguousarray(attrs, np.float64)
    height = int(st.height)
    kc, light, ords, eorders, quick, cf, kd, proto, ks = _rows_consts(mode, dt_, lighting,
                                                                      orders)
    Htri, L, eye, face_id = _frame_args(st, lighting, mode, dt_, orders, light_only=True)
    if mode in (5, 7):
        key, guess = _rows_table(spec, tables, st)
        if guess is not None:
            cf = np.array([dt_(c) for c in guess.coefficients], dt_)
    maps = output_maps(st.width * st.height)
    k = min(threads(), height)
    outs = np.zeros((k, 6), np.int64)
    fouts = np.zeros((k, 2))
    offs = np.zeros((k, 2, MAX_LEVELS + 1), np.bool_)
    common = (st.width, height, mode, xy, attrs, eorders, proto, kc, face_id, per_pixel_h,
              Htri, L, eye, light, ords, 3 if extra_maps else 0, quick, cf, kd, ks)
    tick("spans")
    if clock is not None:     # the frame's passes, cumulatively, for stage_times
        for stop, name in ((4, "ends"), (1, "visibility"), (2, "normals"), (3, "half vectors")):
            run([(_frame_rows, (*common, q, k, *maps, outs[q], fouts[q], offs[q], stop))
                 for q in range(k)])
            tick(name)
            if name == "ends":
                tick("method set-up")
    run_with_caller([(_frame_rows, (*common, q, k, *maps, outs[q], fouts[q], offs[q], 0))
                     for q in range(k)])
    tick("shading")
    # the threads' reports as Python ints, read once (after the frame the interpreter's
    # and numpy's code is out of the cache: each small numpy call costs microseconds)
    status, frags, covered, t0nz, cmax, deep = zip(*outs.tolist())
    if 1 in status:
        raise FrameUnsupported("a span failed a check of check_span_input")
    keep_maps(maps)
    # the set-up of modes 4-7: every value promised (no hard span); modes 5-7 also assumed
    # what the whole frame decides (setup.method_setup's start_left and count_max, the
    # table, the dichotomy's depths off the dyadic grid)
    stats = {}
    spans = sum(frags) > 0
    if 2 in status:
        return None
    if mode in (5, 6) and spans and not (any(t0nz) and (mode == 5 or max(cmax) >= 2)):
        return None
    if mode == 7 and (offs[:, 0].any(axis=0) & ~offs[:, 1].any(axis=0)).any():
        return None
    if mode in (5, 7) and spans:
        clo = None if mode == 7 and not any(deep) else float(fouts[:, 1].min())
        if not _table_holds(spec, tables, guess, key, np.float64(fouts[:, 0].min()), clo,
                            stats):
            return None
    if sum(covered) < 2:
        # numpy computes N @ L for one row by another route than BLAS
        raise FrameUnsupported("fewer than two pixels covered")
    img, mask, tri_map, nlen = maps
    shape = (st.height, st.width)
    extra = (tri_map.reshape(shape), nlen.reshape(shape)) if extra_maps else (None, None)
    return ModeResult(img.reshape(shape), mask.reshape(shape), sum(frags), stats,
                      triangle=extra[0], normal_length=extra[1])


def stage_times(st, spec, lighting, tables=None, dtype=np.float64, extra_maps=True):
    """Process CPU time (all threads) and wall time of each stage of :func:`phong`'s
    frame, for the benchmark's ``--stages``: ``{stage: (cpu_s, wall_s)}`` in order:
    ``spans`` (row spans), ``ends`` (unit end normals, the method's checks, tables),
    ``method set-up``, then the frame's passes over the rows, each timed alone
    (the frame run up to it minus the frame run up to the one before):
    ``visibility`` (z-test, background, winners), ``normals`` (the method's),
    ``half vectors``, ``shading`` (dot products, ``pow``, the output maps). A frame
    drawn row by row (:func:`_frame_rows`: every method in float64) has no frame-sized
    spans: its ``ends`` is the rows' spans, checks and the method's set-up together
    (``spans`` and ``method set-up`` are then about zero).

    Parameters
    ----------
    st, spec, lighting, tables, dtype, extra_maps
        As :func:`phong` takes them.

    Returns
    -------
    dict
        Stage name -> ``(cpu_s, wall_s)``.
    """
    marks = [("start", time.process_time(), time.perf_counter())]

    def clock(name):
        marks.append((name, time.process_time(), time.perf_counter()))

    _phong(st, spec, lighting, tables, dtype, clock, extra_maps)
    out = {}
    for (_, c0, w0), (name, c1, w1) in zip(marks, marks[1:]):
        out[name] = (c1 - c0, w1 - w0)
    # the frame's passes ran cumulatively: each stage is its run minus the one before
    cum = ["visibility", "normals", "half vectors", "shading"]
    if _rows_dtype(spec, MODES[id(method_kernel(spec))], dtype) is not None:
        cum.insert(0, "ends")    # the row-by-row frame: "ends" is its rows' spans, checks, set-up
    runs = {n: out[n] for n in cum}
    for a, b in zip(cum, cum[1:]):
        out[b] = (runs[b][0] - runs[a][0], runs[b][1] - runs[a][1])
    return out
