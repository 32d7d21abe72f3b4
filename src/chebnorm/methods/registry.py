"""The methods' half of the method registry: kernels bound, default tables fitted.

The entries themselves live in :mod:`chebnorm.approx.method_registry` (one
per method, read by every stage); this module resolves each entry's span
kernel (:func:`method_kernel`, :func:`method_kernels`) and fits the tables
the kernels read when the caller gives none (:func:`default_tables`, the one
place chebnorm fits them).

>>> sorted(method_kernels())[:3]
['angular', 'dichotomy', 'exact']
>>> method_kernel("dichotomy").shape
'tree'
"""

from __future__ import annotations

import importlib
from functools import lru_cache

from chebnorm.approx import CoefficientTable, fit_target
# the registry lives in chebnorm.approx; the modules of this stage read it through here
from chebnorm.approx.method_registry import (MethodSpec, TableSpec, get_method,  # noqa: F401
                                             method_names, register, registered_methods,
                                             unit_tables, unregister)

from .kernels import SHAPES

# an implementation module of chebnorm.methods: the API is what chebnorm.methods exports
__all__: list[str] = []

_REQUIRED = {"direct": ("setup", "pixel"), "steps": ("steps",),
             "tree": ("tree", "fraction", "pick")}


def _resolve(spec: MethodSpec):
    kernel = spec.kernel
    if isinstance(kernel, str):
        module, _, attr = kernel.partition(":")
        try:
            kernel = getattr(importlib.import_module(module), attr)
        except (ImportError, AttributeError) as exc:
            raise ValueError(f"method {spec.name!r}: kernel {spec.kernel!r} cannot be "
                             f"loaded ({exc})") from None
    shape = getattr(kernel, "shape", None)
    if shape not in SHAPES:
        raise ValueError(f"method {spec.name!r}: kernel {kernel!r} has shape {shape!r}; "
                         f"accepted: {', '.join(SHAPES)} (see chebnorm.methods.kernels)")
    missing = [a for a in _REQUIRED[shape] if not callable(getattr(kernel, a, None))]
    if missing:
        raise ValueError(f"method {spec.name!r}: {shape} kernel {kernel!r} lacks "
                         f"{', '.join(missing)}")
    return kernel


@lru_cache(maxsize=None)
def _kernel_of(spec: MethodSpec):
    return _resolve(spec)


def method_kernel(method: str | MethodSpec):
    """The span kernel object of ``method`` (a name or a registry entry).

    Parameters
    ----------
    method : str or MethodSpec
        A registered method's name or its registry entry.

    Returns
    -------
    object
        The kernel: an object with a ``shape`` (``"direct"``, ``"steps"``, ``"tree"``)
        and the functions that compute the span.

    Raises
    ------
    ValueError
        For an unknown method, naming the registered ones.

    Examples
    --------
    >>> k = method_kernel("dichotomy")
    >>> k.shape, k.table_scale
    ('tree', 2.0)
    >>> method_kernel("quadratic").shape
    'steps'
    """
    spec = method if isinstance(method, MethodSpec) else get_method(method)
    return _kernel_of(spec)


def method_kernels() -> dict:
    """Every registered method's span kernel: ``{name: kernel}``.

    Returns
    -------
    dict of str to object
        Every registered method's name and kernel.

    Examples
    --------
    >>> sorted({k.shape for k in method_kernels().values()})
    ['direct', 'steps', 'tree']
    """
    return {s.name: _kernel_of(s) for s in registered_methods()}


def table_methods() -> dict[str, TableSpec]:
    """The methods that read a coefficient table, and the table each reads.

    Returns
    -------
    dict of str to TableSpec
        Method name -> the table it reads (target, degree, ``psi_max``).

    Examples
    --------
    >>> sorted(table_methods())
    ['dichotomy', 'quadratic']
    >>> all(t == get_method(m).table for m, t in table_methods().items())   # the registry's own
    True
    """
    return {s.name: s.table for s in registered_methods() if s.table is not None}


@lru_cache(maxsize=None)
def _fit(target: str, degree: int, psi_max) -> CoefficientTable:
    return fit_target(target, degree, psi_max=psi_max)


def default_tables(psi_max: float | str | None = None,
                   degree: int | None = None) -> dict[str, CoefficientTable]:
    """The tables used when ``span_normals`` gets none: for each method with a
    table (:func:`table_methods`), ``fit_target(target, degree, psi_max=psi_max)``,
    None meaning the registered degree (2) and ``psi_max`` (``"pi/4"``).
    Each table is fitted once per process and argument.

    Parameters
    ----------
    psi_max : float or str, optional
        The largest span angle the tables must cover (radians, or sympy text such as ``"pi/4"``).
    degree : int, optional
        The polynomial degree (default: each method's registered degree).

    Returns
    -------
    dict of str to CoefficientTable
        The table of each method that reads one (``dichotomy``, ``quadratic``).

    Raises
    ------
    ValueError
        For an invalid ``psi_max`` or ``degree`` (as :func:`chebnorm.approx.fit_target`).

    Examples
    --------

    Examples
    --------
    >>> t = default_tables()
    >>> [round(c, 5) for c in t["dichotomy"].coefficients]
    [0.68076, -0.11881, 0.01422]
    >>> t["quadratic"].name
    'midpoint_d2'
    """
    return {m: _fit(spec.target, spec.degree if degree is None else degree,
                    spec.psi_max if psi_max is None else psi_max)
            for m, spec in table_methods().items()}
