"""Issue 27, outputs: ``cn.export`` prints both kinds of table in every format the
CLI offers for it, the HDL text comes from one printer (``chebnorm.hw.hdl``),
and a piecewise table now has VHDL, bit for bit its model (GHDL, every input code).
"""

from __future__ import annotations

import re
import subprocess
from fractions import Fraction

import mpmath
import pytest

import chebnorm as cn
from chebnorm.approx import fit_target
from chebnorm.approx.piecewise_table import PiecewiseTable
from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.cli import main
from chebnorm.core.files import write_folder
from chebnorm.hw import hdl
from chebnorm.hw.hdl import hdl_files, module_text, vector_file
from chebnorm.hw.piecewise import design_piecewise
from chebnorm.hw.report import analyze
from conftest import requires_tool, run_cli

needs_gcc = requires_tool("gcc")
needs_ghdl = requires_tool("ghdl")
needs_iverilog = requires_tool("iverilog")

#: piecewise tables covering the datapath's cases: uncentred and centred local
#: variable, one segment (no ROM), degree 0 (no Horner step), degree 3, negative values
PIECEWISE = {
    "rs": dict(expr="1/sqrt(x)", interval=("1", "4"), degree=1, segments=4, coef_frac_bits=16),
    "rc": dict(expr="1/sqrt(x)", interval=("1", "4"), degree=2, segments=8, coef_frac_bits=18,
               centered=True),
    "one": dict(expr="exp(x)", interval=("0", "1"), degree=2, segments=1, coef_frac_bits=16),
    "z0": dict(expr="exp(x)", interval=("-1", "1"), degree=0, segments=16, coef_frac_bits=12),
    "s3": dict(expr="sin(x)", interval=("-1", "1"), degree=3, segments=4, coef_frac_bits=20,
               centered=True),
}
#: (table, in_bits, out_bits): up to 12 input bits (4096 codes) keeps GHDL fast;
#: 16 output bits put y's fractional bits past the datapath's (a left shift at the output)
DESIGNS = [("rs", 8, 8), ("rs", 12, 10), ("rc", 10, 12), ("one", 9, 16), ("z0", 8, 16),
           ("s3", 12, 12)]


@pytest.fixture(scope="module")
def tables():
    out = {}
    for name, spec in PIECEWISE.items():
        spec = dict(spec)
        out[name] = piecewise_fit(spec.pop("expr"), spec.pop("interval"), spec.pop("degree"),
                                  name=name, **spec)
    return out


# ---------------------------------------------------------------- every format
def test_every_format_of_each_kind_prints(tables):
    t, pw = fit_target("dichotomy", 1), tables["rs"]
    assert cn.export.formats_for(t) == cn.export.EXPORT_FORMATS
    assert cn.export.formats_for(pw) == ("c", "json", "verilog", "vhdl")
    for fmt in cn.export.EXPORT_FORMATS:
        kw = dict(in_bits=8, out_bits=8, coef_frac_bits=12) if fmt in ("verilog", "vhdl") else {}
        assert cn.export(t, fmt, **kw)
    for fmt in ("c", "json", "verilog", "vhdl"):
        kw = dict(in_bits=8, out_bits=8) if fmt in ("verilog", "vhdl") else {}
        assert cn.export(pw, fmt, **kw)


def test_json_round_trips(tables):
    for pw in tables.values():
        text = cn.export(pw, "json")
        assert text == pw.to_json() and PiecewiseTable.from_json(text) == pw


def _exact(pw: PiecewiseTable, in_bits: int, k: int) -> Fraction:
    """The table's polynomial at input code ``k``, in exact rational arithmetic."""
    L = in_bits - pw.index_bits
    s, low = k >> L, k & ((1 << L) - 1)
    t = Fraction(low, 2 ** L) - (Fraction(1, 2) if pw.centered else 0)
    q = pw.segments[s].integers
    return sum(Fraction(qj, 2 ** pw.coef_frac_bits) * t ** j for j, qj in enumerate(q))


@needs_gcc
@pytest.mark.parametrize("name,in_bits", [("rs", 10), ("rc", 12), ("s3", 11)])
def test_piecewise_c_compiles_and_agrees_with_the_table(tables, tmp_path, name, in_bits):
    """``cn.export(piecewise, "c")`` (a TypeError before): the compiled evaluator
    agrees with the table's exact polynomials within double Horner rounding
    (Higham's gamma_2n sum |c_j| |t|^j, computed here), and with f within the
    header's own EVAL_ERROR_BOUND."""
    pw = tables[name]
    header = cn.export(pw, "c", in_bits=in_bits)
    (tmp_path / f"chebnorm_{name}.h").write_text(header)
    n = 2 ** in_bits
    (tmp_path / "m.c").write_text(
        f"#include <stdio.h>\n#include \"chebnorm_{name}.h\"\nint main(void) {{ "
        f"for (uint32_t k = 0; k < {n}u; k++) printf(\"%a\\n\", chebnorm_{name}(k)); "
        "return 0; }\n")
    subprocess.run(["gcc", "-std=c99", "-O2", "-Wall", "-Werror", "m.c", "-o", "m", "-lm"],
                   cwd=tmp_path, check=True)
    out = subprocess.run(["./m"], cwd=tmp_path, check=True, capture_output=True, text=True)
    ys = [float.fromhex(v) for v in out.stdout.split()]
    assert len(ys) == n
    u = Fraction(1, 2 ** 53)
    g = 2 * pw.degree * u / (1 - 2 * pw.degree * u)
    tmax = Fraction(1, 2) if pw.centered else Fraction(1)
    eval_bound = float(re.search(rf"#define CHEBNORM_{name.upper()}_EVAL_ERROR_BOUND (\S+)",
                                 header).group(1))
    f = mpmath.mpmathify
    lo, hi = (Fraction(v) for v in pw.interval)
    with mpmath.workdps(40):
        fn = {"rs": lambda x: 1 / mpmath.sqrt(x), "rc": lambda x: 1 / mpmath.sqrt(x),
              "s3": mpmath.sin}[name]
        for k, y in enumerate(ys):
            exact = _exact(pw, in_bits, k)
            s = k >> (in_bits - pw.index_bits)
            rnd = g * sum(abs(Fraction(q, 2 ** pw.coef_frac_bits)) * tmax ** j
                          for j, q in enumerate(pw.segments[s].integers))
            assert abs(Fraction(y) - exact) <= rnd + Fraction(2.0 ** -1074), (k, y)
            x = lo + (hi - lo) * Fraction(k, n)
            assert abs(f(y) - fn(f(x.numerator) / x.denominator)) <= eval_bound, k


# ------------------------------------------------------------- piecewise HDL
def _simulate(tmp_path, d, language: str, module: str):
    """Run ``module`` (the text under test) with its bench and the model's
    vectors; return the simulator's verdict and the outputs it saw (VHDL)."""
    from chebnorm.hw.run_verilog import simulate
    from chebnorm.hw.run_vhdl import simulate_vhdl

    ext = ".v" if language == "verilog" else ".vhd"
    name = d.module_name
    write_folder(tmp_path, {f"{name}{ext}": module, f"tb_{name}{ext}": hdl.testbench_text(d, language),
                            f"{name}.hex": vector_file(d)})
    if language == "verilog":
        return simulate(tmp_path, name), None
    res = simulate_vhdl(tmp_path, name)
    seen = (tmp_path / f"{name}_vhdl_y.hex").read_text().split()
    return res, [int(w, 16) for w in seen]


@needs_ghdl
@pytest.mark.parametrize("name,in_bits,out_bits", DESIGNS)
def test_piecewise_vhdl_is_the_model_on_every_code(tables, tmp_path, name, in_bits, out_bits):
    """The exported VHDL, simulated by GHDL over every input code, outputs the
    bit-accurate model's codes (compared here code by code, and by the bench)."""
    pw = tables[name]
    d = design_piecewise(pw, in_bits, out_bits)
    text = cn.export(pw, "vhdl", "cmd", in_bits=in_bits, out_bits=out_bits)
    assert text == module_text(d, "vhdl", version=cn.__version__, command="cmd")
    res, seen = _simulate(tmp_path, d, "vhdl", text)
    assert seen == d.evaluate().tolist()
    assert res.passed and res.vectors == 2 ** in_bits and res.mismatches == 0, res.line


@needs_iverilog
@pytest.mark.parametrize("name,in_bits,out_bits", DESIGNS[:3])
def test_piecewise_verilog_export_is_the_model_on_every_code(tables, tmp_path, name, in_bits,
                                                             out_bits):
    pw = tables[name]
    d = design_piecewise(pw, in_bits, out_bits)
    text = cn.export(pw, "verilog", in_bits=in_bits, out_bits=out_bits)
    res, _ = _simulate(tmp_path, d, "verilog", text)
    assert res.passed and res.vectors == 2 ** in_bits, res.line


@needs_ghdl
def test_piecewise_vhdl_bench_sees_a_wrong_vector(tables, tmp_path):
    d = design_piecewise(tables["rc"], 8, 8)
    files = hdl_files(d, "vhdl")
    words = files["chebnorm_rc.hex"].split("\n")
    words[77] = f"{int(words[77], 16) ^ 1:02x}"
    files["chebnorm_rc.hex"] = "\n".join(words)
    write_folder(tmp_path, files)
    from chebnorm.hw.run_vhdl import simulate_vhdl

    res = simulate_vhdl(tmp_path, d.module_name)
    assert not res.passed and res.mismatches == 1 and res.vectors == 256


@needs_ghdl
def test_cli_piecewise_vhdl(tables, tmp_path, capsys):
    path = tmp_path / "rc.json"
    tables["rc"].save(path)
    assert main(["export", str(path), "--format", "vhdl", "--in-bits", "10", "--out-bits", "10",
                 "-o", str(tmp_path / "rc.vhd")]) == 0
    text = (tmp_path / "rc.vhd").read_text()
    assert "entity chebnorm_rc is" in text and "_pipe" not in text
    subprocess.run(["ghdl", "-a", "--std=08", "rc.vhd"], cwd=tmp_path, check=True)
    assert main(["hw", "verilog", str(path), "--in-bits", "10", "--out-bits", "10", "--lang",
                 "vhdl", "--simulate", "-o", str(tmp_path / "hw")]) == 0
    out = capsys.readouterr().out
    assert "PASS: 1024 vectors, 0 mismatches (chebnorm_rc)" in out
    written = [line.rsplit("/", 1)[-1] for line in out.splitlines() if "/" in line]
    assert written == ["chebnorm_rc.hex", "chebnorm_rc.vhd", "tb_chebnorm_rc.vhd"]


# ------------------------------------------------------- Python equals the CLI
def _cli_text(argv, out) -> tuple[str, str]:
    """The file ``chebnorm ARGV -o OUT`` writes, and the command its banner names."""
    r = run_cli(*argv, "-o", out)
    assert r.code == 0, r.err
    text = out.read_text()
    command = re.search(r"^(?://|--|/?\s?\*) Command: (.*)$", text, re.M).group(1)
    return text, command


@pytest.mark.parametrize("fmt", ["verilog", "vhdl"])
def test_python_export_is_the_cli_output_byte_for_byte(tables, tmp_path, fmt):
    t = fit_target("dichotomy", 2)
    src = tmp_path / "t.json"
    t.save(src)
    opts = ["--in-bits", "9", "--out-bits", "10", "--coef-frac-bits", "14", "--acc-bits", "15",
            "--rounding", "trunc"]
    text, command = _cli_text(["export", str(src), "--format", fmt, *opts], tmp_path / "o")
    assert cn.export(t, fmt, command, in_bits=9, out_bits=10, coef_frac_bits=14, acc_bits=15,
                     rounding="trunc") == text
    text, command = _cli_text(["export", str(src), "--format", fmt, "--in-bits", "8",
                               "--out-bits", "8", "--coef-frac-bits", "12"], tmp_path / "p")
    assert cn.export(t, fmt, command, in_bits=8, out_bits=8, coef_frac_bits=12) == text
    pw = tables["s3"]
    pw.save(tmp_path / "pw.json")
    text, command = _cli_text(["export", str(tmp_path / "pw.json"), "--format", fmt,
                               "--in-bits", "11", "--out-bits", "9"], tmp_path / "q")
    assert cn.export(pw, fmt, command, in_bits=11, out_bits=9) == text


def test_python_piecewise_c_is_the_cli_output_byte_for_byte(tables, tmp_path):
    pw = tables["rc"]
    pw.save(tmp_path / "pw.json")
    text, command = _cli_text(["export", str(tmp_path / "pw.json"), "--format", "c",
                               "--in-bits", "14"], tmp_path / "o.h")
    assert cn.export(pw, "c", command, in_bits=14) == text
    text, command = _cli_text(["export", str(tmp_path / "pw.json"), "--format", "c"],
                              tmp_path / "p.h")
    assert cn.export(pw, "c", command) == text and "_IN_BITS 24" in text


# ------------------------------------------------------------------- the banner
def _banner(text: str, language: str) -> list[str]:
    """The header comment of the first module, markers removed."""
    marker = "//" if language == "verilog" else "--"
    head = []
    for line in text.splitlines():
        if not line.startswith(marker):
            break
        head.append(line[len(marker):].strip())
    return head


def test_vhdl_and_verilog_banners_state_the_same_facts(tables):
    """The same lines, in each language's comment syntax; the one word that may
    differ is each language's name for the width constants."""
    r = analyze(fit_target("dichotomy", 2), 10, 10, coef_frac_bits=14, gappa=False, synth=False)
    kw = dict(version="1.2.3", command="chebnorm hw verilog t.json --in-bits 10 -o o",
              budget=r.budget)
    cases = [(r.design, False), (r.design, True), (design_piecewise(tables["rc"], 10, 10), False)]
    for d, pipelined in cases:
        v = _banner(module_text(d, "verilog", pipelined=pipelined, **kw), "verilog")
        h = _banner(module_text(d, "vhdl", pipelined=pipelined, **kw), "vhdl")
        assert len(v) >= 9 and len(v) == len(h)
        assert [line.replace("parameters", "generics") for line in v] == h
        joined = "\n".join(v)
        assert "chebnorm 1.2.3" in joined and "Command: chebnorm hw verilog" in joined
        assert ("Error budget" in joined) and ("Rounding: " in joined)


def test_banner_text_is_inert_in_both_languages(tables):
    """A hostile command line stays one comment line in both languages."""
    d = design_piecewise(tables["rs"], 8, 8)
    bad = "x */ y\n`define EVIL\r\n-- evil \\"
    for language, marker in (("verilog", "//"), ("vhdl", "--")):
        text = module_text(d, language, command=bad)
        head = text.split("module " if language == "verilog" else "library ieee;")[0]
        assert all(line.startswith(marker) for line in head.splitlines())
        assert "EVIL" not in text.split("module " if language == "verilog" else
                                        "library ieee;")[1]


# --------------------------------------------------------------------- errors
@pytest.mark.parametrize("call,message", [
    (lambda t, pw: cn.export(t, "vhdl", in_bits=8),
     r"^format 'vhdl' needs in_bits and out_bits"),
    (lambda t, pw: cn.export(t, "glsl", in_bits=8),
     r"^in_bits does nothing with format 'glsl' of a coefficient table; accepted there: "
     r"no option$"),
    (lambda t, pw: cn.export(pw, "json", in_bits=8),
     r"^in_bits does nothing with format 'json' of a piecewise table"),
    (lambda t, pw: cn.export(pw, "vhdl", in_bits=8, out_bits=8, rounding="trunc"),
     r"^rounding does nothing with format 'vhdl' of a piecewise table; accepted there: "
     r"in_bits, out_bits$"),
    (lambda t, pw: cn.export(pw, "glsl"),
     r"^format 'glsl' is not available for a piecewise table; accepted: c, json, verilog, "
     r"vhdl$"),
    (lambda t, pw: cn.export(t, "verilog", in_bits="8", out_bits=8),
     r"^in_bits = '8' is not an integer"),
    (lambda t, pw: cn.export(pw, "spirv"),
     r"^unknown export format 'spirv'; accepted: c, glsl, hlsl, json, verilog, vhdl, wgsl$"),
    (lambda t, pw: cn.export(None, "c"), r"^table of type NoneType is not accepted"),
])
def test_python_errors_name_the_argument(tables, call, message):
    t = fit_target("dichotomy", 1)
    with pytest.raises(ValueError, match=message) as info:
        call(t, tables["rs"])
    assert "--" not in str(info.value)


def test_cli_piecewise_format_errors(tables, tmp_path, capsys):
    tables["rs"].save(tmp_path / "pw.json")
    for argv, words in ((["--format", "glsl"], "accepted: c, json, verilog, vhdl"),
                        (["--format", "vhdl", "--in-bits", "8"], "--format vhdl needs --in-bits "
                         "and --out-bits"),
                        (["--format", "vhdl", "--in-bits", "8", "--out-bits", "8", "--acc-bits",
                          "9"], "--acc-bits does nothing with --format vhdl of a piecewise "
                         "table; accepted there: --in-bits --out-bits")):
        assert main(["export", str(tmp_path / "pw.json"), *argv, "-o",
                     str(tmp_path / "x")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and words in err[0], err
        assert not (tmp_path / "x").exists()
