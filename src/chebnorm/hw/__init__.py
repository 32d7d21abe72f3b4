"""Stage 3 (hardware): bit-accurate fixed-point datapaths, error budgets,
Verilog export checked in Icarus Verilog and sized by Yosys.

Imports only from :mod:`chebnorm.approx` (and :mod:`chebnorm.symbolic`).
Fixed-point conventions are those of :mod:`chebnorm.hw.fixed`: a code ``k``
of a format with ``F`` fractional bits and offset ``O`` stands for
``O + k / 2**F``.
"""

from .budget import ErrorBudget, Measurement, error_budget, gappa_bound, gappa_script, measure
from .fixed import QFormat, fit_bits, shift_round
from .horner import HornerDesign, design_horner
from .verilog import (SimResult, SynthResult, simulate, synthesize, verilog_module,
                      verilog_testbench, vector_file)

__all__ = [
    "QFormat", "shift_round", "fit_bits",
    "HornerDesign", "design_horner",
    "ErrorBudget", "Measurement", "error_budget", "measure", "gappa_script", "gappa_bound",
    "verilog_module", "verilog_testbench", "vector_file", "simulate", "synthesize",
    "SimResult", "SynthResult",
]
