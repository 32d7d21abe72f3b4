"""The self-checking test benches of the normalization units
(:mod:`chebnorm.hw.units`), in Verilog and VHDL: each row of the vector
file (``$readmemh`` hex, made by the bit-accurate model) holds the inputs,
then the expected outputs, packed from the most significant bit in port
order (:func:`row_layout`); the bench applies the inputs (and one rising
clock edge for a clocked unit), compares every output and prints one
``PASS:``/``FAIL:`` line.

>>> from types import SimpleNamespace as P
>>> ports = [P(name="a", bits=4, signed=True, output=False), P(name="b", bits=1, signed=False, output=True)]
>>> row_layout(ports)[1], unit_testbench("chebnorm_t", ports, 16, "vhdl").splitlines()[0]
(5, '-- tb_chebnorm_t: self-checking test bench of chebnorm_t.')
"""

from __future__ import annotations

from .bench import _HEX, bench_verdict
from .common import check_language

# an implementation module of chebnorm.hw.hdl: the API is what chebnorm.hw.hdl exports
__all__: list[str] = []


def row_layout(ports) -> tuple[list, int]:
    """Each port's bit range ``[hi:lo]`` in a vector row, in port order from
    the most significant bit, and the row's width.

    Parameters
    ----------
    ports : sequence
        The ports, each with ``name``, ``bits``, ``signed`` and ``output``
        (:class:`chebnorm.hw.units.Port`).

    Returns
    -------
    tuple of (list of (port, int, int), int)
        ``(port, hi, lo)`` per port, and the total width.
    """
    total = sum(p.bits for p in ports)
    pos, out = total, []
    for p in ports:
        out.append((p, pos - 1, pos - p.bits))
        pos -= p.bits
    return out, total


def unit_testbench(name: str, ports, count: int, language: str = "verilog", *,
                   clocked: bool = False, vectors: str | None = None) -> str:
    """The self-checking bench of unit module ``name`` over ``count`` rows.

    Parameters
    ----------
    name : str
        The unit's module (entity) name, an identifier.
    ports : sequence
        Its ports in port-list order (``name``, ``bits``, ``signed``, ``output``), ``clk`` not
        included.
    count : int
        How many rows the vector file holds.
    language : {"verilog", "vhdl"}, default "verilog"
        The bench's language.
    clocked : bool, default False
        One rising edge of ``clk`` per row (outputs compared after it).
    vectors : str or None, default None
        The vector file name; None: ``NAME.hex``.

    Returns
    -------
    str
        The bench text.

    Raises
    ------
    ValueError
        If ``language`` is unknown.
    """
    vectors = vectors or f"{name}.hex"
    if check_language(language) == "vhdl":
        return _vhdl(name, ports, count, clocked, vectors)
    return _verilog(name, ports, count, clocked, vectors)


def _verilog(name: str, ports, count: int, clocked: bool, vectors: str) -> str:
    layout, total = row_layout(ports)
    ins = [(p, hi, lo) for p, hi, lo in layout if not p.output]
    outs = [(p, hi, lo) for p, hi, lo in layout if p.output]
    ohi, olo = outs[0][1], outs[-1][2]
    lines = [f"// tb_{name}: self-checking test bench of {name}.",
             f"// Rows {{inputs, expected outputs}} come from the chebnorm bit-accurate model "
             f"({vectors}).",
             "`timescale 1ns/1ps",
             f"module tb_{name};",
             f"    localparam COUNT = {count};",
             f"    reg [{total - 1}:0] vec [0:COUNT-1];",
             f"    reg [{total - 1}:0] row;"]
    lines += ["    reg clk;"] if clocked else []
    for p, _, _ in ins + outs:
        lines.append(f"    {'wire' if p.output else 'reg'} "
                     f"{'signed ' if p.signed and p.bits > 1 else ''}[{p.bits - 1}:0] {p.name};")
    conns = ([".clk(clk)"] if clocked else []) + [f".{p.name}({p.name})" for p in ports]
    got = "{" + ", ".join(p.name for p, _, _ in outs) + "}"
    lines += [f"    {name} dut ({', '.join(conns)});",
              "    integer i, errors;",
              "    initial begin",
              f"        $readmemh(\"{vectors}\", vec);",
              "        errors = 0;"]
    if clocked:
        lines.append("        clk = 0;")
    lines.append("        for (i = 0; i < COUNT; i = i + 1) begin")
    lines.append("            row = vec[i];")
    for p, hi, lo in ins:
        lines.append(f"            {p.name} = row[{hi}:{lo}];")
    lines += (["            #1 clk = 1;", "            #1;"] if clocked else ["            #1;"])
    lines += [f"            if ({got} !== row[{ohi}:{olo}]) begin",
              "                errors = errors + 1;",
              "                if (errors <= 10)",
              f"                    $display(\"MISMATCH row %0d: got %h expected %h\", i, {got}, "
              f"row[{ohi}:{olo}]);",
              "            end"]
    if clocked:
        lines.append("            clk = 0;")
    lines += ["        end", *bench_verdict(name)]
    return "\n".join(lines)


def _vhdl_type(p) -> str:
    return "std_logic" if p.bits == 1 else f"std_logic_vector({p.bits - 1} downto 0)"


def _vhdl(name: str, ports, count: int, clocked: bool, vectors: str) -> str:
    layout, total = row_layout(ports)
    ins = [(p, hi, lo) for p, hi, lo in layout if not p.output]
    outs = [(p, hi, lo) for p, hi, lo in layout if p.output]
    ohi, olo = outs[0][1], outs[-1][2]
    ow = ohi - olo + 1
    digits = (ow + 3) // 4
    signals = ["    signal clk : std_logic := '0';"] if clocked else []
    for p, _, _ in ins:
        zero = "'0'" if p.bits == 1 else "(others => '0')"
        signals.append(f"    signal {p.name} : {_vhdl_type(p)} := {zero};")
    signals += [f"    signal {p.name} : {_vhdl_type(p)};" for p, _, _ in outs]
    conns = (["clk => clk"] if clocked else []) + [f"{p.name} => {p.name}" for p in ports]
    apply = [f"            {p.name} <= row({hi});" if p.bits == 1
             else f"            {p.name} <= row({hi} downto {lo});" for p, hi, lo in ins]
    step = (["            wait for 1 ns;", "            clk <= '1';", "            wait for 1 ns;"]
            if clocked else ["            wait for 1 ns;"])
    return "\n".join([
        f"-- tb_{name}: self-checking test bench of {name}.",
        f"-- Rows {{inputs, expected outputs}} come from the chebnorm bit-accurate model "
        f"({vectors}). VHDL-2008.",
        "library ieee;", "use ieee.std_logic_1164.all;", "use ieee.numeric_std.all;",
        "use std.textio.all;", "",
        f"entity tb_{name} is", f"end entity tb_{name};", "",
        f"architecture bench of tb_{name} is",
        f"    constant COUNT : natural := {count};",
        f"    constant BITS  : natural := {total};",
        *_HEX,
        "    function to_hex(v : std_logic_vector) return string is",
        f"        variable u : unsigned({4 * digits - 1} downto 0) := resize(unsigned(v), "
        f"{4 * digits});",
        f"        variable s : string(1 to {digits});",
        "        constant HEX : string(1 to 16) := \"0123456789abcdef\";",
        "    begin",
        f"        for i in 0 to {digits - 1} loop",
        f"            s({digits} - i) := HEX(to_integer(u(4 * i + 3 downto 4 * i)) + 1);",
        "        end loop;",
        "        return s;",
        "    end function;",
        *signals,
        "begin",
        f"    dut : entity work.{name} port map ({', '.join(conns)});",
        "    check : process",
        f"        file vf : text open read_mode is \"{vectors}\";",
        "        variable l : line;",
        "        variable row : std_logic_vector(BITS - 1 downto 0);",
        f"        variable got : std_logic_vector({ow - 1} downto 0);",
        "        variable errors : natural := 0;",
        "    begin",
        "        for i in 0 to COUNT - 1 loop",
        "            readline(vf, l);",
        "            row := from_hex(l.all, BITS);",
        *apply,
        *step,
        f"            got := {' & '.join(p.name for p, _, _ in outs)};",
        f"            if got /= row({ohi} downto {olo}) then",
        "                errors := errors + 1;",
        "                if errors <= 10 then",
        "                    report \"MISMATCH row \" & integer'image(i) & \": got \" & to_hex(got)",
        f"                        & \" expected \" & to_hex(row({ohi} downto {olo}));",
        "                end if;",
        "            end if;",
        *(["            clk <= '0';"] if clocked else []),
        "        end loop;",
        "        if errors = 0 then",
        f"            report \"PASS: \" & integer'image(COUNT) & \" vectors, 0 mismatches ({name})\";",
        "        else",
        f"            report \"FAIL: \" & integer'image(COUNT) & \" vectors, \" & "
        f"integer'image(errors) & \" mismatches ({name})\";",
        "        end if;",
        "        wait;",
        "    end process check;",
        "end architecture bench;", ""])
