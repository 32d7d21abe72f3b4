"""Issue 43, the smaller items: the renderer without numba's compiler, meshes too large
for float64, printed command lines, huge ``--max-error``, digits of other scripts,
repeated monomials, outputs that name one file, false "vanishes"/"not finite"
refusals, and constant and linear functions through every exporter.

Every refusal is exit 2 and one line on stderr; every accepted case is checked
against an independent computation (the JIT path's bytes, mpmath at high precision,
the printed command run again).
"""

from __future__ import annotations

import os
import shlex

import numpy as np
import pytest

from chebnorm.raster.engines.numba.jit import HAVE_NUMBA
from conftest import run_cli, run_process
from quiet_cli import run_cli_quiet


def refused(result, pattern):
    """Exit 2 and exactly one line on stderr naming the problem."""
    code, out, err = result
    assert code == 2, (out, err)
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("chebnorm: error: "), err
    assert pattern in lines[0], lines[0]


# -- NUMBA_DISABLE_JIT: the numpy engine, the same bytes ----------------------------

@pytest.mark.slow   # a child process importing numba: 8.5 s measured cold, 2.4 s warm
@pytest.mark.skipif(not HAVE_NUMBA, reason="numba is not installed: the JIT path is the "
                    "numpy engine already")
def test_render_without_jit_is_the_numpy_engine_with_the_same_bytes(tmp_path):
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    args = ["render", "--mesh", "sphere", "--size", "16", "16", "--json"]
    child = run_process(*args, "--out", tmp_path / "nojit.png", env=env, timeout=300)
    assert child.returncode == 0, child.stderr
    assert "Traceback" not in child.stderr
    code, out, err = run_cli(*args, "--out", tmp_path / "jit.png", "--engine", "numba")
    assert code == 0, err
    assert (tmp_path / "nojit.png").read_bytes() == (tmp_path / "jit.png").read_bytes()
    import json
    nojit, jit = json.loads(child.stdout), json.loads(out)
    for key in ("seconds", "seconds_total"):
        nojit.pop(key, None), jit.pop(key, None)
    assert {k: v for k, v in nojit.items() if k != "engine"} == \
        {k: v for k, v in jit.items() if k != "engine"}
    # asking for the compiled engine with its compiler off: one line, exit 2
    child = run_process(*args, "--engine", "numba", env=env, timeout=300)
    assert child.returncode == 2, child.stderr
    assert child.stderr.splitlines() == [
        "chebnorm: error: engine 'numba' needs numba's compiler, which NUMBA_DISABLE_JIT "
        "turns off; accepted with it: auto, numpy"]


# -- meshes whose squared lengths overflow or underflow float64 ---------------------

TETRA = "v 0 0 0\nv {s} 0 0\nv 0 {s} 0\nv 0 0 {s}\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n"


@pytest.mark.parametrize("text, pattern", [
    ("v 0 0 0\nv 1e308 0 0\nv 0 1 0\nf 1 2 3\n", "vertex 1 has a coordinate of magnitude 1e+308"),
    ("v 0 0 0\nv 1e308 1e308 0\nv 0 1 1e308\nf 1 2 3\n", "magnitude 1e+308"),
    (TETRA.format(s="1e100"), "accepted: coordinates up to 2^200"),
    (TETRA.format(s="1e-100"), "the vertices span only 1e-100"),
])
def test_mesh_out_of_float64_range_is_one_line_and_no_warning(tmp_path, text, pattern):
    mesh = tmp_path / "m.obj"
    mesh.write_text(text)
    refused(run_cli_quiet("render", "--mesh", mesh, "--size", "16", "16"), pattern)


def test_mesh_below_the_near_plane_is_refused_with_that_reason(tmp_path):
    """1e-10 across: the default camera's near distance (1e-9) is the true reason."""
    mesh = tmp_path / "m.obj"
    mesh.write_text(TETRA.format(s="1e-10"))
    refused(run_cli_quiet("render", "--mesh", mesh, "--size", "16", "16", "--engine", "numpy"),
            "scale the mesh up")


def test_mesh_scale_limits_hold_in_the_python_api():
    from chebnorm.raster.meshes import MAX_COORDINATE, Mesh

    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    nrm = np.tile([0.0, 0.0, 1.0], (3, 1))
    Mesh("ok", pos * MAX_COORDINATE, nrm, [[0, 1, 2]])   # the limit itself renders its maths
    with pytest.raises(ValueError, match="overflows float64"):
        Mesh("big", pos * 2 * MAX_COORDINATE, nrm, [[0, 1, 2]])


def test_mesh_at_the_limits_renders(tmp_path):
    """1e60 (just under 2^200) and 1e-8 (the smallest the default camera frames) render."""
    for s in ("1e60", "1e-8"):
        mesh = tmp_path / f"m{s}.obj"
        mesh.write_text(TETRA.format(s=s))
        code, out, err = run_cli("render", "--mesh", mesh, "--size", "16", "16",
                                 "--engine", "numpy")
        assert code == 0 and err == "", err


# -- digits of other scripts ---------------------------------------------------------

ARABIC_3 = "\u0663"      # int("\u0663") == 3 in Python
ARABIC_16 = "\u0661\u0666"


@pytest.mark.parametrize("argv, pattern", [
    (["fit", "exp(x)", "--interval", "0", "1", "--degree", "3", "--kind", "minimax",
      "--monomials", f"0,1,{ARABIC_3}"], "--monomials"),
    (["fit", "exp(x)", "--interval", "0", "1", "--degree", ARABIC_3], "--degree"),
    (["fit", "exp(x)", "--interval", "0", "1", "--degree", "3", "--coef-frac-bits",
      ARABIC_16], "--coef-frac-bits"),
    (["fit", "exp(x)", "--interval", "0", "1", "--degree", "3", "--segments", "\u0664"],
     "segments"),
    (["fit", "exp(x)", "--interval", "0", "1", "--degree", "3", "--segments",
      f"2^{ARABIC_3}"], "segments"),
    (["fit", "exp(x)", "--interval", "0", "1", "--degree", "1_0"], "--degree"),
    (["render", "--mesh", "sphere", "--size", ARABIC_16, "16"], "--size"),
    (["render", "--mesh", "sphere", "--size", "16", "16", "--shininess", ARABIC_16],
     "--shininess"),
    (["render-sweep", "--sizes", ARABIC_16, "-o", "OUT"], "size"),
    (["hw", "verilog", "T.json", "--in-bits", ARABIC_16, "--out-bits", "8", "-o", "D"],
     "--in-bits"),
    (["design", "exp(x)", "--interval", "0", "1", "--in-bits", "8", "--out-bits", "8",
      "--max-error", "1e-2", "--target", "ice40", "--frequency", "\u0661\u0660\u0660", "-o",
      "D"], "--frequency"),
    (["verify", "T.json", "--inputs", ARABIC_16], "--inputs"),
])
def test_digits_of_other_scripts_are_refused(tmp_path, argv, pattern):
    result = run_cli(*argv, cwd=tmp_path)
    refused(result, pattern)
    assert not any(tmp_path.iterdir())


def test_every_int_and_float_option_reads_ascii_only():
    """Every ``type=int`` / ``type=float`` option of every subcommand refuses ``\u0663``."""
    import argparse

    from chebnorm.cli import build_parser

    def parsers(p):
        yield p
        for a in p._actions:
            if isinstance(a, argparse._SubParsersAction):
                for sub in dict.fromkeys(a.choices.values()):
                    yield from parsers(sub)

    checked = 0
    for p in parsers(build_parser()):
        for a in p._actions:
            if a.type in (int, float) and a.option_strings:
                with pytest.raises(argparse.ArgumentError, match="ASCII digits"):
                    p._get_value(a, ARABIC_3)
                checked += 1
    assert checked > 40


# -- --monomials with a repeated power -----------------------------------------------

def test_repeated_monomial_is_refused():
    refused(run_cli("fit", "exp(x)", "--interval", "0", "1", "--degree", "3", "--kind",
                    "minimax", "--monomials", "1,1"), "repeat the power 1")
    import chebnorm as cn

    with pytest.raises(ValueError, match="repeat the power 3"):
        cn.fit("sin(x)", ("0", "1"), 3, kind="minimax", monomials=(1, 3, 3))


# -- --max-error 2^1000 -------------------------------------------------------------

def test_huge_max_error_is_degree_zero():
    code, out, err = run_cli("fit", "exp(x)", "--interval", "0", "1", "--max-error", "2^1000")
    assert code == 0, err
    assert "chebyshev degree 0 fit" in out and "degrees tried: 0:" in out
    # past float64 there is no such number: refused with what is accepted
    refused(run_cli("fit", "exp(x)", "--interval", "0", "1", "--max-error", "2^1024"),
            "accepted: a finite number > 0")


def test_powers_are_refused_by_their_real_size():
    from chebnorm.approx import parse_number

    assert parse_number("2^1000".replace("^", "**")) == 2 ** 1000
    assert parse_number("2**-1000") * 2 ** 1000 == 1
    for text in ("3**800", "5**600", "10**400"):      # 1268, 1394 and 1329 bits
        with pytest.raises(ValueError, match="more than 1200 bits"):
            parse_number(text)


# -- printed command lines are quoted -----------------------------------------------

@pytest.mark.slow   # a design search and a simulation: 8 s measured cold, 2.8 s warm
@pytest.mark.requires_tool("iverilog")
def test_design_reproduce_line_round_trips_and_runs(tmp_path):
    code, out, err = run_cli("design", "1/sqrt(x)", "--interval", "(1)", "4", "--in-bits",
                             "8", "--out-bits", "8", "--max-error", "1e-2", "--no-synth",
                             "-o", tmp_path / "d")
    assert code == 0, err
    line = next(s for s in out.splitlines() if s.startswith("reproduce: "))
    text = line[len("reproduce: "):]
    words = shlex.split(text)
    assert "'(1)'" in line
    cmds, cur = [], []
    for w in words:
        if w == "&&":
            cmds.append(cur)
            cur = []
        else:
            cur.append(w)
    cmds.append(cur)
    assert " && ".join(shlex.join(c) for c in cmds) == text    # quoted as shlex quotes
    assert [c[:2] for c in cmds] == [["chebnorm", "fit"], ["chebnorm", "hw"]]
    assert cmds[0][cmds[0].index("--interval") + 1] == "(1)"
    for cmd in cmds:
        code, out, err = run_cli(*cmd[1:], cwd=tmp_path)
        assert code == 0, (cmd, err)
    assert "PASS:" in out


# -- two outputs of one command naming one file; an output over the mesh ------------

def test_render_outputs_naming_one_file_are_refused(tmp_path):
    base = ["render", "--mesh", "sphere", "--size", "16", "16"]
    refused(run_cli_quiet(*base, "--out", "x.png", "--error-map", "x.png", cwd=tmp_path),
            "are the same file")
    refused(run_cli_quiet(*base, "--out", "x.png", "--error-map", "./sub/../x.png",
                          cwd=tmp_path), "are the same file")
    (tmp_path / "x.png").write_bytes(b"old")
    (tmp_path / "y.png").symlink_to("x.png")
    refused(run_cli_quiet(*base, "--out", "y.png", "--error-map", "x.png", cwd=tmp_path),
            "are the same file")
    assert (tmp_path / "x.png").read_bytes() == b"old"


def test_render_output_over_the_mesh_file_is_refused(tmp_path):
    mesh = tmp_path / "m.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "m.png").symlink_to("m.obj")
    refused(run_cli_quiet("render", "--mesh", "m.obj", "--size", "16", "16", "--out", "m.png",
                          cwd=tmp_path), "is the input --mesh")
    refused(run_cli_quiet("render", "--mesh", "m.obj", "--size", "16", "16", "--error-map",
                          "m.png", cwd=tmp_path), "is the input --mesh")
    assert mesh.read_text().startswith("v 0 0 0")


# -- false "vanishes" / "not finite" refusals ---------------------------------------

def _dense_worst(poly, f, lo, hi, kind, points=4001, extra=()):
    """max |p - f| (or |p/f - 1|) on a dense grid at 200 bits: a lower bound of the sup."""
    import mpmath

    xs = sorted({float(x) for x in np.linspace(lo, hi, points)} | set(extra))
    with mpmath.workprec(200):
        worst = mpmath.mpf(0)
        for x in xs:
            if not lo <= x <= hi:
                continue
            xm = mpmath.mpf(x)
            fx, px = f(xm), poly(xm)
            e = px - fx if kind == "abs" else px / fx - 1
            worst = max(worst, abs(e))
    return float(worst)


def _mono(coeffs):
    import mpmath

    return lambda x: sum(mpmath.mpf(c) * x ** k for k, c in enumerate(coeffs))


ONE_MINUS_COS = (lambda x: 2 * __import__("mpmath").sin(x / 2) ** 2)   # no cancellation


@pytest.mark.parametrize("kind", ["chebyshev", "minimax"])
def test_one_minus_cos_relative_error_near_zero_is_certified(kind):
    """float64 reads 1 - cos(1e-8) as 0; the function has no zero on [1e-8, 1e-4]."""
    import warnings

    import chebnorm as cn

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)    # no numpy warning leaks
        warnings.simplefilter("ignore", cn.approx.FitWarning)
        t = cn.fit("1 - cos(x)", ("1e-8", "1e-4"), 3, kind=kind, error="rel")
    worst = _dense_worst(_mono(t.coefficients), ONE_MINUS_COS, 1e-8, 1e-4, "rel",
                         extra=np.geomspace(1e-8, 1e-4, 400))
    assert worst <= t.rel_error_bound <= 1.01 * worst
    if kind == "minimax":   # the fit sees the true values: a useful relative error
        assert t.rel_error_bound < 1e-6
    from chebnorm.approx.load import table_from_json
    from chebnorm.export import export_text

    assert table_from_json(export_text(t, "json")) == t     # every bound re-proved on load


def test_one_minus_cos_relative_error_cli_and_piecewise():
    code, out, err = run_cli("fit", "1 - cos(x)", "--interval", "1e-8", "1e-4", "--degree",
                             "3", "--error", "rel")
    assert code == 0 and "max |p/f - 1|" in out, err
    import chebnorm as cn

    t = cn.fit("1 - cos(x)", ("1e-8", "1e-4"), 3, error="rel", segments=4, coef_frac_bits=48)
    assert t.rel_error_bound is not None and t.rel_error_bound <= 1.0 + 1e-9
    # a true zero is still refused, with the true reason
    refused(run_cli("fit", "1 - cos(x)", "--interval", "0", "1e-4", "--degree", "3",
                    "--error", "rel"), "vanishes")


def test_sqrt_abs_across_zero_is_certified():
    """sqrt(|x|) is finite and real on [-1, 1]; Arb's abs of a ball around 0 was not."""
    import mpmath

    import chebnorm as cn

    for kind in ("chebyshev", "minimax"):
        t = cn.fit("sqrt(Abs(x))", ("-1", "1"), 4, kind=kind)
        worst = _dense_worst(_mono(t.coefficients), lambda x: mpmath.sqrt(abs(x)), -1.0, 1.0,
                             "abs", extra=(0.0, 1e-12, -1e-12))
        assert worst <= t.abs_error_bound <= 1.01 * worst
    code, out, err = run_cli("fit", "sqrt(abs(x))", "--interval", "-1", "1", "--degree", "4")
    assert code == 0, err


def _piecewise_worst(t, f, points=401):
    import mpmath

    worst = 0.0
    for s in range(t.segment_count):
        a, b = (float(v) for v in t.segment_bounds(s))
        cs = [math_ldexp(q, -t.coef_frac_bits) for q in t.segments[s].integers]
        with mpmath.workprec(200):
            for k in range(points):
                tt = mpmath.mpf(k) / (points - 1)
                x = mpmath.mpf(a) + (mpmath.mpf(b) - mpmath.mpf(a)) * tt
                u = tt - mpmath.mpf(1) / 2 if t.centered else tt   # the local variable
                worst = max(worst, float(abs(mpmath.polyval(cs[::-1], u) - f(x))))
    return worst


def math_ldexp(q, e):
    import math

    return math.ldexp(q, e)


@pytest.mark.parametrize("expr, f", [
    ("sqrt(x)", lambda x: __import__("mpmath").sqrt(x)),
    ("sqrt(1 - x)", lambda x: __import__("mpmath").sqrt(1 - x)),
])
def test_piecewise_sqrt_with_a_singular_end_is_certified(expr, f):
    """The single fit of sqrt(x) on [0, 1] is certified; so is the piecewise one."""
    import chebnorm as cn

    for centered in (False, True):
        t = cn.fit(expr, ("0", "1"), 3, segments=4, centered=centered)
        worst = _piecewise_worst(t, f)
        assert worst <= t.abs_error_bound <= 1.01 * worst
        from chebnorm.approx.load import table_from_json
        from chebnorm.export import export_text

        assert table_from_json(export_text(t, "json")) == t
    code, out, err = run_cli("fit", expr, "--interval", "0", "1", "--degree", "3",
                             "--segments", "4")
    assert code == 0 and "certified max over segments" in out, err
    # the relative error of sqrt(x) at 0 has no value: refused with that reason
    refused(run_cli("fit", "sqrt(x)", "--interval", "0", "1", "--degree", "3", "--segments",
                    "4", "--error", "rel"), "nonzero")


# -- constant and linear functions through every exporter ----------------------------

CONST_LINEAR = ["5", "0.1", "x - x + 1/3", "0", "x", "2*x+1"]
QUANT = {"float": [], "fixed": ["--coef-frac-bits", "20"]}


def _table(tmp_path, expr, quant):
    code, out, err = run_cli("fit", expr, "--interval", "1", "2", "--degree", "2", "--basis",
                             "monomial", *QUANT[quant], "-o", "t.json", cwd=tmp_path)
    assert code == 0, err
    return tmp_path / "t.json"


def _ok(result):
    """Exit 0; stderr holds at most chebnorm's one-line warnings (a re-quantized linear
    table's FitWarning reached stderr as Python prints it, over two lines)."""
    code, out, err = result
    assert code == 0 and "Traceback" not in err, err
    assert all(line.startswith("chebnorm: warning: ") for line in err.splitlines()), err
    return out


@pytest.mark.parametrize("quant", sorted(QUANT))
@pytest.mark.parametrize("expr", CONST_LINEAR)
def test_constant_and_linear_through_every_exporter(tmp_path, expr, quant):
    _table(tmp_path, expr, quant)
    for fmt in ("c", "glsl", "wgsl", "hlsl"):
        _ok(run_cli("export", "t.json", "--format", fmt, "-o", f"e.{fmt}", "--proof",
                    cwd=tmp_path))
        assert (tmp_path / f"e.{fmt}").read_text()
    _ok(run_cli("export", "t.json", "--format", "json", "-o", "e.json", cwd=tmp_path))
    for fmt in ("verilog", "vhdl"):
        _ok(run_cli("export", "t.json", "--format", fmt, "-o", f"e.{fmt}", "--in-bits", "8",
                    "--out-bits", "8", "--coef-frac-bits", "16", cwd=tmp_path))
    assert sorted(p.name for p in tmp_path.glob("*.gappa"))


@pytest.mark.requires_tool("gappa")
@pytest.mark.parametrize("expr", ["5", "0", "2*x+1"])
def test_constant_and_linear_proofs_are_proved_by_gappa(tmp_path, expr):
    import subprocess

    _table(tmp_path, expr, "float")
    for fmt in ("c", "glsl"):
        _ok(run_cli("export", "t.json", "--format", fmt, "-o", f"e.{fmt}", "--proof",
                    cwd=tmp_path))
    proofs = sorted(tmp_path.glob("*.gappa"))
    assert len(proofs) >= 3
    for proof in proofs:
        run = subprocess.run(["gappa", proof.name], cwd=tmp_path, capture_output=True,
                             text=True, timeout=120)
        text = run.stdout + run.stderr
        # gappa says nothing (but warnings) when every goal is proved
        assert run.returncode == 0 and "Error" not in text and "not satisfied" not in text, \
            (proof.name, text)


@pytest.mark.requires_tool("gcc")
@pytest.mark.parametrize("expr", ["5", "0", "x", "2*x+1"])
def test_constant_and_linear_verify_in_c(tmp_path, expr):
    for quant in sorted(QUANT):
        _table(tmp_path, expr, quant)
        out = _ok(run_cli("verify", "t.json", "--inputs", "1000", cwd=tmp_path))
        assert "ok" in out


@pytest.mark.requires_tool("iverilog", "ghdl")
@pytest.mark.parametrize("expr", ["5", "0.1", "0", "x"])
def test_constant_and_linear_circuits_simulate_as_their_model(tmp_path, expr):
    """A constant's output has no span (its datapath was sized past the exact sum); the zero
    polynomial's one-bit wires were rounded at a bit above them (X in the simulator)."""
    _table(tmp_path, expr, "fixed")
    for lang in ("verilog", "vhdl"):
        for rounding in ("rne", "trunc"):
            out = _ok(run_cli("hw", "verilog", "t.json", "--in-bits", "8", "--out-bits", "8",
                              "--coef-frac-bits", "16", "--rounding", rounding, "--lang", lang,
                              "-o", f"{lang}-{rounding}", "--simulate", cwd=tmp_path))
            assert "PASS: 256 vectors, 0 mismatches" in out, out


def test_library_warnings_reach_the_cli_as_one_line(tmp_path):
    """A FitWarning raised while ``export`` re-quantizes a linear table was printed by
    Python (file, line, category, the source line); the command line prints it as
    one ``chebnorm: warning:`` line. A child process: in-process, pytest takes the
    warnings."""
    _table(tmp_path, "2*x+1", "fixed")
    child = run_process("export", "t.json", "--format", "verilog", "-o", "e.v", "--in-bits", "8",
                        "--out-bits", "8", "--coef-frac-bits", "16", cwd=tmp_path, timeout=300)
    assert child.returncode == 0, child.stderr
    lines = child.stderr.splitlines()
    assert lines and all(s.startswith("chebnorm: warning: ") for s in lines), child.stderr
    assert len(lines) == len(set(lines))
