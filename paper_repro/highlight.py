"""Seed 002: highlight detection for Gouraud shading (split Gouraud).

Written under ``figures/highlight/``:

=========================  =================================================
function                   reproduces
=========================  =================================================
``fig_triangulation``      Fig. 4: the 2/3/4 sub-triangle splits at the
                           edge-highlight points ``t*``
``fig_render_comparison``  Fig. 5: Phong, Gouraud and split Gouraud renders
                           with error maps against Phong (claim C11)
``fig_split_sweep``        beyond the paper: C11 over shininess and
                           tessellation, with the extra vertices it costs
=========================  =================================================
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from chebnorm.raster import split_gouraud_study
from chebnorm.symbolic import edge_highlight

from .paths import paper_dir
from .style import error_map, figure, save_figure, write_csv, write_json

__all__ = ["JOB", "run", "fig_triangulation", "fig_render_comparison", "fig_split_sweep",
           "measure_c11", "measure_split_sweep", "triangulation_cases"]

JOB = "seed002_highlight"
CMD = f"chebnorm repro {JOB}"
SEED = "002"
SIZE = (256, 256)
TESS = 6
SHININESS = 64.0
SWEEP_SHININESS = (16.0, 32.0, 64.0, 128.0)
SWEEP_TESS = (4, 6, 8)
SWEEP_SIZE = (128, 128)

#: the illustration of Fig. 4: a triangle, its unit vertex normals, and for
#: each case a half vector, exponent and threshold giving 1, 2 or 3 split edges
_POS = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.85]])
_NRM = np.array([[-0.5, -0.3, 1.0], [0.5, -0.3, 1.0], [0.0, 0.55, 1.0]])
_CASES = ((np.array([0.0, -0.3, 1.0]), 64, 0.3),
          (np.array([0.25, -0.15, 1.0]), 64, 0.3),
          (np.array([0.0, 0.0, 1.0]), 8, 0.3))
_EDGES = ((0, 1), (1, 2), (2, 0))
#: sub-triangles by split edges (slots 0-2: A, B, C; 3-5: points on AB, BC, CA)
_SPLITS = {(True, False, False): [(0, 3, 2), (3, 1, 2)],
           (True, True, False): [(3, 1, 4), (0, 3, 4), (0, 4, 2)],
           (True, True, True): [(0, 3, 5), (3, 1, 4), (5, 4, 2), (3, 4, 5)]}


def _dir(out) -> Path:
    return paper_dir(out, SEED)


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def triangulation_cases() -> list[dict]:
    """For each illustrative case: per edge ``t*``, the peak specular
    ``(max H.N)^n``, whether it passes ``q``, and the sub-triangles (2D points)."""
    nrm = _unit(_NRM)
    out = []
    for H, n, q in _CASES:
        h = _unit(H)
        ts, spec, split = [], [], []
        for i, j in _EDGES:
            peak = edge_highlight(h @ nrm[i], h @ nrm[j], nrm[i] @ nrm[j])
            t, v = float(peak.t), float(peak.value)
            ts.append(t)
            spec.append(max(v, 0.0) ** n)
            split.append(0.0 < t < 1.0 and max(v, 0.0) ** n > q)
        pts = list(_POS) + [_POS[i] + t * (_POS[j] - _POS[i]) for t, (i, j) in zip(ts, _EDGES)]
        subs = [[pts[k] for k in tri] for tri in _SPLITS[tuple(split)]]
        out.append({"H": h, "n": n, "q": q, "t": ts, "spec": spec, "split": split,
                    "sub_triangles": subs})
    return out


def _label(ax, text, anchor, direction, offset_pt, **kw):
    """Annotate ``text`` ``offset_pt`` points from ``anchor`` along the unit ``direction``,
    aligned so that the text extends away from the anchor."""
    dx, dy = float(direction[0]), float(direction[1])
    ha = "left" if dx > 0.35 else "right" if dx < -0.35 else "center"
    va = "bottom" if dy > 0.35 else "top" if dy < -0.35 else "center"
    return ax.annotate(text, tuple(anchor), textcoords="offset points",
                       xytext=(offset_pt * dx, offset_pt * dy), ha=ha, va=va, **kw)


def fig_triangulation(out) -> list[Path]:
    """Seed 002, Fig. 4: one, two and three highlighted edges give 2, 3 and 4 sub-triangles."""
    folder = _dir(out)
    cases = triangulation_cases()
    caption = ("Seed 002, Fig. 4 reproduced: the triangulation cases. Each edge's highlight "
               "maximum t* = (b - ac)/((a + b)(1 - c)) (a = H.N_A, b = H.N_B, c = N_A.N_B) is a new "
               "vertex when the specular term (max H.N)^n there exceeds the threshold q; one, two or "
               "three such edges split the triangle into 2, 3 or 4 sub-triangles, Gouraud-shaded "
               "from normalized normals at their vertices. Same vertex normals in the three cases; "
               "half vector and exponent chosen per case (listed in the CSV).")
    rows = []
    for k, c in enumerate(cases):
        for e, (t, s, sp) in enumerate(zip(c["t"], c["spec"], c["split"])):
            rows.append((k + 1, "ABC"[_EDGES[e][0]] + "ABC"[_EDGES[e][1]], int(c["n"]), c["q"],
                         *map(float, c["H"]), t, s, bool(sp)))
    paths = [write_csv(folder, "fig4_triangulation",
                       ("case", "edge", "n", "q", "Hx", "Hy", "Hz", "t_star", "peak_specular",
                        "split"), rows, caption, CMD,
                       ["vertex normals (unnormalized): " + str(_NRM.tolist()),
                        "triangle (2D): " + str(_POS.tolist())])]
    centroid = _POS.mean(axis=0)
    with figure(1, 3, figsize=(10.5, 3.9)) as (fig, axes):
        for ax, c, k in zip(axes, cases, range(3)):
            for tri in c["sub_triangles"]:
                p = np.array(tri + [tri[0]])
                ax.fill(p[:, 0], p[:, 1], alpha=0.25)
                ax.plot(p[:, 0], p[:, 1], color="0.2", lw=1)
            for e, (i, j) in enumerate(_EDGES):
                if c["split"][e]:
                    q = _POS[i] + c["t"][e] * (_POS[j] - _POS[i])
                    ax.plot(*q, "o", color="C1", ms=5)
                    # outside the triangle, along the edge's outward normal
                    tang = _unit(_POS[j] - _POS[i])
                    nrm = np.array([tang[1], -tang[0]])
                    if nrm @ (q - centroid) < 0:
                        nrm = -nrm
                    _label(ax, f"t*={c['t'][e]:.2f}", q, nrm, 9, fontsize=7, color="#D55E00")
            for name, p in zip("ABC", _POS):
                _label(ax, name, p, _unit(p - centroid), 6, fontsize=9)
            nsplit = sum(c["split"])
            ax.set_title(f"{nsplit} edge{'s' if nsplit > 1 else ''} -> "
                         f"{len(c['sub_triangles'])} sub-triangles (n = {c['n']})")
            ax.set_aspect("equal")
            ax.set_xlim(-0.3, 1.3)
            ax.set_ylim(-0.22, 1.05)
            ax.set_xlabel("x (triangle units)")
            ax.set_ylabel("y (triangle units)")
        fig.suptitle("Seed 002 Fig. 4: each highlighted edge (orange t*, where the specular peak "
                     "exceeds q) adds a vertex; 1, 2, 3 edges give 2, 3, 4 sub-triangles")
        paths += save_figure(fig, folder, "fig4_triangulation", caption)
    return paths


@lru_cache(maxsize=None)
def _study(tess=TESS, shininess=SHININESS, size=SIZE):
    return split_gouraud_study(tess=tess, shininess=shininess, size=size)


def measure_c11() -> dict:
    """C11 on the paper-like case: a sphere of tessellation 6, n = 64, 256x256."""
    return _study().to_dict()


@lru_cache(maxsize=None)
def measure_split_sweep() -> list[dict]:
    out = []
    for tess in SWEEP_TESS:
        for n in SWEEP_SHININESS:
            d = _study(tess, n, SWEEP_SIZE).to_dict()
            out.append(d)
    return out


_METRICS = ("max_abs_8bit", "mean_abs_8bit", "pixels_off_1", "psnr", "ssim", "flip")


def fig_render_comparison(out) -> list[Path]:
    """Seed 002, Fig. 5: Phong, Gouraud and split Gouraud with error maps (C11)."""
    folder = _dir(out)
    s = _study()
    d = s.to_dict()
    st = d["split_stats"]
    caption = ("Seed 002, Fig. 5 reproduced: a coarse sphere (tessellation "
               f"{TESS}, {SIZE[0]}x{SIZE[1]} px, specular exponent {SHININESS:g}) shaded by Phong "
               "(exact normalization, the reference), plain Gouraud and split Gouraud (threshold "
               "q = 1/255); below, |difference to Phong| in 8-bit levels on a common scale. "
               f"Gouraud: max {d['gouraud']['max_abs_8bit']}, mean {d['gouraud']['mean_abs_8bit']:.3f} "
               f"levels; split Gouraud: max {d['split_gouraud']['max_abs_8bit']}, mean "
               f"{d['split_gouraud']['mean_abs_8bit']:.3f}, for {st['extra_vertices']} extra shaded "
               f"vertices ({100 * st['extra_vertices_fraction']:.1f} %).")
    rows = [(mode, *[d[key][k] if d[key][k] is not None else float("nan") for k in _METRICS])
            for mode, key in (("gouraud", "gouraud"), ("split-gouraud", "split_gouraud"))]
    paths = [write_csv(folder, "fig5_render_comparison", ("mode", *_METRICS), rows, caption, CMD,
                       ["split statistics: " + ", ".join(f"{k}={st[k]:.6g}" if isinstance(st[k], float)
                                                         else f"{k}={st[k]}" for k in sorted(st))])]
    img = s.images
    scale = max(1.0, float(np.abs(img["gouraud_error"]).max()), float(np.abs(img["split_gouraud_error"]).max()))
    with figure(2, 3, figsize=(10.0, 6.4)) as (fig, axes):
        panels = ((img["phong"], "Phong (reference)"), (img["gouraud"], "Gouraud"),
                  (img["split_gouraud"], "split Gouraud"))
        for ax, (im, title) in zip(axes[0], panels):
            ax.set_axis_off()
            ax.imshow(im, interpolation="nearest", cmap="gray", vmin=0, vmax=255)
            ax.set_title(title)
        axes[1, 0].set_axis_off()
        error_map(fig, axes[1, 1], img["gouraud_error"], scale,
                  f"|Gouraud - Phong|, max {rows[0][1]} levels")
        error_map(fig, axes[1, 2], img["split_gouraud_error"], scale,
                  f"|split Gouraud - Phong|, max {rows[1][1]} levels")
        axes[1, 0].text(0.0, 0.5, f"error maps: one scale,\n0 to {scale:g} 8-bit levels\n\n"
                        + "\n".join(f"{m}: max {r[1]}, mean {r[2]:.2f}" for m, r in
                                     zip(("Gouraud", "split"), rows)),
                        transform=axes[1, 0].transAxes, va="center", fontsize=8)
        fig.suptitle("Seed 002 Fig. 5: split Gouraud brings the highlight closer to Phong "
                     "(smaller, dimmer error maps)")
        paths += save_figure(fig, folder, "fig5_render_comparison", caption)
    return paths


def fig_split_sweep(out) -> list[Path]:
    """C11 over shininess and tessellation: mean error of both against Phong, and the cost."""
    folder = _dir(out)
    sweep = measure_split_sweep()
    caption = ("Beyond seed 002 (claim C11 made measurable): mean and largest |difference to Phong| "
               "(8-bit levels) of plain and split Gouraud on a sphere over the specular exponent n and "
               f"the tessellation ({SWEEP_SIZE[0]}x{SWEEP_SIZE[1]} px), and the cost: extra shaded "
               "vertices as a fraction of 3 per triangle.")
    rows = [(d["tess"], d["shininess"], d["gouraud"]["mean_abs_8bit"], d["split_gouraud"]["mean_abs_8bit"],
             d["gouraud"]["max_abs_8bit"], d["split_gouraud"]["max_abs_8bit"],
             d["split_stats"]["extra_vertices"], d["split_stats"]["extra_vertices_fraction"],
             bool(d["closer_to_phong"])) for d in sweep]
    paths = [write_csv(folder, "split_sweep", ("tess", "shininess", "gouraud_mean", "split_mean",
                                               "gouraud_max", "split_max", "extra_vertices",
                                               "extra_vertices_fraction", "split_closer"),
                       rows, caption, CMD)]
    with figure(1, 2, figsize=(8.6, 3.6)) as (fig, (a1, a2)):
        r = np.array([row[:8] for row in rows], dtype=float)
        for i, tess in enumerate(SWEEP_TESS):
            sel = r[:, 0] == tess
            a1.plot(r[sel, 1], r[sel, 2], "-o", ms=3, color=f"C{i}", label=f"Gouraud, tess {tess}")
            a1.plot(r[sel, 1], r[sel, 3], "--s", ms=3, color=f"C{i}", label=f"split, tess {tess}")
            a2.plot(r[sel, 1], 100 * r[sel, 7], "-o", ms=3, color=f"C{i}", label=f"tess {tess}")
        for ax in (a1, a2):
            ax.set_xscale("log", base=2)
            ax.set_xlabel("specular exponent n")
            ax.legend(fontsize=7)
        a1.set_ylabel("mean |difference to Phong| (8-bit levels)")
        a2.set_ylabel("extra shaded vertices (% of 3 per triangle)")
        fig.suptitle("Beyond seed 002: split Gouraud against plain Gouraud, and its cost")
        paths += save_figure(fig, folder, "split_sweep", caption)
    paths.append(write_json(folder / "c11_summary.json", {"main": measure_c11(), "sweep": sweep,
                                                          "command": CMD}))
    return paths


FIGURES = (fig_triangulation, fig_render_comparison, fig_split_sweep)


def run(out) -> list[Path]:
    """The seed 002 job."""
    paths = []
    for f in FIGURES:
        paths += f(out)
    return paths
