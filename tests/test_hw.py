"""Tests of chebnorm.hw: fixed point, Horner datapath, budget, Verilog, sweep, CLI."""

from __future__ import annotations

import csv
import io
from dataclasses import astuple
from fractions import Fraction

import numpy as np
import pytest

from chebnorm.approx import fit_target, quantize
from chebnorm.hw import (design_horner, error_budget, gappa_bound, measure, shift_round,
                         simulate, synthesize)
from chebnorm.hw.cost import Cost
from chebnorm.hw.datapaths import (bump_pipeline, classic_normalize, classic_unit,
                                   dichotomy_midpoint, dichotomy_unit, eta_unit,
                                   forward_difference, phong_pipeline,
                                   quadratic_midpoint_unit, forward_difference_stepper)
from chebnorm.hw.fixed import fit_bits, rounding_error_bound, signed_bits
from chebnorm.hw.report import analyze, verilog_outputs, write_outputs
from conftest import requires_tool, run_cli

no_iverilog = requires_tool("iverilog")
no_yosys = requires_tool("yosys")
no_gappa = requires_tool("gappa")


@pytest.fixture(scope="module")
def d2():
    return fit_target("dichotomy", 2)


@pytest.fixture(scope="module")
def acceptance(d2):
    return analyze(d2, 16, 16, coef_frac_bits=20, synth=False, gappa=False)


class TestFixed:
    def test_shift_round_matches_fractions(self):
        rng = np.random.default_rng(0)
        v = rng.integers(-2 ** 40, 2 ** 40, 5000)
        for s in (1, 3, 7):
            for mode in ("trunc", "rne"):
                got = shift_round(v, s, mode)
                for a, b in zip(v[:300].tolist(), got[:300].tolist()):
                    x = Fraction(a, 2 ** s)
                    want = (x.numerator // x.denominator) if mode == "trunc" else round(x)
                    assert b == want  # Python's round() is round-half-even
                    assert b == shift_round(a, s, mode)  # scalar path agrees

    def test_rounding_error_bounds_by_enumeration(self):
        v = np.arange(-4096, 4096)
        for s in (1, 2, 5):
            for mode in ("trunc", "rne"):
                err = np.abs((shift_round(v, s, mode) << s) - v).max() / 2 ** s
                assert err <= rounding_error_bound(0, mode, s)
                assert err == float(rounding_error_bound(0, mode, s))  # tight

    def test_saturate_and_wrap(self):
        out, over = fit_bits(np.array([-129, -128, 127, 128]), 8, signed=True, overflow="wrap")
        assert out.tolist() == [127, -128, 127, -128] and over.tolist() == [1, 0, 0, 1]
        out, over = fit_bits(np.array([-1, 256]), 8, signed=False, overflow="saturate")
        assert out.tolist() == [0, 255] and over.all()
        with pytest.raises(ValueError, match="overflow mode"):
            fit_bits(np.array([1]), 8, signed=False, overflow="clamp")

    def test_signed_bits(self):
        for lo, hi in [(-1, 0), (-8, 7), (-9, 7), (0, 255), (3, 3)]:
            n = signed_bits(lo, hi)
            assert -(2 ** (n - 1)) <= lo and hi < 2 ** (n - 1)
            assert not (-(2 ** (n - 2)) <= lo and hi < 2 ** (n - 2)) or n == 1


class TestHorner:
    def test_model_matches_exact_rational_horner(self, acceptance):
        """Re-derive every output code with Fractions, independently of the int64 kernel."""
        d = acceptance.design
        rng = np.random.default_rng(1)
        codes = np.concatenate([[0, 1, 2 ** 16 - 1, *d.valid_codes], rng.integers(0, 2 ** 16, 300)])
        y = d.evaluate(codes)
        ulp_a = Fraction(1, 2 ** d.acc_frac_bits)
        for k, yk in zip(codes.tolist(), y.tolist()):
            x = d.x_format.value(k)
            acc = Fraction(d.integers[2], 2 ** d.coef_frac_bits)
            acc = round((acc * x + Fraction(d.integers[1], 2 ** d.coef_frac_bits)) / ulp_a) * ulp_a
            top = acc * x + Fraction(d.integers[0], 2 ** d.coef_frac_bits)
            code = round(top * 2 ** d.y_format.frac_bits) - d.y_format.offset_code
            assert yk == min(max(code, 0), 2 ** 16 - 1)

    def test_input_format_covers_interval(self, acceptance):
        d = acceptance.design
        lo, hi = d.valid_codes
        assert d.x_format.value(lo) >= Fraction(1414213562, 10 ** 9)  # > sqrt(2) - 1e-9 ...
        assert float(d.x_format.value(lo - 1)) < 2 ** 0.5 < float(d.x_format.value(lo))
        assert d.x_format.value(hi) == 2
        assert d.x_format.frac_bits == 16  # 2^16 codes at 2^-16 span 1 > 2 - sqrt(2); 2^-17 would not

    def test_requires_fixed_point(self, d2):
        with pytest.raises(ValueError, match="no fixed-point part"):
            design_horner(d2, 16, 16)
        design_horner(quantize(d2, 18), 12, 12)  # the table's own fixed-point part

    @pytest.mark.parametrize("kw, msg", [
        (dict(in_bits=0), "^in_bits = 0 is out of range"),
        (dict(in_bits=-3), "^in_bits = -3 is out of range"),
        (dict(in_bits=21), "accepted: 1 <= in_bits <= 20"),
        (dict(out_bits=0), "^out_bits = 0"),
        (dict(x_frac_bits=18), "does not fit the input format"),
        (dict(out_bits=4, y_frac_bits=20), "^out_bits 4 with y_frac_bits 20 cannot hold the outputs"),
        (dict(acc_bits=60), "accepted: acc_bits <= 36"),
        (dict(rounding="up"), "rounding 'up' is unknown"),
        (dict(coef_bits=32), r"accepted: 1 <= coef_bits <= 31 \(quantized coefficients are "
                             r"signed 32-bit"),
        (dict(coef_bits=0), "^coef_bits = 0 is out of range; accepted: 1 <= coef_bits <= 31"),
    ])
    def test_raises(self, d2, kw, msg):
        args = dict(in_bits=16, out_bits=16, coef_bits=20) | kw
        with pytest.raises(ValueError, match=msg):
            design_horner(d2, args.pop("in_bits"), args.pop("out_bits"), **args)


def test_max_coef_bits_is_quantize_limit(d2):
    """The accepted range of coef-bits is exactly what quantize (int32) takes."""
    from chebnorm.hw.horner import max_coef_bits

    hi = max_coef_bits(d2)
    assert hi == 31
    quantize(d2, hi, reoptimize=False)
    with pytest.raises(ValueError, match="overflows int32"):
        quantize(d2, hi + 1, reoptimize=False)


class TestBudget:
    def test_acceptance_budget(self, acceptance):
        b, m = acceptance.budget, acceptance.measurement
        assert m.codes == acceptance.design.valid_codes[1] - acceptance.design.valid_codes[0] + 1
        assert m.total <= b.total + 1e-15  # f in float64: ~1e-16 error
        assert b.total <= 2 * m.total
        assert all(acceptance.checks.values()), acceptance.checks

    def test_quantization_against_recertification(self, d2):
        for bits in (10, 14, 20):
            r = analyze(d2, 12, 12, coef_frac_bits=bits, synth=False, gappa=False)
            t, b = r.design.table, r.budget
            fp = t.fixed_point
            # triangle inequality in both directions, with rigorous bounds only
            assert fp.max_abs_error <= t.abs_error_bound + b.quantization
            assert t.max_abs_error <= fp.abs_error_bound + b.quantization
            # the certified sup |p_q - p| is attained (within the certifier's 2^-8) on the codes
            assert r.measurement.quantization <= b.quantization + 1e-15  # float64 p: ~1e-16
            assert b.quantization <= r.measurement.quantization * (1 + 2 ** -8) + b.y_lsb * 2 ** -10

    @pytest.mark.parametrize("rounding", ["rne", "trunc"])
    @pytest.mark.parametrize("degree", [1, 3, 4])
    def test_rounding_against_enumeration(self, degree, rounding):
        d = design_horner(fit_target("dichotomy", degree), 12, 12, coef_bits=18,
                          rounding=rounding)
        b, m = error_budget(d), measure(d)
        assert m.rounding <= b.rounding
        # the output rounding alone is nearly attained over thousands of codes
        assert m.rounding >= 0.5 * float(b.output_rounding)
        assert m.total <= b.total + 1e-15

    @no_gappa
    def test_gappa_agrees(self, d2):
        for degree in (2, 3):
            d = design_horner(fit_target("dichotomy", degree), 16, 16, coef_bits=20)
            g = gappa_bound(d)
            b, m = error_budget(d), measure(d)
            assert m.rounding <= g <= b.rounding * (1 + 1e-12)


class TestVerilog:
    @no_iverilog
    def test_acceptance_bit_for_bit(self, acceptance, tmp_path):
        write_outputs(tmp_path, verilog_outputs(acceptance, version="test"))
        res = simulate(tmp_path, acceptance.design)
        assert res.passed and res.vectors == 65536 and res.mismatches == 0

    @no_iverilog
    @pytest.mark.parametrize("degree, rounding", [(1, "trunc"), (3, "rne"), (4, "trunc")])
    def test_other_designs_bit_for_bit(self, degree, rounding, tmp_path):
        r = analyze(fit_target("midpoint", degree), 10, 10, coef_frac_bits=16, rounding=rounding,
                    synth=False, gappa=False)
        write_outputs(tmp_path, verilog_outputs(r))
        assert simulate(tmp_path, r.design).passed

    @no_iverilog
    def test_bench_detects_a_wrong_vector(self, acceptance, tmp_path):
        files = verilog_outputs(acceptance)
        name = acceptance.design.module_name
        lines = files[f"{name}.hex"].splitlines(keepends=True)
        lines[100] = "ffff\n" if lines[100] != "ffff\n" else "0000\n"
        files[f"{name}.hex"] = "".join(lines)
        write_outputs(tmp_path, files)
        res = simulate(tmp_path, acceptance.design)
        assert not res.passed and res.mismatches == 1

    def test_module_text(self, acceptance):
        text = verilog_outputs(acceptance)["chebnorm_dichotomy_d2.v"]
        assert "module chebnorm_dichotomy_d2 #(" in text
        assert "input  wire [IN_BITS-1:0]  x," in text and "output wire [OUT_BITS-1:0] y" in text
        assert "x_format: frac_bits 16" in text and "y_format: frac_bits 20" in text

    @no_yosys
    def test_yosys_cells(self, acceptance, tmp_path):
        f = tmp_path / "m.v"
        f.write_text(verilog_outputs(acceptance)["chebnorm_dichotomy_d2.v"])
        s = synthesize(f, "chebnorm_dichotomy_d2")
        assert s.cells > 100 and sum(s.by_type.values()) == s.cells


class TestDatapaths:
    def test_cost_composition(self):
        c = classic_unit(16).cost
        assert len(c.multipliers) == 3 and len(c.adders) == 2
        assert len(c.sqrts) == 1 and len(c.dividers) == 3  # seed 000's count
        assert (Cost(latency=2) + Cost(latency=3)).latency == 5

    def test_blocks_build(self, acceptance):
        d = acceptance.design
        for block in (dichotomy_unit(d, 16), quadratic_midpoint_unit(d, 16),
                      eta_unit(d, 16), forward_difference_stepper(16)):
            assert block.cost.area > 0 and block.lines()
        phong, bump = phong_pipeline(16), bump_pipeline(16)
        assert len(bump.cost.multipliers) == len(phong.cost.multipliers)
        assert bump.cost.mux_bits - phong.cost.mux_bits == 48  # one 3x16-bit multiplexer
        assert not forward_difference_stepper(16).cost.multipliers

    def test_classic_normalize_bit_accurate(self):
        rng = np.random.default_rng(2)
        f = 14
        v = rng.normal(size=(2000, 3))
        n = np.rint(v / np.linalg.norm(v, axis=1, keepdims=True) * 0.8 * 2 ** f).astype(np.int64)
        out = classic_normalize(n, f) / 2 ** f
        # floor sqrt (<= 1 ulp of s) and floor division: a few ulps of the unit vector
        assert np.max(np.abs(np.linalg.norm(out, axis=1) - 1)) < 8 * 2.0 ** -f

    def test_dichotomy_midpoint(self, acceptance):
        d = acceptance.design
        rng = np.random.default_rng(3)
        f = 14
        th = rng.uniform(0, np.pi / 4, 500)
        n1 = np.stack([np.ones_like(th), np.zeros_like(th), np.zeros_like(th)], -1)
        n2 = np.stack([np.cos(th), np.sin(th), np.zeros_like(th)], -1)
        z = 2 * np.cos(th)
        codes = np.clip(np.rint((z - float(d.x_format.offset)) * 2 ** d.x_format.frac_bits),
                        *d.valid_codes).astype(np.int64)
        q = lambda a: np.rint(a * 2 ** f).astype(np.int64)
        mid = dichotomy_midpoint(q(n1), q(n2), codes, d, f) / 2 ** f
        # length error: 2 * (budget + input quantization) + component rounding
        assert np.max(np.abs(np.linalg.norm(mid, axis=1) - 1)) < 1e-4

    def test_forward_difference_exact_start_and_drift(self):
        G, P, Q = np.array([0.1, -0.2, 0.05]), np.array([0.3, 0.1, -0.4]), np.array([0.5, 0.5, 0.7])
        m = 64
        fd = forward_difference(G, P, Q, m, 16)
        t = np.arange(m + 1)[:, None] / m
        direct = G * t ** 2 + P * t + Q
        # each of d1, d2 and the start rounded to 2^-25; d2's error grows ~ m^2/2 of it
        assert np.max(np.abs(fd - direct)) < (1 + m + m * m) * 2.0 ** -24


class TestSweep:
    def test_sweep_deterministic(self, tmp_path):
        from chebnorm.hw.sweep import sweep

        kw = dict(degrees=(1, 2), coef_bits=(10, 14), acc_bits=(14,), in_bits=10, out_bits=10,
                  progress=False)
        a, b = sweep(**kw), sweep(**kw)
        assert a.csv() == b.csv()
        rows = list(csv.DictReader(io.StringIO(a.csv())))
        assert len(rows) == 4
        assert any(r["pareto"] == "1" for r in rows)
        png = a.plot_png()
        assert png[:8] == b"\x89PNG\r\n\x1a\n"
        best = a.cheapest
        assert best is None or best.shading_levels <= 0.5


class TestCLI:
    @pytest.fixture
    def table_json(self, d2, tmp_path):
        p = tmp_path / "t.json"
        d2.save(p)
        return p

    def test_report_json(self, table_json, capsys):
        import json

        code, out, _ = astuple(run_cli(["hw", "report", str(table_json), "--in-bits", "12",
                                        "--out-bits", "12", "--coef-frac-bits", "16", "--json",
                                        "--no-synth", "--no-gappa"]))
        assert code == 0
        d = json.loads(out)
        assert set(d["x_format"]) >= {"frac_bits", "offset"}
        assert d["total_error_bound"] >= d["measured"]["total"]

    @pytest.mark.parametrize("extra, msg", [
        (["--in-bits", "0", "--out-bits", "16", "--coef-frac-bits", "20"], "--in-bits = 0"),
        (["--in-bits", "16", "--out-bits", "16"], "no fixed-point part"),
        (["--in-bits", "16", "--out-bits", "16", "--coef-frac-bits", "20", "--x-frac-bits", "18"],
         "does not fit the input format"),
        (["--in-bits", "16", "--out-bits", "-2", "--coef-frac-bits", "20"], "--out-bits = -2"),
        (["--in-bits", "16", "--out-bits", "16", "--coef-frac-bits", "40"],
         "accepted: 1 <= --coef-frac-bits <= 31"),
    ])
    def test_errors_leave_nothing(self, table_json, tmp_path, capsys, extra, msg):
        out = tmp_path / "out"
        out.mkdir()
        code, _, err = astuple(run_cli(["hw", "verilog", str(table_json), *extra, "-o", str(out)]))
        assert code == 2 and msg in err and err.count("\n") == 1
        assert list(out.iterdir()) == []

    def test_verilog_writes(self, table_json, tmp_path, capsys):
        code, out, _ = astuple(run_cli(["hw", "verilog", str(table_json), "--in-bits", "10",
                                        "--out-bits", "10", "--coef-frac-bits", "16",
                                        "-o", str(tmp_path)]))
        assert code == 0
        names = sorted(p.name for p in tmp_path.iterdir())
        assert "chebnorm_dichotomy_d2.v" in names and "tb_chebnorm_dichotomy_d2.v" in names
        assert not [n for n in names if n.endswith(".tmp")]
