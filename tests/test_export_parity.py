"""Exporting a table whose coefficients have one parity with no ``monomials``
given (issue 41): an odd or even f on a symmetric interval fitted in the full
basis. The C evaluators (double, float, quantized) and the shaders evaluate
``x*q(x*x)`` or ``q(x*x)`` rather than Horner's rule with zero
coefficients, each bound computed for that scheme: compiled with gcc (and the
shaders with glslangValidator, run on the GPU driver when there is one) and
checked against mpmath within the stated bounds."""

from __future__ import annotations

import re
import shutil
import subprocess
from fractions import Fraction

import mpmath
import numpy as np
import pytest

from chebnorm.approx import fit
from chebnorm.export import c_header
from chebnorm.export.evalbound import BINARY32, Evaluator, Piece
from chebnorm.export.shader import float32_eval_bound, shader_evaluator, shader_source

from test_export import CFLAGS, GCC, macro_value, needs_gcc

pytestmark = pytest.mark.filterwarnings("ignore::chebnorm.approx.FitWarning")

DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include "t.h"
int main(void)
{{
    char buf[128];
    while (fgets(buf, sizeof buf, stdin)) {{
        double x = strtod(buf, NULL);
        float xf = (float)x;
        printf("%a %a %a", chebnorm_t(x), (double)chebnorm_t_f(xf), chebnorm_t_quant(x));
{float_line}
        printf("\n");
    }}
    return 0;
}}
"""

CASES = {
    # name: (fit arguments, f in mpmath, parity, a float evaluator of the quantized part)
    "sin_odd_binary32": (("sin(x)", ("-pi/4", "pi/4"), 7, "binary32"), mpmath.sin, 1, True),
    "cos_even_bfloat16": (("cos(x)", ("-1", "1"), 8, "bfloat16"), mpmath.cos, 0, True),
    "tan_odd_binary64": (("tan(x)", ("-1/4", "1/4"), 9, "binary64"), mpmath.tan, 1, False),
    "tan_odd_binary32": (("tan(x)", ("-1/4", "1/4"), 7, "binary32"), mpmath.tan, 1, True),
    "gauss_even_binary16": (("exp(-x**2)", ("-1/2", "1/2"), 6, "binary16"),
                            lambda x: mpmath.exp(-x * x), 0, True),
}


def _table(case):
    (expr, iv, n, fmt), *_ = CASES[case]
    return fit(expr, iv, n, kind="minimax", coef_format=fmt, name="t")


@needs_gcc
@pytest.mark.parametrize("case", sorted(CASES))
def test_c_parity_evaluators_within_their_bounds(tmp_path, case):
    _, f, parity, quant_float = CASES[case]
    t = _table(case)
    ms = t.quantized.mantissas
    assert all(m == 0 for k, m in enumerate(ms) if k % 2 != parity)   # exact zeros
    assert all(c == 0 for k, c in enumerate(t.coefficients) if k % 2 != parity)
    h = c_header(t)
    kind = "odd" if parity else "even"
    # every evaluator in t = x*x: none steps through a zero coefficient in x
    assert h.count(f"over the {kind} powers, in t = x*x") == 3 + quant_float
    assert "acc * x +" not in h
    assert ("return acc * x;" in h) == bool(parity)
    (tmp_path / "t.h").write_text(h)
    float_line = ('        printf(" %a", (double)chebnorm_t_quant_f(xf));' if quant_float else "")
    (tmp_path / "main.c").write_text(DRIVER.format(float_line=float_line))
    exe = tmp_path / "main"
    proc = subprocess.run([GCC, *CFLAGS, "-o", str(exe), str(tmp_path / "main.c")],
                          capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    lo, hi = t.interval_float
    rng = np.random.default_rng(41)
    xs = np.concatenate([np.linspace(lo, hi, 3001), rng.uniform(lo, hi, 3000),
                         [0.0, 2.0 ** -140, -(2.0 ** -20)]])
    xs = xs.astype(np.float32).astype(np.float64)   # float inputs: every evaluator's bound holds
    xs = xs[(xs >= lo) & (xs <= hi)]
    out = subprocess.run([str(exe)], input="".join(f"{x.hex()}\n" for x in xs),
                         capture_output=True, text=True, check=True).stdout.splitlines()
    rows = [line.split() for line in out]
    assert len(rows) == len(xs) >= 5000
    macros = ["CHEBNORM_T_EVAL_ERROR_BOUND", "CHEBNORM_T_F_EVAL_ERROR_BOUND",
              "CHEBNORM_T_QUANT_EVAL_ERROR_BOUND"] + (
        ["CHEBNORM_T_QUANT_F_EVAL_ERROR_BOUND"] if quant_float else [])
    bounds = [macro_value(h, m) for m in macros]
    worst = [0.0] * len(macros)
    with mpmath.workdps(40):
        for x, row in zip(xs, rows):
            exact = f(mpmath.mpf(float(x)))
            for j, v in enumerate(row):
                worst[j] = max(worst[j], abs(float(mpmath.mpf(float.fromhex(v)) - exact)))
    assert all(w <= b for w, b in zip(worst, bounds)), (worst, bounds)
    # not vacuous: the double evaluators reach most of their polynomials' located maxima
    assert worst[0] >= 0.9 * t.max_abs_error and worst[2] >= 0.9 * t.quantized.max_abs_error


@pytest.mark.parametrize("case", ["sin_odd_binary32", "tan_odd_binary32"])
def test_odd_scheme_bound_below_horner_with_zeros(case):
    """For these odd tables the float32 bound of ``x*q(x*x)`` (the scheme
    printed, half the operations) is below that of Horner's rule stepping
    through the zero coefficients: both rigorous, the same interval analysis.
    (Not a theorem: for some even tables, e.g. cos on [-1, 1], the rounding of
    ``x*x`` makes the scheme's bound a few percent larger.)"""
    t = _table(case)
    ev = shader_evaluator(t)
    assert ev.parity == CASES[case][2]
    piece = ev.pieces[0]
    horner = Evaluator(ev.constant, ev.function, ev.arith, (piece,), target=ev.target)
    assert ev.bound().stated < horner.bound().stated
    # and in the C float evaluator of the quantized coefficients
    cs = tuple(float(c) for c in t.quantized.coefficients)
    p = Piece(cs, cs, Fraction(t.quantized.abs_error_bound), piece.lo, piece.hi)
    par = Evaluator("C", "c", BINARY32, (p,), parity=CASES[case][2])
    plain = Evaluator("C", "c", BINARY32, (p,))
    assert par.bound().stated < plain.bound().stated


@pytest.mark.parametrize("language", ["glsl", "wgsl", "hlsl"])
def test_shaders_evaluate_in_x_squared(language):
    t = _table("sin_odd_binary32")
    src = shader_source(t, language)
    assert "over the odd powers, in t = x*x" in src and "return acc * x;" in src
    assert len(re.findall(r"acc = \S+\(acc, t, ", src)) == 3      # x^5, x^3, x^1
    assert "(acc, x," not in src
    b = float32_eval_bound(t)
    value = re.search(r"EVAL_ERROR_BOUND\W+(?:f32 )?= ([0-9.e+-]+)f?;", src).group(1)
    assert float(np.float32(value)) == b.total32       # the float32 literal, exactly
    even = shader_source(_table("cos_even_bfloat16"), language)
    assert "over the even powers, in t = x*x" in even and "return acc;" in even


@pytest.mark.requires_tool("glslangValidator")
def test_parity_shaders_compile():
    from chebnorm.export.gpu import compute_shader_source, glslang_validate

    for case in ("sin_odd_binary32", "cos_even_bfloat16"):
        t = _table(case)
        glslang_validate(compute_shader_source(t, "glsl"), "glsl")
        glslang_validate(compute_shader_source(t, "glsl", es=True), "glsl")
        glslang_validate(compute_shader_source(t, "hlsl"), "hlsl")


@pytest.mark.parametrize("case", ["sin_odd_binary32", "gauss_even_binary16"])
def test_glsl_parity_shader_runs_within_its_bound(case):
    from chebnorm.export.gpu import ToolMissing, float32_inputs, glsl_evaluate

    _, f, _, _ = CASES[case]
    t = _table(case)
    xs = float32_inputs(t, 20_000)
    try:
        ys = glsl_evaluate(t, xs)
    except ToolMissing as exc:
        pytest.skip(str(exc))
    bound = float32_eval_bound(t).total32
    with mpmath.workdps(30):
        worst = max(abs(float(mpmath.mpf(float(y)) - f(mpmath.mpf(float(x)))))
                    for x, y in zip(xs, ys))
    assert worst <= bound


@needs_gcc
@pytest.mark.parametrize("expr, iv, n, frac, f, parity", [
    ("sin(x)", ("-pi/4", "pi/4"), 7, 28, mpmath.sin, 1),
    ("cos(x)", ("-1", "1"), 8, 24, mpmath.cos, 0),
])
def test_c_fixed_point_parity_evaluator_within_its_bound(tmp_path, expr, iv, n, frac, f, parity):
    from test_export import compile_and_run

    t = fit(expr, iv, n, kind="minimax", coef_frac_bits=frac, name="fx")
    fp = t.fixed_point
    assert fp is not None and all(q == 0 for k, q in enumerate(fp.integers) if k % 2 != parity)
    h = c_header(t)
    assert f"int64_t t_q = ((x_q * x_q + (INT64_C(1) << {frac - 1})) >> {frac});" in h
    assert "acc * x_q +" in h if parity else "acc * x_q" not in h
    bound = macro_value(h, "CHEBNORM_FX_Q_EVAL_ERROR_BOUND")
    lo, hi = t.interval_float
    rng = np.random.default_rng(7)
    xs = np.concatenate([np.linspace(lo, hi, 2001), rng.uniform(lo, hi, 2000), [0.0]])
    rows = compile_and_run(tmp_path, t, xs)
    worst = 0.0
    with mpmath.workdps(40):
        for x, row in zip(xs, rows):
            xq = int(x * 2.0 ** frac)          # the driver's truncation to the input grid
            exact = f(mpmath.mpf(xq) / 2 ** frac)
            worst = max(worst, abs(float(mpmath.mpf(int(row[2])) / 2 ** frac - exact)))
    assert fp.abs_error_bound <= bound and worst <= bound
    assert worst >= 0.9 * fp.max_abs_error            # not vacuous



GAPPA = shutil.which("gappa")
needs_gappa = pytest.mark.skipif(GAPPA is None, reason="gappa is not installed (apt-get install "
                                                       "gappa)")


def _gappa(ev, bound=None):
    from chebnorm.export.gappa import gappa_script

    return subprocess.run([GAPPA], input=gappa_script(ev, bound), capture_output=True, text=True,
                          timeout=600)


@needs_gappa
@pytest.mark.parametrize("expr, iv, n, frac", [
    pytest.param("sin(x)", ("-pi/4", "pi/4"), 7, 28, marks=pytest.mark.slow),  # 8.5 s
    ("cos(x)", ("-1/2", "1/2"), 6, 20)])
def test_gappa_proves_the_integer_parity_bound(expr, iv, n, frac):
    """The integer evaluator's stated bound (in ``t_q``) is proved by its Gappa
    script, and half of it is not."""
    from chebnorm.export.c import c_header_evaluators

    t = fit(expr, iv, n, kind="minimax", coef_frac_bits=frac, name="fx")
    ev = {e.constant: e for e in c_header_evaluators(t)[1]}["CHEBNORM_FX_Q_EVAL_ERROR_BOUND"]
    assert ev.parity == n % 2
    r = _gappa(ev)
    assert r.returncode == 0 and "not satisfied" not in r.stderr, r.stderr
    r = _gappa(ev, ev.bound().stated / 2)
    assert r.returncode != 0 and "not satisfied" in r.stderr


@needs_gappa
def test_gappa_proves_the_float_parity_bounds():
    """Each stated bound of the float parity evaluators (C double and float,
    quantized double and float, the shader's) is proved by its Gappa script."""
    from chebnorm.export.c import c_header_evaluators

    t = _table("sin_odd_binary32")
    evs = c_header_evaluators(t)[1] + [shader_evaluator(t)]
    assert len(evs) == 5 and all(ev.parity == 1 for ev in evs)
    for ev in evs:
        r = _gappa(ev)
        assert r.returncode == 0 and "not satisfied" not in r.stderr, (ev.constant, r.stderr)
