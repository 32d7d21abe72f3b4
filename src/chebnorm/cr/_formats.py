"""Binary floating-point formats given by (precision, exponent range), their
inputs, and rounding of binary64 values to them in the five IEEE 754 modes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__: list[str] = []

#: the five IEEE 754 rounding-direction attributes, in the order used everywhere
MODES = ("RNE", "RNA", "RTZ", "RUP", "RDN")
#: the four C has (``fesetround``); RNA is checked in the exact simulation only
C_MODES = ("RNE", "RTZ", "RUP", "RDN")


@dataclass(frozen=True)
class Format:
    """A binary interchange-like format: ``precision`` significand bits (the
    hidden bit counted), normal exponents ``emin..emax``, gradual underflow,
    infinities and NaN; bias ``emax``."""

    name: str
    precision: int
    emin: int
    emax: int

    def __post_init__(self):
        p, emin, emax = self.precision, self.emin, self.emax
        if not (2 <= p <= 24):
            raise ValueError(f"precision {p} is not accepted; accepted: 2..24")
        if emin != 1 - emax or emax < 1 or (emax + 1) & emax:
            raise ValueError(f"exponent range {emin}..{emax} is not accepted; accepted: "
                             f"emin = 1 - emax with emax = 2**(w-1) - 1")
        if self.bits > 32:
            raise ValueError(f"format of {self.bits} bits is not accepted; accepted: up to 32 bits")

    @property
    def exp_bits(self) -> int:
        return (self.emax + 1).bit_length()

    @property
    def bits(self) -> int:
        return 1 + self.exp_bits + self.precision - 1

    @property
    def inf_bits(self) -> int:
        return ((1 << self.exp_bits) - 1) << (self.precision - 1)

    @property
    def nan_bits(self) -> int:
        return self.inf_bits | (1 << (self.precision - 2) if self.precision >= 2 else 1)

    @property
    def max_finite(self) -> float:
        return float(np.ldexp(2.0 - 2.0 ** (1 - self.precision), self.emax))

    @property
    def q_min(self) -> float:
        """The quantum of the round-to-odd grid below ``2**emin`` (2 bits finer
        than the format's smallest subnormal)."""
        return float(np.ldexp(1.0, self.emin - self.precision - 1))

    @property
    def ctype(self) -> str:
        return "uint16_t" if self.bits <= 16 else "uint32_t"

    def all_bits(self) -> np.ndarray:
        """Every bit pattern of the format, ascending."""
        return np.arange(1 << self.bits, dtype=np.uint64)

    def decode(self, bits) -> np.ndarray:
        """The binary64 values of bit patterns (NaN for every NaN pattern)."""
        bits = np.asarray(bits, dtype=np.uint64)
        p = self.precision
        sign = (bits >> np.uint64(self.bits - 1)) & np.uint64(1)
        e = ((bits >> np.uint64(p - 1)) & np.uint64((1 << self.exp_bits) - 1)).astype(np.int64)
        m = (bits & np.uint64((1 << (p - 1)) - 1)).astype(np.float64)
        top = (1 << self.exp_bits) - 1
        with np.errstate(over="ignore"):
            val = np.where(e == 0, np.ldexp(m, self.emin - p + 1),
                           np.ldexp(m + 2.0 ** (p - 1), np.clip(e - self.emax, -1100, 1100) - p + 1))
        val = np.where(e == top, np.where(m == 0, np.inf, np.nan), val)
        return np.where(sign == 1, -val, val)

    def round(self, y, mode: str) -> np.ndarray:
        """Bit patterns of binary64 values ``y`` rounded to the format in
        ``mode`` (one of :data:`MODES`); NaN gives the canonical quiet NaN.
        The same integer algorithm as the generated C's."""
        y = np.asarray(y, dtype=np.float64)
        b = y.view(np.uint64)
        p, emin = self.precision, self.emin
        sign = (b >> np.uint64(63)).astype(bool)
        ab = b & np.uint64(0x7FFFFFFFFFFFFFFF)
        e = (ab >> np.uint64(52)).astype(np.int64) - 1023
        m = (ab & np.uint64((1 << 52) - 1)) | np.uint64(1 << 52)
        # binary64 subnormals: treat as exponent -1022 without the hidden bit
        dsub = (ab >> np.uint64(52)) == 0
        e = np.where(dsub, -1022, e)
        m = np.where(dsub, ab & np.uint64((1 << 52) - 1), m)
        ee = np.maximum(e, emin)
        shift = (ee - (p - 1)) - (e - 52)
        big = shift > 60
        sh = np.minimum(shift, 60).astype(np.uint64)
        n = np.where(big, np.uint64(0), m >> sh)
        rem = np.where(big, np.uint64(0), m & ((np.uint64(1) << sh) - np.uint64(1)))
        half = np.uint64(1) << (sh - np.uint64(1))
        sticky = np.where(big, m != 0, rem != 0)
        above = np.where(big, False, rem > half)
        tie = np.where(big, False, rem == half)
        if mode == "RNE":
            inc = above | (tie & ((n & np.uint64(1)) == 1))
        elif mode == "RNA":
            inc = above | tie
        elif mode == "RTZ":
            inc = np.zeros_like(sticky)
        elif mode == "RUP":
            inc = sticky & ~sign
        elif mode == "RDN":
            inc = sticky & sign
        else:
            raise ValueError(f"mode {mode!r} is not accepted; accepted: {', '.join(MODES)}")
        away = {"RNE": True, "RNA": True, "RTZ": False}.get(mode)
        away = np.full(sign.shape, away) if away is not None else (~sign if mode == "RUP" else sign)
        n = n + inc.astype(np.uint64)
        over = e > self.emax
        eoff = np.clip(ee - emin, 0, 1 << 20).astype(np.uint64)
        mag = (eoff << np.uint64(p - 1)) + n
        inf = np.uint64(self.inf_bits)
        over = over | (mag >= inf)
        mag = np.where(over, np.where(away, inf, inf - np.uint64(1)), mag)
        mag = np.where(ab == 0, np.uint64(0), mag)
        mag = np.where(ab == np.uint64(0x7FF0000000000000), inf, mag)
        out = mag | (sign.astype(np.uint64) << np.uint64(self.bits - 1))
        return np.where(np.isnan(y), np.uint64(self.nan_bits), out)


BINARY16 = Format("binary16", 11, -14, 15)
BFLOAT16 = Format("bfloat16", 8, -126, 127)
#: the named formats
FORMATS = {"binary16": BINARY16, "bfloat16": BFLOAT16}


def parse_format(text) -> Format:
    """A :class:`Format` from a name (``binary16``, ``bfloat16``), a
    ``Format``, or ``"p,emin,emax"``."""
    if isinstance(text, Format):
        return text
    if isinstance(text, str) and text in FORMATS:
        return FORMATS[text]
    if isinstance(text, str):
        parts = text.split(",")
        if len(parts) == 3 and all(s.strip().lstrip("-").isdigit() and s.strip().isascii()
                                   for s in parts):
            p, emin, emax = (int(s) for s in parts)
            if p <= 16 and emax < 1 << 9:  # 2**(emax+2) and q_min stay normal binary64
                try:
                    return Format(f"p{p}e{emax}", p, emin, emax)
                except ValueError as exc:
                    raise ValueError(f"fmt {text[:40]!r}: {exc}") from None
    raise ValueError(f"fmt {str(text)[:40]!r} is not accepted; accepted: binary16, bfloat16, or "
                     f"'p,emin,emax' of at most 16 bits with emax <= 511")
