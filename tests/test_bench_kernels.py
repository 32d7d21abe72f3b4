"""Smoke test of the benchmark's C kernels (benchmarks/c): they compile with
strict C99 flags and compute what the Python kernels compute. Correctness
only, no timing. Skipped with a reason when gcc is absent."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from chebnorm.methods import count_ops, span_normals

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
sys.path.insert(0, str(BENCH))
import ckernels as ck  # noqa: E402

U = 2.0 ** -24  # float32 unit roundoff


@pytest.fixture(scope="module")
def harness(tmp_path_factory):
    try:
        ck.gcc()
    except ck.ToolMissing as exc:
        pytest.skip(str(exc))
    info = ck.build(tmp_path_factory.mktemp("cbench"), ck.STRICT)
    return info["binary"]


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


@pytest.mark.parametrize("offset", [False, True], ids=["t0=0", "t0>0"])
@pytest.mark.parametrize("kernel", ck.NORMAL_KERNELS)
def test_kernel_matches_python(harness, kernel, offset):
    if kernel not in ck.kernel_names(harness):
        pytest.skip(f"kernel {kernel} not built on this machine (no SSE)")
    method = ck.PY_METHOD[kernel]
    rng = np.random.default_rng(0)
    nl, nr, m, t0, dt, count, psi = _spans(rng, offset=offset)
    out = ck.evaluate(harness, kernel, nl, nr, t0, dt, count).astype(np.float64)
    py = span_normals(method, nl, nr, m, t0=t0, dt=dt, count=count, dtype=np.float32)
    assert out.shape == py.normals.shape
    extra = 0.0
    if kernel == "sse_rsqrt":
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
