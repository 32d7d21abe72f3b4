"""Every command and Python block the README and the manual show is run by a test.

Each fenced block of README.md and docs/*.md that holds a command or Python is
either run here (Python blocks page by page in one namespace, as a reader types
them; chebnorm command blocks in a fresh folder, in-process) or named in
:data:`ELSEWHERE` with the test that runs it. A new block that is neither fails
:func:`test_every_block_is_run`.

A Python line ``expr   # LITERAL ...`` whose comment starts with a Python literal
(``2.158e-05``, ``(44615, -7787, 932)``, ``'shifted'``) is checked: the value of
``expr`` equals it (numbers to the digits shown)."""

from __future__ import annotations

import ast
import math
import re
import shlex
from pathlib import Path

import pytest

from conftest import run_cli

ROOT = Path(__file__).resolve().parent.parent
PAGES = ["README.md"] + sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").glob("*.md"))

#: blocks run by other tests (the first line of the block -> the test that runs it)
ELSEWHERE = {
    "python3 -m venv .venv && .venv/bin/pip install -q -e . && .venv/bin/chebnorm repro":
        ".ci/run and tests/test_repro.py (chebnorm repro)",
    'python3 -m venv --clear .venv && .venv/bin/pip install -q -e ".[test,docs]" && '
    '.venv/bin/python -m pytest -q --full -n auto --dist loadfile':
        ".ci/run, verbatim (tests/test_tiers.py::test_ci_runs_the_readme_test_command_verbatim)",
    ".venv/bin/python -m pytest -q": "tests/test_tiers.py (the quick tier)",
    ".venv/bin/python -m sphinx -W -n -b html docs docs/_build/html": "tests/test_docs.py",
    '$ chebnorm fit "1/sqrt(2+z)" --var z --interval "sqrt(2)" 2 --degree 2':
        "tests/test_readme_figures.py::test_first_fit_console_block_is_verbatim",
    'chebnorm fit "1/sqrt(x)" --interval 1 4 --degree 5 --kind minimax --name rsqrt -o rsqrt.json':
        "tests/test_readme_figures.py::test_fit_to_compiled_evaluator_example",
    'chebnorm fit "1/sqrt(x)" --interval 1 4 --degree 2 --segments 2^8 --kind minimax '
    '--coef-frac-bits 24 --name rsqrt -o rsqrt.json':
        "tests/test_readme_figures.py::test_worked_hardware_example",
    "python3 -m venv .venv": "tests/test_install.py (the non-editable and editable installs)",
    '.venv/bin/pip install -e ".[docs]"': "tests/test_docs.py (the site build)",
    "python -m pytest -q --full -n auto --dist loadfile --store-durations tests/durations.json":
        "tests/test_tiers.py (--store-durations, on a suite of its own)",
}

#: Python blocks that only illustrate (one import, no value)
TRIVIAL = {"import chebnorm as cn"}


def _fences(text: str):
    """``(info, body)`` of each fenced block of a Markdown text, read line by line
    (an opening fence, then everything up to the next bare closing fence)."""
    info, body = None, []
    for line in text.splitlines():
        if info is None:
            m = re.match(r"^```+\s*(\S*)", line)
            if m:
                info, body = m.group(1), []
        elif re.match(r"^```+\s*$", line):
            yield info, "\n".join(body) + "\n"
            info = None
        else:
            body.append(line)


def _blocks():
    for page in PAGES:
        text = (ROOT / page).read_text(encoding="utf-8")
        for lang, body in _fences(text):
            if lang == "python":
                yield page, "python", body
            elif lang in ("", "sh", "console", "shell", "bash") and re.search(
                    r"^(\$ )?(chebnorm|python3?|\.venv/\S+|gcc|cc|pip)\s", body, re.M):
                yield page, "commands", body


def _first(body: str) -> str:
    return body.strip().splitlines()[0].split("  #")[0].rstrip()


def test_every_block_is_run():
    unrun = []
    for page, kind, body in _blocks():
        if kind == "python" or _first(body) in ELSEWHERE:
            continue
        if all(line.startswith("chebnorm ") for line in _commands(body)):
            continue   # run by test_command_blocks
        unrun.append(f"{page}: {_first(body)}")
    assert not unrun, unrun


def _commands(body: str) -> list[str]:
    return [line.split("  #")[0].strip() for line in body.splitlines()
            if line.strip() and not line.lstrip().startswith("#")]


COMMAND_BLOCKS = [(page, body) for page, kind, body in _blocks()
                  if kind == "commands" and _first(body) not in ELSEWHERE]


@pytest.mark.parametrize("page, body", COMMAND_BLOCKS,
                         ids=[f"{p}:{_first(b)[:40]}" for p, b in COMMAND_BLOCKS])
def test_command_blocks(page, body, tmp_path):
    (tmp_path / "figures").symlink_to(ROOT / "figures")   # commands may read committed files
    for command in _commands(body):
        argv = shlex.split(command)
        assert argv[0] == "chebnorm", command
        r = run_cli(*argv[1:], cwd=tmp_path)
        assert r.code == 0, f"{page}: {command}: {r.err}"


def _literal(comment: str):
    """The Python literal a comment starts with, or None."""
    text = comment.strip()
    for end in range(len(text), 0, -1):
        if end < len(text) and text[end] not in " :,;(" and text[end - 1] not in ")]}'\"":
            continue
        try:
            value = ast.literal_eval(text[:end].rstrip(" :,;"))
        except (ValueError, SyntaxError, MemoryError, RecursionError):
            continue
        return value, text[:end].rstrip(" :,;")
    return None


def _same(got, want, shown: str) -> bool:
    if isinstance(want, float):
        digits = len(re.sub(r"e.*|[^0-9]", "", shown.lstrip("-0.")))
        return math.isclose(float(got), want, rel_tol=0.51 * 10 ** (1 - max(digits, 1)))
    if isinstance(want, tuple) and not isinstance(got, str):
        return tuple(got) == want
    if isinstance(want, list):
        return list(got) == want
    return got == want


PY_PAGES = sorted({page for page, kind, body in _blocks() if kind == "python"})


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::chebnorm.approx.FitWarning")
@pytest.mark.parametrize("page", PY_PAGES)
def test_python_blocks(page, tmp_path, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    names: dict = {}
    checked = 0
    blocks = [body for p, kind, body in _blocks() if p == page and kind == "python"]
    for body in blocks:
        if body.strip() in TRIVIAL:
            exec("import chebnorm as cn", names)
            continue
        tree = ast.parse(body)
        lines = body.splitlines()
        for node in tree.body:
            src = ast.get_source_segment(body, node)
            comment = lines[node.end_lineno - 1].partition("#")[2] if "#" in lines[
                node.end_lineno - 1] else ""
            if isinstance(node, ast.Expr):
                value = eval(compile(ast.Expression(node.value), page, "eval"), names)
                lit = _literal(comment) if comment else None
                if lit is not None:
                    want, shown = lit
                    assert _same(value, want, shown), f"{page}: {src} is {value!r}, says {shown}"
                    checked += 1
            else:
                exec(compile(ast.Module([node], []), page, "exec"), names)
    assert blocks and (checked > 0 or page == "docs/index.md" and names.get("t") is not None)


def test_literal_reader():
    assert _literal(" 2.158e-05: sup|p - f| <= this") == (2.158e-05, "2.158e-05")
    assert _literal(" (44615, -7787, 932)") == ((44615, -7787, 932), "(44615, -7787, 932)")
    assert _literal(" 'shifted': the float32 evaluator") == ("shifted", "'shifted'")
    assert _literal(" ascending powers of z: (0.68, ...)") is None
    assert _same(2.15816e-05, 2.158e-05, "2.158e-05") and not _same(2.2e-05, 2.158e-05, "2.158e-05")
