"""Evaluation bounds account for the format's range (issue 26, items 3, 6, 10).

* ``fit "1e30*x" --interval 0 1e10``: the header stated a float bound of
  1.34e33 while ``chebnorm_big_f(1e10f)`` returned inf; the shaders the same.
  Now the float evaluator is left out of the header with a comment naming the
  first input where it overflows (checked with gcc), the shaders refuse.
* ``fit "exp(x)" --interval 90 91`` (a float coefficient beyond float32) and
  the shifted ``[100, 101]`` table crashed every exporter with OverflowError.
* ``fit "0.3*x" --interval -0.1 0``: ``_LO`` was the double nearest -0.1,
  which lies below -1/10, outside the certified interval.
"""

from __future__ import annotations

import math
import re
import subprocess
from fractions import Fraction

import numpy as np
import pytest

import chebnorm as cn
from chebnorm.approx import fit
from chebnorm.export import c_header
from conftest import requires_tool
from quiet_cli import run_cli_quiet as cli

needs_gcc = requires_tool("gcc")


def _macro(text, name):
    m = re.search(rf"#define \w+_{name} (\S+)", text)
    return None if m is None else float.fromhex(m.group(1).rstrip("f"))


@pytest.fixture(scope="module")
def big():
    return fit("1e30*x", ("0", "1e10"), 1, name="big")


@needs_gcc
def test_float_evaluator_left_out_where_it_overflows(tmp_path, big):
    h = c_header(big)
    assert _macro(h, "F_EVAL_ERROR_BOUND") is None and "chebnorm_big_f(" not in h
    m = re.search(r"/\* No float evaluator: the float evaluator overflows at x = (\S+)\. \*/", h)
    assert m, h
    first = float(m.group(1))
    # the double evaluator and its bound stay; gcc confirms where float overflows
    (tmp_path / "big.h").write_text(h)
    probe = f"""#include <stdio.h>
#include <math.h>
#include "big.h"
static float horner_f(float x) {{ float acc = (float)chebnorm_big_coeffs[1];
    return acc * x + (float)chebnorm_big_coeffs[0]; }}
int main(void) {{
    float at = {first!r}f, before = nextafterf(at, 0.0f);
    printf("%d %d %d\\n", isinf(horner_f(at)), isinf(horner_f(before)),
           isinf(horner_f((float)CHEBNORM_BIG_HI)));
    printf("%.17g\\n", fabs(chebnorm_big(CHEBNORM_BIG_HI) - 1e40));
    return 0; }}
"""
    (tmp_path / "p.c").write_text(probe)
    subprocess.run(["gcc", "-std=c99", "-O0", "-ffp-contract=off", "p.c", "-o", "p", "-lm"],
                   cwd=tmp_path, check=True)
    out = subprocess.run(["./p"], cwd=tmp_path, capture_output=True, text=True,
                         check=True).stdout.split()
    assert out[:3] == ["1", "0", "1"]  # inf at the named input, finite just below it
    assert float(out[3]) <= _macro(h, "EVAL_ERROR_BOUND")


@pytest.mark.parametrize("fmt", ["glsl", "wgsl", "hlsl"])
def test_shaders_refuse_an_overflowing_evaluator(big, fmt):
    with pytest.raises(ValueError, match=r"no float32 shader evaluator on its interval: the "
                                         r"float evaluator overflows at x = 34028\d+\.0; accepted"):
        cn.export(big, fmt)


def test_cli_item3(tmp_path):
    assert cli("fit", "1e30*x", "--interval", "0", "1e10", "--degree", "1", "--name", "big",
               "-o", "G.json", cwd=tmp_path).code == 0
    r = cli("export", "G.json", "--format", "c", "-o", "G.h", cwd=tmp_path)
    assert r.code == 0, r.err
    assert "F_EVAL_ERROR_BOUND" not in (tmp_path / "G.h").read_text()
    for fmt in ("glsl", "wgsl", "hlsl"):
        r = cli("export", "G.json", "--format", fmt, "-o", f"G.{fmt}", cwd=tmp_path)
        assert r.code == 2 and r.err.count("\n") == 1, r.err
        assert "overflows at x = " in r.err and "accepted:" in r.err
        assert not (tmp_path / f"G.{fmt}").exists()


@pytest.mark.parametrize("args", [["--interval", "90", "91"],
                                  ["--interval", "100", "101", "--basis", "shifted"]])
def test_item6_tables_it_wrote_itself(tmp_path, args):
    r = cli("fit", "exp(x)", *args, "--degree", "3", "-o", "F.json", cwd=tmp_path)
    assert r.code == 0, r.err
    r = cli("export", "F.json", "--format", "c", "-o", "F.h", cwd=tmp_path)
    assert r.code == 0, r.err
    h = (tmp_path / "F.h").read_text()
    assert "is not finite in float" in h and "_F_EVAL_ERROR_BOUND" not in h
    assert _macro(h, "EVAL_ERROR_BOUND") >= _macro(h, "ABS_ERROR_BOUND")
    for fmt in ("glsl", "wgsl", "hlsl"):
        r = cli("export", "F.json", "--format", fmt, "-o", f"F.{fmt}", cwd=tmp_path)
        assert r.code == 2 and r.err.count("\n") == 1, r.err
        assert "Traceback" not in r.err and "accepted:" in r.err


@needs_gcc
def test_item6_double_evaluator_bound_holds(tmp_path):
    """The double evaluator of the [90, 91] table, compiled, stays within its
    stated bound of exp (measured against mpmath at 1001 points)."""
    import mpmath

    t = fit("exp(x)", ("90", "91"), 3, name="e")
    h = c_header(t)
    (tmp_path / "e.h").write_text(h)
    (tmp_path / "m.c").write_text('#include <stdio.h>\n#include "e.h"\nint main(void) { double x;'
                                  ' while (scanf("%la", &x) == 1) printf("%a\\n", chebnorm_e(x));'
                                  ' return 0; }\n')
    subprocess.run(["gcc", "-std=c99", "-O2", "m.c", "-o", "m"], cwd=tmp_path, check=True)
    xs = np.linspace(90, 91, 1001)
    out = subprocess.run(["./m"], cwd=tmp_path, input="\n".join(float(x).hex() for x in xs),
                         capture_output=True, text=True, check=True).stdout.split()
    bound = _macro(h, "EVAL_ERROR_BOUND")
    mpmath.mp.prec = 200
    worst = max(abs(mpmath.mpf(float.fromhex(y)) - mpmath.exp(mpmath.mpf(float(x))))
                for x, y in zip(xs, out))
    assert worst <= bound


def test_lo_hi_inside_the_certified_interval():
    t = fit("0.3*x", ("-0.1", "0"), 1)
    assert Fraction(t.interval_float[0]) < Fraction(-1, 10)  # the nearest double lies outside
    h = c_header(t)
    lo, hi = _macro(h, "LO"), _macro(h, "HI")
    assert Fraction(-1, 10) <= Fraction(lo) and lo == math.nextafter(-0.1, 0) and hi == 0.0
    for fmt in ("glsl", "wgsl", "hlsl"):
        text = cn.export(t, fmt)
        lo32 = float(re.search(r"_LO\b[^=\n]*=\s*(-?[0-9.]+e[-+][0-9]+)", text).group(1))
        assert Fraction(-1, 10) <= Fraction(float(np.float32(lo32))), fmt
    # an irrational endpoint too: both printed ends inside [sqrt(2), pi]
    t = fit("x", ("sqrt(2)", "pi"), 1)
    h = c_header(t)
    import mpmath
    mpmath.mp.prec = 200
    assert mpmath.sqrt(2) <= _macro(h, "LO") and _macro(h, "HI") <= mpmath.pi


def test_float_bound_covers_underflow():
    """A table whose values are subnormal in float: the float products round
    to subnormals; the stated float bound covers what that loses."""
    t = fit("1e-40*x", ("0", "1"), 1, name="tiny")
    h = c_header(t)
    c1 = float(np.float32(t.coefficients[1]))
    c0 = float(np.float32(t.coefficients[0]))
    bound = _macro(h, "F_EVAL_ERROR_BOUND")
    xs = np.linspace(0, 1, 4097, dtype=np.float32)
    with np.errstate(under="ignore"):
        y = np.float32(c1) * xs + np.float32(c0)
    exact = [Fraction(1, 10 ** 40) * Fraction(float(x)) for x in xs]
    worst = max(abs(Fraction(float(v)) - e) for v, e in zip(y, exact))
    assert worst > 0 and worst <= Fraction(bound)


def test_hw_report_json_with_a_zero_of_f(tmp_path):
    """f(0) = 0 at a valid code: the measured relative error is undefined
    there; ``hw report --json`` failed on the NaN ('not JSON compliant')."""
    assert cli("fit", "0.3*x", "--interval", "-0.1", "0", "--degree", "1", "-o", "L.json",
               cwd=tmp_path).code == 0
    r = cli("hw", "report", "L.json", "--in-bits", "8", "--out-bits", "8", "--coef-frac-bits",
            "12", "--no-gappa", "--no-synth", "--json", cwd=tmp_path)
    assert r.code == 0, r.err
    import json
    d = json.loads(r.out)
    assert d["measured"]["rel_total"] is None and d["measured"]["shading_levels"] is None
