"""Polynomial fits: Chebyshev interpolation (mpmath) and the Remez exchange.

Both return float64 coefficients in ascending powers of the *original*
variable; the certified bounds are computed afterwards for exactly those
floats (:mod:`chebnorm.approx.certify`). Internal module: callers validate.
"""

from __future__ import annotations

import functools
import math
from typing import Callable

import mpmath
import numpy as np
from flint import arb, arb_mat, arb_poly, fmpq, fmpq_poly, fmpz_poly
from numpy.polynomial import chebyshev as C

from chebnorm.core import clib, detlinalg
from chebnorm.core.numeric import arb_precision

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []


def chebyshev_interpolant(f_mp: Callable, lo, hi, degree: int, dps: int = 40) -> list[float]:
    """Interpolant at the ``degree + 1`` Chebyshev nodes, by ``mpmath.chebyfit``.

    ``f_mp`` takes and returns mpmath numbers; ``lo``/``hi`` are mpmath-able.
    Returns ascending float coefficients.

    A polynomial of degree at most ``degree`` is its own interpolant:

    Parameters
    ----------
    f_mp : callable
        ``f``, taking and returning mpmath numbers.
    lo, hi : float, int or mpmath number
        The interval, ``lo < hi``.
    degree : int
        The degree, >= 0; the interpolant uses ``degree + 1`` nodes.
    dps : int, optional
        The decimal digits of the mpmath working precision, default 40.

    Returns
    -------
    list of float
        The ``degree + 1`` monomial coefficients in ``x``, ascending, each
        rounded once to float64.

    Examples
    --------
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

    Parameters
    ----------
    cheb : array_like of float or mpmath numbers
        The Chebyshev coefficients ``c_k`` of ``sum c_k T_k(u)``, ascending; each
        finite and taken exactly.
    lo, hi : float
        The interval that maps to ``u in [-1, 1]``, ``lo < hi``.
    center : float, optional
        The ``c`` of ``t = (x - c)/s``, default 0.
    scale : float, optional
        The ``s`` of ``t = (x - c)/s``, nonzero; default 1.

    Returns
    -------
    list of float
        ``len(cheb)`` coefficients in powers of ``t``, ascending, each the exact
        rational coefficient rounded once to the nearest float64.

    Raises
    ------
    ValueError
        When a coefficient is not finite.

    Examples
    --------
    >>> cheb_to_monomial([0.0, 0.0, 1.0], -1.0, 1.0), cheb_to_monomial([0.0, 0.0, 1.0], 0.0, 2.0)
    ([-1.0, 0.0, 2.0], [1.0, -4.0, 2.0])
    >>> cheb_to_monomial([0.0, 0.0, 1.0], 0.0, 2.0, center=1.0, scale=1.0)
    [-1.0, 0.0, 2.0]
    """
    n = len(cheb)
    if n == 0:
        return []
    series = fmpq_poly([])
    for k, ck in enumerate(cheb):
        series += exact_rational(ck) * chebyshev_t(k)
    # substitute u = alpha t + beta (x = center + scale t), exactly
    lo_q, hi_q = exact_rational(float(lo)), exact_rational(float(hi))
    c_q, s_q = exact_rational(float(center)), exact_rational(float(scale))
    alpha = 2 * s_q / (hi_q - lo_q)
    beta = (2 * c_q - lo_q - hi_q) / (hi_q - lo_q)
    coeffs = series(fmpq_poly([beta, alpha])).coeffs()
    # int / int is correctly rounded in Python, as Fraction's float() is
    return [int(c.p) / int(c.q) for c in coeffs] + [0.0] * (n - len(coeffs))


@functools.lru_cache(maxsize=None)
def chebyshev_t(k: int) -> fmpq_poly:
    """``T_k`` with exact rational coefficients."""
    return fmpq_poly(fmpz_poly.chebyshev_t(k))


def exact_rational(v) -> fmpq:
    """A float or an mpmath number as an exact rational."""
    if isinstance(v, mpmath.mpf):
        if not mpmath.isfinite(v):
            raise ValueError(f"coefficient {v} is not finite")
        sign, man, exp, _ = v._mpf_  # man_exp drops the sign
        man, exp = (-1) ** sign * int(man), int(exp)
        return fmpq(man * 2 ** exp) if exp >= 0 else fmpq(man, 2 ** -exp)
    if isinstance(v, fmpq):
        return v
    num, den = float(v).as_integer_ratio()  # raises on inf and nan
    return fmpq(num, den)


def shift_for(lo: float, hi: float) -> tuple[float, float]:
    """``(c, s)`` of the shifted variable ``t = (x - c)/s`` on ``[lo, hi]``:
    ``c`` the float midpoint, ``s`` the smallest power of two at least the
    half-width, so ``|t| <= 1`` and dividing by ``s`` is exact.

    Parameters
    ----------
    lo, hi : float
        The interval, finite floats with ``lo < hi``.

    Returns
    -------
    tuple of float
        ``(c, s)``: the midpoint ``(lo + hi)/2`` rounded to float64, and the
        power of two ``s >= max(hi - c, c - lo)``.

    Examples
    --------
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
    ``converged``, the final reference ``ref`` and ``noise_limited``.

    Parameters
    ----------
    cheb : numpy.ndarray
        The Chebyshev-basis coefficients in ``t``, ascending.
    levelled : float
        The equioscillation level ``|h|`` of the last solve.
    max_error : float
        The largest weighted error found on the grid.
    iterations : int
        The number of exchanges done.
    converged : bool
        Whether ``levelled`` and ``max_error`` agree to ``rtol`` (or to the
        float64 noise floor).
    ref : numpy.ndarray, optional
        The final reference (``degree + 2`` points of ``t``); default None.
    noise_limited : bool, optional
        Whether float64's resolution of ``w f`` limited the solve; default False.
    """

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


def _unit(x):
    return np.ones_like(x)


@functools.lru_cache(maxsize=32)
def _grid(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The exchange's search grid for degree ``n`` (cached, read-only):
    angles ``theta`` (uniform, from pi down to 0), the points
    ``t = cos(theta)`` (the Chebyshev extreme points, ascending) and the
    Vandermonde matrix ``T_k(t)``, so the error on the grid is one product."""
    grid_n = max(4000, 200 * (n + 2))
    theta = np.pi * np.arange(grid_n, -1, -1) / grid_n
    t = np.cos(theta)
    v = C.chebvander(t, n)
    for a in (theta, t, v):
        a.flags.writeable = False
    return theta, t, v


def _sign_runs(e: np.ndarray) -> tuple[list[int], np.ndarray]:
    """Index of the largest ``|e|`` in each maximal run of one sign (zero
    counts as positive), ascending: alternating in sign, and each the
    largest extremum of its run (consecutive same-sign extrema merged into
    the larger). Returns them and ``|e|``."""
    pos = e >= 0
    change = (pos[1:] != pos[:-1]).nonzero()[0] + 1
    a = np.abs(e)
    if len(change) < 64:  # the usual case: a few runs, a few slices (methods: no wrappers)
        bounds = [0, *change.tolist(), len(e)]
        return [s + int(a[s:t].argmax()) for s, t in zip(bounds[:-1], bounds[1:])], a
    run = np.zeros(len(e), dtype=np.intp)
    run[change] = 1
    run = np.cumsum(run)
    hit = np.flatnonzero(a == np.maximum.reduceat(a, np.concatenate(([0], change)))[run])
    first = np.ones(len(hit), dtype=bool)
    first[1:] = run[hit[1:]] != run[hit[:-1]]
    return hit[first].tolist(), a


def _trim(idx: list[int], vals: list[float], m: int) -> tuple[list[int], list[float]]:
    """Keep ``m`` consecutive entries of ``idx`` (and of their ``vals``),
    dropping the end with the smaller value one at a time: keeps the
    alternation and the largest."""
    lo, hi = 0, len(idx) - 1
    while hi - lo + 1 > m:
        if vals[lo] < vals[hi]:
            lo += 1
        else:
            hi -= 1
    return idx[lo:hi + 1], vals[lo:hi + 1]


_STENCIL = np.arange(-2, 3)


def _peaks(e: np.ndarray, idx: list[int]) -> list[float]:
    """Offsets, in grid spacings within ``[-1, 1]``, of the maxima of ``|e|``
    next to the grid points ``idx``: the root of the derivative of the
    quartic through the five grid values around each (Newton from the
    parabola's vertex). The grid is uniform in ``theta`` and ``e`` is even in
    ``theta`` about both ends (``t = cos theta``), so the values are
    reflected there and an end point's offset is exactly 0.

    The quartic's Taylor coefficients at the centre are the five-point
    differences (exact for quartics); with spacing ``h`` the located point is
    off by ``O(h^4)`` and its value by ``O(h^8)``, relative:

    >>> th = np.linspace(0, 1, 101); e = np.cos(7 * (th - 0.3013))
    >>> bool(abs(th[30] + 0.01 * _peaks(e, [30])[0] - 0.3013) < 1e-9)
    True
    """
    last = len(e) - 1
    j = [abs(i + d) for i in idx for d in (-2, -1, 0, 1, 2)]  # reflected at 0
    j = [2 * last - i if i > last else i for i in j]  # and at the other end
    vals = e[j].tolist()
    out = []
    # a few extrema: Python floats cost less than numpy calls on tiny arrays
    for k in range(0, len(vals), 5):
        em2, em1, e0, e1, e2 = vals[k:k + 5]
        if e0 < 0:  # maxima of sign * e
            em2, em1, e0, e1, e2 = -em2, -em1, -e0, -e1, -e2
        d1 = (8 * (e1 - em1) - (e2 - em2)) / 12
        d2 = (16 * (e1 + em1) - 30 * e0 - (e2 + em2)) / 12
        if not d2 < 0:  # not concave (or nan): the grid point is kept
            out.append(0.0)
            continue
        d3 = 0.5 * ((e2 - em2) - 2 * (e1 - em1))
        d4 = (e2 + em2) - 4 * (e1 + em1) + 6 * e0
        u = min(max(-d1 / d2, -1.0), 1.0)
        for _ in range(2):  # Newton on q'(u) = d1 + d2 u + d3 u^2/2 + d4 u^3/6
            q2 = d2 + u * (d3 + u * (0.5 * d4))
            if q2 < 0:
                q1 = d1 + u * (d2 + u * (0.5 * d3 + u * (d4 / 6)))
                u = min(max(u - q1 / q2, -1.0), 1.0)
        out.append(u if u == u else 0.0)
    return out


def _exchange(e_grid, cheb, n, grid, evaluate):
    """The new reference from the errors ``e_grid`` on the grid ``grid =
    (theta, f, w)``: the largest ``|e|`` of each run of one sign (``n + 2``
    of them kept, dropping the smaller end), each located between grid
    points by :func:`_peaks` and evaluated there (one call of ``f``); a grid
    point stays where its error is the larger. Returns the lists of angles,
    ``|e|``, ``f`` and weights (None without one) and the grid's largest
    ``|e|``. The few per-extremum steps run on Python floats, cheaper than
    numpy calls on arrays of ``n + 2`` elements."""
    theta_grid, f_grid, w_grid = grid
    keep, abs_grid = _sign_runs(e_grid)
    vals = abs_grid[keep].tolist()
    grid_max = max(vals)
    if len(keep) > n + 2:
        keep, vals = _trim(keep, vals, n + 2)
    th_keep = theta_grid[keep]
    step = theta_grid[0] - theta_grid[1]
    th = th_keep - step * np.array(_peaks(e_grid, keep))  # theta decreases along the grid
    ev, fv, wv = evaluate(th, cheb)
    k_p, k_v, k_f, k_w = [], [], [], []
    for j, (g_e, new_e) in enumerate(zip(e_grid[keep].tolist(), ev.tolist())):
        if new_e > g_e if g_e >= 0 else new_e < g_e:
            k_p.append(th[j])
            k_v.append(abs(new_e))
            k_f.append(fv[j])
            k_w.append(None if wv is None else wv[j])
        else:
            k_p.append(th_keep[j])
            k_v.append(abs(g_e))
            k_f.append(f_grid[keep[j]])
            k_w.append(None if w_grid is None else w_grid[keep[j]])
    return k_p, k_v, k_f, k_w, grid_max


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

    Each exchange: the error on a grid uniform in ``theta`` (``t = cos
    theta``, cached per degree; one matrix product), then
    :func:`_exchange`: the extrema located between grid points and
    evaluated in one call of ``f``, whose values are also those of the next
    solve.

    The best line to ``x^2`` on ``[0, 1]`` is ``x - 1/8`` (error ``1/8``,
    equioscillating at 0, 1/2, 1); with ``x = (t + 1)/2`` it is
    ``3/8 + t/2``:

    Parameters
    ----------
    f : callable
        ``f`` on a float64 array of ``x``, returning a float64 array.
    weight : callable or None
        The weight ``w`` on a float64 array of ``x`` (e.g. ``1/|f|`` for the
        relative error), or None for ``w = 1``.
    lo, hi : float
        The interval, finite, ``lo < hi``.
    degree : int
        The degree of ``p``, >= 0.
    max_iter : int, optional
        The most exchanges, default 60 (``converged`` is False when reached).
    rtol : float, optional
        The relative agreement of the level and the largest error that stops
        the iteration, > 0; default 1e-8.

    Returns
    -------
    RemezResult
        The coefficients in the Chebyshev basis of ``t``, the levelled and
        largest errors, and whether it converged.

    Examples
    --------
    >>> import numpy as np
    >>> r = remez(lambda x: x**2, np.ones_like, 0.0, 1.0, 1)
    >>> [round(float(c), 9) for c in r.cheb], round(float(r.levelled), 9), r.converged
    ([0.375, 0.5], 0.125, True)
    """
    n = degree
    unit = weight is None or weight is _unit
    half, mid = 0.5 * (hi - lo), 0.5 * (hi + lo)
    theta_grid, t_grid, v_grid = _grid(n)
    f_grid = f(half * t_grid + mid)
    w_grid = None if unit else weight(half * t_grid + mid)
    grid = (theta_grid, f_grid, w_grid)
    # float64 noise floor of the error: a gap below a few roundings of w f
    # cannot shrink further, so it counts as converged
    floor = 8 * np.finfo(float).eps * float(np.max(np.abs(f_grid if unit else w_grid * f_grid)))
    ks = np.arange(n + 1)
    signs = (-1.0) ** np.arange(n + 2)

    def evaluate(theta, cheb):
        """Error, ``f`` and weight at the angles ``theta`` (any shape)."""
        x = half * np.cos(theta) + mid
        fx = f(x)
        e = detlinalg.matvec(np.cos(theta[..., None] * ks), cheb) - fx
        if unit:
            return e, fx, None
        wx = weight(x)
        return wx * e, fx, wx

    ref = np.pi * np.arange(n + 1, -1, -1) / (n + 1)  # angles of the reference
    x_ref = half * np.cos(ref) + mid
    f_ref = f(x_ref)
    w_ref = None if unit else weight(x_ref)
    best = None
    for it in range(1, max_iter + 1):
        A = np.empty((n + 2, n + 2))
        A[:, : n + 1] = np.cos(ref[:, None] * ks)
        A[:, n + 1] = signs if unit else signs / w_ref
        sol = detlinalg.solve(A, f_ref)  # not LAPACK: its kernels differ by CPU
        if sol is None:  # singular
            break
        cheb, E = sol[: n + 1], float(abs(sol[n + 1]))
        e_grid = detlinalg.matvec(v_grid, cheb) - f_grid
        if not unit:
            e_grid *= w_grid
        k_p, k_v, k_f, k_w, grid_max = _exchange(e_grid, cheb, n, grid, evaluate)
        max_err = max(grid_max, *k_v)
        E = min(E, min(k_v)) if len(k_v) == n + 2 else E
        improved = best is None or max_err < best.max_error
        if improved:
            best = RemezResult(cheb.copy(), E, max_err, it, False, np.cos(ref))
        if max_err - E <= rtol * max_err:
            best = RemezResult(cheb.copy(), E, max_err, it, True, np.cos(ref))
            break
        if max_err - E <= floor:
            # at the noise floor: keep exchanging only while it still helps
            best.converged = True
            if not improved:
                break
        if len(k_v) < n + 2:
            break
        ref, f_ref = np.array(k_p), np.array(k_f)
        w_ref = None if unit else np.array(k_w)
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

    Parameters
    ----------
    f_mp : callable
        ``f``, taking and returning mpmath numbers.
    lo, hi : float
        The interval, ``lo < hi``.
    ref : array_like of float
        The ``degree + 2`` reference points of ``t`` in ``[-1, 1]``.
    degree : int
        The degree, >= 0.
    relative : bool, optional
        Level the relative error ``p/f - 1`` instead of ``p - f``; default False.
    dps : int, optional
        The decimal digits of the mpmath working precision, default 50.

    Returns
    -------
    list of mpmath.mpf
        The ``degree + 1`` Chebyshev coefficients, ascending.

    Examples
    --------
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
        return _solve(rows, rhs, dps)[: n + 1]


def _solve(rows: list, rhs: list, dps: int) -> list:
    """``rows x = rhs`` (mpmath numbers) to about ``dps`` digits: Arb's
    approximate LU solve in C at the same precision, its midpoints returned
    exactly as mpmath numbers (mpmath's pure-Python ``lu_solve`` where Arb
    finds the system singular). Like mpmath's, not a rigorous enclosure:
    the coefficients are certified afterwards."""
    with arb_precision(math.ceil(dps * math.log2(10)) + 16):
        try:
            a = arb_mat([[_to_arb(v) for v in row] for row in rows])
            b = arb_mat([[_to_arb(v)] for v in rhs])
            x = a.solve(b, algorithm="approx")
            out = []
            for k in range(len(rhs)):
                man, exp = x[k, 0].mid().man_exp()
                out.append(mpmath.mpf((int(man), int(exp))))
            return out
        except ZeroDivisionError:
            with mpmath.workdps(dps):
                sol = mpmath.lu_solve(mpmath.matrix(rows), mpmath.matrix(rhs))
                return [sol[k] for k in range(len(rhs))]


def _to_arb(v) -> arb:
    """An mpmath number (or a float) as an exact Arb ball."""
    if not isinstance(v, mpmath.mpf):
        v = mpmath.mpf(v)
    if not mpmath.isfinite(v):
        raise ValueError(f"value {v} is not finite")
    sign, man, exp, _ = v._mpf_
    return arb(((-1) ** sign * int(man), int(exp)))


# --- minimax on a set of powers ---------------------------------------------

class _PowerBasis:
    """A well-conditioned basis of the span of ``x^k`` (``k`` in ``powers``)
    on ``[lo, hi]``: where the powers are ``m + s j`` (``j = 0..J``, an
    arithmetic progression: all powers, the odd or the even ones)
    ``phi_j = (x/S)^m T_j(alpha x^s + beta)``, the Chebyshev polynomials of
    ``x^s`` mapped onto ``[-1, 1]``; otherwise ``(x/S)^k``. ``S``, ``alpha``
    and ``beta`` are floats used exactly both in the float64 evaluation and
    in the exact conversion to monomials (:meth:`monomial`)."""

    def __init__(self, powers: tuple[int, ...], lo: float, hi: float):
        self.powers = tuple(powers)
        self.scale = max(abs(lo), abs(hi)) or 1.0
        steps = {b - a for a, b in zip(self.powers, self.powers[1:])}
        self.step = steps.pop() if len(steps) == 1 else (1 if len(self.powers) == 1 else None)
        self.alpha = self.beta = None
        if self.step is not None:
            s = self.step
            ends = sorted(((lo / self.scale) ** s, (hi / self.scale) ** s))
            if s % 2 == 0 and lo < 0 < hi:
                ends = [0.0, max(ends)]
            width = ends[1] - ends[0]
            self.alpha = 2.0 / width if width > 0 else 1.0
            self.beta = -(ends[0] + ends[1]) / width if width > 0 else 0.0

    def matrix(self, x: np.ndarray) -> np.ndarray:
        """``phi_j(x)`` as a ``(len(x), len(powers))`` float64 matrix."""
        u = x / self.scale
        if self.step is None:
            return np.stack([clib.power(u, k) for k in self.powers], axis=1)
        y = self.alpha * clib.power(u, self.step) + self.beta
        return (clib.power(u, self.powers[0])[:, None]
                * C.chebvander(y, len(self.powers) - 1))

    def monomial(self, coeffs) -> fmpq_poly:
        """``sum_j coeffs[j] phi_j`` exactly, as a polynomial in ``x``."""
        s_inv = 1 / exact_rational(self.scale)
        x_over = fmpq_poly([0, s_inv])
        out = fmpq_poly([])
        if self.step is None:
            for k, c in zip(self.powers, coeffs):
                out += exact_rational(c) * x_over ** k
            return out
        inner = (fmpq_poly([exact_rational(self.beta)])
                 + exact_rational(self.alpha) * x_over ** self.step)
        series = fmpq_poly([])
        for j, c in enumerate(coeffs):
            series += exact_rational(c) * chebyshev_t(j)
        return series(inner) * x_over ** self.powers[0]


class PowersFit:
    """Result of :func:`minimax_powers`: ``coefficients`` (float64, ascending
    powers ``0..degree`` of ``x``, the fixed ones included), ``level`` (the
    discrete minimax error on the final point set, a lower estimate),
    ``max_error`` (the largest error found on the dense grid and at the
    located extrema), ``converged`` (the two agree to ``rtol``).

    Parameters
    ----------
    coefficients : list of float
        The float64 coefficients of ``x^0 .. x^degree``, the fixed ones included
        (zero for the powers not used).
    level : float
        The discrete minimax error on the final point set.
    max_error : float
        The largest error found.
    converged : bool
        Whether ``max_error`` is within ``1 + 10^-4`` of ``level``.
    rounds : int
        The number of exchange rounds of all stages.
    """

    def __init__(self, coefficients, level, max_error, converged, rounds):
        self.coefficients = coefficients
        self.level = level
        self.max_error = max_error
        self.converged = converged
        self.rounds = rounds


def _lp_minimax(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, float] | None:
    """``argmin_c max_i |(a c - b)_i|`` by linear programming (HiGHS, tight
    tolerances, columns and right side scaled to 1); None when HiGHS fails.
    The caller refines the answer on the residual, so HiGHS's tolerances
    (relative to the scaled data) bound only one step's loss."""
    from scipy.optimize import linprog

    col = np.max(np.abs(a), axis=0)
    col[col == 0] = 1.0
    rs = float(np.max(np.abs(b))) or 1.0
    an, bn = a / col, b / rs
    n, m = an.shape
    ones = np.ones((n, 1))
    A = np.block([[an, -ones], [-an, -ones]])
    cost = np.zeros(m + 1)
    cost[-1] = 1.0
    res = linprog(cost, A_ub=A, b_ub=np.concatenate([bn, -bn]),
                  bounds=[(None, None)] * m + [(0, None)], method="highs-ds",
                  options={"primal_feasibility_tolerance": 1e-10,
                           "dual_feasibility_tolerance": 1e-10})
    if not res.success:
        return None
    return res.x[:m] / col * rs, float(res.x[m]) * rs


def _local_maxima(a: np.ndarray, floor: float, most: int) -> list[int]:
    """Indices of the (at most ``most`` largest) local maxima of ``a`` above ``floor``."""
    left = np.concatenate(([True], a[1:] >= a[:-1]))
    right = np.concatenate((a[:-1] >= a[1:], [True]))
    idx = np.flatnonzero(left & right & (a > floor))
    if len(idx) > most:
        idx = idx[np.argsort(-a[idx])[:most]]
    return sorted(idx.tolist())


class _Residual:
    """``g = f - fixed`` and the weight at points, in float64 or, once a
    polynomial ``p`` is known, the residual ``g - p`` in Arb (200 bits)."""

    def __init__(self, fn, fixed: dict, relative: bool):
        self.fn, self.fixed, self.relative = fn, fixed, relative
        self.poly = None                      # exact fmpq_poly of the fitted part so far

    def weight_and_target(self, x: np.ndarray):
        with np.errstate(all="ignore"):
            fx = np.asarray(self.fn.numpy(x), dtype=float) * np.ones_like(x)
        w = 1.0 / np.abs(fx) if self.relative else np.ones_like(fx)
        if self.poly is None:
            g = fx - sum(c * clib.power(x, k) for k, c in self.fixed.items())
        else:
            g = self._exact(x)
        return w, g

    def _exact(self, x: np.ndarray) -> np.ndarray:
        with arb_precision(200):
            total = self.poly
            for k, c in self.fixed.items():
                total += exact_rational(c) * fmpq_poly([0] * k + [1])
            ap = arb_poly([arb(c) for c in total.coeffs()])
            out = np.empty(len(x))
            for i, v in enumerate(x.tolist()):
                xa = arb(v)
                try:
                    r = self.fn.arb(xa) - ap(xa)
                    out[i] = float(r.mid()) if r.is_finite() else math.nan
                except (ValueError, ZeroDivisionError):
                    out[i] = math.nan
            return out


def minimax_powers(fn, lo: float, hi: float, degree: int, powers, fixed: dict | None = None,
                   relative: bool = False, rtol: float = 1e-6) -> PowersFit:
    """The best polynomial ``p = sum_{k in powers} c_k x^k + fixed`` minimizing
    ``max |w (p - f)|`` on ``[lo, hi]`` (``w = 1``, or ``1/|f|`` with
    ``relative``), for any set of powers (Haar system or not).

    ``fn`` is a :class:`~chebnorm.approx.expr.Function1D`; ``fixed`` maps a
    power to its (float) coefficient held fixed. The discrete problem on a
    growing set of points is a linear program (HiGHS); each round adds the
    located extrema of the error on a dense grid (Cheney's exchange), until
    the discrete level and the largest error agree to ``rtol``. The first
    stage works on ``f`` in float64; the next ones on the residual ``f - p``
    evaluated in 200-bit Arb, so the answer is not limited by float64's
    resolution of ``f`` nor by the solver's tolerance (each stage only
    corrects the previous one).

    ``converged`` means the largest error is within ``1 + 10^-4`` of the
    level (so within 0.01 % of the minimax error).

    The best multiple of ``x`` to ``x^3`` on ``[-1, 1]`` is ``3x/4``
    (``x^3 - 3x/4 = T_3(x)/4``, error ``1/4``); with ``p(0)`` held at 1, the
    best ``1 + c x^2`` to ``1 + x^4`` has ``c = 2 sqrt(2) - 2`` (error
    ``c^2/4``, at ``x^2 = c/2`` and at 1):

    Parameters
    ----------
    fn : Function1D
        The function ``f``.
    lo, hi : float
        The interval, finite, ``lo < hi``.
    degree : int
        The highest power of the result's coefficient list, >= every power used.
    powers : iterable of int
        The powers whose coefficients are free, each in ``0..degree``.
    fixed : dict of int to float, optional
        Power -> coefficient held fixed; default None (none).
    relative : bool, optional
        Minimize the relative error (``w = 1/|f|``); default False.
    rtol : float, optional
        The agreement of level and largest error that ends a stage, > 0;
        default 1e-6.

    Returns
    -------
    PowersFit
        The coefficients, the level, the largest error and whether it converged.

    Examples
    --------
    >>> from chebnorm.approx import parse_function
    >>> r = minimax_powers(parse_function("x**3"), -1.0, 1.0, 3, (1,))
    >>> r.converged, round(r.level, 7), [round(c, 7) for c in r.coefficients]
    (True, 0.25, [0.0, 0.75, 0.0, 0.0])
    >>> r = minimax_powers(parse_function("1 + x**4"), -1.0, 1.0, 4, (2,), fixed={0: 1.0})
    >>> abs(r.coefficients[2] - (8 ** 0.5 - 2)) < 1e-7, r.coefficients[0]
    (True, 1.0)
    """
    fixed = dict(fixed or {})
    basis = _PowerBasis(tuple(powers), lo, hi)
    m = len(basis.powers)
    theta = _grid(max(degree, m))[0]
    half, mid = 0.5 * (hi - lo), 0.5 * (hi + lo)
    xd = half * np.cos(theta) + mid
    xd[0], xd[-1] = lo, hi
    phi_d = basis.matrix(xd)
    res = _Residual(fn, fixed, relative)
    w_d, g_d = res.weight_and_target(xd)
    ok = np.isfinite(w_d) & np.isfinite(g_d) & np.all(np.isfinite(phi_d), axis=1)
    count = max(8 * m, 60)
    start = np.unique(np.round(np.linspace(0, len(xd) - 1, count)).astype(int))
    coeff_exact = [fmpq(0)] * m
    level = max_err = math.inf
    converged = False
    rounds = 0
    for stage in range(3):
        c, level, max_err, stage_conv, n = _exchange_lp(
            basis, res, theta, (xd, phi_d, w_d, g_d, ok), start, m, rtol, (lo, hi))
        rounds += n
        if c is None:
            break
        coeff_exact = [a_ + exact_rational(float(b_)) for a_, b_ in zip(coeff_exact, c)]
        converged = stage_conv or max_err <= level * (1 + 1e-4)
        correction = float(np.max(np.abs(w_d[ok] * detlinalg.matvec(phi_d[ok], c))))
        if max_err == 0 or (stage > 0 and correction <= 1e-3 * level):
            break
        # the next stage fits the residual f - p, computed exactly
        res.poly = _sum_poly(basis, coeff_exact)
        w_d, g_d = res.weight_and_target(xd)
        ok &= np.isfinite(g_d)
    poly = _sum_poly(basis, coeff_exact)
    out = [0.0] * (degree + 1)
    for k, c in enumerate(poly.coeffs()):
        if k <= degree:
            out[k] = int(c.p) / int(c.q)
    for k, c in fixed.items():
        out[k] = float(c)
    return PowersFit(out, level, max_err, converged, rounds)


def _exchange_lp(basis, res, theta, dense, start, m, rtol, ends):
    """One stage of :func:`minimax_powers`: linear programs on a growing set of
    points (the dense grid's indices ``start``, then the located extrema of
    the error added), until the level and the largest error agree to
    ``rtol`` or a round no longer raises the level. Returns the basis
    coefficients, the level, the largest error, whether it converged and
    the rounds taken."""
    xd, phi_d, w_d, g_d, ok = dense
    lo, hi = ends
    half, mid = 0.5 * (hi - lo), 0.5 * (hi + lo)
    pts = [i for i in start.tolist() if ok[i]]
    ex_x, ex_w, ex_g = np.empty(0), np.empty(0), np.empty(0)
    best = (None, math.inf, math.inf, False)
    last = -math.inf
    for rounds in range(1, 31):
        xs = np.concatenate([xd[pts], ex_x])
        w_p, g_p = np.concatenate([w_d[pts], ex_w]), np.concatenate([g_d[pts], ex_g])
        sol = _lp_minimax(w_p[:, None] * basis.matrix(xs), w_p * g_p)
        if sol is None:
            break
        c, level = sol
        e_d = np.where(ok, w_d * (detlinalg.matvec(phi_d, c) - g_d), 0.0)
        peaks = _local_maxima(np.abs(e_d), 0.9 * level, 4 * m + 8)
        th = theta[peaks] - (theta[0] - theta[1]) * np.array(_peaks(e_d, peaks))
        xp = np.clip(half * np.cos(th) + mid, lo, hi)
        wp, gp = res.weight_and_target(xp)
        ep = wp * (detlinalg.matvec(basis.matrix(xp), c) - gp)
        good = np.isfinite(ep)
        max_err = max(float(np.max(np.abs(e_d))),
                      float(np.max(np.abs(ep[good]))) if good.any() else 0.0)
        done = max_err <= level * (1 + rtol) or max_err == 0
        if best[0] is None or max_err < best[2] or done:
            best = (c, level, max_err, done)
        if done or level <= last * (1 + 1e-3 * rtol):
            break
        last = level
        new = good & (np.abs(ep) > level)
        pts = sorted(set(pts) | set(peaks))
        ex_x = np.concatenate([ex_x, xp[new]])
        ex_w, ex_g = np.concatenate([ex_w, wp[new]]), np.concatenate([ex_g, gp[new]])
    return (*best, rounds)


def _sum_poly(basis: _PowerBasis, coeffs) -> fmpq_poly:
    """``sum_j coeffs[j] phi_j`` with exact rational ``coeffs``, in ``x``."""
    return basis.monomial(coeffs)
