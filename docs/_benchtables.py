"""The tables of the benchmarks page, printed from the committed result files of
``benchmarks/`` (``results.json``, ``design_targets_results.json``,
``specs_results.json``) so that no figure on the page is typed by hand.

``docs/conf.py`` writes each table to ``docs/_bench/NAME.md`` (a build product,
git-ignored) and ``docs/benchmarks.md`` includes them; ``tests/test_docs_bench.py``
reads the tables back and checks every cell against the JSON files.
"""

from __future__ import annotations

import json
from pathlib import Path

BENCH = Path(__file__).resolve().parent.parent / "benchmarks"

#: the C kernels' builds, in the column order of the kernel tables
CONFIGS = ("O2", "clang O2", "O3-native", "clang O3-native", "O3-native-no-errno",
           "clang O3-native-no-errno", "AVX2", "clang AVX2")
#: the span sets of results.json's kernel timings, in the column order of the span table
SPAN_SETS = ("length_4", "length_16", "length_64", "length_256", "mesh", "triangles")


def load(name: str) -> dict:
    """The parsed JSON file ``benchmarks/NAME``."""
    return json.loads((BENCH / name).read_text(encoding="utf-8"))


def fmt(value, digits: int = 3) -> str:
    """``value`` with ``digits`` significant digits (``-`` for a missing value)."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    return f"{value:#.{digits}g}".rstrip(".")   # trailing zeros kept: 1.00, not 1


def _cell(text) -> str:
    """Text safe in a Markdown table cell (bars, backticks and asterisks escaped)."""
    return "".join("\\" + ch if ch in "\\|`*_<>[]" else ch for ch in str(text))


def table(header: list[str], rows: list[list[str]]) -> str:
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def _machine(doc: dict) -> str:
    m = doc["machine"]
    return (f"Machine: {_cell(m['cpu'])}, {m['cores']} cores, load average "
            f"{fmt(m['loadavg_start'][0])} at the start and {fmt(m['loadavg_end'][0])} at the end; "
            f"Python {_cell(m['python'])}.\n")


def kernels(compiler: str = "gcc") -> str:
    """results.json: ns per pixel (median) and the median speed-up against classic of the
    same build, on the spans of the main frame, per method and build of ``compiler``
    (the machine heads gcc's table)."""
    doc = load("results.json")
    configs = [c for c in CONFIGS if c in doc["configs"] and doc["configs"][c]["compiler"] == compiler]
    methods = sorted({m for c in configs for m in doc["configs"][c]["kernels"]["mesh"]})
    rows = []
    for method in methods:
        row = [f"`{method}`"]
        for c in configs:
            k = doc["configs"][c]["kernels"]["mesh"].get(method)
            row.append("-" if k is None else
                       f"{fmt(k['ns_per_pixel_median'])} ({fmt(k['speedup_vs_classic']['median'])}x)"
                       if "speedup_vs_classic" in k else fmt(k["ns_per_pixel_median"]))
        rows.append(row)
    rows.append(["store floor"] + [fmt(doc["configs"][c]["floor"]["mesh"]["ns_per_pixel_median"])
                                   for c in configs])
    builds = "; ".join(f"`{c}`: `{doc['configs'][c]['command']}` ({_cell(doc['configs'][c]['version'])})"
                       for c in configs)
    head = _machine(doc) + "\n" if compiler == "gcc" else ""
    return (head + table(["method"] + [f"`{c}`" for c in configs], rows)
            + f"\nBuilds: {builds}.\n")


def span_lengths() -> str:
    """results.json: the median speed-up against classic per span set, ``O2`` build."""
    doc = load("results.json")
    k = doc["configs"]["O2"]["kernels"]
    sets = [s for s in SPAN_SETS if s in k]
    methods = sorted(m for m in k["mesh"] if "speedup_vs_classic" in k["mesh"][m])
    rows = [[f"`{m}`"] + [fmt(k[s][m]["speedup_vs_classic"]["median"]) if m in k[s] else "-"
                          for s in sets] for m in methods]
    return table(["method"] + [f"`{s}`" for s in sets], rows)


def fit() -> str:
    """results.json: fit and certification against Sollya on the 18-case workload."""
    doc = load("results.json")
    rows = [[fmt(r["tightness"]), str(r["cases"]), fmt(r["chebnorm_fit_and_certify_s"]),
             fmt(r["sollya_remez_and_supnorm_s"]), fmt(r["fit_and_certify_speedup"]),
             fmt(r["certify_speedup"]), fmt(r["chebnorm_worst_bound_over_max"]),
             fmt(r["sollya_worst_upper_over_lower"])]
            for r in doc["fit_vs_sollya"]["rows"] if "cases" in r]
    return table(["tightness", "cases", "chebnorm fit + certify (s)", "Sollya remez + supnorm (s)",
                  "speed-up", "certify alone: speed-up", "chebnorm: worst bound/max - 1",
                  "Sollya: worst upper/lower - 1"], rows)


def piecewise() -> str:
    """results.json: the batched certifier on every segment of a piecewise table against
    Sollya's supnorm on each segment."""
    doc = load("results.json")
    rows = [[_cell(r["workload"]), fmt(r["tightness"]), fmt(r["chebnorm_certify_s"]),
             fmt(r["chebnorm_per_segment_certify_s"]), fmt(r["sollya_supnorm_s"]),
             fmt(r["certify_speedup"]), fmt(r["chebnorm_bound"]), fmt(r["sollya_bound"])]
            for r in doc["fit_vs_sollya"]["rows"] if "workload" in r]
    return table(["workload", "tightness", "chebnorm batched (s)", "chebnorm one segment at a time (s)",
                  "Sollya supnorm (s)", "speed-up", "chebnorm bound", "Sollya bound"], rows)


def quantize() -> str:
    """results.json: quantization against Sollya's fpminimax."""
    q = load("results.json")["quantize_vs_sollya"]
    cases = q["cases"]
    rows = [[_cell(q["workload"]), str(len(cases)), fmt(q["chebnorm_total_s"]), fmt(q["sollya_total_s"]),
             fmt(q["total_speedup"]), fmt(q["median_speedup"]),
             str(sum(1 for c in cases if c["sollya_bound"] is not None
                     and c["chebnorm_bound"] <= c["sollya_bound"])),
             str(len(q["sollya_failed"]))]]
    return table(["workload", "cases", "chebnorm (s)", "Sollya (s)", "total speed-up", "median speed-up",
                  "cases with a bound at or below Sollya's", "Sollya failed"], rows) + \
        f"\nRun: `{q['command']}` on {_cell(q['cpu'])}.\n"


def raster() -> str:
    """results.json: the renderer per shading mode and method, both engines."""
    r = load("results.json")["raster"]
    rows = [[f"`{m['mode']}`", "-" if m["method"] is None else f"`{m['method']}`",
             fmt(m["numba_mfrag_per_s"]), fmt(m["numba_mfrag_per_cpu_s"]), fmt(m["numpy_mfrag_per_s"]),
             fmt(m["speedup"])] for m in r["modes"]]
    size = "x".join(str(s) for s in r["size"])
    head = (f"{_cell(r['mesh'])} at {size}, {r['modes'][0]['fragments']} fragments, {r['threads']} threads "
            f"on {_cell(r['cpu'])}; load average {fmt(r['load_average_before'][0])} before, "
            f"{fmt(r['load_average_after'][0])} after.\n\n")
    return head + table(["mode", "method", "numba Mfrag/s (wall)", "numba Mfrag/s (CPU)",
                         "numpy Mfrag/s (wall)", "numba / numpy"], rows)


def _bench_module(name: str):
    """A script of ``benchmarks/`` imported as a module (its own table printer)."""
    import importlib
    import sys

    sys.path.insert(0, str(BENCH))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(BENCH))


def design_targets() -> str:
    """design_targets_results.json, printed by ``bench_design_targets.py --markdown``."""
    doc = load("design_targets_results.json")
    return (f"`{doc['command']}`, best of {doc['repeat']} runs per target, {doc['cores']} cores.\n\n"
            + _bench_module("bench_design_targets").markdown(doc))


def specs() -> str:
    """specs_results.json, printed by ``bench_specs.py``'s table printer."""
    doc = load("specs_results.json")
    bench = _bench_module("bench_specs")
    versions = "; ".join(_cell(v) for _k, v in sorted(doc["versions"].items()))
    return bench.markdown(doc["results"], bench.SPECS) + f"\n\nTools: {versions}.\n"


#: fragment name -> the function printing it
TABLES = {"kernels_gcc": kernels, "kernels_clang": lambda: kernels("clang"), "span_lengths": span_lengths, "fit": fit, "piecewise": piecewise,
          "quantize": quantize, "raster": raster, "design_targets": design_targets, "specs": specs}
