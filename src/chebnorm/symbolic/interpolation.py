"""Linear and quadratic interpolation of unit normals, and the error of not
normalizing them (seed 003; midpoint and quadratic span also seed 000).

Every closed form here is *derived* by sympy from its definition, once (the
derivations are cached), and exposed twice:

* ``*_expr()`` returns the sympy expression, written in the symbols of
  :mod:`chebnorm.symbolic.symbols`;
* a numpy function evaluates it.  Scalar closed forms are evaluated by
  ``sympy.lambdify`` of the derived expression; vector results are assembled
  from lambdified scalar factors.  The numpy functions validate their input
  (see :mod:`chebnorm.symbolic.checks` for the tolerances) and return a numpy
  scalar for scalar input, an array otherwise.

Derivations
-----------
1. ``|N(t)|^2`` for ``N(t) = (1-t) N_A + t N_B``: the dot product of generic
   symbolic 3-vectors is expanded and rewritten modulo ``N_A.N_A = 1``,
   ``N_B.N_B = 1``, ``N_A.N_B = c``; the result is ``1 - 2t(1-t)(1-c)``.
2. ``|N_A + N_B|^2`` the same way, ``= 2(1 + c)``; the midpoint normal is
   ``(N_A + N_B)`` times ``1/sqrt(2(1 + c))``.
3. ``d|N(t)|^2/dt = 0`` is solved for ``t`` (``t = 1/2``, a minimum since the
   second derivative ``4(1-c)`` is positive for ``c < 1``), which gives
   ``min |N| = sqrt((1 + c)/2)``.  With ``c = cos(phi) = 2 cos(phi/2)^2 - 1``
   and ``cos(phi/2) >= 0`` on ``[0, pi]`` this is ``cos(phi/2)``.
4. Without normalization a diffuse term ``L.N`` is scaled by ``|N|`` and a
   specular term ``(H.N)^n`` by ``|N|^n``; the relative errors ``1 - |N|``
   and ``1 - |N|^n`` are largest at ``min |N|``: ``delta_d``, ``delta_s``.
5. ``eta`` is the sum over the three edges of the edge bound
   ``1 - min |N| = 1 - sqrt(2(1 + c_ij))/2``.
6. ``N(t) = G t^2 + P t + Q`` through ``N_l, N_c, N_r`` at ``t = 0, 1/2, 1``:
   the three interpolation conditions are solved with ``sympy.linsolve``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import sympy as sp

from . import checks
from .algebra import reduce_modulo, vector
from .symbols import N_c, N_l, N_r, c, c_ab, c_ac, c_bc, n, phi, t

# an implementation module of chebnorm.symbolic: the API is what chebnorm.symbolic exports
__all__: list[str] = []


def _unit_relations(na: sp.Matrix, nb: sp.Matrix) -> list[sp.Expr]:
    """``N_A.N_A = 1``, ``N_B.N_B = 1``, ``N_A.N_B = c`` as polynomials."""
    return [na.dot(na) - 1, nb.dot(nb) - 1, na.dot(nb) - c]


# ---------------------------------------------------------------- 1. |N(t)|^2
@lru_cache(maxsize=None)
def norm2_linear_expr() -> sp.Expr:
    """``|N(t)|^2`` of ``N(t) = (1-t) N_A + t N_B``, unit ``N_A, N_B`` (seed 003).

    Derived by expanding the dot product of generic symbolic vectors and
    rewriting it modulo the unit-length and ``N_A.N_B = c`` relations.

    >>> import sympy as sp
    >>> from chebnorm.symbolic.symbols import t, c
    >>> sp.expand(norm2_linear_expr() - (1 - 2*t*(1 - t)*(1 - c)))
    0
    """
    na, nb = vector("N_A"), vector("N_B")
    nt = (1 - t) * na + t * nb
    return reduce_modulo(nt.dot(nt), _unit_relations(na, nb), [*na, *nb])


@lru_cache(maxsize=None)
def _norm2_linear_kernel():
    return sp.lambdify((t, c), norm2_linear_expr(), modules="numpy")


def norm2_linear_np(t, c):
    """``|N(t)|^2 = 1 - 2t(1-t)(1-c)`` for arrays ``t`` and ``c = N_A.N_B``.

    Seed 003, squared length of the linearly interpolated normal.  ``t`` may
    be any finite real (the identity holds on the whole line); ``c`` must lie
    in ``[-1, 1]`` (up to ``DOT_ATOL``, then clipped).  Arguments broadcast.

    Parameters
    ----------
    t : array_like
        Positions along the edge (any finite reals).
    c : array_like
        ``N_A.N_B``, in ``[-1, 1]``.

    Returns
    -------
    numpy.ndarray or numpy.float64
        The squared lengths.

    Raises
    ------
    ValueError
        For non-finite input or ``c`` outside ``[-1, 1]`` beyond ``DOT_ATOL``.

    Examples
    --------
    >>> print(f"{norm2_linear_np(0.5, 0.0):.3f}")
    0.500
    """
    func = "norm2_linear_np"
    tt = checks.real_array(t, "t", func)
    cc = checks.cosine(c, "c", func)
    tt, cc = checks.broadcast(func, "t and c", tt, cc)
    out = np.asarray(_norm2_linear_kernel()(tt, cc), dtype=float)
    return checks.scalar_or_array(np.broadcast_to(out, tt.shape).copy())


# ------------------------------------------------------ 2. midpoint normal
@lru_cache(maxsize=None)
def midpoint_norm2_expr() -> sp.Expr:
    """``|N_A + N_B|^2`` for unit ``N_A, N_B`` with ``N_A.N_B = c``: ``2(1 + c)``.

    >>> midpoint_norm2_expr()
    2*(c + 1)
    """
    na, nb = vector("N_A"), vector("N_B")
    s = na + nb
    return reduce_modulo(s.dot(s), _unit_relations(na, nb), [*na, *nb])


@lru_cache(maxsize=None)
def midpoint_scale_expr() -> sp.Expr:
    """The factor ``1/|N_A + N_B| = 1/sqrt(2(1 + c))`` that normalizes the
    midpoint (seed 003; seed 000, dichotomy with ``z = 2c``).

    >>> from chebnorm.symbolic.symbols import c
    >>> midpoint_scale_expr().subs(c, 0)
    sqrt(2)/2
    """
    return 1 / sp.sqrt(midpoint_norm2_expr())


@lru_cache(maxsize=None)
def _midpoint_scale_kernel():
    return sp.lambdify((c,), midpoint_scale_expr(), modules="numpy")


def midpoint_normal(na, nb) -> np.ndarray:
    """Normalized midpoint ``(N_A + N_B) / sqrt(2(1 + N_A.N_B))`` (seed 003).

    Parameters
    ----------
    na, nb : array_like
        Unit normals, shape ``(..., 3)``; they broadcast.

    Returns
    -------
    numpy.ndarray
        The unit midpoint normals, shape ``(..., 3)``.

    Raises
    ------
    ValueError
        For zero, non-finite or non-unit vectors and for antiparallel pairs
        (``1 + N_A.N_B <= DOT_ATOL``), where the formula divides by zero.

    Notes
    -----
    Possible issues: the result has unit length only as far as the inputs do;
    its length error is about ``(| |N_A| - 1 | + | |N_B| - 1 |) / (2(1 + c))``.

    Examples
    --------
    >>> m = midpoint_normal([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    >>> print(np.round(m, 6))
    [0.707107 0.707107 0.      ]
    """
    func = "midpoint_normal"
    a = checks.unit_vectors(na, "na", func)
    b = checks.unit_vectors(nb, "nb", func)
    a, b = checks.broadcast(func, "na and nb", a, b)
    cc = checks.dot(a, b)
    checks.not_antiparallel(cc, "na and nb", func)
    scale = np.asarray(_midpoint_scale_kernel()(cc), dtype=float)
    return (a + b) * scale[..., None]


# ---------------------------------------- 3. minimum of |N(t)|, delta_d
@lru_cache(maxsize=None)
def linear_argmin_expr() -> sp.Expr:
    """Where ``|N(t)|`` is smallest: the root of ``d|N(t)|^2/dt``, ``t = 1/2``.

    The root is unique and a minimum for ``c < 1`` (second derivative
    ``4(1-c) > 0``); both facts are checked during the derivation.

    >>> linear_argmin_expr()
    1/2
    """
    f = norm2_linear_expr()
    roots = sp.solve(sp.diff(f, t), t)
    if len(roots) != 1:
        raise RuntimeError(f"expected one stationary point of |N(t)|^2, got {roots}")
    gap = sp.Symbol("gap", positive=True)  # c = 1 - gap, gap > 0
    if not sp.diff(f, t, 2).subs(c, 1 - gap).is_positive:
        raise RuntimeError("the stationary point of |N(t)|^2 is not a minimum")
    return roots[0]


@lru_cache(maxsize=None)
def min_norm_linear_expr() -> sp.Expr:
    """``min_t |N(t)| = |N(1/2)| = sqrt((1 + c)/2)`` in terms of ``c`` (seed 003).

    This is the function ``g(x) = sqrt(2(1+x))/2`` that seed 003 replaces by
    Chebyshev polynomials on ``x in [0, 1]``.

    >>> from chebnorm.symbolic.symbols import c
    >>> min_norm_linear_expr().subs(c, 1)
    1
    """
    return sp.sqrt(sp.factor(norm2_linear_expr().subs(t, linear_argmin_expr())))


@lru_cache(maxsize=None)
def _min_norm_of_phi() -> sp.Expr:
    """``min |N|`` with ``c = cos(phi)``, simplified to ``cos(phi/2)``."""
    theta = sp.Symbol("theta", real=True)  # theta = phi/2 in [0, pi/2]
    w = sp.Symbol("w", nonnegative=True)  # w = cos(theta) >= 0 there
    double_angle = sp.expand_trig(sp.cos(2 * theta))  # 2 cos(theta)^2 - 1
    expr = min_norm_linear_expr().subs(c, double_angle).subs(sp.cos(theta), w)
    expr = sp.simplify(expr)
    if theta in expr.free_symbols:
        raise RuntimeError(f"could not write min |N| in cos(phi/2): {expr}")
    return expr.subs(w, sp.cos(phi / 2))


def _relative_error(power: sp.Expr) -> sp.Expr:
    """``1 - (x s)^p / x^p``: relative error of a term ``x^p`` (``x`` the cosine
    with the unit normal) when the normal has length ``s`` instead of 1."""
    s, x = sp.symbols("s x", positive=True)
    err = sp.expand_power_base(1 - (s * x) ** power / x ** power)
    return err.subs(s, _min_norm_of_phi())


@lru_cache(maxsize=None)
def delta_d_expr() -> sp.Expr:
    """Largest relative diffuse error without normalization, ``1 - cos(phi/2)``.

    Seed 003: ``delta_d(phi) = 1 - sqrt((1 + cos phi)/2)``.

    >>> delta_d_expr()
    1 - cos(phi/2)
    """
    return _relative_error(sp.Integer(1))


@lru_cache(maxsize=None)
def _delta_d_kernel():
    return sp.lambdify((phi,), delta_d_expr(), modules="numpy")


def _check_phi(x, func: str) -> np.ndarray:
    return checks.in_range(x, "phi", func, 0.0, np.pi, "[0, pi] (radians)")


def delta_d(phi):
    """``delta_d(phi) = 1 - cos(phi/2)`` (seed 003, claim C1), ``phi`` in radians.

    Parameters
    ----------
    phi : array_like
        The angle between two unit normals, in ``[0, pi]`` radians.

    Returns
    -------
    numpy.ndarray or numpy.float64
        The largest relative diffuse error of not normalizing (a scalar for
        scalar input).

    Raises
    ------
    ValueError
        For ``phi`` outside ``[0, pi]`` or not finite.

    Notes
    -----
    Possible issues: evaluated as written, so for tiny ``phi`` the relative
    error is about ``8 eps / phi^2`` (the absolute error stays ``~eps``).

    Examples
    --------
    >>> print(f"{delta_d(0.2):.7f}")
    0.0049958
    """
    x = _check_phi(phi, "delta_d")
    return checks.scalar_or_array(np.asarray(_delta_d_kernel()(x), dtype=float))


# ----------------------------------------------------------- 4. delta_s
@lru_cache(maxsize=None)
def delta_s_expr() -> sp.Expr:
    """Largest relative specular error without normalization,
    ``1 - cos(phi/2)^n`` (seed 003: ``1 - ((1 + cos phi)/2)^(n/2)``).

    >>> delta_s_expr()
    1 - cos(phi/2)**n
    """
    return _relative_error(n)


@lru_cache(maxsize=None)
def _delta_s_kernel():
    return sp.lambdify((phi, n), delta_s_expr(), modules="numpy")


def delta_s(phi, n):
    """``delta_s(phi, n) = 1 - cos(phi/2)^n`` (seed 003, Fig. 5, claim C2).

    Parameters
    ----------
    phi : array_like
        The angle between two unit normals, in ``[0, pi]`` radians.
    n : array_like
        The specular exponent, ``n >= 0``; broadcasts against ``phi``.

    Returns
    -------
    numpy.ndarray or numpy.float64
        The largest relative specular error of not normalizing.

    Raises
    ------
    ValueError
        For arguments outside their ranges or not finite.

    Examples
    --------
    >>> print(f"{delta_s(0.2, 1.0):.7f}")
    0.0049958
    >>> print(f"{delta_s(0.2, 64):.4f}")
    0.2742
    """
    func = "delta_s"
    x = _check_phi(phi, func)
    m = checks.in_range(n, "n", func, 0.0, np.inf, "[0, inf)")
    x, m = checks.broadcast(func, "phi and n", x, m)
    out = np.asarray(_delta_s_kernel()(x, m), dtype=float)
    return checks.scalar_or_array(out)


# ---------------------------------------------------------------- 5. eta
@lru_cache(maxsize=None)
def edge_bound_expr() -> sp.Expr:
    """Edge bound ``1 - |N(1/2)| = 1 - sqrt(2(1 + c))/2`` for edge cosine ``c``.

    >>> from chebnorm.symbolic.symbols import c
    >>> edge_bound_expr().subs(c, -1)
    1
    """
    return 1 - min_norm_linear_expr()


@lru_cache(maxsize=None)
def eta_expr() -> sp.Expr:
    """Normalization criterion of a triangle, the sum of its three edge bounds:
    ``eta = 3 - (1/2)[sqrt(2(1+c_ab)) + sqrt(2(1+c_bc)) + sqrt(2(1+c_ac))]``
    (seed 003).

    >>> from chebnorm.symbolic.symbols import c_ab, c_bc, c_ac
    >>> eta_expr().subs({c_ab: 1, c_bc: 1, c_ac: 1})
    0
    """
    bound = edge_bound_expr()
    return sum((bound.subs(c, cij) for cij in (c_ab, c_bc, c_ac)), sp.Integer(0))


@lru_cache(maxsize=None)
def _eta_kernel():
    # powsimp joins sqrt(2)*sqrt(1 + c) into sqrt(2c + 2) (valid: 1 + c >= 0
    # after clipping), which is exactly 2 at c = 1, so that each edge bound,
    # and eta, is never negative in floating point either.
    expr = sp.powsimp(eta_expr(), force=True)
    return sp.lambdify((c_ab, c_bc, c_ac), expr, modules="numpy")


def eta(na, nb, nc):
    """Normalization criterion ``eta`` of triangles with unit vertex normals
    ``na, nb, nc`` (arrays of shape ``(..., 3)``, broadcast) (seed 003).

    ``eta >= 0``; triangles with ``eta`` under a threshold skip normalization.

    .. math::

        \\eta = 3 - \\tfrac12\\left[\\sqrt{2(1 + N_A\\cdot N_B)} + \\sqrt{2(1 + N_B\\cdot N_C)}
          + \\sqrt{2(1 + N_A\\cdot N_C)}\\right]

    Parameters
    ----------
    na, nb, nc : array_like
        Unit vertex normals, shape ``(..., 3)``; they broadcast.

    Returns
    -------
    numpy.ndarray or numpy.float64
        ``eta`` per triangle (a scalar for single vectors).

    Raises
    ------
    ValueError
        For zero, non-finite or non-unit normals.

    Examples
    --------
    >>> e = eta([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0])
    >>> print(f"{e:.3f}")
    0.000
    """
    func = "eta"
    va = checks.unit_vectors(na, "na", func)
    vb = checks.unit_vectors(nb, "nb", func)
    vc = checks.unit_vectors(nc, "nc", func)
    va, vb, vc = checks.broadcast(func, "na, nb and nc", va, vb, vc)
    cos = [np.clip(checks.dot(x, y), -1.0, 1.0) for x, y in ((va, vb), (vb, vc), (va, vc))]
    return checks.scalar_or_array(np.asarray(_eta_kernel()(*cos), dtype=float))


# ----------------------------------------------- 7. quadratic interpolation
@dataclass(frozen=True)
class QuadraticCoefficients:
    """``N(t) = G t^2 + P t + Q`` (seed 000, quadratic span interpolation).

    Holds sympy expressions (from :func:`quadratic_coefficients_expr`) or
    ``(..., 3)`` arrays (from :func:`quadratic_coefficients`).

    Attributes
    ----------
    G : sympy.Expr or numpy.ndarray
        The coefficient of ``t^2``, ``2 N_l - 4 N_c + 2 N_r``.
    P : sympy.Expr or numpy.ndarray
        The coefficient of ``t``, ``-3 N_l + 4 N_c - N_r``.
    Q : sympy.Expr or numpy.ndarray
        The constant, ``N_l``.

    Examples
    --------
    The quadratic passes through ``N_l`` (t = 0), the normalized midpoint
    (t = 1/2) and ``N_r`` (t = 1):

    >>> import numpy as np
    >>> q = quadratic_coefficients(np.array([1.0, 0, 0]), np.array([0, 1.0, 0]))
    >>> N = lambda t: q.G * t**2 + q.P * t + q.Q
    >>> bool(np.allclose(N(0), [1, 0, 0]) and np.allclose(N(1), [0, 1, 0]))
    True
    >>> bool(np.allclose(N(0.5), [2 ** -0.5, 2 ** -0.5, 0]))
    True
    """

    G: Any
    P: Any
    Q: Any

    def evaluate(self, t):
        """``G t^2 + P t + Q``.  For array coefficients of shape ``(..., 3)``,
        ``t`` broadcasts against the leading shape ``...`` and the result has
        a trailing axis of length 3.

        >>> q = QuadraticCoefficients(G=np.zeros(3), P=np.ones(3), Q=np.zeros(3))
        >>> print(q.evaluate(0.5))
        [0.5 0.5 0.5]
        """
        if isinstance(self.G, sp.Basic):
            return self.G * t**2 + self.P * t + self.Q
        tt = np.asarray(t, dtype=float)[..., None]
        return self.G * tt**2 + self.P * tt + self.Q


@lru_cache(maxsize=None)
def quadratic_coefficients_expr() -> QuadraticCoefficients:
    """``G, P, Q`` of the quadratic through ``N_l`` (t=0), ``N_c`` (t=1/2),
    ``N_r`` (t=1), per component (seed 000): solved from the three
    interpolation conditions.  Gives ``Q = N_l``, ``G = 2N_l + 2N_r - 4N_c``,
    ``P = 4N_c - 3N_l - N_r``.

    >>> quadratic_coefficients_expr().Q
    N_l
    """
    g, p, q = sp.symbols("G P Q")
    quad = g * t**2 + p * t + q
    conditions = [
        quad.subs(t, 0) - N_l,
        quad.subs(t, sp.Rational(1, 2)) - N_c,
        quad.subs(t, 1) - N_r,
    ]
    solutions = sp.linsolve(conditions, [g, p, q])
    if len(solutions) != 1:
        raise RuntimeError(f"expected a unique quadratic, got {solutions}")
    (gg, pp, qq), = solutions
    return QuadraticCoefficients(G=sp.expand(gg), P=sp.expand(pp), Q=sp.expand(qq))


@lru_cache(maxsize=None)
def _quadratic_kernels():
    expr = quadratic_coefficients_expr()
    return tuple(
        sp.lambdify((N_l, N_c, N_r), e, modules="numpy")
        for e in (expr.G, expr.P, expr.Q)
    )


def quadratic_coefficients(nl, nr, nc=None) -> QuadraticCoefficients:
    """Coefficients of the quadratic span interpolant (seed 000, method 5).

    ``nl``, ``nr``: unit end normals of the span, ``(..., 3)``.  ``nc``: the
    normal at ``t = 1/2``; by default the exact normalized midpoint
    :func:`midpoint_normal` (``N_l.N_r`` must then not be ``-1``).  A given
    ``nc`` is only checked for shape and finiteness, so an approximate
    midpoint (e.g. from a Chebyshev fit of ``1/sqrt(2(1+x))``) can be used.

    Parameters
    ----------
    nl, nr : array_like
        Unit end normals of the span, shape ``(..., 3)``.
    nc : array_like, optional
        The normal at ``t = 1/2``; the exact normalized midpoint when omitted.

    Returns
    -------
    QuadraticCoefficients
        ``G``, ``P``, ``Q`` as arrays of shape ``(..., 3)``.

    Raises
    ------
    ValueError
        For invalid end normals (as :func:`midpoint_normal`), or an ``nc`` of
        the wrong shape or not finite.

    Examples
    --------
    >>> q = quadratic_coefficients([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    >>> print(np.round(q.evaluate(0.5), 6))
    [0.707107 0.707107 0.      ]
    """
    func = "quadratic_coefficients"
    left = checks.unit_vectors(nl, "nl", func)
    right = checks.unit_vectors(nr, "nr", func)
    left, right = checks.broadcast(func, "nl and nr", left, right)
    if nc is None:
        checks.not_antiparallel(checks.dot(left, right), "nl and nr", func)
        centre = midpoint_normal(left, right)
    else:
        centre = checks.vectors(nc, "nc", func)
    left, centre, right = checks.broadcast(func, "nl, nc and nr", left, centre, right)
    shape = left.shape
    gg, pp, qq = (
        np.broadcast_to(np.asarray(k(left, centre, right), dtype=float), shape).copy()
        for k in _quadratic_kernels()
    )
    return QuadraticCoefficients(G=gg, P=pp, Q=qq)
