"""The eight span-interpolation kernels of seed 000, written once against :mod:`.ops`.

Every kernel runs unchanged on numpy arrays (:class:`~.ops.NumpyOps`, one
array entry per span or per pixel) and on counting scalars
(:class:`~.ops.CountingOps`). Vectors are 3-tuples of scalars.

**These kernels do not validate anything**: they assume unit end normals,
``1 + N_l.N_r > 0``, positive steps and tables covering the angles, as
checked once by :func:`chebnorm.methods.span_normals`.

Three shapes of kernel object, told apart by its ``shape`` attribute (the
method registry, :mod:`chebnorm.approx.method_registry`, names one object per
method; :func:`chebnorm.methods.span_normals` dispatches on the shape only):

* ``"direct"`` (``exact``, ``none``, ``newton``, ``lyon``, ``slerp``):
  ``setup(ops, nl, nr, coefficients)`` once per span, then
  ``pixel(ops, state, t)`` at any position ``t``, independently;
* ``"steps"`` (``quadratic``, ``angular``): ``steps(ops, nl, nr, t0, dt, n, *,
  coefficients, start_at_left, reanchor)``, a generator yielding the pixels
  ``t0, t0 + dt, ...`` in order (forward differences, recurrence);
* ``"tree"`` (``dichotomy``): ``tree(ops, nl, nr, levels, coefficients)``,
  successive angle halving, then ``fraction`` and ``pick`` per pixel.

``coefficients`` are those of the method's table (ascending, None: exact
``1/sqrt``); a kernel's ``table_scale`` says what its table's variable is:
``table_scale * cos(angle)`` of the two normals it combines.

Linear interpolation is ``N(t) = N_l + t (N_r - N_l)`` (3 mul, 3 add per
pixel, the difference once per span).
"""

from __future__ import annotations

from chebnorm.core.docfrag import docstring

# an implementation module of chebnorm.methods: the API is what chebnorm.methods exports
__all__: list[str] = []

#: the one parameter block every kernel shares
_ops_doc = docstring(ops="ops : NumpyOps or CountingOps\n"
                           "    The arithmetic backend (numpy arrays of one dtype, or counted float64).")

#: the kernel shapes (see the module docstring)
SHAPES = ("direct", "steps", "tree")
#: guard for divisions by sin(psi) or sin of a zero angle (parallel end normals)
TINY = 1e-30


# --------------------------------------------------------------- vectors
def vadd(a, b):
    """``a + b``: 3 add."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def vsub(a, b):
    """``a - b``: 3 add."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def vmul(a, s):
    """``a * s`` for a scalar ``s``: 3 mul."""
    return (a[0] * s, a[1] * s, a[2] * s)


def dot(a, b):
    """``a.b``: 3 mul, 2 add.

    Parameters
    ----------
    a, b : tuple of 3 scalars or arrays
        Two vectors, component by component.

    Returns
    -------
    scalar or array
        ``a[0] b[0] + a[1] b[1] + a[2] b[2]``, added in that order.

    Examples
    --------
    >>> dot((1.0, 2.0, 3.0), (4.0, 5.0, 6.0))
    32.0
    """
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def lerp(a, d, t):
    """``a + t d``: 3 mul, 3 add."""
    return (a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2])


@_ops_doc
def horner(ops, coefficients, x):
    """``p(x)`` from ascending coefficients (degree d: d mul, d add).

    Parameters
    ----------
    %(ops)s
    coefficients : sequence of float
        Ascending coefficients (constants of the backend).
    x : scalar or array
        The argument.

    Returns
    -------
    scalar or array
        ``p(x)`` by Horner's rule from the highest coefficient.

    Examples
    --------
    >>> import numpy as np
    >>> from chebnorm.methods.ops import NumpyOps
    >>> float(horner(NumpyOps(), [1.0, 2.0, 3.0], np.array(2.0)))   # 1 + 2*2 + 3*4
    17.0
    """
    p = ops.const(coefficients[-1])
    for c in reversed(coefficients[:-1]):
        p = p * x + ops.const(c)
    return p


# ---------------------------------------------------------- normalizers
@_ops_doc
def normalize_classic(ops, n):
    """Classic normalization ``N / sqrt(N.N)`` (seed 000): 3 mul, 2 add, 1 sqrt, 3 div.

    Parameters
    ----------
    %(ops)s
    n : tuple of 3 scalars or arrays
        The vector to normalize.

    Returns
    -------
    tuple of 3 scalars or arrays
        ``N / sqrt(N.N)``.

    Examples
    --------
    >>> import numpy as np
    >>> from chebnorm.methods.ops import NumpyOps
    >>> [float(c) for c in normalize_classic(NumpyOps(), (np.array(3.0), np.array(4.0), np.array(0.0)))]
    [0.6, 0.8, 0.0]
    """
    r = ops.sqrt(dot(n, n))
    return (n[0] / r, n[1] / r, n[2] / r)


@_ops_doc
def normalize_newton(ops, n):
    """One Newton-Raphson step from 1 for ``1/sqrt(x)``: ``N (3 - N.N) / 2`` (seed 000, method 1).

    The halving is written as a multiplication by 0.5 (an exponent shift).

    For a normal of length ``l`` the result has length ``l (3 - l^2)/2``,
    short of 1 by ``(1 - l)^2 (2 + l)/2``; ``l = 0.95`` gives ``0.9963125``:

    Parameters
    ----------
    %(ops)s
    n : tuple of 3 scalars or arrays
        The vector to normalize.

    Returns
    -------
    tuple of 3 scalars or arrays
        ``N (3 - N.N) / 2``.

    Examples
    --------
    >>> import numpy as np
    >>> from chebnorm.methods.ops import NumpyOps
    >>> float(normalize_newton(NumpyOps(), (np.array(0.95), np.array(0.0), np.array(0.0)))[0])
    0.9963125
    """
    s = (3.0 - dot(n, n)) * 0.5
    return vmul(n, s)


@_ops_doc
def normalize_lyon(ops, n):
    """Lyon's three-term Taylor series ``N (15 - 10 x + 3 x^2) / 8``, ``x = N.N``
    (seed 000, method 2), the 1/8 folded into the coefficients (Horner).

    ``l = 0.95``: ``0.95 (15 - 10 * 0.9025 + 3 * 0.81450625)/8``:

    Parameters
    ----------
    %(ops)s
    n : tuple of 3 scalars or arrays
        The vector to normalize.

    Returns
    -------
    tuple of 3 scalars or arrays
        ``N (15 - 10 x + 3 x^2) / 8``.

    Examples
    --------
    >>> import numpy as np
    >>> from chebnorm.methods.ops import NumpyOps
    >>> round(float(normalize_lyon(NumpyOps(), (np.array(0.95), np.array(0.0), np.array(0.0)))[0]), 10)
    0.9996991016
    """
    x = dot(n, n)
    s = (x * 0.375 - 1.25) * x + 1.875
    return vmul(n, s)


# -------------------------------------------------------- direct kernels
class _Linear:
    """Linear interpolation followed by a normalizer (or none)."""

    shape = "direct"
    table_scale = 1.0

    def __init__(self, normalizer):
        self.normalizer = normalizer

    def setup(self, ops, nl, nr, coefficients=None):
        return {"a": nl, "d": vsub(nr, nl)}

    def pixel(self, ops, st, t):
        n = lerp(st["a"], st["d"], t)
        return n if self.normalizer is None else self.normalizer(ops, n)


class _Slerp:
    """Seed 000, method 3: ``[sin((1-t) psi) N_a + sin(t psi) N_b] / sin psi``,
    ``psi = arccos(N_a.N_b)``; ``1/sin psi`` once per span. Parallel end
    normals (psi = 0) use ``psi = TINY``, which reduces to linear interpolation."""

    shape = "direct"
    table_scale = 1.0
    normalizer = None

    def setup(self, ops, nl, nr, coefficients=None):
        c = ops.minimum(dot(nl, nr), 1.0)
        psi = ops.maximum(ops.arccos(c), TINY)
        return {"a": nl, "b": nr, "psi": psi, "inv": 1.0 / ops.sin(psi)}

    def pixel(self, ops, st, t):
        wa = ops.sin((1.0 - t) * st["psi"]) * st["inv"]
        wb = ops.sin(t * st["psi"]) * st["inv"]
        return vadd(vmul(st["a"], wa), vmul(st["b"], wb))


#: kernel of ``exact``: linear interpolation, then :func:`normalize_classic`
EXACT = _Linear(normalize_classic)
#: kernel of ``none``: linear interpolation, not normalized
NONE = _Linear(None)
#: kernel of ``newton``: linear interpolation, then :func:`normalize_newton`
NEWTON = _Linear(normalize_newton)
#: kernel of ``lyon``: linear interpolation, then :func:`normalize_lyon`
LYON = _Linear(normalize_lyon)
#: kernel of ``slerp``: the spherical interpolation, evaluated directly per pixel
SLERP = _Slerp()


# ------------------------------------------------------ stepping kernels
def _angular_point(ops, nl, nk, angle):
    ca, sa = ops.cos(angle), ops.sin(angle)
    return vadd(vmul(nl, ca), vmul(nk, sa)), ca, sa


@_ops_doc
def angular_steps(ops, nl, nr, t0, dt, n, *, start_at_left=False, reanchor=None):
    """Seed 000, method 6: ``N(t) = N_a cos(t psi) + N_k sin(t psi)`` by the recurrence
    ``N_{j+1} = 2 cos(phi) N_j - N_{j-1}``, ``phi = psi dt`` (``psi/m`` by default).

    Yields ``n`` pixels. Set-up: ``N_k = (N_b - c N_a)/sqrt(1 - c^2)``, psi,
    cos phi, sin phi, the first two pixels. Per pixel: 3 mul, 3 add.
    ``reanchor=K`` recomputes ``N_{j-1}, N_j`` from the closed form every K
    pixels (4 trig, 16 mul, 8 add per anchor instead of 3 mul, 3 add),
    bounding the float32 drift.

    Parameters
    ----------
    %(ops)s
    nl, nr : tuple of 3 scalars or arrays
        The span's unit end normals, component by component.
    t0 : float or array
        The first pixel's position.
    dt : float or array
        The step between pixels.
    n : int
        The number of pixels.
    start_at_left : bool, optional
        The first pixel is ``N_l`` itself (``t0 = 0``), not computed.
    reanchor : int, optional
        Recompute from the closed form every this many pixels.

    Yields
    ------
    tuple of 3 scalars or arrays
        The pixel normals in order, not normalized by anything but the recurrence.

    Examples
    --------
    >>> import math
    >>> import numpy as np
    >>> from chebnorm.methods.ops import NumpyOps
    >>> ops = NumpyOps()
    >>> nl = (np.array([1.0]), np.array([0.0]), np.array([0.0]))
    >>> nr = (np.array([0.0]), np.array([1.0]), np.array([0.0]))
    >>> px = list(angular_steps(ops, nl, nr, 0.0, 0.25, 5))   # quarter-circle in 4 steps
    >>> err = max(abs(float(p[0][0]) - math.cos(j * math.pi / 8)) for j, p in enumerate(px))
    >>> err <= 8 * 2.0 ** -53   # on the slerp points, within a few float64 roundings
    True
    """
    c = ops.minimum(dot(nl, nr), 1.0)
    psi = ops.arccos(c)
    inv_w = 1.0 / ops.maximum(ops.sqrt(1.0 - c * c), TINY)
    nk = vmul(vsub(nr, vmul(nl, c)), inv_w)
    phi = psi * dt
    cp, sp = ops.cos(phi), ops.sin(phi)
    k2 = cp * 2.0
    if start_at_left:
        p0 = nl
        p1 = vadd(vmul(nl, cp), vmul(nk, sp))
    else:
        p0, ca, sa = _angular_point(ops, nl, nk, t0 * psi)
        q0 = vsub(vmul(nk, ca), vmul(nl, sa))  # d/d(angle) of N at t0
        p1 = vadd(vmul(p0, cp), vmul(q0, sp))
    ops.produced(1)
    yield p0
    if n < 2:
        return
    ops.produced(1)
    yield p1
    ops.phase("pixel")
    for j in range(2, n):
        if reanchor and j % reanchor == 0:
            base = 0.0 if start_at_left else t0
            p0 = _angular_point(ops, nl, nk, (base + dt * float(j - 1)) * psi)[0]
            p1 = _angular_point(ops, nl, nk, (base + dt * float(j)) * psi)[0]
        else:
            p0, p1 = p1, vsub(vmul(p1, k2), p0)
        ops.produced(1)
        yield p1


@_ops_doc
def quadratic_steps(ops, nl, nr, t0, dt, n, *, coefficients=None, start_at_left=False):
    """Seed 000, method 5: ``N(t) = G t^2 + P t + Q`` through ``N_l``, ``N_c``, ``N_r``,
    ``N_c = (N_l + N_r) p(N_l.N_r)`` with ``p ~ 1/sqrt(2(1+x))`` (the ``midpoint``
    table; ``coefficients=None``: exact ``1/sqrt``), evaluated by forward
    differences (6 add per pixel) and not normalized.

    ``Q = N_l``, ``G = 2 N_l + 2 N_r - 4 N_c``, ``P = 4 N_c - 3 N_l - N_r``.

    Parameters
    ----------
    %(ops)s
    nl, nr : tuple of 3 scalars or arrays
        The span's unit end normals.
    t0 : float or array
        The first pixel's position.
    dt : float or array
        The step between pixels.
    n : int
        The number of pixels.
    coefficients : sequence of float, optional
        Ascending coefficients of ``p(x) ~ 1/sqrt(2(1 + x))``; None: exact ``1/sqrt``.
    start_at_left : bool, optional
        The first pixel is ``N_l`` itself (``t0 = 0``).

    Yields
    ------
    tuple of 3 scalars or arrays
        The pixel normals ``G t^2 + P t + Q`` in order (not normalized).

    Examples
    --------
    >>> import math
    >>> import numpy as np
    >>> from chebnorm.methods.ops import NumpyOps
    >>> ops = NumpyOps()
    >>> nl = (np.array([1.0]), np.array([0.0]), np.array([0.0]))
    >>> nr = (np.array([0.0]), np.array([1.0]), np.array([0.0]))
    >>> px = list(quadratic_steps(ops, nl, nr, 0.0, 0.5, 3))   # t = 0, 1/2, 1
    >>> [[round(float(c[0]), 6) for c in p] for p in px]   # through N_l, N_c = (N_l + N_r)/sqrt 2, N_r
    [[1.0, 0.0, 0.0], [0.707107, 0.707107, 0.0], [0.0, 1.0, 0.0]]
    """
    x = dot(nl, nr)
    s = vadd(nl, nr)
    r = horner(ops, coefficients, x) if coefficients is not None \
        else 1.0 / ops.sqrt((x + 1.0) * 2.0)
    nc4 = vmul(vmul(s, r), 4.0)
    g = vsub(vmul(s, 2.0), nc4)
    p = vsub(vsub(nc4, vmul(nl, 2.0)), s)
    h2 = dt * dt
    d2 = vmul(g, h2 * 2.0)
    if start_at_left:
        v = nl
        d1 = vadd(vmul(p, dt), vmul(g, h2))
    else:
        v = vadd(nl, vmul(vadd(p, vmul(g, t0)), t0))
        d1 = vadd(vmul(p, dt), vmul(g, (t0 * dt) * 2.0 + h2))
    ops.produced(1)
    yield v
    ops.phase("pixel")
    for _ in range(1, n):
        v = vadd(v, d1)
        d1 = vadd(d1, d2)
        ops.produced(1)
        yield v


class _Steps:
    """A stepping kernel: ``steps`` runs ``generator`` (which takes the options it names)."""

    shape = "steps"
    table_scale = 1.0
    normalizer = None

    def __init__(self, generator, options):
        self.generator = generator
        self.options = options

    def steps(self, ops, nl, nr, t0, dt, n, *, coefficients=None, start_at_left=False,
              reanchor=None):
        given = {"coefficients": coefficients, "reanchor": reanchor}
        kw = {k: given[k] for k in self.options}
        return self.generator(ops, nl, nr, t0, dt, n, start_at_left=start_at_left, **kw)


#: kernel of ``quadratic``: :func:`quadratic_steps`
QUADRATIC = _Steps(quadratic_steps, ("coefficients",))
#: kernel of ``angular``: :func:`angular_steps`
ANGULAR = _Steps(angular_steps, ("reanchor",))


# ------------------------------------------------------------ dichotomy
@_ops_doc
def dichotomy_tree(ops, nl, nr, levels, coefficients=None):
    """Seed 000, method 4: ``levels`` rounds of angle halving; returns the
    ``2**levels + 1`` nodes from ``N_l`` to ``N_r`` (the slerp points at
    ``k / 2**levels``).

    A midpoint is ``(N_1 + N_2) / sqrt(2 + z)``, ``z = 2 cos(theta)``: per level
    one denominator ``r = p(z)`` (the ``dichotomy`` table; ``None``: exact
    ``1/sqrt``) and the next level's ``z' = sqrt(2 + z) = (2 + z) r`` (one mul,
    no sqrt); per midpoint 3 add, 3 mul.

    Parameters
    ----------
    %(ops)s
    nl, nr : tuple of 3 scalars or arrays
        The span's unit end normals.
    levels : int
        The number of halving rounds.
    coefficients : sequence of float, optional
        Ascending coefficients of the denominator polynomial ``p(z) ~ 1/sqrt(2 + z)``;
        None: exact ``1/sqrt``.

    Returns
    -------
    list of tuple of 3 scalars or arrays
        The ``2**levels + 1`` nodes, from ``N_l`` to ``N_r``.

    Examples
    --------
    >>> import math
    >>> import numpy as np
    >>> from chebnorm.methods.ops import NumpyOps
    >>> ops = NumpyOps()
    >>> nl = (np.array([1.0]), np.array([0.0]), np.array([0.0]))
    >>> nr = (np.array([0.0]), np.array([1.0]), np.array([0.0]))
    >>> nodes = dichotomy_tree(ops, nl, nr, 2)   # 5 nodes: slerp at 0, 1/4, 1/2, 3/4, 1
    >>> err = max(abs(float(n[0][0]) - math.cos(k * math.pi / 8)) for k, n in enumerate(nodes))
    >>> err <= 8 * 2.0 ** -53   # within a few float64 roundings
    True
    """
    z = dot(nl, nr) * 2.0
    nodes = [nl, nr]
    for level in range(levels):
        ops.phase("setup")
        s = z + 2.0
        r = horner(ops, coefficients, z) if coefficients is not None else 1.0 / ops.sqrt(s)
        if level < levels - 1:
            z = s * r
        ops.phase("pixel")
        new = [nodes[0]]
        for a, b in zip(nodes[:-1], nodes[1:]):
            new.append(vmul(vadd(a, b), r))
            ops.produced(1)
            new.append(b)
        nodes = new
    return nodes


@_ops_doc
def dichotomy_fraction(ops, t, levels):
    """Position ``t`` on the dyadic grid: node index ``k = floor(t 2**levels)`` (a scalar)
    and fraction ``f`` (1 pow2 mul, 1 cmp, 1 add).

    Parameters
    ----------
    %(ops)s
    t : array
        Pixel positions in ``[0, 1]``.
    levels : int
        The depth of the dyadic grid.

    Returns
    -------
    tuple of (array, array)
        The node index ``k`` (as floats) and the fraction ``f`` in ``[0, 1)``.

    Examples
    --------
    >>> import math
    >>> import numpy as np
    >>> from chebnorm.methods.ops import NumpyOps
    >>> k, f = dichotomy_fraction(NumpyOps(), np.array([0.3]), 2)   # 0.3 * 4 = 1.2
    >>> k.tolist(), f.round(12).tolist()
    ([1.0], [0.2])
    """
    u = t * float(2 ** levels)
    k = ops.floor(u)
    return k, u - k


@_ops_doc
def dichotomy_pick(ops, a, b, f):
    """Linear pick between the nodes around an off-grid pixel: ``A + f (B - A)``.

    Parameters
    ----------
    %(ops)s
    a, b : tuple of 3 scalars or arrays
        The nodes left and right of the pixel.
    f : array
        The pixel's fraction between them.

    Returns
    -------
    tuple of 3 arrays
        ``A + f (B - A)``, not normalized.

    Examples
    --------
    >>> import math
    >>> import numpy as np
    >>> from chebnorm.methods.ops import NumpyOps
    >>> a = (np.array([1.0]), np.array([0.0]), np.array([0.0]))
    >>> b = (np.array([0.0]), np.array([1.0]), np.array([0.0]))
    >>> [float(c[0]) for c in dichotomy_pick(NumpyOps(), a, b, np.array([0.25]))]
    [0.75, 0.25, 0.0]
    """
    return lerp(a, vsub(b, a), f)


class _Tree:
    """The dichotomy kernel: its table's variable is ``z = 2 cos(theta)``."""

    shape = "tree"
    table_scale = 2.0
    normalizer = None
    tree = staticmethod(dichotomy_tree)
    fraction = staticmethod(dichotomy_fraction)
    pick = staticmethod(dichotomy_pick)


#: kernel of ``dichotomy``: :func:`dichotomy_tree`, :func:`dichotomy_fraction`, :func:`dichotomy_pick`
DICHOTOMY = _Tree()
