"""Piecewise polynomial tables: the names of :mod:`chebnorm.approx.piecewise_table`
(the :class:`PiecewiseTable` contract, its reader and verification) and of the
fitter, under the module path they always had.

>>> t = fit_piecewise("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16)
>>> t.segment_count, t.degree, t.abs_error_bound < 2e-2
(4, 1, True)
"""

from .piecewise_table import (MAX_COEF_FRAC_BITS, MAX_INDEX_BITS, MAX_PIECEWISE_DEGREE,
                              PIECEWISE_KIND, PIECEWISE_SCHEMA, SEGMENT_BY, PiecewiseSegment,
                              PiecewiseTable, certify_segments, fit_piecewise, is_piecewise_file,
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
]
