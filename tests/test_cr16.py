"""Correctly rounded binary16 and bfloat16 functions (:mod:`chebnorm.cr`,
``chebnorm correctly-rounded``): every input of the format, five rounding
modes.

Independent computations: the rounding of a binary64 to the format against
the sorted list of every finite value of the format (and numpy's float16);
the oracle against mpmath at 200 bits on every binary16 input of log2 (which
has exact cases) and on every bfloat16 input of sin (huge arguments); the
generated C compiled by gcc and run on every input in the four rounding
modes C has, against the oracle."""

from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np
import pytest

from chebnorm.cr import correctly_rounded
from chebnorm.cr._formats import BFLOAT16, BINARY16, MODES
from chebnorm.cr._kernels import FUNCTIONS
from chebnorm.cr._oracle import oracle
from chebnorm.cr._solve import ro_interval
from conftest import requires_tool, run_cli

needs_gcc = requires_tool("gcc")
FORMATS = (BINARY16, BFLOAT16)


_SORTED = {}


def _reference_round(fmt, y: float, mode: str) -> float:
    """y rounded to fmt by bracketing it between consecutive values of the
    sorted list of every finite value (infinities beyond)."""
    if fmt.name not in _SORTED:
        vals = fmt.decode(fmt.all_bits())
        vals = np.unique(vals[np.isfinite(vals)])
        _SORTED[fmt.name] = np.r_[-np.inf, vals, np.inf]
    vals = _SORTED[fmt.name]
    i = np.searchsorted(vals, y, side="right") - 1
    a, b = vals[i], vals[min(i + 1, len(vals) - 1)]
    if a == y:
        return float(a)
    # IEEE overflow: the boundary beyond max finite is max + half an ulp
    mx = fmt.max_finite
    ulp = 2.0 ** (fmt.emax - fmt.precision + 1)
    if b == np.inf:
        b_mid = mx + ulp / 2
    elif a == -np.inf:
        b_mid = -mx - ulp / 2
    else:
        b_mid = None
    if mode == "RTZ":
        r = a if y > 0 else b
        return float(np.clip(r, -mx, mx))
    if mode == "RUP":
        return float(b if b != np.inf or y > -mx else b)
    if mode == "RDN":
        return float(a)
    if b_mid is not None:
        if abs(y) < abs(b_mid):
            return float(a if y > 0 else b)
        if abs(y) > abs(b_mid) or True:
            return float(b if y > 0 else a)
    mid = (Fraction(a) + Fraction(b)) / 2
    fy = Fraction(y)
    if fy != mid:
        return float(a if fy < mid else b)
    if mode == "RNA":
        return float(b if y > 0 else a)
    ma = int(fmt.round(np.array([a]), "RTZ")[0])  # a is exact: its bits
    return float(a if ma % 2 == 0 else b)


def test_rounding_to_the_format_matches_an_independent_bracketing():
    rng = np.random.default_rng(47)
    for fmt in FORMATS:
        vals = fmt.decode(fmt.all_bits())
        vals = vals[np.isfinite(vals)]
        picks = rng.choice(vals, 300)
        # neighbours, midpoints, tiny and huge values
        ys = np.r_[picks, np.nextafter(picks, np.inf), np.nextafter(picks, -np.inf),
                   picks * (1 + 2.0 ** -(fmt.precision + 1)), fmt.max_finite * 1.001,
                   -fmt.max_finite * 1.0001, fmt.q_min, -fmt.q_min * 3, 1e-300]
        for mode in MODES:
            got = fmt.decode(fmt.round(ys, mode))
            want = np.array([_reference_round(fmt, float(y), mode) for y in ys])
            assert np.array_equal(got, want), (fmt.name, mode)


def test_round_to_nearest_binary16_matches_numpy_float16():
    y = np.random.default_rng(3).standard_normal(20000) * np.exp2(
        np.random.default_rng(4).integers(-28, 18, 20000))
    with np.errstate(over="ignore"):
        want = y.astype(np.float16).view(np.uint16)
    assert np.array_equal(BINARY16.round(y, "RNE").astype(np.uint16), want)


def _mp_contains(name, fmt, x, ro, lo, hi, exact, f):
    # enough bits for x**3 beside x (tiny x) and for the reduction of huge x
    with mpmath.workprec(200 + 3 * abs(int(np.frexp(x)[1]))):
        v = f(mpmath.mpf(x))
        if exact:
            return v == mpmath.mpf(ro)
        return mpmath.mpf(lo) < v < mpmath.mpf(hi)


@pytest.mark.parametrize("name,fmt,f", [
    ("log2", BINARY16, lambda v: mpmath.log(v, 2)),
    pytest.param("sin", BFLOAT16, mpmath.sin, marks=pytest.mark.slow),  # 7 s measured
])
def test_oracle_agrees_with_mpmath_on_every_input(name, fmt, f):
    x = fmt.decode(fmt.all_bits())
    ro = oracle(name, fmt, x)
    lo, hi, exact = ro_interval(ro, fmt)
    ok = np.isfinite(x) & ~np.isnan(ro) & np.isfinite(ro)
    if name == "log2":
        ok &= x > 0
    for i in np.flatnonzero(ok):
        assert _mp_contains(name, fmt, float(x[i]), float(ro[i]), float(lo[i]), float(hi[i]),
                            bool(exact[i]), f), (name, x[i])
    # the exact cases are exactly the powers of two
    if name == "log2":
        pos = ok & exact
        assert np.array_equal(np.sort(x[pos]), np.sort(x[ok][np.frexp(x[ok])[0] == 0.5]))


@pytest.mark.parametrize("name,x,want", [
    ("rsqrt", 0.0, np.inf), ("rsqrt", -0.0, -np.inf), ("rsqrt", np.inf, 0.0),
    ("sqrt", -0.0, -0.0), ("log", 0.0, -np.inf), ("log2", -0.0, -np.inf), ("log", 1.0, 0.0),
    ("exp", -np.inf, 0.0), ("tanh", -np.inf, -1.0), ("sin", -0.0, -0.0), ("cos", 0.0, 1.0),
])
def test_special_values_are_ieee_and_c99(name, x, want):
    got = oracle(name, BINARY16, np.array([x]))[0]
    assert got == want and np.signbit(got) == np.signbit(want)
    assert np.isnan(oracle(name, BINARY16, np.array([-1.0]))[0]) == (name in (
        "rsqrt", "sqrt", "log", "log2"))


_RESULTS = {}


def _result(name, fmt):
    key = (name, fmt.name)
    if key not in _RESULTS:
        _RESULTS[key] = correctly_rounded("1/sqrt" if name == "rsqrt" else name, fmt.name)
    return _RESULTS[key]


@needs_gcc
@pytest.mark.parametrize("fmt", FORMATS, ids=lambda f: f.name)
@pytest.mark.parametrize("name", FUNCTIONS)
def test_every_input_is_correctly_rounded_in_every_mode(name, fmt):
    r = _result(name, fmt)
    assert r.figures["inputs"] == 65536
    assert r.figures["wrong"] == {m: 0 for m in MODES}
    assert r.figures["seconds"] <= 60.0
    assert r.check() == {"RNE": 0, "RTZ": 0, "RUP": 0, "RDN": 0}


@needs_gcc
def test_a_coefficient_one_ulp_off_is_caught():
    r = _result("exp2", BINARY16)
    src = r.files[f"{r.c_name}.c"]
    one = float(1.0).hex()
    table_start = src.index("CR_E[")
    i = src.index(one, table_start)
    bad = src[:i] + float(np.nextafter(1.0, 2.0)).hex() + src[i + len(one):]
    counts = r.check(bad)
    # exp2 of every integer is exact: one ulp more rounds it up in RUP
    assert counts["RUP"] > 0
    # and a coefficient of a non-exact piece one ulp off keeps 0 only if the margin allows:
    # the Python simulation agrees with the compiled check on the changed code
    from chebnorm.cr._build import simulate, wrong_counts
    from chebnorm.cr._kernels import make_kernel

    coefs = {k: [np.array(row) for row in v] for k, v in r.pieces.items()}
    coefs["E"][0][0] = np.nextafter(1.0, 2.0)
    x = BINARY16.decode(BINARY16.all_bits())
    y = simulate(make_kernel("exp2", BINARY16, r.figures["level"]), coefs, x)
    sim = wrong_counts(BINARY16, y, r._ro)
    assert {m: sim[m] for m in counts} == counts


@pytest.mark.parametrize("kwargs,word", [
    ({"expr": "exp3"}, "expr"), ({"expr": "exp", "fmt": "binary32"}, "fmt"),
    ({"expr": "exp", "arithmetic": "float32"}, "arithmetic"),
    ({"expr": "exp", "lang": "glsl"}, "lang"), ({"expr": "exp", "fmt": "11,-14,16"}, "exponent"),
])
def test_bad_arguments_name_themselves(kwargs, word):
    expr = kwargs.pop("expr")
    with pytest.raises(ValueError, match=word):
        correctly_rounded(expr, **kwargs)


@needs_gcc
@pytest.mark.slow  # 5.3 s measured: two generations and a compiled check
def test_cli_writes_deterministic_files_with_provenance(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    r1 = run_cli("correctly-rounded", "exp2", "--format", "binary16", "--arithmetic",
                 "binary64", "--lang", "c", "-o", str(a), "--check")
    assert r1.code == 0, r1.err
    assert "compiled check (gcc): RNE 0, RTZ 0, RUP 0, RDN 0" in r1.out
    r2 = run_cli("correctly-rounded", "exp2", "--format", "binary16", "--arithmetic",
                 "binary64", "--lang", "c", "-o", str(b))
    assert r2.code == 0, r2.err
    src = (a / "cr_exp2_binary16.c").read_text()
    assert ("correctly rounded in all five rounding modes on every binary16 input, checked "
            "exhaustively") in src.lower()
    assert "chebnorm correctly-rounded exp2" in src
    body = lambda p: p.read_text().split("*/", 1)[1]  # noqa: E731 - the banner quotes -o
    for name in ("cr_exp2_binary16.c", "cr_exp2_binary16.h"):
        assert body(a / name) == body(b / name)


@pytest.mark.parametrize("argv,flag", [
    (["exp3"], "EXPR"), (["exp", "--format", "binary32"], "--format"),
    (["exp", "--arithmetic", "float32"], "--arithmetic"), (["exp", "--lang", "wgsl"], "--lang"),
    (["exp", "--interval", "1", "0"], "--interval"), (["exp", "--interval", "0", "x"], "--interval"),
])
def test_cli_refusals_are_one_line_and_status_2(argv, flag, tmp_path):
    r = run_cli("correctly-rounded", *argv, "-o", str(tmp_path / "o"))
    assert r.code == 2
    assert len(r.err.strip().splitlines()) == 1 and flag in r.err and "Traceback" not in r.err


@needs_gcc
@pytest.mark.parametrize("name", FUNCTIONS)
def test_a_small_format_given_by_precision_and_exponents(name):
    # 9 bits: precision 5, exponents -6..7 (every input, the compiled check too)
    r = correctly_rounded("1/sqrt" if name == "rsqrt" else name, "5,-6,7")
    assert r.format == "p5e7" and r.figures["inputs"] == 512
    assert r.figures["wrong"] == {m: 0 for m in MODES}
    assert r.check() == {"RNE": 0, "RTZ": 0, "RUP": 0, "RDN": 0}


@needs_gcc
@pytest.mark.parametrize("name,interval", [("tanh", (-1.0, 1.0)), ("exp", (-1.0, 1.0)),
                                           ("log", (0.5, 2.0))])
def test_an_interval_is_proved_on_its_inputs_only(name, interval):
    r = correctly_rounded(name, "binary16", interval=interval)
    x = BINARY16.decode(BINARY16.all_bits())
    inside = np.isfinite(x) & (x >= interval[0]) & (x <= interval[1])
    assert r.figures["inputs"] == int(inside.sum())
    assert r.figures["wrong"] == {m: 0 for m in MODES}
    assert r.check() == {"RNE": 0, "RTZ": 0, "RUP": 0, "RDN": 0}
    assert f"every binary16 input in [{interval[0]!r}, {interval[1]!r}]" in r.files[
        f"{r.c_name}.c"]


@pytest.mark.parametrize("interval", [(1.0, -1.0), (0.0, float("nan")), (1e9, 2e9), "ab"])
def test_a_bad_interval_is_refused(interval):
    with pytest.raises(ValueError, match="interval"):
        correctly_rounded("exp", "binary16", interval=interval)
