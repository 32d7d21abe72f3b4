"""binary32 1/sqrt correctly rounded with float32 arithmetic only
(``chebnorm correctly-rounded 1/sqrt --format binary32 --arithmetic float32``).

Independent computations: the integer checker (unsigned __int128 midpoint
test) is itself checked against Python's exact integer square root
(math.isqrt) on every input of a binade slice and on subnormals, with
``1.0f/sqrtf(x)`` (numpy float32 reproduces it: IEEE sqrt and division are
correctly rounded) as the function judged; ``(float)(1.0/sqrt((double)x))``
must pass. The generated C is compiled by gcc (no FMA contraction) and run
on all subnormals, the binades around 1 and 4 and every special input (the
full 2^32 run is the slow test)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from chebnorm.cr import correctly_rounded
from chebnorm.cr._check32 import ALL, check_rsqrt32
from conftest import requires_tool, run_cli

needs_gcc = requires_tool("gcc")

#: a few million inputs: every positive subnormal (and +0), 2^21 on each
#: side of 1 and of 4, +inf, the first and last NaNs of each sign, -0 and
#: negative subnormals, negatives around -1, -inf
QUICK = ((0x00000000, 0x00800000),
         (0x3F800000 - (1 << 21), 0x3F800000 + (1 << 21)),
         (0x40800000 - (1 << 21), 0x40800000 + (1 << 21)),
         (0x7F800000, 0x7F800000 + (1 << 16)), (0x80000000 - (1 << 16), 0x80000000 + (1 << 16)),
         (0xBF800000 - (1 << 15), 0xBF800000 + (1 << 15)),
         (0xFF800000, 0xFF800000 + (1 << 16)), ((1 << 32) - (1 << 16), 1 << 32))
#: how many of QUICK are special (zeros, infinities, NaN, negatives)
QUICK_SPECIAL = 1 + 6 * (1 << 16)

REF_SQRTF = "#include <math.h>\nfloat ref_sqrtf(float x) { return 1.0f / sqrtf(x); }\n"
REF_WIDE = ("#include <math.h>\nfloat ref_wide(float x) { return (float)(1.0 / sqrt((double)x)); "
            "}\n")


def _rn_rsqrt_bits(xb: int) -> int:
    """The bits of 1/sqrt(x) rounded to nearest-even, x a positive finite
    float32 given by its bits, by integer square roots."""
    e, f = xb >> 23, xb & 0x7FFFFF
    X, a = (f, -149) if e == 0 else (f | 0x800000, e - 150)
    N = 120  # 2^N / sqrt(x) = sqrt(2^(2N - a) / X) >= 2^(120 - 64)
    num = 1 << (2 * N - a)
    Z = math.isqrt(num // X)  # floor(2^N / sqrt(x))
    exact = Z * Z * X == num
    sh = Z.bit_length() - 24
    q, rem = Z >> sh, Z & ((1 << sh) - 1)
    half = 1 << (sh - 1)
    if rem > half or (rem == half and not exact) or (rem == half and exact and q & 1):
        q += 1
    c = sh - N  # y = q 2^c
    if q == 1 << 24:
        q, c = q >> 1, c + 1
    return ((c + 150) << 23) | (q & 0x7FFFFF)


def _numpy_sqrtf_bits(xbits: np.ndarray) -> np.ndarray:
    x = xbits.astype(np.uint32).view(np.float32)
    with np.errstate(all="ignore"):
        return (np.float32(1) / np.sqrt(x)).view(np.uint32)


@pytest.mark.parametrize("fma", [True, False])
def test_the_generated_code_has_no_double(fma):
    src = correctly_rounded("1/sqrt", "binary32", arithmetic="float32", fma=fma).files[
        "cr_rsqrt_binary32.c"]
    code = re.sub(r"/\*.*?\*/", "", src, flags=re.S)
    assert not re.search(r"\bdouble\b", src)
    # every floating literal carries the f suffix (an unsuffixed one is a double)
    lits = re.findall(r"(?<![\w.])(0x[0-9a-fA-F.]+p[-+]?\d+\w?|\d+\.\d*(?:e[-+]?\d+)?\w?)", code)
    assert lits and all(s.endswith("f") for s in lits), lits
    assert ("fmaf(" in code) == fma
    assert not re.search(r"\b(sqrtf?|long|uint64_t|int64_t|__int128)\b", code)


@needs_gcc
@pytest.mark.parametrize("fma", [True, False])
def test_the_generated_code_compiles_with_double_promotion_as_an_error(fma, tmp_path):
    from chebnorm.core.tools import run_tool

    r = correctly_rounded("1/sqrt", "binary32", arithmetic="float32", fma=fma)
    for name, text in r.files.items():
        (tmp_path / name).write_text(text)
    run_tool(["gcc", "-std=c11", "-O2", "-ffp-contract=off", "-fno-fast-math", "-Wall",
              "-Wextra", "-Wdouble-promotion", "-Wfloat-conversion", "-Werror", "-c",
              str(tmp_path / "cr_rsqrt_binary32.c"), "-o", str(tmp_path / "o.o")],
             tool="gcc", timeout=60, check=True)


def test_the_integer_oracle_of_the_test_is_right_on_known_values():
    assert _rn_rsqrt_bits(0x3F800000) == 0x3F800000  # 1 -> 1
    assert _rn_rsqrt_bits(0x40800000) == 0x3F000000  # 4 -> 0.5
    assert _rn_rsqrt_bits(0x00000001) == 0x64B504F3  # 2^-149 -> 2^74.5 (sqrt(2) is 0x3FB504F3)
    for xb in (0x40000000, 0x3F800001, 0x7F7FFFFF, 0x12345678):
        x = np.uint32(xb).view(np.float32)
        ref = np.float32(1 / math.sqrt(float(x))).view(np.uint32)  # binary64 then float32
        assert _rn_rsqrt_bits(xb) == int(ref)


@needs_gcc
def test_the_integer_checker_agrees_with_exact_square_roots():
    # the checker's count for 1.0f/sqrtf(x) on a slice equals the count of
    # numpy's 1.0f/sqrtf(x) against math.isqrt, input by input
    slices = ((0x3F800000, 0x3F800000 + 40000), (0x40000000 - 20000, 0x40000000 + 20000),
              (0x00000001, 0x00000001 + 20000), (0x7F7FFFFF - 20000, 0x7F800000))
    want = 0
    for lo, hi in slices:
        xb = np.arange(lo, hi, dtype=np.uint64)
        got = _numpy_sqrtf_bits(xb)
        want += sum(int(g) != _rn_rsqrt_bits(int(b)) for b, g in zip(xb, got))
    assert want > 10000  # 1.0f/sqrtf is wrong often enough for the count to mean something
    res = check_rsqrt32(REF_SQRTF, None, "ref_sqrtf", slices)
    assert res["normal"][1] + res["subnormal"][1] == want
    assert res["special"] == (0, 0)


@needs_gcc
def test_the_checker_accepts_the_binary64_reference_and_flags_sqrtf():
    wide = check_rsqrt32(REF_WIDE, None, "ref_wide", QUICK)
    assert [wide[k][1] for k in ("normal", "subnormal", "special")] == [0, 0, 0]
    bad = check_rsqrt32(REF_SQRTF, None, "ref_sqrtf", QUICK)
    assert bad["normal"][1] > 0 and bad["subnormal"][1] > 0 and bad["special"][1] == 0
    assert bad["normal"][0] + bad["subnormal"][0] + bad["special"][0] == sum(
        hi - lo for lo, hi in QUICK)


@needs_gcc
@pytest.mark.parametrize("fma", [True, False])
def test_subnormals_binades_around_1_and_4_and_specials_are_correctly_rounded(fma):
    r = correctly_rounded("1/sqrt", "binary32", arithmetic="float32", fma=fma)
    assert r.check(ranges=QUICK) == {"RNE": 0}
    got = r.figures["check"]
    assert got["subnormal"] == ((1 << 23) - 1, 0)
    assert got["special"] == (QUICK_SPECIAL, 0)


PROBE_DRIVER = r"""#include <math.h>
#include <stdio.h>
#include <stdint.h>
#include <string.h>
static double worst;
/* |1/sqrt(m) - (y + g)| in binary64: y + g is exact there (y near 1, |g| < 2^-15), and
   1.0 / sqrt(m) is within 2^-52 of 1/sqrt(m) (two correctly rounded operations) */
static void probe(float m, float y, float g)
{
    double e = fabs(1.0 / sqrt((double)m) - ((double)y + (double)g));
    if (e > worst) worst = e;
}
#define CR_PROBE(m, y, g) probe(m, y, g)
#include "probe_src.c"
int main(void)
{
    for (uint32_t b = 0x3f800001u; b < 0x40800000u; b++) { /* x = m: every m in (1, 4) */
        float x;
        memcpy(&x, &b, sizeof x);
        volatile float r = cr_rsqrt_binary32(x);
        (void)r;
    }
    printf("%a\n", worst);
    return 0;
}
"""


@needs_gcc
@pytest.mark.parametrize("fma", [True, False])
def test_the_fast_path_error_bound_holds_on_every_reduced_argument(fma, tmp_path):
    # the fast path returns yn when |d| <= 2^-25 - 2^-32, which is right only if
    # |1/sqrt(m) - (y + g)| < 2^-32 for every m: probed on all 2^24 - 1 m in (1, 4)
    from chebnorm.core.tools import run_tool

    r = correctly_rounded("1/sqrt", "binary32", arithmetic="float32", fma=fma)
    src = r.files["cr_rsqrt_binary32.c"]
    assert src.count("    y = yn;\n") == 1 and "0x1.fcp-26f" in src
    (tmp_path / "probe_src.c").write_text(src.replace("    y = yn;\n",
                                                      "    CR_PROBE(m, y, g);\n    y = yn;\n"))
    (tmp_path / "cr_rsqrt_binary32.h").write_text(r.files["cr_rsqrt_binary32.h"])
    (tmp_path / "probe.c").write_text(PROBE_DRIVER)
    exe = str(tmp_path / "probe")
    run_tool(["gcc", "-std=gnu11", "-O2", "-ffp-contract=off", "-fno-fast-math", "-o", exe,
              str(tmp_path / "probe.c"), "-lm"], tool="gcc", timeout=60, check=True)
    worst = float.fromhex(run_tool([exe], tool="probe", timeout=120, check=True).stdout.strip())
    assert 0 < worst + 2.0 ** -52 < 2.0 ** -33.5  # measured 2^-33.76 (both variants)


@needs_gcc
@pytest.mark.parametrize("old, new", [
    ("{1.0f, -b", "{0x1.fffffep-1f, -b"),          # the 1 of 1 - m h^2, one ulp down
    ("-0x1p-24f * a;", "-0x1.000002p-24f * a;"),   # the upper midpoint's offset, one ulp up
])
def test_a_constant_one_ulp_off_is_caught(old, new):
    r = correctly_rounded("1/sqrt", "binary32", arithmetic="float32")
    src = r.files["cr_rsqrt_binary32.c"]
    assert src.count(old) == 1
    assert r.check(src.replace(old, new), ranges=QUICK)["RNE"] > 0


@needs_gcc
def test_a_start_coefficient_far_off_is_caught_and_one_ulp_off_is_absorbed():
    # Newton's steps absorb a small error of the start (its coefficients are
    # not critical); an error beyond what two steps square away is caught
    r = correctly_rounded("1/sqrt", "binary32", arithmetic="float32")
    src = r.files["cr_rsqrt_binary32.c"]
    c0 = "0x1.bfbe14p+0f"
    assert src.count(c0) == 1
    assert r.check(src.replace(c0, "0x1.bfbe16p+0f"), ranges=QUICK)["RNE"] == 0
    assert r.check(src.replace(c0, "0x1.e0p+0f"), ranges=QUICK)["RNE"] > 0


def test_bad_arguments_name_themselves():
    with pytest.raises(ValueError, match="expr 'exp2'.*accepted: 1/sqrt"):
        correctly_rounded("exp2", "binary32", arithmetic="float32")
    with pytest.raises(ValueError, match="fmt 'binary16'.*accepted: binary32"):
        correctly_rounded("1/sqrt", "binary16", arithmetic="float32")
    with pytest.raises(ValueError, match="arithmetic 'binary64'.*accepted: float32"):
        correctly_rounded("1/sqrt", "binary32")
    with pytest.raises(ValueError, match="fma .*accepted"):
        correctly_rounded("exp2", "binary16", fma=False)
    with pytest.raises(ValueError, match="interval .*accepted"):
        correctly_rounded("1/sqrt", "binary32", arithmetic="float32", interval=(1, 2))
    with pytest.raises(ValueError, match="ranges entry .*accepted"):
        check_rsqrt32(REF_WIDE, None, "ref_wide", ((5, 1),))


def test_cli_writes_the_float_only_files(tmp_path):
    res = run_cli("correctly-rounded", "1/sqrt(x)", "--format", "binary32", "--arithmetic",
                  "float32", "--no-fma", "--lang", "c", "-o", str(tmp_path / "a"))
    assert res.code == 0, res.err
    again = run_cli("correctly-rounded", "1/sqrt(x)", "--format", "binary32", "--arithmetic",
                    "float32", "--no-fma", "--lang", "c", "-o", str(tmp_path / "a"))
    assert again.code == 0
    src = (tmp_path / "a" / "cr_rsqrt_binary32.c").read_text()
    assert "fmaf" not in src and "cr_split" in src and "--no-fma" in src
    assert (tmp_path / "a" / "cr_rsqrt_binary32.h").read_text().count("float cr_rsqrt_binary32(") == 1


@pytest.mark.parametrize("argv, flag", [
    (("exp2", "--format", "binary32", "--arithmetic", "float32"), "EXPR"),
    (("1/sqrt", "--format", "binary32"), "--arithmetic"),
    (("1/sqrt", "--format", "binary16", "--arithmetic", "float32"), "--format"),
    (("exp2", "--format", "binary16", "--no-fma"), "--fma"),
])
def test_cli_refusals_are_one_line_and_status_2(argv, flag, tmp_path):
    res = run_cli("correctly-rounded", *argv, "-o", str(tmp_path / "o"))
    assert res.code == 2
    assert res.err.count("\n") == 1 and flag in res.err and "Traceback" not in res.err


@pytest.mark.slow  # 90 s (fma) and 104 s (no FMA) measured: every float32 input, 2 cores
@needs_gcc
@pytest.mark.parametrize("fma", [True, False])
def test_every_float32_input_is_correctly_rounded(fma):
    r = correctly_rounded("1/sqrt", "binary32", arithmetic="float32", fma=fma)
    assert r.check(ranges=ALL) == {"RNE": 0}
    got = r.figures["check"]
    assert sum(got[k][0] for k in ("normal", "subnormal", "special")) == 1 << 32
    assert got["seconds"] <= 600


@needs_gcc
def test_cli_check_runs_the_compiled_check(tmp_path, monkeypatch):
    # the CLI's --check runs every input; here the run is narrowed to QUICK
    import chebnorm.cr._check32 as check32

    monkeypatch.setattr(check32, "ALL", QUICK)
    res = run_cli("correctly-rounded", "1/sqrt", "--format", "binary32", "--arithmetic",
                  "float32", "-o", str(tmp_path / "c"), "--check")
    assert res.code == 0, res.err
    assert f"subnormal 0 wrong of {(1 << 23) - 1}" in res.out
    assert f"special 0 wrong of {QUICK_SPECIAL}" in res.out
