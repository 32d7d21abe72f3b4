"""Certify many polynomial pieces of one function at once (piecewise tables).

Problem
-------
Segment ``s`` maps a local variable ``t`` in ``[l0, l1]`` affinely onto
``x = o_s + w_s t`` and carries a polynomial ``p_s(t) = sum_j c_sj t^j``; the
error is ``g_s = p_s - f(o_s + w_s t)`` (absolute) or ``p_s / f - 1``
(relative). :func:`certify_batch` returns, for every segment, the same
:class:`~chebnorm.approx.Certificate` as :func:`~chebnorm.approx.certify`
would -- a rigorous ``bound >= sup |g_s|`` within ``(1 + tol)`` of the
supremum -- but shares the work across segments instead of running one
branch and bound in ball arithmetic per segment.

Method
------
1. *Taylor model of each segment (Arb).* With ``t0 = (l0 + l1)/2``,
   ``rho = (l1 - l0)/2`` and ``u = t - t0`` in ``[-rho, rho]``, one
   ``arb_series`` evaluation at the centre gives the order-``n`` Taylor
   coefficients ``G_sk`` of ``g_s`` in ``u`` (balls; the polynomial's float
   coefficients and the endpoints enter exactly or as balls), and Lagrange's
   remainder ``|G_s,n+1(xi)| rho^(n+1)`` is enclosed by one evaluation over a
   ball covering the segment -- for the absolute error, where ``p_s`` has no
   term of order ``n + 1``, over a ball covering a whole *group* of segments
   (``f^(n+1) / (n+1)!`` on the group's hull times ``(|w_s| rho)^(n+1)``),
   the group halved until each segment's remainder is small.
2. *One float64 polynomial per segment.* ``D_s(u) = sum_k mid(G_sk) u^k``
   differs from ``g_s`` by at most ``slack_s = sum_k (rad G_sk + |mid| 2^-52)
   rho^k + remainder`` on the whole segment, all terms rounded upward.
3. *Vectorised branch and bound on the D_s (numpy).* Every piece ``[m - r,
   m + r]`` of every segment is handled in the same array operations: the
   Taylor coefficients ``e_k`` of ``D_s`` at ``m`` (Horner shifts), the
   quadratic part's maximum over ``|h| <= r`` taken exactly (both ends and
   the clamped vertex), the higher terms bounded by ``sum_{k>=3} |e_k| r^k``.
   The value of ``D_s`` at the piece's midpoint and at the vertex are lower
   bounds of ``sup |D_s|``. A piece is accepted when its upper bound plus
   ``slack_s`` is within ``(1 + tol)`` of the segment's best lower bound minus
   ``slack_s``; the others are bisected.
4. *Rounding errors of float64.* Each quantity computed in float64 is a
   polynomial expression with at most ``3n + 8`` roundings on every path, in
   coefficients whose absolute values sum, weighted by ``rho^k``, to
   ``S_s = sum_k |mid G_sk| rho^k`` (since ``|m| + r <= rho`` the Taylor
   shift's absolute coefficients obey ``sum_k |e_k|_abs r^k <= S_s``). So
   every piece's upper bound is raised, and every lower bound lowered, by
   ``(4n + 16) 2^-53 S_s`` -- far below the errors themselves, and rigorous
   without control of the rounding mode.

A segment the batch cannot settle -- ``g_s`` not finite on it (a singular
endpoint), a remainder too large at the highest order tried, an error at the
working-precision floor, or a piece narrower than ``2**-40`` of the segment;
and every segment when ``tol < MIN_TOL`` (``2**-40``, near float64's
resolution) -- is certified by :func:`~chebnorm.approx.certify` on its own,
so the result is never less rigorous, nor less tight, than the per-segment
certifier's.

Two segments of ``1/sqrt(x)``, ``[1, 2]`` and ``[2, 4]`` (``x = o + w t``):
the first error peaks inside, at 0.011960..., the second at ``x = 4``,
where it is ``0.55 - 1/2``:

>>> from chebnorm.approx.expr import parse_function
>>> f = parse_function("1/sqrt(x)")
>>> cs = certify_batch(f, [1, 2], [1, 2], [[1.0, -0.4, 0.1], [0.7, -0.2, 0.05]])
>>> [f"{c.maximum:.6f}" for c in cs], cs[1].at
(['0.011960', '0.050000'], 1.0)
>>> all(c.maximum <= c.bound <= (1 + 2**-8) * c.maximum for c in cs)
True
"""

from __future__ import annotations

import math
from fractions import Fraction
from numbers import Rational
from typing import Sequence

import numpy as np
import sympy as sp
from flint import arb, arb_series, ctx

from chebnorm.core import detlinalg
from chebnorm.core.numeric import arb_precision
from chebnorm.exceptions import SegmentError
from .certify import TOL, Certificate, arb_enclose, certify
from .expr import Function1D

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

#: Taylor orders tried in turn, above the polynomial's degree (the first whose
#: remainder is small enough for the segment)
EXTRA_ORDERS = (5, 12, 24)
#: tightness below which float64 cannot settle a segment: every segment then
#: goes to the per-segment certifier (working at 128 bits)
MIN_TOL = 2.0 ** -40
#: initial pieces per segment (a power of two keeps every piece end exact)
_START_PIECES = 8
#: bisection rounds before a segment is handed to the per-segment certifier
_MAX_ROUNDS = 40
_U = 2.0 ** -53


def _ball(value) -> arb:
    """An Arb ball around an exact number (int, Fraction, sympy constant, float, arb)."""
    if isinstance(value, arb):
        return value
    if isinstance(value, (int, np.integer)):
        return arb(int(value))
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"segment end {value!r} is not finite")
        return arb(value)
    if isinstance(value, Rational):
        return arb(int(value.numerator)) / int(value.denominator)
    if isinstance(value, sp.Basic) and value.is_Rational:
        return arb(int(value.p)) / int(value.q)
    if isinstance(value, sp.Basic):
        return arb_enclose(value)
    raise ValueError(f"segment end {value!r}: accepted: an int, Fraction, float, sympy "
                     f"constant or Arb ball")


class _Affine:
    """``t -> f(o + w t)`` with ``o`` and ``w`` balls, for the fallback certifier.

    A ball ``t`` that starts exactly at the local range's start ``l0`` (or ends
    exactly at its end ``l1``) -- the certifier's piece at a singular endpoint,
    ``[0, r]`` for ``sqrt`` at ``x = 0`` -- maps to a ball that starts exactly at
    ``o + w l0`` (ends at ``o + w l1``) when ``o`` and ``w`` are exact (``w > 0``):
    ``o + w t`` in ball arithmetic would widen it past that end, where ``sqrt`` is
    not real."""

    def __init__(self, fn: Function1D, o: arb, w: arb, l0: float = 0.0, l1: float = 1.0):
        self.expr = fn.expr
        f_series, f_point = fn.arb_series, fn.arb
        self.arb_series = lambda s: f_series(o + w * s)
        exact = o.is_exact() and w.is_exact() and w > 0
        ends = (arb(l0), arb(l1))
        self.arb = lambda x: f_point(_affine_image(o, w, x, ends) if exact else o + w * x)

    def __str__(self) -> str:
        return f"{self.expr} on a segment"


def _affine_image(o: arb, w: arb, x: arb, ends: tuple[arb, arb]) -> arb:
    """A ball containing ``o + w x`` for ``x`` in the ball ``x`` (``o``, ``w`` exact,
    ``w > 0``) whose lower end is exactly ``o + w l0`` when ``x`` starts exactly at
    ``l0`` (whose upper end is exactly ``o + w l1`` when ``x`` ends exactly at
    ``l1``), as :func:`chebnorm.approx.certify._ball` builds its pieces."""
    if x.is_exact() or not x.is_finite():
        return o + w * x
    lo_t, hi_t = arb(x.lower()), arb(x.upper())
    lo, hi = o + w * lo_t, o + w * hi_t
    span = arb(0).union((hi - lo).upper()).nonnegative_part()  # [0, >= hi - lo]
    if (lo_t - ends[0]).is_zero() and lo.is_exact():
        return lo + span
    if (hi_t - ends[1]).is_zero() and hi.is_exact():
        return hi - span
    return o + w * x


def _exact_half(lo: float, hi: float) -> tuple[float, float]:
    t0, rho = (lo + hi) / 2, (hi - lo) / 2
    if Fraction(t0) != (Fraction(lo) + Fraction(hi)) / 2 or \
            Fraction(rho) != (Fraction(hi) - Fraction(lo)) / 2 or not rho > 0:
        raise ValueError(f"local interval [{lo!r}, {hi!r}]: accepted: float ends lo < hi "
                         f"whose midpoint and half-width are exact floats")
    return t0, rho


def certify_batch(fn: Function1D, origins: Sequence, widths: Sequence,
                  coefficients: Sequence[Sequence[float]], local=(0, 1), kind: str = "abs",
                  tol: float = TOL) -> list[Certificate]:
    """Certify ``sup_{t in local} |g_s(t)|`` for every segment ``s`` (module docstring).

    ``g_s = p_s - f(x)`` (``kind="abs"``) or ``p_s/f(x) - 1`` (``"rel"``)
    with ``x = origins[s] + widths[s] * t`` and ``p_s(t) = sum_j
    coefficients[s][j] t^j`` (float coefficients, taken exactly).
    ``origins`` and ``widths`` are exact numbers (int, Fraction, sympy
    constants) or Arb balls containing them; ``local`` is the interval of
    ``t``, float ends with an exact midpoint. The returned certificates are
    those of :func:`~chebnorm.approx.certify` on each segment (``at`` is a
    value of ``t``): ``maximum <= sup |g_s| <= bound <= (1 + tol) sup |g_s|``
    unless a cap was reached (then ``tight`` is False and ``reason`` says
    why). Raises ValueError as ``certify`` does when ``g_s`` is not finite.

    Parameters
    ----------
    fn : Function1D
        The function ``f``.
    origins, widths : sequence of exact numbers or flint.arb
        Per segment, the origin and the width of the map ``t -> x``; one of each
        per entry of ``coefficients``.
    coefficients : sequence of sequence of float
        Per segment, the finite float coefficients of ``p_s`` in powers of ``t``
        (an empty list stands for ``[0.0]``).
    local : tuple of float, optional
        The interval of ``t``, default ``(0, 1)``; its midpoint must be exact.
    kind : {"abs", "rel"}, optional
        The error certified, default ``"abs"``.
    tol : float, optional
        The relative tightness aimed at, a finite number > 0; default
        :data:`chebnorm.approx.certify.TOL` (2^-8).

    Returns
    -------
    list of Certificate
        One certificate per segment, in order.

    Raises
    ------
    ValueError
        When ``kind`` or ``tol`` is out of range, the three sequences differ in
        length, a coefficient is not finite, or ``g_s`` is not finite on a
        segment.

    Examples
    --------
    >>> from chebnorm.approx.expr import parse_function
    >>> c, = certify_batch(parse_function("exp(x)"), [0], [1], [[1.0, 1.0, 0.5]], (-0.5, 0.5))
    >>> c.maximum <= c.bound <= (1 + 2**-8) * c.maximum, 0.02 < c.bound < 0.03
    (True, True)
    """
    if kind not in ("abs", "rel"):
        raise ValueError(f"error kind {kind!r} is not one of 'abs', 'rel'")
    if not (isinstance(tol, (int, float)) and math.isfinite(tol) and tol > 0):
        raise ValueError(f"tol {tol!r}: accepted: a finite number > 0")
    count = len(coefficients)
    if len(origins) != count or len(widths) != count:
        raise ValueError(f"{len(origins)} origins, {len(widths)} widths and {count} "
                         f"coefficient lists: accepted: one of each per segment")
    l0, l1 = float(local[0]), float(local[1])
    t0, rho = _exact_half(l0, l1)
    coeffs = [[float(c) for c in cs] or [0.0] for cs in coefficients]
    if any(not math.isfinite(c) for cs in coeffs for c in cs):
        raise ValueError("coefficients: accepted: finite floats")
    old_cap = ctx.cap
    try:
        with arb_precision(128):
            # series of the highest order tried (python-flint truncates at ctx.cap terms)
            ctx.cap = max(old_cap, max(map(len, coeffs), default=1) + EXTRA_ORDERS[-1] + 2)
            o = [_ball(v) for v in origins]
            w = [_ball(v) for v in widths]
            return _run(fn, o, w, coeffs, t0, rho, l0, l1, kind, float(tol))
    finally:
        ctx.cap = old_cap


def _run(fn, o, w, coeffs, t0, rho, l0, l1, kind, tol) -> list[Certificate]:
    count = len(coeffs)
    out: list[Certificate | None] = [None] * count
    todo, alone = ([], list(range(count))) if tol < MIN_TOL else (list(range(count)), [])
    for extra in EXTRA_ORDERS:
        if not todo:
            break
        # order > degree: the polynomial has no term of the remainder's order
        n = max(len(coeffs[s]) for s in todo) - 1 + extra
        model = _models(fn, o, w, coeffs, todo, t0, rho, n, kind, tol)
        done = _branch_and_bound(model.mids, model.slack, t0, rho, tol)
        for i, s in enumerate(model.keep):
            cert = None if done[i] is None else _certificate(fn, o[s], w[s], coeffs[s], kind,
                                                            *done[i])
            if cert is None:
                alone.append(s)
            else:
                out[s] = cert
        alone.extend(model.bad)
        todo = model.coarse
    for s in sorted(alone + todo):
        try:
            out[s] = certify(_Affine(fn, o[s], w[s], l0, l1), coeffs[s], sp.Rational(l0),
                             sp.Rational(l1), kind, tol=tol)
        except ValueError as exc:
            raise SegmentError(s, str(exc)) from None
    return out  # type: ignore[return-value]


class _Model:
    """Float64 Taylor models of the segments ``keep``: row ``i`` of ``mids``
    holds the coefficients of ``D`` in ``u``, ``slack[i]`` bounds ``|g - D|``
    on the segment; ``bad``: segments where ``g`` has no finite model;
    ``coarse``: where the remainder is too large at this order."""

    def __init__(self, keep, mids, slack, bad, coarse):
        self.keep, self.mids, self.slack, self.bad, self.coarse = keep, mids, slack, bad, coarse


def _padded(series: arb_series, n: int) -> list[arb]:
    """The first ``n`` Taylor coefficients; ValueError when the series is shorter
    (python-flint truncates series at ``ctx.cap`` terms)."""
    if series.prec < n:
        raise ValueError(f"series of {series.prec} terms, {n} needed")
    c = series.coeffs()  # flint drops trailing zeros
    return c + [arb(0)] * (n - len(c)) if len(c) < n else c[:n]


def _shifted(cs: Sequence[float], t0: arb | None) -> list[arb]:
    """Coefficients of ``p(t0 + u)`` in ``u`` (Horner shifts in Arb; exact for binary ``t0``)."""
    p = [arb(c) for c in cs]
    if t0 is not None:
        d = len(p) - 1
        for i in range(d):
            for j in range(d - 1, i - 1, -1):
                p[j] = p[j] + t0 * p[j + 1]
    return p


def _up(x: arb) -> float:
    """A float >= every point of the ball ``x`` (inf if it is not finite)."""
    if not x.is_finite():
        return math.inf
    return math.nextafter(float(x.upper()), math.inf)


def _models(fn, o, w, coeffs, todo, t0, rho, n, kind, tol) -> _Model:
    f_series = fn.arb_series
    t0_b = arb(t0) if t0 != 0 else None
    unit = arb_series([0, 1], prec=n + 1)
    u_ball = arb(0, rho)
    rows, rads, rems, keep, bad, centres = [], [], [], [], [], {}
    for s in todo:
        xc = centres[s] = o[s] if t0_b is None else o[s] + w[s] * t0_b
        try:
            p = _shifted(coeffs[s], t0_b)
            f_c = f_series(xc + w[s] * unit)
            if kind == "abs":
                g = _padded(f_c, n + 1)
                for k in range(len(p)):
                    g[k] = g[k] - p[k]  # -(p - f): the sign is restored below
                rem = 0.0
            else:
                g = _padded(arb_series(p, prec=n + 1) / f_c, n + 1)
                g[0] = g[0] - 1
                sb = arb_series([u_ball, 1], prec=n + 2)
                p_b = arb_series(p[-1:], prec=n + 2)
                for c in reversed(p[:-1]):
                    p_b = p_b * sb + c
                g_b = p_b / f_series(xc + w[s] * sb)
                rem = _up(abs(_padded(g_b, n + 2)[n + 1])) * rho ** (n + 1) * (1 + 2.0 ** -40)
        except (ValueError, ZeroDivisionError):
            bad.append(s)
            continue
        keep.append(s)
        rows.append([float(c) for c in g])
        rads.append([float(c.rad()) for c in g])  # inf or nan where not finite
        rems.append(rem)
    k = len(keep)
    with np.errstate(over="ignore", invalid="ignore"):
        mids = np.array(rows, dtype=float).reshape(k, n + 1)
        if kind == "abs":
            mids = -mids
        rad = np.array(rads, dtype=float).reshape(k, n + 1)
        finite = np.all(np.isfinite(mids), axis=1) & np.all(np.isfinite(rad), axis=1)
        # |g - D| <= sum_k (rad_k + |mid_k| 2^-52) rho^k + remainder, rounded up
        powers = rho ** np.arange(n + 1)
        # (2^-1000 per coefficient: a float that underflowed)
        coef_slack = detlinalg.matvec(rad * (1 + 2.0 ** -50) + np.abs(mids) * 2.0 ** -52
                                      + 2.0 ** -1000, powers) * (1 + 2.0 ** -45)
        size = _grid_max(np.where(np.isfinite(mids), mids, 0.0), rho)
    # the slack is spent twice (upper and lower bound): keep it well inside tol
    budget = tol * size / 16
    if kind == "abs":
        rem = _group_remainders(f_series, centres, w, keep, rho, n, budget)
    else:
        rem = np.array(rems, dtype=float).reshape(k)
    with np.errstate(over="ignore", invalid="ignore"):
        slack = (coef_slack + rem) * (1 + 2.0 ** -50)
    ok = np.zeros(k, dtype=bool)
    coarse = []
    for i, s in enumerate(keep):
        if not (finite[i] and math.isfinite(rem[i]) and math.isfinite(slack[i])):
            bad.append(s)
        elif slack[i] <= budget[i]:
            ok[i] = True
        else:
            coarse.append(s)
    idx = np.flatnonzero(ok)
    return _Model([keep[i] for i in idx], mids[idx], slack[idx], sorted(bad), coarse)


def _grid_max(mids: np.ndarray, rho: float, points: int = 33) -> np.ndarray:
    """``max |D|`` on an even grid of ``[-rho, rho]`` (the size of the error, not a bound)."""
    if mids.shape[0] == 0:
        return np.zeros(0)
    u = np.linspace(-rho, rho, points)
    acc = np.repeat(mids[:, -1:], points, axis=1)
    for k in range(mids.shape[1] - 2, -1, -1):
        acc = acc * u + mids[:, k:k + 1]
    return np.max(np.abs(acc), axis=1)


def _group_remainders(f_series, centres, w, segs, rho, n, budget) -> np.ndarray:
    """Lagrange remainders of ``f`` for the absolute error, ``|f^(n+1)(hull)/(n+1)!|
    (|w_s| rho)^(n+1)``, the hull a ball covering a group of segments; a group
    where some remainder exceeds its ``budget`` is halved (down to single segments)."""
    k = len(segs)
    rem = np.full(k, math.inf)
    if not k:
        return rem
    u_ball = arb(0, rho)
    spans = [centres[s] + w[s] * u_ball for s in segs]
    wup = np.empty(k)
    last, last_up = None, math.inf
    for i, s in enumerate(segs):
        if w[s] is not last:  # uniform tables share one width ball
            last, last_up = w[s], _up(abs(w[s]))
        wup[i] = last_up
    with np.errstate(over="ignore"):
        scaled = (wup * rho) ** (n + 1) * (1 + 2.0 ** -40)
    stack = [np.arange(k)]
    while stack:
        grp = stack.pop()
        hull = spans[grp[0]]
        for i in grp[1:]:
            hull = hull.union(spans[i])
        try:
            cf = _up(abs(_padded(f_series(arb_series([hull, 1], prec=n + 2)), n + 2)[n + 1]))
        except (ValueError, ZeroDivisionError):
            cf = math.inf
        with np.errstate(over="ignore", invalid="ignore"):
            r = cf * scaled[grp] if cf > 0 else np.zeros(len(grp))
        rem[grp] = np.where(np.isnan(r), math.inf, r)
        if len(grp) > 1 and not np.all(rem[grp] <= budget[grp]):
            half = len(grp) // 2
            stack += [grp[:half], grp[half:]]
    return rem


#: a segment with more live pieces than this goes to the per-segment certifier
_MAX_LIVE = 4096


def _branch_and_bound(mids: np.ndarray, slack: np.ndarray, t0: float, rho: float,
                      tol: float) -> list[tuple[float, float, int] | None]:
    """Bound ``sup |g_s|`` for every row ``s`` of ``mids`` (the coefficients of
    ``D_s`` in ``u``, ``|g_s - D_s| <= slack[s]``), bisecting pieces of
    ``[-rho, rho]`` until ``upper <= (1 + tol) * lower``: ``(upper, at,
    pieces)`` with ``at = t0 + u`` where ``|D_s|`` was largest; None for a
    segment a cap stopped."""
    count = mids.shape[0]
    if count == 0:
        return []
    n = mids.shape[1] - 1
    if n < 2:
        mids = np.hstack([mids, np.zeros((count, 2 - n))])
        n = 2
    absm = np.abs(mids)
    size = absm[:, -1].copy()
    for k in range(n - 1, -1, -1):
        size = size * rho + absm[:, k]
    # a bound of every float64 rounding error in a piece's bounds (module docstring, 4.)
    err = (8 * n + 32) * _U * size * (1 + 2.0 ** -40)
    grow = 1 + 2.0 ** -48
    # accept within (1 + tol), less a margin (far above float64 rounding: tol >=
    # MIN_TOL) for rounding `at` to a float and this product
    scale = 1 + tol * (1 - 2.0 ** -8)
    r0 = rho / _START_PIECES
    seg = np.repeat(np.arange(count), _START_PIECES)
    m = np.tile(-rho + r0 * (2 * np.arange(_START_PIECES) + 1), count)
    r = np.full(seg.size, r0)
    best = np.full(count, -math.inf)
    best_u = np.zeros(count)
    accepted = np.zeros(count)
    pieces = np.zeros(count, dtype=np.int64)
    failed = np.zeros(count, dtype=bool)
    min_r = rho * 2.0 ** -40
    for _ in range(_MAX_ROUNDS):
        if seg.size == 0:
            break
        pieces += np.bincount(seg, minlength=count)
        c = mids[seg]  # a copy, shifted to each piece's midpoint
        for i in range(n):
            for j in range(n - 1, i - 1, -1):
                c[:, j] += m * c[:, j + 1]
        e0, e1, e2 = c[:, 0], c[:, 1], c[:, 2]
        tail = np.abs(c[:, n])
        for k in range(n - 1, 2, -1):
            tail = tail * r + np.abs(c[:, k])
        tail = tail * (r * r * r)
        r2 = r * r
        nz = e2 != 0
        hv = np.zeros(seg.size)
        hv[nz] = -e1[nz] / (2 * e2[nz])
        hv = np.clip(hv, -r, r)
        q_lo, q_hi = np.abs(e0 - e1 * r + e2 * r2), np.abs(e0 + e1 * r + e2 * r2)
        q_v = np.abs(e0 + hv * (e1 + hv * e2))
        q = np.maximum(np.maximum(q_lo, q_hi), q_v)
        e = err[seg]
        upper = ((q + tail) * grow + e + slack[seg]) * grow
        # lower bounds of sup |D|: D at the midpoint, and where the quadratic part
        # is largest (an end or the vertex)
        hv = np.where(q_v >= q, hv, np.where(q_lo >= q_hi, -r, r))
        dv = c[:, n].copy()
        for k in range(n - 1, -1, -1):
            dv = dv * hv + c[:, k]
        at_vertex = np.abs(dv) >= np.abs(e0)
        low = np.where(at_vertex, np.abs(dv), np.abs(e0)) - e
        where = np.where(at_vertex, m + hv, m)
        order = np.lexsort((low, seg))
        last = np.ones(order.size, dtype=bool)
        last[:-1] = seg[order[1:]] != seg[order[:-1]]
        top = order[last]
        top = top[low[top] > best[seg[top]]]
        best[seg[top]] = low[top]
        best_u[seg[top]] = where[top]
        # |g| at the best point found is at least best - 2 slack (the slack of
        # D there and of D at the vertex): so bound <= (1 + tol) * maximum
        ok = upper <= scale * (best[seg] - 2 * slack[seg])
        np.maximum.at(accepted, seg[ok], upper[ok])
        live = ~ok
        failed[seg[live & (r < min_r)]] = True
        live &= ~failed[seg]
        seg, m, r = seg[live], m[live], r[live]
        crowded = np.bincount(seg, minlength=count) * 2 > _MAX_LIVE
        if crowded.any():
            failed |= crowded
            keep = ~crowded[seg]
            seg, m, r = seg[keep], m[keep], r[keep]
        h = r / 2
        seg = np.concatenate([seg, seg])
        m = np.concatenate([m - h, m + h])
        r = np.concatenate([h, h])
    if seg.size:
        failed[seg] = True
    at = np.clip(t0 + best_u, t0 - rho, t0 + rho)
    return [None if failed[s] else (float(accepted[s]), float(at[s]), int(pieces[s]))
            for s in range(count)]


def _certificate(fn, o, w, cs, kind, bound, at, pieces) -> Certificate | None:
    """The certificate, with ``maximum = |g(at)|`` evaluated in Arb (rounded down)."""
    ta = arb(at)
    p = arb(cs[-1])
    for c in reversed(cs[:-1]):
        p = p * ta + c
    try:
        fx = fn.arb(o + w * ta)
        v = p - fx if kind == "abs" else p / fx - 1
    except (ValueError, ZeroDivisionError):
        return None
    if not v.is_finite():
        return None
    maximum = max(-_up(-abs(v)), 0.0)
    return Certificate(bound=max(bound, maximum), maximum=maximum, at=at, subintervals=pieces)
