"""No environment variable and no path becomes a command (issue 26, item 4).

chebnorm pasted the temporary folder into ``yosys -p "read_verilog PATH; ..."``:
a ``TMPDIR`` with a space broke synthesis with an empty reason, and one holding
``; script FILE; #`` ran that yosys script (whose ``!cmd`` lines run shell
commands). yosys's ABC step and Icarus Verilog's driver also build ``sh``
command lines from ``TMPDIR`` themselves. Every external tool now gets argument
lists, fixed relative file names in a private folder, and ``TMPDIR=.``."""

from __future__ import annotations

import os

import pytest

from chebnorm.hw.run_verilog import synthesize_text
from conftest import requires_tool, run_cli, run_process

needs = requires_tool("yosys", "iverilog")

#: a directory name with a space, both quotes, ``;``, ``!``, ``$`` and a backquote
NASTY = "sp ace 'q\"uo;te!bang $HOME `id`"


def cli(*args, cwd, tmpdir):
    """``chebnorm ARGS`` as a child process started with ``TMPDIR=tmpdir``: the
    variable is read when the process starts (tempfile caches it), so the process
    is the point here."""
    return run_process(*args, cwd=cwd, env=dict(os.environ, TMPDIR=str(tmpdir)), timeout=300,
                       input="")  # stdin at end of file, as from /dev/null


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    d = tmp_path_factory.mktemp("tbl")
    r = run_cli("fit", "1/sqrt(x)", "--interval", "1", "2", "--degree", "1", "-o", "t.json", cwd=d)
    assert r.code == 0, r.err
    return d / "t.json"


def _traps(root):
    """TMPDIR values that ran code before: a yosys script through the
    ``-p`` text, a shell command through ABC's command line (``;``) and one
    through Icarus's (``"``). Each leaves a marker file when it runs."""
    (root / "pwn.ys").write_text(f"log PWNED\n!touch {root / 'MARK_script'}\n")
    (root / "real.v").write_text("module z(input a, output b); assign b = a; endmodule\n")
    values = {
        "yosys script": root / "real.v; script pwn.ys; #",
        "shell ;": root / f"s; touch {root}/MARK_semicolon; #",
        "shell quote": root / f'q"; touch {root}/MARK_quote; "',
        "nasty": root / NASTY,
    }
    for v in values.values():
        v.mkdir(parents=True)
    return values


@needs
@pytest.mark.parametrize("case", ["yosys script", "shell ;", "shell quote", "nasty"])
def test_hw_report_and_verilog_with_hostile_tmpdir(tmp_path, table, case):
    tmpdir = _traps(tmp_path)[case]
    r = cli("hw", "report", table, "--in-bits", "8", "--out-bits", "8", "--coef-frac-bits", "12",
            "--no-gappa", "--json", cwd=tmp_path, tmpdir=tmpdir)
    assert r.returncode == 0, r.stderr
    assert '"yosys_cells": ' in r.stdout and '"yosys_cells": null' not in r.stdout
    r = cli("hw", "verilog", table, "--in-bits", "8", "--out-bits", "8", "--coef-frac-bits", "12",
            "-o", "hdl", "--simulate", cwd=tmp_path, tmpdir=tmpdir)
    assert r.returncode == 0, r.stderr
    assert "PASS: 256 vectors, 0 mismatches" in r.stdout
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith("MARK")]
    # nothing left in the temporary folder either
    assert list(tmpdir.iterdir()) == []


@needs
def test_synthesize_text_in_process(tmp_path, monkeypatch):
    import tempfile

    tmpdir = _traps(tmp_path)["shell ;"]
    monkeypatch.setenv("TMPDIR", str(tmpdir))
    monkeypatch.setattr(tempfile, "tempdir", None)  # re-read TMPDIR
    s = synthesize_text("module m(input [3:0] a, output [7:0] y); assign y = a * a; endmodule\n",
                        "m")
    assert s.cells > 0
    assert not (tmp_path / "MARK_semicolon").exists()
    with pytest.raises(ValueError, match="top: .* is not a module name; accepted: a Verilog"):
        synthesize_text("module m; endmodule\n", "m; script x")
