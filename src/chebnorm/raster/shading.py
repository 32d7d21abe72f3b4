"""The shading modes, written once against the engine interface
(:class:`chebnorm.raster.engines.base.Engine`): ``gouraud``, ``phong`` (any
normalization method; ``adaptive`` is ``phong`` with ``skip_eta``), ``split-gouraud``
(seed 002) and ``bump`` (seed 001).  ``render`` validates its arguments, picks the
engine and calls one of these; the formulas are those of :mod:`chebnorm.raster.render`'s
docstring.
"""

from __future__ import annotations

import numpy as np

from chebnorm.methods import detmath
from chebnorm.symbolic import eta as _eta_criterion

from .engines.base import (FrameUnsupported, ModeResult, auto_tables, dot, half_vectors,
                           triangle_half_vectors)
from .engines.numpy import to_image
from .meshes import unit
from .scanline import project

# an implementation module of chebnorm.raster: the API is what chebnorm.raster exports
__all__: list[str] = []


def _rasterize(engine, st, extra):
    """Spans and visible fragments of ``st``'s triangles with attributes [1/w, *extra]
    (extra (T,3,K))."""
    attrs = np.concatenate([st.inv_w[..., None], extra], axis=2)
    return engine.rasterize(st.xy, attrs, st.width, st.height)


# ---------------------------------------------------------------- gouraud
def _vertex_intensity(st, lighting, pos, nrm, tri_local):
    """Intensity at points ``pos (..., 3)`` with unit normals ``nrm``."""
    if lighting.half_vector == "triangle":
        H = triangle_half_vectors(st)[tri_local]
        H = np.broadcast_to(H[:, None, :], nrm.shape) if nrm.ndim == 3 else H
    else:
        H = half_vectors(st.L, st.camera.eye, pos)
    return lighting.intensity(dot(nrm, st.L), dot(nrm, H))


def gouraud(engine, st, lighting) -> ModeResult:
    """``gouraud``: Blinn-Phong at the vertices, intensities interpolated.

    Parameters
    ----------
    engine : Engine
        The engine drawing the frame.
    st : Setup
        The frame's set-up (``st.L`` set).
    lighting : Lighting
        Blinn-Phong parameters.

    Returns
    -------
    ModeResult
    """
    I = _vertex_intensity(st, lighting, st.pos, st.nrm, np.arange(len(st.tri)))
    sp, vis = _rasterize(engine, st, I[..., None])
    vals = engine.lerp(sp, [1], vis)[:, 0]
    img, mask = to_image(st, sp, vis, vals)
    return ModeResult(img, mask, sp.n_fragments, {"vertices_shaded": int(3 * len(st.tri))})


# ------------------------------------------------------------------ phong
def interpolated_normals(engine, sp, cols, method, interp, tables, dtype, sel=None):
    """Pixel normals of the spans ``sel`` (all if None), in fragment order: the normal
    columns ``cols`` interpolated by ``method`` (``none``: the engine's plain linear
    interpolation), ``interp`` the span interpolator (signature of
    :func:`chebnorm.methods.span_normals`).

    Parameters
    ----------
    engine : module
        The engine (numpy or numba) whose interpolation is used.
    sp : Spans
        The frame's spans.
    cols : slice or sequence of int
        The attribute columns holding the normal.
    method : str
        The normalization method (``none``: linear interpolation).
    interp : callable
        The span interpolator.
    tables : dict or None
        Coefficient tables by method name.
    dtype : numpy dtype
        The interpolator's arithmetic.
    sel : numpy.ndarray, optional
        The spans to interpolate (default: all).

    Returns
    -------
    numpy.ndarray
        The pixel normals ``(P, 3)`` in fragment order.
    """
    idx = np.arange(len(sp.count)) if sel is None else np.flatnonzero(sel)
    if len(idx) == 0:
        return np.zeros((0, 3))
    if method == "none":
        return engine.plain_normals(sp, cols, idx, sel)
    nl, nr = sp.left[idx][:, cols], sp.right[idx][:, cols]
    res = interp(method, unit(nl), unit(nr), sp.m[idx], t0=sp.t0[idx], dt=sp.dt[idx],
                 count=sp.count[idx], tables=tables, dtype=dtype)
    out = np.asarray(res.normals, dtype=np.float64)
    if out.shape != (int(sp.count[idx].sum()), 3):
        raise ValueError(f"span interpolator for {method!r} returned normals of shape {out.shape}; "
                         f"expected ({int(sp.count[idx].sum())}, 3)")
    return out


def phong(engine, st, method, spec, *, lighting, interp, tables, dtype, skip_eta=None,
          builtin=True, extra_maps=True) -> ModeResult:
    """``phong`` (and, with ``skip_eta``, ``adaptive``: no normalization on triangles
    with ``eta < skip_eta``, seed 003).

    Parameters
    ----------
    engine : Engine
        The engine drawing the frame; its whole-frame path is taken where it supports
        the method (``builtin``: ``interp`` is the registry's interpolator, not the
        caller's) and ``skip_eta`` is None.
    st : Setup
        The frame's set-up (``st.L`` set).
    method : str
        The normalization method's name (what ``interp`` is called with).
    spec : MethodSpec or None
        Its registry entry.
    lighting : Lighting
        Blinn-Phong parameters.
    interp : callable
        The span interpolator.
    tables, dtype
        Passed to the span interpolator.
    skip_eta : float, optional
        ``adaptive``'s threshold.
    builtin : bool
        Whether ``interp`` is the registry's interpolator.
    extra_maps : bool
        Also the triangle and ``|N|`` maps (False: ``triangle`` and ``normal_length``
        are None; the whole-frame path then neither computes nor writes them).

    Returns
    -------
    ModeResult
    """
    if skip_eta is None and builtin and engine.supports_frame(spec):
        try:
            return engine.phong_frame(st, spec, lighting, tables, dtype, extra_maps)
        except FrameUnsupported:
            pass    # the same bytes, step by step
    per_pixel_h = lighting.half_vector == "pixel"
    extra = [st.nrm] + ([st.pos] if per_pixel_h else [])
    sp, vis = _rasterize(engine, st, np.concatenate(extra, axis=2))
    ncols = [1, 2, 3]
    stats = {}
    tables = auto_tables(spec, sp, [ncols], tables, stats)
    if skip_eta is None:
        N = interpolated_normals(engine, sp, ncols, method, interp, tables, dtype)
    else:
        eta = np.asarray(_eta_criterion(st.nrm[:, 0], st.nrm[:, 1], st.nrm[:, 2]), dtype=float)
        skip_tri = eta < skip_eta
        skip_span = skip_tri[sp.tri]
        skip_frag = skip_span[sp.frag_span]
        N = np.empty((sp.n_fragments, 3))
        N[skip_frag] = interpolated_normals(engine, sp, ncols, "none", interp, tables, dtype,
                                            skip_span)
        N[~skip_frag] = interpolated_normals(engine, sp, ncols, method, interp, tables, dtype,
                                             ~skip_span)
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
    if per_pixel_h:
        H = engine.half_vectors(st, sp, vis)
    else:
        H = triangle_half_vectors(st)[sp.tri[sp.frag_span[vis]]]
    img, mask, tri, nlen = engine.shade(st, sp, vis, N, H, lighting)
    if not extra_maps:
        tri = nlen = None
    return ModeResult(img, mask, sp.n_fragments, stats, triangle=tri, normal_length=nlen)


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


def split_gouraud(engine, st, lighting, q) -> ModeResult:
    """``split-gouraud`` (seed 002): triangles split at the edge highlights whose
    specular term ``I0 k_s (max H.N)^n`` exceeds ``q``, then Gouraud-shaded.

    Parameters
    ----------
    engine : Engine
        The engine drawing the frame.
    st : Setup
        The frame's set-up (``st.L`` set).
    lighting : Lighting
        Blinn-Phong parameters.
    q : float
        The threshold.

    Returns
    -------
    ModeResult
    """
    T = len(st.tri)
    H = triangle_half_vectors(st)  # seed 002: H constant per triangle for the detection
    edges = ((0, 1), (1, 2), (2, 0))
    t_e = np.zeros((T, 3))
    split = np.zeros((T, 3), dtype=bool)
    for e, (i, j) in enumerate(edges):
        a, b = dot(H, st.nrm[:, i]), dot(H, st.nrm[:, j])
        c = dot(st.nrm[:, i], st.nrm[:, j])
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
        nrm6[:, 3 + e] = unit(st.nrm[:, i] + t * (st.nrm[:, j] - st.nrm[:, i]))
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
    sp, vis = engine.rasterize(xy6[rows, sub_slots], attrs, st.width, st.height)
    img, mask = to_image(st, sp, vis, engine.lerp(sp, [1], vis)[:, 0])
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
    return ModeResult(img, mask, sp.n_fragments, stats)


# -------------------------------------------------------------------- bump
def bump(engine, st, method, spec, variant, height_map, k, *, lighting, interp, tables,
         dtype) -> ModeResult:
    """``bump`` (seed 001): Blinn's bump mapping with the height map's exact
    derivatives, ``L`` and ``H`` interpolated and normalized per pixel by ``method``.

    Parameters
    ----------
    engine : Engine
        The engine drawing the frame.
    st : Setup
        The frame's set-up (``st.L`` set).
    method : str
        The normalization method of ``L`` and ``H``.
    spec : MethodSpec or None
        Its registry entry.
    variant : {"full", "square", "object"}
        See ``render``.
    height_map : HeightMap
        ``F(u, v)`` and its derivatives.
    k : float or None
        ``square``'s scale.
    lighting, interp, tables, dtype
        As for :func:`phong`.

    Returns
    -------
    ModeResult
    """
    from chebnorm.symbolic import bump_coefficients, bump_coefficients_square

    mesh = st.mesh
    f = mesh.faces[st.tri]
    uv, Pu, Pv = mesh.uv[f], mesh.P_u[f], mesh.P_v[f]
    if lighting.half_vector == "triangle":
        Hv = np.broadcast_to(triangle_half_vectors(st)[:, None, :], st.pos.shape)
    else:
        Hv = half_vectors(st.L, st.camera.eye, st.pos)
    stats = {"bump": variant, "amplitude": float(height_map.amplitude)}
    if variant == "object":
        # object space: L and H stay in object space per vertex; interpolated, normalized
        Lv = np.broadcast_to(st.L, st.pos.shape)
        extra = np.concatenate([uv, Pu, Pv, Lv, Hv], axis=2)
    else:
        # tangent space per vertex (seed 001): T = P_u/|P_u|, N^ = unit(P_u x P_v), B = N^ x T
        Tt = unit(Pu)
        Nh = unit(np.cross(Pu, Pv))
        Bt = np.cross(Nh, Tt)
        Lts = np.stack([dot(st.L, Tt), dot(st.L, Bt), dot(st.L, Nh)], axis=-1)
        Hts = np.stack([dot(Hv, Tt), dot(Hv, Bt), dot(Hv, Nh)], axis=-1)
        extra = np.concatenate([uv, Pu, Pv, Lts, Hts], axis=2)
    sp, vis = _rasterize(engine, st, extra)
    tables = auto_tables(spec, sp, [[9, 10, 11], [12, 13, 14]], tables, stats)
    # L and H: interpolated along spans, normalized per pixel by the method
    Lp = interpolated_normals(engine, sp, [9, 10, 11], method, interp, tables,
                               dtype)[vis]
    Hp = interpolated_normals(engine, sp, [12, 13, 14], method, interp, tables,
                               dtype)[vis]
    uvp = engine.lerp(sp, [1, 2], vis)
    F_u, F_v = height_map.derivatives(uvp)
    pu, pv = engine.lerp(sp, [3, 4, 5], vis), engine.lerp(sp, [6, 7, 8], vis)
    if variant == "object":
        N = np.cross(pu, pv)
        nlen = np.linalg.norm(N, axis=1, keepdims=True)
        D = (F_u[:, None] * np.cross(N, pv) + F_v[:, None] * np.cross(pu, N)) / nlen
        Np = unit(N + D)
    elif variant == "full":
        Np = unit(bump_coefficients(pu, pv, F_u, F_v))
    else:
        if k is None:
            k = float(np.median(np.sqrt(np.linalg.norm(np.cross(mesh.P_u, mesh.P_v), axis=1))))
        if not (np.isfinite(k) and k > 0):
            raise ValueError(f"square-patch scale k must be a finite number > 0; got {k!r}")
        stats["k"] = float(k)
        Np = unit(bump_coefficients_square(F_u, F_v, k))
    vals = lighting.intensity(dot(Np, Lp), dot(Np, Hp))
    img, mask = to_image(st, sp, vis, vals)
    return ModeResult(img, mask, sp.n_fragments, stats)
