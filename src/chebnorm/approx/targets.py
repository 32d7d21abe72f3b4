"""The registry of named approximation targets (restated in docs/papers.md).

Each target is a function of one variable on an interval that depends on
``psi_max``, the largest angle between the two unit normals at the ends of
an edge or span (radians, default pi/4).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from chebnorm.core.display import summary_html, summary_repr

from .expr import compare, read_expression, parse_number

# an implementation module of chebnorm.approx: the API is what chebnorm.approx exports
__all__: list[str] = []


@dataclass(frozen=True)
class Target:
    """A named function, its variable, its interval as a function of psi_max,
    the degrees and kind the main job exports, and what it is for.

    Parameters
    ----------
    name : str
        The target's name (``chebnorm fit --target NAME``).
    expression : str
        The function, in chebnorm's expression syntax.
    variable : str
        Its variable.
    interval_text : tuple of str
        The endpoints as exact expressions in ``psi_max`` (see
        :meth:`interval`).
    degrees : tuple of int
        The degrees the repro job exports.
    kind : str
        The fit, ``"chebyshev"`` or ``"minimax"``.
    meaning : str
        What the function is for, one line.

    Examples
    --------
    >>> t = get_target("dichotomy")
    >>> t.expression, t.variable, t.interval("pi/4")
    ('1/sqrt(2+z)', 'z', ('sqrt(2)', '2'))
    """

    name: str
    expression: str
    variable: str
    interval_text: tuple[str, str]  # sympy text in terms of psi_max
    degrees: tuple[int, ...]
    kind: str
    meaning: str

    def _summary(self) -> list[tuple[str, object]]:
        return [("name", self.name), ("expression", self.expression),
                ("variable", self.variable), ("interval_text", self.interval_text),
                ("degrees", self.degrees), ("kind", self.kind)]

    def _display_rows(self) -> list[tuple[str, object]]:
        return self._summary() + [("meaning", self.meaning)]

    __repr__ = summary_repr
    _repr_html_ = summary_html

    def interval(self, psi_max: float | str = "pi/4") -> tuple[str, str]:
        """Exact endpoint strings with psi_max substituted (sympy syntax).

        ``psi_max`` is read by :func:`~chebnorm.approx.expr.parse_number`:
        text exactly (``"0.5"`` is 1/2), a float at its exact binary value.

        >>> TARGETS["midpoint"].interval("pi/4")
        ('sqrt(2)/2', '1')
        """
        try:
            psi = parse_number(psi_max)
        except ValueError as exc:
            raise ValueError(f"psi_max: {exc}") from None
        try:
            inside = compare(psi, sp.Integer(0)) > 0 and compare(psi, sp.pi) < 0
        except ValueError:
            inside = False
        if not inside:
            raise ValueError(f"psi_max = {psi} is out of range; accepted: 0 < psi_max < pi")
        symbol = sp.Symbol("psi_max", real=True)
        out = []
        for text in self.interval_text:
            value = read_expression(text, ["psi_max"]).subs(symbol, psi)
            out.append(sp.sstr(value))
        return (out[0], out[1])


#: the registered approximation targets by name (``chebnorm targets`` lists them;
#: :func:`get_target` reads one, refusing an unknown name)
TARGETS: dict[str, Target] = {t.name: t for t in (
    Target("dichotomy", "1/sqrt(2+z)", "z", ("2*cos(psi_max)", "2"), (1, 2), "chebyshev",
           "seed 000, method 4: denominator of the dichotomy midpoint (N1 + N2)/sqrt(2 + z), "
           "z = 2 cos(theta)"),
    Target("midpoint", "1/sqrt(2*(1+x))", "x", ("cos(psi_max)", "1"), (1, 2), "chebyshev",
           "seed 000, method 5: normalizing factor of the span midpoint (N_l + N_r)/sqrt(2(1 + x)), "
           "x = N_l.N_r"),
    Target("eta_term", "sqrt(2*(1+x))/2", "x", ("0", "1"), (1, 2), "chebyshev",
           "seed 003: one edge term of the normalization criterion eta, x = N_i.N_j in [0, 1]"),
    Target("rsqrt", "1/sqrt(x)", "x", ("cos(psi_max/2)**2", "1"), (2, 3), "minimax",
           "renormalization 1/|N| from x = N.N of a linearly interpolated normal; "
           "|N|^2 >= cos^2(psi_max/2) on a span of angle psi_max"),
)}


def target_names() -> list[str]:
    """The names of the registered targets, sorted.

    Returns
    -------
    list of str
        The registered names, sorted.

    Examples
    --------

    Examples
    --------
    >>> target_names()
    ['dichotomy', 'eta_term', 'midpoint', 'rsqrt']
    """
    return sorted(TARGETS)


def get_target(name: str) -> Target:
    """The registered :class:`~chebnorm.approx.targets.Target` called ``name`` (``chebnorm.target``).

    Seed 000, method 4: the dichotomy denominator ``1/sqrt(2 + z)``,
    ``z = 2 cos(theta)``, on ``[2 cos(psi_max), 2]``:

    Parameters
    ----------
    name : str
        A registered target's name.

    Returns
    -------
    Target
        Its expression, variable, interval rule and fit kind.

    Raises
    ------
    ValueError
        For an unknown name, naming the registered ones.

    Examples
    --------

    Examples
    --------
    >>> t = get_target("dichotomy")
    >>> t.expression, t.interval("pi/4")
    ('1/sqrt(2+z)', ('sqrt(2)', '2'))
    >>> get_target("nope")
    Traceback (most recent call last):
    ...
    ValueError: unknown target 'nope'; accepted: dichotomy, eta_term, midpoint, rsqrt
    """
    try:
        return TARGETS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown target {name!r}; accepted: {', '.join(target_names())}") from None
