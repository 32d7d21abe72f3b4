"""An external tool that runs past its time limit ends in one chebnorm error
naming the tool and the limit, never a traceback (issue 43).

Every tool is replaced by a fake on ``PATH`` that sleeps (``exec sleep``, so
the stopped process holds no pipe), and each call is given a limit of a
fraction of a second (or ``subprocess.run``'s limit is capped, where the
function takes none)."""

from __future__ import annotations

import ast
import subprocess
import types
from dataclasses import astuple
from pathlib import Path

import pytest

from chebnorm.core import tools
from chebnorm.core.tools import ToolTimeout, run_tool
from conftest import run_cli

SRC = Path(__file__).resolve().parent.parent / "src" / "chebnorm"
FAKES = ("gcc", "sollya", "gappa", "iverilog", "vvp", "ghdl", "yosys", "nextpnr-ice40",
         "glslangValidator")
LIMIT = 0.3


@pytest.fixture
def sleepy_path(tmp_path, monkeypatch):
    """Every tool on PATH is a script that sleeps for a minute."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for name in FAKES:
        exe = bin_dir / name
        exe.write_text("#!/bin/sh\nexec sleep 60\n", encoding="utf-8")
        exe.chmod(0o755)
    monkeypatch.setenv("PATH", f"{bin_dir}:/usr/bin:/bin")
    return bin_dir


@pytest.fixture
def capped(monkeypatch):
    """subprocess.run under run_tool waits at most LIMIT seconds whatever the
    caller's limit (for functions that take no timeout argument)."""
    real = subprocess.run

    def run(*args, timeout=None, **kwargs):
        return real(*args, timeout=min(timeout or LIMIT, LIMIT), **kwargs)
    monkeypatch.setattr(tools, "subprocess", types.SimpleNamespace(
        run=run, DEVNULL=subprocess.DEVNULL, TimeoutExpired=subprocess.TimeoutExpired))


def _one_line(exc, tool: str) -> None:
    text = str(exc)
    assert "\n" not in text and text.startswith(tool)
    assert f"did not finish within its time limit of {exc.timeout:g} s" in text
    assert isinstance(exc, ValueError) and isinstance(exc, subprocess.TimeoutExpired)


def test_run_tool_names_the_tool_and_the_limit(sleepy_path):
    with pytest.raises(ToolTimeout) as info:
        run_tool(["gappa"], tool="gappa", timeout=LIMIT)
    _one_line(info.value, "gappa")
    assert f"{LIMIT:g} s" in str(info.value)


def test_run_tool_takes_no_shell_string():
    with pytest.raises(ValueError, match="no shell"):
        run_tool("echo hi", tool="echo", timeout=1)


def test_gappa(sleepy_path):
    from chebnorm.approx import fit_target
    from chebnorm.hw.budget import gappa_bound
    from chebnorm.hw.horner import design_horner

    d = design_horner(fit_target("dichotomy", 2), 12, 12, coef_bits=18)
    with pytest.raises(ToolTimeout) as info:
        gappa_bound(d, timeout=LIMIT)
    _one_line(info.value, "gappa")


def test_sollya(sleepy_path, capped):
    from chebnorm.approx import sollya

    with pytest.raises(ToolTimeout) as info:
        sollya.supnorm("exp(x)", "x", [1.0, 1.0], "0", "1")
    _one_line(info.value, "sollya")


def test_iverilog_and_vvp(sleepy_path, tmp_path):
    from chebnorm.hw.run_verilog import simulate

    (tmp_path / "m.v").write_text("module m; endmodule\n", encoding="utf-8")
    (tmp_path / "tb_m.v").write_text("module tb_m; endmodule\n", encoding="utf-8")
    with pytest.raises(ToolTimeout) as info:
        simulate(tmp_path, "m", timeout=LIMIT)
    _one_line(info.value, "iverilog")


def test_yosys(sleepy_path, tmp_path):
    from chebnorm.hw.targets import synthesize_target
    from chebnorm.hw.run_verilog import synthesize

    path = tmp_path / "m.v"
    path.write_text("module m(input a, output y); assign y = a; endmodule\n", encoding="utf-8")
    with pytest.raises(ToolTimeout) as info:
        synthesize(path, "m", timeout=LIMIT)
    _one_line(info.value, "yosys")
    with pytest.raises(ToolTimeout) as info:
        synthesize_target(path.read_text(), "m", "generic", timeout=LIMIT)
    _one_line(info.value, "yosys")


def test_ghdl(sleepy_path, tmp_path):
    from chebnorm.hw.run_vhdl import simulate_vhdl

    with pytest.raises(ToolTimeout) as info:
        simulate_vhdl(tmp_path, "m", timeout=LIMIT)
    _one_line(info.value, "ghdl -a")


def test_glslang(sleepy_path):
    from chebnorm.export.gpu import glslang_validate

    with pytest.raises(ToolTimeout) as info:
        glslang_validate("#version 430\nvoid main() {}\n", "glsl", timeout=LIMIT)
    _one_line(info.value, "glslangValidator")


def test_gcc_in_verify_is_one_line_and_exit_2(sleepy_path, capped, tmp_path):
    from chebnorm.approx import fit
    from chebnorm.export.verify import verify

    table = fit("1/x", ("1", "1 + 2**-14"), 2, name="inv")
    with pytest.raises(ToolTimeout) as info:
        verify(table, "c", variant="float")
    _one_line(info.value, "gcc")
    path = tmp_path / "inv.json"
    path.write_text(table.to_json(), encoding="utf-8")
    status, out, err = astuple(run_cli("verify", path, "--variant", "float"))
    assert status == 2 and out == "" and err.count("\n") == 1
    assert "gcc did not finish within its time limit of 300 s" in err and "Traceback" not in err


def test_every_tool_call_in_src_goes_through_run_tool():
    """No subprocess.run/Popen/check_output/call in src/chebnorm except in run_tool."""
    found = []
    for path in sorted(SRC.rglob("*.py")):
        if path == SRC / "core" / "tools.py":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and \
                    node.value.id in ("subprocess", "os") and \
                    node.attr in ("run", "Popen", "call", "check_call", "check_output",
                                  "system", "popen"):
                found.append(f"{path.relative_to(SRC)}:{node.lineno} {node.value.id}.{node.attr}")
            if isinstance(node, ast.ImportFrom) and node.module == "subprocess":
                found.append(f"{path.relative_to(SRC)}:{node.lineno} from subprocess import")
    assert found == []


@pytest.mark.slow
def test_yosys_in_design_is_one_line_and_exit_2(sleepy_path, capped, tmp_path):
    status, out, err = astuple(run_cli("design", "1/sqrt(x)", "--interval", "1", "4",
                                       "--in-bits", "8", "--out-bits", "8", "--faithful",
                                       "--workers", "1", "-o", str(tmp_path / "d")))
    assert status == 2 and err.count("\n") == 1 and "Traceback" not in err
    line = err.split("\r")[-1]  # after the search's progress bar
    assert line.startswith("chebnorm: error: yosys") and "did not finish within its time limit" in line
    assert not (tmp_path / "d").exists() or not any((tmp_path / "d").iterdir())


@pytest.mark.parametrize("outputs, calls, ok", [
    # an ABC child killed by SIGABRT: yosys runs once more
    ([(1, 'ERROR: ABC: execution of command ""berkeley-abc" -s -f ./yosys-abc-x/abc.script '
          '2>&1" failed: return code 134.'), (0, "done")], 2, True),
    # crashing twice is reported
    ([(1, "ERROR: ABC: execution of command \"abc\" failed: return code 134.")] * 2, 2, False),
    # any other failure is reported at once
    ([(1, "ERROR: Module `top' not found!"), (0, "done")], 1, False),
])
def test_an_abc_crash_is_run_once_more(monkeypatch, outputs, calls, ok):
    import subprocess

    from chebnorm.exceptions import ToolFailed
    from chebnorm.hw import targets

    seen = []

    def fake(argv, **kw):
        code, text = outputs[len(seen)]
        seen.append(argv)
        return subprocess.CompletedProcess(argv, code, text, "")

    monkeypatch.setattr(targets, "run_tool", fake)
    if ok:
        assert targets._run(["yosys", "-p", "synth"], ".", "yosys (test)", 60) == "done"
    else:
        with pytest.raises(ToolFailed):
            targets._run(["yosys", "-p", "synth"], ".", "yosys (test)", 60)
    assert len(seen) == calls
