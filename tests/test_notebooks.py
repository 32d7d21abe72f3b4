"""Each notebook under notebooks/ runs top to bottom (nbclient, kernel python3).

The notebooks are stored without outputs (checked here too); executing them
is the test. Skipped, with the reason, when nbclient/nbformat/ipykernel are
not installed (``pip install -e ".[test]"`` installs them).
"""

from __future__ import annotations

import importlib.util
import json
import os
import warnings
from pathlib import Path

import pytest

from conftest import one_at_a_time

# found here, imported by the tests that run (importing them costs collection a tenth of a second)
for _mod, _why in (("nbformat", "nbformat not installed (pip install -e '.[test]')"),
                   ("nbclient", "nbclient not installed (pip install -e '.[test]')"),
                   ("ipykernel", "ipykernel not installed: no python3 kernel to run notebooks")):
    if importlib.util.find_spec(_mod) is None:
        pytest.skip(_why, allow_module_level=True)

NOTEBOOKS = sorted((Path(__file__).resolve().parent.parent / "notebooks").glob("*.ipynb"))
#: seconds per cell: every cell takes a few seconds (the renders use the numpy engine, no
#: compile step), so a cell still running after a minute is waiting on a reply that will
#: not come (nbclient with ipywidgets' comms, jupyter/nbclient#312) and is run again
TIMEOUT = 60


def test_there_are_notebooks():
    assert {p.stem for p in NOTEBOOKS} >= {"error_surfaces", "fit_explorer"}


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_stored_without_outputs(path):
    import nbformat

    nb = nbformat.read(path, as_version=4)
    for cell in nb.cells:
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, \
                f"{path.name}: a code cell has stored outputs; clear them before committing"


@pytest.mark.slow
@pytest.mark.timeout(2 * TIMEOUT + 600)  # two cells timed out, and the notebook's own time
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs(path, tmp_path):
    import nbclient
    import nbformat

    env_backend = os.environ.get("MPLBACKEND")
    os.environ["MPLBACKEND"] = "Agg" if env_backend is None else env_backend
    try:
        # one kernel on the machine at a time; a cell whose reply never comes (a client has
        # been seen waiting on an idle kernel) is run once more in a new kernel, and a
        # second time out fails the test
        for attempt in (1, 2):
            nb = nbformat.read(path, as_version=4)
            client = nbclient.NotebookClient(nb, timeout=TIMEOUT, kernel_name="python3",
                                             resources={"metadata": {"path": str(tmp_path)}})
            with one_at_a_time("jupyter-kernel"):
                try:
                    client.execute()
                    break
                except nbclient.exceptions.CellTimeoutError as exc:
                    if attempt == 2:
                        raise
                    # which cell, in the run's warnings summary
                    preview = " | ".join(str(exc).split("-------------------")[1:2]).strip()
                    warnings.warn(f"{path.name}: a cell got no reply within {TIMEOUT} s and the "
                                  f"notebook ran again in a new kernel; the cell: "
                                  f"{' '.join(preview.split())[:300]}", UserWarning)
    finally:
        if env_backend is None:
            os.environ.pop("MPLBACKEND", None)
    # a slider's function runs inside a widget, which shows its exception instead of raising
    # it: look for errors in the stored widget state too
    text = json.dumps(nb)
    assert '"output_type": "error"' not in text and "Traceback" not in text, \
        f"{path.name}: an error was shown in an output or a widget"
