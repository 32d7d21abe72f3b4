"""The test tiers and shared pieces of ``tests/conftest.py``, run on a small
suite of their own (pytester), and the README's test commands as CI runs them."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

HERE = Path(__file__).resolve().parent
#: the inner runs load no plugin they do not test (hypothesis's summary alone costs seconds)
_INNER = ("-p", "no:cacheprovider", "-p", "no:hypothesispytest", "-p", "no:xdist")
REPO = HERE.parent

SUITE = """
import pytest

def test_fast():
    pass

def test_recorded_slow():
    pass

@pytest.mark.slow
def test_marked_slow():
    pass

@pytest.fixture(scope="module")
def costly():
    return 1

def test_pays_for_the_fixture(costly):
    pass

def test_shares_the_fixture(costly):
    pass

@pytest.mark.requires_tool("no-such-tool-xyz")
def test_needs_a_tool():
    pass

@pytest.mark.requires_tool("python3")
@pytest.mark.requires_tool("no-such-tool-abc")
def test_needs_two_tools():
    pass
"""


@pytest.fixture
def suite(pytester):
    pytester.makeconftest((HERE / "conftest.py").read_text(encoding="utf-8"))
    pytester.makepyfile(test_suite=SUITE)
    (pytester.path / "durations.json").write_text(json.dumps({
        "test_suite.py::test_fast": [0.0, 0.01, 0.0],
        "test_suite.py::test_recorded_slow": [0.0, 1.5, 0.0],
        "test_suite.py::test_pays_for_the_fixture": [3.0, 0.01, 0.0],
        "test_suite.py::test_shares_the_fixture": [0.0, 0.01, 0.0],
    }), encoding="utf-8")
    return pytester


def _ran(result) -> set[str]:
    """The tests of an inline run that ran (passed, failed or skipped)."""
    return {r.nodeid.split("::")[-1] for r in result.getreports("pytest_runtest_logreport")
            if r.when == "call" or r.skipped}


def test_quick_tier_leaves_out_the_measured_and_marked_slow(suite):
    result = suite.inline_run(*_INNER)
    assert _ran(result) == {"test_fast", "test_needs_a_tool", "test_needs_two_tools"}
    passed, skipped, failed = result.listoutcomes()
    assert len(passed) == 1 and len(skipped) == 2 and not failed
    deselected = {i.nodeid.split("::")[-1] for r in result.getcalls("pytest_deselected")
                  for i in r.items}
    assert deselected == {"test_recorded_slow", "test_marked_slow", "test_pays_for_the_fixture",
                          "test_shares_the_fixture"}


def test_full_runs_everything(suite):
    result = suite.inline_run(*_INNER, "--full")
    passed, skipped, failed = result.listoutcomes()
    assert len(passed) == 5 and len(skipped) == 2 and not failed


def test_marker_expression_replaces_the_tier(suite):
    result = suite.inline_run(*_INNER, "-m", "slow")
    assert _ran(result) == {"test_recorded_slow", "test_marked_slow", "test_pays_for_the_fixture",
                            "test_shares_the_fixture"}


def test_missing_tool_is_skipped_naming_it_and_its_package(suite):
    result = suite.runpytest(*_INNER, "-rs", "-k", "needs_a_tool or needs_two")
    result.stdout.fnmatch_lines(["*no-such-tool-xyz not installed (apt-get install "
                                 "no-such-tool-xyz*"])
    # stacked markers: every tool named is checked, the missing one is named
    result.stdout.fnmatch_lines(["*no-such-tool-abc not installed*"])
    assert "python3 not installed" not in result.stdout.str()


def test_store_durations_writes_every_phase(suite, tmp_path):
    out = tmp_path / "d.json"
    result = suite.inline_run(*_INNER, "--full", "--store-durations", str(out))
    assert not result.listoutcomes()[2]
    recorded = json.loads(out.read_text(encoding="utf-8"))
    assert set(recorded) == {f"test_suite.py::{n}" for n in (
        "test_fast", "test_recorded_slow", "test_marked_slow", "test_pays_for_the_fixture",
        "test_shares_the_fixture", "test_needs_a_tool", "test_needs_two_tools")}
    assert all(len(v) == 3 and all(x >= 0 for x in v) for v in recorded.values())


def test_cli_runner_captures_status_and_both_streams(tmp_path):
    from conftest import run_cli

    ok = run_cli("fit", "exp(x)", "--interval", "0", "1", "--degree", "2", "-o",
                 tmp_path / "t.json")
    assert ok.code == 0 and ok.err == "" and (tmp_path / "t.json").is_file()
    bad = run_cli(["fit", "exp(x)", "--interval", "1", "0", "--degree", "2"])
    assert bad.code == 2 and bad.out == "" and len(bad.err.splitlines()) == 1
    assert run_cli("--version").out.startswith("chebnorm ")
    code, out, err = run_cli("fit", "exp(x)", "--interval", 0, 1, "--degree", 1)  # numbers as text
    assert code == 0 and "degree 1" in out and err == ""


def test_durations_file_is_well_formed():
    recorded = json.loads((HERE / "durations.json").read_text(encoding="utf-8"))
    assert recorded and all(k.startswith("tests/test_") for k in recorded)
    assert all(len(v) == 3 and all(isinstance(x, (int, float)) and x >= 0 for x in v)
               for v in recorded.values())


def _readme_block_after(marker: str) -> str:
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    tail = readme[readme.index(marker):]
    return re.search(r"```sh\n(.*?)\n```", tail, re.S).group(1)


def test_ci_runs_the_readme_test_command_verbatim():
    command = _readme_block_after("Install with the test and docs extras")
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    assert command in ci.splitlines()
    assert "--full" in shlex.split(command) and "-n" in shlex.split(command)
    assert _readme_block_after("After a change, the quick tier") == ".venv/bin/python -m pytest -q"
