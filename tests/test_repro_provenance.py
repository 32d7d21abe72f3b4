"""The committed coefficient tables' provenance (issue 44): the command each
records is spelled with the current argument names, and replaying it gives the
committed table."""

from __future__ import annotations

import ast
import json
import warnings
from pathlib import Path

import pytest

from chebnorm.approx import fit_target
from chebnorm.core.deprecation import ChebnormDeprecationWarning
from quiet_cli import run_cli_quiet

COEFFS = Path(__file__).resolve().parents[1] / "figures" / "coefficients"
TABLES = sorted(COEFFS.glob("*.json"))


def _call(command: str):
    """``fit_target(...)`` read from the recorded command text (literals only: nothing run)."""
    call = ast.parse(command, mode="eval").body
    assert isinstance(call, ast.Call) and ast.unparse(call.func) == "chebnorm.approx.fit_target"
    return ([ast.literal_eval(a) for a in call.args],
            {k.arg: ast.literal_eval(k.value) for k in call.keywords})


def test_there_are_committed_tables():
    assert len(TABLES) >= 8


@pytest.mark.parametrize("path", TABLES, ids=[p.stem for p in TABLES])
def test_recorded_command_replays_without_deprecation_to_the_same_table(path):
    table = json.loads(path.read_text(encoding="utf-8"))
    command = table["provenance"]["command"]
    args, kwargs = _call(command)
    assert "frac_bits" not in kwargs and kwargs.get("coef_frac_bits") == 24, command
    with warnings.catch_warnings():
        warnings.simplefilter("error", ChebnormDeprecationWarning)   # the current spelling
        again = fit_target(*args, **kwargs)
    assert again.provenance["command"] == command
    assert again.coefficients == tuple(table["coefficients"])
    assert again.abs_error_bound == table["abs_error_bound"]
    assert again.fixed_point.integers == tuple(table["fixed_point"]["integers"])


def test_deprecated_spelling_records_the_current_one():
    with pytest.warns(ChebnormDeprecationWarning):
        t = fit_target("dichotomy", 1, frac_bits=12)
    assert t.provenance["command"].endswith("coef_frac_bits=12)")


def test_committed_tables_are_what_repro_writes(tmp_path):
    r = run_cli_quiet("repro", "coefficients", "-o", tmp_path / "o", "--workers", "1",
                      cwd=tmp_path)
    assert r.code == 0, r.err
    new = tmp_path / "o" / "coefficients"
    assert sorted(p.name for p in new.iterdir()) == sorted(p.name for p in COEFFS.iterdir())
    for p in sorted(new.iterdir()):
        assert p.read_bytes() == (COEFFS / p.name).read_bytes(), p.name
    header = (COEFFS / "chebnorm_rsqrt_d3.h").read_text(encoding="utf-8")
    assert "coef_frac_bits=24" in header and ", frac_bits=" not in header
