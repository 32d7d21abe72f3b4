"""Read a function given as text, and compile it for every arithmetic we use.

Reading: the one reader of user text
------------------------------------
Every string that becomes a sympy expression -- a CLI argument, the
``expression`` and ``interval`` fields of a coefficient table, a target's
``psi_max``, an argument of the Python API -- is read by
:func:`read_expression`. The text is never run: Python's ``ast`` module
parses it (``mode="eval"``), a whitelist of nodes is accepted, and the sympy
tree is built here, node by node. Accepted:

* numbers: integers and decimals, taken **exactly** from the token's text
  (``0.1`` is ``1/10``, ``1e-3`` is ``1/1000``, never the nearest double);
* the declared variable(s), the constants ``pi`` and ``E``;
* ``+ - * / **``, ``^`` as a power (as in sympy's ``convert_xor``), unary
  ``-`` and ``+``, parentheses;
* the functions of :data:`FUNCTIONS` with one argument (``log`` also takes a
  base: ``log(x, 2)``).

Everything else -- names, attribute access, subscripts, lambdas, strings,
comparisons, keyword arguments, ... -- is refused, naming the offending token
and the accepted set. Implicit multiplication (``2x``) is refused: write
``2*x``. Resource limits (:data:`MAX_LENGTH` characters, :data:`MAX_NODES`
nodes, :data:`MAX_DEPTH` levels of nesting, numbers of at most
:data:`MAX_NUMBER_BITS` bits, exponents up to :data:`MAX_EXPONENT`) keep a
hostile string such as ``9**9**9**9`` from exhausting time or memory.

Compiling
---------
One sympy expression of one real variable is compiled to

* a numpy function (``sympy.lambdify``, from our own tree), for dense
  sampling in float64; its elementary functions and ``**`` are the C
  library's (:mod:`.clib`), not numpy's CPU-dispatched loops, so a fit
  writes the same bytes on machines with and without AVX-512;
* an mpmath function, for high-precision point values;
* a python-flint ``arb`` / ``arb_series`` function, for rigorous enclosures
  and Taylor coefficients over balls (the certification engine).

The ``arb`` compiler walks the sympy tree itself. Every constant subtree
(``1/10``, ``pi``, ``sqrt(2)/3``) is evaluated at the working precision of
the Arb evaluation that needs it (``flint.ctx.prec``) and cached per
precision, so a certificate at 128 bits sees constants accurate to 128 bits.
"""

from __future__ import annotations

import ast
import builtins
import functools
import keyword
import re
import warnings
import unicodedata
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from fractions import Fraction
from typing import Callable, Iterable

import numpy as np
import sympy as sp
from flint import arb, arb_series, ctx, fmpq
from sympy.printing.numpy import SciPyPrinter

from chebnorm.core import clib
from chebnorm.core.numeric import arb_precision
from chebnorm.exceptions import UndefinedError

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []

#: the functions an expression may call, by name (one argument each; ``log``
#: also accepts a base). Each is certified by the Arb compiler below; ``log2``,
#: ``log10``, ``exp2``, ``expm1``, ``log1p``, ``rsqrt``, ``sinpi`` and ``cospi``
#: are written with the others (``log(u)/log(2)``, ``2**u``, ``exp(u) - 1``, ...).
FUNCTIONS: dict[str, Callable] = {
    "sqrt": sp.sqrt, "exp": sp.exp, "log": sp.log,
    "sin": sp.sin, "cos": sp.cos, "tan": sp.tan,
    "asin": sp.asin, "acos": sp.acos, "atan": sp.atan,
    "sinh": sp.sinh, "cosh": sp.cosh, "tanh": sp.tanh,
    "asinh": sp.asinh, "acosh": sp.acosh, "atanh": sp.atanh,
    "erf": sp.erf, "erfc": sp.erfc, "gamma": sp.gamma,
    "Abs": sp.Abs, "abs": sp.Abs,
    # the names a function designer types, read as the functions they name
    "log2": lambda u: sp.log(u, 2), "log10": lambda u: sp.log(u, 10),
    "exp2": lambda u: sp.Pow(2, u), "expm1": lambda u: sp.exp(u) - 1,
    "log1p": lambda u: sp.log(1 + u), "rsqrt": lambda u: 1 / sp.sqrt(u),
    "sinpi": lambda u: sp.sin(sp.pi * u), "cospi": lambda u: sp.cos(sp.pi * u),
}
#: the named constants an expression may use
CONSTANTS: dict[str, sp.Expr] = {"pi": sp.pi, "E": sp.E}

#: longest accepted text, in characters
MAX_LENGTH = 1000
#: most syntax-tree nodes in one expression
MAX_NODES = 500
#: deepest nesting of operations (chains ``a + b + c`` count as one level)
MAX_DEPTH = 100
#: largest numerator or denominator of any number, in bits (1e-300 needs 997)
MAX_NUMBER_BITS = 1200
#: largest magnitude of a numeric exponent (``x**1024``)
MAX_EXPONENT = 1024
#: largest magnitude of a number passed to ``gamma``
_MAX_GAMMA_ARG = 1000

_ALLOWED_CHARS = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                           "0123456789 +-*/^()._,")


def _show(text: str, limit: int = 60) -> str:
    """``repr`` of (the start of) a user text, for an error message."""
    if len(text) <= limit:
        return repr(text)
    return repr(text[:limit]) + f"... ({len(text)} characters)"


def _accepted(variables: Iterable[str]) -> str:
    names = list(variables)
    var = ("the variable " + ", ".join(names) + ", ") if names else ""
    return ("accepted: numbers (2, 0.1, 1e-3: decimals are exact), " + var +
            "the constants pi and E, + - * / ** and ^ (power), parentheses, and the "
            "functions " + ", ".join(FUNCTIONS))


class _Refusal(ValueError):
    """A reason to refuse a text; completed with the text and the accepted set."""


_NODE_KINDS = {
    ast.Attribute: "attribute access", ast.Subscript: "subscript", ast.Lambda: "lambda",
    ast.JoinedStr: "f-string", ast.FormattedValue: "f-string", ast.NamedExpr: "assignment (:=)",
    ast.ListComp: "comprehension", ast.SetComp: "comprehension", ast.DictComp: "comprehension",
    ast.GeneratorExp: "comprehension", ast.Compare: "comparison", ast.BoolOp: "boolean operator",
    ast.IfExp: "conditional expression", ast.Tuple: "tuple", ast.List: "list", ast.Set: "set",
    ast.Dict: "dict", ast.Starred: "starred argument", ast.Await: "await", ast.Yield: "yield",
    ast.YieldFrom: "yield", ast.Slice: "slice",
}
#: the text of an accepted number: decimal digits, a point, an exponent
_DECIMAL = re.compile(r"(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_BINOPS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}


def _bits(q: sp.Rational) -> int:
    return max(int(q.p).bit_length(), int(q.q).bit_length())


class _Reader:
    """Builds a sympy tree from a whitelisted ``ast`` tree (see module docstring)."""

    def __init__(self, source: str, symbols: dict[str, sp.Symbol]):
        self.source = source
        self.symbols = symbols
        self.nodes = 0

    def token(self, node: ast.AST) -> str:
        seg = ast.get_source_segment(self.source, node) or type(node).__name__
        return seg if len(seg) <= 40 else seg[:40] + "..."

    def refuse(self, node: ast.AST, what: str) -> _Refusal:
        return _Refusal(f"{self.token(node)!r} ({what}) is not accepted")

    def number(self, value, node: ast.AST) -> sp.Rational:
        if isinstance(value, sp.Rational) and _bits(value) > MAX_NUMBER_BITS:
            raise _Refusal(f"the number {self.token(node)!r} has more than {MAX_NUMBER_BITS} "
                           f"bits (numbers up to about 1e+-300 are accepted)")
        return value

    def build(self, node: ast.AST, depth: int = 0) -> sp.Expr:
        self.nodes += 1
        if self.nodes > MAX_NODES:
            raise _Refusal(f"the expression has more than {MAX_NODES} terms")
        if depth > MAX_DEPTH:
            raise _Refusal(f"the expression is nested more than {MAX_DEPTH} levels deep")
        if isinstance(node, ast.Expression):
            return self.build(node.body, depth)
        if isinstance(node, ast.Constant):
            return self.constant(node)
        if isinstance(node, ast.Name):
            return self.name(node)
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.USub):
                return self.number(-self.build(node.operand, depth + 1), node)
            if isinstance(node.op, ast.UAdd):
                return self.build(node.operand, depth + 1)
            raise self.refuse(node, "operator " + {ast.Not: "not", ast.Invert: "~"}[type(node.op)])
        if isinstance(node, ast.BinOp):
            return self.binop(node, depth)
        if isinstance(node, ast.Call):
            return self.call(node, depth)
        kind = _NODE_KINDS.get(type(node), type(node).__name__)
        raise self.refuse(node, kind)

    def constant(self, node: ast.Constant) -> sp.Expr:
        v = node.value
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            kind = {str: "string", bytes: "bytes", complex: "imaginary number"}.get(
                type(v), type(v).__name__)
            raise self.refuse(node, kind)
        text = ast.get_source_segment(self.source, node) or ""
        if not _DECIMAL.fullmatch(text):
            raise _Refusal(f"the number {self.token(node)!r} is not written in decimal digits "
                           f"(hexadecimal, octal, binary and '_' separators are not accepted: "
                           f"write e.g. 16, 1000, 0.5 or 1e-3)")
        if isinstance(v, int):
            return self.number(sp.Integer(v), node)
        try:
            dec = Decimal(text)
        except InvalidOperation:
            raise self.refuse(node, "number") from None
        sign, digits, exponent = dec.as_tuple()
        if not isinstance(exponent, int) or abs(exponent) > 400 or len(digits) > 400:
            raise _Refusal(f"the number {self.token(node)!r} is too large or too small "
                           f"(numbers up to about 1e+-300 are accepted)")
        q = Fraction(dec)
        return self.number(sp.Rational(q.numerator, q.denominator), node)

    def name(self, node: ast.Name) -> sp.Expr:
        if node.id in self.symbols:
            return self.symbols[node.id]
        if node.id in CONSTANTS:
            return CONSTANTS[node.id]
        if node.id in FUNCTIONS:
            raise _Refusal(f"the function {node.id!r} must be called with an argument, "
                           f"e.g. {node.id}(x)")
        if not node.id.startswith("_") and len(node.id) <= 8 and not hasattr(builtins, node.id):
            raise _Refusal(f"unknown variable {node.id!r}")
        raise self.refuse(node, "unknown name")

    def binop(self, node: ast.BinOp, depth: int) -> sp.Expr:
        op = type(node.op)
        if op in (ast.Pow, ast.BitXor):
            base = self.build(node.left, depth + 1)
            ex = self.build(node.right, depth + 1)
            return self.power(base, ex, node)
        if op not in _BINOPS:
            symbol = {ast.Mod: "%", ast.FloorDiv: "//", ast.MatMult: "@", ast.BitAnd: "&",
                      ast.BitOr: "|", ast.LShift: "<<", ast.RShift: ">>"}.get(op, op.__name__)
            raise self.refuse(node, f"operator {symbol}")
        # a chain a + b - c (or a * b / c) is read iteratively: one level, any length
        family = (ast.Add, ast.Sub) if op in (ast.Add, ast.Sub) else (ast.Mult, ast.Div)
        chain = []
        left: ast.AST = node
        while isinstance(left, ast.BinOp) and isinstance(left.op, family):
            chain.append((type(left.op), left.right, left))
            left = left.left
            self.nodes += 1
        acc = self.build(left, depth + 1)
        for op_type, right, whole in reversed(chain):
            value = self.build(right, depth + 1)
            if op_type is ast.Add:
                acc = acc + value
            elif op_type is ast.Sub:
                acc = acc - value
            elif op_type is ast.Mult:
                acc = acc * value
            else:
                if value == 0:
                    raise _Refusal(f"{self.token(whole)!r} divides by zero")
                acc = acc / value
            acc = self.number(acc, whole)
        return acc

    def power(self, base: sp.Expr, ex: sp.Expr, node: ast.AST) -> sp.Expr:
        if ex.is_Rational:
            if abs(ex) > MAX_EXPONENT:
                raise _Refusal(f"the exponent in {self.token(node)!r} is larger than "
                               f"{MAX_EXPONENT} in magnitude")
            if base.is_Rational:
                if base == 0 and ex < 0:
                    raise _Refusal(f"{self.token(node)!r} divides by zero")
                # a lower bound of the power's bits (2**1000 has 1001); number() checks
                # the exact value
                if (_bits(base) - 1) * abs(int(ex.p)) + 1 > MAX_NUMBER_BITS:
                    raise _Refusal(f"the power {self.token(node)!r} has more than "
                                   f"{MAX_NUMBER_BITS} bits")
                if int(ex.q) > MAX_EXPONENT:
                    raise _Refusal(f"the root in {self.token(node)!r} has a degree larger "
                                   f"than {MAX_EXPONENT}")
        value = sp.Pow(base, ex)
        if value.is_Pow and value.exp.is_Rational and abs(value.exp) > MAX_EXPONENT:
            raise _Refusal(f"the exponent in {self.token(node)!r} is larger than "
                           f"{MAX_EXPONENT} in magnitude")
        if value.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
            raise _Refusal(f"{self.token(node)!r} is not finite")
        return self.number(value, node)

    def call(self, node: ast.Call, depth: int) -> sp.Expr:
        if not isinstance(node.func, ast.Name):
            raise self.refuse(node, "a call of something that is not a function name")
        name = node.func.id
        if name not in FUNCTIONS:
            raise _Refusal(f"{name!r} is not an accepted function")
        if node.keywords:
            raise self.refuse(node.keywords[0].value, "keyword argument")
        nargs = (1, 2) if name == "log" else (1,)
        if len(node.args) not in nargs:
            raise _Refusal(f"{name}() takes {' or '.join(map(str, nargs))} argument(s), "
                           f"got {len(node.args)}")
        args = [self.build(a, depth + 1) for a in node.args]
        if len(args) == 2 and not args[1].free_symbols and not (
                args[1].is_positive and args[1] != 1):
            raise _Refusal(f"the base of {self.token(node)!r} is {args[1]}: a logarithm's "
                           f"base must be a positive constant other than 1 (e.g. log(x, 2))")
        if name == "gamma" and args[0].is_Rational and abs(args[0]) > _MAX_GAMMA_ARG:
            raise _Refusal(f"gamma of a number larger than {_MAX_GAMMA_ARG} in magnitude")
        value = FUNCTIONS[name](*args)
        if value.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
            raise _Refusal(f"{self.token(node)!r} is not finite")
        return self.number(value, node)


def _symbols(variables: Iterable[str]) -> dict[str, sp.Symbol]:
    out = {}
    for v in variables:
        if not isinstance(v, str) or not v.isascii() or not v.isidentifier() \
                or keyword.iskeyword(v) or v.startswith("_") or v in FUNCTIONS or v in CONSTANTS:
            raise ValueError(f"variable name {v!r} is not accepted; accepted: an ASCII "
                             f"identifier such as x or z, not a keyword, function or constant "
                             f"name and not starting with '_'")
        out[v] = sp.Symbol(v, real=True)
    return out


def read_expression(text: str, variables: Iterable[str] = ("x",)) -> sp.Expr:
    """Read ``text`` as a real expression in ``variables`` (see module docstring).

    Decimals are exact, ``^`` is a power, and nothing in ``text`` is ever run.
    Raises ValueError naming the offending token and the accepted set.

    Parameters
    ----------
    text : str
        The expression, at most :data:`MAX_LENGTH` characters of ASCII letters,
        digits, spaces and ``+ - * / ^ ( ) . , _``, using the functions of
        :data:`FUNCTIONS` and the constants ``pi`` and ``E``.
    variables : iterable of str, optional
        The names of the variables it may use, default ``("x",)``.

    Returns
    -------
    sympy.Expr
        The expression, its variables real sympy Symbols.

    Raises
    ------
    ValueError
        When ``text`` is not a string, too long, has a character or construct
        outside the accepted set, an unknown name, or is not a scalar expression.

    Examples
    --------
    >>> read_expression("x^2 + 0.1")
    x**2 + 1/10
    >>> read_expression("2*cos(psi_max)", ["psi_max"])
    2*cos(psi_max)
    >>> read_expression("x.__class__")
    Traceback (most recent call last):
    ...
    ValueError: cannot parse expression 'x.__class__': 'x.__class__' (attribute access) is not accepted; accepted: ...
    """
    symbols = _symbols(variables)
    what = _show(text) if isinstance(text, str) else repr(type(text).__name__)
    try:
        return _read(text, symbols)
    except _Refusal as exc:
        raise ValueError(f"cannot parse expression {what}: {exc}; {_accepted(symbols)}") from None


def _read(text, symbols: dict[str, sp.Symbol]) -> sp.Expr:
    if not isinstance(text, str):
        raise _Refusal(f"expected text, got {type(text).__name__}")
    if len(text) > MAX_LENGTH:
        raise _Refusal(f"it is longer than {MAX_LENGTH} characters")
    for i, ch in enumerate(text):
        if ch not in _ALLOWED_CHARS:
            name = unicodedata.name(ch, "control character" if ord(ch) < 32 else "unnamed")
            raise _Refusal(f"the character {ch!r} (U+{ord(ch):04X} {name}) at position {i} "
                           f"is not accepted (only ASCII letters, digits, spaces and "
                           f"+ - * / ^ ( ) . , _)")
    source = text.strip().replace("^", "**")
    if not source:
        raise _Refusal("it is empty")
    try:
        with warnings.catch_warnings():  # e.g. "'int' object is not callable"
            warnings.simplefilter("ignore")
            tree = ast.parse(source, mode="eval")
    except SyntaxError as exc:
        hint = ""
        if exc.msg == "invalid decimal literal" or "forgot a comma" in str(exc.msg):
            hint = " (implicit multiplication such as 2x is not accepted: write 2*x)"
        raise _Refusal(f"it is not a valid expression: {exc.msg} at column "
                       f"{exc.offset}{hint}") from None
    except (ValueError, RecursionError, MemoryError) as exc:
        raise _Refusal(f"it cannot be parsed ({type(exc).__name__})") from None
    try:
        expr = _Reader(source, symbols).build(tree)
    except RecursionError:
        raise _Refusal(f"the expression is nested more than {MAX_DEPTH} levels deep") from None
    if not isinstance(expr, sp.Expr):
        raise _Refusal("it is not a scalar expression")
    return expr


# ------------------------------------------------------------------- numbers
def parse_number(text: str | float | int) -> sp.Expr:
    """Read an interval endpoint such as ``"sqrt(2)"``, ``"2*cos(pi/4)"`` or ``"0.1"``.

    Text is read by :func:`read_expression` (no variable; decimals exact).
    Python floats are taken at their exact binary value, ints and
    ``fractions.Fraction`` exactly. Raises ValueError for anything that is not
    a finite real constant.

    Parameters
    ----------
    text : str, int, float, fractions.Fraction or sympy.Expr
        The constant; a bool is refused.

    Returns
    -------
    sympy.Expr
        The exact constant (an Integer, a Rational, or an expression such as
        ``sqrt(2)``).

    Raises
    ------
    ValueError
        When ``text`` is not finite, not a constant (it names a variable), cannot
        be parsed, or not a real number.

    Examples
    --------
    >>> parse_number("0.1"), parse_number(0.5), parse_number("2*cos(pi/4)")
    (1/10, 1/2, sqrt(2))
    """
    if type(text) is str:                 # kept: a table's endpoints are read again
        return _parse_number_text(text)   # by every fit and quantization of it
    return _parse_number(text)


@functools.lru_cache(maxsize=512)
def _parse_number_text(text: str) -> sp.Expr:
    """:func:`parse_number` of a text, cached (sympy constants are immutable; a
    refusal raises again each time, not cached)."""
    return _parse_number(text)


def _parse_number(text) -> sp.Expr:
    """:func:`parse_number`'s work."""
    if isinstance(text, (bool, np.bool_)):
        raise ValueError(f"interval endpoint {text!r} is not a number")
    if isinstance(text, (int, np.integer)):
        value = sp.Integer(int(text))
    elif isinstance(text, Fraction):
        value = sp.Rational(text.numerator, text.denominator)
    elif isinstance(text, (float, np.floating)):
        if not np.isfinite(text):
            raise ValueError(f"interval endpoint {text!r} is not finite")
        value = sp.Rational(float(text))
    elif isinstance(text, sp.Expr):
        value = _exact_floats(text)
    else:
        try:
            value = _read(text, {})
        except _Refusal as exc:
            shown = _show(text) if isinstance(text, str) else repr(type(text).__name__)
            if isinstance(text, str) and text.strip().lower() in ("oo", "inf", "infinity", "nan"):
                raise ValueError(f"interval endpoint {shown} is not a finite real number; "
                                 f"accepted: a finite real constant such as 0.1, sqrt(2) or "
                                 f"2*cos(pi/4)") from None
            if str(exc).startswith("unknown variable"):
                raise ValueError(f"interval endpoint {shown} is not a constant ({exc}); "
                                 f"{_accepted(())}") from None
            raise ValueError(f"cannot parse interval endpoint {shown}: {exc}; "
                             f"{_accepted(())}") from None
    if value.free_symbols:
        raise ValueError(f"interval endpoint {_show(str(text))} is not a constant")
    ball = enclose(value)
    if ball is None:
        raise ValueError(f"interval endpoint {_show(str(text))} = {value} is not a finite real "
                         f"number; accepted: a finite real constant such as 0.1, sqrt(2) "
                         f"or 2*cos(pi/4)")
    return value


def enclose(value: sp.Expr, prec: int = 64) -> arb | None:
    """A finite ball enclosing the real constant ``value`` at ``prec`` bits,
    or None when it is not finite and real (``asin(2)``, ``log(-1)``) or not a
    constant the Arb compiler knows."""
    if value.free_symbols or value.has(sp.I, sp.zoo, sp.nan, sp.oo):
        return None
    with arb_precision(prec):
        try:
            ball = compile_arb(value, sp.Dummy(), series=False)(arb(0))
        except (ValueError, ZeroDivisionError):
            return None
        return ball if ball.is_finite() else None


def compare(a: sp.Expr, b: sp.Expr) -> int:
    """The sign of ``a - b`` for real constants, exactly (-1, 0 or 1).

    Rationals are compared exactly; other constants by Arb enclosures at
    64, 256, 1024 and 4096 bits. Raises ValueError when undecided (equal
    constants written differently, or closer than 2**-4000).
    """
    d = a - b
    if d.is_Rational:
        return int(bool(d > 0)) - int(bool(d < 0))
    for prec in (64, 256, 1024, 4096):
        da, db = enclose(a, prec), enclose(b, prec)
        if da is None or db is None:
            break
        if da < db:
            return -1
        if da > db:
            return 1
    raise ValueError(f"cannot decide whether {a} < {b} (they agree to 4096 bits)")


def _exact_floats(expr: sp.Expr) -> sp.Expr:
    """``expr`` with every sympy Float replaced by its exact binary value."""
    floats = expr.atoms(sp.Float)
    return expr.xreplace({f: sp.Rational(f) for f in floats}) if floats else expr


# ------------------------------------------------------------- Arb compiler
def _arb_const(value: sp.Expr) -> arb:
    """An exact or correctly enclosing ball for a sympy number, at ``ctx.prec``."""
    if value.is_Integer:
        return arb(int(value))
    if value.is_Rational:
        return arb(fmpq(int(value.p), int(value.q)))
    if value.is_Float:
        sign, man, exp, _ = value._mpf_
        return arb(-int(man) if sign else int(man)) * arb(2) ** int(exp)
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


def _nan_like(s):
    if isinstance(s, arb_series):
        return arb_series([arb("nan")] * s.prec, prec=s.prec)
    return arb("nan")


def _abs(s):
    """``|s|``: for a ball, a ball of nonnegative numbers (Arb's ``abs`` keeps the
    radius of a ball around 0, whose lower end is then negative, and ``sqrt`` of it
    not real); for a series, the series of ``s`` or ``-s`` when its value has one
    sign on the whole ball, else nan (not differentiable there)."""
    if not isinstance(s, arb_series):
        a = abs(s)
        return a.nonnegative_part() if a.is_finite() and a.lower() < 0 else a
    c = s.coeffs()
    c0 = c[0] if c else arb(0)
    if c0 > 0:
        return s
    if c0 < 0:
        return -s
    return _nan_like(s)


def _series_or_plain(plain: Callable, series: Callable) -> Callable:
    return lambda v: series(v) if isinstance(v, arb_series) else plain(v)


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
    sp.sinh: (lambda v: v.sinh(), _series_or_plain(lambda v: v.sinh(),
                                                   lambda s: (s.exp() - (-s).exp()) / 2)),
    sp.cosh: (lambda v: v.cosh(), _series_or_plain(lambda v: v.cosh(),
                                                   lambda s: (s.exp() + (-s).exp()) / 2)),
    sp.tanh: (lambda v: v.tanh(), _series_or_plain(lambda v: v.tanh(),
                                                   lambda s: 1 - 2 / ((2 * s).exp() + 1))),
    sp.asinh: (lambda v: v.asinh(), _series_or_plain(lambda v: v.asinh(),
                                                     lambda s: (s + (s * s + 1).sqrt()).log())),
    sp.acosh: (lambda v: v.acosh(), _series_or_plain(lambda v: v.acosh(),
                                                     lambda s: (s + (s * s - 1).sqrt()).log())),
    sp.atanh: (lambda v: v.atanh(), _series_or_plain(lambda v: v.atanh(),
                                                     lambda s: ((1 + s).log() - (1 - s).log()) / 2)),
    sp.erf: (lambda v: v.erf(), lambda s: s.erf()),
    sp.erfc: (lambda v: v.erfc(), lambda s: s.erfc()),
    sp.gamma: (lambda v: v.gamma(), lambda s: s.gamma()),
    sp.Abs: (_abs, _abs),
}


def _rational_power(v, q: sp.Rational, exponent: Callable):
    """``v**q`` for a non-integer rational ``q``: exp(q log v), and for a
    plain ball with ``v >= 0`` by monotonicity from its ends (``0**q = 0``)."""
    if isinstance(v, arb_series) or v.lower() != 0:
        return (v.log() * exponent()).exp()
    if q < 0:
        return arb("nan")
    hi = v.upper()
    top = (hi.log() * exponent()).exp() if hi > 0 else arb(0)
    return arb(0).union(top)


def compile_arb(expr: sp.Expr, var: sp.Symbol, series: bool) -> Callable:
    """Compile ``expr`` to a function of one arb (or arb_series) argument.

    Constant subtrees are evaluated at the current ``flint.ctx.prec`` when
    first needed at that precision, and cached per precision.
    """
    slot = 1 if series else 0

    def constant(node: sp.Expr) -> Callable:
        plain = build(node, plain_only=True)
        cache: dict[int, arb] = {}

        def value(x=None):
            prec = ctx.prec
            c = cache.get(prec)
            if c is None:
                c = cache[prec] = plain(arb(0))
            return c
        return value

    def build(node: sp.Expr, plain_only: bool = False) -> Callable:
        if node == var:
            return lambda x: x
        if not plain_only and not node.has(var):
            return constant(node)
        if node.is_Number or node in (sp.pi, sp.E):
            return lambda x: _arb_const(node)
        if node.is_Mul and node.args[0] == -1:
            # negation is exact in ball arithmetic; (-1) * x would round the radius up
            inner = build(sp.Mul(*node.args[1:], evaluate=False), plain_only)
            return lambda x: -inner(x)
        if node.is_Add or node.is_Mul:
            parts = [build(a, plain_only) for a in node.args]
            if node.is_Add:
                def fold(x, parts=parts):
                    acc = parts[0](x)
                    for p in parts[1:]:
                        acc = acc + p(x)
                    return acc
            else:
                def fold(x, parts=parts):
                    acc = parts[0](x)
                    for p in parts[1:]:
                        acc = acc * p(x)
                    return acc
            return fold
        if node.is_Pow:
            base, ex = node.args
            b = build(base, plain_only)
            if ex.is_Integer:
                n = int(ex)
                if n >= 0:
                    return lambda x: _ipow(b(x), n)
                return lambda x: 1 / _ipow(b(x), -n)
            if ex == sp.Rational(1, 2):
                return lambda x: b(x).sqrt()
            if ex == sp.Rational(-1, 2):
                return lambda x: b(x).rsqrt()
            e = build(ex, plain_only)
            if ex.is_Rational:
                return lambda x: _rational_power(b(x), ex, lambda: e(x))
            return lambda x: (b(x).log() * e(x)).exp()
        if node.is_Function and type(node) in _ARB_FUNCS:
            f = _ARB_FUNCS[type(node)][0 if plain_only else slot]
            (arg,) = node.args
            a = build(arg, plain_only)
            return lambda x: f(a(x))
        raise ValueError(f"unsupported operation {type(node).__name__} in {expr}; accepted: "
                         f"+ - * / **, pi, E and the functions {', '.join(FUNCTIONS)}")

    return build(expr)


class _CLibraryPrinter(SciPyPrinter):
    """sympy's numpy printer with the CPU-dispatched loops replaced: the functions of
    :data:`.clib.FUNCTIONS` and every power but ``sqrt`` and ``1/sqrt`` print as
    :mod:`.clib`'s (namespace name ``_clib``, no imports); the printed expression is
    otherwise sympy's, so its evaluation order and constants do not change."""

    def _print_clib_function(self, expr):
        args = ", ".join(map(self._print, expr.args))
        return f"_clib.FUNCTIONS[{type(expr).__name__!r}]({args})"

    def _print_Pow(self, expr, rational=False):
        if expr.exp in (sp.S.Half, -sp.S.Half):
            return super()._print_Pow(expr, rational=rational)     # numpy.sqrt
        e = expr.exp.evalf() if expr.exp.is_integer and expr.exp.is_negative else expr.exp
        return f"_clib.power({self._print(expr.base)}, {self._print(e)})"


# sympy binds _print_exp, _print_acos, ... to its numpy printer class; these override them
for _name in clib.FUNCTIONS:
    setattr(_CLibraryPrinter, f"_print_{_name}", _CLibraryPrinter._print_clib_function)
del _name


@dataclass(frozen=True)
class Function1D:
    """A real function of one variable, with its evaluators.

    ``expr`` is the sympy expression, ``var`` its variable. The evaluators are
    compiled on first use. Internal: no input checking.

    Parameters
    ----------
    expr : sympy.Expr
        The expression, in the single variable ``var``.
    var : sympy.Symbol
        Its variable (a real Symbol).

    Examples
    --------
    >>> f = parse_function("1/sqrt(x)")
    >>> f.numpy([1.0, 4.0]).tolist(), float(f.mpmath(16))
    ([1.0, 0.5], 0.25)
    """

    expr: sp.Expr
    var: sp.Symbol

    @functools.cached_property
    def removable(self):
        """The removable singularities of ``f`` (:mod:`.removable`), or None.

        Where ``f = N/D`` is 0/0 at a point but has a proved finite limit
        (``sin(x)/x`` at 0), every evaluator returns that continuous
        extension, rigorously in Arb (see :mod:`chebnorm.approx.removable`).
        """
        from .removable import analyse

        return analyse(self.expr, self.var, compile_arb, enclose)

    @functools.cached_property
    def numpy(self) -> Callable[[np.ndarray], np.ndarray]:
        f = sp.lambdify(self.var, self.expr, [{"_clib": clib}, "scipy", "numpy"],
                        printer=_CLibraryPrinter)
        if self.removable is not None:
            g = self.removable.wrap_numpy(f, self.arb)
            return lambda x: g(x) * np.ones_like(x, dtype=float)
        return lambda x: np.asarray(f(np.asarray(x, dtype=float)), dtype=float) * np.ones_like(x, dtype=float)

    @functools.cached_property
    def mpmath(self) -> Callable:
        f = sp.lambdify(self.var, self.expr, "mpmath")
        expr, var = self.expr, self.var
        if self.removable is not None:
            f = self.removable.wrap_mpmath(f, self.arb)

        def value(x):
            try:
                return f(x)
            except ZeroDivisionError:  # e.g. exp(-1/x**2) at x = 0
                raise UndefinedError(f"{expr} is undefined at {var} = {x} (a division by "
                                     f"zero); accepted: an interval where the function is "
                                     f"defined, finite and real") from None
        return value

    @functools.cached_property
    def arb(self) -> Callable[[arb], arb]:
        f = compile_arb(self.expr, self.var, series=False)
        return f if self.removable is None else self.removable.wrap_arb(f)

    @functools.cached_property
    def arb_series(self) -> Callable[[arb_series], arb_series]:
        f = compile_arb(self.expr, self.var, series=True)
        return f if self.removable is None else self.removable.wrap_arb(f)

    def __str__(self) -> str:
        return str(self.expr)


class AccurateFunction1D(Function1D):
    """A :class:`Function1D` whose float evaluator rounds Arb's 128-bit value to
    float64 instead of evaluating the expression in float64: for a function that
    float64 evaluates by cancellation (``1 - cos(x)`` near 0, where it reads 0),
    so that fits weighted by ``1/|f|`` see its true values. Slower (one ball
    evaluation per point); the certified bounds never depend on it.

    Parameters
    ----------
    expr : sympy.Expr
        The expression, in the single variable ``var``.
    var : sympy.Symbol
        Its variable (a real Symbol).

    Examples
    --------
    >>> g = parse_function("1 - cos(x)")
    >>> AccurateFunction1D(g.expr, g.var).numpy([1e-8]).tolist(), g.numpy([1e-8]).tolist()
    ([5e-17], [0.0])
    """

    @functools.cached_property
    def numpy(self) -> Callable[[np.ndarray], np.ndarray]:
        f_arb = self.arb

        def value(x) -> np.ndarray:
            xs = np.asarray(x, dtype=float)
            out = np.empty(xs.shape)
            with arb_precision(128):
                for i, v in np.ndenumerate(xs):
                    try:
                        y = f_arb(arb(float(v)))
                    except (ValueError, ZeroDivisionError):
                        y = None
                    out[i] = float(y.mid()) if y is not None and y.is_finite() else np.nan
            return out
        return value


def parse_function(text: str | sp.Expr, var: str = "x") -> Function1D:
    """Read ``text`` as a real function of the single variable ``var`` (cached).

    Text is read by :func:`read_expression` (decimals exact, nothing run).
    A sympy expression is taken as it is, its Floats at their exact binary
    values.

    Parameters
    ----------
    text : str or sympy.Expr
        The function, e.g. ``"1/sqrt(x)"``.
    var : str, optional
        The name of its variable, default ``"x"``.

    Returns
    -------
    Function1D
        The function and its evaluators.

    Raises
    ------
    ValueError
        For text that is not accepted, for variables other than ``var`` and for
        functions the certification engine does not support (or that are not
        finite and real, such as ``1/0``).

    Examples
    --------
    >>> parse_function("1/sqrt(2+z)", "z").expr
    1/sqrt(z + 2)
    >>> parse_function("x + 0.1").expr
    x + 1/10
    """
    if not isinstance(text, (str, sp.Expr)):
        raise ValueError(f"expression of type {type(text).__name__} is not accepted; accepted: "
                         f"a string such as 'exp(x)' or a sympy expression")
    if not isinstance(var, str):
        raise ValueError(f"var of type {type(var).__name__} is not accepted; accepted: a "
                         f"string naming the variable, such as 'x'")
    return _parse_function(text, var)


@functools.lru_cache(maxsize=256)
def _parse_function(text, var: str) -> Function1D:
    symbols = _symbols([var])
    symbol = symbols[var]
    if isinstance(text, sp.Expr):
        expr = _exact_floats(text.subs({s: symbol for s in text.free_symbols if s.name == var}))
        others = sorted(s.name for s in expr.free_symbols if s != symbol)
        if others:
            raise ValueError(f"expression {_show(str(text))} uses unknown variable(s) "
                             f"{', '.join(others)}; the only accepted variable is {var!r}")
    else:
        try:
            expr = _read(text, symbols)
        except _Refusal as exc:
            message = f"cannot parse expression {_show(text) if isinstance(text, str) else ''}: {exc}"
            if str(exc).startswith("unknown variable"):
                message += f" (the variable is {var!r}: set it with var=)"
            raise ValueError(f"{message}; {_accepted(symbols)}") from None
    if expr.has(sp.zoo, sp.nan, sp.oo, -sp.oo, sp.I):
        raise ValueError(f"expression {_show(str(text))} = {expr} is not a finite real function")
    fn = Function1D(expr, symbol)
    try:
        fn.arb_series  # compile now so an unsupported operation is reported here
    except ValueError as exc:
        raise ValueError(f"expression {_show(str(text))}: {exc}") from None
    return fn
