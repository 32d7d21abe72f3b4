"""Gappa proof scripts of the exported evaluators' bounds.

:func:`gappa_script` prints, for one
:class:`~chebnorm.export.evalbound.Evaluator`, a Gappa script whose theorem
is its stated bound (or, where the exporter states the smaller exhaustive
certificate of :mod:`chebnorm.export.certificate`, the a-priori bound
``ev.bound().stated`` that the header quotes beside it)::

    { x in [LO, HI] /\\ |P - F| <= A  ->  |y_unfused - F| <= B /\\ |y_fused - F| <= B }

``F`` stands for ``f(x)``: the certified approximation bound ``A`` of the
polynomial ``P`` (the table's coefficients, exact literals) is the
hypothesis; ``y_unfused`` and ``y_fused`` are Horner's rule on the
coefficients the evaluator holds (exact hexadecimal literals) with every
operation rounded by ``float<ieee_64,ne>`` / ``float<ieee_32,ne>`` (an fma
rounds once), or ``fixed<-F,nu>`` for the integer evaluator (its products
rounded to nearest, ties up, by ``(acc * x_q + 2^(F-1)) >> F``; one
sequence); the input ``x`` is a number of the evaluator's type. A
piecewise evaluator gets one such pair per segment, all in one script over
the segment's local variable. Hints: ``$ x in N`` bisects the interval into
the fewest pieces (a power of two, at most the 64 of
:func:`chebnorm.export.evalbound.horner_bound`) on which our own computation
already proves the bound with half the headroom to spare, and
``~`` / ``->`` tell Gappa which exact value each computed one approximates.

Not modelled: the shaders' flush of subnormal results to zero (the script
proves the IEEE binary32 evaluation; the stated shader bound adds the flush
terms when the interval reaches the subnormal range, which the 8 registered
tables do not), and a compiler fusing only some of the steps (the computed
bound covers every mix; the script proves the two pure sequences).

:func:`gappa_proofs` gives the scripts of an exported file (file name ->
text); ``chebnorm export --proof`` writes them beside the output, one per
stated constant, named ``NAME.CONSTANT.gappa`` (``NAME`` the output's whole
file name, so ``t.h`` and ``t.glsl`` never share a proof).

>>> from chebnorm.approx import fit
>>> from chebnorm.export.c import c_header_evaluators
>>> s = gappa_script(c_header_evaluators(fit("1/x", ("1", "2"), 2, name="inv"))[1][1])
>>> "@rnd = float<ieee_32,ne>;" in s
True
"""

from __future__ import annotations

from fractions import Fraction

from .evalbound import Evaluator

# an implementation module of chebnorm.export: the API is what chebnorm.export exports
__all__: list[str] = []

#: the formats whose evaluators get proofs (json, verilog and vhdl have none
#: here: the HDL budget is checked by ``hw report``)
PROOF_FORMATS = ("c", "glsl", "wgsl", "hlsl")


def _lit(v) -> str:
    v = float(v)
    return "0" if v == 0 else v.hex()


def _horner(coeffs, var: str) -> str:
    expr = _lit(coeffs[-1])
    for c in reversed(coeffs[:-1]):
        expr = f"({expr}) * {var}" + (f" + {_lit(c)}" if c != 0 else "")
    return expr


def _piece_lines(ev: Evaluator, k: int, piece, var: str, bound: float) -> tuple[list, list, list,
                                                                            list]:
    """Definitions, hypotheses, goals and hints of one piece (suffix ``_k``)."""
    fixed = ev.arith.kind == "fixed"
    cs = [float(c) for c in piece.coeffs]
    if ev.parity is not None:
        cs = cs[ev.parity::2]
    defs, hyps, goals, hints = [], [], [], []
    p = f"_{k}"
    pvar = "T" if ev.shift is not None else "x"
    same = tuple(piece.coeffs) == tuple(piece.ref_coeffs)
    if ev.parity is not None and same:  # the certified polynomial, in the evaluator's form
        p_def = f"P{p} = {'Yy' + p if ev.parity == 1 else f'Y{p}_0'};"
    else:
        p_def = f"P{p} = {_horner(piece.ref_coeffs, pvar)};"
    seqs = ["u"] if fixed else ["u", "f"]
    for s in seqs:
        defs.append(f"{s}{p}_{len(cs) - 1} = {_lit(cs[-1])};")
    defs.append(f"Y{p}_{len(cs) - 1} = {_lit(cs[-1])};")
    for j in range(len(cs) - 2, -1, -1):
        c = _lit(cs[j])
        if fixed:
            defs.append(f"u{p}_{j} = rnd(u{p}_{j + 1} * {var}) + {c};")
        elif cs[j] == 0:  # fl(fl(a x) + 0) = fma(a, x, 0) = fl(a x)
            defs.append(f"u{p}_{j} = rnd(u{p}_{j + 1} * {var});")
            defs.append(f"f{p}_{j} = rnd(f{p}_{j + 1} * {var});")
        else:
            defs.append(f"u{p}_{j} = rnd(rnd(u{p}_{j + 1} * {var}) + {c});")
            defs.append(f"f{p}_{j} = rnd(f{p}_{j + 1} * {var} + {c});")
        defs.append(f"Y{p}_{j} = Y{p}_{j + 1} * {'T' if var == 't' else var}"
                    + (f" + {c};" if cs[j] != 0 else ";"))
        for s in seqs:
            hints.append(f"{s}{p}_{j} ~ Y{p}_{j};")
    if ev.parity == 1:
        defs.append(f"Yy{p} = Y{p}_0 * x;")
    for s in seqs:
        y = f"{s}{p}_0"
        if ev.parity == 1:
            defs.append(f"{s}{p}_y = rnd({y} * x);")
            y = f"{s}{p}_y"
            hints.append(f"{y} ~ Yy{p};")
        goals.append(f"|{y} - F{p}| <= {_lit(bound)}")
        yex = f"Yy{p}" if ev.parity == 1 else f"Y{p}_0"
        hints.append(f"{y} - F{p} -> ({y} - P{p}) + (P{p} - F{p});")
        hints.append(f"{y} - P{p} -> ({y} - {yex}) + ({yex} - P{p});")
    if tuple(piece.coeffs) != tuple(piece.ref_coeffs):
        d = [Fraction(c) - Fraction(r) for c, r in zip(piece.coeffs, piece.ref_coeffs)]
        if all(float(v) == v for v in d):  # the differences, exact doubles
            yex = f"Yy{p}" if ev.parity == 1 else f"Y{p}_0"
            hints.append(f"{yex} - P{p} -> {_horner(d, pvar)};")
    defs.append(p_def)  # after the Y its evaluator form uses
    hyps.append(f"|P{p} - F{p}| <= {_lit(piece.approx_bound)}")
    return defs, hyps, goals, hints


def gappa_script(ev: Evaluator, bound: float | None = None) -> str:
    """The Gappa script proving ``|evaluator(x) - f(x)| <= bound`` (default:
    the evaluator's stated bound) from the certified approximation bound.

    Parameters
    ----------
    ev : Evaluator
        From :func:`chebnorm.export.c.c_header_evaluators`,
        :func:`chebnorm.export.shader.shader_evaluator` or
        :func:`chebnorm.export.c_piecewise.piecewise_evaluator`.
    bound : float, optional
        The bound to prove (the tests pass half of it to see gappa fail).

    Returns
    -------
    str

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> from chebnorm.export.shader import shader_evaluator
    >>> "$ x in " in gappa_script(shader_evaluator(fit("1/x", ("1", "2"), 1, name="inv")))
    True
    """
    if bound is None:
        bound = ev.bound().stated
    bound = float(bound)
    a = ev.arith
    piecewise = len(ev.pieces) > 1
    out = [f"# {ev.constant}: |{ev.function}(x) - f(x)| <= {bound!r}",
           "# generated by chebnorm (chebnorm.export.gappa); run: gappa FILE (no output: proved)",
           f"@rnd = {a.gappa};"]
    lo, hi = ev.pieces[0].lo, ev.pieces[0].hi
    if a.kind == "fixed":
        out.append(f"x = fixed<-{a.frac_bits},dn>(xx);  # x = x_q 2^-{a.frac_bits}")
    elif piecewise:
        out.append("x = xx;  # the segment's local variable, computed exactly")
    else:
        out.append("x = rnd(xx);  # the input, a number of the evaluator's type")
    var = "x"
    hints = []
    if ev.parity is not None:
        out += ["t = rnd(x * x);", "T = x * x;"]
        hints.append("t ~ T;")
        var = "t"
    elif ev.shift is not None:
        c, s, c_t, s_t, exact = ev.shift
        d = f"rnd(x - {_lit(c_t)})"
        out.append(f"t = rnd({d} * {_lit(1 / s)});" if exact else
                   f"t = rnd({d} / {_lit(s_t)});")
        out.append(f"T = (x - {_lit(c)}) * {_lit(1 / s)};" if exact else
                   f"T = (x - {_lit(c)}) / {_lit(s)};")
        hints.append(f"rnd(x - {_lit(c_t)}) ~ x - {_lit(c)};")
        hints.append("t ~ T;")
        var = "t"
    hyps, goals = [f"x in [{_lit(lo)}, {_lit(hi)}]"], []
    for k, piece in enumerate(ev.pieces):
        d, h, g, hi_ = _piece_lines(ev, k, piece, var, bound)
        out += d
        hyps += h
        goals += g
        hints += hi_
    out.append("{ " + " /\\ ".join(hyps) + "\n  -> " + " /\\ ".join(goals) + " }")
    out.append(f"$ x in {_pieces(ev, bound)};")
    out += hints
    return "\n".join(out) + "\n"


def _pieces(ev: Evaluator, bound: float) -> int:
    """The fewest pieces (a power of two, at most ``ev.subintervals``) on
    which our own computation proves ``bound`` with half the headroom to
    spare: Gappa's time grows with the pieces, and its enclosures match ours
    to well within that headroom."""
    from dataclasses import replace

    from .evalbound import PROOF_HEADROOM

    n = 1
    while n < ev.subintervals:
        b = replace(ev, subintervals=n).bound()
        if b.approximation + b.local * (1 + PROOF_HEADROOM / 2) <= Fraction(bound):
            return n
        n *= 2
    return ev.subintervals


def gappa_proofs(evaluators, stem: str) -> dict[str, str]:
    """The proof files of an exported file: ``STEM.CONSTANT.gappa`` -> script.

    Parameters
    ----------
    evaluators : iterable of Evaluator
        The evaluators of the exported file, one per stated bound (the
        second item of :func:`chebnorm.export.c.c_header_evaluators`, or
        :func:`chebnorm.export.shader.shader_evaluator`'s).
    stem : str
        The prefix of the proof names, ``STEM.CONSTANT.gappa``
        (``export_with_proofs`` passes the output's whole file name).

    Returns
    -------
    dict of str to str
        File name -> Gappa script (:func:`gappa_script` of each evaluator at
        its stated bound), in the evaluators' order.

    References
    ----------
    .. [1] G. Melquiond, Gappa, a tool for certifying numerical programs,
       https://gappa.gitlabpages.inria.fr/ ; F. de Dinechin, C. Lauter,
       G. Melquiond, "Certifying the floating-point implementation of an
       elementary function using Gappa", IEEE Transactions on Computers
       60(2), 2011.

    Examples
    --------
    >>> from chebnorm.approx import fit
    >>> from chebnorm.export.c import c_header_evaluators
    >>> sorted(gappa_proofs(c_header_evaluators(fit("1/x", ("1", "2"), 1, name="inv"))[1], "inv"))
    ['inv.CHEBNORM_INV_EVAL_ERROR_BOUND.gappa', 'inv.CHEBNORM_INV_F_EVAL_ERROR_BOUND.gappa']
    """
    return {f"{stem}.{ev.constant}.gappa": gappa_script(ev) for ev in evaluators}
