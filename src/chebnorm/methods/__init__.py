"""Stage 3: the normalization methods of seed 000 as span interpolators.

Every method takes the unit normals at the two ends of many scan-line spans
and returns the pixel normals (:func:`span_normals`), vectorized over spans,
in float32 or float64. The kernels (:mod:`.kernels`) are written once
against a tiny op interface (:mod:`.ops`), so the same code also runs on a
counting number type: :func:`count_ops` measures the operations per pixel
and per span from the kernel itself. :mod:`.analysis` measures the errors.

=============  ==========================================================  ==========
method         what it does                                                seed 000
=============  ==========================================================  ==========
``exact``      linear interpolation, then ``N / sqrt(N.N)`` (reference)    classic
``none``       linear interpolation, not normalized                        (seed 003)
``newton``     one Newton-Raphson step ``N (3 - N.N) / 2``                 method 1
``lyon``       ``N (15 - 10 N.N + 3 (N.N)^2) / 8``                         method 2
``slerp``      ``[sin((1-t)psi) N_l + sin(t psi) N_r] / sin psi``          method 3
``dichotomy``  angle halving, ``(N_1 + N_2) p(z)``, ``p ~ 1/sqrt(2+z)``    method 4
``quadratic``  quadratic through ``N_l, N_c, N_r``, forward differences    method 5
``angular``    ``N_{j+1} = 2 cos(phi) N_j - N_{j-1}``                      method 6
=============  ==========================================================  ==========

The methods themselves are entries of the method registry
(:mod:`chebnorm.approx.method_registry`): :func:`method_names` lists them,
:func:`register` adds one (an entry plus its kernel), :mod:`.registry` binds
their kernels and fits their default tables. ``METHODS`` is
``method_names()`` at the time it is read.

Layer rule: imports numpy, mpmath and :mod:`chebnorm.approx` only.

>>> import numpy as np
>>> out = span_normals("exact", [[1.0, 0, 0]], [[0, 1.0, 0]], [4])
>>> out.normals.shape, out.offsets.tolist()
((5, 3), [0, 5])
>>> count_ops("newton", 16).per_pixel["div"]
0
"""

from .analysis import (N_SPECULAR, DriftReport, ErrorSweep, MethodReport, analyze, angular_drift,
                       error_sweep, length_error_bound, reference_normals, slerp_normals)
from .counting import PAPER_COUNTS, NormalizationCounts, OpCounts, count_ops, normalization_ops
from .ops import OP_KINDS
from .registry import (MethodSpec, TableSpec, default_tables, get_method, method_kernel,
                       method_kernels, method_names, register, registered_methods, table_methods,
                       unit_tables, unregister)
from .spans import ANTIPARALLEL_TOL, UNIT_TOL, SpanNormals, span_normals

__all__ = [
    "METHODS", "method_names", "get_method", "register", "unregister", "MethodSpec", "TableSpec",
    "registered_methods", "method_kernel", "method_kernels", "table_methods", "unit_tables",
    "SpanNormals", "span_normals", "default_tables", "UNIT_TOL",
    "ANTIPARALLEL_TOL", "OP_KINDS", "OpCounts", "count_ops", "NormalizationCounts",
    "normalization_ops", "PAPER_COUNTS", "MethodReport", "analyze", "ErrorSweep", "error_sweep",
    "DriftReport", "angular_drift", "length_error_bound", "N_SPECULAR", "reference_normals", "slerp_normals",
]


def __getattr__(name):
    # METHODS stays a tuple of names, read from the registry when accessed (PEP 562)
    if name == "METHODS":
        return method_names()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
