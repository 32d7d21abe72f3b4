"""Stage 3: printers of a CoefficientTable, one per target format.

``FORMATS`` maps a format name to ``(printer, file suffix)``; a printer takes
the table and the generating command and returns text. Use
:func:`export_table` to print and write atomically.
"""

from __future__ import annotations

import sys
import types

from chebnorm.approx import CoefficientTable
from chebnorm.core.files import write_atomic

from .c import c_header, horner_rounding_bound
from .shader import float32_eval_bound, glsl_source, hlsl_source, shader_source, wgsl_source


def json_text(table: CoefficientTable, command: str = "") -> str:
    """The table's JSON contract (sorted keys, shortest float repr).

    >>> from chebnorm.approx import CoefficientTable, fit
    >>> t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 1, var="z")
    >>> CoefficientTable.from_json(json_text(t)) == t
    True
    """
    return table.to_json()


FORMATS = {"c": (c_header, ".h"), "json": (json_text, ".json"), "glsl": (glsl_source, ".glsl"),
           "wgsl": (wgsl_source, ".wgsl"), "hlsl": (hlsl_source, ".hlsl")}

__all__ = ["FORMATS", "c_header", "json_text", "export_text", "export_table",
           "horner_rounding_bound", "glsl_source", "wgsl_source", "hlsl_source", "shader_source",
           "float32_eval_bound"]


def export_text(table: CoefficientTable, fmt: str, command: str = "") -> str:
    """The text of ``table`` in format ``fmt`` (a key of :data:`FORMATS`).

    The package itself is callable with the same arguments, so
    ``chebnorm.export(table, "c")`` is ``export_text(table, "c")``.
    Dispatch is by the :data:`FORMATS` table: a new printer is one entry.

    >>> from chebnorm.approx import fit
    >>> t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 1, var="z", name="dich")
    >>> "static inline double chebnorm_dich(double" in export_text(t, "c")
    True
    >>> export_text(t, "json") == t.to_json()
    True
    >>> export_text(t, "pdf")
    Traceback (most recent call last):
    ...
    ValueError: unknown export format 'pdf'; accepted: c, ...json...
    """
    from chebnorm.approx.piecewise import PiecewiseTable

    if not isinstance(table, (CoefficientTable, PiecewiseTable)):
        raise ValueError(f"table of type {type(table).__name__} is not accepted; accepted: a "
                         f"CoefficientTable or PiecewiseTable (chebnorm.fit, or .load)")
    try:
        printer, _ = FORMATS[fmt]
    except (KeyError, TypeError):
        raise ValueError(f"unknown export format {fmt!r}; accepted: {', '.join(sorted(FORMATS))}") from None
    if isinstance(table, CoefficientTable):
        table.verify()  # a comparison, or a re-proof of fields changed since construction
    return printer(table, command)


def export_table(table: CoefficientTable, fmt: str, path, command: str = "") -> str:
    """Print ``table`` in format ``fmt`` and write it to ``path`` atomically.

    >>> import os, tempfile
    >>> from chebnorm.approx import fit
    >>> t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 1, var="z", name="dich")
    >>> with tempfile.TemporaryDirectory() as d:
    ...     text = export_table(t, "c", os.path.join(d, "dich.h"))
    ...     open(os.path.join(d, "dich.h")).read() == text
    True
    """
    text = export_text(table, fmt, command)
    write_atomic(path, text)
    return text


class _CallableModule(types.ModuleType):
    """``chebnorm.export`` is callable: ``chebnorm.export(table, "c")``."""

    def __call__(self, table: CoefficientTable, fmt: str, command: str = "") -> str:
        return export_text(table, fmt, command)


sys.modules[__name__].__class__ = _CallableModule
