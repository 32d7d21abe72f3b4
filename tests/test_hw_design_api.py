"""``chebnorm.hw.design`` (issue 45): the decisions of ``chebnorm design`` in the
library, the command a thin front. The library's result and the command's output
are the same, byte for byte; its refusals name the argument."""

from __future__ import annotations

import math
import re
import shlex
from pathlib import Path

import pytest

import chebnorm as cn
from chebnorm import __version__
from chebnorm.hw import DesignResult, design
from conftest import run_cli

CLI = Path(__file__).resolve().parent.parent / "src" / "chebnorm" / "cli" / "design.py"

#: Python keyword arguments -> the same spec's flags
FLAGS = {"in_bits": "--in-bits", "out_bits": "--out-bits", "max_error": "--max-error",
         "device": "--target", "frequency": "--frequency", "index": "--index",
         "max_segments": "--max-segments"}


def _argv(expr, interval, out, **kw):
    argv = ["design", expr, "--interval", *map(str, interval)]
    for key, value in kw.items():
        if key in ("faithful", "correctly_rounded"):
            argv.append("--" + key.replace("_", "-"))
        elif key == "synth":
            argv += [] if value else ["--no-synth"]
        elif key == "workers":
            argv += ["--workers", str(value)]
        else:
            argv += [FLAGS[key], str(value)]
    return argv + ["-o", str(out)]


def same_as_cli(tmp_path, expr, interval, **kw) -> DesignResult:
    """Run ``chebnorm design`` and :func:`design` on one spec: the files the
    command wrote are ``files()`` byte for byte, and it printed their paths then
    ``lines()``."""
    argv = _argv(expr, interval, tmp_path / "cli", **kw)
    r = run_cli(*argv)
    assert r.code == 0, r.err
    res = design(expr, interval, **kw)
    files = res.files(command=shlex.join(["chebnorm", *argv]), version=__version__)
    written = {p.name: p.read_bytes() for p in (tmp_path / "cli").iterdir()}
    assert sorted(written) == sorted(files), r.out   # the command's report says why
    for fname, content in files.items():
        want = content if isinstance(content, bytes) else content.encode("utf-8")
        assert written[fname] == want, fname
    paths = [str(tmp_path / "cli" / f) for f in files]
    assert r.out.splitlines() == paths + res.lines()
    return res


@pytest.mark.slow
def test_model_only_design_matches_the_command_and_its_bound_holds(tmp_path):
    res = same_as_cli(tmp_path, "1/sqrt(x)", ("1", "4"), in_bits=8, out_bits=8,
                      max_error="2^-7", synth=False, workers=1)
    w = res.winner
    assert res.search is not None and res.pipeline is None and res.candidates == ()
    assert w.architecture == "piecewise" and w.error <= 2.0 ** -7
    # the certified bound against every input code of the bit-accurate model
    m = w.design.measure()
    assert m["codes"] == 2 ** 8 and m["max_error"] <= w.error
    assert res.name == "rsqrt_1_4_i8_o8_e_2_m7"


@pytest.mark.slow
@pytest.mark.requires_tool("yosys")
def test_issue_acceptance_faithful_xc7_nodsp(tmp_path):
    res = same_as_cli(tmp_path, "1/sqrt(1+3*x)", (0, 1), in_bits=16, out_bits=16,
                      faithful=True, device="xc7-nodsp")
    w = res.winner
    assert res.device == "xc7-nodsp" and res.accuracy == "faithful"
    # faithful: the certified bound is below one unit of the output's last place
    ulp = min(c.ulp for c in res.candidates if c.ulp is not None)
    assert w.error < ulp
    # the winner is the cheapest of what was synthesized
    synthesized = [c.cost.score for c in res.candidates if c.cost is not None]
    assert w.score == min(synthesized)
    assert any(f.endswith(".v") and w.design.module_name in f for f in res.files())


@pytest.mark.slow
@pytest.mark.requires_tool("yosys")
def test_correctly_rounded_and_exponent_match_the_command(tmp_path):
    res = same_as_cli(tmp_path / "cr", "1/sqrt(x)", ("1", "4"), in_bits=8, out_bits=8,
                      correctly_rounded=True)
    assert res.winner.architecture == "table" and res.search is None
    res = same_as_cli(tmp_path / "lz", "1/sqrt(x)", ("2^-8", "1"), in_bits=8, out_bits=8,
                      faithful=True, index="exponent")
    assert res.winner.architecture == "exponent"
    assert res.winner.error < 2.0 ** -res.winner.design.frac_bits   # faithful mantissa
    assert {d.degree for d, _ in res.candidates} | {res.winner.design.degree} == {1, 2, 3}


@pytest.mark.slow
@pytest.mark.requires_tool("yosys", "nextpnr-ice40", "iverilog")
def test_frequency_on_ice40_matches_the_command(tmp_path):
    res = same_as_cli(tmp_path, "1/sqrt(x)", ("1", "4"), in_bits=8, out_bits=8,
                      faithful=True, device="ice40", frequency=100)
    assert res.pipeline is not None and res.pipeline.met
    assert any(ln.startswith("timing: pipelined for 100 MHz") for ln in res.lines())


SPEC = dict(expr="1/sqrt(x)", interval=("1", "4"), in_bits=8, out_bits=8, max_error=1e-2,
            synth=False, workers=1)


@pytest.mark.parametrize("change, named", [
    ({"in_bits": 1}, "in_bits"), ({"in_bits": 21}, "in_bits"), ({"out_bits": 33}, "out_bits"),
    ({"max_error": -1.0}, "max_error"), ({"max_error": "nan"}, "max_error"),
    ({"faithful": True}, "max_error"), ({"max_error": None}, "faithful"),
    ({"device": "xc9"}, "device"), ({"frequency": 0}, "frequency"),
    ({"frequency": 100}, "frequency"), ({"frequency": "\u0661\u0660\u0660"}, "frequency"),
    ({"degrees": ()}, "degrees"), ({"degrees": (1, 99)}, "degrees"),
    ({"max_segments": "2^8"}, "max_segments"), ({"max_segments": 3}, "max_segments"),
    ({"index": "log"}, "index"), ({"var": "1x"}, "var"), ({"name": "1bad"}, "name"),
    ({"synth": "no"}, "synth"), ({"faithful": True, "max_error": None}, "synth"),
    ({"workers": 0}, "workers"), ({"interval": ("1",)}, "interval"), ({"interval": 4}, "interval"), ({"expr": ""}, "expr"),
])
def test_refusal_names_the_argument(change, named):
    kw = dict(SPEC, **change)
    with pytest.raises(ValueError, match=named) as exc:
        design(kw.pop("expr"), kw.pop("interval"), **kw)
    assert re.search("accepted|expected|exactly one", str(exc.value)), exc.value
    assert "--" not in str(exc.value)


@pytest.mark.parametrize("change, says", [
    ({"max_error": None, "correctly_rounded": True},
     "correctly_rounded=True: not available with index='exponent'"),
    ({"frequency": 100, "device": "ice40"}, "frequency 100: not available with index='exponent'"),
    ({"degrees": (4,)}, "degrees 4: accepted with index='exponent': 1, 2 or 3"),
])
def test_exponent_refusals_name_the_argument(change, says):
    kw = dict(SPEC, interval=("2^-8", "1"), index="exponent", synth=True, **change)
    with pytest.raises(ValueError, match=re.escape(says)):
        design(kw.pop("expr"), kw.pop("interval"), **kw)


@pytest.mark.parametrize("argv, says", [
    (["--max-error", "1e-2", "--device", "xc9"], "--target 'xc9' is not known"),
    (["--faithful", "--no-synth"], "--faithful compares architectures by synthesis; "
                                   "accepted: without --no-synth"),
    (["--max-error", "1e-2", "--frequency", "100"], "--frequency 100 needs an FPGA's timing; "
                                                    "accepted: --target ice40, xc7 or xc7-nodsp"),
    (["--max-error", "1e-2", "--max-segments", "2^8"], "--max-segments 2^8: with --in-bits 8"),
])
def test_command_refusal_names_the_flag(tmp_path, argv, says):
    r = run_cli("design", "1/sqrt(x)", "--interval", "1", "4", "--in-bits", "8",
                "--out-bits", "8", *argv, "-o", tmp_path / "D")
    assert r.code == 2 and r.err.count("\n") == 1 and says in r.err, r.err
    assert not (tmp_path / "D").exists()


def test_device_is_the_new_spelling_of_target():
    from chebnorm.cli import build_parser

    p = build_parser()
    base = ["design", "x", "--interval", "0", "1", "--in-bits", "8", "--out-bits", "8",
            "--faithful", "-o", "D"]
    assert p.parse_args(base + ["--device", "ice40"]).target == "ice40"
    assert p.parse_args(base + ["--target", "ice40"]).target == "ice40"


def test_the_command_module_is_a_thin_front():
    text = CLI.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 150
    # no Namespace crosses into the library: the command's helpers take none
    assert "argparse_ns" not in (CLI.parent / "hw.py").read_text(encoding="utf-8")
    assert "import argparse" not in text and "vars(args)" not in text
    assert cn.hw.design is design and "design" in cn.hw.__all__ and "DesignResult" in cn.hw.__all__


def test_result_repr_names_the_winner():
    res = design(SPEC["expr"], SPEC["interval"], in_bits=8, out_bits=8, max_error=2.0 ** -6,
                 synth=False, workers=1)
    assert repr(res).startswith("DesignResult(name='rsqrt_1_4_i8_o8_e_2_m6'")
    assert math.isfinite(res.winner.score) and res.winner.error <= 2.0 ** -6
    # 2^-6 and 0.015625 name the same design, text or number
    assert design(SPEC["expr"], SPEC["interval"], in_bits=8, out_bits=8, max_error="2^-6",
                  synth=False, workers=1).name == res.name
