"""The exponent-indexed 1/sqrt evaluator (issue 28, :mod:`chebnorm.hw.exponent`):
the certified mantissa bound checked at every code in exact rational
arithmetic, independently of the model's own normalization; Verilog (Icarus)
and VHDL (GHDL) bit-identical to the model over every code; bad input refused."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from chebnorm.cli import main
from chebnorm.hw.exponent import design_exponent, exponent_fields, simulate_exponent
from conftest import requires_tool

needs_iverilog = requires_tool("iverilog")
needs_ghdl = requires_tool("ghdl")
needs_yosys = requires_tool("yosys")

W = 10


@pytest.fixture(scope="module")
def designs():
    return {deg: design_exponent("1/sqrt(x)", (f"2^-{W}", "1"), W, W, degree=deg)
            for deg in (1, 2)}


def test_fields_match_integer_normalization():
    """lz, h and the inner code against Python's int.bit_length, every 12-bit code."""
    w = 12
    f = exponent_fields(np.arange(2 ** w), w)
    for k in range(2 ** w):
        lz = w - k.bit_length()
        mant = (k << lz) % 2 ** w
        assert int(f["lz"][k]) == lz and int(f["h"][k]) == (lz + 2) // 2
        assert int(f["inner"][k]) == ((1 - lz % 2) << (w - 1)) | (mant % 2 ** (w - 1))
        if k:   # x = v * 4^-h with v in [1, 4): the binade pair
            v = Fraction(k, 2 ** w) * 4 ** int(f["h"][k])
            assert 1 <= v < 4


@pytest.mark.parametrize("degree", [1, 2])
def test_bound_holds_at_every_code_exactly(designs, degree):
    """|y - 1/sqrt(x)| <= 2^h E at every code of [2^-W, 1), decided in exact rationals
    (squares: no square root taken), x = k / 2^W straight from the code; and the
    bound is not loose by a whole mantissa ulp (the output truncation's width)."""
    d = designs[degree]
    E = d.budget()["mantissa_exact"]
    assert E < Fraction(1, 2 ** d.frac_bits)        # faithful
    lo, hi = d.valid_codes
    y = d.evaluate(np.arange(lo, hi + 1))
    M, off, F = d.mant_bits, d.core.y_format.offset_code, d.frac_bits
    worst = Fraction(0)
    for k, yc in zip(range(lo, hi + 1), y):
        h, m = int(yc) >> M, int(yc) & (2 ** M - 1)
        a = Fraction(off + m, 2 ** F) * 2 ** h       # the output's value
        g2 = Fraction(2 ** W, k)                     # (1/sqrt(x))^2
        tol = E * 2 ** h
        assert (a + tol) ** 2 >= g2, k               # 1/sqrt(x) <= a + tol
        assert a - tol <= 0 or (a - tol) ** 2 <= g2, k   # 1/sqrt(x) >= a - tol
        # the error to 1e-30 (for the looseness check): |a^2 - g2| / (a + g) with g ~ sqrt
        g = Fraction(int(np.sqrt(float(g2)) * 2 ** 40), 2 ** 40)
        for _ in range(3):   # Newton on g^2 = g2, exact rationals: |g - 1/sqrt(x)| < 1e-30
            g = (g + g2 / g) / 2
            g = Fraction(round(g * 2 ** 120), 2 ** 120)
        e = abs(a - g) / 2 ** h
        worst = max(worst, e)
    assert worst <= E
    assert E - worst < Fraction(1, 2 ** F)
    m = d.measure()   # the model's own 40-digit check agrees
    assert abs(m["max_error"] - float(worst)) < 1e-12
    assert m["max_rel_error"] < d.budget()["relative"]


@requires_tool("iverilog", "ghdl")  # one marker: the hook reads the closest only
@pytest.mark.parametrize("degree,pipeline", [(2, None), (1, "full")])
def test_hdl_bit_identical_every_code(designs, tmp_path, degree, pipeline):
    d = designs[degree] if pipeline is None else design_exponent(
        "1/sqrt(x)", (f"2^-{W}", "1"), W, W, degree=degree, pipeline=pipeline)
    assert d.latency == (0 if pipeline is None else degree + 1)
    for lang in ("verilog", "vhdl"):
        r = simulate_exponent(d, tmp_path / lang, lang)
        assert r.passed and r.vectors == 2 ** W and r.mismatches == 0, r.line
    # the VHDL bench wrote the outputs it saw: the model's, code by code
    seen = (tmp_path / "vhdl" / f"{d.module_name}_vhdl_y.hex").read_text().split()
    assert [int(v, 16) for v in seen] == [int(v) for v in d.evaluate()]


@pytest.mark.parametrize("kwargs,word", [
    (dict(interval=("0", "1")), "interval"),
    (dict(interval=("2^-4", "2")), "interval"),
    (dict(interval=("3/16", "1")), "interval"),
    (dict(interval=("2^-11", "1")), "interval"),
    (dict(in_bits=21), "in_bits"),
    (dict(in_bits=3), "in_bits"),
    (dict(out_bits=1), "out_bits"),
    (dict(degree=4), "degree"),
    (dict(expr="sqrt(x)"), "expr"),
    (dict(segments=2 ** 9), "segments"),
])
def test_bad_input_names_the_argument(kwargs, word):
    args = dict(expr="1/sqrt(x)", interval=(f"2^-{W}", "1"), in_bits=W, out_bits=W)
    args.update(kwargs)
    with pytest.raises(ValueError, match=word) as exc:
        design_exponent(args.pop("expr"), args.pop("interval"), args.pop("in_bits"),
                        args.pop("out_bits"), **args)
    assert "accepted" in str(exc.value)


@pytest.mark.parametrize("argv,word", [
    (["--interval", "0", "1", "--in-bits", "10"], "interval"),
    (["--interval", "2^-8", "1", "--in-bits", "24"], "--in-bits"),   # the CLI names its flag
    (["--interval", "2^-8", "1", "--in-bits", "10", "--correctly-rounded"], "correctly-rounded"),
])
def test_cli_bad_input_one_line_exit_2(tmp_path, capsys, argv, word):
    acc = [] if "--correctly-rounded" in argv else ["--faithful"]
    out = tmp_path / "D"
    assert main(["design", "1/sqrt(x)", "--index", "exponent", "--out-bits", "10", *argv, *acc,
                 "--no-synth", "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and word in err[0] and "accepted" in err[0]
    assert not out.exists()


@needs_yosys
def test_cli_design_writes_winner(tmp_path, capsys):
    out = tmp_path / "D"
    assert main(["design", "1/sqrt(x)", "--index", "exponent", "--interval", "2^-8", "1",
                 "--in-bits", "8", "--out-bits", "8", "--faithful", "--degrees", "1", "2",
                 "--name", "rs", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "winner: exponent: degree" in text
    names = sorted(p.name for p in out.iterdir())
    assert names == ["chebnorm_rs.hex", "chebnorm_rs.v", "chebnorm_rs.vhd",
                     "design_rs_architectures.csv", "tb_chebnorm_rs.v", "tb_chebnorm_rs.vhd"]
    rows = (out / "design_rs_architectures.csv").read_text().splitlines()
    assert len(rows) == 3 and sum(r.endswith(",1") for r in rows[1:]) == 1


def test_hand_built_design_is_checked(designs):
    from dataclasses import replace

    d = designs[1]
    with pytest.raises(ValueError, match="shift_bits"):
        replace(d, shift_bits=d.shift_bits + 1)
    with pytest.raises(ValueError, match="core"):
        replace(d, in_bits=W + 1, interval=(f"2^-{W}", "1"))
    with pytest.raises(ValueError, match="interval"):
        replace(d, interval=("0", "1"))
