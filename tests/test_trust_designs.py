"""Hardware design objects re-prove themselves (issue 43, hardware part).

A design changed after it was built (``dataclasses.replace``,
``object.__setattr__``) is refused, or -- if it is still a valid design --
prints a bound its own outputs meet; banners state the input mapping the
circuit implements (checked by simulating the module from the banner's own
formula); an output needing negative fractional bits is sized; ``--frequency``
is not silently ignored with ``--index exponent``.

The six design kinds fuzzed: HornerDesign, PiecewiseDesign (one width),
PiecewiseDesign (sized, pipelined), PlainTableDesign, MultipartiteDesign,
ExponentDesign.
"""

from __future__ import annotations

import copy
import dataclasses
import random
import re
import subprocess
from fractions import Fraction

import mpmath
import numpy as np
import pytest

from chebnorm.approx import fit_target
from chebnorm.approx.expr import parse_function, parse_number
from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.hw import trust
from chebnorm.hw.budget import error_budget
from chebnorm.hw.exhaustive import reference, round_to_nearest
from chebnorm.hw.exponent import design_exponent
from chebnorm.hw.hdl import module_text
from chebnorm.hw.horner import design_horner
from chebnorm.hw.multipartite import design_multipartite
from chebnorm.hw.piecewise import design_piecewise, simulate_piecewise
from chebnorm.hw.plain_table import design_plain_table
from conftest import run_cli

RSQRT = "1/sqrt(1+3*x)"


# -- the designs ------------------------------------------------------------------------

@pytest.fixture(scope="module")
def designs():
    t = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=4, coef_frac_bits=16, name="rs")
    return {
        "horner": design_horner(fit_target("dichotomy", 2), 8, 8, coef_bits=12),
        "piecewise": design_piecewise(t, 8, 8),
        "sized": design_piecewise(t, 8, 8, widths="auto", pipeline=(0,)),
        "plain": design_plain_table(RSQRT, ("0", "1"), 8, 8),
        "multipartite": design_multipartite(RSQRT, ("0", "1"), 8, 8),
        "exponent": design_exponent("1/sqrt(x)", ("2^-8", "1"), 8, 8, degree=1),
    }


def _text(kind, d) -> str:
    """What the HDL printers write for ``d`` (the banner states its bound)."""
    if kind == "horner":
        return module_text(d, budget=error_budget(d))
    if kind in ("piecewise", "sized"):
        return module_text(d)
    return d.verilog()


_BOUND = re.compile(r"<= ([0-9.]+e[+-][0-9]+)")


def _printed_bound(text: str) -> float:
    """The first upper bound the banner states (``<= X``)."""
    banner = "\n".join(line for line in text.splitlines() if line.startswith("//"))
    return float(_BOUND.search(banner).group(1))


def _printed_upper(text: str) -> float:
    """The largest value the banner's first stated bound can stand for: printed
    with 7 significant digits, it is within half a unit of its last digit of
    the bound (a printer rounding upward makes the text itself an upper bound)."""
    banner = "\n".join(line for line in text.splitlines() if line.startswith("//"))
    digits = _BOUND.search(banner).group(1)
    mantissa, exponent = digits.split("e")
    unit = 10.0 ** (int(exponent) - (len(mantissa.split(".")[1]) if "." in mantissa else 0))
    return float(digits) + unit / 2


def _bound(kind, d) -> float:
    """The bound the banner prints, as the design states it."""
    if kind == "horner":
        return error_budget(d).total
    if kind in ("piecewise", "sized"):
        return d.budget()["total"]
    if kind == "exponent":
        return d.budget()["mantissa"]
    return d.certificate.upper


def _f(expression, variable):
    return parse_function(expression, variable).mpmath


def _exact(text) -> Fraction:
    v = parse_number(str(text).replace("^", "**"))
    return Fraction(int(v.p), int(v.q))


def _measured(kind, d) -> float:
    """max |y - f(x)| of the design's own outputs, f at 40 digits, x exact."""
    if kind == "exponent":
        return d.measure()["max_error"]
    y = d.evaluate()
    if kind == "horner":
        lo, hi = d.valid_codes
        codes = range(lo, hi + 1)
        xf = d.x_format
        xs = [Fraction(xf.offset_code + k, 1) * Fraction(2) ** -xf.frac_bits for k in codes]
        f = _f(d.table.expression, d.table.variable)
    elif kind in ("piecewise", "sized"):
        codes = range(2 ** d.in_bits)
        xs = d.x_values(codes)
        f = _f(d.table.expression, d.table.variable)
    else:
        codes = range(2 ** d.in_bits)
        a, b = (_exact(v) for v in d.interval)
        xs = [a + (b - a) * Fraction(k, 2 ** d.in_bits) for k in codes]
        f = _f(d.expression, d.variable)
    yf = d.y_format
    worst = mpmath.mpf(0)
    with mpmath.workdps(40):
        scale = mpmath.mpf(2) ** -yf.frac_bits
        for k, x in zip(codes, xs):
            v = (yf.offset_code + int(y[k])) * scale
            worst = max(worst, abs(v - f(mpmath.mpf(x.numerator) / x.denominator)))
    return float(worst)


def _check_claims(kind, d, text: str) -> None:
    """What an accepted design prints holds for its own outputs."""
    measured = _measured(kind, d)
    bound = _bound(kind, d)
    assert measured <= bound, (kind, measured, bound)
    # the banner states that bound: rounded at its 7th digit (to nearest, or upward)
    printed, upper = _printed_bound(text), _printed_upper(text)
    assert bound <= upper and printed - bound <= 2 * (upper - printed)
    if kind == "plain" and "(correctly rounded)" in text:
        ref = reference(d.expression, d.interval, d.in_bits, d.variable)
        n, proved = round_to_nearest(ref, d.y_format.frac_bits)
        assert proved.all()
        assert np.array_equal(np.asarray(d.values) + d.y_format.offset_code, n)
    if kind == "multipartite" and "(faithful)" in text:
        assert measured < 2.0 ** -d.y_format.frac_bits


# -- the issue's cases, as written --------------------------------------------------------

def test_sized_piecewise_bound_replaced_is_refused(designs):
    d = designs["sized"]
    with pytest.raises(ValueError, match="^bound: stated"):
        dataclasses.replace(d, bound=(0, 0, Fraction(1, 10 ** 30)))


def test_zeroed_coefficients_refused(designs):
    d = designs["sized"]
    with pytest.raises(ValueError, match="^coefficients: stated"):
        dataclasses.replace(d, coefficients=tuple((0,) * len(r) for r in d.coefficients))


def test_plain_table_zeroed_or_other_expression_refused(designs):
    d = designs["plain"]
    with pytest.raises(ValueError, match="^values: the entries of a plain table"):
        dataclasses.replace(d, values=(0,) * len(d.values))
    with pytest.raises(ValueError, match=r"^values: the entries of a plain table of exp\(x\)"):
        dataclasses.replace(d, expression="exp(x)")


def test_plain_table_changed_behind_its_back_refused_before_it_prints(designs):
    d = copy.copy(designs["plain"])
    object.__setattr__(d, "expression", "exp(x)")
    with pytest.raises(ValueError, match="^values: "):
        d.vhdl()
    with pytest.raises(ValueError, match="^values: "):
        d.verilog()


def test_multipartite_zeroed_tables_refused(designs):
    d = designs["multipartite"]
    with pytest.raises(ValueError, match="^certificate.upper: stated"):
        dataclasses.replace(d, tiv=(0,) * len(d.tiv))
    offsets = tuple(dataclasses.replace(t, values=(0,) * len(t.values)) for t in d.offsets)
    with pytest.raises(ValueError, match="^certificate.upper: stated"):
        dataclasses.replace(d, offsets=offsets)


def test_exponent_zeroed_core_refused(designs):
    d = designs["exponent"]
    core = copy.copy(d.core)
    object.__setattr__(core, "coefficients", tuple((0,) * len(r) for r in core.coefficients))
    with pytest.raises(ValueError, match="^coefficients: stated"):
        dataclasses.replace(d, core=core)
    e = copy.copy(d)
    object.__setattr__(e, "core", core)
    with pytest.raises(ValueError, match="^coefficients: stated"):
        e.verilog()


def test_design_piecewise_refuses_a_table_changed_behind_its_back():
    t = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=4, coef_frac_bits=16, name="rs")
    seg = t.segments[0]
    object.__setattr__(seg, "integers", tuple(0 for _ in seg.integers))
    with pytest.raises(ValueError, match=r"segments\[0\]"):
        design_piecewise(t, 8, 8)


def test_piecewise_changed_behind_its_back_refused_before_it_prints(designs):
    d = copy.copy(designs["sized"])
    object.__setattr__(d, "bound", (0, 0, Fraction(1, 10 ** 30)))
    with pytest.raises(ValueError, match="^bound: stated"):
        module_text(d)


def test_unchanged_design_proved_once(designs):
    """A design's proof is cached on its content: an unchanged copy is not proved
    again; a change of content is."""
    d = designs["plain"]
    calls = []
    trust.check(d, calls.append)
    assert calls == []          # proved (sealed by its builder)
    trust.check(dataclasses.replace(d), calls.append)
    assert calls == []          # the same content
    e = copy.copy(d)
    object.__setattr__(e, "name", "other")
    trust.check(e, calls.append)
    assert calls == [e]


def test_valid_change_accepted_and_true(designs):
    d = dataclasses.replace(designs["plain"], name="renamed")
    text = d.verilog()
    assert "chebnorm_renamed" in text
    _check_claims("plain", d, text)
    m = dataclasses.replace(designs["multipartite"], max_error=1.0, faithful=False)
    _check_claims("multipartite", m, m.verilog())


# -- negative fractional bits, --frequency ----------------------------------------------------

def _exp_design():
    """exp on [0, 10) in 8 bits: y's last place is 2^1 (negative fractional bits);
    the faithful sizing raised TypeError in hw/piecewise.py."""
    t = piecewise_fit("exp(x)", ("0", "10"), 2, segments=64, coef_frac_bits=4, centered=True)
    return design_piecewise(t, 8, 8, widths="auto", multipliers="truncated")


def test_output_with_negative_fractional_bits_sized():
    d = _exp_design()
    assert d.y_format.frac_bits < 0
    assert _measured("sized", d) <= d.budget()["total"] < 2.0 ** -d.y_format.frac_bits


@pytest.mark.requires_tool("iverilog")
def test_output_with_negative_fractional_bits_simulated(tmp_path):
    assert simulate_piecewise(_exp_design(), tmp_path).passed


@pytest.mark.slow
@pytest.mark.requires_tool("yosys")
def test_cli_design_negative_fractional_bits(tmp_path):
    r = run_cli("design", "exp(x)", "--interval", "0", "10", "--in-bits", "8", "--out-bits", "8",
                "--faithful", "--workers", "1", "-o", str(tmp_path / "d"))
    assert r.code == 0, r.err
    assert "winner:" in r.out and "Traceback" not in r.err


def test_frequency_with_exponent_index_refused(tmp_path):
    r = run_cli("design", "1/sqrt(x)", "--interval", "2^-8", "1", "--in-bits", "8",
                "--out-bits", "8", "--faithful", "--index", "exponent", "--frequency", "100",
                "-o", str(tmp_path / "d"))
    assert r.code == 2
    assert r.err.count("\n") == 1 and "--frequency 100: not available with --index exponent" \
        in r.err
    assert not (tmp_path / "d").exists()


# -- banners state the mapping the circuit implements -----------------------------------------

def _banner(text: str) -> list[str]:
    return [line[3:] for line in text.splitlines() if line.startswith("// ")]


def _x_from_banner(lines: list[str], codes) -> list[Fraction]:
    """Each code's x by the banner's own formula."""
    lo_hi = re.search(r" on \[(.+?), (.+?)\),$", lines[0])
    text = " ".join(lines)
    m = re.search(r"value = lo \+ \(hi - lo\) \* k / 2\^(\d+);", text)
    if m:
        lo, hi = (_exact(v) for v in lo_hi.groups())
        return [lo + (hi - lo) * Fraction(k, 2 ** int(m.group(1))) for k in codes]
    m = re.search(r"exponent-indexed: value = lo \* 2\^e \* \(1 \+ u / 2\^(\d+)\), "
                  r"e = (?:k\[(\d+):(\d+)\]|0), u = k\[(\d+):0\] \(lo = ([^)]+)\);", text)
    assert m, text
    U, top, low, utop, lo = m.groups()
    assert int(utop) == int(U) - 1 and (low is None or int(low) == int(U))
    lo = _exact(lo)
    return [lo * 2 ** (k >> int(U)) * (1 + Fraction(k % 2 ** int(U), 2 ** int(U)))
            for k in codes]


def _simulate_outputs(tmp_path, text: str, module: str, in_bits: int) -> list[int]:
    bench = (f"module tb;\n  reg [{in_bits - 1}:0] x;\n  wire [63:0] y;\n"
             f"  {module} dut(.x(x), .y(y));\n  integer i;\n  initial begin\n"
             f"    for (i = 0; i < {2 ** in_bits}; i = i + 1) begin x = i; #1 "
             f"$display(\"%0d %0d\", i, y); end\n    $finish;\n  end\nendmodule\n")
    (tmp_path / "m.v").write_text(text)
    (tmp_path / "tb.v").write_text(bench)
    subprocess.run(["iverilog", "-g2005", "-o", str(tmp_path / "a.out"), str(tmp_path / "m.v"),
                    str(tmp_path / "tb.v")], check=True, capture_output=True)
    out = subprocess.run(["vvp", "-n", str(tmp_path / "a.out")], check=True,
                         capture_output=True, text=True).stdout
    rows = [line.split() for line in out.splitlines() if re.match(r"^\d+ \d+$", line)]
    assert [int(r[0]) for r in rows] == list(range(2 ** in_bits))
    return [int(r[1]) for r in rows]


def _banner_error(lines, xs, ys, f=lambda v: 1 / mpmath.sqrt(v)) -> float:
    """The largest |value - f(x)| over the simulated outputs ``ys``, each output read
    with the banner's own formula for y; ``f`` at 40 digits (default 1/sqrt)."""
    m = re.search(r"y: unsigned \d+-bit code k, value = \((-?\d+) \+ k\) / 2\^(-?\d+)",
                  " ".join(lines))
    off, F = int(m.group(1)), int(m.group(2))
    worst = mpmath.mpf(0)
    with mpmath.workdps(40):
        for x, y in zip(xs, ys):
            v = mpmath.mpf(off + y) * mpmath.mpf(2) ** -F
            worst = max(worst, abs(v - f(mpmath.mpf(x.numerator) / x.denominator)))
    return float(worst)


@pytest.mark.requires_tool("iverilog")
@pytest.mark.parametrize("segment_by, interval", [("exponent", ("2^-4", "1")),
                                                  ("uniform", ("1", "4"))])
def test_banner_mapping_holds_in_simulation(tmp_path, segment_by, interval):
    """The issue's case: the exponent-indexed table's banner stated the uniform
    mapping, under which code 254 errs by 0.995. Simulate the module and apply
    the banner's own formula: its stated bound holds at every code."""
    t = piecewise_fit("1/sqrt(x)", interval, 2, segments=4, segment_by=segment_by,
                      coef_frac_bits=20)
    d = design_piecewise(t, 10, 10)
    text = module_text(d)
    lines = _banner(text)
    codes = range(2 ** 10)
    ys = _simulate_outputs(tmp_path, text, d.module_name, 10)
    assert ys == d.evaluate().tolist()
    xs = _x_from_banner(lines, codes)
    bound = _printed_upper(text)
    assert _banner_error(lines, xs, ys) <= bound
    if segment_by == "exponent":   # the uniform formula would be wrong: the check can fail
        lo, hi = (_exact(v) for v in interval)
        uniform = [lo + (hi - lo) * Fraction(k, 2 ** 10) for k in codes]
        assert _banner_error(lines, uniform, ys) > 100 * bound


# -- the fuzz ------------------------------------------------------------------------------

def _variants(value, rng: random.Random) -> list:
    """Changed values of one field (nested dataclasses changed behind their back)."""
    if isinstance(value, bool):
        return [not value]
    if isinstance(value, int):
        return [value + 1, value - 1, 0, 2 * value + 1]
    if isinstance(value, float):
        return [value / 2, 0.0, value * 2]
    if isinstance(value, Fraction):
        return [value / 2, Fraction(0), value * 2]
    if isinstance(value, str):
        return ["exp(x)", "x", "x/2", "2^-3", "1", "sqrt(x)"]
    if isinstance(value, tuple):
        if not value:
            return [(0,), (1, 2)]
        out = [value[:-1], value[::-1]]
        if all(isinstance(v, int) and not isinstance(v, bool) for v in value):
            out.append(tuple(0 for _ in value))
        i = rng.randrange(len(value))
        for v in _variants(value[i], rng)[:2]:
            out.append(value[:i] + (v,) + value[i + 1:])
        return out
    if isinstance(value, dict):
        out = []
        for k in list(value)[:4]:
            out.append({**value, k: 0.0})
        return out
    if dataclasses.is_dataclass(value):
        fields = [f.name for f in dataclasses.fields(value)]
        name = rng.choice(fields)
        out = []
        for v in _variants(getattr(value, name), rng)[:3]:
            c = copy.copy(value)
            object.__setattr__(c, name, v)
            out.append(c)
        return out
    return []


def _mutations(designs, per_kind: int, seed: int):
    rng = random.Random(seed)
    for kind, base in designs.items():
        fields = [f.name for f in dataclasses.fields(base)]
        made = 0
        while made < per_kind:
            name = rng.choice(fields)
            options = _variants(getattr(base, name), rng)
            if not options:
                continue
            value = rng.choice(options)
            yield kind, base, name, value, rng.choice(("replace", "setattr"))
            made += 1


def _run_fuzz(designs, per_kind: int, seed: int) -> dict:
    seen = {"refused": 0, "accepted": 0}
    for kind, base, name, value, how in _mutations(designs, per_kind, seed):
        try:
            if how == "replace":
                d = dataclasses.replace(base, **{name: value})
            else:
                d = copy.copy(base)
                object.__setattr__(d, name, value)
            text = _text(kind, d)
        except ValueError as exc:   # refused, naming what is wrong
            assert str(exc) and "\n" not in str(exc), (kind, name, exc)
            seen["refused"] += 1
            continue
        seen["accepted"] += 1
        _check_claims(kind, d, text)
    return seen


def test_fuzz_quick(designs):
    """A quick subset: 10 mutations per design kind."""
    seen = _run_fuzz(designs, 10, seed=43)
    assert seen["refused"] + seen["accepted"] == 60 and seen["refused"] > 0


def test_fuzz_designs(designs):
    """The acceptance fuzz: 60 mutations of each of the six design kinds (360 in
    all), by dataclasses.replace and object.__setattr__ (nested fields too): each
    is refused, or prints a bound its own outputs meet and claims they hold."""
    seen = _run_fuzz(designs, 60, seed=2026)
    assert seen["refused"] + seen["accepted"] == 360
    assert seen["refused"] > 200


def test_every_printer_proves_a_changed_design(designs):
    """The printers called directly (not through module_text) prove a design
    changed behind its back: every banner is written from proved facts."""
    from chebnorm.hw.hdl.verilog import verilog_module
    from chebnorm.hw.hdl.vhdl import piecewise_vhdl, vhdl_module

    h = copy.copy(designs["horner"])
    object.__setattr__(h, "integers", tuple(0 for _ in h.integers))
    for printer in (verilog_module, vhdl_module):
        with pytest.raises(ValueError, match="^integers: stated"):
            printer(h)
    p = copy.copy(designs["piecewise"])
    object.__setattr__(p, "acc_frac_bits", p.acc_frac_bits + 40)
    with pytest.raises(ValueError, match="^acc_frac_bits"):
        piecewise_vhdl(p)


def test_design_horner_refuses_a_table_changed_behind_its_back():
    t = fit_target("dichotomy", 2)
    object.__setattr__(t, "abs_error_bound", t.abs_error_bound / 1000)
    with pytest.raises(ValueError, match="^abs_error_bound: stated"):
        design_horner(t, 8, 8, coef_bits=12)


def test_pipelined_table_proves_its_base(designs):
    from chebnorm.hw.hdl.tables import table_files
    from chebnorm.hw.pipeline import PipelinedTable

    base = copy.copy(designs["multipartite"])
    p = PipelinedTable(base, (0, 1))
    assert "LATENCY = 2" in p.verilog()
    object.__setattr__(base, "tiv", tuple(0 for _ in base.tiv))
    with pytest.raises(ValueError, match="^certificate.upper: stated"):
        table_files(p, "verilog")


def test_error_budget_proves_its_design(designs):
    h = copy.copy(designs["horner"])
    object.__setattr__(h, "y_format", dataclasses.replace(h.y_format, frac_bits=30))
    with pytest.raises(ValueError, match="cannot hold the outputs"):
        error_budget(h)
    g = copy.copy(designs["horner"])
    object.__setattr__(g, "acc_frac_bits", g.acc_frac_bits - 3)
    with pytest.raises(ValueError, match="^acc_frac_bits: stated|^stages: stated"):
        error_budget(g)


@pytest.mark.requires_tool("iverilog")
@pytest.mark.parametrize("kind", ["plain", "multipartite"])
def test_table_banner_mapping_holds_in_simulation(tmp_path, designs, kind):
    d = designs[kind]
    text = d.verilog()
    lines = _banner(text)
    lo, hi = (_exact(v) for v in re.search(r" on \[(.+?), (.+?)\)\.$", lines[0]).groups())
    W = int(re.search(r"x: unsigned \d+-bit code k, value = lo \+ \(hi - lo\) \* k / 2\^(\d+)$",
                      "\n".join(lines), re.M).group(1))
    xs = [lo + (hi - lo) * Fraction(k, 2 ** W) for k in range(2 ** W)]
    ys = _simulate_outputs(tmp_path, text, d.module_name, d.in_bits)
    worst = _banner_error(lines, xs, ys, f=lambda v: 1 / mpmath.sqrt(1 + 3 * v))
    assert worst <= _printed_upper(text)


@pytest.mark.requires_tool("iverilog")
def test_exponent_banner_mapping_holds_in_simulation(tmp_path, designs):
    """The exponent design's banner: x = k / 2^W on [2^-m, 1), y = {h, m} with
    1/sqrt(x) ~ 2^h (off + m) / 2^F, the error at most 2^h times the stated
    mantissa bound: simulated at every code in the interval."""
    d = designs["exponent"]
    text = d.verilog()
    banner = " ".join(_banner(text))
    W, m_low = (int(v) for v in re.search(r"x = k / 2\^(\d+) in \[2\^-(\d+), 1\)\.",
                                          banner).groups())
    h_hi, h_lo, m_hi, off, F = (int(v) for v in re.search(
        r"y = \{h, m\}: h = y\[(\d+):(\d+)\], m = y\[(\d+):0\]; 1/sqrt\(x\) ~ 2\^h \* "
        r"\((\d+) \+ m\) / 2\^(\d+)\.", banner).groups())
    bound = _printed_upper(text)
    assert "|y - 1/sqrt(x)| <= 2^h * that" in banner
    ys = _simulate_outputs(tmp_path, text, d.module_name, W)
    worst = mpmath.mpf(0)
    with mpmath.workdps(40):
        for k in range(2 ** (W - m_low), 2 ** W):
            y = ys[k]
            h = (y >> h_lo) & ((1 << (h_hi - h_lo + 1)) - 1)
            mant = y & ((1 << (m_hi + 1)) - 1)
            v = mpmath.mpf(2) ** h * (off + mant) / mpmath.mpf(2) ** F
            e = abs(v - 1 / mpmath.sqrt(mpmath.mpf(k) / 2 ** W)) / mpmath.mpf(2) ** h
            worst = max(worst, e)
    assert float(worst) <= bound


@pytest.mark.requires_tool("iverilog")
def test_issue_commands_banner_mapping(tmp_path):
    """The issue's commands: fit an exponent-segmented 1/sqrt, export Verilog; the
    banner's mapping applied to the simulated module meets the stated bound."""
    r = run_cli("fit", "1/sqrt(x)", "--interval", "2^-4", "1", "--degree", "2", "--segments",
                "2^2", "--segment-by", "exponent", "--coef-frac-bits", "20", "-o", "g.json",
                cwd=tmp_path)
    assert r.code == 0, r.err
    r = run_cli("export", "g.json", "--format", "verilog", "--in-bits", "10", "--out-bits", "10",
                "-o", "g.v", cwd=tmp_path)
    assert r.code == 0, r.err
    text = (tmp_path / "g.v").read_text()
    lines = _banner(text)
    module = re.search(r"^module (\w+)", text, re.M).group(1)
    ys = _simulate_outputs(tmp_path, text, module, 10)
    assert "exponent-indexed" in " ".join(lines)
    xs = _x_from_banner(lines, range(2 ** 10))
    assert _banner_error(lines, xs, ys) <= _printed_upper(text)
