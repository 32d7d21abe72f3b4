"""The method registry (chebnorm.approx.method_registry): every registered method
works in every consumer, a method added through the registry alone reaches the
CLI and the renderer, and no other module keeps a method list or a method ->
target map."""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

from chebnorm.approx import fit_target, get_target
from chebnorm.approx.method_registry import (MethodSpec, TableSpec, get_method, method_names,
                                             register, registered_methods, unit_tables,
                                             unregister)
from chebnorm.cli import main
from chebnorm.methods import (count_ops, default_tables, length_error_bound, method_kernel,
                              method_kernels, span_normals)
from chebnorm.methods.kernels import SHAPES
from chebnorm.raster import available_methods, render

REPO = Path(__file__).resolve().parents[1]
BENCH = REPO / "benchmarks"
BUILTIN = ("exact", "none", "newton", "lyon", "slerp", "dichotomy", "quadratic", "angular")


def _pair(psi):
    """A generic pair of unit normals ``psi`` apart (no component zero)."""
    e1 = np.array([2.0, 3.0, 6.0]) / 7.0
    e2 = np.array([3.0, -6.0, 2.0]) / 7.0
    return e1, math.cos(psi) * e1 + math.sin(psi) * e2


# ------------------------------------------------------------ the entries
def test_builtin_methods_in_paper_order():
    assert method_names()[:8] == BUILTIN
    assert available_methods() == method_names()


@pytest.mark.parametrize("name", BUILTIN)
def test_entry_is_complete(name):
    spec = get_method(name)
    assert spec.seed.startswith("seed 00")
    assert spec.c_kernel is not None  # every built-in method has a C benchmark twin
    if spec.table is not None:
        get_target(spec.table.target)


def test_register_rejects_bad_entries():
    with pytest.raises(ValueError, match="already registered"):
        register(get_method("exact"))
    with pytest.raises(ValueError, match="unknown target"):
        register(MethodSpec("bad", "", "", "m:K", table=TableSpec("nope")))
    with pytest.raises(ValueError, match="method name"):
        register(MethodSpec("Bad Name", "", "", "m:K"))
    with pytest.raises(ValueError, match="ideal"):
        register(MethodSpec("bad", "", "", "m:K", ideal="cubic"))
    with pytest.raises(ValueError, match="built in"):
        unregister("exact")
    assert "bad" not in method_names()


# ------------------------------------------- every method in every consumer
@pytest.mark.parametrize("name", BUILTIN)
def test_every_method_in_the_span_kernels(name):
    """The kernel resolves, runs through span_normals and the counting type, and
    stays within the method's analytic length bound (derived independently in
    length_error_bound); the span starts at N_l."""
    assert method_kernel(name).shape in SHAPES
    assert method_kernels()[name] is method_kernel(name)
    psi, m = math.pi / 5, 16
    nl, nr = _pair(psi)
    out = span_normals(name, nl[None], nr[None], [m])
    length = np.abs(np.linalg.norm(out.normals, axis=1) - 1.0)
    assert length.max() <= length_error_bound(name, psi, m)
    eps = np.finfo(np.float64).eps
    assert np.abs(out.normals[0] - nl).max() <= 8 * eps
    counts, values = count_ops(name, m, psi=psi, return_values=True)
    # the counting run is the same kernel on another number type: equal up to libm rounding
    assert np.abs(values - out.normals).max() <= 64 * eps * m


@pytest.mark.parametrize("name", BUILTIN)
def test_every_method_in_the_renderer(name):
    ref = render("sphere", "phong", "exact", size=(40, 40), tess=10)
    r = render("sphere", "phong", name, size=(40, 40), tess=10)
    assert r.method == name and np.array_equal(r.mask, ref.mask)
    assert r.triangle is not None and r.normal_length is not None


def test_every_method_in_the_c_benchmark_kernels():
    sys.path.insert(0, str(BENCH))
    try:
        import ckernels as ck
    finally:
        sys.path.remove(str(BENCH))
    c_kernels = {s.c_kernel: s.name for s in registered_methods() if s.c_kernel}
    assert set(c_kernels) <= set(ck.NORMAL_KERNELS)
    assert all(ck.PY_METHOD[k] == name for k, name in c_kernels.items())
    # the harness's kernel table (ENTRY(name, ...), what `harness list` prints) has them
    entries = set(re.findall(r"^\s*ENTRY\((\w+),", (BENCH / "c" / "harness.c").read_text(), re.M))
    assert set(c_kernels) <= entries
    assert {t.name for t in ck.tables().values()} == {t.name for t in default_tables().values()}


def test_every_declared_hw_unit_exists_and_reads_the_registry():
    from chebnorm.hw.units import UNIT_KINDS, UNIT_TARGETS, design_unit, table_matches

    declared = {u for s in registered_methods() for u in s.units}
    assert declared <= set(UNIT_KINDS)
    tables = unit_tables()
    for spec in registered_methods():
        for unit in spec.units:
            design_unit(unit, frac_bits=8)
        if spec.units and spec.table is not None:
            assert tables[spec.units[0]] == spec.table
            assert table_matches(spec.units[0], fit_target(spec.table.target, spec.table.degree))
    assert UNIT_TARGETS == {u: t.target for u, t in tables.items()}


# ------------------------------------------------ a method added at run time
class _ToyKernel:
    """Linear interpolation, then N / sqrt(N.N): exactly the arithmetic of ``exact``,
    written here, so its results must equal ``exact``'s bit for bit."""

    shape = "direct"
    table_scale = 1.0
    normalizer = None

    def setup(self, ops, nl, nr, coefficients=None):
        return {"a": nl, "d": tuple(r - l for l, r in zip(nl, nr))}

    def pixel(self, ops, st, t):
        a, d = st["a"], st["d"]
        n = (a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2])
        r = ops.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
        return (n[0] / r, n[1] / r, n[2] / r)


@pytest.fixture
def toy():
    register(MethodSpec("toy", "linear, then exact normalization (test)", "none", _ToyKernel()))
    try:
        yield "toy"
    finally:
        unregister("toy")
    assert "toy" not in method_names()


def test_toy_method_through_the_registry_alone(toy, capsys, tmp_path):
    assert "toy" in method_kernels() and method_kernel("toy").shape == "direct"
    # chebnorm methods lists it, with exact's errors and operation counts
    assert main(["methods", "--angle", "0.6", "--span", "8", "--json"]) == 0
    rows = {r["name"]: r for r in json.loads(capsys.readouterr().out)["methods"]}
    assert rows["toy"]["max_length_error"] == rows["exact"]["max_length_error"]
    assert rows["toy"]["ops_per_pixel"] == rows["exact"]["ops_per_pixel"]
    # chebnorm render --method accepts it and names it in --help
    assert main(["render", "--mesh", "sphere", "--tess", "8", "--size", "32", "32",
                 "--method", "toy", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["method"] == "toy" and report["max_abs_8bit"] == 0
    with pytest.raises(SystemExit):
        main(["render", "--help"])
    assert "toy" in capsys.readouterr().out


def test_unknown_method_is_one_line_status_2(capsys):
    assert main(["render", "--method", "toy", "--size", "16", "16"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown method 'toy'; accepted: exact" in err


# -------------------------------------------------------- tables, one place
def test_render_fits_wide_tables_through_default_tables():
    """The teapot's spout lip needs tables beyond pi/4: render reports the psi_max it
    used, and the frame equals one rendered with default_tables(psi_max) given."""
    r = render("teapot", "phong", "dichotomy", size=(96, 96))
    assert r.stats["span_angle_max"] > math.pi / 4
    j = r.stats["table_psi_max"]
    given = render("teapot", "phong", "dichotomy", size=(96, 96), tables=default_tables(psi_max=j))
    assert np.array_equal(r.image, given.image)


def _bump_angles(**kw):
    """Render bump:dichotomy, recording the widest span angle of each interpolated
    vector (L, then H) as the span interpolator receives it."""
    seen = []

    def hook(method, nl, nr, m, **k):
        seen.append(float(np.arccos(np.clip(np.einsum("ij,ij->i", nl, nr), -1, 1)).max()))
        return span_normals(method, nl, nr, m, **k)

    r = render(size=(64, 64), shading="bump", method="dichotomy", span_normals=hook, **kw)
    return r, seen


def test_bump_checks_the_h_spans_angle():
    """Defect: the tables were fitted on L's spans only, so H spans wider than
    them failed (the coarse sphere: L 0.98 rad, H 1.11 rad, tables fitted for
    10 pi/32 = 0.98)."""
    r, (psi_l, psi_h) = _bump_angles(mesh="sphere", tess=3)
    assert psi_h > psi_l > math.pi / 4
    assert r.stats["span_angle_max"] == max(psi_l, psi_h)
    assert r.stats["table_psi_max"] == f"{math.ceil(max(psi_l, psi_h) / (math.pi / 32))}*pi/32"


def test_bump_reports_the_widest_span_angle():
    """Defect: the H spans' angle overwrote the L spans' in stats["span_angle_max"]."""
    r, (psi_l, psi_h) = _bump_angles(mesh="teapot")
    assert psi_l > psi_h
    assert r.stats["span_angle_max"] == psi_l


# ------------------------------------------------------- one home, by grep
def _sources():
    for root in ("src", "benchmarks", "paper_repro", "notebooks"):
        for path in sorted((REPO / root).rglob("*")):
            if path.suffix in (".py", ".ipynb"):
                yield path


#: modules that still hold a pairing another change removes (none: hw.units
#: reads unit_tables())
_PENDING: set[str] = set()


def test_each_method_target_pairing_has_one_home():
    homes = {}
    for spec in registered_methods():
        if spec.table is None:
            continue
        pat = re.compile(rf"""["']{spec.name}["']\s*:\s*(fit_target\(\s*)?["']{spec.table.target}["']"""
                         rf"""|TableSpec\(\s*["']{spec.table.target}["']""")
        for path in _sources():
            rel = path.relative_to(REPO).as_posix()
            if pat.search(path.read_text(encoding="utf-8")) and rel not in _PENDING:
                homes.setdefault(spec.name, []).append(rel)
    assert homes == {"dichotomy": ["src/chebnorm/approx/method_registry.py"],
                     "quadratic": ["src/chebnorm/approx/method_registry.py"]}


def test_no_other_list_of_the_methods():
    listing = re.compile(r"""["']exact["'],\s*["']none["'],\s*["']newton["']""")
    found = [p.relative_to(REPO).as_posix() for p in _sources()
             if listing.search(p.read_text(encoding="utf-8"))]
    assert found == ["src/chebnorm/approx/method_registry.py"]  # its doctest prints the names
