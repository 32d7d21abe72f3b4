"""Issue 41: a table in the shifted basis (``basis="auto"`` picks it, e.g. for
``1/sqrt(x)`` on [1, 4]) exports to GLSL, WGSL and HLSL: the shader forms
``t = (x - c) * (1/s)`` (the product exact, ``s`` a power of two) and its
float32 bound covers that subtraction. Checked by glslangValidator, by the
emitted shader text compiled as C (fused and unfused multiply-adds) over every
float32 of [1, 4], by the C header's float evaluator over the same inputs, and
on the GPU driver when there is one."""

from __future__ import annotations

import re
import subprocess

import mpmath
import numpy as np
import pytest

import chebnorm as cn
from chebnorm.export import c_header
from chebnorm.export.shader import float32_eval_bound, shader_evaluator, shader_source
from conftest import requires_tool, run_cli

pytestmark = pytest.mark.filterwarnings("ignore::chebnorm.approx.FitWarning")

needs_gcc = requires_tool("gcc")


@pytest.fixture(scope="module")
def rsqrt():
    """The issue's case, fitted with the defaults (``basis="auto"``)."""
    return cn.fit("1/sqrt(x)", (1, 4), 11, kind="minimax", name="rs")


def test_auto_basis_picks_shifted_and_the_shader_bound_is_near_the_fit(rsqrt):
    assert rsqrt.basis == "shifted" and rsqrt.shift == (2.5, 2.0)
    b = float32_eval_bound(rsqrt)
    # the acceptance: the float32 evaluator's bound within 4x the fit's
    assert b.total <= 4 * rsqrt.abs_error_bound
    assert shader_evaluator(rsqrt).shift is not None


@pytest.mark.parametrize("language", ["glsl", "wgsl", "hlsl"])
def test_shader_forms_the_shifted_variable(rsqrt, language):
    src = shader_source(rsqrt, language)
    assert "Horner's rule in t = (x - 2.5) * 0.5 (the product exact)" in src
    assert re.search(r"t\b[^=\n]*= \(x - 2\.5e\+00f?\) \* 5\.0e-01f?;", src), src
    assert len(re.findall(r"\(acc, t, ", src)) == 11 and "(acc, x," not in src
    assert "// t^11: " in src and "// x^" not in src
    value = re.search(r"EVAL_ERROR_BOUND\W+(?:f32 )?= ([0-9.e+-]+)f?;", src).group(1)
    assert float(np.float32(value)) == float32_eval_bound(rsqrt).total32


@pytest.mark.requires_tool("glslangValidator")
def test_shifted_shaders_compile(rsqrt):
    from chebnorm.export.gpu import compute_shader_source, glslang_validate

    glslang_validate(compute_shader_source(rsqrt, "glsl"), "glsl")
    glslang_validate(compute_shader_source(rsqrt, "glsl", es=True), "glsl")
    glslang_validate(compute_shader_source(rsqrt, "hlsl"), "hlsl")


#: every float32 of [1, 4] through ``chebnorm_rs`` (the shader's function body,
#: compiled as C) and through the C header's float evaluator; the error against
#: 1/sqrt in double (sqrt and / correctly rounded: within 2^-51 of the true value)
SWEEP = r"""
#include <math.h>
#include <stdio.h>
#define CHEBNORM_RS_PRECISE
#define CHEBNORM_RS_FMA(a, b, c) {madd}
#define chebnorm_rs shader_rs
{body}
#undef chebnorm_rs
#include "rs.h"
int main(void)
{{
    double worst_shader = 0, worst_c = 0;
    long n = 0;
    for (float x = 1.0f; x <= 4.0f; x = nextafterf(x, 5.0f), n++) {{
        double ref = 1.0 / sqrt((double)x);
        double es = fabs((double)shader_rs(x) - ref);
        double ec = fabs((double)chebnorm_rs_f(x) - ref);
        if (es > worst_shader) worst_shader = es;
        if (ec > worst_c) worst_c = ec;
    }}
    printf("%ld %a %a %a\n", n, worst_shader, worst_c, CHEBNORM_RS_F_EVAL_ERROR_BOUND);
    return 0;
}}
"""


@needs_gcc
@pytest.mark.parametrize("madd", ["fmaf(a, b, c)", "((a) * (b) + (c))"])
def test_every_float32_of_the_interval_within_the_bounds(rsqrt, tmp_path, madd):
    glsl = shader_source(rsqrt, "glsl")
    start = glsl.index("const float CHEBNORM_RS_LO")
    body = glsl[start:glsl.index("#undef CHEBNORM_RS_PRECISE")]
    (tmp_path / "rs.h").write_text(c_header(rsqrt))
    (tmp_path / "sweep.c").write_text(SWEEP.format(madd=madd, body=body))
    exe = tmp_path / "sweep"
    subprocess.run(["gcc", "-std=c99", "-O2", "-ffp-contract=off", "-o", str(exe),
                    str(tmp_path / "sweep.c"), "-lm"], check=True)
    n, shader_err, c_err, c_bound = subprocess.run(
        [str(exe)], capture_output=True, text=True, check=True).stdout.split()
    assert int(n) == 2 ** 24 + 1          # [1, 2) and [2, 4) hold 2^23 floats each, and 4
    ref_error = 2.0 ** -51
    shader_bound = float32_eval_bound(rsqrt).total32
    assert float.fromhex(shader_err) - ref_error <= shader_bound
    assert float.fromhex(c_err) - ref_error <= float.fromhex(c_bound)
    # the bounds are not vacuous: the fit's error is reached, and the rounding is seen
    assert float.fromhex(shader_err) >= 0.9 * rsqrt.max_abs_error


def test_glsl_shifted_shader_runs_within_its_bound(rsqrt):
    from chebnorm.export.gpu import ToolMissing, float32_inputs, glsl_evaluate

    xs = float32_inputs(rsqrt, 20_000)
    try:
        ys = glsl_evaluate(rsqrt, xs)
    except ToolMissing as exc:
        pytest.skip(str(exc))
    with mpmath.workdps(30):
        worst = max(abs(mpmath.mpf(float(y)) - 1 / mpmath.sqrt(mpmath.mpf(float(x))))
                    for x, y in zip(xs, ys))
    assert worst <= float32_eval_bound(rsqrt).total32


def test_cli_exports_a_default_fit_to_glsl(rsqrt, tmp_path):
    path = tmp_path / "rs.json"
    rsqrt.save(path)
    res = run_cli("export", str(path), "--format", "glsl", "-o", str(tmp_path / "rs.glsl"))
    assert res.code == 0, res.err
    assert "(x - 2.5e+00) * 5.0e-01" in (tmp_path / "rs.glsl").read_text()


@pytest.mark.requires_tool("gappa")
def test_gappa_proves_the_shifted_shader_bound(rsqrt):
    from chebnorm.export.gappa import gappa_script

    ev = shader_evaluator(rsqrt)
    script = gappa_script(ev, float32_eval_bound(rsqrt).total)
    assert "t = rnd(rnd(x - 0x1.4000000000000p+1) * 0x1.0000000000000p-1);" in script
    r = subprocess.run(["gappa"], input=script, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0 and "not satisfied" not in r.stderr, r.stderr[-2000:]
