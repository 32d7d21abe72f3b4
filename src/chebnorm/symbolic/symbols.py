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

# One assignment per symbol, so each has its own ``#:`` description in the API
# reference (sympy.Symbol's docstring is not theirs); the same names and assumptions
# as ``sp.symbols("t c phi", real=True)`` etc., hence the same symbols.

#: position along an edge or span, ``N(t) = (1-t) N_A + t N_B`` (real)
t = sp.Symbol("t", real=True)
#: ``N_A.N_B``, the cosine of the angle between two unit normals (real)
c = sp.Symbol("c", real=True)
#: the angle between two unit normals in radians, ``c = cos(phi)``, ``phi in [0, pi]`` (real)
phi = sp.Symbol("phi", real=True)
#: the specular (shininess) exponent (nonnegative)
n = sp.Symbol("n", nonnegative=True)
#: the cosine ``N_A.N_B`` of edge AB of a triangle ABC (real)
c_ab = sp.Symbol("c_ab", real=True)
#: the cosine ``N_B.N_C`` of edge BC of a triangle ABC (real)
c_bc = sp.Symbol("c_bc", real=True)
#: the cosine ``N_A.N_C`` of edge AC of a triangle ABC (real)
c_ac = sp.Symbol("c_ac", real=True)
#: one component of a span's left normal (``t = 0``; quadratic interpolation, seed 000) (real)
N_l = sp.Symbol("N_l", real=True)
#: the same component of the span's centre normal (``t = 1/2``) (real)
N_c = sp.Symbol("N_c", real=True)
#: the same component of the span's right normal (``t = 1``) (real)
N_r = sp.Symbol("N_r", real=True)
#: ``H.N_A``, the half vector against the first normal of an edge (seed 002) (real)
a = sp.Symbol("a", real=True)
#: ``H.N_B``, the half vector against the second normal of an edge (seed 002) (real)
b = sp.Symbol("b", real=True)
#: the height map's partial derivative along ``u`` (seed 001) (real)
F_u = sp.Symbol("F_u", real=True)
#: the height map's partial derivative along ``v`` (seed 001) (real)
F_v = sp.Symbol("F_v", real=True)
#: the common length of ``P_u`` and ``P_v`` on a square patch (seed 001) (positive)
k = sp.Symbol("k", positive=True)
#: ``|P_u|``, the length of the surface's ``u`` tangent (seed 001) (positive)
Pu_norm = sp.Symbol("Pu_norm", positive=True)
#: ``|P_u x P_v|``, the length of the unnormalized surface normal (seed 001) (positive)
PuxPv_norm = sp.Symbol("PuxPv_norm", positive=True)
#: ``P_u.P_v``, the dot product of the surface tangents (seed 001) (real)
Pu_dot_Pv = sp.Symbol("Pu_dot_Pv", real=True)
