"""The numpy engine: the reference every other engine reproduces byte for byte."""

from __future__ import annotations

import numpy as np

from chebnorm.methods import span_normals as _span_normals

from ..scanline import fit_camera, project, setup_spans, zbuffer
from .base import Engine, Setup, dot, half_vectors

# an implementation module of chebnorm.raster.engines: the API is what chebnorm.raster.engines exports
__all__: list[str] = []


class NumpyEngine(Engine):
    """The reference engine: numpy arrays, every step in :mod:`chebnorm.raster.scanline`'s
    and :func:`chebnorm.methods.span_normals`'s operation order."""

    name = "numpy"

    def setup(self, mesh, camera, size, cull) -> Setup:
        w, h = size
        cam = camera or fit_camera(mesh.positions, w, h)
        xy, inv_w = project(cam, mesh.positions, w, h)
        f = mesh.faces
        txy = xy[f]
        area = ((txy[:, 1, 0] - txy[:, 0, 0]) * (txy[:, 2, 1] - txy[:, 0, 1])
                - (txy[:, 2, 0] - txy[:, 0, 0]) * (txy[:, 1, 1] - txy[:, 0, 1]))
        # counter-clockwise in world (seen from the normal side) is clockwise with y down
        keep = area < 0 if cull else area != 0
        tri = np.flatnonzero(keep)
        return Setup(mesh, cam, w, h, None, tri, txy[tri], inv_w[f[tri]],
                     mesh.positions[f[tri]], mesh.normals[f[tri]])

    def rasterize(self, xy, attrs, width, height):
        sp = setup_spans(xy, attrs, width, height)
        return sp, zbuffer(sp.frag_pixel, sp.lerp([0])[:, 0], width * height)

    def lerp(self, sp, cols, sel):
        return sp.lerp(cols)[sel]

    def plain_normals(self, sp, cols, idx, sel):
        # normalization skipped altogether (seed 003): plain linear interpolation
        fs = np.repeat(idx, sp.count[idx])
        t = sp.frag_t[sel[sp.frag_span]] if sel is not None else sp.frag_t
        return sp.left[fs][:, cols] + t[:, None] * (sp.right[fs][:, cols] - sp.left[fs][:, cols])

    def span_normals(self, spec, *args, **kw):
        return _span_normals(spec, *args, **kw)

    def half_vectors(self, st, sp, vis):
        return half_vectors(st.L, st.camera.eye, self.lerp(sp, [4, 5, 6], vis))

    def shade(self, st, sp, vis, N, H, lighting):
        vals = lighting.intensity(N @ st.L, dot(N, H))
        img, mask = to_image(st, sp, vis, vals)
        tri = st.tri[sp.tri[sp.frag_span[vis]]].astype(np.int32)   # int32: meshes.MAX_FACES
        return (img, mask, pixel_map(st, sp, vis, tri, -1),
                pixel_map(st, sp, vis, np.linalg.norm(N, axis=1), np.nan))


def to_image(st, sp, vis, values):
    """``(image, mask)`` (H, W) of ``st``'s frame: ``values`` at the visible fragments
    ``vis`` clipped to [0, 1], 0 elsewhere, and the covered pixels.

    Parameters
    ----------
    st : Setup
        The frame's set-up.
    sp : Spans
        The frame's spans.
    vis : numpy.ndarray
        Indices of the visible fragments.
    values : numpy.ndarray
        Intensity per visible fragment.

    Returns
    -------
    image : numpy.ndarray
        Intensities ``(H, W)`` in ``[0, 1]``.
    mask : numpy.ndarray
        Covered pixels, bool ``(H, W)``.
    """
    img = np.zeros(st.width * st.height)
    mask = np.zeros(st.width * st.height, dtype=bool)
    img[sp.frag_pixel[vis]] = values
    mask[sp.frag_pixel[vis]] = True
    return np.clip(img, 0.0, 1.0).reshape(st.height, st.width), mask.reshape(st.height, st.width)


def pixel_map(st, sp, vis, values, fill):
    """An (H, W) map of ``values`` at the visible fragments ``vis``, ``fill`` elsewhere.

    Parameters
    ----------
    st : Setup
        The frame's set-up (its size).
    sp : Spans
        The frame's spans.
    vis : numpy.ndarray
        Indices of the visible fragments.
    values : numpy.ndarray
        One value per visible fragment.
    fill : float
        The value elsewhere.

    Returns
    -------
    numpy.ndarray
        The map ``(H, W)``.
    """
    out = np.full(st.width * st.height, fill, dtype=np.asarray(values).dtype)
    out[sp.frag_pixel[vis]] = values
    return out.reshape(st.height, st.width)
