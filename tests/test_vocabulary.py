"""One spelling per concept: coefficient bits are ``coef_frac_bits`` in fit,
quantize, fit_target and hw.report (as ``--coef-frac-bits`` in the CLI); the old
keywords work for one release with a ChebnormDeprecationWarning."""

import pytest

import chebnorm as cn
from chebnorm.core.deprecation import ChebnormDeprecationWarning


def test_fit_takes_coef_frac_bits_and_the_old_keyword_warns():
    new = cn.fit("exp(x)", (0, 1), 3, coef_frac_bits=16)
    with pytest.warns(ChebnormDeprecationWarning, match=r"fit\(frac_bits=\.\.\.\).*coef_frac_bits="):
        old = cn.fit("exp(x)", (0, 1), 3, frac_bits=16)
    assert old == new and new.quantized.frac_bits == (16,) * 4


def test_quantize_and_fit_target():
    t = cn.fit("exp(x)", (0, 1), 3)
    assert cn.quantize(t, coef_frac_bits=12) == cn.quantize(t, 12)
    with pytest.warns(ChebnormDeprecationWarning):
        assert cn.quantize(t, frac_bits=12) == cn.quantize(t, 12)
    with pytest.warns(ChebnormDeprecationWarning):
        cn.fit_target("dichotomy", 1, frac_bits=12)
    assert cn.fit_target("dichotomy", 1, coef_frac_bits=12).quantized is not None


def test_hw_report_takes_coef_frac_bits():
    t = cn.fit_target("dichotomy", 1)
    r = cn.hw.report(t, 8, 8, coef_frac_bits=12, synth=False, gappa=False)
    with pytest.warns(ChebnormDeprecationWarning, match="coef_bits"):
        old = cn.hw.report(t, 8, 8, coef_bits=12, synth=False, gappa=False)
    assert old.budget.total == r.budget.total


@pytest.mark.parametrize("call", [
    lambda: cn.fit("exp(x)", (0, 1), 3, frac_bits=16, coef_frac_bits=16),
    lambda: cn.quantize(cn.fit("exp(x)", (0, 1), 3), 16, frac_bits=16),
])
def test_both_spellings_at_once_are_refused(call):
    with pytest.raises(ValueError, match="give coef_frac_bits only"):
        call()


def test_messages_say_coef_frac_bits():
    with pytest.raises(ValueError, match=r"^coef_frac_bits 40 overflows int32"):
        cn.fit("exp(x)", (0, 1), 3, coef_frac_bits=40)
