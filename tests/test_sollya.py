"""Independent cross-check with Sollya's remez and supnorm (skipped without sollya)."""

from __future__ import annotations

import pytest

from chebnorm.approx import fit, sollya

pytestmark = pytest.mark.skipif(not sollya.available(),
                                reason="sollya is not installed (apt-get install sollya)")

CASES = (
    [("1/sqrt(2+x)", ("sqrt(2)", "2"), d) for d in range(1, 5)]
    + [("1/sqrt(2*(1+x))", ("0", "1"), d) for d in (1, 4)]
    + [("sqrt(2*(1+x))/2", ("0", "1"), d) for d in (2, 3)]
    + [("1/sqrt(x)", ("1/2", "2"), d) for d in (1, 6)]
)


@pytest.mark.parametrize("expr,interval,degree", CASES, ids=str)
def test_against_sollya(expr, interval, degree):
    t = fit(expr, interval, degree, kind="minimax")
    _, theirs = sollya.remez(expr, "x", *interval, degree)
    # our minimax error within 0.1 % of Sollya's optimum (theirs is an enclosure [lower, upper])
    assert t.max_abs_error <= 1.001 * theirs.upper
    # Sollya's certified supnorm of *our* coefficients never exceeds our certified bound
    ours = sollya.supnorm(expr, "x", t.coefficients, *interval)
    assert ours.lower <= t.abs_error_bound
    assert t.abs_error_bound <= 1.01 * ours.upper
    rel = sollya.supnorm(expr, "x", t.coefficients, *interval, kind="rel")
    assert rel.lower <= t.rel_error_bound <= 1.01 * rel.upper
