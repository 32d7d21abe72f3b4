"""The schema of chebnorm's table files: kinds, limits, versions, and the JSON field readers.

Both kinds of table (:class:`chebnorm.approx.CoefficientTable`, schema
:data:`SCHEMA_VERSION`; :class:`chebnorm.approx.PiecewiseTable`, kind
:data:`PIECEWISE_KIND`) check what they read against the constants here and
read every field with the readers here, so a refusal reads the same in both:
``field: expected WHAT, got VALUE`` with the value spelled as JSON spells it
(``null``, ``true``, ``an array of 3``, ``an object``, or its repr cut to 60
characters).

>>> integer(31, "degree", 0, MAX_DEGREE)
Traceback (most recent call last):
...
ValueError: degree: expected an integer in 0..30, got 31
>>> number(None, "rel_error_bound", optional=True, nonneg=True) is None
True
"""

from __future__ import annotations

import functools
import json
import math
from importlib.metadata import PackageNotFoundError, version as _pkg_version

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

# -- coefficient tables (chebnorm.approx.CoefficientTable) -----------------------

#: the schema version of a coefficient table (its ``schema_version`` field)
SCHEMA_VERSION = 1
#: the highest polynomial degree :func:`chebnorm.approx.fit` fits and a table may hold
MAX_DEGREE = 30
#: how a coefficient table was fitted (its ``kind`` field)
KINDS = ("chebyshev", "minimax")
#: the error a fit minimizes and a table certifies: absolute or relative
ERROR_KINDS = ("abs", "rel")
#: the variable a table's polynomial is written in: ``x``, or ``t = (x - c)/s``
BASES = ("monomial", "shifted")
#: largest coefficient-table file read (a table is a few kB)
MAX_TABLE_BYTES = 1 << 20
#: longest free text accepted in a field (expression, endpoint, provenance value)
MAX_TEXT = 1000
#: most provenance entries
MAX_PROVENANCE = 32
#: longest provenance key
MAX_KEY = 64
#: exactness of the fixed-point coefficients: ``q / 2**frac_bits`` must be a
#: double (the certifier evaluates the stored doubles exactly), so ``|q| < 2**53``
#: (``word_bits <= 53``) and ``frac_bits <= 1074`` (the smallest subnormal)
MAX_WORD_BITS = 53
#: see :data:`MAX_WORD_BITS`
MAX_FRAC_BITS = 1074
#: how fixed-point (and quantized) coefficients were chosen
FIXED_METHODS = ("rounded", "reoptimized", "lattice")
#: the formats of :class:`chebnorm.approx.Quantized` coefficients
QUANT_FORMATS = ("fixed", "binary16", "bfloat16", "binary32", "binary64")

# -- piecewise tables (chebnorm.approx.PiecewiseTable) ----------------------------

#: the ``kind`` field of a piecewise-table file (a coefficient table has none)
PIECEWISE_KIND = "chebnorm.piecewise_table"
#: the ``schema`` field of a piecewise-table file
PIECEWISE_SCHEMA = 1
#: at most 2**12 segments (a ROM of 4096 words)
MAX_INDEX_BITS = 12
#: the highest degree of a segment's polynomial
MAX_PIECEWISE_DEGREE = 8
#: coefficients are integers / 2**F; |integer| < 2**52 keeps them exact doubles
MAX_COEF_FRAC_BITS = 48
#: see :data:`MAX_COEF_FRAC_BITS`
MAX_COEF_INT_BITS = 52
#: how the segments split the interval
SEGMENT_BY = ("uniform", "exponent")
#: how a segment's polynomial is fitted
PIECEWISE_FITS = ("minimax", "chebyshev")
#: most binades of an exponent-indexed table
MAX_EXPONENT_SPAN = 64
#: largest piecewise-table file read
MAX_PIECEWISE_BYTES = 8 << 20


@functools.lru_cache(maxsize=1)
def versions() -> dict[str, str]:
    """The versions of chebnorm and of the libraries a fit depends on, as recorded
    in every table's ``provenance`` (``"unknown"`` for one not installed).

    Returns
    -------
    dict of str to str
        Package name -> version, for chebnorm, numpy, mpmath, sympy, python-flint.
    """
    out = {}
    for name in ("chebnorm", "numpy", "mpmath", "sympy", "python-flint"):
        try:
            out[name] = _pkg_version(name)
        except PackageNotFoundError:
            out[name] = "unknown"
    return out


# -- the field readers: every refusal names its field ------------------------------

def show(value) -> str:
    """``value`` as the user wrote it in JSON, cut to a readable length.

    Parameters
    ----------
    value : object
        A parsed JSON value (or any Python object).

    Returns
    -------
    str
        ``null``/``true``/``false``, ``an object``, ``an array of N``, or the
        ``repr`` cut to 60 characters.

    Examples
    --------
    >>> show(None), show(True), show([1, 2]), show({}), show("x" * 70)[-5:]
    ('null', 'true', 'an array of 2', 'an object', 'xx...')
    """
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "an object"
    if isinstance(value, (list, tuple)):
        return f"an array of {len(value)}"
    shown = repr(value)
    return shown if len(shown) <= 60 else shown[:57] + "..."


def bad(field: str, expected: str, value) -> ValueError:
    """The refusal ``field: expected EXPECTED, got VALUE`` (to raise).

    Parameters
    ----------
    field : str
        The field's name (dotted for a nested one).
    expected : str
        What the field accepts, e.g. ``"a finite number >= 0"``.
    value : object
        The value refused, shown by :func:`show`.

    Returns
    -------
    ValueError
        The error, for the caller to raise.
    """
    return ValueError(f"{field}: expected {expected}, got {show(value)}")


def number(value, field: str, *, optional: bool = False, nonneg: bool = False) -> float | None:
    """A finite JSON number as a float (``>= 0`` with ``nonneg``; null with ``optional``).

    Parameters
    ----------
    value : object
        The parsed JSON value; an int or float (not a bool).
    field : str
        The field's name, for the refusal.
    optional : bool, optional
        Accept null (returned as None); default False.
    nonneg : bool, optional
        Accept only values ``>= 0``; default False.

    Returns
    -------
    float or None
        The value as a float; None for null with ``optional``.

    Raises
    ------
    ValueError
        When ``value`` is not a finite number (or is negative with ``nonneg``),
        naming ``field``.
    """
    if value is None and optional:
        return None
    what = "a finite number" + (" >= 0" if nonneg else "") + (" or null" if optional else "")
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise bad(field, what, value)
    try:
        out = float(value)
    except OverflowError:
        raise bad(field, what, value) from None
    if not math.isfinite(out) or (nonneg and out < 0):
        raise bad(field, what, value)
    return out


def integer(value, field: str, lo: int | None = None, hi: int | None = None, *,
            expected: str | None = None) -> int:
    """A JSON integer (not a boolean, not ``2.0``), in ``lo..hi`` when given.

    ``expected`` replaces the default wording ``an integer in lo..hi``.

    Parameters
    ----------
    value : object
        The parsed JSON value; an int (not a bool, not a float).
    field : str
        The field's name, for the refusal.
    lo, hi : int, optional
        The accepted range, both ends included; default None (any integer).
    expected : str, optional
        The wording of the refusal (keyword only); default None.

    Returns
    -------
    int
        The value.

    Raises
    ------
    ValueError
        When ``value`` is not an integer in ``lo..hi``, naming ``field``.
    """
    what = expected or ("an integer" if lo is None else f"an integer in {lo}..{hi}")
    if isinstance(value, bool) or not isinstance(value, int):
        raise bad(field, what, value)
    if lo is not None and not lo <= value <= hi:
        raise bad(field, what, value)
    return int(value)


def text(value, field: str, max_length: int = MAX_TEXT, *, empty: bool = False) -> str:
    """A JSON string of at most ``max_length`` characters (non-empty unless ``empty``).

    Parameters
    ----------
    value : object
        The parsed JSON value; a str.
    field : str
        The field's name, for the refusal.
    max_length : int, optional
        The most characters, default :data:`MAX_TEXT`.
    empty : bool, optional
        Accept the empty string (keyword only); default False.

    Returns
    -------
    str
        The value.

    Raises
    ------
    ValueError
        When ``value`` is not a string, is empty (without ``empty``) or longer
        than ``max_length``, naming ``field``.
    """
    if not isinstance(value, str):
        raise bad(field, "a string", value)
    if not value and not empty:
        raise bad(field, "a non-empty string", value)
    if len(value) > max_length:
        raise ValueError(f"{field}: {len(value)} characters; accepted: at most {max_length}")
    return value


def choice(value, field: str, choices, *, expected: str | None = None) -> str:
    """One of the strings ``choices`` (``expected`` replaces the wording ``one of 'a', 'b'``).

    Parameters
    ----------
    value : object
        The parsed JSON value.
    field : str
        The field's name, for the refusal.
    choices : collection of str
        The accepted strings.
    expected : str, optional
        The wording of the refusal (keyword only); default None.

    Returns
    -------
    str
        The value.

    Raises
    ------
    ValueError
        When ``value`` is not one of ``choices``, naming ``field``.
    """
    if not isinstance(value, str) or value not in choices:
        raise bad(field, expected or "one of " + ", ".join(repr(c) for c in choices), value)
    return value


def boolean(value, field: str) -> bool:
    """A JSON ``true`` or ``false``.

    Parameters
    ----------
    value : object
        The parsed JSON value.
    field : str
        The field's name, for the refusal.

    Returns
    -------
    bool
        The value.

    Raises
    ------
    ValueError
        When ``value`` is not a bool, naming ``field``.
    """
    if not isinstance(value, bool):
        raise bad(field, "true or false", value)
    return value


def array(value, field: str, what: str, length: int | None = None) -> list:
    """A JSON array (of ``what``), of exactly ``length`` items when given.

    Parameters
    ----------
    value : object
        The parsed JSON value.
    field : str
        The field's name, for the refusal.
    what : str
        What the items are, for the refusal (e.g. ``"numbers"``).
    length : int, optional
        The exact number of items; default None (any).

    Returns
    -------
    list
        The value (items unchecked).

    Raises
    ------
    ValueError
        When ``value`` is not a list (of ``length`` items), naming ``field``.
    """
    if not isinstance(value, list) or (length is not None and len(value) != length):
        raise bad(field, f"an array of {what}", value)
    return value


def check_object(d, field: str, allowed, optional=(), *, what: str = "coefficient table") -> None:
    """Refuse a JSON value ``d`` that is not an object, or has unknown or missing keys.

    ``field`` prefixes the keys (``fixed_point.method``); the top level has
    ``field == ""`` and is called ``what`` when it is not an object.

    Parameters
    ----------
    d : object
        The parsed JSON value.
    field : str
        The dotted name of the object (``""`` at the top level).
    allowed : collection of str
        Every key accepted.
    optional : collection of str, optional
        The keys of ``allowed`` that may be missing; default ``()``.
    what : str, optional
        The name of the top-level object (keyword only); default
        ``"coefficient table"``.

    Raises
    ------
    ValueError
        When ``d`` is not a dict, has a key not in ``allowed`` (the first one,
        sorted) or lacks a required key.
    """
    if not isinstance(d, dict):
        raise bad(field or what, "a JSON object", d)
    prefix = f"{field}." if field else ""
    unknown = sorted(k for k in d if k not in allowed)
    if unknown:
        raise ValueError(f"{prefix}{str(unknown[0])[:60]}: unknown field; accepted: "
                         f"{', '.join(sorted(allowed))}")
    for key in sorted(allowed):
        if key not in d and key not in optional:
            raise ValueError(f"{prefix}{key}: missing (a required field)")


def provenance(value, field: str = "provenance") -> dict[str, str]:
    """The ``provenance`` object: at most :data:`MAX_PROVENANCE` entries, non-empty
    keys of at most :data:`MAX_KEY` characters, values of at most :data:`MAX_TEXT`.

    Parameters
    ----------
    value : object
        The parsed JSON value.
    field : str, optional
        The field's name, default ``"provenance"``.

    Returns
    -------
    dict of str to str
        A copy of the object.

    Raises
    ------
    ValueError
        When ``value`` is not an object of strings, has more than
        :data:`MAX_PROVENANCE` entries, an empty or too long key, or a value
        longer than :data:`MAX_TEXT`.
    """
    if not isinstance(value, dict):
        raise bad(field, "an object of strings", value)
    if len(value) > MAX_PROVENANCE:
        raise ValueError(f"{field}: {len(value)} entries; accepted: at most {MAX_PROVENANCE}")
    for key, entry in value.items():
        text(key, f"{field} key {key[:60]!r}", MAX_KEY)
        text(entry, f"{field}.{key}", empty=True)
    return dict(value)


class _Duplicate(Exception):
    def __init__(self, key):
        super().__init__(key)
        self.key = key


def parse_json(source, what: str):
    """``json.loads`` of a table's text; refuses what is not JSON, and an object
    that gives a key twice (naming the key). ``what`` names the table in a refusal.

    Parameters
    ----------
    source : str or bytes
        The JSON text.
    what : str
        The table's description, e.g. ``"coefficient table"``.

    Returns
    -------
    object
        The parsed value (NaN and Infinity are read, for the field readers to
        refuse).

    Raises
    ------
    ValueError
        When ``source`` is not valid JSON (also too deeply nested) or an object
        gives a key twice.

    Examples
    --------
    >>> parse_json('{"a": 1, "a": 2}', "coefficient table")
    Traceback (most recent call last):
    ...
    ValueError: coefficient table is not valid JSON: key 'a' appears twice in one object; accepted: each key once
    """
    def pairs(items):
        out = {}
        for key, value in items:
            if key in out:
                raise _Duplicate(key)
            out[key] = value
        return out

    try:  # NaN and Infinity are read, for the field's check to refuse naming the field
        return json.loads(source, object_pairs_hook=pairs)
    except _Duplicate as exc:
        raise ValueError(f"{what} is not valid JSON: key {str(exc.key)[:60]!r} appears twice "
                         f"in one object; accepted: each key once") from None
    except (ValueError, RecursionError) as exc:  # JSONDecodeError, huge integers, deep nesting
        raise ValueError(f"{what} is not valid JSON: "
                         f"{' '.join(str(exc).split()) or type(exc).__name__}") from None
