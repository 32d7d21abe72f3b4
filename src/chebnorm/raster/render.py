"""Shading modes on the span rasterizer: ``gouraud``, ``phong`` (any
normalization method), ``adaptive`` (seed 003), ``split-gouraud`` (seed 002)
and ``bump`` (seed 001).

Lighting is Blinn-Phong (the notation of docs/papers.md): ``I = I0 (k_a + k_d max(0, L.N)
+ k_s max(0, H.N)^n)`` with a directional light ``L`` and a viewer at the
camera; ``H = (L+V)/|L+V|`` is computed per pixel (``V`` from the
interpolated position) or once per triangle at its centroid (seed 002).  The
image is the intensity, clipped to ``[0, 1]``; 8-bit images are
``round(255 I)``.

Span-end normals.  The edge-interpolated normals at a span's ends are
normalized exactly (``n / |n|``) before the span interpolator sees them:
every method of seed 000 takes unit end normals.  The method ``none`` is the
exception: it is "normalization skipped" (seed 003), so neither the span
ends nor the pixels are normalized and the pixel normal is the plain
screen-space linear interpolation of the vertex normals.

The per-pixel normals come from :func:`chebnorm.methods.span_normals` (or a
replacement with its signature); the methods are those of the method registry
(:func:`chebnorm.methods.method_names`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from chebnorm.approx import parse_number
from chebnorm.methods import default_tables, detmath, get_method, method_names
from chebnorm.methods import span_normals as _span_normals
from chebnorm.symbolic import eta as _eta_criterion

from . import fast, fused, fusedsetup
from .meshes import Mesh, _unit, get_mesh
from .spans import Camera, fit_camera, project, setup_spans, zbuffer

__all__ = [
    "SHADING_MODES", "BUMP_VARIANTS", "Lighting", "HeightMap", "RenderResult", "render",
    "available_methods", "get_span_normals", "to_8bit",
]

SHADING_MODES = ("gouraud", "phong", "adaptive", "split-gouraud", "bump")
BUMP_VARIANTS = ("full", "square", "object")


def _dot(a, b):
    return np.einsum("...k,...k->...", a, b)


# ------------------------------------------------------------------ methods
def get_span_normals():
    """The default span interpolator, :func:`chebnorm.methods.span_normals`."""
    return _span_normals


def available_methods() -> tuple[str, ...]:
    """The normalization methods ``render`` accepts: every registered method.

    >>> {"exact", "none", "dichotomy"} <= set(available_methods())
    True
    """
    return method_names()


# ----------------------------------------------------------------- lighting
@dataclass(frozen=True)
class Lighting:
    """Blinn-Phong parameters (docs/papers.md): ``I0, k_a, k_d, k_s``, shininess
    ``n``, unit direction ``light`` *toward* the light (world; default: up and
    to the right of the camera), and where ``H`` is computed: ``"pixel"`` or
    ``"triangle"`` (one ``H`` per triangle, at its centroid, as in seed 002)."""

    I0: float = 1.0
    ka: float = 0.1
    kd: float = 0.6
    ks: float = 0.3
    shininess: float = 32.0
    light: tuple | None = None
    half_vector: str = "pixel"

    def validate(self):
        for name in ("I0", "ka", "kd", "ks"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise ValueError(f"lighting {name} must be a finite number >= 0; got {v!r}")
        if not (np.isfinite(self.shininess) and self.shininess >= 1):
            raise ValueError(f"shininess must be a finite number >= 1; got {self.shininess!r}")
        if self.half_vector not in ("pixel", "triangle"):
            raise ValueError(f"half_vector must be 'pixel' or 'triangle'; got {self.half_vector!r}")
        if self.light is not None:
            v = np.asarray(self.light, float)
            if v.shape != (3,) or not np.isfinite(v).all() or np.linalg.norm(v) == 0:
                raise ValueError(f"light must be a finite nonzero 3-vector; got {self.light!r}")

    def direction(self, camera: Camera) -> np.ndarray:
        if self.light is not None:
            return _unit(np.asarray(self.light, float))
        right, up, back = camera.frame()
        return _unit(1.6 * back + 1.0 * right + 1.2 * up)

    def intensity(self, ndotl, ndoth):
        # the C library's pow, not numpy's power loop (SVML on AVX-512: other bits)
        return self.I0 * (self.ka + self.kd * np.maximum(ndotl, 0.0)
                          + self.ks * detmath.power(np.maximum(ndoth, 0.0), self.shininess))


@dataclass(frozen=True)
class HeightMap:
    """Procedural height map ``F(u, v) = A sin(2 pi f_u u) sin(2 pi f_v v)``
    with exact ``F_u, F_v`` (seed 001: the height map gives F_u, F_v)."""

    amplitude: float = 0.01
    frequency: tuple = (8, 8)

    def derivatives(self, uv):
        fu, fv = self.frequency
        a, b = 2 * np.pi * fu * uv[:, 0], 2 * np.pi * fv * uv[:, 1]
        F_u = self.amplitude * 2 * np.pi * fu * np.cos(a) * np.sin(b)
        F_v = self.amplitude * 2 * np.pi * fv * np.sin(a) * np.cos(b)
        return F_u, F_v


@dataclass
class RenderResult:
    """A rendered frame: ``image (H, W)`` intensities in ``[0, 1]``
    (background 0), ``mask`` of covered pixels, and what the mode reports in
    ``stats`` (a flat dict of numbers)."""

    image: np.ndarray
    mask: np.ndarray
    mesh: str
    shading: str
    method: str | None
    seconds: float
    triangles: int
    fragments: int
    stats: dict = field(default_factory=dict)
    #: (H, W) index into mesh.faces of the visible triangle, -1 on background
    triangle: np.ndarray | None = None
    #: (H, W) ``|N|`` of the pixel normal before shading (phong, adaptive), NaN on background
    normal_length: np.ndarray | None = None

    @property
    def image8(self) -> np.ndarray:
        return to_8bit(self.image)

    @property
    def pixels(self) -> int:
        return int(self.mask.sum())

    def _repr_html_(self) -> str:
        """Jupyter: the image beside its length-error map and numbers
        (:func:`chebnorm.raster.display.render_html`)."""
        from .display import render_html

        return render_html(self)


def to_8bit(image) -> np.ndarray:
    """Intensities in ``[0, 1]`` to 8-bit levels, ``round(255 I)`` after
    clipping.

    >>> to_8bit([-0.5, 0.0, 0.5, 1.0, 2.0]).tolist()
    [0, 0, 128, 255, 255]
    """
    return np.round(np.clip(image, 0.0, 1.0) * 255.0).astype(np.uint8)


# --------------------------------------------------------------- set-up
@dataclass
class _Setup:
    mesh: Mesh
    camera: Camera
    width: int
    height: int
    L: np.ndarray
    tri: np.ndarray            # front-facing triangle ids into mesh.faces
    xy: np.ndarray             # (T,3,2)
    inv_w: np.ndarray          # (T,3)
    pos: np.ndarray            # (T,3,3)
    nrm: np.ndarray            # (T,3,3)
    engine: str = "numpy"      # "numpy" (the reference) or "numba" (compiled, same bytes)
    attrs: np.ndarray | None = None   # numba: [inv_w, nrm, pos] (T,3,7), fused.phong's spans

    def rasterize(self, extra):
        """Spans and visible fragments with attributes [1/w, *extra] (extra (T,3,K))."""
        attrs = np.concatenate([self.inv_w[..., None], extra], axis=2)
        if self.engine == "numba":
            sp = fast.fast_setup_spans(self.xy, attrs, self.width, self.height)
            return sp, fast.fast_zbuffer(sp, self.width * self.height)
        sp = setup_spans(self.xy, attrs, self.width, self.height)
        vis = zbuffer(sp.frag_pixel, sp.lerp([0])[:, 0], self.width * self.height)
        return sp, vis

    def lerp_visible(self, sp, cols, vis):
        """``sp.lerp(cols)[vis]``."""
        return fast.fast_lerp(sp, cols, vis) if self.engine == "numba" else sp.lerp(cols)[vis]


def _setup(mesh, camera, size, cull=True, engine="numpy"):
    w, h = size
    if engine == "numba":  # the same camera (remembered per mesh positions) and gathers
        cam = camera or fusedsetup.default_camera_of(mesh.positions, w, h)
        xy, inv_w = fusedsetup.project(cam, mesh.positions, w, h)
        tri, txy, iw, pos, nrm, attrs = fused.gather_setup(mesh, xy, inv_w, cull)
        return _Setup(mesh, cam, w, h, None, tri, txy, iw, pos, nrm, engine, attrs)
    cam = camera or fit_camera(mesh.positions, w, h)
    xy, inv_w = project(cam, mesh.positions, w, h)
    f = mesh.faces
    txy = xy[f]
    area = ((txy[:, 1, 0] - txy[:, 0, 0]) * (txy[:, 2, 1] - txy[:, 0, 1])
            - (txy[:, 2, 0] - txy[:, 0, 0]) * (txy[:, 1, 1] - txy[:, 0, 1]))
    # counter-clockwise in world (seen from the normal side) is clockwise with y down
    keep = area < 0 if cull else area != 0
    tri = np.flatnonzero(keep)
    return _Setup(mesh, cam, w, h, None, tri, txy[tri], inv_w[f[tri]], mesh.positions[f[tri]],
                  mesh.normals[f[tri]])


def _half_vectors(L, eye, points):
    V = _unit(np.asarray(eye, float) - points)
    return _unit(L + V)


def _tri_half(st):
    return _half_vectors(st.L, st.camera.eye, st.pos.mean(axis=1))  # (T,3)


def _validate_size(size):
    try:
        w, h = (int(s) for s in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be two integers (width, height); got {size!r}") from None
    if list(size) != [w, h] or not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise ValueError(f"size must be two integers in [1, 16384]; got {tuple(size)!r}")
    return w, h


# ------------------------------------------------------------------ render
def render(mesh="teapot", shading: str = "phong", method: str | None = "exact", *,
           size=(512, 512), tess: int | None = None, lighting: Lighting | None = None,
           camera: Camera | None = None, tables=None, dtype=np.float64,
           eta_threshold: float = 0.005, q: float = 1.0 / 255.0, bump: str = "full",
           height_map: HeightMap | None = None, k: float | None = None, cull: bool = True,
           span_normals=None, engine: str | None = "auto") -> RenderResult:
    """Render ``mesh`` (a :class:`Mesh`, a name or a file path) with one
    shading mode.

    ``method``: the normalization method of ``phong`` (and of the normalized
    triangles of ``adaptive``), any registered method (:func:`available_methods`),
    checked here once; ignored by ``gouraud`` and ``split-gouraud``;
    for ``bump`` it normalizes the interpolated tangent-space ``L`` and ``H``.
    ``tables``, ``dtype``: passed to the span interpolator.
    ``eta_threshold``: ``adaptive`` skips normalization on triangles with
    ``eta < eta_threshold`` (seed 003).  ``q``: ``split-gouraud``'s threshold
    on ``I0 k_s (max H.N)^n`` at an edge maximum (seed 002).  ``bump``:
    ``full`` (tangent-space coefficients from ``P_u, P_v``), ``square``
    (``[-F_u/k, -F_v/k, 1]``, ``k`` default the median of ``sqrt|P_u x P_v|``
    over the vertices) or ``object`` (Blinn's perturbed normal in object space,
    L and H in object space).  ``span_normals``: a replacement span
    interpolator (same signature as :func:`chebnorm.methods.span_normals`).
    ``engine``: ``"numpy"`` (the reference), ``"numba"`` (the compiled fast path of
    :mod:`chebnorm.raster.fast`, and for ``phong`` the fused, threaded frame of
    :mod:`chebnorm.raster.fused`: the same image bytes) or ``"auto"`` (numba when
    installed).

    >>> r = render("sphere", "phong", "exact", size=(32, 32), tess=8)
    >>> r.image.shape, r.pixels > 300
    ((32, 32), True)
    """
    t_start = time.perf_counter()
    if shading not in SHADING_MODES:
        raise ValueError(f"unknown shading mode {shading!r}; accepted: {', '.join(SHADING_MODES)}")
    w, h = _validate_size(size)
    engine = fast.resolve_engine(engine)
    lighting = lighting or Lighting()
    lighting.validate()
    spec = None
    if shading in ("phong", "adaptive", "bump"):
        method = method or "exact"
        if span_normals is None or method in method_names():
            spec = get_method(method)  # the one check of the method name
    else:
        method = None
    _check_options(shading, bump, eta_threshold, q)
    mesh = get_mesh(mesh, tess)
    if shading == "bump" and not mesh.has_parametrization:
        raise ValueError(f"bump mapping needs a parametrized mesh (uv, P_u, P_v); mesh {mesh.name!r} "
                         "has none; use teapot, sphere, torus or square")
    st = _setup(mesh, camera, (w, h), cull, engine)
    st.engine = engine
    st.L = lighting.direction(st.camera)
    kw = dict(lighting=lighting, interp=_interpolator(spec, span_normals, engine), tables=tables,
              dtype=dtype)
    if shading == "gouraud":
        out = _gouraud(st, lighting)
    elif shading == "phong":
        out = _phong(st, method, spec, **kw)
    elif shading == "adaptive":
        out = _phong(st, method, spec, skip_eta=eta_threshold, **kw)
    elif shading == "split-gouraud":
        out = _split_gouraud(st, lighting, q)
    else:
        out = _bump(st, method, spec, bump, height_map or HeightMap(), k, **kw)
    return RenderResult(out.image, out.mask, mesh.name, shading, method,
                        time.perf_counter() - t_start, int(len(mesh.faces)), int(out.fragments),
                        out.stats, out.triangle, out.normal_length)


def _check_options(shading, bump, eta_threshold, q):
    if shading == "bump" and bump not in BUMP_VARIANTS:
        raise ValueError(f"unknown bump variant {bump!r}; accepted: {', '.join(BUMP_VARIANTS)}")
    for name, value in (("eta_threshold", eta_threshold), ("q", q)):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                or not ((isinstance(value, (int, np.integer)) or np.isfinite(value))
                        and value >= 0):
            raise ValueError(f"{name} must be a finite number >= 0; got {value!r}")


def _interpolator(spec, span_normals, engine="numpy"):
    """The span interpolator ``render`` calls: a given one gets the method's name,
    the built-in one the registry entry ``render`` already looked up."""
    if span_normals is not None:
        return span_normals
    if engine == "numba" and spec is not None and fast.supports(spec):
        fn = lambda _name, *args, **kw: fast.fast_span_normals(spec, *args, **kw)  # noqa: E731
        fn.builtin = True  # the registry's kernel: _phong may take the fused path
        return fn
    return lambda _name, *args, **kw: _span_normals(spec, *args, **kw)


@dataclass
class _ModeResult:
    """What a shading mode hands back to :func:`render`."""

    image: np.ndarray
    mask: np.ndarray
    fragments: int
    stats: dict
    triangle: np.ndarray | None = None
    normal_length: np.ndarray | None = None


def _to_image(st, sp, vis, values):
    img = np.zeros(st.width * st.height)
    mask = np.zeros(st.width * st.height, dtype=bool)
    img[sp.frag_pixel[vis]] = values
    mask[sp.frag_pixel[vis]] = True
    return np.clip(img, 0.0, 1.0).reshape(st.height, st.width), mask.reshape(st.height, st.width)


def _pixel_map(st, sp, vis, values, fill):
    out = np.full(st.width * st.height, fill, dtype=np.asarray(values).dtype)
    out[sp.frag_pixel[vis]] = values
    return out.reshape(st.height, st.width)


# ---------------------------------------------------------------- gouraud
def _vertex_intensity(st, lighting, pos, nrm, tri_local):
    """Intensity at points ``pos (..., 3)`` with unit normals ``nrm``."""
    if lighting.half_vector == "triangle":
        H = _tri_half(st)[tri_local]
        H = np.broadcast_to(H[:, None, :], nrm.shape) if nrm.ndim == 3 else H
    else:
        H = _half_vectors(st.L, st.camera.eye, pos)
    return lighting.intensity(_dot(nrm, st.L), _dot(nrm, H))


def _gouraud(st, lighting):
    I = _vertex_intensity(st, lighting, st.pos, st.nrm, np.arange(len(st.tri)))
    sp, vis = st.rasterize(I[..., None])
    vals = st.lerp_visible(sp, [1], vis)[:, 0]
    img, mask = _to_image(st, sp, vis, vals)
    return _ModeResult(img, mask, sp.n_fragments, {"vertices_shaded": int(3 * len(st.tri))})


# ------------------------------------------------------------------ phong
def _interpolated_normals(sp, cols, method, interp, tables, dtype, sel=None, engine="numpy"):
    """Pixel normals of the spans ``sel`` (all if None), in fragment order."""
    idx = np.arange(len(sp.count)) if sel is None else np.flatnonzero(sel)
    if len(idx) == 0:
        return np.zeros((0, 3))
    nl, nr = sp.left[idx][:, cols], sp.right[idx][:, cols]
    if method == "none" and engine == "numba":
        frags = np.arange(sp.n_fragments) if sel is None else np.flatnonzero(sel[sp.frag_span])
        return fast.fast_lerp(sp, cols, frags)
    if method == "none":
        # normalization skipped altogether (seed 003): plain linear interpolation
        fs = np.repeat(idx, sp.count[idx])
        t = sp.frag_t[sel[sp.frag_span]] if sel is not None else sp.frag_t
        return sp.left[fs][:, cols] + t[:, None] * (sp.right[fs][:, cols] - sp.left[fs][:, cols])
    res = interp(method, _unit(nl), _unit(nr), sp.m[idx], t0=sp.t0[idx], dt=sp.dt[idx],
                 count=sp.count[idx], tables=tables, dtype=dtype)
    out = np.asarray(res.normals, dtype=np.float64)
    if out.shape != (int(sp.count[idx].sum()), 3):
        raise ValueError(f"span interpolator for {method!r} returned normals of shape {out.shape}; "
                         f"expected ({int(sp.count[idx].sum())}, 3)")
    return out


@lru_cache(maxsize=None)
def _psi_max(text) -> float:
    """A table's ``psi_max`` (``"pi/4"``) as a float."""
    return float(parse_number(text))


def _auto_tables(spec, sp, col_groups, tables, stats, dot_min=None):
    """The default tables cover end normals up to the registered ``psi_max`` (pi/4)
    apart.  When ``tables`` is None and a frame has wider spans (the teapot's spout
    lip) in any of ``col_groups`` (the normal columns the method interpolates), use
    :func:`chebnorm.methods.default_tables` on the smallest ``psi_max = j pi/32``
    covering them, and say so in ``stats["table_psi_max"]``; the widest angle is
    ``stats["span_angle_max"]``.  ``dot_min``: the smallest ``N_l.N_r`` of the unit
    end normals of the one column group, already computed (the fused frame's)."""
    if tables is not None or spec is None or spec.table is None or len(sp.count) == 0:
        return tables
    psi = 0.0
    for cols in col_groups:
        if dot_min is None:
            nl, nr = _unit(sp.left[:, cols]), _unit(sp.right[:, cols])
            d = np.min(_dot(nl, nr))
        else:
            d = np.float64(dot_min)
        psi = max(psi, math.acos(min(1.0, max(-1.0, float(d)))))
    stats["span_angle_max"] = psi
    if psi <= _psi_max(spec.table.psi_max):
        return None
    j = min(31, int(np.ceil(psi / (np.pi / 32) + 1e-9)))
    stats["table_psi_max"] = f"{j}*pi/32"
    return default_tables(psi_max=f"{j}*pi/32")


def _phong(st, method, spec, *, lighting, interp, tables, dtype, skip_eta=None):
    if (st.engine == "numba" and skip_eta is None and getattr(interp, "builtin", False)
            and fused.supports(spec)):
        # fused visibility + deferred shading (raster.fused): the same bytes as below
        out = fused.phong(st, spec, lighting, tables, dtype, _tri_half, _auto_tables)
        if out is not None:
            img, mask, tri, nlen, frags, stats = out
            return _ModeResult(img, mask, frags, stats, triangle=tri, normal_length=nlen)
    per_pixel_h = lighting.half_vector == "pixel"
    extra = [st.nrm] + ([st.pos] if per_pixel_h else [])
    sp, vis = st.rasterize(np.concatenate(extra, axis=2))
    ncols = [1, 2, 3]
    stats = {}
    tables = _auto_tables(spec, sp, [ncols], tables, stats)
    if skip_eta is None:
        N = _interpolated_normals(sp, ncols, method, interp, tables, dtype, engine=st.engine)
    else:
        eta = np.asarray(_eta_criterion(st.nrm[:, 0], st.nrm[:, 1], st.nrm[:, 2]), dtype=float)
        skip_tri = eta < skip_eta
        skip_span = skip_tri[sp.tri]
        skip_frag = skip_span[sp.frag_span]
        N = np.empty((sp.n_fragments, 3))
        N[skip_frag] = _interpolated_normals(sp, ncols, "none", interp, tables, dtype, skip_span,
                                             engine=st.engine)
        N[~skip_frag] = _interpolated_normals(sp, ncols, method, interp, tables, dtype, ~skip_span,
                                              engine=st.engine)
        drawn = np.unique(sp.tri)
        stats.update({
            "eta_threshold": float(skip_eta),
            "triangles_front": int(len(st.tri)),
            "triangles_drawn": int(len(drawn)),
            "triangles_skipped": int(skip_tri[drawn].sum()),
            "triangles_skipped_fraction": float(skip_tri[drawn].mean()) if len(drawn) else 0.0,
            "pixels_skipped": int(skip_frag[vis].sum()),
            "pixels_skipped_fraction": float(skip_frag[vis].mean()) if len(vis) else 0.0,
            "eta_max": float(eta.max()) if len(eta) else 0.0,
        })
    N = N[vis]
    if st.engine == "numba":
        # the same operations as below, compiled; dot products stay numpy's (their
        # summation order is numpy's and BLAS's)
        if per_pixel_h:
            H = fast.fast_half_vectors(sp, 4, vis, st.L, st.camera.eye)
        else:
            H = _tri_half(st)[sp.tri[sp.frag_span[vis]]]
        img, mask, tri, nlen = fast.fast_shade(N @ st.L, _dot(N, H), N, sp.frag_pixel[vis],
                                               st.tri[sp.tri[sp.frag_span[vis]]], lighting,
                                               st.width * st.height)
        shape = (st.height, st.width)
        return _ModeResult(img.reshape(shape), mask.reshape(shape), sp.n_fragments, stats,
                           triangle=tri.reshape(shape), normal_length=nlen.reshape(shape))
    if per_pixel_h:
        H = _half_vectors(st.L, st.camera.eye, st.lerp_visible(sp, [4, 5, 6], vis))
    else:
        H = _tri_half(st)[sp.tri[sp.frag_span[vis]]]
    vals = lighting.intensity(N @ st.L, _dot(N, H))
    img, mask = _to_image(st, sp, vis, vals)
    return _ModeResult(img, mask, sp.n_fragments, stats,
                       triangle=_pixel_map(st, sp, vis, st.tri[sp.tri[sp.frag_span[vis]]], -1),
                       normal_length=_pixel_map(st, sp, vis, np.linalg.norm(N, axis=1), np.nan))


# ---------------------------------------------------------- split gouraud
# sub-triangles (slots 0..2 = A, B, C; 3, 4, 5 = points on AB, BC, CA) for
# each split mask (bit 0: AB, bit 1: BC, bit 2: CA)
_SPLITS = {
    0: [(0, 1, 2)],
    1: [(0, 3, 2), (3, 1, 2)],
    2: [(0, 1, 4), (0, 4, 2)],
    4: [(0, 1, 5), (5, 1, 2)],
    3: [(3, 1, 4), (0, 3, 4), (0, 4, 2)],
    6: [(4, 2, 5), (0, 1, 4), (0, 4, 5)],
    5: [(0, 3, 5), (3, 1, 2), (3, 2, 5)],
    7: [(0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5)],
}


def _edge_highlight(a, b, c):
    from chebnorm.symbolic import edge_highlight
    c = np.clip(c, -1.0, 1.0)
    peak = edge_highlight(np.clip(a, -1, 1), np.clip(b, -1, 1), c)
    return np.asarray(peak.t, float), np.asarray(peak.value, float)


def _split_gouraud(st, lighting, q):
    T = len(st.tri)
    H = _tri_half(st)  # seed 002: H constant per triangle for the detection
    edges = ((0, 1), (1, 2), (2, 0))
    t_e = np.zeros((T, 3))
    split = np.zeros((T, 3), dtype=bool)
    for e, (i, j) in enumerate(edges):
        a, b = _dot(H, st.nrm[:, i]), _dot(H, st.nrm[:, j])
        c = _dot(st.nrm[:, i], st.nrm[:, j])
        t, value = _edge_highlight(a, b, c)
        spec = lighting.I0 * lighting.ks * detmath.power(np.maximum(value, 0.0), lighting.shininess)
        t_e[:, e] = t
        split[:, e] = (t > 0) & (t < 1) & (spec > q)
    # the six slots of every triangle
    pos6 = np.empty((T, 6, 3))
    nrm6 = np.empty((T, 6, 3))
    pos6[:, :3], nrm6[:, :3] = st.pos, st.nrm
    for e, (i, j) in enumerate(edges):
        t = t_e[:, e:e + 1]
        pos6[:, 3 + e] = st.pos[:, i] + t * (st.pos[:, j] - st.pos[:, i])
        nrm6[:, 3 + e] = _unit(st.nrm[:, i] + t * (st.nrm[:, j] - st.nrm[:, i]))
    I6 = _vertex_intensity(st, lighting, pos6, nrm6, np.arange(T))
    xy6, inv_w6 = project(st.camera, pos6, st.width, st.height)
    code = split[:, 0] * 1 + split[:, 1] * 2 + split[:, 2] * 4
    sub_tri, sub_slots = [], []
    for c, pattern in _SPLITS.items():
        ids = np.flatnonzero(code == c)
        for slots in pattern:
            sub_tri.append(ids)
            sub_slots.append(np.broadcast_to(np.array(slots), (len(ids), 3)))
    sub_tri = np.concatenate(sub_tri)
    sub_slots = np.concatenate(sub_slots)
    order = np.argsort(sub_tri, kind="stable")  # keep the triangle order: deterministic ties
    sub_tri, sub_slots = sub_tri[order], sub_slots[order]
    rows = sub_tri[:, None]
    attrs = np.stack([inv_w6[rows, sub_slots], I6[rows, sub_slots]], axis=2)
    if st.engine == "numba":
        sp = fast.fast_setup_spans(xy6[rows, sub_slots], attrs, st.width, st.height)
        vis = fast.fast_zbuffer(sp, st.width * st.height)
    else:
        sp = setup_spans(xy6[rows, sub_slots], attrs, st.width, st.height)
        vis = zbuffer(sp.frag_pixel, sp.lerp([0])[:, 0], st.width * st.height)
    img, mask = _to_image(st, sp, vis, st.lerp_visible(sp, [1], vis)[:, 0])
    n_split = split.sum(axis=1)
    stats = {
        "q": float(q),
        "vertices_shaded": int(3 * T + split.sum()),
        "extra_vertices": int(split.sum()),
        "extra_vertices_fraction": float(split.sum() / max(1, 3 * T)),
        "triangles_split_2": int((n_split == 1).sum()),
        "triangles_split_3": int((n_split == 2).sum()),
        "triangles_split_4": int((n_split == 3).sum()),
        "sub_triangles": int(len(sub_tri)),
    }
    return _ModeResult(img, mask, sp.n_fragments, stats)


# -------------------------------------------------------------------- bump
def _bump(st, method, spec, variant, height_map, k, *, lighting, interp, tables, dtype):
    from chebnorm.symbolic import bump_coefficients, bump_coefficients_square

    mesh = st.mesh
    f = mesh.faces[st.tri]
    uv, Pu, Pv = mesh.uv[f], mesh.P_u[f], mesh.P_v[f]
    if lighting.half_vector == "triangle":
        Hv = np.broadcast_to(_tri_half(st)[:, None, :], st.pos.shape)
    else:
        Hv = _half_vectors(st.L, st.camera.eye, st.pos)
    stats = {"bump": variant, "amplitude": float(height_map.amplitude)}
    if variant == "object":
        # object space: L and H stay in object space per vertex; interpolated, normalized
        Lv = np.broadcast_to(st.L, st.pos.shape)
        extra = np.concatenate([uv, Pu, Pv, Lv, Hv], axis=2)
    else:
        # tangent space per vertex (seed 001): T = P_u/|P_u|, N^ = unit(P_u x P_v), B = N^ x T
        Tt = _unit(Pu)
        Nh = _unit(np.cross(Pu, Pv))
        Bt = np.cross(Nh, Tt)
        Lts = np.stack([_dot(st.L, Tt), _dot(st.L, Bt), _dot(st.L, Nh)], axis=-1)
        Hts = np.stack([_dot(Hv, Tt), _dot(Hv, Bt), _dot(Hv, Nh)], axis=-1)
        extra = np.concatenate([uv, Pu, Pv, Lts, Hts], axis=2)
    sp, vis = st.rasterize(extra)
    tables = _auto_tables(spec, sp, [[9, 10, 11], [12, 13, 14]], tables, stats)
    # L and H: interpolated along spans, normalized per pixel by the method
    Lp = _interpolated_normals(sp, [9, 10, 11], method, interp, tables, dtype,
                               engine=st.engine)[vis]
    Hp = _interpolated_normals(sp, [12, 13, 14], method, interp, tables, dtype,
                               engine=st.engine)[vis]
    uvp = st.lerp_visible(sp, [1, 2], vis)
    F_u, F_v = height_map.derivatives(uvp)
    pu, pv = st.lerp_visible(sp, [3, 4, 5], vis), st.lerp_visible(sp, [6, 7, 8], vis)
    if variant == "object":
        N = np.cross(pu, pv)
        nlen = np.linalg.norm(N, axis=1, keepdims=True)
        D = (F_u[:, None] * np.cross(N, pv) + F_v[:, None] * np.cross(pu, N)) / nlen
        Np = _unit(N + D)
    elif variant == "full":
        Np = _unit(bump_coefficients(pu, pv, F_u, F_v))
    else:
        if k is None:
            k = float(np.median(np.sqrt(np.linalg.norm(np.cross(mesh.P_u, mesh.P_v), axis=1))))
        if not (np.isfinite(k) and k > 0):
            raise ValueError(f"square-patch scale k must be a finite number > 0; got {k!r}")
        stats["k"] = float(k)
        Np = _unit(bump_coefficients_square(F_u, F_v, k))
    vals = lighting.intensity(_dot(Np, Lp), _dot(Np, Hp))
    img, mask = _to_image(st, sp, vis, vals)
    return _ModeResult(img, mask, sp.n_fragments, stats)
