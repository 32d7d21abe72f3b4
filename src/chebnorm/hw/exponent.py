"""Hardware of ``1/sqrt(x)`` indexed by exponent: a leading-zero count, a
normalizing shift, and the sized ROM + Horner datapath of an exponent table.

This is the normalization unit's reciprocal square root of ``|N|^2``. The
input is an unsigned ``W``-bit code ``k`` standing for ``x = k / 2^W`` in
``(0, 1)`` (``|N|^2`` as a fixed-point fraction); the interval
``[2^-m, 1)`` (``1 <= m <= W``) says which codes are in the spec
(``k >= 2^(W-m)``; every nonzero code is evaluated the same way, and the
certified bound holds on all of them). The datapath::

    lz   = leading zeros of k in W bits          (W for k = 0)
    mant = (k << lz) mod 2^W                     top bit set: v1 = mant / 2^(W-1) in [1, 2)
    x    = v1 * 2^-(lz + 1)
    h    = (lz + 2) >> 1                         the pair of binades: x = v * 4^-h
    v    = v1 (lz odd) or 2 * v1 (lz even)       v in [1, 4)
    1/sqrt(x) = 2^h * g(v),   g(v) = 1/sqrt(v) in (1/2, 1]

Pairing binades makes the exponent halve exactly: ``v`` lies in ``[1, 4)``,
two binades of an exponent :class:`~chebnorm.approx.PiecewiseTable`
(``segment_by="exponent"``, ``2^s`` segments per binade). Its ROM index is
``{binade, mant[W-2 : W-1-s]}`` (the binade bit is ``~lz[0]``), its local
variable the ``L = W - 1 - s`` bits below: the *core* is
:func:`chebnorm.hw.piecewise.design_piecewise` of that table on the
``W``-bit inner code ``{~lz[0], mant[W-2:0]}`` (a width per coefficient,
truncated products, certified per segment in exact interval arithmetic).

Output format: a mantissa and a shift, ``y = {h, m}`` (``h`` in the top
``H`` bits, ``m`` in the low ``M = out_bits`` bits), value
``1/sqrt(x) ~ 2^h * (offset + m) / 2^F``. That is what a normalization unit
needs: it multiplies each component ``N_i`` (``|N_i| <= |N|``) by the
mantissa and shifts the product left by ``h`` -- the result's *relative*
error is the mantissa's, the same for every ``|N|^2`` however small; a plain
fixed-point output with the range of ``2^(m/2)`` would carry ``m/2`` more
bits and lose relative precision on large ``|N|^2``. The certified bound is
on the mantissa: ``|(offset + m)/2^F - g(v)| <= E``, so ``|y - 1/sqrt(x)|
<= 2^h E`` and the relative error is below ``2E`` (``g > 1/2``); faithful
(the default) means ``E < 2^-F``, one unit of the mantissa's last place.

>>> d = design_exponent("1/sqrt(x)", ("2^-8", "1"), 8, 8, degree=1)
>>> d.out_bits == d.mant_bits + d.shift_bits, d.budget()["mantissa"] < 2.0 ** -d.frac_bits
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import mpmath
import numpy as np
import sympy as sp

from chebnorm.approx.expr import parse_function, parse_number
from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.approx.piecewise_table import MAX_COEF_FRAC_BITS, exact_log2
from chebnorm.core.numeric import float_up
from chebnorm.core.textsafe import identifier
from chebnorm.core.display import field_rows, summary_html, summary_repr

from .fixed import check_width
from .hdl.exponent import exponent_files, exponent_module
from .piecewise import MAX_PW_IN_BITS, PiecewiseDesign, design_piecewise, shape_cost
from .design_base import Design, register
from .trust import check

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []

#: the narrowest input (a degree-2 core needs a few local bits)
MIN_EXP_IN_BITS = 4
#: faithful segment counts tried per degree after the first one
SWEEP = 3


def exponent_fields(k, in_bits: int) -> dict:
    """The normalization of codes ``k`` (``W = in_bits``): leading zeros ``lz``
    (``W`` for 0), ``mant = (k << lz) mod 2^W``, the shift ``h = (lz + 2) >> 1``,
    the binade bit ``1 - lz mod 2`` and the core's inner code
    ``{binade, mant[W-2:0]}``.

    Parameters
    ----------
    k : int or array_like of int
        Input codes, ``0 <= k < 2^in_bits``.
    in_bits : int
        The code width ``W``.

    Returns
    -------
    dict
        ``"lz"``, ``"mant"``, ``"h"``, ``"binade"``, ``"inner"``: int64 arrays
        of the shape of ``k``.

    Examples
    --------

    >>> f = exponent_fields([1, 2, 3, 255, 0], 8)
    >>> [int(v) for v in f["lz"]], [int(v) for v in f["h"]], [int(v) for v in f["inner"]]
    ([7, 6, 6, 0, 8], [4, 4, 4, 1, 5], [0, 128, 192, 255, 128])
    """
    W = int(in_bits)
    k = np.asarray(k, dtype=np.int64)
    # float64 holds every code below 2^53 exactly: frexp's exponent is the bit length
    bl = np.frexp(k.astype(np.float64))[1].astype(np.int64)
    lz = W - bl
    mant = (k << lz) & ((1 << W) - 1)
    binade = 1 - (lz & 1)
    inner = (binade << (W - 1)) | (mant & ((1 << (W - 1)) - 1))
    return {"lz": lz, "mant": mant, "h": (lz + 2) >> 1, "binade": binade, "inner": inner}


def check_rsqrt(expr, var: str = "x") -> str:
    """``expr`` if it is ``1/sqrt(var)`` (any equal sympy form), else ValueError.

    Parameters
    ----------
    expr : str or sympy.Expr
        The function asked for.
    var : str
        Its variable (default ``"x"``).

    Returns
    -------
    str
        ``expr`` as text.

    Raises
    ------
    ValueError
        When ``expr`` is not ``1/sqrt(var)``, naming it and the accepted form.

    Examples
    --------

    >>> check_rsqrt("x**(-1/2)")
    'x**(-1/2)'
    >>> check_rsqrt("sqrt(x)")
    Traceback (most recent call last):
    ...
    ValueError: expr 'sqrt(x)': the exponent-indexed architecture evaluates 1/sqrt(x) only; accepted: 1/sqrt(x) (or an equal form)
    """
    fn = parse_function(expr, var)
    if sp.simplify(fn.expr - fn.var ** sp.Rational(-1, 2)) != 0:
        raise ValueError(f"expr {str(expr)[:60]!r}: the exponent-indexed architecture evaluates "
                         f"1/sqrt({var}) only; accepted: 1/sqrt({var}) (or an equal form)")
    return str(expr)


def _check_interval(interval, in_bits: int) -> int:
    """``m`` of ``interval = (2^-m, 1)``, ``1 <= m <= in_bits``."""
    try:
        lo_t, hi_t = interval
        lo, hi = parse_number(str(lo_t).replace("^", "**")), parse_number(str(hi_t).replace("^", "**"))
    except (TypeError, ValueError):
        lo = hi = None
    e = exact_log2(lo) if lo is not None and lo.is_Rational and lo > 0 else None
    if hi is None or hi != 1 or e is None or not -in_bits <= e <= -1:
        raise ValueError(f"interval {tuple(interval) if isinstance(interval, (tuple, list)) else interval!r}: "
                         f"the exponent-indexed input x = k / 2^in_bits lies in (0, 1); accepted: "
                         f"(2^-m, 1) with 1 <= m <= in_bits = {in_bits} (a low end above 0: "
                         f"1/sqrt is unbounded at 0)")
    return -e


@register("exponent")
@dataclass(frozen=True)
class ExponentDesign(Design):
    """The exponent-indexed ``1/sqrt`` evaluator (module docstring): a
    leading-zero count and shift in front of a sized piecewise ``core``.

    Built by :func:`design_exponent`; a hand-built one is checked the same
    way (ValueError naming the field and its accepted values).

    Attributes
    ----------
    name : str
        The module name stem (an identifier): the module is ``chebnorm_NAME``.
    expression : str
        The function, ``1/sqrt(x)`` in some equal form.
    variable : str
        Its variable.
    interval : tuple of str
        ``("2^-m", "1")``: the codes ``k >= 2^(W - m)`` are in the spec.
    in_bits : int
        The input code width ``W``, 4..20.
    core : PiecewiseDesign
        The sized piecewise evaluator of ``g(v) = 1/sqrt(v)`` on ``[1, 4)``
        (an exponent table) on the inner code.
    shift_bits : int
        ``H``, the width of the shift ``h = (lz + 2) >> 1``.

    Examples
    --------
    >>> d = design_exponent("1/sqrt(x)", ("2^-8", "1"), 8, 8, degree=1)
    >>> y = d.evaluate([64])[0]           # x = 1/4: 1/sqrt(x) = 2 = 2^1 * 1
    >>> int(y) >> d.mant_bits, float(d.mantissa_value(int(y) & (2 ** d.mant_bits - 1)))
    (1, 1.0)
    """

    name: str
    expression: str
    variable: str
    interval: tuple[str, str]
    in_bits: int
    core: PiecewiseDesign
    shift_bits: int

    def _summary(self) -> list[tuple[str, object]]:
        return [("name", self.name), ("expression", self.expression),
                ("interval", self.interval), ("in_bits", self.in_bits),
                ("out_bits", self.out_bits), ("degree", self.degree),
                ("segments", self.core.table.segment_count)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    architecture = "exponent"

    def __post_init__(self):
        self.verify()

    def verify(self) -> "ExponentDesign":
        """Re-prove the design; return it unchanged, or raise ValueError.

        The fields are checked as :func:`design_exponent` builds them (the
        function ``1/sqrt``, the interval, the shift width), and the core is
        re-verified (:meth:`PiecewiseDesign.verify`: its table, ROM and
        certified bound re-proved) and must evaluate ``1/sqrt`` on ``[1, 4)``.
        Proved once per content (:func:`chebnorm.hw.trust.check`).

        Returns
        -------
        ExponentDesign
            ``self``.

        Raises
        ------
        ValueError
            Naming the field that does not hold.
        """
        return check(self, _prove)

    def _check_fields(self):
        # a hand-built design is checked as design_exponent builds it: the printers trust it
        W = check_width(self.in_bits, "in_bits", MIN_EXP_IN_BITS, MAX_PW_IN_BITS)
        identifier(self.name, field="name")
        _check_interval(self.interval, W)
        c = self.core
        t = c.table if isinstance(c, PiecewiseDesign) else None
        if t is None or not c.sized or c.in_bits != W or \
                t.segment_by != "exponent" or tuple(t.interval) != ("1", "4"):
            raise ValueError("core: accepted: a sized PiecewiseDesign of an exponent table of "
                             "1/sqrt on [1, 4) with in_bits equal to the design's "
                             "(design_exponent builds it)")
        if self.shift_bits != ((W + 2) >> 1).bit_length():
            raise ValueError(f"shift_bits {self.shift_bits!r}: accepted: "
                             f"{((W + 2) >> 1).bit_length()} (the width of (in_bits + 2) >> 1)")
        check_rsqrt(self.expression, self.variable)
        c.verify()
        try:
            check_rsqrt(t.expression, t.variable)
        except ValueError:
            raise ValueError(f"core: its table evaluates {str(t.expression)[:40]!r}; accepted: "
                             f"a core of 1/sqrt on [1, 4) (design_exponent builds it)") from None

    @property
    def module_name(self) -> str:
        return f"chebnorm_{self.name}"

    @property
    def mant_bits(self) -> int:
        """``M``: the mantissa code's width (the core's output)."""
        return self.core.out_bits

    @property
    def out_bits(self) -> int:
        """Width of the packed output ``{h, m}``: ``H + M``."""
        return self.shift_bits + self.mant_bits

    @property
    def frac_bits(self) -> int:
        """``F``: the mantissa's fractional bits."""
        return self.core.y_format.frac_bits

    @property
    def degree(self) -> int:
        return self.core.degree

    @property
    def latency(self) -> int:
        return self.core.latency

    @property
    def low_exponent(self) -> int:
        """``m`` of the interval ``[2^-m, 1)``."""
        return _check_interval(self.interval, self.in_bits)

    @property
    def valid_codes(self) -> tuple[int, int]:
        """First and last input code inside the interval."""
        return 2 ** (self.in_bits - self.low_exponent), 2 ** self.in_bits - 1

    def mantissa_value(self, m) -> Fraction:
        """The value ``(offset + m) / 2^F`` of mantissa code ``m``."""
        return Fraction(self.core.y_format.offset_code + int(m), 2 ** self.frac_bits)

    def evaluate(self, codes=None, *, wires: bool = False):
        """Packed output codes ``(h << M) | m`` for input ``codes`` (default all ``2^W``)."""
        k = np.arange(2 ** self.in_bits, dtype=np.int64) if codes is None \
            else np.asarray(codes, dtype=np.int64)
        if k.size and (k.min() < 0 or k.max() >= 2 ** self.in_bits):
            raise ValueError(f"codes: accepted: integers 0 <= code < 2**{self.in_bits}")
        f = exponent_fields(k, self.in_bits)
        m = self.core.evaluate(f["inner"])
        y = (f["h"] << self.mant_bits) | m
        if wires:
            f.update(m=m, y=y)
            return f
        return y

    def budget(self) -> dict:
        """Certified bounds (floats rounded up): ``mantissa`` ``E`` (``|mantissa -
        g(v)|``, the core's total: approximation + datapath), ``relative``
        ``2E`` (``|y / f(x) - 1|``; ``g > 1/2``), the core's parts, and
        ``y_lsb`` (one unit of the mantissa's last place, ``2^-F``)."""
        b = dict(self.core.budget())
        E = Fraction(self.core.bound[2]) if self.core.sized else Fraction(b["total"])
        b["mantissa"] = float_up(E)
        b["relative"] = float_up(2 * E)
        b["mantissa_exact"] = E
        return b

    def measure(self, codes=None) -> dict:
        """Exact check over ``codes`` (default: every code in the interval): the
        largest mantissa error ``|(offset + m)/2^F - 2^-h / sqrt(x)|`` and relative
        error ``|y sqrt(x) - 1|``, ``1/sqrt`` at 40 digits (distinct inner codes
        evaluated once)."""
        lo, hi = self.valid_codes
        k = np.arange(lo, hi + 1, dtype=np.int64) if codes is None \
            else np.asarray(codes, dtype=np.int64)
        w = self.evaluate(k, wires=True)
        inner, first = np.unique(w["inner"], return_index=True)
        off, F = self.core.y_format.offset_code, self.frac_bits
        worst, at, rel = mpmath.mpf(0), 0, mpmath.mpf(0)
        with mpmath.workdps(40):
            for c, x, i in zip(inner, self.core.x_values(inner), first):
                m = mpmath.mpf(off + int(w["m"][i])) / 2 ** F
                g = 1 / mpmath.sqrt(mpmath.mpf(x.numerator) / x.denominator)
                e = abs(m - g)
                if e > worst:
                    worst, at = e, int(k[i])
                rel = max(rel, e / g)
        return {"max_error": float(worst), "at_code": at, "max_rel_error": float(rel),
                "codes": int(k.size), "inner_codes": int(inner.size)}

    def verilog(self, *, version: str = "", command: str | None = None) -> str:
        """The Verilog-2005 module (and its core): :func:`chebnorm.hw.hdl.exponent.exponent_module`."""
        return exponent_module(self, "verilog", version=version, command=command)

    def vhdl(self, *, version: str = "", command: str | None = None) -> str:
        """The VHDL-2008 entities (core first): :func:`chebnorm.hw.hdl.exponent.exponent_module`."""
        return exponent_module(self, "vhdl", version=version, command=command)

    def hdl_files(self, language: str = "verilog") -> dict:
        """Module, bench and vectors (:func:`chebnorm.hw.hdl.exponent.exponent_files`)."""
        return exponent_files(self, language)

    def features(self):
        """The cost model's inputs: the core's
        (:func:`chebnorm.hw.target_model.piecewise_features`) and the
        normalization in front of it, priced as adder bits: the leading-zero
        count (``W`` bits), the left shift by ``lz`` (one ``W``-bit level of
        2:1 multiplexers per bit of ``lz``) and ``h = (lz + 2) >> 1``
        (``shift_bits``). A structural estimate: the target models were not
        calibrated on this architecture."""
        from dataclasses import replace as _replace

        f = self.core.features()
        W = int(self.in_bits)
        norm = (W,) + (W,) * W.bit_length() + (int(self.shift_bits),)
        return _replace(f, adders=tuple(f.adders) + norm)

    def cut_points(self) -> tuple[str, ...]:
        """None: the core's registers are set by :func:`design_exponent` (``pipeline=``)."""
        return ()


def _prove(d: ExponentDesign) -> None:
    d._check_fields()


def _core_shape(d: PiecewiseDesign) -> tuple:
    return (d.local_bits, d.degree, d.table.centered, d.coef_frac, d.t_keep, d.acc_frac,
            d.multipliers == "truncated", d.prod_frac)


def design_exponent(expr, interval, in_bits: int, out_bits: int, *, degree: int = 2,
                    segments=None, max_error=None, multipliers: str = "truncated",
                    pipeline=None, name: str = "rsqrt", var: str = "x") -> ExponentDesign:
    """Design the exponent-indexed ``1/sqrt`` evaluator (module docstring).

    Parameters
    ----------
    expr : str
        ``1/sqrt(x)`` (any equal form; the only function this architecture takes).
    interval : pair
        ``(2^-m, 1)``, ``1 <= m <= in_bits``: the codes ``k >= 2^(in_bits - m)``
        are the spec (a low end of 0 is refused).
    in_bits : int
        ``W``, 4 to 20: code ``k`` stands for ``x = k / 2^W``.
    out_bits : int
        ``M``, 2 to 32: the mantissa code's width (the shift ``h`` adds ``H``
        bits, ``H`` the width of ``(W + 2) >> 1``).
    degree : int
        The core polynomial's degree, 1 to 3.
    segments : int, optional
        Segments per binade ``2^s`` (``s <= W - 3``); default: among the first
        :data:`SWEEP` counts that meet the error, the cheapest by
        :func:`~chebnorm.hw.piecewise.shape_cost`.
    max_error : float or str, optional
        Certified bound on the mantissa's error; default faithful (``< 2^-F``).
    multipliers : {"truncated", "full"}
        The core's multipliers (``"full"`` where a DSP takes them).
    pipeline : None, "full" or cut points
        The core's registers (:func:`~chebnorm.hw.piecewise.design_piecewise`);
        the shift ``h`` is delayed as many cycles.
    name, var : str
        Module stem (an identifier) and the variable of ``expr``.

    Returns
    -------
    ExponentDesign

    Raises
    ------
    ValueError
        Naming the argument and the accepted range.

    See Also
    --------
    chebnorm.hw.piecewise.design_piecewise : the mantissa's core evaluator.
    chebnorm.hw.hdl.exponent : its Verilog and VHDL.

    Examples
    --------
    >>> d = design_exponent("1/sqrt(x)", ("2^-10", "1"), 10, 10, degree=2)
    >>> d.measure()["max_error"] <= d.budget()["mantissa"] < 2.0 ** -d.frac_bits
    True
    >>> design_exponent("1/sqrt(x)", ("0", "1"), 10, 10)
    Traceback (most recent call last):
    ...
    ValueError: interval ('0', '1'): the exponent-indexed input x = k / 2^in_bits lies in (0, 1); accepted: (2^-m, 1) with 1 <= m <= in_bits = 10 (a low end above 0: 1/sqrt is unbounded at 0)
    """
    in_bits = check_width(in_bits, "in_bits", MIN_EXP_IN_BITS, MAX_PW_IN_BITS)
    out_bits = check_width(out_bits, "out_bits", 2, 32)
    degree = check_width(degree, "degree", 1, 3)
    name = identifier(name, field="name")
    expr = check_rsqrt(expr, var)
    m = _check_interval(interval, in_bits)
    if multipliers not in ("truncated", "full"):
        raise ValueError(f"multipliers {multipliers!r}; accepted: 'truncated', 'full'")
    if segments is None:
        ss = range(0, in_bits - 2)
    else:
        from chebnorm.approx.piecewise_table import parse_segments
        s = parse_segments(segments)
        if not 0 <= s <= in_bits - 3:
            raise ValueError(f"segments {segments!r}: accepted: 2^0 .. 2^{in_bits - 3} per binade "
                             f"(with in_bits = {in_bits}: the local variable keeps 2 bits)")
        ss = (s,)
    fc = min(out_bits + 10 if max_error is None else out_bits + 12, MAX_COEF_FRAC_BITS)
    found, last = [], None
    for s in ss:
        t = piecewise_fit("1/sqrt(v)", ("1", "4"), degree, segments=2 ** s,
                          segment_by="exponent", coef_frac_bits=fc, centered=True, var="v",
                          name=f"{name}_core")
        try:
            core = design_piecewise(t, in_bits, out_bits, widths="auto", max_error=max_error,
                                    multipliers=multipliers, pipeline=pipeline)
        except ValueError as exc:   # not reachable at this segment count
            last = exc
            if found:
                break
            continue
        found.append((shape_cost(t, _core_shape(core), core.coefficients), s, core))
        if len(found) == SWEEP:
            break
    if not found:
        raise ValueError(f"max_error: not met by a degree-{degree} core at any segment count "
                         f"tried ({last}); accepted: a larger max_error, more out_bits or a "
                         f"higher degree")
    _, _, core = min(found, key=lambda c: (c[0], c[1]))
    H = ((in_bits + 2) >> 1).bit_length()
    lo = "2^-%d" % m
    return ExponentDesign(name, expr, var, (lo, "1"), in_bits, core, H)


def simulate_exponent(design: ExponentDesign, directory, language: str = "verilog"):
    """Write the module, its exhaustive bench and the model's vectors into
    ``directory`` and run the bench (Icarus Verilog or GHDL): every input
    code's packed output against :meth:`ExponentDesign.evaluate`.

    Parameters
    ----------
    design : ExponentDesign
        The design simulated.
    directory : str or os.PathLike
        An existing folder the files are written into.
    language : {"verilog", "vhdl"}
        Icarus Verilog (default) or GHDL.

    Returns
    -------
    object
        The simulator's verdict (``passed``, ``line``), as
        :func:`chebnorm.hw.run_verilog.simulate` and
        :func:`chebnorm.hw.run_vhdl.simulate_vhdl` return it.

    Raises
    ------
    ValueError
        For an unknown ``language``.

    Examples
    --------
    >>> import tempfile
    >>> d = design_exponent("1/sqrt(x)", ("2^-6", "1"), 6, 6, degree=1)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     simulate_exponent(d, tmp).line
    'PASS: 64 vectors, 0 mismatches (chebnorm_rsqrt)'
    """
    from pathlib import Path

    from chebnorm.core.files import write_folder

    from .run_verilog import simulate
    from .run_vhdl import simulate_vhdl

    write_folder(Path(directory), exponent_files(design, language))
    if language == "verilog":
        return simulate(directory, design)
    return simulate_vhdl(directory, design)
