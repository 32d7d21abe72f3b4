"""Issue 26, items 1, 2, 7, 8 and part of 10: no forged bound survives a consumer.

"A bound is printed only if it was proved for exactly what is printed": a
table is verified when it is constructed from anything but the fitter (a file,
``dataclasses.replace``, a hand-built one), the piecewise table's top-level
bounds are its segments', located maxima are checked, JSON is written strictly
and read without duplicate keys, and names are checked where they enter.
Every forged claim below is also shown false by an independent computation
(mpmath at 40 digits), so a refusal is the right answer.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import astuple
from pathlib import Path

import mpmath
import pytest

import chebnorm as cn
import chebnorm.hw
from chebnorm.approx import CoefficientTable, fit
from chebnorm.approx.piecewise_table import PiecewiseTable
from chebnorm.approx.piecewise_fit import piecewise_fit
from chebnorm.cli import main
from conftest import run_cli

ROOT = Path(__file__).resolve().parents[1]
BASE = ROOT / "figures" / "coefficients" / "dichotomy_d2.json"  # 1/sqrt(z + 2) on [sqrt(2), 2]
PW_ARGS = ["fit", "1/sqrt(x)", "--interval", "1", "4", "--degree", "1", "--segments", "2^5",
           "--kind", "minimax", "--coef-frac-bits", "11"]


def refused(code, err, pattern):
    """Exit 2 and exactly one line naming the problem."""
    assert code == 2, err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("chebnorm: error: "), err
    assert pattern in lines[0], lines[0]


def segment_rel_sup(table: PiecewiseTable, s: int, points: int = 201) -> float:
    """max |p_s/f - 1| on a grid of segment ``s`` at 40 digits (a lower bound of the sup)."""
    with mpmath.workdps(40):
        a, b = (mpmath.mpf(str(v)) for v in table.segment_bounds(s))
        cs = [mpmath.ldexp(q, -table.coef_frac_bits) for q in table.segments[s].integers]
        best = mpmath.mpf(0)
        for k in range(points):
            t = mpmath.mpf(k) / (points - 1)
            x = a + (b - a) * t
            best = max(best, abs(mpmath.polyval(cs[::-1], t) * mpmath.sqrt(x) - 1))
        return float(best)


# -- item 1: the piecewise table's top-level bounds are its segments' ------------

@pytest.fixture(scope="module")
def piecewise_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("pw") / "T.json"
    assert main([*PW_ARGS, "-o", str(path)]) == 0
    return path


def _consumers(path: Path, out: Path):
    return [["export", path, "--format", "c", "-o", out / "t.h"],
            ["export", path, "--format", "json", "-o", out / "t.json"],
            ["export", path, "--format", "verilog", "-o", out / "t.v"],
            ["hw", "verilog", path, "--in-bits", "10", "--out-bits", "10", "-o", out / "v"],
            ["hw", "report", path, "--in-bits", "10", "--out-bits", "10"]]


def test_forged_piecewise_relative_bound_refused_by_every_consumer(piecewise_file, tmp_path,
                                                                   capsys):
    table = PiecewiseTable.load(piecewise_file)
    # the relative error the forgery would hide (independent: mpmath on a grid)
    assert max(segment_rel_sup(table, s) for s in range(table.segment_count)) > 5e-4
    d = json.loads(piecewise_file.read_text())
    assert d["error_kind"] == "abs" and d["rel_error_bound"] is None
    d["rel_error_bound"] = 1e-12
    forged = tmp_path / "forged.json"
    forged.write_text(json.dumps(d))
    for argv in _consumers(forged, tmp_path):
        code, _, err = astuple(run_cli(argv))
        refused(code, err, "rel_error_bound: expected null (error_kind is 'abs'")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["forged.json"]


def test_forged_error_kind_and_top_level_bounds_refused(tmp_path, capsys):
    path = tmp_path / "R.json"
    assert main([*PW_ARGS, "--error", "rel", "-o", str(path)]) == 0
    good = json.loads(path.read_text())
    assert good["error_kind"] == "rel"
    cases = {
        # rel -> abs, the bound divided by 1000: the segments still carry rel bounds
        "segments[0].rel_error_bound: expected null": {"error_kind": "abs",
                                                       "abs_error_bound": good["abs_error_bound"] / 1000},
        "rel_error_bound: stated": {"rel_error_bound": good["rel_error_bound"] / 1000},
        "abs_error_bound: stated": {"abs_error_bound": good["abs_error_bound"] * 2},
    }
    for message, change in cases.items():
        forged = tmp_path / "forged.json"
        forged.write_text(json.dumps({**good, **change}))
        code, _, err = astuple(run_cli(["export", forged, "--format", "c", "-o", tmp_path / "t.h"]))
        refused(code, err, message)
    # the same in memory
    table = PiecewiseTable.load(path)
    with pytest.raises(ValueError, match=r"^rel_error_bound: stated"):
        dataclasses.replace(table, rel_error_bound=table.rel_error_bound / 1000)
    with pytest.raises(ValueError, match=r"^segments\[0\]\.rel_error_bound: expected null"):
        dataclasses.replace(table, error_kind="abs", rel_error_bound=None)


# -- item 2: in-memory tables are verified ------------------------------------------

def _true_abs_error_at_2(coefficients) -> float:
    with mpmath.workdps(40):
        z = mpmath.mpf(2)
        return float(abs(mpmath.polyval([mpmath.mpf(c) for c in coefficients][::-1], z)
                         - 1 / mpmath.sqrt(z + 2)))


def test_replace_with_a_forged_bound_is_refused():
    t = CoefficientTable.load(BASE)
    coefficients = (0.7, -0.1, 0.01)
    assert _true_abs_error_at_2(coefficients) > 3.9e-2  # what 1e-30 would hide
    with pytest.raises(ValueError, match=r"^abs_error_bound: stated 1\.00e-30 but the "
                                         r"coefficients' certified error is 4\.00e-02"):
        dataclasses.replace(t, abs_error_bound=1e-30, coefficients=coefficients)


@pytest.mark.parametrize("part", ["fixed_point", "quantized"])
def test_replace_with_a_forged_nested_bound_is_refused(part):
    t = CoefficientTable.load(BASE)
    claims = getattr(t, part)
    forged = dataclasses.replace(claims, abs_error_bound=claims.abs_error_bound / 2)
    with pytest.raises(ValueError, match=rf"^{part}\.abs_error_bound: stated"):
        dataclasses.replace(t, **{part: forged})


def test_every_consumer_re_proves_a_table_changed_behind_its_back():
    """``object.__setattr__`` defeats the frozen dataclass: the consumers notice."""
    t = CoefficientTable.load(BASE)
    object.__setattr__(t, "abs_error_bound", 1e-30)
    calls = [lambda fmt=fmt: cn.export(t, fmt) for fmt in ("c", "glsl", "wgsl", "hlsl", "json")]
    calls += [lambda: cn.quantize(t, 16),
              lambda: chebnorm.hw.report(t, 10, 10, synth=False, gappa=False),
              t.verify]
    for call in calls:
        with pytest.raises(ValueError, match=r"^abs_error_bound: stated 1\.00e-30"):
            call()
    q = CoefficientTable.load(BASE)
    object.__setattr__(q.quantized, "abs_error_bound", 1e-30)  # a nested object too
    with pytest.raises(ValueError, match=r"^quantized\.abs_error_bound: stated 1\.00e-30"):
        cn.export(q, "c")


def test_hand_built_table_is_verified():
    kw = dict(name="sq", expression="x**2", variable="x", interval=("0", "1"),
              interval_float=(0.0, 1.0), degree=1, kind="chebyshev", error_kind="abs",
              coefficients=(0.0, 1.0), rel_error_bound=None, max_rel_error=None,
              max_rel_at=None)
    # x - x**2 reaches 1/4 at 1/2
    with pytest.raises(ValueError, match=r"^abs_error_bound: stated 1\.00e-03"):
        CoefficientTable(**kw, abs_error_bound=1e-3, max_abs_error=1e-3, max_abs_at=0.5)
    t = CoefficientTable(**kw, abs_error_bound=0.25, max_abs_error=0.25, max_abs_at=0.5)
    assert t.verify() is t


def test_piecewise_replace_with_a_forged_segment_is_refused():
    t = piecewise_fit("x**3", ("0", "1"), 1, segments=2, coef_frac_bits=12)
    seg = dataclasses.replace(t.segments[1], abs_error_bound=1e-9)
    with pytest.raises(ValueError, match=r"^abs_error_bound: stated"):
        dataclasses.replace(t, segments=(t.segments[0], seg))  # the top bound is derived


# -- item 7: strict JSON, a non-finite bound refused at fit time --------------------

@pytest.mark.parametrize("expr, lo, hi", [("x**1024", "0", "2"), ("sin(x)", "0", "1e300")])
def test_non_finite_bound_refused_at_fit(expr, lo, hi, tmp_path, capsys):
    out = tmp_path / "I.json"
    code, stdout, err = astuple(run_cli(["fit", expr, "--interval", lo, hi, "--degree", "2",
                                         "-o", out]))
    refused(code, err, "beyond the float64 range")
    assert not out.exists() and stdout == ""
    code, stdout, err = astuple(run_cli(["fit", expr, "--interval", lo, hi, "--degree", "2",
                                         "--json"]))
    refused(code, err, "beyond the float64 range")
    assert stdout == ""
    with pytest.raises(ValueError, match=r"^abs_error_bound: the certified value is inf"):
        fit(expr, (lo, hi), 2)


def test_json_is_written_strictly():
    from chebnorm.approx.contract import construction

    t = CoefficientTable.load(BASE)
    with construction("unchecked"):
        bad = dataclasses.replace(t, abs_error_bound=math.inf)
    with pytest.raises(ValueError, match="JSON compliant"):
        bad.to_json()


# -- item 8: names checked where they enter ----------------------------------------

@pytest.mark.parametrize("name", ['a"b', "a\nb", "*/", "été", "", "a b"])
def test_fit_name_refused_at_the_source(name, tmp_path, capsys):
    out = tmp_path / "N.json"
    code, _, err = astuple(run_cli(["fit", "exp(x)", "--interval", "0", "1", "--degree", "1",
                                    "--name", name, "-o", out]))
    refused(code, err, "--name: ")
    assert "[A-Za-z_][A-Za-z0-9_]*" in err and not out.exists()
    with pytest.raises(ValueError, match=r"^name: .* is not an identifier: expected "
                                         r"\[A-Za-z_\]\[A-Za-z0-9_\]\*"):
        fit("exp(x)", ("0", "1"), 1, name=name)
    with pytest.raises(ValueError, match=r"^name: "):
        piecewise_fit("exp(x)", ("0", "1"), 1, name=name)
    with pytest.raises(ValueError, match=r"^name: "):
        dataclasses.replace(CoefficientTable.load(BASE), name=name)


def test_default_name_comes_from_the_fit():
    assert fit("exp(x)", ("0", "1"), 1).name == "exp_0_1_d1"


# -- item 10: located maxima checked; duplicate JSON keys refused -------------------

def _load_changed(tmp_path, change):
    d = json.loads(BASE.read_text())
    change(d)
    path = tmp_path / "t.json"
    path.write_text(json.dumps(d))
    return CoefficientTable.load(path)


def test_located_maximum_of_zero_refused(tmp_path):
    def zero(d):
        d["max_abs_error"] = 0.0
    with pytest.raises(ValueError, match=r"max_abs_error: stated 0\.00e\+00 but the error "
                                         r"reaches"):
        _load_changed(tmp_path, zero)


def test_located_maximum_must_be_the_error_at_its_point(tmp_path):
    t = CoefficientTable.load(BASE)
    at = 1.9  # not where the maximum is: |p - f| there, from mpmath
    with mpmath.workdps(40):
        g = abs(mpmath.polyval([mpmath.mpf(c) for c in t.coefficients][::-1], mpmath.mpf(at))
                - 1 / mpmath.sqrt(mpmath.mpf(at) + 2))
    assert float(g) < t.max_abs_error / 1.01

    def moved(d):
        d["max_abs_at"] = at
    with pytest.raises(ValueError, match=r"max_abs_error: stated .* but \|p - f\| at "
                                         r"max_abs_at = 1\.9 is"):
        _load_changed(tmp_path, moved)


@pytest.mark.parametrize("part", ["fixed_point", "quantized"])
def test_nested_located_maximum_checked(part, tmp_path):
    def zero(d):
        d[part]["max_abs_error"] = 0.0

    def above(d):  # above the certified supremum, below the (loosened) stated bound
        d[part]["abs_error_bound"] *= 2
        d[part]["max_abs_error"] *= 1.5
    with pytest.raises(ValueError, match=rf"{part}\.max_abs_error: stated 0\.00e\+00"):
        _load_changed(tmp_path, zero)
    with pytest.raises(ValueError, match=rf"{part}\.max_abs_error: the located maximum .* "
                                         r"exceeds the certified bound"):
        _load_changed(tmp_path, above)


def test_piecewise_segment_maximum_checked(piecewise_file, tmp_path):
    d = json.loads(piecewise_file.read_text())
    d["segments"][3]["max_abs_error"] = 0.0
    path = tmp_path / "t.json"
    path.write_text(json.dumps(d))
    with pytest.raises(ValueError, match=r"segments\[3\]\.max_abs_error: stated 0\.00e\+00"):
        PiecewiseTable.load(path)


def test_duplicate_json_keys_refused(piecewise_file, tmp_path, capsys):
    text = BASE.read_text()
    dup = text.replace('"abs_error_bound": ', '"abs_error_bound": 1e-30, "abs_error_bound": ', 1)
    path = tmp_path / "dup.json"
    path.write_text(dup)
    with pytest.raises(ValueError, match=r"key 'abs_error_bound' appears twice"):
        CoefficientTable.load(path)
    code, _, err = astuple(run_cli(["export", path, "-o", tmp_path / "t.h"]))
    refused(code, err, "key 'abs_error_bound' appears twice in one object")
    pw = piecewise_file.read_text().replace('"name": ', '"name": "x", "name": ', 1)
    path.write_text(pw)
    with pytest.raises(ValueError, match=r"key 'name' appears twice"):
        PiecewiseTable.load(path)
