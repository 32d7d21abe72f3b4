"""Shading throughput per mode and engine, and the cost of a full Phong ``exact``
frame relative to a bare numpy normalization of the same number of vectors
(goal: at most 3x).  Not a test; run it:

    .venv/bin/python benchmarks/bench_raster.py [--size 512 512] [--repeat 5] [--json]
                                                [--engine numba numpy] [--peer llvmpipe]
                                                [--stages]

``--stages``: process CPU time of each stage of the numba engine's ``phong`` frame
(set-up, row spans, end normals and checks, method set-up, then the frame's passes:
visibility and background, the method's normals, half vectors, shading with ``pow``
and the output maps), every method; with ``--image-only`` the frame of
``render(..., extra_maps=False)``.

``--peer llvmpipe``: the ``phong`` frame of every method against Mesa's
llvmpipe drawing the same frame (the shader demo's fragment shader with
``normalize``; see :class:`LlvmpipePeer`), every case once per round, 7 rounds
(``--repeat``) after a warm-up round, best round per case, all in one process;
prints each method's rate relative to llvmpipe's (llvmpipe time / chebnorm time:
>= 1 is as fast or faster) without and with llvmpipe's read-back, the same ratio
in process CPU time, and the load average before and after.  chebnorm's frame is
the whole ``render`` call (projection and set-up included); llvmpipe's draws
buffers uploaded once.  Every method is timed twice: ``render``'s default frame
(image, mask, triangle and ``|N|`` maps: 25 bytes a pixel) and, as ``METHOD/img``,
``render(..., extra_maps=False)``: the image and mask alone, what llvmpipe's frame
holds too (its intensity and coverage target).

Uses the public API only.  Times are the best of ``--repeat`` runs (after one
warm-up run that also fills caches: sympy kernels, tables, numba's compiled
code, so the figures are steady state).  The numpy engine is single-threaded;
the numba engine's ``phong`` frame (chebnorm.raster.engines.numba.frame) splits its scan lines
over the CPUs the process may use (``threads`` in the output), the other modes
run single-threaded, so ``speedup`` (numpy time / numba time, same frame) is the
speedup a user sees, not a per-core figure.  ``cpu_s`` is the process CPU time
(all threads) of the best run, less sensitive than wall time to a machine shared
with other jobs.  The load average is printed beside the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np
from machine import cpu_description

from chebnorm.raster import available_methods, get_mesh, render, to_8bit


def best_of(fn, repeat):
    fn()
    times = []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        times.append((time.perf_counter() - t, time.process_time() - c))
    wall, cpu = min(times)
    return wall, out, cpu


# ------------------------------------------------------------------ llvmpipe peer
_PEER_VERTEX = """#version 430
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

# figures/shaders/shader_demo.py's fragment shader with ``normalize`` (its ``exact``)
_PEER_FRAGMENT = """#version 430
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
void main() {
    vec3 N = normalize(v_normal);
    vec3 H = normalize(L + normalize(eye - v_pos));
    float I = I0 * (ka + kd * max(dot(N, L), 0.0) + ks * pow(max(dot(N, H), 0.0), shininess));
    frag = vec2(clamp(I, 0.0, 1.0), 1.0);
}
"""


class LlvmpipePeer:
    """The same Phong frame drawn by Mesa's llvmpipe (moderngl on the headless EGL
    context of :func:`chebnorm.export.gpu.gl_context`), as the shader demo
    (figures/shaders/shader_demo.py) draws it: same mesh, camera (``fit_camera``),
    light and Blinn-Phong parameters, front faces only, a float32 intensity and
    coverage target with a depth buffer.  Program, buffers and framebuffer are made
    once (a GL application keeps them); a frame is clear + draw + ``finish``
    (:meth:`frame`), and with :meth:`frame_read` also the read-back of the
    intensity/coverage target into a numpy array."""

    def __init__(self, mesh, size):
        from chebnorm.export.gpu import gl_context
        from chebnorm.raster import fit_camera, project
        from chebnorm.raster.render import Lighting

        self.ctx = ctx = gl_context()
        w, h = self.size = size
        camera = fit_camera(mesh.positions, w, h)
        lighting = Lighting()
        xy, inv_w = project(camera, mesh.positions, w, h)
        wv = 1.0 / inv_w
        ndc_x = 2.0 * xy[:, 0] / w - 1.0
        ndc_y = 1.0 - 2.0 * xy[:, 1] / h
        z_ndc = 1.0 - 1.98 * inv_w / inv_w.max()  # monotone in depth, linear in 1/w
        clip = np.stack([ndc_x * wv, ndc_y * wv, z_ndc * wv, wv], axis=1)
        with ctx:
            self.prog = prog = ctx.program(vertex_shader=_PEER_VERTEX,
                                           fragment_shader=_PEER_FRAGMENT)
            values = (("L", tuple(lighting.direction(camera))),
                      ("eye", tuple(np.asarray(camera.eye, float))), ("I0", lighting.I0),
                      ("ka", lighting.ka), ("kd", lighting.kd), ("ks", lighting.ks),
                      ("shininess", lighting.shininess))
            for name, value in values:
                prog[name].value = value
            t = xy[mesh.faces]   # front faces only, as chebnorm culls (clockwise, y down)
            area = ((t[:, 1, 0] - t[:, 0, 0]) * (t[:, 2, 1] - t[:, 0, 1])
                    - (t[:, 2, 0] - t[:, 0, 0]) * (t[:, 1, 1] - t[:, 0, 1]))
            faces = mesh.faces[area < 0]
            data = np.concatenate([clip, mesh.normals, mesh.positions], axis=1).astype("f4")
            self.vbo = ctx.buffer(data.tobytes())
            self.ibo = ctx.buffer(faces.astype("i4").tobytes())
            self.vao = ctx.vertex_array(prog, [(self.vbo, "4f 3f 3f", "in_clip", "in_normal",
                                                "in_pos")], self.ibo)
            self.color = ctx.texture((w, h), 2, dtype="f4")
            self.depth = ctx.depth_renderbuffer((w, h))
            self.fbo = ctx.framebuffer(color_attachments=[self.color],
                                       depth_attachment=self.depth)

    def frame(self):
        """Clear, draw, wait for the rasterizer threads (no read-back)."""
        ctx = self.ctx
        with ctx:
            self.fbo.use()
            ctx.enable(ctx.DEPTH_TEST)
            ctx.disable(ctx.CULL_FACE)
            self.fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            self.vao.render()
            ctx.finish()

    def frame_read(self):
        """:meth:`frame`, then the intensity image and coverage mask in host memory."""
        self.frame()
        with self.ctx:
            raw = np.frombuffer(self.fbo.read(components=2, dtype="f4"), dtype=np.float32)
        w, h = self.size
        img = raw.reshape(h, w, 2)[::-1]   # GL rows are bottom-up
        return img[..., 0], img[..., 1] > 0.5

    def release(self):
        with self.ctx:
            for obj in (self.vao, self.vbo, self.ibo, self.fbo, self.color, self.depth,
                        self.prog):
                obj.release()


def peer_llvmpipe(mesh, size, methods, repeat, engine="numba"):
    """chebnorm's ``phong`` frame per method and llvmpipe's frame (without and with
    read-back), interleaved: ``repeat`` rounds, each timing every case once, best
    of the rounds per case (one warm-up round first).  Returns the rows and the
    load average before and after."""
    peer = LlvmpipePeer(mesh, size)
    cases = [("llvmpipe", peer.frame), ("llvmpipe+read", peer.frame_read)]
    cases += [(m, (lambda m=m: render(mesh, "phong", m, size=size, engine=engine)))
              for m in methods]
    # the image and mask alone (llvmpipe's frame holds no triangle or |N| map either)
    cases += [(m + "/img", (lambda m=m: render(mesh, "phong", m, size=size, engine=engine,
                                               extra_maps=False))) for m in methods]
    timed = {name for name, _ in cases[2:]}
    load_before = os.getloadavg()
    best = {name: float("inf") for name, _ in cases}
    cpu = {}
    frags = {}
    for rnd in range(repeat + 1):
        for name, fn in cases:
            t, c = time.perf_counter(), time.process_time()
            out = fn()
            sec, cs = time.perf_counter() - t, time.process_time() - c
            if name in timed:
                frags[name] = out.fragments
            if rnd and sec < best[name]:
                best[name], cpu[name] = sec, cs
    load_after = os.getloadavg()
    gl_img, gl_mask = peer.frame_read()
    peer.release()
    # the same frame: coverage and the 8-bit intensity where both cover (exact)
    ref = render(mesh, "phong", "exact", size=size, engine=engine)
    both = gl_mask & ref.mask
    diff = np.abs(to_8bit(gl_img.astype(np.float64)).astype(np.int64)
                  - to_8bit(ref.image).astype(np.int64))[both]
    gl = best["llvmpipe"]
    rows = [{"case": name, "seconds": best[name], "cpu_s": cpu[name],
             "fragments": frags.get(name),
             "ratio_vs_llvmpipe": gl / best[name] if name in timed else None,
             "ratio_vs_llvmpipe_read": best["llvmpipe+read"] / best[name]
             if name in timed else None,
             "cpu_ratio_vs_llvmpipe": cpu["llvmpipe"] / cpu[name]
             if name in timed and cpu[name] else None} for name, _ in cases]
    return {"rows": rows, "gl_pixels": int(gl_mask.sum()), "chebnorm_pixels": int(ref.mask.sum()),
            "common_pixels": int(both.sum()),
            "max_abs_8bit": int(diff.max()) if diff.size else None,
            "pixels_over_1_level": int((diff > 1).sum()),
            "load_average_before": load_before,
            "load_average_after": load_after, "rounds": repeat, "engine": engine}


def print_peer(res, mesh, size):
    lb, la = res["load_average_before"], res["load_average_after"]
    print(f"{mesh.name}: {len(mesh.faces)} triangles, {size[0]}x{size[1]}, phong frame vs "
          f"Mesa llvmpipe, best of {res['rounds']} interleaved rounds; load average "
          f"{lb[0]:.2f} {lb[1]:.2f} {lb[2]:.2f} before, {la[0]:.2f} {la[1]:.2f} {la[2]:.2f} "
          f"after ({os.cpu_count()} cores; {cpu_description()})")
    print(f"  {'case':16s} {'ms':>8s} {'cpu ms':>8s}  {'rate vs llvmpipe':>16s}  "
          f"{'(vs +read-back)':>15s} {'(cpu time)':>10s}  goal")
    for r in res["rows"]:
        if r["ratio_vs_llvmpipe"] is None:
            print(f"  {r['case']:16s} {r['seconds'] * 1e3:8.2f} {r['cpu_s'] * 1e3:8.2f}")
            continue
        goal = 1.0 if r["case"].split("/")[0] == "exact" else 0.8
        verdict = "met" if r["ratio_vs_llvmpipe"] >= goal else "NOT met"
        print(f"  {r['case']:16s} {r['seconds'] * 1e3:8.2f} {r['cpu_s'] * 1e3:8.2f}  "
              f"{r['ratio_vs_llvmpipe']:15.2f}x  {r['ratio_vs_llvmpipe_read']:14.2f}x "
              f"{r['cpu_ratio_vs_llvmpipe'] or float('nan'):9.2f}x  >= {goal:.1f}: {verdict}")
    print(f"  same frame: {res['gl_pixels']} pixels covered by llvmpipe, "
          f"{res['chebnorm_pixels']} by chebnorm, {res['common_pixels']} by both; there the 8-bit "
          f"intensities (exact) differ by more than 1 level at {res['pixels_over_1_level']} "
          f"pixels (at most {res['max_abs_8bit']})")
    print("  rate ratio = llvmpipe ms / chebnorm ms (wall, best round); cpu time: the same "
          "with process CPU time (all threads), less sensitive to other jobs; under load "
          "(load average above the core count) neither is a fair measurement; METHOD/img: "
          "render(..., extra_maps=False), the image and mask only (as llvmpipe's frame)")


def stages(mesh, size, methods, repeat, extra_maps=True):
    """Per-stage process CPU time of the numba engine's ``phong`` frame, per method (best
    of ``repeat`` after a warm-up; the median per stage, since the frame's passes are
    differences of runs): the engine's set-up (projection, triangle gather), then
    :func:`chebnorm.raster.engines.numba.frame.stage_times`' stages."""
    from chebnorm.methods import get_method
    from chebnorm.raster.engines import get_engine
    from chebnorm.raster.engines.numba.frame import stage_times
    from chebnorm.raster.render import Lighting

    eng = get_engine("numba")
    lighting = Lighting()
    out = {}
    for m in methods:
        spec = get_method(m)
        seen = {}
        for rnd in range(repeat + 1):
            c, w = time.process_time(), time.perf_counter()
            st = eng.setup(mesh, None, size, True)
            st.L = lighting.direction(st.camera)
            got = {"setup": (time.process_time() - c, time.perf_counter() - w)}
            got.update(stage_times(st, spec, lighting, extra_maps=extra_maps))
            if rnd:
                for k, v in got.items():
                    seen.setdefault(k, []).append(v)
        out[m] = {k: tuple(float(x) for x in np.median(np.array(v), axis=0))
                  for k, v in seen.items()}
    return out


def print_stages(res, mesh, size, load_before, image_only=False):
    la = os.getloadavg()
    what = " (image and mask only: extra_maps=False)" if image_only else ""
    print(f"{mesh.name} {size[0]}x{size[1]}: numba phong frame{what} per stage, process CPU ms "
          f"(all threads; median of the rounds, per stage); load average {load_before[0]:.2f} "
          f"before, {la[0]:.2f} after")
    names = list(next(iter(res.values())))
    print(f"  {'method':12s}" + "".join(f" {n:>12s}" for n in names) + f" {'total':>8s}")
    for m, st in res.items():
        print(f"  {m:12s}" + "".join(f" {st[n][0] * 1e3:12.2f}" for n in names)
              + f" {sum(v[0] for v in st.values()) * 1e3:8.2f}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="teapot")
    ap.add_argument("--size", nargs=2, type=int, default=(512, 512))
    ap.add_argument("--repeat", type=int, default=None,
                    help="timed runs per case, best taken (default 5; 7 rounds with --peer)")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--engine", nargs="+", default=["numba", "numpy"], choices=["numba", "numpy"],
                    help="engines to time (default both: numba, numpy)")
    ap.add_argument("--modes", nargs="+", default=None,
                    help="only these modes (default all; phong runs every method)")
    ap.add_argument("--peer", choices=["llvmpipe"], default=None,
                    help="time the phong frame of every method against Mesa llvmpipe drawing "
                         "the same frame (moderngl, EGL), interleaved; prints the rate ratios")
    ap.add_argument("--methods", nargs="+", default=None, choices=list(available_methods()),
                    help="with --peer or --stages: only these methods (default every one)")
    ap.add_argument("--stages", action="store_true",
                    help="per-stage CPU time of the numba engine's phong frame, every method")
    ap.add_argument("--image-only", action="store_true",
                    help="with --stages: the frame of render(..., extra_maps=False)")
    args = ap.parse_args(argv)
    args.repeat_set = args.repeat is not None
    args.repeat = args.repeat if args.repeat_set else 5
    mesh = get_mesh(args.mesh)
    size = tuple(args.size)
    if args.stages:
        load_before = os.getloadavg()
        res = stages(mesh, size, args.methods or list(available_methods()), args.repeat,
                     extra_maps=not args.image_only)
        if args.json:
            print(json.dumps(res, indent=2))
        else:
            print_stages(res, mesh, size, load_before, args.image_only)
        return
    if args.peer:
        methods = args.methods or list(available_methods())
        res = peer_llvmpipe(mesh, size, methods, args.repeat if args.repeat_set else 7,
                            engine=args.engine[0])
        if args.json:
            print(json.dumps(res, indent=2))
        else:
            print_peer(res, mesh, size)
        return
    load_before = os.getloadavg()
    rows = []
    cases = [("gouraud", None), ("split-gouraud", None), ("adaptive", "exact"), ("bump", "exact")]
    cases += [("phong", m) for m in available_methods()]
    if args.modes:
        cases = [c for c in cases if c[0] in args.modes]
    for mode, method in cases:
        row = {"mode": mode, "method": method}
        for engine in args.engine:
            sec, r, cpu = best_of(lambda: render(mesh, mode, method, size=size, engine=engine),
                                  args.repeat)
            row.update({"fragments": r.fragments, "pixels": r.pixels,
                        f"{engine}_s": sec, f"{engine}_cpu_s": cpu,
                        f"{engine}_mfrag_per_s": r.fragments / sec / 1e6,
                        f"{engine}_mfrag_per_cpu_s": r.fragments / cpu / 1e6 if cpu else None})
        if "numba_s" in row and "numpy_s" in row:
            row["speedup"] = row["numpy_s"] / row["numba_s"]
        row["seconds"] = row[f"{args.engine[0]}_s"]
        rows.append(row)
    phong = next((r for r in rows if r["mode"] == "phong" and r["method"] == "exact"), rows[0])
    rng = np.random.default_rng(0)
    vec = rng.standard_normal((phong["fragments"], 3))
    bare, _, _ = best_of(lambda: vec / np.sqrt(np.einsum("ij,ij->i", vec, vec))[:, None],
                         args.repeat)
    summary = {"mesh": mesh.name, "triangles": int(len(mesh.faces)), "size": list(size),
               "engines": args.engine, "load_average_before": load_before,
               "threads": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
               else os.cpu_count(),
               "load_average_after": os.getloadavg(), "cores": os.cpu_count(),
               "cpu": cpu_description(),
               "phong_exact_frame_s": phong["seconds"], "bare_normalize_s": bare,
               "ratio_frame_to_bare": phong["seconds"] / bare, "goal_ratio": 3.0, "modes": rows}
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"{mesh.name}: {len(mesh.faces)} triangles, {size[0]}x{size[1]}; load average "
              f"{load_before[0]:.2f} before, {summary['load_average_after'][0]:.2f} after "
              f"({os.cpu_count()} cores, {summary['threads']} usable; {summary['cpu']})")
        head = "".join(f"  {e + ' ms':>10s} {e + ' Mfrag/s':>15s} {'(cpu)':>7s}"
                       for e in args.engine)
        print(f"  {'mode':22s} {'fragments':>9s}{head}  speedup")
        for r in rows:
            label = r["mode"] + (f":{r['method']}" if r["method"] else "")
            cols = "".join(f"  {r[e + '_s'] * 1e3:10.1f} {r[e + '_mfrag_per_s']:15.2f} "
                           f"{r[e + '_mfrag_per_cpu_s']:7.2f}" for e in args.engine)
            sp = f"  {r['speedup']:6.1f}x" if "speedup" in r else ""
            print(f"  {label:22s} {r['fragments']:9d}{cols}{sp}")
        print(f"bare numpy normalization of {phong['fragments']} vectors: {bare * 1e3:.2f} ms")
        print(f"Phong exact frame / bare normalization: {summary['ratio_frame_to_bare']:.1f}x "
              f"(goal <= 3x)")


if __name__ == "__main__":
    main()
