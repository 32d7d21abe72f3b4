"""An independent cross-check with Sollya (https://www.sollya.org), when installed.

``remez`` runs Sollya's ``remez`` and returns its coefficients and the
``supnorm`` of its error; ``supnorm`` certifies given float coefficients. The
polynomial is passed to Sollya exactly (each float as ``m * 2^e``).
"""

from __future__ import annotations

import math
import re
import tempfile
from dataclasses import dataclass

import sympy as sp

from .expr import parse_function, parse_number
from chebnorm.core.tools import require, run_tool, which

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []


def available() -> bool:
    """True when the ``sollya`` executable is on PATH.

    Returns
    -------
    bool
        Whether :func:`chebnorm.core.tools.which` finds ``sollya``.
    """
    return which("sollya") is not None


@dataclass(frozen=True)
class SollyaSupnorm:
    """Sollya's certified enclosure ``[lower, upper]`` of ``sup |p - f|``.

    Parameters
    ----------
    lower : float
        A lower bound of the supremum (Sollya's ``inf`` of the enclosure).
    upper : float
        A rigorous upper bound of the supremum (Sollya's ``sup``).
    """

    lower: float
    upper: float


def _sollya_expr(expr: str, var: str) -> str:
    fn = parse_function(expr, var)
    x = sp.Symbol("x", real=True)
    text = sp.sstr(fn.expr.subs(fn.var, x))
    return text.replace("**", "^").replace("E", "exp(1)")


def _exact(value: float) -> str:
    m, e = math.frexp(value)
    mant = int(m * 2 ** 53)
    return f"({mant}*2^({e - 53}))"


def _poly(coefficients) -> str:
    return " + ".join(f"{_exact(float(c))}*x^{k}" for k, c in enumerate(coefficients)) or "0"


def _interval(lo: str, hi: str) -> str:
    return f"[{sp.sstr(parse_number(lo))};{sp.sstr(parse_number(hi))}]".replace("**", "^")


def function_text(expr: str, var: str = "x") -> str:
    """``expr`` (a function of ``var``, parsed by chebnorm's own reader) as a
    Sollya expression in ``x``, for scripts of one's own.

    Parameters
    ----------
    expr : str
        The function, in chebnorm's expression syntax.
    var : str, optional
        Its variable, default ``"x"``.

    Returns
    -------
    str
        The Sollya expression (``^`` for powers, ``exp(1)`` for ``E``).

    Raises
    ------
    ValueError
        When :func:`chebnorm.approx.expr.parse_function` refuses ``expr``.

    Examples
    --------
    >>> function_text("1/sqrt(2+z)", "z")
    '1/sqrt(x + 2)'
    """
    return _sollya_expr(expr, var)


def interval_text(lo: str, hi: str) -> str:
    """The interval ``[lo, hi]`` as a Sollya range with exact endpoints.

    Parameters
    ----------
    lo, hi : str
        The endpoints, exact expressions read by
        :func:`chebnorm.approx.expr.parse_number`.

    Returns
    -------
    str
        ``"[lo;hi]"`` in Sollya syntax.

    Raises
    ------
    ValueError
        When an endpoint is not a finite real constant.

    Examples
    --------
    >>> interval_text("sqrt(2)", "2")
    '[sqrt(2);2]'
    """
    return _interval(lo, hi)


def _run(script: str, timeout: float = 600) -> str:
    exe = require("sollya", "the cross-check with Sollya")
    with tempfile.NamedTemporaryFile("w", suffix=".sollya", delete=False) as fh:
        fh.write(script + "quit;\n")
        path = fh.name
    try:
        proc = run_tool([exe, "--warnonstderr", path], tool="sollya", timeout=timeout, check=True)
    finally:
        import os
        os.unlink(path)
    return proc.stdout


_NUM = r"[-+]?[0-9.]+(?:e[-+]?[0-9]+)?"


def script_supnorm(expr: str, var: str, coefficients, lo: str, hi: str, kind: str = "abs",
                   accuracy: float = 2.0 ** -8) -> str:
    """The Sollya script that bounds ``sup |p - f|`` (``kind="abs"``) or
    ``sup |p/f - 1|`` (``"rel"``) on ``[lo, hi]`` with ``supnorm`` and prints
    ``SUP lower upper``: the independent check of our certified bounds.

    Every coefficient is written exactly, as an integer times a power of two
    (here ``1 = 2^52 * 2^-52``):

    Parameters
    ----------
    expr : str
        The function ``f``.
    var : str
        Its variable.
    coefficients : sequence of float
        The coefficients of ``p`` in powers of ``x``, ascending (finite).
    lo, hi : str
        The interval's exact endpoints.
    kind : {"abs", "rel"}, optional
        The error bounded, default ``"abs"``.
    accuracy : float, optional
        Sollya's relative accuracy of the enclosure, default 2^-8.

    Returns
    -------
    str
        The script (without ``quit;``).

    Examples
    --------
    >>> print(script_supnorm("x**2", "x", [0.0, 0.0, 1.0], "0", "1"))
    prec=200!;
    display=decimal!;
    f=x^2;
    p=(0*2^(-53))*x^0 + (0*2^(-53))*x^1 + (4503599627370496*2^(-52))*x^2;
    r=supnorm(p, f, [0;1], absolute, 0.00390625);
    print("SUP", inf(r), sup(r));
    <BLANKLINE>
    """
    mode = "absolute" if kind == "abs" else "relative"
    return (f"prec=200!;\ndisplay=decimal!;\nf={_sollya_expr(expr, var)};\np={_poly(coefficients)};\n"
            f"r=supnorm(p, f, {_interval(lo, hi)}, {mode}, {accuracy!r});\n"
            f"print(\"SUP\", inf(r), sup(r));\n")


def supnorm(expr: str, var: str, coefficients, lo: str, hi: str, kind: str = "abs",
            accuracy: float = 2.0 ** -8) -> SollyaSupnorm:
    """Sollya's certified supnorm of ``p - f`` (or ``p/f - 1``).

    Parameters
    ----------
    expr : str
        The function ``f``.
    var : str
        Its variable.
    coefficients : sequence of float
        The coefficients of ``p`` in powers of ``x``, ascending (finite).
    lo, hi : str
        The interval's exact endpoints.
    kind : {"abs", "rel"}, optional
        The error bounded, default ``"abs"``.
    accuracy : float, optional
        Sollya's relative accuracy of the enclosure, default 2^-8.

    Returns
    -------
    SollyaSupnorm
        The enclosure of the supremum.

    Raises
    ------
    RuntimeError
        When Sollya fails or prints something unexpected (run it only when
        :func:`available`).
    """
    out = _run(script_supnorm(expr, var, coefficients, lo, hi, kind, accuracy))
    m = re.search(rf"SUP\s+({_NUM})\s+({_NUM})", out)
    if not m:
        raise RuntimeError(f"unexpected sollya output: {out[:300]!r}")
    return SollyaSupnorm(float(m.group(1)), float(m.group(2)))


def remez(expr: str, var: str, lo: str, hi: str, degree: int, kind: str = "abs",
          accuracy: float = 2.0 ** -8) -> tuple[list[float], SollyaSupnorm]:
    """Sollya's ``remez`` fit and the ``supnorm`` of its error.

    Sollya's ``remez(g, n, d, w)`` minimises ``sup |p*w - g|``: the absolute
    fit is ``remez(f, n, d)``, the relative one (``sup |p/f - 1|``)
    ``remez(1, n, d, 1/f)``.

    Parameters
    ----------
    expr : str
        The function ``f``.
    var : str
        Its variable.
    lo, hi : str
        The interval's exact endpoints.
    degree : int
        The degree of the fit, >= 0.
    kind : {"abs", "rel"}, optional
        The error minimized and bounded, default ``"abs"``.
    accuracy : float, optional
        Sollya's relative accuracy of the supnorm, default 2^-8.

    Returns
    -------
    coefficients : list of float
        The ``degree + 1`` coefficients in powers of ``x``, ascending (0.0 where
        Sollya printed none).
    sup : SollyaSupnorm
        The enclosure of the fit's error.

    Raises
    ------
    RuntimeError
        When Sollya fails or prints something unexpected.
    """
    f = _sollya_expr(expr, var)
    target, weight = ("f", "1") if kind == "abs" else ("1", "1/f")
    mode = "absolute" if kind == "abs" else "relative"
    script = (f"prec=200!;\ndisplay=decimal!;\nf={f};\nd={_interval(lo, hi)};\n"
              f"p=remez({target}, {degree}, d, {weight});\n"
              + "".join(f"print(\"C{k}\", coeff(p, {k}));\n" for k in range(degree + 1))
              + f"r=supnorm(p, f, d, {mode}, {accuracy!r});\nprint(\"SUP\", inf(r), sup(r));\n")
    out = _run(script)
    coeffs = []
    for k in range(degree + 1):
        m = re.search(rf"C{k}\s+({_NUM})", out)
        coeffs.append(float(m.group(1)) if m else 0.0)
    m = re.search(rf"SUP\s+({_NUM})\s+({_NUM})", out)
    if not m:
        raise RuntimeError(f"unexpected sollya output: {out[:300]!r}")
    return coeffs, SollyaSupnorm(float(m.group(1)), float(m.group(2)))


#: Sollya's precision (floating) for chebnorm's floating formats; Sollya's
#: ``floating`` formats have an unbounded exponent range, which none of the
#: compared coefficients approach
_SOLLYA_PRECISION = {"binary16": 11, "bfloat16": 8, "binary32": 24, "binary64": 53}


@dataclass(frozen=True)
class FpminimaxCase:
    """One ``fpminimax`` problem: ``expr`` of ``var`` on ``[lo, hi]`` with the
    powers ``monomials``, ``coef_format`` (``"fixed"`` with ``frac_bits`` per
    power, or a floating format), ``kind`` abs or rel, ``constant`` (a float
    held as the constant coefficient) or None; ``check`` optional coefficients
    (all powers) whose supnorm Sollya also computes.

    Parameters
    ----------
    expr : str
        The function ``f``.
    var : str
        Its variable.
    lo, hi : str
        The interval's exact endpoints.
    monomials : tuple of int
        The powers of ``x`` whose coefficients are free.
    coef_format : str
        ``"fixed"`` or a floating format (``"binary16"``, ``"bfloat16"``,
        ``"binary32"``, ``"binary64"``).
    frac_bits : tuple of int or None, optional
        For ``"fixed"``: the fraction bits of every power up to the largest
        monomial; default None.
    kind : {"abs", "rel"}, optional
        The error minimized, default ``"abs"``.
    constant : float or None, optional
        A constant coefficient held fixed; default None.
    check : tuple of float or None, optional
        Coefficients (all powers) whose supnorm Sollya also computes; default
        None.
    """

    expr: str
    var: str
    lo: str
    hi: str
    monomials: tuple[int, ...]
    coef_format: str
    frac_bits: tuple[int, ...] | None = None
    kind: str = "abs"
    constant: float | None = None
    check: tuple[float, ...] | None = None


def _dyadic(text: str):
    from fractions import Fraction

    text = text.strip()
    m = re.fullmatch(r"([-+]?[0-9]+)(?:b([-+]?[0-9]+))?", text)
    if not m:
        raise RuntimeError(f"unexpected sollya number {text!r}")
    return Fraction(int(m.group(1))) * Fraction(2) ** int(m.group(2) or 0)


def fpminimax(cases, accuracy: float = 2.0 ** -20, timeout: float = 1200):
    """Run Sollya's ``fpminimax`` on every case in one Sollya process.

    Returns one dict per case: ``coefficients`` (exact Fractions, all powers
    up to the largest monomial), ``sup`` (:class:`SollyaSupnorm` of its error,
    absolute or relative as the case's ``kind``) and ``check_sup`` (the
    supnorm of the case's ``check`` coefficients, or None); a case Sollya
    fails on gives ``None``.

    Parameters
    ----------
    cases : sequence of FpminimaxCase
        The problems.
    accuracy : float, optional
        Sollya's relative accuracy of the supnorms, default 2^-20.
    timeout : float, optional
        Seconds before the Sollya process is stopped, default 1200.

    Returns
    -------
    list of dict or None
        One entry per case, in order (None when Sollya failed on it).

    Raises
    ------
    RuntimeError
        When the Sollya process fails.
    chebnorm.exceptions.ToolTimeout
        When it runs longer than ``timeout`` (a ``ValueError``
        and a ``subprocess.TimeoutExpired``; one line naming the tool and the limit).
    """
    parts = ["prec=300!;", "display=dyadic!;", "verbosity=0!;"]
    for i, c in enumerate(cases):
        mode = "absolute" if c.kind == "abs" else "relative"
        mons = list(c.monomials)
        if c.coef_format == "fixed":
            fmts = [c.frac_bits[k] for k in mons]
            kind = "fixed"
        else:
            fmts = [_SOLLYA_PRECISION[c.coef_format]] * len(mons)
            kind = "floating"
        constrained = "" if c.constant is None else f", {_exact(c.constant)}"
        parts.append(f"f={_sollya_expr(c.expr, c.var)};\nd={_interval(c.lo, c.hi)};")
        parts.append(f"p=fpminimax(f, [|{','.join(map(str, mons))}|], "
                     f"[|{','.join(map(str, fmts))}|], d, {kind}, {mode}{constrained});")
        parts.append("".join(f"print(\"C{i}_{k}\", coeff(p, {k}));\n"
                             for k in range(max(mons) + 1))
                     + f"r=supnorm(p, f, d, {mode}, {accuracy!r});\n"
                     f"print(\"S{i}\", inf(r), sup(r));")
        if c.check is not None:
            parts.append(f"q={_poly(c.check)};\nr=supnorm(q, f, d, {mode}, {accuracy!r});\n"
                         f"print(\"K{i}\", inf(r), sup(r));")
    out = _run("\n".join(parts) + "\n", timeout=timeout)
    num = r"[-+]?[0-9]+(?:b[-+]?[0-9]+)?"
    results = []
    for i, c in enumerate(cases):
        found = [re.search(rf"^C{i}_{k}\s+({num})\s*$", out, re.M)
                 for k in range(max(c.monomials) + 1)]
        sup = re.search(rf"^S{i}\s+({num})\s+({num})\s*$", out, re.M)
        check = re.search(rf"^K{i}\s+({num})\s+({num})\s*$", out, re.M)
        if sup is None or not all(found):     # Sollya failed on this case
            results.append(None)
            continue
        coeffs = [_dyadic(m.group(1)) for m in found]
        if c.check is not None and check is None:
            # Sollya's supnorm occasionally fails at the tight accuracy: a looser one
            try:
                checked = supnorm(c.expr, c.var, c.check, c.lo, c.hi, c.kind, 2.0 ** -12)
            except RuntimeError:
                checked = None
        else:
            checked = None if check is None else SollyaSupnorm(
                float(_dyadic(check.group(1))), float(_dyadic(check.group(2))))
        results.append({
            "coefficients": coeffs,
            "sup": SollyaSupnorm(float(_dyadic(sup.group(1))), float(_dyadic(sup.group(2)))),
            "check_sup": checked})
    return results
