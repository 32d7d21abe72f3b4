"""Polynomial fits: Chebyshev interpolation (mpmath) and the Remez exchange.

Both return float64 coefficients in ascending powers of the *original*
variable; the certified bounds are computed afterwards for exactly those
floats (:mod:`chebnorm.approx.certify`). Internal module: callers validate.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Callable

import mpmath
import numpy as np
from numpy.polynomial import chebyshev as C

__all__ = ["chebyshev_interpolant", "remez", "RemezResult", "cheb_to_monomial"]


def chebyshev_interpolant(f_mp: Callable, lo, hi, degree: int, dps: int = 40) -> list[float]:
    """Interpolant at the ``degree + 1`` Chebyshev nodes, by ``mpmath.chebyfit``.

    ``f_mp`` takes and returns mpmath numbers; ``lo``/``hi`` are mpmath-able.
    Returns ascending float coefficients.

    A polynomial of degree at most ``degree`` is its own interpolant:

    >>> [round(c, 12) + 0.0 for c in chebyshev_interpolant(lambda x: 3 * x**2 - x, 0, 1, 2)]
    [0.0, -1.0, 3.0]
    """
    with mpmath.workdps(dps):
        coeffs = mpmath.chebyfit(f_mp, [mpmath.mpf(lo), mpmath.mpf(hi)], degree + 1)
        return [float(c) for c in reversed(coeffs)]


def cheb_to_monomial(cheb: np.ndarray, lo: float, hi: float) -> list[float]:
    """Convert a Chebyshev series in ``t = (2x - lo - hi)/(hi - lo)`` to
    ascending monomial coefficients in ``x``, exactly in rationals, then
    rounded once to float.

    ``T_2(t) = 2 t^2 - 1``; on ``[0, 2]``, ``t = x - 1`` and
    ``T_2 = 2 x^2 - 4 x + 1``:

    >>> cheb_to_monomial([0.0, 0.0, 1.0], -1.0, 1.0), cheb_to_monomial([0.0, 0.0, 1.0], 0.0, 2.0)
    ([-1.0, 0.0, 2.0], [1.0, -4.0, 2.0])
    """
    n = len(cheb)
    # monomial coefficients in t, exactly: T_0 = 1, T_1 = t, T_k = 2t T_{k-1} - T_{k-2}
    t_polys = [[Fraction(1)], [Fraction(0), Fraction(1)]]
    for k in range(2, n):
        prev, prev2 = t_polys[-1], t_polys[-2]
        cur = [Fraction(0)] + [2 * c for c in prev]
        for i, c in enumerate(prev2):
            cur[i] -= c
        t_polys.append(cur)
    in_t = [Fraction(0)] * n
    for k, ck in enumerate(cheb):
        for i, c in enumerate(t_polys[k]):
            in_t[i] += Fraction(float(ck)) * c
    # substitute t = alpha x + beta
    lo_f, hi_f = Fraction(float(lo)), Fraction(float(hi))
    alpha = 2 / (hi_f - lo_f)
    beta = -(lo_f + hi_f) / (hi_f - lo_f)
    out = [Fraction(0)] * n
    power = [Fraction(1)]  # (alpha x + beta)^i, ascending in x
    for i in range(n):
        for j, c in enumerate(power):
            out[j] += in_t[i] * c
        nxt = [Fraction(0)] * (len(power) + 1)
        for j, c in enumerate(power):
            nxt[j] += beta * c
            nxt[j + 1] += alpha * c
        power = nxt
    return [float(c) for c in out]


class RemezResult:
    """Result of :func:`remez`: ``cheb``, the Chebyshev-basis coefficients in
    the mapped variable ``t in [-1, 1]``; ``levelled``, the equioscillation
    level; ``max_error``, the largest error on the grid; ``iterations`` and
    ``converged``."""

    def __init__(self, cheb: np.ndarray, levelled: float, max_error: float, iterations: int,
                 converged: bool):
        self.cheb = cheb
        self.levelled = levelled
        self.max_error = max_error
        self.iterations = iterations
        self.converged = converged


def _local_extrema(t: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Indices of local extrema of ``e`` on the grid (ends included)."""
    d = np.diff(e)
    inner = np.nonzero((d[:-1] * d[1:] <= 0) & ((d[:-1] != 0) | (d[1:] != 0)))[0] + 1
    return np.unique(np.concatenate([[0], inner, [len(t) - 1]]))


def _refine(t_grid, idx, err_fn):
    """Golden-section refinement of grid extrema of |e| (vectorized over
    extrema); end points stay put. Returns the points and their errors."""
    i = np.asarray(idx)
    inner = (i > 0) & (i < len(t_grid) - 1)
    lo = np.where(inner, t_grid[np.maximum(i - 1, 0)], t_grid[i])
    hi = np.where(inner, t_grid[np.minimum(i + 1, len(t_grid) - 1)], t_grid[i])
    g = 0.6180339887498949
    x1 = hi - g * (hi - lo)
    x2 = lo + g * (hi - lo)
    f1, f2 = np.abs(err_fn(x1)), np.abs(err_fn(x2))
    for _ in range(24):  # golden section, one evaluation per step, vectorized
        left = f1 > f2
        hi = np.where(left, x2, hi)
        lo = np.where(left, lo, x1)
        x1n = np.where(left, hi - g * (hi - lo), x2)
        x2n = np.where(left, x1, lo + g * (hi - lo))
        fe = np.abs(err_fn(np.where(left, x1n, x2n)))
        f1, f2 = np.where(left, fe, f2), np.where(left, f1, fe)
        x1, x2 = x1n, x2n
    x = 0.5 * (lo + hi)
    base = t_grid[i]
    better = np.abs(err_fn(x)) > np.abs(err_fn(base))
    pts = np.where(better, x, base)
    return pts, err_fn(pts)


def remez(f: Callable[[np.ndarray], np.ndarray], weight: Callable[[np.ndarray], np.ndarray],
          lo: float, hi: float, degree: int, max_iter: int = 60, rtol: float = 1e-8
          ) -> RemezResult:
    """Minimax fit of ``f`` minimizing ``max |w (p - f)|`` on ``[lo, hi]``.

    Works in the Chebyshev basis of the mapped variable ``t in [-1, 1]``
    (well conditioned), in float64. Stops when the levelled error and the
    largest error agree to ``rtol`` (de la Vallee Poussin gap).

    The best line to ``x^2`` on ``[0, 1]`` is ``x - 1/8`` (error ``1/8``,
    equioscillating at 0, 1/2, 1); with ``x = (t + 1)/2`` it is
    ``3/8 + t/2``:

    >>> import numpy as np
    >>> r = remez(lambda x: x**2, np.ones_like, 0.0, 1.0, 1)
    >>> [round(float(c), 9) for c in r.cheb], round(float(r.levelled), 9), r.converged
    ([0.375, 0.5], 0.125, True)
    """
    n = degree
    to_x = lambda t: 0.5 * (hi - lo) * t + 0.5 * (hi + lo)
    grid_n = max(4000, 200 * (n + 2))
    t_grid = np.cos(np.pi * np.arange(grid_n, -1, -1) / grid_n)
    f_grid = f(to_x(t_grid))
    w_grid = weight(to_x(t_grid))
    ref = np.cos(np.pi * np.arange(n + 1, -1, -1) / (n + 1))
    signs = (-1.0) ** np.arange(n + 2)
    best = None
    for it in range(1, max_iter + 1):
        x_ref = to_x(ref)
        A = np.empty((n + 2, n + 2))
        A[:, : n + 1] = C.chebvander(ref, n)
        A[:, n + 1] = signs / weight(x_ref)
        try:
            sol = np.linalg.solve(A, f(x_ref))
        except np.linalg.LinAlgError:
            break
        cheb, E = sol[: n + 1], abs(sol[n + 1])

        def err_fn(t, cheb=cheb):
            x = to_x(t)
            return weight(x) * (C.chebval(t, cheb) - f(x))

        e_grid = w_grid * (C.chebval(t_grid, cheb) - f_grid)
        idx = _local_extrema(t_grid, e_grid)
        # merge consecutive same-sign extrema, keeping the larger
        keep = [idx[0]]
        for k in idx[1:]:
            if np.sign(e_grid[k]) == np.sign(e_grid[keep[-1]]):
                if abs(e_grid[k]) > abs(e_grid[keep[-1]]):
                    keep[-1] = k
            else:
                keep.append(k)
        while len(keep) > n + 2:  # drop the smaller end: keeps alternation and the max
            if abs(e_grid[keep[0]]) < abs(e_grid[keep[-1]]):
                keep.pop(0)
            else:
                keep.pop()
        keep_p, keep_v = _refine(t_grid, keep, err_fn)
        max_err = float(max(np.max(np.abs(keep_v)), np.max(np.abs(e_grid))))
        E = min(E, float(np.min(np.abs(keep_v)))) if len(keep) == n + 2 else E
        if best is None or max_err < best.max_error:
            best = RemezResult(cheb.copy(), E, max_err, it, False)
        if max_err - E <= rtol * max_err:
            best = RemezResult(cheb.copy(), E, max_err, it, True)
            break
        if len(keep_p) < n + 2:
            break
        ref = np.array(keep_p)
    return best
