"""Stage 1 of chebnorm: the closed forms of the four papers, *derived* by sympy.

Each closed form is derived from its definition by sympy the first time it is
asked for (then cached), and exposed twice: a ``*_expr()`` function returns
the sympy expression (in the symbols of :mod:`chebnorm.symbolic.symbols`), and
a numpy function evaluates it -- by ``sympy.lambdify`` of the derived scalar
expression, vector results being assembled from lambdified scalar factors.

Conventions: vectors are ``(..., 3)`` arrays, angles are radians; numpy
functions broadcast their arguments, return a numpy scalar for scalar input,
and validate their input once, raising ``ValueError`` with the value and the
accepted range.  Tolerances: :data:`UNIT_RTOL` (unit normals),
:data:`DOT_ATOL` (cosines, parallel and antiparallel pairs),
:data:`GRAM_ATOL` (consistency of ``H.N_A, H.N_B, N_A.N_B``).

Layer rule: this subpackage imports numpy and sympy only, nothing else from
chebnorm.

=====================================  =======================================  ========
sympy expression                       numpy function                           seed
=====================================  =======================================  ========
``norm2_linear_expr()``                ``norm2_linear_np(t, c)``                003
``midpoint_scale_expr()``              ``midpoint_normal(na, nb)``              003, 000
``delta_d_expr()``                     ``delta_d(phi)``                         003 (C1)
``delta_s_expr()``                     ``delta_s(phi, n)``                      003 (C2)
``eta_expr()``                         ``eta(na, nb, nc)``                      003
``edge_highlight_expr()``              ``edge_highlight(a, b, c)``,             002
                                       ``edge_highlight_unclipped(a, b, c)``
``quadratic_coefficients_expr()``      ``quadratic_coefficients(nl, nr,         000
                                       nc=None)``
``bump_coefficients_expr()``           ``bump_coefficients(P_u, P_v, F_u,       001
                                       F_v)``
``bump_coefficients_square_expr()``    ``bump_coefficients_square(F_u,          001 (C12)
                                       F_v, k)``
=====================================  =======================================  ========

Intermediate results of the derivations are exposed too:
``midpoint_norm2_expr``, ``linear_argmin_expr``, ``min_norm_linear_expr``
(the function ``g(x) = sqrt(2(1+x))/2`` that seed 003 approximates),
``edge_bound_expr``, ``edge_cosine_expr`` and ``bump_coefficients_seed_expr``.

>>> from chebnorm.symbolic import delta_d, delta_d_expr
>>> delta_d_expr()
1 - cos(phi/2)
>>> bool(delta_d(0.2) <= 0.005)
True
"""

from . import symbols
from .checks import DOT_ATOL, UNIT_RTOL
from .bump import (
    bump_coefficients,
    bump_coefficients_expr,
    bump_coefficients_seed_expr,
    bump_coefficients_square,
    bump_coefficients_square_expr,
)
from .highlight import (
    GRAM_ATOL,
    EdgeHighlight,
    edge_cosine_expr,
    edge_highlight,
    edge_highlight_expr,
    edge_highlight_unclipped,
)
from .interpolation import (
    QuadraticCoefficients,
    delta_d,
    delta_d_expr,
    delta_s,
    delta_s_expr,
    edge_bound_expr,
    eta,
    eta_expr,
    linear_argmin_expr,
    midpoint_norm2_expr,
    midpoint_normal,
    midpoint_scale_expr,
    min_norm_linear_expr,
    norm2_linear_expr,
    norm2_linear_np,
    quadratic_coefficients,
    quadratic_coefficients_expr,
)

__all__ = [
    # symbols and tolerances
    "symbols", "UNIT_RTOL", "DOT_ATOL", "GRAM_ATOL",
    # result types
    "EdgeHighlight", "QuadraticCoefficients",
    # seed 003 / 000: interpolation and the error of skipping normalization
    "norm2_linear_expr", "norm2_linear_np",
    "midpoint_norm2_expr", "midpoint_scale_expr", "midpoint_normal",
    "linear_argmin_expr", "min_norm_linear_expr",
    "delta_d_expr", "delta_d", "delta_s_expr", "delta_s",
    "edge_bound_expr", "eta_expr", "eta",
    "quadratic_coefficients_expr", "quadratic_coefficients",
    # seed 002: highlight on an edge
    "edge_cosine_expr", "edge_highlight_expr", "edge_highlight",
    "edge_highlight_unclipped",
    # seed 001: bump mapping
    "bump_coefficients_expr", "bump_coefficients_seed_expr",
    "bump_coefficients_square_expr", "bump_coefficients",
    "bump_coefficients_square",
]
