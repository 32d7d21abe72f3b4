"""``fit`` and ``quantize``: the public entry points of the approximation stage."""

from __future__ import annotations

import functools
import math
from importlib.metadata import PackageNotFoundError, version as _pkg_version

import numpy as np
import sympy as sp
from flint import arb

from .certify import Certificate, _float_down, _float_up, certify
from .expr import Function1D, compare, enclose, parse_function, parse_number
from .fitting import chebyshev_interpolant, cheb_to_monomial, polish, remez, shift_for
from .table import CoefficientTable, FixedPoint

__all__ = ["fit", "quantize", "warnings_of", "MAX_DEGREE", "Interval", "check_interval"]

MAX_DEGREE = 30
KINDS = ("chebyshev", "minimax")
ERROR_KINDS = ("abs", "rel")
BASES = ("monomial", "shifted")


@functools.lru_cache(maxsize=1)
def _versions() -> dict[str, str]:
    out = {}
    for name in ("chebnorm", "numpy", "mpmath", "sympy", "python-flint"):
        try:
            out[name] = _pkg_version(name)
        except PackageNotFoundError:
            out[name] = "unknown"
    return out


class Interval:
    """Exact endpoints (sympy) with their float values. Internal.

    ``lo``/``hi`` are exact; ``lo_f``/``hi_f`` the nearest floats (stored in
    tables as ``interval_float``); ``lo_in``/``hi_in`` the floats nearest
    *inside* the interval (where it is sampled and its maximum located).
    ``binary`` names the endpoints given as Python floats, whose exact binary
    value is used (``0.1`` as a float is 3602879701896397/36028797018963968).
    """

    def __init__(self, lo, hi):
        self.lo = parse_number(lo)
        self.hi = parse_number(hi)
        self.binary = {name: v for name, v in (("LO", lo), ("HI", hi))
                       if isinstance(v, (float, np.floating))}
        balls = []
        for name, value in (("LO", self.lo), ("HI", self.hi)):
            ball = enclose(value, 128)
            if ball is None or not abs(ball) < arb(2) ** 1023:
                raise ValueError(f"interval endpoint {name} = {value} is outside the float64 "
                                 f"range; accepted: a finite real number below 2^1023 in "
                                 f"magnitude")
            balls.append(ball)
        try:
            order = compare(self.lo, self.hi)
        except ValueError:
            order = 0
        if order >= 0:
            raise ValueError(f"interval [{self.lo}, {self.hi}] is empty or reversed: "
                             f"LO must be strictly less than HI")
        self.lo_f, self.hi_f = (_nearest_float(b) for b in balls)
        self.lo_in, self.hi_in = _float_up(balls[0]), _float_down(balls[1])
        if not self.lo_in <= self.hi_in:
            raise ValueError(f"interval [{self.lo}, {self.hi}] holds no float64 number; "
                             f"accepted: an interval wider than one float64 spacing")

    @property
    def strings(self) -> tuple[str, str]:
        return (sp.sstr(self.lo), sp.sstr(self.hi))

    def binary_note(self) -> str | None:
        """Which endpoints were binary floats, and their exact values (or None)."""
        if not self.binary:
            return None
        parts = [f"{name} = {float(v)!r} was given as a float64, used at its exact binary "
                 f"value {sp.sstr(self.lo if name == 'LO' else self.hi)}"
                 for name, v in self.binary.items()]
        return "; ".join(parts) + " (pass the text '0.1' for the exact decimal)"


def _nearest_float(ball: arb) -> float:
    """The float64 nearest the midpoint of a narrow ball."""
    mid = ball.mid()
    f = float(mid)
    best = min((f, math.nextafter(f, -math.inf), math.nextafter(f, math.inf)),
               key=lambda c: abs(arb(c) - mid))
    return best


def check_interval(fn: Function1D, iv: Interval, samples: int = 2001) -> np.ndarray:
    """Sample ``f`` on the interval and reject it where it is not finite and real.

    Returns the samples. The certification later proves finiteness on the
    whole interval; this check only gives an early, precise message.
    """
    x = np.linspace(iv.lo_in, iv.hi_in, samples)
    x[0], x[-1] = iv.lo_in, iv.hi_in
    with np.errstate(all="ignore"):
        try:
            y = np.asarray(sp.lambdify(fn.var, fn.expr, ["scipy", "numpy"])(x.astype(complex)), dtype=complex)
        except (ZeroDivisionError, OverflowError):
            y = np.full(x.shape, np.nan, dtype=complex)
        y = y * np.ones_like(x)
    bad = ~np.isfinite(y) | (np.abs(y.imag) > 1e-12 * np.maximum(1.0, np.abs(y.real)))
    if bad.any():
        where = x[np.argmax(bad)]
        raise ValueError(f"{fn.expr} is not finite and real on [{iv.lo}, {iv.hi}] "
                         f"(for example at {fn.var} = {where:.6g}); accepted: an interval "
                         f"where the function is defined, finite and real")
    return y.real


def _certify_both(fn, coeffs, iv, need_rel: bool, shift=None):
    cert_abs = certify(fn, coeffs, iv.lo, iv.hi, "abs", shift=shift)
    try:
        cert_rel = certify(fn, coeffs, iv.lo, iv.hi, "rel", shift=shift)
    except ValueError:
        if need_rel:
            raise ValueError(f"relative error is undefined: {fn.expr} vanishes on "
                             f"[{iv.lo}, {iv.hi}]; accepted for error='rel': an interval "
                             f"where the function has no zero") from None
        cert_rel = None
    return cert_abs, cert_rel


def fit(expr, interval, degree: int, kind: str = "chebyshev", error: str = "abs", *,
        var: str = "x", name: str | None = None, frac_bits: int | None = None,
        command: str | None = None, basis: str = "monomial") -> CoefficientTable:
    """Fit a polynomial of ``degree`` to ``expr`` on ``interval`` and certify it.

    ``kind="chebyshev"``: interpolation at the Chebyshev nodes (mpmath).
    ``kind="minimax"``: the Remez exchange, minimizing the absolute
    (``error="abs"``) or relative (``error="rel"``) error. Every table carries
    rigorous bounds of both errors (see :mod:`chebnorm.approx.certify`).
    With ``frac_bits`` the table also gets a re-certified fixed-point part.
    ``basis="shifted"`` stores the polynomial in ``t = (x - c)/s`` (``c``
    the midpoint, ``s`` a power of two at least the half-width; recorded in
    ``table.shift``), well conditioned on narrow or offset intervals where
    plain powers of ``x`` (``basis="monomial"``, the default) lose accuracy:

    >>> m = fit("sin(x)", ("100", "101"), 12, kind="minimax")
    >>> s = fit("sin(x)", ("100", "101"), 12, kind="minimax", basis="shifted")
    >>> s.shift, s.abs_error_bound < 1e-16, m.abs_error_bound > 1e-3
    ((100.5, 0.5), True, True)

    Seed 000, method 4 (claim C5): the degree-2 Chebyshev fit of
    ``1/sqrt(2+z)`` on ``[sqrt(2), 2]``:

    >>> t = fit("1/sqrt(2+z)", ("sqrt(2)", 2), 2, var="z")
    >>> [round(c, 5) for c in t.coefficients]
    [0.68076, -0.11881, 0.01422]
    >>> round(t.max_abs_error, 7), t.abs_error_bound >= t.max_abs_error
    (2.16e-05, True)

    Choice of degree: each extra degree buys roughly a factor
    ``(hi - lo) / (4 * distance to the nearest singularity)`` of accuracy.
    Possible issues: coefficients are stored in the original variable's
    monomial basis, which is ill-conditioned on intervals far from 0 at high
    degree; the certified bound is that of the stored floats, so it stays
    honest, but it may then sit above the minimax error.
    """
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)):
        raise ValueError(f"degree {degree!r} is not an integer; accepted: 0 <= degree <= {MAX_DEGREE}")
    degree = int(degree)
    if not 0 <= degree <= MAX_DEGREE:
        raise ValueError(f"degree {degree} is out of range; accepted: 0 <= degree <= {MAX_DEGREE}")
    if kind not in KINDS:
        raise ValueError(f"kind {kind!r} is unknown; accepted: {', '.join(KINDS)}")
    if error not in ERROR_KINDS:
        raise ValueError(f"error kind {error!r} is unknown; accepted: {', '.join(ERROR_KINDS)}")
    if basis not in BASES:
        raise ValueError(f"basis {basis!r} is unknown; accepted: {', '.join(BASES)}")
    if basis != "monomial" and frac_bits is not None:
        raise ValueError("frac-bits with basis shifted is not supported; accepted: "
                         "basis monomial for fixed-point tables")
    try:
        lo, hi = interval
    except (TypeError, ValueError):
        raise ValueError(f"interval {interval!r} must be a pair (LO, HI)") from None
    fn = expr if isinstance(expr, Function1D) else parse_function(expr, var)
    iv = Interval(lo, hi)
    samples = check_interval(fn, iv)
    if error == "rel" and (np.any(samples == 0) or np.ptp(np.sign(samples)) > 0):
        raise ValueError(f"relative error is undefined: {fn.expr} vanishes on [{iv.lo}, {iv.hi}]; "
                         f"accepted for error='rel': an interval where the function has no zero")

    shift = shift_for(iv.lo_f, iv.hi_f) if basis == "shifted" else None
    coeffs, notes = _fit_coefficients(fn, iv, degree, kind, error, shift)
    cert_abs, cert_rel = _certify_both(fn, coeffs, iv, error == "rel", shift)
    notes += _certificate_notes(abs_error_bound=cert_abs, rel_error_bound=cert_rel)
    provenance = dict(_versions())
    provenance["command"] = command or (
        f"chebnorm.fit({str(fn.expr)!r}, {iv.strings!r}, {degree}, kind={kind!r}, "
        f"error={error!r}, var={var!r})")
    if iv.binary_note():
        provenance["binary_endpoints"] = iv.binary_note()
    if notes:
        provenance["warnings"] = " | ".join(notes)
    table = CoefficientTable(
        name=name or "table", expression=sp.sstr(fn.expr), variable=fn.var.name,
        interval=iv.strings, interval_float=(iv.lo_f, iv.hi_f), degree=degree, kind=kind,
        error_kind=error, coefficients=tuple(coeffs),
        abs_error_bound=cert_abs.bound, rel_error_bound=None if cert_rel is None else cert_rel.bound,
        max_abs_error=cert_abs.maximum, max_abs_at=cert_abs.at,
        max_rel_error=None if cert_rel is None else cert_rel.maximum,
        max_rel_at=None if cert_rel is None else cert_rel.at,
        provenance=provenance, shift=shift)
    if frac_bits is not None:
        table = quantize(table, frac_bits)
    return table


def _fit_coefficients(fn: Function1D, iv: Interval, degree: int, kind: str, error: str,
                      shift: tuple[float, float] | None) -> tuple[list[float], list[str]]:
    """The fitted float coefficients (in ``t = (x - c)/s`` with ``shift``)
    and the notes on how the fit went."""
    notes = []
    if kind == "chebyshev" and shift is not None:
        c, s = (sp.Float(v, 60) for v in shift)
        f_mp = fn.mpmath
        coeffs = chebyshev_interpolant(lambda t: f_mp(c + s * t), sp.N((iv.lo - c) / s, 50),
                                       sp.N((iv.hi - c) / s, 50), degree)
    elif kind == "chebyshev":
        coeffs = chebyshev_interpolant(fn.mpmath, sp.N(iv.lo, 50), sp.N(iv.hi, 50), degree)
    else:
        f_np = fn.numpy
        weight = None if error == "abs" else (lambda x: 1.0 / np.abs(f_np(x)))
        res = remez(f_np, weight, iv.lo_f, iv.hi_f, degree)
        cheb = res.cheb
        polished = res.noise_limited and res.ref is not None and len(res.ref) == degree + 2
        if polished:
            # the float64 solve limits the error: re-solve the same reference in 50 digits
            cheb = polish(fn.mpmath, iv.lo_f, iv.hi_f, res.ref, degree, relative=error == "rel")
        coeffs = cheb_to_monomial(cheb, iv.lo_f, iv.hi_f, *(shift or (0.0, 1.0)))
        if not res.converged and not polished:
            notes.append(
                f"the Remez exchange did not converge: the coefficients are its best iterate "
                f"(iteration {res.iterations}: levelled error {res.levelled:.3e}, largest "
                f"error {res.max_error:.3e}), not the minimax polynomial, and kind chebyshev "
                f"may be closer; the certified bounds hold")
    return coeffs, notes


def _certificate_notes(**certs: Certificate | None) -> list[str]:
    """One warning per certificate that missed its ``(1 + tol)`` tightness."""
    return [f"{field} is rigorous but not within 1 + 2^-8 of the supremum: {c.reason}"
            for field, c in certs.items() if c is not None and not c.tight]


def warnings_of(table: CoefficientTable) -> list[str]:
    """The warnings a table's provenance carries (Remez not converged, a
    certificate that missed its tightness), one string each.

    >>> warnings_of(fit("exp(x)", ("0", "1"), 2))
    []
    """
    text = table.provenance.get("warnings", "")
    return [w for w in text.split(" | ") if w]


def _check_frac_bits(frac_bits, coeffs, word_bits) -> None:
    if isinstance(frac_bits, bool) or not isinstance(frac_bits, (int, np.integer)) or frac_bits < 0:
        raise ValueError(f"frac-bits {frac_bits!r} is not a non-negative integer")
    limit = 2 ** (word_bits - 1) - 1
    biggest = max(abs(c) for c in coeffs)
    if biggest == 0:
        return
    max_f = math.floor(math.log2((limit + 0.5) / biggest))
    for k, c in enumerate(coeffs):
        if abs(round(math.ldexp(c, frac_bits))) > limit:
            raise ValueError(f"frac-bits {frac_bits} overflows int{word_bits}: coefficient of "
                             f"x^{k} = {c:.6g} becomes {round(math.ldexp(c, frac_bits))}; "
                             f"accepted: frac-bits <= {max_f}")


def quantize(table: CoefficientTable, frac_bits: int, *, word_bits: int = 32,
             reoptimize: bool = True) -> CoefficientTable:
    """Round the coefficients to ``frac_bits`` fractional bits and re-certify.

    With ``reoptimize`` the coefficients are rounded from the highest power
    down, the lower ones refitted (Remez, same error kind) after each
    rounding -- a greedy version of Sollya's ``fpminimax`` -- and the result
    is kept only when its certified error beats plain rounding.

    >>> t = quantize(fit("1/sqrt(2+z)", ("sqrt(2)", 2), 2, var="z"), 20)
    >>> t.fixed_point.method, t.fixed_point.abs_error_bound < 1.01 * t.abs_error_bound
    ('reoptimized', True)
    """
    table.require_monomial("quantize")
    _check_frac_bits(frac_bits, table.coefficients, word_bits)
    frac_bits = int(frac_bits)
    fn = parse_function(table.expression, table.variable)
    iv = Interval(*table.interval)
    candidates = {"rounded": [round(math.ldexp(c, frac_bits)) for c in table.coefficients]}
    if reoptimize and table.degree >= 1:
        candidates["reoptimized"] = _greedy_integers(fn, iv, table, frac_bits)
    best = None
    limit = 2 ** (word_bits - 1) - 1
    for method, ints in candidates.items():
        if max(abs(q) for q in ints) > limit:
            continue
        coeffs = [math.ldexp(q, -frac_bits) for q in ints]
        ca, cr = _certify_both(fn, coeffs, iv, table.error_kind == "rel")
        key = ca.bound if table.error_kind == "abs" else (cr.bound if cr else math.inf)
        if best is None or key < best[0]:
            best = (key, method, ints, ca, cr)
    _, method, ints, ca, cr = best
    notes = _certificate_notes(**{"fixed_point.abs_error_bound": ca,
                                  "fixed_point.rel_error_bound": cr})
    fixed = FixedPoint(frac_bits=frac_bits, integers=tuple(int(q) for q in ints), word_bits=word_bits,
                       method=method, abs_error_bound=ca.bound,
                       rel_error_bound=None if cr is None else cr.bound,
                       max_abs_error=ca.maximum, max_rel_error=None if cr is None else cr.maximum)
    from dataclasses import replace
    provenance = dict(table.provenance)
    if notes:
        old = warnings_of(table)
        provenance["warnings"] = " | ".join(old + [n for n in notes if n not in old])
    return replace(table, fixed_point=fixed, provenance=provenance)


def _greedy_integers(fn: Function1D, iv: Interval, table: CoefficientTable, frac_bits: int):
    f_np = fn.numpy
    n = table.degree
    fixed: dict[int, int] = {}
    current = list(table.coefficients)
    for k in range(n, -1, -1):
        fixed[k] = round(math.ldexp(current[k], frac_bits))
        if k == 0:
            break
        high = {j: math.ldexp(q, -frac_bits) for j, q in fixed.items()}

        def residual(x, high=high):
            return f_np(x) - sum(c * x ** j for j, c in high.items())

        if table.error_kind == "rel":
            weight = lambda x: 1.0 / np.abs(f_np(x))
        else:
            weight = lambda x: np.ones_like(x)
        res = remez(residual, weight, iv.lo_f, iv.hi_f, k - 1)
        low = cheb_to_monomial(res.cheb, iv.lo_f, iv.hi_f)
        current = low + [math.ldexp(fixed[j], -frac_bits) for j in range(k, n + 1)]
    return [fixed[k] for k in range(n + 1)]
