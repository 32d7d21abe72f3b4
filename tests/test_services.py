"""Shared services, one home each (issue 45).

* External tools: :mod:`chebnorm.core.tools` is the only module that looks a
  tool up (``shutil.which``) or starts a process (``subprocess``); a missing
  tool is one :class:`~chebnorm.exceptions.ToolMissing`, a failed one one
  :class:`~chebnorm.exceptions.ToolFailed`, each a one-line message.
* Exceptions and warnings: every public class deriving from ``BaseException``
  is defined in :mod:`chebnorm.exceptions`; the old import paths give the same
  class objects.
* Arb precision: ``flint.ctx.prec`` is set only by
  :func:`chebnorm.core.numeric.arb_precision`.

The source scans read ``src/chebnorm`` with ``ast`` (strings and comments do
not count); ``TestScansCatch`` shows each scan reports the form it forbids.
"""

from __future__ import annotations

import ast
import builtins
import functools
import importlib
import stat
import sys
import warnings
from pathlib import Path

import pytest
from flint import ctx

import chebnorm
from chebnorm import exceptions
from chebnorm.core import tools

SRC = Path(__file__).resolve().parent.parent / "src" / "chebnorm"
TOOLS = "core/tools.py"
EXCEPTIONS = "exceptions.py"


@functools.lru_cache(maxsize=1)
def _tree_sources() -> tuple[tuple[str, str], ...]:
    return tuple((p.relative_to(SRC).as_posix(), p.read_text(encoding="utf-8"))
                 for p in sorted(SRC.rglob("*.py")))


def _sources() -> dict[str, str]:
    """Path relative to ``src/chebnorm`` -> text of every module (read once)."""
    return dict(_tree_sources())


@functools.lru_cache(maxsize=None)
def _parse(text: str, rel: str) -> ast.Module:
    """The syntax tree of a module (parsed once for the three scans)."""
    return ast.parse(text, filename=rel)


# --- the scans ---------------------------------------------------------------------------------

def process_uses(rel: str, text: str) -> list[str]:
    """Every use of ``subprocess`` or of ``shutil.which`` in one module's source
    (imports, attribute reads, names imported from them), as ``rel:line: what``;
    ``exceptions.py`` may import subprocess for ``subprocess.TimeoutExpired``
    (ToolTimeout's base class) and use nothing else of it."""
    found = []
    bound: dict[str, str] = {}  # local name -> "subprocess", "shutil" or "shutil.which"
    for node in ast.walk(_parse(text, rel)):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name in ("subprocess", "shutil"):
                    bound[a.asname or a.name] = a.name
                    if a.name == "subprocess" and rel != EXCEPTIONS:
                        found.append(f"{rel}:{node.lineno}: import subprocess")
        elif isinstance(node, ast.ImportFrom) and node.module in ("subprocess", "shutil"):
            for a in node.names:
                if node.module == "subprocess":
                    found.append(f"{rel}:{node.lineno}: from subprocess import {a.name}")
                elif a.name in ("which", "*"):
                    found.append(f"{rel}:{node.lineno}: from shutil import {a.name}")
        elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant) \
                and node.args[0].value in ("subprocess", "shutil"):
            func = node.func.id if isinstance(node.func, ast.Name) else \
                node.func.attr if isinstance(node.func, ast.Attribute) else ""
            if func in ("__import__", "import_module"):
                found.append(f"{rel}:{node.lineno}: {func}({node.args[0].value!r})")
    for node in ast.walk(_parse(text, rel)):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
            module = bound.get(node.value.id)
            if module == "shutil" and node.attr == "which":
                found.append(f"{rel}:{node.lineno}: shutil.which")
            elif module == "subprocess" and not (rel == EXCEPTIONS and node.attr == "TimeoutExpired"):
                found.append(f"{rel}:{node.lineno}: subprocess.{node.attr}")
    return sorted(set(found))


def _exception_bases() -> set[str]:
    """The names of the standard library's exception and warning classes."""
    import subprocess
    names = {n for n, v in vars(builtins).items() if isinstance(v, type) and issubclass(v, BaseException)}
    return names | {n for n, v in vars(subprocess).items()
                    if isinstance(v, type) and issubclass(v, BaseException)}


def exception_classes(sources: dict[str, str]) -> list[tuple[str, int, str]]:
    """``(module, line, class name)`` of every class in ``sources`` deriving,
    directly or through other classes of ``sources``, from an exception or
    warning class (a base is matched by its last name: ``subprocess.TimeoutExpired``
    is ``TimeoutExpired``)."""
    classes = []
    for rel, text in sources.items():
        for node in ast.walk(_parse(text, rel)):
            if isinstance(node, ast.ClassDef):
                bases = [b.attr if isinstance(b, ast.Attribute) else b.id if isinstance(b, ast.Name)
                         else "" for b in node.bases]
                classes.append((rel, node.lineno, node.name, bases))
    known = _exception_bases()
    while True:  # to the fixed point: a class deriving from one of ours is one too
        more = {name for _, _, name, bases in classes if name not in known and set(bases) & known}
        if not more:
            break
        known |= more
    return sorted((rel, line, name) for rel, line, name, bases in classes if set(bases) & known)


def public_exceptions_outside(sources: dict[str, str]) -> list[str]:
    return [f"{rel}:{line}: {name}" for rel, line, name in exception_classes(sources)
            if rel != EXCEPTIONS and not name.startswith("_")]


def prec_assignments(rel: str, text: str) -> list[str]:
    """Every assignment to ``<something>.prec`` (``ctx.prec = ...``, ``ctx.prec += ...``,
    ``a, ctx.prec = ...``) outside ``arb_precision``, except of a :mod:`decimal`
    context inside its own ``with decimal.localcontext() as name:`` block."""
    found = []

    def targets(node):
        if isinstance(node, (ast.Tuple, ast.List)):
            for elt in node.elts:
                yield from targets(elt)
        else:
            yield node

    def visit(node, func, exempt):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            func = node.name
        if isinstance(node, ast.With):
            exempt = exempt | {item.optional_vars.id for item in node.items
                               if isinstance(item.optional_vars, ast.Name)
                               and "localcontext" in ast.dump(item.context_expr)}
        if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
            for tgt in node.targets if isinstance(node, ast.Assign) else [node.target]:
                for t in targets(tgt):
                    if isinstance(t, ast.Attribute) and t.attr == "prec" and not (
                            isinstance(t.value, ast.Name) and t.value.id in exempt) \
                            and not (rel == "core/numeric.py" and func == "arb_precision"):
                        found.append(f"{rel}:{node.lineno}: {ast.unparse(t)} =")
        for child in ast.iter_child_nodes(node):
            visit(child, func, exempt)

    visit(_parse(text, rel), None, frozenset())
    return found


# --- the real tree ------------------------------------------------------------------------------

def test_only_core_tools_finds_and_runs_tools():
    bad = [u for rel, text in _sources().items() if rel != TOOLS for u in process_uses(rel, text)]
    assert bad == []
    # ... and core.tools itself is seen using both (the scan reads what it must)
    uses = process_uses(TOOLS, (SRC / TOOLS).read_text(encoding="utf-8"))
    assert any("shutil.which" in u for u in uses) and any("subprocess.run" in u for u in uses)


def test_every_public_exception_class_lives_in_chebnorm_exceptions():
    sources = _sources()
    assert public_exceptions_outside(sources) == []
    defined = {name for rel, _, name in exception_classes(sources) if rel == EXCEPTIONS}
    assert defined == set(exceptions.__all__)
    for name in exceptions.__all__:
        cls = getattr(exceptions, name)
        assert issubclass(cls, BaseException) and cls.__module__ == "chebnorm.exceptions", name


#: the import paths these classes had before chebnorm.exceptions (they keep working)
OLD_PATHS = [
    ("chebnorm.approx", "FitWarning"),
    ("chebnorm.approx.api", "FitWarning"),
    ("chebnorm", "FitWarning"),
    ("chebnorm.approx.expr", "UndefinedError"),
    ("chebnorm.approx.certify_batch", "SegmentError"),
    ("chebnorm.export.gpu", "ToolMissing"),
    ("chebnorm.raster.engines.base", "FrameUnsupported"),
    ("chebnorm.cli", "UsageError"),
    ("chebnorm.hw.pipeline", "FrequencyWarning"),
    ("chebnorm.hw", "FrequencyWarning"),
    ("chebnorm.core.deprecation", "ChebnormDeprecationWarning"),
    ("chebnorm", "ChebnormDeprecationWarning"),
    ("chebnorm.core.files", "WriteError"),
    ("chebnorm.core.tools", "ToolTimeout"),
    ("chebnorm.core.tools", "ToolMissing"),
    ("chebnorm.core.tools", "ToolFailed"),
]


@pytest.mark.parametrize("module, name", OLD_PATHS, ids=[f"{m}.{n}" for m, n in OLD_PATHS])
def test_old_import_paths_give_the_same_class(module, name):
    assert getattr(importlib.import_module(module), name) is getattr(exceptions, name)


def test_numba_warning_old_path():
    jit = importlib.import_module("chebnorm.raster.engines.numba.jit")
    assert jit.NumbaCompileWarning is exceptions.NumbaCompileWarning


def test_exceptions_imports_nothing_of_chebnorm():
    tree = ast.parse((SRC / EXCEPTIONS).read_text(encoding="utf-8"))
    imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    imported |= {n.module or "." for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    assert imported == {"__future__", "subprocess"}


def test_arb_precision_is_the_only_setter_of_ctx_prec():
    bad = [a for rel, text in _sources().items() for a in prec_assignments(rel, text)]
    assert bad == []


# --- the tool services --------------------------------------------------------------------------

@pytest.fixture
def bin_dir(tmp_path, monkeypatch):
    """A PATH holding only a folder of fake tools (``make(name, script)``)."""
    folder = tmp_path / "bin"
    folder.mkdir()
    monkeypatch.setenv("PATH", str(folder))

    def make(name: str, body: str) -> Path:
        path = folder / name
        path.write_text(f"#!{sys.executable}\n{body}\n", encoding="utf-8")
        path.chmod(path.stat().st_mode | stat.S_IXUSR)
        return path
    return make


def test_which_and_require_find_a_tool(bin_dir):
    path = bin_dir("fake-tool-45", "print('hello')")
    assert tools.which("fake-tool-45") == str(path)
    assert tools.require("fake-tool-45", "a test") == str(path)
    assert tools.which("gcc") is None  # PATH is the fake folder only


@pytest.mark.parametrize("name, package", [("gcc", "gcc"), ("vvp", "iverilog"),
                                           ("glslangValidator", "glslang-tools"),
                                           ("nextpnr-ice40", "nextpnr-ice40")])
def test_require_names_the_tool_and_its_package(bin_dir, name, package):
    with pytest.raises(exceptions.ToolMissing) as info:
        tools.require(name, "the\nsimulation")
    text = str(info.value)
    assert "\n" not in text
    assert text == (f"{name} is not installed (needed for the simulation); accepted: install it "
                    f"(apt-get install {package})")
    # the command line's policy: a ValueError (one line, exit status 2); still a RuntimeError
    assert isinstance(info.value, ValueError) and isinstance(info.value, RuntimeError)


@pytest.mark.parametrize("bad", ["", "/usr/bin/gcc", "a\\b", None, 3])
def test_which_refuses_a_path_or_a_non_name(bad):
    with pytest.raises(ValueError, match=r"^name = .* is not a tool name; accepted: "):
        tools.which(bad)


def test_tool_failed_is_one_line_with_the_tail_of_stderr(bin_dir):
    exe = bin_dir("failing-tool-45", "import sys\n"
                  "sys.stderr.write('x' * 1000 + '\\nfirst line\\n  error: the last line\\n')\n"
                  "sys.exit(3)")
    assert tools.run_tool([str(exe)], tool="failing", timeout=60).returncode == 3  # no check
    with pytest.raises(exceptions.ToolFailed) as info:
        tools.run_tool([str(exe)], tool="failing", timeout=60, check=True)
    text = str(info.value)
    assert "\n" not in text
    assert text.startswith("failing failed (exit status 3): ")
    assert text.endswith("first line error: the last line")
    assert len(text) <= len("failing failed (exit status 3): ") + exceptions.ToolFailed.TAIL
    assert info.value.returncode == 3 and info.value.tool == "failing"
    assert isinstance(info.value, ValueError) and isinstance(info.value, RuntimeError)


def test_a_failing_hardware_tool_is_one_tool_failed(bin_dir, tmp_path):
    """yosys exiting with an error (a fake one on PATH): one ToolFailed line naming the
    tool, the module, the status and the end of what it printed."""
    from chebnorm.hw.run_verilog import synthesize

    bin_dir("yosys", "import sys\nprint('-- Parsing --')\n"
            "sys.stderr.write('ERROR: syntax error, unexpected end of file\\n')\nsys.exit(1)")
    v = tmp_path / "m.v"
    v.write_text("module m(\n", encoding="utf-8")
    with pytest.raises(exceptions.ToolFailed) as info:
        synthesize(v, "m")
    text = str(info.value)
    assert "\n" not in text and isinstance(info.value, ValueError)
    assert text == ("yosys failed on m (exit status 1): -- Parsing -- "
                    "ERROR: syntax error, unexpected end of file")


def test_tool_failed_without_stderr():
    assert str(exceptions.ToolFailed("yosys", 1, "")) == "yosys failed (exit status 1)"
    assert str(exceptions.ToolFailed("yosys", -9, None)) == "yosys failed (exit status -9)"
    assert str(exceptions.ToolFailed("ghdl -a", 1, " \n", subject="e")) == \
        "ghdl -a failed on e (exit status 1)"


def test_a_missing_tool_is_one_tool_missing_at_every_call_site(bin_dir):
    """The hardware steps, the shader check and the Sollya cross-check all report a
    missing tool as ToolMissing (it was a ValueError, a RuntimeError or a private
    skip before), naming the tool."""
    from chebnorm.approx import sollya
    from chebnorm.export.gpu import glslang_validate
    from chebnorm.hw.targets import synthesize_target
    from chebnorm.hw.run_verilog import simulate, synthesize
    from chebnorm.hw.run_vhdl import simulate_vhdl

    calls = [
        ("iverilog", lambda: simulate(".", "m")),
        ("yosys", lambda: synthesize("design.v", "m")),
        ("ghdl", lambda: simulate_vhdl(".", "m")),
        ("glslangValidator", lambda: glslang_validate("void main() {}", "glsl")),
        ("sollya", lambda: sollya.supnorm("exp(x)", "x", [1.0, 1.0], "0", "1")),
        ("yosys", lambda: synthesize_target("module m; endmodule", "m", "ice40")),
    ]
    for tool, call in calls:
        with pytest.raises(exceptions.ToolMissing, match=f"^{tool} is not installed "):
            call()
    assert not sollya.available()


def test_the_c_check_skips_without_gcc(bin_dir):
    """Without gcc the C variants are skipped with the one message (a ToolMissing
    caught), and c_evaluate raises it (a RuntimeError, as before)."""
    from chebnorm.approx import fit
    from chebnorm.export import c_header
    from chebnorm.export.verify import c_evaluate, verify

    t = fit("1/x", ("1", "2"), 2, name="inv")
    with pytest.raises(exceptions.ToolMissing, match="^gcc is not installed .*apt-get install gcc"):
        c_evaluate(c_header(t), "chebnorm_inv_f", [1.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        report = verify(t, "c")
    c = [v for v in report.variants if v.format == "c"]
    assert c and all(v.skipped and v.skipped.startswith("gcc is not installed") for v in c)


def test_a_missing_tool_on_the_command_line_is_one_line(bin_dir, cli, tmp_path):
    """``chebnorm hw verilog --simulate`` without iverilog: exit status 2 and one
    line naming the tool and its package (no traceback)."""
    from chebnorm.approx import fit

    table = tmp_path / "t.json"
    fit("1/sqrt(x)", ("1", "2"), 2, name="t").save(table)
    out = tmp_path / "out"
    out.mkdir()
    code, _, err = cli("hw", "verilog", str(table), "--in-bits", "10", "--out-bits", "10",
                       "--coef-frac-bits", "12", "-o", str(out), "--simulate")
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("chebnorm: error: iverilog is not installed") and \
        "apt-get install iverilog" in err, err


def test_arb_precision_is_restored_by_the_converted_sites():
    """The sites that set the precision by hand now use arb_precision: the
    caller's precision is the same afterwards, also when they fail."""
    from chebnorm.approx.certify_batch import certify_batch
    from chebnorm.approx.expr import parse_function
    from chebnorm.approx.fitting import _solve

    import mpmath
    before = ctx.prec
    try:
        ctx.prec = 77
        c, = certify_batch(parse_function("exp(x)"), [0], [1], [[1.0, 1.0, 0.5]], (-0.5, 0.5))
        assert ctx.prec == 77 and c.bound > 0
        x = _solve([[mpmath.mpf(2), mpmath.mpf(0)], [mpmath.mpf(0), mpmath.mpf(4)]],
                   [mpmath.mpf(1), mpmath.mpf(1)], 30)
        assert ctx.prec == 77 and x == [mpmath.mpf(0.5), mpmath.mpf(0.25)]
        with pytest.raises(ValueError):
            certify_batch(parse_function("exp(x)"), [0], [1], [[1.0, float("nan")]], (-0.5, 0.5))
        assert ctx.prec == 77
    finally:
        ctx.prec = before


# --- the scans can fail ---------------------------------------------------------------------------

class TestScansCatch:
    @pytest.mark.parametrize("text, shown", [
        ("import subprocess\n", "import subprocess"),
        ("import subprocess as sp\nsp.run(['x'])\n", "subprocess.run"),
        ("from subprocess import run\n", "from subprocess import run"),
        ("from subprocess import TimeoutExpired\n", "from subprocess import TimeoutExpired"),
        ("import shutil\nshutil.which('gcc')\n", "shutil.which"),
        ("import shutil as s\ndef f():\n    return s.which('gcc')\n", "shutil.which"),
        ("from shutil import which\n", "from shutil import which"),
        ("import importlib\nimportlib.import_module('subprocess')\n", "import_module('subprocess')"),
    ])
    def test_a_process_use_outside_core_tools(self, text, shown):
        found = process_uses("hw/x.py", text)
        assert found and any(shown in f for f in found), found

    def test_allowed_uses(self):
        assert process_uses("hw/x.py", "import shutil\nshutil.rmtree('x')\n") == []
        assert process_uses("hw/x.py", "x = 'subprocess.run and shutil.which in a string'\n") == []
        ok = "import subprocess\nclass T(subprocess.TimeoutExpired): pass\n"
        assert process_uses(EXCEPTIONS, ok) == []
        assert process_uses(EXCEPTIONS, ok + "subprocess.run(['x'])\n") != []
        assert process_uses(EXCEPTIONS, "from subprocess import TimeoutExpired\n") != []

    @pytest.mark.parametrize("text, name", [
        ("class Oops(ValueError):\n    pass\n", "Oops"),
        ("import warnings\nclass W(warnings.UserWarning if 0 else UserWarning): pass\n", None),
        ("class _A(Exception): pass\nclass _B(_A): pass\nclass C(_B): pass\n", "C"),
        ("import subprocess\nclass T(subprocess.TimeoutExpired): pass\n", "T"),
        ("def f():\n    class Inner(RuntimeWarning): pass\n", "Inner"),
    ])
    def test_a_public_exception_outside(self, text, name):
        bad = public_exceptions_outside({"hw/x.py": text})
        if name is None:  # a computed base is not followed: no false report either
            assert bad == []
        else:
            assert bad == [f"hw/x.py:{text[:text.index('class ' + name)].count(chr(10)) + 1}: "
                           f"{name}"], bad

    def test_private_and_non_exception_classes_are_fine(self):
        text = "class _Skip(Exception): pass\nclass Table: pass\nclass Sub(Table): pass\n"
        assert public_exceptions_outside({"hw/x.py": text}) == []
        assert public_exceptions_outside({EXCEPTIONS: "class Oops(ValueError): pass\n"}) == []

    @pytest.mark.parametrize("text", [
        "from flint import ctx\nctx.prec = 128\n",
        "import flint\ndef f():\n    flint.ctx.prec = 53\n",
        "from flint import ctx\nctx.prec, ctx.cap = 1, 2\n",
        "from flint import ctx\nctx.prec += 10\n",
    ])
    def test_a_prec_assignment(self, text):
        assert prec_assignments("approx/x.py", text) != []

    def test_decimal_contexts_and_arb_precision_are_fine(self):
        text = "import decimal\nwith decimal.localcontext() as ctx:\n    ctx.prec = 400\n"
        assert prec_assignments("core/numeric.py", text) == []
        assert prec_assignments("core/numeric.py", text + "ctx.prec = 53\n") != []  # outside
        own = (SRC / "core/numeric.py").read_text(encoding="utf-8")
        assert prec_assignments("core/numeric.py", own) == []
        assert prec_assignments("approx/x.py", own.replace("def arb_precision", "def other"))


def test_the_facade_names_the_module():
    assert chebnorm.exceptions is exceptions
    assert chebnorm.FitWarning is exceptions.FitWarning


def test_arb_precision_scopes_of_two_threads_do_not_mix():
    """``flint.ctx.prec`` is one process-wide value: a thread that enters and
    leaves a precision scope while another certifies must neither change the
    other's bound nor leave its precision behind. (``chebnorm design`` fits
    the one-width search in a thread while the main thread prepares synthesis.)"""
    import threading
    import time

    from chebnorm.approx.piecewise_fit import piecewise_fit
    from chebnorm.core.numeric import arb_precision

    def bounds():
        t = piecewise_fit("1/sqrt(1+3*x)", (0, 1), 1, segments=4, coef_frac_bits=22)
        return [s.abs_error_bound for s in t.segments]

    alone = bounds()
    before = ctx.prec
    stop = threading.Event()

    def churn():  # another thread's short scopes at a much lower precision
        while not stop.is_set():
            with arb_precision(12):
                time.sleep(0.0005)

    other = threading.Thread(target=churn)
    other.start()
    try:
        beside = [bounds() for _ in range(3)]
    finally:
        stop.set()
        other.join()
    assert beside == [alone] * 3
    assert ctx.prec == before
