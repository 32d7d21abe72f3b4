"""The error budget of a :class:`~chebnorm.hw.horner.HornerDesign`, its
exhaustive check over every valid input code, and gappa's cross-check.

Budget (all in the units of ``y``, i.e. absolute errors of the value)::

    |y - f(x)| <= |p_q(x) - f(x)| + |y - p_q(x)|
               <= min(approx + quant, quantized) + sum_j rho_j |x|^j + rho_out

* ``approximation``: the table's certified ``sup |p - f|``;
* ``quantization``: a certified ``sup |p_q - p|`` (Arb Taylor forms, the
  float coefficients of ``p`` taken as exact rationals);
* ``quantized``: the table's re-certified ``sup |p_q - f|`` (at most
  ``approximation + quantization`` by the triangle inequality, often less);
* ``rounding_steps[j]``: the rounding of ``a_j`` (``rho_j`` = one ulp of the
  accumulator for truncation, half of one for ``rne``) carried to the output
  through ``j`` multiplications by ``x``;
* ``output_rounding``: rounding to the output's ``Fy`` fractional bits;
* ``variable_rounding``: for a design whose Horner variable ``v`` is not
  ``x`` (``x*x`` rounded, or ``(x - c')/s`` with ``c`` rounded to ``c'``),
  ``max |v - v_exact| * max |q'|`` (mean value theorem), times ``max |x|``
  for an odd design; each ``rho_j`` then reaches the output times
  ``max|v|^j`` (``max|v|^(j-1) max|x|`` when odd).

Every bound is a float rounded upward.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import sympy as sp

from chebnorm.approx import parse_function, parse_number
from chebnorm.approx.certify import certify

from chebnorm.core.numeric import float_up
from chebnorm.core.display import field_rows, summary_html, summary_repr

from .fixed import rounding_error_bound
from .design_base import provide
from .horner import HornerDesign
from .trust import verify_design
from chebnorm.core.tools import run_tool, which

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: an 8-bit shading output has 255 steps between black and full intensity
SHADING_LEVELS = 255


@dataclass(frozen=True)
class ErrorBudget:
    """Certified parts of the error (see module docstring); ``total`` is
    ``min(approximation + quantization, quantized) + rounding``.

    Attributes
    ----------
    approximation : float
        The table's certified ``sup |p - f|`` on its interval.
    quantization : float
        Certified ``sup |p_q - p|``: the coefficients rounded to ``coef_frac_bits``.
    quantized : float
        The table's re-certified ``sup |p_q - f|``.
    rounding_steps : tuple of float
        Per Horner step (highest power first), the bound of its rounding carried to the
        output: ``rho_j * max|x|**j``.
    output_rounding : float
        Bound of the rounding to the output's fractional bits (0 when none are dropped).
    rounding : float
        ``sum(rounding_steps) + output_rounding``, rounded upward.
    total : float
        The certified bound of ``|y - f(x)|`` over the valid codes.
    y_lsb : float
        The output's LSB ``2**-Fy``, for expressing bounds in LSB (``total / y_lsb``).
    gappa_rounding : float or None, default None
        gappa's independent bound of the rounding part ``|y - p_q(x)|``; None when not
        asked for or gappa is not installed.
    variable_rounding : float, default 0.0
        A one-parity design's rounding of the square ``v = R(x*x)`` carried to the
        output (:func:`variable_error_bound`; included in ``rounding``).

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> b = error_budget(design_horner(fit_target("dichotomy", 2), 10, 10, coef_bits=14), gappa=False)
    >>> parts = min(b.approximation + b.quantization, b.quantized) + b.rounding
    >>> f"{parts / b.total:.12f}"   # total: the same sum, in exact arithmetic rounded up
    '1.000000000000'
    """

    approximation: float
    quantization: float
    quantized: float
    rounding_steps: tuple[float, ...]
    output_rounding: float
    rounding: float
    total: float
    y_lsb: float
    gappa_rounding: float | None = None
    variable_rounding: float = 0.0

    def _summary(self) -> list[tuple[str, object]]:
        return [("total", self.total), ("approximation", self.approximation),
                ("quantization", self.quantization), ("rounding", self.rounding),
                ("gappa_rounding", self.gappa_rounding)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    def as_dict(self) -> dict:
        return {"approximation": self.approximation, "quantization": self.quantization,
                "quantized_certified": self.quantized,
                "rounding_steps": list(self.rounding_steps),
                "output_rounding": self.output_rounding,
                "variable_rounding": self.variable_rounding, "rounding": self.rounding,
                "total": self.total, "total_lsb": self.total / self.y_lsb,
                "gappa_rounding": self.gappa_rounding}


@dataclass(frozen=True)
class Measurement:
    """Errors measured over every valid input code (exhaustive).

    ``rounding`` and ``step_rounding`` are exact (integer arithmetic);
    ``approximation`` (``max |p - f|``), ``quantization`` (``max |p_q - p|``)
    and ``total`` (``max |y - f|``) use float64 values of ``f`` and ``p``,
    whose own error (about 1e-16) is far below the bounds compared with.
    ``rel_total`` is ``max |y / f - 1|`` (None when ``f`` is zero at a valid
    code: no relative error there), ``shading_levels`` is
    ``255 * rel_total``: the largest change of an 8-bit intensity
    ``I <= 1`` when the normal is scaled by ``y`` instead of ``f``.

    Attributes
    ----------
    codes : int
        Number of valid input codes measured.
    total : float
        ``max |y - f(x)|`` over them.
    total_at_code : int
        The input code where ``total`` is reached.
    rel_total : float or None
        ``max |y / f - 1|``; None when ``f`` is zero at some valid code.
    approximation : float
        ``max |p - f|`` measured.
    quantization : float
        ``max |p_q - p|`` measured.
    rounding : float
        ``max |y - p_q|``, exact (rounded upward to float).
    step_rounding : tuple of float
        Per Horner step (highest power first), the largest rounding error of its
        accumulator, exact, in the accumulator's units of value.
    overflows : int
        How many codes saturated or wrapped somewhere in the datapath (0 for a sound design).
    y_lsb : float
        The output's LSB ``2**-Fy``.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 2), 10, 10, coef_bits=14)
    >>> m = measure(d)
    >>> m.codes == d.valid_codes[1] - d.valid_codes[0] + 1, m.total <= error_budget(d, gappa=False).total
    (True, True)
    """

    codes: int
    total: float
    total_at_code: int
    rel_total: float | None
    approximation: float
    quantization: float
    rounding: float
    step_rounding: tuple[float, ...]
    overflows: int
    y_lsb: float

    def _summary(self) -> list[tuple[str, object]]:
        return [("codes", self.codes), ("total", self.total),
                ("total_at_code", self.total_at_code), ("rel_total", self.rel_total),
                ("overflows", self.overflows)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    @property
    def total_lsb(self) -> float:
        return self.total / self.y_lsb

    @property
    def shading_levels(self) -> float | None:
        return None if self.rel_total is None else SHADING_LEVELS * self.rel_total

    def as_dict(self) -> dict:
        return {"codes": self.codes, "total": self.total, "total_at_code": self.total_at_code,
                "total_lsb": self.total_lsb, "rel_total": self.rel_total,
                "shading_levels": self.shading_levels, "approximation": self.approximation,
                "quantization": self.quantization, "rounding": self.rounding,
                "step_rounding": list(self.step_rounding), "overflows": self.overflows}


def _poly_function(table):
    """``p`` itself as an exact sympy function of ``x`` (its floats as
    rationals; of ``(x - c)/s`` for a shifted table)."""
    v = sp.Symbol(table.variable)
    if table.shift is not None:
        c, s = (sp.Rational(*float(w).as_integer_ratio()) for w in table.shift)
        v = (v - c) / s
    expr = sum(sp.Rational(c) * v ** k for k, c in enumerate(table.coefficients))
    return parse_function(expr, table.variable)


def quantization_bound(design: HornerDesign) -> float:
    """Certified ``sup |p_q - p|`` on the table's interval."""
    t = design.table
    coeffs = [math.ldexp(q, -design.coef_frac_bits) for q in design.integers]
    lo, hi = (parse_number(v) for v in t.interval)
    return certify(_poly_function(t), coeffs, lo, hi, "abs", shift=t.shift).bound


def error_budget(design: HornerDesign, *, gappa: bool = False) -> ErrorBudget:
    """The certified budget; with ``gappa`` also gappa's rounding bound (if installed).

    The output is rounded to nearest with 16 fractional bits (half an LSB,
    ``2^-17``), and the budget bounds what every input code measures:

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 2), 12, 12, coef_bits=16)
    >>> b = error_budget(d)
    >>> b.output_rounding == 2.0 ** -17, measure(d).total <= b.total
    (True, True)

    Parameters
    ----------
    design : HornerDesign
        The datapath, from :func:`~chebnorm.hw.horner.design_horner`.
    gappa : bool, default False
        Also run gappa (when installed) for an independent bound of the rounding part.

    Returns
    -------
    ErrorBudget
        The certified parts and their ``total``, each a float rounded upward.

    Raises
    ------
    ValueError
        If gappa is asked for and fails on the datapath (see :func:`gappa_bound`), or
        the design does not hold its claims (changed since it was built).


    See Also
    --------
    measure : the errors every valid input code actually makes.
    gappa_bound : Gappa's independent bound of the rounding part.
    chebnorm.hw.report.analyze : design, budget and measurement together.

    Notes
    -----
    For every valid input code, :math:`p` the table's float polynomial and
    :math:`p_q` its quantized one (module docstring),

    .. math::

        |y - f(x)| \\le |p_q(x) - f(x)| + |y - p_q(x)|
        \\le \\min(\\varepsilon_{a} + \\varepsilon_{q},\\ \\varepsilon_{pq})
        + \\sum_{j=1}^{n-1} \\rho_j \\max_x |x|^j + \\rho_{\\mathrm{out}},

    with :math:`\\varepsilon_a` the certified :math:`\\sup|p - f|`
    (``approximation``), :math:`\\varepsilon_q` a certified
    :math:`\\sup|p_q - p|` (``quantization``), :math:`\\varepsilon_{pq}` the
    re-certified :math:`\\sup|p_q - f|` (``quantized``), :math:`\\rho_j` the
    rounding of the accumulator :math:`a_j` (one unit of its last place for
    ``"trunc"``, half of one for ``"rne"``; 0 when nothing is dropped),
    reaching the output multiplied by :math:`x^j`, and
    :math:`\\rho_{\\mathrm{out}}` the output's rounding. ``gappa=True`` adds
    Gappa's own bound of the rounding part [1]_.

    References
    ----------
    .. [1] G. Melquiond, Gappa, https://gappa.gitlabpages.inria.fr/ ;
       F. de Dinechin, C. Lauter, G. Melquiond, "Certifying the
       floating-point implementation of an elementary function using
       Gappa", IEEE Transactions on Computers 60(2), 2011.
    """
    verify_design(design)   # a design changed since it was proved: proved again (or refused)
    t = design.table
    xmax = design.max_abs_x()
    vmax, x_factor = _variable_max(design), (xmax if design.scheme == "odd" else 1)
    steps = []
    for st in design.stages[:-1]:
        rho = rounding_error_bound(st.out_frac_bits, design.rounding, st.round_shift)
        # a_j reaches the output times v^j; in an odd design times v^(j-1) * x
        steps.append(rho * (vmax ** (st.power - 1) * xmax if design.scheme == "odd"
                            else vmax ** st.power))
    top_frac = design.stages[-1].sum_frac_bits if design.stages else design.coef_frac_bits
    fy = design.y_format.frac_bits
    out = rounding_error_bound(fy, design.rounding, top_frac - fy) if top_frac > fy else Fraction(0)
    var = variable_error_bound(design, vmax) * x_factor
    rounding = sum(steps, Fraction(0)) + out + var
    approx, quant = t.abs_error_bound, quantization_bound(design)
    quantized = t.fixed_point.abs_error_bound
    poly = min(Fraction(approx) + Fraction(quant), Fraction(quantized))
    g = gappa_bound(design) if gappa else None
    return ErrorBudget(approximation=approx, quantization=quant, quantized=quantized,
                       rounding_steps=tuple(float_up(s) for s in steps), output_rounding=float_up(out),
                       rounding=float_up(rounding), total=float_up(poly + rounding),
                       y_lsb=float(design.y_format.lsb), gappa_rounding=g,
                       variable_rounding=float_up(var))


def _variable_max(design: HornerDesign) -> Fraction:
    """A bound of ``|v|`` and of the exact variable (``x`` or ``x*x``) over
    the valid codes: the largest rounded ``|v|`` plus ``v_error``."""
    lo, hi = design.valid_codes
    k = np.arange(lo, hi + 1, dtype=np.int64)
    v = design.evaluate(k, intermediates=True)["v"]
    biggest = max(abs(int(v.min())), abs(int(v.max())))
    return Fraction(biggest, 2 ** design.variable_frac_bits) + design.v_error \
        if design.variable_frac_bits >= 0 else \
        Fraction(biggest * 2 ** -design.variable_frac_bits) + design.v_error


def variable_error_bound(design: HornerDesign, vmax: Fraction | None = None) -> Fraction:
    """A bound of ``|q(v) - q(x*x)|`` (``q`` the quantized polynomial Horner's
    rule runs over) from rounding the square to ``v`` in a one-parity design:
    ``v_error * max |q'|`` by the mean value theorem, with
    ``|q'| <= sum_i i |d_i| V^(i-1)`` on ``|v| <= V``. An odd design's output
    is ``x`` times it (the caller multiplies by ``max |x|``); 0 when ``v``
    is exact or the design is plain Horner in ``x``.

    Parameters
    ----------
    design : HornerDesign
        The datapath.
    vmax : Fraction or None, default None
        A bound ``V`` of ``|v|`` and ``|x*x|`` on the valid codes; None computes it.

    Returns
    -------
    Fraction
        The bound, exact.

    Examples
    --------
    ``cos`` at degree 8 evaluates ``q(v)``, ``v = x*x`` rounded from 24 to
    16 fractional bits; plain Horner has no such term:

    >>> from chebnorm.approx import fit
    >>> from chebnorm.hw.horner import design_horner
    >>> t = fit("cos(x)", ("-1", "1"), 8)
    >>> d = design_horner(t, 12, 10, coef_bits=22)
    >>> d.scheme, d.variable_frac_bits, 0 < variable_error_bound(d) < 2 ** -17
    ('even', 16, True)
    >>> variable_error_bound(design_horner(t, 12, 10, coef_bits=22, parity=False))
    Fraction(0, 1)
    """
    if design.scheme == "monomial" or design.v_error == 0:
        return Fraction(0)
    if vmax is None:
        vmax = _variable_max(design)
    ints = design.horner_integers[1:] if design.scheme == "odd" else design.horner_integers
    slope = sum(i * abs(Fraction(q, 2 ** design.coef_frac_bits)) * vmax ** (i - 1)
                for i, q in enumerate(ints) if i > 0)
    return design.v_error * slope


def measure(design: HornerDesign) -> Measurement:
    """Measure every error over all valid input codes (see :class:`Measurement`).

    ``z`` in ``[sqrt(2), 2]`` with 12 fractional bits: ``(2 - sqrt 2) 2^12``,
    that is 2400 codes:

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 2), 12, 12, coef_bits=16)
    >>> m = measure(d)
    >>> m.codes, m.overflows, m.total <= error_budget(d).total
    (2400, 0, True)

    Parameters
    ----------
    design : HornerDesign
        The datapath to run over its ``valid_codes``.

    Returns
    -------
    Measurement
        The measured errors.


    See Also
    --------
    error_budget : the certified bound the measurement is checked against.

    Notes
    -----
    The bit-accurate model (:meth:`~chebnorm.hw.horner.HornerDesign.evaluate`)
    runs every valid code :math:`k`; ``total`` is :math:`\\max_k |y_k - f(x_k)|` with
    :math:`f` evaluated in float64, and the parts (``approximation``,
    ``quantization``, ``rounding``) are the same maxima of
    :math:`|p - f|`, :math:`|p_q - p|` and :math:`|y - p_q|`.
    """
    lo, hi = design.valid_codes
    k = np.arange(lo, hi + 1, dtype=np.int64)
    wires = design.evaluate(k, intermediates=True)
    y = wires["y"]
    xf = design.x_format.values(k)
    yv = design.y_format.values(y)
    fn = parse_function(design.table.expression, design.table.variable)
    f = np.asarray(fn.numpy(xf), dtype=np.float64) * np.ones_like(xf)
    p = design.table(xf)   # in t = (x - c) * (1/s) for a shifted table
    num, den = design.exact_numerators(k)
    pq = _to_float(num, den)
    # exact rounding error: y - p_q, both over the common denominator 2**D
    fy = design.y_format.frac_bits
    yn = (y.astype(object) + design.y_format.offset_code)
    if den >= fy:
        diff = yn * 2 ** (den - fy) - num
        scale = den
    else:
        diff = yn - num * 2 ** (fy - den)
        scale = fy
    worst = max(abs(int(diff.max())), abs(int(diff.min())))
    rounding = float_up(Fraction(worst, 2 ** scale))
    steps = []
    xs, v = wires["xs"], wires["v"]
    acc = np.full(k.shape, design.horner_integers[-1], dtype=np.int64)
    for st in design.stages[:-1]:
        t = ((acc * (xs if st.operand == "x" else v)) << st.product_shift) + st.coef_shifted
        a = wires[f"a{st.power}"]
        err = np.abs((a << st.round_shift) - t)
        steps.append(float(Fraction(int(err.max()), 2 ** st.sum_frac_bits)))
        acc = a
    e = np.abs(yv - f)
    i = int(np.argmax(e))
    return Measurement(codes=len(k), total=float(e[i]), total_at_code=int(k[i]),
                       rel_total=float(np.max(np.abs(yv / f - 1))) if np.all(f != 0) else None,
                       approximation=float(np.max(np.abs(p - f))),
                       quantization=float(np.max(np.abs(pq - p))), rounding=rounding,
                       step_rounding=tuple(steps), overflows=int(wires["overflow"].sum()),
                       y_lsb=float(design.y_format.lsb))


def _to_float(num, den) -> np.ndarray:
    """Object-int numerators over ``2**den`` to float64 (correctly rounded)."""
    d = 1 << den
    return np.array([int(v) / d for v in num], dtype=np.float64)


# -- gappa ---------------------------------------------------------------------

def _dyadic(q: int, frac: int) -> str:
    return f"{q}b{-frac}" if q else "0"


def _fraction_literal(v: Fraction) -> str:
    """A dyadic rational (a float's value) as a gappa literal ``Nb-E``."""
    return _dyadic(v.numerator, v.denominator.bit_length() - 1)


def gappa_script(design: HornerDesign) -> str:
    """A gappa script bounding ``|y - p_q(x)|`` of the datapath (rounding only).

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 2), 12, 12, coef_bits=16)
    >>> "@ry = fixed<-16,ne>;" in gappa_script(d)     # y: 16 fractional bits, to nearest
    True

    Parameters
    ----------
    design : HornerDesign
        The datapath to describe.

    Returns
    -------
    str
        The script text: the exact polynomial ``M0`` and the rounded datapath ``a0``
        over the valid input range, asking for ``|a0 - M0|``.
    """
    mode = {"rne": "ne", "trunc": "dn"}[design.rounding]
    fc = design.coef_frac_bits
    q = design.integers
    n = design.degree
    lo, hi = design.valid_codes
    xf = design.x_format
    lines = [f"# gappa: rounding error of the Horner datapath of {design.module_name}",
             f"# x in the valid codes {lo}..{hi}; coefficients q_j * 2^-{fc}",
             f"@ry = fixed<{-design.y_format.frac_bits},{mode}>;"]
    if len(design.horner_integers) >= 3:
        lines.append(f"@ra = fixed<{-design.acc_frac_bits},{mode}>;")
    var, exact_var = "x", "x"
    if design.scheme == "shifted":   # v = (x - c') * 2^-e exactly, Mv = (x - c) * 2^-e
        c, s = (Fraction(w) for w in design.table.shift)
        e = s.numerator.bit_length() - s.denominator.bit_length()
        g = design.v_shift + xf.frac_bits
        lines.append(f"Mv = (x - {_fraction_literal(c)}) * 1b{-e};")
        lines.append(f"v = (x - {_dyadic(design.v_offset, g)}) * 1b{-e};")
        var, exact_var = "v", "Mv"
    elif design.scheme != "monomial":   # the Horner variable v = R(x*x), exact Mv = x*x
        q, n = design.horner_integers, len(design.horner_integers) - 1
        lines.append("Mv = x * x;")
        if design.v_round_shift:
            lines.insert(3, f"@rv = fixed<{-design.variable_frac_bits},{mode}>;")
            lines.append("v rv= x * x;")
        else:
            lines.append("v = x * x;")
        var, exact_var = "v", "Mv"
    exact = _dyadic(q[n], fc)
    hw = exact
    for j in range(n - 1, -1, -1):
        c = _dyadic(q[j], fc)
        last_x = design.scheme == "odd" and j == 0
        ev, hv = ("x", "x") if last_x else (exact_var, var)
        tail = "" if last_x else f" + {c}"
        exact_j = f"M{j} = {'M' + str(j + 1) if j < n - 1 else exact} * {ev}{tail};"
        lines.append(exact_j)
        rnd = "ry" if j == 0 else "ra"
        prev = hw if j == n - 1 else f"a{j + 1}"
        lines.append(f"a{j} {rnd}= {prev} * {hv}{tail};")
    if n == 0:
        lines.append(f"M0 = {exact};")
        lines.append(f"a0 ry= {exact};")
    x_lo = _dyadic(xf.offset_code + lo, xf.frac_bits)
    x_hi = _dyadic(xf.offset_code + hi, xf.frac_bits)
    lines.append(f"{{ x in [{x_lo}, {x_hi}] -> |a0 - M0| in ? }}")
    return "\n".join(lines) + "\n"


_NUM = re.compile(r"^\s*(-?\d+)(?:b(-?\d+))?\s*$")


def parse_gappa_upper(text: str) -> Fraction:
    """The upper end of gappa's ``|...| in [lo, hi]`` answer, exactly.

    >>> parse_gappa_upper("|a0 - M0| in [0, 1b-21 {4.76837e-07, 2^(-21)}]")
    Fraction(1, 2097152)
    """
    m = re.search(r"in \[(.*)\]", text)
    if not m:
        raise ValueError(f"gappa gave no bound: {text.strip()[:200]!r}")
    plain = re.sub(r"\{[^}]*\}", "", m.group(1))
    upper = plain.split(",")[-1]
    n = _NUM.match(upper)
    if not n:
        raise ValueError(f"cannot read gappa's bound {upper.strip()!r}")
    mant, exp = int(n.group(1)), int(n.group(2) or 0)
    return Fraction(mant) * Fraction(2) ** exp


def gappa_bound(design: HornerDesign, timeout: float = 60) -> float | None:
    """gappa's bound of ``|y - p_q(x)|``, or None when gappa is not installed.

    An independent bound of the rounding part of :func:`error_budget`:

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 2), 12, 12, coef_bits=16)
    >>> g = gappa_bound(d)
    >>> g is None or measure(d).rounding <= g
    True

    Parameters
    ----------
    design : HornerDesign
        The datapath to bound.
    timeout : float, default 60
        Seconds to wait for gappa.

    Returns
    -------
    float or None
        The bound rounded upward, or None when no ``gappa`` executable is on ``PATH``.

    Raises
    ------
    ValueError
        If gappa fails or gives no bound.
    chebnorm.exceptions.ToolTimeout
        If gappa runs longer than ``timeout`` (a ``ValueError``
        and a ``subprocess.TimeoutExpired``; one line naming the tool and the limit).
    """
    exe = which("gappa")
    if exe is None:
        return None
    proc = run_tool([exe], tool="gappa", timeout=timeout, input=gappa_script(design))
    out = proc.stdout + proc.stderr
    if proc.returncode != 0 or "in [" not in out:
        raise ValueError(f"gappa could not bound the datapath of {design.module_name}: "
                         f"{' '.join(out.split())[:300]}")
    return float_up(parse_gappa_upper(out))


# the Horner design's budget and measurement (chebnorm.hw.design_base.Design): this
# module imports chebnorm.hw.horner, so it hands them over instead of being imported
provide("horner.error_budget", error_budget)
provide("horner.measure", measure)
