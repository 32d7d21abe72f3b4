"""Compiled set-up of the fused ``phong`` frame (:func:`.fused.phong`): the row spans,
the checks and per-span values of :func:`chebnorm.methods.spans.check_span_input` on
the spans' unit end normals, the widest span angle of ``render._auto_tables``, the
per-method span set-up, and ``render``'s default camera and projection, with the bits
of the numpy reference; scratch arrays kept between frames.

The reference stays the reference: every value here is what it computes, in its
operation order (the ``np.linalg.norm`` and ``einsum`` sums in the orders
:func:`ends_orders` finds, the projection's ``@`` as :func:`_gemm_fma` checks), and
wherever a check fails, or a value lands where this code cannot promise the
reference's bits (a dichotomy depth whose ``log2`` is within 1e-6 of an integer, a
table's coverage test that is not clear-cut, a float32 sine or cosine whose rounding
is in doubt), the reference functions run instead, on those spans or on all, so the
user gets exactly the reference's values and errors.
"""

from __future__ import annotations

import math
import sys
import threading
from functools import lru_cache
from types import SimpleNamespace

import numpy as np

from chebnorm.approx import CoefficientTable
from chebnorm.methods.registry import default_tables, method_kernel
from chebnorm.methods.spans import ANTIPARALLEL_TOL, MAX_LEVELS, PICK_TOL, UNIT_TOL
from chebnorm.methods.spans import COVER_SLACK as _COVER_SLACK
from chebnorm.methods.spans import check_dtype as _check_dtype
from chebnorm.methods.spans import check_method as _check_method
from chebnorm.methods.spans import check_span_input
from chebnorm.methods.spans import resolve_table as _resolve_table
from chebnorm.methods.spans import span_levels as _levels

from . import fused
from .fused import _dot3, _njit, _threads
from .meshes import _unit
from .spans import fit_camera
from .spans import project as _ref_project

__all__ = ["Workspace", "take", "give", "output_maps", "keep_maps", "row_spans", "span_input",
           "widest_dot", "method_setup", "ends_orders", "default_camera_of", "project"]

#: the position tolerance of ``check_span_input`` (pixels at ``t`` in [-tol, 1 + tol])
_POS_TOL = 1e-9
#: margin (to an integer ``log2``, to a depth's cosine threshold) inside which numpy
#: computes a dichotomy depth
_NEAR_INT = 1e-6
#: ``cos(theta_max 2**n)``, ``theta_max = 2 acos(1 - PICK_TOL)`` of ``_levels``, while
#: ``theta_max 2**n < pi`` (past the last, every span angle is below ``theta_max 2**n``)
_THRESHOLDS = np.array([math.cos(2.0 * math.acos(1.0 - PICK_TOL) * 2.0 ** n) for n in range(8)
                        if 2.0 * math.acos(1.0 - PICK_TOL) * 2.0 ** n < math.pi])


class Workspace:
    """Scratch arrays of one frame (spans, end normals, per-span set-up), kept for the
    next frame: their pages are mapped already (first-touch page faults cost about as
    much as the set-up's arithmetic). Never handed to the user; one frame at a time
    (:func:`take` and :func:`give`).

    >>> w = Workspace()
    >>> a = w.empty("x", (3, 4)); b = w.empty("x", (2, 5))
    >>> a.shape, b.shape, bool(np.shares_memory(a, b))
    ((3, 4), (2, 5), True)
    """

    def __init__(self):
        self._bufs = {}

    def empty(self, name, shape, dtype=np.float64):
        """An uninitialised C-contiguous array ``name`` (the previous one's memory)."""
        dtype = np.dtype(dtype)
        shape = (shape,) if isinstance(shape, (int, np.integer)) else tuple(shape)
        n = math.prod(shape)
        buf = self._bufs.get(name)
        if buf is None or buf.dtype != dtype or buf.size < n:
            buf = self._bufs[name] = np.empty(n + n // 8 + 1, dtype)
        return buf[:n].reshape(shape)


#: workspaces not in use (a frame takes one, or makes one, and gives it back)
_FREE: list = []


def take() -> Workspace:
    """A workspace for one frame (a new one when every kept one is in use)."""
    try:
        return _FREE.pop()
    except IndexError:
        return Workspace()


def give(work: Workspace) -> None:
    """Return a frame's workspace (at most two are kept)."""
    if len(_FREE) < 2:
        _FREE.append(work)


#: output-map sets ``(image, mask, triangle, normal length)`` of earlier frames, flat (at
#: most :data:`_KEEP_MAPS`): a set nobody else references any more is the next frame's
#: (the memory of arrays the user dropped, its pages mapped already)
_MAPS: list = []
_MAPS_LOCK = threading.Lock()
_KEEP_MAPS = 2
_MAP_DTYPES = (np.float64, np.bool_, np.int64, np.float64)


def output_maps(npx):
    """Four uninitialised flat arrays for a frame's image, mask, triangle and ``|N|``
    maps (float64, bool, int64, float64), each ``npx`` long: a set of an earlier frame
    that only this pool still references (``sys.getrefcount``: the user dropped every
    view of it), else new arrays.  Hand the set back with :func:`keep_maps` once the
    frame is drawn.

    >>> a = output_maps(10); keep_maps(a); a0 = a[2].ctypes.data; del a
    >>> output_maps(10)[2].ctypes.data == a0   # dropped by the caller: the same memory
    True
    """
    with _MAPS_LOCK:
        for i, ms in enumerate(_MAPS):
            # references: the pool's tuple and getrefcount's argument, nothing else
            if ms[0].size == npx and all(sys.getrefcount(ms[k]) == 2 for k in range(len(ms))):
                del _MAPS[i]
                return ms
    return tuple(np.empty(npx, dt) for dt in _MAP_DTYPES)


def keep_maps(maps):
    """Remember a frame's map set for reuse once its user drops it."""
    with _MAPS_LOCK:
        _MAPS.append(tuple(maps))
        del _MAPS[:-_KEEP_MAPS]


def _empty(work, name, shape, dtype=np.float64):
    return np.empty(shape, dtype) if work is None else work.empty(name, shape, dtype)


@_njit(inline=True)
def _depth_base(dt):
    """``(base, 2**base)``, ``base = max(e, 0)`` for ``1/dt = m 2**e`` (``m`` in [1/2, 1),
    :func:`math.frexp` by the bits: no library call), or ``(-1, 0)`` where ``m`` is
    within ``_NEAR_INT`` of 1/2 (``log2`` near an integer) or ``1/dt`` is zero,
    subnormal, negative or not finite: then numpy finds the depth."""
    bits = fused._f2i(1.0 / dt)
    ex = (bits >> 52) & 0x7FF
    mm = fused._i2f((bits & 0xFFFFFFFFFFFFF) | (np.int64(1022) << 52))
    if bits <= 0 or ex == 0 or ex == 0x7FF or mm < 0.5 * (1.0 + _NEAR_INT):
        return np.int64(-1), 0.0
    base = max(ex - 1022, 0)
    return base, fused._i2f((base + 1023) << 52)


@_njit()
def _ends_part(left, right, m, t0, dt, count, o_ein, o_norm, tree, thr, lo, hi, A, B,
               diff, cos, levels, hard, red):
    """Spans ``lo .. hi-1``: the unit end normals ``_unit(left[:, 1:4])``,
    ``_unit(right[:, 1:4])`` in the dtype of ``A``, ``B`` (3, S) (``diff``: ``B - A``
    into ``B``), their cosine as ``check_span_input`` computes it, and (``tree``) the
    dichotomy depth of ``_levels`` (``hard[i]``: the depth is numpy's to compute).
    ``red``: [any check failed, smallest ``N_l.N_r`` (einsum), any ``t0 != 0``, largest
    count, hard spans]."""
    bad = False
    dmin = np.inf
    t0nz = False
    cmax = 0
    nhard = 0
    for i in range(lo, hi):
        a0, a1, a2 = left[i, 1], left[i, 2], left[i, 3]
        r = np.sqrt(_dot3(a0, a1, a2, a0, a1, a2, o_norm))
        a0, a1, a2 = a0 / r, a1 / r, a2 / r
        b0, b1, b2 = right[i, 1], right[i, 2], right[i, 3]
        r = np.sqrt(_dot3(b0, b1, b2, b0, b1, b2, o_norm))
        b0, b1, b2 = b0 / r, b1 / r, b2 / r
        A[0, i], A[1, i], A[2, i] = a0, a1, a2
        B[0, i], B[1, i], B[2, i] = b0, b1, b2
        if diff:
            for c in range(3):
                B[c, i] = B[c, i] - A[c, i]
        hard[i] = False
        if not (np.isfinite(a0) and np.isfinite(a1) and np.isfinite(a2) and np.isfinite(b0)
                and np.isfinite(b1) and np.isfinite(b2) and np.isfinite(t0[i])
                and np.isfinite(dt[i])):
            bad = True
            cos[i] = np.nan
            levels[i] = 0
            continue
        # _as_vectors: | |N| - 1 | <= UNIT_TOL, |N| by einsum; the cosine's |N| by norm
        qa = np.sqrt(_dot3(a0, a1, a2, a0, a1, a2, o_ein))
        qb = np.sqrt(_dot3(b0, b1, b2, b0, b1, b2, o_ein))
        if abs(qa - 1.0) > UNIT_TOL or abs(qb - 1.0) > UNIT_TOL:
            bad = True
        if o_norm != o_ein:
            qa = np.sqrt(_dot3(a0, a1, a2, a0, a1, a2, o_norm))
            qb = np.sqrt(_dot3(b0, b1, b2, b0, b1, b2, o_norm))
        d = _dot3(a0, a1, a2, b0, b1, b2, o_ein)
        c = d / (qa * qb)
        cos[i] = c
        if 1.0 + c <= ANTIPARALLEL_TOL:
            bad = True
        dmin = min(dmin, d)
        # _positions
        if m[i] < 1 or dt[i] <= 0.0 or count[i] < 1:
            bad = True
        last = t0[i] + (count[i] - 1) * dt[i]
        if t0[i] < -_POS_TOL or last > 1.0 + _POS_TOL:
            bad = True
        if t0[i] != 0.0:
            t0nz = True
        cmax = max(cmax, count[i])
        if not tree:
            continue
        # _levels: the base depth ceil(log2(1/dt) - 1e-12), the exponent of 1/dt (a
        # mantissa near 1/2: log2 near an integer, numpy's to round) ...
        base, scale = _depth_base(dt[i])
        if base < 0:
            hard[i] = True
            nhard += 1
            levels[i] = 0
            continue
        off = False
        for j in range(count[i]):
            u = (t0[i] + j * dt[i]) * scale
            if abs(u - np.rint(u)) > 1e-9 * max(1.0, abs(u)):
                off = True
                break
        L = base
        if off:
            # ... then off the grid ceil(log2(arccos(c) / theta_max)): the smallest n >= 0
            # with c >= cos(theta_max 2**n) (thr[n]; 7 past the last), c near a threshold
            # numpy's to round
            cc = min(max(c, -1.0), 1.0)
            need = thr.shape[0]
            for q in range(thr.shape[0]):
                if abs(cc - thr[q]) < _NEAR_INT:
                    hard[i] = True
                    nhard += 1
                    break
                if cc > thr[q]:
                    need = q
                    break
            L = max(base, np.int64(need))
        levels[i] = L
        if L > MAX_LEVELS:
            bad = True
    red[0] = 1.0 if bad else 0.0
    red[1] = dmin
    red[2] = 1.0 if t0nz else 0.0
    red[3] = cmax
    red[4] = nhard


@_njit()
def _cos_range(cos, levels, tree):
    """(smallest cosine, smallest cosine of a span with ``levels > 0``, any such span),
    cosines clipped to [-1, 1] (the values ``_needed_range`` takes the minimum of)."""
    lo = np.inf
    lo_deep = np.inf
    deep = False
    for i in range(cos.shape[0]):
        c = min(max(cos[i], -1.0), 1.0)
        lo = min(lo, c)
        if tree and levels[i] > 0:
            deep = True
            lo_deep = min(lo_deep, c)
    return lo, lo_deep, deep


@lru_cache(maxsize=None)
def ends_orders():
    """``(order of einsum N_l.N_r, order of |N|)`` (see :func:`.fused._dot3`) that reproduce
    ``check_span_input`` and ``render._auto_tables`` on the end normals as ``render``
    passes them, ``_unit(left[:, [1, 2, 3]])``: a fancy-indexed column slice, laid out
    column-major, whose sums numpy runs in another order than on row-major rows (None:
    no order matches; then the reference runs).

    >>> o = ends_orders()
    >>> o is None or len(o) == 2
    True
    """
    if not fused.HAVE_NUMBA:
        return None
    rng = np.random.default_rng(20261124)

    def probe(kind, order, case):
        n, kc = case
        a = rng.standard_normal((n, kc))[:, [1, 2, 3]]
        b = rng.standard_normal((n, kc))[:, [1, 2, 3]]
        ac, bc = np.ascontiguousarray(a), np.ascontiguousarray(b)
        if kind == "einsum":
            got = fused._dots(ac, bc, order)
            return (np.einsum("ij,ij->i", a, b).tobytes() == got.tobytes()
                    and np.einsum("...k,...k->...", a, b).tobytes() == got.tobytes())
        got = np.sqrt(fused._dots(ac, ac, order))
        return (np.linalg.norm(a, axis=-1, keepdims=True)[:, 0].tobytes() == got.tobytes()
                and np.linalg.norm(a, axis=1).tobytes() == got.tobytes())
    return fused.first_orders(("einsum", "norm"), ((2, 7), (3, 4), (5, 7), (8, 7), (17, 4),
                                                   (1000, 7), (4099, 7), (20000, 4)), probe)


def _run(jobs):
    """Run ``[(kernel, args), ...]`` (compiled with ``nogil``): the first on this thread,
    the others on :mod:`.fused`'s pool (whose threads may be busy with the frame's
    background); their results in order."""
    if len(jobs) == 1:
        return [jobs[0][0](*jobs[0][1])]
    futures = [fused._pool().submit(fn, *args) for fn, args in jobs[1:]]
    first = jobs[0][0](*jobs[0][1])
    return [first] + [f.result() for f in futures]


def _parts(n):
    k = min(_threads(), max(1, n // 4096))
    cuts = [n * q // k for q in range(k + 1)]
    return [(cuts[q], cuts[q + 1]) for q in range(k) if cuts[q] < cuts[q + 1]]


class _Ends:
    """What the compiled pass over the spans found (see :func:`_ends_part`)."""

    def __init__(self, sp, tree, orders, dtype, diff, work):
        S = len(sp.count)
        left, right = sp.left, sp.right
        self.A, self.B = _empty(work, "A", (3, S), dtype), _empty(work, "B", (3, S), dtype)
        self.cos = _empty(work, "cos", S)
        self.levels = _empty(work, "levels", S, np.int64)
        self.hard = _empty(work, "hard", S, np.bool_)
        parts = _parts(S)
        red = np.zeros((len(parts), 5))
        _run([(_ends_part, (left, right, sp.m, sp.t0, sp.dt, sp.count, orders[0], orders[1],
                            tree, _THRESHOLDS, lo, hi, self.A, self.B, diff, self.cos,
                            self.levels, self.hard, red[q])) for q, (lo, hi) in enumerate(parts)])
        self.bad = bool(red[:, 0].any())
        self.dot_min = np.float64(red[:, 1].min())
        self.start_left = not red[:, 2].any()
        self.count_max = int(red[:, 3].max())
        if tree and red[:, 4].any():     # depths numpy computes (log2 near an integer)
            h = np.flatnonzero(self.hard)
            self.levels[h] = _levels(sp.dt[h], sp.t0[h], sp.count[h], self.cos[h])
            self.bad = self.bad or bool((self.levels[h] > MAX_LEVELS).any())


def widest_dot(sp, spec, dtype, diff, work=None):
    """``(ends, smallest N_l.N_r)`` of the spans' unit end normals (the einsum of
    ``render._auto_tables``) for method ``spec``, the normals in ``dtype`` (if float32
    or float64; ``diff``: see :func:`_ends_part`); ``(ends, None)`` when a check of
    ``check_span_input`` fails on them, ``(None, None)`` without :func:`ends_orders`
    (then the reference runs); arrays from ``work`` (a :class:`Workspace`) if given."""
    orders = ends_orders()
    if orders is None:
        return None, None
    try:
        dt = np.dtype(dtype).type
    except TypeError:
        dt = None
    dt = dt if dt in (np.float32, np.float64) else np.float64
    ends = _Ends(sp, method_kernel(spec).shape == "tree", orders, dt, diff, work)
    return ends, (None if ends.bad else ends.dot_min)


def _table(spec, tables, ends, tree):
    """``_resolve_table(spec, tables, cos, levels)``: the reference runs unless the table
    clearly covers the spans (its upper end at ``table_scale``, its lower end below what
    the spans need, a comparison of exact values)."""
    method = spec.name
    defaults = tables is None or method not in tables
    table = default_tables()[method] if defaults else tables[method]
    levels = ends.levels if tree else None
    if table is None:
        return None
    if isinstance(table, CoefficientTable):
        scale = float(method_kernel(spec).table_scale)
        lo, hi = table.interval_float
        c_lo, c_lo_deep, deep = _cos_range(ends.cos, ends.levels, tree)
        if tree and not deep:
            return table
        need_lo = scale * float(c_lo_deep if tree else c_lo)
        if hi >= scale and not lo > need_lo + _COVER_SLACK:
            return table
    return _resolve_table(spec, tables, ends.cos, levels)


def span_input(spec, sp, tables, dtype, ends, diff):
    """What :func:`.fused.phong` takes from ``check_span_input(spec, _unit(sp.left[:, [1,
    2, 3]]), _unit(sp.right[:, [1, 2, 3]]), sp.m, t0=sp.t0, dt=sp.dt, count=sp.count,
    tables=tables, dtype=dtype)``, from the compiled pass ``ends`` (:func:`widest_dot`),
    the same values and the same errors: ``(dtype, coefficients, levels, A, B, t0 all
    zero, largest count)``, ``A``, ``B`` the end normals (3, S) in the dtype
    (``diff``: ``B - A`` for ``B``)."""
    if ends is None or ends.bad:
        # the reference, on the spans in its order (triangle, row): its errors name spans
        # by that order
        cols = [1, 2, 3]
        order = np.lexsort((sp.row, sp.tri)) if hasattr(sp, "row") else np.arange(len(sp.m))
        left, right = sp.left[order], sp.right[order]
        inp = check_span_input(spec, _unit(left[:, cols]), _unit(right[:, cols]), sp.m[order],
                               t0=sp.t0[order], dt=sp.dt[order], count=sp.count[order],
                               tables=tables, dtype=dtype)
        back = np.empty_like(order)
        back[order] = np.arange(len(order))
        inp = SimpleNamespace(n_left=inp.n_left[back], n_right=inp.n_right[back],
                              dtype=inp.dtype, coefficients=inp.coefficients,
                              levels=None if inp.levels is None else inp.levels[back])
        A, B = end_arrays(inp, inp.dtype, diff)
        return (inp.dtype, inp.coefficients, inp.levels, A, B, bool((sp.t0 == 0).all()),
                int(sp.count.max()))
    spec = _check_method(spec)
    dtype = _check_dtype(dtype)
    tree = method_kernel(spec).shape == "tree"
    table = _table(spec, tables, ends, tree) if spec.table is not None else None
    coeffs = None if table is None else table.coefficients
    return (dtype, coeffs, ends.levels if tree else None, ends.A, ends.B, ends.start_left,
            ends.count_max)


# ------------------------------------------------------------ per-mode set-up
@_njit()
def _linear_setup(nl, nr, A, B, diff):
    """``A = nl.astype(dtype).T``, ``B = nr.astype(dtype).T`` and (``diff``) ``B - A`` in
    the dtype (``K.vsub(b, a)``)."""
    for i in range(nl.shape[0]):
        for c in range(3):
            A[c, i] = nl[i, c]
            B[c, i] = nr[i, c]
            if diff:
                B[c, i] = B[c, i] - A[c, i]


def end_arrays(inp, dtype, diff):
    """``(A, B)`` of :func:`.fused.phong`: the end normals in ``dtype``, (3, S), and
    (``diff``) ``B - A`` instead of ``B``."""
    S = inp.n_left.shape[0]
    A, B = np.empty((3, S), dtype), np.empty((3, S), dtype)
    parts = _parts(S)
    if len(parts) == 1:
        _linear_setup(inp.n_left, inp.n_right, A, B, diff)
    else:
        _run([(_linear_setup, (inp.n_left[lo:hi], inp.n_right[lo:hi], A[:, lo:hi], B[:, lo:hi],
                               diff)) for lo, hi in parts])
    return A, B


# ------------------------------------------------------------------ camera
#: {(width, height): (positions, camera)}: the default cameras of recent meshes
_CAMERAS: dict = {}


@_njit()
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
    arrays by value (a copy of the positions is kept and compared bit for bit)."""
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


# ------------------------------------------- slerp, quadratic, angular set-up
# The set-up of the kernels in chebnorm.methods.kernels (slerp's ``setup``,
# ``quadratic_steps``, ``angular_steps``) as fast._quadratic_setup and
# fast._angular_setup run it on numpy arrays with fused._DetOps, span by span in the
# same operations and dtype (constants ``k`` in the dtype: 1, 2, 4, TINY). The
# transcendental functions are the C library's in float64 (what detmath and det use);
# in float32 a result whose rounding is in doubt marks the span ``hard`` and the
# caller runs the numpy set-up on those spans.

@_njit(inline=True)
def _trig(kind, x, is64, buf):
    """``sin`` (0), ``cos`` (1) or ``arccos`` (2) of ``x`` in the dtype of ``buf``, and
    whether its float32 rounding is in doubt (:func:`.fused._f32_round`)."""
    v = np.float64(x)
    y = np.sin(v) if kind == 0 else (np.cos(v) if kind == 1 else np.arccos(v))
    buf[0] = y
    if is64:
        return buf[0], False
    r, h = fused._f32_round(y)
    return buf[0], h


@_njit()
def _slerp_part(A, B, k, is64, fast, lo, hi, psi_out, inv_out, hard):
    """``psi = max(arccos(min(N_l.N_r, 1)), TINY)``, ``inv = 1/sin(psi)`` (``fast``: the
    float64 sines by :func:`.fused._trig64`)."""
    if is64 and fast:
        m = hi - lo
        w = np.empty((6, m))
        ok = np.empty(m, np.bool_)
        for j in range(m):
            i = lo + j
            d = A[0, i] * B[0, i] + A[1, i] * B[1, i] + A[2, i] * B[2, i]
            w[0, j] = max(np.arccos(min(d, k[0])), k[3])
        fused._trig64(0, w[0], psi_out[lo:hi], ok, w[1:], m)
        for j in range(m):
            i = lo + j
            inv_out[i] = k[0] / psi_out[i]
            psi_out[i] = w[0, j]
            hard[i] = False
        return 0
    buf = np.empty(1, A.dtype)
    n = 0
    for i in range(lo, hi):
        d = A[0, i] * B[0, i] + A[1, i] * B[1, i] + A[2, i] * B[2, i]
        c = min(d, k[0])
        ac, h1 = _trig(2, c, is64, buf)
        psi = max(ac, k[3])
        s, h2 = _trig(0, psi, is64, buf)
        psi_out[i] = psi
        inv_out[i] = k[0] / s
        hard[i] = h1 or h2
        n += hard[i]
    return n


@_njit()
def _quadratic_part(A, B, t0, dt, k, coeffs, exact, start_left, lo, hi, V, D1, D2):
    """``v``, ``d1``, ``d2`` of ``quadratic_steps`` (``coeffs`` ascending, in the dtype)."""
    for i in range(lo, hi):
        a0, a1, a2 = A[0, i], A[1, i], A[2, i]
        b0, b1, b2 = B[0, i], B[1, i], B[2, i]
        x = a0 * b0 + a1 * b1 + a2 * b2
        s0, s1, s2 = a0 + b0, a1 + b1, a2 + b2
        if exact:
            r = k[0] / np.sqrt((x + k[0]) * k[1])
        else:
            r = coeffs[coeffs.shape[0] - 1]
            for q in range(coeffs.shape[0] - 2, -1, -1):
                r = r * x + coeffs[q]
        c0, c1, c2 = (s0 * r) * k[2], (s1 * r) * k[2], (s2 * r) * k[2]
        g0, g1, g2 = s0 * k[1] - c0, s1 * k[1] - c1, s2 * k[1] - c2
        p0, p1, p2 = (c0 - a0 * k[1]) - s0, (c1 - a1 * k[1]) - s1, (c2 - a2 * k[1]) - s2
        d = dt[i]
        h2 = d * d
        e = h2 * k[1]
        D2[0, i], D2[1, i], D2[2, i] = g0 * e, g1 * e, g2 * e
        if start_left:
            V[0, i], V[1, i], V[2, i] = a0, a1, a2
            D1[0, i], D1[1, i], D1[2, i] = p0 * d + g0 * h2, p1 * d + g1 * h2, p2 * d + g2 * h2
        else:
            t = t0[i]
            V[0, i] = a0 + (p0 + g0 * t) * t
            V[1, i] = a1 + (p1 + g1 * t) * t
            V[2, i] = a2 + (p2 + g2 * t) * t
            f = (t * d) * k[1] + h2
            D1[0, i], D1[1, i], D1[2, i] = p0 * d + g0 * f, p1 * d + g1 * f, p2 * d + g2 * f


@_njit()
def _angular_part(A, B, t0, dt, k, is64, fast, two, start_left, lo, hi, P0, P1, K2, hard):
    """The first two pixels of ``angular_steps`` (``two``: the frame has spans of two
    or more pixels, else ``P1 = P0``) and ``2 cos(phi)`` (``fast``: the float64 sines
    and cosines by :func:`.fused._trig64`, :func:`_angular_fast`)."""
    if is64 and fast:
        _angular_fast(A, B, t0, dt, k, two, start_left, lo, hi, P0, P1, K2, hard)
        return 0
    buf = np.empty(1, A.dtype)
    n = 0
    for i in range(lo, hi):
        a0, a1, a2 = A[0, i], A[1, i], A[2, i]
        b0, b1, b2 = B[0, i], B[1, i], B[2, i]
        c = min(a0 * b0 + a1 * b1 + a2 * b2, k[0])
        psi, h = _trig(2, c, is64, buf)
        iw = k[0] / max(np.sqrt(k[0] - c * c), k[3])
        n0, n1, n2 = (b0 - a0 * c) * iw, (b1 - a1 * c) * iw, (b2 - a2 * c) * iw
        phi = psi * dt[i]
        cp, h1 = _trig(1, phi, is64, buf)
        sp, h2 = _trig(0, phi, is64, buf)
        h = h or h1 or h2
        K2[i] = cp * k[1]
        if start_left:
            q0, q1, q2 = a0, a1, a2
            r0, r1, r2 = a0 * cp + n0 * sp, a1 * cp + n1 * sp, a2 * cp + n2 * sp
        else:
            ang = t0[i] * psi
            ca, h3 = _trig(1, ang, is64, buf)
            sa, h4 = _trig(0, ang, is64, buf)
            h = h or h3 or h4
            q0, q1, q2 = a0 * ca + n0 * sa, a1 * ca + n1 * sa, a2 * ca + n2 * sa
            u0, u1, u2 = n0 * ca - a0 * sa, n1 * ca - a1 * sa, n2 * ca - a2 * sa
            r0, r1, r2 = q0 * cp + u0 * sp, q1 * cp + u1 * sp, q2 * cp + u2 * sp
        P0[0, i], P0[1, i], P0[2, i] = q0, q1, q2
        if two:
            P1[0, i], P1[1, i], P1[2, i] = r0, r1, r2
        else:
            P1[0, i], P1[1, i], P1[2, i] = q0, q1, q2
        hard[i] = h
        n += h
    return n


@_njit()
def _angular_fast(A, B, t0, dt, k, two, start_left, lo, hi, P0, P1, K2, hard):
    """:func:`_angular_part` in float64, its cosines and sines of ``phi`` and of the
    start angle computed for the spans ``lo .. hi-1`` at once (:func:`.fused._trig64`)."""
    m = hi - lo
    w = np.empty((11, m))
    ok = np.empty(m, np.bool_)
    for j in range(m):
        i = lo + j
        c = min(A[0, i] * B[0, i] + A[1, i] * B[1, i] + A[2, i] * B[2, i], k[0])
        psi = np.arccos(c)
        w[0, j] = psi * dt[i]
        w[1, j] = t0[i] * psi
    fused._trig64(1, w[0], w[2], ok, w[6:], m)
    fused._trig64(0, w[0], w[3], ok, w[6:], m)
    if not start_left:
        fused._trig64(1, w[1], w[4], ok, w[6:], m)
        fused._trig64(0, w[1], w[5], ok, w[6:], m)
    for j in range(m):
        i = lo + j
        a0, a1, a2 = A[0, i], A[1, i], A[2, i]
        b0, b1, b2 = B[0, i], B[1, i], B[2, i]
        c = min(a0 * b0 + a1 * b1 + a2 * b2, k[0])
        iw = k[0] / max(np.sqrt(k[0] - c * c), k[3])
        n0, n1, n2 = (b0 - a0 * c) * iw, (b1 - a1 * c) * iw, (b2 - a2 * c) * iw
        cp, sp = w[2, j], w[3, j]
        K2[i] = cp * k[1]
        if start_left:
            q0, q1, q2 = a0, a1, a2
            r0, r1, r2 = a0 * cp + n0 * sp, a1 * cp + n1 * sp, a2 * cp + n2 * sp
        else:
            ca, sa = w[4, j], w[5, j]
            q0, q1, q2 = a0 * ca + n0 * sa, a1 * ca + n1 * sa, a2 * ca + n2 * sa
            u0, u1, u2 = n0 * ca - a0 * sa, n1 * ca - a1 * sa, n2 * ca - a2 * sa
            r0, r1, r2 = q0 * cp + u0 * sp, q1 * cp + u1 * sp, q2 * cp + u2 * sp
        P0[0, i], P0[1, i], P0[2, i] = q0, q1, q2
        if two:
            P1[0, i], P1[1, i], P1[2, i] = r0, r1, r2
        else:
            P1[0, i], P1[1, i], P1[2, i] = q0, q1, q2
        hard[i] = False


def _consts(dtype):
    return np.array([1.0, 2.0, 4.0, 1e-30], dtype)


def method_setup(mode, A, B, t0, dt, coeffs, start_left, count_max, ops, work=None):
    """The per-span arrays of :func:`.fused.phong`'s ``mode`` 4 (slerp: ``(psi, 1/sin
    psi)``), 5 (quadratic: ``(v, d1, d2)``) or 6 (angular: ``(p0, p1, 2 cos phi)``) from
    the end normals ``A``, ``B`` (3, S) in the dtype, ``t0``, ``dt`` in the dtype: the
    bits of ``K.SLERP.setup``, :func:`.fast._quadratic_setup`, :func:`.fast._angular_setup`
    with ``ops`` (``fused._DetOps``); arrays from ``work`` if given."""
    from chebnorm.methods import kernels as K

    from . import fast

    dtype = A.dtype.type
    S = A.shape[1]
    k = _consts(dtype)
    is64 = dtype is np.float64
    quick = is64 and fused.trig_calibrated()
    parts = _parts(S)
    if mode == 4:
        psi, inv = _empty(work, "sc", S, dtype), _empty(work, "sc2", S, dtype)
        hard = _empty(work, "hard2", S, np.bool_)
        nh = sum(_run([(_slerp_part, (A, B, k, is64, quick, lo, hi, psi, inv, hard))
                       for lo, hi in parts]))
        if nh:
            h = np.flatnonzero(hard)
            st = K.SLERP.setup(ops, tuple(A[:, h]), tuple(B[:, h]))
            psi[h], inv[h] = st["psi"], st["inv"]
        return psi, inv
    if mode == 5:
        cf = np.array([0.0] if coeffs is None else [dtype(c) for c in coeffs], dtype)
        V, D1, D2 = (_empty(work, name, (3, S), dtype) for name in ("P0", "P1", "P2"))
        _run([(_quadratic_part, (A, B, t0, dt, k, cf, coeffs is None, start_left, lo, hi, V, D1,
                                 D2)) for lo, hi in parts])
        return V, D1, D2
    P0, P1 = _empty(work, "P0", (3, S), dtype), _empty(work, "P1", (3, S), dtype)
    K2, hard = _empty(work, "sc", S, dtype), _empty(work, "hard2", S, np.bool_)
    nh = sum(_run([(_angular_part, (A, B, t0, dt, k, is64, quick, count_max >= 2, start_left,
                                    lo, hi, P0, P1, K2, hard)) for lo, hi in parts]))
    if nh:
        h = np.flatnonzero(hard)
        p0, p1, k2 = fast._angular_setup(ops, tuple(A[:, h]), tuple(B[:, h]), t0[h], dt[h],
                                         count_max, start_left)
        P0[:, h], P1[:, h], K2[h] = p0, p1, k2
    return P0, P1, K2


# -------------------------------------------------------------- projection
@_njit()
def _project(pts, eye, frame, fa, f, width, height, xy, inv_w):
    """:func:`.spans.project` of ``pts (V, 3)``: ``(pts - eye) @ frame.T`` summed as
    OpenBLAS does (``fma(d2, F2, fma(d1, F1, d0 F0))``, checked by :func:`_gemm_fma`),
    then the reference's divisions; False if a point is not in front of the camera."""
    ok = True
    for i in range(pts.shape[0]):
        d0, d1, d2 = pts[i, 0] - eye[0], pts[i, 1] - eye[1], pts[i, 2] - eye[2]
        p0 = fused._fma(d2, frame[0, 2], fused._fma(d1, frame[0, 1], d0 * frame[0, 0]))
        p1 = fused._fma(d2, frame[1, 2], fused._fma(d1, frame[1, 1], d0 * frame[1, 0]))
        p2 = fused._fma(d2, frame[2, 2], fused._fma(d1, frame[2, 1], d0 * frame[2, 0]))
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
    if not fused.HAVE_NUMBA:
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
    """:func:`.spans.project` (the same bits and errors), compiled where
    :func:`_gemm_fma` holds.

    >>> from chebnorm.raster.spans import default_camera, project as ref
    >>> cam = default_camera((0.0, 0.0, 0.0), 1.0)
    >>> p = np.random.default_rng(1).standard_normal((50, 3)) * 0.3
    >>> all(a.tobytes() == b.tobytes() for a, b in zip(project(cam, p, 64, 48),
    ...                                                  ref(cam, p, 64, 48)))
    True
    """
    pts = np.asarray(points, float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 2 or not _gemm_fma():
        return _ref_project(camera, points, width, height)
    frame = camera.frame()
    f = 1.0 / math.tan(camera.fov_y / 2)
    fa = f / (width / height)
    xy, inv_w = np.empty((len(pts), 2)), np.empty(len(pts))
    if not _project(np.ascontiguousarray(pts), np.asarray(camera.eye, float),
                    np.ascontiguousarray(frame), float(fa), float(f), float(width),
                    float(height), xy, inv_w):
        return _ref_project(camera, points, width, height)
    return xy, inv_w


# --------------------------------------------------------------- row spans
@_njit()
def _row_geom_part(xy, width, first, ids, rlo, rhi, row_n, gc, ga, ge, gs):
    """Rows ``rlo .. rhi-1`` of :func:`.fused.row_spans`: the geometry of every (row,
    triangle) pair ``q`` of the row buckets (:func:`.fused._span_geom`: count ``gc``, first
    pixel ``ga``, edges and swap packed in ``ge``, ``sa, sb, xl, xr`` in ``gs``) and each
    row's number of spans into ``row_n[r + 1]``."""
    for r in range(rlo, rhi):
        n = 0
        for q in range(first[r], first[r + 1]):
            c, a, pa, qa, sa, p, qq, sb, swap, xl, xr = fused._span_geom(xy, ids[q], r, width)
            gc[q] = c
            if c <= 0:
                continue
            ga[q] = a
            ge[q] = pa | (qa << 2) | (p << 4) | (qq << 6) | (np.int64(swap) << 8)
            gs[q, 0] = sa
            gs[q, 1] = sb
            gs[q, 2] = xl
            gs[q, 3] = xr
            n += 1
        row_n[r + 1] = n


@_njit()
def _row_write_part(attrs, first, ids, rlo, rhi, row_start, gc, ga, ge, gs, tri, row, c0, count,
                    m, t0, dt, left, right):
    """Rows ``rlo .. rhi-1``: the spans from the geometry of :func:`_row_geom_part`
    (:func:`.fused._span_write`), row ``r``'s from ``row_start[r]`` on."""
    for r in range(rlo, rhi):
        n = row_start[r]
        for q in range(first[r], first[r + 1]):
            c = gc[q]
            if c <= 0:
                continue
            e = ge[q]
            fused._span_write(attrs, ids[q], r, n, c, ga[q], e & 3, (e >> 2) & 3, gs[q, 0],
                              (e >> 4) & 3, (e >> 6) & 3, gs[q, 1], (e >> 8) != 0, gs[q, 2],
                              gs[q, 3], tri, row, c0, count, m, t0, dt, left, right)
            n += 1


def row_spans(xy, attrs, width, height, work=None):
    """:func:`.fused.row_spans` (the same arrays), the geometry of each (row, triangle)
    pair computed once (the count pass keeps it for the write pass); with ``work`` (a
    :class:`Workspace`, for the geometry) the spans are ``fused.row_spans(...,
    reuse=True)``'s views of this thread's buffers.

    >>> xy = np.array([[[0.0, 0.0], [8.0, 0.0], [0.0, 6.0]], [[1.0, 0.5], [7.0, 1.5], [2.0, 5.0]]])
    >>> a, b = row_spans(xy, np.ones((2, 3, 1)), 8, 6), fused.row_spans(xy, np.ones((2, 3, 1)), 8, 6)
    >>> all((getattr(a, k) == getattr(b, k)).all() for k in ("tri", "row", "x0", "t0", "left"))
    True
    """
    from . import fast

    xy = np.ascontiguousarray(xy, dtype=np.float64)
    attrs = np.ascontiguousarray(attrs, dtype=np.float64)
    height = int(height)
    r0, nrows = fast._count_rows(np.ascontiguousarray(xy[..., 1]), height)
    first, ids = fused._row_buckets(r0, nrows, height)
    Kc = attrs.shape[2]
    P = int(first[-1])
    # row ranges of about equal numbers of (row, triangle) pairs
    k = _threads()
    cuts = [0] + [int(np.searchsorted(first, first[-1] * q / k)) for q in range(1, k)] + [height]
    parts = [(cuts[q], cuts[q + 1]) for q in range(k) if cuts[q] < cuts[q + 1]]
    row_start = _empty(work, "row_start", height + 1, np.int64)
    row_start[0] = 0
    geom = (_empty(work, "gc", P, np.int64), _empty(work, "ga", P, np.int64),
            _empty(work, "ge", P, np.int64), _empty(work, "gs", (P, 4)))
    _run([(_row_geom_part, (xy, int(width), first, ids, lo, hi, row_start, *geom))
          for lo, hi in parts])
    np.cumsum(row_start, out=row_start)
    S = int(row_start[-1])
    out = fused._span_arrays(S, Kc) if work is None else fused._span_buffers(S, Kc)
    _run([(_row_write_part, (attrs, first, ids, lo, hi, row_start, *geom, *out))
          for lo, hi in parts])
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
