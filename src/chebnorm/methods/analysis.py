"""Error analysis of the span interpolators, as functions of the span angle and length.

Errors of a method's pixel normal ``N`` at position ``t`` are measured (in
float64, whatever dtype computed ``N``) against ``R(t)``, the exactly
normalized linear interpolant ``(N_l + t(N_r - N_l)) / |...|`` computed in
float64 from the same (float64) end normals:

* length error ``| |N| - 1 |``;
* angle error ``atan2(|N x R|, N.R)`` (radians). The slerp family (``slerp``,
  ``angular``, ``dichotomy``) spaces its normals evenly in *angle*, not along
  the chord, so against ``R`` it shows a parametrization difference of
  order ``psi^3/40`` even in exact arithmetic; ``max_angle_error_slerp`` is
  the angle against the slerp point ``S(t)`` instead (that family's own ideal);
* vector error ``|N - R|``: the largest absolute diffuse error
  ``|L.N - L.R|`` over all unit lights, for ``I0 k_d = 1``;
* diffuse error ``|N.R - 1|``: the relative diffuse error with the light
  along the true normal (where seed 003's ``delta_d`` is measured);
* specular errors ``|(N.R)^n - 1|``, ``n = 1..128``: relative specular error
  with the half vector along the true normal (seed 003's ``delta_s``).

All are maxima over the pixels of the span. The end normals are a fixed
generic pair at angle ``psi`` (not aligned with the axes). The measurement
uses no CPU-dispatched numpy function (:mod:`.detmath`: the C library's
``sin``/``atan2``, powers by repeated multiplication), so the same inputs give
the same errors on every x86-64 machine.

>>> r = analyze("none", 0.7853981633974483, 64)
>>> round(r.max_length_error, 7), round(r.specular_error(1), 7)
(0.0761205, 0.0761205)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from chebnorm.core.parallel import map_ordered
from chebnorm.core.display import field_rows, summary_html, summary_repr

from . import detmath
from .counting import OpCounts, count_ops, generic_pair
from .registry import default_tables, method_names
from .spans import check_dtype, check_method, span_levels, span_normals

# an implementation module of chebnorm.methods: the API is what chebnorm.methods exports
__all__: list[str] = []

#: specular exponents analysed: 1 .. N_SPECULAR
N_SPECULAR = 128
_DEFAULT_PSI_MAX = math.pi / 4


def _check_psi(psi) -> np.ndarray:
    arr = np.atleast_1d(np.asarray(psi, dtype=np.float64))
    if arr.ndim != 1 or not np.isfinite(arr).all() or (arr < 0).any() or (arr >= math.pi).any():
        raise ValueError(f"span angle psi = {psi!r} is out of range; accepted: 0 <= psi < pi (radians)")
    return arr


#: longest span the analyses accept, in pixels: 4x the widest frame ``render``
#: draws (16384); a span of 2**16 takes ~20 s and ~0.3 GB in :func:`analyze`
MAX_SPAN = 2 ** 16


def _check_m(m) -> int:
    if isinstance(m, bool) or not isinstance(m, (int, np.integer)) or not 1 <= m <= MAX_SPAN:
        raise ValueError(f"span length m = {m!r}; accepted: an integer m >= 1, at most {MAX_SPAN}")
    return int(m)


def reference_normals(nl, nr, t) -> np.ndarray:
    """``R(t)``: linear interpolation then exact normalization, float64, (P, 3).

    Parameters
    ----------
    nl, nr : numpy.ndarray
        End normals per pixel, shape ``(P, 3)``.
    t : numpy.ndarray
        Positions, shape ``(P,)``.

    Returns
    -------
    numpy.ndarray
        ``R(t) = (N_l + t (N_r - N_l)) / |N_l + t (N_r - N_l)|`` in float64, shape ``(P, 3)``.

    Examples
    --------
    >>> import numpy as np
    >>> reference_normals(np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]), np.array([0.5])).round(12).tolist()
    [[0.707106781187, 0.707106781187, 0.0]]
    """
    n = nl + t[:, None] * (nr - nl)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def slerp_normals(nl, nr, psi, t) -> np.ndarray:
    """``S(t)``: the slerp point at angle fraction ``t``, float64, (P, 3); ``psi`` per pixel.

    Seed 000, method 3: ``[sin((1-t) psi) N_l + sin(t psi) N_r] / sin psi``.
    A third of the way along a right angle is 30 degrees from ``N_l``:

    Parameters
    ----------
    nl, nr : numpy.ndarray
        Unit end normals per pixel, shape ``(P, 3)``.
    psi : float or numpy.ndarray
        The angle between them (radians), a scalar or per pixel; ``psi > 0``.
    t : numpy.ndarray
        Angle fractions, shape ``(P,)``.

    Returns
    -------
    numpy.ndarray
        The slerp points in float64, shape ``(P, 3)``.

    Examples
    --------
    >>> import numpy as np
    >>> s = slerp_normals(np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]), np.pi / 2, np.array([1 / 3]))
    >>> bool(np.allclose(s, [[np.cos(np.pi / 6), np.sin(np.pi / 6), 0.0]]))
    True
    """
    psi = np.broadcast_to(psi, t.shape)
    small = psi < 1e-300
    s = np.where(small, 1.0, detmath.sin(psi))
    wa = np.where(small, 1.0 - t, detmath.sin((1.0 - t) * psi) / s)
    wb = np.where(small, t, detmath.sin(t * psi) / s)
    return wa[:, None] * nl + wb[:, None] * nr


def _angle(a, b) -> np.ndarray:
    return detmath.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))


def _pixel_errors(n, nl, nr, psi, t):
    """Per-pixel errors: dict of (P,) arrays and the (P, 128) specular errors."""
    ref = reference_normals(nl, nr, t)
    sl = slerp_normals(nl, nr, psi, t)
    cosr = np.einsum("ij,ij->i", n, ref)
    spec = np.abs(detmath.powers(cosr, N_SPECULAR) - 1.0)
    return {"length": np.abs(np.linalg.norm(n, axis=1) - 1.0), "angle": _angle(n, ref),
            "angle_slerp": _angle(n, sl), "vector": np.linalg.norm(n - ref, axis=1),
            "diffuse": np.abs(cosr - 1.0)}, spec


@dataclass(frozen=True)
class MethodReport:
    """Errors and operation counts of one method on one span (see the module docstring).

    Attributes
    ----------
    method : str
        The method's registry name.
    psi : float
        The span angle (radians).
    m : int
        The span length (pixels ``0..m``).
    dtype : str
        The dtype the method computed in (``"float32"``, ``"float64"``).
    max_length_error : float
        Largest ``| |N| - 1 |``.
    max_angle_error : float
        Largest angle (radians) between ``N`` and the normalized linear interpolant ``R``.
    max_angle_error_slerp : float
        Largest angle between ``N`` and the slerp point ``S(t)``.
    max_vector_error : float
        Largest ``|N - R|``.
    diffuse_error : float
        Largest ``|N.R - 1|``.
    specular_errors : tuple of float
        Largest ``|(N.R)^n - 1|`` for ``n = 1 .. N_SPECULAR``.
    ops : OpCounts
        The method's operation counts on this span.

    Examples
    --------
    >>> r = analyze("none", 0.2, 8)   # linear interpolation, not normalized
    >>> round(r.max_length_error, 7), round(1 - math.cos(0.1), 7)   # shortest at the middle
    (0.0049958, 0.0049958)
    >>> r.specular_error(1) == r.diffuse_error, r.ops.per_pixel["mul"]
    (True, 3)
    """

    method: str
    psi: float
    m: int
    dtype: str
    max_length_error: float
    max_angle_error: float
    max_angle_error_slerp: float
    max_vector_error: float
    diffuse_error: float
    specular_errors: tuple[float, ...]  # n = 1 .. N_SPECULAR
    ops: OpCounts

    def _summary(self) -> list[tuple[str, object]]:
        return [("method", self.method), ("psi", self.psi), ("m", self.m), ("dtype", self.dtype),
                ("max_length_error", self.max_length_error),
                ("max_angle_error", self.max_angle_error)]

    def _display_rows(self) -> list[tuple[str, object]]:
        return self._summary() + [
            ("max_angle_error_slerp", self.max_angle_error_slerp),
            ("max_vector_error", self.max_vector_error), ("diffuse_error", self.diffuse_error),
            ("specular_error(n = 1, 8, 128)", tuple(self.specular_errors[n - 1]
                                                     for n in (1, 8, 128))),
            ("ops per pixel", str(dict(self.ops.per_pixel))),
            ("ops per span", str(dict(self.ops.per_span)))]

    __repr__ = summary_repr
    _repr_html_ = summary_html

    def specular_error(self, n: int) -> float:
        """Largest ``|(N.R)^n - 1|`` over the span, ``1 <= n <= 128``."""
        if not 1 <= n <= N_SPECULAR:
            raise ValueError(f"specular exponent n = {n}; accepted: 1 <= n <= {N_SPECULAR}")
        return self.specular_errors[n - 1]

    def to_dict(self) -> dict:
        return {"name": self.method, "angle": self.psi, "span": self.m, "dtype": self.dtype,
                "max_length_error": self.max_length_error, "max_angle_error": self.max_angle_error,
                "max_angle_error_slerp": self.max_angle_error_slerp,
                "max_vector_error": self.max_vector_error, "diffuse_error": self.diffuse_error,
                "specular_errors": {str(n): self.specular_errors[n - 1] for n in (1, 2, 4, 8, 16, 32, 64, 128)},
                "ops_per_pixel": dict(self.ops.per_pixel), "ops_per_span": dict(self.ops.per_span)}


def _tables_for(tables, psi_max: float):
    if tables is not None or psi_max <= _DEFAULT_PSI_MAX:
        return tables
    return default_tables(float(psi_max))


def analyze(method: str, psi: float, m: int, dtype=np.float64, *, tables=None,
            angular_reanchor: int | None = None) -> MethodReport:
    """Errors of ``method`` on one span of angle ``psi`` (radians) and length ``m``, in ``dtype``.

    ``tables`` as in :func:`~.spans.span_normals`; when None and ``psi`` exceeds
    pi/4, the degree-2 tables fitted for ``psi_max = psi`` are used
    (:func:`~.spans.default_tables`).

    Parameters
    ----------
    method : str
        A registered method (:func:`~chebnorm.methods.method_names`).
    psi : float
        The angle between the end normals, ``0 <= psi < pi`` (radians).
    m : int
        The span length: pixels at ``t = j/m``, ``j = 0..m``.
    dtype : numpy dtype, optional
        float32 or float64, the arithmetic of the method.
    tables : dict, optional
        Coefficient tables by method name, as in :func:`~chebnorm.methods.span_normals`.
    angular_reanchor : int, optional
        Restart the angular recurrence every this many pixels.

    Returns
    -------
    MethodReport
        The errors (maxima over the span, measured in float64) and the operation counts.

    Raises
    ------
    ValueError
        For an unknown method or dtype, ``psi`` outside ``[0, pi)``, ``m < 1``, or
        tables that do not cover the span.

    Examples
    --------
    >>> r = analyze("newton", 0.7853981633974483, 64)
    >>> round(r.max_length_error, 6), r.ops.per_pixel["sqrt"]
    (0.008471, 0)
    """
    method = check_method(method).name
    dt = check_dtype(dtype)
    (psi_v,) = _check_psi(psi)
    m = _check_m(m)
    nl, nr = generic_pair(psi_v)
    tab = _tables_for(tables, psi_v)
    res = span_normals(method, nl[None], nr[None], [m], dtype=dt, tables=tab,
                       angular_reanchor=angular_reanchor)
    err, spec = _pixel_errors(res.normals.astype(np.float64), nl, nr, psi_v, res.t)
    ops = count_ops(method, m, tables=tab, angular_reanchor=angular_reanchor, psi=psi_v)
    return MethodReport(method=method, psi=float(psi_v), m=m, dtype=np.dtype(dt).name,
                        max_length_error=float(err["length"].max()),
                        max_angle_error=float(err["angle"].max()),
                        max_angle_error_slerp=float(err["angle_slerp"].max()),
                        max_vector_error=float(err["vector"].max()),
                        diffuse_error=float(err["diffuse"].max()),
                        specular_errors=tuple(float(v) for v in spec.max(axis=0)), ops=ops)


@dataclass(frozen=True)
class ErrorSweep:
    """Errors over a grid: arrays indexed ``[method, dtype, psi, m]`` (specular: ``[..., n-1]``).

    Attributes
    ----------
    methods, dtypes : tuple of str
        The methods and dtype names along the first two axes.
    psis : numpy.ndarray
        The span angles (radians) along the third axis.
    ms : tuple of int
        The span lengths along the fourth axis.
    length_error, angle_error, angle_error_slerp, vector_error, diffuse_error : numpy.ndarray
        The per-span maxima of the errors of :class:`MethodReport`, shape
        ``(methods, dtypes, psis, ms)``.
    specular_error : numpy.ndarray
        The specular errors, shape ``(methods, dtypes, psis, ms, N_SPECULAR)``.

    Examples
    --------
    >>> s = error_sweep(("none", "exact"), [0.2, 0.4], (8,), (np.float64,))
    >>> s.length_error.shape
    (2, 1, 2, 1)
    >>> float(s.get("length_error", "exact", m=8).max()) < 1e-15
    True
    """

    methods: tuple[str, ...]
    dtypes: tuple[str, ...]
    psis: np.ndarray
    ms: tuple[int, ...]
    length_error: np.ndarray
    angle_error: np.ndarray
    angle_error_slerp: np.ndarray
    vector_error: np.ndarray
    diffuse_error: np.ndarray
    specular_error: np.ndarray

    def _summary(self) -> list[tuple[str, object]]:
        return [("methods", self.methods), ("dtypes", self.dtypes), ("psis", self.psis),
                ("ms", self.ms)]

    def _display_rows(self) -> list[tuple[str, object]]:
        rows = self._summary()
        for i, name in enumerate(self.methods):
            rows.append((f"{name}: max length error", float(self.length_error[i].max())))
        return rows

    __repr__ = summary_repr
    _repr_html_ = summary_html

    def get(self, quantity: str, method: str, dtype="float64", m=None) -> np.ndarray:
        """One curve over psi (or, with ``m=None``, the ``(len(psis), len(ms))`` block)."""
        arr = getattr(self, quantity)
        i, d = self.methods.index(method), self.dtypes.index(np.dtype(dtype).name)
        out = arr[i, d]
        return out if m is None else out[:, self.ms.index(m)]


def _sweep_cell(item):
    """Per-angle maxima of the errors of one (method, dtype, m) cell of :func:`error_sweep`."""
    name, dt, m, nl, nr, psis, tab = item
    res = span_normals(name, nl, nr, np.full(len(psis), m), dtype=dt, tables=tab)
    sid = np.repeat(np.arange(len(psis)), np.diff(res.offsets))
    err, spec = _pixel_errors(res.normals.astype(np.float64), nl[sid], nr[sid], psis[sid], res.t)
    starts = res.offsets[:-1]
    return ({key: np.maximum.reduceat(v, starts) for key, v in err.items()},
            np.maximum.reduceat(spec, starts, axis=0))


def error_sweep(methods=None, psis=None, ms=(8, 64, 512), dtypes=(np.float64, np.float32), *,
                tables=None, workers: int = 1, scheduler=None) -> ErrorSweep:
    """Errors of ``methods`` (None: every registered method) over span angles ``psis`` (default 33 points on [0, pi/2]),
    span lengths ``ms`` and dtypes; vectorized over the angles (one span per angle).

    ``tables=None``: the default degree-2 tables for pi/4 when they cover
    ``max(psis)``, else the degree-2 tables fitted for ``psi_max = max(psis)``.

    ``workers``, ``scheduler``: the (method, dtype, m) cells run on local processes or
    a Dask scheduler (:func:`chebnorm.core.parallel.map_ordered`; default: here);
    the result is the same.

    Parameters
    ----------
    methods : sequence of str, optional
        Registered methods (default: all).
    psis : array_like, optional
        Span angles in ``[0, pi)`` radians (default: 33 points on ``[0, pi/2]``).
    ms : sequence of int, optional
        Span lengths.
    dtypes : sequence of numpy dtypes, optional
        float32 and/or float64.
    tables : dict, optional
        Coefficient tables by method name.
    workers : int, optional
        Local processes (1: in this process).
    scheduler : str or distributed.Client, optional
        A Dask scheduler instead of local processes.

    Returns
    -------
    ErrorSweep
        The per-span maxima of every error over the grid.

    Raises
    ------
    ValueError
        For an unknown method or dtype, angles or lengths out of range.

    Examples
    --------
    >>> s = error_sweep(("none",), [0.2], (4,), (np.float64,))
    >>> round(float(s.get("diffuse_error", "none", m=4)[0]), 7)   # delta_d(0.2), claim C1
    0.0049958
    """
    specs = tuple(check_method(mm) for mm in (method_names() if methods is None else methods))
    methods = tuple(sp.name for sp in specs)
    psis = np.linspace(0.0, math.pi / 2, 33) if psis is None else _check_psi(psis)
    ms = tuple(_check_m(mm) for mm in ms)
    dts = tuple(check_dtype(d) for d in dtypes)
    tab = _tables_for(tables, float(psis.max()))
    shape = (len(methods), len(dts), len(psis), len(ms))
    out = {k: np.zeros(shape) for k in ("length", "angle", "angle_slerp", "vector", "diffuse")}
    spec_out = np.zeros(shape + (N_SPECULAR,))
    pairs = [generic_pair(p) for p in psis]
    nl = np.array([a for a, _ in pairs])
    nr = np.array([b for _, b in pairs])
    cells = [(i, d, k) for i in range(len(specs)) for d in range(len(dts)) for k in range(len(ms))]
    items = [(specs[i], dts[d], ms[k], nl, nr, psis,
              tab if specs[i].table is not None else None) for i, d, k in cells]
    for (i, d, k), (err, spec) in zip(cells, map_ordered(_sweep_cell, items, workers=workers,
                                                         scheduler=scheduler)):
        for key, v in err.items():
            out[key][i, d, :, k] = v
        spec_out[i, d, :, k, :] = spec
    return ErrorSweep(methods=methods, dtypes=tuple(np.dtype(d).name for d in dts), psis=psis, ms=ms,
                      length_error=out["length"], angle_error=out["angle"],
                      angle_error_slerp=out["angle_slerp"], vector_error=out["vector"],
                      diffuse_error=out["diffuse"], specular_error=spec_out)


def _levels_of(m: int) -> int:
    return max(0, math.ceil(math.log2(m) - 1e-12))


def length_error_bound(method: str, psi: float, m: int, *, tables=None, dtype=np.float64) -> float:
    """An analytic bound of ``max | |N| - 1 |`` for ``method`` on a span of angle ``psi``, length ``m``
    (default positions), including a rounding allowance in ``dtype``.

    With ``r = cos(psi/2)`` the smallest length of the linear interpolant:

    * ``exact`` 16 eps, ``slerp`` 32 eps (rounding only);
    * ``none``: ``1 - r`` (seed 003's delta_d, attained at the midpoint);
    * ``newton``: ``1 - r(3 - r^2)/2`` (the step is increasing on [0, 1],
      derivative ``3(1 - x^2)/2``, and maps 1 to 1);
    * ``lyon``: ``1 - r(15 - 10 r^2 + 3 r^4)/8`` (derivative ``15(1 - x^2)^2/8``);
    * ``dichotomy`` (table of certified relative error ``e``, L levels):
      level k's denominator is off by ``rho_k``, the propagated ``z`` by
      ``zeta_k``; to first order ``zeta_{k+1} = eps_k + zeta_k/4`` and
      ``rho_k = eps_k - zeta_k/4`` (``|d log f / d log z| = z/(2(2+z)) <= 1/4``),
      so ``|rho_k| <= e (1 + (1 - 4^-k)/3)``; a midpoint's length error is the
      mean of its neighbours' plus ``rho_k``, so the bound is ``sum_k |rho_k|
      + (L e)^2``; off the dyadic grid (m not a power of two) add the pick's
      ``1 - cos(psi / 2^(L+1))``;
    * ``quadratic`` (midpoint table of relative error ``e``):
      ``1 - sqrt(1 - (1 - r)^2/4) + e(1 + e)``, the first term exact (in the
      plane of the normals ``|N|^2 = 1 - (1-r)^2 u(1-u)``, ``u = (2t-1)^2``),
      the table moving ``|N(t)|`` by at most ``4t(1-t) e``; plus ``8 (m+1)
      eps`` for the forward differences;
    * ``angular``: an *estimate*, not a rigorous bound: ``2 cos(phi)`` is
      off by ~eps, a frequency error ~``eps/phi``, so after m steps
      ``4 m eps m / psi`` (capped at ``4 m sqrt(eps)``) + 64 eps.

    Tables as in :func:`~.spans.span_normals` (missing keys: the defaults).

    Parameters
    ----------
    method : str
        A registered method.
    psi : float
        The span angle, ``0 <= psi < pi`` (radians).
    m : int
        The span length.
    tables : dict, optional
        Coefficient tables by method name (their certified relative bounds enter
        the ``dichotomy`` and ``quadratic`` bounds).
    dtype : numpy dtype, optional
        The arithmetic whose rounding allowance (``eps``) is added.

    Returns
    -------
    float
        The bound (an estimate for ``angular``, see above).

    Raises
    ------
    ValueError
        For an unknown method or dtype, or arguments out of range.

    Examples
    --------
    >>> round(length_error_bound("none", math.pi / 4, 64), 7)
    0.0761205
    """
    spec = check_method(method)
    method = spec.name
    eps = float(np.finfo(check_dtype(dtype)).eps)
    (psi,) = _check_psi(psi)
    m = _check_m(m)
    r = math.cos(psi / 2)
    if spec.table is not None:
        table = default_tables()[method] if tables is None or method not in tables else tables[method]
        e = 0.0 if table is None else table.rel_error_bound
    if method == "exact":
        return 16 * eps
    if method == "slerp":
        return 32 * eps
    if method == "none":
        return 1 - r + 16 * eps
    if method == "newton":
        return 1 - r * (3 - r * r) / 2 + 16 * eps
    if method == "lyon":
        return 1 - r * (15 - 10 * r ** 2 + 3 * r ** 4) / 8 + 16 * eps
    if method == "dichotomy":
        lv = int(span_levels(np.array([1.0 / m]), np.array([0.0]), np.array([m + 1]),
                         np.array([math.cos(psi)]))[0])
        b = sum(e * (1 + (1 - 4.0 ** -k) / 3) for k in range(lv)) + (lv * e) ** 2
        if 2 ** _levels_of(m) != m:  # off the dyadic grid: the linear pick between nodes
            b += 1 - math.cos(psi / 2 ** (lv + 1))
        return b + 16 * (lv + 1) * eps
    if method == "quadratic":
        return 1 - math.sqrt(1 - (1 - r) ** 2 / 4) + e * (1 + e) + 8 * (m + 1) * eps
    if method == "angular":
        drift = 4 * m * eps * m / psi if psi > 0 else 0.0
        return min(drift, 4 * m * math.sqrt(eps)) + 64 * eps
    raise ValueError(f"no analytic length bound is known for method {method!r}; known for: "
                     f"exact, slerp, none, newton, lyon, dichotomy, quadratic, angular")


@dataclass(frozen=True)
class DriftReport:
    """Per-pixel errors of the ``angular`` recurrence against its ideal, slerp (float64).

    Attributes
    ----------
    psi : float
        The span angle (radians).
    m : int
        The span length.
    dtype : str
        The arithmetic: ``"float32"``, ``"float64"`` or ``"Q.F"`` (fixed point).
    reanchor : int or None
        The re-anchoring period in pixels (None: never).
    t : numpy.ndarray
        The pixel positions, ``m + 1`` values in ``[0, 1]``.
    length_error : numpy.ndarray
        ``| |N| - 1 |`` per pixel.
    angle_error : numpy.ndarray
        The angle between ``N`` and the slerp point ``S(t)`` per pixel (radians).
    max_length_error, max_angle_error : float
        The maxima over the span.
    final_length_error, final_angle_error : float
        The errors at the last pixel (``t = 1``).
    ops : OpCounts
        The operation counts (with re-anchoring, ``per_pixel`` is an average).

    Examples
    --------
    >>> d = angular_drift(math.pi / 4, 64, np.float64)
    >>> d.t.shape, d.final_angle_error <= d.max_angle_error < 1e-12
    ((65,), True)
    """

    psi: float
    m: int
    dtype: str
    reanchor: int | None
    t: np.ndarray
    length_error: np.ndarray
    angle_error: np.ndarray        # against the slerp point S(t)
    max_length_error: float
    max_angle_error: float
    final_length_error: float
    final_angle_error: float
    ops: OpCounts

    def _summary(self) -> list[tuple[str, object]]:
        return [("psi", self.psi), ("m", self.m), ("dtype", self.dtype),
                ("reanchor", self.reanchor), ("max_length_error", self.max_length_error),
                ("max_angle_error", self.max_angle_error)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html


def angular_drift(psi: float = math.pi / 4, m: int = 512, dtype=np.float32,
                  reanchor: int | None = None, *, frac_bits: int | None = None) -> DriftReport:
    """The drift of the spherical-angular recurrence (seed 000, method 6) along one span.

    ``reanchor=K`` restarts the recurrence from the closed form every K
    pixels; its cost is in ``ops`` (``per_pixel`` is then an average).
    ``frac_bits=F`` runs it in fixed point instead (``dtype`` ignored): the
    two start vectors and ``2 cos(phi)`` rounded to F fractional bits, each
    product ``2 cos(phi) N_j`` rounded to nearest (ties up) back to F bits,
    the subtraction exact -- what an integer datapath does; ``dtype`` of the
    report is then ``"Q.F"``.

    Parameters
    ----------
    psi : float, optional
        The span angle (radians), default ``pi/4``.
    m : int, optional
        The span length, default 512.
    dtype : numpy dtype, optional
        float32 (default) or float64.
    reanchor : int, optional
        Restart from the closed form every this many pixels.
    frac_bits : int, optional
        Run in fixed point with this many fractional bits instead of ``dtype``.

    Returns
    -------
    DriftReport
        Per-pixel length and angle errors against slerp, and the operation counts.

    Raises
    ------
    ValueError
        For ``psi`` outside ``[0, pi)``, ``m < 1``, or an invalid ``reanchor`` or ``frac_bits``.

    Examples
    --------
    >>> d = angular_drift(math.pi / 4, 512, np.float64)
    >>> d.max_angle_error < 1e-11
    True
    >>> angular_drift(math.pi / 4, 512, frac_bits=16).max_length_error > 1e-4
    True
    """
    if frac_bits is not None:
        return _angular_drift_fixed(psi, m, frac_bits, reanchor)
    dt = check_dtype(dtype)
    (psi_v,) = _check_psi(psi)
    m = _check_m(m)
    nl, nr = generic_pair(psi_v)
    res = span_normals("angular", nl[None], nr[None], [m], dtype=dt, angular_reanchor=reanchor)
    n = res.normals.astype(np.float64)
    length = np.abs(np.linalg.norm(n, axis=1) - 1.0)
    angle = _angle(n, slerp_normals(nl, nr, psi_v, res.t))
    return DriftReport(psi=float(psi_v), m=m, dtype=np.dtype(dt).name, reanchor=reanchor, t=res.t,
                       length_error=length, angle_error=angle,
                       max_length_error=float(length.max()), max_angle_error=float(angle.max()),
                       final_length_error=float(length[-1]), final_angle_error=float(angle[-1]),
                       ops=count_ops("angular", m, angular_reanchor=reanchor, psi=psi_v))


def _angular_drift_fixed(psi, m, frac_bits, reanchor) -> DriftReport:
    if isinstance(frac_bits, bool) or not isinstance(frac_bits, (int, np.integer)) \
            or not 4 <= frac_bits <= 30:
        raise ValueError(f"frac_bits = {frac_bits!r}; accepted: an integer 4..30 "
                         f"(products must fit int64)")
    if reanchor is not None and (not isinstance(reanchor, (int, np.integer)) or reanchor < 2):
        raise ValueError(f"reanchor = {reanchor!r}; accepted: None or an integer >= 2")
    (psi_v,) = _check_psi(psi)
    m = _check_m(m)
    F = int(frac_bits)
    one = 1 << F
    nl, nr = generic_pair(psi_v)
    t = np.arange(m + 1) / m
    exact = slerp_normals(nl, nr, psi_v, t)
    q = lambda v: np.round(np.asarray(v) * one).astype(np.int64)
    k2 = int(round(2 * math.cos(psi_v / m) * one))
    out = np.empty((m + 1, 3), dtype=np.int64)
    out[0], out[1] = q(exact[0]), q(exact[1])
    half = one >> 1
    for j in range(2, m + 1):
        if reanchor and j % reanchor == 0:
            out[j - 1], out[j] = q(exact[j - 1]), q(exact[j])
        else:
            out[j] = ((k2 * out[j - 1] + half) >> F) - out[j - 2]
    n = out.astype(np.float64) / one
    length = np.abs(np.linalg.norm(n, axis=1) - 1.0)
    angle = _angle(n, exact)
    return DriftReport(psi=float(psi_v), m=m, dtype=f"Q.{F}", reanchor=reanchor, t=t,
                       length_error=length, angle_error=angle,
                       max_length_error=float(length.max()), max_angle_error=float(angle.max()),
                       final_length_error=float(length[-1]), final_angle_error=float(angle[-1]),
                       ops=count_ops("angular", m, angular_reanchor=reanchor, psi=psi_v))
