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
from chebnorm.raster import bump_comparison, error_map_rgb
from chebnorm.symbolic import bump_coefficients_square_expr

from .paths import paper_dir
from .style import figure, save_figure, write_csv, write_json

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
               "px); error maps |difference to full| in 8-bit levels on one scale per row.")
    rows = []
    for c in cases:
        for variant, d in (("square", c.square_vs_full), ("object", c.object_vs_full)):
            rows.append((c.mesh, variant, c.k, *[float("nan") if d[k] is None else d[k] for k in _METRICS]))
    paths = [write_csv(folder, "bump_renders", ("mesh", "variant", "k", *_METRICS), rows, caption, CMD,
                       ["k: the patch scale |P_u| used by the square-patch coefficients; "
                        "psnr nan = identical images"])]
    with figure(len(cases), 5, figsize=(11.0, 2.4 * len(cases))) as (fig, axes):
        for r, c in enumerate(cases):
            scale = max(1.0, float(np.abs(c.images["square_error"]).max()),
                        float(np.abs(c.images["object_error"]).max()))
            panels = ((c.images["full"], f"{c.mesh}: full"), (c.images["square"], "square patch"),
                      (c.images["object"], "object space"),
                      (error_map_rgb(c.images["square_error"], scale),
                       f"|square - full| (max {c.square_vs_full['max_abs_8bit']})"),
                      (error_map_rgb(c.images["object_error"], scale),
                       f"|object - full| (max {c.object_vs_full['max_abs_8bit']})"))
            for ax, (im, title) in zip(axes[r], panels):
                ax.imshow(im, interpolation="nearest", cmap="gray", vmin=0, vmax=255)
                ax.set_title(title, fontsize=8)
                ax.set_axis_off()
        fig.suptitle("Seed 001: square-patch bump coefficients against the full formula "
                     "(error maps: black 0 to white = row max, 8-bit levels)")
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
    with figure(figsize=(7.0, 3.6)) as (fig, ax):
        depth = [(r, r[0].count(" > ")) for r in m["rows_bump"]]
        # the Phong pipeline's top-level blocks, then the bump pipeline's own addition
        tops = [r for r, k in depth if k == 2] + [r for r, k in depth if k == 1 and "Phong" not in r[0]]
        names = [r[0].split(" > ")[-1] for r in tops]
        areas = [r[8] for r in tops]
        y = np.arange(len(names))
        ax.barh(y, areas, color=["C0"] * (len(names) - 1) + ["C1"])
        ax.set_yticks(y, names)
        ax.set_xscale("log")
        ax.set_xlabel("area (full-adder equivalents, log scale)")
        ax.set_title(f"Seed 001: bump pipeline = Phong pipeline + {m['extra_mux_bits']}-bit mux "
                     f"(+{100 * m['extra_area_fraction']:.2f} % area)")
        for yy, a in zip(y, areas):
            ax.text(a, yy, f" {a:.0f}", va="center", fontsize=7)
        paths += save_figure(fig, folder, "pipeline_costs", caption)
    return paths


FIGURES = (fig_bump_renders, fig_pipeline_costs)


def run(out) -> list[Path]:
    """The seed 001 job."""
    paths = []
    for f in FIGURES:
        paths += f(out)
    return paths
