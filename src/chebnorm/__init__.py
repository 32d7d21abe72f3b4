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

Architecture: the layer rule
----------------------------
The package is split by pipeline stage, and a stage imports only the stages
:data:`LAYERS` lists for it (the one place the rule is written; the test
``tests/test_architecture.py`` reads that table and checks every import form:
``import``, ``from ... import``, relative imports, imports inside functions,
``importlib.import_module``/``__import__`` with a literal name, and attribute
access such as ``chebnorm.raster.render`` after ``import chebnorm``):

1. ``chebnorm.symbolic`` -- sympy closed forms of the papers; imports no stage.
2. ``chebnorm.approx``   -- targets, fitting (Chebyshev, Remez), certified
   error bounds, fixed-point quantization, :class:`CoefficientTable`.
3. ``chebnorm.export`` (C, JSON printers), ``chebnorm.methods`` (span
   interpolators, operation counting), ``chebnorm.hw`` (fixed-point
   datapaths, Verilog) -- siblings: each imports symbolic and approx, none
   imports another.
4. ``chebnorm.raster``   -- meshes, spans, shading modes, image metrics;
   imports symbolic, approx and methods (not hw, not export).
5. ``chebnorm.cli``      -- the command line; imports any stage.

This module (the package root) is stage 0: at import time it loads no stage.
A lazy facade is allowed: names resolved by a module-level ``__getattr__``
that imports a stage only when the attribute is first used; no stage may
reach a later one through such a name (stages import stage modules, never
``chebnorm.<name>`` facade names). ``chebnorm/__main__.py`` is the program
entry and imports ``chebnorm.cli``. A stage never imports another stage's
private (``_name``) modules or names.

``paper_repro/`` and ``benchmarks/`` use the public API only (no ``_name``
module or attribute of chebnorm); the library never imports them.
"""

from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("chebnorm")
except PackageNotFoundError:  # pragma: no cover - running from a bare checkout
    __version__ = "0.0.0+unknown"

#: The layer rule: each stage of the package and the stages it may import
#: (besides itself). Read by ``tests/test_architecture.py``; keep it a literal.
LAYERS = {
    "symbolic": (),
    "approx": ("symbolic",),
    "export": ("symbolic", "approx"),
    "methods": ("symbolic", "approx"),
    "hw": ("symbolic", "approx"),
    "raster": ("symbolic", "approx", "methods"),
    "cli": ("symbolic", "approx", "export", "methods", "hw", "raster"),
}

__all__ = ["__version__", "LAYERS"]
