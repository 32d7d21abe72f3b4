"""Fixed-point arithmetic, bit-accurate: Q formats, rounding, overflow.

Conventions
-----------
* A fixed-point *code* ``k`` (an integer) in format ``QFormat(frac_bits=F,
  offset=O)`` stands for the value ``O + k / 2**F``. ``O`` is a multiple of
  ``2**-F`` (held as the integer ``offset_code = O * 2**F``), so every
  value of the format is ``(offset_code + k) / 2**F`` exactly.
* ``signed`` formats hold ``-2**(bits-1) <= k < 2**(bits-1)`` (two's
  complement), unsigned ones ``0 <= k < 2**bits``.
* Rounding modes (:data:`ROUNDINGS`): ``"trunc"`` -- toward minus infinity,
  i.e. dropping bits of a two's-complement number (Verilog ``>>>``);
  ``"rne"`` -- to nearest, ties to even. A right shift by ``s`` bits with
  ``"trunc"`` errs by ``(-2**-F', 0]`` in the result's units ``2**-F'``;
  with ``"rne"`` by at most half of one.
* Overflow modes (:data:`OVERFLOWS`): ``"saturate"`` clamps to the
  representable range, ``"wrap"`` keeps the low bits (two's complement);
  both report which codes overflowed.

The kernels take Python ints or numpy ``int64`` arrays and do not check
that int64 does not overflow; :func:`check_int64` is the boundary check.

>>> import numpy as np
>>> shift_round(np.array([5, 6, 7, -5, -6]), 1, "rne").tolist()   # 2.5 3 3.5 -2.5 -3
[2, 3, 4, -2, -3]
>>> shift_round(np.array([5, -5]), 1, "trunc").tolist()
[2, -3]
>>> fit_bits(np.array([-3, 9, 300]), 8, signed=False, overflow="saturate")
(array([  0,   9, 255]), array([ True, False,  True]))
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

# the modules of chebnorm.hw import these from here, with the rest of the fixed-point helpers
from chebnorm.core.numeric import check_int as check_width  # noqa: F401
from chebnorm.core.numeric import signed_bits, unsigned_bits  # noqa: F401

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: rounding modes: toward minus infinity (drop bits), to nearest with ties to even
ROUNDINGS = ("trunc", "rne")
#: overflow modes: clamp to the range, or keep the low bits (two's complement)
OVERFLOWS = ("saturate", "wrap")

#: widest integer the vectorized model keeps in int64 (sign bit and a margin)
INT64_BITS = 62


@dataclass(frozen=True)
class QFormat:
    """An unsigned or signed fixed-point format: code ``k`` stands for
    ``(offset_code + k) / 2**frac_bits``.

    >>> q = QFormat(bits=16, frac_bits=16, offset_code=92681)
    >>> float(q.value(0)), float(q.value(q.max_code))
    (1.4141998291015625, 2.4141845703125)
    >>> q.as_dict()
    {'bits': 16, 'frac_bits': 16, 'offset': 1.4141998291015625, 'offset_code': 92681, 'signed': False}

    Parameters
    ----------
    bits : int
        Width of a code in bits (at least 1).
    frac_bits : int
        Fractional bits ``F``: the weight of the least significant bit is ``2**-F``;
        negative means a coarser than unit LSB (``2**|F|``).
    offset_code : int, default 0
        The offset ``O`` in units of the LSB (``O = offset_code / 2**F``), added to every
        code; 0 for a plain Q format.
    signed : bool, default False
        Two's-complement codes ``-2**(bits-1) <= k < 2**(bits-1)`` when true, else
        ``0 <= k < 2**bits``.
    """

    bits: int
    frac_bits: int
    offset_code: int = 0
    signed: bool = False

    @property
    def offset(self) -> Fraction:
        return Fraction(self.offset_code, 2 ** self.frac_bits) if self.frac_bits >= 0 else \
            Fraction(self.offset_code * 2 ** -self.frac_bits)

    @property
    def min_code(self) -> int:
        return -(2 ** (self.bits - 1)) if self.signed else 0

    @property
    def max_code(self) -> int:
        return 2 ** (self.bits - 1) - 1 if self.signed else 2 ** self.bits - 1

    @property
    def lsb(self) -> Fraction:
        return Fraction(1, 2 ** self.frac_bits) if self.frac_bits >= 0 else Fraction(2 ** -self.frac_bits)

    def value(self, code) -> Fraction:
        """The exact value of one code."""
        return self.offset + int(code) * self.lsb

    def values(self, codes) -> np.ndarray:
        """Float64 values of an array of codes (exact while they fit 53 bits)."""
        return (np.asarray(codes, dtype=np.float64) + float(self.offset_code)) * 2.0 ** -self.frac_bits

    def as_dict(self) -> dict:
        return {"bits": self.bits, "frac_bits": self.frac_bits, "offset": float(self.offset),
                "offset_code": self.offset_code, "signed": self.signed}

    def q_name(self) -> str:
        """Texas-Instruments style name of the code's format, ``UQm.F`` or ``Qm.F``."""
        m = self.bits - self.frac_bits - (1 if self.signed else 0)
        return f"{'' if self.signed else 'U'}Q{m}.{self.frac_bits}"


def shift_round(v, shift: int, mode: str):
    """``v / 2**shift`` rounded to an integer (``shift >= 0``), ints or int64 arrays.

    Does not check its arguments (inner kernel). ``"rne"`` rounds to nearest,
    ties to even; ``"trunc"`` rounds toward minus infinity (drops the bits):

    >>> shift_round(5, 1, "rne"), shift_round(7, 1, "rne"), shift_round(-5, 1, "rne")
    (2, 4, -2)
    >>> shift_round(7, 1, "trunc"), shift_round(-5, 1, "trunc")
    (3, -3)

    Parameters
    ----------
    v : int or numpy.ndarray of int64
        The integer(s) to shift.
    shift : int
        Number of bits to drop, ``>= 0`` (0 returns ``v`` unchanged).
    mode : {"trunc", "rne"}
        Rounding mode (:data:`ROUNDINGS`); any other string behaves as ``"rne"``.

    Returns
    -------
    int or numpy.ndarray
        ``v / 2**shift`` rounded, of the type of ``v``.
    """
    if shift == 0:
        return v
    q = v >> shift
    if mode == "trunc":
        return q
    r = v - (q << shift)
    half = 1 << (shift - 1)
    if isinstance(v, np.ndarray):
        return q + ((r > half) | ((r == half) & ((q & 1) == 1))).astype(q.dtype)
    return q + int(r > half or (r == half and q & 1 == 1))


def fit_bits(v, bits: int, *, signed: bool, overflow: str):
    """Force ``v`` into a ``bits``-wide code; returns ``(codes, overflowed)``.

    ``"saturate"`` clamps, ``"wrap"`` keeps the low ``bits`` bits (two's
    complement when ``signed``). ``overflowed`` flags the codes that did
    not fit before the operation.

    >>> [int(c) for c in fit_bits([300, -1], 8, signed=False, overflow="saturate")[0]]
    [255, 0]
    >>> codes, over = fit_bits([300, 130], 8, signed=True, overflow="wrap")
    >>> codes.tolist(), over.tolist()       # 300 - 256 and 130 - 256
    ([44, -126], [True, True])

    Parameters
    ----------
    v : int, sequence of int or numpy.ndarray
        The code(s) to fit.
    bits : int
        Width of the result in bits (at least 1).
    signed : bool
        Two's-complement range ``[-2**(bits-1), 2**(bits-1) - 1]`` when true, else
        ``[0, 2**bits - 1]``.
    overflow : {"saturate", "wrap"}
        What to do with codes outside the range (:data:`OVERFLOWS`).

    Returns
    -------
    codes : numpy.ndarray
        The codes forced into range.
    overflowed : numpy.ndarray of bool
        True where the input code was outside the range.

    Raises
    ------
    ValueError
        If ``overflow`` is not one of :data:`OVERFLOWS`.
    """
    lo = -(1 << (bits - 1)) if signed else 0
    hi = (1 << (bits - 1)) - 1 if signed else (1 << bits) - 1
    v = np.asarray(v)
    over = (v < lo) | (v > hi)
    if overflow == "saturate":
        out = np.clip(v, lo, hi)
    elif overflow == "wrap":
        out = v & ((1 << bits) - 1)
        if signed:
            out = np.where(out > hi, out - (1 << bits), out)
    else:
        raise ValueError(f"overflow mode {overflow!r} is unknown; accepted: {', '.join(OVERFLOWS)}")
    return out, over






def rounding_error_bound(frac_bits: int, mode: str, dropped_bits: int | None = None) -> Fraction:
    """Largest ``|rounded - exact|`` when rounding to ``frac_bits`` fractional bits.

    With ``dropped_bits`` (the exact value has ``frac_bits + dropped_bits``
    fractional bits) truncation errs by at most ``2**-F - 2**-(F + d)``.

    >>> rounding_error_bound(4, "rne"), rounding_error_bound(4, "trunc"), rounding_error_bound(4, "trunc", 2)
    (Fraction(1, 32), Fraction(1, 16), Fraction(3, 64))

    Parameters
    ----------
    frac_bits : int
        Fractional bits ``F`` of the rounded result (negative: an LSB of ``2**|F|``).
    mode : {"trunc", "rne"}
        Rounding mode (:data:`ROUNDINGS`).
    dropped_bits : int or None, default None
        Fractional bits dropped by the rounding (``>= 0``), if known; 0 means exact
        (bound 0); None means an unknown, possibly unbounded, number.

    Returns
    -------
    fractions.Fraction
        The exact bound: ``2**-F / 2`` for ``"rne"``; ``2**-F`` (or
        ``2**-F - 2**-(F + d)`` with ``d`` dropped bits) for ``"trunc"``.

    Raises
    ------
    ValueError
        If ``mode`` is not one of :data:`ROUNDINGS`.
    """
    ulp = Fraction(1, 2 ** frac_bits) if frac_bits >= 0 else Fraction(2 ** -frac_bits)
    if dropped_bits == 0:
        return Fraction(0)
    if mode == "rne":
        return ulp / 2
    if mode == "trunc":
        return ulp if dropped_bits is None else ulp - ulp / 2 ** dropped_bits
    raise ValueError(f"rounding mode {mode!r} is unknown; accepted: {', '.join(ROUNDINGS)}")


def check_int64(bits: int, what: str) -> None:
    """Boundary check: a value of ``bits`` signed bits fits the int64 model.

    >>> check_int64(62, "the accumulator")
    >>> check_int64(63, "the accumulator")
    Traceback (most recent call last):
    ...
    ValueError: the accumulator needs 63 bits, which overflows the 64-bit bit-accurate model; accepted: at most 62 bits (use fewer input, coefficient or datapath bits)

    Parameters
    ----------
    bits : int
        The signed width the value needs.
    what : str
        What the value is, for the message (e.g. ``"the accumulator"``).

    Raises
    ------
    ValueError
        If ``bits`` exceeds :data:`INT64_BITS` (62).
    """
    if bits > INT64_BITS:
        raise ValueError(f"{what} needs {bits} bits, which overflows the 64-bit bit-accurate "
                         f"model; accepted: at most {INT64_BITS} bits (use fewer input, "
                         f"coefficient or datapath bits)")

