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
"""

from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field

import numpy as np

from .meshes import get_mesh
from .metrics import compare, error_map_rgb, write_png
from .render import HeightMap, Lighting, render

__all__ = ["EtaLevel", "eta_study", "split_gouraud_study", "SplitGouraudStudy", "BumpCase",
           "bump_comparison", "write_bump_figures"]


@dataclass
class EtaLevel:
    """One tessellation level of :func:`eta_study`: the metrics of
    ``phong:none`` against ``phong:exact``, and per visible triangle its eta
    and its worst relative diffuse error (eta bounds it: ``bound_holds``)."""

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
    shaded."""

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
    hold :class:`ImageMetrics` against the full-coefficient render."""

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

    >>> import os, tempfile
    >>> cases = bump_comparison(("square",), size=(16, 16))
    >>> with tempfile.TemporaryDirectory() as d:
    ...     [os.path.basename(p) for p in write_bump_figures(cases, d)]
    ['bump_square_full.png', 'bump_square_square.png', 'bump_square_object.png', 'bump_square_square_error.png', 'bump_square_object_error.png']
    """
    from chebnorm.approx.files import make_folder

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
