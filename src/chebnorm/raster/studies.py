"""Measurements the paper reproduction calls: each returns plain data
(dataclasses with ``to_dict``) and the arrays behind its figures; none
writes files unless asked (``write_*`` helpers write PNGs atomically).

* :func:`eta_study` -- seed 003: ``none`` against ``exact`` on a sphere over
  tessellation levels; per triangle, worst relative diffuse error
  ``1 - |N|`` against the triangle's ``eta``.
* :func:`split_gouraud_study` -- seed 002 (C11): Gouraud and split Gouraud
  against Phong on a coarse sphere, with the extra vertices shaded.
* :func:`bump_comparison` -- seed 001 (C12): square-patch against full
  tangent-space coefficients (and the object-space variant) on the flat
  square, a sphere and a torus, with error maps.
* :func:`render_sweep` -- a grid of meshes x shading modes x methods x sizes
  (:func:`render_sweep_cases`), each render measured against its reference;
  one CSV, the same bytes whatever number of workers runs it.
"""

from __future__ import annotations

import functools
import itertools
import os
import re
import threading
from dataclasses import asdict, dataclass, field

import numpy as np

from .engines import ENGINES
from .meshes import get_mesh
from .metrics import compare, error_map_rgb, write_png
from .render import HeightMap, Lighting, render

# an implementation module of chebnorm.raster: the API is what chebnorm.raster exports
__all__: list[str] = []


@dataclass
class EtaLevel:
    """One tessellation level of :func:`eta_study`: the metrics of
    ``phong:none`` against ``phong:exact``, and per visible triangle its eta
    and its worst relative diffuse error (eta bounds it: ``bound_holds``).

    Attributes
    ----------
    tess : int
        The tessellation level.
    triangles : int
        Triangles rendered.
    metrics : dict
        :class:`~chebnorm.raster.ImageMetrics` (as a dict) of ``phong:none`` against ``phong:exact``.
    eta : numpy.ndarray
        ``eta`` per visible triangle.
    worst_rel_diffuse : numpy.ndarray
        The worst relative diffuse error ``1 - |N|`` per visible triangle.
    """

    tess: int
    triangles: int
    metrics: dict
    #: per visible triangle: its eta and its worst relative diffuse error ``1 - |N|``
    eta: np.ndarray = field(repr=False)
    worst_rel_diffuse: np.ndarray = field(repr=False)

    @property
    def bound_holds(self) -> bool:
        """Every triangle's worst error is at most its eta (to rounding, 1e-12)."""
        return bool(np.all(self.worst_rel_diffuse <= self.eta + 1e-12))

    @property
    def tightness(self) -> float:
        """Largest ratio worst error / eta over the triangles (<= 1 when eta bounds it)."""
        ok = self.eta > 0
        return float(np.max(self.worst_rel_diffuse[ok] / self.eta[ok])) if ok.any() else 0.0

    def to_dict(self) -> dict:
        """The level as a plain dict (for JSON), arrays summarized by their maxima."""
        return {"tess": self.tess, "triangles": self.triangles, "metrics": self.metrics,
                "bound_holds": self.bound_holds, "tightness": self.tightness,
                "eta_max": float(self.eta.max()), "worst_rel_diffuse_max":
                float(self.worst_rel_diffuse.max())}


def eta_study(tess_levels=(4, 6, 8, 12, 16, 24), size=(128, 128), mesh="sphere",
              lighting: Lighting | None = None) -> list[EtaLevel]:
    """Seed 003: render ``phong:none`` and ``phong:exact`` at each level.

    The relative diffuse error of skipping normalization is ``1 - |N|``
    exactly (``L.N`` against ``L.N/|N|``), whatever ``L``; per triangle its
    worst value over the triangle's pixels is compared with the triangle's
    ``eta`` (docs/papers.md: eta sums the three edge bounds).

    Parameters
    ----------
    tess_levels : sequence of int, optional
        Tessellation levels.
    size : tuple of (int, int), optional
        The image size.
    mesh : str, optional
        A generated mesh.
    lighting : Lighting, optional
        Blinn-Phong parameters.

    Returns
    -------
    list of EtaLevel
        One entry per level, in order.

    Examples
    --------
    >>> level = eta_study((4,), size=(48, 48))[0]
    >>> level.tess, level.bound_holds, level.tightness <= 1.0
    (4, True, True)
    """
    from chebnorm.symbolic import eta as eta_fn

    out = []
    for k in tess_levels:
        m = get_mesh(mesh, k)
        ref = render(m, "phong", "exact", size=size, lighting=lighting)
        test = render(m, "phong", "none", size=size, lighting=lighting)
        metrics, _ = compare(test, ref, flip=False)
        tri = test.triangle[test.mask]
        err = 1.0 - test.normal_length[test.mask]
        worst = np.full(len(m.faces), -np.inf)
        np.maximum.at(worst, tri, err)
        seen = np.isfinite(worst)
        n = m.normals[m.faces[seen]]
        e = np.asarray(eta_fn(n[:, 0], n[:, 1], n[:, 2]), dtype=float)
        out.append(EtaLevel(int(k), int(len(m.faces)), metrics.to_dict(), e, worst[seen]))
    return out


@dataclass
class SplitGouraudStudy:
    """Seed 002 (claim C11): plain and split Gouraud against a Phong
    reference on one mesh; ``gouraud`` and ``split_gouraud`` hold each one's
    :class:`ImageMetrics` as a dict, ``split_stats`` the extra vertices
    shaded.

    Attributes
    ----------
    mesh : str
        The mesh's name.
    tess : int
        Its tessellation.
    shininess : float
        The specular exponent.
    gouraud, split_gouraud : dict
        Each mode's metrics against Phong ``exact``.
    split_stats : dict
        The vertices added by splitting (counts and fraction).
    images : dict
        The renders and their error maps.
    """

    mesh: str
    tess: int
    shininess: float
    gouraud: dict
    split_gouraud: dict
    split_stats: dict
    images: dict = field(repr=False, default_factory=dict)

    @property
    def closer_to_phong(self) -> bool:
        """Split Gouraud has a smaller mean and no larger maximum error."""
        g, s = self.gouraud, self.split_gouraud
        return s["mean_abs_8bit"] < g["mean_abs_8bit"] and s["max_abs_8bit"] <= g["max_abs_8bit"]

    def to_dict(self) -> dict:
        """The study as a plain dict (for JSON), without the images."""
        d = {k: v for k, v in asdict(self).items() if k != "images"}
        d["closer_to_phong"] = self.closer_to_phong
        return d


def split_gouraud_study(tess: int = 6, shininess: float = 64.0, size=(256, 256), q=1.0 / 255.0,
                        mesh="sphere", half_vector: str = "triangle") -> SplitGouraudStudy:
    """Seed 002 (C11): plain and split Gouraud against Phong ``exact`` on a
    coarse sphere whose highlight falls inside triangles.

    Parameters
    ----------
    tess : int, optional
        Tessellation of the mesh.
    shininess : float, optional
        The specular exponent.
    size : tuple of (int, int), optional
        The image size.
    q : float, optional
        The split threshold on ``I0 k_s (max H.N)^n``.
    mesh : str, optional
        A generated mesh.
    half_vector : str, optional
        ``"pixel"`` or ``"triangle"``.

    Returns
    -------
    SplitGouraudStudy
        The metrics of both modes and the split statistics.

    Examples
    --------
    >>> s = split_gouraud_study(tess=6, size=(64, 64))
    >>> s.closer_to_phong, s.split_stats["extra_vertices"] > 0
    (True, True)
    """
    light = Lighting(shininess=shininess, half_vector=half_vector)
    m = get_mesh(mesh, tess)
    ref = render(m, "phong", "exact", size=size, lighting=light)
    g = render(m, "gouraud", size=size, lighting=light)
    s = render(m, "split-gouraud", size=size, lighting=light, q=q)
    mg, dg = compare(g, ref)
    ms, ds = compare(s, ref)
    return SplitGouraudStudy(m.name, int(tess), float(shininess), mg.to_dict(), ms.to_dict(),
                             dict(s.stats), {"phong": ref.image8, "gouraud": g.image8,
                                             "split_gouraud": s.image8, "gouraud_error": dg,
                                             "split_gouraud_error": ds})


@dataclass
class BumpCase:
    """Square-patch (and object-space) against full coefficients on one mesh
    (:func:`bump_comparison`): ``k`` is the patch size used, the two dicts
    hold :class:`ImageMetrics` against the full-coefficient render.

    Attributes
    ----------
    mesh : str
        The mesh's name.
    k : float
        The square-patch length used.
    square_vs_full, object_vs_full : dict
        :class:`~chebnorm.raster.ImageMetrics` (as dicts) of the square-patch and the
        object-space renders against the full-coefficient render.
    images : dict
        The renders (``full``, ``square``, ``object``, uint8) and the signed 8-bit
        differences (``square_error``, ``object_error``).
    """

    mesh: str
    k: float
    square_vs_full: dict
    object_vs_full: dict
    images: dict = field(repr=False, default_factory=dict)

    def to_dict(self) -> dict:
        """The case as a plain dict (for JSON), without the images."""
        return {k: v for k, v in asdict(self).items() if k != "images"}


def bump_comparison(meshes=("square", "sphere", "torus"), size=(256, 256), tess=None,
                    height_map: HeightMap | None = None, lighting: Lighting | None = None
                    ) -> list[BumpCase]:
    """Seed 001 (C12): the error of the square-patch simplification
    ``[-F_u/k, -F_v/k, 1]`` against the full tangent-space coefficients, on
    surfaces that are square patches (the flat square: they agree) and that
    are not (a sphere, worst near its poles; a torus).  ``images`` holds the
    three renders and the signed 8-bit differences (the error maps).

    On the flat square (``k = 2``) the simplification is exact (claim C12):

    Parameters
    ----------
    meshes : sequence of str, optional
        Generated meshes with a parametrization.
    size : tuple of (int, int), optional
        The image size.
    tess : int, optional
        Tessellation level (default: each generator's).
    height_map : HeightMap, optional
        The height map (default :class:`~chebnorm.raster.render.HeightMap` ``()``).
    lighting : Lighting, optional
        Blinn-Phong parameters.

    Returns
    -------
    list of BumpCase
        One case per mesh, in order.

    Examples
    --------
    >>> case = bump_comparison(("square",), size=(32, 32))[0]
    >>> case.k, case.square_vs_full["max_abs_8bit"]
    (2.0, 0)
    """
    out = []
    for name in meshes:
        m = get_mesh(name, tess)
        kw = dict(size=size, height_map=height_map, lighting=lighting)
        full = render(m, "bump", bump="full", **kw)
        sq = render(m, "bump", bump="square", **kw)
        obj = render(m, "bump", bump="object", **kw)
        msq, dsq = compare(sq, full)
        mob, dob = compare(obj, full)
        out.append(BumpCase(m.name, float(sq.stats["k"]), msq.to_dict(), mob.to_dict(),
                            {"full": full.image8, "square": sq.image8, "object": obj.image8,
                             "square_error": dsq, "object_error": dob}))
    return out


def write_bump_figures(cases, directory) -> list[str]:
    """For each case write ``bump_<mesh>_{full,square,object}.png`` and the
    error maps ``bump_<mesh>_square_error.png``, ``..._object_error.png``
    (heat maps on a common scale); returns the paths.

    Parameters
    ----------
    cases : sequence of BumpCase
        From :func:`bump_comparison`.
    directory : str or os.PathLike
        The folder (created if missing).

    Returns
    -------
    list of str
        The paths written, in order.

    Examples
    --------
    >>> import os, tempfile
    >>> cases = bump_comparison(("square",), size=(16, 16))
    >>> with tempfile.TemporaryDirectory() as d:
    ...     [os.path.basename(p) for p in write_bump_figures(cases, d)]
    ['bump_square_full.png', 'bump_square_square.png', 'bump_square_object.png', 'bump_square_square_error.png', 'bump_square_object_error.png']
    """
    from chebnorm.core.files import make_folder

    directory = os.fspath(make_folder(directory))
    scale = max([1.0] + [float(np.abs(c.images[key]).max()) for c in cases
                         for key in ("square_error", "object_error")])
    paths = []
    for c in cases:
        for key in ("full", "square", "object"):
            p = os.path.join(directory, f"bump_{c.mesh}_{key}.png")
            write_png(p, c.images[key])
            paths.append(p)
        for key in ("square_error", "object_error"):
            p = os.path.join(directory, f"bump_{c.mesh}_{key}.png")
            write_png(p, error_map_rgb(c.images[key], scale))
            paths.append(p)
    return paths


# ------------------------------------------------------------ render sweeps
#: columns of :meth:`RenderSweep.csv`, in order
RENDER_SWEEP_COLUMNS = ("mesh", "tess", "width", "height", "shininess", "shading", "method",
                        "bump", "reference", "triangles", "fragments", "pixels", "max_abs_8bit",
                        "pixels_off_1", "mean_abs_8bit", "psnr", "ssim", "flip", "name")
#: one process-wide lock: a worker thread renders one case at a time (the fits behind
#: the method tables set python-flint's global precision, which threads would share)
_CASE_LOCK = threading.Lock()
#: largest image side a sweep accepts (as :func:`render`)
MAX_SIZE = 16384


@dataclass(frozen=True)
class RenderCase:
    """One point of a render sweep: the mesh (a name, or a file path as given),
    its tessellation (None: the generator's default; always None for a file),
    the image size, the shininess, the shading mode, the normalization method
    (None for ``gouraud`` and ``split-gouraud``, which have none), the bump
    variant (None unless ``bump``) and the reference ``(mode, method, variant)``.

    Attributes
    ----------
    mesh : str
        A generator's name or a file path.
    tess : int or None
        The tessellation (None: the default; always None for a file).
    width, height : int
        The image size.
    shininess : float
        The specular exponent.
    shading : str
        The shading mode.
    method : str or None
        The normalization method (None for a mode without one).
    bump : str or None
        The bump variant (None unless ``shading == "bump"``).
    reference : tuple of (str, str or None, str or None)
        ``(mode, method, variant)`` of the reference render.
    """

    mesh: str
    tess: int | None
    width: int
    height: int
    shininess: float
    shading: str
    method: str | None
    bump: str | None
    reference: tuple

    @property
    def sort_key(self) -> tuple:
        """The order of the sweep's rows."""
        return (self.mesh, -1 if self.tess is None else self.tess, self.width, self.height,
                self.shininess, self.shading, self.method or "", self.bump or "")

    @property
    def reference_text(self) -> str:
        """``MODE:METHOD`` (``bump:VARIANT`` for a bump reference), as ``chebnorm render``."""
        mode, method, variant = self.reference
        return f"{mode}:{variant if mode == 'bump' else method}"

    @property
    def name(self) -> str:
        """A file-name stem naming the case (letters, digits, ``_``, ``-``, ``.``)."""
        stem = re.sub(r"[^A-Za-z0-9]+", "-", os.path.splitext(os.path.basename(self.mesh))[0])
        parts = [stem.strip("-") or "mesh", "" if self.tess is None else f"t{self.tess}",
                 f"{self.width}x{self.height}", f"n{self.shininess:g}", self.shading,
                 self.method or "", self.bump or ""]
        return "_".join(p for p in parts if p)


@dataclass(frozen=True)
class RenderSweepRow:
    """A rendered case: its triangle and fragment counts, its
    :class:`~chebnorm.raster.ImageMetrics` against the reference (as a dict),
    and, when asked for, the image and its error map as PNG bytes.

    Attributes
    ----------
    case : RenderCase
        The case rendered.
    triangles, fragments : int
        The render's counts.
    metrics : dict
        Its metrics against the reference.
    image_png, error_png : bytes, optional
        The image and its error map as PNG bytes (when asked for).
    """

    case: RenderCase
    triangles: int
    fragments: int
    metrics: dict
    image_png: bytes | None = field(default=None, repr=False)
    error_png: bytes | None = field(default=None, repr=False)

    def cells(self) -> list[str]:
        """The CSV cells of the row, in the order of :data:`RENDER_SWEEP_COLUMNS`;
        floats in fixed formats (a PSNR of identical images is ``inf``)."""
        c, m = self.case, self.metrics
        return [c.mesh, "" if c.tess is None else str(c.tess), str(c.width), str(c.height),
                f"{c.shininess:.10g}", c.shading, c.method or "", c.bump or "",
                c.reference_text, str(self.triangles), str(self.fragments), str(m["pixels"]),
                str(m["max_abs_8bit"]), str(m["pixels_off_1"]), f"{m['mean_abs_8bit']:.6f}",
                "inf" if m["psnr"] is None else f"{m['psnr']:.4f}", f"{m['ssim']:.6f}",
                f"{m['flip']:.6f}", c.name]


@dataclass(frozen=True)
class RenderSweep:
    """The rows of :func:`render_sweep`, in the order of the cases' ``sort_key``.

    Attributes
    ----------
    rows : tuple of RenderSweepRow
        One row per case.
    """

    rows: tuple

    def csv(self) -> str:
        """The rows as CSV text: a header line, then one line per row (text
        fields through :func:`chebnorm.core.textsafe.csv_cell`)."""
        from chebnorm.core.textsafe import csv_cell

        lines = [",".join(RENDER_SWEEP_COLUMNS)]
        lines += [",".join(csv_cell(v) for v in r.cells()) for r in self.rows]
        return "\n".join(lines) + "\n"


def _check_list(values, what, accepted=None) -> list:
    values = list(dict.fromkeys(values))
    if not values:
        raise ValueError(f"{what}: empty list; accepted: one or more"
                         + (f" of {', '.join(accepted)}" if accepted else " values"))
    for v in values:
        if accepted is not None and v not in accepted:
            raise ValueError(f"unknown {what} {v!r}; accepted: {', '.join(accepted)}")
    return values


def _check_sizes(sizes) -> list:
    out = []
    for s in sizes:
        try:
            w, h = (int(v) for v in s)
            ok = [w, h] == list(s) and 1 <= w <= MAX_SIZE and 1 <= h <= MAX_SIZE
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise ValueError(f"size {s!r}: expected two integers (width, height) in "
                             f"[1, {MAX_SIZE}]")
        out.append((w, h))
    return _check_list(out, "size")




def _sweep_meshes(meshes, tess_levels, bump_wanted) -> dict:
    """``{(mesh, tess): Mesh or None}``, every mesh built once here (which checks
    names, tessellation levels and files); None for a generated mesh, which the
    worker builds again rather than receive."""
    from .meshes import MESH_NAMES

    out = {}
    for name in _check_list(meshes, "mesh"):
        generated = name in MESH_NAMES
        for t in (tess_levels if generated else [None]):
            m = get_mesh(name, t)
            if bump_wanted and not m.has_parametrization:
                raise ValueError(f"bump mapping needs a parametrized mesh (uv, P_u, P_v); mesh "
                                 f"{name!r} has none; accepted for bump: teapot, sphere, torus, "
                                 "square")
            out[(name, t)] = None if generated else m
    return out


def render_sweep_cases(meshes=("teapot",), shadings=("phong",), methods=None,
                       sizes=((256, 256),), tess=(None,), shininess=(32.0,), bumps=("full",),
                       reference=None) -> list[RenderCase]:
    """The sorted, checked cases of a render sweep: every mesh x tessellation x
    size x shininess x shading x method (x bump variant for ``bump``); a shading
    without a normalization method (``gouraud``, ``split-gouraud``) gets one case,
    not one per method. ``methods``: default every registered method.
    ``reference``: ``(mode, method, bump variant)`` for every case; default
    ``phong:exact`` (``bump:full`` for bump cases). A bad name or size raises
    ``ValueError`` naming it and the accepted set.

    Parameters
    ----------
    meshes : sequence of str, optional
        Generator names or mesh files.
    shadings : sequence of str, optional
        Shading modes.
    methods : sequence of str, optional
        Normalization methods.
    sizes : sequence of (int, int), optional
        Image sizes.
    tess : sequence of int or None, optional
        Tessellation levels.
    shininess : sequence of float, optional
        Specular exponents.
    bumps : sequence of str, optional
        Bump variants.
    reference : tuple, optional
        ``(mode, method, variant)`` of the reference.

    Returns
    -------
    list of RenderCase
        The cases, sorted.

    Raises
    ------
    ValueError
        See above.

    Examples
    --------
    >>> [(c.shading, c.method) for c in render_sweep_cases(
    ...     ("sphere",), ("gouraud", "phong"), ("none", "exact"), sizes=[(32, 32)])]
    [('gouraud', None), ('phong', 'exact'), ('phong', 'none')]
    """
    from .render import BUMP_VARIANTS, SHADING_MODES, available_methods

    shadings = _check_list(shadings, "shading mode", SHADING_MODES)
    methods = _check_list(available_methods() if methods is None else methods, "method",
                          available_methods())
    bumps = _check_list(bumps, "bump variant", BUMP_VARIANTS)
    sizes = _check_sizes(sizes)
    tess = _check_list(tess, "tessellation level")
    for n in _check_list(shininess, "shininess"):
        Lighting(shininess=n).validate()
    if reference is not None:
        mode, method, variant = reference
        _check_list([mode], "reference mode", SHADING_MODES)
        _check_list([method], "reference method", available_methods())
        _check_list([variant], "reference bump variant", BUMP_VARIANTS)
    meshes = _sweep_meshes(meshes, tess, "bump" in shadings or
                           (reference is not None and reference[0] == "bump"))
    cases = set()
    for (mesh, t), (w, h), n, shading in itertools.product(meshes, sizes, shininess, shadings):
        ref = reference or (("bump", "exact", "full") if shading == "bump"
                            else ("phong", "exact", "full"))
        for method in (methods if shading in ("phong", "adaptive", "bump") else [None]):
            for variant in (bumps if shading == "bump" else [None]):
                cases.add(RenderCase(mesh, t, w, h, float(n), shading, method, variant, ref))
    return sorted(cases, key=lambda c: c.sort_key)


@functools.lru_cache(maxsize=4)
def _generated_mesh(name, tess):
    return get_mesh(name, tess)


def _render_case(item) -> RenderSweepRow:
    """Render one case and its reference and compare them (run by ``map_ordered``
    on a worker)."""
    case, mesh, opts, images = item
    with _CASE_LOCK:
        mesh = mesh if mesh is not None else _generated_mesh(case.mesh, case.tess)
        light = Lighting(shininess=case.shininess, half_vector=opts["half_vector"])
        kw = dict(size=(case.width, case.height), lighting=light, engine=opts["engine"],
                  eta_threshold=opts["eta_threshold"], q=opts["q"])
        result = render(mesh, case.shading, case.method, bump=case.bump or "full", **kw)
        mode, method, variant = case.reference
        ref = render(mesh, mode, method, bump=variant, dtype=np.float64, **kw)
        metrics, diff = compare(result, ref)
    png = err = None
    if images:
        from .metrics import image_bytes

        png, err = image_bytes(result.image8), image_bytes(error_map_rgb(diff))
    return RenderSweepRow(case, result.triangles, result.fragments, metrics.to_dict(), png, err)


def render_sweep(cases, *, half_vector: str = "pixel", eta_threshold: float = 0.005,
                 q: float = 1.0 / 255.0, engine: str = "auto", images: bool = False,
                 workers: int | None = None, scheduler=None, progress: bool = False,
                 on_row=None) -> RenderSweep:
    """Render every case of :func:`render_sweep_cases` and its reference, and
    measure the error (:func:`compare`: max and mean 8-bit error, pixels off,
    PSNR, SSIM, FLIP); ``images``: keep each image and error map as PNG bytes.

    Each case is one parallel item: on ``workers`` local processes (default: the
    core count; 1: here) or a Dask ``scheduler``
    (:func:`chebnorm.core.parallel.map_ordered`); the rows, and so the CSV, are
    the same whatever runs them. ``on_row(index, row)`` sees each row as it
    finishes (``index`` into ``cases``), so a caller can keep finished rows when
    interrupted. ``half_vector``, ``eta_threshold``, ``q``, ``engine``: as
    :func:`render`, for every case.

    Parameters
    ----------
    cases : sequence of RenderCase
        The cases (:func:`render_sweep_cases`).
    half_vector : str, optional
        ``"pixel"`` or ``"triangle"``.
    eta_threshold, q : float, optional
        ``adaptive``'s and ``split-gouraud``'s thresholds.
    engine : str, optional
        ``"numpy"``, ``"numba"`` or ``"auto"``.
    images : bool, optional
        Keep each image and error map as PNG bytes.
    workers : int, optional
        Local processes.
    scheduler : str or distributed.Client, optional
        A Dask scheduler instead.
    progress : bool, optional
        Show a progress bar.
    on_row : callable, optional
        ``on_row(index, row)`` for each finished row.

    Returns
    -------
    RenderSweep
        The rows, in the order of the cases.

    Examples
    --------
    >>> cases = render_sweep_cases(("sphere",), ("phong",), ("exact", "none"),
    ...                            sizes=[(48, 48)], tess=[8])
    >>> sweep = render_sweep(cases, workers=1)
    >>> [(r.case.method, r.metrics["max_abs_8bit"] > 0) for r in sweep.rows]
    [('exact', False), ('none', True)]
    >>> sweep.csv().splitlines()[0].startswith("mesh,tess,width,height,shininess")
    True
    """
    from chebnorm.core.parallel import map_ordered

    from .meshes import MESH_NAMES
    from .render import check_options

    cases = list(cases)
    Lighting(half_vector=half_vector).validate()
    check_options("phong", "full", eta_threshold, q)
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r}; accepted: {', '.join(ENGINES)}")
    opts = dict(half_vector=half_vector, eta_threshold=float(eta_threshold), q=float(q),
                engine=engine)
    # a mesh file is read once, here; a generated mesh is built by the worker
    files = {c.mesh: get_mesh(c.mesh) for c in cases if c.mesh not in MESH_NAMES}
    items = [(c, files.get(c.mesh), opts, bool(images)) for c in cases]
    rows = map_ordered(_render_case, items, workers=workers, scheduler=scheduler,
                       progress=progress, desc="render sweep", on_result=on_row)
    return RenderSweep(tuple(rows))
