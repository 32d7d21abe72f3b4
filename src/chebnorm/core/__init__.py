"""Stage 0, the floor: what every stage may import and none may hold alone.

* :mod:`chebnorm.core.files`     -- atomic writes (``write_atomic``,
  ``write_all``, ``write_folder``); ``-o`` through devices, FIFOs, symlinks.
* :mod:`chebnorm.core.parallel`  -- ``map_ordered``: a process pool whose
  results come back in input order (byte-identical to one worker).
* :mod:`chebnorm.core.textsafe`  -- identifiers, comments and CSV cells that
  cannot inject text into generated C, HDL, shaders or tables.
* :mod:`chebnorm.core.clib`      -- float64 ``exp``/``log``/``pow``/trig from
  the C library element by element (numpy's SIMD ufuncs differ per CPU).
* :mod:`chebnorm.core.detlinalg` -- linear solves and products in a fixed
  order (BLAS and LAPACK kernels differ per CPU).
* :mod:`chebnorm.core.numeric`   -- small exact helpers written once: floats
  rounded up or down from a rational or a ball, two's-complement widths,
  integer argument checks, a scoped Arb working precision
  (``arb_precision``, the one way the package sets it).
* :mod:`chebnorm.core.tools`     -- the one place that finds external tools
  (``which``, ``require``) and runs them (``run_tool``, with a time limit).
* :mod:`chebnorm.core.docfrag`   -- docstring fragments: a parameter block
  written once, filled into ``%(name)s`` placeholders at import.

This stage imports no other stage of chebnorm, only :mod:`chebnorm.exceptions`
(the classes it raises and warns with).
"""

from . import clib, deprecation, detlinalg, files, numeric, parallel, progress, textsafe, tools

__all__ = ["clib", "deprecation", "detlinalg", "files", "numeric", "parallel", "progress", "textsafe",
           "tools"]
