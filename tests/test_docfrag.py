"""Shared docstring fragments (:mod:`chebnorm.core.docfrag`): the fragment text is in
``__doc__`` at import, indented as its placeholder; an unknown placeholder, or one that
shares its line, is an error when the module is imported, never a literal left in the
text; no docstring of the package keeps a placeholder."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
import sys
import textwrap

import pytest

import chebnorm
from chebnorm.core.docfrag import docstring, substitute
from chebnorm.hw._docfrag import HW_FRAGMENTS, hw_doc

BLOCK = 'version : str, default ""\n    The version.'


def test_fragment_text_is_in_the_docstring_indented_as_its_placeholder():
    @docstring(version=BLOCK)
    def f(version=""):
        """F.

        Parameters
        ----------
        %(version)s
        """

    # written by hand: the docstring as it would read with the block typed in place
    assert f.__doc__ == ('F.\n\n        Parameters\n        ----------\n'
                         '        version : str, default ""\n            The version.\n        ')


def test_methods_classes_and_several_fragments():
    doc = docstring(a="a : int\n    The a.", b="b : float\n    The b,\n    on two lines.")

    @doc
    class K:
        """K.

        Parameters
        ----------
        %(a)s
        %(b)s
        """

        @doc
        def m(self, a):
            """M.

            Parameters
            ----------
            %(a)s
            """

    assert "        a : int\n            The a.\n        b : float\n            The b,\n            on two lines." \
        in K.__doc__
    assert "            a : int\n                The a.\n" in K.m.__doc__
    assert "%(" not in K.__doc__ + K.m.__doc__


def test_unknown_placeholder_is_an_error_at_decoration():
    with pytest.raises(ValueError, match=r"unknown docstring fragment %\(verison\)s; known: version"):
        @docstring(version=BLOCK)
        def f():
            """F.

            %(verison)s
            """


def test_a_placeholder_inside_a_line_is_an_error():
    with pytest.raises(ValueError, match=r"%\(version\)s must stand alone on its line"):
        @docstring(version=BLOCK)
        def f():
            """F: %(version)s."""


def test_unknown_placeholder_fails_the_import(tmp_path, monkeypatch):
    """A module whose docstring names no fragment does not import (not a silent literal)."""
    (tmp_path / "docfrag_bad_mod.py").write_text(textwrap.dedent('''\
        from chebnorm.hw._docfrag import hw_doc

        @hw_doc
        def g(version=""):
            """G.

            Parameters
            ----------
            %(versoin)s
            """
        '''))
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(ValueError, match=r"docfrag_bad_mod\.g: unknown docstring fragment %\(versoin\)s"):
        importlib.import_module("docfrag_bad_mod")
    sys.modules.pop("docfrag_bad_mod", None)


def test_other_percent_signs_and_no_docstring_pass():
    assert substitute("50% of %d and %(x) and %s.", {}) == "50% of %d and %(x) and %s."

    def bare():
        pass

    assert docstring(version=BLOCK)(bare) is bare and bare.__doc__ is None


def test_fragments_must_be_text():
    with pytest.raises(TypeError, match="fragments: n must be str"):
        docstring(n=3)


def test_hw_fragment_reaches_a_printer_docstring():
    from chebnorm.hw import hdl
    from chebnorm.hw.hdl import verilog

    for fn in (hdl.module_text, hdl.banner_facts, verilog.verilog_module):
        assert textwrap.indent(HW_FRAGMENTS["version"], "    ") in fn.__doc__
        assert textwrap.indent(HW_FRAGMENTS["command"], "    ") in fn.__doc__
    assert hw_doc.fragments["command"].endswith("None or empty: no such line.")


def _docstrings():
    mods = ["chebnorm"] + [m.name for m in pkgutil.walk_packages(chebnorm.__path__, "chebnorm.")
                           if not m.name.endswith("__main__") and ".numba" not in m.name]
    for name in mods:
        mod = importlib.import_module(name)
        yield name, mod.__doc__
        for key, value in vars(mod).items():
            if (inspect.isfunction(value) or inspect.isclass(value)) and value.__module__ == name:
                yield f"{name}.{key}", value.__doc__
                if inspect.isclass(value):
                    for k, v in vars(value).items():
                        if inspect.isfunction(v):
                            yield f"{name}.{key}.{k}", v.__doc__


def test_no_docstring_keeps_a_placeholder():
    """Every ``%(name)s`` written in a docstring of the package was filled at import
    (a decorated function whose decorator was forgotten would show it)."""
    left = [where for where, doc in _docstrings() if doc and re.search(r"^\s*%\(\w+\)s\s*$", doc, re.M)]
    assert left == []
