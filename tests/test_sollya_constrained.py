"""Issue 25's acceptance against Sollya 8: 62 cases (39 constrained: odd on
symmetric and one-sided intervals, even, a fixed constant; fixed point up to 28
bits and binary64), one Sollya process (tests/sollya_constrained_cases.py)."""

from __future__ import annotations

import math

import pytest

from chebnorm.approx import sollya

pytestmark = [pytest.mark.skipif(not sollya.available(),
                                 reason="sollya is not installed (apt-get install sollya)"),
              pytest.mark.filterwarnings("ignore::chebnorm.approx.FitWarning")]

@pytest.fixture(scope="module")
def rows():
    from sollya_constrained_cases import run
    return run()[0]


def test_enough_cases(rows):
    constrained = [r for r in rows if r[0][4] is not None or r[0][5]]
    assert len(rows) >= 60 and len(constrained) >= len(rows) / 2


def test_quantized_at_least_as_good_as_fpminimax(rows):
    from sollya_constrained_cases import label, quantized_bound

    bad = []
    for case, q, _, sup, ours, _ in rows:
        assert sup is not None, f"sollya's fpminimax failed on {label(case)}"
        b = quantized_bound(q)
        if ours is not None:                       # never below Sollya's lower enclosure
            assert ours[0] <= b, label(case)
        if b > 1.01 * sup[1]:
            bad.append((label(case), b / sup[1]))
    assert not bad, bad


def test_real_constrained_within_a_thousandth_of_remez(rows):
    from sollya_constrained_cases import label, real_error

    for case, _, real, _, _, rem in rows:
        assert rem is not None, f"sollya's remez failed on {label(case)}"
        # the float64 rounding of the stored coefficients adds at most half an ulp each
        scale = max(abs(float(v)) for v in real.interval_float)
        rounding = sum(abs(c) * scale ** k for k, c in enumerate(real.coefficients)) * 2.0 ** -53
        if real.error_kind == "rel":
            rounding /= min(abs(real(x)) for x in real.interval_float)
        assert real_error(real) <= 1.001 * rem + rounding, label(case)
        assert math.isfinite(real_error(real))
