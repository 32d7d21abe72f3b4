"""Every architecture pipelined for ``design --frequency`` (issue 45).

The pipelined plain table (address and ROM output registered), the pipelined
multipartite design (table reads and offsets' sum registered) and the one-width
piecewise design (after the ROM, each multiply, each add) are simulated over every input code in Icarus Verilog and GHDL, output ``i``
against the bit-accurate model's value of code ``i - latency``; the bench is
shown to catch a wrong latency. The choice of the winner at a frequency is
checked on made-up timings (cheapest pipelined design reaching the clock,
else the fastest with one warning naming it) and, with nextpnr-ice40, on the
acceptance command, whose written RTL an independent nextpnr run times again.
"""

from __future__ import annotations

import re
import warnings
from types import SimpleNamespace

import pytest

from chebnorm.hw.pipeline import (PipelinedTable, PipelineResult, PipelineStep, cut_names,
                                  cut_plans, design_files, verify_pipelined, with_cuts)
from conftest import requires_tool, run_cli

BITS = 8


@pytest.fixture(scope="module")
def table():
    from chebnorm.hw.plain_table import design_plain_table

    return design_plain_table("1/sqrt(1+3*x)", ("0", "1"), BITS, BITS)


@pytest.fixture(scope="module")
def multipartite():
    from chebnorm.hw.multipartite import design_multipartite

    return design_multipartite("1/sqrt(1+3*x)", ("0", "1"), BITS, BITS, faithful=True)


def _base(kind, table, multipartite):
    return table if kind == "table" else multipartite


# -- cut points of the plain table ------------------------------------------------------

def test_plain_table_cut_points(table):
    assert cut_plans(table) == [(1,), (0, 1)]
    assert cut_names(table, (0, 1)) == ["address", "rom"]
    p = with_cuts(table, (1, 0, 1))
    assert isinstance(p, PipelinedTable) and p.cuts == (0, 1) and p.latency == 2
    assert (p.evaluate() == table.evaluate()).all()       # same values, later
    v, h = p.verilog(), p.vhdl()
    assert "parameter LATENCY = 2" in v and "addr_r0 <= addr;" in v and "case (addr_r0)" in v
    assert "rom_r1 <= rom;" in v and "assign y = rom_r1;" in v
    assert "LATENCY  : natural := 2" in h and "rom_r1 <= rom;" in h
    assert "Pipelined: registers at the address, the ROM read; latency 2" in v
    assert "Combinational." in table.verilog() and "clk" not in table.verilog()
    with pytest.raises(ValueError, match=r"^cuts \[2\]: accepted: a plain table's sorted cut "
                                         r"points among 0 \(the address register\) and 1"):
        with_cuts(table, (2,))


def test_pipelined_table_refuses_another_design():
    from chebnorm.approx.piecewise_fit import piecewise_fit
    from chebnorm.hw.piecewise import design_piecewise

    t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    with pytest.raises(ValueError, match="accepted: a MultipartiteDesign or a PlainTableDesign"):
        PipelinedTable(design_piecewise(t, 8, 8), (0,))


# -- every code, cycle by cycle, in both simulators ---------------------------------------

@pytest.mark.requires_tool("iverilog")
@pytest.mark.parametrize("kind", ["table", "multipartite"])
def test_every_plan_simulated_in_icarus(kind, table, multipartite):
    base = _base(kind, table, multipartite)
    for plan in cut_plans(base):
        d = with_cuts(base, plan)
        res = verify_pipelined(d)
        assert res.passed and res.vectors == 2 ** BITS and res.mismatches == 0, (plan, res.line)
        assert f"latency {len(plan)}" in res.line
    # the mutation: a bench expecting one cycle less must fail
    full = with_cuts(base, cut_plans(base)[-1])
    bad = verify_pipelined(full, bench_design=with_cuts(base, cut_plans(base)[0]))
    assert not bad.passed and bad.mismatches > 0, bad.line


@pytest.mark.requires_tool("ghdl")
@pytest.mark.parametrize("kind", ["table", "multipartite"])
def test_every_plan_simulated_in_ghdl(tmp_path, kind, table, multipartite):
    from chebnorm.hw.run_vhdl import simulate_vhdl

    base = _base(kind, table, multipartite)
    for plan in cut_plans(base):
        d = with_cuts(base, plan)
        folder = tmp_path / "_".join(map(str, plan))
        folder.mkdir()
        for name, text in design_files(d, "vhdl").items():
            (folder / name).write_text(text, encoding="utf-8")
        res = simulate_vhdl(folder, d)
        assert res.passed and res.vectors == 2 ** BITS, (plan, res.line)
    # the mutation: the full design against the bench of one register fewer
    full = with_cuts(base, cut_plans(base)[-1])
    folder = tmp_path / "wrong"
    folder.mkdir()
    files = design_files(full, "vhdl")
    short = design_files(with_cuts(base, cut_plans(base)[0]), "vhdl")
    for name, text in files.items():
        (folder / name).write_text(short[name] if name.startswith("tb_") else text,
                                   encoding="utf-8")
    assert not simulate_vhdl(folder, full).passed


# -- the one-width piecewise design: the sized design's cut points ------------------------

@pytest.fixture(scope="module")
def one_width():
    from chebnorm.approx.piecewise_fit import piecewise_fit
    from chebnorm.hw.piecewise import design_piecewise

    t = piecewise_fit("1/sqrt(1+3*x)", ("0", "1"), 2, segments=8, coef_frac_bits=14,
                      centered=True, name="ow")
    return design_piecewise(t, BITS, BITS)


def test_one_width_cut_points(one_width):
    d = one_width
    assert not d.sized and d.latency == 0
    # stage weights rom 1, mul 2, add 1, output 0.5 (STAGE_WEIGHTS): one cut after add1
    # leaves 1+2+1 | 2+1+0.5, two after mul1 and mul2 leave 1+2 | 1+2 | 1+0.5, ...
    assert cut_plans(d) == [(2,), (1, 3), (0, 1, 3), (0, 1, 2, 3), (0, 1, 2, 3, 4)]
    p = with_cuts(d, (4, 0, 1))
    assert (p.cuts, p.mult_cuts, p.latency) == ((0, 2), (1,), 3)
    assert (p.evaluate() == d.evaluate()).all()
    assert p.verify() is p                              # re-proved with its registers
    from chebnorm.hw.hdl import module_text

    v, h = module_text(p, "verilog"), module_text(p, "vhdl")
    assert "parameter LATENCY = 3" in v and v.count("always @(posedge clk)") == 3
    assert "LATENCY  : natural := 3" in h and h.count("rising_edge(clk)") == 3
    assert "Pipelined: registers at cut points [0, 2]" in v
    assert "clk" not in module_text(d, "verilog")     # without cuts: the combinational module
    # what design --frequency writes for a pipelined one-width winner
    from chebnorm.hw.design_api import _hdl_files

    files = _hdl_files("architecture", p, "0.0", "chebnorm design ...")
    assert sorted(files) == ["chebnorm_ow.v", "chebnorm_ow.vhd"]
    assert "parameter LATENCY = 3" in files["chebnorm_ow.v"]
    assert "LATENCY  : natural := 3" in files["chebnorm_ow.vhd"]
    with pytest.raises(ValueError, match=r"accepted: integers 0\.\.4"):
        with_cuts(d, (5,))
    from dataclasses import replace

    with pytest.raises(ValueError, match="mult_cuts"):
        replace(d, mult_cuts=(3,))


def _both_simulators(tmp_path, base, plans) -> None:
    from chebnorm.hw.run_vhdl import simulate_vhdl

    for plan in plans:
        d = with_cuts(base, plan)
        res = verify_pipelined(d)
        assert res.passed and res.vectors == 2 ** BITS, (plan, res.line)
        folder = tmp_path / "_".join(map(str, plan))
        folder.mkdir()
        for name, text in design_files(d, "vhdl").items():
            (folder / name).write_text(text, encoding="utf-8")
        res = simulate_vhdl(folder, d)
        assert res.passed and res.vectors == 2 ** BITS, (plan, res.line)


@pytest.mark.requires_tool("iverilog", "ghdl")
def test_one_width_plans_in_both_simulators(tmp_path, one_width):
    top = 2 * one_width.degree
    # every plan design --frequency tries, and each single register alone
    plans = sorted(set(cut_plans(one_width)) | {(c,) for c in range(top + 1)})
    _both_simulators(tmp_path, one_width, plans)
    full = with_cuts(one_width, range(top + 1))
    bad = verify_pipelined(full, bench_design=with_cuts(one_width, range(top)))
    assert not bad.passed and bad.mismatches > 0, bad.line


@pytest.mark.slow
@pytest.mark.requires_tool("iverilog", "ghdl")
def test_one_width_every_cut_set_in_both_simulators(tmp_path, one_width):
    from itertools import combinations

    top = 2 * one_width.degree
    _both_simulators(tmp_path, one_width, [plan for m in range(1, top + 2)
                                           for plan in combinations(range(top + 1), m)])


# -- the winner at a frequency: the cheapest pipelined design reaching it -----------------

def _result(fmax, score, latency, freq=200.0):
    cost = SimpleNamespace(score=score, ffs=8 * latency, line=lambda: f"score {score}")
    steps = tuple(PipelineStep(tuple(range(k)), k, fmax) for k in range(latency + 1))
    return PipelineResult(f"design-{score}", "ice40", freq, fmax >= freq, latency, fmax,
                          "nextpnr-ice40 (made up)", cost, steps)


def _spec(freq=200.0):
    from chebnorm.hw.design_api import _check

    return _check("1/sqrt(1+3*x)", ("0", "1"), 8, 8, None, True, False, "ice40", freq,
                  (1, 2), None, "uniform", "x", None, True, 1, None)


def _candidates(*specs):
    from chebnorm.hw.architectures import Candidate

    return [Candidate(arch, f"{arch} design", f"design-{arch}", 1e-3, 2e-3,
                      SimpleNamespace(score=comb)) for arch, comb in specs]


def _time(monkeypatch, spec, others, timings):
    import chebnorm.hw.design_api as design_api
    import chebnorm.hw.pipeline as pipeline
    from chebnorm.hw.design_api import _time_all

    # the made-up designs have no netlist: priced by their made-up cost
    monkeypatch.setattr(design_api, "_placed_score", lambda run, device: run.cost.score)
    by_design = dict(timings)
    monkeypatch.setattr(pipeline, "pipeline_to_frequency",
                        lambda d, target, f, warn=True: by_design[d])
    return _time_all(spec, others, None)


def test_winner_is_the_cheapest_reaching_the_frequency(monkeypatch):
    # combinationally the sized design is cheapest (100); at 200 MHz it needs 3 registers
    # stages and still misses; the table reaches it as it is, the multipartite with two
    others = _candidates(("piecewise-sized", 100.0), ("multipartite", 150.0), ("table", 300.0))
    t = _time(monkeypatch, _spec(), others, [
        ("design-piecewise-sized", _result(180.0, 160.0, 3)),
        ("design-multipartite", _result(230.0, 190.0, 2)),
        ("design-table", _result(400.0, 300.0, 0))])
    assert t.candidate is others[1] and t.result.fmax_mhz == 230.0 and t.shortfall == ""
    assert [a for a, _, _, _ in t.timings] == ["piecewise-sized", "multipartite", "table"]
    assert t.score == 190.0
    winner = [ln for ln in t.lines if ln.endswith("-- the winner")]
    assert len(winner) == 1 and winner[0].startswith("  multipartite:")
    assert "Fmax 180.00 MHz at latency 3 (does not reach 200 MHz), score 160.0, 24 pipeline " \
           "FFs" in t.lines[1]
    # a tie in score: the shorter latency, then the first listed
    t = _time(monkeypatch, _spec(), others, [
        ("design-piecewise-sized", _result(250.0, 190.0, 3)),
        ("design-multipartite", _result(230.0, 190.0, 2)),
        ("design-table", _result(400.0, 190.0, 2))])
    assert t.candidate is others[1]


def test_none_reaching_names_the_closest(monkeypatch):
    others = _candidates(("piecewise-sized", 100.0), ("multipartite", 150.0))
    t = _time(monkeypatch, _spec(500.0), others, [
        ("design-piecewise-sized", _result(180.0, 160.0, 3, 500.0)),
        ("design-multipartite", _result(230.0, 190.0, 2, 500.0))])
    assert t.candidate is others[1]
    assert re.match(r"500 MHz not reached: the highest is 230\.00 MHz at latency 2, by "
                    r"multipartite, the closest architecture \(highest MHz per architecture: "
                    r"piecewise-sized: 180\.00, multipartite: 230\.00; ", t.shortfall), t.shortfall


def test_an_architecture_the_tools_refuse_is_reported_and_left_out(monkeypatch):
    import chebnorm.hw.design_api as design_api
    import chebnorm.hw.pipeline as pipeline
    from chebnorm.hw.design_api import _time_all

    monkeypatch.setattr(design_api, "_placed_score", lambda run, device: run.cost.score)
    others = _candidates(("multipartite", 150.0), ("table", 300.0))

    def timing(d, target, f, warn=True):
        if d == "design-table":
            raise ValueError("module chebnorm_t needs 300 I/O pins; accepted: at most 206")
        return _result(230.0, 190.0, 2)

    monkeypatch.setattr(pipeline, "pipeline_to_frequency", timing)
    t = _time_all(_spec(), others, None)
    assert t.candidate is others[0] and [a for a, *_ in t.timings] == ["multipartite"]
    assert "  table: table design: not timed (module chebnorm_t needs 300 I/O pins; " \
           "accepted: at most 206)" in t.lines
    monkeypatch.setattr(pipeline, "pipeline_to_frequency",
                        lambda *a, **k: timing("design-table", None, None))
    with pytest.raises(ValueError, match=r"^no architecture could be timed at 200 MHz on ice40 "
                                         r"\(multipartite: module chebnorm_t needs 300 I/O"):
        _time_all(_spec(), others, None)


def test_a_tool_timeout_stops_the_choice_instead_of_changing_the_winner(monkeypatch):
    # a timeout says how busy the machine was, not what the design is: leaving that
    # architecture out would let another win on a loaded machine only
    import chebnorm.hw.design_api as design_api
    import chebnorm.hw.pipeline as pipeline
    from chebnorm.exceptions import ToolTimeout
    from chebnorm.hw.design_api import _time_all

    monkeypatch.setattr(design_api, "_placed_score", lambda run, device: run.cost.score)
    others = _candidates(("multipartite", 150.0), ("table", 300.0))

    def timing(d, target, f, warn=True):
        if d == "design-multipartite":
            raise ToolTimeout("nextpnr-ice40", ["nextpnr-ice40"], 900)
        return _result(230.0, 190.0, 2)

    monkeypatch.setattr(pipeline, "pipeline_to_frequency", timing)
    with pytest.raises(ToolTimeout, match="nextpnr-ice40"):
        _time_all(_spec(), others, None)


@pytest.mark.requires_tool("yosys")
def test_table_is_priced_as_the_netlist_nextpnr_times():
    # between the input and output registers the ROM read becomes a block RAM read:
    # the module alone maps to LUTs, the timed netlist to SB_RAM40_4K (240 LUT each)
    from chebnorm.hw.design_api import _placed_score
    from chebnorm.hw.plain_table import design_plain_table
    from chebnorm.hw.targets import synthesize_target

    d = design_plain_table("1/sqrt(1+3*x)", ("0", "1"), 10, 10)
    alone = synthesize_target(d.verilog(), d.module_name, "ice40")
    run = PipelineResult(d, "ice40", 200.0, True, 0, 469.26, "nextpnr-ice40", alone,
                         (PipelineStep((), 0, 469.26),))
    assert alone.brams == 0 and alone.ffs == 0
    placed = _placed_score(run, "ice40")
    assert placed >= 240.0 + 10 and placed != alone.score      # a RAM and the out register
    assert _placed_score(run, "xc7") == alone.score              # sta times the module itself


# -- the acceptance command on nextpnr-ice40 ---------------------------------------------

SPEC = ["1/sqrt(1+3*x)", "--interval", "0", "1", "--faithful", "--target", "ice40"]


def _figures(out: str):
    """(architecture, Fmax, latency, met, score, winner) per architecture line."""
    rows = re.findall(r"^  (.+?): .*: Fmax ([\d.]+) MHz at latency (\d+) \((reaches|does not "
                      r"reach) \d+ MHz\), score ([\d.]+), \d+ pipeline FFs( -- the winner)?$",
                      out,
                      re.M)
    return [(a, float(f), int(lat), m == "reaches", float(s), bool(w))
            for a, f, lat, m, s, w in rows]


@pytest.mark.slow
@requires_tool("nextpnr-ice40", "yosys", "iverilog")
def test_acceptance_every_architecture_timed_at_200_mhz(tmp_path):
    from chebnorm.hw.targets import fmax_ice40

    out = tmp_path / "o"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = run_cli("design", *SPEC, "--in-bits", "8", "--out-bits", "8", "--frequency", "200",
                    "-o", out)
    assert r.code == 0, r.err
    rows = _figures(r.out)
    archs = {a for a, *_ in rows}
    assert {"piecewise (one width)", "piecewise-sized", "multipartite", "table"} <= archs, r.out
    (win,) = [row for row in rows if row[5]]
    assert win[3] and win[1] >= 200, r.out
    # the cheapest of those reaching 200 MHz
    assert win[4] == min(s for _, f, _, met, s, _ in rows if met), r.out
    m = re.search(r"timing: pipelined for 200 MHz \(met\): latency (\d+) cycles?, Fmax "
                  r"([\d.]+) MHz \(nextpnr-ice40", r.out)
    assert m and float(m.group(2)) == win[1] and int(m.group(1)) == win[2], r.out
    # the written module is the winner's, and an independent nextpnr run agrees
    (vfile,) = out.glob("*.v")
    text = vfile.read_text(encoding="utf-8")
    top = re.search(r"^module (\w+)", text, re.M).group(1)
    assert fmax_ice40(text, top, clocked=win[2] > 0, freq_mhz=200) >= 200


@pytest.mark.slow
@requires_tool("nextpnr-ice40", "yosys", "iverilog", "ghdl")
def test_frequency_changes_the_winner(tmp_path):
    # 10 bits: combinationally a sized piecewise design is the cheapest; at 200 MHz only
    # the table (its ROM read between registers) gets there
    args = [*SPEC, "--in-bits", "10", "--out-bits", "10"]
    comb = run_cli("design", *args, "-o", tmp_path / "c")
    assert comb.code == 0, comb.err
    fast = run_cli("design", *args, "--frequency", "200", "-o", tmp_path / "f")
    assert fast.code == 0, fast.err
    first = comb.out.split("winner: ", 1)[1].split(":", 1)[0]
    rows = _figures(fast.out)
    (win,) = [row for row in rows if row[5]]
    assert win[0] != first and win[3] and win[1] >= 200, (comb.out, fast.out)
    # the combinational winner was timed too, pipelined, and missed 200 MHz (or cost more)
    assert any(a == first and (not met or s > win[4]) for a, _, _, met, s, _ in rows)


@pytest.mark.slow
@requires_tool("nextpnr-ice40", "yosys", "iverilog")
def test_unreachable_frequency_names_the_closest_architecture(tmp_path):
    r = run_cli("design", *SPEC, "--in-bits", "6", "--out-bits", "6", "--frequency", "2000",
                "-o", tmp_path / "o")
    assert r.code == 0, r.err
    warn = [ln for ln in r.err.splitlines() if ln.startswith("chebnorm: warning:")]
    assert len(warn) == 1, r.err
    m = re.search(r"2000 MHz not reached: the highest is ([\d.]+) MHz at latency (\d+), by "
                  r"(.+?), the closest architecture", warn[0])
    assert m, warn[0]
    rows = _figures(r.out)
    assert rows and not any(met for _, _, _, met, _, _ in rows)
    (win,) = [row for row in rows if row[5]]
    # the winner is the fastest of all, and the warning names it with its figures
    assert win[1] == max(f for _, f, *_ in rows) == float(m.group(1)), r.out
    assert win[0] == m.group(3) and win[2] == int(m.group(2)), (win, warn[0])
