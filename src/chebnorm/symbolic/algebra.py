"""Symbolic vector algebra used by the derivations (sympy only).

The derivations work with *generic* vectors -- three independent real
component symbols each -- and impose the constraints of the papers (unit
length, a given dot product, a given norm) as polynomial relations.  An
expression is rewritten modulo those relations by taking the normal form of
its numerator and denominator with respect to a lexicographic Groebner basis
in which the vector components come first: whatever can be expressed in the
remaining symbols (``c``, ``t``, ``|N|``, ...) is so expressed, and the
components disappear.  This is the symbolic counterpart of "expand the dot
product and substitute ``N_A.N_A = 1``, ``N_A.N_B = c``", and it is exact.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import sympy as sp

# an implementation module of chebnorm.symbolic: the API is what chebnorm.symbolic exports
__all__: list[str] = []


def vector(name: str) -> sp.Matrix:
    """A generic real 3-vector ``[name_x, name_y, name_z]`` as a column.

    Parameters
    ----------
    name : str
        The prefix of the component symbols.

    Returns
    -------
    sympy.Matrix
        A 3 x 1 matrix of real symbols.

    Examples
    --------
    >>> vector("N").T
    Matrix([[N_x, N_y, N_z]])
    """
    return sp.Matrix(sp.symbols(f"{name}_x {name}_y {name}_z", real=True))


def _as_expr(value) -> sp.Expr:
    """A relation as a sympy expression (ints allowed); text is refused, never parsed."""
    if isinstance(value, sp.Basic):
        return value
    if isinstance(value, int) and not isinstance(value, bool):
        return sp.Integer(value)
    raise TypeError(f"a relation must be a sympy expression, got {type(value).__name__}")


def reduce_modulo(
    expr: sp.Expr,
    relations: Sequence[sp.Expr],
    eliminate: Iterable[sp.Symbol],
) -> sp.Expr:
    """Rewrite the rational expression ``expr`` using ``relations == 0``.

    ``eliminate`` are the symbols to get rid of (vector components); every
    other symbol is kept.  Numerator and denominator are replaced by their
    normal forms modulo the ideal of ``relations`` (lex order, ``eliminate``
    first), so the result equals ``expr`` wherever the relations hold and the
    denominator does not vanish.

    Parameters
    ----------
    expr : sympy.Expr
        A rational expression.
    relations : sequence of sympy.Expr
        Polynomials that vanish (``|a|^2 - 1`` for a unit vector ``a``).
    eliminate : iterable of sympy.Symbol
        The symbols to remove, eliminated first.

    Returns
    -------
    sympy.Expr
        The reduced expression, equal to ``expr`` where the relations hold.

    Raises
    ------
    ArithmeticError
        If the denominator reduces to zero.

    Examples
    --------
    >>> a = vector("a")
    >>> c = sp.Symbol("c", real=True)
    >>> unit = (a.T * a)[0] - 1          # |a|^2 = 1
    >>> reduce_modulo((a.T * a)[0] ** 2 + c, [unit], a)
    c + 1
    """
    eliminate = list(eliminate)
    numer, denom = sp.fraction(sp.together(sp.expand(expr)))
    relations = [_as_expr(r) for r in relations]
    symbols = set().union(*(r.free_symbols for r in relations))
    symbols |= numer.free_symbols | denom.free_symbols
    keep = sorted(symbols - set(eliminate), key=lambda s: s.name)
    basis = sp.groebner(list(relations), *eliminate, *keep, order="lex")
    numer_nf = basis.reduce(sp.expand(numer))[1]
    denom_nf = basis.reduce(sp.expand(denom))[1]
    if denom_nf == 0:
        raise ArithmeticError(f"denominator {denom} vanishes modulo {relations}")
    return sp.factor(sp.cancel(numer_nf / denom_nf))
