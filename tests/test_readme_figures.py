"""The figures the README quotes are the ones its commands print, so they cannot
drift: the first fit (its whole console block), the fixed-point comparison of
the "Coefficient formats" section, and the worked hardware example of
"Piecewise tables". Each test reads the quoted text from README.md itself and
runs the command the README shows, through the installed CLI's ``main``.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from chebnorm.cli import main

README = (Path(__file__).resolve().parent.parent / "README.md").read_text(encoding="utf-8")


def _run(capsys, *argv) -> str:
    """``chebnorm ARGV`` in this process; its stdout (exit status 0 required)."""
    capsys.readouterr()
    status = main(list(argv))
    out = capsys.readouterr().out
    assert status in (0, None), f"chebnorm {' '.join(argv)} exited {status}"
    return out


def _section(title: str) -> str:
    """The README text from the heading ``title`` to the next heading of its level."""
    level = title.split(" ", 1)[0]
    start = README.index(f"\n{title}\n")
    nxt = re.search(rf"\n{level} ", README[start + 1:])
    return README[start:start + 1 + nxt.start()] if nxt else README[start:]


def test_first_fit_console_block_is_verbatim(capsys):
    block = re.search(r"```console\n\$ (chebnorm fit [^\n]+)\n(.*?)```", _section("## A first fit"), re.S)
    assert block, "README's first fit lost its console block"
    command, quoted = block.group(1), block.group(2)
    assert command == 'chebnorm fit "1/sqrt(2+z)" --var z --interval "sqrt(2)" 2 --degree 2'
    out = _run(capsys, "fit", "1/sqrt(2+z)", "--var", "z", "--interval", "sqrt(2)", "2", "--degree", "2")
    assert out == quoted


def test_first_fit_minimax_optimum(capsys):
    quoted = re.search(r"`--kind minimax` gives the optimum, ([0-9.e-]+)\.", _section("## A first fit")).group(1)
    out = _run(capsys, "fit", "1/sqrt(2+z)", "--var", "z", "--interval", "sqrt(2)", "2", "--degree", "2",
               "--kind", "minimax")
    located = re.search(r"max \|p - f\|\s+= ([0-9.e+-]+)", out).group(1)
    # quoted to 4 digits: the located maximum (the optimum's value) rounded there
    assert f"{float(located):.3e}".replace("e-05", "e-5") == quoted


def test_fixed_point_comparison(capsys):
    text = " ".join(_section("## Coefficient formats").split())
    m = re.search(r"it now gives `\[([-0-9, ]+)\]`, ([0-9.e-]+), and Sollya", text)
    assert m, "README's fixed-point comparison changed shape"
    integers, bound = m.group(1), m.group(2)
    out = _run(capsys, "fit", "1/sqrt(2+z)", "--var", "z", "--interval", "sqrt(2)", "2", "--degree", "2",
               "--coef-frac-bits", "14")
    assert f"lattice): [{integers}]; certified |p_q - f| <= {bound}" in out


def _worked_example() -> tuple[list[str], list[str]]:
    """The commands of the worked example and the lines quoted after ``#``."""
    block = re.search(r"Worked example, .*?```\n(.*?)```", _section("## Piecewise tables"), re.S).group(1)
    commands = [line for line in block.splitlines() if line.startswith("chebnorm ")]
    quoted = [line.lstrip("# ").strip() for line in block.splitlines() if line.startswith("#")]
    return commands, quoted


def _joined(quoted: list[str]) -> str:
    """The quoted report lines, continuation lines (indented in the README) joined."""
    return " ".join(quoted)


@pytest.mark.slow
def test_worked_hardware_example(capsys, tmp_path, monkeypatch):
    commands, quoted = _worked_example()
    assert commands[0].startswith('chebnorm fit "1/sqrt(x)" --interval 1 4 --degree 2 --segments 2^8')
    monkeypatch.chdir(tmp_path)
    _run(capsys, "fit", "1/sqrt(x)", "--interval", "1", "4", "--degree", "2", "--segments", "2^8",
         "--kind", "minimax", "--coef-frac-bits", "24", "--name", "rsqrt", "-o", "rsqrt.json")
    synth = shutil.which("yosys") is not None
    out = _run(capsys, "hw", "report", "rsqrt.json", "--in-bits", "16", "--out-bits", "16",
               *(() if synth else ("--no-synth",)))
    report = " ".join(out.split())
    text = _joined(quoted)
    budget = re.search(r"error budget .*?LSB\)", text).group(0)
    measured = re.search(r"measured over all 65536 codes: max \|y - f\(x\)\| = ([0-9.e-]+)", text).group(1)
    assert budget in report
    assert f"measured over all 65536 codes: max |y - f(x)| = {measured} " in report
    if synth:
        cells = re.search(r"cost: (\d+) yosys cells", text).group(1)
        assert f"cost: {cells} yosys cells" in report


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("iverilog") is None, reason="iverilog not installed")
def test_worked_hardware_example_simulates(capsys, tmp_path, monkeypatch):
    _commands, quoted = _worked_example()
    passed = next(q for q in quoted if q.startswith("PASS:"))
    monkeypatch.chdir(tmp_path)
    _run(capsys, "fit", "1/sqrt(x)", "--interval", "1", "4", "--degree", "2", "--segments", "2^8",
         "--kind", "minimax", "--coef-frac-bits", "24", "--name", "rsqrt", "-o", "rsqrt.json")
    out = _run(capsys, "hw", "verilog", "rsqrt.json", "--in-bits", "16", "--out-bits", "16", "-o", "hw",
               "--simulate")
    assert passed in out


def test_architectures_per_spec_table_is_the_measured_json():
    """Every row of the README's "Architectures per spec" table is what
    ``benchmarks/bench_specs.py`` prints from the committed measurements
    (``benchmarks/specs_results.json``), verbatim: a hand edit of either side
    fails here."""
    import json
    import sys

    bench = Path(__file__).resolve().parent.parent / "benchmarks"
    sys.path.insert(0, str(bench))
    try:
        import bench_specs
    finally:
        sys.path.remove(str(bench))
    doc = json.loads((bench / "specs_results.json").read_text(encoding="utf-8"))
    rows = bench_specs.markdown(doc["results"], bench_specs.SPECS).splitlines()
    assert len(rows) > 2 + len(bench_specs.SPECS)   # header, rule, at least a row per spec
    missing = [r for r in rows if r not in README.splitlines()]
    assert not missing, missing[:3]
