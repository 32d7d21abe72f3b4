"""Exporting a table's ``quantized`` part (issue 13 formats): the C header's
``_quant`` evaluators (Horner in ``x*x`` for odd or even powers) compiled with
gcc and run against mpmath within the header's own bounds, and the shaders'
use of float32-exact quantized coefficients."""

from __future__ import annotations

import subprocess

import mpmath
import numpy as np
import pytest

from chebnorm.approx import fit
from chebnorm.export import c_header
from chebnorm.export.shader import float32_eval_bound, shader_source

from test_export import CFLAGS, GCC, macro_value, needs_gcc

DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include "t.h"
int main(void)
{{
    char buf[128];
    int k;
    for (k = 0; k <= CHEBNORM_T_DEGREE; k++) printf("%a ", chebnorm_t_quant_coeffs[k]);
    printf("\n");
    while (fgets(buf, sizeof buf, stdin)) {{
        double x = strtod(buf, NULL);
        printf("%a", chebnorm_t_quant(x));
{float_line}
        printf("\n");
    }}
    return 0;
}}
"""

CASES = {
    # name: (fit arguments, the function in mpmath, a float evaluator expected, parity)
    "sin_odd_binary16": (dict(expr="sin(x)", interval=("-pi/4", "pi/4"), degree=7,
                              kind="minimax", coef_format="binary16", monomials=(1, 3, 5, 7)),
                         mpmath.sin, True, "odd"),
    "cos_even_bfloat16_fixed_constant": (dict(expr="cos(x)", interval=("-1", "1"), degree=6,
                                              kind="minimax", coef_format="bfloat16",
                                              monomials=(0, 2, 4, 6), fix_constant=True),
                                         mpmath.cos, True, "even"),
    "exp_per_power_fixed": (dict(expr="exp(x)", interval=("0", "1"), degree=3, kind="minimax",
                                 coef_frac_bits=(10, 12, 14, 16)),
                            mpmath.exp, True, None),
    "atan_binary64": (dict(expr="atan(x)", interval=("0", "1"), degree=9, kind="minimax",
                           coef_format="binary64"),
                      mpmath.atan, False, None),
}


def _table(case):
    args, *_ = CASES[case]
    args = dict(args)
    return fit(args.pop("expr"), args.pop("interval"), args.pop("degree"), name="t", **args)


@needs_gcc
@pytest.mark.parametrize("case", sorted(CASES))
def test_quantized_evaluators_within_their_bounds(tmp_path, case):
    _, f, has_float, parity = CASES[case]
    t = _table(case)
    assert t.fixed_point is None and t.quantized is not None
    h = c_header(t)
    assert ("chebnorm_t_quant_f(" in h) == has_float
    assert ("over the odd powers" in h) == (parity == "odd")
    assert ("over the even powers" in h) == (parity == "even")
    (tmp_path / "t.h").write_text(h)
    float_line = '        printf(" %a", (double)chebnorm_t_quant_f((float)x));' if has_float else ""
    (tmp_path / "main.c").write_text(DRIVER.format(float_line=float_line))
    exe = tmp_path / "main"
    proc = subprocess.run([GCC, *CFLAGS, "-o", str(exe), str(tmp_path / "main.c")],
                          capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    lo, hi = t.interval_float
    rng = np.random.default_rng(13)
    xs = np.concatenate([np.linspace(lo, hi, 4001), rng.uniform(lo, hi, 4000)])
    if has_float:  # the float evaluator's bound holds for float inputs in the interval
        xs = xs.astype(np.float32).astype(np.float64)
        xs = xs[(xs >= lo) & (xs <= hi)]
    out = subprocess.run([str(exe)], input="".join(f"{x.hex()}\n" for x in xs),
                         capture_output=True, text=True, check=True).stdout.splitlines()
    # the array is exactly the table's quantized coefficients
    assert [float.fromhex(v) for v in out[0].split()] == [float(c) for c in
                                                          t.quantized.coefficients]
    rows = [line.split() for line in out[1:]]
    assert len(rows) == len(xs) >= 7000
    b_double = macro_value(h, "CHEBNORM_T_QUANT_EVAL_ERROR_BOUND")
    assert t.quantized.abs_error_bound <= b_double
    worst = [0.0, 0.0]
    with mpmath.workdps(40):
        for x, row in zip(xs, rows):
            exact = f(mpmath.mpf(float(x)))
            for j, v in enumerate(row):
                worst[j] = max(worst[j], abs(float(mpmath.mpf(float.fromhex(v)) - exact)))
    assert worst[0] <= b_double
    if has_float:
        assert worst[1] <= macro_value(h, "CHEBNORM_T_QUANT_F_EVAL_ERROR_BOUND")
    # not vacuous: the evaluator reaches most of the located maximum of the quantized polynomial
    assert worst[0] >= 0.9 * t.quantized.max_abs_error


def test_plain_fixed_point_tables_keep_their_header():
    # a uniform fixed-point quantization is the table's fixed_point part: no second copy
    t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 2, var="z", name="d2", coef_frac_bits=24)
    assert t.fixed_point is not None and t.quantized is not None
    assert "_QUANT_" not in c_header(t)


def test_shader_uses_float32_exact_quantized_coefficients():
    t = fit("exp(x)", ("0", "1"), 4, kind="minimax", coef_format="binary32", name="t")
    plain = fit("exp(x)", ("0", "1"), 4, kind="minimax", name="t")
    src = shader_source(t, "glsl")
    for c in t.quantized.coefficients:  # every literal is a quantized coefficient, exactly
        assert f"{float(c).hex()}" in src
    b, b_plain = float32_eval_bound(t), float32_eval_bound(plain)
    assert b.certified == t.quantized.abs_error_bound and b.coefficients == 0
    # the lattice-chosen binary32 coefficients beat rounding the real ones to float32
    assert b.certified + b.coefficients <= b_plain.certified + b_plain.coefficients
    # a fixed-point quantization is not what a shader evaluates: the double coefficients stay
    fixed = fit("exp(x)", ("0", "1"), 4, kind="minimax", coef_frac_bits=20, name="t")
    assert shader_source(fixed, "glsl") == shader_source(plain, "glsl")
