"""The one design interface of chebnorm.hw (issue 45): every registered
architecture is a :class:`~chebnorm.hw.design_base.Design` that implements it,
its ``evaluate`` is bit for bit its model on every code of a small spec and
its recomputed error stays within its certified budget, a subclass missing a
method cannot be built, and nothing in ``chebnorm.hw`` chooses behaviour by
asking a design ``hasattr`` / ``getattr`` (a source scan, shown able to fail).
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import chebnorm.hw  # noqa: F401  (registers every architecture)
from chebnorm.hw.design_base import ARCHITECTURES, Design, architecture

HW = Path(__file__).resolve().parent.parent / "src" / "chebnorm" / "hw"


def _horner():
    from chebnorm.approx import fit_target
    from chebnorm.hw.horner import design_horner

    return design_horner(fit_target("dichotomy", 1), 6, 6, coef_bits=10)


def _piecewise(sized: bool):
    from chebnorm.approx.piecewise_fit import piecewise_fit
    from chebnorm.hw.piecewise import design_piecewise

    t = piecewise_fit("1/sqrt(x)", ("1", "4"), 1, segments=4, coef_frac_bits=16, name="rs")
    if sized:
        return design_piecewise(t, 8, 8, widths="auto", max_error=2 ** -5)
    return design_piecewise(t, 8, 8)


def _exponent():
    from chebnorm.hw.exponent import design_exponent

    return design_exponent("1/sqrt(x)", ("2^-8", "1"), 8, 8, degree=1)


def _table():
    from chebnorm.hw.plain_table import design_plain_table

    return design_plain_table("1/sqrt(1+3*x)", ("0", "1"), 6, 6)


def _multipartite():
    from chebnorm.hw.multipartite import design_multipartite

    return design_multipartite("1/sqrt(1+3*x)", ("0", "1"), 8, 8)


#: a small design of each registered architecture, and the keys of its measured
#: error and of the certified bound that must hold over it
BUILD = {
    "horner": (_horner, "total", "total"),
    "piecewise": (lambda: _piecewise(False), "max_error", "total"),
    "piecewise-sized": (lambda: _piecewise(True), "max_error", "total"),
    "exponent": (_exponent, "max_error", "mantissa"),
    "table": (_table, "upper", "exhaustive"),
    "multipartite": (_multipartite, "upper", "exhaustive"),
}


@pytest.fixture(scope="module")
def designs():
    return {name: build() for name, (build, _, _) in BUILD.items()}


def test_every_registered_architecture_is_built_here():
    """A new architecture registered without a case here fails (and the names
    are the ones the CLI and the CSVs print)."""
    assert set(ARCHITECTURES) == set(BUILD)
    for name, cls in ARCHITECTURES.items():
        assert issubclass(cls, Design) and not cls.__abstractmethods__, name


@pytest.mark.parametrize("name", sorted(BUILD))
def test_architecture_implements_the_protocol(designs, name):
    from chebnorm.hw.target_model import DesignFeatures, model_score

    d = designs[name]
    assert isinstance(d, architecture(name))
    assert isinstance(d, Design)
    assert d.architecture == name   # the tag is the registered name
    assert isinstance(d.in_bits, int) and isinstance(d.out_bits, int)
    assert d.module_name == f"chebnorm_{d.name}"
    assert d.verify() is d
    f = d.features()
    assert isinstance(f, DesignFeatures) and model_score(f, "generic") > 0
    cuts = d.cut_points()
    assert isinstance(cuts, tuple) and all(isinstance(c, str) for c in cuts)
    assert bool(cuts) == (name in ("piecewise", "piecewise-sized", "multipartite", "table"))
    if cuts:   # pipelined, a design keeps its tag
        assert d.with_cuts((0,)).architecture == name
    text = d.verilog()
    assert f"module {d.module_name}" in text
    assert f"entity {d.module_name} is" in d.vhdl()
    files = d.hdl_files("verilog")
    assert f"{d.module_name}.v" in files and any(k.startswith("tb_") for k in files)


@pytest.mark.parametrize("name", sorted(BUILD))
def test_evaluate_is_the_model_on_every_code_and_within_the_budget(designs, name):
    """``evaluate`` of every code at once, of each code alone and of the
    wires' ``y`` agree; the error recomputed over every code (exact or at 40
    digits, :meth:`Design.measure`) is within the certified bound."""
    _, measured, bound = BUILD[name]
    d = designs[name]
    y = np.asarray(d.evaluate())
    codes = np.arange(2 ** d.in_bits, dtype=np.int64)
    if name == "exponent":   # codes below the interval are not in the spec
        lo, hi = d.valid_codes
        codes = codes[lo:hi + 1]
        y = y[lo:hi + 1]
    one = np.array([int(d.evaluate(np.array([k]))[0]) for k in codes], dtype=np.int64)
    assert np.array_equal(one, y)
    wires = d.evaluate(codes, intermediates=True) if name == "horner" else \
        d.evaluate(codes, wires=True)
    assert np.array_equal(np.asarray(wires["y"]), y)
    assert y.min() >= 0 and int(y.max()) < 2 ** d.out_bits
    if name == "table":
        assert np.array_equal(y, np.asarray(d.values))
    m, b = d.measure(), d.budget()
    assert float(m[measured]) <= float(b[bound]), (m, b)


def test_a_subclass_missing_a_method_cannot_be_built():
    class NoHdl(Design):   # everything but hdl_files
        name, in_bits, out_bits = "x", 1, 1
        module_name = "chebnorm_x"

        def verify(self):
            return self

        def evaluate(self, codes=None):
            return np.zeros(2, dtype=np.int64)

        def budget(self):
            return {}

        def measure(self):
            return {}

        def features(self):
            return None

        def cut_points(self):
            return ()

        def verilog(self, *, version="", command=None):
            return ""

        def vhdl(self, *, version="", command=None):
            return ""

    with pytest.raises(TypeError, match="hdl_files"):
        NoHdl()

    class Whole(NoHdl):
        def hdl_files(self, language="verilog"):
            return {}

    w = Whole()
    assert w.latency == 0 and w.cut_plans() == [] and w.combinational() is w
    with pytest.raises(ValueError, match="no pipeline cut points"):
        w.with_cuts((0,))


def test_registry_refuses_unknown_names_and_double_registration():
    from chebnorm.hw.design_base import register

    with pytest.raises(ValueError, match="accepted: exponent, horner"):
        architecture("cordic")
    with pytest.raises(ValueError, match="already"):
        @register("table")
        class Other(type(_table())):
            pass


def test_registry_refuses_a_tag_other_than_the_registered_name():
    """A design's own tag is the name it is registered (and printed) as: a class
    tagged otherwise is refused, and nothing of it is registered."""
    from chebnorm.hw.design_base import register

    with pytest.raises(ValueError, match=r"architecture is 'plain_table'; accepted: one of "
                                         r"the names it is registered as \(tablette\)"):
        @register("tablette")
        class Tagged(type(_table())):
            architecture = "plain_table"
    assert "tablette" not in ARCHITECTURES


# -- the scan: no hasattr / getattr dispatch on design kinds in chebnorm.hw ----------

#: every hasattr / getattr call left in chebnorm.hw, by file and source text, and why
#: it is not a dispatch on a design's kind
ALLOWED = {
    # iterability checks of user input (a str is refused, any iterable accepted)
    ("piecewise.py", 'hasattr(pipeline, "__iter__")'),
    ("design_api.py", 'hasattr(interval, "__iter__")'),
    ("design_api.py", 'hasattr(degrees, "__iter__")'),
    ("pipeline.py", 'hasattr(cuts, "__iter__")'),
    # a design's fields compared with its re-derivation, by dataclass field name
    ("piecewise.py", "getattr(d, f.name)"), ("piecewise.py", "getattr(ref, f.name)"),
    ("horner.py", "getattr(d, f.name)"), ("horner.py", "getattr(ref, f.name)"),
    ("design_base.py", "getattr(self, f.name)"),
    ("trust.py", "getattr(value, f.name, None)"),
    ("trust.py", "getattr(cert, name)"),
    # the digest's serialization of any value that has to_json (tables, not designs)
    ("trust.py", 'hasattr(value, "to_json")'),
    # PipelinedTable reads its base's attributes (a delegation, the same for every base)
    ("pipeline.py", "getattr(self.base, name)"),
    # chebnorm.hw.hdl.netlist: the IR's own traversal of its nodes' dataclass fields
    # (expressions, not designs)
    ("hdl/netlist.py", "getattr(node, f.name)"),
    ("hdl/netlist.py", "getattr(e, name, None)"), ("hdl/netlist.py", "getattr(e, name)"),
    ("hdl/netlist.py", 'getattr(e, "terms", ())'), ("hdl/netlist.py", 'getattr(e, "parts", ())'),
}


def attribute_probes(root: Path) -> set[tuple[str, str]]:
    """``(file relative to root, call source)`` of every ``hasattr``/``getattr`` call
    (also when called through another name: ``probe = getattr`` is a call of a name
    bound to it, and ``builtins.getattr(...)`` an attribute call)."""
    found = set()
    for path in sorted(root.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        if "hasattr" not in text and "getattr" not in text:
            continue
        lines = text.encode("utf-8").splitlines(keepends=True)
        for node in ast.walk(ast.parse(text, filename=str(path))):
            if not isinstance(node, ast.Call):
                continue
            f = node.func
            name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) \
                else ""
            if name not in ("hasattr", "getattr"):
                continue
            first, last = node.lineno - 1, node.end_lineno - 1
            seg = b"".join(lines[first:last + 1])
            seg = seg[node.col_offset:len(seg) - len(lines[last]) + node.end_col_offset]
            found.add((path.relative_to(root).as_posix(), " ".join(seg.decode().split())))
    return found


@pytest.fixture(scope="module")
def probes():
    return attribute_probes(HW)


def test_no_attribute_probe_dispatch_in_hw(probes):
    assert probes <= ALLOWED, sorted(probes - ALLOWED)


def test_no_dispatch_left_in_the_search_pipeline_and_reports(probes):
    """The modules that choose among designs probe no attribute at all, but
    to check user input's iterability."""
    for rel, src in probes:
        if rel in ("architectures.py", "report.py", "target_model.py", "synth_loop.py",
                   "piecewise_search.py", "exponent.py", "multipartite.py", "plain_table.py"):
            pytest.fail(f"{rel}: {src}")


def test_the_scan_catches_a_dispatch(tmp_path):
    """A copy of hw with the old dispatch put back: the scan reports it."""
    import shutil

    copy = tmp_path / "hw"
    shutil.copytree(HW, copy, ignore=shutil.ignore_patterns("__pycache__"))
    p = copy / "architectures.py"
    p.write_text(p.read_text(encoding="utf-8") + "\n\ndef _v(d):\n    return d.verilog() "
                 "if hasattr(d, \"verilog\") else None\n", encoding="utf-8")
    q = copy / "pipeline.py"
    q.write_text(q.read_text(encoding="utf-8") + "\n\ndef _s(d):\n    return builtins.getattr(\n"
                 "        d, \"sized\", False)\n", encoding="utf-8")
    assert attribute_probes(copy) - ALLOWED == {("architectures.py", 'hasattr(d, "verilog")'),
                                                ("pipeline.py", 'builtins.getattr( d, "sized", False)')}


# -- the one pruned synthesis loop -----------------------------------------------------

def _queue(lowers):
    from chebnorm.hw.synth_loop import SynthJob

    return [SynthJob((low, i), low, f"j{i}") for i, low in enumerate(lowers)]


def _run(jobs, true, **kw):
    from chebnorm.hw.synth_loop import pruned_synthesis

    batches = []

    def synthesize(batch):
        batches.append([j.key for j in batch])
        return [true[j.key] for j in batch]

    run = pruned_synthesis(jobs, synthesize, score=lambda j, c: c, **kw)
    return run, batches


def test_pruned_synthesis_rounds_prune_and_join():
    from chebnorm.hw.synth_loop import SYNTH_ROUND, SynthJob

    assert SYNTH_ROUND == 2
    jobs = _queue([3.0, 1.0, 2.0, 5.0, 4.0])   # queue order j1, j2, j0, j4, j3
    true = {"j0": 3.5, "j1": 2.5, "j2": 4.0, "j3": 4.5, "j4": 5.5}
    run, batches = _run(jobs, true)
    # round one: the two lowest bounds; then nothing left can beat 2.5
    assert batches == [["j1", "j2"]] and run.best == 2.5
    assert [j.key for j in run.skipped] == ["j0", "j4", "j3"]
    assert all(j.lower >= run.best for j in run.skipped)
    # without pruning: everything, two at a time, in queue order
    run, batches = _run(jobs, true, prune=False)
    assert batches == [["j1", "j2"], ["j0", "j4"], ["j3"]] and not run.skipped
    # a bound from elsewhere prunes everything; `first` still runs the cheapest
    assert _run(jobs, true, bound=0.5)[1] == []
    assert _run(jobs, true, bound=0.5, first=True)[1] == [["j1"]]
    # later jobs join from round two, even when their bound is the lowest
    late = [SynthJob((0.1, 9), 0.1, "late")]
    run, batches = _run(jobs, dict(true, late=0.2), later=lambda: late)
    assert batches == [["j1", "j2"], ["late"]] and run.best == 0.2
    # no first-round job: the later ones still run
    assert _run([], {"late": 0.2}, later=lambda: late)[1] == [["late"]]


def test_every_synthesis_goes_through_the_one_loop(monkeypatch):
    """synthesize_candidates, synthesize_search and synthesize_with_search each
    run their jobs through synth_loop.pruned_synthesis (no copy of the loop)."""
    from chebnorm.hw import architectures as A
    from chebnorm.hw import piecewise_search as S
    from chebnorm.hw.synth_loop import pruned_synthesis

    seen = []

    def spy(jobs, synthesize, **kw):
        seen.append(kw.get("later") is not None)
        return pruned_synthesis(jobs, synthesize, **kw)

    monkeypatch.setattr(A, "pruned_synthesis", spy)
    monkeypatch.setattr(S, "pruned_synthesis", spy)
    monkeypatch.setattr(A, "_synth_item", lambda item: type("C", (), {"score": 1.0})())
    monkeypatch.setattr(A, "_synth_job", lambda item: type("C", (), {"score": 1.0})())

    class D:
        module_name = "m"

        def verilog(self):
            return "module m; endmodule"

    cands = [A.Candidate("table", "t", D(), 0.0, 1.0, model=5.0, model_rom=5.0)]
    assert A.synthesize_candidates(cands, "generic")[0].cost.score == 1.0
    r = S.search("1/sqrt(x)", ("1", "4"), 8, 8, 1e-2, degrees=(1,), max_index_bits=4,
                 synth=False, progress=False, workers=1, target="xc7")
    assert S.synthesize_search(r, bound=0.0).winner is not None
    out, res = A.synthesize_with_search(cands, r, "xc7", workers=1)
    assert out[0].cost.score == 1.0
    assert seen == [False, False, True]


def test_candidates_name_registered_architectures():
    """The search's candidates and the pruning's calibration use the registry's
    names, and each built candidate's design is of its architecture's class."""
    from chebnorm.hw.architectures import PRUNE_SPREAD, build_candidates

    assert {a for a, _ in PRUNE_SPREAD} <= set(ARCHITECTURES)
    cs = build_candidates("1/sqrt(1+3*x)", ("0", "1"), 6, 6, accuracy="faithful",
                          k_start={1: 2})
    assert {c.architecture for c in cs} == {"piecewise-sized", "multipartite", "table"}
    for c in cs:
        if c.design is not None:
            assert isinstance(c.design, architecture(c.architecture))
            assert c.design.architecture == c.architecture   # one tag, the CSVs' name
            assert c.verilog == c.design.verilog()
