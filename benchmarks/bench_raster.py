"""Shading throughput per mode and engine, and the cost of a full Phong ``exact``
frame relative to a bare numpy normalization of the same number of vectors
(goal: at most 3x).  Not a test; run it:

    .venv/bin/python benchmarks/bench_raster.py [--size 512 512] [--repeat 5] [--json]
                                                [--engine numba numpy]

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

from chebnorm.raster import available_methods, get_mesh, render


def best_of(fn, repeat):
    fn()
    times = []
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        times.append((time.perf_counter() - t, time.process_time() - c))
    wall, cpu = min(times)
    return wall, out, cpu


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="teapot")
    ap.add_argument("--size", nargs=2, type=int, default=(512, 512))
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--engine", nargs="+", default=["numba", "numpy"], choices=["numba", "numpy"],
                    help="engines to time (default both: numba, numpy)")
    ap.add_argument("--modes", nargs="+", default=None,
                    help="only these modes (default all; phong runs every method)")
    args = ap.parse_args(argv)
    mesh = get_mesh(args.mesh)
    size = tuple(args.size)
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
