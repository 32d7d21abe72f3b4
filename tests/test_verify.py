"""``chebnorm verify`` / :func:`chebnorm.export.verify.verify`: the exhaustive
check of an exported evaluator against its stated bound.

Independent computations: every float32 of the interval enumerated here by
its bit pattern, Horner's rule emulated in numpy float32 / float64 / int64,
and ``f`` in mpmath at 40 digits."""

from __future__ import annotations

import re
from dataclasses import astuple

import mpmath
import numpy as np
import pytest

from chebnorm.approx import fit
from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.export import export_text
from chebnorm.export.verify import c_evaluate, stated_bounds, verify
from conftest import requires_tool, run_cli

needs_gcc = requires_tool("gcc")


@pytest.fixture(scope="module")
def table():
    # 8193 float32 in [1, 1 + 2^-10]; a fixed-point part (16385 codes)
    return fit("1/sqrt(x)", ("1", "1 + 2**-10"), 2, name="rsv", coef_frac_bits=24)


@pytest.fixture(scope="module")
def table_file(table, tmp_path_factory):
    path = tmp_path_factory.mktemp("verify") / "rsv.json"
    path.write_text(table.to_json(), encoding="utf-8")
    return path


def _every_float32(lo: float, hi: float) -> np.ndarray:
    """Every float32 in [lo, hi] (positive lo), by bit pattern."""
    a = np.float32(lo)
    if float(a) < lo:
        a = np.nextafter(a, np.float32(np.inf))
    b = np.float32(hi)
    if float(b) > hi:
        b = np.nextafter(b, np.float32(-np.inf))
    bits = np.arange(int(a.view(np.uint32)), int(b.view(np.uint32)) + 1, dtype=np.uint32)
    return bits.view(np.float32)


def _true_errors(xs, ys, f=lambda x: 1 / mpmath.sqrt(x)) -> np.ndarray:
    with mpmath.workdps(40):
        return np.array([float(abs(mpmath.mpf(float(y)) - f(mpmath.mpf(float(x)))))
                         for x, y in zip(xs, ys)])


def _interval(header: str, table) -> tuple[float, float]:
    b = stated_bounds(header)
    m = f"CHEBNORM_{table.name.upper()}"
    return b[m + "_LO"], b[m + "_HI"]


@needs_gcc
def test_float_unfused_is_numpy_float32_horner_bit_for_bit(table):
    header = export_text(table, "c")
    xs = _every_float32(*_interval(header, table))
    got = c_evaluate(header, "chebnorm_rsv_f", xs)
    cs = [np.float32(c) for c in table.coefficients]
    acc = np.full(xs.size, cs[-1], dtype=np.float32)
    for c in reversed(cs[:-1]):
        acc = (acc * xs).astype(np.float32) + c  # two roundings per step
    assert got.dtype == np.float32 and xs.size == 8193
    assert np.array_equal(got.view(np.uint32), acc.view(np.uint32))


@needs_gcc
@pytest.mark.parametrize("variant", ["float", "float-fused", "double"])
def test_exhaustive_maximum_agrees_with_mpmath(table, variant):
    header = export_text(table, "c")
    xs = _every_float32(*_interval(header, table))
    name = "chebnorm_rsv_f" if variant.startswith("float") else "chebnorm_rsv"
    ys = c_evaluate(header, name, xs if variant.startswith("float") else xs.astype(np.float64),
                    fused=variant.endswith("fused"))
    err = _true_errors(xs, ys)
    (r,) = verify(table, "c", variant=variant).variants
    assert r.count == xs.size and r.skipped is None
    # both exact to far below the float64 spacing of the maximum
    assert r.measured_max == pytest.approx(err.max(), rel=1e-12)
    assert r.argmax == float(xs[int(np.argmax(err))])
    assert r.measured_max <= r.upper <= r.measured_max + 10 * r.ref_error
    assert 0 < r.ref_error < 1e-15 and r.passed


@needs_gcc
def test_fixed_point_codes_against_integer_emulation(table):
    fp = table.fixed_point
    F = fp.frac_bits
    header = export_text(table, "c")
    lo, hi = _interval(header, table)
    q = np.arange(int(np.ceil(lo * 2 ** F)), int(np.floor(hi * 2 ** F)) + 1, dtype=np.int64)
    acc = np.full(q.size, fp.integers[-1], dtype=np.int64)
    for c in reversed(fp.integers[:-1]):
        acc = ((acc * q + (1 << (F - 1))) >> F) + c
    assert np.array_equal(c_evaluate(header, "chebnorm_rsv_q_eval", q), acc)
    with mpmath.workdps(40):
        err = [abs(mpmath.mpf(int(a)) / 2 ** F - 1 / mpmath.sqrt(mpmath.mpf(int(k)) / 2 ** F))
               for k, a in zip(q, acc)]
    (r,) = verify(table, "c", variant="fixed").variants
    assert r.count == q.size
    assert r.measured_max == pytest.approx(float(max(err)), rel=1e-12)


@needs_gcc
def test_reports_every_c_variant_with_its_stated_bound(table):
    header = export_text(table, "c")
    bounds = stated_bounds(header)
    r = verify(table, "c")
    assert [v.variant for v in r.variants] == ["double", "double-fused", "float", "float-fused",
                                              "fixed"]
    for v in r.variants:
        assert v.stated_bound == bounds[v.bound_name] and v.passed
        assert v.ratio == v.measured_max / v.stated_bound
    assert "-ffp-contract=fast" in r.variants[1].notes[0]
    assert "float32 inputs only" in " ".join(r.variants[0].notes)
    assert r.passed and "stated" in str(r) and "<table>" in r._repr_html_()
    assert r.markdown().count("\n") == 2 + 5


@needs_gcc
def test_tampered_bound_is_reported_as_exceeded(table, table_file, tmp_path, capsys):
    header = export_text(table, "c")
    macro = "CHEBNORM_RSV_EVAL_ERROR_BOUND"
    stated = stated_bounds(header)[macro]
    assert table.max_abs_error > stated / 2  # the approximation error alone exceeds half
    tampered = re.sub(rf"(#define {macro}) \S+", rf"\1 {(stated / 2).hex()}", header)
    path = tmp_path / "tampered.h"
    path.write_text(tampered, encoding="utf-8")
    status, out, err = astuple(run_cli("verify", table_file, "--format", "c", "--source", path,
                                         "--variant", "double", "--variant", "float"))
    assert status == 1
    assert err.count("\n") == 1 and "exceeded" in err and macro in err
    assert "EXCEEDS" in out and "float" in out
    status, _, _ = astuple(run_cli("verify", table_file, "--format", "c", "--source", path,
                                     "--variant", "float"))
    assert status == 0  # the float bound was not touched


@needs_gcc
def test_changed_coefficient_is_reported_as_exceeded(table):
    header = export_text(table, "c")
    body = header[header.index("chebnorm_rsv_f(float x)"):]
    last = re.findall(r"acc = acc \* x \+ (\S+f) ", body)[-1]  # the constant term
    changed = float.fromhex(last[:-1]) + 1e-4
    tampered = header.replace(body, body.replace(last, f"{changed.hex()}f", 1))
    (r,) = verify(table, "c", variant="float", source=tampered).variants
    assert r.passed is False and r.measured_max > 0.9e-4 > r.stated_bound


def test_glsl_on_llvmpipe(table):
    from chebnorm.export import gpu

    try:
        gpu.gl_context()
    except gpu.ToolMissing as exc:
        pytest.skip(f"no OpenGL 4.3 compute here: {exc}")
    (r,) = verify(table, "glsl").variants
    xs = _every_float32(*gpu.interval32(table))
    ys = gpu.glsl_evaluate(table, xs)  # the driver, one dispatch, independent of verify's
    err = _true_errors(xs, ys)
    assert r.count == xs.size and r.variant == "llvmpipe"
    assert r.measured_max == pytest.approx(err.max(), rel=1e-12)
    literal = stated_bounds(export_text(table, "glsl"))["CHEBNORM_RSV_EVAL_ERROR_BOUND"]
    assert r.stated_bound == float(np.float32(literal)) and r.passed  # the shader's float32


def test_shader_inputs_are_the_c_float_inputs():
    # sqrt(2) rounds to a float32 whose shortest decimal lies above it: read as
    # a double and rounded inward, the interval would lose its first float32
    from chebnorm.export import gpu

    t = fit("1/sqrt(x)", ("sqrt(2)", "sqrt(2) + 2**-12"), 1, name="s2")
    lo, hi = gpu.interval32(t)
    xs = _every_float32(lo, hi)
    for fmt in ("glsl", "wgsl"):
        (r,) = verify(t, fmt).variants
        if r.skipped is not None:
            continue
        assert r.count == xs.size, fmt
    (r,) = verify(t, "c", variant="float").variants
    assert r.count == xs.size


def test_wgsl_on_lavapipe(table):
    from chebnorm.export import gpu

    (r,) = verify(table, "wgsl").variants
    if r.skipped is not None:
        pytest.skip(f"no WebGPU here: {r.skipped}")
    xs = _every_float32(*gpu.interval32(table))
    err = _true_errors(xs, gpu.wgsl_evaluate(table, xs))  # one dispatch, independent
    assert r.count == xs.size and r.variant == "lavapipe"
    assert r.measured_max == pytest.approx(err.max(), rel=1e-12) and r.passed


def test_glsl_without_a_driver_is_skipped_with_the_reason(table, monkeypatch):
    from chebnorm.export import gpu

    def missing():
        raise gpu.ToolMissing("moderngl is not installed; accepted: pip install 'chebnorm[gpu]'")
    monkeypatch.setattr(gpu, "gl_context", missing)
    r = verify(table, "glsl")
    (v,) = r.variants
    assert v.skipped.startswith("moderngl is not installed") and v.passed is None
    assert r.passed and "skipped: moderngl" in str(r)


def test_hlsl_has_no_runtime_and_says_so(table):
    (v,) = verify(table, "hlsl").variants
    assert v.skipped is not None and "no HLSL runtime" in v.skipped and v.measured_max is None


@needs_gcc
def test_piecewise_uniform_codes(tmp_path):
    pw = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=4, name="pwv")
    header = export_text(pw, "c", in_bits=12)
    k = np.arange(2 ** 12, dtype=np.uint32)
    got = c_evaluate(header, "chebnorm_pwv", k)
    L = 12 - pw.index_bits
    t = (k & ((1 << L) - 1)).astype(np.float64) * 2.0 ** -L
    coef = np.array([pw.coefficients(s) for s in range(pw.segment_count)])[k >> L]
    acc = coef[:, -1].copy()
    for j in range(pw.degree - 1, -1, -1):
        acc = acc * t + coef[:, j]
    assert np.array_equal(got, acc)
    with mpmath.workdps(40):
        err = [abs(mpmath.mpf(float(y)) - 1 / mpmath.sqrt(1 + mpmath.mpf(3) * int(i) / 2 ** 12))
               for i, y in zip(k, got)]
    (r,) = verify(pw, "c", variant="double", source=header).variants
    assert r.count == 2 ** 12 and r.measured_max == pytest.approx(float(max(err)), rel=1e-12)
    assert r.passed


@needs_gcc
def test_quantized_float_evaluator():
    q = fit("1/sqrt(x)", ("1", "1 + 2**-10"), 2, name="qv", coef_format="binary16")
    header = export_text(q, "c")
    xs = _every_float32(*_interval(header, q))
    cs = [np.float32(c) for c in q.quantized.coefficients]
    acc = np.full(xs.size, cs[-1], dtype=np.float32)
    for c in reversed(cs[:-1]):
        acc = (acc * xs).astype(np.float32) + c
    got = c_evaluate(header, "chebnorm_qv_quant_f", xs)
    assert np.array_equal(got.view(np.uint32), acc.view(np.uint32))
    (r,) = verify(q, "c", variant="quant-f").variants
    assert r.bound_name == "CHEBNORM_QV_QUANT_F_EVAL_ERROR_BOUND" and r.count == xs.size
    assert r.measured_max == pytest.approx(_true_errors(xs, acc).max(), rel=1e-12)


@needs_gcc
def test_spread_inputs(table):
    (r,) = verify(table, "c", variant="float", inputs=1000).variants
    assert r.count == 1000 and "evenly spread" in r.inputs


@pytest.mark.parametrize("args,needle", [
    (["--format", "pdf"], "unknown format 'pdf'"),
    (["--variant", "triple"], "variant = 'triple'"),
    (["--format", "glsl", "--variant", "float"], "accepted: llvmpipe"),
    (["--inputs", "many"], "--inputs 'many'"),
    (["--inputs", "1"], "accepted: 'all'"),
])
def test_bad_input_exits_2_with_one_line(table_file, capsys, args, needle):
    status, out, err = astuple(run_cli("verify", table_file, *args))
    assert status == 2 and out == "" and err.count("\n") == 1 and needle in err


def test_bad_files_exit_2(table_file, tmp_path, capsys):
    status, _, err = astuple(run_cli("verify", tmp_path / "missing.json"))
    assert status == 2 and err.count("\n") == 1 and "missing.json" in err
    other = tmp_path / "other.h"
    other.write_text("/* not a chebnorm header */\n", encoding="utf-8")
    status, _, err = astuple(run_cli("verify", table_file, "--source", other))
    assert status == 2 and err.count("\n") == 1 and "CHEBNORM_RSV_LO" in err


@needs_gcc
def test_source_that_does_not_compile_exits_2(table, table_file, tmp_path, capsys):
    broken = tmp_path / "broken.h"
    broken.write_text(export_text(table, "c").replace("return acc;", "return acc +;", 1),
                      encoding="utf-8")
    status, out, err = astuple(run_cli("verify", table_file, "--source", broken))
    assert status == 2 and out == "" and err.count("\n") == 1
    assert "does not compile" in err


def test_python_errors_name_the_argument(table):
    with pytest.raises(ValueError, match="^inputs = 0 "):
        verify(table, "c", inputs=0)
    with pytest.raises(ValueError, match="^fmt = 'verilog' "):
        verify(table, "verilog")
    with pytest.raises(ValueError, match="^variant = 'x' "):
        verify(table, "c", variant="x")
    with pytest.raises(ValueError, match="^source of type bytes"):
        verify(table, "c", source=b"")
    with pytest.raises(ValueError, match="^table of type str"):
        verify("t.json", "c")
