"""VHDL printers: the combinational and the pipelined evaluator of a
:class:`~chebnorm.hw.horner.HornerDesign` and the evaluator of a
:class:`~chebnorm.hw.piecewise.PiecewiseDesign` (ROM + Horner), each
bit-identical to :mod:`chebnorm.hw.hdl.verilog`'s, and their self-checking
test benches (:func:`chebnorm.hw.run_vhdl.simulate_vhdl` runs them in GHDL).

The entities follow the Verilog port contract::

    entity chebnorm_NAME is
        generic (IN_BITS : natural := W; OUT_BITS : natural := V);
        port (x : in std_logic_vector(IN_BITS-1 downto 0);
              y : out std_logic_vector(OUT_BITS-1 downto 0));

(``chebnorm_NAME_pipe`` adds ``clk`` and the generic ``LATENCY``; a
piecewise entity has the ports of the combinational one). The
datapath is written in ``ieee.numeric_std`` ``signed`` arithmetic with the
widths of the Verilog wires, and every width change goes through one
function, ``wrap``, that does what a Verilog assignment does: sign-extend
to a wider wire, keep the low bits of a narrower one. So the two HDLs agree
bit for bit even where a wire would overflow (which the sizing rules out
anyway). Constants are printed as bit strings (VHDL's ``integer`` may hold
only 32 bits) with their decimal value in a comment.

The test bench reads the bit-accurate model's expected outputs from the
same ``chebnorm_NAME.hex`` as the Verilog bench (one hex word a line),
checks every input code, writes the outputs it saw to
``chebnorm_NAME_vhdl_y.hex`` (so the two simulators' outputs can be
compared code for code) and reports one ``PASS:``/``FAIL:`` line. VHDL-2008
(``ghdl --std=08``).
"""

from __future__ import annotations

from chebnorm.core.textsafe import identifier

from ..horner import HornerDesign
from .common import (shifted_width, step_comment, variable_name)
from .common import (comment_lines, horner_facts, module_name, piecewise_facts, pipelined_name,
                     vectors_name)

# an implementation module of chebnorm.hw.hdl: the API is what chebnorm.hw.hdl exports
__all__: list[str] = []

#: the VHDL standard of the printed text (``ghdl --std=08``)
VHDL_STD = "08"


def _bits(value: int, bits: int) -> str:
    """A ``signed`` bit-string literal of ``value`` in ``bits`` bits (range-checked)."""
    if not -(1 << (bits - 1)) <= value < (1 << (bits - 1)):
        raise ValueError(f"constant {value} does not fit a signed {bits}-bit literal")
    return f'signed\'("{value & ((1 << bits) - 1):0{bits}b}")'


def _const(name: str, value: int, bits: int) -> str:
    return f"    constant {name} : signed({bits - 1} downto 0) := {_bits(value, bits)};  -- {value}"


def _sig(name: str, bits: int) -> str:
    return f"    signal {name} : signed({bits - 1} downto 0);"


_WRAP = [
    "    -- a Verilog assignment: sign-extend to n bits, or keep the low n bits",
    "    function wrap(a : signed; n : positive) return signed is",
    "        variable v : signed(a'length - 1 downto 0) := a;",
    "        variable r : signed(n - 1 downto 0);",
    "    begin",
    "        if n <= a'length then",
    "            r := v(n - 1 downto 0);",
    "        else",
    "            r := resize(v, n);",
    "        end if;",
    "        return r;",
    "    end function;",
]


class _Body:
    """Declarations and statements of the architecture, built side by side."""

    def __init__(self):
        self.decl: list[str] = []
        self.stmt: list[str] = []

    def wire(self, name: str, bits: int, expr: str) -> None:
        self.decl.append(_sig(name, bits))
        self.stmt.append(f"    {name} <= {expr};")


def _round(b: _Body, src: str, dst: str, src_bits: int, shift: int, dst_bits: int,
           mode: str) -> None:
    """``dst = round(src / 2^shift)`` as in the Verilog :func:`~chebnorm.hw.hdl.verilog.round_lines`."""
    if mode != "trunc" and shift + 1 > src_bits:   # the round bit lies above src: extend it
        b.wire(f"{dst}_x", shift + 1, f"resize({src}, {shift + 1})")
        src, src_bits = f"{dst}_x", shift + 1
    b.wire(f"{dst}_q", src_bits, f"shift_right({src}, {shift})")
    if mode == "trunc" or shift == 0:  # nothing dropped: nothing to round
        b.wire(dst, dst_bits, f"wrap({dst}_q, {dst_bits})")
        return
    sticky = f"(or {src}({shift - 2} downto 0)) or " if shift >= 2 else ""
    b.decl.append(f"    signal {dst}_inc : std_logic;")
    b.stmt.append(f"    {dst}_inc <= {src}({shift - 1}) and ({sticky}{dst}_q(0));")
    w = max(dst_bits, src_bits, 2)
    b.wire(dst, dst_bits, f"wrap(wrap({dst}_q, {w}) + signed'(\"0\" & {dst}_inc), {dst_bits})")


def _variable(b: _Body, design: HornerDesign, xs: str, v: str) -> None:
    """The Horner variable ``v = R(xs * xs)`` of a one-parity design
    (nothing for plain Horner in ``x``), as the Verilog printer's."""
    if design.scheme == "monomial":
        return
    if design.scheme == "shifted":   # v = (xs << m) - C: (x - c')/s
        sw, m = shifted_width(design), design.v_shift
        b.stmt.append(f"    -- {v} = (x - c') / s times 2^{design.variable_frac_bits}, c' = "
                      f"{design.v_offset} / 2^{design.x_format.frac_bits + m}")
        b.decl.append(_const(f"{v}_C", design.v_offset, sw))
        wide = f"wrap({xs}, {sw})"
        b.wire(f"{v}_d", sw, (f"shift_left({wide}, {m})" if m else wide) + f" - {v}_C")
        b.wire(v, design.variable_bits, f"wrap({v}_d, {design.variable_bits})")
        return
    sw, vw, rs = 2 * design.xs_bits, design.variable_bits, design.v_round_shift
    b.stmt.append(f"    -- {v}: x*x with {design.variable_frac_bits} fractional bits "
                  f"({'rounded' if rs else 'exact'}); Horner's rule over the {design.scheme} "
                  f"powers in it")
    b.wire(f"{v}_sq", sw, f"{xs} * {xs}")
    if rs:
        _round(b, f"{v}_sq", v, sw, rs, vw, design.rounding)
    else:
        b.wire(v, vw, f"wrap({v}_sq, {vw})")


def _step(b: _Body, design: HornerDesign, st, prev: str, xs: str) -> None:
    j = st.power
    pw = st.product_bits
    b.stmt.append(f"    -- step {j}: {step_comment(design, st)}"
                  f" with {st.sum_frac_bits} -> {st.out_frac_bits} fractional bits")
    # Verilog extends both operands to pw bits and keeps the product mod 2^pw; the exact
    # product of the narrower operands, wrapped to pw bits, is the same bits for less work
    b.wire(f"p{j}", pw, f"wrap({prev} * {xs}, {pw})")
    b.decl.append(_const(f"C{j}", st.coef_shifted, st.sum_bits))
    shifted = f"shift_left(wrap(p{j}, {st.sum_bits}), {st.product_shift})" if st.product_shift \
        else f"wrap(p{j}, {st.sum_bits})"
    b.wire(f"t{j}", st.sum_bits, f"{shifted} + C{j}")
    if j > 0:
        _round(b, f"t{j}", f"a{j}", st.sum_bits, st.round_shift, st.out_bits, design.rounding)


def _output(b: _Body, top: str, top_bits: int, top_frac: int, yf, out_bits: int, rounding: str,
            min_bits: int = 0) -> None:
    """The evaluator's last statements, as the Verilog
    :func:`~chebnorm.hw.hdl.verilog.saturating_output`: round the signed
    ``top`` to y's fractional bits, remove y's offset, saturate into ``y``."""
    shift = top_frac - yf.frac_bits
    rw = max(min_bits, top_bits + max(0, -shift) + 1, out_bits + 2,
             yf.offset_code.bit_length() + 2)
    b.stmt.append(f"    -- output: round to {yf.frac_bits} fractional bits, remove the offset, "
                  f"saturate")
    if shift > 0:
        _round(b, top, "r", top_bits, shift, rw, rounding)
    elif shift == 0:
        b.wire("r", rw, f"wrap({top}, {rw})")
    else:
        b.wire("r", rw, f"shift_left(wrap({top}, {rw}), {-shift})")
    b.decl.append(_const("KY", yf.offset_code, rw))
    b.decl.append(_const("YMAX", yf.max_code, rw))
    b.wire("raw", rw, "r - KY")
    b.stmt += [f"    y <= (others => '0') when raw({rw - 1}) = '1' else",
               "         (others => '1') when raw > YMAX else",
               "         std_logic_vector(raw(OUT_BITS - 1 downto 0));"]


def _vhdl_name(name: str) -> str:
    """``name`` if it is a VHDL basic identifier (no ``__``, no trailing ``_``)."""
    identifier(name, field="module name")
    if "__" in name or name.endswith("_"):
        raise ValueError(f"module name {name!r} is not a VHDL identifier: VHDL forbids two "
                         f"underscores in a row and a trailing underscore; accepted: a table "
                         f"name without them")
    return name


def _entity(name: str, design, clocked: bool) -> list[str]:
    latency = design.latency if getattr(design, "latency", 0) else \
        getattr(design, "steps", design.degree)
    _vhdl_name(name)
    generics = [f"        IN_BITS  : natural := {design.in_bits};",
                f"        OUT_BITS : natural := {design.out_bits}" + (";" if clocked else "")]
    if clocked:
        generics.append(f"        LATENCY  : natural := {latency}")
    ports = (["        clk : in  std_logic;"] if clocked else []) + [
        "        x   : in  std_logic_vector(IN_BITS - 1 downto 0);",
        "        y   : out std_logic_vector(OUT_BITS - 1 downto 0)"]
    return ["library ieee;", "use ieee.std_logic_1164.all;", "use ieee.numeric_std.all;", "",
            f"entity {name} is", "    generic (", *generics, "    );", "    port (", *ports,
            "    );", f"end entity {name};", ""]


def vhdl_module(design: HornerDesign, *, version: str = "", command: str | None = None,
                budget=None) -> str:
    """The combinational VHDL evaluator of ``design`` (see the module docstring).

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 2), 8, 8, coef_bits=12)
    >>> "entity chebnorm_dichotomy_d2 is" in vhdl_module(d)
    True

    Parameters
    ----------
    design : HornerDesign
        The Horner evaluator (:func:`~chebnorm.hw.horner.design_horner`).
    version : str, default ""
        chebnorm's version, stated in the banner (made comment-safe).
    command : str or None, default None
        The command line that made the file, stated in the banner (made comment-safe);
        None or empty: no such line.
    budget : ErrorBudget or None, default None
        A Horner design's certified budget (:func:`~chebnorm.hw.budget.error_budget`),
        stated in the banner; None: not stated. A piecewise design states its own.

    Returns
    -------
    str
        The VHDL-2008 text, banner first.

    Raises
    ------
    ValueError
        If the design's name is not a safe identifier.
    """
    name = design.module_name
    n = design.degree
    xf = design.x_format
    out = comment_lines(horner_facts(design, "vhdl", version=version, command=command,
                                     budget=budget), "vhdl")
    out += _entity(name, design, clocked=False)
    b = _Body()
    xw = design.xs_bits
    b.decl.append(_const("K0", xf.offset_code, xw))
    b.stmt.append(f"    -- x value times 2^{xf.frac_bits}")
    b.wire("xs", xw, f"wrap(signed('0' & x), {xw}) + K0")
    _variable(b, design, "xs", "v")
    n = len(design.horner_integers) - 1
    if n == 0:
        top_bits = max(design.top_bits, 2)
        b.decl.append(_const("TOPC", design.integers[0], top_bits))
        b.wire("top", top_bits, "TOPC")
        top_frac = design.coef_frac_bits
    else:
        aw = max(design.stages[0].acc_bits, 2)
        b.decl.append(_const(f"A{n}", design.horner_integers[n], aw))
        prev = f"A{n}"
        for st in design.stages:
            _step(b, design, st, prev, variable_name(design, st))
            if st.power > 0:
                prev = f"a{st.power}"
        top_bits, top_frac = design.stages[-1].sum_bits, design.stages[-1].sum_frac_bits
        b.wire("top", top_bits, "t0")
    _output(b, "top", top_bits, top_frac, design.y_format, design.out_bits, design.rounding,
            design.raw_bits)
    out += [f"architecture rtl of {name} is", *_WRAP, *b.decl, "begin", *b.stmt,
            "end architecture rtl;", ""]
    return "\n".join(out)


def vhdl_pipelined_module(design: HornerDesign, *, version: str = "",
                          command: str | None = None, budget=None) -> str:
    """The pipelined VHDL evaluator ``chebnorm_NAME_pipe``: the datapath of
    :func:`vhdl_module` with one register stage after each Horner step, as
    :func:`~chebnorm.hw.hdl.verilog.verilog_pipelined_module` (latency ``degree``).

    Parameters
    ----------
    design : HornerDesign
        The Horner evaluator (:func:`~chebnorm.hw.horner.design_horner`).
    version : str, default ""
        chebnorm's version, stated in the banner (made comment-safe).
    command : str or None, default None
        The command line that made the file, stated in the banner (made comment-safe);
        None or empty: no such line.
    budget : ErrorBudget or None, default None
        A Horner design's certified budget (:func:`~chebnorm.hw.budget.error_budget`),
        stated in the banner; None: not stated. A piecewise design states its own.

    Returns
    -------
    str
        The VHDL-2008 text of ``chebnorm_NAME_pipe``, banner first.

    Raises
    ------
    ValueError
        If the design has degree 0 (nothing to pipeline).
    ValueError
        If the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> v = vhdl_pipelined_module(d)
    >>> [line.strip() for line in v.splitlines() if line.startswith("entity")]
    ['entity chebnorm_dichotomy_d1_pipe is']
    """
    n = design.degree
    if n < 1:
        raise ValueError(f"design {design.name!r} has degree 0: nothing to pipeline; accepted: "
                         f"degree >= 1")
    name = pipelined_name(design)
    xf = design.x_format
    out = comment_lines(horner_facts(design, "vhdl", version=version, command=command,
                                     budget=budget, pipelined=True), "vhdl")
    out += _entity(name, design, clocked=True)
    b = _Body()
    xw = design.xs_bits
    b.decl.append(_const("K0", xf.offset_code, xw))
    b.wire("xs0", xw, f"wrap(signed('0' & x), {xw}) + K0")
    _variable(b, design, "xs0", "v0")
    square = design.scheme != "monomial"
    n = len(design.horner_integers) - 1
    aw = max(design.stages[0].acc_bits, 2)
    b.decl.append(_const(f"A{n}", design.horner_integers[n], aw))
    prev = f"A{n}"
    regs = []
    for s, st in enumerate(design.stages):
        j = st.power
        _step(b, design, st, prev, f"{variable_name(design, st)}{s}")
        if j > 0:
            b.decl.append(_sig(f"a{j}_r", st.out_bits))
            b.decl.append(_sig(f"xs{s + 1}", xw))
            regs += [f"            a{j}_r <= a{j};", f"            xs{s + 1} <= xs{s};"]
            if square:
                b.decl.append(_sig(f"v{s + 1}", design.variable_bits))
                regs.append(f"            v{s + 1} <= v{s};")
            prev = f"a{j}_r"
    top_bits, top_frac = design.stages[-1].sum_bits, design.stages[-1].sum_frac_bits
    b.decl.append(_sig("top", top_bits))
    regs.append("            top <= t0;")
    b.stmt += ["    regs : process (clk)", "    begin", "        if rising_edge(clk) then",
               *regs, "        end if;", "    end process regs;"]
    _output(b, "top", top_bits, top_frac, design.y_format, design.out_bits, design.rounding,
            design.raw_bits)
    out += [f"architecture rtl of {name} is", *_WRAP, *b.decl, "begin", *b.stmt,
            "end architecture rtl;", ""]
    return "\n".join(out)


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


def _bench(design, name: str, vectors: str | None, clocked: bool,
           latency: int | None = None) -> str:
    vectors = vectors_name(name, vectors)
    count = 2 ** design.in_bits
    n = getattr(design, "steps", design.degree) if latency is None else latency
    digits = (design.out_bits + 3) // 4
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
        f"    constant IN_BITS  : natural := {design.in_bits};",
        f"    constant OUT_BITS : natural := {design.out_bits};",
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


def vhdl_testbench(design: HornerDesign, vectors: str | None = None) -> str:
    """Exhaustive self-checking bench of :func:`vhdl_module` (every input code).

    Parameters
    ----------
    design : HornerDesign
        The Horner evaluator (:func:`~chebnorm.hw.horner.design_horner`).
    vectors : str or None, default None
        The vector file the bench reads: an identifier, optionally with ``.hex``; None:
        ``NAME.hex``.

    Returns
    -------
    str
        The VHDL-2008 bench text.

    Raises
    ------
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> tb = vhdl_testbench(d)
    >>> "chebnorm_dichotomy_d1.hex" in tb, "chebnorm_dichotomy_d1_vhdl_y.hex" in tb
    (True, True)
    """
    name = design.module_name
    return _bench(design, name, vectors, clocked=False)


def vhdl_pipelined_testbench(design: HornerDesign, vectors: str | None = None) -> str:
    """Exhaustive bench of the pipelined entity: one code per cycle, the output
    after edge ``i`` checked against code ``i - LATENCY + 1``.

    Parameters
    ----------
    design : HornerDesign
        The Horner evaluator (:func:`~chebnorm.hw.horner.design_horner`).
    vectors : str or None, default None
        The vector file the bench reads: an identifier, optionally with ``.hex``; None:
        ``NAME.hex``.

    Returns
    -------
    str
        The VHDL-2008 bench text.

    Raises
    ------
    ValueError
        If the design has degree 0 (nothing to pipeline).
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> [line.strip() for line in vhdl_pipelined_testbench(d).splitlines() if "LATENCY" in line][:1]
    ['constant LATENCY  : natural := 1;']
    """
    name = pipelined_name(design)
    return _bench(design, name, vectors, clocked=True)


# -- piecewise evaluator -------------------------------------------------------------

def _piecewise_rom(b: _Body, d) -> None:
    """The coefficient ROM: ``c_j`` of the segment the top bits of ``x`` index
    (one constant array per power; one segment: the constants themselves)."""
    t = d.table
    n, K, L = t.degree, d.index_bits, d.local_bits
    if K == 0:  # one segment: constants, as the Verilog
        for j in range(n + 1):
            b.wire(f"c{j}", d.rom_bits[j], _bits(t.segments[0].integers[j], d.rom_bits[j]))
        return
    b.wire("idx", K, f"signed(x({d.in_bits - 1} downto {L}))")
    for j in range(n + 1):
        w = d.rom_bits[j]
        b.decl.append(f"    type rom{j}_t is array (0 to {2 ** K - 1}) of signed({w - 1} downto 0);")
        rows = [f"        {_bits(seg.integers[j], w)}{',' if s < len(t.segments) - 1 else ''}"
                f"  -- segment {s}: {seg.integers[j]}" for s, seg in enumerate(t.segments)]
        b.decl += [f"    constant ROM{j} : rom{j}_t := (", *rows, "    );"]
        b.wire(f"c{j}", w, f"ROM{j}(to_integer(unsigned(idx)))")


def piecewise_vhdl(d, *, version: str = "", command: str | None = None) -> str:
    """The VHDL-2008 entity of a piecewise design ``d``
    (:class:`~chebnorm.hw.piecewise.PiecewiseDesign`): the coefficient ROM
    indexed by the top bits of ``x`` and the Horner datapath in the local
    variable, bit for bit the module of
    :func:`~chebnorm.hw.hdl.verilog.piecewise_verilog` (the same wire widths;
    every width change through ``wrap``, as a Verilog assignment).

    Parameters
    ----------
    d : PiecewiseDesign
        The piecewise design (:func:`~chebnorm.hw.piecewise.design_piecewise`); a sized
        one (``d.sized``) is printed by :func:`sized_piecewise_vhdl`.
    version : str, default ""
        chebnorm's version, stated in the banner (made comment-safe).
    command : str or None, default None
        The command line that made the file, stated in the banner (made comment-safe);
        None or empty: no such line.

    Returns
    -------
    str
        The VHDL-2008 text, banner first.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> v = piecewise_vhdl(design_piecewise(t, 8, 8))
    >>> v.count("-- segment "), "entity chebnorm_rs is" in v   # one ROM row per segment and power
    (8, True)
    """
    if d.sized:
        return sized_piecewise_vhdl(d, version=version, command=command)
    t = d.table
    n, L, fc = t.degree, d.local_bits, t.coef_frac_bits
    name = module_name(d)
    out = comment_lines(piecewise_facts(d, version=version, command=command), "vhdl")
    out += _entity(name, d, clocked=False)
    b = _Body()
    tw = d.t_bits
    low = f"signed(\"00\" & x({L - 1} downto 0))"
    if t.centered:
        b.decl.append(_const("TC", 1 << (L - 1), tw))
        b.wire("t", tw, f"{low} - TC")
    else:
        b.wire("t", tw, low)
    _piecewise_rom(b, d)
    prev, prev_frac = f"c{n}", fc
    for i, j in enumerate(range(n - 1, -1, -1)):
        pw, sw, ow = d.widths[i]
        pf = prev_frac + L
        sf = max(pf, fc)
        b.stmt.append(f"    -- step {j}: a{j} = R(a{j + 1} * t + c{j}), {sf} fractional bits")
        b.wire(f"p{j}", pw, f"wrap({prev} * t, {pw})")
        # the Verilog sum, taken mod 2^sw: the same bits as in its wider context
        terms = [f"shift_left(wrap({v}, {sw}), {sh})" if sh else f"wrap({v}, {sw})"
                 for v, sh in ((f"p{j}", sf - pf), (f"c{j}", sf - fc))]
        b.wire(f"s{j}", sw, " + ".join(terms))
        if j > 0:
            f_out = min(d.acc_frac_bits, sf)
            if sf > f_out:
                _round(b, f"s{j}", f"a{j}", sw, sf - f_out, ow, d.rounding)
            else:
                b.wire(f"a{j}", ow, f"wrap(s{j}, {ow})")
            prev, prev_frac = f"a{j}", f_out
        else:
            prev, prev_frac = f"s{j}", sf
    top_bits = d.widths[-1][1] if n > 0 else d.rom_bits[0]
    _output(b, prev, top_bits, prev_frac, d.y_format, d.out_bits, d.rounding)
    out += [f"architecture rtl of {name} is", *_WRAP, *b.decl, "begin", *b.stmt,
            "end architecture rtl;", ""]
    return "\n".join(out)


def piecewise_vhdl_testbench(d, vectors: str | None = None) -> str:
    """Exhaustive self-checking bench of :func:`piecewise_vhdl` (every input
    code against the model's ``NAME.hex``, as the Verilog bench).

    Parameters
    ----------
    d : PiecewiseDesign
        The piecewise design (:func:`~chebnorm.hw.piecewise.design_piecewise`).
    vectors : str or None, default None
        The vector file the bench reads: an identifier, optionally with ``.hex``; None:
        ``NAME.hex``.

    Returns
    -------
    str
        The VHDL bench text.

    Raises
    ------
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> piecewise_vhdl_testbench(design_piecewise(t, 8, 8)).splitlines()[0]
    '-- tb_chebnorm_rs: exhaustive self-checking test bench of chebnorm_rs.'
    """
    return _bench(d, module_name(d), vectors, clocked=False)


def sized_piecewise_vhdl(d, *, version: str = "", command: str | None = None) -> str:
    """The VHDL-2008 entity of a sized piecewise design ``d`` (``d.sized``),
    bit for bit :func:`~chebnorm.hw.hdl.verilog.sized_piecewise_verilog`
    (the same wire widths, the same cut registers; every width change
    through ``wrap``).

    Parameters
    ----------
    d : PiecewiseDesign
        A sized piecewise design (``design_piecewise(..., widths="auto")``, ``d.sized``).
    version : str, default ""
        chebnorm's version, stated in the banner (made comment-safe).
    command : str or None, default None
        The command line that made the file, stated in the banner (made comment-safe);
        None or empty: no such line.

    Returns
    -------
    str
        The VHDL-2008 text, banner first.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 2, segments=4, coef_frac_bits=16, name="rs")
    >>> v = sized_piecewise_vhdl(design_piecewise(t, 8, 8, widths="auto", max_error=2 ** -5, pipeline=(0, 2)))
    >>> v.count("rising_edge(clk)"), "LATENCY  : natural := 2" in v
    (2, True)
    """
    t = d.table
    n, L, K = t.degree, d.local_bits, d.index_bits
    name = module_name(d)
    out = comment_lines(piecewise_facts(d, version=version, command=command), "vhdl")
    out += _entity(name, d, clocked=d.latency > 0)
    b = _Body()
    b.decl.append(f"    signal low : std_logic_vector({L - 1} downto 0);")
    b.stmt.append(f"    low <= x({L - 1} downto 0);")
    if K == 0:
        for j in range(n + 1):
            b.wire(f"c{j}", d.rom_bits[j], _bits(d.coefficients[0][j], d.rom_bits[j]))
    else:
        b.decl.append(f"    signal idx : unsigned({K - 1} downto 0);")
        b.stmt.append(f"    idx <= unsigned(x({d.in_bits - 1} downto {L}));")
        for j in range(n + 1):
            w = d.rom_bits[j]
            b.decl.append(f"    type rom{j}_t is array (0 to {2 ** K - 1}) of signed({w - 1} downto 0);")
            rows = [f"        {_bits(row[j], w)}{',' if s < len(d.coefficients) - 1 else ''}"
                    f"  -- segment {s}: {row[j]}" for s, row in enumerate(d.coefficients)]
            b.decl += [f"    constant ROM{j} : rom{j}_t := (", *rows, "    );"]
            b.wire(f"c{j}", w, f"ROM{j}(to_integer(idx))")
    live = {"low": (L, False), **{f"c{j}": (d.rom_bits[j], True) for j in range(n + 1)}}
    cur = {k: k for k in live}
    acc, accw = f"c{n}", d.rom_bits[n]

    def cut(stage) -> None:
        regs = []
        for key, (w, sgn) in live.items():
            r = f"{key}_r{stage}"
            typ = f"signed({w - 1} downto 0)" if sgn else f"std_logic_vector({w - 1} downto 0)"
            b.decl.append(f"    signal {r} : {typ};")
            regs.append(f"            {r} <= {cur[key]};")
            cur[key] = r
        b.stmt.extend(["    process (clk)", "    begin", "        if rising_edge(clk) then", *regs,
                       "        end if;", "    end process;"])

    if 0 in d.cuts:
        cut(0)
    for i, st in enumerate(d.sized_signals(), start=1):
        j, T, tw = st["j"], st["T"], st["tw"]
        lo = cur["low"]
        b.stmt.append(f"    -- step {j}: a{j} = (((a{j + 1} * t{j}) >> {st['pshift']}) << {st['qshift']}"
                      f" + c{j} << {st['cshift']}) >> {st['ashift']}, t{j} = top {T} bits of t"
                      + (", truncated multiplier" if st["rows"] else ""))
        if t.centered:
            rest = f" & {lo}({L - 2} downto {L - T})" if T > 1 else ""
            b.wire(f"t{j}", tw, f"signed(not {lo}({L - 1} downto {L - 1}){rest})")
        else:
            b.wire(f"t{j}", tw, f"signed(\"0\" & {lo}({L - 1} downto {L - T}))")
        pw, qw, sw, aw = st["pw"], st["qw"], st["sw"], st["aw"]
        ps = st["pshift"]
        if not st["rows"]:
            b.wire(f"p{j}", pw, f"wrap({cur[acc]} * t{j}, {pw})")
        if st["rows"]:
            _truncated_rows(b, st, cur[acc], accw, lo)
        elif ps > 0:
            b.wire(f"q{j}", qw, f"wrap(shift_right(p{j}, {ps}), {qw})")
        elif ps < 0:
            b.wire(f"q{j}", qw, f"shift_left(wrap(p{j}, {qw}), {-ps})")
        else:
            b.wire(f"q{j}", qw, f"wrap(p{j}, {qw})")
        q = f"q{j}"
        if i in getattr(d, "mult_cuts", ()):  # a register between the multiply and the add
            live.pop(acc, None)
            cur.pop(acc, None)
            if j == 0:
                live.pop("low", None)
            live[q], cur[q] = (qw, True), q
            cut(f"m{i}")
            q = cur.pop(q)
            del live[f"q{j}"]
        ctx = max(qw, sw, d.rom_bits[j])
        c = f"wrap({cur[f'c{j}']}, {ctx})"
        c = f"shift_left({c}, {st['cshift']})" if st["cshift"] else c
        qv = f"wrap({q}, {ctx})"
        qv = f"shift_left({qv}, {st['qshift']})" if st["qshift"] else qv
        b.wire(f"s{j}", sw, f"wrap({qv} + {c}, {sw})")
        a_expr = f"shift_right(s{j}, {st['ashift']})" if st["ashift"] else f"s{j}"
        b.wire(f"a{j}", aw, f"wrap({a_expr}, {aw})")
        del live[f"c{j}"], cur[f"c{j}"]
        live.pop(acc, None)
        cur.pop(acc, None)
        acc, accw = f"a{j}", aw
        live[acc], cur[acc] = (aw, True), acc
        if j == 0:
            live.pop("low", None)
        if i in d.cuts:
            cut(i)
    top_bits = d.widths[-1][2] if n > 0 else d.rom_bits[0]
    if n == 0:
        f0, g0 = d.coef_frac[0], d.acc_frac[0]
        top_bits = d.rom_bits[0] + max(0, g0 - f0)
        src = f"wrap({cur['c0']}, {top_bits})"
        expr = (f"shift_right({src}, {f0 - g0})" if f0 > g0 else
                f"shift_left({src}, {g0 - f0})" if g0 > f0 else src)
        b.wire("a0", top_bits, expr)
        cur["a0"] = acc = "a0"
    _output(b, cur[acc], top_bits, d.y_format.frac_bits, d.y_format, d.out_bits, "trunc")
    out += [f"architecture rtl of {name} is", *_WRAP, *b.decl, "begin", *b.stmt,
            "end architecture rtl;", ""]
    return "\n".join(out)


def _truncated_rows(b: _Body, st: dict, a: str, aw: int, low: str) -> None:
    """The truncated multiplier ``q_j``, as the Verilog printer writes it: one
    row per bit of ``t_j``'s code, floored at column ``P``, gated, summed
    modulo ``2^qw``."""
    j, qw = st["j"], st["qw"]
    if any(neg for _, _, neg in st["rows"]):
        b.wire(f"na{j}", aw + 1, f"-wrap({a}, {aw + 1})")
    terms = []
    for i, sh, neg in st["rows"]:
        src = f"na{j}" if neg else a
        sw = max(aw + 1 if neg else aw, qw)
        if sh > 0:
            expr = f"wrap(shift_right(wrap({src}, {sw}), {sh}), {qw})"
        elif sh < 0:
            expr = f"shift_left(wrap({src}, {qw}), {-sh})"
        else:
            expr = f"wrap({src}, {qw})"
        b.wire(f"r{j}_{i}", qw, expr)
        bit = f"{low}({st['tshift'] + i})"
        on = "'0'" if neg else "'1'"
        b.wire(f"m{j}_{i}", qw, f"r{j}_{i} when {bit} = {on} else (others => '0')")
        terms.append(f"m{j}_{i}")
    b.wire(f"q{j}", qw, " + ".join(terms))


def piecewise_vhdl_clocked_testbench(d, vectors: str | None = None) -> str:
    """Exhaustive bench of a pipelined piecewise entity (``d.latency > 0``):
    one code per cycle, the output after edge ``i`` checked against code
    ``i - LATENCY + 1``.

    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> d = design_piecewise(t, 8, 8, widths="auto", max_error=2 ** -5, pipeline="full")
    >>> [ln.strip() for ln in piecewise_vhdl_clocked_testbench(d).splitlines() if "LATENCY  :" in ln]
    ['constant LATENCY  : natural := 2;']

    Parameters
    ----------
    d : PiecewiseDesign
        A sized piecewise design with pipeline cuts (``d.latency > 0``).
    vectors : str or None, default None
        The vector file the bench reads: an identifier, optionally with ``.hex``; None:
        ``NAME.hex``.

    Returns
    -------
    str
        The VHDL bench text.

    Raises
    ------
    ValueError
        If ``vectors`` (without ``.hex``) or the design's name is not a safe identifier.
    """
    return _bench(d, module_name(d), vectors, clocked=True, latency=d.latency)
