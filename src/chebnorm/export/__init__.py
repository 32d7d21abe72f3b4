"""Stage 3: printers of a CoefficientTable, one per target format.

``FORMATS`` maps a format name to ``(printer, file suffix)``; a printer takes
the table and the generating command and returns text. Use
:func:`export_table` to print and write atomically.
"""

from __future__ import annotations

from chebnorm.approx import CoefficientTable
from chebnorm.approx.files import write_atomic

from .c import c_header, horner_rounding_bound
from .shader import float32_eval_bound, glsl_source, hlsl_source, shader_source, wgsl_source


def json_text(table: CoefficientTable, command: str = "") -> str:
    """The table's JSON contract (sorted keys, shortest float repr)."""
    return table.to_json()


FORMATS = {"c": (c_header, ".h"), "json": (json_text, ".json"), "glsl": (glsl_source, ".glsl"),
           "wgsl": (wgsl_source, ".wgsl"), "hlsl": (hlsl_source, ".hlsl")}

__all__ = ["FORMATS", "c_header", "json_text", "export_table", "horner_rounding_bound",
           "glsl_source", "wgsl_source", "hlsl_source", "shader_source", "float32_eval_bound"]


def export_table(table: CoefficientTable, fmt: str, path, command: str = "") -> str:
    """Print ``table`` in format ``fmt`` and write it to ``path`` atomically."""
    try:
        printer, _ = FORMATS[fmt]
    except KeyError:
        raise ValueError(f"unknown export format {fmt!r}; accepted: {', '.join(sorted(FORMATS))}") from None
    text = printer(table, command)
    write_atomic(path, text)
    return text
