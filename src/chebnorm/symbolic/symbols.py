"""The sympy symbols in which every closed form of :mod:`chebnorm.symbolic` is
written.  Build expressions to substitute into with these objects (a fresh
``sympy.Symbol("c")`` without the same assumptions is a different symbol).

Interpolation and normalization (seeds 003, 000)
    ``t``      -- position along an edge or span, ``N(t) = (1-t) N_A + t N_B``.
    ``c``      -- ``N_A.N_B``, the cosine of the angle between two unit normals.
    ``phi``    -- that angle in radians, ``c = cos(phi)``, ``phi in [0, pi]``.
    ``n``      -- the specular (shininess) exponent, ``n >= 0``.
    ``c_ab, c_bc, c_ac`` -- the three edge cosines of a triangle ABC.
    ``N_l, N_c, N_r`` -- one component of the left, centre (t = 1/2) and
    right normal of a span (quadratic interpolation, seed 000).

Highlight detection (seed 002)
    ``a = H.N_A``, ``b = H.N_B`` (and ``c`` as above).

Bump mapping (seed 001)
    ``F_u, F_v`` -- partial derivatives of the height map.
    ``k``        -- the common length of ``P_u`` and ``P_v`` on a square patch.
    ``Pu_norm = |P_u|``, ``PuxPv_norm = |P_u x P_v|``, ``Pu_dot_Pv = P_u.P_v``
    -- the invariants the tangent-space coefficients depend on.
"""

import sympy as sp

__all__ = [
    "t", "c", "phi", "n", "c_ab", "c_bc", "c_ac", "N_l", "N_c", "N_r",
    "a", "b", "F_u", "F_v", "k", "Pu_norm", "PuxPv_norm", "Pu_dot_Pv",
]

t, c, phi = sp.symbols("t c phi", real=True)
n = sp.Symbol("n", nonnegative=True)
c_ab, c_bc, c_ac = sp.symbols("c_ab c_bc c_ac", real=True)
N_l, N_c, N_r = sp.symbols("N_l N_c N_r", real=True)
a, b = sp.symbols("a b", real=True)
F_u, F_v = sp.symbols("F_u F_v", real=True)
k = sp.Symbol("k", positive=True)
Pu_norm, PuxPv_norm = sp.symbols("Pu_norm PuxPv_norm", positive=True)
Pu_dot_Pv = sp.Symbol("Pu_dot_Pv", real=True)
