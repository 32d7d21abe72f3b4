"""The one printer of bounds: text rounded outward at the digits printed.

The check is exact: the printed text read as a rational (``Fraction``) against
the value as a rational, never a float comparison.
"""

from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chebnorm.core.numeric import format_down, format_up

SPECS = [".0e", ".1e", ".3e", ".4e", ".6e", ".10e", ".14e", ".1g", ".3g", ".6g", ".15g",
         ".0f", ".3f", ">12.4e", "+.3e", ".4E", ">10.2f"]

numbers = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False),
    st.fractions(max_denominator=10**12),
    st.integers(-10**20, 10**20),
)


@settings(max_examples=400, deadline=None)
@given(x=numbers, spec=st.sampled_from(SPECS))
def test_up_is_never_below_and_down_never_above(x, spec):
    up, down = format_up(x, spec).strip(), format_down(x, spec).strip()
    assert Fraction(up) >= Fraction(x)
    assert Fraction(down) <= Fraction(x)
    # one unit of the last printed place at most from round-to-nearest
    nearest = Fraction(format(float(x), spec).strip())
    assert Fraction(down) <= nearest <= Fraction(up) or isinstance(x, Fraction)


@pytest.mark.parametrize("x, spec, up, down", [
    (2.6511904684e-03, ".6e", "2.651191e-03", "2.651190e-03"),  # issue 43's multipartite design
    (9.99996e-05, ".4e", "1.0000e-04", "9.9999e-05"),            # the carry into the exponent
    (0.0, ".3e", "0.000e+00", "0.000e+00"),
    (-1.5e-3, ".2e", "-1.50e-03", "-1.50e-03"),                  # exactly representable in the digits? no: 1.5e-3 is not
    (Fraction(1, 3), ".3f", "0.334", "0.333"),
    (1.0, ".4e", "1.0000e+00", "1.0000e+00"),
])
def test_known_texts(x, spec, up, down):
    assert Fraction(format_up(x, spec)) >= Fraction(x) and Fraction(format_down(x, spec)) <= Fraction(x)
    if x != -1.5e-3:
        assert (format_up(x, spec), format_down(x, spec)) == (up, down)


def test_negative_in_between_rounds_toward_its_direction():
    # -1.5e-3 as a double is -0.00150000000000000003..., below -1.50e-03
    assert format_up(-1.5e-3, ".2e") == "-1.50e-03"
    assert format_down(-1.5e-3, ".2e") == "-1.51e-03"


@pytest.mark.parametrize("spec", ["e", ".4x", "4e", ".16e", ".16g", "%.4e"])
def test_bad_spec_is_refused_naming_it(spec):
    with pytest.raises(ValueError, match="spec"):
        format_up(1.0, spec)


def test_text_is_refused():
    with pytest.raises(TypeError, match="number"):
        format_up("1e-3", ".3e")
