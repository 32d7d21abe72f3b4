"""The table contract: what every kind of chebnorm table is and does.

chebnorm writes two kinds of table file: a :class:`chebnorm.approx.CoefficientTable`
(one polynomial on an interval) and a :class:`chebnorm.approx.PiecewiseTable`
(one polynomial per segment, integer coefficients). Both are frozen dataclasses
deriving from :class:`Table`, so a consumer can hold either:

* construction checks every field and re-proves every stated bound (a file, a
  hand-built table, ``dataclasses.replace``); :meth:`Table.verify` re-proves a
  table whose fields changed since;
* :meth:`Table.to_json` / :meth:`Table.from_json` / :meth:`Table.load` /
  :meth:`Table.save` read and write the file (the JSON bytes are part of the
  contract: keys sorted, floats in Python's shortest round-trip form);
* :attr:`Table.bounds` gives the certified error bounds of the whole table,
  :meth:`Table.plot` draws the error against them, and Jupyter shows a table
  (``_repr_html_``, ``_repr_markdown_``).

:func:`chebnorm.approx.load_table` reads a file of either kind. This module
also holds how tables are constructed (:func:`construction`: checked and
proved, or trusted from the fitter that just certified them) and how a verified
table is remembered (:func:`sealed`).
"""

from __future__ import annotations

import abc
import contextlib
import contextvars
import dataclasses
import functools
import json
import math
import weakref
from typing import Any, ClassVar, NamedTuple

import numpy as np

from .schema import parse_json, show

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []


class ErrorBounds(NamedTuple):
    """The certified error bounds of a whole table.

    Attributes
    ----------
    abs : float
        A rigorous upper bound of ``sup |p - f|`` over the table's interval.
    rel : float or None
        A rigorous upper bound of ``sup |p/f - 1|``, or None when the table
        certifies no relative error.
    """

    abs: float
    rel: float | None


class Table(abc.ABC):
    """A table of polynomial coefficients with certified error bounds (either kind).

    Every table has the attributes below; each kind adds its own (see
    :class:`chebnorm.approx.CoefficientTable` and
    :class:`chebnorm.approx.PiecewiseTable`).

    Attributes
    ----------
    name : str
        An identifier (``[A-Za-z_][A-Za-z0-9_]*``), used to name generated code.
    expression : str
        The approximated function ``f`` (sympy syntax).
    variable : str
        Its variable.
    interval : tuple of str
        The exact endpoints ``(lo, hi)`` as sympy strings.
    degree : int
        The polynomial degree (of every segment, for a piecewise table).
    error_kind : str
        ``"abs"`` or ``"rel"``: the error the fit minimized.
    abs_error_bound : float
        A rigorous upper bound of ``sup |p - f|`` over the interval.
    rel_error_bound : float or None
        A rigorous upper bound of ``sup |p/f - 1|``, or None.
    provenance : dict of str to str
        Where the table came from (command, library versions).

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> t = fit("1/sqrt(x)", ("1", "4"), 2)
    >>> isinstance(t, Table), t.bounds.abs == t.abs_error_bound
    (True, True)
    """

    #: what a refusal calls this kind of table ("coefficient table")
    WHAT: ClassVar[str]
    #: the largest file :meth:`load` reads
    MAX_BYTES: ClassVar[int]
    #: what a refusal of a file larger than :attr:`MAX_BYTES` suggests ("" for nothing)
    TOO_LARGE_HINT: ClassVar[str] = ""
    #: the indentation of the JSON text
    JSON_INDENT: ClassVar[int]

    # -- what each kind provides ------------------------------------------------
    @classmethod
    @abc.abstractmethod
    def _file_fields(cls, d) -> dict[str, Any]:
        """The constructor's keyword arguments from the file's JSON object ``d``,
        every field checked (a refusal names it), no bound re-proved."""

    @classmethod
    def _own_fields(cls, d) -> dict[str, Any]:
        """:meth:`_file_fields` of a constructed table's own fields (``d`` is
        :func:`dataclasses.asdict`-like: what a file holds besides them is added here)."""
        return cls._file_fields(d)

    @abc.abstractmethod
    def _prove_claims(self) -> None:
        """Re-certify every stated bound and located maximum, or raise naming the field."""

    @abc.abstractmethod
    def to_dict(self) -> dict[str, Any]:
        """The JSON object of the file."""

    @abc.abstractmethod
    def _display_rows(self) -> list[tuple[str, str]]:
        """(label, plain text) pairs shown by the HTML and Markdown reprs."""

    @abc.abstractmethod
    def plot(self, ax=None, error: str = "abs", points: int = 801):
        """Plot the error against its certified bound; return the matplotlib Axes."""

    # -- construction and verification -------------------------------------------
    def __post_init__(self) -> None:
        """Check every field and re-prove every claim (see :meth:`verify`): a table
        built by hand or by ``dataclasses.replace`` is verified as a file is."""
        establish(self, _own_fields, _prove_claims)

    def verify(self):
        """Re-prove every claim of the table; return it unchanged, or raise ValueError.

        Every table is verified when it is constructed: this call costs a
        comparison when nothing changed since, and re-proves the table
        otherwise (fields set behind the frozen dataclass's back, an
        unpickled object).
        """
        if not sealed(self):
            establish(self, _own_fields, _prove_claims, mode="prove")
        return self

    @property
    def bounds(self) -> ErrorBounds:
        """The certified bounds of the whole table: ``(abs, rel)`` (``rel`` may be None)."""
        return ErrorBounds(self.abs_error_bound, self.rel_error_bound)

    @property
    def error_bound(self) -> float:
        """The certified bound of ``sup |p - f|`` for the coefficients the table
        delivers (a quantized :class:`~chebnorm.approx.CoefficientTable`: its
        quantized coefficients'; otherwise ``abs_error_bound``)."""
        return self.abs_error_bound

    # -- files ----------------------------------------------------------------------
    def to_json(self) -> str:
        """The JSON text: keys sorted, strict JSON (no ``NaN``/``Infinity``)."""
        return json.dumps(self.to_dict(), sort_keys=True, indent=self.JSON_INDENT,
                          allow_nan=False) + "\n"

    def save(self, path) -> None:
        """Write the JSON atomically (temporary file, then rename)."""
        from chebnorm.core.files import write_atomic

        write_atomic(path, self.to_json())

    @classmethod
    def from_dict(cls, d: Any):
        """Read a table from its JSON object: every field checked (a refusal names
        the field), then every stated bound re-proved (see :meth:`verify`)."""
        return cls(**cls._file_fields(d))

    @classmethod
    def from_json(cls, text: str):
        """Parse JSON text and read it with :meth:`from_dict` (so: verified).
        A key given twice in one object is refused, naming the key."""
        return cls.from_dict(parse_json(text, cls.WHAT))

    @classmethod
    def load(cls, path):
        """Read and verify the table in file ``path`` (at most :attr:`MAX_BYTES`).

        A refusal starts with the kind of table and the file name, and names the field.
        """
        try:
            with open(path, "rb") as fh:
                raw = fh.read(cls.MAX_BYTES + 1)
        except OSError as exc:
            raise ValueError(f"cannot read {cls.WHAT} {str(path)!r}: {exc.strerror}") from None
        return cls.from_bytes(raw, path)

    @classmethod
    def from_bytes(cls, raw: bytes, path):
        """Read and verify a table from the bytes ``raw`` of the file ``path`` (as
        :meth:`load` does once it has read them): refusals name ``path``."""
        if len(raw) > cls.MAX_BYTES:
            raise ValueError(f"{cls.WHAT} {str(path)!r} is larger than {cls.MAX_BYTES} "
                             f"bytes{cls.TOO_LARGE_HINT}")
        try:
            return cls.from_json(raw.decode("utf-8"))
        except UnicodeDecodeError as exc:
            raise ValueError(f"{cls.WHAT} {str(path)!r} is not UTF-8 text (byte "
                             f"{exc.start})") from None
        except ValueError as exc:
            raise ValueError(f"{cls.WHAT} {str(path)!r}: {exc}") from None

    # -- display (Jupyter) ----------------------------------------------------------
    def _repr_html_(self) -> str:
        """An HTML table of the fit for Jupyter; every field is HTML-escaped
        (tables may come from untrusted files).

        >>> from chebnorm.approx import CoefficientTable
        >>> t = CoefficientTable(name="sq", expression="x**2", variable="x",
        ...     interval=("0", "1"), interval_float=(0.0, 1.0), degree=2,
        ...     kind="chebyshev", error_kind="abs", coefficients=(0.0, 0.0, 1.0),
        ...     abs_error_bound=0.0, rel_error_bound=None, max_abs_error=0.0,
        ...     max_abs_at=0.0, max_rel_error=None, max_rel_at=None,
        ...     provenance={"command": "<script>"})
        >>> "&lt;script&gt;" in t._repr_html_() and "<script>" not in t._repr_html_()
        True
        """
        from html import escape

        body = "".join(f"<tr><th style='text-align:left'>{escape(k)}</th>"
                       f"<td style='text-align:left'>{escape(v)}</td></tr>"
                       for k, v in self._display_rows())
        return (f"<table><caption style='text-align:left'><b>{type(self).__name__} "
                f"{escape(self.name)}</b></caption>{body}</table>")

    def _repr_markdown_(self) -> str:
        """A Markdown table of the fit; user text is escaped for Markdown and HTML.

        >>> from chebnorm.approx import CoefficientTable
        >>> t = CoefficientTable(name="sq", expression="x**2", variable="x",
        ...     interval=("0", "1"), interval_float=(0.0, 1.0), degree=2,
        ...     kind="chebyshev", error_kind="abs", coefficients=(0.0, 0.0, 1.0),
        ...     abs_error_bound=0.0, rel_error_bound=None, max_abs_error=0.0,
        ...     max_abs_at=0.0, max_rel_error=None, max_rel_at=None,
        ...     provenance={"command": "a|b"})
        >>> print(t._repr_markdown_().splitlines()[-1])
        | provenance | command: a\\|b |
        """
        lines = [f"**{type(self).__name__} {_markdown_escape(self.name)}**", "", "| | |",
                 "|---|---|"]
        lines += [f"| {_markdown_escape(k)} | {_markdown_escape(v)} |"
                  for k, v in self._display_rows()]
        return "\n".join(lines) + "\n"


def _own_fields(cls, d) -> dict[str, Any]:
    return cls._own_fields(d)


def _prove_claims(t) -> None:
    t._prove_claims()


_MARKDOWN_SPECIAL = "\\`*_[]|~"


def _markdown_escape(value: str) -> str:
    """Backslash-escape Markdown's inline punctuation (a table cell is
    inline), so user text is shown, not interpreted (``<`` and ``&`` also become HTML entities)."""
    out = []
    for ch in str(value):
        if ch == "&":
            out.append("&amp;")
        elif ch == "<":
            out.append("&lt;")
        elif ch == ">":
            out.append("&gt;")
        elif ch in _MARKDOWN_SPECIAL:
            out.append("\\" + ch)
        elif ch in "\r\n":
            out.append(" ")
        else:
            out.append(ch)
    return "".join(out)


# -- construction: every table checked, every claim proved, once ----------------

#: how a table being constructed is checked: ``"prove"`` (the default: every
#: field checked, every claim re-proved), ``"fitted"`` (the fitter's own
#: tables, whose bounds it has just certified: every field checked, nothing
#: proved twice) or ``"unchecked"`` (nothing: for tests of the consumers' own
#: defenses only; such a table is not sealed, so a consumer that verifies
#: re-proves it). Module-private; set only through :func:`construction`.
_MODE: contextvars.ContextVar[str] = contextvars.ContextVar("chebnorm_table_mode",
                                                            default="prove")


@contextlib.contextmanager
def construction(mode: str):
    """Construct tables in ``mode`` inside the block.

    Parameters
    ----------
    mode : {"prove", "fitted", "unchecked"}
        ``"prove"`` (the default outside any block): every field checked, every
        claim re-proved. ``"fitted"``: for a fitter's own tables, whose bounds it
        has just certified: every field checked, nothing proved twice.
        ``"unchecked"``: nothing checked, for tests of the consumers' own
        defenses only (such a table is not sealed, so :meth:`Table.verify`
        re-proves it).

    Yields
    ------
    None
        The block runs with table construction in ``mode``; the previous mode
        is restored on exit, also on an exception.

    Raises
    ------
    ValueError
        When ``mode`` is not one of the three.

    Examples
    --------
    >>> from chebnorm.approx import CoefficientTable
    >>> with construction("unchecked"):
    ...     t = CoefficientTable(name="bad", expression="x", variable="x",
    ...         interval=("0", "1"), interval_float=(0.0, 1.0), degree=0, kind="chebyshev",
    ...         error_kind="abs", coefficients=(0.0,), abs_error_bound=0.0,
    ...         rel_error_bound=None, max_abs_error=0.0, max_abs_at=0.0,
    ...         max_rel_error=None, max_rel_at=None)
    >>> t.verify()
    Traceback (most recent call last):
    ...
    ValueError: abs_error_bound: stated 0.00e+00 but the coefficients' certified error is 1.00e+00; |p - f| reaches 1.00e+00 at x = 1.0
    """
    if mode not in ("prove", "fitted", "unchecked"):
        raise ValueError(f"mode {mode!r}")
    token = _MODE.set(mode)
    try:
        yield
    finally:
        _MODE.reset(token)


#: id(table) -> (weak reference, :func:`_fingerprint` of the fields that were verified)
_SEALS: dict[int, tuple[weakref.ref, str]] = {}


def _fingerprint(t) -> str:
    """Every field of ``t`` (nested ones included) as compact JSON text, keys
    sorted: two tables whose files would differ have different fingerprints
    (it holds everything :meth:`Table.to_dict` writes, and the fields it
    leaves out when they are None). Written by the C encoder: cheaper than
    the file's indented text, which only the file needs."""
    return json.dumps(_plain(t), sort_keys=True, separators=(",", ":"), allow_nan=True)


def _seal(t) -> None:
    """Record that ``t``'s present fields were verified."""
    key = id(t)

    def forget(ref, key=key):
        if _SEALS.get(key, (None,))[0] is ref:
            del _SEALS[key]

    _SEALS[key] = (weakref.ref(t, forget), _fingerprint(t))


def sealed(t) -> bool:
    """True when the table ``t`` was verified and none of its fields (nested ones
    included) changed since.

    Parameters
    ----------
    t : Table
        A table (a :class:`~chebnorm.approx.CoefficientTable` or
        :class:`~chebnorm.approx.PiecewiseTable`), or any object.

    Returns
    -------
    bool
        True only when ``t`` was verified (constructed in ``"prove"`` or
        ``"fitted"`` mode) and its fields are unchanged since; False for
        anything else, including an object whose fields cannot be written as JSON.
    """
    entry = _SEALS.get(id(t))
    if entry is None or entry[0]() is not t:
        return False
    try:
        return entry[1] == _fingerprint(t)
    except (TypeError, ValueError, AttributeError, RecursionError):
        return False


#: the types :func:`_plain` returns as they are (exact types: a subclass such as
#: numpy's float64 takes the general path)
_PLAIN_SCALARS = frozenset({float, int, str, bool, type(None)})


@functools.lru_cache(maxsize=None)
def _field_names(cls) -> tuple[str, ...]:
    """The field names of the dataclass ``cls``, in order (fixed once it is defined)."""
    return tuple(f.name for f in dataclasses.fields(cls))


def _plain(value):
    """A value as JSON would hold it: tuples, numpy arrays and dataclasses as
    lists and objects, numpy scalars as Python numbers; anything else as it is
    (for the reader to refuse, naming the field)."""
    if type(value) in _PLAIN_SCALARS:
        return value
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {name: _plain(getattr(value, name, None)) for name in _field_names(type(value))}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _first_non_finite(value, path: str = ""):
    """``(path, value)`` of the first float in ``value`` (provenance aside) that is
    inf or nan, or None."""
    if isinstance(value, float):
        return None if math.isfinite(value) else (path, value)
    if isinstance(value, dict):
        items = [(f"{path}.{k}" if path else str(k), v) for k, v in value.items()
                 if k != "provenance"]
    elif isinstance(value, list):
        items = [(f"{path}[{k}]", v) for k, v in enumerate(value)]
    else:
        return None
    for where, v in items:
        hit = _first_non_finite(v, where)
        if hit is not None:
            return hit
    return None


def establish(t, read_fields, prove, mode: str | None = None) -> None:
    """Check table ``t``'s fields and re-prove its claims, then seal it.

    Parameters
    ----------
    t : Table
        A table being constructed (or verified again).
    read_fields : callable
        ``read_fields(type(t), d)`` -> the checked, normalized fields (tuples,
        floats) from ``d``, ``t``'s fields as JSON would hold them.
    prove : callable
        ``prove(t)`` re-certifies every claim or raises ValueError.
    mode : str, optional
        As :func:`construction` (default: the mode of the enclosing block).
    """
    mode = mode or _MODE.get()
    if mode == "unchecked":
        return
    d = _plain(t)
    if mode == "fitted":
        bad = _first_non_finite(d)
        if bad is not None:
            lo, hi = (show(str(v)).strip("'") for v in t.interval)
            raise ValueError(f"{bad[0]}: the certified value is {bad[1]!r} for "
                             f"{show(str(t.expression)).strip(chr(39))} on [{lo}, {hi}], "
                             f"beyond the float64 range; accepted: a "
                             f"function, interval and degree whose error and coefficients "
                             f"stay finite (below 1.8e308)")
    fields = read_fields(type(t), d)
    for name, value in fields.items():
        object.__setattr__(t, name, value)
    if mode == "prove":
        prove(t)
    _seal(t)
