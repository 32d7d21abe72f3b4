"""Normalization units in Verilog and VHDL, bit-for-bit equal to the kernels
of :mod:`chebnorm.hw.datapaths`, with self-checking test benches and costs.

Units (``kind``), each one module ``chebnorm_<kind>_unit`` and one Python
module here (:mod:`.classic`, :mod:`.dichotomy`, :mod:`.quadratic`,
:mod:`.stepper`, :mod:`.eta`), registered by name in :data:`UNITS`
(:func:`get_unit`, :func:`unit_names`); what they share is written once
(:mod:`.base`: ports, design, the :class:`UnitKind` interface, the registry;
:mod:`.hdl`: banner, port list, square root, divider, saturation as netlist
statements; :mod:`.bench`: vectors and test benches; :mod:`.evaluator`: the
units with a polynomial evaluator). Each kind builds its netlist
(:meth:`UnitKind.modules`, :mod:`chebnorm.hw.hdl.netlist`), which
:meth:`UnitKind.verilog` and :meth:`UnitKind.vhdl` print:

* ``"classic"`` -- ``N / sqrt(N.N)`` (:func:`~chebnorm.hw.datapaths.classic_normalize`):
  dot product, restoring integer square root, three restoring dividers
  (unrolled, one result bit per step), floor or nearest-even quotient.
* ``"dichotomy"`` -- ``M = (N1 + N2) p(z)`` and ``z' = sqrt(2 + z)``
  (:func:`~chebnorm.hw.datapaths.dichotomy_midpoint`,
  :func:`~chebnorm.hw.datapaths.dichotomy_next_z`), the polynomial ``p``
  the generated evaluator of a ``1/sqrt(2+z)`` table.
* ``"quadratic"`` -- ``x = N_l.N_r``, ``N_c = (N_l + N_r) p(x)`` and the
  coefficients ``G, P, Q`` (:func:`~chebnorm.hw.datapaths.quadratic_midpoint`),
  ``p`` the evaluator of a ``1/sqrt(2(1+x))`` table.
* ``"stepper"`` -- the forward-difference stepper, clocked: on ``load`` it
  sets up ``v, d1, d2`` from ``G, P, Q`` for ``m = 2^LOG_M`` pixels, then
  ``v += d1; d1 += d2`` each cycle
  (:func:`~chebnorm.hw.datapaths.forward_difference_setup`,
  :func:`~chebnorm.hw.datapaths.forward_difference_codes`).
* ``"eta"`` -- ``eta = 3 - sum g(N_i.N_j)`` and ``skip = eta < thr``
  (:func:`~chebnorm.hw.datapaths.eta_criterion`), ``g`` the evaluator of a
  ``sqrt(2(1+x))/2`` table, instantiated three times.

Vector components are signed ``W``-bit codes with ``F`` fractional bits
(``W = F + 2`` holds ``[-2, 2)``; unit vectors need ``W >= F + 2``), ports
``<name>_x``, ``<name>_y``, ``<name>_z``.

Widths: every unit is printed at its generated widths (no parameters): the
evaluator's constants, the output offsets and the output widths were sized,
exactly, from the extremes of every input code; regenerate to change
them. Every output
is wide enough to hold the kernel's exact result for *every* input code,
so the model and the circuit agree everywhere, not only on unit normals.

The test benches (Verilog and VHDL, :mod:`chebnorm.hw.hdl.unit_bench`) read
rows ``{inputs, expected outputs}`` made by the Python kernels (seeded random
vectors, realistic normals, edge cases; every input code when the inputs have
at most 16 bits) from ``chebnorm_<kind>_unit.hex`` and print one
``PASS:``/``FAIL:`` line.

Adding a kind: one module with a subclass of :class:`UnitKind` (or of
:class:`~chebnorm.hw.units.evaluator.EvaluatorUnit` when it has a polynomial
evaluator) passed to :func:`register`, and its import below; the CLI
(``hw unit``, ``hw report --unit``) lists it from the registry.

>>> u = design_unit("classic", frac_bits=3, comp_bits=5)
>>> [(p.name, p.bits) for p in u.ports]
[('n_x', 5), ('n_y', 5), ('n_z', 5), ('u_x', 5), ('u_y', 5), ('u_z', 5)]
>>> u.evaluate({"n_x": np.array([6]), "n_y": np.array([8]), "n_z": np.array([0])})["u_x"]
array([4])
"""

from __future__ import annotations

import numpy as np  # noqa: F401  (the doctest above uses np)

# the kinds register themselves on import, in this order (that of UNIT_KINDS)
from . import dichotomy, classic, quadratic, stepper, eta  # noqa: F401,I001
from .base import (MAX_COMP_BITS, MAX_UNIT_FRAC_BITS, UNITS, Port, UnitDesign, UnitKind,
                   get_unit, register, unit_names)
from .bench import unit_testbench, unit_vector_file, unit_vectors
from .design import UnitReport, analyze_unit, design_unit, unit_outputs, unit_verilog
from .evaluator import table_matches

__all__ = ["UNIT_KINDS", "UNIT_TARGETS", "UNITS", "UnitKind", "get_unit", "unit_names", "register",
           "table_matches", "Port", "UnitDesign", "UnitReport", "design_unit",
           "unit_vectors", "unit_verilog", "unit_testbench", "unit_vector_file",
           "unit_outputs", "analyze_unit", "MAX_COMP_BITS", "MAX_UNIT_FRAC_BITS"]

#: the built-in unit names (the registry, :data:`UNITS`, is the authority)
UNIT_KINDS = unit_names()
#: the coefficient-table target each unit's polynomial evaluator approximates
UNIT_TARGETS = {name: kind.target for name, kind in UNITS.items() if kind.target is not None}
