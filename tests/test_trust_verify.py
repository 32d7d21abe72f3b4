"""Constant functions export without a traceback (issue 43)."""

import pytest

from conftest import run_cli


@pytest.mark.parametrize("expr", ["5", "0.1", "x - x + 1/3"])
def test_constant_function_float_exports(tmp_path, expr):
    table = tmp_path / "t.json"
    code, _, err = run_cli("fit", expr, "--interval", "1", "2", "--degree", "2", "-o", str(table))
    assert code == 0, err
    for fmt in ("c", "glsl", "wgsl", "hlsl"):
        out = tmp_path / f"t.{fmt}"
        code, _, err = run_cli("export", str(table), "--format", fmt, "-o", str(out))
        assert code == 0, err
        assert "Traceback" not in err and out.stat().st_size > 0
