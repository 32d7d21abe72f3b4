"""Tight, rigorous bounds of what an exported evaluator computes.

The exporters state ``|evaluator(x) - f(x)| <= B`` for every input of the
interval. :func:`horner_bound` computes ``B`` for the evaluator's actual
operation sequence -- Horner's rule in binary64, binary32 (with or without
flushing subnormals) or integer fixed point, optionally after ``t = x*x``
(even/odd evaluators, times ``x`` at the end for odd) or ``t = (x - c)/s``
(shifted tables) -- instead of the a priori ``gamma_2n sum |c_k| M^k``:

1. the interval is cut into ``subintervals`` pieces ``X_i`` (equal widths);
2. on each, interval arithmetic (binary64 with every endpoint moved one ulp
   outward, so the enclosures are rigorous) encloses the *exact* partial
   Horner values ``P_k(X_i)``;
3. each operation's rounding error is bounded by half an ulp of the largest
   magnitude its (computed) operands can produce there -- binade-aware, so a
   result in ``[1, 2)`` costs ``2^-24`` in binary32, not ``u |value|`` of the
   largest value anywhere -- and earlier errors are carried through the later
   operations (``|a~ t~ - a t| <= e_a (|t| + e_t) + |a| e_t``);
4. a multiply-add step is bounded both fused (one rounding) and unfused (two)
   and the larger taken, so the bound holds whichever subset of the steps a
   compiler fuses (``-ffp-contract``, ``fma``, GLSL/WGSL/HLSL);
5. the evaluated coefficients may differ from the certified ones (float32
   rounding of double coefficients): ``|sum (c_k - r_k) x^k|`` is enclosed
   on ``X_i`` too;
6. the total is ``A + max_i (D_i + R_i)``: the certified approximation
   bound ``A`` (global) plus the worst local coefficient and rounding error.

Every quantity is a binary64 number rounded upward (``nextafter``), so the
result is an upper bound; the tests compare it with an exhaustive run of the
compiled evaluator over every float32 of the interval, and the same
bound is proved by Gappa from the script :mod:`chebnorm.export.gappa` prints.
Where it is loose (several roundings of similar size, which never all reach
their worst case on one input) a float32 evaluator states instead the
exhaustive certificate of :mod:`chebnorm.export.certificate`.

Examples
--------
>>> from fractions import Fraction
>>> b = horner_bound([1.0, 0.5], [1.0, 0.5], Fraction(0), 1.0, 2.0, BINARY32)
>>> 3 * 2.0 ** -24 <= b.local < 3.0001 * 2.0 ** -24  # half an ulp of 1 and of 2 (largest results)
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

# an implementation module of chebnorm.export: the API is what chebnorm.export exports
__all__: list[str] = []

#: pieces of the interval (the Gappa scripts bisect as finely)
DEFAULT_SUBINTERVALS = 64

#: relative headroom added to a stated bound (rounded up to a float) so that
#: Gappa, whose per-piece enclosures differ slightly from ours, proves it
PROOF_HEADROOM = Fraction(1, 32)


@dataclass(frozen=True)
class Arithmetic:
    """One evaluator arithmetic.

    ``kind`` is ``"float"`` (``precision`` significand bits, ``emin`` the
    smallest normal exponent, ``flush``: subnormal results may become 0) or
    ``"fixed"`` (``frac_bits``: every product rounded to ``2^-frac_bits`` to
    nearest, the sums exact).

    Attributes
    ----------
    kind : {"float", "fixed"}
        Floating point (round to nearest even) or integer fixed point.
    precision : int, default 0
        For ``"float"``: the significand bits, 53 (binary64) or 24
        (binary32); other values print Gappa's binary32 operator.
    emin : int, default 0
        For ``"float"``: the exponent of the smallest normal number
        (``-1022``, ``-126``).
    flush : bool, default False
        For ``"float"``: a subnormal result may be flushed to zero (GPU
        shading languages); each rounding then also costs up to ``2**emin``
        where a result can be subnormal.
    frac_bits : int, default 0
        For ``"fixed"``: the fractional bits ``F`` (``>= 0``) each product is
        rounded to (ties up); ``0`` rounds nothing.

    Examples
    --------
    >>> BINARY32.gappa, fixed_arithmetic(12).gappa
    ('float<ieee_32,ne>', 'fixed<-12,nu>')
    """

    kind: str
    precision: int = 0
    emin: int = 0
    flush: bool = False
    frac_bits: int = 0

    @property
    def gappa(self) -> str:
        """Gappa's rounding operator of this arithmetic (round to nearest; the
        fixed-point evaluators round ties up)."""
        if self.kind == "fixed":
            return f"fixed<-{self.frac_bits},nu>"
        return "float<ieee_64,ne>" if self.precision == 53 else "float<ieee_32,ne>"


#: IEEE 754 binary64 (``double``), round to nearest even, subnormals kept
BINARY64 = Arithmetic("float", 53, -1022)
#: IEEE 754 binary32 (``float``), round to nearest even, subnormals kept
BINARY32 = Arithmetic("float", 24, -126)
#: binary32 as the shading languages allow it: subnormal results may flush to 0
BINARY32_FTZ = Arithmetic("float", 24, -126, flush=True)


def fixed_arithmetic(frac_bits: int) -> Arithmetic:
    """The integer Horner evaluator with ``frac_bits`` fractional bits.

    Parameters
    ----------
    frac_bits : int
        The fractional bits ``F`` of the integers (values are
        ``q * 2**-F``), ``>= 0``; converted with ``int()``.

    Returns
    -------
    Arithmetic
        ``Arithmetic("fixed", frac_bits=F)``: each product rounded to
        ``2**-F`` (ties up), each sum exact.

    Examples
    --------
    >>> fixed_arithmetic(24).frac_bits
    24
    """
    return Arithmetic("fixed", frac_bits=int(frac_bits))


@dataclass(frozen=True)
class EvalBound:
    """A bound of ``|evaluator(x) - f(x)|`` and its parts.

    ``approximation`` is the certified ``|p - f|`` taken as a hypothesis,
    ``local`` the largest over the pieces of (coefficient difference +
    rounding), ``total`` = their sum rounded up to a double, ``stated`` the
    value printed (``total`` plus :data:`PROOF_HEADROOM`, rounded up to 12
    significand bits so its decimal form is short), ``subintervals`` the
    pieces.

    Attributes
    ----------
    approximation : Fraction
        ``A``, the certified ``sup |p - f|`` of the reference coefficients,
        taken as a hypothesis.
    local : Fraction
        ``max_i (D_i + R_i)`` over the pieces ``X_i``: the enclosure of the
        coefficient difference ``|sum (c_k - r_k) x^k|`` plus the bound of
        the rounding errors, both upper bounds.
    total : float
        ``A + local`` rounded up to a double.
    stated : float
        The value an exporter prints: ``A + local (1 + PROOF_HEADROOM)``
        rounded up to 12 significand bits; ``stated >= total``.
    subintervals : int
        The number of pieces of the interval (``1 .. 2**20``).

    Notes
    -----
    For Horner's rule :math:`\\hat a_n = c_n`,
    :math:`\\hat a_k = \\mathrm{fl}(\\hat a_{k+1} \\hat t + c_k)`, the error
    :math:`e_k \\ge |\\hat a_k - a_k|` is carried step by step on each piece:

    .. math::

        e_k \\le e_{k+1} (|t| + e_t) + |a_{k+1}|\\, e_t
              + \\tfrac12 \\mathrm{ulp}(\\max|a_{k+1} t|)
              + \\tfrac12 \\mathrm{ulp}(\\max|a_k|),

    with the magnitudes enclosed by interval arithmetic on the piece; a fused
    multiply-add drops the product's half ulp (one rounding), and the larger
    of the fused and unfused bounds is taken. A sum that is exact (both
    addends on a grid the result fits) costs nothing.
    Its a priori form is Higham's :math:`\\gamma_{2n} \\sum_k |c_k| M^k`
    ([1]_, eq. 5.3); the binade-aware form is usually an order of magnitude
    tighter. Gappa [2]_ proves the same bound from the script of
    :func:`chebnorm.export.gappa.gappa_script`.

    References
    ----------
    .. [1] N. J. Higham, *Accuracy and Stability of Numerical Algorithms*,
       2nd ed., SIAM, 2002, eq. (5.3).
    .. [2] G. Melquiond, Gappa, https://gappa.gitlabpages.inria.fr/ ;
       F. de Dinechin, C. Lauter, G. Melquiond, "Certifying the
       floating-point implementation of an elementary function using
       Gappa", IEEE Transactions on Computers 60(2), 2011.

    Examples
    --------
    >>> b = horner_bound([2.0], [2.0], Fraction(1, 8), 0.0, 1.0, BINARY64)
    >>> b.total >= 0.125 and b.local < 1e-300   # a constant: nothing rounded
    True
    """

    approximation: Fraction
    local: Fraction
    total: float
    stated: float
    subintervals: int


def _up(v):
    return np.nextafter(v, np.inf)


def _down(v):
    return np.nextafter(v, -np.inf)


def _mul(al, ah, bl, bh):
    p = np.stack([al * bl, al * bh, ah * bl, ah * bh])
    return _down(p.min(axis=0)), _up(p.max(axis=0))


def _add(al, ah, bl, bh):
    return _down(al + bl), _up(ah + bh)


def _mag(lo, hi):
    return np.maximum(np.abs(lo), np.abs(hi))


def _enclose(value: Fraction) -> tuple[float, float]:
    f = float(value)
    lo = f if Fraction(f) <= value else math.nextafter(f, -math.inf)
    hi = f if Fraction(f) >= value else math.nextafter(f, math.inf)
    return lo, hi


def _half_ulp(arith: Arithmetic, big, small):
    """Bound of one rounding's error for results of magnitude at most ``big``
    (and at least ``small``)."""
    if arith.kind == "fixed":  # 0 fractional bits: nothing is rounded
        return np.full_like(big, 2.0 ** -(arith.frac_bits + 1) if arith.frac_bits else 0.0)
    e = np.frexp(big)[1]
    h = np.ldexp(1.0, np.maximum(e - arith.precision - 1, arith.emin - arith.precision))
    h = np.where(big == 0, 0.0, h)
    if arith.flush:
        h = h + np.where(small < 2.0 ** arith.emin, 2.0 ** arith.emin, 0.0)
    return h


def _step(arith, acc, e, var, et, c):
    """One Horner step ``acc * t + c``: the exact enclosure of the new partial
    value and the bound of the computed one's error (fused or unfused)."""
    (pl, ph), (tl, th) = acc, var
    ml, mh = _mul(pl, ph, tl, th)
    nl, nh = _add(ml, mh, np.full_like(ml, c), np.full_like(ml, c))
    mag_p, mag_t = _mag(pl, ph), _mag(tl, th)
    carried = _up(_up(e * _up(mag_t + et)) + _up(mag_p * et))
    # the computed operands' exact product lies in the exact product +- carried
    pbig = _up(_mag(ml, mh) + carried)
    psmall = np.maximum(_down(np.where(ml * mh > 0, np.minimum(np.abs(ml), np.abs(mh)), 0.0)
                              - carried), 0.0)
    if arith.kind == "fixed":  # the product rounded, the integer sum exact
        return (nl, nh), _up(carried + _half_ulp(arith, pbig, psmall))
    e_prod = _up(carried + _half_ulp(arith, pbig, psmall))

    def rounded_sum(err, grid=None):
        big = _up(_mag(nl, nh) + err)
        small = np.maximum(_down(np.where(nl * nh > 0, np.minimum(np.abs(nl), np.abs(nh)), 0.0)
                                 - err), 0.0)
        h = _half_ulp(arith, big, small)
        if grid is not None:  # both addends on the grid and the sum fits: exact
            exact = big <= np.ldexp(grid, arith.precision)
            # an exact but subnormal sum may still be flushed (error < 2^emin)
            flushed = (small < 2.0 ** arith.emin) if arith.flush else np.zeros_like(exact)
            h = np.where(exact, np.where(flushed, 2.0 ** arith.emin, 0.0), h)
        return _up(err + h)

    return (nl, nh), np.maximum(rounded_sum(e_prod, _sum_grid(arith, psmall, c)),
                                rounded_sum(carried))


def _grid(arith, small):
    """The spacing every float of magnitude at least ``small`` is a multiple of."""
    e = np.frexp(small)[1]
    g = np.ldexp(1.0, np.maximum(e - arith.precision, arith.emin - arith.precision + 1))
    return np.where(small == 0, 2.0 ** (arith.emin - arith.precision + 1), g)


def _sum_grid(arith, psmall, c):
    """The grid of ``fl(product) + c``: the coarser grids' finer one (the
    rounded product's magnitude is at least the float below ``psmall``)."""
    g = _grid(arith, _down(psmall))
    if c != 0:
        g = np.minimum(g, _grid(arith, np.full_like(psmall, abs(c))))
    return g


def _variable(arith, xl, xh, parity, shift):
    """The enclosure of the exact Horner variable and its computed error."""
    zero = np.zeros_like(xl)
    if parity is not None:
        small = np.where(xl * xh > 0, np.minimum(np.abs(xl), np.abs(xh)), 0.0)
        big = _mag(xl, xh)
        tl, th = _down(small * small), _up(big * big)
        return (tl, th), _half_ulp(arith, th, tl)
    if shift is None:
        return (xl, xh), zero
    c, s, c_t, s_t, exact_scale = shift  # Fractions, s_t: the divisor in the type
    # exact t = (x - c)/s; computed fl(fl(x - c_t) * (1/s)) or fl(fl(x - c_t) / s_t)
    cl, ch = _enclose(c)
    inv_l, inv_h = _enclose(1 / s)
    tl, th = _mul(*_add(xl, xh, np.full_like(xl, -ch), np.full_like(xl, -cl)),
                  np.full_like(xl, inv_l), np.full_like(xl, inv_h))
    dl, dh = _add(xl, xh, np.full_like(xl, -float(c_t)), np.full_like(xl, -float(c_t)))
    d_err = _half_ulp(arith, _mag(dl, dh), zero)  # 0-or-half-ulp: Sterbenz not assumed
    _, inv_t_hi = _enclose(1 / s_t)
    err = _up(d_err * inv_t_hi)
    _, shift_hi = _enclose(abs(c - c_t) / s)
    _, scale_hi = _enclose(abs(1 / s_t - 1 / s))
    err = _up(_up(err + shift_hi) + _up(_up(_mag(dl, dh)) * scale_hi))
    big = _up(_up(_mag(dl, dh) + d_err) * inv_t_hi)
    if not exact_scale:
        err = _up(err + _half_ulp(arith, big, zero))
    else:  # a product by a power of two is exact unless it underflows
        err = _up(err + (2.0 ** (arith.emin - arith.precision) if arith.kind == "float" else 0.0))
    return (tl, th), err


def horner_bound(coeffs, ref_coeffs, approx_bound, lo: float, hi: float, arith: Arithmetic, *,
                 parity: int | None = None, shift=None,
                 subintervals: int = DEFAULT_SUBINTERVALS) -> EvalBound:
    """The bound of ``|evaluator(x) - f(x)|`` for ``x`` in ``[lo, hi]``.

    Parameters
    ----------
    coeffs : sequence of float
        The coefficients the evaluator holds (numbers of ``arith``), ascending.
    ref_coeffs : sequence of float
        The coefficients whose ``|p - f| <= approx_bound`` is certified.
    approx_bound : Fraction
        The certified approximation bound ``A`` (hypothesis).
    lo, hi : float
        The inputs (doubles; every input lies between them).
    arith : Arithmetic
        :data:`BINARY64`, :data:`BINARY32`, :data:`BINARY32_FTZ` or
        :func:`fixed_arithmetic`.
    parity : {None, 0, 1}
        Horner's rule in ``t = x*x`` over the even (0) or odd (1, times
        ``x`` at the end) coefficients.
    shift : tuple, optional
        ``(c, s, c_t, s_t, exact_scale)`` (Fractions and a bool): the
        evaluator forms ``t = (x - c_t) * (1/s)`` (``exact_scale``, ``s`` a
        power of two) or ``(x - c_t) / s_t``; the polynomial is in
        ``(x - c)/s``.
    subintervals : int
        Equal pieces of ``[lo, hi]``.

    Returns
    -------
    EvalBound
        ``A``, the local part and the total and stated bounds.

    Raises
    ------
    ValueError
        When ``coeffs`` is empty or ``ref_coeffs`` has another length, when
        ``subintervals`` is not an int in ``1 .. 2**20``, or when
        ``lo > hi``.

    Examples
    --------
    >>> from fractions import Fraction
    >>> c = [2.2764573097229004, -2.463439702987671, 1.5977978706359863, -0.4108169376850128]
    >>> b = horner_bound(c, c, Fraction(0), 0.8535533905932738, 1.0, BINARY32)
    >>> 1e-7 < b.local < 2e-7       # the a priori formula gives 2.4e-6
    True
    """
    n = len(coeffs) - 1
    if n < 0 or len(ref_coeffs) != len(coeffs):
        raise ValueError(f"coeffs, ref_coeffs: {len(coeffs)} and {len(ref_coeffs)} numbers; "
                         f"expected as many, at least one")
    if not (isinstance(subintervals, int) and 1 <= subintervals <= 2 ** 20):
        raise ValueError(f"subintervals = {subintervals!r}; accepted: an int in 1..2^20")
    lo, hi = float(lo), float(hi)
    if not lo <= hi:
        raise ValueError(f"lo, hi = {lo!r}, {hi!r}: expected lo <= hi")
    edges = np.linspace(lo, hi, subintervals + 1)
    edges[0], edges[-1] = lo, hi
    xl, xh = edges[:-1].copy(), edges[1:].copy()
    # the coefficient differences D_i (in the polynomial's own variable)
    diffs = [_enclose(Fraction(c) - Fraction(r)) for c, r in zip(coeffs, ref_coeffs)]
    var, et = _variable(arith, xl, xh, parity, shift)
    if shift is not None:
        pvar = var
    else:
        pvar = (xl, xh)
    dl, dh = np.full_like(xl, diffs[-1][0]), np.full_like(xl, diffs[-1][1])
    for a, b in reversed(diffs[:-1]):
        dl, dh = _add(*_mul(dl, dh, *pvar), np.full_like(xl, a), np.full_like(xl, b))
    d = _mag(dl, dh)
    cs = [float(c) for c in coeffs]
    if parity is not None:
        cs = cs[parity::2]
    acc = (np.full_like(xl, cs[-1]), np.full_like(xl, cs[-1]))
    e = np.zeros_like(xl)
    for c in reversed(cs[:-1]):
        acc, e = _step(arith, acc, e, var, et, c)
    if parity == 1:  # the final product by x (exact x)
        ml, mh = _mul(*acc, xl, xh)
        carried = _up(e * _mag(xl, xh))
        big = _up(_mag(ml, mh) + carried)
        e = _up(carried + _half_ulp(arith, big, np.zeros_like(big)))
    local = max(Fraction(float(v)) for v in _up(d + e))
    total = Fraction(approx_bound) + local
    from chebnorm.core.numeric import float_up

    return EvalBound(approximation=Fraction(approx_bound), local=local, total=float_up(total),
                     stated=_stated(Fraction(approx_bound), local), subintervals=subintervals)


def _stated(approx: Fraction, local: Fraction) -> float:
    """``approx + local * (1 + PROOF_HEADROOM)`` rounded up to a double."""
    from chebnorm.core.numeric import float_up

    return float_up(approx + local * (1 + PROOF_HEADROOM))


@dataclass(frozen=True)
class Evaluator:
    """One exported evaluator and the constant that states its bound: what
    :func:`horner_bound` bounds and :func:`chebnorm.export.gappa.gappa_script`
    proves.

    ``constant``: the macro or shader constant; ``function``: the evaluator's
    name; ``pieces``: one :class:`Piece` per polynomial (a piecewise table
    has one per segment, its local variable ``t`` in ``[lo, hi]``).

    Attributes
    ----------
    constant : str
        The macro or shader constant that states the bound
        (``CHEBNORM_<NAME>_F_EVAL_ERROR_BOUND``, ...).
    function : str
        The evaluator's name in the generated code.
    arith : Arithmetic
        Its arithmetic: :data:`BINARY64`, :data:`BINARY32`,
        :data:`BINARY32_FTZ` or :func:`fixed_arithmetic`.
    pieces : tuple of Piece
        One per polynomial, at least one.
    parity : {None, 0, 1}, default None
        Horner's rule in ``t = x*x`` over the even (0) or odd (1, times
        ``x`` at the end) coefficients; None: in ``x`` (or the shifted
        ``t``).
    shift : tuple or None, default None
        ``(c, s, c_t, s_t, exact_scale)`` of a shifted table, as
        :func:`horner_bound` takes it.
    subintervals : int, default DEFAULT_SUBINTERVALS
        The pieces each polynomial's range is cut into (``1 .. 2**20``).
    target : tuple of str, default ()
        ``(expression, variable)`` of ``f`` (the table's), for the
        exhaustive certificate of a float32 evaluator
        (:func:`chebnorm.export.certificate.stated_bound`); empty: none.

    Examples
    --------
    >>> e = Evaluator("C_F_EVAL_ERROR_BOUND", "c_f", BINARY32,
    ...               (Piece((1.0, 0.5), (1.0, 0.5), Fraction(0), 1.0, 2.0),))
    >>> e.bound().stated > 0
    True
    """

    constant: str
    function: str
    arith: Arithmetic
    pieces: tuple
    parity: int | None = None
    shift: tuple | None = None
    subintervals: int = DEFAULT_SUBINTERVALS
    target: tuple = ()

    def bound(self) -> EvalBound:
        """The bound over every piece: the largest piece's."""
        per = [horner_bound(p.coeffs, p.ref_coeffs, p.approx_bound, p.lo, p.hi, self.arith,
                            parity=self.parity, shift=self.shift, subintervals=self.subintervals)
               for p in self.pieces]
        return max(per, key=lambda b: b.approximation + b.local)


@dataclass(frozen=True)
class Piece:
    """One polynomial of an :class:`Evaluator`: the coefficients it holds, the
    certified ones (``|p - f| <= approx_bound`` on ``[lo, hi]``) and its
    input range.

    Attributes
    ----------
    coeffs : tuple of float
        The coefficients the evaluator holds (numbers of its arithmetic),
        ascending powers.
    ref_coeffs : tuple of float
        The certified coefficients, as many as ``coeffs``.
    approx_bound : Fraction
        Their certified ``sup |p - f|`` on ``[lo, hi]``.
    lo, hi : float
        The range of the evaluator's variable (``x``, or the segment's local
        ``t``), ``lo <= hi``.

    Examples
    --------
    >>> Piece((1.0,), (1.0,), Fraction(0), 0.0, 1.0).lo
    0.0
    """

    coeffs: tuple
    ref_coeffs: tuple
    approx_bound: Fraction
    lo: float
    hi: float
