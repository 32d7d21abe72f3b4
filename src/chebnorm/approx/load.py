"""Reading a table file of either kind: :func:`load_table` and :func:`table_from_json`.

A file holds a :class:`~chebnorm.approx.CoefficientTable` (a JSON object with
``schema_version``) or a :class:`~chebnorm.approx.PiecewiseTable` (a JSON object
with ``"kind": "chebnorm.piecewise_table"``); these read it as what it declares
and verify it (every field checked, every bound re-proved). A consumer then
dispatches on ``isinstance``.

>>> from chebnorm.approx import fit
>>> t = fit("exp(x)", ("0", "1"), 2)
>>> table_from_json(t.to_json()) == t
True
"""

from __future__ import annotations

import json

from .contract import Table
from .piecewise_table import PiecewiseTable
from .schema import MAX_PIECEWISE_BYTES, PIECEWISE_KIND, SCHEMA_VERSION, parse_json, show
from .table import CoefficientTable

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

#: the kinds of table, by the class that reads them
_ACCEPTED = (f"a coefficient table (a JSON object with schema_version {SCHEMA_VERSION}) or a "
             f"piecewise table (a JSON object with kind {PIECEWISE_KIND!r})")


def table_kind(value) -> type[Table] | None:
    """The class that reads the parsed JSON ``value``, or None when it declares neither kind.

    A JSON object with ``kind`` = :data:`~chebnorm.approx.schema.PIECEWISE_KIND`
    is a piecewise table; else one with ``schema_version`` a coefficient table
    (whatever the version and its own ``kind``, the fit's: the reader refuses
    what it does not support, naming the field).

    Parameters
    ----------
    value : object
        A parsed JSON value (any type; only a dict can name a kind).

    Returns
    -------
    type or None
        :class:`~chebnorm.approx.PiecewiseTable`,
        :class:`~chebnorm.approx.CoefficientTable`, or None.

    Examples
    --------
    >>> table_kind({"kind": "chebnorm.piecewise_table"}).__name__
    'PiecewiseTable'
    >>> table_kind({"schema_version": 1, "kind": "minimax"}).__name__
    'CoefficientTable'
    >>> table_kind([1, 2]) is None, table_kind({"kind": "minimax"}) is None
    (True, True)
    """
    if not isinstance(value, dict):
        return None
    if value.get("kind") == PIECEWISE_KIND:
        return PiecewiseTable
    return CoefficientTable if "schema_version" in value else None


def _neither(value) -> str:
    """Why ``value`` is neither kind of table."""
    if not isinstance(value, dict):
        return f"expected a JSON object, got {show(value)}"
    if "kind" in value:
        return f"kind {show(value['kind'])} is not a chebnorm table kind"
    return "a JSON object with neither schema_version nor kind"


def table_from_json(text: str) -> Table:
    """Read the JSON text of a table of either kind, as what it declares, and verify it.

    Parameters
    ----------
    text : str
        The JSON text of a :class:`~chebnorm.approx.CoefficientTable` or a
        :class:`~chebnorm.approx.PiecewiseTable`.

    Returns
    -------
    CoefficientTable or PiecewiseTable

    Raises
    ------
    ValueError
        Not JSON, neither kind of table, or a table that does not verify (the
        message names the field).

    Examples
    --------
    >>> table_from_json('{"kind": "other"}')
    Traceback (most recent call last):
    ...
    ValueError: not a chebnorm table: kind 'other' is not a chebnorm table kind; accepted: a coefficient table (a JSON object with schema_version 1) or a piecewise table (a JSON object with kind 'chebnorm.piecewise_table')
    """
    value = parse_json(text, "table")
    cls = table_kind(value)
    if cls is None:
        raise ValueError(f"not a chebnorm table: {_neither(value)}; accepted: {_ACCEPTED}")
    return cls.from_dict(value)


def load_table(path) -> Table:
    """Read and verify the table in file ``path``, a coefficient or a piecewise table.

    The file is read once; what it declares picks the reader (see
    :func:`table_kind`), whose refusals start with the kind of table and the
    file name and name the field. A file that cannot be read, is not UTF-8 or
    not JSON is refused as a coefficient table would be (the kind a table
    without a declared kind is read as).

    Parameters
    ----------
    path : str or os.PathLike
        A file written by :meth:`~chebnorm.approx.contract.Table.save` (or ``chebnorm fit``).

    Returns
    -------
    CoefficientTable or PiecewiseTable

    Raises
    ------
    ValueError
        Naming ``path``: unreadable, too large, not a table of either kind, or a
        table that does not verify.

    Examples
    --------
    >>> import os, tempfile
    >>> from chebnorm.approx import fit
    >>> folder = tempfile.mkdtemp()
    >>> p = os.path.join(folder, "t.json")
    >>> fit("exp(x)", ("0", "1"), 2).save(p)
    >>> type(load_table(p)).__name__
    'CoefficientTable'
    >>> with open(p, "w") as fh:
    ...     _ = fh.write('{"name": "x"}')
    >>> load_table(p)
    Traceback (most recent call last):
    ...
    ValueError: '...t.json' is not a chebnorm table: a JSON object with neither schema_version nor kind; accepted: ...
    """
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_PIECEWISE_BYTES + 1)
    except OSError as exc:
        raise ValueError(f"cannot read {CoefficientTable.WHAT} {str(path)!r}: "
                         f"{exc.strerror}") from None
    try:
        value = json.loads(raw.decode("utf-8"))
    except (ValueError, RecursionError):  # not UTF-8, not JSON: refused as a coefficient table
        return CoefficientTable.from_bytes(raw, path)
    cls = table_kind(value)
    if cls is None:
        raise ValueError(f"{str(path)!r} is not a chebnorm table: {_neither(value)}; "
                         f"accepted: {_ACCEPTED}")
    return cls.from_bytes(raw, path)
