"""Issue 41's parity acceptance against Sollya 8: an odd or even f on a
symmetric interval, a floating format and no ``monomials`` -- chebnorm's
certified error within 1.01x Sollya's ``fpminimax`` with the full degree, and
never below Sollya's lower enclosure of its own polynomial's error; one Sollya
process for the module (tests/sollya_parity_cases.py)."""

from __future__ import annotations

import pytest

from chebnorm.approx import sollya

pytestmark = [pytest.mark.skipif(not sollya.available(),
                                 reason="sollya is not installed (apt-get install sollya)"),
              pytest.mark.slow]


@pytest.fixture(scope="module")
def rows():
    from sollya_parity_cases import run
    return run()[0]


def test_enough_cases():
    from sollya_parity_cases import CASES, EVEN, ODD

    assert len(CASES) >= 20
    assert {c[0] for c in CASES} == set(ODD) | set(EVEN)
    assert all(c[1] == "-" + c[2] for c in CASES)            # symmetric
    assert {c[4] for c in CASES} == {"binary16", "bfloat16", "binary32", "binary64"}


def test_parity_sub_basis_exact_zeros(rows):
    from sollya_parity_cases import EVEN, label

    for case, q, _, _ in rows:
        want = 0 if case[0] in EVEN else 1
        ms = q.quantized.mantissas
        assert all(m == 0 for k, m in enumerate(ms) if k % 2 != want), label(case)
        assert q.quantized.monomials == tuple(range(case[3] + 1))   # what the user asked


def test_quantized_at_least_as_good_as_fpminimax(rows):
    from sollya_parity_cases import label

    bad = []
    for case, q, sup, ours in rows:
        assert sup is not None, f"sollya's fpminimax failed on {label(case)}"
        assert ours is not None, f"sollya's supnorm failed on {label(case)}"
        b = q.quantized.abs_error_bound
        # a certified bound below Sollya's lower enclosure of the same error is wrong
        assert ours[0] <= b, label(case)
        if b > 1.01 * sup[1]:
            bad.append((label(case), b / sup[1]))
    assert not bad, bad
