"""Coefficient rounding to fixed or floating formats by lattice reduction.

The approach of Sollya's ``fpminimax`` (Brisebarre and Chevillard, "Efficient
polynomial L-infinity approximations", ARITH 18, 2007): at a set of points
``x_i`` (Chebyshev nodes of the interval) the values of a polynomial whose
``k``-th coefficient is ``n_k * 2^(s_k)`` (``n_k`` an integer, ``2^(s_k)``
the coefficient's quantum in its format) form a lattice point
``sum_k n_k * b_k`` with ``b_k = (w_i x_i^(e_k) 2^(s_k))_i``; the point closest
to the function's (weighted) values is found approximately by LLL reduction
(python-flint) and Babai's nearest plane, on the residual of the real fit
rounded (so the small columns keep their bits). Every candidate -- the lattice
answers for several point sets and their neighbours, each coefficient rounded
to nearest, and the greedy refit of :func:`chebnorm.approx.quantize` -- is
ranked by its error sampled in float64 on a dense grid; candidates are then
certified (:func:`chebnorm.approx.certify.certify`) in that order only while
their sampled error (a lower bound of their supremum) is below the best bound
certified so far: the answer is the smallest certified bound among those
(floating formats: within a factor ``1 + 2^-20`` of it, the certificates' own
tolerance; a candidate whose error, sampled or in ball arithmetic at the best
one's peaks, reaches the best bound / (1 + 2^-20) is not certified).

Fixed formats are monotone in the bits: the pool certified at ``F``
fractional bits holds, for every ``b = 0..F`` bits, the plain rounding and the
cheaply ranked best candidate at ``b`` bits (:func:`_chain_level`), shifted to
``F`` bits; the pool at ``F - 1`` bits is part of it, so more bits never
certify worse. The bit counts whose grid is proven (:func:`_grid_lower_bounds`)
to hold no polynomial as good as the bound certified at ``F`` bits cannot
change the minimum and are not built (:func:`_fixed_pool`).

Internal: the public entry point is :func:`chebnorm.approx.quantize`.
"""

from __future__ import annotations

import functools
import itertools
import math
import operator
from dataclasses import dataclass, field

import numpy as np
from flint import fmpz_mat

from chebnorm.core import clib
from .certify import certify

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

#: floating formats: (precision p including the hidden bit, emin, emax);
#: representable: m * 2^(e - p + 1) with |m| < 2^p and emin <= e <= emax
#: (subnormals: e = emin with |m| < 2^(p-1))
FLOAT_FORMATS = {
    "binary16": (11, -14, 15),
    "bfloat16": (8, -126, 127),
    "binary32": (24, -126, 127),
    "binary64": (53, -1022, 1023),
}
#: every coefficient format of :func:`chebnorm.approx.quantize` (``coef_format``):
#: ``"fixed"`` (two's complement integers over a power of two), then the floating
#: formats of :data:`FLOAT_FORMATS`; the facade exports it as ``COEF_FORMATS``
FORMATS = ("fixed",) + tuple(FLOAT_FORMATS)
#: most lattice rounds (sets of binades) tried for a floating format
FLOAT_ROUNDS = 10


@dataclass(frozen=True)
class Candidate:
    """One rounded polynomial: coefficient of ``x**k`` is ``mantissas[k] * 2**exponents[k]``.

    Parameters
    ----------
    mantissas : tuple of int
        The integer mantissa of each power ``0..degree``.
    exponents : tuple of int
        The power-of-two exponent of each (``-frac_bits`` in fixed point).
    method : str
        How the candidate was found (e.g. rounded to nearest, greedy refit,
        lattice search).
    bound : float
        Its certified error bound (of the table's ``error_kind``).
    abs_cert : Certificate
        The certificate of ``sup |p - f|``.
    rel_cert : Certificate or None
        The certificate of ``sup |p/f - 1|``, None when not computed.
    """

    mantissas: tuple[int, ...]
    exponents: tuple[int, ...]
    method: str
    bound: float
    abs_cert: object
    rel_cert: object | None

    @property
    def coefficients(self) -> tuple[float, ...]:
        return tuple(math.ldexp(m, e) for m, e in zip(self.mantissas, self.exponents))


def float_quantum(value: float, fmt: str) -> int:
    """The exponent ``s`` of the quantum ``2^s`` of ``value`` in float format ``fmt``."""
    p, emin, _ = FLOAT_FORMATS[fmt]
    if value == 0 or not math.isfinite(value):
        return emin - p + 1
    e = math.frexp(value)[1] - 1          # 2^e <= |value| < 2^(e+1)
    return max(e, emin) - p + 1


def round_to_float(value: float, fmt: str) -> tuple[int, int]:
    """``value`` rounded to nearest (ties to even) in ``fmt``, as ``(m, s)``, value = m 2^s.

    Raises ValueError on overflow.
    """
    p, emin, emax = FLOAT_FORMATS[fmt]
    if value == 0:
        return 0, 0
    s = float_quantum(value, fmt)
    m = round(math.ldexp(value, -s))
    if abs(m) >= 1 << p:                  # rounding carried into the next binade
        m, s = round(m / 2), s + 1
    if s > emax - p + 1:
        raise ValueError(f"coefficient {value:.6g} overflows {fmt}; accepted: |c| below "
                         f"{math.ldexp(2 - 2.0 ** (1 - p), emax):.6g}")
    return normal_pair(m, s)


def normal_pair(m: int, s: int) -> tuple[int, int]:
    """``(m', s')`` with ``m' * 2**s' == m * 2**s`` and ``m'`` odd (``(0, 0)`` for zero).

    >>> normal_pair(12, -4)
    (3, -2)
    """
    if m == 0:
        return 0, 0
    zeros = (m & -m).bit_length() - 1     # trailing zero bits (two's complement)
    return m >> zeros, s + zeros


def representable(m: int, s: int, fmt: str) -> bool:
    """True when ``m * 2^s`` is a finite number of ``fmt``."""
    if m == 0:
        return True
    p, emin, emax = FLOAT_FORMATS[fmt]
    m, s = normal_pair(m, s)
    bits = abs(m).bit_length()
    top = s + bits - 1                    # exponent of the leading bit
    return bits <= p and top <= emax and s >= emin - p + 1


def chebyshev_nodes(lo: float, hi: float, count: int) -> np.ndarray:
    """The ``count`` Chebyshev points of the first kind on ``[lo, hi]``, ascending."""
    k = np.arange(count)
    t = np.cos(np.pi * (2 * k + 1) / (2 * count))[::-1]
    return 0.5 * (lo + hi) + 0.5 * (hi - lo) * t


def _reduced(basis: list[list[int]]):
    """LLL reduction of ``basis`` (integer rows): the transform's rows, the
    reduced rows scaled by ``scale`` (floats), their Gram-Schmidt vectors and
    squared norms, and ``scale``. Gram-Schmidt in a fixed order with
    correctly rounded dot products (:func:`_dot`), not LAPACK's QR, whose
    kernels (and last bits) depend on the CPU."""
    mat = fmpz_mat(basis)
    red, trans = mat.lll(transform=True)
    rows = np.array([[float(int(v)) for v in row] for row in red.tolist()])
    tr = [[int(v) for v in row] for row in trans.tolist()]
    # Gram-Schmidt of the reduced rows, in floats (scaled to avoid overflow)
    scale = max(np.max(np.abs(rows)), 1.0)
    b = rows / scale
    stars, norms = [], []
    for i in range(len(b)):                   # modified Gram-Schmidt
        v = b[i].copy()
        for s, nrm in zip(stars, norms):
            if nrm > 0:
                v = v - (_dot(v, s) / nrm) * s
        stars.append(v)
        norms.append(_dot(v, v))
    return tr, b, stars, norms, scale


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """``sum(a * b)``: products correctly rounded, their sum by ``math.fsum``
    (correctly rounded): the same float on every CPU."""
    return math.fsum((a * b).tolist())


def _babai(basis: list[list[int]], target: list[int], spread: bool,
           cache: dict | None = None) -> list[list[int]]:
    """LLL-reduce ``basis`` (integer rows) and return the integer coordinates
    (in ``basis``) of Babai's nearest-plane point to ``target`` and, with
    ``spread``, of its neighbours ``+- one reduced vector``. ``cache`` (basis ->
    reduction) spares the reduction of a basis met before: the fixed-point
    chain meets the same integer basis at most bit counts (the columns only
    scale by 2, and the scaling to 62 bits undoes it)."""
    key = tuple(map(tuple, basis))
    red = None if cache is None else cache.get(key)
    if red is None:
        red = _reduced(basis)
        if cache is not None:
            cache[key] = red
    tr, b, stars, norms, scale = red
    n = len(tr)
    t = np.array([float(v) for v in target]) / scale
    coords = [0] * n
    resid = t.copy()
    for i in range(n - 1, -1, -1):
        if not norms[i] > 0:
            continue
        c = round(_dot(resid, stars[i]) / norms[i])
        coords[i] = c
        resid = resid - c * b[i]
    base = [0] * n                        # sum_i coords[i] tr[i], exact integers
    for c, row in zip(coords, tr):
        if c:
            base = [a + c * v for a, v in zip(base, row)]
    out = [base]
    if spread:                            # coords +- e_i: base +- row i of the transform
        for i in range(n):
            out.append(list(map(operator.sub, base, tr[i])))
            out.append(list(map(operator.add, base, tr[i])))
    return out


def _lattice(points, f_vals, weights, powers, quanta, fixed_poly, base=None, cache=None,
             xp=None):
    """Integer vectors ``n`` (one per free power) near the weighted function values.

    ``base`` (integers, one per free power: the real fit rounded) is subtracted
    from the target first and added back to the answers: the lattice then
    resolves the residual, a few quanta, instead of f itself, whose size would
    leave the small columns (high powers at small points) only a few bits once
    everything is scaled to 62-bit integers. ``xp``: the powers of ``points``
    (a :class:`_Powers`), kept across calls on the same points.
    """
    x = np.asarray(points, dtype=float)
    w = np.asarray(weights, dtype=float)
    xp = _Powers(x) if xp is None else xp         # IEEE products: the same bits on every CPU
    xe = {e: xp[e] for e in powers}
    vecs = [w * xe[e] * math.ldexp(1.0, s) for e, s in zip(powers, quanta)]
    base = [0] * len(powers) if base is None else list(base)
    y = w * (np.asarray(f_vals, dtype=float) - fixed_poly(x)
             - sum(math.ldexp(b, s) * xe[e] for b, e, s in zip(base, powers, quanta)))
    vecs = np.array(vecs)
    big = max(float(np.max(np.abs(vecs))), float(np.max(np.abs(y))), 1e-300)
    shift = 62 - math.frexp(big)[1]
    def ints(v):
        v = np.asarray(v, dtype=float)
        if np.all(np.isfinite(v)):            # |v| 2^shift < 2^62: exact in int64
            return np.rint(np.ldexp(v, shift)).astype(np.int64).tolist()
        if v.ndim == 2:
            return [ints(row) for row in v]
        return [int(round(math.ldexp(float(a), shift))) for a in v]   # raises as before
    basis = ints(vecs)
    if any(not any(row) for row in basis):
        return []
    try:
        vecs = _babai(basis, ints(y), spread=True, cache=cache)
    except (ValueError, ZeroDivisionError, OverflowError):
        return []
    return [list(map(operator.add, base, vec)) for vec in vecs]


@dataclass
class Problem:
    """A quantization problem: round the free ``powers`` of a degree-``degree`` fit of
    ``fn`` on ``[lo, hi]`` (``error_kind`` error) to integers, the ``fixed`` ones held,
    each within ``word_limit`` in fixed point; with the caches of its certificates,
    nodes and lattice reductions (the candidates :func:`greedy` and the lattice
    search compare)."""

    fn: object
    lo: object                    # exact sympy endpoints
    hi: object
    lo_f: float
    hi_f: float
    error_kind: str
    degree: int
    powers: tuple[int, ...]       # free powers (fixed c0 excluded)
    fixed: dict                   # power -> (mantissa, exponent) held fixed
    word_limit: int | None        # fixed point: |integer| <= word_limit
    #: coefficients -> their certificate (or the ValueError, or the bound it is proven
    #: to reach: ("at least", b)); certify is deterministic, so a repeat is not re-run
    certs: dict = field(default_factory=dict, repr=False)
    #: greedy's Chebyshev nodes, f there, powers of them (:func:`greedy`)
    greedy_nodes: dict = field(default_factory=dict, repr=False)
    #: integer lattice basis -> its reduction (:func:`_babai`)
    reductions: dict = field(default_factory=dict, repr=False)


def int_powers(x: np.ndarray, k: int, lower: np.ndarray | None = None) -> np.ndarray:
    """``x ** k`` for an integer ``k >= 0`` as the rounded product ``(..((x * x) * x)
    ..) * x`` (``lower``: ``x ** (k - 1)`` so computed, when at hand): IEEE
    products, the same bits on every CPU, at a fraction of the cost of the C
    library's ``pow`` element by element; within ``(k - 1) 2^-53`` relative of
    ``x ** k`` (the samplers' allowance covers it: they only rank candidates)."""
    x = np.asarray(x, dtype=float)
    if k == 0:
        return np.ones_like(x)
    if k == 1:
        return x.copy()
    if lower is None:
        lower = int_powers(x, k - 1)
    return lower * x


class _Powers:
    """``x ** k`` (:func:`int_powers`: repeated products) of the points ``x``,
    each power computed when first asked for and kept; or, with ``parent`` and
    ``index``, ``parent[k][index]`` (the same floats: every element is computed
    on its own)."""

    def __init__(self, x: np.ndarray, parent: "_Powers | None" = None, index=None):
        self.x, self.parent, self.index = x, parent, index
        self.cache: dict[int, np.ndarray] = {}

    def __getitem__(self, k: int) -> np.ndarray:
        v = self.cache.get(k)
        if v is None:
            if self.parent is not None:
                v = self.parent[k][self.index]
            else:
                v = int_powers(self.x, k, None if k < 2 else self[k - 1])
            v.flags.writeable = False
            self.cache[k] = v
        return v


# at most 8 grids kept, each up to ~1 MB (6000 points, f, weights, powers, views)
@functools.lru_cache(maxsize=8)
def _sample_grid(f_np, lo: float, hi: float, kind: str, samples: int):
    """The sampler's points inside ``(lo, hi)``, ``f`` there, the weights and
    the powers of the points (read-only, powers computed as asked for):
    they depend only on the function, the interval, the error kind and the
    count, so every quantization of one function on one interval (the parity
    sub-basis and the whole basis, several formats or bit counts) shares them,
    as :func:`chebnorm.approx.certify._search_grid` shares its grid."""
    x = np.concatenate([np.linspace(lo, hi, samples), chebyshev_nodes(lo, hi, samples // 2)])
    x = np.clip(x, lo, hi)
    with np.errstate(all="ignore"):
        fx = np.asarray(f_np(x), dtype=float) * np.ones_like(x)
    ok = np.isfinite(fx) & (x > lo) & (x < hi)
    if kind == "rel":
        ok &= fx != 0
    x, f = x[ok], fx[ok]
    w = 1.0 / np.abs(f) if kind == "rel" else np.ones_like(f)
    for a in (x, f, w):
        a.flags.writeable = False
    return _Grid(x, f, w, _Powers(x))


class _Grid:
    """Points, ``f`` there, weights and powers (read-only), with the views
    of them the sampler takes (every ``step``-th point, the points sorted),
    each built once."""

    def __init__(self, x, f, w, xp):
        self.x, self.f, self.w, self.xp = x, f, w, xp
        self.views: dict = {}
        #: every weight is 1 (absolute error): a product by them changes nothing
        self.unit_weights = bool(np.all(w == 1.0))

    def view(self, key, index) -> "_Grid":
        """The grid at ``x[index]`` (``key`` names the view)."""
        got = self.views.get(key)
        if got is None:
            x, f, w = self.x[index], self.f[index], self.w[index]
            for a in (x, f, w):
                a.flags.writeable = False
            got = self.views[key] = _Grid(x, f, w, _Powers(x, self.xp, index))
        return got


class _Sampler:
    """Sampled weighted error of candidate polynomials (a lower bound of the
    supremum up to the float evaluation error, which is accounted for)."""

    def __init__(self, prob: Problem, samples: int = 4097):
        self._use(_sample_grid(prob.fn.numpy, prob.lo_f, prob.hi_f, prob.error_kind, samples))
        self.point_sets: dict = {}            # real coefficients -> _point_sets
        self.lows: dict = {}                  # coefficients -> error (memo of _ranked)
        self.thin_lows: dict = {}             # coefficients -> error on thinned()
        self._thin = None

    def _use(self, grid: "_Grid") -> None:
        self.grid = grid
        self.x, self.f, self.w, self.xp = grid.x, grid.f, grid.w, grid.xp

    def thinned(self, step: int = 16) -> "_Sampler":
        """Every ``step``-th of these points: the error of a polynomial there
        is computed with the same operations point by point, so it is at most
        its error on all the points (a cheaper lower bound of that)."""
        if self._thin is None:
            thin = object.__new__(_Sampler)
            thin._use(self.grid.view(("thin", step), slice(None, None, step)))
            self._thin = thin
        return self._thin

    def ordered(self) -> "_Sampler":
        """These points in increasing order (with ``f``, weights and powers)."""
        srt = object.__new__(_Sampler)
        # stable: the two sorted runs (uniform, Chebyshev) merge in linear time; tied
        # points hold the same values, so any order of them gives the same arrays
        grid = self.grid.views.get("sorted") or self.grid.view(
            "sorted", np.argsort(self.x, kind="stable"))
        srt._use(grid)
        return srt

    def zeros(self, coeffs) -> np.ndarray:
        """Where the error of the real polynomial ``coeffs`` changes sign (its
        interpolation points, linearly interpolated between samples)."""
        srt = self.ordered()
        x, f = srt.x, srt.f
        p = sum(c * srt.xp[k] for k, c in enumerate(coeffs))
        g = p - f
        idx = np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)[0]
        t = g[idx] / (g[idx] - g[idx + 1])
        return x[idx] + t * (x[idx + 1] - x[idx])

    def error(self, coeffs) -> float:
        p = np.zeros_like(self.x)
        mag = np.zeros_like(self.x)
        for k, c in enumerate(coeffs):
            if c:
                term = c * self.xp[k]
                p += term
                mag += np.abs(term)
        err = self.w * (np.abs(p - self.f) - 2.0 ** -50 * (mag + np.abs(self.f)))
        return float(np.max(err)) if err.size else 0.0

    def errors(self, rows, chunk: int = 32) -> list[float]:
        """:meth:`error` of each coefficient list in ``rows`` (all of one
        length), several at a time: the same operations element by element
        (a zero coefficient adds a zero term, which changes no sum), so the
        same floats."""
        out: list[float] = []
        if not self.x.size:
            return [0.0] * len(rows)
        absf = np.abs(self.f)
        unit = self.grid.unit_weights
        for i in range(0, len(rows), chunk):
            c = np.array(rows[i:i + chunk], dtype=float)
            p = mag = term = None
            for k in range(c.shape[1]):
                if not c[:, k].any():         # a zero column adds zeros: no sum changes
                    continue
                if p is None:                 # 0 + t: t (a -0 differs only in a sign
                    p = c[:, k:k + 1] * self.xp[k]      # that |p - f| drops)
                    mag = np.abs(p)
                    term = np.empty_like(p)
                    continue
                np.multiply(c[:, k:k + 1], self.xp[k], out=term)
                p += term
                np.abs(term, out=term)
                mag += term
            if p is None:
                p, mag = np.zeros((len(c), self.x.size)), np.zeros((len(c), self.x.size))
            # w * (|p - f| - 2^-50 (mag + |f|)), the same operations in place
            p -= self.f
            np.abs(p, out=p)
            mag += absf
            mag *= 2.0 ** -50
            p -= mag
            if not unit:                      # absolute error: weights 1, p * 1 = p
                p *= self.w
            out.extend(np.max(p, axis=1).tolist())
        return out


#: tolerance of the certificates that rank candidates: candidates often differ
#: by less than the certifier's default 2^-8, and a looser bound would misrank
SELECT_TOL = 2.0 ** -20


def certify_tight(fn, coeffs, lo, hi, kind, abort_at: float | None = None):
    """:func:`certify` at :data:`SELECT_TOL` (at most 20,000 subintervals);
    with ``abort_at``, None once the bound is proven to reach it."""
    return certify(fn, list(coeffs), lo, hi, kind, tol=SELECT_TOL, max_subintervals=20_000,
                   abort_at=abort_at)


def _certify_key(prob: Problem, coeffs, abort_at: float | None = None):
    """The ranking certificate of ``coeffs``, or None when its bound is proven
    ``>= abort_at`` (it cannot beat that one); raises ValueError as certify."""
    known = prob.certs.get(coeffs)
    if isinstance(known, ValueError):
        raise known
    if isinstance(known, tuple):              # ("at least", bound) from an aborted run
        if abort_at is not None and abort_at <= known[1]:
            return None
    elif known is not None:
        return known
    try:
        cert = certify_tight(prob.fn, coeffs, prob.lo, prob.hi, prob.error_kind, abort_at)
    except ValueError as exc:
        prob.certs[coeffs] = exc
        raise
    prob.certs[coeffs] = ("at least", abort_at) if cert is None else cert
    return cert


def _select(prob: Problem, sampler: _Sampler, cands: dict, best: Candidate | None):
    """The candidate (among ``cands``: method -> (mantissas, exponents)) with the
    smallest certified bound, or ``best`` when none beats it."""
    ranked = []
    seen = set()
    for method, (ms, es) in cands.items():
        coeffs = tuple(map(math.ldexp, ms, es))
        if coeffs in seen or not all(map(math.isfinite, coeffs)):
            continue
        seen.add(coeffs)
        ranked.append((method, ms, es, coeffs))
    lows = sampler.errors([r[3] for r in ranked]) if ranked else []
    ranked = sorted(((low,) + r for low, r in zip(lows, ranked)), key=lambda r: (r[0], r[1]))
    for low, method, ms, es, coeffs in ranked:
        if best is not None and low >= best.bound:
            break
        try:
            cert = _certify_key(prob, coeffs, None if best is None else best.bound)
        except ValueError:
            continue
        if cert is None:                      # proven >= best.bound: cannot win
            continue
        if best is None or cert.bound < best.bound:
            best = Candidate(tuple(ms), tuple(es), method, cert.bound,
                             cert if prob.error_kind == "abs" else None,
                             cert if prob.error_kind == "rel" else None)
    return best


def _full(prob: Problem, free: dict) -> tuple[list[int], list[int]]:
    """Mantissas/exponents of all powers 0..degree from the free and fixed ones."""
    ms, es = [0] * (prob.degree + 1), [0] * (prob.degree + 1)
    for k, (m, e) in {**free, **prob.fixed}.items():
        ms[k], es[k] = int(m), int(e)
    return ms, es


def _fixed_poly(prob: Problem):
    def poly(x):
        out = np.zeros_like(x)
        for k, (m, e) in prob.fixed.items():
            out += math.ldexp(m, e) * clib.power(x, k)
        return out
    return poly


def _symmetric_parity(prob: Problem) -> bool:
    """True when the interval is symmetric and every power (free and fixed)
    has one parity (and f, being fitted by them, is taken to have it too: the
    points on ``[0, hi]`` are then the whole problem)."""
    powers = set(prob.powers) | set(prob.fixed)
    return prob.lo_f == -prob.hi_f and len({k % 2 for k in powers}) == 1


def _point_sets(prob, sampler, real) -> list:
    """The lattice's point sets (2n+1 Chebyshev nodes, n free powers, and the real
    fit's interpolation points) with ``f`` and the weights there: the same at
    every set of quanta, so computed once per ``real`` (kept on ``sampler``)."""
    key = tuple(real)
    if key in sampler.point_sets:
        return sampler.point_sets[key]
    n_free = len(prob.powers)
    lo = prob.lo_f
    if _symmetric_parity(prob):
        # p(-x) = +-p(x) and f likewise: points x and -x give the same row (up
        # to sign), so nodes on [-hi, hi] hold half as many distinct equations;
        # the lattice is posed on [0, hi] instead
        lo = 0.0
    point_sets = [chebyshev_nodes(lo, prob.hi_f, count)
                  for count in (2 * n_free + 1,)]
    zeros = sampler.zeros(real)
    zeros = zeros[zeros > lo] if lo == 0.0 and prob.lo_f < 0 else zeros
    if len(zeros) >= n_free:
        point_sets.append(zeros)
    out = []
    for pts in point_sets:
        with np.errstate(all="ignore"):
            fv = np.asarray(prob.fn.numpy(pts), dtype=float) * np.ones_like(pts)
        if not np.all(np.isfinite(fv)) or (prob.error_kind == "rel" and np.any(fv == 0)):
            continue
        out.append((pts, fv, 1.0 / np.abs(fv) if prob.error_kind == "rel" else np.ones_like(fv),
                    _Powers(pts)))
    sampler.point_sets[key] = out
    return out


def _candidates(prob, sampler, real, quanta, greedy, fmt, lattice: bool = True) -> dict:
    """Candidate (mantissas, exponents) at one set of quanta (power -> s)."""
    cands = {}
    free_exps = [quanta[k] for k in prob.powers]
    # each free coefficient rounded to nearest
    cands["rounded"] = _full(prob, {k: (round(math.ldexp(real[k], -quanta[k])), quanta[k])
                                    for k in prob.powers})
    for pts, fv, w, xp in (_point_sets(prob, sampler, real) if lattice else ()):
        count = len(pts)
        vecs = _lattice(pts, fv, w, prob.powers, free_exps, _fixed_poly(prob),
                        [round(math.ldexp(real[k], -quanta[k])) for k in prob.powers],
                        prob.reductions, xp)
        # _full of each answer: the free powers set, then the fixed ones
        ms0, es0 = _full(prob, {})
        held = [(k, int(m), int(e)) for k, (m, e) in prob.fixed.items()]
        pos = [(k, int(s)) for k, s in zip(prob.powers, free_exps)]
        for j, ints in enumerate(vecs):
            ms, es = ms0.copy(), es0.copy()
            for (k, s), q in zip(pos, ints):
                ms[k], es[k] = int(q), s
            for k, m, e in held:
                ms[k], es[k] = m, e
            cands[f"lattice{count}.{len(cands)}.{j}"] = (ms, es)
    if greedy is not None:
        ints = greedy([quanta[k] for k in range(prob.degree + 1)])
        if ints is not None:
            cands["reoptimized"] = (list(ints), [quanta[k] for k in range(prob.degree + 1)])
    out = {}
    for method, (ms, es) in cands.items():
        if fmt == "fixed":
            if prob.word_limit is not None and max(map(abs, ms)) > prob.word_limit:
                continue
            out[method] = (ms, es)
        else:
            # lattice answers may leave a coefficient's binade: round it into the format
            try:
                pairs = [(m, e) if representable(m, e, fmt) else
                         round_to_float(math.ldexp(m, e), fmt) for m, e in zip(ms, es)]
            except (ValueError, OverflowError):
                continue
            out[method] = ([m for m, _ in pairs], [e for _, e in pairs])
    return out


def _to_monomial(prob: Problem, cheb) -> list[float]:
    """:func:`chebnorm.approx.fitting.cheb_to_monomial` on the problem's
    interval, the same exact rationals rounded once (so the same floats): the
    monomial coefficients of each ``T_k(u(x))`` are kept (:func:`_cheb_rows`),
    and each answer is an exact sum of their multiples (one exact
    matrix-vector product in integers over one common denominator, each
    quotient rounded once by Python's correctly rounded integer division)."""
    n = len(cheb)
    num, den = _cheb_rows_int(float(prob.lo_f), float(prob.hi_f), n)
    ratios = [float(c).as_integer_ratio() for c in cheb]   # raises on inf and nan
    scale = max(q for _, q in ratios)                       # powers of two
    ints = [p * (scale // q) for p, q in ratios]
    den = den * scale
    return [sum(map(operator.mul, row, ints)) / den for row in num]


@functools.lru_cache(maxsize=256)
def _cheb_rows_int(lo: float, hi: float, n: int):
    """:func:`_cheb_rows` as integers over one positive common denominator:
    ``(rows, den)``, ``rows`` a tuple of tuples of int (read only)."""
    rows = _cheb_rows(lo, hi, n)
    entries = [[rows[i, j] for j in range(n)] for i in range(n)]
    den = 1
    for row in entries:
        for e in row:
            den = math.lcm(den, int(e.q))
    return tuple(tuple(int(e.p) * (den // int(e.q)) for e in row) for row in entries), den


@functools.lru_cache(maxsize=256)
def _cheb_rows(lo: float, hi: float, n: int):
    """The exact ``n x n`` matrix (fmpq_mat) whose column ``k`` holds the
    monomial coefficients (powers ``0..n-1`` of ``x``) of ``T_k(u(x))``, ``u``
    mapping ``[lo, hi]`` onto ``[-1, 1]``; read only."""
    from flint import fmpq_mat, fmpq_poly

    from .fitting import chebyshev_t, exact_rational

    lo_q, hi_q = exact_rational(lo), exact_rational(hi)
    sub = fmpq_poly([(-lo_q - hi_q) / (hi_q - lo_q), 2 / (hi_q - lo_q)])
    cols = [(chebyshev_t(k)(sub).coeffs() + [0] * n)[:n] for k in range(n)]
    return fmpq_mat(n, n, [cols[k][j] for j in range(n) for k in range(n)])


@functools.lru_cache(maxsize=128)
def _greedy_nodes(f_np, lo: float, hi: float, n: int, k: int):
    """:func:`greedy`'s step ``k`` (degree ``n``): the ``k`` Chebyshev nodes of
    ``[lo, hi]``, their powers ``k..n``, ``f`` there and the transposed
    Chebyshev-Vandermonde matrix (read-only; shared by every quantization
    of one function on one interval); the powers also as rows ``n, n - 1,
    .., k`` after a row of zeros (the order :func:`greedy` sums them in)."""
    cheb_deg = k - 1
    t = np.polynomial.chebyshev.chebpts1(cheb_deg + 1)
    x = 0.5 * (lo + hi) + 0.5 * (hi - lo) * t
    with np.errstate(all="ignore"):
        fx = np.array(f_np(x))
    xj = {j: clib.power(x, j) for j in range(k, n + 1)}
    rows = np.array([np.zeros_like(x)] + [xj[j] for j in range(n, k - 1, -1)])
    vander_t = np.polynomial.chebyshev.chebvander(t, cheb_deg).T
    for a in (fx, vander_t, rows, *xj.values()):
        a.flags.writeable = False
    return xj, fx, vander_t, rows


def greedy(prob: Problem, real, quanta) -> list[int] | None:
    """Greedy rounding (all powers free): coefficient ``k`` rounded to its quantum
    ``2**quanta[k]`` from the highest power down, the lower ones refitted after
    each rounding (interpolation of the residual at Chebyshev nodes)."""
    f_np = prob.fn.numpy
    lo, hi = prob.lo_f, prob.hi_f
    n = prob.degree
    current = list(real)
    ints: dict[int, int] = {}
    for k in range(n, -1, -1):
        try:
            ints[k] = round(math.ldexp(current[k], -quanta[k]))
        except (OverflowError, ValueError):   # no integer at that quantum (a zero
            return None                       # coefficient's is the format's smallest)
        if k == 0:
            break
        high = {j: math.ldexp(q, quanta[j]) for j, q in ints.items()}
        nodes = prob.greedy_nodes.get(k)
        if nodes is None:                     # the same at every set of quanta
            nodes = prob.greedy_nodes[k] = _greedy_nodes(f_np, lo, hi, n, k)
        xj, fx, vander_t, rows = nodes
        # numpy's chebinterpolate(residual, k - 1) on cached nodes, its product
        # in a fixed order (BLAS sums in a CPU-dependent order): the residual
        # f - (0 + c_n x^n + .. + c_k x^k) and each row of the product summed
        # left to right, running sums (add.accumulate) of the same products
        c = np.array([0.0] + [high[j] for j in range(n, k - 1, -1)])
        with np.errstate(all="ignore"):
            resid = fx - np.add.accumulate(c[:, None] * rows, axis=0)[-1]
            cheb = np.add.accumulate(vander_t * resid, axis=1)[:, -1]
            cheb[0] /= k
            cheb[1:] /= 0.5 * k
        if not np.all(np.isfinite(cheb)):
            return None
        current = _to_monomial(prob, cheb) + [high[j] for j in range(k, n + 1)]
    return [ints[k] for k in range(n + 1)]


def _distinct(cands) -> list:
    """``cands`` (method, mantissas, exponents) as (method, ms, es, coefficient values),
    the first of each set of values kept, non-finite ones dropped."""
    rows, seen = [], set()
    for method, ms, es in cands:
        coeffs = tuple(map(math.ldexp, ms, es))
        if coeffs in seen or not all(map(math.isfinite, coeffs)):
            continue
        seen.add(coeffs)
        rows.append((method, list(ms), list(es), coeffs))
    return rows


def _rank(sampler: _Sampler, cands) -> list:
    """``cands`` (an iterable of (method, mantissas, exponents)) with finite,
    distinct coefficient values, as (sampled error, method, ms, es, coeffs),
    smallest sampled error first (ties: method name, then input order)."""
    rows = _distinct(cands)
    lows = sampler.errors([r[3] for r in rows]) if rows else []
    order = sorted(range(len(rows)), key=lambda i: (lows[i], rows[i][0], i))
    return [(lows[i],) + rows[i] for i in order]


def _ranked(sampler: _Sampler, cands, batch: int = 8):
    """:func:`_rank`'s rows in its order, generated lazily: the error on every
    point (``sampler``) is computed only for the rows that come next once the
    error on a thinned subset of the points (:meth:`_Sampler.thinned`, a lower
    bound of it) says no other row can come before them."""
    import heapq

    rows = _distinct(cands)
    if not rows:
        return
    # the thinned error of the rows whose error on every point is not known yet
    # (each row's error is computed on its own: the same float in any batch)
    lows, thin = sampler.lows, sampler.thin_lows
    new = [r[3] for r in rows if r[3] not in lows and r[3] not in thin]
    thin.update(zip(new, sampler.thinned().errors(new) if new else ()))
    # (error, 1 = on every point / 0 = thinned, method, index): a row whose error on
    # every point is on top comes before every other row, as in _rank's sort
    heap = [(lows[r[3]], 1, r[0], i) if r[3] in lows else (thin[r[3]], 0, r[0], i)
            for i, r in enumerate(rows)]
    heapq.heapify(heap)
    while heap:
        if heap[0][1]:
            low, _, _, i = heapq.heappop(heap)
            yield (low,) + rows[i]
            continue
        todo = []
        while heap and not heap[0][1] and len(todo) < batch:
            todo.append(heapq.heappop(heap)[3])
        for i, low in zip(todo, sampler.errors([rows[i][3] for i in todo])):
            sampler.lows[rows[i][3]] = low
            heapq.heappush(heap, (low, 1, rows[i][0], i))


def _error_at(prob: Problem, points, coeffs) -> float:
    """A rigorous lower bound of the error of ``coeffs`` (sup over the
    interval): its largest value at ``points`` (inside the interval), in ball
    arithmetic at 128 bits (no float evaluation allowance, which at a
    near-minimax binary64 error is larger than the candidates' differences)."""
    from flint import arb

    from chebnorm.core.numeric import arb_precision, ball_float_down

    from .certify import error_function

    with arb_precision(128):
        g = error_function(prob.fn.arb, [arb(c) for c in coeffs], prob.error_kind)
        best = arb(0)
        for x in points:
            v = abs(g(arb(x)))
            if v.is_finite():
                best = best.max(v.lower())
        return max(ball_float_down(best), 0.0)


def _peaks(prob: Problem, sampler: _Sampler, coeffs, zooms: int = 2) -> list[float]:
    """Where the error of ``coeffs`` has its local maxima (every one: a
    near-minimax error has ``n + 2`` of nearly one height), each found on the
    sampler's grid and refined by ``zooms`` denser grids around it."""
    thin = sampler.ordered()
    x = thin.x
    if x.size < 3:
        return []
    err = _point_errors(prob, x, coeffs, thin)
    inner = np.nonzero((err[1:-1] >= err[:-2]) & (err[1:-1] >= err[2:]))[0] + 1
    tops = [i for i in sorted(set(inner.tolist()) | {0, x.size - 1})
            if err[i] >= 0.5 * np.max(err)]
    # the highest few (float noise makes many tiny maxima next to each peak)
    tops = sorted(sorted(tops, key=lambda i: (-err[i], i))[:2 * (prob.degree + 2)])
    a = x[[max(i - 1, 0) for i in tops]]
    b = x[[min(i + 1, x.size - 1) for i in tops]]
    best = x[tops]
    for _ in range(zooms):                    # every peak's grid at once
        grid = a[:, None] + (b - a)[:, None] * np.linspace(0.0, 1.0, 65)[None, :]
        e = _point_errors(prob, grid.ravel(), coeffs).reshape(grid.shape)
        j = np.argmax(e, axis=1)
        rows = np.arange(len(tops))
        best = grid[rows, j]
        a, b = grid[rows, np.maximum(j - 1, 0)], grid[rows, np.minimum(j + 1, 64)]
    out = [float(v) for v in best]
    # the ends (the sampler keeps off them: lo_f and hi_f may lie a rounding
    # outside the exact interval; their inner neighbours do not)
    return out + [math.nextafter(prob.lo_f, math.inf), math.nextafter(prob.hi_f, -math.inf)]


def _point_errors(prob: Problem, x, coeffs, sampler: _Sampler | None = None) -> np.ndarray:
    """The error of ``coeffs`` at each of ``x`` as :meth:`_Sampler.error`
    computes it (``sampler``: one holding exactly these points, for its
    powers); -inf where it is not finite."""
    x = np.asarray(x, dtype=float)
    if sampler is None:
        with np.errstate(all="ignore"):
            f = np.asarray(prob.fn.numpy(x), dtype=float) * np.ones_like(x)
        xp = _Powers(x)
        w = 1.0 / np.abs(f) if prob.error_kind == "rel" else np.ones_like(f)
    else:
        f, xp, w = sampler.f, sampler.xp, sampler.w
    p, mag = np.zeros_like(x), np.zeros_like(x)
    for k, c in enumerate(coeffs):
        if c:
            term = c * xp[k]
            p += term
            mag += np.abs(term)
    with np.errstate(all="ignore"):
        err = w * (np.abs(p - f) - 2.0 ** -50 * (mag + np.abs(f)))
    return np.where(np.isfinite(err), err, -np.inf)


def _certify_ranked(prob: Problem, ranked: list, limit: int | None = None,
                    slack: float = 0.0, sampler: _Sampler | None = None,
                    incumbent: Candidate | None = None):
    """The smallest certified bound among ``ranked`` (from :func:`_rank`):
    candidates are certified in their sampled order, each against the best so
    far (aborted once proven no better); one whose sampled error (a lower bound
    of its supremum) already reaches the best bound is not certified, nor is
    any after it. ``limit``: at most that many certifications after the first
    success. ``slack``: nor is one whose sampled error reaches the best bound
    divided by ``1 + slack``: its certified bound is at least that, so the
    answer's bound is within a factor ``1 + slack`` of the smallest certified
    bound among all the candidates. ``incumbent``: a candidate certified
    before (another problem's answer, same powers 0..degree), the best so far
    from the start; it is returned when none certifies below its bound.
    Returns a Candidate or None (none certified)."""
    best, tries, peaks = incumbent, 0, []
    for low, method, ms, es, coeffs in ranked:
        if best is not None and (low * (1 + slack) >= best.bound
                                 or (limit is not None and tries >= limit)):
            break
        if slack and peaks and _error_at(prob, peaks, coeffs) * (1 + slack) >= best.bound:
            continue                          # its error where the others peak
        try:
            cert = _certify_key(prob, coeffs, None if best is None else best.bound)
        except ValueError:
            continue
        if slack and cert is not None and not peaks and sampler is not None:
            peaks = _peaks(prob, sampler, coeffs)
        tries += best is not None and best is not incumbent
        if cert is not None and (best is None or cert.bound < best.bound):
            best = Candidate(tuple(ms), tuple(es), method, cert.bound,
                             cert if prob.error_kind == "abs" else None,
                             cert if prob.error_kind == "rel" else None)
    return best


#: sample points of the cheap ranking inside the fixed-point chain
CHAIN_SAMPLES = 257
#: most certifications (after the first certified candidate) of a floating format
FLOAT_CERTIFY = None
#: a floating format's candidate is certified only while its sampled error is
#: below the best bound / (1 + FLOAT_SLACK): binary64 candidates often differ
#: by 1e-13 relative, far below the ranking certificates' own tolerance
#: (SELECT_TOL), and each one certified changed the bound by less than that
FLOAT_SLACK = SELECT_TOL


def _grid_lower_bounds(prob: Problem, fracs):
    """A function ``level ->`` a rigorous lower bound of the error (the
    problem's kind, sup over the interval) of EVERY polynomial whose free
    coefficient ``k`` is an integer multiple of ``2^-(fracs[k] - level)`` (the
    fixed ones held), for ``level = 0..min(fracs)``; 0 where nothing is proven.

    At ``n`` points ``x_i`` of the interval (``n`` free powers, Chebyshev
    nodes; on ``[0, hi]`` for one parity on a symmetric interval) with the
    Vandermonde ``V`` and ``g = f - (fixed part)``: a polynomial of error
    vector ``e`` (weighted by ``w = 1`` or ``1/|f|``) has coefficients ``c =
    V^-1 (g - e/w)``, so ``c_k`` on its grid ``q Z`` needs ``|u_k . (e/w)| >=
    dist(u_k . g, q Z)`` (``u_k`` row ``k`` of ``V^-1``), hence ``max|e| >=
    dist(u_k . g, q Z) / sum_i |u_ki| / w_i`` -- in ball arithmetic. The
    grids are nested (fewer bits: a subset), so a bound at a level also holds
    at every coarser one (the caller keeps the largest)."""
    from flint import arb, arb_mat

    from chebnorm.core.numeric import arb_precision

    def nothing(level):
        return 0.0

    n = len(prob.powers)
    lo = 0.0 if _symmetric_parity(prob) else prob.lo_f
    pts = [float(v) for v in chebyshev_nodes(lo, prob.hi_f, n)]
    if n == 0 or not all(prob.lo_f < v < prob.hi_f for v in pts) or len(set(pts)) < n:
        return nothing
    try:
        with arb_precision(128):
            xs = [arb(v) for v in pts]
            fx = [prob.fn.arb(x) for x in xs]
            g = [f - sum((arb(m) * arb(2) ** e * x ** k for k, (m, e) in prob.fixed.items()),
                         arb(0)) for f, x in zip(fx, xs)]
            inv = arb_mat([[x ** e for e in prob.powers] for x in xs]).inv()
            scale = [abs(f) if prob.error_kind == "rel" else arb(1) for f in fx]
            if not all(v.is_finite() for v in g + scale) or (
                    prob.error_kind == "rel" and any(f.contains(0) for f in fx)):
                return nothing
            # dual rows D_k = 2^f_k u_k: at level l the integers are 2^-l D_k . (g - e/w);
            # any integer combination a of them is an integer too, so every row of
            # LLL's transform of D (short combinations: small norms) gives a bound
            dual = [[inv[k, i] * arb(2) ** fracs[power] for i in range(n)]
                    for k, power in enumerate(prob.powers)]
            combos = [[int(j == k) for j in range(n)] for k in range(n)]
            combos += _short_combinations([[float((d * sc).mid()) for d, sc in zip(row, scale)]
                                           for row in dual])
            rows = []
            for a in combos:
                u = [sum((a[k] * dual[k][i] for k in range(n) if a[k]), arb(0)) for i in range(n)]
                v = sum((u[i] * g[i] for i in range(n)), arb(0))
                norm = sum((abs(u[i]) * scale[i] for i in range(n)), arb(0)).upper()
                if v.is_finite() and norm.is_finite() and norm > 0:
                    rows.append((v, norm))
    except (ValueError, ZeroDivisionError, ArithmeticError):
        return nothing

    def at(level: int) -> float:
        # a closure called later: it sets the precision itself
        try:
            with arb_precision(128):
                best = 0.0
                step = arb(2) ** level
                for v, norm in rows:
                    t = v / step
                    z = math.floor(float(t.mid()))
                    dist = min((abs(t - (z + d))).lower() for d in (-1, 0, 1, 2))
                    bound = step * dist / norm
                    if bound.is_finite() and bound > 0:
                        best = max(best, float(bound.lower()) * (1 - 2.0 ** -40))
                return best
        except (ValueError, ZeroDivisionError, ArithmeticError, OverflowError):
            return 0.0
    return at


def _short_combinations(rows: list[list[float]]) -> list[list[int]]:
    """Integer combinations of ``rows`` (floats) that are short: the rows of
    LLL's transform of them scaled to 60-bit integers (none when they cannot
    be reduced). Only which combinations to try depends on it."""
    big = max((abs(v) for row in rows for v in row if math.isfinite(v)), default=0.0)
    if not big > 0 or not all(math.isfinite(v) for row in rows for v in row):
        return []
    shift = 60 - math.frexp(big)[1]
    ints = [[int(round(math.ldexp(v, shift))) for v in row] for row in rows]
    if any(all(v == 0 for v in row) for row in ints):
        return []
    try:
        _, trans = fmpz_mat(ints).lll(transform=True)
    except (ValueError, ZeroDivisionError):
        return []
    return [[int(v) for v in row] for row in trans.tolist()]


def _chain_level(prob: Problem, coarse: _Sampler, real, fracs, level: int, greedy) -> list:
    """The fixed-point pool's members at ``F - level`` bits (all powers shifted
    alike): the plain rounding and the candidate with the smallest cheaply
    sampled error, as (method, mantissas, exponents) at ``F`` bits."""
    quanta = [-(f - level) for f in fracs]
    cands = _candidates(prob, coarse, real, quanta, greedy, "fixed")
    ranked = _rank(coarse, [(m, *c) for m, c in cands.items()])
    members = [("rounded",) + tuple(cands["rounded"])] if "rounded" in cands else []
    if ranked:
        members.append(tuple(ranked[0][1:4]))
    fq = [-f for f in fracs]
    return [(method, [m << (e - q) if m else 0 for m, e, q in zip(ms, es, fq)], fq)
            for method, ms, es in members]


def _fixed_pool(prob: Problem, sampler: _Sampler, real, fracs, greedy,
                incumbent: Candidate | None = None) -> Candidate | None:
    """The best certified member of the fixed-point pool: at every bit count
    ``b = 0..F`` the members of :func:`_chain_level`. The pool at ``F - 1``
    bits is a subset (same values) of the pool at ``F``, so the certified
    minimum over it never grows with the bits. Levels are visited from ``F``
    bits down; once :func:`_grid_lower_bounds` proves that no polynomial on
    the grid of a bit count (and of every coarser one) reaches the bound
    certified at ``F`` bits, the rest of the pool cannot win and is not built:
    the minimum is the one over the whole pool (or ``incumbent``, certified
    before, when nothing certifies below it)."""
    coarse = _Sampler(prob, CHAIN_SAMPLES)
    bound_at = _grid_lower_bounds(prob, fracs)
    pool, best, lower = [], None, 0.0

    def members(level):
        out = _chain_level(prob, coarse, real, fracs, level, greedy)
        if prob.word_limit is not None:
            out = [c for c in out if max(map(abs, c[1])) <= prob.word_limit]
        return out

    for level in range(min(fracs) + 1):       # F bits first, then fewer
        if best is not None:
            lower = max(lower, bound_at(level))   # this grid and every coarser one
            if lower >= best.bound:
                break
        pool += members(level)
        if level == 0:
            best = _certify_ranked(prob, _ranked(sampler, pool), incumbent=incumbent)
    return _certify_ranked(prob, _ranked(sampler, pool), incumbent=incumbent)


def round_coefficients(prob: Problem, real, fmt: str, frac_bits=None, greedy=None,
                       plain: bool = False, incumbent: Candidate | None = None) -> Candidate:
    """The best certified rounding of ``real`` (coefficients of all powers);
    with ``plain``, each coefficient rounded to nearest and nothing else.

    Candidates are ranked by their sampled error (float64, a dense grid) and
    certified in that order only while they can still beat the best bound
    certified (:func:`_certify_ranked`): the answer's bound is always
    rigorous, the ranking only decides which candidates are certified.

    Parameters
    ----------
    prob : Problem
        The function, interval, error kind, free and fixed powers and word limit.
    real : sequence of float
        The real (unrounded) coefficients of every power ``0..degree``.
    fmt : str
        One of :data:`FORMATS`: ``"fixed"`` or a float format of
        :data:`FLOAT_FORMATS`.
    frac_bits : sequence of int, optional
        For ``"fixed"``: the fraction bits of each power (required then);
        default None.
    greedy : callable, optional
        ``quanta -> list of int or None``: the greedy refit's integers for the
        exponents ``quanta`` of each power, one more candidate; default None.
    plain : bool, optional
        Round each coefficient to nearest and nothing else; default False.
    incumbent : Candidate, optional
        A candidate certified before (e.g. the answer of the parity
        sub-basis): these candidates are certified only while they can beat
        it, and it is the answer when none does; default None.

    Returns
    -------
    Candidate or None
        The candidate of least certified bound, or None when none can be
        certified (e.g. every one overflows the word).
    """
    sampler = _Sampler(prob)
    if plain:
        quanta = ([-f for f in frac_bits] if fmt == "fixed" else
                  [float_quantum(real[k], fmt) for k in range(prob.degree + 1)])
        cands = _candidates(prob, sampler, real, quanta, None, fmt, lattice=False)
        return _certify_ranked(prob, _rank(sampler, [(m, *c) for m, c in cands.items()]),
                               incumbent=incumbent)
    if fmt == "fixed":
        return _fixed_pool(prob, sampler, real, list(frac_bits), greedy, incumbent)
    # floating: quanta from the real coefficients, then from the best few
    # candidates' own binades (a lattice answer may leave a binade), a few rounds
    todo = [tuple(float_quantum(real[k], fmt) for k in range(prob.degree + 1))]
    tried = set()
    pool = []
    for _ in range(FLOAT_ROUNDS):
        todo = [q for q in todo if q not in tried]
        if not todo:
            break
        quanta = todo.pop(0)
        tried.add(quanta)
        cands = _candidates(prob, sampler, real, list(quanta), greedy, fmt)
        pool += [(m, *c) for m, c in cands.items()]
        ranked = _ranked(sampler, [(m, *c) for m, c in cands.items()])
        for _, _, ms, es, _ in itertools.islice(ranked, 8):
            # a zero coefficient keeps its quantum (float_quantum(0) is the
            # format's smallest, 2^-1074 in binary64: the real one would overflow)
            q = tuple(float_quantum(math.ldexp(m, e), fmt) if k in prob.powers and m
                      else quanta[k] for k, (m, e) in enumerate(zip(ms, es)))
            if q not in tried and q not in todo:
                todo.append(q)
    return _certify_ranked(prob, _ranked(sampler, pool), FLOAT_CERTIFY, FLOAT_SLACK, sampler,
                           incumbent)
