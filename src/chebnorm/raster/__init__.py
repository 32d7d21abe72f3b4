"""Stage 4: meshes, scan-line spans, shading modes and image metrics.

Layer rule: imports chebnorm.symbolic, chebnorm.approx and chebnorm.methods,
never chebnorm.hw or the CLI.

>>> from chebnorm.raster import render, compare
>>> ref = render("sphere", "phong", "exact", size=(48, 48), tess=8)
>>> m, _ = compare(render("sphere", "phong", "exact", size=(48, 48), tess=8), ref, flip=False)
>>> m.max_abs_8bit
0

Public API: :func:`render` (one frame, any mode), :func:`compare` (metrics
and the signed 8-bit difference), :func:`error_map_rgb`, :func:`write_image`
(PNG, JPEG, TIFF or BMP by file extension); meshes (:func:`get_mesh` and the
generators); studies for the paper reproduction (:func:`eta_study`, :func:`split_gouraud_study`,
:func:`bump_comparison`, :func:`write_bump_figures`); render sweeps over a grid of cases
(:func:`render_sweep_cases`, :func:`render_sweep`: one CSV of metrics, run in parallel).

Where a change goes: ``render.py`` is the front end (validates, picks an engine once,
dispatches the mode); ``shading.py`` holds the shading modes, written once against the
engine interface of ``engines/base.py``; ``engines/numpy.py`` is the reference engine
and ``engines/numba/`` the compiled one (``jit`` < ``calibration``, ``workspace`` <
``rasterize``, ``kernels`` < ``setup`` < ``frame``: the fused ``phong`` frame), which
must give the reference's bytes; ``scanline.py`` the numpy span set-up and camera;
``meshes.py``, ``metrics.py``, ``display.py`` and ``studies.py`` what their names say.
"""

from .meshes import (MESH_NAMES, Mesh, crease_normals, get_mesh, icosphere, load_mesh, square,
                     teapot, torus, uv_sphere)
from .metrics import IMAGE_FORMATS, ImageMetrics, compare, error_map_rgb, write_image, write_png
from .render import (BUMP_VARIANTS, SHADING_MODES, HeightMap, Lighting, RenderResult,
                     available_methods, get_span_normals, render, to_8bit)
from .scanline import Camera, Spans, default_camera, fit_camera, project, setup_spans, zbuffer
from .display import RenderComparison, png_data_uri, render_html
from .studies import (RENDER_SWEEP_COLUMNS, BumpCase, EtaLevel, RenderCase, RenderSweep,
                      RenderSweepRow, SplitGouraudStudy, bump_comparison, eta_study,
                      render_sweep, render_sweep_cases, split_gouraud_study, write_bump_figures)

__all__ = [
    "render", "compare", "error_map_rgb", "write_image", "write_png", "IMAGE_FORMATS", "to_8bit",
    "RenderResult", "ImageMetrics", "Lighting", "HeightMap", "SHADING_MODES", "BUMP_VARIANTS",
    "available_methods", "get_span_normals",
    "Mesh", "MESH_NAMES", "get_mesh", "uv_sphere", "icosphere", "torus", "square", "teapot",
    "load_mesh", "crease_normals",
    "Camera", "Spans", "default_camera", "fit_camera", "project", "setup_spans", "zbuffer",
    "eta_study", "EtaLevel", "split_gouraud_study", "SplitGouraudStudy", "bump_comparison",
    "BumpCase", "write_bump_figures", "render_sweep", "render_sweep_cases", "RenderCase",
    "RenderSweepRow", "RenderSweep", "RENDER_SWEEP_COLUMNS",
    "RenderComparison", "render_html", "png_data_uri",
]
