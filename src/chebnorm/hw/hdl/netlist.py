"""One netlist IR of a fixed-point datapath, and its two printers: Verilog-2005
(:func:`verilog`) and VHDL-2008 (:func:`vhdl`).

A :class:`Module` holds typed :class:`Signal` s and statements
(:class:`Assign`, :class:`ConstDecl`, :class:`Rom`, :class:`Registers`,
:class:`Saturate`, :class:`Comment`) over expression nodes (:class:`Const`,
:class:`Slice`, :class:`Bit`, :class:`Concat`, :class:`Not`, :class:`ZeroExt`,
:class:`Resize`, :class:`Extend`, :class:`Shl`, :class:`Shr`, :class:`Neg`,
:class:`Add`, :class:`Sub`, :class:`Mul`, :class:`Gate`, :class:`And`,
:class:`Or`, :class:`ReduceOr`, :class:`Group`, :class:`Paren`, and the
comparison :class:`Compare` and multiplexer :class:`Select` an assignment
takes whole). The logic is
held once; each language is a table of templates, one per node kind
(:data:`_VERILOG`, :data:`_VHDL`), as :mod:`chebnorm.export.shader` prints
GLSL, WGSL and HLSL from one table.

Every width change is explicit in the IR (:class:`Resize`: Verilog's
assignment semantics, sign-extend or keep the low bits): the Verilog printer
leaves it to the assignment context, the VHDL printer writes it as the
``wrap`` function. The nodes check their operands when built -- an
:class:`Add` of two widths, an :class:`Assign` of a 9-bit value to an 8-bit
signal, a signed/unsigned mix -- and refuse them naming the node, so a
printed module never relies on an implicit conversion the other language
lacks. :func:`evaluate` computes any signal of a combinational module from
its input code in Python (two's complement, the node semantics above).

>>> m = Module("chebnorm_neg", 4, 5, facts=["negate"])
>>> n = Signal("n", 5, signed=True)
>>> m.statements += [Assign(n, Neg(ZeroExt(m.x))), Output(n)]
>>> print(chr(10).join(verilog(m).splitlines()[-3:-1]))
    wire signed [4:0] n = -$signed({1'b0, x});
    assign y = n;
>>> print(chr(10).join(vhdl(m).splitlines()[-3:-1]))
    n <= -signed("0" & x);
    y <= std_logic_vector(n);
>>> evaluate(m, 3)["n"], evaluate(m, 3)["y"]
(-3, 29)
"""

from __future__ import annotations

from dataclasses import dataclass, field

from chebnorm.core.textsafe import identifier

from .common import comment_lines
from .._docfrag import hw_doc

# an implementation module of chebnorm.hw.hdl: the API is what chebnorm.hw.hdl exports
__all__: list[str] = []


def _refuse(what: str, detail: str) -> ValueError:
    return ValueError(f"{what}: {detail}")


def signed_literal(value: int, bits: int) -> str:
    """A sized signed Verilog decimal literal ``[-]BITS'sdMAGNITUDE``.

    >>> signed_literal(5, 4), signed_literal(-8, 4)
    ("4'sd5", "-4'sd8")

    Parameters
    ----------
    value : int
        The constant.
    bits : int
        The literal's width, ``>= 1``; ``value`` must lie in ``[-2**(bits-1), 2**(bits-1) - 1]``.

    Returns
    -------
    str
        The literal, e.g. ``"4'sd5"`` or ``"-4'sd8"``.

    Raises
    ------
    ValueError
        If ``value`` does not fit a signed ``bits``-bit word.
    """
    if not -(1 << (bits - 1)) <= value < (1 << (bits - 1)):
        raise ValueError(f"constant {value} does not fit a signed {bits}-bit literal")
    return f"{'-' if value < 0 else ''}{bits}'sd{abs(value)}"


def vhdl_bits(value: int, bits: int) -> str:
    """A VHDL ``signed`` bit-string literal of ``value`` in ``bits`` bits.

    >>> vhdl_bits(-3, 4)
    'signed\\'("1101")'

    Parameters
    ----------
    value : int
        The constant.
    bits : int
        The width, ``>= 1``; ``value`` must fit a signed ``bits``-bit word.

    Returns
    -------
    str
        ``signed'("...")`` with the two's complement bits.

    Raises
    ------
    ValueError
        If ``value`` does not fit a signed ``bits``-bit word.
    """
    if not -(1 << (bits - 1)) <= value < (1 << (bits - 1)):
        raise ValueError(f"constant {value} does not fit a signed {bits}-bit literal")
    return f'signed\'("{value & ((1 << bits) - 1):0{bits}b}")'


# -- signals and expressions -----------------------------------------------------------

@dataclass(frozen=True)
class Signal:
    """A named wire (register) of ``width`` bits.

    Parameters
    ----------
    name : str
        The identifier.
    width : int
        Bits, ``>= 1``.
    signed : bool, default False
        Two's complement (Verilog ``signed``, VHDL ``signed``); else unsigned.
    logic : bool, default False
        A plain bit vector (VHDL ``std_logic_vector``); unsigned in arithmetic. Not
        with ``signed``.
    scalar : bool, default False
        One bit, not a vector (VHDL ``std_logic``, a Verilog ``wire`` without range);
        ``width`` 1, ``logic``.
    """

    name: str
    width: int
    signed: bool = False
    logic: bool = False
    scalar: bool = False

    def __post_init__(self):
        if not isinstance(self.width, int) or self.width < 1:
            raise _refuse(f"signal {self.name!r}", f"width {self.width!r}; accepted: an integer >= 1")
        if self.signed and self.logic:
            raise _refuse(f"signal {self.name!r}", "signed and logic; accepted: one of them")
        if self.scalar and (self.width != 1 or not self.logic):
            raise _refuse(f"signal {self.name!r}", "scalar; accepted: with width 1 and logic")


def _check_expr(e, what: str):
    if not isinstance(e, _EXPR):
        raise _refuse(what, f"operand {type(e).__name__}; accepted: a Signal or an expression node")
    return e


def _same(what: str, a, b) -> None:
    if a.width != b.width or a.signed != b.signed:
        raise _refuse(what, f"operands of {_kind(a)} and {_kind(b)}; accepted: one width and "
                            f"signedness (make the change explicit with Resize or ZeroExt)")


def _same_sign(what: str, a, b) -> None:
    if a.signed != b.signed:
        raise _refuse(what, f"operands of {_kind(a)} and {_kind(b)}; accepted: one signedness "
                            f"(make the change explicit with Resize or ZeroExt)")


def _kind(e) -> str:
    return f"{e.width} {'signed' if e.signed else 'unsigned'} bits"


class _OfA:
    """A node of its operand ``a``'s width and signedness (unless it says otherwise)."""

    @property
    def width(self) -> int:
        """The operand's width."""
        return self.a.width

    @property
    def signed(self) -> bool:
        """The operand's signedness."""
        return self.a.signed


@dataclass(frozen=True)
class Const:
    """A constant of ``width`` bits.

    Parameters
    ----------
    value : int
        The value; it must fit a ``width``-bit word.
    width : int
        Bits.
    signed : bool, default True
        Two's complement; unsigned constants print as a VHDL integer literal (an
        operand of ``unsigned`` arithmetic only).
    """

    value: int
    width: int
    signed: bool = True

    def __post_init__(self):
        lo, hi = ((-(1 << (self.width - 1)), 1 << (self.width - 1)) if self.signed
                  else (0, 1 << self.width))
        if not lo <= self.value < hi:
            raise _refuse("Const", f"{self.value} does not fit a"
                                   f"{' signed' if self.signed else 'n unsigned'} "
                                   f"{self.width}-bit word")


@dataclass(frozen=True)
class Slice:
    """Bits ``hi`` down to ``lo`` of a signal, unsigned.

    Parameters
    ----------
    src : Signal
        The signal.
    hi, lo : int
        The bit range, ``src.width > hi >= lo >= 0``.
    """

    src: Signal
    hi: int
    lo: int
    signed = False

    def __post_init__(self):
        if not (isinstance(self.src, Signal) and self.src.width > self.hi >= self.lo >= 0):
            raise _refuse("Slice", f"bits {self.hi}..{self.lo} of {self.src!r}; accepted: a "
                                   f"range inside the signal")

    @property
    def width(self) -> int:
        """Bits of the slice."""
        return self.hi - self.lo + 1


@dataclass(frozen=True)
class Bit:
    """Bit ``index`` of a signal (one unsigned bit).

    Parameters
    ----------
    src : Signal
        The signal.
    index : int
        The bit, ``0 <= index < src.width``.
    """

    src: Signal
    index: int
    width = 1
    signed = False

    def __post_init__(self):
        if not (isinstance(self.src, Signal) and 0 <= self.index < self.src.width):
            raise _refuse("Bit", f"bit {self.index} of {self.src!r}; accepted: a bit of the signal")


@dataclass(frozen=True)
class BitVec(Bit):
    """Bit ``index`` of a signal as a one-bit vector (VHDL ``s(i downto i)``).

    Parameters
    ----------
    src : Signal
        The signal.
    index : int
        The bit, ``0 <= index < src.width``.
    """


@dataclass(frozen=True)
class Concat:
    """Unsigned concatenation, most significant part first.

    Parameters
    ----------
    parts : tuple
        The unsigned expressions.
    """

    parts: tuple
    signed = False

    def __post_init__(self):
        for p in self.parts:
            _check_expr(p, "Concat")
            if p.signed:
                raise _refuse("Concat", f"a part of {_kind(p)}; accepted: unsigned parts")

    @property
    def width(self) -> int:
        """Sum of the parts' widths."""
        return sum(p.width for p in self.parts)


@dataclass(frozen=True)
class Not(_OfA):
    """Bitwise complement of an unsigned expression.

    Parameters
    ----------
    a : expression
        The operand (unsigned).
    """

    a: object
    signed = False

    def __post_init__(self):
        if _check_expr(self.a, "Not").signed:
            raise _refuse("Not", f"operand of {_kind(self.a)}; accepted: unsigned")



@dataclass(frozen=True)
class ZeroExt:
    """An unsigned expression made signed by zero bits on top (one by default).

    Parameters
    ----------
    a : expression
        The unsigned operand.
    qualified : bool, default False
        VHDL spelling ``signed'(...)`` (a qualified expression) instead of ``signed(...)``.
    char : bool, default False
        VHDL spelling of the zero bit as ``'0'`` instead of ``"0"``.
    zeros : {1, 2}, default 1
        The zero bits put on top.
    """

    a: object
    qualified: bool = False
    char: bool = False
    zeros: int = 1
    signed = True

    def __post_init__(self):
        if _check_expr(self.a, "ZeroExt").signed:
            raise _refuse("ZeroExt", f"operand of {_kind(self.a)}; accepted: unsigned")
        if self.zeros not in (1, 2) or (self.char and self.zeros != 1):
            raise _refuse("ZeroExt", f"zeros {self.zeros!r}; accepted: 1 or 2 (1 with char)")

    @property
    def width(self) -> int:
        """The operand's width plus the zero bits."""
        return self.a.width + self.zeros


@dataclass(frozen=True)
class Resize:
    """The operand at ``width`` bits as a Verilog assignment does it:
    sign-extended (zero-extended when unsigned) or its low bits kept
    (VHDL: ``wrap``).

    Parameters
    ----------
    a : expression
        The operand.
    width : int
        The new width, ``>= 1``.
    signed : bool or None, default None
        The result's signedness (None: the operand's); a change reinterprets the bits.
    """

    a: object
    width: int
    signed: bool | None = None

    def __post_init__(self):
        _check_expr(self.a, "Resize")
        if self.signed is None:
            object.__setattr__(self, "signed", self.a.signed)
        if not isinstance(self.width, int) or self.width < 1:
            raise _refuse("Resize", f"width {self.width!r}; accepted: an integer >= 1")
        if self.signed != self.a.signed and self.width != self.a.width:
            raise _refuse("Resize", "a change of width and signedness at once; accepted: one")


@dataclass(frozen=True)
class Extend:
    """An operand extended (sign-extended when signed) to ``width`` bits,
    never narrower (VHDL: ``resize``).

    Parameters
    ----------
    a : expression
        The operand.
    width : int
        The new width, ``>= a.width``.
    """

    a: object
    width: int

    def __post_init__(self):
        _check_expr(self.a, "Extend")
        if self.width < self.a.width or _is_logic(self.a):
            raise _refuse("Extend", f"{_kind(self.a)} to {self.width}; accepted: a number, "
                                    f"a width at least its own")

    signed = _OfA.signed



@dataclass(frozen=True)
class Shl(_OfA):
    """Left shift by ``k`` bits within the operand's width (bits shifted out are lost).

    Parameters
    ----------
    a : expression
        The operand.
    k : int
        Bits, ``>= 0``.
    """

    a: object
    k: int

    def __post_init__(self):
        _check_expr(self.a, "Shl")
        if not isinstance(self.k, int) or self.k < 0:
            raise _refuse(type(self).__name__, f"shift {self.k!r}; accepted: an integer >= 0")




@dataclass(frozen=True)
class Shr(Shl):
    """Right shift by ``k`` bits: arithmetic (floor) for a signed operand.

    Parameters
    ----------
    a : expression
        The operand.
    k : int
        Bits, ``>= 0``.
    """


@dataclass(frozen=True)
class Flip(_OfA):
    """An unsigned vector with every bit XORed with one bit, or with its
    complement (``invert``): a symmetric table's folding.

    Parameters
    ----------
    a : expression
        The unsigned vector.
    bit : Bit
        The bit.
    invert : bool, default True
        XOR with the complement of ``bit``.
    """

    a: object
    bit: object
    invert: bool = True

    def __post_init__(self):
        if _check_expr(self.a, "Flip").signed or not isinstance(self.bit, Bit):
            raise _refuse("Flip", "accepted: an unsigned vector and a Bit")


    @property
    def signed(self) -> bool:
        """Unsigned."""
        return False


@dataclass(frozen=True)
class Pad:
    """An unsigned value zero-extended to ``width`` bits.

    Parameters
    ----------
    a : expression
        The unsigned value.
    width : int
        The new width, ``>= a.width``.
    """

    a: object
    width: int
    signed = False

    def __post_init__(self):
        if _check_expr(self.a, "Pad").signed or self.width < self.a.width:
            raise _refuse("Pad", f"{_kind(self.a)} to {self.width}; accepted: unsigned, a "
                                 f"width at least its own")


@dataclass(frozen=True)
class ShiftBy(_OfA):
    """A bit vector shifted left by a variable amount (zeros in).

    Parameters
    ----------
    a : Signal
        The bit vector (a ``logic`` signal).
    amount : Signal
        The unsigned shift amount.
    """

    a: object
    amount: object
    signed = False

    def __post_init__(self):
        if not (isinstance(self.a, Signal) and self.a.logic and isinstance(self.amount, Signal)
                and not self.amount.signed and not self.amount.logic):
            raise _refuse("ShiftBy", "accepted: a logic Signal shifted by an unsigned Signal")



@dataclass(frozen=True)
class Neg(_OfA):
    """Two's complement negation of a signed operand (modulo its width).

    Parameters
    ----------
    a : expression
        The signed operand.
    """

    a: object
    signed = True

    def __post_init__(self):
        if not _check_expr(self.a, "Neg").signed:
            raise _refuse("Neg", f"operand of {_kind(self.a)}; accepted: signed")



@dataclass(frozen=True)
class Add:
    """Sum of terms of one signedness at the widest term's width (narrower
    terms extended, as both languages do), modulo that width.

    Parameters
    ----------
    terms : tuple
        Two or more expressions.
    """

    terms: tuple

    def __post_init__(self):
        if len(self.terms) < 2:
            raise _refuse("Add", f"{len(self.terms)} term(s); accepted: two or more")
        for t in self.terms:
            _same_sign("Add", self.terms[0], _check_expr(t, "Add"))

    @property
    def width(self) -> int:
        """The widest term's width."""
        return max(t.width for t in self.terms)

    @property
    def signed(self) -> bool:
        """The terms' signedness."""
        return self.terms[0].signed


@dataclass(frozen=True)
class Sub:
    """``a - b``, one signedness, at the wider operand's width (modulo it).

    Parameters
    ----------
    a, b : expression
        The operands.
    """

    a: object
    b: object

    def __post_init__(self):
        _same_sign("Sub", _check_expr(self.a, "Sub"), _check_expr(self.b, "Sub"))

    @property
    def width(self) -> int:
        """The wider operand's width."""
        return max(self.a.width, self.b.width)

    @property
    def signed(self) -> bool:
        """The operands' signedness."""
        return self.a.signed


@dataclass(frozen=True)
class Mul:
    """The exact product of two signed operands, ``a.width + b.width`` bits
    (wrap it with :class:`Resize` to keep fewer).

    Parameters
    ----------
    a, b : expression
        The signed operands.
    """

    a: object
    b: object
    signed = True

    def __post_init__(self):
        for e in (self.a, self.b):
            if not _check_expr(e, "Mul").signed:
                raise _refuse("Mul", f"operand of {_kind(e)}; accepted: signed operands")

    @property
    def width(self) -> int:
        """Sum of the operands' widths."""
        return self.a.width + self.b.width


@dataclass(frozen=True)
class Gate(_OfA):
    """``a`` where bit ``bit`` equals ``on``, else zero (a row of a truncated
    multiplier: an AND with the bit repeated).

    Parameters
    ----------
    a : Signal
        The gated signal.
    bit : Bit
        The control bit.
    on : bool, default True
        The bit value that passes ``a``.
    """

    a: object
    bit: object
    on: bool = True

    def __post_init__(self):
        if not isinstance(self.a, Signal) or not isinstance(self.bit, Bit):
            raise _refuse("Gate", "accepted: a Signal gated by a Bit")




@dataclass(frozen=True)
class And:
    """Logical AND of two one-bit operands.

    Parameters
    ----------
    a, b : expression
        One-bit unsigned operands.
    """

    a: object
    b: object
    width = 1
    signed = False

    def __post_init__(self):
        for e in (self.a, self.b):
            if _check_expr(e, type(self).__name__).width != 1 or e.signed:
                raise _refuse(type(self).__name__, f"operand of {_kind(e)}; accepted: one bit")


@dataclass(frozen=True)
class Or(And):
    """Logical OR of two one-bit operands.

    Parameters
    ----------
    a, b : expression
        One-bit unsigned operands.
    """


@dataclass(frozen=True)
class ReduceOr:
    """OR of all the bits of a slice (one bit).

    Parameters
    ----------
    a : Slice
        The bits.
    """

    a: object
    width = 1
    signed = False

    def __post_init__(self):
        if not isinstance(self.a, Slice):
            raise _refuse("ReduceOr", "accepted: a Slice")


@dataclass(frozen=True)
class Group(_OfA):
    """Parentheses the Verilog text has (and the VHDL text has not): no
    change of value.

    Parameters
    ----------
    a : expression
        The operand.
    """

    a: object

    def __post_init__(self):
        _check_expr(self.a, type(self).__name__)




@dataclass(frozen=True)
class Paren(Group):
    """Parentheses in both languages: no change of value.

    Parameters
    ----------
    a : expression
        The operand.
    """


#: the comparison operators of :class:`Compare` and their Python meaning
COMPARE_OPS = {"<": int.__lt__, "<=": int.__le__, ">": int.__gt__, ">=": int.__ge__,
               "==": int.__eq__, "!=": int.__ne__}


@dataclass(frozen=True)
class Compare:
    """``a OP b`` (one bit): operands of one width and signedness, compared
    as numbers (signed or unsigned); the condition of a :class:`Select`, or
    the whole value of an :class:`Assign` to a one-bit ``scalar`` signal.

    Parameters
    ----------
    op : {"<", "<=", ">", ">=", "==", "!="}
        The comparison.
    a, b : expression
        The operands (numbers: neither a bit vector).
    """

    op: str
    a: object
    b: object
    width = 1
    signed = False

    def __post_init__(self):
        if self.op not in COMPARE_OPS:
            raise _refuse("Compare", f"operator {self.op!r}; accepted: {', '.join(COMPARE_OPS)}")
        for e in (self.a, self.b):
            if _is_logic(_check_expr(e, "Compare")):
                raise _refuse("Compare", f"a bit vector {type(e).__name__} operand; accepted: "
                                         f"numbers (assign the vector to a signal first)")
        _same("Compare", self.a, self.b)


@dataclass(frozen=True)
class Select:
    """``a`` when ``cond`` holds, else ``b`` (a multiplexer): the whole value
    of an :class:`Assign` (VHDL prints it as a conditional assignment); ``b``
    may be another Select (a chain).

    Parameters
    ----------
    cond : Compare or expression
        A :class:`Compare`, or a one-bit unsigned expression (true when 1).
    a, b : expression
        The operands, of one width and signedness.
    """

    cond: object
    a: object
    b: object

    def __post_init__(self):
        c = self.cond
        if not isinstance(c, Compare):
            if _check_expr(c, "Select").width != 1 or c.signed:
                raise _refuse("Select", f"condition of {_kind(c)}; accepted: a Compare or one "
                                        f"unsigned bit")
        for e in (self.a, self.b):
            if not isinstance(e, Select):
                _check_expr(e, "Select")
        _same("Select", self.a, self.b)

    @property
    def width(self) -> int:
        """The operands' width."""
        return self.a.width

    @property
    def signed(self) -> bool:
        """The operands' signedness."""
        return self.a.signed


_EXPR = (Signal, Const, Slice, Bit, Concat, Not, ZeroExt, Resize, Extend, Shl, ShiftBy, Flip, Pad,
         Neg, Add, Sub,
         Mul, Gate, And, ReduceOr, Group, Compare, Select)


# -- statements --------------------------------------------------------------------------

@dataclass(frozen=True)
class Assign:
    """``dst`` declared and driven by ``expr`` (a continuous assignment).

    Parameters
    ----------
    dst : Signal
        The driven signal.
    expr : expression
        Its value: the width and signedness of ``dst`` (a :class:`Const`, or a bit
        vector -- a slice or concatenation of a ``logic`` signal -- may drive a signal of
        its width of either signedness: VHDL converts it with ``signed()``/``unsigned()``).
    """

    dst: Signal
    expr: object

    def __post_init__(self):
        _check_expr(self.expr, f"Assign {self.dst.name}")
        if isinstance(self.expr, Compare) and not self.dst.scalar:
            raise _refuse(f"Assign {self.dst.name}", "a Compare to a vector; accepted: a scalar "
                                                     "one-bit signal")
        signed_ok = (self.expr.signed == self.dst.signed or isinstance(self.expr, Const)
                     or _is_logic(self.expr))   # a bit vector takes the signal's type
        if self.expr.width != self.dst.width or not signed_ok:
            raise _refuse(f"Assign {self.dst.name}",
                          f"a value of {_kind(self.expr)} to a signal of {_kind(self.dst)}; "
                          f"accepted: the signal's width and signedness (Resize, ZeroExt or "
                          f"Slice make a change explicit)")


@dataclass(frozen=True)
class ConstDecl:
    """A named signed constant (Verilog ``localparam``, VHDL ``constant``).

    Parameters
    ----------
    dst : Signal
        The constant's name and width (signed).
    value : int
        Its value.
    """

    dst: Signal
    value: int

    def __post_init__(self):
        Const(self.value, self.dst.width)


@dataclass(frozen=True)
class Rom:
    """Signed ROM columns read at one address: ``outputs[j] = rows[address][j]``.

    Parameters
    ----------
    address : Signal
        The unsigned address signal (declared by the ROM).
    address_expr : expression
        The address's value (unsigned, ``address.width`` bits).
    outputs : tuple of Signal
        One signed signal per column.
    rows : tuple of tuple of int
        ``2**address.width`` rows, one value per column.
    """

    address: Signal
    address_expr: object
    outputs: tuple
    rows: tuple

    def __post_init__(self):
        Assign(self.address, self.address_expr)
        if len(self.rows) != 2 ** self.address.width:
            raise _refuse("Rom", f"{len(self.rows)} rows for a {self.address.width}-bit "
                                 f"address; accepted: {2 ** self.address.width}")
        for row in self.rows:
            for q, o in zip(row, self.outputs, strict=True):
                Const(int(q), o.width)


@dataclass(frozen=True)
class Table:
    """An unsigned ROM of one column: ``dst = values[address]`` (0 past the
    last value).

    Parameters
    ----------
    dst : Signal
        The unsigned output.
    address : Signal
        The address (a bit vector).
    values : tuple of int
        The entries, at most ``2**address.width``, each fitting ``dst``.
    """

    dst: Signal
    address: Signal
    values: tuple

    def __post_init__(self):
        if self.dst.signed or len(self.values) > 2 ** self.address.width:
            raise _refuse("Table", f"{len(self.values)} values into {self.dst!r}; accepted: "
                                   f"an unsigned signal, at most 2^{self.address.width} values")
        for v in self.values:
            Const(int(v), self.dst.width, signed=False)


@dataclass(frozen=True)
class Registers:
    """A pipeline register stage: each ``dst`` takes its ``src`` at the
    rising edge of ``clk``.

    Parameters
    ----------
    pairs : tuple of (Signal, Signal)
        ``(register, source)``, one width and signedness each.
    label : str or None, default None
        The VHDL process label (None: an unlabelled process).
    declare : bool, default True
        Declare the registers here; False: a :class:`Declare` with ``reg`` did (a
        register read by the logic that feeds it, as a counter or an accumulator).
    """

    pairs: tuple
    label: str | None = None
    declare: bool = True

    def __post_init__(self):
        for dst, src in self.pairs:
            _same(f"Registers {dst.name}", dst, src)


@dataclass(frozen=True)
class Saturate:
    """``y = 0`` when ``raw`` is negative, all ones above ``ymax``, else
    ``raw``'s low ``OUT_BITS`` bits.

    Parameters
    ----------
    raw : Signal
        The signed value.
    ymax : Signal
        The signed constant (a :class:`ConstDecl`) of the largest code.
    port : Signal or None, default None
        The driven vector (None: the output port ``y``).
    width_name : str, default "OUT_BITS"
        The parameter (generic) that names its width.
    """

    raw: Signal
    ymax: Signal
    port: Signal | None = None
    width_name: str = "OUT_BITS"


@dataclass(frozen=True)
class Declare:
    """A signal declared here and driven by a later statement.

    Parameters
    ----------
    signal : Signal
        The signal.
    reg : bool, default False
        Driven by :class:`Registers` (with ``declare=False``): a Verilog ``reg``.
    """

    signal: Signal
    reg: bool = False


@dataclass(frozen=True)
class Param:
    """A named integer (Verilog ``localparam``, VHDL ``constant ... natural``).

    Parameters
    ----------
    name : str
        The identifier.
    value : int
        The value, ``>= 0``.
    """

    name: str
    value: int


@dataclass(frozen=True)
class LeadingZeros:
    """``dst`` = the number of leading zero bits of ``src`` (its width when
    ``src`` is zero).

    Parameters
    ----------
    dst : Signal
        The unsigned count (wide enough for ``src.width``).
    src : Signal
        The bit vector.
    index : str
        The loop variable's name (Verilog ``integer``).
    label : str
        The VHDL process label.
    """

    dst: Signal
    src: Signal
    index: str
    label: str

    def __post_init__(self):
        if self.dst.signed or self.dst.logic or self.src.width >= 1 << self.dst.width:
            raise _refuse("LeadingZeros", f"count {self.dst!r}; accepted: an unsigned signal "
                                          f"that holds {self.src.width}")


@dataclass(frozen=True)
class Output:
    """The output port ``y`` (or ``port``) driven by ``expr`` (``OUT_BITS`` wide).

    Parameters
    ----------
    expr : expression
        The value (its bits; the module checks its width).
    port : Signal or None, default None
        An output port of a module with a port list (:class:`Port`), of
        ``expr``'s width (None: ``y``).
    """

    expr: object
    port: Signal | None = None

    def __post_init__(self):
        if isinstance(_check_expr(self.expr, "Output"), (Select, Compare)):
            raise _refuse("Output", f"a {type(self.expr).__name__}; accepted: assign it to a "
                                    f"signal first")
        if self.port is not None and self.port.width != self.expr.width:
            raise _refuse(f"Output {self.port.name}", f"a value of {_kind(self.expr)} to a port "
                                                      f"of {_kind(self.port)}; accepted: the "
                                                      f"port's width")


@dataclass(frozen=True)
class Port:
    """A port of a module with its own port list (:attr:`Module.ports`).

    Parameters
    ----------
    signal : Signal
        The port: a ``logic`` bit vector (``scalar`` for one bit), as HDL ports are.
    output : bool, default False
        An output (driven by an :class:`Output` with ``port``); else an input.
    """

    signal: Signal
    output: bool = False

    def __post_init__(self):
        identifier(self.signal.name, field="port name")
        if not self.signal.logic:
            raise _refuse(f"Port {self.signal.name}", f"{_kind(self.signal)}; accepted: a logic "
                                                      f"bit vector (Signal(..., logic=True))")


@dataclass(frozen=True)
class Instance:
    """An instance ``label`` of module (entity) ``module``, its ports mapped by name.

    Parameters
    ----------
    module : str
        The instantiated module's name (an identifier).
    label : str
        The instance name (an identifier).
    connections : tuple of (str, str, int, expression)
        ``(port, "input" | "output", width, value)``: the port's name, direction
        and width, and the bit vector connected to it (a ``logic`` signal or a
        slice of one, of the port's width; an output's a signal or slice this
        module declares).
    """

    module: str
    label: str
    connections: tuple

    def __post_init__(self):
        identifier(self.module, field="instance module")
        identifier(self.label, field="instance label")
        names = set()
        for name, direction, width, value in self.connections:
            what = f"Instance {self.label} port {name}"
            identifier(name, field="port name")
            if name in names:
                raise _refuse(what, "connected twice; accepted: each port once")
            names.add(name)
            if direction not in ("input", "output"):
                raise _refuse(what, f"direction {direction!r}; accepted: 'input' or 'output'")
            if not isinstance(value, (Signal, Slice)) or not _is_logic(value):
                raise _refuse(what, f"{type(value).__name__}; accepted: a logic Signal or a "
                                    f"Slice of one")
            if value.width != width:
                raise _refuse(what, f"{value.width} bits connected to a {width}-bit port; "
                                    f"accepted: the port's width")


@dataclass(frozen=True)
class Comment:
    """A comment line; ``{shr}`` and ``{shl}`` in ``text`` become each
    language's shift operators.

    Parameters
    ----------
    text : str
        The comment (one line, made safe by the caller).
    """

    text: str


@dataclass
class Module:
    """A module: ports ``x`` (``in_bits``) and ``y`` (``out_bits``), ``clk``
    when ``latency > 0``, a banner and the statements.

    Parameters
    ----------
    name : str
        The module (entity) name.
    in_bits, out_bits : int
        Widths of ``x`` and ``y`` (the parameters/generics ``IN_BITS``, ``OUT_BITS``).
    facts : list of str or dict
        The banner lines, without comment marker; or language -> its banner lines.
    statements : list
        The statements, in order; :class:`Cut` markers place the pipeline registers
        (:func:`schedule`, when printed or evaluated).
    latency : int, default 0
        Pipeline latency in cycles: > 0 adds ``clk`` and ``LATENCY``.
    ports : tuple of Port, default ()
        A port list of its own in place of ``x``, ``y`` (and ``clk``), without
        parameters (generics): ``in_bits``, ``out_bits`` and ``latency`` are then
        not printed. Not :func:`evaluate` d.
    """

    name: str
    in_bits: int
    out_bits: int
    facts: list = field(default_factory=list)
    statements: list = field(default_factory=list)
    latency: int = 0
    ports: tuple = ()

    @property
    def x(self) -> Signal:
        """The input port as a signal (a bit vector)."""
        return Signal("x", self.in_bits, logic=True)


def rename(node, signals: dict):
    """``node`` (a statement or an expression, or a list of them) with every
    :class:`Signal` named in ``signals`` replaced by its value -- how a module
    is inlined into another: its ports become the host's signals.

    Parameters
    ----------
    node : object
        A netlist node, or a list or tuple of nodes.
    signals : dict of str to Signal
        Name -> the signal that takes its place (of the same width and type).

    Returns
    -------
    object
        The renamed copy.

    Raises
    ------
    ValueError
        If a replacement's width or signedness differs from the signal it replaces.
    """
    from dataclasses import fields, is_dataclass, replace

    if isinstance(node, (list, tuple)):
        return type(node)(rename(n, signals) for n in node)
    if isinstance(node, Signal):
        new = signals.get(node.name)
        if new is None:
            return node
        if (new.width, new.signed, new.logic) != (node.width, node.signed, node.logic):
            raise _refuse(f"rename {node.name}", f"{new!r} for {node!r}; accepted: the same "
                                                 f"width and type")
        return new
    if not is_dataclass(node):
        return node
    return replace(node, **{f.name: rename(getattr(node, f.name), signals)
                            for f in fields(node) if f.init})


@dataclass(frozen=True)
class Cut:
    """A pipeline cut, placed by :func:`schedule`: every signal defined
    before it and read after it is registered here (``NAME_rSTAGE``).

    Parameters
    ----------
    stage : int or str
        The stage's tag in the register names.
    label : str or None, default None
        The VHDL process label.
    """

    stage: object
    label: str | None = None


def _signals(node, out: list) -> list:
    """Every :class:`Signal` ``node`` reads or writes, in field order."""
    from dataclasses import fields, is_dataclass

    if isinstance(node, (list, tuple)):
        for n in node:
            _signals(n, out)
    elif isinstance(node, Signal):
        out.append(node)
    elif is_dataclass(node):
        for f in fields(node):
            _signals(getattr(node, f.name), out)
    return out


def _defines(s) -> list:
    if isinstance(s, (Assign, Table, LeadingZeros)):
        return [s.dst]
    if isinstance(s, Rom):
        return [s.address, *s.outputs]
    if isinstance(s, Registers):
        return [d for d, _ in s.pairs]
    if isinstance(s, Saturate) and s.port is not None:
        return [s.port]
    return []


def schedule(statements: list) -> list:
    """The statements with each :class:`Cut` replaced by a register stage of
    the signals live across it -- defined before it (not constants, not the
    ports) and read after it, in the order they were defined -- and every later
    read renamed to the register: the one place pipeline registers are placed.

    Parameters
    ----------
    statements : list
        Netlist statements with :class:`Cut` markers.

    Returns
    -------
    list
        The statements without markers (a cut with nothing live adds nothing).
    """
    if not any(isinstance(s, Cut) for s in statements):
        return list(statements)   # no cut: nothing registered, nothing renamed
    reads = []   # names read at or after each position
    later: set = set()
    for s in reversed(statements):
        if not isinstance(s, Cut):
            own = {d.name for d in _defines(s)}
            later = later | {x.name for x in _signals(s, []) if x.name not in own}
        reads.append(later)
    reads.reverse()
    current, out = {}, []   # name as written -> the signal that carries it now
    for k, s in enumerate(statements):
        if not isinstance(s, Cut):
            renamed = {n: c for n, c in current.items() if c.name != n}
            out.append(rename(s, renamed) if renamed else s)
            current.update({d.name: d for d in _defines(s)})
            continue
        after = reads[k + 1] if k + 1 < len(statements) else set()
        pairs = []
        for name, sig in current.items():
            if name in after:
                r = Signal(f"{name}_r{s.stage}", sig.width, sig.signed, sig.logic, sig.scalar)
                pairs.append((r, sig))
                current[name] = r
        if pairs:
            out.append(Registers(tuple(pairs), label=s.label))
    return out


# -- the printers: one template per node kind and language -----------------------------

def _vhdl_type(s: Signal) -> str:
    if s.logic:
        return "std_logic" if s.scalar else f"std_logic_vector({s.width - 1} downto 0)"
    return f"{'signed' if s.signed else 'unsigned'}({s.width - 1} downto 0)"


def _verilog_type(s: Signal, kind: str = "wire") -> str:
    if s.scalar:
        return kind
    return f"{kind} {'signed ' if s.signed else ''}[{s.width - 1}:0]"


def _v_gate(e, p):
    return f"{p(e.a)} & {{{e.width}{{{'' if e.on else '~'}{p(e.bit)}}}}}"


#: Verilog-2005 spelling of each node kind (the printer ``p`` prints the operands)
_VERILOG = {
    Signal: lambda e, p: e.name,
    Const: lambda e, p: (signed_literal(e.value, e.width) if e.signed
                         else f"{e.width}'d{e.value}"),
    Slice: lambda e, p: f"{e.src.name}[{e.hi}:{e.lo}]",
    Bit: lambda e, p: f"{e.src.name}[{e.index}]",
    BitVec: lambda e, p: f"{e.src.name}[{e.index}]",
    Concat: lambda e, p: (p(e.parts[0]) if len(e.parts) == 1
                          else "{" + ", ".join(p(x) for x in e.parts) + "}"),
    Not: lambda e, p: f"~{p(e.a)}",
    ZeroExt: lambda e, p: f"$signed({{{e.zeros}'b{'0' * e.zeros}, {p(e.a)}}})",
    Resize: lambda e, p: p(e.a),
    Extend: lambda e, p: p(e.a),
    Shl: lambda e, p: f"{p(e.a)} <<< {e.k}",
    Shr: lambda e, p: f"{p(e.a)} >>> {e.k}",
    ShiftBy: lambda e, p: f"{p(e.a)} << {p(e.amount)}",
    Flip: lambda e, p: f"{p(e.a)} ^ {{{e.width}{{{'~' if e.invert else ''}{p(e.bit)}}}}}",
    Pad: lambda e, p: p(e.a),
    Neg: lambda e, p: f"-{p(e.a)}",
    Add: lambda e, p: " + ".join(p(t) for t in e.terms),
    Sub: lambda e, p: f"{p(e.a)} - {p(e.b)}",
    Mul: lambda e, p: f"{p(e.a)} * {p(e.b)}",
    Gate: _v_gate,
    And: lambda e, p: f"{p(e.a)} & {p(e.b)}",
    Or: lambda e, p: f"{p(e.a)} | {p(e.b)}",
    ReduceOr: lambda e, p: f"|{p(e.a)}",
    Group: lambda e, p: f"({p(e.a)})",
    Paren: lambda e, p: f"({p(e.a)})",
    Compare: lambda e, p: f"{p(e.a)} {e.op} {p(e.b)}",
    Select: lambda e, p: f"{p(e.cond)} ? {p(e.a)} : {p(e.b)}",
}


def _vh_zeroext(e, p):
    zero = "'0'" if e.char else '"' + "0" * e.zeros + '"'
    return f"signed{chr(39) if e.qualified else ''}({zero} & {p(e.a)})"


def _vh_concat(e, p):
    text = " & ".join(f'"{x.value:0{x.width}b}"' if isinstance(x, Const)
                      else p(x) if _is_logic(x) or type(x) is Bit
                      else f"std_logic_vector({p(x)})" for x in e.parts)
    if len(e.parts) > 1 and all(type(x) is Bit or isinstance(x, Signal) and x.scalar
                                for x in e.parts):   # bits only: the vector type is named
        return f"std_logic_vector'({text})"
    return text


#: VHDL-2008 (``ieee.numeric_std``) spelling of each node kind
_VHDL = {
    Signal: lambda e, p: e.name,
    Const: lambda e, p: vhdl_bits(e.value, e.width) if e.signed else str(e.value),
    Slice: lambda e, p: f"{e.src.name}({e.hi} downto {e.lo})",
    Bit: lambda e, p: f"{e.src.name}({e.index})",
    BitVec: lambda e, p: f"{e.src.name}({e.index} downto {e.index})",
    Concat: lambda e, p: _vh_concat(e, p),
    Not: lambda e, p: f"not {p(e.a)}",
    ZeroExt: _vh_zeroext,
    Resize: lambda e, p: (f"wrap({p(e.a)}, {e.width})" if e.signed == e.a.signed
                          else f"{'signed' if e.signed else 'unsigned'}({p(e.a)})"),
    Extend: lambda e, p: f"resize({p(e.a)}, {e.width})",
    Shl: lambda e, p: f"shift_left({p(e.a)}, {e.k})",
    Shr: lambda e, p: f"shift_right({p(e.a)}, {e.k})",
    Flip: lambda e, p: (f"{p(e.a)} xor ({e.width - 1} downto 0 => "
                        f"{'not ' if e.invert else ''}{p(e.bit)})"),
    Pad: lambda e, p: f"resize({p(e.a)}, {e.width})",
    ShiftBy: lambda e, p: (f"std_logic_vector(shift_left(unsigned({p(e.a)}), "
                           f"to_integer({p(e.amount)})))"),
    Neg: lambda e, p: f"-{p(e.a)}",
    Add: lambda e, p: " + ".join(p(t) for t in e.terms),
    Sub: lambda e, p: f"{p(e.a)} - {p(e.b)}",
    Mul: lambda e, p: f"{p(e.a)} * {p(e.b)}",
    Gate: lambda e, p: f"{p(e.a)} when {p(e.bit)} = '{1 if e.on else 0}' else (others => '0')",
    And: lambda e, p: f"{p(e.a)} and {p(e.b)}",
    Or: lambda e, p: f"{p(e.a)} or {p(e.b)}",
    ReduceOr: lambda e, p: f"or {p(e.a)}",
    Group: lambda e, p: p(e.a),
    Paren: lambda e, p: f"({p(e.a)})",
    Compare: lambda e, p: f"{p(e.a)} {_VHDL_OPS.get(e.op, e.op)} {p(e.b)}",
}

#: VHDL spelling of the comparisons that differ from Verilog's
_VHDL_OPS = {"==": "=", "!=": "/="}

_TABLES = {"verilog": _VERILOG, "vhdl": _VHDL}
_SHIFTS = {"verilog": {"shr": ">>>", "shl": "<<<"}, "vhdl": {"shr": ">>", "shl": "<<"}}
_COMMENT = {"verilog": "//", "vhdl": "--"}


def _comment(text: str, language: str) -> str:
    for token, op in _SHIFTS[language].items():
        text = text.replace("{" + token + "}", op)
    return text


def _expr(e, language: str) -> str:
    table = _TABLES[language]

    def p(node):
        return table[type(node)](node, p)
    return p(e)


def _is_logic(e) -> bool:
    """True when ``e`` is a VHDL bit vector (std_logic_vector) rather than a number."""
    if isinstance(e, Signal):
        return e.logic
    if isinstance(e, (Slice, BitVec)):
        return e.src.logic
    return isinstance(e, (Concat, Not, ShiftBy))


def _vhdl_cond(c) -> str:
    """A VHDL condition (boolean): a comparison, or a bit equal to '1'."""
    return _expr(c, "vhdl") if isinstance(c, Compare) else f"{_expr(c, 'vhdl')} = '1'"


def _vhdl_value(dst: Signal, e) -> str:
    """``e`` converted to ``dst``'s VHDL type where the types differ."""
    if isinstance(e, Select):   # a conditional assignment, one arm per condition
        arms = []
        while isinstance(e, Select):
            arms.append(f"{_vhdl_value(dst, e.a)} when {_vhdl_cond(e.cond)} else")
            e = e.b
        return " ".join(arms + [_vhdl_value(dst, e)])
    if isinstance(e, Compare):
        return f"'1' when {_vhdl_cond(e)} else '0'"
    if isinstance(e, Const) and (dst.logic or not dst.signed):
        if dst.scalar:
            return f"'{e.value}'"
        bits = f"to_unsigned({e.value}, {dst.width})"
        return f"std_logic_vector({bits})" if dst.logic else bits
    text = _expr(e, "vhdl")
    if _is_logic(e) and not dst.logic:
        return f"{'signed' if dst.signed else 'unsigned'}({text})"
    if dst.logic and not dst.scalar and not _is_logic(e):
        return f"std_logic_vector({text})"
    return text


def _hex(value: int, bits: int) -> str:
    return f"{bits}'h{int(value):0{(bits + 3) // 4}x}"


def _verilog_context(e, top: bool = True, high: bool = False) -> None:
    """Refuse what the Verilog text would compute otherwise than the IR says
    (VHDL computes exactly the IR): Verilog sizes an expression by its context,
    so a :class:`Resize` printed as nothing (1) must not widen a sum, a
    difference, a negation or a left shift (Verilog would compute it at the
    wider width), and (2) must not narrow a value whose high bits a consumer
    reads (``high``: a right shift, an extension, a concatenation -- Verilog
    would keep them); (3) a :class:`Gate` (an AND, unsigned in Verilog) must be
    the whole value of its assignment."""
    if isinstance(e, Gate) and not top:
        raise _refuse("Gate", "inside an expression; accepted: the whole value of an Assign "
                              "(Verilog's AND with a repeated bit is unsigned)")
    if isinstance(e, Select):
        if not top:
            raise _refuse("Select", "inside an expression; accepted: the whole value of an "
                                    "Assign (VHDL's conditional assignment)")
        _verilog_context(e.a)
        _verilog_context(e.b)
        return
    if isinstance(e, Resize):
        if e.width > e.a.width and type(e.a) in (Add, Sub, Neg, Shl):
            raise _refuse("Resize", f"{type(e.a).__name__} of {_kind(e.a)} widened to "
                                    f"{e.width} bits; accepted: widen the operands (Verilog "
                                    f"computes it at the wider width)")
        if e.width < e.a.width and high:
            raise _refuse("Resize", f"{_kind(e.a)} narrowed to {e.width} bits under an "
                                    f"operation that reads its high bits; accepted: narrow "
                                    f"in an assignment of its own")
    below = (isinstance(e, (Shr, Extend, Pad, ZeroExt, Concat))
             or (isinstance(e, Resize) and e.width > e.a.width)
             or (high and not (isinstance(e, Resize) and e.width < e.a.width)))
    for name in ("a", "b"):
        if isinstance(getattr(e, name, None), _EXPR):
            _verilog_context(getattr(e, name), False, below)
    for t in getattr(e, "terms", ()) or getattr(e, "parts", ()):
        _verilog_context(t, False, below)


def _verilog_statement(s) -> list[str]:
    if isinstance(s, Assign):
        _verilog_context(s.expr)
        return [f"    {_verilog_type(s.dst)} {s.dst.name} = {_expr(s.expr, 'verilog')};"]
    if isinstance(s, ConstDecl):
        return [f"    localparam signed [{s.dst.width - 1}:0] {s.dst.name} = "
                f"{signed_literal(s.value, s.dst.width)};"]
    if isinstance(s, Comment):
        return [f"    // {_comment(s.text, 'verilog')}"]
    if isinstance(s, Output):
        _verilog_context(s.expr)
        return [f"    assign {s.port.name if s.port else 'y'} = {_expr(s.expr, 'verilog')};"]
    if isinstance(s, Instance):
        conns = ", ".join(f".{n}({_expr(v, 'verilog')})" for n, _, _, v in s.connections)
        return [f"    {s.module} {s.label} ({conns});"]
    if isinstance(s, Declare):
        return [f"    {_verilog_type(s.signal, 'reg' if s.reg else 'wire')} {s.signal.name};"]
    if isinstance(s, Table):
        d, a, w = s.dst.name, s.address, s.dst.width
        return [f"    {_verilog_type(s.dst, 'reg')} {d};", "    always @(*) begin",
                f"        case ({a.name})",
                *(f"            {_hex(i, a.width)}: {d} = {_hex(v, w)};"
                  for i, v in enumerate(s.values)),
                f"            default: {d} = {_hex(0, w)};", "        endcase", "    end"]
    if isinstance(s, Param):
        return [f"    localparam {s.name} = {s.value};"]
    if isinstance(s, LeadingZeros):
        w, z, i = s.src.width, s.dst.width, s.index
        return [f"    {_verilog_type(s.dst, 'reg')} {s.dst.name};", f"    integer {i};",
                "    always @(*) begin", f"        {s.dst.name} = {z}'d{w};",
                f"        for ({i} = 0; {i} < {w}; {i} = {i} + 1)",
                f"            if ({s.src.name}[{i}]) {s.dst.name} = {w - 1} - {i};", "    end"]
    if isinstance(s, Saturate):
        r, top, n = s.raw.name, s.raw.width - 1, s.width_name
        port = s.port.name if s.port else "y"
        return [f"    assign {port} = {r}[{top}] ? {{{n}{{1'b0}}}} : ({r} > {s.ymax.name}) ? "
                f"{{{n}{{1'b1}}}} : {r}[{n}-1:0];"]
    if isinstance(s, Registers):
        out = [f"    {_verilog_type(d, 'reg')} {d.name};" for d, _ in s.pairs if s.declare]
        return out + ["    always @(posedge clk) begin",
                      *(f"        {d.name} <= {src.name};" for d, src in s.pairs), "    end"]
    if isinstance(s, Rom):
        a = s.address
        out = [f"    {_verilog_type(o, 'reg')} {o.name};" for o in s.outputs]
        out += [f"    {_verilog_type(a)} {a.name} = {_expr(s.address_expr, 'verilog')};",
                "    always @(*) begin", f"        case ({a.name})"]
        for i, row in enumerate(s.rows):
            body = " ".join(f"{o.name} = {signed_literal(int(q), o.width)};"
                            for o, q in zip(s.outputs, row))
            out.append(f"            {a.width}'d{i}: begin {body} end")
        return out + ["        endcase", "    end"]
    raise TypeError(f"statement {type(s).__name__}: not a netlist statement")


def _vhdl_statement(s) -> tuple[list[str], list[str]]:
    if isinstance(s, Assign):
        return ([f"    signal {s.dst.name} : {_vhdl_type(s.dst)};"],
                [f"    {s.dst.name} <= {_vhdl_value(s.dst, s.expr)};"])
    if isinstance(s, ConstDecl):
        w = s.dst.width
        return ([f"    constant {s.dst.name} : signed({w - 1} downto 0) := "
                 f"{vhdl_bits(s.value, w)};  -- {s.value}"], [])
    if isinstance(s, Comment):
        return [], [f"    -- {_comment(s.text, 'vhdl')}"]
    if isinstance(s, Output):
        text = _expr(s.expr, "vhdl")
        return [], [f"    {s.port.name if s.port else 'y'} <= "
                    f"{text if _is_logic(s.expr) else f'std_logic_vector({text})'};"]
    if isinstance(s, Instance):
        conns = ", ".join(f"{n} => {_expr(v, 'vhdl')}" for n, _, _, v in s.connections)
        return [], [f"    {s.label} : entity work.{s.module} port map ({conns});"]
    if isinstance(s, Declare):
        return [f"    signal {s.signal.name} : {_vhdl_type(s.signal)};"], []
    if isinstance(s, Table):
        d, n, w = s.dst.name, len(s.values), s.dst.width
        rows = [f"        \"{int(v):0{w}b}\"{',' if i < n - 1 else ''}"
                for i, v in enumerate(s.values)]
        address = s.address.name if s.address.logic else f"std_logic_vector({s.address.name})"
        return ([f"    type {d}_t is array (0 to {n - 1}) of unsigned({w - 1} downto 0);",
                 f"    constant {d.upper()}_ROM : {d}_t := (", *rows, "    );",
                 f"    signal {d} : {_vhdl_type(s.dst)};"],
                [f"    {d} <= {d.upper()}_ROM(to_integer(unsigned({address})));"])
    if isinstance(s, Param):
        return [f"    constant {s.name} : natural := {s.value};"], []
    if isinstance(s, LeadingZeros):
        w, z = s.src.width, s.dst.width
        return ([f"    signal {s.dst.name} : {_vhdl_type(s.dst)};"],
                [f"    {s.label} : process ({s.src.name})",
                 f"        variable c : natural range 0 to {w};", "    begin", f"        c := {w};",
                 f"        for i in 0 to {w - 1} loop", f"            if {s.src.name}(i) = '1' then",
                 f"                c := {w - 1} - i;", "            end if;", "        end loop;",
                 f"        {s.dst.name} <= to_unsigned(c, {z});", f"    end process {s.label};"])
    if isinstance(s, Saturate):
        r, n = s.raw.name, s.width_name
        port = s.port.name if s.port else "y"
        return [], [f"    {port} <= (others => '0') when {r}({s.raw.width - 1}) = '1' else",
                    f"         (others => '1') when {r} > {s.ymax.name} else",
                    f"         std_logic_vector({r}({n} - 1 downto 0));"]
    if isinstance(s, Registers):
        decl = [f"    signal {d.name} : {_vhdl_type(d)};" for d, _ in s.pairs if s.declare]
        head = f"    {s.label} : process (clk)" if s.label else "    process (clk)"
        tail = f"    end process {s.label};" if s.label else "    end process;"
        return decl, [head, "    begin", "        if rising_edge(clk) then",
                      *(f"            {d.name} <= {src.name};" for d, src in s.pairs),
                      "        end if;", tail]
    if isinstance(s, Rom):
        a = s.address
        decl, stmt = _vhdl_statement(Assign(a, s.address_expr))
        for j, o in enumerate(s.outputs):
            w, last = o.width, len(s.rows) - 1
            decl.append(f"    type rom{j}_t is array (0 to {last}) of signed({w - 1} downto 0);")
            rows = [f"        {vhdl_bits(int(row[j]), w)}{',' if i < last else ''}"
                    f"  -- segment {i}: {row[j]}" for i, row in enumerate(s.rows)]
            decl += [f"    constant ROM{j} : rom{j}_t := (", *rows, "    );",
                     f"    signal {o.name} : {_vhdl_type(o)};"]
            index = a.name if not a.signed and not a.logic else f"unsigned({a.name})"
            stmt.append(f"    {o.name} <= ROM{j}(to_integer({index}));")
        return decl, stmt
    raise TypeError(f"statement {type(s).__name__}: not a netlist statement")


@hw_doc
def statement_lines(statement, language: str) -> tuple[list[str], list[str]]:
    """The text of one statement: declarations and body lines (Verilog
    declares in place: its declaration list is empty).

    Parameters
    ----------
    statement : Assign, ConstDecl, Rom, Registers, Saturate or Comment
        The statement.
    %(language_required)s

    Returns
    -------
    tuple of (list of str, list of str)
        Declaration lines (VHDL architecture head) and body lines, indented.

    Raises
    ------
    ValueError
        If ``language`` is unknown.
    """
    if language == "verilog":
        return [], _verilog_statement(statement)
    if language == "vhdl":
        return _vhdl_statement(statement)
    raise ValueError(f"language {language!r}: accepted: 'verilog' or 'vhdl'")


#: the VHDL function every width change of the IR (:class:`Resize`) prints as
VHDL_WRAP = [
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


def _facts(m: Module, language: str) -> list[str]:
    return m.facts[language] if isinstance(m.facts, dict) else m.facts


def verilog(module: Module) -> str:
    """The Verilog-2005 text of ``module``: banner, port list, statements.

    Parameters
    ----------
    module : Module
        The netlist.

    Returns
    -------
    str
        The module text, ending with ``endmodule`` and a newline.
    """
    m = module
    clocked = m.latency > 0
    statements = schedule(m.statements)
    out = comment_lines(_facts(m, "verilog"), "verilog")
    if m.ports:
        out += [f"module {m.name} (", *_verilog_ports(m.ports), ");"]
        for s in statements:
            out += _verilog_statement(s)
        return "\n".join(out + ["endmodule", ""])
    out += [f"module {m.name} #(",
            f"    parameter IN_BITS = {m.in_bits},",
            f"    parameter OUT_BITS = {m.out_bits}" + ("," if clocked else ""),
            *([f"    parameter LATENCY = {m.latency}"] if clocked else []),
            ") (",
            *(["    input  wire                clk,"] if clocked else []),
            "    input  wire [IN_BITS-1:0]  x,",
            "    output wire [OUT_BITS-1:0] y",
            ");"]
    for s in statements:
        out += _verilog_statement(s)
    return "\n".join(out + ["endmodule", ""])


def _verilog_ports(ports) -> list[str]:
    """The port declarations of a module with a port list, comma-separated."""
    return [f"    {'output' if p.output else 'input '} {_verilog_type(p.signal)} {p.signal.name}"
            f"{',' if i < len(ports) - 1 else ''}" for i, p in enumerate(ports)]


def _vhdl_ports(ports) -> list[str]:
    """The port clause entries of a module with a port list, semicolon-separated."""
    return [f"        {p.signal.name} : {'out' if p.output else 'in '} {_vhdl_type(p.signal)}"
            f"{';' if i < len(ports) - 1 else ''}" for i, p in enumerate(ports)]


def vhdl_entity(name: str, in_bits: int, out_bits: int, latency: int = 0) -> list[str]:
    """The library clauses and the entity of a module with ports ``x``, ``y``
    (and ``clk`` with generic ``LATENCY`` when ``latency > 0``).

    Parameters
    ----------
    name : str
        The entity name (a VHDL identifier, checked by the caller).
    in_bits, out_bits : int
        The generics' defaults.
    latency : int, default 0
        The pipeline latency (> 0: clocked).

    Returns
    -------
    list of str
        The lines, ending with an empty one.
    """
    clocked = latency > 0
    generics = [f"        IN_BITS  : natural := {in_bits};",
                f"        OUT_BITS : natural := {out_bits}" + (";" if clocked else "")]
    if clocked:
        generics.append(f"        LATENCY  : natural := {latency}")
    ports = (["        clk : in  std_logic;"] if clocked else []) + [
        "        x   : in  std_logic_vector(IN_BITS - 1 downto 0);",
        "        y   : out std_logic_vector(OUT_BITS - 1 downto 0)"]
    return ["library ieee;", "use ieee.std_logic_1164.all;", "use ieee.numeric_std.all;", "",
            f"entity {name} is", "    generic (", *generics, "    );", "    port (", *ports,
            "    );", f"end entity {name};", ""]


def vhdl_name(name: str) -> str:
    """``name`` if it is a VHDL basic identifier (no ``__``, no trailing ``_``).

    Parameters
    ----------
    name : str
        A module (entity) name.

    Returns
    -------
    str
        ``name``.

    Raises
    ------
    ValueError
        If ``name`` is not a safe identifier, or has two underscores in a row or a trailing
        one.
    """
    identifier(name, field="module name")
    if "__" in name or name.endswith("_"):
        raise ValueError(f"module name {name!r} is not a VHDL identifier: VHDL forbids two "
                         f"underscores in a row and a trailing underscore; accepted: a table "
                         f"name without them")
    return name


def vhdl(module: Module) -> str:
    """The VHDL-2008 text of ``module``: banner, entity, architecture
    (``wrap``, the declarations, the statements).

    Parameters
    ----------
    module : Module
        The netlist.

    Returns
    -------
    str
        The entity and architecture text, ending with a newline.

    Raises
    ------
    ValueError
        If the module's name is not a VHDL identifier (:func:`vhdl_name`).
    """
    m = module
    vhdl_name(m.name)
    out = comment_lines(_facts(m, "vhdl"), "vhdl")
    if m.ports:
        out += ["library ieee;", "use ieee.std_logic_1164.all;", "use ieee.numeric_std.all;", "",
                f"entity {m.name} is", "    port (", *_vhdl_ports(m.ports), "    );",
                f"end entity {m.name};", ""]
    else:
        out += vhdl_entity(m.name, m.in_bits, m.out_bits, m.latency)
    decl, stmt = [], []
    for s in schedule(m.statements):
        d, b = _vhdl_statement(s)
        decl += d
        stmt += b
    wrap = VHDL_WRAP if any("wrap(" in line for line in stmt) else []
    out += [f"architecture rtl of {m.name} is", *wrap, *decl, "begin", *stmt,
            "end architecture rtl;", ""]
    return "\n".join(out)


# -- the independent evaluation ---------------------------------------------------------

def _wrap(v: int, width: int, signed: bool) -> int:
    v &= (1 << width) - 1
    return v - (1 << width) if signed and v >> (width - 1) else v


def _value(e, env: dict) -> int:
    """The value of ``e`` (an integer in its width and signedness)."""
    t = type(e)
    if t is Signal:
        return env[e.name]
    if t is Const:
        return e.value
    if t in (Group, Paren):
        return _value(e.a, env)
    if t is Slice:
        return (env[e.src.name] >> e.lo) & ((1 << e.width) - 1)
    if t in (Bit, BitVec):
        return (env[e.src.name] >> e.index) & 1
    if t is Concat:
        v = 0
        for part in e.parts:
            v = (v << part.width) | (_value(part, env) & ((1 << part.width) - 1))
        return v
    if t is Not:
        return ~_value(e.a, env) & ((1 << e.width) - 1)
    if t is ZeroExt:
        return _value(e.a, env) & ((1 << e.a.width) - 1)
    if t in (Resize, Extend):
        return _wrap(_value(e.a, env) & ((1 << e.a.width) - 1) if e.signed != e.a.signed
                     else _value(e.a, env), e.width, e.signed)
    if t is Shl:
        return _wrap(_value(e.a, env) << e.k, e.width, e.signed)
    if t is Shr:
        return _value(e.a, env) >> e.k   # floor: arithmetic for signed, logical for unsigned
    if t is Neg:
        return _wrap(-_value(e.a, env), e.width, True)
    if t is Flip:
        mask = (1 << e.width) - 1
        bit = _value(e.bit, env) ^ int(e.invert)
        return _value(e.a, env) ^ (mask if bit else 0)
    if t is Pad:
        return _value(e.a, env)
    if t is ShiftBy:
        return (_value(e.a, env) << _value(e.amount, env)) & ((1 << e.width) - 1)
    if t is Add:
        return _wrap(sum(_value(x, env) for x in e.terms), e.width, e.signed)
    if t is Sub:
        return _wrap(_value(e.a, env) - _value(e.b, env), e.width, e.signed)
    if t is Mul:
        return _value(e.a, env) * _value(e.b, env)
    if t is Gate:
        return _value(e.a, env) if _value(e.bit, env) == int(e.on) else 0
    if t is And:
        return _value(e.a, env) & _value(e.b, env)
    if t is Or:
        return _value(e.a, env) | _value(e.b, env)
    if t is ReduceOr:
        return int(_value(e.a, env) != 0)
    if t is Compare:
        return int(COMPARE_OPS[e.op](_value(e.a, env), _value(e.b, env)))
    if t is Select:
        return _value(e.a, env) if _value(e.cond, env) else _value(e.b, env)
    raise TypeError(f"{t.__name__}: not an expression node")


def evaluate(module: Module, code: int | None = None, *, inputs: dict | None = None,
             modules: dict | None = None) -> dict:
    """Every signal of a combinational ``module`` for input code ``code``, in
    Python: the meaning the printers' texts must have (registers pass their
    source through, as the steady state of a pipeline).

    Parameters
    ----------
    module : Module
        The netlist.
    code : int or None, default None
        The input code, ``0 <= code < 2**in_bits`` (a module of ports ``x``, ``y``).
    inputs : dict of str to int or None, default None
        A module with a port list: input port name -> its bits (an unsigned integer).
    modules : dict of str to Module or None, default None
        The modules its :class:`Instance` s name (modules of ports ``x``, ``y``), by name.

    Returns
    -------
    dict
        Signal name -> value (signed signals as negative integers where negative);
        ``"y"`` (or each output port): the output code.

    Raises
    ------
    ValueError
        If ``code`` or an input is out of range or missing, or an instance names a
        module not given.
    """
    modules = modules or {}
    for s in module.statements:
        if isinstance(s, Instance) and s.module not in modules:
            raise ValueError(f"module {module.name}: an instance of {s.module}, not given; "
                             f"accepted: modules={{name: Module}} for each instance")
    if module.ports:
        env = {}
        for p in module.ports:
            if p.output:
                continue
            v = (inputs or {}).get(p.signal.name)
            if v is None or not 0 <= v < 2 ** p.signal.width:
                raise ValueError(f"input {p.signal.name} = {v!r}: accepted 0.."
                                 f"{2 ** p.signal.width - 1}")
            env[p.signal.name] = int(v)
        return _run(module, env, modules)
    if code is None or not 0 <= code < 2 ** module.in_bits:
        raise ValueError(f"code {code}: accepted 0..{2 ** module.in_bits - 1}")
    return _run(module, {"x": code}, modules)


def _run(module: Module, env: dict, modules: dict) -> dict:
    """Evaluate the statements of ``module`` from the inputs in ``env``."""
    for s in schedule(module.statements):
        if isinstance(s, Assign):
            env[s.dst.name] = _wrap(_value(s.expr, env), s.dst.width, s.dst.signed)
        elif isinstance(s, ConstDecl):
            env[s.dst.name] = s.value
        elif isinstance(s, Rom):
            env[s.address.name] = _value(s.address_expr, env)
            for o, q in zip(s.outputs, s.rows[env[s.address.name]]):
                env[o.name] = int(q)
        elif isinstance(s, Registers):
            for d, src in s.pairs:
                env[d.name] = env[src.name]
        elif isinstance(s, Output):
            width = s.port.width if s.port else module.out_bits
            env[s.port.name if s.port else "y"] = _value(s.expr, env) & (2 ** width - 1)
        elif isinstance(s, Instance):
            sub = modules[s.module]
            ins = {n: _value(v, env) for n, d, _, v in s.connections if d == "input"}
            got = evaluate(sub, ins.get("x"), modules=modules)
            for n, d, _, v in s.connections:
                if d == "output":
                    env[v.name] = got[n]
        elif isinstance(s, Table):
            a = env[s.address.name]
            env[s.dst.name] = int(s.values[a]) if a < len(s.values) else 0
        elif isinstance(s, LeadingZeros):
            v = env[s.src.name]
            env[s.dst.name] = s.src.width - v.bit_length()
        elif isinstance(s, Saturate):
            raw, ymax = env[s.raw.name], env[s.ymax.name]
            port = s.port or Signal("y", module.out_bits)
            env[port.name] = 0 if raw < 0 else (2 ** port.width - 1 if raw > ymax
                                                else raw & (2 ** port.width - 1))
    return env
