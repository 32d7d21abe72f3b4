"""``chebnorm design`` chooses among architectures (issue 28): the one-width
piecewise search, the sized piecewise evaluator, multipartite and plain table,
each synthesized on the target; ``--faithful`` and ``--correctly-rounded``
accuracy specs; ``--max-error`` as an exact expression."""

from __future__ import annotations

import csv
import shutil

import pytest

from chebnorm.cli import main
from chebnorm.hw.architectures import architecture_candidates

needs_yosys = pytest.mark.skipif(shutil.which("yosys") is None, reason="yosys not installed")
needs_iverilog = pytest.mark.skipif(shutil.which("iverilog") is None,
                                    reason="iverilog not installed")
SPEC = ["1/sqrt(1+3*x)", "--interval", "0", "1", "--in-bits", "8", "--out-bits", "8"]


@needs_yosys
def test_faithful_design_compares_every_architecture(tmp_path, capsys):
    out = tmp_path / "D"
    assert main(["design", *SPEC, "--faithful", "--target", "xc7-nodsp", "--workers", "1",
                 "-o", str(out)]) == 0
    text = capsys.readouterr().out
    rows = list(csv.DictReader((out / "design_design_architectures.csv").open()))
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


@needs_yosys
@needs_iverilog
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
    rows = list(csv.DictReader((out / "design_design_architectures.csv").open()))
    winner = next(r for r in rows if r["winner"] == "1")
    assert winner["architecture"] == "table" and "correctly rounded (proved)" in \
        winner["description"]
    assert float(winner["error"]) <= float(winner["ulp"]) / 2
    assert (out / "chebnorm_design_table.v").exists()


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
    assert (a / "design_design.csv").read_bytes() == (b / "design_design.csv").read_bytes()
