"""Polynomial fits: Chebyshev interpolation (mpmath) and the Remez exchange.

Both return float64 coefficients in ascending powers of the *original*
variable; the certified bounds are computed afterwards for exactly those
floats (:mod:`chebnorm.approx.certify`). Internal module: callers validate.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Callable

import mpmath
import numpy as np
from numpy.polynomial import chebyshev as C

__all__ = ["chebyshev_interpolant", "remez", "RemezResult", "cheb_to_monomial", "shift_for",
           "polish"]


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


def cheb_to_monomial(cheb: np.ndarray, lo: float, hi: float, center: float = 0.0,
                     scale: float = 1.0) -> list[float]:
    """Convert a Chebyshev series in ``u = (2x - lo - hi)/(hi - lo)`` to
    ascending monomial coefficients in ``t = (x - center)/scale`` (by default
    ``t = x``), exactly in rationals, then rounded once to float.

    On an interval far from 0 or narrow, the plain monomials in ``x`` are
    ill-conditioned (the coefficients are huge and cancel); with ``center``
    the midpoint and ``scale`` the half-width, ``|t| <= 1`` and the rounding
    costs about what the Chebyshev coefficients themselves do.

    ``T_2(u) = 2 u^2 - 1``; on ``[0, 2]``, ``u = x - 1`` and
    ``T_2 = 2 x^2 - 4 x + 1``; in ``t = x - 1`` it stays ``2 t^2 - 1``:

    >>> cheb_to_monomial([0.0, 0.0, 1.0], -1.0, 1.0), cheb_to_monomial([0.0, 0.0, 1.0], 0.0, 2.0)
    ([-1.0, 0.0, 2.0], [1.0, -4.0, 2.0])
    >>> cheb_to_monomial([0.0, 0.0, 1.0], 0.0, 2.0, center=1.0, scale=1.0)
    [-1.0, 0.0, 2.0]
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
    in_t = [Fraction(0)] * n  # monomial coefficients in u
    for k, ck in enumerate(cheb):
        exact = _exact(ck)
        for i, c in enumerate(t_polys[k]):
            in_t[i] += exact * c
    # substitute u = alpha t + beta (x = center + scale t)
    lo_f, hi_f = Fraction(float(lo)), Fraction(float(hi))
    c_f, s_f = Fraction(float(center)), Fraction(float(scale))
    alpha = 2 * s_f / (hi_f - lo_f)
    beta = (2 * c_f - lo_f - hi_f) / (hi_f - lo_f)
    out = [Fraction(0)] * n
    power = [Fraction(1)]  # (alpha t + beta)^i, ascending in t
    for i in range(n):
        for j, c in enumerate(power):
            out[j] += in_t[i] * c
        nxt = [Fraction(0)] * (len(power) + 1)
        for j, c in enumerate(power):
            nxt[j] += beta * c
            nxt[j + 1] += alpha * c
        power = nxt
    return [float(c) for c in out]


def _exact(v) -> Fraction:
    """A float or an mpmath number as an exact rational."""
    if isinstance(v, mpmath.mpf):
        if not mpmath.isfinite(v):
            raise ValueError(f"coefficient {v} is not finite")
        sign, man, exp, _ = v._mpf_  # man_exp drops the sign
        return (-1) ** sign * Fraction(int(man)) * Fraction(2) ** int(exp)
    return Fraction(float(v))


def shift_for(lo: float, hi: float) -> tuple[float, float]:
    """``(c, s)`` of the shifted variable ``t = (x - c)/s`` on ``[lo, hi]``:
    ``c`` the float midpoint, ``s`` the smallest power of two at least the
    half-width, so ``|t| <= 1`` and dividing by ``s`` is exact.

    >>> shift_for(1e6, 1e6 + 1)
    (1000000.5, 0.5)
    """
    c = 0.5 * lo + 0.5 * hi
    half = max(c - lo, hi - c)
    s = math.ldexp(1.0, math.frexp(half)[1]) if half > 0 else 1.0
    if s / 2 >= half:
        s /= 2
    return c, s


class RemezResult:
    """Result of :func:`remez`: ``cheb``, the Chebyshev-basis coefficients in
    the mapped variable ``t in [-1, 1]``; ``levelled``, the equioscillation
    level; ``max_error``, the largest error on the grid; ``iterations``,
    ``converged``, the final reference ``ref`` and ``noise_limited``."""

    def __init__(self, cheb: np.ndarray, levelled: float, max_error: float, iterations: int,
                 converged: bool, ref: np.ndarray | None = None, noise_limited: bool = False):
        self.cheb = cheb
        self.levelled = levelled
        self.max_error = max_error
        self.iterations = iterations
        self.converged = converged
        #: the reference (points in the mapped variable) the coefficients solve
        self.ref = ref
        #: True when the error is so close to float64's resolution of ``w f``
        #: that the float64 solve limits it (see :func:`polish`)
        self.noise_limited = noise_limited


def _clenshaw(t: np.ndarray, c: np.ndarray) -> np.ndarray:
    """``sum c_k T_k(t)`` by Clenshaw's recurrence (numpy's ``chebval``
    without its per-call checks, which dominate on short arrays)."""
    if len(c) == 1:
        return np.full_like(t, c[0])
    b1 = np.zeros_like(t)
    b2 = np.zeros_like(t)
    t2 = 2 * t
    for ck in c[:0:-1]:
        b1, b2 = ck + t2 * b1 - b2, b1
    return c[0] + t * b1 - b2


def _unit(x):
    return np.ones_like(x)


def _local_extrema(t: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Indices of local extrema of ``e`` on the grid (ends included)."""
    d = np.diff(e)
    inner = np.nonzero((d[:-1] * d[1:] <= 0) & ((d[:-1] != 0) | (d[1:] != 0)))[0] + 1
    return np.unique(np.concatenate([[0], inner, [len(t) - 1]]))


def _refine(t_grid, idx, e_idx, err_fn, points: int = 16, rounds: int = 1):
    """Refine grid extrema of ``|e|`` by successive local grids (vectorized
    over extrema, one ``err_fn`` call per round) and a final parabola
    through the best point and its neighbours; end points stay put.
    Returns the points and their errors.

    Each round samples ``points`` points across the bracket around every
    extremum and shrinks the bracket to two spacings around the largest, so
    after ``rounds`` rounds the location is known to ``(2/points)**rounds``
    of the grid spacing; the parabola then gains two more orders (the error
    is flat to second order at an interior extremum, so its value is exact
    to float64 rounding). ``e_idx`` are the errors at the grid extrema.
    """
    i = np.asarray(idx)
    last = len(t_grid) - 1
    inner = (i > 0) & (i < last)
    lo = np.where(inner, t_grid[np.maximum(i - 1, 0)], t_grid[i])
    hi = np.where(inner, t_grid[np.minimum(i + 1, last)], t_grid[i])
    s = np.linspace(0.0, 1.0, points)
    rows = np.arange(len(i))
    best_x = t_grid[i]
    best_e = np.asarray(e_idx, dtype=float)
    for _ in range(rounds):
        x = lo[:, None] + (hi - lo)[:, None] * s[None, :]
        e = err_fn(x.ravel()).reshape(x.shape)
        k = np.argmax(np.abs(e), axis=1)
        better = np.abs(e[rows, k]) > np.abs(best_e)
        best_x = np.where(better, x[rows, k], best_x)
        best_e = np.where(better, e[rows, k], best_e)
        step = (hi - lo) / (points - 1)
        lo = np.where(inner, np.maximum(lo, best_x - step), lo)
        hi = np.where(inner, np.minimum(hi, best_x + step), hi)
    # parabola through (lo, mid, hi) of |e| around the best point
    h = 0.5 * (hi - lo)
    ok = inner & (h > 0)
    if ok.any():
        m = 0.5 * (lo + hi)
        ea = np.abs(err_fn(np.stack([lo, m, hi]).ravel())).reshape(3, -1)
        den = ea[0] - 2 * ea[1] + ea[2]
        with np.errstate(divide="ignore", invalid="ignore"):
            v = m + 0.5 * h * (ea[0] - ea[2]) / den
        v = np.where(ok & (den < 0) & (v > lo) & (v < hi), v, best_x)
        ev = err_fn(v)
        better = np.abs(ev) > np.abs(best_e)
        best_x = np.where(better, v, best_x)
        best_e = np.where(better, ev, best_e)
    return best_x, best_e


def remez(f: Callable[[np.ndarray], np.ndarray], weight: Callable[[np.ndarray], np.ndarray] | None,
          lo: float, hi: float, degree: int, max_iter: int = 60, rtol: float = 1e-8
          ) -> RemezResult:
    """Minimax fit of ``f`` minimizing ``max |w (p - f)|`` on ``[lo, hi]``.

    Works in the Chebyshev basis of the mapped variable ``t in [-1, 1]``
    (well conditioned), in float64. Stops when the levelled error and the
    largest error agree to ``rtol`` (de la Vallee Poussin gap), or once
    they agree to the float64 noise floor of ``w f`` and an exchange no
    longer lowers the largest error.
    ``weight=None`` is the constant 1 (absolute error), without its calls.

    The best line to ``x^2`` on ``[0, 1]`` is ``x - 1/8`` (error ``1/8``,
    equioscillating at 0, 1/2, 1); with ``x = (t + 1)/2`` it is
    ``3/8 + t/2``:

    >>> import numpy as np
    >>> r = remez(lambda x: x**2, np.ones_like, 0.0, 1.0, 1)
    >>> [round(float(c), 9) for c in r.cheb], round(float(r.levelled), 9), r.converged
    ([0.375, 0.5], 0.125, True)
    """
    n = degree
    if weight is None:
        weight = _unit
    to_x = lambda t: 0.5 * (hi - lo) * t + 0.5 * (hi + lo)
    grid_n = max(4000, 200 * (n + 2))
    t_grid = np.cos(np.pi * np.arange(grid_n, -1, -1) / grid_n)
    f_grid = f(to_x(t_grid))
    v_grid = C.chebvander(t_grid, n)  # the grid values are one matrix product
    w_grid = weight(to_x(t_grid))
    # float64 noise floor of the error: a gap below a few roundings of w f
    # cannot shrink further, so it counts as converged
    floor = 8 * np.finfo(float).eps * float(np.max(np.abs(w_grid * f_grid)))
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
            e = _clenshaw(t, cheb) - f(x)
            return e if weight is _unit else weight(x) * e

        e_grid = v_grid @ cheb - f_grid
        if weight is not _unit:
            e_grid *= w_grid
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
        keep_p, keep_v = _refine(t_grid, keep, e_grid[keep], err_fn)
        max_err = float(max(np.max(np.abs(keep_v)), np.max(np.abs(e_grid))))
        E = min(E, float(np.min(np.abs(keep_v)))) if len(keep) == n + 2 else E
        improved = best is None or max_err < best.max_error
        if improved:
            best = RemezResult(cheb.copy(), E, max_err, it, False, ref.copy())
        if max_err - E <= rtol * max_err:
            best = RemezResult(cheb.copy(), E, max_err, it, True, ref.copy())
            break
        if max_err - E <= floor:
            # at the noise floor: keep exchanging only while it still helps
            best.converged = True
            if not improved:
                break
        if len(keep_p) < n + 2:
            break
        ref = np.array(keep_p)
    if best is not None:
        best.noise_limited = best.max_error <= NOISE_LIMIT * floor / 8
    return best


#: a float64 Remez answer whose error is below ``NOISE_LIMIT`` roundings of
#: ``max |w f|`` has lost digits to the float64 solve: :func:`polish` it
NOISE_LIMIT = 2.0 ** 10


def polish(f_mp: Callable, lo: float, hi: float, ref: np.ndarray, degree: int,
           relative: bool = False, dps: int = 50) -> list:
    """Re-solve the levelled Remez system on the reference ``ref`` (points of
    the mapped variable in ``[-1, 1]``) in ``dps``-digit mpmath arithmetic.

    Returns the Chebyshev coefficients as mpmath numbers (pass them to
    :func:`cheb_to_monomial`, which converts them exactly). Used when the
    float64 exchange is limited by float64's own resolution of ``f``: the
    reference it found is still a good one, only its solve is not.

    The best line to ``x^2`` on ``[0, 1]`` solved at its reference 0, 1/2, 1
    (``t = -1, 0, 1``) is ``3/8 + t/2`` exactly:

    >>> [float(c) for c in polish(lambda x: x**2, 0.0, 1.0, [-1.0, 0.0, 1.0], 1)]
    [0.375, 0.5]
    """
    n = degree
    with mpmath.workdps(dps):
        lo_m, hi_m = mpmath.mpf(lo), mpmath.mpf(hi)
        rows, rhs = [], []
        for i, u in enumerate(ref):
            u = mpmath.mpf(float(u))
            x = (hi_m - lo_m) / 2 * u + (hi_m + lo_m) / 2
            fx = f_mp(x)
            t = [mpmath.mpf(1), u]
            while len(t) < n + 1:
                t.append(2 * u * t[-1] - t[-2])
            sign = 1 if i % 2 == 0 else -1
            rows.append(t[: n + 1] + [sign * (abs(fx) if relative else 1)])
            rhs.append(fx)
        sol = mpmath.lu_solve(mpmath.matrix(rows), mpmath.matrix(rhs))
        return [sol[k] for k in range(n + 1)]
