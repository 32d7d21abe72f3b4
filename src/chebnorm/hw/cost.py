"""Resource costs of datapath blocks, composable in series and in parallel.

A :class:`Cost` counts multipliers (with their operand widths), adders
(add, subtract, compare; with their widths), square-root and divider units
(with their result widths), multiplexer bits, ROM bits, and the pipeline
latency. The area estimate is in *full-adder equivalents* (FA): an ``a x b``
array multiplier ~ ``a*b``, an ``n``-bit adder ~ ``n``, a ``w``-bit
digit-recurrence square root ~ ``w*w/2`` and divider ~ ``w*w``, a 2:1 mux bit
~ 1/2, a ROM bit ~ 1/8. Latency assumes one register level per multiply or
add level and one result bit per cycle for square root and division. These
are estimates for comparing designs; Yosys's cell count of the exported
Verilog is the real figure (:func:`chebnorm.hw.run_verilog.synthesize`).

>>> a = Cost(multipliers=((16, 16),), adders=(32,), latency=2)
>>> b = Cost(adders=(16, 16), latency=1)
>>> (a + b).area, (a + b).latency, a.parallel(b).latency
(320.0, 3, 2)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from chebnorm.core.display import field_rows, summary_html, summary_repr

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []


@dataclass(frozen=True)
class Cost:
    """Resources of a block (see module docstring). ``+`` composes in series.

    >>> Cost(multipliers=((8, 8),) * 3, adders=(16, 17), latency=3).area   # a dot product, 8-bit
    225.0

    Parameters
    ----------
    multipliers : tuple of (int, int), default ()
        One ``(a, b)`` pair of operand widths per multiplier (area ``a*b`` FA each).
    adders : tuple of int, default ()
        The width of each adder, subtractor or comparator (area ``n`` FA each).
    sqrts : tuple of int, default ()
        The result width of each square-root unit (area ``w*w/2`` FA each).
    dividers : tuple of int, default ()
        The result width of each divider (area ``w*w`` FA each).
    mux_bits : int, default 0
        2:1 multiplexer bits (1/2 FA each).
    rom_bits : int, default 0
        ROM bits (1/8 FA each).
    latency : int, default 0
        Pipeline latency in clock cycles (``>= 0``).
    """

    multipliers: tuple[tuple[int, int], ...] = ()
    adders: tuple[int, ...] = ()
    sqrts: tuple[int, ...] = ()
    dividers: tuple[int, ...] = ()
    mux_bits: int = 0
    rom_bits: int = 0
    latency: int = 0

    @property
    def area(self) -> float:
        """The area estimate in full-adder equivalents (module docstring)."""
        return float(sum(a * b for a, b in self.multipliers) + sum(self.adders)
                     + sum(w * w / 2 for w in self.sqrts) + sum(w * w for w in self.dividers)
                     + self.mux_bits / 2 + self.rom_bits / 8)

    def _merge(self, other: "Cost", latency: int) -> "Cost":
        return Cost(self.multipliers + other.multipliers, self.adders + other.adders,
                    self.sqrts + other.sqrts, self.dividers + other.dividers,
                    self.mux_bits + other.mux_bits, self.rom_bits + other.rom_bits, latency)

    def __add__(self, other: "Cost") -> "Cost":
        return self._merge(other, self.latency + other.latency)

    def parallel(self, other: "Cost") -> "Cost":
        """Side by side: resources add, latency is the larger."""
        return self._merge(other, max(self.latency, other.latency))

    def times(self, n: int) -> "Cost":
        """``n`` copies side by side."""
        out = Cost()
        for _ in range(n):
            out = out.parallel(self)
        return out

    def as_dict(self) -> dict:
        """The cost as a plain dict (for JSON), with the area and the counts."""
        return {"multipliers": [f"{a}x{b}" for a, b in self.multipliers],
                "adders": list(self.adders), "sqrts": list(self.sqrts),
                "dividers": list(self.dividers), "mux_bits": self.mux_bits,
                "rom_bits": self.rom_bits, "latency": self.latency, "area_fa": self.area,
                "multiplier_count": len(self.multipliers), "adder_count": len(self.adders)}


@dataclass(frozen=True)
class Block:
    """A named datapath block: its own cost plus its sub-blocks.

    ``serial`` children follow each other (latencies add), otherwise they
    work side by side (the larger latency counts).

    >>> dot = Block("dot", Cost(multipliers=((8, 8),) * 3, adders=(16, 17), latency=3))
    >>> three = Block("3 dots", children=(dot,) * 3, serial=False)
    >>> three.cost.latency, three.cost.area, len(three.cost.multipliers)
    (3, 675.0, 9)
    >>> Block("chain", children=(dot, dot)).cost.latency
    6

    Parameters
    ----------
    name : str
        The block's label in :meth:`lines` and :meth:`as_dict`.
    own : Cost, default Cost()
        The block's own resources, apart from its children.
    children : tuple of Block, default ()
        The sub-blocks.
    serial : bool, default True
        True when the children follow each other (latencies add), False when they work
        side by side (the largest latency counts); resources add either way.
    note : str, default ""
        A remark kept in :meth:`as_dict` (omitted when empty).
    """

    name: str
    own: Cost = field(default_factory=Cost)
    children: tuple["Block", ...] = ()
    serial: bool = True
    note: str = ""

    def _summary(self) -> list[tuple[str, object]]:
        c = self.cost
        return [("name", self.name), ("children", len(self.children)), ("area_fa", c.area),
                ("latency", c.latency)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    @property
    def cost(self) -> Cost:
        """Own cost plus the children's, in series or side by side."""
        inner = Cost()
        for i, c in enumerate(self.children):
            inner = (inner + c.cost) if (self.serial or i == 0) else inner.parallel(c.cost)
        return self.own + inner

    def as_dict(self) -> dict:
        """The block tree as a plain dict (for JSON)."""
        d = {"name": self.name, "cost": self.cost.as_dict()}
        if self.note:
            d["note"] = self.note
        if self.children:
            d["children"] = [c.as_dict() for c in self.children]
        return d

    def lines(self, indent: int = 0, depth: bool = False) -> list[str]:
        """One text line per block of the tree, indented by depth. ``depth=True``
        says the model's latency as how many operations deep the block is (a
        report whose design is combinational states its latency once, in cycles)."""
        c = self.cost
        steps = f"{c.latency} operations deep" if depth else f"latency {c.latency}"
        out = [f"{'  ' * indent}{self.name}: {len(c.multipliers)} mul, {len(c.adders)} add, "
               f"{len(c.sqrts)} sqrt, {len(c.dividers)} div, {c.mux_bits} mux bits, "
               f"{c.rom_bits} ROM bits, {steps}, area ~{c.area:.0f} FA"]
        for ch in self.children:
            out += ch.lines(indent + 1, depth)
        return out
