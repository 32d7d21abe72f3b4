"""Scratch memory of the compiled engine kept between frames: a frame's
:class:`Workspace` (spans, end normals, per-span set-up), its output maps, and each
thread's span arrays.  Fresh pages cost about as much as the set-up's arithmetic
(a page fault per 4 KiB); reused ones nothing.  Nothing here is handed to the user
except output maps, and those only once the user dropped every earlier view of them.
"""

from __future__ import annotations

import math
import sys
import threading

import numpy as np

# an implementation module of chebnorm.raster.engines.numba: the API is what chebnorm.raster.engines.numba exports
__all__: list[str] = []


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
    """A workspace for one frame (a new one when every kept one is in use).

    Returns
    -------
    Workspace
        A workspace for this frame (hand it back with :func:`give`).
    """
    try:
        return _FREE.pop()
    except IndexError:
        return Workspace()


def give(work: Workspace) -> None:
    """Return a frame's workspace (at most two are kept).

    Parameters
    ----------
    work : Workspace
        The workspace :func:`take` gave.
    """
    if len(_FREE) < 2:
        _FREE.append(work)


#: output-map sets ``(image, mask, triangle, normal length)`` of earlier frames, flat (at
#: most :data:`_KEEP_MAPS`): a set nobody else references any more is the next frame's
#: (the memory of arrays the user dropped, its pages mapped already)
_MAPS: list = []


_MAPS_LOCK = threading.Lock()


_KEEP_MAPS = 2


_MAP_DTYPES = (np.float64, np.bool_, np.int32, np.float64)


def output_maps(npx):
    """Four uninitialised flat arrays for a frame's image, mask, triangle and ``|N|``
    maps (float64, bool, int32, float64), each ``npx`` long: a set of an earlier frame
    that only this pool still references (``sys.getrefcount``: the user dropped every
    view of it), else new arrays.  Hand the set back with :func:`keep_maps` once the
    frame is drawn.

    Parameters
    ----------
    npx : int
        Pixels of the frame.

    Returns
    -------
    tuple of numpy.ndarray
        ``(image, mask, triangle, normal_length)``, flat, uninitialised.

    Examples
    --------
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
    """Remember a frame's map set for reuse once its user drops it.

    Parameters
    ----------
    maps : tuple of numpy.ndarray
        The set :func:`output_maps` gave.
    """
    with _MAPS_LOCK:
        _MAPS.append(tuple(maps))
        del _MAPS[:-_KEEP_MAPS]


#: buffer sets of the triangle set-up (:func:`setup_buffers`), at most :data:`_KEEP_SETUP`
_SETUP: list = []


_KEEP_SETUP = 2


#: elements per face of each set-up buffer: ids, xy (3x2), attributes (3x7), 1/w (3),
#: positions (3x3), normals (3x3); their dtypes
_SETUP_WIDTH = (1, 6, 21, 3, 9, 9)


_SETUP_DTYPES = (np.int64, np.float64, np.float64, np.float64, np.float64, np.float64)


def setup_buffers(faces):
    """Six flat uninitialised buffers for the triangle set-up of a mesh of ``faces``
    faces (ids, ``xy``, attributes, ``1/w``, positions, normals: :data:`_SETUP_WIDTH`
    elements a face): a kept set nobody else references any more (the arrays of an
    earlier frame's set-up, views included, all dropped: ``sys.getrefcount``), else a new
    set, kept for later frames (fresh pages: a page fault per 4 KiB, 1300 a frame for
    the teapot).  The caller's views keep the set busy until they are dropped.

    Parameters
    ----------
    faces : int
        Faces of the mesh (an upper bound on the front-facing ones).

    Returns
    -------
    tuple of numpy.ndarray
        Six flat buffers, at least ``faces * width`` long each.

    Examples
    --------
    >>> a = setup_buffers(10); p = a[1].ctypes.data; del a
    >>> setup_buffers(10)[1].ctypes.data == p    # dropped: the same memory again
    True
    """
    with _MAPS_LOCK:
        for bufs in _SETUP:
            if (bufs[0].size >= faces and bufs[0].size <= 2 * faces + 64
                    and all(sys.getrefcount(bufs[k]) == 2 for k in range(len(bufs)))):
                return bufs
        n = faces + faces // 8 + 16
        bufs = tuple(np.empty(n * w, dt) for w, dt in zip(_SETUP_WIDTH, _SETUP_DTYPES))
        _SETUP.append(bufs)
        del _SETUP[:-_KEEP_SETUP]
        return bufs


def scratch(work, name, shape, dtype=np.float64):
    """An uninitialised array ``name`` of ``work`` (a :class:`Workspace`), or a new one
    when ``work`` is None.

    Parameters
    ----------
    work : Workspace or None
        The frame's workspace.
    name : str
        The array's name in it.
    shape : tuple of int
        The shape.
    dtype : numpy dtype, optional
        The dtype.

    Returns
    -------
    numpy.ndarray
        An uninitialised array.
    """
    return np.empty(shape, dtype) if work is None else work.empty(name, shape, dtype)


def span_arrays(S, Kc):
    """Arrays for ``S`` spans of ``Kc`` attributes: ``tri, row, x0, count, m, t0, dt, left,
    right``.

    Parameters
    ----------
    S : int
        The number of spans.
    Kc : int
        Attributes per span end.

    Returns
    -------
    tuple of numpy.ndarray
        ``(tri, row, x0, count, m, t0, dt, left, right)``, uninitialised.
    """
    return (np.empty(S, np.int64), np.empty(S, np.int64), np.empty(S, np.int64),
            np.empty(S, np.int64), np.empty(S, np.int64), np.empty(S), np.empty(S),
            np.empty((S, Kc)), np.empty((S, Kc)))


#: per thread: {Kc: span arrays} kept between frames (see span_buffers)
_SCRATCH = threading.local()


_SCRATCH_MAX = 1 << 21     # spans (about 350 MB); larger frames get fresh arrays


def span_buffers(S, Kc):
    """:func:`span_arrays` as views of buffers this thread keeps between frames: fresh
    pages cost as much as the span set-up itself (a page fault per 4 KiB in this VM,
    13 MB of spans at 1024x1024), reused ones nothing. Grown by a quarter when short.

    Parameters
    ----------
    S : int
        The number of spans.
    Kc : int
        Attributes per span end.

    Returns
    -------
    tuple of numpy.ndarray
        ``(tri, row, x0, count, m, t0, dt, left, right)``, uninitialised.
    """
    cache = getattr(_SCRATCH, "spans", None)
    if cache is None:
        cache = _SCRATCH.spans = {}
    buf = cache.get(Kc)
    if buf is None or buf[0].shape[0] < S:
        if S > _SCRATCH_MAX:
            cache.pop(Kc, None)
            return span_arrays(S, Kc)
        buf = cache[Kc] = span_arrays(min(S + S // 4 + 64, _SCRATCH_MAX), Kc)
    return tuple(b[:S] for b in buf)
