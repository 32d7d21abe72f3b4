"""The command line: acceptance commands, JSON keys, one-line errors with status 2."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import astuple

import pytest

from chebnorm.cli import main
from conftest import run_cli
from quiet_cli import run_cli_quiet


def test_fit_json_acceptance_c5():
    rc, out, err = astuple(run_cli("fit", "1/sqrt(2+z)", "--var", "z", "--interval", "sqrt(2)",
                                   "2", "--degree", "2", "--kind", "chebyshev", "--json"))
    assert rc == 0, err
    d = json.loads(out)
    for key in ("coefficients", "max_abs_error", "abs_error_bound", "max_rel_error", "rel_error_bound",
                "degree", "kind", "interval", "name"):
        assert key in d
    assert [round(c, 5) for c in d["coefficients"]] == [0.68076, -0.11881, 0.01422]
    assert round(d["max_abs_error"], 7) == 2.16e-5 and round(d["max_rel_error"] * 100, 4) == 0.0040
    assert d["interval_float"] == [2 ** 0.5, 2.0] and d["interval"] == ["sqrt(2)", "2"]
    assert "fit 1/sqrt(2+z) --var z" in d["provenance"]["command"].replace("'", "")


def test_fit_minimax_acceptance():
    rc, out, err = astuple(run_cli("fit", "1/sqrt(2+z)", "--var", "z", "--interval", "sqrt(2)",
                                   "2", "--degree", "2", "--kind", "minimax", "--json"))
    d = json.loads(out)
    assert abs(d["max_abs_error"] - 2.016e-5) < 1e-8
    assert d["abs_error_bound"] >= d["max_abs_error"]


def test_fit_export_targets_round_trip(tmp_path, capsys):
    table = tmp_path / "t.json"
    assert main(["fit", "sqrt(2*(1+x))/2", "--interval", "0", "1", "--degree", "1",
                 "--name", "eta_d1", "--coef-frac-bits", "16", "-o", str(table)]) == 0
    assert main(["export", str(table), "--format", "c", "-o", str(tmp_path / "eta.h")]) == 0
    h = (tmp_path / "eta.h").read_text()
    assert "chebnorm_eta_d1_q_eval" in h and f"Command: chebnorm export {table}" in h
    assert main(["export", str(table), "--format", "json", "-o", str(tmp_path / "copy.json")]) == 0
    assert (tmp_path / "copy.json").read_text() == table.read_text()
    capsys.readouterr()
    assert main(["targets", "--json"]) == 0
    names = [t["name"] for t in json.loads(capsys.readouterr().out)]
    assert names == ["dichotomy", "eta_term", "midpoint", "rsqrt"]


@pytest.mark.parametrize("args,needle", [
    (["fit", "1/sqrt(x)", "--interval", "-1", "1", "--degree", "2"], "not finite and real"),
    (["fit", "x", "--interval", "1", "0", "--degree", "2"], "LO must be strictly less than HI"),
    (["fit", "x", "--interval", "0", "1", "--degree", "-1"], "accepted: 0 <= degree <= 30"),
    (["fit", "x", "--interval", "0", "1", "--degree", "31"], "accepted: 0 <= degree <= 30"),
    (["fit", "sqrt(", "--interval", "0", "1", "--degree", "2"], "cannot parse expression"),
    (["fit", "x+y", "--interval", "0", "1", "--degree", "2"], "unknown variable"),
    (["fit", "exp(x)", "--interval", "0", "1", "--degree", "3", "--coef-frac-bits", "40"], "overflows int32"),
    (["fit", "x", "--interval", "0", "1"], "required: --degree"),
    (["export", "missing.json", "-o", "x.h"], "cannot read coefficient table"),
    (["nonsense"], "invalid choice"),
])
def test_bad_input_one_line_status_2(args, needle, tmp_path):
    proc = run_cli_quiet(*args, cwd=tmp_path)
    assert proc.code == 2
    lines = proc.err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], proc.err
    assert "Traceback" not in proc.err
    assert proc.out == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nothing written


def test_failed_fit_leaves_no_output(tmp_path):
    out = tmp_path / "t.json"
    assert main(["fit", "1/sqrt(x)", "--interval", "-1", "1", "--degree", "2", "-o", str(out)]) == 2
    assert not out.exists()


# --- one name per quantity; the old spellings are deprecated aliases for one release -------

DEPRECATED = "is deprecated and will be removed in the next release; use "


def _fit_json(tmp_path, flag):
    rc, out, err = astuple(run_cli_quiet("fit", "1/sqrt(x)", "--interval", "1", "2", "--degree",
                                         "2", flag, "12", "--json"))
    assert rc == 0, err
    return json.loads(out), err


def test_fit_coef_frac_bits_and_deprecated_frac_bits(tmp_path):
    new, err_new = _fit_json(tmp_path, "--coef-frac-bits")
    old, err_old = _fit_json(tmp_path, "--frac-bits")
    assert err_new == ""
    assert err_old == f"chebnorm: warning: --frac-bits {DEPRECATED}--coef-frac-bits\n"
    assert new["fixed_point"]["frac_bits"] == 12
    new.pop("provenance"), old.pop("provenance")  # the command line differs
    assert new == old


@pytest.mark.parametrize("argv,old,new", [
    (["hw", "report", "T", "--in-bits", "8", "--out-bits", "8", "--no-gappa", "--no-synth",
      "--json", "--unit", "classic"], ["--coef-bits", "12"], ["--coef-frac-bits", "12"]),
    (["hw", "report", "T", "--in-bits", "8", "--out-bits", "8", "--coef-frac-bits", "12",
      "--no-gappa", "--no-synth", "--json", "--unit", "classic"],
     ["--frac-bits", "6"], ["--vector-frac-bits", "6"]),
])
def test_hw_deprecated_aliases(tmp_path, argv, old, new):
    from chebnorm.approx import fit_target

    t = tmp_path / "t.json"
    fit_target("dichotomy", 2).save(t)
    argv = [str(t) if a == "T" else a for a in argv]
    rc_new, out_new, err_new = astuple(run_cli_quiet(*argv, *new))
    rc_old, out_old, err_old = astuple(run_cli_quiet(*argv, *old))
    assert rc_new == rc_old == 0, err_new + err_old
    assert err_new == ""
    assert err_old == f"chebnorm: warning: {old[0]} {DEPRECATED}{new[0]}\n"
    a, b = json.loads(out_new), json.loads(out_old)
    for d in (a, b):  # timings and the command line differ between runs
        d.pop("provenance", None)
    assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def test_help_names_each_quantity_once():
    for argv, flags in ((["fit"], ["--coef-frac-bits"]),
                        (["hw", "unit"], ["--coef-frac-bits", "--vector-frac-bits"]),
                        (["hw", "sweep"], ["--coef-frac-bits"])):
        rc, out, _ = astuple(run_cli(*argv, "--help"))
        assert rc == 0 and all(f in out for f in flags)
        assert "deprecated spelling of" in out


def test_closed_output_pipe_stops_quietly():
    # `chebnorm fit ... | head -1` when the output outgrows the pipe: the reader is gone; the command
    # must neither print an error nor a traceback, and ends as SIGPIPE would (141).
    # A child process: the closed pipe and the interpreter's flush at exit are the point.
    proc = subprocess.Popen([sys.executable, "-m", "chebnorm", "fit", "exp(x)", "--interval",
                             "0", "1", "--degree", "4", "--kind", "minimax"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()              # no reader at all: the first write fails
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=300) == 141
    assert err == ""
