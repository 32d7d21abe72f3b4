"""Triangle meshes with unit vertex normals and, where the surface is
parametric, the parametrization ``(u, v)`` and its partial derivatives
``P_u, P_v`` (needed by bump mapping, seed 001).

Generators: :func:`uv_sphere`, :func:`icosphere`, :func:`torus`,
:func:`square`, :func:`teapot` (Newell's 32 Bezier patches, normals from
``dP/du x dP/dv``, seed 000), and :func:`load_mesh` for OBJ/PLY/STL files
through trimesh (an OBJ file's own ``vn`` normals, else vertex normals
averaged over faces, kept apart across edges sharper than a crease angle,
seed 000).  :func:`get_mesh` dispatches on a
name or a path.

Every mesh is validated once, when it is built (:class:`Mesh`): finite
positions, unit finite normals, indices in range, no zero-area triangle.
Faces are wound counter-clockwise seen from the side the vertex normals point
to (generators re-orient faces whose winding disagrees with their normals).

>>> m = uv_sphere(8)
>>> m.faces.shape, bool(abs(np.linalg.norm(m.normals, axis=1) - 1).max() < 1e-12)
((224, 3), True)
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from chebnorm.core.display import field_rows, summary_html, summary_repr
from chebnorm.methods import detmath

# an implementation module of chebnorm.raster: the API is what chebnorm.raster exports
__all__: list[str] = []

#: the generated meshes :func:`get_mesh` knows by name
MESH_NAMES = ("teapot", "sphere", "icosphere", "torus", "square")

#: a triangle whose area is below AREA_RTOL * (bounding-box diagonal)^2 is degenerate
AREA_RTOL = 1e-14
#: vertex normals must have |n| within this of 1
UNIT_ATOL = 1e-6
#: the largest vertex coordinate accepted, in magnitude: normals and areas square
#: lengths twice (``|(b - a) x (c - a)|**2`` is a fourth power of the coordinates),
#: which stays finite in float64 below 2**255; 2**200 (about 1.6e60) leaves the
#: renderer's camera and lighting room
MAX_COORDINATE = 2.0 ** 200
#: the smallest bounding-box extent accepted: the same fourth powers stay above
#: float64's underflow (2**-1022) with the area tolerance's 1e-14 to spare
MIN_EXTENT = 2.0 ** -200
#: the most faces a mesh may have: a frame's triangle map is int32 (a GPU's primitive
#: id is 32 bits too)
MAX_FACES = 2**31 - 1


@dataclass(frozen=True, eq=False)
class Mesh:
    """A triangle mesh: ``positions (V,3)``, unit ``normals (V,3)``,
    ``faces (F,3)`` int64; optional ``uv (V,2)``, ``P_u (V,3)``, ``P_v (V,3)``.

    Construction validates everything and raises ``ValueError`` naming the
    first bad value.

    Parameters
    ----------
    name : str
        The mesh's name (a generator's or the file's).
    positions : numpy.ndarray
        Vertex positions, float64 ``(V, 3)``.
    normals : numpy.ndarray
        Unit vertex normals, float64 ``(V, 3)``.
    faces : numpy.ndarray
        Vertex indices of the triangles, int64 ``(F, 3)``.
    uv : numpy.ndarray, optional
        Surface parameters ``(V, 2)`` (bump mapping needs them).
    P_u, P_v : numpy.ndarray, optional
        Surface partial derivatives ``(V, 3)``.

    Raises
    ------
    ValueError
        Naming the first bad value (shape, dtype, non-finite, non-unit normal, index out of range).

    Examples
    --------
    >>> import numpy as np
    >>> m = Mesh("tri", np.eye(3), np.tile([0.0, 0.0, 1.0], (3, 1)), np.array([[0, 1, 2]]))
    >>> m.faces.shape, m.has_parametrization
    ((1, 3), False)
    """

    name: str
    positions: np.ndarray
    normals: np.ndarray
    faces: np.ndarray
    uv: np.ndarray | None = None
    P_u: np.ndarray | None = None
    P_v: np.ndarray | None = None

    def _summary(self) -> list[tuple[str, object]]:
        return [("name", self.name), ("vertices", len(self.positions)),
                ("faces", len(self.faces)), ("uv", self.uv is not None)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    def __post_init__(self):
        pos = np.array(self.positions, dtype=np.float64)
        nrm = np.array(self.normals, dtype=np.float64)
        fac = np.array(self.faces)
        name = self.name
        if pos.ndim != 2 or pos.shape[1] != 3 or len(pos) == 0:
            raise ValueError(f"mesh {name!r}: positions must have shape (V, 3) with V >= 1; "
                             f"got {pos.shape}")
        if nrm.shape != pos.shape:
            raise ValueError(f"mesh {name!r}: normals must have the shape of positions "
                             f"{pos.shape}; got {nrm.shape}")
        if fac.ndim != 2 or fac.shape[1] != 3 or len(fac) == 0:
            raise ValueError(f"mesh {name!r}: faces must have shape (F, 3) with F >= 1; got {fac.shape}")
        if not np.issubdtype(fac.dtype, np.integer):
            raise ValueError(f"mesh {name!r}: faces must be integer indices; got dtype {fac.dtype}")
        if len(fac) > MAX_FACES:
            raise ValueError(f"mesh {name!r}: at most {MAX_FACES} faces (the triangle map is "
                             f"int32); got {len(fac)}")
        fac = fac.astype(np.int64)
        bad = ~np.isfinite(pos).all(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"mesh {name!r}: position {i} is not finite: {pos[i].tolist()}")
        _check_scale(pos, f"mesh {name!r}")
        bad = ~np.isfinite(nrm).all(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"mesh {name!r}: vertex normal {i} is not finite: {nrm[i].tolist()} "
                             "(NaN normals: degenerate geometry or a broken file)")
        length = np.linalg.norm(nrm, axis=1)
        bad = np.abs(length - 1) > UNIT_ATOL
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"mesh {name!r}: vertex normal {i} has length {length[i]!r}; "
                             f"expected 1 within {UNIT_ATOL:g}")
        if fac.min() < 0 or fac.max() >= len(pos):
            raise ValueError(f"mesh {name!r}: face indices must lie in [0, {len(pos) - 1}]; "
                             f"got [{fac.min()}, {fac.max()}]")
        bad = _degenerate_faces(pos, fac)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"mesh {name!r}: triangle {i} (vertices {fac[i].tolist()}) is degenerate "
                             f"(zero area); {int(bad.sum())} such triangle(s) in total")
        for attr, width in (("uv", 2), ("P_u", 3), ("P_v", 3)):
            val = getattr(self, attr)
            if val is not None:
                val = np.array(val, dtype=np.float64)
                if val.shape != (len(pos), width) or not np.isfinite(val).all():
                    raise ValueError(f"mesh {name!r}: {attr} must be finite with shape "
                                     f"({len(pos)}, {width}); got {val.shape}")
                object.__setattr__(self, attr, val)
        object.__setattr__(self, "positions", pos)
        object.__setattr__(self, "normals", nrm)
        object.__setattr__(self, "faces", fac)

    @property
    def has_parametrization(self) -> bool:
        return self.uv is not None and self.P_u is not None and self.P_v is not None

    def face_normals(self) -> np.ndarray:
        """Unit geometric normals of the faces (from the winding)."""
        cr = _face_cross(self.positions, self.faces)
        return cr / np.linalg.norm(cr, axis=1, keepdims=True)

    def bounds(self) -> tuple[np.ndarray, float]:
        """Centre of the bounding box and the radius of its bounding sphere."""
        lo, hi = self.positions.min(axis=0), self.positions.max(axis=0)
        return (lo + hi) / 2, float(np.linalg.norm(hi - lo) / 2)


def _check_scale(pos: np.ndarray, what: str) -> None:
    """Refuse finite positions whose squared areas would overflow or underflow
    (:data:`MAX_COORDINATE`, :data:`MIN_EXTENT`), before any arithmetic on them."""
    big = float(np.max(np.abs(pos)))
    if big > MAX_COORDINATE:
        i = int(np.flatnonzero(np.abs(pos).max(axis=1) == big)[0])
        raise ValueError(f"{what}: vertex {i} has a coordinate of magnitude {big:.6g}; normals "
                         f"and areas square lengths twice, which overflows float64; accepted: "
                         f"coordinates up to 2^200 (about 1.6e60) in magnitude (scale the mesh)")
    extent = float(np.max(pos.max(axis=0) - pos.min(axis=0)))
    if len(pos) > 1 and extent < MIN_EXTENT:
        raise ValueError(f"{what}: the vertices span only {extent:.6g}; normals and areas square "
                         f"lengths twice, which underflows float64; accepted: a bounding box at "
                         f"least 2^-200 (about 6.2e-61) across (scale the mesh)")


def _degenerate_faces(pos: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Mask of triangles whose doubled area is at most AREA_RTOL times the
    squared bounding-box diagonal (zero area, up to rounding)."""
    area2 = np.linalg.norm(_face_cross(pos, faces), axis=1)
    diag2 = float(np.sum((pos.max(axis=0) - pos.min(axis=0)) ** 2))
    return area2 <= AREA_RTOL * max(diag2, np.finfo(float).tiny)


def _face_cross(pos, faces):
    a, b, c = pos[faces[:, 0]], pos[faces[:, 1]], pos[faces[:, 2]]
    return np.cross(b - a, c - a)


def unit(v):
    """``v / |v|`` along the last axis (``np.linalg.norm``: its summation order is part
    of the renderer's reference bytes).

    Parameters
    ----------
    v : numpy.ndarray
        Vectors ``(..., 3)``.

    Returns
    -------
    numpy.ndarray
        The unit vectors (``v`` divided by its norm: NaN where ``v`` is zero).

    Examples
    --------
    >>> unit(np.array([3.0, 4.0])).tolist()
    [0.6, 0.8]
    """
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _orient(pos, normals, faces):
    """Flip the winding of faces whose geometric normal opposes their vertex normals."""
    cr = _face_cross(pos, faces)
    s = np.einsum("fk,fk->f", cr, normals[faces].sum(axis=1))
    faces = faces.copy()
    flip = s < 0
    faces[flip] = faces[flip][:, [0, 2, 1]]
    return faces


def _drop_degenerate(pos, faces):
    area2 = np.linalg.norm(_face_cross(pos, faces), axis=1)
    diag2 = float(np.sum((pos.max(axis=0) - pos.min(axis=0)) ** 2))
    return faces[area2 > 1e3 * AREA_RTOL * diag2]


def _grid_faces(nu, nv, wrap_u=False, wrap_v=False):
    """Two triangles per cell of an (nu+1) x (nv+1) vertex grid, row-major in u."""
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    i, j = i.ravel(), j.ravel()
    w = nv + 1
    a = i * w + j
    b = (i + 1) * w + j
    c = (i + 1) * w + j + 1
    d = i * w + j + 1
    return np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.int64)


def _check_tess(tess, lo, hi, name):
    if isinstance(tess, bool) or not isinstance(tess, (int, np.integer)) or not lo <= tess <= hi:
        raise ValueError(f"{name}: tessellation level must be an integer in [{lo}, {hi}]; got {tess!r}")
    return int(tess)


def uv_sphere(tess: int = 16) -> Mesh:
    """Unit sphere, z up: ``2*tess`` segments in longitude, ``tess`` rings;
    ``u = phi/(2 pi)``, ``v = 1 - theta/pi`` (theta from the north pole), so
    ``P_u x P_v`` points outward.  Normals are exact (the positions).

    At the poles ``P_u`` vanishes; pole vertices carry ``P_u`` evaluated a
    quarter ring away from the pole so that a tangent frame exists there.

    ``(tess + 1)(2 tess + 1)`` vertices (the seam and the poles repeated) and
    ``2 (2 tess) tess`` grid triangles less the ``2 (2 tess)`` of zero area at
    the poles:

    Parameters
    ----------
    tess : int, optional
        Tessellation: rings (``2 tess`` segments) (default 16).

    Returns
    -------
    Mesh
        The mesh with its ``uv``, ``P_u`` and ``P_v``.

    Raises
    ------
    ValueError
        For ``tess`` out of range.

    Examples
    --------
    >>> import numpy as np
    >>> s = uv_sphere(4)
    >>> len(s.positions), len(s.faces)
    (45, 48)
    >>> bool(np.allclose(np.linalg.norm(s.positions, axis=1), 1.0))
    True
    """
    k = _check_tess(tess, 2, 1024, "uv_sphere")
    nu, nv = 2 * k, k
    u = np.linspace(0.0, 1.0, nu + 1)
    v = np.linspace(0.0, 1.0, nv + 1)
    U, V = np.meshgrid(u, v, indexing="ij")
    phi, theta = 2 * np.pi * U, np.pi * (1 - V)
    st, ct, sp, cp = np.sin(theta), np.cos(theta), np.sin(phi), np.cos(phi)
    pos = np.stack([st * cp, st * sp, ct], -1).reshape(-1, 3)
    pole = (V == 0) | (V == 1)
    pos[pole.ravel()] = np.stack([np.zeros(pole.sum()), np.zeros(pole.sum()), ct[pole]], -1)
    st_frame = np.where(pole, np.sin(np.pi / nv / 4), st)
    P_u = (2 * np.pi * np.stack([-st_frame * sp, st_frame * cp, np.zeros_like(st)], -1)).reshape(-1, 3)
    P_v = (-np.pi * np.stack([ct * cp, ct * sp, -st], -1)).reshape(-1, 3)
    faces = _drop_degenerate(pos, _grid_faces(nu, nv))
    nrm = unit(pos)
    return Mesh("sphere", pos, nrm, _orient(pos, nrm, faces), np.stack([U, V], -1).reshape(-1, 2),
                P_u, P_v)


def icosphere(tess: int = 3) -> Mesh:
    """Unit icosphere: ``tess`` subdivisions (0..7) of an icosahedron;
    normals are the positions.  No parametrization (bump mapping needs one).

    ``20 * 4**tess`` faces and, by Euler's formula, ``10 * 4**tess + 2``
    vertices:

    Parameters
    ----------
    tess : int, optional
        Tessellation: subdivisions, 0..7 (default 3).

    Returns
    -------
    Mesh
        The mesh.

    Raises
    ------
    ValueError
        For ``tess`` out of range.

    Examples
    --------
    >>> m = icosphere(2)
    >>> len(m.faces), len(m.positions)
    (320, 162)
    """
    import trimesh

    k = _check_tess(tess, 0, 7, "icosphere")
    tm = trimesh.creation.icosphere(subdivisions=k)
    pos = np.asarray(tm.vertices, dtype=np.float64)
    nrm = unit(pos)
    return Mesh("icosphere", pos, nrm, _orient(pos, nrm, np.asarray(tm.faces, dtype=np.int64)))


def torus(tess: int = 16, R: float = 1.0, r: float = 0.4) -> Mesh:
    """Torus around z: ``2*tess`` segments around the axis (``u``), ``tess``
    around the tube (``v``); exact normals and ``P_u, P_v``.

    The normal is ``P_u x P_v`` normalized (seed 001):

    Parameters
    ----------
    tess : int, optional
        Segments around the tube (``2 tess`` around the axis).
    R : float, optional
        Distance from the axis to the tube's centre.
    r : float, optional
        The tube's radius, ``0 < r < R``.

    Returns
    -------
    Mesh
        The torus with ``uv``, ``P_u`` and ``P_v``.

    Raises
    ------
    ValueError
        For arguments out of range.

    Examples
    --------
    >>> import numpy as np
    >>> t = torus(4)
    >>> len(t.faces)
    64
    >>> n = np.cross(t.P_u, t.P_v)
    >>> bool(np.allclose(n / np.linalg.norm(n, axis=1, keepdims=True), t.normals))
    True
    """
    k = _check_tess(tess, 3, 1024, "torus")
    nu, nv = 2 * k, k
    U, V = np.meshgrid(np.linspace(0, 1, nu + 1), np.linspace(0, 1, nv + 1), indexing="ij")
    a, b = 2 * np.pi * U, 2 * np.pi * V
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
    rad = R + r * cb
    pos = np.stack([rad * ca, rad * sa, r * sb], -1).reshape(-1, 3)
    nrm = np.stack([cb * ca, cb * sa, sb], -1).reshape(-1, 3)
    P_u = (2 * np.pi * np.stack([-rad * sa, rad * ca, np.zeros_like(rad)], -1)).reshape(-1, 3)
    P_v = (2 * np.pi * r * np.stack([-sb * ca, -sb * sa, cb], -1)).reshape(-1, 3)
    faces = _grid_faces(nu, nv)
    return Mesh("torus", pos, nrm, _orient(pos, nrm, faces), np.stack([U, V], -1).reshape(-1, 2),
                P_u, P_v)


def square(tess: int = 8) -> Mesh:
    """Flat square ``[-1, 1]^2`` in the plane z = 0, normal +z, ``tess x tess``
    cells; ``P_u = (2, 0, 0)``, ``P_v = (0, 2, 0)``: a square patch, k = 2.

    Parameters
    ----------
    tess : int, optional
        Tessellation: cells per side (default 8).

    Returns
    -------
    Mesh
        The mesh with its ``uv``, ``P_u`` and ``P_v``.

    Raises
    ------
    ValueError
        For ``tess`` out of range.

    Examples
    --------
    >>> s = square(2)
    >>> len(s.positions), len(s.faces), s.P_u[0].tolist()
    (9, 8, [2.0, 0.0, 0.0])
    """
    k = _check_tess(tess, 1, 4096, "square")
    U, V = np.meshgrid(np.linspace(0, 1, k + 1), np.linspace(0, 1, k + 1), indexing="ij")
    pos = np.stack([2 * U - 1, 2 * V - 1, np.zeros_like(U)], -1).reshape(-1, 3)
    nrm = np.tile([0.0, 0.0, 1.0], (len(pos), 1))
    P_u = np.tile([2.0, 0.0, 0.0], (len(pos), 1))
    P_v = np.tile([0.0, 2.0, 0.0], (len(pos), 1))
    faces = _grid_faces(k, k)
    return Mesh("square", pos, nrm, _orient(pos, nrm, faces), np.stack([U, V], -1).reshape(-1, 2),
                P_u, P_v)


def _bernstein(t):
    s = 1 - t
    b = np.stack([detmath.power(s, 3), 3 * s * s * t, 3 * s * t * t, detmath.power(t, 3)], -1)
    db = np.stack([-3 * s * s, 3 * s * s - 6 * s * t, 6 * s * t - 3 * t * t, 3 * t * t], -1)
    return b, db


def _teapot_patches():
    from .teapot_data import PATCHES, POINTS

    pts = np.array([[float(x) for x in s.split()] for s in POINTS.replace("\n", ";").split(";")
                    if s.strip()])
    idx = np.array(PATCHES.split(), dtype=np.int64).reshape(-1, 4, 4) - 1
    return pts[idx]  # (32, 4, 4, 3)


#: In Newell's data dP/du x dP/dv points into the teapot on all 32 patches
#: (checked at each patch centre: rim -z, body toward the axis, bottom +z,
#: handle and spout toward their core); the outward normal is its negative.
_TEAPOT_SIGN = -1.0


def teapot(tess: int = 20) -> Mesh:
    """Newell's Utah teapot, 32 bicubic Bezier patches, each on a
    ``tess x tess`` grid; ``z`` up, about 3.15 tall.  The default ``tess =
    20`` keeps every scan-line span of a 512x512 view within pi/4 (the range
    of the default coefficient tables); at ``tess = 8`` the spout lip bends
    by up to 84 degrees across one span.

    Normals are ``dP/du x dP/dv`` (seed 000), oriented outward.  Where that
    cross product vanishes (the collapsed rows at the lid knob and the bottom
    centre) the normal is the limit, taken at a parameter ``1e-4`` inside the
    patch.  Zero-area triangles at those poles are dropped.  Patch vertices
    are not welded; ``uv`` is the patch parameter (each patch spans [0,1]^2),
    with ``u`` and ``v`` of the data swapped so that ``P_u x P_v`` is outward.

    Parameters
    ----------
    tess : int, optional
        Tessellation: grid size per patch (default 20).

    Returns
    -------
    Mesh
        The mesh with its ``uv``, ``P_u`` and ``P_v``.

    Raises
    ------
    ValueError
        For ``tess`` out of range.

    Examples
    --------
    >>> t = teapot(4)
    >>> t.has_parametrization, round(float(t.positions[:, 2].max() - t.positions[:, 2].min()), 2)
    (True, 3.15)
    """
    k = _check_tess(tess, 1, 256, "teapot")
    ctrl = _teapot_patches()
    s = np.linspace(0.0, 1.0, k + 1)
    B, dB = _bernstein(s)
    # P[p, i, j] = sum_ab B_a(u_i) B_b(v_j) ctrl[p, a, b]
    P = np.einsum("ia,jb,pabk->pijk", B, B, ctrl)
    Pu = np.einsum("ia,jb,pabk->pijk", dB, B, ctrl)
    Pv = np.einsum("ia,jb,pabk->pijk", B, dB, ctrl)
    cr = np.cross(Pu, Pv)
    scale = np.linalg.norm(Pu, axis=-1) * np.linalg.norm(Pv, axis=-1)
    small = np.linalg.norm(cr, axis=-1) <= 1e-9 * np.maximum(scale, 1e-300) + 1e-12
    if small.any():
        p, i, j = np.nonzero(small)
        uu = np.clip(s[i], 1e-4, 1 - 1e-4)
        vv = np.clip(s[j], 1e-4, 1 - 1e-4)
        bu, dbu = _bernstein(uu)
        bv, dbv = _bernstein(vv)
        pu2 = np.einsum("na,nb,nabk->nk", dbu, bv, ctrl[p])
        pv2 = np.einsum("na,nb,nabk->nk", bu, dbv, ctrl[p])
        cr[p, i, j] = np.cross(pu2, pv2)
        Pu[p, i, j], Pv[p, i, j] = pu2, pv2  # a tangent frame for bump mapping
    nrm = unit(cr)
    nrm *= _TEAPOT_SIGN
    n_p = len(ctrl)
    pos = P.reshape(-1, 3)
    nrm = nrm.reshape(-1, 3)
    base = (np.arange(n_p) * (k + 1) ** 2)[:, None, None]
    faces = (base + _grid_faces(k, k)[None]).reshape(-1, 3)
    faces = _drop_degenerate(pos, faces)
    U, V = np.meshgrid(s, s, indexing="ij")
    uv = np.tile(np.stack([U, V], -1).reshape(-1, 2), (n_p, 1))
    # the outward normal is -(dP/du x dP/dv): swap the roles of u and v so that
    # the mesh's (u, v, P_u, P_v) have P_u x P_v outward, as bump mapping expects
    return Mesh("teapot", pos, nrm, _orient(pos, nrm, faces), uv[:, ::-1], Pv.reshape(-1, 3),
                Pu.reshape(-1, 3))


def crease_normals(positions, faces, crease_angle: float = np.radians(30.0)):
    """Vertex normals averaged (weighted by corner angle) over the faces around each
    vertex, kept apart across edges whose faces meet at more than
    ``crease_angle`` (radians, seed 000: "kept apart across sharp edges").

    Returns ``(positions, normals, faces)`` with vertices split where a vertex
    carries more than one normal.  Fully vectorized: one pass over the pairs
    of faces sharing a vertex.

    A cube's faces meet at 90 degrees: each corner splits into three
    vertices, one per face, each with its face's normal; with a crease angle
    above 90 degrees nothing splits:

    Parameters
    ----------
    positions : numpy.ndarray
        Vertex positions ``(V, 3)``.
    faces : numpy.ndarray
        Triangles ``(F, 3)``.
    crease_angle : float, optional
        Faces meeting at a larger angle (radians) keep separate normals; default 30 degrees.

    Returns
    -------
    tuple of numpy.ndarray
        ``(positions, normals, faces)`` with split vertices.

    Examples
    --------
    >>> import numpy as np, trimesh
    >>> box = trimesh.creation.box()
    >>> pos, nrm, faces = crease_normals(box.vertices, box.faces)
    >>> len(box.vertices), len(pos), sorted(np.abs(nrm).sum(axis=1).round(12).tolist()) == [1.0] * 24
    (8, 24, True)
    >>> len(crease_normals(box.vertices, box.faces, np.radians(100))[0])
    8
    """
    pos = np.asarray(positions, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    if not (0 <= crease_angle <= np.pi):
        raise ValueError(f"crease angle must lie in [0, pi] radians; got {crease_angle!r}")
    fn = unit(_face_cross(pos, faces))
    # angle weighting (Thuermer-Wuethrich): a face's weight at a vertex is its
    # corner angle there, so a quad split into triangles counts as one face
    tri_pos = pos[faces]
    e1 = np.roll(tri_pos, -1, axis=1) - tri_pos
    e2 = np.roll(tri_pos, 1, axis=1) - tri_pos
    corner_angle = detmath.arctan2(np.linalg.norm(np.cross(e1, e2), axis=2),
                                   np.einsum("fck,fck->fc", e1, e2)).ravel()
    corner_v = faces.ravel()
    corner_f = np.repeat(np.arange(len(faces)), 3)
    order = np.argsort(corner_v, kind="stable")
    cv, cf = corner_v[order], corner_f[order]
    starts = np.searchsorted(cv, cv, side="left")
    ends = np.searchsorted(cv, cv, side="right")
    deg = ends - starts
    # pairs (corner c, corner d) sharing the vertex of c
    rep = np.repeat(np.arange(len(cv)), deg)
    off = np.arange(len(rep)) - np.repeat(np.cumsum(deg) - deg, deg)
    other = starts[rep] + off
    fa, fb = cf[rep], cf[other]
    keep = np.einsum("pk,pk->p", fn[fa], fn[fb]) >= np.cos(crease_angle) - 1e-12
    acc = np.zeros((len(cv), 3))
    weight = corner_angle[order][other]
    np.add.at(acc, rep[keep], weight[keep, None] * fn[fb[keep]])
    cn = unit(acc)
    corner_normals = np.empty_like(cn)
    corner_normals[order] = cn
    # one vertex per (old vertex, distinct normal)
    key = np.concatenate([corner_v[:, None].astype(np.float64),
                          np.round(corner_normals * 1e9)], axis=1)
    uniq, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    new_pos = pos[corner_v[first]]
    new_nrm = corner_normals[first]
    return new_pos, new_nrm, inverse.reshape(-1, 3).astype(np.int64)


#: default crease angle of :func:`load_mesh` (degrees)
DEFAULT_CREASE_DEG = 30.0


def _check_obj_numbers(path: str) -> None:
    """Refuse an OBJ file whose ``v`` or ``vn`` lines hold a non-finite
    number, or whose ``vn`` is the zero vector, naming the vertex / normal by
    its OBJ index (1-based, as ``f`` lines count) and its line. trimesh would
    otherwise drop the triangles that use it without a word."""
    counts = {"v": 0, "vn": 0}
    with open(path, encoding="utf-8", errors="replace") as fh:
        for lineno, line in enumerate(fh, 1):
            parts = line.split()
            if not parts or parts[0] not in counts:
                continue
            key = parts[0]
            counts[key] += 1
            what = "vertex" if key == "v" else "normal"
            try:
                xyz = [float(t) for t in parts[1:4]]
            except ValueError:
                raise ValueError(f"mesh file {path!r}: {what} {counts[key]} (line {lineno}) is not "
                                 f"a number triple: {' '.join(parts[1:4])!r}") from None
            if len(xyz) != 3 or not all(np.isfinite(xyz)):
                raise ValueError(f"mesh file {path!r}: {what} {counts[key]} (line {lineno}) is not "
                                 f"finite: {' '.join(parts[1:4])!r}; every coordinate must be a "
                                 "finite number")
            if key == "vn" and not any(xyz):
                raise ValueError(f"mesh file {path!r}: normal {counts[key]} (line {lineno}) is the "
                                 "zero vector; a normal needs a direction")


def _read_obj(path: str):
    """Positions, faces and the file's own vertex normals (``None`` unless
    every triangle carries ``vn`` indices) of an OBJ file, through trimesh's
    OBJ reader, which splits a vertex that carries different normals in
    different faces."""
    from trimesh.exchange.obj import load_obj

    _check_obj_numbers(path)
    with open(path, encoding="utf-8", errors="replace") as fh:
        parts = load_obj(fh)["geometry"].values()
    parts = [g for g in parts if len(g.get("faces", ())) and len(g.get("vertices", ()))]
    if not parts:
        return None, None, None
    pos, faces, normals, offset = [], [], [], 0
    for g in parts:
        v = np.asarray(g["vertices"], dtype=np.float64)
        pos.append(v)
        faces.append(np.asarray(g["faces"], dtype=np.int64) + offset)
        vn = g.get("vertex_normals")
        normals.append(None if vn is None or np.shape(vn) != v.shape
                       else np.asarray(vn, dtype=np.float64))
        offset += len(v)
    nrm = None if any(n is None for n in normals) else np.concatenate(normals)
    return np.concatenate(pos), np.concatenate(faces), nrm


def _read_other(path: str):
    """Positions and faces of a PLY or STL file (file order, then merged
    vertices); the file is refused when a vertex is not finite."""
    import trimesh

    tm = trimesh.load(path, force="mesh", process=False)
    if not isinstance(tm, trimesh.Trimesh) or len(tm.faces) == 0:
        return None, None, None
    pos = np.asarray(tm.vertices, dtype=np.float64)
    bad = ~np.isfinite(pos).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"mesh file {path!r}: vertex {i} (0-based, file order) is not finite: "
                         f"{pos[i].tolist()}; every coordinate must be a finite number")
    tm.merge_vertices()
    return (np.asarray(tm.vertices, dtype=np.float64), np.asarray(tm.faces, dtype=np.int64), None)


def load_mesh(path, crease_angle: float | None = None) -> Mesh:
    """Read an OBJ, PLY or STL file with trimesh.

    Normals: an OBJ file's own ``vn`` normals (normalized) when every
    triangle carries them and ``crease_angle`` is ``None``; otherwise vertex
    normals averaged over the faces and kept apart across edges sharper than
    ``crease_angle`` radians (:func:`crease_normals`; default
    ``DEFAULT_CREASE_DEG`` degrees). Faces whose winding opposes their
    vertex normals are re-wound.

    Raises ``ValueError`` for a missing or unreadable file, a vertex or normal
    that is not finite (naming it: trimesh would silently drop its
    triangles), a zero normal, and degenerate triangles.

    Parameters
    ----------
    path : str or os.PathLike
        An ``.obj``, ``.ply`` or ``.stl`` file.
    crease_angle : float, optional
        Crease angle in radians (see above).

    Returns
    -------
    Mesh
        The mesh, without ``uv``, ``P_u``, ``P_v``.

    Raises
    ------
    ValueError
        See above.

    Examples
    --------
    >>> import tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "tri.obj")
    >>> _ = open(p, "w").write("v 0 0 0\\nv 1 0 0\\nv 0 1 0\\nvn 0 0 2\\nf 1//1 2//1 3//1\\n")
    >>> load_mesh(p).normals.tolist()
    [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
    """
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ValueError(f"mesh file {path!r} does not exist")
    ext = os.path.splitext(path)[1].lower()
    if ext not in (".obj", ".ply", ".stl"):
        raise ValueError(f"mesh file {path!r}: unsupported extension {ext!r}; accepted: .obj, .ply, .stl")
    if crease_angle is not None and not (0 <= crease_angle <= np.pi):
        raise ValueError(f"crease angle must lie in [0, pi] radians; got {crease_angle!r}")
    try:
        pos, faces, nrm = _read_obj(path) if ext == ".obj" else _read_other(path)
    except ValueError as exc:
        if str(exc).startswith(f"mesh file {path!r}"):
            raise
        raise ValueError(f"cannot read mesh file {path!r}: {exc}") from None
    except Exception as exc:  # trimesh raises many types
        raise ValueError(f"cannot read mesh file {path!r}: {exc}") from None
    if faces is None or len(faces) == 0:
        raise ValueError(f"mesh file {path!r} holds no triangles")
    _check_scale(pos, f"mesh file {path!r}")
    bad = _degenerate_faces(pos, faces)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"mesh file {path!r}: triangle {i} is degenerate (zero area); "
                         f"{int(bad.sum())} such triangle(s)")
    name = os.path.basename(path)
    if nrm is not None and crease_angle is None:
        nrm = unit(nrm)
        return Mesh(name, pos, nrm, _orient(pos, nrm, faces))
    angle = np.radians(DEFAULT_CREASE_DEG) if crease_angle is None else crease_angle
    p, n, f = crease_normals(pos, faces, angle)
    return Mesh(name, p, n, f)


def get_mesh(name_or_path, tess: int | None = None, crease_angle: float | None = None) -> Mesh:
    """A mesh by name (``teapot``, ``sphere``, ``icosphere``, ``torus``,
    ``square``) at tessellation level ``tess`` (generator default if None),
    or an OBJ/PLY/STL file path (:func:`load_mesh`, with ``crease_angle`` in
    radians). Generated meshes have exact normals: a ``crease_angle`` for one
    is refused.

    Parameters
    ----------
    name_or_path : str or os.PathLike or Mesh
        A generator's name, a mesh file, or a Mesh (returned as is).
    tess : int, optional
        Tessellation level of a generated mesh.
    crease_angle : float, optional
        Crease angle (radians) for a file's normals.

    Returns
    -------
    Mesh
        The mesh.

    Raises
    ------
    ValueError
        For an unknown name, an unreadable file, or an option that does not apply.

    Examples
    --------
    >>> get_mesh("sphere", 6).name, len(get_mesh("icosphere", 1).faces)
    ('sphere', 80)
    """
    gens = {"teapot": teapot, "sphere": uv_sphere, "icosphere": icosphere, "torus": torus,
            "square": square}
    if isinstance(name_or_path, Mesh):
        return name_or_path
    if not isinstance(name_or_path, (str, os.PathLike)):
        raise ValueError(f"mesh of type {type(name_or_path).__name__} is not accepted; accepted: "
                         f"a Mesh, a name ({', '.join(MESH_NAMES)}) or a path to an .obj, .ply "
                         f"or .stl file")
    name = os.fspath(name_or_path)
    if not isinstance(name, str):
        raise ValueError(f"mesh path {name!r} is not accepted; accepted: a text path")
    if name in gens:
        if crease_angle is not None:
            raise ValueError(f"mesh {name!r} is generated with exact normals; a crease angle "
                             "applies to mesh files (.obj, .ply, .stl) only")
        return gens[name]() if tess is None else gens[name](tess)
    if os.path.splitext(name)[1].lower() in (".obj", ".ply", ".stl") or os.sep in name:
        return load_mesh(name, crease_angle)
    raise ValueError(f"unknown mesh {name!r}; accepted: {', '.join(MESH_NAMES)} or a path to an "
                     ".obj, .ply or .stl file")
