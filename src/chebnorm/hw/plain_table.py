"""A plain table: ``y(k) = round(f(x_k) * 2**F)`` for every input code,
stored as one ROM (FloPoCo's ``FixFunctionByTable``).

Every entry is the integer nearest ``f(x_k) * 2**F`` (ties to even), each
choice proved by :func:`chebnorm.hw.exhaustive.round_to_nearest` (Arb
enclosures, higher precision near a midpoint, exact evaluation at a tie);
:attr:`PlainTableDesign.correctly_rounded` is True only when every code was
proved. The output offset (the smallest entry) is subtracted, so the ROM
holds ``out_bits``-bit codes. Cost: ``2**in_bits * out_bits`` ROM bits.

>>> d = design_plain_table("1/sqrt(1+3*x)", ("0", "1"), 8, 8)
>>> d.correctly_rounded, d.rom_bits, d.certificate.upper <= 2.0 ** -(d.y_format.frac_bits + 1)
(True, 2048, True)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from chebnorm.core.numeric import check_int
from chebnorm.core.textsafe import identifier
from chebnorm.core.display import field_rows, summary_html, summary_repr

from .exhaustive import ExhaustiveCheck, reference, round_to_nearest
from .fixed import QFormat
from .multipartite import output_format
from .design_base import Design, register
from .trust import check, check_certificate, drafting, seal

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: the widest input of a plain table (2**20 ROM entries)
MAX_TABLE_IN_BITS = 20


@register("table")
@dataclass(frozen=True, eq=False)
class PlainTableDesign(Design):
    """A ROM of the correctly rounded ``f`` at every input code.

    ``values[k]`` is the output code of input ``k`` (value ``(offset_code +
    values[k]) / 2**frac_bits``); ``unproved`` counts the codes whose
    rounding could not be proved (then ``correctly_rounded`` is False and
    the entry is the nearest by the float64 value; ``certificate`` still
    bounds the error rigorously).

    >>> d = design_plain_table("1/sqrt(1+3*x)", ("0", "1"), 4, 4)
    >>> [int(v) for v in d.values[:3]], d.y_format.offset_code, d.y_format.frac_bits
    ([8, 7, 6], 8, 4)

    Attributes
    ----------
    name : str
        The design's name.
    expression : str
        The function ``f``.
    variable : str
        Its variable.
    interval : tuple of (str, str)
        The rational interval ``(lo, hi)``.
    in_bits : int
        Input code width, 1 to 20 (``MAX_TABLE_IN_BITS``).
    out_bits : int
        Output code width, 1 to 32.
    y_format : QFormat
        The output format (offset and fractional bits).
    values : tuple of int
        ``2**in_bits`` output codes, each ``0 <= values[k] < 2**out_bits``.
    unproved : int
        How many entries' rounding could not be proved (0: correctly rounded).
    certificate : ExhaustiveCheck
        The exhaustive bound of ``|y - f|`` over every code.
    """

    name: str
    expression: str
    variable: str
    interval: tuple[str, str]
    in_bits: int
    out_bits: int
    y_format: QFormat
    values: tuple[int, ...]
    unproved: int
    certificate: ExhaustiveCheck

    def _summary(self) -> list[tuple[str, object]]:
        return [("name", self.name), ("expression", self.expression),
                ("interval", self.interval), ("in_bits", self.in_bits),
                ("out_bits", self.out_bits), ("correctly_rounded", self.correctly_rounded)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    architecture = "table"
    degree = 0   # the VHDL bench reads it (a latency of 1 when combinational)

    def __post_init__(self):
        check_int(self.in_bits, "in_bits", 1, MAX_TABLE_IN_BITS)
        check_int(self.out_bits, "out_bits", 1, 32)
        identifier(self.name, field="name")
        if len(self.values) != 2 ** self.in_bits or any(
                not 0 <= int(v) < 2 ** self.out_bits for v in self.values):
            raise ValueError(f"values: accepted: {2 ** self.in_bits} codes in 0 .. "
                             f"2**{self.out_bits} - 1")
        self.verify()

    def verify(self) -> "PlainTableDesign":
        """Re-prove the table; return it unchanged, or raise ValueError.

        Every entry must be the nearest code of ``f`` (ties to even),
        ``unproved`` the count of roundings that cannot be proved, and the
        certificate's bound at least the recomputed exhaustive bound. Proved
        once per content (:func:`chebnorm.hw.trust.check`): called again after
        a change behind the frozen dataclass's back, it proves again.

        Returns
        -------
        PlainTableDesign
            ``self``.

        Raises
        ------
        ValueError
            Naming the field that does not hold.
        """
        return check(self, _prove)

    @property
    def module_name(self) -> str:
        return f"chebnorm_{self.name}"

    @property
    def correctly_rounded(self) -> bool:
        """True when every entry is proved to be the nearest integer."""
        return self.unproved == 0

    @property
    def rom_bits(self) -> int:
        return 2 ** self.in_bits * self.out_bits

    def evaluate(self, codes=None, *, wires: bool = False):
        """Output codes for input ``codes`` (default all)."""
        rom = np.asarray(self.values, dtype=np.int64)
        if codes is None:
            y = rom
        else:
            k = np.asarray(codes)
            if k.dtype.kind not in "iu" or k.size and (k.min() < 0 or k.max() >= rom.size):
                raise ValueError(f"codes: accepted: integers 0 <= code < 2**{self.in_bits}")
            y = rom[k.astype(np.int64)]
        return {"y": y} if wires else y

    def measure(self) -> dict:
        """Rigorous bounds of ``max |y - f(x)|`` over every code (recomputed)."""
        ref = reference(self.expression, self.interval, self.in_bits, self.variable)
        return ref.error_bounds(self.evaluate() + self.y_format.offset_code,
                                self.y_format.frac_bits)

    def budget(self) -> dict:
        """``final_rounding`` (half an LSB: the only error of a correctly
        rounded table), ``exhaustive`` (the proved maximum), ``y_lsb``."""
        lsb = 2.0 ** -self.y_format.frac_bits
        return {"method": 0.0, "table_rounding": 0.0, "final_rounding": lsb / 2,
                "a_priori": lsb / 2, "exhaustive": self.certificate.upper, "y_lsb": lsb}

    def verilog(self, *, version: str = "", command: str | None = None) -> str:
        """The Verilog-2005 module (:func:`chebnorm.hw.hdl.tables.table_module`)."""
        from .hdl.tables import table_module
        return table_module(self, "verilog", version=version, command=command)

    def vhdl(self, *, version: str = "", command: str | None = None) -> str:
        """The VHDL-2008 entity (:func:`chebnorm.hw.hdl.tables.table_module`)."""
        from .hdl.tables import table_module
        return table_module(self, "vhdl", version=version, command=command)

    def hdl_files(self, language: str = "verilog") -> dict:
        """Module, bench and vectors (:func:`chebnorm.hw.hdl.tables.table_files`)."""
        from .hdl.tables import table_files
        return table_files(self, language)

    def features(self):
        """The cost model's inputs (:func:`chebnorm.hw.target_model.table_features`)."""
        from .target_model import table_features
        return table_features(self)

    def cut_points(self) -> tuple[str, ...]:
        """``address`` (the address registered) and ``rom`` (the ROM's output
        registered: a synchronous read)."""
        return ("address", "rom")

    def cut_plans(self) -> list[tuple[int, ...]]:
        """The ROM output first (a synchronous read maps to block RAM), then both."""
        return [(1,), (0, 1)]

    def with_cuts(self, cuts):
        """A :class:`~chebnorm.hw.pipeline.PipelinedTable` with registers at ``cuts``."""
        from .pipeline import PipelinedTable
        return PipelinedTable(self, cuts)


def design_plain_table(expr, interval, in_bits: int, out_bits: int, *, var: str = "x",
                       name: str = "table", out_frac_bits: int | None = None
                       ) -> PlainTableDesign:
    """The correctly rounded table of ``expr`` on ``interval``.

    Parameters
    ----------
    expr, interval, var
        The function and its rational interval; code ``k`` of ``in_bits``
        bits stands for ``lo + (hi - lo) k / 2**in_bits``.
    in_bits, out_bits
        Code widths (``1 <= in_bits <= 20``, ``1 <= out_bits <= 32``); the output LSB
        as in :func:`~chebnorm.hw.multipartite.design_multipartite`.
    name : str, default "table"
        The design's name (the HDL module name is derived from it).
    out_frac_bits : int or None, default None
        Fractional bits ``F`` of the output, -60 to 60; None takes the most for which
        ``out_bits`` hold every value (with an offset).

    Returns
    -------
    PlainTableDesign
        With its exhaustive certificate (``<= 2**-(F+1)`` plus the
        enclosures' width when every rounding was proved).

    See Also
    --------
    chebnorm.hw.multipartite.design_multipartite : tables and an adder, smaller ROMs.
    chebnorm.hw.exhaustive : the proof that every entry is the nearest integer.

    Examples
    --------
    >>> d = design_plain_table("x/2", ("0", "1"), 3, 3, out_frac_bits=3)
    >>> d.y_format.frac_bits, list(d.values)     # x/2 = k/16: ties to even
    (3, [0, 0, 1, 2, 2, 2, 3, 4])
    """
    in_bits = check_int(in_bits, "in_bits", 1, MAX_TABLE_IN_BITS)
    out_bits = check_int(out_bits, "out_bits", 1, 32)
    name = identifier(name, field="name")
    ref = reference(expr, interval, in_bits, var)
    F = output_format(ref.mid, out_bits, out_frac_bits)
    n, proved = round_to_nearest(ref, F)
    off = int(n.min())
    y = n - off
    if int(y.max()) > 2 ** out_bits - 1:
        raise ValueError(f"out_bits = {out_bits}: the rounded values span {int(y.max()) + 1} "
                         f"codes; accepted: more out_bits or fewer out_frac_bits")
    proof = ExhaustiveCheck.of(ref.error_bounds(n, F))
    with drafting():
        d = PlainTableDesign(name, str(expr), var, (str(interval[0]), str(interval[1])), in_bits,
                             out_bits, QFormat(out_bits, F, offset_code=off),
                             tuple(int(v) for v in y), int((~proved).sum()), proof)
    return seal(d)


def _prove(d: PlainTableDesign) -> None:
    """Every entry the nearest code of ``f``, the count of unproved roundings
    and the certificate re-proved (ValueError naming the field)."""
    check_int(d.in_bits, "in_bits", 1, MAX_TABLE_IN_BITS)
    check_int(d.out_bits, "out_bits", 1, 32)
    identifier(d.name, field="name")
    yf = d.y_format
    if not isinstance(yf, QFormat) or yf.bits != d.out_bits or yf.signed:
        raise ValueError(f"y_format: accepted: an unsigned QFormat of out_bits = {d.out_bits} bits")
    check_int(yf.frac_bits, "y_format.frac_bits", -60, 60)
    ref = reference(d.expression, d.interval, d.in_bits, d.variable)
    F = yf.frac_bits
    n, proved = round_to_nearest(ref, F)
    vals = np.asarray(d.values, dtype=np.int64) + int(yf.offset_code)
    bad = np.flatnonzero(vals != n)
    lo, hi = d.interval
    if bad.size:
        k = int(bad[0])
        raise ValueError(f"values: the entries of a plain table of {d.expression} on [{lo}, {hi}) "
                         f"are the nearest codes of f; {bad.size} of {vals.size} entries differ "
                         f"(first: code {k} holds {int(vals[k])}, nearest {int(n[k])})")
    count = int((~proved).sum())
    if isinstance(d.unproved, bool) or not isinstance(d.unproved, int) or d.unproved != count:
        raise ValueError(f"unproved: stated {d.unproved!r}; accepted: {count} (the roundings "
                         f"that cannot be proved)")
    check_certificate(d.certificate, ref.error_bounds(vals, F), 2 ** d.in_bits,
                      f"the plain table of {d.expression}")
