"""Smoke test of the benchmark's C kernels (benchmarks/c): they compile with
strict C99 flags under gcc and clang and compute what the Python kernels
compute; the AVX2 kernels (a native build, on an AVX2 machine) too; the
dichotomy kernel calls no libm function. Correctness only, no timing.
Skipped with a reason when a compiler is absent."""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from chebnorm.methods import count_ops, span_normals

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCH))
import ckernels as ck  # noqa: E402

U = 2.0 ** -24  # float32 unit roundoff


#: strict flags plus the native target: builds the AVX2 kernels on an AVX2 machine
NATIVE = [*ck.STRICT, "-O3", "-march=native", "-fno-math-errno"]


def _build(tmp_path_factory, cc, flags):
    try:
        ck.compiler(cc)
    except ck.ToolMissing as exc:
        pytest.skip(str(exc))
    return ck.build(tmp_path_factory.mktemp(f"cbench_{cc}"), flags, cc=cc)["binary"]


@pytest.fixture(scope="module", params=ck.COMPILERS)
def harness(request, tmp_path_factory):
    return _build(tmp_path_factory, request.param, ck.STRICT)


@pytest.fixture(scope="module", params=ck.COMPILERS)
def native(request, tmp_path_factory):
    binary = _build(tmp_path_factory, request.param, NATIVE)
    if not set(ck.AVX2) & set(ck.kernel_names(binary)):
        pytest.skip("no AVX2 on this machine (-march=native does not define __AVX2__)")
    return binary


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _spans(rng, s=48, psi_lo=0.01, psi_hi=math.pi / 4, offset=False):
    """Random float32-exact unit end normals at angles in [psi_lo, psi_hi],
    lengths 1..40, and positions t0 + j dt with float32-exact t0, dt."""
    nl = _unit(rng.normal(size=(s, 3)))
    psi = rng.uniform(psi_lo, psi_hi, s)
    perp = _unit(np.cross(nl, rng.normal(size=(s, 3))))
    nr = nl * np.cos(psi)[:, None] + perp * np.sin(psi)[:, None]
    nl, nr = (a.astype(np.float32).astype(np.float64) for a in (nl, nr))
    m = rng.integers(1, 41, s)
    dt = (1.0 / m).astype(np.float32).astype(np.float64)
    if offset:  # fractional span ends, as the rasterizer makes them
        t0 = (rng.uniform(0, 1, s) * dt).astype(np.float32).astype(np.float64)
    else:
        t0 = np.zeros(s)
    count = np.floor((1.0 - t0) / dt + 1e-9).astype(np.int64) + 1
    count = np.minimum(count, m + 1)
    return nl, nr, m, t0, dt, count, psi


def _tolerance(method, m, count, psi):
    """A few ulps per operation: set-up ops plus per-pixel ops times the pixel
    index (stepping kernels accumulate), times the index again for the angular
    recurrence (a second-order recurrence lets an early rounding grow
    linearly), plus u/psi for the ill-conditioned sqrt(1 - c^2) of the
    angular set-up."""
    c = count_ops(method, int(m))
    per_span = sum(c.per_span.values())
    per_pixel = sum(c.per_pixel.values())
    j = np.arange(1, count + 1)
    ops = per_span + per_pixel * j
    if method == "angular":
        ops = ops * j
    tol = 4 * U * ops
    if method in ("angular", "slerp"):
        tol = tol + 4 * U / psi
    return tol


def _check_against_python(binary, kernel, spans):
    method = ck.PY_METHOD[kernel]
    nl, nr, m, t0, dt, count, psi = spans
    out = ck.evaluate(binary, kernel, nl, nr, t0, dt, count).astype(np.float64)
    py = span_normals(method, nl, nr, m, t0=t0, dt=dt, count=count, dtype=np.float32)
    assert out.shape == py.normals.shape
    extra = 0.0
    if kernel in ("sse_rsqrt", "avx2_rsqrt_newton"):
        # rsqrtss has relative error <= 1.5 * 2^-12; one Newton step squares it (x 3/2)
        extra = 1.5 * (1.5 * 2.0 ** -12) ** 2
    for i in range(len(nl)):
        a, b = out[py.offsets[i]:py.offsets[i + 1]], py.normals[py.offsets[i]:py.offsets[i + 1]]
        tol = _tolerance(method if kernel != "angular_direct" else "angular", m[i], count[i], psi[i])
        if kernel == "angular_direct":
            tol = 4 * U * (30 + 40) + 4 * U / psi[i] + 0 * tol  # set-up + 2 trig + 6 ops, no accumulation
        err = np.abs(a - b).max(axis=1)
        assert (err <= tol + extra).all(), (
            f"{kernel} span {i} (psi {psi[i]:.4g}, m {m[i]}): max |C - Python| = {err.max():.3g} "
            f"above tolerance {float(np.min(tol + extra)):.3g}")


@pytest.mark.parametrize("offset", [False, True], ids=["t0=0", "t0>0"])
@pytest.mark.parametrize("kernel", ck.NORMAL_KERNELS)
def test_kernel_matches_python(harness, kernel, offset):
    if kernel not in ck.kernel_names(harness):
        pytest.skip(f"kernel {kernel} not built on this machine (no SSE)")
    _check_against_python(harness, kernel, _spans(np.random.default_rng(0), offset=offset))


@pytest.mark.parametrize("offset", [False, True], ids=["t0=0", "t0>0"])
@pytest.mark.parametrize("kernel", ck.AVX2_KERNELS)
def test_avx2_kernel_matches_python(native, kernel, offset):
    # lengths 1..40 exercise the full 8-lane stores and every masked tail
    _check_against_python(native, kernel, _spans(np.random.default_rng(3), offset=offset))


def _grid_spans(rng, s=64):
    """Spans whose pixels lie on the dyadic grid but do not fill it (t0 = i / 2^L,
    count below 2^L + 1 - i, the partial spans of the restricted node range) and
    off-grid spans at angles up to 45 deg (the tables' range) (depth raised above the base)."""
    nl, nr, m, t0, dt, count, psi = _spans(rng, s, psi_lo=0.05, psi_hi=math.pi / 4)
    lv = rng.integers(0, 6, s)
    grid = rng.random(s) < 0.5
    m = np.where(grid, 2 ** lv, m)
    dt = (1.0 / m).astype(np.float32).astype(np.float64)
    i0 = np.floor(rng.random(s) * (m + 1)).astype(np.int64)
    t0 = np.where(grid, i0 * dt, (rng.random(s) * dt).astype(np.float32).astype(np.float64))
    room = np.floor((1.0 - t0) / dt + 1e-9).astype(np.int64) + 1
    count = np.maximum(1, np.minimum(room, rng.integers(1, 42, s)))
    return nl, nr, m, t0, dt, count, psi


@pytest.mark.parametrize("seed", [4, 5])
def test_dichotomy_partial_and_deep_spans(harness, seed):
    """Only the nodes the pixels need are computed: the same pixels as the full tree."""
    _check_against_python(harness, "dichotomy", _grid_spans(np.random.default_rng(seed)))


@pytest.mark.parametrize("seed", [6, 7])
def test_avx2_dichotomy_long_spans(native, seed):
    """The 8-lane tree (levels of up to 256 nodes, on and off the grid) and its
    hand-over to the scalar kernel on partial spans."""
    spans = list(_grid_spans(np.random.default_rng(seed)))
    rng = np.random.default_rng(seed + 10)
    m = rng.integers(9, 300, len(spans[0]))
    grid = rng.random(len(m)) < 0.5
    m = np.where(grid, 2 ** rng.integers(4, 9, len(m)), m)
    dt = (1.0 / m).astype(np.float32).astype(np.float64)
    t0 = np.where(grid | (rng.random(len(m)) < 0.5), 0.0,
                  (rng.random(len(m)) * dt).astype(np.float32).astype(np.float64))
    count = np.floor((1.0 - t0) / dt + 1e-9).astype(np.int64) + 1
    spans[2:6] = m, t0, dt, count
    _check_against_python(native, "avx2_dichotomy", tuple(spans))


def _function_source(src, name):
    start = src.index(f"static inline void {name}(") if f"void {name}(" in src else \
        src.index(f"static inline int {name}(")
    return src[start:src.index("\n}\n", start)]


#: libm functions a span set-up must not call (transcendentals, ldexp)
LIBM = ("acos", "asin", "atan", "cos", "sin", "tan", "exp", "log", "pow", "ldexp", "frexp")


def test_dichotomy_setup_has_no_transcendental_call(harness):
    src = (ck.C_DIR / "kernels.h").read_text()
    body = _function_source(src, "dichotomy_levels") + _function_source(src, "k_dichotomy")
    calls = set(re.findall(r"\b([a-z_0-9]+)\s*\(", body))
    bad = {c for c in calls if c.rstrip("f") in LIBM}
    assert not bad, f"the dichotomy kernel calls {sorted(bad)}"
    objdump = shutil.which("objdump")
    if objdump is None:
        pytest.skip("objdump (binutils) not installed: the binary half is not checked")
    asm = subprocess.run([objdump, "-d", "--no-show-raw-insn", str(harness)], capture_output=True,
                         text=True, check=True).stdout
    funcs = re.split(r"\n(?=[0-9a-f]+ <)", asm)
    dich = [f for f in funcs if re.match(r"[0-9a-f]+ <(k_dichotomy|bench_dichotomy)", f)]
    assert dich, "no dichotomy function in the binary"
    called = set(re.findall(r"call\s+[0-9a-f]+ <([^>@+]+)", "\n".join(dich)))
    assert not {c for c in called if c.rstrip("f") in LIBM}, called


def test_midpoint_kernels(harness):
    rng = np.random.default_rng(1)
    nl, nr, m, t0, dt, count, psi = _spans(rng)
    exact = _unit(nl + nr)
    classic = ck.evaluate(harness, "midpoint_classic", nl, nr, t0, dt, count, per_span=True)
    poly = ck.evaluate(harness, "midpoint_poly", nl, nr, t0, dt, count, per_span=True)
    assert classic.shape == poly.shape == (len(nl), 3)
    assert np.abs(classic - exact).max() <= 4 * U * 12
    table = ck.tables()["midpoint"]
    # |N_l + N_r| <= 2 times the evaluator's error, plus the rounding of the sum and products
    bound = 2 * (table.abs_error_bound + 4 * U * 8) + 4 * U * 4
    assert np.abs(poly - exact).max() <= bound


def test_shading_kernels(harness):
    rng = np.random.default_rng(2)
    nl, nr, m, t0, dt, count, psi = _spans(rng)
    n = span_normals("exact", nl, nr, m, t0=t0, dt=dt, count=count).normals
    L, H = np.array([0.48, 0.36, 0.8]), np.array([0.0, 0.6, 0.8])  # SHADE_L, SHADE_H of kernels.h
    ref = 0.6 * np.maximum(n @ L, 0) + 0.3 * np.maximum(n @ H, 0) ** 32
    phong = ck.evaluate(harness, "phong_n", nl, nr, t0, dt, count, width=1)[:, 0]
    assert np.abs(phong - ref).max() <= 4 * U * 60
    for k in ("phong_nlh", "bump"):
        out = ck.evaluate(harness, k, nl, nr, t0, dt, count, width=1)[:, 0]
        assert out.shape == (int(count.sum()),)
        assert np.isfinite(out).all() and (out >= 0).all() and (out <= 0.9 + 1e-5).all()


def test_headers_come_from_the_exporter(harness):
    h = (harness.parent / "chebnorm_dichotomy_d2.h").read_text()
    assert "generated by chebnorm" in h and "chebnorm_dichotomy_d2_f(float x)" in h
    src = (ck.C_DIR / "kernels.h").read_text()
    for c in ck.tables()["dichotomy"].coefficients + ck.tables()["midpoint"].coefficients:
        assert f"{c:.4f}"[:6] not in src and float(c).hex() not in src


def test_missing_gcc_is_a_clear_message(monkeypatch, tmp_path):
    monkeypatch.setenv("CC", "no-such-compiler-chebnorm")
    with pytest.raises(ck.ToolMissing, match="not found on PATH"):
        ck.build(tmp_path, ck.STRICT)


def test_portable_dichotomy_matches_python(tmp_path_factory):
    """The dichotomy without SSE (plain C nodes, as on a non-x86 machine): same pixels."""
    binary = _build(tmp_path_factory, "gcc", [*ck.STRICT, "-U__SSE__"])
    assert "sse_rsqrt" not in ck.kernel_names(binary)
    for seed in (4, 5):
        _check_against_python(binary, "dichotomy", _grid_spans(np.random.default_rng(seed)))
    _check_against_python(binary, "dichotomy", _spans(np.random.default_rng(0), offset=True))
