"""benchmarks/bench_specs.py's ``--sim-missing``: which rows it picks, that it
refuses a rebuilt design that differs from the measured row and a bench that
did not check every code, and that a pass writes only the two GHDL fields."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCH))
import bench_specs  # noqa: E402

SPEC = bench_specs.SPECS[1]   # 2^x [0,1) 12b: the cheapest
KEY = f"{SPEC[0]} | pw2 pipe"


def _doc(detail: str = "8 seg, F=[15, 14, 13], T=[9, 6]") -> dict:
    """A results file with the 12-bit spec's pw2 row (its segment count) and a
    pw2 pipe row with an Icarus PASS and no GHDL record."""
    return {"load": [1.0], "versions": {"ghdl": "x"}, "results": {
        f"{SPEC[0]} | pw2": {"detail": "8 seg, F=[15, 14, 13], T=[9, 6]", "latency": 0},
        KEY: {"detail": detail, "latency": 3, "seconds": 1.0,
              "simulation": "PASS: 4096 vectors, 0 mismatches (chebnorm_pw2, latency 3)"}}}


def _write(path: Path, doc: dict) -> bytes:
    path.write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return path.read_bytes()


def test_missing_vhdl_picks_icarus_pass_without_ghdl_cheapest_first():
    res = {f"{bench_specs.SPECS[0][0]} | pw2 pipe": {"simulation": "PASS: 1"},
           KEY: {"simulation": "PASS: 2"},
           f"{SPEC[0]} | pw1": {"simulation": "PASS: 3", "simulation_vhdl": "PASS: 3"},
           f"{SPEC[0]} | pw2": {"simulation": "FAIL: 4"},
           f"{SPEC[0]} | multipartite": {},
           f"{SPEC[0]} | plain table": None}
    got = [(s[0], a) for s, a in bench_specs.missing_vhdl(res, bench_specs.SPECS)]
    assert got == [(SPEC[0], "pw2 pipe"), (bench_specs.SPECS[0][0], "pw2 pipe")]


def test_a_rebuilt_design_that_differs_is_refused(tmp_path):
    path = tmp_path / "r.json"
    before = _write(path, _doc(detail="8 seg, F=[15, 14, 14], T=[9, 6]"))
    with pytest.raises(RuntimeError, match="not the same design"):
        bench_specs.simulate_missing(json.loads(before), [SPEC], path)
    assert path.read_bytes() == before


def test_a_bench_short_of_codes_is_not_recorded(tmp_path, monkeypatch):
    path = tmp_path / "r.json"
    before = _write(path, _doc())
    monkeypatch.setattr(bench_specs, "simulate",
                        lambda *a, **k: "PASS: 4095 vectors, 0 mismatches (chebnorm_pw2)")
    with pytest.raises(RuntimeError, match="did not check all 4096 codes"):
        bench_specs.simulate_missing(json.loads(before), [SPEC], path)
    assert path.read_bytes() == before


@pytest.mark.requires_tool("ghdl")
def test_a_pass_writes_only_the_two_ghdl_fields(tmp_path):
    path = tmp_path / "r.json"
    doc = _doc()
    _write(path, doc)
    bench_specs.simulate_missing(json.loads(path.read_text()), [SPEC], path)
    text = path.read_text(encoding="utf-8")
    after = json.loads(text)
    assert text == json.dumps(after, indent=1, sort_keys=True) + "\n"   # the file's format
    row = after["results"][KEY]
    assert row.pop("simulation_vhdl") == "PASS: 4096 vectors, 0 mismatches (chebnorm_pw2)"
    assert row.pop("simulation_vhdl_seconds") >= 0
    assert after == doc
