"""The netlist IR (issue 45): small hand-built modules printed in Verilog and
VHDL, simulated over every input code in Icarus and GHDL, against two
independent computations -- plain Python integer arithmetic written here, and
the IR's own evaluation; the IR refuses width and signedness mismatches."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import pytest

from chebnorm.hw.hdl.datapath import output_stage, round_to
from chebnorm.hw.hdl.netlist import (Add, Assign, Bit, BitVec, Compare, Concat, Const, ConstDecl,
                                     Cut, Declare, Extend, Gate, Group, Instance, LeadingZeros,
                                     Module, Mul, Neg, Not, Output, Param, Port, Registers, Resize,
                                     Rom, Saturate, Select, Shl,
                                     ShiftBy, Shr, Signal, Slice, Sub, ZeroExt, evaluate, rename,
                                     schedule, verilog, vhdl)
from chebnorm.hw.hdl.verilog import piecewise_clocked_testbench, verilog_testbench
from chebnorm.hw.hdl.vhdl import piecewise_vhdl_clocked_testbench, piecewise_vhdl_testbench
from chebnorm.hw.fixed import QFormat
from chebnorm.hw.run_verilog import simulate
from chebnorm.hw.run_vhdl import simulate_vhdl
from conftest import requires_tool

W = 6   # input bits of the hand-built modules: 64 codes


def _s(name, width):
    return Signal(name, width, signed=True)


def _wrap(v, bits):
    v &= (1 << bits) - 1
    return v - (1 << bits) if v >> (bits - 1) else v


ROM = ((3, -2), (-4, 1), (0, 7), (-8, -1))


def _arith(latency=0) -> Module:
    """Every expression node: a ROM on the top bits, a product, shifts both
    ways, a negation, a gated row, a concatenation with an inverted bit, a
    difference, then the rounding (ties to even) and the saturating output."""
    m = Module("chebnorm_nl", W, 4, facts=["netlist test module"], latency=latency)
    x = m.x
    low = Signal("low", 4, logic=True)
    c0, c1 = _s("c0", 4), _s("c1", 4)
    u, t, p = _s("u", 5), _s("t", 4), _s("p", 8)
    st = [Assign(low, Slice(x, 3, 0)),
          Rom(Signal("idx", 2), Slice(x, 5, 4), (c0, c1), ROM),
          Assign(u, ZeroExt(Slice(low, 3, 0))),                      # 0..15
          Assign(t, Concat((Not(BitVec(low, 3)), Slice(low, 2, 0)))),  # low - 8
          Assign(p, Resize(Mul(c1, t), 8)),
          Assign(_s("n", 6), Neg(Resize(c0, 6))),
          Assign(_s("g", 6), Gate(_s("n", 6), Bit(low, 1), on=False)),
          Assign(_s("sh", 8), Shl(Resize(c0, 8), 3)),
          Assign(_s("sr", 8), Resize(Shr(p, 1), 8)),
          Assign(_s("k", 9), Resize(Add((Group(Resize(_s("sr", 8), 9)), Resize(_s("g", 6), 9),
                                         Resize(u, 9))), 9)),
          Assign(_s("d", 9), Sub(_s("k", 9), Resize(_s("sh", 8), 9)))]
    top = _s("d", 9)
    if latency:
        st.append(Registers(((_s("d_r", 9), top),)))
        top = _s("d_r", 9)
    # y = saturate(round(d / 4) - 2) on 4 bits: y_format with 2 fractional bits less
    st += output_stage(top, 2, QFormat(4, 0, offset_code=2), 4, "rne")
    m.statements[:] = st
    return m


def _expected(k: int) -> int:
    """The module's y, computed here with Python integers."""
    low, (c0, c1) = k & 15, ROM[k >> 4]
    t = low - 8
    p = _wrap(c1 * t, 8)
    n = -c0
    g = n if not (low >> 1) & 1 else 0
    sh = _wrap(c0 * 8, 8)
    d = _wrap(_wrap(p >> 1, 9) + g + low - sh, 9)
    q, rem = divmod(d, 4)
    r = q + (1 if rem > 2 or (rem == 2 and q % 2) else 0)   # nearest, ties to even
    return min(max(r - 2, 0), 15)


def _composite() -> Module:
    """A normalizer around an inlined sub-module, as the exponent composite is
    built: a leading-zero count, a variable shift, an unsigned increment, a
    second module's statements with its ports renamed, ``y = {h, m}``."""
    core = Module("chebnorm_core", W, 3)
    c, ky, ymax, raw = _s("c", 5), _s("KY", 5), _s("YMAX", 5), _s("raw", 5)
    core.statements += [Assign(c, ZeroExt(Slice(core.x, 5, 2))), ConstDecl(ky, 4),
                        ConstDecl(ymax, 7), Assign(raw, Sub(c, ky)), Saturate(raw, ymax)]
    m = Module("chebnorm_lz", W, 6)
    lz, mant = Signal("nrm_lz", 3), Signal("nrm_mant", W, logic=True)
    lz2, h, mm = Signal("nrm_lz2", 4), Signal("nrm_h", 3), Signal("nrm_m", 3, logic=True)
    body = [replace(s, port=mm, width_name="M_BITS") if isinstance(s, Saturate) else s
            for s in rename(core.statements, {"x": mant})]
    m.statements += [Param("M_BITS", 3), LeadingZeros(lz, m.x, "nrm_i", "nrm_count"),
                     Assign(mant, ShiftBy(m.x, lz)),
                     Assign(lz2, Add((Extend(lz, 4), Const(2, 2, signed=False)))),
                     Assign(h, Slice(lz2, 3, 1)), Declare(mm), *body,
                     Output(Concat((h, mm)))]
    return m


def _composite_expected(k: int) -> int:
    lz = W - k.bit_length()
    mant = (k << lz) & (2 ** W - 1)
    raw = (mant >> 2) - 4
    return (((lz + 2) >> 1) << 3) | min(max(raw, 0), 7)


def _shim(m: Module):
    return SimpleNamespace(name=m.name[len("chebnorm_"):], module_name=m.name,
                           in_bits=m.in_bits, out_bits=m.out_bits, degree=0, latency=m.latency)


def test_evaluation_matches_python_arithmetic():
    m = _arith()
    got = [evaluate(m, k)["y"] for k in range(2 ** W)]
    assert got == [_expected(k) for k in range(2 ** W)]
    assert len(set(got)) >= 10 and 0 in got and 15 in got   # saturation reached both ways


@requires_tool("iverilog", "ghdl")
@pytest.mark.parametrize("latency", [0, 1])
def test_both_printers_simulate_every_code(tmp_path, latency):
    m = _arith(latency)
    shim = _shim(m)
    (tmp_path / f"{m.name}.hex").write_text("".join(f"{_expected(k):02x}\n"
                                                     for k in range(2 ** W)))
    if latency:
        benches = {"v": piecewise_clocked_testbench(shim),
                   "vhd": piecewise_vhdl_clocked_testbench(shim)}
    else:
        benches = {"v": verilog_testbench(shim), "vhd": piecewise_vhdl_testbench(shim)}
    for ext, text in (("v", verilog(m)), ("vhd", vhdl(m))):
        (tmp_path / f"{m.name}.{ext}").write_text(text)
        (tmp_path / f"tb_{m.name}.{ext}").write_text(benches[ext])
    for run in (simulate, simulate_vhdl):
        r = run(tmp_path, m.name)
        assert r.passed and r.vectors == 2 ** W and r.mismatches == 0, r.line


def test_composite_evaluation_matches_python_arithmetic():
    m = _composite()
    assert [evaluate(m, k)["y"] for k in range(2 ** W)] == [_composite_expected(k)
                                                           for k in range(2 ** W)]
    v = verilog(m)
    assert "nrm_m = raw[4] ? {M_BITS{1'b0}}" in v and "core.x" not in v
    assert "    y <= std_logic_vector(nrm_h) & nrm_m;" in vhdl(m)


@requires_tool("iverilog", "ghdl")
def test_composite_simulates_every_code(tmp_path):
    m = _composite()
    shim = _shim(m)
    (tmp_path / f"{m.name}.hex").write_text("".join(f"{_composite_expected(k):02x}\n"
                                                     for k in range(2 ** W)))
    for ext, text, bench in (("v", verilog(m), verilog_testbench(shim)),
                             ("vhd", vhdl(m), piecewise_vhdl_testbench(shim))):
        (tmp_path / f"{m.name}.{ext}").write_text(text)
        (tmp_path / f"tb_{m.name}.{ext}").write_text(bench)
    for run in (simulate, simulate_vhdl):
        r = run(tmp_path, m.name)
        assert r.passed and r.vectors == 2 ** W and r.mismatches == 0, r.line


def test_schedule_registers_what_is_live_across_each_cut():
    """A cut registers the signals defined before it and read after it, in the
    order they were defined (a constant, the port and a dead signal are not),
    and the reads after it take the register."""
    x = Signal("x", 4, logic=True)
    u, v, w, dead = _s("u", 5), _s("v", 5), _s("w", 5), _s("dead", 5)
    k = _s("K", 5)
    st = schedule([ConstDecl(k, 3), Assign(u, ZeroExt(x)), Assign(dead, Neg(u)),
                   Assign(v, Add((u, k))), Cut(0), Cut(1, label="two"),
                   Assign(w, Sub(v, u)), Output(w)])
    regs = [s for s in st if isinstance(s, Registers)]
    assert [[(d.name, src.name) for d, src in r.pairs] for r in regs] == [
        [("u_r0", "u"), ("v_r0", "v")], [("u_r1", "u_r0"), ("v_r1", "v_r0")]]
    assert regs[1].label == "two"
    assert st[-2] == Assign(w, Sub(_s("v_r1", 5), _s("u_r1", 5)))
    m = Module("chebnorm_sch", 4, 5, statements=st, latency=2)
    assert [evaluate(m, c)["y"] for c in range(16)] == [c + 3 - c for c in range(16)]


def test_rename_refuses_another_type():
    with pytest.raises(ValueError, match="rename x: .*accepted: the same width and type"):
        rename(Assign(Signal("low", 4, logic=True), Slice(Signal("x", 6, logic=True), 3, 0)),
               {"x": Signal("nrm", 6)})


def test_output_statement_and_plain_rounding():
    """``round_to`` with floor: an arithmetic shift; Output drives y with the bits."""
    m = Module("chebnorm_fl", W, 4)
    v = _s("v", 7)
    m.statements += [Assign(v, ZeroExt(Slice(m.x, 5, 0))),
                     Assign(_s("w", 7), Sub(v, _s("K", 7))),
                     *round_to(_s("w", 7), "f", 2, 5, "trunc"),
                     Output(Slice(Signal("f", 5, signed=True), 3, 0))]
    m.statements.insert(0, ConstDecl(_s("K", 7), 20))
    assert [evaluate(m, k)["y"] for k in range(64)] == [((k - 20) >> 2) & 15 for k in range(64)]
    assert "    assign y = f[3:0];" in verilog(m)
    assert "    y <= std_logic_vector(f(3 downto 0));" in vhdl(m)


@pytest.mark.parametrize("build, match", [
    (lambda: Add((_s("a", 4), Signal("b", 4))), "Add: .*one signedness"),
    (lambda: Assign(_s("a", 4), _s("b", 5)), "Assign a: a value of 5 signed bits to a signal "
                                             "of 4 signed bits"),
    (lambda: Assign(Signal("a", 4), _s("b", 4)), "Assign a: .*4 unsigned bits"),
    (lambda: Mul(_s("a", 4), Signal("b", 4)), "Mul: .*accepted: signed operands"),
    (lambda: Const(8, 4), "Const: 8 does not fit a signed 4-bit word"),
    (lambda: Const(-1, 4, signed=False), "Const: -1 does not fit an unsigned 4-bit word"),
    (lambda: LeadingZeros(Signal("z", 2), Signal("x", 4, logic=True), "i", "c"),
     "LeadingZeros: .*that holds 4"),
    (lambda: ShiftBy(_s("a", 4), Signal("k", 2)), "ShiftBy: accepted: a logic Signal"),
    (lambda: Slice(Signal("a", 4), 4, 0), "Slice: bits 4..0"),
    (lambda: Signal("a", 0), "signal 'a': width 0"),
    (lambda: Registers(((_s("r", 5), _s("a", 4)),)), "Registers r: operands of 5 signed bits "
                                                      "and 4 signed bits"),
    (lambda: Rom(Signal("i", 1), Slice(Signal("x", 4), 0, 0), (_s("c", 3),), ((1,),)),
     "Rom: 1 rows for a 1-bit address; accepted: 2"),
    (lambda: Resize(_s("a", 4), 5, signed=False), "Resize: a change of width and signedness"),
])
def test_mismatches_are_refused_naming_the_node(build, match):
    with pytest.raises(ValueError, match=match):
        build()


@pytest.mark.parametrize("expr, match", [
    (lambda a: Shr(Resize(a, 3), 1), "Resize: 5 signed bits narrowed to 3 bits under an "
                                     "operation that reads its high bits"),
    (lambda a: Add((Gate(a, Bit(Signal("x", 4, logic=True), 0)), a)), "Gate: inside an "
                                                                      "expression"),
])
def test_verilog_refuses_what_its_context_would_change(expr, match):
    """Verilog sizes an expression by its context: a narrowing the IR makes under a
    right shift, or an AND nested in a sum, would print as a different value."""
    m = Module("chebnorm_w", 4, 4)
    a = _s("a", 5)
    e = expr(a)
    m.statements += [Assign(a, ZeroExt(m.x)), Assign(_s("b", e.width), e)]
    with pytest.raises(ValueError, match=match):
        verilog(m)
    vhdl(m)   # VHDL computes what the IR says: nothing to refuse


def test_verilog_refuses_a_widened_sum():
    """A sum widened by Resize would be computed at the wider width by Verilog
    and at the operands' by VHDL: refused rather than printed two ways."""
    m = Module("chebnorm_w", 4, 4)
    a = _s("a", 5)
    m.statements += [Assign(a, ZeroExt(m.x)),
                     Assign(_s("b", 8), Resize(Add((a, a)), 8))]
    with pytest.raises(ValueError, match="Resize: Add of 5 signed bits widened to 8 bits"):
        verilog(m)


def _instance_host(inner: Module) -> Module:
    """A module of ports x, y that instantiates ``inner`` by name (ports mapped by name)."""
    m = Module("chebnorm_host", inner.in_bits, inner.out_bits, facts=["instance test"])
    yw = Signal("yw", inner.out_bits, logic=True)
    m.statements += [Declare(yw),
                     Instance(inner.name, "dut", (("x", "input", inner.in_bits, m.x),
                                                  ("y", "output", inner.out_bits, yw))),
                     Output(yw)]
    return m


@requires_tool("iverilog", "ghdl")
def test_instance_simulates_every_code_in_both_languages(tmp_path):
    inner = _arith()
    m = _instance_host(inner)
    assert "    chebnorm_nl dut (.x(x), .y(yw));" in verilog(m)
    assert "    dut : entity work.chebnorm_nl port map (x => x, y => yw);" in vhdl(m)
    shim = _shim(m)
    (tmp_path / f"{m.name}.hex").write_text("".join(f"{_expected(k):02x}\n"
                                                     for k in range(2 ** W)))
    for ext, text, bench in (("v", verilog(inner) + verilog(m), verilog_testbench(shim)),
                             ("vhd", vhdl(inner) + vhdl(m), piecewise_vhdl_testbench(shim))):
        (tmp_path / f"{m.name}.{ext}").write_text(text)
        (tmp_path / f"tb_{m.name}.{ext}").write_text(bench)
    for run in (simulate, simulate_vhdl):
        r = run(tmp_path, m.name)
        assert r.passed and r.vectors == 2 ** W and r.mismatches == 0, r.line
    with pytest.raises(ValueError, match="instance"):
        evaluate(m, 0)


@pytest.mark.parametrize("build, match", [
    (lambda: Instance("m", "dut", (("x", "input", 5, Signal("v", 4, logic=True)),)),
     "port x: 4 bits connected to a 5-bit port"),
    (lambda: Instance("m", "dut", (("x", "input", 4, Signal("v", 4, signed=True)),)),
     "port x: Signal; accepted: a logic Signal"),
    (lambda: Instance("m", "dut", (("x", "inout", 4, Signal("v", 4, logic=True)),)),
     "direction 'inout'"),
    (lambda: Instance("m", "dut", (("x", "input", 4, Signal("v", 4, logic=True)),) * 2),
     "connected twice"),
    (lambda: Instance("m;", "dut", ()), "instance module"),
    (lambda: Port(Signal("p", 4, signed=True)), "Port p: 4 signed bits"),
    (lambda: Output(Signal("v", 3, logic=True), port=Signal("p", 4, logic=True)),
     "Output p: a value of 3 unsigned bits to a port of 4"),
])
def test_instance_and_port_refusals_name_the_node(build, match):
    with pytest.raises(ValueError, match=match):
        build()


@requires_tool("ghdl", "iverilog")
def test_register_wrapper_netlist_passes_values_in_both_languages(tmp_path):
    """The I/O register wrapper around a module: two clocks after pin_i is
    applied, pin_o holds the module's output (Verilog and VHDL)."""
    import subprocess

    from chebnorm.hw.targets import register_wrapper, wrapper_netlist

    inner = _arith()
    wrap = wrapper_netlist(inner.name, [("x", W)], [("y", 4)], clocked=False)
    codes = [0, 5, 17, 42, 63]
    vtb = ["module tb;", "    reg clk = 0;", f"    reg [{W - 1}:0] pi;", "    wire [3:0] po;",
           "    chebnorm_fmax_wrap w (.clk(clk), .pin_i(pi), .pin_o(po));", "    initial begin"]
    for k in codes:
        vtb += [f"        pi = {k}; #1 clk = 1; #1 clk = 0; #1 clk = 1; #1 clk = 0;",
                '        $display("%0d", po);']
    vtb += ["    end", "endmodule", ""]
    (tmp_path / "w.v").write_text(verilog(inner) + register_wrapper(inner.name, [
        ("x", "input", W), ("y", "output", 4)], clocked=False) + "\n" + "\n".join(vtb))
    subprocess.run(["iverilog", "-o", str(tmp_path / "w.vvp"), str(tmp_path / "w.v")], check=True)
    out = subprocess.run(["vvp", "-n", str(tmp_path / "w.vvp")], capture_output=True, text=True,
                         check=True).stdout.split()
    assert [int(v) for v in out] == [_expected(k) for k in codes]
    htb = ["library ieee;", "use ieee.std_logic_1164.all;", "use ieee.numeric_std.all;",
           "use std.textio.all;", "entity tb is end entity;", "architecture a of tb is",
           "    signal clk : std_logic := '0';", f"    signal pi : std_logic_vector({W - 1} downto 0);",
           "    signal po : std_logic_vector(3 downto 0);", "begin",
           "    w : entity work.chebnorm_fmax_wrap port map (clk => clk, pin_i => pi, pin_o => po);",
           "    process", "        variable l : line;", "    begin"]
    for k in codes:
        htb += [f"        pi <= std_logic_vector(to_unsigned({k}, {W}));",
                *["        wait for 1 ns; clk <= '1'; wait for 1 ns; clk <= '0';"] * 2,
                "        write(l, to_integer(unsigned(po))); writeline(output, l);"]
    htb += ["        wait;", "    end process;", "end architecture;", ""]
    (tmp_path / "w.vhd").write_text(vhdl(inner) + vhdl(wrap) + "\n".join(htb))
    for step in (["-a", "--std=08", "w.vhd"], ["-e", "--std=08", "tb"],
                 ["-r", "--std=08", "tb", "--ieee-asserts=disable-at-0"]):
        r = subprocess.run(["ghdl", *step], cwd=tmp_path, capture_output=True, text=True,
                           check=True)
    assert [int(v) for v in r.stdout.split()] == [_expected(k) for k in codes]


def _select() -> Module:
    """Comparisons (signed and unsigned), a chain of selects with unsigned
    constants, a concatenation with a constant, a signed value read as
    unsigned bits."""
    m = Module("chebnorm_sel", W, 9, facts=["select test module"])
    a, b, sa, sb = Signal("a", 3), Signal("b", 3), _s("sa", 3), _s("sb", 3)
    lt, ge = Signal("lt", 1, logic=True, scalar=True), Signal("ge", 1, logic=True, scalar=True)
    sel, c, u = Signal("sel", 3), Signal("c", 5), Signal("u", 3)
    m.statements += [Assign(a, Slice(m.x, 5, 3)), Assign(b, Slice(m.x, 2, 0)),
                     Assign(sa, Slice(m.x, 5, 3)), Assign(sb, Slice(m.x, 2, 0)),
                     Assign(lt, Compare("<", sa, sb)), Assign(ge, Compare(">=", a, b)),
                     Assign(sel, Select(lt, a, Select(Compare("==", a, Const(3, 3, signed=False)),
                                                      Const(5, 3, signed=False), b))),
                     Assign(c, Concat((Const(1, 2, signed=False), sel))),
                     Assign(u, Resize(Neg(sa), 3, signed=False)),
                     Output(Concat((lt, ge, Slice(c, 3, 0), u)))]
    return m


def _select_expected(k: int) -> int:
    a, b = k >> 3, k & 7
    sa, sb = _wrap(a, 3), _wrap(b, 3)
    lt, ge = int(sa < sb), int(a >= b)
    sel = a if lt else (5 if a == 3 else b)
    c = 8 | sel
    return (lt << 8) | (ge << 7) | ((c & 15) << 3) | (-sa & 7)


def test_select_and_compare_evaluate_as_python():
    m = _select()
    got = [evaluate(m, k)["y"] for k in range(2 ** W)]
    assert got == [_select_expected(k) for k in range(2 ** W)]
    assert len(set(got)) >= 40   # the selects and comparisons vary
    v, h = verilog(m), vhdl(m)
    assert "    wire [2:0] sel = lt ? a : a == 3'd3 ? 3'd5 : b;" in v
    assert "    sel <= a when lt = '1' else to_unsigned(5, 3) when a = 3 else b;" in h
    assert "    lt <= '1' when sa < sb else '0';" in h
    assert "    u <= unsigned(-sa);" in h and "    c <= unsigned(\"01\" & std_logic_vector(sel));" in h


@requires_tool("iverilog", "ghdl")
def test_select_and_compare_simulate_every_code(tmp_path):
    m = _select()
    shim = _shim(m)
    (tmp_path / f"{m.name}.hex").write_text("".join(f"{_select_expected(k):03x}\n"
                                                     for k in range(2 ** W)))
    for ext, text, bench in (("v", verilog(m), verilog_testbench(shim)),
                             ("vhd", vhdl(m), piecewise_vhdl_testbench(shim))):
        (tmp_path / f"{m.name}.{ext}").write_text(text)
        (tmp_path / f"tb_{m.name}.{ext}").write_text(bench)
    for run in (simulate, simulate_vhdl):
        r = run(tmp_path, m.name)
        assert r.passed and r.vectors == 2 ** W and r.mismatches == 0, r.line


def test_a_register_fed_by_its_own_value_is_declared_first():
    """An accumulator: Declare(reg=True), the next value, Registers(declare=False)."""
    m = Module("chebnorm_acc", 4, 4, latency=1)
    acc, nxt = Signal("acc", 4), Signal("acc_next", 4)
    m.statements += [Declare(acc, reg=True),
                     Assign(nxt, Select(Bit(m.x, 3), Const(0, 4, signed=False),
                                        Add((acc, Slice(m.x, 3, 0))))),
                     Registers(((acc, nxt),), declare=False), Output(acc)]
    v, h = verilog(m), vhdl(m)
    assert v.count("reg [3:0] acc;") == 1 and "acc <= acc_next;" in v
    assert h.count("signal acc : unsigned(3 downto 0);") == 1


@pytest.mark.parametrize("build, match", [
    (lambda: Compare("<", _s("a", 4), Signal("b", 4)), "Compare: operands of 4 signed bits "
                                                       "and 4 unsigned bits"),
    (lambda: Compare("=", _s("a", 4), _s("b", 4)), "Compare: operator '='"),
    (lambda: Compare("<", Signal("a", 4, logic=True), Signal("b", 4)), "Compare: a bit vector"),
    (lambda: Select(Signal("c", 2), _s("a", 4), _s("b", 4)), "Select: condition of 2 unsigned"),
    (lambda: Select(Bit(Signal("c", 2), 0), _s("a", 4), _s("b", 5)), "Select: operands of 4 "
                                                                     "signed bits and 5"),
    (lambda: Assign(Signal("v", 1), Compare("<", _s("a", 4), _s("b", 4))),
     "Assign v: a Compare to a vector"),
    (lambda: Output(Select(Bit(Signal("c", 2), 0), _s("a", 4), _s("b", 4))), "Output: a Select"),
])
def test_select_and_compare_refusals_name_the_node(build, match):
    with pytest.raises(ValueError, match=match):
        build()


def test_a_nested_select_is_refused():
    m = Module("chebnorm_w", 4, 4)
    c = Bit(m.x, 0)
    a = _s("a", 5)
    m.statements += [Assign(a, ZeroExt(m.x)),
                     Assign(_s("b", 5), Add((Select(c, a, a), a)))]
    with pytest.raises(ValueError, match="Select: inside an expression"):
        verilog(m)


def test_a_vector_of_bits_only_names_its_type_in_vhdl():
    """Bits concatenated (std_logic & std_logic) have no type of their own in
    VHDL: the printer qualifies them; Verilog needs nothing."""
    m = Module("chebnorm_bits", 4, 3)
    b = [Signal(f"b{i}", 1, logic=True, scalar=True) for i in range(3)]
    q = Signal("q", 3)
    m.statements += [*(Assign(s, Bit(m.x, i)) for i, s in enumerate(b)),
                     Assign(q, Concat(tuple(b))), Output(q)]
    assert "    q <= unsigned(std_logic_vector'(b0 & b1 & b2));" in vhdl(m)
    assert "    wire [2:0] q = {b0, b1, b2};" in verilog(m)
    assert [evaluate(m, k)["y"] for k in range(8)] == [int(f"{k:03b}"[::-1], 2)
                                                       for k in range(8)]
