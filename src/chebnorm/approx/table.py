"""The coefficient-table contract read by every consumer of chebnorm.

A :class:`CoefficientTable` is a polynomial ``p(x) = sum_k c_k x^k`` (ascending
powers of the original variable ``x``) approximating ``f(x)`` on ``[lo, hi]``,
with rigorous bounds of its absolute and relative error there, the located
maxima, an optional fixed-point version, and where it came from.

JSON schema (version 1): every field of the dataclasses below, floats written
with Python's shortest round-trip repr, keys sorted.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

__all__ = ["CoefficientTable", "FixedPoint", "SCHEMA_VERSION"]

SCHEMA_VERSION = 1


@dataclass(frozen=True)
class FixedPoint:
    """Coefficients rounded to ``frac_bits`` fractional bits.

    ``integers[k] / 2**frac_bits`` is the coefficient of ``x**k`` (exactly).
    ``word_bits`` is the signed integer width they are guaranteed to fit
    (two's complement). Bounds and maxima are those of the quantized
    polynomial, re-certified (evaluated exactly, without rounding inside
    Horner's rule). ``method`` is ``"rounded"`` (each coefficient rounded to
    nearest) or ``"reoptimized"`` (coefficients rounded from the highest power
    down, the lower ones refitted by Remez after each rounding).
    """

    frac_bits: int
    integers: tuple[int, ...]
    word_bits: int
    method: str
    abs_error_bound: float
    rel_error_bound: float | None
    max_abs_error: float
    max_rel_error: float | None

    @property
    def coefficients(self) -> tuple[float, ...]:
        """The quantized coefficients as floats (exact)."""
        return tuple(math.ldexp(q, -self.frac_bits) for q in self.integers)


@dataclass(frozen=True)
class CoefficientTable:
    """A fitted polynomial with certified error bounds (see module docstring).

    ``interval`` holds the exact endpoints as sympy strings; ``interval_float``
    the nearest floats. ``abs_error_bound >= sup|p - f|`` and
    ``rel_error_bound >= sup|p/f - 1|`` are rigorous; ``max_abs_error`` is
    ``|p - f|`` at ``max_abs_at``, a located maximum (so a lower bound of the
    supremum). ``rel_*`` fields are None when ``f`` vanishes on the interval.

    >>> t = CoefficientTable(name="sq", expression="x**2", variable="x",
    ...     interval=("0", "1"), interval_float=(0.0, 1.0), degree=2,
    ...     kind="chebyshev", error_kind="abs", coefficients=(0.0, 0.0, 1.0),
    ...     abs_error_bound=0.0, rel_error_bound=0.0, max_abs_error=0.0,
    ...     max_abs_at=0.0, max_rel_error=0.0, max_rel_at=0.0)
    >>> CoefficientTable.from_json(t.to_json()) == t
    True
    >>> float(t(0.5))
    0.25
    """

    name: str
    expression: str
    variable: str
    interval: tuple[str, str]
    interval_float: tuple[float, float]
    degree: int
    kind: str
    error_kind: str
    coefficients: tuple[float, ...]
    abs_error_bound: float
    rel_error_bound: float | None
    max_abs_error: float
    max_abs_at: float
    max_rel_error: float | None
    max_rel_at: float | None
    fixed_point: FixedPoint | None = None
    provenance: dict[str, str] = field(default_factory=dict)
    schema_version: int = SCHEMA_VERSION

    # -- evaluation -------------------------------------------------------
    def __call__(self, x, dtype=np.float64):
        """Horner evaluation of the float coefficients in ``dtype``."""
        x = np.asarray(x, dtype=dtype)
        acc = np.full_like(x, self.coefficients[-1])
        for c in reversed(self.coefficients[:-1]):
            acc = acc * x + dtype(c)
        return acc

    def covers(self, lo: float, hi: float) -> bool:
        """True when ``[lo, hi]`` lies inside the table's interval."""
        return self.interval_float[0] <= lo and hi <= self.interval_float[1]

    # -- JSON ---------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["interval"] = list(self.interval)
        d["interval_float"] = list(self.interval_float)
        d["coefficients"] = list(self.coefficients)
        if self.fixed_point is not None:
            d["fixed_point"]["integers"] = list(self.fixed_point.integers)
        return d

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True, indent=2) + "\n"

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "CoefficientTable":
        if not isinstance(d, dict):
            raise ValueError(f"a coefficient table must be a JSON object, got {type(d).__name__}")
        version = d.get("schema_version")
        if version != SCHEMA_VERSION:
            raise ValueError(f"coefficient table schema version {version!r} is not supported "
                             f"(accepted: {SCHEMA_VERSION})")
        try:
            fp = d.get("fixed_point")
            fixed = None if fp is None else FixedPoint(
                frac_bits=int(fp["frac_bits"]), integers=tuple(int(q) for q in fp["integers"]),
                word_bits=int(fp["word_bits"]), method=str(fp["method"]),
                abs_error_bound=float(fp["abs_error_bound"]),
                rel_error_bound=None if fp["rel_error_bound"] is None else float(fp["rel_error_bound"]),
                max_abs_error=float(fp["max_abs_error"]),
                max_rel_error=None if fp["max_rel_error"] is None else float(fp["max_rel_error"]))
            opt = lambda v: None if v is None else float(v)
            table = cls(
                name=str(d["name"]), expression=str(d["expression"]), variable=str(d["variable"]),
                interval=tuple(str(v) for v in d["interval"]),
                interval_float=tuple(float(v) for v in d["interval_float"]),
                degree=int(d["degree"]), kind=str(d["kind"]), error_kind=str(d["error_kind"]),
                coefficients=tuple(float(c) for c in d["coefficients"]),
                abs_error_bound=float(d["abs_error_bound"]), rel_error_bound=opt(d["rel_error_bound"]),
                max_abs_error=float(d["max_abs_error"]), max_abs_at=float(d["max_abs_at"]),
                max_rel_error=opt(d["max_rel_error"]), max_rel_at=opt(d["max_rel_at"]),
                fixed_point=fixed, provenance=dict(d.get("provenance", {})),
                schema_version=SCHEMA_VERSION)
        except (KeyError, TypeError) as exc:
            raise ValueError(f"coefficient table is missing or has a malformed field: {exc}") from None
        if len(table.coefficients) != table.degree + 1:
            raise ValueError(f"coefficient table {table.name!r} has {len(table.coefficients)} "
                             f"coefficients for degree {table.degree} (expected degree + 1)")
        return table

    @classmethod
    def from_json(cls, text: str) -> "CoefficientTable":
        try:
            d = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ValueError(f"coefficient table is not valid JSON: {exc}") from None
        return cls.from_dict(d)

    @classmethod
    def load(cls, path) -> "CoefficientTable":
        try:
            with open(path, encoding="utf-8") as fh:
                return cls.from_json(fh.read())
        except OSError as exc:
            raise ValueError(f"cannot read coefficient table {str(path)!r}: {exc.strerror}") from None

    def save(self, path) -> None:
        """Write the JSON atomically (temporary file, then rename)."""
        from .files import write_atomic

        write_atomic(path, self.to_json())
