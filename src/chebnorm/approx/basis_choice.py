"""The evaluator's basis, chosen: ``fit(..., basis="auto")``.

A polynomial stored in plain powers of ``x`` on an interval far from 0 has
huge coefficients that cancel; Horner's rule in binary32 then loses what the
fit gained (``1/sqrt(x)`` on ``[1, 4]`` at degree 11: a float32 evaluation
bound 1700 times the fit's). The shifted basis ``t = (x - c)/s``
(:func:`chebnorm.approx.fitting.shift_for`, ``|t| <= 1``) keeps the
coefficients near the Chebyshev ones. :func:`choose` picks between them
from a cheap estimate of the float32 evaluator's error, not from the
exporters' certificates (:mod:`chebnorm.export.evalbound` comes later in the
stages and costs far more): the a priori running-error bound of Horner's rule
(Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., 2002,
section 5.1), evaluated at sample points,

.. math::

    e_n = |c_n - \\hat c_n|, \\qquad
    e_k = e_{k+1} (|t| + \\varepsilon_t) + |a_{k+1}|\\, \\varepsilon_t
          + h(a_{k+1} t) + h(a_k) + |c_k - \\hat c_k|,

with ``a_k`` the partial Horner values of the binary32 coefficients
``\\hat c_k``, ``h(v)`` half an ulp of binary32 at ``v`` (:func:`half_ulp`,
at most ``2^-24 |v|``) and ``\\varepsilon_t`` the error of the computed
shifted variable (``h(x - c')/s + |c - c'|/s``, ``c'`` the centre rounded to
binary32, the first term zero where Sterbenz's lemma makes ``x - c'`` exact;
zero for plain powers). It is an estimate to rank the bases (first
order, sampled), not a bound: the exported constants are proved by
:mod:`chebnorm.export`.

The rule: with ``A`` a basis's fit error (sampled) and ``F = h(max|f|)`` the
binary32 rounding floor (the error of the correctly rounded result), a basis *reaches* the floor when
``A + E <= 2 (A + F)`` (``E`` its estimate). Plain powers are kept when they
reach it (every consumer evaluates them; quantization needs them); else the
shifted basis when it does; else whichever estimate is smaller, plain powers
unless the shifted one is at least twice as good. The choice, the numbers and
the reason are recorded in the table (:class:`BasisChoice`) and re-checked
when it is read.

A FitWarning says when the chosen basis still makes the float32 evaluator
poor: ``A + E > 4 (A + F)`` and ``E > 4 gamma_2n max|f|``, the second being
Higham's a priori bound of Horner's rule at condition number 1
(``gamma_2n = 2n u / (1 - 2n u)``, ``u = 2^-24``, ``n`` the degree): what
any float32 Horner evaluation of degree ``n`` may cost, however well the
basis suits ``f``. A fit far more accurate than float32 (``A`` well below
``F``) thus warns only when the coefficients' conditioning, not the float32
arithmetic itself, spoils its evaluator.

Examples
--------
>>> import numpy as np
>>> x = np.linspace(1.0, 2.0, 5)
>>> float(rounding_estimate([1.0, 0.5], x)) == 2.0 ** -24 + 2.0 ** -23  # h(a_1 x) + h(a_0)
True
"""

from __future__ import annotations

import functools
import math
import sys
from dataclasses import dataclass

import numpy as np

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

#: the estimate of an evaluator that overflows binary32 (the largest double: JSON
#: holds no infinity)
OVERFLOW = sys.float_info.max
#: the largest finite binary32
FLOAT32_MAX = float(np.finfo(np.float32).max)
#: a basis reaches the floor when its estimate is within this factor of (fit + floor)
REACH = 2.0
#: a FitWarning when the chosen basis's estimate exceeds this factor of (fit + floor)
WARN = 4.0
#: sample points of the estimates (equally spaced, endpoints included)
SAMPLES = 513

#: the relative agreement the re-computed estimate must meet on load (the same
#: float64 operations in the same order; the slack covers a libm's last bit)
_AGREE = 2.0 ** -30


@dataclass(frozen=True)
class BasisChoice:
    """How ``basis="auto"`` chose the table's basis, recorded in the table.

    Attributes
    ----------
    basis : {"monomial", "shifted"}
        The basis chosen (the table's :attr:`~chebnorm.approx.CoefficientTable.basis`).
    reason : str
        Why, in words.
    floor : float
        ``h(max|f|)`` on the interval (sampled): half an ulp of binary32 at
        the largest ``|f|``, the error of the correctly rounded result.
    estimates : dict of str to dict
        Per basis considered, ``{"fit": A, "rounding": E}``: the sampled fit
        error and the binary32 Horner estimate of :func:`rounding_estimate`.

    Examples
    --------
    >>> c = BasisChoice("monomial", "plain powers reach the floor", 6e-8,
    ...                 {"monomial": {"fit": 1e-6, "rounding": 2e-7}})
    >>> c.expected()
    'monomial'
    """

    basis: str
    reason: str
    floor: float
    estimates: dict

    def expected(self) -> str:
        """The basis the rule picks from the recorded numbers (what was chosen,
        unless the choice was forced: a single candidate)."""
        return _rule(self.estimates, self.floor)[0]


def sample_points(lo: float, hi: float, n: int = SAMPLES) -> np.ndarray:
    """``n`` equally spaced points of ``[lo, hi]`` (float64, endpoints exact).

    Only correctly rounded operations (no libm function) compute them, so
    every machine gets the same points, and the same re-computed estimate
    when a table is read.

    Parameters
    ----------
    lo, hi : float
        The interval, ``lo <= hi``.
    n : int, optional
        How many points (at least 2).

    Returns
    -------
    numpy.ndarray
        Ascending points, ``lo`` first and ``hi`` last.

    Examples
    --------
    >>> sample_points(0.0, 2.0, 5).tolist()
    [0.0, 0.5, 1.0, 1.5, 2.0]
    """
    k = np.arange(n, dtype=np.float64)
    x = lo + (hi - lo) * (k / (n - 1))
    x[0], x[-1] = lo, hi
    return np.clip(x, lo, hi)


def half_ulp(v) -> np.ndarray:
    """Half an ulp of binary32 at ``|v|`` (the largest error of rounding ``v``
    to nearest): ``2^(e - 24)`` for ``2^e <= |v| < 2^(e + 1)``, and ``2^-150``
    below the normal range (``e < -126``).

    Parameters
    ----------
    v : array_like of float
        Values (float64).

    Returns
    -------
    numpy.ndarray
        Half an ulp of each (0 for 0).

    Examples
    --------
    >>> half_ulp([1.0, 1.5, 2.0, 0.0]).tolist() == [2.0 ** -24, 2.0 ** -24, 2.0 ** -23, 0.0]
    True
    """
    v = np.abs(np.asarray(v, dtype=np.float64))
    # subnormals: the spacing 2^-149 throughout
    return np.where(v == 0, 0.0, np.ldexp(1.0, np.maximum(np.frexp(v)[1] - 25, -150)))


def _variable(x: np.ndarray, shift):
    """The shifted variable ``t`` and the estimate of its binary32 error."""
    if shift is None:
        return x, np.zeros_like(x)
    c, s = float(shift[0]), float(shift[1])
    c32 = float(np.float32(c))
    t = (x - c) / s
    # fl(x - c') is exact where x/c' lies in [1/2, 2] (Sterbenz's lemma)
    exact = (x * c32 > 0) & (np.abs(x) >= abs(c32) / 2) & (np.abs(x) <= 2 * abs(c32))
    rounded = np.where(exact, 0.0, half_ulp(x - c32) / s)
    return t, rounded + abs(c - c32) / s


def rounding_estimate(coeffs, x, shift=None) -> float:
    """The a priori running-error estimate of binary32 Horner's rule.

    Parameters
    ----------
    coeffs : sequence of float
        The polynomial's coefficients (ascending, float64; the evaluator holds
        them rounded to binary32, and that rounding is counted).
    x : numpy.ndarray
        Sample points of the interval.
    shift : tuple of (float, float), optional
        ``(c, s)``: the coefficients are in ``t = (x - c)/s``.

    Returns
    -------
    float
        ``max`` over the points of ``e_0`` (module docstring): the estimated
        largest ``|evaluator - p|``; :data:`OVERFLOW` when a coefficient or
        a partial value is beyond binary32's range (no float32 evaluator).

    Examples
    --------
    >>> import numpy as np
    >>> rounding_estimate([3.0], np.array([0.0, 1.0]))   # a constant: nothing rounded
    0.0
    """
    c = np.asarray(coeffs, dtype=np.float64)
    with np.errstate(all="ignore"):
        held = c.astype(np.float32).astype(np.float64)
        dc = np.abs(c - held)
        t, et = _variable(np.asarray(x, dtype=np.float64), shift)
        at = np.abs(t)
        a = np.full_like(t, held[-1])
        e = np.full_like(t, dc[-1])
        big = np.abs(a)
        for k in range(len(c) - 2, -1, -1):
            prod = a * t
            new = prod + held[k]
            e = e * (at + et) + np.abs(a) * et + half_ulp(prod) + half_ulp(new) + dc[k]
            a = new
            big = np.maximum(big, np.maximum(np.abs(prod), np.abs(new)))
        worst = float(np.max(e))
    if not (math.isfinite(worst) and float(np.max(big)) <= FLOAT32_MAX):
        return OVERFLOW
    return worst


def _horner64(coeffs, x, shift):
    t = x if shift is None else (x - float(shift[0])) / float(shift[1])
    acc = np.full_like(t, float(coeffs[-1]))
    for c in reversed(coeffs[:-1]):
        acc = acc * t + float(c)
    return acc


def _reaches(numbers: dict, floor: float) -> bool:
    """``A + E <= REACH (A + F)``."""
    return numbers["fit"] + numbers["rounding"] <= REACH * (numbers["fit"] + floor)


def _rule(estimates: dict, floor: float) -> tuple[str, str]:
    """``(basis, reason)`` from the per-basis numbers."""
    def total(b):
        return estimates[b]["fit"] + estimates[b]["rounding"]

    def reaches(b):
        return _reaches(estimates[b], floor)

    def say(b):
        if estimates[b]["rounding"] == OVERFLOW:
            return f"{b}: overflows binary32"
        return (f"{b}: float32 estimate {total(b):.3g} (fit {estimates[b]['fit']:.3g} + "
                f"rounding {estimates[b]['rounding']:.3g})")

    head = f"float32 floor {floor:.3g}; " + "; ".join(say(b) for b in estimates)
    if "monomial" in estimates and reaches("monomial"):
        return "monomial", f"plain powers reach {REACH:g}x (fit + floor). {head}"
    if len(estimates) == 1:
        (only,) = estimates
        verdict = "reaches" if reaches(only) else "does not reach"
        return only, f"the only basis offered ({only}) {verdict} {REACH:g}x (fit + floor). {head}"
    if reaches("shifted"):
        return "shifted", f"only the shifted basis reaches {REACH:g}x (fit + floor). {head}"
    if 2 * total("shifted") <= total("monomial"):
        return "shifted", (f"no basis reaches {REACH:g}x (fit + floor); the shifted one "
                           f"is at least 2x better. {head}")
    return "monomial", (f"no basis reaches {REACH:g}x (fit + floor) and the shifted one is "
                        f"not 2x better; plain powers kept. {head}")


def _numbers(coeffs, x, shift, fx):
    p = _horner64(coeffs, x, shift)
    with np.errstate(all="ignore"):
        gap = np.abs(p - fx)
    gap = gap[np.isfinite(gap)]   # a removable singularity's sample is skipped
    fit = float(np.max(gap)) if gap.size else 0.0
    return {"fit": fit, "rounding": rounding_estimate(coeffs, x, shift)}


def _gamma(k: int) -> float:
    """Higham's ``gamma_k = k u / (1 - k u)`` of binary32 (``u = 2^-24``)."""
    u = 2.0 ** -24
    return k * u / (1 - k * u)


def choose(fn_np, lo: float, hi: float, candidates) -> tuple[BasisChoice, str]:
    """Choose among fitted candidates.

    Parameters
    ----------
    fn_np : callable
        ``f`` on float64 arrays (sampled for the fit error and the floor).
    lo, hi : float
        The interval.
    candidates : callable
        ``candidates(basis)`` -> ``(coefficients, shift)`` of the fit in
        ``"monomial"`` or ``"shifted"`` (called for the shifted basis only
        when plain powers do not reach the floor), or None when that basis
        is not offered.

    Returns
    -------
    tuple
        ``(BasisChoice, note)``: the choice, and a warning text when the
        chosen estimate exceeds :data:`WARN` times (fit + floor) and its
        rounding part :data:`WARN` times ``gamma_2n max|f|`` (module
        docstring), or when it overflows binary32; else "".

    Examples
    --------
    >>> import numpy as np
    >>> ch, note = choose(np.exp, 0.0, 1.0, lambda b: ([1.0, 1.0, 0.5], None)
    ...                   if b == "monomial" else None)
    >>> ch.basis
    'monomial'
    """
    x = sample_points(lo, hi)
    with np.errstate(all="ignore"):
        try:
            fx = np.asarray(fn_np(x), dtype=np.float64) * np.ones_like(x)
        except (TypeError, ValueError, ArithmeticError):
            fx = np.full_like(x, np.nan)
    finite = np.abs(fx[np.isfinite(fx)])
    fmax = float(np.max(finite)) if finite.size else 0.0
    floor = float(half_ulp(fmax))
    estimates, degree = {}, 0
    fitted = candidates("monomial")
    if fitted is not None:
        estimates["monomial"] = _numbers(fitted[0], x, fitted[1], fx)
        degree = len(fitted[0]) - 1
    if not estimates or not _reaches(estimates["monomial"], floor):
        fitted = candidates("shifted")
        if fitted is not None:
            estimates["shifted"] = _numbers(fitted[0], x, fitted[1], fx)
            degree = len(fitted[0]) - 1
    basis, reason = _rule(estimates, floor)
    chosen = estimates[basis]
    note = ""
    if chosen["rounding"] == OVERFLOW:
        note = (f"no float32 evaluator: a coefficient or a Horner value is beyond binary32's "
                f"range in every basis tried ({reason}); accepted: a double evaluator, or an "
                f"interval where f and its polynomial stay within binary32")
    elif (chosen["fit"] + chosen["rounding"] > WARN * (chosen["fit"] + floor)
          and chosen["rounding"] > WARN * _gamma(2 * degree) * fmax):
        note = (f"the float32 evaluator's estimated error {chosen['fit'] + chosen['rounding']:.3g} "
                f"exceeds {WARN:g}x (fit {chosen['fit']:.3g} + float32 floor {floor:.3g}), and "
                f"its rounding {WARN:g}x what Horner's rule costs at condition number 1 "
                f"({_gamma(2 * degree) * fmax:.3g}), in every basis tried ({reason}); accepted: "
                f"a double evaluator, a lower degree or a narrower interval (segments)")
    return BasisChoice(basis, reason, floor, estimates), note


@functools.lru_cache(maxsize=256)
def _stored_estimate(coefficients: tuple, shift, interval_float: tuple) -> float:
    """:func:`rounding_estimate` of stored coefficients at the interval's
    sample points (kept: every table built from another by
    ``dataclasses.replace`` checks the same choice again)."""
    return rounding_estimate(coefficients, sample_points(*interval_float), shift)


def read_basis_choice(value, basis: str, coefficients, shift, interval_float):
    """The ``basis_choice`` field of a table file, checked: its numbers, the
    rule's verdict on them, the table's basis, and the chosen basis's
    rounding estimate re-computed from the stored coefficients.

    Parameters
    ----------
    value : dict or None
        The JSON value (None: a table fitted with an explicit basis, or
        written before the field existed).
    basis : str
        The table's basis (from its ``shift``).
    coefficients : tuple of float
        The stored coefficients.
    shift : tuple or None
        The table's shift.
    interval_float : tuple of float
        The interval.

    Returns
    -------
    BasisChoice or None
        The checked choice.

    Raises
    ------
    ValueError
        Naming the ``basis_choice`` field that is malformed or disagrees.

    Examples
    --------
    >>> read_basis_choice(None, "monomial", (1.0,), None, (0.0, 1.0)) is None
    True
    """
    from .schema import BASES, bad, check_object, choice, number, text

    if value is None:
        return None
    check_object(value, "basis_choice", ("basis", "reason", "floor", "estimates"))
    chosen = choice(value["basis"], "basis_choice.basis", BASES)
    floor = number(value["floor"], "basis_choice.floor", nonneg=True)
    est = value["estimates"]
    if not isinstance(est, dict) or not est or not set(est) <= set(BASES):
        raise bad("basis_choice.estimates", "an object keyed by basis names "
                  f"({', '.join(BASES)}), at least one", est)
    estimates = {}
    for b in sorted(est):
        check_object(est[b], f"basis_choice.estimates.{b}", ("fit", "rounding"))
        estimates[b] = {k: number(est[b][k], f"basis_choice.estimates.{b}.{k}", nonneg=True)
                        for k in ("fit", "rounding")}
    out = BasisChoice(chosen, text(value["reason"], "basis_choice.reason"), floor, estimates)
    if chosen != basis:
        raise ValueError(f"basis_choice.basis: {chosen!r}, but the table is in the {basis} "
                         f"basis; accepted: the table's basis")
    if chosen not in estimates or out.expected() != chosen:
        raise ValueError(f"basis_choice.basis: {chosen!r} is not what the rule picks from "
                         f"basis_choice.estimates and basis_choice.floor")
    again = _stored_estimate(tuple(coefficients), None if shift is None else tuple(shift),
                             tuple(interval_float))
    if abs(again - estimates[chosen]["rounding"]) > _AGREE * max(again, 1e-300):
        raise ValueError(f"basis_choice.estimates.{chosen}.rounding: stated "
                         f"{estimates[chosen]['rounding']!r}, but the stored coefficients give "
                         f"{again!r}")
    return out
