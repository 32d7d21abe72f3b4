"""float64 elementary functions from the C library, element by element.

numpy picks its float64 loops for ``exp``, ``log``, ``power``, ``arccos``,
``arctan``, ``tan``, ``sinh``, ... by CPU: on x86-64 machines without AVX-512
they call the C library, on AVX-512 machines they are SVML, whose results
differ from the C library's in the last bit for a few percent of arguments
(measured on an AMD Zen 5 with numpy 2.4; ``sin``, ``cos``, ``sqrt`` and the
arithmetic agree). A Remez exchange run on those values converges to other
coefficients, so a fit would write other bytes on another machine.

The functions here evaluate with :mod:`math` (the C library) element by element,
whatever the CPU, so they give numpy's bits of a machine without AVX-512. They are
slower than numpy's loops (about 30 ns an element): for the exchange's grids
and the checks, not for images. Where the C library raises (a domain or range
error), the element takes numpy's value (a NaN, an infinity or zero, which every
loop gives exactly).

Internal: no input checking; the arguments are converted to float64.

>>> import numpy as np
>>> FUNCTIONS["exp"](np.array([0.0, 1.0])).tolist() == [1.0, math.exp(1.0)]
True
>>> FUNCTIONS["log"](np.array([0.0, -1.0])).tolist()[0], power(np.array([4.0]), 0.5).tolist()
(-inf, [2.0])
"""

from __future__ import annotations

import itertools
import math

import numpy as np


def elementwise(fn, x, *args: float, numpy_fn=None) -> np.ndarray:
    """``fn(v, *args)`` (a :mod:`math` function, scalar ``args``) for every element of
    ``x`` as float64, in x's shape. Where ``fn`` raises, the element is
    ``numpy_fn(v, *args)``, or NaN without ``numpy_fn``.

    Parameters
    ----------
    fn : callable
        A float64 function of one float and the ``args`` (``math.atan2``, ``math.pow``).
    x : array_like
        The values, converted to float64.
    *args : float
        Further scalar arguments, the same for every element.
    numpy_fn : callable, optional
        The fallback where ``fn`` raises ``ValueError`` or ``OverflowError``
        (a numpy ufunc giving NaN or an infinity); NaN when omitted.

    Returns
    -------
    numpy.ndarray
        float64 values in ``x``'s shape.

    Examples
    --------
    >>> elementwise(math.atan2, np.array([[1.0, -1.0]]), 1.0).shape
    (1, 2)
    """
    x = np.asarray(x, dtype=np.float64)
    flat = x.ravel().tolist()
    try:
        out = np.fromiter(map(fn, flat, *(itertools.repeat(a) for a in args)),
                          dtype=np.float64, count=len(flat))
    except (ValueError, OverflowError):
        def safe(v):
            try:
                return fn(v, *args)
            except (ValueError, OverflowError):
                if numpy_fn is None:
                    return math.nan
                with np.errstate(all="ignore"):
                    return float(numpy_fn(np.float64(v), *args))
        out = np.fromiter(map(safe, flat), dtype=np.float64, count=len(flat))
    return out.reshape(x.shape)


#: the exponents numpy's ``**`` operator computes without its power loop (numpy's
#: ``fast_scalar_power``): the same functions here, so :func:`power` keeps ``**``'s bits
_FAST_POWER = {2.0: np.square, 0.5: np.sqrt, -1.0: np.reciprocal, 1.0: np.positive,
               0.0: np.ones_like}


def _pow(a: float, b: float) -> float:
    try:
        return math.pow(a, b)
    except (ValueError, OverflowError):  # a negative base, a non-integer exponent; overflow
        with np.errstate(all="ignore"):
            return float(np.power(np.float64(a), np.float64(b)))


def power(x, y) -> np.ndarray:
    """``x ** y`` in float64 as numpy's ``**`` computes it where its float64 power loop is
    the C library's ``pow``: a scalar ``y`` of 2, 0.5, -1, 1, 0 by ``square``, ``sqrt``,
    ``reciprocal``, a copy and ones (correctly rounded, as numpy), everything else by
    ``pow`` element by element (``x`` and ``y`` broadcast). NaN where ``x < 0`` and ``y``
    is not an integer, infinities where the power overflows, as numpy.

    Parameters
    ----------
    x : array_like
        Bases (float64).
    y : array_like
        Exponents, broadcast against ``x``.

    Returns
    -------
    numpy.ndarray
        float64 ``x ** y`` in the broadcast shape, the same bits on every CPU.

    Examples
    --------
    >>> power(np.array([0.5, 2.0]), 3).tolist(), power(2.0, np.array([0.5, 10.0])).tolist()
    ([0.125, 8.0], [1.4142135623730951, 1024.0])
    >>> x = np.linspace(0.0, 1.0, 101)
    >>> power(x, 31.9).tolist() == [math.pow(v, 31.9) for v in x]
    True
    """
    x = np.asarray(x, dtype=np.float64)
    if np.ndim(y) == 0:
        y = float(y)
        if y in _FAST_POWER:
            return _FAST_POWER[y](x)
        return elementwise(math.pow, x, y, numpy_fn=np.power)
    x, y = np.broadcast_arrays(x, np.asarray(y, dtype=np.float64))
    xs, ys = x.ravel().tolist(), y.ravel().tolist()
    try:  # math.pow itself where no element raises (2^x on a grid), else element by element
        out = np.fromiter(map(math.pow, xs, ys), dtype=np.float64, count=x.size)
    except (ValueError, OverflowError):
        out = np.fromiter(map(_pow, xs, ys), dtype=np.float64, count=x.size)
    return out.reshape(x.shape)


def _unary(fn, numpy_fn):
    def f(x):
        return elementwise(fn, x, numpy_fn=numpy_fn)
    f.__name__ = fn.__name__
    f.__doc__ = f"``{fn.__name__}`` of the C library, element by element (float64)."
    return f


#: sympy function name -> its float64 C-library version (numpy's answer where the C
#: library raises): every elementary function an expression may use (expr.FUNCTIONS)
#: but ``sqrt`` and ``abs``, which are correctly rounded in every loop
FUNCTIONS = {name: _unary(getattr(math, c), getattr(np, n)) for name, c, n in (
    ("exp", "exp", "exp"), ("log", "log", "log"), ("sin", "sin", "sin"), ("cos", "cos", "cos"),
    ("tan", "tan", "tan"), ("asin", "asin", "arcsin"), ("acos", "acos", "arccos"),
    ("atan", "atan", "arctan"), ("sinh", "sinh", "sinh"), ("cosh", "cosh", "cosh"),
    ("tanh", "tanh", "tanh"), ("asinh", "asinh", "arcsinh"), ("acosh", "acosh", "arccosh"),
    ("atanh", "atanh", "arctanh"))}
