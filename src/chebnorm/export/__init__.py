"""Stage 3: the one place that prints a table in an output format.

Every format ``chebnorm export`` offers is printed here, for both kinds of
table (:data:`EXPORT_FORMATS`, :func:`formats_for`):

* a :class:`~chebnorm.approx.CoefficientTable`: ``c``, ``json``, ``glsl``,
  ``wgsl``, ``hlsl`` (:data:`TABLE_FORMATS`: printers that need only the table) and
  ``verilog``, ``vhdl`` (:data:`HDL_FORMATS`: a fixed-point evaluator, sized
  by ``in_bits`` and ``out_bits``, printed by :mod:`chebnorm.hw.hdl`);
* a :class:`~chebnorm.approx.PiecewiseTable`: ``c``, ``json``,
  ``verilog``, ``vhdl`` (:data:`PIECEWISE_FORMATS`).

:func:`export_text` prints; :func:`export_table` prints and writes
atomically; the package itself is callable: ``chebnorm.export(table, fmt,
**options)`` is :func:`export_text`. The keyword options a format takes are
:func:`options_for`'s.
"""

from __future__ import annotations

import sys
import types

from chebnorm.approx import CoefficientTable
from chebnorm.approx.piecewise_table import PiecewiseTable
from chebnorm.core.files import refuse_inputs, write_all, write_atomic

from .c import c_header, horner_rounding_bound
from .c_piecewise import DEFAULT_C_IN_BITS, piecewise_c_header
from .shader import float32_eval_bound, glsl_source, hlsl_source, shader_source, wgsl_source
from ._docfrag import export_doc


def json_text(table, command: str = "") -> str:
    """The table's JSON contract (sorted keys, shortest float repr), of
    either kind of table.

    Parameters
    ----------
    table : CoefficientTable or PiecewiseTable
        The table.
    command : str, optional
        Not used: the contract records its own provenance (the parameter
        keeps every printer's ``printer(table, command)`` signature).
        Default ``""``.

    Returns
    -------
    str
        ``table.to_json()``: the JSON document ``load_table`` reads back.

    Examples
    --------
    >>> from chebnorm.approx import CoefficientTable, fit
    >>> t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 1, var="z")
    >>> CoefficientTable.from_json(json_text(t)) == t
    True
    """
    return table.to_json()


#: the printers that need only the table: format -> (printer(table, command), file suffix)
TABLE_FORMATS = {"c": (c_header, ".h"), "json": (json_text, ".json"), "glsl": (glsl_source, ".glsl"),
           "wgsl": (wgsl_source, ".wgsl"), "hlsl": (hlsl_source, ".hlsl")}
#: the fixed-point hardware formats (``in_bits`` and ``out_bits`` needed): format -> suffix
HDL_FORMATS = {"verilog": ".v", "vhdl": ".vhd"}
#: every format ``chebnorm export`` offers (for some kind of table): format -> file
#: suffix, sorted by format (``list(chebnorm.export.FORMATS)`` lists the seven)
FORMATS = {fmt: suffix for fmt, suffix in sorted(
    [(f, suffix) for f, (_, suffix) in TABLE_FORMATS.items()] + list(HDL_FORMATS.items()))}
#: the names of :data:`FORMATS`, a sorted tuple
EXPORT_FORMATS = tuple(FORMATS)
#: the formats of a piecewise table
PIECEWISE_FORMATS = ("c", "json", "verilog", "vhdl")
#: the keyword options of a Horner evaluator in an HDL
HDL_OPTIONS = ("in_bits", "out_bits", "coef_frac_bits", "acc_bits", "rounding")

__all__ = ["FORMATS", "TABLE_FORMATS", "HDL_FORMATS", "EXPORT_FORMATS", "PIECEWISE_FORMATS", "HDL_OPTIONS",
           "formats_for", "options_for", "c_header", "json_text", "export_text", "export_table",
           "hdl_export", "horner_rounding_bound", "glsl_source", "wgsl_source", "hlsl_source",
           "shader_source", "float32_eval_bound", "piecewise_c_header", "DEFAULT_C_IN_BITS",
           "export_with_proofs"]


def _kind(table) -> str:
    if isinstance(table, PiecewiseTable):
        return "piecewise table"
    if isinstance(table, CoefficientTable):
        return "coefficient table"
    raise ValueError(f"table of type {type(table).__name__} is not accepted; accepted: a "
                     f"CoefficientTable or PiecewiseTable (chebnorm.fit, or .load)")


def formats_for(table) -> tuple[str, ...]:
    """The formats ``table`` can be exported in (sorted).

    Parameters
    ----------
    table : CoefficientTable or PiecewiseTable
        The table.

    Returns
    -------
    tuple of str
        :data:`EXPORT_FORMATS` (all seven) for a coefficient table,
        :data:`PIECEWISE_FORMATS` for a piecewise one.

    Raises
    ------
    ValueError
        When ``table`` is neither a ``CoefficientTable`` nor a
        ``PiecewiseTable``.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> formats_for(fit("x**2", ("0", "1"), 1))
    ('c', 'glsl', 'hlsl', 'json', 'verilog', 'vhdl', 'wgsl')
    >>> formats_for(piecewise_fit("x**2", ("0", "1"), 1, segments=2))
    ('c', 'json', 'verilog', 'vhdl')
    """
    return PIECEWISE_FORMATS if _kind(table) == "piecewise table" else EXPORT_FORMATS


def options_for(table, fmt: str) -> tuple[str, ...]:
    """The keyword options :func:`export_text` takes for ``table`` in ``fmt``
    (``fmt`` one of :func:`formats_for`'s).

    Parameters
    ----------
    table : CoefficientTable or PiecewiseTable
        The table.
    fmt : str
        The format, one of ``formats_for(table)``.

    Returns
    -------
    tuple of str
        The option names, in their documented order (empty when the format
        takes none): :data:`HDL_OPTIONS` for a coefficient table in
        ``verilog``/``vhdl``, ``("in_bits", "out_bits")`` for a piecewise
        one there, ``("in_bits",)`` for a piecewise table's ``c``.

    Raises
    ------
    ValueError
        When ``table`` is of another type, ``fmt`` is not a known format, or
        the kind of table has no such format.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> options_for(fit("x**2", ("0", "1"), 1), "vhdl")
    ('in_bits', 'out_bits', 'coef_frac_bits', 'acc_bits', 'rounding')
    >>> pw = piecewise_fit("x**2", ("0", "1"), 1, segments=2)
    >>> options_for(pw, "c"), options_for(pw, "verilog"), options_for(pw, "json")
    (('in_bits',), ('in_bits', 'out_bits'), ())
    """
    _check_format(table, fmt)
    if fmt in HDL_FORMATS:
        return ("in_bits", "out_bits") if isinstance(table, PiecewiseTable) else HDL_OPTIONS
    return ("in_bits",) if isinstance(table, PiecewiseTable) and fmt == "c" else ()


def _check_format(table, fmt) -> str:
    kind = _kind(table)
    if not isinstance(fmt, str) or fmt not in EXPORT_FORMATS:
        raise ValueError(f"unknown export format {str(fmt)[:40]!r}; accepted: "
                         f"{', '.join(EXPORT_FORMATS)}")
    accepted = formats_for(table)
    if fmt not in accepted:
        raise ValueError(f"format {fmt!r} is not available for a {kind}; accepted: "
                         f"{', '.join(accepted)}")
    return fmt


def _check_width(value, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{name} = {str(value)[:40]!r} is not an integer; accepted: an int "
                         f"(a code width in bits)")
    return value


def hdl_export(table, language: str, command: str = "", *, in_bits: int, out_bits: int,
               coef_frac_bits: int | None = None, acc_bits: int | None = None,
               rounding: str | None = None) -> str:
    """The fixed-point evaluator of ``table`` in ``language`` (``"verilog"`` or
    ``"vhdl"``), as ``chebnorm export --format verilog|vhdl`` writes it.

    A :class:`~chebnorm.approx.CoefficientTable` becomes a Horner design
    (:func:`chebnorm.hw.report.analyze`: sized, checked over every input code,
    its error budget in the banner): the combinational module and, for degree
    >= 1, the pipelined one. A :class:`~chebnorm.approx.PiecewiseTable`
    becomes its ROM + Horner design (:func:`chebnorm.hw.piecewise.design_piecewise`;
    ``coef_frac_bits``, ``acc_bits`` and ``rounding`` do not apply to it).

    Parameters
    ----------
    table : CoefficientTable or PiecewiseTable
        The table (verified first when piecewise; analysed over every input
        code otherwise).
    language : {"verilog", "vhdl"}
        The HDL.
    command : str
        The command line stated in the banner.
    in_bits, out_bits : int
        Input and output code widths in bits (the accepted range is the
        hardware design's, checked by :func:`chebnorm.hw.report.analyze` or
        :func:`chebnorm.hw.piecewise.design_piecewise`).
    coef_frac_bits, acc_bits : int, optional
        Coefficient and accumulator fractional bits (default: the table's
        own; output's + 3). Coefficient tables only.
    rounding : {"rne", "trunc"}, optional
        After each multiply-add (default ``"rne"``). Coefficient tables only.

    Returns
    -------
    str
        The HDL text: the banner (with the error budget for a Horner
        design), the combinational module and, for degree >= 1, the
        pipelined one.

    Raises
    ------
    ValueError
        When ``language`` is not an HDL, ``in_bits``/``out_bits`` are not
        ints, ``coef_frac_bits``/``acc_bits``/``rounding`` are given with a
        piecewise table, ``table`` is of another type, or the design cannot
        be built at those widths.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> v = hdl_export(fit_target("dichotomy", 1), "vhdl", in_bits=8, out_bits=8, coef_frac_bits=12)
    >>> [line for line in v.splitlines() if line.startswith("entity")]
    ['entity chebnorm_dichotomy_d1 is', 'entity chebnorm_dichotomy_d1_pipe is']
    """
    from chebnorm import __version__
    from chebnorm.hw.hdl import check_language, hdl_text

    check_language(language)
    in_bits, out_bits = _check_width(in_bits, "in_bits"), _check_width(out_bits, "out_bits")
    if _kind(table) == "piecewise table":
        extra = [n for n, v in (("coef_frac_bits", coef_frac_bits), ("acc_bits", acc_bits),
                                ("rounding", rounding)) if v is not None]
        if extra:
            raise ValueError(f"{', '.join(extra)} does nothing with a piecewise table; accepted "
                             f"there: in_bits, out_bits")
        from chebnorm.hw.piecewise import design_piecewise

        table.verify()
        return hdl_text(design_piecewise(table, in_bits, out_bits), language,
                        version=__version__, command=command)
    from chebnorm.hw.report import analyze

    report = analyze(table, in_bits, out_bits, coef_frac_bits=coef_frac_bits, acc_bits=acc_bits,
                     rounding="rne" if rounding is None else rounding, gappa=False, synth=False)
    return hdl_text(report.design, language, version=__version__, command=command,
                    budget=report.budget)


@export_doc
def export_text(table, fmt: str, command: str = "", *, name: str | None = None,
                **options) -> str:
    """The text of ``table`` in format ``fmt``.

    The package itself is callable with the same arguments:
    ``chebnorm.export(table, "c")`` is ``export_text(table, "c")``.

    Parameters
    ----------
    table : CoefficientTable or PiecewiseTable
        The table (verified again if it changed since it was made).
    fmt : str
        One of :func:`formats_for` ``(table)``: ``"c"``, ``"json"``,
        ``"glsl"``, ``"wgsl"``, ``"hlsl"``, ``"verilog"``, ``"vhdl"``
        (:data:`FORMATS`).
    %(command)s
    name : str, optional
        The identifier of the generated function, macro or module (default:
        the table's own ``name``); ``[A-Za-z_][A-Za-z0-9_]*``.
    **options
        The format's keyword options (:func:`options_for`; a ``None`` value
        is not given): ``in_bits`` and ``out_bits`` (required) and
        ``coef_frac_bits``, ``acc_bits``, ``rounding`` for ``verilog`` and
        ``vhdl`` (:func:`hdl_export`); ``in_bits`` for a piecewise table's
        ``c`` (default :data:`DEFAULT_C_IN_BITS`).

    Returns
    -------
    str
        The text of the file.

    Raises
    ------
    ValueError
        For an unknown format, a format the kind of table lacks, an option
        the format does not take (naming the accepted ones), a missing
        ``in_bits``/``out_bits``, a ``name`` that is not an identifier.

    See Also
    --------
    chebnorm.export.export_table : the same text, written to a file.
    chebnorm.export.export_with_proofs : with a Gappa proof of each stated bound.
    chebnorm.export.verify.verify : compile the output and check it against the bound.
    chebnorm.hw.design_horner : the fixed-point datapath the HDL formats print.

    Notes
    -----
    The floating-point outputs (C, GLSL, WGSL, HLSL) state, beside the
    table's certified bound of :math:`|p - f|`, a bound ``EVAL_ERROR_BOUND`` of
    :math:`|\\mathrm{fl}(p(x)) - f(x)|` for the format's arithmetic: the
    certified bound plus the rounding of the Horner evaluation, bounded by
    interval arithmetic on pieces of the interval, every multiply-add fused or
    not (:mod:`chebnorm.export.evalbound`). Its a priori form is Higham's [1]_:
    for the unit roundoff :math:`u` and :math:`\\gamma_k = k u / (1 - k u)`,

    .. math::

        |\\mathrm{fl}(p(x)) - p(x)| \\le \\gamma_{2n} \\sum_{j=0}^{n} |c_j|\\,|x|^j.

    Gappa proves each stated bound independently (``export_with_proofs``
    [2]_). The HDL outputs print the bit-accurate
    fixed-point evaluator of :mod:`chebnorm.hw`, in the style of FloPoCo's
    generated operators [3]_.

    References
    ----------
    .. [1] N. J. Higham, *Accuracy and Stability of Numerical Algorithms*,
       2nd ed., SIAM, 2002, eq. (5.3).
    .. [2] G. Melquiond, Gappa, https://gappa.gitlabpages.inria.fr/ ;
       F. de Dinechin, C. Lauter, G. Melquiond, "Certifying the
       floating-point implementation of an elementary function using
       Gappa", IEEE Transactions on Computers 60(2), 2011.
    .. [3] F. de Dinechin, B. Pasca, "Designing custom arithmetic data paths
       with FloPoCo", IEEE Design & Test of Computers 28(4), 2011.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 1, var="z", name="dich")
    >>> "static inline double chebnorm_dich(double" in export_text(t, "c")
    True
    >>> "chebnorm_rs(" in export_text(t, "glsl", name="rs")
    True
    >>> export_text(t, "json") == t.to_json()
    True
    >>> export_text(t, "pdf")
    Traceback (most recent call last):
    ...
    ValueError: unknown export format 'pdf'; accepted: c, ...json...
    >>> export_text(t, "vhdl")
    Traceback (most recent call last):
    ...
    ValueError: format 'vhdl' needs in_bits and out_bits (input and output code widths); ...
    >>> export_text(t, "glsl", in_bits=8)
    Traceback (most recent call last):
    ...
    ValueError: in_bits does nothing with format 'glsl' of a coefficient table; accepted there: no option
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> pw = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, name="rs")
    >>> "static inline double chebnorm_rs(uint32_t k)" in export_text(pw, "c", in_bits=12)
    True
    """
    kind = _kind(table)
    accepted = options_for(table, fmt)
    given = {k: v for k, v in options.items() if v is not None}
    unknown = [k for k in given if k not in accepted]
    if unknown:
        raise ValueError(f"{', '.join(unknown)} does nothing with format {fmt!r} of a {kind}; "
                         f"accepted there: {', '.join(accepted) or 'no option'}")
    if name is not None and name != table.name:
        table = _renamed(table, name)
    if fmt in HDL_FORMATS:
        if "in_bits" not in given or "out_bits" not in given:
            raise ValueError(f"format {fmt!r} needs in_bits and out_bits (input and output code "
                             f"widths); accepted: ints, e.g. in_bits=12, out_bits=12")
        return hdl_export(table, fmt, command, **given)
    table.verify()  # a comparison, or a re-proof of fields changed since construction
    if kind == "piecewise table":
        if fmt == "c":
            return piecewise_c_header(table, command, in_bits=given.get("in_bits",
                                                                         DEFAULT_C_IN_BITS))
        return json_text(table, command)
    printer, _ = TABLE_FORMATS[fmt]
    return printer(table, command)


def _renamed(table, name):
    """``table`` under another ``name`` (checked; the bounds, verified first, are kept)."""
    from dataclasses import replace

    from chebnorm.approx.contract import construction
    from chebnorm.core.textsafe import identifier

    identifier(name, field="name")
    table.verify()
    with construction("fitted"):  # only the name changes: every field checked, no re-proof
        return replace(table, name=name)


@export_doc
def export_table(table, fmt: str, path, command: str = "", **options) -> str:
    """Print ``table`` in format ``fmt`` (:func:`export_text`, with the same
    ``options``) and write it to ``path`` atomically; nothing is written when
    printing fails.

    Parameters
    ----------
    table : CoefficientTable or PiecewiseTable
        The table.
    fmt : str
        The format, one of ``formats_for(table)``.
    path : str or os.PathLike
        The output file, written atomically (a temporary file in the same
        folder renamed into place; nothing is written when printing fails).
    %(command)s
    **options
        The format's keyword options, as :func:`export_text` takes them
        (``name``, ``in_bits``, ...).

    Returns
    -------
    str
        The text written.

    Raises
    ------
    ValueError
        As :func:`export_text`.
    OSError
        When ``path`` cannot be written.

    Examples
    --------
    >>> import os, tempfile
    >>> from chebnorm.approx import fit
    >>> t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 1, var="z", name="dich")
    >>> with tempfile.TemporaryDirectory() as d:
    ...     text = export_table(t, "c", os.path.join(d, "dich.h"))
    ...     open(os.path.join(d, "dich.h")).read() == text
    True
    """
    text = export_text(table, fmt, command, **options)
    write_atomic(path, text)
    return text


@export_doc
def export_with_proofs(table, fmt: str, path, command: str = "", *, inputs=None,
                       **options) -> dict[str, str]:
    """Print ``table`` in ``fmt`` naming a Gappa proof beside each stated
    evaluation bound, and write the output and the proofs
    (:mod:`chebnorm.export.gappa`: ``NAME.CONSTANT.gappa`` next to ``path``,
    ``NAME`` its whole file name, so outputs of other formats or versions
    never share a proof), all or none. ``fmt``: one of
    :data:`~chebnorm.export.gappa.PROOF_FORMATS` (``c`` of either kind of
    table, ``glsl``, ``wgsl``, ``hlsl``). Returns file name -> text of
    everything written (the output first).

    Parameters
    ----------
    table : CoefficientTable or PiecewiseTable
        The table (a piecewise table has proofs in ``c`` only).
    fmt : {"c", "glsl", "wgsl", "hlsl"}
        The format.
    path : str or os.PathLike
        The output file; the proofs go to its directory.
    %(command)s
    inputs : dict of str to (str or os.PathLike), optional
        The command's input files (what each is -> path): no file written
        may resolve to one of them. Default: none.
    **options
        The format's keyword options (:func:`export_text`).

    Returns
    -------
    dict of str to str
        File name (no directory) -> text, the output first, then one
        ``NAME.CONSTANT.gappa`` per stated evaluation bound (the comment
        naming it shows the name through
        :func:`~chebnorm.core.textsafe.comment_text`).

    Raises
    ------
    ValueError
        When ``fmt`` has no proof, or as :func:`export_text` (checked before
        anything is written).
    OSError
        When a file cannot be written (then none is), or one would replace
        an input (:func:`~chebnorm.core.files.refuse_inputs`).

    Notes
    -----
    Each script states the theorem
    :math:`x \\in [lo, hi] \\wedge |P - F| \\le A \\Rightarrow |y - F| \\le B`
    for the evaluator's fused and unfused Horner sequences; ``gappa`` proves
    it (Melquiond [1]_). The shader scripts prove the float32 constant as
    printed (the bound rounded up to a float32).

    References
    ----------
    .. [1] G. Melquiond, Gappa, https://gappa.gitlabpages.inria.fr/ ;
       F. de Dinechin, C. Lauter, G. Melquiond, "Certifying the
       floating-point implementation of an elementary function using
       Gappa", IEEE Transactions on Computers 60(2), 2011.

    Examples
    --------
    >>> import os, tempfile
    >>> from chebnorm.approx import fit
    >>> t = fit("1/x", ("1", "2"), 1, name="inv")
    >>> with tempfile.TemporaryDirectory() as d:
    ...     sorted(export_with_proofs(t, "glsl", os.path.join(d, "inv.glsl")))
    ['inv.glsl', 'inv.glsl.CHEBNORM_INV_EVAL_ERROR_BOUND.gappa']
    """
    from pathlib import Path

    from .c import c_header_evaluators
    from .c_piecewise import piecewise_evaluator
    from .gappa import PROOF_FORMATS, gappa_proofs
    from .shader import shader_evaluator

    if fmt not in PROOF_FORMATS:
        raise ValueError(f"format {str(fmt)[:40]!r} has no proof; accepted with proofs: "
                         f"{', '.join(PROOF_FORMATS)}")
    export_text(table, fmt, command, **options)  # every check of the plain export
    path = Path(path)
    stem = path.name or "out"
    if _kind(table) == "piecewise table":
        text = piecewise_c_header(table, command, proof=stem,
                                  in_bits=options.get("in_bits") or DEFAULT_C_IN_BITS)
        evaluators = [piecewise_evaluator(table)]
    elif fmt == "c":
        text, evaluators = c_header_evaluators(table, command, proof=stem)
    else:
        text = shader_source(table, fmt, command, proof=stem)
        ev = shader_evaluator(table)
        evaluators = [ev]
    files = {path.name: text}
    scripts = gappa_proofs(evaluators, stem)
    if fmt in ("glsl", "wgsl", "hlsl"):  # the constant printed is the float32 rounded up
        from .gappa import gappa_script
        shader_bound = float32_eval_bound(table)
        if shader_bound.certificate is None:  # else: the proof is of the a-priori bound
            scripts = {name: gappa_script(ev, shader_bound.total32) for name in scripts}
    files.update(scripts)
    written = [(path, text)] + [(path.parent / name, script) for name, script in scripts.items()]
    for i, (p, _) in enumerate(written):
        refuse_inputs({"path" if i == 0 else "proof file": p}, inputs or {})
    write_all(written)
    return files


class _CallableModule(types.ModuleType):
    """``chebnorm.export`` is callable: ``chebnorm.export(table, "c")``."""

    def __call__(self, table, fmt: str | None = None, command: str = "", *,
                 name: str | None = None, **options) -> str:
        """The text of ``table`` in format ``fmt``: :func:`export_text`.

        Parameters
        ----------
        table : CoefficientTable or PiecewiseTable
            The table.
        fmt : str
            The format, one of :data:`FORMATS` (``format=`` is accepted too,
            as the command line's ``--format``).
        command : str, optional
            The command line stated in the banner.
        name : str, optional
            The identifier of the generated function or module.
        **options
            The format's options (:func:`options_for`).

        Returns
        -------
        str
            The text of the file.

        Raises
        ------
        ValueError
            As :func:`export_text`; also when no format is given.

        See Also
        --------
        chebnorm.export.export_table : the same text, written to a file.
        chebnorm.export.export_with_proofs : with a Gappa proof of each stated bound.
        chebnorm.export.verify.verify : compile the output and check it against the bound.
        chebnorm.hw.design_horner : the fixed-point datapath the HDL formats print.

        Notes
        -----
        The floating-point outputs (C, GLSL, WGSL, HLSL) state, beside the
        table's certified bound of :math:`|p - f|`, a bound ``EVAL_ERROR_BOUND`` of
        :math:`|\\mathrm{fl}(p(x)) - f(x)|` for the format's arithmetic: the
        certified bound plus the rounding of the Horner evaluation, bounded by
        interval arithmetic on pieces of the interval, every multiply-add fused or
        not (:mod:`chebnorm.export.evalbound`). Its a priori form is Higham's [1]_:
        for the unit roundoff :math:`u` and :math:`\\gamma_k = k u / (1 - k u)`,

        .. math::

            |\\mathrm{fl}(p(x)) - p(x)| \\le \\gamma_{2n} \\sum_{j=0}^{n} |c_j|\\,|x|^j.

        Gappa proves each stated bound independently (``export_with_proofs``
        [2]_). The HDL outputs print the bit-accurate
        fixed-point evaluator of :mod:`chebnorm.hw`, in the style of FloPoCo's
        generated operators [3]_.

        References
        ----------
        .. [1] N. J. Higham, *Accuracy and Stability of Numerical Algorithms*,
           2nd ed., SIAM, 2002, eq. (5.3).
        .. [2] G. Melquiond, Gappa, https://gappa.gitlabpages.inria.fr/ ;
           F. de Dinechin, C. Lauter, G. Melquiond, "Certifying the
           floating-point implementation of an elementary function using
           Gappa", IEEE Transactions on Computers 60(2), 2011.
        .. [3] F. de Dinechin, B. Pasca, "Designing custom arithmetic data paths
           with FloPoCo", IEEE Design & Test of Computers 28(4), 2011.

        Examples
        --------
        >>> import chebnorm as cn
        >>> t = cn.fit("exp(x)", (0, 1), 3)
        >>> "float chebnorm_e3(float" in cn.export(t, "glsl", name="e3")
        True
        >>> cn.export(t, format="c") == cn.export(t, "c")
        True
        """
        if fmt is None and isinstance(options.get("format"), str):
            fmt = options.pop("format")
        if fmt is None:
            raise ValueError(f"no export format given; accepted: fmt (or format=) one of "
                             f"{', '.join(EXPORT_FORMATS)}")
        return export_text(table, fmt, command, name=name, **options)


sys.modules[__name__].__class__ = _CallableModule
