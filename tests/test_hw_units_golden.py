"""The normalization units write the bytes recorded for them: every file of a
grid of designs and command lines (Verilog and VHDL modules and benches,
vectors, reports) against the sha256 sums tests/units_golden.py recorded at
the commit named in tests/data/units_golden.json (see its docstring for what
they are)."""

from __future__ import annotations

import json

import pytest

import units_golden as ug

GOLDEN = json.loads(ug.GOLDEN.read_text())


def test_fixture_made_from_a_clean_commit():
    assert GOLDEN["src_clean"] and len(GOLDEN["generated_at_commit"]) == 40
    assert len(GOLDEN["units"]) == len(ug._cases())


@pytest.mark.parametrize("case", ug._cases(), ids=ug._case_id)
def test_unit_bytes_unchanged(case):
    assert ug.unit_case(case) == GOLDEN["units"][ug._case_id(case)]


def test_cli_bytes_unchanged():
    now = ug.cli_cases(synth=False)
    assert now.keys() == GOLDEN["cli"].keys()
    for key, want in GOLDEN["cli"].items():
        got = now[key]
        if key.startswith("hw report"):
            # the table's own report is another module's; the units' part is ours
            got, want = dict(got), dict(want)
            got.pop("stdout"), want.pop("stdout")
        assert got == want, key


@pytest.mark.requires_tool("yosys")
def test_yosys_cells_unchanged():
    assert ug.yosys_cells() == GOLDEN["yosys_cells"]
