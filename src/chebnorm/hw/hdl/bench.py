"""The exhaustive self-checking test benches, printed from a netlist's
ports (:class:`~chebnorm.hw.hdl.netlist.Module`: name, widths, latency) and
the bit-accurate model's vector file (:func:`~chebnorm.hw.hdl.common.vector_file`):
every input code applied -- one per clock cycle when the module is
pipelined, each output checked ``LATENCY`` cycles later -- and one
``PASS:``/``FAIL:`` line printed. The Verilog bench reads the vectors with
``$readmemh``; the VHDL bench reads the same file and writes the outputs it
saw to ``NAME_vhdl_y.hex``.

>>> from chebnorm.hw.hdl.netlist import Module
>>> testbench(Module("chebnorm_f", 4, 4), "verilog").splitlines()[0]
'// tb_chebnorm_f: exhaustive self-checking test bench of chebnorm_f.'
"""

from __future__ import annotations

from .common import check_language, vectors_name
from .netlist import Module
from .._docfrag import hw_doc

# an implementation module of chebnorm.hw.hdl: the API is what chebnorm.hw.hdl exports
__all__: list[str] = []


def bench_ports(design, name: str, latency: int = 0) -> Module:
    """The ports of ``design``'s module ``name`` as a netlist without
    statements: what a bench reads.

    Parameters
    ----------
    design : object
        A design with ``in_bits`` and ``out_bits``.
    name : str
        The module (entity) name.
    latency : int, default 0
        Its pipeline latency.

    Returns
    -------
    Module
        The ports.
    """
    return Module(name, design.in_bits, design.out_bits, latency=latency)


def bench_verdict(name: str) -> list[str]:
    """The last lines of an exhaustive test bench of ``name`` that counted
    ``errors`` over ``COUNT`` vectors: print the one ``PASS:``/``FAIL:`` line
    the simulation runners read, then ``$finish``.

    >>> print("\\n".join(bench_verdict("chebnorm_f")[:2]))
            if (errors == 0)
                $display("PASS: %0d vectors, 0 mismatches (chebnorm_f)", COUNT);

    Parameters
    ----------
    name : str
        The module name printed in the verdict (an identifier).

    Returns
    -------
    list of str
        Verilog lines, ending with ``endmodule`` and an empty line.
    """
    return ["        if (errors == 0)",
            f"            $display(\"PASS: %0d vectors, 0 mismatches ({name})\", COUNT);",
            "        else",
            f"            $display(\"FAIL: %0d vectors, %0d mismatches ({name})\", COUNT, errors);",
            "        $finish;",
            "    end",
            "endmodule", ""]


@hw_doc
def testbench(module, language: str, vectors: str | None = None) -> str:
    """The exhaustive self-checking bench of ``module`` in ``language``.

    Parameters
    ----------
    module : Module
        The netlist (only its name, ``in_bits``, ``out_bits`` and ``latency`` are read).
    %(language_required)s
    %(vectors)s

    Returns
    -------
    str
        The bench text.

    Raises
    ------
    ValueError
        If ``language`` is unknown or ``vectors`` (without ``.hex``) is not an identifier.
    """
    name, n = module.name, module.latency
    if check_language(language) == "vhdl":
        return _vhdl(module, name, vectors, clocked=n > 0, n=n)
    if n > 0:
        return _verilog_clocked(module, name, n, vectors)
    return _verilog(module, name, vectors)


def _verilog(module, name: str, vectors: str | None) -> str:
    """The combinational module's bench: one code every nanosecond."""
    vectors = vectors_name(name, vectors)
    count = 2 ** module.in_bits
    return "\n".join([
        f"// tb_{name}: exhaustive self-checking test bench of {name}.",
        f"// Expected outputs come from the chebnorm bit-accurate model ({vectors}).",
        "`timescale 1ns/1ps",
        f"module tb_{name};",
        f"    localparam IN_BITS = {module.in_bits};",
        f"    localparam OUT_BITS = {module.out_bits};",
        f"    localparam COUNT = {count};",
        "    reg  [IN_BITS-1:0]  x;",
        "    wire [OUT_BITS-1:0] y;",
        "    reg  [OUT_BITS-1:0] expected [0:COUNT-1];",
        "    integer i, errors;",
        f"    {name} #(.IN_BITS(IN_BITS), .OUT_BITS(OUT_BITS)) dut (.x(x), .y(y));",
        "    initial begin",
        f"        $readmemh(\"{vectors}\", expected);",
        "        errors = 0;",
        "        for (i = 0; i < COUNT; i = i + 1) begin",
        "            x = i;",
        "            #1;",
        "            if (y !== expected[i]) begin",
        "                errors = errors + 1;",
        "                if (errors <= 10)",
        "                    $display(\"MISMATCH x=%h y=%h expected=%h\", x, y, expected[i]);",
        "            end",
        "        end",
        *bench_verdict(name)])



def _verilog_clocked(module, name: str, n: int, vectors: str | None) -> str:
    """The exhaustive bench of clocked module ``name`` of latency ``n``."""
    vectors = vectors_name(name, vectors)
    count = 2 ** module.in_bits
    return "\n".join([
        f"// tb_{name}: exhaustive self-checking test bench of {name}, latency {n}.",
        f"// Expected outputs come from the chebnorm bit-accurate model ({vectors}).",
        "`timescale 1ns/1ps",
        f"module tb_{name};",
        f"    localparam IN_BITS = {module.in_bits};",
        f"    localparam OUT_BITS = {module.out_bits};",
        f"    localparam LATENCY = {n};",
        f"    localparam COUNT = {count};",
        "    reg clk;",
        "    reg  [IN_BITS-1:0]  x;",
        "    wire [OUT_BITS-1:0] y;",
        "    reg  [OUT_BITS-1:0] expected [0:COUNT-1];",
        "    integer i, errors, checked;",
        f"    {name} #(.IN_BITS(IN_BITS), .OUT_BITS(OUT_BITS), .LATENCY(LATENCY)) dut "
        "(.clk(clk), .x(x), .y(y));",
        "    initial begin",
        f"        $readmemh(\"{vectors}\", expected);",
        "        errors = 0;",
        "        checked = 0;",
        "        clk = 0;",
        "        for (i = 0; i < COUNT + LATENCY - 1; i = i + 1) begin",
        "            x = (i < COUNT) ? i : 0;",
        "            #1 clk = 1;",
        "            #1;",
        "            if (i >= LATENCY - 1) begin",
        "                checked = checked + 1;",
        "                if (y !== expected[i - LATENCY + 1]) begin",
        "                    errors = errors + 1;",
        "                    if (errors <= 10)",
        "                        $display(\"MISMATCH x=%h y=%h expected=%h\", i - LATENCY + 1, y,",
        "                                 expected[i - LATENCY + 1]);",
        "                end",
        "            end",
        "            clk = 0;",
        "        end",
        "        if (errors == 0)",
        f"            $display(\"PASS: %0d vectors, 0 mismatches ({name}, latency %0d)\", "
        "checked, LATENCY);",
        "        else",
        f"            $display(\"FAIL: %0d vectors, %0d mismatches ({name})\", checked, errors);",
        "        $finish;",
        "    end",
        "endmodule", ""])


_HEX = [
    "    -- one hex word of a vector file (the $readmemh format the Verilog bench reads)",
    "    function from_hex(s : string; n : positive) return std_logic_vector is",
    "        variable v : unsigned(4 * s'length + n - 1 downto 0) := (others => '0');",
    "        variable d : natural;",
    "    begin",
    "        for i in s'range loop",
    "            case s(i) is",
    "                when '0' to '9' => d := character'pos(s(i)) - character'pos('0');",
    "                when 'a' to 'f' => d := character'pos(s(i)) - character'pos('a') + 10;",
    "                when 'A' to 'F' => d := character'pos(s(i)) - character'pos('A') + 10;",
    "                when others => report \"bad hex digit in vector file\" severity failure;",
    "            end case;",
    "            v := shift_left(v, 4) + to_unsigned(d, v'length);",
    "        end loop;",
    "        return std_logic_vector(v(n - 1 downto 0));",
    "    end function;",
]


def _vhdl(module, name: str, vectors: str | None, clocked: bool, n: int) -> str:
    vectors = vectors_name(name, vectors)
    count = 2 ** module.in_bits
    digits = (module.out_bits + 3) // 4
    latency = n if clocked else 1
    dut_generics = "IN_BITS => IN_BITS, OUT_BITS => OUT_BITS" + \
        (", LATENCY => LATENCY" if clocked else "")
    dut_ports = ("clk => clk, " if clocked else "") + "x => x, y => y"
    step = (["            x <= std_logic_vector(to_unsigned(i mod COUNT, IN_BITS));",
             "            wait for 1 ns;", "            clk <= '1';", "            wait for 1 ns;"]
            if clocked else
            ["            x <= std_logic_vector(to_unsigned(i, IN_BITS));",
             "            wait for 1 ns;"])
    k = "i - LATENCY + 1" if clocked else "i"
    return "\n".join([
        f"-- tb_{name}: exhaustive self-checking test bench of {name}"
        + (f", latency {n}." if clocked else "."),
        f"-- Expected outputs come from the chebnorm bit-accurate model ({vectors});",
        f"-- the outputs seen are written to {name}_vhdl_y.hex. VHDL-2008.",
        "library ieee;", "use ieee.std_logic_1164.all;", "use ieee.numeric_std.all;",
        "use std.textio.all;", "",
        f"entity tb_{name} is", f"end entity tb_{name};", "",
        f"architecture bench of tb_{name} is",
        f"    constant IN_BITS  : natural := {module.in_bits};",
        f"    constant OUT_BITS : natural := {module.out_bits};",
        f"    constant LATENCY  : natural := {latency};",
        f"    constant COUNT    : natural := {count};",
        "    type vectors_t is array (0 to COUNT - 1) of std_logic_vector(OUT_BITS - 1 downto 0);",
        *_HEX,
        "    signal clk : std_logic := '0';",
        "    signal x   : std_logic_vector(IN_BITS - 1 downto 0) := (others => '0');",
        "    signal y   : std_logic_vector(OUT_BITS - 1 downto 0);",
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
        "begin",
        f"    dut : entity work.{name}",
        f"        generic map ({dut_generics})",
        f"        port map ({dut_ports});",
        "    check : process",
        f"        file vf : text open read_mode is \"{vectors}\";",
        f"        file yf : text open write_mode is \"{name}_vhdl_y.hex\";",
        "        variable l, o : line;",
        "        variable expected : vectors_t;",
        "        variable errors, checked : natural := 0;",
        "    begin",
        "        for i in 0 to COUNT - 1 loop",
        "            readline(vf, l);",
        "            expected(i) := from_hex(l.all, OUT_BITS);",
        "        end loop;",
        "        for i in 0 to COUNT + LATENCY - 2 loop",
        *step,
        "            if i >= LATENCY - 1 then",
        "                checked := checked + 1;",
        "                write(o, to_hex(y));",
        "                writeline(yf, o);",
        f"                if y /= expected({k}) then",
        "                    errors := errors + 1;",
        "                    if errors <= 10 then",
        f"                        report \"MISMATCH x=\" & integer'image({k}) & \" y=\" & to_hex(y)",
        f"                            & \" expected=\" & to_hex(expected({k}));",
        "                    end if;",
        "                end if;",
        "            end if;",
        *(["            clk <= '0';"] if clocked else []),
        "        end loop;",
        "        if errors = 0 then",
        f"            report \"PASS: \" & integer'image(checked) & \" vectors, 0 mismatches ({name})\";",
        "        else",
        f"            report \"FAIL: \" & integer'image(checked) & \" vectors, \" & "
        f"integer'image(errors) & \" mismatches ({name})\";",
        "        end if;",
        "        wait;",
        "    end process check;",
        "end architecture bench;", ""])
