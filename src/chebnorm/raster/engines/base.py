"""The small interface every rendering engine implements, and what the shading modes
share across engines.

A frame is drawn in steps, each an :class:`Engine` method: :meth:`~Engine.setup` (camera,
projection, front-facing triangles), :meth:`~Engine.rasterize` (spans and visible
fragments), :meth:`~Engine.lerp` and :meth:`~Engine.plain_normals` (attributes and
unnormalized normals at fragments), :meth:`~Engine.span_normals` (the method's pixel
normals), :meth:`~Engine.half_vectors` and :meth:`~Engine.shade` (Blinn-Phong).  An
engine may draw a whole ``phong`` frame at once (:meth:`~Engine.phong_frame`, offered
where :meth:`~Engine.supports_frame` says so); it raises :class:`FrameUnsupported`
when a frame turns out to be one it cannot promise the reference's bytes for, and the
caller draws it step by step.  Every engine gives the same bytes as the numpy
reference (:mod:`chebnorm.raster.engines.numpy`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from chebnorm.approx import parse_number
from chebnorm.exceptions import FrameUnsupported
from chebnorm.methods import default_tables

from ..meshes import Mesh, unit
from ..scanline import Camera

# an implementation module of chebnorm.raster.engines: the API is what chebnorm.raster.engines exports
__all__: list[str] = []


@dataclass
class Setup:
    """What a frame's steps share: the mesh, camera, size, the light direction ``L``
    (set by ``render``), the front-facing triangles ``tri`` (ids into ``mesh.faces``)
    and their corners: screen ``xy (T,3,2)``, ``inv_w (T,3)``, positions and normals
    ``(T,3,3)``; ``attrs``: ``[1/w, normal, position] (T,3,7)`` if the engine gathered
    them (the numba engine's ``phong`` frame), else None.

    Attributes
    ----------
    mesh : Mesh
        The mesh.
    camera : Camera
        The view.
    width, height : int
        The image size.
    L : numpy.ndarray or None
        Unit direction toward the light.
    tri : numpy.ndarray
        The front triangles' indices into ``mesh.faces``.
    xy : numpy.ndarray
        Screen corners ``(T, 3, 2)``.
    inv_w : numpy.ndarray
        ``1/w`` at the corners ``(T, 3)``.
    pos, nrm : numpy.ndarray
        Corner positions and normals ``(T, 3, 3)``.
    attrs : numpy.ndarray, optional
        ``[1/w, normal, position]`` per corner ``(T, 3, 7)``, or None.
    """

    mesh: Mesh
    camera: Camera
    width: int
    height: int
    L: np.ndarray | None
    tri: np.ndarray
    xy: np.ndarray
    inv_w: np.ndarray
    pos: np.ndarray
    nrm: np.ndarray
    attrs: np.ndarray | None = None


@dataclass
class ModeResult:
    """What a shading mode hands back to ``render``: the image (H, W), coverage mask,
    fragment count, the mode's ``stats``, and (phong, adaptive) the triangle and
    ``|N|`` maps.

    Attributes
    ----------
    image : numpy.ndarray
        Intensities ``(H, W)`` in ``[0, 1]``.
    mask : numpy.ndarray
        Covered pixels, bool ``(H, W)``.
    fragments : int
        Fragments shaded.
    stats : dict
        The mode's statistics.
    triangle : numpy.ndarray, optional
        Visible triangle per pixel (-1 off the mesh).
    normal_length : numpy.ndarray, optional
        ``|N|`` per pixel before shading (NaN off the mesh).
    """

    image: np.ndarray
    mask: np.ndarray
    fragments: int
    stats: dict
    triangle: np.ndarray | None = None
    normal_length: np.ndarray | None = None


def dot(a, b):
    """Row-wise dot products ``a . b`` over the last axis (numpy's ``einsum``: its
    summation order is part of the reference's bytes).

    Parameters
    ----------
    a, b : numpy.ndarray
        Vectors ``(..., 3)``; they broadcast.

    Returns
    -------
    numpy.ndarray
        The dot products ``(...)``.
    """
    return np.einsum("...k,...k->...", a, b)


def half_vectors(L, eye, points):
    """Blinn half vectors ``unit(L + unit(eye - P))`` at ``points (..., 3)``.

    Parameters
    ----------
    L : numpy.ndarray
        Unit direction toward the light ``(3,)``.
    eye : numpy.ndarray
        The camera position ``(3,)``.
    points : numpy.ndarray
        Surface points ``(..., 3)``.

    Returns
    -------
    numpy.ndarray
        Unit half vectors ``(..., 3)``.
    """
    V = unit(np.asarray(eye, float) - points)
    return unit(L + V)


def triangle_half_vectors(st: Setup) -> np.ndarray:
    """One half vector per front triangle of ``st``, at its centroid (seed 002), (T, 3).

    Parameters
    ----------
    st : Setup
        The frame's set-up (with ``L``).

    Returns
    -------
    numpy.ndarray
        Unit half vectors ``(T, 3)``.
    """
    return half_vectors(st.L, st.camera.eye, st.pos.mean(axis=1))


@lru_cache(maxsize=None)
def _psi_max(text) -> float:
    """A table's ``psi_max`` (``"pi/4"``) as a float."""
    return float(parse_number(text))


def auto_tables(spec, sp, col_groups, tables, stats, dot_min=None):
    """The tables a frame's span interpolation uses.

    The default tables cover end normals up to the registered ``psi_max`` (pi/4)
    apart.  When ``tables`` is None and a frame has wider spans (the teapot's spout
    lip) in any of ``col_groups`` (the normal columns the method interpolates), use
    :func:`chebnorm.methods.default_tables` on the smallest ``psi_max = j pi/32``
    covering them, and say so in ``stats["table_psi_max"]``; the widest angle is
    ``stats["span_angle_max"]``.

    Parameters
    ----------
    spec : MethodSpec or None
        The method's registry entry.
    sp : Spans-like
        The frame's spans (``left``, ``right``, ``count``).
    col_groups : list of list of int
        The attribute columns of each normal the method interpolates.
    tables : mapping or None
        The caller's tables (returned as given unless None).
    stats : dict
        Updated with ``span_angle_max`` and, when wider tables are used,
        ``table_psi_max``.
    dot_min : float, optional
        The smallest ``N_l.N_r`` of the unit end normals of the one column group,
        already computed (the fused frame's).

    Returns
    -------
    mapping or None
        The tables to pass to the span interpolator.
    """
    if tables is not None or spec is None or spec.table is None or len(sp.count) == 0:
        return tables
    psi = 0.0
    for cols in col_groups:
        if dot_min is None:
            nl, nr = unit(sp.left[:, cols]), unit(sp.right[:, cols])
            d = np.min(dot(nl, nr))
        else:
            d = np.float64(dot_min)
        psi = max(psi, math.acos(min(1.0, max(-1.0, float(d)))))
    stats["span_angle_max"] = psi
    if psi <= _psi_max(spec.table.psi_max):
        return None
    j = min(31, int(np.ceil(psi / (np.pi / 32) + 1e-9)))
    stats["table_psi_max"] = f"{j}*pi/32"
    return default_tables(psi_max=f"{j}*pi/32")


class Engine:
    """The steps of a frame, as every engine provides them (see the module docstring).
    :class:`chebnorm.raster.engines.numpy.NumpyEngine` is the reference implementation;
    an engine overrides the steps it computes otherwise, with the same bytes."""

    #: the name ``render(engine=...)`` selects this engine by
    name = ""

    def warm_up(self, key, work, what: str) -> float:
        """Prepare the engine for a kind of frame before ``render``'s clock starts.

        Parameters
        ----------
        key : hashable
            The kind of frame (mode, method, dtype, ...).
        work : callable
            Renders a small frame of that kind (a compiling engine runs it the
            first time it sees ``key``).
        what : str
            The kind, for a message.

        Returns
        -------
        float
            The seconds the preparation took: 0.0 here (nothing is compiled).
        """
        return 0.0

    def setup(self, mesh, camera, size, cull) -> Setup:
        """Camera (``camera`` or the default fitted one), projection and the front-facing
        (``cull``) or all non-degenerate triangles of ``mesh`` at ``size = (w, h)``."""
        raise NotImplementedError

    def rasterize(self, xy, attrs, width, height):
        """``(spans, visible fragment ids)`` of triangles ``xy (T,3,2)`` with corner
        attributes ``attrs (T,3,K)`` (column 0: ``1/w``, the depth of the z-test)."""
        raise NotImplementedError

    def lerp(self, sp, cols, sel):
        """``sp.lerp(cols)[sel]``: attribute columns ``cols`` at fragments ``sel``."""
        raise NotImplementedError

    def plain_normals(self, sp, cols, idx, sel):
        """Normals of method ``none`` (screen-space linear interpolation, not normalized)
        of the spans ``idx`` (``sel``: their mask, or None for all), in fragment order."""
        raise NotImplementedError

    def span_normals(self, spec, *args, **kw):
        """:func:`chebnorm.methods.span_normals` for the registry entry ``spec``."""
        raise NotImplementedError

    def half_vectors(self, st, sp, vis):
        """Per-pixel half vectors at the visible fragments ``vis`` (positions in attribute
        columns 4..6)."""
        raise NotImplementedError

    def shade(self, st, sp, vis, N, H, lighting):
        """``(image, mask, triangle map, |N| map)`` (H, W) of the visible fragments with
        normals ``N`` and half vectors ``H``."""
        raise NotImplementedError

    def supports_frame(self, spec) -> bool:
        """Whether :meth:`phong_frame` draws method ``spec``."""
        return False

    def phong_frame(self, st, spec, lighting, tables, dtype, extra_maps=True) -> ModeResult:
        """A whole ``phong`` frame at once (``extra_maps`` False: without the triangle and
        ``|N|`` maps); raises :class:`FrameUnsupported` where the engine cannot promise
        the reference's bytes."""
        raise FrameUnsupported(self.name)
