"""Property tests: each method's errors stay within its analytic bound (hypothesis).

Bounds, with r = cos(psi/2) the smallest |N| of the linear interpolant on a span of angle psi:

* none:   1 - |N| <= 1 - r (seed 003's delta_d), attained at the midpoint;
* newton: |N|(3 - |N|^2)/2 is increasing on [0, 1] (derivative 3(1 - x^2)/2 >= 0)
          and equals 1 at |N| = 1, so the deficit is <= 1 - r(3 - r^2)/2;
* lyon:   x(15 - 10x^2 + 3x^4)/8 has derivative 15(1 - x^2)^2/8 >= 0: deficit
          <= 1 - r(15 - 10 r^2 + 3 r^4)/8;
* dichotomy with a table of certified relative error e (at L levels): the
  level-k denominator is off by rho_k, the propagated z by zeta_k, with
  zeta_{k+1} = eps_k + zeta_k/4 and rho_k = eps_k - zeta_k/4 to first order
  (d log f/d log z = -z/(2(2+z)) >= -1/4 for z <= 2), so |zeta| <= 4e/3,
  |rho| <= 4e/3; a midpoint's length error is the mean of its two
  neighbours' plus rho_k, so after L levels | |N| - 1 | <= 4 L e / 3
  (+ O(L^2 e^2) + rounding);
* quadratic with a midpoint table of relative error e: deficit
  <= 1 - sqrt(1 - (1 - r)^2/4) + e (the first term exact, derived in
  the plane of the normals; the table moves N_c by e N_c, and |N(t)| by at
  most 4t(1-t) e);
* exact, slerp: rounding only; angular (float64): the recurrence coefficient
  2 cos(phi) is off by ~eps, a frequency error ~eps/phi, giving an angle drift
  <= m * eps * m/psi after m steps.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from chebnorm.methods import METHODS, default_tables, length_error_bound, span_normals

EPS = float(np.finfo(np.float64).eps)
EPS32 = float(np.finfo(np.float32).eps)
SETTINGS = settings(max_examples=40, deadline=None, derandomize=True)


def _frame(theta, phi, roll):
    """A rotation from three angles (z-y-z), as a 3x3 matrix."""
    def rz(a):
        return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])

    def ry(a):
        return np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
    return rz(theta) @ ry(phi) @ rz(roll)


def _pair(psi, theta, phi, roll):
    rot = _frame(theta, phi, roll)
    nl = rot @ np.array([1.0, 0.0, 0.0])
    nr = rot @ np.array([math.cos(psi), math.sin(psi), 0.0])
    return nl[None], nr[None]


angles = st.floats(0.0, 2 * math.pi, allow_nan=False)
spans = st.sampled_from([1, 2, 3, 8, 16, 37, 64, 128])


def _len_err(out):
    return np.linalg.norm(out.normals.astype(np.float64), axis=1) - 1.0


@SETTINGS
@given(psi=st.floats(0.0, 3.0), th=angles, ph=angles, ro=angles, m=spans,
       dtype=st.sampled_from([np.float64, np.float32]))
@example(psi=3.0, th=0.0, ph=0.0, ro=0.0, m=2, dtype=np.float64)
def test_linear_family_bounds(psi, th, ph, ro, m, dtype):
    nl, nr = _pair(psi, th, ph, ro)
    r = math.cos(psi / 2)
    eps = EPS32 if dtype == np.float32 else EPS
    tol = 16 * eps
    bounds = {"none": 1 - r, "newton": 1 - r * (3 - r * r) / 2,
              "lyon": 1 - r * (15 - 10 * r ** 2 + 3 * r ** 4) / 8, "exact": 0.0}
    for method, bound in bounds.items():
        err = _len_err(span_normals(method, nl, nr, [m], dtype=dtype))
        assert err.max() <= tol, method                  # never longer than unit
        assert -err.min() <= bound + tol, method
    # the normalizers do not turn the direction: angle to the exact direction is rounding only
    ex = span_normals("exact", nl, nr, [m]).normals
    for method in ("none", "newton", "lyon"):
        n = span_normals(method, nl, nr, [m], dtype=dtype).normals.astype(np.float64)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        assert np.abs(n - ex).max() <= 16 * eps, method


@SETTINGS
@given(psi=st.floats(0.0, 3.0), th=angles, ph=angles, ro=angles, m=spans)
def test_slerp_unit(psi, th, ph, ro, m):
    nl, nr = _pair(psi, th, ph, ro)
    err = _len_err(span_normals("slerp", nl, nr, [m]))
    # the weights use psi = arccos(c), off by ~eps/psi for small psi; |N| moves by
    # that times |d|N|/d psi| <= psi, i.e. by a few eps whatever psi
    assert np.abs(err).max() <= 32 * EPS


@SETTINGS
@given(psi=st.floats(0.0, math.pi / 4), th=angles, ph=angles, ro=angles,
       m=st.sampled_from([1, 2, 4, 8, 16, 64, 256]), degree=st.sampled_from([1, 2]))
@example(psi=math.pi / 4, th=0.0, ph=0.0, ro=0.0, m=256, degree=1)
def test_dichotomy_bound(psi, th, ph, ro, m, degree):
    nl, nr = _pair(min(psi, 0.7853981633974483), th, ph, ro)
    table = default_tables(degree=degree)["dichotomy"]
    levels = max(0, math.ceil(math.log2(m)))
    e = table.rel_error_bound
    bound = 4 * levels * e / 3 + (levels * e) ** 2 + 16 * (levels + 1) * EPS
    err = _len_err(span_normals("dichotomy", nl, nr, [m], tables={"dichotomy": table}))
    assert np.abs(err).max() <= bound
    # the library's tighter form (sum of |rho_k| level by level)
    assert np.abs(err).max() <= length_error_bound("dichotomy", psi, m,
                                                   tables={"dichotomy": table}) <= bound
    exact = _len_err(span_normals("dichotomy", nl, nr, [m], tables={"dichotomy": None}))
    assert np.abs(exact).max() <= 8 * (levels + 1) * EPS


@SETTINGS
@given(psi=st.floats(0.0, math.pi / 4), th=angles, ph=angles, ro=angles, m=spans,
       degree=st.sampled_from([1, 2]))
def test_quadratic_bound(psi, th, ph, ro, m, degree):
    nl, nr = _pair(min(psi, 0.7853981633974483), th, ph, ro)
    table = default_tables(degree=degree)["quadratic"]
    r = math.cos(psi / 2)
    analytic = 1 - math.sqrt(1 - (1 - r) ** 2 / 4)
    rounding = 8 * m * EPS   # forward differences: m additions of O(1) terms
    err = _len_err(span_normals("quadratic", nl, nr, [m], tables={"quadratic": table}))
    assert -err.min() <= analytic + table.rel_error_bound * (1 + table.rel_error_bound) + rounding
    assert err.max() <= table.rel_error_bound + rounding


@SETTINGS
@given(psi=st.floats(0.01, 2.5), th=angles, ph=angles, ro=angles,
       m=st.sampled_from([2, 16, 128, 512]))
def test_angular_float64_drift_bound(psi, th, ph, ro, m):
    from chebnorm.methods import slerp_normals
    nl, nr = _pair(psi, th, ph, ro)
    out = span_normals("angular", nl, nr, [m])
    ref = slerp_normals(nl[0], nr[0], psi, out.t)
    drift = 4 * m * EPS * (m / psi) + 64 * EPS
    assert np.abs(out.normals - ref).max() <= drift


@SETTINGS
@given(method=st.sampled_from(METHODS), psi=st.floats(0.0, math.pi / 4), th=angles, ph=angles,
       ro=angles, m=spans, dtype=st.sampled_from([np.float64, np.float32]))
@example(method="dichotomy", psi=math.pi / 4, th=0.0, ph=0.0, ro=0.0, m=37, dtype=np.float64)
def test_every_method_within_length_error_bound(method, psi, th, ph, ro, m, dtype):
    psi = min(psi, 0.7853981633974483)
    if method == "angular" and psi < 0.01:
        psi = 0.01  # the drift estimate grows as 1/psi; tiny angles are checked elsewhere
    nl, nr = _pair(psi, th, ph, ro)
    err = _len_err(span_normals(method, nl, nr, [m], dtype=dtype))
    # float32: the end normals themselves are rounded to float32 (|N| off by ~eps32)
    slack = 4 * EPS32 if dtype == np.float32 else 0.0
    assert np.abs(err).max() <= length_error_bound(method, psi, m, dtype=dtype) + slack
