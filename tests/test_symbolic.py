"""Tests of chebnorm.symbolic: every derived closed form against an independent
numeric computation on seeded random data, the sympy expressions against the
formulas of docs/papers.md, and every ValueError of the numpy boundary.

Tolerances are derived, not tuned: ``EPS`` times the scale of the quantities
times the number of roundings on the longest path of either computation, or
the resolution bound of a grid search (derived in the test that uses it).
"""

import ast
import doctest
import sys
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from hypothesis import example, given, settings
from hypothesis import strategies as st

import chebnorm.symbolic as S
from chebnorm.symbolic import bump, highlight, interpolation, symbols
from chebnorm.symbolic.symbols import (
    F_u, F_v, N_c, N_l, N_r, a, b, c, c_ab, c_ac, c_bc, k, n, phi, t,
)

EPS = np.finfo(float).eps
# Roundings on the longest path of the short float computations compared
# below (an interpolation, a dot product, a square root, a division: each a
# handful of operations on O(1) values); both paths count.
ROUNDINGS = 16


@pytest.fixture
def rng():
    return np.random.default_rng(0)


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_unit(rng, size):
    return unit(rng.normal(size=(size, 3)))


def pairs_at_angles(rng, angles):
    """Unit normals ``na, nb`` with ``angle(na, nb) = angles`` (shape (m, 3))."""
    angles = np.asarray(angles, dtype=float)
    na = random_unit(rng, angles.size)
    w = rng.normal(size=na.shape)
    w = unit(w - np.einsum("ij,ij->i", w, na)[:, None] * na)
    nb = np.cos(angles)[:, None] * na + np.sin(angles)[:, None] * w
    return na, nb


def assert_below(x, bound):
    """``x < bound`` elementwise, after broadcasting (numpy 2 requires equal shapes)."""
    x, bound = np.broadcast_arrays(x, bound)
    np.testing.assert_array_less(x, bound)


def sqrt_error(x, dx):
    """Bound on ``|sqrt(x + e) - sqrt(x)|`` for ``|e| <= dx``."""
    x = np.asarray(x, dtype=float)
    with np.errstate(divide="ignore"):
        return np.minimum(np.sqrt(dx), dx / (2 * np.sqrt(x)))


# ==================================================================== sympy
class TestDerivations:
    """The derived expressions equal the formulas stated in docs/papers.md."""

    def test_norm2_linear(self):
        assert sp.expand(S.norm2_linear_expr() - (1 - 2 * t * (1 - t) * (1 - c))) == 0

    def test_midpoint(self):
        assert sp.expand(S.midpoint_norm2_expr() - 2 * (1 + c)) == 0
        assert sp.simplify(S.midpoint_scale_expr() - 1 / sp.sqrt(2 * (1 + c))) == 0

    def test_minimum_at_midpoint(self):
        assert S.linear_argmin_expr() == sp.Rational(1, 2)
        assert sp.simplify(S.min_norm_linear_expr() - sp.sqrt(2 * (1 + c)) / 2) == 0

    def test_delta_d(self):
        assert S.delta_d_expr() == 1 - sp.cos(phi / 2)

    def test_delta_s(self):
        assert S.delta_s_expr() == 1 - sp.cos(phi / 2) ** n
        assert S.delta_s_expr().subs(n, 1) == S.delta_d_expr()

    def test_delta_forms_of_spec(self):
        """SPEC writes them in cos(phi); they agree on [0, pi] (where
        cos(phi/2) >= 0), checked at DIGITS significant digits on a grid."""
        spec_d = 1 - sp.sqrt((1 + sp.cos(phi)) / 2)
        spec_s = 1 - ((1 + sp.cos(phi)) / 2) ** (n / 2)
        digits = 40
        for x in [sp.pi * sp.Rational(j, 12) for j in range(13)]:
            for ours, theirs, subs in (
                (S.delta_d_expr(), spec_d, {phi: x}),
                (S.delta_s_expr(), spec_s, {phi: x, n: sp.Rational(37, 3)}),
            ):
                difference = (ours - theirs).evalf(digits, subs=subs)
                assert abs(difference) <= sp.Float(10) ** (2 - digits)

    def test_eta(self):
        spec = 3 - sp.Rational(1, 2) * sum(
            sp.sqrt(2 * (1 + x)) for x in (c_ab, c_bc, c_ac)
        )
        assert sp.simplify(S.eta_expr() - spec) == 0
        assert sp.simplify(S.edge_bound_expr() - (1 - sp.sqrt(2 * (1 + c)) / 2)) == 0

    def test_edge_highlight(self):
        peak = S.edge_highlight_expr()
        assert sp.simplify(peak.t - (b - a * c) / ((a + b) * (1 - c))) == 0
        assert sp.simplify(peak.value**2 - (a**2 - 2 * a * b * c + b**2) / (1 - c**2)) == 0

    def test_edge_cosine(self):
        h = S.edge_cosine_expr()
        spec = ((1 - t) * a + t * b) / sp.sqrt(1 - 2 * t * (1 - t) * (1 - c))
        assert sp.simplify(h**2 - spec**2) == 0
        assert h.subs(t, 0) == a and h.subs(t, 1) == b

    def test_quadratic(self):
        q = S.quadratic_coefficients_expr()
        assert sp.expand(q.Q - N_l) == 0
        assert sp.expand(q.G - (2 * N_l + 2 * N_r - 4 * N_c)) == 0
        assert sp.expand(q.P - (4 * N_c - 3 * N_l - N_r)) == 0
        for node, value in ((0, N_l), (sp.Rational(1, 2), N_c), (1, N_r)):
            assert sp.expand(q.evaluate(node) - value) == 0

    def test_bump_definitions_match_seed(self):
        """Blinn's definitions and the seed's a, b, c agree (signs included)."""
        difference = S.bump_coefficients_expr() - S.bump_coefficients_seed_expr()
        assert sp.simplify(difference) == sp.zeros(3, 1)

    def test_bump_square(self):
        assert S.bump_coefficients_square_expr() == sp.Matrix([-F_u / k, -F_v / k, 1])
        unscaled = S.bump_coefficients_expr().subs(
            {symbols.Pu_norm: k, symbols.PuxPv_norm: k**2, symbols.Pu_dot_Pv: 0}
        )
        assert sp.simplify(unscaled - sp.Matrix([-F_u * k, -F_v * k, k**2])) == sp.zeros(3, 1)

    @pytest.mark.parametrize("name", [x for x in S.__all__ if x.endswith("_expr")])
    def test_derived_once(self, name):
        func = getattr(S, name)
        assert func() is func()


class TestPackage:
    MODULES = [S, interpolation, highlight, bump, symbols]

    @pytest.mark.parametrize("module", MODULES, ids=lambda m: m.__name__)
    def test_doctests(self, module):
        result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
        assert result.failed == 0

    def test_layer_rule(self):
        """Stage 1 imports numpy, sympy and the standard library only."""
        allowed = {"numpy", "sympy"} | set(sys.stdlib_module_names)
        root = Path(S.__file__).parent
        for path in root.rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.Import):
                    names = [alias.name for alias in node.names]
                elif isinstance(node, ast.ImportFrom) and node.level == 0:
                    names = [node.module]
                else:
                    continue
                for name in names:
                    assert name.split(".")[0] in allowed, f"{path.name} imports {name}"

    def test_facade(self):
        for name in S.__all__:
            assert hasattr(S, name), name


# ===================================================== seed 003: |N(t)|^2
class TestNorm2Linear:
    def test_against_direct_dot(self, rng):
        na, nb = random_unit(rng, 200), random_unit(rng, 200)
        tt = rng.uniform(-0.5, 1.5, size=200)
        nt = (1 - tt)[:, None] * na + tt[:, None] * nb
        direct = np.einsum("ij,ij->i", nt, nt)
        scale = (np.abs(1 - tt) + np.abs(tt)) ** 2  # bound on the terms summed
        got = S.norm2_linear_np(tt, np.einsum("ij,ij->i", na, nb))
        assert_below(np.abs(got - direct), ROUNDINGS * EPS * scale)

    def test_broadcast_and_scalar(self):
        assert S.norm2_linear_np(0.5, -1.0) == 0.0
        assert np.ndim(S.norm2_linear_np(0.25, 0.5)) == 0
        assert S.norm2_linear_np(np.linspace(0, 1, 5)[:, None], [0.0, 1.0]).shape == (5, 2)

    @pytest.mark.parametrize(
        "tt, cc, match",
        [(0.5, 1.5, r"c must lie in \[-1, 1\]"), (0.5, np.nan, "c must be finite"),
         (np.inf, 0.0, "t must be finite"), ([0, 1], [0, 1, 0.5], "must broadcast"),
         ("x", 0.0, "t must be real")],
    )
    def test_raises(self, tt, cc, match):
        with pytest.raises(ValueError, match=match):
            S.norm2_linear_np(tt, cc)


# ============================================= seed 003: midpoint normal
class TestMidpointNormal:
    def test_against_direct_normalization(self, rng):
        na, nb = pairs_at_angles(rng, rng.uniform(0, 0.9 * np.pi, size=200))
        cc = np.einsum("ij,ij->i", na, nb)
        direct = unit(na + nb)
        got = S.midpoint_normal(na, nb)
        # |na|^2, |nb|^2 are 1 within a few eps; the formula assumes exactly 1,
        # and the error of 2(1 + c) is amplified by 1/(1 + c).
        tol = ROUNDINGS * EPS * (1 + 1 / (1 + cc))
        assert_below(np.abs(got - direct).max(axis=-1), tol)
        assert_below(np.abs(np.linalg.norm(got, axis=-1) - 1), tol)
        bisect = np.einsum("ij,ij->i", got, na) - np.einsum("ij,ij->i", got, nb)
        assert_below(np.abs(bisect), tol)

    def test_broadcasts(self, rng):
        na = random_unit(rng, 5)
        assert S.midpoint_normal(na, [0.0, 0.0, 1.0]).shape == (5, 3)

    @pytest.mark.parametrize(
        "na, nb, match",
        [([0, 0, 0], [0, 0, 1], "zero vector"), ([np.nan, 0, 1], [0, 0, 1], "finite"),
         ([0, 0, 1 + 1e-5], [0, 0, 1], "unit vectors"), ([0, 0, 1], [0, 0, -1], "antiparallel"),
         ([0, 1], [1, 0], r"shape \(\.\.\., 3\)"),
         (np.eye(3)[:2], np.eye(3), "must broadcast")],
    )
    def test_raises(self, na, nb, match):
        with pytest.raises(ValueError, match=match):
            S.midpoint_normal(na, nb)

    def test_unit_tolerance_is_the_stated_one(self):
        inside = [0.0, 0.0, 1 + 0.5 * S.UNIT_RTOL]
        outside = [0.0, 0.0, 1 + 2 * S.UNIT_RTOL]
        S.midpoint_normal(inside, [1.0, 0.0, 0.0])
        with pytest.raises(ValueError, match="UNIT_RTOL"):
            S.midpoint_normal(outside, [1.0, 0.0, 0.0])


# =================================================== seed 003: delta_d, delta_s
T_GRID = np.linspace(0.0, 1.0, 1000)  # 1000 points: t = 1/2 is not a node
DT = T_GRID[1] - T_GRID[0]


def grid_min_norm(na, nb):
    nt = (1 - T_GRID)[:, None, None] * na + T_GRID[:, None, None] * nb
    return np.linalg.norm(nt, axis=-1).min(axis=0)


def grid_gap_norm2(cc):
    """|N(t)|^2 = m + 2(1-c)(t - 1/2)^2, so the nearest node to t = 1/2
    (within DT/2) misses the minimum of |N|^2 by at most (1-c) DT^2 / 2."""
    return (1 - cc) * DT**2 / 2


class TestDeltaD:
    def test_claim_c1(self):
        """C1: delta_d(0.2 rad) <= 0.5 %; SPEC gives it as 0.4996 %, i.e. to
        half a unit in its 4th digit."""
        value = S.delta_d(0.2)
        assert value <= 0.005
        assert abs(value - 0.004996) <= 0.5e-6

    def test_against_grid_minimum(self, rng):
        angles = np.linspace(0.0, np.pi, 25)
        na, nb = pairs_at_angles(rng, angles)
        cc = np.cos(angles)
        grid = 1 - grid_min_norm(na, nb)  # the grid minimum is >= the true one
        got = S.delta_d(angles)
        tol = ROUNDINGS * EPS
        assert_below(grid - got, tol)
        bound = sqrt_error(np.cos(angles / 2) ** 2, grid_gap_norm2(cc))
        assert_below(got - grid, bound + tol)

    def test_spec_form_and_monotone(self):
        angles = np.linspace(0.0, np.pi, 101)
        spec = 1 - np.sqrt((1 + np.cos(angles)) / 2)
        # the spec form cancels in 1 + cos(phi) near phi = pi: sqrt amplifies
        tol = ROUNDINGS * EPS + sqrt_error((1 + np.cos(angles)) / 2, ROUNDINGS * EPS)
        assert_below(np.abs(S.delta_d(angles) - spec), tol)
        assert np.all(np.diff(S.delta_d(angles)) > 0)
        assert S.delta_d(0.0) == 0.0 and S.delta_d(np.pi) == pytest.approx(1.0, abs=EPS)

    @pytest.mark.parametrize("x", [-0.1, 3.2, np.nan, [0.1, 4.0]])
    def test_raises(self, x):
        with pytest.raises(ValueError, match="phi"):
            S.delta_d(x)


class TestDeltaS:
    def test_against_grid_minimum(self, rng):
        angles = np.linspace(0.0, np.pi, 13)
        exponents = np.array([0.0, 1.0, 8.0, 64.0])
        na, nb = pairs_at_angles(rng, angles)
        cc = np.cos(angles)
        # |N|^n is increasing in |N|, so the grid minimum of |N| gives the
        # grid minimum of |N|^n; |x^n - y^n| <= n |x - y| for x, y in [0, 1].
        min_norm = grid_min_norm(na, nb)
        grid = 1 - min_norm[:, None] ** exponents
        got = S.delta_s(angles[:, None], exponents)
        tol = ROUNDINGS * EPS * np.maximum(exponents, 1)
        assert_below(grid - got, tol)
        bound = exponents * sqrt_error(np.cos(angles / 2) ** 2, grid_gap_norm2(cc))[:, None]
        assert_below(got - grid, bound + tol)

    def test_spec_form_and_special_cases(self):
        angles = np.linspace(0.0, np.pi, 41)[:, None]
        exponents = np.array([1.0, 2.0, 10.0, 128.0])
        spec = 1 - ((1 + np.cos(angles)) / 2) ** (exponents / 2)
        tol = ROUNDINGS * EPS * exponents
        assert_below(np.abs(S.delta_s(angles, exponents) - spec), tol)
        np.testing.assert_array_equal(S.delta_s(angles, 0.0), 0.0)
        np.testing.assert_allclose(S.delta_s(angles, 1.0), S.delta_d(angles), atol=EPS)
        # it grows with n and with phi (claim C2's premise), until it saturates
        # at 1 in floating point
        values = S.delta_s(angles[1:], exponents)
        assert np.all(np.diff(values, axis=0) >= 0) and np.all(np.diff(values, axis=1) >= 0)
        assert np.all(np.diff(values[:, 0]) > 0) and np.all(np.diff(values[0]) > 0)

    @pytest.mark.parametrize(
        "x, m, match",
        [(0.1, -1.0, r"n must lie in \[0, inf\)"), (-0.1, 1.0, "phi"),
         (3.5, 1.0, "phi"), (0.1, np.nan, "n must be finite"),
         ([0.1, 0.2], [1, 2, 3], "must broadcast")],
    )
    def test_raises(self, x, m, match):
        with pytest.raises(ValueError, match=match):
            S.delta_s(x, m)


# ============================================================ seed 003: eta
unit_vector = (
    st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3)
    .filter(lambda v: np.linalg.norm(v) > 0.1)
    .map(unit)
)
barycentric = (
    st.tuples(*[st.floats(0, 1, allow_nan=False)] * 3)
    .filter(lambda w: sum(w) > 0.1)
    .map(lambda w: np.asarray(w) / sum(w))
)
_third = np.array([1.0, 1.0, 1.0]) / 3
_coplanar = [unit([np.cos(x), np.sin(x), 0.0]) for x in (0.0, 2 * np.pi / 3, 4 * np.pi / 3)]


class TestEta:
    def test_against_direct_sum(self, rng):
        na, nb, nc = (random_unit(rng, 300) for _ in range(3))
        edges = ((na, nb), (nb, nc), (na, nc))
        direct = sum(1 - np.linalg.norm((x + y) / 2, axis=-1) for x, y in edges)
        # |(x + y)/2|^2 and (1 + c)/2 differ by a few eps; the square root
        # amplifies that by 1/(2 |N(1/2)|) (bounded by sqrt_error).
        tol = sum(
            sqrt_error((1 + np.einsum("ij,ij->i", x, y)) / 2, ROUNDINGS * EPS)
            for x, y in edges
        )
        assert_below(np.abs(S.eta(na, nb, nc) - direct), tol + ROUNDINGS * EPS)

    def test_flat_triangle_is_zero(self):
        z = [0.0, 0.0, 1.0]
        assert S.eta(z, z, z) == 0.0

    @given(na=unit_vector, nb=unit_vector, nc=unit_vector, w=barycentric)
    @example(na=_coplanar[0], nb=_coplanar[1], nc=_coplanar[2], w=_third)
    @example(na=_coplanar[0], nb=_coplanar[0], nc=_coplanar[0], w=_third)
    @example(na=_coplanar[0], nb=-_coplanar[0], nc=_coplanar[1], w=np.array([0.5, 0.5, 0.0]))
    @settings(max_examples=300, deadline=None)
    def test_interior_deficit_bounded_by_edge_midpoints(self, na, nb, nc, w):
        """SPEC note: 1 - |N|^2 = sum_{i<j} 2 w_i w_j (1 - c_ij) <= sum of the
        edge-midpoint deficits (1 - c_ij)/2; and 0 <= eta <= that sum too
        (since sqrt(x) >= x on [0, 1])."""
        normals = np.array([na, nb, nc])
        pairs = ((0, 1), (1, 2), (0, 2))
        cos = {p: float(normals[p[0]] @ normals[p[1]]) for p in pairs}
        interior = w @ normals
        deficit = 1 - interior @ interior
        identity = sum(2 * w[i] * w[j] * (1 - cos[i, j]) for i, j in pairs)
        tol = ROUNDINGS * EPS
        assert abs(deficit - identity) <= tol
        midpoint_sum = sum((1 - cos[p]) / 2 for p in pairs)
        assert deficit <= midpoint_sum + tol
        value = S.eta(na, nb, nc)
        assert 0.0 <= value <= midpoint_sum + tol

    @pytest.mark.parametrize(
        "args, match",
        [(([0, 0, 2], [0, 0, 1], [0, 1, 0]), "na must be unit"),
         (([0, 0, 1], [0, 0, 0], [0, 1, 0]), "nb contains a zero vector"),
         (([0, 0, 1], [0, 0, 1], [np.inf, 1, 0]), "nc must be finite"),
         (([0, 0, 1], [0, 0, 1], np.eye(3)[:2]), None),
         ((np.eye(3)[:2], np.eye(3), [0, 0, 1]), "must broadcast")],
    )
    def test_raises(self, args, match):
        if match is None:  # (2, 3) against (3,) broadcasts fine
            assert S.eta(*args).shape == (2,)
            return
        with pytest.raises(ValueError, match=match):
            S.eta(*args)


# ================================================= seed 002: edge highlight
class TestEdgeHighlight:
    T_GRID = np.linspace(0.0, 1.0, 2001)
    XATOL = 1e-10

    @staticmethod
    def h_direct(tt, hv, na, nb):
        """``H.N(t)/|N(t)|`` from the vectors, for scalar or 1-d ``t``."""
        tt = np.asarray(tt, dtype=float)[..., None]
        nt = (1 - tt) * na + tt * nb
        return (nt @ hv) / np.linalg.norm(nt, axis=-1)

    @pytest.fixture
    def edges(self, rng):
        count = 150
        angles = rng.uniform(0.05, 2 * np.pi / 3, size=count)
        na, nb = pairs_at_angles(rng, angles)
        hv = random_unit(rng, count)
        dots = [np.einsum("ij,ij->i", x, y) for x, y in ((hv, na), (hv, nb), (na, nb))]
        return angles, hv, na, nb, dots

    def test_against_brute_force(self, edges):
        angles, hv, na, nb, (aa, bb, cc) = edges
        peak = S.edge_highlight(aa, bb, cc)
        free = S.edge_highlight_unclipped(aa, bb, cc)
        kinds = {"interior": 0, "clipped": 0, "falling": 0}
        for i, angle in enumerate(angles):
            # eps-level tolerance: the value formula cancels in
            # a^2 - 2abc + b^2 and divides by 1 - c^2 before a square root
            value_sq = free.value[i] ** 2
            tol = ROUNDINGS * EPS + sqrt_error(value_sq, ROUNDINGS * EPS / (1 - cc[i] ** 2))
            grid_max = self.h_direct(self.T_GRID, hv[i], na[i], nb[i]).max()
            # the returned t attains the returned value, which is the maximum
            assert abs(self.h_direct(peak.t[i], hv[i], na[i], nb[i]) - peak.value[i]) <= tol
            assert grid_max <= peak.value[i] + tol
            # on the arc h = R cos(theta - theta0), R <= 1, and theta'(t) =
            # sin(phi)/|N(t)|^2 <= 2 tan(phi/2): a grid step DT in t is at most
            # 2 tan(phi/2) DT in theta, and the nearest node loses at most
            # (theta step / 2)^2 / 2 = tan(phi/2)^2 DT^2 / 2 at an interior max
            dt = self.T_GRID[1] - self.T_GRID[0]
            assert peak.value[i] - grid_max <= np.tan(angle / 2) ** 2 * dt**2 / 2 + tol
            # bounded Brent stops within 2 (sqrt(eps) |x| + xatol/3) of the
            # optimum (scipy's termination test); first-order loss |h'| dx
            # with |h'| <= R theta'(t) <= 2 tan(phi/2)
            from scipy.optimize import minimize_scalar

            res = minimize_scalar(
                lambda x: -float(self.h_direct(x, hv[i], na[i], nb[i])),
                bounds=(0.0, 1.0), method="bounded", options={"xatol": self.XATOL},
            )
            assert -res.fun <= peak.value[i] + tol
            dx = 2 * (np.sqrt(EPS) + self.XATOL / 3)
            assert peak.value[i] + res.fun <= 2 * np.tan(angle / 2) * dx + tol
            if aa[i] + bb[i] <= 0:
                kinds["falling"] += 1
            elif 0 <= free.t[i] <= 1:
                kinds["interior"] += 1
            else:
                kinds["clipped"] += 1
        assert all(count > 0 for count in kinds.values()), kinds

    def test_unclipped(self, edges):
        angles, hv, na, nb, (aa, bb, cc) = edges
        free = S.edge_highlight_unclipped(aa, bb, cc)
        seed_t = (bb - aa * cc) / ((aa + bb) * (1 - cc))
        tol_t = ROUNDINGS * EPS * (1 + np.abs(seed_t))
        assert_below(np.abs(free.t - seed_t), tol_t)
        # value = length of H projected on the plane of N_A, N_B = |H x m|
        m = unit(np.cross(na, nb))
        projected = np.linalg.norm(np.cross(hv, m), axis=-1)
        tol = ROUNDINGS * EPS + sqrt_error(projected**2, ROUNDINGS * EPS / (1 - cc**2))
        assert_below(np.abs(free.value - projected), tol)
        # h(t*) = sign(a + b) * value, evaluated with the vectors
        for i in range(len(angles)):
            h = self.h_direct(free.t[i], hv[i], na[i], nb[i])
            assert abs(h - np.sign(aa[i] + bb[i]) * free.value[i]) <= tol[i]

    def test_parallel_normals(self):
        peak = S.edge_highlight(0.7, 0.7, 1.0)
        assert (peak.t, peak.value) == (0.0, 0.7)
        free = S.edge_highlight_unclipped(0.7, 0.7, 1.0)
        assert np.isnan(free.t) and np.isnan(free.value)
        # within DOT_ATOL of parallel: endpoint max, off by at most (1 - c)/4
        cc = 1 - S.DOT_ATOL / 2
        na, nb = pairs_at_angles(np.random.default_rng(1), [np.arccos(cc)])
        hv = unit(na[0] + 0.3 * np.array([1.0, -2.0, 0.5]))
        aa, bb = hv @ na[0], hv @ nb[0]
        peak = S.edge_highlight(aa, bb, cc)
        assert peak.value == max(aa, bb)
        best = self.h_direct(self.T_GRID, hv, na[0], nb[0]).max()
        assert best - peak.value <= (1 - cc) / 4 + ROUNDINGS * EPS

    def test_symmetric_and_falling(self):
        peak = S.edge_highlight(0.8, 0.8, 0.6)
        assert peak.t == pytest.approx(0.5, abs=ROUNDINGS * EPS)
        assert peak.value == pytest.approx(np.sqrt(0.8), abs=ROUNDINGS * EPS)
        # a + b = 0: h is monotone, t* does not exist; endpoint maximum
        peak = S.edge_highlight(0.5, -0.5, 0.0)
        assert (peak.t, peak.value) == (0.0, 0.5)
        assert np.isnan(S.edge_highlight_unclipped(0.5, -0.5, 0.0).t)
        # a + b < 0: t* is a minimum; the maximum is the better endpoint
        peak = S.edge_highlight(-0.2, -0.6, 0.5)
        assert (peak.t, peak.value) == (0.0, -0.2)

    def test_shapes(self):
        peak = S.edge_highlight([[0.8], [0.5]], [0.8, 0.1, 0.3], 0.6)
        assert peak.t.shape == peak.value.shape == (2, 3)
        assert np.ndim(S.edge_highlight(0.8, 0.8, 0.6).t) == 0

    @pytest.mark.parametrize(
        "abc, match",
        [((1.5, 0.0, 0.0), r"a = H.N_A must lie in \[-1, 1\]"),
         ((0.0, np.nan, 0.0), "b = H.N_B must be finite"),
         ((0.0, 0.0, -1.0), "antiparallel"),
         ((1.0, -1.0, 1.0), "Gram determinant"),
         (([0.1, 0.2], [0.1, 0.2, 0.3], 0.0), "must broadcast")],
    )
    @pytest.mark.parametrize("func", [S.edge_highlight, S.edge_highlight_unclipped])
    def test_raises(self, func, abc, match):
        with pytest.raises(ValueError, match=match):
            func(*abc)


# ================================================ seed 000: quadratic span
class TestQuadraticCoefficients:
    NODES = np.array([0.0, 0.5, 1.0])

    def test_against_vandermonde_solve(self, rng):
        nl, nr = pairs_at_angles(rng, rng.uniform(0, 0.9 * np.pi, size=50))
        q = S.quadratic_coefficients(nl, nr)
        nc = S.midpoint_normal(nl, nr)
        vander = np.vander(self.NODES, 3)  # columns t^2, t, 1
        # backward-stable solve: error <= n cond(V) eps |values|, values <= 1
        tol = len(self.NODES) * np.linalg.cond(vander) * EPS + ROUNDINGS * EPS
        for i in range(len(nl)):
            solved = np.linalg.solve(vander, np.array([nl[i], nc[i], nr[i]]))
            for got, ref in zip((q.G[i], q.P[i], q.Q[i]), solved):
                assert_below(np.abs(got - ref), tol)

    def test_interpolates(self, rng):
        nl, nr = pairs_at_angles(rng, rng.uniform(0, 0.9 * np.pi, size=20))
        nc = unit(nl + nr + 0.01 * rng.normal(size=nl.shape))  # any given centre
        q = S.quadratic_coefficients(nl, nr, nc)
        for node, ref in zip(self.NODES, (nl, nc, nr)):
            np.testing.assert_allclose(q.evaluate(node), ref, rtol=0, atol=ROUNDINGS * EPS)
        assert q.Q is not nl  # a copy, not the input

    def test_approximate_centre_and_antiparallel_with_given_centre(self):
        nl, nr = [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]
        q = S.quadratic_coefficients(nl, nr, [0.0, 0.9, 0.0])
        np.testing.assert_allclose(q.evaluate(0.5), [0.0, 0.9, 0.0], atol=ROUNDINGS * EPS)

    @pytest.mark.parametrize(
        "nl, nr, nc, match",
        [([1, 0, 0], [-1, 0, 0], None, "nl and nr are antiparallel"),
         ([2, 0, 0], [0, 1, 0], None, "nl must be unit"),
         ([1, 0, 0], [0, 1, 0], [np.nan, 0, 0], "nc must be finite"),
         ([1, 0, 0], [0, 1, 0], [0, 1], r"nc must have shape"),
         ([1, 0, 0], [0, 1, 0], np.zeros((2, 2, 3)) + [0, 1, 0], None),
         (np.eye(3)[:2], np.eye(3), None, "must broadcast")],
    )
    def test_raises(self, nl, nr, nc, match):
        if match is None:  # a batch of centres broadcasts against one span
            assert S.quadratic_coefficients(nl, nr, nc).G.shape == (2, 2, 3)
            return
        with pytest.raises(ValueError, match=match):
            S.quadratic_coefficients(nl, nr, nc)


# ======================================================= seed 001: bump map
def random_rotations(rng, count):
    q, r = np.linalg.qr(rng.normal(size=(count, 3, 3)))
    q = q * np.sign(np.diagonal(r, axis1=-2, axis2=-1))[:, None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1  # proper rotations only
    return q


class TestBumpCoefficients:
    def test_against_definitions(self, rng):
        count = 300
        pu = rng.normal(size=(count, 3)) * rng.lognormal(size=(count, 1))
        pv = rng.normal(size=(count, 3)) * rng.lognormal(size=(count, 1))
        fu, fv = rng.normal(size=count), rng.normal(size=count)
        # Blinn's definitions, straight from np.cross
        normal = np.cross(pu, pv)
        length = np.linalg.norm(normal, axis=-1, keepdims=True)
        d = (fu[:, None] * np.cross(normal, pv) + fv[:, None] * np.cross(pu, normal)) / length
        perturbed = normal + d
        tangent = unit(pu)
        unit_normal = normal / length
        binormal = np.cross(unit_normal, tangent)
        defs = np.stack(
            [np.einsum("ij,ij->i", perturbed, x) for x in (tangent, binormal, unit_normal)],
            axis=-1,
        )
        seed = np.stack(
            [-fu * np.einsum("ij,ij->i", binormal, pv),
             fu * np.einsum("ij,ij->i", tangent, pv) - fv * np.linalg.norm(pu, axis=-1),
             length[:, 0]],
            axis=-1,
        )
        got = S.bump_coefficients(pu, pv, fu, fv)
        # the coefficients are of size |P_u||P_v| + |F_u||P_v| + |F_v||P_u|;
        # the cross product's absolute error eps|P_u||P_v| is relative to
        # |N| = |P_u||P_v| sin(angle), hence the 1/sin amplification
        pu_len, pv_len = np.linalg.norm(pu, axis=-1), np.linalg.norm(pv, axis=-1)
        scale = pu_len * pv_len + np.abs(fu) * pv_len + np.abs(fv) * pu_len
        sin = length[:, 0] / (pu_len * pv_len)
        tol = (2 * ROUNDINGS * EPS * scale / sin)[:, None]
        assert_below(np.abs(got - defs), tol)
        assert_below(np.abs(got - seed), tol)

    def test_square_patch(self, rng):
        count = 50
        rot = random_rotations(rng, count)
        kk = rng.lognormal(size=count)
        pu = kk[:, None] * rot[:, :, 0]
        pv = kk[:, None] * rot[:, :, 1]
        fu, fv = rng.normal(size=count), rng.normal(size=count)
        full = S.bump_coefficients(pu, pv, fu, fv)
        scale = (np.abs(fu) + np.abs(fv) + kk) * kk
        tol = (2 * ROUNDINGS * EPS * scale)[:, None]
        assert_below(
            np.abs(full - np.stack([-fu * kk, -fv * kk, kk**2], axis=-1)), tol
        )
        square = S.bump_coefficients_square(fu, fv, kk)
        assert_below(np.abs(full / full[:, 2:] - square), tol / kk[:, None] ** 2)

    def test_square_formula_is_not_general(self):
        """Off a square patch the simplification is wrong (what C12 measures)."""
        full = S.bump_coefficients([1.0, 0.0, 0.0], [0.5, 2.0, 0.0], 0.3, 0.4)
        assert not np.allclose(full / full[2], S.bump_coefficients_square(0.3, 0.4, 1.0))

    def test_shapes(self, rng):
        pu, pv = rng.normal(size=(4, 3)), rng.normal(size=(4, 3))
        assert S.bump_coefficients(pu, pv, 0.1, 0.2).shape == (4, 3)
        assert S.bump_coefficients(pu[0], pv[0], [0.1, 0.2], 0.0).shape == (2, 3)
        assert S.bump_coefficients_square([0.1, 0.2], 0.0, 1.0).shape == (2, 3)

    @pytest.mark.parametrize(
        "args, match",
        [(([0, 0, 0], [0, 1, 0], 0.1, 0.1), "P_u contains a zero vector"),
         (([1, 0, 0], [2, 0, 0], 0.1, 0.1), "P_u and P_v are parallel"),
         (([1, 0, 0], [0, 1, 0], np.nan, 0.1), "F_u must be finite"),
         (([1, 0], [0, 1], 0.1, 0.1), r"P_u must have shape"),
         ((np.eye(3)[:2], [0, 0, 1], [0.1, 0.2, 0.3], 0.1), "must broadcast")],
    )
    def test_raises(self, args, match):
        with pytest.raises(ValueError, match=match):
            S.bump_coefficients(*args)

    @pytest.mark.parametrize(
        "args, match",
        [((0.1, 0.1, 0.0), r"k must lie in \(0, inf\)"),
         ((0.1, 0.1, -2.0), r"k must lie in \(0, inf\)"),
         ((0.1, np.inf, 1.0), "F_v must be finite"),
         (([0.1, 0.2], [0.1, 0.2, 0.3], 1.0), "must broadcast")],
    )
    def test_raises_square(self, args, match):
        with pytest.raises(ValueError, match=match):
            S.bump_coefficients_square(*args)
