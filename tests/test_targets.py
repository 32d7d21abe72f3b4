"""Shader (GLSL, WGSL, HLSL) and VHDL targets: text, escaping, and real tools.

The shader checks compile every export with glslangValidator and run the
GLSL and WGSL functions on Mesa's llvmpipe / lavapipe over every float32 of
the interval (or 2^20 of them), against ``f`` evaluated independently (numpy
float64, and mpmath at 40 digits wherever the float64 reference is too close
to the bound to decide). The VHDL checks run GHDL on the generated benches
and compare its outputs code for code with Icarus Verilog's.
"""

from __future__ import annotations

import json
import math
import re
import subprocess
from dataclasses import replace
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp

from chebnorm.approx import CoefficientTable, fit
from chebnorm.approx.contract import construction
from chebnorm.export import c_header
from chebnorm.export.shader import (SHADER_LANGUAGES, float32_eval_bound, float32_literal,
                                    shader_source)
from conftest import requires_tool, run_cli
from quiet_cli import run_cli_quiet

ROOT = Path(__file__).resolve().parents[1]
TABLES = sorted((ROOT / "figures" / "coefficients").glob("*.json"))
FITS = {  # three fits of our choosing: a zero endpoint, a minimax fit, degree 5
    "cos6": ("cos(x)", ("0", "pi/2"), 6, "chebyshev"),
    "sqrt4": ("sqrt(x)", ("1/4", "1"), 4, "minimax"),
    "exp5": ("exp(x)", ("-1", "1"), 5, "chebyshev"),
}
_FIT_CACHE: dict = {}


def _table(key: str) -> CoefficientTable:
    if key not in _FIT_CACHE:
        if key in FITS:
            expr, iv, deg, kind = FITS[key]
            _FIT_CACHE[key] = fit(expr, iv, deg, kind=kind, name=key)
        else:
            _FIT_CACHE[key] = CoefficientTable.load(ROOT / "figures" / "coefficients" / key)
    return _FIT_CACHE[key]


ALL = [p.name for p in TABLES] + list(FITS)


def test_registered_tables_present():
    assert len(TABLES) == 8


# -- literals and the bound (no tools) ------------------------------------------------------

def _mp_round24(num: int, den: int) -> float:
    """num/den rounded once to 24 significant bits, nearest-even (mpmath's exact
    rational rounding; normal float32 range only)."""
    return float(mpmath.mpf(mpmath.libmp.from_rational(num, den, 24, mpmath.libmp.round_nearest)))


@pytest.mark.parametrize("value", [0.1, -0.11881066410044379, 1.0, 3.4e38, 1.17549435e-38,
                                   2.0 ** -149, 16777217.0, 0.6807562243159899, 1e-45])
def test_float32_literal_exact(value):
    target = float(np.float32(value))
    s = float32_literal(value)
    # a correctly rounding compiler (mpmath rounds the decimal straight to 24 bits) ...
    num, den = Decimal(s).as_integer_ratio()
    if abs(target) >= 2.0 ** -126:  # mpmath has no subnormals: check normal numbers this way
        assert _mp_round24(num, den) == target
    # ... and one that reads a double first, then narrows (double rounding)
    assert float(np.float32(float(Decimal(s)))) == target
    assert len(s.replace("-", "").split("e")[0].replace(".", "").lstrip("0")) <= 100


def test_float32_literal_random():
    rng = np.random.default_rng(0)
    bits = rng.integers(0, 2 ** 31 - 2 ** 23, size=2000, dtype=np.int64).astype(np.uint32)
    for v in bits.view(np.float32):
        s = float32_literal(float(v))
        assert np.float32(float(Decimal(s))) == v
        num, den = Decimal(s).as_integer_ratio()
        if v >= np.float32(2.0 ** -126):
            assert _mp_round24(num, den) == float(v)


def test_float32_literal_refuses_overflow():
    with pytest.raises(ValueError, match="not finite in float32"):
        float32_literal(1e39)


@pytest.mark.parametrize("key", ALL)
def test_bound_matches_the_c_header_float_bound(key):
    """Without the flush term the shader bound is the C header's float bound."""
    t = _table(key)
    b = float32_eval_bound(t)
    m = re.search(r"_F_EVAL_ERROR_BOUND (\S+)", c_header(t))
    c_float = float.fromhex(m.group(1))
    assert b.flush < Fraction(2) ** -100
    assert b.total >= c_float
    # total = (the float bound + flush) rounded up to a double: one ulp above
    assert b.total - float(b.flush) <= math.nextafter(c_float, math.inf)
    assert b.total32 >= b.total and float(np.float32(b.total32)) == b.total32


def _reference(t: CoefficientTable):
    x = sp.Symbol(t.variable)
    e = sp.sympify(t.expression, locals={t.variable: x})
    return sp.lambdify([x], e, "numpy"), sp.lambdify([x], e, "mpmath")


def _check_against_f(t: CoefficientTable, xs: np.ndarray, ys: np.ndarray, bound: float) -> float:
    """max |ys - f(xs)|, asserting it is within ``bound``: float64 decides where it
    is clearly inside; mpmath (40 digits) decides the points within 2^-40 |f| of it."""
    f64, fmp = _reference(t)
    ref = np.asarray(f64(xs.astype(np.float64)), dtype=np.float64) * np.ones_like(xs, np.float64)
    err = np.abs(ys.astype(np.float64) - ref)
    slack = 2.0 ** -40 * max(1.0, float(np.max(np.abs(ref))))
    doubtful = np.flatnonzero(err > bound - slack)
    worst = np.argsort(err)[-16:]
    with mpmath.workdps(40):
        for i in np.union1d(doubtful, worst):
            true = abs(mpmath.mpf(float(ys[i])) - fmp(mpmath.mpf(float(xs[i]))))
            assert true <= bound, (t.name, float(xs[i]), float(true), bound)
    return float(err.max())


def _numpy_horner32(t: CoefficientTable, xs: np.ndarray) -> np.ndarray:
    """Unfused float32 Horner: numpy's float32 * and + are correctly rounded."""
    c = [np.float32(v) for v in t.coefficients]
    acc = np.full(xs.shape, c[-1], dtype=np.float32)
    for ck in reversed(c[:-1]):
        acc = (acc * xs).astype(np.float32) + ck
    return acc.astype(np.float32)


def _fused_horner32(t: CoefficientTable, xs: np.ndarray) -> np.ndarray:
    """Fused float32 Horner, exactly: acc*x+c in rationals of float64 parts,
    rounded once (a float32 product is exact in float64; the sum is rounded
    to float64 with a sticky correction before the final float32 rounding)."""
    c = [np.float32(v) for v in t.coefficients]
    out = np.empty(xs.shape, dtype=np.float32)
    for i, x in enumerate(xs):
        acc = c[-1]
        for ck in reversed(c[:-1]):
            exact = Fraction(float(acc)) * Fraction(float(x)) + Fraction(float(ck))
            acc = np.float32(_round32(exact))
        out[i] = acc
    return out


def _round32(q: Fraction) -> float:
    return _mp_round24(q.numerator, q.denominator)


@pytest.mark.parametrize("key", ALL)
def test_bound_covers_cpu_float32_horner(key):
    """The bound holds for an unfused (numpy) and a fused (exact rounding)
    float32 evaluation, without any GPU."""
    from chebnorm.export.gpu import float32_inputs

    t = _table(key)
    b = float32_eval_bound(t)
    xs = float32_inputs(t, 2 ** 16)
    _check_against_f(t, xs, _numpy_horner32(t, xs), b.total)
    few = xs[:: max(1, xs.size // 512)]
    _check_against_f(t, few, _fused_horner32(t, few), b.total)


# -- text -----------------------------------------------------------------------------------

def _tiny(name="t1", expression="1/sqrt(z + 2)"):
    t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 1, var="z", name="t1")
    return replace(t, name=name, expression=expression)


def test_exact_text_of_the_evaluators():
    t = _tiny()
    c = [float(np.float32(v)) for v in t.coefficients]
    lit = {k: float32_literal(v) for k, v in enumerate(c)}
    g = shader_source(t, "glsl")
    assert ("float chebnorm_t1(float x)\n{\n"
            f"    CHEBNORM_T1_PRECISE float acc = {lit[1]};  // x^1: {c[1].hex()}\n"
            f"    acc = CHEBNORM_T1_FMA(acc, x, {lit[0]});  // x^0: {c[0].hex()}\n"
            "    return acc;\n}\n#undef CHEBNORM_T1_PRECISE\n#undef CHEBNORM_T1_FMA\n") in g
    w = shader_source(t, "wgsl")
    assert ("fn chebnorm_t1(x: f32) -> f32 {\n"
            f"    var acc: f32 = {lit[1]}f;  // x^1: {c[1].hex()}\n"
            f"    acc = fma(acc, x, {lit[0]}f);  // x^0: {c[0].hex()}\n"
            "    return acc;\n}\n") in w
    h = shader_source(t, "hlsl")
    assert f"    acc = mad(acc, x, {lit[0]}f);" in h
    assert "static const float CHEBNORM_T1_EVAL_ERROR_BOUND = " in h
    b = float32_eval_bound(t)
    assert f"const CHEBNORM_T1_EVAL_ERROR_BOUND: f32 = {float32_literal(b.total32)}f;" in w


def test_interval_constants_round_inward():
    t = _tiny()
    g = shader_source(t, "glsl")
    lo = float(re.search(r"CHEBNORM_T1_LO = (\S+);", g).group(1))
    hi = float(re.search(r"CHEBNORM_T1_HI = (\S+);", g).group(1))
    assert t.interval_float[0] <= lo and hi <= t.interval_float[1]
    assert np.float32(lo) == lo and np.float32(hi) == hi


HOSTILE = ["1/sqrt(z)\n#define chebnorm_evil 1\nvoid evil() {}",
           "*/ evil(); /*", "/* /* nested", "x \\\nevil();", "a -- b\r\nend architecture;",
           "??/\nint evil;"]


@pytest.mark.parametrize("language", list(SHADER_LANGUAGES))
@pytest.mark.parametrize("hostile", HOSTILE)
def test_hostile_text_stays_in_comments(language, hostile):
    with construction("unchecked"):  # the constructor refuses it: test the printer alone
        t = replace(_tiny(), expression=hostile, provenance={"command": hostile})
    text = shader_source(t, language, command=hostile)
    clean = shader_source(_tiny(), language)
    # the hostile text changes comment lines only: the code lines are those of a clean table
    code = [ln for ln in text.splitlines() if not ln.lstrip().startswith("//")]
    assert code == [ln for ln in clean.splitlines() if not ln.lstrip().startswith("//")]
    for ln in text.splitlines():
        if ln.startswith("//"):
            assert "*/" not in ln and "/*" not in ln and not ln.endswith("\\")
    assert "evil" not in "\n".join(code)


@pytest.mark.parametrize("name", ["a b", "x;y", "é", "1abc", "a*/b", "", "n\nm"])
def test_hostile_names_refused(name):
    with pytest.raises(ValueError, match="^name: .* is not an identifier"):
        _tiny(name=name)  # the table's constructor refuses it
    with construction("unchecked"):  # and the printers do on their own
        t = _tiny(name=name)
    for language in SHADER_LANGUAGES:
        with pytest.raises(ValueError, match="is not an identifier"):
            shader_source(t, language)


# -- glslangValidator -----------------------------------------------------------------------

need_glslang = requires_tool("glslangValidator")


@need_glslang
@pytest.mark.parametrize("key", ALL)
def test_glslang_compiles_every_export(key):
    from chebnorm.export.gpu import compute_shader_source, glslang_validate

    t = _table(key)
    glslang_validate(compute_shader_source(t, "glsl"), "glsl")
    glslang_validate(compute_shader_source(t, "glsl", es=True), "glsl")
    glslang_validate(compute_shader_source(t, "hlsl"), "hlsl")


@need_glslang
def test_glslang_rejects_broken_code():
    """The compile check can fail: a syntax error is reported."""
    from chebnorm.export.gpu import compute_shader_source, glslang_validate

    src = compute_shader_source(_tiny(), "glsl").replace("return acc;", "return acc")
    with pytest.raises(ValueError, match="glslangValidator rejected"):
        glslang_validate(src, "glsl")


@need_glslang
@pytest.mark.parametrize("hostile", HOSTILE)
def test_glslang_compiles_hostile_tables(hostile):
    from chebnorm.export.gpu import compute_shader_source, glslang_validate

    with construction("unchecked"):  # the constructor refuses it: test the printer alone
        t = replace(_tiny(), expression=hostile, provenance={"command": hostile})
    glslang_validate(compute_shader_source(t, "glsl"), "glsl")
    glslang_validate(compute_shader_source(t, "hlsl"), "hlsl")


# -- real drivers ---------------------------------------------------------------------------

def _gl():
    from chebnorm.export.gpu import ToolMissing, gl_context

    try:
        return gl_context()
    except ToolMissing as exc:
        pytest.skip(str(exc))


@pytest.mark.parametrize("key", ALL)
def test_glsl_on_llvmpipe_within_bound(key):
    from chebnorm.export.gpu import float32_inputs, glsl_evaluate

    _gl()
    t = _table(key)
    xs = float32_inputs(t)
    ys = glsl_evaluate(t, xs)
    assert ys.shape == xs.shape and np.all(np.isfinite(ys))
    worst = _check_against_f(t, xs, ys, float32_eval_bound(t).total)
    assert worst >= t.max_abs_error * 0.5  # the kernel really computed p (not a constant)


@pytest.fixture(scope="module")
def wgpu_device():
    try:
        import wgpu
    except ImportError:
        pytest.skip("wgpu is not installed (pip install 'chebnorm[gpu]')")
    try:
        return wgpu.utils.get_default_device()
    except Exception as exc:  # the driver's own error types
        pytest.skip(f"no WebGPU adapter: {exc} (apt-get install mesa-vulkan-drivers)")


@pytest.mark.parametrize("key", ALL)
def test_wgsl_on_lavapipe_within_bound(key, wgpu_device):
    from chebnorm.export.gpu import float32_inputs, wgsl_evaluate

    t = _table(key)
    xs = float32_inputs(t)
    ys = wgsl_evaluate(t, xs)
    assert ys.shape == xs.shape and np.all(np.isfinite(ys))
    worst = _check_against_f(t, xs, ys, float32_eval_bound(t).total)
    assert worst >= t.max_abs_error * 0.5


def test_glsl_and_wgsl_interleaved_agree(wgpu_device):
    """GL after WebGPU in one process (the GL context is made current again)
    gives the same bits as before; both stay within the bound (the drivers
    may round differently: fused or not)."""
    from chebnorm.export.gpu import float32_inputs, glsl_evaluate, wgsl_evaluate

    _gl()
    t = _table("rsqrt_d3.json")
    xs = float32_inputs(t, 4096)
    a = glsl_evaluate(t, xs)
    b = wgsl_evaluate(t, xs)
    c = glsl_evaluate(t, xs)
    assert xs.size == 4096
    assert np.array_equal(a, c)
    _check_against_f(t, xs, b, float32_eval_bound(t).total)


def test_wgsl_invalid_module_is_rejected(wgpu_device):
    """naga (inside wgpu) validates the WGSL: a type error does not run."""
    from chebnorm.export import gpu

    t = _tiny()
    good = gpu.compute_shader_source(t, "wgsl")
    bad = good.replace("var acc: f32 =", "var acc: i32 =")
    from wgpu.utils.compute import compute_with_buffers

    with pytest.raises(Exception):
        compute_with_buffers({0: np.ones(64, np.float32)}, {1: (64, "f")}, bad, n=(1, 1, 1))


# -- VHDL -----------------------------------------------------------------------------------

need_ghdl = requires_tool("ghdl")
need_iverilog = requires_tool("iverilog", "vvp")


def _verilog_dump(directory: Path, design) -> Path:
    """Run the Verilog module over every code in iverilog and dump y, one hex word a line."""
    name = design.module_name
    digits = (design.out_bits + 3) // 4
    bench = "\n".join([
        "module dump;",
        f"    reg [{design.in_bits - 1}:0] x;",
        f"    wire [{design.out_bits - 1}:0] y;",
        "    integer i, fd;",
        f"    {name} dut (.x(x), .y(y));",
        "    initial begin",
        f"        fd = $fopen(\"{name}_verilog_y.hex\", \"w\");",
        f"        for (i = 0; i < {2 ** design.in_bits}; i = i + 1) begin",
        "            x = i;",
        "            #1;",
        f"            $fdisplay(fd, \"%0{digits}h\", y);",
        "        end",
        "        $fclose(fd);",
        "        $finish;",
        "    end",
        "endmodule", ""])
    (directory / "dump.v").write_text(bench)
    subprocess.run(["iverilog", "-g2005", "-o", "dump.vvp", "dump.v", f"{name}.v"],
                   cwd=directory, check=True, capture_output=True)
    subprocess.run(["vvp", "-n", "dump.vvp"], cwd=directory, check=True, capture_output=True)
    return directory / f"{name}_verilog_y.hex"


def _hw(tmp_path, table_path, in_bits, out_bits, *extra):
    out = tmp_path / "hw"
    for lang in ("verilog", "vhdl"):
        proc = run_cli("hw", "verilog", table_path, "--in-bits", str(in_bits), "--out-bits",
                       str(out_bits), "--lang", lang, "-o", out, "--simulate", *extra)
        assert proc.code == 0, proc.err
        assert "FAIL" not in proc.out
    return out, proc.out


@requires_tool("ghdl", "iverilog", "vvp")  # one marker: the hook reads the closest only
@pytest.mark.slow
def test_vhdl_dichotomy_d2_16_bits_all_codes_and_agrees_with_iverilog(tmp_path):
    """Acceptance: 65,536 codes, 0 mismatches in GHDL, and GHDL's outputs equal
    iverilog's code for code."""
    from chebnorm.hw.report import analyze

    path = ROOT / "figures" / "coefficients" / "dichotomy_d2.json"
    out, stdout = _hw(tmp_path, path, 16, 16)
    assert "PASS: 65536 vectors, 0 mismatches (chebnorm_dichotomy_d2)" in stdout
    design = analyze(CoefficientTable.load(path), 16, 16, gappa=False, synth=False).design
    vlog = _verilog_dump(out, design).read_text().split()
    vhdl = (out / "chebnorm_dichotomy_d2_vhdl_y.hex").read_text().split()
    assert len(vhdl) == len(vlog) == 65536
    assert vhdl == vlog
    assert vhdl == (out / "chebnorm_dichotomy_d2.hex").read_text().split()


@requires_tool("ghdl", "iverilog", "vvp")  # one marker: the hook reads the closest only
@pytest.mark.parametrize("table,bits,kw", [
    ("rsqrt_d3.json", 9, {"rounding": "trunc"}),
    ("midpoint_d1.json", 8, {}),
    ("eta_term_d2.json", 8, {"coef_frac_bits": 12, "acc_bits": 6}),
])
def test_vhdl_pipelined_and_combinational_agree_with_verilog(tmp_path, table, bits, kw):
    from chebnorm.hw.report import analyze, verilog_outputs
    from chebnorm.hw.run_verilog import simulate
    from chebnorm.hw.run_vhdl import simulate_vhdl, vhdl_outputs

    report = analyze(CoefficientTable.load(ROOT / "figures" / "coefficients" / table), bits,
                     bits, gappa=False, synth=False, **kw)
    design = report.design
    files = {**verilog_outputs(report, pipelined=True), **vhdl_outputs(report, pipelined=True)}
    for k, v in files.items():
        (tmp_path / k).write_text(v)
    for name in (design.module_name, design.module_name + "_pipe"):
        assert simulate(tmp_path, name).passed
        res = simulate_vhdl(tmp_path, name)
        assert res.passed and res.vectors == 2 ** bits, res.line
    vlog = _verilog_dump(tmp_path, design).read_text().split()
    for name in (design.module_name, design.module_name + "_pipe"):
        assert (tmp_path / f"{name}_vhdl_y.hex").read_text().split() == vlog


@need_ghdl
def test_vhdl_bench_detects_a_wrong_vector(tmp_path):
    """The bench can fail: one corrupted expected word is one mismatch."""
    from chebnorm.hw.report import analyze
    from chebnorm.hw.run_vhdl import simulate_vhdl, vhdl_outputs

    t = CoefficientTable.load(ROOT / "figures" / "coefficients" / "dichotomy_d1.json")
    files = vhdl_outputs(analyze(t, 6, 6, gappa=False, synth=False))
    lines = files["chebnorm_dichotomy_d1.hex"].splitlines()
    lines[5] = format((int(lines[5], 16) + 1) % 64, "02x")
    files["chebnorm_dichotomy_d1.hex"] = "\n".join(lines) + "\n"
    for k, v in files.items():
        (tmp_path / k).write_text(v)
    res = simulate_vhdl(tmp_path, "chebnorm_dichotomy_d1")
    assert not res.passed and res.mismatches == 1 and res.vectors == 64


@need_ghdl
@pytest.mark.parametrize("hostile", HOSTILE)
def test_vhdl_hostile_expression_stays_in_comments(tmp_path, hostile):
    from chebnorm.hw.report import analyze
    from chebnorm.hw.hdl.vhdl import vhdl_module

    clean = CoefficientTable.load(ROOT / "figures" / "coefficients" / "dichotomy_d1.json")
    d = analyze(clean, 6, 6, gappa=False, synth=False).design
    # the design step parses the expression and would refuse most of these: put the
    # hostile text into the designed table, as a hand-edited table file would
    from chebnorm.hw.trust import drafting

    with construction("unchecked"):  # the constructor refuses it: test the printer alone
        t = replace(clean, expression=hostile, provenance={"command": hostile})
    with pytest.raises(ValueError):   # and so does a design of it
        replace(d, table=t)
    with drafting():   # a design left unchecked: the printer alone
        d = replace(d, table=t)
        text = vhdl_module(d, command=hostile)
    head = text.split("library ieee;")[0]
    assert all(ln.startswith("-- ") for ln in head.splitlines())
    assert "evil" not in text.split("library ieee;")[1]
    (tmp_path / "m.vhd").write_text(text)
    subprocess.run(["ghdl", "-a", "--std=08", "m.vhd"], cwd=tmp_path, check=True,
                   capture_output=True)


@pytest.mark.parametrize("name", ["a__b", "ab_"])
def test_vhdl_refuses_names_vhdl_cannot_spell(name):
    from chebnorm.hw.report import analyze
    from chebnorm.hw.hdl.vhdl import vhdl_module

    t = replace(CoefficientTable.load(ROOT / "figures" / "coefficients" / "dichotomy_d1.json"),
                name=name)
    d = analyze(t, 6, 6, gappa=False, synth=False).design
    with pytest.raises(ValueError, match="not a VHDL identifier"):
        vhdl_module(d)


# -- CLI ------------------------------------------------------------------------------------

@pytest.mark.parametrize("fmt,marker", [("glsl", "float chebnorm_rsqrt_d3(float x)"),
                                        ("wgsl", "fn chebnorm_rsqrt_d3(x: f32) -> f32 {"),
                                        ("hlsl", "mad(acc, x, "), ("c", "#ifndef"),
                                        ("json", '"schema_version"')])
def test_cli_export_formats(tmp_path, fmt, marker):
    out = tmp_path / f"o.{fmt}"
    proc = run_cli_quiet("export", str(ROOT / "figures/coefficients/rsqrt_d3.json"), "--format", fmt,
                "-o", str(out))
    assert proc.code == 0, proc.err
    assert marker in out.read_text()
    if fmt != "json":
        assert "Command: " in out.read_text()


@need_ghdl
def test_cli_export_vhdl(tmp_path):
    out = tmp_path / "e.vhd"
    proc = run_cli_quiet("export", str(ROOT / "figures/coefficients/rsqrt_d3.json"), "--format", "vhdl",
                "--in-bits", "10", "--out-bits", "10", "-o", str(out))
    assert proc.code == 0, proc.err
    text = out.read_text()
    assert "entity chebnorm_rsqrt_d3 is" in text and "entity chebnorm_rsqrt_d3_pipe is" in text
    subprocess.run(["ghdl", "-a", "--std=08", str(out)], cwd=tmp_path, check=True)


@pytest.mark.parametrize("args,message", [
    (("--format", "vhdl"), "needs --in-bits and --out-bits"),
    (("--format", "glsl", "--in-bits", "8"), "apply to --format vhdl or verilog only"),
    (("--format", "spirv"), "unknown export format 'spirv'"),
])
def test_cli_export_errors(tmp_path, args, message):
    proc = run_cli_quiet("export", str(ROOT / "figures/coefficients/rsqrt_d3.json"), *args,
                "-o", str(tmp_path / "x"))
    assert proc.code == 2
    assert message in proc.err and len(proc.err.strip().splitlines()) == 1
    assert not (tmp_path / "x").exists()


def test_cli_hw_lang_choices(tmp_path):
    proc = run_cli_quiet("hw", "verilog", str(ROOT / "figures/coefficients/rsqrt_d3.json"), "--in-bits",
                "8", "--out-bits", "8", "--lang", "spice", "-o", str(tmp_path))
    assert proc.code == 2 and "invalid choice: 'spice'" in proc.err


def test_json_export_roundtrips(tmp_path):
    out = tmp_path / "t.json"
    assert run_cli_quiet("export", str(TABLES[0]), "--format", "json", "-o", str(out)).code == 0
    assert json.loads(out.read_text()) == json.loads(TABLES[0].read_text())


@need_ghdl
@pytest.mark.parametrize("spec", [
    ("exp(x)", ("0", "1/8"), 0, 5, 6, "rne"),      # degree 0: no Horner step
    ("exp(x)", ("-1", "1"), 4, 7, 9, "trunc"),     # negative inputs, four steps
])
def test_vhdl_matches_the_model_on_fresh_fits(tmp_path, spec):
    from chebnorm.hw.report import analyze
    from chebnorm.hw.run_vhdl import simulate_vhdl, vhdl_outputs

    expr, iv, deg, wi, wo, rounding = spec
    t = fit(expr, iv, deg, name=f"f{deg}", coef_frac_bits=20)
    r = analyze(t, wi, wo, rounding=rounding, gappa=False, synth=False)
    files = vhdl_outputs(r, pipelined=deg >= 1)
    for k, v in files.items():
        (tmp_path / k).write_text(v)
    names = [r.design.module_name] + ([r.design.module_name + "_pipe"] if deg >= 1 else [])
    for name in names:
        res = simulate_vhdl(tmp_path, name)
        assert res.passed and res.vectors == 2 ** wi, res.line


@need_iverilog
def test_cli_export_verilog(tmp_path):
    out = tmp_path / "e.v"
    proc = run_cli_quiet("export", str(ROOT / "figures/coefficients/rsqrt_d3.json"), "--format",
                "verilog", "--in-bits", "10", "--out-bits", "10", "-o", str(out))
    assert proc.code == 0, proc.err
    text = out.read_text()
    assert "module chebnorm_rsqrt_d3 #(" in text and "module chebnorm_rsqrt_d3_pipe #(" in text
    subprocess.run(["iverilog", "-g2005", "-o", str(tmp_path / "a.out"), str(out)], check=True)
