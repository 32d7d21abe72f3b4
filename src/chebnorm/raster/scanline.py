"""Camera, projection, viewport and the scan-line span set-up, batched in
numpy over all triangles (no Python loop per triangle or per pixel).

Conventions
-----------
* World space is right-handed; the camera looks along ``-z`` of its frame
  (OpenGL).  Screen space: ``x`` to the right, ``y`` down, pixel ``(row, col)``
  has its centre at ``(col + 0.5, row + 0.5)``.
* Coverage: a pixel belongs to a triangle when its centre lies in the
  half-open ranges ``[y_min, y_max)`` of the scan line and ``[x_left, x_right)``
  of the span (a top-left-like rule: shared edges are drawn once).
* Attributes (depth, normals, positions, intensities, ...) are interpolated
  linearly in *screen space*, first along the edges to the span ends and then
  along the span, as in the scan-line hardware of the papers (no perspective
  correction).  Depth is carried as ``1/w`` (affine in screen space); the
  z-buffer keeps the largest ``1/w``, ties going to the earliest fragment
  in (triangle, row, column) order, so output is deterministic.
* A span of triangle ``i`` on a scan line runs from its left edge crossing
  ``x_l`` to its right crossing ``x_r``; its pixels sit at
  ``t = t0 + j dt`` (``j = 0 .. count-1``) with ``t0 = (x_0 + 0.5 - x_l)/(x_r - x_l)``
  and ``dt = 1/(x_r - x_l)``: ``t0 > 0`` in general, the span ends are at
  fractional ``x``.  ``m = max(1, ceil(x_r - x_l))`` is its length in pixels.

The kernels here assume valid input (validated in :mod:`.render`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# an implementation module of chebnorm.raster: the API is what chebnorm.raster exports
__all__: list[str] = []


@dataclass(frozen=True)
class Camera:
    """A pinhole camera: ``eye``, ``target``, ``up`` (world), vertical field
    of view ``fov_y`` (radians).

    Attributes
    ----------
    eye : tuple of 3 float
        The camera's position (world).
    target : tuple of 3 float
        The point looked at.
    up : tuple of 3 float
        The up direction.
    fov_y : float
        Vertical field of view (radians).
    """

    eye: tuple
    target: tuple
    up: tuple = (0.0, 0.0, 1.0)
    fov_y: float = np.radians(30.0)

    def frame(self):
        """Rows: right, up, back (unit, right-handed); read only, computed once per camera
        (a frame calls it twice: projection and light)."""
        try:
            key = (tuple(map(float, self.eye)), tuple(map(float, self.target)),
                   tuple(map(float, self.up)))
        except (TypeError, ValueError):
            key = None
        got = _FRAMES.get(key) if key is not None else None
        if got is None:
            got = self._frame()
            got.flags.writeable = False
            if key is not None:
                if len(_FRAMES) >= 64:
                    _FRAMES.clear()
                _FRAMES[key] = got
        return got

    def _frame(self):
        eye, target = np.asarray(self.eye, float), np.asarray(self.target, float)
        back = eye - target
        back /= np.linalg.norm(back)
        right = np.cross(np.asarray(self.up, float), back)
        nr = np.linalg.norm(right)
        if nr < 1e-9:
            raise ValueError(f"camera up {self.up} is parallel to the view direction")
        right /= nr
        return np.stack([right, np.cross(back, right), back])


#: {(eye, target, up): frame}: :meth:`Camera.frame` of recent cameras
_FRAMES: dict = {}


def default_camera(center, radius, direction=(2.0, -3.0, 1.8), fov_y=np.radians(30.0)) -> Camera:
    """A camera looking at ``center`` from ``direction``, far enough for the
    bounding sphere ``radius`` to fill about 90 % of the view height.

    Parameters
    ----------
    center : array_like
        The point looked at.
    radius : float
        The bounding sphere's radius.
    direction : array_like, optional
        From the centre toward the eye.
    fov_y : float, optional
        Vertical field of view (radians).

    Returns
    -------
    Camera
        The camera.

    Examples
    --------
    >>> import numpy as np
    >>> cam = default_camera((0.0, 0.0, 0.0), 1.0)
    >>> bool(np.isclose(np.linalg.norm(cam.eye), 1 / np.sin(np.radians(15)) / 0.9))
    True
    """
    d = np.asarray(direction, float)
    d /= np.linalg.norm(d)
    dist = radius / np.sin(fov_y / 2) / 0.9
    eye = np.asarray(center, float) + dist * d
    return Camera(tuple(eye), tuple(np.asarray(center, float)), (0.0, 0.0, 1.0), float(fov_y))


def fit_camera(points, width: int, height: int, direction=(2.0, -3.0, 1.8),
               fov_y=np.radians(30.0), fill: float = 0.9) -> Camera:
    """:func:`default_camera` re-aimed and zoomed so that the projected
    ``points`` are centred and fill ``fill`` of the tighter image dimension.

    Parameters
    ----------
    points : numpy.ndarray
        World points ``(N, 3)`` to frame.
    width, height : int
        The image size in pixels.
    direction : array_like, optional
        From the points toward the eye.
    fov_y : float, optional
        Vertical field of view (radians).
    fill : float, optional
        The fraction of the tighter image dimension the points fill.

    Returns
    -------
    Camera
        The camera.

    Examples
    --------
    >>> import numpy as np
    >>> pts = np.array([[-1.0, -1, -1], [1, 1, 1]])
    >>> xy, _ = project(fit_camera(pts, 64, 48), pts, 64, 48)
    >>> bool(np.all((xy >= 0) & (xy <= [64, 48])))
    True
    """
    pts = np.asarray(points, float)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    center, radius = (lo + hi) / 2, float(np.linalg.norm(hi - lo) / 2) or 1.0
    cam = default_camera(center, radius, direction, fov_y)
    frame = cam.frame()
    pc = (pts - np.asarray(cam.eye)) @ frame.T
    w = -pc[:, 2]
    sx, sy = pc[:, 0] / w, pc[:, 1] / w  # tangent of the angle off the axis
    aspect = width / height
    half = max((sx.max() - sx.min()) / 2 / aspect, (sy.max() - sy.min()) / 2) / fill
    dist = float(np.linalg.norm(np.asarray(cam.eye) - center))
    shift = dist * ((sx.max() + sx.min()) / 2 * frame[0] + (sy.max() + sy.min()) / 2 * frame[1])
    return Camera(tuple(np.asarray(cam.eye) + shift), tuple(center + shift), cam.up,
                  2 * math.atan(float(half)))


def project(camera: Camera, points, width: int, height: int):
    """World points ``(..., 3)`` to screen ``(x, y)`` and ``1/w`` (w the
    distance along the view axis).  Raises ``ValueError`` if a point is not
    in front of the camera.

    The target lands on the image centre, at ``1/w = 1/|eye - target|``:

    Parameters
    ----------
    camera : Camera
        The view.
    points : numpy.ndarray
        World points ``(..., 3)``.
    width, height : int
        The image size in pixels.

    Returns
    -------
    xy : numpy.ndarray
        Screen coordinates ``(..., 2)`` in pixels.
    inv_w : numpy.ndarray
        ``1/w`` per point.

    Raises
    ------
    ValueError
        If a point is not in front of the camera.

    Examples
    --------
    >>> import numpy as np
    >>> cam = default_camera((0.0, 0.0, 0.0), 1.0)
    >>> xy, inv_w = project(cam, [[0.0, 0.0, 0.0]], 100, 100)
    >>> bool(np.allclose(xy, [[50.0, 50.0]])), bool(np.isclose(inv_w[0], 1 / np.linalg.norm(cam.eye)))
    (True, True)
    """
    frame = camera.frame()
    pc = (np.asarray(points, float) - np.asarray(camera.eye, float)) @ frame.T
    w = -pc[..., 2]
    if (w <= 1e-9).any():
        raise ValueError("the mesh reaches behind the camera, or within 1e-9 of the plane "
                         "through the eye (a mesh under about 1e-8 across, seen by the default "
                         "camera); move the camera back, or scale the mesh up")
    f = 1.0 / math.tan(camera.fov_y / 2)
    aspect = width / height
    x_ndc = f / aspect * pc[..., 0] / w
    y_ndc = f * pc[..., 1] / w
    sx = (x_ndc + 1) * 0.5 * width
    sy = (1 - y_ndc) * 0.5 * height
    return np.stack([sx, sy], -1), 1.0 / w


@dataclass(frozen=True)
class Spans:
    """Scan-line spans of a set of triangles (one row per span).

    ``tri``, ``row``, ``x0`` (first pixel column), ``count`` (pixels), ``m``
    (span length in pixels, >= 1), ``t0``, ``dt``: as in the module notes;
    ``left``, ``right``: the attributes ``(S, K)`` interpolated along the
    edges to the span ends; ``offsets (S+1,)``: span ``i``'s fragments are
    ``offsets[i]:offsets[i+1]`` of the fragment arrays.

    Fragment arrays (one entry per covered pixel of each span, in span order):
    ``frag_span``, ``frag_pixel`` (``row * width + col``), ``frag_t``.

    Attributes
    ----------
    tri, row, x0, count, m : numpy.ndarray
        Per span: triangle index, pixel row, first pixel column, pixel count, span length.
    t0, dt : numpy.ndarray
        Per span: the first pixel's position and the step along the span.
    left, right : numpy.ndarray
        The attributes at the span ends ``(S, K)``.
    offsets : numpy.ndarray
        ``(S + 1,)`` indices into the fragment arrays.
    frag_span, frag_pixel, frag_t : numpy.ndarray
        Per fragment: its span, its pixel index ``row * width + col`` and its position.
    """

    tri: np.ndarray
    row: np.ndarray
    x0: np.ndarray
    count: np.ndarray
    m: np.ndarray
    t0: np.ndarray
    dt: np.ndarray
    left: np.ndarray
    right: np.ndarray
    offsets: np.ndarray
    frag_span: np.ndarray
    frag_pixel: np.ndarray
    frag_t: np.ndarray

    @property
    def n_fragments(self) -> int:
        """The number of covered pixels (fragments) of all spans."""
        return int(self.offsets[-1])

    def lerp(self, cols) -> np.ndarray:
        """Attribute columns ``cols`` linearly interpolated at every fragment."""
        s, t = self.frag_span, self.frag_t[:, None]
        lo, hi = self.left[s][:, cols], self.right[s][:, cols]
        return lo + t * (hi - lo)


_EDGES = np.array([[0, 1], [1, 2], [2, 0]])


def setup_spans(xy, attrs, width: int, height: int) -> Spans:
    """Triangle set-up into spans: ``xy (T,3,2)`` screen corners, ``attrs
    (T,3,K)`` corner attributes.  Vectorized over triangles, rows and pixels.

    A right triangle with legs of 8 pixels from the centre of pixel (0, 0):
    rows 0..7, row ``r`` covering the ``8 - r`` centres left of the
    hypotenuse ``x + y = 9`` (half-open ranges), 36 pixels in all:

    Parameters
    ----------
    xy : numpy.ndarray
        Screen corners ``(T, 3, 2)``.
    attrs : numpy.ndarray
        Corner attributes ``(T, 3, K)``.
    width, height : int
        The image size in pixels.

    Returns
    -------
    Spans
        The spans and their fragments (pixel centres inside, half-open ranges).

    Examples
    --------
    >>> import numpy as np
    >>> sp = setup_spans(np.array([[[0.5, 0.5], [8.5, 0.5], [0.5, 8.5]]]), np.zeros((1, 3, 1)), 16, 16)
    >>> sp.count.tolist(), sp.n_fragments
    ([8, 7, 6, 5, 4, 3, 2, 1], 36)
    """
    xy = np.asarray(xy, float)
    attrs = np.asarray(attrs, float)
    T, _, K = attrs.shape
    ys = xy[..., 1]
    ymin, ymax = ys.min(axis=1), ys.max(axis=1)
    r0 = np.clip(np.ceil(ymin - 0.5), 0, height).astype(np.int64)
    r1 = np.clip(np.ceil(ymax - 0.5), 0, height).astype(np.int64)
    nrows = np.maximum(r1 - r0, 0)
    tri = np.repeat(np.arange(T, dtype=np.int64), nrows)
    start = np.cumsum(nrows) - nrows
    row = r0[tri] + (np.arange(len(tri), dtype=np.int64) - start[tri])
    y = row + 0.5
    # edge crossings: edge e = (i, j) is hit when min(yi,yj) <= y < max(yi,yj)
    yi = ys[tri][:, _EDGES[:, 0]]
    yj = ys[tri][:, _EDGES[:, 1]]
    hit = (np.minimum(yi, yj) <= y[:, None]) & (y[:, None] < np.maximum(yi, yj))
    # exactly two edges are hit (half-open intervals around a closed loop)
    e_first = np.argmax(hit, axis=1)
    e_second = 2 - np.argmax(hit[:, ::-1], axis=1)
    ok = hit.sum(axis=1) == 2
    tri, row, y, e_first, e_second = tri[ok], row[ok], y[ok], e_first[ok], e_second[ok]

    def crossing(e):
        i, j = _EDGES[e, 0], _EDGES[e, 1]
        pi, pj = xy[tri, i], xy[tri, j]
        s = (y - pi[:, 1]) / (pj[:, 1] - pi[:, 1])
        x = pi[:, 0] + s * (pj[:, 0] - pi[:, 0])
        ai, aj = attrs[tri, i], attrs[tri, j]
        return x, ai + s[:, None] * (aj - ai)

    xa, aa = crossing(e_first)
    xb, ab = crossing(e_second)
    swap = xb < xa
    xl = np.where(swap, xb, xa)
    xr = np.where(swap, xa, xb)
    left = np.where(swap[:, None], ab, aa)
    right = np.where(swap[:, None], aa, ab)
    c0 = np.clip(np.ceil(xl - 0.5), 0, width).astype(np.int64)
    c1 = np.clip(np.ceil(xr - 0.5), 0, width).astype(np.int64)
    count = np.maximum(c1 - c0, 0)
    keep = count > 0
    tri, row, xl, xr, c0, count = tri[keep], row[keep], xl[keep], xr[keep], c0[keep], count[keep]
    left, right = left[keep], right[keep]
    width_span = xr - xl
    dt = 1.0 / width_span
    t0 = (c0 + 0.5 - xl) * dt
    m = np.maximum(1, np.ceil(width_span)).astype(np.int64)
    offsets = np.zeros(len(count) + 1, dtype=np.int64)
    np.cumsum(count, out=offsets[1:])
    frag_span = np.repeat(np.arange(len(count), dtype=np.int64), count)
    j = np.arange(offsets[-1], dtype=np.int64) - offsets[:-1][frag_span]
    frag_pixel = row[frag_span] * width + c0[frag_span] + j
    frag_t = np.clip(t0[frag_span] + j * dt[frag_span], 0.0, 1.0)
    return Spans(tri, row, c0, count, m, t0, dt, left, right, offsets, frag_span, frag_pixel,
                 frag_t)


def zbuffer(pixel, inv_w, n_pixels: int):
    """Indices of the visible fragments (largest ``1/w`` per pixel, ties to
    the earliest fragment), sorted by pixel.

    Parameters
    ----------
    pixel : numpy.ndarray
        Pixel index per fragment.
    inv_w : numpy.ndarray
        ``1/w`` per fragment (larger is nearer).
    n_pixels : int
        The number of pixels of the image.

    Returns
    -------
    numpy.ndarray
        Indices of the visible fragments, sorted by pixel.

    Examples
    --------
    >>> import numpy as np
    >>> zbuffer(np.array([3, 1, 3]), np.array([0.5, 0.2, 0.9]), 4).tolist()
    [1, 2]
    """
    order = np.lexsort((np.arange(len(pixel)), -inv_w, pixel))
    p = pixel[order]
    first = np.ones(len(p), dtype=bool)
    first[1:] = p[1:] != p[:-1]
    return order[first]
