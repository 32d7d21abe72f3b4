"""Shading throughput per mode, and the cost of a full Phong ``exact`` frame
relative to a bare numpy normalization of the same number of vectors
(goal: at most 3x).  Not a test; run it:

    .venv/bin/python benchmarks/bench_raster.py [--size 512 512] [--repeat 5] [--json]

Uses the public API only.  Times are the best of ``--repeat`` runs
(after one warm-up run that also fills caches: sympy kernels, tables).
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from chebnorm.raster import available_methods, get_mesh, render


def best_of(fn, repeat):
    fn()
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return min(times), out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="teapot")
    ap.add_argument("--size", nargs=2, type=int, default=(512, 512))
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    mesh = get_mesh(args.mesh)
    size = tuple(args.size)
    rows = []
    cases = [("gouraud", None), ("split-gouraud", None), ("adaptive", "exact"), ("bump", "exact")]
    cases += [("phong", m) for m in available_methods()]
    for mode, method in cases:
        sec, r = best_of(lambda: render(mesh, mode, method, size=size), args.repeat)
        rows.append({"mode": mode, "method": method, "seconds": sec, "fragments": r.fragments,
                     "pixels": r.pixels, "mfragments_per_s": r.fragments / sec / 1e6})
    phong = next(r for r in rows if r["mode"] == "phong" and r["method"] == "exact")
    rng = np.random.default_rng(0)
    vec = rng.standard_normal((phong["fragments"], 3))
    bare, _ = best_of(lambda: vec / np.sqrt(np.einsum("ij,ij->i", vec, vec))[:, None], args.repeat)
    summary = {"mesh": mesh.name, "triangles": int(len(mesh.faces)), "size": list(size),
               "phong_exact_frame_s": phong["seconds"], "bare_normalize_s": bare,
               "ratio_frame_to_bare": phong["seconds"] / bare, "goal_ratio": 3.0, "modes": rows}
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"{mesh.name}: {len(mesh.faces)} triangles, {size[0]}x{size[1]}")
        for r in rows:
            label = r["mode"] + (f":{r['method']}" if r["method"] else "")
            print(f"  {label:22s} {r['seconds'] * 1e3:8.1f} ms  {r['fragments']:8d} fragments  "
                  f"{r['mfragments_per_s']:6.2f} Mfrag/s")
        print(f"bare numpy normalization of {phong['fragments']} vectors: {bare * 1e3:.2f} ms")
        print(f"Phong exact frame / bare normalization: {summary['ratio_frame_to_bare']:.1f}x "
              f"(goal <= 3x)")


if __name__ == "__main__":
    main()
