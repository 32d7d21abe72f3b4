"""The layer rule of the package docstring: a stage imports only from the
stages before it, and the library never imports paper_repro or benchmarks."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import chebnorm

ROOT = Path(chebnorm.__file__).parent
#: what each stage may import from chebnorm (besides itself)
ALLOWED = {
    "symbolic": set(),
    "approx": {"symbolic"},
    "export": {"symbolic", "approx"},
    "methods": {"symbolic", "approx"},
    "hw": {"symbolic", "approx"},
    "raster": {"symbolic", "approx", "methods"},
    "cli": {"symbolic", "approx", "export", "methods", "hw", "raster"},
}


def imported_modules(path: Path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node.module
        elif isinstance(node, ast.ImportFrom) and node.level >= 2:
            # from ..stage import x, written inside chebnorm/<stage>/
            yield "chebnorm." + (node.module or "")


@pytest.mark.parametrize("stage", sorted(ALLOWED))
def test_stage_imports_only_earlier_stages(stage):
    bad = []
    for path in sorted((ROOT / stage).rglob("*.py")):
        for name in imported_modules(path):
            parts = name.split(".")
            if parts[0] in ("paper_repro", "benchmarks"):
                bad.append(f"{path.name}: {name}")
            if parts[0] == "chebnorm" and len(parts) > 1 and parts[1] in ALLOWED:
                if parts[1] != stage and parts[1] not in ALLOWED[stage]:
                    bad.append(f"{path.name}: {name}")
    assert bad == []
