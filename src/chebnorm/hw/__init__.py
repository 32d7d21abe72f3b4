"""Stage 3 (hardware): bit-accurate fixed-point datapaths, error budgets,
Verilog and VHDL checked in Icarus Verilog and GHDL and sized by Yosys.

Where things are: every design is a :class:`~.design_base.Design` (one
interface, one registry of architectures by name: :mod:`.design_base`);
:mod:`.horner` and :mod:`.piecewise` size a design (the bit-accurate
model); :mod:`.hdl` prints any design in Verilog or VHDL (the one HDL printer, with the benches and vector files); :mod:`.run_verilog` and
:mod:`.run_vhdl` run the simulators and Yosys on what it printed; :mod:`.report`
checks a design against its error budget; :mod:`.units` are the
normalization units (Verilog and VHDL); :func:`design` (:mod:`.design_api`) picks the
cheapest certified evaluator of a function on a device (``chebnorm design``). Every design object re-proves its bound and
claims when it is constructed and before it prints (:mod:`.trust`).

Imports only from :mod:`chebnorm.approx` (and :mod:`chebnorm.symbolic`).
Fixed-point conventions are those of :mod:`chebnorm.hw.fixed`: a code ``k``
of a format with ``F`` fractional bits and offset ``O`` stands for
``O + k / 2**F``.
"""

from .budget import ErrorBudget, Measurement, error_budget, gappa_bound, gappa_script, measure
from .fixed import QFormat, fit_bits, shift_round
from .horner import HornerDesign, design_horner
from .cost import Block, Cost
from .datapaths import (bump_pipeline, classic_normalize, classic_unit, dichotomy_midpoint,
                        dichotomy_next_z, dichotomy_unit, eta_criterion, eta_unit,
                        forward_difference, forward_difference_codes, forward_difference_setup,
                        forward_difference_stepper, horner_block, phong_pipeline,
                        quadratic_midpoint, quadratic_midpoint_unit)
from .units import (UNIT_KINDS, UNITS, UnitDesign, UnitKind, UnitReport, analyze_unit, design_unit,
                    get_unit, unit_names, unit_outputs, unit_verilog)
from .report import HardwareReport, analyze, verilog_outputs, write_outputs
from .sweep import SweepPoint, SweepResult, sweep
from .hdl import hdl_files, hdl_text, module_text, testbench_text, vector_file
from .design_base import ARCHITECTURES, Design, architecture, provide as _provide
from .hdl.verilog import verilog_module, verilog_testbench
from .run_verilog import SimResult, SynthResult, simulate, synthesize
from .multipartite import (MultipartiteDesign, OffsetTable, design_multipartite,
                           multipartite_candidates)
from .plain_table import PlainTableDesign, design_plain_table
from .targets import TargetCost, fmax_ice40, synthesize_target
from .architectures import Candidate, architecture_candidates
from .hdl.tables import table_files, table_module
from .table_run import simulate_table
from .pipeline import FrequencyWarning, PipelineResult, pipeline_to_frequency
from .exponent import ExponentDesign, design_exponent, simulate_exponent
from .design_api import DesignResult, Winner, design

# the HDL seam (chebnorm.hw.design_base): chebnorm.hw.hdl imports the Horner design,
# so the Horner design gets its printers from here instead of importing them
_provide("horner.module_text", module_text)
_provide("horner.hdl_files", hdl_files)

__all__ = [
    "QFormat", "shift_round", "fit_bits",
    "HornerDesign", "design_horner",
    "ErrorBudget", "Measurement", "error_budget", "measure", "gappa_script", "gappa_bound",
    "verilog_module", "verilog_testbench", "vector_file", "simulate", "synthesize",
    "module_text", "testbench_text", "hdl_text", "hdl_files",
    "SimResult", "SynthResult",
    "Cost", "Block", "horner_block", "classic_unit", "dichotomy_unit", "quadratic_midpoint_unit",
    "forward_difference_stepper", "eta_unit", "phong_pipeline", "bump_pipeline",
    "classic_normalize", "dichotomy_midpoint", "dichotomy_next_z", "quadratic_midpoint",
    "eta_criterion", "forward_difference", "forward_difference_setup", "forward_difference_codes",
    "UNIT_KINDS", "UnitDesign", "UnitReport", "design_unit", "unit_outputs", "unit_verilog",
    "analyze_unit", "UNITS", "UnitKind", "get_unit", "unit_names",
    "HardwareReport", "analyze", "verilog_outputs", "write_outputs",
    "SweepPoint", "SweepResult", "sweep",
    "MultipartiteDesign", "OffsetTable", "design_multipartite", "multipartite_candidates",
    "PlainTableDesign",
    "design_plain_table", "table_module", "table_files", "simulate_table",
    "TargetCost", "synthesize_target", "fmax_ice40", "Candidate", "architecture_candidates",
    "FrequencyWarning", "PipelineResult", "pipeline_to_frequency",
    "ExponentDesign", "design_exponent", "simulate_exponent",
    "design", "DesignResult", "Winner",
    "Design", "ARCHITECTURES", "architecture",
]
