"""Text that reaches generated code: one validation/escaping function per use.

Every string chebnorm writes into generated C, C++, Verilog, VHDL, GLSL, WGSL,
HLSL, Gappa or CSV comes from somewhere a user controls (a table file, a
command line, an output file name such as the proof file a header cites), so
it passes through exactly one of these functions first:

* :func:`identifier` -- a name that becomes part of a symbol (function,
  macro, module, entity, port). It must match ``[A-Za-z_][A-Za-z0-9_]*``;
  anything else is refused, never "fixed".
* :func:`comment_text` -- free text placed inside a comment of any of the
  target languages. The result is one line of printable ASCII that cannot
  close or open a block comment (``*/``, ``/*``: WGSL's block comments
  nest), cannot continue a line comment onto the next line (a trailing
  backslash, or the C trigraph ``??/``), and contains no line terminator,
  so it is inert in ``//``, ``/* */``, ``--`` and ``#`` comments alike.
* :func:`csv_cell` -- a text cell of a CSV file (RFC 4180 quoting, and no
  leading ``= + - @`` that a spreadsheet would run as a formula).

>>> identifier("dichotomy_d2")
'dichotomy_d2'
>>> comment_text("1/sqrt(x) */ int injected = 1; /*")
'1/sqrt(x) * / int injected = 1; / *'
>>> csv_cell('=cmd|" /C calc"!A0')
'"\\'=cmd|"" /C calc""!A0"'
"""

from __future__ import annotations

import hashlib
import re

#: the identifiers accepted in generated sources (a regular expression; at most 63 characters)
IDENTIFIER_PATTERN = r"[A-Za-z_][A-Za-z0-9_]*"
_IDENT = re.compile(IDENTIFIER_PATTERN + r"\Z")
_MAX_IDENT = 63  # C99 guarantees 63 significant characters in an internal identifier


def _words(text: str) -> list[str]:
    """The letters-and-digits runs of ``text``: ``-`` before a run is ``m``, a
    decimal point ``p``."""
    text = re.sub(r"(?<=\d)\.(?=\d)", "p", text)
    text = re.sub(r"-(?=[A-Za-z0-9])", "m", text)
    return re.findall(r"[A-Za-z0-9]+", text)


def default_name(expression: str, interval, degree: int, var: str = "x",
                 segments: int | None = None) -> str:
    """The name a table gets when none is given: its expression, interval and
    degree (and segment count) made an identifier, so the headers and HDL
    modules of different fits never collide in one build.

    ``1/f(...)`` reads ``rf``; a single call ``f(var)`` drops the variable;
    ``-`` reads ``m`` and a decimal point ``p``; a name over 63 characters is
    cut and ends in six hex digits of a hash of the whole text.

    Parameters
    ----------
    expression : str
        The function's text (``sympy.sstr`` of it).
    interval : (str, str)
        The endpoints' exact texts.
    degree : int
        The polynomial degree.
    var : str, optional
        The variable.
    segments : int, optional
        A piecewise table's segment count.

    Returns
    -------
    str
        An identifier (:func:`identifier` accepts it).

    Examples
    --------
    >>> default_name("1/sqrt(x)", ("1", "4"), 3), default_name("sin(x)", ("-pi/4", "pi/4"), 7)
    ('rsqrt_1_4_d3', 'sin_mpi_4_pi_4_d7')
    >>> default_name("exp(-x**2)", ("0", "1/2"), 4, segments=8)
    'exp_mx_2_0_1_2_d4_s8'
    """
    parts = _spec_words(expression, interval, var) + [f"d{degree}"]
    if segments is not None:
        parts.append(f"s{segments}")
    return _join(parts, _MAX_IDENT)


#: the longest default design name: its modules append ``_table``, ``_mp``, ``_core``
#: or ``_sized_dN`` (and a pipeline stage suffix) and must stay within 63 characters
_MAX_DESIGN = 44


def design_name(expression: str, interval, in_bits: int, out_bits: int, var: str = "x",
                tags=()) -> str:
    """The name a hardware design gets when none is given: its expression,
    interval, input and output widths (and ``tags``, e.g. the accuracy asked)
    made an identifier by the rule of :func:`default_name`, so the modules of
    different designs never collide in one synthesis run.

    The name is at most 44 characters (cut and ended by six hex digits of a
    hash of the whole text when longer), so the modules derived from it
    (``NAME_table``, ``NAME_sized_d3``, ...) are identifiers too. It never
    holds two underscores in a row nor starts or ends with one: a VHDL
    basic identifier as well as a Verilog and C one.

    Parameters
    ----------
    expression : str
        The function's text, as given.
    interval : (str, str)
        The endpoints' texts, as given.
    in_bits, out_bits : int
        The input and output code widths.
    var : str, optional
        The variable.
    tags : sequence of str, optional
        Further texts appended in order (their letters-and-digits runs).

    Returns
    -------
    str
        An identifier (:func:`identifier` accepts it).

    Examples
    --------
    >>> design_name("1/sqrt(x)", ("1", "4"), 8, 8, tags=("faithful",))
    'rsqrt_1_4_i8_o8_faithful'
    >>> design_name("log2(1+x)", ("0", "1"), 10, 12, tags=("e", "2^-10"))
    'log2_1_x_0_1_i10_o12_e_2_m10'
    """
    parts = _spec_words(expression, interval, var)
    parts += [f"i{in_bits}".replace("-", "m"), f"o{out_bits}".replace("-", "m")]
    for tag in tags:
        parts += _words(str(tag))
    return _join(parts, _MAX_DESIGN)


def _spec_words(expression, interval, var) -> list[str]:
    """The words naming a function on an interval: ``1/f(...)`` reads ``rf``,
    a single call ``f(var)`` drops the variable, then both endpoints."""
    text = str(expression).replace(" ", "")
    if text.startswith("1/") and re.match(r"[A-Za-z]", text[2:3]):
        text = "r" + text[2:]
    head = _words(text)
    if len(head) == 2 and head[1] == var and text == f"{head[0]}({var})":
        head = head[:1]
    return head + _words(str(interval[0])) + _words(str(interval[1]))


def _join(parts, limit: int) -> str:
    """``parts`` joined by ``_``, led by ``f`` unless a letter starts it, at most
    ``limit`` characters (a longer one cut, ending in a hash of the whole)."""
    name = "_".join(parts)
    if not re.match(r"[A-Za-z_]", name):
        name = "f" + name
    if len(name) > limit:
        digest = hashlib.sha256(name.encode()).hexdigest()[:6]
        name = name[:limit - 7].rstrip("_") + "_" + digest
    return identifier(name)


def identifier(name, *, field: str = "name") -> str:
    """Return ``name`` if it is a safe identifier in every target, else raise.

    Accepted: ``[A-Za-z_][A-Za-z0-9_]*``, at most 63 characters (C99's
    significant length).

    Parameters
    ----------
    name : str
        The identifier.
    field : str, optional
        What ``name`` is, for the message (``"table.name"``).

    Returns
    -------
    str
        ``name`` unchanged.

    Raises
    ------
    ValueError
        Naming ``field`` when ``name`` is not a safe identifier.

    Examples
    --------
    >>> identifier("rsqrt d2", field="table.name")
    Traceback (most recent call last):
    ...
    ValueError: table.name: 'rsqrt d2' is not an identifier: expected [A-Za-z_][A-Za-z0-9_]*, at most 63 characters
    """
    if not isinstance(name, str) or not _IDENT.match(name) or len(name) > _MAX_IDENT:
        shown = name if isinstance(name, str) else type(name).__name__
        raise ValueError(f"{field}: {shown!r:.80} is not an identifier: expected "
                         f"{IDENTIFIER_PATTERN}, at most {_MAX_IDENT} characters")
    return name


def comment_text(text, *, max_length: int = 400) -> str:
    """Make ``text`` inert inside a comment of C, Verilog, VHDL, GLSL, WGSL, HLSL or Gappa.

    Characters outside printable ASCII (line breaks included) become ``_``;
    backslashes become ``_`` (line continuation); ``*/`` and ``/*`` get a space
    between their characters, ``??`` too (trigraphs), repeatedly until none is
    left. Longer texts are cut to ``max_length`` characters and end in ``...``.

    Parameters
    ----------
    text : object
        The text (anything else is converted with ``str``).
    max_length : int, optional
        The longest result, ``...`` included.

    Returns
    -------
    str
        Printable ASCII that cannot end the comment or continue its line.

    Examples
    --------
    >>> comment_text("a */ b\\nc")
    'a * / b_c'
    """
    text = str(text)
    out = "".join(ch if " " <= ch <= "~" and ch != "\\" else "_" for ch in text)
    while True:
        fixed = out.replace("*/", "* /").replace("/*", "/ *").replace("??", "? ?")
        if fixed == out:
            break
        out = fixed
    if len(out) > max_length:
        out = out[: max_length - 3].rstrip() + "..."
        # cutting cannot create a pair: every pair was split above and '...' starts none
    return out


def csv_cell(text) -> str:
    """Quote ``text`` as one CSV cell (RFC 4180), neutralising spreadsheet formulas.

    A cell starting with ``=``, ``+``, ``-``, ``@``, tab or carriage return that
    is not a plain number gets a leading apostrophe (the OWASP advice for CSV
    injection); a cell holding a comma, quote or line break is quoted with
    doubled quotes.

    Parameters
    ----------
    text : object
        The cell's value (converted with ``str``).

    Returns
    -------
    str
        The cell as it appears between commas.

    Examples
    --------
    >>> csv_cell("=1+2"), csv_cell("-0.5"), csv_cell('say "hi", twice')
    ("'=1+2", '-0.5', '"say ""hi"", twice"')
    """
    text = str(text)
    if text[:1] in ("=", "+", "-", "@", "\t", "\r"):
        try:
            float(text)
        except ValueError:
            text = "'" + text
    if any(ch in text for ch in ',"\n\r'):
        text = '"' + text.replace('"', '""') + '"'
    return text
