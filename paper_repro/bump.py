"""Seed 001: bump mapping that reuses the Phong hardware.

Written under ``figures/bump/``:

======================  ====================================================
function                what
======================  ====================================================
``fig_bump_renders``    full tangent-space coefficients against the
                        square-patch ``[-F_u/k, -F_v/k, 1]`` and the
                        object-space variant, on the flat square, a sphere
                        and a torus, with error maps (claim C12)
``fig_pipeline_costs``  the paper's pipeline block diagrams as cost tables
                        from :mod:`chebnorm.hw` (Phong vs bump, claim C13)
======================  ====================================================
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from chebnorm.hw.datapaths import bump_pipeline, phong_pipeline
from chebnorm.raster import bump_comparison
from chebnorm.symbolic import bump_coefficients_square_expr

from .paths import paper_dir
from .style import error_map, figure, save_figure, write_csv, write_json

__all__ = ["JOB", "run", "fig_bump_renders", "fig_pipeline_costs", "measure_c12", "measure_c13"]

JOB = "seed001_bump"
CMD = f"chebnorm repro {JOB}"
SEED = "001"
SIZE = (256, 256)
MESHES = ("square", "sphere", "torus")
WIDTH = 18   # component width (bits) of the pipeline cost model (16 fractional bits + 2, as benchmarks/run.py)
_METRICS = ("max_abs_8bit", "mean_abs_8bit", "pixels_off_1", "psnr", "ssim", "flip")


def _dir(out) -> Path:
    return paper_dir(out, SEED)


@lru_cache(maxsize=None)
def _cases():
    return tuple(bump_comparison(MESHES, size=SIZE))


def measure_c12() -> dict:
    """Square-patch (and object-space) against full coefficients per mesh."""
    return {"coefficients_square": "[" + ", ".join(str(e) for e in bump_coefficients_square_expr()) + "]",
            "size": list(SIZE), "cases": {c.mesh: c.to_dict() for c in _cases()}}


def _flatten(block, path=""):
    name = f"{path} > {block.name}" if path else block.name
    c = block.cost
    rows = [(name, len(c.multipliers), len(c.adders), len(c.sqrts), len(c.dividers), c.mux_bits,
             c.rom_bits, c.latency, c.area)]
    for ch in block.children:
        rows += _flatten(ch, name)
    return rows


@lru_cache(maxsize=None)
def measure_c13() -> dict:
    """Phong and bump pipelines of :mod:`chebnorm.hw` (``WIDTH``-bit components)."""
    p, b = phong_pipeline(WIDTH), bump_pipeline(WIDTH)
    pc, bc = p.cost, b.cost
    return {"width_bits": WIDTH,
            "phong": pc.as_dict(), "bump": bc.as_dict(),
            "extra_mux_bits": bc.mux_bits - pc.mux_bits,
            "extra_multipliers": len(bc.multipliers) - len(pc.multipliers),
            "extra_adders": len(bc.adders) - len(pc.adders),
            "extra_area_fraction": (bc.area - pc.area) / pc.area,
            "latency_phong": pc.latency, "latency_bump": bc.latency,
            "rows_phong": _flatten(p), "rows_bump": _flatten(b)}


def fig_bump_renders(out) -> list[Path]:
    """Full vs square-patch vs object-space bump mapping, with error maps (C12)."""
    folder = _dir(out)
    cases = _cases()
    caption = ("Seed 001 (claim C12): bump-mapped renders with the full tangent-space coefficients "
               "[a, b, c] = [-F_u (B.P_v), F_u (T.P_v) - F_v |P_u|, |P_u x P_v|] (reference), the "
               "square-patch simplification [-F_u/k, -F_v/k, 1] and the object-space variant, on a "
               f"flat square (a square patch: they agree), a sphere and a torus ({SIZE[0]}x{SIZE[1]} "
               "px); error maps |difference to full| in 8-bit levels on one scale for the whole figure, "
               "with its colour bar beside each map.")
    rows = []
    for c in cases:
        for variant, d in (("square", c.square_vs_full), ("object", c.object_vs_full)):
            rows.append((c.mesh, variant, c.k, *[float("nan") if d[k] is None else d[k] for k in _METRICS]))
    paths = [write_csv(folder, "bump_renders", ("mesh", "variant", "k", *_METRICS), rows, caption, CMD,
                       ["k: the patch scale |P_u| used by the square-patch coefficients; "
                        "psnr nan = identical images"])]
    # one scale for every error map of the figure, so a 3-level and a 62-level error look different
    scale = max([1.0] + [float(np.abs(c.images[k]).max()) for c in cases
                         for k in ("square_error", "object_error")])
    with figure(len(cases), 5, figsize=(12.0, 2.5 * len(cases))) as (fig, axes):
        for r, c in enumerate(cases):
            panels = ((c.images["full"], f"{c.mesh}: full (reference)"),
                      (c.images["square"], "square patch"), (c.images["object"], "object space"))
            for ax, (im, title) in zip(axes[r], panels):
                ax.imshow(im, interpolation="nearest", cmap="gray", vmin=0, vmax=255)
                ax.set_title(title, fontsize=8)
                ax.set_axis_off()
            error_map(fig, axes[r][3], c.images["square_error"], scale,
                      f"|square - full|, max {c.square_vs_full['max_abs_8bit']} levels")
            error_map(fig, axes[r][4], c.images["object_error"], scale,
                      f"|object - full|, max {c.object_vs_full['max_abs_8bit']} levels")
        fig.suptitle("Seed 001: the square-patch coefficients are exact on the square and err on the "
                     "sphere and torus; the object-space variant stays near 0 "
                     f"(error maps: one scale, 0-{scale:g} 8-bit levels)")
        paths += save_figure(fig, folder, "bump_renders", caption)
    paths.append(write_json(folder / "c12_summary.json", {**measure_c12(), "command": CMD}))
    return paths


def fig_pipeline_costs(out) -> list[Path]:
    """Seed 001's pipeline block diagrams as cost tables (C13)."""
    folder = _dir(out)
    m = measure_c13()
    caption = ("Seed 001 (claim C13): the Phong pipeline (interpolation of N, L, H; three classic "
               "normalization units; intensity) and the bump-mapping pipeline built on it, as cost "
               f"tables of chebnorm.hw's datapath model ({WIDTH}-bit components; area in full-adder "
               f"equivalents). Bump mapping adds {m['extra_mux_bits']} multiplexer bits "
               f"(+{100 * m['extra_area_fraction']:.2f} % area), latency {m['latency_phong']} -> "
               f"{m['latency_bump']} cycles; texture memory and the per-vertex transform of L, H "
               "into tangent space are outside the model.")
    cols = ("pipeline", "block", "multipliers", "adders", "sqrts", "dividers", "mux_bits", "rom_bits",
            "latency", "area_fa")
    rows = [("phong", *r) for r in m["rows_phong"]] + [("bump", *r) for r in m["rows_bump"]]
    paths = [write_csv(folder, "pipeline_costs", cols, rows, caption, CMD)]
    with figure(figsize=(8.0, 3.4)) as (fig, ax):
        depth = [(r, r[0].count(" > ")) for r in m["rows_bump"]]
        # the Phong pipeline's top-level blocks, then the bump pipeline's own addition
        tops = [r for r, k in depth if k == 2]
        extra = [r for r, k in depth if k == 1 and "Phong" not in r[0]]
        total_b = sum(r[8] for r in tops + extra)
        colors = ["#0072B2", "#56B4E9", "#009E73", "#CC79A7", "#999999", "#000000"]
        for yy, (label, blocks) in enumerate((("Phong", tops), ("bump", tops + extra))):
            left = 0.0
            for i, r in enumerate(blocks):
                is_extra = r in extra
                ax.barh(yy, r[8], left=left, height=0.55, edgecolor="white", lw=0.5,
                        color="#D55E00" if is_extra else colors[i % len(colors)],
                        label=(r[0].split(" > ")[-1] if yy == 1 else None))
                left += r[8]
            ax.text(left, yy, f" {left:.0f} FA", va="center", fontsize=8)
        mux = sum(r[8] for r in extra)
        ax.annotate(f"multiplexer: {mux:.0f} FA = {100 * mux / total_b:.2f} % of the bump pipeline",
                    xy=(total_b - mux / 2, 1.3), xytext=(0.45 * total_b, 1.75), fontsize=8,
                    color="#D55E00", arrowprops={"arrowstyle": "->", "color": "#D55E00"})
        ax.set_yticks([0, 1], ["Phong pipeline", "bump pipeline"])
        ax.set_ylim(-0.5, 2.1)
        ax.set_xlim(0, 1.12 * total_b)
        ax.set_xlabel("area (full-adder equivalents, linear scale)")
        ax.legend(fontsize=7, ncol=3, loc="lower center", bbox_to_anchor=(0.5, 1.0), frameon=False)
        ax.set_title(f"Seed 001: the bump pipeline is the Phong pipeline plus a {m['extra_mux_bits']}-bit "
                     f"multiplexer (+{100 * m['extra_area_fraction']:.2f} % area; model, not synthesis)",
                     pad=40)
        paths += save_figure(fig, folder, "pipeline_costs", caption)
    return paths


FIGURES = (fig_bump_renders, fig_pipeline_costs)


def run(out) -> list[Path]:
    """The seed 001 job."""
    paths = []
    for f in FIGURES:
        paths += f(out)
    return paths
