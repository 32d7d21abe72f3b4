"""Default module names (issue 44): a design's, like a table's, comes from its
spec, so the HDL of different fits and designs coexists in one build."""

from __future__ import annotations

import json
import re
import subprocess

import pytest

from chebnorm.core.textsafe import default_name, design_name, identifier
from conftest import requires_tool, run_cli
from quiet_cli import run_cli_quiet

# a VHDL basic identifier (no leading, trailing or doubled underscore), which is a
# Verilog and C identifier too
VHDL_IDENT = re.compile(r"[A-Za-z](_?[A-Za-z0-9])*\Z")
SPEC = ["--in-bits", "6", "--out-bits", "6", "--correctly-rounded"]


@pytest.mark.parametrize("expr, interval, tags", [
    ("1/sqrt(x)", ("1", "4"), ("faithful",)),
    ("exp(-x**2)", ("-1/2", "0.75"), ("e", "2^-10")),
    ("2*x", ("0", "1"), ("cr",)),                       # a digit first: led by f
    ("log2(1+x)" * 12, ("-pi/4", "pi/4"), ("e", "1e-05")),   # long: cut and hashed
    ("__x__ + _y_", ("-_-", "+"), ("_",)),              # no runs of underscores
])
def test_design_name_is_a_vhdl_identifier_with_room_for_suffixes(expr, interval, tags):
    name = design_name(expr, interval, 6, 6, tags=tags)
    assert VHDL_IDENT.match(name), name
    # the derived modules (architectures.py, exponent.py) are identifiers too
    for suffix in ("_table", "_mp", "_core", "_sized_d12"):
        identifier(name + suffix)
    assert name == design_name(expr, interval, 6, 6, tags=tags)   # deterministic


def test_design_name_tells_specs_apart():
    names = {design_name("1/sqrt(x)", ("1", "4"), 8, 8, tags=t)
             for t in [("faithful",), ("cr",), ("e", "2^-6")]}
    names |= {design_name("1/sqrt(x)", ("1", "4"), i, o, tags=("cr",))
              for i, o in [(8, 10), (10, 8)]}
    names |= {design_name("1/sqrt(x)", iv, 8, 8, tags=("cr",)) for iv in [("1", "2"), ("2", "4")]}
    assert len(names) == 7
    assert design_name("1/sqrt(x)", ("1", "4"), 8, 8, tags=("cr",)) == "rsqrt_1_4_i8_o8_cr"
    # the long name is cut at 44 characters, keeping its hash
    a = design_name("sin(x)+" * 10, ("0", "1"), 8, 8)
    b = design_name("sin(x)+" * 10 + "1", ("0", "1"), 8, 8)
    assert len(a) == len(b) == 44 and a != b


@requires_tool("yosys")
def test_two_default_designs_synthesize_in_one_yosys_run(tmp_path):
    mods = []
    for i, (expr, iv) in enumerate([("1/sqrt(x)", ("1", "4")), ("log2(1+x)", ("0", "1"))]):
        out = tmp_path / f"d{i}"
        r = run_cli_quiet("design", expr, "--interval", *iv, *SPEC, "-o", out)
        assert r.code == 0, r.err
        [v] = out.glob("*.v")
        [vhd] = out.glob("*.vhd")
        assert v.stem == vhd.stem
        mods.append(v)
    assert [m.stem for m in mods] == ["chebnorm_rsqrt_1_4_i6_o6_cr_table",
                                      "chebnorm_log2_1_x_0_1_i6_o6_cr_table"]
    # both read and elaborated in one run: no "Re-definition of module"
    res = subprocess.run(["yosys", "-q", "-p", f"read_verilog {mods[0]} {mods[1]}; "
                          f"hierarchy; proc; stat"], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr + res.stdout
    # --name still names it
    out = tmp_path / "named"
    r = run_cli_quiet("design", "1/sqrt(x)", "--interval", "1", "4", *SPEC, "--name", "mine",
                      "-o", out)
    assert r.code == 0, r.err
    assert (out / "chebnorm_mine_table.v").exists()
    assert (out / "design_mine_architectures.csv").exists()


def test_design_default_name_from_the_max_error_value(tmp_path):
    argv = ["design", "1/sqrt(x)", "--interval", "1", "4", "--in-bits", "8", "--out-bits", "8",
            "--degrees", "1", "--max-segments", "2^3", "--no-synth", "--workers", "1"]
    r = run_cli_quiet(*argv, "--max-error", "2^-5", "-o", tmp_path / "a")
    assert r.code == 0, r.err
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == [
        "design_rsqrt_1_4_i8_o8_e_2_m5.csv", "design_rsqrt_1_4_i8_o8_e_2_m5.png"]
    # a refused --max-error is refused by its own message, not by the name
    code, out, err = run_cli(*argv, "--max-error", "-1", "-o", tmp_path / "b")
    assert code == 2 and "--max-error" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("shape, expected", [
    (["--degree", "1", "--segments", "4"], "rsqrt_1_4_d1_s4"),   # piecewise
    (["--degree", "2"], "rsqrt_1_4_d2"),                          # one polynomial (Horner)
])
def test_hw_verilog_and_report_default_module_is_the_tables_default_name(tmp_path, shape,
                                                                         expected):
    table = tmp_path / "t.json"
    r = run_cli_quiet("fit", "1/sqrt(x)", "--interval", "1", "4", *shape, "--kind", "minimax",
                      "--coef-frac-bits", "10", "-o", table)
    assert r.code == 0, r.err
    name = json.loads(table.read_text())["name"]
    segments = int(shape[3]) if len(shape) > 2 else None
    assert name == default_name("1/sqrt(x)", ("1", "4"), int(shape[1]), segments=segments)
    assert name == expected and VHDL_IDENT.match(name)
    r = run_cli_quiet("hw", "verilog", table, "--in-bits", "6", "--out-bits", "6", "-o",
                      tmp_path / "v")
    assert r.code == 0, r.err
    assert f"chebnorm_{name}.v" in {p.name for p in (tmp_path / "v").iterdir()}
    r = run_cli_quiet("hw", "report", table, "--in-bits", "6", "--out-bits", "6", "--no-synth",
                      "--json")
    assert r.code == 0, r.err
    assert json.loads(r.out)["module"] == f"chebnorm_{name}"


def test_exponent_design_default_name_says_its_index(tmp_path):
    out = tmp_path / "x"
    r = run_cli_quiet("design", "1/sqrt(x)", "--index", "exponent", "--interval", "2^-8", "1",
                      "--in-bits", "8", "--out-bits", "8", "--faithful", "--degrees", "1",
                      "--no-synth", "-o", out)
    assert r.code == 0, r.err
    name = "rsqrt_2_m8_1_i8_o8_faithful_lz"   # lz: the leading-zero (exponent) index
    assert {f"chebnorm_{name}.v", f"chebnorm_{name}.vhd",
            f"design_{name}_architectures.csv"} <= {p.name for p in out.iterdir()}
