"""Trace a Python callable into a sympy expression, so it can be certified.

:func:`chebnorm.approx.fit` accepts ``expr`` as text, as a sympy expression,
or as a Python callable of one argument built from arithmetic operators,
numpy ufuncs (``np.exp``, ``np.sqrt``, ``np.power``, ...), functions of
:mod:`math` (``math.exp``, ``math.sqrt``, ...) and sympy functions. The
callable is called once with a tracer standing for the variable: operators
and ufuncs applied to it build the sympy expression, and ``math`` functions
named in the callable's globals or closure are replaced, for that one call,
by their sympy counterparts. A callable that branches on its argument
(``if x > 0``), calls a helper that uses ``math`` itself, or uses a numpy
function that is not a ufunc cannot be traced: :func:`trace_callable` then
raises a ValueError that says to pass a string or a sympy expression.

Floats in the callable are taken at their exact binary values, as the
callable computes with them: ``lambda x: np.sin(np.pi * x)`` is
``sin(884279719003555/281474976710656 * x)``, not ``sin(pi*x)`` (pass the
text ``"sin(pi*x)"`` for the exact constant).
"""

from __future__ import annotations

import math
import types

import numpy as np
import sympy as sp

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []


def _log_base(base):
    return lambda v: sp.log(v) / sp.log(base)


#: numpy ufunc name -> the sympy function of its arguments
UFUNCS = {
    "add": lambda a, b: a + b, "subtract": lambda a, b: a - b,
    "multiply": lambda a, b: a * b, "divide": lambda a, b: a / b,
    "true_divide": lambda a, b: a / b, "power": lambda a, b: a ** b,
    "float_power": lambda a, b: a ** b, "negative": lambda a: -a, "positive": lambda a: a,
    "reciprocal": lambda a: 1 / a, "square": lambda a: a ** 2, "sqrt": sp.sqrt,
    "cbrt": lambda a: sp.root(a, 3), "absolute": sp.Abs, "fabs": sp.Abs,
    "exp": sp.exp, "exp2": lambda a: 2 ** a, "expm1": lambda a: sp.exp(a) - 1,
    "log": sp.log, "log2": _log_base(2), "log10": _log_base(10),
    "log1p": lambda a: sp.log(1 + a),
    "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "arcsin": sp.asin, "arccos": sp.acos,
    "arctan": sp.atan, "sinh": sp.sinh, "cosh": sp.cosh, "tanh": sp.tanh,
    "arcsinh": sp.asinh, "arccosh": sp.acosh, "arctanh": sp.atanh,
    "hypot": lambda a, b: sp.sqrt(a ** 2 + b ** 2),
}

#: :mod:`math` function name -> the sympy function of its arguments
MATH_FUNCTIONS = {
    "exp": sp.exp, "expm1": lambda a: sp.exp(a) - 1, "log": lambda a, b=None: (
        sp.log(a) if b is None else sp.log(a) / sp.log(b)),
    "log2": _log_base(2), "log10": _log_base(10), "log1p": lambda a: sp.log(1 + a),
    "sqrt": sp.sqrt, "cbrt": lambda a: sp.root(a, 3), "pow": lambda a, b: a ** b,
    "fabs": sp.Abs, "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "asin": sp.asin,
    "acos": sp.acos, "atan": sp.atan, "sinh": sp.sinh, "cosh": sp.cosh, "tanh": sp.tanh,
    "asinh": sp.asinh, "acosh": sp.acosh, "atanh": sp.atanh, "erf": sp.erf, "erfc": sp.erfc,
    "gamma": sp.gamma, "hypot": lambda a, b: sp.sqrt(a ** 2 + b ** 2),
    "exp2": lambda a: 2 ** a,
}


class _Untraceable(Exception):
    """Raised inside a traced call where the callable leaves what can be traced."""


def _sym(value):
    """``value`` as a sympy object (floats at their exact binary value)."""
    if isinstance(value, _Tracer):
        return value.expr
    if isinstance(value, (bool, np.bool_)):
        raise _Untraceable(f"a boolean {value!r}")
    if isinstance(value, (int, np.integer)):
        return sp.Integer(int(value))
    if isinstance(value, (float, np.floating)):
        f = float(value)
        if not math.isfinite(f):
            raise _Untraceable(f"the non-finite constant {f!r}")
        return sp.Rational(*f.as_integer_ratio())
    if isinstance(value, sp.Basic):
        return value
    if isinstance(value, np.ndarray) and value.shape == ():
        return _sym(value.item() if value.dtype == object else value[()])
    raise _Untraceable(f"a value of type {type(value).__name__}")


class _Tracer:
    """Stands for the variable (or an expression of it) during a traced call."""

    __array_priority__ = 1000

    def __init__(self, expr):
        self.expr = expr

    def _sympy_(self):  # sympy functions accept a tracer
        return self.expr

    # arithmetic builds the expression
    def __add__(self, o): return _Tracer(self.expr + _sym(o))
    def __radd__(self, o): return _Tracer(_sym(o) + self.expr)
    def __sub__(self, o): return _Tracer(self.expr - _sym(o))
    def __rsub__(self, o): return _Tracer(_sym(o) - self.expr)
    def __mul__(self, o): return _Tracer(self.expr * _sym(o))
    def __rmul__(self, o): return _Tracer(_sym(o) * self.expr)
    def __truediv__(self, o): return _Tracer(self.expr / _sym(o))
    def __rtruediv__(self, o): return _Tracer(_sym(o) / self.expr)
    def __pow__(self, o): return _Tracer(self.expr ** _sym(o))
    def __rpow__(self, o): return _Tracer(_sym(o) ** self.expr)
    def __neg__(self): return _Tracer(-self.expr)
    def __pos__(self): return self
    def __abs__(self): return _Tracer(sp.Abs(self.expr))

    def _refuse(self, *_):
        raise _Untraceable("a comparison, branch or conversion of the variable")

    __lt__ = __le__ = __gt__ = __ge__ = __bool__ = __index__ = __floordiv__ = \
        __rfloordiv__ = __mod__ = __rmod__ = _refuse

    def __float__(self):
        if self.expr.is_number:
            return float(self.expr)
        self._refuse()

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        rule = UFUNCS.get(ufunc.__name__)
        if method != "__call__" or kwargs or rule is None:
            raise _Untraceable(f"numpy.{ufunc.__name__} (supported ufuncs: "
                               f"{', '.join(sorted(UFUNCS))})")
        return _Tracer(rule(*(_sym(v) for v in inputs)))

    def __array_function__(self, func, types_, args, kwargs):
        raise _Untraceable(f"numpy.{getattr(func, '__name__', func)} (not a ufunc)")


def _math_shim(name: str, original):
    """A stand-in for ``math.<name>``: sympy on a traced value, the original otherwise."""
    rule = MATH_FUNCTIONS.get(name)

    def shim(*args):
        if any(isinstance(a, (_Tracer, sp.Basic)) for a in args):
            if rule is None:
                raise _Untraceable(f"math.{name}")
            return _Tracer(rule(*(_sym(a) for a in args)))
        return original(*args)

    return shim


def _math_module():
    """A namespace like :mod:`math` whose functions accept traced values."""
    ns = types.SimpleNamespace()
    for name in dir(math):
        if not name.startswith("_"):
            value = getattr(math, name)
            setattr(ns, name, _math_shim(name, value) if callable(value) else value)
    return ns


def _substitute(value, shims: dict):
    """``value`` with :mod:`math` (or one of its functions) replaced by its shim."""
    if value is math:
        return shims["__module__"]
    if isinstance(value, types.BuiltinFunctionType) and getattr(value, "__module__", None) == "math":
        return shims.get(value.__name__, value)
    return value


def _rebound(fn):
    """``fn`` (a Python function) with the ``math`` names of its globals and
    closure replaced by shims; other callables unchanged."""
    module = _math_module()
    shims = {name: getattr(module, name) for name in dir(module) if not name.startswith("_")}
    shims["__module__"] = module
    if not isinstance(fn, types.FunctionType):
        return _substitute(fn, shims)   # math.exp itself, or another callable unchanged
    glob = {k: _substitute(v, shims) for k, v in fn.__globals__.items()}
    if all(glob[k] is v for k, v in fn.__globals__.items()) and not fn.__closure__:
        return fn
    closure = None
    if fn.__closure__:
        closure = tuple(types.CellType(_substitute(c.cell_contents, shims))
                        if _filled(c) else c for c in fn.__closure__)
    new = types.FunctionType(fn.__code__, glob, fn.__name__, fn.__defaults__, closure)
    new.__kwdefaults__ = fn.__kwdefaults__
    return new


def _filled(cell) -> bool:
    try:
        cell.cell_contents
    except ValueError:
        return False
    return True


def trace_callable(fn, var: sp.Symbol) -> sp.Expr:
    """The sympy expression a callable computes, traced with ``var``.

    Parameters
    ----------
    fn : callable
        A function of one argument built from arithmetic operators, numpy
        ufuncs (:data:`UFUNCS`, e.g. ``np.exp`` itself), :mod:`math`
        functions (:data:`MATH_FUNCTIONS`, named in ``fn``'s globals or
        closure) and sympy functions.
    var : sympy.Symbol
        The variable the result is a function of.

    Returns
    -------
    sympy.Expr
        The expression; floats in ``fn`` become their exact binary values.

    Raises
    ------
    ValueError
        When ``fn`` cannot be traced (it branches on its argument, calls a
        numpy function that is not a ufunc, raises, or returns something
        other than a number or an expression); the message says to pass a
        string or a sympy expression instead.

    Examples
    --------
    >>> import math
    >>> import numpy as np
    >>> import sympy as sp
    >>> x = sp.Symbol("x")
    >>> trace_callable(np.exp, x), trace_callable(math.sqrt, x), trace_callable(sp.cos, x)
    (exp(x), sqrt(x), cos(x))
    >>> trace_callable(lambda t: 1 / np.sqrt(2 + t) + math.sin(t) ** 2, x)
    sin(x)**2 + 1/sqrt(x + 2)
    >>> trace_callable(lambda t: t if t > 0 else -t, x)
    Traceback (most recent call last):
    ...
    ValueError: callable <lambda> cannot be traced: it uses a comparison, branch or conversion of the variable; accepted: a callable built from arithmetic, numpy ufuncs and math or sympy functions, or pass a string such as 'exp(x)' or a sympy expression
    """
    what = getattr(fn, "__name__", type(fn).__name__)
    try:
        out = _rebound(fn)(_Tracer(var))
        if isinstance(out, np.ndarray) and out.size == 1 and out.dtype == object:
            out = out.reshape(()).item()
        expr = _sym(out)
    except _Untraceable as exc:
        reason = f"it uses {exc}"
    except Exception as exc:  # noqa: BLE001 - any failure of the user's callable is reported
        reason = f"calling it with a symbol raised {type(exc).__name__}: {str(exc)[:200]}"
    else:
        if isinstance(expr, sp.Expr):
            return expr
        reason = f"it returned {type(out).__name__}, not an expression"
    raise ValueError(f"callable {what} cannot be traced: {reason}; accepted: a callable built "
                     f"from arithmetic, numpy ufuncs and math or sympy functions, or pass a "
                     f"string such as 'exp(x)' or a sympy expression")
