"""Per-span set-up of the compiled ``phong`` frame (:func:`.frame.phong`): the checks and
per-span values of :func:`chebnorm.methods.spans.check_span_input` on the spans' unit
end normals, the widest span angle the table choice needs
(:func:`chebnorm.raster.engines.base.auto_tables`), and the per-method span set-up,
with the bits of the numpy reference.

The reference stays the reference: every value here is what it computes, in its
operation order (the ``np.linalg.norm`` and ``einsum`` sums in the orders
:func:`.calibration.ends_orders` finds), and wherever a check fails, or a value lands
where this code cannot promise the reference's bits (a dichotomy depth whose ``log2``
is within 1e-6 of an integer, a table's coverage test that is not clear-cut, a float32
sine or cosine whose rounding is in doubt), the reference functions run instead, on
those spans or on all, so the user gets exactly the reference's values and errors.
"""

from __future__ import annotations

import math
import platform
from functools import lru_cache
from types import SimpleNamespace

import numpy as np

from chebnorm.approx import CoefficientTable
from chebnorm.methods import kernels as K
from chebnorm.methods.registry import default_tables, method_kernel
from chebnorm.methods.spans import (ANTIPARALLEL_TOL, COVER_SLACK, MAX_LEVELS, PICK_TOL, UNIT_TOL,
                                    check_dtype, check_method, check_span_input, resolve_table,
                                    span_levels)

from ...meshes import unit
from .calibration import dot3, ends_orders, f32_round, sin_small, trig64, trig_calibrated
from .jit import HAVE_NUMBA, f2i, i2f, njit, run_with_caller, threads
from .kernels import angular_setup
from .workspace import scratch

# an implementation module of chebnorm.raster.engines.numba: the API is what chebnorm.raster.engines.numba exports
__all__: list[str] = []


#: the position tolerance of ``check_span_input`` (pixels at ``t`` in [-tol, 1 + tol])
_POS_TOL = 1e-9


#: margin (to an integer ``log2``, to a depth's cosine threshold) inside which numpy
#: computes a dichotomy depth
_NEAR_INT = 1e-6


#: ``cos(theta_max 2**n)``, ``theta_max = 2 acos(1 - PICK_TOL)`` of ``span_levels``, while
#: ``theta_max 2**n < pi`` (past the last, every span angle is below ``theta_max 2**n``)
DEPTH_THRESHOLDS = np.array([math.cos(2.0 * math.acos(1.0 - PICK_TOL) * 2.0 ** n) for n in range(8)
                        if 2.0 * math.acos(1.0 - PICK_TOL) * 2.0 ** n < math.pi])


@njit(inline=True)
def _depth_base(dt):
    """``(base, 2**base)``, ``base = max(e, 0)`` for ``1/dt = m 2**e`` (``m`` in [1/2, 1),
    :func:`math.frexp` by the bits: no library call), or ``(-1, 0)`` where ``m`` is
    within ``_NEAR_INT`` of 1/2 (``log2`` near an integer) or ``1/dt`` is zero,
    subnormal, negative or not finite: then numpy finds the depth."""
    bits = f2i(1.0 / dt)
    ex = (bits >> 52) & 0x7FF
    mm = i2f((bits & 0xFFFFFFFFFFFFF) | (np.int64(1022) << 52))
    if bits <= 0 or ex == 0 or ex == 0x7FF or mm < 0.5 * (1.0 + _NEAR_INT):
        return np.int64(-1), 0.0
    base = max(ex - 1022, 0)
    return base, i2f((base + 1023) << 52)


#: ``theta_max`` of ``span_levels`` (the largest node angle of the linear pick)
_THETA_MAX = 2.0 * math.acos(1.0 - PICK_TOL)


@njit()
def span_level_libm(dt, t0, count, cos):
    """The dichotomy depth of one span as :func:`chebnorm.methods.spans.span_levels`
    computes it, its ``log2`` and ``arccos`` the C library's (numba calls ``log2`` and
    ``acos``, as :mod:`chebnorm.methods.detmath` does through :func:`math.log2` and
    :func:`math.acos`; :func:`levels_calibrated` checks that they agree), for the spans
    whose depth :func:`ends_part` leaves to the reference; -1 where ``1/dt`` is not a
    finite normal number (the reference's own function decides those).

    Parameters
    ----------
    dt, t0 : float
        The span's step and first position.
    count : int
        Its pixels.
    cos : float
        ``N_l.N_r``.

    Returns
    -------
    int
        The depth, or -1.

    Examples
    --------
    >>> from chebnorm.methods.spans import span_levels
    >>> int(span_levels([0.25], [0.1], [3], [0.9])[0]) == span_level_libm(0.25, 0.1, 3, 0.9)
    True
    """
    bits = f2i(1.0 / dt)
    ex = (bits >> 52) & 0x7FF
    if bits <= 0 or ex == 0 or ex == 0x7FF:
        return -1
    base = np.int64(max(np.ceil(np.log2(1.0 / dt) - 1e-12), 0.0))
    scale = i2f((base + 1023) << 52)      # np.ldexp(1.0, base), exactly
    off = False
    for j in range(count):
        u = (t0 + j * dt) * scale
        if abs(u - np.rint(u)) > 1e-9 * max(1.0, abs(u)):
            off = True
            break
    if not off:
        return base
    psi = np.arccos(min(max(cos, -1.0), 1.0))
    need = np.int64(max(np.ceil(np.log2(max(psi, 1e-300) / _THETA_MAX)), 0.0))
    return max(base, need)


@lru_cache(maxsize=1)
def levels_calibrated() -> bool:
    """Whether compiled code's ``log2`` and ``arccos`` give :func:`math.log2`'s and
    :func:`math.acos`'s bits (the reference's, :mod:`chebnorm.methods.detmath`) on
    probes around every power of two the depths meet and over ``[-1, 1]``, and
    :func:`span_level_libm` the reference's depths on spans near its hard cases.

    Returns
    -------
    bool
        True where :func:`span_level_libm` may stand in for ``span_levels``.

    Examples
    --------
    >>> levels_calibrated() == (HAVE_NUMBA and platform.libc_ver()[0] == "glibc")
    True
    """
    if not HAVE_NUMBA or platform.libc_ver()[0] != "glibc":
        return False
    rng = np.random.default_rng(20261128)
    ulps = 1.0 + np.arange(-16, 17) * 2.0 ** -52
    x = np.concatenate([(2.0 ** np.arange(-20, 40)[:, None] * ulps).ravel(),
                        2.0 ** rng.uniform(-20, 40, 20_000)])
    c = np.concatenate([rng.uniform(-1.0, 1.0, 20_000), np.cos(_THETA_MAX * 2.0 ** np.arange(8)),
                        [-1.0, 1.0, 0.0]])
    got_l, got_a = _libm_pair(x, c)
    if (got_l.tobytes() != np.array([math.log2(v) for v in x]).tobytes()
            or got_a.tobytes() != np.array([math.acos(v) for v in c]).tobytes()):
        return False
    dt = 1.0 / np.concatenate([(2.0 ** np.arange(0, 12)[:, None] * ulps).ravel(),
                               rng.uniform(1.0, 64.0, 2_000)])
    t0 = rng.uniform(0.0, 0.5, dt.size) * dt
    count = rng.integers(1, 9, dt.size)
    cos = rng.uniform(0.3, 1.0, dt.size)
    ref = span_levels(dt, t0, count, cos)
    got = np.array([span_level_libm(a, b, n, q) for a, b, n, q in zip(dt, t0, count, cos)])
    return got.tobytes() == ref.astype(np.int64).tobytes()


@njit()
def _libm_pair(x, c):
    """``log2(x)`` and ``arccos(c)`` element by element, compiled."""
    a, b = np.empty(x.shape[0]), np.empty(c.shape[0])
    for i in range(x.shape[0]):
        a[i] = np.log2(x[i])
    for i in range(c.shape[0]):
        b[i] = np.arccos(c[i])
    return a, b


@njit()
def ends_part(left, right, m, t0, dt, count, o_ein, o_norm, tree, thr, lo, hi, A, B,
              diff, cos, levels, hard, red, dsc):
    """Spans ``lo .. hi-1``: the unit end normals ``unit(left[:, 1:4])``,
    ``unit(right[:, 1:4])`` in the dtype of ``A``, ``B`` (3, S) (``diff``: ``B - A``
    into ``B``), their cosine as ``check_span_input`` computes it, and (``tree``) the
    dichotomy depth of ``span_levels`` (``hard[i]``: the depth is numpy's to compute).
    ``red``: [any check failed, smallest ``N_l.N_r`` (einsum), any ``t0 != 0``, largest
    count, hard spans]; ``dsc``: scratch (the spans' ``N_l.N_r``).

    The normals, cosines and checks are one loop of arithmetic and comparisons alone
    (LLVM vectorizes it; NaN and infinities fail its comparisons), the depths a loop of
    their own.  Where a check fails the caller stops (the reference's checks then raise),
    so the other outputs are only promised where none does."""
    nbad = 0
    t0nz = 0
    cmax = 0
    for i in range(lo, hi):
        a0, a1, a2, b0, b1, b2 = _unit_ends(left, right, i, o_norm)
        A[0, i], A[1, i], A[2, i] = a0, a1, a2
        B[0, i], B[1, i], B[2, i] = b0, b1, b2
        if diff:
            for c in range(3):
                B[c, i] = B[c, i] - A[c, i]
        hard[i] = False
        # _as_vectors: | |N| - 1 | <= UNIT_TOL, |N| by einsum; the cosine's |N| by norm
        qa = np.sqrt(dot3(a0, a1, a2, a0, a1, a2, o_ein))
        qb = np.sqrt(dot3(b0, b1, b2, b0, b1, b2, o_ein))
        fine = (abs(qa - 1.0) <= UNIT_TOL) & (abs(qb - 1.0) <= UNIT_TOL)
        if o_norm != o_ein:
            qa = np.sqrt(dot3(a0, a1, a2, a0, a1, a2, o_norm))
            qb = np.sqrt(dot3(b0, b1, b2, b0, b1, b2, o_norm))
        d = dot3(a0, a1, a2, b0, b1, b2, o_ein)
        c = d / (qa * qb)
        cos[i] = c
        dsc[i] = d
        # _positions (count - 1 through int32: it converts to float64 four lanes at once)
        ti, di, ci = t0[i], dt[i], count[i]
        last = ti + np.float64(np.int32(ci - 1)) * di
        fine &= ((1.0 + c > ANTIPARALLEL_TOL) & (abs(ti) < np.inf) & (abs(di) < np.inf)
                 & (m[i] >= 1) & (di > 0.0) & (ci >= 1) & (ti >= -_POS_TOL)
                 & (last <= 1.0 + _POS_TOL))
        nbad += not fine
        t0nz |= ti != 0.0
        cmax = max(cmax, ci)
    dmin = np.inf
    for i in range(lo, hi):
        dmin = min(dmin, dsc[i])
    nhard = 0
    if tree:
        for i in range(lo, hi):
            # span_levels: the base depth ceil(log2(1/dt) - 1e-12), the exponent of 1/dt
            # (a mantissa near 1/2: log2 near an integer, numpy's to round) ...
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
                # ... then off the grid ceil(log2(arccos(c) / theta_max)): the smallest
                # n >= 0 with c >= cos(theta_max 2**n) (thr[n]; 7 past the last), c near a
                # threshold numpy's to round
                cc = min(max(cos[i], -1.0), 1.0)
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
            nbad += L > MAX_LEVELS
    red[0] = 1.0 if nbad > 0 else 0.0
    red[1] = dmin
    red[2] = 1.0 if t0nz else 0.0
    red[3] = cmax
    red[4] = nhard


@njit(inline=True)
def _unit_ends(left, right, i, o_norm):
    """Span ``i``'s end normals (columns 1-3 of ``left``, ``right``) divided by their
    ``np.linalg.norm`` (summed in order ``o_norm``), as ``unit`` computes them."""
    a0, a1, a2 = left[i, 1], left[i, 2], left[i, 3]
    r = np.sqrt(dot3(a0, a1, a2, a0, a1, a2, o_norm))
    b0, b1, b2 = right[i, 1], right[i, 2], right[i, 3]
    q = np.sqrt(dot3(b0, b1, b2, b0, b1, b2, o_norm))
    return a0 / r, a1 / r, a2 / r, b0 / q, b1 / q, b2 / q


@njit()
def end_checks(left, right, m, t0, dt, count, o_ein, o_norm, n, A, B, diff=True):
    """The unit end normals of spans ``0 .. n-1`` into ``A`` and ``B - A`` (a linear
    method; ``diff`` False: ``B``) into ``B`` ((3, n), their dtype), as :func:`ends_part`
    computes them, and
    whether every check of ``check_span_input`` passes on them (False: one fails).  The
    fused frame's per-row set-up (:func:`chebnorm.raster.engines.numba.frame.phong`).

    Only the outcome of the checks is wanted here (no cosines, no depths), so two of
    them take a shortcut that decides as the reference does: ``| |N| - 1 | <= UNIT_TOL``
    holds wherever ``|N.N - 1| <= UNIT_TOL`` (``| |N| - 1 | = |N.N - 1| / (|N| + 1)``, half
    of that, and the square root's rounding is far below the other half), and the
    cosine ``N_l.N_r / (|N_l| |N_r|)`` of two such normals is above ``-1 + ANTIPARALLEL_TOL``
    wherever ``N_l.N_r > -1/2``; elsewhere the reference's own expressions decide.

    Parameters
    ----------
    left, right : numpy.ndarray
        The spans' end attributes ``(>= n, K)``, the normal in columns 1-3.
    m, t0, dt, count : numpy.ndarray
        The spans' pixel counts and steps, as :func:`.rasterize.row_spans` gives them.
    o_ein, o_norm : int
        The summation orders of :func:`.calibration.ends_orders`.
    n : int
        The number of spans.
    A, B : numpy.ndarray
        The outputs described above.
    diff : bool, optional
        ``B - A`` into ``B`` (the linear methods' difference), else ``B``.

    Returns
    -------
    bool
        Whether every check passed.
    """
    # one loop of arithmetic and comparisons alone (LLVM vectorizes it): the normals, and
    # whether every span is clearly fine; NaN and infinities fail its comparisons
    easy = 0
    for i in range(n):
        a0, a1, a2, b0, b1, b2 = _unit_ends(left, right, i, o_norm)
        A[0, i], A[1, i], A[2, i] = a0, a1, a2
        B[0, i], B[1, i], B[2, i] = b0, b1, b2
        if diff:
            B[0, i] -= A[0, i]           # in the dtype, as the reference subtracts
            B[1, i] -= A[1, i]
            B[2, i] -= A[2, i]
        ti, di = t0[i], dt[i]
        last = ti + (count[i] - 1) * di
        sa = dot3(a0, a1, a2, a0, a1, a2, o_ein)
        sb = dot3(b0, b1, b2, b0, b1, b2, o_ein)
        d = dot3(a0, a1, a2, b0, b1, b2, o_ein)
        easy += ((abs(sa - 1.0) <= UNIT_TOL) & (abs(sb - 1.0) <= UNIT_TOL) & (d > -0.5)
                 & (m[i] >= 1) & (count[i] >= 1) & (di > 0.0) & (di < np.inf)
                 & (ti >= -_POS_TOL) & (last <= 1.0 + _POS_TOL))
    if easy == n:
        return True
    # some span is not clearly fine: the reference's checks, span by span
    ok = True
    for i in range(n):
        a0, a1, a2, b0, b1, b2 = _unit_ends(left, right, i, o_norm)
        if not (np.isfinite(a0) and np.isfinite(a1) and np.isfinite(a2) and np.isfinite(b0)
                and np.isfinite(b1) and np.isfinite(b2) and np.isfinite(t0[i])
                and np.isfinite(dt[i])):
            ok = False
            continue
        # ends_part's expressions
        qa = np.sqrt(dot3(a0, a1, a2, a0, a1, a2, o_ein))
        qb = np.sqrt(dot3(b0, b1, b2, b0, b1, b2, o_ein))
        if abs(qa - 1.0) > UNIT_TOL or abs(qb - 1.0) > UNIT_TOL:
            ok = False
        if o_norm != o_ein:
            qa = np.sqrt(dot3(a0, a1, a2, a0, a1, a2, o_norm))
            qb = np.sqrt(dot3(b0, b1, b2, b0, b1, b2, o_norm))
        if 1.0 + dot3(a0, a1, a2, b0, b1, b2, o_ein) / (qa * qb) <= ANTIPARALLEL_TOL:
            ok = False
        if m[i] < 1 or dt[i] <= 0.0 or count[i] < 1:
            ok = False
        last = t0[i] + (count[i] - 1) * dt[i]
        if t0[i] < -_POS_TOL or last > 1.0 + _POS_TOL:
            ok = False
    return ok


@njit()
def cos_range(cos, levels, tree, n):
    """(smallest cosine, smallest cosine of a span with ``levels > 0``, any such span) of
    the first ``n`` spans, cosines clipped to [-1, 1] (the values ``_needed_range`` takes
    the minimum of; the row-by-row frame takes it row by row)."""
    lo = np.inf
    lo_deep = np.inf
    deep = False
    for i in range(n):
        c = min(max(cos[i], -1.0), 1.0)
        lo = min(lo, c)
        if tree and levels[i] > 0:
            deep = True
            lo_deep = min(lo_deep, c)
    return lo, lo_deep, deep


def _parts(n):
    k = min(threads(), max(1, n // 4096))
    cuts = [n * q // k for q in range(k + 1)]
    return [(cuts[q], cuts[q + 1]) for q in range(k) if cuts[q] < cuts[q + 1]]


class _Ends:
    """What the compiled pass over the spans found (see :func:`ends_part`)."""

    def __init__(self, sp, tree, orders, dtype, diff, work):
        S = len(sp.count)
        left, right = sp.left, sp.right
        self.A, self.B = scratch(work, "A", (3, S), dtype), scratch(work, "B", (3, S), dtype)
        self.cos = scratch(work, "cos", S)
        self.levels = scratch(work, "levels", S, np.int64)
        self.hard = scratch(work, "hard", S, np.bool_)
        dsc = scratch(work, "dsc", S)
        parts = _parts(S)
        red = np.zeros((len(parts), 5))
        run_with_caller([(ends_part, (left, right, sp.m, sp.t0, sp.dt, sp.count, orders[0],
                                       orders[1], tree, DEPTH_THRESHOLDS, lo, hi, self.A, self.B,
                                       diff, self.cos, self.levels, self.hard, red[q], dsc))
                         for q, (lo, hi) in enumerate(parts)])
        self.bad = bool(red[:, 0].any())
        self.dot_min = np.float64(red[:, 1].min())
        self.start_left = not red[:, 2].any()
        self.count_max = int(red[:, 3].max())
        # depths numpy computes (log2 near an integer); where a check failed the reference
        # runs instead (its depths are not wanted)
        if tree and not self.bad and red[:, 4].any():
            h = np.flatnonzero(self.hard)
            self.levels[h] = span_levels(sp.dt[h], sp.t0[h], sp.count[h], self.cos[h])
            self.bad = self.bad or bool((self.levels[h] > MAX_LEVELS).any())


def widest_dot(sp, spec, dtype, diff, work=None):
    """``(ends, smallest N_l.N_r)`` of the spans' unit end normals (the einsum of
    ``auto_tables``) for method ``spec``, the normals in ``dtype`` (if float32
    or float64; ``diff``: see :func:`ends_part`); ``(ends, None)`` when a check of
    ``check_span_input`` fails on them, ``(None, None)`` without :func:`ends_orders`
    (then the reference runs); arrays from ``work`` (a :class:`Workspace`) if given.

    Parameters
    ----------
    sp : Spans
        The frame's spans.
    spec : MethodSpec
        The method's registry entry.
    dtype : numpy dtype
        The arithmetic.
    diff : object
        The end-normal summation orders.
    work : Workspace, optional
        Scratch arrays.

    Returns
    -------
    tuple
        ``(ends, smallest N_l.N_r)`` as described above.
    """
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


def clear_table(spec, tables, c_lo):
    """``(True, table)`` where the table of method ``spec`` in ``tables`` (None or absent:
    the default) clearly covers spans whose smallest cosine is ``c_lo`` (clipped to
    [-1, 1]; None: no span needs it) or is None; ``(False, None)`` where
    ``resolve_table`` must decide (see :func:`_table`)."""
    method = spec.name
    defaults = tables is None or method not in tables
    table = default_tables()[method] if defaults else tables[method]
    if table is None:
        return True, None
    if isinstance(table, CoefficientTable):
        if c_lo is None:
            return True, table
        scale = float(method_kernel(spec).table_scale)
        lo, hi = table.interval_float
        need_lo = scale * float(c_lo)
        if hi >= scale and not lo > need_lo + COVER_SLACK:
            return True, table
    return False, None


def _table(spec, tables, ends, tree):
    """``resolve_table(spec, tables, cos, levels)``: the reference runs unless the table
    clearly covers the spans (its upper end at ``table_scale``, its lower end below what
    the spans need, a comparison of exact values)."""
    c_lo, c_lo_deep, deep = cos_range(ends.cos, ends.levels, tree, ends.cos.shape[0])
    clear, table = clear_table(spec, tables, None if tree and not deep
                               else (c_lo_deep if tree else c_lo))
    if clear:
        return table
    return resolve_table(spec, tables, ends.cos, ends.levels if tree else None)


def span_input(spec, sp, tables, dtype, ends, diff):
    """What :func:`~chebnorm.raster.engines.numba.frame.phong` takes from ``check_span_input(spec, unit(sp.left[:, [1,
    2, 3]]), unit(sp.right[:, [1, 2, 3]]), sp.m, t0=sp.t0, dt=sp.dt, count=sp.count,
    tables=tables, dtype=dtype)``, from the compiled pass ``ends`` (:func:`widest_dot`),
    the same values and the same errors: ``(dtype, coefficients, levels, A, B, t0 all
    zero, largest count)``, ``A``, ``B`` the end normals (3, S) in the dtype
    (``diff``: ``B - A`` for ``B``).

    Parameters
    ----------
    spec : MethodSpec
        The method's registry entry.
    sp : Spans
        The frame's spans.
    tables : dict or None
        Coefficient tables by method name.
    dtype : numpy dtype
        float32 or float64.
    ends : object
        The compiled pass's end normals (:func:`widest_dot`).
    diff : object
        The end-normal summation orders.

    Returns
    -------
    tuple
        The values listed above.

    Raises
    ------
    ValueError
        As :func:`chebnorm.methods.spans.check_span_input`.
    """
    if ends is None or ends.bad:
        # the reference, on the spans in its order (triangle, row): its errors name spans
        # by that order
        cols = [1, 2, 3]
        order = np.lexsort((sp.row, sp.tri)) if hasattr(sp, "row") else np.arange(len(sp.m))
        left, right = sp.left[order], sp.right[order]
        inp = check_span_input(spec, unit(left[:, cols]), unit(right[:, cols]), sp.m[order],
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
    spec = check_method(spec)
    dtype = check_dtype(dtype)
    tree = method_kernel(spec).shape == "tree"
    table = _table(spec, tables, ends, tree) if spec.table is not None else None
    coeffs = None if table is None else table.coefficients
    return (dtype, coeffs, ends.levels if tree else None, ends.A, ends.B, ends.start_left,
            ends.count_max)


# ------------------------------------------------------------ per-mode set-up
@njit()
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
    """``(A, B)`` of :func:`~chebnorm.raster.engines.numba.frame.phong`: the end normals in ``dtype``, (3, S), and
    (``diff``) ``B - A`` instead of ``B``.

    Parameters
    ----------
    inp : tuple
        What :func:`span_input` derived.
    dtype : numpy dtype
        float32 or float64.
    diff : object
        The end-normal summation orders (see :func:`widest_dot`).

    Returns
    -------
    tuple of numpy.ndarray
        ``(A, B)``, each ``(3, S)``.
    """
    S = inp.n_left.shape[0]
    A, B = np.empty((3, S), dtype), np.empty((3, S), dtype)
    parts = _parts(S)
    if len(parts) == 1:
        _linear_setup(inp.n_left, inp.n_right, A, B, diff)
    else:
        run_with_caller([(_linear_setup, (inp.n_left[lo:hi], inp.n_right[lo:hi], A[:, lo:hi],
                                          B[:, lo:hi], diff)) for lo, hi in parts])
    return A, B


@njit(inline=True)
def _trig(kind, x, is64, buf):
    """``sin`` (0), ``cos`` (1) or ``arccos`` (2) of ``x`` in the dtype of ``buf``, and
    whether its float32 rounding is in doubt (:func:`f32_round`)."""
    v = np.float64(x)
    y = np.sin(v) if kind == 0 else (np.cos(v) if kind == 1 else np.arccos(v))
    buf[0] = y
    if is64:
        return buf[0], False
    r, h = f32_round(y)
    return buf[0], h


@njit()
def slerp_part(A, B, k, is64, fast, lo, hi, psi_out, inv_out, hard):
    """``psi = max(arccos(min(N_l.N_r, 1)), TINY)``, ``inv = 1/sin(psi)`` (``fast``: the
    float64 sines by :func:`sin_small`)."""
    if is64 and fast:
        # in blocks of _BLOCK spans: the scratch rows stay in the cache
        w = np.empty((6, _BLOCK))
        ok = np.empty(_BLOCK, np.bool_)
        for b0 in range(lo, hi, _BLOCK):
            m = min(hi - b0, _BLOCK)
            for j in range(m):
                i = b0 + j
                d = A[0, i] * B[0, i] + A[1, i] * B[1, i] + A[2, i] * B[2, i]
                w[0, j] = max(np.arccos(min(d, k[0])), k[3])
            sin_small(w[0], psi_out[b0:b0 + m], ok, m)
            for j in range(m):
                i = b0 + j
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


@njit()
def quadratic_part(A, B, t0, dt, k, coeffs, exact, start_left, lo, hi, V, D1, D2):
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


@njit()
def angular_part(A, B, t0, dt, k, is64, fast, two, start_left, lo, hi, P0, P1, K2, hard):
    """The first two pixels of ``angular_steps`` (``two``: the frame has spans of two
    or more pixels, else ``P1 = P0``) and ``2 cos(phi)`` (``fast``: the float64 sines
    by :func:`sin_small`, cosines by :func:`trig64`, :func:`_angular_fast`)."""
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


@njit()
def _angular_fast(A, B, t0, dt, k, two, start_left, lo, hi, P0, P1, K2, hard):
    """:func:`angular_part` in float64, its cosines and sines of ``phi`` and of the
    start angle computed for the spans ``lo .. hi-1`` at once (:func:`trig64`,
    :func:`sin_small`)."""
    # in blocks of _BLOCK spans: the scratch rows stay in the cache
    w = np.empty((11, _BLOCK))
    ok = np.empty(_BLOCK, np.bool_)
    for b0 in range(lo, hi, _BLOCK):
        _angular_block(A, B, t0, dt, k, two, start_left, b0, min(hi, b0 + _BLOCK), P0, P1,
                       K2, hard, w, ok)


@njit(inline=True)
def _angular_block(A, B, t0, dt, k, two, start_left, lo, hi, P0, P1, K2, hard, w, ok):
    """:func:`_angular_fast` on the spans ``lo .. hi-1`` (at most ``_BLOCK``)."""
    m = hi - lo
    for j in range(m):
        i = lo + j
        c = min(A[0, i] * B[0, i] + A[1, i] * B[1, i] + A[2, i] * B[2, i], k[0])
        psi = np.arccos(c)
        w[0, j] = psi * dt[i]
        w[1, j] = t0[i] * psi
    trig64(1, w[0], w[2], ok, w[6:], m)
    sin_small(w[0], w[3], ok, m)
    if not start_left:
        trig64(1, w[1], w[4], ok, w[6:], m)
        sin_small(w[1], w[5], ok, m)
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


#: spans per block of the float64 slerp and angular set-up (scratch rows of this length)
_BLOCK = 512


def setup_consts(dtype):
    """The constants ``(1, 2, 4, 1e-30)`` in ``dtype`` that :func:`slerp_part`,
    :func:`quadratic_part` and :func:`angular_part` take (``k``).

    Parameters
    ----------
    dtype : type
        ``numpy.float32`` or ``numpy.float64``.

    Returns
    -------
    numpy.ndarray
        The four constants.
    """
    return np.array([1.0, 2.0, 4.0, 1e-30], dtype)


def method_setup(mode, A, B, t0, dt, coeffs, start_left, count_max, ops, work=None):
    """The per-span arrays of :func:`~chebnorm.raster.engines.numba.frame.phong`'s ``mode`` 4 (slerp: ``(psi, 1/sin
    psi)``), 5 (quadratic: ``(v, d1, d2)``) or 6 (angular: ``(p0, p1, 2 cos phi)``) from
    the end normals ``A``, ``B`` (3, S) in the dtype, ``t0``, ``dt`` in the dtype: the
    bits of ``K.SLERP.setup``, :func:`quadratic_setup`, :func:`angular_setup`
    with ``ops`` (``DetOps``); arrays from ``work`` if given.

    Parameters
    ----------
    mode : int
        4 (slerp), 5 (quadratic) or 6 (angular).
    A, B : numpy.ndarray
        End normals ``(3, S)`` in the dtype.
    t0, dt : numpy.ndarray
        First position and step per span.
    coeffs : sequence of float or None
        The table's coefficients (None: exact).
    start_left : bool
        The first pixel is ``N_l`` itself.
    count_max : int
        The largest pixel count of a span.
    ops : DetOps
        The arithmetic backend.
    work : Workspace, optional
        Scratch arrays.

    Returns
    -------
    tuple of numpy.ndarray
        The per-span set-up arrays of the mode.
    """
    dtype = A.dtype.type
    S = A.shape[1]
    k = setup_consts(dtype)
    is64 = dtype is np.float64
    quick = is64 and trig_calibrated()
    parts = _parts(S)
    if mode == 4:
        psi, inv = scratch(work, "sc", S, dtype), scratch(work, "sc2", S, dtype)
        hard = scratch(work, "hard2", S, np.bool_)
        nh = sum(run_with_caller([(slerp_part, (A, B, k, is64, quick, lo, hi, psi, inv, hard))
                                  for lo, hi in parts]))
        if nh:
            h = np.flatnonzero(hard)
            st = K.SLERP.setup(ops, tuple(A[:, h]), tuple(B[:, h]))
            psi[h], inv[h] = st["psi"], st["inv"]
        return psi, inv
    if mode == 5:
        cf = np.array([0.0] if coeffs is None else [dtype(c) for c in coeffs], dtype)
        V, D1, D2 = (scratch(work, name, (3, S), dtype) for name in ("P0", "P1", "P2"))
        run_with_caller([(quadratic_part, (A, B, t0, dt, k, cf, coeffs is None, start_left, lo,
                                            hi, V, D1, D2)) for lo, hi in parts])
        return V, D1, D2
    P0, P1 = scratch(work, "P0", (3, S), dtype), scratch(work, "P1", (3, S), dtype)
    K2, hard = scratch(work, "sc", S, dtype), scratch(work, "hard2", S, np.bool_)
    nh = sum(run_with_caller([(angular_part, (A, B, t0, dt, k, is64, quick, count_max >= 2,
                                               start_left, lo, hi, P0, P1, K2, hard))
                              for lo, hi in parts]))
    if nh:
        h = np.flatnonzero(hard)
        p0, p1, k2 = angular_setup(ops, tuple(A[:, h]), tuple(B[:, h]), t0[h], dt[h],
                                         count_max, start_left)
        P0[:, h], P1[:, h], K2[h] = p0, p1, k2
    return P0, P1, K2
