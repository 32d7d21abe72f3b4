"""Small dense linear algebra in a fixed order of operations, whatever the CPU.

numpy's ``@``/``dot`` and ``numpy.linalg`` call OpenBLAS/LAPACK, which pick
their kernels by CPU at run time (``DYNAMIC_ARCH``): on an AMD Zen 4 with
AVX-512 OpenBLAS runs its SkylakeX kernels, on a Zen 5 or an AVX2 machine its
Haswell/Zen ones, and a matrix-vector product or an LU solve sums in another
order, so a Remez exchange converged to coefficients ~1e-13 apart (measured
here: the committed ``rsqrt_d3`` table's minimax coefficients differed between
``OPENBLAS_CORETYPE=SkylakeX`` and ``Haswell``). The functions here use only
element-wise numpy arithmetic (each operation correctly rounded, the same on
every SIMD path) in an order fixed by this code.

Internal: no input checking; arguments are float64 arrays of matching shapes.

>>> import numpy as np
>>> a = np.array([[2.0, 1.0], [1.0, 3.0]])
>>> solve(a, np.array([3.0, 5.0])).tolist()
[0.8, 1.4]
>>> matvec(a, np.array([1.0, -1.0])).tolist()
[1.0, -2.0]
"""

from __future__ import annotations

import numpy as np


def matvec(a: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``a @ x`` over the last axis of ``a``, summed from the first column to the
    last (``(..., m) x (m,) -> (...)``).

    Parameters
    ----------
    a : numpy.ndarray
        float64 array of shape ``(..., m)``.
    x : numpy.ndarray
        float64 vector of length ``m``.

    Returns
    -------
    numpy.ndarray
        ``sum_j a[..., j] * x[j]`` of shape ``a.shape[:-1]``, added in the order
        ``j = 0, 1, ..., m - 1`` (no BLAS: the same bits on every CPU).

    Examples
    --------
    >>> matvec(np.array([[1.0, 2.0], [3.0, 4.0]]), np.array([1.0, 1.0])).tolist()
    [3.0, 7.0]"""
    a = np.asarray(a, dtype=float)
    x = np.asarray(x, dtype=float)
    out = a[..., 0] * x[0]
    for k in range(1, x.shape[0]):
        out = out + a[..., k] * x[k]
    return out


def solve(a: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """The solution of ``a y = b`` (``a`` square, ``b`` a vector) by Gaussian
    elimination with partial pivoting (the first largest pivot wins a tie), or
    None when a pivot is zero or the result is not finite (singular).

    Parameters
    ----------
    a : numpy.ndarray
        float64 matrix of shape ``(n, n)``.
    b : numpy.ndarray
        float64 right-hand side of length ``n``.

    Returns
    -------
    numpy.ndarray or None
        The solution ``y`` (length ``n``), computed in a fixed order without
        LAPACK (the same bits on every CPU); None when ``a`` is singular.

    Examples
    --------
    >>> solve(np.array([[2.0, 0.0], [0.0, 4.0]]), np.array([1.0, 1.0])).tolist()
    [0.5, 0.25]
    >>> solve(np.zeros((2, 2)), np.ones(2)) is None
    True"""
    m = np.array(a, dtype=float)
    y = np.array(b, dtype=float)
    n = m.shape[0]
    for k in range(n):
        p = k + int(np.argmax(np.abs(m[k:, k])))
        if m[p, k] == 0.0:
            return None
        if p != k:
            m[[k, p]] = m[[p, k]]
            y[[k, p]] = y[[p, k]]
        if k + 1 < n:
            factors = m[k + 1:, k] / m[k, k]
            m[k + 1:, k:] = m[k + 1:, k:] - factors[:, None] * m[k, k:]
            y[k + 1:] = y[k + 1:] - factors * y[k]
    rows, rhs, out = m.tolist(), y.tolist(), [0.0] * n   # Python floats: IEEE doubles
    for k in range(n - 1, -1, -1):
        acc = rhs[k]
        for j in range(k + 1, n):
            acc = acc - rows[k][j] * out[j]
        out[k] = acc / rows[k][k]
    res = np.array(out)
    return res if np.all(np.isfinite(res)) else None
