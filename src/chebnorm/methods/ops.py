"""The tiny op interface every kernel of :mod:`chebnorm.methods` is written against.

A kernel does its arithmetic with Python operators (``+ - * /``) on
"scalars", and calls ``ops.sqrt``, ``ops.cos``, ``ops.sin``, ``ops.arccos``,
``ops.minimum``, ``ops.maximum``, ``ops.const`` for everything else. Vectors
are 3-tuples of scalars. Two backends implement the interface:

* :class:`NumpyOps` -- scalars are numpy arrays of one dtype (float32 or
  float64), one entry per span (or per pixel); computation stays in that
  dtype (numpy >= 2 keeps Python-float constants "weak"). ``sin``, ``cos``
  and ``arccos`` come from :mod:`.detmath` (float32 correctly rounded, float64
  by the C library), not from numpy's CPU-dispatched loops, so the float32
  datapath gives the same bits on every machine.
* :class:`CountingOps` -- scalars are :class:`Counted` numbers: a float64
  value plus a shared :class:`Counter` that records every operation applied
  to it (add, mul, div, sqrt, trig, cmp), split by the phase the kernel is
  in (``"setup"`` once per span, ``"pixel"`` per produced pixel).

So the operation counts come from the very code that computes the values.
Counting rules:

* ``a + b``, ``a - b`` -> add; ``a * b`` -> mul; ``a / b`` -> div;
* a multiplication by a constant power of two (``x * 0.5``) is a mul, and is
  also tallied as ``pow2``: in floating point it is an exponent shift, in
  fixed point a wire shift -- free in hardware;
* ``sqrt`` -> sqrt; ``sin``, ``cos``, ``arccos`` -> trig;
* ``minimum``, ``maximum`` (compare and select), ``floor`` -> cmp;
* negation (sign flip) and arithmetic between two plain constants (folded
  at compile time) are free and not counted.

>>> c = Counter(); ops = CountingOps(c)
>>> x, y = Counted(3.0, c), Counted(4.0, c)
>>> r = ops.sqrt(x * x + y * y); r.v
5.0
>>> c.counts["setup"]
{'add': 1, 'mul': 2, 'div': 0, 'sqrt': 1, 'trig': 0, 'cmp': 0}
"""

from __future__ import annotations

import math

import numpy as np

from . import detmath

# an implementation module of chebnorm.methods: the API is what chebnorm.methods exports
__all__: list[str] = []

#: the operation kinds every count reports, in this order
OP_KINDS = ("add", "mul", "div", "sqrt", "trig", "cmp")
PHASES = ("setup", "pixel")


def _is_pow2(c) -> bool:
    if not isinstance(c, (int, float)) or c == 0 or not math.isfinite(c):
        return False
    return math.frexp(abs(c))[0] == 0.5


class NumpyOps:
    """numpy backend: every scalar is an array of ``dtype``.

    Parameters
    ----------
    dtype : numpy dtype, optional
        float32 or float64: every constant and result has this dtype.

    Examples
    --------
    >>> ops = NumpyOps(np.float32)
    >>> ops.const(0.1).dtype, ops.sqrt(np.float32(2)).dtype, ops.counting
    (dtype('float32'), dtype('float32'), False)
    """

    counting = False

    def __init__(self, dtype=np.float64):
        self.dtype = np.dtype(dtype).type

    def const(self, c):
        return self.dtype(c)

    def sqrt(self, x):
        return np.sqrt(x)

    def sin(self, x):
        return detmath.sin(x)

    def cos(self, x):
        return detmath.cos(x)

    def arccos(self, x):
        return detmath.arccos(x)

    def minimum(self, a, b):
        return np.minimum(a, b)

    def maximum(self, a, b):
        return np.maximum(a, b)

    def floor(self, x):
        return np.floor(x)

    def phase(self, name: str) -> None:
        """Mark the kernel's phase (no-op here)."""

    def produced(self, k: int = 1) -> None:
        """Tell the counter how many pixels the current phase produced (no-op here)."""


class Counter:
    """Operation tallies per phase, and pixels produced per phase.

    Examples
    --------
    >>> c = Counter()
    >>> c.record("add"); c.current = "pixel"; c.record("mul", pow2=True)
    >>> c.counts["setup"]["add"], c.counts["pixel"]["mul"], c.pow2
    (1, 1, {'setup': 0, 'pixel': 1})
    """

    def __init__(self):
        self.counts = {p: dict.fromkeys(OP_KINDS, 0) for p in PHASES}
        self.pow2 = dict.fromkeys(PHASES, 0)
        self.pixels = dict.fromkeys(PHASES, 0)
        self.current = "setup"

    def record(self, kind: str, pow2: bool = False) -> None:
        self.counts[self.current][kind] += 1
        if pow2:
            self.pow2[self.current] += 1


class Counted:
    """A float64 value that records the operations applied to it in a :class:`Counter`.

    Parameters
    ----------
    v : float
        The value.
    counter : Counter
        Where the operations on it are recorded.

    Examples
    --------
    >>> c = Counter()
    >>> x = Counted(3.0, c)
    >>> (x * 0.5, x / 2.0, -x), c.pow2["setup"], c.counts["setup"]["div"]
    ((Counted(1.5), Counted(1.5), Counted(-3.0)), 1, 1)
    """

    __slots__ = ("v", "c")

    def __init__(self, v, counter: Counter):
        self.v = float(v)
        self.c = counter

    def __repr__(self) -> str:
        return f"Counted({self.v!r})"

    @staticmethod
    def _val(o):
        return o.v if isinstance(o, Counted) else float(o)

    def _bin(self, o, kind, fn, pow2=False):
        self.c.record(kind, pow2)
        return Counted(fn(self.v, self._val(o)), self.c)

    def __add__(self, o):
        return self._bin(o, "add", lambda a, b: a + b)

    def __radd__(self, o):
        return self._bin(o, "add", lambda a, b: b + a)

    def __sub__(self, o):
        return self._bin(o, "add", lambda a, b: a - b)

    def __rsub__(self, o):
        return self._bin(o, "add", lambda a, b: b - a)

    def __mul__(self, o):
        return self._bin(o, "mul", lambda a, b: a * b, pow2=_is_pow2(o))

    def __rmul__(self, o):
        return self._bin(o, "mul", lambda a, b: b * a, pow2=_is_pow2(o))

    def __truediv__(self, o):
        return self._bin(o, "div", lambda a, b: a / b if b != 0 else math.copysign(math.inf, a))

    def __rtruediv__(self, o):
        return self._bin(o, "div", lambda a, b: b / a if a != 0 else math.inf)

    def __neg__(self):
        return Counted(-self.v, self.c)

    def __float__(self) -> float:
        return self.v


class CountingOps:
    """Counting backend: scalars are :class:`Counted`, constants stay plain floats.

    Parameters
    ----------
    counter : Counter
        Where the operations are recorded (set-up and per-pixel phases).

    Examples
    --------
    >>> c = Counter()
    >>> ops = CountingOps(c)
    >>> ops.cos(Counted(0.0, c)).v, ops.cos(0.0), c.counts["setup"]["trig"]   # a constant is folded, free
    (1.0, 1.0, 1)
    """

    counting = True

    def __init__(self, counter: Counter):
        self.counter = counter

    def const(self, c):
        return float(c)

    def _un(self, x, kind, fn):
        if not isinstance(x, Counted):  # a constant: folded, free
            return fn(float(x))
        self.counter.record(kind)
        return Counted(fn(x.v), self.counter)

    def sqrt(self, x):
        return self._un(x, "sqrt", math.sqrt)

    def sin(self, x):
        return self._un(x, "trig", math.sin)

    def cos(self, x):
        return self._un(x, "trig", math.cos)

    def arccos(self, x):
        return self._un(x, "trig", math.acos)

    def minimum(self, a, b):
        self.counter.record("cmp")
        return Counted(min(Counted._val(a), Counted._val(b)), self.counter)

    def maximum(self, a, b):
        self.counter.record("cmp")
        return Counted(max(Counted._val(a), Counted._val(b)), self.counter)

    def floor(self, x):
        self.counter.record("cmp")
        return Counted(math.floor(Counted._val(x)), self.counter)

    def phase(self, name: str) -> None:
        if name not in PHASES:
            raise ValueError(f"unknown phase {name!r}; accepted: {', '.join(PHASES)}")
        self.counter.current = name

    def produced(self, k: int = 1) -> None:
        self.counter.pixels[self.counter.current] += k
