"""The benchmarks page (docs/benchmarks.md) shows only figures of the committed
result files of ``benchmarks/``: its tables are printed at build time by
``docs/_benchtables.py``, and here every cell of every table is read back and
compared with the JSON, read independently (a number equals the JSON's value to
half a unit of its last printed digit); the page's own prose types no figure."""

from __future__ import annotations

import importlib.util
import json
import re
from decimal import Decimal
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BENCH = ROOT / "benchmarks"


def _tables_module():
    spec = importlib.util.spec_from_file_location("_benchtables", ROOT / "docs" / "_benchtables.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def tables():
    return _tables_module()


def _json(name: str) -> dict:
    return json.loads((BENCH / name).read_text(encoding="utf-8"))


def _unescape(text: str) -> str:
    return re.sub(r"\\(.)", r"\1", text).strip()


def parse(markdown: str) -> list[dict[str, str]]:
    """The rows of the (first) Markdown table of ``markdown``, as header -> cell text
    (escapes and code backticks removed)."""
    lines = [line for line in markdown.splitlines() if line.startswith("|")]
    assert len(lines) >= 3 and set(lines[1]) <= set("|-"), markdown[:300]

    def cells(line):
        return [_unescape(c).strip("`") for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]

    header = cells(lines[0])
    rows = []
    for line in lines[2:]:
        row = cells(line)
        # a renderer ignores cells beyond the header's: only empty ones are allowed
        assert len(row) >= len(header) and not any(row[len(header):]), line
        rows.append(dict(zip(header, row)))
    return rows


def same(printed: str, value) -> bool:
    """``printed`` is ``value`` rounded to the digits it shows (within half a unit of its
    last digit; an integer exactly), with at least two significant digits unless the
    value is an integer."""
    if value is None:
        return printed == "-"
    d = Decimal(printed)
    if isinstance(value, int) or float(value).is_integer() and "." not in printed and "e" not in printed:
        return d == Decimal(value)
    sign, digits, exponent = d.as_tuple()
    if len(digits) < 2 and float(d) != float(value):
        return False
    return abs(float(d) - float(value)) <= 0.5 * 10.0 ** exponent * (1 + 1e-12)


def test_parse_and_same_reject_what_they_should():
    rows = parse("| a | b |\n|---|---|\n| `x\\_y` | 1.5 (2x) |\n")
    assert rows == [{"a": "x_y", "b": "1.5 (2x)"}]
    assert same("2.26", 2.2614) and not same("2.26", 2.2662) and not same("2.2", 2.26)
    assert same("5.3e-08", 5.2979e-08) and not same("5.3e-08", 5.36e-08)
    assert same("18", 18) and not same("18", 19) and same("-", None) and not same("0", None)


def _pair(cell: str) -> tuple[str, str | None]:
    """``"2.26 (0.813x)"`` -> ``("2.26", "0.813")``; ``"2.17"`` -> ``("2.17", None)``."""
    m = re.fullmatch(r"(\S+)(?: \((\S+)x\))?", cell)
    assert m, cell
    return m.group(1), m.group(2)


@pytest.mark.parametrize("compiler", ["gcc", "clang"])
def test_kernel_table_is_results_json(tables, compiler):
    doc = _json("results.json")
    text = tables.TABLES[f"kernels_{compiler}"]()
    rows = parse(text)
    configs = [c for c in rows[0] if c != "method"]
    assert set(configs) == {c for c, v in doc["configs"].items() if v["compiler"] == compiler}
    methods = {m for c in configs for m in doc["configs"][c]["kernels"]["mesh"]}
    assert {r["method"] for r in rows} == methods | {"store floor"}
    for r in rows:
        for c in configs:
            if r["method"] == "store floor":
                assert same(r[c], doc["configs"][c]["floor"]["mesh"]["ns_per_pixel_median"]), (c, r[c])
                continue
            k = doc["configs"][c]["kernels"]["mesh"].get(r["method"])
            if k is None:
                assert r[c] == "-", (r["method"], c)
                continue
            ns, speedup = _pair(r[c])
            assert same(ns, k["ns_per_pixel_median"]), (r["method"], c, r[c])
            if "speedup_vs_classic" in k:
                assert same(speedup, k["speedup_vs_classic"]["median"]), (r["method"], c, r[c])
            else:
                assert speedup is None
    m = doc["machine"]
    assert (m["cpu"] in text and f"{m['cores']} cores" in text) == (compiler == "gcc")


def test_span_table_is_results_json(tables):
    k = _json("results.json")["configs"]["O2"]["kernels"]
    rows = parse(tables.span_lengths())
    sets = [s for s in rows[0] if s != "method"]
    assert sets and all(s in k for s in sets)
    assert {r["method"] for r in rows} == {m for m in k["mesh"] if "speedup_vs_classic" in k["mesh"][m]}
    for r in rows:
        for s in sets:
            e = k[s].get(r["method"])
            assert same(r[s], None if e is None else e["speedup_vs_classic"]["median"]), (r["method"], s)


FIT_COLUMNS = {"tightness": "tightness", "cases": "cases",
               "chebnorm fit + certify (s)": "chebnorm_fit_and_certify_s",
               "Sollya remez + supnorm (s)": "sollya_remez_and_supnorm_s",
               "speed-up": "fit_and_certify_speedup", "certify alone: speed-up": "certify_speedup",
               "chebnorm: worst bound/max - 1": "chebnorm_worst_bound_over_max",
               "Sollya: worst upper/lower - 1": "sollya_worst_upper_over_lower"}
PIECEWISE_COLUMNS = {"tightness": "tightness", "chebnorm batched (s)": "chebnorm_certify_s",
                     "chebnorm one segment at a time (s)": "chebnorm_per_segment_certify_s",
                     "Sollya supnorm (s)": "sollya_supnorm_s", "speed-up": "certify_speedup",
                     "chebnorm bound": "chebnorm_bound", "Sollya bound": "sollya_bound"}


@pytest.mark.parametrize(("name", "columns", "key"), [("fit", FIT_COLUMNS, "cases"),
                                                      ("piecewise", PIECEWISE_COLUMNS, "workload")])
def test_sollya_tables_are_results_json(tables, name, columns, key):
    expected = [r for r in _json("results.json")["fit_vs_sollya"]["rows"] if key in r]
    rows = parse(getattr(tables, name)())
    assert len(rows) == len(expected) >= 2
    for r, e in zip(rows, expected, strict=True):
        assert set(columns) <= set(r)
        for header, field in columns.items():
            assert same(r[header], e[field]), (name, header, r[header], e[field])
        if key == "workload":
            assert r["workload"] == e["workload"]


def test_quantize_table_is_results_json(tables):
    q = _json("results.json")["quantize_vs_sollya"]
    (r,) = parse(tables.quantize())
    assert r["workload"] == q["workload"] and same(r["cases"], len(q["cases"]))
    for header, field in {"chebnorm (s)": "chebnorm_total_s", "Sollya (s)": "sollya_total_s",
                          "total speed-up": "total_speedup", "median speed-up": "median_speedup"}.items():
        assert same(r[header], q[field]), header
    at_or_below = [c for c in q["cases"] if c["sollya_bound"] is not None
                   and c["chebnorm_bound"] <= c["sollya_bound"]]
    assert same(r["cases with a bound at or below Sollya's"], len(at_or_below))
    assert same(r["Sollya failed"], len(q["sollya_failed"]))


def test_raster_table_is_results_json(tables):
    ra = _json("results.json")["raster"]
    rows = parse(tables.raster())
    assert len(rows) == len(ra["modes"])
    by_key = {(m["mode"], m["method"]): m for m in ra["modes"]}
    for r in rows:
        m = by_key[(r["mode"], None if r["method"] == "-" else r["method"])]
        for header, field in {"numba Mfrag/s (wall)": "numba_mfrag_per_s",
                              "numba Mfrag/s (CPU)": "numba_mfrag_per_cpu_s",
                              "numpy Mfrag/s (wall)": "numpy_mfrag_per_s", "numba / numpy": "speedup"}.items():
            assert same(r[header], m[field]), (r["mode"], r["method"], header)
    assert f"{ra['modes'][0]['fragments']} fragments" in tables.raster()


def test_design_target_table_is_the_json(tables):
    doc = _json("design_targets_results.json")
    rows = parse(tables.design_targets())
    assert [r["target"] for r in rows] == [r["target"] for r in doc["results"]]
    for r, e in zip(rows, doc["results"], strict=True):
        wall, cpu = re.fullmatch(r"(\d+) s / (\d+) s", r["wall / CPU time"]).groups()
        assert (int(wall), int(cpu)) == (round(e["wall_s"]), round(e["cpu_s"]))


def test_spec_table_is_the_json(tables):
    results = _json("specs_results.json")["results"]
    rows = parse(tables.specs())
    assert len(rows) >= 20
    for r in rows:
        arch = r["architecture"].split(" (")[0]
        e = results[f"{r['spec']} | {arch}"]
        if "targets" not in e:
            continue
        assert int(r["generic cells"]) == e["targets"]["generic"]["cells"]
        assert r["ice40 LUT4"].split(" ")[0] == str(e["targets"]["ice40"]["luts"])
        assert same(r["max error / ulp"], e["max_error_ulp"]) and int(r["latency"]) == e["latency"]


def test_page_includes_every_table_and_types_no_figure(tables):
    """Every table is included; outside code, commands and the included tables the
    page has no number (a claim's name, C6, is no figure)."""
    page = (ROOT / "docs" / "benchmarks.md").read_text(encoding="utf-8")
    included = re.findall(r"^```\{include\} _bench/(\w+)\.md\n```$", page, re.M)
    assert sorted(included) == sorted(tables.TABLES)
    prose = re.sub(r"^```.*?^```$", "", page, flags=re.M | re.S)   # fenced blocks
    prose = re.sub(r"`[^`]*`", "", prose)                            # code spans
    prose = re.sub(r"\]\([^)]*\)", "]", prose)                       # link targets
    figures = re.findall(r"\b\d[\d.,]*", prose)
    assert figures == [], figures
