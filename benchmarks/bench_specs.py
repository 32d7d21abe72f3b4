"""Architectures per spec on every FPGA target: faithful designs,
checked exhaustively, synthesized by yosys, timed by nextpnr-ice40.

    python benchmarks/bench_specs.py [--quick] [--json PATH] [--no-sim] [--spec I ...]
    python benchmarks/bench_specs.py --sim-missing --json PATH [--spec I ...]

For each spec (function, interval, input and output bits, faithful: error
< 1 ulp of the output) and each architecture:

* ``pw1``, ``pw2``: the sized piecewise polynomial (``design_piecewise(...,
  widths="auto", multipliers="truncated")``, a width per coefficient) of
  degree 1 and 2 on a centred uniform table; the segment count is the
  cheapest faithful one of a small sweep (``2**k``, from the first ``k``
  that is faithful, three counts) by the design's own area proxy
  (:func:`chebnorm.hw.piecewise.shape_cost`, the greedy's price);
* ``pw1 pipe``, ``pw2 pipe``: the same design fully pipelined
  (``pipeline="full"``, latency = degree + 1 cycles);
* ``multipartite``: ``design_multipartite`` (faithful, its own LUT model);
* ``plain table``: ``design_plain_table`` (correctly rounded), only when
  ``2**in_bits * out_bits <= 2**20`` ROM bits;
* ``exp1``, ``exp2`` (``pipe``): the exponent-indexed ``1/sqrt``
  (:func:`chebnorm.hw.exponent.design_exponent`, degree-1/2 core, its
  segment count the cheapest of three faithful ones by the same proxy),
  for the specs of :data:`SPEC_ARCHS` (which also trims the 20-bit specs).

Each design's exhaustive maximum error is measured (piecewise: ``measure()``
against 40-digit mpmath; tables: ``measure()``, Arb enclosures; exponent:
the mantissa's error, ``measure()``) and must be below one output ulp; its
certified bound is kept too. Every design is synthesized on ``generic``,
``xc7`` (with the ``sta`` cell-delay model: the "model" Fmax), ``xc7-nodsp``
and ``ice40`` (:func:`chebnorm.hw.targets.synthesize_target`) and placed and
routed by nextpnr-ice40 for Fmax (:func:`chebnorm.hw.targets.fmax_ice40`,
HX8K ct256, seed 1, the module between input and output registers). When a
spec's rows are done, the winner on each target (:func:`winners`: fewest
generic cells, lowest target score) is rebuilt (deterministic: the same
design) and simulated over every input code in Icarus Verilog and in GHDL
against the bit-accurate model (:func:`simulate_winners`; a failure is an
error).

Output: a Markdown table on stdout (deterministic row order), progress on
stderr; ``--json PATH`` keeps every finished row (written after each one), and
a rerun with the same ``--json`` reuses the rows finished there (delete the
file to measure afresh; a failed row is tried again). A row that fails records the error and the run goes on.
``--sim-missing`` only runs GHDL for the rows of ``--json`` that have an Icarus
PASS and no GHDL record (:func:`simulate_missing`: each design rebuilt and
checked to be the measured one, pipelined ones clocked code by code), the
cheapest first, and writes ``simulation_vhdl`` and its seconds into each row.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

from tqdm import tqdm

from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.core.files import write_atomic, write_folder
from chebnorm.hw.exponent import design_exponent, simulate_exponent
from chebnorm.hw.multipartite import design_multipartite
from chebnorm.hw.piecewise import (design_piecewise, piecewise_outputs, shape_cost,
                                   simulate_piecewise)
from chebnorm.hw.plain_table import design_plain_table
from chebnorm.hw.table_run import simulate_table
from chebnorm.hw.targets import fmax_ice40, synthesize_target, target_names
from chebnorm.hw.run_vhdl import simulate_vhdl

#: (label, expression, interval, in_bits, out_bits); the first is the FloPoCo comparison spec's
SPECS = (
    ("1/sqrt(1+3x) [0,1) 16b", "1/sqrt(1+3*x)", ("0", "1"), 16, 16),
    ("2^x [0,1) 12b", "2**x", ("0", "1"), 12, 12),
    ("exp(-x) [0,1) 14b", "exp(-x)", ("0", "1"), 14, 14),
    ("1/sqrt(x) [1,4) 14b", "1/sqrt(x)", ("1", "4"), 14, 14),
    ("sin(pi/2 x) [0,1) 16b", "sin(pi/2*x)", ("0", "1"), 16, 16),
    ("log2(1+x) [0,1) 18b", "log(1+x)/log(2)", ("0", "1"), 18, 18),
    # the normalization unit's 1/sqrt of |N|^2 indexed by exponent (chebnorm.hw.exponent):
    # x = k / 2^W, output a mantissa of W bits and a shift
    ("1/sqrt(x) by exponent [2^-16,1) 16b", "1/sqrt(x)", ("2^-16", "1"), 16, 16),
    ("1/sqrt(x) by exponent [2^-20,1) 20b", "1/sqrt(x)", ("2^-20", "1"), 20, 20),
    ("sin(pi/2 x) [0,1) 20b", "sin(pi/2*x)", ("0", "1"), 20, 20),
    ("log2(1+x) [0,1) 20b", "log(1+x)/log(2)", ("0", "1"), 20, 20),
    ("1/x [1,2) 24b", "1/x", ("1", "2"), 24, 24),
)
ARCHS = ("pw1", "pw1 pipe", "pw2", "pw2 pipe", "multipartite", "plain table")
#: the architectures of a spec when not :data:`ARCHS`: the exponent-indexed ones
#: (``exp1``, ``exp2``: degree-1 and -2 cores, ``pipe``: pipeline="full"); at 20
#: bits the degree-1 piecewise (thousands of segments), the plain table
#: (2^20 x 20 bits, over PLAIN_LIMIT) and the multipartite (not run: its design,
#: synthesis and placement did not fit the time of the run) are left out; at 24 bits every
#: architecture refuses the width (each accepts at most 20 input bits): one row says so
SPEC_ARCHS = {
    "1/sqrt(x) by exponent [2^-16,1) 16b": ("exp1", "exp1 pipe", "exp2", "exp2 pipe"),
    "1/sqrt(x) by exponent [2^-20,1) 20b": ("exp1", "exp2", "exp2 pipe"),
    "sin(pi/2 x) [0,1) 20b": ("pw2", "pw2 pipe"),
    "log2(1+x) [0,1) 20b": ("pw2", "pw2 pipe"),
    "1/x [1,2) 24b": ("pw2",),
}
#: the targets' figure a winner has the lowest of
WIN_KEY = {"generic": "cells", "xc7": "score", "xc7-nodsp": "score", "ice40": "score"}
#: segment counts tried per degree after the first faithful one
SWEEP = 3
PLAIN_LIMIT = 2 ** 20


def _shape(d):
    """The public shape tuple of a sized design (as :func:`sized_bound` takes it)."""
    return (d.local_bits, d.degree, d.table.centered, d.coef_frac, d.t_keep, d.acc_frac,
            d.multipliers == "truncated", d.prod_frac)


def sized_piecewise(expr, interval, in_bits, out_bits, degree, only_k=None):
    """The cheapest faithful sized piecewise design of ``degree`` over a sweep of
    segment counts, by :func:`shape_cost`; (design, sweep notes). ``only_k``:
    rebuild the design a finished row chose (``2^only_k`` segments) without the
    sweep (the greedy is deterministic: the same design)."""
    fc = min(out_bits + 10, 40)
    notes, found = [], []
    for k in (range(1, in_bits - degree - 1) if only_k is None else (only_k,)):
        try:
            t = piecewise_fit(expr, interval, degree, segments=2 ** k, coef_frac_bits=fc,
                              centered=True, name=f"pw{degree}")
            d = design_piecewise(t, in_bits, out_bits, widths="auto", multipliers="truncated")
        except ValueError as e:
            if found:
                notes.append(f"2^{k}: {str(e)[:80]}")
                break
            continue
        cost = shape_cost(t, _shape(d), d.coefficients)
        found.append((cost, k, d))
        notes.append(f"2^{k}: proxy {cost:.0f}")
        if len(found) == SWEEP:
            break
    if not found:
        raise ValueError(f"no faithful degree-{degree} design for 2 .. 2^{in_bits - degree - 2} "
                         f"segments")
    cost, k, d = min(found, key=lambda c: (c[0], c[1]))
    return d, {"segments": 2 ** k, "sweep": notes, "proxy": round(cost, 1)}


def _piecewise_detail(d, info) -> str:
    return f"{info['segments']} seg, F={list(d.coef_frac)}, T={list(d.t_keep)}"


def _piecewise_row(d, info) -> dict:
    m = d.measure()
    lsb = Fraction(1, 2 ** d.y_format.frac_bits)
    return {"detail": _piecewise_detail(d, info), "out_lsb": f"2^-{d.y_format.frac_bits}",
            "sweep": info["sweep"], "bound_ulp": round(d.budget()["total"] / float(lsb), 4),
            "max_error_ulp": round(m["max_error"] / float(lsb), 4), "latency": d.latency,
            "verilog": d_verilog(d), "top": d.module_name, "clocked": d.latency > 0}


def d_verilog(d) -> str:
    from chebnorm.hw.hdl import hdl_text

    return hdl_text(d, "verilog")


def _table_row(d, detail) -> dict:
    m = d.measure()
    lsb = 2.0 ** -d.y_format.frac_bits
    return {"detail": detail, "out_lsb": f"2^-{d.y_format.frac_bits}",
            "bound_ulp": round(m["upper"] / lsb, 4),
            "max_error_ulp": round(m["upper"] / lsb, 4), "latency": 0,
            "verilog": d.verilog(), "top": d.module_name, "clocked": False}


def _exponent_detail(d) -> str:
    c = d.core
    return (f"{c.table.segment_count // 2} seg/binade x 2, F={list(c.coef_frac)}, "
            f"T={list(c.t_keep)}, mantissa {d.mant_bits} + shift {d.shift_bits} b")


def _exponent_row(d) -> dict:
    m = d.measure()
    b = d.budget()
    lsb = 2.0 ** -d.frac_bits
    return {"detail": _exponent_detail(d), "out_lsb": f"mantissa 2^-{d.frac_bits}",
            "bound_ulp": round(b["mantissa"] / lsb, 4),
            "max_error_ulp": round(m["max_error"] / lsb, 4),
            "max_rel_error": m["max_rel_error"], "latency": d.latency,
            "verilog": d.verilog(), "top": d.module_name, "clocked": d.latency > 0}


def build(spec, arch, cache, measure: bool = True):
    """The design of ``arch`` for ``spec`` and its row fields (measured error;
    without ``measure`` only its ``detail`` and ``latency``: no exhaustive error)."""
    _, expr, interval, wi, wo = spec
    if wi > 20:
        raise ValueError(f"in_bits {wi} > 20: design_piecewise, design_multipartite and "
                         f"design_plain_table accept at most 20 input bits (each design is "
                         f"certified and simulated over every input code)")
    if arch.startswith("exp"):
        degree = int(arch[3])
        key = (spec[0], arch)
        if key not in cache:
            if arch.endswith("pipe"):
                d0, _ = build(spec, arch.split()[0], cache)
                cache[key] = design_exponent(expr, interval, wi, wo, degree=degree,
                                             segments=d0.core.table.segment_count // 2,
                                             pipeline="full")
            else:
                cache[key] = design_exponent(expr, interval, wi, wo, degree=degree)
        d = cache[key]
        if not measure:
            return d, {"detail": _exponent_detail(d), "latency": d.latency}
        return d, _exponent_row(d)
    if arch.startswith("pw"):
        degree = int(arch[2])
        key = (spec[0], degree)
        if key not in cache:
            cache[key] = sized_piecewise(expr, interval, wi, wo, degree,
                                         cache.get(("segments",) + key))
        d, info = cache[key]
        if arch.endswith("pipe"):   # the same widths (the greedy ignores the registers)
            p = design_piecewise(d.table, wi, wo, multipliers="truncated", pipeline="full",
                                 widths={"coef_frac": d.coef_frac, "t_keep": d.t_keep,
                                         "acc_frac": d.acc_frac[1:d.degree],
                                         "prod_frac": d.prod_frac})
            if p.acc_frac != d.acc_frac or p.bound != d.bound:   # y's last place moved
                p = design_piecewise(d.table, wi, wo, widths="auto", multipliers="truncated",
                                     pipeline="full")
            d = p
        if not measure:
            return d, {"detail": _piecewise_detail(d, info), "latency": d.latency}
        return d, _piecewise_row(d, info)
    if arch == "multipartite":
        d = design_multipartite(expr, interval, wi, wo)
        return d, _table_row(d, f"split {d.split}, guard {d.guard_bits}, ROM {d.rom_bits} b")
    if 2 ** wi * wo > PLAIN_LIMIT:
        return None, None
    d = design_plain_table(expr, interval, wi, wo)
    return d, _table_row(d, f"ROM {d.rom_bits} b, correctly rounded {d.correctly_rounded}")


def simulate(d, arch, language: str = "verilog", timeout: float = 600) -> str:
    """Run ``d``'s exhaustive bench in Icarus Verilog or GHDL: the PASS/FAIL line
    (``timeout``: seconds per GHDL step of a piecewise design)."""
    with tempfile.TemporaryDirectory() as tmp:
        if arch.startswith("exp"):
            r = simulate_exponent(d, tmp, language)
        elif arch.startswith("pw") and language == "verilog":
            r = simulate_piecewise(d, tmp)
        elif arch.startswith("pw"):
            write_folder(Path(tmp), piecewise_outputs(d, language="vhdl"))
            r = simulate_vhdl(tmp, d, timeout=timeout)
        else:
            r = simulate_table(d, tmp, language)
    if not r.passed:
        raise RuntimeError(f"{language} simulation of {d.module_name} failed: {r.line}")
    return r.line


def winners(results: dict, spec) -> dict:
    """``{arch: [targets it wins]}``: per target the measured row of the lowest figure
    (:data:`WIN_KEY`; ties: the first in the spec's architecture order)."""
    out: dict = {}
    archs = SPEC_ARCHS.get(spec[0], ARCHS)
    for t, key in WIN_KEY.items():
        rows = [(results[f"{spec[0]} | {a}"]["targets"][t][key], i, a)
                for i, a in enumerate(archs)
                if (results.get(f"{spec[0]} | {a}") or {}).get("targets")
                and not results[f"{spec[0]} | {a}"].get("error")]   # not faithful: no winner
        if rows:
            out.setdefault(min(rows)[2], []).append(t)
    return out


def simulate_winners(results: dict, spec, cache, path, doc) -> None:
    """Simulate every winner of ``spec`` (:func:`winners`) over every input code in
    Icarus Verilog and GHDL against the bit-accurate model (rebuilt: the same
    deterministic design), unless its row has both results already."""
    if spec[3] > 20:
        return
    for arch in winners(results, spec):
        row = results[f"{spec[0]} | {arch}"]
        if row.get("simulation") and row.get("simulation_vhdl"):
            continue
        d, again = build(spec, arch, cache)
        if again["detail"] != row["detail"]:   # the row measured another design
            raise RuntimeError(f"{spec[0]} | {arch}: rebuilt as {again['detail']!r}, measured "
                               f"as {row['detail']!r}; delete the row and run again")
        for lang, field in (("verilog", "simulation"), ("vhdl", "simulation_vhdl")):
            if not row.get(field):
                t0 = time.perf_counter()
                row[field] = simulate(d, arch, lang)
                row[f"{field}_seconds"] = round(time.perf_counter() - t0, 1)
                tqdm.write(f"{spec[0]} | {arch}: {row[field]}", file=sys.stderr)
        if path is not None:
            write_atomic(path, json.dumps(doc, indent=1, sort_keys=True) + "\n")


def missing_vhdl(results: dict, specs) -> list:
    """``[(spec, arch)]``: the rows of ``specs`` with an Icarus PASS and no GHDL
    record, the cheapest (fewest input bits) first."""
    rows = []
    for spec in specs:
        for arch in SPEC_ARCHS.get(spec[0], ARCHS):
            r = results.get(f"{spec[0]} | {arch}") or {}
            if "PASS" in (r.get("simulation") or "") and not r.get("simulation_vhdl"):
                rows.append((spec, arch))
    return sorted(rows, key=lambda sa: sa[0][3])


def simulate_missing(doc: dict, specs, path: Path, timeout: float = 3600) -> None:
    """GHDL over every input code for the rows of :func:`missing_vhdl`: each
    design rebuilt (deterministic) and checked to be the row's (``detail``:
    segments, widths, ROM bits; ``latency``), then its VHDL (a pipelined one
    clock by clock) against the bit-accurate model; ``simulation_vhdl`` and
    ``simulation_vhdl_seconds`` written into the row, the file rewritten
    (atomic) after each one and nothing else changed. A mismatch, a rebuilt
    design that differs, or a bench that checked fewer codes raises
    ``RuntimeError`` (nothing recorded for that row)."""
    results = doc["results"]
    cache = _segment_cache(results)
    for spec, arch in missing_vhdl(results, specs):
        key = f"{spec[0]} | {arch}"
        row = results[key]
        d, again = build(spec, arch, cache, measure=False)
        if (again["detail"], again["latency"]) != (row["detail"], row["latency"]):
            raise RuntimeError(f"{key}: rebuilt as {again['detail']!r} (latency "
                               f"{again['latency']}), measured as {row['detail']!r} (latency "
                               f"{row['latency']}): not the same design")
        t0 = time.perf_counter()
        line = simulate(d, arch, "vhdl", timeout=timeout)
        seconds = round(time.perf_counter() - t0, 1)
        if not line.startswith(f"PASS: {2 ** spec[3]} vectors, 0 mismatches"):
            raise RuntimeError(f"{key}: GHDL did not check all {2 ** spec[3]} codes: {line}")
        row["simulation_vhdl"], row["simulation_vhdl_seconds"] = line, seconds
        write_atomic(path, json.dumps(doc, indent=1, sort_keys=True) + "\n")
        tqdm.write(f"{key}: {line} in {seconds} s", file=sys.stderr)


def _segment_cache(results: dict) -> dict:
    """A build cache holding each finished piecewise row's segment count (no sweep again)."""
    cache: dict = {}
    for key, r in results.items():
        label, _, arch = key.rpartition(" | ")
        if arch in ("pw1", "pw2") and r and r.get("detail", "").split(" seg")[0].isdigit():
            cache[("segments", label, int(arch[2]))] = int(r["detail"].split(" seg")[0]).bit_length() - 1
    return cache


def measure_row(spec, arch, cache, sim: bool) -> dict | None:
    t0 = time.perf_counter()
    d, row = build(spec, arch, cache)
    if d is None:
        return None
    if row["max_error_ulp"] >= 1:
        row["error"] = f"not faithful: measured {row['max_error_ulp']} ulp"
    if sim:
        row["simulation"] = simulate(d, arch)
    text, top = row.pop("verilog"), row.pop("top")
    row["targets"] = {t: synthesize_target(text, top, t, timing=t == "xc7").as_dict()
                      for t in target_names()}
    for c in row["targets"].values():
        c.pop("by_type", None)
    ns = row["targets"]["xc7"].get("delay_ns")
    row["fmax_xc7_model_mhz"] = round(1000.0 / ns, 1) if ns else None
    try:
        row["fmax_ice40_mhz"] = round(fmax_ice40(text, top, clocked=row.pop("clocked")), 2)
    except ValueError as e:   # e.g. a ROM needing more RAM blocks than the HX8K has
        row["fmax_ice40_mhz"] = None
        row["fmax_error"] = " ".join(str(e).split())[:400]
    row["seconds"] = round(time.perf_counter() - t0, 1)
    return row


def _ram(cost: dict) -> str:
    return f" + {cost['brams']} RAM" if cost.get("brams") else ""


def _fmax(r: dict) -> str:
    if r.get("fmax_ice40_mhz") is not None:
        return f"{r['fmax_ice40_mhz']:.1f}"
    err = r.get("fmax_error", "")
    return "does not fit HX8K" if "no BELs remaining" in err else "failed (JSON)"


def _cell(v, fmt: str = "{:.1f}") -> str:
    return "n/m" if v is None else fmt.format(v)


def _wins(r: dict, targets) -> str:
    if not targets:
        return ""
    sims = [lang for lang, f in (("Icarus", "simulation"), ("GHDL", "simulation_vhdl"))
            if "PASS" in (r.get(f) or "")]
    sim = f"{' + '.join(sims)} PASS" if sims else "not simulated"
    return f"**{', '.join(targets)}** ({sim})"


def markdown(results: dict, specs) -> str:
    head = ("| spec | architecture | out LSB | generic cells | xc7 LUT+DSP | xc7 Fmax MHz (model) "
            "| xc7-nodsp LUT | ice40 LUT4 | ice40 Fmax MHz | latency | certified / ulp "
            "| max error / ulp | wins on (exhaustive simulation) |")
    lines = [head, "|" + "---|" * 13]
    for spec in specs:
        won = {a: ts for a, ts in winners(results, spec).items()}
        for arch in SPEC_ARCHS.get(spec[0], ARCHS):
            r = results.get(f"{spec[0]} | {arch}")
            if r is None:
                continue
            if "targets" not in r:
                what = "not run" if r.get("error", "").startswith("in_bits") else "failed"
                lines.append(f"| {spec[0]} | {arch} |  | {what}: {r.get('error', '?')[:170]} "
                             f"|" + " |" * 10)
                continue
            t = r["targets"]
            name = f"{arch} ({r['detail']})"
            lines.append(
                f"| {spec[0]} | {name} | {r.get('out_lsb', '?')} | {t['generic']['cells']} | "
                f"{t['xc7']['luts']} + "
                f"{t['xc7']['dsps']}{_ram(t['xc7'])} | {_cell(r.get('fmax_xc7_model_mhz'))} | "
                f"{t['xc7-nodsp']['luts']}{_ram(t['xc7-nodsp'])} | "
                f"{t['ice40']['luts']}{_ram(t['ice40'])} | {_fmax(r)} | {r['latency']} | "
                f"{_cell(r.get('bound_ulp'), '{:.3f}')} | {r['max_error_ulp']:.3f} | "
                f"{_wins(r, won.get(arch))} |")
    return "\n".join(lines)


def _versions() -> dict:
    out = {}
    for tool, arg in (("yosys", "-V"), ("nextpnr-ice40", "--version"), ("iverilog", "-V")):
        try:
            p = subprocess.run([tool, arg], capture_output=True, text=True, timeout=30,
                               stdin=subprocess.DEVNULL)
            out[tool] = (p.stdout + p.stderr).strip().splitlines()[0]
        except (OSError, IndexError, subprocess.SubprocessError):
            out[tool] = "unavailable"
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="only the first spec (1/sqrt(1+3x) on [0, 1), 16 bits)")
    ap.add_argument("--json", help="keep the rows here (and reuse those already there)")
    ap.add_argument("--no-sim", action="store_true",
                    help="skip the winners' Icarus and GHDL simulations")
    ap.add_argument("--spec", type=int, action="append", choices=range(len(SPECS)),
                    help="run only these specs (indexes into SPECS; repeatable)")
    ap.add_argument("--sim-missing", action="store_true",
                    help="only GHDL for the --json rows with an Icarus PASS and no GHDL "
                         "record (rebuilt, checked to be the same design)")
    args = ap.parse_args(argv)
    specs = SPECS[:1] if args.quick else SPECS
    if args.spec:
        specs = tuple(SPECS[i] for i in sorted(set(args.spec)))
    path = Path(args.json) if args.json else None
    doc = {"results": {}}
    if path is not None and path.exists():
        doc = json.loads(path.read_text(encoding="utf-8"))
    if args.sim_missing:
        if path is None or not path.exists():
            ap.error("--sim-missing needs --json PATH of an existing results file")
        try:
            simulate_missing(doc, specs, path)
        except (ValueError, RuntimeError, OSError, subprocess.SubprocessError) as e:
            print(f"bench_specs: {' '.join(str(e).split())[:400]}", file=sys.stderr)
            return 1
        return 0
    results = doc.setdefault("results", {})
    doc["versions"] = _versions()
    cache = _segment_cache(results)
    jobs = [(s, a) for s in specs for a in SPEC_ARCHS.get(s[0], ARCHS)]
    bar = tqdm(jobs, file=sys.stderr, desc="bench_specs")
    for n, (spec, arch) in enumerate(bar):
        key = f"{spec[0]} | {arch}"
        bar.set_postfix_str(key)
        if not (key in results and (results[key] is None or "targets" in results[key])):
            t0 = time.perf_counter()
            try:
                row = measure_row(spec, arch, cache, False)
            except (ValueError, RuntimeError, OSError, subprocess.SubprocessError) as e:
                row = {"error": " ".join(str(e).split())[:300],
                       "seconds": round(time.perf_counter() - t0, 1)}
            results[key] = row
            tqdm.write(f"{key}: {json.dumps(row, sort_keys=True)[:400]}", file=sys.stderr)
            if path is not None:
                doc["load"] = os.getloadavg()
                write_atomic(path, json.dumps(doc, indent=1, sort_keys=True) + "\n")
        last = n + 1 == len(jobs) or jobs[n + 1][0] is not spec
        if last and not args.no_sim:   # the spec's rows done: its winners simulated
            try:
                simulate_winners(results, spec, cache, path, doc)
            except (ValueError, RuntimeError, OSError, subprocess.SubprocessError) as e:
                tqdm.write(f"{spec[0]}: winner simulation failed: {e}", file=sys.stderr)
    print(markdown(results, specs))
    print(f"\n{doc['versions']}; load {tuple(round(v, 2) for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
