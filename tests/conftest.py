"""What the tests share: the two tiers, the command-line runners and the
external-tool marker.

Tiers
-----
``python -m pytest`` runs the quick tier: every test except the slow ones.
``python -m pytest --full`` runs everything (what CI runs). A test is slow when
it carries ``@pytest.mark.slow`` or when its duration recorded in
``tests/durations.json`` is at least :data:`SLOW_SECONDS`; the file is written
by a full run with ``--store-durations`` (see ``docs/contributing.md``), so the
tiers follow measured times, not guesses. Selecting with ``-m`` (``-m slow``,
``-m "not slow"``) replaces the default tier choice.

Runners
-------
``cli`` (a fixture) runs ``chebnorm.cli.main`` in this process and returns its
exit status, stdout and stderr; ``run_process`` starts ``python -m chebnorm``
for the tests where the process is the point (signals, the console script,
environment variables, warnings that reach stderr, Ctrl-C).

External tools
--------------
``@pytest.mark.requires_tool("yosys", "iverilog")`` skips a test, with one
reason naming the tool and its Debian package, when a tool is not on PATH.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
#: per-test durations of the last full run: node id -> [setup, call, teardown] seconds
DURATIONS = HERE / "durations.json"
#: a test whose recorded duration reaches this belongs to the full suite only
SLOW_SECONDS = 1.0

#: the Debian package of each external tool the tests use (what .ci/run installs)
TOOL_PACKAGES = {
    "gcc": "gcc", "clang": "clang", "cc": "gcc", "sollya": "sollya", "gappa": "gappa",
    "iverilog": "iverilog", "vvp": "iverilog", "yosys": "yosys", "ghdl": "ghdl",
    "glslangValidator": "glslang-tools", "nextpnr-ice40": "nextpnr-ice40",
    "icepack": "fpga-icestorm", "icetime": "fpga-icestorm", "objdump": "binutils",
}


def tool_missing(*tools: str) -> str | None:
    """The skip reason when one of ``tools`` is not on PATH, else None."""
    missing = [t for t in tools if shutil.which(t) is None]
    if not missing:
        return None
    packages = sorted({TOOL_PACKAGES.get(t, t) for t in missing})
    return (f"{', '.join(missing)} not installed (apt-get install {' '.join(packages)}; "
            f".ci/run installs it)")


def requires_tool(*tools: str):
    """``pytest.mark.requires_tool(*tools)``, for module-level ``pytestmark`` lists."""
    return pytest.mark.requires_tool(*tools)


def pytest_addoption(parser):
    group = parser.getgroup("chebnorm")
    group.addoption("--full", action="store_true",
                    help="run the whole suite, slow tests included (what CI runs)")
    group.addoption("--store-durations", metavar="PATH", default=None,
                    help="write every test's measured duration to PATH (JSON); a full run "
                         "with PATH = tests/durations.json refreshes the tiers")


def pytest_configure(config):
    path = config.getoption("--store-durations")
    if path and not hasattr(config, "workerinput"):  # xdist workers report to the controller
        config.pluginmanager.register(_DurationRecorder(Path(path)), "chebnorm-durations")


class _DurationRecorder:
    """Adds up each test's setup, call and teardown times and writes them at the end."""

    def __init__(self, path: Path):
        self.path = path
        self.durations: dict[str, list[float]] = {}

    def pytest_runtest_logreport(self, report):
        phases = self.durations.setdefault(report.nodeid, [0.0, 0.0, 0.0])
        phases[("setup", "call", "teardown").index(report.when)] += report.duration

    def pytest_sessionfinish(self, session, exitstatus):
        rows = [f"{json.dumps(k)}: [{', '.join(f'{v:.3f}' for v in phases)}]"
                for k, phases in sorted(self.durations.items())]
        self.path.write_text("{\n" + ",\n".join(rows) + "\n}\n", encoding="utf-8")


def _recorded() -> dict[str, list[float]]:
    try:
        return json.loads(DURATIONS.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return {}


def _shared_fixtures(item) -> set[str]:
    """The fixtures of ``item`` made once for many tests (module, class or session scope)."""
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return set()
    return {name for name, defs in info.name2fixturedefs.items()
            if defs and defs[-1].scope != "function"}


def _measured_slow(items, recorded) -> list:
    """The tests the recorded durations put in the full suite: a test that took
    :data:`SLOW_SECONDS` or more, and with a test whose set-up took that long (an
    expensive shared fixture), every test of its file sharing that fixture, since
    whichever of them runs first pays for it."""
    slow, costly = [], {}
    for item in items:
        phases = recorded.get(item.nodeid)
        if phases is None:
            continue
        if sum(phases) >= SLOW_SECONDS:
            slow.append(item)
        if phases[0] >= SLOW_SECONDS:
            costly.setdefault(item.nodeid.split("::")[0], set()).update(_shared_fixtures(item))
    for item in items:
        shared = costly.get(item.nodeid.split("::")[0])
        if shared and shared & _shared_fixtures(item):
            slow.append(item)
    return slow


def pytest_collection_modifyitems(config, items):
    for item in items:
        tools = [t for marker in item.iter_markers("requires_tool") for t in marker.args]
        reason = tool_missing(*tools) if tools else None
        if reason is not None:
            item.add_marker(pytest.mark.skip(reason=reason))
    for item in _measured_slow(items, _recorded()):
        if item.get_closest_marker("slow") is None:
            item.add_marker(pytest.mark.slow)
    if config.getoption("--full") or config.getoption("markexpr"):
        return
    quick = [i for i in items if i.get_closest_marker("slow") is None]
    slow = [i for i in items if i.get_closest_marker("slow") is not None]
    if slow:
        config.hook.pytest_deselected(items=slow)
        items[:] = quick


@pytest.hookimpl(tryfirst=True)
def pytest_report_header(config):
    if config.getoption("--full") or config.getoption("markexpr"):
        return None
    return (f"quick tier: tests marked slow or recorded at >= {SLOW_SECONDS:g} s in "
            f"{DURATIONS.name} are deselected; --full runs them")


# --- resources one test at a time may use ------------------------------------------------

@contextlib.contextmanager
def one_at_a_time(resource: str):
    """Hold the machine-wide lock of ``resource`` (a file lock every xdist worker and
    every other test run on the machine shares) while the block runs. Jupyter
    kernels need it: a client picks a kernel's free ports before the kernel binds
    them, so two kernels started at once (the notebooks test on one worker, the
    docs build's notebook execution on another) can take the same ports, and the
    client of one then waits forever on the other's."""
    import fcntl
    import tempfile

    path = Path(tempfile.gettempdir()) / f"chebnorm-tests-{resource}.lock"
    with open(path, "a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


# --- running the command line -------------------------------------------------------------

@dataclass
class CliResult:
    """What one run of the command line gave: exit status, stdout, stderr."""

    code: int
    out: str
    err: str

    def __iter__(self):
        """``code, out, err = run_cli(...)``."""
        return iter((self.code, self.out, self.err))


def _args(argv) -> list[str]:
    """Command-line words: one list, or the words themselves; paths and numbers as text."""
    words = argv[0] if len(argv) == 1 and isinstance(argv[0], (list, tuple)) else argv
    return [os.fspath(a) if isinstance(a, (str, os.PathLike)) else str(a) for a in words]


def run_cli(*argv, cwd=None) -> CliResult:
    """Run ``chebnorm ARGV`` in this process (``chebnorm.cli.main``), in ``cwd``
    when given, and capture its exit status and output."""
    from chebnorm.cli import main

    out, err = io.StringIO(), io.StringIO()
    args = _args(argv)
    with contextlib.ExitStack() as stack:
        if cwd is not None:
            stack.enter_context(contextlib.chdir(cwd))
        stack.enter_context(contextlib.redirect_stdout(out))
        stack.enter_context(contextlib.redirect_stderr(err))
        try:
            code = main(args)
        except SystemExit as exc:  # argparse's --help and --version; Python's own codes
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return CliResult(int(code), out.getvalue(), err.getvalue())


@pytest.fixture
def cli():
    """:func:`run_cli`: ``cli("fit", "exp(x)", ...)`` -> :class:`CliResult`."""
    return run_cli


def run_process(*argv, cwd=None, env=None, timeout=600, input=None) -> subprocess.CompletedProcess:
    """``python -m chebnorm ARGV`` as a child process (text output), for the tests
    where the process itself is the point."""
    args = _args(argv)
    return subprocess.run([sys.executable, "-m", "chebnorm", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout, input=input)
