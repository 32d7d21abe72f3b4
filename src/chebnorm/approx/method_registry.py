"""The method registry: one entry per normalization method, read by every stage.

A method (seed 000's span interpolators) is declared here once: what it
does, where the papers define it, the coefficient table its kernel reads
(target name, degree, ``psi_max``), its span kernel, the hardware units
(:mod:`chebnorm.hw.units` names) that implement it, its C benchmark kernel
and the curve its pixels ideally follow. Nothing else in chebnorm keeps a
list of methods or a method -> target map: :mod:`chebnorm.methods` binds
the kernels and fits the default tables from these entries, ``chebnorm.hw``
reads the unit -> table map (:func:`unit_tables`), the rasterizer, the CLI
and the benchmarks list :func:`method_names`.

Why here, in ``approx``: ``methods`` and ``hw`` are sibling stages and both
need the method -> target pairing, so it lives in the earliest stage every
consumer may import. The span kernel is therefore named by a dotted
reference (``"chebnorm.methods.kernels:DICHOTOMY"``), resolved by
:func:`chebnorm.methods.method_kernel`; a method registered at run time may
pass the kernel object itself.

Adding a method: one :func:`register` call (or one entry in
:data:`_BUILTIN`) plus its kernel (see :mod:`chebnorm.methods.kernels` for
the three kernel shapes).

>>> method_names()[:3]
('exact', 'none', 'newton')
>>> get_method("dichotomy").table
TableSpec(target='dichotomy', degree=2, psi_max='pi/4')
>>> unit_tables()["quadratic"].target
'midpoint'
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from .targets import get_target

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

#: the curves a method's pixels ideally lie on: the exactly normalized linear
#: interpolant, or the slerp points (evenly spaced in angle)
IDEALS = ("linear", "slerp")
_NAME = re.compile(r"[a-z][a-z0-9_]*\Z")
_DOTTED = re.compile(r"[A-Za-z_][\w.]*:[A-Za-z_]\w*\Z")


@dataclass(frozen=True)
class TableSpec:
    """The coefficient table a kernel reads: ``fit_target(target, degree, psi_max=psi_max)``.

    Parameters
    ----------
    target : str
        A registered target name (:func:`chebnorm.approx.get_target`).
    degree : int, optional
        The degree of the fit, default 2.
    psi_max : str, optional
        The largest span angle, an exact expression in radians, default
        ``"pi/4"``.

    Examples
    --------
    >>> TableSpec("rsqrt", 3)
    TableSpec(target='rsqrt', degree=3, psi_max='pi/4')
    """

    target: str
    degree: int = 2
    psi_max: str = "pi/4"


@dataclass(frozen=True)
class MethodSpec:
    """One normalization method.

    ``name``: what users type (``--method``); ``summary``: what it computes;
    ``seed``: where the papers define it (e.g. ``"seed 000, method 4"``);
    ``kernel``: the span kernel, an object or a ``"module:attribute"``
    reference (:mod:`chebnorm.methods.kernels`); ``table``: the table the
    kernel reads (None: no table); ``units``: the :mod:`chebnorm.hw.units`
    unit names implementing it, the first one evaluating ``table``;
    ``c_kernel``: its kernel in ``benchmarks/c/kernels.h`` (None: none);
    ``ideal``: ``"linear"`` or ``"slerp"`` (see :data:`IDEALS`).

    Parameters
    ----------
    name : str
        Lower-case letters, digits and ``_``, starting with a letter.
    summary : str
        One line saying what the method computes.
    seed : str
        Where the papers define it.
    kernel : object
        The span kernel, or its ``"module:attribute"`` reference (resolved on
        use).
    table : TableSpec or None, optional
        The table the kernel reads; default None (no table).
    units : tuple of str, optional
        The hardware unit names, default ``()``.
    c_kernel : str or None, optional
        The C benchmark kernel, default None.
    ideal : {"linear", "slerp"}, optional
        What the method's error is measured against, default ``"linear"``.

    Examples
    --------
    >>> s = get_method("quadratic")
    >>> s.seed, s.table.target, s.units
    ('seed 000, method 5', 'midpoint', ('quadratic', 'stepper'))
    """

    name: str
    summary: str
    seed: str
    kernel: object
    table: TableSpec | None = None
    units: tuple[str, ...] = ()
    c_kernel: str | None = None
    ideal: str = "linear"


_K = "chebnorm.methods.kernels:"
_BUILTIN = (
    MethodSpec("exact", "linear interpolation, then N / sqrt(N.N) (reference)",
               "seed 000, classic", _K + "EXACT", units=("classic",), c_kernel="classic"),
    MethodSpec("none", "linear interpolation, not normalized", "seed 003", _K + "NONE",
               c_kernel="none"),
    MethodSpec("newton", "one Newton-Raphson step N (3 - N.N) / 2", "seed 000, method 1",
               _K + "NEWTON", c_kernel="newton"),
    MethodSpec("lyon", "N (15 - 10 N.N + 3 (N.N)^2) / 8", "seed 000, method 2", _K + "LYON",
               c_kernel="lyon"),
    MethodSpec("slerp", "[sin((1-t) psi) N_l + sin(t psi) N_r] / sin psi", "seed 000, method 3",
               _K + "SLERP", c_kernel="slerp", ideal="slerp"),
    MethodSpec("dichotomy", "angle halving, (N_1 + N_2) p(z), p ~ 1/sqrt(2+z)",
               "seed 000, method 4", _K + "DICHOTOMY", table=TableSpec("dichotomy"),
               units=("dichotomy",), c_kernel="dichotomy", ideal="slerp"),
    MethodSpec("quadratic", "quadratic through N_l, N_c, N_r, forward differences",
               "seed 000, method 5", _K + "QUADRATIC", table=TableSpec("midpoint"),
               units=("quadratic", "stepper"), c_kernel="quadratic"),
    MethodSpec("angular", "N_{j+1} = 2 cos(phi) N_j - N_{j-1}", "seed 000, method 6",
               _K + "ANGULAR", c_kernel="angular", ideal="slerp"),
)
#: hardware units that belong to no span method: the eta criterion of adaptive
#: shading (seed 003), whose evaluator approximates one edge term of eta
_UNIT_ONLY_TABLES = {"eta": TableSpec("eta_term")}

_REGISTRY: dict[str, MethodSpec] = {}


def _check_spec(spec) -> MethodSpec:
    if not isinstance(spec, MethodSpec):
        raise ValueError(f"register() takes a MethodSpec; got {type(spec).__name__}")
    if not isinstance(spec.name, str) or not _NAME.match(spec.name):
        raise ValueError(f"method name {spec.name!r} is not accepted; accepted: lower-case "
                         f"letters, digits and '_', starting with a letter")
    if isinstance(spec.kernel, str) and not _DOTTED.match(spec.kernel):
        raise ValueError(f"method {spec.name!r}: kernel reference {spec.kernel!r}; accepted: "
                         f"'package.module:attribute' or a kernel object")
    if spec.table is not None:
        if not isinstance(spec.table, TableSpec):
            raise ValueError(f"method {spec.name!r}: table is a {type(spec.table).__name__}; "
                             f"accepted: a TableSpec or None")
        get_target(spec.table.target)  # raises for an unknown target
    if spec.ideal not in IDEALS:
        raise ValueError(f"method {spec.name!r}: ideal {spec.ideal!r}; accepted: "
                         f"{', '.join(IDEALS)}")
    if not all(isinstance(u, str) and u for u in spec.units):
        raise ValueError(f"method {spec.name!r}: units {spec.units!r}; accepted: unit names")
    return spec


def register(spec: MethodSpec, *, replace: bool = False) -> MethodSpec:
    """Add ``spec`` to the registry (``replace=True`` to redefine a name).

    Parameters
    ----------
    spec : MethodSpec
        The method; its name, kernel reference, table, ideal and units are
        checked.
    replace : bool, optional
        Allow redefining a registered name (keyword only); default False.

    Returns
    -------
    MethodSpec
        ``spec``, as registered.

    Raises
    ------
    ValueError
        When ``spec`` is not a :class:`MethodSpec`, a field is not accepted (the
        error names it), its table names an unknown target, or the name is taken
        and ``replace`` is False.

    Examples
    --------
    >>> s = register(MethodSpec("toy_doc", "copy N_l", "none", "mymodule:KERNEL"))
    >>> "toy_doc" in method_names()
    True
    >>> unregister("toy_doc")
    """
    spec = _check_spec(spec)
    if spec.name in _REGISTRY and not replace:
        raise ValueError(f"method {spec.name!r} is already registered; pass replace=True "
                         f"to redefine it")
    _REGISTRY[spec.name] = spec
    return spec


def unregister(name: str) -> None:
    """Remove a method registered at run time (the built-in eight stay).

    Parameters
    ----------
    name : str
        A method registered with :func:`register`.

    Raises
    ------
    ValueError
        When ``name`` is built in or not registered.

    Examples
    --------
    >>> s = register(MethodSpec("toy_unreg", "copy N_l", "none", "mymodule:KERNEL"))
    >>> unregister("toy_unreg")
    >>> "toy_unreg" in method_names()
    False
    >>> unregister("dichotomy")
    Traceback (most recent call last):
    ...
    ValueError: method 'dichotomy' is built in and cannot be removed
    """
    if name in {s.name for s in _BUILTIN}:
        raise ValueError(f"method {name!r} is built in and cannot be removed")
    get_method(name)
    del _REGISTRY[name]


def get_method(name) -> MethodSpec:
    """The entry of method ``name``; the one check of a method name in chebnorm.

    Parameters
    ----------
    name : str
        A registered method name (:func:`method_names`).

    Returns
    -------
    MethodSpec
        Its registry entry.

    Raises
    ------
    ValueError
        When ``name`` is not registered (or not a string), listing the
        registered names.

    Examples
    --------
    >>> get_method("nope")
    Traceback (most recent call last):
    ...
    ValueError: unknown method 'nope'; accepted: exact, none, newton, lyon, slerp, dichotomy, quadratic, angular
    """
    try:
        return _REGISTRY[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown method {name!r}; accepted: {', '.join(_REGISTRY)}") from None


def method_names() -> tuple[str, ...]:
    """The registered methods, in the order the papers and the CLI list them.

    Returns
    -------
    tuple of str
        The names.

    Examples
    --------
    >>> method_names()
    ('exact', 'none', 'newton', 'lyon', 'slerp', 'dichotomy', 'quadratic', 'angular')
    """
    return tuple(_REGISTRY)


def registered_methods() -> tuple[MethodSpec, ...]:
    """Every registry entry, in :func:`method_names` order.

    Returns
    -------
    tuple of MethodSpec
        The entries.

    Examples
    --------
    >>> [s.name for s in registered_methods() if s.table is not None]
    ['dichotomy', 'quadratic']
    """
    return tuple(_REGISTRY.values())


def unit_tables() -> dict[str, TableSpec]:
    """Hardware unit name -> the table its polynomial evaluator approximates (units
    without an evaluator are absent): the first unit of every method with a table,
    and the units that belong to no method (``eta``).

    Returns
    -------
    dict of str to TableSpec
        Unit name -> its table.

    Examples
    --------
    >>> sorted(unit_tables())
    ['dichotomy', 'eta', 'quadratic']
    >>> unit_tables()["eta"]
    TableSpec(target='eta_term', degree=2, psi_max='pi/4')
    """
    out = {s.units[0]: s.table for s in _REGISTRY.values() if s.units and s.table is not None}
    out.update(_UNIT_ONLY_TABLES)
    return out


for _spec in _BUILTIN:
    register(_spec)
del _spec
