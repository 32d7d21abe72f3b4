"""Tangent-space coefficients of Blinn's perturbed normal (seed 001, bump
mapping on Phong hardware).

Definitions (Blinn; seed 001):  ``N = P_u x P_v``, perturbed normal
``N' = N + D`` with ``D = [F_u (N x P_v) + F_v (P_u x N)] / |N|``; tangent frame
``T = P_u/|P_u|``, ``N^ = N/|N|``, ``B = N^ x T`` (right-handed:
``T x B = N^``); coefficients ``N'_ts = [a, b, c] = [N'.T, N'.B, N'.N^]``.

Derivation (:func:`bump_coefficients_expr`): ``P_u, P_v`` are generic symbolic
3-vectors; ``|N|`` and ``|P_u|`` are kept as the positive symbols
``PuxPv_norm`` and ``Pu_norm``, and each coefficient is rewritten modulo
``PuxPv_norm^2 = N.N``, ``Pu_norm^2 = P_u.P_u``, ``Pu_dot_Pv = P_u.P_v``
(exact Groebner normal forms, see :mod:`chebnorm.symbolic.algebra`).  This
gives, in terms of the three invariants,

    ``a = -F_u |P_u x P_v| / |P_u|``,
    ``b = F_u (P_u.P_v)/|P_u| - F_v |P_u|``,
    ``c = |P_u x P_v|``.

The seed's forms ``a = -F_u (B.P_v)``, ``b = F_u (T.P_v) - F_v |P_u|``,
``c = |P_u x P_v|`` reduce to the same expressions
(:func:`bump_coefficients_seed_expr`): with these definitions the signs of
docs/papers.md are right.

Square patch (:func:`bump_coefficients_square_expr`): with ``P_u = k e_1``,
``P_v = k e_2`` the definitions give ``[a, b, c] = [-F_u k, -F_v k, k^2]``;
SPEC's ``[-F_u/k, -F_v/k, 1]`` is this vector divided by ``c = k^2``.  Only
the direction matters (the texel is renormalized), so both describe the same
normal, but the SPEC values are ``[a, b, c]/c``, not ``a, b, c`` themselves.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy as sp

from . import checks
from .algebra import reduce_modulo, vector
from .symbols import F_u, F_v, Pu_dot_Pv, Pu_norm, PuxPv_norm, k

# an implementation module of chebnorm.symbolic: the API is what chebnorm.symbolic exports
__all__: list[str] = []


def _frame():
    """Generic ``P_u, P_v`` with the definitions of seed 001 built on them."""
    pu, pv = vector("P_u"), vector("P_v")
    normal = pu.cross(pv)
    perturbation = (F_u * normal.cross(pv) + F_v * pu.cross(normal)) / PuxPv_norm
    perturbed = normal + perturbation
    tangent = pu / Pu_norm
    unit_normal = normal / PuxPv_norm
    binormal = unit_normal.cross(tangent)
    relations = [
        PuxPv_norm**2 - normal.dot(normal),
        Pu_norm**2 - pu.dot(pu),
        Pu_dot_Pv - pu.dot(pv),
    ]
    return pu, pv, perturbed, tangent, binormal, unit_normal, relations


def _reduce(exprs, pu, pv, relations) -> sp.Matrix:
    return sp.Matrix([reduce_modulo(e, relations, [*pu, *pv]) for e in exprs])


@lru_cache(maxsize=None)
def bump_coefficients_expr() -> sp.Matrix:
    """``[N'.T, N'.B, N'.N^]`` derived from Blinn's definitions (seed 001),
    as a column in ``F_u, F_v, Pu_norm, PuxPv_norm, Pu_dot_Pv``.

    >>> bump_coefficients_expr().T
    Matrix([[-F_u*PuxPv_norm/Pu_norm, (F_u*Pu_dot_Pv - F_v*Pu_norm**2)/Pu_norm, PuxPv_norm]])
    """
    pu, pv, perturbed, tangent, binormal, unit_normal, relations = _frame()
    exprs = [perturbed.dot(tangent), perturbed.dot(binormal), perturbed.dot(unit_normal)]
    return _reduce(exprs, pu, pv, relations)


@lru_cache(maxsize=None)
def bump_coefficients_seed_expr() -> sp.Matrix:
    """The seed's (and SPEC's) forms ``[-F_u (B.P_v), F_u (T.P_v) - F_v |P_u|,
    |P_u x P_v|]`` reduced the same way; equal to
    :func:`bump_coefficients_expr`.

    >>> import sympy as sp
    >>> sp.simplify(bump_coefficients_seed_expr() - bump_coefficients_expr())
    Matrix([
    [0],
    [0],
    [0]])
    """
    pu, pv, _, tangent, binormal, _, relations = _frame()
    exprs = [
        -F_u * binormal.dot(pv),
        F_u * tangent.dot(pv) - F_v * Pu_norm,
        PuxPv_norm,
    ]
    return _reduce(exprs, pu, pv, relations)


@lru_cache(maxsize=None)
def bump_coefficients_square_expr() -> sp.Matrix:
    """Square patch ``P_u = k e_1``, ``P_v = k e_2``: ``[a, b, c]/c =
    [-F_u/k, -F_v/k, 1]`` (seed 001, claim C12).  Before the division by
    ``c = k^2`` the coefficients are ``[-F_u k, -F_v k, k^2]``.

    >>> bump_coefficients_square_expr().T
    Matrix([[-F_u/k, -F_v/k, 1]])
    """
    pu = sp.Matrix([k, 0, 0])
    pv = sp.Matrix([0, k, 0])
    cross = pu.cross(pv)
    invariants = {
        Pu_norm: sp.sqrt(pu.dot(pu)),
        PuxPv_norm: sp.sqrt(cross.dot(cross)),
        Pu_dot_Pv: pu.dot(pv),
    }
    coefficients = bump_coefficients_expr().subs(invariants)
    return sp.simplify(coefficients / coefficients[2])


@lru_cache(maxsize=None)
def _kernel():
    args = (F_u, F_v, Pu_norm, PuxPv_norm, Pu_dot_Pv)
    return sp.lambdify(args, list(bump_coefficients_expr()), modules="numpy")


@lru_cache(maxsize=None)
def _square_kernel():
    return sp.lambdify((F_u, F_v, k), list(bump_coefficients_square_expr()), modules="numpy")


def _stack(values, shape) -> np.ndarray:
    return np.stack([np.broadcast_to(np.asarray(v, dtype=float), shape) for v in values], axis=-1)


def bump_coefficients(P_u, P_v, F_u, F_v) -> np.ndarray:
    """Tangent-space perturbed normal ``[a, b, c] = [N'.T, N'.B, N'.N^]``
    (seed 001), not normalized.

    Parameters
    ----------
    P_u, P_v : array_like
        The surface's partial derivatives, shape ``(..., 3)``.
    F_u, F_v : array_like
        The height map's partial derivatives, broadcasting against the
        leading shape of ``P_u``.

    Returns
    -------
    numpy.ndarray
        ``[a, b, c]`` of shape ``(..., 3)``.

    Raises
    ------
    ValueError
        For non-finite input, zero vectors and parallel tangents
        (``|P_u x P_v| <= eps |P_u| |P_v|``, no surface normal).

    Examples
    --------
    >>> bump_coefficients([2.0, 0.0, 0.0], [0.0, 2.0, 0.0], 0.5, 0.25)
    array([-1. , -0.5,  4. ])
    """
    func = "bump_coefficients"
    pu, pu_len = checks.nonzero_vectors(P_u, "P_u", func)
    pv, pv_len = checks.nonzero_vectors(P_v, "P_v", func)
    pu, pv = checks.broadcast(func, "P_u and P_v", pu, pv)
    fu = checks.real_array(F_u, "F_u", func)
    fv = checks.real_array(F_v, "F_v", func)
    cross = np.cross(pu, pv)
    cross_len = np.linalg.norm(cross, axis=-1)
    bad = cross_len <= np.finfo(float).eps * pu_len * pv_len
    if bad.any():
        raise ValueError(
            f"{func}: P_u and P_v are parallel{checks.where_text(bad)}: "
            f"|P_u x P_v| = {cross_len[bad].flat[0]!r} must exceed "
            f"eps |P_u| |P_v| (there is no surface normal)"
        )
    shape = checks.broadcast(
        func, "F_u, F_v and the leading shape of P_u, P_v", fu, fv, cross_len
    )[0].shape
    values = _kernel()(fu, fv, np.linalg.norm(pu, axis=-1), cross_len, checks.dot(pu, pv))
    return _stack(values, shape)


def bump_coefficients_square(F_u, F_v, k) -> np.ndarray:
    """Square-patch coefficients ``[-F_u/k, -F_v/k, 1]`` (seed 001, claim C12):
    ``bump_coefficients(k e_1, k e_2, F_u, F_v)`` divided by its ``c = k^2``.

    Parameters
    ----------
    F_u, F_v : array_like
        The height map's partial derivatives.
    k : array_like
        The common length of ``P_u`` and ``P_v``, ``k > 0``; all three broadcast.

    Returns
    -------
    numpy.ndarray
        ``[-F_u/k, -F_v/k, 1]`` of shape ``(..., 3)``.

    Raises
    ------
    ValueError
        For non-finite input or ``k <= 0``.

    Examples
    --------
    >>> bump_coefficients_square(0.5, 0.25, 2.0)
    array([-0.25 , -0.125,  1.   ])
    """
    func = "bump_coefficients_square"
    fu = checks.real_array(F_u, "F_u", func)
    fv = checks.real_array(F_v, "F_v", func)
    kk = checks.real_array(k, "k", func)
    bad = kk <= 0
    if bad.any():
        raise ValueError(
            f"{func}: k must lie in (0, inf); got {kk[bad].flat[0]!r}{checks.where_text(bad)}"
        )
    shape = checks.broadcast(func, "F_u, F_v and k", fu, fv, kk)[0].shape
    return _stack(_square_kernel()(fu, fv, kk), shape)
