"""Running the table designs' HDL: the exhaustive benches in Icarus Verilog
or GHDL (:func:`simulate_table`), each in a fresh folder.

The text comes from :mod:`chebnorm.hw.hdl.tables`; the simulators are run by
:mod:`chebnorm.hw.run_verilog` and :mod:`chebnorm.hw.run_vhdl`.
"""

from __future__ import annotations

from pathlib import Path

from chebnorm.core.files import write_folder

from .hdl.tables import table_files
from .run_verilog import SimResult, simulate
from .run_vhdl import simulate_vhdl

# an implementation module of chebnorm.hw: the API is what chebnorm.hw exports
__all__: list[str] = []


def simulate_table(design, directory, language: str = "verilog") -> SimResult:
    """Write the module, its exhaustive bench and the model's vectors into
    ``directory`` and run the bench (Icarus Verilog or GHDL): every input
    code's output compared with ``design.evaluate``'s.

    Parameters
    ----------
    design : MultipartiteDesign, PlainTableDesign or PipelinedTable
        A table-based design with a bit-accurate ``evaluate``.
    directory : str or os.PathLike
        The folder to write into (created if missing); the files stay there.
    language : {"verilog", "vhdl"}, default "verilog"
        The HDL, simulated with Icarus Verilog or GHDL.

    Returns
    -------
    SimResult
        The bench's verdict.

    Raises
    ------
    ValueError
        If ``language`` is unknown, the simulator is missing or fails, or the files
        cannot be written.

    Examples
    --------
    >>> import tempfile
    >>> from chebnorm.hw.plain_table import design_plain_table
    >>> d = design_plain_table("1/sqrt(1+3*x)", ("0", "1"), 6, 6)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     simulate_table(d, tmp).line
    'PASS: 64 vectors, 0 mismatches (chebnorm_table)'
    """
    write_folder(Path(directory), table_files(design, language))
    if language == "verilog":
        return simulate(directory, design)
    return simulate_vhdl(directory, design)
