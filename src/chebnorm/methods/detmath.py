"""Elementary functions whose results do not depend on the CPU: the same bits on every x86-64.

numpy >= 2 picks its float32 ``sin``/``cos``/``exp``/``log`` loops by CPU group
(``X86_V4`` AVX-512, ``X86_V3`` AVX2, baseline), and on AVX-512 machines also
its float64 ``arccos``, ``arctan2``, ``power``, ``log10``, ... (SVML). Those
loops are accurate to an ulp or so but not correctly rounded, and they round
differently from one another, so a float32 figure computed with ``np.sin``
changes with the machine. The functions here do not:

* **float32** arguments give the *correctly rounded* float32 result (what an
  ideal float32 datapath computes). The function is evaluated in float64
  (any numpy loop: all are within a few float64 ulps, i.e. ~2^-50 relative),
  rounded once to float32; where that float64 value lies within 2^-16 of a
  float32 ulp from a rounding boundary (a tie between two float32 values;
  about 3 arguments in 100 000) or the result is a power of two or zero, the
  value is recomputed with mpmath at 160 bits and rounded once to 24 bits.
  Both paths give the correctly rounded value, so the result is the same
  whichever numpy loop ran.
* **float64** arguments are evaluated element by element with :mod:`math`
  (the C library's ``sin``, ``cos``, ``acos``, ``atan2``, ``pow``, ``log2``),
  never with a SIMD-dispatched numpy loop. (On x86-64 machines with or without
  AVX2 numpy's float64 loops agree with :mod:`math`; on AVX-512 machines they
  may not: on an AMD Zen 5 with numpy 2.4, ``power``, ``arccos``, ``arctan2``,
  ``exp``, ``log``, ``log2``, ``log10``, ``tan`` and ``arctan`` differ from the
  C library in up to a few percent of arguments, scalars included; ``sin``,
  ``cos`` and ``sqrt`` do not.)

Sums and products (``+ - * /``, ``sqrt``) are correctly rounded in every
numpy loop and need nothing here; :func:`powers` gives ``x, x^2, ..., x^n``
by multiplications only for the same reason.

>>> import numpy as np
>>> x = np.float32([0.1, 0.7853982, 3.0])
>>> sin(x).dtype, bool((sin(x) == np.float32([math.sin(v) for v in x.tolist()])).all())
(dtype('float32'), True)
>>> float(arccos(np.float64([0.5]))[0]) == math.acos(0.5)
True
>>> powers(np.array([2.0]), 4).tolist()
[[2.0, 4.0, 8.0, 16.0]]
>>> float(power(np.float64([0.9]), 32.0)[0]) == math.pow(0.9, 32.0)
True
"""

from __future__ import annotations

import math

import mpmath
import numpy as np

from chebnorm.core import clib

# an implementation module of chebnorm.methods: the API is what chebnorm.methods exports
__all__: list[str] = []

#: float32 results within this fraction of a float32 ulp of a rounding boundary are recomputed
_TIE_MARGIN = 2.0 ** -16
#: working precision (bits) of the mpmath recomputation
_MP_BITS = 160
_F64 = {"sin": math.sin, "cos": math.cos, "arccos": math.acos}
_MP = {"sin": mpmath.sin, "cos": mpmath.cos, "arccos": mpmath.acos}
_NP = {"sin": np.sin, "cos": np.cos, "arccos": np.arccos}


def _mp_float32(name: str, x: float) -> np.float32:
    """``name(x)`` correctly rounded to float32 (x a float32 value, result a normal float32 or 0)."""
    with mpmath.workprec(_MP_BITS):
        v = _MP[name](mpmath.mpf(x))
    if isinstance(v, mpmath.mpc) or not mpmath.isfinite(v):
        return np.float32(np.nan)
    with mpmath.workprec(24):
        v = +v  # one rounding, to nearest (ties to even), to the 24-bit significand
    return np.float32(float(v))


def _float64(name: str, x: np.ndarray) -> np.ndarray:
    return clib.elementwise(_F64[name], x)   # math.acos outside [-1, 1]: NaN, as numpy


def _float32(name: str, x: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        y = _NP[name](x.astype(np.float64))
    r = y.astype(np.float32)
    r64 = r.astype(np.float64)
    ulp = np.abs(np.spacing(r)).astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = np.abs(y - r64) / ulp                       # in [0, 1/2] away from powers of two
    mant = np.frexp(r)[0]
    hard = np.isfinite(y) & ((np.abs(frac - 0.5) < _TIE_MARGIN) | (np.abs(mant) == 0.5) | (r == 0))
    if hard.any():
        idx = np.flatnonzero(hard.ravel())
        flat = r.ravel().copy()
        xs = x.ravel()
        for i in idx:
            flat[i] = _mp_float32(name, float(xs[i]))
        r = flat.reshape(r.shape)
    return r


def _apply(name: str, x):
    arr = np.asarray(x)
    if arr.dtype == np.float32:
        out = _float32(name, arr)
    else:
        out = _float64(name, arr.astype(np.float64, copy=False))
    return out if isinstance(x, np.ndarray) or out.ndim else out.dtype.type(out)


def sin(x):
    """``sin(x)``: float32 correctly rounded, float64 by the C library (see the module docstring).

    Parameters
    ----------
    x : numpy.ndarray or numpy scalar
        Angles (radians), float32 or float64.

    Returns
    -------
    numpy.ndarray or numpy scalar
        ``sin(x)`` in the dtype of ``x`` and its shape.

    Examples
    --------
    >>> import mpmath
    >>> x = np.float32(0.7)
    >>> bool(sin(x) == np.float32(mpmath.sin(mpmath.mpf(float(x))))), sin(x).dtype
    (True, dtype('float32'))
    """
    return _apply("sin", x)


def cos(x):
    """``cos(x)``: float32 correctly rounded, float64 by the C library.

    Parameters
    ----------
    x : numpy.ndarray or numpy scalar
        Angles (radians), float32 or float64.

    Returns
    -------
    numpy.ndarray or numpy scalar
        ``cos(x)`` in the dtype of ``x`` and its shape.

    Examples
    --------
    >>> cos(np.array([0.0, np.pi])).tolist(), cos(np.float32(0.0)).dtype
    ([1.0, -1.0], dtype('float32'))
    """
    return _apply("cos", x)


def arccos(x):
    """``arccos(x)``: float32 correctly rounded, float64 by the C library; NaN outside [-1, 1].

    Parameters
    ----------
    x : numpy.ndarray or numpy scalar
        Cosines, float32 or float64.

    Returns
    -------
    numpy.ndarray or numpy scalar
        ``arccos(x)`` in the dtype of ``x`` and its shape.

    Examples
    --------
    >>> arccos(np.array([1.0, -1.0, 2.0])).tolist()
    [0.0, 3.141592653589793, nan]
    """
    return _apply("arccos", x)


def arctan2(y, x) -> np.ndarray:
    """``arctan2(y, x)`` in float64 by the C library's ``atan2``, element by element.

    Parameters
    ----------
    y, x : array_like
        float64 coordinates; they broadcast.

    Returns
    -------
    numpy.ndarray
        The angles in ``[-pi, pi]`` (radians).

    Examples
    --------
    >>> arctan2(np.array([1.0, -1.0]), np.array([1.0, 0.0])).tolist() == [math.pi / 4, -math.pi / 2]
    True
    """
    y, x = np.broadcast_arrays(np.asarray(y, dtype=np.float64), np.asarray(x, dtype=np.float64))
    flat = np.fromiter(map(math.atan2, y.ravel().tolist(), x.ravel().tolist()), dtype=np.float64,
                       count=y.size)
    return flat.reshape(y.shape)


def power(x, y: float) -> np.ndarray:
    """``x ** y`` (float64, ``y`` a real scalar) as numpy's ``**`` computes it where its
    float64 power loop is the C library's ``pow`` (x86-64 without AVX-512): ``y`` = 2,
    0.5, -1, 1, 0 by ``square``, ``sqrt``, ``reciprocal``, a copy and ones (correctly
    rounded), any other ``y`` by ``pow`` element by element (:func:`chebnorm.core.clib.power`).

    Parameters
    ----------
    x : array_like
        float64 bases.
    y : float
        The exponent.

    Returns
    -------
    numpy.ndarray
        ``x ** y``, the same bits on every x86-64 CPU.

    Examples
    --------
    >>> power(np.array([0.5, 2.0]), 3.0).tolist(), power(np.array([3.0]), 2.0).tolist()
    ([0.125, 8.0], [9.0])
    >>> x = np.linspace(0.0, 1.0, 1001)
    >>> power(x, 31.9).tolist() == [math.pow(v, 31.9) for v in x]
    True
    """
    return clib.power(x, float(y))


def log2(x) -> np.ndarray:
    """``log2(x)`` in float64 by the C library, element by element: ``-inf`` at 0,
    NaN below 0, as numpy.

    Parameters
    ----------
    x : array_like
        float64 values.

    Returns
    -------
    numpy.ndarray
        ``log2(x)`` element by element.

    Examples
    --------
    >>> log2(np.array([8.0, 0.0, -1.0, np.inf])).tolist()
    [3.0, -inf, nan, inf]
    """
    return clib.elementwise(math.log2, x, numpy_fn=np.log2)


def powers(x, n: int) -> np.ndarray:
    """``x^1 .. x^n`` along a new last axis by binary powering: ``x^k`` is the product, in a
    fixed order, of the squarings ``x^(2^i)`` for the bits of ``k`` (at most ``2 log2 n``
    correctly rounded multiplications; a rounding of ``x^j`` moves ``x^k`` by ``k/j`` of it,
    so the result is within ``(k - 1)/2`` ulp of the exact ``x^k``).

    Parameters
    ----------
    x : numpy.ndarray
        float64 values.
    n : int
        The highest power, ``n >= 1``.

    Returns
    -------
    numpy.ndarray
        Shape ``x.shape + (n,)``: ``[..., k-1]`` is ``x^k``.

    Examples
    --------
    >>> powers(np.array([2.0, 0.5]), 5).tolist()
    [[2.0, 4.0, 8.0, 16.0, 32.0], [0.5, 0.25, 0.125, 0.0625, 0.03125]]
    """
    x = np.asarray(x)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n = {n!r}; accepted: an integer n >= 1")
    k = np.arange(1, int(n) + 1)
    out = np.ones(x.shape + (int(n),), dtype=np.result_type(x, np.float32))
    sq = x
    for bit in range(int(n).bit_length()):
        sel = (k >> bit) & 1 == 1
        out[..., sel] *= sq[..., None]
        sq = sq * sq
    return out
