"""The compiled engine (numba, optional): the numpy reference's bytes, faster.

Modules, each importing only those above it: :mod:`.jit` (the numba import guard,
``njit``, LLVM intrinsics, the one thread pool), :mod:`.calibration` (the library
reductions' summation orders and the shortcuts checked once per process),
:mod:`.workspace` (scratch memory kept between frames), :mod:`.rasterize` (spans,
z-buffer, triangle gather, projection), :mod:`.kernels` (span normals, half vectors,
shading), :mod:`.setup` (the fused frame's per-span set-up) and :mod:`.frame` (the
fused, threaded ``phong`` frame).  :class:`NumbaEngine` is what ``render`` uses.
"""

from __future__ import annotations

import time

import numpy as np

from ..base import Setup, dot
from ..numpy import NumpyEngine
from . import frame
from .jit import announce_slow
from .kernels import fast_half_vectors, fast_shade, fast_span_normals
from .kernels import supports as kernels_support
from .rasterize import (default_camera_of, fast_lerp, fast_setup_spans, fast_zbuffer,
                        gather_setup, project)

# HAVE_NUMBA is chebnorm.raster.engines' (from .jit); the gathered set-up is
# the engine's own type: the API of this package is its engine
__all__ = ["NumbaEngine"]


class GatheredSetup(Setup):
    """A :class:`~chebnorm.raster.engines.base.Setup` whose corner ``inv_w``, ``pos`` and
    ``nrm`` are copies of ``attrs``' columns made when first read (the fused frame reads
    ``attrs`` alone: the set-up then writes 40 % fewer bytes; the other shading modes
    read them, the same values, C-contiguous, as the numpy engine's).

    Attributes
    ----------
    mesh, camera, width, height, L, tri, xy, inv_w, pos, nrm, attrs
        As :class:`~chebnorm.raster.engines.base.Setup`'s.
    """

    @property
    def inv_w(self):
        if self._inv_w is None:
            self._inv_w = np.ascontiguousarray(self.attrs[..., 0])
        return self._inv_w

    @inv_w.setter
    def inv_w(self, value):
        self._inv_w = value

    @property
    def pos(self):
        if self._pos is None:
            self._pos = np.ascontiguousarray(self.attrs[..., 4:7])
        return self._pos

    @pos.setter
    def pos(self, value):
        self._pos = value

    @property
    def nrm(self):
        if self._nrm is None:
            self._nrm = np.ascontiguousarray(self.attrs[..., 1:4])
        return self._nrm

    @nrm.setter
    def nrm(self, value):
        self._nrm = value


class NumbaEngine(NumpyEngine):
    """The compiled engine: the steps of :class:`~chebnorm.raster.engines.numpy.NumpyEngine`
    compiled (the same bytes), and for ``phong`` the fused, threaded frame of
    :mod:`.frame`."""

    name = "numba"

    def __init__(self):
        #: the kinds of frame compiled in this process (see :meth:`warm_up`)
        self.warmed: set = set()

    def warm_up(self, key, work, what: str) -> float:
        """Run ``work()`` the first time ``key`` is seen in this process.

        numba compiles (or loads from its disk cache) the kernels ``work`` calls;
        when that is slow, one :class:`~.jit.NumbaCompileWarning` per process
        says so (:func:`~.jit.announce_slow`).

        Parameters
        ----------
        key : hashable
            The kind of frame.
        work : callable
            Renders a small frame of that kind.
        what : str
            The kind, for the warning.

        Returns
        -------
        float
            The seconds ``work()`` took; 0.0 after the first time.
        """
        if key in self.warmed:
            return 0.0
        self.warmed.add(key)   # before the work: it renders with this key itself
        t0 = time.perf_counter()
        announce_slow(work, what)
        return time.perf_counter() - t0

    def setup(self, mesh, camera, size, cull) -> Setup:
        w, h = size
        # the same camera (remembered per mesh positions) and gathers, compiled
        cam = camera or default_camera_of(mesh.positions, w, h)
        xy, inv_w = project(cam, mesh.positions, w, h)
        tri, txy, iw, pos, nrm, attrs = gather_setup(mesh, xy, inv_w, cull, corners=False)
        return GatheredSetup(mesh, cam, w, h, None, tri, txy, iw, pos, nrm, attrs)

    def rasterize(self, xy, attrs, width, height):
        sp = fast_setup_spans(xy, attrs, width, height)
        return sp, fast_zbuffer(sp, width * height)

    def lerp(self, sp, cols, sel):
        return fast_lerp(sp, cols, sel)

    def plain_normals(self, sp, cols, idx, sel):
        frags = np.arange(sp.n_fragments) if sel is None else np.flatnonzero(sel[sp.frag_span])
        return fast_lerp(sp, cols, frags)

    def span_normals(self, spec, *args, **kw):
        if kernels_support(spec):
            return fast_span_normals(spec, *args, **kw)
        return super().span_normals(spec, *args, **kw)

    def half_vectors(self, st, sp, vis):
        return fast_half_vectors(sp, 4, vis, st.L, st.camera.eye)

    def shade(self, st, sp, vis, N, H, lighting):
        # dot products stay numpy's (their summation order is numpy's and BLAS's)
        img, mask, tri, nlen = fast_shade(N @ st.L, dot(N, H), N, sp.frag_pixel[vis],
                                          st.tri[sp.tri[sp.frag_span[vis]]], lighting,
                                          st.width * st.height)
        shape = (st.height, st.width)
        return img.reshape(shape), mask.reshape(shape), tri.reshape(shape), nlen.reshape(shape)

    def supports_frame(self, spec) -> bool:
        return kernels_support(spec) and frame.supports(spec)

    def phong_frame(self, st, spec, lighting, tables, dtype, extra_maps=True):
        return frame.phong(st, spec, lighting, tables, dtype, extra_maps)
