"""Where a highlight peaks on a triangle edge (seed 002, Gouraud highlight
detection).

On the edge ``N(t) = (1-t) N_A + t N_B`` of unit normals the cosine with the
half vector is ``h(t) = H.N(t) / |N(t)|``.  With ``a = H.N_A``, ``b = H.N_B``,
``c = N_A.N_B`` sympy derives (see :func:`edge_highlight_expr`):

* ``H.N(t) = (1-t) a + t b`` (generic vectors, modulo ``H.N_A = a``,
  ``H.N_B = b``) and ``|N(t)|^2`` from :func:`norm2_linear_expr`;
* the one root of ``dh/dt = 0``, ``t* = (b - a c) / ((a + b)(1 - c))``;
* ``h(t*)^2 = (a^2 - 2abc + b^2) / (1 - c^2)``, so the peak value is
  ``sqrt((a^2 - 2abc + b^2)/(1 - c^2))``.

Which stationary point is it?  ``t -> N(t)/|N(t)|`` maps the real line onto
the open half of the great circle through ``N_A, N_B`` centred on their
midpoint ``M``, and ``H.u`` restricted to that circle is ``R cos(angle)``
with ``R = sqrt((a^2 - 2abc + b^2)/(1 - c^2))`` the length of ``H`` projected
on the circle's plane.  Since ``H.M`` has the sign of ``a + b``:

* ``a + b > 0``: ``t*`` is the maximum of ``h`` on the whole line and
  ``h(t*) = R``; ``h`` increases before ``t*`` and decreases after it, so on
  the edge the maximum is at ``clip(t*, 0, 1)``;
* ``a + b < 0``: ``t*`` is the minimum (``h(t*) = -R``) and the maximum on the
  edge is at an endpoint; ``a + b = 0``: ``h`` is monotone, same conclusion.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import sympy as sp

from . import checks
from .algebra import reduce_modulo, vector
from .interpolation import norm2_linear_expr
from .symbols import a, b, c, t

# an implementation module of chebnorm.symbolic: the API is what chebnorm.symbolic exports
__all__: list[str] = []

GRAM_ATOL = 12 * checks.DOT_ATOL
"""Slack on the Gram determinant ``1 + 2abc - a^2 - b^2 - c^2 >= 0`` of
``H, N_A, N_B``: each partial derivative is at most 4 in size on
``[-1, 1]^3``, so ``DOT_ATOL`` of error in each of ``a, b, c`` moves it by at
most ``12 DOT_ATOL``."""


@dataclass(frozen=True)
class EdgeHighlight:
    """A point ``t`` on edge AB and the cosine ``value = H.N(t)/|N(t)|`` there.

    Holds sympy expressions (:func:`edge_highlight_expr`) or numpy arrays
    (:func:`edge_highlight`, :func:`edge_highlight_unclipped`).

    Attributes
    ----------
    t : sympy.Expr or numpy.ndarray
        The position on the edge, ``N(t) = (1 - t) N_A + t N_B``.
    value : sympy.Expr or numpy.ndarray
        The cosine ``H.N(t)/|N(t)|`` at ``t``.

    Examples
    --------
    Seed 002: the maximum is at ``t* = (b - a c)/((a + b)(1 - c))``, where it
    is ``sqrt((a^2 - 2abc + b^2)/(1 - c^2))``. With ``N_A``, ``N_B`` at 45
    degrees either side of ``H`` (``a = b = cos 45``, ``c = 0``) it is the
    midpoint, where the normalized normal is ``H`` itself:

    >>> import numpy as np
    >>> h = edge_highlight(np.cos(np.pi / 4), np.cos(np.pi / 4), 0.0)
    >>> float(h.t), round(float(h.value), 12)
    (0.5, 1.0)
    """

    t: Any
    value: Any


@lru_cache(maxsize=None)
def edge_cosine_expr() -> sp.Expr:
    """``h(t) = H.N(t)/|N(t)|`` in ``t, a, b, c`` (seed 002).

    >>> from chebnorm.symbolic.symbols import t, a
    >>> edge_cosine_expr().subs(t, 0)
    a
    """
    hv, na, nb = vector("H"), vector("N_A"), vector("N_B")
    nt = (1 - t) * na + t * nb
    h_dot_n = reduce_modulo(
        hv.dot(nt), [hv.dot(na) - a, hv.dot(nb) - b], [*hv, *na, *nb]
    )
    return h_dot_n / sp.sqrt(norm2_linear_expr())


@lru_cache(maxsize=None)
def edge_highlight_expr() -> EdgeHighlight:
    """The stationary point ``t*`` of ``h(t)`` and the value
    ``sqrt(h(t*)^2)`` (seed 002), derived by solving ``dh/dt = 0``.

    ``t* = (b - a c)/((a + b)(1 - c))`` and
    ``value = sqrt((a^2 - 2abc + b^2)/(1 - c^2))``; ``value = h(t*)`` when
    ``a + b > 0`` (then ``t*`` is the maximum), ``-h(t*)`` when ``a + b < 0``.

    >>> import sympy as sp
    >>> from chebnorm.symbolic.symbols import a, b, c
    >>> peak = edge_highlight_expr()
    >>> sp.simplify(peak.t - (b - a*c)/((a + b)*(1 - c)))
    0
    >>> sp.simplify(peak.value**2 - (a**2 - 2*a*b*c + b**2)/(1 - c**2))
    0
    """
    h = edge_cosine_expr()
    roots = sp.solve(sp.numer(sp.together(sp.diff(h, t))), t)
    if len(roots) != 1:
        raise RuntimeError(f"expected one stationary point of h(t), got {roots}")
    t_star = sp.factor(roots[0])
    value_sq = sp.factor(sp.cancel((h**2).subs(t, t_star)))
    return EdgeHighlight(t=t_star, value=sp.sqrt(value_sq))


@lru_cache(maxsize=None)
def _kernels():
    peak = edge_highlight_expr()
    args = (a, b, c)
    return (
        sp.lambdify(args, peak.t, modules="numpy"),
        sp.lambdify(args, peak.value, modules="numpy"),
        sp.lambdify((t, *args), edge_cosine_expr(), modules="numpy"),
    )


def _validate(a, b, c, func: str):
    aa = checks.cosine(a, "a = H.N_A", func)
    bb = checks.cosine(b, "b = H.N_B", func)
    cc = checks.cosine(c, "c = N_A.N_B", func)
    aa, bb, cc = checks.broadcast(func, "a, b and c", aa, bb, cc)
    checks.not_antiparallel(cc, "N_A and N_B", func)
    gram = 1 + 2 * aa * bb * cc - aa**2 - bb**2 - cc**2
    bad = gram < -GRAM_ATOL
    if bad.any():
        raise ValueError(
            f"{func}: a, b, c are not the dot products of three unit vectors "
            f"H, N_A, N_B: their Gram determinant 1 + 2abc - a^2 - b^2 - c^2 = "
            f"{gram[bad].flat[0]!r}{checks.where_text(bad)} must be >= "
            f"-GRAM_ATOL = {-GRAM_ATOL:g}"
        )
    return aa, bb, cc


def edge_highlight(a, b, c) -> EdgeHighlight:
    """The maximum of ``h(t) = H.N(t)/|N(t)|`` on the edge ``t in [0, 1]``
    (seed 002, steps 1-2 of the algorithm).

    Parameters
    ----------
    a : array_like
        ``H.N_A``, in ``[-1, 1]``.
    b : array_like
        ``H.N_B``, in ``[-1, 1]``.
    c : array_like
        ``N_A.N_B``, in ``(-1 + DOT_ATOL, 1]``. The three broadcast and must be
        the dot products of three unit vectors, up to ``GRAM_ATOL``.

    Returns
    -------
    EdgeHighlight
        If ``a + b > 0`` and ``t*`` lies in ``[0, 1]``, ``t = t*`` and
        ``value = sqrt((a^2 - 2abc + b^2)/(1 - c^2))``; otherwise ``t`` is the
        endpoint (``clip(t*, 0, 1)`` when ``a + b > 0``, the better endpoint
        when ``a + b <= 0``) and ``value = h(t)``, i.e. ``a`` or ``b``.

    Raises
    ------
    ValueError
        For arguments outside their ranges or not the dot products of unit vectors.

    Notes
    -----
    Parallel normals (``1 - c <= DOT_ATOL``): ``t*`` is undefined (0/0); the
    endpoint maximum ``max(a, b)`` is returned (``t = 0`` on ties).  The
    maximum over such an edge exceeds it by at most ``(1 - c)/4``.

    Examples
    --------
    >>> peak = edge_highlight(0.8, 0.8, 0.6)
    >>> print(f"{peak.t:.2f} {peak.value:.6f}")
    0.50 0.894427
    """
    aa, bb, cc = _validate(a, b, c, "edge_highlight")
    t_kernel, value_kernel, h_kernel = _kernels()
    parallel = 1 - cc <= checks.DOT_ATOL
    rising = (aa + bb > 0) & ~parallel
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t_star = np.asarray(t_kernel(aa, bb, cc), dtype=float)
        peak = np.asarray(value_kernel(aa, bb, cc), dtype=float)
    endpoint_t = np.where(aa >= bb, 0.0, 1.0)
    t_clipped = np.clip(np.where(rising, t_star, endpoint_t), 0.0, 1.0)
    interior = rising & (t_star >= 0.0) & (t_star <= 1.0)
    at_clipped = np.asarray(h_kernel(t_clipped, aa, bb, cc), dtype=float)
    value = np.where(interior, peak, at_clipped)
    return EdgeHighlight(
        t=checks.scalar_or_array(t_clipped), value=checks.scalar_or_array(value)
    )


def edge_highlight_unclipped(a, b, c) -> EdgeHighlight:
    """The stationary point ``t*`` of ``h`` on the whole line and
    ``value = sqrt((a^2 - 2abc + b^2)/(1 - c^2))`` (seed 002), unclipped.

    ``value`` is the largest ``H.u`` over unit ``u`` in the plane of
    ``N_A, N_B``; ``h(t*) = value`` if ``a + b > 0`` (``t*`` maximizes ``h``),
    ``h(t*) = -value`` if ``a + b < 0`` (``t*`` minimizes it).  Same input
    rules as :func:`edge_highlight`.  Where ``t*`` does not exist it is NaN:
    parallel normals (``1 - c <= DOT_ATOL``, then ``value`` is NaN too, the
    plane being undefined) and ``a + b = 0`` (``h`` monotone).

    Parameters
    ----------
    a, b, c : array_like
        ``H.N_A``, ``H.N_B``, ``N_A.N_B``, as for :func:`edge_highlight`.

    Returns
    -------
    EdgeHighlight
        ``t*`` (possibly outside ``[0, 1]``) and the value there.

    Raises
    ------
    ValueError
        As :func:`edge_highlight`.

    Examples
    --------
    >>> peak = edge_highlight_unclipped(0.9, 0.3, 0.6)
    >>> print(f"{peak.t:.3f} {peak.value:.6f}")
    -0.500 0.948683
    """
    aa, bb, cc = _validate(a, b, c, "edge_highlight_unclipped")
    t_kernel, value_kernel, _ = _kernels()
    parallel = 1 - cc <= checks.DOT_ATOL
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t_star = np.asarray(t_kernel(aa, bb, cc), dtype=float)
        peak = np.asarray(value_kernel(aa, bb, cc), dtype=float)
    t_star = np.where(parallel | (aa + bb == 0), np.nan, t_star)
    peak = np.where(parallel, np.nan, peak)
    return EdgeHighlight(
        t=checks.scalar_or_array(t_star), value=checks.scalar_or_array(peak)
    )
