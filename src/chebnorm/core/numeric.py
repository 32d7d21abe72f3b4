"""Small exact helpers that several stages need, written once.

Floats rounded outward from exact values (a bound printed as a float must not
be below the proved rational or ball it stands for), two's-complement
widths, the integer argument check every width and degree goes through, and
a scoped Arb working precision (``flint.ctx.prec`` is process-global, so a
function that raises it must restore it on every exit, and two threads' scopes
must not interleave).

>>> from fractions import Fraction
>>> float_up(Fraction(1, 3)) >= Fraction(1, 3) >= float_down(Fraction(1, 3))
True
>>> signed_bits(-4, 3), unsigned_bits(256)
(3, 9)
"""

from __future__ import annotations

import contextlib
import decimal
import math
import numbers
import re
import threading
from fractions import Fraction

import numpy as np


def float_up(x: Fraction) -> float:
    """The smallest float64 ``>= x`` (``x`` a rational, or an int or float).

    Parameters
    ----------
    x : fractions.Fraction or int or float
        An exact rational.

    Returns
    -------
    float
        ``x`` rounded toward plus infinity.

    Examples
    --------
    >>> float_up(Fraction(1, 10)) == math.nextafter(0.1, 1.0) or float_up(Fraction(1, 10)) == 0.1
    True
    >>> Fraction(float_up(Fraction(1, 10))) >= Fraction(1, 10)
    True
    """
    x = Fraction(x)
    f = float(x)
    while Fraction(f) < x:
        f = math.nextafter(f, math.inf)
    return f


_SPEC = re.compile(r"([<>^=]?)([-+ ]?)(\d*)\.(\d+)([efgEFG])")


def _format_directed(x, spec: str, rounding: str) -> str:
    if isinstance(x, str) or isinstance(x, bool):
        raise TypeError(f"a bound must be a number, not {type(x).__name__}")
    m = _SPEC.fullmatch(spec.lstrip(":"))
    if m is None:
        raise ValueError(f"spec must look like '.4e', '.3g' or '.6f', not {spec!r}")
    digits, kind = int(m.group(4)), m.group(5)
    if kind in "eE" and digits > 14 or kind in "gG" and digits > 15:
        raise ValueError(f"spec prints at most 15 significant digits, not {spec!r}")
    if isinstance(x, numbers.Rational):
        # the float on the safe side of the rational (an int beyond 2^53 too), then rounded in the same direction
        x = float_up(x) if rounding == decimal.ROUND_CEILING else float_down(x)
    x = float(x)
    if not math.isfinite(x) or x == 0:
        return format(x, spec.lstrip(":"))
    d = decimal.Decimal(x)  # exact
    if kind in "fF":
        quantum = decimal.Decimal(1).scaleb(-digits)
    else:
        keep = digits if kind in "eE" else max(digits, 1) - 1
        adjusted = d.adjusted() if d else 0
        quantum = decimal.Decimal(1).scaleb(adjusted - keep)
    with decimal.localcontext() as ctx:
        ctx.prec = 400
        q = d.quantize(quantum, rounding=rounding)
    if kind in "fF":
        return format(q, spec.lstrip(":"))  # fixed point prints a decimal as a float
    # q has at most 15 significant digits, so the float nearest it prints as q
    # (float's own exponent style), except deep in the subnormals
    text = format(float(q), spec.lstrip(":"))
    if decimal.Decimal(text.strip()) != q:
        text = format(q, spec.lstrip(":"))
    return text


def format_up(x, spec: str = ".4e") -> str:
    """``x`` printed with ``spec``, rounded upward at the last digit printed.

    An upper bound printed as text must not read smaller than the bound it
    stands for: ``f"{x:.6e}"`` rounds to nearest and may print a number below
    ``x``.  Every printer of an upper bound goes through this helper (a lower
    bound through :func:`format_down`).

    Parameters
    ----------
    x : float or int or fractions.Fraction
        The bound (a rational or an integer is first rounded up to a float).
    spec : str, optional
        A format spec ``[align][sign][width].N(e|f|g)`` (upper case allowed).

    Returns
    -------
    str
        The text; the number it reads is ``>= x``.

    Raises
    ------
    ValueError
        When ``spec`` is not of that form (or asks for more than 15 significant digits).

    Examples
    --------
    >>> format_up(2.6511904684e-03, ".6e"), f"{2.6511904684e-03:.6e}"
    ('2.651191e-03', '2.651190e-03')
    >>> format_up(9.99996e-05, ".4e"), format_up(0.5, ".3g"), format_up(Fraction(1, 3), ".3f")
    ('1.0000e-04', '0.5', '0.334')
    """
    return _format_directed(x, spec, decimal.ROUND_CEILING)


def format_down(x, spec: str = ".4e") -> str:
    """``x`` printed with ``spec``, rounded downward at the last digit printed.

    Parameters
    ----------
    x : float or int or fractions.Fraction
        A lower bound.
    spec : str, optional
        As for :func:`format_up`.

    Returns
    -------
    str
        The text; the number it reads is ``<= x``.

    Examples
    --------
    >>> format_down(2.6511904684e-03, ".6e"), format_down(Fraction(2, 3), ".2f")
    ('2.651190e-03', '0.66')
    """
    return _format_directed(x, spec, decimal.ROUND_FLOOR)


def float_down(x: Fraction) -> float:
    """The largest float64 ``<= x``.

    Parameters
    ----------
    x : fractions.Fraction or int or float
        An exact rational.

    Returns
    -------
    float
        ``x`` rounded toward minus infinity.

    Examples
    --------
    >>> Fraction(float_down(Fraction(1, 10))) <= Fraction(1, 10)
    True
    """
    x = Fraction(x)
    f = float(x)
    while Fraction(f) > x:
        f = math.nextafter(f, -math.inf)
    return f


def ball_float_up(x) -> float:
    """The smallest float64 ``>=`` every point of the Arb ball ``x``.

    Parameters
    ----------
    x : flint.arb
        A finite ball.

    Returns
    -------
    float
        The bound, rounded up to float64 (directed rounding
        of the ball's upper end).

    Examples
    --------
    >>> from flint import arb
    >>> ball_float_up(arb(1) / 3) >= 1 / 3
    True
    """
    from flint import arb

    u = x.upper()
    f = float(u)
    while arb(f) < u:
        f = math.nextafter(f, math.inf)
    return f


def ball_float_down(x) -> float:
    """The largest float64 ``<=`` every point of the Arb ball ``x``.

    Parameters
    ----------
    x : flint.arb
        A finite ball.

    Returns
    -------
    float
        The bound, rounded down to float64 (directed rounding
        of the ball's lower end).

    Examples
    --------
    >>> from flint import arb
    >>> ball_float_down(arb(1) / 3) <= 1 / 3
    True
    """
    from flint import arb

    lo = x.lower()
    f = float(lo)
    while arb(f) > lo:
        f = math.nextafter(f, -math.inf)
    return f


def signed_bits(lo: int, hi: int) -> int:
    """Smallest two's-complement width holding every integer of ``[lo, hi]``.

    Parameters
    ----------
    lo, hi : int
        The range, ``lo <= hi``.

    Returns
    -------
    int
        The width in bits (sign bit included).

    Examples
    --------
    >>> signed_bits(-4, 3), signed_bits(0, 4), signed_bits(-5, 0)
    (3, 4, 4)
    """
    n = 1
    while not (-(1 << (n - 1)) <= lo and hi <= (1 << (n - 1)) - 1):
        n += 1
    return n


def unsigned_bits(hi: int) -> int:
    """Smallest unsigned width holding ``0..hi`` (at least 1).

    Parameters
    ----------
    hi : int
        The largest value, ``hi >= 0``.

    Returns
    -------
    int
        The width in bits.

    Examples
    --------
    >>> unsigned_bits(0), unsigned_bits(255), unsigned_bits(256)
    (1, 8, 9)
    """
    return max(1, int(hi).bit_length())


def check_int(value, name: str, lo: int, hi: int) -> int:
    """``value`` as an int when it is an integer (not a bool) in ``[lo, hi]``;
    otherwise a ValueError naming ``name`` and the accepted range.

    Parameters
    ----------
    value : object
        The value to check (numpy integers are accepted, bools and floats are not).
    name : str
        The argument's name, used in the message.
    lo, hi : int
        The accepted range, both ends included.

    Returns
    -------
    int
        ``value`` as a Python int.

    Raises
    ------
    ValueError
        When ``value`` is not an integer or lies outside ``[lo, hi]``.

    Examples
    --------
    >>> check_int(12, "in_bits", 1, 31)
    12
    >>> check_int(40, "in_bits", 1, 31)
    Traceback (most recent call last):
    ...
    ValueError: in_bits = 40 is out of range; accepted: 1 <= in_bits <= 31
    >>> check_int(2.0, "degree", 0, 30)
    Traceback (most recent call last):
    ...
    ValueError: degree 2.0 is not an integer; accepted: 0 <= degree <= 30
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} {value!r} is not an integer; accepted: {lo} <= {name} <= {hi}")
    if not lo <= int(value) <= hi:
        raise ValueError(f"{name} = {value} is out of range; accepted: {lo} <= {name} <= {hi}")
    return int(value)


#: held for the whole of an :func:`arb_precision` scope: python-flint keeps one
#: precision per process, so a second thread's scope waits (re-entrant: scopes nest)
_PRECISION_LOCK = threading.RLock()


@contextlib.contextmanager
def arb_precision(prec: int):
    """Run a block at Arb working precision ``prec`` bits, restoring the
    previous ``flint.ctx.prec`` on every exit (return, exception).

    The scope holds a process-wide re-entrant lock: python-flint's precision
    is one value for all threads, so another thread's scope waits until this
    one ends instead of changing the precision under it (a thread's own
    scopes nest freely).

    Parameters
    ----------
    prec : int
        Working precision in bits.

    Yields
    ------
    None
        Inside the ``with`` block the precision is ``prec``.

    Examples
    --------
    >>> from flint import ctx
    >>> before = ctx.prec
    >>> with arb_precision(200):
    ...     ctx.prec
    200
    >>> ctx.prec == before
    True
    """
    from flint import ctx

    with _PRECISION_LOCK:
        old = ctx.prec
        try:
            ctx.prec = prec
            yield
        finally:
            ctx.prec = old
