"""Operation counts measured by running the kernels on :class:`~.ops.Counted` scalars.

Nothing here is a hand-written table: :func:`count_ops` runs the very kernel
:func:`~.spans.span_normals` runs, on one span, and reads the tallies.

* ``per_span`` -- operations in the kernel's set-up phase (once per span;
  for ``dichotomy`` this includes the per-level denominators, so it grows
  with ``log2 m``; for ``angular`` and ``quadratic`` it includes the first
  pixel(s), which the set-up produces);
* ``per_pixel`` -- operations in the per-pixel phase divided by the pixels
  that phase produced (``pixels_in_loop``). For a steady loop this is an
  exact integer; for ``dichotomy`` off the dyadic grid, or ``angular`` with
  re-anchoring, it is an average.

``total = per_span + per_pixel * pixels_in_loop`` holds exactly. Multiplications
by a power of two (``* 0.5``, ``* 2``, ``* 4``) are included in ``mul`` and
tallied again in ``pow2_per_pixel`` / ``pow2_per_span``: in hardware they are
exponent (or wire) shifts.

Claim C9 (seeds 000, 003): :func:`normalization_ops` counts the normalization
step alone (no interpolation):

>>> for name in ("exact", "newton", "lyon"):
...     c = normalization_ops(name); print(name, c.ops, "pow2:", c.pow2)
exact {'add': 2, 'mul': 3, 'div': 3, 'sqrt': 1, 'trig': 0, 'cmp': 0} pow2: 0
newton {'add': 3, 'mul': 7, 'div': 0, 'sqrt': 0, 'trig': 0, 'cmp': 0} pow2: 1
lyon {'add': 4, 'mul': 8, 'div': 0, 'sqrt': 0, 'trig': 0, 'cmp': 0} pow2: 0

Newton-Raphson ``N (3 - N.N) / 2`` is 6 general mul (3 for ``N.N``, 3 for the
scaling of N), 3 add (2 in ``N.N``, 1 in ``3 - N.N``) and one halving. Seed
000 counts the halving as 1 div (``(3 - N.N)/2`` once, then 6 mul, 3 add);
seed 003's 3 div halve each component of ``N (3 - N.N)``. Neither division
is needed: ``/2`` is a multiplication by 0.5, i.e. an exponent decrement in
floating point (a shift in fixed point), so the honest count is 6 mul, 3 add,
0 div (+1 free shift); seed 000's count is right if its "div" is read as that
shift, seed 003's 3 div is an artefact of where the halving is written.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from chebnorm.core.display import field_rows, summary_html, summary_repr
from .ops import OP_KINDS, Counted, Counter, CountingOps
from .registry import method_kernel, method_kernels
from .spans import check_method, resolve_table, span_levels, span_normals

# an implementation module of chebnorm.methods: the API is what chebnorm.methods exports
__all__: list[str] = []

#: the counts the papers state (claim C9); missing kinds are not stated
PAPER_COUNTS = {
    "exact": {"seed 000": {"mul": 3, "add": 2, "sqrt": 1, "div": 3}},
    "newton": {"seed 000": {"div": 1, "mul": 6, "add": 3}, "seed 003": {"div": 3}},
    "lyon": {},
}



def _normalizers() -> dict:
    """The methods whose kernel is linear interpolation then a normalization step."""
    return {name: k.normalizer for name, k in method_kernels().items()
            if getattr(k, "normalizer", None) is not None}


def _clean(v):
    return int(v) if float(v).is_integer() else float(v)


@dataclass(frozen=True)
class OpCounts:
    """Counts of one method on one span (see the module docstring).

    Attributes
    ----------
    method : str
        The method counted.
    m : int
        The span length.
    per_pixel : dict of str to int or float
        Operations per pixel of the loop, by kind.
    per_span : dict of str to int
        Operations of the span's set-up, by kind.
    pixels_in_setup : int
        Pixels the set-up computes itself.
    pixels_in_loop : int
        Pixels the loop computes.
    pow2_per_pixel : float
        Multiplications by a power of two per pixel (among ``per_pixel["mul"]``).
    pow2_per_span : int
        Multiplications by a power of two in the set-up.
    total : dict of str to int
        The whole span's counts, by kind.

    Examples
    --------
    >>> c = count_ops("none", 8)   # N_l + t (N_r - N_l): 3 mul, 3 add per pixel
    >>> c.per_pixel["mul"], c.per_pixel["add"], c.per_span["add"]
    (3, 3, 3)
    """

    method: str
    m: int
    per_pixel: dict
    per_span: dict
    pixels_in_setup: int
    pixels_in_loop: int
    pow2_per_pixel: float
    pow2_per_span: int
    total: dict = field(default_factory=dict)

    def _summary(self) -> list[tuple[str, object]]:
        return [("method", self.method), ("m", self.m), ("per_pixel", self.per_pixel),
                ("per_span", self.per_span)]

    _display_rows = field_rows
    __repr__ = summary_repr
    _repr_html_ = summary_html

    def to_dict(self) -> dict:
        return {"method": self.method, "m": self.m, "per_pixel": dict(self.per_pixel),
                "per_span": dict(self.per_span), "pixels_in_setup": self.pixels_in_setup,
                "pixels_in_loop": self.pixels_in_loop, "pow2_per_pixel": self.pow2_per_pixel,
                "pow2_per_span": self.pow2_per_span, "total": dict(self.total)}


@dataclass(frozen=True)
class NormalizationCounts:
    """Counts of a normalization step alone (claim C9): ``ops`` maps each
    operation kind to its count, ``pow2`` counts the multiplications by a
    power of two among them (see :func:`normalization_ops`).

    Attributes
    ----------
    method : str
        The method counted.
    ops : dict of str to int
        Count per operation kind (``add``, ``mul``, ``div``, ``sqrt``, ``trig``, ``cmp``).
    pow2 : int
        How many of the multiplications are by a power of two.

    Examples
    --------
    >>> c = normalization_ops("lyon")
    >>> c.method, c.ops["sqrt"], c.ops["div"]
    ('lyon', 0, 0)
    """

    method: str
    ops: dict
    pow2: int


def normalization_ops(method: str) -> NormalizationCounts:
    """Count ``exact`` (classic ``N/sqrt(N.N)``), ``newton`` or ``lyon`` (any method
    whose kernel has a ``normalizer``) on one vector.

    Seed 000 counts the classic step as 3 mul, 2 add, 1 sqrt, 3 div (claim
    C9). Newton's ``N (3 - N.N)/2``: ``N.N`` (3 mul, 2 add), ``3 - N.N``
    (1 add), the product with ``N`` (3 mul) and the halving (1 mul by a
    power of two, ``pow2``), no division:

    Parameters
    ----------
    method : str
        A method whose kernel has a normalizer: ``exact``, ``newton`` or ``lyon``.

    Returns
    -------
    NormalizationCounts
        The counts of one normalization.

    Raises
    ------
    ValueError
        For a method without a normalization step.

    Examples
    --------
    >>> normalization_ops("exact").ops
    {'add': 2, 'mul': 3, 'div': 3, 'sqrt': 1, 'trig': 0, 'cmp': 0}
    >>> c = normalization_ops("newton")
    >>> c.ops["mul"], c.ops["add"], c.ops["div"], c.pow2
    (7, 3, 0, 1)
    """
    normalizers = _normalizers()
    if method not in normalizers:
        raise ValueError(f"method {method!r} has no separate normalization step; accepted: "
                         f"{', '.join(normalizers)}")
    c = Counter()
    n = tuple(Counted(v, c) for v in (0.6, 0.5, 0.4))
    normalizers[method](CountingOps(c), n)
    return NormalizationCounts(method, dict(c.counts["setup"]), c.pow2["setup"])


def generic_pair(psi: float):
    """Unit normals at angle ``psi`` in a generic plane (no component zero or equal):
    the end normals the counting and analysis functions run one span on.

    Parameters
    ----------
    psi : float
        The angle between the two normals (radians).

    Returns
    -------
    tuple of numpy.ndarray
        ``(nl, nr)``, two float64 unit vectors of shape ``(3,)`` with ``nl . nr = cos(psi)``.

    Examples
    --------
    >>> nl, nr = generic_pair(0.5)
    >>> round(float(nl @ nr), 12) == round(math.cos(0.5), 12)
    True
    """
    e1 = np.array([2.0, 3.0, 6.0]) / 7.0
    e2 = np.array([3.0, -6.0, 2.0]) / 7.0
    return e1, math.cos(psi) * e1 + math.sin(psi) * e2


def _run_counting(kern, nl, nr, t0, dt, count, coeffs, levels, reanchor):
    """Run kernel ``kern`` on one span with counting scalars; returns (counter, values (count, 3))."""
    c = Counter()
    ops = CountingOps(c)
    a = tuple(Counted(v, c) for v in nl)
    b = tuple(Counted(v, c) for v in nr)
    ct0, cdt = Counted(t0, c), Counted(dt, c)
    vals = []
    if kern.shape == "direct":
        st = kern.setup(ops, a, b, coeffs)
        ops.phase("pixel")
        for j in range(count):
            vals.append(kern.pixel(ops, st, Counted(t0 + j * dt, c)))
            ops.produced(1)
    elif kern.shape == "steps":
        vals = list(kern.steps(ops, a, b, ct0, cdt, count, coefficients=coeffs,
                               start_at_left=t0 == 0, reanchor=reanchor))
    else:
        nodes = kern.tree(ops, a, b, levels, coeffs)
        ts = [t0 + j * dt for j in range(count)]
        scale = 2 ** levels
        if all(float(t * scale).is_integer() for t in ts):
            vals = [nodes[int(t * scale)] for t in ts]
            c.pixels["setup"] += max(count - c.pixels["pixel"], 0)
        else:
            c.pixels["pixel"] = 0  # the midpoints are nodes, the pixels are the picks
            ops.phase("pixel")
            for t in ts:
                k, f = kern.fraction(ops, Counted(t, c), levels)
                ka, kb = int(k.v), min(int(k.v) + 1, scale)
                vals.append(kern.pick(ops, nodes[ka], nodes[kb], f))
                ops.produced(1)
    values = np.array([[float(x) for x in v] for v in vals])
    return c, values


def count_ops(method: str, m: int, *, t0: float = 0.0, dt: float | None = None,
              count: int | None = None, tables=None, angular_reanchor: int | None = None,
              psi: float = math.pi / 4, return_values: bool = False) -> OpCounts:
    """Operation counts of ``method`` on one span of length ``m``, measured by the kernel.

    Arguments as in :func:`~.spans.span_normals` for one span (``psi`` is the
    angle of the generic end normals used; counts do not depend on it).
    With ``return_values`` the result is ``(OpCounts, values)``, the values
    being the float64 normals the counting run computed (equal to
    ``span_normals`` in float64 up to the libm's last bit).

    Parameters
    ----------
    method : str
        A registered method.
    m : int
        The span length.
    t0, dt, count : optional
        The first position, step and pixel count, as in :func:`~chebnorm.methods.span_normals`.
    tables : dict, optional
        Coefficient tables by method name (their degrees set the Horner counts).
    angular_reanchor : int, optional
        Re-anchoring period of the angular recurrence.
    psi : float, optional
        The angle of the end normals the counting run uses.
    return_values : bool, optional
        Also return the normals computed.

    Returns
    -------
    OpCounts or tuple of (OpCounts, numpy.ndarray)
        The counts; with ``return_values``, also the float64 normals, shape ``(P, 3)``.

    Raises
    ------
    ValueError
        For an unknown method or arguments out of range (as :func:`~chebnorm.methods.span_normals`).

    Examples
    --------
    >>> c = count_ops("exact", 8)
    >>> c.per_pixel["sqrt"], c.per_pixel["div"], c.per_span["add"]
    (1, 3, 3)
    >>> count_ops("quadratic", 64).per_pixel
    {'add': 6, 'mul': 0, 'div': 0, 'sqrt': 0, 'trig': 0, 'cmp': 0}
    """
    spec = check_method(method)
    kern = method_kernel(spec)
    nl, nr = generic_pair(psi)
    if isinstance(m, bool) or not isinstance(m, (int, np.integer)):
        raise ValueError(f"span length m = {m!r} is not an integer; accepted: m >= 1")
    m = int(m)
    res = span_normals(spec, nl[None], nr[None], [m], t0=None if t0 == 0 else [t0],
                       dt=None if dt is None else [dt], count=None if count is None else [count],
                       tables=tables, angular_reanchor=angular_reanchor)  # validates
    dt = 1.0 / m if dt is None else float(dt)
    count = m + 1 if count is None else int(count)
    tree = kern.shape == "tree"
    levels = (int(span_levels(np.array([dt]), np.array([float(t0)]), np.array([count]),
                          np.array([float(nl @ nr)]))[0]) if tree else 0)
    coeffs = None
    if spec.table is not None:
        table = resolve_table(spec, tables, np.array([float(nl @ nr)]),
                               np.array([levels]) if tree else None)
        coeffs = None if table is None else table.coefficients
    c, values = _run_counting(kern, nl, nr, float(t0), dt, count, coeffs, levels, angular_reanchor)
    loop = c.pixels["pixel"]
    per_pixel = {k: _clean(c.counts["pixel"][k] / loop) if loop else 0 for k in OP_KINDS}
    out = OpCounts(method=spec.name, m=m, per_pixel=per_pixel, per_span=dict(c.counts["setup"]),
                   pixels_in_setup=c.pixels["setup"], pixels_in_loop=loop,
                   pow2_per_pixel=_clean(c.pow2["pixel"] / loop) if loop else 0,
                   pow2_per_span=c.pow2["setup"],
                   total={k: c.counts["setup"][k] + c.counts["pixel"][k] for k in OP_KINDS})
    if return_values:
        del res
        return out, values
    return out
