"""One contract for two kinds of table: CoefficientTable and PiecewiseTable are both
:class:`chebnorm.approx.contract.Table`, and :func:`chebnorm.approx.load_table` reads
a file of either kind as what it declares (issue 27, tables)."""

from __future__ import annotations

import json
import math
import re
import sys
from dataclasses import replace
from pathlib import Path

import mpmath
import numpy as np
import pytest

import chebnorm as cn
from chebnorm import approx
from chebnorm.approx import (CoefficientTable, PiecewiseTable, Table, load_table, parse_function,
                             table_from_json)

REPO = Path(__file__).resolve().parent.parent
DATA = REPO / "tests" / "data"
#: coefficient tables committed by ``chebnorm repro`` and the hardware tests
COEFFICIENT_FILES = sorted((REPO / "figures" / "coefficients").glob("*.json")) + \
    sorted((DATA / "units_tables").glob("*.json"))
#: piecewise tables written by the fitter before it moved to approx/piecewise_fit.py
PIECEWISE_FILES = sorted((DATA / "piecewise_tables").glob("*.json"))
#: the arguments each committed piecewise table was fitted with
PIECEWISE_ARGS = {
    "rsqrt_uniform.json": (("1/sqrt(x)", ("1", "4"), 2),
                           dict(segments=8, coef_frac_bits=20, centered=True, name="rsqrt_u8",
                                command="tests/data/piecewise_tables (fit_piecewise, uniform, "
                                        "abs)")),
    "rsqrt_exponent_rel.json": (("1/sqrt(x)", ("1/4", "4"), 1),
                                dict(segments=4, segment_by="exponent", coef_frac_bits=18,
                                     error="rel", fit="chebyshev", name="rsqrt_e4",
                                     command="tests/data/piecewise_tables (fit_piecewise, "
                                             "exponent, rel)")),
}
ALL_FILES = COEFFICIENT_FILES + PIECEWISE_FILES


def test_the_committed_files_are_there():
    assert len(COEFFICIENT_FILES) >= 20 and len(PIECEWISE_FILES) == len(PIECEWISE_ARGS) == 2


# -- load_table: the right kind, or a refusal naming the path ----------------------

@pytest.mark.parametrize("path", ALL_FILES, ids=[p.name for p in ALL_FILES])
def test_load_table_returns_the_declared_kind_byte_identically(path, tmp_path):
    t = load_table(path)
    text = path.read_text(encoding="utf-8")
    kind = PiecewiseTable if json.loads(text).get("kind") == "chebnorm.piecewise_table" \
        else CoefficientTable
    assert type(t) is kind and isinstance(t, Table)
    assert kind.load(path) == t
    # the contract: to_json is the file, byte for byte; save writes it; from_json reads it back
    assert t.to_json() == text
    out = tmp_path / path.name
    t.save(out)
    assert out.read_bytes() == path.read_bytes()
    assert kind.from_json(text) == t and table_from_json(text) == t
    assert t.verify() is t


@pytest.mark.parametrize("content, why", [
    ('{"cells": [], "metadata": {}}', "a JSON object with neither schema_version nor kind"),
    ('{"kind": "chebyshev", "name": "t"}', "kind 'chebyshev' is not a chebnorm table kind"),
    ("[1, 2, 3]", "expected a JSON object, got an array of 3"),
    ('"chebnorm.piecewise_table"', "expected a JSON object, got 'chebnorm.piecewise_table'"),
])
def test_load_table_refuses_other_json_naming_the_path(tmp_path, content, why):
    path = tmp_path / "other.json"
    path.write_text(content)
    with pytest.raises(ValueError) as info:
        load_table(path)
    message = str(info.value)
    assert message.startswith(f"{str(path)!r} is not a chebnorm table: {why}; accepted: "), message
    assert "schema_version 1" in message and "'chebnorm.piecewise_table'" in message
    with pytest.raises(ValueError, match=f"^not a chebnorm table: {re.escape(why)}"):
        table_from_json(content)


def test_load_table_refuses_a_committed_file_that_is_no_table():
    path = REPO / "figures" / "provenance.json"
    with pytest.raises(ValueError, match=rf"^{re.escape(repr(str(path)))} is not a chebnorm table"):
        load_table(path)


def test_load_table_refusals_start_with_the_kind_and_the_path(tmp_path):
    """A damaged file of each kind is refused by its own reader, naming the file and field;
    an unreadable or non-JSON file as a coefficient table (what the CLI always said)."""
    d = json.loads(PIECEWISE_FILES[0].read_text())
    d["degree"] = True
    bad = tmp_path / "p.json"
    bad.write_text(json.dumps(d))
    with pytest.raises(ValueError, match=rf"^piecewise table {re.escape(repr(str(bad)))}: degree: "
                                         r"expected an integer in \[0, 8\], got true$"):
        load_table(bad)
    d = json.loads(COEFFICIENT_FILES[0].read_text())
    d["degree"] = "2"
    bad.write_text(json.dumps(d))
    with pytest.raises(ValueError, match=rf"^coefficient table {re.escape(repr(str(bad)))}: degree: "
                                         r"expected an integer in 0\.\.30, got '2'$"):
        load_table(bad)
    bad.write_text("{")
    with pytest.raises(ValueError, match=r"^coefficient table .* is not valid JSON"):
        load_table(bad)
    with pytest.raises(ValueError, match=r"^cannot read coefficient table .*missing\.json"):
        load_table(tmp_path / "missing.json")
    bad.write_bytes(b" " * (2 ** 20 + 1))  # larger than a coefficient table may be
    with pytest.raises(ValueError, match=r"is larger than 1048576 bytes"):
        load_table(bad)


# -- the contract ------------------------------------------------------------------

def _both():
    return [load_table(COEFFICIENT_FILES[0]), load_table(PIECEWISE_FILES[1])]


def test_both_kinds_satisfy_the_contract():
    from chebnorm.core.numeric import format_up

    for t in _both():
        assert isinstance(t, Table)
        for attr in ("name", "expression", "variable", "interval", "degree", "error_kind",
                     "abs_error_bound", "rel_error_bound", "provenance"):
            assert hasattr(t, attr), (type(t).__name__, attr)
        assert t.bounds == (t.abs_error_bound, t.rel_error_bound)
        assert t.bounds.abs == t.abs_error_bound and t.bounds.rel == t.rel_error_bound
        html_text, markdown = t._repr_html_(), t._repr_markdown_()
        assert f"<b>{type(t).__name__} {t.name}</b>" in html_text
        assert markdown.startswith(f"**{type(t).__name__} {t.name.replace('_', chr(92) + '_')}**")
        shown = format_up(t.abs_error_bound, ".6e")  # a bound is printed rounded up
        assert shown in html_text and shown in markdown
    with pytest.raises(TypeError):
        Table()  # the contract alone is abstract


def test_piecewise_display_escapes_untrusted_text():
    t = load_table(PIECEWISE_FILES[0])
    hostile = replace(t, provenance={"command": "<script>a|b</script>"})
    assert "<script>" not in hostile._repr_html_() and "&lt;script&gt;" in hostile._repr_html_()
    assert r"a\|b" in hostile._repr_markdown_()


def test_a_changed_piecewise_table_is_reproved_by_verify():
    t = load_table(PIECEWISE_FILES[0])
    seg = t.segments[3]
    with pytest.raises(ValueError, match=r"^segments\[3\]\.abs_error_bound: stated"):
        replace(t, segments=t.segments[:3] + (replace(seg, abs_error_bound=seg.max_abs_error / 2),)
                + t.segments[4:])
    object.__setattr__(t, "segments", t.segments[:3] + (replace(
        seg, integers=(seg.integers[0] + 4096, *seg.integers[1:])),) + t.segments[4:])
    with pytest.raises(ValueError, match=r"^segments\[3\]\.abs_error_bound: stated"):
        t.verify()


@pytest.mark.parametrize("path", PIECEWISE_FILES, ids=[p.name for p in PIECEWISE_FILES])
def test_piecewise_error_curve_is_the_error_and_stays_in_the_bound(path):
    """``error_curve`` against an independent evaluation: the float64 table
    (``t(x)``, Horner on exact doubles) minus ``f`` in mpmath; their difference is the
    float evaluation's rounding, a few ulps of the largest term."""
    t = load_table(path)
    error = t.error_kind
    x, g = t.error_curve(301, error)
    f_mp = parse_function(t.expression, t.variable).mpmath
    with mpmath.workdps(30):
        f = np.array([float(f_mp(mpmath.mpf(float(v)))) for v in x])
    p = t(x)
    direct = p - f if error == "abs" else p / f - 1
    scale = max(max(abs(c) for c in t.coefficients(s)) for s in range(t.segment_count))
    tol = 8 * (t.degree + 2) * sys.float_info.epsilon * scale / (1 if error == "abs" else f.min())
    assert np.max(np.abs(g - direct)) <= tol
    bound = t.abs_error_bound if error == "abs" else t.rel_error_bound
    assert np.max(np.abs(g)) <= bound
    # the segment bounds hold segment by segment
    seg_of = [t._segment_of(float(v)) for v in x]
    own = np.array([getattr(t.segments[s], f"{error}_error_bound") for s in seg_of])
    assert np.all(np.abs(g) <= own)


def test_piecewise_plot_draws_the_curve_and_the_bounds():
    import matplotlib

    matplotlib.use("Agg")
    t = load_table(DATA / "piecewise_tables" / "rsqrt_exponent_rel.json")
    ax = t.plot(error="rel", points=101)
    assert ax.get_xlabel() == "x" and ax.get_ylabel() == "p/f - 1"
    ys = [line.get_ydata() for line in ax.get_lines()]
    assert any(len(y) == 101 for y in ys)
    assert any(np.allclose(y, t.rel_error_bound) for y in ys if len(y) == 2)
    with pytest.raises(ValueError, match="has no relative error"):
        load_table(DATA / "piecewise_tables" / "rsqrt_uniform.json").plot(error="rel")


@pytest.mark.parametrize("name", sorted(PIECEWISE_ARGS))
def test_the_moved_fitter_writes_the_committed_tables(name):
    """The committed piecewise tables were written by the fitter before it moved; the
    fitter now gives the same table (the versions in the provenance aside)."""
    args, kwargs = PIECEWISE_ARGS[name]
    fitted = approx.piecewise_fit(*args, **kwargs).to_dict()
    committed = json.loads((DATA / "piecewise_tables" / name).read_text())
    for d in (fitted, committed):
        d["provenance"] = {"command": d["provenance"]["command"]}
    assert fitted == committed


# -- the public names ----------------------------------------------------------------

def test_public_names():
    for name in ("PiecewiseTable", "load_table", "table_from_json", "Table", "piecewise_fit"):
        assert name in approx.__all__, name
    assert cn.PiecewiseTable is PiecewiseTable and cn.load_table is load_table
    assert "PiecewiseTable" in cn.__all__ and "load_table" in cn.__all__
    doc = PiecewiseTable.__doc__
    fields = [f for f in PiecewiseTable.__dataclass_fields__]
    assert "Attributes" in doc and all(re.search(rf"^    {f} : ", doc, re.M) for f in fields)
    assert all(math.isfinite(b) for b in load_table(PIECEWISE_FILES[0]).bounds if b is not None)
