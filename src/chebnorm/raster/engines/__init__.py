"""Rendering engines: one interface (:class:`~chebnorm.raster.engines.base.Engine`), two
implementations with the same image bytes: :mod:`.numpy` (the reference) and
:mod:`.numba` (compiled, optional).  ``render`` picks one with :func:`get_engine`.
"""

from __future__ import annotations

from .base import Engine, FrameUnsupported
from .numba import NumbaEngine
from .numba.jit import HAVE_NUMBA
from .numba.jit import JIT_DISABLED
from .numpy import NumpyEngine

__all__ = ["ENGINES", "HAVE_NUMBA", "Engine", "FrameUnsupported", "resolve_engine",
           "get_engine"]

#: accepted values of ``render(engine=...)``
ENGINES = ("auto", "numpy", "numba")

_ENGINES = {"numpy": NumpyEngine(), "numba": NumbaEngine()}


def resolve_engine(engine) -> str:
    """``"numpy"`` or ``"numba"``: what ``engine`` (``"auto"``, None, ``"numpy"``,
    ``"numba"``) means here; ``"numba"`` without numba installed (or with
    ``NUMBA_DISABLE_JIT=1``) is an error.

    Parameters
    ----------
    engine : str or None
        ``"auto"``, None, ``"numpy"`` or ``"numba"``.

    Returns
    -------
    str
        ``"numpy"`` or ``"numba"``.

    Raises
    ------
    ValueError
        For another name, or ``"numba"`` without numba installed or with its compiler
        turned off (``NUMBA_DISABLE_JIT=1``).

    Examples
    --------
    >>> resolve_engine("numpy")
    'numpy'
    """
    if engine is None:
        engine = "auto"
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r}; accepted: {', '.join(ENGINES)}")
    if engine == "auto":
        return "numba" if HAVE_NUMBA else "numpy"
    if engine == "numba" and JIT_DISABLED:
        raise ValueError("engine 'numba' needs numba's compiler, which NUMBA_DISABLE_JIT turns "
                         "off; accepted with it: auto, numpy")
    if engine == "numba" and not HAVE_NUMBA:
        raise ValueError("engine 'numba' needs the numba package (pip install numba); "
                         "accepted without it: auto, numpy")
    return engine


def get_engine(engine="auto") -> Engine:
    """The engine ``render(engine=...)`` means (see :func:`resolve_engine`).

    Parameters
    ----------
    engine : {"auto", "numpy", "numba"} or None
        ``"auto"`` (and None): numba when installed, else numpy.

    Returns
    -------
    Engine
        The engine object (one per process and name).

    >>> get_engine("numpy").name
    'numpy'
    """
    return _ENGINES[resolve_engine(engine)]
