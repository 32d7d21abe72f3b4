"""``chebnorm design`` chooses among architectures (issue 28): the one-width
piecewise search, the sized piecewise evaluator, multipartite and plain table,
each synthesized on the target; ``--faithful`` and ``--correctly-rounded``
accuracy specs; ``--max-error`` as an exact expression."""

from __future__ import annotations

import csv

import pytest

from chebnorm.cli import main
from chebnorm.hw.architectures import architecture_candidates
from conftest import requires_tool

needs_yosys = requires_tool("yosys")
needs_iverilog = requires_tool("iverilog")
SPEC = ["1/sqrt(1+3*x)", "--interval", "0", "1", "--in-bits", "8", "--out-bits", "8"]
NAME = "rsqrt_1_3_x_0_1_i8_o8"   # the default name's start (chebnorm.core.textsafe.design_name)


@needs_yosys
def test_faithful_design_compares_every_architecture(tmp_path, capsys):
    out = tmp_path / "D"
    assert main(["design", *SPEC, "--faithful", "--target", "xc7-nodsp", "--workers", "1",
                 "-o", str(out)]) == 0
    text = capsys.readouterr().out
    rows = list(csv.DictReader((out / f"design_{NAME}_faithful_architectures.csv").open()))
    archs = {r["architecture"] for r in rows}
    assert {"piecewise", "piecewise-sized", "multipartite", "table"} <= archs
    assert sum(int(r["winner"]) for r in rows) == 1
    winner = next(r for r in rows if r["winner"] == "1")
    scores = [float(r["score"]) for r in rows if r["score"]]
    assert float(winner["score"]) == min(scores)
    for r in rows:  # faithful: every built candidate's certified error below one ulp
        if r["ulp"]:
            assert float(r["error"]) < float(r["ulp"])
    assert "winner:" in text


@requires_tool("yosys", "iverilog")  # one marker: the hook reads the closest only
def test_each_architecture_winner_simulates_over_every_code(tmp_path):
    from chebnorm.hw.piecewise import simulate_piecewise
    from chebnorm.hw.table_run import simulate_table

    cands = architecture_candidates("1/sqrt(1+3*x)", ("0", "1"), 8, 8, accuracy="faithful",
                                    degrees=(1, 2), k_start={1: 3, 2: 2}, synth=False)
    built = [c for c in cands if c.design is not None]
    assert {c.architecture for c in built} == {"piecewise-sized", "multipartite", "table"}
    for i, c in enumerate(built):
        assert c.error < c.ulp
        d = c.design
        folder = tmp_path / f"c{i}"
        folder.mkdir()
        res = (simulate_table(d, folder, "verilog") if c.architecture != "piecewise-sized"
               else simulate_piecewise(d, folder))
        assert res.passed, (c.architecture, res.line)


@needs_yosys
def test_correctly_rounded_builds_the_proved_table(tmp_path, capsys):
    out = tmp_path / "D"
    assert main(["design", *SPEC, "--correctly-rounded", "-o", str(out)]) == 0
    rows = list(csv.DictReader((out / f"design_{NAME}_cr_architectures.csv").open()))
    winner = next(r for r in rows if r["winner"] == "1")
    assert winner["architecture"] == "table" and "correctly rounded (proved)" in \
        winner["description"]
    assert float(winner["error"]) <= float(winner["ulp"]) / 2
    assert (out / f"chebnorm_{NAME}_cr_table.v").exists()


@pytest.mark.parametrize("bad", ["0", "-2^-16", "nan", "2^^3", "x"])
def test_max_error_refused_one_line(bad, tmp_path, capsys):
    assert main(["design", *SPEC, f"--max-error={bad}", "--no-synth", "-o",
                 str(tmp_path / "D")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--max-error" in err[0] and "accepted" in err[0]


def test_max_error_takes_an_exact_power_of_two(tmp_path, capsys):
    a, b = tmp_path / "A", tmp_path / "B"
    assert main(["design", *SPEC, "--max-error", "2^-6", "--no-synth", "--workers", "1",
                 "-o", str(a)]) == 0
    assert main(["design", *SPEC, "--max-error", "0.015625", "--no-synth", "--workers", "1",
                 "-o", str(b)]) == 0
    # the default name comes from the value: both runs name their design alike
    assert (a / f"design_{NAME}_e_2_m6.csv").read_bytes() == \
        (b / f"design_{NAME}_e_2_m6.csv").read_bytes()


def _fake_candidates(models):
    from chebnorm.hw.architectures import Candidate

    class D:  # the least a candidate's design needs here: a module name and Verilog
        def __init__(self, i):
            self.module_name = f"m{i}"

        def verilog(self):
            return self.module_name

    return [Candidate("piecewise-sized", f"c{i}", D(i), 0.0, 1.0, model=m)
            for i, m in enumerate(models)]


def test_pruning_synthesizes_cheapest_model_first_and_skips_what_cannot_win(monkeypatch):
    """With yosys replaced by fixed scores (each within the spread of its model),
    the pruned run finds the same best score as synthesizing everything, and a
    skipped candidate's lower bound is never below that best."""
    from chebnorm.hw import architectures as A
    from chebnorm.hw.target_model import MODEL_SPREAD

    s = max(A.prune_spread("piecewise-sized", "generic"))   # no ROM part: the larger ratio
    assert s >= MODEL_SPREAD["generic"]
    # two per round: m4 and m0 (best 990), then m1 alone: m2 and m3 cannot beat 990
    models = [1000.0, 1010.0, 1.07 * 990.0 * s, 2000.0 * s, 990.0]
    # true scores: the model ratio stays within s; candidate 1 scores lowest
    true = {"m0": 1000.0, "m1": 1010.0 / s, "m2": 1.07 * 990.0, "m3": 2000.0, "m4": 990.0}
    calls = []

    def fake(item):
        calls.append(item[1])
        return type("C", (), {"score": true[item[1]], "line": lambda self: "x"})()

    monkeypatch.setattr(A, "_synth_item", fake)
    cands = _fake_candidates(models)
    full = A.synthesize_candidates(cands, "generic", prune=False, workers=1)
    pruned = A.synthesize_candidates(cands, "generic", workers=1)
    best = min(c.cost.score for c in full)
    assert min(c.cost.score for c in pruned if c.cost is not None) == best
    assert calls[len(models):][:2] == ["m4", "m0"]   # cheapest model first
    skipped = [c for c in pruned if c.cost is None]
    assert {c.design.module_name for c in skipped} == {"m2", "m3"}
    for c in skipped:
        assert c.model / s >= best and "cannot win" in c.note
    # a bound from elsewhere (the one-width winner) prunes before any run
    calls.clear()
    none = A.synthesize_candidates(cands, "generic", bound=100.0, workers=1)
    assert calls == [] and all(c.cost is None for c in none)


@needs_yosys
@pytest.mark.parametrize("target", ["generic", "ice40"])
def test_pruned_synthesis_keeps_the_winner_of_synthesizing_everything(target):
    """On a small spec, every built candidate synthesized against the pruned run:
    the same best score, and no skipped candidate would have beaten it."""
    from chebnorm.hw.architectures import build_candidates, prune_lower, synthesize_candidates

    cands = build_candidates("1/sqrt(1+3*x)", ("0", "1"), 10, 10, accuracy="faithful",
                             degrees=(1, 2, 3), k_start={1: 4, 2: 2, 3: 1}, target=target)
    full = synthesize_candidates(cands, target, prune=False, workers=1)
    pruned = synthesize_candidates(cands, target, workers=1)
    best = min(c.cost.score for c in full if c.cost is not None)
    assert min(c.cost.score for c in pruned if c.cost is not None) == best
    for f, p in zip(full, pruned):
        if f.design is not None and p.cost is None:
            assert f.cost.score >= best
            assert prune_lower(f.architecture, target, f.model, f.model_rom) <= f.cost.score


def test_prune_spread_holds_on_its_calibration():
    """Every candidate of benchmarks/prune_calibration.json (three specs, four
    targets, synthesized without pruning): the pruning's lower bound is below
    its yosys score by the 10 % headroom PRUNE_SPREAD was chosen with, so no
    candidate there would have been skipped wrongly; and each measured pair
    is one the rule reads."""
    import json
    from pathlib import Path

    from chebnorm.hw.architectures import PRUNE_SPREAD, prune_lower

    rows = json.loads((Path(__file__).parent.parent / "benchmarks" /
                       "prune_calibration.json").read_text(encoding="utf-8"))["rows"]
    assert len({(r["expr"], r["bits"]) for r in rows}) >= 3
    seen = set()
    for r in rows:
        low = prune_lower(r["architecture"], r["target"], r["model"], r["model_rom"])
        assert 1.1 * low <= r["yosys"] + 0.05, r   # rows are rounded to 0.1
        seen.add((r["architecture"], r["target"]))
    assert seen <= set(PRUNE_SPREAD)
    assert {(a, t) for a, t in PRUNE_SPREAD if a != "table"} <= seen



@needs_yosys
def test_search_bound_skips_points_that_cannot_win():
    """A bound below every point's model lower bound: no point is synthesized
    (the architecture that set the bound wins), and the winner named is the
    model-cheapest meeting point; without a bound, points are synthesized."""
    from chebnorm.hw.piecewise_search import search

    kw = dict(degrees=(1, 2), max_index_bits=4, progress=False, workers=1, target="ice40")
    r = search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, bound=1.0, **kw)
    assert not [p for p in r.points if p.target_cost is not None]
    assert r.winner.target_cost is None
    assert r.winner.target_model == min(p.target_model for p in r.points if p.meets)
    full = search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, **kw)
    assert sum(p.target_cost is not None for p in full.points) >= 1


def test_one_queue_for_candidates_and_search_points(monkeypatch):
    """synthesize_with_search: candidates and the search front's points in one
    queue by lower bound, two at a time; with yosys replaced by fixed scores
    (each within its lower bound), it finds the best score of synthesizing
    everything, never skips a job whose lower bound is below that best, runs
    the same jobs with one worker or two, and says why it skipped one."""
    from chebnorm.hw import architectures as A
    from chebnorm.hw.piecewise_search import search, synthesis_queue

    res = search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, degrees=(1, 2), max_index_bits=4,
                 synth=False, progress=False, workers=1, target="xc7")
    queue = synthesis_queue(res)
    assert queue and all(low > 0 for _, low in queue)
    # candidates: one far below the points, one far above, one near the best point
    pt_low = min(low for _, low in queue)
    cands = _fake_candidates([0.5 * pt_low, 10.0 * pt_low, 1.2 * pt_low])
    cands = [A.Candidate(c.architecture, c.description, c.design, c.error, c.ulp, None, "",
                         c.model, 0.0) for c in cands]
    true = {"m0": 0.9 * pt_low * 1.2, "m1": 11.0 * pt_low, "m2": 1.3 * pt_low}
    calls = []

    def fake(item):
        kind, payload = item
        calls.append(payload[1] if kind == "arch" else payload[0].name + str(payload[0].index_bits))
        if kind == "arch":
            return type("C", (), {"score": true[payload[1]], "line": lambda self: "x"})()
        low = dict(queue)[next(k for k in res.designs if res.designs[k] is payload[0])]
        return type("C", (), {"score": 1.05 * low, "line": lambda self: "x"})()

    monkeypatch.setattr(A, "_synth_job", fake)
    one, r1 = A.synthesize_with_search(cands, res, "xc7", workers=1)
    first = list(calls)
    calls.clear()
    two, r2 = A.synthesize_with_search(cands, res, "xc7", workers=2)
    assert sorted(calls) == sorted(first) and [c.note for c in one] == [c.note for c in two]
    w1, w2 = r1.winner, r2.winner
    assert (w1.degree, w1.segments, w1.coef_frac_bits, w1.cost) == \
        (w2.degree, w2.segments, w2.coef_frac_bits, w2.cost)
    best = min([c.cost.score for c in one if c.cost is not None] +
               [p.target_cost.score for p in r1.points if p.target_cost is not None])
    assert best == min(list(true.values()) + [1.05 * low for _, low in queue])
    lows = {c.design.module_name: A.prune_lower(c.architecture, "xc7", c.model, c.model_rom)
            for c in cands}
    for c in one:
        if c.cost is None:
            assert lows[c.design.module_name] >= best and "cannot win" in c.note
    assert one[1].cost is None   # ten times the points' models: never synthesized
    assert first[0] == "m0"      # the lowest bound first


@pytest.mark.parametrize("queue", ["candidates", "with_search"])
def test_a_skipped_candidates_lower_bound_is_printed_rounded_down(monkeypatch, queue):
    """Both pruned queues print a skipped candidate's lower bound rounded down
    (issue 45: synthesize_with_search rounded it to nearest). The bound here is
    ~123.46, whose nearest one-decimal text 123.5 reads above it; the text is
    read back and compared with the bound exactly."""
    import re
    from decimal import Decimal
    from fractions import Fraction

    from chebnorm.hw import architectures as A
    from chebnorm.hw.piecewise_search import search

    s = max(A.prune_spread("piecewise-sized", "xc7"))   # no ROM part: the larger ratio
    cands = _fake_candidates([50.0 * s, 60.0 * s, 123.46 * s])   # m2 skipped: 123.46 >= 100

    def fake(item):
        return type("C", (), {"score": 100.0, "line": lambda self: "x"})()

    if queue == "candidates":
        monkeypatch.setattr(A, "_synth_item", fake)
        out = A.synthesize_candidates(cands, "xc7", workers=1)
    else:   # a search with no point meeting the error: the candidates alone queue
        r = search("1/sqrt(x)", ("1", "4"), 6, 6, 1e-9, degrees=(1,), max_index_bits=2,
                   synth=False, progress=False, workers=1)
        monkeypatch.setattr(A, "_synth_job", lambda item: fake(item[1]))
        out, _ = A.synthesize_with_search(cands, r, "xc7", workers=1)
    assert [c.cost is None for c in out] == [False, False, True]
    low = A.prune_lower("piecewise-sized", "xc7", cands[2].model)
    assert f"{low:.1f}" == "123.5"   # what rounding to nearest printed
    printed = re.search(r"lower bound (\S+) >= best synthesized 100\.0: cannot win",
                        out[2].note)[1]
    assert printed == "123.4"
    assert Fraction(Decimal(printed)) <= Fraction(low) < Fraction(Decimal(printed)) + \
        Fraction(1, 10)
