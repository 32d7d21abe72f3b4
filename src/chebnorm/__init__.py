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

0. ``chebnorm.exceptions`` and ``chebnorm.core`` -- the floor every stage
   may import. ``exceptions`` (a module) holds every public exception and
   warning class and imports nothing of chebnorm; ``core`` imports only it:
   atomic files, the ordered parallel map, safe text for generated sources,
   the C-library math and fixed-order linear algebra that keep outputs
   byte-identical, finding and running external tools, small numeric
   helpers written once.
1. ``chebnorm.symbolic`` -- sympy closed forms of the papers; imports core.
2. ``chebnorm.approx``   -- targets, fitting (Chebyshev, Remez), certified
   error bounds, fixed-point quantization, the table contract.
3. ``chebnorm.methods`` (span interpolators, operation counting) and
   ``chebnorm.hw`` (fixed-point datapaths, the HDL printers) -- siblings:
   each imports core, symbolic and approx, neither imports the other.
4. ``chebnorm.export``   -- one place per output format (C, JSON, shaders,
   and through hw the Verilog and VHDL); imports core, symbolic, approx, hw.
5. ``chebnorm.raster``   -- meshes, spans, shading modes, image metrics;
   imports core, symbolic, approx and methods (not hw, not export).
   ``chebnorm.cr``       -- correctly rounded functions of a floating-point
   format, proved on every input; imports core, symbolic and approx.
6. ``chebnorm.cr``       -- correctly rounded functions of small formats, proved
   on every input; imports core, symbolic and approx.
7. ``chebnorm.cli``      -- the command line; imports any stage.

Where a change goes: the table format in ``approx/schema.py`` and the
contract both kinds of table share in ``approx/contract.py`` (read either
with :func:`chebnorm.approx.load_table`); an output format in ``export/``
(HDL text in ``hw/hdl/``); the Phong frame in ``raster/shading.py`` over
the engines of ``raster/engines/`` (numpy, the reference; numba, compiled);
a helper two stages need in ``core/``; a public exception or warning class
in ``exceptions.py``; a run of an external tool through ``core/tools.py``
(the only module that looks tools up or starts processes). Within the package the module graph
has no import cycle and a ``_name`` never leaves its stage
(``tests/test_import_graph.py``).

A stage's API is the ``__all__`` of its ``__init__`` (for ``core``, the
modules it lists, whose own names are public). An implementation module
declares ``__all__ = []``: what it defines is the stage's implementation,
shared by the stage's modules, and the names users need the stage exports.

This module (the package root) loads no stage at import time.
A lazy facade is allowed: names resolved by a module-level ``__getattr__``
that imports a stage only when the attribute is first used; no stage may
reach a later one through such a name (stages import stage modules, never
``chebnorm.<name>`` facade names). ``chebnorm/__main__.py`` is the program
entry and imports ``chebnorm.cli``. A stage never imports another stage's
private (``_name``) modules or names.

``paper_repro/`` and ``benchmarks/`` use the public API only (no ``_name``
module or attribute of chebnorm); the library never imports them.

The everyday names, one import away
-----------------------------------
``import chebnorm as cn`` gives the facade below. Each name is re-exported
from its stage (nothing is moved) and imported only when first used
(PEP 562 module ``__getattr__``), so ``import chebnorm`` stays fast.

* ``cn.fit``, ``cn.quantize``, ``cn.certify``: fit and certify a polynomial,
  round it to fixed point and re-certify, bound ``sup|p - f|`` of given
  coefficients (:mod:`chebnorm.approx`).
* ``cn.CoefficientTable``, ``cn.FixedPoint``, ``cn.PiecewiseTable``: the two
  kinds of table (JSON, verification, rich display in Jupyter, ``table.plot()``);
  ``cn.load_table(path)`` reads a file of either kind.
* ``cn.target(name)``, ``cn.target_names()``, ``cn.fit_target(name, degree)``:
  the registered targets of the papers.
* ``cn.span_normals(method, ...)``, ``cn.method_names()``: run a
  normalization method of seed 000 on scan-line spans; the registered
  methods (:mod:`chebnorm.methods`).
* ``cn.render(...)``, ``cn.compare(test, reference)``,
  ``cn.RenderComparison(test, reference)``: render a frame with a shading
  mode, compare two frames (metrics; shown side by side in Jupyter)
  (:mod:`chebnorm.raster`).
* ``cn.export(table, "c")``: the text of a table in a format; the formats
  are the keys of ``cn.export.FORMATS`` (:mod:`chebnorm.export`).
* ``cn.hw.report(table, in_bits, out_bits)``: the bit-accurate hardware
  report of a table (:mod:`chebnorm.hw`).
* ``cn.symbolic``, ``cn.approx``, ``cn.export``, ``cn.methods``, ``cn.hw``,
  ``cn.raster``: the stage subpackages themselves; ``cn.exceptions``: every
  exception and warning class (:mod:`chebnorm.exceptions`).

>>> import chebnorm as cn
>>> t = cn.fit("1/sqrt(2+z)", ("sqrt(2)", "2"), 2, var="z")
>>> t.max_abs_error <= t.abs_error_bound < 2.2e-5
True
>>> cn.export(t, "c").startswith("/*")
True
"""

from importlib import import_module as _import_module
from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _version

try:
    #: the installed version of chebnorm (PEP 440 text, from the package metadata)
    __version__ = _version("chebnorm")
except PackageNotFoundError:  # pragma: no cover - running from a bare checkout
    __version__ = "0.0.0+unknown"

#: The layer rule: each stage of the package (a subpackage, or a module at the
#: root such as ``exceptions``) and the stages it may import (besides itself).
#: Read by ``tests/test_architecture.py``; keep it a literal.
LAYERS = {
    "exceptions": (),
    "core": ("exceptions",),
    "symbolic": ("exceptions", "core"),
    "approx": ("exceptions", "core", "symbolic"),
    "methods": ("exceptions", "core", "symbolic", "approx"),
    "hw": ("exceptions", "core", "symbolic", "approx"),
    "export": ("exceptions", "core", "symbolic", "approx", "hw"),
    "raster": ("exceptions", "core", "symbolic", "approx", "methods"),
    "cr": ("exceptions", "core", "symbolic", "approx"),
    "cli": ("exceptions", "core", "symbolic", "approx", "methods", "hw", "export", "raster", "cr"),
}


#: the stage subpackages, imported on first attribute access
_SUBPACKAGES = ("exceptions", "core", "symbolic", "approx", "export", "methods", "hw", "raster",
                "cr")

#: facade name -> (module, attribute); imported on first use
_LAZY = {
    "fit": ("chebnorm.approx", "fit"),
    "quantize": ("chebnorm.approx", "quantize"),
    "certify": ("chebnorm.approx", "certify"),
    "fit_target": ("chebnorm.approx", "fit_target"),
    "CoefficientTable": ("chebnorm.approx", "CoefficientTable"),
    "FixedPoint": ("chebnorm.approx", "FixedPoint"),
    "PiecewiseTable": ("chebnorm.approx", "PiecewiseTable"),
    "load_table": ("chebnorm.approx", "load_table"),
    "FitWarning": ("chebnorm.exceptions", "FitWarning"),
    "ChebnormDeprecationWarning": ("chebnorm.exceptions", "ChebnormDeprecationWarning"),
    "target": ("chebnorm.approx", "get_target"),
    "target_names": ("chebnorm.approx", "target_names"),
    "span_normals": ("chebnorm.methods", "span_normals"),
    "method_names": ("chebnorm.methods", "method_names"),
    "render": ("chebnorm.raster", "render"),
    "compare": ("chebnorm.raster", "compare"),
    "RenderComparison": ("chebnorm.raster", "RenderComparison"),
    "correctly_rounded": ("chebnorm.cr", "correctly_rounded"),
}

__all__ = [  # noqa: RUF022 - grouped: facade names, then the stage subpackages
    "__version__", "LAYERS", "fit", "quantize", "certify", "fit_target", "CoefficientTable", "FixedPoint",
    "PiecewiseTable", "load_table",
    "FitWarning", "ChebnormDeprecationWarning", "target", "target_names", "span_normals", "method_names", "render", "compare", "RenderComparison",
    "correctly_rounded",
    "exceptions", "core", "symbolic", "approx", "export", "methods", "hw", "raster", "cr",
]
assert set(__all__) == {"__version__", "LAYERS", *_LAZY, *_SUBPACKAGES}


def __getattr__(name: str):
    """Import a facade name or a stage subpackage on first access (PEP 562)."""
    if name in _SUBPACKAGES:
        return _import_module(f"chebnorm.{name}")
    try:
        module, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'chebnorm' has no attribute {name!r}") from None
    value = getattr(_import_module(module), attr)
    globals()[name] = value  # later accesses skip __getattr__
    return value


def __dir__():
    """The facade names, for tab completion."""
    return sorted(set(globals()) | set(__all__))
