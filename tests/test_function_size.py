"""No function in src/ reaches 100 lines (issue 12: a function that long hides
switches and duplicated cases). Measured with ast: ``end_lineno - lineno + 1``,
decorators excluded, nested functions counted on their own and inside their
parent. One test per module, so a failure names the file."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parent.parent / "src"
MAX_LINES = 99
MODULES = sorted(SRC.rglob("*.py"))


def long_functions(path: Path) -> list[tuple[str, int]]:
    """``(name, lines)`` of every function of ``path`` longer than MAX_LINES."""
    tree = ast.parse(path.read_text(), filename=str(path))
    return [(f"{n.name} (line {n.lineno})", n.end_lineno - n.lineno + 1)
            for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))
            and n.end_lineno - n.lineno + 1 > MAX_LINES]


def test_measure_is_right(tmp_path):
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_LINES - 1))
    ok, bad = tmp_path / "ok.py", tmp_path / "bad.py"
    ok.write_text(f"def f():\n{body}\n")  # exactly MAX_LINES lines
    bad.write_text(f"def f():\n{body}\n    return 0\n")
    assert long_functions(ok) == [] and long_functions(bad) == [("f (line 1)", MAX_LINES + 1)]


def test_every_module_is_found():
    assert len(MODULES) > 20 and SRC / "chebnorm" / "hw" / "units" / "base.py" in MODULES


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(SRC)))
def test_functions_under_100_lines(path):
    assert long_functions(path) == [], f"{path.relative_to(SRC)}: functions of 100+ lines"
