"""A cost model per FPGA target, calibrated against yosys, so a design search
need not synthesize every candidate.

A design is described by its :class:`DesignFeatures`: its ROMs (index bits
``k``, word bits ``w``), its multipliers (operand widths ``a x b``), its
adders (widths) and its register bits. :func:`model_score` predicts the
target's score (:mod:`chebnorm.hw.targets`: yosys cells on ``generic``, LUT
equivalents on the FPGA targets) as a sum of per-block terms whose *shape*
follows the device and whose *constants* were fitted against yosys 0.23:

* ``generic``: ``c_rom * w * 2**k + c_mul * a * b + c_add * width + bits``;
* ``xc7``: a ROM output bit of ``k`` address bits is ``max(1, 2**(k-6))``
  LUT6 (``c_rom`` of them survive constant folding); a multiplier goes to
  ``ceil(a/25) * ceil(b/18)`` DSP48E1 (the 25 x 18 signed ports, wider operand
  on A) scored at the device weight (264.2 LUTs each); adders ``c_add`` LUT
  per bit (beside their CARRY4); registers 0.5 LUT per bit;
* ``xc7-nodsp``: as ``xc7`` with multipliers in LUTs, ``c_mul * a * b``;
* ``ice40``: as ``xc7-nodsp`` with LUT4 (``max(1, 2**(k-4))`` per ROM bit)
  and 1 LUT per register bit.

The constants (:data:`CALIBRATION`) come from ``benchmarks/calibrate_targets.py``:
a fixed set of piecewise designs (three functions, degrees 1 to 3, 4 to 128
segments, 12- and 16-bit) and single Horner designs (degrees 1 to 3), each
synthesized on every target, fitted by non-negative least squares on the
relative error (13 designs x 4 targets, ``benchmarks/target_calibration.json``).
:data:`MODEL_SPREAD` is the largest ratio ``max(model/yosys, yosys/model)``
measured per target on that set (generic 1.165, xc7 1.056, xc7-nodsp 1.257,
ice40 1.254) and on four held-out designs the fit never saw (exp, sin, a
20-bit 1/sqrt, a degree-3 1/(1+x): 1.049, 1.063, 1.249, 1.094), whichever is
larger; the test ``tests/test_targets_fpga.py`` re-synthesizes designs of the
set and holds the model to it. It is a model for ranking candidates; the winner is always
synthesized.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .design_base import Design
from .targets import DEVICE_WEIGHTS, get_target
from ._docfrag import hw_doc

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []


@dataclass(frozen=True)
class DesignFeatures:
    """What the cost model reads of a design.

    ``roms``: ``((index_bits, word_bits), ...)``; ``multipliers``: ``((a, b), ...)``
    operand widths (two's complement); ``adders``: widths; ``register_bits``:
    flip-flops (0 for a combinational design); ``const_multipliers``:
    ``((a, b, naf), ...)``, a variable ``b``-bit operand times an ``a``-bit
    constant with ``naf`` nonzero digits (:func:`naf_weight`): ``naf - 1``
    adders of ``a + b`` bits in LUTs, but a DSP48E1 on ``xc7`` (yosys maps
    every ``$mul`` there).

    Parameters
    ----------
    roms : tuple of (int, int), default ()
        ``(index_bits, word_bits)`` per ROM, each an integer in 0..4096.
    multipliers : tuple of (int, int), default ()
        ``(a, b)`` operand widths of each variable multiplier, integers 0..4096.
    adders : tuple of int, default ()
        The width of each adder, integers 0..2^20.
    register_bits : int, default 0
        Flip-flops, 0..2^20 (0 for a combinational design).
    const_multipliers : tuple of (int, int, int), default ()
        ``(a, b, naf)`` per constant multiplier, integers 0..4096.
    partial_products : tuple of int, default ()
        Kept partial-product bits per truncated multiplier, integers 0..2^20.

    Raises
    ------
    ValueError
        An item is not a tuple of the right length, or a width is not an
        integer (bools refused) in its range.

    Examples
    --------
    >>> DesignFeatures(roms=((5, 42),), multipliers=((10, 13),)).roms
    ((5, 42),)
    >>> DesignFeatures(adders=(-1,))
    Traceback (most recent call last):
    ...
    ValueError: adders/partial_products/register_bits: -1; accepted: integers 0..2^20
    """

    roms: tuple[tuple[int, int], ...] = ()
    multipliers: tuple[tuple[int, int], ...] = ()
    adders: tuple[int, ...] = ()
    register_bits: int = 0
    const_multipliers: tuple[tuple[int, int, int], ...] = ()
    partial_products: tuple[int, ...] = ()

    def __post_init__(self):
        for name, items, n in (("roms", self.roms, 2), ("multipliers", self.multipliers, 2),
                               ("const_multipliers", self.const_multipliers, 3)):
            for it in items:
                if len(it) != n or any(isinstance(v, bool) or not isinstance(v, int) or
                                       not 0 <= v <= 4096 for v in it):
                    raise ValueError(f"{name}: {it!r} is not a pair of widths; accepted: "
                                     f"integers 0..4096")
        for w in tuple(self.adders) + tuple(self.partial_products) + (self.register_bits,):
            if isinstance(w, bool) or not isinstance(w, int) or not 0 <= w <= 1 << 20:
                raise ValueError(f"adders/partial_products/register_bits: {w!r}; accepted: "
                                 f"integers 0..2^20")


#: fitted constants per target (benchmarks/calibrate_targets.py; module docstring)
CALIBRATION = {
    "generic": {"rom": 0.1105, "mul": 5.317, "add": 4.2394},
    "xc7": {"rom": 1.0068, "mul": 0.0, "add": 0.2125},
    "xc7-nodsp": {"rom": 1.5723, "mul": 1.9433, "add": 0.8552},
    "ice40": {"rom": 1.2842, "mul": 2.0591, "add": 1.3325},
}
#: largest max(model/yosys, yosys/model) on the calibration set and the held-out designs
MODEL_SPREAD = {"generic": 1.165, "xc7": 1.063, "xc7-nodsp": 1.257, "ice40": 1.254}


def dsp_count(a: int, b: int) -> int:
    """DSP48E1 blocks of an ``a x b`` signed multiplier: ``ceil(max/25) * ceil(min/18)``.

    Parameters
    ----------
    a, b : int
        The operand widths in bits (positive; the wider goes to the 25-bit port).

    Returns
    -------
    int
        The DSP48E1 count, tiles of 25 x 18 bits.

    Examples
    --------
    >>> dsp_count(17, 19), dsp_count(30, 19), dsp_count(8, 8)
    (1, 4, 1)
    """
    hi, lo = max(a, b), min(a, b)
    return math.ceil(hi / 25) * math.ceil(lo / 18)


def dsp_mapped(a: int, b: int) -> bool:
    """Whether ``synth_xilinx -family xc7`` puts an ``a x b`` signed ``$mul`` in
    DSP48E1s: yosys's ``mul2dsp`` leaves a product in LUTs when an operand is
    under 2 bits or the product (``a + b - 1`` bits, signed) under 9 bits
    (``-D DSP_A_MINWIDTH=2 -D DSP_B_MINWIDTH=2 -D DSP_Y_MINWIDTH=9``).

    Parameters
    ----------
    a, b : int
        The operand widths in bits.

    Returns
    -------
    bool
        True when the product goes to DSP48E1s.

    Examples
    --------
    >>> dsp_mapped(12, 8), dsp_mapped(5, 4), dsp_mapped(18, 1)
    (True, False, False)
    """
    return min(a, b) >= 2 and a + b - 1 >= 9


@hw_doc
def model_terms(f: DesignFeatures, target: str) -> dict:
    """The uncalibrated terms of ``target``'s model: ROM, multiplier and adder
    sizes (each multiplied by its constant in :func:`model_score`), and the
    fixed part (DSPs and registers at their device weights).

    Parameters
    ----------
    f : DesignFeatures
        The design's features.
    %(target)s

    Returns
    -------
    dict of str to float
        ``"rom"`` (bits on ``generic``, LUT-sized ROM bits on the FPGAs),
        ``"mul"`` (sum of ``a * b`` and the truncated multipliers' kept
        partial-product bits; 0 on ``xc7``, where DSPs take the products and
        the LUT ones are priced in ``"fixed"`` at ``xc7-nodsp``'s constant),
        ``"add"`` (adder bits, the constant multipliers' adders included off
        ``xc7``) and ``"fixed"`` (registers, and DSPs on ``xc7``, at the device
        weights of :data:`~chebnorm.hw.targets.DEVICE_WEIGHTS`).

    Raises
    ------
    ValueError
        ``target`` is not a known target.

    Examples
    --------
    >>> f = DesignFeatures(roms=((8, 10),), multipliers=((20, 12),), adders=(30,))
    >>> model_terms(f, "xc7") == {"rom": 40.0, "mul": 0.0, "add": 30.0, "fixed": 63400 / 240}
    True
    >>> model_terms(f, "ice40")["rom"], model_terms(f, "generic")["rom"]
    (160.0, 2560.0)
    """
    t = get_target(target)
    add = float(sum(f.adders))
    if t.name != "xc7":
        add += float(sum((n - 1) * (a + b) for a, b, n in f.const_multipliers if n > 1))
    if t.name == "generic":
        rom = float(sum(w * 2 ** k for k, w in f.roms))
        return {"rom": rom, "mul": float(sum(a * b for a, b in f.multipliers)
                                     + sum(f.partial_products)), "add": add,
                "fixed": float(f.register_bits)}
    lut_in = 6 if t.name.startswith("xc7") else 4
    rom = float(sum(w * max(1, 2 ** (k - lut_in)) for k, w in f.roms))
    wts = DEVICE_WEIGHTS[t.device]
    fixed = wts["ff"] * f.register_bits
    mul = float(sum(a * b for a, b in f.multipliers) + sum(f.partial_products))
    if t.name == "xc7":
        fixed += wts["dsp"] * sum(dsp_count(a, b) for a, b in f.multipliers if dsp_mapped(a, b))
        fixed += wts["dsp"] * sum(dsp_count(a, b) for a, b, n in f.const_multipliers if n > 1)
        soft = sum(a * b for a, b in f.multipliers if not dsp_mapped(a, b))
        fixed += CALIBRATION["xc7-nodsp"]["mul"] * (soft + sum(f.partial_products))
        mul = 0.0
    return {"rom": rom, "mul": mul, "add": add, "fixed": fixed}


@hw_doc
def model_score(features: DesignFeatures, target: str) -> float:
    """Predicted score of a design on ``target`` (yosys cells on ``generic``, LUT
    equivalents otherwise), within :data:`MODEL_SPREAD` of yosys on the
    calibration set.

    Parameters
    ----------
    features : DesignFeatures
        The design's features (:func:`design_features`).
    %(target)s

    Returns
    -------
    float
        ``sum(CALIBRATION[target][k] * terms[k]) + terms["fixed"]`` over the
        terms of :func:`model_terms`.

    Raises
    ------
    ValueError
        ``features`` is not a :class:`DesignFeatures`, or ``target`` is unknown.

    Examples
    --------
    >>> f = DesignFeatures(roms=((5, 42),), multipliers=((17, 13), (19, 13)), adders=(20, 22, 18))
    >>> model_score(f, "xc7") > 2 * 264
    True
    """
    if not isinstance(features, DesignFeatures):
        raise ValueError("features: not a DesignFeatures; accepted: piecewise_features(d), "
                         "horner_features(d) or a DesignFeatures")
    terms = model_terms(features, target)
    c = CALIBRATION[get_target(target).name]
    return float(c["rom"] * terms["rom"] + c["mul"] * terms["mul"] + c["add"] * terms["add"]
                 + terms["fixed"])


def model_parts(features: DesignFeatures, target: str) -> tuple[float, float]:
    """``(score, rom_part)``: :func:`model_score` and the part of it its ROMs
    make (``CALIBRATION[target]["rom"] * terms["rom"]``). Yosys compresses a
    large ROM of smooth data well below the model while it maps multipliers
    and adders close to it, so a lower bound treats the parts apart
    (:func:`chebnorm.hw.architectures.prune_lower`).

    Parameters
    ----------
    features : DesignFeatures
        The design's features.
    target : str
        A target name.

    Returns
    -------
    tuple of float
        The model score and its ROM part (``0 <= rom_part <= score``).

    Raises
    ------
    ValueError
        As :func:`model_score`.

    Examples
    --------
    >>> score, rom = model_parts(DesignFeatures(roms=((8, 10),), adders=(20,)), "xc7")
    >>> round(rom, 2), round(score - rom, 2)   # 10 bits x 4 LUT6, 20 adder bits
    (40.27, 4.25)
    """
    score = model_score(features, target)
    rom = CALIBRATION[get_target(target).name]["rom"] * model_terms(features, target)["rom"]
    return score, min(score, float(rom))


def piecewise_features(d) -> DesignFeatures:
    """Features of a :class:`~chebnorm.hw.piecewise.PiecewiseDesign`: its
    coefficient ROM (index bits x word bits), one ``acc x t`` multiplier and
    one adder per Horner step (a sized design's step ``j`` multiplies by its
    own ``T_j`` bits of ``t``; a truncated multiplier is its kept
    partial-product bits), the output rounding and saturation.

    Parameters
    ----------
    d : PiecewiseDesign
        A one-width or sized piecewise design.

    Returns
    -------
    DesignFeatures
        One ROM, one multiplier (or truncated multiplier's partial
        products) per Horner step, the steps' adders and two
        ``out_bits + 2``-bit adders; no registers.

    Examples
    --------
    >>> from chebnorm.approx.piecewise_fit import piecewise_fit
    >>> from chebnorm.hw.piecewise import design_piecewise
    >>> t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=12)
    >>> f = piecewise_features(design_piecewise(t, 8, 8))
    >>> f.roms[0][0], len(f.multipliers)
    (2, 1)
    """
    n = d.degree
    mults, adds, partial = [], [], []
    acc_w = d.rom_bits[n] if n > 0 else 0
    if d.sized:
        for st in d.sized_signals():   # each step multiplies by its own T_j bits of t
            a = int(acc_w)
            if st["rows"]:   # truncated: the kept bits of the shifted-multiplicand rows
                partial.append(sum(max(0, a - sh) if sh >= 0 else a for _i, sh, _n in
                                   st["rows"]))
            else:
                mults.append((a, int(st["tw"])))
            adds.append(int(st["sw"]))
            acc_w = st["aw"]
    else:
        for _pw, sw, ow in d.widths:
            mults.append((int(acc_w), int(d.t_bits)))
            adds.append(int(sw))
            acc_w = ow
    adds += [d.out_bits + 2, d.out_bits + 2]  # rounding increment and saturation compare
    return DesignFeatures(roms=((int(d.index_bits), int(sum(d.rom_bits))),),
                          multipliers=tuple(mults), adders=tuple(adds),
                          partial_products=tuple(partial))


def naf_weight(q: int) -> int:
    """Nonzero digits of the non-adjacent form of ``q`` (a constant multiplier
    ``q * x`` is that many shifted copies of ``x`` added).

    Parameters
    ----------
    q : int
        Any integer (its sign is ignored).

    Returns
    -------
    int
        The NAF weight of ``abs(q)`` (0 for 0).

    Examples
    --------
    >>> naf_weight(7), naf_weight(0), naf_weight(-10)
    (2, 0, 2)
    """
    q, n = abs(int(q)), 0
    while q:
        if q & 1:
            q -= 2 - (q & 3)   # digit +1 (q = 1 mod 4) or -1 (q = 3 mod 4)
            n += 1
        q >>= 1
    return n


def horner_features(d) -> DesignFeatures:
    """Features of a single-polynomial :class:`~chebnorm.hw.horner.HornerDesign`
    (coefficients are constants: no ROM; the first step multiplies ``x`` by the
    constant top coefficient, priced as the adders of its non-adjacent form).

    Parameters
    ----------
    d : HornerDesign
        A single-polynomial design (:func:`chebnorm.hw.horner.design_horner`).

    Returns
    -------
    DesignFeatures
        No ROM; one variable multiplier per step after the first (and the
        squarer ``x*x`` of a one-parity design), one constant multiplier
        (the first step), and the adders of the input shift (and of a
        shifted table's ``x - c``), the steps, their roundings and the output.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> f = horner_features(design_horner(fit_target("dichotomy", 2), 10, 10, coef_bits=14))
    >>> f.roms, len(f.multipliers), len(f.const_multipliers)
    ((), 1, 1)
    """
    scheme = d.scheme

    def operand(st) -> int:   # x, or the Horner variable v (x*x, (x - c)/s)
        return int(d.xs_bits if scheme == "monomial" or st.operand == "x" else d.variable_bits)

    st0 = d.stages[0]
    mults = tuple((int(st.acc_bits), operand(st)) for st in d.stages[1:])
    top = int(d.horner_integers[-1]) if scheme != "monomial" else int(d.integers[-1])
    const = ((int(st0.acc_bits), operand(st0), naf_weight(top)),)
    adds = [int(d.xs_bits)] + [int(st.sum_bits) for st in d.stages]
    adds += [int(st.out_bits) for st in d.stages[:-1] if st.round_shift]
    adds += [int(d.raw_bits), int(d.raw_bits)]
    if scheme in ("even", "odd"):   # the squarer x*x (and its rounding)
        mults = ((int(d.xs_bits), int(d.xs_bits)),) + mults
        adds += [int(d.variable_bits)] if d.v_round_shift else []
    elif scheme == "shifted":       # v = (xs << m) - C
        adds.append(int(d.variable_bits))
    return DesignFeatures(multipliers=mults, adders=tuple(adds), const_multipliers=const)


def multipartite_features(d) -> DesignFeatures:
    """Features of a :class:`~chebnorm.hw.multipartite.MultipartiteDesign`: its
    TIV and offset ROMs, the adders that sum the offsets (narrowest first) and
    the TIV, and the complement of a symmetric table's address and entry
    (priced as adder bits). No multiplier.

    Parameters
    ----------
    d : MultipartiteDesign
        As :func:`chebnorm.hw.multipartite.design_multipartite` builds it.

    Returns
    -------
    DesignFeatures
        The TIV and offset ROMs and the adders; no multiplier.

    Examples
    --------
    >>> from chebnorm.hw.multipartite import design_multipartite
    >>> f = multipartite_features(design_multipartite("1/sqrt(1+3*x)", ("0", "1"), 10, 10))
    >>> len(f.roms) >= 2, f.multipliers
    (True, ())
    """
    roms = ((int(d.tiv_bits), int(d.sum_bits)),) + tuple(
        (int(t.address_bits), int(t.width)) for t in d.offsets)
    widths = sorted(int(t.width) for t in d.offsets)
    adds, acc = [], 0
    for w in widths[1:]:
        acc = max(acc, w) + 1
        adds.append(acc)
    if widths:
        adds.append(int(d.sum_bits))
    adds += [int(t.field_bits - 1 + t.width) for t in d.offsets if t.symmetric]
    return DesignFeatures(roms=roms, adders=tuple(adds))


def table_features(d) -> DesignFeatures:
    """Features of a :class:`~chebnorm.hw.plain_table.PlainTableDesign`: one ROM
    of ``2**in_bits`` words.

    Parameters
    ----------
    d : PlainTableDesign
        As :func:`chebnorm.hw.plain_table.design_plain_table` builds it.

    Returns
    -------
    DesignFeatures
        One ROM of ``in_bits`` address bits and ``out_bits``-bit words.

    Examples
    --------
    >>> from chebnorm.hw.plain_table import design_plain_table
    >>> table_features(design_plain_table("1/sqrt(1+3*x)", ("0", "1"), 6, 6)).roms
    ((6, 6),)
    """
    return DesignFeatures(roms=((int(d.in_bits), int(d.out_bits)),))


def design_features(d) -> DesignFeatures:
    """The features of any design ``chebnorm design`` builds: a piecewise
    (one-width or sized), multipartite or plain-table design.

    Parameters
    ----------
    d : Design
        Any design of :mod:`chebnorm.hw` (:class:`~chebnorm.hw.design_base.Design`).

    Returns
    -------
    DesignFeatures
        Its :meth:`~chebnorm.hw.design_base.Design.features` (e.g.
        :func:`piecewise_features`, :func:`multipartite_features`,
        :func:`table_features`).

    Raises
    ------
    ValueError
        ``d`` is not a design.

    Examples
    --------
    >>> from chebnorm.hw.plain_table import design_plain_table
    >>> design_features(design_plain_table("1/sqrt(1+3*x)", ("0", "1"), 6, 6)).roms
    ((6, 6),)
    """
    if isinstance(d, Design):
        return d.features()
    raise ValueError(f"design: a {type(d).__name__}; accepted: a design of chebnorm.hw "
                     f"(chebnorm.hw.design_base.Design)")
