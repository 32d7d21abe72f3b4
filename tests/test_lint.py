"""``ruff check`` with the pyflakes rules (F: unused imports and variables,
undefined names, f-strings without placeholders, ...) passes on the library,
the paper reproduction, the benchmarks and the tests."""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
FOLDERS = ("src", "paper_repro", "benchmarks", "tests")


def _ruff() -> list[str]:
    if importlib.util.find_spec("ruff") is not None:  # installed in this interpreter
        return [sys.executable, "-m", "ruff"]
    exe = shutil.which("ruff")
    if exe is None:
        pytest.skip("ruff is not installed (pip install ruff, or the test extra)")
    return [exe]


def _check(*args):
    # --isolated: the rule set is the one stated here, whatever config is around
    return subprocess.run([*_ruff(), "check", "--isolated", "--select", "F",
                           "--output-format", "concise", *args],
                          capture_output=True, text=True, cwd=REPO, timeout=300)


def test_pyflakes_clean():
    proc = _check(*FOLDERS)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_lint_rules_match_pyproject():
    text = (REPO / "pyproject.toml").read_text(encoding="utf-8")
    assert '[tool.ruff.lint]\nselect = ["F"]' in text
    assert '"ruff>=' in text
