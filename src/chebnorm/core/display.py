"""Short text reprs and HTML displays of result objects (Jupyter), written once.

A result class lists what it shows in ``_summary()`` (``(label, value)``
pairs: a few, for the one-line repr) and, optionally, ``_display_rows()``
(more, for the HTML table), then sets in its body::

    __repr__ = summary_repr
    _repr_html_ = summary_html

(a dataclass keeps a ``__repr__`` defined in its own body). Every value is
shortened (floats to 6 significant digits, arrays to their shape and dtype,
long sequences to their ends) and every text is HTML-escaped (results may hold
text from untrusted files).
"""

from __future__ import annotations

from dataclasses import fields
from html import escape

import numpy as np

# an implementation module of chebnorm.core: the API is what chebnorm.core exports
__all__: list[str] = []

#: the most characters one value takes in a repr
MAX_VALUE = 60


def short(value, limit: int = MAX_VALUE) -> str:
    """A short text of ``value`` for a repr.

    Parameters
    ----------
    value : object
        A number, text, array, sequence, mapping or anything with a repr.
    limit : int, optional
        The most characters returned.

    Returns
    -------
    str

    Examples
    --------
    >>> short(0.1234567891), short(np.zeros((3, 4))), short(tuple(range(20)))
    ('0.123457', 'array(shape=(3, 4), float64)', '(0, 1, 2, ..., 19) [20 items]')
    >>> short(None), short("x" * 100)[-4:]
    ('None', "...'")
    """
    if isinstance(value, (bool, np.bool_)) or value is None:
        text = repr(bool(value)) if value is not None else "None"
    elif isinstance(value, (float, np.floating)):
        text = f"{float(value):.6g}"
    elif isinstance(value, (int, np.integer)):
        text = str(int(value))
    elif isinstance(value, np.ndarray):
        text = f"array(shape={value.shape}, {value.dtype})"
    elif isinstance(value, (tuple, list)):
        items = [short(v, 16) for v in value]
        if len(items) > 6:
            items = items[:3] + ["..."] + items[-1:]
            text = "(" + ", ".join(items) + f") [{len(value)} items]"
        else:
            text = "(" + ", ".join(items) + ("," if len(items) == 1 else "") + ")"
    elif isinstance(value, dict):
        text = "{" + ", ".join(f"{k}: {short(v, 16)}" for k, v in list(value.items())[:4]) + \
            (", ...}" if len(value) > 4 else "}")
    elif isinstance(value, str):
        text = repr(value)
    else:
        text = repr(value)
    if len(text) > limit:
        keep = limit - 4
        text = text[:keep] + "...'" if text.startswith("'") else text[:limit - 3] + "..."
    return text


def summary_repr(self) -> str:
    """``Name(label=value, ...)`` from ``self._summary()`` (each value :func:`short`).

    Parameters
    ----------
    self : object
        A result with ``_summary()`` (``(label, value)`` pairs).

    Returns
    -------
    str

    Examples
    --------
    >>> class R:
    ...     def _summary(self):
    ...         return [("n", 3), ("bound", 1.23456789e-5)]
    >>> summary_repr(R())
    'R(n=3, bound=1.23457e-05)'
    """
    items = ", ".join(f"{k}={short(v)}" for k, v in self._summary())
    return f"{type(self).__name__}({items})"


def summary_html(self) -> str:
    """An HTML table of ``self._display_rows()`` (or ``self._summary()``), escaped.

    Parameters
    ----------
    self : object
        A result with ``_summary()`` and, optionally, ``_display_rows()``.

    Returns
    -------
    str

    Examples
    --------
    >>> class R:
    ...     def _summary(self):
    ...         return [("expression", "<b>")]
    >>> "&lt;b&gt;" in summary_html(R()) and "<b>R</b>" in summary_html(R())
    True
    """
    rows = self._display_rows() if hasattr(self, "_display_rows") else self._summary()
    body = "".join(f"<tr><th style='text-align:left'>{escape(str(k))}</th>"
                   f"<td style='text-align:left'>{escape(short(v, 400) if not isinstance(v, str) else v)}"
                   f"</td></tr>" for k, v in rows)
    return (f"<table><caption style='text-align:left'><b>{escape(type(self).__name__)}</b>"
            f"</caption>{body}</table>")


def field_rows(self, skip=()) -> list[tuple[str, object]]:
    """Every field of a dataclass as ``(name, value)`` rows, for an HTML table
    (``_display_rows``): the full record where the repr shows a few.

    Parameters
    ----------
    self : object
        A dataclass instance.
    skip : iterable of str, optional
        Fields left out (e.g. bulky ones already summarized).

    Returns
    -------
    list of (str, object)

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass
    ... class P:
    ...     a: int
    ...     b: str = "x"
    >>> field_rows(P(1)), field_rows(P(1), skip=("a",))
    ([('a', 1), ('b', 'x')], [('b', 'x')])
    """
    skip = set(skip)
    return [(f.name, getattr(self, f.name)) for f in fields(self) if f.name not in skip]
