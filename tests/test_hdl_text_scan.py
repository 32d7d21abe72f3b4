"""HDL text is printed in one place, chebnorm.hw.hdl (issue 45): a source scan
(ast) of every other module's string literals -- f-strings read whole, their
fields as a placeholder; docstrings left out -- for HDL keywords. Every other
module, the normalization units (hw/units) included, builds netlists or calls the
printers."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parent.parent / "src" / "chebnorm"

#: HDL syntax, not prose: a module header, endmodule, a clocked or combinational
#: block, an entity or architecture, a port map, a continuous assignment, a ranged wire
HDL = re.compile(r"\bendmodule\b|^\s*module\s+\w+\s*(#\(|\(\s*$|\(\s*(input|output)\b|;)|"
                 r"\balways\s*@|\bentity\s+\w+\s+is\b|\bend\s+architecture\b|\bport\s+map\b|"
                 r"^\s*assign\s+\w+(\[[^\]]*\])?\s*=|\bposedge\b|\bwire\s+(signed\s+)?\[", re.M)



def _literals(tree):
    """(line, text) of every string literal but docstrings; an f-string whole."""
    skip = set()
    for n in ast.walk(tree):
        if isinstance(n, (ast.Module, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            first = n.body[0] if n.body else None
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                skip.add(id(first.value))
        if isinstance(n, ast.JoinedStr):
            skip.update(id(v) for v in n.values)   # its parts (a field's own strings stay in)
    for n in ast.walk(tree):
        if id(n) in skip:
            continue
        if isinstance(n, ast.Constant) and isinstance(n.value, str):
            yield n.lineno, n.value
        elif isinstance(n, ast.JoinedStr):
            yield n.lineno, "".join(v.value if isinstance(v, ast.Constant) else "X"
                                    for v in n.values)


def hdl_literals(source: str) -> list[tuple[int, str]]:
    """The lines and texts of ``source``'s string literals that hold HDL."""
    return [(line, t) for line, t in _literals(ast.parse(source)) if HDL.search(t)]


def _printers() -> dict[str, list]:
    found = {}
    for p in sorted(SRC.rglob("*.py")):
        rel = p.relative_to(SRC).as_posix()
        if rel.startswith("hw/hdl/"):
            continue
        hits = hdl_literals(p.read_text(encoding="utf-8"))
        if hits:
            found[rel] = hits
    return found


def test_hdl_text_is_printed_only_in_hw_hdl():
    found = {k: v[:3] for k, v in _printers().items()}
    assert not found, f"HDL text outside chebnorm.hw.hdl: {found}"


def test_the_hdl_package_itself_is_found():
    # the scan sees HDL where it is printed (else the test above could not fail)
    hits = hdl_literals((SRC / "hw" / "hdl" / "netlist.py").read_text(encoding="utf-8"))
    assert any("endmodule" in t for _, t in hits) and any("port map" in t for _, t in hits)


@pytest.mark.parametrize("source, count", [
    ('def f(name):\n    return [f"module {name} #(", "endmodule"]\n', 2),
    ('W = "    always @(posedge clk) begin"\n', 1),
    ('def f(t):\n    return f"    assign {t} = a + b;"\n', 1),
    ('def f(n):\n    return f"entity {n} is"\n', 1),
    ('def f():\n    """Write the module (see the module docstring): endmodule."""\n', 0),
    ('H = "module name (an identifier; default: from EXPR)"\n', 0),
    ('E = "top: is not a module name; accepted: a Verilog identifier"\n', 0),
])
def test_scan_finds_hdl_and_passes_prose(source, count):
    assert len(hdl_literals(source)) == count
