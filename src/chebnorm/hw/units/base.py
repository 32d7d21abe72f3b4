"""What every normalization unit shares: ports, the sized design, the
:class:`UnitKind` interface each kind implements, and the registry of kinds
by name.

A kind is one object registered under its name (``"classic"``, ...): it
sizes a design (:meth:`UnitKind.design`), evaluates it bit-accurately
(:meth:`UnitKind.evaluate`), prices it (:meth:`UnitKind.block`), makes its
test rows (:meth:`UnitKind.vector_rows`) and builds its netlist
(:meth:`UnitKind.modules`), printed in Verilog (:meth:`UnitKind.verilog`) and VHDL
(:meth:`UnitKind.vhdl`). Everything else (test bench, vector file, report)
is the same for every kind and dispatches through :func:`get_unit`.

>>> from chebnorm.hw.units import get_unit, unit_names
>>> unit_names()
('dichotomy', 'classic', 'quadratic', 'stepper', 'eta')
>>> get_unit("quadratic").target
'midpoint'
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from chebnorm.approx.method_registry import TableSpec, unit_tables
from chebnorm.core.textsafe import identifier
from chebnorm.core.display import field_rows, summary_html, summary_repr

from ..cost import Block
from ..hdl.netlist import verilog as _verilog
from ..hdl.netlist import vhdl as _vhdl
from ..horner import HornerDesign

# an implementation module of chebnorm.hw.units: the API is what chebnorm.hw.units exports
__all__: list[str] = []

#: widest vector component (``comp_bits``, W) a unit accepts
MAX_COMP_BITS = 28
#: most fractional bits (``frac_bits``, F) of a unit's components
MAX_UNIT_FRAC_BITS = 26
#: largest ``log_m`` of the stepper unit (``2**log_m`` pixels per span)
MAX_LOG_M = 10
#: most guard bits of the stepper unit's set-up
MAX_GUARD = 24
#: input spaces up to this many bits are tested exhaustively
EXHAUSTIVE_BITS = 16


@dataclass(frozen=True)
class Port:
    """One port: ``bits`` wide, two's complement when ``signed``.

    Attributes
    ----------
    name : str
        The Verilog port name (``<vector>_x``, ``skip``, ...).
    bits : int
        Width, ``>= 1``.
    signed : bool, default True
        Two's complement when true.
    output : bool, default False
        An output port when true, else an input.

    Examples
    --------
    >>> Port("n_x", 8), Port("skip", 1, signed=False, output=True).output
    (Port(name='n_x', bits=8, signed=True, output=False), True)
    """

    name: str
    bits: int
    signed: bool = True
    output: bool = False


def vec_ports(name: str, bits: int, output: bool = False,
              signed: bool = True) -> tuple[Port, ...]:
    """The three ports ``<name>_x``, ``<name>_y``, ``<name>_z``.

    Parameters
    ----------
    name : str
        The vector's name.
    bits : int
        Width of each component, ``>= 1``.
    output : bool, default False
        Output ports when true.
    signed : bool, default True
        Two's-complement components.

    Returns
    -------
    tuple of Port
        ``<name>_x``, ``<name>_y``, ``<name>_z``.

    Examples
    --------
    >>> [(p.name, p.bits, p.output) for p in vec_ports("m", 9, output=True)]
    [('m_x', 9, True), ('m_y', 9, True), ('m_z', 9, True)]
    """
    return tuple(Port(f"{name}_{c}", bits, signed, output) for c in "xyz")


@dataclass(frozen=True)
class UnitDesign:
    """A sized normalization unit (see :mod:`chebnorm.hw.units`); ``evaluate``
    is the bit-accurate model, :func:`~chebnorm.hw.units.unit_verilog` its circuit.

    Attributes
    ----------
    kind : str
        The unit's name in the registry (:func:`unit_names`).
    ports : tuple of Port
        Inputs and outputs, in port-list order.
    frac_bits : int
        ``F``: fractional bits of the components, 1 to :data:`MAX_UNIT_FRAC_BITS`.
    comp_bits : int
        ``W``: width of the components, 2 to :data:`MAX_COMP_BITS` (``F + 2`` holds ``[-2, 2)``).
    horner : HornerDesign or None, default None
        The polynomial evaluator (dichotomy, quadratic, eta units); None for the others.
    rounding : {"rne", "trunc"}, default "rne"
        The classic unit's quotient rounding or the evaluator's.
    log_m : int, default 0
        The stepper's span length ``m = 2**log_m``, 0 to :data:`MAX_LOG_M`.
    guard : int, default 0
        The stepper's guard bits, 0 to :data:`MAX_GUARD`.
    sizes : dict of str to int, default {}
        Widths sized by the kind (e.g. ``m_bits``, ``eta_bits``).
    notes : tuple of str, default ()
        Remarks on the sizing, stated in the banner.

    Examples
    --------
    >>> from chebnorm.hw.units import design_unit
    >>> u = design_unit("classic", frac_bits=6)
    >>> u.module_name, [p.name for p in u.inputs], u.comp_bits
    ('chebnorm_classic_unit', ['n_x', 'n_y', 'n_z'], 8)
    >>> out = u.evaluate({"n_x": [3 << 4], "n_y": [4 << 4], "n_z": [0]})   # (0.75, 1, 0): length 1.25
    >>> int(out["u_x"][0]), int(out["u_y"][0]), int(0.6 * 64), int(0.8 * 64)   # floor quotients
    (38, 51, 38, 51)
    """

    kind: str
    ports: tuple[Port, ...]
    frac_bits: int
    comp_bits: int
    horner: HornerDesign | None = None
    rounding: str = "rne"
    log_m: int = 0
    guard: int = 0
    sizes: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    def _summary(self) -> list[tuple[str, object]]:
        return [("kind", self.kind), ("frac_bits", self.frac_bits),
                ("comp_bits", self.comp_bits),
                ("evaluator", None if self.horner is None else self.horner.module_name)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    @property
    def spec(self) -> UnitKind:
        """The registered kind of this unit."""
        return get_unit(self.kind)

    @property
    def module_name(self) -> str:
        return f"chebnorm_{self.kind}_unit"

    @property
    def clocked(self) -> bool:
        return self.spec.clocked

    @property
    def inputs(self) -> tuple[Port, ...]:
        return tuple(p for p in self.ports if not p.output)

    @property
    def outputs(self) -> tuple[Port, ...]:
        return tuple(p for p in self.ports if p.output)

    @property
    def block(self) -> Block:
        """The cost model of the unit (:mod:`chebnorm.hw.datapaths`)."""
        return self.spec.block(self)

    def evaluate(self, inputs: dict) -> dict:
        """Outputs (name -> int64 array) for input arrays (name -> codes); for the
        clocked stepper, one row per cycle, outputs as seen after each edge."""
        g = {k: np.asarray(v, dtype=np.int64) for k, v in inputs.items()}
        return self.spec.evaluate(self, g)


def vec(g: dict, name: str) -> np.ndarray:
    """The ``(..., 3)`` array of ports ``<name>_x``, ``_y``, ``_z`` of ``g``."""
    return np.stack([g[f"{name}_{c}"] for c in "xyz"], axis=-1)


def put(out: dict, name: str, arr: np.ndarray) -> None:
    """Store the ``(..., 3)`` array ``arr`` as ports ``<name>_x``, ``_y``, ``_z``."""
    for i, c in enumerate("xyz"):
        out[f"{name}_{c}"] = arr[..., i]


class UnitKind(ABC):
    """One kind of normalization unit; subclasses fill in the methods and are
    registered once with :func:`~chebnorm.hw.units.base.register`. The methods take valid designs
    (made by their own :meth:`design`) and do not check them again.

    Examples
    --------
    >>> k = get_unit("dichotomy")
    >>> isinstance(k, UnitKind), k.clocked, k.table_spec
    (True, False, TableSpec(target='dichotomy', degree=2, psi_max='pi/4'))
    """

    #: registry name, also the ``<kind>`` of the module ``chebnorm_<kind>_unit``
    name: str = ""
    #: one rising clock edge per row (else combinational)
    clocked: bool = False

    @property
    def table_spec(self) -> TableSpec | None:
        """The table its polynomial evaluator approximates, as the method registry
        declares it (:func:`chebnorm.approx.method_registry.unit_tables`); None
        for a unit without an evaluator."""
        return unit_tables().get(self.name)

    @property
    def target(self) -> str | None:
        """The coefficient-table target of its evaluator, if it has one."""
        spec = self.table_spec
        return None if spec is None else spec.target

    @abstractmethod
    def design(self, f: int, w: int, notes: list[str], *, table, in_bits: int, out_bits: int,
               coef_bits: int | None, rounding: str | None, log_m: int,
               guard: int | None) -> UnitDesign:
        """Size the unit for ``F = f``, ``W = w`` (both already checked)."""

    @abstractmethod
    def evaluate(self, unit: UnitDesign, g: dict) -> dict:
        """Bit-accurate outputs for int64 input arrays ``g`` (name -> codes)."""

    @abstractmethod
    def block(self, unit: UnitDesign) -> Block:
        """The cost model (:mod:`chebnorm.hw.datapaths`)."""

    @abstractmethod
    def vector_rows(self, unit: UnitDesign, rng, count: int) -> dict:
        """Input rows (name -> int64 array) of the test bench, drawn from ``rng``
        (``count`` checked); combinational kinds use
        :func:`~chebnorm.hw.units.bench.combinational_rows`."""

    @abstractmethod
    def modules(self, unit: UnitDesign, *, version: str, command: str | None) -> list:
        """The unit's netlist (:class:`~chebnorm.hw.hdl.netlist.Module`), then the
        modules it instantiates."""

    def verilog(self, unit: UnitDesign, *, version: str, command: str | None) -> str:
        """The Verilog-2005 text of :meth:`modules`, the unit first."""
        return "\n".join(_verilog(m) for m in self.modules(unit, version=version,
                                                            command=command))

    def vhdl(self, unit: UnitDesign, *, version: str, command: str | None) -> str:
        """The VHDL-2008 text of :meth:`modules`, each entity after those it instantiates."""
        return "\n".join(_vhdl(m) for m in reversed(self.modules(unit, version=version,
                                                                  command=command)))


_UNITS: dict[str, UnitKind] = {}
#: name -> registered :class:`UnitKind`, in registration order (read-only)
UNITS = MappingProxyType(_UNITS)


def register(kind: UnitKind) -> UnitKind:
    """Add ``kind`` to the registry under ``kind.name`` (a new identifier).

    Parameters
    ----------
    kind : UnitKind
        The unit kind; its ``name`` must be an identifier not yet registered.

    Returns
    -------
    UnitKind
        ``kind`` (so it can decorate or be assigned).

    Raises
    ------
    ValueError
        If the name is not an identifier or is already registered.

    Examples
    --------
    >>> register(get_unit("classic"))
    Traceback (most recent call last):
    ...
    ValueError: unit 'classic' is already registered
    """
    name = identifier(kind.name, field="unit name")
    if name in _UNITS:
        raise ValueError(f"unit {name!r} is already registered")
    _UNITS[name] = kind
    return kind


def unit_names() -> tuple[str, ...]:
    """The registered unit names, in registration order.

    Returns
    -------
    tuple of str
        The names, in registration order.

    Examples
    --------
    >>> unit_names()
    ('dichotomy', 'classic', 'quadratic', 'stepper', 'eta')
    """
    return tuple(_UNITS)


def get_unit(name: str) -> UnitKind:
    """The registered unit ``name``; ValueError naming the accepted names.

    Parameters
    ----------
    name : str
        A registered unit name (:func:`unit_names`).

    Returns
    -------
    UnitKind
        The unit kind.

    Raises
    ------
    ValueError
        If ``name`` is not registered (the message lists the accepted names).

    Examples
    --------
    >>> get_unit("eta").target
    'eta_term'
    >>> get_unit("nope")
    Traceback (most recent call last):
    ...
    ValueError: unit 'nope' is unknown; accepted: dichotomy, classic, quadratic, stepper, eta
    """
    try:
        return _UNITS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unit {name!r} is unknown; accepted: {', '.join(_UNITS)}") from None
