"""The stated evaluation bounds against every float32 input, and their Gappa proofs.

For the 8 registered tables (``figures/coefficients``) and fits of our own
(a high-degree one, rounding-dominated ones, a fixed-point one, an odd and an
even evaluator, a piecewise one), each exported evaluator is compiled with gcc
-O2 twice (``-ffp-contract=off`` and ``-mfma -ffp-contract=fast``) and run on
every float32 of its interval (every input code for the fixed-point and
piecewise evaluators). The reference ``f`` is computed in x87 long double
(64-bit significand; glibc's ``sqrtl``/``powl``/``sinl``/... are within a few
ulps, so its error is below ``2^-60 |f|``); a measured maximum ``m`` is
accepted when ``m + 2^-56 max|f| <= bound``, a margin 16x larger than the
reference's error. Tightness: wherever rounding dominates (the local rounding
part of the bound exceeds the approximation bound) the bound is at most 1.25x
the measured maximum.

Every proof script is run through ``gappa`` (skipped when it is absent), and a
tampered one (the bound halved) must fail.
"""

from __future__ import annotations

import glob
import os
import subprocess
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from chebnorm.approx import load_table
from chebnorm.core.numeric import float_up
from chebnorm.export import export_with_proofs
from chebnorm.export.c import c_header_evaluators
from chebnorm.export.c_piecewise import piecewise_evaluator
from chebnorm.export.gappa import gappa_script
from chebnorm.export.shader import float32_eval_bound, shader_evaluator

ROOT = Path(__file__).resolve().parents[1]
REGISTERED = sorted(glob.glob(str(ROOT / "figures" / "coefficients" / "*.json")))
BUILDS = (("-O2", "-ffp-contract=off"), ("-O2", "-march=native", "-mfma", "-ffp-contract=fast"))
REF_MARGIN = 2.0 ** -56
TIGHT = 1.25
#: rounding-dominated evaluators whose bound exceeds TIGHT x the measured
#: maximum. Empty: where the interval analysis is loose (own_exp_d6 float on
#: [1, 2]: 1.79x; own_sin_odd degree 7 float: 1.50x, several roundings that
#: never all reach their worst case on one float32) the header states the
#: exhaustive certificate of chebnorm.export.certificate instead.
KNOWN_LOOSE = frozenset()


def _own(key):
    from chebnorm.approx import fit
    from chebnorm.approx.piecewise_fit import piecewise_fit

    if key == "rsqrt_d8":  # high degree: rounding dominates in float and double
        return fit("1/sqrt(x)", ("1/2", "1"), 8, kind="minimax", name="own_rsqrt_d8")
    if key == "exp_d6":
        # plain powers: the shader evaluators take no shifted table
        return fit("exp(x)", ("1", "2"), 6, kind="minimax", name="own_exp_d6", basis="monomial")  # 2^23 float32s (on [0, 1]: 2^30, minutes in long double)
    if key == "rsqrt_d3_fixed":
        return fit("1/sqrt(x)", ("1/2", "1"), 3, kind="minimax", coef_frac_bits=16,
                   name="own_rsqrt_fixed")
    if key == "sin_odd":
        return fit("sin(x)", ("1/4", "1"), 7, monomials=[1, 3, 5, 7], coef_format="binary32",
                   name="own_sin_odd")
    if key == "cos_even":
        return fit("cos(x)", ("1/4", "1"), 6, monomials=[0, 2, 4, 6], coef_format="binary32",
                   name="own_cos_even")
    if key == "log_d5":
        return fit("log(x)", ("1", "2"), 5, kind="minimax", name="own_log_d5")
    if key == "shifted":  # t = (x - 3/4) * 4 computed in the evaluator's type
        return fit("1/sqrt(x)", ("1/2", "1"), 4, kind="minimax", basis="shifted",
                   name="own_shifted")
    if key == "piecewise":
        return piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=8, name="own_pw")
    raise KeyError(key)


OWN = ("rsqrt_d8", "exp_d6", "rsqrt_d3_fixed", "sin_odd", "cos_even", "log_d5", "shifted")
_CACHE: dict = {}


def _table(key):
    if key not in _CACHE:
        _CACHE[key] = load_table(key) if key.endswith(".json") else _own(key)
    return _CACHE[key]


def _ref_expr(table) -> str:
    from sympy.codegen.ast import float80, real
    from sympy.printing.c import C99CodePrinter

    class Printer(C99CodePrinter):
        def _print_Pow(self, expr):  # 1/sqrtl, not the much slower powl(b, -1/2)
            if expr.exp == -sp.S.Half:
                return f"(1.0L/sqrtl({self._print(expr.base)}))"
            return super()._print_Pow(expr)

    x = sp.Symbol(table.variable)
    e = sp.sympify(table.expression, locals={table.variable: x})
    return Printer({"type_aliases": {real: float80}}).doprint(e.subs(x, sp.Symbol("X")))


_HARNESS = r"""
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include "%(header)s"
static long double ref(long double X) { return %(expr)s; }
int main(void)
{
    long double md = 0, mf = 0, mq = 0, mqu = 0, mqf = 0, fmax = 0;
    float lo = (float)%(macro)s_LO, hi = (float)%(macro)s_HI;
    if ((double)lo < %(macro)s_LO) lo = nextafterf(lo, INFINITY);
    if ((double)hi > %(macro)s_HI) hi = nextafterf(hi, -INFINITY);
    for (float x = lo; x <= hi; x = nextafterf(x, INFINITY)) {
        long double r = ref(x), e;
        if (fabsl(r) > fmax) fmax = fabsl(r);
        e = fabsl((long double)%(fn)s((double)x) - r); if (e > md) md = e;
%(float)s
%(quant)s
        if (x == hi) break;
    }
%(fixed)s
    printf("%%.20Le %%.20Le %%.20Le %%.20Le %%.20Le %%.20Le\n", md, mf, mq, mqu, mqf, fmax);
    return 0;
}
"""


def _harness(table, header: str) -> str:
    name = table.name
    macro, fn = f"CHEBNORM_{name.upper()}", f"chebnorm_{name}"
    text = Path(header).read_text()
    flt = (f"        e = fabsl((long double){fn}_f(x) - r); if (e > mf) mf = e;"
           if f"{fn}_f(float x)" in text else "")
    quant = ""
    if f"{fn}_quant(double x)" in text:
        quant += f"        e = fabsl((long double){fn}_quant((double)x) - r); if (e > mqu) mqu = e;\n"
    if f"{fn}_quant_f(float x)" in text:
        quant += f"        e = fabsl((long double){fn}_quant_f(x) - r); if (e > mqf) mqf = e;\n"
    fixed = ""
    if f"{fn}_q_eval(" in text:
        f = table.fixed_point.frac_bits
        fixed = (f"    for (int64_t k = (int64_t)ceill((long double){macro}_LO * {2 ** f}.0L);"
                 f" k <= (int64_t)floorl((long double){macro}_HI * {2 ** f}.0L); k++) {{\n"
                 f"        long double X = (long double)k / {2 ** f}.0L;\n"
                 f"        long double e = fabsl((long double){fn}_q_eval(k) / {2 ** f}.0L"
                 f" - ref(X));\n        if (e > mq) mq = e;\n    }}")
    return _HARNESS % {"header": header, "expr": _ref_expr(table), "macro": macro, "fn": fn,
                       "float": flt, "quant": quant, "fixed": fixed}


def _run_c(src: str, tmp: Path, flags) -> list[float]:
    c = tmp / "h.c"
    c.write_text(src)
    exe = tmp / "h"
    subprocess.run(["gcc", *flags, "-o", str(exe), str(c), "-lm"], check=True,
                   capture_output=True)
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    return [float(v) for v in out.split()]


def _bounds(header_text: str) -> dict:
    out = {}
    for line in header_text.splitlines():
        if line.startswith("#define") and "EVAL_ERROR_BOUND" in line:
            v = line.split()[2]  # a hex literal (c.py) or a repr (c_piecewise.py)
            out[line.split()[1]] = float.fromhex(v) if "0x" in v else float(v)
    return out


CASES = [os.path.basename(p) for p in REGISTERED] + list(OWN)


def _key(case):
    return str(ROOT / "figures" / "coefficients" / case) if case.endswith(".json") else case


@pytest.mark.requires_tool("gcc")
@pytest.mark.parametrize("case", CASES)
def test_bounds_hold_over_every_float32_and_are_tight(case, tmp_path):
    table = _table(_key(case))
    text, evaluators = c_header_evaluators(table)
    header = tmp_path / f"chebnorm_{table.name}.h"
    header.write_text(text)
    stated = _bounds(text)
    macro = f"CHEBNORM_{table.name.upper()}"
    slots = {f"{macro}_EVAL_ERROR_BOUND": 0, f"{macro}_F_EVAL_ERROR_BOUND": 1,
             f"{macro}_Q_EVAL_ERROR_BOUND": 2, f"{macro}_QUANT_EVAL_ERROR_BOUND": 3,
             f"{macro}_QUANT_F_EVAL_ERROR_BOUND": 4}
    by_constant = {ev.constant: ev for ev in evaluators}
    assert set(stated) == set(by_constant)
    runs = [_run_c(_harness(table, str(header)), tmp_path, flags) for flags in BUILDS]
    loose = []
    for constant, bound in stated.items():
        for flags, measured in zip(BUILDS, runs):
            m = measured[slots[constant]]
            assert m > 0, (constant, flags)  # the evaluator ran
            assert m + REF_MARGIN * measured[5] <= bound, (constant, flags, m, bound)
        # one bound for both builds: tight against the larger maximum
        m = max(measured[slots[constant]] for measured in runs)
        b = by_constant[constant].bound()
        if b.local > b.approximation and bound > TIGHT * m:  # rounding dominates
            loose.append((constant, m, bound, bound / m))
    assert not [x for x in loose if x[0] not in KNOWN_LOOSE], loose


@pytest.mark.requires_tool("gcc")
def test_piecewise_bound_holds_over_every_input_code(tmp_path):
    table = _own("piecewise")
    ev = piecewise_evaluator(table)
    files = export_with_proofs(table, "c", tmp_path / "pw.h")
    bound = _bounds(files["pw.h"])["CHEBNORM_OWN_PW_EVAL_ERROR_BOUND"]
    assert bound == ev.bound().stated
    src = r"""
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include "pw.h"
int main(void) {
    long double m = 0;
    for (uint32_t k = 0; k < (UINT32_C(1) << 24); k++) {
        long double x = 1.0L + 3.0L * (long double)k / 16777216.0L;
        long double e = fabsl((long double)chebnorm_own_pw(k) - 1.0L / sqrtl(x));
        if (e > m) m = e;
    }
    printf("%.20Le\n", m);
    return 0;
}
"""
    for flags in BUILDS:
        (tmp_path / "pw.c").write_text(src)
        subprocess.run(["gcc", *flags, "-o", str(tmp_path / "pw"), str(tmp_path / "pw.c"), "-lm"],
                       check=True, capture_output=True)
        m = float(subprocess.run([str(tmp_path / "pw")], check=True, capture_output=True,
                                 text=True).stdout)
        assert 0 < m and m + REF_MARGIN <= bound


def test_tighter_than_the_a_priori_formula_on_rsqrt_d3_float():
    """The issue's example: 3.88e-6 stated (a priori) against 1.64e-6 measured."""
    table = _table(str(ROOT / "figures" / "coefficients" / "rsqrt_d3.json"))
    b = _bounds(c_header_evaluators(table)[0])["CHEBNORM_RSQRT_D3_F_EVAL_ERROR_BOUND"]
    assert 1.64e-6 < b < 1.25 * 1.64e-6


def _gappa(script: str, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run(["gappa"], input=script, capture_output=True, text=True, timeout=timeout)


def _all_evaluators():
    out = []
    for case in CASES:
        table = _table(_key(case))
        evs = c_header_evaluators(table)[1]
        out += [(case, ev.constant, ev, None) for ev in evs]
        if table.shift is None:
            b = float32_eval_bound(table)  # the proof proves the a-priori bound
            out.append((case, "shader", shader_evaluator(table),  # behind a certificate
                        b.total32 if b.certificate is None else None))
    table = _own("piecewise")
    out.append(("piecewise", "c", piecewise_evaluator(table), None))
    return out


@pytest.mark.requires_tool("gappa")
@pytest.mark.parametrize("index", range(len(CASES) * 4 + 1))
def test_gappa_proves_every_stated_bound(index):
    evs = _all_evaluators()
    if index >= len(evs):
        pytest.skip("no evaluator at this index")
    case, what, ev, bound = evs[index]
    r = _gappa(gappa_script(ev, bound))
    assert r.returncode == 0, (case, what, r.stderr[-2000:])
    assert "not satisfied" not in r.stderr


@pytest.mark.requires_tool("gappa")
@pytest.mark.parametrize("constant", ["CHEBNORM_RSQRT_D3_Q_EVAL_ERROR_BOUND",
                                      "CHEBNORM_RSQRT_D3_F_EVAL_ERROR_BOUND"])
def test_gappa_refuses_a_tampered_bound(constant):
    table = _table(str(ROOT / "figures" / "coefficients" / "rsqrt_d3.json"))
    ev = {e.constant: e for e in c_header_evaluators(table)[1]}[constant]
    r = _gappa(gappa_script(ev, ev.bound().stated / 2))
    assert r.returncode != 0 and "not satisfied" in r.stderr


def test_committed_proofs_are_the_printed_ones():
    """Each committed header names its proof files, and they hold the scripts printed now."""
    for path in REGISTERED:
        table = load_table(path)
        stem = f"chebnorm_{table.name}"
        text, evs = c_header_evaluators(table, "chebnorm repro coefficients", proof=f"{stem}.h")
        folder = Path(path).parent
        assert (folder / f"{stem}.h").read_text() == text
        for ev in evs:
            name = f"{stem}.h.{ev.constant}.gappa"
            assert f"proof: {name}" in text
            assert (folder / name).read_text() == gappa_script(ev)


def test_cli_export_proof_writes_the_scripts(tmp_path):
    from chebnorm.cli import main

    src = REGISTERED[0]
    for fmt, suffix in (("c", ".h"), ("glsl", ".glsl"), ("wgsl", ".wgsl"), ("hlsl", ".hlsl")):
        out = tmp_path / f"t{suffix}"
        assert main(["export", src, "--format", fmt, "-o", str(out), "--proof"]) == 0
        scripts = sorted(p.name for p in tmp_path.glob("t.*.gappa"))
        assert scripts and all(p.startswith(f"t{suffix}.CHEBNORM_") for p in scripts)
        text = out.read_text()
        assert all(name in text for name in scripts if fmt == "c" or "_F_" not in name)
        for p in tmp_path.glob("t.*.gappa"):
            p.unlink()


def test_shader_bound_is_the_float_bound_in_float32():
    for path in REGISTERED:
        table = load_table(path)
        c_f = _bounds(c_header_evaluators(table)[0])[
            f"CHEBNORM_{table.name.upper()}_F_EVAL_ERROR_BOUND"]
        b = float32_eval_bound(table)
        assert b.flush < Fraction(2) ** -100  # a subnormal input flushed to 0
        assert b.total == float_up(Fraction(c_f) + b.flush) and b.total <= b.total32
        assert np.float32(b.total32) == b.total32


# -- the exhaustive certificate (chebnorm.export.certificate) ------------------------------


def _every_float32(ev):
    from chebnorm.export.certificate import float32_range

    k0, k1 = float32_range(ev.pieces[0].lo, ev.pieces[0].hi)
    k = np.arange(k0, k1 + 1, dtype=np.int64)
    assert k0 >= 0  # the intervals below are positive
    return k.astype(np.uint32).view(np.float32)


def _float_evaluator(case, constant_part):
    table = _table(_key(case))
    text, evs = c_header_evaluators(table)
    ev = next(e for e in evs if e.constant.endswith(constant_part))
    return table, text, ev


def _pure(ev, x, fused):
    """The evaluator with every step fused, or none, written out here."""
    from chebnorm.export.certificate import fma32

    cs = [np.float32(c) for c in ev.pieces[0].coeffs]
    if ev.parity is not None:
        cs, t = cs[ev.parity::2], x * x
    elif ev.shift is not None:
        _, s, c_t, s_t, exact = ev.shift
        d = x - np.float32(c_t)
        t = d * np.float32(1 / s) if exact else d / np.float32(s_t)
    else:
        t = x
    acc = np.full_like(x, cs[-1])
    for c in reversed(cs[:-1]):
        acc = fma32(acc, t, np.full_like(acc, c)) if fused else acc * t + c
    return (acc * x if ev.parity == 1 else acc).astype(np.float64)


@pytest.mark.requires_tool("gcc")
@pytest.mark.parametrize("case, part, drop", [("exp_d6", "_F_EVAL_ERROR_BOUND", 2),
                                               ("sin_odd", "_QUANT_F_EVAL_ERROR_BOUND", "t"),
                                               ("shifted", "_F_EVAL_ERROR_BOUND", 1)])
def test_certificate_simulation_is_the_compiled_evaluator(case, part, drop):
    """Every output of the compiled float evaluator (gcc -O2 -ffp-contract=off, and
    -O2 -march=native -ffp-contract=fast) on every float32 of its interval lies in
    the simulated [lo, hi] of all fused/unfused mixes, and each pure build's output
    is one of its ends; the simulation with one rounding left out is caught."""
    from chebnorm.export.certificate import float32_simulation
    from chebnorm.export.verify import c_evaluate

    table, text, ev = _float_evaluator(case, part)
    x = _every_float32(ev)
    lo, hi = float32_simulation(ev, x)
    pure = float32_simulation(ev, x, pure=True)
    bad = float32_simulation(ev, x, drop=drop, pure=True)
    for fused in (False, True):
        y = c_evaluate(text, ev.function, x, fused=fused).astype(np.float64)
        assert np.all((lo <= y) & (y <= hi)), (case, fused)
        assert np.array_equal(y, _pure(ev, x, fused)), (case, fused)  # written out here
        assert np.array_equal(y, pure[fused]), (case, fused)  # the certificate's simulation
        if not fused or drop == "t":  # a dropped product rounding is the unfused path's
            assert not np.array_equal(y, bad[fused]), (case, fused, "mutation not caught")
    assert np.any(lo < hi)  # fusing does change some results


@pytest.mark.requires_tool("gcc")
def test_fma32_is_gccs_fmaf(tmp_path):
    """The exact fma emulation against the C library's fmaf, bit for bit, on
    seeded random triples over many binades and on ties, sticky bits and
    subnormal results."""
    import ctypes

    from chebnorm.export.certificate import fma32

    src = tmp_path / "f.c"
    src.write_text("#include <math.h>\nvoid f(const float *a, const float *b, const float *c,"
                   " float *o, long n) { for (long i = 0; i < n; i++) o[i] = fmaf(a[i], b[i],"
                   " c[i]); }\n")
    lib = tmp_path / "f.so"
    subprocess.run(["gcc", "-O2", "-fPIC", "-shared", "-fno-builtin", "-o", str(lib), str(src),
                    "-lm"], check=True, capture_output=True)
    f = ctypes.CDLL(str(lib)).f
    rng = np.random.default_rng(29)
    n = 1 << 20

    def rand(lo, hi):
        m = rng.uniform(1, 2, n) * rng.choice([-1, 1], n)
        return np.ldexp(m, rng.integers(lo, hi, n)).astype(np.float32)

    a, b = rand(-60, 60), rand(-60, 60)  # products within the float32 range
    c = np.where(rng.random(n) < 0.5, (a.astype(np.float64) * b * rng.uniform(-1.5, 1.5, n)),
                 rand(-150, 70)).astype(np.float32)
    one = np.float32(1 + 2.0 ** -12)
    extra = [(one, one, np.float32(-1)), (one, one, np.float32(2.0 ** -60)),
             (np.float32(1 + 2.0 ** -23), np.float32(1 + 2.0 ** -23), np.float32(-2.0 ** -70)),
             (np.float32(2.0 ** -70), np.float32(2.0 ** -70), np.float32(0)),
             (np.float32(2.0 ** -63), np.float32(1.5 * 2.0 ** -63), np.float32(-2.0 ** -126))]
    a = np.concatenate([a, [e[0] for e in extra]]).astype(np.float32)
    b = np.concatenate([b, [e[1] for e in extra]]).astype(np.float32)
    c = np.concatenate([c, [e[2] for e in extra]]).astype(np.float32)
    out = np.empty_like(a)
    p = ctypes.POINTER(ctypes.c_float)
    f(a.ctypes.data_as(p), b.ctypes.data_as(p), c.ctypes.data_as(p), out.ctypes.data_as(p),
      ctypes.c_long(len(a)))
    mine = fma32(a, b, c)
    assert np.array_equal(mine.view(np.uint32), out.view(np.uint32))
    assert np.any(mine != (a * b) + c)  # the triples do tell fused from unfused


@pytest.mark.requires_tool("gcc")
def test_certificate_is_the_exhaustive_maximum_and_a_halved_one_is_caught(tmp_path):
    """The certified value is the measured maximum over both builds to within the
    stated rounding (it covers mixed fusions too, so it may be a little larger),
    and half of it is exceeded by the measurement."""
    from chebnorm.export.certificate import stated_bound

    table, text, ev = _float_evaluator("rsqrt_d8", "_F_EVAL_ERROR_BOUND")
    value, cert = stated_bound(ev)
    assert cert is not None and value == cert.stated == _bounds(text)[ev.constant]
    header = tmp_path / f"chebnorm_{table.name}.h"
    header.write_text(text)
    m = max(_run_c(_harness(table, str(header)), tmp_path, flags)[1] for flags in BUILDS)
    assert m + REF_MARGIN <= float(cert.maximum) <= cert.stated <= TIGHT * m
    assert not m <= cert.stated / 2


@pytest.mark.requires_tool("gappa")
@pytest.mark.parametrize("fmt, suffix", [("c", ".h"), ("glsl", ".glsl")])
def test_a_certified_constant_names_its_evidence_and_its_proof_holds(fmt, suffix, tmp_path):
    """Where the exhaustive certificate is stated, the text says so, gives the
    a-priori bound, and the written Gappa script proves that a-priori bound."""
    from chebnorm.export.certificate import stated_bound

    table = _table("exp_d6")
    out = tmp_path / f"e{suffix}"
    files = export_with_proofs(table, fmt, out)
    ev = (c_header_evaluators(table)[1][1] if fmt == "c" else shader_evaluator(table))
    value, cert = stated_bound(ev)
    assert cert is not None and value < ev.bound().stated
    text = files[out.name]
    assert "exhaustive" in text and repr(ev.bound().stated) in text
    name = f"e{suffix}.{ev.constant}.gappa"
    assert name in text and files[name] == gappa_script(ev)
    r = _gappa(files[name])
    assert r.returncode == 0 and "not satisfied" not in r.stderr, r.stderr[-2000:]


@pytest.mark.parametrize("fmt", ["glsl", "wgsl"])
def test_certified_shader_constant_holds_on_the_driver(fmt):
    """The shader constant backed by a certificate holds on Mesa's llvmpipe
    (GLSL) and lavapipe (WGSL) over every float32 (skipped without a driver)."""
    from chebnorm.export.verify import verify

    table = _table("exp_d6")
    assert float32_eval_bound(table).certificate is not None
    result = verify(table, fmt)
    ran = [v for v in result.variants if v.skipped is None]
    if not ran:
        pytest.skip("; ".join(v.skipped for v in result.variants))
    assert all(v.passed for v in ran), [v.line() for v in ran]
    assert all(v.measured_max * TIGHT >= v.stated_bound for v in ran), [v.line() for v in ran]
