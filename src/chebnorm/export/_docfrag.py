"""The parameter blocks that many docstrings of :mod:`chebnorm.export` share, written
once (:func:`chebnorm.core.docfrag.docstring`): a docstring holds ``%(name)s`` alone
on a line where the block goes, and its function is decorated with
:data:`export_doc`."""

from __future__ import annotations

from ..core.docfrag import docstring

# an implementation module of chebnorm.export: the API is what chebnorm.export exports
__all__: list[str] = []

#: placeholder name -> parameter block (``name : type`` line, description indented by four)
EXPORT_FRAGMENTS = {
    "command": '''\
command : str, optional
    The generating command, stated in the banner. Default ``""`` (none).''',
    "shader_table": '''\
table : CoefficientTable
    A table in powers of ``x`` or of a shifted ``t = (x - c)/s`` (``s`` a
    power of two); its name must be an identifier.''',
}

#: the decorator that fills :data:`EXPORT_FRAGMENTS` into a docstring
export_doc = docstring(**EXPORT_FRAGMENTS)
