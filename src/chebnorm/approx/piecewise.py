"""Piecewise polynomial tables under the module path they always had: the names of
:mod:`chebnorm.approx.piecewise_table` (the :class:`PiecewiseTable` contract, its
reader and verification) and the fitter of :mod:`chebnorm.approx.piecewise_fit`
(``fit_piecewise``, also named ``piecewise_fit``).

>>> t = fit_piecewise("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
>>> t.segment_count, t.degree, t.abs_error_bound < 2e-2
(4, 1, True)
"""

from .piecewise_fit import fit_piecewise, piecewise_fit
from .piecewise_table import (MAX_COEF_FRAC_BITS, MAX_INDEX_BITS, MAX_PIECEWISE_DEGREE,
                              PIECEWISE_KIND, PIECEWISE_SCHEMA, SEGMENT_BY, PiecewiseSegment,
                              PiecewiseTable, certify_segments, is_piecewise_file,
                              parse_segments)

__all__ = [
    "MAX_COEF_FRAC_BITS",
    "MAX_INDEX_BITS",
    "MAX_PIECEWISE_DEGREE",
    "PIECEWISE_KIND",
    "PIECEWISE_SCHEMA",
    "SEGMENT_BY",
    "PiecewiseSegment",
    "PiecewiseTable",
    "certify_segments",
    "fit_piecewise",
    "is_piecewise_file",
    "parse_segments",
    "piecewise_fit",
]
