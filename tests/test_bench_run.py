"""benchmarks/run.py's verdict logic and the results.json shape the claims
ledger reads (no timing: the verdict functions are fed made-up figures)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCH))
import run as bench_run  # noqa: E402

VERDICTS = {"reproduced", "not reproduced", "reproduced with a stated condition", "not checkable"}


def _s(x):
    return {"median": x, "q25": x, "q75": x, "min": x, "max": x}


def _timing(speed):
    """Fake timings: every kernel ``speed`` x faster than classic on every workload."""
    kernels = {}
    for w in ["mesh", "triangles"] + [f"length_{n}" for n in bench_run.LENGTHS]:
        kernels[w] = {k: {"ns_per_pixel": 1.0, "speedup_vs_classic": _s(speed)}
                      for k in ("classic", "none", "sse_rsqrt", "dichotomy", "quadratic", "angular")}
        kernels[w]["angular"]["speedup_vs_angular_direct"] = _s(speed)
    kernels["mesh"]["midpoint_poly"] = {"ns_per_pixel": 1.0,
                                        "speedup_vs_midpoint_classic": _s(speed)}
    kernels["mesh"]["bump"] = {"ns_per_pixel": 1.0, "time_over_phong_nlh": _s(1.0),
                               "time_over_phong_n": _s(1.8)}
    return kernels


@pytest.mark.parametrize("speed, expected", [(3.0, "reproduced"), (1.0, "not reproduced")])
def test_speed_verdicts(speed, expected):
    timing = {c: {"kernels": _timing(speed)} for c in ("O2", "O3-native")}
    v = bench_run.verdicts(timing, bench_run.hardware_costs())
    assert set(v) == {"C6", "C7", "C8", "C13"}
    for cid in ("C6", "C7", "C8"):
        assert v[cid]["verdict"] == expected, (cid, v[cid])
    for d in v.values():
        assert set(d) == {"verdict", "measured", "why"} and d["verdict"] in VERDICTS
        assert d["measured"] and d["why"]


def test_mixed_configs_give_a_condition():
    timing = {"O2": {"kernels": _timing(1.0)}, "O3-native": {"kernels": _timing(3.0)}}
    v = bench_run.verdicts(timing, bench_run.hardware_costs())
    assert v["C6"]["verdict"] == "reproduced with a stated condition"
    assert "O3-native" in v["C6"]["why"]


def test_no_compiler_leaves_only_the_hardware_half():
    v = bench_run.verdicts({}, bench_run.hardware_costs())
    assert {v[c]["verdict"] for c in ("C6", "C7", "C8")} == {"not checkable"}
    assert v["C13"]["verdict"] == "reproduced with a stated condition"
    assert "gcc missing" in v["C13"]["why"]


def test_hardware_bump_adds_only_a_multiplexer():
    hw = bench_run.hardware_costs()
    assert hw["extra"]["only_mux"] and hw["extra"]["latency"] == 0
    assert hw["bump"]["latency"] == hw["phong"]["latency"]
