"""Parse a function given as text and compile it for every arithmetic we use.

One sympy expression of one real variable is compiled to

* a numpy function (``sympy.lambdify``), for dense sampling in float64;
* an mpmath function, for high-precision point values;
* a python-flint ``arb`` / ``arb_series`` function, for rigorous enclosures
  and Taylor coefficients over balls (the certification engine).

The ``arb`` compiler walks the sympy tree itself, so that every constant
enters as an exact rational or a correctly rounded ball (``pi``), never as a
float that was already rounded by the printer.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable

import mpmath
import numpy as np
import sympy as sp
from flint import arb, arb_series, fmpq
from sympy.parsing.sympy_parser import (
    convert_xor,
    implicit_multiplication_application,
    parse_expr,
    rationalize,
    standard_transformations,
)

__all__ = ["Function1D", "parse_function", "parse_number"]

_TRANSFORMS = standard_transformations + (convert_xor,)

# Functions that the arb compiler knows; the value is (arb method, series method).
_ARB_FUNCS: dict[type, tuple[Callable, Callable]] = {
    sp.exp: (lambda v: v.exp(), lambda s: s.exp()),
    sp.log: (lambda v: v.log(), lambda s: s.log()),
    sp.sin: (lambda v: v.sin(), lambda s: s.sin()),
    sp.cos: (lambda v: v.cos(), lambda s: s.cos()),
    sp.tan: (lambda v: v.tan(), lambda s: s.tan()),
    sp.atan: (lambda v: v.atan(), lambda s: s.atan()),
    sp.asin: (lambda v: v.asin(), lambda s: s.asin()),
    sp.acos: (lambda v: v.acos(), lambda s: s.acos()),
    sp.sinh: (lambda v: v.sinh(), lambda s: (s.exp() - (-s).exp()) / 2),
    sp.cosh: (lambda v: v.cosh(), lambda s: (s.exp() + (-s).exp()) / 2),
    sp.tanh: (lambda v: v.tanh(), lambda s: 1 - 2 / ((2 * s).exp() + 1)),
}


def _local_names(var: str) -> dict:
    names = {name: getattr(sp, name) for name in (
        "sqrt", "exp", "log", "sin", "cos", "tan", "atan", "asin", "acos",
        "sinh", "cosh", "tanh", "pi", "E", "Rational", "Integer")}
    names[var] = sp.Symbol(var, real=True)
    return names


def parse_number(text: str | float | int) -> sp.Expr:
    """Parse an interval endpoint such as ``"sqrt(2)"`` or ``"2*cos(pi/4)"``.

    Floats are taken at their exact binary value. Raises ValueError for text
    that is not a finite real constant.
    """
    if isinstance(text, (int, np.integer)):
        return sp.Integer(int(text))
    if isinstance(text, (float, np.floating)):
        if not np.isfinite(text):
            raise ValueError(f"interval endpoint {text!r} is not finite")
        return sp.Rational(float(text))
    try:
        value = parse_expr(str(text), local_dict=_local_names("_"),
                           transformations=_TRANSFORMS + (rationalize,), evaluate=True)
    except Exception as exc:  # sympy raises many kinds
        raise ValueError(f"cannot parse interval endpoint {text!r}: {exc}") from None
    if not isinstance(value, sp.Expr) or value.free_symbols:
        raise ValueError(f"interval endpoint {text!r} is not a constant")
    num = complex(sp.N(value, 30))
    if num.imag != 0 or not np.isfinite(num.real):
        raise ValueError(f"interval endpoint {text!r} is not a finite real number")
    return value


def _arb_const(value: sp.Expr) -> arb:
    """An exact or correctly enclosing ball for a sympy constant."""
    if value.is_Integer:
        return arb(int(value))
    if value.is_Rational:
        return arb(fmpq(int(value.p), int(value.q)))
    if value.is_Float:
        m, e = sp.Float(value)._mpf_[1], sp.Float(value)._mpf_[2]
        sign = -1 if sp.Float(value)._mpf_[0] else 1
        return arb(sign * int(m)) * arb(2) ** e
    if value is sp.pi:
        return arb.pi()
    if value is sp.E:
        return arb(1).exp()
    raise ValueError(f"unsupported constant {value!r}")


def _ipow(v, n: int):
    """``v**n`` by repeated squaring with multiplications only (Arb's ``**``
    goes through exp/log and returns nan for balls that contain 0)."""
    result = None
    base = v
    while n:
        if n & 1:
            result = base if result is None else result * base
        n >>= 1
        if n:
            base = base * base
    return v * 0 + 1 if result is None else result


def _compile_arb(expr: sp.Expr, var: sp.Symbol, series: bool) -> Callable:
    """Compile ``expr`` to a function of one arb (or arb_series) argument."""
    slot = 1 if series else 0

    def build(node: sp.Expr) -> Callable:
        if node == var:
            return lambda x: x
        if node.is_Number or node in (sp.pi, sp.E):
            c = _arb_const(node)
            return lambda x: c
        if node.is_Add:
            parts = [build(a) for a in node.args]
            def add(x, parts=parts):
                acc = parts[0](x)
                for p in parts[1:]:
                    acc = acc + p(x)
                return acc
            return add
        if node.is_Mul:
            parts = [build(a) for a in node.args]
            def mul(x, parts=parts):
                acc = parts[0](x)
                for p in parts[1:]:
                    acc = acc * p(x)
                return acc
            return mul
        if node.is_Pow:
            base, ex = node.args
            b = build(base)
            if ex.is_Integer:
                n = int(ex)
                if n >= 0:
                    return lambda x: _ipow(b(x), n)
                return lambda x: 1 / _ipow(b(x), -n)
            if ex == sp.Rational(1, 2):
                return lambda x: b(x).sqrt()
            if ex == sp.Rational(-1, 2):
                return lambda x: b(x).rsqrt()
            if ex.is_Rational:
                q = arb(fmpq(int(ex.p), int(ex.q)))
                return lambda x: (b(x).log() * q).exp()
            e = build(ex)
            return lambda x: (b(x).log() * e(x)).exp()
        if node.is_Function and type(node) in _ARB_FUNCS:
            f = _ARB_FUNCS[type(node)][slot]
            (arg,) = node.args
            a = build(arg)
            return lambda x: f(a(x))
        raise ValueError(f"unsupported operation {type(node).__name__} in {expr}")

    return build(expr)


@dataclass(frozen=True)
class Function1D:
    """A real function of one variable, with its evaluators.

    ``expr`` is the sympy expression, ``var`` its variable. The evaluators are
    compiled on first use. Internal: no input checking.
    """

    expr: sp.Expr
    var: sp.Symbol

    @functools.cached_property
    def numpy(self) -> Callable[[np.ndarray], np.ndarray]:
        f = sp.lambdify(self.var, self.expr, "numpy")
        return lambda x: np.asarray(f(np.asarray(x, dtype=float)), dtype=float) * np.ones_like(x, dtype=float)

    @functools.cached_property
    def mpmath(self) -> Callable:
        return sp.lambdify(self.var, self.expr, "mpmath")

    @functools.cached_property
    def arb(self) -> Callable[[arb], arb]:
        return _compile_arb(self.expr, self.var, series=False)

    @functools.cached_property
    def arb_series(self) -> Callable[[arb_series], arb_series]:
        return _compile_arb(self.expr, self.var, series=True)

    def __str__(self) -> str:
        return str(self.expr)


def parse_function(text: str | sp.Expr, var: str = "x") -> Function1D:
    """Parse ``text`` as a real function of the single variable ``var`` (cached).

    >>> parse_function("1/sqrt(2+z)", "z").expr
    1/sqrt(z + 2)

    Raises ValueError for text sympy cannot parse, for symbols other than
    ``var`` and for functions the certification engine does not support.
    """
    return _parse_function(text, var)


@functools.lru_cache(maxsize=256)
def _parse_function(text, var: str) -> Function1D:
    if not isinstance(var, str) or not var.isidentifier():
        raise ValueError(f"variable name {var!r} is not an identifier")
    symbol = sp.Symbol(var, real=True)
    if isinstance(text, sp.Expr):
        expr = text.subs({s: symbol for s in text.free_symbols if s.name == var})
    else:
        try:
            expr = parse_expr(str(text), local_dict=_local_names(var), transformations=_TRANSFORMS)
        except Exception as exc:
            raise ValueError(f"cannot parse expression {text!r}: {type(exc).__name__}: {exc}".splitlines()[0]) from None
    if not isinstance(expr, sp.Expr):
        raise ValueError(f"expression {text!r} is not a scalar expression")
    others = sorted(s.name for s in expr.free_symbols if s != symbol)
    if others:
        raise ValueError(f"expression {text!r} uses unknown variable(s) {', '.join(others)}; "
                         f"the only accepted variable is {var!r} (set it with --var)")
    fn = Function1D(expr, symbol)
    try:
        fn.arb_series  # compile now so an unsupported operation is reported here
    except ValueError as exc:
        raise ValueError(f"expression {text!r}: {exc}") from None
    return fn
