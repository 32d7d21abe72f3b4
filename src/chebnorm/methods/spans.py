"""``span_normals``: the public span interpolator and its input validation.

Methods, their kernels and tables come from the method registry
(:mod:`chebnorm.approx.method_registry`, bound in :mod:`.registry`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from chebnorm.approx import CoefficientTable, get_target
from chebnorm.core.display import summary_html, summary_repr
from chebnorm.approx.method_registry import MethodSpec, get_method

from . import detmath
from .ops import NumpyOps
from .registry import default_tables, method_kernel

# an implementation module of chebnorm.methods: the API is what chebnorm.methods exports
__all__: list[str] = []

#: accepted | |N| - 1 | of an end normal
UNIT_TOL = 1e-5
#: accepted smallest 1 + N_l.N_r / (|N_l| |N_r|) (angle between end normals below pi)
ANTIPARALLEL_TOL = 1e-6
#: deepest dichotomy (steps down to 2**-MAX_LEVELS)
MAX_LEVELS = 20
#: the dtypes a method computes in
DTYPES = (np.float32, np.float64)
#: slack on a table's interval when checking that it covers the spans' range
#: (rounding of N_l.N_r; the polynomial is smooth just outside its interval)
COVER_SLACK = 1e-9


@dataclass(frozen=True)
class SpanNormals:
    """Pixel normals of S spans: span i's pixels are ``normals[offsets[i]:offsets[i+1]]``,
    at positions ``t[offsets[i]:offsets[i+1]]`` (0 at ``N_l``, 1 at ``N_r``).

    Attributes
    ----------
    normals : numpy.ndarray
        Every pixel normal, shape ``(P, 3)``, in the dtype of the computation.
    offsets : numpy.ndarray
        ``S + 1`` increasing indices into ``normals``.
    t : numpy.ndarray
        Each pixel's position along its span, shape ``(P,)``.

    Examples
    --------
    >>> r = span_normals("exact", [[1.0, 0, 0]], [[0.0, 1, 0]], [4])
    >>> r.offsets.tolist(), r.t.tolist()
    ([0, 5], [0.0, 0.25, 0.5, 0.75, 1.0])
    >>> np.round(r.span(0)[2], 6).tolist()   # t = 1/2: the normal at 45 degrees
    [0.707107, 0.707107, 0.0]
    """

    normals: np.ndarray   # (P, 3), dtype of the computation
    offsets: np.ndarray   # (S + 1,) int64
    t: np.ndarray         # (P,) float64

    def _summary(self) -> list[tuple[str, object]]:
        return [("spans", len(self.offsets) - 1), ("pixels", len(self.normals)),
                ("dtype", str(self.normals.dtype))]

    __repr__ = summary_repr
    _repr_html_ = summary_html

    def span(self, i: int) -> np.ndarray:
        """The normals of span ``i``."""
        return self.normals[self.offsets[i]:self.offsets[i + 1]]


# ------------------------------------------------------------ validation
def _as_vectors(name, a) -> np.ndarray:
    try:
        arr = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an array of shape (S, 3) of numbers") from None
    if arr.ndim == 1 and arr.shape == (3,):
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 3 or arr.shape[0] < 1:
        raise ValueError(f"{name} has shape {arr.shape}; accepted: (S, 3) with S >= 1")
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{name}[{i}] = {arr[i].tolist()} is not finite (NaN or inf); "
                         f"accepted: finite unit vectors")
    norm = np.sqrt(np.einsum("ij,ij->i", arr, arr))
    dev = np.abs(norm - 1.0)
    if (dev > UNIT_TOL).any():
        i = int(np.argmax(dev))
        what = "is zero" if norm[i] == 0 else f"has length {norm[i]:.9g}"
        raise ValueError(f"{name}[{i}] {what}; accepted: unit vectors, | |N| - 1 | <= {UNIT_TOL:g}")
    return arr


def _as_per_span(name, a, s, dtype, default):
    if a is None:
        return default
    arr = np.asarray(a)
    if arr.ndim == 0:
        arr = np.full(s, arr)
    if arr.shape != (s,):
        raise ValueError(f"{name} has shape {arr.shape}; accepted: ({s},), one value per span")
    try:
        out = arr.astype(dtype, casting="safe" if dtype is np.int64 else "unsafe")
    except TypeError:
        raise ValueError(f"{name} must hold {'integers' if dtype is np.int64 else 'numbers'}, "
                         f"got {arr.dtype}") from None
    if dtype is not np.int64 and not np.isfinite(out).all():
        raise ValueError(f"{name} holds NaN or inf; accepted: finite numbers")
    return out


def check_method(method) -> MethodSpec:
    """The registry entry of ``method`` (a name, or an entry already looked up); an
    unknown name is the registry's ValueError naming the accepted methods.

    Parameters
    ----------
    method : str or MethodSpec
        A method name or registry entry.

    Returns
    -------
    MethodSpec
        The registry entry.

    Raises
    ------
    ValueError
        For an unknown name, naming the registered methods.

    Examples
    --------

    Examples
    --------
    >>> check_method("exact").name
    'exact'
    """
    return method if isinstance(method, MethodSpec) else get_method(method)


def check_dtype(dtype):
    """The numpy scalar type of ``dtype`` if it is one of :data:`DTYPES` (float32,
    float64); ValueError naming the accepted ones otherwise.

    Parameters
    ----------
    dtype : object
        A numpy dtype, scalar type or name.

    Returns
    -------
    type
        ``numpy.float32`` or ``numpy.float64``.

    Raises
    ------
    ValueError
        For any other dtype, naming the accepted ones.

    Examples
    --------

    Examples
    --------
    >>> check_dtype("float32")
    <class 'numpy.float32'>
    """
    try:
        dt = np.dtype(dtype).type
    except TypeError:
        dt = None
    if dt not in DTYPES:
        raise ValueError(f"dtype {dtype!r} is not supported; accepted: float32, float64")
    return dt


def _angle_range_of_table(scale: float, table: CoefficientTable) -> tuple[float, float]:
    """(smallest, largest) angle between end normals the table's interval covers,
    the table's variable being ``scale * cos(angle)``."""
    lo, hi = table.interval_float
    big = math.acos(min(1.0, max(-1.0, lo / scale)))
    small = math.acos(min(1.0, max(-1.0, hi / scale)))
    return small, big


def _needed_range(scale, cosines, levels):
    """(lowest, highest) value of the table's variable the spans need (None: no table use)."""
    c = np.clip(cosines, -1.0, 1.0)
    if levels is None:
        return scale * float(np.min(c)), scale * float(np.max(c))
    if not (levels > 0).any():
        return None, None
    deepest = detmath.arccos(c) / np.ldexp(1.0, np.maximum(levels - 1, 0))
    return scale * float(np.min(c[levels > 0])), scale * float(np.max(np.cos(deepest[levels > 0])))


def resolve_table(spec, tables, cosines, levels):
    """The table for method ``spec`` (None: exact), checked to cover what the spans need
    (``levels``: the tree kernel's depth per span, None for the others): the caller's
    ``tables[spec.name]`` if given, else the registry's default; ValueError when it does
    not cover the end normals' cosines ``cosines``.

    Parameters
    ----------
    spec : MethodSpec
        The method's registry entry.
    tables : dict or None
        The caller's tables by method name.
    cosines : numpy.ndarray
        ``N_l.N_r`` per span.
    levels : numpy.ndarray or None
        The dichotomy depth per span.

    Returns
    -------
    CoefficientTable or None
        The table to use; None for exact denominators or a method without a table.

    Raises
    ------
    ValueError
        When the table does not cover the spans, naming the interval needed.

    Examples
    --------

    Examples
    --------
    >>> import numpy as np
    >>> spec = check_method("dichotomy")
    >>> type(resolve_table(spec, None, np.array([0.9]), np.array([2]))).__name__
    'CoefficientTable'
    >>> resolve_table(spec, {"dichotomy": None}, np.array([0.9]), np.array([2])) is None
    True
    """
    method = spec.name
    defaults = tables is None or method not in tables
    table = default_tables()[method] if defaults else tables[method]
    if table is None:
        return None
    if not isinstance(table, CoefficientTable):
        raise ValueError(f"tables[{method!r}] is a {type(table).__name__}; accepted: a "
                         f"CoefficientTable, or None for exact denominators")
    scale = float(method_kernel(spec).table_scale)
    need_lo, need_hi = _needed_range(scale, cosines, levels)
    if need_lo is None:
        return table
    lo, hi = table.interval_float
    small, big = _angle_range_of_table(scale, table)
    var = f"{get_target(spec.table.target).variable} = {'' if scale == 1 else f'{scale:g} '}cos(psi)"
    where = "the default" if defaults else "the given"
    if lo > need_lo + COVER_SLACK:
        psi = detmath.arccos(np.clip(cosines, -1.0, 1.0))
        raise ValueError(
            f"largest span angle {float(np.max(psi)):.9g} rad exceeds {where} {method} table "
            f"{table.name!r}: its interval [{lo:.9g}, {hi:.9g}] of {var} covers angles "
            f"{small:.9g} to {big:.9g} rad; pass tables={{{method!r}: fit_target("
            f"{spec.table.target!r}, {spec.table.degree}, psi_max=...)}} covering the spans, "
            f"or None for exact")
    if hi < need_hi - COVER_SLACK:
        raise ValueError(
            f"smallest angle the {method} method needs, "
            f"{math.acos(min(1.0, need_hi / scale)):.9g} rad, "
            f"is below the range of {where} {method} table {table.name!r}: its interval "
            f"[{lo:.9g}, {hi:.9g}] of {var} covers angles {small:.9g} to {big:.9g} rad")
    return table


#: largest length error ``1 - cos(theta/2)`` accepted from the linear pick between two
#: dyadic nodes ``theta`` apart, for pixels off the dyadic grid (2**-12: 1/16 of an 8-bit level)
PICK_TOL = 2.0 ** -12


def span_levels(dt, t0=None, count=None, cos=None) -> np.ndarray:
    """Dichotomy depth per span.

    The base depth is the smallest ``L >= 0`` with ``2**-L <= dt`` (within 1e-12). With
    the pixel positions (``t0``, ``count``) and the end-normal cosines, spans that have a
    pixel off that dyadic grid are halved deeper, until the node angle ``theta = psi/2**L``
    keeps the linear pick's length error ``1 - cos(theta/2)`` within :data:`PICK_TOL`
    (a one-pixel span between normals 34 degrees apart would otherwise be short by
    ``1 - cos(17 deg) = 4.4 %``, as bad as no normalization).

    Parameters
    ----------
    dt : numpy.ndarray
        The step per span.
    t0, count : numpy.ndarray, optional
        The first position and number of pixels per span.
    cos : numpy.ndarray, optional
        ``N_l.N_r`` per span.

    Returns
    -------
    numpy.ndarray
        The depth ``L`` per span (int).

    Examples
    --------

    Examples
    --------
    >>> span_levels([0.25, 0.1]).tolist()      # ceil(log2(1/dt))
    [2, 4]
    """
    dt = np.asarray(dt, dtype=np.float64)
    with np.errstate(divide="ignore"):
        lv = np.ceil(detmath.log2(1.0 / dt) - 1e-12)
    base = np.maximum(lv, 0).astype(np.int64)
    if cos is None:
        return base
    t0 = np.zeros_like(dt) if t0 is None else np.asarray(t0, dtype=np.float64)
    count = np.asarray(count, dtype=np.int64)
    sid = np.repeat(np.arange(dt.size), count)
    j = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
    u = (t0[sid] + j * dt[sid]) * np.ldexp(1.0, base[sid])
    off = np.abs(u - np.round(u)) > 1e-9 * np.maximum(1.0, np.abs(u))
    off_span = np.bincount(sid, weights=off, minlength=dt.size) > 0
    psi = detmath.arccos(np.clip(np.asarray(cos, dtype=np.float64), -1.0, 1.0))
    theta_max = 2.0 * math.acos(1.0 - PICK_TOL)
    with np.errstate(divide="ignore"):
        need = np.ceil(detmath.log2(np.maximum(psi, 1e-300) / theta_max))
    need = np.maximum(need, 0).astype(np.int64)
    return np.where(off_span, np.maximum(base, need), base)


# --------------------------------------------------------------- driver
def span_normals(method, n_left, n_right, m, *, t0=None, dt=None, count=None, tables=None,
                 dtype=np.float64, angular_reanchor: int | None = None) -> SpanNormals:
    """Pixel normals of many scan-line spans by one of the seed-000 methods.

    ``n_left``, ``n_right``: (S, 3) unit end normals; ``m``: (S,) span lengths
    (>= 1). Span i has pixels at ``t = t0[i] + j dt[i]``, ``j = 0 .. count[i]-1``
    (defaults ``t0 = 0``, ``dt = 1/m``, ``count = m + 1``: both ends
    included). The computation runs in ``dtype`` (float32 or float64).

    Methods (seed 000): ``exact`` (linear then ``N/sqrt(N.N)``, the
    reference), ``none``, ``newton`` (eq. ``N(3 - N.N)/2``), ``lyon``
    (``N(15 - 10 N.N + 3 (N.N)^2)/8``), ``slerp``, ``dichotomy`` (method 4),
    ``quadratic`` (method 5), ``angular`` (method 6); see :mod:`.kernels`.
    ``method`` is a name of the method registry
    (:func:`chebnorm.methods.method_names`) or its entry (:class:`MethodSpec`).

    Positions: ``quadratic`` and ``angular`` step with ``dt`` from ``t0``.
    ``dichotomy`` halves each span to depth ``L``, the smallest with
    ``2**-L <= dt`` (``ceil(log2 m)`` by default); a pixel on the dyadic grid
    takes its node, one off the grid (``m`` not a power of two, or arbitrary
    ``t0``) is linearly picked between its two neighbouring nodes (so it is
    not exactly unit: at most ``1 - cos(psi / 2**(L+1))`` short).

    Tables: ``tables={"dichotomy": T1, "quadratic": T2}``; a missing key uses
    :func:`~.registry.default_tables` (degree 2, angles up to pi/4); the value ``None``
    means exact denominators (``1/sqrt``). A table must cover the spans:
    ``z = 2 N_l.N_r .. 2 cos(psi / 2**(L-1))`` for dichotomy, ``x = N_l.N_r``
    for quadratic (up to a 1e-9 slack for rounding).

    ``angular_reanchor=K``: the angular recurrence is restarted from the
    closed form every K pixels (see :func:`chebnorm.methods.angular_drift`).

    Raises ``ValueError`` for: an unknown method or dtype; end normals that
    are not finite, zero, or not unit (``| |N| - 1 | > UNIT_TOL = 1e-5``);
    antiparallel end normals (``1 + cos psi <= 1e-6``); ``m < 1``; ``count < 1``;
    ``dt <= 0``; pixels outside ``[0, 1]``; tables not covering the angles.

    Parameters
    ----------
    method : str
        A registered method (:func:`~chebnorm.methods.method_names`).
    n_left, n_right : array_like
        Unit end normals, shape ``(S, 3)``.
    m : array_like
        Span lengths, shape ``(S,)`` (``m >= 1``).
    t0 : array_like, optional
        First pixel position per span (default 0).
    dt : array_like, optional
        Step per span (default ``1/m``).
    count : array_like, optional
        Pixels per span (default ``m + 1``, both ends included).
    tables : dict, optional
        Coefficient tables by method name (see Tables above).
    dtype : numpy dtype, optional
        float32 or float64.
    angular_reanchor : int, optional
        Restart the angular recurrence every this many pixels.

    Returns
    -------
    SpanNormals
        The pixel normals, their offsets per span and positions.

    Raises
    ------
    ValueError
        See above.

    Examples
    --------

    Examples
    --------
    >>> import numpy as np
    >>> nl = np.array([[1.0, 0.0, 0.0]]); nr = np.array([[0.0, 1.0, 0.0]])
    >>> out = span_normals("none", nl, nr, [2])
    >>> out.normals.tolist(), out.offsets.tolist()
    ([[1.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.0, 1.0, 0.0]], [0, 3])
    >>> np.linalg.norm(span_normals("slerp", nl, nr, [4]).normals, axis=1).round(15).tolist()
    [1.0, 1.0, 1.0, 1.0, 1.0]
    """
    inp = check_span_input(method, n_left, n_right, m, t0=t0, dt=dt, count=count, tables=tables,
                           dtype=dtype)
    dtype, kern, nl, nr = inp.dtype, inp.kernel, inp.n_left, inp.n_right
    dt_arr, t0_arr, cnt, levels, coeffs = inp.dt, inp.t0, inp.count, inp.levels, inp.coefficients
    if angular_reanchor is not None and (not isinstance(angular_reanchor, (int, np.integer))
                                         or isinstance(angular_reanchor, bool)
                                         or angular_reanchor < 2):
        raise ValueError(f"angular_reanchor = {angular_reanchor!r}; accepted: None or an integer >= 2")

    offsets = np.zeros(nl.shape[0] + 1, dtype=np.int64)
    np.cumsum(cnt, out=offsets[1:])
    sid = np.repeat(np.arange(nl.shape[0]), cnt)
    t = t0_arr[sid] + (np.arange(int(offsets[-1])) - offsets[sid]) * dt_arr[sid]

    ops = NumpyOps(dtype)
    a = tuple(nl.astype(dtype).T)
    b = tuple(nr.astype(dtype).T)
    out = np.empty((int(offsets[-1]), 3), dtype=dtype)
    if kern.shape == "direct":
        st = kern.setup(ops, a, b, coeffs)
        st = {k: (tuple(c[sid] for c in v) if isinstance(v, tuple) else v[sid]) for k, v in st.items()}
        res = kern.pixel(ops, st, t.astype(dtype))
        for c in range(3):
            out[:, c] = res[c]
    elif kern.shape == "steps":
        gen = kern.steps(ops, a, b, t0_arr.astype(dtype), dt_arr.astype(dtype), int(cnt.max()),
                         coefficients=coeffs, start_at_left=bool((t0_arr == 0).all()),
                         reanchor=angular_reanchor)
        starts = offsets[:-1]
        for jj, v in enumerate(gen):
            act = cnt > jj
            out[starts[act] + jj] = np.stack(v, axis=-1)[act]
    else:
        _tree(kern, ops, a, b, levels, coeffs, t, sid, out, dtype)
    return SpanNormals(normals=out, offsets=offsets, t=t)


@dataclass(frozen=True)
class SpanInput:
    """The checked input of :func:`span_normals` (what a compiled twin of it starts from):
    the registry entry ``spec``, its ``kernel``, ``dtype``, the (S, 3) float64 end normals,
    their ``cosines``, per-span ``m``, ``dt``, ``t0``, ``count``, the dichotomy depth
    ``levels`` (None for the other kernels) and the table's ``coefficients`` (None: exact).

    Attributes
    ----------
    spec : MethodSpec
        The method's registry entry.
    kernel : object
        Its span kernel.
    dtype : type
        ``numpy.float32`` or ``numpy.float64``.
    n_left, n_right : numpy.ndarray
        The unit end normals, float64, shape ``(S, 3)``.
    cosines : numpy.ndarray
        ``N_l.N_r`` per span, shape ``(S,)``.
    m, dt, t0, count : numpy.ndarray
        Per span: length, step, first position, number of pixels.
    levels : numpy.ndarray or None
        The dichotomy depth per span (None for the other kernels).
    coefficients : tuple or None
        The table's coefficients (None: exact denominators).

    Examples
    --------
    >>> inp = check_span_input("quadratic", [[1.0, 0, 0]], [[0.8, 0.6, 0]], [4])
    >>> inp.kernel.shape, inp.cosines.tolist(), inp.levels, len(inp.coefficients)
    ('steps', [0.8], None, 3)
    """

    spec: MethodSpec
    kernel: object
    dtype: type
    n_left: np.ndarray
    n_right: np.ndarray
    cosines: np.ndarray
    m: np.ndarray
    dt: np.ndarray
    t0: np.ndarray
    count: np.ndarray
    levels: np.ndarray | None
    coefficients: tuple | None


def check_span_input(method, n_left, n_right, m, *, t0=None, dt=None, count=None, tables=None,
                     dtype=np.float64) -> SpanInput:
    """Every check :func:`span_normals` makes, and the values it derives before computing
    (same arguments, same errors).

    Parameters
    ----------
    method, n_left, n_right, m, t0, dt, count, tables, dtype
        As in :func:`span_normals`.

    Returns
    -------
    SpanInput
        The checked and derived values.

    Raises
    ------
    ValueError
        As :func:`span_normals`.

    Examples
    --------

    Examples
    --------
    >>> inp = check_span_input("dichotomy", [[1.0, 0, 0]], [[0.8, 0.6, 0]], [4])
    >>> inp.levels.tolist(), inp.count.tolist()
    ([2], [5])
    """
    spec = check_method(method)
    dtype = check_dtype(dtype)
    kern = method_kernel(spec)
    nl, nr, cos = _end_normals(n_left, n_right)
    m_arr, dt_arr, t0_arr, cnt = _positions(nl.shape[0], m, dt, t0, count)
    levels = span_levels(dt_arr, t0_arr, cnt, cos) if kern.shape == "tree" else None
    if levels is not None and (levels > MAX_LEVELS).any():
        raise ValueError(f"{spec.name} step dt = {float(dt_arr.min()):.3g} needs more than "
                         f"{MAX_LEVELS} halvings; accepted: dt >= 2**-{MAX_LEVELS}")
    table = resolve_table(spec, tables, cos, levels) if spec.table is not None else None
    coeffs = None if table is None else table.coefficients
    return SpanInput(spec, kern, dtype, nl, nr, cos, m_arr, dt_arr, t0_arr, cnt, levels, coeffs)


def _end_normals(n_left, n_right):
    """Validated (S, 3) end normals and the cosines of their angles."""
    nl = _as_vectors("n_left", n_left)
    nr = _as_vectors("n_right", n_right)
    if nl.shape != nr.shape:
        raise ValueError(f"n_left has shape {nl.shape} but n_right {nr.shape}; accepted: equal (S, 3)")
    cos = np.einsum("ij,ij->i", nl, nr) / (np.linalg.norm(nl, axis=1) * np.linalg.norm(nr, axis=1))
    if (1.0 + cos <= ANTIPARALLEL_TOL).any():
        i = int(np.argmin(cos))
        raise ValueError(f"end normals of span {i} are antiparallel (1 + N_l.N_r = {1 + cos[i]:.3g}); "
                         f"accepted: angle below pi, 1 + N_l.N_r > {ANTIPARALLEL_TOL:g}")
    return nl, nr, cos


#: most pixels one call interpolates (count summed over the spans)
MAX_PIXELS = 16384 * 16384


def _positions(s, m, dt, t0, count):
    """Validated per-span ``m, dt, t0, count`` of ``s`` spans (defaults filled in)."""
    m_arr = _as_per_span("m", m, s, np.int64, None)
    if m_arr is None:
        raise ValueError("m is required; accepted: span lengths >= 1")
    if (m_arr < 1).any():
        i = int(np.argmin(m_arr))
        raise ValueError(f"span length m[{i}] = {int(m_arr[i])}; accepted: m >= 1")
    dt_arr = _as_per_span("dt", dt, s, np.float64, 1.0 / m_arr)
    if (dt_arr <= 0).any():
        raise ValueError(f"dt holds {float(dt_arr.min())}; accepted: dt > 0")
    t0_arr = _as_per_span("t0", t0, s, np.float64, np.zeros(s))
    cnt = _as_per_span("count", count, s, np.int64, m_arr + 1)
    if (cnt < 1).any():
        raise ValueError(f"count holds {int(cnt.min())}; accepted: count >= 1 (pixels per span)")
    if int(cnt.sum()) > MAX_PIXELS:
        raise ValueError(f"count: {int(cnt.sum())} pixels in all; accepted: at most {MAX_PIXELS} "
                         f"(the pixels of the largest frame, 16384 x 16384)")
    last = t0_arr + (cnt - 1) * dt_arr
    tol = 1e-9
    if (t0_arr < -tol).any() or (last > 1 + tol).any():
        i = int(np.argmax((t0_arr < -tol) | (last > 1 + tol)))
        raise ValueError(f"span {i} has pixels at t = {t0_arr[i]:.9g} .. {last[i]:.9g}; "
                         f"accepted: 0 <= t0 and t0 + (count-1) dt <= 1")
    return m_arr, dt_arr, t0_arr, cnt


def _tree(kern, ops, a, b, levels, coeffs, t, sid, out, dtype):
    for lv in np.unique(levels):
        spans = np.flatnonzero(levels == lv)
        pix = np.flatnonzero(levels[sid] == lv)
        lv = int(lv)
        nodes = kern.tree(ops, tuple(c[spans] for c in a), tuple(c[spans] for c in b), lv, coeffs)
        comp = [np.stack([nd[c] for nd in nodes], axis=1) for c in range(3)]  # (S_g, 2**lv + 1)
        local = np.searchsorted(spans, sid[pix])
        tt = t[pix].astype(dtype)
        k, f = kern.fraction(ops, tt, lv)
        k = k.astype(np.int64)
        node_a = tuple(cc[local, k] for cc in comp)
        if (f == 0).all():
            res = node_a
        else:
            kb = np.minimum(k + 1, 2 ** lv)
            node_b = tuple(cc[local, kb] for cc in comp)
            res = kern.pick(ops, node_a, node_b, f)
        for c in range(3):
            out[pix, c] = res[c]

