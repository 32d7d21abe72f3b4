"""Stage 2: targets, fitting, certified error bounds, fixed point, tables.

Where things are: ``schema`` (kinds, limits, versions, the JSON field readers),
``contract`` (:class:`Table`, what both kinds of table are and do), ``table``
(:class:`CoefficientTable`), ``piecewise_table`` (:class:`PiecewiseTable`),
``load`` (:func:`load_table`: a file of either kind); the fitters ``api``
(:func:`fit`, :func:`quantize`) and ``piecewise_fit`` (:func:`piecewise_fit`), on
``fitting``, ``rounding``, ``certify`` and ``certify_batch``; ``trace`` turns a Python
callable given to :func:`fit` into a sympy expression.

>>> from chebnorm.approx import fit
>>> t = fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 2, kind="minimax", var="z")
>>> t.max_abs_error <= t.abs_error_bound <= 1.01 * t.max_abs_error
True
"""

from .api import MAX_DEGREE, FitWarning, fit, quantize, warnings_of
from .certify import Certificate, certify
from .contract import ErrorBounds, Table
from .expr import Function1D, read_expression, parse_function, parse_number
from .load import load_table, table_from_json
from .piecewise_fit import piecewise_fit
from .piecewise_table import PiecewiseSegment, PiecewiseTable
from .rounding import FORMATS as COEF_FORMATS
from .table import SCHEMA_VERSION, CoefficientTable, FixedPoint, Quantized
from .targets import TARGETS, Target, get_target, target_names

__all__ = [
    "CoefficientTable", "FixedPoint", "Quantized", "COEF_FORMATS", "SCHEMA_VERSION", "fit", "quantize", "warnings_of", "FitWarning", "MAX_DEGREE",
    "Certificate", "certify", "Function1D", "read_expression", "parse_function", "parse_number",
    "Target", "TARGETS", "get_target", "target_names", "fit_target",
    "Table", "ErrorBounds", "PiecewiseTable", "PiecewiseSegment", "piecewise_fit", "load_table",
    "table_from_json",
]


def fit_target(name: str, degree: int, *, psi_max="pi/4", kind: str | None = None,
               error: str = "abs", coef_frac_bits: int | None = None,
               frac_bits: int | None = None) -> CoefficientTable:
    """Fit a registered target: ``fit_target("dichotomy", 2)``.

    Parameters
    ----------
    name : str
        A registered target (:func:`target_names`).
    degree : int
        The polynomial degree.
    psi_max : str or float, optional
        The largest angle the table must cover (sympy text or radians).
    kind : str, optional
        ``"chebyshev"`` or ``"minimax"`` (default: the target's).
    error : str, optional
        ``"abs"`` or ``"rel"``.
    coef_frac_bits : int, optional
        Also quantize to this many fractional bits.
    frac_bits : int, optional
        The deprecated spelling of ``coef_frac_bits``.

    Returns
    -------
    CoefficientTable
        The certified table, named ``<name>_d<degree>``, in powers of the
        target's variable (``basis="monomial"``: the papers' polynomials).

    Raises
    ------
    ValueError
        For an unknown target or arguments out of range (as :func:`fit`).

    Examples
    --------
    >>> fit_target("dichotomy", 2).name
    'dichotomy_d2'
    """
    from chebnorm.core.deprecation import renamed

    frac_bits = renamed(frac_bits, coef_frac_bits, "frac_bits", "coef_frac_bits", "fit_target")
    t = get_target(name)
    return fit(t.expression, t.interval(psi_max), degree, kind=kind or t.kind, error=error,
               var=t.variable, name=f"{name}_d{degree}", coef_frac_bits=frac_bits,
               basis="monomial",  # the papers' polynomials, in powers of the variable
               command=f"chebnorm.approx.fit_target({name!r}, {degree}, psi_max={psi_max!r}, "
                       f"kind={(kind or t.kind)!r}, error={error!r}, coef_frac_bits={frac_bits!r})")
