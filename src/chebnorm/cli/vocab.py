"""The words the command line's parsers need before a command runs.

``chebnorm --help``, ``chebnorm --version`` and ``chebnorm COMMAND --help``
build every parser, so the parsers import no stage: a stage pulls in numpy,
sympy, python-flint or numba (about 1 s) before a line is printed. The
choices and help texts of the flags come from here instead, and the stage is
imported when its command runs. Each constant is a copy of the library's
value that ``tests/test_cli_vocab.py`` compares with the stage it comes from,
so the two cannot drift apart.
"""

from __future__ import annotations

__all__ = ["COEF_FORMATS", "MAX_DEGREE", "EXPORT_FORMATS", "VERIFY_FORMATS", "VARIANTS",
           "MAX_INPUTS", "UNIT_NAMES", "MESH_NAMES", "SHADING_MODES",
           "BUMP_VARIANTS"]

#: :data:`chebnorm.approx.COEF_FORMATS`
COEF_FORMATS = ("fixed", "binary16", "bfloat16", "binary32", "binary64")
#: :data:`chebnorm.approx.MAX_DEGREE`
MAX_DEGREE = 30
#: :data:`chebnorm.export.EXPORT_FORMATS`
EXPORT_FORMATS = ("c", "glsl", "hlsl", "json", "verilog", "vhdl", "wgsl")
#: :data:`chebnorm.export.verify.VERIFY_FORMATS`
VERIFY_FORMATS = ("c", "glsl", "wgsl", "hlsl")
#: :data:`chebnorm.export.verify.VARIANTS`
VARIANTS = {"c": ("double", "double-fused", "float", "float-fused", "fixed", "quant",
                  "quant-fused", "quant-f", "quant-f-fused"),
            "glsl": ("llvmpipe",), "wgsl": ("lavapipe",), "hlsl": ("glslang",)}
#: :data:`chebnorm.export.verify.MAX_INPUTS`
MAX_INPUTS = 2 ** 31
#: :func:`chebnorm.hw.units.unit_names`
UNIT_NAMES = ("dichotomy", "classic", "quadratic", "stepper", "eta")
#: :data:`chebnorm.raster.MESH_NAMES`
MESH_NAMES = ("teapot", "sphere", "icosphere", "torus", "square")
#: :data:`chebnorm.raster.SHADING_MODES`
SHADING_MODES = ("gouraud", "phong", "adaptive", "split-gouraud", "bump")
#: :data:`chebnorm.raster.BUMP_VARIANTS`
BUMP_VARIANTS = ("full", "square", "object")
