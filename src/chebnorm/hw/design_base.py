"""What every hardware design of :mod:`chebnorm.hw` is: the :class:`Design`
interface and the registry of architectures by name.

A *design* is a sized, bit-accurate evaluator of one function of an
``in_bits``-bit input code into an ``out_bits``-bit output code. Each
architecture (a Horner evaluator, a piecewise ROM + Horner evaluator, its
sized variant, the exponent-indexed ``1/sqrt``, a plain table, a
multipartite table) is one subclass of :class:`Design`, registered under the
name the CLI and the CSVs print (:func:`register`, :data:`ARCHITECTURES`).
Whatever works on any design (the architecture search, the pruned synthesis
queue, pipelining, the reports, the trust checks) calls the interface and
never asks a design what kind it is.

The interface (abstract: a subclass missing one cannot be instantiated):

* :meth:`Design.evaluate` -- output codes of input codes, bit for bit the circuit;
* :meth:`Design.budget` -- the certified error bound by part;
* :meth:`Design.measure` -- the error over every code, recomputed;
* :meth:`Design.features` -- the cost model's inputs
  (:class:`~chebnorm.hw.target_model.DesignFeatures`);
* :meth:`Design.cut_points` -- names of the positions a pipeline register may
  take (empty: none);
* :meth:`Design.verilog`, :meth:`Design.vhdl`, :meth:`Design.hdl_files` -- the
  HDL text (the module; the module, bench and vectors);
* :meth:`Design.verify` -- re-prove the design's claims;
* :attr:`Design.module_name`.

The normalization units of :mod:`chebnorm.hw.units` are not designs in this
sense: each is a whole multi-port unit (vectors in, vectors out, some
clocked) sized per kind, with its own interface
(:class:`~chebnorm.hw.units.base.UnitKind` and its registry); the polynomial
evaluator inside some of them is a Horner design.

The HDL seam: the three HDL methods print through :mod:`chebnorm.hw.hdl`
today. A design module that :mod:`chebnorm.hw.hdl` itself imports (the Horner
design) cannot import it back (no import cycles), so its printers are handed
to it by a later module through :func:`provide` / :func:`provided`; a netlist
IR replacing the text printers changes those three methods only.

>>> from chebnorm.hw.design_base import ARCHITECTURES, architecture
>>> sorted(ARCHITECTURES)
['exponent', 'horner', 'multipartite', 'piecewise', 'piecewise-sized', 'table']
>>> architecture("table").__name__
'PlainTableDesign'
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from types import MappingProxyType

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

_REGISTRY: dict[str, type] = {}
#: architecture name -> its :class:`Design` subclass (read-only; :func:`~chebnorm.hw.design_base.register` adds)
ARCHITECTURES = MappingProxyType(_REGISTRY)
_PROVIDED: dict[str, object] = {}


class Design(ABC):
    """A sized, bit-accurate hardware evaluator (module docstring): the one
    interface the search, synthesis, pipelining and reports use.

    Attributes
    ----------
    architecture : str
        The architecture's name (a key of :data:`ARCHITECTURES`; the plain
        table's tag is ``"plain_table"``, registered as ``"table"``).
    name : str
        The design's name (its module is ``chebnorm_<name>``).
    in_bits : int
        Width of the input code.
    out_bits : int
        Width of the output code.

    Examples
    --------
    A subclass that leaves out part of the interface cannot be built:

    >>> class Half(Design):
    ...     def evaluate(self, codes=None):
    ...         return codes
    >>> Half()
    Traceback (most recent call last):
    ...
    TypeError: Can't instantiate abstract class Half ...
    """

    architecture: str = ""
    name: str
    in_bits: int
    out_bits: int

    @property
    @abstractmethod
    def module_name(self) -> str:
        """The HDL module's (entity's) name, ``chebnorm_<name>``."""

    @property
    def latency(self) -> int:
        """Clock cycles from input to output (0: combinational)."""
        return 0

    @abstractmethod
    def verify(self) -> "Design":
        """Re-prove the design's claims; return it unchanged, or raise ValueError."""

    @abstractmethod
    def evaluate(self, codes=None):
        """Output codes (int64 array) of the input ``codes`` (default: every
        ``2**in_bits`` code), bit for bit the circuit."""

    @abstractmethod
    def budget(self) -> dict:
        """The certified bound of ``|y - f(x)|`` by part (floats rounded up)."""

    @abstractmethod
    def measure(self) -> dict:
        """The error over every input code, recomputed (rigorous or at high precision)."""

    @abstractmethod
    def features(self):
        """The cost model's inputs
        (:class:`~chebnorm.hw.target_model.DesignFeatures`)."""

    @abstractmethod
    def cut_points(self) -> tuple[str, ...]:
        """Names of the positions a pipeline register may take, position ``i``
        at index ``i`` (empty: the architecture has none)."""

    def cut_plans(self) -> list[tuple[int, ...]]:
        """The cut sets tried by :func:`chebnorm.hw.pipeline.pipeline_to_frequency`,
        one per latency ``1, 2, ...``: here the first ``m`` positions for
        ``m = 1 .. len(cut_points())`` (a subclass may weigh its stages)."""
        return [tuple(range(m)) for m in range(1, len(self.cut_points()) + 1)]

    def with_cuts(self, cuts) -> "Design":
        """The design with registers at the positions ``cuts`` (sorted, no
        duplicates; the same values, ``len(cuts)`` cycles later). Here:
        ValueError, the architecture has no cut points."""
        raise ValueError(f"design: a {type(self).__name__} has no pipeline cut points; "
                         f"accepted: a piecewise design (design_piecewise), a multipartite "
                         f"design or a plain table")

    def combinational(self) -> "Design":
        """The design without pipeline registers (here: itself)."""
        return self

    def state(self) -> dict:
        """The values that define the design, by name (what its digest reads,
        :func:`chebnorm.hw.trust.digest`): a dataclass design's fields."""
        import dataclasses

        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    @abstractmethod
    def verilog(self, *, version: str = "", command: str | None = None) -> str:
        """The Verilog-2005 module, banner first (``version`` and ``command`` stated in it)."""

    @abstractmethod
    def vhdl(self, *, version: str = "", command: str | None = None) -> str:
        """The VHDL-2008 entity and architecture, banner first."""

    @abstractmethod
    def hdl_files(self, language: str = "verilog") -> dict:
        """File name -> text: the module, its exhaustive self-checking bench and
        its vector file in ``language`` (``"verilog"`` or ``"vhdl"``)."""


def register(*names: str):
    """Class decorator: register a :class:`Design` subclass under ``names``.

    Parameters
    ----------
    *names : str
        The architecture names (one or more; each registered once).

    Returns
    -------
    callable
        The decorator (it returns the class unchanged).

    Raises
    ------
    ValueError
        No name, a name taken by another class, or a class that is not a
        :class:`Design`.

    Examples
    --------
    >>> register()
    Traceback (most recent call last):
    ...
    ValueError: names: none given; accepted: one or more architecture names
    """
    if not names:
        raise ValueError("names: none given; accepted: one or more architecture names")

    def add(cls):
        if not (isinstance(cls, type) and issubclass(cls, Design)):
            raise ValueError(f"register: {cls!r} is not a Design subclass")
        for n in names:
            old = _REGISTRY.get(n)
            if old is not None and old.__qualname__ != cls.__qualname__:
                raise ValueError(f"architecture {n!r} is already {old.__name__}")
            _REGISTRY[n] = cls
        return cls

    return add


def architecture_names() -> tuple[str, ...]:
    """The registered architecture names, sorted.

    Returns
    -------
    tuple of str

    Examples
    --------
    >>> import chebnorm.hw
    >>> "multipartite" in architecture_names()
    True
    """
    return tuple(sorted(_REGISTRY))


def architecture(name: str) -> type:
    """The :class:`Design` subclass registered as ``name``.

    Parameters
    ----------
    name : str
        An architecture name (:func:`architecture_names`).

    Returns
    -------
    type
        The design class.

    Raises
    ------
    ValueError
        ``name`` is not registered (the message lists the names).

    Examples
    --------
    >>> import chebnorm.hw
    >>> architecture("piecewise-sized").__name__
    'PiecewiseDesign'
    >>> architecture("cordic")
    Traceback (most recent call last):
    ...
    ValueError: architecture 'cordic': accepted: exponent, horner, multipartite, piecewise, piecewise-sized, table
    """
    cls = _REGISTRY.get(name) if isinstance(name, str) else None
    if cls is None:
        raise ValueError(f"architecture {str(name)[:40]!r}: accepted: "
                         f"{', '.join(architecture_names())}")
    return cls


def provide(role: str, fn) -> None:
    """Hand a function to the designs that cannot import it (the HDL seam of
    the module docstring): ``role`` names what it does, e.g.
    ``"horner.module_text"``.

    Parameters
    ----------
    role : str
        The role's name.
    fn : callable
        The function.

    Examples
    --------
    >>> import chebnorm.hw
    >>> provided("horner.module_text").__name__   # chebnorm.hw provides it on import
    'module_text'
    """
    _PROVIDED[role] = fn


def provided(role: str):
    """The function provided for ``role`` (:func:`provide`).

    Parameters
    ----------
    role : str
        The role's name.

    Returns
    -------
    callable

    Raises
    ------
    RuntimeError
        Nothing was provided: ``chebnorm.hw`` was not imported whole (it
        provides every role on import, before any design exists).

    Examples
    --------
    >>> import chebnorm.hw
    >>> provided("horner.error_budget").__name__
    'error_budget'
    >>> provided("horner.netlist")
    Traceback (most recent call last):
    ...
    RuntimeError: horner.netlist: not provided; import chebnorm.hw (it provides it)
    """
    fn = _PROVIDED.get(role)
    if fn is None:
        raise RuntimeError(f"{role}: not provided; import chebnorm.hw (it provides it)")
    return fn
