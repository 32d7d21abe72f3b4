"""chebnorm: error analysis and certified polynomial fits for the fast
normalization of interpolated normals in Phong shading and its hardware.

Conventions (fixed once, for the whole package)
-----------------------------------------------
* Polynomial coefficients are ordered from the lowest power to the highest
  ("ascending powers"), always in the *original* variable of the fitted
  function, never in a mapped one.
* Vectors are numpy arrays of shape ``(..., 3)``; angles are in radians.
* Fixed point: a coefficient with ``F`` fractional bits is stored as the
  integer ``q = round(c * 2**F)`` and stands for ``q / 2**F`` (Q format
  ``Qm.F``).

Architecture (a stage imports only from stages above it)
-------------------------------------------------------
1. ``chebnorm.symbolic`` -- sympy closed forms of the papers.
2. ``chebnorm.approx``   -- targets, fitting (Chebyshev, Remez), certified
   error bounds, fixed-point quantization, :class:`CoefficientTable`.
3. ``chebnorm.export`` (C, JSON printers), ``chebnorm.methods`` (span
   interpolators, operation counting), ``chebnorm.hw`` (fixed-point
   datapaths, Verilog) -- siblings, none imports another.
4. ``chebnorm.raster``   -- meshes, spans, shading modes, image metrics.
5. ``chebnorm.cli``      -- the command line; imports anything above.

``paper_repro/`` and ``benchmarks/`` use the public API only; the library
never imports them.
"""

from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("chebnorm")
except PackageNotFoundError:  # pragma: no cover - running from a bare checkout
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
