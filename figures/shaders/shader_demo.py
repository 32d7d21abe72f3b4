"""Shader demo: the per-pixel normalization methods of seed 000 in a real
OpenGL fragment shader (Mesa llvmpipe, moderngl, headless EGL), against
chebnorm's own span rasterizer on the same mesh, camera and light.

Writes, next to this script (deterministically):

* ``shader_demo.csv`` -- per method: pixels covered by each renderer and by
  both, and the 8-bit max / mean |GL - chebnorm| on the pixels both cover;
* ``shader_demo.png`` -- one row per method: the GL render, chebnorm's render,
  and |difference| x 16 (grey, saturating at 16 levels).

Methods: ``exact`` (N / |N|), ``none``, ``newton`` (N (3 - N.N) / 2),
``lyon`` (N (15 - 10 N.N + 3 (N.N)^2) / 8) and ``N p(N.N)`` with the exported
GLSL of the registered ``rsqrt_d2`` and ``rsqrt_d3`` tables (1/sqrt(x) on
[sqrt(2)/4 + 1/2, 1]: the squared length of the chord-midpoint normal at
45 degrees). The span methods (dichotomy, quadratic/midpoint, angular, slerp)
need the span's end normals, which a fragment shader does not have: not
drawn.

The two pipelines interpolate differently, and the CSV measures the sum of
both effects: GL interpolates the unit *vertex* normals linearly over the
triangle (``noperspective``, as chebnorm's scan-line hardware); chebnorm
interpolates along the edges, normalizes the span ends exactly (seed 000's
methods take unit end normals), then runs the method along the span. For
``exact`` only the direction can differ; for ``none``/``newton``/``lyon``/
``rsqrt`` the length before the method differs too, most on large triangles.
Coverage follows each rasterizer's own edge rule (both sample pixel centres),
so the comparison is on the pixels both cover.

Run: ``python figures/shaders/shader_demo.py`` (needs moderngl and an EGL
OpenGL 4.3 driver; about ten seconds).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from chebnorm.approx import CoefficientTable
from chebnorm.core.files import write_atomic
from chebnorm.core.textsafe import csv_cell
from chebnorm.export import glsl_source
from chebnorm.export.gpu import gl_context
from chebnorm.methods import span_normals
from chebnorm.raster import render
from chebnorm.raster.meshes import get_mesh
from chebnorm.raster.metrics import to_8bit, write_png
from chebnorm.raster.render import Lighting
from chebnorm.raster.scanline import fit_camera, project

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
SIZE = (256, 256)
MESH, TESS = "teapot", 8
POLY = ("rsqrt_d2", "rsqrt_d3")
METHODS = ("exact", "none", "newton", "lyon") + POLY

_GLSL_METHOD = {
    "exact": "n / sqrt(dot(n, n))",
    "none": "n",
    "newton": "n * ((3.0 - dot(n, n)) * 0.5)",
    "lyon": "n * ((dot(n, n) * 0.375 - 1.25) * dot(n, n) + 1.875)",
}

VERTEX = """#version 430
in vec4 in_clip;
in vec3 in_normal;
in vec3 in_pos;
noperspective out vec3 v_normal;
noperspective out vec3 v_pos;
void main() {
    gl_Position = in_clip;
    v_normal = in_normal;
    v_pos = in_pos;
}
"""

FRAGMENT = """#version 430
noperspective in vec3 v_normal;
noperspective in vec3 v_pos;
uniform vec3 L;
uniform vec3 eye;
uniform float I0;
uniform float ka;
uniform float kd;
uniform float ks;
uniform float shininess;
layout(location = 0) out vec2 frag;
{functions}
vec3 normalize_method(vec3 n) {{ return {method}; }}
void main() {{
    vec3 N = normalize_method(v_normal);
    vec3 H = normalize(L + normalize(eye - v_pos));
    float I = I0 * (ka + kd * max(dot(N, L), 0.0) + ks * pow(max(dot(N, H), 0.0), shininess));
    frag = vec2(clamp(I, 0.0, 1.0), 1.0);
}}
"""


def _table(name: str) -> CoefficientTable:
    return CoefficientTable.load(ROOT / "figures" / "coefficients" / f"{name}.json")


def _poly_interp(table: CoefficientTable):
    """chebnorm's span interpolator for ``N p(N.N)``: linear between the unit
    span ends (as every seed-000 method), then the polynomial, in float32."""
    c = [np.float32(v) for v in table.coefficients]

    def interp(method, nl, nr, m, *, t0=None, dt=None, count=None, tables=None,
               dtype=np.float64, **_):
        res = span_normals("none", nl, nr, m, t0=t0, dt=dt, count=count, dtype=np.float32)
        n = np.asarray(res.normals, dtype=np.float32)
        x = np.einsum("ij,ij->i", n, n).astype(np.float32)
        acc = np.full(x.shape, c[-1], dtype=np.float32)
        for ck in reversed(c[:-1]):
            acc = (acc * x + ck).astype(np.float32)
        return type(res)(normals=(n * acc[:, None]).astype(np.float64), offsets=res.offsets,
                         t=res.t)

    return interp


def gl_render(mesh, camera, lighting: Lighting, method: str) -> tuple[np.ndarray, np.ndarray]:
    """Intensity image and coverage mask rendered by OpenGL."""
    ctx = gl_context()
    w, h = SIZE
    xy, inv_w = project(camera, mesh.positions, w, h)
    wv = 1.0 / inv_w
    ndc_x = 2.0 * xy[:, 0] / w - 1.0
    ndc_y = 1.0 - 2.0 * xy[:, 1] / h
    z_ndc = 1.0 - 1.98 * inv_w / inv_w.max()  # monotone in depth, linear in 1/w
    clip = np.stack([ndc_x * wv, ndc_y * wv, z_ndc * wv, wv], axis=1)
    if method in POLY:
        table = _table(method)
        functions = glsl_source(table)
        expr = f"n * chebnorm_{table.name}(dot(n, n))"
    else:
        functions, expr = "", _GLSL_METHOD[method]
    prog = ctx.program(vertex_shader=VERTEX,
                       fragment_shader=FRAGMENT.format(functions=functions, method=expr))
    L = lighting.direction(camera)
    for name, value in (("L", tuple(L)), ("eye", tuple(np.asarray(camera.eye, float))),
                        ("I0", lighting.I0), ("ka", lighting.ka), ("kd", lighting.kd),
                        ("ks", lighting.ks), ("shininess", lighting.shininess)):
        prog[name].value = value
    faces = mesh.faces
    # front faces only, as chebnorm culls them (clockwise on screen with y down)
    t = xy[faces]
    area = ((t[:, 1, 0] - t[:, 0, 0]) * (t[:, 2, 1] - t[:, 0, 1])
            - (t[:, 2, 0] - t[:, 0, 0]) * (t[:, 1, 1] - t[:, 0, 1]))
    faces = faces[area < 0]
    data = np.concatenate([clip, mesh.normals, mesh.positions], axis=1).astype("f4")
    vbo = ctx.buffer(data.tobytes())
    ibo = ctx.buffer(faces.astype("i4").tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "4f 3f 3f", "in_clip", "in_normal", "in_pos")], ibo)
    color = ctx.texture((w, h), 2, dtype="f4")
    depth = ctx.depth_renderbuffer((w, h))
    fbo = ctx.framebuffer(color_attachments=[color], depth_attachment=depth)
    try:
        fbo.use()
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        vao.render()
        ctx.finish()
        raw = np.frombuffer(fbo.read(components=2, dtype="f4"), dtype=np.float32)
        img = raw.reshape(h, w, 2)[::-1]  # GL rows are bottom-up
        return img[..., 0].astype(np.float64), img[..., 1] > 0.5
    finally:
        for obj in (vao, vbo, ibo, fbo, color, depth, prog):
            obj.release()


def main() -> int:
    mesh = get_mesh(MESH, TESS)
    camera = fit_camera(mesh.positions, *SIZE)
    lighting = Lighting()
    rows, tiles = [], []
    for method in METHODS:
        kw = dict(size=SIZE, camera=camera, lighting=lighting)
        if method in POLY:
            ref = render(mesh, "phong", "newton", span_normals=_poly_interp(_table(method)), **kw)
        else:
            ref = render(mesh, "phong", method, **kw)
        gl, gl_mask = gl_render(mesh, camera, lighting, method)
        a, b = to_8bit(gl).astype(np.int64), to_8bit(ref.image).astype(np.int64)
        both = gl_mask & ref.mask
        d = np.abs(a - b)
        rows.append([method, int(gl_mask.sum()), int(ref.mask.sum()), int(both.sum()),
                     int(d[both].max()), f"{d[both].mean():.4f}", int((d[both] > 1).sum())])
        shown = np.where(both, np.minimum(d * 16, 255), 0)
        tiles.append(np.concatenate([np.where(gl_mask, a, 0), np.where(ref.mask, b, 0), shown],
                                    axis=1).astype(np.uint8))
    header = ["method", "gl_pixels", "chebnorm_pixels", "common_pixels", "max_abs_8bit",
              "mean_abs_8bit", "pixels_over_1_level"]
    csv = "\n".join(",".join(csv_cell(v) for v in r) for r in [header, *rows]) + "\n"
    write_atomic(HERE / "shader_demo.csv", csv)
    sep = np.full((2, tiles[0].shape[1]), 255, np.uint8)
    mosaic = np.concatenate([x for t in tiles for x in (t, sep)][:-1], axis=0)
    write_png(HERE / "shader_demo.png", mosaic)
    sys.stdout.write(csv)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
