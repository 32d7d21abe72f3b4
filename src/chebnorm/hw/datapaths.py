"""Datapath models of the papers' normalization hardware, as composable
:class:`~chebnorm.hw.cost.Block` trees, with bit-accurate kernels for the
classic unit, the dichotomy midpoint and the forward-difference stepper.

Vector components are signed fixed-point codes with ``frac_bits``
fractional bits (value ``code / 2**frac_bits``), arrays of shape ``(..., 3)``.
Widths ``w`` below are the signed component widths (``frac_bits + 2`` holds
``[-2, 2)``, enough for unit vectors and sums of two).

Blocks (seed 000 and seed 001):

* :func:`classic_unit` -- ``N / sqrt(N.N)``: 3 mul, 2 add, 1 sqrt, 3 div.
* :func:`dichotomy_unit` -- ``(N1 + N2) * p(z)``, ``z' = sqrt(2 + z)``
  (seed 000, method 4): 3 add, the polynomial evaluator, 3 mul, and the
  next level's add and square root.
* :func:`quadratic_midpoint_unit` and :func:`forward_difference_stepper`
  (seed 000, method 5): the midpoint ``N_c`` and the coefficients ``G, P, Q``;
  then two additions per component and pixel.
* :func:`eta_unit` (seed 003): three dot products, three polynomial
  evaluators, the sum and the threshold compare.
* :func:`phong_pipeline` and :func:`bump_pipeline` (seed 001): interpolation,
  normalization and intensity blocks; bump mapping adds one multiplexer.
"""

from __future__ import annotations

import numpy as np

from .cost import Block, Cost
from .fixed import shift_round
from .horner import HornerDesign
from ._docfrag import hw_doc

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []


def horner_block(design: HornerDesign) -> Block:
    """The polynomial evaluator: one multiplier and adder per Horner step
    (per degree; per two degrees plus the squarer ``x*x`` in a one-parity
    design), the input-offset adder, rounding incrementers, the output
    offset and clamp.

    Parameters
    ----------
    design : HornerDesign
        The sized evaluator (:func:`~chebnorm.hw.horner.design_horner`).

    Returns
    -------
    Block
        Its cost: multipliers and adders of the exact widths, the coefficient ROM, latency
        ``1 + 2 * degree``.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 2), 10, 10, coef_bits=14)
    >>> c = horner_block(d).cost
    >>> len(c.multipliers) == d.degree, c.latency
    (True, 5)
    """
    square = design.scheme in ("even", "odd")
    mults = tuple((st.acc_bits, design.xs_bits if st.operand == "x" or design.scheme == "monomial"
                   else design.variable_bits) for st in design.stages)
    adders = [design.xs_bits] + [st.sum_bits for st in design.stages]
    adders += [st.out_bits for st in design.stages[:-1] if st.round_shift]
    adders += [design.raw_bits, design.raw_bits]  # output rounding + offset, clamp compare
    if design.scheme == "shifted":   # v = (xs << m) - C
        adders.append(design.variable_bits)
    if square:   # the squarer x*x and its rounding
        mults = ((design.xs_bits, design.xs_bits),) + mults
        if design.v_round_shift:
            adders.append(design.variable_bits)
    rom = sum(max(abs(q), 1).bit_length() + 1 for q in design.horner_integers)
    scheme = ("" if design.scheme == "monomial" else ", in v = (x - c)/s"
              if design.scheme == "shifted" else f", {design.scheme} powers in v = x*x")
    return Block(f"horner {design.module_name}",
                 Cost(multipliers=mults, adders=tuple(adders), rom_bits=rom,
                      mux_bits=design.out_bits,
                      latency=1 + 2 * (design.steps + square)),
                 note=f"degree {design.degree}{scheme}, {design.in_bits}-bit x, "
                      f"{design.out_bits}-bit y")


@hw_doc
def dot_block(w: int) -> Block:
    """``A.B`` of two 3-vectors of ``w``-bit components.

    Parameters
    ----------
    %(component_width)s

    Returns
    -------
    Block
        Three ``w x w`` multipliers, two adders, latency 3.

    Examples
    --------
    >>> c = dot_block(8).cost
    >>> c.multipliers, len(c.adders)
    (((8, 8), (8, 8), (8, 8)), 2)
    """
    return Block("dot product", Cost(multipliers=((w, w),) * 3, adders=(2 * w, 2 * w + 1),
                                     latency=3))


@hw_doc
def classic_unit(w: int, frac_bits: int | None = None) -> Block:
    """Classic normalization ``N / sqrt(N.N)`` (seed 000): 3 mul, 2 add, 1 sqrt, 3 div.

    With ``frac_bits = F`` the dividers are priced as in :func:`classic_normalize`:
    a ``W + F``-bit quotient of ``N << F`` (without it, a ``W``-bit quotient).

    Parameters
    ----------
    %(component_width)s
    frac_bits : int or None, default None
        ``F``: price the dividers as ``W + F``-bit quotients; None: ``W``-bit ones.

    Returns
    -------
    Block
        The dot product, the square root and the three dividers in series.

    Examples
    --------
    >>> c = classic_unit(12).cost
    >>> len(c.multipliers), len(c.adders), len(c.sqrts), len(c.dividers)
    (3, 2, 1, 3)
    """
    q = w if frac_bits is None else w + frac_bits
    return Block("classic normalization", children=(
        dot_block(w),
        Block("square root", Cost(sqrts=(w,), latency=w)),
        Block("3 dividers", Cost(dividers=(q,) * 3, latency=q)),
    ))


@hw_doc
def dichotomy_unit(design: HornerDesign, w: int) -> Block:
    """Dichotomy midpoint ``(N1 + N2) p(z)`` and next level ``z' = sqrt(2 + z)``.

    Parameters
    ----------
    design : HornerDesign
        The polynomial evaluator of ``1/sqrt(2 + z)``; its ``in_bits`` size the next level.
    %(component_width)s

    Returns
    -------
    Block
        The sum, evaluator, scaling and next-level blocks in series.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> b = dichotomy_unit(design_horner(fit_target("dichotomy", 2), 10, 10, coef_bits=14), 12)
    >>> [c.name for c in b.children]
    ['N1 + N2', 'horner chebnorm_dichotomy_d2', 'scale', "next level z' = sqrt(2 + z)"]
    """
    return Block("dichotomy midpoint", children=(
        Block("N1 + N2", Cost(adders=(w + 1,) * 3, latency=1)),
        horner_block(design),
        Block("scale", Cost(multipliers=((w + 1, design.out_bits),) * 3, latency=1)),
        Block("next level z' = sqrt(2 + z)", Cost(adders=(design.in_bits + 1,),
                                                   sqrts=(design.in_bits,),
                                                   latency=1 + design.in_bits)),
    ), note="seed 000, method 4")


@hw_doc
def quadratic_midpoint_unit(design: HornerDesign, w: int) -> Block:
    """Midpoint ``N_c = (N_l + N_r) p(N_l.N_r)`` and ``G, P, Q`` (seed 000, method 5).

    Parameters
    ----------
    design : HornerDesign
        The polynomial evaluator of ``1/sqrt(2(1 + x))``.
    %(component_width)s

    Returns
    -------
    Block
        The dot product, evaluator, midpoint and ``G, P`` blocks in series.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> b = quadratic_midpoint_unit(design_horner(fit_target("midpoint", 2), 10, 10, coef_bits=14), 12)
    >>> len(b.cost.sqrts), len(b.cost.dividers)   # no square root, no division
    (0, 0)
    """
    return Block("quadratic-interpolation midpoint", children=(
        dot_block(w),
        horner_block(design),
        Block("N_c = (N_l + N_r) * p", Cost(adders=(w + 1,) * 3,
                                            multipliers=((w + 1, design.out_bits),) * 3,
                                            latency=2)),
        Block("G = 2N_l + 2N_r - 4N_c, P = 4N_c - 3N_l - N_r",
              Cost(adders=(w + 3,) * 3 * 4, latency=2), note="shifts are wiring"),
    ), note="seed 000, method 5")


@hw_doc
def forward_difference_stepper(w: int, guard: int = 8) -> Block:
    """Per pixel ``N += D1; D1 += D2`` for each component: 6 adders, no multiplier.

    Parameters
    ----------
    %(component_width)s
    guard : int, default 8
        Guard bits of the accumulators (``>= 0``).

    Returns
    -------
    Block
        Six ``w + guard``-bit adders, latency 1 (per pixel).

    Examples
    --------
    >>> c = forward_difference_stepper(12).cost
    >>> len(c.adders), len(c.multipliers)
    (6, 0)
    """
    return Block("forward-difference stepper", Cost(adders=(w + guard,) * 6, latency=1),
                 note="seed 000, method 5: additions only")


@hw_doc
def eta_unit(design: HornerDesign, w: int) -> Block:
    """eta = 3 - sum of three g(N_i.N_j) (seed 003) and the threshold compare.

    Parameters
    ----------
    design : HornerDesign
        The polynomial evaluator ``g`` of ``sqrt(2(1 + x))/2``, instantiated three times.
    %(component_width)s

    Returns
    -------
    Block
        Three dot products and three evaluators side by side, then the sum and compare.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> b = eta_unit(design_horner(fit_target("eta_term", 2), 10, 10, coef_bits=14), 12)
    >>> len(b.cost.sqrts), b.cost.latency > 0
    (0, True)
    """
    return Block("eta criterion", children=(
        Block("3 dot products", children=(dot_block(w),) * 3, serial=False),
        Block("3 evaluators", children=(horner_block(design),) * 3, serial=False),
        Block("sum, 3 - sum, compare", Cost(adders=(design.out_bits + 2,) * 4, latency=3)),
    ), note="seed 003")


def _intensity(w: int, shininess_bits: int = 7) -> Block:
    """Diffuse L.N and specular (H.N)^n by repeated squaring, then the sum."""
    return Block("intensity", children=(
        Block("L.N, H.N", children=(dot_block(w), dot_block(w)), serial=False),
        Block("(H.N)^n", Cost(multipliers=((w, w),) * shininess_bits, latency=shininess_bits)),
        Block("I = Ia + kd Id + ks Is", Cost(multipliers=((w, w),) * 2, adders=(w,) * 2,
                                             latency=2)),
    ))


@hw_doc
def phong_pipeline(w: int, normalizer: Block | None = None) -> Block:
    """Phong pipeline (seed 001): interpolate N, L, H; normalize each; intensity.

    Parameters
    ----------
    %(component_width)s
    normalizer : Block or None, default None
        The normalization block used for each of N, L, H; None: :func:`classic_unit` of ``w``.

    Returns
    -------
    Block
        Interpolation, three normalizers side by side, intensity.

    Examples
    --------
    >>> p = phong_pipeline(12)
    >>> p.cost.area > classic_unit(12).cost.area, len(p.cost.sqrts)
    (True, 3)
    """
    norm = normalizer or classic_unit(w)
    return Block("Phong pipeline", children=(
        Block("interpolation of N, L, H", Cost(adders=(w + 8,) * 9, latency=1)),
        Block("normalization of N, L, H", children=(norm,) * 3, serial=False),
        _intensity(w),
    ), note="seed 001")


@hw_doc
def bump_pipeline(w: int, normalizer: Block | None = None) -> Block:
    """Bump mapping on the Phong pipeline (seed 001): the perturbed normal comes
    from a texture; one added 3w-bit 2:1 multiplexer selects it over the
    interpolated normal.

    Parameters
    ----------
    %(component_width)s
    normalizer : Block or None, default None
        The normalization block used for each of N, L, H; None: :func:`classic_unit` of ``w``.

    Returns
    -------
    Block
        The Phong pipeline plus a ``3w``-bit 2:1 multiplexer.

    Examples
    --------
    >>> bump_pipeline(12).cost.mux_bits - phong_pipeline(12).cost.mux_bits   # one 3w-bit multiplexer
    36
    """
    base = phong_pipeline(w, normalizer)
    return Block("bump-mapping pipeline", children=(
        base, Block("multiplexer N / texture normal", Cost(mux_bits=3 * w)),
    ), note="seed 001: Phong speed, one extra multiplexer")


# -- bit-accurate kernels ----------------------------------------------------------

def _isqrt(v: np.ndarray) -> np.ndarray:
    """floor(sqrt(v)) of non-negative int64, exactly."""
    r = np.floor(np.sqrt(v.astype(np.float64))).astype(np.int64)
    r = np.where(r * r > v, r - 1, r)
    r = np.where((r + 1) * (r + 1) <= v, r + 1, r)
    return r


@hw_doc
def classic_normalize(n, frac_bits: int, rounding: str = "trunc") -> np.ndarray:
    """Bit-accurate classic unit: ``s = isqrt(N.N)`` (``F`` fractional bits),
    each component ``(n_i << F) / s`` rounded (``"trunc"``: toward minus
    infinity). ``n``: int codes ``(..., 3)`` with ``F`` fractional bits.

    >>> classic_normalize(np.array([[3 << 10, 4 << 10, 0]]), 12).tolist()
    [[2457, 3276, 0]]

    Parameters
    ----------
    n : array_like of int
        Component codes, shape ``(..., 3)``, ``W``-bit with ``W + F <= 62``
        (int64 arithmetic, unchecked here).
    %(frac_bits)s
    rounding : {"trunc", "rne"}, default "trunc"
        The quotient's rounding: toward minus infinity, or to nearest with ties to even;
        any other value behaves as ``"trunc"``.

    Returns
    -------
    numpy.ndarray of int64
        Shape ``(..., 3)``: the normalized components with ``F`` fractional bits
        (a zero vector gives zeros: ``s`` is clamped to 1).
    """
    n = np.asarray(n, dtype=np.int64)
    dot = np.sum(n * n, axis=-1)
    s = np.maximum(_isqrt(dot), 1)[..., None]
    num = n << frac_bits
    q = np.floor_divide(num, s)
    if rounding == "rne":
        r2 = 2 * (num - q * s)
        q = q + ((r2 > s) | ((r2 == s) & (q % 2 == 1)))
    return q


def dichotomy_midpoint(n1, n2, z_codes, design: HornerDesign, frac_bits: int) -> np.ndarray:
    """Bit-accurate dichotomy midpoint ``(N1 + N2) * p(z)`` (seed 000, method 4),
    the product rounded to nearest-even back to ``frac_bits``.

    Parameters
    ----------
    n1, n2 : array_like of int
        The two normals' codes, shape ``(..., 3)``.
    z_codes : array_like of int
        The evaluator's input codes of ``z``, shape ``(...)``.
    design : HornerDesign
        The polynomial evaluator of ``1/sqrt(2 + z)``.
    frac_bits : int
        ``F``: fractional bits of ``n1`` and ``n2``, ``>= 0`` (not used: the product is
        rounded back by the evaluator's ``Fy`` bits, so the result keeps ``F``).

    Returns
    -------
    numpy.ndarray of int64
        Shape ``(..., 3)``: the midpoint's codes with ``frac_bits`` fractional bits.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 2), 12, 12, coef_bits=16)
    >>> F = 12
    >>> n1 = np.array([1 << F, 0, 0])
    >>> n2 = np.rint(2.0 ** F * np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0]))
    >>> z = 2 * np.cos(np.pi / 4)
    >>> k = int(np.rint((z - float(d.x_format.offset)) * 2 ** d.x_format.frac_bits))
    >>> m = dichotomy_midpoint(n1, n2, k, d, F)
    >>> exact = np.rint(2.0 ** F * np.array([np.cos(np.pi / 8), np.sin(np.pi / 8), 0]))  # 22.5 degrees
    >>> m.tolist(), exact.astype(int).tolist()
    ([3784, 1567, 0], [3784, 1567, 0])
    """
    s = np.asarray(n1, dtype=np.int64) + np.asarray(n2, dtype=np.int64)
    y = design.evaluate(z_codes)[..., None] + design.y_format.offset_code
    return shift_round(s * y, design.y_format.frac_bits, "rne")


def dichotomy_next_z(z_codes, design: HornerDesign) -> np.ndarray:
    """Bit-accurate next level ``z' = sqrt(2 + z)`` (seed 000, method 4) in the
    input format of ``design`` (``Fx >= 0`` fractional bits, offset ``K0``):
    the square root rounded to nearest (no ties: ``sqrt`` of an integer is
    never a half-integer), computed as ``(isqrt(4 X 2^Fx) + 1) >> 1`` with
    ``X = 2^(Fx+1) + K0 + k``; the code ``z' 2^Fx - K0`` saturates to
    ``[0, 2^in_bits - 1]``. For a valid ``z`` the result is valid (``z' >= z``, equal only at
    ``z = 2``, where ``sqrt(2 + z) = z``).

    Every valid code of the 12-bit input on ``[sqrt 2, 2]`` steps to
    ``sqrt(2 + z)`` within half an LSB (``2^-13``):

    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("dichotomy", 2), 12, 12, coef_bits=16)
    >>> k = np.arange(d.valid_codes[0], d.valid_codes[1] + 1)
    >>> z, z_next = d.x_format.values(k), d.x_format.values(dichotomy_next_z(k, d))
    >>> bool(np.all(np.abs(z_next - np.sqrt(2 + z)) <= 2.0 ** -13)), bool(np.all(z_next >= z))
    (True, True)

    Parameters
    ----------
    z_codes : array_like of int
        Input codes of ``z`` in ``design``'s input format.
    design : HornerDesign
        The polynomial evaluator (its input format, ``Fx >= 0``).

    Returns
    -------
    numpy.ndarray of int64
        The input codes of ``sqrt(2 + z)``, in ``[0, 2**in_bits - 1]``.
    """
    fx, k0 = design.x_format.frac_bits, design.x_format.offset_code
    x = np.asarray(z_codes, dtype=np.int64) + (2 << fx) + k0
    r = (_isqrt(x << (fx + 2)) + 1) >> 1
    return np.clip(r - k0, 0, 2 ** design.in_bits - 1)


def dot_to_code(dot, dot_frac_bits: int, design: HornerDesign) -> np.ndarray:
    """Input code of ``design`` for a dot product ``dot / 2**dot_frac_bits``:
    rounded to nearest-even to the ``Fx`` fractional bits of the input, less
    the offset, saturated to ``0 .. 2^in_bits - 1``.

    Parameters
    ----------
    dot : array_like of int
        Dot-product codes.
    dot_frac_bits : int
        Their fractional bits (``2F`` for a dot product of ``F``-bit components).
    design : HornerDesign
        The polynomial evaluator whose input code is wanted.

    Returns
    -------
    numpy.ndarray of int64
        Input codes in ``[0, 2**in_bits - 1]``.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("midpoint", 2), 10, 10, coef_bits=14)
    >>> F = 8
    >>> one = np.array([1 << F, 0, 0])
    >>> int(dot_to_code(one @ one, 2 * F, d)) == d.valid_codes[1]   # x = 1, the top of [cos(pi/4), 1]
    True
    """
    fx, k0 = design.x_format.frac_bits, design.x_format.offset_code
    dot = np.asarray(dot, dtype=np.int64)
    v = shift_round(dot, dot_frac_bits - fx, "rne") if dot_frac_bits >= fx else \
        dot << (fx - dot_frac_bits)
    return np.clip(v - k0, 0, 2 ** design.in_bits - 1)


def _scaled_sum(n1, n2, y_codes, design: HornerDesign) -> np.ndarray:
    """``(N1 + N2) * y`` rounded to nearest-even by the ``Fy`` bits of ``y``."""
    s = np.asarray(n1, dtype=np.int64) + np.asarray(n2, dtype=np.int64)
    y = np.asarray(y_codes, dtype=np.int64)[..., None] + design.y_format.offset_code
    return shift_round(s * y, design.y_format.frac_bits, "rne")


@hw_doc
def quadratic_midpoint(nl, nr, design: HornerDesign, frac_bits: int):
    """Bit-accurate quadratic-interpolation set-up (seed 000, method 5).

    ``x = N_l.N_r`` (exact, ``2F`` fractional bits) becomes the input code of
    ``design`` (a table of ``1/sqrt(2(1+x))``) by :func:`dot_to_code`; the
    midpoint ``N_c = (N_l + N_r) p(x)`` is rounded to nearest-even back to
    ``F`` bits; ``G = 2N_l + 2N_r - 4N_c``, ``P = 4N_c - 3N_l - N_r``,
    ``Q = N_l`` are exact. Returns ``(G, P, Q, N_c)``, int codes ``(..., 3)``
    with ``F`` fractional bits.

    Parameters
    ----------
    nl, nr : array_like of int
        The span's end normals, codes of shape ``(..., 3)``.
    design : HornerDesign
        The polynomial evaluator of ``1/sqrt(2(1 + x))``.
    %(frac_bits)s

    Returns
    -------
    G, P, Q, N_c : numpy.ndarray of int64
        Each of shape ``(..., 3)`` with ``F`` fractional bits.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import design_horner
    >>> d = design_horner(fit_target("midpoint", 2), 12, 12, coef_bits=16)
    >>> nl, nr = np.array([1 << 10, 0, 0]), np.array([0, 1 << 10, 0])
    >>> G, P, Q, nc = quadratic_midpoint(nl, nr, d, 10)
    >>> bool(np.all(Q == nl)), bool(np.all(G + P + Q == nr))   # the curve starts at N_l and ends at N_r
    (True, True)
    """
    nl, nr = np.asarray(nl, dtype=np.int64), np.asarray(nr, dtype=np.int64)
    k = dot_to_code(np.sum(nl * nr, axis=-1), 2 * frac_bits, design)
    nc = _scaled_sum(nl, nr, design.evaluate(k), design)
    return 2 * nl + 2 * nr - 4 * nc, 4 * nc - 3 * nl - nr, nl, nc


@hw_doc
def eta_criterion(na, nb, nc, design: HornerDesign, frac_bits: int) -> np.ndarray:
    """Bit-accurate ``eta = 3 - g(N_A.N_B) - g(N_B.N_C) - g(N_A.N_C)`` (seed 003)
    with ``g ~ sqrt(2(1+x))/2`` the polynomial of ``design``: each dot product
    exact, converted by :func:`dot_to_code`; the sum exact. Returns the codes of
    eta with the ``Fy`` fractional bits of ``design``'s output (value
    ``code / 2**Fy``, no offset).

    Parameters
    ----------
    na, nb, nc : array_like of int
        The three vertex normals, codes of shape ``(..., 3)``.
    design : HornerDesign
        The polynomial evaluator ``g`` of ``sqrt(2(1 + x))/2``; the dot products
        reach 1, so its input format should cover ``[0, 1]`` (``x_frac_bits=``
        :func:`~chebnorm.hw.horner.cover_frac_bits`, as the eta unit's evaluator):
        under the input-code mapping onto ``[0, 1)`` ``x = 1`` saturates to
        ``1 - 2**-in_bits``.
    %(frac_bits)s

    Returns
    -------
    numpy.ndarray of int64
        Shape ``(...)``: eta codes with ``design``'s ``Fy`` fractional bits.

    Examples
    --------
    >>> from chebnorm.approx import fit_target
    >>> from chebnorm.hw.horner import cover_frac_bits, design_horner
    >>> t = fit_target("eta_term", 2)
    >>> d = design_horner(t, 10, 10, coef_bits=14, x_frac_bits=cover_frac_bits(t, 10))
    >>> n = np.array([[1 << 8, 0, 0]])
    >>> eta = eta_criterion(n, n, n, d, 8)   # three equal normals: eta = 3 - 3 g(1) = 0
    >>> from chebnorm.hw.budget import error_budget
    >>> abs(int(eta[0])) * 2.0 ** -d.y_format.frac_bits <= 3 * error_budget(d, gappa=False).total
    True
    """
    na, nb, nc = (np.asarray(a, dtype=np.int64) for a in (na, nb, nc))
    fy, ky = design.y_format.frac_bits, design.y_format.offset_code
    total = np.zeros(na.shape[:-1], dtype=np.int64)
    for a, b in ((na, nb), (nb, nc), (na, nc)):
        total = total + design.evaluate(dot_to_code(np.sum(a * b, axis=-1), 2 * frac_bits,
                                                    design)) + ky
    return (3 << fy) - total if fy >= 0 else 3 * 2 ** fy - total


def forward_difference_setup(G, P, Q, log_m: int, guard: int):
    """Start values of the stepper for ``m = 2**log_m`` pixels, integer codes:
    ``v0 = Q 2^g``, ``d1 = R((G + m P) 2^g / m^2)``, ``d2 = R(2 G 2^g / m^2)``
    (``R``: nearest-even, exact when ``g >= 2 log_m``), the shifts being wiring.
    ``G, P, Q``: int codes ``(..., 3)``; the results have ``g`` more fractional
    bits. Equal to what :func:`forward_difference` computes from the values.

    Parameters
    ----------
    G, P, Q : array_like of int
        The quadratic's coefficient codes, shape ``(..., 3)``.
    log_m : int
        ``m = 2**log_m`` pixels per span, ``>= 0``.
    guard : int
        ``g``: guard bits, ``>= 0`` (exact set-up when ``g >= 2 log_m``).

    Returns
    -------
    v0, d1, d2 : numpy.ndarray of int64
        Start value and first and second differences, ``g`` more fractional bits.

    Examples
    --------
    >>> G, P, Q = np.array([1 << 8, 0, 0]), np.zeros(3, int), np.zeros(3, int)   # G = 1, F = 8
    >>> v = forward_difference_codes(*forward_difference_setup(G, P, Q, 2, 4), 4)
    >>> (v[:, 0] / 2 ** (8 + 4)).tolist()   # t^2 at t = i/4, exact
    [0.0, 0.0625, 0.25, 0.5625, 1.0]
    """
    G, P, Q = (np.asarray(a, dtype=np.int64) for a in (G, P, Q))

    def scale(v, up):
        sh = 2 * log_m - up
        return shift_round(v, sh, "rne") if sh >= 0 else v << -sh
    return Q << guard, scale(G + (P << log_m), guard), scale(G, guard + 1)


def forward_difference_codes(v0, d1, d2, m: int) -> np.ndarray:
    """``m + 1`` pixel codes ``v_i`` by ``v += d1; d1 += d2`` (additions only);
    int arrays ``(..., 3)`` in, ``(..., m+1, 3)`` out.

    ``d1 = 1``, ``d2 = 2`` step through the squares (``(i+1)^2 - i^2 = 2i + 1``):

    >>> forward_difference_codes(np.zeros(3, int), np.ones(3, int), np.full(3, 2), 4)[:, 0].tolist()
    [0, 1, 4, 9, 16]

    Parameters
    ----------
    v0, d1, d2 : array_like of int
        Start value and differences, shape ``(..., 3)``.
    m : int
        Steps, ``>= 0``.

    Returns
    -------
    numpy.ndarray of int64
        Shape ``(..., m+1, 3)``: ``v_0 .. v_m``.
    """
    v, d1, d2 = (np.asarray(a, dtype=np.int64) for a in (v0, d1, d2))
    out = [v]
    for _ in range(m):
        v = v + d1
        d1 = d1 + d2
        out.append(v)
    return np.stack(out, axis=-2)


def forward_difference(G, P, Q, m: int, frac_bits: int, guard: int = 8) -> np.ndarray:
    """Pixel values of ``G t^2 + P t + Q`` at ``t = i/m``, ``i = 0..m``, by forward
    differences in fixed point (``frac_bits + guard`` fractional bits inside,
    the start values rounded once): additions only, as the hardware does it.
    ``G, P, Q``: float arrays ``(..., 3)``. Returns float values ``(..., m+1, 3)``.

    Parameters
    ----------
    G, P, Q : array_like of float
        The quadratic's coefficients, shape ``(..., 3)``.
    m : int
        Pixels per span, ``>= 1``.
    frac_bits : int
        Fractional bits of the result.
    guard : int, default 8
        Extra fractional bits inside, ``>= 0``.

    Returns
    -------
    numpy.ndarray of float64
        Shape ``(..., m+1, 3)``: the pixel values.

    Examples
    --------
    >>> forward_difference(np.array([1.0, 0, 0]), np.zeros(3), np.zeros(3), 4, 8)[:, 0].tolist()   # t^2
    [0.0, 0.0625, 0.25, 0.5625, 1.0]
    """
    scale = 2.0 ** (frac_bits + guard)
    G, P, Q = (np.asarray(a, dtype=np.float64) for a in (G, P, Q))
    v = np.rint(Q * scale).astype(np.int64)
    d1 = np.rint((G / m ** 2 + P / m) * scale).astype(np.int64)
    d2 = np.rint((2 * G / m ** 2) * scale).astype(np.int64)
    out = [v]
    for _ in range(m):
        v = v + d1
        d1 = d1 + d2
        out.append(v)
    return np.stack(out, axis=-2) / scale
