"""Shared docstring fragments: a parameter block written once, placed in many docstrings.

A docstring holds a placeholder ``%(name)s`` alone on its line where a fragment
goes; the decorator that :func:`docstring` returns replaces it, when the module
is imported, by the fragment's text indented as the placeholder was. The
substituted text is in ``__doc__``, so ``help()``, Sphinx autodoc, numpydoc and
doctest read the full docstring. A placeholder naming no fragment, or one that
shares its line with other text, raises at import: it never stays in the text
as a literal. Other ``%`` signs in a docstring are left alone.

>>> doc = docstring(level="level : int\\n    How deep.")
>>> @doc
... def f(level):
...     '''Do it.
...
...     Parameters
...     ----------
...     %(level)s
...     '''
>>> print(f.__doc__.splitlines()[4])
    level : int
>>> print(f.__doc__.splitlines()[5])
        How deep.
"""

from __future__ import annotations

import re
import textwrap

# an implementation module of chebnorm.core: the API is what chebnorm.core exports
__all__: list[str] = []

#: ``%(name)s``: a fragment's placeholder (the name: letters, digits, underscores)
_PLACEHOLDER = re.compile(r"%\((\w+)\)s")
#: a placeholder alone on its line (leading and trailing blanks allowed)
_ALONE = re.compile(r"^([ \t]*)%\((\w+)\)s[ \t]*$", re.M)


def substitute(doc: str, fragments: dict[str, str], where: str = "docstring") -> str:
    """Put each fragment in place of its placeholder in ``doc``.

    Parameters
    ----------
    doc : str
        The docstring, as written (indented as in the source).
    fragments : dict of str to str
        Placeholder name -> the fragment's text: its first line unindented, the lines
        after it indented relative to the first (a numpydoc parameter block: the
        ``name : type`` line, then its description indented by four spaces).
    where : str, default "docstring"
        What ``doc`` documents, named in the error.

    Returns
    -------
    str
        ``doc`` with every line ``%(name)s`` replaced by ``fragments[name]``, each of
        its lines indented as the placeholder was.

    Raises
    ------
    ValueError
        If a placeholder names no fragment, or is not alone on its line.

    Examples
    --------
    >>> print(substitute("A.\\n  %(x)s\\n", {"x": "x : int\\n    The x."}))
    A.
      x : int
          The x.
    <BLANKLINE>
    """
    alone = {m.start(2) - 2 for m in _ALONE.finditer(doc)}  # where each lone ``%(`` starts
    for m in _PLACEHOLDER.finditer(doc):
        if m.group(1) not in fragments:
            raise ValueError(f"{where}: unknown docstring fragment %({m.group(1)})s; "
                             f"known: {', '.join(sorted(fragments)) or 'none'}")
        if m.start() not in alone:
            raise ValueError(f"{where}: docstring fragment %({m.group(1)})s must stand alone on its line")
    return _ALONE.sub(lambda m: textwrap.indent(fragments[m.group(2)], m.group(1)), doc)


def docstring(**fragments: str):
    """A decorator that fills the fragments' placeholders in a function's or class's docstring.

    Parameters
    ----------
    **fragments : str
        Placeholder name -> fragment text (as :func:`substitute` takes it). The texts
        are dedented and stripped of trailing blank lines first.

    Returns
    -------
    callable
        The decorator: it rewrites ``obj.__doc__`` (see :func:`substitute`) and returns
        ``obj`` itself. An object without docstring (``python -OO``) passes unchanged.

    Raises
    ------
    TypeError
        If a fragment is not a string.

    Examples
    --------
    >>> banner = docstring(version='version : str, default ""\\n    The version.')
    >>> @banner
    ... def g(version=""):
    ...     '''G.
    ...
    ...     Parameters
    ...     ----------
    ...     %(version)s
    ...     '''
    >>> "    version : str" in g.__doc__ and "%(" not in g.__doc__
    True
    """
    bad = [k for k, v in fragments.items() if not isinstance(v, str)]
    if bad:
        raise TypeError(f"fragments: {', '.join(bad)} must be str")
    texts = {k: textwrap.dedent(v).strip("\n") for k, v in fragments.items()}

    def fill(obj):
        if obj.__doc__:
            where = f"{getattr(obj, '__module__', '?')}.{getattr(obj, '__qualname__', obj)}"
            obj.__doc__ = substitute(obj.__doc__, texts, where)
        return obj

    fill.fragments = texts
    return fill
