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


def test_one_compiler_alone_does_not_settle_a_claim():
    """gcc reaches the claim everywhere, clang nowhere: not reproduced, and said so."""
    timing = {}
    for c in ("O2", "O3-native"):
        timing[c] = {"kernels": _timing(3.0)}
        timing[f"clang {c}"] = {"kernels": _timing(1.0)}
    v = bench_run.verdicts(timing, bench_run.hardware_costs())
    for cid in ("C6", "C7", "C8"):
        assert v[cid]["verdict"] == "not reproduced", (cid, v[cid])
        assert "compiler artifact" in v[cid]["why"]
        assert "gcc 3.00x" in v[cid]["measured"] and "clang 1.00x" in v[cid]["measured"]


def test_a_condition_needs_both_compilers():
    timing = {"O2": {"kernels": _timing(1.0)}, "clang O2": {"kernels": _timing(1.0)},
              "O3-native": {"kernels": _timing(3.0)}, "clang O3-native": {"kernels": _timing(2.9)}}
    v = bench_run.verdicts(timing, bench_run.hardware_costs())
    assert v["C6"]["verdict"] == "reproduced with a stated condition"
    assert "holds only with O3-native" in v["C6"]["why"]


def test_config_keys_split_compiler_and_configuration():
    assert bench_run._split("clang O3-native-no-errno") == ("clang", "O3-native-no-errno")
    assert bench_run._split("AVX2") == ("gcc", "AVX2")
    keys = ["clang AVX2", "O2", "AVX2", "clang O2", "O3-native"]
    assert bench_run._config_keys(dict.fromkeys(keys)) == ["O2", "clang O2", "O3-native", "AVX2",
                                                           "clang AVX2"]


def test_summary_ratios_are_taken_per_repeat_and_against_the_floor():
    per = {"classic": [4.0, 8.0], "dichotomy": [2.0, 8.0], "store_floor": [0.5, 1.0]}
    wall = {k: [2 * x for x in v] for k, v in per.items()}
    out = bench_run._summarize(per, wall)
    assert "store_floor" not in out
    d = out["dichotomy"]
    # ratios per repeat: 4/2 = 2 and 8/8 = 1 (not the ratio of medians, 6/5)
    assert d["speedup_vs_classic"]["min"] == 1.0 and d["speedup_vs_classic"]["max"] == 2.0
    assert d["ns_per_pixel_min"] == 2.0 and d["ns_per_pixel_median"] == 5.0
    assert d["wall_ns_per_pixel_min"] == 4.0
    assert d["over_floor"] == 2.0 / 0.5
    fl = bench_run._floor(per, wall, floor_bytes=1200, pixels=100)
    assert fl["bytes_per_pixel"] == 12.0 and fl["store_bandwidth_gb_s"] == 12.0 / 0.5


def test_verdict_changes_name_what_moved(tmp_path):
    old = tmp_path / "results.json"
    old.write_text('{"verdicts": {"C6": {"verdict": "not reproduced"}, "C8": {"verdict": "reproduced"}}}')
    new = {"C6": {"verdict": "reproduced with a stated condition"}, "C8": {"verdict": "reproduced"},
           "C7": {"verdict": "not reproduced"}}
    lines = bench_run.verdict_changes(old, new)
    assert lines[0].startswith("C6: not reproduced -> reproduced with a stated condition")
    assert lines[1].startswith("C8: verdict unchanged")
    assert len(lines) == 2
    assert bench_run.verdict_changes(tmp_path / "missing.json", new) == []


def test_c8_reports_other_frame_sizes():
    kernels = _timing(2.0)
    kernels["frame_2048"] = {"angular": {"ns_per_pixel": 1.0, "speedup_vs_classic": _s(1.0),
                                         "speedup_vs_angular_direct": _s(2.5)}}
    v = bench_run.verdicts({"O2": {"kernels": kernels}}, bench_run.hardware_costs())
    assert "2048x2048 frame: O2 2.50x" in v["C8"]["why"]


def test_verdict_changes_name_a_changed_condition(tmp_path):
    old = tmp_path / "results.json"
    old.write_text('{"verdicts": {"C8": {"verdict": "reproduced with a stated condition", '
                   '"why": "holds only with O3-native. more"}}}')
    new = {"C8": {"verdict": "reproduced with a stated condition", "why": "holds on big frames. x"}}
    (line,) = bench_run.verdict_changes(old, new)
    assert "condition was: holds only with O3-native; now: holds on big frames" in line


def test_rerender_settles_from_the_measurements_alone(tmp_path):
    """--from-json: the verdicts come from the stored timings, no timing run."""
    res = {"configs": {"O2": {"kernels": _timing(3.0), "command": "gcc -O2", "rounds": 5}},
           "accuracy": {}, "quick": False,
           "hardware": bench_run.hardware_costs(), "skipped": [], "seconds": 1.0,
           "machine": {"cpu": "x", "cores": 2}, "fit_vs_sollya": {"skipped": "t"},
           "raster": {"skipped": "t"}, "main_job": {"skipped": "t"},
           "workloads": {w: {"description": w, "spans": 1, "pixels": 1, "m_min": 1, "m_max": 1,
                             "m_median": 1.0, "psi_deg": {"p10": 1, "p50": 1, "p90": 1, "max": 1}}
                         for w in ["mesh", "triangles"] + [f"length_{n}" for n in bench_run.LENGTHS]}}
    src = tmp_path / "in.json"
    src.write_text(bench_run.json.dumps(res))
    out = bench_run.rerender(src, tmp_path)
    assert out["verdicts"]["C6"]["verdict"] == "reproduced"
    assert (tmp_path / "RESULTS.md").read_text().startswith("# Benchmark results")
    assert bench_run.json.loads((tmp_path / "results.json").read_text())["verdicts"]["C8"]


def test_cpu_description_names_family_model_and_simd():
    import doctest

    import machine

    assert doctest.testmod(machine).failed == 0
    text = "model name\t: Some CPU\ncpu family\t: 25\nmodel\t\t: 17\nflags\t\t: fpu avx2 fma\n\n" \
           "model name\t: Some CPU\ncpu family\t: 25\nmodel\t\t: 17\nflags\t\t: fpu avx2 avx512f\n"
    assert machine.cpu_description(text) == "Some CPU (family 25, model 17; AVX2)"  # the first CPU's
