"""The reproduction writes the same bytes on another machine and in another install mode.

* :mod:`chebnorm.methods.detmath`: float32 results are the correctly rounded
  ones (checked against mpmath at 200 bits, rounded once), float64 ones are
  the C library's, whichever numpy SIMD loop runs;
* the jobs whose float32 numbers came from numpy's CPU-dispatched loops, fits of
  functions whose float64 loops are CPU-dispatched (exp, acos, pow) and renders give
  bit-identical raw numbers and byte-identical files with numpy's SIMD groups
  disabled (``NPY_DISABLE_CPU_FEATURES``) as with them enabled;
* ``chebnorm repro`` after a non-editable ``pip install .`` finds the
  benchmark results and writes the ledger where the editable install does,
  and its outputs equal the committed ones byte for byte;
* the version check names exactly the packages whose versions differ.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import mpmath
import numpy as np
import pytest

from chebnorm.cli.repro import (
    NUMERIC_DEPENDENCIES,
    installed_versions,
    version_differences,
)
from chebnorm.methods import detmath
from paper_repro.style import stable_svg_ids
from quiet_cli import run_cli_quiet

REPO = Path(__file__).resolve().parents[1]


# ---------------------------------------------------------------- detmath
def _cr32(name: str, x: float) -> np.float32:
    """``name(x)`` at 200 bits, rounded once to 24 bits (independent of detmath's two paths)."""
    fn = {"sin": mpmath.sin, "cos": mpmath.cos, "arccos": mpmath.acos}[name]
    with mpmath.workprec(200):
        v = fn(mpmath.mpf(x))
    if v == 0:
        return np.float32(0.0)
    sign = -1.0 if v < 0 else 1.0
    man, exp = abs(v).man_exp                      # |v| = man * 2**exp, man > 0
    man = int(man)
    shift = max(man.bit_length() - 24, 0)
    q, r = divmod(man, 1 << shift)                 # round half to even, by integers
    half = (1 << shift) >> 1
    if shift and (r > half or (r == half and q & 1)):
        q += 1
    return np.float32(sign * math.ldexp(q, exp + shift))


@pytest.mark.parametrize("name, lo, hi", [("sin", -4.0, 4.0), ("cos", -4.0, 4.0),
                                          ("arccos", -1.0, 1.0)])
def test_float32_functions_are_correctly_rounded(name, lo, hi):
    rng = np.random.default_rng(7)
    x = rng.uniform(lo, hi, 3000).astype(np.float32)
    x = np.concatenate([x, np.float32([0.0, 1.0, -1.0, 0.5, 1e-8, 0.7853982, 3.1415927])])
    x = x[(x >= lo) & (x <= hi)]
    got = getattr(detmath, name)(x)
    assert got.dtype == np.float32
    want = np.array([_cr32(name, float(v)) for v in x], dtype=np.float32)
    bad = np.flatnonzero(got.view(np.uint32) != want.view(np.uint32))
    assert bad.size == 0, [(float(x[i]), float(got[i]), float(want[i])) for i in bad[:5]]


def test_float32_near_ties_take_the_exact_path():
    """Arguments whose float64 value lies near a float32 rounding boundary: detmath's
    recomputation must agree with the independent correctly rounded value."""
    rng = np.random.default_rng(3)
    x = rng.uniform(-4, 4, 400000).astype(np.float32)
    y = np.sin(x.astype(np.float64))
    r = y.astype(np.float32)
    frac = np.abs(y - r.astype(np.float64)) / np.abs(np.spacing(r)).astype(np.float64)
    order = np.argsort(np.abs(frac - 0.5))
    assert np.abs(frac[order[:5]] - 0.5).max() < 2.0 ** -16   # some do go the exact way
    near = x[order[:40]]                                    # the 40 closest to a tie
    got = detmath.sin(near)
    want = np.array([_cr32("sin", float(v)) for v in near], dtype=np.float32)
    assert (got.view(np.uint32) == want.view(np.uint32)).all()


def test_float64_functions_are_the_c_librarys():
    x = np.linspace(-1.0, 1.0, 2001)
    assert detmath.arccos(x).tolist() == [math.acos(v) for v in x]
    assert detmath.sin(x * 3).tolist() == [math.sin(3 * v) for v in x]
    assert detmath.cos(np.float64(0.5)) == math.cos(0.5)
    assert detmath.arctan2(x, x[::-1]).tolist() == [math.atan2(a, b) for a, b in zip(x, x[::-1])]
    assert np.isnan(detmath.arccos(np.array([1.5])))[0]


@pytest.mark.parametrize("y", [31.9, 3.0, 32.0, 1000.0, 2.0, 0.5, -1.0, 1.0, 0.0])
def test_float64_power_is_the_c_librarys_or_numpys_fast_path(y):
    rng = np.random.default_rng(11)
    x = np.concatenate([rng.random(20000) * 3, [0.0, 1.0, np.nan, np.inf, 1e-300, 1e300, -2.0]])
    with np.errstate(all="ignore"):      # numpy's ** warns the same way
        got = detmath.power(x, y)
    fast = {2.0: lambda v: v * v, 0.5: math.sqrt, -1.0: lambda v: 1.0 / v, 1.0: lambda v: v,
            0.0: lambda v: 1.0}

    def want(v):
        if y in fast:
            try:
                return fast[y](v)
            except (ValueError, ZeroDivisionError):
                return math.nan if v < 0 else math.inf
        try:
            return math.pow(v, y)
        except ValueError:          # a negative base, a non-integer exponent
            return math.nan
        except OverflowError:
            return math.inf
    assert got.dtype == np.float64
    _same_bits_nan_as_nan(got, np.array([want(v) for v in x.tolist()]))


def _same_bits_nan_as_nan(got, want):
    """Bit for bit, except that a NaN's sign is free (math.nan is positive, the x86
    default NaN that numpy and the C library return is negative)."""
    nan = np.isnan(want)
    assert (np.isnan(got) == nan).all()
    assert got[~nan].tobytes() == want[~nan].tobytes()


def test_float64_log2_is_the_c_librarys():
    x = np.concatenate([np.linspace(1e-3, 1e3, 5001), [0.0, -1.0, np.inf, np.nan, 2.0 ** -1074]])
    with np.errstate(all="ignore"):
        want = [math.log2(v) if v > 0 else (-math.inf if v == 0 else math.nan) for v in x.tolist()]
    _same_bits_nan_as_nan(detmath.log2(x), np.array(want))


def test_powers_within_their_rounding_bound():
    x = np.array([0.9999999, 1.0000001, 0.5, 0.99])
    p = detmath.powers(x, 128)
    for i, v in enumerate(x):
        for k in range(1, 129):
            exact = mpmath.mpf(float(v)) ** k
            err = abs(mpmath.mpf(float(p[i, k - 1])) - exact) / exact
            assert err <= (k - 1) * 2.0 ** -53 + 2.0 ** -53, (v, k, float(err))
    with pytest.raises(ValueError, match="n >= 1"):
        detmath.powers(x, 0)


def test_stable_svg_ids():
    a = '<path clip-path="url(#p0123456789)"/><clipPath id="p0123456789"/><use href="#mabcdefabcd"/>' \
        '<path id="mabcdefabcd"/><g id="patch_1"/>'
    b = a.replace("p0123456789", "p9876543210").replace("mabcdefabcd", "m1111111111")
    assert stable_svg_ids(a) == stable_svg_ids(b)
    assert 'id="p0000000001"' in stable_svg_ids(a) and 'id="patch_1"' in stable_svg_ids(a)


# ------------------------------------------------------ SIMD independence
def _env_variants() -> dict[str, str | None]:
    """NPY_DISABLE_CPU_FEATURES settings that make this CPU take each SIMD path it has:
    unset (the best), without AVX-512 (X86_V4 and up), without AVX2 (X86_V3 and up: baseline).
    Only groups this CPU has are named (disabling an absent one is a no-op)."""
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    present = [g for g in __cpu_dispatch__ if __cpu_features__.get(g)]
    out: dict[str, str | None] = {"all": None}
    above_v3 = [g for g in present if g != "X86_V3"]
    if "X86_V4" in present:
        out["no X86_V4"] = " ".join(above_v3)
    if "X86_V3" in present:
        out["baseline"] = " ".join(present)
    return out


_PROBE = r"""
import hashlib, json, sys
from pathlib import Path
import numpy as np
from chebnorm.methods import error_sweep, METHODS
from paper_repro import normalization as N
out = Path(sys.argv[1])
h = lambda b: hashlib.sha256(b).hexdigest()
# numpy's own loops whose bits change with the SIMD path on some CPU: float32 sin/exp
# (AVX2 vs baseline), float64 power/arccos (AVX-512's SVML vs the C library)
u = np.linspace(0, 1, 10001)
res = {"numpy_own": h(b"".join(a.tobytes() for a in (
    np.sin(np.linspace(0, 10, 10001, dtype=np.float32)), np.exp(u.astype(np.float32)),
    np.power(u, 31.9), np.arccos(u))))}
methods = tuple(m for m in METHODS if m != "exact")
psis = np.radians(np.linspace(1.0, 45.0, 45))
for key, sweep in (("angle", error_sweep(methods, psis, (64,))),
                   ("length", error_sweep(methods, [N.SPAN_PSI], (2, 64, 512, 1024)))):
    for q in ("length_error", "angle_error", "angle_error_slerp", "vector_error", "specular_error"):
        res[f"sweep_{key}_{q}"] = h(getattr(sweep, q).tobytes())
res["method_errors"] = json.dumps(N.measure_method_errors(), sort_keys=True)
res["drift"] = h(b"".join(np.asarray(v[k]).tobytes() for v in N.measure_drift().values()
                          for k in ("length_error", "angle_error")))
for f in (N.methods_table, N.fig_angular_drift):
    for p in f(out):
        res[p.name] = h(p.read_bytes())
# fits whose float64 exchange evaluates exp, acos, pow (numpy's loops are SVML on AVX-512)
import chebnorm as cn
for expr, iv, d in (("exp(x)", ("0", "1"), 5), ("acos(x)", ("-0.9", "0.9"), 8),
                    ("x**0.7", ("0.5", "2"), 4)):
    t = cn.fit(expr, iv, d, "minimax")
    res[f"fit {expr}"] = h(t.to_json().encode())
# the minimax fit on a set of powers (linear programs on points found by the float64 error)
for expr, iv, d, mons in (("sinh(x)", ("-1/2", "1/2"), 7, (1, 3, 5, 7)),
                          ("exp(-x**2)", ("-1", "1"), 8, None)):
    res[f"powers {expr}"] = h(cn.fit(expr, iv, d, "minimax", monomials=mons).to_json().encode())
    res[f"quantized {expr}"] = h(cn.quantize(t, 16).to_json().encode())
# the rasterizer: mesh construction (Bernstein cubes, corner angles), the numpy reference
# and the compiled engine (specular power, span angles, camera)
from chebnorm.raster import Lighting, get_mesh, render
mesh = get_mesh("teapot")
res["teapot"] = h(mesh.positions.tobytes() + mesh.normals.tobytes())
for engine in ("numpy", "numba"):
    for mode, method, dt in (("phong", "exact", np.float64), ("phong", "dichotomy", np.float32),
                             ("phong", "slerp", np.float32), ("split-gouraud", None, np.float64)):
        r = render(mesh, mode, method, size=(96, 80), dtype=dt, engine=engine,
                   lighting=Lighting(shininess=31.0))
        res[f"render_{engine}_{mode}_{method}"] = h(r.image.tobytes())
print(json.dumps(res))
"""


@pytest.mark.slow
def test_float32_jobs_do_not_depend_on_the_simd_path(tmp_path):
    variants = _env_variants()
    if len(variants) < 2:
        pytest.skip("this CPU has only numpy's baseline SIMD path; nothing to compare")
    results = {}
    for label, disabled in variants.items():
        env = dict(os.environ)
        env.pop("NPY_DISABLE_CPU_FEATURES", None)
        if disabled:
            env["NPY_DISABLE_CPU_FEATURES"] = disabled
        proc = subprocess.run([sys.executable, "-c", _PROBE, str(tmp_path / label.replace(" ", "_"))],
                              env=env, capture_output=True, text=True, cwd=REPO, timeout=900, check=False)
        assert proc.returncode == 0, proc.stderr[-2000:]
        results[label] = json.loads(proc.stdout.splitlines()[-1])
    ref_label, ref = next(iter(results.items()))
    for label, res in results.items():
        if label == ref_label:
            continue
        # the probe shows the setting took effect: numpy's own loops changed bits ...
        assert res.pop("numpy_own") != ref["numpy_own"], f"{label}: numpy path unchanged"
        # ... and nothing the reproduction computes or writes did
        differ = sorted(k for k in res if res[k] != ref[k])
        assert not differ, f"{label} differs from {ref_label}: {differ}"


# ------------------------------------------------------- install mode
def _tracked_copy(dest: Path) -> None:
    files = subprocess.run(["git", "ls-files", "-z"], cwd=REPO, capture_output=True,
                           check=True).stdout.decode().split("\0")
    for name in filter(None, files):
        src = REPO / name
        if src.is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / name)


def _hashes(root: Path) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


@pytest.mark.slow
def test_non_editable_install_writes_the_committed_outputs(tmp_path):
    """A fresh venv (the running interpreter's dependencies, no chebnorm), ``pip install .``
    (not editable) of a copy of the checkout, then ``chebnorm repro`` in that copy: the
    speed-ups come from ./benchmarks/results.json, the ledger lands in ./paper_repro, and
    every file equals the committed one."""
    if not (REPO / ".git").exists():
        pytest.skip("not a git checkout")
    src = tmp_path / "clone"
    _tracked_copy(src)
    venv = tmp_path / "venv"
    subprocess.run([getattr(sys, "_base_executable", sys.executable), "-m", "venv", "--without-pip",
                    str(venv)], check=True)
    py = venv / "bin" / "python"
    site = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          capture_output=True, text=True, check=True).stdout.strip()
    deps = [p for p in sys.path if p.endswith("site-packages")]
    Path(site, "deps.pth").write_text("\n".join(deps) + "\n")   # the dependencies, not chebnorm
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "NPY_DISABLE_CPU_FEATURES")}
    # an ordinary `pip install .` (build isolation: pip fetches setuptools from its index)
    pip = subprocess.run([str(py), "-m", "pip", "install", "-q", "--no-deps", str(src)], env=env,
                         capture_output=True, text=True, cwd=tmp_path, check=False, timeout=900)
    if pip.returncode != 0 and "No matching distribution found for setuptools" in pip.stderr:
        pytest.skip("pip cannot reach an index with setuptools to build the package")
    assert pip.returncode == 0, pip.stderr[-2000:]
    probe = "import chebnorm, paper_repro; print(chebnorm.__file__); print(paper_repro.__file__)"
    where = subprocess.run([str(py), "-c", probe],
                           env=env, capture_output=True, text=True, cwd=tmp_path, check=True).stdout
    assert all(line.startswith(site) for line in where.split()), where   # installed, not src
    # the layer rule is checked on the source tree beside the tests, whatever is installed,
    # run from another folder
    rule = subprocess.run([str(py), "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           str(src / "tests" / "test_architecture.py")], env=env,
                          capture_output=True, text=True, cwd=tmp_path, timeout=600, check=False)
    assert rule.returncode == 0, rule.stdout[-3000:]
    assert " passed" in rule.stdout.splitlines()[-1] and "skipped" not in rule.stdout.splitlines()[-1]
    shutil.rmtree(src / "build", ignore_errors=True)
    before = {**_hashes(src / "figures"), **{f"ledger/{k}": v for k, v in
                                             _hashes(src / "paper_repro").items() if "." in k
                                             and k.split(".")[-1] in ("md", "json")}}
    jobs = ["seed000_normalization", "zz_claims"]
    run = subprocess.run([str(venv / "bin" / "chebnorm"), "repro", *jobs], env=env, cwd=src,
                         capture_output=True, text=True, timeout=1800, check=False)
    assert run.returncode == 0, run.stderr[-2000:]
    assert "versions differ" not in run.stderr
    assert not (src / "figures" / "claims").exists(), "ledger written beside the figures"
    table = (src / "figures" / "normalization" / "methods_table.csv").read_text()
    assert ",nan" not in table.splitlines()[-1], "benchmark results not found"
    after = {**_hashes(src / "figures"), **{f"ledger/{k}": v for k, v in
                                            _hashes(src / "paper_repro").items() if "." in k
                                            and k.split(".")[-1] in ("md", "json")}}
    changed = sorted(k for k in before.keys() | after.keys() if before.get(k) != after.get(k))
    assert not changed, f"a non-editable install rewrote committed files: {changed}"


# ---------------------------------------------------------------- versions
def test_version_differences_name_exactly_the_changed_packages():
    inst = installed_versions()
    assert set(inst) == set(NUMERIC_DEPENDENCIES)
    assert version_differences(inst, inst) == []
    rec = dict(inst, numpy="0.0", scipy=inst["scipy"])
    assert version_differences(rec, inst) == [f"numpy {inst['numpy']} (recorded 0.0)"]


def test_repro_prints_one_line_when_versions_differ(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    rec = dict(installed_versions(), mpmath="0.1")
    (out / "provenance.json").write_text(json.dumps({"versions": rec}))
    proc = run_cli_quiet("repro", "coefficients", "-o", out, cwd=tmp_path)
    assert proc.code == 0, proc.err
    lines = [ln for ln in proc.err.splitlines() if "versions differ" in ln]
    assert len(lines) == 1 and "mpmath" in lines[0] and "numpy" not in lines[0], proc.err
    assert json.loads((out / "provenance.json").read_text())["versions"] == installed_versions()
    again = run_cli_quiet("repro", "coefficients", "-o", out, cwd=tmp_path)
    assert "versions differ" not in again.err


def test_repro_refuses_a_missing_bench_results_file(tmp_path):
    proc = run_cli_quiet("repro", "coefficients", "-o", tmp_path / "o", "--bench-results",
                         tmp_path / "none.json", cwd=tmp_path)
    assert proc.code == 2
    assert len(proc.err.strip().splitlines()) == 1 and "--bench-results" in proc.err


def test_ledger_dir_rule(tmp_path, monkeypatch):
    from paper_repro.paths import ledger_dir
    monkeypatch.chdir(tmp_path)
    assert ledger_dir("figures") == Path("figures") / "claims"      # not a checkout
    (tmp_path / "paper_repro").mkdir()
    assert ledger_dir("figures") == Path("paper_repro")             # a checkout
    assert ledger_dir(tmp_path / "figures") == Path("paper_repro")
    assert ledger_dir("other") == Path("other") / "claims"
    assert ledger_dir("figures", tmp_path / "x") == tmp_path / "x"


# ------------------------------------------------------- OpenBLAS kernels
_BLAS_PROBE = r"""
import hashlib, json
import numpy as np
h = lambda b: hashlib.sha256(b).hexdigest()
rng = np.random.default_rng(0)
a, b = rng.normal(size=(40, 40)), rng.normal(size=40)
res = {"blas_own": h(np.linalg.solve(a, b).tobytes() + (a @ b).tobytes())}
import chebnorm as cn
from chebnorm.approx import fit_target
for name, d in (("rsqrt", 3), ("dichotomy", 2)):
    res[f"target {name}"] = h(fit_target(name, d, coef_frac_bits=24).to_json().encode())
for expr, iv, d, err in (("exp(x)", ("0", "1"), 9, "abs"), ("acos(x)", ("-0.9", "0.9"), 12, "rel"),
                         ("1/sqrt(x)", ("1", "4"), 6, "rel")):
    res[f"fit {expr}"] = h(cn.fit(expr, iv, d, "minimax", err).to_json().encode())
for expr, iv, d, mons in (("sin(x)", ("-1/8", "1/8"), 7, (1, 3, 5, 7)),
                          ("atan(x)", ("0", "1"), 7, (1, 3, 5, 7)),
                          ("cos(x)", ("-pi/4", "pi/4"), 6, None)):
    res[f"powers {expr}"] = h(cn.fit(expr, iv, d, "minimax", monomials=mons).to_json().encode())
pw = cn.fit("1/sqrt(x)", ("1", "4"), 2, kind="minimax", segments=32, coef_frac_bits=20)
res["piecewise"] = h(pw.to_json().encode())
from paper_repro.criterion import interior_min_norm
v = rng.normal(size=(3, 500, 3))
v[1:] = v[0] + 0.05 * v[1:]
v /= np.sqrt((v * v).sum(axis=-1, keepdims=True))
res["interior_min_norm"] = h(interior_min_norm(*v).tobytes())
print(json.dumps(res))
"""


def _blas_core_types() -> list[str]:
    """OpenBLAS kernel families this CPU can run (OPENBLAS_CORETYPE), or [] without OpenBLAS
    dynamic dispatch: Haswell and Sandybridge need AVX2/AVX, SkylakeX AVX-512."""
    from numpy._core._multiarray_umath import __cpu_features__ as feats
    cfg = str(np.show_config(mode="dicts").get("Build Dependencies", {}).get("blas", {}))
    if "openblas" not in cfg.lower() or "DYNAMIC_ARCH" not in cfg:
        return []
    out = []
    if feats.get("AVX512F") and feats.get("AVX512BW"):
        out.append("SkylakeX")
    if feats.get("AVX2") and feats.get("FMA3"):
        out.append("Haswell")
    if feats.get("AVX"):
        out.append("Sandybridge")
    return out


@pytest.mark.slow
def test_fits_do_not_depend_on_the_blas_kernels():
    """The Remez exchange, the batched certifier and the criterion's interior minimum
    use no BLAS/LAPACK (chebnorm.core.detlinalg): the same bytes whichever OpenBLAS
    kernels the CPU selects (on an AMD Zen 4 OpenBLAS picks SkylakeX, on a Zen 5 Zen)."""
    kinds = _blas_core_types()
    if len(kinds) < 2:
        pytest.skip(f"OpenBLAS with dynamic kernels for two CPU families needed; have {kinds}")
    results = {}
    for kind in kinds:
        env = {**os.environ, "OPENBLAS_CORETYPE": kind}
        proc = subprocess.run([sys.executable, "-c", _BLAS_PROBE], env=env, capture_output=True,
                              text=True, cwd=REPO, timeout=900, check=False)
        assert proc.returncode == 0, proc.stderr[-2000:]
        results[kind] = json.loads(proc.stdout.splitlines()[-1])
    ref_kind, ref = kinds[0], results[kinds[0]]
    changed = [k for k in kinds[1:] if results[k]["blas_own"] != ref["blas_own"]]
    assert changed, "no OPENBLAS_CORETYPE setting changed BLAS's own bits: the probe is void"
    for kind in changed:
        differ = sorted(k for k in ref if k != "blas_own" and results[kind][k] != ref[k])
        assert not differ, f"OPENBLAS_CORETYPE={kind} differs from {ref_kind}: {differ}"
