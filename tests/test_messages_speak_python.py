"""Errors speak the caller's language (issue 31): from Python a refused width
names the *argument* (``in_bits``), from the command line the *flag*
(``--in-bits``), in one stderr line with exit status 2."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import chebnorm as cn
from chebnorm.cli import build_parser
from chebnorm.cli.common import cli_flags, command_flags
from chebnorm.hw import design_horner, design_unit, sweep
from chebnorm.hw.piecewise import design_piecewise
from chebnorm.hw.piecewise_search import search
from conftest import run_cli

SRC = Path(__file__).resolve().parent.parent / "src" / "chebnorm"

#: a CLI flag's word in a message (``in-bits``, ``--acc-bits``)
FLAG_WORD = re.compile(r"--[a-z]|\b[a-z]+(?:-[a-z]+)*-bits\b|\blog-m\b")


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    d = tmp_path_factory.mktemp("tables")
    plain = cn.fit("1/sqrt(2+x)", ("0", "1"), 2, name="rs")
    q = cn.quantize(plain, 16)
    pw = cn.fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="pw")
    q.save(d / "q.json")
    plain.save(d / "plain.json")
    pw.save(d / "pw.json")
    return {"plain": plain, "q": q, "pw": pw, "dir": d}


def _python_message(call) -> str:
    with pytest.raises(ValueError) as exc:
        call()
    return str(exc.value)


def _cli_line(argv) -> str:
    """The one error line of ``chebnorm ARGV`` (exit status 2 required)."""
    r = run_cli(*map(str, argv))
    err = r.err
    assert r.code == 2, err
    assert err.count("\n") == 1 and err.startswith("chebnorm: error: ") and "Traceback" not in err
    return err.strip()


# each case: the library call, what its message says; the command, what it says
CASES = {
    "horner in_bits": (
        lambda t: design_horner(t["q"], 40, 8),
        "in_bits = 40 is out of range; accepted: 1 <= in_bits <= 20",
        lambda t, d: ["hw", "verilog", t / "q.json", "--in-bits", 40, "--out-bits", 8, "-o", d],
        "--in-bits = 40 is out of range; accepted: 1 <= --in-bits <= 20"),
    "horner coef_bits": (
        lambda t: design_horner(t["q"], 8, 8, coef_bits=40),
        "coef_bits = 40 is out of range; accepted: 1 <= coef_bits <= 31",
        lambda t, d: ["hw", "report", t / "q.json", "--in-bits", 8, "--out-bits", 8,
                   "--coef-frac-bits", 40, "--no-synth", "--no-gappa"],
        "--coef-frac-bits = 40 is out of range; accepted: 1 <= --coef-frac-bits <= 31"),
    "horner acc_bits": (
        lambda t: design_horner(t["q"], 8, 8, acc_bits=61),
        "acc_bits = 61 is out of range; accepted: 1 <= acc_bits <= 60",
        lambda t, d: ["hw", "verilog", t / "q.json", "--in-bits", 8, "--out-bits", 8,
                   "--acc-bits", 61, "-o", d],
        "--acc-bits = 61 is out of range; accepted: 1 <= --acc-bits <= 60"),
    "horner no fixed point": (
        lambda t: design_horner(t["plain"], 8, 8),
        "or give coef_bits (1 <= coef_bits <= 31) to quantize it here",
        lambda t, d: ["hw", "verilog", t / "plain.json", "--in-bits", 8, "--out-bits", 8, "-o", d],
        "quantized with `chebnorm fit ... --coef-frac-bits F`, or give --coef-frac-bits "
        "(1 <= --coef-frac-bits <= 31)"),
    "horner y_frac_bits": (
        lambda t: design_horner(t["q"], 8, 4, y_frac_bits=20),
        "out_bits 4 with y_frac_bits 20 cannot hold the outputs",
        lambda t, d: ["hw", "verilog", t / "q.json", "--in-bits", 8, "--out-bits", 4,
                   "--y-frac-bits", 20, "-o", d],
        "--out-bits 4 with --y-frac-bits 20 cannot hold the outputs"),
    "piecewise in_bits": (
        lambda t: design_piecewise(t["pw"], 2, 8),
        "in_bits = 2 is out of range; accepted: 3 <= in_bits <= 20",
        lambda t, d: ["hw", "verilog", t / "pw.json", "--in-bits", 2, "--out-bits", 8, "-o", d],
        "--in-bits = 2 is out of range; accepted: 3 <= --in-bits <= 20"),
    "unit frac_bits": (
        lambda t: design_unit("classic", frac_bits=27),
        "frac_bits = 27 is out of range; accepted: 1 <= frac_bits <= 26",
        lambda t, d: ["hw", "unit", "classic", "--vector-frac-bits", 27, "-o", d],
        "--vector-frac-bits = 27 is out of range; accepted: 1 <= --vector-frac-bits <= 26"),
    "unit log_m": (
        lambda t: design_unit("stepper", frac_bits=8, log_m=11),
        "log_m = 11 is out of range; accepted: 0 <= log_m <= 10",
        lambda t, d: ["hw", "unit", "stepper", "--log-m", 11, "-o", d],
        "--log-m = 11 is out of range; accepted: 0 <= --log-m <= 10"),
    "sweep coef_bits": (
        lambda t: sweep("dichotomy", degrees=(1,), coef_bits=(41,), acc_bits=(14,), in_bits=8,
                        out_bits=8, synth=False, workers=1, progress=False),
        "coef_bits = 41 is out of range; accepted: 1 <= coef_bits <= 40",
        lambda t, d: ["hw", "sweep", "--degrees", 1, "--coef-frac-bits", 41, "--acc-bits", 14,
                   "--no-synth", "-o", d],
        "--coef-frac-bits = 41 is out of range; accepted: 1 <= --coef-frac-bits <= 40"),
    "design in_bits": (
        lambda t: search("1/sqrt(x)", ("1", "4"), 1, 8, 1e-2, synth=False, progress=False,
                         workers=1),
        "in_bits = 1 is out of range; accepted: 2 <= in_bits <= 20",
        lambda t, d: ["design", "1/sqrt(x)", "--interval", 1, 4, "--in-bits", 1, "--out-bits", 8,
                   "--max-error", "1e-2", "--no-synth", "-o", d / "D"],
        "--in-bits = 1 is out of range; accepted: 2 <= --in-bits <= 20"),
    "piecewise fit coef_frac_bits": (
        lambda t: cn.fit("1/sqrt(x)", ("1", "4"), 3, segments=4, coef_frac_bits=62),
        "coef_frac_bits = 62 is out of range; accepted: 0 <= coef_frac_bits <= 48",
        lambda t, d: ["fit", "1/sqrt(x)", "--interval", 1, 4, "--degree", 3, "--segments", 4,
                   "--coef-frac-bits", 62],
        "--coef-frac-bits = 62 is out of range; accepted: 0 <= --coef-frac-bits <= 48"),
}


def test_design_search_names_max_error():
    message = _python_message(lambda: search("1/sqrt(x)", ("1", "4"), 8, 8, -1.0, synth=False,
                                             progress=False, workers=1))
    assert message.startswith("max_error -1.0 is not a positive number")


@pytest.mark.parametrize("case", sorted(CASES))
def test_python_names_the_argument(tables, case):
    call, says, _, _ = CASES[case]
    message = _python_message(lambda: call(tables))
    assert says in message
    assert not FLAG_WORD.search(message), message


@pytest.mark.parametrize("case", sorted(CASES))
def test_cli_names_the_flag(tables, case, capsys, tmp_path):
    _, _, argv, says = CASES[case]
    line = _cli_line(argv(tables["dir"], tmp_path))
    assert says in line
    # no Python spelling of a width left over
    assert not re.search(r"(?<![\w.^])[a-z]+(?:_[a-z]+)*_(?:bits|m)\b", line), line
    assert list(tmp_path.iterdir()) == []   # nothing half-written


def test_no_library_width_check_is_named_as_a_flag():
    """The checks of the library name the Python argument: no ``check_width(x,
    "in-bits", ...)`` left outside the command line."""
    call = re.compile(r"(?:check_width|check_int|_validate_list)\([^,()]+,\s*f?\"([^\"]*)\"")
    offenders = []
    for path in SRC.rglob("*.py"):
        if "cli" in path.relative_to(SRC).parts:
            continue
        for m in call.finditer(path.read_text(encoding="utf-8")):
            if "-" in m.group(1):
                offenders.append(f"{path.relative_to(SRC)}: {m.group(1)!r}")
    assert offenders == []


def test_command_flags_follow_the_parser():
    parser = build_parser()
    args = parser.parse_args(["hw", "unit", "classic", "--frac-bits", "6", "-o", "."])
    flags = command_flags(parser, args)
    # the deprecated --frac-bits and --coef-bits never name an argument
    assert flags["frac_bits"] == "--vector-frac-bits" and flags["coef_bits"] == "--coef-frac-bits"
    assert flags["log_m"] == "--log-m" and "guard" not in flags and "output" not in flags
    args = parser.parse_args(["fit", "x", "--interval", "0", "1", "--degree", "1"])
    flags = command_flags(parser, args)
    assert flags["frac_bits"] == flags["coef_frac_bits"] == "--coef-frac-bits"
    assert "in_bits" not in flags   # fit has no --in-bits


def test_cli_flags_leaves_fields_and_longer_names():
    flags = {"in_bits": "--in-bits", "frac_bits": "--coef-frac-bits"}
    text = ("in_bits = 3; quantized.frac_bits is 9; x_frac_bits 4; x = k / 2^in_bits; "
            "frac_bits")
    assert cli_flags(text, flags) == ("--in-bits = 3; quantized.frac_bits is 9; x_frac_bits 4; "
                                      "x = k / 2^in_bits; --coef-frac-bits")
