"""What every HDL printer shares: module names, the banner, the vector file.

The banner (the header comment of a generated evaluator) is written once, as
language-neutral lines of text -- the *facts* -- by :func:`horner_facts` and
:func:`piecewise_facts`; :func:`comment_lines` then puts each language's
comment syntax in front (``//`` for Verilog, ``--`` for VHDL). Text from
the table, the version and the command line goes through
:func:`~chebnorm.core.textsafe.comment_text` (no line break, no backslash,
no ``*/``, no backquote directive can start a line: every line is a
comment); names through :func:`~chebnorm.core.textsafe.identifier`.

A *design* is a :class:`~chebnorm.hw.horner.HornerDesign` (one Horner
evaluator of a coefficient table) or a
:class:`~chebnorm.hw.piecewise.PiecewiseDesign` (coefficient ROM + one
Horner datapath of a uniform piecewise table); the printers read only their
attributes.
"""

from __future__ import annotations

from chebnorm.core.textsafe import comment_text, identifier
from chebnorm.core.numeric import format_up

from ..trust import verify_design
from .._docfrag import hw_doc

# an implementation module of chebnorm.hw.hdl: the API is what chebnorm.hw.hdl exports
__all__: list[str] = []

#: the hardware description languages the printers write
LANGUAGES = ("verilog", "vhdl")
#: the line-comment marker of each language
COMMENT = {"verilog": "//", "vhdl": "--"}
#: the file suffix of each language
SUFFIX = {"verilog": ".v", "vhdl": ".vhd"}
#: each language's word for a module's width constants
_WIDTH_WORD = {"verilog": "parameters", "vhdl": "generics"}
#: a VHDL comment line is re-made inert in full (long lines are kept whole)
_VHDL_LINE = 2000


def check_language(language) -> str:
    """``language`` if it is one of :data:`LANGUAGES`, else ValueError naming them.

    >>> check_language("vhdl")
    'vhdl'
    >>> check_language("spice")
    Traceback (most recent call last):
    ...
    ValueError: language: unknown HDL 'spice'; accepted: verilog, vhdl

    Parameters
    ----------
    language : object
        The language asked for; accepted: ``"verilog"`` or ``"vhdl"``.

    Returns
    -------
    str
        ``language``, checked.

    Raises
    ------
    ValueError
        If ``language`` is not one of :data:`LANGUAGES`.
    """
    if not isinstance(language, str) or language not in LANGUAGES:
        raise ValueError(f"language: unknown HDL {str(language)[:40]!r}; accepted: "
                         f"{', '.join(LANGUAGES)}")
    return language


def module_name(design) -> str:
    """``chebnorm_NAME``, ``NAME`` checked to be an identifier (it names modules,
    entities, files and the bench's vector file).

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> module_name(design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10))
    'chebnorm_dichotomy_d1'

    Parameters
    ----------
    design : object
        A design of :mod:`chebnorm.hw` (Horner, piecewise, multipartite, plain table or a
        pipelined one): anything with ``name`` and ``module_name``.

    Returns
    -------
    str
        ``design.module_name`` (``chebnorm_NAME``).

    Raises
    ------
    ValueError
        If ``design.name`` is not a safe identifier.
    """
    identifier(design.name, field="name")
    return design.module_name


def pipelined_name(design) -> str:
    """Module name of the pipelined variant: ``chebnorm_NAME_pipe``.

    Parameters
    ----------
    design : object
        A design of :mod:`chebnorm.hw` (Horner, piecewise, multipartite, plain table or a
        pipelined one): anything with ``name`` and ``module_name``.

    Returns
    -------
    str
        ``chebnorm_NAME_pipe``.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> pipelined_name(d)
    'chebnorm_dichotomy_d1_pipe'
    """
    return f"{module_name(design)}_pipe"


@hw_doc
def horner_facts(design, language: str, *, version: str = "", command: str | None = None,
                 budget=None, pipelined: bool = False) -> list[str]:
    """The banner of a Horner evaluator as text lines without comment marker
    (``""``: an empty comment line): what it evaluates, the tool, the command,
    the input and output formats, the coefficients, the rounding, the error
    budget when given (a :class:`~chebnorm.hw.budget.ErrorBudget`), and
    whether it is combinational or pipelined. Both languages state the same
    facts; only the word for the width constants is the language's own.

    Parameters
    ----------
    %(horner_design)s
    %(language_required)s
    %(version)s
    %(command)s
    %(budget)s
    pipelined : bool, default False
        State the pipelined variant's name and latency instead of the combinational one's.

    Returns
    -------
    list of str
        The banner lines.

    Raises
    ------
    ValueError
        If ``language`` is unknown or a name is not a safe identifier.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> horner_facts(d, "verilog", version="1.0")[2]
    'Generated by chebnorm 1.0; do not edit.'
    >>> horner_facts(d, "vhdl", pipelined=True)[-1][:50]
    'Pipelined: one register stage per Horner step, lat'
    """
    check_language(language)
    verify_design(design)   # changed since it was proved: proved again (or refused)
    t = design.table
    xf, yf = design.x_format, design.y_format
    lo, hi = design.valid_codes
    module = pipelined_name(design) if pipelined else module_name(design)
    lines = [
        f"{module}: fixed-point Horner evaluator of p({comment_text(t.variable)}) ~ "
        f"{comment_text(t.expression)}",
        f"  on [{comment_text(t.interval[0])}, {comment_text(t.interval[1])}], "
        f"{comment_text(t.kind)} degree {int(design.degree)} "
        f"(table {identifier(t.name, field='name')!r}).",
        f"Generated by chebnorm {comment_text(version)}; do not edit."]
    if command:
        lines.append(f"Command: {comment_text(command)}")
    lines += [
        "",
        f"x: unsigned {design.in_bits}-bit code k, value = {float(xf.offset)!r} + k / 2^{xf.frac_bits}"
        f"   (x_format: frac_bits {xf.frac_bits}, offset {xf.offset_code}/2^{xf.frac_bits})",
        f"y: unsigned {design.out_bits}-bit code k, value = {float(yf.offset)!r} + k / 2^{yf.frac_bits}"
        f"   (y_format: frac_bits {yf.frac_bits}, offset {yf.offset_code}/2^{yf.frac_bits})",
        f"Valid input codes {lo}..{hi} (values inside the table's interval); other codes are",
        "  evaluated by the same datapath and the output saturates to 0..2^OUT_BITS-1.",
        f"Coefficients q_j / 2^{design.coef_frac_bits}, ascending powers: "
        f"{', '.join(str(int(q)) for q in design.integers)}",
        f"Rounding: {comment_text(design.rounding)} after each multiply-add; accumulators with "
        f"{design.acc_frac_bits} fractional bits.",
    ]
    if design.scheme == "shifted":
        c, s = design.table.shift
        exact = "c' = c" if design.v_error == 0 else f"c' = c to {design.x_format.frac_bits + design.v_shift} fractional bits"
        lines.append(f"Shifted basis: y = q(v) with v = (x - c')/s, c = {c!r}, s = {s!r} "
                     f"({exact}); coefficients q_j of powers of v.")
    elif design.scheme != "monomial":
        v_how = (f"rounded to {design.variable_frac_bits} fractional bits"
                 if design.v_round_shift else "exact")
        lines.append(f"Only {design.scheme} powers: y = {'x * ' if design.scheme == 'odd' else ''}"
                     f"q(v) with v = x*x ({v_how}), Horner's rule over the nonzero "
                     f"coefficients; {design.multipliers} multipliers (the squarer included), "
                     f"{design.degree} for Horner's rule in x.")
    if budget is not None:
        lines.append(f"Error budget (|y - f(x)| on the valid codes): total <= "
                     f"{format_up(budget.total, '.6e')} "
                     f"= {format_up(budget.total / budget.y_lsb, '.4g')} LSB of y")
        lines.append(f"  approximation {format_up(budget.approximation, '.6e')}, quantization "
                     f"{format_up(budget.quantization, '.6e')} (quantized, re-certified "
                     f"{format_up(budget.quantized, '.6e')}), "
                     f"rounding {format_up(budget.rounding, '.6e')}")
    if pipelined:
        lines.append(f"Pipelined: one register stage per Horner step, latency {design.steps} "
                     f"cycles (LATENCY); one result per cycle. Constants sized for these widths.")
    else:
        lines.append(f"Combinational. The widths are {_WIDTH_WORD[language]} for readability; "
                     f"the constants were sized for these values.")
    return lines


@hw_doc
def piecewise_facts(design, *, version: str = "", command: str | None = None) -> list[str]:
    """The banner of a piecewise (ROM + Horner) evaluator as text lines without
    comment marker: the function, the segments, the tool, the command, the
    input and output formats, the ROM, the rounding and the certified error
    budget by part (:meth:`~chebnorm.hw.piecewise.PiecewiseDesign.budget`).

    Parameters
    ----------
    design : PiecewiseDesign
        The piecewise design (:func:`~chebnorm.hw.piecewise.design_piecewise`).
    %(version)s
    %(command)s

    Returns
    -------
    list of str
        The banner lines, the same in both languages.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    >>> print("\\n".join(piecewise_facts(design_piecewise(t, 8, 8))[:2]))
    chebnorm_rs: piecewise degree-1 evaluator of 1/sqrt(x) on [1, 4),
      2^2 uniform segments (table 'rs'), uncentred local variable.
    """
    verify_design(design)   # changed since it was proved: proved again (or refused)
    t = design.table
    n, L, K, fc = t.degree, design.local_bits, design.index_bits, t.coef_frac_bits
    yf = design.y_format
    b = design.budget()
    lo, hi = t.interval
    lines = [f"{module_name(design)}: piecewise degree-{n} evaluator of "
             f"{comment_text(t.expression)} on [{comment_text(lo)}, {comment_text(hi)}),",
             f"  2^{K} {t.segment_by} segments"
             + (f" (2^{t.index_bits} per binade)" if t.segment_by == "exponent" else "")
             + f" (table {identifier(t.name, field='name')!r}), "
             f"{'centred' if t.centered else 'uncentred'} local variable.",
             f"Generated by chebnorm {comment_text(version)}; do not edit."]
    if command:
        lines.append(f"Command: {comment_text(command)}")
    W = design.in_bits
    local = f"segment = k[{W - 1}:{L}], t = k[{L - 1}:0] / 2^{L}" + (" - 1/2" if t.centered else "")
    if t.segment_by == "exponent":
        # the code indexes binades: x = lo * 2^e * (1 + u / 2^(L + m)), the ROM's segment
        # of a binade is u's top m bits (the circuit's own mapping, not lo + (hi - lo) k / 2^W)
        U = L + t.index_bits
        e = f"e = k[{W - 1}:{U}]" if W > U else "e = 0"
        mapping = [f"x: unsigned {W}-bit code k, exponent-indexed: value = lo * 2^e * "
                   f"(1 + u / 2^{U}), {e}, u = k[{U - 1}:0] (lo = {comment_text(lo)});",
                   f"  {local}"]
    else:
        mapping = [f"x: unsigned {W}-bit code k, value = lo + (hi - lo) * k / 2^{W}; {local}"]
    lines += mapping + [
              f"y: unsigned {design.out_bits}-bit code k, value = ({yf.offset_code} + k) / "
              f"2^{yf.frac_bits}",
              f"ROM: coefficients q_j / 2^{fc}, widths {list(design.rom_bits)} bits (j ascending)."
              if not design.sized else
              f"ROM: coefficient c_j / 2^F_j, F = {list(design.coef_frac)}, widths "
              f"{list(design.rom_bits)} bits (j ascending).",
              f"Rounding: {design.rounding} after each multiply-add; accumulators with "
              f"{design.acc_frac_bits} fractional bits."
              if not design.sized else
              f"Step j multiplies by the top T_j bits of t, T = {list(design.t_keep)}; "
              f"{design.multipliers} multipliers, products truncated (floor) to P = "
              f"{list(design.prod_frac)} and sums to G = {list(design.acc_frac)} fractional "
              f"bits (a_0 .. a_n); the bias is centred in the ROM.",
              f"Error budget |y - f(x)| <= {format_up(b['total'], '.6e')} = approximation "
              f"{format_up(b['approximation'], '.6e')} + Horner rounding "
              f"{format_up(b['horner_rounding'], '.6e')} + output "
              f"rounding {format_up(b['output_rounding'], '.6e')}"]
    if design.latency:
        mult = design.mult_cuts
        lines.append(f"Pipelined: registers at cut points {list(design.cuts)} (0 after the ROM, "
                     f"i after the i-th multiply-add)"
                     + (f" and between the multiply and the add of steps {list(mult)}"
                        if mult else "")
                     + f"; latency {design.latency} cycles (LATENCY), one result per cycle.")
    return lines


@hw_doc
def comment_lines(facts: list[str], language: str) -> list[str]:
    """The banner ``facts`` as comment lines of ``language``: ``// `` before
    each Verilog line (``//`` alone for an empty one); ``-- `` before each
    VHDL line, the line made inert again after ``--`` (a no-op on text that
    went through ``comment_text`` already; it keeps a hand-built fact inert).

    >>> comment_lines(["Rounding: rne", ""], "verilog")
    ['// Rounding: rne', '//']
    >>> comment_lines(["Rounding: rne", ""], "vhdl")
    ['-- Rounding: rne', '-- ']

    Parameters
    ----------
    facts : list of str
        The banner lines (no line breaks).
    %(language_required)s

    Returns
    -------
    list of str
        One comment line per fact.

    Raises
    ------
    ValueError
        If ``language`` is unknown.
    """
    if check_language(language) == "verilog":
        return [f"// {text}" if text else "//" for text in facts]
    return ["-- " + comment_text(text, max_length=_VHDL_LINE) for text in facts]


def vector_file(design) -> str:
    """Expected ``y`` of every input code, one hex word a line (``$readmemh``;
    the VHDL benches read the same file).

    Parameters
    ----------
    design : object
        A design with a bit-accurate ``evaluate()`` over every input code and ``out_bits``.

    Returns
    -------
    str
        ``2**in_bits`` lines of ``ceil(out_bits / 4)`` lowercase hex digits each.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)
    >>> v = vector_file(d).split()
    >>> len(v) == 2 ** 6, [int(w, 16) for w in v[:3]] == d.evaluate()[:3].tolist()
    (True, True)
    """
    verify_design(design)   # the expected outputs of a design that holds its claims only
    y = design.evaluate()
    digits = (design.out_bits + 3) // 4
    return "".join(f"{int(v):0{digits}x}\n" for v in y)


def vectors_name(name: str, vectors: str | None) -> str:
    """The vector file a bench of module ``name`` reads: ``NAME.hex``, or
    ``vectors`` checked to be an identifier plus ``.hex`` (it goes into a
    Verilog or VHDL string literal).

    >>> vectors_name("chebnorm_f", None), vectors_name("chebnorm_f", "v.hex")
    ('chebnorm_f.hex', 'v.hex')

    Parameters
    ----------
    name : str
        The module name (already checked).
    vectors : str or None
        The vector file the bench reads: an identifier, optionally with ``.hex``; None:
        ``NAME.hex``.

    Returns
    -------
    str
        ``NAME.hex`` or ``vectors`` as given.

    Raises
    ------
    ValueError
        If ``vectors`` (without ``.hex``) is not a safe identifier.
    """
    if vectors is None:
        return f"{name}.hex"
    stem = vectors[:-4] if isinstance(vectors, str) and vectors.endswith(".hex") else vectors
    identifier(stem, field="vectors (without .hex)")
    return vectors


def variable_name(design, stage=None) -> str:
    """The wire a Horner step multiplies by: ``xs`` (the input value) in a
    plain design and in an odd design's last step, ``v`` (``x*x``) otherwise.

    Parameters
    ----------
    design : HornerDesign
        The Horner evaluator.
    stage : Stage or None, default None
        The step; None: the design's Horner variable.

    Returns
    -------
    str
        ``"xs"`` or ``"v"``.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit("sin(x)", ("-1", "1"), 5), 8, 8, coef_bits=16)
    >>> d.scheme, [variable_name(d, st) for st in d.stages]
    ('odd', ['v', 'v', 'xs'])
    """
    if design.scheme == "monomial" or (stage is not None and stage.operand == "x"):
        return "xs"
    return "v"


def step_comment(design, st) -> str:
    """What one Horner step computes, for the HDL comment (``q_k``: the
    coefficient of ``x^k``).

    Parameters
    ----------
    design : HornerDesign
        The Horner evaluator.
    st : Stage
        The step.

    Returns
    -------
    str
        E.g. ``"a2 = R(a3 * v + q4 / 2^16)"``.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit("sin(x)", ("-1", "1"), 5), 8, 8, coef_bits=16)
    >>> [step_comment(d, st) for st in d.stages]
    ['a2 = R(a3 * v + q3 / 2^16)', 'a1 = R(a2 * v + q1 / 2^16)', 'a0 = a1 * x']
    """
    j = st.power
    fc = design.coef_frac_bits
    if design.scheme == "monomial":
        return f"a{j} = R(a{j + 1} * x + q{j} / 2^{fc})"
    if design.scheme == "shifted":
        return f"a{j} = R(a{j + 1} * v + q{j} / 2^{fc})"
    if st.operand == "x":
        return f"a{j} = a{j + 1} * x"
    k = 2 * j if design.scheme == "even" else 2 * j - 1
    return f"a{j} = R(a{j + 1} * v + q{k} / 2^{fc})"


def shifted_width(design) -> int:
    """Signed width of ``(xs << m) - C`` in a shifted design, with its
    operands (wide enough that the subtraction wraps nowhere).

    Parameters
    ----------
    design : HornerDesign
        A design of scheme ``"shifted"``.

    Returns
    -------
    int
        The width in bits.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit("exp(x)", ("1", "2"), 3, basis="shifted"), 8, 8, coef_bits=16)
    >>> d.scheme, d.v_offset, shifted_width(d) >= d.variable_bits   # c = 3/2 times 2^8
    ('shifted', 384, True)
    """
    from chebnorm.core.numeric import signed_bits

    xf, m = design.x_format, design.v_shift
    lo, hi = xf.offset_code << m, (xf.offset_code + 2 ** design.in_bits - 1) << m
    c = design.v_offset
    return signed_bits(min(lo, hi, c, lo - c, hi - c), max(lo, hi, c, lo - c, hi - c)) + 1
