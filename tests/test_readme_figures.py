"""The figures the README and the manual quote are the ones their commands print,
so they cannot drift: the README's first fit (its whole console block) and its
fit-to-compiled-evaluator example, the fixed-point comparison of "Coefficient
formats" (docs/formats.md), and the worked hardware example of "Piecewise
tables" (docs/hardware.md). Each test reads the quoted text from the page itself
and runs the command it shows, through the installed CLI's ``main``. The
benchmark tables (architectures per spec, the issue-28 design per target) are
compared with the committed JSON the benchmarks wrote, printed by the
benchmark's own formatter (nothing synthesized again); the ``chebnorm verify``
table is measured again (a few seconds: gcc, and the GPU drivers where present).
"""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

import pytest

from conftest import run_cli, tool_missing

ROOT = Path(__file__).resolve().parent.parent
#: the README and the manual's pages that quote measured figures, as one text (each
#: page starts with a level-1 heading, so a section never runs into the next page's)
PAGES = ("README.md", "docs/formats.md", "docs/hardware.md", "docs/benchmarks.md")
README = "\n".join((ROOT / page).read_text(encoding="utf-8") for page in PAGES)


def _run(*argv) -> str:
    """``chebnorm ARGV`` in this process (:func:`conftest.run_cli`); its stdout
    (exit status 0 required)."""
    r = run_cli(*argv)
    assert r.code == 0, f"chebnorm {' '.join(argv)} exited {r.code}: {r.err}"
    return r.out


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
    out = _run("fit", "1/sqrt(2+z)", "--var", "z", "--interval", "sqrt(2)", "2", "--degree", "2")
    assert out == quoted


def test_first_fit_minimax_optimum(capsys):
    quoted = re.search(r"`--kind minimax` gives the optimum, ([0-9.e-]+)\.", _section("## A first fit")).group(1)
    out = _run("fit", "1/sqrt(2+z)", "--var", "z", "--interval", "sqrt(2)", "2", "--degree", "2",
               "--kind", "minimax")
    located = re.search(r"max \|p - f\|\s+= ([0-9.e+-]+)", out).group(1)
    # quoted to 4 digits: the located maximum (the optimum's value) rounded there
    assert f"{float(located):.3e}".replace("e-05", "e-5") == quoted


def test_fixed_point_comparison(capsys):
    text = " ".join(_section("## Coefficient formats").split())
    m = re.search(r"--coef-frac-bits 14` it gives `\[([-0-9, ]+)\]`, ([0-9.e-]+) \(", text)
    assert m, "README's fixed-point comparison changed shape"
    integers, bound = m.group(1), m.group(2)
    out = _run("fit", "1/sqrt(2+z)", "--var", "z", "--interval", "sqrt(2)", "2", "--degree", "2",
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
    _run("fit", "1/sqrt(x)", "--interval", "1", "4", "--degree", "2", "--segments", "2^8",
         "--kind", "minimax", "--coef-frac-bits", "24", "--name", "rsqrt", "-o", "rsqrt.json")
    synth = tool_missing("yosys") is None  # the README's figures with or without synthesis
    out = _run("hw", "report", "rsqrt.json", "--in-bits", "16", "--out-bits", "16",
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
@pytest.mark.requires_tool("iverilog")
def test_worked_hardware_example_simulates(capsys, tmp_path, monkeypatch):
    _commands, quoted = _worked_example()
    passed = next(q for q in quoted if q.startswith("PASS:"))
    monkeypatch.chdir(tmp_path)
    _run("fit", "1/sqrt(x)", "--interval", "1", "4", "--degree", "2", "--segments", "2^8",
         "--kind", "minimax", "--coef-frac-bits", "24", "--name", "rsqrt", "-o", "rsqrt.json")
    out = _run("hw", "verilog", "rsqrt.json", "--in-bits", "16", "--out-bits", "16", "-o", "hw",
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


BENCH = Path(__file__).resolve().parent.parent / "benchmarks"


def _bench_module(name: str):
    """A script of ``benchmarks/`` imported as a module."""
    sys.path.insert(0, str(BENCH))
    try:
        return __import__(name)
    finally:
        sys.path.remove(str(BENCH))


def test_design_per_target_table_is_the_measured_json():
    """The README's table of the issue-28 spec per FPGA target (winner, cells,
    timing, wall / CPU seconds) is what ``bench_design_targets.py --markdown``
    prints from ``benchmarks/design_targets_results.json``, verbatim; the
    prose's ranges (load average, each target's wall times) are the same runs', and
    it says the 20 s goal is met only if every run was under 20 s."""
    bench = _bench_module("bench_design_targets")
    doc = json.loads((BENCH / "design_targets_results.json").read_text(encoding="utf-8"))
    assert all(r["status"] == 0 for r in doc["results"])
    rows = bench.markdown(doc).splitlines()
    assert len(rows) == 2 + len(doc["results"]) >= 6
    missing = [r for r in rows if r not in README.splitlines()]
    assert not missing, missing[:3]
    text = " ".join(README.split())
    walls = {r["target"]: r["walls_s"] for r in doc["results"]}
    for t, w in walls.items():   # the prose's per-target ranges are the runs'
        assert f"{t} {min(w):.1f}-{max(w):.1f} s" in text, t
    under = all(max(w) < 20 for w in walls.values())
    assert ("Every run of every target finished in under 20 s" in text) == under
    lo = math.floor(10 * min(r["load_before"] for r in doc["results"])) / 10
    hi = math.ceil(10 * max(max(r["load_before"], r["load_after"]) for r in doc["results"])) / 10
    assert f"load average {lo} to {hi}" in text
    assert f"--repeat {doc['repeat']}`" in text


def _verify_rows():
    """The README's ``chebnorm verify`` rows by (format, variant)."""
    start, end = "<!-- verify-rsqrt-start -->", "<!-- verify-rsqrt-end -->"
    block = README.split(start, 1)[1].split(end, 1)[0].strip().splitlines()[2:]
    return {tuple(c.strip() for c in r.split("|")[1:3]): r for r in block}


@pytest.mark.requires_tool("gcc")
def test_verify_table_is_what_verify_measures():
    """Every row of the README's ``chebnorm verify`` table is measured again on
    the committed table: the unfused C evaluators (IEEE arithmetic, the same
    bits on any machine) verbatim; the fused and GPU rows where this machine
    runs the same variant (FMA, llvmpipe, lavapipe) verbatim too, otherwise
    their stated bounds and input counts (what the exporters state); and the
    prose's "bound against measured" figures are the float row's."""
    from chebnorm.approx import load_table
    from chebnorm.export.verify import verify

    bench = _bench_module("verify_rsqrt")
    readme = _verify_rows()
    assert len(readme) == 7
    table = load_table(bench.TABLE)
    seen = set()
    for fmt in ("c", "glsl", "wgsl"):
        for v in verify(table, fmt).variants:
            if v.skipped is not None:
                continue
            key = (fmt, v.variant)
            seen.add(key)
            assert v.measured_max <= v.stated_bound
            if key not in readme:   # another GPU driver than the README's
                continue
            fresh = bench.row_text(fmt, v)
            if fmt == "c" and "fused" not in v.variant:
                assert fresh == readme[key]
            else:   # FMA or the driver may move the measurement: what is stated must agree
                cells, want = fresh.split("|"), readme[key].split("|")
                assert (cells[3], cells[6], cells[8]) == (want[3], want[6], want[8]), key
    assert {("c", "double"), ("c", "float"), ("c", "fixed")} <= seen
    f32 = readme[("c", "float")].split("|")
    stated, measured = f32[6].split()[0], f32[4].strip()
    assert f"the float and shader bound {stated} against a measured {measured}" in \
        " ".join(README.split())


@pytest.mark.requires_tool("gcc")
def test_fit_to_compiled_evaluator_example(tmp_path, monkeypatch):
    """The README's "From a fit to a compiled evaluator": every command of its
    ``sh`` block runs as shown (the chebnorm ones in this process, gcc as itself)
    on the ``main.c`` it shows, and ``verify`` finds the stated float bound held."""
    import shlex
    import subprocess

    section = _section("## From a fit to a compiled evaluator")
    commands = re.search(r"```sh\n(.*?)```", section, re.S).group(1).strip().splitlines()
    source = re.search(r"```c\n(.*?)```", section, re.S).group(1)
    assert [c.split()[0] for c in commands] == ["chebnorm", "chebnorm", "chebnorm", "gcc"]
    monkeypatch.chdir(tmp_path)
    (tmp_path / "main.c").write_text(source, encoding="utf-8")
    for command in commands:
        argv = shlex.split(command)
        if argv[0] == "chebnorm":
            out = _run(*argv[1:])
        else:  # the compiler itself: the header must build with -Wall -Werror
            done = subprocess.run(argv, cwd=tmp_path, capture_output=True, text=True)
            assert done.returncode == 0, done.stderr
    assert re.search(r"c float .* ok$", out.strip(), re.M), out
    assert (tmp_path / "main.o").stat().st_size > 0
    stated = re.search(r"`(CHEBNORM_\w+_F_EVAL_ERROR_BOUND)`", section).group(1)
    assert f"#define {stated} " in (tmp_path / "rsqrt.h").read_text(encoding="utf-8")
