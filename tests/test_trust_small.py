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

@pytest.mark.slow   # a child process importing numba: 8.5 s measured
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


def test_mesh_scale_limits_hold_in_the_python_api():
    from chebnorm.raster.meshes import MAX_COORDINATE, Mesh

    pos = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    nrm = np.tile([0.0, 0.0, 1.0], (3, 1))
    Mesh("ok", pos * MAX_COORDINATE, nrm, [[0, 1, 2]])   # the limit itself renders its maths
    with pytest.raises(ValueError, match="overflows float64"):
        Mesh("big", pos * 2 * MAX_COORDINATE, nrm, [[0, 1, 2]])


def test_mesh_at_the_limits_renders(tmp_path):
    """2^200 and 2^-200 (the accepted extremes' neighbours, 1e60 and 1e-8) render without a warning."""
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

@pytest.mark.slow   # a design search and a simulation: 8 s measured
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
