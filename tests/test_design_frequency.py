"""``chebnorm design --frequency``: pipelining the winner to a clock (issue 28).

The Fmax figures come from nextpnr-ice40 (place and route, seed 1) and are
checked against the asked frequency and against an independent nextpnr run
of the written RTL; the pipelined RTL is checked by a cycle-accurate
Icarus Verilog bench over every input code, and that bench is shown to catch
a wrong latency (a mutation). Tests needing yosys/nextpnr-ice40/iverilog skip
with the reason when the tool is absent.
"""

from __future__ import annotations

import re
import warnings

import pytest

from chebnorm.hw.pipeline import (FrequencyWarning, PipelinedTable, check_frequency, cut_names,
                                  cut_plans, design_files, pipeline_to_frequency,
                                  verify_pipelined, with_cuts)
from conftest import requires_tool, run_cli
from quiet_cli import run_cli_quiet

SPEC = ["1/sqrt(1+3*x)", "--interval", "0", "1", "--in-bits", "10", "--out-bits", "10",
        "--faithful", "--target", "ice40"]

need_iverilog = requires_tool("iverilog")
need_pnr = requires_tool("nextpnr-ice40", "yosys")


@pytest.fixture(scope="module")
def multipartite():
    from chebnorm.hw.multipartite import design_multipartite

    return design_multipartite("1/sqrt(1+3*x)", ("0", "1"), 10, 10, faithful=True)


@pytest.fixture(scope="module")
def sized():
    from chebnorm.approx.piecewise_fit import piecewise_fit
    from chebnorm.hw.piecewise import design_piecewise

    t = piecewise_fit("1/sqrt(1+3*x)", ("0", "1"), 2, segments=16, coef_frac_bits=20,
                      centered=True, name="fq")
    return design_piecewise(t, 10, 10, widths="auto", multipliers="truncated")


# -- bad input ------------------------------------------------------------------------

@pytest.mark.parametrize("value", ["0", "-5", "nan", "inf", "fast", "-0"])
def test_bad_frequency_exits_2_with_one_line(tmp_path, value):
    out = tmp_path / "o"
    r = run_cli_quiet("design", *SPEC, "--frequency", value, "-o", out)
    assert r.code == 2, r.err
    lines = r.err.strip().splitlines()
    assert len(lines) == 1 and "--frequency" in lines[0] and "MHz > 0" in lines[0], r.err
    assert not out.exists()  # refused before the search: nothing written


def test_frequency_needs_a_device(tmp_path):
    r = run_cli_quiet("design", *SPEC[:-1], "generic", "--frequency", "50", "-o", tmp_path / "o")
    assert r.code == 2
    assert r.err.count("\n") == 1 and "ice40, xc7 or xc7-nodsp" in r.err


@pytest.mark.parametrize("value", [0, -1.0, float("nan"), float("inf"), "x", None, True])
def test_check_frequency_names_the_argument(value):
    with pytest.raises(ValueError, match=r"^frequency_mhz .*accepted: a finite number of MHz"):
        check_frequency(value, "frequency_mhz")


def test_pipeline_refuses_generic(multipartite):
    with pytest.raises(ValueError, match="no device and no clock"):
        pipeline_to_frequency(multipartite, "generic", 100)


# -- cut points -----------------------------------------------------------------------

def test_cut_plans(sized, multipartite):
    n = sized.degree
    plans = cut_plans(sized)
    assert [len(c) for c in plans] == list(range(1, 2 * n + 2))  # one plan per latency
    assert plans[-1] == tuple(range(2 * n + 1))                  # every boundary at the end
    assert cut_names(sized, plans[-1]) == ["rom", "mul1", "add1", "mul2", "add2"]
    assert cut_plans(multipartite) == [(0,), (0, 1)]
    d = with_cuts(sized, (3, 0, 2))
    assert (d.cuts, d.mult_cuts, d.latency) == ((0, 1), (2,), 3)
    assert (d.evaluate() == sized.evaluate()).all()
    with pytest.raises(ValueError, match="accepted: integers 0..4"):
        with_cuts(sized, (5,))
    with pytest.raises(ValueError, match="accepted: a multipartite"):
        with_cuts(multipartite, (2,))


# -- the cycle-accurate check, and a mutation it must catch ----------------------------

@need_iverilog
@pytest.mark.parametrize("kind", ["sized", "multipartite"])
def test_cycle_accurate_simulation_catches_a_wrong_latency(kind, sized, multipartite):
    base = sized if kind == "sized" else multipartite
    plan = cut_plans(base)[-1]
    full = with_cuts(base, plan)
    ok = verify_pipelined(full)
    assert full.latency == len(plan) and (full.evaluate() == base.evaluate()).all()
    assert ok.passed and ok.vectors == 2 ** base.in_bits and ok.mismatches == 0, ok.line
    # the bench of a design with fewer registers: same module name and model, wrong latency
    shorter = with_cuts(base, plan[:-1])
    for wrong in (shorter, with_cuts(base, plan[:1])):
        bad = verify_pipelined(full, bench_design=wrong)
        assert not bad.passed and bad.mismatches > 0, bad.line
    # a wrong module (registers the bench does not expect) against the right bench
    bad = verify_pipelined(shorter, bench_design=full)
    assert not bad.passed and bad.mismatches > 0, bad.line


@pytest.mark.requires_tool("ghdl")
@pytest.mark.parametrize("kind", ["sized", "multipartite"])
def test_pipelined_vhdl_cycle_accurate(tmp_path, kind, sized, multipartite):
    from chebnorm.hw.run_vhdl import simulate_vhdl

    base = sized if kind == "sized" else multipartite
    for plan in cut_plans(base)[::2]:  # every other latency, the full plan among them
        d = with_cuts(base, plan)
        folder = tmp_path / "_".join(map(str, plan))
        folder.mkdir()
        for name, text in design_files(d, "vhdl").items():
            (folder / name).write_text(text, encoding="utf-8")
        res = simulate_vhdl(folder, d)
        assert res.passed and res.vectors == 2 ** base.in_bits, (plan, res.line)


# -- nextpnr-ice40: low, reachable with cuts, impossible --------------------------------

@need_pnr
def test_low_frequency_is_met_combinationally(multipartite):
    with warnings.catch_warnings():
        warnings.simplefilter("error", FrequencyWarning)
        res = pipeline_to_frequency(multipartite, "ice40", 5)
    assert res.met and res.latency == 0 and len(res.steps) == 1
    assert res.fmax_mhz >= 5 and res.extra_ffs == 0 and res.design is multipartite
    assert "nextpnr-ice40" in res.source and res.shortfall() == ""


@need_pnr
def test_impossible_frequency_warns_with_the_highest(multipartite):
    with pytest.warns(FrequencyWarning, match=r"2000 MHz not reached: the highest is "
                      r"\d+\.\d\d MHz at latency \d"):
        res = pipeline_to_frequency(multipartite, "ice40", 2000)
    assert not res.met and len(res.steps) == 3  # combinational + both cut plans
    assert res.fmax_mhz == max(s.fmax_mhz for s in res.steps)
    assert res.latency == len(res.design.cuts) if res.latency else True


@requires_tool("nextpnr-ice40", "yosys", "iverilog")  # one marker: the hook reads the closest only
def test_cli_pipelines_the_winner_to_the_asked_frequency(tmp_path, multipartite):
    from chebnorm.hw.targets import fmax_ice40

    # combinational Fmax of this spec's winner first, then ask 15 % above it
    comb = pipeline_to_frequency(multipartite, "ice40", 1, warn=False).fmax_mhz
    ask = round(comb * 1.15)
    out = tmp_path / "o"
    r = run_cli("design", *SPEC, "--frequency", str(ask), "-o", out)
    assert r.code == 0, r.err
    m = re.search(r"pipelined for (\d+) MHz \((met|NOT met)\): latency (\d+) cycles?, Fmax "
                  r"([\d.]+) MHz \(nextpnr-ice40.*?\), (\d+) extra FFs", r.out)
    assert m, r.out
    assert int(m.group(1)) == ask and m.group(2) == "met", r.out
    latency, fmax, ffs = int(m.group(3)), float(m.group(4)), int(m.group(5))
    assert latency > 0 and fmax >= ask and ffs > 0
    assert "cycle-accurate simulation (Icarus Verilog, every code): PASS: 1024 vectors, 0 " \
           "mismatches" in r.out
    # the written module is the pipelined one, and an independent run meets the frequency
    (vfile,) = [p for p in out.glob("*.v")]
    text = vfile.read_text(encoding="utf-8")
    assert f"parameter LATENCY = {latency}" in text
    top = re.search(r"^module (\w+)", text, re.M).group(1)
    assert fmax_ice40(text, top, clocked=True, freq_mhz=ask) >= ask
    assert (out / f"{top}.vhd").exists()


@need_pnr
def test_cli_impossible_frequency_exits_0_with_one_line(tmp_path):
    r = run_cli("design", "1/sqrt(1+3*x)", "--interval", "0", "1", "--in-bits", "6",
                "--out-bits", "6", "--faithful", "--target", "ice40", "--frequency", "2000",
                "-o", tmp_path / "o")
    assert r.code == 0, r.err
    warn = [ln for ln in r.err.splitlines() if ln.startswith("chebnorm: warning:")]
    assert len(warn) == 1 and re.search(r"2000 MHz not reached: the highest is \d+\.\d\d MHz "
                                        r"at latency \d+", warn[0]), r.err


def test_pipelined_table_keeps_the_model(multipartite):
    p = PipelinedTable(multipartite, (0, 1))
    assert (p.evaluate() == multipartite.evaluate()).all() and p.latency == 2
    assert "Pipelined: registers at the table reads, the offsets' sum; latency 2" in p.verilog()
    assert "LATENCY  : natural := 2" in p.vhdl() and "Combinational." in multipartite.verilog()
